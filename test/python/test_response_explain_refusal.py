"""`explain --mode response` refuses a record only when the model it selects has no resonance
(issue #24; docs/response.md): a rival candidate whose width interval reaches zero must not refuse a
record the selected model describes. The record is the response generator's xi record of seed
52420000 (validate_response.py, base 52410000): a hardening backbone at Q 500, a drifting f0, a
background with a slope, velocity output, conjugated lock-in. Its gamma_nl-only fit reads the
width's interval as [-3.2, 6.4] Hz, so `identify --model gamma_nl` is refused; the refusal of that
candidate used to refuse the whole explain (11 of the 150 generator records of the reporting run).
Noise only is still refused by explain (test_bad_input_suite). Skipped when the tool is not built."""
import json
import os
import subprocess
import tempfile
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT",
                                      os.path.join(os.path.dirname(__file__), "..", "..")))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")
BUILT = os.path.exists(os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench", "cvg_ident"))

RECORD = ["--f0", "256.3988730571789", "--q", "500.0", "--levels", "4", "--sweeps-per-level", "2",
          "--points", "40", "--max-amplitude", "0.00027503521657688877", "--noise",
          "5.500704331537776e-07", "--correlation", "0.0", "--seed", "52420000", "--f0-drift-hz",
          "0.015383932383430733", "--background", "-1.020174791827651e-06,3.907941126043492e-06",
          "--background-slope", "1.2973187744945337e-05,-7.535081946756607e-06", "--response",
          "velocity", "--conjugate", "--effect", "xi=25945565.722230062"]


def run(*args):
    return subprocess.run([TOOL] + list(args), capture_output=True, text=True, timeout=600)


@unittest.skipUnless(BUILT, "tool not built")
class ResponseExplainRefusal(unittest.TestCase):
    def test_a_rivals_open_width_interval_does_not_refuse_the_record(self):
        with tempfile.TemporaryDirectory() as tmp:
            csv = os.path.join(tmp, "xi.csv")
            p = run("simulate", "--mode", "response", "--out", csv, *RECORD)
            self.assertEqual(p.returncode, 0, p.stderr)
            rival = run("identify", csv, "--mode", "response", "--response", "velocity",
                        "--model", "gamma_nl", "--json", os.path.join(tmp, "g.json"))
            self.assertNotEqual(rival.returncode, 0)
            self.assertIn("no resonance", rival.stderr)
            out = os.path.join(tmp, "x.json")
            p = run("explain", csv, "--mode", "response", "--response", "velocity", "--json", out)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(out) as f:
                x = json.load(f)
            self.assertEqual(x["selected"], "xi")
            self.assertFalse(x["unexplained"])


if __name__ == "__main__":
    unittest.main()
