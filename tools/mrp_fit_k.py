#!/usr/bin/env python3
"""Reproduce the MRP paper's Eq. 25 fit and its error (the paper's Fig. 4).

The attenuation of the radiance a GGX rectangle reflects around its
specular peak (Eq. 23, with the half-vector angle psi of Eq. 24)

    f(theta) = m^4 / (1 - (1 - m^2) cos^2 psi(theta))^2
    psi      = -sigma/2 + atan(sec^2(sigma) tan(theta) + tan(sigma)) / 2

is fitted by exp(-k sin^2 theta) cos theta with the paper's
k = 0.288 cos(sigma) / m^2 - 0.673 (Eq. 25).

1. For each (sigma, m) of a grid, the least-squares k (weight sin theta,
   the solid angle of Eq. 20, theta in [0, pi/2)); then a least-squares
   fit k ~ a cos(sigma) / m^2 + b over the grid, next to the paper's
   (a, b) = (0.288, -0.673).
2. The error of Eq. 25 at the paper's four Fig. 4 configurations
   (sigma = pi/6, 2pi/5; m = 0.1, 0.7): max |fit - f| and the relative
   error of the cap integral E (Eq. 22 against Eq. 26) for a cap of
   aperture alpha = atan(r_d cos sigma), r_d = 0.5 and 2.

numpy only (Debian's /usr/bin/python3 has it). Runs in a few seconds.
Usage: /usr/bin/python3 tools/mrp_fit_k.py
"""
import numpy as np

THETA = np.linspace(0.0, np.pi / 2, 4001)[:-1]
W = np.sin(THETA)


def psi(theta, sigma):
    c = np.cos(sigma)
    return -sigma / 2 + np.arctan(np.tan(theta) / (c * c) + np.tan(sigma)) / 2


def f23(theta, sigma, m):
    c = np.cos(psi(theta, sigma))
    den = m * m * c * c + (1 - c * c)
    return (m * m / den) ** 2


def f25(theta, k):
    return np.exp(-k * np.sin(theta) ** 2) * np.cos(theta)


def k_paper(sigma, m):
    return 0.288 * np.cos(sigma) / (m * m) - 0.673


def best_k(sigma, m):
    target = f23(THETA, sigma, m)
    ks = np.concatenate([-np.logspace(1, -3, 60), [0.0], np.logspace(-3, 5, 400)])
    err = [np.sum(W * (f25(THETA, k) - target) ** 2) for k in ks]
    i = int(np.argmin(err))
    lo, hi = ks[max(i - 1, 0)], ks[min(i + 1, len(ks) - 1)]
    for _ in range(60):  # golden section
        a = hi - 0.618 * (hi - lo)
        b = lo + 0.618 * (hi - lo)
        fa = np.sum(W * (f25(THETA, a) - target) ** 2)
        fb = np.sum(W * (f25(THETA, b) - target) ** 2)
        if fa < fb:
            hi = b
        else:
            lo = a
    return 0.5 * (lo + hi)


def E_exact(sigma, m, alpha):
    t = np.linspace(0.0, alpha, 20001)
    return np.trapz(f23(t, sigma, m) * np.sin(t), t)


def E_fit(k, alpha):
    s2 = np.sin(alpha) ** 2
    if abs(k) < 1e-12:
        return s2 / 2
    return (1 - np.exp(-k * s2)) / (2 * k)


def main():
    sig = np.radians(np.arange(0, 81, 5))
    ms = np.array([0.05, 0.075, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.7])
    rows = []
    for s in sig:
        for m in ms:
            rows.append((s, m, best_k(s, m)))
    rows = np.array(rows)
    x = np.cos(rows[:, 0]) / rows[:, 1] ** 2
    A = np.stack([x, np.ones_like(x)], axis=1)
    (a, b), *_ = np.linalg.lstsq(A, rows[:, 2], rcond=None)
    print("1. least-squares k per (sigma, m), sigma 0..80 deg, m 0.05..0.7 (%d points)" % len(rows))
    print("   fitted  k = %.3f cos(sigma)/m^2 %+.3f" % (a, b))
    print("   paper   k = 0.288 cos(sigma)/m^2 -0.673")
    print("   (the small-theta limit at sigma = 0 is k = 1/(2 m^2) - 1/2)")
    print("   per-m least-squares k at sigma = 0:",
          ", ".join("m=%.3g: %.4g (paper %.4g)" % (m, best_k(0.0, m), k_paper(0.0, m)) for m in ms))
    print()
    print("2. Fig. 4 configurations: Eq. 25 (paper's k) against Eq. 23")
    print("| sigma | m | k paper | k best | max abs err (paper k) | max abs err (best k) |"
          " E rel err r_d=0.5 | E rel err r_d=2 |")
    print("|---|---|---|---|---|---|---|---|")
    for s, m in ((np.pi / 6, 0.1), (2 * np.pi / 5, 0.1), (np.pi / 6, 0.7), (2 * np.pi / 5, 0.7)):
        kp, kb = k_paper(s, m), best_k(s, m)
        tgt = f23(THETA, s, m)
        e_p = np.max(np.abs(f25(THETA, kp) - tgt))
        e_b = np.max(np.abs(f25(THETA, kb) - tgt))
        rel = []
        for rd in (0.5, 2.0):
            al = np.arctan(rd * np.cos(s))
            ex = E_exact(s, m, al)
            rel.append((E_fit(max(kp, 0.0), al) - ex) / ex)
        print("| %.0f deg | %.1f | %.3f | %.3f | %.3f | %.3f | %+.1f %% | %+.1f %% |"
              % (np.degrees(s), m, kp, kb, e_p, e_b, 100 * rel[0], 100 * rel[1]))


if __name__ == "__main__":
    main()
