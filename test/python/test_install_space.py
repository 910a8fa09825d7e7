"""`catkin_make install` gives a working install space: the workspace's install target fills
build/ws/install, and with only that install space sourced (a clean environment, no source tree on
ROS_PACKAGE_PATH) `rosrun cvg_bench cvg_ident --help` runs, a preset is found in the installed
share/cvg_bench (not in the source tree), and `roslaunch --files cvg_bench bench_sim.launch`
resolves the installed launch and config files. Neither the install nor the development space makes
rosrun/roslaunch warn about a file system loop."""
import os
import subprocess
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT", os.path.join(os.path.dirname(__file__), "..", "..")))
WS = os.path.join(ROOT, "build", "ws")
INSTALL = os.path.join(WS, "install")
DEVEL = os.path.join(WS, "devel")


def in_space(setup, command, timeout=120):
    """Runs a bash command with only `setup` sourced (clean environment)."""
    env = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/root"),
           "ROS_HOME": os.path.join(ROOT, "build", "ros_home")}
    script = "source '%s' >/dev/null 2>&1 && %s" % (setup, command)
    return subprocess.run(["/bin/bash", "-c", script], env=env, capture_output=True, text=True,
                          timeout=timeout)


@unittest.skipUnless(os.path.isfile(os.path.join(DEVEL, "setup.bash")), "workspace not built (make build)")
class InstallSpace(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        out = subprocess.run(["cmake", "--build", os.path.join(WS, "build"), "--target", "install"],
                             capture_output=True, text=True, timeout=600)
        cls.install_log = out.stdout[-3000:] + out.stderr[-3000:]
        cls.install_rc = out.returncode

    def setUp(self):
        self.assertEqual(self.install_rc, 0, self.install_log)

    def test_cvg_ident_runs_from_the_install_space(self):
        out = in_space(os.path.join(INSTALL, "setup.bash"), "rospack find cvg_bench && rosrun cvg_bench cvg_ident --help")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(out.stdout.splitlines()[0], os.path.join(INSTALL, "share", "cvg_bench"))
        self.assertIn("usage: cvg_ident", out.stdout)
        self.assertNotIn("loop", out.stderr)

    def test_live_plot_runs_from_the_install_space(self):
        # Issue #27: scripts/plot_live.py was not installed.
        out = in_space(os.path.join(INSTALL, "setup.bash"), "rosrun cvg_bench plot_live.py --help")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("usage: plot_live.py", out.stdout)

    def test_presets_come_from_the_install_space(self):
        out = in_space(os.path.join(INSTALL, "setup.bash"),
                       "rosrun cvg_bench cvg_ident simulate --preset no_such_preset --mode forced --out /dev/null")
        self.assertEqual(out.returncode, 2, out.stderr)
        self.assertIn(os.path.join(INSTALL, "share", "cvg_bench", "config", "resonators"), out.stderr)
        self.assertIn("mems_ring", out.stderr)

    def test_launch_file_resolves_in_the_install_space(self):
        out = in_space(os.path.join(INSTALL, "setup.bash"), "roslaunch --files cvg_bench bench_sim.launch")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertEqual(out.stdout.split(),
                         [os.path.join(INSTALL, "share", "cvg_bench", "launch", "bench_sim.launch")])
        self.assertNotIn("loop", out.stderr)
        # Its parameters load: the installed config/*.yaml files resolve through $(find cvg_bench).
        out = in_space(os.path.join(INSTALL, "setup.bash"), "roslaunch --dump-params cvg_bench bench_sim.launch")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("/cvg/identifier/idle_identify_s", out.stdout)

    def test_development_space_does_not_warn(self):
        out = in_space(os.path.join(DEVEL, "setup.bash"),
                       "rosrun cvg_bench cvg_ident --help >/dev/null && roslaunch --files cvg_bench bench_sim.launch")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertNotIn("File system loop", out.stderr)
        self.assertEqual(len(out.stdout.split()), len(set(out.stdout.split())))


if __name__ == "__main__":
    unittest.main()
