"""Foot contacts and foot skating: synthetic legs with known answers and the CMU walk/jog."""

import itertools

import numpy as np
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.motion import Motion
from cyclecoord.quality.contacts import (
    contact_runs,
    find_feet,
    foot_contacts,
    foot_skating,
    leg_length,
)
from _legs import legs_skeleton, make_motion  # tests/ is on the path (rootdir conftest)
from _measured import at_least, at_most
from cyclecoord.skeleton import Joint, Skeleton




def test_find_feet_and_leg_length():
    skel = legs_skeleton()
    assert find_feet(skel) == ("lfoot", "ltoes", "rfoot", "rtoes")
    assert leg_length(skel) == pytest.approx(8.0)
    bvh = legs_skeleton(
        (
            "LeftUpLeg",
            "LeftLeg",
            "LeftFoot",
            "LeftToeBase",
            "RightUpLeg",
            "RightLeg",
            "RightFoot",
            "RightToeBase",
        )
    )
    assert find_feet(bvh) == ("LeftFoot", "LeftToeBase", "RightFoot", "RightToeBase")


def test_standing_still_is_planted_and_does_not_skate():
    m = make_motion(legs_skeleton())
    c = foot_contacts(m)
    assert c.planted.all()
    assert c.floor == pytest.approx(10 - 1 - 8 - 0.5)  # toe end site, on a floor at 0.5
    assert np.allclose(c.speed, 0)
    s = foot_skating(m, c)
    assert s.skating_frames == 0 and s.mean_speed == 0


def test_sliding_feet_skate_at_the_root_speed():
    skel = legs_skeleton()
    v = 0.3 * leg_length(skel)  # below the contact speed limit, above the skate threshold
    m = make_motion(skel, root_speed=v)
    s = foot_skating(m)
    assert s.skating_fraction == 1.0
    assert s.mean_speed == pytest.approx(v)
    assert s.mean_speed_legs == pytest.approx(0.3)
    assert np.allclose(s.foot_mean_speed, v)


def test_vertical_speed_is_neither_contact_speed_nor_skating():
    """Known answer: feet that bob up and down inside the contact height band (0.3 units of
    its 0.4), at up to 5.7 units/s vertically (the contact speed limit is 4, the skating
    one 0.8), never move horizontally: always planted, never skating."""
    skel = legs_skeleton()
    m = make_motion(skel, T=240, fps=120.0, bob=(0.15, 6.0))
    pos = m.positions()
    feet = [pos.names.index(f) for f in find_feet(skel)]
    vertical = np.abs(np.gradient(pos.positions[:, feet, 1], axis=0)) * m.fps
    assert vertical.max() > 1.3 * 0.5 * leg_length(skel)  # well over the contact speed limit
    c = foot_contacts(m)
    np.testing.assert_allclose(c.speed, 0.0, atol=1e-9)
    assert c.planted.all()
    s = foot_skating(m, c)
    assert s.skating_frames == 0 and s.mean_speed == pytest.approx(0.0, abs=1e-9)
    # measured on the contacts found afresh too (foot_skating's own call)
    assert foot_skating(m).skating_frames == 0


def test_lifted_foot_is_not_planted():
    T = 120
    lift = np.zeros(T, bool)
    lift[40:80] = True
    m = make_motion(legs_skeleton(), T=T, lift_left=lift)
    c = foot_contacts(m)
    left = c.side_planted("left")
    right = c.side_planted("right")
    assert right.all()
    assert not left[41:79].any()
    assert left[:39].all() and left[81:].all()
    assert contact_runs(~left) == [(39, 81)]  # central differences see the jump a frame early


def test_errors():
    skel = legs_skeleton()
    m = make_motion(skel)
    bare = Motion(m.frames, m.channels, fps=m.fps)
    with pytest.raises(ParameterError, match="skeleton"):
        foot_contacts(bare)
    with pytest.raises(ParameterError, match="skeleton"):
        foot_skating(bare)
    frames = m.frames.copy()
    frames[7, 3] = np.nan
    with pytest.raises(ParameterError, match="frame 7"):
        foot_contacts(m.with_frames(frames))
    with pytest.raises(ParameterError, match="no joint"):
        foot_contacts(m, feet=("nosuch",))
    with pytest.raises(ParameterError, match="positive"):
        foot_contacts(m, height=0)
    other = Skeleton((Joint("root", -1, [0, 0, 0], ("tx",), ""), Joint("a", 0, [0, 1, 0])))
    with pytest.raises(ParameterError, match="foot joints"):
        find_feet(other)


def _alternates(c):
    """Left-only and right-only stance stretches alternate (merging double support)."""
    left, right = c.side_planted("left"), c.side_planted("right")
    labels = []
    for lo, ro in zip(left & ~right, right & ~left):
        lab = "L" if lo else "R" if ro else None
        if lab and (not labels or labels[-1] != lab):
            labels.append(lab)
    return labels


def test_walk_69_01_alternates(walk_69_01):
    c = foot_contacts(walk_69_01)
    assert c.feet == ("lfoot", "ltoes", "rfoot", "rtoes")
    labels = _alternates(c)
    assert len(labels) >= 4
    assert all(a != b for a, b in itertools.pairwise(labels))
    # a walk always has a foot down; the floor is estimated well above 0 for CMU
    assert (c.side_planted("left") | c.side_planted("right")).mean() > 0.97
    assert 0.2 < c.floor < 1.5
    s = foot_skating(walk_69_01, c)
    assert 0 < s.mean_speed_legs <= at_most(0.0894)  # measured 0.0894 leg lengths/s


def test_jog_143_01_alternates_with_flight(cmu_dir):
    import cyclecoord as cc

    m = cc.load(cmu_dir / "143" / "143_01.amc")
    c = foot_contacts(m)
    labels = _alternates(c)
    assert len(labels) >= 4
    assert all(a != b for a, b in itertools.pairwise(labels))
    flight = ~(c.side_planted("left") | c.side_planted("right"))
    assert at_least(0.69) <= flight.mean() <= at_most(0.69)  # a jog leaves the ground: measured 69 %


def test_skating_report(walk_69_01):
    from cyclecoord.quality.contacts import skating_report

    rep = skating_report(walk_69_01[200:450])
    assert rep["skating_frames"] > 0 and set(rep["per_foot"]) == {
        "lfoot",
        "ltoes",
        "rfoot",
        "rtoes",
    }
    assert 0 < rep["planted_fraction"]["lfoot"] < 1
    bare = Motion(walk_69_01.frames[:5], walk_69_01.channels, fps=120)
    assert skating_report(bare) is None


def test_skating_line(walk_69_01):
    from cyclecoord.quality.contacts import foot_skating, skating_line, skating_report

    m = walk_69_01[200:450]
    assert skating_line(skating_report(m)) == foot_skating(m).summary()
    assert skating_line(skating_report(m), "blend").startswith("blend foot skating: ")
    assert "not measured" in skating_line(None, "cycle")


def test_clean_closes_short_gaps_inside_and_drops_short_runs():
    """Gaps inside shorter than min_frames are closed, then contacts shorter than
    min_frames dropped; min_frames 1 or less leaves the mask as it is.  min_frames 3: gaps
    of 2 and 1 frames between contacts are closed, a 3-frame gap is kept, a gap at either
    end is not between contacts; a 2-frame contact is dropped."""
    from cyclecoord.quality.contacts import _clean

    m = np.array([0, 1, 1, 1, 0, 0, 1, 1, 1, 0, 0, 0, 1, 1, 1, 1, 0, 1, 1, 0, 0, 0, 1, 1, 0], bool)
    want = np.array([0, 1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0],
                    bool)
    np.testing.assert_array_equal(_clean(m, 3), want)
    np.testing.assert_array_equal(_clean(m, 1), m)  # 1 frame: nothing to clean
    # 2 frames: the one-frame gap inside is closed, the one-frame contact dropped, two kept
    m2 = np.array([1, 0, 1, 1, 0, 0, 1, 0, 0, 1, 1, 0], bool)
    np.testing.assert_array_equal(_clean(m2, 2),
                                  np.array([1, 1, 1, 1, 0, 0, 0, 0, 0, 1, 1, 0], bool))
    np.testing.assert_array_equal(_clean(m, 2), m | (np.arange(m.size) == 16))


def test_a_foot_held_up_all_take_is_never_planted():
    """Standing on the right leg, the left thigh held 50 degrees forward all take: the
    left foot is 2.86 units (0.36 leg) over the floor on every frame.  A point's contact
    level may lie at most a quarter leg over the floor, so the held foot never reads as
    down (its own lowest height would make it planted throughout)."""
    skel = legs_skeleton()
    m = make_motion(skel, T=120, lift_left=np.ones(120, bool))
    f = m.frames.copy()
    f[:, m.channels.index(("lfemur", "rx"))] = -50.0
    c = foot_contacts(m.with_frames(f))
    assert c.floor == pytest.approx(0.5) and c.leg_length == pytest.approx(8.0)
    np.testing.assert_allclose(c.contact_level, [2.5, 2.5, 1.0, 0.5])  # capped at 0.5 + 8 / 4
    lifted = 9 - 8 * np.cos(np.radians(50))  # hip at 9, leg of 8
    np.testing.assert_allclose(c.height[:, 0], lifted - 2.5)
    assert not c.side_planted("left").any() and c.side_planted("right").all()


def test_skate_speed_zero_counts_every_moving_planted_foot():
    """A planted point skates when it moves faster than skate_speed: at 0 a still foot
    does not, a foot sliding however slowly does (the threshold is not reached by
    standing still)."""
    skel = legs_skeleton()
    still = foot_skating(make_motion(skel), skate_speed=0.0)
    assert still.skating_frames == 0 and still.skate_threshold == 0.0
    assert not still.skating.any()
    creep = foot_skating(make_motion(skel, root_speed=0.05), skate_speed=0.0)
    assert creep.skating_fraction == 1.0 and creep.skating.all()
    # at 0.1 leg lengths/s (0.8 units/s here) the same creep is not skating
    slow = foot_skating(make_motion(skel, root_speed=0.05))
    assert slow.skating_frames == 0 and slow.skate_threshold == pytest.approx(0.8)
    assert foot_skating(make_motion(skel, root_speed=0.9)).skating_fraction == 1.0


def test_mean_speeds_are_over_planted_frames_only():
    """Sliding at 2 units/s with the left foot lifted on frames 40-80: every foot's mean
    speed while planted is 2 (the lift's jumps are not planted frames); with no foot ever
    planted (a jump) nothing slides: mean speed 0."""
    from dataclasses import replace

    T = 120
    lift = np.zeros(T, bool)
    lift[40:80] = True
    m = make_motion(legs_skeleton(), T=T, root_speed=2.0, lift_left=lift)
    c = foot_contacts(m)
    assert not c.side_planted("left").all() and c.planted.any(axis=0).all()
    s = foot_skating(m, c)
    np.testing.assert_allclose(s.foot_mean_speed, 2.0)
    assert s.mean_speed == pytest.approx(2.0)
    air = foot_skating(m, replace(c, planted=np.zeros_like(c.planted)))
    assert air.mean_speed == 0.0 and air.skating_frames == 0
    assert np.isnan(air.foot_mean_speed).all()


def test_two_frames_are_enough_one_is_not():
    """Documented: at least 2 frames; two frames of standing still are planted."""
    m = make_motion(legs_skeleton(), T=2)
    assert foot_contacts(m).planted.all()
    with pytest.raises(ParameterError, match="at least 2 frames"):
        foot_contacts(make_motion(legs_skeleton(), T=1))


def test_min_duration_is_in_seconds():
    """A lift of 4 frames at 120 fps (about 0.05 s with the frames central differences
    add) is a gap under min_duration = 0.2 s (24 frames), closed; under 0.01 s (1 frame)
    it stays."""
    lift = np.zeros(240, bool)
    lift[100:104] = True
    m = make_motion(legs_skeleton(), T=240, fps=120.0, lift_left=lift)
    assert foot_contacts(m, min_duration=0.2).side_planted("left").all()
    short = foot_contacts(m, min_duration=0.01).side_planted("left")
    assert not short[100:104].any() and short[:98].all() and short[106:].all()
