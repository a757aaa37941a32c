#!/usr/bin/env bash
# Accuracy report (docs/accuracy.md): every fit mode and VSGL count against
# brute-force VPL gathering on the same RSMs. Usage: tools/accuracy.sh [w h rsm]
set -euo pipefail
cd "$(dirname "$0")/.."
make --no-print-directory build/libvsgl.so >/dev/null
mkdir -p build/bench
cc -O2 -Itests/c -Icsrc/include -Icsrc/src tools/accuracy.c build/obj/csrc/src/*/*.o \
   -lembree3 -lOpenEXRCore-3_1 -ldeflate -lpthread -lm -o build/bench/accuracy
build/bench/accuracy "$@"
