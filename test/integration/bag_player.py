"""Test support: play a bag with `rosbag play --clock` once the nodes under test are up (their
services answer) and subscribed to every topic in the bag (`--wait-for-subscribers`; a loaded CI
machine can take longer than the one-second delay to connect), so no message is lost to start-up
order; stop it by its own process id."""
import subprocess

import rospy


class BagPlayer(object):
    def __init__(self, bag, wait_for_services, timeout_s, loop=False):
        for name in wait_for_services:
            rospy.wait_for_service(name, timeout_s)
        args = [
            "rosbag", "play", "--clock", "--quiet", "--delay=1.0", "--wait-for-subscribers"
        ]
        if loop:
            args.append("--loop")
        self.proc = subprocess.Popen(args + [bag], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def stop(self):
        if self.proc.poll() is None:
            self.proc.terminate()
        self.proc.wait(10)
