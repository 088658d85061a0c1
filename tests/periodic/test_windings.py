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
    unwrap_across_gaps,
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


# ------------------------------------------------------------------ known answers, by hand
def fast_slow(n_cycles: int = 4) -> np.ndarray:
    """A coordinate with a 10-frame cycle that goes half a turn slowly (1/16 a frame, 8
    frames) then half a turn fast (1/4 a frame, 2 frames), starting 1/16 in (so no level
    sits on frame 0); every value is a multiple of 1/16, exact in floating point.  Frame
    by frame: level 0.25 is reached on frame 3 (+ 10 k), 0.5 on 7, 0.75 on 8, 0 (a whole
    turn) on 9; its central differences there are 1/16, 5/32, 1/4 and 5/32."""
    per = []
    for k in range(n_cycles):
        per.append(k + np.arange(8) / 16)
        per.append(k + 0.5 + np.arange(2) / 4)
    return np.concatenate(per)[1:]


def test_stretches_reach_both_ends_of_the_mask():
    assert stretches(np.ones(3, dtype=bool)) == [(0, 3)]
    assert stretches(np.array([1, 0, 0, 1, 1], dtype=bool)) == [(0, 1), (3, 5)]
    assert stretches(np.array([True])) == [(0, 1)]
    assert stretches(np.zeros(0, dtype=bool)) == []


def test_crossing_times_of_a_steady_coordinate_by_hand():
    """u = 0.25, 0.75, 1.25, 1.75 (half a turn a frame): level 0 is reached at 1 (frame
    1.5), 0.25 at 1.25 exactly on frame 2 (its 0.25 on frame 0 is where the stretch starts,
    no crossing), 0.5 at 0.5 and 1.5 (frames 0.5, 2.5), 0.875 at 0.875 (frame 1.25)."""
    u = np.array([0.25, 0.75, 1.25, 1.75])
    got = crossing_times(u, np.array([0.0, 0.25, 0.5, 0.875]))
    want = [[1.5], [2.0], [0.5, 2.5], [1.25]]
    assert len(got) == 4
    for g, x in zip(got, want):
        np.testing.assert_allclose(g, x, rtol=0, atol=1e-12)


def test_crossing_times_edges():
    # a level reached on the last frame is crossed; a jump over several turns in one frame
    # crosses each of them, evenly spaced in the frame (linear interpolation)
    (c,) = crossing_times(np.array([0.0, 2.5]), np.array([0.5]))
    np.testing.assert_allclose(c, [0.2, 0.6, 1.0], rtol=0, atol=1e-12)
    # a level never reached, a coordinate going backwards only: no crossing
    assert [x.size for x in crossing_times(np.array([0.1, 0.2]), np.array([0.5, 0.15]))] == [0, 1]
    assert crossing_times(np.array([0.9, 0.5, 0.1]), np.array([0.0, 0.5]))[1].size == 0
    # fewer than 2 frames: one empty array per level
    out = crossing_times(np.array([0.5]), np.array([0.1, 0.2, 0.3]))
    assert len(out) == 3 and all(x.size == 0 for x in out)
    assert len(crossing_times(np.zeros(0), np.array([0.0]))) == 1


def test_sharpness_is_the_mean_speed_at_the_rounded_crossings():
    from cyclecoord.periodic.windings import _sharpness

    u = np.array([0.0, 0.1, 0.3, 0.6])
    # np.gradient by hand: 0.1, 0.15, 0.25, 0.3; crossings at 1.4 and 2.6 round to 1 and 3
    assert _sharpness(u, [np.array([1.4, 2.6])]) == pytest.approx((0.15 + 0.3) / 2)
    # backward steps are read on the running maximum: 0, 0.1, 0.1, 0.6 -> 0.1, 0.05, 0.25, 0.5
    assert _sharpness(np.array([0.0, 0.1, 0.05, 0.6]), [np.array([2.0])]) == pytest.approx(0.25)
    assert _sharpness(u, []) == 0.0 and _sharpness(u, [np.zeros(0)]) == 0.0


def test_complete_windings_of_a_fast_slow_coordinate_by_hand():
    """fast_slow's levels 0.75 (speed 1/4), 0 and 0.5 (5/32) and 0.25 (1/16): the
    median speed is 5/32, so 0.25 alone is too blunt to be an anchor, and the two levels
    exactly at the median are kept; the sharpest, 0.75, is the reference.  Level 0 is
    reached 1 frame after it (0.1 of the 10-frame cycle), 0.5 nine frames after (0.9)."""
    u = fast_slow()  # 39 frames, 1/16 to 3.75
    w = complete_windings(u, [(0, 39)], n_levels=4)
    np.testing.assert_array_equal(w.levels, [0.0, 0.25, 0.5, 0.75])
    assert w.anchors.tolist() == [3, 0, 2] and w.reference == 3
    np.testing.assert_allclose(w.lengths, [10.0, 10.0, 10.0])  # reached on frames 8, 18, 28, 38
    assert w.n_complete == 3
    # every level's complete windings: 2 at level 0 (frames 9, 19, 29), 3 at each other
    np.testing.assert_allclose(w.pooled, np.full(11, 10.0))
    assert w.period_frames == 10.0 and w.spread == 0.0
    assert w.turns == 3.75 - 1 / 16
    np.testing.assert_allclose(w.positions, [0.0, 0.1, 0.9], atol=1e-12)
    # anchors closer than min_anchor_gap to a sharper one are dropped: a quarter turn < 0.3
    w = complete_windings(u, [(0, 39)], n_levels=4, min_anchor_gap=0.3)
    assert w.anchors.tolist() == [3] and w.positions.tolist() == [0.0]
    # the phase re-timed between the pins is the time since a reference crossing, plus 0
    ph = retime(u, [(0, 39)], complete_windings(u, [(0, 39)], n_levels=4))
    np.testing.assert_allclose(ph, np.mod((np.arange(39) - 8) / 10.0, 1.0), atol=1e-12)


def test_complete_windings_do_not_span_the_gap_between_runs():
    """fast_slow split at frame 19 (where the coordinate is exactly 2): each run is read on
    its own, so the windings are 2 at the reference level (18 - 8 in the first, 38 - 28
    in the second; none from 18 to 28 across runs), and the net turns add up per run:
    1.75 - 1/16 and 3.75 - 2."""
    u = fast_slow()
    w = complete_windings(u, [(0, 19), (19, 39)], n_levels=4)
    np.testing.assert_allclose(w.lengths, [10.0, 10.0])
    assert w.pooled.size == 6 and w.turns == (1.75 - 1 / 16) + (3.75 - 2.0)
    # a run of a single frame adds nothing, not even turns
    w1 = complete_windings(u, [(0, 19), (19, 39), (5, 6)], n_levels=4)
    assert w1.turns == w.turns and w1.pooled.size == 6


def test_anchor_positions_without_a_complete_reference_winding():
    """Frames 5-17 of fast_slow: the reference level 0.75 is reached once (run frame 3),
    level 0.5 twice (frames 2 and 12, one winding of 10: the period), level 0 once (frame
    4).  Level 0's position is then its offset after the reference crossing over the
    period: 1 / 10."""
    w = complete_windings(fast_slow(), [(5, 18)], n_levels=4)
    assert w.reference == 3 and w.anchors.tolist() == [3, 0]
    assert w.lengths.size == 0 and w.pooled.tolist() == [10.0] and w.period_frames == 10.0
    np.testing.assert_allclose(w.positions, [0.0, 0.1], atol=1e-12)
    assert w.turns == 1.5 - 0.375


def test_anchor_positions_without_any_complete_winding_follow_the_levels():
    """An even pace from 1/8 to 7/8 of a turn: levels 0.25, 0.5, 0.75 are each reached
    once, equally sharp (1/8 a frame), level 0 never.  No winding is complete: no period,
    and each anchor sits at its level's offset from the reference's (the first of the
    equally sharp)."""
    w = complete_windings(0.125 + np.arange(7) / 8, [(0, 7)], n_levels=4)
    assert w.anchors.tolist() == [1, 2, 3] and w.reference == 1
    assert np.isnan(w.period_frames) and w.pooled.size == 0 and w.spread == 0.0
    np.testing.assert_allclose(w.positions, [0.0, 0.25, 0.5])
    assert w.turns == 0.75 and w.n_complete == 0
    assert np.isnan(retime(0.125 + np.arange(7) / 8, [(0, 7)], w)).all()  # no period: no phase


def test_a_coordinate_that_never_moves_has_no_anchor():
    w = complete_windings(np.full(10, 0.3), [(0, 10)], n_levels=4)
    assert w.anchors.size == 0 and w.reference == 0 and w.positions.size == 0
    assert np.isnan(w.period_frames) and w.spread == 0.0 and w.turns == 0.0
    assert w.lengths.size == 0 and w.pooled.size == 0
    assert np.isnan(retime(np.full(10, 0.3), [(0, 10)], w)).all()


def test_period_and_spread_of_uneven_windings():
    """Windings of 8, 10, 12, 14 and 16 frames at an even pace within each: every level's
    lengths are those five (nearly: a level's crossing lies between frames), so the period
    is the median, 12, and the spread (p90 - p10) / median of the pooled lengths."""
    u = np.concatenate([k + np.arange(n) / n for k, n in enumerate((8, 10, 12, 14, 16, 10))])
    u = u + 1 / 64  # no level on frame 0
    w = complete_windings(u, [(0, u.size)], n_levels=8)
    pooled = np.concatenate([np.diff(c) for c in crossing_times(u - np.floor(u[0]),
                                                                 np.arange(8) / 8)])
    np.testing.assert_allclose(np.sort(w.pooled), np.sort(pooled[pooled > 0]))
    assert w.period_frames == pytest.approx(np.median(pooled))
    assert abs(w.period_frames - 12.0) < 0.5
    want = (np.percentile(pooled, 90) - np.percentile(pooled, 10)) / np.median(pooled)
    assert w.spread == pytest.approx(want) and 0.4 < w.spread < 0.6


def _two_level_windings(reference, positions, period=8.0):
    from cyclecoord.periodic.windings import Windings

    return Windings(levels=np.array([0.0, 0.5]), anchors=np.array([0, 1]), reference=reference,
                    lengths=np.zeros(0), pooled=np.array([period]), period_frames=period,
                    spread=0.0, turns=3.0, positions=np.array(positions, dtype=float))


def test_retime_pins_each_anchor_crossing_to_its_position_by_hand():
    """u = 3/8 + t / 8 over 24 frames: level 0.5 is reached on frames 1, 9, 17 and level 0
    (whole turns 1, 2, 3) on frames 5, 13, 21.  With the reference at level 0 and level
    0.5 placed a quarter of the way round, the pins are (1, 0.25), (5, 1), (9, 1.25),
    (13, 2), ...: the phase runs 0.75 in the 4 frames after a level-0.5 pin and 0.25 in
    the 4 after a level-0 pin; before the first pin and after the last it runs at one
    cycle per period (8 frames)."""
    t = np.arange(24, dtype=float)
    u = 0.375 + t / 8
    want = np.empty(24)
    for a, b, ya, yb in [(1, 5, 0.25, 1.0), (5, 9, 1.0, 1.25), (9, 13, 1.25, 2.0),
                         (13, 17, 2.0, 2.25), (17, 21, 2.25, 3.0)]:
        want[a:b + 1] = ya + (yb - ya) * (t[a:b + 1] - a) / (b - a)
    want[0] = 0.25 - 1 / 8
    want[22:] = 3.0 + (t[22:] - 21) / 8
    out = retime(u, [(0, 24)], _two_level_windings(0, [0.0, 0.25]))
    np.testing.assert_allclose(out, np.mod(want, 1.0), atol=1e-12)
    # the reference at level 0.5 (its crossings are whole turns 0, 1, 2) and level 0 placed
    # 0.75 after it: pins (1, 0), (5, 0.75), (9, 1), (13, 1.75), ...
    want2 = np.empty(24)
    for a, b, ya, yb in [(1, 5, 0.0, 0.75), (5, 9, 0.75, 1.0), (9, 13, 1.0, 1.75),
                         (13, 17, 1.75, 2.0), (17, 21, 2.0, 2.75)]:
        want2[a:b + 1] = ya + (yb - ya) * (t[a:b + 1] - a) / (b - a)
    want2[0] = -1 / 8
    want2[22:] = 2.75 + (t[22:] - 21) / 8
    out2 = retime(u, [(0, 24)], _two_level_windings(1, [0.75, 0.0]))
    np.testing.assert_allclose(out2, np.mod(want2, 1.0), atol=1e-12)


def test_retime_drops_pins_that_do_not_advance():
    """Level 0.5 placed a whole cycle on (position 1): its pins (frames 1, 9, 17) land on
    1, 2, 3, the same phases level 0's pins (frames 5, 13, 21) land on later.  A pin no
    later in phase than the one before it is dropped, so only level 0.5's pins remain and
    the phase runs at one cycle per 8 frames from them."""
    u = 0.375 + np.arange(24) / 8
    out = retime(u, [(0, 24)], _two_level_windings(0, [0.0, 1.0]))
    np.testing.assert_allclose(out, np.mod(1.0 + (np.arange(24) - 1) / 8, 1.0), atol=1e-12)


def test_retime_reads_runs_of_two_frames_but_not_of_one():
    """A 2-frame run from 0.9 to 1.1 reaches level 0 half-way: the phase there is 0 and
    runs at one cycle per period (8) either side; a 1-frame run gets no phase."""
    u = np.array([0.9, 1.1, 0.3, 0.2])
    out = retime(u, [(0, 2), (2, 3)], _two_level_windings(0, [0.0, 0.5]))
    np.testing.assert_allclose(out[:2], np.mod([-0.5 / 8, 0.5 / 8], 1.0), atol=1e-12)
    assert np.isnan(out[2:]).all()


def test_retime_without_a_usable_period_gives_no_phase():
    from dataclasses import replace

    u = 0.375 + np.arange(24) / 8
    w = _two_level_windings(0, [0.0, 0.5])
    for bad in (replace(w, period_frames=float("nan")), replace(w, period_frames=0.0),
                replace(w, period_frames=-8.0), replace(w, anchors=np.zeros(0, dtype=int))):
        assert np.isnan(retime(u, [(0, 24)], bad)).all()
    # the same windings with a period of 8 do give every frame a phase
    assert np.isfinite(retime(u, [(0, 24)], w)).all()


def test_edge_taper_is_a_raised_cosine_over_length_frames():
    """Known answer from the docstring's formula: frame k of a run of n is (min(k, n-1-k)
    + 0.5) frames from the run's edge, and weighs (1 - cos(pi min(1, edge / length))) / 2."""
    mask = np.zeros(30, dtype=bool)
    mask[3:23] = True
    length = 4.0
    w = edge_taper(mask, length)
    want = np.zeros(30)
    for k in range(20):
        edge = min(k, 19 - k) + 0.5
        want[3 + k] = (1 - np.cos(np.pi * min(1.0, edge / length))) / 2
    np.testing.assert_allclose(w, want, rtol=0, atol=1e-15)
    assert w[3] == pytest.approx((1 - np.cos(np.pi / 8)) / 2) and w[7] == 1.0 and w[6] < 1.0
    # a run at the mask's start and end tapers too; a negative length means no taper
    full = edge_taper(np.ones(10, dtype=bool), 2.0)
    assert full[0] == full[-1] == pytest.approx((1 - np.cos(np.pi / 4)) / 2)
    np.testing.assert_array_equal(edge_taper(mask, -1.0), mask.astype(float))


def _brute_phase_average(phase, values, n_out, width, weights=None):
    """A periodic Gaussian average by a loop: every row at its wrapped phase distance,
    weighted exp(-d^2 / 2 width^2) when closer than min(4 width, 1/2)."""
    wts = np.ones(len(phase)) if weights is None else weights
    out = np.empty((n_out, values.shape[1]))
    half = min(4 * width, 0.5)
    for j in range(n_out):
        c = j / n_out
        d = np.mod(phase - c + 0.5, 1.0) - 0.5
        k = np.where(np.abs(d) < half, np.exp(-0.5 * (d / width) ** 2), 0.0) * wts
        out[j] = k @ values / k.sum()
    return out


@pytest.mark.parametrize("width", [0.01, 0.05, 0.3])
def test_phase_average_matches_a_brute_force_periodic_kernel(width):
    """Random rows (no row on a window's edge): the same as the loop above, windows that
    wrap round 0 included; a width over 1/8 reads each row once (window of one cycle)."""
    rng = np.random.default_rng(1)
    ph = rng.uniform(0, 1, 300)
    vals = rng.normal(size=(300, 2))
    wts = rng.uniform(0, 2, 300)
    np.testing.assert_allclose(phase_average(ph, vals, 16, width),
                               _brute_phase_average(ph, vals, 16, width), rtol=1e-10)
    np.testing.assert_allclose(phase_average(ph, vals, 16, width, weights=wts),
                               _brute_phase_average(ph, vals, 16, width, wts), rtol=1e-10)


def test_phase_average_kernel_ends_at_four_widths():
    """Two rows, values 0 at the output phase 0.5 and 1 at 3.9 widths from it: weight
    exp(-3.9^2 / 2) for the second; at 4.1 widths the second row gets no weight."""
    width = 0.01
    vals = np.array([[0.0], [1.0]])
    near = phase_average(np.array([0.5, 0.5 + 3.9 * width]), vals, 2, width)
    e = np.exp(-0.5 * 3.9**2)
    assert near[1, 0] == pytest.approx(e / (1 + e), rel=1e-9)
    far = phase_average(np.array([0.5, 0.5 + 4.1 * width]), vals, 2, width)
    assert far[1, 0] == 0.0
    assert near.shape == (2, 1)


def test_phase_average_takes_the_nearest_row_where_no_row_is_in_reach():
    """Rows at phases 0 (value 0) and 0.5 (value 10), a kernel of 0.01: the output phases
    0.2 and 0.8 have no row within 4 widths and take the nearest one's value (0.8 is
    nearest the row at 0, across the wrap), 0.4 and 0.6 the row at 0.5's."""
    out = phase_average(np.array([0.0, 0.5]), np.array([[0.0], [10.0]]), 5, 0.01)
    np.testing.assert_allclose(out[:, 0], [0.0, 0.0, 10.0, 10.0, 0.0])
    # rows whose weights are all 0 near an output phase: the nearest row's value too
    out = phase_average(np.array([0.0, 0.01, 0.5]), np.array([[1.0], [2.0], [10.0]]), 2, 0.01,
                        weights=np.array([0.0, 0.0, 1.0]))
    np.testing.assert_allclose(out[:, 0], [1.0, 10.0])
    assert phase_average(np.array([0.3]), np.array([[4.0, 5.0]]), 3, 0.01).tolist() == [[4.0, 5.0]] * 3


def test_phase_average_validation():
    ph, vals = np.array([0.1, 0.2]), np.ones((2, 1))
    for bad_ph, bad_vals in ((ph[:, None], vals), (ph, vals[:, 0]), (np.zeros(0), np.zeros((0, 1))),
                             (ph, np.ones((3, 1)))):
        with pytest.raises(ParameterError, match="phases"):
            phase_average(bad_ph, bad_vals, 4, 0.01)
    for width in (0.0, -0.01, np.inf, np.nan):
        with pytest.raises(ParameterError, match="width"):
            phase_average(ph, vals, 4, width)
    # zero weights are allowed (non-negative)
    assert phase_average(ph, vals, 4, 0.01, weights=np.zeros(2)).shape == (4, 1)


def test_retime_of_a_run_starting_exactly_on_a_level():
    """u = t / 8 from exactly 0: the reference level 0 is on frame 0 (no crossing there,
    crossing_times), then crossed on frames 8 and 16, whole turns 1 and 2; level 0.5,
    placed a quarter after it, on frames 4, 12, 20.  The pins are (4, 0.25), (8, 1),
    (12, 1.25), (16, 2), (20, 2.25): the phase is 0 at each reference crossing, the same
    as for a run starting a hair above 0."""
    t = np.arange(24, dtype=float)
    w = _two_level_windings(0, [0.0, 0.25])
    want = np.empty(24)
    for a, b, ya, yb in [(4, 8, 0.25, 1.0), (8, 12, 1.0, 1.25), (12, 16, 1.25, 2.0),
                         (16, 20, 2.0, 2.25)]:
        want[a:b + 1] = ya + (yb - ya) * (t[a:b + 1] - a) / (b - a)
    want[:4] = 0.25 + (t[:4] - 4) / 8
    want[21:] = 2.25 + (t[21:] - 20) / 8
    out = retime(t / 8, [(0, 24)], w)
    np.testing.assert_allclose(out, np.mod(want, 1.0), atol=1e-12)
    assert out[8] == out[16] == 0.0
    np.testing.assert_allclose(retime(t / 8 + 1e-9, [(0, 24)], w), out, atol=1e-6)


def test_defaults_32_levels_and_anchors_over_0_04_apart():
    """An even pace (1/64 a frame, exact: every level equally sharp): the default 32
    levels are 1/32 apart, under the default gap of 0.04, so every other level is an
    anchor (2/32 = 0.0625 apart), taken from level 0 on."""
    import dataclasses

    w = complete_windings(np.arange(640) / 64, [(0, 640)])
    np.testing.assert_array_equal(w.levels, np.arange(32) / 32)
    assert sorted(w.anchors.tolist()) == list(range(0, 32, 2)) and w.reference == 0
    with pytest.raises(dataclasses.FrozenInstanceError):
        w.reference = 1


def test_a_level_reached_only_on_frame_0_is_not_crossed():
    assert crossing_times(np.array([0.25, 0.5]), np.array([0.25]))[0].size == 0
    assert crossing_times(np.array([0.25, 0.25, 0.2]), np.array([0.25]))[0].size == 0


def test_sharpness_at_the_ends_of_the_coordinate():
    from cyclecoord.periodic.windings import _sharpness

    u = np.array([0.0, 0.1, 0.3, 0.6])  # np.gradient 0.1, 0.15, 0.25, 0.3
    assert _sharpness(u, [np.array([0.3])]) == pytest.approx(0.1)  # rounds to frame 0
    assert _sharpness(u, [np.array([3.0])]) == pytest.approx(0.3)  # the last frame
    assert _sharpness(np.array([0.0, 0.5]), [np.array([0.6])]) == pytest.approx(0.5)
    assert _sharpness(np.array([0.5]), [np.array([0.0])]) == 0.0  # one frame: no speed


def test_runs_of_two_frames_count_and_empty_runs_are_harmless():
    """A 2-frame run from 0.9 to 1.1 crosses level 0: an anchor, 0.2 turns; a half-open
    empty run (even at the end) and 1-frame runs change nothing."""
    w = complete_windings(np.array([0.9, 1.1]), [(0, 2)], n_levels=4)
    assert w.anchors.tolist() == [0] and w.turns == pytest.approx(0.2)
    u = fast_slow()
    base = complete_windings(u, [(0, 19), (19, 39)], n_levels=4)
    for extra in ([(39, 39)], [(5, 6)], [(5, 6), (30, 31), (12, 12)]):
        w = complete_windings(u, [(0, 19), (19, 39)] + extra, n_levels=4)
        assert w.anchors.tolist() == base.anchors.tolist() == [3, 0, 2]
        np.testing.assert_array_equal(w.pooled, base.pooled)
        np.testing.assert_array_equal(w.positions, base.positions)
        assert w.turns == base.turns


def test_windings_shorter_than_a_frame():
    """2.5 turns in one frame: level 0 is reached at 0.4 and 0.8, level 0.5 at 0.2, 0.6
    and 1.0 (linear interpolation): windings of 0.4 frames, the period; level 0.5 sits
    half-way.  The re-timed phase is 0 on frame 0 (0.2 before the 0.5 pin at 0.2, half a
    period) and 0.5 on frame 1 (2.5 turns)."""
    u = np.array([0.0, 2.5])
    w = complete_windings(u, [(0, 2)], n_levels=2)
    np.testing.assert_allclose(w.pooled, [0.4, 0.4, 0.4])
    assert w.period_frames == pytest.approx(0.4) and w.anchors.tolist() == [0, 1]
    np.testing.assert_allclose(w.positions, [0.0, 0.5])
    ph = retime(u, [(0, 2)], w)
    assert np.all(np.abs(np.mod(ph - [0.0, 0.5] + 0.5, 1.0) - 0.5) < 1e-9)


def test_spread_of_two_windings_by_hand():
    """Level 0 reached on frames 2, 10 and 22 exactly (u piecewise linear through whole
    turns there): windings 8 and 12, period 10, and (p90 - p10) / median =
    (11.6 - 8.4) / 10 = 0.32 (linear percentiles)."""
    u = np.interp(np.arange(25), [0, 2, 10, 22, 24], [0.75, 1, 2, 3, 3.25])
    w = complete_windings(u, [(0, 25)], n_levels=1)
    np.testing.assert_allclose(w.lengths, [8.0, 12.0])
    assert w.period_frames == 10.0 and w.spread == pytest.approx(0.32)


def test_positions_are_the_median_fraction_over_reference_windings():
    """Uneven windings (8 to 16 frames): each anchor's position is the median over the
    complete reference windings of how far into the winding it is first reached, counted
    here by a loop over crossing_times."""
    u = np.concatenate([k + np.arange(n) / n for k, n in enumerate((8, 10, 12, 14, 16, 10))])
    u = u + 1 / 64
    w = complete_windings(u, [(0, u.size)], n_levels=8)
    c = crossing_times(u - np.floor(u[0]), np.arange(8) / 8)
    r = c[w.reference]
    assert w.anchors.size > 2
    for j, pos in zip(w.anchors, w.positions):
        fr = []
        for k in range(r.size - 1):
            inside = [x for x in c[j] if r[k] <= x < r[k + 1]]
            if inside:
                fr.append((inside[0] - r[k]) / (r[k + 1] - r[k]))
        assert len(fr) == r.size - 1 and pos == pytest.approx(np.median(fr))
    assert len(set(np.round(w.positions, 6))) == w.anchors.size


def test_positions_without_windings_wrap_below_the_reference_level():
    """1/8 a frame, then a quarter turn in the last frame: 0.75 is the sharpest level and
    the reference, 0.25 and 0.5 are as sharp as the median; no winding is complete, so
    they sit at their levels' offsets after 0.75, wrapped into [0, 1): 0.5 and 0.75."""
    u = np.array([0.125, 0.25, 0.375, 0.5, 0.625, 0.875])
    w = complete_windings(u, [(0, 6)], n_levels=4)
    assert w.anchors.tolist() == [3, 1, 2]
    np.testing.assert_allclose(w.positions, [0.0, 0.5, 0.75])


def test_edge_taper_of_zero_length_is_no_taper():
    mask = np.array([0, 1, 1, 1, 0, 1], dtype=bool)
    for length in (0.0, -0.0, 0):
        np.testing.assert_array_equal(edge_taper(mask, length), mask.astype(float))


def test_the_glitch_filter_of_typical_amplitude_is_timed_in_seconds():
    """Five frames at 120 fps: 5 at 100 and 120 fps, 3 at 60, none at 30 and 24 (where a
    5-frame median clipped a real ankle roll of a sixth of a second)."""
    from cyclecoord.periodic.clip import spike_frames, typical_amplitude

    assert [spike_frames(f) for f in (24, 30, 48, 60, 100, 120, 240)] == [1, 1, 3, 3, 5, 5, 11]
    # a 2-frame plateau at 30 fps is motion: each window of the capture holds one at full
    # height, the averaged cycle holds it at half, so the cycle is widened back to it
    P = 30
    rep = np.zeros(P)
    rep[14:16] = 1.0
    poses = np.tile(rep, 6)[:, None]
    cycle = 0.5 * rep[:, None]
    out = typical_amplitude(cycle, np.zeros(poses.shape[0]), poses, spike=spike_frames(30))
    assert np.ptp(out) == pytest.approx(1.5 * np.ptp(cycle))  # to the gain's cap: 0.75
    # the 120-fps filter (5 frames) takes the same plateau for a glitch: no widening
    np.testing.assert_allclose(typical_amplitude(cycle, np.zeros(poses.shape[0]), poses,
                                                 spike=spike_frames(120)), cycle)


def test_phase_average_is_the_same_under_small_weights():
    """A weighted phase average does not depend on the weights' scale: two samples at
    phases 0 and 0.01 (values 0 and 1), width 0.01, read at phase 0 give
    e^-0.5 / (1 + e^-0.5) = 0.3775 with weights of 1 or of 0.001 alike (weights summing
    under 1 are still weights, not an empty window)."""
    ph = np.array([0.0, 0.01])
    vals = np.array([[0.0], [1.0]])
    want = np.exp(-0.5) / (1.0 + np.exp(-0.5))
    for scale in (1.0, 1e-3):
        out = phase_average(ph, vals, 1, 0.01, weights=np.full(2, scale))
        assert out[0, 0] == pytest.approx(want)


def test_a_gap_in_the_steady_frames_advances_by_its_whole_cycles():
    """The pipeline leaves out a walk's turn (135 frames, 2.74 cycles of 49.25 frames):
    across the gap the phase advances by the whole cycles nearest that (3.19 here: the
    coordinate's 0.19 plus 3), not the 0.19 ``np.unwrap`` sees; a coordinate running
    backwards is turned round first."""
    P = 49.25
    at = np.r_[np.arange(0, 55), np.arange(189, 262)]  # frames 55-188 left out
    true = at / P
    p = true % 1.0
    u = unwrap_across_gaps(p, at, P)
    np.testing.assert_allclose(u - u[0], true - true[0], atol=1e-9)
    np.testing.assert_allclose(unwrap_across_gaps((-true) % 1.0, at, P) - u, -u[0], atol=1e-9)
    # the coordinate 0.2 cycles on after the gap (a turn taken at another pace): the
    # gap advances by the period's 2.741 cycles plus those 0.2, the nearest whole count
    p2 = np.r_[true[:55], true[55:] + 0.2] % 1.0
    u2 = unwrap_across_gaps(p2, at, P)
    assert u2[55] - u2[54] == pytest.approx(135 / P + 0.2, abs=1e-9)
    # the period estimated from neighbouring frames, and a backwards coordinate kept so
    np.testing.assert_allclose(unwrap_across_gaps(p, at) - u[0], true - true[0], atol=1e-9)
    back = unwrap_across_gaps((-true) % 1.0, at, P, forwards=False)
    np.testing.assert_allclose(back - back[0], -(true - true[0]), atol=1e-9)
