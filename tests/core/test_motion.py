"""The motion object and forward kinematics."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import cyclecoord as cc
from cyclecoord.skeleton import Joint, Skeleton, rotation_matrices, forward_kinematics


def two_joint():
    return Skeleton((
        Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
        Joint("arm", 0, [0, 1, 0], ("rx", "rz"), "ZX", end_site=[1, 0, 0]),
    ))


@pytest.mark.parametrize("order", ["ZXY", "ZYX", "XYZ", "YXZ", "X", "ZY"])
def test_rotation_matrices_match_scipy_intrinsic(order):
    v = np.random.default_rng(1).uniform(-180, 180, (200, len(order)))
    np.testing.assert_allclose(
        rotation_matrices(v, order), Rotation.from_euler(order, v, degrees=True).as_matrix(), atol=1e-12
    )


def test_forward_kinematics_by_hand():
    sk = two_joint()
    m = cc.Motion(np.array([[1, 2, 3, 0, 0, 90, 0, 0], [0, 0, 0, 0, 0, 0, 90, 0]]), sk.channels, skeleton=sk)
    p = forward_kinematics(m)
    assert p.names == ["root", "arm", "arm/end"]
    np.testing.assert_allclose(p.positions[0], [[1, 2, 3], [0, 2, 3], [0, 3, 3]], atol=1e-12)
    np.testing.assert_allclose(p.positions[1], [[0, 0, 0], [0, 1, 0], [1, 1, 0]], atol=1e-12)
    np.testing.assert_allclose(p["arm/end"], p.positions[:, 2])


def test_slicing_keeps_everything_else():
    cap = cc.datasets.example_capture()
    m = cap.motion
    part = m[200:450]
    assert part.n_frames == 250 and part.start_frame == 200
    assert part.channels == m.channels and part.skeleton is m.skeleton and part.fps == m.fps
    np.testing.assert_array_equal(part.frames, m.frames[200:450])
    assert m[::2].fps == m.fps / 2
    assert m[5].n_frames == 1 and m[-1].start_frame == m.n_frames - 1
    with pytest.raises(IndexError):
        m[10_000]


def test_select_and_concatenate():
    m = cc.datasets.example_capture().motion
    arm = m.select(["rhumerus", "root.tz"])
    assert arm.channels == (("rhumerus", "rx"), ("rhumerus", "ry"), ("rhumerus", "rz"), ("root", "tz"))
    both = cc.Motion.concatenate([m[:100], m[100:]])
    np.testing.assert_array_equal(both.frames, m.frames)
    with pytest.raises(cc.ParameterError, match="channels"):
        cc.Motion.concatenate([m, arm])
    with pytest.raises(KeyError):
        m.select(["nosuchjoint"])


def test_inputs_are_not_frozen_or_modified():
    f = np.zeros((5, 8))
    m = cc.Motion(f, two_joint().channels)
    assert f.flags.writeable
    f[0, 0] = 7.0
    assert m.frames[0, 0] == 0.0  # the motion owns a copy
    with pytest.raises(ValueError):
        m.frames[0, 0] = 1.0  # and it is read-only


def test_bad_motions():
    with pytest.raises(cc.ParameterError, match="channel names"):
        cc.Motion(np.zeros((3, 4)), [("a", "rx")])
    with pytest.raises(cc.ParameterError, match="duplicate"):
        cc.Motion(np.zeros((3, 2)), [("a", "rx"), ("a", "rx")])
    with pytest.raises(cc.ParameterError, match="fps"):
        cc.Motion(np.zeros((3, 1)), [("a", "rx")], fps=0)
    with pytest.raises(cc.ParameterError, match="skeleton"):
        cc.Motion(np.zeros((3, 1)), [("a", "rx")]).positions()


def test_skeleton_does_not_import_motion():
    """Issue 25: motion and skeleton imported each other (skeleton for its type hints);
    the dependency now goes one way, from the capture to its skeleton."""
    import ast
    from pathlib import Path

    import cyclecoord.skeleton as skeleton_module

    tree = ast.parse(Path(skeleton_module.__file__).read_text())
    imported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            imported.add(("." * node.level) + (node.module or ""))
        elif isinstance(node, ast.Import):
            imported.update(a.name for a in node.names)
    assert not {".motion", "cyclecoord.motion"} & imported, imported
    m = cc.datasets.example_capture().motion
    assert m.positions().positions.shape[0] == m.n_frames  # Motion.positions still works


def test_positions_are_made_once_and_kept_read_only(monkeypatch):
    sk = two_joint()
    frames = np.random.default_rng(0).uniform(-90, 90, (50, 8))
    m = cc.Motion(frames, sk.channels, skeleton=sk)
    p = m.positions()
    assert m.positions() is p  # kept: the frames and skeleton never change
    np.testing.assert_array_equal(p.positions, forward_kinematics(m).positions)
    with pytest.raises(ValueError, match="read-only"):
        p.positions[0, 0, 0] = 1.0  # a caller changing them would change every later call's
    other = m.with_frames(frames[::-1].copy())
    np.testing.assert_array_equal(other.positions().positions, p.positions[::-1])
    # a motion over the limit has its positions made on each call (memory)
    monkeypatch.setattr(cc.motion, "FK_KEPT_VALUES", 50 * 3 * 3 - 1)
    big = cc.Motion(frames, sk.channels, skeleton=sk)
    a, b = big.positions(), big.positions()
    assert a is not b and a.positions.flags.writeable
    np.testing.assert_array_equal(a.positions, b.positions)


def test_derived_values_are_found_once_per_key_and_kept_read_only():
    """Legs and foot contacts are found once per motion and settings (a latent script
    measured its training takes' twice); a caller cannot change the kept arrays."""
    from cyclecoord.quality.contacts import foot_contacts
    from cyclecoord.quality.legs import find_legs

    m = cc.datasets.example_capture().motion[:90]
    calls = []
    assert m.derived("k", lambda: calls.append(1) or 5) == 5
    assert m.derived("k", lambda: calls.append(1) or 6) == 5 and len(calls) == 1
    legs = find_legs(m.skeleton, m)
    assert find_legs(m.skeleton, m) is legs
    c = foot_contacts(m)
    assert foot_contacts(m, legs.feet) is c  # the same feet given by name: the same contacts
    d = foot_contacts(m, speed=None)
    assert d is not c and d.planted.sum() >= c.planted.sum()  # other settings: found anew
    with pytest.raises(ValueError, match="read-only"):
        c.planted[0, 0] = not c.planted[0, 0]
    # a copy with other frames has its own
    other = m.with_frames(m.frames[::-1].copy())
    assert foot_contacts(other) is not c


def test_derived_motions_positions_equal_forward_kinematics_bit_for_bit():
    """Slices and copies with a few frames changed take their unchanged frames' positions
    from the motion they came from: the same bits as forward kinematics on all frames."""
    m = cc.datasets.example_capture().motion[:120]
    m.positions()
    rng = np.random.default_rng(3)
    for key in (slice(10, 70), slice(0, 120, 3), np.array([5, 9, 40, 41]), slice(7, 8)):
        sub = m[key]
        assert sub.n_frames == m.frames[key].shape[0]
        np.testing.assert_array_equal(sub.positions().positions, forward_kinematics(sub).positions)
    for changed in (0, 1, 2, 17, 100):
        frames = m.frames.copy()
        rows = rng.choice(m.n_frames, size=changed, replace=False)
        frames[rows, 3:] += rng.normal(0.0, 20.0, (changed, frames.shape[1] - 3))
        child = m.with_frames(frames)
        got = child.positions().positions
        np.testing.assert_array_equal(got, forward_kinematics(child).positions)
        if changed:
            assert not np.array_equal(got[rows], m.positions().positions[rows])
    # the frames are taken as they were when the positions were made: a caller that then
    # changes the parent's array in place does not change the child's positions
    frames = m.frames.copy()
    parent = m.with_frames(frames)
    parent.positions()
    frames[3, 5] += 30.0
    child = parent.with_frames(frames.copy())
    np.testing.assert_array_equal(child.positions().positions, forward_kinematics(child).positions)
