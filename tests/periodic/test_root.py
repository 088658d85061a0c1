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
