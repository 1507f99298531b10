#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs the Debian packages that building, testing and running InertialNet-CL need (OpenCL
# headers and ICD loader, PoCL for the CPU, CLBlast, OpenCV, FFmpeg's libraries for videos;
# sqlite3, zstd, lz4 and bz2 for ROS bags; GStreamer's base plugins and gst-launch for the
# live-capture tests (videotestsrc; OpenCV's videoio reads live sources through GStreamer);
# Eigen, GoogleTest, Google Benchmark, CLI11, nlohmann-json, CMake and a C++17 compiler; OpenBLAS
# only as the benchmarks' reference, never linked into the library; python3 and zsh for the CLI's
# terminal and completion tests; python3-venv and python3-dev for the Python package, whose own
# build and test tools come from PyPI through tools/python_env.sh; clang with its sanitizer and
# libFuzzer runtimes (libclang-rt-14-dev, which clang only recommends) and llvm's symbolizer for
# CI's sanitizer pass, tools/check_sanitizers.sh).
# Does nothing when everything is present. Works as root (no sudo needed) or through sudo.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  opencl-headers ocl-icd-opencl-dev pocl-opencl-icd clinfo
  libclblast-dev libopenblas-dev
  libopencv-dev libeigen3-dev libopengv-dev
  libavformat-dev libavcodec-dev libswscale-dev libavutil-dev
  libsqlite3-dev libzstd-dev liblz4-dev libbz2-dev
  gstreamer1.0-plugins-base gstreamer1.0-tools
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev
  python3 zsh python3-venv python3-dev
  clang libclang-rt-14-dev llvm
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [ "$status" = "installed" ] || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo)
else
  echo "setup: missing packages (${missing[*]}) and neither root nor sudo to install them" >&2
  exit 1
fi

echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
