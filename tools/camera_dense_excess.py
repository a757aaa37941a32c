#!/usr/bin/env python3
"""Camera flicker above a dense render, at any image size, for one or more
builds of the library (issue 9).

The quality suite measures camera flicker at 80 x 60, where its Cycles
references live; there balanced and quality take 2 x 2 and 3 x 3 samples.
From 320 x 240 up every preset takes one sample per pixel
(aa_pixel_limit), which the 80 x 60 figures do not show. This renders a
quality scene's camera animation (tests/quality/scenes.py, 12 frames) with
a configuration and with the suite's dense render (evaluate.CAMERA_TRUTH:
8 x 8 samples, every pixel shaded, no edge refinement, no visibility rays;
here without the pixel limit, which would take it to one sample), and
prints metrics.excess_flicker per pass (Diff / Gloss): the median over
frame steps of the RMS of our step minus the dense render's, relative to
the frame. No Cycles render is needed. Each library renders in its own
process (VSGL_LIBRARY), so builds can be compared in one run:

    python3 tools/camera_dense_excess.py --scenes sun_opening,glossy_sphere_floor
    python3 tools/camera_dense_excess.py --libs /tmp/old/libvsgl.so,build/libvsgl.so --config preview

The dense frames are cached under --cache (they take most of the time:
the box room's ~4 minutes at 320 x 240 on 2 cores). --map writes the
per-pixel excess of the last library as false-colour PNGs.
"""
import argparse
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))
sys.path.insert(0, os.path.join(ROOT, "addon"))

import imgutil  # noqa: E402
import metrics as M  # noqa: E402

PASSES = ("Diff", "Gloss")
FRAMES = 12


def render_child(scene, config, size, out):
    """In a child process: render the camera animation and save it."""
    import evaluate as E
    import scenes
    if config == "dense":
        cfg = E.Config("dense", E.CAMERA_TRUTH[0], dict(E.CAMERA_TRUTH[1], aa_pixel_limit=0))
    else:
        cfg = E.parse_config(config)
    rend = E.Renderer()
    base = scenes.case(scene, size)
    seq = [rend.render(scenes.animate(base, "camera", f), cfg)[0] for f in range(FRAMES)]
    np.savez(out, **{"%s%d" % (p, f): seq[f][p] for f in range(FRAMES) for p in PASSES})


def load(path):
    z = np.load(path)
    return [{p: z["%s%d" % (p, f)] for p in PASSES} for f in range(FRAMES)]


def run(scene, config, size, out, lib=None):
    env = dict(os.environ)
    if lib:
        env["VSGL_LIBRARY"] = os.path.abspath(lib)
    subprocess.run([sys.executable, os.path.abspath(__file__), "--child", scene, config, "%dx%d" % size, out],
                   check=True, env=env, cwd=ROOT)
    return load(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default="spot_metal_floor,metal_floor_red_wall,box_point_area_glossy_green,"
                    "glossy_sphere_floor,sun_opening,sun_opening_thick,textured_interior")
    ap.add_argument("--config", default="balanced", help="a configuration of tests/quality/evaluate.py")
    ap.add_argument("--size", default="320x240")
    ap.add_argument("--libs", default="", help="comma-separated libvsgl.so paths (default: the one evaluate.py loads)")
    ap.add_argument("--cache", default=os.path.join(ROOT, "build", "camera_dense"))
    ap.add_argument("--map", default="", help="directory for per-pixel excess PNGs")
    ap.add_argument("--keep-runs", action="store_true", help="keep each library's frames (npz) in --cache")
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.child:
        scene, config, size, out = a.child
        render_child(scene, config, tuple(int(v) for v in size.split("x")), out)
        return 0
    size = tuple(int(v) for v in a.size.split("x"))
    libs = [x for x in a.libs.split(",") if x] or [None]
    os.makedirs(a.cache, exist_ok=True)
    print("camera flicker above the dense render (metrics.excess_flicker), %dx%d, %s, Diff / Gloss; libraries: %s"
          % (size[0], size[1], a.config, ", ".join(x or "default" for x in libs)), flush=True)
    for scene in a.scenes.split(","):
        dense_path = os.path.join(a.cache, "%s_%dx%d_dense.npz" % (scene, size[0], size[1]))
        dense = load(dense_path) if os.path.exists(dense_path) else run(scene, "dense", size, dense_path)
        cells = []
        for i, lib in enumerate(libs):
            path = os.path.join(a.cache, "run_%s_%d_%d.npz" % (scene, os.getpid(), i))
            seq = run(scene, a.config, size, path, lib)
            if a.keep_runs:
                print("  frames of %s: %s" % (lib or "default", path))
            else:
                os.remove(path)
            cells.append(" / ".join("%.4f" % M.excess_flicker([x[p] for x in seq], [x[p] for x in dense])
                                    for p in PASSES))
        print("%-28s %s" % (scene, "  ->  ".join(cells)), flush=True)
        if a.map:  # the last library's excess, per pass
            os.makedirs(a.map, exist_ok=True)
            for p in PASSES:
                steps = M.excess_steps([x[p].sum(-1) for x in seq], [x[p].sum(-1) for x in dense])
                path = os.path.join(a.map, "%s_%s.png" % (scene, p))
                red, top = imgutil.save_error_map(path, np.sqrt(sum(d ** 2 for d in steps)))
                print("  wrote %s (red = %.4g, the 99.5th percentile; max %.4g)" % (path, red, top))
    return 0


if __name__ == "__main__":
    sys.exit(main())
