"""Offline = live demodulation: `cvg_ident identify RAW.bag` demodulates with the node's settings
(config/demodulator.yaml: 2 kHz output), so it equals `cvg_ident demod --rate 2000` followed by
identify (same number of equations, estimates within one standard error), not the 100 Hz default of a raw CSV, and it recovers the
MEMS ring's gamma within 5 %."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.environ.get("CVG_BENCH_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")
TRUE_GAMMA = 43.029  # config/resonators/mems_ring.yaml


def run(*args):
    p = subprocess.run([TOOL] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True)
    if p.returncode != 0:
        raise AssertionError("cvg_ident %s: %s" % (" ".join(args), p.stderr))


class OfflineRawBag(unittest.TestCase):
    def test_raw_bag_uses_the_node_settings(self):
        sys.path.insert(0, os.path.join(ROOT, "test", "integration"))
        from demod_bag_loop import write_raw_bag
        with tempfile.TemporaryDirectory() as tmp:
            path = lambda name: os.path.join(tmp, name)  # noqa: E731
            run("simulate", "--preset", "mems_ring", "--mode", "free_decay", "--raw",
                "--duration", "0.1", "--seed", "11", "--out", path("raw.csv"))
            write_raw_bag(path("raw.csv"), path("raw.bag"))
            common = ["--mode", "free_decay", "--model", "linear", "--json"]
            run("identify", path("raw.bag"), *common, path("bag.json"))
            run("demod", path("raw.csv"), "--rate", "2000", "--out", path("slow.csv"))
            run("identify", path("slow.csv"), *common, path("live.json"))
            bag, live = (json.load(open(path(n))) for n in ("bag.json", "live.json"))
        self.assertEqual(bag["n_equations"], live["n_equations"])
        self.assertGreater(bag["n_equations"], 4 * 150)  # ~200 slow states of 0.1 s at 2 kHz
        for name, p in live["parameters"].items():
            # Same filter and rate; the two paths align the first output sample differently, so the
            # estimates agree to within one standard error, not bit for bit.
            self.assertAlmostEqual(bag["parameters"][name]["value"], p["value"], delta=p["std"],
                                   msg=name)
        self.assertAlmostEqual(bag["parameters"]["gamma"]["value"], TRUE_GAMMA,
                               delta=0.05 * TRUE_GAMMA)


if __name__ == "__main__":
    unittest.main()
