#!/usr/bin/env bash
# Package the Blender add-on: build/vsgl_indirect.zip with the Python package
# and the built library in vsgl_indirect/lib/libvsgl.so (where libvsgl.py looks
# first), self-contained: the libraries it links against that a Linux machine
# with Blender may lack (Embree 3, OpenEXR Core, oneTBB, libdeflate) are copied beside it,
# found through its $ORIGIN rpath (Makefile). Not copied: glibc, libstdc++,
# libgcc_s and zlib, which every Linux that runs Blender has (the zip needs
# x86-64 Linux with glibc >= 2.34 and libstdc++ of GCC >= 12: Debian 12,
# Ubuntu 22.04, RHEL 9 or newer; docs/addon.md). Install it with Edit >
# Preferences > Add-ons > Install (3.4+) or `blender --command extension
# install-file` (4.2+, blender_manifest.toml).
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
# Every dependency ldd resolves, under its soname, but the system's own.
ldd "$lib" | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}' | while read -r soname path; do
  case "$soname" in
    libc.so*|libm.so*|libpthread.so*|libdl.so*|librt.so*|ld-linux*|libstdc++.so*|libgcc_s.so*|libz.so*) continue ;;
  esac
  cp -L "$path" "$stage/vsgl_indirect/lib/$soname"
  echo "$soname" >>"$stage/vsgl_indirect/lib/BUNDLED"
done
cat >"$stage/vsgl_indirect/lib/README" <<'TXT'
libvsgl.so and the libraries it links against, found through its $ORIGIN rpath:
libembree3 (Intel Embree 3, Apache-2.0), libOpenEXRCore (OpenEXR, BSD-3-Clause),
libtbb (oneTBB, Apache-2.0), libdeflate (MIT), copied from Debian 12. Needs x86-64 Linux with
glibc >= 2.34 and libstdc++ from GCC >= 12.
TXT
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
