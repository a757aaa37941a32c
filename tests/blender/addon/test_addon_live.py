"""The live viewport preview (viewport.py, live.py): the viewport camera
against Blender's own projection, the scheduler's supersede/cancel rules,
the mesh cache, and the live render against the F12 path."""
import threading
import time

import bpy
import numpy as np
import pytest

from conftest import camera, cube, link, room
from vsgl_indirect import engine, export, live, viewport
from vsgl_indirect.config import Options


def _projection(cam, depsgraph, w, h):
    return cam.calc_matrix_camera(depsgraph, x=w, y=h, scale_x=1.0, scale_y=1.0)


@pytest.mark.parametrize("kind,w,h,shift", [("PERSP", 96, 54, (0.0, 0.0)), ("PERSP", 60, 80, (0.1, -0.05)),
                                            ("ORTHO", 96, 54, (0.07, 0.03))])
def test_view_camera_matches_blenders_projection(scene, kind, w, h, shift):
    """A camera described by its view and projection matrices (what a 3D
    viewport gives) must project every point where Blender's camera does:
    compare the library camera's fields with the export of the camera itself."""
    cam = camera(scene, location=(0.3, -5, 1.2), rotation=(1.35, 0.0, 0.2), lens=42.0)
    cam.data.type = kind
    cam.data.ortho_scale = 5.5
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.shift_x, cam.data.shift_y = shift
    cam.data.clip_start, cam.data.clip_end = 0.2, 80.0
    scene.render.resolution_x, scene.render.resolution_y = w, h
    dg = bpy.context.evaluated_depsgraph_get()
    P = _projection(cam, dg, w, h)
    V = cam.matrix_world.inverted()
    got = live.view_camera(V, P, w, h, 0.2, 80.0)
    from vsgl_indirect import compat
    sd = export.SceneData()
    export._add_camera(sd, scene, dg, compat)
    want = sd.camera
    assert got["type"] == want["type"]
    assert got["width"], got["height"] == (w, h)
    if kind == "PERSP":
        # lens / sensor width is what matters (36 mm sensor here)
        assert got["lens_mm"] / got["sensor_width_mm"] == pytest.approx(
            want["lens_mm"] / want["sensor_width_mm"], rel=1e-5)
        np.testing.assert_allclose(got["world_from_camera"], want["world_from_camera"], atol=1e-5)
    else:
        assert got["ortho_scale"] == pytest.approx(want["ortho_scale"], rel=1e-5)
        # the ortho camera is moved back along its axis; its rotation is the same
        g = np.array(got["world_from_camera"]).reshape(3, 4)
        e = np.array(want["world_from_camera"]).reshape(3, 4)
        np.testing.assert_allclose(g[:, :3], e[:, :3], atol=1e-5)
        np.testing.assert_allclose(np.cross(g[:, 3] - e[:, 3], e[:, 2]), 0, atol=1e-4)
    assert (got["shift_x"], got["shift_y"]) == pytest.approx(shift, abs=1e-5)


def test_scheduler_renders_first_and_last_of_a_burst():
    r = live.LiveRenderer()
    started, release = threading.Event(), threading.Event()
    ran = []

    def slow(job):
        ran.append(job.key)
        started.set()
        while not job.cancelled.is_set() and not release.is_set():
            time.sleep(0.001)
        return "slow"

    def quick(tag):
        def work(job):
            ran.append(job.key)
            return tag
        return work

    a = r.submit("a", slow)
    assert started.wait(5)
    r.submit("b", quick("b"))
    r.submit("c", quick("c"))
    assert r.wait(5)
    assert a.cancelled.is_set()
    assert ran == ["a", "c"] and r.dropped == 1        # b superseded before it ran
    got = r.poll()
    assert got is not None and got[2] == "c" and got[1] == "c"
    assert r.poll() is None                           # delivered once
    assert r.submit("c", quick("c")) is None          # same key: nothing to do
    r.submit("d", lambda job: 1 / 0)
    assert r.wait(5) and r.errors and "division" in r.errors[0]


def test_display_rgba_is_srgb_bottom_up():
    rgb = np.zeros((2, 3, 3), np.float32)
    rgb[0, 0] = (0.18, 1.0, 4.0)      # top-left
    rgb[1, 2] = (np.nan, -1, 0.002)
    out = live.display_rgba(rgb, exposure=0.0)
    assert out.shape == (2, 3, 4) and out.dtype == np.float32
    top_left = out[1, 0]               # the texture's last row is the image's top
    # a table lookup: within a quarter of an 8-bit display step of the formula
    assert top_left[0] == pytest.approx(1.055 * 0.18 ** (1 / 2.4) - 0.055, abs=1e-3)
    assert top_left[1] == pytest.approx(1.0) and top_left[2] == pytest.approx(1.0)
    assert np.all(np.isfinite(out)) and out[0, 2, 0] == 0 and out[0, 2, 1] == 0
    assert out[0, 2, 2] == pytest.approx(0.002 * 12.92, abs=1e-3)
    ramp = np.linspace(0, 1, 5000, dtype=np.float32)[None, :, None].repeat(3, axis=2)
    exact = np.where(ramp <= 0.0031308, ramp * 12.92, 1.055 * np.power(ramp, 1 / 2.4) - 0.055)
    assert np.abs(live.display_rgba(ramp)[0, :, :3] - exact).max() < 1.0 / 255 / 4
    assert np.all(out[..., 3] == 1)
    assert live.display_rgba(np.full((1, 1, 3), 0.1, np.float32), exposure=1.0)[0, 0, 0] == \
        pytest.approx(live.display_rgba(np.full((1, 1, 3), 0.2, np.float32))[0, 0, 0], rel=1e-6)


def test_mesh_cache_reads_only_changed_geometry(scene, monkeypatch):
    room(scene)
    box = link(scene, cube("Box", 1.0, (0.5, 1.0, 0.5)))
    dg = bpy.context.evaluated_depsgraph_get()
    cache = {}
    a = export.collect(dg, scene, camera=False, mesh_cache=cache)
    meshes = lambda: len([k for k in cache if k != export._ASSEMBLED])  # noqa: E731
    assert a.camera is None and meshes() == 3
    reads = []
    real = export._mesh_arrays
    monkeypatch.setattr(export, "_mesh_arrays", lambda *k, **kw: reads.append(1) or real(*k, **kw))
    bpy.data.objects["Spot"].location.x += 0.5       # a light moved: no mesh is read
    dg = bpy.context.evaluated_depsgraph_get()
    b = export.collect(dg, scene, camera=False, mesh_cache=cache)
    assert reads == []
    np.testing.assert_array_equal(a.positions, b.positions)
    assert b.positions is a.positions           # the assembly was reused too
    assert not np.array_equal(a.lights[0]["world_from_light"], b.lights[0]["world_from_light"])
    # the box's geometry changes: the session drops its entry, only it is read again
    s = viewport._Session(0)
    s.mesh_cache = cache
    box.data.vertices[0].co.z -= 0.25
    box.data.update()
    dg = bpy.context.evaluated_depsgraph_get()

    class U:
        def __init__(self, idb):
            self.id, self.is_updated_geometry = idb, True

    class D:
        updates = [U(box.evaluated_get(dg))]
    monkeypatch.setattr(viewport, "_SESSION", s)
    viewport._on_depsgraph_update(scene, D())
    assert meshes() == 2
    c = export.collect(dg, scene, camera=False, mesh_cache=cache)
    assert len(reads) == 1 and not np.array_equal(b.positions, c.positions)


def test_live_render_equals_the_f12_path(scene):
    """The worker's render of a viewport at the scene camera's view is the
    preview preset's Combined pass of the normal path, pixel for pixel."""
    room(scene)
    w, h = 48, 27
    scene.render.resolution_x, scene.render.resolution_y = w, h
    dg = bpy.context.evaluated_depsgraph_get()
    cam = scene.camera
    sd = export.collect(dg, scene, camera=False, mesh_cache={})
    sd.camera = live.view_camera(cam.matrix_world.inverted(), _projection(cam, dg, w, h), w, h,
                                 cam.data.clip_start, cam.data.clip_end)
    sd.width, sd.height = w, h
    s = viewport._Session(0)
    job = live.Job(1, "k")
    try:
        out = viewport._render(s, sd, "PREVIEW", 0, job, 0.0, 0.0)
    finally:
        s.close()
    ref_sd = export.collect(dg, scene)
    planes, _ = engine.render_planes(ref_sd, Options(enabled=True, preset="PREVIEW"))
    want = live.display_rgba(planes["combined"])
    assert out["width"] == w and out["height"] == h
    assert float(planes["combined"].mean()) > 0
    np.testing.assert_allclose(out["rgba"], want, atol=2e-3)
    assert {"export", "scene", "render", "encode", "gbuffer", "shade"} <= set(out["timings"])


def test_live_quality_is_the_preview_preset_sparser():
    """The panel's Live quality: the preview preset with LIVE_OVERRIDES and
    nothing else changed; the presets pass through unchanged."""
    lib = engine._binding()
    prev = lib.render_settings_preset(lib.Preset.PREVIEW)
    lv = live.render_settings(lib, "LIVE", 960 * 540)
    assert live.LIVE_OVERRIDES == {"shade_stride": 4, "stride_pixels": 0, "edge_samples": 0, "visibility": 0,
                                   "glossy_mode": 0}
    assert (lv.shade_stride, lv.stride_pixels, lv.edge_samples, lv.visibility, lv.glossy_mode) == \
        (4, 0, 0, 0, lib.GlossyMode.ASG)
    assert prev.stride_pixels == 320 * 240  # the presets' stride grows above 320 x 240; Live's stays 4
    assert prev.visibility == lib.Visibility.RAY and prev.glossy_mode == lib.GlossyMode.ASG2
    for name, _ in lv._fields_:
        if name not in live.LIVE_OVERRIDES:
            assert getattr(lv, name) == getattr(prev, name), name
    for q in ("PREVIEW", "BALANCED"):
        a, b = live.render_settings(lib, q, 960 * 540), lib.render_settings_preset(getattr(lib.Preset, q))
        assert all(getattr(a, n) == getattr(b, n) for n, _ in a._fields_), q


def test_live_render_is_cancelled_when_superseded(scene):
    room(scene)
    dg = bpy.context.evaluated_depsgraph_get()
    sd = export.collect(dg, scene)
    sd.width, sd.height = sd.camera["width"], sd.camera["height"] = 640, 360
    s = viewport._Session(0)
    job = live.Job(1, "k")
    job.cancelled.set()
    try:
        assert viewport._render(s, sd, "PREVIEW", 0, job, 0.0, 0.0) is None
    finally:
        s.close()


def test_operator_and_panel_register():
    assert hasattr(bpy.types.WindowManager, "vsgl_live")
    props = bpy.context.window_manager.vsgl_live
    assert props.quality == "LIVE" and props.scale == 2 and props.display == "INDIRECT"
    assert props.coarse == live.COARSE_DEFAULT == 2
    for p in props.bl_rna.properties:
        if p.identifier != "rna_type":
            assert len(p.description) > 20, p.identifier
    assert hasattr(bpy.types, "VIEW3D_PT_vsgl_live")
    assert hasattr(bpy.ops.vsgl, "live_preview")


def test_live_keeps_the_library_scene_while_geometry_stands_still(scene):
    """A light edit reuses the library scene (vsgl_scene_set_view) and gives
    the image a new scene would; a geometry edit builds a new one."""
    room(scene)
    w, h = 40, 30
    scene.render.resolution_x, scene.render.resolution_y = w, h
    s = viewport._Session(0)
    cache = {}

    def live_render():
        dg = bpy.context.evaluated_depsgraph_get()
        sd = export.collect(dg, scene, mesh_cache=cache)
        return sd, viewport._render(s, sd, "PREVIEW", 0, live.Job(1, "k"), 0.0, 0.0)

    try:
        live_render()
        bpy.data.objects["Spot"].location.x += 0.7
        sd, moved = live_render()
        assert s.scene_builds == 1
        assert moved["reused"] == 1            # the G-buffer (libvsgl.REUSED_GBUFFER)
        planes, _ = engine.render_planes(sd, Options(enabled=True, preset="PREVIEW"))
        np.testing.assert_array_equal(moved["rgba"], live.display_rgba(planes["combined"]))
        bpy.data.objects["Wall"].location.z += 0.3
        cache.clear()
        live_render()
        assert s.scene_builds == 2
    finally:
        s.close()


def test_scene_signature_sees_textures_and_materials():
    """The live preview rebuilds its library scene when anything but camera
    and lights changed: a texture's pixels or flags, a material, geometry."""
    sd = export.SceneData()
    sd.positions = np.zeros((3, 3), np.float32)
    sd.indices = np.array([[0, 1, 2]], np.uint32)
    sd.materials = [dict(base_color=(0.5, 0.5, 0.5))]
    sd.textures = [(np.zeros((2, 2, 4), np.float32), 1)]
    a = viewport._scene_signature(sd)
    assert viewport._equal(a, viewport._scene_signature(sd))
    sd.lights = [dict(power=5.0)]                       # lights are not part of it
    assert viewport._equal(a, viewport._scene_signature(sd))
    pix = sd.textures[0][0].copy()
    pix[1, 1, 0] = 0.25
    sd.textures = [(pix, 1)]
    assert not viewport._equal(a, viewport._scene_signature(sd))
    sd.textures = [(np.zeros((2, 2, 4), np.float32), 0)]
    assert not viewport._equal(a, viewport._scene_signature(sd))
    sd.textures = [(np.zeros((2, 2, 4), np.float32), 1)]
    sd.materials = [dict(base_color=(0.5, 0.5, 0.6))]
    assert not viewport._equal(a, viewport._scene_signature(sd))


def test_navigation_schedule_coarse_while_moving_full_at_rest():
    """live.NavigationSchedule, on a fake clock: each view change starts a
    coarse render at once (never two at a time), a rest of the debounce the
    full one; a scene edit only the full one; coarse 1 is the old debounce."""
    s = live.NavigationSchedule(coarse=2, debounce=0.04)
    assert s.tick(0.00, "v0") == "coarse"              # the first view: a quick coarse image
    assert s.tick(0.02, "v1") == "coarse"              # moving: at once, no debounce
    assert s.tick(0.04, "v2", coarse_busy=True) is None   # one coarse render at a time...
    assert s.tick(0.05, "v2", coarse_busy=True) is None
    assert s.tick(0.06, "v2") == "coarse"              # ...the newest view when it ends
    assert s.tick(0.07, "v2") is None                  # resting, within the debounce
    assert s.tick(0.079, "v2") is None
    assert s.tick(0.081, "v2") == "full"               # rested 40 ms since the last change (0.04)
    assert s.tick(0.2, "v2") is None and s.dirty_since is None
    s.edited(0.30)                                     # a light moved: no coarse render
    assert s.tick(0.31, "v2") is None and s.tick(0.339, "v2") is None
    assert s.tick(0.341, "v2") == "full"
    s.edited(0.40)                                     # an edit while the view moves
    assert s.tick(0.41, "v3") == "coarse" and s.tick(0.43, "v4") == "coarse"
    assert s.tick(0.46, "v4") is None and s.tick(0.471, "v4") == "full"
    off = live.NavigationSchedule(coarse=1, debounce=0.04)
    assert [off.tick(t, "v%d" % i) for i, t in enumerate((0.0, 0.02, 0.04))] == [None] * 3
    assert off.tick(0.07, "v2") is None and off.tick(0.081, "v2") == "full"


def test_scheduler_lets_a_coarse_render_end_and_cancels_a_full_one():
    """A full render is cancelled by a newer submit; a coarse one
    (interruptible=False) runs to its end and its image is delivered, while
    a newer coarse one waiting behind it is replaced by the newest."""
    r = live.LiveRenderer()
    started = {k: threading.Event() for k in ("f1", "c1", "f2")}
    release = threading.Event()
    ran = []

    def slow(job):
        ran.append(job.key)
        started[job.key].set()
        while not job.cancelled.is_set() and not release.is_set():
            time.sleep(0.001)
        return None if job.cancelled.is_set() else job.key

    f1 = r.submit("f1", slow)
    assert started["f1"].wait(5)
    c1 = r.submit("c1", slow, interruptible=False)     # the view moves: the full render is superseded
    assert started["c1"].wait(5) and f1.cancelled.is_set()
    assert r.busy_uninterruptible()
    r.submit("c2", slow, interruptible=False)          # waits behind c1 ...
    f2 = r.submit("f2", slow)                          # ... replaced by the rest's full render
    assert not c1.cancelled.is_set() and r.dropped == 1
    release.set()
    assert r.wait(5)
    assert ran == ["f1", "c1", "f2"] and not f2.cancelled.is_set()
    assert r.poll()[2] == "f2" and not r.busy_uninterruptible()
    release.clear()
    c3 = r.submit("c3", lambda job: "c3", interruptible=False)
    assert r.wait(5) and not c3.cancelled.is_set() and r.poll()[2] == "c3"


def test_live_navigation_renders_coarse_then_the_full_image(scene):
    """The timer's logic without a viewport: views change on every tick for
    a while (coarse renders at 1/2 x 1/2 through the session's one cache,
    with a full render superseded and cancelled on the way), then rest: the
    last image is the full one, equal to a plain (uncached) library render
    of that view with the Live settings and to a session that never went
    coarse."""
    room(scene)
    w, h = 48, 28
    scene.render.resolution_x, scene.render.resolution_y = w, h
    cam = scene.camera
    mesh_cache = {}
    s = viewport._Session(0)
    sch = live.NavigationSchedule(coarse=2, debounce=0.04)
    shown = []

    def view_sd(x, div):
        cam.location.x = x
        d = bpy.context.evaluated_depsgraph_get()
        vw, vh = live.internal_size(w, h, div)
        sd = export.collect(d, scene, camera=False, mesh_cache=mesh_cache)
        sd.camera = live.view_camera(cam.matrix_world.inverted(), _projection(cam, d, vw, vh), vw, vh,
                                     cam.data.clip_start, cam.data.clip_end)
        sd.width, sd.height = vw, vh
        return sd

    x0 = cam.location.x
    try:
        views = [x0 + 0.02 * i for i in range(5)]
        t = 0.0
        for tick in range(12):
            t = 0.02 * tick
            x = views[min(tick, len(views) - 1)]
            what = sch.tick(t, x, coarse_busy=s.renderer.busy_uninterruptible())
            if what is not None:
                div = sch.coarse if what == "coarse" else 1
                sd = view_sd(x, div)
                s.renderer.submit((x, div), lambda job, sd=sd: viewport._render(s, sd, "LIVE", 0, job, 0.0, 0.0),
                                  interruptible=div == 1)
                s.renderer.wait(30)                    # renders are quick here: each ends before the next tick
                got = s.renderer.poll()
                shown.append((what, x, got[2]["width"], got[2]["height"], got[2]))
            if tick == 2:                              # a full render superseded by the next view
                gate, started = threading.Event(), threading.Event()

                def held(job, sd=view_sd(x, 1)):
                    started.set()
                    gate.wait(5)
                    return viewport._render(s, sd, "LIVE", 0, job, 0.0, 0.0)
                full = s.renderer.submit(("held", x), held)
                assert started.wait(5)
                s.renderer.submit(("moved", x), lambda job, sd=view_sd(x, 2): viewport._render(
                    s, sd, "LIVE", 0, job, 0.0, 0.0), interruptible=False)
                assert full.cancelled.is_set()
                gate.set()
                assert s.renderer.wait(30)
                assert s.renderer.poll()[2]["width"] == w // 2
        coarse = [v for v in shown if v[0] == "coarse"]
        assert len(coarse) == len(views) and all((v[2], v[3]) == (w // 2, h // 2) for v in coarse)
        assert shown[-1][:4] == ("full", views[-1], w, h)
        assert [v[0] for v in shown].count("full") == 1
        refine = shown[-1][4]
        fresh = viewport._Session(0)
        try:
            plain = viewport._render(fresh, view_sd(views[-1], 1), "LIVE", 0, live.Job(1, "k"), 0.0, 0.0)
        finally:
            fresh.close()
        np.testing.assert_array_equal(refine["rgba"], plain["rgba"])
        ref_sd = view_sd(views[-1], 1)
        lib = engine._binding()
        arrays = engine.scene_arrays(ref_sd, lib)
        ctx = lib.Context(log_level=lib.LogLevel.ERROR)
        try:
            sc = lib.Scene(ctx, **arrays)
            try:
                images, _ = lib.render(ctx, sc, live.render_settings(lib, "LIVE"), ("combined",))
            finally:
                sc.close()
        finally:
            ctx.close()
        np.testing.assert_array_equal(refine["rgba"], live.display_rgba(images["combined"]))
    finally:
        cam.location.x = x0
        s.close()
