#!/usr/bin/env bash
# The README's test command: set up, build, and run every test (on PoCL unless another device
# is selected with INERTIALNET_TEST_DEVICE / INERTIALNET_DEVICE).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh
jobs=$(nproc 2>/dev/null || echo 2)
ctest --test-dir build --output-on-failure -j "$jobs"
