"""Context: lifetime, errors with the library's messages, callbacks."""

import ctypes
import gc
import logging

import numpy as np
import pytest

import libvsgl as L
from conftest import require
from scenes import floor_and_wall


def test_context_lifetime(lib):
    with L.Context(thread_count=3) as c:
        assert c.thread_count == 3
        assert c.last_error == ""
    c.close()  # idempotent
    with pytest.raises(ValueError):
        c.thread_count
    assert L.Context().thread_count >= 1


def test_context_del_without_close_is_safe(lib):
    for _ in range(20):
        c = L.Context(log=lambda level, msg: None, progress=lambda s, f: False)
        del c
    gc.collect()


def test_bad_desc_raises_vsgl_error(lib):
    with pytest.raises(L.VsglError) as e:
        L.Context(desc_size=ctypes.sizeof(L.vsgl_context_desc) + 8)
    assert e.value.code == L.Result.ERROR_INVALID_ARGUMENT
    assert "vsgl_context_create" in str(e.value) and "invalid argument" in str(e.value)
    with pytest.raises(ValueError):
        L.Context(thread_count=-1)
    with pytest.raises(ValueError):
        L.Context(log_level="chatty")


def test_null_desc_and_out_at_c_level(lib):
    h = ctypes.c_void_p()
    assert lib.vsgl_context_create(None, ctypes.byref(h)) == 0 and h.value
    lib.vsgl_context_destroy(h)
    assert lib.vsgl_context_create(None, None) == L.Result.ERROR_INVALID_ARGUMENT
    lib.vsgl_context_destroy(None)  # NULL is allowed
    assert lib.vsgl_context_last_error(None)  # a static message, never NULL


def _bad_scene(ctx):
    s = floor_and_wall()
    s["positions"] = s["positions"].copy()
    s["positions"][3, 1] = np.nan
    return L.Scene(ctx, **s)


def test_scene_error_carries_library_message_and_logs(lib):
    require(lib, "vsgl_scene_create")
    lines = []
    with L.Context(log=lambda level, msg: lines.append((level, msg))) as ctx:
        with pytest.raises(L.VsglError) as e:
            _bad_scene(ctx)
        err = e.value
        assert err.code == L.Result.ERROR_INVALID_ARGUMENT
        assert err.message and err.message == ctx.last_error
        assert "vertex 3" in err.message, err.message  # names the element at fault
        assert err.message in str(err) and "vsgl_scene_create" in str(err)
        assert (L.LogLevel.ERROR, err.message) in lines


def test_exception_in_log_callback_does_not_propagate(lib, caplog):
    require(lib, "vsgl_scene_create")

    def bad_log(level, msg):
        raise RuntimeError("boom in log")
    with L.Context(log=bad_log) as ctx, caplog.at_level(logging.ERROR, "vsgl_indirect.libvsgl"):
        with pytest.raises(L.VsglError):  # the library's error, not the callback's
            _bad_scene(ctx)
    assert any("log callback" in r.getMessage() for r in caplog.records)


def _render(ctx, **kw):
    scene = L.Scene(ctx, **floor_and_wall())
    return L.render(ctx, scene, L.render_settings_preset("preview"), **kw)


def test_progress_callback_reports_and_cancels(lib):
    require(lib, "vsgl_scene_create", "vsgl_render", "vsgl_render_settings_preset")
    seen = []
    with L.Context(progress=lambda stage, f: seen.append((stage, f)) and False) as ctx:
        _render(ctx)
    assert seen and all(0.0 <= f <= 1.0 for _, f in seen), seen
    assert all(isinstance(s, str) and s for s, _ in seen)
    with L.Context(progress=lambda stage, f: f >= 0.0) as ctx:
        with pytest.raises(L.VsglCancelledError) as e:
            _render(ctx)
        assert e.value.code == L.Result.ERROR_CANCELLED


def test_keyboard_interrupt_in_progress_cancels_and_reraises(lib):
    require(lib, "vsgl_scene_create", "vsgl_render", "vsgl_render_settings_preset")
    calls = []

    def progress(stage, f):
        calls.append(stage)
        raise KeyboardInterrupt
    with L.Context(progress=progress) as ctx:
        with pytest.raises(KeyboardInterrupt):
            _render(ctx)
        assert len(calls) == 1, "the call must stop at the first interrupted report"
        # the context stays usable afterwards
        assert ctx.thread_count >= 1


def test_other_exception_in_progress_is_logged_and_ignored(lib, caplog):
    require(lib, "vsgl_scene_create", "vsgl_render", "vsgl_render_settings_preset")

    def progress(stage, f):
        raise ValueError("boom in progress")
    with L.Context(progress=progress) as ctx, caplog.at_level(logging.ERROR, "vsgl_indirect.libvsgl"):
        images, stats = _render(ctx)
    assert images["combined"].shape == (12, 16, 3)
    assert any("progress callback" in r.getMessage() for r in caplog.records)


def test_warnings_reach_the_log_callback(lib):
    require(lib, "vsgl_scene_create")
    lines = []
    s = floor_and_wall()
    s["indices"] = np.vstack([s["indices"], [[0, 0, 1]]]).astype(np.uint32)  # degenerate
    with L.Context(log=lambda level, msg: lines.append((level, msg)), log_level="warning") as ctx:
        L.Scene(ctx, **s).close()
    assert any(level == L.LogLevel.WARNING and "triangle 4" in msg for level, msg in lines), lines
    # (log_level 0 is both VSGL_LOG_ERROR and "default = warnings and errors"
    # in vsgl_context_desc, so errors-only cannot be requested)
