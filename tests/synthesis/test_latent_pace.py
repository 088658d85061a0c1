"""The root of latent synthesis travels at the pace its poses play the training takes
(``_Chunk.pace``): a MOVE that eases in from rest, or plays at ``speed``, moves the root
as fast as its legs, and an IDLE eases the pace it was given to a stand."""

from __future__ import annotations

import numpy as np
import pytest

from _bench import load_bench  # tests/ is on the path (rootdir conftest)
from _gait_models import gait_pair
from cyclecoord.synthesis.carry import STAND_AFTER
from cyclecoord.synthesis.latent import Synthesizer


@pytest.fixture(scope="module")
def models():
    return gait_pair()


def _root_accel(motion) -> np.ndarray:
    """Horizontal root acceleration (m/s^2): the latent benchmark's diagnostic."""
    return load_bench("bench_latent_gait")._root_accel(motion)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_run_set_off_from_an_idle_does_not_lurch(models, seed):
    """The run's root read its captured speed from the pose at once: after an IDLE it
    went from standing to 3.5 m/s in two frames, 3.0-4.3x the takes' p99 of root
    acceleration on these seeds (the joints, measured against the root, saw nothing)."""
    syn = Synthesizer(models, fps=30, seed=seed)
    syn.start("run", {"frame": 0})
    syn.move({"ahead": 1.0})
    syn.idle(duration=1.5)
    a = syn.n_frames
    syn.move({"ahead": 1.0})
    motion = syn.motion()
    p99 = np.percentile(_root_accel(models["run"].training_motion()), 99)
    assert _root_accel(motion)[a - 3 : a + 20].max() < 2.5 * p99


def test_a_move_from_rest_paces_its_root_with_its_ease_and_speed(models):
    """From rest the pace rises from near 0 to the asked ``speed`` over the ease; a MOVE
    that a MOVE follows keeps its pace to its end; the next one goes on at its own."""
    syn = Synthesizer(models, fps=30, seed=0)
    syn.start("walk", {"frame": 0})
    syn.move({"ahead": 1.5}, speed=0.8, stop=False)
    first = syn.chunks[-1].pace
    ramp = int(round(syn.ease * syn.fps))
    assert first[0] < 0.1 and first[ramp:].min() == pytest.approx(0.8, rel=0.02)
    assert np.all(np.diff(first[: ramp + 1]) >= -1e-12)  # rising
    syn.move({"ahead": 1.0})
    second = syn.chunks[-1].pace
    assert second[0] == pytest.approx(1.0, rel=0.02)  # no ease in: it flows on
    assert second[-1] < 0.1  # it stops


def test_an_idle_eases_the_pace_it_was_given_to_a_stand(models):
    """After a MOVE that stops, the IDLE's pace starts near that MOVE's last and is 0
    from STAND_AFTER s on; the root then stands."""
    syn = Synthesizer(models, fps=30, seed=0)
    syn.start("walk", {"frame": 0})
    syn.move({"ahead": 1.0})
    last = float(syn.chunks[-1].pace[-1])
    n = int(round(STAND_AFTER * syn.fps))
    k = np.arange(1, 46)
    u = np.clip(k / n, 0, 1)
    want = last * (1 - u * u * (3 - 2 * u))  # by hand: a smoothstep from the MOVE's last
    syn.idle(duration=1.5)
    pace = syn.chunks[-1].pace
    np.testing.assert_allclose(pace, want)
    assert last < 0.1 and np.all(pace[n - 1 :] == 0.0)


def test_at_the_captured_pace_the_root_travels_as_the_takes_did(models):
    """Between its ease in and its stop a MOVE ahead plays at pace 1: the root's speed
    there is the one the pose reads from the takes (as before the pace)."""
    syn = Synthesizer(models, fps=30, seed=0)
    syn.start("run", {"frame": 0})
    syn.move({"ahead": 3.0})
    c = syn.chunks[-1]
    ramp = int(round(syn.ease * syn.fps))
    mid = slice(ramp + 2, len(c.pace) - ramp - 2)
    np.testing.assert_allclose(c.pace[mid], 1.0, rtol=0.02)
    raw = syn._root(models["run"], c.X)["velocity"] + c.detail["velocity"]
    np.testing.assert_allclose(c.root["velocity"][mid], raw[mid] * c.pace[mid, None])
