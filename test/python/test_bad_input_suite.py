"""Table-driven bad-input suite of the offline tool (interfaces.md: exit 2 = bad usage or input,
with a message naming file, line and field; exit 1 = the analysis ran but the data cannot answer).

Every case runs bin/cvg_ident (or $CVG_IDENT_TOOL, e.g. a sanitizer build) on a small record with
one defect and asserts one of:
  "bad"     exit 2, the message names the file (and the line and column or field where given);
  "refuse"  exit 1 or 2 with a reason: the data cannot carry the answer;
  "ok"      exit 0 and the result equals the clean record's (the defect is harmless or repaired).
No case may end by a signal or print a sanitizer report. Base records come from `cvg_ident
simulate` (mems_ring preset, fixed seeds) so the expected results are known.
"""
import json
import math
import os
import shutil
import subprocess
import tempfile
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT",
                                      os.path.join(os.path.dirname(__file__), "..", "..")))
# The built binary directly (bin/cvg_ident sources the ROS environment: 4x the start-up cost).
_BUILT = os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench", "cvg_ident")
TOOL = os.environ.get("CVG_IDENT_TOOL",
                      _BUILT if os.path.exists(_BUILT) else os.path.join(ROOT, "bin", "cvg_ident"))
BAG = os.path.join(ROOT, "test", "data", "mems_free_decay_slow.bag")
# Columns the analyses read (the simulator also writes extra columns, e.g. "stationary", kept as
# they are and never used in a fit).
USED = ("t", "omega0", "q1", "p1", "q2", "p2", "f", "g")
SANITIZER_MARKS = ("runtime error:", "AddressSanitizer", "LeakSanitizer", "UndefinedBehavior",
                   "internal error")


def tool_works():
    try:
        return subprocess.run([TOOL, "--help"], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL, timeout=60).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def run_tool(args, timeout=60):
    p = subprocess.run([TOOL] + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


class Csv:
    """A CSV record as meta lines, header and rows of cell strings; line numbers are 1-based."""

    def __init__(self, path):
        self.meta, self.header, self.rows = [], None, []
        with open(path) as f:
            for line in f:
                line = line.rstrip("\n")
                if not line.strip():
                    continue
                if line.startswith("#"):
                    self.meta.append(line)
                elif self.header is None:
                    self.header = line.split(",")
                else:
                    self.rows.append(line.split(","))

    def copy(self):
        c = Csv.__new__(Csv)
        c.meta, c.header, c.rows = list(self.meta), list(self.header), [list(r) for r in self.rows]
        return c

    def line_of_row(self, k):
        return len(self.meta) + 2 + k

    def text(self, sep=",", eol="\n"):
        lines = self.meta + [sep.join(self.header)] + [sep.join(r) for r in self.rows]
        return eol.join(lines) + eol


@unittest.skipUnless(tool_works(), "cvg_ident not built")
class BadInputSuite(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = tempfile.mkdtemp(prefix="cvg_bad_input_")
        w = cls.work
        cls.slow_path = os.path.join(w, "slow.csv")
        cls.sweep_path = os.path.join(w, "sweep.csv")
        cls.raw_path = os.path.join(w, "raw.csv")
        for args in (["--mode", "free_decay", "--seed", "3", "--out", cls.slow_path],
                     ["--mode", "forced", "--seed", "4", "--out", cls.sweep_path],
                     ["--mode", "free_decay", "--raw", "--seed", "5", "--duration", "0.03",
                      "--out", cls.raw_path]):
            rc, _, err = run_tool(["simulate", "--preset", "mems_ring"] + args)
            assert rc == 0, err
        cls.slow, cls.sweep, cls.raw = Csv(cls.slow_path), Csv(cls.sweep_path), Csv(cls.raw_path)
        cls.base = {}
        for name, path, mode in (("slow", cls.slow_path, "free_decay"),
                                 ("sweep", cls.sweep_path, "forced")):
            js = os.path.join(w, name + ".json")
            rc, _, err = run_tool(["identify", path, "--mode", mode, "--model", "linear",
                                   "--json", js])
            assert rc == 0, err
            with open(js) as f:
                cls.base[name] = json.load(f)
        cls.base_json_path = os.path.join(w, "slow.json")
        cls.counter = 0
        cls.outcomes = {}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.work, ignore_errors=True)
        # The per-class tally printed for the note (crash / silent / wrong exit must all be 0).
        print("\nbad-input suite outcomes: " + ", ".join(
            "%s=%d" % kv for kv in sorted(cls.outcomes.items())))

    # ---- helpers --------------------------------------------------------------------------------
    def write(self, text, suffix=".csv", binary=False):
        type(self).counter += 1
        path = os.path.join(self.work, "case%04d%s" % (self.counter, suffix))
        with open(path, "wb" if binary else "w") as f:
            f.write(text)
        return path

    def out(self, suffix=".json"):
        type(self).counter += 1
        return os.path.join(self.work, "out%04d%s" % (self.counter, suffix))

    def check(self, label, args, expect, names=(), result_check=None):
        """Runs one case; expect is "bad", "refuse" or "ok"; names must all appear in stderr."""
        with self.subTest(case=label):
            rc, out, err = run_tool(args)
            crashed = rc < 0 or rc > 2 or any(m in err for m in SANITIZER_MARKS)
            cls = type(self)
            self.assertFalse(crashed, "%s: crash (exit %d)\n%s" % (label, rc, err[-2000:]))
            if expect == "bad":
                cls.outcomes["bad_exit2"] = cls.outcomes.get("bad_exit2", 0) + 1
                self.assertEqual(rc, 2, "%s: expected exit 2, got %d\n%s%s" % (label, rc, out, err))
            elif expect == "refuse":
                cls.outcomes["refused"] = cls.outcomes.get("refused", 0) + 1
                self.assertIn(rc, (1, 2), "%s: expected a refusal, got exit %d\n%s" % (label, rc, out))
                self.assertTrue(err.strip(), label + ": refusal without a reason")
            else:
                cls.outcomes["ok_correct"] = cls.outcomes.get("ok_correct", 0) + 1
                self.assertEqual(rc, 0, "%s: expected exit 0\n%s" % (label, err))
                if result_check:
                    result_check(label)
            for n in names:
                self.assertIn(str(n), err, "%s: message does not name %r:\n%s" % (label, n, err))

    def same_estimate(self, json_path, base, rel=1e-9):
        def check(label):
            with open(json_path) as f:
                got = json.load(f)
            for name, p in base["parameters"].items():
                b, g = p["value"], got["parameters"][name]["value"]
                self.assertLessEqual(abs(g - b), rel * max(1.0, abs(b)), "%s: %s %g vs %g" %
                                     (label, name, g, b))
        return check

    # ---- non-finite, huge and outlying values in every column -----------------------------------
    def test_values_in_every_column(self):
        bad_values = ["nan", "inf", "1e300", "-1e300", "1e31", "-"]
        cases = [("slow", self.slow, ["--mode", "free_decay"]),
                 ("sweep", self.sweep, ["--mode", "forced"])]
        for kind, base, mode in cases:
            k = len(base.rows) // 2
            for col, name in enumerate(base.header):
                if name not in USED:
                    continue
                for v in bad_values:
                    c = base.copy()
                    c.rows[k][col] = v
                    path = self.write(c.text())
                    self.check("%s %s=%s" % (kind, name, v),
                               ["identify", path, "--model", "linear"] + mode, "bad",
                               names=(path, c.line_of_row(k), name))
        # Outlier relative to the record (finite, below the absolute bound): states only.
        for kind, base, mode in cases:
            k = len(base.rows) // 3
            for col, name in enumerate(base.header):
                if name in ("t", "omega0") or name not in USED:
                    continue
                c = base.copy()
                c.rows[k][col] = "3e12"
                path = self.write(c.text())
                self.check("%s %s outlier" % (kind, name),
                           ["identify", path, "--model", "linear"] + mode, "bad",
                           names=(path, c.line_of_row(k), name))

    def test_methods_and_commands_on_1e300(self):
        for kind, base, mode in (("slow", self.slow, "free_decay"), ("sweep", self.sweep, "forced")):
            k = 7
            for col, name in enumerate(base.header):
                if name not in USED:
                    continue
                c = base.copy()
                c.rows[k][col] = "1e300"
                path = self.write(c.text())
                line = c.line_of_row(k)
                for cmd in (["identify", "--method", "rls", "--model", "linear"],
                            ["identify", "--method", "ceres", "--model", "xi"],
                            ["explain"]):
                    if kind == "sweep" and "rls" in cmd:
                        continue
                    self.check("%s %s=1e300 %s" % (kind, name, " ".join(cmd)),
                               [cmd[0], path, "--mode", mode] + cmd[1:], "bad",
                               names=(path, line, name))

    def test_raw_values(self):
        k = len(self.raw.rows) // 2
        for col, name in enumerate(self.raw.header):
            for v in ["nan", "inf", "1e300", "1e31", "x1"]:
                c = self.raw.copy()
                c.rows[k][col] = v
                path = self.write(c.text())
                self.check("raw %s=%s demod" % (name, v), ["demod", path, "--out", self.out(".csv")],
                           "bad", names=(path, c.line_of_row(k), name))
            c = self.raw.copy()
            c.rows[k][col] = "1e300"
            path = self.write(c.text())
            for extra in (["--method", "ls"], ["--method", "rls"], ["--method", "ceres"]):
                self.check("raw %s=1e300 identify %s" % (name, extra[1]),
                           ["identify", path, "--mode", "free_decay", "--model", "linear"] + extra,
                           "bad", names=(path, c.line_of_row(k), name))
            self.check("raw %s=1e300 explain" % name,
                       ["explain", path, "--mode", "free_decay"], "bad",
                       names=(path, c.line_of_row(k), name))

    # ---- structure of the file ------------------------------------------------------------------
    def test_structure(self):
        s = self.slow
        idf = ["--mode", "free_decay", "--model", "linear"]
        meta = "\n".join(s.meta) + "\n"
        header = ",".join(s.header) + "\n"
        row = ",".join(s.rows[0]) + "\n"
        cases = [
            ("empty file", "", "bad", ()),
            ("blank lines only", "\n\n  \n", "bad", ()),
            ("comments only", meta, "bad", ()),
            ("header only", meta + header, "bad", ()),
            ("one row", meta + header + row, "refuse", ()),
            ("three rows", meta + header + "".join(",".join(r) + "\n" for r in s.rows[:3]),
             "refuse", ()),
            ("wrong columns", meta + "t,x,y,z\n1,2,3,4\n", "bad", ("header",)),
            ("missing column", meta + "t,q1,p1,q2\n0,1,2,3\n", "bad", ("header",)),
            ("empty column name", meta + "t,q1,,q2,p2\n0,1,2,3,4\n", "bad", ("empty column name",)),
            ("duplicate column", meta + "t,q1,q1,q2,p2\n0,1,2,3,4\n", "bad", ("twice",)),
            ("tab separated", meta + s.text(sep="\t")[len(meta):], "bad", ("not a number",)),
            ("binary junk", "\x00\x01\x02garbage\xff\n", "bad", ()),
        ]
        for label, text, expect, names in cases:
            path = self.write(text)
            # A refusal names the reason (the regression's own "more data needed" has no file).
            self.check(label, ["identify", path] + idf, expect,
                       names=((path,) if expect == "bad" else ()) + names)
        # Row-level defects at a known line.
        k = 10
        for label, mutate, names in [
                ("extra field", lambda c: c.rows[k].append("1"), ("fields",)),
                ("missing field", lambda c: c.rows[k].pop(), ("fields",)),
                ("text in number", lambda c: c.rows[k].__setitem__(1, "abc"), ("q1", "not a number")),
                ("two dots", lambda c: c.rows[k].__setitem__(2, "1.2.3"), ("p1",)),
                ("hex number", lambda c: c.rows[k].__setitem__(3, "0x10"), ("q2",)),
                ("comma decimal", lambda c: c.rows[k].__setitem__(4, "1,5"), ("fields",)),
                ("empty cell", lambda c: c.rows[k].__setitem__(1, ""), ("empty cell",)),
                ("duplicated stamp", lambda c: c.rows[k].__setitem__(0, c.rows[k - 1][0]),
                 ("repeats",)),
                ("decreasing stamp", lambda c: c.rows[k].__setitem__(0, "-1"), ("before",)),
                ("jumping last stamp", lambda c: c.rows[-1].__setitem__(0, "5000"), ("jumps",)),
                ("stamp 1e300 at the end", lambda c: c.rows[-1].__setitem__(0, "1e300"),
                 ("out of range",)),
        ]:
            c = s.copy()
            mutate(c)
            path = self.write(c.text())
            line = c.line_of_row(len(c.rows) - 1 if "last" in label or "end" in label else k)
            self.check(label, ["identify", path] + idf, "bad", names=(path, line) + names)
        # Metadata lines.
        for v in ["1e300", "-5", "0", "abc", "nan", "inf", "1e11", ""]:
            c = s.copy()
            c.meta = ["# omega: " + v] + [m for m in c.meta if not m.startswith("# omega")]
            path = self.write(c.text())
            self.check("# omega: %s" % v, ["identify", path] + idf, "bad",
                       names=(path + ":1", "omega", "rad/s"))

    def test_harmless_variants_give_the_clean_answer(self):
        idf = ["--mode", "free_decay", "--model", "linear"]
        s = self.slow
        variants = [
            ("semicolon separated", s.text(sep=";")),
            ("CRLF line ends", s.text(eol="\r\n")),
            ("blank lines and spaces", "\n".join(s.meta) + "\n\n" + ", ".join(s.header) + "\n" +
             "\n".join(" " + ", ".join(r) + " " for r in s.rows) + "\n\n"),
            ("comment after header", s.text().replace("\n" + ",".join(s.rows[5]),
                                                      "\n# a note\n" + ",".join(s.rows[5]), 1)),
            ("leading plus signs", s.copy().text().replace(",0.", ",+0.")),
        ]
        perm = s.copy()
        order = [0, 3, 1, 4, 2]
        perm.header = [s.header[i] for i in order] + ["temperature"]
        perm.rows = [[r[i] for i in order] + ["21.5"] for r in s.rows]
        variants.append(("permuted columns and an extra column", perm.text()))
        for label, text in variants:
            path = self.write(text)
            js = self.out()
            self.check(label, ["identify", path, "--json", js] + idf, "ok",
                       result_check=self.same_estimate(js, self.base["slow"]))
        # Forced: ';' separated and permuted rows (a sweep's order does not matter to (3.4)).
        sw = self.sweep.copy()
        sw.rows = sw.rows[::-1]
        for label, text in (("sweep semicolons", self.sweep.text(sep=";")),
                            ("sweep reversed", sw.text())):
            path = self.write(text)
            js = self.out()
            self.check(label, ["identify", path, "--mode", "forced", "--model", "linear",
                               "--json", js], "ok",
                       result_check=self.same_estimate(js, self.base["sweep"], rel=1e-7))

    def test_raw_timestamps(self):
        r = self.raw
        ref = self.out(".csv")
        rc, _, err = run_tool(["demod", self.raw_path, "--rate", "2000", "--out", ref])
        self.assertEqual(rc, 0, err)
        with open(ref) as f:
            ref_rows = [l for l in f if l[:1].isdigit() or l[:1] == "-"]

        def same_demod(out_path):
            def check(label):
                with open(out_path) as f:
                    rows = [l for l in f if l[:1].isdigit() or l[:1] == "-"]
                self.assertEqual(rows, ref_rows, label + ": demodulated output differs")
            return check
        k = len(r.rows) // 2
        swapped = r.copy()
        swapped.rows[k], swapped.rows[k + 1] = swapped.rows[k + 1], swapped.rows[k]
        dup = r.copy()
        dup.rows.insert(k, list(dup.rows[k]))
        for label, c in (("raw swapped rows (repaired)", swapped),
                         ("raw duplicated row (dropped)", dup)):
            path = self.write(c.text())
            o = self.out(".csv")
            self.check(label, ["demod", path, "--rate", "2000", "--out", o], "ok",
                       result_check=same_demod(o))
        jump = r.copy()
        jump.rows[-1][0] = "1e4"
        path = self.write(jump.text())
        self.check("raw clock jump", ["demod", path, "--out", self.out(".csv")], "bad",
                   names=(path, jump.line_of_row(len(jump.rows) - 1), "jumps"))
        few = r.copy()
        few.rows = few.rows[:2]
        path = self.write(few.text())
        self.check("raw two rows", ["identify", path, "--mode", "free_decay", "--model", "linear"],
                   "refuse")

    # ---- files and outputs ----------------------------------------------------------------------
    def test_files_and_outputs(self):
        d = os.path.join(self.work, "a_dir")
        os.makedirs(d, exist_ok=True)
        missing = os.path.join(self.work, "no_such_file.csv")
        nodir = os.path.join(self.work, "no_such_dir", "x.json")
        cases = [
            ("input is a directory", ["identify", d, "--mode", "free_decay", "--model", "linear"],
             (d, "directory")),
            ("input missing", ["identify", missing, "--mode", "free_decay", "--model", "linear"],
             (missing,)),
            ("explain input missing", ["explain", missing, "--mode", "free_decay"], (missing,)),
            ("demod input directory", ["demod", d, "--out", self.out(".csv")], (d,)),
            ("params directory", ["drift", "--params", d], (d, "directory")),
            ("params missing", ["drift", "--params", missing], (missing,)),
            ("config directory", ["simulate", "--config", d, "--mode", "free_decay", "--out",
                                  self.out(".csv")], (d, "directory")),
            ("config missing", ["simulate", "--config", missing, "--mode", "free_decay", "--out",
                                self.out(".csv")], (missing,)),
            ("identify --json into missing dir",
             ["identify", self.slow_path, "--mode", "free_decay", "--model", "linear",
              "--json", nodir], (nodir,)),
            ("identify --json is a directory",
             ["identify", self.slow_path, "--mode", "free_decay", "--model", "linear",
              "--json", d], (d,)),
            ("identify --json /proc", ["identify", self.slow_path, "--mode", "free_decay",
                                       "--model", "linear", "--json", "/proc/version"],
             ("/proc/version",)),
            ("identify --json /dev/full", ["identify", self.slow_path, "--mode", "free_decay",
                                           "--model", "linear", "--json", "/dev/full"],
             ("/dev/full",)),
            ("simulate --out directory", ["simulate", "--preset", "mems_ring", "--mode",
                                          "free_decay", "--out", d], (d,)),
            ("simulate --out missing dir", ["simulate", "--preset", "mems_ring", "--mode",
                                            "free_decay", "--out", nodir], (nodir,)),
            ("simulate --out /dev/full", ["simulate", "--preset", "mems_ring", "--mode",
                                          "free_decay", "--out", "/dev/full"], ("/dev/full",)),
            ("demod --out directory", ["demod", self.raw_path, "--out", d], (d,)),
            ("drift --json missing dir", ["drift", "--params", self.base_json_path, "--json",
                                          nodir], (nodir,)),
            ("explain --json directory", ["explain", self.slow_path, "--mode", "free_decay",
                                          "--json", d], (d,)),
            ("explain --report is a file", ["explain", self.slow_path, "--mode", "free_decay",
                                            "--report", self.slow_path, "--no-figures"],
             (self.slow_path,)),
        ]
        for label, args, names in cases:
            self.check(label, args, "bad", names=names)

    def test_bags(self):
        with open(BAG, "rb") as f:
            data = f.read()
        cases = [
            ("truncated bag (half)", data[: len(data) // 2]),
            ("truncated bag (header only)", data[:200]),
            ("empty bag", b""),
            ("csv named .bag", self.slow.text().encode()),
            ("random bytes bag", bytes(range(256)) * 8),
        ]
        for label, blob in cases:
            path = self.write(blob, suffix=".bag", binary=True)
            self.check(label, ["identify", path, "--mode", "free_decay", "--model", "linear"],
                       "bad", names=(path,))
        # Stored lengths rosbag would trust (it allocated 2.3e9 bytes for the fuzz input): the
        # bag's structure is walked first, the message names the byte offset.
        starts, pos = [], 13
        while pos + 4 <= len(data):
            starts.append(pos)
            hlen = int.from_bytes(data[pos:pos + 4], "little")
            pos += 4 + hlen
            pos += 4 + int.from_bytes(data[pos:pos + 4], "little")
        self.assertEqual(pos, len(data))
        big = (0x70000000).to_bytes(4, "little")
        corrupt = [("fuzz: record length 2e9 (regression)",
                    os.path.join(ROOT, "test", "fuzz", "regressions", "bag", "record_length_2e9.bag")),
                   ("fuzz: version line '#ROSB#ROSBAAG V2.0' (regression)",
                    os.path.join(ROOT, "test", "fuzz", "regressions", "bag",
                                 "version_line_rosb_rosbaag.bag")),
                   ("fuzz: connection header field length beyond its record (regression)",
                    os.path.join(ROOT, "test", "fuzz", "regressions", "bag",
                                 "connection_header_field_length.bag")),
                   ("fuzz: index offset outside its chunk (regression)",
                    os.path.join(ROOT, "test", "fuzz", "regressions", "bag",
                                 "index_offset_outside_chunk.bag")),
                   ("fuzz: index offset outside its chunk, second find (regression)",
                    os.path.join(ROOT, "test", "fuzz", "regressions", "bag",
                                 "index_offset_outside_chunk_2.bag")),
                   ("version line with a 200-character word", self.write(
                       b"#ROS" + b"A" * 200 + b" V2.0\n" + data[13:], ".bag", binary=True)),
                   ("first record length 1.9e9", self.write(data[:13] + big + data[17:], ".bag",
                                                            binary=True)),
                   ("index record length 1.9e9", self.write(
                       data[:starts[-1]] + big + data[starts[-1] + 4:], ".bag", binary=True))]
        for label, path in corrupt:
            rc, _, err = run_tool(["identify", path, "--mode", "free_decay", "--model", "linear"])
            self.check(label, ["identify", path, "--mode", "free_decay", "--model", "linear"],
                       "bad", names=(path,))
            self.assertTrue("no rosbag support" in err or "byte" in err or "format 2.0" in err,
                            label + ": " + err)
        # A compressed bag (rosbag record --lz4): refused with the way out, not read unchecked.
        try:
            import rosbag
        except ImportError:
            rosbag = None
        if rosbag is not None:
            lz4 = self.write(b"", ".bag", binary=True)
            with rosbag.Bag(BAG) as src, rosbag.Bag(lz4, "w", compression="lz4") as dst:
                for topic, msg, t in src.read_messages(raw=True):
                    dst.write(topic, msg, t, raw=True)
            rc, _, err = run_tool(["identify", lz4, "--mode", "free_decay", "--model", "linear"])
            if "no rosbag support" not in err:
                self.check("lz4-compressed bag", ["identify", lz4, "--mode", "free_decay",
                                                  "--model", "linear"], "bad",
                           names=(lz4, "compressed", "rosbag decompress"))
        self.check("bag with --mode forced", ["identify", BAG, "--mode", "forced", "--model",
                                              "linear"], "bad", names=(BAG,))
        rc, _, err = run_tool(["identify", BAG, "--mode", "free_decay", "--model", "linear"])
        bag_support = "no rosbag support" not in err
        self.check("bag unknown topic", ["identify", BAG, "--mode", "free_decay", "--model",
                                         "linear", "--topic", "/nope"], "bad",
                   names=("/nope",) if bag_support else (BAG,))
        self.check("bag as raw demod input", ["demod", BAG, "--out", self.out(".csv")], "bad",
                   names=(BAG,))
        self.check("--topic on a csv", ["identify", self.slow_path, "--mode", "free_decay",
                                        "--model", "linear", "--topic", "/x"], "bad")
        rc, _, err = run_tool(["identify", BAG, "--mode", "free_decay", "--model", "linear"])
        if "no rosbag support" in err:  # a core-only build (make test-asan): exit 2 is right
            self.assertEqual(rc, 2)
            return
        js = self.out()
        self.check("valid bag", ["identify", BAG, "--mode", "free_decay", "--model", "linear",
                                 "--json", js], "ok")

    def test_fuzz_findings(self):
        """Inputs the fuzzers crashed the readers with (test/fuzz/regressions/): now exit 2."""
        reg = os.path.join(ROOT, "test", "fuzz", "regressions")
        # A sweep's jump flag 7.8e27: integral, but no int (UB in the conversion).
        csv = os.path.join(reg, "csv", "flag_column_7e27.csv")
        self.check("fuzz: direction flag 7.8e27 (regression)",
                   ["identify", csv, "--mode", "forced", "--model", "linear"], "bad",
                   names=(csv + ":3:7", "jump"))
        # A YAML map used as a key (`? nu: ...`): yaml-cpp threw through the key conversion.
        yml = os.path.join(reg, "preset", "map_as_key.yaml")
        self.check("fuzz: preset with a map as a key (regression)",
                   ["simulate", "--config", yml, "--mode", "free_decay", "--out",
                    self.out(".csv")], "bad", names=(yml, "not text"))

    # ---- one-mode frequency response (--mode response) -----------------------------------------
    def test_response_mode(self):
        clean = os.path.join(self.work, "response.csv")
        rc, _, err = run_tool(["simulate", "--mode", "response", "--q", "50", "--levels", "2",
                               "--points", "20", "--seed", "7", "--out", clean])
        self.assertEqual(rc, 0, err)
        with open(clean) as f:
            lines = f.read().splitlines()
        body = [l for l in lines if not l.startswith("#")]
        ident = ["identify", "--mode", "response"]

        def variant(row, field, value):
            rows = list(body)
            cells = rows[row].split(",")
            cells[field] = value
            rows[row] = ",".join(cells)
            return self.write("\n".join(rows) + "\n")

        self.check("response: clean", ident[:1] + [clean] + ident[1:], "ok")
        for v in ["nan", "inf", "-", "1e400"]:
            p = variant(5, 2, v)
            self.check("response: x = " + v, ["identify", p, "--mode", "response"], "bad",
                       names=(p + ":6", "field 3 (x)"))
        p = variant(5, 4, "0")
        self.check("response: drive 0", ["identify", p, "--mode", "response"], "bad",
                   names=(p + ":6", "drive"))
        p = variant(5, 1, "-3")
        self.check("response: negative frequency", ["identify", p, "--mode", "response"], "bad",
                   names=(p + ":6", "frequency_hz"))
        p = variant(5, 0, "0")
        self.check("response: time back", ["identify", p, "--mode", "response"], "bad",
                   names=(p + ":6", "time must increase"))
        p = self.write(body[0] + "\n")
        self.check("response: header only", ["identify", p, "--mode", "response"], "bad",
                   names=("at least 8",))
        p = self.write("")
        self.check("response: empty", ["identify", p, "--mode", "response"], "bad")
        p = self.write("\n".join(body[1:]) + "\n")
        self.check("response: headerless with --columns", ["identify", p, "--mode", "response",
                   "--columns", "t=1,frequency_hz=2,x=3,y=4,drive=5"], "ok")
        for cols, name in (("t=1,x=3,y=4", "frequency_hz"), ("frequency_hz=0,x=3,y=4", "from 1"),
                           ("frequency_hz=2,x=3,y=4,z=5", "unknown key"),
                           ("frequency_hz=2,frequency_hz=3,x=3,y=4", "twice"),
                           ("frequency_hz=9,x=3,y=4", "no field 9")):
            self.check("response: --columns " + cols, ["identify", p, "--mode", "response",
                       "--columns", cols], "bad", names=(name,))
        for opt, val, name in (("--response", "speed", "response"), ("--model", "xi_diff", "two modes"),
                               ("--model", "mu", "two modes"), ("--confidence", "2", "confidence")):
            self.check("response: %s %s" % (opt, val), ["identify", clean, "--mode", "response",
                       opt, val], "bad", names=(name,))
        noise = self.write("t,frequency_hz,x,y,drive\n" + "".join(
            "%d,%g,%g,%g,1\n" % (i, 100 + 0.1 * i, math.sin(7.3 * i), math.cos(3.1 * i ** 1.5))
            for i in range(60)))
        self.check("response: no resonance (noise only)", ["identify", noise, "--mode",
                   "response"], "refuse", names=("no resonance",))
        self.check("response: no resonance (noise only), explain", ["explain", noise, "--mode",
                   "response"], "refuse", names=("no resonance",))
        for args, name in ((["--levels", "0"], "levels"), (["--points", "3"], "points"),
                           (["--q", "-1"], "q"), (["--effect", "kappa=1"], "kappa"),
                           (["--correlation", "1"], "correlation"),
                           (["--effect", "gamma_nl=-100"], "diverged")):
            self.check("response simulate " + " ".join(args), ["simulate", "--mode", "response",
                       "--out", self.out(".csv")] + args, "bad" if name != "diverged" else "refuse",
                       names=(name,))

    # ---- options --------------------------------------------------------------------------------
    def test_absurd_options(self):
        slow = ["identify", self.slow_path, "--mode", "free_decay", "--model", "linear"]
        sweep = ["identify", self.sweep_path, "--mode", "forced", "--model", "linear"]
        cases = []
        for v in ["nan", "-1", "1e300", "1e11", "abc"]:
            cases.append(("identify --omega " + v, slow + ["--omega", v], ("omega",)))
            cases.append(("sweep --omega " + v, sweep + ["--omega", v], ("omega",)))
            cases.append(("demod --omega " + v, ["demod", self.raw_path, "--omega", v, "--out",
                                                 self.out(".csv")], ("omega",)))
            cases.append(("explain --omega " + v, ["explain", self.slow_path, "--mode",
                                                   "free_decay", "--omega", v], ("omega",)))
        for v in ["0", "1", "1.5", "-0.1", "nan"]:
            cases.append(("--confidence " + v, slow + ["--confidence", v], ("confidence",)))
        for v in ["0", "-1", "nan"]:
            cases.append(("--angular-gain " + v, slow + ["--angular-gain", v], ("gain",)))
        for v in ["-1", "0", "abc"]:
            cases.append(("demod --rate " + v, ["demod", self.raw_path, "--rate", v, "--out",
                                                self.out(".csv")], ("rate",)))
        cases += [
            ("--method foo", slow[:-2] + ["--model", "linear", "--method", "foo"], ("method",)),
            ("--mode foo", ["identify", self.slow_path, "--mode", "foo", "--model", "linear"],
             ("mode",)),
            ("no --mode", ["identify", self.slow_path, "--model", "linear"], ("mode",)),
            ("no --model", ["identify", self.slow_path, "--mode", "free_decay"], ("model",)),
            ("same input twice", slow + [self.slow_path], ("twice",)),
            ("unknown option", slow + ["--frobnicate", "1"], ("frobnicate",)),
            ("option without value", slow + ["--json"], ("json",)),
            ("option twice", slow + ["--omega", "85732", "--omega", "85732"], ("twice",)),
            ("drift --theta-grid 0", ["drift", "--params", self.base_json_path, "--theta-grid",
                                      "0"], ("theta-grid",)),
            ("drift --theta-grid abc", ["drift", "--params", self.base_json_path, "--theta-grid",
                                        "abc"], ("theta-grid",)),
            ("drift --r nan", ["drift", "--params", self.base_json_path, "--r", "nan"], ("--r",)),
            ("drift theta and grid", ["drift", "--params", self.base_json_path, "--theta", "0",
                                      "--theta-grid", "4"], ("theta",)),
            ("simulate --seed -1", ["simulate", "--preset", "mems_ring", "--mode", "free_decay",
                                    "--seed", "-1", "--out", self.out(".csv")], ("seed",)),
            ("simulate --duration 0", ["simulate", "--preset", "mems_ring", "--mode",
                                       "free_decay", "--duration", "0", "--out",
                                       self.out(".csv")], ("duration",)),
            ("simulate --noise -1", ["simulate", "--preset", "mems_ring", "--mode",
                                     "free_decay", "--noise", "-1", "--out", self.out(".csv")],
             ("noise",)),
            ("simulate --preset nope", ["simulate", "--preset", "nope", "--mode", "free_decay",
                                        "--out", self.out(".csv")], ("nope",)),
            ("unknown subcommand", ["frobnicate"], ("frobnicate",)),
            ("whole_angle --amplitude 0", ["simulate", "--preset", "quartz_cylinder", "--mode",
                                           "whole_angle", "--amplitude", "0", "--out",
                                           self.out(".csv")], ("r0",)),
            ("whole_angle --quadrature 1", ["simulate", "--preset", "quartz_cylinder", "--mode",
                                            "whole_angle", "--quadrature", "1", "--out",
                                            self.out(".csv")], ("k0",)),
            ("whole_angle --walk nan", ["simulate", "--preset", "quartz_cylinder", "--mode",
                                        "whole_angle", "--walk", "nan", "--out",
                                        self.out(".csv")], ("walk",)),
            ("--amplitude in free decay", ["simulate", "--preset", "quartz_cylinder", "--mode",
                                           "free_decay", "--amplitude", "0.5", "--out",
                                           self.out(".csv")], ("amplitude",)),
            ("drift --measured sweep", ["drift", "--params", self.base_json_path, "--measured",
                                        self.sweep_path], ("whole-angle",)),
            ("drift --measured no walk", ["drift", "--params", self.base_json_path, "--measured",
                                          self.slow_path], ("3/4",)),
            ("drift --bins 2", ["drift", "--params", self.base_json_path, "--measured",
                                self.slow_path, "--bins", "2"], ("bins",)),
            ("drift --bins 1e12", ["drift", "--params", self.base_json_path, "--measured",
                                   self.slow_path, "--bins", "1000000000000"], ("bins",)),
        ]
        for label, args, names in cases:
            self.check(label, args, "bad", names=names)

    def test_model_names(self):
        slow = ["identify", self.slow_path, "--mode", "free_decay", "--model"]
        sweep = ["identify", self.sweep_path, "--mode", "forced", "--model"]
        for m in ["xi+", "+xi", "xi++kappa", "", " ", "+", "foo", "xi+foo", "xi+xi", "linear+",
                  "XI", "xi,kappa", "mu", "xi+mu", "controls"]:
            names = ("forced",) if m in ("mu", "xi+mu", "controls") else (
                ("model",) if m.strip() else ())
            self.check("free decay --model %r" % m, slow + [m], "bad", names=names)
        for m in ["xi+", "cm_rate", "mu", "xi+mu", "linear+mu"]:
            # mu needs --method ceres (exit 2 with LS); cm_rate is free decay only.
            self.check("forced --model %r (ls)" % m, sweep + [m], "bad")

    def test_free_decay_without_omega(self):
        """A slow record without '# omega:' (and no --omega) is refused by identify and explain:
        their model could not be used downstream (issue #25); with --omega it runs."""
        with open(self.slow_path) as f:
            text = "".join(line for line in f if "omega" not in line)
        path = self.write(text)
        for cmd in (["identify", path, "--mode", "free_decay", "--model", "linear"],
                    ["explain", path, "--mode", "free_decay"]):
            self.check(cmd[0] + " without omega", cmd, "bad", names=(path, "--omega"))
        with open(self.slow_path) as f:
            omega = next(line.split(":")[1].strip() for line in f if line.startswith("# omega:"))
        self.check("identify with --omega", ["identify", path, "--mode", "free_decay", "--model", "linear",
                                             "--omega", omega], "ok")

    def test_mu_models_run_under_ceres(self):
        for m in ["mu", "xi+mu"]:
            js = self.out()
            self.check("forced --model %s --method ceres" % m,
                       ["identify", self.sweep_path, "--mode", "forced", "--model", m,
                        "--method", "ceres", "--json", js], "ok")

    def test_mode_mismatch(self):
        cases = [
            ("sweep as free decay", ["identify", self.sweep_path, "--mode", "free_decay",
                                     "--model", "linear"]),
            ("slow as forced", ["identify", self.slow_path, "--mode", "forced", "--model",
                                "linear"]),
            ("raw as forced", ["identify", self.raw_path, "--mode", "forced", "--model",
                               "linear"]),
            ("slow into demod", ["demod", self.slow_path, "--out", self.out(".csv")]),
            ("explain sweep as free decay", ["explain", self.sweep_path, "--mode",
                                             "free_decay"]),
            ("explain slow as forced", ["explain", self.slow_path, "--mode", "forced"]),
        ]
        for label, args in cases:
            self.check(label, args, "bad", names=(args[1],))

    # ---- output paths ---------------------------------------------------------------------------
    def test_writes_only_where_told(self):
        """Run from an empty working directory: only the named outputs appear, nothing else."""
        cwd = os.path.join(self.work, "cwd")
        os.makedirs(cwd, exist_ok=True)
        outs = os.path.join(self.work, "outs")
        os.makedirs(outs, exist_ok=True)
        runs = [["identify", self.slow_path, "--mode", "free_decay", "--model", "linear",
                 "--json", os.path.join(outs, "i.json")],
                ["explain", self.slow_path, "--mode", "free_decay", "--json",
                 os.path.join(outs, "e.json"), "--report", os.path.join(outs, "rep"),
                 "--no-figures"],
                ["drift", "--params", self.base_json_path, "--json", os.path.join(outs, "d.json")],
                ["demod", self.raw_path, "--rate", "2000", "--out", os.path.join(outs, "s.csv")],
                ["simulate", "--preset", "mems_ring", "--mode", "free_decay", "--seed", "7",
                 "--duration", "0.5", "--out", os.path.join(outs, "sim.csv")]]
        for args in runs:
            p = subprocess.run([TOOL] + args, cwd=cwd, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, universal_newlines=True, timeout=120)
            self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(os.listdir(cwd), [])
        self.assertEqual(sorted(os.listdir(outs)),
                         ["d.json", "e.json", "i.json", "rep", "s.csv", "sim.csv"])
        self.assertTrue(set(os.listdir(os.path.join(outs, "rep"))) <=
                        {"explain.json", "curves.csv", "residuals.csv", "signature.csv",
                         "report.md"})

    def test_nodes_write_no_files(self):
        """The nodes take no output path (none in a service request, parameter or topic): their
        sources open no file for writing, and no service field names a path, file or directory."""
        writers = ("ofstream", "fopen", "FILE *", "FILE*", "bagmode::Write", "bagmode::Append",
                   "std::filesystem", "mkdir", "rename(", "unlink(", "creat(", "O_CREAT",
                   "writeJsonFile", "writeRecordCsv", "writeReport")
        files = [os.path.join(d, f) for d in ("src/ros", "src/nodes", "include/cvg_bench/ros")
                 for f in sorted(os.listdir(os.path.join(ROOT, d)))]
        self.assertGreater(len(files), 10)
        for path in files:
            with open(os.path.join(ROOT, path)) as f:
                text = f.read()
            for w in writers:
                self.assertNotIn(w, text, "%s writes files (%s)" % (path, w))
        srv_dir = os.path.join(ROOT, "srv")
        for name in sorted(os.listdir(srv_dir)):
            with open(os.path.join(srv_dir, name)) as f:
                request = f.read().split("---")[0]
            for line in request.splitlines():
                field = line.split("#")[0].split()
                if len(field) == 2:
                    self.assertFalse(any(k in field[1].lower() for k in ("path", "file", "dir")),
                                     "%s: request field %s names a location" % (name, field[1]))

    # ---- drift --params JSON --------------------------------------------------------------------
    def test_params_json(self):
        with open(self.base_json_path) as f:
            base = json.load(f)
        self.assertIn("covariance", base)

        def variant(fn):
            j = json.loads(json.dumps(base))
            fn(j)
            return json.dumps(j)
        names = base["covariance"]["names"]

        def set_cov(r, c, v):
            return lambda j: j["covariance"]["matrix"][r].__setitem__(c, v)
        def not_psd(j):
            # Every pair within the Cauchy-Schwarz bound, the three together not a covariance
            # (correlations 0.9, 0.9, -0.9: eigenvalue -0.8).
            m = j["covariance"]["matrix"]
            d = [m[i][i] for i in range(3)]
            for a, b, rho in ((0, 1, 0.9), (0, 2, 0.9), (1, 2, -0.9)):
                m[a][b] = m[b][a] = rho * (d[a] * d[b]) ** 0.5
        cases = [
            ("not json", "{", ()),
            ("covariance not positive semi-definite", variant(not_psd), ("semi-definite",)),
            ("empty", "", ()),
            ("array", "[1, 2]", ("parameters",)),
            ("NaN literal", json.dumps(base).replace(str(base["omega"]), "NaN", 1), ()),
            ("no omega", variant(lambda j: j.pop("omega")), ("omega",)),
            ("omega string", variant(lambda j: j.__setitem__("omega", "85732")), ("omega",)),
            ("omega negative", variant(lambda j: j.__setitem__("omega", -1.0)), ("omega",)),
            ("omega 1e300", variant(lambda j: j.__setitem__("omega", 1e300)), ("omega",)),
            ("parameters array", variant(lambda j: j.__setitem__("parameters", [1])),
             ("parameters",)),
            ("parameter string", variant(lambda j: j["parameters"].__setitem__("gamma", "x")),
             ("gamma",)),
            ("parameter value null",
             variant(lambda j: j["parameters"]["gamma"].__setitem__("value", None)), ("gamma",)),
            ("negative variance", variant(set_cov(0, 0, -1.0)), ("variance", names[0])),
            ("string in covariance", variant(set_cov(0, 1, "0.1")), ("covariance",)),
            ("null in covariance", variant(set_cov(1, 0, None)), ("covariance",)),
            ("asymmetric covariance", variant(set_cov(0, 1, 1e3)), ("covariance",)),
            ("correlation above 1", variant(lambda j: (set_cov(0, 1, 1e6)(j), set_cov(1, 0, 1e6)(j))),
             ("covariance",)),
            ("unknown covariance name",
             variant(lambda j: j["covariance"]["names"].__setitem__(0, "bogus")), ("bogus",)),
            ("covariance name a number",
             variant(lambda j: j["covariance"]["names"].__setitem__(0, 3)), ("names",)),
            ("covariance names missing", variant(lambda j: j["covariance"].pop("names")),
             ("names",)),
            ("covariance matrix short",
             variant(lambda j: j["covariance"]["matrix"].pop()), ("matrix",)),
            ("covariance row short",
             variant(lambda j: j["covariance"]["matrix"][0].pop()), ("matrix",)),
            ("covariance a string", variant(lambda j: j.__setitem__("covariance", "x")),
             ("covariance",)),
            ("negative interval_dof", variant(lambda j: j.__setitem__("interval_dof", -3)),
             ("interval_dof",)),
            ("fractional interval_dof", variant(lambda j: j.__setitem__("interval_dof", 2.5)),
             ("interval_dof",)),
            ("string dof", variant(lambda j: j.__setitem__("dof", "x")), ("dof",)),
            ("confidence 2", variant(lambda j: j.__setitem__("confidence", 2)), ("confidence",)),
            ("confidence string", variant(lambda j: j.__setitem__("confidence", "a")),
             ("confidence",)),
        ]
        for label, text, nm in cases:
            path = self.write(text, suffix=".json")
            self.check("params: " + label, ["drift", "--params", path], "bad", names=(path,) + nm)
        # The unmodified file and a flat file give the same drift as each other.
        outs = []
        flat = {"omega": base["omega"],
                "parameters": {k: v["value"] for k, v in base["parameters"].items()}}
        for label, text in (("params: valid identify json", json.dumps(base)),
                            ("params: valid flat json", json.dumps(flat))):
            path = self.write(text, suffix=".json")
            js = self.out()
            self.check(label, ["drift", "--params", path, "--theta", "0.3", "--json", js], "ok")
            with open(js) as f:
                outs.append(json.load(f)["drift"][0]["drift_rad_s"])
        self.assertAlmostEqual(outs[0], outs[1], delta=1e-12 * max(1.0, abs(outs[0])))


if __name__ == "__main__":
    unittest.main()
