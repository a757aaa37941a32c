#!/usr/bin/env bash
# RSM light units (SUITE=lights, default) or the brute-force gather (SUITE=gather) vs Cycles' DiffDir (tests/blender/cycles_ref.py --suite lights) in Blender 3.4;
# then the same suite in the pip `bpy` module (newest Blender) if $BPY_PYTHON imports it.
# Cycles renders are cached in build/blender/cycles/cycles/ (keyed by a hash of the script, case, version).
# Prints one line per light and ends with "N passed, N failed"; exits non-zero on failure.
set -uo pipefail
cd "$(dirname "$0")/../.."
BLENDER=${BLENDER:-blender}
OUT=build/blender/cycles
SUITE=${SUITE:-lights}
if ! command -v "$BLENDER" >/dev/null 2>&1; then
  echo "run_$SUITE.sh: $BLENDER not found; check skipped"
  echo "0 passed, 0 failed"
  exit 0
fi
make --no-print-directory build/libvsgl.so >/dev/null || { echo "building libvsgl failed"; echo "0 passed, 1 failed"; exit 1; }
mkdir -p "$OUT"
rm -f "$OUT/summary_$SUITE.txt"
"$BLENDER" -b --factory-startup --python-exit-code 1 --python tests/blender/cycles_ref.py -- \
  --suite "$SUITE" --lib build/libvsgl.so --out "$OUT" >"$OUT/blender_$SUITE.log" 2>&1
rc=$?
grep -E "^(PASS|FAIL|gather res)" "$OUT/blender_$SUITE.log"
if [ -f "$OUT/summary_$SUITE.txt" ]; then
  echo "(report: $OUT/report_$SUITE.md)"
  cat "$OUT/summary_$SUITE.txt"
else
  tail -20 "$OUT/blender_$SUITE.log"
  echo "0 passed, 1 failed"
  [ $rc -eq 0 ] && rc=1
fi
[ $rc -ne 0 ] && echo "(Blender log: $OUT/blender_$SUITE.log)"
BPY_PYTHON=${BPY_PYTHON:-python3}
if "$BPY_PYTHON" -c "import bpy, numpy" >/dev/null 2>&1; then
  # Blender 4.x+ semantics (lights, GGX shadowing and multiple scattering, DiffCol) against that Blender's Cycles
  OUT5=build/blender/cycles_bpy
  mkdir -p "$OUT5"
  rm -f "$OUT5/summary_$SUITE.txt"
  "$BPY_PYTHON" tests/blender/cycles_ref.py -- --suite "$SUITE" --lib build/libvsgl.so --out "$OUT5" >"$OUT5/bpy_$SUITE.log" 2>&1
  rc5=$?
  ver=$("$BPY_PYTHON" -c 'import bpy; print(bpy.app.version_string)' 2>/dev/null | tail -1)
  echo "== $SUITE in pip bpy $ver"
  grep -E "^(PASS|FAIL|SKIP|gather res)" "$OUT5/bpy_$SUITE.log"
  p1=$(grep -Eo '^[0-9]+ passed' "$OUT/summary_$SUITE.txt" 2>/dev/null | grep -Eo '[0-9]+' || echo 0)
  f1=$(grep -Eo '[0-9]+ failed' "$OUT/summary_$SUITE.txt" 2>/dev/null | grep -Eo '[0-9]+' || echo 1)
  if [ -f "$OUT5/summary_$SUITE.txt" ]; then
    p5=$(grep -Eo '^[0-9]+ passed' "$OUT5/summary_$SUITE.txt" | grep -Eo '[0-9]+'); f5=$(grep -Eo '[0-9]+ failed' "$OUT5/summary_$SUITE.txt" | grep -Eo '[0-9]+')
    echo "(bpy $ver: ${p5} passed, ${f5} failed)"
  else
    tail -20 "$OUT5/bpy_$SUITE.log"; p5=0; f5=1; [ $rc5 -eq 0 ] && rc5=1
  fi
  [ $rc5 -ne 0 ] && { echo "(log: $OUT5/bpy_$SUITE.log)"; rc=1; }
  echo "$((p1 + p5)) passed, $((f1 + f5)) failed"
else
  echo "run_$SUITE.sh: bpy not importable in $BPY_PYTHON; the newest Blender's check skipped"
fi
exit $rc
