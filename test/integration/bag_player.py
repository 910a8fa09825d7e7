"""Test support: play a bag with `rosbag play --clock` once the nodes under test are up (their
services answer) and subscribed to every topic in the bag (`--wait-for-subscribers`; a loaded CI
machine can take longer than the one-second delay to connect), so no message is lost to start-up
order; stop it by its own process id. The player's outgoing queue holds the whole bag: at its default
of 100 a burst (401 slow states in 0.2 s) overflows while a loaded machine's subscriber reads, and
rosbag drops the oldest messages without a word (CI on 958c372: rls_equals_batch)."""
import subprocess

import rospy

QUEUE = 1000000  # messages; memory is only used while the subscriber lags


class BagPlayer(object):
    def __init__(self, bag, wait_for_services, timeout_s, loop=False):
        for name in wait_for_services:
            rospy.wait_for_service(name, timeout_s)
        args = [
            "rosbag", "play", "--clock", "--quiet", "--delay=1.0", "--wait-for-subscribers",
            "--queue=%d" % QUEUE
        ]
        if loop:
            args.append("--loop")
        self.proc = subprocess.Popen(args + [bag], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
        self.proc.wait(10)
