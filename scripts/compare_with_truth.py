#!/usr/bin/python3
"""Prints an estimate next to the truth a simulated record carries (`# truth_<name>: value` lines).

Usage: compare_with_truth.py RECORD.csv ESTIMATE.json
ESTIMATE.json is `cvg_ident identify --json` output or `cvg_ident explain --json` output (its
`final` member is used). Exit status 0; the last column says whether the truth lies in the interval.
"""
import json
import sys


def truth_of(path):
    truth = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            if not line.startswith("#"):
                break
            key, _, value = line[1:].partition(":")
            key = key.strip()
            if key.startswith("truth_"):
                try:
                    truth[key[len("truth_"):]] = float(value)
                except ValueError:
                    pass
    return truth


def main(record, estimate):
    truth = truth_of(record)
    with open(estimate, encoding="utf-8") as f:
        est = json.load(f)
    if "final" in est:
        est = est["final"]
    params = est.get("parameters", {})
    print("model %s, method %s, confidence %.2f" % (est.get("model"), est.get("method"), est.get("confidence", 0.95)))
    print("%-10s %14s %14s %14s %14s  %s" % ("parameter", "truth", "estimate", "ci_low", "ci_high", "truth inside"))
    inside = 0
    for name, p in params.items():
        t = truth.get(name)
        ok = t is not None and p["ci_low"] <= t <= p["ci_high"]
        inside += ok
        print("%-10s %14s %14.6g %14.6g %14.6g  %s" % (
            name, "-" if t is None else "%.6g" % t, p["value"], p["ci_low"], p["ci_high"],
            "-" if t is None else ("yes" if ok else "NO")))
    missed = [n for n, v in truth.items() if n not in params and v != 0.0 and n not in ("eta",)]
    print("truth inside the interval for %d of %d parameters" % (inside, len(params)))
    if missed:
        print("true effects the model does not have: " + ", ".join(missed))
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2]))
