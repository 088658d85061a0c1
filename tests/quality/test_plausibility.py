"""Self-intersection and joint-range checks (cyclecoord.quality.plausibility)."""

import json
import re

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from cyclecoord.quality.plausibility import (
    DEFAULT_CLEARANCE,
    bones,
    check_plausibility,
    joint_range_violations,
    segment_distances,
    self_intersections,
)

# a left-arm pose whose forearm crosses the chest (found by forward kinematics)
ARM_THROUGH_TORSO = {("lhumerus", "rx"): -30.0, ("lhumerus", "ry"): 45.0, ("lhumerus", "rz"): -45.0,
                     ("lradius", "rx"): 120.0}
LEFT_ARM = {"lhumerus", "lradius", "lwrist", "lhand", "lfingers", "lthumb"}
TORSO = {"lowerback", "upperback", "thorax", "lowerneck", "rclavicle", "rhumerus", "rradius"}


@pytest.fixture(scope="module")
def walk():
    cap = cc.datasets.make_periodic_capture(kind="walk", n_frames=120, period=120, noise=0.0,
                                            speed_variation=0.0, random_state=0)
    return cap.motion


def arm_through_torso(walk, first=40, last=80):
    """The walk with the left arm driven smoothly into the chest and out again."""
    f = np.array(walk.frames)
    t = np.arange(walk.n_frames)
    ramp = np.clip(np.minimum(t - first + 20, last + 20 - t) / 20.0, 0.0, 1.0)  # 1 on [first, last]
    for (joint, dof), value in ARM_THROUGH_TORSO.items():
        c = walk.channel_index(joint, dof)
        f[:, c] = (1 - ramp) * f[:, c] + ramp * value
    return walk.with_frames(f)


def test_bones_follow_the_asf_bones_and_skip_touching_pairs(walk):
    bn = bones(walk)
    assert len(bn.names) == 30
    for name in ("lfemur", "ltibia", "thorax", "lhumerus", "lradius", "head", "lthumb"):
        assert name in bn.names
    pairs = {frozenset(p) for p in bn.pair_names()}
    # parent/child and siblings at one joint are never compared
    for p in [("lfemur", "ltibia"), ("lhumerus", "lradius"), ("lhipjoint", "lowerback"),
              ("lhipjoint", "rhipjoint"), ("thorax", "lclavicle"), ("lowerneck", "rclavicle")]:
        assert frozenset(p) not in pairs, p
    for p in [("lfemur", "rfemur"), ("ltibia", "rtibia"), ("lradius", "upperback"), ("lhand", "lfemur")]:
        assert frozenset(p) in pairs, p


def test_segment_distances_match_brute_force():
    rng = np.random.default_rng(0)
    p0, p1, q0, q1 = rng.normal(size=(4, 300, 3))
    p1[:20] = p0[:20]  # points
    q1[20:40] = q0[20:40] + 0.0
    # parallel copies moved by a unit vector square to them: distance exactly 1
    u = p1[40:60] - p0[40:60]
    side = np.cross(u, rng.normal(size=(20, 3)))
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    q0[40:60], q1[40:60] = p0[40:60] + side, p1[40:60] + side
    d = segment_distances(p0, p1, q0, q1)
    s = np.linspace(0, 1, 401)[:, None]
    brute = np.empty(d.shape)
    for i in range(d.size):  # nearest pair of 401 points along each segment
        a = p0[i] + s * (p1[i] - p0[i])
        b = q0[i] + s * (q1[i] - q0[i])
        brute[i] = np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(-1).min())
    assert np.all(d <= brute + 1e-12)
    assert np.abs(d - brute).max() < 2e-2
    assert d[40:60] == pytest.approx(np.ones(20))
    # crossing segments touch
    assert segment_distances(np.array([-1.0, 0, 0]), np.array([1.0, 0, 0]),
                             np.array([0, -1.0, 0]), np.array([0, 1.0, 0])) == pytest.approx(0.0)


def test_normal_walk_is_clean(walk):
    found = self_intersections(walk)
    assert found.threshold == pytest.approx(DEFAULT_CLEARANCE * walk.skeleton.total_length())
    assert found.frames.size == 0 and found.contacts() == []
    report = check_plausibility(walk, [walk])
    assert report.clean and "no bones closer" in report.summary()


def test_arm_through_the_torso_is_flagged(walk):
    bad = arm_through_torso(walk)
    found = self_intersections(bad)
    frames = found.frames
    assert frames.size >= 30
    assert frames.min() >= 20 and frames.max() <= 100  # only while the arm is in
    assert set(range(45, 76)) <= set(frames.tolist())
    crossing = [c for c in found.contacts()
                if (set(c["bones"]) & LEFT_ARM) and (set(c["bones"]) & TORSO)]
    assert crossing and min(c["min_distance"] for c in crossing) < 0.2
    report = check_plausibility(bad, [walk])
    assert not report.clean
    assert set(range(45, 76)) <= set(report.new_contact_frames)
    assert any(v.channel == ("lradius", "rx") for v in report.joint_range)
    assert "closer than the inputs ever do" in report.summary()
    # every distance in the note is printed to three significant figures
    note = next(n for n in report.notes if "closer than the inputs ever do" in n)
    assert re.fullmatch(r".* at [0-9.e-]+ \(clearance [0-9.e-]+, inputs' closest ([0-9.]{1,5}|n/a)\)", note), note
    payload = json.loads(json.dumps(report.to_dict()))
    assert payload["clean"] is False and payload["joint_range_violations"]


def test_a_reference_of_another_size_is_measured_at_the_motions_size(walk):
    """The same walk built at a total bone length of 0.5 (other units) keeps its bones
    as far apart, relative to its size: the arm through the torso is as new as against
    the walk itself."""
    from dataclasses import replace

    from cyclecoord.skeleton import Skeleton

    sk = walk.skeleton
    k = 0.5 / sk.total_length()
    small_sk = Skeleton(tuple(
        replace(j, offset=j.offset * k, end_site=None if j.end_site is None else j.end_site * k)
        for j in sk.joints), name=sk.name, length_unit=sk.length_unit,
        source_format=sk.source_format)
    f = np.array(walk.frames)
    for c in walk.root_channels():
        if walk.channels[c][1].startswith("t"):
            f[:, c] *= k
    small = cc.Motion(f, walk.channels, fps=walk.fps, skeleton=small_sk)
    assert small_sk.total_length() == pytest.approx(0.5)
    bad = arm_through_torso(walk)
    want = check_plausibility(bad, [walk]).new_contact_frames
    assert len(want) >= 30 and check_plausibility(bad, [small]).new_contact_frames == want


def test_contacts_the_inputs_share_are_explained_not_new(walk):
    bad = arm_through_torso(walk)
    report = check_plausibility(bad, [walk, bad])
    assert report.new_contact_frames == [] and not report.joint_range
    assert report.clean
    assert any("the inputs come as close" in n for n in report.notes)
    # a tighter or looser clearance changes what is flagged
    assert self_intersections(bad, threshold=0.01).frames.size < self_intersections(bad).frames.size


def test_joint_range(walk):
    assert joint_range_violations(walk, [walk]) == []
    c = walk.channel_index("ltibia", "rx")
    f = np.array(walk.frames)
    f[:, c] += 360.0  # the same rotations one turn up: not a violation
    assert joint_range_violations(walk.with_frames(f), [walk]) == []
    g = np.array(walk.frames)
    top = g[:, c].max()
    g[10, c] = top + 12.0
    found = joint_range_violations(walk.with_frames(g), [walk], margin_deg=5.0)
    assert len(found) == 1
    v = found[0]
    assert v.channel == ("ltibia", "rx") and v.frames == 1 and v.first_frame == 10
    assert v.excess == pytest.approx(7.0) and v.high == pytest.approx(top + 5.0)
    assert joint_range_violations(walk.with_frames(g), [walk], margin_deg=15.0) == []
    # a second reference one turn up is brought onto the first's turn: the same range
    found = joint_range_violations(walk.with_frames(g), [walk, walk.with_frames(f)], margin_deg=5.0)
    assert len(found) == 1 and found[0].high == pytest.approx(top + 5.0)


def test_bones_are_frozen(walk):
    import dataclasses

    bn = bones(walk)
    with pytest.raises(dataclasses.FrozenInstanceError):
        bn.names = []


def test_bad_arguments(walk):
    with pytest.raises(ParameterError, match="skeleton"):
        self_intersections(cc.Motion(walk.frames, walk.channels))
    with pytest.raises(ParameterError, match="threshold"):
        self_intersections(walk, threshold=-1.0)
    with pytest.raises(ParameterError, match="reference"):
        joint_range_violations(walk, [])
    with pytest.raises(ParameterError, match="margin"):
        joint_range_violations(walk, [walk], margin_deg=float("nan"))


def test_real_walk_near_contacts_explain_themselves(walk_69_01):
    clip = walk_69_01[200:450]
    found = self_intersections(clip)
    # legs passing each other come within 2 % of the skeleton size in a real walk
    assert any({"ltibia", "rtibia"} == set(c["bones"]) for c in found.contacts())
    report = check_plausibility(clip, [clip])
    assert report.clean
    assert any("the inputs come as close" in n for n in report.notes)


def test_a_reference_played_on_narrower_hips_explains_the_legs_meeting(walk):
    """The walk on a skeleton whose hips are half as wide: its legs pass within the
    clearance of each other on every frame.  The input on its own skeleton never brings
    them that close, but played on the narrower skeleton (same joints) it does: nothing
    is new.  A reference on its own skeleton alone would call every frame new."""
    from dataclasses import replace

    from cyclecoord.quality.plausibility import _reference_views
    from cyclecoord.skeleton import Skeleton

    walk = walk.window((0, 30))  # the legs meet on every frame: a quarter of the walk
    sk = walk.skeleton
    narrow_sk = Skeleton(tuple(
        replace(j, offset=j.offset * np.array([0.5, 1.0, 1.0])) if j.name in ("lfemur", "rfemur")
        else j for j in sk.joints), name=sk.name, length_unit=sk.length_unit,
        source_format=sk.source_format)
    narrow = cc.Motion(walk.frames, walk.channels, fps=walk.fps, skeleton=narrow_sk)
    legs = {"lfemur", "ltibia", "rfemur", "rtibia"}
    met = [c for c in self_intersections(narrow).contacts() if set(c["bones"]) <= legs]
    assert met and self_intersections(walk).frames.size == 0
    views = _reference_views(walk, narrow)
    assert len(views) == 2 and views[0].skeleton is sk and views[1].skeleton is narrow_sk
    # root translation scaled by the ratio of the skeletons' sizes
    k = narrow_sk.total_length() / sk.total_length()
    tx = walk.channel_index("root", "tx")
    np.testing.assert_allclose(views[1].frames[:, tx], k * walk.frames[:, tx])
    rest = [i for i, (j, d) in enumerate(walk.channels) if not (j == "root" and d.startswith("t"))]
    np.testing.assert_array_equal(views[1].frames[:, rest], walk.frames[:, rest])
    report = check_plausibility(narrow, [walk])
    assert report.clean and report.new_contact_frames == []
    assert any("the inputs come as close" in n for n in report.notes)
    # the same skeleton object: one view, nothing to replay
    assert len(_reference_views(walk, walk)) == 1


def test_the_note_names_the_worst_joint_angle(walk):
    """check_plausibility's joint-range note counts the angles out of range and names the
    worst excess (joint_range_violations lists it first), not the first channel."""
    g = np.array(walk.frames)
    low, high = walk.channel_index("lfemur", "rx"), walk.channel_index("ltibia", "rx")
    g[10, low] = g[:, low].max() + 8.0  # 3 degrees beyond the 5-degree margin
    g[20, high] = g[:, high].max() + 25.0  # 20 beyond: the worst
    rep = check_plausibility(walk.with_frames(g), [walk])
    note = next(n for n in rep.notes if "joint angles leave" in n)
    assert note.startswith("2 joint angles leave") and "worst ltibia.rx at" in note
    assert [v.channel for v in rep.joint_range] == [("ltibia", "rx"), ("lfemur", "rx")]


def test_a_zero_length_link_away_from_the_origin_is_one_node():
    """A child at its parent's place (offset 0) is one node with it, wherever it is."""
    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    skel = Skeleton((
        Joint("root", -1, [0.0, 0.0, 0.0]),
        Joint("a", 0, [2.0, 0.0, 0.0]),
        Joint("a_twist", 1, [0.0, 0.0, 0.0]),  # zero-length link at (2, 0, 0)
        Joint("b", 2, [0.0, 2.0, 0.0]),
        Joint("c", 1, [0.0, 0.0, 2.0]),
    ))
    bn = bones(Motion(np.zeros((1, 0)), (), skeleton=skel))
    assert len(bn.names) == 3  # root-a, a-b (through a_twist), a-c: no bone of length 0
    assert np.all(bn.start != bn.end)
