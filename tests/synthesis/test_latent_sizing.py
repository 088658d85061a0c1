"""A script's models of actors of other sizes: their root tracks sized to the skeleton
the frames are written on (``synthesis.latent.sizing``)."""

from __future__ import annotations

import copy
from dataclasses import replace

import numpy as np
import pytest

from _gait_models import gait_pair  # tests/ is on the path (rootdir conftest)
from cyclecoord.quality.contacts import foot_contacts
from cyclecoord.skeleton import Skeleton
from cyclecoord.synthesis.latent import Synthesizer
from cyclecoord.synthesis.latent.model import RootTrack
from cyclecoord.synthesis.latent.sizing import sized_roots

K = 0.8  # the smaller actor's size


@pytest.fixture(scope="module")
def models():
    """The synthetic walk, and the same walk by an actor K times its size (bones, root
    travel and height all scaled: what a capture of a smaller actor on the rig gives)."""
    big = gait_pair()["walk"]
    small = copy.copy(big)
    small.skeleton_ = Skeleton(tuple(
        replace(j, offset=K * np.asarray(j.offset),
                end_site=None if j.end_site is None else K * np.asarray(j.end_site))
        for j in big.skeleton_.joints))
    frames = big.frames_.copy()
    root = big.skeleton_.joints[0].name
    for i, (j, d) in enumerate(big.all_channels_):
        if j == root and d in ("tx", "ty", "tz"):
            frames[:, i] *= K
    small.frames_ = frames
    small.__dict__.pop("_train", None)
    r = big.root_
    small.root_ = RootTrack(height=K * r.height, velocity=K * r.velocity, turn=r.turn,
                            tilt=r.tilt)
    small._detail = None
    return {"big": big, "small": small}


def test_the_other_actors_root_is_sized_to_the_output_skeleton(models):
    given = {k: (m, m.root_) for k, m in models.items()}
    sized, scales = sized_roots(models, "small")
    assert set(scales) == {"big"} and scales["big"] == pytest.approx(K, rel=1e-6)
    assert sized["small"] is models["small"]
    # the big actor's root on the small skeleton is the small actor's own
    np.testing.assert_allclose(sized["big"].root_.height, models["small"].root_.height,
                               rtol=1e-3, atol=1e-3 * models["small"].root_.height.max())
    np.testing.assert_allclose(sized["big"].root_.velocity, models["small"].root_.velocity,
                               atol=1e-9)
    np.testing.assert_array_equal(sized["big"].root_.turn, models["big"].root_.turn)
    # nothing given changed
    for k, (m, r) in given.items():
        assert models[k] is m and m.root_ is r
    assert sized["big"] is not models["big"]
    # one actor: nothing sized
    same, none = sized_roots({"a": models["big"], "b": models["big"]}, "a")
    assert none == {} and same["b"] is models["big"]


def test_a_script_that_starts_on_the_smaller_actor_keeps_the_other_actors_feet_down(models):
    """Started in the small actor and moved on in the big one (unsized, the big actor's
    hip height put the small skeleton's feet in the air: no contact, gliding feet)."""
    syn = Synthesizer(dict(models), fps=30, seed=0)
    syn.start("small", {"frame": 0})
    syn.command += 1
    syn.move({"ahead": 0.5}, stop=False)
    syn.command += 1
    syn.transition("big", blend=0.4)
    syn.command += 1
    syn.move({"ahead": 1.5})
    assert syn.sizes == {"big": pytest.approx(K)}
    assert any(n.startswith("model 'big': another actor (legs 1.25x 'small''s") for n in syn.notes)
    motion = syn.motion()
    c = foot_contacts(motion)
    floor = foot_contacts(models["small"].training_motion()).floor
    start = sum(ch.X.shape[0] for ch in syn.chunks[:-1])
    assert abs(c.floor - floor) < 0.05 * c.leg_length
    assert c.planted[start:].any(axis=1).mean() > 0.8  # a foot down on most frames


def test_a_second_start_before_any_frame_sizes_to_its_own_model(models):
    syn = Synthesizer(dict(models), fps=30, seed=0)
    syn.start("small", {"frame": 0})
    assert syn.sizes == {"big": pytest.approx(K)}
    syn.start("big", {"frame": 0})
    assert syn.sizes == {"small": pytest.approx(1.0 / K)}
    assert syn.models["big"] is models["big"]
