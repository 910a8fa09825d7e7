#!/usr/bin/python3
"""Figures of `cvg_ident explain --mode response --report DIR` (docs/response.md): reads
DIR/response_points.csv and DIR/explain.json, writes DIR/response_levels.png (amplitude and phase
per drive level against frequency, up sweeps blue, down sweeps red, the selected model as lines),
DIR/response_backbone.png (peak frequency against squared amplitude: data per level and the
model's backbone) and DIR/response_residuals.png (residual per point in time order, every
candidate)."""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load(d):
    data = np.genfromtxt(os.path.join(d, "response_points.csv"), delimiter=",", names=True)
    with open(os.path.join(d, "explain.json")) as f:
        x = json.load(f)
    return data, x


def sweep_direction(f, sweep):
    """+1 where the sweep's frequency rises, -1 where it falls."""
    out = np.ones(len(f))
    for s in np.unique(sweep):
        m = sweep == s
        if m.sum() > 1 and f[m][-1] < f[m][0]:
            out[m] = -1
    return out


def main(d):
    data, x = load(d)
    sel = x["selected"].replace("+", "_")
    f, drive, sweep = data["frequency_hz"], data["drive"], data["sweep"]
    z = data["x"] + 1j * data["y"]
    m = data["x_" + sel] + 1j * data["y_" + sel]
    direction = sweep_direction(f, sweep)
    levels = np.unique(drive)
    ncol = min(4, len(levels))
    nrow = int(np.ceil(len(levels) / ncol))
    fig, axes = plt.subplots(2 * nrow, ncol, figsize=(4 * ncol, 5 * nrow), squeeze=False)
    for k, lev in enumerate(levels):
        r, c = 2 * (k // ncol), k % ncol
        for sgn, colour in ((1, "tab:blue"), (-1, "tab:red")):
            for s in np.unique(sweep[(drive == lev) & (direction == sgn)]):
                i = sweep == s
                axes[r][c].plot(f[i], np.abs(z[i]), ".", ms=3, color=colour)
                axes[r][c].plot(f[i], np.abs(m[i]), "-", lw=1, color=colour)
                axes[r + 1][c].plot(f[i], np.angle(z[i]), ".", ms=3, color=colour)
                axes[r + 1][c].plot(f[i], np.angle(m[i]), "-", lw=1, color=colour)
        axes[r][c].set_title("drive %.4g" % lev, fontsize=9)
        axes[r][c].set_ylabel("|Z|")
        axes[r + 1][c].set_ylabel("phase [rad]")
        axes[r + 1][c].set_xlabel("frequency [Hz]")
    fig.suptitle("%s: %s (up blue, down red; lines: model)" % (x["selected"], x["verdict"][:90]),
                 fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "response_levels.png"), dpi=80)
    plt.close(fig)

    final = x["final"]
    fig, ax = plt.subplots(figsize=(6, 4))
    for lev in final.get("levels", []):
        ax.plot(lev["peak_amplitude"] ** 2, lev["f0_hz"], "o", color="k", ms=4)
    dci = final["derived_ci"]
    if "f0_hz" in dci:
        umax = max([lv["peak_amplitude"] ** 2 for lv in final.get("levels", [])] + [1e-300])
        u = np.linspace(0, umax, 50)
        xi = dci.get("backbone_hz_per_amp2", {"value": 0.0})["value"]
        ax.plot(u, dci["f0_hz"]["value"] + xi * u, "-", color="tab:green", label="model backbone")
    ax.set_xlabel("squared amplitude (x, y unit^2)")
    ax.set_ylabel("frequency [Hz]")
    ax.set_title("per-level Lorentzian peaks (dots) and the backbone", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "response_backbone.png"), dpi=80)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(9, 4))
    for c in x["candidates"]:
        name = c["model"].replace("+", "_")
        mc = data["x_" + name] + 1j * data["y_" + name]
        ax.plot(np.abs(z - mc), lw=0.8, label="%s (rss %.3g)" % (c["model"], c["rss"]))
    ax.set_xlabel("point (time order)")
    ax.set_ylabel("|Z - model|")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "response_residuals.png"), dpi=80)
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1])
