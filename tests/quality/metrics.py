"""What the eye sees: bias, relMSE, structured error, FLIP, flicker (numpy).

Images are float arrays (H, W, 3) of linear RGB, row 0 = top. The passes
compared are the coloured ones: Diff = DiffInd*DiffCol, Gloss =
GlossInd*GlossCol, Combined = Diff + Gloss (`coloured`).

- bias(a, ref): sum(a) / sum(ref) (1 = no energy lost or added).
- relmse(a, ref): mean((a - ref)^2 / (ref^2 + 0.01)) over pixels and
  channels (docs/references.md §6).
- structured(a, ref, k=4): relmse after both are box-downsampled k x k; it
  removes most of the reference's noise but keeps blotches.
- ref_noise(c1, c2, k): what a perfect image would score against the mean of
  two independent reference renders c1, c2 (each with per-pixel noise
  variance s^2): their difference has variance 2 s^2, the mean's error s^2/2,
  so the mean's own relMSE is relmse(c1, c2) / 4 (k = 1: full resolution,
  k = 4: the structured error's floor). A method's structured error is its
  structure plus this floor: "3x the reference noise" leaves 2x for blotches.
- flip(a, ref): mean FLIP (flip-evaluator, HDR mode, linear input; exposure
  range chosen by FLIP from the reference), or None if the package does not
  import (FLIP_ERROR says why).
- flicker(frames): relative RMS of consecutive frames
  sqrt(sum((f[t+1] - f[t])^2) / sum(f[t]^2)); the median over the pairs, and
  the ratio of the median second difference
  sqrt(sum((f[t+2] - 2 f[t+1] + f[t])^2) / sum(f[t+1]^2)) to it. For a smooth
  change the second difference is much smaller than the first (ratio << 1);
  for frame-to-frame noise of equal variance it is sqrt(3) = 1.73x: a ratio
  > 1 means jitter. Also the L1 form, median of sum|f[t+1] - f[t]| / sum|f[t]|,
  which a few hot pixels cannot dominate.
"""
import math

import numpy as np

EPS = 0.01  # relMSE's regulariser (docs/references.md §6)

try:  # FLIP is optional: the rest of the harness works without it
    import flip_evaluator as _flip
    FLIP_ERROR = None
except Exception as e:  # noqa: BLE001  (any import failure: report it, skip FLIP)
    _flip = None
    FLIP_ERROR = "%s: %s" % (type(e).__name__, e)


def coloured(p):
    """Diff, Gloss, Combined from a dict with DiffInd, GlossInd, DiffCol, GlossCol."""
    d = np.asarray(p["DiffInd"], np.float64) * np.asarray(p["DiffCol"], np.float64)
    g = np.asarray(p["GlossInd"], np.float64) * np.asarray(p["GlossCol"], np.float64)
    return {"Diff": d, "Gloss": g, "Combined": d + g}


def bias(a, ref):
    s = float(np.sum(ref, dtype=np.float64))
    return float(np.sum(a, dtype=np.float64)) / s if s > 0 else float("nan")


def relmse(a, ref):
    a = np.asarray(a, np.float64)
    b = np.asarray(ref, np.float64)
    return float(np.mean((a - b) ** 2 / (b * b + EPS)))


def rel_rmse(a, ref):
    """Relative RMSE sqrt(sum((a - ref)^2) / sum(ref^2)) (bright pixels dominate; relMSE weights them down)."""
    return _rel(np.asarray(a, np.float64) - np.asarray(ref, np.float64), ref)


def pareto_front(times, errors):
    """Indices of the points no other point beats in both time and error
    (lower is better in both; a point equal in both to another is kept
    once, the first), sorted by time."""
    t, e = np.asarray(times, np.float64), np.asarray(errors, np.float64)
    keep = []
    for i in np.lexsort((e, t)):
        if not (np.isfinite(t[i]) and np.isfinite(e[i])):
            continue
        if not keep or e[i] < e[keep[-1]]:
            keep.append(int(i))
    return keep


def time_at_error(times, errors, target):
    """The time a method whose runs (times, errors) form a curve (ordered
    by cost, e.g. by spp) needs to reach `target` error: log-log
    interpolation between the last run above the target and the first at
    or below it. Returns (time, how) with how = "reached" (interpolated),
    "first" (the cheapest run already reaches it: its time, an upper
    bound) or "never" (no run reaches it: the dearest run's time, a lower
    bound)."""
    t, e = np.asarray(times, np.float64), np.asarray(errors, np.float64)
    for i in range(len(t)):
        if e[i] <= target:
            if i == 0:
                return float(t[0]), "first"
            f = (math.log(e[i - 1]) - math.log(target)) / (math.log(e[i - 1]) - math.log(e[i]))
            return float(math.exp(math.log(t[i - 1]) + f * (math.log(t[i]) - math.log(t[i - 1])))), "reached"
    return float(t[-1]), "never"


def downsample(img, k=4):
    """Box mean over k x k blocks (the image cropped to a multiple of k)."""
    img = np.asarray(img, np.float64)
    if k <= 1:
        return img
    h, w = img.shape[0] // k * k, img.shape[1] // k * k
    x = img[:h, :w]
    return x.reshape(h // k, k, w // k, k, *x.shape[2:]).mean(axis=(1, 3))


def structured(a, ref, k=4):
    return relmse(downsample(a, k), downsample(ref, k))


def ref_noise(c1, c2, k=4):
    """relMSE of the two-seed mean against the truth, estimated as
    relmse(down(c1), down(c2)) / 4 (see the module docstring)."""
    return relmse(downsample(c1, k), downsample(c2, k)) / 4.0


def seed_agreement(c1, c2):
    """z = sum(c1 - c2) / sqrt(sum((c1 - c2)^2)): for independent renders of
    one image, approximately standard normal (the sum of independent
    per-pixel differences over its own standard error). |z| > 4: the two
    renders disagree by more than their noise."""
    d = np.asarray(c1, np.float64) - np.asarray(c2, np.float64)
    s = float(np.sqrt(np.sum(d * d)))
    return float(np.sum(d)) / s if s > 0 else float("nan")


def flip(a, ref):
    """Mean HDR-FLIP of a against ref (both linear RGB), or None without the package."""
    if _flip is None:
        return None
    r = np.ascontiguousarray(np.clip(ref, 0, None), np.float32)
    t = np.ascontiguousarray(np.clip(a, 0, None), np.float32)
    if not np.any(r > 0):
        return None
    _, mean, _ = _flip.evaluate(r, t, "HDR", inputsRGB=False, applyMagma=False)
    return float(mean)


def flip_map(a, ref):
    """The per-pixel FLIP error map (H, W) in [0, 1], or None."""
    if _flip is None:
        return None
    r = np.ascontiguousarray(np.clip(ref, 0, None), np.float32)
    t = np.ascontiguousarray(np.clip(a, 0, None), np.float32)
    m, _, _ = _flip.evaluate(r, t, "HDR", inputsRGB=False, applyMagma=False)
    return np.asarray(m).reshape(r.shape[:2])


def _rel(d, f):
    s = float(np.sum(np.asarray(f, np.float64) ** 2))
    return float(np.sqrt(np.sum(np.asarray(d, np.float64) ** 2) / s)) if s > 0 else float("nan")


def _rel_cross(da, db, f):
    """_rel of a change d seen twice with independent noise, da = d + n_a and
    db = d + n_b: sqrt(max(0, da . db)) / |f|, since E[da . db] = |d|^2 (0
    when the product is negative: no change measurable above the noise)."""
    s = float(np.sum(np.asarray(f, np.float64) ** 2))
    dot = float(np.sum(np.asarray(da, np.float64) * np.asarray(db, np.float64)))
    return math.sqrt(max(dot, 0.0) / s) if s > 0 else float("nan")


def _rel_l1(d, f):
    s = float(np.sum(np.abs(np.asarray(f, np.float64))))
    return float(np.sum(np.abs(np.asarray(d, np.float64)))) / s if s > 0 else float("nan")


def flicker(frames):
    """dict(first=[per pair], second=[per triple], median, median_second,
    mean (over pairs: the sequence's change spread evenly over its frames),
    ratio = median_second / median, l1 = median over pairs of
    sum|f[t+1] - f[t]| / sum|f[t]|) of a frame sequence (>= 3 frames for the
    ratio). The RMS form (the issue's) is dominated by a few hot pixels when
    there are any (a junction pixel jumping from 1.5 to 0.4 can carry 99 % of
    the squared difference); the L1 form shows how much of the image moves."""
    f = [np.asarray(x, np.float64) for x in frames]
    first = [_rel(f[t + 1] - f[t], f[t]) for t in range(len(f) - 1)]
    second = [_rel(f[t + 2] - 2 * f[t + 1] + f[t], f[t + 1]) for t in range(len(f) - 2)]
    l1 = [_rel_l1(f[t + 1] - f[t], f[t]) for t in range(len(f) - 1)]
    med = float(np.median(first)) if first else float("nan")
    med2 = float(np.median(second)) if second else float("nan")
    return dict(first=first, second=second, median=med, median_second=med2,
                mean=float(np.mean(first)) if first else float("nan"),
                ratio=med2 / med if med > 0 else float("nan"), l1=float(np.median(l1)) if l1 else float("nan"))


def jitter(frames):
    """Median over consecutive pairs of the RMS of (f[t+1] - f[t]) - (f[n] -
    f[0]) / n relative to the RMS of f[t]: the change in excess of the
    sequence's own straight-line trend. A smooth motion over a few frames
    changes each pixel at a steady rate (jitter ~0); a fit that reshuffles,
    or an edge or highlight that jumps across pixels, does not."""
    f = [np.asarray(x, np.float64) for x in frames]
    n = len(f) - 1
    if n < 2:
        return float("nan")
    trend = (f[-1] - f[0]) / n
    return float(np.median([_rel((f[t + 1] - f[t]) - trend, f[t]) for t in range(n)]))


def excess_steps(frames, truth):
    """Per consecutive pair, (f[t+1] - f[t]) - (g[t+1] - g[t]): a sequence's
    change beyond that of `truth` (the same motion rendered densely)."""
    f = [np.asarray(x, np.float64) for x in frames]
    g = [np.asarray(x, np.float64) for x in truth]
    if len(f) != len(g) or len(f) < 2:
        raise ValueError("excess_flicker: %d frames against %d truth frames" % (len(f), len(g)))
    return [(f[t + 1] - f[t]) - (g[t + 1] - g[t]) for t in range(len(f) - 1)]


def excess_flicker(frames, truth):
    """Median over consecutive pairs of the RMS of excess_steps relative to
    the RMS of f[t]: how much a sequence changes beyond the change of
    `truth` (the same motion rendered densely)."""
    f = [np.asarray(x, np.float64) for x in frames]
    return float(np.median([_rel(d, f[t]) for t, d in enumerate(excess_steps(frames, truth))]))


def motion_change(first, last, steps):
    """The per-frame change of a smooth motion, in flicker()'s RMS form,
    from two independent renders (seeds) of its first and last frames:
    first = (a0, b0), last = (a1, b1). With d_a = a1 - a0 and d_b = b1 - b0,
    E[d_a . d_b] = |d|^2 (their noise is independent), so sqrt(d_a . d_b) /
    steps over the RMS of the first frame is the motion's own change per
    frame without the noise that inflates |d_a| (a fixed-seed Cycles frame
    difference at 4096 spp is still hot-pixel noise at junctions). 0 when
    the product is negative (no change measurable above the noise)."""
    a0, b0 = (np.asarray(x, np.float64) for x in first)
    a1, b1 = (np.asarray(x, np.float64) for x in last)
    return _rel_cross(a1 - a0, b1 - b0, 0.5 * (a0 + b0)) / steps if steps > 0 else float("nan")


def motion_steps(seq_a, seq_b):
    """The motion's own change at every step of an animation, in flicker()'s
    RMS form, from two independent renders (seeds) of every frame: step t is
    sqrt(max(0, d_a . d_b)) / |m_t| with d = f[t+1] - f[t] per seed and m_t
    the seeds' mean (their noise is independent: E[d_a . d_b] = |d|^2). Unlike
    motion_change's straight line from the first to the last frame, it keeps
    what does not move at a steady rate: an edge crossing a pixel (the
    references are pixel-area averages) changes it in one or two frames, not
    a little in each. Returns the list over steps."""
    a = [np.asarray(x, np.float64) for x in seq_a]
    b = [np.asarray(x, np.float64) for x in seq_b]
    if len(a) != len(b) or len(a) < 2:
        raise ValueError("motion_steps: %d frames against %d" % (len(a), len(b)))
    return [_rel_cross(a[t + 1] - a[t], b[t + 1] - b[t], 0.5 * (a[t] + b[t])) for t in range(len(a) - 1)]


def firefly_mask(seq_a, seq_b, share=0.02):
    """Pixels (H x W bool) whose change over an animation Cycles' two seeds
    disagree about: sum_t |d_a - d_b|^2 > sum_t (|d_a|^2 + |d_b|^2) / 2, d
    = f[t+1] - f[t] per seed, and that carry more than `share` of both
    seeds' step energy. With a fixed seed per frame a path that one seed
    finds (a caustic's firefly: a sun glinting off a metal cabinet onto the
    floor) stays from frame to frame, so one seed's pixel jumps and keeps
    its value while the other's does not: that change is neither the
    motion (the product of the seeds' steps leaves it out) nor noise that
    averages away over the frames, and a smooth render of the same light
    changing there is charged as flicker beyond Cycles' own. Seeds that
    agree about a step (an edge crossing a pixel) are not flagged, nor is
    independent noise on pixels that barely change (their share)."""
    a = np.asarray([np.asarray(x, np.float64) for x in seq_a])
    b = np.asarray([np.asarray(x, np.float64) for x in seq_b])
    if a.shape != b.shape or len(a) < 2:
        raise ValueError("firefly_mask: %s frames against %s" % (a.shape, b.shape))
    da, db = np.diff(a, axis=0), np.diff(b, axis=0)
    axes = (0,) + tuple(range(3, a.ndim))
    dis = ((da - db) ** 2).sum(axis=axes)
    energy = 0.5 * (da ** 2 + db ** 2).sum(axis=axes)
    return (dis > energy) & (energy > share * energy.sum())


def masked(frames, mask):
    """The frames with the pixels of `mask` set to 0 (flicker() and
    motion_steps() on the rest of the image)."""
    out = []
    for f in frames:
        f = np.array(f, np.float64)
        f[mask] = 0.0
        out.append(f)
    return out


def excess_over_seeds(frames, seq_a, seq_b):
    """Median over steps of how much a sequence changes beyond the motion
    rendered by two independent seeds of every frame: sqrt(max(0, (df - d_a)
    . (df - d_b))) / |f[t]|, df = f[t+1] - f[t], d_a and d_b the seeds' own
    steps. The product of the two differences removes the seeds' noise
    (E[(df - d_a) . (df - d_b)] = |df - d|^2), so this is excess_flicker
    against the noise-free motion itself rather than against a dense render
    of the same method (which shares its model's errors)."""
    f = [np.asarray(x, np.float64) for x in frames]
    a = [np.asarray(x, np.float64) for x in seq_a]
    b = [np.asarray(x, np.float64) for x in seq_b]
    if not (len(f) == len(a) == len(b)) or len(f) < 2:
        raise ValueError("excess_over_seeds: %d frames against %d and %d" % (len(f), len(a), len(b)))
    df = [f[t + 1] - f[t] for t in range(len(f) - 1)]
    return float(np.median([_rel_cross(df[t] - (a[t + 1] - a[t]), df[t] - (b[t + 1] - b[t]), f[t])
                            for t in range(len(df))]))


def all_metrics(img, ref_seeds, k=4):
    """Every still metric of one configuration's passes against the
    reference seeds (each a dict of coloured passes). Returns
    {pass: dict(bias, relmse, structured)} plus 'flip' (combined); the
    glossy pass also has its own 'flip' (issue 14's acceptance is on it)."""
    ref = {p: 0.5 * (ref_seeds[0][p] + ref_seeds[1][p]) for p in ("Diff", "Gloss", "Combined")}
    out = {}
    for p in ("Diff", "Gloss", "Combined"):
        out[p] = dict(bias=bias(img[p], ref[p]), relmse=relmse(img[p], ref[p]),
                      structured=structured(img[p], ref[p], k))
    out["flip"] = flip(img["Combined"], ref["Combined"])
    out["Gloss"]["flip"] = flip(img["Gloss"], ref["Gloss"])
    return out
