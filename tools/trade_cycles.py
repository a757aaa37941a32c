"""Cycles sweeps of the trade measurement (issue 11; run inside Blender by tools/trade.py).

    blender -b --factory-startup --python-exit-code 1 --python tools/trade_cycles.py -- \
        --size WxH --scenes a,b --spp 1,4,16 --seed 7 --out build/trade/cycles

Builds each scene with tests/blender/cycles_ref.py's build_blender, times the
add-on's export of it (vsgl_indirect.export.collect on the evaluated
depsgraph, as a render does: the fastest of 3), then renders it once per
spp (after a 1-spp warm-up render that is not kept) with cycles_ref.render_cycles (the quality references' one-bounce
settings, each pixel its area's average, no denoising) plus the Normal pass (a guide for
OIDN). Each render is stored as an .npz (DiffInd, GlossInd, DiffCol,
GlossCol, Normal; meta: render seconds = the render call, scene sync
included, the faster of two up to 16 spp; export seconds) under --out, named by refs.path with the digest
of this file's render_sweep (and of the references' code); existing files
are kept.
"""
import os
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, ".."))
for d in (os.path.join(ROOT, "tests", "quality"), os.path.join(ROOT, "tests", "blender"), os.path.join(ROOT, "addon")):
    sys.path.insert(0, d)
import cycles_ref  # noqa: E402
import cycles_textures  # noqa: E402
import gbuffer_ref  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402

NAMES = refs.PASSES + ("Normal",)
# the code whose change re-renders the sweeps (with refs.CODE)
SWEEP_CODE = dict(refs.CODE, **{os.path.join("tools", "trade_cycles.py"): ("render_sweep",)})


def render_sweep(case, spp, seed, tmp):
    """Passes NAMES ((H, W, 3) float32, row 0 = top) and seconds of one
    Cycles one-bounce render of the scene built from `case`."""
    os.makedirs(tmp, exist_ok=True)
    prefix = os.path.join(tmp, "sweep")
    bpy.context.view_layer.use_pass_normal = True
    secs = cycles_ref.render_cycles(case, list(refs.PASSES), prefix, spp, seed)
    # every pass of the render result in one multilayer file (Blender 3.4 writes
    # only the compositor's file outputs, which hold the four light/colour passes)
    s = bpy.context.scene.render.image_settings
    s.file_format, s.color_depth, s.exr_codec = "OPEN_EXR_MULTILAYER", "32", "NONE"
    path = prefix + "_all.exr"
    if not os.path.exists(path):  # Blender 5 wrote it already
        bpy.data.images["Render Result"].save_render(path)
    ch = gbuffer_ref.read_exr(path)
    out = {}
    for p in NAMES:
        long_name = cycles_ref.PASS_LONG_NAMES.get(p, p)
        keys = [k for k in ch if k.split(".")[-2] in (p, long_name)]
        comps = [next(k for k in keys if k.endswith("." + c) or k.endswith("." + a)) for c, a in zip("RGB", "XYZ")]
        out[p] = np.stack([ch[k] for k in comps], axis=-1).astype(np.float32)
    return out, secs


def export_seconds(repeat=3):
    """The fastest of `repeat` exports of the current scene by the add-on."""
    from vsgl_indirect import export
    best = None
    for _ in range(repeat):
        dg = bpy.context.evaluated_depsgraph_get()
        t0 = time.perf_counter()
        export.collect(dg, bpy.context.scene)
        t = time.perf_counter() - t0
        best = t if best is None else min(best, t)
    return best


def clear(tmp):
    for f in os.listdir(tmp):
        os.remove(os.path.join(tmp, f))


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    a = dict(zip(argv[0::2], argv[1::2]))
    w, h = (int(v) for v in a["--size"].split("x"))
    seed = int(a.get("--seed", 7))
    out = os.path.abspath(a["--out"])
    os.makedirs(out, exist_ok=True)
    version = bpy.app.version_string
    code = refs.code_digest(SWEEP_CODE)
    for name in [n for n in a["--scenes"].split(",") if n]:
        c = scenes.case(name, (w, h))
        todo = [int(s) for s in a["--spp"].split(",")
                if not os.path.exists(refs.path(out, name, (w, h, int(s)), seed, version, code))]
        if not todo:
            continue
        t0 = time.perf_counter()
        cycles_textures.apply_textures(c, cycles_ref.build_blender(c)[0])
        build = time.perf_counter() - t0
        exp = export_seconds()
        print("%s: built in %.1f s, add-on export %.3f s" % (name, build, exp), flush=True)
        tmp = os.path.join(out, "tmp_%d" % os.getpid())
        render_sweep(c, 1, seed, tmp)  # warm-up, not kept: the session's first render loads the kernels
        clear(tmp)  # (render_sweep reads an existing multilayer file as Blender 5's own)
        for spp in todo:
            passes, secs = render_sweep(c, spp, seed, tmp)
            clear(tmp)
            if spp <= 16:  # cheap: the faster of two renders (the machine is shared); the first one's image
                secs = min(secs, render_sweep(c, spp, seed, tmp)[1])
                clear(tmp)
            meta = dict(scene=name, width=w, height=h, spp=spp, seed=seed, blender=version, render_seconds=secs,
                        export_seconds=exp, threads=bpy.context.scene.render.threads)
            refs.save(refs.path(out, name, (w, h, spp), seed, version, code), passes, meta, NAMES)
            print("%s %d spp: %.2f s" % (name, spp, secs), flush=True)


main()
