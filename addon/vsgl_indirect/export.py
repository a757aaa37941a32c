"""Evaluated Blender scene -> flat numpy arrays for ``vsgl_scene_desc``.

Two halves: ``collect()`` reads bpy (depsgraph instances, evaluated meshes,
lights, camera, materials) into plain values; ``assemble()`` (no bpy) turns
mesh chunks into world-space arrays. No per-vertex Python loops: every
array comes from ``foreach_get`` and numpy.
"""
import numpy as np

from . import convert, materials
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
        self.material_indices = np.zeros(0, np.uint32)
        self.materials = []        # vsgl_material field dicts
        self.material_names = []
        self.lights = []           # vsgl_light field dicts
        self.light_names = []
        self.camera = None         # vsgl_camera field dict
        self.camera_name = ""
        self.warnings = []
        self.object_names = []     # one per exported mesh instance
        self.instance_count = 0    # instances among them
        self.width = self.height = 0

    @property
    def triangle_count(self):
        return int(self.indices.shape[0])

    def summary(self):
        return ("%d triangles, %d objects (%d instances), %d materials, %d lights, camera '%s' %dx%d"
                % (self.triangle_count, len(self.object_names), self.instance_count,
                   len(self.materials), len(self.lights), self.camera_name, self.width, self.height))


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
        self.loop_uvs = loop_uvs          # (L,2) float32 or None
        self.tri_material = tri_material  # (T,) int: slot index
        self.slots = []                   # material per slot (bpy materials)
        self.texspace = None              # (location, size) of the texture space; None = bounds
        self.undeformed = None            # (V,3) undeformed coordinates (generated); None = positions
        # Flat-shaded triangles: Cycles shades them with the triangle's own
        # normal, not the polygon's (they differ on non-planar quads)
        self.tri_flat = None              # (T,) bool or None (all smooth)
        self.flat_normals = None          # (T,3) float64 unit local geometric normals


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


def degenerate_mask(positions, indices, corner_normals):
    """Triangles libvsgl would drop: zero area (in the float32 positions it is
    given) or a corner normal of (near) zero length (as vsgl_scene_create)."""
    p = np.asarray(positions, np.float32).astype(np.float64)[np.asarray(indices, np.int64)]
    area2 = np.square(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])).sum(axis=1)
    n = np.asarray(corner_normals, np.float32).astype(np.float64)
    n2 = np.square(n).sum(axis=2)
    return ~(area2 > 0) | ~np.isfinite(area2) | ~np.all(n2 > 1e-20, axis=1)


def assemble(chunks, want_uvs=False, want_tangents=False, dropped=None):
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
    pos, idx, nrm, uvs, mats, tan = [], [], [], [], [], []
    base = 0
    for key in order:
        arr, ms, smaps, chunk_ids = groups[key]
        M = np.stack(ms)                       # (k, 4, 4)
        k, V, T = len(ms), arr.positions.shape[0], arr.tri_verts.shape[0]
        A, t = M[:, :3, :3], M[:, :3, 3]
        p = np.einsum("kij,vj->kvi", A, arr.positions.astype(np.float64)) + t[:, None, :]
        det = np.linalg.det(A)
        tv = np.broadcast_to(arr.tri_verts.astype(np.int64), (k, T, 3)).copy()
        tl = np.broadcast_to(arr.tri_loops.astype(np.int64), (k, T, 3)).copy()
        flip = det < 0
        if flip.any():
            tv[flip] = tv[flip][:, :, [0, 2, 1]]
            tl[flip] = tl[flip][:, :, [0, 2, 1]]
        nm = _cofactor(A)
        ok = np.abs(det) > 1e-30
        if ok.any():
            nm[ok] = np.linalg.inv(A[ok]).transpose(0, 2, 1)
        n = np.einsum("kij,ktcj->ktci", nm, arr.loop_normals.astype(np.float64)[tl])
        if arr.tri_flat is not None:
            g = np.einsum("kij,tj->kti", nm, arr.flat_normals)           # (k,T,3)
            n[:, arr.tri_flat] = g[:, arr.tri_flat][:, :, None, :]
        ln = np.linalg.norm(n, axis=3, keepdims=True)
        zero = ~(ln[..., 0] > 0)
        ln[ln == 0] = 1.0
        p32 = p.reshape(-1, 3).astype(np.float32)
        tri = (tv + (np.arange(k) * V)[:, None, None]).reshape(-1, 3)
        n32 = (n / ln).reshape(-1, 3, 3).astype(np.float32)
        bad = degenerate_mask(p32, tri, n32) | zero.reshape(-1, 3).any(axis=1)
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
            tc = tw[np.arange(k)[:, None, None], tv]                            # (k, T, 3, 3)
            t4 = np.ones((k, T, 3, 4), np.float32)
            t4[..., :3] = tc
            tan.append(t4.reshape(-1, 3, 4)[keep])
        if want_uvs:
            if arr.loop_uvs is not None:
                uvs.append(arr.loop_uvs[tl].reshape(-1, 3, 2).astype(np.float32)[keep])
            else:
                uvs.append(np.zeros((int(keep.sum()), 3, 2), np.float32))
        width = max(len(sm) for sm in smaps)
        table = np.array([sm + [sm[-1]] * (width - len(sm)) for sm in smaps], np.uint32)
        slot = np.clip(arr.tri_material, 0, None)[None, :]
        last = np.array([len(sm) - 1 for sm in smaps])[:, None]
        mats.append(table[np.arange(k)[:, None], np.minimum(slot, last)].reshape(-1)[keep])
        base += k * V
    if not idx:
        out = (np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32),
               np.zeros((0, 3, 3), np.float32), None, np.zeros(0, np.uint32))
        return out + (np.zeros((0, 3, 4), np.float32),) if want_tangents else out
    out = (np.concatenate(pos), np.concatenate(idx), np.concatenate(nrm),
           np.concatenate(uvs) if want_uvs else None, np.concatenate(mats).astype(np.uint32))
    return out + (np.concatenate(tan),) if want_tangents else out


# --------------------------------------------------------------------------
# bpy glue
# --------------------------------------------------------------------------

def _mesh_arrays(mesh, compat, want_undeformed=False):
    mesh.calc_loop_triangles()
    lt = mesh.loop_triangles
    nt, nv = len(lt), len(mesh.vertices)
    pos = np.empty(nv * 3, np.float32)
    mesh.vertices.foreach_get("co", pos)
    tv = np.empty(nt * 3, np.int32)
    lt.foreach_get("vertices", tv)
    tl = np.empty(nt * 3, np.int32)
    lt.foreach_get("loops", tl)
    mi = np.empty(nt, np.int32)
    lt.foreach_get("material_index", mi)
    ln = compat.corner_normals(mesh) if nt else np.zeros((0, 3), np.float32)
    uv = None
    layer = mesh.uv_layers.active if len(mesh.uv_layers) else None
    if layer is not None and nt:
        uv = np.empty(len(mesh.loops) * 2, np.float32)
        layer.data.foreach_get("uv", uv)
        uv = uv.reshape(-1, 2)
    arr = MeshArrays(pos.reshape(nv, 3), tv.reshape(nt, 3), tl.reshape(nt, 3), ln, uv, mi)
    if nt:
        smooth = np.empty(nt, bool)
        lt.foreach_get("use_smooth", smooth)
        if not smooth.all():
            p = arr.positions.astype(np.float64)[arr.tri_verts]             # (T,3,3)
            gn = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
            length = np.linalg.norm(gn, axis=1, keepdims=True)
            flat = ~smooth & (length[:, 0] > 0)
            if flat.any():
                length[length == 0] = 1.0
                arr.tri_flat = flat
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
             "ShaderNodeBsdfAnisotropic": materials.ANISOTROPIC}
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
    return materials.ShaderDesc(name, kind, inputs, linked, node=node.name, viewport=vp,
                                version=ver,
                                multiscatter=getattr(node, "distribution", "") == "MULTI_GGX")


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
    mapped_cache = {}   # key -> (fields, warnings) of a bpy material, mapped once

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
            mapped_cache[key] = (fields, warns)
        return mapped_cache[key]

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
        if key == HOLDOUT_KEY:
            fields = materials.default_material()
            fields.update(base_color=(0.0, 0.0, 0.0), specular_f0=0.0)
            warns = []
        elif key == DEFAULT_KEY:
            fields, warns = materials.default_material(), []
        else:
            fields, warns = mapped(mat)
        if compat.VERSION >= (4, 0, 0):  # Cycles 4.x+ GGX shadowing (vsgl/scene.h)
            fields = dict(fields, flags=int(fields.get("flags", 0)) | materials.MATERIAL_FLAG_BLENDER_4)
        sd.warnings.extend(warns)
        mat_index[key] = len(sd.materials)
        sd.materials.append(fields)
        sd.material_names.append(key)
        return mat_index[key]

    mesh_cache = {} if mesh_cache is None else mesh_cache
    chunks = []
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
                    arr = _mesh_arrays(mesh, compat, any(anisotropic(m) for m in slots))
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

    want_uvs = any(a.loop_uvs is not None for a, _, _ in chunks)
    # Tangents only matter to anisotropic lobes: skip them (NULL) otherwise.
    want_tangents = any(m.get("anisotropy", 0.0) > 0.0 for m in sd.materials)
    dropped = {}
    # The same meshes at the same places as the last export (an edit of a
    # light or of the camera): reuse its assembled arrays.
    # (The arrays objects themselves are kept and compared by identity: a
    # re-read mesh is a new object, even where it reuses an old address.)
    signature = (want_uvs, want_tangents, tuple((m.tobytes(), tuple(sm)) for _, m, sm in chunks))
    members = [a for a, _, _ in chunks]
    last = mesh_cache.get(_ASSEMBLED)
    if last is not None and last[0] == signature and len(last[3]) == len(members) and \
            all(x is y for x, y in zip(last[3], members)):
        out, dropped = last[1], dict(last[2])
    else:
        out = assemble(chunks, want_uvs, want_tangents, dropped)
        mesh_cache[_ASSEMBLED] = (signature, out, dict(dropped), members)
    for ci, (n, total) in sorted(dropped.items()):
        what = ("all %d triangles are" % total) if n == total else ("%d of %d triangles are" % (n, total))
        sd.warnings.append("object '%s': %s degenerate (zero area or zero-length normal, e.g. a "
                           "scale of 0 along an axis) and not lit or shaded" % (sd.object_names[ci], what))
    (sd.positions, sd.indices, sd.corner_normals, sd.corner_uvs,
     sd.material_indices) = out[:5]
    sd.corner_tangents = out[5] if want_tangents else None
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
