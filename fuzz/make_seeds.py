#!/usr/bin/env python3
"""make_seeds.py OUT: the binary seeds of the fuzz targets, written rather than committed.

merl: headers (valid dimensions, wrong ones, huge ones) with a few values, NaN and negative among them.
rgl: a tensor-file header with one field, and the first RGL material of ../shared/data/rgl when present.
"""
import math
import os
import struct
import sys


def main(out):
    merl = os.path.join(out, "merl")
    rgl = os.path.join(out, "rgl")
    os.makedirs(merl, exist_ok=True)
    os.makedirs(rgl, exist_ok=True)
    values = struct.pack("<8d", 0.1, 0.5, -0.01, float("nan"), 1e30, 0.0, math.pi, -1.0)
    for name, dims in {"valid": (90, 90, 180), "wrong": (90, 90, 90), "huge": (100000, 100000, 100000), "zero": (0, 0, 0)}.items():
        with open(os.path.join(merl, name + ".binary"), "wb") as f:
            f.write(struct.pack("<3i", *dims) + values)
    # One uint8 field 'description' of 4 bytes, then its data.
    name = b"description"
    table_end = 12 + 2 + 4 + 2 + len(name) + 2 + 1 + 8 + 8
    header = b"tensor_file\0" + bytes([1, 0]) + struct.pack("<I", 1)
    header += struct.pack("<H", len(name)) + name + struct.pack("<HBQQ", 1, 1, table_end, 4) + b"test"
    with open(os.path.join(rgl, "one-field.bsdf"), "wb") as f:
        f.write(header)
    shared = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "data", "rgl")
    if os.path.isdir(shared):
        first = sorted(n for n in os.listdir(shared) if n.endswith(".bsdf"))[:1]
        for n in first:
            with open(os.path.join(shared, n), "rb") as src, open(os.path.join(rgl, n), "wb") as dst:
                dst.write(src.read())


if __name__ == "__main__":
    main(sys.argv[1])
