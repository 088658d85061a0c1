"""Limbs turned apart at the shoulder or hip (cyclecoord.synthesis.clearance)."""

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.quality.bones import segment_distances
from cyclecoord.quality.plausibility import check_plausibility
from cyclecoord.synthesis.clearance import PUSH_WIDTH, push_limbs_apart


@pytest.fixture(scope="module")
def walk():
    cap = cc.datasets.make_periodic_capture(kind="walk", n_frames=120, period=60, noise=0.0,
                                            speed_variation=0.0, random_state=0)
    return cap.motion


def moved(walk, joint, dof, degrees, first, last, ramp=10):
    """The walk with one channel moved by ``degrees`` on [first, last], ramped in and out."""
    f = np.array(walk.frames)
    t = np.arange(walk.n_frames)
    w = np.clip(np.minimum(t - first + ramp, last + ramp - t) / ramp, 0.0, 1.0)
    f[:, walk.channel_index(joint, dof)] += degrees * w
    return walk.with_frames(f)


def changed_joints(a, b):
    diff = np.abs(a.frames - b.frames).max(axis=0) > 1e-9
    return {a.channels[i][0] for i in np.flatnonzero(diff)}


def bone_gap(motion, a, b):
    """Closest distance per frame between the bones of joints ``a`` and ``b`` (each from
    its joint to its child), from the positions."""
    fk = motion.positions()
    names = list(fk.names)
    child = {n: names[list(fk.parents).index(i)] for i, n in enumerate(names)
             if i in list(fk.parents)}
    p = fk.positions
    return segment_distances(p[:, names.index(a)], p[:, names.index(child[a])],
                             p[:, names.index(b)], p[:, names.index(child[b])])


def test_an_arm_driven_into_the_hip_is_turned_out_at_the_shoulder(walk):
    bad = moved(walk, "lhumerus", "rz", -12.0, 40, 60)
    before = check_plausibility(bad, [walk])
    assert before.new_contact_frames  # the arm now meets the hip, as no frame of the walk does
    out, pushed = push_limbs_apart(bad, [walk], analysed=False)
    after = check_plausibility(out, [walk])
    assert after.new_contact_frames == [] and pushed.left == []
    # the shoulder alone turned, by a few degrees, eased in and out about the contact
    assert changed_joints(bad, out) == {"lhumerus"}
    (spans, largest), = [pushed.turns[k] for k in pushed.turns]
    assert list(pushed.turns) == ["lhumerus"] and 0.5 < largest < 12.0
    width = int(round(PUSH_WIDTH * walk.fps))
    first = min(before.new_contact_frames)
    last = max(before.new_contact_frames)
    assert spans[0][0] >= first - width - 1 and spans[-1][1] <= last + width + 1
    untouched = np.r_[0 : first - width - 1, last + width + 2 : walk.n_frames]
    np.testing.assert_array_equal(out.frames[untouched], bad.frames[untouched])
    # the forearm ends up at least as far from the hip as the check allows, and no
    # frame-to-frame step of the shoulder's channels grows by more than a degree
    assert bone_gap(out, "lradius", "lhipjoint").min() > bone_gap(bad, "lradius", "lhipjoint").min()
    cols = [walk.channel_index("lhumerus", d) for d in ("rx", "ry", "rz")]
    assert np.abs(np.diff(out.frames[:, cols], axis=0)).max() < (
        np.abs(np.diff(bad.frames[:, cols], axis=0)).max() + 1.0)
    assert "lhumerus by up to" in pushed.line()
    assert pushed.to_dict()["turned"][0]["joint"] == "lhumerus"


def test_a_clean_motion_is_returned_as_it_is(walk):
    out, pushed = push_limbs_apart(walk, [walk], analysed=False)
    assert out is walk and pushed.turns == {} and pushed.line() is None


def test_a_contact_needing_a_larger_turn_than_allowed_is_left_and_named(walk):
    bad = moved(walk, "lhumerus", "rz", -15.0, 40, 60)
    out, pushed = push_limbs_apart(bad, [walk], analysed=False, max_deg=1.0)
    assert out is bad and pushed.turns == {}
    assert any("lhipjoint" in c or "lfemur" in c for c in pushed.left)


def test_two_legs_meeting_turn_the_swinging_one(walk):
    bad = moved(walk, "rfemur", "rz", 15.0, 30, 50)
    new = check_plausibility(bad, [walk]).new_contact_frames
    assert new
    fk = bad.positions()
    names = list(fk.names)
    height = fk.positions[:, :, 1]
    right_higher = height[new, names.index("rfoot")] > height[new, names.index("lfoot")]
    assert right_higher.all()  # the right leg swings there, the left foot is down
    out, pushed = push_limbs_apart(bad, [walk], analysed=False, feet=("lfoot", "rfoot"))
    assert check_plausibility(out, [walk]).new_contact_frames == []
    assert changed_joints(bad, out) == {"rfemur"}
    # the planted foot has not moved
    np.testing.assert_allclose(out.positions().positions[:, names.index("lfoot")],
                               fk.positions[:, names.index("lfoot")], atol=1e-9)


def test_a_latent_script_turns_apart_the_limbs_its_pulls_left_too_close(monkeypatch):
    """Synthesizer.motion() ends with push_limbs_apart against the training takes: an arm
    driven into the hip after the feet are planted comes out apart, and the console
    says which joint turned, by how much and where."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parents[1]))
    from _gait_models import gait_pair

    from cyclecoord.synthesis.latent import Synthesizer
    from cyclecoord.synthesis.latent.output import OutputMixin

    models = gait_pair()
    syn = Synthesizer(models, fps=30, seed=0, plant="off", lock=False)
    syn.start("walk", {"frame": 0})
    for _ in range(3):
        syn.command += 1
        syn.move({"ahead": 0.3}, stop=False)
    planted = OutputMixin._plant_feet

    def into_the_hip(self, motion):
        return moved(planted(self, motion), "lhumerus", "rz", -14.0, 12, 18, ramp=5)

    monkeypatch.setattr(OutputMixin, "_plant_feet", into_the_hip)
    takes = [models["walk"].training_motion()]
    bad = into_the_hip(syn, syn._untangled())
    assert check_plausibility(bad, takes, analysed=True).new_contact_frames
    out = syn.motion()
    assert check_plausibility(out, takes, analysed=True).new_contact_frames == []
    assert changed_joints(bad, out) == {"lhumerus"}
    assert any(n.startswith("limbs turned apart") and "lhumerus by up to" in n
               for n in syn.notes)


def test_a_leg_does_not_turn_while_its_foot_is_planted(walk, monkeypatch):
    """Given the feet, a leg's turn is zero on the frames its foot is planted and eases
    back in away from them (turned over the frames about a contact, it slid the foot)."""
    from types import SimpleNamespace

    import cyclecoord.quality.contacts as contacts

    bad = moved(walk, "rfemur", "rz", 15.0, 30, 50)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    free, _ = push_limbs_apart(bad, [walk], analysed=False, feet=feet)  # (no contact found)
    turned = np.flatnonzero(np.abs(free.frames - bad.frames).max(axis=1) > 1e-9)
    planted = np.zeros((walk.n_frames, 4), dtype=bool)
    down = turned[: len(turned) // 4]  # the right foot down on the first quarter of them
    planted[down, 2] = True
    monkeypatch.setattr(contacts, "foot_contacts",
                        lambda motion, f, **kw: SimpleNamespace(planted=planted))
    out, pushed = push_limbs_apart(bad, [walk], analysed=False, feet=feet)
    cols = [walk.channel_index("rfemur", d) for d in ("rx", "ry", "rz")]
    np.testing.assert_array_equal(out.frames[np.ix_(down, cols)], bad.frames[np.ix_(down, cols)])
    assert not np.array_equal(out.frames[:, cols], bad.frames[:, cols])
