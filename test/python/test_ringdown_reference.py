"""Known-answer tests of the reference Q estimators in scripts/validate_ringdown.py (the published
formulas of mdovale/RingDownAnalysis reimplemented for the comparison in
docs/validation_ringdown.md): exact Q on a noise-free decay, and a profile-likelihood interval
whose width matches the Cramer-Rao bound of the same model under white noise."""
import math
import os
import sys
import unittest

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import validate_ringdown as V  # noqa: E402


class ReferenceEstimators(unittest.TestCase):
    f, tau = 1.0e4, 0.8  # Q = pi f tau = 25132.7

    def test_profile_exact_on_noise_free_decay(self):
        t = np.linspace(0.0, 3.0, 1500)
        a = 2.0e-4 * np.exp(-t / self.tau) + 1e-7
        q, lo, hi = V.ref_profile_q(t, a, self.f)
        self.assertAlmostEqual(q / (math.pi * self.f * self.tau), 1.0, delta=2e-3)

    def test_profile_interval_matches_cramer_rao_under_white_noise(self):
        rng = np.random.default_rng(7)
        t = np.linspace(0.0, 3.0, 2000)
        sig = 0.01
        a = np.exp(-t / self.tau) + sig * rng.normal(size=t.size)
        q, lo, hi = V.ref_profile_q(t, a, self.f)
        self.assertIsNotNone(lo)
        self.assertIsNotNone(hi)
        # Fisher information of (c1, tau, c0) for A = c1 e^{-t/tau} + c0, white noise sig.
        e = np.exp(-t / self.tau)
        J = np.column_stack([e, e * t / self.tau ** 2, np.ones_like(t)])
        R = np.linalg.qr(J, mode="r")
        Rinv = np.linalg.solve(R, np.eye(3))
        sd_tau = sig * math.sqrt((Rinv @ Rinv.T)[1, 1])
        half = 0.5 * (hi - lo) / (math.pi * self.f)
        self.assertAlmostEqual(half / (1.96 * sd_tau), 1.0, delta=0.1)
        self.assertLess(abs(q / (math.pi * self.f) - self.tau), 4 * sd_tau)

    def test_envelope_slope_q(self):
        t = np.linspace(0.0, 3.0, 1500)
        a = 3.0 * np.exp(-t / self.tau)
        q, lo, hi = V.ref_envelope_q(t, a, self.f)
        self.assertAlmostEqual(q / (math.pi * self.f * self.tau), 1.0, delta=1e-9)
        # Only samples at or above 5 % of the largest: ln 20 tau = 2.4 s of the 3 s.
        rng = np.random.default_rng(3)
        q2, lo2, hi2 = V.ref_envelope_q(t, a * np.exp(0.02 * rng.normal(size=t.size)), self.f)
        self.assertTrue(lo2 < math.pi * self.f * self.tau < hi2)


if __name__ == "__main__":
    unittest.main()
