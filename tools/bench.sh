#!/usr/bin/env bash
# make bench: speed benchmarks, reported as ratios measured in the same run.
# Builds the benchmark programs against the library's objects (internal
# stages are timed directly) and runs them. BENCH_QUICK=1 shrinks sizes.
set -euo pipefail
cd "$(dirname "$0")/.."
# the objects of the current sources (a build dir may still hold those of moved files)
objs=$(ls csrc/src/*/*.c | sed 's|^|build/obj/|; s|\.c$|.o|')
flags="-O2 -march=native -Itests/c -Icsrc/include -Icsrc/src"
libs="-lembree3 -lOpenEXRCore-3_1 -ldeflate -lpthread -lm"
# BENCH_DIR: where the programs go; BENCH_BUILD_ONLY=1: build them and stop
# (tests/tools/run_tools.sh checks that they still build)
bin=${BENCH_DIR:-build/bench}
mkdir -p "$bin"
cc $flags tools/bench/bench_shade.c $objs $libs -o "$bin/bench_shade"
cc $flags tools/bench/bench_kernel.c $objs $libs -o "$bin/bench_kernel"
if [ -f tools/bench_gbuffer.c ]; then cc $flags tools/bench_gbuffer.c $objs $libs -o "$bin/bench_gbuffer"; fi
# not a benchmark: the per-VSGL probe of tools/probe_frames.py, built here against the same objects
cc $flags tools/probe_vsgls.c $objs $libs -o "$bin/probe_vsgls"
if [ "${BENCH_BUILD_ONLY:-0}" = 1 ]; then exit 0; fi
if [ "${BENCH_QUICK:-0}" = 1 ]; then size="480 270 64 1"; kreps=100; else size="1920 1080 256 3"; kreps=3000; fi
echo "== machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "== shading: vectorised kernel vs scalar build of the same code (same run)"
# shellcheck disable=SC2086
"$bin/bench_shade" $size
echo "== the kernel alone"
"$bin/bench_kernel" $kreps
if [ -x "$bin/bench_gbuffer" ]; then
  echo "== scene build and G-buffer"
  "$bin/bench_gbuffer" ${BENCH_GBUFFER_ARGS:-}
fi
echo "== live viewport preview (issue 12 targets), headless"
py=${BPY_PYTHON:-python3}
if "$py" -c 'import bpy' >/dev/null 2>&1; then
  "$py" tools/bench_live.py --repeat "${BENCH_LIVE_REPEAT:-5}" 2>&1 | grep -v "DeprecationWarning\|use_nodes = True"
else
  echo "live preview: skipped: cannot import bpy in $py (tools/install_bpy.sh installs it)"
fi
echo "== Blender export of a 1M-triangle scene (issue 12 target: 3x faster than 2.7 CPU-s)"
if "$py" -c 'import bpy' >/dev/null 2>&1; then
  "$py" tools/bench_export.py 2>&1 | grep "^export"
else
  echo "export: skipped in pip bpy: cannot import bpy in $py"
fi
if command -v blender >/dev/null 2>&1; then
  blender -b --factory-startup --python tools/bench_export.py 2>&1 | grep "^export"
fi
echo "== visibility rays: their cost over the shade stage without them, and their error gain (issue 12)"
if "$py" -c 'import numpy' >/dev/null 2>&1; then
  if [ "${BENCH_QUICK:-0}" = 1 ]; then "$py" tools/bench_visibility.py --size 480x270 --repeat 1
  else "$py" tools/bench_visibility.py; fi
else
  echo "visibility: skipped: $py lacks numpy"
fi
echo "== camera flicker at one sample per pixel (320 x 240: every preset), above a dense render (issue 9)"
if "$py" -c 'import numpy' >/dev/null 2>&1; then
  # the dense 8 x 8 renders are cached in build/camera_dense (the box room's ~4 minutes, once)
  if [ "${BENCH_QUICK:-0}" = 1 ]; then
    "$py" tools/camera_dense_excess.py --scenes glossy_sphere_floor --size 160x120 --config balanced
  else
    for preset in preview balanced quality; do "$py" tools/camera_dense_excess.py --config "$preset"; done
  fi
else
  echo "camera flicker: skipped: $py lacks numpy"
fi
echo "== EXR writing: every compression, float and half"
tools/bench_exr.sh
echo "== the trade: error against whole-frame time, library vs Cycles and Cycles + OIDN (issue 11)"
# the modules the trade needs that $py cannot import, by their PyPI names
lacks=$("$py" -c '
import importlib
for mod, pkg in (("numpy", "numpy"), ("matplotlib", "matplotlib"), ("flip_evaluator", "flip-evaluator"), ("bpy", "bpy")):
    try:
        importlib.import_module(mod)
    except Exception:
        print(pkg, end=" ")' 2>/dev/null || echo "numpy matplotlib flip-evaluator bpy")
if [ -z "$lacks" ]; then
  # Cycles references and sweeps are rendered (niced) when missing, then cached
  if [ "${BENCH_QUICK:-0}" = 1 ]; then "$py" tools/trade.py --quick; else "$py" tools/trade.py --docs; fi
else
  echo "trade: skipped: $py ($("$py" -c 'import sys; print(sys.executable)' 2>/dev/null)) lacks: ${lacks% }" \
    "(pip install them into it; bpy, with OIDN: tools/install_bpy.sh)"
fi
