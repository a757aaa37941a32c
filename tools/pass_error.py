#!/usr/bin/env python3
"""Per-pass error images of one bundled quality scene against its cached
Cycles references: for each pass (Diff = DiffInd x DiffCol, Gloss =
GlossInd x GlossCol) a row of reference | each configuration | each
configuration's signed error (red too bright, blue too dark, x --gain of
the reference's 99th-percentile luminance), labelled; and per
configuration the pass's sum over the reference's, overall and by sixths
of the image's rows (top to bottom), printed.

    python3 tools/pass_error.py dense_floor --size 320x240x2048 \\
        --configs balanced,brute -o docs/img/accuracy/dense_floor_passes.png

The references come from the cache (tests/quality/refs.py), rendered in
Blender where missing; the library is the one evaluate.py loads
(VSGL_LIBRARY to choose another).
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))
sys.path.insert(0, os.path.join(ROOT, "addon"))

import evaluate as E  # noqa: E402
import imgutil as I  # noqa: E402
import metrics as M  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scene")
    ap.add_argument("--size", default="320x240x2048", help="WxHxSPP of the cached references")
    ap.add_argument("--configs", default="balanced", help="comma-separated evaluate.py configurations")
    ap.add_argument("--passes", default="Diff,Gloss")
    ap.add_argument("--gain", type=float, default=4.0, help="error scale (default 4)")
    ap.add_argument("-o", "--out", required=True, help="PNG to write")
    args = ap.parse_args(argv)

    case = scenes.case(args.scene, args.size)
    # the cached references, rendered in Blender where missing
    ref = [M.coloured(p) for p, _ in refs.ensure([args.scene], scenes.size_of(args.size))[args.scene]]
    cfgs = [E.parse_config(c) for c in E.split_configs(args.configs)]
    rend = E.Renderer()
    imgs = [rend.render(case, c)[0] for c in cfgs]
    passes = args.passes.split(",")
    rows = []
    for P in passes:
        r = 0.5 * (ref[0][P] + ref[1][P])
        lr = I.luminance(r)
        ex = I.exposure_for(r)
        scale = args.gain / max(float(np.percentile(lr, 99)), 1e-30)
        h = lr.shape[0]
        shaded, errs = [], []
        for c, img in zip(cfgs, imgs):
            la = I.luminance(img[P])
            sixths = " ".join("%.3f" % (la[y:y + h // 6].sum() / max(lr[y:y + h // 6].sum(), 1e-30))
                              for y in range(0, h - h // 6 + 1, h // 6))
            print("%-10s %-5s sum %.4f  by sixths of rows: %s" % (c.label, P, la.sum() / lr.sum(), sixths))
            shaded.append(I.tonemap(img[P], ex))
            errs.append(I.signed_error(la - lr, scale))
        rows.append([I.tonemap(r, ex)] + shaded + errs)
    heads = ([["reference", "rows: " + ", ".join(passes)]] + [[c.label] for c in cfgs] +
             [["error x%g" % args.gain, c.label] for c in cfgs])
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    I.save_png(args.out, I.grid(rows, heads, max(1, 320 // rows[0][0].shape[1])))
    print("wrote", args.out)


if __name__ == "__main__":
    main()
