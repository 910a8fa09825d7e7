#!/usr/bin/python3
"""Figures and a Markdown summary for `cvg_ident explain INPUT --mode ringdown --report DIR`.

Reads what the tool writes into DIR (every model curve comes from the C++ core):
  explain.json                  the ring-down explain JSON (interfaces.md)
  ringdown_envelope.csv         t,level_db,in_span,dropout   the whole record (level in dB)
  ringdown_fit.csv              model,t,level_db,fitted_db,residual_db   samples fitted, per model
  ringdown_q_vs_amplitude.csv   level_db,amplitude,Q,ci_low,ci_high,n   local Q per amplitude bin
Writes envelope.png (record in dB, span used, drop-outs, fitted models), residuals.png,
q_vs_amplitude.png and report.md into DIR.

Usage: ringdown_report.py DIR
"""
import csv
import json
import math
import os
import sys
import textwrap
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def fnum(s):
    try:
        return float(s)
    except ValueError:
        return math.nan


def main(d):
    x = json.load(open(os.path.join(d, "explain.json")))
    env = rows(os.path.join(d, "ringdown_envelope.csv"))
    fit = defaultdict(lambda: defaultdict(list))
    for r in rows(os.path.join(d, "ringdown_fit.csv")):
        for k in ("t", "level_db", "fitted_db", "residual_db"):
            fit[r["model"]][k].append(fnum(r[k]))
    qa = rows(os.path.join(d, "ringdown_q_vs_amplitude.csv"))
    seg = x["final"]["segment"]

    fig, ax = plt.subplots(figsize=(8, 4.5))
    t = [fnum(r["t"]) for r in env]
    lv = [fnum(r["level_db"]) for r in env]
    ax.plot(t, lv, ".", ms=2, color="0.6", label="record")
    dt = [fnum(r["t"]) for r in env if r["dropout"] == "1"]
    dl = [fnum(r["level_db"]) for r in env if r["dropout"] == "1"]
    if dt:
        ax.plot(dt, dl, "x", color="k", ms=4, label="drop-outs (left out)")
    ax.axvspan(seg["t_start"], seg["t_end"], color="#1f77b4", alpha=0.08, label="span fitted")
    colors = ["#d62728", "#2ca02c"]
    for i, (m, c) in enumerate(fit.items()):
        ax.plot(c["t"], c["fitted_db"], "-", color=colors[i % 2], lw=1.5, label="model " + m)
    if seg.get("floor_db") is not None:
        ax.axhline(seg["floor_db"], color="k", ls=":", lw=1, label="noise floor")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("level [dB]")
    ax.set_title("\n".join(textwrap.wrap("ring-down envelope: " + seg["why"], 110)), fontsize=7)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "envelope.png"), dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(8, 3.5))
    for i, (m, c) in enumerate(fit.items()):
        ax.plot(c["t"], c["residual_db"], ".", ms=2, color=colors[i % 2], label=m)
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("residual [dB]")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "residuals.png"), dpi=110)
    plt.close(fig)

    have_q = len(qa) > 0
    if have_q:
        fig, ax = plt.subplots(figsize=(6, 4))
        a = [fnum(r["amplitude"]) for r in qa]
        q = [fnum(r["Q"]) for r in qa]
        lo = [fnum(r["Q"]) - fnum(r["ci_low"]) for r in qa]
        hi = [(fnum(r["ci_high"]) - fnum(r["Q"])) if math.isfinite(fnum(r["ci_high"])) else 0
              for r in qa]
        ax.errorbar(a, q, yerr=[lo, hi], fmt="o", capsize=3, label="local Q per bin (95 %)")
        q0 = x["final"]["derived_ci"].get("Q0")
        if q0:
            ax.axhline(q0["value"], color="#d62728", ls="--", label="Q0 (zero amplitude)")
        ax.set_title("local Q per amplitude bin; final model " + x["final"]["model"], fontsize=8)
        ax.set_xscale("log")
        ax.set_xlabel("amplitude [file unit]")
        ax.set_ylabel("Q")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(d, "q_vs_amplitude.png"), dpi=110)
        plt.close(fig)

    f = x["final"]
    lines = ["# Ring-down report", "", "**Verdict:** " + x["cause"], "",
             "- span: %.6g .. %.6g s (%s)" % (seg["t_start"], seg["t_end"], seg["why"]),
             "- error model: %s (%s)" % (f["error_model"]["name"], f["error_model"]["why"]),
             "- intervals: " + f["interval_method"],
             "- selected: %s; unexplained: %s; adequate: %s" % (
                 ", ".join(x["selected"]) or "none", x["unexplained"], x["adequate"]), "",
             "| quantity | value | 95 % interval | std | Cramer-Rao std |", "|---|---|---|---|---|"]
    for k, v in sorted(f["derived_ci"].items()):
        lines.append("| %s | %.6g | [%s, %s] | %.3g | %s |" % (
            k, v["value"], v["ci_low"], v["ci_high"], v["std"] or 0, v.get("crb_std", "")))
    lines += ["", "![envelope](envelope.png)", "", "![residuals](residuals.png)", ""]
    if have_q:
        lines += ["![Q against amplitude](q_vs_amplitude.png)", ""]
    open(os.path.join(d, "report.md"), "w").write("\n".join(lines) + "\n")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: ringdown_report.py DIR")
    main(sys.argv[1])
