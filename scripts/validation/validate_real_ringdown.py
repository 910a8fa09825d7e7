#!/usr/bin/python3
"""Real ring-down validation: the tool against the authors' Q on the development set
(../shared/data/ringdowns_qpit_dev; skipped with a message when absent).

Runs `cvg_ident explain RECORD --mode ringdown --json` on every record of a part of the split
(scripts/validation/ringdown_real_split.csv, by sample, fixed before tuning), compares Q with the
authors' published Q, and reports, with Wilson 95 % intervals (thresholds fixed here, before runs):
  - Q within 5 % of the authors' on the records classified `clean` by eye
    (scripts/validation/ringdown_real_classes.csv; target >= 0.95);
  - the same on every record, refusals (exit 1) and their reasons, crashes (target 0);
  - Q intervals negative, open or of zero width (target 0 where Q is printed);
  - doublets (D301-D316): `beat` named;
  - repeat groups (3 records of one sample and mode on one day): RMS of
    z = (Q_i - Q_j) / sqrt(se_i^2 + se_j^2) over pairs, with the within-record std and with the
    total std (span part included; target <= 2); added 29 Nov, after the runs had shown why: the
    same over the pairs whose authors' Q agree within 10 % (repeats of one state: a group's record
    whose authors' Q differs by 50 % is another state of the resonator, which no single record's
    interval can cover; reported beside the full row, not instead of it);
  - causes named (selected, unexplained) per class.
A contact sheet (PNG grid: record, chosen span, fit, floor) of the records where tool and authors
disagree by more than 5 % goes to OUT/disagree_*.png.

  validate_real_ringdown.py --part tuning|heldout|all [--jobs 2] [--out build/validate_real]
                            [--markdown FILE] [--ids D001,D002] [--no-sheet]
"""
import argparse
import collections
import concurrent.futures as cf
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import real_ringdown_common as rc  # noqa: E402

TOOL = os.path.join(rc.REPO, "bin", "cvg_ident")
Q_TOLERANCE = 0.05          # "within 5 % of the authors' Q"
TARGET_CLEAN = 0.95         # rate on clean records
TARGET_Z_RMS = 2.0          # repeat groups


def run_one(rid, out_dir, timeout):
    out = os.path.join(out_dir, rid + ".json")
    cmd = [TOOL, "explain", rc.record_path(rid), "--mode", "ringdown", "--json", out]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        rcode, err = p.returncode, (p.stderr.strip().splitlines() or [""])[-1]
    except subprocess.TimeoutExpired:
        rcode, err = -999, "timeout"
    res = {"id": rid, "exit": rcode, "message": err}
    if rcode == 0 and os.path.exists(out):
        with open(out) as f:
            j = json.load(f)
        fin = j.get("final", {})
        q = fin.get("derived_ci", {}).get("Q", {})
        seg = fin.get("segment", {})
        res.update({
            "Q": q.get("value"), "Q_std": q.get("std"), "Q_lo": q.get("ci_low"),
            "Q_hi": q.get("ci_high"), "Q_std_total": q.get("std_total", q.get("std")),
            "t_start": seg.get("t_start"), "t_end": seg.get("t_end"), "why": seg.get("why"),
            "floor_db": seg.get("floor_db"), "selected": j.get("selected", []),
            "unexplained": j.get("unexplained"), "tau_s": fin.get("derived", {}).get("tau_s"),
            "beat": "beat" in j.get("selected", []),
        })
    return res


def rate_row(name, k, n, target=None, cmp=">="):
    lo, hi = rc.wilson(k, n)
    r = k / n if n else float("nan")
    verdict = ""
    if target is not None and n:
        ok = r >= target if cmp == ">=" else r <= target
        verdict = "pass" if ok else "FAIL"
    tgt = "" if target is None else "%s %.2f" % (cmp, target)
    return "| %s | %d / %d | %.3f | [%.3f, %.3f] | %s | %s |" % (name, k, n, r, lo, hi, tgt, verdict)


SAME_STATE = 0.10  # |authors' Q_i / Q_j - 1| of a repeat pair counted as one state (row above)


def z_rms(results, labels, key, same_state=None):
    groups = collections.defaultdict(list)
    for r in results:
        lab = labels[r["id"]]
        groups[(lab["sample_id"], lab["mode_id"], lab["datetime"][:10])].append(r)
    zs, lost = [], 0
    for g in groups.values():
        if len(g) < 2:
            continue
        for i in range(len(g)):
            for k in range(i + 1, len(g)):
                a, b = g[i], g[k]
                if a.get("Q") is None or b.get("Q") is None or not a.get(key) or not b.get(key):
                    lost += 1
                    continue
                qa, qb = (float(labels[x["id"]]["authors_q"]) for x in (a, b))
                if same_state is not None and abs(qa / qb - 1.0) > same_state:
                    continue
                zs.append((a["Q"] - b["Q"]) / math.sqrt(a[key] ** 2 + b[key] ** 2))
    rms = math.sqrt(sum(z * z for z in zs) / len(zs)) if zs else float("nan")
    return rms, len(zs), lost


def contact_sheet(results, labels, out_dir, prefix, per=12):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    names = []
    for k in range(0, len(results), per):
        chunk = results[k:k + per]
        rows = (len(chunk) + 2) // 3
        fig, axes = plt.subplots(rows, 3, figsize=(13, 2.8 * rows), squeeze=False)
        for ax in axes.flat:
            ax.set_visible(False)
        for ax, r in zip(axes.flat, chunk):
            ax.set_visible(True)
            lab = labels[r["id"]]
            t, y = rc.load_record(r["id"])
            st = max(1, len(t) // 3000)
            ax.plot(t[::st], y[::st], lw=0.5, color="0.35")
            fa = float(lab["frequency_hz"])
            qa = float(lab["authors_q"])
            title = "%s %s/%s auth %.3g" % (r["id"], lab["sample_id"], lab["mode_id"], qa)
            if r.get("Q"):
                a, b = r["t_start"], r["t_end"]
                ax.axvspan(a, b, color="tab:blue", alpha=0.12)
                m = (t >= a) & (t <= b)
                if m.sum() > 2:
                    for q, col in ((r["Q"], "tab:blue"), (qa, "tab:red")):
                        s = rc.authors_slope_db_per_s(q, fa)
                        c = np.median(y[m] - s * t[m])
                        tl = np.array([a, b])
                        ax.plot(tl, c + s * tl, "--" if col == "tab:red" else "-", color=col,
                                lw=0.9)
                if r.get("floor_db") is not None:
                    ax.axhline(r["floor_db"], color="tab:green", lw=0.7, ls=":")
                title += " tool %.3g (%+.0f%%) %s%s" % (
                    r["Q"], 100 * (r["Q"] / qa - 1), "+".join(r.get("selected") or ["lin"]),
                    " unexpl" if r.get("unexplained") else "")
            else:
                title += " exit %d" % r["exit"]
            cls = r.get("class", "?")
            ax.set_title(title + " [%s]" % cls, fontsize=6)
            ax.tick_params(labelsize=5)
        fig.tight_layout()
        name = os.path.join(out_dir, "%s_disagree_%02d.png" % (prefix, k // per))
        fig.savefig(name, dpi=85)
        plt.close(fig)
        names.append(name)
    return names


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--part", choices=["tuning", "heldout", "all"], default="tuning")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", default=os.path.join(rc.REPO, "build", "validate_real"))
    ap.add_argument("--markdown", default="")
    ap.add_argument("--ids", default="")
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--no-sheet", action="store_true")
    ap.add_argument("--report-only", action="store_true", help="re-report OUT/PART/results.json")
    a = ap.parse_args()
    if not os.path.isdir(rc.data_dir()):
        print("validate_real_ringdown: %s absent, skipped" % rc.data_dir())
        return 0
    labels, split, classes = rc.labels(), rc.split(), rc.classes()
    ids = a.ids.split(",") if a.ids else sorted(
        i for i in labels if a.part == "all" or split.get(i) == a.part)
    out = os.path.join(a.out, a.part)
    os.makedirs(out, exist_ok=True)
    if a.report_only:
        with open(os.path.join(out, "results.json")) as f:
            results = json.load(f)
    else:
        with cf.ThreadPoolExecutor(a.jobs) as ex:
            results = list(ex.map(lambda i: run_one(i, out, a.timeout), ids))
    for r in results:
        r["class"] = classes.get(r["id"], {}).get("class", "?")
        r["part"] = split.get(r["id"], "?")
        qa = float(labels[r["id"]]["authors_q"])
        r["authors_q"] = qa
        r["within"] = bool(r.get("Q")) and abs(r["Q"] / qa - 1) <= Q_TOLERANCE
    with open(os.path.join(out, "results.json"), "w") as f:
        json.dump(results, f, indent=1)

    lines = []
    P = lines.append
    for part in (["tuning", "heldout"] if a.part == "all" else [a.part]):
        rs = [r for r in results if r["part"] == part]
        if not rs:
            continue
        P("\n### Part: %s (%d records)\n" % (part, len(rs)))
        P("| check | count | rate | Wilson 95 % | target | |")
        P("|---|---|---|---|---|---|")
        clean = [r for r in rs if r["class"] == "clean"]
        P(rate_row("Q within 5 % of the authors', clean single exponentials",
                   sum(r["within"] for r in clean), len(clean), TARGET_CLEAN))
        P(rate_row("Q within 5 %, every record", sum(r["within"] for r in rs), len(rs)))
        P(rate_row("refused (exit 1, reason stated)", sum(r["exit"] == 1 for r in rs), len(rs)))
        P(rate_row("refused, clean records", sum(r["exit"] == 1 for r in clean), len(clean)))
        crash = [r for r in rs if r["exit"] not in (0, 1, 2)]
        P(rate_row("crash or timeout", len(crash), len(rs), 0.0, "<="))
        printed = [r for r in rs if r.get("Q") is not None]
        bad_ci = [r for r in printed if not (r.get("Q_lo") is not None and r.get("Q_hi") is not None
                                             and r["Q_lo"] > 0 and r["Q_hi"] > r["Q_lo"])]
        P(rate_row("Q interval negative, open or zero width", len(bad_ci), len(printed), 0.0, "<="))
        dbl = [r for r in rs if int(r["id"][1:]) > 300]
        if dbl:
            P(rate_row("doublet records with `beat` named", sum(bool(r.get("beat")) for r in dbl),
                       len(dbl)))
        for key, name in (("Q_std", "within-record std"), ("Q_std_total", "total std (span part)")):
            z, npair, lost = z_rms(rs, labels, key)
            P("| repeat z RMS, %s | %d pairs (%d lost) | %.2f | | <= %.1f | %s |" % (
                name, npair, lost, z, TARGET_Z_RMS,
                "pass" if z <= TARGET_Z_RMS else "FAIL" if key == "Q_std_total" else ""))
        z, npair, lost = z_rms(rs, labels, "Q_std_total", SAME_STATE)
        P("| repeat z RMS, total std, pairs whose authors' Q agree within %d %% | %d pairs | %.2f "
          "| | <= %.1f | %s |" % (100 * SAME_STATE, npair, z, TARGET_Z_RMS,
                                  "pass" if z <= TARGET_Z_RMS else "FAIL"))
        P("\nVerdicts per by-eye class (selected extension; +unexplained where flagged; "
          "refused = exit 1):\n")
        P("| class | n | within 5 % | verdicts |")
        P("|---|---|---|---|")
        by = collections.defaultdict(list)
        for r in rs:
            by[r["class"]].append(r)
        for cls in sorted(by):
            v = collections.Counter(
                ("refused" if r["exit"] == 1 else "exit %d" % r["exit"]) if r.get("Q") is None else
                ("+".join(r["selected"]) or "linear") + (" +unexplained" if r["unexplained"] else "")
                for r in by[cls])
            P("| %s | %d | %d | %s |" % (cls, len(by[cls]), sum(x["within"] for x in by[cls]),
                                         ", ".join("%s %d" % kv for kv in v.most_common())))
        refusals = collections.Counter(r["message"][:90] for r in rs if r["exit"] == 1)
        if refusals:
            P("\nRefusal reasons (first 90 characters):\n")
            for m, c in refusals.most_common(8):
                P("- %d x %s" % (c, m))
        dis = [r for r in rs if not r["within"]]
        P("\nDisagreements (> 5 %% or no Q): %s" % ", ".join(
            "%s[%s]" % (r["id"], r["class"]) for r in dis))
        if not a.no_sheet and dis:
            sheet_dir = os.path.join(out, "sheets")
            os.makedirs(sheet_dir, exist_ok=True)
            for n in contact_sheet(dis, labels, sheet_dir, part):
                P("  sheet: %s" % os.path.relpath(n, rc.REPO))
    text = "\n".join(lines)
    print(text)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
