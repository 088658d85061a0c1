"""Tests of the typical-cycle construction: neighbours, resampling, root integration."""

from __future__ import annotations


import numpy as np
import pytest

from cyclecoord.periodic.cycle import (
    TypicalCycle,
    integrate_root,
    kernel_centroids,
    knn_centroids,
    resample_cyclic,
    select_bandwidth,
    typical_cycle,
)
from cyclecoord.periodic.density import PeriodicDensity
from cyclecoord.errors import ParameterError
from cyclecoord.quality.metrics import circular_distance, distance_to_cycle

PERIOD = 100  # frames per period of the synthetic motion
WARP = 0.5  # phase speed varies between 1 - WARP and 1 + WARP


def curve(phi: np.ndarray) -> np.ndarray:
    """A closed 5-D Lissajous curve, shape (len(phi), 5)."""
    a = 2 * np.pi * np.asarray(phi, dtype=float)
    return np.stack(
        [np.cos(a), np.sin(a), 0.5 * np.cos(2 * a), 0.3 * np.sin(3 * a), 0.4 * np.cos(a + 1.0)], axis=1
    )


def warp(tau: np.ndarray) -> np.ndarray:
    """Phase (unwrapped) at time tau (in periods): monotone, uneven speed."""
    return tau + WARP * np.sin(2 * np.pi * tau) / (2 * np.pi)


@pytest.fixture(scope="module")
def noisy_motion():
    rng = np.random.default_rng(11)
    t = np.arange(4 * PERIOD)
    phase = warp(t / PERIOD)
    clean = curve(phase)
    poses = clean + 0.05 * rng.standard_normal(clean.shape)
    return np.mod(phase, 1.0), poses, clean


# ------------------------------------------------------------------- knn_centroids
def brute_force_centroids(theta, poses, phases, k):
    out = []
    for p in phases:
        d = circular_distance(theta, p)
        out.append(poses[np.argsort(d, kind="stable")[:k]].mean(axis=0))
    return np.array(out)


@pytest.mark.parametrize("k", [1, 3, 10, 37])
def test_knn_centroids_match_brute_force(k):
    rng = np.random.default_rng(k)
    theta = rng.random(37)
    poses = rng.standard_normal((37, 4))
    phases = np.concatenate([rng.random(200), [0.0, 1e-9, 0.5, 1 - 1e-9]])
    np.testing.assert_allclose(
        knn_centroids(theta, poses, phases, k=k), brute_force_centroids(theta, poses, phases, k), atol=1e-12
    )


def test_knn_centroids_use_both_sides_of_the_seam():
    n = 100
    theta = (np.arange(n) + 0.5) / n
    signed = np.where(theta < 0.5, theta, theta - 1.0)  # signed offset from phase 0
    poses = np.stack([signed, np.cos(2 * np.pi * theta)], axis=1)
    out = knn_centroids(theta, poses, np.array([0.0, 0.999999, 1e-6]), k=10)
    # neighbours 0.005..0.045 and 0.955..0.995: symmetric, mean offset 0
    np.testing.assert_allclose(out[:, 0], 0.0, atol=1e-5)
    assert np.all(out[:, 1] > np.cos(2 * np.pi * 0.05))
    # the neighbours of phase 0 at k=10 are exactly the 5 lowest and 5 highest frames
    single = knn_centroids(theta, np.arange(n, dtype=float), [0.0], k=10)
    assert single[0, 0] == pytest.approx(np.mean([0, 1, 2, 3, 4, 95, 96, 97, 98, 99]))


def test_gaussian_weighting_pulls_towards_nearest():
    theta = np.array([0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9])
    poses = np.arange(10.0)[:, None]
    mean = knn_centroids(theta, poses, [0.21], k=3, weighting="mean")
    gauss = knn_centroids(theta, poses, [0.21], k=3, weighting="gaussian", bandwidth=0.02)
    assert mean[0, 0] == pytest.approx(2.0)
    assert 2.0 < gauss[0, 0] < 2.2  # dominated by frame 2, pulled towards frame 3
    wide = knn_centroids(theta, poses, [0.21], k=3, weighting="gaussian", bandwidth=100.0)
    assert wide[0, 0] == pytest.approx(2.0, abs=1e-3)
    default = knn_centroids(theta, poses, [0.21, 0.5], k=3, weighting="gaussian")
    assert default.shape == (2, 1)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"k": 0},
        {"k": 11},
        {"k": 2.5},
        {"weighting": "median"},
        {"weighting": "gaussian", "bandwidth": -1.0},
    ],
)
def test_knn_centroids_bad_parameters(kwargs):
    theta = np.linspace(0, 1, 10, endpoint=False)
    with pytest.raises(ParameterError):
        knn_centroids(theta, np.zeros((10, 2)), [0.5], **kwargs)


def test_knn_centroids_bad_arrays():
    theta = np.linspace(0, 1, 10, endpoint=False)
    with pytest.raises(ParameterError):
        knn_centroids(theta, np.zeros((9, 2)), [0.5])
    with pytest.raises(ParameterError):
        knn_centroids(theta, np.zeros((10, 2)), [np.nan])
    with pytest.raises(ParameterError):
        knn_centroids(theta[:, None], np.zeros((10, 2)), [0.5])


# ----------------------------------------------------------------- resample_cyclic
def test_resample_circle_exact_to_interpolation_error():
    rng = np.random.default_rng(3)
    times = np.sort(rng.random(64))
    circle = np.stack([np.cos(2 * np.pi * times), np.sin(2 * np.pi * times)], axis=1)
    out = resample_cyclic(circle[::-1], 100, times=times[::-1])  # order does not matter
    q = np.arange(100) / 100
    exact = np.stack([np.cos(2 * np.pi * q), np.sin(2 * np.pi * q)], axis=1)
    gaps = np.diff(np.concatenate([times, [times[0] + 1]]))
    sagitta = 1 - np.cos(np.pi * gaps.max())  # largest chord-to-arc distance
    assert np.abs(np.linalg.norm(out - exact, axis=1)).max() <= sagitta + 1e-12
    # and the resampled points lie on the chords: |x| between cos(pi gap) and 1
    assert np.all(np.linalg.norm(out, axis=1) <= 1 + 1e-12)


def test_resample_polygon_is_exact_including_wrap():
    # a closed square traversed at constant speed; samples include the corners
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    times = np.array([0.0, 0.25, 0.5, 0.75, 0.1, 0.9])
    def square(t):
        t = np.mod(t, 1.0) * 4
        i = np.floor(t).astype(int) % 4
        f = (t - np.floor(t))[:, None]
        return corners[i] * (1 - f) + corners[(i + 1) % 4] * f
    out = resample_cyclic(square(times), 40, times=times)
    np.testing.assert_allclose(out, square(np.arange(40) / 40), atol=1e-12)
    # default times i / N
    np.testing.assert_allclose(resample_cyclic(corners, 8), square(np.arange(8) / 8), atol=1e-12)


def test_resample_bad_input():
    with pytest.raises(ParameterError):
        resample_cyclic(np.zeros((5, 2)), 1)
    with pytest.raises(ParameterError):
        resample_cyclic(np.zeros((5, 2)), 10, times=np.zeros(4))
    with pytest.raises(ParameterError):
        resample_cyclic(np.zeros((0, 2)), 10)


# ------------------------------------------------------------------ integrate_root
def test_integrate_root_cumulative_sum():
    deltas = np.array([[1.0, 0.0], [2.0, 1.0], [3.0, -1.0]])
    out = integrate_root(deltas, start=[10.0, 5.0])
    np.testing.assert_allclose(out, [[10, 5], [11, 5], [13, 6]])
    back = integrate_root(deltas, start=[10.0, 5.0], convention="backward")
    np.testing.assert_allclose(back, [[10, 5], [12, 6], [15, 5]])


def test_integrate_root_hits_displacement_exactly():
    rng = np.random.default_rng(0)
    deltas = rng.normal(1.0, 0.3, size=(97, 3))
    target = np.array([40.0, -2.5, 0.0])
    out = integrate_root(deltas, start=[1.0, 2.0, 3.0], displacement=target)
    np.testing.assert_array_equal(out[0], [1.0, 2.0, 3.0])
    steps = np.diff(out, axis=0)
    const = steps - deltas[:-1]
    np.testing.assert_allclose(const, const[0][None, :].repeat(96, axis=0), atol=1e-12)  # same shift
    last_step = deltas[-1] + const[0]
    np.testing.assert_allclose(out[-1] + last_step - out[0], target, atol=1e-10)
    # looping: next cycle starts exactly one displacement further
    np.testing.assert_allclose(steps.sum(axis=0) + last_step, target, atol=1e-10)


def test_integrate_root_bad_shapes():
    with pytest.raises(ParameterError):
        integrate_root(np.zeros((5, 2)), start=[0.0])
    with pytest.raises(ParameterError):
        integrate_root(np.zeros((5, 2)), start=[0.0, 0.0], displacement=[1.0])
    with pytest.raises(ParameterError):
        integrate_root(np.zeros((5, 2)), start=[0.0, 0.0], convention="sideways")


# -------------------------------------------------------------------- typical_cycle
@pytest.mark.parametrize("weighting", ["kernel", "mean", "gaussian"])
@pytest.mark.parametrize("sampling", ["quantile", "random"])
def test_typical_cycle_is_closer_to_truth_than_frames(noisy_motion, sampling, weighting):
    theta, poses, clean = noisy_motion
    cyc = typical_cycle(theta, poses, PERIOD, sampling=sampling, weighting=weighting, random_state=0)
    assert isinstance(cyc, TypicalCycle)
    assert cyc.frames.shape == (PERIOD, 5)
    assert cyc.curve.shape == (500, 5)
    assert cyc.sample_phases.shape == (500,)
    assert np.all(np.diff(cyc.sample_phases) >= 0)
    assert cyc.phases[0] == 0.0 and np.all(np.diff(cyc.phases) > 0) and cyc.phases[-1] < 1

    noise_err = np.linalg.norm(poses - clean, axis=1).mean()
    curve_err = np.linalg.norm(cyc.curve - curve(cyc.sample_phases), axis=1).mean()
    frame_err = np.linalg.norm(cyc.frames - curve(cyc.phases), axis=1).mean()
    assert curve_err < 0.5 * noise_err
    assert frame_err < 0.5 * noise_err
    # the cycle's polyline runs through the true curve: the clean poses lie close to it
    assert distance_to_cycle(clean, cyc.frames).mean() < 0.5 * noise_err


@pytest.mark.parametrize("sampling", ["quantile", "random"])
def test_typical_cycle_keeps_the_timing(noisy_motion, sampling):
    """Frame j sits at time j / P: its phase follows the motion's uneven speed."""
    theta, poses, _ = noisy_motion
    cyc = typical_cycle(theta, poses, PERIOD, sampling=sampling, random_state=1)
    expected = np.mod(warp(np.arange(PERIOD) / PERIOD), 1.0)  # warp(0) = 0
    assert circular_distance(cyc.phases, expected).max() < 0.02
    # an even-speed (uniform) parameterisation would be far off
    assert circular_distance(np.arange(PERIOD) / PERIOD, expected).max() > 0.05


def test_typical_cycle_reuses_density_and_is_deterministic(noisy_motion):
    theta, poses, _ = noisy_motion
    density = PeriodicDensity(random_state=4).fit(theta)
    a = typical_cycle(theta, poses, 99.6, density=density, n_samples=300, k=5)
    b = typical_cycle(theta, poses, 99.6, density=density, n_samples=300, k=5)
    assert a.frames.shape == (100, 5)
    np.testing.assert_array_equal(a.frames, b.frames)
    c = typical_cycle(theta, poses, 50, sampling="random", random_state=9)
    d = typical_cycle(theta, poses, 50, sampling="random", random_state=9)
    np.testing.assert_array_equal(c.frames, d.frames)
    with pytest.raises(ValueError):
        a.frames[0, 0] = 1.0  # read-only result


@pytest.mark.parametrize(
    "kwargs",
    [
        {"period_frames": 1.2},
        {"period_frames": float("nan")},
        {"sampling": "grid"},
        {"weighting": "max"},
        {"n_samples": 0},
        {"k": 10_000},
        {"density": PeriodicDensity()},  # not fitted
    ],
)
def test_typical_cycle_bad_parameters(noisy_motion, kwargs):
    theta, poses, _ = noisy_motion
    args = {"period_frames": 100, **kwargs}
    with pytest.raises(ParameterError):
        typical_cycle(theta, poses, **args)



def test_kernel_centroids_are_smooth_where_knn_jumps():
    """Two repetitions that differ: the k-nearest mean jumps as frames enter and leave,
    the kernel average changes smoothly (small second differences along the phase)."""
    T = 400
    theta = np.mod(np.arange(T) / 200.0, 1.0)  # two cycles
    poses = np.zeros((T, 1))
    poses[200:, 0] = 1.0  # the second repetition is offset
    poses[:, 0] += np.sin(2 * np.pi * theta)
    q = np.linspace(0, 1, 2000, endpoint=False)
    knn = knn_centroids(theta, poses, q, k=10)
    ker = kernel_centroids(theta, poses, q, k=10)
    # both average the two repetitions
    np.testing.assert_allclose(ker[:, 0], 0.5 + np.sin(2 * np.pi * q), atol=0.01)
    assert np.abs(np.diff(ker[:, 0], 2)).max() < 0.2 * np.abs(np.diff(knn[:, 0], 2)).max()


def test_kernel_centroids_validate():
    with pytest.raises(ParameterError):
        kernel_centroids(np.zeros(5), np.zeros((4, 2)), np.zeros(3))
    with pytest.raises(ParameterError):
        kernel_centroids(np.zeros(5), np.zeros((5, 2)), np.zeros(3), k=6)


# ------------------------------------------------------------ bandwidth selection
def noisy_sine(noise, cycles=8, per=100, seed=0):
    rng = np.random.default_rng(seed)
    theta = np.mod(np.arange(cycles * per) / per, 1.0)
    truth = np.stack([np.sin(2 * np.pi * theta), np.cos(4 * np.pi * theta)], axis=1)
    return theta, truth + noise * rng.standard_normal(truth.shape), per


def test_select_bandwidth_smooths_a_noisy_sine():
    theta, poses, per = noisy_sine(0.5)
    sel = select_bandwidth(theta, poses, per)
    narrow = sel.candidates[0]
    assert narrow <= 0.5 < sel.bandwidth <= per / 8
    assert sel.cv_error.shape == sel.candidates.shape == sel.cv_se.shape
    assert sel.cv_error[sel.index] == sel.cv_error.min()
    q = np.arange(200) / 200
    truth = np.stack([np.sin(2 * np.pi * q), np.cos(4 * np.pi * q)], axis=1)
    err = lambda w: np.sqrt(np.mean((kernel_centroids(theta, poses, q, bandwidth=w / per) - truth) ** 2))
    assert err(sel.bandwidth) < 0.5 * err(narrow)
    # the one-standard-error rule never picks a narrower width
    assert select_bandwidth(theta, poses, per, rule="1se").bandwidth >= sel.bandwidth


def test_select_bandwidth_keeps_a_clean_curve_sharp():
    theta, poses, per = noisy_sine(0.0)
    poses = np.sin(2 * np.pi * 5 * theta)[:, None]  # five bumps a period, no noise
    sel = select_bandwidth(theta, poses, per)
    assert sel.bandwidth <= sel.candidates[1]


def test_select_bandwidth_exclude_and_query():
    theta, poses, per = noisy_sine(0.3, cycles=3)
    a = select_bandwidth(theta, poses, per, exclude=2, max_validation=50)
    assert a.exclude == 2 and a.n_validation == 50
    # predicting every frame far from its own phase makes every width bad
    b = select_bandwidth(theta, poses, per, query=np.mod(theta + 0.5, 1.0))
    assert b.cv_error.min() > 5 * select_bandwidth(theta, poses, per).cv_error.min()


@pytest.mark.parametrize(
    "kwargs",
    [
        {"rule": "median"},
        {"exclude": -1},
        {"candidates": [0.0, 1.0]},
        {"candidates": []},
        {"period_frames": 0.0},
        {"max_width": -3.0},
        {"query": np.zeros(5)},
    ],
)
def test_select_bandwidth_bad_parameters(kwargs):
    theta, poses, per = noisy_sine(0.3, cycles=2)
    args = {"period_frames": per, **kwargs}
    with pytest.raises(ParameterError):
        select_bandwidth(theta, poses, **args)


@pytest.mark.parametrize("bandwidth", [0.0, -1.0, float("nan"), float("inf"), "wide", True])
def test_bad_bandwidths_are_refused(noisy_motion, bandwidth):
    theta, poses, _ = noisy_motion
    with pytest.raises(ParameterError):
        typical_cycle(theta, poses, PERIOD, bandwidth=bandwidth)
    if not isinstance(bandwidth, str):
        with pytest.raises(ParameterError):
            kernel_centroids(theta, poses, [0.5], bandwidth=bandwidth)


def test_a_bandwidth_needs_the_kernel(noisy_motion):
    theta, poses, _ = noisy_motion
    with pytest.raises(ParameterError):
        typical_cycle(theta, poses, PERIOD, weighting="mean", bandwidth=3.0)
    with pytest.raises(ParameterError, match="needs weighting='kernel'"):
        typical_cycle(theta, poses, PERIOD, weighting="mean", bandwidth="auto")
    assert np.isnan(typical_cycle(theta, poses, PERIOD, weighting="mean").bandwidth)


def test_typical_cycle_reports_its_bandwidth(noisy_motion):
    theta, poses, clean = noisy_motion
    legacy = typical_cycle(theta, poses, PERIOD, random_state=0)
    assert legacy.bandwidth == pytest.approx(10 / (len(theta) * np.sqrt(2 * np.pi)) * PERIOD)
    assert legacy.bandwidth_selection is None
    auto = typical_cycle(theta, poses, PERIOD, bandwidth="auto", random_state=0)
    assert auto.bandwidth == auto.bandwidth_selection.bandwidth > legacy.bandwidth
    err = lambda c: np.linalg.norm(c.frames - curve(c.phases), axis=1).mean()
    # within the density fit's noise: with scikit-learn's k-means start this held for
    # seed 0 only (seeds 1 and 2: 2% worse); the deterministic start: 2% worse
    assert err(auto) < 1.05 * err(legacy)
    fixed = typical_cycle(theta, poses, PERIOD, bandwidth=auto.bandwidth, random_state=0)
    np.testing.assert_allclose(fixed.frames, auto.frames)


def _dense_kernel(theta, poses, phases, sigma):
    """The textbook Nadaraya-Watson sum over every frame (the reference)."""
    d = np.mod(phases[:, None] - theta[None, :] + 0.5, 1.0) - 0.5
    w = np.exp(-0.5 * (d / sigma) ** 2)
    tot = w.sum(axis=1)
    out = (w / np.where(tot < 1e-300, 1.0, tot)[:, None]) @ poses
    for r in np.flatnonzero(tot < 1e-300):
        out[r] = poses[np.argmin(np.abs(d[r]))]
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_windowed_kernel_centroids_equal_the_dense_sum(seed):
    rng = np.random.default_rng(seed)
    T = int(rng.integers(3000, 9000))
    # uneven coordinate: a dense stretch, a sparse one and an empty gap of 0.05
    theta = np.concatenate([rng.random(T // 2) * 0.3, 0.35 + rng.random(T - T // 2) * 0.65])
    theta[:5] = [0.0, 1.0 - 1e-17, 0.9999999, 1e-12, 0.5]  # values at the seam
    poses = rng.normal(size=(T, 7)) * rng.uniform(0.1, 100.0, size=7)
    phases = np.concatenate([rng.random(300), [0.0, 0.32, 0.33, 0.999999, 0.5]])
    for k in (1, 10, 37):
        sigma = k / (T * np.sqrt(2.0 * np.pi))
        got = kernel_centroids(theta, poses, phases, k=k, chunk_elements=5000)
        want = _dense_kernel(np.mod(theta, 1.0) % 1.0, poses, phases, sigma)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(poses).max())
    # widths in phase units, from narrower than a frame to wider than the window rule allows
    for sigma in (1e-6, 3e-4, 0.004, 0.2):
        got = kernel_centroids(theta, poses, phases, bandwidth=sigma)
        want = _dense_kernel(np.mod(theta, 1.0) % 1.0, poses, phases, sigma)
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.abs(poses).max())


def test_heldout_times_interpolate_from_the_neighbours_left_out():
    """Each frame's time is read from frames ``exclude + 1`` before and after it (their
    midpoint), the end frames extrapolated linearly from their one-sided neighbours; with
    fewer than ``2 exclude + 4`` frames the frames' own times are given.  With the cdf the
    identity and theta_i = i^2 / 100 the answers are exact: frame i's midpoint of
    frames i -+ 2 is (i^2 + 4) / 100."""
    from types import SimpleNamespace

    from cyclecoord.periodic.cycle import _heldout_times

    identity = SimpleNamespace(cdf=lambda x: np.asarray(x, dtype=float))
    i = np.arange(10)
    theta = i**2 / 100
    out = _heldout_times(theta, identity, exclude=1)
    np.testing.assert_allclose(out[2:8], (i[2:8] ** 2 + 4) / 100, atol=1e-12)
    # frame 0 from frames 2 and 3: 0.04 - 2 (0.09 - 0.04) = -0.06, wrapped; frame 9 from 7, 6
    np.testing.assert_allclose(out[[0, 1, 8, 9]], [0.94, 0.95, 0.58, 0.75], atol=1e-12)
    np.testing.assert_allclose(_heldout_times(theta[:5], identity, exclude=1), theta[:5], atol=1e-15)
    # six frames are the fewest read from neighbours with exclude=1
    np.testing.assert_allclose(_heldout_times(theta[:6], identity, exclude=1),
                               [0.94, 0.95, 0.08, 0.13, 0.10, 0.19], atol=1e-12)
    for n in (2, 3):
        np.testing.assert_allclose(_heldout_times(theta[[0, 4, 9]][:n], identity), theta[[0, 4, 9]][:n], atol=1e-15)
    # four frames are the fewest read from neighbours with exclude=0
    np.testing.assert_allclose(_heldout_times(theta[[0, 1, 3, 6]], identity),
                               [0.93, 0.045, 0.185, 0.17], atol=1e-12)


def test_select_bandwidth_needs_two_exclude_plus_two_frames():
    """With ``exclude=1`` four frames are enough (each keeps one frame to predict it from);
    three are refused."""
    theta = np.arange(4) / 4.0
    poses = np.cos(2 * np.pi * theta)[:, None]
    sel = select_bandwidth(theta, poses, 4.0, k=1, exclude=1, candidates=[0.5, 1.0])
    assert np.isfinite(sel.bandwidth) and np.all(np.isfinite(sel.cv_error))
    with pytest.raises(ParameterError, match="too few"):
        select_bandwidth(theta[:3], poses[:3], 4.0, k=1, exclude=1, candidates=[0.5, 1.0])


# ------------------------------------------------- known answers, helper by helper
def test_wrap01_keeps_every_value_in_the_unit_interval():
    """``x mod 1`` in [0, 1): -1e-17 % 1 rounds to 1.0 in floating point and becomes 0."""
    from cyclecoord.periodic.cycle import _wrap01

    x = np.array([-1e-17, 0.0, 1.0, 2.25, -0.25, 0.999, -3.5])
    np.testing.assert_array_equal(_wrap01(x), [0.0, 0.0, 0.0, 0.25, 0.75, 0.999, 0.5])


def brute_force_gaussian(theta, poses, phases, k, bandwidth=None):
    """k nearest frames by circular distance, weighted exp(-d^2 / (2 bw^2)); the default
    bandwidth is the median over the phases of the k-th neighbour's distance."""
    near, dist = [], []
    for p in phases:
        d = circular_distance(theta, p)
        idx = np.argsort(d, kind="stable")[:k]
        near.append(idx)
        dist.append(d[idx])
    bw = np.median([d.max() for d in dist]) if bandwidth is None else bandwidth
    out = []
    for idx, d in zip(near, dist):
        w = np.exp(-d**2 / (2 * bw**2))
        out.append(w @ poses[idx] / w.sum())
    return np.array(out)


@pytest.mark.parametrize("k", [2, 5, 23])
@pytest.mark.parametrize("bandwidth", [None, 0.01, 0.3])
def test_gaussian_knn_centroids_match_brute_force(k, bandwidth):
    rng = np.random.default_rng(100 + k)
    theta = rng.random(23)
    poses = rng.standard_normal((23, 3))
    phases = np.concatenate([rng.random(40), [0.0, 0.5, 1 - 1e-9]])
    got = knn_centroids(theta, poses, phases, k=k, weighting="gaussian", bandwidth=bandwidth)
    np.testing.assert_allclose(got, brute_force_gaussian(theta, poses, phases, k, bandwidth), atol=1e-12)


def test_gaussian_knn_centroids_tend_to_the_nearest_frame_as_the_bandwidth_shrinks():
    """Neighbours 0.04 and 0.06 away with a bandwidth of 1e-3: the farther one's weight is
    e^(-(0.06^2 - 0.04^2) / 2e-6) = e^-1000 relative to the nearer one's, so the centroid
    is the nearer frame's pose (each weight alone, e^-800 and e^-1800, underflows to 0:
    the result must still be finite)."""
    theta = np.array([0.0, 0.2, 0.3 - 0.04, 0.3 + 0.06, 0.7])
    poses = np.array([0.0, 1.0, 5.0, 9.0, 3.0])[:, None]
    out = knn_centroids(theta, poses, [0.3], k=2, weighting="gaussian", bandwidth=1e-3)
    assert out[0, 0] == pytest.approx(5.0, abs=1e-12)


def test_gaussian_knn_centroids_fall_back_to_the_mean_when_all_neighbours_sit_on_the_phase():
    """Every phase has its k neighbours at distance 0: the default bandwidth (their median
    farthest distance) is 0 and the plain mean is returned."""
    theta = np.array([0.3, 0.3, 0.3, 0.6, 0.6, 0.6])
    poses = np.array([1.0, 2.0, 6.0, 10.0, 20.0, 30.0])[:, None]
    out = knn_centroids(theta, poses, [0.3, 0.6], k=3, weighting="gaussian")
    np.testing.assert_array_equal(out[:, 0], [3.0, 20.0])


def test_knn_centroids_shapes_and_limits():
    theta = np.arange(6) / 6.0
    chan = np.arange(6.0)
    # a 1-D pose array is one channel; k = T averages every frame
    out = knn_centroids(theta, chan, [0.1, 0.6], k=6)
    assert out.shape == (2, 1)
    np.testing.assert_allclose(out[:, 0], 2.5)
    for bad in (7, 0, True, 3.0):
        with pytest.raises(ParameterError):
            knn_centroids(theta, chan, [0.1], k=bad)
    for bad in (0.0, float("inf"), True, "wide"):
        with pytest.raises(ParameterError):
            knn_centroids(theta, chan, [0.1], k=2, weighting="gaussian", bandwidth=bad)
    with pytest.raises(ParameterError):
        knn_centroids(theta, np.zeros((6, 2, 2)), [0.1])


def test_kernel_centroids_of_a_cosine_are_damped_by_the_gaussian_transform():
    """Evenly spaced frames of cos(2 pi m theta): the circular Gaussian average of width
    sigma is exp(-2 pi^2 m^2 sigma^2) cos(2 pi m phi) (the Gaussian's Fourier transform;
    with 1,000 frames the sampling error is far below 1e-9, and the widths are under a
    twelfth of the half period the kernel reaches).  The default width is
    sigma = k / (T sqrt(2 pi)); one given as ``bandwidth`` is used as such."""
    T, m = 1000, 5
    theta = (np.arange(T) + 0.25) / T
    poses = np.cos(2 * np.pi * m * theta)[:, None]
    q = np.linspace(0.0, 1.0, 37, endpoint=False)
    for k in (10, 50, 100):  # 100: wide enough for the dense sum, the others windowed
        sigma = k / (T * np.sqrt(2 * np.pi))
        want = np.exp(-2 * np.pi**2 * m**2 * sigma**2) * np.cos(2 * np.pi * m * q)
        np.testing.assert_allclose(kernel_centroids(theta, poses, q, k=k)[:, 0], want, atol=1e-9)
    for sigma in (0.004, 0.03):
        want = np.exp(-2 * np.pi**2 * m**2 * sigma**2) * np.cos(2 * np.pi * m * q)
        got = kernel_centroids(theta, poses, q, bandwidth=sigma)
        np.testing.assert_allclose(got[:, 0], want, atol=1e-9)


def test_kernel_centroids_limits_of_k():
    theta = np.arange(8) / 8.0
    poses = np.arange(16.0).reshape(8, 2)
    assert kernel_centroids(theta, poses, [0.5], k=8).shape == (1, 2)  # k = T is allowed
    for bad in (9, 0, True, 2.5):
        with pytest.raises(ParameterError):
            kernel_centroids(theta, poses, [0.5], k=bad)


@pytest.mark.parametrize("sigma", [0.01, 0.2])  # the windowed and the dense sum
def test_kernel_centroids_of_a_phase_far_from_every_frame_take_the_nearest(sigma):
    """Frames at 0 and 0.1 only; phase 0.58 is 0.42 and 0.48 away (at least 2.4 widths of
    0.2 -- still weighted -- and 42 widths of 0.01: every weight exactly 0), so with the
    narrow width it takes the pose of the nearer frame (phase 0, across the seam)."""
    from cyclecoord.periodic._kernel import kernel_dense, kernel_windowed

    theta = np.array([0.0, 0.1])
    poses = np.array([[4.0, -1.0], [8.0, 2.0]])
    phases = np.array([0.58, 0.05])
    d = np.array([[0.42, 0.48], [0.05, 0.05]])
    w = np.exp(-0.5 * (d / sigma) ** 2)
    want = (w / w.sum(axis=1, keepdims=True)) @ poses if sigma > 0.1 else np.array([[4.0, -1.0], [6.0, 0.5]])
    for fn in (kernel_dense, kernel_windowed):
        for chunk in (1, 10_000):
            np.testing.assert_allclose(fn(theta, poses, phases, sigma, chunk), want, rtol=1e-12)
    np.testing.assert_allclose(kernel_centroids(theta, poses, phases, k=1, bandwidth=sigma), want, rtol=1e-12)


@pytest.mark.parametrize("chunk", [1, 7, 64, 10_000])
def test_kernel_sums_do_not_depend_on_the_chunk_size(chunk):
    """The chunk only bounds the memory: every phase's average is computed whole, so the
    results equal the brute-force sum whatever the chunk."""
    from cyclecoord.periodic._kernel import kernel_dense, kernel_windowed

    rng = np.random.default_rng(5)
    theta = rng.random(50)
    poses = rng.standard_normal((50, 3))
    phases = rng.random(23)
    for fn, sigma in ((kernel_dense, 0.05), (kernel_windowed, 0.004)):
        np.testing.assert_allclose(fn(theta, poses, phases, sigma, chunk),
                                   _dense_kernel(theta, poses, phases, sigma), rtol=1e-12, atol=1e-12)


# ---------------------------------------------- bandwidth selection, by brute force
def brute_force_cv(theta, query, poses, widths, period, exclude, val):
    """Leave-out squared error of each validation frame (rows) for each width (columns)."""
    T = len(theta)
    err = np.empty((len(val), len(widths)))
    for r, i in enumerate(val):
        keep = np.abs(np.arange(T) - i) > exclude
        d = circular_distance(theta[keep], query[i])
        for g, w in enumerate(widths):
            wt = np.exp(-(d**2) / (2 * (w / period) ** 2))
            pred = wt @ poses[keep] / wt.sum()
            err[r, g] = np.sum((poses[i] - pred) ** 2)
    return err


def _cv_data(T=40, seed=0):
    rng = np.random.default_rng(seed)
    theta = np.mod(np.arange(T) / 10.0 + 0.01 * rng.standard_normal(T), 1.0)
    poses = np.stack([np.sin(2 * np.pi * theta), np.cos(4 * np.pi * theta)], axis=1)
    return theta, poses + 0.2 * rng.standard_normal(poses.shape)


@pytest.mark.parametrize("exclude", [0, 1, 3])
def test_select_bandwidth_errors_match_brute_force(exclude):
    theta, poses = _cv_data()
    widths = np.array([0.3, 0.6, 1.0, 1.5, 2.5])
    query = np.mod(theta + 0.003, 1.0)
    sel = select_bandwidth(theta, poses, 10.0, candidates=widths[::-1], exclude=exclude, query=query,
                           chunk_elements=100)
    err = brute_force_cv(theta, query, poses, widths, 10.0, exclude, np.arange(40))
    np.testing.assert_array_equal(sel.candidates, widths)  # sorted ascending
    np.testing.assert_allclose(sel.cv_error, err.mean(axis=0), rtol=1e-5)  # float32 weights
    np.testing.assert_allclose(sel.cv_se, err.std(axis=0, ddof=1) / np.sqrt(40), rtol=1e-4)
    assert sel.exclude == exclude and sel.n_validation == 40 and sel.rule == "min"
    assert sel.bandwidth == widths[np.argmin(err.mean(axis=0))]
    assert sel.index == np.argmin(err.mean(axis=0))
    # the query defaults to the frames' own phases
    plain = select_bandwidth(theta, poses, 10.0, candidates=widths, exclude=exclude)
    np.testing.assert_allclose(plain.cv_error, brute_force_cv(theta, theta, poses, widths, 10.0, exclude,
                                                              np.arange(40)).mean(axis=0), rtol=1e-5)


def test_select_bandwidth_validates_on_evenly_spaced_frames():
    """max_validation=7 of 40 frames: frames round(linspace(0, 39, 7)) = 0, 6, 13, 20, 26,
    32, 39; with one validation frame the standard error is 0."""
    theta, poses = _cv_data()
    widths = np.array([0.5, 1.0, 2.0])
    sel = select_bandwidth(theta, poses, 10.0, candidates=widths, max_validation=7)
    val = [0, 6, 13, 20, 26, 32, 39]
    err = brute_force_cv(theta, theta, poses, widths, 10.0, 0, val)
    assert sel.n_validation == 7
    np.testing.assert_allclose(sel.cv_error, err.mean(axis=0), rtol=1e-5)
    one = select_bandwidth(theta, poses, 10.0, candidates=widths, max_validation=1)
    assert one.n_validation == 1
    np.testing.assert_allclose(one.cv_error, brute_force_cv(theta, theta, poses, widths, 10.0, 0, [0])[0],
                               rtol=1e-5)
    np.testing.assert_array_equal(one.cv_se, 0.0)
    # with one validation frame "1se" is "min": the least error, with no margin
    assert select_bandwidth(theta, poses, 10.0, candidates=widths, max_validation=1, rule="1se").bandwidth == \
        widths[np.argmin(one.cv_error)]
    # two validation frames (0 and 39) have a standard error (ddof 1) like any number of them
    two = select_bandwidth(theta, poses, 10.0, candidates=widths, max_validation=2)
    err = brute_force_cv(theta, theta, poses, widths, 10.0, 0, [0, 39])
    assert two.n_validation == 2
    np.testing.assert_allclose(two.cv_se, err.std(axis=0, ddof=1) / np.sqrt(2), rtol=1e-4)
    assert np.all(two.cv_se > 0)
    for bad in (0, 2.5, True):
        with pytest.raises(ParameterError):
            select_bandwidth(theta, poses, 10.0, candidates=widths, max_validation=bad)


def test_select_bandwidth_validates_on_at_most_2000_frames_by_default():
    """2,001 frames: 2,000 of them, evenly spaced, are predicted (one width, to stay fast)."""
    theta = np.mod(np.arange(2001) / 50.0, 1.0)
    poses = np.sin(2 * np.pi * theta)[:, None]
    assert select_bandwidth(theta, poses, 50.0, candidates=[1.0]).n_validation == 2000


def test_results_compare_by_identity_and_hash():
    """The results hold arrays: they compare by identity (never element-wise) and can be
    kept in sets and as dict keys."""
    theta, poses = _cv_data()
    a = select_bandwidth(theta, poses, 10.0, candidates=[1.0])
    b = select_bandwidth(theta, poses, 10.0, candidates=[1.0])
    assert a == a and a != b and len({a, b, a}) == 2
    cyc = typical_cycle(theta, poses, 10, n_samples=20, k=3)
    assert cyc == cyc and cyc != typical_cycle(theta, poses, 10, n_samples=20, k=3)
    assert len({cyc, cyc}) == 1


def test_select_bandwidth_one_standard_error_rule_takes_the_widest_within_it():
    """"1se": the widest width whose mean error is at most the least plus that width's
    standard error; checked against the brute-force errors."""
    theta, poses = _cv_data(T=40, seed=2)
    widths = np.geomspace(0.2, 4.0, 9)
    sel = select_bandwidth(theta, poses, 10.0, candidates=widths, rule="1se")
    err = brute_force_cv(theta, theta, poses, widths, 10.0, 0, np.arange(40))
    mean, se = err.mean(axis=0), err.std(axis=0, ddof=1) / np.sqrt(40)
    best = np.argmin(mean)
    want = widths[np.flatnonzero(mean <= mean[best] + se[best]).max()]
    assert sel.rule == "1se" and sel.bandwidth == want
    assert want > widths[best]  # the rule matters here


def test_select_bandwidth_default_grid():
    """14 widths log-spaced from k / (T sqrt(2 pi)) periods' frames (at most half a frame)
    to an eighth of a period, or to ``max_width``; one width when the grid would be empty."""
    theta, poses = _cv_data()  # T = 40
    lo = 1 / (40 * np.sqrt(2 * np.pi)) * 10.0  # k = 1: 0.0997 frames
    sel = select_bandwidth(theta, poses, 10.0, k=1)
    np.testing.assert_allclose(sel.candidates, np.geomspace(lo, 10.0 / 8, 14), rtol=1e-12)
    sel = select_bandwidth(theta, poses, 10.0, k=1, max_width=3.0, n_candidates=5)
    np.testing.assert_allclose(sel.candidates, np.geomspace(lo, 3.0, 5), rtol=1e-12)
    # k = 10: 0.997 frames, more than half a frame
    np.testing.assert_allclose(select_bandwidth(theta, poses, 10.0).candidates,
                               np.geomspace(0.5, 10.0 / 8, 14), rtol=1e-12)
    np.testing.assert_allclose(select_bandwidth(theta, poses, 10.0, n_candidates=1).candidates, [0.5])
    np.testing.assert_allclose(select_bandwidth(theta, poses, 10.0, max_width=0.5).candidates, [0.5])
    np.testing.assert_allclose(select_bandwidth(theta, poses, 10.0, max_width=0.4).candidates, [0.5])
    with pytest.raises(ParameterError):
        select_bandwidth(theta, poses, 10.0, n_candidates=0)


def test_select_bandwidth_with_a_width_far_below_the_frame_spacing_predicts_from_the_nearest():
    """A width of 1e-5 frames (sigma = 1e-6 of a period) is under a fortieth of the distance
    from any frame to the nearest other one, and the next is so much farther that its weight
    relative to the nearest underflows: each frame is predicted by its nearest other frame in
    phase (leave-one-out 1-NN), and with ``exclude=1`` by its nearest frame more than one
    frame away in time (the result must be finite although every weight alone is 0)."""
    theta, poses = _cv_data()
    for exclude in (0, 1):
        err = []
        for i in range(40):
            keep = np.flatnonzero(np.abs(np.arange(40) - i) > exclude)
            d = circular_distance(theta[keep], theta[i])
            d1, d2 = np.sort(d)[:2]
            assert d1 > 40e-6 and (d2**2 - d1**2) / 2e-12 > 800  # the preconditions above
            err.append(np.sum((poses[i] - poses[keep[np.argmin(d)]]) ** 2))
        sel = select_bandwidth(theta, poses, 10.0, candidates=[1e-5], exclude=exclude)
        np.testing.assert_allclose(sel.cv_error, [np.mean(err)], rtol=1e-5)


def test_select_bandwidth_accepts_one_channel_and_checks_k():
    theta, poses = _cv_data()
    sel = select_bandwidth(theta, poses[:, 0], 10.0, candidates=[1.0, 2.0])
    err = brute_force_cv(theta, theta, poses[:, :1], [1.0, 2.0], 10.0, 0, np.arange(40))
    np.testing.assert_allclose(sel.cv_error, err.mean(axis=0), rtol=1e-5)
    select_bandwidth(theta, poses, 10.0, k=40, candidates=[1.0])  # k = T is allowed
    for bad in (41, 0):
        with pytest.raises(ParameterError):
            select_bandwidth(theta, poses, 10.0, k=bad)
    with pytest.raises(ParameterError):
        select_bandwidth(theta, poses[:39], 10.0)


# -------------------------------------------------------- resampling, integration
def test_resample_cyclic_is_periodic_linear_interpolation():
    """Against numpy's periodic interpolation (``np.interp(..., period=1)``), with times
    unsorted, outside [0, 1) and crossing the seam."""
    rng = np.random.default_rng(8)
    times = rng.random(9)
    values = rng.standard_normal((9, 2))
    q = np.arange(13) / 13
    want = np.stack([np.interp(q, times, values[:, c], period=1.0) for c in range(2)], axis=1)
    np.testing.assert_allclose(resample_cyclic(values, 13, times=times), want, atol=1e-12)
    np.testing.assert_allclose(resample_cyclic(values, 13, times=times + 3.0), want, atol=1e-12)
    np.testing.assert_allclose(resample_cyclic(values, 13, times=times - 2.0), want, atol=1e-12)


def test_resample_cyclic_default_times_and_shapes():
    """Samples at i / 4 with values 0, 10, 20, 30: at j / 8 the curve is 5 j up to 3/4, and
    at 7/8, between 30 and the wrapped first sample 0, it is 15."""
    out = resample_cyclic(np.array([0.0, 10.0, 20.0, 30.0]), 8)
    assert out.shape == (8, 1)
    np.testing.assert_allclose(out[:, 0], [0, 5, 10, 15, 20, 25, 30, 15], atol=1e-12)
    # two output frames are the fewest; a one-sample curve is constant
    np.testing.assert_allclose(resample_cyclic([[1.0, 2.0], [3.0, 6.0]], 2), [[1.0, 2.0], [3.0, 6.0]])
    np.testing.assert_allclose(resample_cyclic([[7.0, -1.0]], 3), [[7.0, -1.0]] * 3)
    np.testing.assert_allclose(resample_cyclic([[7.0]], 2, times=[0.6]), [[7.0]] * 2)
    for bad in (1, 0, True, 2.0):
        with pytest.raises(ParameterError):
            resample_cyclic(np.zeros((4, 2)), bad)
    with pytest.raises(ParameterError):
        resample_cyclic(np.zeros((4, 2, 1)), 5)
    with pytest.raises(ParameterError):
        resample_cyclic(np.zeros((4, 2)), 5, times=[0.1, 0.2, 0.3, np.inf])


def test_integrate_root_known_answers():
    """Deltas 1, 2, 3 from 0: forward 0, 1, 3; with a displacement of 12 every delta gains
    (12 - 6) / 3 = 2: 0, 3, 7 (then 5 more back to 12); backward (deltas[0] the wrap step)
    steps 2 + 2, 3 + 2: 0, 4, 9.  A 1-D delta array is one channel, a scalar start and
    displacement fit it."""
    d = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(integrate_root(d, 0.0), [[0.0], [1.0], [3.0]])
    np.testing.assert_allclose(integrate_root(d, 0.0, displacement=12.0), [[0.0], [3.0], [7.0]])
    np.testing.assert_allclose(integrate_root(d, [0.0], displacement=[12.0], convention="backward"),
                               [[0.0], [4.0], [9.0]])
    np.testing.assert_allclose(integrate_root(d[:1], 5.0, displacement=2.0), [[5.0]])
    with pytest.raises(ParameterError):
        integrate_root(np.zeros((0, 2)), [0.0, 0.0])
    with pytest.raises(ParameterError):
        integrate_root(np.zeros((3, 2)), [0.0, np.nan])
    with pytest.raises(ParameterError):
        integrate_root(np.zeros((3, 2)), [0.0, 0.0], displacement=np.zeros((2, 1)))


# ------------------------------------------------------- typical cycle, composed
@pytest.fixture(scope="module")
def small_motion():
    """Three cycles of 40 frames, uneven speed, a little noise; its density."""
    rng = np.random.default_rng(21)
    t = np.arange(120) / 40
    theta = np.mod(warp(t), 1.0)
    poses = curve(theta) + 0.02 * rng.standard_normal((120, 5))
    return theta, poses, PeriodicDensity(random_state=0).fit(theta)


def test_typical_cycle_is_its_documented_steps(small_motion):
    """Quantile sampling: phases ppf((i + 0.5) / N) at times (i + 0.5) / N, the kernel
    curve there, resampled at times j / P; frame j's phase is ppf(j / P)."""
    theta, poses, density = small_motion
    cyc = typical_cycle(theta, poses, 40.4, density=density, n_samples=50, k=4)
    times = (np.arange(50) + 0.5) / 50
    np.testing.assert_array_equal(cyc.sample_phases, density.quantiles(50))
    np.testing.assert_allclose(cyc.curve, kernel_centroids(theta, poses, cyc.sample_phases, k=4), rtol=1e-12)
    np.testing.assert_allclose(cyc.frames, resample_cyclic(cyc.curve, 40, times=times), rtol=1e-12)
    np.testing.assert_allclose(cyc.phases, density.ppf(np.arange(40) / 40), atol=1e-15)
    assert cyc.n_frames == 40
    assert cyc.bandwidth == pytest.approx(4 / (120 * np.sqrt(2 * np.pi)) * 40.4, rel=1e-12)
    # random sampling: the density's draws, placed in time by its cdf
    rnd = typical_cycle(theta, poses, 40, density=density, n_samples=50, k=4, sampling="random",
                        random_state=5)
    np.testing.assert_array_equal(rnd.sample_phases, density.sample(50, random_state=5))
    np.testing.assert_allclose(rnd.frames, resample_cyclic(rnd.curve, 40, times=density.cdf(rnd.sample_phases)),
                               rtol=1e-12)
    # the k-nearest weightings
    for weighting in ("mean", "gaussian"):
        knn = typical_cycle(theta, poses, 40, density=density, n_samples=50, k=4, weighting=weighting)
        np.testing.assert_allclose(knn.curve, knn_centroids(theta, poses, knn.sample_phases, k=4,
                                                            weighting=weighting), rtol=1e-12)


def test_typical_cycle_runs_a_given_bandwidth_in_time(small_motion):
    """A width in frames: the kernel runs over the frames' times cdf(theta) with sigma =
    width / period_frames, queried at the sampled times; "auto" chooses the width by
    select_bandwidth on those times, predicting each frame at its held-out time."""
    from cyclecoord.periodic.cycle import _heldout_times

    theta, poses, density = small_motion
    tau = np.mod(density.cdf(theta), 1.0)
    times = (np.arange(60) + 0.5) / 60
    cyc = typical_cycle(theta, poses, 40, density=density, n_samples=60, k=4, bandwidth=1.5)
    assert cyc.bandwidth == 1.5 and cyc.bandwidth_selection is None
    np.testing.assert_allclose(cyc.curve, _dense_kernel(tau, poses, times, 1.5 / 40), rtol=1e-10, atol=1e-12)
    auto = typical_cycle(theta, poses, 40, density=density, n_samples=60, k=4, bandwidth="auto")
    sel = select_bandwidth(tau, poses, 40.0, k=4, query=_heldout_times(theta, density))
    np.testing.assert_array_equal(auto.bandwidth_selection.cv_error, sel.cv_error)
    assert auto.bandwidth == sel.bandwidth and auto.bandwidth_selection.exclude == 0
    assert auto.bandwidth_selection.rule == "min"


def test_typical_cycle_limits(small_motion):
    theta, poses, density = small_motion
    ok = dict(density=density, n_samples=10, k=3)
    assert typical_cycle(theta, poses, 2, **ok).frames.shape == (2, 5)  # the shortest cycle
    assert typical_cycle(theta, poses, 2.6, **ok).n_frames == 3
    assert typical_cycle(theta, poses, 3.4, **ok).n_frames == 3
    assert typical_cycle(theta, poses, 40, density=density, n_samples=2, k=3).curve.shape == (2, 5)
    for k in (1, 120):  # k from 1 to the number of frames
        assert typical_cycle(theta, poses, 40, density=density, n_samples=10, k=k).curve.shape == (10, 5)
    for k in (0, 121):  # refused up front, whatever the weighting
        for weighting in ("kernel", "mean"):
            with pytest.raises(ParameterError, match=r"between 1 and the number of frames \(120\), got"):
                typical_cycle(theta, poses, 40, density=density, k=k, weighting=weighting)
    bad = [{"period_frames": 1.99}, {"period_frames": True}, {"period_frames": "40"},
           {"period_frames": float("inf")}, {"n_samples": 1}, {"k": 0}, {"k": 121}, {"k": True},
           {"k": 3.0}, {"density": "uniform"}, {"weighting": "gaussian", "bandwidth": "auto"}]
    for kwargs in bad:
        args = {"period_frames": 40, **ok, **kwargs}
        with pytest.raises(ParameterError):
            typical_cycle(theta, poses, **args)


def test_typical_cycle_random_state_defaults_to_zero(small_motion):
    """The package's one default seed, 0: random sampling without a seed draws as with 0."""
    theta, poses, density = small_motion
    kw = dict(density=density, n_samples=30, k=3, sampling="random")
    default = typical_cycle(theta, poses, 40, **kw).sample_phases
    np.testing.assert_array_equal(default, typical_cycle(theta, poses, 40, random_state=0, **kw).sample_phases)
    assert not np.array_equal(default, typical_cycle(theta, poses, 40, random_state=1, **kw).sample_phases)


def test_typical_cycle_is_frozen(small_motion):
    import dataclasses

    theta, poses, density = small_motion
    cyc = typical_cycle(theta, poses, 40, density=density, n_samples=10, k=3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        cyc.bandwidth = 3.0
    for arr in (cyc.frames, cyc.phases, cyc.curve, cyc.sample_phases):
        assert not arr.flags.writeable


def test_check_bandwidth_normalises():
    from cyclecoord.periodic.cycle import check_bandwidth

    assert check_bandwidth(None) is None and check_bandwidth(None, "mean") is None
    assert check_bandwidth("auto") == "auto"
    value = check_bandwidth(3)
    assert value == 3.0 and isinstance(value, float)
    for bad in ("Auto", "", 0, -2.0, float("nan"), False):
        with pytest.raises(ParameterError):
            check_bandwidth(bad)
    for weighting in ("mean", "gaussian"):
        with pytest.raises(ParameterError):
            check_bandwidth(2.0, weighting)


def test_knn_centroids_default_to_the_papers_ten_neighbours():
    """Without k: the 10 nearest (the paper's), here the 5 lowest and 5 highest frames around
    phase 0; a capture of exactly 10 frames is averaged whole."""
    theta = (np.arange(100) + 0.5) / 100
    out = knn_centroids(theta, np.arange(100, dtype=float), [0.0])
    assert out[0, 0] == pytest.approx(np.mean([0, 1, 2, 3, 4, 95, 96, 97, 98, 99]))
    ten = knn_centroids(np.arange(10) / 10, np.arange(10, dtype=float), [0.3])
    assert ten[0, 0] == pytest.approx(4.5)
