"""The presets' render times on the bundled scenes, this library against an
earlier build (issue 9: "nothing gets slower without a measured reason").

    python3 tools/preset_times.py --before /path/to/old/libvsgl.so [--size 960x540] [--repeat 3]

Each (scene, preset) is timed in child processes that alternate between the
two libraries (before, after, before, after, ...), so that a change in the
machine's load falls on both; the figure is the fastest `vsgl_render` call
of each library (scene creation excluded). Prints a markdown table with the
ratio after / before. Without --before, this library alone.
"""
import argparse
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))
sys.path.insert(0, os.path.join(ROOT, "addon"))

PRESETS = ("preview", "balanced", "quality")


def child(scene, preset, size):
    """One timing in this process: seconds of the render call."""
    import evaluate as E
    import scenes
    rend = E.Renderer()
    s = scenes.case(scene, size)
    return rend.render(s, E.parse_config(preset))[1]


def time_once(lib, scene, preset, size):
    env = dict(os.environ)
    if lib:
        env["VSGL_LIBRARY"] = lib
    else:
        env.pop("VSGL_LIBRARY", None)
    out = subprocess.run([sys.executable, os.path.abspath(__file__), "--child", scene, preset,
                          "%dx%d" % size], env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.strip().splitlines()[-1])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--before", help="the earlier build's libvsgl.so")
    ap.add_argument("--size", default="960x540")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--scenes", default="all")
    ap.add_argument("--child", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        w, h = (int(v) for v in args.child[2].split("x"))
        print("%.6f" % child(args.child[0], args.child[1], (w, h)))
        return 0
    import scenes
    w, h = (int(v) for v in args.size.split("x"))
    names = scenes.NAMES if args.scenes == "all" else args.scenes.split(",")
    after_lib = os.environ.get("VSGL_LIBRARY")
    rows = []
    for name in names:
        for preset in PRESETS:
            t_b, t_a = [], []
            for _ in range(max(1, args.repeat)):
                if args.before:
                    t_b.append(time_once(args.before, name, preset, (w, h)))
                t_a.append(time_once(after_lib, name, preset, (w, h)))
            b = min(t_b) if t_b else None
            a = min(t_a)
            rows.append(dict(scene=name, preset=preset, before=b, after=a))
            before = "" if b is None else "%.3f s ->" % b
            ratio = "" if b is None else "  x%.2f" % (a / b)
            print("%-28s %-9s %s %.3f s%s" % (name, preset, before, a, ratio), file=sys.stderr)
    print("| scene | preset | before s | after s | after / before |")
    print("|---|---|---|---|---|")
    for r in rows:
        b = r["before"]
        before = "-" if b is None else "%.3f" % b
        ratio = "-" if b is None else "%.2f" % (r["after"] / b)
        print("| %s | %s | %s | %.3f | %s |" % (r["scene"], r["preset"], before, r["after"], ratio))
    if os.environ.get("PRESET_TIMES_JSON"):
        with open(os.environ["PRESET_TIMES_JSON"], "w") as f:
            json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
