"""Render the Cycles one-bounce references of the quality scenes (run inside Blender).

    blender -b --factory-startup --python-exit-code 1 --python tests/quality/render_refs.py -- \
        [--size test|bench|WxH[xSPP]] [--scenes a,b,...] [--seeds 1,2] [--out build/quality/refs] \
        [--anim light|camera --frame N[,N...]] [--check-builder] [--force]

Builds each scene with tests/blender/cycles_ref.py's build_blender and renders
it with its render_cycles (max_bounces 1, no clamps, blur_glossy 0, box pixel
filter: 1 px wide whatever its width is set to, so each pixel is the average
over its area; fixed seed, no denoising, world strength 0), passes
DiffInd, GlossInd, DiffCol, GlossCol, once per seed; stores each as an .npz
under --out (refs.py names and keys them; existing ones are kept unless
--force).

--anim/--frame: render frame N of that animation (scenes.animate) instead
of the still (evaluate.py --motion-truth: the motion's own change); N may
be a comma-separated list of frames, rendered in one Blender session.

--check-builder: compares the pure-Python builder (scenes.library_arrays)
with the arrays cycles_ref.library_arrays reads back from the bpy-built scene
(positions, triangles, normals, materials, every light and camera field) and
prints PASS/FAIL per scene (renders nothing unless --size is also given).
Ends with "N passed, N failed".
"""
import os
import shutil
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
sys.path.insert(0, os.path.join(ROOT, "addon", "vsgl_indirect"))
import cycles_ref  # noqa: E402  (guarded main: importing renders nothing)
import libvsgl  # noqa: E402
import cycles_textures  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402


def render_passes(case, spp, seed, tmp):
    """Cycles passes of the scene currently built from `case`: dict of
    (H, W, 3) float32, row 0 = top; and the render's seconds."""
    os.makedirs(tmp, exist_ok=True)
    prefix = os.path.join(tmp, "ref")
    secs = cycles_ref.render_cycles(case, list(refs.PASSES), prefix, spp, seed)
    if not hasattr(bpy.context.scene, "node_tree"):  # Blender 5: one multilayer file
        out = cycles_ref.read_passes_exr(prefix + "_all.exr", list(refs.PASSES))
    else:
        out = {p: cycles_ref.load_exr_rgb(prefix + "_" + p + "_0001.exr") for p in refs.PASSES}
    return out, secs


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    args = {"--size": None, "--scenes": ",".join(scenes.NAMES), "--seeds": ",".join(map(str, scenes.SEEDS)),
            "--out": refs.DEFAULT_DIR, "--anim": "light", "--frame": "0"}
    flags = set()
    i = 0
    while i < len(argv):
        if argv[i] in ("--check-builder", "--force"):
            flags.add(argv[i])
            i += 1
        else:
            args[argv[i]] = argv[i + 1]
            i += 2
    return args, flags


def _close(a, b, tol):
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return a.shape == b.shape and bool(np.all(np.abs(a - b) <= tol * (1 + np.abs(b))))


def check_builder(name):
    """The pure-Python scene against the one read back from Blender. Returns
    a list of differences (empty: equal)."""
    c = scenes.case(name, "test")
    ob, lights, co, mats = cycles_ref.build_blender(c)
    cycles_textures.apply_textures(c, ob)
    want = cycles_ref.library_arrays(ob, lights, co, mats, c["materials"])
    got = scenes.library_arrays(c, libvsgl)
    bad = []
    if list(mats) != scenes.material_order(c):
        bad.append("material order %s vs %s" % (list(mats), scenes.material_order(c)))
    if not _close(got["positions"], want["positions"], 1e-6):
        bad.append("positions")
    if not np.array_equal(got["indices"], want["indices"]):
        bad.append("indices")
    if not np.array_equal(got["material_indices"], want["material_indices"]):
        bad.append("material indices")
    cn = want["corner_normals"]
    if cn is None:  # flat mesh: the face normals
        P = want["positions"].astype(np.float64)[want["indices"]]
        fn = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
        cn = np.repeat((fn / np.linalg.norm(fn, axis=1, keepdims=True))[:, None, :], 3, axis=1)
    if not _close(got["corner_normals"], cn, 1e-4):
        bad.append("corner normals (max diff %.2e)" % float(np.abs(got["corner_normals"] - cn).max()))
    for kind, gl, wl in (("material", got["materials"], want["materials"]), ("light", got["lights"], want["lights"])):
        if len(gl) != len(wl):
            bad.append("%s count" % kind)
            continue
        for i, (g, w) in enumerate(zip(gl, wl)):
            gd, wd = g.as_dict(), libvsgl.STRUCTS[type(g).__name__].from_buffer_copy(w).as_dict()
            for f in gd:
                if not _close(gd[f], wd[f], 1e-5):
                    bad.append("%s %d field %s: %s vs %s" % (kind, i, f, gd[f], wd[f]))
    gd, wd = got["camera"].as_dict(), want["camera"].as_dict()
    for f in gd:
        if not _close(gd[f], wd[f], 1e-5):
            bad.append("camera field %s: %s vs %s" % (f, gd[f], wd[f]))
    return bad


def main():
    args, flags = parse_args()
    names = [n for n in args["--scenes"].split(",") if n]
    passed = failed = 0
    if "--check-builder" in flags:
        for n in names:
            bad = check_builder(n)
            print(("PASS" if not bad else "FAIL") + " builder %s: pure-Python scene %s the bpy-built one%s"
                  % (n, "equals" if not bad else "differs from", "" if not bad else ": " + "; ".join(bad[:6])),
                  flush=True)
            passed += not bad
            failed += bool(bad)
    if args["--size"]:
        out = os.path.abspath(args["--out"])
        os.makedirs(out, exist_ok=True)
        version = bpy.app.version_string
        code = refs.code_digest()
        w, h, spp = scenes.size_of(args["--size"])
        anim = args["--anim"]
        for n, frame in [(n, int(f)) for n in names for f in args["--frame"].split(",")]:
            c = scenes.animate(scenes.case(n, (w, h)), anim, frame)
            built = False
            for seed in [int(s) for s in args["--seeds"].split(",")]:
                p = refs.path_frame(out, n, (w, h, spp), seed, version, anim, frame, code)
                if os.path.exists(p) and "--force" not in flags:
                    print("cached %s" % os.path.basename(p), flush=True)
                    continue
                if not built:
                    cycles_textures.apply_textures(c, cycles_ref.build_blender(c)[0])
                    built = True
                tmp = os.path.join(out, "tmp_%d" % os.getpid())
                t0 = time.time()
                passes, secs = render_passes(c, spp, seed, tmp)
                shutil.rmtree(tmp, ignore_errors=True)
                meta = dict(scene=n, width=w, height=h, spp=spp, seed=seed, blender=version, anim=anim, frame=frame,
                            render_seconds=secs, wall_seconds=time.time() - t0,
                            threads=bpy.context.scene.render.threads)
                refs.save(p, passes, meta)
                print("rendered %s: %.1f s (%d x %d, %d spp, seed %d, %d threads)"
                      % (os.path.basename(p), secs, w, h, spp, seed, meta["threads"]), flush=True)
    if "--check-builder" in flags:
        print("%d passed, %d failed" % (passed, failed))
    if failed:
        sys.exit(1)


main()
