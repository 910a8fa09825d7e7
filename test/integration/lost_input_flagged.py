#!/usr/bin/python3
"""rostest: input lost on the way is never silent. The test writes copies of the slow-state bag
numbered as a publisher numbers them (header.seq 0, 1, ...; the stored bag has none), one with
messages 100..109 left out (their numbers stay missing, as after an overflowing queue), replays
them, and asserts that the final estimate over all received states is published `suspect` with a
reason naming the 10 lost messages; the whole copy's estimate has no such reason."""
import os
import tempfile
import threading
import unittest

import rosbag
import rospy
import rostest

from bag_player import BagPlayer
from cvg_bench.msg import ModelEstimate
from std_srvs.srv import Trigger

LEFT_OUT = range(100, 110)


def numbered_copy(bag, out, left_out):
    kept = 0
    with rosbag.Bag(bag) as src, rosbag.Bag(out, "w") as dst:
        for i, (topic, msg, t) in enumerate(src.read_messages()):
            msg.header.seq = i
            if i not in left_out:
                dst.write(topic, msg, t)
                kept += 1
    return kept


def final_estimate(bag, n, timeout):
    got = []
    done = threading.Event()

    def on_estimate(msg):
        if msg.method == "ls" and msg.n_samples == n:
            got.append(msg)
            done.set()

    sub = rospy.Subscriber("/cvg/estimate", ModelEstimate, on_estimate)
    player = BagPlayer(bag, ["/cvg/identify"], timeout)
    try:
        done.wait(timeout)
    finally:
        player.stop()
        sub.unregister()
    return got[0] if got else None


class LostInputFlagged(unittest.TestCase):
    def test_gaps_mark_the_estimate_suspect(self):
        bag = rospy.get_param("~bag")
        timeout = rospy.get_param("~timeout_s", 40.0)
        with tempfile.TemporaryDirectory() as tmp:
            holed = os.path.join(tmp, "holed.bag")
            kept = numbered_copy(bag, holed, LEFT_OUT)
            e = final_estimate(holed, kept, timeout)
            self.assertIsNotNone(e, "no ls estimate over %d states" % kept)
            self.assertTrue(e.suspect)
            reasons = [p for p in e.sanity_problems if "lost in transport" in p]
            self.assertEqual(len(reasons), 1, e.sanity_problems)
            self.assertTrue(reasons[0].startswith("%d " % len(LEFT_OUT)), reasons[0])

            # The same data whole, after a reset: nothing lost, no such reason.
            rospy.ServiceProxy("/cvg/identifier/reset", Trigger)()
            whole = os.path.join(tmp, "whole.bag")
            n = numbered_copy(bag, whole, ())
            e = final_estimate(whole, n, timeout)
            self.assertIsNotNone(e, "no ls estimate over %d states" % n)
            self.assertFalse([p for p in e.sanity_problems if "lost in transport" in p],
                             e.sanity_problems)


if __name__ == "__main__":
    rospy.init_node("lost_input_flagged_test")
    rostest.rosrun("cvg_bench", "lost_input_flagged", LostInputFlagged)
