#!/usr/bin/env bash
# make test-asan: the ROS-free core, the offline tool and the core tests built with AddressSanitizer
# + UndefinedBehaviorSanitizer (plain CMake, CVG_CORE_ONLY, separate build dir build/asan), then
# run: the core gtests and the bad-input suite (test/python/test_bad_input_suite.py) against the
# sanitized tool. Any sanitizer report fails the run (-fno-sanitize-recover, halt_on_error).
# Env: JOBS (default 2), CVG_ASAN_FILTER (gtest filter; default skips the slowest validation cases).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
b="$root/build/asan"
jobs=${JOBS:-2}
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g1"
start=$(date +%s)
cmake -S "$root" -B "$b" -DCVG_CORE_ONLY=ON -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" > "$root/build/asan_configure.log" 2>&1 \
  || { tail -n 40 "$root/build/asan_configure.log"; exit 1; }
cmake --build "$b" --target cvg_ident cvg_core_tests -j "$jobs" > "$root/build/asan_build.log" 2>&1 \
  || { grep -E "error|Error" "$root/build/asan_build.log" | head -n 40; exit 1; }
echo "test-asan: built in $(( $(date +%s) - start )) s"

export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
filter=${CVG_ASAN_FILTER:-"-*Validation*:*LongRun*"}
failed=0
"$b/cvg_core_tests" --gtest_filter="$filter" --gtest_brief=1 || failed=1
echo "test-asan: core tests done at $(( $(date +%s) - start )) s"
CVG_BENCH_ROOT="$root" CVG_IDENT_TOOL="$b/bin/cvg_ident" \
  /usr/bin/python3 -m unittest discover -s "$root/test/python" -p "test_bad_input_suite.py" \
  || failed=1
echo "test-asan: total $(( $(date +%s) - start )) s; $([ $failed = 0 ] && echo passed || echo FAILED)"
exit $failed
