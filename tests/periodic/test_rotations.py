"""Joint rotations as rotations: wraps and Euler flips change nothing in the analysis."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import cyclecoord as cc
from cyclecoord.datasets import example_capture
from cyclecoord.periodic.preprocess import Preprocessor
from cyclecoord.periodic.rotations import RotationMap, euler_is_safe, fit_rotation_map


def three_dof_joints(m):
    out = []
    for j in m.skeleton.joints[1:]:
        if len(j.rotation_order) == 3:
            out.append((j.name, [m.channel_index(j.name, "r" + a.lower()) for a in j.rotation_order]))
    return out


def scrambled(m, seed=0):
    """The same rotations written as wrapping, branch-flipping Euler numbers."""
    rng = np.random.default_rng(seed)
    f = m.frames.copy()
    for _, cols in three_dof_joints(m):
        a = f[:, cols]
        flip = rng.random(len(f)) < 0.5
        alt = a + np.array([180.0, 0.0, 180.0])
        alt[:, 1] = 180.0 - a[:, 1]
        a = np.where(flip[:, None], alt, a)
        a = a + 360.0 * rng.integers(-2, 3, size=a.shape)
        f[:, cols] = a
    return m.with_frames(f)


def test_scrambled_euler_is_the_same_motion():
    m = example_capture().motion
    s = scrambled(m)
    np.testing.assert_allclose(s.positions().positions, m.positions().positions, atol=1e-8)
    assert not euler_is_safe(s.frames[:, three_dof_joints(m)[0][1]])
    assert euler_is_safe(m.frames[:, three_dof_joints(m)[0][1]])


@pytest.mark.parametrize("mode", ["auto", "rotvec"])
def test_vectors_ignore_wraps_and_flips(mode):
    m = example_capture().motion
    s = scrambled(m)
    root = np.asarray(m.root_channels())
    a = Preprocessor(rotations=mode).fit_transform(m).poses
    b = Preprocessor(rotations="rotvec").fit_transform(s).poses
    if mode == "rotvec":
        np.testing.assert_allclose(a, b, atol=1e-6)
    # the scrambled capture's steps are the clean one's (no 360 or 180 jumps)
    joints = np.setdiff1d(np.arange(m.n_channels), root)
    step_b = np.abs(np.diff(b[:, joints], axis=0)).max()
    step_m = np.abs(np.diff(m.frames[:, joints], axis=0)).max()
    assert step_b < 1.5 * step_m
    # the raw Euler numbers jump by hundreds of degrees
    assert np.abs(np.diff(s.frames[:, joints], axis=0)).max() > 100


def test_round_trip_is_continuous_and_exact():
    m = scrambled(example_capture().motion)
    rmap = fit_rotation_map(m, exclude=np.asarray(m.root_channels()))
    back = rmap.to_channels(rmap.to_vectors(m.frames), near=example_capture().motion.frames[0])
    # the same rotations ...
    np.testing.assert_allclose(m.with_frames(back).positions().positions,
                               m.positions().positions, atol=1e-6)
    # ... written continuously: no frame-to-frame jump of a wrap or flip
    assert np.abs(np.diff(back, axis=0))[:, rmap.columns].max() < 20


def test_map_survives_its_arrays():
    m = example_capture().motion
    rmap = fit_rotation_map(m, exclude=np.asarray(m.root_channels()))
    again = RotationMap.from_arrays(rmap.to_arrays(), m.n_channels)
    np.testing.assert_allclose(again.to_vectors(m.frames), rmap.to_vectors(m.frames))
    bad = rmap.to_arrays()
    bad["group_means"] = bad["group_means"] * 2
    with pytest.raises(ValueError, match="unit"):
        RotationMap.from_arrays(bad, m.n_channels)


def test_extract_reads_a_scrambled_capture_as_the_clean_one(tmp_path):
    """The period, the barcode and the written cycle do not depend on how the capture's
    Euler numbers wrap; with the paper's Euler space the same capture is another point cloud."""
    m = example_capture().motion
    s = scrambled(m)
    a = cc.extract(m, rotations="rotvec")
    b = cc.extract(s)  # default: the scrambled joints are found unsafe and read as rotations
    assert b.period_frames == pytest.approx(a.period_frames, rel=1e-3)
    assert b.selection.birth == pytest.approx(a.selection.birth, rel=1e-3)
    pa = a.cycle.positions().positions
    pb = b.cycle.positions().positions
    np.testing.assert_allclose(pb, pa, atol=1e-3 * np.ptp(pa))
    # the written cycle's Euler channels are continuous
    joints = np.setdiff1d(np.arange(s.n_channels), np.asarray(s.root_channels()))
    assert np.abs(np.diff(b.cycle.frames[:, joints], axis=0)).max() < 20
    pe = Preprocessor(rotations="euler").fit_transform(s).points
    assert np.ptp(pe) > 5 * np.ptp(Preprocessor().fit_transform(s).points)


def test_euler_option_is_the_paper_space():
    m = example_capture().motion
    p = Preprocessor(rotations="euler").fit_transform(m)
    joints = np.setdiff1d(np.arange(m.n_channels), np.asarray(m.root_channels()))
    np.testing.assert_array_equal(p.poses[:, joints], m.frames[:, joints])
    with pytest.raises(cc.errors.ParameterError, match="rotations"):
        Preprocessor(rotations="quat").fit(m)


def test_rotation_vector_is_the_angle_from_the_mean():
    """A single joint turning by a known angle about a fixed axis reads that angle."""
    m = example_capture().motion
    name, cols = three_dof_joints(m)[0]
    order = m.skeleton.joints[[j.name for j in m.skeleton.joints].index(name)].rotation_order
    ang = np.linspace(-40, 40, m.n_frames)
    f = m.frames.copy()
    f[:, cols] = Rotation.from_rotvec(np.outer(np.radians(ang), [0.6, 0.8, 0.0])).as_euler(
        order, degrees=True)
    rmap = fit_rotation_map(m.with_frames(f), exclude=np.asarray(m.root_channels()))
    v = rmap.to_vectors(f)[:, cols]
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), np.abs(ang), atol=1e-6)


def test_hinge_angles_move_by_whole_turns_into_half_a_turn_of_their_centre():
    """Centre 10: every angle lands in [-170, 190) by whole turns; one there stays exact."""
    rmap = RotationMap(groups=(), hinge_columns=np.array([0]), hinge_centres=np.array([10.0]))
    x = np.array([10.0, 189.5, 191.0, -171.0, 550.0, -700.0, 0.1])
    out = rmap.to_vectors(np.column_stack([x, x]))
    np.testing.assert_array_equal(out[:, 0], [10.0, 189.5, -169.0, 189.0, -170.0, 20.0, 0.1])
    np.testing.assert_array_equal(out[:, 1], x)  # not a hinge column: copied


def test_without_a_skeleton_every_rotation_channel_is_a_hinge():
    """fit_rotation_map's documentation: without a skeleton (no Euler orders) every
    rotation channel is a hinge; with it each three-channel joint is a rotation and the
    others hinges.  Excluded columns (the root) and position channels are neither."""
    import dataclasses

    m = example_capture().motion
    root = np.asarray(m.root_channels())
    rot = [i for i, (j, d) in enumerate(m.channels) if d in ("rx", "ry", "rz") and i not in root]
    bare = fit_rotation_map(dataclasses.replace(m, skeleton=None), exclude=root)
    assert bare.groups == ()
    np.testing.assert_array_equal(bare.hinge_columns, rot)
    full = fit_rotation_map(m, exclude=root)
    grouped = sorted(int(c) for g in full.groups for c in g.columns)
    assert sorted(c for _, cols in three_dof_joints(m) for c in cols) == grouped
    assert sorted(grouped + full.hinge_columns.tolist()) == rot
    assert all(len(g.columns) == 3 and sorted(g.order) == ["X", "Y", "Z"] for g in full.groups)
