"""The references themselves: the quadrature rules of vsgl_reference.py
against closed forms (so a failing SG/ASG test points at the library)."""

import math

import numpy as np
import pytest

import vsgl_reference as R


@pytest.mark.parametrize("lam", [0.0, 1e-8, 0.3, 1.0, 7.0, 250.0, 1e5, 1e9, 2.0 ** 41])
def test_sg_integral_quadrature(lam):
    assert R.quad_sg_integral(lam) == pytest.approx(R.sg_area(lam), rel=1e-12)


@pytest.mark.parametrize("lam", [0.5, 3.0, 40.0, 1e4])
def test_axis_rule_integrates_sphere_and_sg(lam):
    axis = R.unit([0.3, -0.2, 0.9])
    dirs, w = R.axis_rule(axis, 1.0 / lam)
    assert np.sum(w) == pytest.approx(4 * np.pi, rel=1e-12)
    got = R.integrate_log(R.sg_log(axis, lam, 0.0), dirs, w)
    assert got == pytest.approx(R.sg_area(lam), rel=1e-10)


@pytest.mark.parametrize("lam", [0.2, 2.0, 30.0, 1e3, 1e5])
@pytest.mark.parametrize("tilt", [0.0, 0.7, 1.5, 2.5])
def test_disk_rule_sg_cosine_matches_closed_form_aligned(lam, tilt):
    # n = z; SG axis tilted by `tilt` radians. Closed form for tilt 0:
    # int_0^1 c e^{lam (c - 1)} 2 pi dc. For other tilts, compare with a brute
    # polar rule about n (fine grid; smooth integrand on the hemisphere).
    n = np.array([0.0, 0.0, 1.0])
    axis = np.array([math.sin(tilt), 0.0, math.cos(tilt)])
    got = R.quad_sg_clamped_cosine(axis, lam, 0.0, n)
    if tilt == 0.0:
        want = 2 * np.pi * (lam - 1 + math.exp(-lam)) / lam ** 2
    else:
        ct, wt = R.graded_rule(0.0, 1.0, [(math.cos(tilt), 1 / lam), (0.0, 1 / lam)], 40)
        ph, wp = R.graded_rule(-np.pi, np.pi, [(0.0, 1 / math.sqrt(lam))], 40)
        st = np.sqrt(1 - ct ** 2)
        dot = st[:, None] * math.sin(tilt) * np.cos(ph)[None, :] + ct[:, None] * math.cos(tilt)
        want = float(np.sum(wt[:, None] * wp[None, :] * ct[:, None] * np.exp(lam * (dot - 1))))
    assert got == pytest.approx(want, rel=1e-9, abs=1e-300)


@pytest.mark.parametrize("lam,mu", [(0.5, 0.5), (3.0, 3.0), (50.0, 50.0), (1e4, 1e4)])
def test_disk_rule_isotropic_asg_integral(lam, mu):
    # lam = mu: int z exp(-lam (1 - z^2)) over the hemisphere = pi (1 - e^-lam) / lam
    F = R.frame_from_z([0.2, 0.3, 0.9])
    got = R.quad_asg_times((F[0], F[1], F[2], lam, mu, 0.0))
    assert got == pytest.approx(np.pi * -math.expm1(-lam) / lam, rel=1e-11)


@pytest.mark.parametrize("lam,mu", [(20.0, 2000.0), (1e4, 30.0), (300.0, 3.0)])
def test_disk_rule_anisotropic_asg_integral(lam, mu):
    # for sharp lobes the disk integral is the Gaussian pi / sqrt(lam mu) times
    # erf(sqrt(lam)) erf(sqrt(mu)) up to the (tiny) part outside the disk
    F = R.frame_from_z([0.0, 0.0, 1.0])
    got = R.quad_asg_times((F[0], F[1], F[2], lam, mu, 0.0))
    want = np.pi / math.sqrt(lam * mu) * math.erf(math.sqrt(lam)) * math.erf(math.sqrt(mu))
    # the square [-1,1]^2 minus the disk contributes at most exp(-min(lam, mu))
    assert abs(got - want) <= 2 * math.exp(-min(lam, mu)) * want + 1e-12 * want


@pytest.mark.parametrize("a", [0.0, 1e-6, 0.5, 3.0, 40.0, 1e4, 1e8])
def test_bessel_f_quadrature(a):
    # F(a) = 2 pi e^{-a/2} I0(a/2); np.i0 is fine up to a ~ 1400
    if a < 1000:
        want = 2 * np.pi * math.exp(-a / 2) * float(np.i0(a / 2))
    else:  # asymptotic: 2 pi e^{-a/2} I0(a/2) ~ 2 sqrt(pi / a) (1 + 1/(4a) + 9/(32 a^2))
        want = 2 * math.sqrt(np.pi / a) * (1 + 1 / (4 * a) + 9 / (32 * a * a))
    assert R.bessel_f_quad(a) == pytest.approx(want, rel=1e-10)


def test_sg_product_quadrature_matches_closed_form():
    rng = np.random.default_rng(5)
    for _ in range(20):
        x1, x2 = R.unit(rng.normal(size=3)), R.unit(rng.normal(size=3))
        l1, l2 = 10 ** rng.uniform(-2, 4, size=2)
        s = l1 * x1 + l2 * x2
        lm = np.linalg.norm(s)
        want = math.exp(lm - l1 - l2) * R.sg_area(lm)
        got = R.quad_sg_product((x1, l1, 0.0), (x2, l2, 0.0))
        assert got == pytest.approx(want, rel=1e-9), (x1, x2, l1, l2)
