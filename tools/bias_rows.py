#!/usr/bin/env python3
"""Where a pass's light is lost or gained: the sum of a configuration's
coloured pass over the Cycles reference's, per image row and, for a band of
rows, per column (80 x 60 by default, against the cached references of the
quality suite, tests/quality/refs.py).

    python3 tools/bias_rows.py grazing_corridor balanced brute
    python3 tools/bias_rows.py grazing_corridor balanced brute --pass Gloss --cols 20,31

Rows (columns) holding less than --min-share of the reference's sum are
left out. Configurations as tests/quality/evaluate.py names them.
"""
import argparse
import os
import sys

import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))
import evaluate as E  # noqa: E402
import metrics as M  # noqa: E402
import refs  # noqa: E402
import scenes  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("configs", nargs="+")
    ap.add_argument("--size", default="test")
    ap.add_argument("--pass", dest="pas", default="Diff", choices=("Diff", "Gloss", "Combined"))
    ap.add_argument("--cols", help="ROW0,ROW1: also the per-column sums over rows [ROW0, ROW1)")
    ap.add_argument("--min-share", type=float, default=0.004)
    args = ap.parse_args(argv)
    size = scenes.size_of(args.size)
    seeds = [M.coloured(p) for p, _ in refs.ensure([args.scene], size, refs.DEFAULT_DIR)[args.scene]]
    ref = np.mean([s[args.pas] for s in seeds], axis=0).sum(-1)
    case = scenes.case(args.scene, args.size)
    rend = E.Renderer()
    out = {c: rend.render(case, E.parse_config(c))[0][args.pas].sum(-1) for c in args.configs}
    total = ref.sum()
    print("%s %s at %dx%d: sum over Cycles' per row (rows with >= %.1f %% of its sum)"
          % (args.scene, args.pas, size[0], size[1], 100 * args.min_share))
    print("row  share  " + "  ".join("%9s" % c for c in out))
    for y in range(ref.shape[0]):
        share = ref[y].sum() / total
        if share >= args.min_share:
            ratios = "  ".join("%9.3f" % (o[y].sum() / ref[y].sum()) for o in out.values())
            print("%3d %5.1f%%  %s" % (y, 100 * share, ratios))
    print("all         " + "  ".join("%9.3f" % (o.sum() / total) for o in out.values()))
    if args.cols:
        y0, y1 = (int(v) for v in args.cols.split(","))
        band = ref[y0:y1].sum(0)
        print("columns over rows [%d, %d):" % (y0, y1))
        print("col  share  " + "  ".join("%9s" % c for c in out))
        for x in range(ref.shape[1]):
            if band[x] >= args.min_share * band.sum():
                print("%3d %5.1f%%  " % (x, 100 * band[x] / band.sum()) +
                      "  ".join("%9.3f" % (o[y0:y1, x].sum() / band[x]) for o in out.values()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
