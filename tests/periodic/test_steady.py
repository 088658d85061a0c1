"""Steady frames of a take: pace, heading and the speed ramps out of standing (periodic.steady)."""

import numpy as np

from cyclecoord.periodic.steady import period_speed, steady_mask
from cyclecoord.periodic.windings import stretches


def _take(T=1000, period=100.0, still=200, ramp=150):
    """A coordinate turning once per period after ``still`` standing frames; the joint
    speed ramps up linearly over the first ``ramp`` moving frames."""
    t = np.arange(T, dtype=float)
    moving = t >= still
    u = np.where(moving, (t - still) / period, np.nan)
    speed = np.where(moving, np.clip((t - still) / ramp, 0.2, 1.0), 0.0)
    return u, moving, speed


def test_the_ramp_out_of_a_standing_start_is_not_steady():
    u, moving, speed = _take()
    without = steady_mask(u, moving, 100.0)
    assert stretches(without) == [(200, 1000)]
    with_speed = steady_mask(u, moving, 100.0, speed=speed)
    (a, b), = stretches(with_speed)
    # trimmed while slower than the median / 1.3 (speed 1 / 1.3 is reached 115 frames in)
    assert b == 1000 and 200 + 110 <= a <= 200 + 120


def test_the_takes_own_first_frames_and_the_inside_are_not_judged_by_speed():
    u, moving, speed = _take(still=0)
    assert stretches(steady_mask(u, moving, 100.0, speed=speed)) == [(0, 1000)]
    # a slow stretch inside a moving run (arm circles that grow, then shrink) stays steady
    u, moving, _ = _take()
    inside = np.where(moving, 1.0, 0.0)
    inside[500:600] = 0.3
    assert stretches(steady_mask(u, moving, 100.0, speed=inside)) == [(200, 1000)]


def test_period_speed_averages_the_smoothed_steps_over_a_period():
    rng = np.random.default_rng(0)
    x = np.cumsum(np.r_[np.zeros((300, 3)), np.full((300, 3), 0.5)], axis=0) + rng.normal(0, 1e-3, (600, 3))
    v = period_speed(x, fps=120.0, period=60.0)
    assert v.shape == (600,)
    assert v[:200].max() < 0.05 and np.allclose(v[400:550], 0.5 * np.sqrt(3), rtol=0.02)
    cols = period_speed(np.c_[x, 100 * x], 120.0, 60.0, columns=np.array([0, 1, 2]))
    np.testing.assert_allclose(cols, v)


def test_recurrence_is_the_nearest_pose_one_period_away_either_way():
    from cyclecoord.periodic.steady import recurrence

    rng = np.random.default_rng(1)
    x = rng.normal(size=(700, 4))
    period = 50.0
    got = recurrence(x, period, chunk=64)  # blocks smaller than the lags
    lags = range(35, 74)  # floor(0.7 * 50) to ceil(1.45 * 50)
    want = np.full(len(x), np.inf)
    for t in range(len(x)):
        for lag in lags:
            for s in (t - lag, t + lag):
                if 0 <= s < len(x):
                    want[t] = min(want[t], np.linalg.norm(x[s] - x[t]))
    np.testing.assert_allclose(got, want, rtol=1e-12)
    assert np.isinf(recurrence(x[:30], period)).all()  # no pose a period away
