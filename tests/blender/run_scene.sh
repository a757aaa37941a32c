#!/usr/bin/env bash
# G-buffer vs Cycles (tests/blender/gbuffer_ref.py): in Debian's Blender 3.4
# (the reference) and, if the pip `bpy` module imports in $BPY_PYTHON, in
# that newest Blender too. Cycles renders are cached under
# build/blender/gbuffer*/cycles_<hash of script + Blender version>/.
# Prints the comparison tables and ends with "N passed, N failed" (both
# runs summed); exits non-zero on any failure.
set -uo pipefail
cd "$(dirname "$0")/../.."
BLENDER=${BLENDER:-blender}
BPY_PYTHON=${BPY_PYTHON:-python3}
passed=0; failed=0; rc=0

run() {  # run <name> <out dir> <command...>
  local name=$1 out=$2; shift 2
  mkdir -p "$out"
  rm -f "$out/summary.txt"
  "$@" >"$out/run.log" 2>&1
  local r=$?
  echo "== $name"
  if [ -f "$out/summary.txt" ]; then
    sed '$d' "$out/summary.txt"
    local last p f
    last=$(tail -1 "$out/summary.txt")
    p=$(echo "$last" | grep -Eo '^[0-9]+'); f=$(echo "$last" | grep -Eo '[0-9]+ failed' | grep -Eo '[0-9]+')
    passed=$((passed + ${p:-0})); failed=$((failed + ${f:-1}))
  else
    tail -20 "$out/run.log"
    failed=$((failed + 1)); [ $r -eq 0 ] && r=1
  fi
  if [ $r -ne 0 ]; then echo "(log: $out/run.log)"; rc=1; fi
}

if ! make --no-print-directory build/libvsgl.so >/dev/null; then
  echo "run_scene.sh: building libvsgl failed"; echo "0 passed, 1 failed"; exit 1
fi
if command -v "$BLENDER" >/dev/null 2>&1; then
  run "Blender $("$BLENDER" --version 2>/dev/null | head -1 | awk '{print $2}') (Debian)" build/blender/gbuffer \
    "$BLENDER" -b --factory-startup --python-exit-code 1 --python tests/blender/gbuffer_ref.py -- \
    --lib build/libvsgl.so --out build/blender/gbuffer
else
  echo "run_scene.sh: $BLENDER not found; Blender 3.4 G-buffer check skipped"
fi
if "$BPY_PYTHON" -c "import bpy" >/dev/null 2>&1; then
  run "pip bpy in $BPY_PYTHON" build/blender/gbuffer_bpy \
    "$BPY_PYTHON" tests/blender/gbuffer_ref.py -- --lib build/libvsgl.so --out build/blender/gbuffer_bpy
else
  echo "run_scene.sh: bpy not importable in $BPY_PYTHON; newest-Blender G-buffer check skipped"
fi
echo "$passed passed, $failed failed"
exit $rc
