"""The core library stays ROS-free: no ROS header in its sources (nor in the JSON report library's),
no catkin library on its link line; and its stage folders depend only downwards:
common <- model <- io <- simulate, demod <- estimate <- single_mode, diagnose (a stage includes its own
folder and the stages before it; common/ (errors, package resources, small numeric helpers) includes
nothing of the core and any stage may use it; estimate/internal/ holds kernels any stage may use)."""
import glob
import os
import re
import unittest

ROOT = os.environ.get("CVG_BENCH_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
ROS_INCLUDE = re.compile(r'#\s*include\s*[<"](ros|rosbag|tf2|tf2_ros|diagnostic_updater|std_msgs|'
                         r'geometry_msgs|cvg_bench/ros|cvg_bench/[A-Z]\w*\.h)')


STAGE_ORDER = ["common", "model", "io", "simulate", "demod", "estimate", "single_mode", "diagnose"]
ALLOWED = {
    "common": {"common"},
    "model": {"common", "model"},
    "io": {"common", "model", "io"},
    "simulate": {"common", "model", "io", "simulate"},
    "demod": {"common", "model", "io", "demod"},
    "estimate": {"common", "model", "io", "demod", "estimate"},
    "single_mode": {"common", "model", "io", "demod", "estimate", "single_mode"},
    "diagnose": {"common", "model", "io", "demod", "estimate", "diagnose"},
}
CORE_INCLUDE = re.compile(r'#\s*include\s*"cvg_bench/core/([a-z_]+)/(internal/)?')


class CoreBoundaries(unittest.TestCase):
    def test_stages_depend_only_downwards(self):
        offenders = []
        seen = set()
        for stage in STAGE_ORDER:
            files = glob.glob(os.path.join(ROOT, "include", "cvg_bench", "core", stage, "**", "*.h"),
                              recursive=True)
            files += glob.glob(os.path.join(ROOT, "src", "core", stage, "**", "*.cpp"), recursive=True)
            if files:
                seen.add(stage)
            for path in files:
                with open(path, encoding="utf-8") as f:
                    for n, line in enumerate(f, 1):
                        m = CORE_INCLUDE.search(line)
                        if m and m.group(1) not in ALLOWED[stage] and not m.group(2):
                            offenders.append("%s:%d: %s" % (os.path.relpath(path, ROOT), n, line.strip()))
        self.assertEqual(seen, set(STAGE_ORDER))
        loose = glob.glob(os.path.join(ROOT, "src", "core", "*.cpp"))
        loose += glob.glob(os.path.join(ROOT, "include", "cvg_bench", "core", "*.h"))
        self.assertEqual(loose, [], "core files outside a stage folder")
        self.assertEqual(offenders, [])

    def test_no_ros_header_in_core_sources(self):
        files = glob.glob(os.path.join(ROOT, "include", "cvg_bench", "core", "**", "*.h"), recursive=True)
        files += glob.glob(os.path.join(ROOT, "src", "core", "**", "*.cpp"), recursive=True)
        self.assertGreater(len(files), 10)
        report = glob.glob(os.path.join(ROOT, "include", "cvg_bench", "report", "*.h"))
        report += glob.glob(os.path.join(ROOT, "src", "report", "*.cpp"))
        self.assertEqual(len(report), 8)  # estimate, explain, ringdown, response JSON writers
        files += report
        offenders = []
        for path in files:
            with open(path, encoding="utf-8") as f:
                for n, line in enumerate(f, 1):
                    if ROS_INCLUDE.search(line):
                        offenders.append("%s:%d: %s" % (os.path.relpath(path, ROOT), n, line.strip()))
        self.assertEqual(offenders, [])

    def test_core_link_line_has_no_catkin_library(self):
        with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
            cmake = f.read()
        links = re.findall(r"target_link_libraries\(\s*cvg_bench_core\b([^)]*)\)", cmake)
        self.assertTrue(links, "no target_link_libraries for cvg_bench_core")
        for args in links:
            self.assertNotIn("catkin", args)
            self.assertNotIn("ros", args.lower().replace("ceres", ""))

    def test_built_core_library_has_no_ros_symbols(self):
        lib = glob.glob(os.path.join(ROOT, "build", "ws", "devel", "lib", "libcvg_bench_core.*"))
        if not lib:
            self.skipTest("core library not built as a shared library here")
        import subprocess
        out = subprocess.run(["nm", "-D", "--undefined-only", lib[0]], capture_output=True, text=True).stdout
        self.assertNotIn("ros::", subprocess.run(["c++filt"], input=out, capture_output=True, text=True).stdout)


if __name__ == "__main__":
    unittest.main()
