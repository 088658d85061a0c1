"""Known-answer tests of the windowed stage's helpers (detection/windows.py), each on small
synthetic inputs checked against a brute-force computation or an answer worked by hand."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from cyclecoord.periodic.detection import windows as W
from cyclecoord.periodic.detection.result import WindowInfo
from cyclecoord.quality.metrics import distance_to_cycle


# ------------------------------------------------------------------- binned_cycle
def brute_binned(theta, poses, bins):
    """Mean pose per bin floor(bins * (theta mod 1)); an empty bin is interpolated between
    the nearest filled bins before and after it around the circle, by their distances."""
    b = [min(int(np.mod(t, 1.0) * bins), bins - 1) for t in theta]
    filled = {k: np.mean([p for p, j in zip(poses, b) if j == k], axis=0) for k in set(b)}
    out = np.zeros((bins, poses.shape[1]))
    for k in range(bins):
        if k in filled:
            out[k] = filled[k]
            continue
        dp = next(d for d in range(1, bins + 1) if (k - d) % bins in filled)
        dn = next(d for d in range(1, bins + 1) if (k + d) % bins in filled)
        out[k] = (filled[(k - dp) % bins] * dn + filled[(k + dn) % bins] * dp) / (dp + dn)
    return out


@pytest.mark.parametrize("bins", [5, 16])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_binned_cycle_matches_brute_force(bins, seed):
    rng = np.random.default_rng(seed)
    # values in a few stretches only (empty bins between, one stretch across the seam)
    theta = np.concatenate([0.93 + 0.12 * rng.random(6), 0.4 + 0.1 * rng.random(5), [0.66]]) + rng.integers(-2, 3, 12)
    poses = rng.standard_normal((12, 3))
    np.testing.assert_allclose(W.binned_cycle(theta, poses, bins=bins), brute_binned(theta, poses, bins), atol=1e-12)


def test_binned_cycle_edges():
    """A phase of exactly 1 is bin 0; -1e-17 (whose mod 1 rounds to 1.0) is the last bin;
    one filled bin fills every bin; no frames at all give zeros; the default is 16 bins."""
    out = W.binned_cycle(np.array([1.0, -1e-17]), np.array([[2.0], [6.0]]), bins=4)
    np.testing.assert_allclose(out[:, 0], [2.0, 10 / 3, 14 / 3, 6.0])
    np.testing.assert_allclose(W.binned_cycle([0.3, 0.31], [[1.0, 2.0], [3.0, 4.0]], bins=4), [[2.0, 3.0]] * 4)
    np.testing.assert_array_equal(W.binned_cycle(np.zeros(0), np.zeros((0, 2)), bins=3), np.zeros((3, 2)))
    assert W.CYCLE_BINS == 16
    assert W.binned_cycle(np.linspace(0, 1, 50), np.ones((50, 2))).shape == (16, 2)


# ------------------------------------------------------------------ cycle_distance
def brute_cycle_distance(a, b):
    n = len(a)
    best = np.inf
    for bb in (b, b[::-1]):
        for s in range(n):
            d = np.sqrt(np.mean([np.sum((a[i] - bb[(i - s) % n]) ** 2) for i in range(n)]))
            best = min(best, d)
    return best


def test_cycle_distance_matches_brute_force_and_ignores_shift_and_direction():
    rng = np.random.default_rng(3)
    for n, d in ((16, 3), (5, 1), (2, 2)):
        a, b = rng.standard_normal((n, d)), rng.standard_normal((n, d))
        assert W.cycle_distance(a, b) == pytest.approx(brute_cycle_distance(a, b), rel=1e-12)
        assert W.cycle_distance(a, np.roll(a, 3, axis=0)) == pytest.approx(0.0, abs=1e-12)
        assert W.cycle_distance(a, np.roll(a[::-1], 1, axis=0)) == pytest.approx(0.0, abs=1e-12)
    # a constant offset c between otherwise equal cycles: |c|
    a = rng.standard_normal((8, 2))
    assert W.cycle_distance(a, a + [3.0, 4.0]) == pytest.approx(5.0, rel=1e-12)


def test_amplitude_is_the_rms_distance_from_the_mean():
    """Sixteen points on a circle of radius 5 about (1, 2): 5; a segment -1..1: sqrt(mean(x^2))."""
    ang = 2 * np.pi * np.arange(16) / 16
    assert W._amplitude(np.column_stack([1 + 5 * np.cos(ang), 2 + 5 * np.sin(ang)])) == pytest.approx(5.0)
    x = np.linspace(-1, 1, 5)[:, None] + 7.0
    assert W._amplitude(x) == pytest.approx(np.sqrt(np.mean(np.linspace(-1, 1, 5) ** 2)))


# ------------------------------------------------------------------------ viterbi
@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_viterbi_finds_the_cheapest_path(seed):
    """Against every one of the 3^6 paths: per-frame costs plus ``switch`` per change of
    state (some states forbidden with an infinite cost)."""
    rng = np.random.default_rng(seed)
    cost = rng.random((6, 3)) * 2.0
    cost[rng.random((6, 3)) < 0.2] = np.inf
    cost[:, 2] = np.minimum(cost[:, 2], 1.5)  # one state always allowed
    switch = 0.6
    best, best_path = np.inf, None
    for path in itertools.product(range(3), repeat=6):
        c = sum(cost[t, s] for t, s in enumerate(path)) + switch * sum(a != b for a, b in zip(path, path[1:]))
        if c < best:
            best, best_path = c, path
    got = W._viterbi(cost, switch)
    assert got.tolist() == list(best_path)


def test_viterbi_takes_the_path_with_fewer_switches_on_equal_cost():
    """Staying in state 0 costs 1 + 1 = 2, switching to state 1 costs 1 + 0.5 + 0.5 = 2:
    equal, and the path stays; likewise staying in state 1 (1.5 + 0) against coming from
    state 0 (1 + 0.5 + 0)."""
    cost = np.array([[1.0, 5.0], [1.0, 0.5]])
    assert W._viterbi(cost, 0.5).tolist() == [0, 0]
    assert W._viterbi(cost, 0.4).tolist() == [0, 1]
    assert W._viterbi(np.array([[1.0, 1.5], [1.0, 0.0]]), 0.5).tolist() == [1, 1]
    assert W._viterbi(np.array([[1.0, 1.6], [1.0, 0.0]]), 0.5).tolist() == [0, 1]
    assert W._viterbi(np.array([[3.0, 1.0, 2.0]]), 1.0).tolist() == [1]


# ------------------------------------------------------------- dilate and distances
def test_dilate_grows_every_run_by_the_margin():
    mask = np.zeros(15, dtype=bool)
    mask[[0, 6, 7, 14]] = True
    for margin in (1, 2, 3):
        want = np.array([np.any(mask[max(0, i - margin) : i + margin + 1]) for i in range(15)])
        np.testing.assert_array_equal(W._dilate(mask, margin), want)
    for margin in (0, -2):
        out = W._dilate(mask, margin)
        np.testing.assert_array_equal(out, mask)
        assert out is not mask
    empty = np.zeros(5, dtype=bool)
    assert not W._dilate(empty, 3).any() and W._dilate(empty, 3) is not empty


def test_typical_distance_is_the_median_distance_to_the_cycle():
    """Frames at distances 1, 2 and 10 above a closed square cycle: median 2; frames on
    the cycle give the floor 1e-9."""
    square = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]])
    frames = np.array([[2.0, -1.0], [2.0, 6.0], [-10.0, 2.0]])
    assert W._typical_distance(frames, square) == pytest.approx(2.0)
    assert W._typical_distance(square, square) == 1e-9


def test_candidate_cost_is_the_nearest_cycle_over_its_scale_where_allowed():
    square = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]])
    poses = np.array([[2.0, -1.0], [2.0, 6.0], [2.0, 2.0]])
    c = W._Candidate(cycles=[square, square + 100.0], scales=[2.0, 0.5],
                     allowed=np.array([True, True, False]))
    want = np.minimum(distance_to_cycle(poses, square) / 2.0, distance_to_cycle(poses, square + 100.0) / 0.5)
    np.testing.assert_allclose(W._candidate_cost(c, poses), [want[0], want[1], np.inf])
    np.testing.assert_allclose(want[:2], [0.5, 1.0])


# ---------------------------------------------------------- autocorrelation period
def test_autocorrelation_period_on_a_two_frame_pattern():
    """A pattern repeating every 2 frames correlates +1 at even lags, -1 at odd ones.  The
    lags examined run from max(2, floor(guess / 2)) to min(ceil(1.5 guess), 0.8 T): a guess
    of 5 examines 2..8 and finds 2, one of 6 examines 3..9 and finds 4, one of 9 examines
    4..14 and finds 4."""
    x = np.tile([[1.0, -2.0], [-1.0, 2.0]], (20, 1))
    assert W.autocorrelation_period(x, 5.0) == 2.0
    assert W.autocorrelation_period(x, 4.0) == 2.0
    assert W.autocorrelation_period(x, 6.0) == 4.0
    assert W.autocorrelation_period(x, 9.0) == 4.0
    # a guess of 0, a negative or an infinite one is returned as it is
    for guess in (0.0, -3.0, float("inf")):
        assert W.autocorrelation_period(x, guess) == guess


def test_autocorrelation_period_needs_the_minimum_correlation():
    """The period is taken only when its correlation is at least ``min_correlation`` (0.3 by
    default): computed here by hand at the lag of the pattern."""
    rng = np.random.default_rng(0)
    t = np.arange(120)
    x = np.column_stack([np.sin(2 * np.pi * t / 12), np.cos(2 * np.pi * t / 12)]) + 1.2 * rng.standard_normal((120, 2))
    xc = x - x.mean(axis=0)
    a, b = xc[:-12], xc[12:]
    corr = np.sum(a * b) / np.sqrt(np.sum(a * a) * np.sum(b * b))
    assert 0.3 < corr < 0.6
    assert W.autocorrelation_period(x, 11.0) == 12.0
    assert W.autocorrelation_period(x, 11.0, min_correlation=corr) == 12.0
    assert W.autocorrelation_period(x, 11.0, min_correlation=corr + 1e-9) == 11.0
    # a constant stretch correlates with nothing: the guess stands
    assert W.autocorrelation_period(np.ones((60, 2)), 10.0) == 10.0


def test_autocorrelation_period_needs_three_lags():
    """Lags lo..hi with hi - lo < 2 leave no interior maximum to find: 13 frames allow lags
    up to int(0.8 * 13) = 10, so a guess of 14 (lags from 7) examines 7..10 and one of 18
    (lags 9..10) keeps the guess."""
    x = np.tile([[0, 0], [3, 1], [1, -2], [-2, 2], [2, 3], [-1, -1], [0, -3], [4, 0]], (2, 1))[:13].astype(float)
    assert W.autocorrelation_period(x, 14.0) == 8.0
    assert W.autocorrelation_period(x, 18.0) == 18.0


# ------------------------------------------------------------------- window_table
def _fake_fit(calls, cycles_of, steadiness=1.0, clear=True):
    """A stand-in for _fit_window: the window's first analysed frame number is in column 0
    of its points; it turns cycles_of(start) times (a coordinate of that many turns)."""

    def fit(points, prime, scale_fraction):
        start = int(points[0, 0])
        calls.append((start, points[:, 0].astype(int).tolist(), prime, scale_fraction))
        c = cycles_of(start)
        info = {"threshold": 2.0, "birth": 0.5, "death": 1.5, "clear": clear, "scale": 1.0,
                "cycles": c, "steadiness": steadiness}
        theta = np.mod(np.linspace(0.0, c, len(points)), 1.0) if clear else None
        return info, theta

    return fit


def test_window_table_plans_the_windows(monkeypatch):
    """100 frames at 10 fps.  2 s: 20 frames stepped by max(0.5, 2 / 8) s = 5 frames, from
    0 to 75 and a last one ending at frame 100 (start 80); 6 s: 60 frames stepped by
    round(7.5) = 8 frames, 0 to 40 (which already ends at the last frame); 0.9 s (9 frames)
    and 11 s (110) are skipped, 1 s (10 frames) and 10 s (all 100) are kept.  At most 7
    points a window: every ceil(20 / 7) = 3rd frame of 20, every 9th of 60, every 2nd of
    10, every 15th of 100."""
    calls = []
    monkeypatch.setattr(W, "_fit_window", _fake_fit(calls, lambda s: 2.0))
    pts = np.column_stack([np.arange(100.0), np.zeros(100)])
    wins = W.window_table(pts, pts, 10.0, lengths=(2.0, 6.0, 0.9, 11.0, 1.0, 10.0), max_points=7, prime=5,
                          scale_fraction=0.7, progress=False)
    want = [(a, a + 20, 3) for a in list(range(0, 76, 5)) + [80]]
    want += [(a, a + 60, 9) for a in range(0, 41, 8)]
    want += [(a, a + 10, 2) for a in list(range(0, 91, 5))]
    want += [(0, 100, 15)]
    assert [(w.start, w.stop, w.step) for w in wins] == want
    assert [c[0] for c in calls] == [a for a, _, _ in want]
    assert calls[0][1:] == ([0, 3, 6, 9, 12, 15, 18], 5, 0.7)
    assert calls[-2][1] == list(range(90, 100, 2))
    assert calls[-1][1] == list(range(0, 100, 15))


def test_window_table_loops_on_enough_steady_turns(monkeypatch):
    """A window loops when its bar is clear, it turns at least ``min_cycles`` times and at
    least ``min_steadiness`` of its steps go one way (both inclusive); its period is its
    frames over its turns, its cycle the binned cycle of its coordinate and poses."""
    pts = np.column_stack([np.arange(60.0), np.zeros(60)])
    poses = np.column_stack([np.sin(np.arange(60.0)), np.cos(np.arange(60.0))])
    turns = {0: 0.9, 10: 0.89, 20: 0.0, 30: 2.5, 40: 1.0}
    calls = []
    monkeypatch.setattr(W, "_fit_window", _fake_fit(calls, lambda s: turns[s]))
    wins = W.window_table(pts, poses, 10.0, lengths=(2.0,), stride=1.0, progress=False)
    assert [w.start for w in wins] == [0, 10, 20, 30, 40]
    assert [w.looping for w in wins] == [True, False, False, True, True]
    assert [w.cycles for w in wins] == [0.9, 0.89, 0.0, 2.5, 1.0]
    np.testing.assert_allclose([w.period_frames for w in wins[:2]] + [w.period_frames for w in wins[3:]],
                               [20 / 0.9, 20 / 0.89, 8.0, 20.0])
    assert np.isnan(wins[2].period_frames)
    assert wins[1].cycle is None and wins[2].cycle is None
    theta = np.mod(np.linspace(0.0, 2.5, 20), 1.0)
    np.testing.assert_allclose(wins[3].cycle, W.binned_cycle(theta, poses[30:50]))
    # the steadiness threshold, inclusive
    for steady, loops in ((0.5, True), (0.49, False)):
        monkeypatch.setattr(W, "_fit_window", _fake_fit([], lambda s: 2.0, steadiness=steady))
        assert all(w.looping is loops for w in W.window_table(pts, poses, 10.0, lengths=(2.0,), progress=False))
    # no clear bar: no coordinate, no loop, however many turns
    monkeypatch.setattr(W, "_fit_window", _fake_fit([], lambda s: 2.0, clear=False))
    assert not any(w.looping for w in W.window_table(pts, poses, 10.0, lengths=(2.0,), progress=False))


def test_fit_window_reads_turns_and_steadiness_of_a_circle():
    """Forty points round a circle twice: one clear bar, a coordinate of two turns, every
    step the same way; three points on a line have no H1 bar at all."""
    t = np.arange(40)
    pts = np.column_stack([np.cos(2 * np.pi * t / 20), np.sin(2 * np.pi * t / 20)])
    info, theta = W._fit_window(pts, 47, 0.9)
    assert theta is not None and theta.shape == (40,)
    assert info["clear"] and info["birth"] < info["death"]
    assert info["cycles"] == pytest.approx(39 / 20, abs=0.05)
    assert info["steadiness"] == 1.0
    info, theta = W._fit_window(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]), 47, 0.9)
    assert theta is None and np.isnan(info["birth"]) and np.isnan(info["death"]) and "clear" not in info


# ------------------------------------------------------------------- clustering
def _loop(cycle, looping=True):
    return WindowInfo(start=0, stop=20, step=1, birth=0.1, death=1.0, threshold=2.0, looping=looping,
                      cycle=cycle, cycles=2.0, period_frames=10.0)


def test_cluster_windows_by_relative_cycle_distance():
    """Cycles of amplitude 10: one shifted by (3, 0) is 0.3 amplitudes away, one by
    (0, 8) 0.8; average linkage cut at 0.5 groups the first two, at 0.2 none."""
    ang = 2 * np.pi * np.arange(16) / 16
    a = 10 * np.column_stack([np.cos(ang), np.sin(ang)])
    w1, w2, w3 = _loop(a), _loop(a + [3.0, 0.0]), _loop(a + [0.0, 8.0])
    off = _loop(a + 50.0, looping=False)
    groups = W._cluster_windows([w1, off, w2, w3], 0.5)
    assert sorted([[id(w) for w in g] for g in groups], key=len) == [[id(w3)], [id(w1), id(w2)]]
    assert len(W._cluster_windows([w1, w2, w3], 0.2)) == 3
    assert len(W._cluster_windows([w1, w2, w3], 0.9)) == 1
    assert W._cluster_windows([w1, off], 0.5) == [[w1]]
    assert W._cluster_windows([off], 0.5) == []


# ------------------------------------------------------------- windowed_motions
def _two_motions():
    """96 frames: 48 round circle A (16 frames a turn, radius 10), then 48 round circle B
    (centred 100 away); each window's cycle is its circle's 16 frames, so every frame lies
    on its own motion's cycle (distance 0) and 10 radii from the other's."""
    ang = 2 * np.pi * np.arange(16) / 16
    a = 10 * np.column_stack([np.cos(ang), np.sin(ang)])
    b = a + [100.0, 0.0]
    poses = np.concatenate([a[np.arange(48) % 16], b[np.arange(48) % 16]])

    def win(start, cycle, birth, death, scale):
        return WindowInfo(start=start, stop=start + 32, step=1, birth=birth, death=death, threshold=9.0,
                          scale=scale, clear=True, cycles=2.0, steadiness=1.0, period_frames=16.0,
                          looping=True, cycle=cycle)

    wins = [win(0, a, 0.1, 1.0, 0.5), win(16, a, 0.3, 2.0, 0.7), win(48, b, 0.2, 3.0, 0.4),
            win(64, b, 0.4, 5.0, 0.6)]
    return poses, wins


def test_windowed_motions_from_windows_alone():
    """Two groups of alike windows, one on each circle: frames 0-47 are motion 0 and 48-95
    motion 1; each segment's period is its stretch's autocorrelation period (16), its turns
    48 / 16 = 3, its birth, death and scale the medians over the windows inside it."""
    poses, wins = _two_motions()
    labels, segments, n = W.windowed_motions(wins, [], np.full(96, -1), 0, poses, window=4, min_cycles=1.5,
                                             similarity=0.5, merge_overlap=0.5)
    assert n == 2
    np.testing.assert_array_equal(labels, [0] * 48 + [1] * 48)
    assert [w.motion for w in wins] == [0, 0, 1, 1]
    got = [(s.start, s.stop, s.motion, s.classes, s.cycles, s.period_frames) for s in segments]
    assert got == [(0, 48, 0, (), 3.0, 16.0), (48, 96, 1, (), 3.0, 16.0)]
    assert [(s.birth, s.death, s.scale) for s in segments] == [(0.2, 1.5, 0.6), (pytest.approx(0.3), 4.0, 0.5)]
    # two windows of 2 turns each hold fewer than min_cycles = 2.5 turns: no motion at all
    poses, wins = _two_motions()
    labels, segments, n = W.windowed_motions(wins, [], np.full(96, -1), 0, poses, window=4, min_cycles=2.5,
                                             similarity=0.5, merge_overlap=0.5)
    assert n == 0 and segments == [] and np.all(labels == -1) and all(w.motion == -1 for w in wins)


def test_windowed_motions_join_windows_to_the_global_motion_they_overlap():
    """A global class excites frames 0-47 (circle A, three turns of its coordinate): the
    windows on A cover exactly those frames (share 1 > merge_overlap 0.5) and join its
    motion, whose segment then reads turns and period from the class's coordinate and its
    birth, death and scale from the class; the windows on B make motion 1.  With
    merge_overlap = 1 (a share must exceed it) the A windows stay apart, label nothing
    (the global labels win on frames 0-47) and keep no motion."""
    from cyclecoord.periodic.detection.result import DetectedClass

    for overlap, joined in ((0.5, True), (1.0, False)):
        poses, wins = _two_motions()
        mask = np.arange(96) < 48
        coord = np.where(mask, np.mod(np.arange(96) / 16, 1.0), 0.0)
        cls = DetectedClass(index=3, birth=0.25, death=7.0, scale=0.8, coordinate=coord, speed=np.zeros(96),
                            consistency=np.ones(96), mask=mask, motion=0)
        glob = np.where(mask, 0, -1)
        labels, segments, n = W.windowed_motions(wins, [cls], glob, 1, poses, window=4, min_cycles=1.5,
                                                 similarity=0.5, merge_overlap=overlap)
        assert n == 2 and cls.motion == 0
        np.testing.assert_array_equal(labels, [0] * 48 + [1] * 48)
        assert [w.motion for w in wins] == ([0, 0, 1, 1] if joined else [-1, -1, 1, 1])
        first = segments[0]
        assert (first.start, first.stop, first.motion, first.classes) == (0, 48, 0, (3,))
        assert (first.birth, first.death, first.scale) == (0.25, 7.0, 0.8)
        assert first.period_frames == pytest.approx(16.0) and first.cycles == pytest.approx(47 / 16)
        assert (segments[1].start, segments[1].stop, segments[1].classes) == (48, 96, ())


@pytest.mark.parametrize("r, labelled", [(1.9, True), (2.1, False)])
def test_windowed_motions_leave_frames_beyond_none_cost_unlabelled(r, labelled):
    """One window on a 16-gon of radius 10, every 16th frame of it at distance 1 from the
    polygon (radially out from a vertex) but the last two at distance r: its typical
    distance is the median, 1.  Frames 48-79 at distance r cost r a frame against
    NONE_COST = 2 for "nothing periodic": at 2.1 the 32 frames save 3.2 by switching, more
    than the one switch costs (window / 2 = 2), and go unlabelled; at 1.9 they stay."""
    assert W.NONE_COST == 2.0
    ang = 2 * np.pi * np.arange(16) / 16
    cycle = 10 * np.column_stack([np.cos(ang), np.sin(ang)])
    radius = np.where(np.arange(80) < 48, 11.0, 10.0 + r)
    poses = (cycle[np.arange(80) % 16] / 10.0) * radius[:, None]
    w = WindowInfo(start=0, stop=80, step=16, birth=0.1, death=1.0, threshold=9.0, scale=0.5, clear=True,
                   cycles=5.0, steadiness=1.0, period_frames=16.0, looping=True, cycle=cycle)
    assert W._typical_distance(poses[0:80:16], cycle) == pytest.approx(1.0)
    labels, segments, n = W.windowed_motions([w], [], np.full(80, -1), 0, poses, window=4, min_cycles=1.5,
                                             similarity=0.5, merge_overlap=0.5)
    assert n == 1
    np.testing.assert_array_equal(labels, [0] * 48 + [0 if labelled else -1] * 32)
    assert [(s.start, s.stop) for s in segments] == [(0, 80 if labelled else 48)]


def test_windowed_segment_period_from_the_windows_holding_min_cycles():
    """A segment without a class takes its period from the median frames-per-turn of the
    windows inside it that turn at least ``min_cycles`` times (exactly 1.5 counts), refined
    by the stretch's autocorrelation -- which a still stretch cannot refine, so the
    median of 13 and 14 stands: 40 frames are 40 / 13.5 turns.  With no window holding
    min_cycles every window inside counts: the median of 13, 20 and 14."""
    poses = np.zeros((40, 2))
    cycle = np.zeros((16, 2))

    def win(a, turns, period):
        return WindowInfo(start=a, stop=a + 20, step=1, birth=0.1, death=1.0, threshold=2.0, scale=0.5,
                          clear=True, cycles=turns, steadiness=1.0, period_frames=period, looping=True,
                          cycle=cycle)

    for min_cycles, period in ((1.5, 13.5), (1.6, 14.0)):
        wins = [win(0, 1.5, 13.0), win(10, 1.0, 20.0), win(20, 1.5, 14.0)]
        labels, segments, n = W.windowed_motions(wins, [], np.full(40, -1), 0, poses, window=4,
                                                 min_cycles=min_cycles, similarity=0.5, merge_overlap=0.5)
        assert n == 1 and np.all(labels == 0)
        ((seg,),) = [segments]
        assert (seg.start, seg.stop, seg.period_frames) == (0, 40, period)
        assert seg.cycles == pytest.approx(40 / period)


def test_window_table_defaults_and_a_hop_of_one_frame(monkeypatch):
    """By default windows of 2, 4 and 6 s; at 1 fps a 10 s window steps by
    round(max(0.5, 10 / 8)) = 1 frame."""
    monkeypatch.setattr(W, "_fit_window", _fake_fit([], lambda s: 2.0))
    pts = np.column_stack([np.arange(100.0), np.zeros(100)])
    wins = W.window_table(pts, pts, 10.0, progress=False)
    assert sorted({w.stop - w.start for w in wins}) == [20, 40, 60]
    slow = W.window_table(pts[:14], pts[:14], 1.0, lengths=(10.0,), progress=False)
    assert [w.start for w in slow] == [0, 1, 2, 3, 4]


def _circle_win(a, b, birth=1.0, cycles=3.0):
    ang = 2 * np.pi * np.arange(16) / 16
    cycle = 10.0 * np.column_stack([np.cos(ang), np.sin(ang)])
    return WindowInfo(start=a, stop=b, step=1, birth=birth, death=5.0, threshold=6.0, scale=4.0,
                      clear=True, cycles=cycles, steadiness=1.0, period_frames=16.0, looping=True,
                      cycle=cycle)


def _circle_class(index, motion, lo, hi, T):
    from cyclecoord.periodic.detection.result import DetectedClass

    mask = np.zeros(T, bool)
    mask[lo:hi] = True
    return DetectedClass(index=index, birth=1.0, death=5.0, scale=3.0,
                         coordinate=(np.arange(T) % 16) / 16.0, speed=np.full(T, 1 / 16),
                         consistency=np.ones(T), mask=mask, motion=motion)


def test_a_window_group_sharing_two_global_motions_equally_joins_the_first():
    """Global motions 0 (frames 0-49) and 1 (50-99); a group of windows over frames 25-74
    shares half its frames with each (over merge_overlap 0.4): a tie goes to the first."""
    T = 100
    ang = 2 * np.pi * np.arange(T) / 16
    poses = 10.0 * np.column_stack([np.cos(ang), np.sin(ang)])
    kept = [_circle_class(0, 0, 0, 50, T), _circle_class(1, 1, 50, 100, T)]
    win = _circle_win(25, 75)
    glob = np.r_[np.zeros(50, int), np.ones(50, int)]
    labels, segments, n = W.windowed_motions([win], kept, glob, 2, poses, window=5,
                                             min_cycles=1.5, similarity=0.5, merge_overlap=0.4)
    assert n == 2 and np.array_equal(labels, glob)
    assert win.motion == 0


def test_windows_inside_a_segment_start_before_its_end():
    """One group of two windows, 0-40 (birth 1) and 40-100 (birth 3); the poses of frames
    40-59 are far off the cycle, so the motion labels 0-39 and 60-99.  The first segment
    ends at frame 40, where the second window starts: that window is not inside it, so the
    segment's birth is the first window's alone."""
    T = 100
    ang = 2 * np.pi * np.arange(T) / 16
    poses = 10.0 * np.column_stack([np.cos(ang), np.sin(ang)])
    poses[40:60] += 1000.0
    wins = [_circle_win(0, 40, birth=1.0), _circle_win(40, 100, birth=3.0)]
    labels, segments, n = W.windowed_motions(wins, [], np.full(T, -1), 0, poses, window=3,
                                             min_cycles=1.5, similarity=0.5, merge_overlap=0.5)
    assert n == 1
    assert [(s.start, s.stop) for s in segments] == [(0, 40), (60, 100)]
    assert segments[0].birth == 1.0 and segments[1].birth == 3.0
