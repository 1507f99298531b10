#!/usr/bin/env bash
# The README's main command: set up, build, and run the main job on the bundled default.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh
./build/inertialnet devices
