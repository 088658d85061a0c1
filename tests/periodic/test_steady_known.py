"""Known answers of periodic.steady's helpers at their edges (issue 27: mutation score).

Each expected value is computed here by hand or by a plain loop written from the
docstrings, never by the code under test.
"""

import numpy as np
import pytest
from scipy.ndimage import gaussian_filter1d, uniform_filter1d

from cyclecoord.periodic.steady import (
    _smoothed_steps,
    centred_window,
    moving_mask,
    period_speed,
    recurrence,
    steady_mask,
    steady_turning,
)
from cyclecoord.periodic.windings import stretches


def _runs(mask):
    out, t, m = [], 0, list(map(bool, mask))
    while t < len(m):
        if m[t]:
            s = t
            while t < len(m) and m[t]:
                t += 1
            out.append((s, t))
        else:
            t += 1
    return out


def _clean(mask, min_run, max_gap):
    """clean_runs written from its docstring, with plain loops."""
    m = list(map(bool, mask))
    r = _runs(m)
    for (a0, b0), (a1, _) in zip(r[:-1], r[1:]):
        if a1 - b0 <= max_gap:
            for t in range(b0, a1):
                m[t] = True
    for a, b in _runs(m):
        if b - a < min_run:
            for t in range(a, b):
                m[t] = False
    return np.array(m, dtype=bool)


def _whole_steps(x, sigma):
    sm = gaussian_filter1d(np.asarray(x, float), sigma=sigma, axis=0, mode="nearest")
    return np.linalg.norm(np.diff(sm, axis=0), axis=1)


# ------------------------------------------------------------------ _smoothed_steps
@pytest.mark.parametrize("block", [1, 5, 16, 37, 1000])
def test_smoothed_steps_in_blocks_equal_the_whole_take_smoothed_at_once(block):
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.normal(size=(120, 4)), axis=0)
    got = _smoothed_steps(x, 3.0, None, block=block)
    assert got.shape == (119,)
    np.testing.assert_allclose(got, _whole_steps(x, 3.0), rtol=1e-10, atol=1e-12)
    cols = np.array([3, 1])
    np.testing.assert_allclose(
        _smoothed_steps(x, 3.0, cols, block=block), _whole_steps(x[:, cols], 3.0),
        rtol=1e-10, atol=1e-12,
    )


def test_smoothed_steps_sigma_is_capped_at_the_take_length():
    rng = np.random.default_rng(4)
    x = np.cumsum(rng.normal(size=(12, 2)), axis=0)
    got = _smoothed_steps(x, 500.0, None, block=5)
    np.testing.assert_allclose(got, _whole_steps(x, 12.0), rtol=1e-10, atol=1e-13)
    assert not np.allclose(got, _whole_steps(x, 11.0), rtol=1e-6)  # the cap is T itself


def test_smoothed_steps_of_one_or_two_frames():
    assert _smoothed_steps(np.ones((1, 3)), 1.0, None).shape == (0,)
    x = np.array([[0.0, 0.0], [3.0, 4.0]])
    np.testing.assert_allclose(_smoothed_steps(x, 1.0, None), _whole_steps(x, 1.0))


# ------------------------------------------------------------------ moving_mask
def _moving(j, fps, min_speed=0.35, smooth_seconds=0.5):
    """moving_mask from its docstring: light smoothing (max(1, 0.04 fps) frames), steps,
    last step repeated, moving average over smooth_seconds, >= min_speed of the 80th
    percentile, then still gaps up to half a second bridged and runs under a second dropped."""
    step = _whole_steps(j, max(1.0, 0.04 * fps))
    step = np.r_[step, step[-1]]
    speed = uniform_filter1d(step, size=max(1, int(round(smooth_seconds * fps))), mode="nearest")
    level = np.percentile(speed, 80)
    return _clean(speed >= min_speed * level, int(round(fps)), int(round(0.5 * fps)))


@pytest.mark.parametrize("fps", [10.0, 24.0, 60.0, 120.0])
@pytest.mark.parametrize("min_speed", [0.35, 0.6])
def test_moving_mask_equals_its_definition(fps, min_speed):
    """A swing whose amplitude steps through levels, with still stretches between, at
    frame rates where the light smoothing is 1 frame (10, 24 fps) and more (60, 120)."""
    T = int(12 * fps)
    t = np.arange(T) / fps
    amp = np.select([t < 2, t < 4, t < 5, t < 7, t < 7.4, t < 9], [0.0, 10.0, 0.0, 3.0, 0.0, 1.0], 0.2)
    s = amp * np.sin(2 * np.pi * 1.3 * t)
    j = np.c_[s, 0.5 * s, np.cos(3 * t) * amp]
    want = _moving(j, fps, min_speed)
    got = moving_mask(j, fps, min_speed=min_speed)
    np.testing.assert_array_equal(got, want)
    assert 0 < got.sum() < T  # the case has both moving and still frames
    np.testing.assert_array_equal(
        moving_mask(j, fps, min_speed=min_speed, smooth_seconds=0.2),
        _moving(j, fps, min_speed, 0.2),
    )


def test_moving_mask_default_min_speed_is_035():
    """Speed levels 1 (most frames), 0.36 and 0.34 of it over 3 s each (10 fps: 1 frame of
    light smoothing): the 0.36 stretch moves, the 0.34 one is still."""
    fps = 10.0
    v = np.r_[np.ones(90), np.full(30, 0.36), np.ones(60), np.full(30, 0.34), np.ones(90)]
    x = np.cumsum(v)[:, None] * np.ones((1, 2))
    got = moving_mask(x, fps)
    assert got[95:115].all() and not got[185:205].any()


def test_moving_mask_of_three_frames_judges_them():
    x = np.array([[0.0], [0.0], [5.0]])
    assert moving_mask(x, 10.0).sum() == 0  # a run of 1-3 frames is under a second (10)
    assert moving_mask(x[:2], 10.0).all()  # two frames: not judged


# ------------------------------------------------------------------ recurrence
def _brute_recurrence(x, period, shortest=0.7, longest=1.45):
    T = len(x)
    lo = max(1, int(np.floor(shortest * period)))
    hi = max(lo, int(np.ceil(longest * period)))
    want = np.full(T, np.inf)
    for t in range(T):
        for lag in range(lo, hi + 1):
            for s in (t - lag, t + lag):
                if 0 <= s < T:
                    want[t] = min(want[t], np.linalg.norm(x[s] - x[t]))
    return want


@pytest.mark.parametrize(
    "T,period,chunk,shortest,longest",
    [(40, 1.0, 7, 0.7, 1.45), (40, 0.5, 3, 0.7, 1.45), (30, 10.0, 4, 0.7, 1.45),
     (30, 25.0, 8, 0.7, 1.45), (30, 20.0, 2048, 1.0, 1.0), (50, 7.0, 5, 0.3, 2.0),
     (25, 16.0, 9, 0.7, 1.45)],
)
def test_recurrence_equals_brute_force_at_the_lag_edges(T, period, chunk, shortest, longest):
    rng = np.random.default_rng(int(period * 10) + T)
    x = rng.normal(size=(T, 3))
    got = recurrence(x, period, chunk=chunk, shortest=shortest, longest=longest)
    np.testing.assert_allclose(got, _brute_recurrence(x, period, shortest, longest), rtol=1e-12)


def test_recurrence_of_a_repeating_sequence_is_zero_where_a_repeat_exists():
    x = np.tile(np.array([[0.0], [1.0], [3.0], [7.0]]), (5, 1))  # period 4, 20 frames
    got = recurrence(x, 4.0, shortest=1.0, longest=1.0)
    np.testing.assert_array_equal(got, np.zeros(20))
    got = recurrence(x, 3.0, shortest=1.0, longest=1.0)  # lag 3 only: never the same pose
    assert (got > 0).all()


# ------------------------------------------------------------------ period_speed
@pytest.mark.parametrize("period", [0.4, 1.0, 1.4, 2.0, 7.6])
def test_period_speed_equals_its_definition(period):
    rng = np.random.default_rng(5)
    x = np.cumsum(rng.normal(size=(60, 3)), axis=0)
    fps = 100.0  # light smoothing 4 frames
    step = _whole_steps(x, 4.0)
    want = uniform_filter1d(np.r_[step, step[-1]], size=max(1, int(round(period))), mode="nearest")
    np.testing.assert_allclose(period_speed(x, fps, period), want, rtol=1e-10)
    if round(period) <= 1:  # one period of at most a frame: the steps themselves
        np.testing.assert_allclose(period_speed(x, fps, period), np.r_[step, step[-1]], rtol=1e-10)


def test_period_speed_light_smoothing_is_at_least_one_frame():
    rng = np.random.default_rng(6)
    x = np.cumsum(rng.normal(size=(50, 2)), axis=0)
    step = _whole_steps(x, 1.0)  # 0.04 * 10 fps = 0.4 frames: raised to 1
    np.testing.assert_allclose(period_speed(x, 10.0, 1.0), np.r_[step, step[-1]], rtol=1e-10)
    step = _whole_steps(x, 2.0)  # 0.04 * 50 = 2 frames
    np.testing.assert_allclose(period_speed(x, 50.0, 1.0), np.r_[step, step[-1]], rtol=1e-10)


def test_period_speed_of_under_three_frames_is_one():
    np.testing.assert_array_equal(period_speed(np.zeros((2, 3)), 30.0, 5.0), [1.0, 1.0])
    assert period_speed(np.zeros((0, 3)), 30.0, 5.0).shape == (0,)
    v = period_speed(np.array([[0.0], [0.0], [0.0]]), 30.0, 5.0)
    np.testing.assert_array_equal(v, np.zeros(3))


# ------------------------------------------------------------------ centred_window
@pytest.mark.parametrize("n", [1, 2, 3, 6, 9, 14])
@pytest.mark.parametrize("half", [0, 1, 2, 3, 7])
def test_centred_window_by_loop(n, half):
    lo, hi = centred_window(n, half)
    for i in range(n):
        if 2 * half >= n - 1:  # the window holds every frame
            want = (0, n - 1)
        else:
            a = min(max(i - half, 0), n - 1 - 2 * half)
            want = (a, a + 2 * half)
        assert (lo[i], hi[i]) == want, (n, half, i)


# ------------------------------------------------------------------ steady_turning
def _turning(h, period, max_turn=30.0, max_curve=60.0):
    n = len(h)
    half = max(1, int(round(period / 2)))
    lo, hi = centred_window(n, half)
    rate = [(h[hi[i]] - h[lo[i]]) / max(hi[i] - lo[i], 1) * period for i in range(n)]
    out = []
    for i in range(n):
        b = rate[min(max(i - half, 0), n - 1)]
        a = rate[min(max(i + half, 0), n - 1)]
        change = max(abs(rate[i] - b), abs(rate[i] - a))
        out.append(change <= max_turn and abs(rate[i]) <= max_curve)
    return np.array(out)


@pytest.mark.parametrize("period", [1.0, 2.0, 3.0, 10.0, 21.0])
def test_steady_turning_equals_its_definition(period):
    t = np.arange(120.0)
    h = np.interp(t, [0, 30, 50, 70, 119], [0, 5, 60, 40, 200]) + 3 * np.sin(t / 4)
    for max_turn, max_curve in ((30.0, 60.0), (5.0, 200.0), (200.0, 20.0)):
        np.testing.assert_array_equal(
            steady_turning(h, period, max_turn, max_curve), _turning(h, period, max_turn, max_curve)
        )


def test_steady_turning_default_limits():
    """Period 10: the heading turns -30 degrees a period, then +30 from frame 50: at frame
    50 the window rate is 0, the windows half a period before and after read -30 and +30,
    a change of exactly the default 30 (kept); -31 to +31 is a change of 31 (not).  90
    degrees a period all along is the default curve limit (kept), 91 is a corner."""
    t = np.arange(100.0)
    for r, ok in ((3.0, True), (3.1, False)):
        h = np.where(t < 50, -r * t, -50 * r + r * (t - 50))
        assert steady_turning(h, 10.0)[50] == ok, r
    assert not steady_turning(9.1 * t, 10.0).any() and steady_turning(9.0 * t, 10.0).all()
    assert steady_turning(-9.0 * t, 10.0).all() and not steady_turning(-9.1 * t, 10.0).any()


# ------------------------------------------------------------------ steady_mask
def test_steady_mask_trims_the_ramp_into_a_stop_but_not_the_takes_last_frames():
    """Moving frames 0-599 of 800 then still; the speed drops to 0.5 over the last 100
    moving frames: the ramp into the stop is trimmed exactly where speed < median / 1.3.
    The same ramp at the take's very end is the motion's own."""
    T, P = 800, 50.0
    t = np.arange(T)
    moving = t < 600
    u = np.where(moving, t / P, np.nan)
    speed = np.where(t < 500, 1.0, np.where(t < 520, 0.77, 0.5))
    speed = np.where(moving, speed, 0.0)
    # median over the moving frames is 1: 0.77 < 1 / 1.3 = 0.769...? no: 0.77 is not slow
    got = steady_mask(u, moving, P, speed=speed)
    assert stretches(got) == [(0, 520)]
    speed2 = np.where(moving, np.where(t < 500, 1.0, 0.76), 0.0)  # 0.76 < 0.769: slow
    assert stretches(steady_mask(u, moving, P, speed=speed2)) == [(0, 500)]
    # a ratio of 1.25: 0.77 is slow too (0.8 limit)
    assert stretches(steady_mask(u, moving, P, speed=speed, max_speed_ratio=1.25)) == [(0, 500)]
    # the take ends moving: nothing trimmed at its end
    u_all, cand = t / P, np.ones(T, bool)
    sp = np.where(t < 700, 1.0, 0.5)
    assert stretches(steady_mask(u_all, cand, P, speed=sp)) == [(0, T)]


def test_steady_mask_speed_equal_to_the_limit_is_kept_and_a_zero_median_trims_nothing():
    T, P = 400, 40.0
    t = np.arange(T)
    moving = (t >= 100) & (t < 300)
    u = np.where(moving, t / P, np.nan)
    speed = np.where(moving, 1.0, 0.0)
    speed[100:130] = 0.5  # ramp out of standing: slow; then exactly the limit
    speed[130:140] = 1.0 / 1.25
    got = steady_mask(u, moving, P, speed=speed, max_speed_ratio=1.25)
    assert stretches(got) == [(130, 300)]
    zero = np.zeros(T)
    assert stretches(steady_mask(u, moving, P, speed=zero)) == [(100, 300)]
    # no candidate frame: nothing steady, no error
    assert not steady_mask(u, np.zeros(T, bool), P, speed=speed).any()


def test_steady_mask_a_stretch_slow_all_along_loses_every_frame():
    """A moving stretch after a still start that is slow throughout: the trim from the
    start takes all of it (the trim from the end stops where the first one did)."""
    T, P = 500, 20.0
    t = np.arange(T)
    cand = (t >= 50) & (t < 150) | (t >= 200) & (t < 500)
    u = np.where(cand, t / P, np.nan)
    speed = np.where(t < 150, 0.3, 1.0)
    got = steady_mask(u, cand, P, speed=speed)
    assert stretches(got) == [(200, 500)]


def test_steady_mask_recurrence_limit_is_strict_and_ignores_infinite_and_non_candidates():
    T, P = 400, 40.0
    t = np.arange(T)
    cand = t >= 40
    u = np.where(cand, t / P, np.nan)
    r = np.ones(T)
    r[:40] = 1000.0  # not candidates: left out of the median
    r[-20:] = np.inf  # no partner: left out of the median, and not steady
    r[200:250] = 2.0  # exactly max_recurrence x the median (1): kept
    got = steady_mask(u, cand, P, recurrence_distance=r)
    assert stretches(got) == [(40, 380)]
    r[200:250] = 2.0000001
    assert stretches(steady_mask(u, cand, P, recurrence_distance=r)) == [(40, 200), (250, 380)]
    assert stretches(steady_mask(u, cand, P, recurrence_distance=r, max_recurrence=3.0)) == [(40, 380)]


def test_steady_mask_runs_under_a_rounded_period_are_dropped():
    """Period 40.4 rounds to 40: a steady run of exactly 40 frames stays, 39 go."""
    T = 200
    t = np.arange(T)
    for n, kept in ((40, True), (39, False)):
        cand = (t >= 50) & (t < 50 + n)
        u = np.where(cand, t / 40.4, np.nan)
        assert steady_mask(u, cand, 40.4).any() == kept, n


def test_steady_mask_pace_window_is_in_periods():
    """The coordinate stands still for 30 frames then jumps through 1.5 turns in 10, every
    40 frames (period 40): the pace over one period varies; over pace_window periods it is
    steady.  With pace_window 1 only the one-period window is read."""
    P, t = 40, np.arange(800)
    ph = t % P
    u = (t // P) * 1.0 + np.where(ph < 30, 0.0, (ph - 30) / 10.0)
    cand = np.ones(t.size, bool)
    one = steady_mask(u, cand, float(P), pace_window=1.0)
    two = steady_mask(u, cand, float(P), pace_window=2.0)
    assert one.all() and two.all()
    # a heading that turns 90 degrees over frames 380-420 breaks the steadiness there
    h = np.interp(t, [0, 380, 420, 799], [0, 0, 90, 90])
    got = steady_mask(u, cand, float(P), heading=h)
    assert got[:330].all() and not got[380:420].any() and got[480:].all()
    # the turn limits reach steady_turning: a 200-degree limit keeps the 90-degree corner
    assert steady_mask(u, cand, float(P), heading=h, max_turn=200.0, max_curve=200.0).all()


def test_steady_mask_pace_limits():
    P, t = 20.0, np.arange(400)
    cand = np.ones(t.size, bool)
    assert steady_mask(t * 1.25 / P, cand, P, max_pace=1.25).all()
    assert not steady_mask(t * 1.3 / P, cand, P, max_pace=1.25).any()
    assert steady_mask(t * 0.8 / P, cand, P, max_pace=1.25).all()
    assert not steady_mask(t * 0.75 / P, cand, P, max_pace=1.25).any()
    assert not steady_mask(-t / P, cand, P).any()  # backwards is not at pace


def test_steady_mask_reads_the_pace_over_one_period_besides_pace_window():
    """Period 100, one turn a period but a stall over frames 400-549.  At frame 380 the
    one-period window (330-430) turns 0.7 (at pace: over 1 / 1.6); the two-period one
    (280-480) 1.2 turns over 2 periods, 0.6 a period (not): frame 380 is steady."""
    t = np.arange(1000)
    u = np.where(t < 400, t, np.where(t < 550, 400, t - 150)) / 100.0
    cand = np.ones(1000, bool)
    got = steady_mask(u, cand, 100.0)
    assert got[380] and got[:380].all()
    assert not got[420:530].any()


def test_steady_mask_trims_a_slow_stretch_at_the_takes_start_from_its_end():
    """Candidates 0-99 (slow, 0.3) and 150-279 (1.0), still after: the first stretch meets
    still frames at its end, and slow all along it is trimmed whole from there (the
    take's first frame does not stop the trim)."""
    T, P = 300, 20.0
    t = np.arange(T)
    cand = (t < 100) | ((t >= 150) & (t < 280))
    u = np.where(cand, t / P, np.nan)
    speed = np.where(t < 100, 0.3, np.where(t < 280, 1.0, 0.0))
    assert stretches(steady_mask(u, cand, P, speed=speed)) == [(150, 280)]


def test_steady_mask_a_slow_stretch_reaching_the_takes_end_is_trimmed_from_its_start():
    """Candidates 50-149 at speed 1 and 200-299 at 0.3 (the median over both, 0.65, makes
    0.3 slow): the second stretch, out of still frames and slow to the take's last frame,
    is trimmed whole from its start; the take's end does not trim."""
    T, P = 300, 20.0
    t = np.arange(T)
    cand = ((t >= 50) & (t < 150)) | (t >= 200)
    u = np.where(cand, t / P, np.nan)
    speed = np.where(t < 150, 1.0, 0.3)
    assert stretches(steady_mask(u, cand, P, speed=speed)) == [(50, 150)]
