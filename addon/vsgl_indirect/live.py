"""Live preview logic without Blender: the viewport's camera as a
``vsgl_camera``, the display encoding of a pass, when to render what
(NavigationSchedule: coarse while the view moves, full once it rests), and
the scheduler that renders the newest edit on a worker thread and drops
superseded ones.

viewport.py is the Blender glue (handlers, drawing, panel); everything here
is testable headless.
"""
import threading
import time

import numpy as np

from . import convert

#: Debounce: an edit is rendered once nothing changed for this long (s).
DEBOUNCE_S = 0.04
#: Viewport resolution divisors offered in the panel.
SCALES = (1, 2, 3, 4)
#: The panel's default divider while the view moves (``coarse``): each
#: camera edit renders 1/2 x 1/2 of the pixels, drawn enlarged, until the
#: view rests. Measured in docs/performance.md ("Issue 12: navigation"):
#: ~1/3 of a full camera edit's time; mean FLIP 0.02-0.04 against the full
#: image.
COARSE_DEFAULT = 2
#: The largest divider while moving offered in the panel.
COARSE_MAX = 4

#: The panel's "Live" quality: the preview preset without edge rays and
#: without visibility rays, shading one pixel in 4 x 4 (not 2 x 2), with
#: GGX as one lobe (glossy_mode 0, ASG). On the live room its Combined pass
#: is within relMSE ~1e-4 / mean FLIP 0.02-0.04 of the preview preset's
#: without rays and with one lobe (docs/performance.md, "Live viewport");
#: with rays the preview also draws indirect shadows (a sun-lit cabinet's
#: on the wall behind it) at 1.5-1.8x the time, and with two lobes a glossy
#: surface's glint holds still as a light moves, at 1.2-1.45x. F12 keeps
#: the scene's preset. Its stride is 4 at every viewport size (stride_pixels
#: 0): the presets' stride_pixels would make it 8 at 960 x 540, where the
#: interpolation test then shades more than the wider spacing saves
#: (tools/bench_live.py, LIVE at 960 x 540, library time of a light / camera
#: edit: 0.072 / 0.128 s at 4, 0.082 / 0.152 s at 6, 0.103 / 0.191 s at 8;
#: the error against the preview preset's image the same, relMSE 3.6e-4).
LIVE_OVERRIDES = {"shade_stride": 4, "stride_pixels": 0, "edge_samples": 0, "visibility": 0, "glossy_mode": 0}


def render_settings(lib, quality, pixels=0):
    """Library settings of a live render (of ``pixels`` pixels: unused, kept
    for a size-dependent choice) at the panel's ``quality``: "LIVE" is the
    preview preset with LIVE_OVERRIDES, any other the preset of that name
    unchanged. ``lib``: the binding (libvsgl)."""
    s = lib.render_settings_preset(getattr(lib.Preset, "PREVIEW" if quality == "LIVE" else quality))
    if quality == "LIVE":
        for k, v in LIVE_OVERRIDES.items():
            setattr(s, k, v)
    return s


def _rows(m):
    """4x4 nested sequence / mathutils.Matrix / ndarray -> float64 ndarray."""
    return np.array([[float(m[r][c]) for c in range(4)] for r in range(4)], np.float64)


def view_camera(view_matrix, window_matrix, width, height, clip_start, clip_end,
                name="viewport"):
    """``vsgl_camera`` fields of a 3D viewport (Blender's ``region_3d``).

    ``view_matrix`` maps world to view space, ``window_matrix`` is the
    OpenGL projection of the region. Perspective: the projection's
    ``P[0][0] = 2 lens / sensor_width`` with a 36 mm horizontal sensor, and
    its off-centre terms are Blender's lens shift, ``P[0][2] = 2 shift_x``,
    ``P[1][2] = 2 shift_y width / height`` (shift in units of the fitted
    width, as ``BKE_camera_params_compute_viewplane`` defines it).
    Orthographic: ``ortho_scale = 2 / P[0][0]``, ``P[0][3] = -2 shift_x``.
    """
    V = _rows(view_matrix)
    P = _rows(window_matrix)
    world_from_view = np.linalg.inv(V)
    aspect = float(width) / float(height)
    if abs(P[3][3]) > 0.5:      # orthographic: w = 1
        scale = 2.0 / P[0][0]
        sx, sy = -P[0][3] / 2.0, -P[1][3] / 2.0 / aspect
        # Blender's orthographic view volume reaches behind the eye
        # (clip_start < 0): move the camera back so that it lies in front.
        back = max(0.0, -float(clip_start))
        world_from_view[:3, 3] += world_from_view[:3, 2] * back
        cs, ce = max(float(clip_start) + back, 1e-4), float(clip_end) + back
        return convert.camera_fields(name, "ORTHO", world_from_view, 50.0, 36.0, 36.0 / aspect,
                                     "HORIZONTAL", scale, sx, sy, cs, ce, width, height)
    lens = P[0][0] * 36.0 / 2.0
    sx, sy = P[0][2] / 2.0, P[1][2] / 2.0 / aspect
    return convert.camera_fields(name, "PERSP", world_from_view, lens, 36.0, 36.0 / aspect,
                                 "HORIZONTAL", 1.0, sx, sy, float(clip_start), float(clip_end),
                                 width, height)


def internal_size(region_width, region_height, scale):
    """The render size for a region drawn at 1/``scale`` resolution (>= 8 x 8)."""
    s = max(1, int(scale))
    return max(8, (int(region_width) + s - 1) // s), max(8, (int(region_height) + s - 1) // s)


def display_rgba(rgb, exposure=0.0, alpha=1.0):
    """Linear scene light (H, W, 3), rows top-down -> display-referred RGBA
    float32 (H, W, 4), rows bottom-up as a GPU texture wants: exposure in
    stops, the sRGB transfer function (Blender's "Standard" view), clipped
    to [0, 1]. NaN/negative become 0."""
    x = np.asarray(rgb, np.float32)
    # a table of the transfer function, looked up at 1/16384 steps (1/4 of an
    # 8-bit display step where the curve is steepest); NaN and negative -> 0
    # (fmax/fmin take the number over a NaN), +inf -> the last entry
    idx = np.multiply(x, np.float32(2.0 ** exposure * (_LUT_N - 1)))
    np.fmax(idx, np.float32(0.0), out=idx)
    np.fmin(idx, np.float32(_LUT_N - 1), out=idx)
    idx += np.float32(0.5)
    out = np.empty(x.shape[:2] + (4,), np.float32)
    out[::-1, :, :3] = _srgb_lut()[idx.astype(np.int32)]
    out[..., 3] = alpha
    return out


_LUT_N = 16385
_LUT = []


def _srgb_lut():
    if not _LUT:
        v = np.linspace(0.0, 1.0, _LUT_N, dtype=np.float64)
        _LUT.append(np.where(v <= 0.0031308, v * 12.92, 1.055 * np.power(v, 1 / 2.4) - 0.055).astype(np.float32))
    return _LUT[0]


class NavigationSchedule:
    """When the live preview renders what (the timer's logic, no Blender).

    Cycles' viewport renders at a coarse resolution while the view moves;
    so does this. ``view_changed(now)`` when the viewport's matrices or
    size changed, ``edited(now)`` for a scene edit or a changed setting;
    ``next(now, coarse_busy)`` on every timer tick says what to start
    (``tick(now, view_key, coarse_busy)``: both, the view's change seen as a
    new ``view_key``):

    * ``"coarse"``: the view moved and ``coarse`` > 1: render the view at
      1/``coarse`` of the pixels in each direction (drawn enlarged) at once,
      without waiting for the debounce; not while a coarse render is
      running or waiting (``coarse_busy``): the newest view is rendered when
      it ends, so the motion is drawn as fast as coarse images come;
    * ``"full"``: nothing changed for ``debounce`` seconds: the full image
      (the same as with ``coarse`` 1);
    * None: nothing to start.

    A scene edit asks only for the full render (a light edit is close to the
    coarse one's cost; a geometry edit is mostly export). With ``coarse`` 1
    every change waits for the debounce and renders full, as before.
    """

    def __init__(self, coarse=1, debounce=DEBOUNCE_S):
        self.coarse = int(coarse)
        self.debounce = float(debounce)
        self.dirty_since = None   # the newest change the full render waits for, or None
        self.moved = False        # the view moved since the last coarse render was started
        self.view_key = None      # the view seen by the last tick

    def view_changed(self, now):
        self.dirty_since = now
        self.moved = True

    def edited(self, now):
        self.dirty_since = now

    def tick(self, now, view_key, coarse_busy=False):
        if view_key != self.view_key:
            self.view_key = view_key
            self.view_changed(now)
        return self.next(now, coarse_busy)

    def next(self, now, coarse_busy=False):
        if self.dirty_since is not None and now - self.dirty_since >= self.debounce:
            self.dirty_since = None
            self.moved = False
            return "full"
        if self.moved and self.coarse > 1 and not coarse_busy:
            self.moved = False
            return "coarse"
        return None


class Job:
    """One render of one edit: ``cancelled`` is polled by the library's
    progress callback, so a superseded render stops within a block. A job
    that is not ``interruptible`` (a coarse render while the view moves: a
    fraction of a full one) runs to its end even when superseded; a newer
    submit only replaces it while it waits."""

    def __init__(self, seq, key, interruptible=True):
        self.seq = seq
        self.key = key
        self.interruptible = bool(interruptible)
        self.cancelled = threading.Event()
        self.t_submit = time.perf_counter()


class LiveRenderer:
    """Renders the newest request on one worker thread.

    ``submit(key, work)`` starts ``work(job)`` for a new edit (``work`` runs
    on the worker thread and returns the result; it must poll
    ``job.cancelled``). A newer submit cancels the running job (unless that
    was submitted with ``interruptible=False``: it ends and its image is
    shown); at most one job waits behind it, the newest, so a burst of edits
    renders the first and the last, never the ones between. ``poll()`` (main thread) returns a
    new finished result once, or None. A request whose key equals the last
    submitted one is ignored.
    """

    def __init__(self):
        self._lock = threading.Lock()
        self._seq = 0
        self._running = None       # Job on the worker
        self._pending = None       # (Job, work) waiting for the worker
        self._thread = None
        self._result = None        # (seq, key, value, seconds) newest finished
        self._delivered = 0
        self.last_key = None
        self.errors = []
        self.dropped = 0

    def submit(self, key, work, interruptible=True):
        with self._lock:
            if key is not None and key == self.last_key:
                return None
            self.last_key = key
            self._seq += 1
            job = Job(self._seq, key, interruptible)
            if self._running is not None and self._running.interruptible:
                self._running.cancelled.set()
            if self._pending is not None:
                self.dropped += 1
            self._pending = (job, work)
            if self._thread is None or not self._thread.is_alive():
                self._thread = threading.Thread(target=self._loop, name="vsgl-live", daemon=True)
                self._thread.start()
            return job

    def _loop(self):
        while True:
            with self._lock:
                if self._pending is None:
                    self._running = None
                    self._thread = None
                    return
                job, work = self._pending
                self._pending = None
                self._running = job
            try:
                value = work(job)
                err = None
            except Exception as e:  # reported on the main thread by poll()
                value, err = None, e
            with self._lock:
                if err is not None and not job.cancelled.is_set():
                    self.errors.append(str(err))
                elif value is not None and not job.cancelled.is_set():
                    self._result = (job.seq, job.key, value, time.perf_counter() - job.t_submit)

    def busy(self):
        with self._lock:
            return self._running is not None or self._pending is not None

    def busy_uninterruptible(self):
        """A job submitted with ``interruptible=False`` is running or waiting."""
        with self._lock:
            return ((self._running is not None and not self._running.interruptible)
                    or (self._pending is not None and not self._pending[0].interruptible))

    def poll(self):
        """(seq, key, value, seconds from submit) of a result not returned before, else None."""
        with self._lock:
            r = self._result
            if r is None or r[0] <= self._delivered:
                return None
            self._delivered = r[0]
            return r

    def cancel(self, wait=True):
        with self._lock:
            if self._running is not None:
                self._running.cancelled.set()
            self._pending = None
            self.last_key = None
            t = self._thread
        if wait and t is not None:
            t.join(timeout=10)

    def wait(self, timeout=30.0):
        """Block until the worker is idle (tests, headless timing)."""
        end = time.perf_counter() + timeout
        while self.busy() and time.perf_counter() < end:
            time.sleep(0.002)
        return not self.busy()
