"""The Preview operator's modal path (timer polling, progress, Esc), driven
with stand-ins for the window manager and events: no GUI in background."""
import time
import types

import bpy
import pytest

from conftest import real_render_or_skip, room
from vsgl_indirect import engine, operators


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
    if engine.render_missing():
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
    assert any("cancelled" in m for _, m in op.reports), op.reports
