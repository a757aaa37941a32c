"""ctypes binding of libvsgl, the only module of the add-on that calls the
library (with _libvsgl_abi.py, its ABI mirror generated from the headers by
tools/gen_abi.py: constants, enums, structs, prototypes; this module
re-exports all of it and adds the Pythonic layer).

Pure Python + numpy; no ``bpy`` import, so the tests can import it as a
top-level module (setup.cfg puts ``addon/vsgl_indirect`` on the path) and
the add-on as ``from . import libvsgl``.

Library lookup, first match wins:

1. ``$VSGL_LIBRARY`` (an explicit path; no fallback if it is wrong),
2. ``lib/libvsgl.so`` beside this module (where the add-on zip should ship
   it), then ``libvsgl.so`` beside this module. Caution: a ``libvsgl.so``
   in the same folder as ``libvsgl.py`` shadows it: Python's import system
   takes ``libvsgl.so`` for an extension module named ``libvsgl`` and
   ``import libvsgl`` fails. Ship it in ``lib/`` (or under another name).
3. ``../../build/libvsgl.so`` relative to this module (a dev checkout).

The library is loaded once, on first use, and every ``argtypes``/``restype``
is set at that moment. A library that lacks a bound function, or has
another major.minor version, is refused with :class:`VsglLibraryError`
naming what is wrong. See docs/python.md.
"""

import ctypes
import logging
import math
import os
import threading
import weakref
from dataclasses import dataclass

import numpy as np

__all__ = [
    "BINDING_VERSION", "VsglLibraryError", "VsglError",
    "VsglCancelledError", "library", "load_library", "find_library", "version",
    "version_string", "result_string",
    "SG", "ASG", "Context", "Scene", "render", "render_estimate", "render_settings_preset",
    "Material", "Light", "Camera", "RenderSettings",
]

_logger = logging.getLogger("vsgl_indirect.libvsgl")

# --------------------------------------------------------------------------
# Errors
# --------------------------------------------------------------------------


class VsglLibraryError(RuntimeError):
    """libvsgl could not be found or loaded, or has another major.minor."""


class VsglError(Exception):
    """A libvsgl call failed. ``code`` is the vsgl_result, ``message`` the
    context's last-error message (may be empty), ``function`` the C name."""

    def __init__(self, code, message="", function=""):
        self.code = int(code)
        self.message = message or ""
        self.function = function
        self.result_string = result_string(self.code)
        text = "%s (%d)" % (self.result_string, self.code)
        if function:
            text = "%s failed: %s" % (function, text)
        if self.message:
            text += ": " + self.message
        super().__init__(text)


class VsglCancelledError(VsglError):
    """The progress callback cancelled the call (VSGL_ERROR_CANCELLED)."""


# --------------------------------------------------------------------------
# The C ABI: constants, enums, structs, callbacks and prototypes are generated
# from the headers into _libvsgl_abi.py (tools/gen_abi.py, `make abi`) and
# re-exported here; what follows them is written by hand.
# --------------------------------------------------------------------------

# Every name of it is re-exported (*); the ones this module uses are named.
if __package__:  # the add-on package
    from ._libvsgl_struct import _enum
    from ._libvsgl_abi import *  # noqa: F401,F403
    from ._libvsgl_abi import (
        BINDING_VERSION, EXR_MAX_CHANNELS, PROTOTYPES, CosineMode, ExrCompression, ExrPixelType,
        LogLevel, NDF, Preset, Result, SharpnessEstimator, Visibility, vsgl_asg, vsgl_bundle_info,
        vsgl_bundle_options, vsgl_camera, vsgl_context_desc, vsgl_debug_vsgl, vsgl_exr_metadata,
        vsgl_exr_options, vsgl_exr_pass, vsgl_light, vsgl_log_fn, vsgl_material, vsgl_material_textures,
        vsgl_memory_estimate, vsgl_progress_fn, vsgl_reference_stats, vsgl_render_output,
        vsgl_render_settings, vsgl_render_stats, vsgl_scene_desc, vsgl_scene_info, vsgl_sg,
        vsgl_texture, vsgl_texture_slot, vsgl_vec3)
else:  # a top-level module (the tests, tools/; see the module docstring)
    from _libvsgl_struct import _enum
    from _libvsgl_abi import *  # noqa: F401,F403
    from _libvsgl_abi import (
        BINDING_VERSION, EXR_MAX_CHANNELS, PROTOTYPES, CosineMode, ExrCompression, ExrPixelType,
        LogLevel, NDF, Preset, Result, SharpnessEstimator, Visibility, vsgl_asg, vsgl_bundle_info,
        vsgl_bundle_options, vsgl_camera, vsgl_context_desc, vsgl_debug_vsgl, vsgl_exr_metadata,
        vsgl_exr_options, vsgl_exr_pass, vsgl_light, vsgl_log_fn, vsgl_material, vsgl_material_textures,
        vsgl_memory_estimate, vsgl_progress_fn, vsgl_reference_stats, vsgl_render_output,
        vsgl_render_settings, vsgl_render_stats, vsgl_scene_desc, vsgl_scene_info, vsgl_sg,
        vsgl_texture, vsgl_texture_slot, vsgl_vec3)

#: The planes of vsgl_render_output, in field order (each H x W x 3 except alpha: H x W).
PLANES = tuple(name for name, ftype in vsgl_render_output._fields_
               if ftype is ctypes.POINTER(ctypes.c_float))
#: Cycles/EXR pass names of the planes (vsgl_exr_write_render).
PLANE_PASS_NAMES = {"diffuse_light": "DiffInd", "glossy_light": "GlossInd",
                    "diffuse_color": "DiffCol", "glossy_color": "GlossCol",
                    "diffuse": "Diff", "glossy": "Gloss", "combined": "Combined",
                    "alpha": "Combined.A"}

LOG_FN = vsgl_log_fn
PROGRESS_FN = vsgl_progress_fn

_P = ctypes.POINTER
_PF32 = _P(ctypes.c_float)
_PU32 = _P(ctypes.c_uint32)

# Friendlier names for the structs users fill in.
Material = vsgl_material
Light = vsgl_light
Camera = vsgl_camera
TextureSlot = vsgl_texture_slot
MaterialTextures = vsgl_material_textures
RenderSettings = vsgl_render_settings

# --------------------------------------------------------------------------
# Loading
# --------------------------------------------------------------------------

_HERE = os.path.dirname(os.path.abspath(__file__))
_LIB_NAME = "libvsgl.so"


def find_library():
    """Path of the library to load (see the module docstring for the order).
    Raises VsglLibraryError listing what was tried if nothing is found."""
    env = os.environ.get("VSGL_LIBRARY")
    if env:
        if not os.path.isfile(env):
            raise VsglLibraryError(
                "VSGL_LIBRARY=%s: no such file. Point VSGL_LIBRARY at a built libvsgl.so "
                "(build it with `make` in the repository root, giving build/libvsgl.so) "
                "or unset it to use the bundled library." % env)
        return env
    tried = [os.path.join(_HERE, "lib", _LIB_NAME),
             os.path.join(_HERE, _LIB_NAME),
             os.path.normpath(os.path.join(_HERE, "..", "..", "build", _LIB_NAME))]
    for path in tried:
        if os.path.isfile(path):
            return path
    raise VsglLibraryError(
        "libvsgl.so not found (tried %s). Build it with `make` in the repository root "
        "(it writes build/libvsgl.so), or set VSGL_LIBRARY to its path." % ", ".join(tried))


#: sonames libvsgl links against -> (what it is, Debian/Ubuntu package).
DEPENDENCIES = {
    "libembree3.so.3": ("Intel Embree 3", "libembree3-3"),
    "libOpenEXRCore-3_1.so.30": ("OpenEXR Core 3.1", "libopenexr-3-1-30"),
    "libtbb.so.12": ("oneTBB", "libtbb12"),
    "libdeflate.so.0": ("libdeflate", "libdeflate0"),
    "libstdc++.so.6": ("the GNU C++ runtime", "libstdc++6"),
    "libz.so.1": ("zlib", "zlib1g"),
}


def load_error_message(path, error):
    """What to tell a user whose ``ctypes.CDLL(path)`` failed with ``error``:
    the missing library and the package that provides it; a zip user is not
    told to run `make`."""
    import re
    in_addon = os.path.dirname(os.path.abspath(path)) == os.path.join(_HERE, "lib")
    fix = ("reinstall the add-on from a zip built by tools/build_addon.sh, which ships it in "
           "vsgl_indirect/lib/" if in_addon else
           "or rebuild libvsgl with `make` on this machine")
    m = re.search(r"([\w.+-]+\.so[\w.]*): cannot open shared object file", error)
    if m:
        soname = m.group(1)
        what, pkg = DEPENDENCIES.get(soname, (None, None))
        if pkg:
            return ("cannot load %s: it needs %s (%s), which is not installed: install the "
                    "package %s (Debian/Ubuntu: apt-get install %s), %s"
                    % (path, soname, what, pkg, pkg, fix))
        return ("cannot load %s: it needs %s, which is not installed (install the package "
                "that provides it), %s" % (path, soname, fix))
    m = re.search(r"version `([^']+)' not found", error)
    if m:
        return ("cannot load %s: this system's libraries are too old (%s not found; the add-on "
                "zip needs x86-64 Linux with glibc >= 2.34 and libstdc++ of GCC >= 12): %s"
                % (path, m.group(1), error))
    return "cannot load %s: %s (%s)" % (path, error, fix)


class _Library:
    """A loaded libvsgl: one attribute per exported prototype, argtypes and
    restype set once here. Immutable after construction."""

    def __init__(self, path):
        self.path = os.path.abspath(path)
        try:
            self.cdll = ctypes.CDLL(self.path)
        except OSError as e:
            raise VsglLibraryError(load_error_message(self.path, str(e))) from None
        missing = []
        for name, restype, argtypes in PROTOTYPES:
            try:
                fn = getattr(self.cdll, name)
            except AttributeError:
                missing.append(name)
                continue
            fn.restype = restype
            fn.argtypes = argtypes
            self.__dict__[name] = fn
        if "vsgl_version" in missing:
            raise VsglLibraryError("%s does not export vsgl_version: not a libvsgl "
                                   "(build it with `make`)" % self.path)
        v = int(self.vsgl_version())
        self.version = (v // 10000, v // 100 % 100, v % 100)
        if self.version[:2] != BINDING_VERSION:
            raise VsglLibraryError(
                "%s is libvsgl %d.%d.%d but this add-on needs %d.%d.x; rebuild the library "
                "from the same checkout with `make` (or reinstall the add-on)"
                % ((self.path,) + self.version + BINDING_VERSION))
        if missing:
            raise VsglLibraryError(
                "%s (libvsgl %d.%d.%d) does not export %s, which this binding calls: it was built "
                "from another checkout; rebuild it with `make` (or reinstall the add-on)"
                % ((self.path,) + self.version + (", ".join(missing),)))

    def has(self, name):
        """Is ``name`` a bound function of the library (every prototype is)."""
        return name in self.__dict__


_lib = None
_lib_lock = threading.Lock()


def load_library(path=None):
    """Load a libvsgl (``path`` or :func:`find_library`) without caching it."""
    return _Library(path if path is not None else find_library())


def library():
    """The process-wide library, loaded on first use."""
    global _lib
    if _lib is None:
        with _lib_lock:
            if _lib is None:
                _lib = load_library()
    return _lib


def version():
    """(major, minor, patch) of the loaded library."""
    return library().version


def version_string():
    return library().vsgl_version_string().decode()


def result_string(code):
    try:
        return library().vsgl_result_string(int(code)).decode()
    except VsglLibraryError:
        return "result %d" % int(code)


# --------------------------------------------------------------------------
# SG / ASG
# --------------------------------------------------------------------------


def _vec3(v, name="vector"):
    a = np.asarray(v, dtype=np.float64)
    if a.shape != (3,):
        raise ValueError("%s must have 3 components, got shape %s" % (name, a.shape))
    return vsgl_vec3(float(a[0]), float(a[1]), float(a[2]))


def _tuple3(c):
    return (float(c.x), float(c.y), float(c.z))


@dataclass(frozen=True)
class SG:
    """exp(log_amplitude + sharpness * (dot(w, axis) - 1))."""

    axis: tuple
    sharpness: float
    log_amplitude: float = 0.0

    def __post_init__(self):
        a = np.asarray(self.axis, dtype=np.float64)
        if a.shape != (3,):
            raise ValueError("SG axis must have 3 components, got shape %s" % (a.shape,))
        object.__setattr__(self, "axis", tuple(float(x) for x in a))
        object.__setattr__(self, "sharpness", float(self.sharpness))
        object.__setattr__(self, "log_amplitude", float(self.log_amplitude))

    @classmethod
    def from_amplitude(cls, axis, sharpness, amplitude=1.0):
        return cls(axis, sharpness, math.log(amplitude) if amplitude > 0 else -math.inf)

    @property
    def amplitude(self):
        return math.exp(self.log_amplitude)

    def to_c(self):
        return vsgl_sg(vsgl_vec3(*self.axis), self.sharpness, self.log_amplitude)

    @classmethod
    def from_c(cls, s):
        return cls(_tuple3(s.axis), s.sharpness, s.log_amplitude)


@dataclass(frozen=True)
class ASG:
    """exp(log_amplitude) * max(v.z, 0) * exp(-lam (v.x)^2 - mu (v.y)^2)."""

    x: tuple
    y: tuple
    z: tuple
    lam: float
    mu: float
    log_amplitude: float = 0.0

    def __post_init__(self):
        for k in ("x", "y", "z"):
            a = np.asarray(getattr(self, k), dtype=np.float64)
            if a.shape != (3,):
                raise ValueError("ASG %s must have 3 components, got shape %s" % (k, a.shape))
            object.__setattr__(self, k, tuple(float(c) for c in a))
        for k in ("lam", "mu", "log_amplitude"):
            object.__setattr__(self, k, float(getattr(self, k)))

    @classmethod
    def from_frame(cls, frame, lam, mu, log_amplitude=0.0):
        """``frame``: 3x3 array whose rows are x, y, z."""
        f = np.asarray(frame, dtype=np.float64).reshape(3, 3)
        return cls(f[0], f[1], f[2], lam, mu, log_amplitude)

    @property
    def frame(self):
        return np.array([self.x, self.y, self.z])

    @property
    def amplitude(self):
        return math.exp(self.log_amplitude)

    def to_c(self):
        return vsgl_asg(vsgl_vec3(*self.x), vsgl_vec3(*self.y), vsgl_vec3(*self.z),
                        self.lam, self.mu, self.log_amplitude)

    @classmethod
    def from_c(cls, a):
        return cls(_tuple3(a.x), _tuple3(a.y), _tuple3(a.z), a.lambda_, a.mu, a.log_amplitude)


def _sg(g):
    if isinstance(g, vsgl_sg):
        return g
    if isinstance(g, SG):
        return g.to_c()
    raise TypeError("expected an SG, got %s" % type(g).__name__)


def _asg(a):
    if isinstance(a, vsgl_asg):
        return a
    if isinstance(a, ASG):
        return a.to_c()
    raise TypeError("expected an ASG, got %s" % type(a).__name__)


def _eval_dirs(fn, lobe, dirs):
    d = np.asarray(dirs, dtype=np.float64)
    if d.shape == (3,):
        return float(fn(ctypes.byref(lobe), ctypes.byref(_vec3(d, "dir"))))
    if d.ndim < 1 or d.shape[-1] != 3:
        raise ValueError("dir must have shape (3,) or (..., 3), got %s" % (d.shape,))
    flat = d.reshape(-1, 3)
    out = np.empty(len(flat))
    v = vsgl_vec3()
    ref, vref = ctypes.byref(lobe), ctypes.byref(v)
    for i, (x, y, z) in enumerate(flat.tolist()):
        v.x, v.y, v.z = x, y, z
        out[i] = fn(ref, vref)
    return out.reshape(d.shape[:-1])


def sg_eval(g, dir):
    """G(dir); ``dir`` of shape (3,) gives a float, (..., 3) an array."""
    return _eval_dirs(library().vsgl_sg_eval, _sg(g), dir)


def sg_integral(sharpness):
    """Integral over the sphere of exp(sharpness (w.xi - 1)), steradians."""
    return float(library().vsgl_sg_integral(float(sharpness)))


def sg_lobe_integral(g):
    return float(library().vsgl_sg_lobe_integral(ctypes.byref(_sg(g))))


def sg_product(a, b):
    out = vsgl_sg()
    library().vsgl_sg_product(ctypes.byref(_sg(a)), ctypes.byref(_sg(b)), ctypes.byref(out))
    return SG.from_c(out)


def sg_product_integral(a, b):
    return float(library().vsgl_sg_product_integral(ctypes.byref(_sg(a)), ctypes.byref(_sg(b))))


def sg_product_integral_iwasaki(a, b):
    return float(library().vsgl_sg_product_integral_iwasaki(ctypes.byref(_sg(a)),
                                                            ctypes.byref(_sg(b))))


def sg_cosine_sharpness():
    return float(library().vsgl_sg_cosine_sharpness())


def sg_cosine_integral(g, n, mode=CosineMode.ACCURATE):
    """Integral of G(w) max(w.n, 0); ``mode`` a CosineMode, int or name."""
    return float(library().vsgl_sg_cosine_integral(
        ctypes.byref(_sg(g)), ctypes.byref(_vec3(n, "n")), _enum(mode, CosineMode, "mode")))


def sharpness_from_mean_length(r, estimator=SharpnessEstimator.TOKSVIG):
    return float(library().vsgl_sharpness_from_mean_length(
        float(r), _enum(estimator, SharpnessEstimator, "estimator")))


def mean_length_from_sharpness(sharpness, estimator=SharpnessEstimator.TOKSVIG):
    return float(library().vsgl_mean_length_from_sharpness(
        float(sharpness), _enum(estimator, SharpnessEstimator, "estimator")))


def asg_eval(a, dir):
    """ASG(dir); ``dir`` of shape (3,) gives a float, (..., 3) an array."""
    return _eval_dirs(library().vsgl_asg_eval, _asg(a), dir)


def asg_bessel_f(a):
    """F(a) = integral_0^{2pi} exp(-a cos^2 phi) dphi."""
    return float(library().vsgl_asg_bessel_f(float(a)))


def asg_integral(a):
    return float(library().vsgl_asg_integral(ctypes.byref(_asg(a))))


def asg_integral_approx(a):
    return float(library().vsgl_asg_integral_approx(ctypes.byref(_asg(a))))


def asg_product(a, b):
    out = vsgl_asg()
    library().vsgl_asg_product(ctypes.byref(_asg(a)), ctypes.byref(_asg(b)), ctypes.byref(out))
    return ASG.from_c(out)


def asg_convolve_sg(a, kernel):
    out = vsgl_asg()
    library().vsgl_asg_convolve_sg(ctypes.byref(_asg(a)), ctypes.byref(_sg(kernel)),
                                   ctypes.byref(out))
    return ASG.from_c(out)


def asg_sg_product_integral(a, g):
    return float(library().vsgl_asg_sg_product_integral(ctypes.byref(_asg(a)),
                                                        ctypes.byref(_sg(g))))


def sg_to_asg(g):
    out = vsgl_asg()
    library().vsgl_sg_to_asg(ctypes.byref(_sg(g)), ctypes.byref(out))
    return ASG.from_c(out)


# lobes.h

def lambert_to_sg(n):
    out = vsgl_sg()
    library().vsgl_lambert_to_sg(ctypes.byref(_vec3(n, "n")), ctypes.byref(out))
    return SG.from_c(out)


def ndf_sharpness(alpha):
    return float(library().vsgl_ndf_sharpness(float(alpha)))


def ndf_to_sg(n, alpha, ndf=NDF.GGX):
    out = vsgl_sg()
    library().vsgl_ndf_to_sg(ctypes.byref(_vec3(n, "n")), float(alpha),
                             _enum(ndf, NDF, "ndf"), ctypes.byref(out))
    return SG.from_c(out)


def ndf_aniso_to_asg(n, tangent, alpha_x, alpha_y):
    out = vsgl_asg()
    library().vsgl_ndf_aniso_to_asg(ctypes.byref(_vec3(n, "n")),
                                    ctypes.byref(_vec3(tangent, "tangent")),
                                    float(alpha_x), float(alpha_y), ctypes.byref(out))
    return ASG.from_c(out)


def warp_ndf_sg(ndf, view):
    out = vsgl_sg()
    library().vsgl_warp_ndf_sg(ctypes.byref(_sg(ndf)), ctypes.byref(_vec3(view, "view")),
                               ctypes.byref(out))
    return SG.from_c(out)


def warp_ndf_asg(ndf, view):
    out = vsgl_asg()
    library().vsgl_warp_ndf_asg(ctypes.byref(_asg(ndf)), ctypes.byref(_vec3(view, "view")),
                                ctypes.byref(out))
    return ASG.from_c(out)


def specular_factor(n, view, light, alpha, f0):
    return float(library().vsgl_specular_factor(
        ctypes.byref(_vec3(n, "n")), ctypes.byref(_vec3(view, "view")),
        ctypes.byref(_vec3(light, "light")), float(alpha), float(f0)))


def ward_to_asg(n, x, alpha_x, alpha_y):
    out = vsgl_asg()
    library().vsgl_ward_to_asg(ctypes.byref(_vec3(n, "n")), ctypes.byref(_vec3(x, "x")),
                               float(alpha_x), float(alpha_y), ctypes.byref(out))
    return ASG.from_c(out)


def ashikhmin_shirley_to_asg(n, u, n_u, n_v):
    out = vsgl_asg()
    library().vsgl_ashikhmin_shirley_to_asg(ctypes.byref(_vec3(n, "n")),
                                            ctypes.byref(_vec3(u, "u")),
                                            float(n_u), float(n_v), ctypes.byref(out))
    return ASG.from_c(out)


# --------------------------------------------------------------------------
# Context
# --------------------------------------------------------------------------


def _log_trampoline(ctx_ref):
    def log(user, level, message):
        ctx = ctx_ref()
        try:
            if ctx is not None and ctx._log is not None:
                ctx._log(int(level), message.decode("utf-8", "replace") if message else "")
        except KeyboardInterrupt:
            if ctx is not None:
                ctx._interrupted = True
        except BaseException:
            _logger.exception("vsgl log callback raised (ignored)")
    return LOG_FN(log)


def _progress_trampoline(ctx_ref):
    def progress(user, stage, fraction):
        ctx = ctx_ref()
        if ctx is None:
            return 0
        if ctx._interrupted:
            return 1
        try:
            if ctx._progress is not None:
                return 1 if ctx._progress(stage.decode("utf-8", "replace") if stage else "",
                                          float(fraction)) else 0
        except KeyboardInterrupt:
            ctx._interrupted = True
            return 1
        except BaseException:
            _logger.exception("vsgl progress callback raised (ignored)")
        return 0
    return PROGRESS_FN(progress)


class _Owned:
    """A library object the Python side owns: ``handle`` (ValueError once
    closed), ``close()`` calls ``_destroy`` once; usable with ``with``;
    ``__del__`` closes too."""

    _handle = None
    _what = "object"       # for the closed-handle message
    _destroy = ""          # the library function that frees the handle

    @property
    def handle(self):
        if self._handle is None:
            raise ValueError("the vsgl %s is closed" % self._what)
        return self._handle

    def close(self):
        h, self._handle = self._handle, None
        if h is not None:
            getattr(self._lib, self._destroy)(h)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:
            pass


class Context(_Owned):
    """A vsgl_context: thread count, callbacks, last error.

    ``log(level, message)`` receives the library's log lines (levels are
    LogLevel); ``progress(stage, fraction)`` returns True to cancel. An
    exception inside a callback never reaches C: it is logged to the
    ``vsgl_indirect.libvsgl`` logger; a KeyboardInterrupt cancels the
    running call and is re-raised when it returns. Use as a context manager
    or call close(); ``__del__`` also destroys it.
    """

    _what, _destroy = "context", "vsgl_context_destroy"

    def __init__(self, thread_count=0, log=None, log_level=None, progress=None,
                 desc_size=None, max_memory=0):
        lib = library()
        self._lib = lib
        self._log, self._progress = log, progress
        self._interrupted = False
        desc = vsgl_context_desc()
        if int(thread_count) < 0:
            raise ValueError("thread_count must be >= 0 (0 = all cores), got %r" % thread_count)
        desc.thread_count = int(thread_count)
        if int(max_memory) < 0:
            raise ValueError("max_memory must be >= 0 bytes (0 = what the machine has), got %r"
                             % max_memory)
        desc.max_memory = int(max_memory)
        if log_level is not None:
            desc.log_level = _enum(log_level, LogLevel, "log_level")
        if desc_size is not None:  # for tests of the size check
            desc.size = int(desc_size)
        ref = weakref.ref(self)
        self._log_cb = _log_trampoline(ref) if log is not None else None
        self._progress_cb = _progress_trampoline(ref)  # also carries KeyboardInterrupts
        if self._log_cb is not None:
            desc.log = self._log_cb
        desc.progress = self._progress_cb
        handle = ctypes.c_void_p()
        rc = lib.vsgl_context_create(ctypes.byref(desc), ctypes.byref(handle))
        if rc != 0:
            raise VsglError(rc, "", "vsgl_context_create")
        self._handle = handle

    @property
    def last_error(self):
        """Message of the last failed call on this context ("" if none)."""
        if self._handle is None:
            return ""
        return self._lib.vsgl_context_last_error(self._handle).decode("utf-8", "replace")

    @property
    def thread_count(self):
        return int(self._lib.vsgl_context_thread_count(self.handle))

    def check(self, rc, function=""):
        """Raise for a vsgl_result (and re-raise a KeyboardInterrupt from a callback)."""
        if self._interrupted:
            self._interrupted = False
            raise KeyboardInterrupt
        if rc != 0:
            cls = VsglCancelledError if rc == Result.ERROR_CANCELLED else VsglError
            raise cls(rc, self.last_error, function)


# --------------------------------------------------------------------------
# Scene
# --------------------------------------------------------------------------


def _check_array(a, name, dtype, shapes, required=False):
    """Validate dtype, shape (one of ``shapes``) and C-contiguity; no copies."""
    if a is None:
        if required:
            raise ValueError("%s is required" % name)
        return None
    dt = np.dtype(dtype)
    if not isinstance(a, np.ndarray):
        raise TypeError("%s must be a numpy.ndarray of %s, got %s (use np.ascontiguousarray"
                        "(%s, dtype=np.%s))" % (name, dt.name, type(a).__name__, name, dt.name))
    if a.dtype != dt:
        raise TypeError("%s must have dtype %s, got %s (use np.ascontiguousarray(%s, "
                        "dtype=np.%s))" % (name, dt.name, a.dtype, name, dt.name))
    if a.shape not in shapes:
        raise ValueError("%s must have shape %s, got %s" % (
            name, " or ".join(str(s) for s in shapes), a.shape))
    if not (a.flags.c_contiguous and a.flags.aligned):
        raise ValueError("%s must be C-contiguous and aligned (use np.ascontiguousarray(%s))"
                         % (name, name))
    return a


def _ptr(a, ctype):
    return None if a is None else a.ctypes.data_as(ctypes.POINTER(ctype))


_FRIENDLY = {"vsgl_material": "Material", "vsgl_light": "Light", "vsgl_camera": "Camera",
             "vsgl_material_textures": "MaterialTextures"}


def _struct_array(items, cls, name):
    items = list(items or ())
    for i, it in enumerate(items):
        if not isinstance(it, cls):
            raise TypeError("%s[%d] must be a libvsgl.%s, got %s"
                            % (name, i, _FRIENDLY[cls.__name__], type(it).__name__))
    return (cls * len(items))(*items) if items else None


def _u32_count(n, name):
    if n > 0xFFFFFFFF:
        raise ValueError("%s: %d exceeds the uint32 limit" % (name, n))
    return n


def _texture_array(textures):
    """vsgl_texture[] from a sequence of (H,W,4) float32 arrays (rows bottom to
    top, as Blender's Image.pixels) or (array, flags) pairs; returns (array, keep)."""
    items, keep = [], []
    for i, t in enumerate(textures or ()):
        flags = 0
        if isinstance(t, tuple):
            t, flags = t
        a = np.asarray(t)
        if a.ndim != 3 or a.shape[2] != 4 or a.shape[0] < 1 or a.shape[1] < 1:
            raise ValueError("textures[%d] must have shape (height, width, 4), got %s" % (i, a.shape))
        a = np.ascontiguousarray(a, dtype=np.float32)
        keep.append(a)
        tex = vsgl_texture(width=a.shape[1], height=a.shape[0], flags=int(flags))
        tex.pixels = _ptr(a, ctypes.c_float)
        items.append(tex)
    return ((vsgl_texture * len(items))(*items) if items else None), keep


def _build_scene_desc(positions, indices, corner_normals=None, corner_uvs=None,
                      corner_tangents=None, material_indices=None, materials=(),
                      lights=(), camera=None, textures=(), material_textures=None,
                      corner_colors=None):
    """Validate numpy inputs and fill a vsgl_scene_desc. Returns (desc, keep)
    where ``keep`` holds every object the desc points into."""
    if not isinstance(positions, np.ndarray) or positions.ndim != 2:
        _check_array(positions, "positions", np.float32, [("V", 3)])
    V = positions.shape[0]
    positions = _check_array(positions, "positions", np.float32, [(V, 3)], True)
    if not isinstance(indices, np.ndarray) or indices.ndim != 2:
        _check_array(indices, "indices", np.uint32, [("T", 3)], True)
    T = indices.shape[0]
    indices = _check_array(indices, "indices", np.uint32, [(T, 3)], True)
    corner_normals = _check_array(corner_normals, "corner_normals", np.float32,
                                  [(T, 3, 3), (T, 9)])
    corner_uvs = _check_array(corner_uvs, "corner_uvs", np.float32, [(T, 3, 2), (T, 6)])
    corner_tangents = _check_array(corner_tangents, "corner_tangents", np.float32,
                                   [(T, 3, 4), (T, 12)])
    material_indices = _check_array(material_indices, "material_indices", np.uint32, [(T,)])
    corner_colors = _check_array(corner_colors, "corner_colors", np.float32, [(T, 3, 3), (T, 9)])
    mats = _struct_array(materials, vsgl_material, "materials")
    texs, tex_keep = _texture_array(textures)
    mtex = None
    if material_textures is not None:
        mtex = _struct_array(material_textures, vsgl_material_textures, "material_textures")
        if mtex is not None and len(mtex) != len(list(materials or ())):
            raise ValueError("material_textures has %d entries, materials %d (one per material)"
                             % (len(mtex), len(list(materials or ()))))
    lits = _struct_array(lights, vsgl_light, "lights")
    if camera is None:
        raise ValueError("camera is required (a libvsgl.Camera)")
    if not isinstance(camera, vsgl_camera):
        raise TypeError("camera must be a libvsgl.Camera, got %s" % type(camera).__name__)
    desc = vsgl_scene_desc(
        vertex_count=_u32_count(V, "vertex count"),
        triangle_count=_u32_count(T, "triangle count"),
        material_count=len(mats) if mats is not None else 0,
        light_count=len(lits) if lits is not None else 0)
    desc.positions = _ptr(positions, ctypes.c_float)
    desc.indices = _ptr(indices, ctypes.c_uint32)
    desc.corner_normals = _ptr(corner_normals, ctypes.c_float)
    desc.corner_uvs = _ptr(corner_uvs, ctypes.c_float)
    desc.corner_tangents = _ptr(corner_tangents, ctypes.c_float)
    desc.material_indices = _ptr(material_indices, ctypes.c_uint32)
    if mats is not None:
        desc.materials = ctypes.cast(mats, ctypes.POINTER(vsgl_material))
    if lits is not None:
        desc.lights = ctypes.cast(lits, ctypes.POINTER(vsgl_light))
    desc.camera = ctypes.pointer(camera)
    if texs is not None:
        desc.texture_count = len(texs)
        desc.textures = ctypes.cast(texs, ctypes.POINTER(vsgl_texture))
    if mtex is not None:
        desc.material_textures = ctypes.cast(mtex, ctypes.POINTER(vsgl_material_textures))
    desc.corner_colors = _ptr(corner_colors, ctypes.c_float)
    keep = (positions, indices, corner_normals, corner_uvs, corner_tangents,
            material_indices, mats, lits, camera, texs, tex_keep, mtex, corner_colors)
    return desc, keep


class Scene(_Owned):
    """A validated vsgl_scene built from numpy arrays (zero-copy: read during
    construction only).

    positions (V,3) float32; indices (T,3) uint32; optional corner_normals
    (T,3,3) float32, corner_uvs (T,3,2), corner_tangents (T,3,4),
    material_indices (T,) uint32; materials: sequence of Material; lights:
    sequence of Light; camera: Camera; textures: sequence of (H,W,4) float32
    arrays or (array, flags) pairs (TEXTURE_FLAG_SRGB); material_textures:
    one MaterialTextures per material (slot ``texture`` is 1-based) or None;
    corner_colors (T,3,3) float32. Raises TypeError/ValueError for
    bad arrays and VsglError (with the library's message) for bad content.
    """

    _what, _destroy = "scene", "vsgl_scene_destroy"

    def __init__(self, ctx, positions, indices, corner_normals=None, corner_uvs=None,
                 corner_tangents=None, material_indices=None, materials=(), lights=(),
                 camera=None, textures=(), material_textures=None, corner_colors=None):
        desc, keep = _build_scene_desc(positions, indices, corner_normals, corner_uvs,
                                       corner_tangents, material_indices, materials,
                                       lights, camera, textures, material_textures,
                                       corner_colors)
        self._ctx = ctx  # destroy the scene before its context
        self._lib = ctx._lib
        fn = self._lib.vsgl_scene_create
        handle = ctypes.c_void_p()
        rc = fn(ctx.handle, ctypes.byref(desc), ctypes.byref(handle))
        del keep
        ctx.check(rc, "vsgl_scene_create")
        self._handle = handle
        self.width, self.height = int(camera.width), int(camera.height)

    def set_view(self, camera, lights=()):
        """Replace the camera and lights, keeping geometry, materials and the
        BVH (vsgl_scene_set_view). On an error the scene is unchanged."""
        if not isinstance(camera, vsgl_camera):
            raise TypeError("camera must be a libvsgl.Camera, got %s" % type(camera).__name__)
        lits = _struct_array(lights, vsgl_light, "lights")
        n = len(lits) if lits is not None else 0
        ptr = ctypes.cast(lits, ctypes.POINTER(vsgl_light)) if n else None
        rc = self._lib.vsgl_scene_set_view(self._ctx.handle, self.handle, ctypes.byref(camera), ptr, n)
        self._ctx.check(rc, "vsgl_scene_set_view")
        self.width, self.height = int(camera.width), int(camera.height)

    def info(self):
        """Counts after validation, as a dict (bounds as 3-tuples)."""
        info = vsgl_scene_info()
        rc = self._lib.vsgl_scene_get_info(self.handle, ctypes.byref(info))
        self._ctx.check(rc, "vsgl_scene_get_info")
        d = info.as_dict()
        del d["size"]
        d["bounds_min"], d["bounds_max"] = tuple(d["bounds_min"]), tuple(d["bounds_max"])
        return d


# --------------------------------------------------------------------------
# Render
# --------------------------------------------------------------------------


def render_settings_preset(preset=Preset.BALANCED):
    out = vsgl_render_settings()
    library().vsgl_render_settings_preset(_enum(preset, Preset, "preset"), ctypes.byref(out))
    return out


def _settings(settings):
    if settings is None:
        return vsgl_render_settings()
    if isinstance(settings, vsgl_render_settings):
        return settings
    if isinstance(settings, dict):
        return vsgl_render_settings(**settings)
    raise TypeError("settings must be a RenderSettings, a dict of its fields or None")


def _stats_dict(stats):
    d = stats.as_dict()
    del d["size"]
    d["skipped"] = stats.skipped.decode("utf-8", "replace")
    d["budget"] = stats.budget.decode("utf-8", "replace")
    return d


def _output_floats(planes):
    return sum(1 if p == "alpha" else 3 for p in planes)


def render_estimate(ctx, scene, settings=None, planes=PLANES):
    """Validate ``settings`` as :func:`render` would and estimate the bytes a
    render of ``scene`` with the output ``planes`` needs. Returns the
    vsgl_memory_estimate as a dict (output, gbuffer, planes, rsm, fit,
    shade, total, limit); raises VsglError (ERROR_OUT_OF_MEMORY: the message
    names the size, the estimate and the limit) if it cannot fit."""
    est = vsgl_memory_estimate()
    rc = ctx._lib.vsgl_render_estimate(ctx.handle, scene.handle, ctypes.byref(_settings(settings)),
                                       _output_floats(planes), ctypes.byref(est))
    ctx.check(rc, "vsgl_render_estimate")
    return est.as_dict()


class RenderCache(_Owned):
    """A vsgl_render_cache: the G-buffer and VSGLs of the last render passed
    to ``render(..., cache=)``, reused while their inputs stand still. Close
    it (or use ``with``) before its context."""

    _what, _destroy = "render cache", "vsgl_render_cache_destroy"

    def __init__(self, ctx):
        self._ctx, self._lib = ctx, ctx._lib
        h = ctypes.c_void_p()
        ctx.check(self._lib.vsgl_render_cache_create(ctx.handle, ctypes.byref(h)), "vsgl_render_cache_create")
        self._handle = h


def render(ctx, scene, settings=None, planes=PLANES, cache=None):
    """Render the indirect planes of ``scene``.

    ``settings``: RenderSettings, a dict of its fields, or None (defaults).
    ``planes``: names from PLANES. ``cache``: a RenderCache (vsgl_render_cached)
    or None. Returns ``(images, stats)``: images maps each plane to a float32
    array (H, W, 3) ((H, W) for "alpha"), rows from the top; stats is a dict
    of vsgl_render_stats (``skipped`` a str).
    """
    planes = tuple(planes)
    for p in planes:
        if p not in PLANES:
            raise ValueError("unknown plane %r (one of %s)" % (p, ", ".join(PLANES)))
    s = _settings(settings)
    fn = ctx._lib.vsgl_render
    # Refused before the output arrays exist if it cannot fit.
    estimate = render_estimate(ctx, scene, s, planes) if ctx._lib.has("vsgl_render_estimate") else None
    H, W = scene.height, scene.width
    images = {p: np.zeros((H, W) if p == "alpha" else (H, W, 3), np.float32) for p in planes}
    out = vsgl_render_output(width=W, height=H)
    for p, a in images.items():
        setattr(out, p, a.ctypes.data_as(_PF32))
    stats = vsgl_render_stats()
    if cache is None:
        rc = fn(ctx.handle, scene.handle, ctypes.byref(s), ctypes.byref(out), ctypes.byref(stats))
    else:
        rc = ctx._lib.vsgl_render_cached(ctx.handle, scene.handle, ctypes.byref(s), cache.handle,
                                         ctypes.byref(out), ctypes.byref(stats))
    ctx.check(rc, "vsgl_render")
    stats = _stats_dict(stats)
    stats["memory_estimate"] = estimate
    return images, stats


# --------------------------------------------------------------------------
# Files (io.h)
# --------------------------------------------------------------------------


def _path(p):
    return os.fsencode(p)


def check_output_path(ctx, path):
    """Raise VsglError if ``path`` cannot be written by the atomic writers."""
    rc = ctx._lib.vsgl_check_output_path(ctx.handle, _path(path))
    ctx.check(rc, "vsgl_check_output_path")


def _exr_options(layer=None, pixel_type=ExrPixelType.FLOAT, compression=ExrCompression.ZIP,
                 metadata=None, zip_level=0):
    keep = []
    opt = vsgl_exr_options(pixel_type=pixel_type, compression=compression, zip_level=int(zip_level))
    if layer is not None:
        opt.layer = layer.encode()
    if metadata:
        items = [vsgl_exr_metadata(key=str(k).encode(), value=str(v).encode())
                 for k, v in dict(metadata).items()]
        arr = (vsgl_exr_metadata * len(items))(*items)
        keep.append(arr)
        opt.metadata_count = len(items)
        opt.metadata = ctypes.cast(arr, ctypes.POINTER(vsgl_exr_metadata))
    return opt, keep


def exr_write(ctx, path, passes, layer=None, pixel_type="float", compression="zip",
              metadata=None, zip_level=0):
    """Write a multilayer EXR. ``passes`` maps pass name -> float32 array of
    shape (H, W, C) with C in 1..4 (or (H, W) for one channel), or to a
    tuple (array, channels) such as (a, "RGBA"). Default channel letters:
    "V", "??", "RGB", "RGBA" for 1..4 channels (2 needs explicit names).
    ``zip_level``: deflate level 1..9 of ZIP / ZIPS, 0 = the library's default
    (EXR_ZIP_LEVEL_DEFAULT)."""
    passes = dict(passes)
    if not passes:
        raise ValueError("exr_write needs at least one pass")
    arrays, c_passes, H, W = [], [], None, None
    for name, spec in passes.items():
        arr, chans = (spec if isinstance(spec, tuple) else (spec, None))
        if not isinstance(arr, np.ndarray):
            raise TypeError("pass %s must be a numpy.ndarray of float32" % name)
        if arr.ndim == 2:
            arr = arr[:, :, None]
        if arr.ndim != 3 or not 1 <= arr.shape[2] <= EXR_MAX_CHANNELS:
            raise ValueError("pass %s must have shape (H, W) or (H, W, 1..4), got %s"
                             % (name, arr.shape))
        _check_array(arr, "pass %s" % name, np.float32, [arr.shape])
        if H is None:
            H, W = arr.shape[:2]
        elif arr.shape[:2] != (H, W):
            raise ValueError("pass %s is %dx%d, the first pass %dx%d"
                             % (name, arr.shape[1], arr.shape[0], W, H))
        C = arr.shape[2]
        if chans is None:
            chans = {1: "V", 3: "RGB", 4: "RGBA"}.get(C)
            if chans is None:
                raise ValueError("pass %s has 2 channels: give their letters, (array, 'XY')"
                                 % name)
        if len(chans) != C:
            raise ValueError("pass %s: %d channel letters for %d channels" % (name, len(chans), C))
        p = vsgl_exr_pass(name=name.encode(), channels=chans.encode())
        base = arr.ctypes.data
        for c in range(C):
            p.data[c] = ctypes.cast(base + 4 * c, _PF32)
            p.stride[c] = C
        arrays.append(arr)
        c_passes.append(p)
    parr = (vsgl_exr_pass * len(c_passes))(*c_passes)
    opt, keep = _exr_options(layer, pixel_type, compression, metadata, zip_level)
    rc = ctx._lib.vsgl_exr_write(ctx.handle, _path(path), W, H, parr, len(c_passes),
                                 ctypes.byref(opt))
    del arrays, keep
    ctx.check(rc, "vsgl_exr_write")


def exr_write_render(ctx, path, images, layer=None, pixel_type="float", compression="zip",
                     metadata=None, zip_level=0):
    """Write the planes returned by :func:`render` with the standard pass names."""
    H = W = None
    out = vsgl_render_output()
    kept = []
    for p, arr in images.items():
        if p not in PLANES:
            raise ValueError("unknown plane %r (one of %s)" % (p, ", ".join(PLANES)))
        if not isinstance(arr, np.ndarray) or arr.ndim not in (2, 3):
            raise TypeError("plane %s must be a numpy array (H, W[, 3])" % p)
        if H is None:
            H, W = arr.shape[:2]
        shape = (H, W) if p == "alpha" else (H, W, 3)
        _check_array(arr, "plane %s" % p, np.float32, [shape])
        setattr(out, p, arr.ctypes.data_as(_PF32))
        kept.append(arr)
    if H is None:
        raise ValueError("exr_write_render needs at least one plane")
    out.width, out.height = W, H
    opt, keep = _exr_options(layer, pixel_type, compression, metadata, zip_level)
    rc = ctx._lib.vsgl_exr_write_render(ctx.handle, _path(path), ctypes.byref(out),
                                        ctypes.byref(opt))
    del kept, keep
    ctx.check(rc, "vsgl_exr_write_render")


def _bundle_options(output_path=None, frame=None):
    opt = vsgl_bundle_options()
    if output_path is not None:
        opt.output_path = os.fsencode(output_path)
    if frame is not None:
        opt.has_frame, opt.frame = 1, int(frame)
    return opt


def bundle_write(ctx, path, scene_arrays, settings=None, output_path=None, frame=None):
    """Write a scene bundle. ``scene_arrays``: a dict of Scene's keyword
    arguments (positions, indices, ..., camera)."""
    desc, keep = _build_scene_desc(**scene_arrays)
    s = _settings(settings)
    opt = _bundle_options(output_path, frame)
    rc = ctx._lib.vsgl_bundle_write(ctx.handle, _path(path), ctypes.byref(desc),
                                    ctypes.byref(s), ctypes.byref(opt))
    del keep
    ctx.check(rc, "vsgl_bundle_write")


def bundle_write_memory(ctx, scene_arrays, settings=None, output_path=None, frame=None):
    """The bundle as bytes (see bundle_write)."""
    desc, keep = _build_scene_desc(**scene_arrays)
    s = _settings(settings)
    opt = _bundle_options(output_path, frame)
    fn = ctx._lib.vsgl_bundle_write_memory
    size = ctypes.c_size_t()
    rc = fn(ctx.handle, ctypes.byref(desc), ctypes.byref(s), ctypes.byref(opt), None, 0,
            ctypes.byref(size))
    ctx.check(rc, "vsgl_bundle_write_memory")
    buf = ctypes.create_string_buffer(size.value)
    rc = fn(ctx.handle, ctypes.byref(desc), ctypes.byref(s), ctypes.byref(opt), buf,
            size.value, ctypes.byref(size))
    del keep
    ctx.check(rc, "vsgl_bundle_write_memory")
    return buf.raw[:size.value]


def _copy(ptr, count, dtype, shape):
    if not ptr or count == 0:
        return None
    return np.ctypeslib.as_array(ptr, shape=(count,)).astype(dtype, copy=True).reshape(shape)


def _read_bundle(ctx, handle):
    lib = ctx._lib
    try:
        d = lib.vsgl_bundle_scene(handle).contents
        T, V = d.triangle_count, d.vertex_count
        scene = {
            "positions": _copy(d.positions, V * 3, np.float32, (V, 3)),
            "indices": _copy(d.indices, T * 3, np.uint32, (T, 3)),
            "corner_normals": _copy(d.corner_normals, T * 9, np.float32, (T, 3, 3)),
            "corner_uvs": _copy(d.corner_uvs, T * 6, np.float32, (T, 3, 2)),
            "corner_tangents": _copy(d.corner_tangents, T * 12, np.float32, (T, 3, 4)),
            "material_indices": _copy(d.material_indices, T, np.uint32, (T,)),
            "materials": [vsgl_material.from_buffer_copy(d.materials[i])
                          for i in range(d.material_count)],
            "lights": [vsgl_light.from_buffer_copy(d.lights[i]) for i in range(d.light_count)],
            "camera": vsgl_camera.from_buffer_copy(d.camera.contents) if d.camera else None,
        }
        if scene["positions"] is None:
            scene["positions"] = np.zeros((0, 3), np.float32)
        if scene["indices"] is None:
            scene["indices"] = np.zeros((0, 3), np.uint32)
        settings = vsgl_render_settings.from_buffer_copy(lib.vsgl_bundle_settings(handle).contents)
        info = vsgl_bundle_info()
        ctx.check(lib.vsgl_bundle_get_info(handle, ctypes.byref(info)), "vsgl_bundle_get_info")
        info = info.as_dict()
        del info["size"]
        return scene, settings, info
    finally:
        lib.vsgl_bundle_destroy(handle)


def bundle_read(ctx, path):
    """Read a bundle file: returns (scene_arrays, settings, info); the arrays
    are copies (scene_arrays can be passed to Scene(ctx, **scene_arrays))."""
    handle = ctypes.c_void_p()
    rc = ctx._lib.vsgl_bundle_read(ctx.handle, _path(path), ctypes.byref(handle))
    ctx.check(rc, "vsgl_bundle_read")
    return _read_bundle(ctx, handle)


def bundle_read_memory(ctx, data):
    """As bundle_read, from bytes."""
    data = bytes(data)
    handle = ctypes.c_void_p()
    rc = ctx._lib.vsgl_bundle_read_memory(ctx.handle, data, len(data), ctypes.byref(handle))
    ctx.check(rc, "vsgl_bundle_read_memory")
    return _read_bundle(ctx, handle)


# --------------------------------------------------------------------------
# Debugging (debug.h; signatures may change between minor versions)
# --------------------------------------------------------------------------


def debug_gbuffer(ctx, scene, aa=1):
    """The camera G-buffer of ``scene``: a dict with ``positions`` and
    ``normals`` float32 (H, W, aa*aa, 3) and ``materials`` uint32
    (H, W, aa*aa) (0 / 0xFFFFFFFF where a sample missed), samples ordered
    s = j*aa + i as documented in vsgl/debug.h."""
    aa = int(aa) or 1
    H, W, S = scene.height, scene.width, aa * aa
    pos = np.zeros((H, W, S, 3), np.float32)
    nrm = np.zeros((H, W, S, 3), np.float32)
    mat = np.zeros((H, W, S), np.uint32)
    rc = ctx._lib.vsgl_debug_gbuffer(ctx.handle, scene.handle, aa, pos.ctypes.data_as(_PF32),
                                     nrm.ctypes.data_as(_PF32), mat.ctypes.data_as(_PU32))
    ctx.check(rc, "vsgl_debug_gbuffer")
    return {"positions": pos, "normals": nrm, "materials": mat}


def debug_gbuffer_frames(ctx, scene, aa=1):
    """The shading frames of the same samples as :func:`debug_gbuffer`:
    ``tangents`` and ``views`` float32 (H, W, aa*aa, 3)."""
    aa = int(aa) or 1
    H, W, S = scene.height, scene.width, aa * aa
    tan = np.zeros((H, W, S, 3), np.float32)
    view = np.zeros((H, W, S, 3), np.float32)
    rc = ctx._lib.vsgl_debug_gbuffer_frames(ctx.handle, scene.handle, aa,
                                            tan.ctypes.data_as(_PF32), view.ctypes.data_as(_PF32))
    ctx.check(rc, "vsgl_debug_gbuffer_frames")
    return {"tangents": tan, "views": view}


def debug_vsgls(ctx, scene, settings=None):
    """The VSGLs :func:`render` would shade with ``settings``, as a dict of
    arrays over them: mean, axis, normal, power (N, 3) float32, variance,
    sharpness, coherence (N,) float32, light, lobe (N,) uint32 (0 diffuse,
    1 specular)."""
    s = _settings(settings)
    fn = ctx._lib.vsgl_debug_vsgls
    count = ctypes.c_size_t(0)
    ctx.check(fn(ctx.handle, scene.handle, ctypes.byref(s), ctypes.byref(count), None), "vsgl_debug_vsgls")
    items = (vsgl_debug_vsgl * max(count.value, 1))()
    ctx.check(fn(ctx.handle, scene.handle, ctypes.byref(s), ctypes.byref(count),
                 ctypes.cast(items, _P(vsgl_debug_vsgl))), "vsgl_debug_vsgls")
    n = count.value
    a = np.ctypeslib.as_array(ctypes.cast(items, _P(ctypes.c_float)), (max(n, 1) * 17,))[:n * 17].reshape(n, 17)
    u = a.view(np.uint32)
    return {"mean": a[:, 0:3].copy(), "variance": a[:, 3].copy(), "axis": a[:, 4:7].copy(),
            "sharpness": a[:, 7].copy(), "power": a[:, 8:11].copy(), "normal": a[:, 11:14].copy(),
            "coherence": a[:, 14].copy(), "light": u[:, 15].copy(), "lobe": u[:, 16].copy()}


# --------------------------------------------------------------------------
# Test-only references (reference.h; signatures may change between minors)
# --------------------------------------------------------------------------


def reference_rsm(ctx, scene, light, res):
    """The RSM of light index ``light`` at ``res`` texels per side, as a dict
    of arrays over its N texels: positions, normals, flux (N, 3) float32,
    areas (N,) float32, materials (N,) uint32 (0xFFFFFFFF where empty)."""
    fn = ctx._lib.vsgl_reference_rsm
    count = ctypes.c_size_t()
    rc = fn(ctx.handle, scene.handle, int(light), int(res), ctypes.byref(count),
            None, None, None, None, None)
    ctx.check(rc, "vsgl_reference_rsm")
    N = count.value
    out = {"positions": np.zeros((N, 3), np.float32), "normals": np.zeros((N, 3), np.float32),
           "flux": np.zeros((N, 3), np.float32), "areas": np.zeros(N, np.float32),
           "materials": np.zeros(N, np.uint32)}
    rc = fn(ctx.handle, scene.handle, int(light), int(res), ctypes.byref(count),
            out["positions"].ctypes.data_as(_PF32), out["normals"].ctypes.data_as(_PF32),
            out["flux"].ctypes.data_as(_PF32), out["areas"].ctypes.data_as(_PF32),
            out["materials"].ctypes.data_as(_PU32))
    ctx.check(rc, "vsgl_reference_rsm")
    return out


def reference_render(ctx, scene, rsm_res=256, aa=1, visibility=Visibility.NONE):
    """Brute-force one-bounce reference: (images, stats) with images the
    planes diffuse_light, glossy_light, diffuse_color, glossy_color
    (float32 (H, W, 3)) and stats a dict of vsgl_reference_stats."""
    H, W = scene.height, scene.width
    names = ("diffuse_light", "glossy_light", "diffuse_color", "glossy_color")
    images = {p: np.zeros((H, W, 3), np.float32) for p in names}
    stats = vsgl_reference_stats()
    rc = ctx._lib.vsgl_reference_render(
        ctx.handle, scene.handle, int(rsm_res), int(aa), _enum(visibility, Visibility, "visibility"),
        *[images[p].ctypes.data_as(_PF32) for p in names], ctypes.byref(stats))
    ctx.check(rc, "vsgl_reference_render")
    d = stats.as_dict()
    d["total_flux"] = tuple(d["total_flux"])
    return images, d


def reference_brdf(material, normals, tangents, wi, wo):
    """The reference's exact BRDF times the cosine, f(wi, wo) max(wi.n, 0),
    of ``material`` for N direction pairs: each argument float32 (N, 3)
    (unit normal, tangent, towards the light, towards the viewer).
    Returns (diffuse, glossy), float32 (N, 3) RGB in 1/sr."""
    if not isinstance(material, vsgl_material):
        raise TypeError("material must be a libvsgl.Material")
    n = _check_array(normals, "normals", np.float32, [(len(normals), 3)], True)
    N = n.shape[0]
    args = [n] + [_check_array(a, k, np.float32, [(N, 3)], True)
                  for a, k in ((tangents, "tangents"), (wi, "wi"), (wo, "wo"))]
    diffuse = np.zeros((N, 3), np.float32)
    glossy = np.zeros((N, 3), np.float32)
    rc = library().vsgl_reference_brdf(ctypes.byref(material), _u32_count(N, "count"),
                                       *[a.ctypes.data_as(_PF32) for a in args],
                                       diffuse.ctypes.data_as(_PF32), glossy.ctypes.data_as(_PF32))
    if rc != 0:
        raise VsglError(rc, "", "vsgl_reference_brdf")
    return diffuse, glossy
