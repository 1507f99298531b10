#!/usr/bin/env bash
# The sanitizer pass, run by CI after the normal suites (.ci/run): a second build (build-asan/,
# clang) with AddressSanitizer, LeakSanitizer and UBSan on the project's own targets
# (INERTIALNET_SANITIZE; not CMAKE_CXX_FLAGS), running the unit and OpenCL suites and replaying
# the fuzz corpora, then each libFuzzer target for FUZZ_SECONDS (default 30) through
# tools/fuzz.sh, which prints one `fuzz <target>: N executions in S s` line per target. Any
# sanitizer report, failed suite or fuzz finding fails the script.
#
# Left out here, and why:
#  - the CLI scripts (label cli): the same code is reached by the unit suites and the fuzzers,
#    and their subprocess runs would triple this pass; the CLI is therefore not built either;
#  - install_consumer: it installs the library and builds a consumer project against it; the
#    sanitizer flags stay out of the installed package by design, so that consumer would not
#    link against an instrumented archive;
#  - test_flownet_fixtures (all plans): whole-network runs whose work is the OpenCL kernels
#    (PoCL, uninstrumented); the host code they reach is covered by the per-op suites, and they
#    are the slowest suites (about 4 × 30 s plain, more under ASan).
set -euo pipefail
cd "$(dirname "$0")/.."
build=build-asan
jobs=$(nproc 2>/dev/null || echo 2)
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DINERTIALNET_BUILD_BENCHMARKS=OFF \
  -DINERTIALNET_SANITIZE=address,undefined -DINERTIALNET_BUILD_FUZZERS=ON

selection=(-L "unit|opencl|fuzz" -E "^test_flownet_fixtures")
# Build only what the selection runs: a suite's executable is its test's name less the plan
# suffix (_clblast, _winograd), a replay's is fuzz_<target>. A name that maps to no target
# fails the build step, so the mapping cannot drift silently.
mapfile -t targets < <(ctest --test-dir "$build" -N "${selection[@]}" 2>/dev/null \
  | sed -n 's/^ *Test *#[0-9]*: *//p' \
  | sed -E -e 's/^(test_.+)_(clblast|winograd)$/\1/' -e 's/^fuzz_replay_/fuzz_/' | sort -u)
cmake --build "$build" -j "$jobs" --target "${targets[@]}"

# Pinned cache state: PoCL compiles every kernel afresh in this pass (see the suppressions).
export POCL_CACHE_DIR="$PWD/$build/pocl-cache"
export INERTIALNET_CACHE_DIR="$PWD/$build/program-cache"
rm -rf "$POCL_CACHE_DIR" "$INERTIALNET_CACHE_DIR"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan_suppressions.txt:print_suppressions=0"
status=0
ctest --test-dir "$build" --output-on-failure -j "$jobs" "${selection[@]}" || status=$?
if [ "$status" -ne 0 ]; then
  # LeakSanitizer's tracer (the thread that stops the process at exit to scan its memory) now
  # and then crashes with SIGSEGV after an OpenCL suite has passed, PoCL's worker threads still
  # alive: "Tracer caught signal 11" and "LeakSanitizer has encountered a fatal error", no
  # report (seen once each in test_conv2d_winograd and test_head_backprop, in different passes;
  # both passed when run again). That is the checker failing, not a finding; its cause is not
  # pinned down (rare, and LSan prints nothing more). Such a suite runs
  # once more, everything else as before; a suite that failed in any other way (a sanitizer
  # report, a failed assertion, a timeout, a second tracer crash) fails the pass.
  log="$build/Testing/Temporary/LastTest.log"
  mapfile -t failed < <(sed 's/^[0-9]*://' "$build/Testing/Temporary/LastTestsFailed.log")
  mapfile -t tracer < <(awk '
    /^[0-9]+\/[0-9]+ Testing: / { name = $3 }
    /Tracer caught signal/ { crashed[name] = 1 }
    /ERROR: (AddressSanitizer|LeakSanitizer: detected)|runtime error:|\[  FAILED  \]/ { report[name] = 1 }
    END { for (t in crashed) if (!(t in report)) print t }' "$log" | sort)
  if [ "${#tracer[@]}" -eq 0 ] || [ "${#tracer[@]}" -ne "${#failed[@]}" ]; then
    exit "$status"
  fi
  echo "check_sanitizers: LeakSanitizer's tracer crashed in ${tracer[*]}; running them once more"
  ctest --test-dir "$build" --output-on-failure -j "$jobs" -R "^($(IFS='|'; echo "${tracer[*]}"))\$"
fi
bash tools/fuzz.sh "${FUZZ_SECONDS:-30}"
