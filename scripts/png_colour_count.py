#!/usr/bin/env python3
"""Counts the pixels of a PNG whose hue is close to a given colour (brightness aside), as the GUI
tests do: `png_colour_count.py FILE R G B` prints the count. Plain Python (zlib), 8-bit RGB or
RGBA, non-interlaced: what Chromium's screenshots are."""
import struct
import sys
import zlib


def pixels(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    at, idat = 8, b""
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and colour in (2, 6) and interlace == 0, "8-bit RGB(A) only"
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    previous = bytearray(stride)
    for y in range(height):
        row = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        kind, line = row[0], bytearray(row[1:])
        for x in range(stride):
            left = line[x - channels] if x >= channels else 0
            up = previous[x]
            corner = previous[x - channels] if x >= channels else 0
            if kind == 1:
                line[x] = (line[x] + left) & 255
            elif kind == 2:
                line[x] = (line[x] + up) & 255
            elif kind == 3:
                line[x] = (line[x] + (left + up) // 2) & 255
            elif kind == 4:
                p = left + up - corner
                pa, pb, pc = abs(p - left), abs(p - up), abs(p - corner)
                line[x] = (line[x] + (left if pa <= pb and pa <= pc else up if pb <= pc else corner)) & 255
        previous = line
        for x in range(width):
            yield tuple(line[x * channels:x * channels + 3])


def hue(c):
    total = c[0] + c[1] + c[2] + 1.0
    return [v / total for v in c]


if __name__ == "__main__":
    path, target = sys.argv[1], hue([int(v) for v in sys.argv[2:5]])
    count = 0
    for p in pixels(path):
        h = hue(p)
        if sum(abs(a - b) for a, b in zip(h, target)) < 0.08 and sum(p) > 120:
            count += 1
    print(count)
