#!/usr/bin/env bash
# Screenshots and timings of the live viewport preview in Blender's real UI
# (under Xvfb): docs/img/live/live_N.png and live.txt. Usage: tools/live_screenshot.sh [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-docs/img/live}
mkdir -p "$out"
make --no-print-directory build/libvsgl.so >/dev/null
trap 'rm -f "$out/live.blend" "$out/live.blend1"' EXIT
blender -b --factory-startup --python tools/live_screenshot.py -- "$out" >/dev/null
xvfb-run -a -s "-screen 0 1280x800x24" blender "$out/live.blend" --python tools/live_screenshot.py -- "$out" \
  | grep '^step'
