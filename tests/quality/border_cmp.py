"""The library's frames against tests/quality/border_ref.py's Cycles over its box.

    python3 tests/quality/border_cmp.py build/quality/border.npz --scene sun_opening --configs balanced,brute

Per configuration, over the box: its flicker (metrics.flicker), Cycles' own
motion from the two independently seeded sequences (metrics.motion_steps),
the change in excess of it (metrics.excess_over_seeds), and the mean over
Cycles' at the first and last frames; then per pixel of --pixels the
frames' values."""
import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import evaluate as E  # noqa: E402
import metrics as M  # noqa: E402
import scenes  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("npz")
ap.add_argument("--scene", default="sun_opening")
ap.add_argument("--anim", default="light")
ap.add_argument("--configs", default="balanced,brute")
ap.add_argument("--pass", dest="p", default="Diff", choices=("Diff", "Gloss"))
ap.add_argument("--pixels", default="68:46,71:47,74:48,77:49", help="x:y,... (image coordinates)")
ap.add_argument("--png", default=None,
                help="also write the box at the first, middle and last frames: Cycles, then each configuration "
                     "(one exposure per frame, 12x enlarged)")
args = ap.parse_args()
r = np.load(args.npz)
x0, x1, y0, y1 = (int(v) for v in r["box"])
n = len([k for k in r.files if k.endswith("_s1_" + args.p)])
if n < 2:
    sys.exit("%s: %d frames of %s (border_ref.py writes Diff and Gloss)" % (args.npz, n, args.p))
A = [r["f%02d_s1_%s" % (f, args.p)].astype(np.float64) for f in range(n)]
B = [r["f%02d_s2_%s" % (f, args.p)].astype(np.float64) for f in range(n)]
C = [0.5 * (a + b) for a, b in zip(A, B)]
rend = E.Renderer()
shown = sorted({0, n // 2, n - 1})
strips = {f: [C[f]] for f in shown}
base = scenes.case(args.scene, (80, 60))
pix = [tuple(int(v) for v in q.split(":")) for q in args.pixels.split(",") if q]
print("%s %s, box x %d-%d y %d-%d, Cycles %s spp x 2 seeds per frame (Blender %s)" % (
    args.scene, args.p, x0, x1, y0, y1, r["spp"], r["blender"]))
for x, y in pix:
    print("  Cycles (%d,%d): %s" % (x, y, " ".join("%.3f" % c[y - y0, x - x0].mean() for c in C)))
for spec in E.split_configs(args.configs):
    cfg = E.parse_config(spec)
    F = [rend.render(scenes.animate(base, args.anim, f), cfg)[0][args.p][y0:y1, x0:x1].astype(np.float64)
         for f in range(n)]
    print("%-10s flicker %.4f, Cycles' own %.4f, above it %.4f; mean over Cycles' frame 0 %.3f, frame %d %.3f" % (
        cfg.label, M.flicker(F)["median"], float(np.median(M.motion_steps(A, B))), M.excess_over_seeds(F, A, B),
        F[0].mean() / C[0].mean(), n - 1, F[-1].mean() / C[-1].mean()))
    for f in shown:
        strips[f].append(F[f])
    for x, y in pix:
        print("  %s (%d,%d): %s" % (cfg.label, x, y, " ".join("%.3f" % f[y - y0, x - x0].mean() for f in F)))
if args.png:
    import imgutil
    rows = []
    for f in shown:
        scale = np.percentile(C[f], 99) or 1.0
        gap = np.ones((y1 - y0, 1, 3))
        parts = []
        for img in strips[f]:
            parts += [np.clip(img / scale, 0.0, 1.0), gap]
        rows += [np.concatenate(parts[:-1], 1), np.ones((1, sum(p.shape[1] for p in parts[:-1]), 3))]
    imgutil.save_png(args.png, np.repeat(np.repeat(np.concatenate(rows[:-1], 0), 12, 0), 12, 1))
    print("wrote %s (rows: frames %s; columns: Cycles, %s)" % (args.png, ", ".join(map(str, shown)), args.configs))
