# SPDX-License-Identifier: Apache-2.0
"""Replaces one frame of a EuRoC-layout sequence with what real recordings hold now and then:
a frame of noise (a flash, a sensor fault), a uniform grey frame or a black one (a covered lens,
a frame a camera filled in). The frame is written as a binary PGM under the PNG's name (OpenCV
reads an image by its content, not by its extension), so no imaging package is needed.

    python3 deface_frame.py SEQUENCE INDEX noise|uniform|black
"""
import os
import random
import struct
import sys
import zlib


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path} is not a PNG")
    return struct.unpack(">II", head[16:24])


def main():
    sequence, index, kind = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    folder = os.path.join(sequence, "mav0", "cam0", "data")
    names = sorted(n for n in os.listdir(folder) if n.endswith(".png"))
    path = os.path.join(folder, names[index])
    width, height = png_size(path)
    if kind == "noise":
        rng = random.Random(zlib.crc32(path.encode()))
        pixels = bytes(rng.getrandbits(8) for _ in range(width * height))
    elif kind == "uniform":
        pixels = bytes([128]) * (width * height)
    elif kind == "black":
        pixels = bytes(width * height)
    else:
        raise SystemExit(f"unknown kind {kind}: noise, uniform or black")
    with open(path, "wb") as f:
        f.write(b"P5\n%d %d\n255\n" % (width, height) + pixels)


main()
