"""The brute-force reference's exact BRDF (vsgl/reference.h) through the
binding: physical properties checked by numpy quadrature (lobe albedos,
reciprocity, Lambert limit, nothing below the horizon)."""

import math

import numpy as np
import pytest

import libvsgl as L
import vsgl_reference as R
from conftest import require


def _pairs(wi, wo, n=(0.0, 0.0, 1.0), t=(1.0, 0.0, 0.0)):
    wi = np.ascontiguousarray(np.atleast_2d(wi), np.float32)
    N = len(wi)
    wo = np.ascontiguousarray(np.broadcast_to(np.asarray(wo, np.float32), (N, 3)))
    nn = np.ascontiguousarray(np.broadcast_to(np.asarray(n, np.float32), (N, 3)))
    tt = np.ascontiguousarray(np.broadcast_to(np.asarray(t, np.float32), (N, 3)))
    return nn, tt, wi, wo


MATERIALS = [
    dict(base_color=(1, 1, 1), roughness=0.5, specular_f0=0.04),
    dict(base_color=(1, 1, 1), roughness=0.2, metallic=1.0),
    dict(base_color=(0.9, 0.5, 0.1), roughness=0.8, metallic=0.3, specular_f0=0.08),
    dict(base_color=(1, 1, 1), roughness=0.35, specular_f0=0.04, anisotropy=0.7),
]


@pytest.mark.parametrize("mat", MATERIALS)
@pytest.mark.parametrize("theta_o", [0.0, 0.7, 1.3])
def test_lobe_albedos(lib, mat, theta_o):
    """docs/units.md, "Materials": the diffuse lobe is Lambert base (1 - metallic)/pi,
    so its albedo is exactly base (1 - metallic); the glossy lobe's albedo is <= 1
    (their sum may exceed 1, as in Cycles 3.x's Principled BSDF)."""
    require(lib, "vsgl_reference_brdf")
    m = L.Material(**mat)
    wo = np.array([math.sin(theta_o), 0.0, math.cos(theta_o)])
    refl = np.array([-wo[0], -wo[1], wo[2]])
    alpha = max(mat["roughness"] ** 2, 1e-3)
    F = np.eye(3)
    cx, cy = R.disk_centres(F, refl, alpha)
    dirs, w = R.disk_rule(F, cx, cy, 16)
    diff, glos = L.reference_brdf(m, *_pairs(dirs, wo))
    cos_i = dirs[:, 2][:, None]
    # disk_rule integrates max(v.z, 0) h(v): h = (f cos) / cos
    a_diff = np.sum(w[:, None] * diff.astype(float) / cos_i, axis=0)
    a_glos = np.sum(w[:, None] * glos.astype(float) / cos_i, axis=0)
    want = np.array(mat["base_color"], float) * (1 - mat.get("metallic", 0.0))
    np.testing.assert_allclose(a_diff, want, rtol=1e-4, atol=1e-6, err_msg=str((mat, theta_o)))
    assert np.all(a_glos <= 1.0 + 1e-3) and np.all(a_glos > 0), (mat, theta_o, a_glos)


def test_lambert_limit(lib):
    """A rough dielectric with no specular layer is Lambertian: albedo/pi * cos."""
    require(lib, "vsgl_reference_brdf")
    m = L.Material(base_color=(0.8, 0.4, 0.2), roughness=1.0, specular_f0=0.0)
    rng = np.random.default_rng(2)
    wi = R.unit_rows(rng.normal(size=(200, 3)) * [1, 1, 0.5] + [0, 0, 0.6])
    wo = R.unit([0.3, -0.2, 0.9])
    diff, glos = L.reference_brdf(m, *_pairs(wi, wo))
    want = np.maximum(wi[:, 2], 0)[:, None] * np.array([0.8, 0.4, 0.2]) / np.pi
    np.testing.assert_allclose(diff, want, rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(glos, 0.0, atol=1e-7)


@pytest.mark.parametrize("mat", MATERIALS)
def test_reciprocity_and_horizon(lib, mat):
    require(lib, "vsgl_reference_brdf")
    m = L.Material(**mat)
    rng = np.random.default_rng(4)
    a = R.unit_rows(rng.normal(size=(300, 3)))
    b = R.unit_rows(rng.normal(size=(300, 3)))
    n = np.broadcast_to(np.float32([0, 0, 1]), (300, 3))
    t = np.broadcast_to(np.float32([1, 0, 0]), (300, 3))
    args = [np.ascontiguousarray(x, np.float32) for x in (n, t, a, b)]
    d1, g1 = L.reference_brdf(m, *args)
    d2, g2 = L.reference_brdf(m, args[0], args[1], args[3], args[2])
    below = (a[:, 2] <= 0) | (b[:, 2] <= 0)
    assert np.all(d1[below] == 0) and np.all(g1[below] == 0)
    ok = ~below & (a[:, 2] > 0.05) & (b[:, 2] > 0.05)
    ca, cb = a[ok, 2:3], b[ok, 2:3]
    np.testing.assert_allclose((d1[ok] + g1[ok]) / ca, (d2[ok] + g2[ok]) / cb, rtol=1e-4, atol=1e-6)


def test_reference_brdf_validation(lib):
    require(lib, "vsgl_reference_brdf")
    m = L.Material(base_color=(1, 1, 1))
    n, t, wi, wo = _pairs([[0, 0, 1.0]], [0, 0, 1.0])
    with pytest.raises(TypeError):
        L.reference_brdf(m, n.astype(np.float64), t, wi, wo)
    with pytest.raises(ValueError):
        L.reference_brdf(m, n, t, np.zeros((2, 3), np.float32), wo)
    with pytest.raises(TypeError):
        L.reference_brdf(dict(base_color=(1, 1, 1)), n, t, wi, wo)
