#!/usr/bin/python3
"""Independent validation of `cvg_ident explain` and of `cvg_ident identify`'s intervals
(docs/validation_independent.md): records made by a path the fit does not share, scored against fixed targets.

Data (scripts/independent_model/, written from the paper, never `cvg_ident simulate`):
  fd_slow   free decay t,q1,p1,q2,p2 of the averaged model (numerical averaging of the forces of
            (2.3), DOP853), the harness's own presets (1 h at 2 s steps ... 3 s at 2 ms steps)
  sweep     forced sweeps omega0,q1,p1,q2,p2: stationary equations solved by Newton with
            continuation over the detuning
  fd_raw    raw t,f,g of the full equations (2.3) (solve_ivp DOP853 in f, f', g, g') that the
            tool demodulates itself
Each record hides nothing (clean), one library term, every pair of library terms, or an effect
outside the library; noise white, AR(1) rho 0.5 / 0.9 on q, or white with a pick-off gain drift.
Coverage kinds (cov_fd_ar1, cov_sweep_ar1, cov_raw) redraw the noise on one truth and score the
95 % intervals of `identify --method ls` and `--method ceres`.

Scoring (fixed here, before any run):
  explain correct   library effects: selected set == hidden set and unexplained false;
                    outside the library: unexplained true, or exactly the named stand-in selected
                    (gamma_nl4 -> gamma_nl, cm_step -> cm_rate; drive delay and 2 omega0 pumping
                    have none)
  false alarm       clean record: any term selected or unexplained true
  coverage          fraction of (run, parameter) intervals containing the truth; SE ratio per
                    parameter = mean reported std / RMS error
Rates carry Wilson 95 % intervals (scipy.stats.binomtest). Seeds from 50000 (50000 + a hash of
the case; the unit tests use < 10000, the old own-simulator validation 1000-1199).

Usage: validate_independent.py [--quick] [--kinds fd_slow,sweep,fd_raw,cov_fd_ar1,cov_sweep_ar1,
         cov_raw] [--jobs 2] [--tool bin/cvg_ident] [--json FILE] [--markdown FILE]
         [--explain-markdown FILE] [--work DIR] [--coverage-runs N]
"""
import argparse
import hashlib
import itertools
import json
import math
import multiprocessing
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
import zlib

import numpy as np
from scipy.stats import binomtest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from independent_model import averaged, full, noise, presets, records, selfcheck  # noqa: E402

SEED0 = 50000  # the reporting seeds; tuning runs use --seed-base TUNING_SEED0 (disjoint)
TUNING_SEED0 = 2000000  # 2000000..2999999: disjoint from 50000..1049999
KINDS = ["fd_slow", "sweep", "fd_raw", "cov_fd_ar1", "cov_sweep_ar1", "cov_raw"]
# Targets, fixed before running.
TARGET_CORRECT = 0.95
TARGET_FALSE_ALARM = 0.05
TARGET_COVERAGE = (0.90, 0.98)
TARGET_SE_RATIO = (0.8, 1.25)
MODE = {"fd_slow": "free_decay", "fd_raw": "free_decay", "sweep": "forced",
        "cov_fd_ar1": "free_decay", "cov_raw": "free_decay", "cov_sweep_ar1": "forced"}
# Coverage setups: preset, true model (library terms), noise model.
COVERAGE = {"cov_fd_ar1": ("fd_cyl_40s", ["xi"], "ar1_0.9"),
            "cov_sweep_ar1": ("sw_ring_24k", ["xi"], "ar1_0.9"),
            "cov_raw": ("raw_1k2", ["xi"], "white")}
RAW_RTOL = 1e-8


def wilson(k, n):
    if n == 0:
        return float("nan"), float("nan")
    ci = binomtest(k, n).proportion_ci(0.95, method="wilson")
    return ci.low, ci.high


# ---------------------------------------------------------------- the clean trajectories


def truth(kind, preset, hidden):
    table = {"fd_slow": presets.FREE_DECAY, "fd_raw": presets.RAW, "sweep": presets.SWEEP}
    base = kind if kind in table else {"cov_fd_ar1": "fd_slow", "cov_sweep_ar1": "sweep",
                                        "cov_raw": "fd_raw"}[kind]
    p = table[base][preset]
    z = dict(p["z"])
    z.update(presets.effect_coefficients(preset, hidden, p.get("duration")))
    return base, p, z


def traj_key(kind, preset, hidden):
    base = truth(kind, preset, hidden)[0]
    return hashlib.sha1(json.dumps([base, preset, sorted(hidden)]).encode()).hexdigest()[:16]


def make_trajectory(args):
    """Clean record of one (kind, preset, hidden effects), cached as .npz in the work folder."""
    kind, preset, hidden, work = args
    path = os.path.join(work, "traj_" + traj_key(kind, preset, hidden) + ".npz")
    if os.path.exists(path):
        return path, 0.0, ""
    t0 = time.process_time()
    base, p, z = truth(kind, preset, hidden)
    try:
        if base == "fd_slow":
            t = np.arange(int(round(p["duration"] / p["step"])) + 1) * p["step"]
            np.savez(path + ".tmp.npz", x=t, q=averaged.free_decay(z, p["omega"], p["q0"], t))
        elif base == "sweep":
            w0 = p["omega"] + np.linspace(p["lam"][0], p["lam"][1], p["points"])
            q, stable = averaged.stationary_sweep(z, p["omega"], w0)
            if not stable.all():
                return path, 0.0, "unstable stationary points (bistable sweep)"
            np.savez(path + ".tmp.npz", x=w0, q=q)
        else:
            t, f, g = full.raw_free_decay(z, p["omega"], p["q0"], p["duration"], p["rate"],
                                          rtol=RAW_RTOL)
            np.savez(path + ".tmp.npz", x=t, f=f, g=g)
    except Exception as e:  # noqa: BLE001 - reported as a generator failure of that case
        return path, 0.0, "generator failed: %s" % e
    os.replace(path + ".tmp.npz", path)
    return path, time.process_time() - t0, ""


def noisy_record(case, work):
    """Writes the measured record of a case; returns (csv path, truth z, omega)."""
    # "gen" = what the generator hid (an outside effect included); "hidden" is what is scored
    gen = case.get("gen", case["hidden"])
    base, p, z = truth(case["kind"], case["preset"], gen)
    d = np.load(os.path.join(work, "traj_" + traj_key(case["kind"], case["preset"], gen) + ".npz"))
    rng = np.random.default_rng(case["seed"])
    path = os.path.join(work, "rec_%s_%d_%s.csv" % (case["kind"], case["id"],
                                                     case.get("method", "explain")))
    if base == "fd_slow":
        records.write_slow(path, p["omega"], d["x"], noise.noisy_slow(d["q"], case["noise"],
                                                                       p["sigma"], rng))
    elif base == "sweep":
        records.write_sweep(path, p["omega"], d["x"], noise.noisy_slow(d["q"], case["noise"],
                                                                        p["sigma"], rng))
    else:
        f, g = noise.noisy_raw(d["f"], d["g"], case["noise"], p["sigma"], rng, p["omega"], d["x"])
        records.write_raw(path, p["omega"], d["x"], f, g)
    return path, z, p["omega"]


# ---------------------------------------------------------------- one run


def child_cpu_s():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_tool(cmd, timeout=600):
    """(exit code, stderr, wall seconds, CPU seconds of the tool: user + system)."""
    t0, c0 = time.time(), child_cpu_s()
    try:
        p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           universal_newlines=True, timeout=timeout)
        return p.returncode, p.stderr, time.time() - t0, child_cpu_s() - c0
    except subprocess.TimeoutExpired:
        return -1, "timeout after %d s" % timeout, time.time() - t0, child_cpu_s() - c0


def verdict(case, selected, unexplained):
    hidden, outside = set(case["hidden"]), case["outside"]
    if outside:
        stand_in = case["stand_in"]
        correct = unexplained or (stand_in is not None and set(selected) == {stand_in})
    else:
        correct = set(selected) == hidden and not unexplained
    false_term = [s for s in selected if s not in hidden] if not outside else []
    return dict(correct=bool(correct), false_term=false_term,
                missed=[h for h in hidden if h not in selected],
                false_alarm=bool(not hidden and not outside and (selected or unexplained)))


def run_case(job):
    case, tool, work, keep = job
    out = dict(case)
    if case.get("generator_error"):
        out.update(status="generator failed", why=case["generator_error"])
        return out
    path, z, omega = noisy_record(case, work)
    mode = MODE[case["kind"]]
    js = path[:-4] + "_%s.json" % case.get("method", "explain")
    if case["kind"].startswith("cov_"):
        model = "+".join(case["model"]) or "linear"
        cmd = [tool, "identify", path, "--mode", mode, "--model", model, "--method",
               case["method"], "--json", js]
    else:
        cmd = [tool, "explain", path, "--mode", mode, "--json", js]
    rc, err, secs, cpu = run_tool(cmd)
    out["seconds"] = round(secs, 2)
    out["cpu_s"] = round(cpu, 2)
    if rc != 0 or not os.path.exists(js):
        out.update(status="tool failed", why="exit %d: %s" % (rc, err.strip()[-300:]))
    else:
        with open(js) as fh:
            j = json.load(fh)
        if case["kind"].startswith("cov_"):
            params = j.get("parameters", {})
            rows = {}
            for k, v in params.items():
                if k in z and v.get("std") is not None and math.isfinite(v.get("std", float("nan"))):
                    rows[k] = dict(truth=z[k], value=v["value"], std=v["std"], lo=v["ci_low"],
                                   hi=v["ci_high"])
            out.update(status="ok", params=rows,
                       interval_method=j.get("interval_method", j.get("covariance", "")))
        else:
            sel, unexp = list(j.get("selected", [])), bool(j.get("unexplained", False))
            out.update(status="ok", selected=sel, unexplained=unexp)
            out.update(verdict(case, sel, unexp))
    if not keep:
        for p in (path, js):
            if os.path.exists(p):
                os.remove(p)
    return out


# ---------------------------------------------------------------- the cases


def stable(text):
    """A platform-independent integer hash of a string (seeds, noise-model rotation)."""
    return zlib.crc32(text.encode())


def label(hidden, outside):
    return outside if outside else ("+".join(hidden) if hidden else "none")


def tool_terms(tool):
    """Newer library terms (presets.NEWER_TERMS) that this tool's `explain --help` names, as
    "mode:term" (the help lists the candidates per mode: "free decay: a, b; forced: c, d")."""
    try:
        text = subprocess.run([tool, "explain", "--help"], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, universal_newlines=True).stdout
    except OSError:
        return []
    text = " ".join(text.split())
    lists = {mode: re.search(r"%s:([^;)]*)" % label, text)
             for mode, label in (("free_decay", "free decay"), ("forced", "forced"))}
    out = []
    for t in presets.NEWER_TERMS:
        if not re.search(r"\b%s\b" % re.escape(t), text):
            continue
        for mode, m in lists.items():
            if m is None or re.search(r"\b%s\b" % re.escape(t), m.group(1)):
                out.append("%s:%s" % (mode, t))
    return out


def tool_version(tool):
    """The git commit the tool was built from (the repository's HEAD)."""
    try:
        return subprocess.run(["git", "-C", os.path.dirname(os.path.abspath(tool)), "rev-parse",
                               "--short", "HEAD"], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, universal_newlines=True).stdout.strip()
    except OSError:
        return "?"


def explain_cases(kind, quick, terms=()):
    mode = MODE[kind]
    lib, outside_effects = presets.library(mode, terms)
    configs = [([], None)] + [([a], None) for a in lib]
    configs += [(list(p), None) for p in itertools.combinations(lib, 2)]
    configs += [([], o) for o in outside_effects]
    table = {"fd_slow": presets.FREE_DECAY, "sweep": presets.SWEEP, "fd_raw": presets.RAW}[kind]
    models = list(noise.NOISE_MODELS)
    cases = []
    if kind == "fd_raw":  # raw: white, narrow-band AR(1) around the carrier, gain drift
        models = ["white", "ar1_0.9", "white+gain_drift"]
    for pi, preset in enumerate(table):
        for ci, (hidden, outside) in enumerate(configs):
            reps, use = 1, models
            if not hidden and not outside:
                reps = {"fd_raw": 5, "fd_slow": 3, "sweep": 4}[kind]  # more clean runs
            elif kind == "fd_slow" and len(hidden) == 2:
                # pairs: two of the four noise models (white + AR 0.9 or AR 0.5 + gain drift),
                # chosen by the pair's name so that a larger library keeps the old assignments
                use = models[stable(label(hidden, None)) % 2::2]
            elif kind == "fd_raw" and len(hidden) == 2:  # pairs: one of three noise models
                use = [models[(stable(label(hidden, None)) + pi) % len(models)]]
            for m in use:
                for rep in range(reps):
                    cases.append(dict(kind=kind, preset=preset, noise=m,
                                      hidden=hidden + ([outside] if outside else []),
                                      outside=outside, label=label(hidden, outside),
                                      stand_in=outside_effects.get(outside), rep=rep))
    if quick:
        pick = {"fd_slow": [("fd_cyl_40s", "none", "white"), ("fd_mems_3s", "xi+kappa", "ar1_0.9")],
                "sweep": [("sw_ring_24k", "none", "ar1_0.9"), ("sw_ring_11k", "gamma_nl+mu", "white")],
                "fd_raw": [("raw_1k2", "none", "white")]}[kind]
        cases = [next(c for c in sorted(cases, key=lambda c: c["noise"] != p[2])
                      if (c["preset"], c["label"]) == p[:2]) for p in pick]
    # effect coefficients use the library names; outside effects are listed in hidden for the
    # generator and removed for scoring
    for c in cases:
        c["gen"] = c["hidden"]
        c["hidden"] = [h for h in c["hidden"] if h != c["outside"]]
    return cases


def coverage_cases(kind, runs):
    preset, model, nm = COVERAGE[kind]
    return [dict(kind=kind, preset=preset, noise=nm, hidden=model, gen=model, outside=None,
                 model=model, method=meth, label="+".join(model), rep=r)
            for r in range(runs) for meth in ("ls", "ceres")]


# ---------------------------------------------------------------- summaries


def summarize_explain(results):
    by_kind = {}
    for r in results:
        by_kind.setdefault(r["kind"], []).append(r)
    out = {}
    for kind, rs in by_kind.items():
        ok = [r for r in rs if r["status"] == "ok"]
        n = len(rs)
        k = sum(r.get("correct", False) for r in rs)  # failed runs count as wrong
        clean = [r for r in rs if r["label"] == "none"]
        fa = sum(r.get("false_alarm", False) or r["status"] != "ok" for r in clean)
        lib = [r for r in rs if not r["outside"]]
        ft = sum(bool(r.get("false_term")) for r in lib)
        per = {}
        for r in rs:
            d = per.setdefault((r["label"], "outside" if r["outside"] else
                                ("clean" if r["label"] == "none" else
                                 "one" if len(r["hidden"]) == 1 else "pair")), [0, 0])
            d[0] += 1
            d[1] += bool(r.get("correct", False))
        groups = {}
        for r in rs:
            g = ("clean" if r["label"] == "none" else "outside" if r["outside"] else
                 "one effect" if len(r["hidden"]) == 1 else "two effects")
            groups.setdefault(g, [0, 0])
            groups[g][0] += 1
            groups[g][1] += bool(r.get("correct", False))
        noises = {}
        for r in rs:
            noises.setdefault(r["noise"], [0, 0])
            noises[r["noise"]][0] += 1
            noises[r["noise"]][1] += bool(r.get("correct", False))
        out[kind] = dict(runs=n, correct=k, ci=wilson(k, n), failed=n - len(ok),
                         clean_runs=len(clean), false_alarms=fa, fa_ci=wilson(fa, len(clean)),
                         lib_runs=len(lib), false_terms=ft, ft_ci=wilson(ft, len(lib)),
                         per=per, groups=groups, noises=noises,
                         seconds=sum(r.get("seconds", 0) for r in rs) / max(1, n),
                         cpu_s=sum(r.get("cpu_s", 0) for r in rs) / max(1, n),
                         failing=[r for r in rs if not r.get("correct", False)])
    return out


def summarize_coverage(results):
    out = {}
    for r in results:
        d = out.setdefault((r["kind"], r["method"]), dict(runs=0, failed=0, rows={}, methods=set()))
        d["runs"] += 1
        if r["status"] != "ok":
            d["failed"] += 1
            continue
        # Numbers (fitted rho, lags) vary per run: one entry per method, numbers shown as '#'.
        d["methods"].add(re.sub(r"(?<![\w^(_.])-?(\d+\.\d+(e[-+]?\d+)?|\d{2,})", "#",
                                r.get("interval_method") or ""))
        for k, v in r["params"].items():
            d["rows"].setdefault(k, []).append(v)
    for d in out.values():
        cov_k = cov_n = 0
        per = {}
        for k, vs in d["rows"].items():
            inside = sum(v["lo"] <= v["truth"] <= v["hi"] for v in vs)
            err = np.array([v["value"] - v["truth"] for v in vs])
            rms = float(np.sqrt(np.mean(err ** 2)))
            se = float(np.mean([v["std"] for v in vs]))
            per[k] = dict(n=len(vs), coverage=inside / len(vs), se_ratio=se / rms if rms > 0 else
                          float("nan"), rms=rms, bias_over_rms=float(np.mean(err)) / rms if rms > 0
                          else float("nan"))
            cov_k += inside
            cov_n += len(vs)
        d["per"] = per
        d["coverage"] = cov_k / cov_n if cov_n else float("nan")
        d["cov_ci"] = wilson(cov_k, cov_n)
        ratios = [p["se_ratio"] for p in per.values()]
        d["se_min"] = min(ratios) if ratios else float("nan")
        d["se_max"] = max(ratios) if ratios else float("nan")
        d["se_median"] = float(np.median(ratios)) if ratios else float("nan")
        d["methods"] = sorted(d["methods"])
    return out


def pct(x):
    return "%.1f %%" % (100 * x) if x == x else "-"


def ci_txt(ci):
    return "%.1f-%.1f %%" % (100 * ci[0], 100 * ci[1]) if ci[0] == ci[0] else "-"


def explain_tables(sx):
    L = ["| data kind | runs | correct | 95 % CI | target >= 95 % | clean runs | false alarms "
         "(any term or unexplained) | 95 % CI | target <= 5 % | false term, library runs | "
         "tool failed | s/run (wall) | CPU s/run |", "|---" * 13 + "|"]
    for kind in KINDS:
        if kind not in sx:
            continue
        s = sx[kind]
        L.append("| %s | %d | %d (%s) | %s | %s | %d | %d (%s) | %s | %s | %d / %d | %d | %.1f | %.1f "
                 "|" % (
            kind, s["runs"], s["correct"], pct(s["correct"] / s["runs"]), ci_txt(s["ci"]),
            "met" if s["correct"] / s["runs"] >= TARGET_CORRECT else "MISSED", s["clean_runs"],
            s["false_alarms"], pct(s["false_alarms"] / max(1, s["clean_runs"])), ci_txt(s["fa_ci"]),
            "met" if s["false_alarms"] <= TARGET_FALSE_ALARM * s["clean_runs"] else "MISSED",
            s["false_terms"], s["lib_runs"], s["failed"], s["seconds"], s["cpu_s"]))
    L += ["", "By what was hidden (correct / runs):", "",
          "| data kind | clean | one effect | two effects | outside the library |",
          "|---|---|---|---|---|"]
    for kind in KINDS:
        if kind in sx:
            g = sx[kind]["groups"]
            L.append("| %s | %s |" % (kind, " | ".join(
                "%d / %d" % (g[x][1], g[x][0]) if x in g else "-"
                for x in ("clean", "one effect", "two effects", "outside"))))
    L += ["", "By noise (correct / runs):", "",
          "| data kind | " + " | ".join(noise.NOISE_MODELS) + " |",
          "|---" * (1 + len(noise.NOISE_MODELS)) + "|"]
    for kind in KINDS:
        if kind in sx:
            g = sx[kind]["noises"]
            L.append("| %s | %s |" % (kind, " | ".join(
                "%d / %d" % (g[x][1], g[x][0]) if x in g else "-" for x in noise.NOISE_MODELS)))
    L += ["", "Per hidden effect (correct / runs):", "", "| data kind | hidden | correct / runs |",
          "|---|---|---|"]
    for kind in KINDS:
        if kind in sx:
            for (lab, grp), (n, k) in sorted(sx[kind]["per"].items(), key=lambda x: (
                    ["clean", "one", "pair", "outside"].index(x[0][1]), x[0][0])):
                L.append("| %s | %s%s | %d / %d |" % (kind, lab, " (outside)" if grp == "outside"
                                                      else "", k, n))
    L += ["", "Failing cases (kind, preset, hidden, noise, seed: what the tool said):", ""]
    for kind in KINDS:
        if kind in sx:
            for r in sx[kind]["failing"]:
                said = ("selected [%s], unexplained %s" % (", ".join(r.get("selected", [])),
                                                          str(r.get("unexplained")).lower())
                        if r["status"] == "ok" else r["status"] + ": " + r.get("why", ""))
                L.append("- %s %s hidden %s, %s, seed %d: %s" % (kind, r["preset"], r["label"],
                                                               r["noise"], r["seed"], said))
    return L


def summary_part(lines):
    """The main table and the by-what-was-hidden table of explain_tables."""
    return lines[:lines.index("By noise (correct / runs):")]


def coverage_tables(sc):
    L = ["| data | method | runs | failed | coverage (all parameters) | 95 % CI | target 0.90-0.98 "
         "| SE/RMS min / median / max | target 0.8-1.25 (all) | interval method (JSON) |",
         "|---" * 10 + "|"]
    for (kind, meth), d in sorted(sc.items()):
        L.append("| %s | %s | %d | %d | %.3f | %.3f-%.3f | %s | %.2f / %.2f / %.2f | %s | %s |" % (
            kind, meth, d["runs"], d["failed"], d["coverage"], d["cov_ci"][0], d["cov_ci"][1],
            "met" if TARGET_COVERAGE[0] <= d["coverage"] <= TARGET_COVERAGE[1] else "MISSED",
            d["se_min"], d["se_median"], d["se_max"],
            "met" if TARGET_SE_RATIO[0] <= d["se_min"] and d["se_max"] <= TARGET_SE_RATIO[1]
            else "MISSED", ", ".join(m for m in d["methods"] if m) or "not stated"))
    L += ["", "Per parameter (coverage / SE ratio / bias in RMS units):", ""]
    for (kind, meth), d in sorted(sc.items()):
        L.append("- %s, %s: " % (kind, meth) + "; ".join(
            "%s %.2f / %.2f / %+.2f" % (k, p["coverage"], p["se_ratio"], p["bias_over_rms"])
            for k, p in d["per"].items()))
    return L


def case_key(r):
    return (r["kind"], r["preset"], r["label"], r["noise"], r.get("rep", 0), r.get("method", ""))


def compare_tables(old, new, old_note):
    """Before/after: explain verdicts on the same records (same case, same seed) and coverage."""
    before = {case_key(r): r for r in old}
    L = ["Before: %s." % old_note, "",
         "| data kind | runs in both | same verdict | correct before | correct after | "
         "wrong -> right | right -> wrong | new cases (correct / runs) |", "|---" * 8 + "|"]
    for kind in KINDS:
        rs = [r for r in new if r["kind"] == kind and not kind.startswith("cov_")]
        if not rs:
            continue
        both = [(before[case_key(r)], r) for r in rs if case_key(r) in before]
        if not both and not rs:
            continue
        same = sum((sorted(a.get("selected", [])), a.get("unexplained"), a["status"]) ==
                   (sorted(b.get("selected", [])), b.get("unexplained"), b["status"])
                   for a, b in both)
        cb = sum(bool(a.get("correct")) for a, _ in both)
        ca = sum(bool(b.get("correct")) for _, b in both)
        up = sum(not a.get("correct") and bool(b.get("correct")) for a, b in both)
        down = sum(bool(a.get("correct")) and not b.get("correct") for a, b in both)
        fresh = [r for r in rs if case_key(r) not in before]
        L.append("| %s | %d | %d | %d | %d | %d | %d | %d / %d |" % (
            kind, len(both), same, cb, ca, up, down, sum(bool(r.get("correct")) for r in fresh),
            len(fresh)))
    so = summarize_coverage([r for r in old if r["kind"].startswith("cov_")])
    sn = summarize_coverage([r for r in new if r["kind"].startswith("cov_")])
    if so and sn:
        L += ["", "| coverage data | method | coverage before | after | SE/RMS min-max before | "
              "after |", "|---" * 6 + "|"]
        for key in sorted(set(so) & set(sn)):
            a, b = so[key], sn[key]
            L.append("| %s | %s | %.3f | %.3f | %.2f-%.2f | %.2f-%.2f |" % (
                key[0], key[1], a["coverage"], b["coverage"], a["se_min"], a["se_max"],
                b["se_min"], b["se_max"]))
    return L


def setup_text():
    L = ["Presets (own, not config/resonators):", ""]
    for name, p in list(presets.FREE_DECAY.items()) + list(presets.RAW.items()):
        L.append("- %s: omega %.6g rad/s, Q %.3g, record %g s, %s, noise sigma %g" % (
            name, p["omega"], p["omega"] / p["z"]["gamma"], p["duration"],
            ("slow step %g s" % p["step"]) if "step" in p else ("raw %g Hz" % p["rate"]),
            p["sigma"]))
    for name, p in presets.SWEEP.items():
        L.append("- %s: omega %.6g rad/s, Q %.3g, %d detunings %g..%g rad/s, noise sigma %g" % (
            name, p["omega"], p["omega"] / p["z"]["gamma"], p["points"], p["lam"][0],
            p["lam"][1], p["sigma"]))
    L += ["", "Effect sizes: " + "; ".join("%s: %s" % (k, ", ".join("%s %g" % kv for kv in
                                                                      v.items()))
                                          for k, v in presets.EFFECTS.items())]
    return L


# ---------------------------------------------------------------- main


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--tool", default=os.path.join(HERE, "..", "bin", "cvg_ident"))
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--quick", action="store_true", help="smoke subset (~5 explain runs)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--coverage-runs", type=int, default=60)
    ap.add_argument("--thin", type=int, default=1,
                    help="explain: keep clean records and 1/THIN of the others (seed-chosen)")
    ap.add_argument("--labels", default="",
                    help="only these hidden labels (comma-separated; 'outside' = every effect "
                    "outside the library); for studies, not for the doc tables")
    ap.add_argument("--json", default="", help="all results as JSON")
    ap.add_argument("--markdown", default="", help="write the full report (tables) here")
    ap.add_argument("--work", default="", help="cache the clean trajectories in this folder")
    ap.add_argument("--keep-records", action="store_true",
                    help="keep the noisy records and the tool's JSON in the work folder")
    ap.add_argument("--explain-doc", default="",
                    help="replace the independent section of this file (docs/validation_explain.md)")
    ap.add_argument("--from-json", default="",
                    help="comma-separated --json files of earlier runs: report them as one run")
    ap.add_argument("--compare", default="",
                    help="an earlier run's --json: add before/after tables on the same records")
    ap.add_argument("--coverage-doc", default="",
                    help="replace the independent coverage section of this file (docs/validation.md)")
    ap.add_argument("--seed-base", type=int, default=SEED0,
                    help="first seed (default %d: the reporting seeds). Thresholds are tuned only "
                    "on --seed-base %d (seeds base + CRC mod 10^6: the two ranges are disjoint); "
                    "a run with another base writes no doc section" % (SEED0, TUNING_SEED0))
    args = ap.parse_args()
    kinds = [k for k in args.kinds.split(",") if k]
    bad = [k for k in kinds if k not in KINDS]
    if bad:
        ap.error("unknown kinds %s (known: %s)" % (bad, ", ".join(KINDS)))
    if args.from_json:
        results, t_start, kinds, terms = load_runs(args)
    else:
        t_start = time.time()
        results, terms = run_all(args, kinds)
        if results is None:
            return 2
    report(args, kinds, terms, results, t_start)
    return 0


def load_runs(args):
    """Results of earlier runs (their --json files, e.g. one per data kind) as one run."""
    results, elapsed, kinds, terms, gen = [], 0.0, [], None, 0.0
    for path in args.from_json.split(","):
        with open(path) as fh:
            d = json.load(fh)
        results += d["results"]
        elapsed += d["elapsed_s"]
        kinds += [k for k in d["kinds"] if k not in kinds]
        terms = d.get("library_terms_beyond_ten", []) if terms is None else terms
        tools = [t for t in getattr(args, "tool_commit", "").split(", ") if t]
        args.tool_commit = ", ".join(tools + [d.get("tool", "?")] * (d.get("tool", "?") not in tools))
        args.thin = max(args.thin, d.get("thin", 1))
        args.parts = getattr(args, "parts", []) + ["%s (tool %s)" % (",".join(d["kinds"]),
                                                                      d.get("tool", "?"))]
        gen += d.get("gen_cpu_s", 0.0)
    args.terms, args.gen_cpu = terms or [], gen
    args.kinds = ",".join(k for k in KINDS if k in kinds)
    args.quick = False
    return results, time.time() - elapsed, kinds, args.terms


def run_all(args, kinds):
    """Generates the records, runs the tool on every case; (results, terms) or (None, None)."""
    t_start = time.time()
    print("generator self-check:")
    if not selfcheck.run(fast=True):
        print("validate_independent: the generator's self-check FAILED; no validation run")
        return None, None
    cases = []
    terms = args.terms = tool_terms(args.tool)
    print("library terms beyond the original ten that the tool names: %s" % (
        ", ".join(terms) or "none"))
    for kind in kinds:
        if kind.startswith("cov_"):
            cases += coverage_cases(kind, 3 if args.quick else args.coverage_runs)
        else:
            cases += explain_cases(kind, args.quick, terms)
    for i, c in enumerate(cases):
        c["id"] = i
    for c in cases:  # a case keeps its seed when other cases are added (before/after comparisons)
        c["seed"] = args.seed_base + stable(json.dumps([c["kind"], c["preset"], c["label"], c["noise"],
                                               c["rep"]])) % 1000000
    if args.thin > 1:  # keep the clean records, and a seed-chosen 1/thin of the others
        cases = [c for c in cases if c["kind"].startswith("cov_") or c["label"] == "none"
                 or c["seed"] % args.thin == 0]
    if args.labels:  # a subset by what was hidden (e.g. the effects outside the library)
        want = set(args.labels.split(","))
        cases = [c for c in cases if c["label"] in want
                 or ("outside" in want and c.get("outside"))]
    if args.quick:  # the smoke subset: explain cases, plus at most 1 coverage pair
        cov = [c for c in cases if c["kind"].startswith("cov_")][:2]
        cases = [c for c in cases if not c["kind"].startswith("cov_")] + cov
    work_ctx = None
    if args.work:
        os.makedirs(args.work, exist_ok=True)
        work = args.work
    else:
        work_ctx = tempfile.TemporaryDirectory()
        work = work_ctx.name
    trajs = {}
    for c in cases:
        trajs.setdefault(traj_key(c["kind"], c["preset"], c["gen"]),
                         (c["kind"], c["preset"], c["gen"], work))
    print("%d runs, %d clean trajectories to generate (work folder %s)" % (
        len(cases), len(trajs), work))
    errors = {}
    args.gen_cpu = 0.0
    with multiprocessing.Pool(args.jobs) as pool:
        for key, (path, secs, err) in zip(trajs, pool.imap(make_trajectory, trajs.values())):
            args.gen_cpu += secs
            if err:
                errors[key] = err
                print("  generator: %s %s: %s" % (trajs[key][0], trajs[key][1], err))
        print("generated in %.0f s" % (time.time() - t_start))
        for c in cases:
            key = traj_key(c["kind"], c["preset"], c["gen"])
            if key in errors:
                c["generator_error"] = errors[key]
        results = []
        jobs = [(c, args.tool, work, args.keep_records) for c in cases]
        for i, r in enumerate(pool.imap_unordered(run_case, jobs)):
            results.append(r)
            if (i + 1) % 25 == 0 or i + 1 == len(jobs):
                print("  %d / %d runs (%.0f s)" % (i + 1, len(jobs), time.time() - t_start),
                      flush=True)
    if work_ctx:
        work_ctx.cleanup()
    return results, terms


def report(args, kinds, terms, results, t_start):
    """Prints the tables, writes the JSON, the full report and the doc sections."""
    results.sort(key=lambda r: (KINDS.index(r["kind"]), r["id"]))
    args.cpu_total = sum(r.get("cpu_s", 0.0) for r in results)
    ex = [r for r in results if not r["kind"].startswith("cov_")]
    cv = [r for r in results if r["kind"].startswith("cov_")]
    sx = summarize_explain(ex) if ex else {}
    sc = summarize_coverage(cv) if cv else {}
    elapsed = time.time() - t_start
    lines = []
    if sx:
        lines += ["## Explain verdicts", ""] + explain_tables(sx)
    if sc:
        lines += ["", "## Interval coverage (identify)", "", COVERAGE_TEXT, ""] + coverage_tables(sc)
    if args.compare and os.path.exists(args.compare):
        with open(args.compare) as fh:
            old = json.load(fh)
        note = "%s (tool %s, library terms beyond ten: %s)" % (
            old.get("measured", "earlier run"), old.get("tool", "?"),
            ", ".join(old.get("library_terms_beyond_ten", [])) or "none")
        lines += ["", "## Before / after (same records)", ""] + compare_tables(
            old["results"], results, note)
    print("\n".join(lines))
    print("total %.0f s, %d runs; tool CPU %.0f s (%.1f min on %d cores)" % (
        elapsed, len(results), args.cpu_total, args.cpu_total / 60.0 / args.jobs, args.jobs))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(dict(results=results, elapsed_s=elapsed, quick=args.quick, thin=args.thin,
                           selfcheck="ok", kinds=kinds, library_terms_beyond_ten=terms,
                           gen_cpu_s=args.gen_cpu, seed_base=getattr(args, "seed_base", SEED0),
                           tool=tool_version(args.tool),
                           measured=time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())), fh,
                      indent=1, default=str)
    if args.markdown:
        with open(args.markdown, "w") as fh:
            fh.write("\n".join(report_header(args, elapsed, len(results)) + lines) + "\n")
    head = report_header(args, elapsed, len(results))
    if getattr(args, "seed_base", SEED0) != SEED0:
        print("note: tuning seeds (--seed-base %d): no doc section written" % args.seed_base)
        return
    if getattr(args, "labels", ""):
        print("note: a subset (--labels): no doc section written")
        return
    explain_kinds = [k for k in KINDS if not k.startswith("cov_")]
    if args.explain_doc and sx:
        if args.quick or any(k not in kinds for k in explain_kinds):
            print("note: %s not updated (quick run or not every explain kind)" % args.explain_doc)
        else:
            replace_section(args.explain_doc, "independent explain", head[2:3] + [
                "", "Full tables, presets and effect sizes: docs/validation_independent.md.", ""]
                + summary_part(explain_tables(sx)), after_title=True)
    if args.coverage_doc and sc:
        if args.quick or any(k not in kinds for k in KINDS if k.startswith("cov_")):
            print("note: %s not updated (quick run or not every coverage kind)" % args.coverage_doc)
        else:
            replace_section(args.coverage_doc, "independent coverage", [
                "## Coverage on independent records (scripts/validate_independent.py)", ""]
                + head[2:3] + ["", COVERAGE_TEXT, ""] + coverage_tables(sc),
                before="<!-- measured by scripts/validate_identification.py -->")


COVERAGE_TEXT = ("One truth per row (%s), the noise redrawn per run (seeds from %d); "
                 "`cvg_ident identify --model xi --method ls|ceres`, 95 %% intervals; coverage "
                 "pooled over runs and parameters (Wilson interval treats them as independent), "
                 "SE/RMS = mean reported std / RMS error per parameter." % (
                     "; ".join("%s: %s, noise %s" % (k, v[0], v[2]) for k, v in COVERAGE.items()),
                     SEED0))


def replace_section(path, name, lines, after_title=False, before=None):
    """Replaces the text between <!-- begin NAME --> and <!-- end NAME --> (inserted after the
    first heading, before the line `before`, or at the end when absent)."""
    begin, end = "<!-- begin %s (scripts/validate_independent.py) -->" % name, \
        "<!-- end %s -->" % name
    text = open(path).read() if os.path.exists(path) else ""
    block = "\n".join([begin] + lines + [end]) + "\n"
    if begin in text and end in text:
        a = text.index(begin)
        b = text.index(end) + len(end) + 1
        text = text[:a] + block + text[b:]
    elif after_title and text.startswith("#"):
        cut = text.index("\n") + 1
        text = text[:cut] + "\n" + block + text[cut:]
    elif before and before in text:
        a = text.index(before)
        text = text[:a] + block + "\n" + text[a:]
    else:
        text += "\n" + block
    with open(path, "w") as fh:
        fh.write(text)


DOC_INTRO = """# Independent validation: explain verdicts and identify intervals

Written by `make validate` (scripts/validate_all.sh -> scripts/validate_independent.py); do not
edit by hand. The records come from the harness's own generator (scripts/independent_model/),
written from the paper and sharing no code with the tool: the averaged model by numerical
averaging of the forces of (2.3)/(3.1) over a period (checked against the printed (2.5) rows and
the compact cubic/quintic forms of docs/paper.md item 1), integrated by DOP853 (free decay) or
solved for stationary points by Newton with continuation over the detuning (sweeps); raw f, g of
the full equations (2.3) integrated by solve_ivp DOP853 in f, f', g, g' and demodulated by the
tool itself. Own presets (below), other sample steps and record lengths, noise white, AR(1)
rho 0.5 / 0.9 on q (independent per channel; for sweeps along the sweep), or white with a slow
pick-off gain drift (+0.3 % on f, -0.2 % on g over the record); raw records: white, narrow-band
noise around the carrier (a cos + b sin with a, b AR(1) rho 0.9 per raw sample, coloured after
demodulation), or the gain drift. The tool is not told what was hidden, nor the noise.

Data kinds: fd_slow (free decay t,q1,p1,q2,p2), sweep (omega0,q1,p1,q2,p2), fd_raw (t,f,g through
the tool's demodulator). Hidden: nothing (clean), one library term, every pair of library terms
(free decay: xi, kappa, gamma_nl, xi_diff, cm_rate; forced: xi, kappa, gamma_nl, xi_diff, mu;
fd_slow pairs under two of the four noise models, fd_raw pairs under one of its three, rotating),
or an effect outside the library: gamma_nl4 (damping -gamma_nl4 (f^2+g^2)^2 f'), cm_step (a
saturating frequency transient c_m + d (1 - exp(-t/tau))), delay (the drive arrives delayed: its
phase turns with omega0 across the sweep), pump (the 2 omega0 parametric terms of (2.1),
docs/paper.md item 6). The second isotropic cubic invariant xi_k (F_f = -(xi_k/(2 omega)) l g',
F_g = +(xi_k/(2 omega)) l f', l = f g' - g f'; same precession coupling r k / 8 as xi, no
amplitude-frequency law of its own on a standing wave) is a library term when the tool's
`explain --help` names it (then also in every pair), otherwise an effect outside the library
with no stand-in.

Scoring, fixed in the script before running: **correct** = the selected set equals the hidden
set and `unexplained` is false; for an effect outside the library, correct = `unexplained: true`
or exactly the named stand-in selected (gamma_nl4 -> gamma_nl, cm_step -> cm_rate; delay and
pump have none). **False alarm** (clean records) = any term selected or `unexplained: true`.
**False term** = a selected term that was not hidden (library runs). A run where the tool fails
counts as wrong. Targets: correct >= 95 % per data kind; false alarms <= 5 % on clean records
of every kind; interval coverage 0.90-0.98 and SE/RMS 0.8-1.25 for every parameter. Intervals
are Wilson 95 % (scipy.stats.binomtest). Seeds 50000 + (CRC-32 of the case: kind, preset,
hidden, noise, repeat) mod 10^6, so a case keeps its record when cases are added; the LS and
Ceres coverage runs of one repeat share a record. Tuning discipline: every threshold and choice
of the tool's adequacy test and selection was made on runs with `--seed-base 2000000` (seeds
2000000 + CRC mod 10^6, disjoint from these); the tables here are the reporting seeds only, run
after those choices were fixed.

**Harness bug, fixed 2026-11-26**: until then a record with an effect outside the library was
written from the *clean* trajectory (the generator made the right one; the record writer looked it
up by the scored hidden set, without the outside effect). Every "outside the library" row before
that date scored clean records, and a "before" of the before/after tables on those rows is a clean
record. **A look-alike by design**: cm_step's time constant (record / 4) lies within a factor 2 of
1 / (2 gamma) on every free-decay preset, so its frequency transient has the time course of an
amplitude^2 law; explain fits it as xi + xi_k (a frequency law without precession) and now says
that one decay cannot tell the two apart. Scored wrong here, as fixed before the run.
**Not a clean hold-out for fd_raw's false alarms**: the demodulated records' runs-test noise model
(the known correlation, then an AR(1) of what it leaves) was changed on 2026-11-26 after two
clean raw_700 records of these reporting seeds had been examined (called "unexplained" before:
3 / 30 false alarms). On fresh seeds (`--seed-base 5000000`, not looked at before) fd_raw was
52 / 55 correct with 1 / 30 false alarms both before and after the change.
"""


def report_header(args, elapsed, n):
    return [DOC_INTRO, "<!-- written by scripts/validate_independent.py -->",
            "Measured %s, command `/usr/bin/python3 scripts/validate_independent.py%s%s%s` "
            "(%d runs, %.0f s on %d worker processes; tool %s, library terms beyond the original ten "
            "that it names: %s)." % (
                time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), " --quick" if args.quick else "",
                (" --coverage-runs %d" % args.coverage_runs if args.coverage_runs != 60 else "")
                + (" --thin %d" % args.thin if args.thin > 1 else ""),
                "" if args.kinds == ",".join(KINDS) else " --kinds " + args.kinds, n, elapsed,
                args.jobs, getattr(args, "tool_commit", None) or tool_version(args.tool),
                ", ".join(args.terms) or "none"),
            ] + ([("Assembled by --from-json from separate runs of the same command with "
                   "--kinds %s." % "; --kinds ".join(args.parts))]
                 if getattr(args, "parts", None) else []) + [
            "", "Cost: the tool's CPU time (user + system, summed over runs) %.0f s, i.e. %.1f min "
            "on %d unloaded cores; generator %.0f s (CPU, cached trajectories not counted). "
            "Wall time depends on the machine's load." % (
                args.cpu_total, args.cpu_total / 60.0 / args.jobs, args.jobs, args.gen_cpu), ""] + setup_text() + [""]


if __name__ == "__main__":
    sys.exit(main())
