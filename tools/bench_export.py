#!/usr/bin/env python3
"""make bench: the add-on's Blender export of a 1M-triangle scene (issue 12:
"Blender export at least 3x faster on a 1M-triangle scene"; the issue
measured 2.7-3.1 CPU-s before).

A grid of --sub x --sub quads (2 x sub^2 triangles, with its UV map), half
its faces flat and two material slots, a light and a camera. Times
export.collect (what a render and the viewport's first frame run) with an
empty mesh cache, the fastest of --repeat, wall and CPU seconds, and again
with the cache warm (a frame whose geometry did not change). Runs in the
pip bpy (python3 tools/bench_export.py) and in Blender
(blender -b --factory-startup --python tools/bench_export.py -- ARGS).
"""
import argparse
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "addon"))

import bpy  # noqa: E402

BASELINE_CPU = 2.7   # the figure, CPU-s (the faster end of 2.7-3.1)
TARGET = 3.0


def build(sub):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=sub + 1, y_subdivisions=sub + 1, size=4)
    grid = bpy.context.object
    me = grid.data
    for name in ("A", "B"):
        me.materials.append(bpy.data.materials.new(name))
    import numpy as np
    n = len(me.polygons)
    me.polygons.foreach_set("material_index", (np.arange(n) % 2).astype(np.int32))
    me.polygons.foreach_set("use_smooth", (np.arange(n) % 4 < 2))
    bpy.ops.object.light_add(type="POINT", location=(0, 0, 2))
    bpy.ops.object.camera_add(location=(0, -5, 3), rotation=(1.0, 0, 0))
    scene.camera = bpy.context.object
    return scene


def main(argv=None):
    if argv is None:
        # in Blender (--python) the script's own arguments follow "--"
        argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else (
            [] if "--python" in sys.argv else sys.argv[1:])
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sub", type=int, default=707, help="the grid's subdivisions per side (707: 1,002,528 triangles)")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    from vsgl_indirect import export
    scene = build(args.sub)
    dg = bpy.context.evaluated_depsgraph_get()
    best = None
    for _ in range(args.repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        sd = export.collect(dg, scene)
        cur = (time.perf_counter() - t0, time.process_time() - c0)
        best = cur if best is None or cur[1] < best[1] else best
    cache = {}
    export.collect(dg, scene, mesh_cache=cache)
    t0, c0 = time.perf_counter(), time.process_time()
    export.collect(dg, scene, mesh_cache=cache)
    warm = (time.perf_counter() - t0, time.process_time() - c0)
    print("export: Blender %s, %d triangles: %.2f s wall, %.2f CPU-s (the fastest of %d, mesh cache empty); "
          "%.1fx faster than the issue's %.1f CPU-s (target %.0fx: %s); unchanged geometry (cache warm) %.3f s"
          % (bpy.app.version_string, sd.triangle_count, best[0], best[1], args.repeat, BASELINE_CPU / best[1],
             BASELINE_CPU, TARGET, "PASS" if BASELINE_CPU / best[1] >= TARGET else "FAIL", warm[0]), flush=True)


if __name__ == "__main__":
    main()
