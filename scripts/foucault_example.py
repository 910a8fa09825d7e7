#!/usr/bin/python3
"""The Florence Foucault pendulum (2021-09-17) end to end through cvg_ident (docs/examples/foucault.md).

Every number of the write-up comes from cvg_ident's output; this script only prepares the input,
runs the commands, reads their JSON and does arithmetic on it (a sum of two parameters with its
covariance, a correlation, unit conversions):
  1. read ../shared/data/foucault_florence_2021/2021_09_17_14_57_N.csv (time;x;y [px]), drop the
     glitched frames at the start (implied bob speed > 3x the 99.9th percentile of the record) and
     write the trimmed raw t,f,g record into the work directory (never into the repository);
  2. `cvg_ident demod` (reference frequency estimated; windowed LS, one output per period, window
     two periods);
  3. `cvg_ident explain` (what the tool selects on its own; --report for the orbit elements r, k,
     theta of the measured slow record);
  4. `cvg_ident identify` for the paper's cubic (linear+xi) and the extended model with the second
     cubic invariant (linear+xi+xi_k, docs/paper.md "The second cubic invariant"), and the linear
     base for reference; no frequency-drift term (a pendulum's natural frequency does not drift);
  5. `cvg_ident drift` with each model at the record's median state: the swing-plane rate
     phi' = 2 theta' of (5.9) (phi, the angle of the vector (f, g), is twice the n = 2 pattern
     angle theta of (5.2)) at the observed quadrature k and at k = 0 (Airy's r k term removed), and
     the amplitude envelope's decay -2 r'/r of (5.7) with the Q it implies;
  6. figures (trajectory, orbit elements, swing-plane rates) and a summary JSON that the regression
     test test/python/test_foucault_example.py checks against the numbers quoted in the write-up.

Usage: foucault_example.py [--tool bin/cvg_ident] [--data CSV] [--work DIR] [--figures DIR]
                           [--summary FILE] [--no-figures]
"""
import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.environ.get("CVG_BENCH_ROOT", os.path.join(HERE, ".."))
DATA = os.path.join(ROOT, "..", "shared", "data", "foucault_florence_2021",
                    "2021_09_17_14_57_N.csv")
LATITUDE_DEG = 43.77          # Florence
EARTH_DEG_PER_H = 15.041      # sidereal rotation rate
GRAVITY = 9.806               # m/s^2 at Florence's latitude (43.8 deg), sea level
RAD_S_TO_DEG_H = 180.0 / math.pi * 3600.0
PAPER_CUBIC = "xi"            # the paper's one-parameter cubic
EXTENDED = "xi+xi_k"          # with the second cubic invariant
LADDER = ["linear", PAPER_CUBIC, EXTENDED]
# Parameters of the linear base a single standing wave cannot separate (docs/paper.md item 11).
LINEAR = ["gamma", "nu", "b_c", "b_s", "c_m", "n", "h_c", "h_s"]


def foucault_rate_deg_h():
    """Omega_z = Omega_earth sin(latitude): the swing plane turns at -Omega_z (clockwise from above)."""
    return EARTH_DEG_PER_H * math.sin(math.radians(LATITUDE_DEG))


def run(cmd, allowed=(0,)):
    """Runs a cvg_ident command; identify exits 1 (with its JSON written) when the data cannot
    identify every parameter, which the write-up reports rather than hides."""
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    if p.returncode not in allowed:
        raise RuntimeError("%s failed (exit %d): %s" % (" ".join(cmd), p.returncode, p.stderr))
    return p.stdout, p.stderr


def load_raw(path):
    d = np.genfromtxt(path, delimiter=";", names=True)
    return d["time"], d["x"].astype(float), d["y"].astype(float)


def glitch_trim(t, x, y):
    """Index of the first kept sample: after the last implausibly fast step in the first 1 %."""
    speed = np.hypot(np.diff(x), np.diff(y)) / np.diff(t)
    limit = 3.0 * np.percentile(speed, 99.9)
    head = max(10, len(t) // 100)
    bad = np.where(speed[:head] > limit)[0]
    return (int(bad[-1]) + 1 if len(bad) else 0), float(limit), speed


def read_slow(path):
    omega = None
    rows = []
    with open(path) as fh:
        for line in fh:
            if line.startswith("#"):
                m = re.match(r"#\s*omega:\s*(\S+)", line)
                if m:
                    omega = float(m.group(1))
                continue
            rows.append(line.strip())
    data = list(csv.DictReader(rows))
    cols = {k: np.array([float(r[k]) for r in data]) for k in ("t", "q1", "p1", "q2", "p2")}
    return omega, cols


def read_curves(path, model):
    out = {}
    with open(path) as fh:
        for row in csv.DictReader(fh):
            if row["model"] != model:
                continue
            for k, v in row.items():
                if k != "model":
                    out.setdefault(k, []).append(float(v))
    return {k: np.array(v) for k, v in out.items()}


def interval(value, std, quantile):
    return {"value": value, "std": std, "ci_low": value - quantile * std,
            "ci_high": value + quantile * std}


def combination(est, weights):
    """A linear combination of the tool's estimates with its CI from the tool's covariance and the
    tool's own interval quantile (ci half-width / std of the parameters)."""
    names = est["covariance"]["names"]
    cov = np.array(est["covariance"]["matrix"])
    w = np.array([weights.get(n, 0.0) for n in names])
    value = sum(weights[n] * est["parameters"][n]["value"] for n in weights)
    p = est["parameters"][next(iter(weights))]
    quantile = (p["ci_high"] - p["value"]) / p["std"]
    return interval(value, math.sqrt(max(0.0, w @ cov @ w)), quantile)


def correlations(est, names):
    """The largest |correlation| of the tool's covariance among the named parameters."""
    all_names = est["covariance"]["names"]
    cov = np.array(est["covariance"]["matrix"])
    idx = [all_names.index(n) for n in names if n in all_names]
    sd = np.sqrt(np.diag(cov))
    best = (0.0, None, None)
    for a in range(len(idx)):
        for b in range(a + 1, len(idx)):
            i, j = idx[a], idx[b]
            c = cov[i, j] / (sd[i] * sd[j])
            if abs(c) > abs(best[0]):
                best = (float(c), all_names[i], all_names[j])
    return {"corr": best[0], "pair": [best[1], best[2]]}


def drift_at(args, params_json, r, k, theta, out_json):
    run([args.tool, "drift", "--params", params_json, "--r", repr(r), "--k", repr(k), "--theta",
         repr(theta), "--json", out_json])
    with open(out_json) as fh:
        return json.load(fh)


def phi_rate(point):
    """phi' = 2 theta' [deg/h] with its CI from one point of a `cvg_ident drift` JSON."""
    return {"value": 2 * point["drift_rad_s"] * RAD_S_TO_DEG_H,
            "std": 2 * point["std_rad_s"] * RAD_S_TO_DEG_H,
            "ci_low": 2 * point["ci_low_rad_s"] * RAD_S_TO_DEG_H,
            "ci_high": 2 * point["ci_high_rad_s"] * RAD_S_TO_DEG_H}


def analyse(args):
    t, x, y = load_raw(args.data)
    first, limit, speed = glitch_trim(t, x, y)
    os.makedirs(args.work, exist_ok=True)
    raw = os.path.join(args.work, "trimmed_raw.csv")
    with open(raw, "w") as fh:
        fh.write("t,f,g\n")
        for i in range(first, len(t)):
            fh.write("%.6f,%g,%g\n" % (t[i], x[i], y[i]))
    summary = {"data": os.path.abspath(args.data), "n_samples": int(len(t)),
               "duration_s": float(t[-1] - t[0]), "trimmed_samples": first,
               "trimmed_until_s": float(t[first - 1]) if first else 0.0,
               "first_kept_s": float(t[first]), "speed_limit_px_s": limit,
               "max_glitch_speed_px_s": float(speed[:first].max()) if first else 0.0,
               "max_kept_speed_px_s": float(speed[first:].max()),
               "median_step_s": float(np.median(np.diff(t[first:])))}

    # 1. Reference frequency (estimated by the tool), then one output per period, window 2 periods.
    slow = os.path.join(args.work, "slow.csv")
    _, err = run([args.tool, "demod", raw, "--out", slow])
    m = re.search(r"W\s*=\s*([0-9.eE+-]+)\s*\+/-\s*([0-9.eE+-]+)", err)
    omega, _ = read_slow(slow)
    summary["omega_rad_s"] = omega
    summary["omega_std_rad_s"] = float(m.group(2)) if m else None
    period = 2 * math.pi / omega
    run([args.tool, "demod", raw, "--omega", "%.10g" % omega, "--rate", "%.10g" % (1 / period),
         "--window", "%.10g" % (2 * period), "--out", slow])
    _, q = read_slow(slow)
    summary["n_slow"] = int(len(q["t"]))
    summary["period_s"] = period
    summary["length_m"] = GRAVITY / omega ** 2

    # 2. explain: what the tool selects on its own.
    rep = os.path.join(args.work, "report")
    out, _ = run([args.tool, "explain", slow, "--mode", "free_decay", "--json",
                  os.path.join(args.work, "explain.json"), "--report", rep, "--no-figures"])
    with open(os.path.join(args.work, "explain.json")) as fh:
        ex = json.load(fh)
    summary["explain"] = {"stdout": out.strip().splitlines(), "selected": ex["selected"],
                          "unexplained": ex["unexplained"], "cause": ex["cause"],
                          "lack_of_fit": ex["lack_of_fit"], "baseline": ex["baseline"],
                          "steps": ex["steps"]}
    meas = read_curves(os.path.join(rep, "curves.csv"), "measured")
    r, k, theta, tt = meas["r"], meas["k"], meas["theta"], meas["x"]
    state = {"r": float(np.median(r)), "k": float(np.median(k)), "theta": float(np.median(theta))}
    summary["state"] = state
    summary["k_over_r"] = {"start": float(k[0] / r[0]), "end": float(k[-1] / r[-1]),
                           "median": float(np.median(k / r))}
    summary["r_px"] = {"start": float(np.median(r[:10])), "end": float(np.median(r[-10:]))}
    phi = np.unwrap(2 * theta)
    summary["phi_deg"] = {"start": float(np.degrees(np.median(phi[:10]))),
                          "end": float(np.degrees(np.median(phi[-10:])))}

    # The envelope's decay over the whole record from the tool's amplitude r (medians of the first
    # and last 10 slow samples): r ~ exp(-omega t / (2 Q)).
    span = float(tt[-1] - tt[0])
    summary["Q_envelope_record"] = omega * span / (2 * math.log(summary["r_px"]["start"] /
                                                                 summary["r_px"]["end"]))

    # 3. The ladder: identify (LS, and the output-error fit by Ceres for the cubic models), then
    # drift at the median state (observed k, and k = 0).
    ladder = {}
    runs = [(m, "ls") for m in LADDER] + [(m, "ceres") for m in (PAPER_CUBIC, EXTENDED)]
    for model, method in runs:
        key = model if method == "ls" else model + " (ceres)"
        js = os.path.join(args.work, "id_%s_%s.json" % (model.replace("+", "_"), method))
        run([args.tool, "identify", slow, "--mode", "free_decay", "--model", model, "--method",
             method, "--json", js], allowed=(0, 1))
        with open(js) as fh:
            est = json.load(fh)
        at_state = drift_at(args, js, state["r"], state["k"], state["theta"],
                            js.replace(".json", "_drift.json"))
        at_k0 = drift_at(args, js, state["r"], 0.0, state["theta"],
                         js.replace(".json", "_drift_k0.json"))
        entry = {"sigma": est["sigma"], "rank": est["rank"], "n_params": est["n_params"],
                 "unidentifiable": est.get("unidentifiable", []),
                 "parameters": est["parameters"],
                 "Q_from_gamma": omega / est["parameters"]["gamma"]["value"],
                 "phi_rate_deg_h": phi_rate(at_state["drift"][0]),
                 "phi_rate_k0_deg_h": phi_rate(at_k0["drift"][0]),
                 "envelope": at_state["envelope"],
                 "max_linear_corr": correlations(est, LINEAR)}
        if "xi" in est["parameters"]:
            # Precession coupling of (5.9): theta' = (xi + xi_k) r k / 8.
            weights = {"xi": 1.0}
            if "xi_k" in est["parameters"]:
                weights["xi_k"] = 1.0
            entry["precession_coupling"] = combination(est, weights)
        ladder[key] = entry
    summary["ladder"] = ladder
    summary["physics"] = physics(summary)
    if not args.no_figures:
        figures(args, t, x, y, first, tt, r, k, phi, summary)
    return summary


def physics(summary):
    """What the extended model's numbers mean for a pendulum.

    Airy: an elliptical swing of semi-axes a, b [m] precesses at (3/8) omega a b / L^2 in the sense
    of the bob's motion; the model's swing-plane term is phi' = 2 (xi + xi_k) r k / 8, so in pixels
    (scale s px/m) xi + xi_k = (3/2) omega / (s^2 L^2) > 0 whatever the camera's mirror (r k and
    phi flip together). The pendulum's own frequency law is xi = omega / (6 L^2 s^2) > 0 (softening).
    """
    omega, length = summary["omega_rad_s"], summary["length_m"]
    out = {"foucault_deg_h": foucault_rate_deg_h(), "record_h": summary["duration_s"] / 3600.0}
    ext = summary["ladder"][EXTENDED]
    c = ext["precession_coupling"]
    rk = summary["state"]["r"] * summary["state"]["k"]
    out["airy_part_at_state_deg_h"] = 2 * c["value"] * rk / 8 * RAD_S_TO_DEG_H
    if c["value"] > 0:
        s = math.sqrt(1.5 * omega / (c["value"] * length ** 2))
        out["pixels_per_m_from_coupling"] = s
        out["amplitude_m"] = summary["r_px"]["start"] / s
        out["xi_pendulum_expected"] = omega / (6 * length ** 2 * s ** 2)
    paper = summary["ladder"][PAPER_CUBIC]
    out["sigma_gain_over_paper_cubic"] = paper["sigma"] / ext["sigma"]
    out["sigma_gain_over_linear"] = summary["ladder"]["linear"]["sigma"] / ext["sigma"]
    out["sigma_gain_over_paper_cubic_ceres"] = (summary["ladder"][PAPER_CUBIC + " (ceres)"]["sigma"]
                                                / summary["ladder"][EXTENDED + " (ceres)"]["sigma"])
    return out


def figures(args, t, x, y, first, tt, r, k, phi, summary):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(args.figures, exist_ok=True)

    fig, ax = plt.subplots(1, 2, figsize=(11, 5))
    sc = ax[0].scatter(x[first:], y[first:], c=t[first:], s=1, cmap="viridis")
    ax[0].plot(x[:first + 1], y[:first + 1], "r.-", label="dropped glitch frames (t < %.2f s)"
               % t[first])
    ax[0].set_xlabel("x [px]")
    ax[0].set_ylabel("y [px] (down)")
    ax[0].invert_yaxis()
    ax[0].set_aspect("equal")
    ax[0].legend(loc="upper right", fontsize=8)
    ax[0].set_title("bob track in the image (colour = time)")
    fig.colorbar(sc, ax=ax[0], label="t [s]")
    sel = (t > 700) & (t < 712)
    ax[1].plot(t[sel], x[sel] - x.mean(), ".-", label="x - mean")
    ax[1].plot(t[sel], y[sel] - y.mean(), ".-", label="y - mean")
    ax[1].set_xlabel("t [s]")
    ax[1].set_ylabel("[px]")
    ax[1].set_title("12 s of the raw track: irregular frames, median step %.3f s"
                    % summary["median_step_s"])
    ax[1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.figures, "foucault_trajectory.png"), dpi=90)
    plt.close(fig)

    fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    ax[0].plot(tt, r, "k.", ms=2)
    ax[0].set_ylabel("r [px]")
    ax[0].set_title("orbit elements (5.2) of the demodulated record (cvg_ident explain --report)")
    ax[1].plot(tt, k, "k.", ms=2)
    ax[1].set_ylabel("k [px]")
    ax[2].plot(tt, np.degrees(phi), "k.", ms=2, label="phi = 2 theta, swing azimuth (image axes)")
    ax[2].set_ylabel("phi [deg]")
    ax[2].set_xlabel("t [s]")
    ax[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(args.figures, "foucault_orbit.png"), dpi=90)
    plt.close(fig)

    # Swing-plane rates of the ladder (cvg_ident drift) with their 95 % CIs.
    labels, vals, lo, hi = [], [], [], []
    for model, v in summary["ladder"].items():
        for key, what in (("phi_rate_deg_h", "at the observed k"),
                          ("phi_rate_k0_deg_h", "at k = 0 (Airy term removed)")):
            e = v[key]
            labels.append("%s: %s" % (model, what))
            vals.append(e["value"])
            lo.append(e["value"] - e["ci_low"])
            hi.append(e["ci_high"] - e["value"])
    fig, ax = plt.subplots(figsize=(9, 4))
    yy = np.arange(len(labels))
    ax.errorbar(vals, yy, xerr=[lo, hi], fmt="o", capsize=3)
    fou = summary["physics"]["foucault_deg_h"]
    ax.axvline(fou, color="g", ls="--", label="Foucault, 43.77 N: %.2f deg/h" % fou)
    ax.axvline(0, color="k", lw=0.5)
    ax.set_yticks(yy)
    ax.set_yticklabels(labels, fontsize=8)
    ax.set_xlabel("swing-plane rate phi' = 2 theta' of (5.9), image axes [deg/h] (95 % CI)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.figures, "foucault_precession.png"), dpi=90)
    plt.close(fig)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--tool", default=os.path.join(ROOT, "bin", "cvg_ident"))
    ap.add_argument("--data", default=DATA)
    ap.add_argument("--work", default="/tmp/foucault_example")
    ap.add_argument("--figures", default=os.path.join(ROOT, "docs", "examples"))
    ap.add_argument("--summary", default="")
    ap.add_argument("--no-figures", action="store_true")
    args = ap.parse_args(argv)
    summary = analyse(args)
    text = json.dumps(summary, indent=1, default=float)
    if args.summary:
        with open(args.summary, "w") as fh:
            fh.write(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
