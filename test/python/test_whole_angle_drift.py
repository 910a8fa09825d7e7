"""The identify -> predict chain closed (issue #26): a simulated whole-angle run (loops hold r and
k, the pattern is walked over 1.5 periods) measured by `drift --measured` against (a) the true
parameters and (b) the parameters identified from a free decay of the same resonator. Measured and
predicted must agree within their intervals, and compensating with the prediction must remove most
of the drift (the gain of identification at the gyro's output)."""
import json
import os
import subprocess
import tempfile
import unittest

ROOT = os.environ.get("CVG_BENCH_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")


def run(args, ok=(0,)):
    p = subprocess.run([TOOL] + args, capture_output=True, text=True, timeout=600)
    if p.returncode not in ok:
        raise AssertionError("%s -> %d\n%s" % (args, p.returncode, p.stderr))
    return p


class WholeAngleDrift(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        d = cls.tmp.name
        cls.wa = os.path.join(d, "wa.csv")
        run(["simulate", "--preset", "quartz_cylinder", "--mode", "whole_angle",
             "--seed", "3", "--out", cls.wa])
        truth, omega = {}, None
        with open(cls.wa) as f:
            for line in f:
                if line.startswith("# truth_") and not line.startswith("# truth_model"):
                    k, v = line[len("# truth_"):].split(":")
                    truth[k.strip()] = float(v)
                if line.startswith("# omega:"):
                    omega = float(line.split(":")[1])
        cls.truth = os.path.join(d, "truth.json")
        with open(cls.truth, "w") as f:
            json.dump({"omega": omega, "parameters": truth}, f)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def measured(self, params, name):
        out = os.path.join(self.tmp.name, name)
        run(["drift", "--params", params, "--measured", self.wa, "--json", out])
        with open(out) as f:
            return json.load(f)

    def test_contract_names_and_truth_agree(self):
        j = self.measured(self.truth, "truth_drift.json")
        for key in ("theta_deg", "measured_deg_h", "measured_ci", "predicted_deg_h", "predicted_ci"):
            self.assertEqual(len(j[key]), 24, key)
        inside = total = 0
        for m, ci, p in zip(j["measured_deg_h"], j["measured_ci"], j["predicted_deg_h"]):
            if m is None:
                continue
            total += 1
            inside += ci[0] <= p <= ci[1]
        self.assertGreaterEqual(total, 20)
        # The truth's prediction inside the measured 95 % interval in most bins.
        self.assertGreaterEqual(inside, int(0.8 * total), (inside, total))
        # The drift varies with theta (the 4 theta harmonic of the damping anisotropy) and the
        # truth removes nearly all of it.
        self.assertGreater(j["harmonics"]["measured"]["amp4_deg_h"], 10.0)
        self.assertGreater(j["compensation_gain"], 20.0)

    def test_identified_model_compensates_the_drift(self):
        fd = os.path.join(self.tmp.name, "fd.csv")
        est = os.path.join(self.tmp.name, "est.json")
        run(["simulate", "--preset", "quartz_cylinder", "--mode", "free_decay", "--seed", "5", "--out", fd])
        run(["identify", fd, "--mode", "free_decay", "--model", "xi", "--json", est], ok=(0, 1))
        j = self.measured(est, "est_drift.json")
        png = os.path.join(self.tmp.name, "drift.png")
        run(["drift", "--params", est, "--measured", self.wa, "--png", png])
        self.assertGreater(os.path.getsize(png), 10000)
        # Identification from a free decay predicts the whole-angle drift: most of it is removed.
        self.assertGreater(j["compensation_gain"], 3.0, j["rms_difference_deg_h"])
        self.assertLess(j["residual_after_compensation_deg_h"], j["rms_measured_deg_h"] / 3.0)

    def test_decays_at_several_pattern_angles_compensate_tenfold(self):
        # One decay bounds the damping anisotropy's two axes loosely (the gain above is 3-8x);
        # eight decays started at r = 0.5 and pattern angles over 90 deg, stacked in one identify,
        # bound them well enough for the 10x.
        files = []
        for k in range(8):
            f = os.path.join(self.tmp.name, "fd%d.csv" % k)
            run(["simulate", "--preset", "quartz_cylinder", "--mode", "free_decay", "--seed",
                 str(50 + k), "--start", "0.5,0,%r" % (k * 3.141592653589793 / 16), "--out", f])
            files.append(f)
        est = os.path.join(self.tmp.name, "stacked.json")
        run(["identify"] + files + ["--mode", "free_decay", "--model", "xi", "--json", est], ok=(0, 1))
        with open(est) as f:
            self.assertTrue(any("8 records stacked into one regression" in n for n in json.load(f)["notes"]))
        j = self.measured(est, "stacked_drift.json")
        self.assertGreater(j["compensation_gain"], 10.0, j["rms_difference_deg_h"])
        p = run(["identify", files[0], files[1], "--mode", "forced", "--model", "xi"], ok=(2,))
        self.assertIn("several: free decays only", p.stderr)
        p = run(["identify", files[0], files[1], "--mode", "free_decay", "--model", "xi",
                 "--method", "ceres"], ok=(2,))
        self.assertIn("one trajectory", p.stderr)

    def test_a_run_that_does_not_cover_the_period_is_refused(self):
        short = os.path.join(self.tmp.name, "short.csv")
        run(["simulate", "--preset", "quartz_cylinder", "--mode", "whole_angle", "--walk", "1e-5",
             "--out", short])
        p = run(["drift", "--params", self.truth, "--measured", short], ok=(2,))
        self.assertIn("under 3/4 of its period", p.stderr)

    def test_a_garbled_walk_header_is_an_input_error(self):
        # The header was read by an unchecked strtod before 29 Nov: garbage gave a walk of 0.
        bad = os.path.join(self.tmp.name, "bad_walk.csv")
        with open(self.wa) as f, open(bad, "w") as g:
            n = 0
            for line in f:
                if line.startswith("# whole_angle_walk_rad_s"):
                    line, n = "# whole_angle_walk_rad_s: fast\n", n + 1
                g.write(line)
        self.assertEqual(n, 1)
        p = run(["drift", "--params", self.truth, "--measured", bad], ok=(2,))
        self.assertIn("whole_angle_walk_rad_s", p.stderr)
        self.assertIn("'fast'", p.stderr)
        # --walk overrides the header (the documented way out).
        run(["drift", "--params", self.truth, "--measured", bad, "--walk", "2e-3"])


if __name__ == "__main__":
    unittest.main()
