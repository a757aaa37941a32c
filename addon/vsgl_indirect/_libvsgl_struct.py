"""The base of the binding's ctypes structs (_libvsgl_abi.py, generated):
keyword construction with numpy arrays, enum names and Blender matrices, the
versioned ``size`` field set, ``as_dict``, a readable repr. Hand-written; the
generated module imports it."""

import ctypes

import numpy as np


def _enum(value, cls, what):
    """Accept an IntEnum member, an int or a (case-insensitive) member name."""
    if isinstance(value, str):
        try:
            return int(cls[value.upper()])
        except KeyError:
            raise ValueError("%s: unknown %s %r (one of %s)" % (
                what, cls.__name__, value, ", ".join(m.name for m in cls))) from None
    return int(value)


_MATRIX_FIELDS = {"world_from_light", "world_from_camera"}


class _Struct(ctypes.Structure):
    """Positional or keyword construction; keywords accept numpy arrays, enum
    names and Blender-style 4x4 / 3x4 matrices for the 12-float matrix
    fields. A ``size`` field (versioned structs) is set to the struct's size."""

    _enums = {}

    def __init__(self, *args, **fields):
        super().__init__(*args)
        names = [f[0] for f in self._fields_]
        if "size" in names and not args:
            self.size = ctypes.sizeof(self)
        for key, value in fields.items():
            if key not in names:
                raise TypeError("%s has no field %r (fields: %s)" % (
                    type(self).__name__, key, ", ".join(names)))
            setattr(self, key, self._convert(key, value))

    def _convert(self, key, value):
        ftype = dict(self._fields_)[key]
        if key in self._enums:
            return _enum(value, self._enums[key], key)
        if issubclass(ftype, ctypes.Array) and not isinstance(value, (bytes, str)):
            arr = np.asarray(value, dtype=np.float64)
            if key in _MATRIX_FIELDS and arr.shape in ((4, 4), (3, 4)):
                arr = arr[:3, :]
            arr = arr.reshape(-1)
            if arr.size != ftype._length_:
                raise ValueError("%s.%s needs %d values, got shape %s" % (
                    type(self).__name__, key, ftype._length_, np.shape(value)))
            return ftype(*arr.tolist())
        return value

    def as_dict(self):
        out = {}
        for name, ftype in self._fields_:
            v = getattr(self, name)
            if isinstance(v, bytes):
                v = v.decode("utf-8", "replace")
            elif isinstance(v, ctypes.Array):
                v = list(v)
            out[name] = v
        return out

    def __repr__(self):
        return "%s(%s)" % (type(self).__name__, ", ".join(
            "%s=%r" % kv for kv in self.as_dict().items()))
