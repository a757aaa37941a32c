"""Render handlers: compute the AOV of each rendered frame before Cycles/EEVEE
render it and before the compositor runs (F12, ``-f N``, ``-a``).

- ``render_pre`` (once per frame, before the render depsgraph is built):
  prepares the compositor nodes to read this frame's file.
- ``frame_change_post`` with a RENDER depsgraph (Blender calls it while it
  evaluates the render depsgraph, after render_pre and before the engine and
  the compositor): exports that depsgraph (render visibility, render modifier
  levels) and writes this frame's EXR.
- ``render_post``/``render_cancel``: end of frame bookkeeping.
"""
import os

import bpy
from bpy.app.handlers import persistent

from . import compositor, convert, engine, runner

_state = {"active": {}, "placeholders": {}, "done": set()}


def _layers(scene):
    if getattr(scene.render, "use_single_layer", False):
        vl = bpy.context.view_layer if bpy.context.scene == scene else scene.view_layers[0]
        return [vl.name]
    return [vl.name for vl in scene.view_layers if vl.use]


@persistent
def on_render_pre(scene, *args):
    props = getattr(scene, "vsgl_indirect", None)
    if props is None or not props.enabled:
        return
    frame = scene.frame_current
    options = runner.options_of(scene)
    runner.begin(scene.name, frame)
    if not engine.can_render():
        runner.fail(scene.name, "frame %d: no indirect AOV: %s" % (frame, engine.render_missing()))
        return
    _state["active"][scene.name] = frame
    w, h = convert.render_size(scene.render.resolution_x, scene.render.resolution_y,
                               scene.render.resolution_percentage)
    for layer in _layers(scene):
        path = runner.output_path(scene, layer, frame, options)
        try:
            engine.check_output_path(path)
            # Always replace the frame's file: a failed computation must not
            # leave an older AOV to be composited (the placeholder is deleted then).
            compositor.placeholder(path, w, h)
            _state["placeholders"][(scene.name, layer, frame)] = path
            compositor.ensure(scene, layer, path, frame, options.add_to_render)
        except engine.AovError as e:
            runner.fail(scene.name, "frame %d, view layer '%s': %s" % (frame, layer, e))
        except Exception as e:
            import traceback
            traceback.print_exc()
            runner.fail(scene.name, "frame %d, view layer '%s': compositor setup failed: %r"
                        % (frame, layer, e))


@persistent
def on_frame_change_post(scene, depsgraph=None, *args):
    if depsgraph is None or depsgraph.mode != "RENDER":
        return
    frame = _state["active"].get(scene.name)
    if frame is None or frame != scene.frame_current:
        return
    layer = depsgraph.view_layer.name
    key = (scene.name, layer, frame)
    if key in _state["done"]:
        return
    _state["done"].add(key)
    result = runner.run_frame(scene, depsgraph, frame)
    ph = _state["placeholders"].pop(key, None)
    if result is None and ph is not None and os.path.exists(ph):
        os.unlink(ph)   # no file rather than a black AOV that looks valid
    img = bpy.data.images.get(compositor.IMAGE_NAME % (scene.name, layer))
    if img is not None:
        img.reload()


@persistent
def on_render_end(scene, *args):
    frame = _state["active"].pop(scene.name, None)
    _state["done"] = {k for k in _state["done"] if k[0] != scene.name}
    for key in [k for k in _state["placeholders"] if k[0] == scene.name]:
        path = _state["placeholders"].pop(key)
        # A placeholder never replaced means the layer was not computed.
        if os.path.exists(path):
            os.unlink(path)
            runner.fail(scene.name, "frame %s, view layer '%s': the AOV was not computed "
                        "(no render depsgraph for it)" % (frame, key[1]))


HANDLERS = (
    ("render_pre", on_render_pre),
    ("frame_change_post", on_frame_change_post),
    ("render_post", on_render_end),
    ("render_cancel", on_render_end),
)


def register():
    for name, fn in HANDLERS:
        lst = getattr(bpy.app.handlers, name)
        for old in [f for f in lst if getattr(f, "__name__", "") == fn.__name__
                    and getattr(f, "__module__", "") == fn.__module__]:
            lst.remove(old)
        lst.append(fn)


def unregister():
    for name, fn in HANDLERS:
        lst = getattr(bpy.app.handlers, name)
        for old in [f for f in lst if getattr(f, "__name__", "") == fn.__name__
                    and getattr(f, "__module__", "") == fn.__module__]:
            lst.remove(old)
