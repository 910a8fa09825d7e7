"""Ring-down records of the independent generator (scripts/validate_ringdown.py, tuning seeds only)
on which earlier versions of `explain --mode ringdown` went wrong, with their known truth:
- two_stage 42400014: a fast first stage 10x the mode at the first sample; the additive-noise
  weights collapsed (no relative-noise term, levels from a polynomial overshooting the corner) and
  the span's first samples outweighed the rest: a beat was called, with lack of fit;
- clean 41000029: lock-in-filtered floor noise wandering over the span's last decibels; the span's
  scatter understated it, the tail was overweighted and the record was called unexplained;
- det_loss 42500020: a detection-gain step inside one block of the lack-of-fit test's local AR
  models (their least-squares fit came out non-stationary): it must stay unexplained;
- clean 41000063: a floor of lock-in-filtered noise whose deep Rayleigh dips kept the
  line-plus-floor evidence at 19 (under 30): no floor was claimed though the tail scatters 3.6x
  the decay's (noise_floor must be found);
- gamma_a 41200000 and det_loss 42500015 without a floor: a decay that slows (damping in A) or
  a detection step bent the line-plus-floor fit towards a level near the end; the span was cut
  10 dB above a suspected floor, and the detection step was called a floor. Neither scatters like
  noise: no floor may be claimed or suspected;
- two_stage 41400082: a plateau shorter than the head the plateau level is read from; the decay
  samples in it put the drive-off 3 dB into a 12 dB fast first stage, the span skipped the rest
  of it and a single exponential was called;
- beat 41300004: a plateau that beats less than once before the drive-off; the drive-off must stay
  at the real switch-off (not at the plateau's first beat dip) and the beat be found.
Skipped when the tool is not built."""
import importlib.util
import json
import os
import subprocess
import tempfile
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT",
                                      os.path.join(os.path.dirname(__file__), "..", "..")))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")


def generator():
    spec = importlib.util.spec_from_file_location(
        "validate_ringdown", os.path.join(ROOT, "scripts", "validate_ringdown.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@unittest.skipUnless(os.path.exists(os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench",
                                                 "cvg_ident")), "tool not built")
class RingdownRegressions(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.gen = generator()
        cls.tmp = tempfile.mkdtemp()

    def explain(self, kind, seed, with_floor=True):
        t, y, idx, fmt, truth = self.gen.make_record(kind, seed, with_floor)
        path = os.path.join(self.tmp, "%s_%d.csv" % (kind, seed))
        self.gen.write_record(path, t, y, idx, fmt, truth)
        out = path + ".json"
        p = subprocess.run([TOOL, "explain", path, "--mode", "ringdown", "--json", out],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        return json.load(open(out)), truth

    def test_fast_first_stage_is_a_two_stage_decay(self):
        j, _ = self.explain("two_stage", 42400014)
        self.assertEqual(j["selected"], ["two_stage"], j["cause"])
        self.assertFalse(j["unexplained"], j["cause"])

    def test_clean_record_with_slow_floor_noise_is_a_single_exponential(self):
        j, truth = self.explain("clean", 41000029)
        self.assertEqual(j["selected"], [], j["cause"])
        self.assertFalse(j["unexplained"], j["cause"])
        q = j["final"]["derived_ci"]["Q"]
        self.assertLessEqual(q["ci_low"], truth["Q"])
        self.assertGreaterEqual(q["ci_high"], truth["Q"])
        self.assertIn("floor's rms", j["final"]["error_model"]["why"])

    def test_detection_step_stays_unexplained(self):
        j, _ = self.explain("det_loss", 42500020)
        self.assertTrue(j["unexplained"], j["cause"])

    def test_noisy_floor_with_weak_evidence_is_found(self):
        j, truth = self.explain("clean", 41000063)
        self.assertIn("noise_floor", j["causes"], j["final"]["segment"]["why"])
        self.assertEqual(j["selected"], [], j["cause"])
        q = j["final"]["derived_ci"]["Q"]
        self.assertLessEqual(q["ci_low"], truth["Q"])
        self.assertGreaterEqual(q["ci_high"], truth["Q"])

    def test_slowing_decay_without_a_floor_is_fitted_to_the_end(self):
        j, _ = self.explain("gamma_a", 41200000, with_floor=False)
        why = j["final"]["segment"]["why"]
        self.assertNotIn("noise_floor", j["causes"], why)
        self.assertIn("no noise floor reached", why)
        self.assertEqual(j["selected"], ["gamma_a"], j["cause"])

    def test_detection_step_without_a_floor_claims_none(self):
        j, _ = self.explain("det_loss", 42500015, with_floor=False)
        self.assertNotIn("noise_floor", j["causes"], j["final"]["segment"]["why"])
        self.assertTrue(j["unexplained"], j["cause"])

    def test_short_plateau_keeps_the_fast_first_stage(self):
        j, _ = self.explain("two_stage", 41400082)
        self.assertEqual(j["selected"], ["two_stage"], j["cause"])
        self.assertLess(j["final"]["segment"]["drive_off_s"], 9.0, j["final"]["segment"]["why"])

    def test_slowly_beating_plateau_is_a_beat(self):
        j, _ = self.explain("beat", 41300004)
        self.assertTrue(j["final"]["segment"]["has_plateau"], j["final"]["segment"]["why"])
        self.assertEqual(j["selected"], ["beat"], j["cause"])


if __name__ == "__main__":
    unittest.main()
