"""Live viewport preview timings, headless (make bench): what an edit costs
from Blender's data to a displayable image, without Blender's drawing.

    python3 tools/bench_live.py [--triangles N] [--size 960x540] [--repeat 5] [--quality LIVE,PREVIEW]
                                [--coarse 2]

Runs in the pip bpy module (or `blender -b --python tools/bench_live.py --`).
Builds a room with a subdivided object of about N triangles (default 100k),
then times, each the median of --repeat edits:
  * light moved:  export (mesh cache warm) + library (scene reused) + encode
  * camera moved: the same with another view
  * geometry edit: export of the changed object + a new library scene + render
and the CPU time of the library call and the encode (all threads: a
figure less sensitive to other jobs on the machine than the wall times).
for the viewport at full size and at the panel's default 1/2, for each
panel quality asked for (LIVE, the panel's default: the preview preset
without edge rays, shading 1 pixel in 4 x 4; PREVIEW: the preset as F12
renders it). Then the error of each quality's image against PREVIEW's
(Combined, the last view: relMSE and mean FLIP as tests/quality/metrics.py
computes them).
Navigation (--coarse N, default 2, the panel's Divider While Moving; 0
skips it), at the full size for each quality: "camera moved, 1/N" is a
camera edit rendered at 1/N of the size in each direction, as the live
preview renders each view while the view moves (live.NavigationSchedule);
"refine after 1/N" the full image of that view right after it (the view at
rest: a full camera edit, the coarse render's G-buffer replaced), through
the same cache. Then the coarse image's error against the full one of the
same view (Combined, enlarged to the full size by repeating pixels, as a
GPU texture drawn without filtering, and bilinearly): what the artist sees
while the view moves.
Targets (issue 12): library time <= 50 ms at 960x540; <= 200 ms with the
export for a 100k-triangle scene. Prints measured/target ratios.
"""
import argparse
import math
import os
import statistics
import sys
import time

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.join(REPO, "addon"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bpy  # noqa: E402

import vsgl_indirect  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
ap = argparse.ArgumentParser()
ap.add_argument("--triangles", type=int, default=100_000)
ap.add_argument("--size", default="960x540")
ap.add_argument("--repeat", type=int, default=5)
ap.add_argument("--quality", default="LIVE,PREVIEW", help="panel qualities to time, comma-separated")
ap.add_argument("--coarse", default="2",
                help="dividers while the view moves to time at the full size, comma-separated (0: none)")
ap.add_argument("--save-bundle", metavar="PATH",
                help="only write the room at --size with the first quality's settings as a scene bundle "
                     "(for a C driver, e.g. tools/live_edit.c) and exit")
args = ap.parse_args(argv)
W, H = (int(v) for v in args.size.lower().split("x"))

if "vsgl_indirect" not in bpy.types.Scene.bl_rna.properties:
    vsgl_indirect.register()
from vsgl_indirect import export, live, viewport  # noqa: E402


def build(triangles):
    from live_room import build_room, material
    bpy.ops.wm.read_factory_settings(use_empty=True)
    s = bpy.context.scene
    light, cam = build_room(s)
    # a grid bent into a wave: ~triangles triangles
    n = max(2, int(math.sqrt(triangles / 2)))
    verts = [(-1.5 + 3.0 * i / n, -1.0 + 2.0 * j / n, 0.6 + 0.2 * math.sin(6.0 * i / n) * math.cos(5.0 * j / n))
             for j in range(n + 1) for i in range(n + 1)]
    faces = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i)
             for j in range(n) for i in range(n)]
    me = bpy.data.meshes.new("Wave")
    me.from_pydata(verts, [], faces)
    me.materials.append(material("Gold", (0.9, 0.6, 0.2), 0.3, 1.0))
    wave = bpy.data.objects.new("Wave", me)
    s.collection.objects.link(wave)
    return light, cam, wave


def view_data(cache, w, h, scene, cam):
    """The scene data of the live preview's render of the camera's view at w x h."""
    dg = bpy.context.evaluated_depsgraph_get()
    sd = export.collect(dg, scene, require_lights=False, camera=False, mesh_cache=cache)
    dg_cam = cam.evaluated_get(dg)
    P = dg_cam.calc_matrix_camera(dg, x=w, y=h, scale_x=1.0, scale_y=1.0)
    sd.camera = live.view_camera(dg_cam.matrix_world.inverted(), P, w, h, cam.data.clip_start, cam.data.clip_end)
    sd.width, sd.height = w, h
    return sd


def edit_cost(session, cache, w, h, scene, cam, edit, quality):
    """Apply ``edit``, then export + library + encode as the live preview does."""
    edit()
    t0 = time.perf_counter()
    sd = view_data(cache, w, h, scene, cam)
    t_export = time.perf_counter() - t0
    c0 = time.process_time()
    out = viewport._render(session, sd, quality, 0, live.Job(1, None), 0.0, t_export)
    return dict(out["timings"], cpu=time.process_time() - c0, triangles=sd.triangle_count)


def enlarge(img, h, w, bilinear=False):
    """``img`` (h0, w0, 3) drawn over h x w pixels as a texture stretched over
    the region: each pixel centre samples the texture at the same relative
    place; nearest texel, or bilinear with the edges clamped."""
    import numpy as np
    h0, w0 = img.shape[:2]
    y = (np.arange(h) + 0.5) * h0 / h - 0.5
    x = (np.arange(w) + 0.5) * w0 / w - 0.5
    if not bilinear:
        yi = np.clip(np.floor(y + 0.5).astype(int), 0, h0 - 1)
        xi = np.clip(np.floor(x + 0.5).astype(int), 0, w0 - 1)
        return img[yi][:, xi]
    y0 = np.clip(np.floor(y).astype(int), 0, h0 - 1)
    x0 = np.clip(np.floor(x).astype(int), 0, w0 - 1)
    y1, x1 = np.minimum(y0 + 1, h0 - 1), np.minimum(x0 + 1, w0 - 1)
    fy = np.clip(y - y0, 0.0, 1.0)[:, None, None]
    fx = np.clip(x - x0, 0.0, 1.0)[None, :, None]
    a = img[y0][:, x0] * (1 - fx) + img[y0][:, x1] * fx
    b = img[y1][:, x0] * (1 - fx) + img[y1][:, x1] * fx
    return (a * (1 - fy) + b * fy).astype(np.float32)


def combined(w, h, scene, cam, quality):
    """The linear Combined pass the live preview renders at ``quality``."""
    from vsgl_indirect import engine
    lib = engine._binding()
    arrays = engine.scene_arrays(view_data({}, w, h, scene, cam), lib)
    ctx = lib.Context(log_level=lib.LogLevel.ERROR)
    try:
        sc = lib.Scene(ctx, **arrays)
        try:
            images, _ = lib.render(ctx, sc, live.render_settings(lib, quality, w * h), ("combined",))
        finally:
            sc.close()
    finally:
        ctx.close()
    return images["combined"]


def save_bundle(path, w, h, scene, cam, quality):
    """The room as the live preview renders it, as a scene bundle."""
    from vsgl_indirect import engine
    lib = engine._binding()
    arrays = engine.scene_arrays(view_data({}, w, h, scene, cam), lib)
    ctx = lib.Context(log_level=lib.LogLevel.ERROR)
    try:
        lib.bundle_write(ctx, path, arrays, live.render_settings(lib, quality, w * h))
    finally:
        ctx.close()


def main():
    light, cam, wave = build(args.triangles)
    scene = bpy.context.scene
    qualities = [q.strip().upper() for q in args.quality.split(",") if q.strip()]
    coarse = [int(c) for c in args.coarse.split(",") if c.strip() and int(c) > 1]
    if args.save_bundle:
        save_bundle(args.save_bundle, W, H, scene, cam, qualities[0])
        print("wrote %s (%dx%d, %s)" % (args.save_bundle, W, H, qualities[0]))
        return
    rows = []
    for quality in qualities:
        for div in (1, 2):
            w, h = live.internal_size(W, H, div)
            session = viewport._Session(0)
            cache = {}
            try:
                edit_cost(session, cache, w, h, scene, cam, lambda: None, quality)  # warm: first export, scene
                for name, edit in (
                        ("light moved", lambda: setattr(light.location, "x", light.location.x + 0.01)),
                        ("camera moved", lambda: setattr(cam.location, "x", cam.location.x + 0.01)),
                        ("geometry edit",
                         lambda: (cache.clear(), setattr(wave.location, "z", wave.location.z + 0.001)))):
                    ts = [edit_cost(session, cache, w, h, scene, cam, edit, quality) for _ in range(args.repeat)]
                    rows.append((quality, w, h, div, name, _median(ts), ts[0]["triangles"]))
                if div == 1:
                    for n in coarse:   # navigation: each view coarse, then its full image (the rest)
                        cw, ch = live.internal_size(w, h, n)
                        moving, rest = [], []
                        for _ in range(args.repeat):
                            moving.append(edit_cost(session, cache, cw, ch, scene, cam,
                                                    lambda: setattr(cam.location, "x", cam.location.x + 0.01),
                                                    quality))
                            rest.append(edit_cost(session, cache, w, h, scene, cam, lambda: None, quality))
                        rows.append((quality, cw, ch, n, "camera moved, 1/%d" % n, _median(moving),
                                     moving[0]["triangles"]))
                        rows.append((quality, w, h, 1, "refine after 1/%d" % n, _median(rest), rest[0]["triangles"]))
            finally:
                session.close()
    print("live preview, %d triangles, median of %d edits (s); machine: %d cores, load %s"
          % (rows[0][6], args.repeat, os.cpu_count(), " ".join("%.1f" % v for v in os.getloadavg())))
    print("%-8s %-10s %-14s %8s %8s %8s %8s %8s  %-26s %-37s %s"
          % ("quality", "size", "edit", "export", "scene", "render", "encode", "total", "library/50 ms, all/200 ms",
             "render = gbuffer + rsm + fit + shade", "CPU-s"))
    targets = []
    for quality, w, h, div, name, m, _ in rows:
        lib = m["scene"] + m["render"]
        total = m["export"] + lib + m["encode"]
        print("%-8s %-10s %-14s %8.3f %8.3f %8.3f %8.3f %8.3f  %-26s %-37s %.3f"
              % (quality, "%dx%d" % (w, h), name, m["export"], m["scene"], m["render"], m["encode"], total,
                 "%.2fx, %.2fx" % (lib / 0.050, total / 0.200),
                 "%.3f + %.3f + %.3f + %.3f" % (m["gbuffer"], m["rsm"], m["fit"], m["shade"]), m["cpu"]))
        if name.startswith("camera moved, 1/"):
            targets.append("%s %s %s (while the view moves, drawn at %dx%d): library %.3f s / 0.050 s = %.2f, "
                           "with export %.3f s / 0.200 s = %.2f"
                           % (quality, "%dx%d" % (w, h), name, W, H, lib, lib / 0.050, total, total / 0.200))
        elif name.startswith("refine"):
            targets.append("%s %s %s (the full image once the view rests): library %.3f s, with export %.3f s"
                           % (quality, "%dx%d" % (w, h), name, lib, total))
        elif div == 1 and name != "geometry edit":
            targets.append("%s %s %s: library %.3f s / 0.050 s = %.2f, with export %.3f s / 0.200 s = %.2f"
                           % (quality, "%dx%d" % (w, h), name, lib, lib / 0.050, total, total / 0.200))
    print("issue 12 targets, measured/target (<= 1 meets it):")
    for t in targets:
        print("  " + t)
    if any(q != "PREVIEW" for q in qualities) or coarse:
        sys.path.insert(0, os.path.join(REPO, "tests", "quality"))
        import metrics
        print("error against the preview preset's image (Combined, last view): relMSE, mean FLIP"
              + ("" if metrics.FLIP_ERROR is None else " (FLIP unavailable: %s)" % metrics.FLIP_ERROR))
        for div in (1, 2):
            w, h = live.internal_size(W, H, div)
            ref = combined(w, h, scene, cam, "PREVIEW")
            for quality in qualities:
                if quality != "PREVIEW":
                    a = combined(w, h, scene, cam, quality)
                    f = metrics.flip(a, ref)
                    print("  %-8s %dx%d: relMSE %.2e, FLIP %s"
                          % (quality, w, h, metrics.relmse(a, ref), "n/a" if f is None else "%.4f" % f))
        if coarse:
            print("while the view moves: the coarse image enlarged against the full one (same quality and view, "
                  "Combined): relMSE, mean FLIP, pixels repeated / bilinear")
            for quality in qualities:
                for div in (1, 2):     # the full size, and the panel's default Resolution Divider
                    w, h = live.internal_size(W, H, div)
                    full = combined(w, h, scene, cam, quality)
                    for n in coarse:
                        cw, ch = live.internal_size(w, h, n)
                        small = combined(cw, ch, scene, cam, quality)
                        out = []
                        for bilinear in (False, True):
                            a = enlarge(small, h, w, bilinear)
                            f = metrics.flip(a, full)
                            out.append("relMSE %.2e, FLIP %s" % (metrics.relmse(a, full),
                                                                 "n/a" if f is None else "%.4f" % f))
                        print("  %-8s %dx%d at 1/%d (%dx%d): %s / %s" % (quality, w, h, n, cw, ch, out[0], out[1]))


def _median(ts):
    return {k: statistics.median(t[k] for t in ts)
            for k in ("export", "scene", "render", "encode", "gbuffer", "rsm", "fit", "shade", "cpu")}


main()
