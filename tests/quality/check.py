#!/usr/bin/env python3
"""The quality suite's checks (make test, via tests/blender/run_quality.sh), at test size.

Checks that hold today and can fail; prints PASS/FAIL lines and ends with
"N passed, N failed":

- the metrics against hand-computed cases (test_metrics.py);
- each reference: finite and non-negative; its two seeds differ and agree
  within their noise (|z| < 4 per pass, metrics.seed_agreement); its own 4x4
  noise small enough to see blotches (< 0.002 per pass);
- each scene shows what it exists for (checked on the reference, with the
  library's G-buffer to find the surfaces);
- the brute-force gather (RSM 128, aa 1) within +-6 % of Cycles per pass
  (issue 9 measured this on its rooms: the RSM holds the light);

then measures the presets (still and both animations, VSGL_QUALITY_FRAMES
frames, default 12) and checks what they hold (MAX_EXCESS_LIGHT, the light
animation's change beyond the motion's own change in Cycles, step by step,
MAX_FLICKER_CAMERA, MAX_BIAS, MAX_STRUCT_GLOSS, QUALITY_OVER_BALANCED below; every one fails with
the session-1 presets: flicker 0.12-0.74, bias up to 3.4x; the camera checks
and the 5 % bias of balanced and quality fail with the session-3 presets),
with issue 9's own acceptance criteria as
INFO lines. Writes build/quality/check_test.md and .json.
"""
import argparse
import json
import os
import sys
import traceback

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "addon", "vsgl_indirect"))
import evaluate as E  # noqa: E402
import imgutil  # noqa: E402
import libvsgl as L  # noqa: E402
import metrics as M  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402
import test_metrics  # noqa: E402

TOL_BRUTE = 0.06
# What the presets hold at test size (issue 9; its own thresholds, flicker 0.01 and bias 5 %, are
# reported as INFO acceptance lines): the median light-animation flicker per pass, the bias per
# pass, and quality's structured error (combined pass) against balanced's, where a tie within the
# references' noise is allowed (the spot room: both at its noise floor).
# The light animation: its change beyond the motion's own change in Cycles, step by step (evaluate.py
# --motion-truth; metrics.excess_over_seeds against both seeds of every frame, which removes their noise).
# A sun patch sliding across a floor changes a room's indirect light by 0.008-0.045 a frame in Cycles
# itself, unevenly (an edge of the patch crossing a junction), so a bound on the raw change would be
# either too loose for the small lights or fail a renderer that follows the motion. Balanced and quality:
# the 0.01 (measured at 12 frames, before a sun's RSM covered only what it lights: 0.0101 /
# 0.0108 in sun_opening_thick; after: 0.0024 / 0.0071). The preview: with one ASG for GGX on a
# lattice of 32 its glint jumped as the sun's patch slid over a glossy cabinet (Gloss 0.024 in the sun
# rooms); with two (since 2026-12-03) 0.007-0.009, but a visibility ray to one of its few clusters can
# flip (the sphere room's 0.011), so its bound is the tolerance for a preview, 3 x.
MAX_EXCESS_LIGHT = dict(preview=0.03, balanced=0.01, quality=0.01)
# The camera animation, where a moving view's own change stays below 0.01 a frame at 80x60 (the
# sphere's rim and the sun rooms' sunlit patch change more than that by themselves: INFO there):
# 0.012-0.028 per frame before edge pixels were refined (crawling silhouettes), 0.006-0.010 after.
MAX_FLICKER_CAMERA = 0.012
CAMERA_SCENES = ("spot_metal_floor", "metal_floor_red_wall", "box_point_area_glossy_green")
MAX_BIAS = dict(preview=0.30, balanced=0.05, quality=0.05)
QUALITY_OVER_BALANCED = 1.15
# Blotches in the glossy pass: balanced's and quality's structured Gloss error on every room (the
# spot room's metal floor broke the reflected ellipse into lobes: 0.0054 in session 4, 0.0019 in the
# red-wall room, with one Gaussian for GGX and the sparse shading's bilinear blur; 0.0004-0.0011
# with GGX as two lobes and the sparse shading's contrast bound; 0.00002-0.00022 since 2026-12-06,
# the largest the corridor's floor seen at grazing angles, 0.00064 before the horizon cut took its
# lobe's fan, docs/math.md 5.4.3).
MAX_STRUCT_GLOSS = 0.0004
TOL_Z = 4.0
MAX_NOISE_S4 = 0.002


class Counter:
    def __init__(self):
        self.passed = self.failed = 0

    def check(self, ok, text):
        print(("PASS " if ok else "FAIL ") + text, flush=True)
        self.passed += bool(ok)
        self.failed += not ok


def gbuffer_materials(name):
    """(material index image (H, W), material names) of a scene at test size, pixel centres."""
    c = scenes.case(name, "test")
    ctx = L.Context()
    with L.Scene(ctx, **scenes.library_arrays(c, L)) as sc:
        m = L.debug_gbuffer(ctx, sc, 1)["materials"][:, :, 0].astype(np.int64)
    return m, scenes.material_order(c)


def adjacent(m, a, b):
    """Pixels of material a with a 4-neighbour of material b (a junction in the image)."""
    h, w = m.shape
    hit = np.zeros((h, w), bool)
    for dy, dx in ((0, 1), (0, -1), (1, 0), (-1, 0)):
        sh = np.full((h, w), -1)
        ys, yd = slice(max(dy, 0), h + min(dy, 0)), slice(max(-dy, 0), h + min(-dy, 0))
        xs, xd = slice(max(dx, 0), w + min(dx, 0)), slice(max(-dx, 0), w + min(-dx, 0))
        sh[yd, xd] = m[ys, xs]
        hit |= (m == a) & (sh == b)
    return int(hit.sum())


def feature_checks(name, ref, cnt):
    """What each scene exists for, on the reference (coloured passes)."""
    m, mats = gbuffer_materials(name)
    idx = {n: i for i, n in enumerate(mats)}
    lum = {p: imgutil.luminance(ref[p]) for p in ("Diff", "Gloss", "Combined")}
    walls = [idx[n] for n in ("wall", "back_wall", "red_wall", "window_wall") if n in idx]
    junction_ceiling = sum(adjacent(m, idx["ceiling"], w) for w in walls)
    junction_floor = sum(adjacent(m, f, w) for w in walls for f in [idx[n] for n in mats if "floor" in n])
    if name == "spot_metal_floor":
        fl = m == idx["metal_floor"]
        g = lum["Gloss"][fl]
        ratio = float(ref["Gloss"][fl].sum() / ref["Diff"].sum())
        peak = float(np.percentile(g, 99) / max(np.median(g), 1e-9))
        cnt.check(ratio > 0.5 and peak > 5, "feature %s: the metal floor reflects a bright ellipse (floor Gloss sum "
                  "%.2f x the image's Diff sum, > 0.5; its 99th percentile %.1f x its median, > 5)"
                  % (name, ratio, peak))
    elif name == "metal_floor_red_wall":
        bw = m == idx["back_wall"]
        r, g = float(ref["Diff"][bw][:, 0].mean()), float(ref["Diff"][bw][:, 1].mean())
        fl = m == idx["metal_floor"]
        rg = float(ref["Gloss"][fl][:, 0].sum() / max(ref["Gloss"][fl][:, 1].sum(), 1e-9))
        cnt.check(r > 2 * g and rg > 2, "feature %s: the back wall receives red light (Diff R/G %.2f, > 2) and the "
                  "metal floor reflects it (Gloss R/G %.2f, > 2)" % (name, r / max(g, 1e-9), rg))
    elif name == "box_point_area_glossy_green":
        gw = m == idx["green_glossy"]
        gg = ref["Gloss"][gw]
        sheen = float(gg[:, 1].mean() / max(lum["Diff"][m != idx["green_glossy"]].mean(), 1e-9))
        cnt.check(sheen > 0.1 and gg[:, 1].mean() > 3 * gg[:, 0].mean(),
                  "feature %s: the green wall has a green sheen (its Gloss G %.2f x the other walls' Diff, > 0.1; "
                  "G/R %.1f, > 3)" % (name, sheen, gg[:, 1].mean() / max(gg[:, 0].mean(), 1e-9)))
        cnt.check(junction_ceiling >= 40 and junction_floor >= 40,
                  "feature %s: the camera frames the junctions (%d wall/ceiling and %d wall/floor junction pixels, "
                  ">= 40 each)" % (name, junction_ceiling, junction_floor))
    elif name == "glossy_sphere_floor":
        sp, fl = m == idx["sphere"], m == idx["polished_floor"]
        ys, xs = np.nonzero(sp)
        # the floor just below the sphere in the image (its columns, 8 rows under its lowest pixel)
        band = np.zeros_like(fl)
        band[ys.max() + 1:ys.max() + 9, xs.min():xs.max() + 1] = True
        band &= fl
        g = lum["Gloss"]
        ratio = float(g[band].mean() / max(np.median(g[fl]), 1e-9)) if band.any() else 0.0
        cnt.check(sp.sum() >= 100 and ratio > 5,
                  "feature %s: the sphere (%d px) is reflected in the floor below it (the floor's Gloss there %.1f x "
                  "its median, > 5)" % (name, sp.sum(), ratio))
    elif name == "grazing_corridor":
        fl, ew = m == idx["polished_floor"], m == idx["end_wall"]
        ys, xs = np.nonzero(ew)
        # the floor below the end wall in the image (its columns, every row under its lowest pixel)
        band = np.zeros_like(fl)
        band[ys.max() + 1:, xs.min():xs.max() + 1] = True
        band &= fl
        g = lum["Gloss"]
        ratio = float(g[band].mean() / max(np.median(g[fl]), 1e-9)) if band.any() else 0.0
        cnt.check(ew.sum() >= 50 and band.sum() >= 100 and ratio > 20,
                  "feature %s: the floor reflects the lit end wall (%d px) down %d px below it (the floor's Gloss "
                  "there %.0f x its median, > 20)" % (name, ew.sum(), band.sum(), ratio))
    elif name.startswith("sun_opening"):
        c = scenes.case(name, "test")
        ctx = L.Context()
        with L.Scene(ctx, **scenes.library_arrays(c, L)) as sc:
            rsm = L.reference_rsm(ctx, sc, 0, 128)
        lit = rsm["materials"] != 0xFFFFFFFF
        flux = rsm["flux"].sum(1)
        inside = float(flux[lit & (rsm["materials"] == idx["floor"])].sum() / max(flux.sum(), 1e-9))
        ceil = float(lum["Diff"][m == idx["ceiling"]].mean())
        cnt.check(inside > 0.01 and ceil > 0.01,
                  "feature %s: the sun enters through the window (%.1f %% of its RSM flux lands on the floor inside, "
                  "> 1 %%) and lights the room (ceiling Diff %.3f, > 0.01)" % (name, 100 * inside, ceil))
    elif name == "textured_interior":
        d = ref["Diff"]
        cl, fl, wp = m == idx["ceiling"], m == idx["planks"], m == idx["wallpaper"]
        ce = float(d[cl][:, 0].mean() / max(d[cl][:, 1].mean(), 1e-9))
        fg = ref["Gloss"][fl]
        rg = float(fg[:, 0].sum() / max(fg[:, 1].sum(), 1e-9))
        gl = float(fg.sum() / max(d[fl].sum(), 1e-9))
        gr = d[wp][:, 1] / np.maximum(d[wp][:, 0], 1e-9)
        spread = float(np.percentile(gr, 95) - np.percentile(gr, 5))
        cnt.check(spread > 0.3 and ce > 1.3 and rg > 1.3 and gl > 0.2,
                  "feature %s: the wallpaper's stripes are in view (its Diff G/R spans %.2f between the 5th and "
                  "95th percentiles, > 0.3), its red bleeds onto the white ceiling (Diff R/G %.2f, > 1.3) and the "
                  "varnished planks reflect it (floor Gloss R/G %.2f, > 1.3; Gloss %.2f x the floor's Diff, > 0.2)"
                  % (name, spread, ce, rg, gl))
    elif name == "rough_room":
        wl = np.isin(m, [idx["wall"], idx["back_wall"], idx["ceiling"]])
        sp = m == idx["sphere"]
        share = float(ref["Gloss"][wl].sum() / max(ref["Diff"][wl].sum(), 1e-9))
        cnt.check(share > 0.03 and sp.sum() >= 50,
                  "feature %s: the rough walls and ceiling have a glossy pass (Gloss %.3f x their Diff, > 0.03) and "
                  "the rough sphere is in view (%d px, >= 50)" % (name, share, sp.sum()))
    print("INFO %s: %d wall/ceiling and %d wall/floor junction pixels in view" % (name, junction_ceiling,
                                                                                  junction_floor))


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default=",".join(scenes.NAMES))
    ap.add_argument("--refs", default=refs.DEFAULT_DIR)
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "quality"))
    ap.add_argument("--frames", type=int, default=int(os.environ.get("VSGL_QUALITY_FRAMES", scenes.FRAMES)))
    args = ap.parse_args(argv)
    cnt = Counter()

    for t in test_metrics.TESTS:
        name = t.__name__[5:].replace("_", " ")
        if t.__name__ == "test_flip_of_identical_images_is_zero" and M.FLIP_ERROR:
            print("SKIP metrics: %s (flip-evaluator does not import: %s)" % (name, M.FLIP_ERROR))
            continue
        try:
            t()
            cnt.check(True, "metrics: " + name)
        except Exception:  # noqa: BLE001  (a failed assertion or an error: report, go on)
            cnt.check(False, "metrics: %s\n%s" % (name, traceback.format_exc(limit=2)))

    names = [n for n in args.scenes.split(",") if n]
    try:
        R = refs.ensure(names, "test", args.refs)
    except RuntimeError as e:
        cnt.check(False, "references: %s" % e)
        print("%d passed, %d failed" % (cnt.passed, cnt.failed))
        return 1
    rend = E.Renderer()
    cfgs = [E.parse_config(c) for c in ("preview", "balanced", "quality", "brute")]
    results = dict(command="python3 tests/quality/check.py", library=L.version_string(), commit=E.git_commit(),
                   blender=refs.blender_version(args.refs), spp=scenes.size_of("test")[2],
                   size=list(scenes.size_of("test")[:2]), anim_size=list(E.ANIM_SIZES["test"]), frames=args.frames,
                   flip_error=M.FLIP_ERROR, scenes={})
    for n in names:
        raw = [p for p, _ in R[n]]
        ok = all(np.all(np.isfinite(p[k])) and np.all(p[k] >= 0) for p in raw for k in refs.PASSES)
        cnt.check(ok, "reference %s: both seeds finite and non-negative" % n)
        seeds = [M.coloured(p) for p in raw]
        ref = {p: 0.5 * (seeds[0][p] + seeds[1][p]) for p in seeds[0]}
        z = {p: M.seed_agreement(seeds[0][p], seeds[1][p]) for p in ("Diff", "Gloss")}
        cnt.check(all(np.isfinite(v) and abs(v) < TOL_Z for v in z.values()),
                  "reference %s: the seeds differ and agree within their noise (z Diff %.2f, Gloss %.2f; |z| < %g)"
                  % (n, z["Diff"], z["Gloss"], TOL_Z))
        s4 = {p: M.ref_noise(seeds[0][p], seeds[1][p], 4) for p in ("Diff", "Gloss")}
        cnt.check(all(v < MAX_NOISE_S4 for v in s4.values()),
                  "reference %s: its own 4x4 noise is small (Diff %.5f, Gloss %.5f; < %g)"
                  % (n, s4["Diff"], s4["Gloss"], MAX_NOISE_S4))
        feature_checks(n, ref, cnt)

        r, _ = E.evaluate_scene(n, cfgs, "test", E.ANIM_SIZES["test"], args.frames, ["light", "camera"], args.refs,
                                rend, want_images=False, log=lambda line: print("INFO " + line, flush=True),
                                motion_truth=True, steps=("light",), steps_frames=args.frames)
        results["scenes"][n] = r
        b = r["configs"]["brute"]["still"]
        cnt.check(all(abs(b[p]["bias"] - 1) <= TOL_BRUTE for p in ("Diff", "Gloss")),
                  "brute force %s: within %d %% of Cycles per pass (Diff %.3f, Gloss %.3f; %s)"
                  % (n, 100 * TOL_BRUTE, b["Diff"]["bias"], b["Gloss"]["bias"], r["configs"]["brute"]["describe"]))
        for label in ("preview", "balanced", "quality"):
            e = r["configs"][label]
            fl = e["flicker"]["light"]
            exc = {p: fl[p]["excess_cycles"] for p in ("Diff", "Gloss")}
            cnt.check(all(exc[p] <= MAX_EXCESS_LIGHT[label] for p in ("Diff", "Gloss")),
                      "%s %s: the light animation changes beyond Cycles' own change, step by step, Diff %.4f, "
                      "Gloss %.4f (<= %g; flicker %.4f / %.4f, Cycles' own from frames 0 and %d %.4f / %.4f)"
                      % (label, n, exc["Diff"], exc["Gloss"], MAX_EXCESS_LIGHT[label], fl["Diff"]["median"],
                         fl["Gloss"]["median"], E.MOTION_STEPS, r["motion"]["light"]["Diff"],
                         r["motion"]["light"]["Gloss"]))
            fc = e["flicker"]["camera"]
            if n in CAMERA_SCENES:
                cnt.check(all(fc[p]["median"] <= MAX_FLICKER_CAMERA for p in ("Diff", "Gloss")),
                          "%s %s: the camera animation's flicker Diff %.4f, Gloss %.4f (<= %g)"
                          % (label, n, fc["Diff"]["median"], fc["Gloss"]["median"], MAX_FLICKER_CAMERA))
            s = e["still"]
            if label != "preview":
                cnt.check(s["Gloss"]["structured"] <= MAX_STRUCT_GLOSS,
                          "%s %s: glossy structured error %.5f (<= %g: no blotches in the reflections)"
                          % (label, n, s["Gloss"]["structured"], MAX_STRUCT_GLOSS))
            cnt.check(all(abs(s[p]["bias"] - 1) <= MAX_BIAS[label] for p in ("Diff", "Gloss")),
                      "%s %s: bias Diff %.3f, Gloss %.3f (within %d %%)" % (label, n, s["Diff"]["bias"],
                                                                            s["Gloss"]["bias"], 100 * MAX_BIAS[label]))
        q, b = (r["configs"][k]["still"]["Combined"]["structured"] for k in ("quality", "balanced"))
        cnt.check(q <= QUALITY_OVER_BALANCED * b, "quality %s: structured error %.5f, balanced %.5f (<= %gx)"
                  % (n, q, b, QUALITY_OVER_BALANCED))
        for label, a in E.acceptance(r).items():
            print("INFO acceptance %s %s: %s" % (n, label, "; ".join("%s %s" % kv for kv in a.items())))
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "check_test.json"), "w") as fh:
        json.dump(results, fh, indent=1)
    with open(os.path.join(args.out, "check_test.md"), "w") as fh:
        fh.write(E.markdown(results, argparse.Namespace(acceptance=True), None))
    print("(report: %s)" % os.path.join(args.out, "check_test.md"))
    print("%d passed, %d failed" % (cnt.passed, cnt.failed))
    return 1 if cnt.failed else 0


if __name__ == "__main__":
    sys.exit(main())
