"""Known answers of quality.cycle_quality's figures at their edges (issue 27: mutation score).

Tiny hand-made motions; every expected figure is worked out in the comments.
"""

from __future__ import annotations

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from cyclecoord.quality.cycle_quality import (
    LEG_JOINTS,
    CycleQuality,
    cycle_jerk,
    cycle_quality,
    foot_skating_speed,
    heading_change,
    leg_channels,
    leg_joint_ranges,
    leg_ranges,
    period_error,
    root_closure,
    root_orientation,
    targets,
)

ROOT = [("root", d) for d in ("tx", "ty", "tz", "rx", "ry", "rz")]


def _motion(cols: dict, root=None, fps: float = 10.0) -> cc.Motion:
    n = len(next(iter(cols.values())))
    root = np.zeros((n, 6)) if root is None else root
    frames = np.column_stack([root] + [np.asarray(v, dtype=float) for v in cols.values()])
    return cc.Motion(frames, ROOT + [tuple(k.split(".")) for k in cols], fps=fps)


# ------------------------------------------------------------------ period, jerk
def test_period_error_missing_or_non_positive_reference():
    assert period_error(95.0, 100.0) == pytest.approx(-0.05)
    assert period_error(100.0, 100.0) == 0.0
    assert np.isnan(period_error(100.0, 0.0))
    assert np.isnan(period_error(100.0, -50.0))
    assert np.isnan(period_error(float("nan"), 100.0))
    assert np.isnan(period_error(float("inf"), 100.0))
    assert period_error(50.0, 1e-3) == pytest.approx(49999.0)


def test_cycle_jerk_needs_four_frames_of_two_dimensions():
    with pytest.raises(ParameterError, match="at least 4 frames"):
        cycle_jerk(np.zeros((3, 2)), 10.0)
    with pytest.raises(ParameterError, match="at least 4 frames"):
        cycle_jerk(np.zeros(8), 10.0)
    # 4 frames: j = x[t+3] - 3x[t+2] + 3x[t+1] - x[t] around the loop; x = (0, 1, 0, 0)
    # t=0: 0 - 0 + 3 - 0 = 3; t=1: 1 - 0 + 0 - 1 = 0 ... by hand:
    x = np.array([0.0, 1.0, 0.0, 0.0])
    j = [x[(t + 3) % 4] - 3 * x[(t + 2) % 4] + 3 * x[(t + 1) % 4] - x[t] for t in range(4)]
    assert cycle_jerk(x[:, None], 2.0) == pytest.approx(np.mean(np.abs(j)) * 8.0)
    # the norm over channels: two channels (3, 4) times the same pattern: 5 times it
    assert cycle_jerk(np.c_[3 * x, 4 * x], 2.0) == pytest.approx(5 * np.mean(np.abs(j)) * 8.0)
    # a straight line (no seam jump removed): the jerk of a ramp is zero inside and not at the seam
    assert cycle_jerk(np.zeros((6, 1)), 30.0) == 0.0


# ------------------------------------------------------------------ leg channels, ranges
def test_leg_channels_are_rotation_channels_of_joints_ending_in_a_leg_stem():
    assert LEG_JOINTS == ("femur", "tibia", "foot", "toes")
    m = _motion({
        "lfemur.rx": np.zeros(4), "lfemur.tx": np.zeros(4), "LTibia.rz": np.zeros(4),
        "lfemurx.rx": np.zeros(4), "rtoes.ry": np.zeros(4), "ltoe.rx": np.zeros(4),
        "lhumerus.rx": np.zeros(4), "rfoot.rx": np.zeros(4),
    })
    # positions within the joint columns (the root's 6 are not counted)
    assert leg_channels(m) == [0, 2, 4, 7]
    no_root = cc.Motion(np.zeros((3, 2)), [("lhumerus", "rx"), ("lfoot", "rx")])
    assert leg_channels(no_root) == [1]


def test_leg_ranges_are_unwrapped_and_named_joint_dot_dof():
    m = _motion({"lfemur.rx": [170.0, 179.0, -179.0, -170.0], "lfoot.tx": [0, 5, 0, 9],
                 "rtibia.rz": [1.0, -2.0, 3.0, 0.0]})
    assert leg_ranges(m) == {"lfemur.rx": pytest.approx(20.0), "rtibia.rz": pytest.approx(5.0)}
    assert leg_ranges(_motion({"lhumerus.rx": [0.0, 9.0]})) == {}


def _diamond(n, hold=3):
    """(1, 0), (0, 1), (-1, 0), (0, -1), each held ``hold`` frames, repeated to n frames:
    a diameter of 2 and a bounding box whose diagonal is 2 sqrt 2."""
    pts = np.repeat(np.array([[1.0, 0], [0, 1], [-1, 0], [0, -1]]), hold, axis=0)
    return np.resize(pts, (n, 2))


@pytest.mark.parametrize("n,want", [(12, 2.0), (2000, 2.0), (2001, 2 * np.sqrt(2)), (2400, 2 * np.sqrt(2))])
def test_leg_joint_ranges_diameter_up_to_2000_frames_then_the_box_diagonal(n, want):
    d = _diamond(n)
    m = _motion({"lfemur.rx": d[:, 0], "lfemur.ry": d[:, 1], "rtibia.rx": 3 * d[:, 0]})
    got = leg_joint_ranges(m, spike=1)
    assert got["lfemur"] == pytest.approx(want)
    assert got["rtibia"] == pytest.approx(6.0)
    assert set(got) == {"lfemur", "rtibia"}


def test_leg_joint_ranges_spike_filter_needs_more_frames_than_its_width():
    """A one-frame spike of 10 degrees: kept with spike=1 and in a cycle of exactly
    ``spike`` frames (not filtered), removed from one frame longer."""
    five = _motion({"ltibia.rx": [0.0, 0.0, 10.0, 0.0, 0.0]})
    assert leg_joint_ranges(five, spike=5) == {"ltibia": 10.0}
    six = _motion({"ltibia.rx": [0.0, 0.0, 10.0, 0.0, 0.0, 0.0]})
    assert leg_joint_ranges(six, spike=5) == {"ltibia": 0.0}
    assert leg_joint_ranges(six, spike=1) == {"ltibia": 10.0}
    assert leg_joint_ranges(six) == {"ltibia": 0.0}  # default 5
    # a three-frame spike: filtered by a width of 7, kept by 5
    seven = _motion({"ltibia.rx": [0.0, 0.0, 10.0, 10.0, 10.0, 0.0, 0.0, 0.0, 0.0]})
    assert leg_joint_ranges(seven, spike=5) == {"ltibia": 10.0}
    assert leg_joint_ranges(seven, spike=7) == {"ltibia": 0.0}
    # the filter wraps around the loop: a spike at the seam held over it is a hold
    seam = _motion({"ltibia.rx": [10.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.0, 10.0]})
    assert leg_joint_ranges(seam, spike=5) == {"ltibia": 10.0}


# ------------------------------------------------------------------ foot skating
def _legs(T=60, fps=30.0):
    from _legs import legs_skeleton, make_motion

    return make_motion(legs_skeleton(), T=T, fps=fps)


def test_foot_skating_height_limit_is_five_percent_of_the_leg():
    """Leg (root to toes) sqrt 2 + 4 + 4 + sqrt 1.25 = 10.532: in contact up to 0.527 over
    the resting level.  Frames 30-59 raised by r slide at 4 units/s, the others at 2; the
    step from frame 29 to 30 slides at 2 at mid height r / 2 (in contact).  r = 0.5: every
    step is in contact, (30 x 2 + 29 x 4) / 59; r = 0.6: the raised steps are not, 2."""
    m = _legs()
    f = m.frames.copy()
    tx = np.r_[2.0 * np.arange(31), 60.0 + 4.0 * np.arange(1, 30)] / 30.0
    f[:, m.channels.index(("root", "tx"))] = tx
    for r, want in ((0.5, (30 * 2 + 29 * 4) / 59), (0.6, 2.0)):
        g = f.copy()
        g[30:, m.channels.index(("root", "ty"))] += r
        assert foot_skating_speed(m.with_frames(g)) == pytest.approx(want, rel=1e-9), r


def test_foot_skating_speed_limit_is_one_leg_a_second():
    m = _legs()
    f = m.frames.copy()
    for v, want in ((10.5, 10.5), (10.6, 0.0)):
        f[:, m.channels.index(("root", "tx"))] = v * np.arange(60) / 30.0
        assert foot_skating_speed(m.with_frames(f)) == pytest.approx(want, rel=1e-9), v


def test_foot_skating_needs_foot_joints():
    from _legs import legs_skeleton, make_motion

    skel = legs_skeleton(names=("lfemur", "ltibia", "lankle", "lball", "rfemur", "rtibia",
                                "rankle", "rball"))
    assert np.isnan(foot_skating_speed(make_motion(skel, T=20)))
    # "toe" is a foot point too
    skel = legs_skeleton(names=("lfemur", "ltibia", "lankle", "ltoe", "rfemur", "rtibia",
                                "rankle", "rtoe"))
    m = make_motion(skel, T=20, fps=10.0, root_speed=3.0)
    assert foot_skating_speed(m) == pytest.approx(3.0)


# ------------------------------------------------------------------ root
def test_root_orientation_without_a_skeleton_is_the_channels_unwrapped():
    n = 5
    root = np.zeros((n, 6))
    root[:, 4] = [170.0, 178.0, -176.0, -170.0, -160.0]  # ry crosses 180
    root[:, 3] = [1.0, 2.0, 3.0, 4.0, 5.0]
    root[:, 5] = [-1.0, -2.0, -3.0, -4.0, -5.0]
    m = _motion({"lfemur.rx": np.zeros(n)}, root)
    hpr = root_orientation(m)
    np.testing.assert_allclose(hpr[:, 0], [170.0, 178.0, 184.0, 190.0, 200.0])
    np.testing.assert_allclose(hpr[:, 1], root[:, 3])
    np.testing.assert_allclose(hpr[:, 2], root[:, 5])
    assert heading_change(m) == pytest.approx(30.0 * 5 / 4)
    # no rotation channels: None, and no closure or heading
    only_t = cc.Motion(np.zeros((4, 4)), [("root", "tx"), ("root", "ty"), ("root", "tz"), ("root", "ry")])
    assert root_orientation(only_t) is None
    assert all(np.isnan(v) for v in root_closure(only_t)) and np.isnan(heading_change(only_t))


def test_root_closure_edges():
    n = 6
    root = np.zeros((n, 6))
    m = _motion({"lfemur.rx": np.zeros(n)}, root)
    assert root_closure(m) == (0.0, 0.0)  # closed and still
    root[-1, 3] = 3.0  # one step of 3 at the end: median step 0, gap 3
    root[-1, 5] = 4.0
    gap, steps = root_closure(_motion({"lfemur.rx": np.zeros(n)}, root))
    assert gap == pytest.approx(5.0) and steps == np.inf
    one = _motion({"lfemur.rx": np.zeros(1)}, np.zeros((1, 6)))
    assert all(np.isnan(v) for v in root_closure(one)) and np.isnan(heading_change(one))
    two = np.zeros((2, 6))
    two[:, 3] = [0.0, 2.0]
    two[:, 4] = [0.0, 3.0]
    m2 = _motion({"lfemur.rx": np.zeros(2)}, two)
    assert root_closure(m2) == (pytest.approx(2.0), pytest.approx(1.0))
    assert heading_change(m2) == pytest.approx(6.0)  # 3 over 1 step, times 2 / 1


# ------------------------------------------------------------------ cycle_quality
def test_cycle_quality_by_hand():
    """A take of 20 frames and a 4-frame cycle of two leg channels and one arm channel."""
    t = np.arange(20)
    take = _motion({"lfemur.rx": 10.0 * (t % 4), "rtibia.rx": 4.0 * (t % 2), "lhumerus.rx": np.zeros(20)})
    cyc = _motion({"lfemur.rx": [0.0, 10.0, 20.0, 30.0], "rtibia.rx": [0.0, 2.0, 0.0, 2.0],
                   "lhumerus.rx": np.zeros(4)})
    ref = cycle_quality(take.with_frames(take.frames[:4]), take, method="cut", reference_period=4.0,
                        skating_take=2.0)
    assert ref.method == "cut" and ref.n_frames == 4 and ref.period_frames == 4.0
    assert ref.period_error == 0.0 and ref.reference_period == 4.0
    assert ref.leg_ranges == {"lfemur.rx": 30.0, "rtibia.rx": 4.0}
    assert np.isnan(ref.jerk_ratio) and np.isnan(ref.coverage_ratio) and ref.leg_range_ratios == {}
    assert ref.min_leg_channel is None and np.isnan(ref.min_leg_range_ratio)
    assert ref.min_joint is None and np.isnan(ref.min_femur_tibia_ratio)
    assert ref.coverage == pytest.approx(0.0)  # every take frame is a cut frame
    assert ref.skating_take == 2.0 and np.isnan(ref.skating)  # no skeleton: NaN skating
    q = cycle_quality(cyc, take, method="ours", period_frames=5.0, reference_period=4.0,
                      reference=ref, used_frames=[[0, 4]])
    assert q.period_frames == 5.0 and q.period_error == pytest.approx(0.25)
    assert q.leg_ranges == {"lfemur.rx": 30.0, "rtibia.rx": 2.0}
    assert q.leg_range_ratios == {"lfemur.rx": 1.0, "rtibia.rx": 0.5}
    assert q.min_leg_channel == "rtibia.rx" and q.min_leg_range_ratio == 0.5
    assert q.min_femur_tibia_ratio == 0.5
    assert q.joint_ranges == {"lfemur": 30.0, "rtibia": 2.0}
    assert q.joint_range_ratios == {"lfemur": 1.0, "rtibia": 0.5} and q.min_joint == "rtibia"
    assert q.min_joint_range_ratio == 0.5
    assert q.jerk_ratio == pytest.approx(q.jerk / ref.jerk)
    # used frames 0-3 of the take: (0, 0), (10, 4), (20, 0), (30, 4) against the cycle's
    # closed polyline through (0,0) (10,2) (20,0) (30,2): distances 0, 2, 0, 2 -> mean 1
    assert q.coverage == pytest.approx(1.0)
    assert np.isnan(q.coverage_ratio)  # the reference's coverage is 0
    # seam: step 30 -> 0 (with rtibia 2 -> 0) over the median step
    # pop: the seam step (30, 2) over the used take frames' steps, all (10, 4); over the
    # whole take the steps (30, 4) back to each group's start (4 of 19) weigh in too
    assert q.largest_step == pytest.approx(np.hypot(30, 2) / np.hypot(10, 4))
    assert cycle_quality(cyc, take, reference=ref).largest_step == pytest.approx(
        np.hypot(30, 2) / np.percentile([np.hypot(10, 4)] * 15 + [np.hypot(30, 4)] * 4, 99))
    steps = [np.hypot(10, 2)] * 3 + [np.hypot(30, 2)]
    assert q.step_spread == pytest.approx(np.percentile(steps, 90) / np.percentile(steps, 10))
    # seam: the step 30 -> 0 (rtibia 2 -> 0) over the median inside step (10, 2)
    assert q.seam == pytest.approx(np.hypot(30, 2) / np.hypot(10, 2))
    assert q.root_closure_degrees == 0.0 and q.heading_change == 0.0
    with pytest.raises(ParameterError, match="the odd cycle's channels differ"):
        cycle_quality(_motion({"lfemur.rx": np.zeros(4)}), take, method="odd")


def test_cycle_quality_femur_tibia_ratio_leaves_out_feet_and_toes():
    t = np.arange(8)
    take = _motion({"lfemur.rx": 10.0 * (t % 2), "lfoot.rx": 10.0 * (t % 2), "rtoes.rx": 10.0 * (t % 2)})
    ref = cycle_quality(take, take)
    cyc = take.with_frames(take.frames * np.r_[np.ones(6), 0.8, 0.3, 0.1])
    q = cycle_quality(cyc, take, reference=ref)
    assert q.min_femur_tibia_ratio == pytest.approx(0.8)
    assert q.min_leg_range_ratio == pytest.approx(0.1) and q.min_leg_channel == "rtoes.rx"
    assert ref.coverage == 0.0 and np.isnan(q.coverage_ratio)  # over a zero: no ratio
    half = cycle_quality(take.with_frames(take.frames * np.r_[np.ones(6), 0.5, 0.5, 0.5]), take)
    q = cycle_quality(take.with_frames(take.frames * np.r_[np.ones(6), 0.8, 0.8, 0.8]), take,
                      reference=half)
    # distances to the cycle: half (10 - 5) sqrt 3 / 2 for each of the 8 frames against
    # 2 sqrt 3 / 2 for the 0.8 one: 0.4
    assert q.coverage_ratio == pytest.approx(0.4)


def test_cycle_quality_skating_ratio_over_the_takes_and_a_zero_take():
    from _legs import legs_skeleton, make_motion

    skel = legs_skeleton()
    take = make_motion(skel, T=30, fps=10.0, root_speed=4.0)
    cyc = make_motion(skel, T=10, fps=10.0, root_speed=1.0)
    q = cycle_quality(cyc, take)
    assert q.skating == pytest.approx(1.0) and q.skating_take == pytest.approx(4.0)
    assert q.skating_ratio == pytest.approx(0.25)
    q = cycle_quality(cyc, take, skating_take=0.5)
    assert q.skating_take == 0.5 and q.skating_ratio == pytest.approx(2.0)
    assert np.isnan(cycle_quality(cyc, take, skating_take=0.0).skating_ratio)


def test_to_dict_cleans_nan_numpy_and_nested_values():
    q = CycleQuality(**{**_BASE, "n_frames": np.int64(7), "jerk": np.float64(np.inf),
                        "leg_ranges": {"a": float("nan"), "b": np.float64(2.5)},
                        "extra": {"k": np.int32(3)}})
    d = q.to_dict()
    assert d["n_frames"] == 7 and type(d["n_frames"]) is int
    assert d["jerk"] is None and d["leg_ranges"] == {"a": None, "b": 2.5}
    assert type(d["leg_ranges"]["b"]) is float and d["extra"] == {"k": 3}
    assert d["method"] == "x" and d["min_leg_channel"] == "lfemur.rx"
    assert d["seam"] == 1.5


# ------------------------------------------------------------------ targets
_BASE = dict(
    method="x", n_frames=100, period_frames=100.0, reference_period=100.0, period_error=0.0,
    jerk=1.0, jerk_ratio=1.0, leg_ranges={}, leg_range_ratios={}, min_leg_range_ratio=1.0,
    min_leg_channel="lfemur.rx", min_femur_tibia_ratio=1.0, joint_ranges={},
    joint_range_ratios={}, min_joint_range_ratio=1.0, min_joint="lfemur", step_spread=2.0,
    largest_step=1.0, seam=1.5, coverage=1.0, coverage_ratio=1.0, skating=1.0,
    skating_take=1.0, skating_ratio=1.0, root_closure_degrees=0.0, root_closure_steps=0.0,
    heading_change=0.0,
)


@pytest.mark.parametrize(
    "target,field,ok,bad",
    [
        ("period", "period_error", [0.05, -0.05, 0.0], [0.0501, -0.0501]),
        ("jerk", "jerk_ratio", [1.5, 0.0], [1.5001]),
        ("legs", "min_joint_range_ratio", [0.85, 1.2], [0.8499]),
        ("seam", "seam", [1.5, 1.0], [1.5001]),
        ("coverage", "coverage_ratio", [1.0, 0.5], [1.0001]),
        ("skating", "skating_ratio", [1.0, 0.0], [1.0001, 1.5]),
    ],
)
def test_each_target_at_its_threshold(target, field, ok, bad):
    for v in ok:
        assert targets(CycleQuality(**{**_BASE, field: v}))[target] is True, v
    for v in bad:
        assert targets(CycleQuality(**{**_BASE, field: v}))[target] is False, v
    assert targets(CycleQuality(**{**_BASE, field: float("nan")}))[target] is None


def test_targets_table_and_the_root_either_or():
    root = lambda deg, st: targets(CycleQuality(**{**_BASE, "root_closure_degrees": deg,
                                                  "root_closure_steps": st}))["root"]
    assert root(0.5, 9.0) is True and root(9.0, 1.5) is True
    assert root(0.5001, 1.5001) is False
    assert root(float("nan"), 0.0) is None
    # the legs target reads the per-joint ratio, not the per-channel one
    v = targets(CycleQuality(**{**_BASE, "min_leg_range_ratio": 0.1, "min_joint_range_ratio": 0.9}))
    assert v["legs"] is True
    assert list(targets(CycleQuality(**_BASE))) == ["period", "root", "jerk", "legs", "seam",
                                                   "coverage", "skating"]


def test_leg_length_is_the_chain_from_the_root_down():
    from cyclecoord.quality.cycle_quality import _leg_length

    m = _legs()
    # root -> lfemur (1, -1, 0) -> ltibia 4 -> lfoot 4 -> ltoes (0, -0.5, 1)
    assert _leg_length(m, "ltoes") == pytest.approx(np.sqrt(2) + 8 + np.sqrt(1.25))
    assert _leg_length(m, "lfemur") == pytest.approx(np.sqrt(2))
    assert _leg_length(m, "rfoot") == pytest.approx(np.sqrt(2) + 8)
    assert _leg_length(m, "root") == 0.0


def test_root_heading_of_a_skeleton_is_unwrapped_through_180():
    """The legs rig's root turning from 170 to 190 degrees (ry) over 11 frames: the
    heading read from its rotation crosses 180 and is unwrapped: 20 degrees over 10
    steps, 22 a loop of 11 frames."""
    m = _legs(T=11, fps=10.0)
    f = m.frames.copy()
    f[:, m.channels.index(("root", "ry"))] = np.linspace(170.0, 190.0, 11)
    m = m.with_frames(f)
    hpr = root_orientation(m)
    np.testing.assert_allclose(hpr[:, 0] - hpr[0, 0], np.linspace(0.0, 20.0, 11), atol=1e-9)
    assert heading_change(m) == pytest.approx(22.0)


def test_foot_skating_reads_each_point_at_its_own_resting_level():
    """The left leg held out 30 degrees to the side (its foot about 1.07 over the floor,
    under a quarter leg) and swinging 5 degrees to and fro; the right leg stands.  Each
    point is in contact near its own resting level, so the swinging foot's speed counts:
    the mean of the four points' horizontal speeds."""
    m = _legs(T=60, fps=30.0)
    f = m.frames.copy()
    f[:, m.channels.index(("lfemur", "rz"))] = 30.0
    f[:, m.channels.index(("lfemur", "rx"))] = 5.0 * np.sin(2 * np.pi * np.arange(60) / 30.0)
    m = m.with_frames(f)
    pos = m.positions()
    idx = [pos.names.index(n) for n in ("lfoot", "ltoes", "rfoot", "rtoes")]
    p = pos.positions[:, idx]
    assert 0.6 < p[:, 0, 1].min() - p[:, 2, 1].max()  # the left foot is off the floor
    v = np.linalg.norm(np.diff(p[:, :, [0, 2]], axis=0), axis=2) * 30.0
    assert v[:, :2].mean() > 1.0 and v[:, 2:].max() < 1e-9
    assert foot_skating_speed(m) == pytest.approx(v.mean(), rel=1e-9)


def test_a_ratio_with_an_infinite_side_is_no_ratio():
    from cyclecoord.quality.cycle_quality import _ratio

    assert _ratio(3.0, 2.0) == 1.5
    for a, b in ((1.0, float("inf")), (float("inf"), 2.0), (float("nan"), 2.0), (1.0, float("nan")),
                 (1.0, 0.0)):
        assert np.isnan(_ratio(a, b)), (a, b)
    take = _motion({"lfemur.rx": 10.0 * (np.arange(8) % 2)})
    assert np.isnan(cycle_quality(take, take, skating_take=float("inf")).skating_ratio)
