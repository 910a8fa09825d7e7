#!/usr/bin/python3
"""Fleet report of a `cvg_ident batch` output folder (docs/fleet.md): groups with their repeat
scatter, outliers, failures, throughput, plots, and a Markdown summary.

usage: fleet_report.py DIR [--group-by COL[,COL...]]

Reads DIR/fleet.json (written by `cvg_ident batch`) and DIR/records/*.status.json; writes
DIR/fleet_groups.csv, DIR/fleet_groups.json, DIR/fleet_q_hist.png, DIR/fleet_q_vs_frequency.png,
DIR/fleet_repeat_scatter.png (when groups have repeats) and DIR/fleet.md.

Groups: records with equal values of the grouping columns (default: the manifest's sample column,
the first of sample_id, sample, resonator, serial, with mode_id when present). Per group: n, median
Q, relative scatter (sd / mean), the between-run excess sqrt(max(0, sd^2 - mean se^2)) / mean, and the
RMS of z = (Q_i - Q_j) / sqrt(se_i^2 + se_j^2) over the
pairs: about 1 when the intervals account for what varies between repeats, above 1 when repeats
differ by more than each record's interval says (run-to-run variation).
Outliers: within a group of 3 or more, a record whose Q differs from the median of the others by
more than 10 % and by more than 4 combined standard errors; over the fleet, |log10 Q - median| more
than 3.5 scaled MADs (robust z).
"""
import csv
import glob
import json
import math
import os
import sys

SAMPLE_COLUMNS = ["sample_id", "sample", "resonator", "serial"]
VERDICT_COLOURS = {"ok": "tab:green", "explained": "tab:blue", "flagged": "tab:orange",
                   "unexplained": "tab:red"}


def estimate(row, name):
    v = row.get(name)
    if isinstance(v, dict) and isinstance(v.get("value"), (int, float)):
        return v
    return None


def frequency(row):
    if isinstance(row.get("frequency_hz"), (int, float)):
        return row["frequency_hz"]
    f0 = estimate(row, "f0_hz")
    return f0["value"] if f0 else None


def group_columns(records, requested):
    if requested:
        return requested
    names = set()
    for r in records:
        names.update(r.get("columns", {}).keys())
    cols = [c for c in SAMPLE_COLUMNS if c in names][:1]
    if cols and "mode_id" in names:
        cols.append("mode_id")
    return cols


def median(xs):
    s = sorted(xs)
    n = len(s)
    return None if n == 0 else (s[n // 2] if n % 2 else 0.5 * (s[n // 2 - 1] + s[n // 2]))


def groups_of(records, cols):
    groups = {}
    if not cols:
        return groups
    for r in records:
        key = tuple(r.get("columns", {}).get(c, "") for c in cols)
        groups.setdefault(key, []).append(r)
    out = []
    for key, members in groups.items():
        with_q = [(m, estimate(m, "Q")) for m in members if estimate(m, "Q")]
        qs = [q["value"] for _, q in with_q]
        g = {"group": dict(zip(cols, key)), "n": len(members), "n_with_q": len(qs),
             "records": [m["record"] for m in members], "Q_median": median(qs),
             "first_index": min(m.get("index", 0) for m in members)}
        if len(qs) >= 2:
            mean = sum(qs) / len(qs)
            sd = math.sqrt(sum((q - mean) ** 2 for q in qs) / (len(qs) - 1))
            g["Q_mean"] = mean
            g["Q_relative_scatter"] = sd / mean if mean else None
            zs = []
            for i in range(len(with_q)):
                for j in range(i + 1, len(with_q)):
                    a, b = with_q[i][1], with_q[j][1]
                    se = math.hypot(a.get("std") or 0.0, b.get("std") or 0.0)
                    if se > 0:
                        zs.append((a["value"] - b["value"]) / se)
            # Between-run excess: the part of the repeats' variance their own intervals do not
            # explain, sqrt(max(0, s^2 - mean se^2)), relative to the mean (0 when they cover it).
            se2 = [(q.get("std") or 0.0) ** 2 for _, q in with_q]
            g["Q_between_run_excess"] = math.sqrt(max(0.0, sd * sd - sum(se2) / len(se2))) / mean if mean else None
            g["pairs"] = len(zs)
            g["z_rms"] = math.sqrt(sum(z * z for z in zs) / len(zs)) if zs else None
        out.append(g)
    out.sort(key=lambda g: g["first_index"])
    return out


def outliers(records, groups):
    by_name = {r["record"]: r for r in records}
    found = []
    for g in groups:
        members = [by_name[n] for n in g["records"] if estimate(by_name[n], "Q")]
        if len(members) < 3:
            continue
        for m in members:
            others = [estimate(o, "Q") for o in members if o is not m]
            ref = median([o["value"] for o in others])
            q = estimate(m, "Q")
            se = math.hypot(q.get("std") or 0.0, median([o.get("std") or 0.0 for o in others]))
            if ref and abs(q["value"] - ref) > 0.10 * ref and se > 0 and abs(q["value"] - ref) > 4 * se:
                found.append({"record": m["record"], "why": "Q %.4g vs %.4g for the rest of its group %s"
                              % (q["value"], ref, ", ".join("%s=%s" % kv for kv in g["group"].items()))})
    logs = [(r, math.log10(estimate(r, "Q")["value"])) for r in records
            if estimate(r, "Q") and estimate(r, "Q")["value"] > 0]
    if len(logs) >= 5:
        med = median([l for _, l in logs])
        mad = median([abs(l - med) for _, l in logs]) * 1.4826
        if mad > 0:
            for r, l in logs:
                z = (l - med) / mad
                if abs(z) > 3.5:
                    found.append({"record": r["record"], "why": "Q %.4g: robust z %.1f over the fleet"
                                  % (10 ** l, z)})
    for r in records:
        q = estimate(r, "Q")
        if q and q["value"] <= 0:
            found.append({"record": r["record"], "why": "Q %.4g is not positive" % q["value"]})
    return found


def plots(d, records, groups):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    made = []
    with_q = [r for r in records if estimate(r, "Q") and estimate(r, "Q")["value"] > 0]
    if with_q:
        fig, ax = plt.subplots(figsize=(7, 4))
        verdicts = sorted({r["verdict"] for r in with_q})
        data = [[math.log10(estimate(r, "Q")["value"]) for r in with_q if r["verdict"] == v] for v in verdicts]
        ax.hist(data, bins=30, stacked=True, label=verdicts,
                color=[VERDICT_COLOURS.get(v, "tab:gray") for v in verdicts])
        ax.set_xlabel("log10 Q")
        ax.set_ylabel("records")
        ax.set_title("Q over the fleet (%d records with a Q)" % len(with_q))
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(d, "fleet_q_hist.png"), dpi=90)
        plt.close(fig)
        made.append("fleet_q_hist.png")
        fq = [r for r in with_q if frequency(r)]
        if fq:
            fig, ax = plt.subplots(figsize=(7, 5))
            for v in sorted({r["verdict"] for r in fq}):
                sel = [r for r in fq if r["verdict"] == v]
                x = [frequency(r) for r in sel]
                y = [estimate(r, "Q")["value"] for r in sel]
                lo = [max(0.0, yy - (estimate(r, "Q").get("ci_low") or yy)) for r, yy in zip(sel, y)]
                hi = [max(0.0, (estimate(r, "Q").get("ci_high") or yy) - yy) for r, yy in zip(sel, y)]
                hi = [h if math.isfinite(h) else 0.0 for h in hi]
                ax.errorbar(x, y, yerr=[lo, hi], fmt="o", ms=3, lw=0.8, label="%s (%d)" % (v, len(sel)),
                            color=VERDICT_COLOURS.get(v, "tab:gray"))
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("frequency [Hz]")
            ax.set_ylabel("Q (bars: interval)")
            ax.set_title("Q against frequency, coloured by verdict")
            ax.legend(fontsize=8)
            fig.tight_layout()
            fig.savefig(os.path.join(d, "fleet_q_vs_frequency.png"), dpi=90)
            plt.close(fig)
            made.append("fleet_q_vs_frequency.png")
    rep = [g for g in groups if g.get("Q_relative_scatter") is not None]
    if rep:
        fig, axs = plt.subplots(1, 2, figsize=(9, 3.6))
        axs[0].hist([100 * g["Q_relative_scatter"] for g in rep], bins=20, color="tab:blue")
        axs[0].set_xlabel("repeat scatter of Q within a group [%]")
        axs[0].set_ylabel("groups")
        zr = [g["z_rms"] for g in rep if g.get("z_rms") is not None]
        axs[1].hist([math.log10(z) for z in zr if z > 0], bins=20, color="tab:purple")
        axs[1].axvline(0.0, color="k", lw=0.8)
        axs[1].set_xlabel("log10 RMS z of repeat pairs (0: intervals cover repeats)")
        fig.tight_layout()
        fig.savefig(os.path.join(d, "fleet_repeat_scatter.png"), dpi=90)
        plt.close(fig)
        made.append("fleet_repeat_scatter.png")
    return made


def fmt(x, spec="%.4g"):
    return "" if x is None else spec % x


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0 if len(argv) >= 2 else 2
    d = argv[1]
    requested = []
    if "--group-by" in argv:
        requested = argv[argv.index("--group-by") + 1].split(",")
    with open(os.path.join(d, "fleet.json")) as f:
        fleet = json.load(f)
    records = fleet["records"]
    statuses = []
    for p in sorted(glob.glob(os.path.join(d, "records", "*.status.json"))):
        try:
            with open(p) as f:
                statuses.append(json.load(f))
        except (OSError, ValueError):
            pass
    for s in statuses:
        for r in records:
            if r["record"] == s.get("record"):
                r["index"] = s.get("index", 0)
    cols = group_columns(records, requested)
    groups = groups_of(records, cols)
    odd = outliers(records, groups)
    with open(os.path.join(d, "fleet_groups.json"), "w") as f:
        json.dump({"group_by": cols, "groups": groups, "outliers": odd}, f, indent=1)
    with open(os.path.join(d, "fleet_groups.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols + ["n", "n_with_q", "Q_median", "Q_mean", "Q_relative_scatter", "Q_between_run_excess",
                           "pairs", "z_rms", "records"])
        for g in groups:
            w.writerow([g["group"][c] for c in cols] + [g["n"], g["n_with_q"], fmt(g.get("Q_median"), "%.8g"),
                        fmt(g.get("Q_mean"), "%.8g"), fmt(g.get("Q_relative_scatter"), "%.5g"),
                        fmt(g.get("Q_between_run_excess"), "%.5g"),
                        g.get("pairs", ""), fmt(g.get("z_rms"), "%.4g"), " ".join(g["records"])])
    made = plots(d, records, groups)

    verdicts = {}
    for r in records:
        verdicts[r["verdict"]] = verdicts.get(r["verdict"], 0) + 1
    failures = {}
    for r in records:
        if r["exit_status"] != 0:
            msg = r.get("message", "")
            # Grouped by the message's fixed part (record-specific numbers follow in brackets).
            key = "exit %d: %s" % (r["exit_status"], msg.split(": ", 2)[-1].split(" (")[0][:90])
            failures.setdefault(key, []).append(r["record"])
    secs = [s.get("seconds", 0.0) for s in statuses]
    rss = [s.get("peak_rss_kb", 0) for s in statuses]
    lines = ["# Fleet report: %s" % os.path.abspath(d), "",
             "%d of %d records have a result row; %d failed (exit status and message in fleet.csv)."
             % (fleet["present"], fleet["record_count"], fleet["failed"]), ""]
    if fleet.get("missing_indices"):
        lines += ["**Missing** (no outcome yet, e.g. a shard not run or merged): indices %s" %
                  ", ".join(str(i) for i in fleet["missing_indices"][:50]), ""]
    lines += ["| verdict | records |", "|---|---|"] + ["| %s | %d |" % kv for kv in sorted(verdicts.items())]
    lines += ["", "Verdicts: `ok` (identify, nothing flagged), `flagged` (identify: not adequate, flags or "
              "parameters not identified), `explained` / `unexplained` (explain), `failed` (no result).", ""]
    if secs:
        lines += ["Analysis time per record: median %.2f s, total %.1f s of CPU-bound work; peak memory per "
                  "record: median %.0f MB, max %.0f MB." % (median(secs), sum(secs), median(rss) / 1024.0,
                                                            max(rss) / 1024.0), ""]
    for p in made:
        lines += ["![%s](%s)" % (p, p), ""]
    if groups:
        lines += ["## Groups by %s" % ", ".join(cols), "",
                  "| group | n | median Q | repeat scatter | between-run excess | RMS z of pairs |",
                  "|---|---|---|---|---|---|"]
        for g in groups:
            if g["n"] < 2:
                continue
            lines.append("| %s | %d | %s | %s | %s | %s |" % (
                " ".join(str(v) for v in g["group"].values()), g["n"], fmt(g.get("Q_median")),
                fmt(100 * g["Q_relative_scatter"], "%.1f %%") if g.get("Q_relative_scatter") is not None else "",
                fmt(100 * g["Q_between_run_excess"], "%.1f %%") if g.get("Q_between_run_excess") is not None else "",
                fmt(g.get("z_rms"), "%.2f")))
        rep = [g for g in groups if g.get("Q_relative_scatter") is not None]
        if rep:
            lines += ["", "Median repeat scatter %.1f %% over %d groups with repeats; median between-run excess "
                      "%.1f %% (the scatter the records' own intervals do not explain: add it in quadrature to a "
                      "record's interval when the question is what a repeat would give)." %
                      (100 * median([g["Q_relative_scatter"] for g in rep]), len(rep),
                       100 * median([g["Q_between_run_excess"] for g in rep if g.get("Q_between_run_excess") is not None]))]
        lines.append("")
    if odd:
        lines += ["## Outliers", ""] + ["- %s: %s" % (o["record"], o["why"]) for o in odd] + [""]
    if failures:
        lines += ["## Failures", ""]
        for k, names in sorted(failures.items(), key=lambda kv: -len(kv[1])):
            lines.append("- %d x %s (%s%s)" % (len(names), k, ", ".join(names[:8]), ", ..." if len(names) > 8 else ""))
        lines.append("")
    with open(os.path.join(d, "fleet.md"), "w") as f:
        f.write("\n".join(lines))
    print("fleet report: %s/fleet.md (%d plots, %d groups, %d outliers)" % (d, len(made), len(groups), len(odd)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
