#!/usr/bin/python3
"""rostest: simulator node -> demodulator node. The slow variables the demodulator publishes match
the simulator's noise-free averaged-model slow variables within a tolerance derived from the raw
noise (through the filter's bandwidth) and the first-order averaging error (small parameter
epsilon = sum |z| A^p / omega)."""
import math
import threading
import unittest

import rospy
import rostest

from cvg_bench.msg import SimulationTruth, SlowState
from diagnostic_msgs.msg import DiagnosticArray
from cvg_bench.srv import StartFreeDecay

EPOCH_TOL_NS = 0


class DemodMatchesTruth(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.truth = None
        self.demod = []
        self.exact = []
        self.truth_event = threading.Event()
        self.last_demod_wall = None
        rospy.Subscriber("/cvg/truth", SimulationTruth, self.on_truth)
        rospy.Subscriber("/cvg/slow", SlowState, self.on_demod)
        rospy.Subscriber("/cvg/sim/slow_truth", SlowState, self.on_exact)
        self.diagnostics = None
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics)

    def on_diagnostics(self, msg):
        for status in msg.status:
            if status.name.endswith("demodulator") and any(kv.key == "accepted" for kv in status.values):
                with self.lock:
                    self.diagnostics = {kv.key: kv.value for kv in status.values}

    def on_truth(self, msg):
        with self.lock:
            self.truth = msg
        self.truth_event.set()

    def on_demod(self, msg):
        with self.lock:
            self.demod.append(msg)
            self.last_demod_wall = rospy.get_time()

    def on_exact(self, msg):
        with self.lock:
            self.exact.append(msg)

    def wait_until(self, predicate, timeout_s, what):
        deadline = rospy.get_time() + timeout_s
        ev = threading.Event()
        while not predicate():
            if rospy.get_time() > deadline or rospy.is_shutdown():
                self.fail("timed out after %g s waiting for %s" % (timeout_s, what))
            ev.wait(0.02)

    def test_demodulated_slow_variables_match_truth(self):
        timeout = rospy.get_param("~timeout_s", 40.0)
        rospy.wait_for_service("/cvg/start_free_decay", timeout)
        rospy.wait_for_service("/cvg/demodulator/reset", timeout)
        start = rospy.ServiceProxy("/cvg/start_free_decay", StartFreeDecay)
        res = start(duration_s=0.0, seed=3)
        self.assertTrue(res.success, res.message)
        self.assertTrue(self.truth_event.wait(timeout), "no /cvg/truth")
        truth = self.truth
        n_exact = truth.n_slow_states
        self.wait_until(lambda: len(self.exact) >= n_exact, timeout, "%d noise-free slow states" % n_exact)
        # The demodulator finishes a group delay after the last raw sample: wait until it is quiet.
        self.wait_until(lambda: self.last_demod_wall is not None and
                        rospy.get_time() - self.last_demod_wall > 0.5, timeout, "the demodulator to finish")

        with self.lock:
            demod = list(self.demod)
            exact = list(self.exact)
        self.assertGreater(len(demod), 50, "too few demodulated states")
        epoch = exact[0].phase_epoch
        for m in demod:
            self.assertEqual(m.phase_epoch, epoch, "demodulator and simulator disagree on the phase epoch")
        te = [(m.header.stamp - epoch).to_sec() for m in exact]
        qe = [(m.q1, m.p1, m.q2, m.p2) for m in exact]

        # Tolerance. Noise: white noise sigma on f, g mixed by 2 cos / 2 sin has variance 2 sigma^2
        # spread over [0, fs/2]; the low-pass passes at most up to its stopband edge B (0.5 x output
        # rate by default), so the slow noise std is <= sigma sqrt(4 B / fs); 5 of those bound the
        # maximum over the record. Averaging: the averaged model tracks the full equations to first
        # order in epsilon = sum_i |z_i| A^p_i / omega (A the largest amplitude), error <= eps A.
        out_rate = rospy.get_param("/cvg/demodulator/output_rate_hz", 2000.0)
        fs = truth.raw_sample_rate_hz
        sigma_slow = truth.raw_noise_std * math.sqrt(4.0 * 0.5 * out_rate / fs)
        amp = max(math.sqrt(sum(c * c for c in q)) for q in qe)
        powers = {"xi": 2, "kappa": 4, "gamma_nl": 2, "xi_diff": 2, "xi_k": 2}
        eps = sum(abs(v) * amp ** powers.get(n, 0) for n, v in zip(truth.names, truth.values)) / truth.omega_rad_s
        tol = 5.0 * sigma_slow + eps * amp
        rospy.loginfo("demod vs truth: sigma_slow %.3g, eps %.3g, A %.3g -> tolerance %.3g", sigma_slow, eps, amp, tol)

        worst, sq, n = 0.0, 0.0, 0
        j = 0
        for m in demod:
            t = (m.header.stamp - epoch).to_sec()
            if t < te[0] or t > te[-1]:
                continue
            while j + 1 < len(te) and te[j + 1] < t:
                j += 1
            w = (t - te[j]) / (te[j + 1] - te[j])
            ref = [qe[j][c] + w * (qe[j + 1][c] - qe[j][c]) for c in range(4)]
            for c, v in enumerate((m.q1, m.p1, m.q2, m.p2)):
                d = v - ref[c]
                worst = max(worst, abs(d))
                sq += d * d
                n += 1
        self.assertGreater(n, 200)
        rms = math.sqrt(sq / n)
        rospy.loginfo("demod vs truth over %d values: max %.3g, rms %.3g (tolerance %.3g)", n, worst, rms, tol)
        self.assertLess(worst, tol)
        # The typical error is the noise plus the averaging error, not a phase or scale slip.
        self.assertLess(rms, sigma_slow * 2.0 + eps * amp)

        # Diagnostics carry the sample counters: every raw sample accepted, none dropped.
        n_raw = truth.n_raw_samples
        self.wait_until(lambda: self.diagnostics is not None and
                        int(self.diagnostics.get("accepted", "0")) >= n_raw, 10.0,
                        "demodulator diagnostics counting %d accepted samples" % n_raw)
        self.assertEqual(int(self.diagnostics["rejected_total"]), 0)
        self.assertEqual(int(self.diagnostics["accepted"]), n_raw)

        # A free decay from chosen orbit elements (5.2): the first noise-free slow state has
        # |q|^2 = r^2 + k^2; impossible requests are refused with a reason.
        start = rospy.ServiceProxy("/cvg/start_free_decay", StartFreeDecay)
        bad = start(duration_s=0.0, seed=3, amplitude=0.0, quadrature=0.1, theta_rad=0.0)
        self.assertFalse(bad.success)
        self.assertIn("amplitude", bad.message)
        bad = start(duration_s=0.0, seed=3, amplitude=0.5, quadrature=0.6, theta_rad=0.3)
        self.assertFalse(bad.success)
        self.assertIn("|k| <= r", bad.message)
        with self.lock:
            self.exact = []
        res = start(duration_s=0.0, seed=3, amplitude=0.5, quadrature=0.1, theta_rad=0.3)
        self.assertTrue(res.success, res.message)
        self.wait_until(lambda: len(self.exact) >= 1, timeout, "the first slow state of the new run")
        with self.lock:
            first = self.exact[0]
        norm_sq = first.q1 ** 2 + first.p1 ** 2 + first.q2 ** 2 + first.p2 ** 2
        self.assertAlmostEqual(norm_sq, 0.5 ** 2 + 0.1 ** 2, delta=1e-9)


if __name__ == "__main__":
    rospy.init_node("demod_matches_truth_test")
    rostest.rosrun("cvg_bench", "demod_matches_truth", DemodMatchesTruth)
