#!/usr/bin/env python3
"""Writes one small PNG test image of a given kind, built byte by byte (no imaging
library), for the workspace tests and benchmarks/bad_inputs.sh.

usage: make_test_image.py KIND PATH
  corrupt    64x64 grey: valid signature, chunks and CRCs, but the IDAT data is not
             zlib data, so it passes the header check and fails at decoding
  huge       a header claiming 100000x100000 pixels (10 gigapixels), tiny data
  thin       1x400 grey gradient (one pixel wide); thin-h: 400x1
  flat       256x256 uniform grey (no features)
  noise      256x256 grey noise with a fixed seed
"""
import random
import struct
import sys
import zlib


def chunk(kind, data):
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


def png(width, height, idat):
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)  # 8-bit grey
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", idat) + chunk(b"IEND", b"")


def grey(width, height, value):
    rows = b"".join(b"\x00" + bytes(value(x, y) for x in range(width)) for y in range(height))
    return png(width, height, zlib.compress(rows))


def main():
    kind, path = sys.argv[1], sys.argv[2]
    rng = random.Random(7)
    if kind == "corrupt":
        data = png(64, 64, bytes(rng.randrange(256) for _ in range(300)))
    elif kind == "huge":
        data = png(100000, 100000, zlib.compress(b"\x00" * 64))
    elif kind == "thin":
        data = grey(1, 400, lambda x, y: y * 255 // 399)
    elif kind == "thin-h":
        data = grey(400, 1, lambda x, y: x * 255 // 399)
    elif kind == "flat":
        data = grey(256, 256, lambda x, y: 128)
    elif kind == "noise":
        data = grey(256, 256, lambda x, y: rng.randrange(256))
    else:
        sys.exit("unknown kind " + kind)
    with open(path, "wb") as f:
        f.write(data)


main()
