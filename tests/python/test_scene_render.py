"""Scene construction from numpy arrays (validation in Python and in the
library) and render() outputs."""

import numpy as np
import pytest

import libvsgl as L
from conftest import require
from scenes import floor_and_wall

ALL = ("vsgl_scene_create", "vsgl_scene_get_info", "vsgl_render", "vsgl_render_settings_preset")


# ---- validation in Python (no library call needed) -------------------------

@pytest.mark.parametrize("field,value,exc,words", [
    ("positions", np.zeros((4, 3)), TypeError, ["positions", "float32", "float64"]),
    ("positions", [[0, 0, 0]] * 4, TypeError, ["positions", "ndarray"]),
    ("positions", np.zeros((4, 2), np.float32), ValueError, ["positions", "shape"]),
    ("positions", np.zeros((3, 4), np.float32).T, ValueError, ["positions", "contiguous"]),
    ("indices", np.zeros((2, 3), np.int64), TypeError, ["indices", "uint32"]),
    ("indices", np.zeros((6,), np.uint32), ValueError, ["indices", "shape"]),
    ("corner_normals", np.zeros((2, 3, 3), np.float64), TypeError, ["corner_normals", "float32"]),
    ("corner_normals", np.zeros((5, 9), np.float32), ValueError, ["corner_normals", "(2, 3, 3)"]),
    ("corner_uvs", np.zeros((2, 3, 3), np.float32), ValueError, ["corner_uvs"]),
    ("corner_tangents", np.zeros((2, 3, 3), np.float32), ValueError, ["corner_tangents"]),
    ("material_indices", np.zeros((2,), np.int32), TypeError, ["material_indices", "uint32"]),
    ("materials", [object()], TypeError, ["materials[0]", "Material"]),
    ("lights", [L.Material()], TypeError, ["lights[0]", "Light"]),
    ("camera", None, ValueError, ["camera"]),
])
def test_python_side_validation(lib, ctx, field, value, exc, words):
    s = floor_and_wall(wall=False)
    s[field] = value
    with pytest.raises(exc) as e:
        L.Scene(ctx, **s)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_struct_keyword_constructors():
    m = L.Material(base_color=np.array([0.1, 0.2, 0.3]), roughness=0.5)
    assert list(m.base_color) == pytest.approx([0.1, 0.2, 0.3]) and m.reserved == 0
    T = np.arange(16.0).reshape(4, 4)
    light = L.Light(type="area", area_shape="disk", world_from_light=T)
    assert light.type == L.LightType.AREA and light.area_shape == L.AreaShape.DISK
    assert list(light.world_from_light) == list(range(12))  # 3x4 row-major, last row dropped
    with pytest.raises(TypeError):
        L.Light(colour=(1, 1, 1))
    with pytest.raises(ValueError):
        L.Camera(world_from_camera=np.eye(2))
    with pytest.raises(ValueError):
        L.Camera(type="fisheye")
    assert L.RenderSettings().size == L.ctypes.sizeof(L.vsgl_render_settings)


# ---- validation in the library ------------------------------------------

def test_library_rejects_bad_content_naming_the_element(lib, ctx):
    require(lib, "vsgl_scene_create")
    s = floor_and_wall()
    s["indices"] = s["indices"].copy()
    s["indices"][1, 2] = 99
    with pytest.raises(L.VsglError) as e:
        L.Scene(ctx, **s)
    assert e.value.code == L.Result.ERROR_INVALID_ARGUMENT and e.value.message == ctx.last_error
    assert "triangle 1" in e.value.message or "99" in e.value.message, e.value.message
    s = floor_and_wall()
    bad = L.Light.from_buffer_copy(s["lights"][0])
    bad.spot_size = 0.0
    s["lights"] = [s["lights"][0], bad]
    with pytest.raises(L.VsglError) as e:
        L.Scene(ctx, **s)
    assert "light 1" in e.value.message, e.value.message
    s = floor_and_wall()
    s["positions"] = s["positions"].copy()
    s["positions"][2, 0] = np.inf
    with pytest.raises(L.VsglError) as e:
        L.Scene(ctx, **s)
    assert "vertex 2" in e.value.message, e.value.message


def test_scene_info(lib, ctx):
    require(lib, "vsgl_scene_create", "vsgl_scene_get_info")
    s = floor_and_wall()
    # add a degenerate triangle: it is dropped with a warning
    s["indices"] = np.vstack([s["indices"], [[0, 0, 1]]]).astype(np.uint32)
    with L.Scene(ctx, **s) as scene:
        info = scene.info()
    assert info["triangle_count"] == 4 and info["dropped_triangles"] == 1
    assert info["light_count"] == 1 and info["material_count"] == 1
    P = s["positions"]
    assert info["bounds_min"] == pytest.approx(tuple(P.min(0))) and \
        info["bounds_max"] == pytest.approx(tuple(P.max(0)))
    with pytest.raises(ValueError):
        scene.info()  # closed


def test_scene_arrays_may_be_freed_after_construction(lib, ctx):
    require(lib, *ALL)
    s = floor_and_wall()
    scene = L.Scene(ctx, **s)
    s["positions"][:] = np.nan  # the library copied them
    del s
    images, _ = L.render(ctx, scene, L.render_settings_preset("preview"))
    assert np.all(np.isfinite(images["combined"]))


# ---- render ------------------------------------------------------------------

@pytest.fixture(scope="module")
def rendered(lib):
    require(lib, *ALL)
    with L.Context(thread_count=2) as ctx:
        scene = L.Scene(ctx, **floor_and_wall())
        s = L.render_settings_preset("preview")
        s.aa_samples = 1  # one sample per pixel: the identities below hold per pixel exactly
        s.edge_samples = 0
        a = L.render(ctx, scene, s)
        b = L.render(ctx, scene, s)
    return a, b


def test_render_planes_shapes_and_ranges(rendered):
    (images, stats), _ = rendered
    assert set(images) == set(L.PLANES)
    for name, a in images.items():
        assert a.dtype == np.float32
        assert a.shape == ((12, 16) if name == "alpha" else (12, 16, 3)), name
        assert np.all(np.isfinite(a)) and np.all(a >= 0), name
    assert np.all(images["alpha"] <= 1.0)
    assert images["alpha"].max() == 1.0, "the camera must see the floor"
    assert images["diffuse_light"].max() > 0, "the wall lights the floor (and back)"


def test_render_planes_documented_identities(rendered):
    (im, _), _ = rendered
    # combined = diffuse + glossy; with 1 sample per pixel light * colour = coloured
    np.testing.assert_allclose(im["combined"], im["diffuse"] + im["glossy"], rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(im["diffuse"], im["diffuse_light"] * im["diffuse_color"],
                               rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(im["glossy"], im["glossy_light"] * im["glossy_color"],
                               rtol=1e-5, atol=1e-7)
    # the floor and wall are grey 0.8: DiffCol is 0.8 wherever a surface was hit
    hit = im["alpha"] > 0
    np.testing.assert_allclose(im["diffuse_color"][hit], 0.8, rtol=1e-6)


def test_render_is_deterministic(rendered):
    (a, sa), (b, sb) = rendered
    for k in a:
        assert np.array_equal(a[k], b[k]), k
    assert sa["lights_used"] == 1 and sa["lights_skipped"] == 0 and sa["skipped"] == sb["skipped"]
    # no light skipped; the only notes are work the scene does not need (negligible specular VSGLs, faint
    # pairs, and the preset's visibility rays in a scene where nothing can block light)
    assert all("specular VSGLs under 1 %" in line or line.startswith("faint pairs: ")
               or line.startswith("visibility rays: every surface lies on")
               for line in sa["skipped"].splitlines()), sa["skipped"]
    assert sa["budget"] == ""  # one light: the settings as they are
    assert sa["vsgl_count"] == sb["vsgl_count"] >= 1 and sa["shading_pairs"] > 0
    for k in ("seconds_total", "seconds_rsm", "seconds_shade"):
        assert sa[k] >= 0


def test_render_plane_subset_and_settings_forms(lib, ctx):
    require(lib, *ALL)
    scene = L.Scene(ctx, **floor_and_wall())
    images, _ = L.render(ctx, scene, {"aa_samples": 1, "fit_mode": "two"}, planes=("combined",))
    assert list(images) == ["combined"]
    full, _ = L.render(ctx, scene, L.RenderSettings(aa_samples=1, fit_mode=L.FitMode.TWO))
    np.testing.assert_array_equal(images["combined"], full["combined"])
    with pytest.raises(ValueError):
        L.render(ctx, scene, None, planes=("beauty",))
    with pytest.raises(L.VsglError) as e:
        L.render(ctx, scene, {"method": 99})
    assert e.value.code == L.Result.ERROR_INVALID_ARGUMENT and "method" in e.value.message, \
        e.value.message


def test_render_settings_preset(lib):
    require(lib, "vsgl_render_settings_preset")
    for p in L.Preset:
        s = L.render_settings_preset(p)
        # the library's own sizeof (an older build of the same minor may know fewer fields)
        assert 0 < s.size <= L.ctypes.sizeof(L.vsgl_render_settings)
    assert L.render_settings_preset(99).as_dict() == L.render_settings_preset("balanced").as_dict()


def test_floor_alone_has_no_brute_force_indirect_light(lib, ctx):
    """Physics, independent of the method: a single plane cannot light
    itself, so the brute-force reference is exactly black on it. Alone, its
    texels have nothing in front of them and are not gathered at all
    (vsgl__rsm_drop_outward); with a speck of geometry above the floor,
    behind the camera and unlit, they are gathered and still give nothing."""
    require(lib, "vsgl_scene_create", "vsgl_reference_render")
    scene = L.Scene(ctx, **floor_and_wall(wall=False))
    images, stats = L.reference_render(ctx, scene, rsm_res=32)
    assert stats["vpl_count"] == 0
    assert np.all(images["diffuse_light"] == 0) and np.all(images["glossy_light"] == 0)
    s = floor_and_wall(wall=False)
    n = len(s["positions"])
    s["positions"] = np.vstack([s["positions"], np.array([[0, -7, 1.5], [0.01, -7, 1.5], [0, -7, 1.51]], np.float32)])
    s["indices"] = np.vstack([s["indices"], np.array([[n, n + 1, n + 2]], np.uint32)])
    images, stats = L.reference_render(ctx, L.Scene(ctx, **s), rsm_res=32)
    assert stats["vpl_count"] > 0
    assert np.all(images["diffuse_light"] == 0) and np.all(images["glossy_light"] == 0)
    scene = L.Scene(ctx, **floor_and_wall(wall=True))
    images, _ = L.reference_render(ctx, scene, rsm_res=32)
    assert images["diffuse_light"].max() > 0


def test_reference_rsm_flux_is_bounded_by_light_power(lib, ctx):
    require(lib, "vsgl_scene_create", "vsgl_reference_rsm")
    scene = L.Scene(ctx, **floor_and_wall(wall=False))
    rsm = L.reference_rsm(ctx, scene, 0, 32)
    N = len(rsm["areas"])
    assert N >= 32 * 32 and rsm["positions"].shape == (N, 3)
    lit = rsm["materials"] != 0xFFFFFFFF
    assert lit.any()
    # every lit texel lies on the floor (z = 0) with its normal facing the light (+z)
    np.testing.assert_allclose(rsm["positions"][lit][:, 2], 0.0, atol=1e-5)
    np.testing.assert_allclose(rsm["normals"][lit], [[0, 0, 1]] * int(lit.sum()), atol=1e-5)
    # the flux received cannot exceed the light's 500 W
    assert 0 < rsm["flux"].sum(0).max() <= 500.0 * 1.001


def test_debug_gbuffer_hits_the_scene(lib, ctx):
    require(lib, "vsgl_scene_create", "vsgl_debug_gbuffer")
    scene = L.Scene(ctx, **floor_and_wall())
    g = L.debug_gbuffer(ctx, scene, aa=2)
    assert g["positions"].shape == (12, 16, 4, 3) and g["materials"].shape == (12, 16, 4)
    hit = g["materials"] != 0xFFFFFFFF
    assert hit.any()
    p, n = g["positions"][hit], g["normals"][hit]
    on_floor = np.abs(p[:, 2]) < 1e-4
    on_wall = np.abs(p[:, 1] - 2) < 1e-4
    assert np.all(on_floor | on_wall)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)


def test_debug_gbuffer_frames(lib, ctx):
    require(lib, "vsgl_scene_create", "vsgl_debug_gbuffer", "vsgl_debug_gbuffer_frames")
    scene = L.Scene(ctx, **floor_and_wall())
    g = L.debug_gbuffer(ctx, scene, aa=1)
    f = L.debug_gbuffer_frames(ctx, scene, aa=1)
    hit = g["materials"] != 0xFFFFFFFF
    t, n, v = f["tangents"][hit], g["normals"][hit], f["views"][hit]
    np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, atol=1e-5)
    np.testing.assert_allclose(np.sum(t * n, axis=1), 0.0, atol=1e-5)
    np.testing.assert_allclose(np.linalg.norm(f["views"], axis=-1), 1.0, atol=1e-5)
    # the view direction points from the surface point to the camera at (0, -6, 1.5)
    to_cam = np.array([0, -6, 1.5]) - g["positions"][hit]
    to_cam /= np.linalg.norm(to_cam, axis=1, keepdims=True)
    np.testing.assert_allclose(v, to_cam, atol=1e-4)


# ---- memory limit (issue 10) -----------------------------------------------

def test_render_estimate_and_memory_limit(lib):
    """A render above the context's max_memory is refused before the output
    arrays are allocated, naming the size, the estimate and the limit; the
    estimate is the documented sum of its parts and is returned in stats."""
    require(lib, "vsgl_render_estimate")
    s = floor_and_wall(width=640, height=480)
    with L.Context(max_memory=1 << 20) as small:
        scene = L.Scene(small, **s)
        try:
            with pytest.raises(L.VsglError) as e:
                L.render(small, scene, L.render_settings_preset("balanced"))
            assert e.value.code == L.Result.ERROR_OUT_OF_MEMORY
            # balanced's 2 x 2 samples: 1 from 320 x 240 pixels up (aa_pixel_limit)
            assert "render: 640x480 with aa 1 and RSM 256 needs about" in e.value.message
            assert "more than the memory limit of 1.0 MiB (max_memory)" in e.value.message
        finally:
            scene.close()
    with L.Context() as ctx:
        scene = L.Scene(ctx, **s)
        try:
            est = L.render_estimate(ctx, scene, L.render_settings_preset("balanced"), planes=("combined", "alpha"))
            assert est["output"] == 640 * 480 * 4 * 4
            # one sample per pixel (aa_pixel_limit) with two more slots for edges, each + edge weight
            # and normal spread, and the edge mask; 2 x 2 samples without the limit
            assert est["gbuffer"] == 640 * 480 * (3 * (56 + 8) + 1)
            unlimited = L.render_settings_preset("balanced")
            unlimited.aa_pixel_limit = 0
            full = L.render_estimate(ctx, scene, unlimited, planes=("combined", "alpha"))
            assert full["gbuffer"] == 640 * 480 * (4 * (56 + 8) + 1)
            assert est["total"] == sum(est[k] for k in ("output", "gbuffer", "planes", "rsm", "fit", "shade"))
            assert est["limit"] > est["total"]
            with pytest.raises(L.VsglError) as e:
                L.render_estimate(ctx, scene, dict(rsm_resolution=16384))
            assert e.value.message == "settings: rsm_resolution is 16384 (valid 2..8192)"
            _, stats = L.render(ctx, scene, L.render_settings_preset("preview"), planes=("combined",))
            assert stats["memory_estimate"]["total"] > 0
        finally:
            scene.close()
    with pytest.raises(ValueError):
        L.Context(max_memory=-1)


def test_render_glossy_mode_mrp(lib, ctx):
    """glossy_mode MRP (rectangle proxies, docs/mrp.md) through the binding:
    finite, non-negative, and the diffuse pass unchanged."""
    require(lib, *ALL)
    scene = L.Scene(ctx, **floor_and_wall())
    base = {"aa_samples": 1, "fit_mode": "two"}
    asg, _ = L.render(ctx, scene, base, planes=("diffuse", "glossy"))
    mrp, _ = L.render(ctx, scene, dict(base, glossy_mode=L.GlossyMode.MRP), planes=("diffuse", "glossy"))
    assert np.all(np.isfinite(mrp["glossy"])) and np.all(mrp["glossy"] >= 0)
    np.testing.assert_array_equal(mrp["diffuse"], asg["diffuse"])
    assert L.GlossyMode.MRP == 3


def test_render_glossy_mode_hybrid(lib, ctx):
    """glossy_mode HYBRID (MRP per pixel where it applies, docs/mrp.md §4)
    through the binding: finite, non-negative, ASG2's diffuse pass."""
    require(lib, *ALL)
    scene = L.Scene(ctx, **floor_and_wall())
    base = {"aa_samples": 1, "fit_mode": "two"}
    asg2, _ = L.render(ctx, scene, dict(base, glossy_mode=L.GlossyMode.ASG2), planes=("diffuse", "glossy"))
    hyb, _ = L.render(ctx, scene, dict(base, glossy_mode=L.GlossyMode.HYBRID), planes=("diffuse", "glossy"))
    assert np.all(np.isfinite(hyb["glossy"])) and np.all(hyb["glossy"] >= 0)
    np.testing.assert_array_equal(hyb["diffuse"], asg2["diffuse"])
    assert L.GlossyMode.HYBRID == 4


def test_auto_preset_says_what_it_chose(lib, ctx):
    """The auto preset (render.h, VSGL_PRESET_AUTO): balanced's knobs with auto_target set; the render says
    what it chose in stats["budget"], and rendering balanced with those knobs by hand gives the same pixels."""
    require(lib, *ALL)
    a = L.render_settings_preset("auto")
    b = L.render_settings_preset("balanced")
    assert a.auto_target == L.AUTO_BALANCED and b.auto_target == L.AUTO_OFF
    knobs = lambda s: {k: v for k, v in s.as_dict().items() if k != "auto_target"}  # noqa: E731
    assert knobs(a) == knobs(b)
    scene = L.Scene(ctx, **floor_and_wall())
    im, st = L.render(ctx, scene, a)
    lines = st["budget"].splitlines()
    assert lines[0].startswith("auto: aa ") and lines[1].startswith("auto: glossy "), st["budget"]
    rsm = int(next(x for x in lines if x.startswith("light 0:")).split("RSM ")[1].split()[0])
    aa = int(lines[0].split()[2].rstrip(":"))
    by_hand = L.render_settings_preset("balanced")
    by_hand.aa_samples, by_hand.rsm_resolution = aa, rsm
    if "glossy asg (not" in st["budget"]:
        by_hand.glossy_mode = L.GlossyMode.ASG
    im2, st2 = L.render(ctx, scene, by_hand)
    for k in im:
        assert np.array_equal(im[k], im2[k]), k
    assert st2["budget"] == ""
    with pytest.raises(L.VsglError) as e:
        L.render(ctx, scene, {"auto_target": 5})
    assert e.value.code == L.Result.ERROR_INVALID_ARGUMENT and "auto_target" in e.value.message
