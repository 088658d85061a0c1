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


# ------------------------------------------------------------- known answers, exact edges
# legs_skeleton at 64 fps: leg length 8, so a height band of 1/16 is 0.5 units, the
# default speed limit (0.5 leg/s) 4 units/s; root moves of k / 16 a frame are exact in
# floating point, and so are the heights and central differences they give.
def _lifted(*offsets):
    """64 standing frames at 64 fps, the whole body raised on frames a to b by dy units
    for each (a, b, dy) of ``offsets``."""
    m = make_motion(legs_skeleton(), T=64, fps=64.0)
    f = m.frames.copy()
    ty = m.channels.index(("root", "ty"))
    for a, b, dy in offsets:
        f[a:b, ty] += dy
    return m.with_frames(f)


def test_a_point_exactly_at_the_height_band_is_not_planted():
    """Raised by exactly the band (0.5 units) a point is no longer down (height < band),
    raised by half of it it is; each point's level is its own (ankle 1, toe 0.5)."""
    m = _lifted((20, 30, 0.5), (40, 50, 0.25))
    c = foot_contacts(m, height=1 / 16, min_duration=0)
    assert c.height_threshold == 0.5 and c.floor == 0.5
    np.testing.assert_array_equal(c.contact_level, [1.0, 0.5, 1.0, 0.5])
    want = np.ones(64, bool)
    want[20:30] = False
    for i in range(4):
        np.testing.assert_array_equal(c.planted[:, i], want)
    np.testing.assert_allclose(c.height[25], 0.5)
    np.testing.assert_allclose(c.height[45], 0.25)
    # the default band, 0.05 of the leg (0.4 units): 0.25 is inside, 0.5 not
    d = foot_contacts(m, min_duration=0)
    assert d.height_threshold == pytest.approx(0.4)
    np.testing.assert_array_equal(d.planted[:, 0], want)


def test_a_point_exactly_at_the_speed_limit_is_not_planted():
    """Sliding at exactly the default limit (0.5 leg/s: 4 units/s) is not planted (speed
    < limit), at half of it is; with speed=None contact is from height alone."""
    fast = make_motion(legs_skeleton(), T=64, fps=64.0, root_speed=4.0)
    c = foot_contacts(fast)
    assert c.speed_threshold == 4.0
    np.testing.assert_array_equal(c.speed, np.full((64, 4), 4.0))
    assert not c.planted.any()
    assert foot_contacts(make_motion(legs_skeleton(), T=64, fps=64.0, root_speed=2.0)).planted.all()
    # a limit of 0.75 leg/s (6 units/s) lets 4 units/s through; None lets any speed through
    assert foot_contacts(fast, speed=0.75).planted.all()
    free = foot_contacts(make_motion(legs_skeleton(), T=64, fps=64.0, root_speed=40.0), speed=None)
    assert free.planted.all() and free.speed_threshold == np.inf


def test_a_planted_point_exactly_at_the_skate_speed_does_not_skate():
    """skate_speed 1/8 leg/s is 1 unit/s: sliding at exactly 1 does not skate (speed >
    threshold), at 1.25 it does; the default 0.1 leg/s (0.8 units/s) is passed by 1."""
    sk = legs_skeleton()
    at = foot_skating(make_motion(sk, T=64, fps=64.0, root_speed=1.0), skate_speed=0.125)
    assert at.skate_threshold == 1.0 and at.skating_frames == 0 and not at.skating.any()
    assert at.mean_speed == 1.0 and at.mean_speed_legs == 1 / 8
    over = foot_skating(make_motion(sk, T=64, fps=64.0, root_speed=1.25), skate_speed=0.125)
    assert over.skating_frames == 64 and over.skating_fraction == 1.0
    default = foot_skating(make_motion(sk, T=64, fps=64.0, root_speed=1.0))
    assert default.skate_threshold == pytest.approx(0.8) and default.skating_fraction == 1.0


def test_the_floor_is_a_low_quantile_of_the_lowest_points_end_sites_included():
    """The toe end sites 0.25 below the toe joints (at 0.25 when standing) are the lowest
    points: the floor.  Raised by 0.01 k on frame k (k = 0..99), the floor is the 5 %
    quantile of 0.25 + 0.01 k: 0.25 + 0.0495 (linear interpolation at 99 * 0.05)."""
    from dataclasses import replace

    sk = legs_skeleton()
    low = Skeleton(tuple(replace(j, end_site=np.array([0.0, -0.25, 0.5]))
                         if j.name.endswith("toes") else j for j in sk.joints), name="legs")
    c = foot_contacts(make_motion(low))
    assert c.floor == pytest.approx(0.25)
    np.testing.assert_allclose(c.contact_level, [1.0, 0.5, 1.0, 0.5])  # points' own levels
    m = make_motion(low, T=100)
    f = m.frames.copy()
    f[:, m.channels.index(("root", "ty"))] += 0.01 * np.arange(100)
    c = foot_contacts(m.with_frames(f))
    assert c.floor == pytest.approx(0.25 + 0.0495)
    np.testing.assert_allclose(c.contact_level, [1.0495, 0.5495, 1.0495, 0.5495])


def test_a_given_floor_bounds_each_points_contact_level():
    """A point's level is kept between the floor and a quarter leg (2 units) above it:
    with the floor at 1.2 every level is raised to 1.2 (heights below it are negative,
    still down); with the floor at -5 every level is lowered to -3 and nothing is down."""
    m = make_motion(legs_skeleton())
    high = foot_contacts(m, floor=1.2)
    assert high.floor == 1.2
    np.testing.assert_allclose(high.contact_level, [1.2] * 4)
    np.testing.assert_allclose(high.height[0], [-0.2, -0.7, -0.2, -0.7])
    assert high.planted.all()
    low = foot_contacts(m, floor=-5.0)
    np.testing.assert_allclose(low.contact_level, [-3.0] * 4)
    np.testing.assert_allclose(low.height[0], [4.0, 3.5, 4.0, 3.5])
    assert not low.planted.any()
    np.testing.assert_allclose(foot_contacts(m, floor=0.0).contact_level, [1.0, 0.5, 1.0, 0.5])


def test_the_up_axis_decides_height_and_horizontal_speed():
    """The standing legs bobbing along y, read with z up: their heights are the z
    coordinates (ankle 0, toe 1: constant, the floor at 0) and the bobbing is horizontal
    speed, |d ty / dt| by central differences."""
    m = make_motion(legs_skeleton(), T=120, fps=60.0, bob=(0.15, 2.0))
    c = foot_contacts(m, up="z", speed=None)
    assert c.up == 2 and c.floor == pytest.approx(0.0)
    np.testing.assert_allclose(c.contact_level, [0.0, 1.0, 0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(c.height, 0.0, atol=1e-12)
    ty = m.frames[:, m.channels.index(("root", "ty"))]
    want = np.abs(np.gradient(ty)) * m.fps
    for i in range(4):
        np.testing.assert_allclose(c.speed[:, i], want, atol=1e-9)
    assert foot_contacts(m).up == 1
    with pytest.raises(ParameterError, match="up axis"):
        foot_contacts(m, up="w")


def test_min_duration_default_closes_one_frame_gaps_only():
    """The default 0.03 s at 64 fps is round(1.92) = 2 frames: a 1-frame lift is a gap
    closed, a 2-frame lift stays; min_duration 0 keeps the 1-frame lift too."""
    m = _lifted((20, 21, 0.5), (40, 42, 0.5))
    c = foot_contacts(m)
    want = np.ones(64, bool)
    want[40:42] = False
    np.testing.assert_array_equal(c.planted[:, 0], want)
    want[20] = False
    np.testing.assert_array_equal(foot_contacts(m, min_duration=0).planted[:, 0], want)
    # and 1-frame contacts (down on frames 10, 20 ... 50 of a lifted take: enough for the
    # 5 % quantile to be the level down) are dropped
    up = _lifted((0, 10, 0.5), *[(a + 1, a + 10, 0.5) for a in (10, 20, 30, 40)], (51, 64, 0.5))
    short = foot_contacts(up, min_duration=0)
    assert short.planted[:, 0].tolist() == [i in (10, 20, 30, 40, 50) for i in range(64)]
    assert not foot_contacts(up).planted.any()


def test_threshold_validation():
    m = make_motion(legs_skeleton())
    for kw, match in ((dict(height=np.nan), "height"), (dict(height=-0.1), "height"),
                      (dict(height=np.inf), "height"), (dict(speed=0.0), "speed"),
                      (dict(speed=np.nan), "speed"), (dict(speed=None, height=0.0), "height"),
                      (dict(min_duration=-0.01), "min_duration"),
                      (dict(min_duration=np.nan), "min_duration")):
        with pytest.raises(ParameterError, match=match):
            foot_contacts(m, **kw)
    assert foot_contacts(m, min_duration=0.0).planted.all()
    for bad in (-0.1, np.nan, np.inf):
        with pytest.raises(ParameterError, match="skate_speed"):
            foot_skating(m, skate_speed=bad)
    c = foot_contacts(m)
    with pytest.raises(ParameterError, match="either"):
        foot_skating(m, c, height=0.1)
    with pytest.raises(ParameterError, match="cover 120 frames"):
        foot_skating(m[:100], c)
    bare = Motion(m.frames, m.channels, fps=m.fps)
    with pytest.raises(ParameterError, match="skeleton"):
        foot_skating(bare, c)


def test_contact_skeleton_names_the_first_bad_frame_in_the_motions_numbering():
    from cyclecoord.quality.contacts import contact_skeleton

    m = make_motion(legs_skeleton())
    f = m.frames.copy()
    f[[7, 9], 2] = np.inf
    with pytest.raises(ParameterError, match=r"frame 107 .*\(2 such frames\)"):
        contact_skeleton(Motion(f, m.channels, fps=m.fps, skeleton=m.skeleton, start_frame=100))
    assert contact_skeleton(m) is m.skeleton


def test_leg_length_is_the_mean_over_legs_of_thigh_plus_shin():
    """Neutral joint names (no role from the names): a point given alone whose bone is
    under half its parent's is a toe, its parent the ankle; the left toe made 3 long (not
    under half the 4 of its parent) is an ankle itself: shin 3, thigh 4.  Mean of 7 and 8."""
    from dataclasses import replace

    n = legs_skeleton(("a1", "a2", "a3", "a4", "b1", "b2", "b3", "b4"))
    assert leg_length(n, ("a4", "b4")) == 8.0 and leg_length(n, ("a3", "b3")) == 8.0
    js = list(n.joints)
    js[4] = replace(js[4], offset=np.array([0.0, 0.0, 3.0]))
    assert leg_length(Skeleton(tuple(js)), ("a4", "b4")) == 7.5
    # a foot hanging from the root: no thigh, the shin alone
    hang = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz"), ""),
                     Joint("foot", 0, [0, -5, 0], ("rx",), "X")))
    assert leg_length(hang, ("foot",)) == 5.0
    with pytest.raises(ParameterError, match="leg length"):
        leg_length(hang, ("root",))


def test_per_foot_skating_and_the_report():
    """Sliding at 2 units/s (over the 0.8 skate threshold) with the left foot lifted on
    frames 40-80: each point skates on the frames it is planted; every frame has a
    planted right foot, so every frame skates."""
    from cyclecoord.quality.contacts import skating_line, skating_report

    T = 120
    lift = np.zeros(T, bool)
    lift[40:80] = True
    m = make_motion(legs_skeleton(), T=T, root_speed=2.0, lift_left=lift)
    c = foot_contacts(m)
    s = foot_skating(m, c)
    np.testing.assert_array_equal(s.skating, c.planted)
    np.testing.assert_allclose(s.foot_skating_fraction, c.planted.mean(axis=0))
    assert s.foot_skating_fraction[0] < 1.0 and s.foot_skating_fraction[2] == 1.0
    assert s.skating_frames == T and s.skating_fraction == 1.0
    d = s.to_dict()
    assert d["per_foot"]["lfoot"]["skating_fraction"] == pytest.approx(s.foot_skating_fraction[0])
    assert d["per_foot"]["rfoot"]["mean_speed_units_per_s"] == pytest.approx(2.0)
    assert d["leg_length"] == 8.0 and d["skate_threshold_units_per_s"] == pytest.approx(0.8)
    rep = skating_report(m)
    assert rep["planted_fraction"]["lfoot"] == pytest.approx(c.planted[:, 0].mean())
    assert rep["planted_fraction"]["rtoes"] == 1.0 and rep["floor"] == c.floor
    assert skating_line(rep) == ("foot skating: 2 units/s (0.25 leg lengths/s) while planted, "
                                 "120 frames skating (100.0%)")
    assert skating_line(None) == "foot skating: not measured (no skeleton with recognisable feet)"


def test_a_point_never_planted_has_no_mean_speed_in_the_dict():
    from dataclasses import replace

    m = make_motion(legs_skeleton(), root_speed=2.0)
    c = foot_contacts(m)
    planted = c.planted.copy()
    planted[:, 1] = False
    d = foot_skating(m, replace(c, planted=planted)).to_dict()
    assert d["per_foot"]["ltoes"]["mean_speed_units_per_s"] is None
    assert d["per_foot"]["ltoes"]["skating_fraction"] == 0.0
    assert d["per_foot"]["lfoot"]["mean_speed_units_per_s"] == pytest.approx(2.0)


def test_sides_legs_and_the_summary():
    from dataclasses import replace

    T = 120
    lift = np.zeros(T, bool)
    lift[60:] = True  # lifted on the second half: planted half the time
    c = foot_contacts(make_motion(legs_skeleton(), T=T, lift_left=lift))
    assert c.sides == ("left", "left", "right", "right") and c.n_frames == T
    assert c.leg_labels == (c.legs or c.sides)
    frac = 100 * c.planted[:, 0].mean()
    assert 45 < frac < 55
    assert c.summary() == (f"planted: lfoot {frac:.0f}%, ltoes {100 * c.planted[:, 1].mean():.0f}%, "
                           "rfoot 100%, rtoes 100%")
    with pytest.raises(ParameterError, match="no front left foot"):
        c.side_planted("front left")
    # leg labels (a quadruped's) are matched as well as the sides; empty: the sides
    q = replace(c, legs=("front left", "front left", "hind right", "hind right"))
    np.testing.assert_array_equal(q.side_planted("front left"), c.side_planted("left"))
    np.testing.assert_array_equal(q.side_planted("left"), c.side_planted("left"))
    assert replace(c, legs=()).leg_labels == c.sides


def test_the_ankle_rules_of_leg_length():
    """The ankle of a leg is its highest given point, moved to its parent when it is a toe
    (named so, or a bone under half its parent's).  By hand on the test legs (thigh 4, shin
    4, hip bone sqrt 2, toe sqrt(1.25)):"""
    from dataclasses import replace

    sk = legs_skeleton()
    js = list(sk.joints)
    js[4] = replace(js[4], offset=np.array([0.0, 0.0, 3.0]))  # ltoes 3 long, still a toe by name
    assert leg_length(Skeleton(tuple(js)), ("ltoes", "rtoes")) == 8.0
    n = legs_skeleton(("a1", "a2", "a3", "a4", "b1", "b2", "b3", "b4"))
    js = list(n.joints)
    js[4] = replace(js[4], offset=np.array([0.0, 0.0, 2.0]))  # exactly half its parent: kept
    assert leg_length(Skeleton(tuple(js)), ("a4", "b4")) == (2.0 + 4.0 + 8.0) / 2
    # the knees given: shin 4 (the knee's bone), thigh the hip bone sqrt 2 (parent 1)
    assert leg_length(n, ("a2", "b2")) == pytest.approx(4 + np.sqrt(2))
    # a toe right under the root is its own ankle (the root is no ankle): no thigh
    t = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz"), ""),
                  Joint("ltoes", 0, [0, -5.0, 0], ("rx",), "X")))
    assert leg_length(t, ("ltoes",)) == 5.0
    # a toe under joint 1: the ankle is joint 1, whose parent (the root) adds no thigh
    s = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz"), ""),
                  Joint("shin", 0, [0, -4.0, 0], ("rx",), "X"),
                  Joint("ltoes", 1, [0, -0.5, 1], ("rx",), "X")))
    assert leg_length(s, ("ltoes",)) == 4.0
    # a root with an offset: never a thigh; but the highest given point of a chain even
    # when that is the root (its own offset the shin)
    h = Skeleton((Joint("root", -1, [0, 3.0, 0], ("tx", "ty", "tz"), ""),
                  Joint("foot", 0, [0, -5.0, 0], ("rx",), "X")))
    assert leg_length(h, ("foot",)) == 5.0 and leg_length(h, ("root", "foot")) == 3.0
    small = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz"), ""),
                      Joint("foot", 0, [0, -0.5, 0], ("rx",), "X")))
    assert leg_length(small, ("foot",)) == 0.5
    with pytest.raises(ParameterError, match="leg length"):
        leg_length(h, ())


def test_only_the_feet_end_sites_count_for_the_floor():
    """A tail whose end site hangs 9 below the hips' level is no foot: the floor stays at
    the toe end sites (0.5)."""
    sk = legs_skeleton()
    tail = Skeleton(sk.joints + (Joint("tail", 0, [0, -2.0, -1], ("rx",), "X",
                                       end_site=np.array([0, -9.0, 0])),), name="legs")
    c = foot_contacts(make_motion(tail), feet=("lfoot", "ltoes", "rfoot", "rtoes"))
    assert c.floor == 0.5 and c.planted.all()


def test_x_up_and_frozen_results():
    import dataclasses

    c = foot_contacts(make_motion(legs_skeleton()), up="x", speed=None)
    # along x the left foot points are at +1, the right ones at -1: the floor
    assert c.up == 0 and c.floor == -1.0
    np.testing.assert_allclose(c.contact_level, [1.0, 1.0, -1.0, -1.0])
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.floor = 0.0
    s = foot_skating(make_motion(legs_skeleton()))
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.mean_speed = 1.0
