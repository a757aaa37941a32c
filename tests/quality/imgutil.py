"""Image helpers shared by the quality harness and tests/blender/cycles_ref.py.

numpy + the standard library only (no bpy): an 8-bit PNG writer, the false
colour ramp of the error images, a fixed display transform.
"""
import os
import struct
import zlib

import numpy as np


def save_png(path, rgb):
    """rgb: (H, W, 3) floats in [0, 1] (clipped), row 0 = top; written as an
    8-bit sRGB-agnostic PNG (values are stored as given: apply a display
    transform first). Atomic: written to a temporary name, then renamed."""
    a = np.clip(np.asarray(rgb, np.float64), 0, 1)
    h, w, _ = a.shape
    b = (a * 255.0 + 0.5).astype(np.uint8)
    raw = b"".join(b"\x00" + b[y].tobytes() for y in range(h))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    tmp = path + ".part"
    with open(tmp, "wb") as fh:
        fh.write(png)
    os.replace(tmp, path)


def false_colour(err, vmax):
    """Per-pixel error -> blue (0) .. green (vmax/2) .. red (>= vmax)."""
    t = np.clip(np.asarray(err, np.float64) / vmax, 0, 1)
    return np.stack([np.clip(2 * t - 1, 0, 1), 1 - np.abs(2 * t - 1), np.clip(1 - 2 * t, 0, 1)], -1)


def signed_error(diff, scale):
    """A signed error image: diff * scale (diff: luminance differences), red
    where positive (too bright), blue where negative (too dark), through the
    same Reinhard + gamma curve as the images (so 1 on the scale looks like a
    mid-bright pixel)."""
    v = np.asarray(diff, np.float64) * scale
    pos, neg = np.clip(v, 0, None), np.clip(-v, 0, None)
    t = lambda x: (x / (1.0 + x)) ** (1 / 2.2)
    return np.stack([t(pos), np.zeros_like(v), t(neg)], -1)


def tonemap(x, exposure=1.0):
    """Linear RGB -> display: exposure, Reinhard x/(1+x), gamma 2.2."""
    x = np.clip(np.asarray(x, np.float64) * exposure, 0, None)
    return (x / (1.0 + x)) ** (1 / 2.2)


def exposure_for(ref, percentile=99.0, target=1.5):
    """The exposure that maps the reference's `percentile` luminance to
    `target` before the tone curve (one value per scene, shared by every tile)."""
    lum = luminance(ref)
    p = float(np.percentile(lum, percentile)) if lum.size else 0.0
    return target / p if p > 0 else 1.0


def luminance(rgb):
    rgb = np.asarray(rgb, np.float64)
    return 0.2126 * rgb[..., 0] + 0.7152 * rgb[..., 1] + 0.0722 * rgb[..., 2]


def upscale(img, k):
    """Nearest-neighbour k x k enlargement (small test images stay readable)."""
    if k <= 1:
        return img
    return np.repeat(np.repeat(img, k, axis=0), k, axis=1)

