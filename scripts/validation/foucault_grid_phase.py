#!/usr/bin/python3
"""How the Florence pendulum's verdict depends on where the demodulator's output grid falls.

The irregular-timestamp demodulator (core/demod/irregular_demodulator) puts its slow samples on
multiples of one period from the clock's zero. Shifting the record's clock by a fraction of a
period moves that grid against the swing (and rotates the slow states' phase, which changes
nothing). This runs `cvg_ident explain RECORD --mode free_decay --json` on the record with its
clock shifted by j / N of a period, j = 0 .. N-1, and prints per shift the exit code, the
selected model, `determined`, the final model's rank and Q; then the count of each verdict.
Nothing is tuned on it.
(../shared/data/foucault_florence_2021; skipped with a message when absent.)

  foucault_grid_phase.py [--n 24] [--jobs 2] [--work DIR] [--tool bin/cvg_ident] [--data CSV]
"""
import argparse
import collections
import concurrent.futures as cf
import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(REPO, "..", "shared", "data", "foucault_florence_2021",
                    "2021_09_17_14_57_N.csv")
OMEGA = 2.2371955  # rad/s, the record's reference frequency as explain estimates it


def explain_shifted(tool, work, t, x, y, j, n):
    delta = j * (2.0 * math.pi / OMEGA) / n
    path = os.path.join(work, "shift_%02d.csv" % j)
    with open(path, "w") as f:
        f.write("t,f,g\n")
        for a, b, c in zip(t + delta, x, y):
            f.write("%.17g,%.17g,%.17g\n" % (a, b, c))
    out = path + ".json"
    if os.path.exists(out):
        os.remove(out)  # a reused --work must not show an earlier run's answer
    p = subprocess.run([tool, "explain", path, "--mode", "free_decay", "--json", out],
                       capture_output=True, text=True, timeout=1200)
    if not os.path.exists(out):
        return j, delta, p.returncode, "no JSON: " + p.stderr.strip()[:200], None, None, "-"
    with open(out) as f:
        j_out = json.load(f)
    final = j_out.get("final", {})
    q = final.get("derived_ci", {}).get("Q", {}).get("value")
    terms = "+".join(["linear"] + list(j_out.get("selected") or []))
    rank = "%s of %s" % (final.get("rank"), final.get("n_params"))
    return j, delta, p.returncode, terms, j_out.get("determined"), q, rank


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=24)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--work", default=None)
    ap.add_argument("--tool", default=os.path.join(REPO, "bin", "cvg_ident"))
    ap.add_argument("--data", default=DATA)
    a = ap.parse_args()
    if not os.path.isfile(a.data):
        print("foucault_grid_phase: %s absent, skipped" % a.data)
        return 0
    d = np.genfromtxt(a.data, delimiter=";", names=True)
    t, x, y = d["time"], d["x"].astype(float), d["y"].astype(float)
    work = a.work or tempfile.mkdtemp(prefix="foucault_grid_")
    os.makedirs(work, exist_ok=True)
    verdicts = collections.Counter()
    print("| shift [s] | exit | selected | determined | rank | Q |")
    print("|---|---|---|---|---|---|")
    with cf.ThreadPoolExecutor(a.jobs) as ex:
        for j, delta, rc, terms, det, q, rank in ex.map(
                lambda j: explain_shifted(a.tool, work, t, x, y, j, a.n), range(a.n)):
            print("| %.3f | %d | %s | %s | %s | %s |" % (delta, rc, terms, det, rank,
                                                       "%.0f" % q if q is not None else "-"))
            verdicts["%s (%s)" % (terms, "determined" if det else "not determined")] += 1
    print()
    for v, c in verdicts.most_common():
        print("- %s: %d of %d grid phases" % (v, c, a.n))
    return 0


if __name__ == "__main__":
    sys.exit(main())
