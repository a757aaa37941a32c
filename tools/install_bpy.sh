#!/usr/bin/env bash
# Install the newest `bpy` (Blender as a Python module) that PyPI offers for
# $BPY_PYTHON (default: the python3 on PATH, e.g. the pyenv build or a venv;
# Debian's /usr/bin/python3 is for Debian's Blender 3.4), plus numpy,
# pytest and OpenImageIO (the EXR reader) for the tests it runs. BPY_VERSION pins a release ("4.2.23", "4.2.*").
#
# The interpreter is named by BPY_PYTHON, never by a PIP_* variable: pip
# reads every PIP_<OPTION> environment variable as its own option. pip runs
# through tools/pip_install.sh, which keeps pip's own --python option out
# of its environment (see there).
set -euo pipefail
BPY_PYTHON=${BPY_PYTHON:-python3}
spec=bpy
[ -n "${BPY_VERSION:-}" ] && spec="bpy==$BPY_VERSION"
if "$BPY_PYTHON" -c 'import bpy, numpy, pytest, OpenImageIO' >/dev/null 2>&1; then exit 0; fi
where=$("$BPY_PYTHON" -c 'import sys; print(sys.executable, "(Python %d.%d)" % sys.version_info[:2])') || {
  echo "install_bpy.sh: cannot run '$BPY_PYTHON'" >&2; exit 1; }
echo "install_bpy.sh: installing $spec, numpy, pytest, OpenImageIO into $where (a large wheel: a few minutes)" >&2
# OpenImageIO reads the tests' EXRs (tests/blender/addon/exr_read.py); 3.1 and
# later require numpy >= 2, which bpy (numpy < 2) does not allow.
# (tools/pip_install.sh: pip without a --python option from the environment, its output in a log)
log="${TMPDIR:-/tmp}/install_bpy.$$.pip.log"
"$(dirname "$0")/pip_install.sh" "$BPY_PYTHON" "$log" "$spec" numpy pytest "OpenImageIO<3.1" || {
  echo "install_bpy.sh: could not install $spec into $where (pip's output: $log)" >&2; exit 1; }
rm -f "$log"
"$BPY_PYTHON" -c 'import bpy; print("install_bpy.sh: bpy", bpy.app.version_string)' 2>/dev/null | tail -1 >&2
