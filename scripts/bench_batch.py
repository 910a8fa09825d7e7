#!/usr/bin/python3
"""Throughput of `cvg_ident batch` against the single-record command in a shell loop (docs/fleet.md).

usage: bench_batch.py [--records N] [--repeats R] [--out FILE.md]

Two record sets: the real ring-down development set (../shared/data/ringdowns_qpit_dev, the first N
records; skipped when absent) and N simulated free decays (quartz_cylinder, `identify --model linear`).
Per set, R rounds of three whole-command runs in turn (loop, batch --jobs 1, batch --jobs 2; pairing
in rounds keeps ratios fair when the machine's speed drifts): wall seconds, records per minute, the
ratio batch --jobs 1 / a loop over the binary itself (per-core overhead of batch, target <= ~1) and the speed-up
jobs 2 / jobs 1 (target near 2 on 2 free cores), each as the median over rounds; peak memory per
record from batch's status files. Writes a Markdown table (default docs/benchmarks_batch.md).
"""
import glob
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")  # the documented wrapper (sources the workspace)
BINARY = os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench", "cvg_ident")
QPIT = os.path.join(ROOT, "..", "shared", "data", "ringdowns_qpit_dev", "records")


def arg(name, default):
    return type(default)(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def timed(cmd, **kw):
    t0 = time.monotonic()
    subprocess.run(cmd, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, **kw)
    return time.monotonic() - t0


def bench_set(label, files, mode_args, tmp, repeats):
    def loop(tool):
        return "for f in \"$@\"; do %s identify \"$f\" %s --json %s/loop.json; done" % (
            tool, " ".join(mode_args), tmp)
    rows = {"loop": [], "loop_direct": [], "jobs1": [], "jobs2": []}
    for _ in range(repeats):
        rows["loop"].append(timed(["/bin/bash", "-c", loop(TOOL), "loop"] + files))
        rows["loop_direct"].append(timed(["/bin/bash", "-c", loop(BINARY), "loop"] + files))
        for jobs in (1, 2):
            out = os.path.join(tmp, "%s_j%d" % (label, jobs))
            shutil.rmtree(out, ignore_errors=True)
            rows["jobs%d" % jobs].append(timed([TOOL, "batch"] + files + mode_args + [
                "--jobs", str(jobs), "--no-plots", "--out", out]))
    rss, failed = [], 0
    for p in glob.glob(os.path.join(tmp, "%s_j2" % label, "records", "*.status.json")):
        with open(p) as f:
            s = json.load(f)
        rss.append(s["peak_rss_kb"] / 1024.0)
        failed += s["exit_status"] != 0
    med = {k: statistics.median(v) for k, v in rows.items()}
    per_core = statistics.median([b / a for a, b in zip(rows["loop_direct"], rows["jobs1"])])
    speedup = statistics.median([a / b for a, b in zip(rows["jobs1"], rows["jobs2"])])
    return {"set": label, "records": len(files), "failed": failed, "repeats": repeats,
            "wall_s": med, "records_per_min": {k: 60 * len(files) / v for k, v in med.items()},
            "jobs1_over_loop": per_core, "speedup_jobs2": speedup,
            "peak_rss_mb_median": statistics.median(rss) if rss else None,
            "peak_rss_mb_max": max(rss) if rss else None}


def main():
    n = arg("--records", 40)
    repeats = arg("--repeats", 3)
    out_md = arg("--out", os.path.join(ROOT, "docs", "benchmarks_batch.md"))
    tmp = tempfile.mkdtemp(prefix="cvg_bench_batch_")
    results = []
    try:
        if os.path.isdir(QPIT):
            files = sorted(glob.glob(os.path.join(QPIT, "*.txt")))[:n]
            results.append(bench_set("ringdown_real", files, ["--mode", "ringdown"], tmp, repeats))
        sim = []
        for i in range(n):
            p = os.path.join(tmp, "fd%03d.csv" % i)
            subprocess.run([TOOL, "simulate", "--preset", "quartz_cylinder", "--mode", "free_decay", "--seed",
                            str(1000 + i), "--out", p], check=True, stdout=subprocess.DEVNULL)
            sim.append(p)
        for p in sim[:1]:  # a benchmark of failures would be fast and meaningless
            subprocess.run([TOOL, "identify", p, "--mode", "free_decay", "--model", "linear", "--json",
                            os.path.join(tmp, "check.json")], check=True, stdout=subprocess.DEVNULL)
        results.append(bench_set("free_decay_sim", sim, ["--mode", "free_decay", "--model", "linear"], tmp, repeats))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    cores = os.cpu_count()
    lines = ["# `cvg_ident batch` throughput", "",
             "Written by `scripts/bench_batch.py` (%s, %d cores). Whole commands timed from outside, median of %d "
             "rounds run in turn; per-record peak memory from batch's status files. The documented "
             "`bin/cvg_ident` is a wrapper that sources the catkin workspace (about 0.1 s a call); batch starts "
             "its records from the binary, so the fair per-core comparison is against a loop over the binary "
             "itself (\"direct\")." % (time.strftime("%Y-%m-%d"), cores, repeats), "",
             "| set | records | loop of `bin/cvg_ident identify` / of the binary [rec/min] | batch --jobs 1 [rec/min] | batch --jobs 2 [rec/min] "
             "| jobs 1 / direct loop (time) | speed-up jobs 2 | peak memory per record (median, max) |",
             "|---|---|---|---|---|---|---|---|"]
    for r in results:
        rpm = r["records_per_min"]
        lines.append("| %s | %d (%d failed) | %.0f / %.0f | %.0f | %.0f | %.2f | %.2f | %.0f MB, %.0f MB |" % (
            r["set"], r["records"], r["failed"], rpm["loop"], rpm["loop_direct"], rpm["jobs1"], rpm["jobs2"], r["jobs1_over_loop"],
            r["speedup_jobs2"], r["peak_rss_mb_median"] or 0, r["peak_rss_mb_max"] or 0))
    with open(out_md, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(json.dumps(results))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
