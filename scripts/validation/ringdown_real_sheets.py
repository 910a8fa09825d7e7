#!/usr/bin/python3
"""Contact sheets of the raw real ring-down records (no tool output): each panel is one record's
level in dB against time, with a dashed line of the authors' published slope (Q = pi f tau) laid
through the upper half of the decay. Used to classify the records by eye before looking at the
tool (scripts/validation/ringdown_real_classes.csv).

  ringdown_real_sheets.py --part tuning --out build/real_sheets [--per-sheet 12]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import real_ringdown_common as rc  # noqa: E402


def smooth(y, half):
    out = np.empty_like(y)
    for i in range(len(y)):
        out[i] = np.median(y[max(0, i - half): i + half + 1])
    return out


def panel(ax, rid, lab, extra=None):
    t, y = rc.load_record(rid)
    stride = max(1, len(t) // 3000)
    ax.plot(t[::stride], y[::stride], lw=0.5, color="0.3")
    q = float(lab["authors_q"])
    f = float(lab["frequency_hz"])
    s = rc.authors_slope_db_per_s(q, f)
    ys = smooth(y[::stride], max(2, len(y[::stride]) // 100))
    ip = int(np.argmax(ys))
    floor = np.median(ys[-max(4, len(ys) // 10):])
    top = ys[ip]
    sel = np.arange(len(ys)) >= ip
    sel &= ys > 0.5 * (top + floor)
    tt = t[::stride]
    if sel.sum() > 3:
        c = np.median(ys[sel] - s * tt[sel])
        t_line = np.linspace(tt[ip], tt[-1], 50)
        y_line = c + s * t_line
        keep = y_line > floor - 10
        ax.plot(t_line[keep], y_line[keep], "--", color="tab:red", lw=0.8)
    if extra:
        extra(ax, t, y)
    ax.set_title("%s %s/%s Q=%.3g f=%.3gHz n=%d" % (rid, lab["sample_id"], lab["mode_id"], q, f,
                                                   len(t)), fontsize=6)
    ax.tick_params(labelsize=5)
    ax.set_ylim(min(y.min(), top - 80), top + 5)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--part", choices=["tuning", "heldout", "all"], default="tuning")
    ap.add_argument("--out", required=True)
    ap.add_argument("--per-sheet", type=int, default=12)
    ap.add_argument("--ids", default="", help="comma-separated ids instead of a part")
    a = ap.parse_args()
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels, split = rc.labels(), rc.split()
    ids = a.ids.split(",") if a.ids else sorted(
        i for i in labels if a.part == "all" or split.get(i) == a.part)
    os.makedirs(a.out, exist_ok=True)
    per = a.per_sheet
    cols = 3
    for k in range(0, len(ids), per):
        chunk = ids[k:k + per]
        rows = (len(chunk) + cols - 1) // cols
        fig, axes = plt.subplots(rows, cols, figsize=(12, 2.6 * rows), squeeze=False)
        for ax in axes.flat:
            ax.set_visible(False)
        for ax, rid in zip(axes.flat, chunk):
            ax.set_visible(True)
            panel(ax, rid, labels[rid])
        fig.tight_layout()
        name = os.path.join(a.out, "sheet_%s_%s.png" % (chunk[0], chunk[-1]))
        fig.savefig(name, dpi=90)
        plt.close(fig)
        print(name)


if __name__ == "__main__":
    main()
