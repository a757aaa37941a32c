#!/usr/bin/env python3
"""The sun room's indirect shadow, where visibility rays aim (issue 9).

    python3 tools/penumbra.py [--size 960x540] [--out docs/img/penumbra.png]

Renders sun_opening at --size with the balanced preset twice: every
visibility ray at its VSGL's centre (visibility_spread -1: one hard edge
per VSGL behind the cabinet) and over the cluster's disk (the preset's
spread 2), beside the Cycles one-bounce reference (two seeds of 256 spp,
rendered and cached by tests/quality/refs.py if missing). Writes a crop of
the wall behind the cabinet: Cycles | centre | spread, each
tone-mapped alike, and prints each render's time, structured error
(4 x 4 box relMSE of the combined pass) and FLIP against the reference.
"""
import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))
sys.path.insert(0, os.path.join(ROOT, "addon", "vsgl_indirect"))
import evaluate  # noqa: E402
import imgutil  # noqa: E402
import metrics as M  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402

SCENE = "sun_opening"
CONFIGS = (("centre", "balanced:visibility_spread=-1"), ("spread 2", "balanced"))
# the wall behind the cabinet, as fractions of the image (rows, columns)
CROP = ((0.15, 0.85), (0.54, 0.94))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="960x540")
    ap.add_argument("--spp", type=int, default=256, help="the reference's samples per seed")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "img", "penumbra.png"))
    args = ap.parse_args()
    w, h = (int(v) for v in args.size.split("x"))
    ref = refs.mean_combined(SCENE, (w, h, args.spp))
    rend = evaluate.Renderer()
    s = scenes.case(SCENE, (w, h))
    outs = []
    for label, spec in CONFIGS:
        out, secs, stats, _ = rend.render(s, evaluate.parse_config(spec))
        c = out["Combined"]
        flip = M.flip(c, ref)
        print("%-9s %-34s %.3f s  pairs %.3g  struct C %.6f  FLIP %s" %
              (label, spec, secs, stats["shading_pairs"], M.structured(c, ref),
               "-" if flip is None else "%.4f" % flip))
        outs.append(c)
    imgutil.save_png(args.out, imgutil.crop_row([ref] + outs, CROP, 1.8))
    print("wrote", os.path.relpath(args.out, ROOT))


if __name__ == "__main__":
    main()
