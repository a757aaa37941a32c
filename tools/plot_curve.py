"""Plot the error-against-time curve of build/blender/cycles/report_curve.md
(tools/curve.sh) to docs/img/curve.png. Needs matplotlib (pip, in the
python3 on PATH): python3 tools/plot_curve.py"""
import os
import re
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

root = os.path.normpath(os.path.join(os.path.dirname(__file__), ".."))
src = os.path.join(root, "build", "blender", "cycles", "report_curve.md")
rows = []
for line in open(src):
    m = re.match(r"\| (.+?) \| ([0-9.]+) \| ([0-9.]+) \|", line)
    if m:
        rows.append((m.group(1), float(m.group(2)), float(m.group(3))))
if not rows:
    sys.exit("no rows in %s (run tools/curve.sh)" % src)
fig, ax = plt.subplots(figsize=(7, 4.5))
cyc = [(t, e, l) for l, t, e in rows if l.startswith("Cycles")]
ax.plot([c[0] for c in cyc], [c[1] for c in cyc], "o-", color="grey", label="Cycles 1..256 spp")
for t, e, l in cyc:
    ax.annotate(l.replace("Cycles ", ""), (t, e), textcoords="offset points", xytext=(4, 4), fontsize=7, color="grey")
for l, t, e in rows:
    if l.startswith("vsgl"):
        ax.plot([t], [e], "s" if "preset" in l else "^", label=l[5:], markersize=6)
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel("seconds (80x60 px, 2 cores)")
ax.set_ylabel("relMSE vs 2x1024-spp Cycles reference")
ax.set_title("One-bounce indirect light: error against time")
ax.grid(True, which="both", alpha=0.3)
ax.legend(fontsize=6, loc="upper right")
fig.tight_layout()
out = os.path.join(root, "docs", "img", "curve.png")
fig.savefig(out, dpi=110)
print("wrote", out)
