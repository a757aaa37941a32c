#!/usr/bin/env python3
"""Reproduce the two fitted constants of the SG x clamped-cosine operators
(docs/math.md, csrc/src/math/sg_cosine.c, csrc/src/math/sg_internal.h).

1. lambda_d, the poster's SG cosine lobe: argmin over l of
       J(l) = integral over the sphere of (max(w.n,0)/pi - G(w;n,l)/A(l))^2
   (a 1-D integral in u = w.n times 2 pi).
2. The coefficients (A, B, C, D, E) of
       t(l) = l sqrt(0.5 (l^2 + A l + B) / (l^3 + C l^2 + D l + E))
   used by the ACCURATE mode, by least squares of (I_model - I_exact)/A(l)
   over 45 log-spaced l in [0.05, 5000] and 162 cosines c in [-1, 1].
   I_exact is the exact 1-D reduction (closed-form azimuthal integral).

Needs numpy and scipy (the pyenv python3 on PATH has them). Takes ~1 min.
Usage: python3 tools/fit_cosine_sharpness.py
"""
import numpy as np
from scipy import integrate, optimize, special


def A(l):
    return -2 * np.pi * np.expm1(-2 * l) / l


def K(u, c):
    """Azimuthal integral of max(w.n, 0) at polar cosine u about the SG axis."""
    s = np.sqrt(max(0.0, 1 - c * c))
    a = s * np.sqrt(max(0.0, 1 - u * u))
    b = u * c
    if b >= a:
        return 2 * np.pi * b
    if b <= -a:
        return 0.0
    p0 = np.arccos(-b / a)
    return 2 * a * np.sin(p0) + 2 * b * p0


def exact(l, c):
    s = np.sqrt(max(0.0, 1 - c * c))
    f = lambda u: np.exp(l * (u - 1)) * K(u, c)
    pts = sorted(set([-1.0, -s, s, 1.0]))
    return sum(integrate.quad(f, x0, x1, epsabs=0, epsrel=1e-12, limit=200)[0]
               for x0, x1 in zip(pts[:-1], pts[1:]) if x1 > x0)


def lambda_d():
    def J(ld):
        f = lambda u: 2 * np.pi * (max(u, 0) / np.pi - np.exp(ld * (u - 1)) / A(ld)) ** 2
        return (integrate.quad(f, -1, 0, epsabs=0, epsrel=1e-13)[0]
                + integrate.quad(f, 0, 1, epsabs=0, epsrel=1e-13)[0])
    r = optimize.minimize_scalar(J, bracket=(1, 2, 3), tol=1e-12)
    norm = 2 * np.pi / (3 * np.pi ** 2)  # integral of (max(u,0)/pi)^2
    return r.x, r.fun, np.sqrt(r.fun / norm)


def i_up(l):
    return 2 * np.pi * (l - 1 + np.exp(-l)) / l ** 2


def i_low(l):
    return 2 * np.pi * (np.exp(-l) - np.exp(-2 * l) * (1 + l)) / l ** 2


def t_of(l, p):
    a, b, c, d, e = p
    return l * np.sqrt(0.5 * (l * l + a * l + b) / (l ** 3 + c * l * l + d * l + e))


def model(l, c, t):
    s = (0.5 * c * special.erfc(-t * c) + 0.5 * special.erfc(t)
         - np.exp(-t * t * c * c) * np.expm1(-t * t * (1 - c * c)) / (2 * np.sqrt(np.pi) * t))
    return i_low(l) + (i_up(l) - i_low(l)) * np.clip(s, 0, 1)


def main():
    ld, j, rel = lambda_d()
    print(f"lambda_d = {ld:.9f}  J = {j:.6g}  relative L2 = {rel:.4f}")
    cs = np.concatenate([np.linspace(-1, 1, 101), np.cos(np.linspace(0, np.pi, 61))])
    lams = np.exp(np.linspace(np.log(0.05), np.log(5000), 45))
    ex = np.array([[exact(l, c) for c in cs] for l in lams])

    def resid(p):
        return np.concatenate([(model(l, cs, t_of(l, p)) - ex[i]) / A(l) for i, l in enumerate(lams)])

    r = optimize.least_squares(resid, [3, 17, 4, 15, 76], x_scale=[1, 10, 1, 10, 50], xtol=1e-14, ftol=1e-14)
    print("t(l) coefficients A B C D E =", ", ".join(f"{v:.8f}" for v in r.x))
    e = np.abs(resid(r.x))
    print(f"fit grid: max |err|/A = {e.max():.3g}, mean = {e.mean():.3g}")


if __name__ == "__main__":
    main()
