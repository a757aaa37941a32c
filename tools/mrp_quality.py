"""The MRP glossy mode against the VSGL glossy term and Cycles (docs/mrp.md §4).

Two steps, so that library variants (built with other compile-time
defaults, loaded through $VSGL_LIBRARY) can be measured in their own
processes and shown side by side:

    # measure (the quality harness's scenes, cached Cycles references, test size)
    # (default --configs: balanced, km256, mrp, hybrid, hybrid-km256, brute)
    python3 tools/mrp_quality.py run build/mrp_quality/main.npz
    # a variant library: only its MRP configuration, labelled with a suffix
    VSGL_LIBRARY=/tmp/mrp1/libvsgl.so python3 tools/mrp_quality.py run build/mrp_quality/lobe1.npz \\
        --configs "mrp:glossy_mode=3" --suffix " (1 lobe)"
    # the tables and images of docs/mrp.md from the measurements
    python3 tools/mrp_quality.py docs build/mrp_quality/main.npz build/mrp_quality/lobe1.npz

tools/mrp_quality.sh runs all of it. Metrics are the harness's
(tests/quality/metrics.py) on the glossy pass: bias (sum ratio), relMSE,
structured error (4 x 4 box-downsampled relMSE), FLIP of the glossy pass
alone, and flicker (median relative frame-to-frame change of the glossy
pass, light and camera animations, extent/1000 per frame). Times are the
fastest of --repeat still renders, all cores; the tables also give them
as ratios to k-means 256 measured in the same process, back to back.
"""
import argparse
import json
import os
import re
import sys

import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))

BEGIN, END = "<!-- mrp_quality: begin (tools/mrp_quality.py docs) -->", "<!-- mrp_quality: end -->"
SCENES = "spot_metal_floor,metal_floor_red_wall,sun_opening"
CONFIGS = ("balanced,km256:fit_mode=kmeans,vsgl_count=256,mrp:glossy_mode=3,hybrid:glossy_mode=4,"
           "hybrid-km256:glossy_mode=4,fit_mode=kmeans,vsgl_count=256,brute")
TIME_CONFIGS = "km256:fit_mode=kmeans,vsgl_count=256,balanced,mrp:glossy_mode=3,hybrid:glossy_mode=4"


def run(args):
    import evaluate as E  # noqa: E402 (loads the library: $VSGL_LIBRARY or build/)
    import refs
    cfgs = [E.parse_config(c) for c in E.split_configs(args.configs)]
    anims = [] if args.anim == "none" else args.anim.split(",")
    rend = E.Renderer(args.threads)
    out = dict(library=E.L.version_string(), library_path=os.environ.get("VSGL_LIBRARY", "build/libvsgl.so"),
               commit=E.git_commit(), frames=args.frames, scenes={})
    arrays = {}
    for name in args.scenes.split(","):
        r, images = E.evaluate_scene(name, cfgs, "test", (80, 60), args.frames, anims, refs.DEFAULT_DIR, rend,
                                     want_images=True, repeat=args.repeat)
        entry = {}
        for label, e in r["configs"].items():
            lab = label + args.suffix
            g = e["still"]["Gloss"]
            entry[lab] = dict(seconds=e["seconds"], bias=g["bias"], relmse=g["relmse"], structured=g["structured"],
                              flip=g.get("flip"), describe=e["describe"],
                              flicker={k: e["flicker"][k]["Gloss"]["median"] for k in e["flicker"]})
            arrays["%s|%s" % (name, lab)] = images["still"][label]["Gloss"].astype(np.float32)
            print("%-22s %-16s %6.3f s  gloss bias %.3f relMSE %.4f struct %.5f FLIP %s flicker %s" % (
                name, lab, e["seconds"], g["bias"], g["relmse"], g["structured"],
                "-" if g.get("flip") is None else "%.4f" % g["flip"],
                " ".join("%s %.4f" % kv for kv in entry[lab]["flicker"].items()) or "-"), flush=True)
        arrays["%s|ref" % name] = images["ref"]["Gloss"].astype(np.float32)
        out["scenes"][name] = dict(configs=entry, noise_s4=r["reference"]["noise"]["Gloss"]["s4"])
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    np.savez_compressed(args.out, results=json.dumps(out), **arrays)
    print("wrote", args.out)


def timing(args):
    """Interleaved rounds: every configuration once per round, in turn, so
    that a changing load on a shared machine hits them alike; the median."""
    import evaluate as E  # noqa: E402
    import scenes
    cfgs = [E.parse_config(c) for c in E.split_configs(args.configs)]
    rend = E.Renderer(args.threads)
    out = {}
    for name in args.scenes.split(","):
        case = scenes.case(name, (80, 60))
        times = {c.label: [] for c in cfgs}
        for c in cfgs:  # warm-up
            rend.render(case, c)
        for _ in range(args.rounds):
            for c in cfgs:
                times[c.label].append(rend.render(case, c)[1])
        out[name] = {k: float(np.median(v)) for k, v in times.items()}
        print(name, " ".join("%s %.3f" % kv for kv in out[name].items()), flush=True)
    with open(args.out, "w") as fh:
        json.dump(dict(rounds=args.rounds, medians=out, commit=E.git_commit()), fh, indent=1)


def timing_table(t):
    labels = list(next(iter(t["medians"].values())).keys())
    lines = ["| scene | " + " | ".join(labels) + " |", "|---" * (len(labels) + 1) + "|"]
    for name, m in t["medians"].items():
        base = m.get("km256")
        lines.append("| %s | " % name + " | ".join(
            "%.3f s (%s)" % (m[l], _f(m[l] / base if base else float("nan"), "%.2fx")) for l in labels) + " |")
    return "\n".join(lines)


def _load(paths):
    res, arrs = None, {}
    for p in paths:
        z = np.load(p)
        r = json.loads(str(z["results"]))
        for k in z.files:
            if k != "results":
                arrs[k] = z[k]
        if res is None:
            res = r
            res["variants"] = []
        else:
            res["variants"].append(dict(library_path=r["library_path"], commit=r["commit"]))
            for name, s in r["scenes"].items():
                for e in s["configs"].values():
                    e["other_process"] = True
                res["scenes"].setdefault(name, dict(configs={}, noise_s4=s["noise_s4"]))["configs"].update(s["configs"])
    return res, arrs


def _f(x, fmt):
    return "-" if x is None or not np.isfinite(x) else fmt % x


def table(res):
    lines = ["| scene | config | time | time / k-means 256 | glossy bias | glossy relMSE | glossy structured "
             "| glossy FLIP | flicker light | flicker camera |", "|---|---|---|---|---|---|---|---|---|---|"]
    for name, s in res["scenes"].items():
        cf = s["configs"]
        base = cf.get("km256", {}).get("seconds")
        for label, e in cf.items():
            ratio = e["seconds"] / base if base else float("nan")
            bold = "**" if label.startswith(("mrp", "hybrid")) and not e.get("other_process") else ""
            rtxt = "(another run)" if e.get("other_process") else _f(ratio, "%.1fx")
            lines.append("| %s | %s%s%s | %.2f s | %s | %.3f | %s | %s | %s | %s | %s |" % (
                name, bold, label, bold, e["seconds"], rtxt, e["bias"], _f(e["relmse"], "%.4f"),
                _f(e["structured"], "%.5f"), _f(e["flip"], "%.3f"), _f(e["flicker"].get("light"), "%.4f"),
                _f(e["flicker"].get("camera"), "%.4f")))
    return "\n".join(lines)


def verdict(res):
    """One line per scene and MRP configuration: does it beat k-means 256 on glossy relMSE and FLIP at no
    more time (the acceptance), and does it beat balanced (the lattice it runs beside) on both?"""
    out = []
    for name, s in res["scenes"].items():
        cf = s["configs"]
        k, b = cf.get("km256"), cf.get("balanced")
        if not k:
            continue
        for label, e in cf.items():
            if not label.startswith(("mrp", "hybrid")) or e.get("other_process"):
                continue
            t = res.get("timing", {}).get(name, {})
            tk, te = t.get("km256"), t.get(label)
            if tk and te:  # the interleaved medians (timing table) decide, not the single still
                tq, tt = te <= tk, "median %.3f vs %.3f s" % (te, tk)
            else:
                tq, tt = e["seconds"] <= k["seconds"], "%.2f vs %.2f s" % (e["seconds"], k["seconds"])
            wins = [e["relmse"] < k["relmse"], (e["flip"] or 1) < (k["flip"] or 0), tq]
            vb = ""
            if b:
                bw = [e["relmse"] < b["relmse"], (e["flip"] or 1) < (b["flip"] or 0)]
                vb = "; against balanced (%.4f, %s): %s" % (
                    b["relmse"], _f(b["flip"], "%.4f"), "lower relMSE and FLIP" if all(bw) else
                    "lower relMSE only" if bw[0] else "lower FLIP only" if bw[1] else "neither lower")
            out.append("- %s, %s: glossy relMSE %.4f vs %.4f (%s), FLIP %s vs %s (%s), time %s (%s): %s%s" % (
                name, label, e["relmse"], k["relmse"], "lower" if wins[0] else "higher",
                _f(e["flip"], "%.4f"), _f(k["flip"], "%.4f"), "lower" if wins[1] else "higher",
                tt, "no more" if wins[2] else "more",
                "**meets** the acceptance" if all(wins) else "does not meet the acceptance", vb))
    return "\n".join(out)


def image(res, arrs, name, labels, path):
    import imgutil
    ref = arrs["%s|ref" % name]
    e = imgutil.exposure_for(ref)
    lum = imgutil.luminance
    heads, top, bot = [["cycles", "glossy pass", ""]], [imgutil.tonemap(ref, e)], [np.zeros(ref.shape)]
    for lab in labels:
        key = "%s|%s" % (name, lab)
        if key not in arrs:
            continue
        img = arrs[key]
        c = res["scenes"][name]["configs"][lab]
        top.append(imgutil.tonemap(img, e))
        bot.append(imgutil.signed_error(lum(img) - lum(ref), 4 * e))
        base, _, var = lab.partition(" (")  # a variant's label on a second line
        heads.append([base, "(" + var if var else "", "relmse %.4f" % c["relmse"]])
    up = 3
    rows = [[imgutil.upscale(t, up) for t in row] for row in (top, bot)]
    h, w = rows[0][0].shape[:2]
    cols = []
    for j in range(len(top)):
        parts = [imgutil.text_strip(heads[j], w)]
        for row in rows:
            parts += [np.ones((1, w, 3)), row[j]]
        cols.append(np.concatenate(parts, axis=0))
    sep = np.ones((cols[0].shape[0], 1, 3))
    imgutil.save_png(path, np.concatenate(sum([[c, sep] for c in cols], [])[:-1], axis=1))


MRP_ALONE = "hybrid (MRP's light alone)"
RATIOS = (0.0, 1.0, 1.25, 1.5, 2.0, 3.0)


def ratio_sweep(res, arrs):
    """The hybrid's ratio rule (VSGL__MRP_HYBRID_RATIO) replayed per pixel from the stills: MRP's light
    (the hybrid's MRP pass alone, variant hybmrp) where its sum of channels is above r times balanced's,
    balanced's elsewhere. The off-proxy clusters' light is left out of the comparison (the floor's
    specular clusters: little at the floor's own pixels), so ratio 1 and 2 give about the hybrid's rows."""
    import metrics
    lines = ["| scene | ratio r | pixels taking MRP | glossy relMSE | glossy FLIP |", "|---|---|---|---|---|"]
    for name in res["scenes"]:
        keys = ["%s|%s" % (name, l) for l in ("ref", "balanced", MRP_ALONE)]
        if not all(k in arrs for k in keys):
            continue
        ref, bal, mrp = (arrs[k].astype(np.float64) for k in keys)
        for r in RATIOS:
            take = mrp.sum(2) > r * bal.sum(2)
            a = np.where(take[..., None], mrp, bal)
            row = (name, "%g" % r, int(take.sum()), metrics.relmse(a, ref), _f(metrics.flip(a, ref), "%.4f"))
            lines.append("| %s | %s | %d | %.5f | %s |" % row)
        row = (name, metrics.relmse(bal, ref), _f(metrics.flip(bal, ref), "%.4f"))
        lines.append("| %s | balanced | 0 | %.5f | %s |" % row)
    return "\n".join(lines)


def win_map(res, arrs, path):
    """Per scene a row: Cycles | balanced | MRP's light (the hybrid's pass alone) | where each is closer to
    Cycles (per-pixel relMSE term: green MRP's light, magenta balanced's; brightness the difference)."""
    import imgutil
    rows = []
    for name in res["scenes"]:
        keys = ["%s|%s" % (name, l) for l in ("ref", "balanced", MRP_ALONE)]
        if not all(k in arrs for k in keys):
            continue
        ref, bal, mrp = (arrs[k].astype(np.float64) for k in keys)
        err = lambda a: np.mean((a - ref) ** 2 / (ref * ref + 0.01), axis=2)  # noqa: E731 (metrics.relmse per pixel)
        d = err(bal) - err(mrp)
        t = np.clip(d / (np.percentile(np.abs(d), 99) or 1.0), -1, 1)
        win = np.stack([np.clip(-t, 0, 1), np.clip(t, 0, 1), np.clip(-t, 0, 1)], -1)
        e = imgutil.exposure_for(ref)
        tiles = [imgutil.tonemap(ref, e), imgutil.tonemap(bal, e), imgutil.tonemap(mrp, e), win]
        up = [imgutil.upscale(x, 3) for x in tiles]
        sep = np.ones((up[0].shape[0], 1, 3))
        rows.append(np.concatenate(sum([[x, sep] for x in up], [])[:-1], axis=1))
        rows.append(np.ones((1, rows[-1].shape[1], 3)))
    if rows:
        imgutil.save_png(path, np.concatenate(rows[:-1], axis=0))
    return bool(rows)


def docs(args):
    res, arrs = _load(args.inputs)
    t = json.load(open(args.timing)) if args.timing else None
    if t:
        res["timing"] = t["medians"]
    img_dir = os.path.join(ROOT, "docs", "img")
    md = [BEGIN, "", "Measured at %s (library %s%s); command: `tools/mrp_quality.sh`. Glossy pass against the "
          "mean of two 1024-spp Cycles seeds, 80 x 60; times: the fastest of 3 stills in one process "
          "(variants: built with other defaults, run in another process: their times are not comparable)." % (
              res["commit"], res["library"], "".join("; variant %s" % os.path.basename(os.path.dirname(
                  v["library_path"])) for v in res["variants"])), "", table(res), ""]
    if t:
        md += ["Times as medians of %d interleaved rounds (each configuration once per round, in turn; "
               "ratio to k-means 256):" % t["rounds"], "", timing_table(t), ""]
    md += ["The acceptance, per scene and configuration (k-means 256 as the reference; the time from the "
           "interleaved medians where measured):", "", verdict(res), ""]
    sweep = ratio_sweep(res, arrs)
    if sweep.count("\n") > 1:
        md += ["The hybrid's ratio rule replayed per pixel from these stills (`ratio_sweep`: MRP's light, the "
               "hybrid's pass alone, where it is above r times balanced's, balanced's elsewhere; r 0 is MRP's light "
               "alone, 1 the rule before, 2 the default):", "", sweep, ""]
    if win_map(res, arrs, os.path.join(img_dir, "mrp_quality_win.png")):
        md += ["![Per scene (spot_metal_floor, metal_floor_red_wall, sun_opening): Cycles | balanced | MRP's light "
               "(the hybrid's pass alone) | per pixel, which of the two is closer to Cycles (green MRP's light, "
               "magenta balanced's)](img/mrp_quality_win.png)", ""]
    for name in res["scenes"]:
        shown = lambda l: l != "hybrid-km256" and "(" not in l  # noqa: E731
        labels = [l for l in res["scenes"][name]["configs"]
                  if shown(l) or l in ("hybrid (ratio 1, the rule before)", "hybrid (MRP's light alone)")]
        fn = "mrp_quality_%s.png" % name
        image(res, arrs, name, labels, os.path.join(img_dir, fn))
        md += ["![%s, glossy pass (80 x 60): Cycles | %s; below, the signed error of each (red too bright, blue "
               "too dark)](img/%s)" % (name, " | ".join(labels), fn), ""]
    md.append(END)
    path = os.path.join(ROOT, "docs", "mrp.md")
    text = open(path).read()
    block = "\n".join(md)
    if BEGIN in text:
        text = re.sub(re.escape(BEGIN) + ".*?" + re.escape(END), lambda m: block, text, flags=re.S)
    else:
        text = text.rstrip("\n") + "\n\n" + block + "\n"
    open(path, "w").write(text)
    print("\n".join(md))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("out")
    r.add_argument("--configs", default=CONFIGS)
    r.add_argument("--scenes", default=SCENES)
    r.add_argument("--anim", default="light,camera")
    r.add_argument("--frames", type=int, default=12)
    r.add_argument("--repeat", type=int, default=3)
    r.add_argument("--threads", type=int, default=0)
    r.add_argument("--suffix", default="")
    tm = sub.add_parser("time")
    tm.add_argument("out")
    tm.add_argument("--configs", default=TIME_CONFIGS)
    tm.add_argument("--scenes", default=SCENES)
    tm.add_argument("--rounds", type=int, default=7)
    tm.add_argument("--threads", type=int, default=0)
    d = sub.add_parser("docs")
    d.add_argument("inputs", nargs="+")
    d.add_argument("--timing", default=None, help="the JSON of the time command")
    args = ap.parse_args(argv)
    dict(run=run, time=timing, docs=docs)[args.cmd](args)


if __name__ == "__main__":
    main()
