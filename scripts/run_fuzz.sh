#!/usr/bin/env bash
# make fuzz: libFuzzer (clang-14, -fsanitize=fuzzer,address,undefined) on the CSV record reader,
# the ring-down CSV reader, the one-mode response reader, the files batch reads back, the rosbag reader, the `drift --params` JSON and the preset YAML, each
# for FUZZ_SECONDS (default 60 s) from the seed corpus in test/fuzz/corpus/<target>/ (new inputs go
# to build/fuzz/corpus, crashes to build/fuzz/crashes). A crash fails the run; add the input to the
# bad-input suite.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
b="$root/build/fuzz"
jobs=${JOBS:-2}
secs=${FUZZ_SECONDS:-60}
# FUZZ_SEED: a fixed libFuzzer seed (CI sets one, so that its run is a reproducible prefix of the
# same input sequence on every machine); unset or 0 = a new random seed each run.
seed=${FUZZ_SEED:-0}
msg_include="$root/build/ws/devel/include"
extra=()
if [ -f "$msg_include/cvg_bench/SlowState.h" ]; then
  extra=(-DCVG_FUZZ_MSG_INCLUDE="$msg_include")
else
  echo "fuzz: no generated message headers (run make build first): the bag reader is skipped"
fi
# EIGEN_MALLOC_ALREADY_ALIGNED=1: as in scripts/run_asan_tests.sh (Eigen code shared with the
# uninstrumented libraries must allocate and free alike).
san="-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -g -O1"
san+=" -DEIGEN_MALLOC_ALREADY_ALIGNED=1"
cmake -S "$root" -B "$b" -DCVG_CORE_ONLY=ON -DCVG_FUZZ=ON -DCVG_WERROR=OFF -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_CXX_FLAGS_RELEASE="-DNDEBUG" -DCMAKE_CXX_FLAGS="$san" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" "${extra[@]}" \
  > "$root/build/fuzz_configure.log" 2>&1 || { tail -n 30 "$root/build/fuzz_configure.log"; exit 1; }
targets=(fuzz_csv_reader fuzz_params_json fuzz_preset_yaml fuzz_ringdown_reader fuzz_response_reader
  fuzz_batch_files)
[ ${#extra[@]} -gt 0 ] && targets+=(fuzz_bag_reader)
cmake --build "$b" --target "${targets[@]}" -j "$jobs" > "$root/build/fuzz_build.log" 2>&1 \
  || { grep -E "error" "$root/build/fuzz_build.log" | head -n 30; exit 1; }
export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
failed=0
for t in "${targets[@]}"; do
  name=${t#fuzz_}
  case $name in csv_reader) c=csv;; params_json) c=params;; preset_yaml) c=preset;; ringdown_reader) c=ringdown;; response_reader) c=response;; bag_reader) c=bag;;
    batch_files) c=batch;; esac
  mkdir -p "$b/corpus/$c" "$b/crashes/$c"
  # Past findings (test/fuzz/regressions/<kind>/, also cases of the bad-input suite) are rerun first.
  regress=()
  [ -d "$root/test/fuzz/regressions/$c" ] && regress=("$root/test/fuzz/regressions/$c")
  echo "fuzz: $t for $secs s"
  if ! (cd "$b/crashes/$c" && "$b/$t" -max_total_time="$secs" -seed="$seed" -max_len=65536 -timeout=10 \
        -rss_limit_mb=2048 -print_final_stats=1 "$b/corpus/$c" "$root/test/fuzz/corpus/$c" "${regress[@]}" \
        > "$b/$t.log" 2>&1); then
    failed=1
    echo "fuzz: $t FOUND A CRASH (log: $b/$t.log, input in $b/crashes/$c)"
    grep -E "ERROR|runtime error|SUMMARY" "$b/$t.log" | head -n 5
  else
    grep -E "stat::number_of_executed_units|cov:" "$b/$t.log" | tail -n 2
  fi
done
exit $failed
