"""Render Properties panel: settings, library status, last run."""
import bpy

from . import config, engine, runner


class VSGL_PT_indirect(bpy.types.Panel):
    bl_label = "VSGL Indirect Light"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(context.scene.vsgl_indirect, "enabled", text="")

    def draw(self, context):
        layout = self.layout
        scene = context.scene
        props = scene.vsgl_indirect
        ok, msg = engine.library_status()
        box = layout.box()
        box.label(text=msg, icon="CHECKMARK" if ok else "ERROR")
        layout.use_property_split = True
        layout.prop(props, "add_to_render")
        layout.prop(props, "output_path")
        layout.prop(props, "preset")
        layout.prop(props, "use_advanced")
        if props.use_advanced:
            col = layout.column(align=True)
            for k in config.KNOBS:
                col.prop(props, k)
        layout.prop(props, "threads")
        layout.prop(props, "max_memory_gb")
        layout.prop(props, "half_float")
        row = layout.row()
        row.enabled = ok
        row.operator("vsgl.preview_indirect", icon="RENDER_STILL")
        layout.operator("vsgl.remove_compositor_nodes", icon="X")

        info = runner.LAST_RUN.get(scene.name)
        if not info:
            return
        box = layout.box()
        box.label(text="Last run: frame %s, %s" % (info.get("frame", "?"), info.get("status", "?")))
        if info.get("error"):
            box.label(text=info["error"], icon="ERROR")
        if info.get("summary"):
            box.label(text=info["summary"])
        if info.get("memory"):
            box.label(text="Memory: " + info["memory"])
        t = info.get("timings") or {}
        if t:
            col = box.column(align=True)
            for k, v in t.items():
                col.label(text="%s: %.3f s" % (k, v))
        for line in (info.get("skipped") or "").splitlines():
            box.label(text="skipped: " + line, icon="INFO")
        for level, m in (info.get("messages") or [])[-8:]:
            if level != "INFO":
                box.label(text=m, icon="ERROR" if level == "ERROR" else "INFO")


classes = (VSGL_PT_indirect,)


def register():
    for c in classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
