"""The baselines of generated motion: Kovar et al.'s motion graph and nearest-take replay."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from cyclecoord.synthesis.classic_graph import (
    ClassicMotionGraph,
    _clouds,
    _fit,
    replay_nearest,
    window_distance,
)


def test_window_distance_ignores_a_turn_and_a_floor_shift_only():
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(12, 5, 3))  # 12 frames of 5 joints
    turned = Rotation.from_rotvec([0, 0.7, 0]).apply(pts.reshape(-1, 3)).reshape(pts.shape)
    turned += [3.0, 0.0, -2.0]
    pos = np.concatenate([pts, turned])
    take = np.r_[np.zeros(12, int), np.ones(12, int)]
    c = _clouds(pos, take, 4, 1)
    d = window_distance(c)
    assert d[0, 12] == pytest.approx(0.0, abs=1e-6)
    theta, shift = _fit(c, 0, 12)  # window 12 onto window 0
    back = Rotation.from_rotvec([0, theta, 0]).apply(turned[0]) + shift
    assert np.allclose(back, pts[0], atol=1e-6)
    lifted = pos.copy()
    lifted[12:, :, 1] += 0.5  # a vertical shift is a real difference
    assert window_distance(_clouds(lifted, take, 4, 1))[0, 12] == pytest.approx(0.5, rel=1e-6)


@pytest.fixture(scope="module")
def walks():
    return [
        cc.datasets.make_periodic_capture(kind="walk", n_frames=n, period=60, random_state=s).motion
        for s, n in ((0, 200), (1, 180), (2, 190))
    ]


def _root_steps(m):
    p = m.positions().positions[:, 0]
    return np.linalg.norm(np.diff(p[:, [0, 2]], axis=0), axis=1)


def test_classic_walk_transitions_without_a_root_jump(walks):
    g = ClassicMotionGraph().fit(walks)
    assert g.n_transitions > 0 and g.alive_.sum() > 100
    walk = g.walk(500, 0, seed=1, jump=0.2)
    assert walk.motion.n_frames == 500 and len(walk.transitions) >= 3
    steps = _root_steps(walk.motion)
    own = np.concatenate([_root_steps(m) for m in walks])
    assert steps.max() <= 2.0 * np.percentile(own, 99)  # root aligned at every transition
    with pytest.raises(ParameterError, match="no transition points"):
        ClassicMotionGraph(threshold=0.0).fit(walks).walk(10)


def test_replay_plays_the_nearest_take_then_cuts(walks):
    rep = replay_nearest(walks, 400, walks[1], 20)
    assert rep.motion.n_frames == 400
    assert np.allclose(rep.motion.frames[:50], walks[1].frames[20:70])
    assert len(rep.transitions) >= 2
    assert _root_steps(rep.motion).max() <= 2.0 * np.percentile(
        np.concatenate([_root_steps(m) for m in walks]), 99
    )
