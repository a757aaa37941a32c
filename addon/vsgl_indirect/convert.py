"""Pure conversions (no ``bpy``): transforms, lights, camera, output paths.

The bpy glue passes plain values (tuples, floats, strings) read from
Blender; these functions produce the field dicts of ``vsgl_light`` and
``vsgl_camera`` (csrc/include/vsgl/scene.h) and flat numpy arrays.
"""
import math
import os
import re

import numpy as np

LIGHT_TYPES = {"POINT": 0, "SPOT": 1, "SUN": 2, "AREA": 3}
AREA_SHAPES = {"SQUARE": 0, "RECTANGLE": 1, "DISK": 2, "ELLIPSE": 3}
SENSOR_FITS = {"AUTO": 0, "HORIZONTAL": 1, "VERTICAL": 2}
CAMERA_TYPES = {"PERSP": 0, "ORTHO": 1}


class ExportError(Exception):
    """A scene that cannot be exported; the message names the element."""


def matrix_3x4(m):
    """Rows 0..2 of a 4x4 matrix (Blender ``matrix_world``) as 12 float32."""
    a = np.asarray(m, dtype=np.float64).reshape(4, 4)
    return a[:3, :].astype(np.float32).reshape(12)


def without_scale(m):
    """4x4 matrix with unit-length rotation columns (Blender renders cameras unscaled)."""
    a = np.array(m, dtype=np.float64).reshape(4, 4)
    for c in range(3):
        n = np.linalg.norm(a[:3, c])
        if n > 0:
            a[:3, c] /= n
    return a


def transform_points(m, p):
    """world = M[:3,:3] @ p + M[:3,3] for an (N,3) array; float32 out."""
    a = np.asarray(m, dtype=np.float64).reshape(4, 4)
    return (np.asarray(p, np.float64) @ a[:3, :3].T + a[:3, 3]).astype(np.float32)


def transform_normals(m, n):
    """Normals by the inverse transpose of M[:3,:3], renormalised; float32 out."""
    a = np.asarray(m, dtype=np.float64).reshape(4, 4)[:3, :3]
    try:
        nm = np.linalg.inv(a).T
    except np.linalg.LinAlgError:
        nm = a
    out = np.asarray(n, np.float64) @ nm.T
    ln = np.linalg.norm(out, axis=1, keepdims=True)
    ln[ln == 0] = 1.0
    return (out / ln).astype(np.float32)


LIGHT_FLAG_BLENDER_4 = 1  # vsgl_light.flags (vsgl/scene.h)


def light_power(energy, color, exposure=0.0, blackbody=(1.0, 1.0, 1.0)):
    """(rgb, power): Cycles strength = colour x energy x 2^exposure (x blackbody)."""
    rgb = tuple(float(c) * float(b) for c, b in zip(color[:3], blackbody[:3]))
    return rgb, float(energy) * (2.0 ** float(exposure))


def light_fields(name, ltype, matrix_world, energy, color, exposure=0.0,
                 blackbody=(1.0, 1.0, 1.0), radius=0.0, spot_size=math.pi / 4,
                 spot_blend=0.15, sun_angle=0.0, shape="SQUARE", size=1.0, size_y=1.0,
                 spread=math.pi, blender_version=(3, 4, 0)):
    """``vsgl_light`` fields for a Blender light. Raises ExportError naming it.

    Spot and area lights follow ``blender_version``'s Cycles (4.x and later:
    a spot has no extra cos(theta) and its cone scales with the object, an
    area light of P watts emits P watts; docs/units.md)."""
    if ltype not in LIGHT_TYPES:
        raise ExportError("light '%s': unsupported light type %s" % (name, ltype))
    rgb, power = light_power(energy, color, exposure, blackbody)
    vals = [power, radius, spot_size, spot_blend, sun_angle, size, size_y, spread] + list(rgb)
    if not all(math.isfinite(v) for v in vals):
        raise ExportError("light '%s': non-finite parameter" % name)
    f = dict(type=LIGHT_TYPES[ltype], area_shape=0, color=rgb, power=power,
             world_from_light=matrix_3x4(matrix_world), radius=max(float(radius), 0.0),
             spot_size=0.0, spot_blend=0.0, sun_angle=0.0, size_x=0.0, size_y=0.0,
             spread=0.0, flags=LIGHT_FLAG_BLENDER_4 if tuple(blender_version) >= (4, 0, 0) else 0)
    if ltype == "SPOT":
        f["spot_size"] = float(spot_size)
        f["spot_blend"] = min(max(float(spot_blend), 0.0), 1.0)
    elif ltype == "SUN":
        f["sun_angle"] = float(sun_angle)
        f["radius"] = 0.0
    elif ltype == "AREA":
        if shape not in AREA_SHAPES:
            raise ExportError("light '%s': unsupported area shape %s" % (name, shape))
        f["area_shape"] = AREA_SHAPES[shape]
        f["size_x"] = float(size)
        f["size_y"] = float(size_y) if shape in ("RECTANGLE", "ELLIPSE") else float(size)
        f["spread"] = float(spread)
        f["radius"] = 0.0
    return f


def render_size(res_x, res_y, percentage):
    """Final pixel size as Blender computes it: floor(res * pct / 100), at least 1."""
    return (max(int(res_x * percentage / 100), 1), max(int(res_y * percentage / 100), 1))


def camera_fields(name, ctype, matrix_world, lens, sensor_width, sensor_height,
                  sensor_fit, ortho_scale, shift_x, shift_y, clip_start, clip_end,
                  width, height, pixel_aspect_x=1.0, pixel_aspect_y=1.0):
    """``vsgl_camera`` fields. Raises ExportError naming the camera."""
    if ctype not in CAMERA_TYPES:
        raise ExportError("camera '%s': %s cameras are not supported (perspective or "
                          "orthographic only)" % (name, ctype))
    if sensor_fit not in SENSOR_FITS:
        raise ExportError("camera '%s': unknown sensor fit %s" % (name, sensor_fit))
    return dict(type=CAMERA_TYPES[ctype], sensor_fit=SENSOR_FITS[sensor_fit],
                world_from_camera=matrix_3x4(without_scale(matrix_world)),
                lens_mm=float(lens), sensor_width_mm=float(sensor_width),
                sensor_height_mm=float(sensor_height), ortho_scale=float(ortho_scale),
                shift_x=float(shift_x), shift_y=float(shift_y),
                clip_start=float(clip_start), clip_end=float(clip_end),
                width=int(width), height=int(height),
                pixel_aspect_x=float(pixel_aspect_x), pixel_aspect_y=float(pixel_aspect_y))


_HASHES = re.compile(r"#+")


def frame_path(template, frame, scene="Scene", view_layer="ViewLayer", render_dir=""):
    """Expand an output path template for one frame.

    ``{scene}``, ``{view_layer}``, ``{render_dir}`` are replaced (names made
    file-safe); the last run of ``#`` becomes the zero-padded frame (Blender's
    rule); without ``#`` the frame is appended as ``_0001`` before the
    extension, so every frame gets its own file. ``.exr`` is appended if
    missing.
    """
    def safe(s):
        return re.sub(r"[^A-Za-z0-9_.-]+", "_", s) or "_"
    p = template.replace("{scene}", safe(scene)).replace("{view_layer}", safe(view_layer))
    p = p.replace("{render_dir}", render_dir.rstrip("/\\") if render_dir else ".")
    p = re.sub(r"(?<!^)/{2,}", "/", p) if not p.startswith("//") else "//" + re.sub(r"/{2,}", "/", p[2:])
    root, ext = os.path.splitext(p)
    if ext.lower() != ".exr":
        root, ext = p, ".exr"
    runs = list(_HASHES.finditer(root))
    if runs:
        r = runs[-1]
        n = len(r.group(0))
        num = ("-%0*d" % (n - 1, -frame)) if frame < 0 else "%0*d" % (n, frame)
        root = root[:r.start()] + num + root[r.end():]
    else:
        root = "%s_%04d" % (root, frame)
    return root + ext
