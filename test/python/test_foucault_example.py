"""Regression test of the real-data Foucault example (docs/examples/foucault.md).

Runs scripts/foucault_example.py (no figures) on ../shared/data/foucault_florence_2021 relative to
the repository root (env CVG_BENCH_ROOT) with the built tool $CVG_BENCH_ROOT/bin/cvg_ident; skipped
when the data or the tool is missing. Tolerances are ~2x the 95 % half-widths the example reports
(Newey-West for the direct fits, the tool's honest intervals for the ladder).
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT",
                                      os.path.join(os.path.dirname(__file__), "..", "..")))
DATA = os.path.join(ROOT, "..", "shared", "data", "foucault_florence_2021",
                    "2021_09_17_14_57_N.csv")
TOOL = os.path.join(ROOT, "bin", "cvg_ident")
SCRIPT = os.path.join(ROOT, "scripts", "foucault_example.py")


def tool_works():
    try:
        return subprocess.run([TOOL, "--help"], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL).returncode == 0
    except OSError:
        return False


@unittest.skipUnless(os.path.exists(DATA), "Foucault data not present")
@unittest.skipUnless(tool_works(), "cvg_ident not built")
class FoucaultExample(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.TemporaryDirectory()
        out = os.path.join(cls.work.name, "summary.json")
        subprocess.run(["/usr/bin/python3", SCRIPT, "--tool", TOOL, "--data", DATA, "--work",
                        cls.work.name, "--summary", out, "--no-figures"], check=True,
                       stdout=subprocess.DEVNULL, env=dict(os.environ, CVG_BENCH_ROOT=ROOT))
        with open(out) as fh:
            cls.s = json.load(fh)

    @classmethod
    def tearDownClass(cls):
        cls.work.cleanup()

    def test_glitch_frames_trimmed(self):
        self.assertEqual(self.s["trimmed_samples"], 5)
        self.assertLess(self.s["max_kept_speed_px_s"], self.s["speed_limit_px_s"])

    def test_reference_frequency(self):
        # 2.2371955 +/- 8.3e-6 rad/s (1 sigma); period 2.8085 s, L = g / omega^2 = 1.959 m.
        self.assertAlmostEqual(self.s["omega_rad_s"], 2.2371955, delta=5e-5)
        self.assertAlmostEqual(self.s["length_m"], 1.959, delta=0.002)

    def test_direct_precession(self):
        d = self.s["direct"]
        # phi = a + b t: 4.73 deg/h, 95 % half-width 0.52 (Newey-West).
        self.assertAlmostEqual(d["phi_rate_linear_deg_h"]["value"], 4.73, delta=1.0)
        # with the r k (Airy-type) term: 7.67 deg/h at k = 0, half-width 0.16.
        self.assertAlmostEqual(d["phi_rate_at_k0_deg_h"]["value"], 7.67, delta=0.35)
        self.assertLess(d["phi_rate_at_k0_deg_h"]["ci_high"],
                        self.s["physics"]["foucault_deg_h"])

    def test_airy_pixel_scale(self):
        # s = sqrt((3/8) omega / (c L^2)) = 1050 +/- 14 px/m (1 sigma).
        self.assertAlmostEqual(self.s["physics"]["pixels_per_m_from_airy"], 1050.0, delta=60.0)

    def test_ladder_xi_is_hardening(self):
        # The amplitude-frequency law has the opposite sign of a pendulum's softening.
        xi = self.s["ladder"]["xi"]["parameters"]["xi"]
        self.assertAlmostEqual(xi["value"], -6.47e-7, delta=3e-8)
        self.assertIn("xi", self.s["explain"]["selected"])


if __name__ == "__main__":
    unittest.main()
