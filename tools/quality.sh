#!/usr/bin/env bash
# The full quality measurement (issue 9) at bench size: every bundled scene (tests/quality/scenes.py),
# the three presets, brute force, k-means 1024 and FIS 128, stills at 320x240 against Cycles
# references of two seeds x 2048 spp (rendered in Blender when missing: ~30 min the first time on
# 2 cores, cached in build/quality/refs/), light and camera animations at 160x120, 12 frames.
# Writes build/quality/report_bench.md, results_bench.json and img_bench/; with --docs,
# docs/quality.md and docs/img/quality/ instead. Extra arguments go to tests/quality/evaluate.py
# (e.g. --set fit_mode=kmeans vsgl_count=512, --scenes a,b, --size test).
set -euo pipefail
cd "$(dirname "$0")/.."
make --no-print-directory build/libvsgl.so >/dev/null
PY=${BPY_PYTHON:-python3}
"$PY" -c "import numpy" >/dev/null 2>&1 || PY=${PYTHON:-/usr/bin/python3}
exec "$PY" tests/quality/evaluate.py --size "${QUALITY_SIZE:-bench}" --acceptance "$@"
