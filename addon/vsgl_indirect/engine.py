"""One AOV computation: SceneData (from export.py) -> libvsgl -> EXR file.

No bpy here: callable from a worker thread (the C render releases the GIL
through ctypes) and from tests. Every failure is an :class:`AovError` whose
message names the element at fault.
"""
import os
import time

import numpy as np

from .convert import ExportError

# Planes requested from the library and their EXR pass names (vsgl/io.h).
PLANES = ("diffuse_light", "glossy_light", "diffuse_color", "glossy_color",
          "diffuse", "glossy", "combined", "alpha")
PASS_NAMES = {"diffuse_light": "DiffInd", "glossy_light": "GlossInd",
              "diffuse_color": "DiffCol", "glossy_color": "GlossCol",
              "diffuse": "Diff", "glossy": "Gloss", "combined": "Combined"}
LAYER = "VSGL"

#: Test seam: a callable ``(scene_data, options) -> (planes, stats)`` used
#: instead of the C renderer (the add-on's tests use it to check wiring
#: while ``vsgl_render`` is not built). None in production.
RENDER_OVERRIDE = None


class AovError(Exception):
    """The AOV could not be computed; the message says which element or part."""


class AovCancelled(AovError):
    """The user cancelled the computation (the progress callback said so)."""

    def __init__(self, message="cancelled"):
        super().__init__(message)


def _binding():
    try:
        from . import libvsgl
    except ImportError as e:  # the binding module itself is missing
        raise AovError("the libvsgl binding is missing from the add-on: %s" % e)
    return libvsgl


def library_status():
    """(ok, message) about the C library, for the panel and reports."""
    try:
        lib = _binding().library()
    except AovError as e:
        return False, str(e)
    except Exception as e:  # VsglLibraryError and anything the loader raises
        return False, str(e)
    return True, "libvsgl %d.%d.%d (%s)" % (lib.version + (lib.path,))


def library_error():
    """'' if libvsgl loads, else why not (the loader's message)."""
    ok, msg = library_status()
    return "" if ok else msg


def can_render():
    return RENDER_OVERRIDE is not None or not library_error()


def settings_for(options, libvsgl):
    preset, knobs = options.render_settings()
    if knobs is None:
        return libvsgl.render_settings_preset(preset)
    if preset == "AUTO":  # the knobs are the auto budget's ceilings
        return libvsgl.RenderSettings(auto_target=libvsgl.AUTO_BALANCED, **knobs)
    return libvsgl.RenderSettings(**knobs)


def _material_structs(libvsgl, sd):
    return [libvsgl.Material(**m) for m in sd.materials]


def scene_arrays(sd, libvsgl):
    """Keyword arguments of ``libvsgl.Scene`` / ``libvsgl.bundle_write`` for ``sd``."""
    def opt(a, dtype):
        return None if a is None else np.ascontiguousarray(a, dtype)
    return dict(positions=np.ascontiguousarray(sd.positions, np.float32),
                indices=np.ascontiguousarray(sd.indices, np.uint32),
                corner_normals=np.ascontiguousarray(sd.corner_normals, np.float32),
                corner_uvs=opt(sd.corner_uvs, np.float32),
                corner_tangents=opt(getattr(sd, "corner_tangents", None), np.float32),
                material_indices=np.ascontiguousarray(sd.material_indices, np.uint32),
                materials=_material_structs(libvsgl, sd),
                lights=[libvsgl.Light(**l) for l in sd.lights],
                camera=libvsgl.Camera(**sd.camera),
                **_texture_arrays(sd, libvsgl))


def _texture_arrays(sd, libvsgl):
    """The textures, material texture slots and corner colours of ``sd`` (export.py)."""
    mts = getattr(sd, "material_textures", None)
    if not mts:
        return {}
    structs = []
    for mt in mts:
        kw = {slot: libvsgl.TextureSlot(**f) for slot, f in mt["slots"].items()}
        structs.append(libvsgl.MaterialTextures(flags=mt["flags"], **kw))
    cc = getattr(sd, "corner_colors", None)
    return dict(textures=list(sd.textures), material_textures=structs,
                corner_colors=None if cc is None else np.ascontiguousarray(cc, np.float32))


def render_planes(sd, options, progress=None, log=None):
    """(planes dict, stats dict). ``progress(stage, fraction)`` returns True to
    cancel; ``log(level, message)`` receives the library's warnings/errors."""
    if RENDER_OVERRIDE is not None:
        return RENDER_OVERRIDE(sd, options)
    missing = library_error()
    if missing:
        raise AovError(missing)
    libvsgl = _binding()
    try:
        ctx = libvsgl.Context(thread_count=max(int(options.threads), 0), progress=progress,
                              log=log, log_level=libvsgl.LogLevel.WARNING,
                              max_memory=options.max_memory_bytes())
    except Exception as e:
        raise AovError("cannot create a libvsgl context: %s" % e)
    try:
        try:
            scene = libvsgl.Scene(ctx, **scene_arrays(sd, libvsgl))
        except libvsgl.VsglError as e:
            raise AovError("the scene was refused: %s" % _name_elements(e.message or str(e), sd))
        try:
            planes, stats = libvsgl.render(ctx, scene, settings_for(options, libvsgl), PLANES)
        except libvsgl.VsglCancelledError:
            raise AovCancelled()
        except libvsgl.VsglError as e:
            raise AovError("render failed: %s" % _name_elements(e.message or str(e), sd))
        finally:
            scene.close()
    finally:
        ctx.close()
    return planes, stats


def _name_elements(message, sd):
    """Append Blender names to library messages that cite 'light 3', 'material 2'."""
    import re

    def sub(kind, names):
        def f(m):
            i = int(m.group(1))
            return "%s %d ('%s')" % (kind, i, names[i]) if 0 <= i < len(names) else m.group(0)
        return f
    message = re.sub(r"\blight (\d+)", sub("light", sd.light_names), message)
    message = re.sub(r"\bmaterial (\d+)", sub("material", sd.material_names), message)
    return message


def format_bytes(n):
    return "%.1f GiB" % (n / float(1 << 30)) if n >= (1 << 30) else "%.1f MiB" % (n / float(1 << 20))


def memory_summary(stats):
    """'about 1.4 GiB of 22.8 GiB' from a render's stats, '' without an estimate."""
    est = (stats or {}).get("memory_estimate")
    if not est:
        return ""
    return "about %s of %s" % (format_bytes(est["total"]), format_bytes(est["limit"]))


def check_output_path(path):
    """Create the directory and check a file can be written there; AovError naming it."""
    d = os.path.dirname(os.path.abspath(path))
    try:
        os.makedirs(d, exist_ok=True)
    except OSError as e:
        raise AovError("output path '%s': cannot create directory '%s': %s"
                       % (path, d, e.strerror or e))
    if os.path.isdir(path):
        raise AovError("output path '%s' is a directory" % path)
    probe = os.path.join(d, ".vsgl_write_test_%d" % os.getpid())
    try:
        with open(probe, "wb"):
            pass
        os.unlink(probe)
    except OSError as e:
        raise AovError("output path '%s': directory is not writable: %s"
                       % (path, e.strerror or e))


#: The library's colour passes: written only with Options.color_passes (the
#: compositor setup reads Diff and Gloss, or DiffInd and GlossInd times
#: Cycles' own colours; Diff = DiffInd x DiffCol already holds them).
COLOR_PASSES = ("DiffCol", "GlossCol")


def exr_passes(planes, color_passes=True):
    """EXR passes (name -> HxWxC float32) from library planes; without
    ``color_passes``, not DiffCol and GlossCol."""
    out = {}
    for p, name in PASS_NAMES.items():
        if p in planes and p != "combined" and (color_passes or name not in COLOR_PASSES):
            out[name] = np.asarray(planes[p], np.float32)
    if "combined" in planes:
        c = np.asarray(planes["combined"], np.float32)
        a = planes.get("alpha")
        a = np.ones(c.shape[:2], np.float32) if a is None else np.asarray(a, np.float32)
        out["Combined"] = np.ascontiguousarray(np.dstack([c, a[:, :, None]]))
    return out


def write_exr(path, planes, options, metadata=None, warnings=None):
    """Write the planes as a multilayer EXR with libvsgl's writer (atomic, chunks
    compressed in parallel); any failure is an AovError naming the path."""
    passes = exr_passes(planes, options.color_passes)
    bad = [n for n, a in passes.items() if not np.all(np.isfinite(a))]
    if bad:
        raise AovError("the AOV has non-finite values in pass(es) %s; not written" % ", ".join(bad))
    try:
        libvsgl = _binding()
        ctx = libvsgl.Context()
        try:
            libvsgl.exr_write(ctx, path, passes, layer=LAYER,
                              pixel_type="half" if options.half_float else "float",
                              metadata=metadata)
        finally:
            ctx.close()
    except OSError as e:
        raise AovError("cannot write '%s': %s" % (path, e.strerror or e))
    except Exception as e:
        raise AovError("cannot write '%s': %s" % (path, e))
    return path


class Result:
    def __init__(self):
        self.path = ""
        self.stats = {}
        self.planes = None
        self.timings = {}
        self.warnings = []
        self.summary = ""


def compute(sd, options, path, progress=None, keep_planes=False, metadata=None):
    """Render ``sd`` and write ``path``. Returns a :class:`Result`; raises AovError."""
    res = Result()
    res.warnings = list(sd.warnings)
    res.summary = sd.summary()
    check_output_path(path)
    t0 = time.perf_counter()

    def log(level, message):
        if message:
            res.warnings.append("libvsgl: %s" % _name_elements(message, sd))
    planes, stats = render_planes(sd, options, progress, log)
    t1 = time.perf_counter()
    for p in ("combined", "diffuse_light"):
        if p in planes and np.asarray(planes[p]).shape[:2] != (sd.height, sd.width):
            raise AovError("renderer returned %s of size %s, camera is %dx%d"
                           % (p, np.asarray(planes[p]).shape[:2], sd.width, sd.height))
    if progress is not None:
        progress("write", 0.0)   # the status bar says "writing", not "shade 100%"
    write_exr(path, planes, options, metadata, res.warnings)
    t2 = time.perf_counter()
    if progress is not None:
        progress("write", 1.0)
    res.path = path
    res.stats = dict(stats or {})
    res.timings = {"render": t1 - t0, "write": t2 - t1}
    if keep_planes:
        res.planes = planes
    combined = planes.get("combined")
    if combined is not None and not np.any(np.asarray(combined) > 0):
        res.warnings.append("the AOV is black everywhere (lights see nothing the camera sees?)")
    return res


__all__ = ["AovError", "AovCancelled", "ExportError", "compute", "library_status", "library_error",
           "can_render", "write_exr", "exr_passes", "RENDER_OVERRIDE"]
