#!/usr/bin/env python3
"""make lint: every stage loop of the shading kernel is vectorised.

The kernel (csrc/src/shade/kernel_impl.h) is branch-free C that GCC
vectorises over a block's receivers; each stage is one loop, written as a
macro invocation (K_FORN, K_FORI, K_DIFFUSE, K_FOLD) inside k_shade. A stage that
stops vectorising still computes the same pixels, only several times
slower, and no test sees it: a fold rewrite once left five of its seven
loops scalar and balanced renders 15-40 % slower (docs/performance.md,
"The light edit within 50 ms"). This compiles kernel.c as the Makefile
does, with GCC's vectorisation report, and fails naming each invocation
line that has no vectorised loop in the AVX2 (32-byte) and AVX-512
(64-byte) clones.

    python3 tools/check_vectorised.py [--cc gcc]
"""
import argparse
import os
import re
import subprocess
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
IMPL = os.path.join("csrc", "src", "shade", "kernel_impl.h")
# the Makefile's flags for kernel.o (KERNEL_MATH, -O3)
FLAGS = ["-std=c11", "-D_POSIX_C_SOURCE=200809L", "-DVSGL_BUILDING", "-fPIC", "-Icsrc/include", "-Icsrc/src",
         "-O3", "-fno-math-errno", "-fno-trapping-math", "-funsafe-math-optimizations", "-ffinite-math-only",
         "-mrecip", "-fopt-info-vec-all"]
STAGE = re.compile(r"^\s*(?:if \(.*\)\s*|else\s*|case \d+:\s*|default:\s*)*(K_FORN|K_FORI|K_DIFFUSE|K_FOLD)\(")


def stage_lines(path):
    """Line numbers (1-based) of the stage loops' macro invocations."""
    out = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if "#define" not in line and STAGE.search(line):
                out.append(n)
    return out


def vectorised_lines(cc):
    """{vector bytes: set of kernel_impl.h lines with a loop vectorised at that width}, and under
    the key "scalar" the lines where some instance of a loop was left scalar for control flow
    (one stage inlined once per light count: a select on a load, a short-circuit && in one
    instance, left the others vectorised, and the check passed while balanced ran 2-5x
    slower)."""
    cmd = [cc] + FLAGS + ["-c", os.path.join("csrc", "src", "shade", "kernel.c"), "-o", os.devnull]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("check_vectorised: %s failed:\n%s" % (" ".join(cmd), p.stderr[-2000:]))
    found = {}
    pat = re.compile(r"kernel_impl\.h:(\d+):\d+: optimized: loop vectorized using (\d+) byte vectors")
    for m in pat.finditer(p.stderr):
        found.setdefault(int(m.group(2)), set()).add(int(m.group(1)))
    flow = re.compile(r"kernel_impl\.h:(\d+):\d+: missed: not vectorized: control flow in loop")
    found["scalar"] = {int(m.group(1)) for m in flow.finditer(p.stderr)}
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cc", default=os.environ.get("CC", "gcc"))
    args = ap.parse_args()
    if "clang" in os.path.basename(args.cc):
        print("check_vectorised: %s: the check reads GCC's report; skipped" % args.cc)
        return 0
    lines = stage_lines(os.path.join(ROOT, IMPL))
    if len(lines) < 20:
        sys.exit("check_vectorised: found only %d stage loops in %s: has the kernel's layout changed?"
                 % (len(lines), IMPL))
    found = vectorised_lines(args.cc)
    src = open(os.path.join(ROOT, IMPL)).read().splitlines()
    bad = []
    for width, isa in ((32, "x86-64-v3"), (64, "x86-64-v4")):
        for n in lines:
            if n not in found.get(width, set()):
                bad.append("%s:%d: not vectorised in the %s clone: %s" % (IMPL, n, isa, src[n - 1].strip()))
    for n in lines:
        if n in found["scalar"]:
            bad.append("%s:%d: an instance left scalar (control flow in the loop): %s" % (IMPL, n, src[n - 1].strip()))
    for b in bad:
        print(b)
    verdict = "%d not vectorised" % len(bad) if bad else "all vectorised"
    print("check_vectorised: %d stage loops, %s" % (len(lines), verdict))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
