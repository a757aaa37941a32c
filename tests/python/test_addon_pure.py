"""Pure mapping logic of the add-on: materials (3.x and 4.x Principled),
lights, camera, paths. Independent facts: Fresnel formula,
Blender's rules. No bpy: the add-on package imports Blender only when it
registers, so this runs in the fast suite with Debian's Python."""

import numpy as np
import pytest

from vsgl_indirect import convert, materials


def desc(kind, inputs, version, linked=()):
    return materials.ShaderDesc("M", kind, inputs, linked, node="BSDF", version=version)


def test_principled_3x_specular_to_f0():
    m, w = materials.map_material(desc(materials.PRINCIPLED, {
        "Base Color": (0.2, 0.4, 0.6, 1.0), "Metallic": 0.25, "Roughness": 0.7,
        "Specular": 0.5, "IOR": 3.0, "Anisotropic": 0.3, "Anisotropic Rotation": 0.1}, (3, 4, 1)))
    assert m["specular_f0"] == pytest.approx(0.04)  # 0.08 * 0.5; IOR ignored on 3.x
    assert m["base_color"] == pytest.approx((0.2, 0.4, 0.6))
    assert (m["metallic"], m["roughness"]) == pytest.approx((0.25, 0.7))
    assert (m["anisotropy"], m["anisotropic_rotation"]) == pytest.approx((0.3, 0.1))
    # Cycles 3.x's Principled diffuse is Burley's (retro-reflection), 4.x's Lambert
    assert m["flags"] == materials.MATERIAL_FLAG_BURLEY and w == []
    m4, _ = materials.map_material(desc(materials.PRINCIPLED, {"Roughness": 0.7}, (4, 2, 0)))
    assert not m4["flags"] & materials.MATERIAL_FLAG_BURLEY
    d, _ = materials.map_material(desc(materials.DIFFUSE, {"Color": (0.1, 0.2, 0.3, 1)}, (3, 4, 1)))
    assert not d["flags"] & materials.MATERIAL_FLAG_BURLEY  # the Diffuse BSDF stays Lambert


@pytest.mark.parametrize("ior,level", [(1.5, 0.5), (1.45, 0.5), (2.0, 1.0), (1.5, 0.0)])
def test_principled_4x_ior_and_level_to_f0(ior, level):
    m, _ = materials.map_material(desc(materials.PRINCIPLED, {
        "IOR": ior, "Specular IOR Level": level, "Specular": 0.9}, (4, 2, 0)))
    expect = ((ior - 1) / (ior + 1)) ** 2 * 2 * level
    assert m["specular_f0"] == pytest.approx(min(expect, 1.0))


def test_diffuse_glossy_and_unsupported():
    d, _ = materials.map_material(desc(materials.DIFFUSE, {"Color": (0.1, 0.2, 0.3, 1)}, (4, 0, 0)))
    assert d["base_color"] == pytest.approx((0.1, 0.2, 0.3)) and d["specular_f0"] == 0
    g, _ = materials.map_material(desc(materials.GLOSSY, {"Color": (0.9, 0.8, 0.7, 1),
                                                          "Roughness": 0.2}, (3, 4, 0)))
    assert g["metallic"] == 1 and g["roughness"] == pytest.approx(0.2)
    o = materials.ShaderDesc("Weird", materials.OTHER, viewport=((0.5, 0.6, 0.7, 1), 0.3, 0.4),
                             reason="surface is a 'ShaderNodeEmission' node")
    u, w = materials.map_material(o)
    assert u["flags"] & materials.MATERIAL_UNSUPPORTED
    assert u["base_color"] == pytest.approx((0.5, 0.6, 0.7)) and u["roughness"] == pytest.approx(0.4)
    assert len(w) == 1 and "'Weird'" in w[0] and "ShaderNodeEmission" in w[0]


def test_linked_inputs_warn_with_names():
    _, w = materials.map_material(desc(materials.PRINCIPLED, {"Base Color": (1, 1, 1, 1)},
                                       (4, 0, 0), linked={"Base Color"}))
    assert len(w) == 1 and "'Base Color'" in w[0] and "'M'" in w[0]


def test_light_units_and_exposure():
    m = np.eye(4)
    f = convert.light_fields("L", "POINT", m, 100.0, (1, 0.5, 0.25), exposure=2.0, radius=0.1)
    assert f["power"] == pytest.approx(400.0) and f["color"] == pytest.approx((1, 0.5, 0.25))
    assert f["radius"] == pytest.approx(0.1) and f["type"] == 0
    s = convert.light_fields("S", "SPOT", m, 10.0, (1, 1, 1), spot_size=1.0, spot_blend=0.3)
    assert (s["type"], s["spot_size"], s["spot_blend"]) == (1, pytest.approx(1.0), pytest.approx(0.3))
    a = convert.light_fields("A", "AREA", m, 10.0, (1, 1, 1), shape="SQUARE", size=2, size_y=5)
    assert a["size_x"] == a["size_y"] == 2 and a["area_shape"] == 0
    e = convert.light_fields("E", "AREA", m, 10.0, (1, 1, 1), shape="ELLIPSE", size=2, size_y=5,
                             spread=1.0)
    assert (e["size_x"], e["size_y"], e["area_shape"], e["spread"]) == (2, 5, 3, 1.0)
    with pytest.raises(convert.ExportError, match="'X'"):
        convert.light_fields("X", "HEMI", m, 1.0, (1, 1, 1))
    # Blender 4.x+ semantics travel as a flag
    assert s["flags"] == 0
    s4 = convert.light_fields("S", "SPOT", m, 10.0, (1, 1, 1), spot_size=1.0, blender_version=(4, 2, 0))
    assert s4["flags"] == convert.LIGHT_FLAG_BLENDER_4 == 1


def test_camera_scale_removed_and_render_size():
    m = np.diag([2.0, 3.0, 4.0, 1.0])
    m[:3, 3] = (1, 2, 3)
    c = convert.camera_fields("C", "PERSP", m, 50, 36, 24, "HORIZONTAL", 7, 0.1, -0.2, 0.1, 100,
                              *convert.render_size(1920, 1080, 50))
    w = np.asarray(c["world_from_camera"]).reshape(3, 4)
    assert np.allclose(w[:, :3], np.eye(3)) and np.allclose(w[:, 3], (1, 2, 3))
    assert (c["width"], c["height"], c["sensor_fit"]) == (960, 540, 1)
    with pytest.raises(convert.ExportError, match="'C'.*PANO"):
        convert.camera_fields("C", "PANO", m, 50, 36, 24, "AUTO", 7, 0, 0, 0.1, 100, 10, 10)


def test_frame_path_template():
    p = convert.frame_path("{render_dir}/vsgl/{scene}_{view_layer}_####.exr", 7, "My Scene",
                           "View Layer", "/r")
    assert p == "/r/vsgl/My_Scene_View_Layer_0007.exr"
    assert convert.frame_path("/a/b", 12) == "/a/b_0012.exr"
    assert convert.frame_path("/a/x##.exr", 3) != convert.frame_path("/a/x##.exr", 4)


@pytest.mark.parametrize("version,color", [((3, 4, 1), "Emission"), ((4, 2, 0), "Emission Color")])
def test_principled_emission_is_a_light(version, color):
    """Emission is exported as area lights (export.py), not warned about here."""
    d = desc(materials.PRINCIPLED, {"Emission Strength": 2.0, color: (1, 0.5, 0.25, 1)}, version)
    _, w = materials.map_material(d)
    assert w == []
    assert materials.emission(d) == ((1.0, 0.5, 0.25), 2.0)
    d = desc(materials.PRINCIPLED, {"Emission Strength": 1.0, color: (0, 0, 0, 1)}, version)
    assert materials.map_material(d)[1] == [] and materials.emission(d) is None
    e = desc(materials.EMISSION, {"Strength": 3.0, "Color": (1, 1, 1, 1)}, version)
    fields, w = materials.map_material(e)
    assert w == [] and fields["base_color"] == (0.0, 0.0, 0.0) and materials.emission(e) == ((1.0, 1.0, 1.0), 3.0)


def test_library_messages_get_blender_names():
    from vsgl_indirect import engine, export
    sd = export.SceneData()
    sd.light_names = ["Key", "Fill"]
    sd.material_names = ["Floor"]
    msg = engine._name_elements("light 1: spot size is 0; material 0: NaN; light 7: x", sd)
    assert msg == "light 1 ('Fill'): spot size is 0; material 0 ('Floor'): NaN; light 7: x"


def test_batched_assemble_matches_per_instance_transform():
    from vsgl_indirect import export
    rng = np.random.RandomState(3)
    pos = rng.rand(5, 3).astype(np.float32)
    tv = np.array([[0, 1, 2], [2, 3, 4]])
    tl = np.array([[0, 1, 2], [3, 4, 5]])
    ln = rng.randn(6, 3).astype(np.float32)
    ln /= np.linalg.norm(ln, axis=1, keepdims=True)
    arr = export.MeshArrays(pos, tv, tl, ln, None, np.array([0, 1]))
    mats = []
    for i, scale in enumerate([(1, 1, 1), (-1, 2, 1), (0.5, 0.5, 3)]):
        m = np.eye(4)
        m[:3, :3] = np.diag(scale) @ np.linalg.qr(rng.randn(3, 3))[0]
        m[:3, 3] = (i, 2 * i, -i)
        mats.append(m)
    chunks = [(arr, mats[0], [4, 7]), (arr, mats[1], [5]), (arr, mats[2], [6, 8])]
    P, I, N, U, M = export.assemble(chunks)
    assert P.shape == (15, 3) and I.shape == (6, 3) and U is None
    for k, m in enumerate(mats):
        assert np.allclose(P[5 * k:5 * k + 5], convert.transform_points(m, pos), atol=1e-5)
        flip = np.linalg.det(m[:3, :3]) < 0
        order = [0, 2, 1] if flip else [0, 1, 2]
        assert np.array_equal(I[2 * k:2 * k + 2], tv[:, order] + 5 * k)
        ref = convert.transform_normals(m, ln[tl[:, order].reshape(-1)]).reshape(2, 3, 3)
        assert np.allclose(N[2 * k:2 * k + 2], ref, atol=1e-5)
    assert M.tolist() == [4, 7, 5, 5, 6, 8]


def test_multiscatter_ggx_flag_from_4_0():
    for version, want in (((3, 4, 1), 0), ((5, 0, 1), materials.MATERIAL_FLAG_MULTISCATTER)):
        d = materials.ShaderDesc("M", materials.PRINCIPLED, {"Roughness": 0.7}, node="BSDF", version=version,
                                 multiscatter=True)
        m, _ = materials.map_material(d)
        assert m["flags"] & materials.MATERIAL_FLAG_MULTISCATTER == want
    d = materials.ShaderDesc("M", materials.DIFFUSE, {"Color": (1, 1, 1, 1)}, node="BSDF", version=(5, 0, 1),
                             multiscatter=True)
    assert materials.map_material(d)[0]["flags"] == 0


def test_emissive_faces_become_area_lights_of_the_emitted_power():
    """A 2 x 1 m emissive rectangle (two triangles) of strength 3: one
    rectangular light per side whose emitted power is pi A S (radiance S):
    a Blender 3.x area light of 4 A S watts, a 4.x one of pi A S."""
    from vsgl_indirect import export
    P = np.array([(0, 0, 2), (2, 0, 2), (2, 1, 2), (0, 1, 2), (5, 5, 0), (6, 5, 0), (5, 6, 0)], np.float32)
    I = np.array([(0, 2, 1), (0, 3, 2), (4, 5, 6)], np.uint32)   # the rectangle faces down; a grey triangle
    M = np.array([1, 1, 0], np.uint32)
    for version, power in (((3, 4, 1), 4 * 2 * 3.0), ((4, 2, 0), np.pi * 2 * 3.0)):
        L = export.emissive_lights(P, I, M, {1: ((1.0, 0.5, 0.25), 3.0)}, version)
        assert len(L) == 2
        for lt in L:
            assert lt["area_shape"] == 1 and abs(lt["power"] - power) < 1e-4 * power
            assert sorted((lt["size_x"], lt["size_y"])) == [1.0, 2.0]
            assert lt["color"] == (1.0, 0.5, 0.25)
        # one emits down (-z), the other up: the light's local -Z column
        z = sorted(-np.asarray(lt["world_from_light"]).reshape(3, 4)[2, 2] for lt in L)
        assert np.allclose(z, [-1.0, 1.0], atol=1e-6)
    # a lone triangle: a disk of its area
    L = export.emissive_lights(P, I, M, {0: ((1.0, 1.0, 1.0), 1.0)})
    assert len(L) == 2 and L[0]["area_shape"] == 2
    assert abs(np.pi * (L[0]["size_x"] / 2) ** 2 - 0.5) < 1e-5


def test_degenerate_mask_matches_the_librarys_double_precision_test():
    from vsgl_indirect import export
    # zero area in double from float32 corners (as vsgl_scene_create's
    # face_normal), and zero-length corner normals; against a per-triangle
    # loop in Python floats (doubles)
    rng = np.random.RandomState(11)
    pos = (rng.randn(40, 3) * 10.0 ** rng.randint(-6, 6, (40, 1))).astype(np.float32)
    pos[5] = pos[4]                                   # coincident corners
    pos[8] = pos[6] + np.float32(0.5) * (pos[7] - pos[6])  # collinear (to float rounding)
    pos[9] = (np.inf, 0, 0)
    pos[10:13] = [(1e30, 1e30, 1e30), (1e30, -1e30, 0), (0, 1e30, 1e30)]  # an area beyond float's range, not double's
    tris = rng.randint(0, 40, (400, 3))
    tris[:6] = [[4, 5, 1], [6, 7, 8], [9, 1, 2], [10, 11, 12], [3, 3, 3], [0, 1, 2]]
    nrm = rng.randn(400, 3, 3).astype(np.float32)
    nrm[7, 1] = 0.0
    nrm[11, 2] = 1e-11
    want = []
    for t, (a, b, c) in enumerate(tris):
        p0, p1, p2 = (tuple(float(v) for v in pos[i]) for i in (a, b, c))
        e1 = [p1[k] - p0[k] for k in range(3)]
        e2 = [p2[k] - p0[k] for k in range(3)]
        cr = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        a2 = sum(v * v for v in cr)
        zero_n = any(sum(float(v) ** 2 for v in nrm[t, q]) <= 1e-20 for q in range(3))
        want.append(not (a2 > 0) or not np.isfinite(a2) or zero_n)
    with np.errstate(all="ignore"):
        got = export.degenerate_mask(pos, tris, nrm)
        got_pos = export.degenerate_mask(pos, tris)
    assert got.tolist() == want
    assert got[[0, 2, 4, 7, 11]].all() and not got[3] and not got[5]
    assert got_pos[7] == False and got_pos[0] == True  # noqa: E712


def test_triangle_cross_and_rows_equal_numpy():
    from vsgl_indirect import export
    rng = np.random.RandomState(2)
    a = rng.randn(50, 3)
    pos = rng.randn(30, 3).astype(np.float32)
    tri = rng.randint(0, 30, (40, 3))
    q = pos.astype(np.float64)[tri]
    want = np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0])
    assert np.array_equal(np.stack(export._triangle_cross(pos, tri), axis=1), want)
    idx = rng.randint(0, 50, (7, 3))
    assert np.array_equal(export._rows(a, idx), a[idx])
    k = rng.randn(2, 50, 3)
    idx2 = rng.randint(0, 50, (2, 9, 3))
    assert np.array_equal(export._per_instance(k, idx2), np.stack([k[0][idx2[0]], k[1][idx2[1]]]))
    assert np.array_equal(export._per_instance(k[:1], idx2[:1]), k[:1][0][idx2[0]][None])
