#!/usr/bin/env bash
# Brute-force VPL gather vs a Cycles one-bounce reference (tests/blender/cycles_ref.py --suite gather).
# RSM sizes: VSGL_GATHER_RES (default 32,64,128). Ends with "N passed, N failed".
SUITE=gather exec "$(dirname "$0")/run_lights.sh"
