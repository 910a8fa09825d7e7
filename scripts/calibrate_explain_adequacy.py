#!/usr/bin/python3
"""False-alarm and correct-selection rates of `cvg_ident explain` on records of the independent
generator (scripts/independent_model/, read only): clean records with white noise, AR(1) rho = 0.9
on q and raw f, g through the tool's demodulator, and two-effect free decays. Each record is one
noise redraw of a fixed clean trajectory; seeds 3000.. (disjoint from the unit tests' < 1000 and
the harness's >= 50000). Reports, per setup, the rate of
  false alarm     clean record: any term selected or `unexplained`
  unexplained     `unexplained` true (the adequacy verdict, residuals whitened by the noise model)
  runs p<0.01 raw the lack-of-fit runs test on the unwhitened residuals (the former test)
  correct         selected set == hidden set and not unexplained
with Wilson 95 % intervals, and the explain wall time.

Usage: calibrate_explain_adequacy.py [--runs 100] [--setups clean_white,clean_ar1,clean_raw,...]
         [--tool bin/cvg_ident] [--json FILE]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.stats import binomtest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from independent_model import averaged, full, noise, presets, records  # noqa: E402

SEED0 = 3000
SETUPS = {
    "clean_white": ("fd_slow", "fd_cyl_40s", [], "white"),
    "clean_ar1": ("fd_slow", "fd_cyl_40s", [], "ar1_0.9"),
    "clean_ar1_hrg": ("fd_slow", "fd_hrg_1h", [], "ar1_0.9"),
    "clean_raw": ("fd_raw", "raw_1k2", [], "white"),
    "xi_kappa": ("fd_slow", "fd_mems_3s", ["xi", "kappa"], "white"),
    "xi_kappa_ar1": ("fd_slow", "fd_cyl_40s", ["xi", "kappa"], "ar1_0.9"),
    "xi_gamma_nl": ("fd_slow", "fd_hrg_1h", ["xi", "gamma_nl"], "white"),
}


def wilson(k, n):
    ci = binomtest(k, n).proportion_ci(0.95, method="wilson")
    return ci.low, ci.high


def clean(kind, preset, hidden):
    table = presets.FREE_DECAY if kind == "fd_slow" else presets.RAW
    p = table[preset]
    z = dict(p["z"])
    z.update(presets.effect_coefficients(preset, hidden, p.get("duration")))
    if kind == "fd_slow":
        t = np.arange(int(round(p["duration"] / p["step"])) + 1) * p["step"]
        return p, dict(t=t, q=averaged.free_decay(z, p["omega"], p["q0"], t))
    t, f, g = full.raw_free_decay(z, p["omega"], p["q0"], p["duration"], p["rate"], rtol=1e-8)
    return p, dict(t=t, f=f, g=g)


def run_setup(name, runs, tool, work):
    kind, preset, hidden, nm = SETUPS[name]
    p, d = clean(kind, preset, hidden)
    rows = []
    for r in range(runs):
        seed = SEED0 + 1000 * list(SETUPS).index(name) + r
        rng = np.random.default_rng(seed)
        path = os.path.join(work, "%s_%d.csv" % (name, seed))
        if kind == "fd_slow":
            records.write_slow(path, p["omega"], d["t"], noise.noisy_slow(d["q"], nm, p["sigma"], rng))
        else:
            f, g = noise.noisy_raw(d["f"], d["g"], nm, p["sigma"], rng)
            records.write_raw(path, p["omega"], d["t"], f, g)
        js = path[:-4] + ".json"
        t0 = time.time()
        rc = subprocess.run([tool, "explain", path, "--mode", "free_decay", "--json", js],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE).returncode
        secs = time.time() - t0
        if rc != 0:
            rows.append(dict(seed=seed, failed=True))
            continue
        j = json.load(open(js))
        sel, unexp = sorted(j["selected"]), bool(j["unexplained"])
        lof = j["lack_of_fit"]
        rows.append(dict(seed=seed, selected=sel, unexplained=unexp, p=lof["p_value"],
                         p_raw=lof.get("p_value_unwhitened", lof["p_value"]), seconds=secs,
                         runner_up=(j.get("runner_up") or {}).get("model"),
                         false_alarm=bool(not hidden and (sel or unexp)),
                         correct=bool(sel == sorted(hidden) and not unexp)))
        os.remove(path)
        os.remove(js)
    return rows


def summary(name, rows):
    ok = [r for r in rows if not r.get("failed")]
    n = len(ok)
    out = dict(setup=name, n=n, failed=len(rows) - n)
    for key, f in (("false_alarm", lambda r: r["false_alarm"]),
                   ("unexplained", lambda r: r["unexplained"]),
                   ("runs_raw_p_lt_0.01", lambda r: r["p_raw"] < 0.01),
                   ("correct", lambda r: r["correct"])):
        k = sum(1 for r in ok if f(r))
        out[key] = (k, n, wilson(k, n) if n else (float("nan"), float("nan")))
    out["median_seconds"] = float(np.median([r["seconds"] for r in ok])) if ok else float("nan")
    sel = {}
    for r in ok:
        sel["+".join(r["selected"]) or "none"] = sel.get("+".join(r["selected"]) or "none", 0) + 1
    out["selected"] = sel
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--setups", default="clean_white,clean_ar1,clean_raw")
    ap.add_argument("--tool", default=os.path.join(HERE, "..", "bin", "cvg_ident"))
    ap.add_argument("--json", default="")
    a = ap.parse_args()
    res = []
    with tempfile.TemporaryDirectory() as work:
        for name in a.setups.split(","):
            rows = run_setup(name, a.runs, a.tool, work)
            s = summary(name, rows)
            res.append(dict(summary=s, rows=rows))
            line = "%-14s n=%3d" % (name, s["n"])
            for key in ("false_alarm", "unexplained", "runs_raw_p_lt_0.01", "correct"):
                k, n, ci = s[key]
                line += "  %s %d/%d [%.2f, %.2f]" % (key, k, n, ci[0], ci[1])
            print(line + "  median %.2f s  selected %s" % (s["median_seconds"], s["selected"]),
                  flush=True)
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(res, fh, indent=1)


if __name__ == "__main__":
    main()
