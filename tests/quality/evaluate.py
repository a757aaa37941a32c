#!/usr/bin/env python3
"""Measure what the eye sees (issue 9): the library against Cycles on the bundled scenes.

Quick (one scene, one configuration, numbers only; a few seconds once the
references exist):

    python3 tests/quality/evaluate.py --quick                       # balanced on spot_metal_floor
    python3 tests/quality/evaluate.py --quick --set fit_mode=kmeans vsgl_count=1024
    python3 tests/quality/evaluate.py --quick --scenes sun_opening --configs preview,brute
    python3 tests/quality/evaluate.py --quick --set preset=quality visibility=none --anim none

Full (every scene, the presets, brute force, k-means 1024, FIS 128, images
and a markdown report under --out; --docs writes docs/quality.md and
docs/img/quality/ instead):

    python3 tests/quality/evaluate.py [--size test|bench] [--acceptance] [--docs]

Configurations (--configs, comma-separated; --set adds one more):
  preview, balanced, quality, auto   vsgl_render_settings_preset (read from the library at run time)
  brute                        vsgl_reference_render: every RSM texel a VPL, exact BRDF,
                               RSM 128, aa 1, one shadow ray per pair
  km1024, fis128               balanced with fit_mode kmeans / fis and vsgl_count 1024 / 128
  LABEL:k=v,k=v                a preset (preset=NAME, default balanced; preset=brute for the
                               brute force) with fields of vsgl_render_settings changed (enum
                               names or numbers); NAME:k=v,... changes a named configuration,
                               e.g. brute:rsm_resolution=64,visibility=ray,aa_samples=1 (brute:
                               visibility auto = no rays in the rooms marked convex)
  --set k=v k=v ...            the same as one configuration labelled by its changes
                               (--name LABEL to name it); repeat --set for more

For each scene and configuration: the still (against the mean of two Cycles
seeds), the light animation and the camera animation (each light or the
camera moving by extent/1000 per frame), and the metrics of metrics.py per
pass (Diff, Gloss, Combined). Cycles references are rendered in Blender when
missing (refs.py; ~35 s for all five scenes at test size).

Times: the `vsgl_render` (or `vsgl_reference_render`) call of the still,
scene creation excluded, all cores; median over the animation frames beside it.
"""
import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "addon", "vsgl_indirect"))
import imgutil  # noqa: E402
import libvsgl as L  # noqa: E402
import metrics as M  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402

PASSES = ("Diff", "Gloss", "Combined")
ANIM_SIZES = {"test": (80, 60), "bench": (160, 120)}
# visibility "auto": no shadow rays in a scene marked convex (a closed box room with nothing in it:
# the exact BRDF's cosines at both ends already make every pair the rays would test visible), rays otherwise
BRUTE_DEFAULTS = dict(rsm_resolution=128, aa_samples=1, visibility="auto")
NAMED = {
    "preview": ("preview", {}),
    "balanced": ("balanced", {}),
    "quality": ("quality", {}),
    "auto": ("auto", {}),
    "brute": ("brute", {}),
    "km1024": ("balanced", dict(fit_mode="kmeans", vsgl_count=1024)),
    "fis128": ("balanced", dict(fit_mode="fis", vsgl_count=128)),
}
FULL_CONFIGS = ["preview", "balanced", "quality", "brute", "km1024", "fis128"]
STILL_IMAGE_CONFIGS = ("preview", "balanced", "quality", "brute")
ACCEPT = dict(flicker=0.01, bias=0.05, bias_preview=0.30, structured_x=3.0)
# The camera animation's own change: consecutive frames differ because the view moved (silhouettes
# slide, glossy highlights move), and at 80x60 that alone exceeds 0.01 in some rooms. --camera-truth
# renders the camera animation densely (12 x 12 samples, every pixel shaded, no edge rays, no
# visibility rays, for time) and reports for each configuration the change in excess of it: the median
# over frames of |(f[t+1] - f[t]) - (g[t+1] - g[t])| / |f[t]| (RMS form), g the dense frames. Each
# render's own change above Cycles' motion (Gloss in the sphere room / Diff in the textured room / Gloss
# in the rough room): 8 x 8 samples 0.0168 / 0.0032 / 0.0192 (aliasing at the sphere's glossy rim);
# 8 x 8 with 16 x 16 edge rays 0.0082 / 0.0153 / 0.0215 (an edge pixel's flat group takes one texture
# lookup filtered over a quarter pixel); 12 x 12 0.0063 / 0.0025 / 0.0126 (docs/accuracy.md, "A curved rim
# shaded at several points").
CAMERA_TRUTH = ("balanced", dict(aa_samples=12, shade_stride=1, edge_samples=0, visibility=0))
# The motion's own change in Cycles (--motion-truth), rendered with both reference seeds; the product of
# the two seeds' frame differences gives the per-frame change without their noise. Every frame of both
# animations (metrics.motion_steps, the median over the steps): a silhouette crossing a pixel changes it
# in a frame or two, which the straight line from the first to the last frame (metrics.motion_change,
# the light's and the camera's over 0 and MOTION_STEPS in check.py, for time) spreads over all steps
# (glossy_sphere_floor's camera Gloss 0.034 that way, 0.040 step by step); those frames also give each
# configuration's change in excess of Cycles' own (metrics.excess_over_seeds), which tells a fit that
# reshuffles from one that follows the motion. A sun's patch sliding across a floor changes the
# indirect light of a room by more than 0.01 a frame in Cycles itself; a renderer steadier than that would be wrong. The
# acceptance then reads "flicker <= max(0.01, the motion's own change)" beside the 0.01.
# Always over MOTION_STEPS frames, whatever --frames is: over 5 steps the seeds' noise moves the
# light's estimate by 30 % (sun_opening Diff 0.0083 against 0.0128 over 11).
MOTION_STEPS = scenes.FRAMES - 1


# ---------------------------------------------------------------------------
# configurations
# ---------------------------------------------------------------------------

def _value(v):
    try:
        return int(v)
    except ValueError:
        try:
            return float(v)
        except ValueError:
            return v


class Config:
    """A labelled way to render: a preset plus changed fields, or the brute force."""

    def __init__(self, label, base, changes):
        self.label, self.base, self.changes = label, base, dict(changes)
        if base == "brute":
            unknown = set(self.changes) - set(BRUTE_DEFAULTS)
            if unknown:
                raise SystemExit("brute takes %s, not %s" % (", ".join(BRUTE_DEFAULTS), ", ".join(sorted(unknown))))
        elif base not in ("preview", "balanced", "quality", "auto"):
            raise SystemExit("unknown preset %r (preview, balanced, quality, auto or brute)" % base)

    @property
    def brute(self):
        return self.base == "brute"

    def settings(self):
        """The vsgl_render_settings (VSGL configurations)."""
        s = L.render_settings_preset(self.base)
        names = [f[0] for f in s._fields_]
        for k, v in self.changes.items():
            if k not in names:
                raise SystemExit("vsgl_render_settings has no field %r (fields: %s)" % (k, ", ".join(names[1:])))
            setattr(s, k, s._convert(k, v))
        return s

    def brute_params(self, scene=None):
        """RSM size, aa, visibility (0/1; "auto" resolved for `scene`, or left as "auto")."""
        p = dict(BRUTE_DEFAULTS, **self.changes)
        vis = p["visibility"]
        if vis == "auto":
            p["visibility"] = "auto" if scene is None else (0 if scene.get("convex") else 1)
        else:
            p["visibility"] = L._enum(vis, L.Visibility, "visibility")
        return p

    def describe(self):
        if self.brute:
            p = self.brute_params()
            return "brute force, RSM %d, aa %d, %s" % (
                p["rsm_resolution"], p["aa_samples"],
                {"auto": "visibility rays unless the room is convex", 0: "no visibility", 1: "visibility rays"}[
                    p["visibility"]])
        s = self.settings().as_dict()
        fit = {0: "two VSGLs/light", 1: "FIS %d" % s["vsgl_count"], 2: "k-means %d" % s["vsgl_count"],
               3: "lattice %d" % s["vsgl_count"]}[s["fit_mode"]]
        bits = [fit, "RSM %d" % s["rsm_resolution"], "aa %d" % s["aa_samples"],
                {0: "accurate cosine", 1: "SG cosine", 2: "pulled-out cosine"}[s["diffuse_mode"]],
                {0: "ASG", 1: "SG", 2: "two-ASG (GGX core + tail)", 3: "rectangle-proxy (MRP)",
                 4: "hybrid (MRP where it applies, else two-ASG)"}[s["glossy_mode"]]
                + " glossy"]
        if s["visibility"]:
            bits.append("visibility rays")
        if s["leak_correction"]:
            bits.append("leak correction %s" % {1: "off", 2: "on", 3: "clip only"}[s["leak_correction"]])
        if s["method"]:
            bits.append("brute-force method")
        if s.get("auto_target"):
            bits.append("auto: aa, RSM per light and glossy chosen per scene, at most these")
        return ", ".join(bits)

    def as_dict(self):
        if self.brute:
            return dict(brute=self.brute_params())
        return self.settings().as_dict()


def split_configs(text):
    """"preview,brute:rsm_resolution=64,visibility=0,km1024" -> ["preview",
    "brute:rsm_resolution=64,visibility=0", "km1024"]: a k=v piece without
    a label belongs to the LABEL:... spec before it."""
    out = []
    for piece in [p for p in text.split(",") if p]:
        if "=" in piece and ":" not in piece and out and ":" in out[-1]:
            out[-1] += "," + piece
        else:
            out.append(piece)
    return out


def parse_config(spec, label=None):
    if ":" in spec or "=" in spec:
        head, _, rest = spec.partition(":") if ":" in spec else ("", "", spec)
        changes = {}
        for kv in [x for x in rest.replace(",", " ").split() if x]:
            k, _, v = kv.partition("=")
            changes[k] = _value(v)
        base = changes.pop("preset", None)
        if head in NAMED and base is None:
            # a named configuration changed: labelled by the whole spec ("brute:rsm_resolution=64")
            label = label or (spec if changes else head)
            base, extra = NAMED[head]
            changes = dict(extra, **changes)
        base = base or "balanced"
        return Config(label or head or " ".join("%s=%s" % kv for kv in changes.items()) or base, base, changes)
    if spec not in NAMED:
        raise SystemExit("unknown configuration %r (%s, or LABEL:k=v,...)" % (spec, ", ".join(NAMED)))
    base, changes = NAMED[spec]
    return Config(label or spec, base, changes)


# ---------------------------------------------------------------------------
# rendering
# ---------------------------------------------------------------------------

class Renderer:
    def __init__(self, threads=0):
        self.warnings = []
        self.ctx = L.Context(thread_count=threads, log=self._log, log_level="warning")

    def _log(self, level, message):
        if level <= int(L.LogLevel.WARNING):
            self.warnings.append(message)

    def render(self, s, cfg):
        """Coloured passes of scene dict `s` (with a resolution), seconds of the
        render call, stats dict, warnings logged during the call."""
        self.warnings = []
        with L.Scene(self.ctx, **scenes.library_arrays(s, L)) as sc:
            if cfg.brute:
                p = cfg.brute_params(s)
                t0 = time.perf_counter()
                im, st = L.reference_render(self.ctx, sc, p["rsm_resolution"], p["aa_samples"], p["visibility"])
                secs = time.perf_counter() - t0
                out = M.coloured(dict(DiffInd=im["diffuse_light"], GlossInd=im["glossy_light"],
                                      DiffCol=im["diffuse_color"], GlossCol=im["glossy_color"]))
                st = dict(vsgl_count=int(st["vpl_count"]), skipped="")
            else:
                t0 = time.perf_counter()
                im, st = L.render(self.ctx, sc, cfg.settings(), planes=("diffuse", "glossy"))
                secs = time.perf_counter() - t0
                d, g = im["diffuse"].astype(np.float64), im["glossy"].astype(np.float64)
                out = {"Diff": d, "Gloss": g, "Combined": d + g}
        return out, secs, st, list(self.warnings)


def evaluate_scene(name, cfgs, size, anim_size, frames, anims, refdir, rend, brute_anim=False, want_images=True,
                   log=print, repeat=1, camera_truth=False, motion_truth=False, steps=True, steps_frames=None):
    """Every metric of every configuration on one scene. Returns (result
    dict, images dict for the pictures). motion_truth: Cycles' own change of
    each animation; for the kinds in steps (True: all), from every frame
    (both seeds, MOTION_STEPS + 1 renders each) and each configuration's
    change in excess of it, else from its first and last frames
    (metrics.motion_change). steps_frames: render only that many frames for
    those kinds (the excess over the first steps_frames frames; the motion's
    own change then from frames 0 and MOTION_STEPS)."""
    truth = None
    if camera_truth and "camera" in anims:
        base = scenes.case(name, anim_size)
        tc = Config("camera truth", *CAMERA_TRUTH)
        truth = [rend.render(scenes.animate(base, "camera", f), tc)[0] for f in range(frames)]
    w, h, spp = scenes.size_of(size)
    R = refs.ensure([name], (w, h, spp), refdir)[name]
    seeds = [M.coloured(p) for p, _ in R]
    ref = {p: 0.5 * (seeds[0][p] + seeds[1][p]) for p in PASSES}
    motion = None
    anim_seeds = {}  # each animation in Cycles, every frame, both seeds: {kind: [(seed 1, seed 2) per frame]}
    motion_steps = None
    fireflies, motion_clean, motion_mean = {}, {}, {}
    if motion_truth and anims:
        motion = {}
        motion_steps = {}
        asz = (anim_size[0], anim_size[1], spp)
        for kind in anims:
            stepped = steps is True or kind in (steps or ())
            if stepped:
                n = min(frames, steps_frames) if steps_frames else max(frames, MOTION_STEPS + 1)
                refs.ensure_frames([name], asz, kind, list(range(n)), refdir)
                anim_seeds[kind] = [[M.coloured(p) for p, _ in refs.ensure_frame([name], asz, kind, f, refdir)[name]]
                                    for f in range(n)]
            if stepped and not steps_frames:
                seq = anim_seeds[kind][:MOTION_STEPS + 1]
                motion_steps[kind], motion[kind], fireflies[kind], motion_clean[kind] = {}, {}, {}, {}
                motion_mean[kind] = {}
                for p in PASSES:
                    a, b = [x[0][p] for x in seq], [x[1][p] for x in seq]
                    st = M.motion_steps(a, b)
                    motion_steps[kind][p] = [round(v, 5) for v in st]
                    motion[kind][p] = float(np.median(st))
                    motion_mean[kind][p] = float(np.mean(st))
                    # pixels whose change the seeds disagree about (a caustic's kept firefly): the motion and
                    # each configuration's flicker again without them (metrics.firefly_mask)
                    mask = fireflies[kind][p] = M.firefly_mask(a, b)
                    motion_clean[kind][p] = float(np.median(M.motion_steps(M.masked(a, mask), M.masked(b, mask))))
                continue
            f0 = [M.coloured(p) for p, _ in refs.ensure_frame([name], asz, kind, 0, refdir)[name]]
            f1 = [M.coloured(p) for p, _ in refs.ensure_frame([name], asz, kind, MOTION_STEPS, refdir)[name]]
            motion[kind] = {p: M.motion_change((f0[0][p], f0[1][p]), (f1[0][p], f1[1][p]), MOTION_STEPS)
                            for p in PASSES}
    res = dict(feature=scenes.scene(name)["feature"], size=[w, h], anim_size=list(anim_size), frames=frames,
               motion=motion, motion_steps=motion_steps,
               fireflies={k: {p: int(m.sum()) for p, m in v.items()} for k, v in fireflies.items()} or None,
               motion_clean=motion_clean or None, motion_mean=motion_mean or None,
               camera_truth=None if truth is None else dict(
                   (p, M.flicker([x[p] for x in truth])["median"]) for p in PASSES),
               camera_truth_jitter=None if truth is None else dict(
                   (p, M.jitter([x[p] for x in truth])) for p in PASSES),
               reference=dict(spp=spp, seeds=[m["seed"] for _, m in R], blender=R[0][1]["blender"],
                              seconds=[round(m["render_seconds"], 2) for _, m in R],
                              mean={p: float(ref[p].mean()) for p in PASSES},
                              noise={p: ref_noise_entry(seeds, p) for p in PASSES},
                              flip_seeds=M.flip(seeds[0]["Combined"], seeds[1]["Combined"]),
                              agreement={p: M.seed_agreement(seeds[0][p], seeds[1][p]) for p in PASSES}),
               configs={})
    images = dict(ref=ref, seeds=seeds, still={}, anim={})
    still_case = scenes.case(name, (w, h))
    for cfg in cfgs:
        img, secs, st, warns = rend.render(still_case, cfg)
        for _ in range(1 if cfg.brute else repeat - 1):  # the fastest of `repeat` runs (a shared machine)
            secs = min(secs, rend.render(still_case, cfg)[1])
        m = M.all_metrics(img, seeds)
        entry = dict(describe=cfg.describe(), settings=cfg.as_dict(), seconds=secs, vsgls=int(st["vsgl_count"]),
                     warnings=warns, skipped=st.get("skipped", ""), flip=m.pop("flip"), still=m,
                     finite=bool(all(np.all(np.isfinite(img[p])) for p in PASSES)), flicker={}, anim_seconds=None)
        images["still"][cfg.label] = img
        anim_t = []
        for kind in anims:
            if cfg.brute and not brute_anim:
                continue
            seq = []
            base = scenes.case(name, anim_size)
            for f in range(frames):
                fi, fs, _, _ = rend.render(scenes.animate(base, kind, f), cfg)
                seq.append(fi)
                anim_t.append(fs)
            entry["flicker"][kind] = {}
            for p in PASSES:
                fl = M.flicker([x[p] for x in seq])
                entry["flicker"][kind][p] = dict(median=fl["median"], ratio=fl["ratio"],
                                                 median_second=fl["median_second"], l1=fl["l1"],
                                                 jitter=M.jitter([x[p] for x in seq]))
                if kind == "camera" and truth is not None:
                    entry["flicker"][kind][p]["excess"] = M.excess_flicker([x[p] for x in seq],
                                                                           [x[p] for x in truth])
                if kind in fireflies and len(seq) > MOTION_STEPS:
                    entry["flicker"][kind][p]["clean"] = M.flicker(
                        M.masked([x[p] for x in seq[:MOTION_STEPS + 1]], fireflies[kind][p]))["median"]
                if kind in anim_seeds:
                    m = len(anim_seeds[kind][:frames])
                    entry["flicker"][kind][p]["excess_cycles"] = M.excess_over_seeds(
                        [x[p] for x in seq[:m]], [x[0][p] for x in anim_seeds[kind][:m]],
                        [x[1][p] for x in anim_seeds[kind][:m]])
            if want_images and kind == "light":
                images["anim"][cfg.label] = [x["Combined"] for x in seq]
        if anim_t:
            entry["anim_seconds"] = float(np.median(anim_t))
        res["configs"][cfg.label] = entry
        log(quick_line(name, cfg.label, entry, res["reference"]))
    return res, images


def ref_noise_entry(seeds, p):
    return dict(full=M.ref_noise(seeds[0][p], seeds[1][p], 1), s4=M.ref_noise(seeds[0][p], seeds[1][p], 4))


# ---------------------------------------------------------------------------
# acceptance (issue 9), as a report column
# ---------------------------------------------------------------------------

def _flicker_under(fl, own):
    """PASS, or FAIL naming the passes, for flicker fl (Diff, Gloss) against
    max(the issue's 0.01, own[pass]) per pass."""
    over = [(fl[i], max(ACCEPT["flicker"], own[p])) for i, p in enumerate(("Diff", "Gloss"))]
    return ("PASS" if all(f <= lim for f, lim in over) else
            "FAIL (%s)" % ", ".join("%.3f > %.3f" % (f, lim) for f, lim in over if f > lim))


def acceptance(res):
    """{config label: {criterion: "PASS" / "FAIL" / "WARN ..."}} for the presets of one scene."""
    out = {}
    cfgs = res["configs"]
    noise = res["reference"]["noise"]
    for label in ("preview", "balanced", "quality"):
        e = cfgs.get(label)
        if e is None:
            continue
        a = {}
        for k in ("light", "camera"):
            if k not in e["flicker"]:
                continue
            fl = [e["flicker"][k][p]["median"] for p in ("Diff", "Gloss")]
            a["flicker %s <= %.2f" % (k, ACCEPT["flicker"])] = ("PASS" if max(fl) <= ACCEPT["flicker"]
                                                                else "FAIL (%.3f)" % max(fl))
            mo = (res.get("motion") or {}).get(k)
            if mo:
                a["flicker %s <= max(%.2f, Cycles' own)" % (k, ACCEPT["flicker"])] = _flicker_under(fl, mo)
            mm = (res.get("motion_mean") or {}).get(k)
            if mm:
                # the motion's change per frame as its mean step: a sun's patch edge crossing pixels moves
                # the truth in bursts (sun_opening's light steps 0.007-0.037, median 0.0099, mean 0.0149),
                # which a smooth render spreads over every frame, so its median exceeds the truth's
                # median while its mean stays under the truth's
                a["flicker %s <= max(%.2f, Cycles' mean step)" % (k, ACCEPT["flicker"])] = _flicker_under(fl, mm)
            mc = (res.get("motion_clean") or {}).get(k)
            cl = [e["flicker"][k][p].get("clean") for p in ("Diff", "Gloss")]
            if mc and None not in cl:
                a["flicker %s <= max(%.2f, Cycles' own), without Cycles' kept fireflies" % (
                    k, ACCEPT["flicker"])] = _flicker_under(cl, mc)
            exc = [e["flicker"][k][p].get("excess_cycles") for p in ("Diff", "Gloss")]
            if None not in exc:
                a["%s flicker above Cycles' own motion <= %.2f" % (k, ACCEPT["flicker"])] = (
                    "PASS" if max(exc) <= ACCEPT["flicker"] else "FAIL (%.3f)" % max(exc))
            ex = [e["flicker"][k][p].get("excess") for p in ("Diff", "Gloss")]
            if k == "camera" and None not in ex:
                a["camera flicker above the dense render's <= %.2f" % ACCEPT["flicker"]] = (
                    "PASS" if max(ex) <= ACCEPT["flicker"] else "FAIL (%.3f)" % max(ex))
            tj = res.get("camera_truth_jitter") if k == "camera" else None
            if tj:
                jt = [(e["flicker"][k][p]["jitter"], max(ACCEPT["flicker"], tj[p])) for p in ("Diff", "Gloss")]
                a["camera jitter <= max(%.2f, the dense render's)" % ACCEPT["flicker"]] = (
                    "PASS" if all(j <= lim for j, lim in jt) else
                    "FAIL (%s)" % ", ".join("%.3f > %.3f" % (j, lim) for j, lim in jt if j > lim))
        tol = ACCEPT["bias_preview"] if label == "preview" else ACCEPT["bias"]
        worst = max(abs(e["still"][p]["bias"] - 1) for p in ("Diff", "Gloss"))
        if worst <= tol:
            a["bias"] = "PASS"
        elif label == "preview" and any("light" in w.lower() for w in e["warnings"]):
            a["bias"] = "PASS (warned: %s)" % e["warnings"][0][:60]
        else:
            a["bias"] = "FAIL (%+.0f %%)" % (100 * max((e["still"][p]["bias"] - 1 for p in ("Diff", "Gloss")), key=abs))
        if label == "balanced":
            x = max(e["still"][p]["structured"] / noise[p]["s4"] for p in ("Diff", "Gloss") if noise[p]["s4"] > 0)
            a["structured <= 3x noise"] = "PASS" if x <= ACCEPT["structured_x"] else "FAIL (%.1fx)" % x
            # the criterion is out of reach of the brute force itself (the reference's own 4x4 noise is
            # ~1e-5 / 1e-7 here): the same against max(noise, the brute force's structured error), the RSM's floor
            bf = cfgs.get("brute")
            if bf is not None:
                x2 = max(e["still"][p]["structured"] / max(noise[p]["s4"], bf["still"][p]["structured"], 1e-12)
                         for p in ("Diff", "Gloss"))
                a["structured <= 3x max(noise, brute)"] = ("PASS" if x2 <= ACCEPT["structured_x"]
                                                           else "FAIL (%.1fx)" % x2)
        if label == "quality" and "balanced" in cfgs:
            b = cfgs["balanced"]["still"]
            worse = [p for p in ("Diff", "Gloss") if e["still"][p]["structured"] >= b[p]["structured"]]
            a["structured < balanced"] = "PASS" if not worse else "FAIL (%s)" % ", ".join(worse)
        out[label] = a
    return out


# ---------------------------------------------------------------------------
# output
# ---------------------------------------------------------------------------

def _f(x, fmt="%.3f"):
    return "-" if x is None or (isinstance(x, float) and not np.isfinite(x)) else fmt % x


def quick_line(name, label, e, ref):
    s = e["still"]
    nz = ref["noise"]
    fl = e["flicker"]

    def flk(kind):
        if kind not in fl:
            return "-"
        return "%s/%s (x%s/%s, L1 %s/%s)" % (
            _f(fl[kind]["Diff"]["median"], "%.4f"), _f(fl[kind]["Gloss"]["median"], "%.4f"),
            _f(fl[kind]["Diff"]["ratio"], "%.1f"), _f(fl[kind]["Gloss"]["ratio"], "%.1f"),
            _f(fl[kind]["Diff"]["l1"], "%.4f"), _f(fl[kind]["Gloss"]["l1"], "%.4f"))
    return ("%-28s %-16s %6.3fs  bias D %s G %s C %s  relMSE C %s G %s  struct D %s (%sx) G %s (%sx)  FLIP %s G %s  "
            "flicker light %s camera %s%s" % (
                name, label, e["seconds"], _f(s["Diff"]["bias"]), _f(s["Gloss"]["bias"]), _f(s["Combined"]["bias"]),
                _f(s["Combined"]["relmse"], "%.4f"), _f(s["Gloss"]["relmse"], "%.4f"),
                _f(s["Diff"]["structured"], "%.5f"), _ratio(s["Diff"]["structured"], nz["Diff"]["s4"]),
                _f(s["Gloss"]["structured"], "%.5f"), _ratio(s["Gloss"]["structured"], nz["Gloss"]["s4"]),
                _f(e["flip"], "%.4f"), _f(s["Gloss"].get("flip"), "%.4f"), flk("light"), flk("camera"),
                ("  WARN: " + e["warnings"][0][:80]) if e["warnings"] else ""))


def own(motion, kind):
    """Summary cell suffix: the motion's own change in Cycles, when measured."""
    m = (motion or {}).get(kind)
    return "" if not m else " (Cycles' own: %s / %s)" % (_f(m["Diff"], "%.4f"), _f(m["Gloss"], "%.4f"))


def flicker_cell(e, kind):
    """Summary cell: an animation's flicker Diff / Gloss, and above the motion's own change when measured."""
    f = e["flicker"].get(kind)
    if not f:
        return "-"
    out = "%s / %s" % (_f(f["Diff"]["median"], "%.4f"), _f(f["Gloss"]["median"], "%.4f"))
    if f["Diff"].get("excess_cycles") is not None:
        out += " (above Cycles' motion: %s / %s)" % (
            _f(f["Diff"]["excess_cycles"], "%.4f"), _f(f["Gloss"]["excess_cycles"], "%.4f"))
    if f["Diff"].get("excess") is not None:
        out += " (above the dense render: %s / %s)" % (
            _f(f["Diff"]["excess"], "%.4f"), _f(f["Gloss"]["excess"], "%.4f"))
    return out


def _ratio(a, b):
    if not b or b <= 0:
        return "-"
    r = a / b
    return "%.1f" % r if r < 100 else "%.0f" % r


def markdown(results, args, img_rel):
    size = results["size"]
    lines = ["# Quality against Cycles: what the eye sees (issue 9)", "",
             "Generated by `%s` (do not edit by hand). Library %s, commit %s; Cycles references: Blender %s, "
             "one bounce, two seeds of %d spp each, each pixel the average over its area (a 1-px box filter: "
             "Blender's Cycles sync renders a box pixel filter 1 px wide whatever its width is set to, so "
             "cycles_ref.py's 0.01 px does not take; the library's aa x aa samples and edge refinement estimate the "
             "same average)." % (
                 results["command"], results["library"], results["commit"], results["blender"],
                 results["spp"]), "",
             "Still images %dx%d, animations %dx%d, %d frames, moving by 1/1000 of the scene's extent per frame. "
             "Times: the `vsgl_render` / `vsgl_reference_render` call of the still (the fastest of %d runs; brute "
             "force one) on this %d-core machine, which other jobs share, scene creation excluded." % (
                 size[0], size[1], results["anim_size"][0], results["anim_size"][1], results["frames"],
                 results.get("repeat", 1), os.cpu_count() or 0), "",
             "Metrics (tests/quality/metrics.py), per coloured pass (Diff = DiffInd x DiffCol, Gloss = GlossInd x "
             "GlossCol): **bias** = sum over the reference's sum; **relMSE** = mean((a-b)^2/(b^2+0.01)); "
             "**struct** = relMSE after 4x4 box downsampling, with **(Nx)** = over the reference's own noise "
             "measured the same way (relMSE(seed 1, seed 2)/4 = what a perfect image scores against the two-seed "
             "mean; a blotch-free image is ~1x); **FLIP** = mean HDR-FLIP of the combined pass; **flicker** = "
             "median relative RMS of consecutive frames, Diff/Gloss, light moving and camera moving, with "
             "the second-to-first difference ratio in brackets (> 1: jitter, the fit reshuffling), the mean "
             "step (the mean over consecutive frames of the same: the sequence's change spread evenly over its "
             "frames; with --motion-truth the acceptance also reads flicker <= max(0.01, Cycles' mean step), "
             "since a sun's patch edge crossing pixels moves Cycles' frames in bursts that a smooth render "
             "spreads over every frame: its median then exceeds Cycles' median while its mean stays under "
             "Cycles' mean) and the L1 form (median sum|f[t+1]-f[t]|/sum|f[t]|; the RMS form is dominated by "
             "hot pixels where there are any, e.g. the brute force's at junctions); **the motion's own change** "
             "(with --motion-truth) = the per-frame change of the same animation in Cycles without its noise "
             "(the product of the two seeds' differences: E[d1 . d2] = |d|^2): every frame rendered with both seeds "
             "and the median over the steps "
             "(metrics.motion_steps: an edge crossing a pixel changes it in a frame or two, which a straight line "
             "from the first to the last frame spreads over all of them and underestimates); the acceptance then "
             "also reads flicker <= max(0.01, that); **above Cycles' motion** (with --motion-truth) = an "
             "animation's change in excess of "
             "Cycles' own, frame by frame, without Cycles' noise (metrics.excess_over_seeds: the median over steps "
             "of sqrt((df - d1) . (df - d2)) / |f[t]|): a moving view changes some rooms by more than 0.01 a frame "
             "by itself, and this is what a renderer adds to it; **above the dense render** (with --camera-truth) "
             "= the same against the method's own frames rendered with 12 x 12 samples and every pixel shaded "
             "(median of |(f[t+1] - f[t]) - (g[t+1] - g[t])| / |f[t]|; a diagnostic: the dense "
             "render shares the model's errors); **jitter** = the median "
             "relative RMS of "
             "(f[t+1] - f[t]) - (f[n] - f[0]) / n, the change in excess of the sequence's own straight-line trend "
             "(a smooth motion's is ~0; a reshuffling fit's, or an edge jumping across pixels, is not), checked "
             "for the camera against the dense render's own (with --camera-truth); **without Cycles' kept "
             "fireflies** (with --motion-truth) = the flicker and the motion's own change again with the pixels "
             "left out whose change the two seeds disagree about and that carry over 2 %% of the step energy "
             "(metrics.firefly_mask): with a fixed seed per frame a caustic path that one seed finds (a sun "
             "glinting off a metal cabinet onto the floor) stays, so that seed's pixel jumps once and keeps its "
             "value, the other seed's does not, and a render of the same light changing smoothly there is charged "
             "with more flicker than Cycles' own.", ""]
    if results.get("flip_error"):
        lines += ["FLIP skipped: flip-evaluator does not import (%s)." % results["flip_error"], ""]
    summary = ["## Summary (presets)", "",
               "| scene | preset | time s | bias D | bias G | struct D (x noise) | struct G (x noise) | FLIP | "
               "flicker light D/G | flicker camera D/G |", "|---|---|---|---|---|---|---|---|---|---|"]
    body = []
    for name, r in results["scenes"].items():
        nz = r["reference"]["noise"]
        body += ["## %s" % name, "", r["feature"] + ".", "",
                 "Reference: mean of seeds %s (%s s per render), own noise relMSE full/4x4: Diff %s / %s, Gloss "
                 "%s / %s, Combined %s / %s; FLIP of seed 1 vs seed 2: %s; seed agreement z (Diff/Gloss): %s / %s." % (
                     ", ".join(map(str, r["reference"]["seeds"])),
                     ", ".join("%.1f" % s for s in r["reference"]["seconds"]),
                     _f(nz["Diff"]["full"], "%.5f"), _f(nz["Diff"]["s4"], "%.5f"), _f(nz["Gloss"]["full"], "%.5f"),
                     _f(nz["Gloss"]["s4"], "%.5f"), _f(nz["Combined"]["full"], "%.5f"),
                     _f(nz["Combined"]["s4"], "%.5f"),
                     _f(r["reference"]["flip_seeds"], "%.4f"), _f(r["reference"]["agreement"]["Diff"], "%.2f"),
                     _f(r["reference"]["agreement"]["Gloss"], "%.2f")), ""]
        mo = r.get("motion")
        if mo:
            ms = r.get("motion_steps") or {}
            if "Diff" in ms:  # a result from before the light's steps were rendered: the camera's only
                ms = dict(camera=ms)
            how = {k: ("the median over its %d steps, metrics.motion_steps" % MOTION_STEPS if k in ms else
                       "from frames 0 and %d, metrics.motion_change" % MOTION_STEPS) for k in mo}
            mm = r.get("motion_mean") or {}
            body += ["The motion's own change per frame in Cycles (both seeds), Diff / Gloss: %s." % "; ".join(
                "%s %s / %s (%s%s)" % (k, _f(v["Diff"], "%.4f"), _f(v["Gloss"], "%.4f"), how[k],
                                       "; the mean step %s / %s" % (_f(mm[k]["Diff"], "%.4f"),
                                                                    _f(mm[k]["Gloss"], "%.4f")) if k in mm else "")
                for k, v in mo.items()), ""]
            ff, mc = r.get("fireflies") or {}, r.get("motion_clean") or {}
            if ff:
                body += ["Cycles' kept fireflies (metrics.firefly_mask), pixels Diff / Gloss: %s; the motion's own "
                         "change without them: %s." % (
                             "; ".join("%s %d / %d" % (k, v["Diff"], v["Gloss"]) for k, v in ff.items()),
                             "; ".join("%s %s / %s" % (k, _f(v["Diff"], "%.4f"), _f(v["Gloss"], "%.4f"))
                                       for k, v in mc.items())), ""]
            for k, v in ms.items():
                body += ["The %s animation's steps in Cycles, Diff: %s; Gloss: %s." % (
                    k, " ".join(_f(x, "%.4f") for x in v["Diff"]), " ".join(_f(x, "%.4f") for x in v["Gloss"])), ""]
        acc = acceptance(r) if args.acceptance else {}
        head = ("| config | time s | VSGLs/VPLs | bias D | bias G | bias C | relMSE D | relMSE G | relMSE C | "
                "struct D | struct G | struct C | FLIP | flicker light D/G | flicker camera D/G |")
        body += [head, "|" + "---|" * (head.count("|") - 1)]
        for label, e in r["configs"].items():
            s = e["still"]

            def fl(kind):
                if kind not in e["flicker"]:
                    return "-"
                f = e["flicker"][kind]
                ex = ""
                if f["Diff"].get("excess_cycles") is not None:
                    ex += "; above Cycles' motion %s / %s" % (_f(f["Diff"]["excess_cycles"], "%.4f"),
                                                              _f(f["Gloss"]["excess_cycles"], "%.4f"))
                if f["Diff"].get("excess") is not None:
                    ex += "; above the dense render %s / %s" % (_f(f["Diff"]["excess"], "%.4f"),
                                                                _f(f["Gloss"]["excess"], "%.4f"))
                if f["Diff"].get("clean") is not None:
                    ex += "; without Cycles' kept fireflies %s / %s" % (_f(f["Diff"]["clean"], "%.4f"),
                                                                        _f(f["Gloss"]["clean"], "%.4f"))
                return "%s / %s (%s / %s; mean step %s / %s; L1 %s / %s; jitter %s / %s%s)" % (
                    _f(f["Diff"]["median"], "%.4f"), _f(f["Gloss"]["median"], "%.4f"),
                    _f(f["Diff"]["ratio"], "%.1f"), _f(f["Gloss"]["ratio"], "%.1f"),
                    _f(f["Diff"].get("mean"), "%.4f"), _f(f["Gloss"].get("mean"), "%.4f"),
                    _f(f["Diff"].get("l1"), "%.4f"), _f(f["Gloss"].get("l1"), "%.4f"),
                    _f(f["Diff"].get("jitter"), "%.4f"), _f(f["Gloss"].get("jitter"), "%.4f"), ex)
            row = "| %s | %.3f | %d | %s | %s | %s | %s | %s | %s | %s (%sx) | %s (%sx) | %s (%sx) | %s | %s | %s |" % (
                label, e["seconds"], e["vsgls"], _f(s["Diff"]["bias"]), _f(s["Gloss"]["bias"]),
                _f(s["Combined"]["bias"]),
                _f(s["Diff"]["relmse"], "%.4f"), _f(s["Gloss"]["relmse"], "%.4f"), _f(s["Combined"]["relmse"], "%.4f"),
                _f(s["Diff"]["structured"], "%.5f"), _ratio(s["Diff"]["structured"], nz["Diff"]["s4"]),
                _f(s["Gloss"]["structured"], "%.5f"), _ratio(s["Gloss"]["structured"], nz["Gloss"]["s4"]),
                _f(s["Combined"]["structured"], "%.5f"), _ratio(s["Combined"]["structured"], nz["Combined"]["s4"]),
                _f(e["flip"], "%.4f"), fl("light"), fl("camera"))
            body.append(row)
            if label in ("preview", "balanced", "quality"):
                summary.append("| %s | %s | %.3f | %s | %s | %s (%sx) | %s (%sx) | %s | %s | %s |" % (
                    name, label, e["seconds"], _f(s["Diff"]["bias"]), _f(s["Gloss"]["bias"]),
                    _f(s["Diff"]["structured"], "%.5f"), _ratio(s["Diff"]["structured"], nz["Diff"]["s4"]),
                    _f(s["Gloss"]["structured"], "%.5f"), _ratio(s["Gloss"]["structured"], nz["Gloss"]["s4"]),
                    _f(e["flip"], "%.4f"), flicker_cell(e, "light") + own(mo, "light"),
                    flicker_cell(e, "camera") + own(mo, "camera")))
        body.append("")
        body.append("Configurations: " + "; ".join("**%s** = %s" % (l, e["describe"]) for l, e in r["configs"].items())
                    + ".")
        warned = ["%s: %s" % (l, "; ".join(sorted(set(e["warnings"])))[:200]) for l, e in r["configs"].items()
                  if e["warnings"]]
        if warned:
            body += ["", "Warnings logged: " + " | ".join(warned) + "."]
        body.append("")
        if acc:
            crit = []
            for a in acc.values():
                crit += [c for c in a if c not in crit]
            body += ["Acceptance (issue 9):", "", "| preset | " + " | ".join(crit) + " |",
                     "|---|" + "---|" * len(crit)]
            for label, a in acc.items():
                body.append("| %s | %s |" % (label, " | ".join(a.get(c, "") for c in crit)))
            body.append("")
        if img_rel:
            labels = " | ".join(["reference"] + ([l for l in r["configs"] if l in STILL_IMAGE_CONFIGS]
                                                 or list(r["configs"])))
            body += ["![%s](%s/%s_still.png)" % (name, img_rel, name), "",
                     "Top: %s (combined pass, tone-mapped with one exposure per scene). Bottom: the signed "
                     "error x4 through the same exposure and curve, red = too bright, blue = too dark; under the "
                     "reference its own noise (seed 1 - seed 2) / 2, under each configuration it - reference." % labels,
                     ""]
            if any("light" in e["flicker"] for e in r["configs"].values()):
                anim_labels = [l for l, e in r["configs"].items() if "light" in e["flicker"]]
                body += ["![%s light animation](%s/%s_flicker.png)" % (name, img_rel, name), "",
                         "Light animation, columns %s (labels: median flicker, Diff and Gloss). Rows: frame 0; mean "
                         "|frame t+1 - frame t|; mean |second difference|; false colour (blue 0, green 1 %%, red >= "
                         "2 %% of the reference's 99th-percentile luminance per frame; a smooth 1/1000 step changes "
                         "a pixel by well under that)." % ", ".join(anim_labels), ""]
            if img_rel == "img/quality" and os.path.exists(os.path.join(ROOT, "docs", img_rel, name + "_glint.png")):
                body += ["![%s: Cycles without kept fireflies](%s/%s_glint.png)" % (name, img_rel, name), "",
                         "Where Cycles' kept fireflies are (above), rendered again with a new seed per frame at 65536 "
                         "spp (tests/quality/border_ref.py and border_cmp.py, commands in tests/quality/README.md; "
                         "not rerun by this command): rows frames 0, 6 and 11; columns Cycles, balanced, quality, "
                         "the brute force at RSM 512. The sun glinting off the cabinet's face onto the floor "
                         "brightens smoothly from frame to frame in Cycles too; the fixed-seed references show it "
                         "as fireflies that appear and stay.", ""]
    return "\n".join(lines + summary + [""] + body) + "\n"


def before_after(before, after):
    """Markdown: each preset before (an earlier library's results) and after, per scene."""
    def cell(e, p, key):
        return _f(e["still"][p][key], "%.3f" if key == "bias" else "%.5f")

    def flk(e):
        f = e["flicker"].get("light")
        return "-" if f is None else "%s / %s" % (_f(f["Diff"]["median"], "%.4f"), _f(f["Gloss"]["median"], "%.4f"))
    lines = ["## Before and after (presets)", "",
             "Before: library %s (commit %s, `%s`); after: this run. Same scenes, references and metrics." % (
                 before.get("library", "?"), before.get("commit", "?"), before.get("command", "?")), "",
             "| scene | preset | time s before / after | bias D | bias G | struct D | struct G | flicker light D / G |",
             "|---|---|---|---|---|---|---|---|"]
    changed = []
    for name, r in after["scenes"].items():
        b = before.get("scenes", {}).get(name)
        if not b:
            continue
        if b.get("feature") != r.get("feature"):  # the scene itself changed: no like-for-like comparison
            changed.append(name)
            continue
        for label in ("preview", "balanced", "quality"):
            e1, e0 = r["configs"].get(label), b["configs"].get(label)
            if not e1 or not e0:
                continue
            lines.append("| %s | %s | %.3f / %.3f | %s / %s | %s / %s | %s / %s | %s / %s | %s / %s |" % (
                name, label, e0["seconds"], e1["seconds"], cell(e0, "Diff", "bias"), cell(e1, "Diff", "bias"),
                cell(e0, "Gloss", "bias"), cell(e1, "Gloss", "bias"), cell(e0, "Diff", "structured"),
                cell(e1, "Diff", "structured"), cell(e0, "Gloss", "structured"), cell(e1, "Gloss", "structured"),
                flk(e0), flk(e1)))
    if changed:
        lines += ["", "Not compared: %s (the scene changed since the earlier run; its description below says how)."
                  % ", ".join(changed)]
    return "\n".join(lines) + "\n\n"


def still_image(name, r, images, up):
    ref = images["ref"]["Combined"]
    e = imgutil.exposure_for(ref)
    top = [imgutil.tonemap(ref, e)]
    lum = imgutil.luminance
    noise = (lum(images["seeds"][0]["Combined"]) - lum(images["seeds"][1]["Combined"])) / 2
    bot = [imgutil.signed_error(noise, 4 * e)]
    heads = [["reference", "cycles 2x%d spp" % r["reference"]["spp"]]]
    # the presets and the brute force (the RSM's floor); other configurations are in the tables only
    shown = [l for l in r["configs"] if l in STILL_IMAGE_CONFIGS] or list(r["configs"])
    for label in shown:
        c = r["configs"][label]
        img = images["still"][label]["Combined"]
        top.append(imgutil.tonemap(img, e))
        bot.append(imgutil.signed_error(lum(img) - lum(ref), 4 * e))
        heads.append([label, "bias d %.2f g %.2f" % (c["still"]["Diff"]["bias"], c["still"]["Gloss"]["bias"])])
    return imgutil.grid([top, bot], heads, up)


def flicker_image(images, up, ref, r):
    e = imgutil.exposure_for(ref)
    p99 = 1.5 / e
    rows, heads = [[], [], []], []
    for label, seq in images["anim"].items():
        lum = [imgutil.luminance(f) for f in seq]
        d1 = np.mean([np.abs(lum[t + 1] - lum[t]) for t in range(len(lum) - 1)], axis=0)
        d2 = np.mean([np.abs(lum[t + 2] - 2 * lum[t + 1] + lum[t]) for t in range(len(lum) - 2)], axis=0)
        rows[0].append(imgutil.tonemap(seq[0], e))
        rows[1].append(imgutil.false_colour(d1 / p99, 0.02))
        rows[2].append(imgutil.false_colour(d2 / p99, 0.02))
        f = r["configs"][label]["flicker"]["light"]
        heads.append([label, "d %.3f g %.3f" % (f["Diff"]["median"], f["Gloss"]["median"])])
    if not heads:
        return None
    return imgutil.grid(rows, heads, up)


def git_commit():
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True,
                              text=True).stdout.strip() or "?"
    except OSError:
        return "?"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--size", default="test", help="test (80x60, 2x1024 spp), bench (320x240) or WxH[xSPP]")
    ap.add_argument("--scenes", default=None, help="comma-separated (default: all; --quick: spot_metal_floor)")
    ap.add_argument("--configs", default=None, help="comma-separated (default: %s; --quick: balanced)"
                    % ",".join(FULL_CONFIGS))
    ap.add_argument("--set", nargs="+", action="append", default=[], metavar="K=V",
                    help="one more configuration: preset=NAME (default balanced) and vsgl_render_settings fields")
    ap.add_argument("--name", action="append", default=[], help="labels of the --set configurations, in order")
    ap.add_argument("--anim", default="light,camera", help="animations: light,camera | light | camera | none")
    ap.add_argument("--frames", type=int, default=scenes.FRAMES)
    ap.add_argument("--anim-size", default=None, help="WxH of the animations (default: test 80x60, bench 160x120)")
    ap.add_argument("--brute-anim", action="store_true", help="also animate the brute force (slow)")
    ap.add_argument("--quick", action="store_true", help="one scene, one configuration, numbers only")
    ap.add_argument("--camera-truth", action="store_true",
                    help="also render the camera animation densely and report each configuration's camera flicker "
                         "above the motion's own change (slow: 12 x 12 samples, every pixel shaded)")
    ap.add_argument("--motion-truth", action="store_true",
                    help="also render the first and last frame of each animation in Cycles (both seeds, cached) and "
                         "report the motion's own change per frame")
    ap.add_argument("--acceptance", action="store_true", help="add issue 9's acceptance criteria (PASS/FAIL)")
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "quality"))
    ap.add_argument("--docs", action="store_true", help="write docs/quality.md and docs/img/quality/")
    ap.add_argument("--refs", default=refs.DEFAULT_DIR, help="reference cache directory")
    ap.add_argument("--no-images", action="store_true")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--repeat", type=int, default=1, help="time the still as the fastest of N runs (not brute)")
    ap.add_argument("--json", default=None, help="write the results here (default: under --out)")
    ap.add_argument("--before", default=None,
                    help="a results JSON of an earlier library: the report gains a before/after table of the presets")
    args = ap.parse_args(argv)

    if args.scenes in (None, "all"):
        names = ["spot_metal_floor"] if args.quick and args.scenes is None else list(scenes.NAMES)
    else:
        names = [n for n in args.scenes.split(",") if n]
        for n in names:
            scenes.scene(n)
    cfgs = []
    for i, group in enumerate(args.set):
        label = args.name[i] if i < len(args.name) else None
        cfgs.append(parse_config(" ".join(group), label))
    if args.configs is not None:
        cfgs = [parse_config(c) for c in split_configs(args.configs)] + cfgs
    elif not cfgs:
        cfgs = [parse_config(c) for c in (["balanced"] if args.quick else FULL_CONFIGS)]
    elif not args.quick:
        cfgs = [parse_config(c) for c in FULL_CONFIGS] + cfgs
    labels = [c.label for c in cfgs]
    if len(set(labels)) != len(labels):
        raise SystemExit("two configurations share a label: %s (use --name)" % labels)
    anims = [] if args.anim == "none" else [a for a in args.anim.split(",") if a]
    for a in anims:
        if a not in ("light", "camera"):
            raise SystemExit("--anim: light, camera or none")
    size_key = args.size if args.size in scenes.SIZES else "x".join(map(str, scenes.size_of(args.size)))
    if args.anim_size:
        anim_size = tuple(int(v) for v in args.anim_size.lower().split("x")[:2])
    else:
        anim_size = ANIM_SIZES.get(args.size, scenes.size_of(args.size)[:2])
    want_images = not (args.quick or args.no_images)

    rend = Renderer(args.threads)
    if args.docs:
        img_dir, md_path = os.path.join(ROOT, "docs", "img", "quality"), os.path.join(ROOT, "docs", "quality.md")
        img_rel = "img/quality"
    else:
        img_dir = os.path.join(args.out, "img_%s" % size_key)
        md_path = os.path.join(args.out, "report_%s.md" % size_key)
        img_rel = "img_%s" % size_key
    w, h, spp = scenes.size_of(args.size)
    # another library (VSGL_LIBRARY, e.g. an earlier commit's build for --before): its path in the
    # command, and the commit not the checkout's (which built a different library)
    other = os.environ.get("VSGL_LIBRARY")
    results = dict(command=("VSGL_LIBRARY=%s " % other if other else "") + "python3 tests/quality/evaluate.py " +
                   " ".join(argv if argv is not None else sys.argv[1:]),
                   library=L.version_string(),
                   commit=("checkout %s, library from VSGL_LIBRARY" % git_commit()) if other else git_commit(),
                   blender=refs.blender_version(args.refs),
                   spp=spp, size=[w, h], anim_size=list(anim_size), frames=args.frames, flip_error=M.FLIP_ERROR,
                   repeat=max(1, args.repeat), scenes={})
    if M.FLIP_ERROR:
        print("note: FLIP skipped (flip-evaluator does not import: %s)" % M.FLIP_ERROR)
    t0 = time.time()
    for name in names:
        r, images = evaluate_scene(name, cfgs, args.size, anim_size, args.frames, anims, args.refs, rend,
                                   args.brute_anim, want_images, repeat=max(1, args.repeat),
                                   camera_truth=args.camera_truth, motion_truth=args.motion_truth)
        results["scenes"][name] = r
        if want_images:
            os.makedirs(img_dir, exist_ok=True)
            up = max(1, 240 // h)
            imgutil.save_png(os.path.join(img_dir, "%s_still.png" % name), still_image(name, r, images, up))
            # one exposure per scene: the still reference's (a percentile does not depend on the size)
            fimg = flicker_image(images, max(1, 180 // anim_size[1]), images["ref"]["Combined"], r)
            if fimg is not None:
                imgutil.save_png(os.path.join(img_dir, "%s_flicker.png" % name), fimg)
        if args.acceptance:
            for label, a in acceptance(r).items():
                print("  acceptance %-9s %s" % (label, "  ".join("%s: %s" % kv for kv in a.items())))
    print("(%.1f s)" % (time.time() - t0))
    if args.quick:
        return results
    os.makedirs(args.out, exist_ok=True)
    jpath = args.json or os.path.join(args.out, "results_%s.json" % size_key)
    with open(jpath, "w") as fh:
        json.dump(results, fh, indent=1)
    os.makedirs(os.path.dirname(md_path), exist_ok=True)
    with open(md_path, "w") as fh:
        md = markdown(results, args, img_rel if want_images else None)
        if args.before:
            with open(args.before) as bf:
                md = md.replace("## Summary (presets)",
                                before_after(json.load(bf), results) + "## Summary (presets)", 1)
        fh.write(md)
    print("report: %s\nresults: %s%s" % (md_path, jpath, ("\nimages: " + img_dir) if want_images else ""))
    return results


if __name__ == "__main__":
    main()
