# SPDX-License-Identifier: Apache-2.0
"""An independent reader of what `inertialnet export` writes, with the standard library only:
each format parsed as its own documentation describes it (Gyroflow's gcsv: a first line, key,value
lines, scales, then t,gx,gy,gz; EuRoC's imu0/data.csv; TUM's `t tx ty tz qx qy qz qw`) and
compared with the rates CSV it comes from. The TUM orientation is checked against an integration
of our own, with rotation matrices (Rodrigues' formula) rather than the exporter's quaternions.

    python3 read_exports.py RATES.csv GCSV EUROC_CSV TUM_TXT
Exits 1 with the first difference it finds.
"""
import csv
import math
import struct
import sys


def fail(message):
    raise SystemExit(f"read_exports: {message}")


def f32(x):
    return struct.unpack("f", struct.pack("f", x))[0]


def read_rates(path):
    rows = []
    with open(path) as f:
        lines = [line.strip() for line in f if line.strip() and not line.startswith("#")]
    header = lines[0].split(",")
    if header[:5] != ["timestamp_ns", "wx", "wy", "wz", "status"]:
        fail(f"{path}: unexpected header {header}")
    for line in lines[1:]:
        cells = line.split(",")
        ok = cells[4] == "ok"
        rows.append((int(cells[0]), [float(c) for c in cells[1:4]] if ok else None))
    return rows


def check_gcsv(path, rates):
    with open(path) as f:
        lines = f.read().splitlines()
    if lines[0] not in ("GYROFLOW IMU LOG", "CAMERA IMU LOG"):
        fail(f"{path}: line 1 is {lines[0]!r}")
    meta = {}
    i = 1
    while not lines[i].startswith("t,"):
        key, _, value = lines[i].partition(",")
        meta[key] = value
        i += 1
    for key in ("version", "id", "orientation", "tscale", "gscale", "ascale"):
        if key not in meta:
            fail(f"{path}: no {key} line")
    if list(meta)[:3] != ["version", "id", "orientation"]:
        fail(f"{path}: lines 2-4 are {list(meta)[:3]}, not version, id, orientation")
    columns = lines[i].split(",")
    if columns != ["t", "gx", "gy", "gz"]:
        fail(f"{path}: columns {columns}")
    tscale, gscale = float(meta["tscale"]), float(meta["gscale"])
    ok = [(t, w) for t, w in rates if w is not None]
    data = lines[i + 1:]
    if len(data) != len(ok):
        fail(f"{path}: {len(data)} rows for {len(ok)} ok pairs")
    for line, (t_ns, w) in zip(data, ok):
        cells = line.split(",")
        seconds = float(cells[0]) * tscale
        if abs(seconds - t_ns * 1e-9) > 0.6e-6:
            fail(f"{path}: t {cells[0]} × {tscale} = {seconds} s for t_k = {t_ns} ns")
        for k in range(3):
            if f32(float(cells[1 + k]) * gscale) != f32(w[k]):
                fail(f"{path}: {line} against the rates {w}")
    return len(data)


def check_euroc(path, rates):
    with open(path, newline="") as f:
        table = list(csv.reader(f))
    if not table[0][0].startswith("#timestamp [ns]") or len(table[0]) != 7:
        fail(f"{path}: header {table[0]}")
    ok = [(t, w) for t, w in rates if w is not None]
    if len(table) - 1 != len(ok):
        fail(f"{path}: {len(table) - 1} rows for {len(ok)} ok pairs")
    for cells, (t_ns, w) in zip(table[1:], ok):
        if len(cells) != 7 or int(cells[0]) != t_ns or any(cells[4:]):
            fail(f"{path}: row {cells} for t_k = {t_ns}")
        if [f32(float(c)) for c in cells[1:4]] != [f32(x) for x in w]:
            fail(f"{path}: row {cells} against the rates {w}")
    return len(table) - 1


def matmul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]


def rodrigues(phi):
    angle = math.sqrt(sum(x * x for x in phi))
    if angle == 0:
        return [[1.0 if r == c else 0.0 for c in range(3)] for r in range(3)]
    x, y, z = (v / angle for v in phi)
    s, c = math.sin(angle), math.cos(angle)
    C = 1 - c
    return [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
            [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
            [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]


def quaternion_matrix(x, y, z, w):
    return [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]


def check_tum(path, rates):
    with open(path) as f:
        poses = [line.split() for line in f if line.strip() and not line.startswith("#")]
    if len(poses) != len(rates):
        fail(f"{path}: {len(poses)} poses for {len(rates)} rows")
    R = rodrigues([0, 0, 0])
    for k, (cells, (t_ns, w)) in enumerate(zip(poses, rates)):
        if len(cells) != 8 or cells[1:4] != ["0", "0", "0"]:
            fail(f"{path}: pose {cells}")
        whole, _, fraction = cells[0].partition(".")
        if int(whole) * 10**9 + int(fraction.ljust(9, "0")) != t_ns:
            fail(f"{path}: time {cells[0]} for t_k = {t_ns} ns")
        if k > 0 and w is not None:
            dt = (t_ns - rates[k - 1][0]) * 1e-9
            R = matmul(R, rodrigues([v * dt for v in w]))
        q = [float(c) for c in cells[4:]]
        if abs(sum(v * v for v in q) - 1) > 1e-6:
            fail(f"{path}: quaternion {q} is not of unit length")
        M = quaternion_matrix(*q)
        if max(abs(M[r][c] - R[r][c]) for r in range(3) for c in range(3)) > 1e-6:
            fail(f"{path}: pose {k} {q} is not the integrated orientation {R}")
    return len(poses)


def main():
    rates_path, gcsv, euroc, tum = sys.argv[1:5]
    rates = read_rates(rates_path)
    counts = (check_gcsv(gcsv, rates), check_euroc(euroc, rates), check_tum(tum, rates))
    print("independent reader: gcsv %d rows, euroc-imu %d rows, tum %d poses agree with %s" % (*counts, rates_path))


if __name__ == "__main__":
    main()
