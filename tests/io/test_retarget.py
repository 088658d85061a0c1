"""Takes of one rig by actors of other proportions put on one skeleton (cyclecoord.rig.retarget)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.rig import onto_skeleton, proportions_differ, same_rig


def _walk(seed: int = 0) -> cc.Motion:
    return cc.datasets.make_periodic_capture(kind="walk", n_frames=200, random_state=seed).motion


def _scaled(m: cc.Motion, s: float) -> cc.Motion:
    """The same take by an actor ``s`` times as tall: every bone and the travel scaled."""
    joints = tuple(
        replace(j, offset=np.asarray(j.offset) * s,
                end_site=None if j.end_site is None else np.asarray(j.end_site) * s)
        for j in m.skeleton.joints
    )
    frames = np.array(m.frames)
    for i, (_, d) in enumerate(m.channels):
        if d.startswith("t"):
            frames[:, i] *= s
    return cc.Motion(frames, m.channels, m.fps, replace(m.skeleton, joints=joints), "tall.bvh")


def test_a_taller_actors_take_comes_back_exactly():
    """Rotations kept, travel divided by the legs' ratio: the taller actor's take put on
    the first skeleton is the first take again, joint positions included."""
    m = _walk()
    tall = _scaled(m, 1.25)
    assert same_rig(m.skeleton, tall.skeleton) == ""
    assert proportions_differ(m.skeleton, tall.skeleton)
    back, p = onto_skeleton(tall, m)
    assert p.scale == pytest.approx(0.8) and p.legs == pytest.approx(1.25)
    assert back.skeleton is m.skeleton
    np.testing.assert_allclose(back.frames, m.frames, atol=1e-9)
    np.testing.assert_allclose(back.positions().positions, m.positions().positions, atol=1e-9)
    assert "legs 1.25x" in p.describe("tall.bvh", "walk.bvh")


def test_constant_position_channels_take_the_targets_values():
    """A rig storing a bone's offset as a constant channel: the target's value, not the
    source's scaled."""
    m = _walk()
    j = next(k for k, jt in enumerate(m.skeleton.joints) if k > 0 and jt.dofs)
    name = m.skeleton.joints[j].name
    joints = list(m.skeleton.joints)
    joints[j] = replace(joints[j], dofs=("tx", "ty", "tz") + joints[j].dofs)
    skel = replace(m.skeleton, joints=tuple(joints))
    chans = skel.channels
    off = np.asarray(m.skeleton.joints[j].offset)

    def with_offset(motion, value, skeleton):
        f = np.zeros((motion.n_frames, len(chans)))
        for c, ch in enumerate(chans):
            if ch[0] == name and ch[1].startswith("t"):
                f[:, c] = value["xyz".index(ch[1][1])]
            else:
                f[:, c] = motion.frames[:, motion.channels.index(ch)]
        return cc.Motion(f, chans, motion.fps, skeleton)

    a = with_offset(m, off, skel)
    tall = _scaled(m, 1.25)
    tall_joints = list(tall.skeleton.joints)
    tall_joints[j] = replace(tall_joints[j], dofs=joints[j].dofs)
    b = with_offset(tall, off * 1.25, replace(tall.skeleton, joints=tuple(tall_joints)))
    out, _ = onto_skeleton(b, a)
    cols = [c for c, ch in enumerate(chans) if ch[0] == name and ch[1].startswith("t")]
    np.testing.assert_allclose(out.frames[:, cols], a.frames[:, cols], atol=1e-9)


def test_another_rig_is_refused():
    m = _walk()
    joints = list(m.skeleton.joints)
    k = next(i for i, j in enumerate(joints) if i > 0 and j.dofs)
    joints[k] = replace(joints[k], axis=np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]]))
    other = cc.Motion(m.frames, m.channels, m.fps, replace(m.skeleton, joints=tuple(joints)))
    assert same_rig(m.skeleton, other.skeleton) == "other joint axes"
    with pytest.raises(cc.CycleCoordError, match="other joint axes"):
        onto_skeleton(other, m)
    joints[k] = replace(joints[k], name="elsewhere")
    renamed = replace(m.skeleton, joints=tuple(joints))
    assert same_rig(m.skeleton, renamed) == "other joints"
