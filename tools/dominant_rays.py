#!/usr/bin/env python3
"""The preview's indirect shadows with one ray per pair and with dominant rays (issue 9).

    python3 tools/dominant_rays.py [--size 320x240] [--spp 256] [--out docs/img/dominant_rays.png]

Renders rough_room at --size: the preview preset with one visibility ray
per (pixel, VSGL) pair (dominant_rays 1), the preview as it is (4 rays for
the pairs that carry 0.5 % or more of a pixel's light near a shadow's
edge), with 8, and balanced with one ray and as it is (4), beside
the Cycles one-bounce reference (two seeds of --spp, rendered and cached
by tests/quality/refs.py if missing). Writes a crop of the floor beside the
sphere, Cycles | preview, one ray | preview | preview, 8 | balanced, one ray |
balanced, tone-mapped alike,
and prints each render's time, structured error (4 x 4 box relMSE of the
combined pass), FLIP against the reference and the pixel-scale noise of
the floor below the sphere: the RMS of each pixel minus the mean of its 8
neighbours, over the mean (the reference's own is its Monte Carlo noise at
--spp).
"""
import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))
sys.path.insert(0, os.path.join(ROOT, "addon", "vsgl_indirect"))
import evaluate  # noqa: E402
import imgutil  # noqa: E402
import metrics as M  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402

SCENE = "rough_room"
CONFIGS = (("preview, one ray", "preview:dominant_rays=1"), ("preview", "preview"),
           ("preview, 8 rays", "preview:dominant_rays=8"), ("balanced, one ray", "balanced:dominant_rays=1"),
           ("balanced", "balanced"))
# the floor beside and in front of the sphere, as fractions of the image (rows, columns)
CROP = ((0.62, 0.98), (0.04, 0.62))
# where the noise is measured: the crop's floor below the sphere (no edges)
NOISE = ((0.76, 0.98), (0.04, 0.62))


def pixel_noise(a):
    """RMS of each pixel minus the mean of its 8 neighbours (interior pixels), over the mean."""
    y = a.mean(-1)
    nb = sum(np.roll(np.roll(y, dy, 0), dx, 1) for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx) / 8.0
    d = (y - nb)[1:-1, 1:-1]
    return float(np.sqrt(np.mean(d * d)) / np.mean(y[1:-1, 1:-1]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--spp", type=int, default=256, help="the reference's samples per seed")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "img", "dominant_rays.png"))
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split("x"))
    ref = refs.mean_combined(SCENE, (w, h, args.spp))
    (n0, n1), (m0, m1) = NOISE
    ny, nx = slice(int(n0 * h), int(n1 * h)), slice(int(m0 * w), int(m1 * w))
    print("%-18s %-26s %s" % ("Cycles", "2 x %d spp" % args.spp, "pixel-scale noise %.4f" % pixel_noise(ref[ny, nx])))
    rend = evaluate.Renderer()
    s = scenes.case(SCENE, (w, h))
    outs = []
    for label, spec in CONFIGS:
        best = None
        for _ in range(3):  # the fastest of three (the image is the same)
            out, secs, stats, _ = rend.render(s, evaluate.parse_config(spec))
            best = secs if best is None else min(best, secs)
        c = out["Combined"]
        flip = M.flip(c, ref)
        print("%-18s %-26s %.3f s  struct C %.6f  FLIP %s  pixel-scale noise %.4f" %
              (label, spec, best, M.structured(c, ref), "-" if flip is None else "%.4f" % flip,
               pixel_noise(c[ny, nx])))
        outs.append(c)
    imgutil.save_png(args.out, imgutil.crop_row([ref] + outs, CROP, 1.5, zoom=2))  # 2x: the grain is a pixel's
    print("wrote", os.path.relpath(args.out, ROOT))


if __name__ == "__main__":
    main()
