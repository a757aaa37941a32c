"""Render handlers: compute the AOV of each rendered frame before Cycles/EEVEE
render it and before the compositor runs (F12, ``-f N``, ``-a``).

Order Blender calls them in (checked on 3.4 and 5.0, background and -a):
render_init (once per job) -> per frame: render_pre -> frame_change_post
with the RENDER depsgraph -> engine render -> compositor -> render_post.

- render_init / load_post / settings changes: set up the compositor nodes
  (never in render_pre: editing the node tree there stops Blender 3.4 from
  calling frame_change_post for the next frames of ``-a``).
- render_pre: replace this frame's file by a black placeholder (so a failed
  computation can never leave an older AOV to be composited).
- frame_change_post with a RENDER depsgraph: export that depsgraph (render
  visibility, render modifier levels), compute, write this frame's EXR.
- render_post/render_cancel/render_complete: placeholders never replaced are
  deleted and reported.
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


def _render_size(scene):
    return convert.render_size(scene.render.resolution_x, scene.render.resolution_y,
                               scene.render.resolution_percentage)


def setup_scene(scene, frame=None):
    """Create/update the compositor nodes of every rendered view layer of
    ``scene`` (outside a render). Returns the list of error messages."""
    props = getattr(scene, "vsgl_indirect", None)
    if props is None or not props.enabled:
        return []
    frame = scene.frame_current if frame is None else frame
    options = runner.options_of(scene)
    errors = []
    w, h = _render_size(scene)
    for i, layer in enumerate(_layers(scene)):
        path = runner.output_path(scene, layer, frame, options)
        try:
            engine.check_output_path(path)
            # Blender creates the pass sockets from a real file; never
            # replace one (a parallel process may have rendered this frame).
            made = not os.path.exists(path) and compositor.placeholder(path, w, h, exclusive=True)
            if made:
                _placeholder_mtimes[path] = os.path.getmtime(path)
            try:
                # One composite output: only the first rendered view layer's AOV is
                # added onto it; the others get their Image node to wire by hand.
                compositor.ensure(scene, layer, path, options.add_to_render and i == 0)
            finally:
                # The sockets stay; a black file must not look like an AOV.
                if made and os.path.exists(path) and _is_placeholder(path):
                    os.unlink(path)
                    _placeholder_mtimes.pop(path, None)
        except engine.AovError as e:
            errors.append("view layer '%s': %s" % (layer, e))
        except Exception as e:
            import traceback
            traceback.print_exc()
            errors.append("view layer '%s': compositor setup failed: %r" % (layer, e))
    for e in errors:
        runner.fail(scene.name, e)
    return errors


_placeholder_mtimes = {}


def _is_placeholder(path):
    return _placeholder_mtimes.get(path) == os.path.getmtime(path)


def _write_placeholder(scene, path):
    w, h = _render_size(scene)
    compositor.placeholder(path, w, h)
    _placeholder_mtimes[path] = os.path.getmtime(path)


@persistent
def on_render_init(scene, *args):
    props = getattr(scene, "vsgl_indirect", None)
    if props is None or not props.enabled or not engine.can_render():
        return
    setup_scene(scene)
    if scene.vsgl_indirect.add_to_render and not scene.render.use_compositing:
        runner.report(scene.name, "WARNING", "compositing is off (Output Properties > Post "
                      "Processing): the AOV files are written but not added to the render")


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
    for layer in _layers(scene):
        path = runner.output_path(scene, layer, frame, options)
        try:
            engine.check_output_path(path)
            _write_placeholder(scene, path)
            _state["placeholders"][(scene.name, layer, frame)] = path
        except engine.AovError as e:
            runner.fail(scene.name, "frame %d, view layer '%s': %s" % (frame, layer, e))


@persistent
def on_frame_change_post(scene, depsgraph=None, *args):
    if depsgraph is None or depsgraph.mode != "RENDER":
        return
    frame = _state["active"].get(scene.name)
    if frame is None or frame != scene.frame_current:
        return
    layer = depsgraph.view_layer.name
    key = (scene.name, layer, frame)
    if key in _state["done"] or key not in _state["placeholders"]:
        return
    _state["done"].add(key)
    result = runner.run_frame(scene, depsgraph, frame)
    path = _state["placeholders"].pop(key, None)
    if result is None and path is not None and os.path.exists(path):
        os.unlink(path)   # no file rather than a black AOV that looks valid
    else:
        _placeholder_mtimes.pop(path, None)
    img = bpy.data.images.get(compositor.IMAGE_NAME % (scene.name, layer))
    if img is not None:
        img.reload()


@persistent
def on_render_post(scene, *args):
    frame = _state["active"].pop(scene.name, None)
    _state["done"] = {k for k in _state["done"] if k[0] != scene.name}
    for key in [k for k in _state["placeholders"] if k[0] == scene.name]:
        path = _state["placeholders"].pop(key)
        if os.path.exists(path):
            os.unlink(path)
        runner.fail(scene.name, "frame %s, view layer '%s': the AOV was not computed "
                    "(Blender gave no render depsgraph for it)" % (frame, key[1]))


@persistent
def on_render_end(scene, *args):
    on_render_post(scene)


@persistent
def on_load_post(*args):
    for scene in bpy.data.scenes:
        props = getattr(scene, "vsgl_indirect", None)
        if props is not None and props.enabled and engine.can_render():
            setup_scene(scene)


HANDLERS = (
    ("render_init", on_render_init),
    ("render_pre", on_render_pre),
    ("frame_change_post", on_frame_change_post),
    ("render_post", on_render_post),
    ("render_cancel", on_render_end),
    ("render_complete", on_render_end),
    ("load_post", on_load_post),
)


def _remove(lst, fn):
    for old in [f for f in lst if getattr(f, "__name__", "") == fn.__name__
                and getattr(f, "__module__", "") == fn.__module__]:
        lst.remove(old)


def register():
    for name, fn in HANDLERS:
        lst = getattr(bpy.app.handlers, name)
        _remove(lst, fn)
        lst.append(fn)


def unregister():
    for name, fn in HANDLERS:
        _remove(getattr(bpy.app.handlers, name), fn)
