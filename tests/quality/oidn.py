"""Intel Open Image Denoise 2.x through ctypes (the library the PyPI `bpy` wheel ships).

Debian's Blender 3.4 has no OIDN; the pip `bpy` module (5.x) carries
libOpenImageDenoise.so.2 in its lib/ folder. `denoise(color, albedo,
normal)` runs its "RT" filter (HDR colour, optional albedo and normal
guides) as Blender's denoiser does, and returns the image and the seconds
taken: device creation, filter commit (weights) and execution, i.e. what a
render waits for. $VSGL_OIDN_LIB overrides the library's path.
"""
import ctypes
import importlib.util
import os
import time

import numpy as np

_CPU = 1            # OIDN_DEVICE_TYPE_CPU
_FLOAT3 = 3         # OIDN_FORMAT_FLOAT3
QUALITY = {"default": 0, "fast": 4, "balanced": 5, "high": 6}
_lib = None


def library_path():
    p = os.environ.get("VSGL_OIDN_LIB")
    if p:
        return p
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        return None
    for d in spec.submodule_search_locations:
        cand = os.path.join(d, "lib", "libOpenImageDenoise.so.2")
        if os.path.exists(cand):
            return cand
    return None


def load():
    """The ctypes library (raises RuntimeError when it cannot be found or loaded)."""
    global _lib
    if _lib is not None:
        return _lib
    p = library_path()
    if p is None:
        raise RuntimeError("OIDN not found: no pip bpy with lib/libOpenImageDenoise.so.2 and no $VSGL_OIDN_LIB")
    lib = ctypes.CDLL(p)
    vp, cp, sz = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t
    lib.oidnNewDevice.argtypes, lib.oidnNewDevice.restype = [ctypes.c_int], vp
    lib.oidnSetDeviceInt.argtypes, lib.oidnSetDeviceInt.restype = [vp, cp, ctypes.c_int], None
    lib.oidnCommitDevice.argtypes, lib.oidnCommitDevice.restype = [vp], None
    lib.oidnGetDeviceError.argtypes, lib.oidnGetDeviceError.restype = [vp, ctypes.POINTER(cp)], ctypes.c_int
    lib.oidnNewFilter.argtypes, lib.oidnNewFilter.restype = [vp, cp], vp
    lib.oidnSetSharedFilterImage.argtypes = [vp, cp, vp, ctypes.c_int, sz, sz, sz, sz, sz]
    lib.oidnSetSharedFilterImage.restype = None
    lib.oidnSetFilterBool.argtypes, lib.oidnSetFilterBool.restype = [vp, cp, ctypes.c_bool], None
    lib.oidnSetFilterInt.argtypes, lib.oidnSetFilterInt.restype = [vp, cp, ctypes.c_int], None
    for f in ("oidnCommitFilter", "oidnExecuteFilter", "oidnReleaseFilter", "oidnReleaseDevice"):
        getattr(lib, f).argtypes, getattr(lib, f).restype = [vp], None
    _lib = lib
    return lib


def _check(lib, dev, what):
    msg = ctypes.c_char_p()
    err = lib.oidnGetDeviceError(dev, ctypes.byref(msg))
    if err:
        raise RuntimeError("OIDN %s: error %d: %s" % (what, err, (msg.value or b"").decode()))


def denoise(color, albedo=None, normal=None, quality="high", threads=0):
    """(denoised (H, W, 3) float32, seconds). color: linear HDR RGB;
    albedo in [0, 1]; normal: unit vectors (any space); guides are taken as
    noise-free (cleanAux: pixel-centre guides from one camera ray)."""
    lib = load()
    color = np.ascontiguousarray(color, np.float32)
    h, w = color.shape[:2]
    out = np.zeros_like(color)
    bufs = {"color": color, "output": out}
    if albedo is not None:
        bufs["albedo"] = np.ascontiguousarray(np.clip(albedo, 0.0, 1.0), np.float32)
        if normal is not None:  # OIDN takes a normal guide only with an albedo guide
            bufs["normal"] = np.ascontiguousarray(normal, np.float32)
    t0 = time.perf_counter()
    dev = lib.oidnNewDevice(_CPU)
    try:
        if threads:
            lib.oidnSetDeviceInt(dev, b"numThreads", int(threads))
        lib.oidnCommitDevice(dev)
        _check(lib, dev, "device")
        flt = lib.oidnNewFilter(dev, b"RT")
        try:
            for name, a in bufs.items():
                lib.oidnSetSharedFilterImage(flt, name.encode(), a.ctypes.data, _FLOAT3, w, h, 0, 12, 12 * w)
            lib.oidnSetFilterBool(flt, b"hdr", True)
            if "albedo" in bufs:
                lib.oidnSetFilterBool(flt, b"cleanAux", True)
            lib.oidnSetFilterInt(flt, b"quality", QUALITY[quality])
            lib.oidnCommitFilter(flt)
            lib.oidnExecuteFilter(flt)
            _check(lib, dev, "filter")
        finally:
            lib.oidnReleaseFilter(flt)
    finally:
        lib.oidnReleaseDevice(dev)
    return out, time.perf_counter() - t0
