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

    def test_export_variants_give_the_same_answer(self):
        """The same sweeps as other exports write them: four columns without the drive (one
        level), F X Y drive without the clock, an instrument header (`t F X Y D`), a clock of 5 s
        resolution (ties), the drive read back with 0.2 % noise, CRLF line ends. f0 and Q as the
        original's within 0.1 %; nothing refused."""
        import random
        rows = []
        with open(os.path.join(DATA, "example1.txt")) as f:
            rows = [l.split() for l in f if l.strip() and not l.startswith("#")]
        rnd = random.Random(1)
        variants = {
            "4col": [r[:4] for r in rows],
            "fxyd": [r[1:] for r in rows],
            "header": [["t", "F", "X", "Y", "D"]] + rows,
            "ties": [["%.0f" % (5 * (float(r[0]) // 5))] + r[1:] for r in rows],
            "noisy_drive": [r[:4] + ["%.9g" % (float(r[4]) * (1 + 0.002 * rnd.gauss(0, 1)))]
                            for r in rows],
        }
        ref = os.path.join(self.tmp, "ref.json")
        p = run(["identify", os.path.join(DATA, "example1.txt"), "--mode", "response",
                 "--response", "velocity", "--json", ref])
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(ref) as f:
            want = json.load(f)["derived_ci"]
        for name, body in variants.items():
            path = os.path.join(self.tmp, name + ".txt")
            with open(path, "w", newline="") as f:
                f.write("".join(" ".join(r) + ("\r\n" if name == "header" else "\n")
                                for r in body))
            out = os.path.join(self.tmp, name + ".json")
            p = run(["identify", path, "--mode", "response", "--response", "velocity",
                     "--json", out])
            self.assertEqual(p.returncode, 0, name + ": " + p.stderr)
            with open(out) as f:
                got = json.load(f)["derived_ci"]
            for k in ("f0_hz", "Q"):
                self.assertAlmostEqual(got[k]["value"], want[k]["value"],
                                       delta=1e-3 * want[k]["value"], msg=name + " " + k)

    def test_low_drive_half_of_example6_is_a_resonance(self):
        """The first 12 sweeps of example6 (the six lowest levels): a linear fit is a resonance
        with a bounded width (the within-sweep sandwich of a fold-free model no longer floors the
        jackknife; it had made the width's interval reach zero and the record was refused)."""
        with open(os.path.join(DATA, "example6.txt")) as f:
            rows = [l for l in f if l.strip() and not l.startswith("#")]
        half = os.path.join(self.tmp, "example6_low.txt")
        with open(half, "w") as f:
            f.write("".join(rows[:len(rows) // 2]))
        out = os.path.join(self.tmp, "example6_low.json")
        p = run(["identify", half, "--mode", "response", "--response", "velocity", "--json", out])
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(out) as f:
            d = json.load(f)["derived_ci"]
        self.assertTrue(1632.0 < d["f0_hz"]["value"] < 1634.0, d["f0_hz"])
        self.assertGreater(d["width_hz"]["ci_low"], 0.5 * d["width_hz"]["value"], d["width_hz"])


if __name__ == "__main__":
    unittest.main()
