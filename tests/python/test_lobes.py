"""Reflection lobes (vsgl/lobes.h) against numpy re-implementations of the
documented formulas, quadrature (normalisation) and a finite-difference
Hessian of the exactly warped NDF (spherical warping of an ASG)."""

import math

import numpy as np
import pytest

import libvsgl
import vsgl_reference as R
from conftest import require
from vsgl_reference import asg_log, dirs_near, rand_frame

L = libvsgl
LAM_MAX = 2.0 ** 41
ALPHA_MIN = 2.0 ** -31


def f32v(v):
    return np.float32(v).astype(float)


def rand_unit(rng):
    return R.unit(rng.normal(size=3))


def as_tuple(a):
    return (np.array(a.x), np.array(a.y), np.array(a.z), a.lam, a.mu, a.log_amplitude)


def test_lambert_to_sg_is_a_normalised_lobe_about_n(lib, rng):
    require(lib, "vsgl_lambert_to_sg", "vsgl_sg_cosine_sharpness")
    ld = L.sg_cosine_sharpness()
    for _ in range(20):
        n = f32v(rand_unit(rng) * rng.uniform(0.5, 2))
        g = L.lambert_to_sg(n)
        assert np.allclose(g.axis, R.unit(n), atol=3e-7), (n, g)
        assert g.sharpness == pytest.approx(ld, rel=1e-6)
        # integral of exp(log_amp + ld (w.n - 1)) over the sphere = 1 (max(w.n,0)/pi integrates to 1)
        total = math.exp(g.log_amplitude) * R.quad_sg_integral(g.sharpness)
        assert total == pytest.approx(1.0, rel=2e-6), g


@pytest.mark.parametrize("alpha", [0.0, 1e-12, ALPHA_MIN, 1e-6, 1e-3, 0.05, 0.3, 1.0, 1.5, 10.0])
def test_ndf_sharpness(lib, alpha):
    require(lib, "vsgl_ndf_sharpness")
    a = min(max(R.f32(alpha), ALPHA_MIN), 1.0)
    want = min(2.0 / (a * a), LAM_MAX)
    assert L.ndf_sharpness(alpha) == pytest.approx(want, rel=2e-6), alpha


@pytest.mark.parametrize("ndf", list(L.NDF))
def test_ndf_to_sg(lib, rng, ndf):
    require(lib, "vsgl_ndf_to_sg")
    for alpha in [1e-4, 1e-2, 0.05, 0.1, 0.2, 0.5, 1.0]:
        n = f32v(rand_unit(rng))
        g = L.ndf_to_sg(n, alpha, ndf)
        a = R.f32(alpha)
        assert np.allclose(g.axis, R.unit(n), atol=3e-7), (n, alpha, g)
        assert g.sharpness == pytest.approx(min(2 / a ** 2, LAM_MAX), rel=2e-6), (alpha, g)
        assert g.log_amplitude == pytest.approx(-math.log(math.pi * a * a), abs=2e-6 * (1 + abs(math.log(a)))), g
        if alpha <= 0.2:
            # an NDF is normalised as  int D(h) (h.n) dh = 1; the SG fit to O(alpha^2)
            proj = R.quad_sg_clamped_cosine(np.array(g.axis), g.sharpness, g.log_amplitude, n)
            assert proj == pytest.approx(1.0, abs=alpha ** 2 + 1e-5), (alpha, proj)


def test_ndf_aniso_to_asg(lib, rng):
    require(lib, "vsgl_ndf_aniso_to_asg")
    for _ in range(60):
        n = f32v(rand_unit(rng))
        t = f32v(rand_unit(rng))
        if abs(R.unit(n) @ R.unit(t)) > 0.95:
            continue
        ax, ay = 10 ** rng.uniform(-3, 0, size=2)
        a = L.ndf_aniso_to_asg(n, t, ax, ay)
        z = R.unit(n)
        x = R.unit(t - (t @ z) * z)
        y = np.cross(z, x)
        ax32, ay32 = R.f32(ax), R.f32(ay)
        ref = (x, y, z, 1 / ax32 ** 2, 1 / ay32 ** 2, -math.log(math.pi * ax32 * ay32))
        got = as_tuple(a)
        assert np.dot(got[2], z) > 1 - 1e-6 and np.dot(got[0], x) > 1 - 1e-5, (n, t, a)
        assert got[3] == pytest.approx(ref[3], rel=3e-6) and got[4] == pytest.approx(ref[4], rel=3e-6), a
        assert got[5] == pytest.approx(ref[5], abs=3e-6 * (1 + abs(ref[5]))), a
        d = dirs_near(z, 1 / math.sqrt(min(ref[3], ref[4])), rng, 8)
        gl, rl = asg_log(got, d), asg_log(ref, d)
        ok = rl > ref[5] - 50
        assert np.all(np.abs(gl[ok] - rl[ok]) <= 2e-5 * (1 + ref[3] + ref[4])), (n, t, a)


def reflect(o, n):
    return 2 * np.dot(o, n) * n - o


def test_warp_ndf_sg_formula(lib, rng):
    require(lib, "vsgl_warp_ndf_sg")
    for _ in range(100):
        n = f32v(rand_unit(rng))
        o = f32v(rand_unit(rng))
        lam = 10 ** rng.uniform(-1, 6)
        ndf = L.SG(n, np.float32(lam), np.float32(rng.uniform(-5, 5)))
        w = L.warp_ndf_sg(ndf, o)
        nn, oo = R.unit(n), R.unit(o)
        on = max(abs(oo @ nn), 1e-6)
        assert np.allclose(R.unit(np.array(w.axis)), R.unit(reflect(oo, nn)), atol=2e-6), (ndf, o, w)
        assert w.sharpness == pytest.approx(min(ndf.sharpness / (4 * on), LAM_MAX),
                                            rel=1e-5 + 2e-7 / on), (ndf, o, w)
        assert w.log_amplitude == ndf.log_amplitude


def _warped_exponent_hessian(ndf, o, i0, h=1e-4):
    """2x2 Hessian at i0 (tangent-plane exponential-map coordinates, basis
    e1, e2) of E(i) = -lam (h(i).x)^2 - mu (h(i).y)^2, h(i) = (i + o)/|i + o|."""
    x, y, z, lam, mu, _ = ndf
    F = R.frame_from_z(i0)
    e1, e2 = F[0], F[1]

    def E(a, b):
        t = math.hypot(a, b)
        d = e1 * a + e2 * b
        i = i0 * math.cos(t) + (d / t * math.sin(t) if t > 0 else 0)
        hv = R.unit(i + o)
        return -lam * (hv @ x) ** 2 - mu * (hv @ y) ** 2
    H = np.empty((2, 2))
    H[0, 0] = (E(h, 0) - 2 * E(0, 0) + E(-h, 0)) / h ** 2
    H[1, 1] = (E(0, h) - 2 * E(0, 0) + E(0, -h)) / h ** 2
    H[0, 1] = H[1, 0] = (E(h, h) - E(h, -h) - E(-h, h) + E(-h, -h)) / (4 * h * h)
    return H, e1, e2


def test_warp_ndf_asg_matches_exact_warp_hessian(lib, rng):
    require(lib, "vsgl_warp_ndf_asg")
    done = 0
    while done < 60:
        F = rand_frame(rng)
        o = R.unit(rng.normal(size=3))
        on = o @ F[2]
        if on < 0.2:
            continue
        done += 1
        lam, mu = 10 ** rng.uniform(0, 4, size=2)
        a = L.ASG(np.float32(F[0]), np.float32(F[1]), np.float32(F[2]), np.float32(lam),
                  np.float32(mu), 0.0)
        ndf = as_tuple(a)
        o32 = f32v(o)
        w = as_tuple(L.warp_ndf_asg(a, o32))
        i0 = reflect(R.unit(o32), R.unit(ndf[2]))
        assert np.dot(R.unit(w[2]), i0) > 1 - 1e-6, (a, o32, w)
        H, e1, e2 = _warped_exponent_hessian(ndf, R.unit(o32), i0)
        # the ASG's exponent -lam'(v.x')^2 - mu'(v.y')^2 has Hessian -2 (lam' x'x'^T + mu' y'y'^T)
        P = np.array([e1, e2])
        Hw = -2 * P @ (w[3] * np.outer(w[0], w[0]) + w[4] * np.outer(w[1], w[1])) @ P.T
        scale = np.max(np.abs(H))
        assert np.allclose(Hw, H, atol=2e-3 * scale), (a, o32, w, H, Hw)


def test_warp_ndf_asg_isotropic_closed_form(lib):
    require(lib, "vsgl_warp_ndf_asg")
    s = 400.0
    for on in (1.0, 0.8, 0.5, 0.3):
        o = np.array([math.sqrt(1 - on * on), 0.0, on])
        a = L.ASG([1, 0, 0], [0, 1, 0], [0, 0, 1], s / 2, s / 2, 0.0)  # SG of sharpness s
        w = L.warp_ndf_asg(a, np.float32(o))
        bands = sorted([w.lam, w.mu])
        want = sorted([s / (8 * on * on), s / 8])
        assert bands == pytest.approx(want, rel=1e-4), (on, w)


def _g2_height_correlated(ci, co, a):
    lam = lambda c: (math.sqrt(1 + a * a * (1 - c * c) / (c * c)) - 1) / 2  # noqa: E731
    return 1 / (1 + lam(ci) + lam(co))


def test_specular_factor(lib, rng):
    """M = F_schlick(i.h; f0) G2 / (4 |o.n|), G2 Smith GGX height-correlated
    (lobes.c; lobes.h says only "G2_smith_ggx")."""
    require(lib, "vsgl_specular_factor")
    for _ in range(300):
        n = f32v(rand_unit(rng))
        o = f32v(rand_unit(rng))
        i = f32v(rand_unit(rng))
        alpha = 10 ** rng.uniform(-3, 0)
        f0 = rng.uniform(0, 1)
        got = L.specular_factor(n, o, i, alpha, f0)
        nn, oo, ii = R.unit(n), R.unit(o), R.unit(i)
        co, ci = oo @ nn, ii @ nn
        if co <= 0 or ci <= 0:
            assert got == 0.0
            continue
        if min(co, ci) < 1e-3:
            continue
        hv = R.unit(ii + oo)
        a = R.f32(alpha)
        F = R.f32(f0) + (1 - R.f32(f0)) * (1 - ii @ hv) ** 5
        want = F * _g2_height_correlated(ci, co, a) / (4 * co)
        assert got == pytest.approx(want, rel=2e-5 / min(ci, co)), (n, o, i, alpha, f0)


@pytest.mark.parametrize("which", ["ward", "ashikhmin_shirley"])
def test_ward_and_ashikhmin_shirley_to_asg(lib, rng, which):
    name = "vsgl_ward_to_asg" if which == "ward" else "vsgl_ashikhmin_shirley_to_asg"
    require(lib, name)
    for _ in range(50):
        n = f32v(rand_unit(rng))
        t = f32v(rand_unit(rng))
        if abs(R.unit(n) @ R.unit(t)) > 0.95:
            continue
        if which == "ward":
            p, q = 10 ** rng.uniform(-3, 0, size=2)
            a = L.ward_to_asg(n, t, p, q)
            want = (1 / R.f32(p) ** 2, 1 / R.f32(q) ** 2)
        else:
            p, q = 10 ** rng.uniform(0, 4, size=2)
            a = L.ashikhmin_shirley_to_asg(n, t, p, q)
            want = (R.f32(p) / 2, R.f32(q) / 2)
        z = R.unit(n)
        x = R.unit(t - (t @ z) * z)
        got = as_tuple(a)
        assert np.dot(got[2], z) > 1 - 1e-6 and np.dot(got[0], x) > 1 - 1e-5, (n, t, a)
        assert np.allclose(got[1], np.cross(z, x), atol=3e-6), "frame [x, y, n] right-handed: %s" % (a,)
        assert (a.lam, a.mu) == pytest.approx(want, rel=3e-6), a
        assert a.log_amplitude == 0.0, a
