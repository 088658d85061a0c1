"""Cycle quality on joint positions: the same from every file, pops and strays called."""

import pytest

import cyclecoord as cc
from cyclecoord.quality.pose_space import pose_quality


@pytest.fixture(scope="module")
def extracted():
    return cc.extract(cc.datasets.example_capture().motion)


@pytest.mark.parametrize("suffix", [".bvh", ".npz", ".amc", ".glb"])
def test_same_figures_from_every_file(extracted, tmp_path, suffix):
    res = extracted
    path = tmp_path / f"cycle{suffix}"
    cc.save(res.cycle, path)
    back = cc.load(path)
    a = pose_quality(res.cycle, res.motion, res.used_frames, res.period_frames)
    b = pose_quality(back, res.motion, res.used_frames, res.period_frames)
    for k in ("seam", "pop", "nearest_max", "jerk_ratio"):
        assert getattr(b, k) == pytest.approx(getattr(a, k), rel=0.02), k


def test_a_pop_and_a_stray_pose_are_called(extracted):
    res = extracted
    good = pose_quality(res.cycle, res.motion, res.used_frames, res.period_frames)
    assert not good.pops and good.seamless and not good.strays
    f = res.cycle.frames.copy()
    knee = res.cycle.channel_index("ltibia", "rx")
    f[40:45, knee] += 60.0  # the knee snaps 60 degrees for five frames
    bad = pose_quality(res.cycle.with_frames(f), res.motion, res.used_frames, res.period_frames)
    assert bad.pops and not bad.seamless and bad.strays
    assert bad.pop > 2.0 and bad.nearest_max > 1.0


def test_capture_copy_is_at_distance_zero(extracted):
    res = extracted
    a, b = res.used_frames[0]
    P = int(round(res.period_frames))
    copy = res.motion.window((a, a + P))
    q = pose_quality(copy, res.motion, res.used_frames, res.period_frames)
    assert q.nearest_max == pytest.approx(0.0, abs=1e-9)


def test_a_two_frame_run_has_one_capture_step():
    """A run of two frames has one frame step: the first step of a longer run from there."""
    from cyclecoord.quality.pose_space import _capture_steps
    from cyclecoord.rig import describe_rig

    m = cc.datasets.make_periodic_capture(kind="walk", n_frames=40, period=20, random_state=0).motion
    rig = describe_rig(m)
    two, three = _capture_steps(m, [(5, 7)], rig), _capture_steps(m, [(5, 8)], rig)
    assert two.shape == (1,) and three.shape == (2,) and two[0] == three[0] > 0
    assert _capture_steps(m, [(5, 6)], rig).size == 0  # one frame: no step


def test_distances_are_rms_point_distances_even_for_one_point():
    """A rig of one point (a root alone) climbing 0.01 a frame: its steps are 0.01 and
    the nearest pose half a period (10 frames) away is 0.1 away, the spread; with one
    point the RMS point distance is the distance itself."""
    import numpy as np

    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),))
    f = np.zeros((60, 6))
    f[:, 1] = 1 + 0.01 * np.arange(60)
    m = Motion(f, sk.channels, fps=30, skeleton=sk)
    q = pose_quality(m.window((20, 40)), m, [(0, 60)], 20.0)
    assert q.median_cycle_step == pytest.approx(0.01) and q.spread == pytest.approx(0.1)
    assert q.nearest_max == 0.0  # the cycle's poses are captured ones


def test_point_jerk_of_a_cubic_and_of_a_circle():
    """Known third derivatives: points moving as a * t**3 have jerk 6 a at every frame
    (a cubic's third difference is exact); two points going round circles of radius r,
    T frames a turn, have third differences of norm r (2 sin(pi / T))**3 each, times
    fps**3, and the loop's seam reads like any frame (RMS over the points)."""
    import numpy as np

    from cyclecoord.quality.pose_space import point_jerk

    fps, a = 30.0, 0.7
    t = np.arange(20) / fps
    cubic = np.zeros((20, 7))  # rows as root_frame_points gives: 2 points and the root height
    cubic[:, 0] = a * t ** 3
    cubic[:, 4] = a * t ** 3
    j = point_jerk(cubic, fps, cyclic=False)
    assert j.shape == (17,)
    # each point's jerk is 6 a along one axis; the RMS over the two points is 6 a
    np.testing.assert_allclose(j, 6 * a, rtol=1e-6)
    np.testing.assert_allclose(point_jerk(cubic[:, :1], fps, cyclic=False), 6 * a, rtol=1e-6)
    T, r = 40, 2.0
    w = 2 * np.pi * np.arange(T) / T
    loop = np.zeros((T, 7))
    loop[:, 0], loop[:, 1] = r * np.cos(w), r * np.sin(w)
    loop[:, 3], loop[:, 5] = r * np.sin(w), r * np.cos(w)
    jc = point_jerk(loop, fps, cyclic=True)
    assert jc.shape == (T,)
    np.testing.assert_allclose(jc, r * (2 * np.sin(np.pi / T)) ** 3 * fps ** 3, rtol=1e-9)


def test_a_two_frame_run_keeps_the_frame_numbers_of_the_runs_after_it():
    """The one-point rig climbing 0.01 a frame, made from a 2-frame run and frames 10-60:
    each captured pose's nearest one half a period (10 frames) away or more is 0.1 away,
    the spread, with the short run in or out."""
    import numpy as np

    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),))
    f = np.zeros((60, 6))
    f[:, 1] = 1 + 0.01 * np.arange(60)
    m = Motion(f, sk.channels, fps=30, skeleton=sk)
    cycle = m.window((20, 40))
    alone = pose_quality(cycle, m, [(10, 60)], 20.0)
    short = pose_quality(cycle, m, [(0, 2), (5, 6), (10, 60)], 20.0)  # one frame: no step
    assert alone.spread == pytest.approx(0.1) and short.spread == pytest.approx(0.1)
    assert short.nearest_max == 0.0


def test_cycle_figures_lengths_are_in_metres(extracted):
    """Steps and jerk scale with the rig's metres per unit; the loop closure has no unit."""
    from dataclasses import replace

    from cyclecoord.quality.pose_space import cycle_figures
    from cyclecoord.rig import describe_rig

    cycle = extracted.cycle
    rig = describe_rig(cycle)
    a = cycle_figures(cycle, rig)
    b = cycle_figures(cycle, replace(rig, metres_per_unit=2.0 * rig.metres_per_unit))
    for k in ("jerk", "largest_step", "median_step"):
        assert getattr(b, k) == pytest.approx(2.0 * getattr(a, k), rel=1e-12), k
    assert b.loop_closure == pytest.approx(a.loop_closure, rel=1e-12)
    assert 0 < a.median_step <= a.largest_step


def test_capture_jerk_from_runs_of_five_frames(extracted):
    """The capture's jerk needs runs of at least 5 frames (the open 5-point stencil): a run
    of exactly 5 has one (that run's jerk, in metres), runs of 4 have none (NaN)."""
    import numpy as np

    from cyclecoord.quality.pose_space import _jerk, root_frame_points
    from cyclecoord.rig import describe_rig

    res = extracted
    a = res.used_frames[0][0]
    rig = describe_rig(res.motion)
    q = pose_quality(res.cycle, res.motion, [(a, a + 5)], res.period_frames)
    pts = root_frame_points(res.motion.window((a, a + 5)), rig)
    assert q.capture_jerk == pytest.approx(_jerk(pts, res.motion.fps, False) * rig.metres_per_unit)
    assert np.isfinite(q.capture_jerk) and q.capture_jerk > 0
    assert np.isnan(pose_quality(res.cycle, res.motion, [(a, a + 4)], res.period_frames).capture_jerk)


# ------------------------------------------------------------------ known answers, by hand
def _root_only(y, fps=30):
    """A rig of one point (the root) at heights ``y``: its root-frame points are 0, 0, 0
    and y, so every step and jerk is read off ``y`` by hand."""
    import numpy as np

    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),))
    f = np.zeros((len(y), 6))
    f[:, 1] = y
    return Motion(f, sk.channels, fps=fps, skeleton=sk)


def _unit_rig(motion, metres=1.0):
    from dataclasses import replace

    from cyclecoord.rig import describe_rig

    return replace(describe_rig(motion), metres_per_unit=metres)


def test_root_frame_points_remove_travel_and_heading_but_keep_lean():
    """Root, an arm 1 along x, a zero-length twist under it (with a zero end site) and a
    leg 2 down with an end site 1 further: the twist and its end site sit on the arm and
    are left out, so 4 points (12 columns) and the root's height.  Moving the root, or
    turning it 90 degrees about the vertical, changes nothing; rolling it 90 degrees about
    z (a lean) turns the arm to +y and the leg to +x; 30 degrees about x tilts the leg."""
    import numpy as np

    from cyclecoord.motion import Motion
    from cyclecoord.quality.pose_space import _distinct_points, root_frame_points
    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
                   Joint("arm", 0, [1.0, 0, 0], ("rx",), "X"),
                   Joint("twist", 1, [0, 0, 0], ("rx",), "X", end_site=np.zeros(3)),
                   Joint("leg", 0, [0, -2.0, 0], ("rx",), "X", end_site=np.array([0, -1.0, 0]))))
    ch = list(sk.channels)
    f = np.zeros((4, len(ch)))
    f[:, 0] = [0, 5, 10, 15]  # travelling along x
    f[:, 1] = 3.0
    f[1, ch.index(("root", "ry"))] = 90.0
    f[2, ch.index(("root", "rz"))] = 90.0
    f[3, ch.index(("root", "rx"))] = 30.0
    m = Motion(f, sk.channels, fps=30, skeleton=sk)
    names = m.positions().names
    assert names == ["root", "arm", "twist", "leg", "twist/end", "leg/end"]
    assert _distinct_points(sk, names) == [0, 1, 3, 5]
    got = root_frame_points(m)
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    want = np.array([
        [0, 0, 0, 1, 0, 0, 0, -2, 0, 0, -3, 0, 3],
        [0, 0, 0, 1, 0, 0, 0, -2, 0, 0, -3, 0, 3],
        [0, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 3],
        [0, 0, 0, 1, 0, 0, 0, -2 * c, -2 * s, 0, -3 * c, -3 * s, 3],
    ])
    np.testing.assert_allclose(got, want, atol=1e-12)
    # named points only, in the order given (the root always first)
    np.testing.assert_allclose(root_frame_points(m, names=["leg/end", "arm"])[3],
                               [0, 0, 0, 0, -3 * c, -3 * s, 1, 0, 0, 3], atol=1e-12)


def test_seam_is_the_last_step_over_the_median():
    import numpy as np

    from cyclecoord.quality.pose_space import _seam

    assert _seam(np.array([1.0, 2.0, 1.0, 3.0])) == 2.0  # median 1.5
    assert _seam(np.array([0.0, 0.0, 0.0])) == 1.0  # nothing moves: a clean loop
    assert _seam(np.array([0.0, 0.0, 0.0, 1.0])) == np.inf  # only the seam moves


def test_cycle_figures_of_five_frames_by_hand():
    """Heights 1, 1.01 ... 1.04 looped: four steps of 0.01 and a seam of 0.04 (loop
    closure 4); the loop's third differences (from 1.02, 1.03, 1.04 leading in) are
    -0.05, 0.1, -0.05, 0, 0: mean 0.04, times 30^3 = 1080 units/s^3.  In metres at 0.5 m
    a unit every length halves."""
    import numpy as np

    from cyclecoord.quality.pose_space import cycle_figures

    cyc = _root_only(1 + 0.01 * np.arange(5))
    f = cycle_figures(cyc, _unit_rig(cyc))
    assert f.loop_closure == pytest.approx(4.0)
    assert f.largest_step == pytest.approx(0.04) and f.median_step == pytest.approx(0.01)
    assert f.jerk == pytest.approx(1080.0) and f.metres_per_unit == 1.0
    h = cycle_figures(cyc, _unit_rig(cyc, 0.5))
    assert h.jerk == pytest.approx(540.0) and h.largest_step == pytest.approx(0.02)
    assert h.loop_closure == pytest.approx(4.0)
    assert f.to_dict() == {"loop_closure": pytest.approx(4.0), "jerk": pytest.approx(1080.0),
                           "largest_step": pytest.approx(0.04), "median_step": pytest.approx(0.01),
                           "metres_per_unit": 1.0}
    # fewer than 5 frames, or no skeleton: no figures
    assert cycle_figures(_root_only(1 + 0.01 * np.arange(4))) is None
    bare = cc.Motion(cyc.frames, cyc.channels, fps=30)
    assert cycle_figures(bare) is None


def test_pose_quality_of_a_cycle_cut_from_a_climb():
    """The one-point rig climbing 0.01 a frame, a cycle of frames 20-39: 19 steps of 0.01
    and a seam of 0.19 (back down to the start), so seam 19 and, against the capture's
    steps (all 0.01), pop 19; the cycle's poses are captured ones (nearest 0)."""
    import numpy as np

    m = _root_only(1 + 0.01 * np.arange(60))
    q = pose_quality(m.window((20, 40)), m, [(0, 60)], 20.0)
    assert q.seam == pytest.approx(19.0) and q.pop == pytest.approx(19.0)
    assert q.largest_step == pytest.approx(0.19) and q.p99_capture_step == pytest.approx(0.01)
    assert q.median_cycle_step == pytest.approx(0.01)
    assert q.nearest_max == 0.0 and q.nearest_median == 0.0 and q.spread == pytest.approx(0.1)
    assert q.pops and not q.seamless and not q.strays
    assert q.figures is not None and q.figures.loop_closure == pytest.approx(19.0)


def test_an_exactly_repeating_capture_has_the_median_step_as_spread():
    """A triangle wave of 0.01 a frame repeating every 20 frames exactly: every pose has a
    copy a period away (spread 0 on its own), so the spread is the capture's median
    step, 0.01.  A cycle pose raised to 1.2 is 0.1 above the highest captured pose (1.1):
    nearest_max 10, while the other poses are captured ones (median 0); the step up to it
    is 0.16, 16 capture steps (a pop); the loop itself closes evenly (seam 1)."""
    import numpy as np

    tri = 1 + 0.01 * np.abs(((np.arange(80) + 10) % 20) - 10)
    cyc = tri[:20].copy()
    cyc[5] = 1.2
    q = pose_quality(_root_only(cyc), _root_only(tri), [(0, 80)], 20.0)
    assert q.spread == pytest.approx(0.01)
    assert q.nearest_max == pytest.approx(10.0) and q.nearest_median == 0.0
    assert q.pop == pytest.approx(16.0) and q.seam == pytest.approx(1.0)
    assert q.strays and q.pops and not q.seamless


def test_capture_jerk_is_the_length_weighted_mean_over_runs():
    """Two runs of cubics, y = a t^3 (jerk 6 a exactly): 10 frames at a = 0.7 (4.2) and 30
    at a = 0.2 (1.2): the capture's jerk is (10 * 4.2 + 30 * 1.2) / 40 = 1.95, each run
    weighed by its frames; a run of 4 frames (no open 5-point stencil) does not count,
    however much it jerks.  The jerk ratio is the cycle's jerk over it."""
    import numpy as np

    from cyclecoord.quality.pose_space import cycle_figures

    fps = 30.0
    t10, t30 = np.arange(10) / fps, np.arange(30) / fps
    y = np.concatenate([1 + 0.7 * t10**3, 1 + 0.2 * t30**3, [1.0, 9.0, -9.0, 1.0]])
    cap = _root_only(y, fps=fps)
    cyc = _root_only(1 + 0.01 * np.arange(20), fps=fps)
    q = pose_quality(cyc, cap, [(0, 10), (10, 40), (40, 44)], 20.0)
    rig_m = cc.rig.describe_rig(cap).metres_per_unit
    assert q.capture_jerk == pytest.approx(1.95 * rig_m, rel=1e-6)
    want = cycle_figures(cyc, cc.rig.describe_rig(cap)).jerk / rig_m / 1.95
    assert q.jerk_ratio == pytest.approx(want, rel=1e-6)


def test_pose_quality_needs_a_skeleton_three_frames_and_a_run():
    import numpy as np

    m = _root_only(1 + 0.01 * np.arange(60))
    assert pose_quality(m.window((0, 2)), m, [(0, 60)], 20.0) is None
    q3 = pose_quality(m.window((0, 3)), m, [(0, 60)], 20.0)
    assert q3 is not None and q3.figures is None  # a cycle of 3 frames has no jerk figures
    assert pose_quality(m.window((0, 5)), m, [(0, 60)], 20.0).figures is not None
    bare = cc.Motion(m.frames, m.channels, fps=30)
    assert pose_quality(bare, m, [(0, 60)], 20.0) is None
    assert pose_quality(m, bare, [(0, 60)], 20.0) is None
    assert pose_quality(m.window((0, 20)), m, [(3, 4), (7, 8)], 20.0) is None  # no run of 2


def test_pose_quality_flags_at_their_limits():
    """pops: a pop over MAX_POP (2), not at it; seamless: a seam up to MAX_SEAM (1.5)
    and no pop; strays: nearest over 1; a NaN figure calls nothing."""
    import numpy as np

    from cyclecoord.quality.pose_space import MAX_POP, MAX_SEAM, PoseQuality

    assert MAX_POP == 2.0 and MAX_SEAM == 1.5

    def q(seam=1.0, pop=1.0, near=0.5):
        return PoseQuality(seam=seam, pop=pop, largest_step=1.0, p99_capture_step=1.0,
                           median_cycle_step=1.0, nearest_max=near, nearest_median=0.1,
                           spread=1.0, jerk_ratio=1.0)

    assert not q(pop=2.0).pops and q(pop=2.0001).pops and not q(pop=np.nan).pops
    assert q(seam=1.5).seamless and not q(seam=1.5001).seamless
    assert not q(pop=2.5).seamless and q(pop=np.nan).seamless
    assert not q(near=1.0).strays and q(near=1.0001).strays and not q(near=np.nan).strays
    d = q(pop=np.nan).to_dict()
    assert d["pop"] is None and d["seam"] == 1.0 and d["figures"] is None
    assert d["capture_jerk"] is None  # NaN by default


def test_long_takes_are_sampled_down_to_the_reference_frames(monkeypatch):
    """With MAX_REFERENCE_FRAMES 10: a run of 60 frames is read every 6th frame
    (ceil(60 / 10)), and its steps are those of its middle 10 frames (25-34)."""
    import numpy as np

    from cyclecoord.quality import pose_space as ps

    y = 1 + 0.001 * np.arange(60) ** 2  # steps 0.001 (2k + 1): each tells its frame
    m = _root_only(y)
    rig = _unit_rig(m)
    monkeypatch.setattr(ps, "MAX_REFERENCE_FRAMES", 10)
    (part,) = ps._runs_points(m, [(0, 60)], rig)
    np.testing.assert_allclose(part[:, -1], y[::6])
    np.testing.assert_allclose(ps._capture_steps(m, [(0, 60)], rig), np.diff(y[25:35]))
    parts = ps._runs_points(m, [(0, 35), (35, 59), (59, 60)], rig)  # 60 frames in all
    assert [len(p) for p in parts] == [6, 4]  # every 6th; the 1-frame run is left out
    # up to MAX_REFERENCE_FRAMES frames in all, every run is read whole
    monkeypatch.setattr(ps, "MAX_REFERENCE_FRAMES", 60)
    np.testing.assert_allclose(ps._capture_steps(m, [(0, 30), (30, 60)], rig),
                               np.r_[np.diff(y[:30]), np.diff(y[30:])])


def _turning_arm(n=120):
    """A root travelling 0.1 a frame along x (removed in its frame) at height 1, with an
    arm 1 along x whose end site, 1 further, turns 6 degrees a frame about z: a period of
    60 frames.  Three points (root, arm, end), so a pose step of angle a is the end's
    chord 2 sin(a / 2) over sqrt(3) (RMS over the points)."""
    import numpy as np

    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
                   Joint("arm", 0, [1.0, 0, 0], ("rz",), "Z", end_site=np.array([1.0, 0, 0]))))
    f = np.zeros((n, 7))
    f[:, 0] = 0.1 * np.arange(n)
    f[:, 1] = 1.0
    f[:, 6] = 6.0 * np.arange(n)
    return Motion(f, sk.channels, fps=30, skeleton=sk)


def test_distances_are_rms_over_the_points_of_a_turning_arm():
    """Known answers: steps of 2 sin(3 deg) / sqrt 3; the capture repeats exactly, so the
    spread is that step; a cycle pose turned 3 degrees more (half-way between two
    captured ones) is 2 sin(1.5 deg) / sqrt 3 from the nearest, sin 1.5 / sin 3 of the
    spread, and the steps either side of it are 9 and 3 degrees (pop sin 4.5 / sin 3)."""
    import numpy as np

    cap = _turning_arm()
    cyc = cap.window((0, 60))
    g = cyc.frames.copy()
    g[10, 6] += 3.0
    q = pose_quality(cyc.with_frames(g), cap, [(0, 120)], 60.0)
    step = 2 * np.sin(np.radians(3)) / np.sqrt(3)
    assert q.median_cycle_step == pytest.approx(step) and q.spread == pytest.approx(step)
    assert q.p99_capture_step == pytest.approx(step)
    s = np.sin(np.radians([1.5, 3.0, 4.5]))
    assert q.nearest_max == pytest.approx(s[0] / s[1]) and q.nearest_median == pytest.approx(0.0)
    assert q.largest_step == pytest.approx(2 * s[2] / np.sqrt(3))
    assert q.pop == pytest.approx(s[2] / s[1]) and q.seam == pytest.approx(1.0)


def test_steps_are_rms_over_the_points():
    """Two points and the root height per row (7 columns): a step moving each point by 3
    and 4 is sqrt((9 + 16) / 2); cyclic adds the last-to-first step; fewer than 3 columns
    count as one point."""
    import numpy as np

    from cyclecoord.quality.pose_space import _steps

    x = np.zeros((3, 7))
    x[1, 0], x[1, 4] = 3.0, 4.0
    x[2] = x[1]
    np.testing.assert_allclose(_steps(x), [np.sqrt(12.5), 0.0])
    np.testing.assert_allclose(_steps(x, cyclic=True), [np.sqrt(12.5), 0.0, np.sqrt(12.5)])
    np.testing.assert_allclose(_steps(np.array([[0.0], [2.0]])), [2.0])


def test_a_point_within_a_billionth_of_the_skeletons_size_sits_on_its_parent():
    """Bones of 100: a twist 5e-8 from its parent (under 1e-9 of 100) is the parent's
    place again and left out; one 1.5e-7 away is a point of its own; the root is always
    kept, and the names given may include it (it is not repeated)."""
    import numpy as np

    from cyclecoord.motion import Motion
    from cyclecoord.quality.pose_space import _distinct_points, root_frame_points
    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
                   Joint("a", 0, [100.0, 0, 0]),
                   Joint("near", 1, [0, 5e-8, 0]),
                   Joint("apart", 1, [0, 1.5e-7, 0])))
    m = Motion(np.zeros((2, 6)), sk.channels, fps=30, skeleton=sk)
    assert _distinct_points(sk, ["root", "a", "near", "apart"]) == [0, 1, 3]
    f = np.zeros((2, 6))
    f[:, 0] = [0.0, 1.0]
    m = m.with_frames(f)
    assert root_frame_points(m, names=["root", "a"]).shape == (2, 7)


def test_pose_quality_on_another_layout_of_the_same_body():
    """A cycle whose skeleton has one more point than the capture's is compared on the
    points both have (here exactly three: the root, the arm and its end site): a copy of
    captured frames is at distance 0.  With fewer than three shared points there is
    nothing to compare."""
    import numpy as np

    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    root = Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX")
    arm = Joint("arm", 0, [1.0, 0, 0], ("rz",), "Z", end_site=np.array([1.0, 0, 0]))
    cap_sk = Skeleton((root, arm))
    cyc_sk = Skeleton((root, arm, Joint("c", 0, [0, 1.0, 0])))
    cap = _turning_arm()
    assert cap.channels == cap_sk.channels == cyc_sk.channels
    cyc = Motion(cap.frames[30:90], cyc_sk.channels, fps=30, skeleton=cyc_sk)
    q = pose_quality(cyc, cap, [(0, 120)], 60.0)
    assert q is not None and q.nearest_max == pytest.approx(0.0, abs=1e-9)
    assert q.seam == pytest.approx(1.0)
    # a cycle sharing only the root and the arm (no end site) with the capture: None
    lone_sk = Skeleton((root, Joint("arm", 0, [1.0, 0, 0], ("rz",), "Z"),
                        Joint("d", 0, [0, 0, 1.0])))
    lone = Motion(cap.frames[:60], lone_sk.channels, fps=30, skeleton=lone_sk)
    assert pose_quality(lone, cap, [(0, 120)], 60.0) is None


def test_p99_capture_step_and_a_still_capture():
    """99 steps of 1/64 and one of 1: the 99th percentile (linear) is at 98.01 of the
    sorted steps, 1/64 + 0.01 (1 - 1/64).  A capture that never moves has no step to
    compare a pop with (NaN) and no jerk (the ratio is NaN, not a division by 0)."""
    import numpy as np

    y = 1 + np.arange(101) / 64
    y[60:] += 1.0 - 1 / 64
    q = pose_quality(_root_only(y).window((0, 20)), _root_only(y), [(0, 101)], 20.0)
    assert q.p99_capture_step == pytest.approx(1 / 64 + 0.01 * (1 - 1 / 64))
    still = _root_only(np.ones(60))
    q = pose_quality(_root_only(1 + np.arange(20) / 64), still, [(0, 60)], 20.0)
    assert np.isnan(q.pop) and np.isnan(q.jerk_ratio) and q.capture_jerk == 0.0
    # a capture moving at an even pace (exact in binary) has no jerk either
    even = _root_only(1 + np.arange(60) / 64)
    assert np.isnan(pose_quality(even.window((0, 20)), even, [(0, 60)], 20.0).jerk_ratio)


def test_spread_is_the_90th_percentile_of_the_nearest_pose_half_a_period_away():
    """A climb at an uneven pace (steps growing with the frame): each frame's nearest pose
    at least half a period away (10 frames for a period of 20, 1 for a period of 2) is
    the nearer of the two poses exactly that far, found here by a loop."""
    import numpy as np

    y = 1 + 0.001 * np.arange(60) ** 1.5
    m = _root_only(y)
    for period, half in ((20.0, 10), (2.0, 1)):
        best = []
        for k in range(60):
            d = [abs(y[j] - y[k]) for j in range(60) if abs(j - k) >= half]
            best.append(min(d))
        q = pose_quality(m.window((20, 40)), m, [(0, 60)], period)
        want = max(np.percentile(best, 90), np.median(np.diff(y)))
        assert q.spread == pytest.approx(want, rel=1e-9)


def test_the_reference_frames_limit_is_inclusive():
    """MAX_REFERENCE_FRAMES (20 000) frames are read whole (two runs of 10 000 give every
    step of both, 2 x 9 999); one more frame, and every other frame is read."""
    import numpy as np

    from cyclecoord.quality import pose_space as ps

    assert ps.MAX_REFERENCE_FRAMES == 20_000
    m = _root_only(1 + np.arange(20_001) / 64)
    rig = _unit_rig(m)
    assert len(ps._runs_points(m, [(0, 20_001)], rig)[0]) == 10_001
    assert ps._capture_steps(m, [(0, 10_000), (10_000, 20_000)], rig).size == 19_998


def test_a_long_takes_steps_come_from_its_longest_run(monkeypatch):
    """With MAX_REFERENCE_FRAMES 10: the middle 10 frames of the longest run, whichever
    comes first, clipped to the run when it is shorter."""
    import numpy as np

    from cyclecoord.quality import pose_space as ps

    y = 1 + 0.001 * np.arange(60) ** 2
    m = _root_only(y)
    rig = _unit_rig(m)
    monkeypatch.setattr(ps, "MAX_REFERENCE_FRAMES", 10)
    np.testing.assert_allclose(ps._capture_steps(m, [(0, 35), (35, 60)], rig), np.diff(y[12:22]))
    np.testing.assert_allclose(ps._capture_steps(m, [(0, 25), (25, 60)], rig), np.diff(y[37:47]))
    np.testing.assert_allclose(ps._capture_steps(m, [(0, 8), (10, 16)], rig), np.diff(y[0:8]))


def test_results_are_frozen():
    import dataclasses

    import numpy as np

    from cyclecoord.quality.pose_space import cycle_figures

    cyc = _root_only(1 + 0.01 * np.arange(5))
    f = cycle_figures(cyc, _unit_rig(cyc))
    with pytest.raises(dataclasses.FrozenInstanceError):
        f.jerk = 0.0
    q = pose_quality(cyc, cyc, [(0, 5)], 5.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        q.seam = 0.0
    nan = dataclasses.replace(f, jerk=float("nan")).to_dict()
    assert nan["jerk"] is None and nan["loop_closure"] == pytest.approx(4.0)


def test_pose_quality_to_dict_carries_the_cycles_figures():
    import numpy as np

    m = _root_only(1 + 0.01 * np.arange(60))
    q = pose_quality(m.window((20, 40)), m, [(0, 60)], 20.0)
    d = q.to_dict()
    assert d["figures"] == q.figures.to_dict() and d["figures"]["loop_closure"] == pytest.approx(19.0)
    assert d["seam"] == pytest.approx(19.0) and d["spread"] == pytest.approx(0.1)
    assert set(d) == {"seam", "pop", "largest_step", "p99_capture_step", "median_cycle_step",
                      "nearest_max", "nearest_median", "spread", "jerk_ratio", "capture_jerk",
                      "figures"}
