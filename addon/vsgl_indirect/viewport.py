"""Live indirect light in the 3D viewport.

Toggle in the 3D viewport's sidebar (N) > VSGL. While it is on, every edit
(a light or object moved, a material changed) and every view change
re-renders the indirect light of that view on a worker thread and draws it
over the viewport. While the view moves, each view is rendered at once at a
coarser resolution (the panel's "Divider While Moving") and drawn enlarged;
once the view rests, and after every other edit, the full image follows
(debounced, live.DEBOUNCE_S; live.NavigationSchedule). A newer edit cancels
the full render of an older one. Meshes are read from Blender only when
their geometry changed (the export's mesh cache). Scene logic lives in
live.py; this module is the bpy glue: handlers, a timer, drawing.
"""
import time

import bpy
import numpy as np

from . import export, live, settings
from .convert import ExportError

#: The one live session (None when off): see _Session.
_SESSION = None


class _Session:
    """What the live preview keeps between edits."""

    def __init__(self, area_ptr):
        self.area_ptr = area_ptr
        self.renderer = live.LiveRenderer()
        self.mesh_cache = {}
        self.scene_serial = 0        # bumped by depsgraph updates
        self.schedule = live.NavigationSchedule()   # coarse while moving, full at rest
        self.schedule.edited(time.perf_counter())
        self.image = None            # (display RGBA float32, w, h)
        self.texture = None          # (gpu texture, image serial)
        self.image_serial = 0
        self.message = ""
        self.timings = {}
        self.ctx = None              # libvsgl context, created on the worker thread
        self.last_edit = time.perf_counter()   # newest edit or view change seen
        self.last_done = 0.0                   # when the newest image arrived
        self.last_submit = 0.0                 # when the newest render was started
        self.submits = 0                       # renders started
        self.lib_scene = None                  # libvsgl.Scene reused while geometry stands still
        self.lib_arrays = None                 # _scene_signature(sd) of what it was built from
        self.scene_builds = 0
        self.lib_cache = None                  # libvsgl.RenderCache: G-buffer / VSGLs of the last render
        self.updates = 0                       # depsgraph updates seen
        self.current_job = None
        self.coarse_submits = 0                # coarse renders started (the view moving)

    @property
    def dirty_since(self):
        """When the newest change waiting for its full render happened, or None."""
        return self.schedule.dirty_since

    def close(self):
        self.renderer.cancel(wait=True)
        if self.lib_cache is not None:
            self.lib_cache.close()
            self.lib_cache = None
        if self.lib_scene is not None:
            self.lib_scene.close()
            self.lib_scene = None
        if self.ctx is not None:
            try:
                self.ctx.close()
            except Exception:
                pass
            self.ctx = None


def _props(context):
    return context.window_manager.vsgl_live


def _find_area(ptr):
    wm = bpy.context.window_manager
    for win in wm.windows:
        for area in win.screen.areas:
            if area.as_pointer() == ptr:
                return win, area
    return None, None


def _region_of(area):
    for r in area.regions:
        if r.type == "WINDOW":
            return r
    return None


# --------------------------------------------------------------------------
# Edits
# --------------------------------------------------------------------------

def _on_depsgraph_update(scene, depsgraph=None):
    s = _SESSION
    if s is None:
        return
    geometry = set()
    everything = False
    for u in (depsgraph.updates if depsgraph is not None else ()):
        if u.is_updated_geometry:
            idb = u.id
            if isinstance(idb, bpy.types.Object):
                geometry.add(idb.original.name_full if idb.original else idb.name_full)
            elif isinstance(idb, bpy.types.Mesh):
                everything = True     # a mesh shared by several objects: read them all again
    if everything:
        s.mesh_cache.clear()
    elif geometry:
        for k in [k for k in s.mesh_cache if k[0] in geometry]:
            del s.mesh_cache[k]
    s.scene_serial += 1
    s.updates += 1
    s.last_edit = time.perf_counter()
    s.schedule.edited(s.last_edit)


def _view_key(region, rv3d, props):
    return (tuple(tuple(r) for r in rv3d.view_matrix), tuple(tuple(r) for r in rv3d.window_matrix),
            region.width, region.height, int(props.scale))


def _submit(session, context_scene, depsgraph, region, rv3d, space, props, coarse=1):
    """Export on this (main) thread, render on the worker. ``coarse`` > 1:
    the view while it moves, at 1/coarse of the pixels in each direction
    (drawn enlarged), not cancelled by a newer edit."""
    t0 = time.perf_counter()
    w, h = live.internal_size(region.width, region.height, int(props.scale) * max(1, int(coarse)))
    try:
        sd = export.collect(depsgraph, context_scene, require_lights=False, camera=False,
                            mesh_cache=session.mesh_cache)
        if rv3d.is_perspective:
            cs, ce = space.clip_start, space.clip_end
        else:
            cs, ce = -space.clip_end * 0.5, space.clip_end * 0.5
        sd.camera = live.view_camera(rv3d.view_matrix, rv3d.window_matrix, w, h, cs, ce)
        sd.camera_name, sd.width, sd.height = "viewport", w, h
    except ExportError as e:
        session.message = str(e)
        return
    t_export = time.perf_counter() - t0
    if not sd.lights:
        session.message = "no light with non-zero power"
        session.image = None
        return
    coarse = max(1, int(coarse))
    key = (session.scene_serial, _view_key(region, rv3d, props), props.quality, coarse)
    preset = props.quality
    threads = context_scene.vsgl_indirect.threads if hasattr(context_scene, "vsgl_indirect") else 0
    exposure = context_scene.view_settings.exposure

    def work(job):
        out = _render(session, sd, preset, threads, job, exposure, t_export)
        if out is not None:
            out["coarse"] = coarse
        return out

    if session.renderer.submit(key, work, interruptible=coarse == 1) is not None:
        session.submits += 1
        session.coarse_submits += coarse > 1
        session.last_submit = time.perf_counter()


def _render(session, sd, preset, threads, job, exposure, t_export):
    """Worker thread: the library call and the display encoding (no bpy)."""
    from . import engine
    lib = engine._binding()
    session.current_job = job
    if session.ctx is None:
        session.ctx = lib.Context(thread_count=max(int(threads), 0), log_level=lib.LogLevel.ERROR,
                                  progress=lambda stage, f: bool(session.current_job and
                                                                 session.current_job.cancelled.is_set()))
    if session.lib_cache is None:
        session.lib_cache = lib.RenderCache(session.ctx)
    t0 = time.perf_counter()
    arrays = engine.scene_arrays(sd, lib)
    view = dict(camera=arrays.pop("camera"), lights=arrays.pop("lights"))
    signature = _scene_signature(sd)
    if session.lib_scene is None or not _equal(session.lib_arrays, signature):
        if session.lib_scene is not None:
            session.lib_scene.close()
            session.lib_scene = None
        try:
            session.lib_scene = lib.Scene(session.ctx, **arrays, **view)
        except lib.VsglError as e:
            raise RuntimeError("the scene was refused: %s" % (e.message or e))
        session.lib_arrays = signature
        session.scene_builds += 1
    else:
        session.lib_scene.set_view(view["camera"], view["lights"])
    t1 = time.perf_counter()
    settings = live.render_settings(lib, preset, sd.width * sd.height)
    try:
        images, stats = lib.render(session.ctx, session.lib_scene, settings, ("combined",),
                                   cache=session.lib_cache)
    except lib.VsglCancelledError:
        return None
    t2 = time.perf_counter()
    rgba = live.display_rgba(images["combined"], exposure)
    t3 = time.perf_counter()
    return dict(rgba=rgba, width=sd.width, height=sd.height,
                timings=dict(export=t_export, scene=t1 - t0, render=t2 - t1, encode=t3 - t2,
                             **{k: float(stats.get("seconds_" + k, 0.0)) for k in ("gbuffer", "rsm", "fit", "shade")}),
                reused=int(stats.get("reused", 0)),
                triangles=sd.triangle_count, vsgls=int(stats.get("vsgl_count", 0)) if isinstance(stats, dict) else 0)


def _scene_signature(sd):
    """Everything of ``sd`` a library scene is built from but camera and
    lights: while it stays equal, vsgl_scene_set_view keeps the BVH."""
    return (sd.positions, sd.indices, sd.corner_normals, sd.corner_uvs,
            getattr(sd, "corner_tangents", None), sd.material_indices, list(sd.materials),
            getattr(sd, "material_textures", None), list(getattr(sd, "textures", ()) or ()),
            getattr(sd, "corner_colors", None))


def _equal(a, b):
    """Deep equality of arrays, sequences, dicts and plain values."""
    if a is b:
        return True
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and a.shape == b.shape
                and a.dtype == b.dtype and np.array_equal(a, b))
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    return type(a) is type(b) and a == b


def _tick():
    """Timer on the main thread: start renders of settled edits, pick up results."""
    s = _SESSION
    if s is None:
        return None
    win, area = _find_area(s.area_ptr)
    if area is None:
        stop()
        return None
    region = _region_of(area)
    space = area.spaces.active
    rv3d = getattr(space, "region_3d", None)
    if region is None or rv3d is None:
        return 0.05
    props = bpy.context.window_manager.vsgl_live
    vk = _view_key(region, rv3d, props)
    now = time.perf_counter()
    s.schedule.coarse = int(props.coarse)
    if vk != s.schedule.view_key:
        s.last_edit = now
    what = s.schedule.tick(now, vk, coarse_busy=s.renderer.busy_uninterruptible())
    if what is not None:
        scene = win.scene
        with bpy.context.temp_override(window=win, area=area, region=region):
            depsgraph = bpy.context.evaluated_depsgraph_get()
        _submit(s, scene, depsgraph, region, rv3d, space, props,
                coarse=s.schedule.coarse if what == "coarse" else 1)
    r = s.renderer.poll()
    if r is not None:
        seq, key, value, seconds = r
        s.image = value
        s.image_serial += 1
        s.last_done = time.perf_counter()
        s.timings = dict(value["timings"], total=seconds)
        s.message = ""
        area.tag_redraw()
    while s.renderer.errors:
        s.message = s.renderer.errors.pop(0)
        area.tag_redraw()
    return 0.02


# --------------------------------------------------------------------------
# Drawing
# --------------------------------------------------------------------------

_DRAW_HANDLE = None


def _image_shader():
    import gpu
    return gpu.shader.from_builtin("2D_IMAGE" if bpy.app.version < (4, 0, 0) else "IMAGE")


def _texture(s):
    import gpu
    if s.texture is not None and s.texture[1] == s.image_serial:
        return s.texture[0]
    img = s.image
    flat = img["rgba"].ravel()
    buf = gpu.types.Buffer("FLOAT", flat.size, flat)
    tex = gpu.types.GPUTexture((img["width"], img["height"]), format="RGBA16F", data=buf)
    s.texture = (tex, s.image_serial)
    return tex


def _draw():
    s = _SESSION
    ctx = bpy.context
    if s is None or ctx.area is None or ctx.area.as_pointer() != s.area_ptr or s.image is None:
        return
    import gpu
    from gpu_extras.batch import batch_for_shader
    region = ctx.region
    props = ctx.window_manager.vsgl_live
    tex = _texture(s)
    shader = _image_shader()
    w, h = region.width, region.height
    quad = {"pos": ((0, 0), (w, 0), (w, h), (0, h)), "texCoord": ((0, 0), (1, 0), (1, 1), (0, 1))}
    batch = batch_for_shader(shader, "TRI_FAN", quad)
    gpu.state.blend_set("ADDITIVE" if props.display == "ADD" else "NONE")
    shader.bind()
    shader.uniform_sampler("image", tex)
    batch.draw(shader)
    gpu.state.blend_set("NONE")


# --------------------------------------------------------------------------
# On / off, properties, operator, panel
# --------------------------------------------------------------------------

def start(area):
    global _SESSION, _DRAW_HANDLE
    stop()
    _SESSION = _Session(area.as_pointer())
    if _on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(_on_depsgraph_update)
    if _DRAW_HANDLE is None and not bpy.app.background:
        _DRAW_HANDLE = bpy.types.SpaceView3D.draw_handler_add(_draw, (), "WINDOW", "POST_PIXEL")
    bpy.app.timers.register(_tick, first_interval=0.0)
    area.tag_redraw()
    return _SESSION


def stop():
    global _SESSION, _DRAW_HANDLE
    s, _SESSION = _SESSION, None
    if s is not None:
        s.close()
    if _on_depsgraph_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(_on_depsgraph_update)
    if _DRAW_HANDLE is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_DRAW_HANDLE, "WINDOW")
        _DRAW_HANDLE = None
    if bpy.app.timers.is_registered(_tick):
        bpy.app.timers.unregister(_tick)


def session():
    return _SESSION


def _redraw(self, context):
    s = _SESSION
    if s is not None:
        s.schedule.edited(time.perf_counter())
        s.renderer.last_key = None


# No update= callbacks in the pip bpy module: its 4.2 LTS build segfaults at
# exit while one is registered (settings.py; a module has no viewport to redraw).
_REDRAW = {"update": _redraw} if settings.IN_APPLICATION else {}


class VSGLLiveProps(bpy.types.PropertyGroup):
    quality: bpy.props.EnumProperty(
        name="Quality",
        items=(("LIVE", "Live", "Preview's lattice and RSM, 1 sample without edge rays, shading 1 pixel "
                "in 4 x 4: about half of Preview's time, within a few per cent of Preview's image"),
               ("PREVIEW", "Preview", "Lattice 32, RSM 128, 1 sample (8 x 8 rays at edges), "
                "shading 1 pixel in 2 x 2: about 0.1-0.4 s at 960 x 540 on 2 cores, bias within about 20 %"),
               ("BALANCED", "Balanced", "Lattice 192, RSM 256, 2 x 2 samples (8 x 8 rays at edges), "
                "visibility rays: several times slower than Preview, bias within about 5 %")),
        default="LIVE", **_REDRAW,
        description="Settings of the live render (the scene's own preset is used for F12)")
    scale: bpy.props.IntProperty(
        name="Resolution Divider", min=1, max=4, default=2, **_REDRAW,
        description="Render the viewport at 1/N of its pixels in each direction: 2 renders a "
                    "quarter of the pixels, about 3-4x faster")
    coarse: bpy.props.IntProperty(
        name="Divider While Moving", min=1, max=live.COARSE_MAX, default=live.COARSE_DEFAULT, **_REDRAW,
        description="While the view moves, render each view at 1/N of the Resolution Divider's pixels in "
                    "each direction and draw it enlarged (as Cycles' viewport does while navigating); once "
                    "the view rests, the full image follows, the same as with 1. 2: about a third of the "
                    "time per view. 1: off")
    display: bpy.props.EnumProperty(
        name="Display",
        items=(("INDIRECT", "Indirect Only", "Show only the indirect light (the AOV's Combined pass)"),
               ("ADD", "Add to Viewport", "Add the indirect light over what the viewport draws "
                "(approximate: the addition happens after the view transform)")),
        default="INDIRECT", **_REDRAW,
        description="How the live indirect light is drawn over the viewport")


class VSGL_OT_live_preview(bpy.types.Operator):
    bl_idname = "vsgl.live_preview"
    bl_label = "Live Indirect Light"
    bl_description = ("Toggle the live indirect light in this 3D viewport: re-rendered on a worker "
                      "thread after every edit or view change, drawn over the viewport")

    @classmethod
    def poll(cls, context):
        return context.area is not None and context.area.type == "VIEW_3D"

    def execute(self, context):
        s = _SESSION
        if s is not None and s.area_ptr == context.area.as_pointer():
            stop()
            self.report({"INFO"}, "Live indirect light off")
        else:
            start(context.area)
            self.report({"INFO"}, "Live indirect light on")
        context.area.tag_redraw()
        return {"FINISHED"}


class VIEW3D_PT_vsgl_live(bpy.types.Panel):
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "VSGL"
    bl_label = "Live Indirect Light"

    def draw(self, context):
        layout = self.layout
        props = context.window_manager.vsgl_live
        s = _SESSION
        on = s is not None and context.area is not None and s.area_ptr == context.area.as_pointer()
        layout.operator(VSGL_OT_live_preview.bl_idname, text="Stop" if on else "Start",
                        icon="PAUSE" if on else "PLAY", depress=on)
        col = layout.column()
        col.use_property_split = True
        col.use_property_decorate = False
        col.prop(props, "quality")
        col.prop(props, "scale")
        col.prop(props, "coarse")
        col.prop(props, "display")
        if on:
            if s.message:
                for line in _wrap(s.message, 40):
                    layout.label(text=line, icon="ERROR" if line is not None else "NONE")
            if s.timings:
                t = s.timings
                layout.label(text="%.0f ms: render %.0f, scene %.0f, export %.0f" % (
                    1000 * t["total"], 1000 * t["render"], 1000 * t["scene"], 1000 * t["export"]))
            if s.image is not None:
                img = s.image
                layout.label(text="%d x %d%s, %d triangles" % (
                    img["width"], img["height"], " (moving)" if img.get("coarse", 1) > 1 else "",
                    img["triangles"]))


def _wrap(text, width):
    words, lines, cur = text.split(), [], ""
    for w in words:
        if cur and len(cur) + 1 + len(w) > width:
            lines.append(cur)
            cur = w
        else:
            cur = (cur + " " + w).strip()
    if cur:
        lines.append(cur)
    return lines


_classes = (VSGLLiveProps, VSGL_OT_live_preview, VIEW3D_PT_vsgl_live)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.WindowManager.vsgl_live = bpy.props.PointerProperty(type=VSGLLiveProps)


def unregister():
    stop()
    if hasattr(bpy.types.WindowManager, "vsgl_live"):
        del bpy.types.WindowManager.vsgl_live
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
