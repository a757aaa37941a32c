#!/usr/bin/env bash
# G-buffer vs Cycles (tests/blender/gbuffer_ref.py) in Blender 3.4.
# Cycles renders are cached in build/blender/gbuffer/cycles_<hash of script+version>/.
# Prints the comparison table and ends with "N passed, N failed"; exits non-zero on failure.
set -uo pipefail
cd "$(dirname "$0")/../.."
BLENDER=${BLENDER:-blender}
OUT=build/blender/gbuffer
if ! command -v "$BLENDER" >/dev/null 2>&1; then
  echo "run_scene.sh: $BLENDER not found; G-buffer check skipped"
  echo "0 passed, 0 failed"
  exit 0
fi
make --no-print-directory build/libvsgl.so >/dev/null || { echo "run_scene.sh: building libvsgl failed"; echo "0 passed, 1 failed"; exit 1; }
mkdir -p "$OUT"
rm -f "$OUT/summary.txt"
"$BLENDER" -b --factory-startup --python-exit-code 1 --python tests/blender/gbuffer_ref.py -- \
  --lib build/libvsgl.so --out "$OUT" >"$OUT/blender.log" 2>&1
rc=$?
if [ -f "$OUT/summary.txt" ]; then
  cat "$OUT/summary.txt"
else
  tail -20 "$OUT/blender.log"
  echo "0 passed, 1 failed"
  [ $rc -eq 0 ] && rc=1
fi
[ $rc -ne 0 ] && echo "(Blender log: $OUT/blender.log)"
exit $rc
