#!/usr/bin/python3
"""rostest: dynamic_reconfigure of identifier_node. After the run's estimate (linear, 95 %), a
lower confidence (90 %) re-identifies the buffered data: same values, intervals narrower by the
ratio of the Student quantiles (1.645 / 1.960 for ~1500 dof, within 0.5 %); a model change to
linear+xi adds the xi parameter; an invalid model, and values out of range (confidence 1.5,
forgetting 1.2, window -3 s), are refused and the settings stay (never clamped silently)."""
import threading
import time
import unittest

import dynamic_reconfigure.client
import rospy
import rostest

from cvg_bench.msg import ModelEstimate

RATIO_90_95 = 1.6449 / 1.9600  # normal quantiles; the Student ones at ~1500 dof differ by < 0.1 %


class LiveTuning(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.latest = None
        rospy.Subscriber("/cvg/estimate", ModelEstimate, self.on_estimate)

    def on_estimate(self, msg):
        with self.lock:
            self.latest = msg

    def wait_for(self, what, timeout_s=20.0):
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline and not rospy.is_shutdown():
            with self.lock:
                if self.latest is not None and what(self.latest):
                    return self.latest
            time.sleep(0.05)  # poll period of the bounded wait
        self.fail("no matching estimate within %.0f s" % timeout_s)

    def test_reconfigure(self):
        first = self.wait_for(lambda e: e.n_samples > 300)
        self.assertAlmostEqual(first.confidence, 0.95)
        client = dynamic_reconfigure.client.Client("/cvg/identifier", timeout=10)
        client.update_configuration({"confidence": 0.90})
        narrow = self.wait_for(lambda e: abs(e.confidence - 0.90) < 1e-12)
        i = list(first.names).index("gamma")
        self.assertAlmostEqual(narrow.values[i], first.values[i], delta=1e-12 * abs(first.values[i]))
        ratio = (narrow.ci_high[i] - narrow.ci_low[i]) / (first.ci_high[i] - first.ci_low[i])
        self.assertAlmostEqual(ratio, RATIO_90_95, delta=0.005 * RATIO_90_95)
        client.update_configuration({"model": "xi"})
        cubic = self.wait_for(lambda e: "xi" in e.names)
        self.assertEqual(cubic.model, "linear+xi")
        applied = client.update_configuration({"model": "bogus"})
        self.assertEqual(applied["model"], "xi")  # refused: the previous setting stays
        # Out of range: refused with the reason, never clamped silently (issue #27).
        applied = client.update_configuration({"confidence": 1.5})
        self.assertAlmostEqual(applied["confidence"], 0.90)
        applied = client.update_configuration({"rls_forgetting": 1.2})
        self.assertAlmostEqual(applied["rls_forgetting"], 1.0)
        applied = client.update_configuration({"window_s": -3.0})
        self.assertAlmostEqual(applied["window_s"], 0.0)


if __name__ == "__main__":
    rospy.init_node("live_tuning_test")
    rostest.rosrun("cvg_bench", "live_tuning", LiveTuning)
