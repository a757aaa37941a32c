"""The Preview operator's modal path (timer polling, progress, Esc), driven
with stand-ins for the window manager and events: no GUI in background."""
import os
import time
import types

import bpy
import numpy as np

from conftest import real_render_or_skip, room
from vsgl_indirect import engine, operators, runner
from vsgl_indirect.config import Options


class WM:
    def __init__(self):
        self.progress = []
        self.ended = False

    def progress_begin(self, a, b):
        pass

    def progress_update(self, v):
        self.progress.append(v)

    def progress_end(self):
        self.ended = True

    def event_timer_remove(self, t):
        pass


class Workspace:
    def __init__(self):
        self.texts = []

    def status_text_set(self, t):
        self.texts.append(t)


def make_op():
    cls = operators.VSGL_OT_preview_indirect
    op = types.SimpleNamespace(reports=[])
    op.report = lambda kind, msg: op.reports.append((set(kind), msg))
    for name in ("_start", "_finish", "modal"):
        setattr(op, name, types.MethodType(getattr(cls, name), op))
    op._timer = None
    return op


def run_modal(op, first_event="TIMER"):
    ctx = types.SimpleNamespace(scene=bpy.context.scene, window_manager=WM(),
                                workspace=Workspace(),
                                evaluated_depsgraph_get=bpy.context.evaluated_depsgraph_get)
    op._start(ctx)
    ev = types.SimpleNamespace(type=first_event)
    ret = op.modal(ctx, ev)
    deadline = time.time() + 60
    while ret == {"RUNNING_MODAL"} and time.time() < deadline:
        time.sleep(0.02)
        ret = op.modal(ctx, types.SimpleNamespace(type="TIMER"))
    return ret, ctx


def test_modal_polls_until_done_and_shows_progress(scene, monkeypatch):
    room(scene)
    if engine.library_error():
        monkeypatch.setattr(engine, "RENDER_OVERRIDE", lambda sd, o: (time.sleep(0.3), (
            {p: __import__("numpy").zeros((sd.height, sd.width, 3), "float32")
             for p in engine.PLANES if p != "alpha"}, {}))[1])
    op = make_op()
    ret, ctx = run_modal(op)
    assert ret == {"FINISHED"}, op.reports
    assert ctx.window_manager.ended and ctx.window_manager.progress
    assert any(t and t.startswith("VSGL indirect:") for t in ctx.workspace.texts)
    assert ctx.workspace.texts[-1] is None        # status bar restored
    assert "VSGL Preview" in bpy.data.images


def test_modal_escape_cancels_through_progress_callback(scene):
    real_render_or_skip()
    room(scene)
    scene.render.resolution_x, scene.render.resolution_y = 320, 240
    scene.vsgl_indirect.preset = "QUALITY"
    op = make_op()
    ret, ctx = run_modal(op, first_event="ESC")
    assert ret == {"CANCELLED"}
    # Cancelled, not failed: an INFO report, no error, status "cancelled".
    assert op.reports == [({"INFO"}, "VSGL: preview cancelled")], op.reports
    info = runner.LAST_RUN[scene.name]
    assert info["status"] == "cancelled" and not info["error"]
    assert not any(level == "ERROR" for level, _ in info["messages"])


def test_modal_shows_the_write_phase(scene, monkeypatch):
    """The status bar says the EXR is being written (it sat at 'shade 100%'
    through a 4-7 s write)."""
    room(scene)
    real_write = engine.write_exr

    def slow_write(*a, **kw):
        time.sleep(0.4)
        return real_write(*a, **kw)
    monkeypatch.setattr(engine, "write_exr", slow_write)
    if engine.library_error():
        monkeypatch.setattr(engine, "RENDER_OVERRIDE", lambda sd, o: (
            {p: np.zeros((sd.height, sd.width, 3), "float32") for p in engine.PLANES if p != "alpha"}, {}))
    op = make_op()
    ret, ctx = run_modal(op)
    assert ret == {"FINISHED"}, op.reports
    assert any(t and t.startswith("VSGL indirect: writing the EXR") for t in ctx.workspace.texts), \
        ctx.workspace.texts
    assert 99 in ctx.window_manager.progress


class Area:
    def __init__(self, kind, image=None):
        self.type = kind
        self.spaces = types.SimpleNamespace(active=types.SimpleNamespace(image=image))
        self.redrawn = 0

    def tag_redraw(self):
        self.redrawn += 1


def wm_with(*areas):
    win = types.SimpleNamespace(screen=types.SimpleNamespace(areas=list(areas)))
    return types.SimpleNamespace(windows=[win])


def test_preview_goes_to_an_open_image_editor_preferring_its_own(scene, tmp_path):
    """Reuse: the editor already showing the preview, else one showing no
    image (or a VSGL one), else any; the user's render result stays put."""
    path = str(tmp_path / "p.exr")
    z = np.full((6, 8, 3), 0.25, np.float32)
    engine.write_exr(path, {p: z for p in engine.PLANES if p != "alpha"}, Options())
    img = operators.load_preview_image(path)
    other = bpy.data.images.new("Render Result stand-in", 4, 4)
    user, empty, view3d = Area("IMAGE_EDITOR", other), Area("IMAGE_EDITOR"), Area("VIEW_3D")
    ctx = types.SimpleNamespace(window_manager=wm_with(view3d, user, empty), window=None)
    assert operators.show_image(ctx, img) is empty
    assert empty.spaces.active.image == img and user.spaces.active.image == other
    assert empty.redrawn == 1
    mine = Area("IMAGE_EDITOR", img)
    ctx = types.SimpleNamespace(window_manager=wm_with(user, empty, mine), window=None)
    empty.spaces.active.image = None
    assert operators.show_image(ctx, img) is mine
    # No editor and no window (background): nothing to open, None.
    ctx = types.SimpleNamespace(window_manager=wm_with(view3d), window=None)
    assert operators.show_image(ctx, img) is None


def test_preview_image_reloads_as_multilayer(scene, tmp_path):
    """A second preview reloads the same image (its editor keeps its
    layer/pass menus: tools/panel_screenshots.sh checks that in the UI)."""
    for i, v in enumerate((0.25, 0.5)):
        path = str(tmp_path / ("p%d.exr" % i))
        z = np.full((6, 8, 3), v, np.float32)
        engine.write_exr(path, {p: z for p in engine.PLANES if p != "alpha"}, Options())
        img = operators.load_preview_image(path)
        assert img.name == operators.PREVIEW_IMAGE
        assert os.path.normpath(bpy.path.abspath(img.filepath)) == path
        assert img.type == "MULTILAYER", img.type
    assert len([im for im in bpy.data.images if im.name.startswith(operators.PREVIEW_IMAGE)]) == 1
