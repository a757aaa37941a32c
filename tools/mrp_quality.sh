#!/usr/bin/env bash
# docs/mrp.md §4's tables and images (tools/mrp_quality.py): the MRP glossy
# mode against balanced, k-means 256 and the brute force over Cycles, on the
# quality harness's metal-floor and sun scenes, stills and animations; and
# MRP variants built into build/mrp_variants/ with other compile-time
# defaults (csrc/src/mrp/glossy.c, shade_mrp.c) and loaded through
# $VSGL_LIBRARY.
# Cycles references come from the harness's cache (build/quality/refs);
# about 15 min on 2 shared cores. Then interleaved timing rounds of the
# main configurations (the acceptance's "no more time").
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
OUT=build/mrp_quality
mkdir -p "$OUT"
make -s build/libvsgl.so
"$PY" tools/mrp_quality.py run "$OUT/main.npz" "$@"
# variants: one GGX lobe (the old default); the light shrunk to a cell; the
# isotropic cell cull only (before the lobe's ASG test); the exact BRDF
# integrated over each cell instead of the MRP term (diagnostic: what the
# cells' radiance allows); the hybrid with MRP's light alone in its pixels
# (before the larger-of-two rule) and with the larger of the two (the rule
# before VSGL__MRP_HYBRID_RATIO 2); the cell pyramid off (every cell on its
# own) and every pixel shaded (no 2 x 2 interpolation): the pass before
# both speed-ups. Stills only.
for v in "one:-DVSGL__MRP_LOBES=1:one lobe:mrp:glossy_mode=3" \
         "shrink:-DVSGL__MRP_SHRINK=1.0:shrink 1:mrp:glossy_mode=3" \
         "nocull:-DVSGL__MRP_CULL=0:box cull only:mrp:glossy_mode=3" \
         "exact:-DVSGL__MRP_EXACT_CELLS=4:exact cells:mrp:glossy_mode=3" \
         "hybmrp:-DVSGL__MRP_HYBRID_RATIO=0:MRP's light alone:hybrid:glossy_mode=4" \
         "hybmax:-DVSGL__MRP_HYBRID_RATIO=1:ratio 1, the rule before:hybrid:glossy_mode=4" \
         "slow:-DVSGL__MRP_MERGE=0 -DVSGL__MRP_SPARSE_CONTRAST=0:no pyramid, every pixel:mrp:glossy_mode=3"; do
    tag=${v%%:*}; rest=${v#*:}; flags=${rest%%:*}; rest=${rest#*:}; label=${rest%%:*}; cfg=${rest#*:}
    dir=build/mrp_variants/$tag
    rm -rf "$dir"
    make -s BUILD="$dir" OPT="-O2 -g $flags" "$dir/libvsgl.so"
    VSGL_LIBRARY="$PWD/$dir/libvsgl.so" "$PY" tools/mrp_quality.py run "$OUT/$tag.npz" \
        --configs "$cfg" --suffix " ($label)" "$@" --anim none
done
"$PY" tools/mrp_quality.py time "$OUT/time.json"
"$PY" tools/mrp_quality.py docs --timing "$OUT/time.json" "$OUT/main.npz" "$OUT/one.npz" "$OUT/shrink.npz" "$OUT/nocull.npz" "$OUT/exact.npz" \
    "$OUT/hybmrp.npz" "$OUT/hybmax.npz" "$OUT/slow.npz"
