#!/usr/bin/env bash
# docs/mrp.md §4's tables and images (tools/mrp_quality.py): the MRP glossy
# mode against balanced, k-means 256 and the brute force over Cycles, on the
# quality harness's metal-floor and sun scenes, stills and animations; and
# the MRP variants of the previous defaults (one GGX lobe; the light spanning
# the whole disk), built into build/mrp_variants/ with other compile-time
# defaults (csrc/src/mrp/glossy.c) and loaded through $VSGL_LIBRARY.
# Cycles references come from the harness's cache (build/quality/refs);
# about 15 min on 2 shared cores.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
OUT=build/mrp_quality
mkdir -p "$OUT"
make -s build/libvsgl.so
"$PY" tools/mrp_quality.py run "$OUT/main.npz" "$@"
for v in "1 0:one lobe" "2 0:no shrink"; do
    flags=${v%%:*}; label=${v#*:}
    lobes=${flags% *}; shrink=${flags#* }
    dir=build/mrp_variants/l${lobes}s${shrink}
    make -s BUILD="$dir" OPT="-O2 -g -DVSGL__MRP_LOBES=$lobes -DVSGL__MRP_SHRINK=$shrink" "$dir/libvsgl.so"
    VSGL_LIBRARY="$PWD/$dir/libvsgl.so" "$PY" tools/mrp_quality.py run "$OUT/l${lobes}s${shrink}.npz" \
        --configs "mrp:glossy_mode=3" --suffix " ($label)" "$@"
done
"$PY" tools/mrp_quality.py docs "$OUT/main.npz" "$OUT/l1s0.npz" "$OUT/l2s0.npz"
