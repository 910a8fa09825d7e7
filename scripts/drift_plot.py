#!/usr/bin/python3
"""The angle-dependent drift plot of `cvg_ident drift --measured ... --png FILE` (issue #26):
measured theta'(theta) per bin with its interval, the model's prediction with its band, and the
residual after compensation with the prediction.

usage: drift_plot.py DRIFT.json OUT.png
"""
import json
import sys


def main(argv):
    if len(argv) != 3:
        print(__doc__)
        return 2
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    with open(argv[1]) as f:
        j = json.load(f)
    th = j["theta_deg"]
    meas = [(t, m, ci) for t, m, ci in zip(th, j["measured_deg_h"], j["measured_ci"]) if m is not None]
    fig, (a, b) = plt.subplots(2, 1, figsize=(8, 6.5), sharex=True, gridspec_kw={"height_ratios": [3, 1.4]})
    lo = [c[0] for c in j["predicted_ci"]]
    hi = [c[1] for c in j["predicted_ci"]]
    a.fill_between(th, lo, hi, color="tab:red", alpha=0.2, label="prediction band (%s)" % j.get("model", ""))
    a.plot(th, j["predicted_deg_h"], "-", color="tab:red", label="predicted")
    a.errorbar([t for t, _, _ in meas], [m for _, m, _ in meas],
               yerr=[[m - ci[0] for _, m, ci in meas], [ci[1] - m for _, m, ci in meas]],
               fmt="o", color="k", ms=4, label="measured (whole-angle run)")
    a.axhline(0.0, color="0.6", lw=0.8)
    a.set_ylabel("drift theta' [deg/h]")
    a.set_title("drift against pattern angle: RMS %.3g deg/h, after compensation %.3g deg/h (%.3gx)" % (
        j["rms_measured_deg_h"], j["residual_after_compensation_deg_h"], j.get("compensation_gain") or 0.0))
    a.legend(fontsize=8)
    pred = dict(zip(th, j["predicted_deg_h"]))
    b.errorbar([t for t, _, _ in meas], [m - pred[t] for t, m, _ in meas],
               yerr=[[m - ci[0] for _, m, ci in meas], [ci[1] - m for _, m, ci in meas]], fmt="o", ms=3,
               color="tab:blue")
    b.axhline(0.0, color="0.6", lw=0.8)
    b.set_xlabel("pattern angle theta [deg]")
    b.set_ylabel("measured - predicted")
    fig.tight_layout()
    fig.savefig(argv[2], dpi=100)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
