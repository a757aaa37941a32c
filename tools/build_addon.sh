#!/usr/bin/env bash
# Package the Blender add-on: build/vsgl_indirect.zip with the Python package
# and the built library in vsgl_indirect/lib/libvsgl.so (where libvsgl.py looks
# first). Install it with Edit > Preferences > Add-ons > Install (3.4+) or
# `blender --command extension install-file` (4.2+, blender_manifest.toml).
set -euo pipefail
cd "$(dirname "$0")/.."
lib=build/libvsgl.so
[ -f "$lib" ] || { echo "build_addon.sh: $lib is missing; run 'make' first" >&2; exit 1; }
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/vsgl_indirect/lib"
for f in addon/vsgl_indirect/*.py addon/vsgl_indirect/blender_manifest.toml; do
  cp "$f" "$stage/vsgl_indirect/"
done
cp "$lib" "$stage/vsgl_indirect/lib/libvsgl.so"
out=$(pwd)/build/vsgl_indirect.zip
rm -f "$out"
python3 - "$stage" "$out" <<'PY'
import os, sys, zipfile
stage, out = sys.argv[1], sys.argv[2]
with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as z:
    for root, dirs, files in os.walk(stage):
        dirs.sort()
        for name in sorted(files):
            full = os.path.join(root, name)
            z.write(full, os.path.relpath(full, stage))
PY
echo "build_addon.sh: wrote build/vsgl_indirect.zip ($(du -h "$out" | cut -f1))"
