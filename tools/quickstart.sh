#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The README's main command: set up, build, and run the main job on the bundled default — a
# synthetic EuRoC-layout sequence with exact gyro ground truth (rendered on the first run into
# data/synthetic-rotation/), angular rates for every frame pair, and the paper's metrics.
# Without weights, predict uses Lucas-Kanade flow and the geometric head; pass weights with
#   bash tools/quickstart.sh --weights flownet2.safetensors --weights head.safetensors
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
bash tools/build.sh
sequence=data/synthetic-rotation
mkdir -p data out
if [ ! -d "$sequence/mav0" ]; then
  ./build/inertialnet synth "$sequence" --frames 40 --motion rotation --seed 1
fi
./build/inertialnet predict "$sequence" -o out/rates.csv --stats "$@"
# The geometric head measures each inter-frame rotation, an average over the frame interval:
# compare with the interval mean of the gyro.
./build/inertialnet eval out/rates.csv "$sequence" --target mean --plot out/rates.png
echo "rates: out/rates.csv; plots: out/rates.png, out/rates_hist.png"
