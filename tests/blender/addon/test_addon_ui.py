"""The panel and its subpanels drawn with a recording layout (no GUI in the
background; docs/img/ has the real ones, tools/panel_screenshots.sh), every
property's label and tooltip, the knobs' presets, greying and marks, the
double-counting check and its operators, the select-named operator."""
import json
import types

import bpy
import pytest

import vsgl_indirect
from conftest import room
from vsgl_indirect import checks, config, engine, operators, runner, settings, ui


class Layout:
    """Records what a draw() puts in a layout: labels, props and operators,
    each with the effective active/enabled of its ancestors."""

    def __init__(self, parent=None, root=None):
        self.parent = parent
        self.root = root or self
        self.active = True
        self.enabled = True
        self.alert = False
        self.alignment = "EXPAND"
        self.use_property_split = parent.use_property_split if parent else False
        self.use_property_decorate = True
        if root is None:
            self.labels, self.props, self.ops = [], [], []

    def _state(self):
        a = e = True
        n = self
        while n is not None:
            a, e, n = a and n.active, e and n.enabled, n.parent
        return a, e

    def _child(self, *args, **kw):
        return Layout(self, self.root)

    box = row = column = split = grid_flow = column_flow = _child

    def label(self, text="", icon="NONE", **kw):
        self.root.labels.append((text, icon))

    def separator(self, **kw):
        pass

    def prop(self, data, name, **kw):
        assert name in data.bl_rna.properties, name
        a, e = self._state()
        self.root.props.append(types.SimpleNamespace(name=name, active=a, enabled=e, kw=kw))

    def operator(self, idname, **kw):
        mod, op = idname.split(".")
        assert hasattr(getattr(bpy.ops, mod), op), idname
        a, e = self._state()
        rec = types.SimpleNamespace(idname=idname, active=a, enabled=e, kw=kw)
        self.root.ops.append(rec)
        return rec


def context_for(scene):
    return types.SimpleNamespace(scene=scene, view_layer=scene.view_layers[0],
                                 region=types.SimpleNamespace(width=300),
                                 preferences=bpy.context.preferences)


PANELS = ui.classes


def draw(scene, panels=PANELS):
    """Draw ``panels`` into one recording layout (headers included)."""
    lay = Layout()
    ctx = context_for(scene)
    for cls in panels:
        panel = types.SimpleNamespace(layout=Layout(lay, lay))
        if hasattr(cls, "draw_header"):
            cls.draw_header(panel, ctx)
        if getattr(cls, "poll", None) and not cls.poll(ctx):
            continue
        cls.draw(panel, ctx)
    return lay


def props_by_name(lay):
    return {p.name: p for p in lay.props}


def texts(lay):
    return [t for t, _ in lay.labels]


def test_every_panel_draws_every_setting(scene):
    scene.vsgl_indirect.enabled = True
    lay = draw(scene)
    drawn = set(props_by_name(lay))
    hidden = {n for n, p in settings.VSGLIndirectSettings.bl_rna.properties.items()
              if "HIDDEN" in p.is_hidden.__class__.__name__ or n in ("rna_type", "name", "cycles_saved")}
    every = set(settings.VSGLIndirectSettings.bl_rna.properties.keys()) - hidden
    assert every <= drawn, every - drawn
    assert {o.idname for o in lay.ops} >= {"vsgl.preview_indirect", "vsgl.remove_compositor_nodes",
                                           "vsgl.setup_compositor"}
    assert [c.bl_label for c in PANELS[1:]] == ["Quality", "Lights & Materials", "Output",
                                                "Compositing", "Last Run"]
    assert all(c.bl_parent_id == "VSGL_PT_indirect" for c in PANELS[1:])


def test_header_toggle_is_labelled_and_off_greys_the_contents(scene):
    label = settings.VSGLIndirectSettings.bl_rna.properties["enabled"].name
    assert label == "VSGL Indirect Light"
    scene.vsgl_indirect.enabled = False
    lay = draw(scene)
    enabled = [p for p in lay.props if p.name == "enabled"]
    assert enabled and enabled[0].kw.get("text") is None   # the property's own label
    others = [p for p in lay.props if p.name != "enabled"]
    assert others and not any(p.active for p in others), [p.name for p in others if p.active]
    scene.vsgl_indirect.enabled = True
    lay = draw(scene)
    assert props_by_name(lay)["preset"].active


def _rna(name):
    return settings.VSGLIndirectSettings.bl_rna.properties[name]


def test_every_property_and_enum_item_has_a_label_and_a_tooltip():
    from vsgl_indirect import viewport
    for group in (settings.VSGLIndirectSettings, viewport.VSGLLiveProps):
        for name, p in group.bl_rna.properties.items():
            if name in ("rna_type", "name"):
                continue
            assert p.name and p.name != name, (group, name, p.name)
            assert len(p.description) >= 30, (group, name, p.description)
            if p.type == "ENUM":
                for item in p.enum_items:
                    assert item.name and len(item.description) >= 20, (group, name, item.identifier)
    # proper names, not title-cased identifiers
    assert _rna("method").enum_items["VSGL"].name == "VSGL"
    assert _rna("glossy_mode").enum_items["ASG"].name == "ASG"
    assert _rna("fit_mode").enum_items["TWO"].name == "Two per Light"
    assert _rna("fit_mode").enum_items["KMEANS"].name == "k-means"


def test_knob_tooltips_carry_figures():
    """Cost and benefit, with numbers (docs/accuracy.md)."""
    import re
    for name in list(config.KNOBS) + ["preset"]:
        p = _rna(name)
        blobs = [p.description] + ([i.description for i in p.enum_items] if p.type == "ENUM" else [])
        if name not in ("sharpness_estimator", "seed", "method", "leak_correction"):
            assert any(re.search(r"\d", b) for b in blobs), name
    for item in _rna("preset").enum_items:
        assert re.search(r"\d+(\.\d+)? s\b", item.description) and "%" in item.description or \
            "relMSE" in item.description, item.identifier


def test_preset_table_matches_the_library():
    from vsgl_indirect import libvsgl
    try:
        libvsgl.library()
    except Exception as e:
        pytest.skip("no libvsgl: %s" % e)
    for p in config.PRESETS:
        s = libvsgl.render_settings_preset(p)
        d = s.as_dict() if hasattr(s, "as_dict") else {k: getattr(s, k) for k, _ in s._fields_}
        for k, v in config.PRESET_VALUES[p].items():
            got = d[k]
            enum = libvsgl.vsgl_render_settings._enums.get(k)
            if enum is not None and not isinstance(got, str):
                got = enum(got).name
            assert config.same_knob_value(got, v) if isinstance(v, float) else str(got).upper() == str(v).upper(), \
                (p, k, got, v)


def test_knob_defaults_are_the_balanced_preset_and_advanced_starts_from_the_preset(scene):
    props = scene.vsgl_indirect
    assert config.differing_knobs(props, "BALANCED") == []
    o = config.Options.from_props(props)
    o.use_advanced = True
    got, want = o.render_settings()[1], config.PRESET_VALUES["BALANCED"]
    assert got.keys() == want.keys() and all(config.same_knob_value(got[k], want[k]) for k in want), (got, want)
    # Picking Preview, then ticking Advanced: the knobs are Preview's.
    props.preset = "PREVIEW"
    settings._update_preset(props, bpy.context)
    props.use_advanced = True
    settings._update_advanced(props, bpy.context)
    assert config.differing_knobs(props) == []
    assert props.vsgl_count == 32 and props.aa_samples == 1
    # An edit is kept when Advanced is ticked again, and marked.
    props.vsgl_count = 64
    props.use_advanced = False
    props.use_advanced = True
    settings._update_advanced(props, bpy.context)
    assert props.vsgl_count == 64
    lay = draw(scene, [ui.VSGL_PT_lights_materials])
    assert props_by_name(lay)["vsgl_count"].kw.get("icon") == "MODIFIER_ON"
    assert "Preview: 32" in texts(lay)
    assert props_by_name(lay)["rsm_resolution"].kw.get("icon") is None
    lay = draw(scene, [ui.VSGL_PT_quality])
    assert any(t.startswith("1 knob(s) differ from Preview") for t in texts(lay))
    assert any(o.idname == "vsgl.reset_knobs" for o in lay.ops)
    assert bpy.ops.vsgl.reset_knobs() == {"FINISHED"}
    assert props.vsgl_count == 32


def test_knobs_editable_only_with_advanced_and_inapplicable_ones_greyed(scene):
    props = scene.vsgl_indirect
    props.enabled = True
    lay = props_by_name(draw(scene))
    assert not lay["vsgl_count"].enabled and not lay["aa_samples"].enabled
    props.use_advanced = True
    props.fit_mode = "TWO"
    lay = props_by_name(draw(scene))
    assert lay["aa_samples"].enabled and lay["aa_samples"].active
    assert lay["vsgl_count"].enabled and not lay["vsgl_count"].active
    assert not lay["fis_iterations"].active and not lay["seed"].active
    props.fit_mode = "FIS"
    lay = props_by_name(draw(scene))
    assert lay["vsgl_count"].active and lay["fis_iterations"].active and lay["seed"].active
    props.method = "BRUTE_FORCE"
    lay = props_by_name(draw(scene))
    assert not lay["fit_mode"].active and not lay["glossy_mode"].active
    assert lay["rsm_resolution"].active and lay["visibility"].active


def test_double_counting_detected_fixed_and_restored(scene):
    props = scene.vsgl_indirect
    props.enabled = True
    cy = scene.cycles
    cy.max_bounces, cy.diffuse_bounces, cy.glossy_bounces = 12, 4, 4
    msg = checks.double_counting(scene)
    assert "counted twice" in msg and "diffuse 4" in msg
    lay = draw(scene, [ui.VSGL_PT_indirect])
    assert any("counted twice" in t for t in texts(lay))
    assert any(o.idname == "vsgl.cycles_direct_only" for o in lay.ops)
    assert bpy.ops.vsgl.cycles_direct_only() == {"FINISHED"}
    assert (cy.diffuse_bounces, cy.glossy_bounces, cy.max_bounces) == (0, 0, 12)
    assert checks.double_counting(scene) == ""
    assert json.loads(props.cycles_saved) == {"max_bounces": 12, "diffuse_bounces": 4,
                                              "glossy_bounces": 4}
    lay = draw(scene, [ui.VSGL_PT_indirect])
    assert any(o.idname == "vsgl.cycles_restore_bounces" for o in lay.ops)
    assert bpy.ops.vsgl.cycles_restore_bounces() == {"FINISHED"}
    assert (cy.diffuse_bounces, cy.glossy_bounces) == (4, 4) and props.cycles_saved == ""
    # Not counted twice: Total = 0, the AOV not added, another engine, add-on off.
    for change, undo in ((("max_bounces", 0), ("max_bounces", 12)),):
        setattr(cy, *change)
        assert checks.double_counting(scene) == ""
        setattr(cy, *undo)
    props.add_to_render = False
    assert checks.double_counting(scene) == ""
    props.add_to_render = True
    scene.render.engine = "BLENDER_WORKBENCH"
    assert checks.double_counting(scene) == ""
    scene.render.engine = "CYCLES"
    props.enabled = False
    assert checks.double_counting(scene) == ""


def test_double_counting_logged_at_render_start(scene, capsys):
    from vsgl_indirect import handlers
    room(scene)
    scene.cycles.max_bounces, scene.cycles.diffuse_bounces = 4, 2
    assert any("counted twice" in w for w in handlers.check_scene(scene))
    scene.cycles.diffuse_bounces = scene.cycles.glossy_bounces = 0
    assert not any("counted twice" in w for w in handlers.check_scene(scene))


def test_output_in_tmp_warned(scene, tmp_path):
    props = scene.vsgl_indirect
    props.enabled = True
    scene.render.filepath = "/tmp/"
    lay = draw(scene, [ui.VSGL_PT_output])
    assert "a temporary folder the system may clear" in " ".join(texts(lay)), texts(lay)
    assert checks.in_temp_dir("/tmp/vsgl/x.exr") and not checks.in_temp_dir("/home/x/vsgl/x.exr")
    scene.render.filepath = "/srv/shots/beauty_"
    lay = draw(scene, [ui.VSGL_PT_output])
    assert "temporary" not in " ".join(texts(lay))


def test_defaults_half_float_no_fail():
    assert _rna("half_float").default is True
    assert _rna("fail_render").default is False
    assert config.Options().half_float is True


def test_last_run_shows_wrapped_warnings_with_select_buttons(scene):
    room(scene)
    long = ("material 'WallMat': Base Color input(s) are linked (textures are not supported); "
            "their unlinked values are used, which may look nothing like the render")
    runner.begin(scene.name, 3)
    runner.report(scene.name, "WARNING", long)
    runner.report(scene.name, "WARNING", "light 'Spot': its node setup is ignored")
    lay = draw(scene, [ui.VSGL_PT_last_run])
    lines = [t for t in texts(lay) if t]
    assert all(len(t) <= ui._chars(context_for(scene)) for t in lines), lines
    joined = " ".join(lines)
    assert "which may look nothing like the render" in joined     # nothing cut off
    sel = [o for o in lay.ops if o.idname == "vsgl.select_named"]
    assert len(sel) == 3   # one per warning, one for all
    assert ui.named_elements(long) == [("material", "WallMat")]
    assert bpy.ops.vsgl.select_named(message=long) == {"FINISHED"}
    assert [o.name for o in bpy.context.selected_objects] == ["Wall"]
    assert bpy.ops.vsgl.select_named(message="light 'Spot': x\nmaterial 'FloorMat': y") == {"FINISHED"}
    assert sorted(o.name for o in bpy.context.selected_objects) == ["Floor", "Spot"]


def test_panel_draws_settings_status_and_last_run(scene):
    scene.vsgl_indirect.use_advanced = True
    runner.begin(scene.name, 3)
    runner.fail(scene.name, "frame 3, view layer 'ViewLayer': light 'Key': broken")
    lay = draw(scene)
    assert {"preset", "output_path", "add_to_render", "rsm_resolution", "fit_mode",
            "visibility"} <= set(props_by_name(lay))
    t = texts(lay)
    assert sum("light 'Key': broken" in x for x in t) == 1, t   # listed once
    assert "Frame 3: failed" in t


def test_cancelled_is_not_failed(scene):
    runner.begin(scene.name, 2)
    runner.cancel(scene.name)
    info = runner.LAST_RUN[scene.name]
    assert info["status"] == "cancelled" and not info["error"]
    t = texts(draw(scene, [ui.VSGL_PT_last_run]))
    assert "Frame 2: cancelled" in t and not any("fail" in x for x in t), t


def test_panel_shows_library_error(scene, monkeypatch):
    def broken():
        raise engine.AovError("libvsgl.so not found (tried /x). Build it with `make`")
    monkeypatch.setattr(engine, "_binding", broken)
    ok, msg = engine.library_status()
    assert not ok and "libvsgl.so not found" in msg
    lay = draw(scene, [ui.VSGL_PT_indirect])
    assert "libvsgl.so not found (tried /x). Build it with `make`" in " ".join(texts(lay))
    assert not engine.can_render()


def test_classes_and_properties_registered():
    for mod in (settings, operators, ui):
        for cls in mod.classes:
            assert cls.is_registered, cls
    assert "vsgl_indirect" in bpy.types.Scene.bl_rna.properties
    assert vsgl_indirect.bl_info["blender"] == (3, 4, 0)


def test_operators_have_tooltips():
    for cls in operators.classes:
        assert cls.__doc__ and len(cls.__doc__) > 20, cls
        assert cls.bl_label, cls


def test_property_limits_are_the_library_ranges():
    """Issue 10: the RSM range was 8..4096 here, 2..8192 in the library and
    1+ in the CLI docs. The properties take the library's (render.h via
    libvsgl.py, which tests/python/test_layout.py checks against the header)."""
    from vsgl_indirect import libvsgl
    props = bpy.types.Scene.bl_rna.properties["vsgl_indirect"].fixed_type.bl_rna.properties
    want = {"rsm_resolution": (libvsgl.RSM_RESOLUTION_MIN, libvsgl.RSM_RESOLUTION_MAX),
            "aa_samples": (1, libvsgl.AA_SAMPLES_MAX),
            "vsgl_count": (1, libvsgl.VSGL_COUNT_MAX),
            "fis_iterations": (1, libvsgl.FIS_ITERATIONS_MAX),
            "shade_stride": (1, libvsgl.SHADE_STRIDE_MAX),
            "edge_samples": (0, libvsgl.AA_SAMPLES_MAX)}
    for name, (lo, hi) in want.items():
        assert (props[name].hard_min, props[name].hard_max) == (lo, hi), name
    assert (libvsgl.RSM_RESOLUTION_MIN, libvsgl.RSM_RESOLUTION_MAX) == (2, 8192)


def test_last_run_box_shows_the_memory_estimate(scene):
    runner.begin(scene.name, 4)
    res = engine.Result()
    res.path, res.summary = "/tmp/x.exr", "2 triangles"
    res.stats = {"memory_estimate": {"total": 3 << 29, "limit": 22 << 30},
                 "lights_used": 2, "lights_skipped": 1, "vsgl_count": 398}
    res.timings = {"render": 0.1, "write": 0.01}
    runner.finish(scene.name, res, 0.01)
    assert "Memory: about 1.5 GiB of 22.0 GiB" in texts(draw(scene))
    assert "max_memory_gb" in props_by_name(draw(scene))
    assert "Last run: 2 light(s) used, 1 skipped, 398 VSGLs" in texts(draw(scene))
