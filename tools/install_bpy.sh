#!/usr/bin/env bash
# Install the newest `bpy` (Blender as a Python module) that PyPI offers for
# the python3 on PATH (the pyenv build; Debian's /usr/bin/python3 is for
# Debian's Blender 3.4), plus numpy and pytest for the tests it runs.
set -euo pipefail
PIP_PYTHON=${PIP_PYTHON:-python3}
if "$PIP_PYTHON" -c 'import bpy, numpy, pytest' >/dev/null 2>&1; then exit 0; fi
echo "install_bpy.sh: installing bpy, numpy, pytest into $($PIP_PYTHON -c 'import sys; print(sys.executable)')" >&2
"$PIP_PYTHON" -m pip install -q --disable-pip-version-check bpy numpy pytest
