#!/usr/bin/python3
"""rostest: the identifier's tf frames. Once the replayed bag's states are identified (latched
/cvg/estimate and /cvg/derived over all of them), tf holds resonator -> stiffness_axis and
resonator -> damping_axis as pure rotations about z by the derived alpha_rad and beta_rad, and
resonator -> wave_pattern.

Convention (src/ros/identifier_node.cpp publishFrames, core defectAxes): the child frames are
rotated by the axis angle itself, yaw = alpha = atan2(h~s, h~c) / 4 and yaw = beta =
atan2(b_s, b_c) / 4 (the physical angle of the n = 2 pattern's axis, in (-pi/4, pi/4]), not by
4 alpha or 2 alpha; wave_pattern is rotated by the orbit angle theta of the latest slow state."""
import math
import threading
import time
import unittest

import rosbag
import rospy
import rostest
import tf2_ros

from bag_player import BagPlayer
from cvg_bench.msg import DerivedQuantitiesStamped, ModelEstimate

PARENT = "resonator"  # config/identifier.yaml frame_id; child_frame_prefix is ""
ANGLE_TOL = 1e-9
STAMP_TOL = rospy.Duration(0, 1000)  # tf2's Python buffer returns stamps rounded through a double


def same_stamp(a, b):
    return abs(a - b) <= STAMP_TOL


def yaw_of(q):
    """Rotation angle about z of a unit quaternion; also returns how far it is from a pure z rotation."""
    yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
    return yaw, math.hypot(q.x, q.y)


def wrap(a):
    """Angle difference wrapped to (-pi, pi]."""
    return math.atan2(math.sin(a), math.cos(a))


class TfFrames(unittest.TestCase):
    def lookup(self, tf_buffer, child, timeout_s, not_before=rospy.Time(0)):
        """Latest PARENT -> child transform (time 0) stamped not before not_before, or None; polled
        against the WALL clock: under use_sim_time tf2's own lookup timeout counts sim time, which
        stops with the bag."""
        deadline = time.monotonic() + timeout_s
        while not rospy.is_shutdown():
            if tf_buffer.can_transform(PARENT, child, rospy.Time(0)):
                t = tf_buffer.lookup_transform(PARENT, child, rospy.Time(0))
                if t.header.stamp >= not_before:
                    return t
            if time.monotonic() > deadline:
                return None
            time.sleep(0.01)  # poll period of the bounded wait
        return None

    def test_axis_frames_match_the_derived_angles(self):
        bag = rospy.get_param("~bag")
        timeout = rospy.get_param("~timeout_s", 40.0)
        deadline = time.monotonic() + timeout  # one budget for every wait, below rostest's limit

        def left():
            return max(0.1, deadline - time.monotonic())
        with rosbag.Bag(bag) as b:
            n = b.get_message_count("/cvg/slow")
        self.assertGreater(n, 20)

        got = {}
        done = threading.Event()
        lock = threading.Lock()

        def check_done():
            if "estimate" in got and "derived" in got and \
                    got["derived"].header.stamp == got["estimate"].window_end:
                done.set()

        def on_estimate(msg):
            with lock:
                if msg.n_samples == n and msg.method == "ls":
                    got["estimate"] = msg
                    check_done()

        def on_derived(msg):
            with lock:
                got["derived"] = msg
                check_done()

        tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(600.0))
        listener = tf2_ros.TransformListener(tf_buffer)
        subs = [rospy.Subscriber("/cvg/estimate", ModelEstimate, on_estimate),
                rospy.Subscriber("/cvg/derived", DerivedQuantitiesStamped, on_derived)]
        player = BagPlayer(bag, ["/cvg/identify"], timeout)
        try:
            finished = done.wait(left())
        finally:
            player.stop()
            for s in subs:
                s.unregister()
        self.assertTrue(finished, "no estimate over all %d slow states with its derived quantities "
                        "within %g s (got %s)" % (n, timeout, sorted(got)))
        estimate, derived = got["estimate"], got["derived"]
        self.assertEqual(estimate.rank, estimate.n_params, estimate.identifiability_note)
        self.assertEqual(estimate.header.frame_id, PARENT)

        # wave_pattern goes out with every (20 Hz throttled) slow state and with the estimate,
        # stamped with the latest slow state: wait until tf holds the last one.
        w = self.lookup(tf_buffer, "wave_pattern", left(), estimate.window_end - STAMP_TOL)
        self.assertIsNotNone(w, "no %s -> wave_pattern transform of the last slow state within %g s"
                             % (PARENT, timeout))
        self.assertEqual(w.child_frame_id, "wave_pattern")
        yaw, tilt = yaw_of(w.transform.rotation)
        self.assertLess(tilt, 1e-12, "wave_pattern is not a rotation about z")
        self.assertTrue(math.isfinite(yaw))

        # The axis frames are sent in the same callback as the latched estimate, so a short wait.
        expected = {"stiffness_axis": derived.alpha_rad, "damping_axis": derived.beta_rad}
        for child, angle in sorted(expected.items()):
            t = self.lookup(tf_buffer, child, min(5.0, left()))
            self.assertIsNotNone(t, "no %s -> %s transform" % (PARENT, child))
            self.assertEqual(t.header.frame_id, PARENT)
            self.assertEqual(t.child_frame_id, child)
            v = t.transform.translation
            self.assertEqual((v.x, v.y, v.z), (0.0, 0.0, 0.0), child)
            yaw, tilt = yaw_of(t.transform.rotation)
            self.assertLess(tilt, 1e-12, "%s is not a rotation about z" % child)
            self.assertLess(abs(wrap(yaw - angle)), ANGLE_TOL,
                            "%s: yaw %.15g rad, derived angle %.15g rad" % (child, yaw, angle))
            self.assertTrue(same_stamp(t.header.stamp, w.header.stamp), child)
        # Not a vacuous check: the two defect axes of the simulated ring differ.
        self.assertGreater(abs(wrap(derived.alpha_rad - derived.beta_rad)), 1e-6)

        del listener


if __name__ == "__main__":
    rospy.init_node("tf_frames_test")
    rostest.rosrun("cvg_bench", "tf_frames", TfFrames)
