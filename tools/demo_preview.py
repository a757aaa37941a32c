"""preview.png of the demo: direct | indirect AOV | composite | Cycles
one-bounce reference | error, each labelled with what it is and its time.

    python3 tools/demo_preview.py OUT_DIR T0 T1 T2 T3 T_START REF_SPP

(T0-T1: the main render, T2-T3: the reference, wall-clock seconds)

Reads OUT_DIR/{direct,indirect,composite,reference}.exr and the logs;
writes preview.png and timings.txt.
"""
import os
import re
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "blender", "addon"))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "quality"))
from exr_read import read_exr  # noqa: E402
from imgutil import false_colour, luminance, save_png, text_strip, tonemap  # noqa: E402

out = sys.argv[1]
t0, t1, t2, t3, t_start = (float(x) for x in sys.argv[2:7])
ref_spp = int(sys.argv[7])
t_main, t_ref = t1 - t0, t3 - t2


def rgb(path, prefix=""):
    ch, _ = read_exr(path)
    keys = {}
    for k in ch:
        if prefix and not k.startswith(prefix):
            continue
        keys.setdefault(k.rsplit(".", 1)[-1], k)
    return np.dstack([ch[keys[c]] for c in "RGB"]).astype(np.float64)


def find_prefix(path, name):
    ch, _ = read_exr(path)
    for k in ch:
        parts = k.split(".")
        if len(parts) >= 2 and parts[-2] == name:
            return k[:-1]
    raise KeyError("%s: no pass %s (%s)" % (path, name, sorted(ch)[:8]))


direct = rgb(out + "/direct.exr")
aov = rgb(out + "/indirect.exr", "VSGL.Combined.")
comp = rgb(out + "/composite.exr")
refp = out + "/reference.exr"
ref = rgb(refp, find_prefix(refp, "Combined"))
ref_ind = sum(rgb(refp, find_prefix(refp, a)) * rgb(refp, find_prefix(refp, b))
              for a, b in (("DiffInd", "DiffCol"), ("GlossInd", "GlossCol")))
err = np.abs(comp - (direct + aov)).max()
assert err < 1e-2, "composite != direct + AOV (max error %g)" % err
assert aov.max() > 0, "the AOV is black"

log = open(out + "/render.log").read()
m = re.search(r"export ([\d.]+)s, render ([\d.]+)s, write ([\d.]+)s", log)
t_export, t_vsgl, t_write = (float(x) for x in m.groups()) if m else (float("nan"),) * 3
cyc = re.findall(r"Time: ?(\d+):([\d.]+)", log)
t_cycles = 60 * float(cyc[-1][0]) + float(cyc[-1][1]) if cyc else float("nan")
# Blender's render clock includes the add-on's work (it runs in render_pre)
t_cycles = max(t_cycles - (t_export + t_vsgl + t_write), 0.0) if m else t_cycles
rlog = open(out + "/reference.log").read()
rc = re.findall(r"Time: ?(\d+):([\d.]+)", rlog)
t_cycles_ref = 60 * float(rc[-1][0]) + float(rc[-1][1]) if rc else t_ref


def half(img):
    h, w = img.shape[0] // 2 * 2, img.shape[1] // 2 * 2
    return img[:h:2, :w:2] * 0.25 + img[1:h:2, :w:2] * 0.25 + img[:h:2, 1:w:2] * 0.25 + img[1:h:2, 1:w:2] * 0.25


def box(img, k=4):
    h, w = img.shape[0] // k * k, img.shape[1] // k * k
    b = img[:h, :w].reshape(h // k, k, w // k, k, *img.shape[2:]).mean(axis=(1, 3))
    return np.repeat(np.repeat(b, k, 0), k, 1)


lum_ref = luminance(ref)
expo = 1.2 / max(float(np.percentile(lum_ref, 95)), 1e-6)
aov_gain = 2.0
ind_mean = max(float(luminance(ref_ind).mean()), 1e-9)
e = np.abs(luminance(box(aov)) - luminance(box(ref_ind))) / ind_mean
bias = aov.reshape(-1, 3).mean(0) / np.maximum(ref_ind.reshape(-1, 3).mean(0), 1e-12)
rel_err = float(e.mean())
tiles = [
    (tonemap(direct, expo), ["CYCLES DIRECT LIGHT, %d SPP" % 0, "%.1f S (CYCLES)" % t_cycles]),
    (tonemap(aov * aov_gain, expo), ["VSGL INDIRECT AOV (X%g)" % aov_gain,
                                     "%.2f S (EXPORT %.2f + RENDER %.2f)" % (t_export + t_vsgl, t_export, t_vsgl)]),
    (tonemap(comp, expo), ["COMPOSITE = DIRECT + AOV", "%.1f S IN ALL" % (t_cycles + t_export + t_vsgl + t_write)]),
    (tonemap(ref, expo), ["CYCLES ONE BOUNCE, %d SPP" % ref_spp, "%.1f S" % t_cycles_ref]),
    (false_colour(e, 0.5), ["ERROR |AOV - CYCLES INDIRECT|", "4X4 BLUR, 0-50%% OF MEAN: %.0f%%" % (100 * rel_err)]),
]
direct_spp = re.findall(r"Sample (\d+)/(\d+)", log)
if direct_spp:
    tiles[0][1][0] = "CYCLES DIRECT LIGHT, %s SPP" % direct_spp[-1][1]
rows = []
for img, label in tiles:
    t = half(img)
    strip = text_strip(label, t.shape[1], scale=2)
    rows.append(np.concatenate([strip, t], axis=0))
gap = np.ones((rows[0].shape[0], 4, 3))
row = np.concatenate(sum([[r, gap] for r in rows], [])[:-1], axis=1)
save_png(out + "/preview.png", row)

line = ("timings: vsgl export %.2fs, vsgl render %.2fs, exr write %.2fs | Cycles direct %.1fs | blender -f 1 "
        "total %.1fs | Cycles one-bounce reference %d spp %.1fs | demo %.1fs | AOV / Cycles indirect (mean RGB) "
        "%s | mean |AOV - Cycles indirect| (4x4 blur) %.0f %% of its mean | composite = direct + AOV (max err %.1e)"
        % (t_export, t_vsgl, t_write, t_cycles, t_main, ref_spp, t_cycles_ref, time.time() - t_start,
           np.round(bias, 3), 100 * rel_err, err))
open(out + "/timings.txt", "w").write(line + "\n")
print(line)
