#!/usr/bin/env python3
"""Where a scene's camera animation jitters, before and after a change (issue 9).

Renders a quality scene's camera animation (tests/quality/scenes.py, 80 x 60,
12 frames) with one configuration through two libraries, and draws one row
each for Cycles (the cached two-seed references), the library given by
--before and this checkout's build/libvsgl.so: frame 0, the mean |step|
between consecutive frames and the mean |second difference| (jitter: a
smooth motion has little), both in false colour (blue 0, green 2 %, red >=
4 % of the reference's 99th percentile). Prints the means.

    python3 tools/camera_strip.py grazing_corridor preview Diff \\
        --before /path/to/old/libvsgl.so --out docs/img/corridor_camera_edges.png

Needs the cached 80 x 60 camera references (`make test` renders them).
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))
sys.path.insert(0, os.path.join(ROOT, "addon"))
sys.path.insert(0, os.path.join(ROOT, "tools"))

from camera_dense_excess import FRAMES, run  # noqa: E402  (its camera animation, rendered in a child)


def render(lib, scene, config, plane, out):
    """The animation's frames (FRAMES x H x W x 3) of one pass through library lib."""
    return np.array([f[plane] for f in run(scene, config, (80, 60), out, lib)])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene")
    ap.add_argument("config", help="a configuration of tests/quality/evaluate.py (preview, balanced, LABEL:k=v ...)")
    ap.add_argument("plane", choices=("Diff", "Gloss"))
    ap.add_argument("--before", required=True, help="the library to compare with (a libvsgl.so)")
    ap.add_argument("--out", required=True, help="the PNG to write")
    args = ap.parse_args()

    import imgutil
    import metrics as M
    import refs
    tmp = os.path.join(ROOT, "build", "camera_strip")
    os.makedirs(tmp, exist_ok=True)
    seq = {"cycles": np.array([0.5 * sum(M.coloured(img)[args.plane] for img, _ in refs.ensure_frame(
        [args.scene], (80, 60, 1024), "camera", f, refs.DEFAULT_DIR)[args.scene]) for f in range(FRAMES)])}
    seq["before"] = render(args.before, args.scene, args.config, args.plane, os.path.join(tmp, "before.npz"))
    seq["after"] = render(os.path.join(ROOT, "build", "libvsgl.so"), args.scene, args.config, args.plane,
                          os.path.join(tmp, "after.npz"))
    lum = {k: v.sum(-1) for k, v in seq.items()}
    top = np.percentile(lum["cycles"][0], 99)
    exposure = imgutil.exposure_for(seq["cycles"][0])
    rows = []
    for name in ("cycles", "before", "after"):
        step = np.abs(np.diff(lum[name], axis=0)).mean(0) / top
        jitter = np.abs(np.diff(lum[name], 2, axis=0)).mean(0) / top
        print("%-7s mean |step| %.5f, mean |second difference| %.5f (of the reference's 99th percentile)"
              % (name, step.mean(), jitter.mean()))
        rows.append(np.concatenate([imgutil.tonemap(seq[name][0], exposure), imgutil.false_colour(step, 0.04),
                                    imgutil.false_colour(jitter, 0.04)], axis=1))
    imgutil.save_png(args.out, imgutil.upscale(np.concatenate(rows, axis=0), 4))
    print("wrote %s: rows Cycles, before, after; columns frame 0, mean |step|, mean |second difference|" % args.out)


if __name__ == "__main__":
    main()
