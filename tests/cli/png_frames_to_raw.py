# SPDX-License-Identifier: Apache-2.0
"""Writes the frames of a EuRoC folder's camera (8-bit grayscale PNGs, as `inertialnet synth` makes
them) one after another as raw GRAY8 bytes, for GStreamer's rawvideoparse to play back as a live
source (GStreamer's base plugins have no PNG decoder). Python's standard library only.

    python3 png_frames_to_raw.py SEQUENCE/mav0/cam0 OUT.raw
Prints WIDTHxHEIGHT FRAMES.
"""
import os
import struct
import sys
import zlib


def paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    if pa <= pb and pa <= pc:
        return a
    return b if pb <= pc else c


def read_gray8_png(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, width, height = 8, b"", 0, 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour != 0 or interlace != 0:
                sys.exit(f"{path}: only 8-bit grayscale, non-interlaced PNGs are read here")
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    rows, previous = [], bytearray(width)
    for y in range(height):
        filt, line = raw[y * (width + 1)], bytearray(raw[y * (width + 1) + 1:(y + 1) * (width + 1)])
        for x in range(width):
            a = line[x - 1] if x else 0
            b, c = previous[x], previous[x - 1] if x else 0
            predictor = (0, a, b, (a + b) // 2, paeth(a, b, c))[filt]
            line[x] = (line[x] + predictor) & 0xFF
        rows.append(bytes(line))
        previous = line
    return width, height, b"".join(rows)


def main():
    camera, out = sys.argv[1:3]
    with open(os.path.join(camera, "data.csv"), encoding="utf-8") as f:
        names = [line.strip().split(",")[1] for line in f if line.strip() and not line.startswith("#")]
    size = None
    with open(out, "wb") as raw:
        for name in names:
            width, height, pixels = read_gray8_png(os.path.join(camera, "data", name))
            size = size or (width, height)
            raw.write(pixels)
    print(f"{size[0]}x{size[1]} {len(names)}")


main()
