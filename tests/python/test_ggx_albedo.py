"""csrc/src/scene/ggx_albedo.c is what tools/gen_ggx_albedo.py generates:
a sample of entries regenerated, the row averages from the file's own
rows, and the estimator against an independent quadrature."""
import numpy as np
import pytest

import gen_ggx_albedo as gen  # tools/ is on setup.cfg's pythonpath


def test_sampled_entries_regenerate_exactly():
    t, _ = gen.parse()
    assert t.shape == (32, 32)
    rng = np.random.default_rng(7)
    cells = [(0, 0), (31, 31), (31, 0), (0, 31)] + [tuple(rng.integers(0, 32, 2)) for _ in range(12)]
    for j, k in cells:
        assert round(gen.e1(gen.cosine(k), j / 31), 5) == pytest.approx(t[j, k], abs=1e-9), (j, k)


def test_row_averages_follow_from_the_rows():
    t, avg = gen.parse()
    np.testing.assert_allclose(gen.row_averages(t), avg, atol=1e-9)


@pytest.mark.parametrize("roughness,mu", [(0.3, 0.7), (0.6, 0.25), (0.9, 0.9)])
def test_estimator_against_quadrature(roughness, mu):
    """E1 by brute-force quadrature over the outgoing hemisphere with the
    same BRDF (D G2 / (4 n.o n.i), F = 1): an independent check of the
    importance-sampling estimator the table comes from."""
    a = roughness * roughness
    n_t, n_p = 1200, 720
    ct = (np.arange(n_t) + 0.5) / n_t                    # cos(theta_i), uniform
    ph = (np.arange(n_p) + 0.5) / n_p * 2 * np.pi
    C, P = np.meshgrid(ct, ph, indexing="ij")
    S = np.sqrt(1 - C * C)
    i = np.stack([S * np.cos(P), S * np.sin(P), C], -1)
    o = np.array([np.sqrt(1 - mu * mu), 0.0, mu])
    h = i + o
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    nh = h[..., 2]
    D = a * a / (np.pi * ((nh * nh) * (a * a - 1) + 1) ** 2)
    G2 = 1 / (1 + gen.smith_lambda(a, mu) + gen.smith_lambda(a, C))
    f = D * G2 / (4 * mu * C)
    quad = float((f * C).sum() * (1.0 / n_t) * (2 * np.pi / n_p))
    assert gen.e1(mu, roughness) == pytest.approx(quad, rel=2e-3)
