#!/usr/bin/python3
"""rostest: launch/replay.launch with its default bag (401 slow states, no raw batches): the replay
player chooses /cvg/slow, the identifier's batch estimate covers all 401 states without a
lost-input reason, and the player leaves /use_sim_time false when the bag has been played."""
import threading
import time
import unittest

import rospy
import rostest

from cvg_bench.msg import ModelEstimate

N = 401


class ReplayLaunch(unittest.TestCase):
    def test_replay_covers_the_bag_and_restores_wall_time(self):
        got = []
        done = threading.Event()

        def on_estimate(msg):
            if msg.method == "ls" and msg.n_samples == N:
                got.append(msg)
                done.set()

        rospy.Subscriber("/cvg/estimate", ModelEstimate, on_estimate)
        self.assertTrue(done.wait(60.0), "no ls estimate over %d states in 60 s" % N)
        self.assertFalse([p for p in got[0].sanity_problems if "lost" in p])
        deadline = time.monotonic() + 20.0
        while rospy.get_param("/use_sim_time", True) and time.monotonic() < deadline:
            time.sleep(0.2)
        self.assertFalse(rospy.get_param("/use_sim_time", True))


if __name__ == "__main__":
    rospy.init_node("replay_launch_check")
    rostest.rosrun("cvg_bench", "replay_launch", ReplayLaunch)
