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
