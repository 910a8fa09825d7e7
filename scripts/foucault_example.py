#!/usr/bin/python3
"""The Florence Foucault pendulum (2021-09-17) end to end through cvg_ident (docs/examples/foucault.md).

Steps (every model equation is evaluated by the tool, never here):
  1. read ../shared/data/foucault_florence_2021/2021_09_17_14_57_N.csv (time;x;y [px]), drop the
     glitched frames at the start (implied bob speed > 3x the 99.9th percentile of the record) and
     write the trimmed raw t,f,g record into the work directory (never into the repository);
  2. `cvg_ident demod` (reference frequency estimated; windowed LS, one output per period, window
     two periods), `cvg_ident explain` (forward selection, --report for the orbit elements r, k,
     theta of the measured slow record), `cvg_ident identify` for the model ladder and
     `cvg_ident drift` for theta' (5.9) with its CI at the observed state;
  3. direct fits of the swing-plane azimuth phi = 2 theta (a pendulum's swing plane is the vector
     (f, g); theta of (5.2) is the n = 2 pattern angle, half of it): phi = a + b t, and
     phi = a + b t + c int(r k dt) (the Airy/split term of (5.9) is proportional to r k); the
     phase chi on int(r^2 dt) (amplitude-dependent frequency); CIs by Newey-West (Bartlett kernel,
     lag sqrt(n)) because the residuals wander slowly;
  4. figures (trajectory, r/k/phi with fits, precession estimates with CIs, ladder residuals) and a
     summary JSON (the regression test test/python/test_foucault_example.py reads the same numbers).

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
LADDER = ["linear", "cm_rate", "xi", "xi+cm_rate", "gamma_nl", "xi+kappa"]


def foucault_rate_deg_h():
    """Omega_z = Omega_earth sin(latitude): the swing plane turns at -Omega_z (clockwise from above)."""
    return EARTH_DEG_PER_H * math.sin(math.radians(LATITUDE_DEG))


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    if p.returncode != 0:
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


def read_residuals(path):
    out = {}
    with open(path) as fh:
        for row in csv.DictReader(fh):
            m = out.setdefault(row["model"], {"x": [], "radial": [], "tangential": []})
            for k in ("x", "radial", "tangential"):
                m[k].append(float(row[k]))
    return {k: {c: np.array(v) for c, v in m.items()} for k, m in out.items()}


def newey_west_fit(X, y, lag=None):
    """OLS (by lstsq) with the Newey-West (Bartlett) covariance; returns beta, cov, residuals."""
    n, k = X.shape
    beta, *_ = np.linalg.lstsq(X, y, rcond=None)
    e = y - X @ beta
    lag = int(math.ceil(math.sqrt(n))) if lag is None else lag
    u = X * e[:, None]
    s = u.T @ u
    for L in range(1, lag + 1):
        g = u[L:].T @ u[:-L]
        s += (1.0 - L / (lag + 1.0)) * (g + g.T)
    q, r = np.linalg.qr(X)
    rinv = np.linalg.solve(r, np.eye(k))
    bread = rinv @ rinv.T  # (X'X)^-1 through R, not by inverting X'X
    cov = bread @ s @ bread * n / (n - k)
    return beta, cov, e


def cumulative(t, v):
    """int_0^t v dt by the trapezoid rule."""
    return np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])


def phase_chi(q, theta):
    """Temporal phase chi of (5.2): c q1 + s q2 = r cos chi, c p1 + s p2 = -r sin chi, c, s of 2 theta."""
    c, s = np.cos(2 * theta), np.sin(2 * theta)
    return np.unwrap(np.arctan2(-(c * q["p1"] + s * q["p2"]), c * q["q1"] + s * q["q2"]))


def fit_entry(beta, cov, i, scale=1.0):
    v, sd = beta[i] * scale, math.sqrt(cov[i, i]) * abs(scale)
    return {"value": v, "std": sd, "ci_low": v - 1.96 * sd, "ci_high": v + 1.96 * sd}


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
    summary["demod_estimate_note"] = err.strip().splitlines()
    period = 2 * math.pi / omega
    run([args.tool, "demod", raw, "--omega", "%.10g" % omega, "--rate", "%.10g" % (1 / period),
         "--window", "%.10g" % (2 * period), "--out", slow])
    _, q = read_slow(slow)
    summary["n_slow"] = int(len(q["t"]))
    summary["period_s"] = period
    summary["length_m"] = GRAVITY / omega ** 2

    # 2. explain (forward selection) and the ladder.
    rep = os.path.join(args.work, "report")
    out, _ = run([args.tool, "explain", slow, "--mode", "free_decay", "--json",
                  os.path.join(args.work, "explain.json"), "--report", rep, "--no-figures"])
    with open(os.path.join(args.work, "explain.json")) as fh:
        ex = json.load(fh)
    summary["explain"] = {"stdout": out.strip().splitlines(), "selected": ex["selected"],
                          "unexplained": ex["unexplained"], "cause": ex["cause"],
                          "lack_of_fit": ex["lack_of_fit"]}
    meas = read_curves(os.path.join(rep, "curves.csv"), "measured")
    r, k, theta = meas["r"], meas["k"], meas["theta"]
    tt = meas["x"]
    state = {"r": float(np.median(r)), "k": float(np.median(k)), "theta": float(np.median(theta))}
    summary["state"] = state
    ladder = {}
    models = list(LADDER)
    final = "+".join(ex["selected"]) if ex["selected"] else "linear"
    if final not in models:
        models.append(final)
    for model in models:
        js = os.path.join(args.work, "id_%s.json" % model.replace("+", "_"))
        try:
            run([args.tool, "identify", slow, "--mode", "free_decay", "--model", model,
                 "--json", js])
        except RuntimeError as e:
            ladder[model] = {"error": str(e)}
            continue
        with open(js) as fh:
            est = json.load(fh)
        dj = js.replace(".json", "_drift.json")
        run([args.tool, "drift", "--params", js, "--r", repr(state["r"]), "--k", repr(state["k"]),
             "--theta", repr(state["theta"]), "--json", dj])
        with open(dj) as fh:
            drift = json.load(fh)
        ladder[model] = {"sigma": est["sigma"], "rank": est["rank"], "n_params": est["n_params"],
                         "unidentifiable": est.get("unidentifiable", []),
                         "parameters": est["parameters"],
                         "phi_rate_deg_h": phi_rate_from_drift(drift["drift"][0])}
    summary["ladder"] = ladder

    # 3. Direct fits. phi = 2 theta: the swing-plane azimuth in image axes.
    phi = np.unwrap(2 * theta)
    one = np.ones_like(tt)
    b1, c1, e1 = newey_west_fit(np.column_stack([one, tt]), phi)
    irk = cumulative(tt, r * k)
    b2, c2, e2 = newey_west_fit(np.column_stack([one, tt, irk]), phi)
    # The split term of (5.9), -(k / 2r) h_m cos 4(theta - alpha), is also proportional to k: how
    # well can the record tell it from the Airy-type r k term?
    ikr = cumulative(tt, k / r)
    corr_rk_kr = float(np.corrcoef(np.diff(irk), np.diff(ikr))[0, 1])
    chi = phase_chi(q if len(q["t"]) == len(tt) else {
        c: np.interp(tt, q["t"], q[c]) for c in ("q1", "p1", "q2", "p2")}, theta)
    ir2 = cumulative(tt, r ** 2 + k ** 2)
    b3, c3, _ = newey_west_fit(np.column_stack([one, tt, ir2]), chi)
    fits = {
        "phi_rate_linear_deg_h": fit_entry(b1, c1, 1, RAD_S_TO_DEG_H),
        "phi_rate_at_k0_deg_h": fit_entry(b2, c2, 1, RAD_S_TO_DEG_H),
        "phi_rk_coefficient": fit_entry(b2, c2, 2),
        "chi_r2_coefficient": fit_entry(b3, c3, 2),
        "phi_residual_rms_deg": float(np.degrees(np.std(e1))),
        "phi_residual_rms_rk_deg": float(np.degrees(np.std(e2))),
        "corr_rk_vs_k_over_r": corr_rk_kr,
        "n": int(len(tt)), "lag": int(math.ceil(math.sqrt(len(tt)))),
    }
    summary["direct"] = fits
    summary["k_over_r"] = {"start": float(k[0] / r[0]), "end": float(k[-1] / r[-1]),
                           "median": float(np.median(k / r))}
    summary["r_px"] = {"start": float(np.median(r[:10])), "end": float(np.median(r[-10:]))}
    summary["phi_deg"] = {"start": float(np.degrees(np.median(phi[:10]))),
                          "end": float(np.degrees(np.median(phi[-10:])))}
    summary["physics"] = physics(summary, fits, ladder)
    if not args.no_figures:
        figures(args, t, x, y, first, tt, r, k, phi, (b1, c1), (b2, c2, irk), summary,
                read_residuals(os.path.join(rep, "residuals.csv")), ex)
    return summary


def phi_rate_from_drift(point):
    """phi' = 2 theta' [deg/h] with its 95 % CI from one point of a `cvg_ident drift` JSON."""
    out = {"value": 2 * point["drift_rad_s"] * RAD_S_TO_DEG_H}
    if "std_rad_s" in point:
        out["std"] = 2 * point["std_rad_s"] * RAD_S_TO_DEG_H
        out["ci_low"] = 2 * point["ci_low_rad_s"] * RAD_S_TO_DEG_H
        out["ci_high"] = 2 * point["ci_high_rad_s"] * RAD_S_TO_DEG_H
    return out


def physics(summary, fits, ladder):
    """Pixel scale from the Airy precession and what it implies for the amplitude-frequency law.

    Airy: an elliptical swing of semi-axes a, b [m] precesses at (3/8) omega a b / L^2 in the sense
    of the bob's motion; in pixels (scale s px/m) phi' = c r k with c = (3/8) omega / (s^2 L^2), so
    the fitted r k coefficient gives s. A planar pendulum's frequency falls with amplitude,
    omega(a) = omega (1 - a^2 / (16 L^2)): in the model's terms (5.10), chi' = -(3/8) xi r^2 with an
    equivalent xi_pendulum = omega / (6 L^2 s^2) > 0 (softening).
    """
    omega, length = summary["omega_rad_s"], summary["length_m"]
    out = {"foucault_deg_h": foucault_rate_deg_h(), "record_h": summary["duration_s"] / 3600.0}
    out["expected_rotation_deg"] = out["foucault_deg_h"] * out["record_h"]
    c = fits["phi_rk_coefficient"]
    if c["value"] > 0:
        s = math.sqrt(3.0 / 8.0 * omega / (c["value"] * length ** 2))
        out["pixels_per_m_from_airy"] = s
        out["pixels_per_m_from_airy_std"] = 0.5 * s * c["std"] / c["value"]
        out["amplitude_m"] = summary["r_px"]["start"] / s
        out["xi_pendulum_expected"] = omega / (6 * length ** 2 * s ** 2)
    cx = fits["chi_r2_coefficient"]
    out["xi_from_chi"] = {"value": -8.0 / 3.0 * cx["value"], "std": 8.0 / 3.0 * cx["std"]}
    if "xi" in ladder and "parameters" in ladder["xi"]:
        out["xi_ladder"] = ladder["xi"]["parameters"]["xi"]
    # The ladder's single xi ties the precession to the amplitude-frequency law with the ratio of a
    # cubic spring (xi r k / 4 in phi'); a pendulum's precession coupling is 9x its frequency
    # coupling, and the observed frequency law has the opposite sign.
    rk = summary["state"]["r"] * summary["state"]["k"]
    if "xi_ladder" in out:
        out["ladder_xi_phi_rate_at_state_deg_h"] = (
            out["xi_ladder"]["value"] * rk / 4.0 * RAD_S_TO_DEG_H)
    out["airy_phi_rate_at_state_deg_h"] = c["value"] * rk * RAD_S_TO_DEG_H
    return out


def figures(args, t, x, y, first, tt, r, k, phi, fit1, fit2, summary, res, ex):
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

    (b1, c1), (b2, c2, irk) = fit1, fit2
    one = np.ones_like(tt)
    fig, ax = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    ax[0].plot(tt, r, "k.", ms=2)
    ax[0].set_ylabel("r [px]")
    ax[0].set_title("orbit elements (5.2) of the demodulated record; phi = 2 theta = swing azimuth")
    ax[1].plot(tt, k, "k.", ms=2)
    ax[1].set_ylabel("k [px]")
    ax[2].plot(tt, np.degrees(phi), "k.", ms=2, label="measured phi (image axes)")
    f1 = b1[0] + b1[1] * tt
    f2 = b2[0] + b2[1] * tt + b2[2] * irk
    d = summary["direct"]
    ax[2].plot(tt, np.degrees(f1), "r-", label="phi = a + b t: b = %.1f +/- %.1f deg/h (95 %%)"
               % (d["phi_rate_linear_deg_h"]["value"], 1.96 * d["phi_rate_linear_deg_h"]["std"]))
    ax[2].plot(tt, np.degrees(f2), "b-", label="a + b t + c int(r k): b = %.1f +/- %.1f deg/h"
               % (d["phi_rate_at_k0_deg_h"]["value"], 1.96 * d["phi_rate_at_k0_deg_h"]["std"]))
    fou = summary["physics"]["foucault_deg_h"]
    for sgn, sty in ((1, "g--"), (-1, "g:")):
        ax[2].plot(tt, np.degrees(f1[0]) + sgn * fou * (tt - tt[0]) / 3600, sty,
                   label="%+.2f deg/h (Foucault, 43.77 N)" % (sgn * fou))
    ax[2].set_ylabel("phi [deg]")
    ax[2].set_xlabel("t [s]")
    ax[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(args.figures, "foucault_orbit.png"), dpi=90)
    plt.close(fig)

    # Precession estimates with 95 % CIs.
    labels, vals, errs = [], [], []
    for name in ("phi_rate_linear_deg_h", "phi_rate_at_k0_deg_h"):
        e = d[name]
        labels.append({"phi_rate_linear_deg_h": "direct: phi = a + b t",
                       "phi_rate_at_k0_deg_h": "direct: + c int(r k) (k = 0)"}[name])
        vals.append(e["value"])
        errs.append(1.96 * e["std"])
    for model, v in summary["ladder"].items():
        if "phi_rate_deg_h" not in v or "std" not in v["phi_rate_deg_h"]:
            continue
        e = v["phi_rate_deg_h"]
        labels.append("model %s: 2 theta' (5.9)" % model)
        vals.append(e["value"])
        errs.append(0.5 * (e["ci_high"] - e["ci_low"]))
    fig, ax = plt.subplots(figsize=(9, 4.5))
    yy = np.arange(len(labels))
    ax.errorbar(vals, yy, xerr=errs, fmt="o", capsize=3)
    for sgn in (1, -1):
        ax.axvline(sgn * fou, color="g", ls="--")
    ax.axvline(0, color="k", lw=0.5)
    ax.set_yticks(yy)
    ax.set_yticklabels(labels, fontsize=8)
    ax.set_xlabel("swing-plane precession phi' in image axes [deg/h] (95 % CI); green: +/-10.40")
    fig.tight_layout()
    fig.savefig(os.path.join(args.figures, "foucault_precession.png"), dpi=90)
    plt.close(fig)

    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for i, comp in enumerate(("radial", "tangential")):
        for model, c in zip([m for m in res], ["#d62728", "#1f77b4", "#2ca02c", "#9467bd"]):
            ax[i].plot(res[model]["x"], res[model][comp], ".", ms=2, color=c, label=model)
        ax[i].set_ylabel(comp + " residual\n[equation units]")
    ax[0].set_title("equation residuals (2.8) of the ladder (explain: selected %s, lack-of-fit p = "
                    "%.2g)" % (ex["selected"] or "none", ex["lack_of_fit"]["p_value"]))
    ax[0].legend(fontsize=7, markerscale=4)
    ax[1].set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(os.path.join(args.figures, "foucault_residuals.png"), dpi=90)
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
