"""The NumPy reference of the forced batch benchmark (scripts/bench_numpy_identify.py) computes the
same identification as `cvg_ident identify --mode forced --model xi+kappa`: on a 300-point sweep the
estimates agree to 1e-9 and the per-point sandwich standard errors to 1e-9 (relative), so the
speed ratio in docs/benchmarks.md compares equal work, and the tool's forced regression and
covariance are checked against an independent implementation."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

ROOT = os.environ.get("CVG_BENCH_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import bench_numpy_identify  # noqa: E402

NAMES = ["gamma", "nu", "b_c", "b_s", "c_m", "n", "h_c", "h_s", "u1", "u2", "u3", "u4", "xi",
         "kappa"]


class NumpyReference(unittest.TestCase):
    def test_forced_batch_matches_the_tool(self):
        tool = os.path.join(ROOT, "bin", "cvg_ident")
        built = os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench", "cvg_ident")
        if not os.path.exists(built):
            self.skipTest("cvg_ident not built (make build)")
        rng = np.random.default_rng(5)
        n, omega = 300, 85732.0
        omega0 = omega - 80.0 + 160.0 * np.arange(n) / n
        q = rng.uniform(-1.0, 1.0, (n, 4))
        z, cov = bench_numpy_identify.identify_forced(omega, omega0, q)
        work = tempfile.mkdtemp(prefix="cvg_numpy_ref_")
        sweep, out = os.path.join(work, "sweep.csv"), os.path.join(work, "est.json")
        with open(sweep, "w") as f:
            f.write("# omega: %r\n# mode: forced\nomega0,q1,p1,q2,p2\n" % omega)
            for j in range(n):
                f.write("%.17g,%.17g,%.17g,%.17g,%.17g\n" % (omega0[j], *q[j]))
        proc = subprocess.run([tool, "identify", sweep, "--mode", "forced", "--model", "xi+kappa",
                               "--json", out], capture_output=True, text=True)
        self.assertEqual(proc.returncode, 0, proc.stderr)
        with open(out) as f:
            est = json.load(f)
        self.assertEqual(sorted(est["parameters"]), sorted(NAMES))
        for i, name in enumerate(NAMES):
            p = est["parameters"][name]
            self.assertAlmostEqual(p["value"], z[i], delta=1e-9 * max(1.0, abs(z[i])), msg=name)
            se = np.sqrt(cov[i, i])
            self.assertAlmostEqual(p["std"], se, delta=1e-9 * se, msg=name)


if __name__ == "__main__":
    unittest.main()
