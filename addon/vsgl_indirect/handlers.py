"""Render handlers: compute the AOV of each rendered frame before Cycles/EEVEE
render it and before the compositor runs (F12, ``-f N``, ``-a``).

Order Blender calls them in (checked on 3.4 and 5.0, background and -a):
render_init (once per job) -> per frame: render_pre -> frame_change_post
with the RENDER depsgraph -> engine render -> compositor -> render_post.

- render_init / load_post / settings changes: set up the compositor nodes
  (never in render_pre: editing the node tree there stops Blender 3.4 from
  calling frame_change_post for the next frames of ``-a``).
- render_pre: note the frame (nothing is written: several farm workers may
  share the AOV files, and a file another worker finished is a valid AOV of
  this frame that it may be compositing right now).
- frame_change_post with a RENDER depsgraph: export that depsgraph (render
  visibility, render modifier levels), compute, write this frame's EXR
  atomically (a reader sees the old complete file or the new one). If the
  computation fails, a file older than this render job (a previous run's)
  is retired (renamed away, then deleted) so it is not composited; one
  written meanwhile by another worker stays.
- render_post/render_cancel/render_complete: frames never computed are
  reported.

Farm safety (issue 10): no handler ever replaces or deletes a complete AOV
another process wrote; the compositor-setup placeholder is only ever put
where no file exists and only ever removed if it is still the same inode.
"""
import contextlib
import os
import sys
import time

import bpy
from bpy.app.handlers import persistent

from . import checks, compositor, convert, engine, runner

#: Exit status of ``blender -b ... -f/-a`` when a frame has no AOV and
#: *Fail Render Without AOV* is on.
FAIL_EXIT_CODE = 1

_state = {"active": {}, "pending": {}, "done": set(), "job_start": {}}


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
            with _setup_lock(os.path.dirname(path)):
                _setup_layer(scene, layer, path, w, h, options.add_to_render and i == 0, options)
        except engine.AovError as e:
            errors.append("view layer '%s': %s" % (layer, e))
        except Exception as e:
            import traceback
            traceback.print_exc()
            errors.append("view layer '%s': compositor setup failed: %r" % (layer, e))
    try:
        compositor.ensure_export(scene, _layers(scene), runner.export_prefix(scene, options),
                                 options)
    except Exception as e:
        import traceback
        traceback.print_exc()
        errors.append("passes file output setup failed: %r" % (e,))
    for e in errors:
        runner.fail(scene.name, e)
    return errors


def fail_render(scene, message):
    """A frame has no AOV: with *Fail Render Without AOV* on, stop. In the
    background (farm) the process exits with FAIL_EXIT_CODE before the
    frame is written, so the task fails and is retried; in the UI nothing
    can stop the render job from Python: the error stays in the panel."""
    props = getattr(scene, "vsgl_indirect", None)
    if props is None or not props.fail_render:
        return
    if bpy.app.background:
        runner.report(scene.name, "ERROR", "stopping the render (exit status %d): %s "
                      "(Fail Render Without AOV is on)" % (FAIL_EXIT_CODE, message))
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(FAIL_EXIT_CODE)
    runner.report(scene.name, "ERROR", "this frame has no AOV (Fail Render Without AOV is on; "
                  "the UI cannot stop a running render): %s" % message)


def check_scene(scene):
    """Warnings about the setup around the AOV (logged at render start and
    shown in the panel): double counting, output in a temporary folder."""
    out = []
    dc = checks.double_counting(scene)
    if dc:
        out.append(dc)
    layers = _layers(scene)
    if layers:
        try:
            warn = checks.temp_output_warning(runner.output_path(scene, layers[0],
                                                                 scene.frame_current))
        except Exception:
            warn = ""
        if warn:
            out.append(warn)
    return out


SETUP_LOCK = ".vsgl-setup.lock"


@contextlib.contextmanager
def _setup_lock(directory):
    """One compositor setup at a time per AOV folder, across processes (and
    hosts sharing it): otherwise a worker may read another's placeholder just
    as that one removes it ("Cannot read ..."). An empty hidden file
    ``.vsgl-setup.lock`` stays in the folder."""
    try:
        import fcntl
        fd = os.open(os.path.join(directory, SETUP_LOCK), os.O_RDWR | os.O_CREAT, 0o666)
    except (ImportError, OSError):   # no fcntl (Windows) or a read-only folder: no lock
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)                 # releases the lock


def _setup_layer(scene, layer, path, w, h, add, options=None, attempts=6):
    """compositor.ensure with a file at ``path`` for the pass sockets. Another
    worker's placeholder may vanish while Blender reads it (the sockets then
    come out empty): check and retry with our own placeholder."""
    err = None
    for attempt in range(attempts):
        # Blender creates the pass sockets from a real file; never replace
        # one (a parallel process may have rendered this frame).
        inode = None if os.path.exists(path) else compositor.placeholder(path, w, h, exclusive=True, options=options)
        try:
            # One composite output: only the first rendered view layer's AOV is
            # added onto it; the others get their Image node to wire by hand.
            node = compositor.ensure(scene, layer, path, add, options)
            if compositor.has_passes(node, add):
                return node
            err = None
        except (engine.AovError, RuntimeError) as e:   # RuntimeError: "Cannot read" (it vanished)
            err = e
        finally:
            # The sockets stay; a black file must not look like an AOV.
            if inode:
                remove_if_inode(path, inode)
        time.sleep(0.02 * (attempt + 1))
    if isinstance(err, engine.AovError):
        raise err
    raise engine.AovError("compositor: the Image node for '%s' shows no AOV passes (%s)"
                          % (path, err or "the file could not be read"))


def _aside(path):
    d, name = os.path.split(path)
    return os.path.join(d, ".%s.retired-%d-%d" % (name, os.getpid(), time.monotonic_ns()))


def _retire(path, keep):
    """Rename ``path`` aside and delete it, unless ``keep(stat)`` holds for the
    file actually moved (another process renamed a new file over ``path``
    between our check and the rename): that one is linked back. Readers see
    the old file, the new one or none; never half a file."""
    aside = _aside(path)
    try:
        os.rename(path, aside)
    except FileNotFoundError:
        return False
    try:
        if keep(os.stat(aside)):
            try:
                os.link(aside, path)      # put it back unless yet another file is there
            except FileExistsError:
                pass
            return False
        return True
    finally:
        os.unlink(aside)


def remove_if_inode(path, inode):
    """Remove our placeholder at ``path`` only while it is the same file."""
    try:
        if os.stat(path).st_ino != inode:
            return False
    except FileNotFoundError:
        return False
    return _retire(path, lambda st: st.st_ino != inode)


def retire_stale(path, since):
    """After a failed computation: retire the file at ``path`` if it is older
    than ``since`` (a previous run's AOV must not be composited); a file
    written since (by another worker of this job) is a valid AOV and stays."""
    try:
        if os.stat(path).st_mtime >= since:
            return False
    except FileNotFoundError:
        return False
    return _retire(path, lambda st: st.st_mtime >= since)


@persistent
def on_render_init(scene, *args):
    props = getattr(scene, "vsgl_indirect", None)
    if props is None or not props.enabled or not engine.can_render():
        return
    _state["job_start"][scene.name] = time.time()
    errors = setup_scene(scene)
    if scene.vsgl_indirect.add_to_render and not scene.render.use_compositing:
        runner.report(scene.name, "WARNING", "compositing is off (Output Properties > Post "
                      "Processing): the AOV files are written but not added to the render")
    for w in check_scene(scene):
        runner.report(scene.name, "WARNING", w)
    if errors:
        fail_render(scene, errors[0])


@persistent
def on_render_pre(scene, *args):
    props = getattr(scene, "vsgl_indirect", None)
    if props is None or not props.enabled:
        return
    frame = scene.frame_current
    options = runner.options_of(scene)
    runner.begin(scene.name, frame)
    if not engine.can_render():
        msg = "frame %d: no indirect AOV: %s" % (frame, engine.library_error())
        runner.fail(scene.name, msg)
        fail_render(scene, msg)
        return
    _state["active"][scene.name] = frame
    _state["job_start"].setdefault(scene.name, time.time())
    for layer in _layers(scene):
        path = runner.output_path(scene, layer, frame, options)
        try:
            engine.check_output_path(path)
            _state["pending"][(scene.name, layer, frame)] = path
        except engine.AovError as e:
            msg = "frame %d, view layer '%s': %s" % (frame, layer, e)
            runner.fail(scene.name, msg)
            fail_render(scene, msg)


@persistent
def on_frame_change_post(scene, depsgraph=None, *args):
    if depsgraph is None or depsgraph.mode != "RENDER":
        return
    frame = _state["active"].get(scene.name)
    if frame is None or frame != scene.frame_current:
        return
    layer = depsgraph.view_layer.name
    key = (scene.name, layer, frame)
    if key in _state["done"] or key not in _state["pending"]:
        return
    _state["done"].add(key)
    result = runner.run_frame(scene, depsgraph, frame)
    path = _state["pending"].pop(key, None)
    if result is None and path is not None:
        # No AOV from us: a previous run's file must not be composited.
        since = _state["job_start"].get(scene.name, time.time())
        if retire_stale(path, since):
            runner.report(scene.name, "WARNING", "frame %d, view layer '%s': removed the previous "
                          "run's AOV %s (this frame's could not be computed)" % (frame, layer, path))
        fail_render(scene, "frame %d, view layer '%s': %s" % (
            frame, layer, runner.LAST_RUN.get(scene.name, {}).get("error") or "no AOV"))
    img = bpy.data.images.get(compositor.IMAGE_NAME % (scene.name, layer))
    if img is not None:
        img.reload()


@persistent
def on_render_post(scene, *args):
    frame = _state["active"].pop(scene.name, None)
    _state["done"] = {k for k in _state["done"] if k[0] != scene.name}
    for key in [k for k in _state["pending"] if k[0] == scene.name]:
        _state["pending"].pop(key)
        msg = ("frame %s, view layer '%s': the AOV was not computed "
               "(Blender gave no render depsgraph for it)" % (frame, key[1]))
        runner.fail(scene.name, msg)
        fail_render(scene, msg)


@persistent
def on_render_end(scene, *args):
    on_render_post(scene)
    _state["job_start"].pop(scene.name, None)


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
