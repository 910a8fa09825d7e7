#!/usr/bin/python3
"""rostest: the demodulator node on a looping bag. A raw record (cvg_ident simulate --raw) is written
to a bag of RawSampleBatch and played with `rosbag play --clock --loop`; at the loop the data jump
back in time, the node resets once, and its slow states of the second pass are exactly those of the
first (same stamps, same values): the reset is clean, no state leaks across the jump."""
import os
import subprocess
import tempfile
import threading
import unittest

import rosbag
import roslib.packages
import rospy
import rostest

from bag_player import BagPlayer
from cvg_bench.msg import RawSampleBatch, SlowState
from diagnostic_msgs.msg import DiagnosticArray
from slow_csv_to_bag import read_csv

START = rospy.Time(1700000000, 0)
BATCH = 500


def write_raw_bag(csv_path, bag_path):
    meta, rows = read_csv(csv_path)
    t = [r["t"] for r in rows]
    f = [r["f"] for r in rows]
    g = [r["g"] for r in rows]
    rate = round(1.0 / (t[1] - t[0]))
    with rosbag.Bag(bag_path, "w") as bag:
        for b in range(0, len(t), BATCH):
            m = RawSampleBatch()
            m.header.stamp = START + rospy.Duration.from_sec(t[b])
            m.header.frame_id = "resonator"
            m.sample_rate_hz = rate
            m.f = f[b:b + BATCH]
            m.g = g[b:b + BATCH]
            m.omega_rad_s = float(meta["omega"])
            m.phase_epoch = START
            bag.write("/cvg/raw", m, m.header.stamp)
    return len(t)


class DemodBagLoop(unittest.TestCase):
    def test_second_pass_equals_first(self):
        timeout = rospy.get_param("~timeout_s", 40.0)
        tmp = tempfile.mkdtemp(prefix="cvg_loop_")
        csv_path, bag_path = os.path.join(tmp, "raw.csv"), os.path.join(tmp, "raw.bag")
        tool = roslib.packages.find_node("cvg_bench", "cvg_ident")
        self.assertTrue(tool, "cvg_ident not built")
        sim = subprocess.run([tool[0], "simulate", "--preset", "mems_ring", "--mode", "free_decay", "--raw",
                              "--duration", "0.03", "--seed", "5", "--out", csv_path],
                             capture_output=True, text=True)
        self.assertEqual(sim.returncode, 0, sim.stderr)
        write_raw_bag(csv_path, bag_path)

        lock = threading.Lock()
        passes = [[]]
        diag = {}
        enough = threading.Event()

        def on_slow(msg):
            with lock:
                cur = passes[-1]
                if cur and msg.header.stamp < cur[-1].header.stamp:
                    passes.append([])
                    cur = passes[-1]
                cur.append(msg)
                if len(passes) >= 3:  # the second pass is complete once the third starts
                    enough.set()

        def on_diag(msg):
            for s in msg.status:
                if s.name.endswith("demodulator"):
                    with lock:
                        diag.update({kv.key: kv.value for kv in s.values})

        rospy.Subscriber("/cvg/slow", SlowState, on_slow, queue_size=100000)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag)
        player = BagPlayer(bag_path, ["/cvg/demodulator/reset"], timeout, loop=True)
        try:
            self.assertTrue(enough.wait(timeout), "the bag did not loop twice within %g s" % timeout)
        finally:
            player.stop()
        with lock:
            first, second = passes[0], passes[1]
        self.assertGreater(len(first), 20)
        self.assertEqual(len(first), len(second))
        for a, b in zip(first, second):
            self.assertEqual(a.header.stamp, b.header.stamp)
            for c in ("q1", "p1", "q2", "p2"):
                self.assertAlmostEqual(getattr(a, c), getattr(b, c), delta=1e-12)
        # Diagnostics (1 Hz) count the resets and no dropped sample.
        ev = threading.Event()
        for _ in range(int(10.0 / 0.05)):
            with lock:
                if int(diag.get("node_resets", "0")) >= 1:
                    break
            ev.wait(0.05)
        with lock:
            self.assertGreaterEqual(int(diag.get("node_resets", "0")), 1, diag)
            self.assertEqual(int(diag.get("rejected_total", "-1")), 0, diag)


if __name__ == "__main__":
    rospy.init_node("demod_bag_loop_test")
    rostest.rosrun("cvg_bench", "demod_bag_loop", DemodBagLoop)
