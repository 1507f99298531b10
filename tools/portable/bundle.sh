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
set -euo pipefail
build=$1 out=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
mkdir -p "$work/bin" "$work/lib"
cp "$build/inertialnet" "$work/bin/"
for t in "$@"; do cp "$build/tests/$t" "$work/bin/"; done
strip "$work"/bin/*
libdir=/lib/x86_64-linux-gnu
keep="libopencv_core.so.406 libopencv_imgproc.so.406 libopencv_imgcodecs.so.406 libopencv_videoio.so.406
      libopencv_video.so.406 libopencv_calib3d.so.406 libopencv_features2d.so.406 libopencv_flann.so.406
      libopengv.so.1.0 libclblast.so.1 libOpenCL.so.1 libsqlite3.so.0 libtbb.so.12 libz.so.1 libjpeg.so.62
      libpng16.so.16 libzstd.so.1 liblz4.so.1 libbz2.so.1.0"
system=" libstdc++.so.6 libm.so.6 libgcc_s.so.1 libc.so.6 ld-linux-x86-64.so.2 libpthread.so.0 libdl.so.2 librt.so.1 "
for l in $keep; do cp -L "$libdir/$l" "$work/lib/"; done
needed=$( (for b in "$work"/bin/* "$work"/lib/*; do readelf -d "$b"; done) | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p' | sort -u)
for n in $needed; do
  case " $keep $system " in *" $n "*) continue ;; esac
  python3 "$here/stub_library.py" "$libdir/$n" "$work/lib"
done
# Every library the binaries load must now come from the bundle or the system list above.
for b in "$work"/bin/*; do
  missing=$(LD_LIBRARY_PATH="$work/lib" ldd "$b" | awk '$3 ~ /^\// && $3 !~ /^'"${work//\//\\/}"'/ {print $1}' |
            while read -r l; do case "$system" in *" $l "*) ;; *) echo "$l" ;; esac; done)
  [ -z "$missing" ] || { echo "bundle: $b still loads from the system: $missing" >&2; exit 1; }
done
tar cJf "$out" -C "$work" bin lib
echo "bundle: $out ($(du -h "$out" | cut -f1))"
