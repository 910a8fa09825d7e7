#!/usr/bin/python3
"""Figures and a Markdown summary for `cvg_ident explain --report DIR`.

Reads what the tool writes into DIR (no model equation is evaluated here; every model curve comes
from the C++ core):
  explain.json   the explain JSON of interfaces.md (mode, baseline, steps, selected, cause, ...)
  curves.csv     model,x,q1,p1,q2,p2,A,B,phase_a,phase_b,r,k,theta
                 model = "measured" or a model spec ("linear", "linear+xi", ...); x = t [s] for free
                 decay, omega0 [rad/s] for a forced sweep; A = sqrt(q1^2+p1^2), B = sqrt(q2^2+p2^2),
                 phases atan2(p, q) [rad]; r, k, theta the orbit elements (5.2)
  residuals.csv  model,x,radial,tangential,amp2,theta  equation-error residuals of (2.8)/(3.4) per
                 block/point, projected on the amplitude (radial) and phase (tangential) directions
  signature.csv  model,variable,component,bin_center,mean,sem  binned residual means
Writes into DIR: response.png (forced) or slow.png + orbit.png + measured.png (free decay), residuals.png,
signature.png and report.md.

Usage: explain_report.py DIR
"""
import csv
import json
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLORS = ["#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"]


def read_table(path):
    """CSV -> dict of column name -> list (floats where they parse), grouped by 'model'."""
    groups = defaultdict(lambda: defaultdict(list))
    order = []
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            m = row["model"]
            if m not in groups:
                order.append(m)
            for key, val in row.items():
                if key == "model":
                    continue
                try:
                    groups[m][key].append(float(val))
                except (TypeError, ValueError):
                    groups[m][key].append(val)
    return groups, order


def model_label(model, explanation):
    if model == explanation["baseline"]["model"]:
        return "%s (sigma %.3g)" % (model, explanation["baseline"]["sigma"])
    for step in explanation.get("steps", []):
        if step["model"] == model:
            return "%s (sigma %.3g)" % (model, step["sigma"])
    return model


def ladder(explanation):
    """Models in the order the selection tried them: baseline, then each accepted step."""
    models = [explanation["baseline"]["model"]]
    for step in explanation.get("steps", []):
        if step.get("accepted", True) and step["model"] not in models:
            models.append(step["model"])
    final = explanation.get("final", {}).get("model")
    if final and final not in models:
        models.append(final)
    return models


def x_axis(mode, values):
    if mode == "forced":
        return [v / (2.0 * math.pi) for v in values], "drive frequency omega0 / 2 pi [Hz]"
    return values, "time t [s]"


def plot_forced_response(curves, order, explanation, out_dir):
    models = [m for m in ladder(explanation) if m in curves]
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5), sharex=True)
    panels = [("A", "A = sqrt(q1^2 + p1^2)"), ("B", "B = sqrt(q2^2 + p2^2)"),
              ("phase_a", "phase of f: atan2(p1, q1) [rad]"),
              ("phase_b", "phase of g: atan2(p2, q2) [rad]")]
    meas = curves["measured"]
    xm, xlabel = x_axis("forced", meas["x"])
    for ax, (key, title) in zip(axes.flat, panels):
        ax.plot(xm, meas[key], "o", ms=4, mfc="none", color="k", label="measured")
        for i, m in enumerate(models):
            xs, _ = x_axis("forced", curves[m]["x"])
            ax.plot(xs, curves[m][key], "-", lw=1.6, color=COLORS[i % len(COLORS)],
                    label=model_label(m, explanation))
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel(xlabel)
    axes[0, 0].legend(fontsize=8, loc="best")
    fig.suptitle("Amplitude-phase frequency response: measured vs each model (paper Figs. 1-3)")
    fig.tight_layout()
    path = os.path.join(out_dir, "response.png")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return "response.png"


def plot_free_decay(curves, explanation, out_dir):
    models = [m for m in ladder(explanation) if m in curves]
    meas = curves["measured"]
    names = []
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5), sharex=True)
    for ax, key in zip(axes.flat, ["q1", "p1", "q2", "p2"]):
        ax.plot(meas["x"], meas[key], ".", ms=2, color="k", label="measured")
        for i, m in enumerate(models):
            ax.plot(curves[m]["x"], curves[m][key], "-", lw=1.3, color=COLORS[i % len(COLORS)],
                    label=model_label(m, explanation))
        ax.set_title(key, fontsize=10)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time t [s]")
    axes[0, 0].legend(fontsize=8, loc="best")
    fig.suptitle("Free decay: slow variables, measured vs each model (integrated averaged equations)")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "slow.png"), dpi=110)
    plt.close(fig)
    names.append("slow.png")

    fig, axes = plt.subplots(3, 2, figsize=(11, 9), sharex=True)
    for row, key in enumerate(["r", "k", "theta"]):
        unit = " [rad]" if key == "theta" else ""
        ax = axes[row, 0]
        ax.plot(meas["x"], meas[key], ".", ms=2, color="k", label="measured")
        for i, m in enumerate(models):
            ax.plot(curves[m]["x"], curves[m][key], "-", lw=1.3, color=COLORS[i % len(COLORS)],
                    label=model_label(m, explanation))
        ax.set_ylabel(key + unit)
        ax.grid(alpha=0.3)
        ax = axes[row, 1]
        for i, m in enumerate(models):
            diff = [a - b for a, b in zip(meas[key], curves[m][key])] \
                if len(curves[m][key]) == len(meas[key]) else []
            if diff:
                ax.plot(meas["x"], diff, "-", lw=1.0, color=COLORS[i % len(COLORS)], label=m)
        ax.axhline(0.0, color="k", lw=0.6)
        ax.set_ylabel("measured - model: " + key)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8, loc="best")
    axes[0, 1].legend(fontsize=8, loc="best")
    for ax in axes[2]:
        ax.set_xlabel("time t [s]")
    fig.suptitle("Orbit elements (5.2): amplitude r, quadrature k, pattern angle theta")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "orbit.png"), dpi=110)
    plt.close(fig)
    names.append("orbit.png")
    return names


def plot_residuals(res, explanation, out_dir):
    mode = explanation["mode"]
    models = [m for m in ladder(explanation) if m in res]
    shown = [models[0], models[-1]] if len(models) > 1 else models
    fig, axes = plt.subplots(2, len(shown), figsize=(5.5 * len(shown), 6.5), sharex=True,
                             squeeze=False)
    for col, m in enumerate(shown):
        xs, xlabel = x_axis(mode, res[m]["x"])
        for row, key in enumerate(["tangential", "radial"]):
            ax = axes[row, col]
            style = "o-" if mode == "forced" else "."
            ax.plot(xs, res[m][key], style, ms=3 if mode == "forced" else 1.5, lw=0.8,
                    color=COLORS[models.index(m) % len(COLORS)])
            ax.axhline(0.0, color="k", lw=0.6)
            ax.grid(alpha=0.3)
            what = "phase (frequency-like)" if key == "tangential" else "amplitude (damping-like)"
            ax.set_title("%s: %s residual" % (m, what), fontsize=9)
            if row == 1:
                ax.set_xlabel(xlabel)
    fig.suptitle("Equation-error residuals before and after (projected on the amplitude and phase "
                 "directions of q)")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "residuals.png"), dpi=110)
    plt.close(fig)
    return "residuals.png"


def plot_signature(path, explanation, out_dir):
    rows = defaultdict(lambda: defaultdict(list))
    with open(path, newline="") as fh:
        for r in csv.DictReader(fh):
            rows[(r["variable"], r["component"])][r["model"]].append(
                (float(r["bin_center"]), float(r["mean"]), float(r["sem"])))
    if not rows:
        return None
    keys = sorted(rows.keys())
    variables = sorted(set(k[0] for k in keys))
    comps = ["tangential", "radial"]
    models = ladder(explanation)
    fig, axes = plt.subplots(len(comps), len(variables),
                             figsize=(3.6 * len(variables), 6.0), squeeze=False)
    for c, comp in enumerate(comps):
        for v, var in enumerate(variables):
            ax = axes[c, v]
            for m, pts in rows.get((var, comp), {}).items():
                i = models.index(m) if m in models else len(COLORS) - 1
                xs = [p[0] for p in pts]
                ax.errorbar(xs, [p[1] for p in pts], yerr=[p[2] for p in pts], fmt="o-", ms=3,
                            lw=1.0, capsize=2, color=COLORS[i % len(COLORS)], label=m)
            ax.axhline(0.0, color="k", lw=0.6)
            ax.grid(alpha=0.3)
            ax.set_xlabel(var, fontsize=9)
            if v == 0:
                ax.set_ylabel("mean %s residual" % comp, fontsize=9)
            ax.tick_params(labelsize=8)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("Residual signature: binned mean residual vs amplitude^2, amplitude^4, time or "
                 "detuning, pattern angle (+/- 1 standard error)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "signature.png"), dpi=110)
    plt.close(fig)
    return "signature.png"


def plot_measured(explanation, out_dir):
    """Free decay: the model-free orbit reading (explain JSON "measured") per window: theta' measured
    and predicted by the final model, amplitude r and quadrature k, and Q against amplitude."""
    m = explanation.get("measured")
    if not m or not m.get("windows"):
        return None
    w = m["windows"]
    mid = [0.5 * (x["t_start_s"] + x["t_end_s"]) for x in w]
    fig, axs = plt.subplots(1, 3, figsize=(14, 4))
    meas = [x["theta_rate_deg_h"] for x in w]
    axs[0].errorbar(mid, [v["value"] for v in meas],
                    yerr=[[v["value"] - v["ci_low"] for v in meas], [v["ci_high"] - v["value"] for v in meas]],
                    fmt="o-", color="k", label="measured")
    pred = [(t, x["predicted_theta_rate_deg_h"]) for t, x in zip(mid, w) if x.get("predicted_theta_rate_deg_h")]
    if pred:
        axs[0].errorbar([t for t, _ in pred], [v["value"] for _, v in pred],
                        yerr=[[v["value"] - v["ci_low"] for _, v in pred], [v["ci_high"] - v["value"] for _, v in pred]],
                        fmt="s--", color="tab:red", label="predicted by %s" % m.get("model", "the model"))
    axs[0].axhline(0.0, color="0.6", lw=0.8)
    axs[0].set_xlabel("t [s]")
    axs[0].set_ylabel("pattern angle rate theta' [deg/h]")
    axs[0].set_title("theta' per window (oscillation plane: 2 theta')")
    axs[0].legend(fontsize=8)
    axs[1].plot(mid, [x["r"] for x in w], "o-", label="amplitude r")
    axs[1].set_xlabel("t [s]")
    axs[1].set_ylabel("r")
    ax2 = axs[1].twinx()
    ax2.plot(mid, [x["k"] for x in w], "s-", color="tab:orange", label="quadrature k")
    ax2.set_ylabel("k", color="tab:orange")
    axs[1].set_title("amplitude and quadrature (ellipse)")
    qs = [(x["r"], x["Q"]) for x in w if x.get("Q")]
    if qs:
        axs[2].errorbar([r for r, _ in qs], [q["value"] for _, q in qs],
                        yerr=[[q["value"] - q["ci_low"] for _, q in qs],
                              [min(q["ci_high"], 10 * q["value"]) - q["value"] for _, q in qs]], fmt="o")
    axs[2].set_xlabel("amplitude r")
    axs[2].set_ylabel("Q = omega / (-2 r'/r)")
    axs[2].set_title("Q against amplitude")
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "measured.png"), dpi=110)
    plt.close(fig)
    return "measured.png"


def fmt(v, spec="%.4g"):
    if v is None:
        return "-"
    if isinstance(v, float) and (math.isinf(v) or math.isnan(v)):
        return str(v)
    return spec % v


def write_markdown(explanation, figures, out_dir):
    e = explanation
    lines = ["# cvg_ident explain: %s record" % e["mode"], ""]
    for note in e.get("notes", []):
        lines.append("- " + note)
    if e.get("notes"):
        lines.append("")
    lines += ["## Verdict", "", e.get("cause", ""), ""]
    lines.append("Selected extensions: %s. Unexplained structure left: %s."
                 % (", ".join(e.get("selected", [])) or "none",
                    "yes" if e.get("unexplained") else "no"))
    lof = e.get("lack_of_fit", {})
    lines += ["", "Lack-of-fit test of the final model: %s, p = %s."
              % (lof.get("test", "-"), fmt(lof.get("p_value"))), ""]
    lines += ["## Model ladder", "",
              "| step | added | model | sigma | sigma ratio | F | p | delta BIC | hold-out ratio "
              "| accepted |",
              "|---|---|---|---|---|---|---|---|---|---|",
              "| 0 | - | %s | %s | - | - | - | - | - | baseline |"
              % (e["baseline"]["model"], fmt(e["baseline"]["sigma"]))]
    for i, s in enumerate(e.get("steps", []), 1):
        lines.append("| %d | %s | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            i, s["added"], s["model"], fmt(s["sigma"]), fmt(s["sigma_ratio"], "%.3g"),
            fmt(s["f_statistic"], "%.4g"), fmt(s["p_value"], "%.2g"),
            fmt(s["delta_bic"], "%.1f"), fmt(s["holdout_ratio"], "%.3g"),
            "yes" if s.get("accepted", True) else "no"))
    rejected = e.get("rejected", [])
    if rejected:
        lines += ["", "Candidates tried at the last step and not accepted:", "",
                  "| candidate | F | p | threshold | hold-out ratio |", "|---|---|---|---|---|"]
        for r in rejected:
            lines.append("| %s | %s | %s | %s | %s |" % (
                r["added"], fmt(r["f_statistic"]), fmt(r["p_value"], "%.2g"),
                fmt(r.get("threshold"), "%.2g"), fmt(r["holdout_ratio"], "%.3g")))
    m = e.get("measured")
    if m:
        lines += ["", "## Measured before modelling", "", m.get("summary", ""), "",
                  "| window [s] | r | k | theta' [deg/h] | predicted [deg/h] | Q |", "|---|---|---|---|---|---|"]
        for x in m.get("windows", []):
            p = x.get("predicted_theta_rate_deg_h")
            q = x.get("Q")
            lines.append("| %.0f-%.0f | %.4g | %.4g | %.3g [%.3g, %.3g] | %s | %s |" % (
                x["t_start_s"], x["t_end_s"], x["r"], x["k"], x["theta_rate_deg_h"]["value"],
                x["theta_rate_deg_h"]["ci_low"], x["theta_rate_deg_h"]["ci_high"],
                "%.3g [%.3g, %.3g]" % (p["value"], p["ci_low"], p["ci_high"]) if p else "-",
                "%.4g" % q["value"] if q else "-"))
    final = e.get("final", {})
    params = final.get("parameters", {})
    if params:
        lines += ["", "## Final model: %s (%s)" % (final.get("model", ""), final.get("method", "")),
                  "", "| parameter | value | std | CI low | CI high |", "|---|---|---|---|---|"]
        for name, p in params.items():
            lines.append("| %s | %.6g | %.3g | %.6g | %.6g |"
                         % (name, p["value"], p["std"], p["ci_low"], p["ci_high"]))
    sig = e.get("signature", [])
    if sig:
        lines += ["", "## Residual signature of the baseline", "",
                  "| variable | component | correlation | p |", "|---|---|---|---|"]
        for s in sig:
            lines.append("| %s | %s | %.3f | %.2g |" % (s["variable"], s["component"],
                                                       s["correlation"], s["p_value"]))
    lines += ["", "## Figures", ""]
    for f in figures:
        lines += ["![%s](%s)" % (f, f), ""]
    with open(os.path.join(out_dir, "report.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")


def make_report(out_dir):
    with open(os.path.join(out_dir, "explain.json")) as fh:
        explanation = json.load(fh)
    figures = []
    curves_path = os.path.join(out_dir, "curves.csv")
    if os.path.exists(curves_path):
        curves, order = read_table(curves_path)
        if "measured" in curves:
            if explanation["mode"] == "forced":
                figures.append(plot_forced_response(curves, order, explanation, out_dir))
            else:
                figures += plot_free_decay(curves, explanation, out_dir)
    res_path = os.path.join(out_dir, "residuals.csv")
    if os.path.exists(res_path):
        res, _ = read_table(res_path)
        figures.append(plot_residuals(res, explanation, out_dir))
    if explanation.get("measured"):
        name = plot_measured(explanation, out_dir)
        if name:
            figures.append(name)
    sig_path = os.path.join(out_dir, "signature.csv")
    if os.path.exists(sig_path):
        name = plot_signature(sig_path, explanation, out_dir)
        if name:
            figures.append(name)
    write_markdown(explanation, figures, out_dir)
    return figures


def main(argv):
    if len(argv) != 2 or argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0 if len(argv) == 2 else 2
    if not os.path.exists(os.path.join(argv[1], "explain.json")):
        sys.stderr.write("explain_report.py: %s/explain.json not found\n" % argv[1])
        return 2
    figures = make_report(argv[1])
    print("explain_report.py: wrote %s/report.md and %s" % (argv[1], ", ".join(figures)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
