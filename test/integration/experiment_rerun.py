#!/usr/bin/python3
"""rostest: a rerun of start_free_decay gives a fresh estimate. Experiment 1 (autostart) and
experiment 2 (service call, seed 7) are identified separately: the second estimate's window lies
after the second start, its sample count equals the first's (not the sum), gamma and Q match the
preset's truth within 5 % (the mixed fit of the issue gave a negative gamma), and get_estimate by
experiment_id returns experiment 1's estimate unchanged. A rerun is normal bench work (issue #27):
no WARN or worse from the bench's nodes, no tf frame sent twice at one stamp (TF_REPEATED_DATA in
rviz), the simulator's and the identifier's diagnostics say "finished", and the rviz panel names
the gyro and heads with the window-mean drift in deg/h."""
import threading
import time
import unittest

import rospy
import rostest

from diagnostic_msgs.msg import DiagnosticArray
from rosgraph_msgs.msg import Log
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from cvg_bench.msg import ModelEstimate, SimulationTruth
from cvg_bench.srv import GetEstimate, StartFreeDecay

REL_TOL = 0.05  # gamma and Q of the linear model on the MEMS ring's 0.2 s decay (cubic term unmodelled)
QUIET_S = 1.5  # an experiment's estimate is final when none newer came for this long [wall s]


def value(est, name):
    return est.values[list(est.names).index(name)]


class ExperimentRerun(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.estimates = {}  # experiment id -> (latest estimate, wall time received)
        self.truth = None
        rospy.Subscriber("/cvg/estimate", ModelEstimate, self.on_estimate)
        rospy.Subscriber("/cvg/truth", SimulationTruth, self.on_truth)
        self.warnings = []  # WARN or worse from the bench's nodes
        self.tf_seen = set()
        self.tf_repeated = []  # (child frame, stamp) sent more than once
        self.diag = {}  # node name -> summary message
        self.panel = ""
        rospy.Subscriber("/rosout", Log, self.on_log, queue_size=1000)
        rospy.Subscriber("/tf", TFMessage, self.on_tf, queue_size=1000)
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diag, queue_size=100)
        rospy.Subscriber("/cvg/markers", MarkerArray, self.on_markers, queue_size=10)
        self.timeout_s = rospy.get_param("~timeout_s", 25.0)

    def on_estimate(self, msg):
        with self.lock:
            self.estimates[msg.experiment_id] = (msg, time.monotonic())

    def on_log(self, msg):
        if msg.level >= Log.WARN and msg.name.startswith("/cvg/"):
            with self.lock:
                self.warnings.append("%s: %s" % (msg.name, msg.msg))

    def on_tf(self, msg):
        with self.lock:
            for t in msg.transforms:
                key = (t.child_frame_id, t.header.stamp.to_nsec())
                if key in self.tf_seen:
                    self.tf_repeated.append(key)
                self.tf_seen.add(key)

    def on_diag(self, msg):
        with self.lock:
            for st in msg.status:
                self.diag[st.name.split(":")[0].strip()] = st.message

    def on_markers(self, msg):
        with self.lock:
            for m in msg.markers:
                if m.ns == "panel" and m.text:
                    self.panel = m.text

    def on_truth(self, msg):
        with self.lock:
            self.truth = msg

    def final_estimate(self, experiment_id):
        deadline = time.monotonic() + self.timeout_s
        while time.monotonic() < deadline and not rospy.is_shutdown():
            with self.lock:
                got = self.estimates.get(experiment_id)
            if got and time.monotonic() - got[1] > QUIET_S:
                return got[0]
            time.sleep(0.05)  # poll period of the bounded wait
        self.fail("no final estimate of experiment %d within %.0f s" % (experiment_id, self.timeout_s))

    def check_against_truth(self, est, truth):
        true_gamma = truth.values[list(truth.names).index("gamma")]
        gamma = value(est, "gamma")
        self.assertAlmostEqual(gamma, true_gamma, delta=REL_TOL * true_gamma)
        self.assertFalse(est.suspect, est.sanity_problems)
        self.assertEqual(est.sanity_problems, [])

    def test_rerun_gives_a_fresh_estimate(self):
        first = self.final_estimate(1)
        with self.lock:
            truth = self.truth
        self.assertIsNotNone(truth)
        self.check_against_truth(first, truth)
        rospy.wait_for_service("/cvg/start_free_decay", 5.0)
        res = rospy.ServiceProxy("/cvg/start_free_decay", StartFreeDecay)(seed=7)
        self.assertTrue(res.success, res.message)
        second = self.final_estimate(2)
        self.check_against_truth(second, truth)
        # Fresh: only the second run's samples, all after its start.
        self.assertGreater(second.window_start, first.window_end)
        self.assertGreaterEqual(second.window_start, second.experiment_start)
        self.assertLessEqual(abs(int(second.n_samples) - int(first.n_samples)), 2)
        self.assertNotEqual(value(second, "gamma"), value(first, "gamma"))  # other noise seed
        get = rospy.ServiceProxy("/cvg/get_estimate", GetEstimate)
        old = get(experiment_id=1)
        self.assertEqual(old.estimate.experiment_id, 1)
        self.assertEqual(list(old.estimate.values), list(first.values))
        latest = get(experiment_id=0)
        self.assertEqual(latest.estimate.experiment_id, 2)
        missing = get(experiment_id=99)
        self.assertFalse(missing.success)
        self.assertIn("kept: 1, 2", missing.message)
        time.sleep(2.5)  # one more diagnostics period (1 s) and panel after the final estimate
        with self.lock:
            self.assertEqual(self.warnings, [])
            self.assertEqual(self.tf_repeated, [])
            self.assertGreater(len(self.tf_seen), 10)
            diag = dict(self.diag)
            panel = self.panel
        sim = [v for k, v in diag.items() if "simulator" in k]
        ident = [v for k, v in diag.items() if "identifier" in k]
        self.assertEqual(sim, ["finished"], diag)
        self.assertEqual(ident, ["finished: final estimate of experiment 2"], diag)
        self.assertTrue(panel.startswith("/cvg: experiment 2 finished: final estimate"), panel)
        self.assertIn("drift (window mean) = ", panel)
        self.assertIn("deg/h", panel)


if __name__ == "__main__":
    rospy.init_node("experiment_rerun_test")
    rostest.rosrun("cvg_bench", "experiment_rerun", ExperimentRerun)
