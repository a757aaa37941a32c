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
    b = (a * 255.0 + 0.5).astype(np.uint8).reshape(h, w * 3)
    raw = b"".join(bytes([f]) + row.tobytes() for f, row in zip(*_filter_rows(b)))

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))
    tmp = path + ".part"
    with open(tmp, "wb") as fh:
        fh.write(png)
    os.replace(tmp, path)


def _filter_rows(b):
    """PNG row filters (None, Sub, Up, Average, Paeth; 3 bytes per pixel),
    the one with the smallest sum of |signed bytes| per row (the usual
    heuristic): smooth renders compress to about half of unfiltered rows."""
    x = b.astype(np.int16)
    left = np.zeros_like(x)
    left[:, 3:] = x[:, :-3]
    up = np.zeros_like(x)
    up[1:] = x[:-1]
    ul = np.zeros_like(x)
    ul[1:, 3:] = x[:-1, :-3]
    p = left + up - ul
    pa, pb, pc = np.abs(p - left), np.abs(p - up), np.abs(p - ul)
    paeth = np.where((pa <= pb) & (pa <= pc), left, np.where(pb <= pc, up, ul))
    cands = np.stack([x, x - left, x - up, x - (left + up) // 2, x - paeth]) & 0xFF
    cost = np.where(cands > 127, 256 - cands, cands).sum(axis=2)
    best = np.argmin(cost, axis=0)
    rows = cands[best, np.arange(x.shape[0])].astype(np.uint8)
    return best.tolist(), rows


def false_colour(err, vmax):
    """Per-pixel error -> blue (0) .. green (vmax/2) .. red (>= vmax)."""
    t = np.clip(np.asarray(err, np.float64) / vmax, 0, 1)
    return np.stack([np.clip(2 * t - 1, 0, 1), 1 - np.abs(2 * t - 1), np.clip(1 - 2 * t, 0, 1)], -1)


def save_error_map(path, err):
    """A per-pixel error (H, W) as a false-colour PNG, blue 0 .. red at its
    99.5th percentile, enlarged by whole pixels to about 640 wide. Returns
    (the red level, the maximum) for the caller to print."""
    err = np.asarray(err, np.float64)
    vmax = max(float(np.percentile(err, 99.5)), 1e-30)
    img = false_colour(err, vmax)
    k = max(1, 640 // img.shape[1])
    save_png(path, np.repeat(np.repeat(img, k, 0), k, 1))
    return vmax, float(err.max())


def signed_error(diff, scale):
    """A signed error image: diff * scale (diff: luminance differences), red
    where positive (too bright), blue where negative (too dark), through the
    same Reinhard + gamma curve as the images (so 1 on the scale looks like a
    mid-bright pixel)."""
    v = np.asarray(diff, np.float64) * scale
    pos, neg = np.clip(v, 0, None), np.clip(-v, 0, None)

    def t(x):
        return (x / (1.0 + x)) ** (1 / 2.2)
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


# A 3x5 pixel font (upper case, digits, a little punctuation) for the labels
# of the comparison images, so that a PNG says what each tile is.
_GLYPHS = {
    "A": "010101111101101", "B": "110101110101110", "C": "011100100100011", "D": "110101101101110",
    "E": "111100110100111", "F": "111100110100100", "G": "011100101101011", "H": "101101111101101",
    "I": "111010010010111", "J": "001001001101010", "K": "101101110101101", "L": "100100100100111",
    "M": "101111111101101", "N": "110101101101101", "O": "010101101101010", "P": "110101110100100",
    "Q": "010101101110011", "R": "110101110101101", "S": "011100010001110", "T": "111010010010010",
    "U": "101101101101111", "V": "101101101101010", "W": "101101111111101", "X": "101101010101101",
    "Y": "101101010010010", "Z": "111001010100111", "0": "111101101101111", "1": "010110010010111",
    "2": "110001010100111", "3": "110001010001110", "4": "101101111001001", "5": "111100110001110",
    "6": "011100111101111", "7": "111001010010010", "8": "111101111101111", "9": "111101111001110",
    " ": "000000000000000", "-": "000000111000000", ".": "000000000000010", "=": "000111000111000",
    ",": "000000000010100", ":": "000010000010000", "_": "000000000000111", "(": "010100100100010",
    ")": "010001001001010", "/": "001001010100100", "%": "101001010100101", "+": "000010111010000",
}


def text_strip(lines, width, scale=2, pad=2):
    """White text on black, one row per line, `width` pixels wide (cut at the
    right edge): an (H, width, 3) array to stack above a tile."""
    lh = 5 * scale + pad
    out = np.zeros((lh * len(lines) + pad, width, 3))
    for li, text in enumerate(lines):
        x = pad
        for ch in str(text).upper():
            g = _GLYPHS.get(ch, _GLYPHS[" "])
            bits = np.array([int(b) for b in g], float).reshape(5, 3)
            glyph = np.repeat(np.repeat(bits, scale, 0), scale, 1)
            y0 = pad + li * lh
            if x + glyph.shape[1] > width:
                break
            out[y0:y0 + glyph.shape[0], x:x + glyph.shape[1]] = glyph[..., None]
            x += 4 * scale
    return out


def grid(rows, heads, up):
    """Tiles (rows of equal-size images) upscaled, 1-px white gaps, a label
    strip above each column (heads[j]: its lines, the shorter padded)."""
    rows = [[upscale(t, up) for t in row] for row in rows]
    w = rows[0][0].shape[1]
    lines = max(len(h) for h in heads)
    cols = []
    for j in range(len(rows[0])):
        parts = [text_strip(list(heads[j]) + [""] * (lines - len(heads[j])), w)]
        for row in rows:
            parts += [np.ones((1, w, 3)), row[j]]
        cols.append(np.concatenate(parts, axis=0))
    sep = np.ones((cols[0].shape[0], 1, 3))
    return np.concatenate(sum([[c, sep] for c in cols], [])[:-1], axis=1)


def crop_row(images, crop, gain, zoom=1):
    """A row of the same crop of each image, side by side with 4-pixel white
    gaps: crop ((r0, r1), (c0, c1)) as fractions of the image, each tile
    scaled alike so that the first image's 99th percentile maps to `gain`
    (clipped at 1), gamma 2.2, each pixel repeated zoom x zoom times."""
    h, w = images[0].shape[:2]
    (r0, r1), (c0, c1) = crop
    ys, xs = slice(int(r0 * h), int(r1 * h)), slice(int(c0 * w), int(c1 * w))
    scale = np.percentile(images[0][ys, xs], 99)
    tiles = [np.clip(a[ys, xs] / scale * gain, 0, 1) ** (1 / 2.2) for a in images]
    tiles = [upscale(t, zoom) for t in tiles]
    gap = np.ones((tiles[0].shape[0], 4, 3))
    return np.concatenate(sum(([t, gap] for t in tiles), [])[:-1], 1)
