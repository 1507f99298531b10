#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Makes (or completes) a Python virtual environment with what building and testing the Python
# package needs, from PyPI: pybind11 and scikit-build-core (the build), numpy, pytest (the tests),
# pandas (the rates CSV read back with its defaults), rosbags (an independent writer of the
# ROS 1 and ROS 2 bags the tests read) and mcap (MCAP files with lz4 chunks, which rosbags does
# not write), and ray (inertialnet.batch's cluster backend, the optional extra `.[ray]`: its test
# runs in CI).
#   bash tools/python_env.sh [FOLDER]     (default: .venv-python; prints the interpreter's path)
# Needs python3-venv and python3-dev (tools/setup.sh installs them).
set -euo pipefail
cd "$(dirname "$0")/.."
venv=${1:-.venv-python}
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv" >&2
fi
if ! "$venv/bin/python" -c "import pybind11, scikit_build_core, numpy, pytest, pandas, rosbags, mcap, ray" 2>/dev/null; then
  "$venv/bin/python" -m pip install -q --disable-pip-version-check "pybind11>=2.12" "scikit-build-core>=0.9" \
    "numpy>=1.21" "pytest>=7" "pandas>=1.3" "rosbags>=0.9" "mcap>=1.1" "ray>=2.9" >&2
fi
echo "$PWD/$venv/bin/python"
