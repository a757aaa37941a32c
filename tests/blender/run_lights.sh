#!/usr/bin/env bash
# RSM light units (SUITE=lights, default) or the brute-force gather (SUITE=gather) vs Cycles' DiffDir (tests/blender/cycles_ref.py --suite lights) in Blender 3.4.
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
exit $rc
