#!/usr/bin/python3
"""Seeded batch validation of `cvg_ident explain` (docs/validation_explain.md).

For each seed an effect is drawn from the library (or none: clean data), the record is simulated by
`cvg_ident simulate` on the mems_ring preset with its own cubic stiffness switched off, and
`cvg_ident explain` runs without being told. Reports, per mode:
  correct rate         selected set == hidden set (target >= 95 %)
  false-discovery rate fraction of runs that select an extension that is not hidden (target <= 5 %)
and a per-effect breakdown; --markdown FILE writes the table for docs/validation_explain.md.

Usage: validate_explain.py [--tool bin/cvg_ident] [--runs N] [--seed0 S] [--modes forced,free_decay]
                           [--markdown FILE]
"""
import argparse
import json
import os
import random
import subprocess
import sys
import tempfile
import time

LIBRARY = {
    "forced": [None, ("xi", 18.217), ("kappa", 5.0), ("gamma_nl", 8.0), ("xi_diff", 3.0),
               ("mu", 0.05)],
    "free_decay": [None, ("xi", 30.0), ("kappa", 30.0), ("gamma_nl", 12.0), ("xi_diff", 10.0),
                   ("cm_rate", 100.0)],
}


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    return p.returncode, p.stdout, p.stderr


def one(tool, mode, seed, workdir):
    effect = random.Random(seed).choice(LIBRARY[mode])
    rec = os.path.join(workdir, "rec_%s_%d.csv" % (mode, seed))
    out = os.path.join(workdir, "explain_%s_%d.json" % (mode, seed))
    cmd = [tool, "simulate", "--preset", "mems_ring", "--mode", mode, "--seed", str(seed),
           "--effect", "xi=0", "--out", rec]
    if effect:
        cmd += ["--effect", "%s=%g" % effect]
    rc, _, err = run(cmd)
    if rc != 0:
        return effect, None, "simulate failed: " + err.strip()
    rc, _, err = run([tool, "explain", rec, "--mode", mode, "--json", out])
    if rc != 0:
        return effect, None, "explain failed: " + err.strip()
    with open(out) as fh:
        return effect, json.load(fh), ""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--tool", default=os.path.join(here, "..", "bin", "cvg_ident"))
    ap.add_argument("--runs", type=int, default=60, help="runs per mode")
    ap.add_argument("--seed0", type=int, default=1000)
    ap.add_argument("--modes", default="forced,free_decay")
    ap.add_argument("--markdown", default="")
    args = ap.parse_args()
    lines = ["| mode | runs | correct | false discoveries | missed | failed | seconds/run |",
             "|---|---|---|---|---|---|---|"]
    per_effect_lines = ["| mode | hidden effect | runs | correct |", "|---|---|---|---|"]
    ok = True
    with tempfile.TemporaryDirectory() as workdir:
        for mode in args.modes.split(","):
            stats = {"correct": 0, "false": 0, "missed": 0, "failed": 0}
            per = {}
            t0 = time.time()
            for i in range(args.runs):
                seed = args.seed0 + i
                effect, result, why = one(args.tool, mode, seed, workdir)
                name = effect[0] if effect else "none"
                per.setdefault(name, [0, 0])
                per[name][0] += 1
                if result is None:
                    stats["failed"] += 1
                    print("%s seed %d (%s): %s" % (mode, seed, name, why))
                    continue
                hidden = [effect[0]] if effect else []
                selected = result["selected"]
                if selected == hidden:
                    stats["correct"] += 1
                    per[name][1] += 1
                else:
                    print("%s seed %d: hidden %s, selected %s" % (mode, seed, hidden, selected))
                if any(s not in hidden for s in selected):
                    stats["false"] += 1
                if any(h not in selected for h in hidden):
                    stats["missed"] += 1
            n = args.runs
            dt = (time.time() - t0) / max(1, n)
            correct, fdr = stats["correct"] / n, stats["false"] / n
            ok &= correct >= 0.95 and fdr <= 0.05
            print("%s: %d runs, correct %.1f %%, false discoveries %.1f %%, missed %d, failed %d"
                  % (mode, n, 100 * correct, 100 * fdr, stats["missed"], stats["failed"]))
            lines.append("| %s | %d | %.1f %% | %.1f %% | %d | %d | %.2f |" % (
                mode, n, 100 * correct, 100 * fdr, stats["missed"], stats["failed"], dt))
            for name, (runs, good) in sorted(per.items()):
                per_effect_lines.append("| %s | %s | %d | %d |" % (mode, name, runs, good))
    table = "\n".join(lines + [""] + per_effect_lines) + "\n"
    print(table)
    if args.markdown:
        with open(args.markdown, "w") as fh:
            fh.write(table)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
