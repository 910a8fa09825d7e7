#!/usr/bin/python3
"""Writes a free-decay slow-variable CSV (cvg_ident simulate output: t,q1,p1,q2,p2 with `# omega:`)
into a rosbag of cvg_bench/SlowState on /cvg/slow, stamps = START + t (exact nanoseconds), as the
demodulator node would publish them. Used to make test/data/mems_free_decay_slow.bag:

  bin/cvg_ident simulate --preset mems_ring --mode free_decay --seed 7 --out /tmp/fd.csv
  test/integration/slow_csv_to_bag.py /tmp/fd.csv test/data/mems_free_decay_slow.bag
"""
import sys

import rosbag
import rospy

from cvg_bench.msg import SlowState

START = rospy.Time(1700000000, 0)


def read_csv(path):
    meta, rows, header = {}, [], None
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line:
                continue
            if line.startswith("#"):
                key, _, value = line[1:].partition(":")
                meta[key.strip()] = value.strip()
                continue
            cells = [c.strip() for c in line.replace(";", ",").split(",")]
            if header is None:
                header = cells
                continue
            rows.append(dict(zip(header, (float(c) for c in cells))))
    return meta, rows


def main(argv):
    if len(argv) != 3:
        sys.stderr.write(__doc__)
        return 2
    meta, rows = read_csv(argv[1])
    omega = float(meta.get("omega", 0.0))
    with rosbag.Bag(argv[2], "w") as bag:
        for r in rows:
            stamp = START + rospy.Duration.from_sec(r["t"])
            m = SlowState()
            m.header.stamp = stamp
            m.header.frame_id = "resonator"
            m.phase_epoch = START
            m.q1, m.p1, m.q2, m.p2 = r["q1"], r["p1"], r["q2"], r["p2"]
            m.reference_frequency_rad_s = omega
            bag.write("/cvg/slow", m, stamp)
    print("%d slow states -> %s" % (len(rows), argv[2]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
