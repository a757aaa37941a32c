"""Minimal multilayer OpenEXR writer in pure Python + numpy (no bpy, no ctypes).

Used when the C library's EXR writer (``vsgl_exr_write`` through
``libvsgl.py``) is not available. Writes a single-part, scanline,
uncompressed file whose channels are named ``Layer.Pass.Channel`` (for
example ``VSGL.DiffInd.R``), which Blender loads as a MULTILAYER image with
one Image-node socket per pass.
"""
import os
import struct

import numpy as np

_MAGIC = 20000630
_HALF, _FLOAT = 1, 2


def _attr(name, type_name, payload):
    return (name.encode() + b"\0" + type_name.encode() + b"\0"
            + struct.pack("<i", len(payload)) + payload)


def channel_names(layer, planes):
    """Channel names for ``planes`` (dict pass name -> HxWxC array)."""
    names = {}
    for pass_name, arr in planes.items():
        c = arr.shape[2] if arr.ndim == 3 else 1
        comps = {1: "V", 3: "RGB", 4: "RGBA"}.get(c)
        if comps is None:
            raise ValueError("pass %r: %d channels (1, 3 or 4 expected)" % (pass_name, c))
        if c == 1:
            comps = ["V"]
        for i, comp in enumerate(comps):
            prefix = "%s.%s" % (layer, pass_name) if layer else pass_name
            names["%s.%s" % (prefix, comp)] = (pass_name, i)
    return names


def write_multilayer_exr(path, planes, layer="VSGL", half=False):
    """Write ``planes`` (dict pass -> float array HxW, HxWx1, HxWx3 or HxWx4,
    rows top to bottom) to ``path`` atomically (temp file + rename).
    Raises OSError if the file cannot be written, ValueError on bad input."""
    if not planes:
        raise ValueError("no planes to write")
    shapes = {a.shape[:2] for a in planes.values()}
    if len(shapes) != 1:
        raise ValueError("planes differ in size: %s" % sorted(shapes))
    (h, w), = shapes
    if w <= 0 or h <= 0:
        raise ValueError("empty image %dx%d" % (w, h))
    chans = channel_names(layer, planes)
    order = sorted(chans)  # OpenEXR requires channels sorted by name
    ptype = _HALF if half else _FLOAT
    dtype = np.dtype("<f2") if half else np.dtype("<f4")

    chlist = b""
    for n in order:
        chlist += n.encode() + b"\0" + struct.pack("<iB3xii", ptype, 0, 1, 1)
    chlist += b"\0"
    box = struct.pack("<iiii", 0, 0, w - 1, h - 1)
    header = (struct.pack("<ii", _MAGIC, 2)
              + _attr("channels", "chlist", chlist)
              + _attr("compression", "compression", b"\0")
              + _attr("dataWindow", "box2i", box)
              + _attr("displayWindow", "box2i", box)
              + _attr("lineOrder", "lineOrder", b"\0")
              + _attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + _attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + _attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + b"\0")

    # One scanline per chunk: y, byte count, then each channel's row.
    cols = []
    for n in order:
        pass_name, i = chans[n]
        a = np.asarray(planes[pass_name])
        a = a[:, :, i] if a.ndim == 3 else a
        cols.append(np.ascontiguousarray(a, dtype=dtype))
    data = np.stack(cols, axis=1)  # h x nchan x w
    row_bytes = data.shape[1] * w * dtype.itemsize
    chunk = 8 + row_bytes
    table_start = len(header)
    first = table_start + 8 * h
    offsets = np.arange(h, dtype="<u8") * chunk + first
    body = np.empty((h, chunk), dtype=np.uint8)
    prefix = np.zeros((h, 2), dtype="<i4")
    prefix[:, 0] = np.arange(h)
    prefix[:, 1] = row_bytes
    body[:, :8] = prefix.view(np.uint8).reshape(h, 8)
    body[:, 8:] = data.reshape(h, -1).view(np.uint8).reshape(h, row_bytes)

    d = os.path.dirname(os.path.abspath(path))
    os.makedirs(d, exist_ok=True)
    tmp = "%s.tmp%d" % (path, os.getpid())
    try:
        with open(tmp, "wb") as f:
            f.write(header)
            f.write(offsets.tobytes())
            f.write(body.tobytes())
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path
