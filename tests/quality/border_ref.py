"""Cycles of a part of an animation at high spp with a new seed every frame (run inside Blender).

    blender -b --factory-startup --python-exit-code 1 --python tests/quality/border_ref.py -- \
        --scene sun_opening --anim light --box 55,80,40,53 --spp 65536 --out build/quality/border.npz

The references of evaluate.py --motion-truth use one seed for every frame of
an animation (two seeds, two sequences), so their noise hardly changes from
frame to frame and the product of the two sequences' steps is the motion
alone. Where a path is rare (a sun glinting off a metal face onto the floor),
a fixed seed finds it at some frame and keeps it: one sequence's pixel jumps
and stays, the other's does not, and the product leaves that change out
(metrics.firefly_mask). This renders only the pixels in --box (x0,x1,y0,y1,
columns and rows from the top-left of the scene's 80 x 60 image) of every
frame, twice, each render with its own seed: unbiased for the motion there,
noisier, so many samples. tests/quality/border_cmp.py compares the library's
frames with it. Writes DiffInd x DiffCol and GlossInd x GlossCol over the
box per frame and seed (keys f00_s1_Diff ...)."""
import argparse
import os
import shutil
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path[:0] = [HERE, os.path.join(ROOT, "tests", "blender"), os.path.join(ROOT, "addon", "vsgl_indirect")]
import cycles_ref  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("--scene", default="sun_opening")
ap.add_argument("--anim", default="light")
ap.add_argument("--box", default="55,80,40,53")
ap.add_argument("--spp", type=int, default=65536)
ap.add_argument("--frames", type=int, default=scenes.FRAMES)
ap.add_argument("--out", required=True)
args = ap.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
x0, x1, y0, y1 = (int(v) for v in args.box.split(","))
W, H = 80, 60
if not (0 <= x0 < x1 <= W and 0 <= y0 < y1 <= H):
    sys.exit("--box %s: not inside the %d x %d image" % (args.box, W, H))
res = dict(box=np.array([x0, x1, y0, y1]), spp=args.spp, blender=bpy.app.version_string)
tmp = os.path.join(os.path.dirname(os.path.abspath(args.out)), "border_tmp_%d" % os.getpid())
for f in range(args.frames):
    c = scenes.animate(scenes.case(args.scene, (W, H)), args.anim, f)
    cycles_ref.build_blender(c)
    r = bpy.context.scene.render
    r.use_border, r.use_crop_to_border = True, False
    r.border_min_x, r.border_max_x = x0 / W, x1 / W
    r.border_min_y, r.border_max_y = 1.0 - y1 / H, 1.0 - y0 / H  # Blender's y runs up
    for s in (1, 2):
        os.makedirs(tmp, exist_ok=True)
        prefix = os.path.join(tmp, "r")
        t0 = time.time()
        cycles_ref.render_cycles(c, list(refs.PASSES), prefix, args.spp, 1000 * s + 17 * f + 3)
        p = {k: cycles_ref.load_exr_rgb(prefix + "_" + k + "_0001.exr") for k in refs.PASSES}
        res["f%02d_s%d_Diff" % (f, s)] = (p["DiffInd"] * p["DiffCol"])[y0:y1, x0:x1]
        res["f%02d_s%d_Gloss" % (f, s)] = (p["GlossInd"] * p["GlossCol"])[y0:y1, x0:x1]
        shutil.rmtree(tmp, ignore_errors=True)
        print("frame %d seed %d: %.1f s" % (f, s, time.time() - t0), flush=True)
part = args.out + ".part.npz"
np.savez(part, **res)
os.replace(part, args.out)
print("wrote %s" % args.out)
