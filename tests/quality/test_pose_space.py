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
