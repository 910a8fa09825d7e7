"""`cvg_ident batch` (docs/fleet.md): one JSON per record from the same pipeline as `identify`,
results independent of --jobs and of sharding (GNU parallel, a Slurm array's variables), merge,
resume after a kill, failed records listed, bad usage refused, and the fleet report."""
import csv
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import unittest

ROOT = os.environ.get("CVG_BENCH_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")
QPIT = os.path.join(ROOT, "..", "shared", "data", "ringdowns_qpit_dev")

# Simulated ring-downs: two samples, three repeats each (true Q 2e5 and 5e5), one unreadable record.
SAMPLES = [("S1", 2.0e5, 11), ("S1", 2.0e5, 12), ("S1", 2.0e5, 13),
           ("S2", 5.0e5, 21), ("S2", 5.0e5, 22), ("S2", 5.0e5, 23)]


def run(args, env=None, check=None):
    p = subprocess.run([TOOL] + args, capture_output=True, text=True, env=env, timeout=600)
    if check is not None and p.returncode != check:
        raise AssertionError("%s -> %d\n%s\n%s" % (args, p.returncode, p.stdout, p.stderr))
    return p


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


class Batch(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="cvg_batch_")
        d = os.path.join(cls.tmp, "records")
        os.makedirs(d)
        rows = []
        for i, (sample, q, seed) in enumerate(SAMPLES):
            name = "rd%d.csv" % (i + 1)
            run(["simulate", "--mode", "ringdown", "--q", str(q), "--frequency", "20000", "--seed", str(seed),
                 "--out", os.path.join(d, name)], check=0)
            rows.append(["records/" + name, sample, q])
        with open(os.path.join(d, "broken.csv"), "w") as f:
            f.write("t,amplitude\n0,1\n0.1,oops\n")
        rows.append(["records/broken.csv", "S3", ""])
        cls.manifest = os.path.join(cls.tmp, "manifest.csv")
        with open(cls.manifest, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["path", "sample_id", "true_q"])
            w.writerows(rows)
        cls.serial = os.path.join(cls.tmp, "serial")
        cls.serial_run = run(["batch", cls.manifest, "--mode", "ringdown", "--jobs", "1", "--out", cls.serial])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def out(self, name):
        return os.path.join(self.tmp, name)

    def test_results_listed_with_failures_and_true_q(self):
        self.assertEqual(self.serial_run.returncode, 0, self.serial_run.stderr)
        rows = read_csv(os.path.join(self.serial, "fleet.csv"))
        self.assertEqual([r["record"] for r in rows], ["rd%d" % i for i in range(1, 7)] + ["broken"])
        broken = rows[-1]
        self.assertEqual(broken["exit_status"], "2")
        self.assertEqual(broken["verdict"], "failed")
        self.assertIn("broken.csv", broken["message"])
        for r in rows[:-1]:
            self.assertEqual(r["exit_status"], "0")
            q, lo, hi, true_q = (float(r[k]) for k in ("Q", "Q_ci_low", "Q_ci_high", "true_q"))
            self.assertLess(lo, q)
            self.assertLess(q, hi)
            # A clean simulated decay: the estimate within 3 % of the truth (its interval is ~1 %).
            self.assertLess(abs(q / true_q - 1), 0.03, r)
            self.assertEqual(r["sample_id"], "S1" if true_q == 2e5 else "S2")

    def test_same_pipeline_as_identify(self):
        run(["identify", os.path.join(self.tmp, "records", "rd2.csv"), "--mode", "ringdown",
             "--json", self.out("rd2_single.json")], check=0)
        with open(self.out("rd2_single.json")) as a, open(os.path.join(self.serial, "records", "rd2.json")) as b:
            self.assertEqual(a.read(), b.read())

    def test_jobs_do_not_change_results(self):
        par = self.out("parallel_jobs")
        run(["batch", self.manifest, "--mode", "ringdown", "--jobs", "3", "--out", par, "--no-plots"], check=0)
        for name in ["fleet.csv", "fleet.json"] + ["records/rd%d.json" % i for i in range(1, 7)]:
            with open(os.path.join(self.serial, name)) as a, open(os.path.join(par, name)) as b:
                self.assertEqual(a.read(), b.read(), name)

    def test_gnu_parallel_shards_merged_equal_one_run(self):
        if shutil.which("parallel") is None:
            self.skipTest("GNU parallel not installed (scripts/install_deps.sh installs it)")
        sh = self.out("shards")
        p = subprocess.run(["parallel", "--halt", "never", TOOL, "batch", self.manifest, "--mode", "ringdown",
                            "--shard", "{}/3", "--out", sh, "--no-plots", ":::", "0", "1", "2"],
                           capture_output=True, text=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stderr)
        shard0 = read_csv(os.path.join(sh, "fleet_shard_0_of_3.csv"))
        self.assertEqual([r["record"] for r in shard0], ["rd1", "rd4", "broken"])
        self.assertFalse(os.path.exists(os.path.join(sh, "fleet.csv")))
        merged = self.out("merged")
        run(["batch", "--merge", sh, "--out", merged, "--no-plots"], check=0)
        for name in ["fleet.csv", "fleet.json"]:
            with open(os.path.join(self.serial, name)) as a, open(os.path.join(merged, name)) as b:
                self.assertEqual(a.read(), b.read(), name)

    def test_slurm_array_variables_choose_the_shard(self):
        outs = []
        for task in ("1", "2"):
            env = dict(os.environ, SLURM_ARRAY_TASK_ID=task, SLURM_ARRAY_TASK_MIN="1", SLURM_ARRAY_TASK_COUNT="2")
            o = self.out("slurm_%s" % task)
            p = run(["batch", self.manifest, "--mode", "ringdown", "--out", o, "--no-plots"], env=env, check=0)
            self.assertIn("Slurm job array", p.stderr)
            outs.append(o)
        self.assertEqual([r["record"] for r in read_csv(os.path.join(outs[1], "fleet_shard_1_of_2.csv"))],
                         ["rd2", "rd4", "rd6"])
        merged = self.out("slurm_merged")
        run(["batch", "--merge", outs[0], "--merge", outs[1], "--out", merged, "--no-plots"], check=0)
        with open(os.path.join(self.serial, "fleet.csv")) as a, open(os.path.join(merged, "fleet.csv")) as b:
            self.assertEqual(a.read(), b.read())
        # One shard alone: the merge says what is missing and exits 1.
        alone = self.out("slurm_alone")
        p = run(["batch", "--merge", outs[0], "--out", alone, "--no-plots"])
        self.assertEqual(p.returncode, 1)
        with open(os.path.join(alone, "fleet.json")) as f:
            self.assertEqual(json.load(f)["missing_indices"], [1, 3, 5])

    def test_rerun_skips_done_records_and_redoes_changed_ones(self):
        o = self.out("resume")
        shutil.copytree(self.serial, o)
        p = run(["batch", self.manifest, "--mode", "ringdown", "--out", o, "--no-plots"], check=0)
        self.assertIn("ran 0, skipped 7", p.stderr)
        # Same settings but a changed record: only that one runs again.
        rec_dir = self.out("resume_records")
        shutil.copytree(os.path.join(self.tmp, "records"), rec_dir)
        man = self.out("resume_manifest.csv")
        with open(self.manifest) as f, open(man, "w") as g:
            g.write(f.read().replace("records/", "resume_records/"))
        run(["batch", man, "--mode", "ringdown", "--out", o, "--no-plots"], check=0)
        with open(os.path.join(rec_dir, "rd3.csv"), "a") as f:
            f.write("# an appended comment changes the content\n")
        p = run(["batch", man, "--mode", "ringdown", "--out", o, "--no-plots"], check=0)
        self.assertIn("ran 1, skipped 6", p.stderr)
        # Other settings: every record runs again.
        p = run(["batch", man, "--mode", "ringdown", "--confidence", "0.9", "--out", o, "--no-plots"], check=0)
        self.assertIn("ran 7, skipped 0", p.stderr)

    def test_corrupt_status_files_are_rerun_not_trusted(self):
        o = self.out("corrupt")
        shutil.copytree(self.serial, o)
        st = os.path.join(o, "records", "rd2.status.json")
        with open(st) as f:
            s = json.load(f)
        s["exit_status"] = "0"  # hand-edited: a string
        with open(st, "w") as f:
            json.dump(s, f)
        with open(os.path.join(o, "records", "rd3.status.json"), "w") as f:
            f.write('{"record": "rd3", "compl')  # truncated
        s4 = os.path.join(o, "records", "rd4.status.json")
        with open(s4) as f:
            s = json.load(f)
        s["record"] = "../../escape"
        with open(s4, "w") as f:
            json.dump(s, f)
        p = run(["batch", self.manifest, "--mode", "ringdown", "--out", o, "--no-plots"], check=0)
        self.assertIn("ran 3, skipped 4", p.stderr)
        with open(os.path.join(self.serial, "fleet.csv")) as a, open(os.path.join(o, "fleet.csv")) as b:
            self.assertEqual(a.read(), b.read())

    def test_killed_batch_resumes_to_the_same_table(self):
        o = self.out("killed")
        proc = subprocess.Popen([TOOL, "batch", self.manifest, "--mode", "ringdown", "--jobs", "1",
                                 "--out", o, "--no-plots"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        status_dir = os.path.join(o, "records")
        deadline = time.time() + 120
        while time.time() < deadline:
            done = [f for f in os.listdir(status_dir)] if os.path.isdir(status_dir) else []
            if sum(f.endswith(".status.json") for f in done) >= 2:
                break
            time.sleep(0.01)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        time.sleep(0.3)  # the running child dies with the batch (PR_SET_PDEATHSIG)
        done_before = sum(f.endswith(".status.json") for f in os.listdir(status_dir))
        self.assertGreaterEqual(done_before, 2)
        self.assertLess(done_before, 7, "killed too late to test a resume")
        p = run(["batch", self.manifest, "--mode", "ringdown", "--jobs", "2", "--out", o, "--no-plots"], check=0)
        self.assertIn("skipped %d" % done_before, p.stderr)
        with open(os.path.join(self.serial, "fleet.csv")) as a, open(os.path.join(o, "fleet.csv")) as b:
            self.assertEqual(a.read(), b.read())

    def test_fleet_report_groups_repeats(self):
        with open(os.path.join(self.serial, "fleet_groups.json")) as f:
            g = json.load(f)
        self.assertEqual(g["group_by"], ["sample_id"])
        by = {x["group"]["sample_id"]: x for x in g["groups"]}
        self.assertEqual(by["S1"]["n"], 3)
        self.assertEqual(by["S1"]["pairs"], 3)
        # Repeats are independent draws of one resonator: scatter of a few tenths of a per cent, and
        # the records' intervals account for it (RMS z near 1, not several).
        self.assertLess(by["S1"]["Q_relative_scatter"], 0.03)
        self.assertLess(by["S2"]["z_rms"], 3.0)
        self.assertEqual(by["S3"]["n_with_q"], 0)
        for png in ("fleet_q_hist.png", "fleet_q_vs_frequency.png", "fleet_repeat_scatter.png"):
            self.assertGreater(os.path.getsize(os.path.join(self.serial, png)), 5000, png)
        with open(os.path.join(self.serial, "fleet.md")) as f:
            md = f.read()
        self.assertIn("1 failed", md)
        self.assertIn("broken", md)

    def test_bad_usage_exits_2_with_the_reason(self):
        cases = [
            (["batch", self.manifest, "--mode", "ringdown", "--shard", "3/3", "--out", self.out("x")], "--shard"),
            (["batch", self.manifest, "--mode", "ringdown"], "--out"),
            (["batch", self.manifest, "--mode", "ringdown", "--json", "a.json", "--out", self.out("x")], "--json"),
            (["batch", self.manifest, "--mode", "sideways", "--out", self.out("x")], "sideways"),
            (["batch", self.manifest, "--mode", "ringdown", "--jobs", "0", "--out", self.out("x")], "--jobs"),
            (["batch", "--merge", self.tmp + "/nowhere", "--out", self.out("x")], "records/"),
        ]
        bad = self.out("bad_manifest.csv")
        with open(bad, "w") as f:
            f.write("path,sample_id\nrecords/rd1.csv,S1\nrecords/rd2.csv\n")
        cases.append((["batch", bad, "--mode", "ringdown", "--out", self.out("x")], "bad_manifest.csv:3"))
        for args, needle in cases:
            with self.subTest(args=args):
                p = run(args)
                self.assertEqual(p.returncode, 2, p.stderr)
                self.assertIn(needle, p.stderr)


class BatchExplainTwoMode(unittest.TestCase):
    def test_explain_rows_carry_the_selected_model_and_reports(self):
        tmp = tempfile.mkdtemp(prefix="cvg_batch_explain_")
        try:
            files = []
            for seed, effect in ((5, []), (6, ["--effect", "xi=0.05"])):
                p = os.path.join(tmp, "fd%d.csv" % seed)
                run(["simulate", "--preset", "quartz_cylinder", "--mode", "free_decay", "--seed", str(seed),
                     "--out", p] + effect, check=0)
                files.append(p)
            o = os.path.join(tmp, "o")
            run(["batch"] + files + ["--mode", "free_decay", "--explain", "--reports", "--no-figures",
                                     "--jobs", "2", "--out", o], check=0)
            rows = read_csv(os.path.join(o, "fleet.csv"))
            self.assertEqual([r["record"] for r in rows], ["fd5", "fd6"])
            for r in rows:
                with open(os.path.join(o, "records", r["json"])) as f:
                    x = json.load(f)
                self.assertEqual(r["verdict"], "unexplained" if x["unexplained"] else "explained")
                self.assertEqual(r["model"], "+".join(["linear"] + x["selected"]))
                self.assertAlmostEqual(float(r["Q"]), x["final"]["derived_ci"]["Q"]["value"],
                                       delta=1e-8 * float(r["Q"]))
                self.assertAlmostEqual(float(r["frequency_hz"]), x["final"]["omega"] / (2 * 3.141592653589793),
                                       delta=1e-6)
                self.assertTrue(os.path.isdir(os.path.join(o, "records", r["record"] + "_report")))
            # The hidden cubic stiffness of fd6 is found (as by a single explain call).
            self.assertIn("xi", rows[1]["model"].split("+"))
            # Drift harmonics per record, the same as `drift` of the record's JSON at r = 1, k = 0:
            # harmonics of its theta grid by least squares.
            import numpy as np
            for r in rows:
                dj = os.path.join(tmp, r["record"] + "_drift.json")
                run(["drift", "--params", os.path.join(o, "records", r["json"]), "--r", "1", "--k", "0",
                     "--theta-grid", "36", "--json", dj], check=0)
                with open(dj) as f:
                    grid = json.load(f)["drift"]
                th = np.array([g["theta_rad"] for g in grid])
                th = np.remainder(th + np.pi / 4, np.pi / 2) - np.pi / 4
                y = np.array([g["drift_deg_h"] for g in grid])
                a = np.column_stack([np.ones_like(th), np.cos(4 * th), np.sin(4 * th), np.cos(8 * th), np.sin(8 * th)])
                c = np.linalg.lstsq(a, y, rcond=None)[0]
                self.assertAlmostEqual(float(r["drift_c0_deg_h"]), c[0], delta=1e-6 * abs(c[0]) + 1e-6)
                self.assertAlmostEqual(float(r["drift_4theta_deg_h"]), np.hypot(c[1], c[2]),
                                       delta=1e-6 * np.hypot(c[1], c[2]) + 1e-6)
                self.assertLess(float(r["drift_4theta_deg_h_ci_low"]), float(r["drift_4theta_deg_h"]))
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


@unittest.skipUnless(os.path.isdir(QPIT), "real ring-downs absent (../shared/data/ringdowns_qpit_dev)")
class BatchOnRealRingdowns(unittest.TestCase):
    def test_a_repeat_group_equals_single_calls(self):
        tmp = tempfile.mkdtemp(prefix="cvg_batch_real_")
        try:
            with open(os.path.join(QPIT, "labels.csv"), newline="") as f:
                labels = list(csv.DictReader(f))[:3]  # D001-D003: one sample and mode, three repeats
            man = os.path.join(tmp, "m.csv")
            with open(man, "w", newline="") as f:
                w = csv.writer(f)
                w.writerow(["path", "sample_id", "mode_id", "frequency_hz", "authors_q"])
                for r in labels:
                    w.writerow([os.path.join(QPIT, "records", r["id"] + ".txt"), r["sample_id"], r["mode_id"],
                                r["frequency_hz"], r["authors_q"]])
            run(["batch", man, "--mode", "ringdown", "--jobs", "2", "--out", os.path.join(tmp, "o")], check=0)
            rows = read_csv(os.path.join(tmp, "o", "fleet.csv"))
            for r in rows:
                single = os.path.join(tmp, r["record"] + ".json")
                run(["identify", r["input"], "--mode", "ringdown", "--frequency", r["frequency_hz"],
                     "--json", single], check=0)
                with open(single) as a:
                    self.assertAlmostEqual(json.load(a)["derived_ci"]["Q"]["value"], float(r["Q"]),
                                           delta=1e-8 * float(r["Q"]))
                # These three are clean decays: within 10 % of the authors' Q.
                self.assertLess(abs(float(r["Q"]) / float(r["authors_q"]) - 1), 0.10, r["record"])
            with open(os.path.join(tmp, "o", "fleet_groups.json")) as f:
                g = json.load(f)["groups"]
            self.assertEqual(len(g), 1)
            self.assertEqual(g[0]["n_with_q"], 3)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    unittest.main()
