#!/usr/bin/env python3
"""Where a configuration's camera flicker exceeds Cycles' own (issue 9).

Renders a quality scene's camera animation (tests/quality/scenes.py) with
one configuration and splits the per-pixel excess energy of its frame steps
over Cycles' (the two-seed references of tests/quality/refs.py, cached)
by what the pixel shows (the 4 x 4 G-buffer's materials: pixels two
surfaces share, the object's interior, the floor) and by direction from
the object's centre in the image. The excess of a step is the part of
our frame difference that both Cycles seeds' differences miss,
max((d - c1) . (d - c2), 0) per pixel (metrics.flicker's "above Cycles'
motion" before its median over steps). Optionally prints pixels' values
over the frames beside Cycles' and writes the excess map as a PNG.

    python3 tools/camera_excess.py balanced
    python3 tools/camera_excess.py "x:aa_samples=4 edge_samples=16" --pixels 46,29 45,31
    python3 tools/camera_excess.py balanced --map /tmp/excess.png
    python3 tools/camera_excess.py balanced --top 8

Needs the cached 80 x 60 camera references (`make test` renders them with
Blender 3.4 when they are missing) and numpy; --map writes a false-colour PNG.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))
sys.path.insert(0, os.path.join(ROOT, "addon"))

import evaluate as E  # noqa: E402
import metrics as M  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402

DIRECTIONS = ["right", "upper right", "top", "upper left", "left", "lower left", "bottom", "lower right"]


def region_masks(base, L, obj_px, floor_rows):
    """Masks of pixels whose 4 x 4 samples lie on more than one surface,
    wholly on the object (the material at obj_px), wholly on the floor (the
    most common material of the rows floor_rows)."""
    ctx = L.Context(thread_count=0, log_level="error")
    with L.Scene(ctx, **scenes.library_arrays(base, L)) as sc:
        mat = L.debug_gbuffer(ctx, sc, aa=4)["materials"]
    mixed = (mat != mat[..., :1]).any(-1)
    x, y = obj_px
    obj = np.bincount(mat[y - 1:y + 2, x - 1:x + 2].ravel()).argmax()
    floor = np.bincount(mat[floor_rows[0]:floor_rows[1]].ravel()).argmax()
    return mixed, (mat == obj).all(-1), (mat == floor).all(-1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("config", help="a configuration of tests/quality/evaluate.py (balanced, LABEL:k=v ...)")
    ap.add_argument("--scene", default="glossy_sphere_floor")
    ap.add_argument("--object", default="40,28", help="a pixel on the object whose rim is split (x,y; 80 x 60)")
    ap.add_argument("--floor-rows", default="55,60", help="image rows that show the floor (y0,y1)")
    ap.add_argument("--pass", dest="plane", default="Gloss", choices=("Diff", "Gloss"))
    ap.add_argument("--frames", type=int, default=12)
    ap.add_argument("--pixels", nargs="*", default=[], help="x,y pixels whose values over the frames to print")
    ap.add_argument("--top", type=int, default=0,
                    help="print the N pixels that carry the most excess, with their share and values over the frames")
    ap.add_argument("--map", help="write the excess map (sqrt of the summed excess) to this PNG")
    args = ap.parse_args()

    size = (80, 60, 1024)
    L = E.L
    rend = E.Renderer()
    base = scenes.case(args.scene, size[:2])
    cfg = E.parse_config(args.config)
    p = args.plane
    ours = [rend.render(scenes.animate(base, "camera", f), cfg)[0][p].astype(np.float64)
            for f in range(args.frames)]
    seq = []
    for f in range(args.frames):
        pair = refs.ensure_frame([args.scene], size, "camera", f, refs.DEFAULT_DIR)[args.scene]
        seq.append([M.coloured(img)[p].astype(np.float64) for img, _ in pair])
    mid = scenes.animate(base, "camera", args.frames // 2)
    obj_px = tuple(int(v) for v in args.object.split(","))
    mixed, on_obj, on_floor = region_masks(mid, L, obj_px, [int(v) for v in args.floor_rows.split(",")])

    acc = np.zeros(mixed.shape)
    for t in range(args.frames - 1):
        d = ours[t + 1] - ours[t]
        c1, c2 = seq[t + 1][0] - seq[t][0], seq[t + 1][1] - seq[t][1]
        acc += np.maximum(((d - c1) * (d - c2)).sum(-1), 0.0)
    total = acc.sum()
    other = ~(mixed | on_obj | on_floor)
    print("%s, %s, camera animation, %s: excess energy %.4f (sum over %d steps of the per-pixel excess)"
          % (args.scene, cfg.label, p, total, args.frames - 1))
    print("share: pixels two surfaces share %.2f | the object %.2f | the floor %.2f | the rest %.2f"
          % tuple(acc[m].sum() / max(total, 1e-30) for m in (mixed, on_obj, on_floor, other)))

    ys, xs = np.nonzero(on_obj | mixed)
    cy, cx = ys.mean(), xs.mean()
    yy, xx = np.mgrid[0:mixed.shape[0], 0:mixed.shape[1]]
    ang = (np.degrees(np.arctan2(-(yy - cy), xx - cx)) + 360.0) % 360.0
    sector = ((ang + 22.5) // 45).astype(int) % 8
    print("by direction from the object's centre (%.1f, %.1f):" % (cx, cy))
    for name, m in (("  shared", mixed), ("  object", on_obj), ("  floor", on_floor)):
        print("%-8s " % name + "  ".join("%s %.3f" % (DIRECTIONS[s], acc[m & (sector == s)].sum() / max(total, 1e-30))
                                         for s in range(8)))
    pixels = [tuple(int(v) for v in spec.split(",")) for spec in args.pixels]
    cum = 0.0
    for k in np.argsort(-acc.ravel())[:max(args.top, 0)]:
        y, x = divmod(int(k), acc.shape[1])
        cum += acc[y, x]
        print("(%d,%d) carries %.3f of the excess (the %d pixels so far %.3f)"
              % (x, y, acc[y, x] / max(total, 1e-30), len(pixels) - len(args.pixels) + 1, cum / max(total, 1e-30)))
        pixels.append((x, y))
    for x, y in pixels:
        cyc = [0.5 * (s[0][y, x].sum() + s[1][y, x].sum()) for s in seq]
        print("(%d,%d) Cycles %s" % (x, y, " ".join("%.3f" % v for v in cyc)))
        print("(%d,%d) ours   %s" % (x, y, " ".join("%.3f" % o[y, x].sum() for o in ours)))
    if args.map:
        import imgutil
        red, top = imgutil.save_error_map(args.map, np.sqrt(acc))
        print("map: blue 0 .. red %.4g (99.5th percentile), max %.4g" % (red, top))
        print("wrote", args.map)


if __name__ == "__main__":
    main()
