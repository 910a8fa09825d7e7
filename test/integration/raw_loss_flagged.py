#!/usr/bin/python3
"""rostest: raw batches lost before the demodulator are never silent. A simulated raw record
(cvg_ident simulate --raw) is written to a bag of RawSampleBatch numbered as a publisher numbers
them (header.seq 0, 1, ...) with an empty end-of-record batch, once with batch LEFT_OUT missing
(its number stays missing, as after an overflowing queue) and once whole. Played through the
demodulator into the identifier, the holed bag must give an estimate marked suspect with the
reason "1 raw batches lost upstream ..." (InputLoss.msg), both as published and as the identify
service answers; the whole bag, after both nodes are reset, gives no such reason."""
import os
import subprocess
import tempfile
import threading
import time
import unittest

import rosbag
import roslib.packages
import rospy
import rostest

from bag_player import BagPlayer
from cvg_bench.msg import ModelEstimate, RawSampleBatch
from cvg_bench.srv import Identify
from slow_csv_to_bag import read_csv
from std_srvs.srv import Trigger

START = rospy.Time(1700000000, 0)
BATCH = 5000
LEFT_OUT = 5


def write_raw_bag(csv_path, bag_path, left_out):
    meta, rows = read_csv(csv_path)
    t = [r["t"] for r in rows]
    rate = round(1.0 / (t[1] - t[0]))
    seq = 0
    with rosbag.Bag(bag_path, "w") as bag:
        for b in range(0, len(t), BATCH):
            m = RawSampleBatch()
            m.header.seq = seq
            m.header.stamp = START + rospy.Duration.from_sec(t[b])
            m.header.frame_id = "resonator"
            m.sample_rate_hz = rate
            m.f = [r["f"] for r in rows[b:b + BATCH]]
            m.g = [r["g"] for r in rows[b:b + BATCH]]
            m.omega_rad_s = float(meta["omega"])
            m.phase_epoch = START
            if seq != left_out:
                bag.write("/cvg/raw", m, m.header.stamp)
            seq += 1
        end = RawSampleBatch()  # end of record: its number shows a lost tail too
        end.header.seq = seq
        end.header.stamp = START + rospy.Duration.from_sec(t[-1])
        end.phase_epoch = START
        bag.write("/cvg/raw", end, end.header.stamp + rospy.Duration(0, 1000))


def upstream_reasons(est):
    return [p for p in est.sanity_problems if "lost upstream" in p]


class RawLossFlagged(unittest.TestCase):
    def play(self, bag, timeout):
        """The last estimate published once the bag is over and the identifier is quiet."""
        lock = threading.Lock()
        got = []

        def on_estimate(msg):
            with lock:
                got.append((msg, time.monotonic()))

        sub = rospy.Subscriber("/cvg/estimate", ModelEstimate, on_estimate)
        player = BagPlayer(bag, ["/cvg/identify", "/cvg/demodulator/reset"], timeout)
        try:
            player.proc.wait(timeout)
            deadline = time.monotonic() + timeout
            while time.monotonic() < deadline:
                with lock:
                    if got and time.monotonic() - got[-1][1] > 3.0:
                        break
                time.sleep(0.1)  # poll period of the bounded wait
        finally:
            player.stop()
            sub.unregister()
        with lock:
            return got[-1][0] if got else None

    def test_raw_loss_marks_the_estimate(self):
        timeout = rospy.get_param("~timeout_s", 40.0)
        tmp = tempfile.mkdtemp(prefix="cvg_rawloss_")
        csv_path = os.path.join(tmp, "raw.csv")
        tool = roslib.packages.find_node("cvg_bench", "cvg_ident")
        self.assertTrue(tool, "cvg_ident not built")
        sim = subprocess.run([tool[0], "simulate", "--preset", "mems_ring", "--mode", "free_decay",
                              "--raw", "--duration", "0.2", "--seed", "5", "--out", csv_path],
                             capture_output=True, text=True)
        self.assertEqual(sim.returncode, 0, sim.stderr)
        holed, whole = os.path.join(tmp, "holed.bag"), os.path.join(tmp, "whole.bag")
        write_raw_bag(csv_path, holed, LEFT_OUT)
        write_raw_bag(csv_path, whole, -1)

        e = self.play(holed, timeout)
        self.assertIsNotNone(e, "no estimate from the holed bag")
        self.assertTrue(e.suspect, e.sanity_problems)
        reasons = upstream_reasons(e)
        self.assertEqual(len(reasons), 1, e.sanity_problems)
        self.assertTrue(reasons[0].startswith("1 raw batches lost upstream"), reasons[0])
        # The service answers with the same reasons as the published estimate.
        ans = rospy.ServiceProxy("/cvg/identify", Identify)(model="", method="ls", confidence=0.0)
        self.assertTrue(ans.estimate.suspect, ans.message)
        self.assertEqual(len(upstream_reasons(ans.estimate)), 1, ans.estimate.sanity_problems)

        # The whole record after both nodes are reset: nothing lost, no such reason.
        rospy.ServiceProxy("/cvg/demodulator/reset", Trigger)()
        rospy.ServiceProxy("/cvg/identifier/reset", Trigger)()
        e = self.play(whole, timeout)
        self.assertIsNotNone(e, "no estimate from the whole bag")
        self.assertFalse(upstream_reasons(e), e.sanity_problems)


if __name__ == "__main__":
    rospy.init_node("raw_loss_flagged_test")
    rostest.rosrun("cvg_bench", "raw_loss_flagged", RawLossFlagged)
