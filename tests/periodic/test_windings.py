"""Complete windings, the re-timed phase and the phase average (periodic.windings)."""

import numpy as np
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.periodic.windings import complete_windings, crossing_times, phase_average, retime, stretches


def staircase(n_frames: int, period: float, flat: float = 0.6) -> np.ndarray:
    """An unwrapped coordinate that stalls for ``flat`` of each period, then jumps."""
    t = np.arange(n_frames) / period
    frac = np.mod(t, 1.0)
    jump = np.clip((frac - flat) / (1.0 - flat), 0.0, 1.0)
    return np.floor(t) + 0.5 * frac * 0.1 + jump * (1 - 0.05)


def test_stretches():
    assert stretches(np.array([0, 1, 1, 0, 1], dtype=bool)) == [(1, 3), (4, 5)]
    assert stretches(np.zeros(3, dtype=bool)) == []


def test_crossing_times_are_interpolated_and_ignore_backward_jitter():
    u = np.array([0.0, 0.4, 0.3, 0.8, 1.2, 1.1, 1.6, 2.1])
    (c,) = crossing_times(u, np.array([0.5]))
    # 0.5 is first reached between frames 2 and 3 (running maximum 0.4 -> 0.8), 1.5 between 5 and 6
    np.testing.assert_allclose(c, [2 + 0.1 / 0.4, 5 + 0.3 / 0.4])


def test_period_is_the_median_complete_winding_not_net_turns():
    period = 120.0
    u = np.full(1000, np.nan)
    u[:400] = 0.0  # a standing start: the coordinate does not move
    u[400:] = np.arange(600) / period
    w = complete_windings(u, [(0, 1000)])
    assert w.period_frames == pytest.approx(period, rel=0.01)
    # dividing the take by its net turns (as before) would say 1000 / 5 = 200
    assert (1000 - 1) / w.turns > 1.5 * period
    assert w.spread < 0.02
    assert w.n_complete == 4


def test_windings_of_a_staircase_and_the_retimed_phase_is_linear_in_time():
    period = 100.0
    u = staircase(700, period)
    w = complete_windings(u, [(0, 700)])
    assert w.period_frames == pytest.approx(period, rel=0.01)
    ph = retime(u, [(0, 700)], w)
    steps = np.mod(np.diff(ph), 1.0)
    # a phase that advances at the capture's pace: every step close to 1 / period
    assert np.all(np.abs(steps - 1 / period) < 0.25 / period)


def test_retime_leaves_frames_outside_the_runs_without_phase():
    u = np.arange(500) / 100.0
    w = complete_windings(u, [(100, 450)])
    ph = retime(u, [(100, 450)], w)
    assert np.all(np.isnan(ph[:100])) and np.all(np.isnan(ph[450:]))
    assert np.all(np.isfinite(ph[100:450]))


def test_phase_average_recovers_a_periodic_signal():
    rng = np.random.default_rng(0)
    ph = rng.uniform(0, 1, 5000)
    vals = np.column_stack([np.sin(2 * np.pi * ph), np.cos(2 * np.pi * ph)]) + rng.normal(0, 0.05, (5000, 2))
    out = phase_average(ph, vals, 50, 0.01)
    grid = np.arange(50) / 50
    np.testing.assert_allclose(out, np.column_stack([np.sin(2 * np.pi * grid), np.cos(2 * np.pi * grid)]), atol=0.03)
    with pytest.raises(ParameterError):
        phase_average(ph, vals[:10], 50, 0.01)
    with pytest.raises(ParameterError):
        phase_average(ph, vals, 50, 0.0)


def test_typical_amplitude_restores_what_averaging_flattens():
    from cyclecoord.periodic.clip import MAX_AMPLITUDE_GAIN, typical_amplitude

    rng = np.random.default_rng(0)
    P, n = 100, 12
    phase, poses = [], []
    for _ in range(n):  # a sharp flick whose timing differs from repetition to repetition
        centre = 0.5 + rng.normal(0, 0.03)
        ph = np.arange(P) / P
        phase.append(ph)
        poses.append(np.exp(-0.5 * ((ph - centre) / 0.02) ** 2)[:, None] * [30.0, 0.0] + [0.0, 1.0])
    phase, poses = np.concatenate(phase), np.vstack(poses)
    avg = phase_average(phase, poses, P, 0.01)
    assert np.ptp(avg[:, 0]) < 0.8 * 30.0  # the plain average flattens the flick
    out = typical_amplitude(avg, phase, poses)
    assert np.ptp(out[:, 0]) == pytest.approx(min(30.0, MAX_AMPLITUDE_GAIN * np.ptp(avg[:, 0])), rel=0.1)
    np.testing.assert_allclose(out[:, 1], avg[:, 1])  # a constant channel stays as it is
    assert np.argmax(out[:, 0]) == np.argmax(avg[:, 0])  # the shape is kept, only widened
