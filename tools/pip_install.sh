#!/usr/bin/env bash
# pip-install packages into a given Python, quietly, its output in a log:
#   tools/pip_install.sh PYTHON LOG PACKAGE...
# pip reads PIP_PYTHON from the environment as its own --python option
# (pip >= 22.3): with PIP_PYTHON=python3 exported, as some setups do, pip
# run from a venv's Python fails with "Could not locate Python interpreter
# python3" and installs nothing. So pip runs without it. On failure: exit 1
# and pip's last line on stderr.
set -uo pipefail
if [ $# -lt 3 ]; then
  echo "usage: tools/pip_install.sh PYTHON LOG PACKAGE..." >&2
  exit 2
fi
py=$1 log=$2
shift 2
if env -u PIP_PYTHON "$py" -m pip install -q --disable-pip-version-check "$@" >"$log" 2>&1; then
  exit 0
fi
echo "pip failed: $(tail -1 "$log")" >&2
exit 1
