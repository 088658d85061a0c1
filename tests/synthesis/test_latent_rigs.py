"""Latent models on rigs whose Euler channels wrap or sit near gimbal lock (the Bandai
rig's thighs at +-180 and its spine at 88 degrees of the middle angle): such a joint is
modelled about its mean rotation (``LatentModel.chart``) and written back as continuous
channels of the same rotations; a rig without such a joint is modelled as written."""

from __future__ import annotations

import numpy as np
import pytest
from _rigs import walk
from scipy.spatial.transform import Rotation

from cyclecoord.synthesis.latent import LatentModel, Synthesizer

JOINT = "lowerback"


def _turned(m, turn: Rotation):
    """The walk with ``JOINT``'s rotation premultiplied by ``turn`` (ZXY channels)."""
    cols = [m.channel_index(JOINT, d) for d in ("rz", "rx", "ry")]
    frames = np.array(m.frames)
    R = turn * Rotation.from_euler("ZXY", frames[:, cols], degrees=True)
    frames[:, cols] = R.as_euler("ZXY", degrees=True)
    return m.with_frames(frames), cols


def _rotations(frames, cols):
    return Rotation.from_euler("ZXY", frames[:, cols], degrees=True).as_matrix()


@pytest.fixture(scope="module")
def gimbal():
    # the middle angle (x of ZXY) about 88 degrees: y and z swing by tens of degrees
    # from frame to frame while the rotation hardly moves
    m, cols = _turned(walk()[::2], Rotation.from_euler("x", 88, degrees=True))
    assert np.abs(np.diff(m.frames[:, cols], axis=0)).max() > 45
    model = LatentModel(gplvm={"max_iter": 30}, random_state=0).fit([m], ["a"], gait=False)
    return m, cols, model


def test_a_joint_near_gimbal_lock_is_charted_about_its_mean(gimbal):
    m, cols, model = gimbal
    chart = model.chart()
    assert len(chart) == 1
    idx, order, mean = chart[0]
    assert order == "ZXY" and [model.channels_[k] for k in idx] == [
        (JOINT, "rz"), (JOINT, "rx"), (JOINT, "ry")
    ]
    # the mean is the rotations' own mean (SciPy's, an independent computation)
    R = Rotation.from_euler("ZXY", m.frames[:, cols], degrees=True)
    np.testing.assert_allclose(mean, R.mean().as_matrix(), atol=1e-12)
    # in the chart the joint moves smoothly and stays near the identity
    a = model.angles(m.frames)[:, idx]
    assert np.abs(np.diff(a, axis=0)).max() < 10 and np.abs(a).max() < 45
    # and back: the same rotations (written as Euler channels they swing again: at
    # gimbal lock no Euler triple can follow the rotation smoothly)
    back = model.to_channels(model.angles(m.frames), continuous=True)
    np.testing.assert_allclose(_rotations(back, idx), R.as_matrix(), atol=1e-9)
    # every other channel is modelled as written
    others = [k for k in range(len(model.channels_)) if k not in set(idx)]
    plain = model.angles(m.frames)[:, others]
    col = [m.channel_index(*model.channels_[k]) for k in others]
    np.testing.assert_array_equal(plain, m.frames[:, col])


def test_a_rig_without_such_joints_is_modelled_bit_for_bit():
    m = walk()[::2]
    model = LatentModel(gplvm={"max_iter": 5}, random_state=0).fit([m], ["a"], gait=False)
    assert model.chart() == ()
    cols = [m.channel_index(*c) for c in model.channels_]
    np.testing.assert_array_equal(model.angles(m.frames), m.frames[:, cols])
    np.testing.assert_array_equal(model.to_channels(model.angles(m.frames)), m.frames[:, cols])


def test_a_wrapping_channel_is_centred_on_its_branch():
    # a hinge-like channel near 180 that wraps: the model sees it continuous about 180
    m = walk()[::2]
    k = m.channel_index("lfemur", "ry")
    frames = np.array(m.frames)
    frames[:, k] = 180.0 + 10.0 * np.sin(np.arange(m.n_frames) / 5.0)
    frames[:, k] = (frames[:, k] + 180.0) % 360.0 - 180.0  # written in [-180, 180)
    m = m.with_frames(frames)
    model = LatentModel(gplvm={"max_iter": 5}, random_state=0).fit([m], ["a"], gait=False)
    j = model.channels_.index(("lfemur", "ry"))
    assert model.angle_centres()[j] == 180.0
    got = model.angles(m.frames)[:, j]
    np.testing.assert_allclose(got, 180.0 + 10.0 * np.sin(np.arange(m.n_frames) / 5.0))


def test_a_bandai_walk_chain_keeps_its_feet_and_its_spine():
    """The Bandai walk's spine sits at 88 degrees of its middle Euler angle. Modelled as
    written, ten MOVEs ahead accelerated the joints 5.41x the capture's 99th percentile
    and the support foot slid 0.42 m/s; charted about its mean, 1.47x and 0.00 m/s
    (measured at the commit that charted it; limits 1.3x those)."""
    from _rigs import bandai

    from cyclecoord.quality.generated import measure_generated

    m = bandai(2)  # dataset-1_walk_normal_001
    model = LatentModel(gplvm={"max_iter": 100}, random_state=0).fit([m], ["walk"])
    assert [model.channels_[idx[0]][0] for idx, _, _ in model.chart()] == ["Spine"]
    syn = Synthesizer({"walk": model}, fps=30, seed=0)
    syn.start("walk", {"frame": 0})
    for _ in range(10):
        syn.command += 1
        syn.move({"ahead": 0.3}, stop=False)
    out = syn.motion()
    assert out.channels == model.training_motion().channels
    q = measure_generated(out, [m])
    assert q.largest_accel <= 1.9
    assert q.support_slip <= 0.05
    assert min(q.knee_ratio) >= 0.9
