#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# tools/portable on the build machine, with PoCL standing in for NVIDIA's OpenCL library:
#  1. a stand-in (stub_library.py) loads in place of the real library and, when its code is
#     reached, aborts naming the function;
#  2. the bundle of the CLI loads nothing but its own libraries and the system's, and runs
#     `devices` and a small `bench` through run.sh;
#  3. bad input (a missing build folder, binary or bundle) exits 2 and a failed copy, tarball or
#     unpacking exits 1, each with one line on stderr naming the file.
#
#   tools/portable/test_portable.sh BUILD_DIR
set -euo pipefail
build=$1
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT

# 1. A stand-in for zlib, and a program that calls it.
zlib=$(ldconfig -p | awk '$1 == "libz.so.1" && $NF ~ /^\// {print $NF}' | sed -n 1p)
[ -n "$zlib" ] || { echo "test_portable: no libz.so.1 on this machine" >&2; exit 1; }
mkdir "$work/stubs"
python3 "$here/stub_library.py" "$zlib" "$work/stubs"
printf 'const char* zlibVersion(void);\nint main(void) { return zlibVersion() != 0; }\n' > "$work/call.c"
cc -o "$work/call" "$work/call.c" -L"$work/stubs" -l:libz.so.1
# (through sh, so that the abort's "Aborted" line lands in the log too)
if LD_LIBRARY_PATH="$work/stubs" sh -c '"$0"' "$work/call" 2> "$work/call.err"; then
  echo "test_portable: the program ran through the stand-in instead of aborting" >&2; exit 1
fi
grep -q "stand-in libz.so.1: zlibVersion called" "$work/call.err" ||
  { echo "test_portable: the stand-in did not name the function:" >&2; cat "$work/call.err" >&2; exit 1; }

# 2. The CLI's bundle, run with PoCL's ICD library in NVIDIA's place.
"$here/bundle.sh" "$build" "$work/bundle.tar.xz" > "$work/bundle.log"
icd=$(cat /etc/OpenCL/vendors/pocl.icd 2>/dev/null || true)
[ -n "$icd" ] || { echo "test_portable: no PoCL ICD on this machine" >&2; exit 1; }
run_bundle() { INERTIALNET_BUNDLE_DIR="$work/unpacked" INERTIALNET_BUNDLE_ICD="$icd" "$here/run.sh" "$@"; }
run() { run_bundle "$work/bundle.tar.xz" -- "$@"; }
run inertialnet devices | grep "Portable Computing Language" > /dev/null ||
  { echo "test_portable: the bundle's inertialnet found no device" >&2; exit 1; }
run inertialnet bench --model FlowNet2-C --size 64x64 --pairs 1 --json -q | grep '"seconds_per_pair"' > /dev/null ||
  { echo "test_portable: the bundle's bench gave no figures" >&2; exit 1; }
# What ran came from the bundle: its own binary and its OpenCV.
[ "$(run sh -c 'command -v inertialnet')" = "$work/unpacked/bin/inertialnet" ] ||
  { echo "test_portable: run.sh did not put the bundle's bin/ first on PATH" >&2; exit 1; }
compgen -G "$work/unpacked/lib/libclblast.so*" > /dev/null && compgen -G "$work/unpacked/lib/libopencv_core.so*" > /dev/null ||
  { echo "test_portable: the bundle lacks CLBlast or OpenCV's core" >&2; exit 1; }

# 3. Failures: expect_failure STATUS TEXT COMMAND...: the command exits STATUS and says, in one
# line on stderr, TEXT (which names the file).
expect_failure() {
  local status=$1 text=$2 code=0; shift 2
  "$@" > /dev/null 2> "$work/fail.err" || code=$?
  [ "$code" = "$status" ] && [ "$(wc -l < "$work/fail.err")" = 1 ] && grep -qF -- "$text" "$work/fail.err" ||
    { echo "test_portable: '$*' exited $code (expected $status, one line saying '$text'):" >&2
      cat "$work/fail.err" >&2; exit 1; }
}
expect_failure 2 "bundle: no build folder $work/no-build" "$here/bundle.sh" "$work/no-build" "$work/b.tar.xz"
expect_failure 2 "bundle: no CLI binary $work/stubs/inertialnet" "$here/bundle.sh" "$work/stubs" "$work/b.tar.xz"
expect_failure 2 "bundle: no test binary $build/tests/test_none" "$here/bundle.sh" "$build" "$work/b.tar.xz" test_none
expect_failure 2 "bundle: no folder $work/no-dir" "$here/bundle.sh" "$build" "$work/no-dir/b.tar.xz"
expect_failure 2 "bundle: usage:" "$here/bundle.sh" "$build"
expect_failure 1 "bundle: cannot write the bundle /dev/full" "$here/bundle.sh" "$build" /dev/full
expect_failure 2 "run.sh: no bundle $work/none.tar.xz" run_bundle "$work/none.tar.xz" -- true
echo "not a tarball" > "$work/junk.tar.xz"
expect_failure 1 "run.sh: cannot unpack the bundle $work/junk.tar.xz" run_bundle "$work/junk.tar.xz" -- true
expect_failure 2 "run.sh: no command to run from $work/bundle.tar.xz" run_bundle "$work/bundle.tar.xz"
echo "test_portable: ok ($(du -h "$work/bundle.tar.xz" | cut -f1) bundle, $(ls "$work/unpacked/lib" | wc -l) libraries)"
