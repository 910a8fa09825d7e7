#!/usr/bin/python3
"""Monte Carlo validation of the identification (docs/validation.md).

Runs the DISABLED Monte Carlo gtests of test/core/ceres_refinement_test.cpp (seeded simulations of
the averaged model, estimators from the core library) and summarises them:
  - free decay (model linear+xi, 401 samples, sigma_q = 1e-3): CI coverage (target 0.93-0.97) and
    the ratio of the mean reported standard error to the actual RMS error (target 0.8-1.25) for
    the paper's (2.11) intervals, the identification's honest LS intervals, and Ceres;
  - forced sweeps (the paper's section-4 model, 61 points): bias of LS vs Ceres as sigma_q grows
    (1e-3, 1e-2, 3e-2), docs/paper.md item 15.

Usage:
  scripts/validate_identification.py [--binary PATH] [--runs N] [--markdown docs/validation.md]
The binary defaults to the first cvg_core_tests found under build/ (catkin) or /tmp/build_*/.
"""
import argparse
import glob
import os
import re
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LINE = re.compile(r"^MC (?P<label>.*?) param=(?P<param>\S+) (?P<rest>.*)$")
FIELD = re.compile(r"(\w+)=(\S+)")
TARGET_COVERAGE = (0.93, 0.97)
TARGET_SE_RATIO = (0.8, 1.25)


def find_binary():
    candidates = glob.glob(os.path.join(REPO, "build", "**", "cvg_core_tests"), recursive=True)
    candidates += glob.glob("/tmp/build_*/cvg_core_tests")
    candidates = [c for c in candidates if os.access(c, os.X_OK)]
    if not candidates:
        sys.exit("validate_identification: no cvg_core_tests binary found; build it (make build) "
                 "or pass --binary")
    return max(candidates, key=os.path.getmtime)


def run(binary, runs):
    env = dict(os.environ, CVG_MC_RUNS=str(runs))
    cmd = [binary, "--gtest_also_run_disabled_tests", "--gtest_filter=*MonteCarlo*"]
    proc = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True, check=False)
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout[-4000:])
        sys.exit("validate_identification: %s failed (exit %d)" % (binary, proc.returncode))
    return proc.stdout


def parse(text):
    """{label: {param: {field: value}}} and the setup line."""
    rows, setup = {}, ""
    for line in text.splitlines():
        if line.startswith("MC free_decay setup"):
            setup = line[len("MC free_decay setup "):]
            continue
        m = LINE.match(line)
        if not m:
            continue
        fields = {k: float(v) for k, v in FIELD.findall(m.group("rest"))}
        rows.setdefault(m.group("label"), {})[m.group("param")] = fields
    return rows, setup


def verdict(value, bounds):
    return "ok" if bounds[0] <= value <= bounds[1] else "OFF"


def free_decay_section(rows, setup):
    methods = [("ls_paper", "LS, paper (2.11)"), ("ls_honest", "LS, honest (sandwich)"),
               ("ceres", "Ceres output error")]
    out = ["## Free decay: coverage and standard errors", "",
           "Setup: %s; seeded runs; 95 %% intervals." % setup, "",
           "| method | runs | mean coverage | mean SE / RMS error | coverage in %.2f-%.2f | "
           "SE ratio in %.2f-%.2f |" % (TARGET_COVERAGE + TARGET_SE_RATIO),
           "|---|---|---|---|---|---|"]
    for key, name in methods:
        a = rows.get("free_decay method=" + key, {}).get("ALL")
        if a is None:
            continue
        out.append("| %s | %d | %.3f | %.3f | %s | %s |" % (
            name, a["runs"], a["coverage"], a["se_ratio"], verdict(a["coverage"], TARGET_COVERAGE),
            verdict(a["se_ratio"], TARGET_SE_RATIO)))
    params = sorted(p for p in rows.get("free_decay method=ceres", {}) if p != "ALL")
    out += ["", "Per parameter (coverage / SE ratio / RMS error):", "",
            "| parameter | " + " | ".join(n for _, n in methods) + " |",
            "|---|" + "---|" * len(methods)]
    for p in params:
        cells = []
        for key, _ in methods:
            f = rows["free_decay method=" + key][p]
            cells.append("%.3f / %.2f / %.3g" % (f["coverage"], f["se_ratio"], f["rms"]))
        out.append("| %s | %s |" % (p, " | ".join(cells)))
    return out


def forced_section(rows):
    labels = sorted({l.split(" method=")[0] for l in rows if l.startswith("forced")},
                    key=lambda l: float(l.split("=")[1]))
    out = ["", "## Forced sweep: errors-in-variables bias of LS vs Ceres", "",
           "Paper's section-4 cubic model (13 parameters), 61 points, lambda = -150..150 rad/s; "
           "bias = mean(estimate - truth) / |truth| in %, +- its standard error.", "",
           "| sigma_q | gamma LS | gamma Ceres | xi LS | xi Ceres | c_m LS | c_m Ceres | "
           "coverage LS | coverage Ceres | SE ratio LS | SE ratio Ceres |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for l in labels:
        ls, ce = rows[l + " method=ls_honest"], rows[l + " method=ceres"]

        def b(d, p):
            return "%+.2f +- %.2f" % (d[p]["bias_pct"], d[p]["bias_se_pct"])
        out.append("| %s | %s | %s | %s | %s | %s | %s | %.3f | %.3f | %.3f | %.3f |" % (
            l.split("=")[1], b(ls, "gamma"), b(ce, "gamma"), b(ls, "xi"), b(ce, "xi"),
            b(ls, "c_m"), b(ce, "c_m"), ls["ALL"]["coverage"], ce["ALL"]["coverage"],
            ls["ALL"]["se_ratio"], ce["ALL"]["se_ratio"]))
    out += ["", "Per parameter at each sigma_q (bias % LS / Ceres):", "",
            "| parameter | " + " | ".join(l.split("=")[1] for l in labels) + " |",
            "|---|" + "---|" * len(labels)]
    params = [p for p in rows[labels[0] + " method=ceres"] if p != "ALL"] if labels else []
    for p in params:
        cells = ["%+.1f / %+.1f" % (rows[l + " method=ls_honest"][p]["bias_pct"],
                                    rows[l + " method=ceres"][p]["bias_pct"]) for l in labels]
        out.append("| %s | %s |" % (p, " | ".join(cells)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", help="cvg_core_tests binary (default: newest found)")
    ap.add_argument("--runs", type=int, default=200, help="Monte Carlo runs per case (>= 10)")
    ap.add_argument("--markdown", help="write the tables into this Markdown file section")
    args = ap.parse_args()
    binary = args.binary or find_binary()
    rows, setup = parse(run(binary, max(10, args.runs)))
    if not rows:
        sys.exit("validate_identification: the binary printed no Monte Carlo figures")
    lines = free_decay_section(rows, setup) + forced_section(rows)
    text = "\n".join(lines) + "\n"
    print(text)
    if args.markdown:
        marker = "<!-- measured by scripts/validate_identification.py -->"
        old = open(args.markdown).read() if os.path.exists(args.markdown) else marker + "\n"
        head = old.split(marker)[0]
        with open(args.markdown, "w") as f:
            f.write(head + marker + "\n\n" + text)


if __name__ == "__main__":
    main()
