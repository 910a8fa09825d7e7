"""The independent validation harness (scripts/validate_independent.py) and its generator.

The generator's known answers need no tool: the averaged model equals the paper's (2.5) rows and
the compact cubic/quintic forms (docs/paper.md item 1), a linear free decay has the envelope
exp(-gamma t / 2), the stationary sweep solves (3.3) and its linear points the closed form, and the
full equations (2.3) integrated by solve_ivp differ from the averaged model at first order (the
difference halves when omega doubles). The --quick smoke run needs the built tool: 5 explain runs
of 3 data kinds that must each end with a verdict (this checks the harness, not the tool's
accuracy, which docs/validation_independent.md reports).
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT",
                                      os.path.join(os.path.dirname(__file__), "..", "..")))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from independent_model import selfcheck  # noqa: E402

TOOL = os.path.join(ROOT, "bin", "cvg_ident")


def tool_works():
    try:
        return subprocess.run([TOOL, "--help"], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL).returncode == 0
    except OSError:
        return False


class GeneratorKnownAnswers(unittest.TestCase):
    def test_checks_pass(self):
        for name, err, tol in selfcheck.checks(fast=True):
            with self.subTest(check=name):
                self.assertLessEqual(err, tol, name)


@unittest.skipUnless(tool_works(), "cvg_ident not built")
class QuickRun(unittest.TestCase):
    def test_quick_subset_runs_and_scores(self):
        with tempfile.TemporaryDirectory() as work:
            out = os.path.join(work, "quick.json")
            p = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts",
                                                                 "validate_independent.py"),
                                "--quick", "--kinds", "fd_slow,sweep,fd_raw", "--tool", TOOL,
                                "--json", out], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               universal_newlines=True)
            self.assertEqual(p.returncode, 0, p.stdout[-2000:])
            with open(out) as fh:
                res = json.load(fh)
        self.assertEqual(res["selfcheck"], "ok")
        runs = res["results"]
        self.assertEqual(len(runs), 5)
        self.assertEqual({r["kind"] for r in runs}, {"fd_slow", "sweep", "fd_raw"})
        for r in runs:
            with self.subTest(kind=r["kind"], label=r["label"]):
                self.assertEqual(r["status"], "ok", r.get("why", ""))
                self.assertIn("correct", r)
                self.assertGreaterEqual(r["seed"], 50000)


if __name__ == "__main__":
    unittest.main()
