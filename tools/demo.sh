#!/usr/bin/env bash
# make demo: demo scene -> indirect-light AOV (libvsgl, via the add-on installed
# from build/vsgl_indirect.zip) -> Cycles direct light + AOV composited.
# Writes out/demo/: demo.blend, indirect.exr, composite.exr, direct.exr,
# preview.png (direct | AOV | composite) and timings.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
BLENDER=${BLENDER:-blender}
PY=${PYTHON:-/usr/bin/python3}
OUT=out/demo
t_start=$(date +%s.%N)

command -v "$BLENDER" >/dev/null || { echo "demo: no '$BLENDER' binary (apt-get install blender)" >&2; exit 1; }
make --no-print-directory -s all >/dev/null
make --no-print-directory -s addon >/dev/null

# Is the C renderer there? (vsgl_render and everything it calls.)
missing=$("$PY" - <<'PY'
import sys
sys.path.insert(0, "addon/vsgl_indirect")
try:
    import libvsgl
    lib = libvsgl.library()
except Exception as e:
    print(e); sys.exit(0)
if not lib.has("vsgl_render"):
    print("vsgl_render is not built yet (the C renderer is missing from %s)" % lib.path)
elif getattr(lib, "undefined", ()):
    print("the library build is incomplete: %s undefined" % ", ".join(lib.undefined))
PY
)
if [ -n "$missing" ]; then
  echo "demo: cannot compute the indirect AOV: $missing" >&2
  echo "demo: the add-on, export and compositor wiring are ready; what is missing is a loadable" >&2
  echo "demo: libvsgl with a working vsgl_render (build/libvsgl.so from 'make'; csrc/src/shade)." >&2
  exit 1
fi

rm -rf "$OUT"; mkdir -p "$OUT/.scripts/addons"
"$PY" -c "import zipfile; zipfile.ZipFile('build/vsgl_indirect.zip').extractall('$OUT/.scripts/addons')"

echo "demo: building the scene"
"$BLENDER" -b --factory-startup --python-exit-code 1 --python tools/make_demo_scene.py -- "$OUT/demo.blend" \
  > "$OUT/make_scene.log" 2>&1 || { cat "$OUT/make_scene.log"; exit 1; }

echo "demo: rendering (Cycles direct light + VSGL indirect AOV in the compositor)"
t0=$(date +%s.%N)
BLENDER_USER_SCRIPTS="$PWD/$OUT/.scripts" "$BLENDER" -b "$OUT/demo.blend" --addons vsgl_indirect -f 1 \
  > "$OUT/render.log" 2>&1 || { cat "$OUT/render.log"; exit 1; }
t1=$(date +%s.%N)
grep -E "^VSGL" "$OUT/render.log" || true
if grep -q "^VSGL ERROR" "$OUT/render.log"; then echo "demo: the add-on reported an error (above)" >&2; exit 1; fi

cp "$OUT/aov/indirect_0001.exr" "$OUT/indirect.exr"
cp "$OUT/composite_0001.exr" "$OUT/composite.exr"
cp "$OUT/direct/direct_0001.exr" "$OUT/direct.exr"

"$PY" - "$OUT" "$t0" "$t1" "$t_start" <<'PY'
import re, struct, sys, time, zlib
sys.path.insert(0, "tests/blender/addon")
import numpy as np
from exr_read import read_exr
out, t0, t1, ts = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])

def rgb(path, prefix):
    ch, _ = read_exr(path)
    keys = {k.rsplit(".", 1)[-1]: k for k in ch if k.startswith(prefix) or prefix == ""}
    return np.dstack([ch[keys[c]] for c in "RGB"])

direct = rgb(out + "/direct.exr", "")
aov = rgb(out + "/indirect.exr", "VSGL.Combined.")
comp = rgb(out + "/composite.exr", "")
assert direct.shape == aov.shape == comp.shape, (direct.shape, aov.shape, comp.shape)
err = np.abs(comp - (direct + aov)).max()
assert err < 1e-2, "composite != direct + AOV (max error %g)" % err
assert aov.max() > 0, "the AOV is black"

def srgb(x):
    x = np.clip(x, 0, None)
    y = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    return (np.clip(y, 0, 1) * 255 + 0.5).astype(np.uint8)

gap = np.full((direct.shape[0], 4, 3), 255, np.uint8)
img = np.concatenate([srgb(direct), gap, srgb(aov), gap, srgb(comp)], axis=1)
h, w, _ = img.shape
raw = b"".join(b"\0" + img[y].tobytes() for y in range(h))
def chunk(t, d):
    c = struct.pack(">I", len(d)) + t + d
    return c + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) \
    + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
open(out + "/preview.png", "wb").write(png)

log = open(out + "/render.log").read()
m = re.search(r"export ([\d.]+)s, render ([\d.]+)s, write ([\d.]+)s", log)
cyc = re.findall(r"Time: (\d+):([\d.]+)", log)
cycles = 60 * float(cyc[-1][0]) + float(cyc[-1][1]) if cyc else float("nan")
line = ("timings: vsgl export %ss, vsgl render %ss, exr write %ss | blender -f 1 total %.2fs "
        "(Cycles+compositor %.2fs) | demo %.1fs | composite = direct + AOV (max err %.1e)"
        % (m.group(1), m.group(2), m.group(3), t1 - t0, cycles, time.time() - ts, err))
open(out + "/timings.txt", "w").write(line + "\n")
print(line)
PY
echo "demo: wrote $OUT/demo.blend, indirect.exr, composite.exr, direct.exr, preview.png, timings.txt"
