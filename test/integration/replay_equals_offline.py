#!/usr/bin/python3
"""rostest: replay = live. A bag of slow states is played with `rosbag play --clock` into the
identifier node; its estimate over all the bag's states equals `cvg_ident identify` on the same bag
(same core function, same times relative to the first stamp: equal to rounding)."""
import json
import os
import subprocess
import tempfile
import threading
import unittest

import rosbag
import roslib.packages
import rospy
import rostest

from cvg_bench.msg import ModelEstimate


class ReplayEqualsOffline(unittest.TestCase):
    def test_live_estimate_equals_offline_tool(self):
        bag = rospy.get_param("~bag")
        model = rospy.get_param("~model", "linear")
        timeout = rospy.get_param("~timeout_s", 40.0)
        with rosbag.Bag(bag) as b:
            n = b.get_message_count("/cvg/slow")
        self.assertGreater(n, 20)
        got = {}
        done = threading.Event()

        def on_estimate(msg):
            if msg.n_samples == n and msg.method == "ls":
                got["estimate"] = msg
                done.set()

        rospy.Subscriber("/cvg/estimate", ModelEstimate, on_estimate)
        self.assertTrue(done.wait(timeout), "no estimate over all %d slow states within %g s" % (n, timeout))
        live = got["estimate"]

        tools = roslib.packages.find_node("cvg_bench", "cvg_ident")
        self.assertTrue(tools, "cvg_ident not built")
        out = os.path.join(tempfile.mkdtemp(prefix="cvg_replay_"), "offline.json")
        proc = subprocess.run([tools[0], "identify", bag, "--mode", "free_decay", "--model", model,
                               "--method", "ls", "--json", out], capture_output=True, text=True)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        with open(out) as f:
            offline = json.load(f)

        self.assertEqual(live.model, offline["model"])
        self.assertEqual(live.n_equations, offline["n_equations"])
        self.assertEqual(live.rank, offline["rank"])
        self.assertAlmostEqual(live.sigma, offline["sigma"], delta=1e-12 * max(1.0, abs(offline["sigma"])))
        self.assertEqual(sorted(live.names), sorted(offline["parameters"].keys()))
        for i, name in enumerate(live.names):
            p = offline["parameters"][name]
            scale = 1e-9 * max(1.0, abs(p["value"]))
            self.assertAlmostEqual(live.values[i], p["value"], delta=scale, msg=name)
            self.assertAlmostEqual(live.ci_low[i], p["ci_low"], delta=scale, msg=name)
            self.assertAlmostEqual(live.ci_high[i], p["ci_high"], delta=scale, msg=name)


if __name__ == "__main__":
    rospy.init_node("replay_equals_offline_test")
    rostest.rosrun("cvg_bench", "replay_equals_offline", ReplayEqualsOffline)
