"""The ring-down contract of interfaces.md ("Single-channel ring-downs") through bin/cvg_ident:
simulate -> identify / explain --mode ringdown, the JSON fields, exit statuses 1 (no decay) and 2
(bad input, with file and line). Skipped when the tool is not built."""
import json
import os
import subprocess
import tempfile
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT",
                                      os.path.join(os.path.dirname(__file__), "..", "..")))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")


def run(*args):
    return subprocess.run([TOOL] + list(args), capture_output=True, text=True)


@unittest.skipUnless(os.path.exists(os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench",
                                                 "cvg_ident")), "tool not built")
class RingdownCli(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp()

    def path(self, name):
        return os.path.join(self.tmp, name)

    def test_identify_db_record_gives_q_with_interval_and_segment(self):
        rec, js = self.path("rd.csv"), self.path("q.json")
        self.assertEqual(run("simulate", "--mode", "ringdown", "--q", "2e5", "--frequency", "1e4",
                             "--scale", "db", "--db-offset", "-30", "--dropouts", "3", "--seed",
                             "4", "--out", rec).returncode, 0)
        p = run("identify", rec, "--mode", "ringdown", "--model", "linear", "--json", js)
        self.assertEqual(p.returncode, 0, p.stderr)
        j = json.load(open(js))
        self.assertEqual(j["mode"], "ringdown")
        self.assertAlmostEqual(j["frequency_hz"], 1e4)
        for k in ("t_start", "t_end", "why"):
            self.assertIn(k, j["segment"])
        self.assertIn("drive off", j["segment"]["why"])
        q = j["derived_ci"]["Q"]
        half = q["ci_high"] - q["ci_low"]
        self.assertLess(abs(q["value"] - 2e5), max(2 * half, 0.005 * 2e5))
        self.assertIn("tau_s", j["derived_ci"])
        self.assertRegex(j["interval_method"], r"AR\(\d+\) noise model|white-noise")
        self.assertGreater(j["cramer_rao"]["Q"]["crb_std"], 0)

    def test_explain_finds_amplitude_squared_damping_and_q0(self):
        rec, js = self.path("nl.csv"), self.path("x.json")
        run("simulate", "--mode", "ringdown", "--effect", "gamma_nl=0.3", "--seed", "5", "--out", rec)
        p = run("explain", rec, "--mode", "ringdown", "--json", js)
        self.assertEqual(p.returncode, 0, p.stderr)
        j = json.load(open(js))
        self.assertEqual(j["selected"], ["gamma_nl"])
        self.assertFalse(j["unexplained"])
        self.assertIn("Q0", j["final"]["derived_ci"])
        q0 = j["final"]["derived_ci"]["Q0"]
        self.assertLess(q0["ci_low"], 1e5 * 1.02)
        self.assertGreater(q0["ci_high"], 1e5 * 0.98)

    def test_no_decay_exits_1_and_bad_field_exits_2(self):
        rec = self.path("flat.csv")
        run("simulate", "--mode", "ringdown", "--q", "1e12", "--duration-s", "10", "--out", rec)
        p = run("identify", rec, "--mode", "ringdown", "--model", "linear")
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        self.assertIn("no decay", p.stderr)
        bad = self.path("bad.csv")
        with open(bad, "w") as fh:
            fh.write("% Frequency [Hz]: 1000\ntime [s]; power [dBm]\n0; -10\n0.1; -11\n0.2; x\n")
        p = run("identify", bad, "--mode", "ringdown", "--model", "linear")
        self.assertEqual(p.returncode, 2)
        self.assertIn("bad.csv:5", p.stderr)

    def test_method_is_ceres_or_refused(self):
        # --method was accepted with --mode ringdown and ignored (issue #23): every ring-down fit
        # is weighted least squares on ln A by Ceres, so ceres/wls_log run and the same Q comes
        # out; ls or rls is an input error, not silently something else.
        rec, a, b = self.path("m.csv"), self.path("a.json"), self.path("b.json")
        run("simulate", "--mode", "ringdown", "--q", "2e5", "--frequency", "1e4", "--seed", "6",
            "--out", rec)
        self.assertEqual(run("identify", rec, "--mode", "ringdown", "--json", a).returncode, 0)
        p = run("identify", rec, "--mode", "ringdown", "--method", "ceres", "--json", b)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(json.load(open(a))["derived_ci"]["Q"]["value"],
                         json.load(open(b))["derived_ci"]["Q"]["value"])
        self.assertEqual(json.load(open(b))["method"], "wls_log")
        for cmd in ("identify", "explain"):
            p = run(cmd, rec, "--mode", "ringdown", "--method", "ls")
            self.assertEqual(p.returncode, 2, p.stdout + p.stderr)
            self.assertIn("--method ls", p.stderr)

    def test_explain_report_writes_figures_and_summary(self):
        rec, rep = self.path("rep.csv"), self.path("report")
        run("simulate", "--mode", "ringdown", "--effect", "gamma_nl=0.15", "--floor-db", "-60",
            "--dropouts", "3", "--seed", "12", "--out", rec)
        p = run("explain", rec, "--mode", "ringdown", "--report", rep)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertNotIn("figures were not made", p.stderr)
        for f in ("explain.json", "ringdown_envelope.csv", "ringdown_fit.csv",
                  "ringdown_q_vs_amplitude.csv", "envelope.png", "residuals.png",
                  "q_vs_amplitude.png", "report.md"):
            self.assertGreater(os.path.getsize(os.path.join(rep, f)), 100, f)
        with open(os.path.join(rep, "report.md")) as fh:
            md = fh.read()
        self.assertIn("gamma_nl", md)
        self.assertIn("![envelope](envelope.png)", md)


if __name__ == "__main__":
    unittest.main()
