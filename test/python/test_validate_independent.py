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


class OutsideEffectRecords(unittest.TestCase):
    """A record with an effect outside the library is written from the trajectory that has it
    (until 2026-11-26 the writer looked up the clean one): same seed, the records differ by >5
    noise std (identical under the bug)."""

    def test_outside_effect_reaches_the_record(self):
        import numpy as np
        import validate_independent as vi
        with tempfile.TemporaryDirectory() as work:
            paths = []
            for i, gen in enumerate([[], ["delay"]]):
                case = dict(kind="sweep", preset="sw_ring_24k", noise="white", hidden=[],
                            gen=gen, outside=gen[0] if gen else None, id=i, seed=4242)
                _, _, err = vi.make_trajectory(("sweep", "sw_ring_24k", gen, work))
                self.assertEqual(err, "")
                paths.append(vi.noisy_record(case, work)[0])
            clean, delayed = (np.genfromtxt(p, delimiter=",", comments="#", skip_header=3)
                              for p in paths)
        sigma = vi.presets.SWEEP["sw_ring_24k"]["sigma"]
        self.assertEqual(clean.shape, delayed.shape)
        self.assertGreater(np.abs(clean[:, 1:] - delayed[:, 1:]).max(), 5 * sigma)  # 7.4 sigma


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
