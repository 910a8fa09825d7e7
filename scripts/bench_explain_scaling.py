#!/usr/bin/python3
"""Scaling of the steps a bench engineer waits for: `cvg_ident explain` and `identify --method
ceres` on free-decay records of 10^3 .. 10^6 slow samples, CPU time and peak memory (RSS).

Records: the shipped hrg_hemispherical preset with cubic stiffness hidden (xi = 30), over three
decay times (tau = 2 / gamma ~ 320 s), the slow sample rate chosen to give N samples. Each command
runs once (they take seconds to minutes); CPU seconds and peak RSS come from wait4()'s rusage, wall
seconds from the clock around it (explain runs its candidate fits on all cores: wall < CPU).
Prints one JSON line per (command, N); scripts/run_benchmarks.sh turns them into a table.
Usage: bench_explain_scaling.py [--sizes 1000,10000,...] [--tool bin/cvg_ident]
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
DURATION_S = 960.0


def preset_with_rate(src, rate_hz, dst):
    text = open(src).read()
    text = re.sub(r"(free_decay:\s*\n\s*duration_s:)\s*[0-9.eE+-]+", r"\g<1> %g" % DURATION_S, text)
    text = re.sub(r"(\n\s*sample_rate_hz:)\s*[0-9.eE+-]+", r"\g<1> %g" % rate_hz, text, count=1)
    open(dst, "w").write(text)


def run(cmd):
    start = time.monotonic()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.monotonic() - start
    err = proc.stderr.read().decode(errors="replace")
    code = os.waitstatus_to_exitcode(status)
    return code, usage.ru_utime + usage.ru_stime, usage.ru_maxrss * 1024, err, wall


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1000,10000,100000,1000000")
    ap.add_argument("--tool", default=os.path.join(ROOT, "bin", "cvg_ident"))
    args = ap.parse_args()
    preset = os.path.join(ROOT, "config", "resonators", "hrg_hemispherical.yaml")
    with tempfile.TemporaryDirectory() as tmp:
        for n in [int(s) for s in args.sizes.split(",")]:
            cfg = os.path.join(tmp, "preset.yaml")
            preset_with_rate(preset, n / DURATION_S, cfg)
            rec = os.path.join(tmp, "decay.csv")
            code, _, _, err, _ = run([args.tool, "simulate", "--config", cfg, "--mode", "free_decay",
                                      "--effect", "xi=30", "--seed", "7", "--out", rec])
            if code != 0:
                print("simulate failed for N = %d: %s" % (n, err.strip()), file=sys.stderr)
                continue
            for name, cmd in (
                    ("explain", [args.tool, "explain", rec, "--mode", "free_decay"]),
                    ("identify_ceres", [args.tool, "identify", rec, "--mode", "free_decay",
                                        "--model", "xi", "--method", "ceres"])):
                code, cpu, rss, err, wall = run(cmd)
                print(json.dumps({"name": "%s/%d" % (name, n), "samples": n, "exit": code,
                                  "cpu_s": cpu, "wall_s": wall, "peak_rss_bytes": rss,
                                  "bytes_per_sample": rss / n}), flush=True)


if __name__ == "__main__":
    main()
