#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""A GoPro-like MP4 from a EuRoC sequence, written independently of inertialnet's reader (gpmf.cpp)
for the tests: a video track of the cam0 PNG files as they are (sample entry 'png ', which FFmpeg
decodes losslessly) and a 'meta' track with sample description 'gpmd' whose payloads are GPMF
(DEVC > STRM > SCAL, SIUN, GYRO int16 triples in HERO5's Z,X,Y order, as gpmf-parser's README
describes a HERO5), plus an ACCL stream the reader must skip.

The gyro stored is imu0's, rotated into the camera frame with cam0's T_BS and then into GoPro's
labelled frame (X left, Y back, Z up: camera x = -X, y = -Z, z = -Y), quantized to int16 / SCAL.
Times: the MP4 timeline starts at the first frame; gyro samples before it are left out; payloads
of --payload samples start at their first sample's time, so the reader's fit recovers each time.

--expected FILE writes what a correct reader returns, rotated back into the camera frame: a CSV
`t_ns,gx,gy,gz` (times from the first frame, rad/s after quantization).

--orin ABC stores the triple in that order instead and says so in an ORIN item (gpmf-parser's
GPMF_common.h: "input channel data orientation, lowercase is negative, e.g. Zxy"), as HERO8 and
later do; the expected samples are the same.

Usage: write_gopro_mp4.py SEQ OUT.mp4 [--expected CSV] [--payload N] [--scal S] [--orin ABC]
Standard library only (struct, csv): nothing shared with the C++ reader but the published format.
"""
import argparse
import os
import struct


def box(kind, *parts):
    body = b"".join(parts)
    return struct.pack(">I4s", 8 + len(body), kind.encode("latin1")) + body


def full_box(kind, version, flags, *parts):
    return box(kind, struct.pack(">I", (version << 24) | flags), *parts)


def klv(key, type_char, struct_size, repeat, data):
    head = key.encode("latin1") + (b"\0" if type_char is None else type_char.encode("latin1"))
    head += struct.pack(">BH", struct_size, repeat)
    return head + data + b"\0" * ((-len(data)) % 4)


def nest(key, *items):
    data = b"".join(items)
    return klv(key, None, 1, len(data), data)  # type 0: nested; size 1 × repeat = byte count


def text(key, value):
    raw = value.encode("latin1")
    return klv(key, "c", 1, len(raw), raw)


def read_rows(path):
    with open(path) as f:
        return [line.strip().split(",") for line in f if line.strip() and not line.startswith("#")]


def read_T_BS(path):
    with open(path) as f:
        content = f.read()
    data = content[content.index("data:", content.index("T_BS")):]
    numbers = data[data.index("[") + 1:data.index("]")].replace("\n", " ").split(",")
    return [float(v) for v in numbers]


def stbl(sample_entry, durations, sizes, offsets):
    stts = full_box("stts", 0, 0, struct.pack(">I", len(durations)),
                    b"".join(struct.pack(">II", 1, d) for d in durations))
    stsc = full_box("stsc", 0, 0, struct.pack(">IIII", 1, 1, 1, 1))  # one sample per chunk
    stsz = full_box("stsz", 0, 0, struct.pack(">II", 0, len(sizes)), b"".join(struct.pack(">I", s) for s in sizes))
    stco = full_box("stco", 0, 0, struct.pack(">I", len(offsets)), b"".join(struct.pack(">I", o) for o in offsets))
    stsd = full_box("stsd", 0, 0, struct.pack(">I", 1), sample_entry)
    return box("stbl", stsd, stts, stsc, stsz, stco)


def trak(track_id, handler, timescale, media_header, sample_table, width=0, height=0):
    duration = 0
    matrix = struct.pack(">9I", 0x10000, 0, 0, 0, 0x10000, 0, 0, 0, 0x40000000)
    tkhd = full_box("tkhd", 0, 3, struct.pack(">IIII", 0, 0, track_id, 0), struct.pack(">I", duration),
                    b"\0" * 8, struct.pack(">hhhH", 0, 0, 0, 0), matrix, struct.pack(">II", width << 16, height << 16))
    mdhd = full_box("mdhd", 0, 0, struct.pack(">IIIIHH", 0, 0, timescale, duration, 0x55C4, 0))
    hdlr = full_box("hdlr", 0, 0, struct.pack(">I", 0), handler.encode("latin1"), b"\0" * 12, b"inertialnet test\0")
    dinf = box("dinf", full_box("dref", 0, 0, struct.pack(">I", 1), full_box("url ", 0, 1)))
    minf = box("minf", media_header, dinf, sample_table)
    return box("trak", tkhd, box("mdia", mdhd, hdlr, minf))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("sequence")
    ap.add_argument("out")
    ap.add_argument("--expected")
    ap.add_argument("--payload", type=int, default=20)
    ap.add_argument("--scal", type=int, default=10000)
    ap.add_argument("--orin", default="")
    a = ap.parse_args()
    mav0 = os.path.join(a.sequence, "mav0")
    frames = read_rows(os.path.join(mav0, "cam0", "data.csv"))
    t_frames = [int(r[0]) for r in frames]
    pngs = []
    for r in frames:
        with open(os.path.join(mav0, "cam0", "data", r[1]), "rb") as f:
            pngs.append(f.read())
    with open(os.path.join(mav0, "cam0", "data", frames[0][1]), "rb") as f:
        head = f.read(24)
    width, height = struct.unpack(">II", head[16:24])

    # imu0 (body) → camera: the rotation of cam0's T_BS (camera → body), transposed.
    T = read_T_BS(os.path.join(mav0, "cam0", "sensor.yaml"))
    R_bc = [[T[0], T[1], T[2]], [T[4], T[5], T[6]], [T[8], T[9], T[10]]]
    origin = t_frames[0]
    imu = [r for r in read_rows(os.path.join(mav0, "imu0", "data.csv")) if int(r[0]) >= origin]
    t_imu = [int(r[0]) - origin for r in imu]
    stored, expected = [], []
    for r in imu:
        w = [float(v) for v in r[1:4]]
        cam = [sum(R_bc[j][i] * w[j] for j in range(3)) for i in range(3)]
        X, Y, Z = -cam[0], -cam[2], -cam[1]  # GoPro labels from camera x, y, z
        labelled = {"X": X, "Y": Y, "Z": Z}
        order = a.orin or "ZXY"  # HERO5 stores Z, X, Y
        q = [int(round((1 if c.isupper() else -1) * labelled[c.upper()] * a.scal)) for c in order]
        assert all(-32768 <= v <= 32767 for v in q), "gyro beyond int16 at this SCAL"
        stored.append(q)
        back = {c.upper(): (1 if c.isupper() else -1) * v / a.scal for c, v in zip(order, q)}
        expected.append((-back["X"], -back["Z"], -back["Y"]))
    step = t_imu[1] - t_imu[0]
    assert t_imu[0] == 0 and all(t_imu[k] == k * step for k in range(len(t_imu))), "gyro not uniform from frame 0"

    payloads, payload_starts = [], []
    for k in range(0, len(stored), a.payload):
        chunk = stored[k:k + a.payload]
        gyro = b"".join(struct.pack(">hhh", *v) for v in chunk)
        accl = struct.pack(">hhh", 0, 418, 0) * len(chunk)  # 9.8 m/s² at SCAL 418 (the README's example)
        payloads.append(nest("DEVC", klv("DVID", "L", 4, 1, struct.pack(">I", 1)), text("DVNM", "Camera"),
                             nest("STRM", klv("TSMP", "L", 4, 1, struct.pack(">I", k + len(chunk))),
                                  text("STNM", "Accelerometer"), text("SIUN", "m/s\xb2"),
                                  klv("SCAL", "s", 2, 1, struct.pack(">h", 418)),
                                  klv("ACCL", "s", 6, len(chunk), accl)),
                             nest("STRM", klv("TSMP", "L", 4, 1, struct.pack(">I", k + len(chunk))),
                                  text("STNM", "Gyroscope"), *([text("ORIN", a.orin)] if a.orin else []),
                                  text("SIUN", "rad/s"),
                                  klv("SCAL", "s", 2, 1, struct.pack(">h", a.scal)),
                                  klv("GYRO", "s", 6, len(chunk), gyro))))
        payload_starts.append(t_imu[k])

    # Layout: ftyp, mdat (frames, then payloads), moov. Timescales in nanoseconds keep times exact.
    ftyp = box("ftyp", b"mp42", struct.pack(">I", 0), b"mp42isom")
    offset = len(ftyp) + 8
    frame_offsets, payload_offsets = [], []
    for p in pngs:
        frame_offsets.append(offset)
        offset += len(p)
    for p in payloads:
        payload_offsets.append(offset)
        offset += len(p)
    mdat = box("mdat", *pngs, *payloads)
    frame_durations = [t_frames[k + 1] - t_frames[k] for k in range(len(t_frames) - 1)]
    frame_durations.append(frame_durations[-1])
    payload_durations = [payload_starts[k + 1] - payload_starts[k] for k in range(len(payload_starts) - 1)]
    payload_durations.append((len(stored) - (len(payloads) - 1) * a.payload) * step)
    visual = box("png ", b"\0" * 6, struct.pack(">H", 1), b"\0" * 16, struct.pack(">HH", width, height),
                 struct.pack(">III", 0x480000, 0x480000, 0), struct.pack(">H", 1), b"\0" * 32,
                 struct.pack(">Hh", 24, -1))
    video = trak(1, "vide", 1_000_000_000, full_box("vmhd", 0, 1, b"\0" * 8),
                 stbl(visual, frame_durations, [len(p) for p in pngs], frame_offsets), width, height)
    meta = trak(2, "meta", 1_000_000_000, full_box("nmhd", 0, 0),
                stbl(box("gpmd", b"\0" * 6, struct.pack(">H", 1)), payload_durations, [len(p) for p in payloads],
                     payload_offsets))
    mvhd = full_box("mvhd", 0, 0, struct.pack(">IIII", 0, 0, 1000, 0), struct.pack(">IH", 0x10000, 0x100),
                    b"\0" * 10, struct.pack(">9I", 0x10000, 0, 0, 0, 0x10000, 0, 0, 0, 0x40000000), b"\0" * 24,
                    struct.pack(">I", 3))
    with open(a.out, "wb") as f:
        f.write(ftyp + mdat + box("moov", mvhd, video, meta))
    if a.expected:
        with open(a.expected, "w") as f:
            f.write("t_ns,gx,gy,gz\n")
            for t, w in zip(t_imu, expected):
                f.write("%d,%.17g,%.17g,%.17g\n" % (t, *w))


if __name__ == "__main__":
    main()
