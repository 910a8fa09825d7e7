#!/usr/bin/env bash
# make test-asan: the ROS-free core, the offline tool and the core tests built with AddressSanitizer
# + UndefinedBehaviorSanitizer (g++, the compiler of the Release build, so the x86-64-v3 clones are
# exercised too; plain CMake, CVG_CORE_ONLY, own build dir build/asan: the catkin build is left
# alone), then run: the core gtests and the bad-input suite (test/python/test_bad_input_suite.py)
# against the sanitized tool. Any sanitizer report fails the run (-fno-sanitize-recover,
# halt_on_error). A last step builds the SIMD-clone units and their tests at -O0 (nothing inlined).
# Env: JOBS (default 2), CVG_ASAN_FILTER (gtest filter; default skips the 2 slow cases below).
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
b="$root/build/asan"
jobs=${JOBS:-2}
# EIGEN_MALLOC_ALREADY_ALIGNED=1: Debian's Ceres is linked statically (libceres.a, built without
# sanitizers), so its copies of Eigen's inline functions and ours are merged by the linker (one
# copy of each is kept). Eigen turns the "malloc is 16-byte aligned" assumption off whenever
# __SANITIZE_ADDRESS__ is defined and then allocates with its hand-made aligned malloc (pointer
# moved by 16 bytes); Ceres' copies, built with the assumption, free with plain free(): ASan
# reported "attempting free on address which was not malloc()-ed" in BDCSVD::divide (ceres::
# Covariance DENSE_SVD) on a JacobiSVD block allocated by our copy. Stating the macro makes both
# sides agree, as in the Release build. ASan's malloc returns 16-byte aligned blocks on x86-64
# (checked: 2900 allocations of 1..5000 bytes, none misaligned).
flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g1"
flags+=" -DEIGEN_MALLOC_ALREADY_ALIGNED=1"
start=$(date +%s)
cmake -S "$root" -B "$b" -DCVG_CORE_ONLY=ON -DCVG_WERROR=OFF -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1 -DNDEBUG" -DCMAKE_CXX_FLAGS="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" > "$root/build/asan_configure.log" 2>&1 \
  || { tail -n 40 "$root/build/asan_configure.log"; exit 1; }
cmake --build "$b" --target cvg_ident cvg_core_tests -j "$jobs" > "$root/build/asan_build.log" 2>&1 \
  || { grep -E "error|Error" "$root/build/asan_build.log" | head -n 40; exit 1; }
echo "test-asan: built in $(( $(date +%s) - start )) s"

export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# Trimmed (they run in the Release `make test`; here they would only repeat code paths of faster
# cases): the two slowest cases, 40 % of the core tests' time (1.9 s and 1.1 s of 7.4 s in Release):
# the filter checked on a dense frequency grid, a Monte Carlo coverage count of Ceres intervals.
filter=${CVG_ASAN_FILTER:-"-FirLowpass.MeetsSpecOnDenseGrid:CorrelatedIntervals.OutputErrorFitHoldsCoverageUnderAr1Noise"}
failed=0
"$b/cvg_core_tests" --gtest_filter="$filter" --gtest_brief=1 || failed=1
echo "test-asan: core tests done at $(( $(date +%s) - start )) s"
CVG_BENCH_ROOT="$root" CVG_IDENT_TOOL="$b/bin/cvg_ident" \
  /usr/bin/python3 -m unittest discover -s "$root/test/python" -p "test_bad_input_suite.py" \
  || failed=1
echo "test-asan: bad-input suite done at $(( $(date +%s) - start )) s"

# -O0: helpers taking or returning a 4-double vector by value must be inlined into their
# x86-64-v3 clone callers (an out-of-line copy has the default target's calling convention).
o0="$b/o0"
mkdir -p "$o0"
g++ -std=gnu++17 -O0 -g1 -fsanitize=address,undefined -fno-sanitize-recover=undefined \
  -I"$root/include" "$root/src/core/io/sample_validator.cpp" \
  "$root/test/core/io/sample_validator_test.cpp" "$root/test/core/io/sample_validator_stream_test.cpp" \
  -o "$o0/sample_validator_o0_tests" -lgtest -lgtest_main -pthread \
  && "$o0/sample_validator_o0_tests" --gtest_brief=1 || failed=1
echo "test-asan: total $(( $(date +%s) - start )) s; $([ $failed = 0 ] && echo passed || echo FAILED)"
exit $failed
