#!/usr/bin/python3
"""Drift validation (issue #26 item 4, docs/validation_drift.md): identify -> predict -> measure ->
compensate, for each preset and the terms that move the pattern at the whole-angle run's state.

Per case: `simulate --mode free_decay` with the case's effects, `identify` with the resonator's
terms (or, for a "missed" case, without the case's term), `simulate --mode whole_angle` of the same
resonator (seed differs), `drift --params EST --measured RUN --png`. Each case twice: identified
from the one free decay of the preset's drive state (the paper's experiment), and from --decays N
free decays started at r = 0.5 and N pattern angles over 90 deg, stacked in one `identify` (the
remedy for the loosely bound anisotropies of one decay; the verdict is the stacked run's). Reported: the fraction of theta
bins whose measured drift lies in the prediction's band (target >= 0.9) and the compensation gain
RMS(measured) / RMS(measured - predicted) (target >= 10 where the drift is large against the noise).
A model that leaves out a term the resonator has must visibly fail (band fraction or gain).

Thresholds fixed before the first run: band >= 0.9, gain >= 10; "large against the noise" = the
measured RMS drift above 20x the median measured interval half-width. Changed after the run of
29 Nov (stacked decays): the band criterion is now "agree", |measured - predicted| within the
root sum of squares of both 95 % half-widths, in >= 90 % of bins; "inside the prediction's band"
(still reported) fails a perfect prediction whose band is narrower than the measurement's.
With k held at 0 (ideal loops), theta' is moved by the linear terms (nu, b) and xi_diff only; xi,
kappa and xi_k act through r k (orbit_rates_chain_rule_test.cpp declares each term's effect).

Pooled check (--pool N, default 10): the "as shipped" case of each preset with 8 stacked decays
over N further seeds; agreement and "in band" counted over all seeds' bins with Wilson 95 %
intervals (one case is one draw: its bins all depend on the same few parameters). Target, fixed
before its first run: pooled agreement >= 0.90; median gain >= 10.
--pool-cases all (29 Nov, target the same, fixed before its first run): every case of the table
pooled, the added-term cases (xi_diff, xi_diff + gamma_nl) as well; a case identified without a
term the resonator has is expected to fail the pooled check where that term moves theta'.
--k0 F (29 Nov, later): the whole-angle loops hold k0 = F r0; the stacked decays then start at
quadrature +-k0 in turn (decays started at k = 0 bound the cubic terms' r k action too loosely),
and the added xi_diff is sized so that its own theta' swing at (r0, k0) is 0.3 of the preset's
peak drift there. Target the same, fixed before the first pooled run at k0 = 0.2. mems_ring also
has a case identified from one forced sweep (its experiment in the paper's section 4).
--jobs N: pooled seeds run N at a time. --cases A,B: only the pooled cases whose label holds A or B.
At k0 != 0 xi_k and kappa (the other terms that move theta' through r k) are added and left out
as xi_diff is, sized the same way.

usage: validate_drift.py [--out DIR] [--markdown FILE] [--seed N] [--decays N] [--pool N] [--pool-only]
                         [--pool-cases shipped|all] [--k0 FRACTION_OF_R0] [--jobs N]
                         [--cases LABEL_PART,...]
"""
import concurrent.futures
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")
PRESETS = ["mems_ring", "hrg_hemispherical", "quartz_cylinder"]
SWEEP_PRESETS = {"mems_ring"}  # identified from a forced sweep in the paper (section 4)


def arg(name, default):
    return type(default)(sys.argv[sys.argv.index(name) + 1]) if name in sys.argv else default


def run(args):
    p = subprocess.run([TOOL] + args, capture_output=True, text=True, timeout=1800)
    return p.returncode, p.stdout, p.stderr


def header(path):
    h = {}
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                break
            k, _, v = line[1:].partition(":")
            h[k.strip()] = v.strip()
    return h


# --k0 F: the quadrature the whole-angle loops hold, as a fraction of r0 (default 0). At k = 0 the
# cubic terms (xi, xi_k, kappa, xi_diff) do not move theta' (they act through k), so a left-out
# xi_diff shows only through the bias it leaves in the other parameters; at k0 != 0 directly.
K0_FRACTION = 0.0
JOBS = 1  # --jobs N: pooled seeds run N at a time
CASES = []  # --cases A,B: only the pooled cases whose label holds one of these


def drift_scale(truth, r0):
    """A size for xi_diff whose theta' is about twice the damping anisotropy's at r0."""
    bm = math.hypot(truth.get("b_c", 0.0), truth.get("b_s", 0.0))
    return max(2.0 * bm, 1e-4) / (r0 * r0)


def drift_curve(params, omega, work, tag, r0, k0):
    """theta' over a 36-point theta grid of the resonator `params` at (r0, k0), by `drift` [rad/s]."""
    tj = os.path.join(work, tag + "_size.json")
    gj = os.path.join(work, tag + "_size_grid.json")
    with open(tj, "w") as f:
        json.dump({"omega": omega, "parameters": params}, f)
    rc, _, err = run(["drift", "--params", tj, "--r", repr(r0), "--k", repr(k0), "--theta-grid", "36",
                      "--json", gj])
    if rc != 0:
        raise RuntimeError("drift (sizing): " + err.strip()[-200:])
    with open(gj) as f:
        return [g["drift_rad_s"] for g in json.load(f)["drift"]]


def term_size(truth, r0, work, preset, term):
    """A size for `term` (xi_k, kappa) whose own theta' swing at (r0, k0) is 0.3 of the preset's
    peak drift there, as xi_diff's (k0 != 0 only: these act through r k)."""
    k0 = K0_FRACTION * r0
    omega = float(header(os.path.join(work, preset + "_probe.csv"))["omega"])
    params = {k: v for k, v in truth.items() if k != "model"}
    base = drift_curve(params, omega, work, preset + "_base", r0, k0)
    with_unit = drift_curve(dict(params, **{term: params.get(term, 0.0) + 1.0}), omega, work,
                            preset + "_unit_" + term, r0, k0)
    unit = max(abs(a - b) for a, b in zip(with_unit, base))
    if unit <= 0.0:
        raise RuntimeError("%s = 1 does not move theta' at k0 = %g" % (term, k0))
    return 0.3 * max(abs(b) for b in base) / unit


def xi_diff_size(truth, r0, work, preset):
    """At k0 = 0 xi_diff does not move theta': sized from the damping anisotropy (drift_scale), as
    in the runs of 27-29 Nov. At k0 != 0 (29 Nov, later): sized so that its own theta' swing at
    (r0, k0) is 0.3 of the preset's peak drift there: leaving it out must cost the 10x target on
    every preset (measured: gains 4.3-8.4x; the fit without it absorbs part of it). xi_diff/xi comes out 2.8 (mems_ring), 5.7
    (hrg), 37 (quartz): sizes chosen to be seen against each preset's drift, not typical values."""
    if K0_FRACTION == 0.0:
        return drift_scale(truth, r0)
    k0 = K0_FRACTION * r0
    omega = float(header(os.path.join(work, preset + "_probe.csv"))["omega"])
    params = {k: v for k, v in truth.items() if k != "model"}
    base = drift_curve(params, omega, work, preset + "_base", r0, k0)
    with_unit = drift_curve(dict(params, xi_diff=1.0), omega, work, preset + "_unit", r0, k0)
    unit = max(abs(a - b) for a, b in zip(with_unit, base))
    base = max(abs(b) for b in base)
    if unit <= 0.0:
        raise RuntimeError("xi_diff = 1 does not move theta' at k0 = %g" % k0)
    print("sizing", preset, "peak drift", base, "rad/s; xi_diff = 1 alone:", unit, flush=True)
    return 0.3 * base / unit


def case_list(preset, truth, r0, work="."):
    base_terms = [t for t in truth.get("model", "linear").split("+") if t != "linear"]
    v = xi_diff_size(truth, r0, work, preset)
    both = "gamma_nl=%g" % (0.5 * abs(truth.get("gamma", 0.01)) / (r0 * r0))
    return [
        ("resonator as shipped", [], base_terms),
        ("+ xi_diff", ["xi_diff=%g" % v], base_terms + ["xi_diff"]),
        ("+ xi_diff, identified without it", ["xi_diff=%g" % v], base_terms),
        ("+ xi_diff + gamma_nl (two at once)", ["xi_diff=%g" % v, both], base_terms + ["xi_diff", "gamma_nl"]),
    ] + ([("sweep: resonator as shipped", [], base_terms)] if preset in SWEEP_PRESETS else []) + \
        [c for term in (("xi_k", "kappa") if K0_FRACTION != 0.0 else ())
         for c in term_cases(truth, r0, work, preset, base_terms, term)]


def term_cases(truth, r0, work, preset, base_terms, term):
    """At k0 != 0: the other terms that move theta' through r k, added and left out (30 Nov)."""
    e = ["%s=%g" % (term, term_size(truth, r0, work, preset, term))]
    return [("+ " + term, e, base_terms + [term]), ("+ " + term + ", identified without it", e, base_terms)]


def one(preset, label, effects, terms, work, seed, decays):
    """One case. A label holding "sweep:" is identified from one forced sweep of the preset (its
    forced section; mems_ring's own experiment, the paper's section 4) instead of free decays."""
    sweep = "sweep:" in label
    tag = preset + "_" + "".join(c if c.isalnum() else "_" for c in label) + "_%d" % decays
    fx = []
    for e in effects:
        fx += ["--effect", e]
    fd = os.path.join(work, tag + "_fd.csv")
    wa = os.path.join(work, tag + "_wa.csv")
    est = os.path.join(work, tag + "_est.json")
    out = os.path.join(work, tag + "_drift.json")
    png = os.path.join(work, tag + "_drift.png")
    mode = "forced" if sweep else "free_decay"
    rc, _, err = run(["simulate", "--preset", preset, "--mode", mode, "--seed", str(seed), "--out", fd] + fx)
    if rc != 0:
        return {"error": "simulate %s: " % mode + err.strip()[-200:]}
    inputs = [fd]
    if decays > 1 and not sweep:
        inputs = []
        for k in range(decays):
            fk = os.path.join(work, tag + "_fd%d.csv" % k)
            theta = k * (math.pi / 2) / decays
            # At k0 != 0 the decays start at quadrature +-k0 in turn: decays at k = 0 bound the r k
            # action of the cubic terms (which moves theta' at k0) only loosely (29 Nov, --k0 0.2).
            kstart = (1 if k % 2 == 0 else -1) * K0_FRACTION * 0.5
            rc, _, err = run(["simulate", "--preset", preset, "--mode", "free_decay", "--seed",
                              str(seed + 10 * k), "--start", "0.5,%r,%r" % (kstart, theta), "--out", fk] + fx)
            if rc != 0:
                return {"error": "simulate free decay %d: " % k + err.strip()[-200:]}
            inputs.append(fk)
    model = "+".join(sorted(set(terms), key=terms.index)) if terms else "linear"
    rc, _, err = run(["identify"] + inputs + ["--mode", mode, "--model", model, "--json", est])
    if rc not in (0, 1) or not os.path.exists(est):
        return {"error": "identify: " + err.strip()[-200:]}
    # The walk: 4x the largest true drift over theta (slower, and the pattern would lock where the
    # drift cancels the walk), over 1.5 periods of theta.
    h = header(fd)
    truth = {k[len("truth_"):]: float(v) for k, v in h.items() if k.startswith("truth_") and k != "truth_model"}
    tj = os.path.join(work, tag + "_truth.json")
    with open(tj, "w") as f:
        json.dump({"omega": float(h["omega"]), "parameters": truth}, f)
    gj = os.path.join(work, tag + "_grid.json")
    k0 = K0_FRACTION * 0.5
    rc, _, err = run(["drift", "--params", tj, "--r", "0.5", "--k", repr(k0), "--theta-grid", "36", "--json", gj])
    if rc != 0:
        return {"error": "drift grid: " + err.strip()[-200:]}
    with open(gj) as f:
        peak = max(abs(g["drift_rad_s"]) for g in json.load(f)["drift"])
    walk = max(4.0 * peak, 1e-6)
    duration = 1.5 * (math.pi / 2) / walk
    rc, _, err = run(["simulate", "--preset", preset, "--mode", "whole_angle", "--seed", str(seed + 1),
                      "--walk", repr(walk), "--duration", repr(duration), "--quadrature", repr(k0),
                      "--out", wa] + fx)
    if rc != 0:
        return {"error": "simulate whole_angle: " + err.strip()[-200:]}
    rc, _, err = run(["drift", "--params", est, "--measured", wa, "--json", out, "--png", png])
    if rc != 0:
        return {"error": "drift --measured: " + err.strip()[-300:], "model": model}
    with open(out) as f:
        j = json.load(f)
    inside = agree = total = 0
    halfwidths = []
    for m, mci, p, pci in zip(j["measured_deg_h"], j["measured_ci"], j["predicted_deg_h"], j["predicted_ci"]):
        if m is None:
            continue
        total += 1
        inside += pci[0] <= m <= pci[1]
        hm, hp = 0.5 * (mci[1] - mci[0]), 0.5 * (pci[1] - pci[0])
        # Agreement within both intervals: a perfect prediction (a band of zero width) still meets
        # it, where "inside the prediction's band" only holds while that band is the wider one.
        agree += abs(m - p) <= math.hypot(hm, hp)
        halfwidths.append(hm)
    large = j["rms_measured_deg_h"] > 20 * statistics.median(halfwidths)
    band = inside / total if total else 0.0
    agreement = agree / total if total else 0.0
    gain = j["compensation_gain"] or 0.0
    return {"model": model, "band": band, "agreement": agreement, "bins": total, "gain": gain,
            "large": large, "rms_measured": j["rms_measured_deg_h"],
            "rms_after": j["residual_after_compensation_deg_h"],
            "png": png, "pass": agreement >= 0.9 and (gain >= 10 or not large)}


def wilson(k, n, z=1.959963984540054):
    if n == 0:
        return float("nan"), float("nan")
    p = k / n
    c = (p + z * z / (2 * n)) / (1 + z * z / n)
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return c - h, c + h


def pooled_rows(work, seed, decays, pool, all_cases=False):
    lines = ["", "Pooled over %d seeds (%s, %d stacked decays; target: agreement >= 0.90, median gain "
             ">= 10):" % (
                 pool, "every case" if all_cases else "as shipped", decays), "",
             "| preset | case | bins | agree | Wilson 95 % | in band | median gain (min) | verdict |",
             "|---|---|---|---|---|---|---|---|"]
    for preset in PRESETS:
        probe = os.path.join(work, preset + "_probe.csv")
        h = header(probe)
        truth = {k[len("truth_"):]: float(v) for k, v in h.items() if k.startswith("truth_") and k != "truth_model"}
        truth["model"] = h.get("truth_model", "linear")
        shipped = [t for t in truth["model"].split("+") if t != "linear"]
        cases = case_list(preset, truth, 0.5, work) if all_cases else [("resonator as shipped", [], shipped)]
        for label, effects, terms in cases:
            if CASES and not any(c in label for c in CASES):
                continue
            lines.append(pooled_case(work, seed, decays, pool, preset, label, effects, terms))
    return lines


def pooled_case(work, seed, decays, pool, preset, label, effects, terms):
    agree = inside = total = 0
    gains = []
    with concurrent.futures.ThreadPoolExecutor(JOBS) as ex:
        results = list(ex.map(lambda k: one(preset, "pool %d %s" % (k, label), effects, terms, work,
                                            seed + 1000 * (k + 1), decays), range(pool)))
    for k, r in enumerate(results):
        if "error" in r:
            print("pool error", preset, k, r["error"], flush=True)
            continue
        agree += round(r["agreement"] * r["bins"])
        inside += round(r["band"] * r["bins"])
        total += r["bins"]
        gains.append(r["gain"])
    lo, hi = wilson(agree, total)
    mg = statistics.median(gains) if gains else 0.0
    ok = bool(total) and agree / total >= 0.9 and mg >= 10  # the target as first fixed
    verdict = ("fails, as it must" if not ok else "PASSES (should fail)") if "without" in label else \
        ("pass" if ok else "FAIL")
    print("pooled", preset, label, agree, total, mg, flush=True)
    return "| %s | %s | %d | %.3f | [%.3f, %.3f] | %.3f | %.1f (%.1f) | %s |" % (
        preset, label, total, agree / total if total else 0, lo, hi, inside / total if total else 0, mg,
        min(gains) if gains else 0, verdict)


def main():
    global K0_FRACTION, JOBS, CASES
    K0_FRACTION = arg("--k0", 0.0)
    JOBS = arg("--jobs", 1)
    CASES = [c for c in arg("--cases", "").split(",") if c]
    seed = arg("--seed", 4100)
    pool = arg("--pool", 10)
    decays = arg("--decays", 8)
    work = arg("--out", os.path.join(ROOT, "build", "validate_drift"))
    md = arg("--markdown", "")
    os.makedirs(work, exist_ok=True)
    rows = []
    r0 = 0.5
    for preset in PRESETS:
        probe = os.path.join(work, preset + "_probe.csv")
        run(["simulate", "--preset", preset, "--mode", "free_decay", "--seed", "1", "--out", probe])
        h = header(probe)
        truth = {k[len("truth_"):]: float(v) for k, v in h.items() if k.startswith("truth_") and k != "truth_model"}
        truth["model"] = h.get("truth_model", "linear")
        for label, effects, terms in ([] if "--pool-only" in sys.argv else case_list(preset, truth, r0, work)):
            single = one(preset, label, effects, terms, work, seed, 1)
            res = one(preset, label, effects, terms, work, seed, decays)
            res.update({"preset": preset, "case": label, "effects": effects, "single": single})
            rows.append(res)
            print(json.dumps(res), flush=True)
    lines = ["| preset | case | model identified | one decay: in band, agree, gain | %d decays: bins in band | "
             "agree | gain | RMS drift -> after [deg/h] | verdict |" % decays,
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        sg = r["single"]
        one_col = "-" if "error" in sg else "%.2f, %.2f, %.1f" % (sg["band"], sg["agreement"], sg["gain"])
        if "error" in r:
            lines.append("| %s | %s | %s | %s | - | - | - | - | error: %s |" % (
                r["preset"], r["case"], r.get("model", ""), one_col, r["error"].replace("|", "/")))
            continue
        expect_fail = "without" in r["case"]
        verdict = ("fails, as it must" if not r["pass"] else "PASSES (should fail)") if expect_fail else \
            ("pass" if r["pass"] else "FAIL")
        lines.append("| %s | %s | %s | %s | %.2f of %d | %.2f | %.1f | %.3g -> %.3g | %s |" % (
            r["preset"], r["case"], r["model"], one_col, r["band"], r["bins"], r["agreement"], r["gain"],
            r["rms_measured"], r["rms_after"], verdict))
    if pool > 0:
        lines += pooled_rows(work, seed, decays, pool, arg("--pool-cases", "shipped") == "all")
    table = "\n".join(lines)
    print(table)
    if md:
        with open(md, "w") as f:
            f.write("<!-- written by scripts/validation/validate_drift.py --seed %d --decays %d -->\n%s\n" % (
                seed, decays, table))


if __name__ == "__main__":
    main()
