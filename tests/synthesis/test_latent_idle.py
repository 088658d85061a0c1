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


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_an_idle_after_an_in_step_transition_first_stops_along_the_gait(models, seed):
    """An in-step TRANSITION's blend ends stepping at the gait's latent pace; held where
    it was, the particle overshot, met the IDLE's radius and turned back within a frame
    (a Bandai run's knee 2.2x its p99).  The IDLE first comes to a stop along the gait,
    as a MOVE ahead that stops does, and says so; it stands as any IDLE does."""
    from cyclecoord.synthesis.carry import _accel

    syn = Synthesizer(models, fps=30, seed=seed)
    syn.start("walk", {"frame": 0})
    syn.command += 1
    syn.move({"ahead": 1.0}, stop=False)
    syn.command += 1
    syn.transition("run", blend=0.4)
    a = syn.n_frames
    assert syn._moving_on()  # (the blend ends stepping on)
    syn.command += 1
    syn.idle(duration=1.0)
    assert any(n.startswith("commands[2] IDLE: stepping on at the gait's pace, it first came "
                            "to a stop along the gait") for n in syn.notes)
    assert syn.held == syn.stands == [(a, syn.n_frames)]
    # (the stand's legs are held where the stop ended, the hover's first frame)
    hover = syn.chunks[-1]
    assert syn.rests[a] == syn.n_frames - a - hover.X.shape[0] > 0
    stop = next(c for c in syn.chunks if c.command == 2)
    assert stop.pace[-1] < 0.1  # (it came to rest)
    motion = syn.motion()
    acc = _accel(motion) / syn._frame_acc99(motion.n_frames)
    assert acc[a - 3 : a + 25].max() < 1.5


def test_two_crossings_in_a_row_do_not_stop_between_them(models):
    """Crossed while both models idle after a MOVE to a frame, each crossing's approach
    stopped at its bridge: two in a row stood still for 0.23-0.3 s between them on 2 of
    these 10 seeds (a freeze).  From a figure that moves the approach flows into the
    blend; it stops only where the figure stood."""
    from cyclecoord.quality.generated import measure_generated
    from cyclecoord.synthesis.latent.script import training_takes

    longest = []
    for seed in range(10):
        syn = Synthesizer(models, fps=30, seed=seed)
        syn.start("walk", {"frame": 10})
        syn.command += 1
        syn.move(models["walk"].X_[60].tolist(), path="graph")  # (not stepping)
        for to in ("run", "walk"):
            syn.command += 1
            syn.transition(to, blend=0.6)
        syn.command += 1
        syn.move({"ahead": 1.0})
        motion = syn.motion()
        q = measure_generated(motion, training_takes(models),
                              hold=syn.hold_mask(motion.n_frames, asked=True))
        assert not q.freezes, (seed, q.freezes)
        longest.append(q.longest_freeze_s)
    assert max(longest) <= 0.2
