#!/usr/bin/env bash
# Runs every test: gtest (core, no roscore), gtest (ROS adapters), rostest integration tests,
# launch-file checks and Python tests; ends with one line `N passed, N failed`.
set -uo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
ws="$root/build/ws"
results="$ws/build/test_results"
rm -rf "$results" "$root/build/python_test_results"
mkdir -p "$root/build/python_test_results"
export PATH=/usr/bin:/bin:$PATH
# shellcheck disable=SC1091
set +u
source "$ws/devel/setup.bash"
set -u
export ROS_HOME="$root/build/ros_home"
export ROS_LOG_DIR="$ROS_HOME/log"

(cd "$ws" && catkin_make --source .src run_tests -DPYTHON_EXECUTABLE=/usr/bin/python3 -j2 > "$root/build/run_tests.log" 2>&1)
# A test that does not compile is a failure, not a test fewer (the summary counts only results
# written, so a failed test build once passed as "0 failed").
build_failed=0
for t in cvg_core_tests cvg_ros_tests; do
  if ! ls "$results"/cvg_bench/*"$t"*.xml >/dev/null 2>&1; then
    build_failed=1
    echo "run_tests: no results of $t: its build failed (build/run_tests.log):"
    grep -E "error:" "$root/build/run_tests.log" | head -n 20
  fi
done

if ls test/python/test_*.py >/dev/null 2>&1; then
  CVG_BENCH_ROOT="$root" /usr/bin/python3 scripts/run_python_tests.py test/python "$root/build/python_test_results/python.xml"
fi

/usr/bin/python3 scripts/summarize_test_results.py "$results" "$root/build/python_test_results"
summary_rc=$?
[ "$build_failed" -ne 0 ] && exit 1
exit $summary_rc
