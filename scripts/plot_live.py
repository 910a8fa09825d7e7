#!/usr/bin/python3
"""Live plot of the identifier's estimates (rospy + matplotlib), or the same plot from a bag.

  scripts/plot_live.py                          # live: /cvg/estimate, /cvg/derived, /cvg/drift
  scripts/plot_live.py --ns gyro_a              # another gyro's namespace
  scripts/plot_live.py --bag run.bag --out estimates.png   # headless, from a recorded run

Panels over time (the estimate's window end, s from the first): Q with its confidence band,
frequency split [Hz] with its band, sigma-hat (2.10) [equation units], drift rate (5.9) [deg/h] with
its band. Each estimate's experiment id is marked where it changes and the lines break there; on a
simulated bench the true Q (omega / gamma of /cvg/truth) is drawn dashed. A zoom or pan the user
makes is kept across the once-a-second redraws (the home button returns to following the data).
Q's band is the message's interval where it stays positive; where it reaches zero it is drawn
from the same half-width taken on the decay rate omega / Q (first order, so positive, open above
when the rate's interval reaches zero). The window is titled with the gyro's namespace. The topics
keep their rqt_plot ready fields (e.g. /cvg/derived/Q)."""
import argparse
import math
import sys
import threading

import matplotlib

PANELS = [  # (series key, title, unit)
    ("Q", "quality factor Q", ""),
    ("split_hz", "frequency split", "Hz"),
    ("sigma", "sigma-hat (2.10)", "1/s x amplitude"),
    ("drift_deg_h", "drift rate (5.9)", "deg/h"),
]


class Series:
    """Time series of the plotted quantities: value, ci_low, ci_high per time [s]."""

    def __init__(self):
        self.t0 = None
        self.data = {key: [] for key, _, _ in PANELS}
        self.experiments = []  # (t, id) where the experiment id changes
        self.truth_q = None  # omega / gamma of the simulator's truth, when it publishes one
        self.lock = threading.Lock()

    def _t(self, stamp):
        s = stamp.to_sec()
        if self.t0 is None:
            self.t0 = s
        return s - self.t0

    def add_estimate(self, msg):
        with self.lock:
            t = self._t(msg.window_end)
            self.data["sigma"].append((t, msg.sigma, msg.sigma, msg.sigma))
            if not self.experiments or self.experiments[-1][1] != msg.experiment_id:
                self.experiments.append((t, msg.experiment_id))

    def add_derived(self, msg):
        with self.lock:
            t = self._t(msg.header.stamp)
            self.data["Q"].append((t, msg.Q, msg.Q_ci_low, msg.Q_ci_high))
            self.data["split_hz"].append(
                (t, msg.frequency_split_hz, msg.frequency_split_hz_ci_low,
                 msg.frequency_split_hz_ci_high))

    def add_drift(self, msg):
        with self.lock:
            t = self._t(msg.header.stamp)
            to_deg_h = msg.drift_rate_deg_h / msg.drift_rate_rad_s if msg.drift_rate_rad_s else 0.0
            self.data["drift_deg_h"].append((t, msg.drift_rate_deg_h, msg.ci_low_rad_s * to_deg_h,
                                             msg.ci_high_rad_s * to_deg_h))

    def add_truth(self, msg):
        with self.lock:
            values = dict(zip(msg.names, msg.values))
            gamma = values.get("gamma", 0.0)
            self.truth_q = msg.omega_rad_s / gamma if gamma > 0 else None


def positive_q_band(q, lo, hi):
    """The Q band drawn: (lo, hi) where lo > 0; else the same half-width on the decay rate
    omega / Q: [q / (1 + h / q), q / (1 - h / q)], the upper end infinite when h >= q."""
    if lo > 0 or not q > 0:
        return lo, hi
    h = 0.5 * (hi - lo)
    return q / (1.0 + h / q), (q / (1.0 - h / q) if h < q else math.inf)


def experiment_segments(rows, experiments):
    """rows (sorted by t) cut where an experiment starts, so that lines do not join experiments."""
    starts = sorted(t for t, _ in experiments)
    out, current, k = [], [], 0
    for row in rows:
        while k < len(starts) and row[0] >= starts[k]:
            if current:
                out.append(current)
            current = []
            k += 1
        current.append(row)
    if current:
        out.append(current)
    return out


def read_bag(path, ns):
    import rosbag
    series = Series()
    topics = {"/%s/estimate" % ns: series.add_estimate, "/%s/derived" % ns: series.add_derived,
              "/%s/drift" % ns: series.add_drift, "/%s/truth" % ns: series.add_truth}
    with rosbag.Bag(path) as bag:
        for topic, msg, _ in bag.read_messages(topics=list(topics)):
            topics[topic](msg)
    return series


def draw(fig, series, ns="cvg", keep_view=False):
    """Redraws every panel; with keep_view, a panel whose limits the user changed keeps them."""
    views = {}
    if keep_view:
        for i, ax in enumerate(fig.axes):
            auto = getattr(ax, "cvg_auto_view", None)
            view = (ax.get_xlim(), ax.get_ylim())
            if auto is not None and view != auto:
                views[i] = view
    fig.clf()
    axes = fig.subplots(len(PANELS), 1, sharex=True)
    fig.suptitle("cvg_bench live estimates: /%s" % ns.strip("/"), fontsize=9)
    with series.lock:
        for ax, (key, title, unit) in zip(axes, PANELS):
            rows = sorted(series.data[key])
            for n, seg in enumerate(experiment_segments(rows, series.experiments)):
                t, v, lo, hi = zip(*seg)
                ax.plot(t, v, ".-", lw=1, ms=3, color="C0")
                if key == "Q":
                    band = [positive_q_band(*r[1:]) for r in seg]
                    top = max([b[1] for b in band if math.isfinite(b[1])] + list(v)) * 2
                    lo = [b[0] for b in band]
                    hi = [min(b[1], top) for b in band]
                if key != "sigma":
                    ax.fill_between(t, lo, hi, alpha=0.25, color="C0",
                                    label="confidence interval" if n == 0 else None)
            if key == "Q" and series.truth_q:
                ax.axhline(series.truth_q, color="k", ls="--", lw=0.8, label="truth")
            for te, eid in series.experiments:
                ax.axvline(te, color="grey", lw=0.6, ls=":")
                if key == PANELS[0][0]:
                    ax.annotate("exp %d" % eid, (te, 1.0), xycoords=("data", "axes fraction"),
                                fontsize=7, va="top")
            ax.set_ylabel("%s [%s]" % (title, unit) if unit else title, fontsize=8)
            ax.grid(alpha=0.3)
        axes[-1].set_xlabel("time of the window end [s from the first estimate]")
    fig.tight_layout()
    for i, ax in enumerate(axes):
        ax.cvg_auto_view = (ax.get_xlim(), ax.get_ylim())
        if i in views:
            ax.set_xlim(views[i][0])
            ax.set_ylim(views[i][1])


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--ns", default="cvg", help="namespace of the identifier's topics")
    p.add_argument("--bag", help="plot the estimates recorded in this bag instead of live")
    p.add_argument("--out", help="write the plot to this PNG (no window)")
    p.add_argument("--duration", type=float, default=0.0,
                   help="live with --out: record this long [s], then write the PNG")
    args = p.parse_args(argv)
    if args.out:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(8, 9))
    if args.bag:
        series = read_bag(args.bag, args.ns)
        n = sum(len(v) for v in series.data.values())
        if n == 0:
            print("plot_live: no estimates under /%s in %s" % (args.ns, args.bag), file=sys.stderr)
            return 1
        draw(fig, series, args.ns)
        fig.savefig(args.out) if args.out else plt.show()
        return 0

    import rospy
    from cvg_bench.msg import DerivedQuantitiesStamped, DriftRate, ModelEstimate, SimulationTruth
    rospy.init_node("plot_live", anonymous=True)
    series = Series()
    rospy.Subscriber("/%s/estimate" % args.ns, ModelEstimate, series.add_estimate)
    rospy.Subscriber("/%s/derived" % args.ns, DerivedQuantitiesStamped, series.add_derived)
    rospy.Subscriber("/%s/drift" % args.ns, DriftRate, series.add_drift, queue_size=100)
    rospy.Subscriber("/%s/truth" % args.ns, SimulationTruth, series.add_truth)
    if args.out:
        rospy.sleep(args.duration)
        draw(fig, series, args.ns)
        fig.savefig(args.out)
        return 0
    fig.canvas.manager.set_window_title("cvg_bench: /%s" % args.ns.strip("/"))
    while not rospy.is_shutdown() and plt.fignum_exists(fig.number):
        draw(fig, series, args.ns, keep_view=True)
        plt.pause(1.0)  # redraw once a second
    return 0


if __name__ == "__main__":
    sys.exit(main())
