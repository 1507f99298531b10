# SPDX-License-Identifier: Apache-2.0
"""What `inertialnet predict --format csv|gcsv|euroc-imu|tum` writes, read back by readers that
share no code with ours (issue 21, "Outputs"):

  * the rates CSV by pandas.read_csv(path) and numpy.genfromtxt(path, delimiter=",", names=True)
    with their defaults, and its sidecar <file>.json by json (schema, row count, FNV-1a 64 of the
    CSV's bytes computed here);
  * the gcsv, the EuRoC-style file and the TUM trajectory by read_exports.py's parsers (standard
    library only, each format as its own documentation describes it), against the CSV;
  * the TUM trajectory against the synthetic sequence's ground-truth orientation
    (state_groundtruth_estimate0) over the rows before the first pair without an answer.

    python read_predicted.py RATES.csv GCSV EUROC_CSV TUM_TXT SEQUENCE
Exits 1 with the first difference it finds.
"""
import json
import math
import os
import sys

import numpy as np
import pandas as pd

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from read_exports import (check_euroc, check_gcsv, check_tum, f32, fail, matmul, quaternion_matrix,  # noqa: E402
                          read_rates)

# Ground truth against integrated rates: DIS + the geometric head drift by < 0.1 deg over 0.35 s of
# this sequence (about 12 deg of rotation); an axis or sign mistake is off by degrees.
TOLERANCE_DEG = 0.5
MIN_ROTATION_DEG = 5.0


def fnv1a64(data):
    h = 0xcbf29ce484222325
    for byte in data:
        h = ((h ^ byte) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
    return "%016x" % h


def check_csv(path, rates):
    frame = pd.read_csv(path)
    if list(frame.columns) != ["timestamp_ns", "wx", "wy", "wz", "status", "sigma_wx", "sigma_wy", "sigma_wz"]:
        fail(f"pandas.read_csv({path}) columns {list(frame.columns)}")
    if frame["timestamp_ns"].dtype != np.int64 or len(frame) != len(rates):
        fail(f"pandas: {len(frame)} rows of {frame['timestamp_ns'].dtype} timestamps, expected {len(rates)} int64")
    for (_, row), (t_ns, w) in zip(frame.iterrows(), rates):
        if row["timestamp_ns"] != t_ns or (row["status"] == "ok") != (w is not None):
            fail(f"pandas row {row.to_dict()} for t_k = {t_ns}")
        got = [row["wx"], row["wy"], row["wz"]]
        if w is None and not all(math.isnan(v) for v in got):
            fail(f"pandas: a pair without an answer reads {got}, not NaN")
        # Rates are floats written with %.9g: any reader's double rounds to the same float.
        if w is not None and [f32(v) for v in got] != [f32(v) for v in w]:
            fail(f"pandas: {got} against {w}")
    table = np.genfromtxt(path, delimiter=",", names=True)
    if table.dtype.names != ("timestamp_ns", "wx", "wy", "wz", "status", "sigma_wx", "sigma_wy", "sigma_wz") or table.shape != (len(rates),):
        fail(f"numpy.genfromtxt({path}): fields {table.dtype.names}, shape {table.shape}")
    if not np.array_equal(table["wx"], frame["wx"].to_numpy(), equal_nan=True):
        fail("numpy.genfromtxt's wx differs from pandas'")
    if np.max(np.abs(table["timestamp_ns"] - frame["timestamp_ns"].to_numpy(dtype=float))) > 512:
        fail("numpy.genfromtxt's timestamps differ from pandas' beyond a double's rounding")

    with open(path + ".json") as f:
        sidecar = json.load(f)
    with open(path, "rb") as f:
        data = f.read()
    if sidecar.get("schema") != "inertialnet.rates/4" or sidecar.get("rows") != len(frame):
        fail(f"{path}.json: {sidecar}")
    if sidecar.get("fnv1a64") != fnv1a64(data):
        fail(f"{path}.json: fnv1a64 {sidecar.get('fnv1a64')}, the CSV's is {fnv1a64(data)}")
    if sidecar["metadata"].get("frame") != "body":
        fail(f"{path}.json: metadata {sidecar['metadata']}")
    return len(frame)


def ground_truth(sequence):
    """t_ns → the body's orientation (rotation matrix, body to world) from q_RS_w, q_RS_x, …"""
    truth = {}
    with open(os.path.join(sequence, "mav0", "state_groundtruth_estimate0", "data.csv")) as f:
        for line in f:
            if line.startswith("#"):
                continue
            cells = line.split(",")
            w, x, y, z = (float(c) for c in cells[4:8])
            truth[int(cells[0])] = quaternion_matrix(x, y, z, w)
    return truth


def angle_deg(m):
    return math.degrees(math.acos(max(-1.0, min(1.0, (m[0][0] + m[1][1] + m[2][2] - 1) / 2))))


def transpose(m):
    return [[m[c][r] for c in range(3)] for r in range(3)]


def check_truth(tum, sequence, rates):
    truth = ground_truth(sequence)
    with open(tum) as f:
        poses = [line.split() for line in f if line.strip() and not line.startswith("#")]
    first_gap = next(k for k, (_, w) in enumerate(rates) if w is None)
    start = truth[rates[0][0]]
    worst, turned = 0.0, 0.0
    for cells, (t_ns, _) in zip(poses[:first_gap], rates):
        # TUM: timestamp tx ty tz qx qy qz qw, seconds, orientation relative to the first row.
        whole, _, fraction = cells[0].partition(".")
        if int(whole) * 10**9 + int(fraction.ljust(9, "0")) != t_ns:
            fail(f"{tum}: time {cells[0]} for t_k = {t_ns}")
        estimated = quaternion_matrix(*(float(c) for c in cells[4:8]))
        relative = matmul(transpose(start), truth[t_ns])
        worst = max(worst, angle_deg(matmul(transpose(estimated), relative)))
        turned = max(turned, angle_deg(relative))
    if turned < MIN_ROTATION_DEG:
        fail(f"the ground truth turns only {turned:.2f} deg over the span: the check could not fail")
    if worst > TOLERANCE_DEG:
        fail(f"{tum}: {worst:.3f} deg from the ground-truth orientation (tolerance {TOLERANCE_DEG})")
    return first_gap, worst, turned


def main():
    rates_path, gcsv, euroc, tum, sequence = sys.argv[1:6]
    rates = read_rates(rates_path)
    rows = check_csv(rates_path, rates)
    counts = (check_gcsv(gcsv, rates), check_euroc(euroc, rates), check_tum(tum, rates))
    span, worst, turned = check_truth(tum, sequence, rates)
    print("read back: csv %d rows (pandas, numpy, sidecar), gcsv %d rows, euroc-imu %d rows, tum %d poses; "
          "tum within %.3f deg of the ground truth over %d poses (%.1f deg turned)"
          % (rows, *counts, worst, span, turned))


if __name__ == "__main__":
    main()
