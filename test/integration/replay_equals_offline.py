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

from bag_player import BagPlayer
from cvg_bench.msg import ModelEstimate
from cvg_bench.srv import Explain, GetEstimate, Identify, PredictDrift
from std_srvs.srv import Trigger


PLAYED = []  # the bag is played once for all tests of this file


def wait_for_full_estimate(test):
    """The identifier's estimate over every slow state of the bag (it identifies once the replay
    stops); waits on the latched topic with a timeout."""
    bag = rospy.get_param("~bag")
    timeout = rospy.get_param("~timeout_s", 40.0)
    with rosbag.Bag(bag) as b:
        n = b.get_message_count("/cvg/slow")
    test.assertGreater(n, 20)
    got = {}
    done = threading.Event()

    def on_estimate(msg):
        if msg.n_samples == n and msg.method == "ls" and not done.is_set():
            got["estimate"] = msg
            done.set()

    sub = rospy.Subscriber("/cvg/estimate", ModelEstimate, on_estimate)
    if not PLAYED:
        PLAYED.append(BagPlayer(bag, ["/cvg/identify"], timeout))
    test.assertTrue(done.wait(timeout), "no estimate over all %d slow states within %g s" % (n, timeout))
    sub.unregister()
    return got["estimate"], n


class ReplayEqualsOffline(unittest.TestCase):
    def test_live_estimate_equals_offline_tool(self):
        bag = rospy.get_param("~bag")
        model = rospy.get_param("~model", "linear")
        live, n = wait_for_full_estimate(self)

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

    def test_services_answer_on_the_replayed_window(self):
        live, n = wait_for_full_estimate(self)
        timeout = rospy.get_param("~timeout_s", 40.0)
        for name in ("get_estimate", "predict_drift", "identify", "explain", "identifier/reset"):
            rospy.wait_for_service("/cvg/" + name, timeout)
        got = rospy.ServiceProxy("/cvg/get_estimate", GetEstimate)()
        self.assertTrue(got.success, got.message)
        self.assertEqual(list(got.estimate.values), list(live.values))
        self.assertGreater(got.derived.Q, 0.0)
        self.assertLessEqual(got.derived.Q_ci_low, got.derived.Q)
        self.assertGreaterEqual(got.derived.Q_ci_high, got.derived.Q)

        drift = rospy.ServiceProxy("/cvg/predict_drift", PredictDrift)(r=1.0, k=0.05, theta_rad=0.0, theta_grid=8)
        self.assertTrue(drift.success, drift.message)
        self.assertEqual(len(drift.rates), 8)
        for rate in drift.rates:
            self.assertLess(rate.ci_low_rad_s, rate.drift_rate_rad_s)
            self.assertGreater(rate.ci_high_rad_s, rate.drift_rate_rad_s)
        bad = rospy.ServiceProxy("/cvg/predict_drift", PredictDrift)(r=0.01, k=0.05, theta_rad=0.0, theta_grid=0)
        self.assertFalse(bad.success)  # |r| < |k|: (5.9) does not apply; said, not NaN

        ident = rospy.ServiceProxy("/cvg/identify", Identify)
        cubic = ident(model="xi", method="", confidence=0.0)
        self.assertTrue(cubic.success, cubic.message)
        self.assertEqual(cubic.estimate.model, "linear+xi")
        self.assertEqual(cubic.estimate.n_params, 9)
        self.assertEqual(cubic.estimate.n_samples, n)
        wrong = ident(model="warp", method="", confidence=0.0)
        self.assertFalse(wrong.success)
        self.assertIn("warp", wrong.message)

        explained = rospy.ServiceProxy("/cvg/explain", Explain)(mode="")
        self.assertTrue(explained.success, explained.message)
        self.assertIn("xi", explained.message)  # the simulated ring has cubic stiffness
        report = json.loads(explained.report_json)  # the JSON of `cvg_ident explain`
        for key in ("baseline", "steps", "selected", "unexplained", "cause", "final"):
            self.assertIn(key, report)
        self.assertIn("xi", report["selected"])
        tools = roslib.packages.find_node("cvg_bench", "cvg_ident")
        out = os.path.join(tempfile.mkdtemp(prefix="cvg_replay_"), "explain.json")
        proc = subprocess.run([tools[0], "explain", rospy.get_param("~bag"), "--mode", "free_decay",
                               "--json", out], capture_output=True, text=True)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        with open(out) as f:
            offline = json.load(f)
        self.assertEqual(report["selected"], offline["selected"])  # same window, same answer
        self.assertEqual(report["final"]["model"], offline["final"]["model"])

        reset = rospy.ServiceProxy("/cvg/identifier/reset", Trigger)()
        self.assertTrue(reset.success)
        after = rospy.ServiceProxy("/cvg/get_estimate", GetEstimate)()
        self.assertFalse(after.success)


if __name__ == "__main__":
    rospy.init_node("replay_equals_offline_test")
    try:
        rostest.rosrun("cvg_bench", "replay_equals_offline", ReplayEqualsOffline)
    finally:
        for player in PLAYED:
            player.stop()
