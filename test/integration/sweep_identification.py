#!/usr/bin/python3
"""rostest: forced sweep on the bench. The simulator node sweeps the MEMS ring (section 4's
parameters, cubic stiffness); the identifier node (forced mode, model xi) identifies every
parameter from the published sweep points; each estimate lies within 4 of its own standard errors
of the simulator's truth (latched /cvg/truth), and the derived quantities come with intervals."""
import threading
import unittest

import rospy
import rostest

from cvg_bench.msg import DerivedQuantitiesStamped, ModelEstimate, SimulationTruth
from cvg_bench.srv import StartSweep


class SweepIdentification(unittest.TestCase):
    def test_sweep_estimate_matches_truth(self):
        timeout = rospy.get_param("~timeout_s", 40.0)
        lock = threading.Lock()
        state = {}
        truth_ev, est_ev = threading.Event(), threading.Event()

        def on_truth(msg):
            with lock:
                state["truth"] = msg
            truth_ev.set()

        def on_estimate(msg):
            with lock:
                t = state.get("truth")
                if t is not None and msg.n_samples == t.n_sweep_points:
                    state["estimate"] = msg
                    est_ev.set()

        def on_derived(msg):
            with lock:
                state["derived"] = msg

        rospy.Subscriber("/cvg/truth", SimulationTruth, on_truth)
        rospy.Subscriber("/cvg/estimate", ModelEstimate, on_estimate)
        rospy.Subscriber("/cvg/derived", DerivedQuantitiesStamped, on_derived)
        rospy.wait_for_service("/cvg/start_sweep", timeout)
        rospy.wait_for_service("/cvg/identify", timeout)
        res = rospy.ServiceProxy("/cvg/start_sweep", StartSweep)(
            omega0_start_rad_s=0.0, omega0_end_rad_s=0.0, n_points=0, up_and_down=False, seed=11)
        self.assertTrue(res.success, res.message)
        self.assertTrue(truth_ev.wait(timeout), "no /cvg/truth")
        self.assertTrue(est_ev.wait(timeout), "no estimate over the whole sweep within %g s" % timeout)
        with lock:
            truth, est = state["truth"], state["estimate"]
        self.assertEqual(est.mode, "forced")
        self.assertEqual(est.rank, est.n_params)
        true = dict(zip(truth.names, truth.values))
        worst = max(abs(est.values[i] - true[n]) / est.std_errors[i] for i, n in enumerate(est.names))
        rospy.loginfo("sweep estimate: %d params, worst |error| / se = %.2f, sigma %.3g", len(est.names), worst, est.sigma)
        for i, name in enumerate(est.names):
            self.assertIn(name, true)
            err = abs(est.values[i] - true[name])
            self.assertLess(err, 4.0 * est.std_errors[i],
                            "%s: %.6g vs truth %.6g (se %.3g)" % (name, est.values[i], true[name], est.std_errors[i]))
        # Section 4's Q with its interval (published next to the estimate).
        got = threading.Event()
        for _ in range(100):
            with lock:
                if "derived" in state:
                    break
            got.wait(0.05)
        with lock:
            d = state.get("derived")
        self.assertIsNotNone(d, "no /cvg/derived")
        q_true = truth.omega_rad_s / true["gamma"]
        self.assertLess(d.Q_ci_low, d.Q)
        self.assertGreater(d.Q_ci_high, d.Q)
        self.assertLess(abs(d.Q - q_true), 4.0 * (d.Q_ci_high - d.Q_ci_low) / 2.0)


if __name__ == "__main__":
    rospy.init_node("sweep_identification_test")
    rostest.rosrun("cvg_bench", "sweep_identification", SweepIdentification)
