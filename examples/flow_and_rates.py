#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Angular rates of a synthetic sequence with the weight-free path, step by step and in one call.

    pip install .                      # from a clone (needs the packages of tools/setup.sh)
    python3 examples/flow_and_rates.py [OUT_FOLDER]

Renders a short synthetic EuRoC-layout sequence, computes DIS optical flow and the geometric
head's angular rate for each frame pair, checks that predict() gives the same numbers, scores them
against the gyro with evaluate(), and saves one flow as .flo, KITTI PNG and colour-wheel PNG.
"""
import pathlib
import sys

import numpy as np

import inertialnet

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "example-out")
sequence = out / "sequence"
if not (sequence / "mav0").exists():
    inertialnet.synth(sequence, frames=10, width=376, height=240, seed=3)

seq = inertialnet.Sequence(sequence)
head = inertialnet.GeometricHead()  # device=None: $INERTIALNET_DEVICE, else the first GPU, else a CPU
t = seq.timestamps_ns
previous = seq[0]  # uint8 RGB (H, W, 3)
for k in range(1, len(seq)):
    frame = seq[k]
    flow = inertialnet.dis_flow(previous, frame)  # float32 (H, W, 2), pixels
    # The head gets the flow with its forward-backward check, as predict() gives it (flow_check=0.5):
    # vectors whose round trip misses by over half a pixel (at 752 columns) are marked unknown.
    checked = inertialnet.dis_flow(previous, frame, flow_check=0.5)
    w = head.rates(checked, seq.camera, dt=(t[k] - t[k - 1]) * 1e-9, camera_to_body=seq.camera_to_body)
    print(f"{t[k]}  wx {w[0]:+.4f}  wy {w[1]:+.4f}  wz {w[2]:+.4f} rad/s")
    previous = frame

# The same in one call (what `inertialnet predict` does): Rates (.w is (N, 3) rad/s, .sigma each
# rate's standard deviation). The loop above gives two-frame rates; predict() by default smooths
# them over the next two pairs (smooth="lag:2"), so the comparison asks for the two-frame ones;
# and its weight-free default is sparse Lucas-Kanade flow, so it is asked for DIS, the loop's.
rates = inertialnet.predict(sequence, smooth="off", flow="dis")
print("predict() agrees with the loop:", np.allclose([rates[c][-1] for c in ("wx", "wy", "wz")], w))

report = inertialnet.evaluate(rates, sequence, target="mean")
print("RMSE against gyro − bias (deg/s):", report["estimators"][0]["bias_corrected"]["rmse_deg_s"])

inertialnet.write_flo(out / "last.flo", flow)
inertialnet.write_kitti_flow(out / "last_kitti.png", flow)
inertialnet.write_flow_png(out / "last_color.png", flow)
print(f"flow files in {out}/: last.flo, last_kitti.png, last_color.png")
