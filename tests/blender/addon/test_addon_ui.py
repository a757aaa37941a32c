"""Panel drawing (with a recording layout: no GUI in background), registration
of every class, and the library error shown in the panel."""
import types

import bpy
import pytest

import vsgl_indirect
from vsgl_indirect import engine, operators, runner, settings, ui


class Layout:
    def __init__(self):
        self.labels, self.props, self.ops = [], [], []
        self.use_property_split = False
        self.enabled = True

    def box(self):
        return self

    def row(self, **kw):
        return self

    def column(self, **kw):
        return self

    def label(self, text="", icon="NONE"):
        self.labels.append((text, icon))

    def prop(self, data, name, **kw):
        assert name in data.bl_rna.properties, name
        self.props.append(name)

    def operator(self, idname, **kw):
        mod, op = idname.split(".")
        assert hasattr(getattr(bpy.ops, mod), op), idname
        self.ops.append(idname)


def draw(scene):
    panel = types.SimpleNamespace(layout=Layout())
    ui.VSGL_PT_indirect.draw(panel, types.SimpleNamespace(scene=scene))
    return panel.layout


def test_panel_draws_settings_status_and_last_run(scene):
    scene.vsgl_indirect.use_advanced = True
    runner.begin(scene.name, 3)
    runner.fail(scene.name, "frame 3, view layer 'ViewLayer': light 'Key': broken")
    lay = draw(scene)
    assert {"preset", "output_path", "add_to_render", "rsm_resolution", "fit_mode",
            "visibility"} <= set(lay.props)
    assert "vsgl.preview_indirect" in lay.ops
    texts = [t for t, _ in lay.labels]
    assert any("light 'Key': broken" in t for t in texts)
    assert any(t.startswith("Last run: frame 3, failed") for t in texts)


def test_panel_shows_library_error(scene, monkeypatch):
    def broken():
        raise engine.AovError("libvsgl.so not found (tried /x). Build it with `make`")
    monkeypatch.setattr(engine, "_binding", broken)
    ok, msg = engine.library_status()
    assert not ok and "libvsgl.so not found" in msg
    lay = draw(scene)
    assert ("libvsgl.so not found (tried /x). Build it with `make`", "ERROR") in lay.labels
    assert not engine.can_render()


def test_classes_and_properties_registered():
    for mod in (settings, operators, ui):
        for cls in mod.classes:
            assert cls.is_registered, cls
    assert "vsgl_indirect" in bpy.types.Scene.bl_rna.properties
    assert vsgl_indirect.bl_info["blender"] == (3, 4, 0)


def test_property_limits_are_the_library_ranges():
    """Issue 10: the RSM range was 8..4096 here, 2..8192 in the library and
    1+ in the CLI docs. The properties take the library's (render.h via
    libvsgl.py, which tests/python/test_layout.py checks against the header)."""
    from vsgl_indirect import libvsgl
    props = bpy.types.Scene.bl_rna.properties["vsgl_indirect"].fixed_type.bl_rna.properties
    want = {"rsm_resolution": (libvsgl.RSM_RESOLUTION_MIN, libvsgl.RSM_RESOLUTION_MAX),
            "aa_samples": (1, libvsgl.AA_SAMPLES_MAX),
            "vsgl_count": (1, libvsgl.VSGL_COUNT_MAX),
            "fis_iterations": (1, libvsgl.FIS_ITERATIONS_MAX)}
    for name, (lo, hi) in want.items():
        assert (props[name].hard_min, props[name].hard_max) == (lo, hi), name
    assert (libvsgl.RSM_RESOLUTION_MIN, libvsgl.RSM_RESOLUTION_MAX) == (2, 8192)


def test_last_run_box_shows_the_memory_estimate(scene):
    runner.begin(scene.name, 4)
    res = engine.Result()
    res.path, res.summary = "/tmp/x.exr", "2 triangles"
    res.stats = {"memory_estimate": {"total": 3 << 29, "limit": 22 << 30}}
    res.timings = {"render": 0.1, "write": 0.01}
    runner.finish(scene.name, res, 0.01)
    texts = [t for t, _ in draw(scene).labels]
    assert "Memory: about 1.5 GiB of 22.0 GiB" in texts, texts
    assert "max_memory_gb" in draw(scene).props
