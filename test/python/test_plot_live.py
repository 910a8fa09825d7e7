"""scripts/plot_live.py from a bag (headless): the series read back equal the recorded estimates
(Q with its interval, split in Hz, sigma, drift in deg/h with its interval converted from rad/s),
experiment changes are found, and the PNG is written."""
import importlib.util
import math
import os
import tempfile
import unittest

ROOT = os.environ.get("CVG_BENCH_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))


def load_plot_live():
    spec = importlib.util.spec_from_file_location(
        "plot_live", os.path.join(ROOT, "scripts", "plot_live.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class PlotLiveFromBag(unittest.TestCase):
    def test_bag_to_png(self):
        import rosbag
        import rospy
        from cvg_bench.msg import DerivedQuantitiesStamped, DriftRate, ModelEstimate
        plot_live = load_plot_live()
        with tempfile.TemporaryDirectory() as tmp:
            bag_path = os.path.join(tmp, "est.bag")
            with rosbag.Bag(bag_path, "w") as bag:
                for i in range(6):
                    stamp = rospy.Time(100 + i)
                    e = ModelEstimate(window_end=stamp, sigma=0.01 * (i + 1),
                                      experiment_id=1 if i < 3 else 2)
                    d = DerivedQuantitiesStamped(Q=1990.0 + i, Q_ci_low=1980.0 + i,
                                                 Q_ci_high=2000.0 + i, frequency_split_hz=2.5,
                                                 frequency_split_hz_ci_low=2.4,
                                                 frequency_split_hz_ci_high=2.6)
                    d.header.stamp = stamp
                    r = DriftRate(drift_rate_rad_s=1e-3, ci_low_rad_s=0.5e-3, ci_high_rad_s=1.5e-3,
                                  drift_rate_deg_h=1e-3 * 180 / math.pi * 3600)
                    r.header.stamp = stamp
                    bag.write("/cvg/estimate", e, stamp)
                    bag.write("/cvg/derived", d, stamp)
                    bag.write("/cvg/drift", r, stamp)
            series = plot_live.read_bag(bag_path, "cvg")
            self.assertEqual([row[1] for row in series.data["Q"]], [1990.0 + i for i in range(6)])
            self.assertEqual(series.data["Q"][2], (2.0, 1992.0, 1982.0, 2002.0))
            self.assertAlmostEqual(series.data["sigma"][5][1], 0.06)
            t, v, lo, hi = series.data["drift_deg_h"][0]
            self.assertAlmostEqual(v, 206.26480624709637, places=9)  # 1e-3 rad/s in deg/h
            self.assertAlmostEqual(lo, v / 2, places=9)
            self.assertAlmostEqual(hi, 1.5 * v, places=9)
            self.assertEqual(series.experiments, [(0.0, 1), (3.0, 2)])
            out = os.path.join(tmp, "plot.png")
            self.assertEqual(plot_live.main(["--bag", bag_path, "--out", out]), 0)
            with open(out, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
            self.assertGreater(os.path.getsize(out), 20000)
            self.assertEqual(plot_live.main(["--bag", bag_path, "--ns", "gyro_b", "--out", out]), 1)


class PlotLiveBenchView(unittest.TestCase):
    """What a bench engineer keeps open: Q bands that stay positive, lines that break between
    experiments, the user's zoom kept across redraws, the truth on a simulated bench."""

    def setUp(self):
        self.m = load_plot_live()

    def test_q_band_stays_positive(self):
        self.assertEqual(self.m.positive_q_band(2000.0, 1900.0, 2100.0), (1900.0, 2100.0))
        lo, hi = self.m.positive_q_band(100.0, -20.0, 220.0)  # half-width 120 > Q: open above
        self.assertAlmostEqual(lo, 100.0 / 2.2)
        self.assertEqual(hi, math.inf)
        lo, hi = self.m.positive_q_band(100.0, 0.0, 200.0 - 1e-9)
        self.assertGreater(lo, 0.0)
        self.assertGreater(hi, 1e6)

    def test_lines_break_between_experiments(self):
        rows = [(t, 1.0, 0.0, 2.0) for t in (0.0, 1.0, 2.0, 3.0, 4.0)]
        segs = self.m.experiment_segments(rows, [(0.0, 1), (2.5, 2)])
        self.assertEqual([len(s) for s in segs], [3, 2])

    def test_zoom_kept_and_truth_drawn(self):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        series = self.m.Series()
        for i in range(5):
            series.data["Q"].append((float(i), 1000.0 + i, 990.0, 1010.0 + i))
            series.data["sigma"].append((float(i), 0.1, 0.1, 0.1))
        series.experiments = [(0.0, 1)]
        series.truth_q = 1002.0
        fig = plt.figure()
        self.m.draw(fig, series, "gyro_a", keep_view=True)
        self.assertIn("/gyro_a", fig._suptitle.get_text())
        q_ax = fig.axes[0]
        self.assertTrue(any(abs(l.get_ydata()[0] - 1002.0) < 1e-9 for l in q_ax.get_lines()
                            if l.get_linestyle() == "--"))
        q_ax.set_ylim(1001.0, 1003.0)  # the user zooms
        series.data["Q"].append((5.0, 1005.0, 995.0, 1015.0))
        self.m.draw(fig, series, "gyro_a", keep_view=True)
        self.assertEqual(tuple(fig.axes[0].get_ylim()), (1001.0, 1003.0))
        # Not zoomed: the next redraw follows the data.
        ylim_sigma = fig.axes[2].get_ylim()
        series.data["sigma"].append((6.0, 5.0, 5.0, 5.0))
        self.m.draw(fig, series, "gyro_a", keep_view=True)
        self.assertGreater(fig.axes[2].get_ylim()[1], ylim_sigma[1])
        plt.close(fig)


if __name__ == "__main__":
    unittest.main()
