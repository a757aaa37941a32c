"""Texture node chains -> libvsgl texture slots (pure numpy, no ``bpy``).

The bpy glue (``export.py``) reads the nodes in front of a shader input into
a small expression tree of tuples; this module plans how the library
evaluates it and bakes what the library cannot do itself into pixels.

Expressions (``kind`` first):

- ``("const", (r, g, b, a))``: an unlinked socket or an RGB / Value node;
- ``("img", key)``: an Image Texture's Color (RGBA) output; ``key`` indexes
  the :class:`ImageRef` table;
- ``("alpha", expr)``: its Alpha output (or any expression's alpha);
- ``("vc", name)``: a Color Attribute (vertex colours; "" = the default one);
- ``("mix", blend, fac, a, b, clamp)``: MixRGB / Mix (colour);
- ``("invert", fac, c)``, ``("hsv", h, s, v, fac, c)``, ``("gamma", c, g)``,
  ``("bc", c, bright, contrast)``, ``("ramp", stops, interpolation, fac)``,
  ``("sep", channel, c)``, ``("bw", c)``, ``("math", op, a, b, clamp)``;
- ``("unsupported", reason, default)``: a node the export cannot evaluate;
  ``default`` is the socket's own unlinked value (the documented fallback).

Scalars are carried as grey RGBA (Blender's implicit float -> colour);
a colour read as a float is its luminance (Rec. 709, Blender's default
scene-linear space), as Cycles' implicit conversion.
"""
import math

import numpy as np

LUMA = np.array([0.2126, 0.7152, 0.0722], np.float32)
# libvsgl enums (vsgl/scene.h)
FILTER = {"Linear": 0, "Closest": 1, "Cubic": 0, "Smart": 0}
WRAP = {"REPEAT": 0, "EXTEND": 1, "CLIP": 2, "MIRROR": 0}
TEXTURE_FLAG_SRGB = 1
VERTEX_COLOR_FLAG = 1  # VSGL_MATERIAL_TEXTURES_VERTEX_COLOR
MISSING_COLOR = (1.0, 0.0, 1.0, 1.0)  # Cycles shows a missing image as magenta


class ImageRef:
    """One Image Texture node's lookup: the image, how it is sampled and with
    which UVs. ``pixels``: (H, W, 4) float32 rows bottom to top (Blender's
    Image.pixels), or None when the image has no data; ``srgb``: the RGB
    values are sRGB-encoded (an 8-bit image in the sRGB colour space)."""

    def __init__(self, name, pixels, srgb=False, interpolation="Linear", extension="REPEAT",
                 uv_map="", uv_transform=None, problem=""):
        self.name = name
        self.pixels = pixels
        self.srgb = bool(srgb)
        self.interpolation = interpolation
        self.extension = extension
        self.uv_map = uv_map or ""
        self.uv_transform = tuple(uv_transform) if uv_transform is not None else None
        self.problem = problem  # why it cannot be sampled by UV (then its mean is used)
        self._linear = None

    def lookup_key(self):
        """Images sampled with the same key can be baked into one texture."""
        return (self.uv_map, self.uv_transform, self.extension)

    def linear(self):
        if self._linear is None:
            if self.pixels is None:
                self._linear = np.array(MISSING_COLOR, np.float32).reshape(1, 1, 4)
            else:
                p = np.asarray(self.pixels, np.float32)
                if self.srgb:
                    p = p.copy()
                    p[..., :3] = srgb_to_linear(p[..., :3])
                self._linear = p
        return self._linear

    def mean(self):
        return self.linear().reshape(-1, 4).mean(axis=0)


def srgb_to_linear(c):
    c = np.asarray(c, np.float32)
    return np.where(c <= 0.04045, c / 12.92, np.power((np.maximum(c, 0) + 0.055) / 1.055, 2.4)).astype(np.float32)


def mapping_uv_transform(vector_type, location, rotation, scale):
    """2 x 3 UV transform (vsgl_texture_slot.uv_transform) of a Mapping node
    acting on UVs (z = 0), or None if it is not affine in (u, v) alone.
    POINT: v' = R S v + L; TEXTURE: v' = (R S)^-1 (v - L); only rotation
    about Z keeps (u, v) in the plane."""
    rx, ry, rz = rotation
    if abs(rx) > 1e-6 or abs(ry) > 1e-6:
        return None
    c, s = math.cos(rz), math.sin(rz)
    R = np.array([[c, -s], [s, c]])
    S = np.diag([scale[0], scale[1]])
    M = R @ S
    L = np.array(location[:2], np.float64)
    if vector_type == "POINT":
        A, t = M, L
    elif vector_type == "TEXTURE":
        if abs(np.linalg.det(M)) < 1e-12:
            return None
        A = np.linalg.inv(M)
        t = -A @ L
    else:
        return None
    return (float(A[0, 0]), float(A[0, 1]), float(t[0]), float(A[1, 0]), float(A[1, 1]), float(t[1]))


# --------------------------------------------------------------------------
# analysis
# --------------------------------------------------------------------------

def walk(expr):
    yield expr
    for a in expr[1:]:
        if isinstance(a, tuple) and a and isinstance(a[0], str) and a[0] in KINDS:
            yield from walk(a)


KINDS = {"const", "img", "alpha", "vc", "mix", "invert", "hsv", "gamma", "bc", "ramp", "sep", "bw",
         "math", "unsupported"}


def images_of(expr):
    return sorted({e[1] for e in walk(expr) if e[0] == "img"})


def vertex_colors_of(expr):
    return sorted({e[1] for e in walk(expr) if e[0] == "vc"})


def unsupported_of(expr):
    return [e[1] for e in walk(expr) if e[0] == "unsupported"]


# --------------------------------------------------------------------------
# evaluation (numpy, over N points)
# --------------------------------------------------------------------------

def _rgb_to_hsv(c):
    r, g, b = c[..., 0], c[..., 1], c[..., 2]
    mx = np.maximum(np.maximum(r, g), b)
    mn = np.minimum(np.minimum(r, g), b)
    d = mx - mn
    v = mx
    s = np.where(mx > 0, d / np.where(mx > 0, mx, 1), 0)
    dd = np.where(d > 0, d, 1)
    h = np.where(mx == r, (g - b) / dd, np.where(mx == g, 2.0 + (b - r) / dd, 4.0 + (r - g) / dd))
    h = np.where(d > 0, (h / 6.0) % 1.0, 0.0)
    return h, s, v


def _hsv_to_rgb(h, s, v):
    h6 = (h % 1.0) * 6.0
    i = np.floor(h6).astype(np.int64) % 6
    f = h6 - np.floor(h6)
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    choices = [(v, t, p), (q, v, p), (p, v, t), (p, q, v), (t, p, v), (v, p, q)]
    out = np.zeros(h.shape + (3,), np.float32)
    for k, (a, b, c) in enumerate(choices):
        m = i == k
        out[m, 0], out[m, 1], out[m, 2] = a[m], b[m], c[m]
    return out


def _mix(blend, f, a, b):
    f = f[..., :1]
    if blend == "MIX":
        return a * (1 - f) + b * f
    if blend == "MULTIPLY":
        return a * (1 - f + f * b)
    if blend == "ADD":
        return a + f * b
    if blend == "SUBTRACT":
        return a - f * b
    if blend == "SCREEN":
        return 1 - (1 - f + f * (1 - b)) * (1 - a)
    if blend == "DIFFERENCE":
        return a * (1 - f) + f * np.abs(a - b)
    if blend == "DARKEN":
        return a * (1 - f) + f * np.minimum(a, b)
    if blend == "LIGHTEN":
        return np.maximum(a, b * f)
    if blend == "OVERLAY":
        return np.where(a < 0.5, a * (1 - f + 2 * f * b), 1 - (1 - f + 2 * f * (1 - b)) * (1 - a))
    if blend == "DIVIDE":
        return np.where(b != 0, a * (1 - f) + f * a / np.where(b != 0, b, 1), a)
    raise ValueError(blend)


MIX_BLENDS = {"MIX", "MULTIPLY", "ADD", "SUBTRACT", "SCREEN", "DIFFERENCE", "DARKEN", "LIGHTEN",
              "OVERLAY", "DIVIDE"}
MATH_OPS = {"MULTIPLY", "ADD", "SUBTRACT", "POWER", "MINIMUM", "MAXIMUM", "DIVIDE"}


def _grey(x):
    return np.repeat(x[..., None], 4, axis=-1)


def _scalar(c):
    """A colour read as a float: its luminance."""
    return c[..., :3] @ LUMA


def _ramp(stops, interpolation, t):
    pos = np.array([p for p, _ in stops], np.float64)
    col = np.array([c for _, c in stops], np.float32)
    order = np.argsort(pos, kind="stable")
    pos, col = pos[order], col[order]
    t = np.clip(t, 0.0, 1.0)
    if interpolation == "CONSTANT":
        idx = np.clip(np.searchsorted(pos, t, side="right") - 1, 0, len(pos) - 1)
        return col[idx]
    if len(pos) == 1:
        return np.broadcast_to(col[0], t.shape + (4,)).astype(np.float32)
    j = np.clip(np.searchsorted(pos, t, side="right"), 1, len(pos) - 1)
    p0, p1 = pos[j - 1], pos[j]
    w = np.where(p1 > p0, (t - p0) / np.where(p1 > p0, p1 - p0, 1), 0.0)
    w = np.clip(w, 0.0, 1.0)
    if interpolation == "EASE":
        w = w * w * (3 - 2 * w)
    out = col[j - 1] * (1 - w[..., None]) + col[j] * w[..., None]
    below, above = t <= pos[0], t >= pos[-1]
    out[below] = col[0]
    out[above] = col[-1]
    return out.astype(np.float32)


def evaluate(expr, env, n):
    """RGBA (n, 4) float32 of ``expr`` at n points; ``env[("img", key)]`` and
    ``env[("vc", name)]`` give (n, 4) arrays (missing: mean / white)."""
    k = expr[0]
    if k == "const":
        v = expr[1]
        v = tuple(v) if isinstance(v, (tuple, list)) else (float(v),) * 3 + (1.0,)
        v = (tuple(v) + (1.0,) * 4)[:4] if len(v) >= 3 else (float(v[0]),) * 3 + (1.0,)
        return np.broadcast_to(np.array(v, np.float32), (n, 4)).copy()
    if k == "img":
        return env[("img", expr[1])]
    if k == "vc":
        return env.get(("vc", expr[1]), np.ones((n, 4), np.float32))
    if k == "alpha":
        return _grey(evaluate(expr[1], env, n)[..., 3])
    if k == "unsupported":
        return evaluate(("const", expr[2]), env, n)
    if k == "mix":
        _, blend, fac, a, b, clamp = expr
        out = _mix(blend, evaluate(fac, env, n), evaluate(a, env, n), evaluate(b, env, n))
        out[..., 3] = 1.0
        return np.clip(out, 0, 1) if clamp else out
    if k == "invert":
        f = evaluate(expr[1], env, n)[..., :1]
        c = evaluate(expr[2], env, n)
        out = c.copy()
        out[..., :3] = c[..., :3] * (1 - f) + (1 - c[..., :3]) * f
        return out
    if k == "hsv":
        _, h, s, v, fac, c = expr
        c = evaluate(c, env, n)
        hh, ss, vv = _rgb_to_hsv(c)
        hh = (hh + evaluate(h, env, n)[..., 0] + 0.5) % 1.0
        ss = np.clip(ss * evaluate(s, env, n)[..., 0], 0, 1)
        vv = vv * evaluate(v, env, n)[..., 0]
        rgb = np.maximum(_hsv_to_rgb(hh, ss, vv), 0)
        f = evaluate(fac, env, n)[..., :1]
        out = c.copy()
        out[..., :3] = c[..., :3] * (1 - f) + rgb * f
        return out
    if k == "gamma":
        c = evaluate(expr[1], env, n)
        g = evaluate(expr[2], env, n)[..., :1]
        out = c.copy()
        out[..., :3] = np.where(c[..., :3] > 0, np.power(np.maximum(c[..., :3], 0), g), c[..., :3])
        return out
    if k == "bc":
        c = evaluate(expr[1], env, n)
        bright = evaluate(expr[2], env, n)[..., :1]
        contrast = evaluate(expr[3], env, n)[..., :1]
        a = 1 + contrast
        b = bright - contrast * 0.5
        out = c.copy()
        out[..., :3] = np.maximum(a * c[..., :3] + b, 0)
        return out
    if k == "ramp":
        _, stops, interp, fac = expr
        return _ramp(stops, interp, _scalar(evaluate(fac, env, n)))
    if k == "sep":
        return _grey(evaluate(expr[2], env, n)[..., expr[1]])
    if k == "bw":
        return _grey(_scalar(evaluate(expr[1], env, n)))
    if k == "math":
        _, op, a, b, clamp = expr
        x, y = _scalar(evaluate(a, env, n)), _scalar(evaluate(b, env, n))
        with np.errstate(all="ignore"):
            r = {"MULTIPLY": lambda: x * y, "ADD": lambda: x + y, "SUBTRACT": lambda: x - y,
                 "POWER": lambda: np.where(x >= 0, np.power(np.maximum(x, 0), y), 0.0),
                 "MINIMUM": lambda: np.minimum(x, y), "MAXIMUM": lambda: np.maximum(x, y),
                 "DIVIDE": lambda: np.where(y != 0, x / np.where(y != 0, y, 1), 0.0)}[op]()
        r = np.nan_to_num(r.astype(np.float32))
        return _grey(np.clip(r, 0, 1) if clamp else r)
    raise ValueError("unknown expression kind %r" % (k,))


# --------------------------------------------------------------------------
# planning: expression -> (constant, texture pixels, flags) for one slot
# --------------------------------------------------------------------------

class SlotPlan:
    """How one material input reaches the library.

    ``constant``: the vsgl_material value (RGB for colour, float for
    scalars); ``texture``: None or a dict(pixels (H,W,4) float32 rows
    bottom to top, srgb, filter, wrap, uv_map, uv_transform, name);
    ``vertex_color``: name of the colour attribute multiplied in (base colour
    only) or None; ``warnings``: what was approximated and how."""

    def __init__(self, constant):
        self.constant = constant
        self.texture = None
        self.vertex_color = None
        self.warnings = []


def _resample(p, h, w):
    """Nearest-texel resampling of (H0, W0, 4) to (h, w, 4)."""
    H0, W0 = p.shape[:2]
    if (H0, W0) == (h, w):
        return p
    yi = np.minimum(((np.arange(h) + 0.5) * H0 / h).astype(np.int64), H0 - 1)
    xi = np.minimum(((np.arange(w) + 0.5) * W0 / w).astype(np.int64), W0 - 1)
    return p[yi][:, xi]


def _split_vertex_color(expr):
    """(rest, vc_name) if expr = rest x vertex colour (a Multiply mix of factor
    1 or the attribute alone), else (expr, None)."""
    if expr[0] == "vc":
        return ("const", (1.0, 1.0, 1.0, 1.0)), expr[1]
    if expr[0] == "mix" and expr[1] == "MULTIPLY" and expr[2][0] == "const":
        f = expr[2][1]
        f = f[0] if isinstance(f, (tuple, list)) else f
        if abs(float(f) - 1.0) < 1e-6:
            a, b = expr[3], expr[4]
            if b[0] == "vc" and not vertex_colors_of(a):
                return a, b[1]
            if a[0] == "vc" and not vertex_colors_of(b):
                return b, a[1]
    return expr, None


def plan_slot(expr, images, who, scalar=False):
    """Plan one input. ``images``: key -> ImageRef. Colour inputs return an
    RGB constant, scalar inputs a float (constant x texture channel 0)."""
    warnings = []
    for reason in unsupported_of(expr):
        warnings.append("%s: %s; its unlinked value is used there" % (who, reason))
    vc = None
    if not scalar:
        expr, vc = _split_vertex_color(expr)
    if vertex_colors_of(expr):
        warnings.append("%s: a colour attribute is used other than multiplied into the base colour; "
                        "white is assumed for it" % who)
    keys = images_of(expr)
    usable = [k for k in keys if not images[k].problem and images[k].pixels is not None]
    env = {}
    for k in keys:
        im = images[k]
        if im.pixels is None:
            warnings.append("%s: image '%s' has no pixels (missing file?); magenta is used, as Cycles "
                            "shows it" % (who, im.name))
        elif im.problem:
            warnings.append("%s: image '%s' %s; its mean colour is used" % (who, im.name, im.problem))
    # one lookup (UV map, transform, extension) per slot: the rest are averaged
    lookup = images[usable[0]].lookup_key() if usable else None
    baked = [k for k in usable if images[k].lookup_key() == lookup]
    for k in usable:
        if k not in baked:
            warnings.append("%s: image '%s' uses another UV map, mapping or extension than '%s' in the "
                            "same input; its mean colour is used" % (who, images[k].name,
                                                                     images[baked[0]].name))
    for k in keys:
        if k not in baked:
            env[("img", k)] = None  # filled with means below
    if not baked:
        for k in keys:
            env[("img", k)] = np.broadcast_to(images[k].mean(), (1, 4)).astype(np.float32)
        v = evaluate(expr, env, 1)[0]
        plan = SlotPlan(float(_scalar(v[None])[0]) if scalar else tuple(float(x) for x in v[:3]))
        plan.vertex_color = vc
        plan.warnings = warnings
        return plan
    # the identity chain on one image: hand the pixels over as they are (sRGB flag)
    first = images[baked[0]]
    if expr == ("img", baked[0]) and not scalar:
        plan = SlotPlan((1.0, 1.0, 1.0))
        plan.texture = dict(pixels=first.pixels, srgb=first.srgb, name=first.name,
                            filter=FILTER.get(first.interpolation, 0), wrap=WRAP.get(first.extension, 0),
                            uv_map=first.uv_map, uv_transform=first.uv_transform, channel=0)
        plan.vertex_color = vc
        plan.warnings = warnings
        return plan
    h = max(images[k].linear().shape[0] for k in baked)
    w = max(images[k].linear().shape[1] for k in baked)
    n = h * w
    for k in keys:
        if k in baked:
            env[("img", k)] = _resample(images[k].linear(), h, w).reshape(n, 4)
        else:
            env[("img", k)] = np.broadcast_to(images[k].mean(), (n, 4)).astype(np.float32)
    out = evaluate(expr, env, n).reshape(h, w, 4).astype(np.float32)
    if scalar:
        out = _grey(_scalar(out)).astype(np.float32)
    plan = SlotPlan(1.0 if scalar else (1.0, 1.0, 1.0))
    closest = all(images[k].interpolation == "Closest" for k in baked)
    plan.texture = dict(pixels=np.ascontiguousarray(out), srgb=False,
                        name="+".join(images[k].name for k in baked),
                        filter=FILTER["Closest"] if closest else FILTER["Linear"],
                        wrap=WRAP.get(first.extension, 0), uv_map=first.uv_map,
                        uv_transform=first.uv_transform, channel=0)
    plan.vertex_color = vc
    plan.warnings = warnings
    return plan
