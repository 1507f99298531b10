#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Runs every libFuzzer target of tests/fuzz for a set time and prints each one's executions, one
# grep-able line per target: `fuzz <target>: N executions in S s` (or `fuzz <target>: FAILED ...`).
#   bash tools/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]     (default 30 s, every target; as many at
#   once as there are cores)
# Builds the targets in build-asan/ (clang, AddressSanitizer + UBSan, the same tree as CI's
# sanitizer build; FUZZ_BUILD_DIR moves it). Each target starts from its seed corpus
# (tests/fuzz/corpus/<target>/) and keeps what it learns in <build>/fuzz-corpus/<target>/;
# a finding is written to <build>/fuzz-findings/<target>/ and fails the script. An input that
# runs for more than 10 s is a finding too (a hang; libFuzzer's own default waits 20 min). Copy
# a finding into tests/fuzz/regressions/<target>/ with the fix: CTest replays that folder
# (fuzz_replay_<target>).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-30}"
shift || true
build="${FUZZ_BUILD_DIR:-build-asan}"
all_targets=(safetensors camera_csv imu_csv gyro_log sensor_yaml rates_csv image device_spec flo)
all_targets+=(mcap ros2_sqlite)  # ROS 2 bag containers
all_targets+=(ros1_bag)  # the ROS 1 bag container and the sensor_msgs decoders
all_targets+=(gpmf)  # GoPro MP4s' GPMF gyro
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=("${all_targets[@]}")

if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DINERTIALNET_BUILD_BENCHMARKS=OFF \
    -DINERTIALNET_SANITIZE=address,undefined -DINERTIALNET_BUILD_FUZZERS=ON
fi
jobs=$(nproc 2>/dev/null || echo 2)
cmake --build "$build" -j "$jobs" --target "${targets[@]/#/fuzz_}"

# Leaks count as findings; the readers touch no OpenCL driver, so no suppressions are needed.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}"
# One target per core at a time: a libFuzzer process runs on one core, so each target still has a
# core for its SECONDS, and the pass takes about ceil(targets / cores) × SECONDS instead of
# targets × SECONDS. On a 2-core machine like CI's: 3.8 min for the 13 targets instead of 6.9 min.
# Each target's executions against a run one at a time, from an empty corpus: 73-130 % in one run,
# 28 % for imu_csv and gyro_log (run side by side) in another, the rest 74-117 %. Throughput
# depends on which inputs a run happens to reach and on the two processes sharing the memory bus.
# Each target writes its result line to its own file, and the lines are printed in target order
# whatever order the targets finish in.
results="$build/fuzz-findings/results"
rm -rf "$results"
mkdir -p "$results"
run_target() {
  local target=$1 corpus="$build/fuzz-corpus/$1" findings="$build/fuzz-findings/$1"
  local log="$build/fuzz-findings/$1.log" code runs
  mkdir -p "$corpus" "$findings"
  set +e
  "$build/tests/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout=10 -print_final_stats=1 -max_len=65536 \
    -artifact_prefix="$findings/" "$corpus" "tests/fuzz/corpus/$target" >"$log" 2>&1
  code=$?
  set -e
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  if [ "$code" -ne 0 ]; then
    printf 'fuzz %s: FAILED after %s executions (exit %d): see %s and %s\n' "$target" "${runs:-?}" "$code" "$log" \
      "$findings" >"$results/$target.line"
  else
    printf 'fuzz %s: %s executions in %s s\n' "$target" "${runs:-?}" "$seconds" >"$results/$target.line"
  fi
}
running=0
for target in "${targets[@]}"; do
  if [ "$running" -ge "$jobs" ]; then
    wait -n || true  # a target that dies early is reported below, from its missing line
    running=$((running - 1))
  fi
  run_target "$target" &
  running=$((running + 1))
done
wait

failed=0
for target in "${targets[@]}"; do
  line="$results/$target.line"
  if [ -f "$line" ]; then
    if grep -q '^fuzz [^:]*: FAILED' "$line"; then
      failed=1
      tail -n 60 "$build/fuzz-findings/$target.log" >&2  # the report, for a CI log that outlives the build tree
    fi
    cat "$line"
  else
    failed=1  # the run itself did not finish (killed, or the shell failed before the line)
    printf 'fuzz %s: FAILED: no result (see %s)\n' "$target" "$build/fuzz-findings/$target.log"
  fi
done
exit "$failed"
