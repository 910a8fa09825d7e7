"""Real one-mode lock-in sweeps of a vibrating wire (../shared/data/sweeps_vibrating_wire; not in
the repository) go into `identify` and `explain --mode response` as the instrument wrote them
(headerless t, F, X, Y, drive) and give what the records show (docs/validation_response.md):
- example1 (one drive level, 8 sweeps, Q ~ 60): linear; f0 inside the half-power band; Q within
  15 % of the half-power width read from the data; an interval from the jackknife over sweeps;
- example6 (12 levels, 23 sweeps, Q ~ 1000): a softening backbone and a width growing with
  amplitude, jumps reproduced by the branch (up and down sweeps differ), not unexplained.
Also the command-line contract: --columns in another order gives the same answer, a bad column
map is exit 2. Skipped when the data or the tool is absent."""
import json
import os
import subprocess
import tempfile
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT",
                                      os.path.join(os.path.dirname(__file__), "..", "..")))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")
DATA = os.path.join(os.path.dirname(ROOT), "shared", "data", "sweeps_vibrating_wire")
BUILT = os.path.exists(os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench", "cvg_ident"))


def run(args):
    return subprocess.run([TOOL] + args, capture_output=True, text=True)


@unittest.skipUnless(BUILT and os.path.isdir(DATA), "tool not built or real sweeps absent")
class RealWireSweeps(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp()

    def explain(self, name, extra=()):
        out = os.path.join(self.tmp, name + ".json")
        p = run(["explain", os.path.join(DATA, name + ".txt"), "--mode", "response",
                 "--response", "velocity", "--json", out] + list(extra))
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(out) as f:
            return json.load(f)

    def test_example1_is_linear_with_f0_and_q(self):
        x = self.explain("example1")
        self.assertEqual(x["selected"], "linear")
        self.assertFalse(x["unexplained"])
        d = x["final"]["derived_ci"]
        self.assertTrue(3955.0 < d["f0_hz"]["value"] < 3980.0, d["f0_hz"])
        self.assertTrue(54.0 < d["Q"]["value"] < 66.0, d["Q"])  # half-power reading: 64
        self.assertLess(d["Q"]["ci_low"], d["Q"]["value"])
        self.assertGreater(d["Q"]["ci_high"], d["Q"]["value"])
        self.assertIn("jackknife", x["final"]["interval_method"])
        self.assertEqual(x["final"]["n_sweeps"], 8)

    def test_example6_softening_backbone_growing_width_and_jumps(self):
        x = self.explain("example6")
        self.assertEqual(x["selected"], "xi+gamma_nl")
        self.assertFalse(x["unexplained"])
        f = x["final"]
        d = f["derived_ci"]
        self.assertLess(d["backbone_hz_per_amp2"]["ci_high"], 0.0)       # softening
        self.assertGreater(d["width_growth_hz_per_amp2"]["ci_low"], 0.0)  # width grows
        self.assertGreaterEqual(f["jumps"], 6)
        self.assertEqual(f["n_drive_levels"], 12)
        self.assertEqual(f["n_sweeps"], 23)
        self.assertTrue(1633.0 < d["f0_hz"]["value"] < 1634.5, d["f0_hz"])
        self.assertTrue(1000.0 < d["Q"]["value"] < 1450.0, d["Q"])

    def test_columns_map_and_bad_map(self):
        src = os.path.join(DATA, "example1.txt")
        swapped = os.path.join(self.tmp, "swapped.csv")
        with open(src) as f, open(swapped, "w") as g:
            for line in f:
                if line.startswith("#") or not line.strip():
                    continue
                t, fr, x, y, d = line.split()
                g.write(",".join([fr, d, t, x, y]) + "\n")
        a = os.path.join(self.tmp, "a.json")
        b = os.path.join(self.tmp, "b.json")
        self.assertEqual(run(["identify", src, "--mode", "response", "--json", a]).returncode, 0)
        p = run(["identify", swapped, "--mode", "response", "--json", b,
                 "--columns", "frequency_hz=1,drive=2,t=3,x=4,y=5"])
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(a) as f, open(b) as g:
            qa, qb = json.load(f)["derived_ci"]["Q"], json.load(g)["derived_ci"]["Q"]
        self.assertAlmostEqual(qa["value"], qb["value"], delta=1e-6 * qa["value"])
        p = run(["identify", src, "--mode", "response", "--columns", "t=1,x=3,y=4"])
        self.assertEqual(p.returncode, 2)
        self.assertIn("frequency_hz", p.stderr)
        p = run(["identify", src, "--mode", "response", "--model", "xi_diff"])
        self.assertEqual(p.returncode, 2)
        self.assertIn("two modes", p.stderr)


if __name__ == "__main__":
    unittest.main()
