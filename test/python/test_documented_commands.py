"""Every command line the documentation shows runs end to end: the `bin/cvg_ident ...` lines of
README.md's code blocks (in order, in one scratch folder, so later lines read what earlier ones
wrote; `../shared/` resolved from the repository, the line skipped when that data is absent) and the `example:` lines of every subcommand's --help text. Each must exit 0. Joint mu
estimation from the command line is checked against the simulator's truth (the interval of
`identify --model xi+mu --method ceres` must hold the true mu)."""
import json
import os
import re
import shlex
import subprocess
import tempfile
import unittest

ROOT = os.environ.get("CVG_BENCH_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.abspath(os.path.join(ROOT, "bin", "cvg_ident"))
BUILT = os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench", "cvg_ident")
SUBCOMMANDS = ("simulate", "demod", "identify", "drift", "explain")


def readme_commands():
    """`bin/cvg_ident` lines of README.md's fenced code blocks, trailing comments removed."""
    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
        text = f.read()
    lines = []
    for block in re.findall(r"```[a-z]*\n(.*?)```", text, re.S):
        for line in block.splitlines():
            line = line.split(" #", 1)[0].strip()
            if line.startswith("bin/cvg_ident "):
                lines.append(line[len("bin/cvg_ident "):])
    return lines


SHARED = os.path.abspath(os.path.join(ROOT, "..", "shared"))


def run(args, cwd, timeout=300):
    return subprocess.run([TOOL] + args, cwd=cwd, capture_output=True, text=True, timeout=timeout)


def help_examples():
    """`example: cvg_ident SUB ...` lines of every subcommand's --help."""
    found = []
    for sub in SUBCOMMANDS:
        out = run([sub, "--help"], ROOT)
        assert out.returncode == 0, (sub, out.stderr)
        for line in out.stdout.splitlines():
            m = re.match(r"\s*example:\s*cvg_ident (.*)$", line)
            if m:
                found.append((sub, m.group(1).strip()))
    return found


@unittest.skipUnless(os.path.exists(BUILT), "cvg_ident is not built (make build)")
class DocumentedCommands(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.work = cls.tmp.name

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def check(self, command):
        if "../shared/" in command:
            command = command.replace("../shared/", SHARED + "/")
            if not os.path.isdir(SHARED + "/data"):
                self.skipTest("../shared/data absent")
        out = run(shlex.split(command), self.work)
        self.assertEqual(out.returncode, 0,
                         "cvg_ident %s exited %d:\n%s" % (command, out.returncode, out.stderr[-2000:]))

    def test_1_readme_command_lines(self):
        commands = readme_commands()
        self.assertGreaterEqual(len(commands), 8, commands)
        for c in commands:
            with self.subTest(command=c):
                self.check(c)

    def test_2_help_examples(self):
        examples = help_examples()
        # identify's example is the joint mu fit; every subcommand shows at least one.
        self.assertEqual({s for s, _ in examples}, set(SUBCOMMANDS))
        # The examples read the files the README's lines write (made here when missing).
        for name, c in (("sweep.csv", "simulate --preset mems_ring --mode forced --seed 1 --out sweep.csv"),
                        ("est.json", "identify sweep.csv --mode forced --model xi --json est.json"),
                        ("raw.csv", "simulate --preset hrg_hemispherical --mode free_decay --raw --out raw.csv"),
                        ("slow.csv", "demod raw.csv --rate 100 --out slow.csv")):
            if not os.path.exists(os.path.join(self.work, name)):
                self.check(c)
        for sub, c in examples:
            with self.subTest(command=c):
                self.check(c)

    def test_3_joint_mu_from_the_command_line(self):
        mu = 0.05
        self.check("simulate --preset mems_ring --mode forced --seed 3 --effect mu=%g --out mu.csv" % mu)
        self.check("identify mu.csv --mode forced --model xi+mu --method ceres --json mu.json")
        with open(os.path.join(self.work, "mu.json"), encoding="utf-8") as f:
            est = json.load(f)
        self.assertEqual(est["method"], "ceres")
        p = est["parameters"]["mu"]
        self.assertLessEqual(p["ci_low"], mu)
        self.assertGreaterEqual(p["ci_high"], mu)
        self.assertLess(p["ci_high"] - p["ci_low"], mu, "mu is not resolved: %s" % p)


if __name__ == "__main__":
    unittest.main()
