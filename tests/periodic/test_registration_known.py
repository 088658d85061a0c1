"""periodic.registration on templates shifted or time-warped by a known amount."""

import numpy as np

from cyclecoord.periodic.registration import _align_run, hold_weights, register


def ring(P):
    """P distinct template samples on a closed curve (a circle with a second harmonic)."""
    t = 2 * np.pi * np.arange(P) / P
    return np.column_stack([np.cos(t), np.sin(t), 0.3 * np.cos(2 * t)]) * 10.0


def test_hold_weights_by_hand():
    nan = np.nan
    ph = [0.1, 0.1, 0.1, 0.2, nan, 0.2, 0.2, 0.3, 0.3, nan, 0.3]
    np.testing.assert_allclose(hold_weights(ph),
                               [1 / 3, 1 / 3, 1 / 3, 1.0, 0.0, 0.5, 0.5, 0.5, 0.5, 0.0, 1.0])
    np.testing.assert_array_equal(hold_weights([nan, nan]), [0.0, 0.0])
    assert hold_weights(np.zeros(0)).shape == (0,)
    np.testing.assert_array_equal(hold_weights([0.5]), [1.0])
    np.testing.assert_array_equal(hold_weights([0.4, 0.4]), [0.5, 0.5])


def test_align_run_recovers_a_known_shift():
    """The frames are template samples 5, 6, ... but were given the phase one sample late
    (and a fraction): alignment puts each on its own sample, unwrapped past the seam."""
    P = 20
    tpl = ring(P)
    true = np.arange(5, 5 + 30)  # one and a half cycles, unwrapped
    poses = tpl[true % P]
    psi = (true + 1.3) / P
    out = _align_run(poses, psi, tpl, band=2, penalty=0.15)
    np.testing.assert_array_equal(out, true)
    # one sample early as well
    out = _align_run(poses, (true - 0.8) / P, tpl, band=2, penalty=0.15)
    np.testing.assert_array_equal(out, true)


def test_align_run_follows_a_hold_and_a_skip():
    """Samples 2, 3, 3, 4, 5, 7, 8, 9: one hold and one skip against a phase that advances
    one sample a frame; both cost a small penalty, cheaper than the mismatches.  At a
    prohibitive penalty the path advances exactly one sample a frame."""
    P = 16
    tpl = ring(P)
    true = np.array([2, 3, 3, 4, 5, 7, 8, 9, 10, 11])
    psi = (2 + np.arange(true.size)) / P
    np.testing.assert_array_equal(_align_run(tpl[true], psi, tpl, band=2, penalty=0.15), true)
    stiff = _align_run(tpl[true], psi, tpl, band=2, penalty=1e6)
    np.testing.assert_array_equal(np.diff(stiff), 1)
    # each frame stays inside its band around the phase it has
    assert np.all(np.abs(stiff - np.round(psi * P)) <= 2)


def test_align_run_of_a_phase_running_backwards():
    """A phase that runs back three samples a frame cannot be followed by steps of 0, 1 or
    2 samples: no path is cheaper than another, but every frame still gets a sample inside
    its band (no failure)."""
    P = 20
    tpl = ring(P)
    psi = (40 - 3.0 * np.arange(8)) / P
    poses = tpl[np.round(psi * P).astype(int) % P]
    out = _align_run(poses, psi, tpl, band=1, penalty=0.15)
    assert out.shape == (8,)
    assert np.all(np.abs(out - np.round(psi * P)) <= 1)


def _capture(P=20, cycles=8):
    """Frames exactly on the template's samples, one a frame, for ``cycles`` cycles."""
    tpl = ring(P)
    n = P * cycles
    true = np.arange(n)
    return tpl, true, tpl[true % P], (true % P) / P


def test_register_moves_a_late_run_onto_its_samples_and_keeps_the_rest():
    """Two long runs timed right, one short run of 3 frames given its phase one sample
    late, one run of 2 frames likewise: the run of 3 is aligned (frames 5, 6, 7 back to
    samples 5, 6, 7), the run of 2 is too short and keeps its phase; NaN stays NaN."""
    P = 20
    tpl, true, poses, phase = _capture(P, 8)
    ph = phase.copy()
    ph[100] = np.nan  # a gap between the runs
    ph[60:63] = np.nan
    ph[140:142] = np.nan
    # the short runs: frames 200.. of the pose list below
    extra_true = np.array([5, 6, 7, 11, 12])
    x = np.vstack([poses, tpl[extra_true]])
    ph = np.concatenate([ph, (extra_true + 1) / P])
    runs = [(0, 60), (63, 100), (101, 140), (142, 160), (160, 163), (163, 165)]
    ph[160:] = np.nan
    ph[160:163] = (extra_true[:3] + 1) / P
    ph[163:165] = (extra_true[3:] + 1) / P
    x = x[:165]
    ph = ph[:165]
    out = register(ph, x, runs, P, 0.2 / P, n_iter=1)
    np.testing.assert_allclose(out[160:163], extra_true[:3] / P, atol=1e-12)
    np.testing.assert_array_equal(out[163:165], ph[163:165])
    assert np.isnan(out[100]) and np.all(np.isnan(out[60:63])) and np.all(np.isnan(out[140:142]))
    long = np.r_[0:60, 63:100, 101:140, 142:160]
    np.testing.assert_allclose(out[long], (long % P) / P, atol=1e-12)
    assert np.all((out[np.isfinite(out)] >= 0) & (out[np.isfinite(out)] < 1))


def test_register_band_and_rounds():
    """No rounds: the phase as given (a copy).  A run late by 3 samples with a band of
    0.1 cycle (2 of 20 samples) moves 2 samples in one round, 3 in two."""
    P = 20
    tpl, true, poses, phase = _capture(P, 8)
    ph = phase.copy()
    same = register(ph, poses, [(0, len(ph))], P, 0.2 / P, n_iter=0)
    np.testing.assert_array_equal(same, ph)
    assert same is not ph
    np.testing.assert_array_equal(register(ph, poses, [(0, len(ph))], P, 0.2 / P, n_iter=-3), ph)
    # a long run timed right builds the template, a later run 3 samples late
    ph[100:] = np.mod((true[100:] + 3) / P, 1.0)
    ph[99] = np.nan
    runs = [(0, 99), (100, len(ph))]
    with_tpl = ph.copy()
    one = register(with_tpl, poses, runs, P, 0.2 / P, n_iter=1, band=0.1)
    d1 = np.round(np.mod(one[100:] * P - true[100:] + P / 2, P) - P / 2)
    assert np.median(d1) == 1  # 3 late, moved 2 (the band) toward its samples
    # band below half a sample still moves one sample (at least one)
    tiny = register(with_tpl, poses, runs, P, 0.2 / P, n_iter=1, band=0.001)
    dt = np.round(np.mod(tiny[100:] * P - true[100:] + P / 2, P) - P / 2)
    assert np.median(dt) == 2


def test_register_stops_without_two_phased_frames():
    ph = np.array([np.nan, 0.3, np.nan, np.nan])
    out = register(ph, np.zeros((4, 2)), [(1, 2)], 10, 0.05)
    np.testing.assert_array_equal(np.isnan(out), np.isnan(ph))
    assert out[1] == 0.3


def test_align_run_holds_on_the_last_frame_and_skips_on_the_first():
    """The path's end is the cheapest column of the last frame: a run that holds its last
    sample (6, 6) against a phase still advancing ends on 6, not on the advancing 7; one
    that skips at its start (1, 3) starts on 1."""
    P = 16
    tpl = ring(P)
    true = np.array([2, 3, 4, 5, 6, 6])
    psi = (2 + np.arange(6)) / P
    np.testing.assert_array_equal(_align_run(tpl[true], psi, tpl, band=2, penalty=0.15), true)
    true = np.array([1, 3, 4, 5, 6, 7])
    psi = (2 + np.arange(6)) / P
    np.testing.assert_array_equal(_align_run(tpl[true], psi, tpl, band=2, penalty=0.15), true)
