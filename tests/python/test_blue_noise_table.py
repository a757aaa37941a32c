"""csrc/src/shade/blue_noise_table.c is what tools/gen_blue_noise.py
generates, and it is blue noise: every rank once, thresholded at any of
the 16 levels the visibility rays pick from its cells spread evenly (no
two of a level's cells are adjacent more often than a white-noise mask's),
and its spectrum holds almost nothing at low frequencies."""
import re

import numpy as np

import gen_blue_noise as gen  # tools/ is on setup.cfg's pythonpath


def _table():
    with open(gen.PATH) as f:
        text = f.read()
    body = text[text.index("= {") + 3:text.rindex("};")]
    return np.array([int(v) for v in re.findall(r"\d+", body)]).reshape(gen.N, gen.N)


def test_file_is_what_the_generator_writes():
    with open(gen.PATH) as f:
        assert f.read() == gen.c_file(gen.mask())


def test_every_rank_once_and_levels_spread():
    t = _table()
    assert sorted(t.ravel().tolist()) == list(range(gen.N * gen.N))
    level = t >> 8  # the 16 levels vsgl__ray_target_for reads
    same_blue = np.mean([np.mean(level == np.roll(level, 1, a)) for a in (0, 1)])
    white = np.random.default_rng(3).integers(0, 16, t.shape)
    same_white = np.mean([np.mean(white == np.roll(white, 1, a)) for a in (0, 1)])
    # neighbours share a level 1/16 of the time in white noise, far less in blue noise
    assert same_blue < 0.25 * same_white, (same_blue, same_white)


def test_spectrum_is_blue():
    t = _table().astype(float)
    f = np.abs(np.fft.fft2(t - t.mean())) ** 2
    k = np.fft.fftfreq(gen.N) * gen.N
    r = np.hypot(*np.meshgrid(k, k))
    low, high = f[(r > 0) & (r <= 8)].mean(), f[r >= 16].mean()
    assert low < 0.05 * high, (low, high)
