#!/usr/bin/env bash
# Quality suite (issue 9) at test size (80x60): the bundled scenes of tests/quality/scenes.py.
#  1. in Blender 3.4: the pure-Python scene builder against the bpy-built scene, and the Cycles
#     one-bounce references (two seeds x 1024 spp), rendered only when missing (cached in
#     build/quality/refs/ by a hash of scene, size, seed, Blender version and rendering code);
#  2. tests/quality/check.py: the metrics against hand-computed cases, the references' sanity,
#     each scene's feature, the brute force within 6 % of Cycles per pass; then the presets'
#     numbers (INFO lines; VSGL_QUALITY_FRAMES animation frames, default 6 here) and issue 9's
#     acceptance criteria as INFO (not failures yet). Report: build/quality/check_test.md.
# Python: $BPY_PYTHON if it imports numpy, else $PYTHON; flip-evaluator is pip-installed into it when
# missing (FLIP skipped, with the reason printed, if that fails, e.g. Debian's externally managed Python).
# Ends with "N passed, N failed"; exits non-zero on failure.
set -uo pipefail
cd "$(dirname "$0")/../.."
BLENDER=${BLENDER:-blender}
OUT=build/quality
if ! command -v "$BLENDER" >/dev/null 2>&1; then
  echo "run_quality.sh: $BLENDER not found; check skipped"
  echo "0 passed, 0 failed"
  exit 0
fi
make --no-print-directory build/libvsgl.so >/dev/null || { echo "building libvsgl failed"; echo "0 passed, 1 failed"; exit 1; }
mkdir -p "$OUT/refs"
"$BLENDER" -b --factory-startup --python-exit-code 1 --python tests/quality/render_refs.py -- \
  --check-builder --size test --out "$OUT/refs" >"$OUT/blender_quality.log" 2>&1
rc=$?
grep -E "^(PASS|FAIL|rendered)" "$OUT/blender_quality.log"
p1=$(grep -Eo '^[0-9]+ passed' "$OUT/blender_quality.log" | tail -1 | grep -Eo '[0-9]+' || true)
f1=$(grep -Eo '[0-9]+ failed' "$OUT/blender_quality.log" | tail -1 | grep -Eo '[0-9]+' || true)
if [ -z "$p1" ]; then
  tail -20 "$OUT/blender_quality.log"; p1=0; f1=1; [ $rc -eq 0 ] && rc=1
fi
[ $rc -ne 0 ] && echo "(Blender log: $OUT/blender_quality.log)"
PY=${BPY_PYTHON:-python3}
"$PY" -c "import numpy" >/dev/null 2>&1 || PY=${PYTHON:-/usr/bin/python3}
# FLIP (the perceptual error) needs the reference implementation from PyPI.
if ! "$PY" -c "import flip_evaluator" >/dev/null 2>&1; then
  echo "run_quality.sh: installing flip-evaluator into $("$PY" -c 'import sys; print(sys.executable)')"
  tools/pip_install.sh "$PY" "$OUT/pip_flip.log" flip-evaluator 2>"$OUT/pip_flip.err" ||
    echo "run_quality.sh: could not install flip-evaluator ($(cat "$OUT/pip_flip.err")): FLIP is skipped"
fi
VSGL_QUALITY_FRAMES=${VSGL_QUALITY_FRAMES:-6} "$PY" tests/quality/check.py --out "$OUT" >"$OUT/check.log" 2>&1
rc2=$?
grep -E "^(PASS|FAIL|SKIP|INFO|\(report)" "$OUT/check.log"
p2=$(grep -Eo '^[0-9]+ passed' "$OUT/check.log" | tail -1 | grep -Eo '[0-9]+' || true)
f2=$(grep -Eo '[0-9]+ failed' "$OUT/check.log" | tail -1 | grep -Eo '[0-9]+' || true)
if [ -z "$p2" ]; then
  tail -20 "$OUT/check.log"; p2=0; f2=1; [ $rc2 -eq 0 ] && rc2=1
fi
[ $rc2 -ne 0 ] && { echo "(log: $OUT/check.log)"; rc=1; }
echo "$((p1 + p2)) passed, $((f1 + f2)) failed"
exit $rc
