#!/usr/bin/env bash
# Check (and, as root, install) the Debian 12 packages a make target needs.
# Usage: tools/deps.sh build|test|asan|demo|bench|lint
# Without root it prints the exact apt-get line and exits 1.
set -euo pipefail

build_pkgs="gcc make pkg-config libembree-dev libopenexr-dev libdeflate-dev"
python_pkgs="python3 python3-numpy python3-pytest"
case "${1:-build}" in
  build) pkgs="$build_pkgs" ;;
  # xvfb, xauth (xvfb-run) and Mesa's software OpenGL: the add-on's panel and viewport tests
  # start Blender's real UI on a virtual screen; without them they skip.
  test)  pkgs="$build_pkgs $python_pkgs blender openimageio-tools python3-openimageio xvfb xauth libgl1-mesa-dri" ;;
  asan)  pkgs="$build_pkgs clang libclang-rt-14-dev" ;;
  demo)  pkgs="$build_pkgs $python_pkgs blender" ;;
  bench) pkgs="$build_pkgs $python_pkgs" ;;
  lint)  pkgs="flake8 cppcheck" ;;
  *) echo "deps.sh: unknown target '$1'" >&2; exit 2 ;;
esac

missing=""
for p in $pkgs; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  case "$status" in
    *"install ok installed"*) ;;
    *) missing="$missing $p" ;;
  esac
done
[ -z "$missing" ] && exit 0

if [ "$(id -u)" = 0 ]; then
  echo "deps.sh: installing missing Debian packages:$missing" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -q >&2
  # shellcheck disable=SC2086
  apt-get install -y -q $missing >&2
else
  echo "deps.sh: missing Debian packages:$missing" >&2
  echo "deps.sh: install them with:  sudo apt-get install -y$missing" >&2
  exit 1
fi
