"""Export of the evaluated depsgraph against the scene built in each test and
Blender's own values (matrix_world, loop counts, light settings)."""
import os

import bpy
import numpy as np
import pytest

from conftest import VERSION, camera, cube, light, link, mesh_object, plane, principled, shader_material
from vsgl_indirect import export, materials
from vsgl_indirect.convert import ExportError


def collect(scene, **kw):
    return export.collect(bpy.context.evaluated_depsgraph_get(), scene, **kw)


def basic(scene):
    camera(scene)
    light(scene)


def face_normals(sd):
    p = sd.positions[sd.indices.astype(np.int64)]
    n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_counts_transforms_and_flat_normals(scene):
    basic(scene)
    ob = link(scene, cube("Box", 2.0))
    ob.location = (1, 2, 3)
    ob.rotation_euler = (0.3, 0.2, 0.1)
    ob.scale = (1, 2, 0.5)
    bpy.context.view_layer.update()
    sd = collect(scene)
    assert sd.triangle_count == 12 and sd.positions.shape == (8, 3)
    mw = ob.matrix_world
    expect = np.array([tuple(mw @ v.co) for v in ob.data.vertices], np.float32)
    assert np.allclose(sd.positions, expect, atol=1e-5)
    # Flat cube: every corner normal is its triangle's geometric normal.
    fn = face_normals(sd)
    assert np.allclose(sd.corner_normals, fn[:, None, :].repeat(3, 1), atol=1e-5)


def test_flat_non_planar_quad_uses_triangle_normals(scene):
    """Cycles shades a flat (not smooth) face with each triangle's own normal;
    on a non-planar quad that differs from the polygon normal (by ~14 deg
    here), so the export must not pass the polygon's. Smooth faces keep their
    split normals."""
    basic(scene)
    ob = link(scene, mesh_object("Warped", [(-1, -1, 0), (1, -1, 0.6), (1, 1, 0), (-1, 1, 0.6)], [(0, 1, 2, 3)]))
    ob.rotation_euler = (0.2, -0.4, 0.7)
    ob.scale = (1.5, -1.0, 1.0)           # mirrored too
    bpy.context.view_layer.update()
    sd = collect(scene)
    fn = face_normals(sd)
    assert sd.triangle_count == 2
    assert float(np.dot(fn[0], fn[1])) < 0.99          # the two triangles really differ
    assert np.allclose(sd.corner_normals, fn[:, None, :].repeat(3, 1), atol=1e-5)
    for poly in ob.data.polygons:
        poly.use_smooth = True
    ob.data.update()
    bpy.context.view_layer.update()
    sd = collect(scene)
    # smooth: Blender's split normals, here the one polygon's normal at every
    # corner of both triangles, which is neither triangle's own normal
    cn = sd.corner_normals.reshape(-1, 3)
    assert np.allclose(cn, cn[:1].repeat(6, 0), atol=1e-5)
    assert float(np.dot(cn[0], fn[0])) < 0.9999 and float(np.dot(cn[0], fn[1])) < 0.9999


def test_negative_scale_keeps_winding(scene):
    basic(scene)
    ob = link(scene, cube("Mirror", 2.0))
    ob.scale = (-1, 1, 1)
    bpy.context.view_layer.update()
    sd = collect(scene)
    fn = face_normals(sd)
    assert np.all(np.einsum("ij,ij->i", fn, sd.corner_normals[:, 0]) > 0.999)
    # Outward: normal points away from the cube centre.
    centres = sd.positions[sd.indices.astype(np.int64)].mean(1)
    assert np.all(np.einsum("ij,ij->i", fn, centres) > 0)


def test_smooth_split_normals_and_modifier_applied(scene):
    basic(scene)
    ob = link(scene, cube("Smooth", 2.0))
    for p in ob.data.polygons:
        p.use_smooth = True
    mod = ob.modifiers.new("Sub", "SUBSURF")
    mod.levels = 2
    bpy.context.view_layer.update()
    sd = collect(scene)
    assert sd.triangle_count == 6 * 16 * 2
    # Smooth, centred blob: corner normals point roughly along the position.
    pos = sd.positions[sd.indices.astype(np.int64)]
    d = pos / np.linalg.norm(pos, axis=2, keepdims=True)
    assert np.all(np.einsum("tci,tci->tc", d, sd.corner_normals) > 0.8)
    assert np.allclose(np.linalg.norm(sd.corner_normals, axis=2), 1, atol=1e-4)
    assert len(ob.data.vertices) == 8  # the original mesh is untouched


def test_instances_collection_and_verts(scene):
    basic(scene)
    col = bpy.data.collections.new("Src")
    scene.collection.children.link(col)
    link(scene, plane("Tile", 1.0), col)
    bpy.context.view_layer.layer_collection.children["Src"].exclude = True
    for i in range(3):
        e = bpy.data.objects.new("Inst%d" % i, None)
        e.instance_type = "COLLECTION"
        e.instance_collection = col
        e.location = (3 * i, 0, 0)
        link(scene, e)
    # Vertex instancing: a 4-vertex carrier instancing a cube 4 times.
    carrier = link(scene, mesh_object("Carrier", [(0, 5, 0), (2, 5, 0), (4, 5, 0), (6, 5, 0)], []))
    child = link(scene, cube("Child", 0.2))
    child.parent = carrier
    carrier.instance_type = "VERTS"
    bpy.context.view_layer.update()
    sd = collect(scene)
    assert sd.instance_count == 3 + 4
    assert sd.triangle_count == 3 * 2 + 4 * 12
    xs = sorted(set(np.round(sd.positions[:, 0][sd.positions[:, 1] < 1], 3)))
    assert xs == [-0.5, 0.5, 2.5, 3.5, 5.5, 6.5]


def test_visibility_hide_render_excluded_and_holdout(scene):
    basic(scene)
    link(scene, plane("Shown", 1.0))
    link(scene, plane("NoRender", 1.0, (5, 0, 0))).hide_render = True
    col = bpy.data.collections.new("Excluded")
    scene.collection.children.link(col)
    link(scene, plane("InExcluded", 1.0, (9, 0, 0)), col)
    bpy.context.view_layer.layer_collection.children["Excluded"].exclude = True
    hold = link(scene, plane("Hold", 1.0, (0, 4, 0), principled("Red", (1, 0, 0, 1))))
    hold.is_holdout = True
    bpy.context.view_layer.update()
    sd = collect(scene)
    assert sorted(sd.object_names) == ["Hold", "Shown"]
    hm = sd.materials[sd.material_indices[sd.positions[sd.indices[:, 0], 1] > 3][0]]
    assert hm["base_color"] == (0.0, 0.0, 0.0) and hm["specular_f0"] == 0.0


def test_materials_from_nodes_both_versions(scene):
    basic(scene)
    if VERSION >= (4, 0, 0):
        m1 = principled("P", (0.1, 0.2, 0.3, 1), 0.5, 0.25, **{"IOR": 2.0, "Specular IOR Level": 0.25})
        f0 = ((2.0 - 1) / 3.0) ** 2 * 0.5
    else:
        m1 = principled("P", (0.1, 0.2, 0.3, 1), 0.5, 0.25, Specular=0.25)
        f0 = 0.02
    m2, _ = shader_material("Emit", "ShaderNodeEmission")
    m2.diffuse_color = (0.3, 0.6, 0.9, 1)
    m3, d = shader_material("Diff", "ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (0.7, 0.6, 0.5, 1)
    ob = link(scene, cube("Multi", 2.0))
    for m in (m1, m2, m3):
        ob.data.materials.append(m)
    for i, p in enumerate(ob.data.polygons):
        p.material_index = i % 3
    bpy.context.view_layer.update()
    sd = collect(scene)
    by = dict(zip(sd.material_names, sd.materials))
    assert by["P"]["specular_f0"] == pytest.approx(f0, rel=1e-5)
    assert by["P"]["base_color"] == pytest.approx((0.1, 0.2, 0.3))
    assert (by["P"]["metallic"], by["P"]["roughness"]) == pytest.approx((0.5, 0.25))
    # an Emission shader reflects nothing; its faces are area lights (issue 13)
    assert not by["Emit"]["flags"] & materials.MATERIAL_UNSUPPORTED
    assert by["Emit"]["base_color"] == pytest.approx((0.0, 0.0, 0.0))
    assert any("'Emit'" in n for n in sd.light_names)
    assert by["Diff"]["base_color"] == pytest.approx((0.7, 0.6, 0.5))
    assert by["Diff"]["specular_f0"] == 0
    # the running Blender's GGX shadowing (height-correlated from 4.0 on)
    want = materials.MATERIAL_FLAG_BLENDER_4 if VERSION >= (4, 0, 0) else 0
    assert all(m["flags"] & materials.MATERIAL_FLAG_BLENDER_4 == want for m in sd.materials)
    # a Principled BSDF's distribution: Multiscatter GGX is 4.x's default
    ms = by["P"]["flags"] & materials.MATERIAL_FLAG_MULTISCATTER
    assert bool(ms) == (VERSION >= (4, 0, 0) and m1.node_tree.nodes["Principled BSDF"].distribution == "MULTI_GGX")
    # Cycles 3.x's Principled diffuse is Burley's, 4.x's and the Diffuse BSDF's Lambert
    assert bool(by["P"]["flags"] & materials.MATERIAL_FLAG_BURLEY) == (VERSION < (4, 0, 0))
    assert not by["Diff"]["flags"] & materials.MATERIAL_FLAG_BURLEY
    # Per-triangle material: polygon i -> material i % 3 (two triangles each).
    names = [sd.material_names[i] for i in sd.material_indices]
    assert names.count("P") == names.count("Emit") == names.count("Diff") == 4


def test_lights_units_per_type(scene):
    camera(scene)
    link(scene, plane("Floor", 4))
    p = light(scene, "POINT", "P", 100.0, (0, 0, 2), shadow_soft_size=0.25, color=(1, 0.5, 0.25))
    s = light(scene, "SPOT", "S", 50.0, (1, 0, 2), spot_size=0.8, spot_blend=0.4)
    s.rotation_euler = (0.5, 0, 0)
    light(scene, "SUN", "Sun", 3.0, (0, 0, 5), angle=0.1)
    light(scene, "AREA", "A", 20.0, (0, 0, 3), shape="RECTANGLE", size=0.5, size_y=2.0, spread=1.0)
    light(scene, "AREA", "Disk", 20.0, (0, 0, 3), shape="DISK", size=0.7)
    has_exposure = hasattr(p.data, "exposure")      # light exposure: 4.3+ (not in 4.2 LTS)
    if has_exposure:
        p.data.exposure = 1.5
    bpy.context.view_layer.update()
    sd = collect(scene)
    L = dict(zip(sd.light_names, sd.lights))
    expo = 2 ** 1.5 if has_exposure else 1.0
    assert L["P"]["power"] == pytest.approx(100 * expo, rel=1e-5)
    assert L["P"]["color"] == pytest.approx((1, 0.5, 0.25)) and L["P"]["radius"] == pytest.approx(0.25)
    assert (L["S"]["type"], L["S"]["spot_size"], L["S"]["spot_blend"]) == \
        (1, pytest.approx(0.8), pytest.approx(0.4))
    assert np.allclose(np.reshape(L["S"]["world_from_light"], (3, 4)),
                       np.array(s.matrix_world)[:3], atol=1e-6)
    assert (L["Sun"]["type"], L["Sun"]["power"], L["Sun"]["sun_angle"]) == \
        (2, pytest.approx(3.0), pytest.approx(0.1))
    assert (L["A"]["area_shape"], L["A"]["size_x"], L["A"]["size_y"], L["A"]["spread"]) == \
        (1, pytest.approx(0.5), pytest.approx(2.0), pytest.approx(1.0))
    assert (L["Disk"]["area_shape"], L["Disk"]["size_y"]) == (2, pytest.approx(0.7))
    # the running Blender's light semantics (spots, area power; docs/units.md)
    want = 1 if VERSION >= (4, 0, 0) else 0
    assert all(f["flags"] == want for f in sd.lights), [f["flags"] for f in sd.lights]


def test_camera_fields(scene):
    light(scene)
    link(scene, plane("Floor", 4))
    cam = camera(scene, (1, -5, 2), (1.2, 0, 0.3), lens=42.0)
    c = cam.data
    c.sensor_fit = "VERTICAL"
    c.sensor_height = 20.0
    c.shift_x, c.shift_y = 0.1, -0.05
    c.clip_start, c.clip_end = 0.5, 50.0
    cam.scale = (2, 2, 2)
    scene.render.resolution_x, scene.render.resolution_y = 400, 300
    scene.render.resolution_percentage = 25
    scene.render.pixel_aspect_x = 2.0
    bpy.context.view_layer.update()
    sd = collect(scene)
    k = sd.camera
    assert (k["width"], k["height"]) == (100, 75)
    assert (k["lens_mm"], k["sensor_height_mm"], k["sensor_fit"]) == (pytest.approx(42.0), pytest.approx(20.0), 2)
    assert (k["shift_x"], k["shift_y"]) == (pytest.approx(0.1), pytest.approx(-0.05))
    assert (k["clip_start"], k["clip_end"], k["pixel_aspect_x"]) == (0.5, 50.0, 2.0)
    m = np.reshape(k["world_from_camera"], (3, 4))
    mw = cam.matrix_world.normalized()
    assert np.allclose(m[:, :3], np.array(mw.to_3x3()), atol=1e-5)
    assert np.allclose(m[:, 3], tuple(cam.matrix_world.translation), atol=1e-5)


def test_bad_scenes_name_the_problem(scene):
    link(scene, plane("Floor", 4))
    with pytest.raises(ExportError, match="no active camera"):
        collect(scene)
    camera(scene)
    with pytest.raises(ExportError, match="no light"):
        collect(scene)
    light(scene, energy=0.0, name="Dark")
    with pytest.raises(ExportError, match="no light"):
        collect(scene)
    scene.camera.data.type = "PANO"
    light(scene, name="Lamp")
    with pytest.raises(ExportError, match="'Cam'.*PANO"):
        collect(scene)


def test_empty_scene_reports(scene):
    basic(scene)
    with pytest.raises(ExportError, match="no visible mesh geometry"):
        collect(scene)


def _gn_instances_group(count):
    ng = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    if hasattr(ng, "interface"):   # 4.0+
        ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
        ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    else:                          # 3.x
        ng.inputs.new("NodeSocketGeometry", "Geometry")
        ng.outputs.new("NodeSocketGeometry", "Geometry")
    ng.nodes.new("NodeGroupInput")
    out = ng.nodes.new("NodeGroupOutput")
    line = ng.nodes.new("GeometryNodeMeshLine")
    line.inputs["Count"].default_value = count
    cube_node = ng.nodes.new("GeometryNodeMeshCube")
    inst = ng.nodes.new("GeometryNodeInstanceOnPoints")
    ng.links.new(line.outputs["Mesh"], inst.inputs["Points"])
    ng.links.new(cube_node.outputs["Mesh"], inst.inputs["Instance"])
    ng.links.new(inst.outputs["Instances"], out.inputs[0])
    return ng


def test_geometry_nodes_and_particle_instances(scene):
    basic(scene)
    carrier = link(scene, plane("GNCarrier", 1.0, (0, 0, -5)))
    mod = carrier.modifiers.new("GN", "NODES")
    mod.node_group = _gn_instances_group(5)
    emitter = link(scene, plane("Emitter", 2.0, (10, 0, 0)))
    emitter.modifiers.new("P", "PARTICLE_SYSTEM")
    ps = emitter.particle_systems[0].settings
    ps.type = "HAIR"
    ps.count = 10
    ps.render_type = "OBJECT"
    tiny = link(scene, cube("Tiny", 0.1, (0, 0, 50)))
    ps.instance_object = tiny
    ps.particle_size = 1.0
    bpy.context.view_layer.update()
    sd = collect(scene)
    inst = [n for n in sd.object_names if "instance of" in n]
    assert sum("GNCarrier" in n for n in inst) == 5
    assert sum("Emitter" in n for n in inst) == 10
    # GN cubes (size 1) stacked along +Z from the carrier at z = -5.
    gz = sd.positions[(np.abs(sd.positions[:, 0]) <= 0.5 + 1e-6) & (sd.positions[:, 2] < 0)][:, 2]
    assert gz.min() == pytest.approx(-5.5, abs=1e-5) and gz.max() == pytest.approx(-0.5, abs=1e-5)
    # Hair instances sit on the emitter (x in [9, 11]).
    hx = sd.positions[(sd.positions[:, 0] > 8.5)][:, 0]
    assert hx.min() >= 9 - 0.2 and hx.max() <= 11 + 0.2


def test_light_blackbody_and_nodes_warning(scene):
    camera(scene)
    link(scene, plane("Floor", 4))
    lamp = light(scene, "POINT", "Warm", 10.0, color=(1, 1, 1))
    if "use_temperature" in lamp.data.bl_rna.properties:      # 4.5+
        lamp.data.use_temperature = True
        lamp.data.temperature = 3000.0
        expect = tuple(lamp.data.temperature_color)
    else:
        expect = (1.0, 1.0, 1.0)
    lamp.data.use_nodes = True
    bpy.context.view_layer.update()
    sd = collect(scene)
    assert sd.lights[0]["color"] == pytest.approx(expect, rel=1e-5)
    if expect != (1.0, 1.0, 1.0):
        assert expect[2] < expect[0]    # 3000 K is reddish: independent sanity
    assert any("'Warm'" in w and "node" in w for w in sd.warnings)


def test_collection_holdout_and_layer_paths_distinct(scene):
    from vsgl_indirect import runner
    basic(scene)
    link(scene, plane("Shown", 1.0))
    col = bpy.data.collections.new("Matte")
    scene.collection.children.link(col)
    link(scene, plane("InMatte", 1.0, (0, 5, 0), principled("Blue", (0, 0, 1, 1))), col)
    bpy.context.view_layer.layer_collection.children["Matte"].holdout = True
    bpy.context.view_layer.update()
    sd = collect(scene)
    tri = np.flatnonzero(sd.positions[sd.indices[:, 0], 1] > 4)
    assert len(tri) == 2
    assert sd.materials[sd.material_indices[tri[0]]]["base_color"] == (0.0, 0.0, 0.0)
    # Two rendered view layers and a template without {view_layer}: distinct files.
    scene.view_layers.new("Other")
    scene.vsgl_indirect.output_path = "/tmp/x/aov_####.exr"
    a = runner.output_path(scene, "ViewLayer", 5)
    b = runner.output_path(scene, "Other", 5)
    assert a != b and a.endswith("_0005.exr") and b.endswith("_0005.exr")


def test_degenerate_objects_dropped_with_named_warning(scene, tmp_path):
    """Issue 10: an object scaled (1, 1, 0) or (0, 0, 0) gave zero-length
    normals and the library refused the whole frame without naming it. Its
    degenerate triangles are dropped with a warning naming the object; the
    rest of the scene (and the object's faces that keep an area) is exported."""
    basic(scene)
    link(scene, plane("Floor", 6.0))
    flat = link(scene, cube("Flat", 1.0, location=(0, 0, 1)))
    flat.scale = (1, 1, 0)
    gone = link(scene, cube("Gone", 1.0, location=(1, 1, 1)))
    gone.scale = (0, 0, 0)
    bpy.context.view_layer.update()
    sd = collect(scene)
    lengths = np.linalg.norm(sd.corner_normals.astype(np.float64), axis=2)
    assert lengths.min() > 0.5, "zero-length normals exported"
    p = sd.positions.astype(np.float64)[sd.indices.astype(np.int64)]
    area = np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    assert area.min() > 0, "zero-area triangles exported"
    # Floor (2) and Flat's top and bottom (2 + 2) stay; Flat's sides and all of Gone go.
    assert sd.triangle_count == 6, sd.triangle_count
    text = "\n".join(sd.warnings)
    assert "object 'Flat': 8 of 12 triangles are degenerate" in text, text
    assert "object 'Gone': all 12 triangles are degenerate" in text, text
    assert "Floor" not in text
    # ... and the frame renders: the library accepts what is left and lights it.
    from conftest import real_render_or_skip
    real_render_or_skip()
    from vsgl_indirect import engine
    from vsgl_indirect.config import Options
    res = engine.compute(sd, Options(preset="PREVIEW"), os.path.join(str(tmp_path), "flat.exr"))
    assert os.path.exists(res.path) and res.stats["lights_used"] == 1


def test_frame_above_max_memory_is_refused_with_its_size(scene, tmp_path):
    """Issue 10: the add-on's 'Max Memory' reaches the library, which refuses
    the frame up front, naming the image size, the estimate and the limit."""
    from conftest import real_render_or_skip
    real_render_or_skip()
    from vsgl_indirect import engine
    from vsgl_indirect.config import Options
    basic(scene)
    link(scene, plane("Floor", 6.0))
    bpy.context.view_layer.update()
    sd = collect(scene)
    with pytest.raises(engine.AovError) as e:
        engine.compute(sd, Options(preset="PREVIEW", max_memory_gb=0.0001), os.path.join(str(tmp_path), "m.exr"))
    assert "needs about" in str(e.value) and "memory limit of 0.1 MiB (max_memory)" in str(e.value), str(e.value)
    res = engine.compute(sd, Options(preset="PREVIEW"), os.path.join(str(tmp_path), "m.exr"))
    assert engine.memory_summary(res.stats).startswith("about ")


def _slow_reads(me):
    """The mesh's triangles, face materials, smoothness and UVs through the
    per-element collections with signed buffers (what the export read
    before it took Blender's one-copy paths)."""
    me.calc_loop_triangles()
    lt = me.loop_triangles
    nt = len(lt)
    tv, tl, mi = np.empty(nt * 3, np.int32), np.empty(nt * 3, np.int32), np.empty(nt, np.int32)
    lt.foreach_get("vertices", tv)
    lt.foreach_get("loops", tl)
    lt.foreach_get("material_index", mi)
    sm = np.empty(nt, bool)
    lt.foreach_get("use_smooth", sm)
    uvs = {}
    for layer in me.uv_layers:
        a = np.empty(len(me.loops) * 2, np.float32)
        layer.data.foreach_get("uv", a)
        uvs[layer.name] = a.reshape(-1, 2)
    return tv.reshape(-1, 3), tl.reshape(-1, 3), mi, sm, uvs


@pytest.mark.parametrize("mixed", [True, False])
def test_mesh_reads_equal_the_per_element_collections(scene, mixed):
    # export._mesh_arrays reads indices into unsigned buffers and, from 4.1,
    # face materials, smoothness and UVs as generic attributes (absent
    # attributes: slot 0, smooth). mixed: faces of two slots, every third
    # flat, two UV maps; else one slot, all smooth (no attributes to read).
    from vsgl_indirect import compat
    basic(scene)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8)
    ob = bpy.context.object
    me = ob.data
    me.materials.append(principled("M0"))
    me.materials.append(principled("M1"))
    me.uv_layers.new(name="Second")
    for i, p in enumerate(me.polygons):
        p.material_index = (i % 2) if mixed else 0
        p.use_smooth = (i % 3 != 0) if mixed else True
    rng = np.random.RandomState(5)
    second = rng.rand(len(me.loops) * 2).astype(np.float32)
    me.uv_layers["Second"].data.foreach_set("uv", second)
    bpy.context.view_layer.update()
    tv, tl, mi, sm, uvs = _slow_reads(me)
    arr = export._mesh_arrays(me, compat)
    assert np.array_equal(arr.tri_verts, tv) and np.array_equal(arr.tri_loops, tl)
    assert np.array_equal(arr.tri_material, mi)
    assert mi.max() == (1 if mixed else 0)
    flat = arr.tri_flat if arr.tri_flat is not None else np.zeros(len(tv), bool)
    assert np.array_equal(flat, ~sm) and flat.any() == mixed
    assert sorted(arr.uv_layers) == sorted(uvs)
    for name, a in uvs.items():
        assert np.array_equal(arr.uv_layers[name], a)
    assert np.array_equal(arr.uv_layers["Second"].reshape(-1), second)
