"""An IDLE at one pose ends back at its first frame's pose (``easing.settle``), where its
stand holds the legs, so the motion after it goes on from the stand's own legs."""

from __future__ import annotations

import numpy as np
import pytest

from _gait_models import gait_pair  # tests/ is on the path (rootdir conftest)
from cyclecoord.synthesis.latent import Synthesizer
from cyclecoord.synthesis.latent.easing import settle


@pytest.fixture(scope="module")
def models():
    return gait_pair()


def test_settle_eases_a_path_to_its_target_over_its_last_frames():
    rng = np.random.default_rng(0)
    X, V = rng.normal(size=(20, 3)), rng.normal(size=(20, 3))
    target = np.array([1.0, 2.0, 3.0])
    Xs, Vs = settle(X, V, target, 6)
    np.testing.assert_array_equal(Xs[:14], X[:14])  # untouched before the last six
    np.testing.assert_allclose(Xs[-1], target)
    np.testing.assert_allclose(Vs[-1], 0.0)
    # by hand: frame 16 is u = 2/5 of the way, smoothstep 0.352
    np.testing.assert_allclose(Xs[16], X[16] + 0.352 * (target - X[16]))
    Xs, _ = settle(X[:4], V[:4], target, 6)  # (at most half of a short path)
    np.testing.assert_array_equal(Xs[:2], X[:2])
    Xs, Vs = settle(X, V, target, 6, amount=0.25)  # (part of the way: a short IDLE's)
    np.testing.assert_allclose(Xs[-1], X[-1] + 0.25 * (target - X[-1]))
    np.testing.assert_allclose(Vs[-1], 0.75 * V[-1])


@pytest.mark.parametrize("seed", [0, 1, 5])
def test_a_stand_goes_on_from_the_legs_it_holds(models, seed):
    """The particle hovering through an IDLE drifted along the run's stride; the legs
    eased out of the stand to where it had drifted, a stride away (54-64 degrees on a
    leg channel between the IDLE's first and last frames on these seeds), while
    the pins held the feet, and the motion after swept a foot 0.4 m in two frames."""
    syn = Synthesizer(models, fps=30, seed=seed)
    syn.start("run", {"frame": 0})
    syn.move({"ahead": 1.0})
    a = syn.n_frames
    syn.idle(duration=2.0)
    b = syn.n_frames
    syn.move({"ahead": 1.0})
    angles = syn._posed()[0]
    legs = syn._leg_mask(models["run"])
    assert np.abs(angles[b - 1] - angles[a])[legs].max() < 15.0
    (idle,) = [c for c in syn.chunks if c.pace is not None and c.pace[-1] == 0.0
               and c.X.shape[0] == b - a]
    np.testing.assert_allclose(idle.X[-1], idle.X[0])
