#!/usr/bin/python3
"""rostest: failures are visible. (1) identifier_node with four invalid settings (mode, confidence,
window_s, queue_size) prints each problem to its console and to /rosout (FATAL, before ROS shuts
down) and exits with status 1. (2) A simulator with autostart:=forced next to a free-decay identifier
(launched by the .test) logs a WARN naming the mismatch."""
import subprocess
import threading
import time
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Log

BAD = {"mode": "sideways", "confidence": "2.0", "window_s": "-1.0", "queue_size": "0"}
EXPECTED = ["mode:", "confidence", "window_s: must be >= 0", "queue_size: must be >= 1"]


LOCK = threading.Lock()
LOGS = []  # every /rosout message since the test node started (shared by the tests)


def on_log(msg):
    with LOCK:
        LOGS.append(msg)


class StartupFailure(unittest.TestCase):
    def setUp(self):
        self.lock = LOCK
        self.logs = LOGS

    def test_invalid_settings_are_listed_everywhere(self):
        args = ["rosrun", "cvg_bench", "identifier_node", "__name:=bad_identifier"]
        args += ["_%s:=%s" % kv for kv in BAD.items()]
        proc = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=20,
                              universal_newlines=True)
        self.assertEqual(proc.returncode, 1, proc.stdout)
        for text in EXPECTED:
            self.assertIn(text, proc.stdout)
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline:
            with self.lock:
                fatal = " ".join(m.msg for m in self.logs
                                 if m.name == "/bad_identifier" and m.level == Log.FATAL)
            if all(text in fatal for text in EXPECTED) and "not started" in fatal:
                break
            time.sleep(0.05)  # poll period of the bounded wait
        for text in EXPECTED:
            self.assertIn(text, fatal)
        self.assertIn("4 problems", fatal)

    def test_mode_mismatch_is_warned(self):
        deadline = time.monotonic() + 15.0
        found = []
        while time.monotonic() < deadline and not found:
            with self.lock:
                found = [m.msg for m in self.logs if m.name == "/cvg/resonator_simulator"
                         and m.level == Log.WARN and "autostart:=forced" in m.msg]
            time.sleep(0.05)  # poll period of the bounded wait
        self.assertTrue(found, "no mode-mismatch warning from the simulator")
        self.assertIn("free_decay instead of forced", found[0])


if __name__ == "__main__":
    rospy.init_node("startup_failure_test")
    # /rosout directly: rostest starts no rosout node (no /rosout_agg); a failing node waits for a
    # /rosout subscriber before it logs.
    rospy.Subscriber("/rosout", Log, on_log)
    time.sleep(0.5)  # the subscription is registered before the tests start anything
    rostest.rosrun("cvg_bench", "startup_failure", StartupFailure)
