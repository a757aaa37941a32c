#!/usr/bin/env bash
# make demo: demo scene -> indirect-light AOV (libvsgl, via the add-on installed
# from build/vsgl_indirect.zip) -> Cycles direct light + AOV composited.
# Then a Cycles one-bounce reference at REF_SPP samples for comparison.
# Writes out/demo/: demo.blend, indirect.exr, composite.exr, direct.exr,
# reference.exr, preview.png (direct | AOV | composite | Cycles
# reference | error, each labelled with its time) and timings.txt.
set -euo pipefail
cd "$(dirname "$0")/.."
BLENDER=${BLENDER:-blender}
PY=${PYTHON:-/usr/bin/python3}
OUT=out/demo
REF_SPP=${REF_SPP:-16}     # samples of the Cycles one-bounce reference
DIRECT_SPP=${DIRECT_SPP:-8}  # samples of the direct-light render the AOV is added to
PRESET=${PRESET:-BALANCED}   # the add-on's preset (PREVIEW, BALANCED, QUALITY)
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
"$BLENDER" -b --factory-startup --python-exit-code 1 --python tools/make_demo_scene.py -- "$OUT/demo.blend" 960 540 "$DIRECT_SPP" "$PRESET" \
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

echo "demo: Cycles one-bounce reference ($REF_SPP spp) for comparison"
t2=$(date +%s.%N)
"$BLENDER" -b "$OUT/demo.blend" --python-exit-code 1 --python tools/demo_reference.py -- "$REF_SPP" \
  > "$OUT/reference.log" 2>&1 || { tail -20 "$OUT/reference.log"; exit 1; }
t3=$(date +%s.%N)

"$PY" tools/demo_preview.py "$OUT" "$t0" "$t1" "$t2" "$t3" "$t_start" "$REF_SPP"
echo "demo: wrote $OUT/demo.blend, indirect.exr, composite.exr, direct.exr, reference.exr, preview.png, timings.txt"
