#!/bin/bash
# SPDX-License-Identifier: Apache-2.0
# Pack the built CLI and test binaries with the shared libraries they need into one tarball that
# runs on another x86-64 Linux machine without Debian's packages (a lent GPU machine):
#
#   tools/portable/bundle.sh build OUT.tar.xz [test_name ...]
#   # there: tools/portable/run.sh OUT.tar.xz -- bin/inertialnet bench --model FlowNet2
#
# OpenCV, CLBlast, OpenGV, the OpenCL ICD loader and the small codecs (zlib, PNG, JPEG, zstd, lz4,
# bzip2, SQLite, TBB) travel as they are. The deep trees behind OpenCV's image and video I/O and
# FFmpeg (GDAL, GStreamer, FFmpeg, TIFF, WebP, OpenEXR, DICOM, LAPACK, protobuf through opencv_dnn)
# travel as stand-ins (stub_library.py): the bundle runs bench, the network tests and
# tools/compare/compare.py; reading a video or a TIFF through it aborts naming the stand-in.
# glibc and libstdc++ are the other machine's (they must be as new as Debian 12's).
#
# Exits 2 on bad input (a missing build folder, binary or output folder, a wrong argument count),
# 1 when the bundling itself fails (a copy or the tarball could not be written), each with one
# message naming the file.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
me=bundle
source "$here/errors.sh"
[ $# -ge 2 ] || fail 2 "usage: tools/portable/bundle.sh BUILD_DIR OUT.tar.xz [test_name ...]"
build=$1 out=$2; shift 2
[ -d "$build" ] || fail 2 "no build folder $build"
[ -f "$build/inertialnet" ] || fail 2 "no CLI binary $build/inertialnet (build the inertialnet_cli target first)"
for t in "$@"; do [ -f "$build/tests/$t" ] || fail 2 "no test binary $build/tests/$t"; done
[ -d "$(dirname "$out")" ] || fail 2 "no folder $(dirname "$out") for the bundle $out"
[ ! -d "$out" ] || fail 2 "the bundle $out would replace a folder"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin" "$work/lib"
attempt "cannot copy $build/inertialnet into the bundle" cp "$build/inertialnet" "$work/bin/"
for t in "$@"; do attempt "cannot copy $build/tests/$t into the bundle" cp "$build/tests/$t" "$work/bin/"; done
attempt "cannot strip the binaries in the bundle" strip "$work"/bin/*
# Kept as they are (by name, any version); the system's own libraries stay the other machine's;
# every other library one of these needs becomes a stand-in.
keep='^lib(opencv_(core|imgproc|imgcodecs|videoio|video|calib3d|features2d|flann)|opengv|clblast|OpenCL|sqlite3|tbb|z|jpeg|png16|zstd|lz4|bz2)\.so'
system=" libstdc++.so.6 libm.so.6 libgcc_s.so.1 libc.so.6 ld-linux-x86-64.so.2 libpthread.so.0 libdl.so.2 librt.so.1 "
# Where each library the binaries load lives here (soname → path), from the dynamic loader.
declare -A path_of
for b in "$work"/bin/*; do
  while read -r name arrow path _; do
    [ "$arrow" = "=>" ] && [ "${path:0:1}" = "/" ] && path_of[$name]=$path
  done < <(ldd "$b")
done
needed_by() { readelf -d "$1" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'; }
declare -A done_
queue=$(for b in "$work"/bin/*; do needed_by "$b"; done | sort -u)
while [ -n "$queue" ]; do
  next=""
  for n in $queue; do
    [ -n "${done_[$n]:-}" ] && continue
    done_[$n]=1
    case "$system" in *" $n "*) continue ;; esac
    real=${path_of[$n]:-}
    [ -n "$real" ] || fail 1 "cannot find $n"
    if [[ $n =~ $keep ]]; then
      attempt "cannot copy $real into the bundle" cp -L "$real" "$work/lib/$n"
      next="$next $(needed_by "$work/lib/$n")"
    else
      python3 "$here/stub_library.py" "$real" "$work/lib"
    fi
  done
  queue=$next
done
# Every library the binaries load must now come from the bundle or the system list above.
for b in "$work"/bin/*; do
  missing=$(LD_LIBRARY_PATH="$work/lib" ldd "$b" | awk '$3 ~ /^\// && $3 !~ /^'"${work//\//\\/}"'/ {print $1}' |
            while read -r l; do case "$system" in *" $l "*) ;; *) echo "$l" ;; esac; done)
  [ -z "$missing" ] || fail 1 "$b still loads from the system: $missing"
done
attempt "cannot write the bundle $out" tar cJf "$out" -C "$work" bin lib
echo "bundle: $out ($(du -h "$out" | cut -f1))"
