"""Evaluated Blender scene -> flat numpy arrays for ``vsgl_scene_desc``.

Two halves: ``collect()`` reads bpy (depsgraph instances, evaluated meshes,
lights, camera, materials) into plain values; ``assemble()`` (no bpy) turns
mesh chunks into world-space arrays. No per-vertex Python loops: every
array comes from ``foreach_get`` and numpy.
"""
import math

import numpy as np

from . import convert, materials, textures
from .convert import ExportError

MESH_TYPES = {"MESH", "CURVE", "SURFACE", "META", "FONT"}
HOLDOUT_KEY = "<holdout>"
DEFAULT_KEY = "<default>"


class SceneData:
    """Flat arrays and tables ready for the binding; names for messages."""

    def __init__(self):
        self.positions = np.zeros((0, 3), np.float32)
        self.indices = np.zeros((0, 3), np.uint32)
        self.corner_normals = np.zeros((0, 3, 3), np.float32)
        self.corner_uvs = None
        self.corner_tangents = None  # (T,3,4) float32 when a material is anisotropic
        self.corner_colors = None    # (T,3,3) float32 when a material multiplies a colour attribute
        self.textures = []           # (pixels (H,W,4) float32, flags) for libvsgl
        self.material_textures = None  # one dict per material (slot -> field dict) or None
        self.material_indices = np.zeros(0, np.uint32)
        self.materials = []        # vsgl_material field dicts
        self.material_names = []
        self.lights = []           # vsgl_light field dicts
        self.light_names = []
        self.camera = None         # vsgl_camera field dict
        self.camera_name = ""
        self.warnings = []
        self.emissive_log = []     # info lines: emissive meshes turned into lights
        self.object_names = []     # one per exported mesh instance
        self.instance_count = 0    # instances among them
        self.width = self.height = 0

    @property
    def triangle_count(self):
        return int(self.indices.shape[0])

    def summary(self):
        emissive = sum(1 for n in self.light_names if n.startswith("emission of"))
        return ("%d triangles, %d objects (%d instances), %d materials, %d lights%s, camera '%s' %dx%d"
                % (self.triangle_count, len(self.object_names), self.instance_count,
                   len(self.materials), len(self.lights),
                   (" (%d from emissive faces)" % emissive) if emissive else "",
                   self.camera_name, self.width, self.height))


# --------------------------------------------------------------------------
# Pure assembly
# --------------------------------------------------------------------------

class MeshArrays:
    """Local-space arrays of one evaluated mesh (shared by its instances)."""

    def __init__(self, positions, tri_verts, tri_loops, loop_normals, loop_uvs, tri_material):
        self.positions = positions        # (V,3) float32
        self.tri_verts = tri_verts        # (T,3) int
        self.tri_loops = tri_loops        # (T,3) int
        self.loop_normals = loop_normals  # (L,3) float32
        self.loop_uvs = loop_uvs          # (L,2) float32 or None: the default (active render) UV map
        self.uv_layers = {}               # name -> (L,2) float32: every UV map
        self.loop_colors = {}             # colour attribute name ("" = default) -> (L,3) float32 linear
        self.tri_material = tri_material  # (T,) int: slot index
        self.slots = []                   # material per slot (bpy materials)
        self.texspace = None              # (location, size) of the texture space; None = bounds
        self.undeformed = None            # (V,3) undeformed coordinates (generated); None = positions
        # Flat-shaded triangles: Cycles shades them with the triangle's own
        # normal, not the polygon's (they differ on non-planar quads)
        self.tri_flat = None              # (T,) bool or None (all smooth)
        self.flat_normals = None          # (F,3) float64 unit local geometric normals of the F tri_flat ones


def _texspace(arr):
    """(location, size) float64 of ``arr``'s texture space: the mesh's own,
    else Blender's automatic one (bounding box centre and half extent, a zero
    extent counting as 1)."""
    if arr.texspace is not None:
        loc, size = arr.texspace
        return np.asarray(loc, np.float64), np.asarray(size, np.float64)
    p = arr.positions.astype(np.float64)
    lo, hi = (p.min(0), p.max(0)) if len(p) else (np.zeros(3), np.zeros(3))
    size = (hi - lo) / 2.0
    return (lo + hi) / 2.0, np.where(size == 0, 1.0, size)


def default_tangents_local(arr):
    """Cycles' tangent for an unlinked Tangent socket (graph.cpp connects a
    Tangent node, radial, axis Z), per vertex, object space, unnormalised:
    ``(-g.y, g.x, 0)`` with ``g`` = generated coordinates - 0.5 =
    ``(co - texspace_location) / (2 texspace_size)`` (a zero size gives 0, as
    Cycles' mesh_texture_space). ``co`` is the undeformed coordinate (the
    mesh without deform modifiers, as Cycles' generated attribute) when the
    evaluated mesh has it, else the position."""
    loc, size = _texspace(arr)
    f = np.divide(0.5, size, out=np.zeros(3), where=size != 0)
    co = arr.undeformed if arr.undeformed is not None else arr.positions
    g = (co.astype(np.float64) - loc) * f
    return np.stack([-g[:, 1], g[:, 0], np.zeros(len(g))], -1)


def _cofactor(A):
    """Cofactor matrices of (k,3,3) ``A``: det(A) inv(A)^T where A is invertible,
    and still the normal transform where it is not (a scale of 0 along an axis
    maps the faces across that axis to faces with normals along it)."""
    c0, c1, c2 = A[:, :, 0], A[:, :, 1], A[:, :, 2]
    return np.stack([np.cross(c1, c2), np.cross(c2, c0), np.cross(c0, c1)], axis=2)


def degenerate_mask(positions, indices, corner_normals=None):
    """Triangles libvsgl would drop: zero area (in the float32 positions it is
    given, computed in double as the library does) or a corner normal of
    (near) zero length (as vsgl_scene_create; corner_normals None: none is)."""
    cx, cy, cz = _triangle_cross(positions, indices)
    area2 = cx * cx + cy * cy + cz * cz
    bad = ~(area2 > 0) | ~np.isfinite(area2)
    if corner_normals is not None:
        n = np.asarray(corner_normals, np.float32).astype(np.float64)
        bad |= ~np.all(np.einsum("tci,tci->tc", n, n) > 1e-20, axis=1)
    return bad


def _triangle_cross(positions, indices):
    """The cross product (e1 x e2 per coordinate, float64) of each
    triangle's edges from its first corner, its corners' float32 positions
    taken to double first (as the library's face_normal). A coordinate at
    a time: contiguous arrays, 2-4x faster than rows of three."""
    P = np.asarray(positions, np.float32)
    idx = np.asarray(indices, np.int64)
    i0, i1, i2 = idx[:, 0], idx[:, 1], idx[:, 2]
    e1, e2 = [], []
    for a in range(3):
        col = P[:, a].astype(np.float64)
        x0 = col[i0]
        e1.append(col[i1] - x0)
        e2.append(col[i2] - x0)
    return (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])


def _unit32(v):
    """(v / |v| as float32, |v| == 0 or NaN) of float64 vectors v (..., 3);
    a zero vector stays zero."""
    length = np.sqrt(np.einsum("...i,...i->...", v, v))
    zero = ~(length > 0)
    length[zero] = 1.0
    return (v / length[..., None]).astype(np.float32), zero


def _rows(a, idx):
    """a[idx] for row indices idx (any shape): np.take, several times faster
    than fancy indexing on arrays of a million rows."""
    return np.take(a, idx, axis=0)


def _per_instance(a, idx):
    """(k, n, ...) a and (k, ...) row indices -> a[i][idx[i]] for each i."""
    if a.shape[0] == 1:
        return _rows(a[0], idx[0])[None]
    return a[np.arange(a.shape[0]).reshape((-1,) + (1,) * (idx.ndim - 1)), idx]


def _corner_values(out, gm, tl, layer_of):
    """Fill ``out`` (k, T, 3, C) with per-loop values through the triangles'
    loops ``tl`` (k, T, 3): for the triangles of global material g (``gm``,
    (k, T)), the (L, C) array ``layer_of(g)`` (None: left as it is). One
    gather per distinct array, whichever materials share it."""
    by_layer = {}   # id(array) -> (array, its materials)
    for g in np.unique(gm):
        layer = layer_of(int(g))
        if layer is not None:
            by_layer.setdefault(id(layer), (layer, []))[1].append(g)
    for layer, gs in by_layer.values():
        m = np.isin(gm, gs)
        if m.all():
            out[:] = _rows(layer, tl)
        else:
            out[m] = layer[tl[m]]
    return out


def assemble(chunks, want_uvs=False, want_tangents=False, dropped=None, uv_map_of=None, color_of=None):
    """Concatenate ``chunks`` = [(MeshArrays, matrix 4x4, slot_to_global list)]
    into world-space (positions, indices, corner_normals, corner_uvs,
    material_indices) and, with ``want_tangents``, a sixth item
    corner_tangents (T,3,4): Cycles' default tangent
    (:func:`default_tangents_local`) through the normal matrix, unnormalised,
    bitangent sign 1. Instances of one MeshArrays are transformed together
    (one batched numpy op per mesh, not per instance). Mirrored instances
    (det < 0) get their winding flipped so geometric normals keep facing
    the same way as in Blender; normals and tangents use the inverse
    transpose (the cofactor matrix where the matrix is singular) and follow
    the flipped corner order.

    ``uv_map_of(g)`` names the UV map the triangles of global material ``g``
    take their UVs from ("" or None: the mesh's default one); with
    ``color_of(g)`` (a colour attribute name or None), a last item
    corner_colors (T,3,3) is returned: that attribute's corner colours, white
    where the material has none.

    Degenerate triangles (:func:`degenerate_mask`: zero area or zero-length
    normal, e.g. an object scaled (1, 1, 0) or (0, 0, 0)) are left out; with
    a dict ``dropped``, ``dropped[i] = (n_dropped, n_triangles)`` for every
    chunk ``i`` that lost some.
    """
    groups, order = {}, []
    for ci, (arr, matrix, slot_map) in enumerate(chunks):
        if arr.tri_verts.shape[0] == 0:
            continue
        g = groups.get(id(arr))
        if g is None:
            g = groups[id(arr)] = (arr, [], [], [])
            order.append(id(arr))
        g[1].append(np.asarray(matrix, np.float64).reshape(4, 4))
        g[2].append(list(slot_map) if len(slot_map) else [0])
        g[3].append(ci)
    pos, idx, nrm, uvs, mats, tan, cols = [], [], [], [], [], [], []
    base = 0
    for key in order:
        arr, ms, smaps, chunk_ids = groups[key]
        M = np.stack(ms)                       # (k, 4, 4)
        k, V, T = len(ms), arr.positions.shape[0], arr.tri_verts.shape[0]
        A, t = M[:, :3, :3], M[:, :3, 3]
        p = np.matmul(arr.positions.astype(np.float64)[None], A.transpose(0, 2, 1)) + t[:, None, :]
        det = np.linalg.det(A)
        flip = det < 0
        tv = np.broadcast_to(arr.tri_verts.astype(np.int64), (k, T, 3))
        tl = np.broadcast_to(arr.tri_loops.astype(np.int64), (k, T, 3))
        if flip.any():
            tv, tl = tv.copy(), tl.copy()
            tv[flip] = tv[flip][:, :, [0, 2, 1]]
            tl[flip] = tl[flip][:, :, [0, 2, 1]]
        nm = _cofactor(A)
        ok = np.abs(det) > 1e-30
        if ok.any():
            nm[ok] = np.linalg.inv(A[ok]).transpose(0, 2, 1)
        # normals per loop (a mesh has fewer loops than triangle corners),
        # transformed and normalised there, then gathered to the corners
        fi = np.nonzero(arr.tri_flat)[0] if arr.tri_flat is not None else None
        if fi is None or len(fi) < T:
            n32l, zero_l = _unit32(np.matmul(arr.loop_normals.astype(np.float64)[None],
                                             nm.transpose(0, 2, 1)))                    # (k, L, 3)
            n32 = _per_instance(n32l, tl)                                               # (k, T, 3, 3)
            zero = _per_instance(zero_l, tl)
        if fi is not None:
            g32, gz = _unit32(np.matmul(arr.flat_normals[None], nm.transpose(0, 2, 1)))  # (k, F, 3)
            if len(fi) == T:  # a flat-shaded mesh (Blender's default): every corner its face's
                n32 = np.repeat(g32[:, :, None, :], 3, axis=2)
                zero = np.repeat(gz[:, :, None], 3, axis=2)
            else:
                n32[:, fi] = g32[:, :, None, :]
                zero[:, fi] = gz[:, :, None]
        p32 = p.reshape(-1, 3).astype(np.float32)
        tri = (tv + (np.arange(k) * V)[:, None, None]).reshape(-1, 3)
        n32 = n32.reshape(-1, 3, 3)
        # the corner normals are unit vectors here but where zero says (NaN included)
        bad = degenerate_mask(p32, tri) | zero.reshape(-1, 3).any(axis=1)
        keep = ~bad
        if dropped is not None:
            per = bad.reshape(k, T).sum(axis=1)
            for j in np.nonzero(per)[0]:
                dropped[chunk_ids[j]] = (int(per[j]), T)
        pos.append(p32)
        idx.append((tri[keep] + base).astype(np.uint32))
        nrm.append(n32[keep])
        if want_tangents:
            tw = np.einsum("kij,vj->kvi", nm, default_tangents_local(arr))     # (k, V, 3)
            tc = _per_instance(tw, tv)                                           # (k, T, 3, 3)
            t4 = np.ones((k, T, 3, 4), np.float32)
            t4[..., :3] = tc
            tan.append(t4.reshape(-1, 3, 4)[keep])
        width = max(len(sm) for sm in smaps)
        table = np.array([sm + [sm[-1]] * (width - len(sm)) for sm in smaps], np.uint32)
        slot = np.clip(arr.tri_material, 0, None)[None, :]
        last = np.array([len(sm) - 1 for sm in smaps])[:, None]
        gm = table[np.arange(k)[:, None], np.minimum(slot, last)]                 # (k, T)
        if want_uvs:
            def uv_layer(g):
                name = uv_map_of(g) if uv_map_of else ""
                layer = arr.uv_layers.get(name) if name else None
                return arr.loop_uvs if layer is None and not (name and arr.uv_layers) else layer
            uv = _corner_values(np.zeros((k, T, 3, 2), np.float32), gm, tl, uv_layer)
            uvs.append(uv.reshape(-1, 3, 2)[keep])
        if color_of is not None:
            def color_layer(g):
                name = color_of(g)
                return arr.loop_colors.get(name) if name is not None else None
            col = _corner_values(np.ones((k, T, 3, 3), np.float32), gm, tl, color_layer)
            cols.append(col.reshape(-1, 3, 3)[keep])
        mats.append(gm.reshape(-1)[keep])
        base += k * V
    if not idx:
        out = (np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32),
               np.zeros((0, 3, 3), np.float32), None, np.zeros(0, np.uint32))
        out = out + (np.zeros((0, 3, 4), np.float32),) if want_tangents else out
        return out + (np.zeros((0, 3, 3), np.float32),) if color_of is not None else out
    out = (np.concatenate(pos), np.concatenate(idx), np.concatenate(nrm),
           np.concatenate(uvs) if want_uvs else None, np.concatenate(mats).astype(np.uint32))
    out = out + (np.concatenate(tan),) if want_tangents else out
    return out + (np.concatenate(cols),) if color_of is not None else out


# --------------------------------------------------------------------------
# bpy glue
# --------------------------------------------------------------------------

def _color_layer(mesh, name):
    """(L,3) float32 linear corner colours of colour attribute ``name`` ("" =
    the default / render one), or None."""
    attrs = getattr(mesh, "color_attributes", None)
    layer = None
    if attrs is not None and len(attrs):
        if name:
            layer = attrs.get(name)
        else:
            for prop in ("default_color_name", "active_color_name"):
                n = getattr(mesh.attributes, prop, None) if hasattr(mesh, "attributes") else None
                if n:
                    layer = attrs.get(n)
                    break
            if layer is None:
                idx = getattr(attrs, "render_color_index", -1)
                layer = attrs[idx] if 0 <= idx < len(attrs) else attrs[0]
    elif getattr(mesh, "vertex_colors", None) is not None and len(mesh.vertex_colors):
        layer = mesh.vertex_colors.get(name) if name else mesh.vertex_colors.active
    if layer is None:
        return None
    n = len(layer.data)
    buf = np.empty(n * 4, np.float32)
    layer.data.foreach_get("color", buf)
    c = buf.reshape(n, 4)[:, :3]
    if getattr(layer, "domain", "CORNER") == "POINT":
        lv = np.empty(len(mesh.loops), np.int32)
        mesh.loops.foreach_get("vertex_index", lv)
        c = c[lv]
    return np.ascontiguousarray(c)


def _foreach_u32(coll, prop, n):
    """``coll.foreach_get(prop)`` of a non-negative integer property as int32."""
    a = np.empty(n, np.uint32)
    coll.foreach_get(prop, a)
    return a.view(np.int32)


def _triangle_faces(mesh, lt, nt):
    """The face of each loop triangle (4.0+: the mesh's own array, read in one go)."""
    tri_faces = getattr(mesh, "loop_triangle_polygons", None)
    if tri_faces is not None:
        a = np.empty(nt, np.int32)
        tri_faces.foreach_get("value", a)
        return a
    return _foreach_u32(lt, "polygon_index", nt)


# Blender 4.1+ keeps these as generic attributes, read in one go (1M
# triangles: 0.05-0.15 s each through the face and UV collections). Older
# versions: the collections.
def _attributes(compat):
    return tuple(compat.VERSION) >= (4, 1, 0)


def _attribute(mesh, compat, name, domain, prop, dtype, n, width=1):
    """Generic attribute ``name`` of ``domain`` as an (n[, width]) array, or None."""
    attr = mesh.attributes.get(name) if _attributes(compat) else None
    if attr is None or attr.domain != domain:
        return None
    a = np.empty(n * width, dtype)
    attr.data.foreach_get(prop, a)
    return a.reshape(n, width) if width > 1 else a


def _face_material(mesh, compat):
    """Per face: its material slot."""
    n = len(mesh.polygons)
    if _attributes(compat):
        a = _attribute(mesh, compat, "material_index", "FACE", "value", np.int32, n)
        return a if a is not None else np.zeros(n, np.int32)  # no attribute: every face slot 0
    return _foreach_u32(mesh.polygons, "material_index", n)


def _face_smooth(mesh, compat):
    """Per face: is it smooth-shaded?"""
    n = len(mesh.polygons)
    if _attributes(compat):
        a = _attribute(mesh, compat, "sharp_face", "FACE", "value", bool, n)
        return ~a if a is not None else np.ones(n, bool)      # no attribute: every face smooth
    a = np.empty(n, bool)
    mesh.polygons.foreach_get("use_smooth", a)
    return a


def _uv_layer(mesh, compat, layer):
    """(n_loops, 2) float32 UVs of UV map ``layer``."""
    n = len(mesh.loops)
    a = _attribute(mesh, compat, layer.name, "CORNER", "vector", np.float32, n, 2)
    if a is None:
        a = np.empty(n * 2, np.float32)
        layer.data.foreach_get("uv", a)
        a = a.reshape(n, 2)
    return a


def _mesh_arrays(mesh, compat, want_undeformed=False, color_names=()):
    mesh.calc_loop_triangles()
    lt = mesh.loop_triangles
    nt, nv = len(lt), len(mesh.vertices)
    pos = np.empty(nv * 3, np.float32)
    mesh.vertices.foreach_get("co", pos)
    # Unsigned buffers: Blender stores these indices unsigned, and
    # foreach_get copies an array whose type matches in one go but converts
    # any other element by element (1M triangles: the triangles' loops
    # 0.14-0.28 s as int32, 0.002-0.04 s as uint32). Material and smoothness
    # per face, then per triangle through its face: cheaper than per triangle.
    tl = _foreach_u32(lt, "loops", nt * 3)
    corner_vert = _attribute(mesh, compat, ".corner_vert", "CORNER", "value", np.int32, len(mesh.loops))
    tv = _rows(corner_vert, tl) if corner_vert is not None else _foreach_u32(lt, "vertices", nt * 3)
    face = _triangle_faces(mesh, lt, nt)
    mi = _face_material(mesh, compat)[face]
    smooth = _face_smooth(mesh, compat)[face] if nt else np.zeros(0, bool)
    # a flat-shaded mesh (Blender's default) takes its face normals at every
    # corner (assemble): its corner normals are not read (3.4: 0.17 s per 1M
    # triangles through calc_normals_split and the loops)
    ln = compat.corner_normals(mesh) if smooth.any() else np.zeros((len(mesh.loops), 3), np.float32)
    uv = None
    layers = {}
    if len(mesh.uv_layers) and nt:
        for layer in mesh.uv_layers:
            layers[layer.name] = _uv_layer(mesh, compat, layer)
        # Cycles' default UVs (an Image Texture without a Vector link) are the
        # active *render* UV map
        default = next((l_.name for l_ in mesh.uv_layers if getattr(l_, "active_render", False)), None)
        if default is None and mesh.uv_layers.active is not None:
            default = mesh.uv_layers.active.name
        uv = layers.get(default)
    arr = MeshArrays(pos.reshape(nv, 3), tv.reshape(nt, 3), tl.reshape(nt, 3), ln, uv, mi)
    arr.uv_layers = layers
    for name in color_names:
        if nt:
            c = _color_layer(mesh, name)
            if c is not None:
                arr.loop_colors[name] = c
    if nt and not smooth.all():
        cand = np.nonzero(~smooth)[0]                                       # flat-shaded faces' triangles
        gn = np.stack(_triangle_cross(arr.positions, arr.tri_verts[cand]), axis=1)   # (F,3)
        length = np.linalg.norm(gn, axis=1, keepdims=True)
        # zero-area ones keep a zero normal: assemble drops them (as the library would for their area)
        length[length == 0] = 1.0
        arr.tri_flat = ~smooth
        arr.flat_normals = gn / length
    # Cycles' generated coordinates: the evaluated mesh's texture space (Blender
    # gives it the original mesh's, also under modifiers) and undeformed
    # coordinates (the ORCO layer a render depsgraph carries through to_mesh;
    # without it undeformed_co is the position).
    arr.texspace = (tuple(mesh.texspace_location), tuple(mesh.texspace_size))
    if want_undeformed and nv:
        und = np.empty(nv * 3, np.float32)
        try:
            mesh.vertices.foreach_get("undeformed_co", und)
        except (AttributeError, TypeError, RuntimeError):
            und = None
        if und is not None:
            und = und.reshape(nv, 3)
            if not np.array_equal(und, arr.positions):
                arr.undeformed = und
    return arr


def _socket_value(s):
    v = getattr(s, "default_value", None)
    if v is None:
        return None
    try:
        return tuple(float(x) for x in v)
    except TypeError:
        try:
            return float(v)
        except (TypeError, ValueError):
            return None


# --------------------------------------------------------------------------
# texture node chains (bpy glue; the evaluation is textures.py)
# --------------------------------------------------------------------------

_image_pixels_cache = {}   # one export's images (cleared by collect)


def _image_pixels(img):
    """(H, W, 4) float32 of a bpy image, rows bottom to top, or None."""
    key = (img.as_pointer(), img.name_full, getattr(img, "filepath", ""), tuple(img.size))
    if key in _image_pixels_cache:
        return _image_pixels_cache[key]
    px = None
    try:
        w, h = int(img.size[0]), int(img.size[1])
        if w > 0 and h > 0:
            buf = np.empty(w * h * 4, np.float32)
            img.pixels.foreach_get(buf)
            px = buf.reshape(h, w, 4)
    except (RuntimeError, ValueError, TypeError):
        px = None
    if len(_image_pixels_cache) > 64:
        _image_pixels_cache.clear()
    _image_pixels_cache[key] = px
    return px


def _socket_default(sock):
    v = _socket_value(sock)
    if v is None:
        return (0.0, 0.0, 0.0, 1.0)
    return v


def _find_socket(coll, identifier, name=None):
    for s in coll:
        if s.identifier == identifier:
            return s
    return coll.get(name) if name else None


class _ExprBuilder:
    """Reads the nodes in front of a socket into textures.py expressions."""

    def __init__(self, mat_name):
        self.mat = mat_name
        self.images = {}   # key -> textures.ImageRef
        self.warnings = []

    def socket(self, sock, depth=0):
        if not sock.is_linked:
            return ("const", _socket_default(sock))
        if depth > 48:
            return ("unsupported", "node chain too deep", _socket_default(sock))
        link = sock.links[0]
        if not getattr(link, "is_valid", True) or getattr(link, "is_muted", False):
            return ("const", _socket_default(sock))
        out = link.from_socket
        node = link.from_node
        while node.bl_idname == "NodeReroute":
            if not node.inputs[0].is_linked:
                return ("const", _socket_default(sock))
            l2 = node.inputs[0].links[0]
            out, node = l2.from_socket, l2.from_node
        return self.node(node, out, sock, depth + 1)

    def node(self, node, out, target, depth):
        t = node.bl_idname
        inp = node.inputs
        S = lambda name: self.socket(inp[name], depth)  # noqa: E731
        default = _socket_default(target)
        if node.mute:
            return ("unsupported", "node '%s' is muted" % node.name, default)
        if t == "ShaderNodeTexImage":
            key = self.image(node, depth)
            if key is None:
                return ("unsupported", "Image Texture '%s' has no image" % node.name, default)
            return ("alpha", ("img", key)) if out.name == "Alpha" else ("img", key)
        if t in ("ShaderNodeVertexColor",):
            e = ("vc", getattr(node, "layer_name", "") or "")
            return ("alpha", e) if out.name == "Alpha" else e
        if t == "ShaderNodeAttribute" and getattr(node, "attribute_type", "GEOMETRY") == "GEOMETRY":
            e = ("vc", node.attribute_name or "")
            return ("alpha", e) if out.name == "Alpha" else e
        if t == "ShaderNodeRGB":
            return ("const", tuple(out.default_value))
        if t == "ShaderNodeValue":
            v = float(out.default_value)
            return ("const", (v, v, v, 1.0))
        if t == "ShaderNodeMixRGB":
            if node.blend_type not in textures.MIX_BLENDS:
                return ("unsupported", "Mix node '%s' blend %s is not evaluated" % (node.name, node.blend_type),
                        default)
            return ("mix", node.blend_type, S("Fac"), S("Color1"), S("Color2"), bool(node.use_clamp))
        if t == "ShaderNodeMix":
            dt = getattr(node, "data_type", "RGBA")
            if dt not in ("RGBA", "FLOAT") or node.blend_type not in textures.MIX_BLENDS or \
                    getattr(node, "factor_mode", "UNIFORM") != "UNIFORM":
                return ("unsupported", "Mix node '%s' (%s, %s) is not evaluated" % (node.name, dt, node.blend_type),
                        default)
            suf = "Color" if dt == "RGBA" else "Float"
            fac = self.socket(_find_socket(inp, "Factor_Float", "Factor"), depth)
            a = self.socket(_find_socket(inp, "A_" + suf, "A"), depth)
            b = self.socket(_find_socket(inp, "B_" + suf, "B"), depth)
            blend = node.blend_type if dt == "RGBA" else "MIX"
            clamp = bool(getattr(node, "clamp_result", False)) or (dt == "FLOAT" and False)
            return ("mix", blend, fac, a, b, clamp)
        if t == "ShaderNodeInvert":
            return ("invert", S("Fac"), S("Color"))
        if t == "ShaderNodeHueSaturation":
            return ("hsv", S("Hue"), S("Saturation"), S("Value"), S("Fac"), S("Color"))
        if t == "ShaderNodeGamma":
            return ("gamma", S("Color"), S("Gamma"))
        if t == "ShaderNodeBrightContrast":
            return ("bc", S("Color"), S("Bright"), S("Contrast"))
        if t == "ShaderNodeValToRGB":
            ramp = node.color_ramp
            stops = tuple((float(e.position), tuple(float(c) for c in e.color)) for e in ramp.elements)
            interp = ramp.interpolation
            if interp not in ("LINEAR", "CONSTANT", "EASE"):
                self.warnings.append("material '%s': Color Ramp '%s' interpolation %s is evaluated as linear"
                                     % (self.mat, node.name, interp))
                interp = "LINEAR"
            if getattr(ramp, "color_mode", "RGB") != "RGB":
                self.warnings.append("material '%s': Color Ramp '%s' colour mode %s is evaluated in RGB"
                                     % (self.mat, node.name, ramp.color_mode))
            e = ("ramp", stops, interp, S("Fac"))
            return ("alpha", e) if out.name == "Alpha" else e
        if t in ("ShaderNodeSeparateRGB", "ShaderNodeSeparateColor"):
            if getattr(node, "mode", "RGB") != "RGB":
                return ("unsupported", "Separate Color '%s' in %s mode" % (node.name, node.mode), default)
            ch = {"R": 0, "G": 1, "B": 2, "Red": 0, "Green": 1, "Blue": 2}.get(out.name)
            if ch is None:
                return ("unsupported", "Separate node '%s' output %s" % (node.name, out.name), default)
            c = self.socket(_find_socket(inp, "Image", "Image") or _find_socket(inp, "Color", "Color"), depth)
            return ("sep", ch, c)
        if t == "ShaderNodeRGBToBW":
            return ("bw", S("Color"))
        if t == "ShaderNodeMath" and node.operation in textures.MATH_OPS:
            return ("math", node.operation, self.socket(inp[0], depth), self.socket(inp[1], depth),
                    bool(node.use_clamp))
        return ("unsupported", "node '%s' (%s) is not evaluated" % (node.name, t), default)

    def uv_source(self, node, depth):
        """(uv_map, uv_transform, problem) of an Image Texture's Vector input."""
        sock = node.inputs.get("Vector")
        if sock is None or not sock.is_linked:
            return "", None, ""
        transform = None
        link = sock.links[0]
        src, out = link.from_node, link.from_socket
        while src.bl_idname == "NodeReroute" and src.inputs[0].is_linked:
            l2 = src.inputs[0].links[0]
            src, out = l2.from_node, l2.from_socket
        if src.bl_idname == "ShaderNodeMapping":
            vt = src.vector_type
            vals = {}
            for name in ("Location", "Rotation", "Scale"):
                s_ = src.inputs.get(name)
                if s_ is not None and s_.is_linked:
                    return "", None, "has a linked Mapping input"
                vals[name] = tuple(s_.default_value) if s_ is not None else None
            if vals["Location"] is None:  # Blender 2.8x-style properties
                vals = {"Location": tuple(src.translation), "Rotation": tuple(src.rotation),
                        "Scale": tuple(src.scale)}
            transform = textures.mapping_uv_transform(vt, vals["Location"], vals["Rotation"], vals["Scale"])
            if transform is None:
                return "", None, "has a Mapping node that is not a 2-D transform of the UVs"
            vin = src.inputs.get("Vector")
            if vin is None or not vin.is_linked:
                return "", None, "has a Mapping node without UV input (generated coordinates)"
            link = vin.links[0]
            src, out = link.from_node, link.from_socket
        if src.bl_idname == "ShaderNodeUVMap":
            return src.uv_map or "", transform, ""
        if src.bl_idname == "ShaderNodeTexCoord" and out.name == "UV":
            return "", transform, ""
        return "", None, "is looked up with '%s' coordinates, not UVs" % (
            out.name if src.bl_idname == "ShaderNodeTexCoord" else src.bl_idname)

    def image(self, node, depth):
        img = node.image
        if img is None:
            return None
        uv_map, transform, problem = self.uv_source(node, depth)
        if getattr(node, "projection", "FLAT") != "FLAT":
            problem = problem or "uses %s projection" % node.projection
        if getattr(img, "source", "FILE") == "TILED":
            problem = problem or "is a UDIM tile set"
        cs = getattr(img.colorspace_settings, "name", "sRGB")
        is_float = bool(getattr(img, "is_float", False))
        srgb = (not is_float) and cs == "sRGB"
        if cs not in ("sRGB", "Non-Color", "Linear", "Linear Rec.709", "Raw", "Linear CIE-XYZ E", "XYZ"):
            self.warnings.append("material '%s': image '%s' colour space '%s' is read as %s"
                                 % (self.mat, img.name, cs, "linear" if is_float else "sRGB"))
            srgb = not is_float
        key = "%s|%s|%s|%s|%s|%s" % (img.name_full, node.interpolation, node.extension, uv_map, transform, problem)
        if key not in self.images:
            self.images[key] = textures.ImageRef(
                img.name, _image_pixels(img), srgb=srgb, interpolation=node.interpolation,
                extension=node.extension, uv_map=uv_map, uv_transform=transform, problem=problem)
        return key


def describe_material(mat, compat):
    """Read a material into a :class:`materials.ShaderDesc` (bpy glue)."""
    vp = (tuple(mat.diffuse_color), float(mat.metallic), float(mat.roughness))
    ver = compat.VERSION
    name = mat.name
    if not compat.material_uses_nodes(mat):
        return materials.ShaderDesc(name, materials.NO_NODES, viewport=vp, version=ver)
    out = compat.shader_output_node(mat.node_tree)
    if out is None:
        return materials.ShaderDesc(name, materials.OTHER, viewport=vp, version=ver,
                                    reason="no Material Output node")
    sock = out.inputs.get("Surface")
    node = None
    seen = 0
    while sock is not None and sock.is_linked and seen < 64:
        node = sock.links[0].from_node
        seen += 1
        if node.bl_idname == "NodeReroute":
            sock = node.inputs[0]
            node = None
            continue
        break
    if node is None:
        return materials.ShaderDesc(name, materials.OTHER, viewport=vp, version=ver,
                                    reason="nothing connected to the Material Output's Surface")
    kinds = {"ShaderNodeBsdfPrincipled": materials.PRINCIPLED,
             "ShaderNodeBsdfDiffuse": materials.DIFFUSE,
             "ShaderNodeBsdfGlossy": materials.GLOSSY,
             "ShaderNodeBsdfAnisotropic": materials.ANISOTROPIC,
             "ShaderNodeEmission": materials.EMISSION}
    kind = kinds.get(node.bl_idname)
    if kind is None:
        return materials.ShaderDesc(name, materials.OTHER, viewport=vp, version=ver,
                                    node=node.name,
                                    reason="surface is a '%s' node" % node.bl_idname)
    inputs, linked = {}, set()
    for s in node.inputs:
        v = _socket_value(s)
        if v is not None and s.name not in inputs:
            inputs[s.name] = v
        if s.is_linked:
            linked.add(s.name)
    builder = _ExprBuilder(name)
    exprs = {}
    for sock_name in list(materials.TEXTURED_INPUTS.get(kind, {})) + list(materials.EMISSION_INPUTS.get(kind, ())):
        s_ = node.inputs.get(sock_name)
        if s_ is not None and s_.is_linked:
            exprs[sock_name] = builder.socket(s_)
    return materials.ShaderDesc(name, kind, inputs, linked, node=node.name, viewport=vp,
                                version=ver,
                                multiscatter=getattr(node, "distribution", "") == "MULTI_GGX",
                                exprs=exprs, images=builder.images, extra_warnings=builder.warnings)


def _holdout_objects(view_layer):
    """Names of objects in collections marked holdout in ``view_layer``."""
    names = set()

    def walk(lc, inherited):
        h = inherited or getattr(lc, "holdout", False)
        if h and not lc.exclude:
            names.update(o.name for o in lc.collection.all_objects)
        for c in lc.children:
            walk(c, h)
    walk(view_layer.layer_collection, False)
    return names


_ASSEMBLED = ("", "assembled")   # mesh_cache key of the last assembly (never an object name)


def collect(depsgraph, scene=None, require_lights=True, camera=True, mesh_cache=None):
    """Export the evaluated ``depsgraph`` (render or viewport) to a SceneData.

    ``camera=False`` leaves ``sd.camera`` unset (the live viewport sets its
    own). ``mesh_cache``: a dict kept by the caller between exports; meshes
    found in it are not read again (the caller removes the entries of
    objects whose geometry changed, keyed by the original object's name in
    the key's first field).

    Raises ExportError (naming the element) when the scene cannot give an
    AOV: no camera, unsupported camera, no geometry, no lights.
    """
    from . import compat
    scene = scene or depsgraph.scene
    sd = SceneData()
    view_layer = scene.view_layers.get(depsgraph.view_layer.name) or depsgraph.view_layer
    holdout_names = _holdout_objects(view_layer)
    viewport = depsgraph.mode != "RENDER"

    mat_index = {}
    mapped_cache = {}   # key -> (fields, warnings, slot plans) of a bpy material, mapped once
    material_plans = []  # per global material: slot -> textures.SlotPlan
    material_emission = {}  # global material -> (rgb, strength) of its emission

    def material_key(mat):
        return mat.original.name_full if mat.original else mat.name_full

    def mapped(mat):
        key = material_key(mat)
        if key not in mapped_cache:
            desc = describe_material(mat, compat)
            fields, warns = materials.map_material(desc)
            if fields.get("anisotropy", 0.0) > 0.0 and "Tangent" in desc.linked:
                warns = list(warns) + [
                    "material '%s': its Tangent input is linked; Cycles' default tangent "
                    "(radial about the object's Z) is used instead" % key]
            plans, more = _material_slots(key, fields, materials.texture_plans(desc))
            mapped_cache[key] = (fields, list(warns) + more, plans, materials.emission(desc))
        return mapped_cache[key]

    def vertex_color_of(mat):
        if mat is None:
            return None
        pl = mapped(mat)[2].get("base_color")
        return pl.vertex_color if pl is not None else None

    def anisotropic(mat):
        """Does ``mat`` map to an anisotropic lobe (needs tangents)?"""
        return mat is not None and mapped(mat)[0].get("anisotropy", 0.0) > 0.0

    def material_global(mat, holdout):
        if holdout:
            key = HOLDOUT_KEY
        elif mat is None:
            key = DEFAULT_KEY
        else:
            key = material_key(mat)
        if key in mat_index:
            return mat_index[key]
        plans = {}
        if key == HOLDOUT_KEY:
            fields = materials.default_material()
            fields.update(base_color=(0.0, 0.0, 0.0), specular_f0=0.0)
            warns = []
        elif key == DEFAULT_KEY:
            fields, warns = materials.default_material(), []
        else:
            fields, warns, plans, emit = mapped(mat)
            if emit is not None:
                material_emission[len(sd.materials)] = emit
        if compat.VERSION >= (4, 0, 0):  # Cycles 4.x+ GGX shadowing (vsgl/scene.h)
            fields = dict(fields, flags=int(fields.get("flags", 0)) | materials.MATERIAL_FLAG_BLENDER_4)
        sd.warnings.extend(warns)
        mat_index[key] = len(sd.materials)
        material_plans.append(plans)
        sd.materials.append(fields)
        sd.material_names.append(key)
        return mat_index[key]

    mesh_cache = {} if mesh_cache is None else mesh_cache
    _image_pixels_cache.clear()   # images are read once per export (painted pixels change)
    chunks = []
    warned_objects = set()
    _world_warnings(sd, scene)
    _collection_warnings(sd, view_layer)
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type not in MESH_TYPES and obj.type != "LIGHT":
            continue
        orig = obj.original
        parent = inst.parent if inst.is_instance else None
        if viewport:
            # A viewport depsgraph still contains render-hidden objects.
            if orig.hide_render or (parent is not None and parent.original.hide_render):
                continue
            # Render mode hides objects instanced on their parent's verts/faces.
            if not inst.is_instance and orig.parent is not None and \
                    orig.parent.instance_type in {"VERTS", "FACES"}:
                continue
        _visibility_warnings(sd, orig, warned_objects)
        if obj.type == "LIGHT":
            _add_light(sd, obj, inst.matrix_world, compat)
            continue
        holdout = (compat.is_holdout(orig) or orig.name in holdout_names
                   or (parent is not None and (compat.is_holdout(parent.original)
                                               or parent.original.name in holdout_names)))
        # Instances of one object share its evaluated mesh; Blender reuses one
        # temporary object for geometry-nodes instances, hence the data pointer.
        key = (orig.name_full, obj.as_pointer(), obj.data.as_pointer() if obj.data else 0,
               inst.is_instance)
        arr = mesh_cache.get(key)
        if arr is None:
            try:
                mesh = obj.to_mesh()
            except RuntimeError:
                mesh = None
            if mesh is None:
                mesh_cache[key] = arr = MeshArrays(np.zeros((0, 3), np.float32),
                                                   np.zeros((0, 3), np.int32),
                                                   np.zeros((0, 3), np.int32),
                                                   np.zeros((0, 3), np.float32), None,
                                                   np.zeros(0, np.int32))
            else:
                try:
                    slots = [s.material for s in obj.material_slots] or list(mesh.materials)
                    vc_names = sorted({n for n in (vertex_color_of(m) for m in slots) if n is not None})
                    arr = _mesh_arrays(mesh, compat, any(anisotropic(m) for m in slots), vc_names)
                finally:
                    obj.to_mesh_clear()
                arr.slots = slots
                mesh_cache[key] = arr
        if arr.tri_verts.shape[0] == 0:
            continue
        slot_map = [material_global(m, holdout) for m in (arr.slots or [None])]
        chunks.append((arr, np.array(inst.matrix_world), slot_map))
        sd.object_names.append(orig.name if not inst.is_instance
                               else "%s (instance of %s)" % (orig.name, parent.name if parent else "?"))
        sd.instance_count += int(inst.is_instance)

    want_uvs = any(a.loop_uvs is not None or a.uv_layers for a, _, _ in chunks)
    # Tangents only matter to anisotropic lobes: skip them (NULL) otherwise.
    want_tangents = any(m.get("anisotropy", 0.0) > 0.0 for m in sd.materials)
    dropped = {}

    def uv_map_of(g):
        for pl in material_plans[g].values():
            if pl.texture is not None:
                return pl.texture["uv_map"]
        return ""

    def color_of(g):
        pl = material_plans[g].get("base_color") if g < len(material_plans) else None
        return pl.vertex_color if pl is not None else None

    any_vc = any(color_of(g) is not None for g in range(len(material_plans)))
    # The same meshes at the same places as the last export (an edit of a
    # light or of the camera): reuse its assembled arrays.
    # (The arrays objects themselves are kept and compared by identity: a
    # re-read mesh is a new object, even where it reuses an old address.)
    per_material = tuple((uv_map_of(g), color_of(g)) for g in range(len(material_plans)))
    signature = (want_uvs, want_tangents, any_vc, per_material,
                 tuple((m.tobytes(), tuple(sm)) for _, m, sm in chunks))
    members = [a for a, _, _ in chunks]
    last = mesh_cache.get(_ASSEMBLED)
    if last is not None and last[0] == signature and len(last[3]) == len(members) and \
            all(x is y for x, y in zip(last[3], members)):
        out, dropped = last[1], dict(last[2])
    else:
        out = assemble(chunks, want_uvs, want_tangents, dropped, uv_map_of, color_of if any_vc else None)
        mesh_cache[_ASSEMBLED] = (signature, out, dict(dropped), members)
    for ci, (n, total) in sorted(dropped.items()):
        what = ("all %d triangles are" % total) if n == total else ("%d of %d triangles are" % (n, total))
        sd.warnings.append("object '%s': %s degenerate (zero area or zero-length normal, e.g. a "
                           "scale of 0 along an axis) and not lit or shaded" % (sd.object_names[ci], what))
    (sd.positions, sd.indices, sd.corner_normals, sd.corner_uvs,
     sd.material_indices) = out[:5]
    sd.corner_tangents = out[5] if want_tangents else None
    sd.corner_colors = out[-1] if any_vc else None
    _library_textures(sd, material_plans)
    _add_emissive_lights(sd, material_emission, compat.VERSION)
    if not sd.materials:
        material_global(None, False)

    if camera:
        _add_camera(sd, scene, depsgraph, compat)

    if sd.triangle_count == 0:
        raise ExportError("view layer '%s' of scene '%s' has no visible mesh geometry to light"
                          % (view_layer.name, scene.name))
    if require_lights and not any(l["power"] > 0 and max(l["color"]) > 0 for l in sd.lights):
        raise ExportError("scene '%s' (view layer '%s') has no light with non-zero power"
                          % (scene.name, view_layer.name))
    return sd


_RAY_VISIBILITY = (("visible_camera", "camera"), ("visible_diffuse", "diffuse"), ("visible_glossy", "glossy"),
                   ("visible_transmission", "transmission"), ("visible_volume_scatter", "volume scatter"),
                   ("visible_shadow", "shadow"))


def _visibility_warnings(sd, obj, warned):
    """Per-object settings Cycles honours and the library does not, once per object."""
    if obj.name in warned:
        return
    warned.add(obj.name)
    what = "light" if obj.type == "LIGHT" else "object"
    light_only = ("visible_camera", "visible_transmission", "visible_volume_scatter", "visible_shadow")
    off = [label for prop, label in _RAY_VISIBILITY if not getattr(obj, prop, True)
           and not (what == "light" and prop in light_only)]
    if off:
        sd.warnings.append("%s '%s': ray visibility (%s off) is not modelled; it is seen, lights, is lit and "
                           "casts shadows as if every ray type were on" % (what, obj.name, ", ".join(off)))
    if what == "object" and getattr(obj, "is_shadow_catcher", False):
        sd.warnings.append("object '%s': shadow catcher is not modelled; it is shaded as its material" % obj.name)
    if what == "object" and getattr(obj, "is_holdout", False):
        sd.warnings.append("object '%s': holdout: it blocks light but reflects none and gets no indirect light "
                           "in the AOV" % obj.name)


def _collection_warnings(sd, view_layer):
    def walk(lc):
        if lc.exclude:
            return
        if getattr(lc, "holdout", False):
            sd.warnings.append("collection '%s': holdout: its objects block light but reflect none and get no "
                               "indirect light in the AOV" % lc.name)
        if getattr(lc, "indirect_only", False):
            sd.warnings.append("collection '%s': 'indirect only' is not modelled; its objects are also seen "
                               "directly in the AOV" % lc.name)
        for c in lc.children:
            walk(c)
    for c in view_layer.layer_collection.children:
        walk(c)


def _world_warnings(sd, scene):
    """The world lights Cycles' render but is not a light source for the AOV."""
    w = scene.world
    if w is None:
        return
    strength, what = 0.0, ""
    if w.use_nodes and w.node_tree is not None:
        out = next((n for n in w.node_tree.nodes if n.bl_idname == "ShaderNodeOutputWorld" and
                    getattr(n, "is_active_output", True)), None)
        sock = out.inputs.get("Surface") if out is not None else None
        if sock is not None and sock.is_linked:
            node = sock.links[0].from_node
            if node.bl_idname == "ShaderNodeBackground":
                st = node.inputs["Strength"]
                col = node.inputs["Color"]
                strength = 1.0 if st.is_linked else float(st.default_value)
                if not col.is_linked:
                    strength *= max(tuple(col.default_value)[:3])
                what = "background" + (" with a texture" if col.is_linked else "")
            else:
                strength, what = 1.0, "a '%s' node" % node.bl_idname
    else:
        strength, what = max(tuple(w.color)[:3]), "colour"
    if strength > 0.0:
        sd.warnings.append("world '%s': world lighting (%s) is not a light source for the indirect AOV; "
                           "only lamps (and emissive meshes) bounce" % (w.name, what))


def _material_slots(name, fields, plans):
    """Keep the textured slots of one material that share one UV map (the
    library has one UV set per triangle): others are reduced to their mean.
    Returns (plans, warnings)."""
    warns, out, uv = [], {}, None
    for slot in ("base_color", "roughness", "metallic"):
        pl = plans.get(slot)
        if pl is None:
            continue
        if pl.texture is not None:
            if uv is None:
                uv = pl.texture["uv_map"]
            elif pl.texture["uv_map"] != uv:
                mean = pl.texture["pixels"].reshape(-1, 4).mean(axis=0)
                if slot == "base_color":
                    fields[slot] = tuple(float(min(max(c, 0), 1)) for c in mean[:3])
                else:
                    fields[slot] = float(min(max(mean[0] * fields[slot], 0), 1))
                warns.append("material '%s': its %s texture uses UV map '%s', another input '%s'; "
                             "its mean is used" % (name, slot, pl.texture["uv_map"], uv))
                pl = textures.SlotPlan(pl.constant)
        out[slot] = pl
    return out, warns


def _library_textures(sd, material_plans):
    """sd.textures and sd.material_textures (vsgl_material_textures fields)
    from the slot plans; one texture per distinct pixel array."""
    sd.textures, ids, mts, any_tex = [], {}, [], False
    for plans in material_plans:
        mt = {}
        flags = 0
        for slot, pl in plans.items():
            if slot == "base_color" and pl.vertex_color is not None and sd.corner_colors is not None:
                flags |= textures.VERTEX_COLOR_FLAG
                any_tex = True
            t = pl.texture
            if t is None:
                continue
            key = (id(t["pixels"]), t["srgb"])
            if key not in ids:
                sd.textures.append((np.ascontiguousarray(t["pixels"], np.float32),
                                    textures.TEXTURE_FLAG_SRGB if t["srgb"] else 0))
                ids[key] = len(sd.textures)
            mt[slot] = dict(texture=ids[key], filter=t["filter"], wrap=t["wrap"], channel=t.get("channel", 0),
                            uv_transform=t["uv_transform"] or (0.0,) * 6)
            any_tex = True
        mts.append(dict(slots=mt, flags=flags))
    sd.material_textures = mts if any_tex else None


MAX_EMISSIVE_LIGHTS = 32       # area lights made from emissive faces, at most
EMISSIVE_MIN_FRACTION = 1e-3   # faces emitting less than this of the brightest light are skipped


def _ray_distance(P, I, org, d, exclude=(), chunk=65536):
    """Distance along unit ``d`` from ``org`` to the nearest triangle (numpy
    Moller-Trumbore over every triangle, in chunks), inf if none."""
    best = np.inf
    for c0 in range(0, len(I), chunk):
        tri = P[I[c0:c0 + chunk]]
        e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        pv = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, pv)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        tv = org - tri[:, 0]
        u = np.einsum("ij,ij->i", tv, pv) * inv
        qv = np.cross(tv, e1)
        v = np.einsum("j,ij->i", d, qv) * inv
        t = np.einsum("ij,ij->i", e2, qv) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6)
        for x in exclude:
            if x is not None and c0 <= x < c0 + len(tri):
                hit[x - c0] = False
        if hit.any():
            best = min(best, float(t[hit].min()))
    return best


def emissive_lights(positions, indices, material_indices, emission, version=(3, 4, 0), split=1,
                    split_above=0.5, skipped=None):
    """Area lights (vsgl_light field dicts, with a "name" key) standing for
    the emissive triangles (pure numpy).

    Two triangles in a row that share an edge and form a rectangle become
    one rectangular light, every other triangle a disk of its area at its
    centroid. Each face emits on both sides (as Cycles' emission): one light
    per side, along +-its normal, nudged off the face. A face of area A with
    emission S (colour C) has radiance S C: a Blender 3.x area light of
    power 4 A S, a 4.x one of pi A S (docs/units.md)."""
    P = np.asarray(positions, np.float64)
    I = np.asarray(indices, np.int64)
    M = np.asarray(material_indices, np.int64)
    v4 = tuple(version) >= (4, 0, 0)
    out = []
    emissive = [t for t in range(len(I)) if int(M[t]) in emission]
    done = set()
    for n, t in enumerate(emissive):
        if t in done:
            continue
        g = int(M[t])
        rgb, strength = emission[g]
        tri = P[I[t]]
        e1, e2 = tri[1] - tri[0], tri[2] - tri[0]
        nrm = np.cross(e1, e2)
        area = 0.5 * np.linalg.norm(nrm)
        if not area > 0:
            continue
        nrm = nrm / (2 * area)
        rect = None
        u = t + 1
        if u < len(I) and u not in done and int(M[u]) == g and len(set(I[t]) & set(I[u])) == 2:
            other = P[[v for v in I[u] if v not in I[t]][0]]
            # corners in order around the quad: t's vertices with the new one between the shared pair
            shared = [v for v in I[t] if v in I[u]]
            lone = [v for v in I[t] if v not in I[u]][0]
            c = [P[lone], P[shared[0]], other, P[shared[1]]]
            a, b = c[1] - c[0], c[3] - c[0]
            la, lb = np.linalg.norm(a), np.linalg.norm(b)
            if la > 0 and lb > 0 and abs(np.dot(a, b)) < 1e-3 * la * lb and \
                    np.linalg.norm(c[0] + a + b - c[2]) < 1e-3 * max(la, lb) and \
                    abs(np.dot(np.cross(a, b) / (la * lb), nrm)) > 0.999:
                rect = (np.mean(c, axis=0), a / la, la, lb)
        pieces = []  # (centre, x axis, size x, size y, shape)
        if rect is not None:
            done.add(u)
            centre, xa, sx, sy = rect
            # the library's area-light RSM starts its rays at the light's centre:
            # a large panel is split so that each piece is small next to the room
            ya = np.cross(nrm, xa)
            if np.dot(np.cross(xa, ya), nrm) < 0:
                ya = -ya
            nx, ny = (split, split) if max(sx, sy) > split_above else (1, 1)
            for i in range(nx):
                for j in range(ny):
                    off = xa * sx * ((i + 0.5) / nx - 0.5) + ya * sy * ((j + 0.5) / ny - 0.5)
                    pieces.append((centre + off, xa, sx / nx, sy / ny, "RECTANGLE"))
        else:
            d = 2.0 * math.sqrt(area / math.pi)
            pieces.append((tri.mean(axis=0), e1 / np.linalg.norm(e1), d, d, "DISK"))
        for centre, xa, sx, size_y, shape in pieces:
            a = sx * size_y if shape == "RECTANGLE" else area
            power = (math.pi if v4 else 4.0) * a * strength
            for side in (1.0, -1.0):
                # a side facing a surface closer than 1/40 of its size (a panel
                # mounted on a ceiling) keeps its light in the gap: skipped
                gap = _ray_distance(P, I, centre, side * nrm, exclude=(t, u))
                if gap < 0.025 * max(sx, size_y):
                    if skipped is not None:
                        skipped.append((g, side, gap))
                    continue
                z = -side * nrm                       # an area light emits along its local -Z
                x = xa
                y = np.cross(z, x)
                m = np.eye(4)
                m[:3, 0], m[:3, 1], m[:3, 2] = x, y, z
                m[:3, 3] = centre + side * nrm * (1e-4 * max(sx, size_y) + 1e-5)
                f = convert.light_fields("emissive", "AREA", m, power, rgb, shape=shape, size=sx, size_y=size_y,
                                         blender_version=version)
                f["name"] = g
                out.append(f)
    return out


def _add_emissive_lights(sd, material_emission, version):
    if not material_emission or sd.triangle_count == 0:
        return
    blocked = []
    lights = emissive_lights(sd.positions, sd.indices, sd.material_indices, material_emission, version,
                             skipped=blocked)
    for g, side, gap in blocked[:10]:
        sd.warnings.append("material '%s': the %s side of an emissive face is %.3g m from a surface it faces; "
                           "its light stays in the gap and is skipped"
                           % (sd.material_names[g], "front" if side > 0 else "back", gap))
    if not lights:
        return
    brightest = max([l["power"] * max(l["color"]) for l in sd.lights + lights] or [0.0])
    kept, dim = [], {}
    for l in lights:
        if l["power"] * max(l["color"]) < EMISSIVE_MIN_FRACTION * brightest:
            dim[l["name"]] = dim.get(l["name"], 0) + 1
        else:
            kept.append(l)
    for g, n in sorted(dim.items()):
        sd.warnings.append("material '%s': %d emissive face side(s) emit less than %g of the brightest light "
                           "and are skipped (too small or too dim to matter)" % (sd.material_names[g], n,
                                                                                 EMISSIVE_MIN_FRACTION))
    if len(kept) > MAX_EMISSIVE_LIGHTS:
        kept.sort(key=lambda l: -l["power"] * max(l["color"]))
        for l in kept[MAX_EMISSIVE_LIGHTS:]:
            dim[l["name"]] = dim.get(l["name"], 0) + 1
        sd.warnings.append("emissive meshes: %d light samples, the brightest %d are used (materials %s)"
                           % (len(kept), MAX_EMISSIVE_LIGHTS,
                              ", ".join("'%s'" % sd.material_names[g] for g in sorted({l["name"] for l in kept}))))
        kept = kept[:MAX_EMISSIVE_LIGHTS]
    counts = {}
    for l in kept:
        g = l.pop("name")
        counts[g] = counts.get(g, 0) + 1
        sd.lights.append(l)
        sd.light_names.append("emission of material '%s'" % sd.material_names[g])
    for g, n in sorted(counts.items()):
        sd.emissive_log.append("material '%s': emissive faces exported as %d area light(s) (both sides)"
                               % (sd.material_names[g], n))


def _add_light(sd, obj, matrix, compat):
    light = obj.data
    name = obj.original.name if obj.original else obj.name
    if not getattr(light, "normalize", True):
        sd.warnings.append("light '%s': 'Normalize' off is not modelled; its power is used "
                           "as if normalized" % name)
    if getattr(light, "use_nodes", False) and light.node_tree is not None:
        sd.warnings.append("light '%s': its node setup is ignored (colour x power only)" % name)
    try:
        f = convert.light_fields(
            name, light.type, np.array(matrix), light.energy, tuple(light.color),
            exposure=compat.light_exposure(light), blackbody=compat.light_blackbody(light),
            radius=getattr(light, "shadow_soft_size", 0.0),
            spot_size=getattr(light, "spot_size", 0.0), spot_blend=getattr(light, "spot_blend", 0.0),
            sun_angle=getattr(light, "angle", 0.0), shape=getattr(light, "shape", "SQUARE"),
            size=getattr(light, "size", 0.0), size_y=getattr(light, "size_y", 0.0),
            spread=getattr(light, "spread", np.pi), blender_version=compat.VERSION)
    except ExportError as e:
        sd.warnings.append("%s; skipped" % e)
        return
    if f["power"] <= 0 or max(f["color"]) <= 0:
        sd.warnings.append("light '%s': zero power, skipped" % name)
        return
    sd.lights.append(f)
    sd.light_names.append(name)


def _add_camera(sd, scene, depsgraph, compat):
    cam = scene.camera
    if cam is None:
        raise ExportError("scene '%s' has no active camera" % scene.name)
    if cam.type != "CAMERA":
        raise ExportError("scene '%s': active camera '%s' is not a camera object"
                          % (scene.name, cam.name))
    ev = cam.evaluated_get(depsgraph)
    c = ev.data
    r = scene.render
    w, h = convert.render_size(r.resolution_x, r.resolution_y, r.resolution_percentage)
    sd.camera = convert.camera_fields(
        cam.name, c.type, np.array(ev.matrix_world), c.lens, c.sensor_width, c.sensor_height,
        c.sensor_fit, c.ortho_scale, c.shift_x, c.shift_y, c.clip_start, c.clip_end, w, h,
        r.pixel_aspect_x, r.pixel_aspect_y)
    sd.camera_name = cam.name
    sd.width, sd.height = w, h
