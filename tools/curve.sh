#!/usr/bin/env bash
# The product curve (docs/references.md §6): relMSE against time for the library's
# presets and knobs next to Cycles at 1..256 spp, on the gather room of
# tests/blender/cycles_ref.py, against a two-seed 1024-spp Cycles reference.
# Writes build/blender/cycles/report_curve.md (docs/accuracy.md quotes it).
set -euo pipefail
cd "$(dirname "$0")/.."
tools/deps.sh test
make --no-print-directory build/libvsgl.so >/dev/null
OUT=build/blender/cycles
mkdir -p "$OUT"
blender -b --factory-startup --python-exit-code 1 --python tests/blender/cycles_ref.py -- \
  --suite curve --lib build/libvsgl.so --out "$OUT" >"$OUT/blender_curve.log" 2>&1 || {
  tail -30 "$OUT/blender_curve.log"; exit 1; }
grep "^curve:" "$OUT/blender_curve.log"
echo "(report: $OUT/report_curve.md)"
if python3 -c "import matplotlib" >/dev/null 2>&1; then python3 tools/plot_curve.py; fi
