"""One set of derived figures for every term (issues #25 item 5, #26 item 1): `drift` of an
identify or explain JSON reports the Q and section-4 figures the estimate reported, and its theta'
comes from the model's own averaged equations, so gamma_nl (absent from the printed (5.9)) moves
the envelope's decay and xi_diff the drift."""
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


class DriftConsistency(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.rec = os.path.join(cls.tmp.name, "gnl.csv")
        run(["simulate", "--preset", "quartz_cylinder", "--mode", "free_decay", "--seed", "4",
             "--effect", "gamma_nl=2", "--out", cls.rec])

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def path(self, name):
        return os.path.join(self.tmp.name, name)

    def test_a_rank_deficient_estimate_gives_no_drift(self):
        # identify exits 1 on a record that does not determine the model; its JSON is still
        # written, and drift of it is refused (exit 2, the null space named), never a Q or rate
        # from arbitrary values along the null space (issue #25).
        full = self.path("full.json")
        run(["identify", self.rec, "--mode", "free_decay", "--model", "linear", "--json", full])
        with open(full) as f:
            j = json.load(f)
        j["rank"] = j["n_params"] - 2
        j["unidentifiable"] = ["gamma", "b_c"]
        bad = self.path("rank_deficient.json")
        with open(bad, "w") as f:
            json.dump(j, f)
        p = run(["drift", "--params", bad], ok=(2,))
        self.assertIn("rank-deficient", p.stderr)
        self.assertIn("gamma, b_c", p.stderr)
        run(["drift", "--params", full, "--theta-grid", "4"])  # the full-rank one still works

    def test_drift_reports_the_estimates_q(self):
        run(["identify", self.rec, "--mode", "free_decay", "--model", "gamma_nl", "--json", self.path("id.json")],
            ok=(0, 1))
        run(["drift", "--params", self.path("id.json"), "--theta-grid", "4", "--json", self.path("dr.json")])
        with open(self.path("id.json")) as f:
            est = json.load(f)
        with open(self.path("dr.json")) as f:
            dr = json.load(f)
        for name, v in est["derived_ci"].items():
            self.assertAlmostEqual(dr["derived_ci"][name]["value"], v["value"], delta=1e-9 * abs(v["value"]) + 1e-15,
                                   msg=name)
        q = est["derived_ci"]["Q"]
        self.assertGreater(q["ci_low"], 0.0, "a Q interval reaching 0 is no Q")

    def test_drift_takes_explains_final_model(self):
        run(["explain", self.rec, "--mode", "free_decay", "--json", self.path("ex.json")])
        p = run(["drift", "--params", self.path("ex.json"), "--r", "0.5", "--k", "0.05", "--theta", "0.3",
                 "--json", self.path("drx.json")])
        with open(self.path("ex.json")) as f:
            ex = json.load(f)
        with open(self.path("drx.json")) as f:
            dr = json.load(f)
        self.assertAlmostEqual(dr["derived_ci"]["Q"]["value"], ex["final"]["derived_ci"]["Q"]["value"],
                               delta=1e-9 * ex["final"]["derived_ci"]["Q"]["value"])
        self.assertIn("gamma_nl", ex["selected"])
        self.assertIn("linear+gamma_nl", p.stdout)  # the envelope and drift name the model used

    def test_drift_of_an_explain_file_defaults_to_the_records_state(self):
        """Without --r/--k, drift of an explain JSON is evaluated at the record's median amplitude
        and quadrature over its measured windows (comparable with the measured rate); with them,
        at the state given."""
        run(["explain", self.rec, "--mode", "free_decay", "--json", self.path("ex2.json")])
        p = run(["drift", "--params", self.path("ex2.json"), "--theta-grid", "4",
                 "--json", self.path("drs.json")])
        with open(self.path("ex2.json")) as f:
            windows = json.load(f)["measured"]["windows"]
        with open(self.path("drs.json")) as f:
            dr = json.load(f)
        rs, ks = sorted(w["r"] for w in windows), sorted(w["k"] for w in windows)
        self.assertAlmostEqual(dr["r"], rs[len(rs) // 2], delta=1e-12 * rs[-1])
        self.assertAlmostEqual(dr["k"], ks[len(ks) // 2], delta=1e-12 * rs[-1])
        self.assertIn("the record's median amplitude", p.stdout)
        run(["drift", "--params", self.path("ex2.json"), "--r", "0.5", "--k", "0.05",
             "--theta-grid", "4", "--json", self.path("drg.json")])
        with open(self.path("drg.json")) as f:
            given = json.load(f)
        self.assertEqual((given["r"], given["k"]), (0.5, 0.05))

    def test_gamma_nl_moves_the_envelope_decay_with_amplitude(self):
        params = {"omega": 21991.0, "model": "linear+gamma_nl",
                  "parameters": {"gamma": 0.05, "nu": 0.0, "b_c": 0.0, "b_s": 0.0, "c_m": 0.0, "n": 0.0,
                                 "h_c": 0.0, "h_s": 0.0, "gamma_nl": 0.02}}
        pf = self.path("gnl_params.json")
        with open(pf, "w") as f:
            json.dump(params, f)
        rates = []
        for r in (0.5, 1.0):
            run(["drift", "--params", pf, "--r", str(r), "--k", "0", "--theta", "0", "--json", self.path("e.json")])
            with open(self.path("e.json")) as f:
                rates.append(json.load(f)["envelope"]["decay_rate_1_s"])
        # -2 r'/r = gamma + gamma_nl r^2 x (the term's averaging factor): grows with r^2, not flat.
        self.assertAlmostEqual(rates[0], 0.05 + 0.25 * (rates[1] - 0.05), delta=1e-9)
        self.assertGreater(rates[1], 0.05 + 1e-3)

    def test_xi_diff_moves_the_drift(self):
        base = {"omega": 21991.0, "parameters": {"gamma": 0.05, "nu": 0.001, "h_c": 0.002, "xi_diff": 0.0}}
        out = []
        for v in (0.0, 0.5):
            base["parameters"]["xi_diff"] = v
            pf = self.path("xd.json")
            with open(pf, "w") as f:
                json.dump(base, f)
            run(["drift", "--params", pf, "--r", "1", "--k", "0.2", "--theta", "0.3", "--json", self.path("x.json")])
            with open(self.path("x.json")) as f:
                out.append(json.load(f)["drift"][0]["drift_rad_s"])
        self.assertGreater(abs(out[1] - out[0]), 1e-3)


if __name__ == "__main__":
    unittest.main()
