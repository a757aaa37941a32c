"""CPU time of one scene and configuration of the quality harness at 80 x 60
(docs/mrp.md §4, "Speed"): a warm-up render, then N renders, each timed as
wall time and as the process's CPU time (time.process_time() around
vsgl_render: with one thread, the time the render needs whatever the load).
The library is build/libvsgl.so or $VSGL_LIBRARY, so two libraries can be
compared by alternating runs:

    for r in 1 2; do for L in old/libvsgl.so build/libvsgl.so; do
        VSGL_LIBRARY=$L python3 tools/mrp_cpu.py metal_floor_red_wall "x:glossy_mode=3" 3 - 1; done; done

usage: mrp_cpu.py SCENE CONFIG N [GLOSSY.npy or -] [THREADS (0 = all cores)]
GLOSSY.npy keeps the last render's glossy plane (to compare two libraries'
images).
"""
import os
import sys
import time

import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "quality"))


def main(argv):
    import evaluate as E  # noqa: E402 (loads the library: $VSGL_LIBRARY or build/)
    import scenes
    if len(argv) < 3:
        raise SystemExit(__doc__)
    name, spec, n = argv[0], argv[1], int(argv[2])
    save = argv[3] if len(argv) > 3 and argv[3] != "-" else None
    threads = int(argv[4]) if len(argv) > 4 else 0
    cfg = E.parse_config(spec)
    rend = E.Renderer(threads)
    case = scenes.case(name, (80, 60))
    out = rend.render(case, cfg)[0]  # warm-up
    wall, cpu = [], []
    for _ in range(n):
        c0 = time.process_time()
        out, secs = rend.render(case, cfg)[:2]
        cpu.append(time.process_time() - c0)
        wall.append(secs)
    if n:
        print("%s %s wall median %.4f min %.4f  cpu median %.4f" % (name, spec, np.median(wall), min(wall),
                                                                    np.median(cpu)))
    if save:
        np.save(save, out["Gloss"].astype(np.float32))


if __name__ == "__main__":
    main(sys.argv[1:])
