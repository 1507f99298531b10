#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The sanitizer pass, run by CI after the normal suites (.ci/run): a second build (build-asan/,
# clang) with AddressSanitizer, LeakSanitizer and UBSan on the project's own targets
# (INERTIALNET_SANITIZE; not CMAKE_CXX_FLAGS), running the unit and OpenCL suites and replaying
# the fuzz corpora, then each libFuzzer target for FUZZ_SECONDS (default 30) through
# tools/fuzz.sh, which prints one `fuzz <target>: N executions in S s` line per target. Any
# sanitizer report, failed suite or fuzz finding fails the script.
#
# Left out here, and why:
#  - the CLI scripts (label cli): the same code is reached by the unit suites and the fuzzers,
#    and their subprocess runs would triple this pass. The CLI is still built, so that CI
#    compiles every source with clang as well as gcc;
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
# The interpreter of tools/python_env.sh (made by tools/check.sh before): tests that write their
# input with PyPI packages first (test_ros2_bags' bags from rosbags and mcap) find them there.
python=$(bash tools/python_env.sh build/python-venv)
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DINERTIALNET_BUILD_BENCHMARKS=OFF \
  -DINERTIALNET_SANITIZE=address,undefined -DINERTIALNET_BUILD_FUZZERS=ON -DPython_EXECUTABLE="$python"

# Statistical tests (hundreds of solved pairs to measure a distribution; label "statistics") run
# in the main pass: under the sanitizers they take over 15 min and exercise nothing the
# geometric-head and pipeline suites do not.
selection=(-L "unit|opencl|fuzz" -LE "statistics" -E "^test_flownet_fixtures")
# Build only what the selection runs: a suite's executable is its test's name less the plan
# suffix (_clblast, _winograd), a replay's is fuzz_<target>. A name that maps to no target
# fails the build step, so the mapping cannot drift silently.
mapfile -t targets < <(ctest --test-dir "$build" -N "${selection[@]}" 2>/dev/null \
  | sed -n 's/^ *Test *#[0-9]*: *//p' \
  | sed -E -e 's/^(test_.+)_(clblast|winograd)$/\1/' -e 's/^fuzz_replay_/fuzz_/' | sort -u)
# A test that is no target of its own (a fixture that writes data with Python) is left out of the
# build list: only names the build system knows as targets are built.
mapfile -t known < <(cmake --build "$build" --target help | sed -n 's/^\.\.\. \([^ ]*\).*/\1/p')
mapfile -t targets < <(comm -12 <(printf '%s\n' "${targets[@]}" | sort -u) <(printf '%s\n' "${known[@]}" | sort -u))
cmake --build "$build" -j "$jobs" --target "${targets[@]}" inertialnet_cli

# Pinned cache state: PoCL compiles every kernel afresh in this pass (see the suppressions).
export POCL_CACHE_DIR="$PWD/$build/pocl-cache"
export INERTIALNET_CACHE_DIR="$PWD/$build/program-cache"
rm -rf "$POCL_CACHE_DIR" "$INERTIALNET_CACHE_DIR"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# intercept_tls_get_addr=0: LeakSanitizer's tracer crashed (SIGSEGV, "Tracer caught signal 11",
# no report) at the exit of a passing OpenCL suite, a few suites per pass. The cause is in the
# sanitizer runtime of clang 14 (up to 16): its __tls_get_addr interceptor takes a dynamic TLS
# block whose address is 16 modulo 4096 for one allocated by glibc 2.19-2.24, and reads the
# 16 bytes before it as that block's start and size. Since glibc 2.25 those blocks come from
# malloc, so under ASan the two words are ASan's own chunk header, and the tracer scans a
# range that is not mapped. A dynamic TLS block exists per thread for each dlopen'ed library
# with thread-locals: PoCL (loaded by the ICD loader) and its LLVM, with PoCL's worker
# threads, so OpenCL suites draw that offset now and then (verbosity=2 shows the interceptor
# at work there). Without the interception LeakSanitizer no longer scans those blocks for
# pointers; they belong to the OpenCL driver, whose allocations are suppressed anyway, and our
# own thread-locals are static TLS, which is still scanned.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1:intercept_tls_get_addr=0"
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan_suppressions.txt:print_suppressions=0"
ctest --test-dir "$build" --output-on-failure -j "$jobs" "${selection[@]}"
bash tools/fuzz.sh "${FUZZ_SECONDS:-30}"
