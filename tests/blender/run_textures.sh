#!/usr/bin/env bash
# Textured materials through the add-on's export vs Cycles
# (tests/blender/texture_ref.py) in Debian's Blender 3.4: DiffCol per pixel,
# the colour a textured wall bleeds, an emissive panel's light. Cycles
# renders are cached under build/blender/textures/cycles/. Ends with
# "N passed, N failed"; exits non-zero on any failure.
set -uo pipefail
cd "$(dirname "$0")/../.."
BLENDER=${BLENDER:-blender}
out=build/blender/textures
if ! make --no-print-directory build/libvsgl.so >/dev/null; then
  echo "run_textures.sh: building libvsgl failed"; echo "0 passed, 1 failed"; exit 1
fi
if ! command -v "$BLENDER" >/dev/null 2>&1; then
  echo "run_textures.sh: $BLENDER not found (tools/deps.sh test installs it)"; echo "0 passed, 1 failed"; exit 1
fi
mkdir -p "$out"
rm -f "$out/summary.txt"
"$BLENDER" -b --factory-startup --python-exit-code 1 --python tests/blender/texture_ref.py -- \
  --lib build/libvsgl.so --out "$out" >"$out/run.log" 2>&1
rc=$?
if [ -f "$out/summary.txt" ]; then
  cat "$out/summary.txt"
else
  tail -20 "$out/run.log"; echo "0 passed, 1 failed"; rc=1
fi
[ $rc -ne 0 ] && echo "(log: $out/run.log)"
exit $rc
