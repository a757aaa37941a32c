"""The metrics against hand-computed cases (pytest, or called by check.py)."""
import math
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import metrics as M  # noqa: E402


def _img(seed=0, h=12, w=16):
    return np.random.default_rng(seed).uniform(0.1, 1.0, (h, w, 3))


def test_bias_of_a_scaled_image():
    x = _img()
    assert abs(M.bias(1.25 * x, x) - 1.25) < 1e-12
    assert abs(M.bias(x, x) - 1.0) < 1e-12
    assert math.isnan(M.bias(x, np.zeros_like(x)))


def test_relmse_by_hand():
    b = np.full((4, 4, 3), 0.3)
    a = b + 0.1
    want = 0.1 ** 2 / (0.3 ** 2 + 0.01)  # = 0.1
    assert abs(M.relmse(a, b) - want) < 1e-12


def test_downsample_is_a_box_mean():
    x = np.arange(8 * 8, dtype=float).reshape(8, 8, 1)
    d = M.downsample(x, 4)
    assert d.shape == (2, 2, 1)
    assert d[0, 0, 0] == np.mean(x[:4, :4]) and d[1, 1, 0] == np.mean(x[4:, 4:])
    # a size that is not a multiple of 4 is cropped
    assert M.downsample(np.ones((10, 9, 3)), 4).shape == (2, 2, 3)


def test_structured_error_ignores_pixel_noise_but_keeps_blotches():
    b = np.full((16, 16, 3), 0.5)
    checker = (np.indices((16, 16)).sum(0) % 2 * 2 - 1)[..., None] * 0.05  # +-0.05, zero mean per 4x4 block
    assert abs(M.relmse(b + checker, b) - 0.05 ** 2 / 0.26) < 1e-12
    assert M.structured(b + checker, b) < 1e-20
    blotch = np.zeros((16, 16, 3))
    blotch[:4, :4] = 0.1  # one 4x4 block 0.1 too bright: 1 block of 16
    assert abs(M.structured(b + blotch, b) - (0.1 ** 2 / 0.26) / 16) < 1e-12


def test_reference_noise_of_a_two_seed_mean():
    # c1 = t + n, c2 = t - n: the mean is exact, its estimate relmse(c1, c2)/4 = mean(4 n^2/(c2^2+eps))/4
    t = np.full((8, 8, 3), 0.5)
    n = np.full((8, 8, 3), 0.02)
    want = np.mean((2 * n) ** 2 / ((t - n) ** 2 + 0.01)) / 4
    assert abs(M.ref_noise(t + n, t - n, 1) - want) < 1e-12
    # independent noise: the estimate matches the mean's true error on average, within 10 % (its
    # denominator is a noisy seed, not the truth: 1/(c^2 + eps) averages a little high, +6 % at 10 % noise)
    rng = np.random.default_rng(3)
    t = np.full((64, 64, 3), 0.5)
    est, true = [], []
    for _ in range(20):
        c1, c2 = t + rng.normal(0, 0.05, t.shape), t + rng.normal(0, 0.05, t.shape)
        est.append(M.ref_noise(c1, c2, 1))
        true.append(M.relmse(0.5 * (c1 + c2), t))
    assert abs(np.mean(est) / np.mean(true) - 1) < 0.10


def test_seed_agreement():
    rng = np.random.default_rng(1)
    t = np.full((60, 80, 3), 0.4)
    z = [M.seed_agreement(t + rng.normal(0, 0.05, t.shape), t + rng.normal(0, 0.05, t.shape)) for _ in range(50)]
    assert abs(np.mean(z)) < 0.5 and 0.6 < np.std(z) < 1.4   # ~ standard normal
    assert M.seed_agreement(t * 1.01 + rng.normal(0, 0.05, t.shape), t + rng.normal(0, 0.05, t.shape)) > 4
    assert math.isnan(M.seed_agreement(t, t))


def test_flicker_of_a_linear_ramp():
    x = _img(2)
    frames = [(1 + 0.01 * t) * x for t in range(12)]
    f = M.flicker(frames)
    want = [0.01 / (1 + 0.01 * t) for t in range(11)]
    assert np.allclose(f["first"], want, rtol=1e-9)
    assert abs(f["median"] - np.median(want)) < 1e-12
    assert f["median_second"] < 1e-12 and f["ratio"] < 1e-9      # smooth: no second difference
    assert abs(f["l1"] - np.median(want)) < 1e-12                  # uniform scaling: L1 = RMS
    assert abs(f["mean"] - np.mean(want)) < 1e-12


def test_flicker_mean_step_of_a_burst_and_of_its_smooth_spread():
    # the truth moves in a burst (two big steps), a smooth render spreads the
    # same total change over every frame: its median step is the larger, its
    # mean the same (the acceptance's "Cycles' mean step")
    x = _img(3)
    burst = np.cumsum([0.0, 0.005, 0.005, 0.005, 0.04, 0.04, 0.005, 0.005])
    smooth = np.linspace(0.0, burst[-1], len(burst))
    fb = M.flicker([(1 + 0.0 * b) * x + b for b in burst])
    fs = M.flicker([(1 + 0.0 * b) * x + b for b in smooth])
    assert fs["median"] > fb["median"] * 1.5
    assert abs(fs["mean"] - fb["mean"]) < 0.1 * fb["mean"]


def test_flicker_l1_is_not_dominated_by_one_hot_pixel():
    x = np.full((60, 80, 3), 0.1)
    frames = []
    for t in range(6):
        y = x.copy()
        y[30, 40] = 3.0 if t % 2 else 0.5   # one junction pixel jumping
        frames.append(y)
    f = M.flicker(frames)
    assert f["median"] > 0.3                 # the RMS form: dominated by that pixel
    assert f["l1"] < 0.01                    # the L1 form: 1 pixel of 4800


def test_flicker_of_an_alternating_sequence_is_jitter():
    x = _img(4)
    e = 0.02
    frames = [(1 + e * (-1) ** t) * x for t in range(12)]
    f = M.flicker(frames)
    # first difference 2e/(1 +- e), second 4e/(1 -+ e): ratio ~2
    assert abs(f["median"] - np.median([2 * e / (1 + e * (-1) ** t) for t in range(11)])) < 1e-12
    assert 1.9 < f["ratio"] < 2.1


def test_flip_of_identical_images_is_zero():
    if M.FLIP_ERROR:
        import pytest
        pytest.skip("flip-evaluator does not import: %s" % M.FLIP_ERROR)
    x = _img(5, 32, 32).astype(np.float32)
    assert M.flip(x, x) < 1e-6
    assert M.flip(1.5 * x, x) > 0.01


TESTS = [v for k, v in sorted(globals().items()) if k.startswith("test_")]


def test_excess_flicker_removes_the_motions_own_change():
    x = _img(5)
    truth = [(1 + 0.03 * t) * x for t in range(8)]              # the true change: 3 % a frame
    same = [g.copy() for g in truth]
    assert M.flicker(same)["median"] > 0.02                      # plain flicker sees the motion
    assert M.excess_flicker(same, truth) < 1e-12                 # nothing beyond it
    jitter = [g * (1 + 0.01 * (-1) ** t) for t, g in enumerate(truth)]
    e = M.excess_flicker(jitter, truth)
    assert 0.015 < e < 0.025                                     # +-1 % alternating: ~2 % a frame
    with pytest.raises(ValueError):
        M.excess_flicker(same, truth[:-1])


def test_motion_change_removes_independent_noise():
    rng = np.random.default_rng(3)
    f0 = _img(5, 40, 50)
    d = 0.002 * _img(6, 40, 50)  # the true change per frame
    steps = 11
    seeds = [(f0 + rng.normal(0, 0.02, f0.shape), f0 + steps * d + rng.normal(0, 0.02, f0.shape)) for _ in range(2)]
    want = M._rel(d, f0)
    got = M.motion_change((seeds[0][0], seeds[1][0]), (seeds[0][1], seeds[1][1]), steps)
    naive = M._rel((seeds[0][1] - seeds[0][0]) / steps, f0)
    assert abs(got - want) < 0.1 * want
    assert naive > 1.5 * want  # one seed's difference is noise-dominated here
    # no motion: nothing measurable above the noise
    again = [seeds[k][0] + rng.normal(0, 0.02, f0.shape) for k in range(2)]
    still = M.motion_change((seeds[0][0], seeds[1][0]), (again[0], again[1]), steps)
    assert still < 0.2 * want


def _edge_sequence(n=12, h=30, w=40, speed=0.35):
    """A bright square sliding right by `speed` px a frame over a dim
    background, each pixel the area it covers (a box-filtered edge)."""
    xs = np.arange(w, dtype=np.float64)
    out = []
    for t in range(n):
        left = 10.0 + speed * t
        cover = np.clip(np.minimum(xs + 1, left + 12) - np.maximum(xs, left), 0, 1)
        img = 0.1 + 0.9 * np.tile(cover, (h, 1))
        out.append(np.repeat(img[..., None], 3, axis=2))
    return out


def test_motion_steps_keep_an_edges_jumps_and_remove_noise():
    truth = _edge_sequence()
    rng = np.random.default_rng(11)
    seeds = [[f + rng.normal(0, 0.1, f.shape) for f in truth] for _ in range(2)]
    want = [M._rel(truth[t + 1] - truth[t], truth[t]) for t in range(len(truth) - 1)]
    got = M.motion_steps(seeds[0], seeds[1])
    assert max(abs(g - w) for g, w in zip(got, want)) < 0.15 * max(want)
    assert abs(np.median(got) - np.median(want)) < 0.1 * np.median(want)
    naive = M.flicker(seeds[0])["median"]
    assert naive > 1.5 * np.median(want)  # one seed's steps are noise-dominated here
    # the straight line from the first to the last frame misses the edge's per-frame change
    line = M.motion_change((seeds[0][0], seeds[1][0]), (seeds[0][-1], seeds[1][-1]), len(truth) - 1)
    assert line < 0.8 * np.median(want)
    with pytest.raises(ValueError):
        M.motion_steps(seeds[0], seeds[1][:-1])


def test_firefly_mask_finds_a_kept_firefly_and_not_an_edge_or_noise():
    truth = _edge_sequence()
    rng = np.random.default_rng(13)
    seeds = [[f + rng.normal(0, 0.01, f.shape) for f in truth] for _ in range(2)]
    assert not M.firefly_mask(seeds[0], seeds[1]).any()  # the seeds agree about the edge's steps
    # seed 2 finds a firefly at (5, 3) in frame 4 and keeps it (a fixed seed per frame)
    for t in range(4, len(truth)):
        seeds[1][t][5, 3] += 6.0
    m = M.firefly_mask(seeds[0], seeds[1])
    assert m[5, 3] and m.sum() == 1
    # the same jump in both seeds is the motion, not a firefly
    for t in range(4, len(truth)):
        seeds[0][t][5, 3] += 6.0
    assert not M.firefly_mask(seeds[0], seeds[1]).any()
    # masked: the pixel no longer counts in either sequence's steps
    clean = M.masked(seeds[1], m)
    assert clean[6][5, 3, 0] == 0.0 and clean[6][5, 4, 0] == seeds[1][6][5, 4, 0]
    with pytest.raises(ValueError):
        M.firefly_mask(seeds[0], seeds[1][:-1])


def test_excess_over_seeds_is_zero_for_the_truth_and_sees_a_jittering_edge():
    truth = _edge_sequence()
    rng = np.random.default_rng(12)
    seeds = [[f + rng.normal(0, 0.05, f.shape) for f in truth] for _ in range(2)]
    step = np.median([M._rel(truth[t + 1] - truth[t], truth[t]) for t in range(len(truth) - 1)])
    assert M.excess_over_seeds(truth, seeds[0], seeds[1]) < 0.2 * step
    # point-sampled (aliased) edge: the same motion in whole-pixel jumps
    aliased = [np.where(f > 0.55, 1.0, 0.1) for f in truth]
    assert M.excess_over_seeds(aliased, seeds[0], seeds[1]) > 0.5 * step
    with pytest.raises(ValueError):
        M.excess_over_seeds(truth[:-1], seeds[0], seeds[1])


def test_jitter_of_a_ramp_is_zero_and_of_a_reshuffle_is_not():
    base = _img(7)
    ramp = [base * (1 + 0.01 * t) for t in range(8)]
    assert M.jitter(ramp) < 1e-12 < M.flicker(ramp)["median"]
    rng = np.random.default_rng(8)
    shuffled = [x * (1 + 0.02 * rng.standard_normal(x.shape)) for x in ramp]
    assert M.jitter(shuffled) > 0.02  # two independent 2 % perturbations per pair


def test_rel_rmse_by_hand():
    b = np.full((4, 4, 3), 2.0)
    assert abs(M.rel_rmse(b * 1.1, b) - 0.1) < 1e-12


def test_pareto_front_against_the_definition():
    rng = np.random.default_rng(3)
    for _ in range(50):
        n = int(rng.integers(1, 30))
        t = rng.choice([0.5, 1.0, 2.0, 3.0], n) if rng.random() < 0.3 else rng.uniform(0, 1, n)
        e = rng.uniform(0, 1, n)
        # independent: i is on the front iff no j is <= in both and < in one (duplicates kept once)
        want = set()
        for i in range(n):
            dominated = any((t[j] <= t[i] and e[j] <= e[i] and (t[j] < t[i] or e[j] < e[i])) for j in range(n))
            dup_before = any(t[j] == t[i] and e[j] == e[i] for j in range(n) if j != i and j in want)
            if not dominated and not dup_before:
                want.add(i)
        got = M.pareto_front(t, e)
        assert set(got) == want, (t, e)
        assert list(np.asarray(t)[got]) == sorted(np.asarray(t)[got])


def test_pareto_front_ties():
    # equal error at a higher time is dominated; equal time at a higher error too
    assert M.pareto_front([1.0, 2.0, 3.0], [0.5, 0.5, 0.2]) == [0, 2]
    assert M.pareto_front([1.0, 1.0, 3.0], [0.6, 0.5, 0.2]) == [1, 2]
    assert M.pareto_front([2.0, float("nan"), 1.0], [0.1, 0.0, 0.3]) == [2, 0]


def test_time_at_error_on_a_power_law():
    t = np.array([1.0, 4.0, 16.0, 64.0])
    e = 0.3 / t  # error inversely proportional to time: exact in log-log
    got, how = M.time_at_error(t, e, 0.3 / 10.0)
    assert how == "reached" and abs(got - 10.0) < 1e-9
    assert M.time_at_error(t, e, 1.0) == (1.0, "first")
    assert M.time_at_error(t, e, 1e-4) == (64.0, "never")
