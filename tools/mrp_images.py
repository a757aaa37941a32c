#!/usr/bin/env python3
"""Side-by-side PNG of the glossy planes tests/c/test_mrp_render.c dumps
(VSGL_MRP_DUMP=dir): brute force | k-means 256 | lattice | MRP, and the
error |x - ref| of each, tone-mapped x / (1 + x) after scaling by the
reference's 99th percentile. numpy only.

Usage: /usr/bin/python3 tools/mrp_images.py DIR PREFIX W H OUT.png
(PREFIX e.g. r20 for roughness 0.2)."""
import struct
import sys
import zlib

import numpy as np


def load(d, prefix, name, w, h):
    a = np.fromfile("%s/%s_%s_%dx%d.f32" % (d, prefix, name, w, h), np.float32)
    return a.reshape(h, w, 3)


def png(path, img):
    h, w, _ = img.shape
    raw = b"".join(b"\x00" + img[y].astype(np.uint8).tobytes() for y in range(h))

    def chunk(t, data):
        c = struct.pack(">I", len(data)) + t + data
        return c + struct.pack(">I", zlib.crc32(t + data) & 0xFFFFFFFF)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    d, prefix, w, h, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
    names = ("ref", "kmeans", "lattice", "mrp")
    planes = [load(d, prefix, n, w, h) for n in names]
    scale = np.percentile(planes[0], 99) or 1.0

    def tone(x):
        x = np.maximum(x / scale, 0) * 2.0
        return 255 * (x / (1 + x)) ** (1 / 2.2)
    top = np.concatenate([tone(p) for p in planes], axis=1)
    bottom = np.concatenate([tone(np.abs(p - planes[0])) for p in planes], axis=1)
    png(out, np.concatenate([top, bottom], axis=0))


if __name__ == "__main__":
    main()
