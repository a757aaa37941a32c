"""RSM stage time and memory at 1024^2 per light on a large scene (not a test).

    /usr/bin/python3 tests/blender/bench_rsm.py [res] [threads]

Scene: a 1000 x 500 heightfield (1 M triangles) plus 2000 boxes (24 k
triangles) in 40 x 20 m; a point, a spot, a sun and an area light. Times
vsgl_reference_rsm (RSM build + copy-out of positions and flux) per light,
median of 3 (wall clock and process CPU time: the machine may be shared), \
and the RSM's memory (68 bytes per texel: position, normal,
tangent, incident direction, flux, footprint, material).
"""
import ctypes
import math
import os
import sys
import time

import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "addon", "vsgl_indirect"))
import libvsgl  # noqa: E402

res = int(sys.argv[1]) if len(sys.argv) > 1 else 1024
threads = int(sys.argv[2]) if len(sys.argv) > 2 else 0
lib = ctypes.CDLL(os.path.join(ROOT, "build", "libvsgl.so"))
P = ctypes.POINTER
vp = ctypes.c_void_p
lib.vsgl_context_create.argtypes = [P(libvsgl.vsgl_context_desc), P(vp)]
lib.vsgl_scene_create.argtypes = [vp, P(libvsgl.vsgl_scene_desc), P(vp)]
lib.vsgl_context_last_error.restype = ctypes.c_char_p
lib.vsgl_context_last_error.argtypes = [vp]
lib.vsgl_reference_rsm.argtypes = [vp, vp, ctypes.c_uint32, ctypes.c_uint32, P(ctypes.c_size_t),
                                   P(ctypes.c_float), P(ctypes.c_float), P(ctypes.c_float), P(ctypes.c_float),
                                   P(ctypes.c_uint32)]
lib.vsgl_scene_destroy.argtypes = [vp]
lib.vsgl_context_destroy.argtypes = [vp]

# heightfield
nx, ny = 1000, 500
xs, ys = np.linspace(-20, 20, nx + 1), np.linspace(-10, 10, ny + 1)
X, Y = np.meshgrid(xs, ys)
Z = 0.3 * np.sin(X * 0.7) * np.cos(Y * 0.9) + 0.1 * np.sin(3.1 * X + 2.3 * Y)
V = [np.stack([X, Y, Z], -1).reshape(-1, 3)]
i = np.arange(ny)[:, None] * (nx + 1) + np.arange(nx)[None, :]
a, b, c, d = i, i + 1, i + nx + 2, i + nx + 1
T = [np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])]
base = V[0].shape[0]
rng = np.random.default_rng(1)
cube_v = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
cube_t = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                   [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])
for k in range(2000):
    s = rng.uniform(0.2, 1.0, 3)
    o = np.array([rng.uniform(-19, 19), rng.uniform(-9, 9), 0.2])
    V.append(cube_v * s + o)
    T.append(cube_t + base)
    base += 8
V = np.concatenate(V).astype(np.float32)
T = np.concatenate(T).astype(np.uint32)
mats = (libvsgl.vsgl_material * 2)()
for m, col in zip(mats, (0.6, 0.8)):
    m.base_color[:] = (col, col, col)
    m.roughness = 0.5
    m.specular_f0 = 0.04
Mi = (np.arange(len(T)) >= 2 * nx * ny).astype(np.uint32)


def mat(loc, rx=0.0):
    c, s = math.cos(rx), math.sin(rx)
    return [1, 0, 0, loc[0], 0, c, -s, loc[1], 0, s, c, loc[2]]


lights = (libvsgl.vsgl_light * 4)()
for L in lights:
    L.color[:] = (1, 1, 1)
    L.power = 1000.0
    L.spread = math.pi
    L.size_x = L.size_y = 1.0
    L.spot_size, L.spot_blend = 1.2, 0.2
lights[0].type, lights[0].world_from_light[:] = 0, mat((0, 0, 4))
lights[1].type, lights[1].world_from_light[:] = 1, mat((5, 0, 6), 0.3)
lights[2].type, lights[2].world_from_light[:], lights[2].power = 2, mat((0, 0, 10), 0.5), 3.0
lights[3].type, lights[3].world_from_light[:] = 3, mat((-5, 2, 5))
cam = libvsgl.vsgl_camera()
cam.world_from_camera[:] = mat((0, -15, 5), 1.2)
cam.lens_mm, cam.sensor_width_mm, cam.sensor_height_mm = 35, 36, 24
cam.clip_start, cam.clip_end, cam.width, cam.height = 0.1, 1000, 64, 48
cam.pixel_aspect_x = cam.pixel_aspect_y = 1
cam.ortho_scale = 1
desc = libvsgl.vsgl_scene_desc()
desc.size = ctypes.sizeof(desc)
desc.vertex_count, desc.positions = len(V), V.ctypes.data_as(P(ctypes.c_float))
desc.triangle_count, desc.indices = len(T), T.ctypes.data_as(P(ctypes.c_uint32))
desc.material_indices = Mi.ctypes.data_as(P(ctypes.c_uint32))
desc.material_count, desc.materials = 2, ctypes.cast(mats, P(libvsgl.vsgl_material))
desc.light_count, desc.lights = 4, ctypes.cast(lights, P(libvsgl.vsgl_light))
desc.camera = ctypes.pointer(cam)
cd = libvsgl.vsgl_context_desc()
cd.size = ctypes.sizeof(cd)
cd.thread_count = threads
ctx, scene = vp(), vp()
lib.vsgl_context_create(ctypes.byref(cd), ctypes.byref(ctx))
t0 = time.time()
if lib.vsgl_scene_create(ctx, ctypes.byref(desc), ctypes.byref(scene)) != 0:
    sys.exit("scene: " + lib.vsgl_context_last_error(ctx).decode())
print("scene: %d triangles, BVH %.2f s" % (len(T), time.time() - t0))
for li, name in enumerate(("point (cube)", "spot", "sun", "area")):
    n = ctypes.c_size_t()
    lib.vsgl_reference_rsm(ctx, scene, li, res, ctypes.byref(n), None, None, None, None, None)
    Pp = np.zeros((n.value, 3), np.float32)
    F = np.zeros((n.value, 3), np.float32)
    ts, cs = [], []
    for rep in range(3):
        t0, c0 = time.perf_counter(), time.process_time()
        rc = lib.vsgl_reference_rsm(ctx, scene, li, res, ctypes.byref(n), Pp.ctypes.data_as(P(ctypes.c_float)),
                                    None, F.ctypes.data_as(P(ctypes.c_float)), None, None)
        ts.append(time.perf_counter() - t0)
        cs.append(time.process_time() - c0)
        assert rc == 0, lib.vsgl_context_last_error(ctx)
    hit = int((F.sum(1) > 0).sum())
    print("%-13s %d x %d^2 = %8d texels (%7d lit)  wall median %.3f s, CPU %.3f s (%.2f us/texel)  RSM memory %.0f MiB"
          % (name, n.value // (res * res), res, n.value, hit, sorted(ts)[1], sorted(cs)[1],
             1e6 * sorted(cs)[1] / n.value, n.value * 68 / 2**20))
lib.vsgl_scene_destroy(scene)
lib.vsgl_context_destroy(ctx)
