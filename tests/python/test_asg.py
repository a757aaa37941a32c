"""ASG operators (vsgl/asg.h) against double-precision quadrature and
numpy re-implementations of Xu et al. 2013's formulas as the header states
them. Tolerances: float32 (a few 1e-6 relative, plus 3e-7 per unit of
exponent magnitude) where asg.h promises exact values (the integral, the
convolution's normalisation); the paper's stated accuracy for the
approximations (Eq. 11: 0.68 % for lambda, mu > 5)."""

import math

import numpy as np
import pytest

import libvsgl
import vsgl_reference as R
from conftest import require
from vsgl_reference import asg_log, dirs_near, rand_frame

L = libvsgl
LAM_MAX = 2.0 ** 41


def c_asg(frame, lam, mu, la):
    """An ASG as the library receives it (float32) and its double twin."""
    F = np.float32(frame)
    a = L.ASG(F[0], F[1], F[2], np.float32(lam), np.float32(mu), np.float32(la))
    return a, (np.array(a.x), np.array(a.y), np.array(a.z), a.lam, a.mu, a.log_amplitude)


def test_asg_eval_vs_formula(lib, rng):
    require(lib, "vsgl_asg_eval")
    for _ in range(100):
        a, t = c_asg(rand_frame(rng), 10 ** rng.uniform(-2, 4), 10 ** rng.uniform(-2, 4),
                     rng.uniform(-5, 5))
        d = dirs_near(t[2], 3 / math.sqrt(min(t[3], t[4]) + 1), rng, 8)
        d = np.float32(d * rng.uniform(0.2, 5, size=(8, 1))).astype(float)
        got = L.asg_eval(a, d)
        want = asg_log(t, d)
        for g, wl, di in zip(got, want, d):
            if wl < -80:
                continue
            tol = 3e-7 * (t[3] + t[4] + abs(t[5]) + 1) + 2e-6 / max(R.unit(di) @ t[2], 1e-6)
            assert g > 0 and abs(math.log(g) - wl) <= tol, (a, di, g, math.exp(wl))
    # below the horizon: exactly 0; zero lobe: 0
    a, t = c_asg(np.eye(3), 2.0, 3.0, 0.0)
    assert L.asg_eval(a, [0.3, 0.2, -0.5]) == 0.0
    assert L.asg_eval(L.ASG([1, 0, 0], [0, 1, 0], [0, 0, 1], 2, 3, -math.inf), [0, 0, 1]) == 0.0


@pytest.mark.parametrize("a", [0.0, 1e-6, 0.01, 0.5, 3.0, 40.0, 700.0, 1e5, 1e8, 1e12])
def test_bessel_f_vs_quadrature(lib, a):
    require(lib, "vsgl_asg_bessel_f")
    want = R.bessel_f_quad(R.f32(a))
    assert L.asg_bessel_f(a) == pytest.approx(want, rel=1e-5), a


def _bandwidth_pairs(rng, lo, hi, count):
    for _ in range(count):
        yield 10 ** rng.uniform(math.log10(lo), math.log10(hi), size=2)


@pytest.mark.parametrize("lo,hi", [(5.0, 1e4), (1.0, 5.0), (1e-3, 1.0), (1e-3, 1e4)])
def test_asg_integral_vs_quadrature(lib, rng, lo, hi):
    """asg.h: Eq. 10 (exact F) for min(lambda, mu) >= 12, an exact quadrature
    below; max relative error 1.7e-9 before rounding to float (Xu's own bounds
    for Eq. 10 are 0.027 % above 5 and 5.2 % above 1)."""
    require(lib, "vsgl_asg_integral")
    for lam, mu in _bandwidth_pairs(rng, lo, hi, 40):
        a, t = c_asg(rand_frame(rng), lam, mu, rng.uniform(-3, 3))
        want = R.quad_asg_times(t)
        got = L.asg_integral(a)
        assert got == pytest.approx(want, rel=3e-6 + 2e-7 * abs(t[5])), (a, got, want)


def test_asg_integral_eq11_formula_and_accuracy(lib, rng):
    require(lib, "vsgl_asg_integral_approx")
    for lam, mu in _bandwidth_pairs(rng, 5.0, 1e4, 40):
        a, t = c_asg(rand_frame(rng), lam, mu, rng.uniform(-3, 3))
        got = L.asg_integral_approx(a)
        formula = math.exp(t[5]) * math.pi * min(1.0, 1 / math.sqrt(t[3] * t[4]))  # capped at c pi
        assert got == pytest.approx(formula, rel=4e-6 + 2e-7 * abs(t[5])), a
        assert got == pytest.approx(R.quad_asg_times(t), rel=6.8e-3 + 2e-5), a


@pytest.mark.parametrize("lam", [0.0, 1e-8, 1e-3, 0.5, 1e6, 1e30])
@pytest.mark.parametrize("mu", [0.0, 1e-3, 2.0, 1e30])
def test_asg_integrals_finite_at_extremes(lib, lam, mu):
    require(lib, "vsgl_asg_integral", "vsgl_asg_integral_approx")
    a = L.ASG([1, 0, 0], [0, 1, 0], [0, 0, 1], lam, mu, 0.0)
    for f in (L.asg_integral, L.asg_integral_approx):
        v = f(a)
        assert math.isfinite(v) and v >= 0, (f.__name__, lam, mu, v)


def _product_ref(t1, t2):
    """Xu Eq. 13: A3 = A1 + A2 eigen-decomposed; c3 = c1 c2 S(z3; z1) S(z3; z2) e^{-e1}."""
    x1, y1, z1, l1, m1, c1 = t1
    x2, y2, z2, l2, m2, c2 = t2
    A = (l1 * np.outer(x1, x1) + m1 * np.outer(y1, y1)
         + l2 * np.outer(x2, x2) + m2 * np.outer(y2, y2))
    e, U = np.linalg.eigh(A)
    z3 = U[:, 0] * (1 if U[:, 0] @ (R.unit(z1) + R.unit(z2)) >= 0 else -1)
    if min(z3 @ R.unit(z1), z3 @ R.unit(z2)) < 0.05:
        return None, e  # the smooth term (nearly) vanishes at the peak: a zero lobe
    la = c1 + c2 + math.log(max(z3 @ R.unit(z1), 0)) + math.log(max(z3 @ R.unit(z2), 0)) - e[0]
    return (U[:, 1], U[:, 2], z3, e[1] - e[0], e[2] - e[0], la), e


def test_asg_product_eq13(lib, rng):
    require(lib, "vsgl_asg_product")
    checked = 0
    while checked < 100:
        F1 = rand_frame(rng)
        F2 = rand_frame(rng)
        if F1[2] @ F2[2] < 0.3:
            continue
        a, t1 = c_asg(F1, 10 ** rng.uniform(0, 3), 10 ** rng.uniform(0, 3), rng.uniform(-3, 3))
        b, t2 = c_asg(F2, 10 ** rng.uniform(0, 3), 10 ** rng.uniform(0, 3), rng.uniform(-3, 3))
        ref, e = _product_ref(t1, t2)
        if ref is None:
            continue
        if min(e[1] - e[0], e[2] - e[1]) < 1e-3 * e[2]:
            continue  # near-degenerate eigenvalues: the frame is ill-determined
        checked += 1
        p = L.asg_product(a, b)
        got = (np.array(p.x), np.array(p.y), np.array(p.z), p.lam, p.mu, p.log_amplitude)
        scale = e[2] + 1
        gap = (e[1] - e[0]) / scale
        assert abs(np.dot(got[2], ref[2]) - 1) <= 1e-5 / gap ** 2, (a, b, p, ref)
        assert abs(p.log_amplitude - ref[5]) <= 4e-6 * scale / gap + 1e-5, (a, b, p, ref)
        # the exponent as a function (frame- and order-invariant) near the peak
        d = dirs_near(ref[2], 1 / math.sqrt(min(ref[3], ref[4]) + 1), rng, 16)
        g, w = asg_log(got, d), asg_log(ref, d)
        ok = np.isfinite(w) & (w > ref[5] - 50)
        assert np.all(np.abs(g[ok] - w[ok]) <= 2e-5 * scale / gap + 1e-4), (a, b, p, ref)
        # and at its axis it equals the true product there (the smooth term at the peak)
        pk = ref[2][None]
        true = asg_log(t1, pk)[0] + asg_log(t2, pk)[0]
        assert abs(asg_log(got, pk)[0] - true) <= 4e-6 * scale / gap + 1e-4


def test_asg_product_aliasing(lib):
    require(lib, "vsgl_asg_product")
    a = L.ASG([1, 0, 0], [0, 1, 0], [0, 0, 1], 3.0, 30.0, 0.1).to_c()
    b = L.ASG([0, 0.8, -0.6], [1, 0, 0], [0, 0.6, 0.8], 7.0, 2.0, -0.2).to_c()
    want = L.asg_product(a, b)
    lib.vsgl_asg_product(a, b, b)
    assert L.ASG.from_c(b) == want


def _conv_ref(t, kernel_sharpness, kernel_la):
    """Eq. 18 as asg.h states it, and the tolerance of its log-amplitude:
    bandwidths nu lam / (nu + lam), nu mu / (nu + mu); amplitude times the
    exact integral of a unit ASG of bandwidths (lam + nu, mu + nu) (here by
    quadrature; Xu's pi / sqrt((lam + nu)(mu + nu)) is its Eq. 11 limit)."""
    x, y, z, lam, mu, la = t
    nu = kernel_sharpness / 2
    F = np.array([x, y, z])
    bl, bm = lam + nu, mu + nu
    exact = R.quad_asg_times((F[0], F[1], F[2], bl, bm, 0.0))
    amp_tol = 3e-6  # asg.h (since ebce8f9): the exact integral, to float rounding
    return (x, y, z, nu * lam / (nu + lam), nu * mu / (nu + mu),
            la + kernel_la + math.log(exact)), amp_tol


def _same_asg(got, ref, amp_tol, rng, tol):
    g = (np.array(got.x), np.array(got.y), np.array(got.z), got.lam, got.mu, got.log_amplitude)
    assert np.dot(R.unit(g[2]), R.unit(ref[2])) > 1 - 1e-6, (got, ref)
    assert math.isfinite(got.log_amplitude), got
    assert abs(got.log_amplitude - ref[5]) <= amp_tol + tol * (1 + abs(ref[5])), (got, ref)
    # the exponent (bandwidths along the frame), amplitude removed
    d = dirs_near(ref[2], 1 / math.sqrt(min(ref[3], ref[4]) + 1e-3), rng, 16)
    a = asg_log(g, d) - g[5]
    b = asg_log(ref, d) - ref[5]
    ok = np.isfinite(b) & (b > -60)
    assert np.all(np.abs(a[ok] - b[ok]) <= tol * (1 + ref[3] + ref[4])), (got, ref)


def test_asg_convolve_sg_eq18(lib, rng):
    require(lib, "vsgl_asg_convolve_sg")
    for _ in range(100):
        a, t = c_asg(rand_frame(rng), 10 ** rng.uniform(-1, 4), 10 ** rng.uniform(-1, 4),
                     rng.uniform(-3, 3))
        k = L.SG(np.float32(R.unit(rng.normal(size=3))), np.float32(10 ** rng.uniform(-1, 4)),
                 np.float32(rng.uniform(-3, 3)))
        got = L.asg_convolve_sg(a, k)
        ref, amp_tol = _conv_ref(t, k.sharpness, k.log_amplitude)
        _same_asg(got, ref, amp_tol, rng, 4e-6)


def test_asg_sg_product_integral_is_eq18_at_the_axis(lib, rng):
    require(lib, "vsgl_asg_sg_product_integral")
    for _ in range(100):
        a, t = c_asg(rand_frame(rng), 10 ** rng.uniform(-1, 3), 10 ** rng.uniform(-1, 3),
                     rng.uniform(-3, 3))
        xi = R.unit(t[2] + rng.normal(size=3) * 0.5)
        g = L.SG(np.float32(xi), np.float32(10 ** rng.uniform(-1, 3)), np.float32(rng.uniform(-3, 3)))
        ref, amp_tol = _conv_ref(t, g.sharpness, g.log_amplitude)
        want_log = asg_log(ref, np.array(g.axis)[None])[0]
        got = L.asg_sg_product_integral(a, g)
        assert math.isfinite(got) and got >= 0, (a, g, got)
        if want_log < -80:
            continue
        assert got > 0 and abs(math.log(got) - want_log) <= amp_tol + 4e-6 * (
            1 + abs(want_log) + ref[3] + ref[4]), (a, g, got, math.exp(want_log))


@pytest.mark.parametrize("lam,mu,s", [(3.0, 3.0, 20.0), (4.0, 40.0, 10.0), (30.0, 300.0, 100.0),
                                      (100.0, 10.0, 1000.0)])
def test_asg_sg_product_integral_accuracy_at_peak(lib, lam, mu, s):
    """Where it is used (the SG's axis on the ASG's lobe axis, lambda, mu > 3),
    Eq. 18 is within 5 % of the exact integral (numpy's Eq. 18 against
    quadrature: 3.1 %, 1.5 %, 0.18 %, 0.08 % for these cases)."""
    require(lib, "vsgl_asg_sg_product_integral")
    F = R.frame_from_z([0.1, -0.3, 0.9])
    a, t = c_asg(F, lam, mu, 0.0)
    g = L.SG(np.float32(t[2]), s, 0.0)
    exact = R.quad_asg_times(t, R.sg_log(np.array(g.axis), s, 0.0), np.array(g.axis),
                             1 / math.sqrt(s), 16)
    assert L.asg_sg_product_integral(a, g) == pytest.approx(exact, rel=0.05)


def test_sg_to_asg_eq3(lib, rng):
    require(lib, "vsgl_sg_to_asg")
    for _ in range(50):
        axis = np.float32(R.unit(rng.normal(size=3)))
        g = L.SG(axis, np.float32(10 ** rng.uniform(-3, 6)), np.float32(rng.uniform(-5, 5)))
        a = L.sg_to_asg(g)
        F = a.frame
        assert np.allclose(F @ F.T, np.eye(3), atol=2e-6), a
        assert np.linalg.det(F) > 0, "frame must be right-handed: %s" % (a,)
        assert np.allclose(F[2], R.unit(np.array(g.axis)), atol=2e-7 * 4), a
        assert a.lam == pytest.approx(g.sharpness / 2, rel=1e-6) and a.mu == pytest.approx(a.lam, rel=1e-6)
        assert a.log_amplitude == g.log_amplitude


@pytest.mark.parametrize("lam,mu", [(0.0, 0.0), (1e30, 1e30), (1e30, 0.0), (-5.0, 2.0)])
def test_asg_extreme_bandwidths_are_finite(lib, lam, mu):
    require(lib, "vsgl_asg_eval", "vsgl_asg_integral", "vsgl_asg_convolve_sg",
            "vsgl_asg_sg_product_integral")
    a = L.ASG([1, 0, 0], [0, 1, 0], [0, 0, 1], lam, mu, 0.0)
    assert L.asg_eval(a, [0, 0, 1]) == pytest.approx(1.0, rel=1e-6)  # the peak is c, always
    for d in ([0.3, 0.1, 0.9], [1, 0, 0]):
        v = L.asg_eval(a, d)
        assert math.isfinite(v) and 0 <= v <= 1.0 + 1e-6
    v = L.asg_integral(a)
    assert math.isfinite(v) and v >= 0
    g = L.SG([0, 0, 1], 10.0, 0.0)
    c = L.asg_convolve_sg(a, g)
    assert all(math.isfinite(x) for x in (c.lam, c.mu)) and c.lam >= 0 and c.mu >= 0
    v = L.asg_sg_product_integral(a, g)
    assert math.isfinite(v) and v >= 0


@pytest.mark.parametrize("a", [-1.0, 1e30])
def test_bessel_f_extremes(lib, a):
    require(lib, "vsgl_asg_bessel_f")
    v = L.asg_bessel_f(a)
    assert math.isfinite(v) and 0 <= v <= 2 * math.pi * (1 + 1e-6), (a, v)
