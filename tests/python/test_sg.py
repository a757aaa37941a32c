"""SG operators (vsgl/sg.h) against double-precision quadrature and numpy
re-implementations of the documented formulas.

Tolerances: the library works in float32, so a well-conditioned result is
good to a few ulps (rel 2e-6..1e-5); a result exp(E) carries the absolute
error of E, about 1e-7 * (the magnitudes summed into E), which the
tolerances below add explicitly."""

import math

import numpy as np
import pytest

import libvsgl
import vsgl_reference as R
from conftest import require

L = libvsgl
F32_EPS = 2.0 ** -23
LAM_MAX = 2.0 ** 41


def rand_unit(rng):
    return R.unit(rng.normal(size=3))


def c_sg(axis, lam, la):
    """An SG exactly as the library sees it (float32 values) and its double twin."""
    g = L.SG(np.float32(axis), np.float32(lam), np.float32(la))
    return g, (np.array(g.axis), g.sharpness, g.log_amplitude)


SHARPNESS = [0.0, 1e-8, 1e-4, 0.1, 0.5, 1.0, 2.2925, 10.0, 100.0, 1e4, 1e6, 1e12, LAM_MAX]


@pytest.mark.parametrize("lam", SHARPNESS + [1e30])
def test_sg_integral_vs_quadrature(lib, lam):
    require(lib, "vsgl_sg_integral")
    lam32 = R.f32(lam)
    want = R.quad_sg_integral(min(lam32, LAM_MAX))  # documented clamp to 2^41
    got = L.sg_integral(lam)
    assert got == pytest.approx(want, rel=4e-6), "sg_integral(%r)" % lam


def test_sg_integral_negative_is_clamped_to_zero(lib):
    require(lib, "vsgl_sg_integral")
    assert L.sg_integral(-3.0) == pytest.approx(4 * np.pi, rel=2e-7)


def test_sg_lobe_integral(lib, rng):
    require(lib, "vsgl_sg_lobe_integral")
    for _ in range(50):
        g, (x, lam, la) = c_sg(rand_unit(rng), 10 ** rng.uniform(-3, 5), rng.uniform(-20, 20))
        want = math.exp(la) * R.quad_sg_integral(lam)
        got = L.sg_lobe_integral(g)
        assert got == pytest.approx(want, rel=4e-6 + 2e-7 * abs(la)), g
    assert L.sg_lobe_integral(L.SG([0, 0, 1], 3.0, -math.inf)) == 0.0


def test_sg_eval_vs_formula(lib, rng):
    require(lib, "vsgl_sg_eval")
    for _ in range(300):
        g, (x, lam, la) = c_sg(rand_unit(rng), 10 ** rng.uniform(-3, 4), rng.uniform(-10, 10))
        # directions within the lobe (value not below float range), not normalised
        t = rng.uniform(0, min(np.pi, math.sqrt(60.0 / lam)))
        F = R.frame_from_z(x)
        d = (math.sin(t) * F[0] + math.cos(t) * F[2]) * rng.uniform(0.1, 10.0)
        d32 = np.float32(d).astype(float)
        want_log = R.sg_log(x, lam, la)(d32[None])[0]
        got = L.sg_eval(g, d32)
        tol = 3e-7 * (lam + abs(la) + 1)
        assert got > 0 and abs(math.log(got) - want_log) <= tol, (g, d32, got, math.exp(want_log))


def test_sg_eval_array_and_zero_lobes(lib):
    require(lib, "vsgl_sg_eval")
    g = L.SG([0, 0, 1], 2.0, 0.5)
    dirs = np.array([[0, 0, 1], [0, 1, 0], [0, 0, -2.0]])
    got = L.sg_eval(g, dirs)
    want = np.exp(0.5 + 2.0 * (np.array([1.0, 0.0, -1.0]) - 1))
    np.testing.assert_allclose(got, want, rtol=2e-6)
    assert L.sg_eval(L.SG([0, 0, 1], 2.0, -math.inf), [0, 0, 1]) == 0.0
    assert L.sg_eval(L.SG([0, 0, 0], 2.0, 0.0), [0, 0, 1]) == 0.0  # zero axis: zero lobe
    assert math.isnan(L.sg_eval(L.SG([0, 0, 1], 2.0, math.nan), [0, 0, 1]))


def _product_ref(a, b):
    (x1, l1, c1), (x2, l2, c2) = a, b
    x1, x2 = R.unit(x1), R.unit(x2)
    s = l1 * x1 + l2 * x2
    lm = np.linalg.norm(s)
    la = c1 + c2 - l1 * l2 * np.sum((x1 - x2) ** 2) / (lm + l1 + l2)
    return s / lm, lm, la


def test_sg_product_is_the_pointwise_product(lib, rng):
    require(lib, "vsgl_sg_product")
    for _ in range(200):
        ga, a = c_sg(rand_unit(rng), 10 ** rng.uniform(-2, 4), rng.uniform(-5, 5))
        gb, b = c_sg(rand_unit(rng), 10 ** rng.uniform(-2, 4), rng.uniform(-5, 5))
        p = L.sg_product(ga, gb)
        axis, lm, la = _product_ref(a, b)
        tol_l = 4e-6 * (a[1] + b[1])
        assert abs(p.sharpness - lm) <= tol_l + 1e-6 * lm, (ga, gb, p, lm)
        assert abs(p.log_amplitude - la) <= 4e-7 * (a[1] + b[1] + abs(la)) + 1e-6, (ga, gb, p, la)
        if lm > 1e-3:
            assert np.linalg.norm(np.array(p.axis) - axis) <= 2e-6 * (a[1] + b[1]) / lm + 2e-6, \
                (ga, gb, p, axis)
        # pointwise: log G_p(w) = log G_a(w) + log G_b(w) near the product's peak
        F = R.frame_from_z(axis)
        for t in (0.0, min(1.0, 1 / math.sqrt(max(lm, 1e-9)))):
            w = math.sin(t) * F[0] + math.cos(t) * F[2]
            want = R.sg_log(*a)(w[None])[0] + R.sg_log(*b)(w[None])[0]
            got = R.sg_log(np.array(p.axis), p.sharpness, p.log_amplitude)(w[None])[0]
            assert abs(got - want) <= 1e-6 * (a[1] + b[1] + abs(want) + 1), (ga, gb, p, t)


def test_sg_product_aliasing_output(lib):
    require(lib, "vsgl_sg_product")
    a = L.SG([0, 0, 1], 3.0, 0.2).to_c()
    b = L.SG([0, 1, 0], 5.0, -0.1).to_c()
    want = L.sg_product(a, b)
    lib.vsgl_sg_product(a, b, a)  # out aliases the first input
    assert L.SG.from_c(a) == want


def _exp_tol(la_total, *lams):
    """Relative tolerance of exp(E) with |E| made of these magnitudes."""
    return 1e-5 + 4e-7 * (abs(la_total) + sum(lams))


def test_sg_product_integral_vs_quadrature(lib, rng):
    require(lib, "vsgl_sg_product_integral")
    for i in range(120):
        ga, a = c_sg(rand_unit(rng), 10 ** rng.uniform(-3, 4), rng.uniform(-3, 3))
        xb = R.unit(a[0] + rng.normal(size=3) * 10 ** rng.uniform(-2, 0.5))
        gb, b = c_sg(xb, 10 ** rng.uniform(-3, 4), rng.uniform(-3, 3))
        want = R.quad_sg_product(a, b)
        if want < 1e-30:
            continue
        got = L.sg_product_integral(ga, gb)
        E = math.log(want)
        assert got == pytest.approx(want, rel=_exp_tol(E, a[1] * 1e-2, b[1] * 1e-2)), (ga, gb)


@pytest.mark.parametrize("lam", [0.0, 1e-8, 1e-3, 1e6, 1e12, 1e30])
def test_sg_product_integral_extremes(lib, lam):
    require(lib, "vsgl_sg_product_integral")
    g = L.SG([0, 0, 1], lam, 0.0)
    lam_c = min(R.f32(lam), LAM_MAX)
    # same axis: the product is exp(2 lam (w.xi - 1)); the library also clamps
    # the product's sharpness to 2^41, so past it A(2^41) is the answer
    want = R.quad_sg_integral(min(2 * lam_c, LAM_MAX))
    got = L.sg_product_integral(g, g)
    assert got == pytest.approx(want, rel=1e-5), lam
    # opposite axes: exp(-2 lam) * A(0) (product sharpness 0)
    h = L.SG([0, 0, -1], lam, 0.0)
    got = L.sg_product_integral(g, h)
    want = math.exp(-2 * lam_c) * 4 * np.pi
    assert got == pytest.approx(want, rel=1e-5, abs=1e-37), lam
    assert math.isfinite(got) and got >= 0


def test_sg_product_integral_iwasaki_formula(lib, rng):
    require(lib, "vsgl_sg_product_integral_iwasaki")
    for _ in range(200):
        ga, (x1, l1, c1) = c_sg(rand_unit(rng), 10 ** rng.uniform(-2, 4), rng.uniform(-3, 3))
        gb, (x2, l2, c2) = c_sg(rand_unit(rng), 10 ** rng.uniform(-2, 4), rng.uniform(-3, 3))
        lr = l1 * l2 / (l1 + l2)
        E = c1 + c2 + lr * (np.dot(R.unit(x1), R.unit(x2)) - 1)
        if E < -80:
            continue
        want = 2 * np.pi * math.exp(E) / (l1 + l2)
        # capped by the exact bound a1 a2 min(A(l1), A(l2)) where the formula
        # diverges (l1 + l2 -> 0; sg.c, docs/math.md; not stated in sg.h)
        want = min(want, math.exp(c1 + c2) * R.sg_area(max(l1, l2)))
        got = L.sg_product_integral_iwasaki(ga, gb)
        assert got == pytest.approx(want, rel=_exp_tol(E, lr)), (ga, gb)


def test_iwasaki_accuracy_as_documented(lib, rng):
    """Close to the exact integral for sharp lobes, an over-estimate for broad ones."""
    require(lib, "vsgl_sg_product_integral_iwasaki")
    for _ in range(40):
        l1, l2 = 10 ** rng.uniform(2.5, 4, size=2)
        x1 = rand_unit(rng)
        lr = l1 * l2 / (l1 + l2)
        x2 = R.unit(x1 + rng.normal(size=3) * 1.0 / math.sqrt(lr))
        ga, a = c_sg(x1, l1, 0.0)
        gb, b = c_sg(x2, l2, 0.0)
        exact = R.quad_sg_product(a, b)
        if exact < 1e-30:
            continue
        # relative error of Iwasaki's form is O(1/lambda) for sharp lobes
        got = L.sg_product_integral_iwasaki(ga, gb)
        assert got == pytest.approx(exact, rel=5.0 / min(l1, l2) + 1e-4), (ga, gb)
    for lam in (0.05, 0.3, 1.0):
        g = L.SG([0, 0, 1], lam, 0.0)
        exact = R.quad_sg_product(([0, 0, 1.0], R.f32(lam), 0.0), ([0, 0, 1.0], R.f32(lam), 0.0))
        assert L.sg_product_integral_iwasaki(g, g) > 1.001 * exact, lam


def _least_squares_cosine_sharpness():
    """argmin over lambda of || max(cos, 0) - pi G(.; n, lambda) / A(lambda) ||^2 (sphere)."""
    u, w = R.graded_rule(0.0, 2.0, [(1.0, 0.05)], 48)
    c = 1.0 - u

    def err(lam):
        g = np.pi * np.exp(lam * (c - 1)) / R.sg_area(lam)
        return float(np.sum(w * (np.maximum(c, 0) - g) ** 2))
    a, b = 0.5, 6.0
    phi = (math.sqrt(5) - 1) / 2
    for _ in range(80):
        x1, x2 = b - phi * (b - a), a + phi * (b - a)
        if err(x1) < err(x2):
            b = x2
        else:
            a = x1
    return 0.5 * (a + b)


def test_cosine_sharpness_is_the_least_squares_fit(lib):
    require(lib, "vsgl_sg_cosine_sharpness")
    want = _least_squares_cosine_sharpness()
    assert L.sg_cosine_sharpness() == pytest.approx(want, rel=1e-5)


def _cos_cases(rng, count):
    for _ in range(count):
        n = rand_unit(rng)
        lam = 10 ** rng.uniform(-3, 4)
        c = rng.uniform(-1, 1)
        if rng.uniform() < 0.3:  # near the horizon
            c = rng.uniform(-3, 3) / math.sqrt(lam + 1)
            c = max(-1.0, min(1.0, c))
        F = R.frame_from_z(n)
        axis = math.sqrt(1 - c * c) * F[0] + c * F[2]
        yield n, axis, lam, rng.uniform(-3, 3)


def test_cosine_integral_pulled_out_formula(lib, rng):
    require(lib, "vsgl_sg_cosine_integral")
    for n, axis, lam, la in _cos_cases(rng, 200):
        g, (x, l32, la32) = c_sg(axis, lam, la)
        n32 = np.float32(n).astype(float)
        want = max(np.dot(R.unit(x), R.unit(n32)), 0.0) * math.exp(la32) * R.quad_sg_integral(l32)
        got = L.sg_cosine_integral(g, n32, L.CosineMode.PULLED_OUT)
        assert got == pytest.approx(want, rel=1e-5, abs=1e-6 * math.exp(la32) * R.sg_area(l32)), \
            (g, n32)


def test_cosine_integral_sg_mode_vs_quadrature(lib, rng):
    require(lib, "vsgl_sg_cosine_integral", "vsgl_sg_cosine_sharpness")
    ld = L.sg_cosine_sharpness()
    for n, axis, lam, la in _cos_cases(rng, 80):
        g, a = c_sg(axis, lam, la)
        n32 = np.float32(n).astype(float)
        prod = R.quad_sg_product(a, (n32, ld, 0.0))
        want = np.pi * prod / R.sg_area(ld)
        got = L.sg_cosine_integral(g, n32, "sg")
        assert got == pytest.approx(want, rel=_exp_tol(math.log(max(want, 1e-300)), ld),
                                    abs=1e-37), (g, n32)


# docs/math.md, "SG x clamped cosine": the ACCURATE form is within
# 1.5e-3 A(l) (absolute error over the lobe's integral) of the exact value.
ACCURATE_ABS_OVER_A = 1.5e-3


def test_cosine_integral_accurate_vs_quadrature(lib, rng):
    require(lib, "vsgl_sg_cosine_integral")
    for n, axis, lam, la in _cos_cases(rng, 150):
        g, (x, l32, la32) = c_sg(axis, lam, la)
        n32 = np.float32(n).astype(float)
        want = R.quad_sg_clamped_cosine(x, l32, la32, n32)
        lobe = math.exp(la32) * R.sg_area(l32)
        got = L.sg_cosine_integral(g, n32, L.CosineMode.ACCURATE)
        assert abs(got - want) <= ACCURATE_ABS_OVER_A * lobe + 1e-6 * want, (
            "accurate cosine integral: got %g want %g (lobe integral %g) for %s n=%s"
            % (got, want, lobe, g, n32))
    # unknown modes behave as ACCURATE
    g = L.SG([0.6, 0, 0.8], 3.0, 0.0)
    assert L.sg_cosine_integral(g, [0, 0, 1], 99) == L.sg_cosine_integral(g, [0, 0, 1], "accurate")


@pytest.mark.parametrize("mode", list(L.CosineMode))
@pytest.mark.parametrize("lam", [0.0, 1e-8, 1e6, 1e30])
@pytest.mark.parametrize("c", [1.0, 1e-4, 0.0, -1e-4, -1.0])
def test_cosine_integral_finite_nonnegative(lib, mode, lam, c):
    require(lib, "vsgl_sg_cosine_integral")
    g = L.SG([math.sqrt(1 - c * c), 0, c], lam, 0.0)
    got = L.sg_cosine_integral(g, [0, 0, 1], mode)
    assert math.isfinite(got) and got >= 0, (mode, lam, c, got)
    if mode == L.CosineMode.PULLED_OUT:
        assert got <= 4 * np.pi * (1 + 1e-6)
    else:  # pi is the integral of 1 * max(cos, 0), the most a lobe of peak 1 can give
        assert got <= np.pi * (1 + 1e-5), (mode, lam, c, got)
    assert L.sg_cosine_integral(L.SG([0, 0, 1], lam, -math.inf), [0, 0, 1], mode) == 0.0


def test_sharpness_from_mean_length(lib, rng):
    require(lib, "vsgl_sharpness_from_mean_length")
    rs = np.concatenate([rng.uniform(0, 1, 200), 1 - 10 ** rng.uniform(-7, -1, 50),
                         10 ** rng.uniform(-8, -1, 20)])
    for r in rs:
        r32 = R.f32(r)
        if r32 >= 1.0:
            continue
        tok = min(r32 / (1 - r32), LAM_MAX)
        ban = min(r32 * (3 - r32 * r32) / (1 - r32 * r32), LAM_MAX)
        assert L.sharpness_from_mean_length(r, "toksvig") == pytest.approx(tok, rel=4e-6), r32
        assert L.sharpness_from_mean_length(r, L.SharpnessEstimator.BANERJEE) == pytest.approx(
            ban, rel=4e-6), r32
    for est in L.SharpnessEstimator:
        assert L.sharpness_from_mean_length(0.0, est) == 0.0
        assert L.sharpness_from_mean_length(-0.5, est) == 0.0
        assert L.sharpness_from_mean_length(math.nan, est) == 0.0
        top = L.sharpness_from_mean_length(1.0, est)
        assert math.isfinite(top) and 0 < top <= LAM_MAX
        assert L.sharpness_from_mean_length(2.0, est) <= LAM_MAX


def _vmf_mean_cosine(lam):
    """Quadrature of the mean of w.xi under the normalised SG (vMF)."""
    u, w = R.graded_rule(0.0, 2.0, [(0.0, 1.0 / max(lam, 1e-300))], 24)
    g = np.exp(-lam * u)
    return float(np.sum(w * g * (1 - u)) / np.sum(w * g))


@pytest.mark.parametrize("lam", [1e-6, 1e-3, 0.1, 0.5, 1.0, 2.2925, 10.0, 1e3, 1e6])
def test_mean_length_from_sharpness(lib, lam):
    require(lib, "vsgl_mean_length_from_sharpness")
    l32 = R.f32(lam)
    # Banerjee: the vMF's true mean length (coth - 1/lambda), by quadrature
    want = _vmf_mean_cosine(l32)
    assert L.mean_length_from_sharpness(lam, "banerjee") == pytest.approx(want, rel=2e-5, abs=1e-12)
    assert L.mean_length_from_sharpness(lam, "toksvig") == pytest.approx(l32 / (l32 + 1), rel=2e-6)
    # Toksvig round trip
    r = L.mean_length_from_sharpness(lam, "toksvig")
    assert L.sharpness_from_mean_length(r, "toksvig") == pytest.approx(l32, rel=1e-5 * (1 + l32))


def test_zero_lobes_propagate(lib):
    """sg.h: a zero axis gives a zero-lobe result; -inf log-amplitude is an exact zero."""
    require(lib, "vsgl_sg_product", "vsgl_sg_product_integral", "vsgl_sg_lobe_integral")
    live = L.SG([0, 0, 1], 4.0, 0.3)
    for dead in (L.SG([0, 0, 0], 4.0, 0.0), L.SG([0, 1, 0], 4.0, -math.inf)):
        p = L.sg_product(live, dead)
        assert L.sg_lobe_integral(p) == 0.0, p
        assert L.sg_product_integral(live, dead) == 0.0
        assert L.sg_product_integral(dead, live) == 0.0
