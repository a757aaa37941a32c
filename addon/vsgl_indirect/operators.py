"""Operators: preview the AOV (threaded, cancellable), export a scene bundle,
remove the compositor nodes."""
import json
import os
import threading

import bpy
from bpy.props import StringProperty

from . import checks, compositor, engine, runner
from .convert import ExportError

PREVIEW_IMAGE = "VSGL Preview"


def load_preview_image(path):
    """The image 'VSGL Preview' reading ``path``, reloaded in place (the same
    datablock, so an editor showing it keeps it and its layer/pass choice).
    The file path is only assigned when it changed, and the file is read
    here (asking for ``size`` reads it and rebuilds the multilayer layers
    and passes the editor's menus list; the size itself stays 0 x 0 for a
    multilayer image without an image user)."""
    img = bpy.data.images.get(PREVIEW_IMAGE)
    if img is None:
        img = bpy.data.images.load(path, check_existing=False)
        img.name = PREVIEW_IMAGE
    else:
        if os.path.normpath(bpy.path.abspath(img.filepath)) != os.path.normpath(path):
            img.filepath = path
        img.reload()
    tuple(img.size)
    return img


def _image_editors(window_manager):
    for window in getattr(window_manager, "windows", []):
        for area in window.screen.areas:
            if area.type == "IMAGE_EDITOR":
                yield window, area


def find_image_editor(window_manager, image=None):
    """An Image Editor area: one showing ``image`` first, else one showing no
    image or a VSGL image, else any; None if there is none."""
    editors = list(_image_editors(window_manager))
    for pred in (lambda sp: image is not None and sp.image == image,
                 lambda sp: sp.image is None or sp.image.name.startswith("VSGL"),
                 lambda sp: True):
        for window, area in editors:
            if pred(area.spaces.active):
                return area
    return None


def show_image(context, img):
    """Show ``img`` in an Image Editor: reuse one that is open, else open one
    the way F11 does (Preferences > Interface > Temporary Editors > Render
    In; "New Window" if that is set to keep the interface). Returns the area
    or None (background mode, no window)."""
    wm = context.window_manager
    area = find_image_editor(wm, img)
    if area is None and getattr(context, "window", None) is not None and not bpy.app.background:
        view = context.preferences.view
        old = view.render_display_type
        try:
            if old == "NONE":
                view.render_display_type = "WINDOW"
            bpy.ops.render.view_show("INVOKE_DEFAULT")
        except RuntimeError as e:
            print("VSGL WARNING: could not open an Image Editor: %s" % e)
        finally:
            if view.render_display_type != old:
                view.render_display_type = old
        area = find_image_editor(wm)
    if area is not None:
        space = area.spaces.active
        if space.image != img:
            space.image = img
        area.tag_redraw()
    return area


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
        if isinstance(self._error, engine.AovCancelled):
            runner.cancel(name, "preview")
            self.report({"INFO"}, "VSGL: preview cancelled")
            return {"CANCELLED"}
        if self._error is not None:
            msg = str(self._error)
            runner.fail(name, "preview: %s" % msg)
            self.report({"ERROR"}, "VSGL: %s" % msg)
            return {"CANCELLED"}
        runner.finish(name, self._result, self._t_export)
        for w in self._result.warnings:
            self.report({"WARNING"}, "VSGL: %s" % w)
        img = load_preview_image(self._path)
        area = show_image(context, img)
        self.report({"INFO"}, "VSGL: indirect light in image '%s'%s (%s)" % (
            PREVIEW_IMAGE, "" if area is not None else "; open an Image Editor to see it",
            self._path))
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
        if stage == "write":   # one call, no fraction: say what it is doing
            wm.progress_update(99)
            text = "VSGL indirect: writing the EXR %s" % os.path.basename(self._path)
        else:
            wm.progress_update(int(100 * frac))
            text = "VSGL indirect: %s %d%% (Esc to cancel)" % (stage, int(100 * frac))
        if context.workspace is not None:
            context.workspace.status_text_set(text)
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
    """Remove the compositor nodes this add-on created in this scene and reconnect the original chain"""
    bl_idname = "vsgl.remove_compositor_nodes"
    bl_label = "Remove VSGL Compositor Nodes"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        compositor.remove(context.scene)
        return {"FINISHED"}


class VSGL_OT_setup_compositor(bpy.types.Operator):
    """Create or update the VSGL compositor nodes now (renders do it by themselves)"""
    bl_idname = "vsgl.setup_compositor"
    bl_label = "Update Compositor Nodes"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        props = getattr(context.scene, "vsgl_indirect", None)
        return props is not None and props.enabled

    def execute(self, context):
        from . import handlers
        errors = handlers.setup_scene(context.scene)
        for e in errors:
            self.report({"ERROR"}, "VSGL: %s" % e)
        return {"CANCELLED"} if errors else {"FINISHED"}


class VSGL_OT_reset_knobs(bpy.types.Operator):
    """Set every advanced knob to the selected preset's value"""
    bl_idname = "vsgl.reset_knobs"
    bl_label = "Reset to Preset"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        from . import settings
        settings.load_preset_knobs(context.scene.vsgl_indirect)
        return {"FINISHED"}


class VSGL_OT_cycles_direct_only(bpy.types.Operator):
    """Set Cycles' Diffuse and Glossy bounces to 0 so that it renders direct light only and the \
VSGL AOV adds the one-bounce indirect light (saved: 'Restore' puts the previous values back)"""
    bl_idname = "vsgl.cycles_direct_only"
    bl_label = "Cycles: Direct Light Only"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None and hasattr(context.scene, "cycles")

    def execute(self, context):
        scene = context.scene
        props, cy = scene.vsgl_indirect, scene.cycles
        if not props.cycles_saved:   # keep the first saved values over repeated clicks
            props.cycles_saved = json.dumps({k: int(getattr(cy, k)) for k in checks.SAVED_KEYS})
        for k in checks.BOUNCE_KEYS:
            setattr(cy, k, 0)
        runner.report(scene.name, "INFO", "Cycles: diffuse and glossy bounces set to 0 "
                      "(were %s); the composite is Cycles' direct light + the AOV"
                      % props.cycles_saved)
        return {"FINISHED"}


class VSGL_OT_cycles_restore_bounces(bpy.types.Operator):
    """Put back the Cycles bounces 'Cycles: Direct Light Only' changed"""
    bl_idname = "vsgl.cycles_restore_bounces"
    bl_label = "Restore Cycles Bounces"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        props = getattr(context.scene, "vsgl_indirect", None)
        return props is not None and bool(props.cycles_saved) and hasattr(context.scene, "cycles")

    def execute(self, context):
        scene = context.scene
        props = scene.vsgl_indirect
        try:
            saved = json.loads(props.cycles_saved)
        except ValueError:
            saved = {}
        for k, v in saved.items():
            if k in checks.SAVED_KEYS:
                setattr(scene.cycles, k, int(v))
        props.cycles_saved = ""
        return {"FINISHED"}


class VSGL_OT_select_named(bpy.types.Operator):
    """Select the objects a message names (objects, lights, and the objects using a named material)"""
    bl_idname = "vsgl.select_named"
    bl_label = "Select Named Objects"
    bl_options = {"REGISTER", "UNDO"}

    message: StringProperty(name="Message", options={"HIDDEN", "SKIP_SAVE"},
                            description="Text naming object 'X', light 'Y' or material 'Z'")

    def execute(self, context):
        from .ui import named_elements
        found = objects_named(context.view_layer, named_elements(self.message))
        if not found:
            self.report({"WARNING"}, "VSGL: no object of this view layer is named in the message")
            return {"CANCELLED"}
        for ob in context.view_layer.objects:
            if ob.select_get():
                ob.select_set(False)
        for ob in found:
            ob.select_set(True)
        context.view_layer.objects.active = found[0]
        self.report({"INFO"}, "VSGL: selected %s" % ", ".join(o.name for o in found[:10]))
        return {"FINISHED"}


def objects_named(view_layer, named):
    """Objects of ``view_layer`` for [(kind, name)]: an object or light by its
    object (or data) name, a material by the objects using it."""
    out = []
    for ob in view_layer.objects:
        hit = False
        for kind, name in named:
            if kind in ("object", "light"):
                hit = ob.name == name or (ob.data is not None and ob.data.name == name
                                          and (kind == "object" or ob.type == "LIGHT"))
            elif kind == "material":
                hit = any(s.material is not None and s.material.name == name
                          for s in ob.material_slots)
            if hit:
                break
        if hit:
            out.append(ob)
    return out


def menu_export(self, context):
    self.layout.operator(VSGL_OT_export_bundle.bl_idname, text="VSGL scene bundle (.vsglb)")


classes = (VSGL_OT_preview_indirect, VSGL_OT_export_bundle, VSGL_OT_remove_nodes,
           VSGL_OT_setup_compositor, VSGL_OT_reset_knobs, VSGL_OT_cycles_direct_only,
           VSGL_OT_cycles_restore_bounces, VSGL_OT_select_named)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.TOPBAR_MT_file_export.append(menu_export)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(menu_export)
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
