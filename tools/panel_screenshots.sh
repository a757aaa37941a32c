#!/usr/bin/env bash
# Screenshots of the add-on's panels, compositor setup and preview in
# Blender's real UI under Xvfb (software OpenGL), written to docs/img/
# (or $1), plus the preview-to-editor checks of tools/panel_screenshots.py.
# Needs: blender, xvfb-run (apt: blender xvfb libgl1-mesa-dri).
set -euo pipefail
cd "$(dirname "$0")/.."
out=$(realpath -m "${1:-docs/img}")
BLENDER=${BLENDER:-blender}
command -v xvfb-run >/dev/null || { echo "panel_screenshots.sh: needs xvfb-run (apt-get install xvfb)"; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# A file on the command line: no splash screen over the UI.
"$BLENDER" -b --factory-startup --python-expr \
  "import bpy; bpy.ops.wm.save_as_mainfile(filepath='$tmp/start.blend')" >/dev/null 2>&1
LIBGL_ALWAYS_SOFTWARE=1 timeout 300 xvfb-run -a -s "-screen 0 ${VSGL_SCREEN:-820x1250x24}" \
  "$BLENDER" --factory-startup "$tmp/start.blend" --python tools/panel_screenshots.py -- "$out" 2>&1 |
  grep -E "^VSGL-UI|Error|Traceback|^  File" || true
ls "$out"/panel*.png "$out"/compositor.png "$out"/preview*.png 2>/dev/null
