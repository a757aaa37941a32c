"""Render Properties > VSGL Indirect Light: a Cycles-style panel with a
labelled header toggle and subpanels (Quality, Lights & Materials, Output,
Compositing, Last Run), property-split layout, contents inactive while the
toggle is off."""
import re
import textwrap

import bpy

from . import checks, config, engine, runner

#: Knobs per subpanel, in drawing order.
QUALITY_KNOBS = ("method", "aa_samples", "aa_pixel_limit", "edge_samples", "shade_stride", "stride_pixels",
                 "sample_merging", "visibility", "visibility_budget", "visibility_spread",
                 "dominant_rays", "seed")
LIGHT_KNOBS = ("rsm_resolution", "fit_mode", "vsgl_count", "fis_iterations",
               "sharpness_estimator", "leak_correction")
MATERIAL_KNOBS = ("diffuse_mode", "glossy_mode", "glossy_lobes", "mrp_min_area")
assert set(QUALITY_KNOBS + LIGHT_KNOBS + MATERIAL_KNOBS) == set(config.KNOBS)

#: Blender's report icons: an error is a cross, a warning a triangle.
LEVEL_ICONS = {"ERROR": "CANCEL", "WARNING": "ERROR", "INFO": "INFO"}

_NAMED = re.compile(r"\b(object|light|material) '([^']+)'")


def named_elements(message):
    """[(kind, name)] of the objects, lights and materials a message names."""
    return _NAMED.findall(message or "")


def _chars(context):
    """Characters that fit on one line of the region (for wrapping)."""
    region = getattr(context, "region", None)
    width = getattr(region, "width", 0) or 400
    scale = 1.0
    prefs = getattr(context, "preferences", None)
    if prefs is not None:
        scale = getattr(prefs.system, "ui_scale", 1.0) or 1.0
    return max(24, int((width - 50) / (6.5 * scale)))


def wrapped(layout, context, text, icon="NONE", select=None):
    """Draw ``text`` over as many label lines as it needs; ``select``: add a
    button selecting the objects it names."""
    col = layout.column(align=True)
    lines = textwrap.wrap(text, _chars(context) - (4 if select else 0)) or [""]
    for i, line in enumerate(lines):
        row = col.row(align=True)
        row.label(text=line, icon=icon if i == 0 else "BLANK1")
        if i == 0 and select:
            op = row.operator("vsgl.select_named", text="", icon="RESTRICT_SELECT_OFF")
            op.message = text
    return col


def _props(context):
    return context.scene.vsgl_indirect


class _Sub:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    bl_parent_id = "VSGL_PT_indirect"


def _sub_layout(panel, context):
    layout = panel.layout
    layout.use_property_split = True
    layout.use_property_decorate = False
    layout.active = _props(context).enabled
    return layout


def draw_knobs(layout, props, names):
    """The knobs ``names``: editable with Advanced on, greyed out where they
    do not apply, marked (with the preset's value) where they differ from
    the preset."""
    differ = set(config.differing_knobs(props))
    inactive = config.inactive_knobs(props)
    want = config.preset_knobs(props.preset)
    col = layout.column()
    col.enabled = props.use_advanced
    for k in names:
        row = col.row(align=True)
        row.active = k not in inactive
        if k in differ:
            row.prop(props, k, icon="MODIFIER_ON")
            sub = row.row(align=True)
            sub.alignment = "RIGHT"
            sub.label(text=_value_text(props, k, want[k]))
        else:
            row.prop(props, k)
    return col


def _value_text(props, k, v):
    if isinstance(v, str):
        item = props.bl_rna.properties[k].enum_items.get(v)
        v = item.name if item is not None else v
    return "%s: %s" % (props.bl_rna.properties["preset"].enum_items[props.preset].name, v)


class VSGL_PT_indirect(bpy.types.Panel):
    # The label is drawn by the header toggle itself (clicking it toggles).
    bl_label = ""
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(_props(context), "enabled")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        scene = context.scene
        props = scene.vsgl_indirect
        ok, msg = engine.library_status()
        if not ok:
            box = layout.box()
            wrapped(box, context, msg, icon="ERROR")
        col = layout.column()
        col.active = props.enabled
        col.prop(props, "preset")
        row = col.row()
        row.enabled = ok
        row.operator("vsgl.preview_indirect", icon="RENDER_STILL")
        dc = checks.double_counting(scene)
        if dc:
            box = layout.box()
            wrapped(box, context, dc, icon="ERROR")
            box.operator("vsgl.cycles_direct_only", icon="LIGHT")
        elif props.cycles_saved:
            row = layout.row()
            row.label(text="Cycles renders direct light only (set by VSGL)", icon="INFO")
            row.operator("vsgl.cycles_restore_bounces", text="Restore", icon="LOOP_BACK")


class VSGL_PT_quality(_Sub, bpy.types.Panel):
    bl_label = "Quality"

    def draw(self, context):
        layout = _sub_layout(self, context)
        props = _props(context)
        layout.prop(props, "use_advanced")
        differ = config.differing_knobs(props)
        if props.use_advanced and differ:
            sub = layout.row()
            sub.label(text="%d knob(s) differ from %s" % (
                len(differ), props.bl_rna.properties["preset"].enum_items[props.preset].name),
                icon="MODIFIER_ON")
            sub.operator("vsgl.reset_knobs", text="Reset", icon="LOOP_BACK")
        draw_knobs(layout, props, QUALITY_KNOBS)


class VSGL_PT_lights_materials(_Sub, bpy.types.Panel):
    bl_label = "Lights & Materials"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = _sub_layout(self, context)
        props = _props(context)
        if not props.use_advanced:
            layout.label(text="Values of the preset; tick Advanced (Quality) to edit", icon="INFO")
        layout.label(text="Lights")
        lights = (runner.LAST_RUN.get(context.scene.name) or {}).get("lights") or {}
        if lights:
            layout.label(text="Last run: %d light(s) used, %d skipped, %d VSGLs" % (
                lights.get("lights_used", 0), lights.get("lights_skipped", 0),
                lights.get("vsgl_count", 0)), icon="LIGHT")
        draw_knobs(layout, props, LIGHT_KNOBS)
        layout.label(text="Materials")
        draw_knobs(layout, props, MATERIAL_KNOBS)


class VSGL_PT_output(_Sub, bpy.types.Panel):
    bl_label = "Output"

    def draw(self, context):
        layout = _sub_layout(self, context)
        props = _props(context)
        scene = context.scene
        layout.prop(props, "output_path")
        try:
            path = runner.output_path(scene, context.view_layer.name, scene.frame_current)
        except Exception:   # a bad template is reported at render time
            path = ""
        if path:
            col = layout.column(align=True)
            wrapped(col, context, "Frame %d: %s" % (scene.frame_current, path), icon="FILE_IMAGE")
            warn = checks.temp_output_warning(path)
            if warn:
                wrapped(col, context, warn, icon="ERROR")
        layout.prop(props, "half_float")
        layout.prop(props, "color_passes")
        layout.prop(props, "fail_render")
        col = layout.column(align=True)
        col.prop(props, "threads")
        col.prop(props, "max_memory_gb")


class VSGL_PT_compositing(_Sub, bpy.types.Panel):
    bl_label = "Compositing"

    def draw(self, context):
        layout = _sub_layout(self, context)
        props = _props(context)
        layout.prop(props, "add_to_render")
        col = layout.column()
        col.active = props.add_to_render
        col.prop(props, "strength", slider=True)
        row = col.row(heading="Passes") if bpy.app.version >= (2, 90, 0) else col.row()
        row.prop(props, "use_diffuse", toggle=True)
        row.prop(props, "use_glossy", toggle=True)
        col.prop(props, "use_cycles_colors")
        layout.prop(props, "export_passes")
        sub = layout.column()
        sub.active = props.export_passes
        sub.prop(props, "export_path")
        layout.operator("vsgl.setup_compositor", icon="NODETREE")
        layout.operator("vsgl.remove_compositor_nodes", icon="X")


class VSGL_PT_last_run(_Sub, bpy.types.Panel):
    bl_label = "Last Run"

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def draw(self, context):
        layout = _sub_layout(self, context)
        layout.use_property_split = False
        layout.active = True
        scene = context.scene
        info = runner.LAST_RUN.get(scene.name)
        if not info:
            layout.label(text="Nothing computed yet in this session")
            return
        status = info.get("status", "?")
        icon = {"done": "CHECKMARK", "failed": "ERROR", "cancelled": "CANCEL",
                "running": "SORTTIME"}.get(status, "INFO")
        layout.label(text="Frame %s: %s" % (info.get("frame", "?"), runner.STATUS_TEXT.get(status, status)),
                     icon=icon)
        if info.get("summary"):
            wrapped(layout, context, info["summary"], icon="SCENE_DATA")
        if info.get("memory"):
            layout.label(text="Memory: " + info["memory"], icon="MEMORY")
        t = info.get("timings") or {}
        if t:
            flow = layout.grid_flow(row_major=True, columns=2, even_columns=True, align=True)
            for k, v in t.items():
                flow.label(text="%s: %.3f s" % (k, v))
        messages = [(lv, m) for lv, m in (info.get("messages") or []) if lv != "INFO"]
        skipped = [l.strip() for l in (info.get("skipped") or "").splitlines() if l.strip()]
        if skipped:
            box = layout.box()
            box.label(text="Skipped by the library", icon="INFO")
            for line in skipped:
                wrapped(box, context, line, select=bool(named_elements(line)))
        budget = [l.strip() for l in (info.get("budget") or "").splitlines() if l.strip()]
        if budget:
            box = layout.box()
            box.label(text="Budget per light", icon="LIGHT")
            for line in budget:
                wrapped(box, context, line)
        if messages:
            box = layout.box()
            box.label(text="Warnings and errors (%d)" % len(messages), icon="ERROR")
            for level, m in messages[-20:]:
                wrapped(box, context, m, icon=LEVEL_ICONS.get(level, "INFO"),
                        select=bool(named_elements(m)))
            if len(messages) > 20:
                box.label(text="... %d earlier (see the console)" % (len(messages) - 20))
            names = [m for _, m in messages if named_elements(m)]
            if names:
                op = box.operator("vsgl.select_named", text="Select Everything Named",
                                  icon="RESTRICT_SELECT_OFF")
                op.message = "\n".join(names)


classes = (VSGL_PT_indirect, VSGL_PT_quality, VSGL_PT_lights_materials, VSGL_PT_output,
           VSGL_PT_compositing, VSGL_PT_last_run)


def register():
    for c in classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
