#!/usr/bin/env bash
# Add-on tests (tests/blender/addon) on Debian's Blender 3.4 binary, on the
# pip `bpy` module (the newest for $BPY_PYTHON) and on pip bpy 4.2 LTS (in
# build/venv-bpy42). Ends with "N passed, N failed".
set -uo pipefail
cd "$(dirname "$0")/../.."
BPY_PYTHON=${BPY_PYTHON:-python3}
BLENDER=${BLENDER:-blender}
export PYTHONDONTWRITEBYTECODE=1
pass=0; fail=0; status=0
log=$(mktemp)

tally() {  # tally <label> <exit code>: add pytest's counts from $log
  local p f e
  p=$(grep -Eo '[0-9]+ passed' "$log" | tail -1 | grep -Eo '[0-9]+' || true)
  f=$(grep -Eo '[0-9]+ failed' "$log" | tail -1 | grep -Eo '[0-9]+' || true)
  e=$(grep -Eo '[0-9]+ errors?' "$log" | tail -1 | grep -Eo '[0-9]+' || true)
  p=${p:-0}; f=$(( ${f:-0} + ${e:-0} ))
  if [ "$2" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
  echo "-- $1: $p passed, $f failed (exit $2)"
  pass=$((pass + p)); fail=$((fail + f)); [ "$2" -ne 0 ] && status=1
  return 0
}

if command -v "$BLENDER" >/dev/null 2>&1; then
  echo "== add-on tests in $("$BLENDER" --version 2>/dev/null | head -1)"
  "$BLENDER" -b --factory-startup --python-exit-code 1 \
    --python tests/blender/pytest_in_blender.py -- -q -rs tests/blender/addon "$@" 2>&1 | tee "$log"
  tally "Blender binary" "${PIPESTATUS[0]}"
else
  echo "run_addon.sh: no '$BLENDER' binary; install Debian's blender (tools/deps.sh test)"; fail=$((fail + 1)); status=1
fi

if "$BPY_PYTHON" -c 'import bpy, numpy, pytest, OpenImageIO' >/dev/null 2>&1 || tools/install_bpy.sh; then
  echo "== add-on tests in bpy $("$BPY_PYTHON" -c 'import bpy; print(bpy.app.version_string)' 2>/dev/null | tail -1)"
  "$BPY_PYTHON" -m pytest -q -rs -p no:cacheprovider tests/blender/addon "$@" 2>&1 | tee "$log"
  tally "pip bpy" "${PIPESTATUS[0]}"
else
  echo "run_addon.sh: cannot import bpy in $BPY_PYTHON (tools/install_bpy.sh failed)"; fail=$((fail + 1)); status=1
fi
# Blender 4.2 LTS as the pip module (bpy 4.2.x wheels exist for Python 3.11
# only), in its own venv under build/ made from the python3 on PATH.
# BPY42=0 skips it; a Python the 4.2 wheels do not support skips it with
# the reason printed.
if [ "${BPY42:-1}" != 0 ]; then
  venv=build/venv-bpy42
  py=$(command -v python3)
  pyver=$("$py" -c 'import sys; print("%d.%d" % sys.version_info[:2])' 2>/dev/null)
  if [ "$pyver" != "3.11" ]; then
    echo "== add-on tests in bpy 4.2 LTS: SKIP (its wheels need Python 3.11; python3 on PATH is $pyver)"
  else
    [ -x "$venv/bin/python3" ] || "$py" -m venv "$venv" >/dev/null 2>&1
    if BPY_PYTHON="$venv/bin/python3" BPY_VERSION="4.2.*" tools/install_bpy.sh; then
      echo "== add-on tests in bpy $("$venv/bin/python3" -c 'import bpy; print(bpy.app.version_string)' 2>/dev/null | tail -1)"
      "$venv/bin/python3" -m pytest -q -rs -p no:cacheprovider tests/blender/addon "$@" 2>&1 | tee "$log"
      tally "pip bpy 4.2" "${PIPESTATUS[0]}"
    else
      echo "run_addon.sh: could not install bpy 4.2 into $venv"; fail=$((fail + 1)); status=1
    fi
  fi
fi
rm -f "$log"
echo "$pass passed, $fail failed"
exit $status
