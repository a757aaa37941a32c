#!/usr/bin/env python3
"""What makes a pixel flicker: for frames of a bundled quality scene's
animation (tests/quality/scenes.py), the light every VSGL gives one pixel
(tools/probe_vsgls.c, built by `BENCH_BUILD_ONLY=1 tools/bench.sh` into
build/bench/), side by side over the frames, largest change first.

    python3 tools/probe_frames.py glossy_sphere_floor preview 16 28 --frames 2,3
    python3 tools/probe_frames.py glossy_sphere_floor balanced 44 44 --anim camera --pass diffuse

VSGLs are matched across frames by their lattice cell (or, off the
lattice, by their index): a cluster whose power is steady while its light
at the pixel jumps points at the model (a cut, a fold); one whose power or
extent jumps, at the fit. Every pixel is shaded and no visibility ray is
traced (the model's own answer); configurations as evaluate.py names them.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))
import evaluate as E  # noqa: E402
import scenes  # noqa: E402

LINE = re.compile(r"\s*(\d+) lobe (\d+) light (\d+)\s+([\d.e+-]+)\s+(.*)")
CELL = re.compile(r"cell axis (\d+) side (\d+) at (-?\d+) (-?\d+)")


def probe(binary, bundle, x, y, pas):
    out = subprocess.run([binary, bundle, str(x), str(y), pas, "0"], capture_output=True, text=True, check=True)
    lines = out.stdout.splitlines()
    total, rows = float(lines[0].split()[4].rstrip(";")), {}
    for line in lines[1:]:
        m = LINE.match(line)
        c = CELL.search(m.group(5))
        key = (m.group(2), m.group(3)) + (c.groups() if c else ("#" + m.group(1),))
        rows[key] = (float(m.group(4)), m.group(5))
    return total, rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("config")
    ap.add_argument("x", type=int)
    ap.add_argument("y", type=int)
    ap.add_argument("--anim", default="light", choices=("light", "camera"))
    ap.add_argument("--frames", default="0,1,2,3,4,5")
    ap.add_argument("--size", default="test")
    ap.add_argument("--pass", dest="pas", default="glossy", choices=("glossy", "diffuse"))
    ap.add_argument("--top", type=int, default=12)
    ap.add_argument("--probe", default=os.path.join(ROOT, "build", "bench", "probe_vsgls"))
    args = ap.parse_args(argv)
    if not os.path.exists(args.probe):
        raise SystemExit("no %s: build it with BENCH_BUILD_ONLY=1 tools/bench.sh" % args.probe)
    cfg = E.parse_config(args.config)
    if cfg.brute:
        raise SystemExit("the brute force has no VSGLs to probe")
    frames = [int(f) for f in args.frames.split(",")]
    base = scenes.case(args.scene, args.size)
    totals, per = [], []
    ctx = E.L.Context()
    with tempfile.TemporaryDirectory() as tmp:
        for f in frames:
            path = os.path.join(tmp, "frame%d.vsglb" % f)
            E.L.bundle_write(ctx, path, scenes.library_arrays(scenes.animate(base, args.anim, f), E.L),
                             cfg.settings())
            t, rows = probe(args.probe, path, args.x, args.y, args.pas)
            totals.append(t)
            per.append(rows)
    print("%s %s pixel (%d, %d) %s, %s animation frames %s: %s" % (
        args.scene, args.config, args.x, args.y, args.pas, args.anim, args.frames,
        "  ".join("%.4f" % t for t in totals)))
    keys = set().union(*per)

    def swing(k):
        v = [r.get(k, (0.0, ""))[0] for r in per]
        return max(v) - min(v)
    for k in sorted(keys, key=swing, reverse=True)[:args.top]:
        vals = "  ".join("%.4f" % r.get(k, (0.0, ""))[0] for r in per)
        last = next((r[k][1] for r in reversed(per) if k in r), "")
        print("lobe %s light %s %-28s %s\n    %s" % (k[0], k[1], "cell " + " ".join(k[2:]), vals, last))
    return 0


if __name__ == "__main__":
    sys.exit(main())
