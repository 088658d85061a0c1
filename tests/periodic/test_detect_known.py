"""Known answers of detection's stages on hand-made inputs (issue 27: mutation score).

Label sequences, coordinates and bars are built by hand here; the expected runs, periods,
labels and segments are worked out in the comments, never taken from the code under test.
"""

import numpy as np
import pytest

from cyclecoord.errors import NoPeriodicMotionError, ParameterError
from cyclecoord.motion import Motion
from cyclecoord.periodic.barcode import CLEAR_RATIO, Barcode
from cyclecoord.periodic.detection._segments import (
    MAX_TURN,
    MIN_SPEED,
    class_period,
    drop_unsteady,
    mask_runs,
)
from cyclecoord.periodic.detection.classes import (
    _stretches,
    candidate_classes,
    excitation,
    motions_from_classes,
    read_classes,
)
from cyclecoord.periodic.detection.result import DetectedClass, Segment
from cyclecoord.periodic.detection.scoring import best_match_accuracy, boundary_errors


# ------------------------------------------------------------------ mask_runs
@pytest.mark.parametrize(
    "mask,runs",
    [
        ([], []),
        ([0], []),
        ([1], [(0, 1)]),
        ([1, 1, 0, 1], [(0, 2), (3, 4)]),
        ([0, 1, 1, 1, 0, 0, 1, 0, 1, 1], [(1, 4), (6, 7), (8, 10)]),
        ([1, 1, 1], [(0, 3)]),
    ],
)
def test_mask_runs_half_open(mask, runs):
    got = mask_runs(np.array(mask, dtype=bool))
    assert [(int(a), int(b)) for a, b in got] == runs


# ------------------------------------------------------------------ class_period
def test_class_period_reads_the_excited_runs_inside_an_offset_segment():
    """Frames 0-99 turn every 20 frames, 100-299 every 40; the class is excited on
    100-299 only.  Over the segment 50-250 the period is the excited part's 40 (the fast
    frames before it are not read), the turns are the whole segment's: 50 frames at
    1/20 and 150 at 1/40 (49 + 150 steps: 50/20 + 150/40 - the step into frame 100)."""
    t = np.arange(300, dtype=float)
    u = np.where(t < 100, t / 20.0, 5.0 + (t - 100) / 40.0)
    theta = np.mod(u, 1.0)
    mask = t >= 100
    cyc, period = class_period(theta, mask, 50, 250)
    assert cyc == pytest.approx(u[249] - u[50])
    assert period == pytest.approx(40.0, abs=1e-6)
    # backwards: the same turns and period
    cyc, period = class_period(np.mod(-u, 1.0), mask, 50, 250)
    assert cyc == pytest.approx(u[249] - u[50]) and period == pytest.approx(40.0, abs=1e-6)


def test_class_period_without_a_complete_winding_counts_frames_per_excited_turn():
    """Two excited runs of 20 frames (19 steps of 1/32 each: 0.59375 turns), together
    1.1875 >= 0.75 turns, neither a complete winding: 38 steps / 1.1875 turns = 32."""
    t = np.arange(120, dtype=float)
    theta = np.mod(t / 32.0, 1.0)
    mask = np.zeros(120, bool)
    mask[10:30] = True
    mask[60:80] = True
    cyc, period = class_period(theta, mask, 0, 120)
    assert cyc == pytest.approx(119 / 32.0)
    assert period == pytest.approx(38 / (38 / 32.0))


def test_class_period_excited_turns_at_exactly_three_quarters():
    """Frames 0-39 turn 1/16 a frame (not excited); frames 40-64 a run of 25 frames at
    1/32 a frame: 24 steps = 0.75 turns exactly, enough for the excited reading (24 / 0.75
    = 32 frames a turn); 23 steps (0.71875) are not: the whole segment then gives frames
    per turn over all of it."""
    t = np.arange(65, dtype=float)
    u = np.where(t < 40, t / 16.0, 39 / 16.0 + (t - 39) / 32.0)
    theta = np.mod(u, 1.0)
    mask = t >= 40
    cyc, period = class_period(theta, mask, 0, 65)
    assert cyc == pytest.approx(u[64] - u[0])
    assert period == pytest.approx(32.0)
    mask[40] = False  # 23 excited steps
    cyc, period = class_period(theta, mask, 0, 65)
    assert period == pytest.approx(64 / (u[64] - u[0]))


def test_class_period_one_frame_runs_and_a_still_segment():
    theta = np.full(50, 0.3)
    cyc, period = class_period(theta, np.ones(50, bool), 0, 50)
    assert cyc == 0.0 and np.isnan(period)
    # one-frame excited runs add no turn: the whole segment's frames per turn
    t = np.arange(50, dtype=float)
    theta = np.mod(t / 10.0, 1.0)
    mask = np.zeros(50, bool)
    mask[::2] = True
    cyc, period = class_period(theta, mask, 0, 50)
    assert cyc == pytest.approx(4.9) and period == pytest.approx(49 / 4.9)


def test_class_period_two_frame_runs_count():
    """Runs of exactly two frames (one step) are read: 40 of them, each 1/8 of a turn, make
    5 excited turns, no complete winding: 40 steps / 5 turns = 8."""
    t = np.arange(200, dtype=float)
    # the coordinate advances 1/8 on steps inside a run, 0 elsewhere
    inc = np.zeros(200)
    mask = (t % 5) < 2
    inc[1:] = np.where(mask[1:] & mask[:-1], 1 / 8.0, 0.0)
    theta = np.mod(np.cumsum(inc), 1.0)
    cyc, period = class_period(theta, mask, 0, 200)
    assert cyc == pytest.approx(5.0)
    assert period == pytest.approx(8.0)


# ------------------------------------------------------------------ drop_unsteady
def _turning_walk(T=240, turn=(100, 140, 90.0)):
    """The synthetic walk with its root rotations replaced by a heading alone: 0, then a
    ramp of ``turn[2]`` degrees over frames turn[0]-turn[1], then constant."""
    from cyclecoord.datasets import make_periodic_capture
    from cyclecoord.periodic.root import root_layout

    m = make_periodic_capture(n_frames=T, period=40.0, noise=0.0, speed_variation=0.0,
                              random_state=0).motion
    lay = root_layout(m)
    f = m.frames.copy()
    for c in ("rx", "rz"):
        f[:, lay.column(c)] = 0.0
    a, b, deg = turn
    f[:, lay.column("ry")] = np.interp(np.arange(T), [0, a, b, T - 1], [0, 0, deg, deg])
    joints = 30.0 * np.column_stack([np.sin(2 * np.pi * np.arange(T) / 40),
                                     np.cos(2 * np.pi * np.arange(T) / 40)])
    return m.with_frames(f), joints


def test_drop_unsteady_labels_a_turn_minus_one_and_splits_the_segment():
    """90 degrees over one period (40 frames) is over MAX_TURN (45) a period: the frames
    whose period-long window holds more than half of the turn go; 40 degrees a period stays."""
    assert MAX_TURN == 45.0 and MIN_SPEED == 0.2
    m, joints = _turning_walk()
    seg = Segment(0, 240, 0, (0,), 1.0, 2.0, 1.5, 6.0, 40.0)
    labels, out = drop_unsteady(np.zeros(240, int), [seg], joints, m, min_run=10)
    assert np.all(labels[103:137] == -1)
    assert np.all(labels[:95] == 0) and np.all(labels[145:] == 0)
    assert [(s.start, s.stop) for s in out] == [tuple(r) for r in mask_runs(labels == 0)]
    assert len(out) == 2
    # cycles shared in proportion to the frames kept
    for s in out:
        assert s.cycles == pytest.approx(6.0 * (s.stop - s.start) / 240)
    m, joints = _turning_walk(turn=(100, 140, 40.0))
    labels, out = drop_unsteady(np.zeros(240, int), [seg], joints, m, min_run=10)
    assert np.all(labels == 0) and out == [seg]
    # without a finite period no turn is judged
    m, joints = _turning_walk()
    nan_seg = Segment(0, 240, 0, (0,), 1.0, 2.0, 1.5, 6.0, float("nan"))
    labels, out = drop_unsteady(np.zeros(240, int), [nan_seg], joints, m, min_run=10)
    assert np.all(labels == 0) and len(out) == 1


def test_drop_unsteady_turn_threshold_is_strict():
    """A steady turn of 44.5 degrees a period all along is kept; 45.5 is not (exactly 45
    is not exact after the heading's trigonometry)."""
    for deg, kept in ((44.5 * 239 / 40.0, True), (45.5 * 239 / 40.0, False)):
        m, joints = _turning_walk(turn=(1, 239, deg))
        f = m.frames.copy()
        from cyclecoord.periodic.root import root_layout

        f[:, root_layout(m).column("ry")] = np.arange(240) * deg / 239.0
        m = m.with_frames(f)
        seg = Segment(0, 240, 0, (0,), 1.0, 2.0, 1.5, 6.0, 40.0)
        labels, _ = drop_unsteady(np.zeros(240, int), [seg], joints, m, min_run=10)
        assert np.all(labels[30:210] == (0 if kept else -1)), deg


def test_drop_unsteady_keeps_other_motions_and_sorts_by_start():
    T = 120
    ang = 2 * np.pi * np.arange(T) / 30
    joints = 30.0 * np.column_stack([np.sin(ang), np.cos(ang)])
    motion = Motion(joints, [("a", "rx"), ("b", "rx")], fps=30.0)
    labels = np.r_[np.ones(60, int), np.zeros(60, int)]
    s1 = Segment(0, 60, 1, (3,), 1.0, 2.0, 1.5, 2.0, 30.0)
    s0 = Segment(60, 120, 0, (0,), 1.0, 2.0, 1.5, 2.0, 30.0)
    got, out = drop_unsteady(labels.copy(), [s0, s1], joints, motion, min_run=5)
    np.testing.assert_array_equal(got, labels)
    assert [s.start for s in out] == [0, 60] and [s.motion for s in out] == [1, 0]
    # a label run inside a segment shorter than min_run is dropped, the rest stays
    lab = np.zeros(T, int)
    lab[50:53] = -1  # splits segment (0, 120) into 50 and 67 frames
    seg = Segment(0, 120, 0, (0,), 1.0, 2.0, 1.5, 4.0, 30.0)
    got, out = drop_unsteady(lab, [seg], joints, motion, min_run=60)
    assert [(s.start, s.stop) for s in out] == [(53, 120)]
    assert np.all(got[:53] == -1) and np.all(got[53:] == 0)
    assert out[0].cycles == pytest.approx(4.0 * 67 / 120)


# ------------------------------------------------------------------ excitation
def test_excitation_by_hand():
    theta = np.array([0.0, 0.1, 0.3, 0.2, 0.7])
    v = np.array([0.1, 0.2, -0.1, -0.5, -0.5])  # 0.5 wraps to -0.5; the last step repeated
    speed, cons = excitation(theta, 1)
    np.testing.assert_allclose(speed, v, atol=1e-12)
    np.testing.assert_array_equal(cons, np.ones(5))
    speed, cons = excitation(theta, 0)  # under one frame: one frame
    np.testing.assert_allclose(speed, v, atol=1e-12)
    speed, cons = excitation(theta, 3)  # centred mean, reflected at the ends
    want = [(v[0] + v[0] + v[1]) / 3, v[:3].mean(), v[1:4].mean(), v[2:5].mean(), (v[3] + 2 * v[4]) / 3]
    np.testing.assert_allclose(speed, want, atol=1e-12)
    np.testing.assert_allclose(cons, [1.0, 1 / 3, 1 / 3, 1.0, 1.0], atol=1e-12)
    speed, cons = excitation(np.array([0.95, 0.05]), 1)  # across the wrap: +0.1
    np.testing.assert_allclose(speed, [0.1, 0.1], atol=1e-12)
    speed, cons = excitation(np.array([0.4]), 5)
    np.testing.assert_array_equal(speed, [0.0])
    np.testing.assert_array_equal(cons, [0.0])


# ------------------------------------------------------------------ _stretches
def test_stretches_bridge_gaps_under_gap_and_need_min_cycles():
    """1/8 of a turn a frame (exact); excited 0-8 and 11-20 (a gap of 3 frames)."""
    t = np.arange(30)
    theta = np.mod(t / 8.0, 1.0)
    exc = np.zeros(30, bool)
    exc[0:9] = True
    exc[11:20] = True
    # the gap (frame 9 to 11) of 2 is not under 2: two stretches, each 8 steps = 1 turn
    got = _stretches(theta, exc, gap=2, min_cycles=1.0)
    np.testing.assert_array_equal(got, exc)
    assert not _stretches(theta, exc, gap=2, min_cycles=1.0 + 1e-9).any()
    # gap 3: bridged into 0-20, 19 steps = 2.375 turns
    want = np.zeros(30, bool)
    want[0:20] = True
    np.testing.assert_array_equal(_stretches(theta, exc, gap=3, min_cycles=2.375), want)
    assert not _stretches(theta, exc, gap=3, min_cycles=2.4).any()
    # a backward coordinate completes as many cycles
    np.testing.assert_array_equal(_stretches(np.mod(-t / 8.0, 1.0), exc, gap=3, min_cycles=2.375), want)
    # a one-frame run has no step
    one = np.zeros(30, bool)
    one[5] = True
    assert not _stretches(theta, one, gap=1, min_cycles=1e-9).any()
    assert _stretches(theta, one, gap=1, min_cycles=0.0)[5]


# ------------------------------------------------------------------ candidate_classes
def _bars(h1, threshold=10.0):
    h1 = np.array(h1, dtype=float).reshape(-1, 2)
    return Barcode(h0=np.zeros((0, 2)), h1=h1, cocycles=[None] * len(h1), threshold=threshold,
                   prime=47, n_points=10)


def test_candidate_classes_by_hand():
    assert candidate_classes(_bars([]), None, 5, 0.1) == []
    assert candidate_classes(_bars([]), 3, 5, 0.1) == []
    bars = _bars([[1.0, 9.0], [1.0, 5.0], [2.0, 2.5], [0.0, 0.5]])  # persistence 8, 4, 0.5, 0.5
    assert candidate_classes(bars, 2, 5, 0.1) == [0, 1]
    assert candidate_classes(bars, 9, 5, 0.1) == [0, 1, 2, 3]
    assert candidate_classes(bars, 1, 5, 0.1) == [0]
    # ratio 2.5/2 = 1.25 < 1.5: bar 2 out; bar 3 born at 0: ratio infinite; 0.5 >= 0.0625 * 8
    assert candidate_classes(bars, None, 5, 0.0625) == [0, 1, 3]
    assert candidate_classes(bars, None, 5, 0.0626) == [0, 1]
    assert candidate_classes(bars, None, 5, 0.5) == [0, 1]  # 4 >= 0.5 * 8
    assert candidate_classes(bars, None, 5, 0.51) == [0]
    assert candidate_classes(bars, None, 1, 0.0) == [0]
    assert candidate_classes(bars, None, 2, 0.0) == [0, 1]
    # the death is capped at the threshold: 1 -> 1.4 is a ratio of 1.4 only
    capped = _bars([[1.0, 100.0]], threshold=1.4)
    assert candidate_classes(capped, None, 5, 0.1) == []
    assert candidate_classes(_bars([[1.0, 100.0]], threshold=CLEAR_RATIO), None, 5, 0.1) == [0]


# ------------------------------------------------------------------ read_classes
class _Stub:
    """An estimator whose classes read given coordinates (a missing one fails)."""

    def __init__(self, thetas):
        self.thetas = thetas

    def with_coordinate_params(self, class_index):
        from types import SimpleNamespace

        def fit():
            if class_index not in self.thetas:
                raise ParameterError("no cocycle")

        return SimpleNamespace(
            fit_coordinate=fit, coordinates_=self.thetas.get(class_index),
            selection_=SimpleNamespace(birth=1.0 + class_index, death=3.0, scale=2.0),
        )


def test_read_classes_speed_threshold_both_ways_and_failed_classes():
    t = np.arange(200)
    fwd = np.mod(t / 64.0, 1.0)  # 1/64 turns a frame (exact)
    back = np.mod(-t / 32.0, 1.0)  # -1/32
    notes = []
    got = read_classes(_Stub({0: fwd, 2: back}), [0, 1, 2], window=5, min_speed=1 / 64,
                       min_consistency=0.4, min_cycles=1.5, notes=notes)
    assert [c.index for c in got] == [0, 2]
    assert notes == ["H1 class 1 skipped: no cocycle"]
    assert all(c.status == "kept" and c.mask.all() for c in got)
    assert got[1].birth == 3.0 and got[1].scale == 2.0 and got[1].death == 3.0
    np.testing.assert_array_equal(got[1].speed, np.full(200, -1 / 32))
    # 1/32 a frame is under 0.0313: never excited
    (c,) = read_classes(_Stub({0: back}), [0], window=5, min_speed=0.0313, min_consistency=0.4,
                        min_cycles=1.5, notes=[])
    assert not c.mask.any() and c.status == "never completes 1.5 steady cycles"
    # 200 frames at 1/64: 199/64 = 3.11 turns; 3.2 cycles are never completed
    (c,) = read_classes(_Stub({0: fwd}), [0], window=5, min_speed=0.01, min_consistency=0.4,
                        min_cycles=3.2, notes=[])
    assert c.status == "never completes 3.2 steady cycles"
    (c,) = read_classes(_Stub({0: fwd}), [0], window=5, min_speed=0.01, min_consistency=0.4,
                        min_cycles=199 / 64, notes=[])
    assert c.status == "kept"


def test_read_classes_bridges_gaps_shorter_than_the_window():
    """A coordinate stalling for 6 frames between two stretches of 2 turns: with a window
    of 3 the stall splits the mask; with a window of 9 it is bridged into one stretch."""
    inc = np.r_[np.full(80, 1 / 40.0), np.zeros(6), np.full(80, 1 / 40.0)]
    theta = np.mod(np.r_[0.0, np.cumsum(inc)], 1.0)
    (c3,) = read_classes(_Stub({0: theta}), [0], window=3, min_speed=0.01, min_consistency=0.4,
                         min_cycles=1.5, notes=[])
    assert c3.mask[:75].all() and not c3.mask[82:85].any() and c3.mask[90:].all()
    (c9,) = read_classes(_Stub({0: theta}), [0], window=9, min_speed=0.01, min_consistency=0.4,
                         min_cycles=1.5, notes=[])
    assert c9.mask.sum() > c3.mask.sum() and c9.mask[70:95].all()


# ------------------------------------------------------------------ motions_from_classes
def _cls(index, mask, speed, n=100, period=20.0, status="kept"):
    t = np.arange(n)
    m = np.zeros(n, bool)
    for a, b in mask:
        m[a:b] = True
    return DetectedClass(index=index, birth=float(index), death=10.0, scale=5.0,
                         coordinate=np.mod(t / period, 1.0), speed=np.full(n, speed),
                         consistency=np.ones(n), mask=m, status=status)


def test_motions_from_classes_merge_label_and_segment_by_hand():
    """A (index 3) excited 0-60 and B (index 1) 10-60 overlap by 50 of B's 50 frames: one
    motion, numbered 0 (first excited frame 0), led by B (the lower index).  C (index 0)
    excited 50-100 overlaps A and B by 10 of 50: motion 1.  Frames 50-59 go to C, the
    stronger (0.05 against 0.02).  D is not kept."""
    A = _cls(3, [(0, 60)], 0.02)
    B = _cls(1, [(10, 60)], 0.02)
    C = _cls(0, [(50, 100)], -0.05)
    D = _cls(5, [(0, 100)], 0.9, status="never completes")
    kept, labels, segs, n = motions_from_classes([A, B, C, D], 100, 10, 0.5)
    assert n == 2 and kept == [A, B, C]
    assert (A.motion, B.motion, C.motion, D.motion) == (0, 0, 1, -1)
    np.testing.assert_array_equal(labels, [0] * 50 + [1] * 50)
    assert [(s.start, s.stop, s.motion, s.classes) for s in segs] == [(0, 50, 0, (1, 3)), (50, 100, 1, (0,))]
    s0 = segs[0]
    assert (s0.birth, s0.death, s0.scale) == (1.0, 10.0, 5.0)
    assert s0.cycles == pytest.approx(49 / 20.0) and s0.period_frames == pytest.approx(20.0, abs=1e-6)
    # overlap of exactly merge_overlap is not more: A and B stay apart (3 motions)
    A2, B2, C2 = _cls(3, [(0, 60)], 0.02), _cls(1, [(10, 60)], 0.03), _cls(0, [(50, 100)], 0.05)
    _, labels, segs, n = motions_from_classes([A2, B2, C2], 100, 10, 1.0)
    assert n == 3 and (A2.motion, B2.motion, C2.motion) == (0, 1, 2)
    np.testing.assert_array_equal(labels, [0] * 10 + [1] * 40 + [2] * 50)


def test_motions_from_classes_merges_chains_through_union_find():
    """A-B overlap, B-C overlap, A-C do not: all three are one motion."""
    A, B, C = _cls(2, [(0, 40)], 0.02), _cls(1, [(30, 70)], 0.02), _cls(0, [(60, 100)], 0.02)
    _, labels, segs, n = motions_from_classes([A, B, C], 100, 4, 0.2)
    assert n == 1 and {A.motion, B.motion, C.motion} == {0}
    assert [(s.start, s.stop, s.classes) for s in segs] == [(0, 100, (0, 2, 1))]
    # later classes first: motions numbered by their first excited frame
    late, early = _cls(0, [(60, 100)], 0.02), _cls(1, [(0, 30)], 0.02)
    _, labels, segs, n = motions_from_classes([late, early], 100, 4, 0.5)
    assert (late.motion, early.motion) == (1, 0) and n == 2
    assert [s.motion for s in segs] == [0, 1]


def test_motions_from_classes_drops_label_runs_under_half_the_window():
    """window 10: a run of 4 frames goes, one of 5 stays."""
    for length, kept in ((4, False), (5, True)):
        c = _cls(0, [(0, 30), (40, 40 + length)], 0.02)
        _, labels, segs, n = motions_from_classes([c], 100, 10, 0.5)
        assert np.all(labels[40 : 40 + length] == (0 if kept else -1)), length
        assert len(segs) == (2 if kept else 1)
        assert np.all(labels[:30] == 0) and np.all(labels[50:] == -1)


def test_motions_from_classes_without_kept_classes():
    c = _cls(0, [(0, 50)], 0.02, n=60, status="never completes")
    kept, labels, segs, n = motions_from_classes([c], 60, 10, 0.5)
    assert kept == [] and segs == [] and n == 0
    np.testing.assert_array_equal(labels, np.full(60, -1))
    # a kept class excited nowhere with any strength labels nothing
    z = _cls(0, [(0, 50)], 0.0, n=60)
    _, labels, segs, n = motions_from_classes([z], 60, 10, 0.5)
    assert n == 1 and segs == [] and np.all(labels == -1)


# ------------------------------------------------------------------ scoring
def _seg(a, b):
    return Segment(a, b, 0, (0,), 1, 2, 1.5, 1, 10)


def test_boundary_errors_by_hand():
    truth = [(5, 40, "a"), (50, 90, "b")]  # boundaries: 5 (first start), 40-50, 90 (last stop)
    segs = [_seg(0, 38), _seg(45, 95), _seg(95, 100)]
    # true, gaps first: 40-50 holds 45: 0; 5 -> nearest predicted 38: 33; 90 -> 95: 5
    # predicted 38 -> 2, 45 -> 0 (inside), 95 -> 5 (or the end 100: 5)
    assert boundary_errors(segs, truth, 100) == [0, 33, 5, 2, 0, 5]
    # no predicted boundary: every true one is off by the frame count
    assert boundary_errors([_seg(0, 100)], truth, 100) == [100, 100, 100]
    # truth spanning the whole capture has no boundary; a predicted one is judged
    # against the capture's ends
    assert boundary_errors([_seg(0, 30), _seg(30, 100)], [(0, 100, "a")], 100) == [30]
    assert boundary_errors([_seg(0, 98)], [(0, 100, "a")], 100) == [2]
    assert boundary_errors([], [], 10) == []


def test_best_match_accuracy_by_hand():
    truth = np.array([0, 0, 0, 1, 1, 1, -1, -1])
    pred = np.array([4, 4, 9, 9, 9, -1, 4, 4])
    # matching 4->0 (2 frames), 9->1 (2 frames): 4 of the 6 labelled frames
    acc, match = best_match_accuracy(pred, truth)
    assert acc == pytest.approx(4 / 6) and match == {4: 0, 9: 1}
    acc, match = best_match_accuracy(np.full(8, -1), truth)
    assert acc == 0.0 and match == {}
    acc, match = best_match_accuracy(pred, np.full(8, -1))
    assert np.isnan(acc) and match == {}
    # more predicted motions than true ones: the best one-to-one match
    acc, match = best_match_accuracy(np.array([1, 1, 2, 3, 3, 3]), np.array([0, 0, 0, 0, 0, 5]))
    assert match == {3: 5, 1: 0} or match == {1: 0, 3: 5}
    assert acc == pytest.approx(3 / 6)


# ------------------------------------------------------------------ detect (detector.py)
@pytest.fixture(scope="module")
def walk():
    """A short synthetic walk: 240 frames at 120 fps, a steady 40-frame period."""
    from cyclecoord.datasets import make_periodic_capture

    return make_periodic_capture(n_frames=240, period=40.0, speed_variation=0.0,
                                 random_state=0).motion


@pytest.fixture(scope="module")
def found(walk):
    from cyclecoord.periodic.detection import detect

    return detect(walk, progress=False, method="global")


def _bare(T):
    """A motion without a skeleton (two swinging channels)."""
    t = np.arange(T)
    return Motion(np.c_[np.sin(t / 5.0), np.cos(t / 5.0)], [("a", "rx"), ("b", "rx")], fps=30.0)


def test_detect_reads_the_rig_only_when_asked_and_there_is_a_skeleton(walk, monkeypatch):
    import cyclecoord.rig
    from cyclecoord.periodic.detection import detect

    class Called(Exception):
        pass

    def refuse(*args, **kwargs):
        raise Called

    monkeypatch.setattr(cyclecoord.rig, "normalize_rig", refuse)
    short = walk.window((0, 19))  # too few frames: refused right after the rig is read
    with pytest.raises(Called):
        detect(short, progress=False)
    with pytest.raises(ParameterError, match="19 frames are too few"):
        detect(short, rig=False, progress=False)
    with pytest.raises(ParameterError, match="19 frames are too few"):
        detect(_bare(19), progress=False)  # no skeleton: no rig to read


def test_detect_needs_twenty_frames():
    from cyclecoord.periodic.detection import detect

    with pytest.raises(ParameterError, match="19 frames are too few"):
        detect(_bare(19), progress=False)
    with pytest.raises(NoPeriodicMotionError):  # 20 frames are looked at
        detect(_bare(20), progress=False)


@pytest.mark.parametrize(
    "name,value",
    [("window", 0.0), ("max_period", 0.0), ("min_cycles", 0.0), ("min_consistency", 0.0),
     ("min_consistency", 1.01), ("merge_overlap", 0.0), ("merge_overlap", 1.5),
     ("min_persistence", -0.1), ("min_persistence", 1.1), ("n_classes", 0),
     ("method", "both"), ("window_stride", 0.0), ("window_cycles", 0.0), ("similarity", 0.0),
     ("window_steadiness", 1.1), ("window_steadiness", -0.1), ("window_points", 9),
     ("normalize", 1), ("temporal", "no"), ("difference_root", None), ("rotations", "quat"),
     ("progress", 0)],
)
def test_detect_refuses_each_bad_option(name, value):
    from cyclecoord.periodic.detection import detect

    with pytest.raises(ParameterError, match=name):
        detect(_bare(19), **{name: value})


@pytest.mark.parametrize(
    "name,value",
    [("min_consistency", 1.0), ("merge_overlap", 1.0), ("min_persistence", 0.0),
     ("min_persistence", 1.0), ("n_classes", 1), ("window_steadiness", 0.0),
     ("window_steadiness", 1.0), ("window_points", 10), ("method", "windows"),
     ("rotations", "euler"), ("window_lengths", 3.0), ("window_lengths", (1, 2.5))],
)
def test_detect_accepts_each_option_at_its_bound(name, value):
    """Accepted: the run goes on to refuse the 19 frames."""
    from cyclecoord.periodic.detection import detect

    with pytest.raises(ParameterError, match="too few"):
        detect(_bare(19), progress=False, **{name: value})


@pytest.mark.parametrize("lengths", [(), (0.0,), (2.0, -1.0), (np.inf,), ("long",), None])
def test_detect_refuses_bad_window_lengths(lengths):
    from cyclecoord.periodic.detection import detect

    with pytest.raises(ParameterError, match="window_lengths"):
        detect(_bare(19), window_lengths=lengths, progress=False)


def test_detect_takes_a_motion_only():
    from cyclecoord.periodic.detection import detect

    with pytest.raises(ParameterError, match="takes a Motion, got ndarray"):
        detect(np.zeros((30, 2)))


def test_detect_parameters_and_method(walk, found):
    from cyclecoord.periodic.detection import detect

    p = found.parameters
    assert p["frames"] is None and p["method"] == "global" and p["window_lengths"] == [2.0, 4.0, 6.0]
    assert (p["delay"], p["min_cycles"], p["window"], p["max_period"]) == (0.25, 1.5, 1.0, 4.0)
    assert isinstance(p["window_points"], int) and p["rig"] is True
    assert found.method == "global" and found.windows == []
    assert found.n_motions == 1 and [s.motion for s in found.segments] == [0]
    assert set(found.timings) >= {"prepare", "barcode", "coordinates", "segments", "total"}
    assert found.timings["total"] == pytest.approx(
        sum(v for k, v in found.timings.items() if k != "total"))
    seg = found.segments[0]
    assert seg.period_frames == pytest.approx(40.0, abs=1.0)
    w = detect(walk, frames=(20, 220), progress=False, method="windows", window_lengths=(1.0,))
    assert w.motion.n_frames == 200 and w.parameters["frames"] == [20, 220]
    assert w.classes == [] and w.method == "windows" and len(w.windows) > 0
    assert w.parameters["window_lengths"] == [1.0]


def test_detect_max_period_bounds_the_slowest_motion(walk):
    """The walk turns once every 40 frames (1/3 s at 120 fps): a max_period of 0.32 s asks
    for faster motion and finds nothing in the global stage; 0.37 s finds it."""
    from cyclecoord.periodic.detection import detect

    with pytest.raises(NoPeriodicMotionError) as err:
        detect(walk, progress=False, method="global", max_period=0.32)
    assert "1 candidate H1 class(es), none completes 1.5 steady cycles" in str(err.value)
    assert "window" not in str(err.value)  # the global stage alone
    assert err.value.result.segments == [] and err.value.result.method == "global"
    r = detect(walk, progress=False, method="global", max_period=0.37)
    assert r.n_motions == 1


def test_detect_nothing_found_names_the_windows_too(walk):
    from cyclecoord.periodic.detection import detect

    with pytest.raises(NoPeriodicMotionError) as err:
        detect(walk, progress=False, min_cycles=50, window_lengths=(2.0,))
    msg = str(err.value)
    assert "none completes 50 steady cycles" in msg
    n = len(err.value.result.windows)
    looping = sum(w.looping for w in err.value.result.windows)
    assert f"; {n} window(s), {looping} looping, no group of them holds 50 cycles" in msg


# ------------------------------------------------------------------ motion_cycles (cycles.py)
def test_motion_cycles_by_the_lead_class(found):
    from cyclecoord.periodic.detection import motion_cycles

    seg = found.segments[0]
    lead = found.classes[0]
    (mc,) = motion_cycles(found)
    assert (mc.motion, mc.start, mc.stop) == (0, seg.start, seg.stop)
    assert mc.phase_from == "class 0" and mc.period_frames == seg.period_frames
    assert mc.n_frames_used == int(lead.mask[seg.start:seg.stop].sum())
    assert mc.cycle.n_frames == int(round(seg.period_frames))
    assert mc.cycle.channels == found.motion.channels
    assert 0 < mc.loop_closure < 3 and 0 < mc.largest_step < 3
    (mc2,) = motion_cycles(found, timing="coordinate", n_samples=50)
    assert mc2.phase_from == "class 0" and mc2.cycle.n_frames == int(round(seg.period_frames))


def test_motion_cycles_need_min_cycles_and_a_period(found):
    import dataclasses

    from cyclecoord.periodic.detection import motion_cycles
    from cyclecoord.periodic.results import CycleOptions

    seg = found.segments[0]
    assert len(motion_cycles(found, min_cycles=float(seg.cycles))) == 1  # at least
    assert motion_cycles(found, min_cycles=float(seg.cycles) + 1e-6) == []
    assert motion_cycles(found, cycle=CycleOptions(min_turns=float(seg.cycles) + 1e-6)) == []
    assert len(motion_cycles(found, cycle=CycleOptions(min_turns=float(seg.cycles)))) == 1
    for period in (1.9, float("nan")):
        short = dataclasses.replace(found, segments=[dataclasses.replace(seg, period_frames=period)])
        assert motion_cycles(short) == []
    two = dataclasses.replace(found, segments=[dataclasses.replace(seg, period_frames=2.0)])
    assert len(motion_cycles(two, timing="coordinate", n_samples=20)) == 1
    none = dataclasses.replace(found, segments=[])
    assert motion_cycles(none) == []


def test_motion_cycles_phase_from_time_when_the_lead_excites_under_a_period(found):
    import dataclasses

    from cyclecoord.periodic.detection import motion_cycles

    seg = found.segments[0]
    period = int(round(seg.period_frames))
    lead = found.classes[0]
    for n, source in ((period - 1, "time"), (period, "class 0")):
        mask = np.zeros_like(lead.mask)
        mask[seg.start : seg.start + n] = True
        cls = dataclasses.replace(lead, mask=mask)
        res = dataclasses.replace(found, classes=[cls], segments=[dataclasses.replace(seg, period_frames=float(period))])
        (mc,) = motion_cycles(res, timing="coordinate", n_samples=20)
        assert mc.phase_from == source, n
        assert mc.n_frames_used == (n if source != "time" else seg.stop - seg.start)
    windowed = dataclasses.replace(found, segments=[dataclasses.replace(seg, classes=())])
    (mc,) = motion_cycles(windowed, timing="coordinate", n_samples=20)
    assert mc.phase_from == "time" and mc.n_frames_used == seg.stop - seg.start


def test_motion_cycles_refuses_bad_arguments(found):
    from cyclecoord.periodic.detection import motion_cycles

    with pytest.raises(ParameterError, match="takes a DetectionResult, got dict"):
        motion_cycles({})
    with pytest.raises(ParameterError, match="timing must be one of"):
        motion_cycles(found, timing="fast")


def test_pop_is_the_largest_cycle_step_over_the_p99_step_of_the_rows():
    from cyclecoord.periodic.detection.cycles import _pop

    poses = np.cumsum(np.r_[np.zeros(1), np.ones(9), 10 * np.ones(10)])[:, None]
    cycle = np.array([[0.0], [3.0], [1.0]])  # steps around the loop 3, 2, 1
    # rows 0-9: steps of 1 between consecutive rows -> p99 1
    assert _pop(cycle, poses, np.arange(10)) == pytest.approx(3.0)
    # rows 10-19: steps of 10
    assert _pop(cycle, poses, np.arange(10, 20)) == pytest.approx(0.3)
    assert np.isnan(_pop(cycle, np.zeros((20, 1)), np.arange(20)))


# ------------------------------------------------------------------ detect's stages, spied on
class _Stop(Exception):
    pass


@pytest.mark.parametrize(
    "delay,lags", [(0.25, [30]), ((0.1, 0.2), [12, 24]), (0, None), (None, None), ((0, 0.1), [12])]
)
def test_detect_delay_seconds_become_frames(walk, monkeypatch, delay, lags):
    from cyclecoord.periodic.detection import detector

    seen = {}

    class Spy:
        def __init__(self, **kw):
            seen.update(kw)
            raise _Stop

    monkeypatch.setattr(detector, "Preprocessor", Spy)
    with pytest.raises(_Stop):
        detector.detect(walk, delay=delay, progress=False)
    assert seen["delay"] == lags
    assert seen["difference_root"] is True and seen["rotations"] == "auto"


@pytest.mark.parametrize("memory_limit", [None, 5e8])
def test_detect_passes_the_estimator_options(walk, monkeypatch, memory_limit):
    from cyclecoord.periodic.detection import detector

    seen = {}

    class Spy:
        def __init__(self, **kw):
            seen.update(kw)
            raise _Stop

    monkeypatch.setattr(detector, "CircularCoordinates", Spy)
    with pytest.raises(_Stop):
        detector.detect(walk, memory_limit=memory_limit, prime=13, scale_fraction=0.7,
                        landmarks=40, progress=False)
    assert seen["refine_birth"] is False and seen["prime"] == 13
    assert seen["scale_fraction"] == 0.7 and seen["landmarks"] == 40
    assert ("memory_limit" in seen) == (memory_limit is not None)
    if memory_limit is not None:
        assert seen["memory_limit"] == memory_limit


def test_detect_notes_a_landmark_barcode(walk):
    from cyclecoord.periodic.detection import detect

    r = detect(walk, landmarks=60, progress=False, method="global")
    assert any(n.startswith("barcode on 60 landmarks: ") for n in r.warnings)
    assert not any("landmarks" in n for n in detect(walk, landmarks=None, progress=False,
                                                   method="global").warnings)


def test_detect_drops_unsteady_frames_on_the_joints_with_half_the_speed_window(walk, monkeypatch):
    """window 0.5 s at 120 fps: 61 frames (odd); pieces under 30 frames are dropped; the
    joints read are the prepared poses without the root's columns."""
    from cyclecoord.periodic.detection import _segments, detector

    seen = {}
    real = _segments.drop_unsteady

    def spy(labels, segments, joints, motion, min_run):
        seen.update(joints=joints.shape, min_run=min_run)
        return real(labels, segments, joints, motion, min_run)

    monkeypatch.setattr(detector, "drop_unsteady", spy)
    detector.detect(walk, window=0.5, progress=False, method="global")
    assert seen["min_run"] == 30
    from cyclecoord.periodic.preprocess import Preprocessor

    prep = Preprocessor(delay=[30]).fit_transform(walk)
    assert seen["joints"] == (240, prep.poses.shape[1] - len(prep.root_columns))


def test_detect_windows_method_leaves_classes_out_and_auto_joins_them(walk):
    from cyclecoord.periodic.detection import detect

    auto = detect(walk, progress=False, window_lengths=(1.0,))
    assert auto.method == "auto" and len(auto.windows) > 0 and len(auto.classes) >= 1
    assert auto.n_motions == 1 and auto.classes[0].motion == 0
    assert "windows" in auto.timings


def test_motion_cycles_read_a_backward_coordinate_as_the_same_cycle(found):
    """The lead class's coordinate turned backwards (1 - theta) winds as many times the
    other way: the phase is its negation, and the cycle is the same, frame for frame."""
    import dataclasses

    from cyclecoord.periodic.detection import motion_cycles

    lead = found.classes[0]
    back = dataclasses.replace(found, classes=[dataclasses.replace(
        lead, coordinate=np.mod(-lead.coordinate, 1.0))])
    (a,), (b,) = motion_cycles(found), motion_cycles(back)
    np.testing.assert_allclose(b.cycle.frames, a.cycle.frames, atol=1e-9)
    assert b.phase_from == "class 0" and b.n_frames_used == a.n_frames_used


def test_class_period_of_a_segment_under_one_turn():
    """21 frames at 1/40 of a turn a frame, never excited: 0.5 turns, 20 steps: 40."""
    theta = np.mod(np.arange(21) / 40.0, 1.0)
    cyc, period = class_period(theta, np.zeros(21, bool), 0, 21)
    assert cyc == pytest.approx(0.5) and period == pytest.approx(40.0)


def test_drop_unsteady_does_not_judge_the_turn_of_a_two_frame_segment():
    """Frames 100-101 inside the 90-degree turn (2.25 degrees a frame, 90 a period): a
    segment of two frames has no window to judge a turn over and is kept; one of three
    frames is judged and dropped."""
    m, joints = _turning_walk()
    for n, kept in ((2, True), (3, False)):
        seg = Segment(110, 110 + n, 0, (0,), 1.0, 2.0, 1.5, 0.1, 40.0)
        labels = np.full(240, -1)
        labels[110 : 110 + n] = 0
        labels, out = drop_unsteady(labels, [seg], joints, m, min_run=1)
        assert (len(out) == 1) == kept, n


def test_motions_from_classes_strength_is_speed_times_consistency():
    """C excites frames 50-59 with speed 0.05 but consistency 0.2 (strength 0.01): A and
    B (0.02 x 1) are stronger there."""
    A = _cls(3, [(0, 60)], 0.02)
    B = _cls(1, [(10, 60)], 0.02)
    C = _cls(0, [(50, 100)], 0.05)
    C.consistency = np.full(100, 0.2)
    _, labels, segs, n = motions_from_classes([A, B, C], 100, 10, 0.5)
    np.testing.assert_array_equal(labels, [0] * 60 + [1] * 40)


@pytest.mark.parametrize("timing", ["capture", "coordinate"])
def test_motion_cycles_in_time_over_the_period_loop_cleanly(found, timing):
    """Without a lead class the phase is time over the segment's period (40 frames of a
    steady 40-frame walk): a clean loop, close to the class-phase cycle."""
    import dataclasses

    from cyclecoord.periodic.detection import motion_cycles

    seg = found.segments[0]
    timed = dataclasses.replace(found, segments=[dataclasses.replace(seg, classes=())])
    (mc,) = motion_cycles(timed, timing=timing, n_samples=100)
    (ref,) = motion_cycles(found, timing=timing, n_samples=100)
    assert mc.phase_from == "time" and mc.cycle.n_frames == ref.cycle.n_frames
    assert mc.loop_closure < 1.5 and mc.largest_step < 1.5
    cols = [i for i, (j, _) in enumerate(found.motion.channels) if j != "root"]
    a, b = mc.cycle.frames[:, cols], ref.cycle.frames[:, cols]
    shift = min(np.abs(np.roll(a, k, axis=0) - b).mean() for k in range(len(a)))
    assert shift < 0.2 * np.abs(b - b.mean(axis=0)).mean()  # measured 0.11-0.13


def test_class_period_reads_a_run_ending_where_it_started_as_it_goes():
    """Run 0-48 rises 1.5 turns at 1/16 a frame and comes back exactly; run 60-69 turns
    1.125 at 1/8 a frame (together 1.125 excited turns).  The first run, ending where it
    started, is read as it goes (rising first): its complete windings of 16 frames
    outnumber the second run's of 8, so the period is 16."""
    inc = np.r_[np.full(24, 1 / 16), np.full(24, -1 / 16), np.zeros(11), np.full(10, 1 / 8)]
    u = np.r_[0.0, np.cumsum(inc)]  # 70 frames, exact sixteenths
    theta = np.mod(u, 1.0)
    mask = np.zeros(70, bool)
    mask[0:49] = True
    mask[60:70] = True
    assert u[48] == u[0]
    cyc, period = class_period(theta, mask, 0, 70)
    assert period == pytest.approx(16.0)


def test_drop_unsteady_drops_a_short_piece_late_in_the_capture():
    """A 5-frame segment at frames 100-104 is under min_run 10 wherever it lies (at 2 fps
    its joints move for over a second: no pause in it)."""
    T = 120
    ang = 2 * np.pi * np.arange(T) / 30
    joints = 30.0 * np.column_stack([np.sin(ang), np.cos(ang)])
    motion = Motion(joints, [("a", "rx"), ("b", "rx")], fps=2.0)
    labels = np.full(T, -1)
    labels[100:105] = 0
    seg = Segment(100, 105, 0, (0,), 1.0, 2.0, 1.5, 0.2, 30.0)
    got, out = drop_unsteady(labels, [seg], joints, motion, min_run=10)
    assert out == [] and np.all(got == -1)
    got, out = drop_unsteady(labels, [seg], joints, motion, min_run=5)
    assert [(s.start, s.stop) for s in out] == [(100, 105)]


def test_motion_cycles_fall_back_to_time_when_the_class_phase_never_winds(found):
    """A lead class whose coordinate stands still over its excited frames has no complete
    winding to re-time by: the phase falls back to time over the period from the
    segment's start.  With cycle_start="first" the cycle then starts at phase 0, the
    pose of the segment's first frame and of every period after it (their mean, within a
    few degrees; two frames later the poses are 17 degrees away)."""
    import dataclasses

    from cyclecoord.periodic.detection import motion_cycles

    lead = found.classes[0]
    seg = found.segments[0]
    assert lead.mask[seg.start:seg.stop].all() and seg.period_frames == pytest.approx(40.0)
    still = dataclasses.replace(found, classes=[dataclasses.replace(
        lead, coordinate=np.full_like(lead.coordinate, 0.3))])
    (mc,) = motion_cycles(still, cycle_start="first")
    assert mc.phase_from == "class 0"
    cols = [i for i, (j, _) in enumerate(found.motion.channels) if j != "root"]
    starts = np.arange(seg.start, seg.stop, 40)
    first = found.motion.frames[starts][:, cols].mean(axis=0)
    assert np.abs(mc.cycle.frames[0, cols] - first).max() < 5.0  # measured 2.2


def test_detect_defaults_beside_a_configured_preprocessor_are_no_conflict(walk, monkeypatch):
    """Every keyword a Preprocessor carries left at detect's default is no clash; the
    preprocessor's settings (its delays in frames, as seconds) reach the preparation, and
    the estimator's reach the barcode; a changed keyword beside it is an error."""
    from cyclecoord.periodic.coordinates import CircularCoordinates
    from cyclecoord.periodic.detection import detector
    from cyclecoord.periodic.preprocess import Preprocessor

    seen = {}

    def spy(motion, timings, notes, preprocess, estimate):
        seen.update(preprocess=dict(preprocess), estimate=dict(estimate))
        raise _Stop

    monkeypatch.setattr(detector, "_barcode_of", spy)
    pre = Preprocessor(delay=[12, 24], normalize=True, pca=4, difference_root=False,
                       rotations="euler")
    est = CircularCoordinates(prime=13, scale_fraction=0.6, temporal=True, landmarks=50,
                              max_scale=7.0, memory_limit=1e9)
    with pytest.raises(_Stop):
        detector.detect(walk, preprocessor=pre, estimator=est, progress=False)
    assert seen["preprocess"] == dict(difference_root=False, normalize=True, pca=4,
                                      delay=(0.1, 0.2), rotations="euler")
    assert seen["estimate"] == dict(max_scale=7.0, prime=13, scale_fraction=0.6, temporal=True,
                                    landmarks=50, memory_limit=1e9)
    with pytest.raises(_Stop):
        detector.detect(walk, preprocessor=Preprocessor(), estimator=CircularCoordinates(),
                        progress=False)
    for name, value in (("delay", 0.5), ("normalize", True), ("pca", 3),
                        ("difference_root", False), ("rotations", "rotvec")):
        with pytest.raises(ParameterError, match=name):
            detector.detect(walk, preprocessor=Preprocessor(), progress=False, **{name: value})


def test_detect_timings_are_each_stages_seconds(found):
    assert all(0.0 <= v < 600.0 for v in found.timings.values()), found.timings


def test_motion_cycles_turn_each_backward_run_of_the_class_forward(found):
    """The lead class excited on the segment but one frame three before its end: a
    two-frame run closes it.  With the coordinate backwards each run is turned forward,
    the two-frame one too, so the cycle is the forward coordinate's, frame for frame."""
    import dataclasses

    from cyclecoord.periodic.detection import motion_cycles

    lead = found.classes[0]
    seg = found.segments[0]
    mask = lead.mask.copy()
    mask[seg.stop - 3] = False
    fwd = dataclasses.replace(found, classes=[dataclasses.replace(lead, mask=mask)])
    back = dataclasses.replace(found, classes=[dataclasses.replace(
        lead, mask=mask, coordinate=np.mod(-lead.coordinate, 1.0))])
    (a,), (b,) = motion_cycles(fwd), motion_cycles(back)
    np.testing.assert_allclose(b.cycle.frames, a.cycle.frames, atol=1e-9)


def test_detect_runs_with_one_blas_thread(walk, monkeypatch):
    """detect holds the one-BLAS-thread limit (cyclecoord._blas) while its stages run, as
    extract does; _speed_window, a pure helper, needs none."""
    from cyclecoord import _blas
    from cyclecoord.periodic.detection import detector

    seen = []

    def spy(*args):
        seen.append(_blas._LIMITED.get())
        raise _Stop

    monkeypatch.setattr(detector, "candidate_classes", spy)
    with pytest.raises(_Stop):
        detector.detect(walk, progress=False)
    assert seen == [True]
    assert not _blas._LIMITED.get()  # restored afterwards
