#!/usr/bin/env python3
"""Axial slices of two volumes (or two 2D images, slice 0) side by side in one 8-bit PNG, same window per slice (the first
volume's 1st-99th percentile), for the PNG pairs in docs/history/RESULTS.md. Python's standard library
only: reads float32 .npy and NIfTI-1 (.nii) volumes [z, y, x] as riner writes them.

  slice_pair_png.py FIRST SECOND OUT.png Z [Z ...]
"""
import array
import ast
import struct
import sys
import zlib


def read_volume(path):
    data = open(path, "rb").read()
    if path.endswith(".npy"):
        header_len = struct.unpack("<H", data[8:10])[0]
        header = ast.literal_eval(data[10:10 + header_len].decode())
        if header["descr"] != "<f4" or header["fortran_order"]:
            sys.exit(f"{path}: expected little-endian float32 in C order")
        shape, offset = tuple(header["shape"]), 10 + header_len
    elif path.endswith(".nii"):
        dims = struct.unpack("<8h", data[40:56])
        if struct.unpack("<h", data[70:72])[0] != 16:
            sys.exit(f"{path}: expected float32 NIfTI")
        shape = tuple(reversed(dims[1:1 + dims[0]]))  # NIfTI is x fastest: [z, y, x]
        offset = int(struct.unpack("<f", data[108:112])[0])
    else:
        sys.exit(f"{path}: .npy or .nii")
    if len(shape) == 2:
        shape = (1,) + shape  # a 2D image is one slice
    values = array.array("f")
    values.frombytes(data[offset:offset + 4 * shape[0] * shape[1] * shape[2]])
    return shape, values


def axial(shape, values, z):
    n = shape[1] * shape[2]
    return values[z * n:(z + 1) * n]


def window(pixels):
    finite = sorted(v for v in pixels if v == v)
    return finite[int(0.01 * (len(finite) - 1))], finite[int(0.99 * (len(finite) - 1))]


def write_png(path, rows):
    height, width = len(rows), len(rows[0])
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body +
                struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF))

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)) +
           chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    open(path, "wb").write(png)


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    first, second, out = sys.argv[1:4]
    slices = [int(z) for z in sys.argv[4:]]
    (shape_a, a), (shape_b, b) = read_volume(first), read_volume(second)
    if shape_a != shape_b:
        sys.exit(f"shapes differ: {shape_a} and {shape_b}")
    ny, nx, gap = shape_a[1], shape_a[2], 4
    rows = []
    for z in slices:
        sa, sb = axial(shape_a, a, z), axial(shape_b, b, z)
        lo, hi = window(sa)
        scale = 255.0 / max(hi - lo, 1e-12)
        grey = lambda v: 0 if v != v else int(min(255, max(0, (v - lo) * scale)))
        for i in range(ny):
            left = [grey(v) for v in sa[i * nx:(i + 1) * nx]]
            right = [grey(v) for v in sb[i * nx:(i + 1) * nx]]
            rows.append(left + [255] * gap + right)
        rows.append([255] * (2 * nx + gap))
    write_png(out, rows[:-1])


if __name__ == "__main__":
    main()
