"""Complete windings, the re-timed phase and the phase average (periodic.windings)."""

import numpy as np
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.periodic.windings import (
    complete_windings,
    crossing_times,
    edge_taper,
    phase_average,
    retime,
    stretches,
)


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


@pytest.mark.parametrize("width", [0.02, 0.05])
def test_phase_average_is_a_gaussian_of_the_stated_width(width):
    """Known answer: a Gaussian of standard deviation s (in phase) multiplies harmonic k of
    a periodic signal by exp(-2 pi^2 s^2 k^2); a kernel narrower or wider than stated
    (exp(-(d / s)^2) is s / sqrt(2)) changes that attenuation by 5-35 %."""
    ph = (np.arange(4000) + 0.5) / 4000  # dense and even: the sum is the integral
    k = np.arange(1, 5)
    vals = np.cos(2 * np.pi * np.outer(ph, k))
    grid = np.arange(64) / 64
    out = phase_average(ph, vals, 64, width)
    want = np.cos(2 * np.pi * np.outer(grid, k)) * np.exp(-2 * np.pi**2 * width**2 * k**2)
    np.testing.assert_allclose(out, want, atol=1.5e-4)  # measured 1.1e-4: the kernel ends at 4 widths


def test_edge_taper_fades_each_run_in_and_out():
    mask = np.zeros(40, dtype=bool)
    mask[2:30] = True
    mask[33:36] = True
    w = edge_taper(mask, 5.0)
    assert np.all(w[~mask] == 0) and np.all(w[mask] > 0) and np.all(w <= 1)
    np.testing.assert_allclose(w[2:30], w[2:30][::-1])  # symmetric in each run
    assert w[2] < 0.05 and np.all(w[7:25] == 1.0)  # near 0 at the edge, 1 past 5 frames
    assert np.all(np.diff(w[2:8]) > 0)  # rises monotonically
    assert np.all(w[33:36] < 1)  # a run shorter than twice the taper never reaches 1
    np.testing.assert_array_equal(edge_taper(mask, 0.0), mask.astype(float))


def test_phase_average_weights_and_their_validation():
    ph = np.tile(np.arange(100) / 100, 2)
    vals = np.concatenate([np.zeros((100, 1)), np.ones((100, 1))])
    np.testing.assert_allclose(phase_average(ph, vals, 50, 0.01), 0.5)
    w = np.r_[np.ones(100), 3 * np.ones(100)]
    np.testing.assert_allclose(phase_average(ph, vals, 50, 0.01, weights=w), 0.75)
    for bad in (np.ones(5), -w, np.r_[np.nan, w[1:]]):
        with pytest.raises(ParameterError, match="weights"):
            phase_average(ph, vals, 50, 0.01, weights=bad)


def test_tapered_average_of_a_partial_repetition_does_not_jump():
    """1.8 repetitions of a take that drifts: with equal weights the average jumps where
    the partial repetition starts and ends (it averages two repetitions on one side, one on
    the other); fading the run's ends spreads those changes over several frames."""
    P, drift = 100, 10.0
    t = np.arange(int(1.8 * P))
    ph = np.mod(t / P, 1.0)
    vals = (np.sin(2 * np.pi * ph) + drift * t / t.size)[:, None]
    width = 1.0 / P

    def largest_step(cycle):
        return np.max(np.abs(np.diff(np.r_[cycle[:, 0], cycle[0, 0]])))

    capture = np.max(np.abs(np.diff(vals[:, 0])))
    plain = phase_average(ph, vals, P, width)
    run = np.ones(t.size, dtype=bool)
    assert largest_step(plain) > 5 * capture  # a pop the capture never makes
    steps = [largest_step(phase_average(ph, vals, P, width, weights=edge_taper(run, f * P)))
             for f in (0.05, 0.25)]
    assert steps[0] < 0.75 * largest_step(plain)  # the default taper (clip.EDGE_TAPER)
    assert steps[1] < 0.3 * largest_step(plain)  # a longer taper spreads it further


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


def test_typical_amplitude_windows_start_at_every_frame_for_short_cycles():
    """A 4-frame cycle: P // 8 is 0, so a window of one period starts at every frame of the
    phased run (not every other one); no running median (spike 1), so the known answer is
    the median of the 6 windows' ranges 0, 0, 1, 2, 2, 2: 1.5, a gain of 1.5 on a cycle of
    range 1, about its mean."""
    from cyclecoord.periodic.clip import typical_amplitude

    poses = np.array([0, 0, 0, 0, 0, 1, 2, 0, 0], float)[:, None]
    phase = np.zeros(9)  # every frame phased; only finiteness is read
    cycle = np.array([[0.0], [1.0], [0.0], [0.0]])
    out = typical_amplitude(cycle, phase, poses, spike=1)
    np.testing.assert_allclose(out[:, 0], 0.25 + 1.5 * (cycle[:, 0] - 0.25))
    # a run shorter than the cycle gives no window: the cycle is returned as it is
    np.testing.assert_array_equal(typical_amplitude(cycle, phase[:3], poses[:3], spike=1), cycle)


def test_typical_amplitude_first_window_starts_at_the_run_start():
    """A phased run exactly one period long has one window, the one starting at its first
    frame: its range (1.3 times the cycle's, plateaus a running median keeps) sets a gain
    of 1.3 about the cycle's mean."""
    from cyclecoord.periodic.clip import typical_amplitude

    cycle = np.repeat([1.0, -1.0], 8)[:, None]
    poses = 1.3 * cycle
    out = typical_amplitude(cycle, np.zeros(16), poses, spike=3)
    np.testing.assert_allclose(out, 1.3 * cycle)


def test_typical_amplitude_never_narrows_nor_widens_a_glitch():
    """Three channels of a 12-frame cycle against a capture of four repetitions of a
    plateaued pattern (range 3; a running median of 3 frames keeps it): a channel 1.2x
    narrower than the capture is widened 1.2x about its mean; one wider than the capture
    is kept (never narrowed); one flat but for a one-frame glitch has no amplitude after
    the running median and is kept as it is (a glitch is not amplitude to restore)."""
    from cyclecoord.periodic.clip import typical_amplitude

    pattern = np.array([0, 0, 0, 1, 2, 3, 3, 3, 2, 1, 0, 0], float)
    glitch = np.zeros(12)
    glitch[5] = 1.0
    cycle = np.column_stack([pattern, 2.0 * pattern, glitch])
    poses = np.tile(np.column_stack([1.2 * pattern, pattern, 5.0 * pattern]), (4, 1))
    out = typical_amplitude(cycle, np.zeros(len(poses)), poses, spike=3)
    mean = pattern.mean()
    np.testing.assert_allclose(out[:, 0], mean + 1.2 * (pattern - mean))
    np.testing.assert_allclose(out[:, 1:], cycle[:, 1:], rtol=0, atol=1e-12)


def test_register_straightens_a_warped_phase_and_keeps_runs_too_short_to_align():
    """Poses on a circle, one turn per 50 frames; the phase given is warped by up to 0.03
    of a cycle.  Registration brings the long run back to the true phase (to a sample of
    the 50-sample cycle: exactly, since the frames sit on the samples); a run of 2 frames
    is left as it was."""
    from cyclecoord.periodic.registration import register

    t = np.arange(200)
    true = t / 50.0
    poses = np.column_stack([np.cos(2 * np.pi * true), np.sin(2 * np.pi * true)])
    given = np.full(200, np.nan)
    runs = [(0, 140), (150, 152)]
    for a, b in runs:
        given[a:b] = np.mod(true[a:b] + 0.03 * np.sin(2 * np.pi * t[a:b] / 37), 1.0)
    out = register(given, poses, runs, n_samples=50, width=0.02)

    err = np.abs(np.mod(out - true + 0.5, 1.0) - 0.5)
    was = np.abs(np.mod(given - true + 0.5, 1.0) - 0.5)
    assert was[:140].max() > 0.025 and err[:140].max() < 1e-12
    np.testing.assert_array_equal(out[150:152], given[150:152])
    assert np.all(np.isnan(out[140:150])) and np.all(np.isnan(out[152:]))


def test_one_complete_winding_has_no_spread():
    """From 0.99 to 2.015 turns at 1/40 a frame: level 0 alone is crossed twice, one
    winding of 40 frames, and one length has no spread."""
    w = complete_windings(0.99 + np.arange(42) / 40, [(0, 42)])
    assert w.pooled.tolist() == [pytest.approx(40.0)]
    assert w.period_frames == pytest.approx(40.0) and w.spread == 0.0


def test_retime_from_a_single_pin_runs_at_one_cycle_a_period():
    """A run that crosses its one anchor once: the phase is 0 there and advances one cycle
    per period before and after (here the coordinate's own fraction)."""
    from cyclecoord.periodic.windings import Windings

    w = Windings(levels=np.array([0.0]), anchors=np.array([0]), reference=0,
                 lengths=np.zeros(0), pooled=np.array([20.0]), period_frames=20.0,
                 spread=0.0, turns=1.0, positions=np.array([0.0]))
    u = np.full(14, np.nan)
    u[2:12] = 0.7 + np.arange(10) / 20  # reaches 1.0 at frame 8
    out = retime(u, [(2, 12)], w)
    np.testing.assert_allclose(out[2:12], np.mod(u[2:12], 1.0), atol=1e-12)
    assert out[8] == pytest.approx(0.0, abs=1e-12) and np.isnan(out[:2]).all() and np.isnan(out[12:]).all()


def test_hold_weights_give_a_held_stretch_one_vote():
    from cyclecoord.periodic.registration import hold_weights

    ph = np.array([0.1, 0.2, 0.2, 0.2, 0.3, np.nan, 0.3, 0.3, 0.5])
    w = hold_weights(ph)
    np.testing.assert_allclose(w, [1, 1 / 3, 1 / 3, 1 / 3, 1, 0, 0.5, 0.5, 1])
    assert hold_weights(np.full(4, np.nan)).sum() == 0


def test_register_moves_a_phase_at_most_the_band_and_at_least_one_sample():
    """A band of 0.02 cycle is one sample of a 50-sample cycle, and a band of a quarter
    sample is rounded up to one: in one round each frame goes to one of the three samples
    about the one nearest its given phase, within 1.5 samples of that phase, even where
    the given phase is warped by 2 samples."""
    from cyclecoord.periodic.registration import register

    t = np.arange(200)
    true = t / 50.0
    poses = np.column_stack([np.cos(2 * np.pi * true), np.sin(2 * np.pi * true)])
    given = np.mod(true + 0.04 * np.sin(2 * np.pi * t / 37), 1.0)
    for band in (0.02, 0.005):
        out = register(given, poses, [(0, 200)], n_samples=50, width=0.02, n_iter=1, band=band)
        moved = np.abs(np.mod(out - given + 0.5, 1.0) - 0.5) * 50
        assert moved.max() <= 1.5 + 1e-9 and moved.max() > 1.0


def test_anchors_exactly_min_anchor_gap_apart_are_kept():
    """Only anchors *closer* than min_anchor_gap are dropped: a coordinate turning evenly
    (1/64 a frame, exact) is equally sharp at every level, and 8 levels 1/8 apart with a
    gap of 0.125 all stay anchors."""
    u = np.arange(640) / 64.0
    w = complete_windings(u, [(0, 640)], n_levels=8, min_anchor_gap=0.125)
    assert sorted(w.anchors.tolist()) == list(range(8))
    w = complete_windings(u, [(0, 640)], n_levels=8, min_anchor_gap=0.2)
    assert len(w.anchors) == 4


def test_retime_reads_only_the_fraction_of_a_runs_first_frame():
    """Each run is re-unwrapped from its own first frame: whole turns added to the
    coordinate (2^40 of them, exactly representable with it) leave the phase unchanged."""
    period = 100.0
    u = staircase(700, period)
    u = np.round(u * 4096) / 4096  # on the grid of 2^-12 that 2^40 + u keeps exactly
    w = complete_windings(u, [(0, 700)])
    shifted = u + 2.0**40
    assert np.array_equal(shifted - 2.0**40, u)
    np.testing.assert_array_equal(retime(shifted, [(0, 700)], complete_windings(shifted, [(0, 700)])),
                                  retime(u, [(0, 700)], w))
