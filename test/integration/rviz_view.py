#!/usr/bin/python3
"""rostest: rviz under Xvfb (software GL) with config/bench.rviz shows the identifier's markers.
The screenshot (xwd of the root window) must hold the standing wave's yellow, the stiffness axis'
red, the damping axis' blue and the panel's white text; a blank or marker-less view fails. The PNG
goes to $CVG_SCREENSHOT when set (docs/bench_rviz.png was made so)."""
import os
import struct
import subprocess
import tempfile
import threading
import time
import unittest

import numpy as np
import rospy
import rostest

from cvg_bench.msg import ModelEstimate
from visualization_msgs.msg import MarkerArray

WIDTH, HEIGHT = 1200, 846  # config/bench.rviz window geometry
MIN_PIXELS = {"wave_yellow": 300, "stiffness_red": 40, "damping_blue": 40, "text_white": 100}


def read_xwd(path):
    """RGB array of a 24/32-bit ZPixmap XWD file (the X window dump format)."""
    data = open(path, "rb").read()
    h = struct.unpack(">25I", data[:100])
    header_size, depth, width, height = h[0], h[3], h[4], h[5]
    byte_order, bpp, bytes_per_line, ncolors = h[7], h[11], h[12], h[19]
    if bpp not in (24, 32) or depth < 24:
        raise ValueError("xwd: expected 24 or 32 bits per pixel, got %d (depth %d)" % (bpp, depth))
    step = bpp // 8
    start = header_size + 12 * ncolors
    raw = np.frombuffer(data[start:start + bytes_per_line * height], dtype=np.uint8)
    px = raw.reshape(height, bytes_per_line)[:, :step * width].reshape(height, width, step)
    if byte_order == 0:  # least significant byte first: B, G, R(, X)
        return px[:, :, [2, 1, 0]]
    return px[:, :, [step - 3, step - 2, step - 1]]


BACKGROUND = (30, 30, 36)  # config/bench.rviz Background Color


def render_area(rgb):
    """The 3D view: the bounding box of the pixels of the view's background colour (the panels
    around it are light grey and would count as white text)."""
    bg = np.all(np.abs(rgb.astype(int) - BACKGROUND) <= 3, axis=2)
    rows, cols = np.where(bg)
    if rows.size == 0:
        return rgb[:0, :0]
    return rgb[rows.min():rows.max() + 1, cols.min():cols.max() + 1]


def colour_counts(rgb):
    rgb = render_area(rgb)
    r, g, b = (rgb[:, :, i].astype(int) for i in range(3))
    return {
        "wave_yellow": int(np.sum((r > 180) & (g > 150) & (b < 100))),
        "stiffness_red": int(np.sum((r > 150) & (g < 110) & (b < 110))),
        "damping_blue": int(np.sum((b > 170) & (r < 130) & (g > 80) & (g < 200))),
        "text_white": int(np.sum((r > 235) & (g > 235) & (b > 235))),
    }


class RvizView(unittest.TestCase):
    def setUp(self):
        self.lock = threading.Lock()
        self.estimate = None
        self.markers = None
        self.ns = rospy.get_param("~ns", "/cvg")
        rospy.Subscriber(self.ns + "/estimate", ModelEstimate, self.on_estimate)
        rospy.Subscriber(self.ns + "/markers", MarkerArray, self.on_markers)

    def on_estimate(self, msg):
        with self.lock:
            self.estimate = msg

    def on_markers(self, msg):
        with self.lock:
            self.markers = msg

    def wait_for(self, what, timeout_s):
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline and not rospy.is_shutdown():
            with self.lock:
                if what():
                    return True
            time.sleep(0.05)  # poll period of the bounded wait
        return False

    def test_markers_are_drawn(self):
        display = ":%d" % (90 + os.getpid() % 100)
        env = dict(os.environ, DISPLAY=display, LIBGL_ALWAYS_SOFTWARE="1")
        xvfb = subprocess.Popen(["Xvfb", display, "-screen", "0", "%dx%dx24" % (WIDTH, HEIGHT),
                                 "-nolisten", "tcp"], stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        rviz = None
        try:
            time.sleep(1.0)  # Xvfb accepts clients
            # As launch/bench_sim.launch starts it: in the gyro's namespace, -f its resonator frame.
            rviz = subprocess.Popen(["rosrun", "rviz", "rviz", "-d", rospy.get_param("~rviz_config"),
                                     "-f", rospy.get_param("~frame_prefix", "") + "resonator",
                                     "__name:=rviz_view_test_rviz", "__ns:=" + self.ns], env=env,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            self.assertTrue(self.wait_for(
                lambda: self.markers is not None and self.estimate is not None
                and any(m.ns == "panel" for m in self.markers.markers), 40.0),
                "no estimate and panel marker")
            # rviz takes 10-30 s to show its window under software GL on a loaded machine:
            # screenshots every 2 s until the markers are drawn (or the deadline).
            deadline = time.monotonic() + 50.0
            with tempfile.TemporaryDirectory() as tmp:
                dump = os.path.join(tmp, "root.xwd")
                while True:
                    self.assertIsNone(rviz.poll(), "rviz exited")
                    # xwd can fail while Xvfb or rviz's window is still coming up: retry.
                    if subprocess.run(["xwd", "-root", "-silent", "-out", dump], env=env,
                                      timeout=10).returncode != 0:
                        self.assertLess(time.monotonic(), deadline, "xwd kept failing")
                        time.sleep(2.0)  # screenshot period of the bounded wait
                        continue
                    rgb = read_xwd(dump)
                    counts = colour_counts(rgb)
                    if all(counts[k] >= v for k, v in MIN_PIXELS.items()):
                        time.sleep(2.0)  # one more frame: the screenshot shows the settled view
                        subprocess.run(["xwd", "-root", "-silent", "-out", dump], env=env,
                                       check=True, timeout=10)
                        rgb = read_xwd(dump)
                        counts = colour_counts(rgb)
                        break
                    if time.monotonic() > deadline:
                        break
                    time.sleep(2.0)  # screenshot period of the bounded wait
            out = os.environ.get("CVG_SCREENSHOT")
            if out:
                from PIL import Image
                img = Image.fromarray(np.ascontiguousarray(rgb))
                img.thumbnail((720, 720))
                img.save(out)
            for name, least in MIN_PIXELS.items():
                self.assertGreaterEqual(counts[name], least, "%s: %s" % (name, counts))
        finally:
            for p in (rviz, xvfb):
                if p is not None and p.poll() is None:
                    p.terminate()
                    try:
                        p.wait(5)
                    except subprocess.TimeoutExpired:
                        p.kill()


if __name__ == "__main__":
    rospy.init_node("rviz_view_test")
    rostest.rosrun("cvg_bench", "rviz_view", RvizView)
