#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The README's test command: set up, build, and run every test (on PoCL unless another device
# is selected with INERTIALNET_TEST_DEVICE / INERTIALNET_DEVICE): the C++ suites, the CLI, the
# Python package's pytest suite on the build tree, and `pip install .` with the suite again.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
python=$(bash tools/python_env.sh build/python-venv)
bash tools/build.sh -DINERTIALNET_BUILD_PYTHON=ON -DPython_EXECUTABLE="$python"
jobs=$(nproc 2>/dev/null || echo 2)
ctest --test-dir build --output-on-failure -j "$jobs"
bash tools/check_pip_install.sh
