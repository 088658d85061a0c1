"""The root of a loop: decomposition into tilt, height, heading and ground steps (periodic.root)."""

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.periodic.root import compose_root, decompose_root, heading, root_layout


@pytest.fixture(scope="module")
def walk():
    return cc.datasets.make_periodic_capture(n_frames=480, period=120.0, noise=0.5, random_state=0).motion


def test_decompose_then_compose_gives_the_root_back(walk):
    layout = root_layout(walk)
    x = decompose_root(walk.frames, layout)
    h = heading(walk.frames, layout)
    ground = walk.frames[0, [layout.column("tx"), layout.column("tz")]]
    back = compose_root(x, layout, h[0], tuple(ground))
    np.testing.assert_allclose(back[:-1], walk.frames[:-1][:, layout.columns], atol=1e-9)


def test_straight_and_in_place(walk):
    layout = root_layout(walk)
    x = decompose_root(walk.frames, layout)
    x[:, 4] = 0.5  # turn half a degree every frame
    turned = compose_root(x, layout, 0.0, (0.0, 0.0))
    straight = compose_root(x, layout, 0.0, (0.0, 0.0), travel="straight")
    still = compose_root(x, layout, 0.0, (0.0, 0.0), travel="in_place")
    f = np.zeros((len(x), walk.n_channels))
    for out, turn in ((turned, 0.5 * (len(x) - 1)), (straight, 0.0)):
        f[:, layout.columns] = out
        hd = heading(f, layout)
        assert hd[-1] - hd[0] == pytest.approx(turn, abs=1e-6)
    assert np.ptp(still[:, layout.dofs.index("tx")]) == 0 and np.ptp(still[:, layout.dofs.index("tz")]) == 0
    # tilt and height are untouched by the travel choice
    np.testing.assert_allclose(still[:, layout.dofs.index("ty")], x[:, 0])


def test_no_layout_without_a_skeleton(walk):
    bare = cc.Motion(frames=walk.frames, channels=walk.channels, fps=walk.fps)
    assert root_layout(bare) is None


def _striding(turn_per_frame=0.0):
    """The left leg sweeps back under a root that stays put (and may turn)."""
    from tests._legs import legs_skeleton, make_motion

    skel = legs_skeleton()
    m = make_motion(skel, T=40)
    f = m.frames.copy()
    col = {c: i for i, c in enumerate(m.channels)}
    f[:, col[("lfemur", "rx")]] = np.linspace(-25.0, 25.0, len(f))
    f[:, col[("rfemur", "rx")]] = np.linspace(25.0, -25.0, len(f))
    f[:, col[("root", "ry")]] = turn_per_frame * np.arange(len(f))
    return m.with_frames(f)


@pytest.mark.parametrize("turn", [0.0, 1.5])
def test_planted_ground_keeps_the_planted_foot_still(turn):
    from cyclecoord.periodic.root import planted_ground

    clip = _striding(turn)
    layout = root_layout(clip)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    pos = clip.positions()
    before = 0.5 * (pos["lfoot"] + pos["ltoes"])[:, [0, 2]]  # the planted points' mean
    assert np.ptp(before, axis=0).max() > 3.0  # the foot slides under a root that stays put
    weights = np.tile([1.0, 1.0, 0.0, 0.0], (clip.n_frames, 1))
    ground = planted_ground(clip, layout, feet, weights)
    f = clip.frames.copy()
    f[:, [layout.column("tx"), layout.column("tz")]] = ground
    after = clip.with_frames(f).positions()
    held = 0.5 * (after["lfoot"] + after["ltoes"])[:, [0, 2]]
    np.testing.assert_allclose(held, np.tile(before[0], (clip.n_frames, 1)), atol=1e-9)
    # the root moved instead, by the stride, while the swinging foot travels twice as far
    assert np.ptp(after["root"][:, 2]) > 3.0
    np.testing.assert_allclose(ground[0], clip.frames[0, [layout.column("tx"), layout.column("tz")]])


def test_planted_ground_without_contacts_keeps_the_clips_own_steps():
    from cyclecoord.periodic.root import planted_ground

    clip = _striding()
    f = clip.frames.copy()
    f[:, clip.channels.index(("root", "tz"))] += 0.3 * np.arange(clip.n_frames)
    clip = clip.with_frames(f)
    layout = root_layout(clip)
    ground = planted_ground(clip, layout, ("lfoot", "ltoes", "rfoot", "rtoes"), np.zeros((clip.n_frames, 4)))
    np.testing.assert_allclose(ground, clip.frames[:, [layout.column("tx"), layout.column("tz")]], atol=1e-9)


def test_decompose_root_has_the_seven_documented_columns(walk):
    layout = root_layout(walk)
    x = decompose_root(walk.frames[:5], layout)
    assert x.shape == (5, 7)
    np.testing.assert_allclose(x[:, 0], walk.frames[:5, layout.column("ty")])
