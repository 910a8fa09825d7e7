#!/usr/bin/python3
"""rostest: the demodulator node recovers from bad samples. Raw batches of a constant envelope
q = (q1, p1, q2, p2) at W (f = p1 sin W t + q1 cos W t, g likewise: the substitution (2.4)) are
published with, in order: a sample f = 1e300, a sample g = NaN, a batch whose stamps go back in
time, then good data. Every published slow state must equal q (noise-free input: the filter's
passband ripple 1e-6 at 120 dB bounds the error), and the diagnostics count each bad input."""
import math
import threading
import unittest

import rospy
import rostest

from cvg_bench.msg import RawSampleBatch, SlowState
from diagnostic_msgs.msg import DiagnosticArray

W = 2.0 * math.pi * 2000.0  # reference frequency [rad/s]
FS = 50000.0                # sample rate [Hz]
N = 500                     # samples per batch (10 ms)
Q = (0.8, 0.1, -0.3, 0.2)   # envelope (q1, p1, q2, p2)


class DemodRecovers(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.slow = []
        self.diag = None
        rospy.Subscriber("/cvg/slow", SlowState, self.on_slow)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diag)
        self.pub = rospy.Publisher("/cvg/raw", RawSampleBatch, queue_size=1000)
        self.epoch = rospy.Time(1000, 0)

    def on_slow(self, msg):
        with self.lock:
            self.slow.append(msg)

    def on_diag(self, msg):
        for s in msg.status:
            if s.name.endswith("demodulator") and any(kv.key == "out_of_range" for kv in s.values):
                with self.lock:
                    self.diag = {kv.key: kv.value for kv in s.values}

    def batch(self, t0):
        m = RawSampleBatch()
        m.header.stamp = self.epoch + rospy.Duration.from_sec(t0)
        m.phase_epoch = self.epoch
        m.sample_rate_hz = FS
        m.omega_rad_s = W
        ts = [t0 + i / FS for i in range(N)]
        m.f = [Q[1] * math.sin(W * t) + Q[0] * math.cos(W * t) for t in ts]
        m.g = [Q[3] * math.sin(W * t) + Q[2] * math.cos(W * t) for t in ts]
        return m

    def wait_until(self, pred, timeout, what):
        deadline = rospy.get_time() + timeout
        while not pred():
            if rospy.get_time() > deadline or rospy.is_shutdown():
                self.fail("timed out waiting for " + what)
            rospy.sleep(0.02)

    def test_bad_samples_are_dropped_and_the_filter_recovers(self):
        timeout = rospy.get_param("~timeout_s", 30.0)
        self.wait_until(lambda: self.pub.get_num_connections() > 0, timeout, "the demodulator")
        batches = []
        k = 0
        for _ in range(20):
            batches.append(self.batch(k * N / FS))
            k += 1
        b = self.batch(k * N / FS)
        b.f[100] = 1e300
        batches.append(b)
        k += 1
        b = self.batch(k * N / FS)
        b.g[50] = float("nan")
        batches.append(b)
        k += 1
        batches.append(self.batch((k - 6) * N / FS))  # stamps back in time (a replayed batch)
        for _ in range(25):
            batches.append(self.batch(k * N / FS))
            k += 1
        for m in batches:
            self.pub.publish(m)
            rospy.sleep(0.005)
        t_end = k * N / FS
        self.wait_until(lambda: len(self.slow) > 0 and
                        (self.slow[-1].header.stamp - self.epoch).to_sec() > t_end - 0.03,
                        timeout, "slow states up to the end of the data")
        # Diagnostics are published about once a second: the one read must come after the last
        # batch (an earlier one may predate the replayed batch and count no reset yet).
        n_batches = len(batches)
        self.wait_until(lambda: self.diag is not None and
                        int(self.diag["batches"]) >= n_batches,
                        timeout, "diagnostics after the last batch")
        with self.lock:
            slow = list(self.slow)
            diag = dict(self.diag)
        worst = 0.0
        for s in slow:
            worst = max(worst, max(abs(a - b) for a, b in zip((s.q1, s.p1, s.q2, s.p2), Q)))
        rospy.loginfo("demod_recovers: %d slow states, worst error %.3g; diagnostics %s",
                      len(slow), worst, diag)
        self.assertGreater(len(slow), 150)
        self.assertLess(worst, 1e-4)
        # Good data after the last bad batch reach the output (the last 0.1 s is covered).
        late = [s for s in slow if (s.header.stamp - self.epoch).to_sec() > t_end - 0.1]
        self.assertGreater(len(late), 100)
        self.assertGreaterEqual(int(diag["out_of_range"]), 1)
        self.assertGreaterEqual(int(diag["non_finite"]), 1)
        self.assertGreaterEqual(int(diag["node_resets"]), 1)


if __name__ == "__main__":
    rospy.init_node("demod_recovers_test")
    rostest.rosrun("cvg_bench", "demod_recovers", DemodRecovers)
