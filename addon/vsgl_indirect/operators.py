"""Operators: preview the AOV (threaded, cancellable), export a scene bundle,
remove the compositor nodes."""
import os
import threading

import bpy
from bpy.props import StringProperty

from . import compositor, engine, runner
from .convert import ExportError

PREVIEW_IMAGE = "VSGL Preview"


class VSGL_OT_preview_indirect(bpy.types.Operator):
    """Compute the indirect-light AOV of the current frame and show it in an Image Editor (Esc cancels)"""
    bl_idname = "vsgl.preview_indirect"
    bl_label = "Preview Indirect Light"
    bl_options = {"REGISTER"}

    _timer = None

    def _start(self, context):
        scene = context.scene
        self._scene_name = scene.name
        options = runner.options_of(scene)
        runner.begin(scene.name, scene.frame_current)
        sd, self._t_export = runner.export_scene(scene, context.evaluated_depsgraph_get())
        base = bpy.app.tempdir or "/tmp"
        self._path = os.path.join(base, "vsgl_preview_%s.exr" % scene.name.replace(os.sep, "_"))
        self._cancel = False
        self._stage = ("export", 0.0)
        self._result = None
        self._error = None

        def progress(stage, fraction):
            self._stage = (stage, fraction)
            return self._cancel

        def work():
            try:
                self._result = engine.compute(sd, options, self._path, progress=progress)
            except Exception as e:   # reported on the main thread
                self._error = e
        self._thread = threading.Thread(target=work, name="vsgl-preview", daemon=True)
        self._thread.start()

    def _finish(self, context):
        name = self._scene_name
        if self._error is not None:
            msg = str(self._error)
            runner.fail(name, "preview: %s" % msg)
            self.report({"ERROR"} if msg != "cancelled" else {"WARNING"}, "VSGL: %s" % msg)
            return {"CANCELLED"}
        runner.finish(name, self._result, self._t_export)
        for w in self._result.warnings:
            self.report({"WARNING"}, "VSGL: %s" % w)
        img = bpy.data.images.get(PREVIEW_IMAGE)
        if img is None:
            img = bpy.data.images.load(self._path, check_existing=False)
            img.name = PREVIEW_IMAGE
        else:
            img.filepath = self._path
            img.reload()
        shown = False
        for window in getattr(context.window_manager, "windows", []):
            for area in window.screen.areas:
                if area.type == "IMAGE_EDITOR":
                    area.spaces.active.image = img
                    area.tag_redraw()
                    shown = True
                    break
            if shown:
                break
        self.report({"INFO"}, "VSGL: indirect light in image '%s'%s (%s)" % (
            PREVIEW_IMAGE, "" if shown else "; open an Image Editor to see it", self._path))
        return {"FINISHED"}

    def execute(self, context):   # synchronous (scripts, background mode)
        try:
            self._start(context)
        except (ExportError, engine.AovError) as e:
            runner.fail(context.scene.name, "preview: %s" % e)
            self.report({"ERROR"}, "VSGL: %s" % e)
            return {"CANCELLED"}
        self._thread.join()
        return self._finish(context)

    def invoke(self, context, event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        try:
            self._start(context)
        except (ExportError, engine.AovError) as e:
            runner.fail(context.scene.name, "preview: %s" % e)
            self.report({"ERROR"}, "VSGL: %s" % e)
            return {"CANCELLED"}
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self._cancel = True
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        wm = context.window_manager
        stage, frac = self._stage
        wm.progress_update(int(100 * frac))
        if context.workspace is not None:
            context.workspace.status_text_set("VSGL indirect: %s %d%% (Esc to cancel)"
                                              % (stage, int(100 * frac)))
        if self._thread.is_alive():
            return {"RUNNING_MODAL"}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        return self._finish(context)


def _bundle_available():
    try:
        from . import libvsgl
        lib = libvsgl.library()
        return lib.has("vsgl_bundle_write") and not getattr(lib, "undefined", ())
    except Exception:
        return False


class VSGL_OT_export_bundle(bpy.types.Operator):
    """Export the evaluated scene and settings as a VSGL scene bundle (for the vsgl CLI or a farm)"""
    bl_idname = "vsgl.export_bundle"
    bl_label = "Export VSGL Scene Bundle"
    filename_ext = ".vsglb"
    filepath: StringProperty(subtype="FILE_PATH")
    filter_glob: StringProperty(default="*.vsglb", options={"HIDDEN"})

    @classmethod
    def poll(cls, context):
        if not _bundle_available():
            if hasattr(cls, "poll_message_set"):
                cls.poll_message_set("libvsgl has no vsgl_bundle_write in this build")
            return False
        return context.scene is not None

    def invoke(self, context, event):
        if not self.filepath:
            base = bpy.path.abspath("//") or (bpy.app.tempdir or "/tmp")
            self.filepath = os.path.join(base, bpy.path.clean_name(context.scene.name) + ".vsglb")
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}

    def execute(self, context):
        from . import libvsgl
        scene = context.scene
        path = bpy.path.ensure_ext(bpy.path.abspath(self.filepath), ".vsglb")
        options = runner.options_of(scene)
        try:
            sd, _ = runner.export_scene(scene, context.evaluated_depsgraph_get())
            engine.check_output_path(path)
            arrays = engine.scene_arrays(sd, libvsgl)  # the same arrays a render passes (tangents included)
            ctx = libvsgl.Context()
            try:
                libvsgl.bundle_write(ctx, path, arrays, engine.settings_for(options, libvsgl),
                                     output_path=runner.output_path(
                                         scene, context.view_layer.name, scene.frame_current,
                                         options),
                                     frame=scene.frame_current)
            finally:
                ctx.close()
        except (ExportError, engine.AovError, libvsgl.VsglError, libvsgl.VsglLibraryError) as e:
            self.report({"ERROR"}, "VSGL: %s" % e)
            return {"CANCELLED"}
        for w in sd.warnings:
            self.report({"WARNING"}, "VSGL: %s" % w)
        self.report({"INFO"}, "VSGL: wrote %s (%s)" % (path, sd.summary()))
        return {"FINISHED"}


class VSGL_OT_remove_nodes(bpy.types.Operator):
    """Remove the compositor nodes this add-on created in this scene"""
    bl_idname = "vsgl.remove_compositor_nodes"
    bl_label = "Remove VSGL Compositor Nodes"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        compositor.remove(context.scene)
        return {"FINISHED"}


def menu_export(self, context):
    self.layout.operator(VSGL_OT_export_bundle.bl_idname, text="VSGL scene bundle (.vsglb)")


classes = (VSGL_OT_preview_indirect, VSGL_OT_export_bundle, VSGL_OT_remove_nodes)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.TOPBAR_MT_file_export.append(menu_export)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(menu_export)
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
