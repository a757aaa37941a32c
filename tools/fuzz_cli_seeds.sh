#!/usr/bin/env bash
# Seed corpus of tests/fuzz/fuzz_cli.c: argument vectors (NUL-separated, after "vsgl").
set -euo pipefail
d=$1; mkdir -p "$d"
i=0
seed() { i=$((i + 1)); printf '%s\0' "$@" | head -c -1 >"$d/seed$i"; }
seed render s.vsglb
seed render s.vsglb -o out.exr --preset quality --aa 4 --rsm 512 --fit kmeans --vsgls 256
seed render s.vsglb --dry-run -v --max-memory 8G --threads 2 --seed 7
seed render --fit=fis --diffuse=pulled --glossy=sg --visibility=ray --leak=on --merge=off --method=brute s.vsglb
seed render s.vsglb --half --compression zips -- -weird.vsglb
seed info s.vsglb
seed --version
seed render s.vsglb --aa 99999999999 --rsm 2x --bogus
