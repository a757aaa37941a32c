#!/usr/bin/env python3
"""Fit GGX's NDF with two Gaussian lobes (the core and the tail of
VSGL_GLOSSY_ASG2; csrc/src/shade/kernel.h VSGL__GGX_*).

Near its peak, GGX's D(h) with roughness alpha is, in x = tan(theta) / alpha,
proportional to f(x) = 1 / (1 + x^2)^2, and a lobe exp(l (cos - 1)) with
l = 2 k / alpha^2 is exp(-k x^2). Wang et al.'s single SG is k = 1, c = 1
(the peak and the integral of GGX). Two lobes c1 exp(-k1 x^2) + c2 exp(-k2
x^2), with the integral kept (c1 / k1 + c2 / k2 = 1, as f's), are fitted by
minimising the squared relative error

    E = int_0^X ((g(x) - f(x)) / f(x))^2 x dx,     X = 3,

so that the reflection of a lit wall is right within three alphas of the
mirror direction, where a glossy floor shows it. (The plain least-squares
fit, int (g - f)^2 x dx, overshoots GGX by 25-34 % at x = 2-3.)

    python3 tools/fit_ggx_lobes.py          # prints the constants and the ratios g / f

With --lobes 4 it fits the four lobes of the half-vector model
(VSGL__HV_*, csrc/src/shade/kernel.h) the same way over x <= 10: GGX's
tail out to ten alphas, where a lit wall's haze on a metal floor lies.

    python3 tools/fit_ggx_lobes.py --lobes 4

With --emitter it fits the lobes a specular lattice cluster is split into
(a metal floor's reflection of a lit wall; csrc/src/fit/lattice.c
split_specular, VSGL__GGX_EMIT_*): GGX's core as the receivers' (VSGL__GGX_CORE_*,
kept), the rest of the integral in a tail and a far tail, over x <= 6: the
two lobes fall to 0.39 of GGX at four alphas and 0.08 at five, and the
floor's reflection onto the upper part of a wall it faces was 9 % dark.

    python3 tools/fit_ggx_lobes.py --emitter

Needs numpy and scipy (pip install scipy).
"""
import sys

import numpy as np

X_MAX = 3.0


def lobes(params):
    """(k1, c1, k2, c2) from the free parameters (log k1, log k2, logit of the core's energy share)."""
    k1, k2 = np.exp(params[0]), np.exp(params[1])
    share = 1.0 / (1.0 + np.exp(-params[2]))
    return k1, share * k1, k2, (1.0 - share) * k2


def model(k1, c1, k2, c2, x):
    return c1 * np.exp(-k1 * x * x) + c2 * np.exp(-k2 * x * x)


def ggx(x):
    return 1.0 / (1.0 + x * x) ** 2


def objective(k1, c1, k2, c2, x_max=X_MAX, n=6001):
    x = np.linspace(0.0, x_max, n)
    e = ((model(k1, c1, k2, c2, x) - ggx(x)) / ggx(x)) ** 2 * x
    return float(np.sum((e[1:] + e[:-1]) * 0.5 * np.diff(x)))


def best_minimum(f, starts, **options):
    """scipy's Nelder-Mead from every start: the lowest result."""
    from scipy.optimize import minimize
    best = None
    for p0 in starts:
        r = minimize(f, p0, method="Nelder-Mead", options=options)
        if best is None or r.fun < best.fun:
            best = r
    return best


def fit():
    starts = [[np.log(k1), np.log(k2), 0.0] for k1 in (1.0, 2.0, 3.0) for k2 in (0.1, 0.3, 0.6)]
    best = best_minimum(lambda p: objective(*lobes(p)), starts, maxiter=5000, xatol=1e-9, fatol=1e-14)
    return lobes(best.x)


def model_n(k, c, x):
    """sum_i c_i exp(-k_i x^2)."""
    return sum(ci * np.exp(-ki * x * x) for ki, ci in zip(k, c))


def objective_n(k, c, x_max=10.0, n=6001):
    x = np.linspace(0.0, x_max, n)
    e = ((model_n(k, c, x) - ggx(x)) / ggx(x)) ** 2 * x
    return float(np.sum((e[1:] + e[:-1]) * 0.5 * np.diff(x)))


def lobes_n(params, n):
    """(k, c) from the free parameters (log k_i, log weights of the energy shares, the last share's weight 1)."""
    k = np.exp(params[:n])
    w = np.exp(np.append(params[n:], 0.0))
    return k, w / w.sum() * k


def fit_n(n=4, x_max=10.0, starts=40):
    rng = np.random.default_rng(1)
    p0s = []
    for _ in range(starts):
        k0 = np.sort(np.exp(rng.uniform(np.log(0.005), np.log(3.0), n)))[::-1]
        p0s.append(np.concatenate([np.log(k0), rng.normal(0.0, 1.0, n - 1)]))
    best = best_minimum(lambda p: objective_n(*lobes_n(p, n), x_max=x_max), p0s,
                        maxiter=40000, xatol=1e-10, fatol=1e-16)
    k, c = lobes_n(best.x, n)
    order = np.argsort(-k)
    return k[order], c[order]


def main_n(n):
    try:
        k, c = fit_n(n)
    except ImportError:
        sys.exit("fit_ggx_lobes.py needs scipy: python3 -m pip install scipy")
    print("#define VSGL__HV_LOBES %d" % n)
    print("#define VSGL__HV_K_LIST {%s}" % ", ".join("%.5gf" % v for v in k))
    print("#define VSGL__HV_C_LIST {%s}" % ", ".join("%.5gf" % v for v in c))
    print("energy shares " + " ".join("%.3f" % (ci / ki) for ki, ci in zip(k, c)) +
          "; objective %.5f" % objective_n(k, c))
    xs = np.array([0.0, 1.0, 2.0, 3.0, 5.0, 7.0, 10.0])
    print("x = tan / alpha: " + " ".join("%5.1f" % x for x in xs))
    print("lobes / GGX:     " + " ".join("%5.2f" % r for r in model_n(k, c, xs) / ggx(xs)))


EMIT_X_MAX = 6.0


def emitter_lobes(params, k1, c1):
    """(k, c) of the emitters' three lobes from the free parameters (log k2,
    log k3, logit of the far tail's share of what the core leaves)."""
    rest = 1.0 - c1 / k1
    k2, k3 = np.exp(params[0]), np.exp(params[1])
    s3 = rest / (1.0 + np.exp(-params[2]))
    return np.array([k1, k2, k3]), np.array([c1, (rest - s3) * k2, s3 * k3])


def fit_emitter(k1, c1):
    starts = [[np.log(k2), np.log(k3), 0.0] for k2 in (0.2, 0.3, 0.5) for k3 in (0.02, 0.06, 0.15)]
    best = best_minimum(lambda p: objective_n(*emitter_lobes(p, k1, c1), x_max=EMIT_X_MAX), starts,
                        maxiter=20000, xatol=1e-10, fatol=1e-14)
    return emitter_lobes(best.x, k1, c1)


def main_emitter():
    try:
        k1, c1, _, _ = fit()
        k, c = fit_emitter(k1, c1)
    except ImportError:
        sys.exit("fit_ggx_lobes.py needs scipy: python3 -m pip install scipy")
    print("#define VSGL__GGX_EMIT_TAIL_K %.4gf" % k[1])
    print("#define VSGL__GGX_EMIT_TAIL_C %.4gf" % c[1])
    print("#define VSGL__GGX_EMIT_FAR_K %.4gf" % k[2])
    print("#define VSGL__GGX_EMIT_FAR_C %.4gf" % c[2])
    print("energy shares " + " ".join("%.3f" % (ci / ki) for ki, ci in zip(k, c)) +
          "; objective %.5f over x <= %g" % (objective_n(k, c, x_max=EMIT_X_MAX), EMIT_X_MAX))
    xs = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0])
    print("x = tan / alpha: " + " ".join("%5.1f" % x for x in xs))
    print("lobes / GGX:     " + " ".join("%5.2f" % r for r in model_n(k, c, xs) / ggx(xs)))


def main():
    if "--emitter" in sys.argv:
        return main_emitter()
    if "--lobes" in sys.argv:
        n = int(sys.argv[sys.argv.index("--lobes") + 1])
        if n != 2:
            return main_n(n)
    try:
        k1, c1, k2, c2 = fit()
    except ImportError:
        sys.exit("fit_ggx_lobes.py needs scipy: python3 -m pip install scipy")
    xs = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0])
    print("#define VSGL__GGX_CORE_K %.4gf" % k1)
    print("#define VSGL__GGX_CORE_C %.4gf" % c1)
    print("#define VSGL__GGX_TAIL_K %.4gf" % k2)
    print("#define VSGL__GGX_TAIL_C %.4gf" % c2)
    print("core's share of the energy %.3f; objective %.5f" % (c1 / k1, objective(k1, c1, k2, c2)))
    print("x = tan / alpha:      " + " ".join("%5.1f" % x for x in xs))
    print("two lobes / GGX:      " + " ".join("%5.2f" % r for r in model(k1, c1, k2, c2, xs) / ggx(xs)))
    print("one lobe (k=1) / GGX: " + " ".join("%5.2f" % r for r in np.exp(-xs * xs) / ggx(xs)))


if __name__ == "__main__":
    main()
