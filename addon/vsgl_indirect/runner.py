"""bpy glue around one AOV computation: paths, export, reports, last-run info."""
import os
import sys
import time

import bpy

from . import convert, engine, export
from .config import Options
from .convert import ExportError

#: scene name -> dict(status, error, warnings, timings, skipped, summary, path, frame)
LAST_RUN = {}
#: How the panel words each status.
STATUS_TEXT = {"running": "running", "done": "done", "failed": "failed", "cancelled": "cancelled"}


def options_of(scene):
    return Options.from_props(scene.vsgl_indirect)


def report(scene_name, level, message):
    """Print to Blender's log (stdout) and keep it for the panel."""
    line = "VSGL %s: %s" % (level, message)
    print(line, file=sys.stderr if level == "ERROR" else sys.stdout, flush=True)
    LAST_RUN.setdefault(scene_name, {}).setdefault("messages", []).append((level, message))


def _absolute(p):
    """Blender path -> absolute; '//' of an unsaved file goes to the temp dir."""
    if p.startswith("//") and not bpy.data.filepath:
        return os.path.join(bpy.app.tempdir or "/tmp", p[2:])
    p = bpy.path.abspath(p)
    if p.startswith("//"):
        p = os.path.join(bpy.app.tempdir or "/tmp", p[2:])
    return os.path.abspath(p)


def render_dir(scene):
    return _absolute(os.path.dirname(scene.render.filepath) or "//")


def output_path(scene, view_layer, frame, options=None):
    options = options or options_of(scene)
    template = options.output_path or "{render_dir}/vsgl/{scene}_{view_layer}_####.exr"
    if "{view_layer}" not in template and sum(vl.use for vl in scene.view_layers) > 1:
        # Several rendered view layers must not share one file.
        head, tail = os.path.split(template)
        template = os.path.join(head, "{view_layer}_" + tail)
    p = convert.frame_path(template, frame, scene.name, view_layer, render_dir(scene))
    return os.path.normpath(_absolute(p))


def export_prefix(scene, options=None):
    """Absolute path prefix of the passes EXR (Blender appends frame + .exr)."""
    options = options or options_of(scene)
    template = options.export_path or "{render_dir}/passes/{scene}_"
    safe = convert.frame_path("{scene}", 0, scene.name).rsplit("_", 1)[0]   # the file-safe name
    p = template.replace("{render_dir}", render_dir(scene).rstrip("/\\")).replace("{scene}", safe)
    return os.path.normpath(_absolute(p)) + (os.sep if p.endswith(("/", "\\")) else "")


def begin(scene_name, frame):
    LAST_RUN[scene_name] = {"status": "running", "frame": frame, "messages": [],
                            "timings": {}, "skipped": "", "budget": "", "summary": "", "path": "", "error": "",
                            "memory": ""}


def export_scene(scene, depsgraph):
    t = time.perf_counter()
    sd = export.collect(depsgraph, scene)
    return sd, time.perf_counter() - t


def finish(scene_name, result, t_export):
    info = LAST_RUN.setdefault(scene_name, {})
    st = result.stats or {}
    timings = {"export": t_export}
    timings.update(result.timings)
    for k in ("scene_prep", "gbuffer", "rsm", "fit", "shade", "total"):
        if "seconds_" + k in st:
            timings["lib " + k] = st["seconds_" + k]
    info.update(status="done", timings=timings, skipped=st.get("skipped", ""), budget=st.get("budget", ""),
                summary=result.summary, path=result.path, memory=engine.memory_summary(st),
                lights={k: st[k] for k in ("lights_used", "lights_skipped", "vsgl_count") if k in st})
    for w in result.warnings:
        report(scene_name, "WARNING", w)
    for line in (st.get("skipped") or "").splitlines():
        if line.strip():
            report(scene_name, "INFO", "skipped: " + line.strip())
    for line in (st.get("budget") or "").splitlines():
        if line.strip():
            report(scene_name, "INFO", "budget: " + line.strip())
    mem = info.get("memory")
    report(scene_name, "INFO", "wrote %s (%s; export %.3fs, render %.3fs, write %.3fs%s)"
           % (result.path, result.summary, t_export, result.timings.get("render", 0),
              result.timings.get("write", 0), "; memory %s" % mem if mem else ""))


def cancel(scene_name, what="preview"):
    """The user cancelled (Esc): not a failure, no error."""
    info = LAST_RUN.setdefault(scene_name, {})
    info.update(status="cancelled", error="")
    report(scene_name, "INFO", "%s cancelled" % what)


def fail(scene_name, message):
    info = LAST_RUN.setdefault(scene_name, {})
    info.update(status="failed", error=message)
    report(scene_name, "ERROR", message)


def run_frame(scene, depsgraph, frame, options=None, progress=None, keep_planes=False):
    """Export the depsgraph's view layer, render, write this frame's EXR.
    Returns the engine Result or None after reporting the error."""
    options = options or options_of(scene)
    if options.threads == 0 and scene.render.threads_mode == "FIXED":
        options.threads = scene.render.threads   # honour blender -t N / Fixed threads
    layer = depsgraph.view_layer.name
    path = output_path(scene, layer, frame, options)
    begin(scene.name, frame)
    try:
        sd, t_export = export_scene(scene, depsgraph)
        result = engine.compute(sd, options, path, progress=progress, keep_planes=keep_planes,
                                metadata={"vsgl.scene": scene.name, "vsgl.view_layer": layer,
                                          "vsgl.frame": str(frame)})
    except (ExportError, engine.AovError) as e:
        fail(scene.name, "frame %d, view layer '%s': %s" % (frame, layer, e))
        return None
    except Exception as e:  # never let a bug take the render down silently
        import traceback
        traceback.print_exc()
        fail(scene.name, "frame %d, view layer '%s': internal error: %r" % (frame, layer, e))
        return None
    finish(scene.name, result, t_export)
    return result
