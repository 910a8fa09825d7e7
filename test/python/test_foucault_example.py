"""Regression test of the real-data Foucault example (docs/examples/foucault.md).

Runs scripts/foucault_example.py (no figures) on ../shared/data/foucault_florence_2021 relative to
the repository root (env CVG_BENCH_ROOT) with the built tool $CVG_BENCH_ROOT/bin/cvg_ident and
checks every number the write-up quotes, all of which come from cvg_ident's output; skipped when
the data or the tool is missing (the data are not in the repository). Tolerances: a few units of
the last quoted digit for deterministic numbers (the tool is deterministic; the slack absorbs
compiler and library differences), not the statistical intervals.
"""
import json
import os
import subprocess
import tempfile
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT",
                                      os.path.join(os.path.dirname(__file__), "..", "..")))
DATA = os.path.join(ROOT, "..", "shared", "data", "foucault_florence_2021",
                    "2021_09_17_14_57_N.csv")
TOOL = os.path.join(ROOT, "bin", "cvg_ident")
SCRIPT = os.path.join(ROOT, "scripts", "foucault_example.py")

# The numbers quoted in docs/examples/foucault.md.
DOC = {
    "omega_rad_s": 2.2371955,
    "length_m": 1.959,
    "n_slow": 516,
}


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

    def test_reference_frequency_and_demodulation(self):
        self.assertAlmostEqual(self.s["omega_rad_s"], DOC["omega_rad_s"], delta=5e-6)
        self.assertAlmostEqual(self.s["length_m"], DOC["length_m"], delta=0.002)
        self.assertEqual(self.s["n_slow"], DOC["n_slow"])
        self.assertAlmostEqual(self.s["r_px"]["start"], 253.5, delta=0.1)
        self.assertAlmostEqual(self.s["r_px"]["end"], 183.1, delta=0.1)

    def test_explain_verdict_today(self):
        # Pinned: best-subset selection now reaches the second cubic invariant by itself: xi + xi_k
        # (the gamma_nl subsets, whose output-error fits diverge from the LS start, are retried
        # from nested refined fits and said in the notes; the correlation factor comes from the
        # largest finalist whose trajectory exists, c ~ 23, where a diverged one gave zeros and
        # c = 1). The adequacy test still finds a slow misfit (AR(1) rho ~0.84 after the smooth
        # part). docs/examples/foucault.md quotes these; update both together.
        e = self.s["explain"]
        self.assertEqual(sorted(e["selected"]), ["xi", "xi_k"])
        self.assertTrue(e["unexplained"])
        lof = e["lack_of_fit"]
        self.assertLess(lof["p_value_unwhitened"], 1e-6)
        self.assertLess(lof["low_frequency_p_value"], 1e-15)
        self.assertIn("rho = 0.84", lof["noise_model"])
        self.assertAlmostEqual(e["baseline"]["sigma"], 7.51, delta=0.01)
        self.assertAlmostEqual(e["steps"][0]["sigma"], 0.714, delta=0.002)
        self.assertAlmostEqual(e["steps"][1]["sigma"], 0.529, delta=0.002)

    def check(self, entry, value, low=None, high=None, rel=0.005):
        self.assertAlmostEqual(entry["value"], value, delta=rel * abs(value))
        if low is not None:
            self.assertAlmostEqual(entry["ci_low"], low, delta=rel * abs(value))
            self.assertAlmostEqual(entry["ci_high"], high, delta=rel * abs(value))

    def test_paper_cubic_precesses_the_wrong_way(self):
        xi = self.s["ladder"]["xi"]
        self.check(xi["parameters"]["xi"], -6.47e-7, -6.70e-7, -6.23e-7)
        self.check(xi["phi_rate_k0_deg_h"], 1.79, 1.24, 2.33, rel=0.02)
        self.check(xi["phi_rate_deg_h"], 3.81, 3.30, 4.32, rel=0.01)
        # +-0.10 deg/h (6 % of its std): the endpoints follow the AR(1) rho (~0.96) of the Ceres
        # residuals, whose third digit moved with how the solve's residual pass is taken
        # (-2.07, -2.03, -1.99, -2.04 over the last three sessions' versions).
        self.check(self.s["ladder"]["xi (ceres)"]["phi_rate_k0_deg_h"], 1.28, -2.04, 4.59, rel=0.08)

    def test_extended_model(self):
        ls, ce = self.s["ladder"]["xi+xi_k"], self.s["ladder"]["xi+xi_k (ceres)"]
        self.check(ls["precession_coupling"], 9.36e-7, 1.59e-7, 17.12e-7, rel=0.01)
        self.check(ce["precession_coupling"], 2.26e-6, 1.15e-6, 3.37e-6, rel=0.01)
        self.check(ls["phi_rate_k0_deg_h"], 8.81, 5.47, 12.15, rel=0.005)
        self.check(ce["phi_rate_k0_deg_h"], 12.93, 4.91, 20.94, rel=0.01)
        self.check(ls["phi_rate_deg_h"], 5.02, 4.27, 5.77, rel=0.01)
        self.check(ce["phi_rate_deg_h"], 4.24, -1.97, 10.46, rel=0.02)
        self.assertAlmostEqual(self.s["ladder"]["xi (ceres)"]["sigma"], 0.714, delta=0.002)
        self.assertAlmostEqual(ce["sigma"], 0.529, delta=0.002)
        self.assertAlmostEqual(self.s["physics"]["sigma_gain_over_paper_cubic_ceres"], 1.35,
                               delta=0.01)
        self.assertAlmostEqual(self.s["physics"]["sigma_gain_over_paper_cubic"], 1.0002,
                               delta=0.0005)
        self.assertAlmostEqual(self.s["physics"]["pixels_per_m_from_coupling"], 967, delta=5)
        self.assertAlmostEqual(self.s["physics"]["foucault_deg_h"], 10.40, delta=0.005)
        # Both swing-rate intervals (correlation-honest) contain Foucault's 10.40 deg/h.
        for fit in (ls, ce):
            self.assertLess(fit["phi_rate_k0_deg_h"]["ci_low"], 10.40)
            self.assertGreater(fit["phi_rate_k0_deg_h"]["ci_high"], 10.40)

    def test_quality_factor(self):
        self.assertAlmostEqual(self.s["Q_envelope_record"], 4970, delta=10)
        ce = self.s["ladder"]["xi+xi_k (ceres)"]["envelope"]
        ls = self.s["ladder"]["xi+xi_k"]["envelope"]
        for e, q, lo, hi in ((ce, 4874, 4281, 5656), (ls, 4481, 4295, 4683)):
            self.assertAlmostEqual(e["Q"], q, delta=20)
            self.assertAlmostEqual(e["Q_ci_low"], lo, delta=20)
            self.assertAlmostEqual(e["Q_ci_high"], hi, delta=20)
        gamma = self.s["ladder"]["xi+xi_k"]["parameters"]["gamma"]
        self.assertLess(gamma["ci_low"], 0.0)  # not identified: W/gamma means nothing
        self.assertAlmostEqual(self.s["ladder"]["xi+xi_k"]["Q_from_gamma"], 8917, delta=50)
        self.assertAlmostEqual(self.s["ladder"]["linear"]["Q_from_gamma"], 1553, delta=10)

    def test_not_separable(self):
        c = self.s["ladder"]["xi+xi_k"]["max_linear_corr"]
        self.assertEqual(sorted(c["pair"]), ["h_c", "n"])
        self.assertGreater(abs(c["corr"]), 0.9998)
        p = self.s["ladder"]["xi+xi_k"]["parameters"]
        self.assertAlmostEqual(p["n"]["value"], -0.042, delta=0.001)
        self.assertAlmostEqual(p["h_c"]["value"], -0.040, delta=0.001)
        self.assertAlmostEqual(p["nu"]["value"], -0.0035, delta=0.0001)
        self.assertAlmostEqual(self.s["ladder"]["xi+xi_k (ceres)"]["parameters"]["n"]["value"],
                               -0.027, delta=0.001)


if __name__ == "__main__":
    unittest.main()
