#!/usr/bin/python3
"""rostest: two simulated gyros (gyro_a, gyro_b) side by side. Each publishes its own estimate
(gamma within 5 % of the MEMS truth) with frame_id <gyro>/resonator; tf holds
<gyro>/resonator -> <gyro>/stiffness_axis, damping_axis, wave_pattern for both; apart from the
shared infrastructure topics (/rosout, /tf, /tf_static, /diagnostics) no topic has publishers in
both namespaces and every service of one gyro lives under its namespace."""
import threading
import time
import unittest

import rosgraph
import rospy
import rostest
import tf2_ros
import yaml

from cvg_bench.msg import ModelEstimate, SimulationTruth
from cvg_bench.srv import StartFreeDecay

GYROS = ("gyro_a", "gyro_b")
SHARED = {"/rosout", "/rosout_agg", "/tf", "/tf_static", "/diagnostics", "/clock"}
REL_TOL = 0.05


class TwoGyros(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.estimates = {}
        self.truth = {}
        # Listening from the start: the frames are broadcast while the data arrive.
        self.tf_buffer = tf2_ros.Buffer(rospy.Duration(60.0))
        self.tf_listener = tf2_ros.TransformListener(self.tf_buffer)
        for g in GYROS:
            rospy.Subscriber("/%s/estimate" % g, ModelEstimate, self.on_estimate, g)
            rospy.Subscriber("/%s/truth" % g, SimulationTruth, self.on_truth, g)

    def on_estimate(self, msg, gyro):
        with self.lock:
            self.estimates[gyro] = msg

    def on_truth(self, msg, gyro):
        with self.lock:
            self.truth[gyro] = msg

    def test_no_collisions(self):
        tf_buffer = self.tf_buffer
        # A run per gyro while this node listens to tf (the autostarted runs may be over already).
        for g in GYROS:
            rospy.wait_for_service("/%s/start_free_decay" % g, 10.0)
            self.assertTrue(rospy.ServiceProxy("/%s/start_free_decay" % g, StartFreeDecay)().success)
        deadline = time.monotonic() + 30.0
        while time.monotonic() < deadline:
            with self.lock:
                done = all(g in self.estimates and self.estimates[g].experiment_id >= 2
                           and self.estimates[g].n_samples > 300 for g in GYROS)
            if done:
                break
            time.sleep(0.05)  # poll period of the bounded wait
        for g in GYROS:
            with self.lock:
                est, truth = self.estimates.get(g), self.truth.get(g)
            self.assertIsNotNone(est, g)
            self.assertEqual(est.header.frame_id, "%s/resonator" % g)
            true_gamma = truth.values[list(truth.names).index("gamma")]
            gamma = est.values[list(est.names).index("gamma")]
            self.assertAlmostEqual(gamma, true_gamma, delta=REL_TOL * true_gamma)
            for child in ("stiffness_axis", "damping_axis", "wave_pattern"):
                ok = False
                until = time.monotonic() + 5.0
                while not ok and time.monotonic() < until:
                    ok = tf_buffer.can_transform("%s/resonator" % g, "%s/%s" % (g, child),
                                                 rospy.Time(0))
                    time.sleep(0.05)  # poll period of the bounded wait
                self.assertTrue(ok, "%s/%s" % (g, child))
        frames = yaml.safe_load(tf_buffer.all_frames_as_yaml()) or {}
        self.assertEqual(len(frames), 6, frames)  # 3 child frames per gyro, none shared
        for child, info in frames.items():
            gyro = child.split("/")[0]
            self.assertIn(gyro, GYROS, child)
            self.assertEqual(info["parent"], "%s/resonator" % gyro)
        publishers, _, services = rosgraph.Master("/two_gyros_check").getSystemState()
        for topic, nodes in publishers:
            if topic in SHARED:
                continue
            owners = {g for g in GYROS for n in nodes if n.startswith("/%s/" % g)}
            self.assertLessEqual(len(owners), 1, "%s published by %s" % (topic, nodes))
            for g in owners:
                self.assertTrue(topic.startswith("/%s/" % g), "%s published by %s" % (topic, nodes))
        for service, nodes in services:
            for g in GYROS:
                if any(n.startswith("/%s/" % g) for n in nodes) and not service.endswith(
                        ("/get_loggers", "/set_logger_level")):
                    self.assertTrue(service.startswith("/%s/" % g), service)


if __name__ == "__main__":
    rospy.init_node("two_gyros_check")
    rostest.rosrun("cvg_bench", "two_gyros", TwoGyros)
