"""csrc/src/math/asg_table.c is what tools/gen_asg_table.py generates: a
sample of entries regenerated from the library's exact integral (the C
test asg_integral_fast_within_its_bound checks every node against an
independent quadrature)."""
import numpy as np
import pytest

import gen_asg_table as gen  # tools/ is on setup.cfg's pythonpath


def test_sampled_entries_regenerate():
    t = gen.parse()
    assert t.shape == (gen.NX, gen.NY)
    L = gen._lib()
    rng = np.random.default_rng(11)
    cells = [(0, 0), (gen.NX - 1, gen.NY - 1), (gen.NX - 1, 0), (0, gen.NY - 1)]
    cells += [tuple(int(v) for v in (rng.integers(0, gen.NX), rng.integers(0, gen.NY))) for _ in range(24)]
    for i, j in cells:
        assert gen.entry(L, i, j) == pytest.approx(float(t[i, j]), rel=2e-7), (i, j)


def test_table_is_smooth_and_bounded():
    """g is 1 at (0, 0) and in the Gaussian limit, ~1.3 at most between."""
    t = gen.parse()
    assert t[-1, -1] == pytest.approx(1.0, abs=1e-6)
    assert 0.99 < t.min() and t.max() < 1.35
    # second differences along each axis are small beside the values (a bad row shows)
    assert np.abs(np.diff(t, 2, axis=0)).max() < 0.002 and np.abs(np.diff(t, 2, axis=1)).max() < 0.002
