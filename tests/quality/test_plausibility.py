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


# ------------------------------------------------------------------ known answers, by hand
def _swing_rig():
    """Root at the origin with two arms: ``a`` 1 along +x, its bone to ``a2`` 1 further,
    turning about z (angle th: a2 = (1 + cos th, sin th, 0)); ``b`` 1 along -x, its bone
    to ``b2`` 1 up along z (b's own turn about z does not move it).  Bones, in order:
    root>a, a, root>b, b; the pairs sharing no joint are (root>a, b), (a, root>b), (a, b),
    at distances 1, 1 and sqrt(5 + 4 cos th) (1 at th = 180)."""
    from cyclecoord.skeleton import Joint, Skeleton

    return Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz"), ""),
                     Joint("a", 0, [1.0, 0, 0], ("rz",), "Z"),
                     Joint("a2", 1, [1.0, 0, 0]),
                     Joint("b", 0, [-1.0, 0, 0], ("rz",), "Z"),
                     Joint("b2", 3, [0, 0, 1.0])))


def _swing(angles, b_angles=None, start_frame=0):
    sk = _swing_rig()
    f = np.zeros((len(angles), 5))
    f[:, 3] = angles
    if b_angles is not None:
        f[:, 4] = b_angles
    return cc.Motion(f, sk.channels, fps=30, skeleton=sk, start_frame=start_frame)


def _d(th):
    """Distance of bones a and b at angle th (degrees), by the law of cosines."""
    return np.sqrt(5 + 4 * np.cos(np.radians(th)))


def test_bones_and_pairs_of_a_small_rig_by_hand():
    bn = bones(_swing([0.0]))
    assert bn.names == ["root>a", "a", "root>b", "b"]
    assert bn.start.tolist() == [0, 1, 0, 3] and bn.end.tolist() == [1, 2, 3, 4]
    assert bn.pairs.tolist() == [[0, 3], [1, 2], [1, 3]]
    assert bn.pair_names() == [("root>a", "b"), ("a", "root>b"), ("a", "b")]
    np.testing.assert_allclose(bn.rest_distance, [1.0, 1.0, 2.0])
    # root>b touches both root>a and b, root>a both a and root>b; nothing touches a and b
    assert bn.second_neighbours.tolist() == [True, True, False]
    with pytest.raises(ParameterError, match="skeleton"):
        bones(cc.Motion(np.zeros((1, 5)), _swing_rig().channels))


def test_siblings_starting_at_one_place_are_one_node():
    """Two children of one joint at the same place (CMU's neck and clavicles) make one
    node: a bone from each to its own child, and the link to them one bone."""
    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    skel = Skeleton((
        Joint("root", -1, [0.0, 0.0, 0.0]),
        Joint("p", 0, [0.0, 2.0, 0.0]),
        Joint("q", 0, [0.0, 2.0, 0.0]),
        Joint("p1", 1, [1.0, 0.0, 0.0]),
        Joint("q1", 2, [-1.0, 0.0, 0.0]),
    ))
    bn = bones(Motion(np.zeros((1, 0)), (), skeleton=skel))
    assert bn.names == ["root", "p", "q"]  # root-p (root-q is the same bone), p-p1, q-q1
    assert bn.pairs.size == 0  # all three share the node at (0, 2, 0)
    one = Skeleton((Joint("root", -1, [0.0, 0.0, 0.0]), Joint("p", 0, [0.0, 2.0, 0.0])))
    with pytest.raises(ParameterError, match="fewer than two bones"):
        bones(Motion(np.zeros((1, 0)), (), skeleton=one))


def test_segment_distances_in_closed_form():
    def sd(p0, p1, q0, q1):
        return float(segment_distances(*(np.array(x, float) for x in (p0, p1, q0, q1))))

    assert sd([0, 0, 0], [0, 0, 0], [3, 4, 0], [3, 4, 0]) == pytest.approx(5.0)  # two points
    assert sd([0, 1, 0], [0, 1, 0], [-1, 0, 0], [1, 0, 0]) == pytest.approx(1.0)  # point, segment
    assert sd([2, 1, 0], [2, 1, 0], [-1, 0, 0], [1, 0, 0]) == pytest.approx(np.sqrt(2))
    assert sd([-1, 0, 0], [1, 0, 0], [0.5, 3, 0], [0.5, 3, 0]) == pytest.approx(3.0)  # segment, point
    assert sd([-1, 0, 0], [1, 0, 0], [-3, -4, 0], [-3, -4, 0]) == pytest.approx(np.sqrt(20))
    assert sd([-1, 0, 0], [1, 0, 0], [0, -1, 2], [0, 1, 2]) == pytest.approx(2.0)  # skew, inside
    assert sd([0, 0, 0], [1, 0, 0], [2, 1, 0], [3, 1, 0]) == pytest.approx(np.sqrt(2))  # parallel
    assert sd([0, 0, 0], [1, 0, 0], [-3, 1, 0], [-2, 1, 0]) == pytest.approx(np.sqrt(5))
    assert sd([0, 0, 0], [4, 0, 0], [1, 1, 0], [3, 1, 0]) == pytest.approx(1.0)  # overlapping
    # the second segment's closest point beyond either end: clamped, the first re-solved
    assert sd([0, 0, 0], [0, 4, 0], [1, 2, 1], [5, 2, 1]) == pytest.approx(np.sqrt(2))
    assert sd([0, 0, 0], [0, 4, 0], [-5, 6, 1], [-1, 6, 1]) == pytest.approx(np.sqrt(1 + 4 + 1))


def test_segment_distances_match_an_exact_search():
    """Against a ternary search over the first segment of the (exact) distance from its
    point to the second segment (convex in the parameter): random, parallel and
    degenerate segments, to 1e-9."""
    rng = np.random.default_rng(3)
    p0, p1, q0, q1 = rng.normal(size=(4, 200, 3))
    p1[:10] = p0[:10]
    q1[10:20] = q0[10:20]
    q0[20:30], q1[20:30] = p0[20:30] + 0.3, p1[20:30] + 0.3  # parallel
    q0[30:40], q1[30:40] = p1[30:40] + 0.2, p0[30:40] + 0.2  # antiparallel

    def to_q(x):
        v = q1 - q0
        vv = np.einsum("ij,ij->i", v, v)
        t = np.clip(np.einsum("ij,ij->i", x - q0, v) / np.where(vv > 0, vv, 1.0), 0, 1)
        return np.linalg.norm(x - q0 - t[:, None] * v, axis=1)

    def f(s):
        return to_q(p0 + s[:, None] * (p1 - p0))

    lo, hi = np.zeros(200), np.ones(200)
    for _ in range(120):
        a, b = lo + (hi - lo) / 3, hi - (hi - lo) / 3
        left = f(a) < f(b)
        hi = np.where(left, b, hi)
        lo = np.where(left, lo, a)
    want = np.minimum(f(0.5 * (lo + hi)), np.minimum(f(np.zeros(200)), f(np.ones(200))))
    np.testing.assert_allclose(segment_distances(p0, p1, q0, q1), want, rtol=0, atol=1e-9)


def test_self_intersections_at_the_clearance():
    """Arm a turned 0, 90 and 180 degrees: pair (a, root>b) goes from 1 to 0 (a's tip at
    the root), (a, b) from 2 to 1.  Closer than the clearance is flagged, at it is not: a
    clearance of 1 flags (a, root>b) on the last frame only.  A clearance of 1.5 ignores
    (root>a, b) and (a, root>b), one bone apart and 1 apart at rest, and flags (a, b) at
    1; unless rest contacts are not ignored."""
    m = _swing([0.0, 90.0, 180.0], start_frame=10)
    one = self_intersections(m, 1.0)
    np.testing.assert_allclose(one.distances, [[1, 1, 2], [1, 1, 2], [1, 0, 1]], atol=1e-12)
    assert one.flagged.tolist() == [[False] * 3, [False] * 3, [False, True, False]]
    assert not one.ignored.any() and one.frames.tolist() == [2] and one.start_frame == 10
    np.testing.assert_allclose(one.min_distance, [1, 0, 1], atol=1e-12)
    c15 = self_intersections(m, 1.5)
    assert c15.ignored.tolist() == [True, True, False] and c15.threshold == 1.5
    assert c15.flagged.tolist() == [[False] * 3, [False] * 3, [False, False, True]]
    assert c15.contacts() == [{"bones": ["a", "b"], "frames": 1, "first_frame": 12,
                               "min_distance": pytest.approx(1.0)}]
    every = self_intersections(m, 1.5, ignore_rest_contacts=False)
    assert not every.ignored.any()
    assert every.flagged.tolist() == [[True, True, False], [True, True, False], [True, True, True]]
    assert [c["frames"] for c in every.contacts()] == [3, 3, 1]
    # the default clearance is 2 % of the bones' total length (4 here)
    assert self_intersections(m).threshold == pytest.approx(0.08)
    for bad in (0.0, -1.0, np.nan, np.inf):
        with pytest.raises(ParameterError, match="threshold"):
            self_intersections(m, bad)
    with pytest.raises(ParameterError, match="Motion"):
        self_intersections("walk")


def test_joint_range_by_hand():
    """References turn a through 0, 90, 180 and b through -10, 10: with the 5-degree
    margin a may go -5 to 185 and b -15 to 15 (taken on the turn nearest the middle).
    a at 200 is 15 over; -170 is 190 on that turn, 5 over; 185 is at the limit, inside;
    b at 40 is 25 over: the worst, listed first."""
    ref = _swing([0.0, 90.0, 180.0], [-10.0, 10.0, 0.0])
    m = _swing([200.0, -170.0, 185.0, 30.0], [0.0, 0.0, 40.0, 0.0], start_frame=100)
    found = joint_range_violations(m, [ref])
    assert [v.channel for v in found] == [("b", "rz"), ("a", "rz")]
    b, a = found
    assert (b.frames, b.first_frame, b.low, b.high, b.worst, b.excess) == (
        1, 102, -15.0, 15.0, 40.0, pytest.approx(25.0))
    assert (a.frames, a.first_frame, a.low, a.high, a.worst) == (2, 100, -5.0, 185.0, 200.0)
    assert a.excess == pytest.approx(15.0)
    assert a.to_dict() == {"channel": "a.rz", "frames": 2, "first_frame": 100,
                           "allowed": [-5.0, 185.0], "worst": 200.0,
                           "excess_deg": pytest.approx(15.0)}
    # no margin: 185 is out too (5 over 180); a reference a turn down is the same range
    a0 = [v for v in joint_range_violations(m, [ref], margin_deg=0.0) if v.channel[0] == "a"][0]
    assert a0.frames == 3 and a0.low == 0.0 and a0.high == 180.0
    down = _swing([-360.0, -270.0, -180.0], [-10.0, 10.0, 0.0])
    assert [(v.channel, v.frames) for v in joint_range_violations(m, [ref, down])] == [
        (("b", "rz"), 1), (("a", "rz"), 2)]
    with pytest.raises(ParameterError, match="margin"):
        joint_range_violations(m, [ref], margin_deg=-1.0)
    with pytest.raises(ParameterError, match="reference"):
        joint_range_violations(m, [ref, "ref"])
    with pytest.raises(ParameterError, match="Motion"):
        joint_range_violations("m", [ref])


def test_a_ball_joint_is_judged_by_its_rotation_not_its_euler_angles():
    """A joint with three rotation channels (ZXY) whose references turn it (z, x, y) =
    (10, 30, 20) and (20, 40, 30): (190, 150, 200) is the same rotation as the first
    (the other Euler solution, z + 180, 180 - x, y + 180), so its channels' 170-180 degree
    excesses are no violation; (10, 30, 120) is 100 degrees from either, and its y
    channel is out (z and x are within their ranges); (10, 32, 22), 3 degrees away, is in
    on every channel."""
    from scipy.spatial.transform import Rotation

    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz"), ""),
                   Joint("ball", 0, [0, 1.0, 0], ("rz", "rx", "ry"), "ZXY"),
                   Joint("tip", 1, [0, 1.0, 0]),
                   Joint("side", 0, [1.0, 0, 0]),
                   Joint("side_tip", 3, [1.0, 0, 0])))

    def motion(rows):
        f = np.zeros((len(rows), 6))
        f[:, 3:] = rows
        return cc.Motion(f, sk.channels, fps=30, skeleton=sk)

    ref = motion([[10.0, 30.0, 20.0], [20.0, 40.0, 30.0]])
    same = Rotation.from_euler("ZXY", [190.0, 150.0, 200.0], degrees=True)
    assert same.approx_equal(Rotation.from_euler("ZXY", [10.0, 30.0, 20.0], degrees=True))
    assert joint_range_violations(motion([[190.0, 150.0, 200.0]]), [ref]) == []
    assert joint_range_violations(motion([[10.0, 32.0, 22.0]]), [ref]) == []
    (far,) = joint_range_violations(motion([[10.0, 30.0, 120.0]]), [ref])
    assert far.channel == ("ball", "ry") and far.excess == pytest.approx(85.0)
    # the same through check_plausibility's cached path
    report = check_plausibility(motion([[190.0, 150.0, 200.0], [10.0, 30.0, 120.0]]), [ref],
                                cache={})
    assert [(v.channel, v.frames, v.first_frame) for v in report.joint_range] == [
        (("ball", "ry"), 1, 1)]


def test_new_contacts_against_the_references_closest_approach():
    """Clearance 1.5 on (a, b), at sqrt(5 + 4 cos th).  A reference that comes within
    sqrt(3) (th = 120, beyond the clearance) lets the motion come to 1.5 - 0.15 = 1.35
    before a contact is new; one that comes to _d(150) (1.24) lets it come to
    1.24 - 0.15.  Closer is new, not so close is listed but explained."""
    far = _swing([0.0, 120.0])
    th_135 = np.degrees(np.arccos((1.4**2 - 5) / 4))  # (a, b) at 1.4
    m = _swing([0.0, th_135, 180.0])
    rep = check_plausibility(m, [far], threshold=1.5, margin_deg=90.0)
    (c,) = rep.contacts
    assert c["bones"] == ["a", "b"] and c["frames"] == 2 and c["first_frame"] == 1
    assert c["new"] and c["reference_min_distance"] == pytest.approx(np.sqrt(3))
    assert rep.new_contact_frames == [2]  # 1.4 is not under 1.35; 1 is
    near = _swing([0.0, 150.0])
    th_160 = _swing([0.0, 160.0, 170.0])
    rep = check_plausibility(th_160, [near], threshold=1.5, margin_deg=90.0)
    (c,) = rep.contacts
    assert c["reference_min_distance"] == pytest.approx(_d(150))
    # 160: 1.114, not under 1.239 - 0.15 = 1.089; 170: 1.031, under it
    assert rep.new_contact_frames == [2] and c["new"]
    rep = check_plausibility(_swing([0.0, 160.0]), [near], threshold=1.5, margin_deg=90.0)
    assert rep.new_contact_frames == [] and not rep.contacts[0]["new"] and rep.clean
    assert any(n.startswith("1 bone pairs come within the clearance 1.5") for n in rep.notes)
    assert any(n.startswith("2 pairs of neighbouring bones") for n in rep.notes)


def test_without_references_every_contact_is_new_and_ranges_are_not_checked():
    rep = check_plausibility(_swing([0.0, 170.0, 180.0], start_frame=5), threshold=1.5)
    assert rep.new_contact_frames == [6, 7] and rep.joint_range == []
    assert rep.contacts[0]["reference_min_distance"] is None and rep.contacts[0]["new"]
    assert not rep.clean
    note = rep.notes[-1]
    assert note == ("1 bone pairs come closer than the inputs ever do, e.g. a and b at 1 "
                    "(clearance 1.5, inputs' closest n/a)")
    assert rep.summary().splitlines()[0] == "plausibility: new limb contacts in 2 frames"
    d = rep.to_dict()
    assert d["clean"] is False and d["n_frames"] == 3 and d["threshold"] == 1.5
    assert d["new_contact_frames"] == [6, 7] and d["joint_range_violations"] == []
    clean = check_plausibility(_swing([0.0, 10.0]), threshold=0.5)
    assert clean.clean and clean.contacts == [] and clean.summary() == (
        "plausibility: clean\n  no bones closer than 0.5 and every joint angle within the "
        "inputs' range")


def test_the_summary_counts_joint_angles_out_of_range():
    ref = _swing([0.0, 90.0])
    rep = check_plausibility(_swing([0.0, 120.0]), [ref], threshold=0.5)
    assert rep.new_contact_frames == [] and len(rep.joint_range) == 1 and not rep.clean
    assert rep.summary().splitlines()[0] == "plausibility: 1 joint angles outside the inputs' range"
    assert rep.notes == ["1 joint angles leave the inputs' range (+-5 deg), worst a.rz at 120.0 "
                         "(allowed -5.0 to 95.0)"]


def test_root_channels_are_not_joint_angles():
    """The root turned 90 degrees and moved (its channels are not joint angles) while the
    references never turn it: no violation; the joints' own angles are still checked."""
    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
                   Joint("a", 0, [1.0, 0, 0], ("rz",), "Z"), Joint("a2", 1, [1.0, 0, 0])))
    ref = cc.Motion(np.zeros((3, 7)), sk.channels, fps=30, skeleton=sk)
    f = np.zeros((3, 7))
    f[:, 0] = [0.0, 50.0, 100.0]
    f[:, 5] = 90.0
    assert joint_range_violations(cc.Motion(f, sk.channels, fps=30, skeleton=sk), [ref]) == []
    f[1, 6] = 10.0
    (v,) = joint_range_violations(cc.Motion(f, sk.channels, fps=30, skeleton=sk), [ref])
    assert v.channel == ("a", "rz") and v.excess == pytest.approx(5.0)


def test_a_reference_turning_through_180_degrees_is_unwrapped():
    """A reference going 170, 179, -179, -170 turns steadily through 180 (unwrapped: 170
    to 190): the allowed range is 165 to 195, so -175 (185) is inside and 0 is 165 degrees
    outside it (nearest turn)."""
    ref = _swing([170.0, 179.0, -179.0, -170.0])
    assert joint_range_violations(_swing([-175.0, 175.0]), [ref]) == []
    (v,) = [v for v in joint_range_violations(_swing([0.0, 180.0]), [ref]) if v.channel[0] == "a"]
    assert (v.low, v.high, v.frames, v.first_frame) == (165.0, 195.0, 1, 0)
    assert v.excess == pytest.approx(165.0)


def test_violations_are_frozen_and_two_bones_are_enough():
    import dataclasses

    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    (v,) = [v for v in joint_range_violations(_swing([0.0, 120.0]), [_swing([0.0, 90.0])])]
    with pytest.raises(dataclasses.FrozenInstanceError):
        v.frames = 0
    two = Skeleton((Joint("root", -1, [0.0, 0.0, 0.0]), Joint("p", 0, [0.0, 2.0, 0.0]),
                    Joint("q", 1, [1.0, 0.0, 0.0])))
    bn = bones(Motion(np.zeros((1, 0)), (), skeleton=two))
    assert bn.names == ["root", "p"] and bn.pairs.shape == (0, 2)


def test_contacts_count_their_frames_in_the_motions_numbering():
    rep = check_plausibility(_swing([0.0, 170.0, 180.0, 0.0, 175.0], start_frame=5),
                             threshold=1.5)
    (c,) = rep.contacts
    assert c["frames"] == 3 and c["first_frame"] == 6
    assert c["min_distance"] == pytest.approx(1.0)
    assert rep.new_contact_frames == [6, 7, 9]


def test_a_reference_listing_the_bones_the_other_way_round_explains_the_contact():
    """The same rig with b's arm written before a's: its pair is (b, a), the motion's
    (a, b); matched by bone names either way round, the reference's own approach (1, arm a
    turned 180 degrees) explains the motion's."""
    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz"), ""),
                   Joint("b", 0, [-1.0, 0, 0], ("rz",), "Z"), Joint("b2", 1, [0, 0, 1.0]),
                   Joint("a", 0, [1.0, 0, 0], ("rz",), "Z"), Joint("a2", 3, [1.0, 0, 0])))
    f = np.zeros((2, 5))
    f[:, 4] = [0.0, 180.0]
    ref = cc.Motion(f, sk.channels, fps=30, skeleton=sk)
    assert ("b", "a") in bones(ref).pair_names()
    rep = check_plausibility(_swing([0.0, 180.0]), [ref], threshold=1.5, margin_deg=90.0)
    (c,) = rep.contacts
    assert c["reference_min_distance"] == pytest.approx(1.0) and not c["new"]
    assert rep.new_contact_frames == [] and rep.clean


def test_siblings_exactly_the_tolerance_apart_are_one_node():
    """Siblings p and q 2**-17 apart, in a skeleton whose total length L makes the
    tolerance 1e-6 L exactly 2**-17 (the bone r is cut to that length): at the tolerance
    is within it, so root>p and root>q are one bone."""
    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    d = 2.0**-17
    skel = Skeleton((
        Joint("root", -1, [0.0, 0.0, 0.0]),
        Joint("p", 0, [0.0, 2.0, 0.0]),
        Joint("q", 0, [d, 2.0, 0.0]),
        Joint("p1", 1, [1.0, 0.0, 0.0]),
        Joint("q1", 2, [-1.0, 0.0, 0.0]),
        Joint("r", 0, [0.0, 0.0, 1.6293945312354476]),
    ))
    m = Motion(np.zeros((1, 0)), (), skeleton=skel)
    pos = m.positions().positions[0]
    assert 1e-6 * skel.total_length() == d and np.linalg.norm(pos[1] - pos[2]) == d
    assert bones(m).names == ["root>p", "p", "q", "root>r"]


def test_check_plausibility_cache_reuses_a_report_only_for_the_same_joint_angles(monkeypatch):
    """With ``cache=``, a motion whose joint angles match an earlier call's (its root
    moved elsewhere: no bone moves against another) gets that report without measuring
    again, a copy the caller may change; other joint angles, or other references, are
    measured afresh and read as without the cache."""
    import cyclecoord.quality.plausibility as plaus

    m = cc.datasets.make_periodic_capture(kind="walk", n_frames=80, random_state=0).motion
    ref = cc.datasets.make_periodic_capture(kind="walk", n_frames=80, random_state=1).motion
    calls = []
    real = plaus.self_intersections
    monkeypatch.setattr(plaus, "self_intersections", lambda *a, **k: calls.append(1) or real(*a, **k))
    cache: dict = {}
    first = plaus.check_plausibility(m, [ref], cache=cache)
    moved = m.frames.copy()
    root = [m.channel_index(m.skeleton.joints[0].name, d) for d in ("tx", "tz", "ry")]
    moved[:, root] += [3.0, -2.0, 40.0]
    again = plaus.check_plausibility(m.with_frames(moved), [ref], cache=cache)
    assert len(calls) == 1 and again.to_dict() == first.to_dict()
    again.notes.append("changed by the caller")
    assert "changed by the caller" not in plaus.check_plausibility(m, [ref], cache=cache).notes
    bent = m.frames.copy()
    knee = m.channel_index("ltibia", "rx")
    bent[:, knee] += 30.0
    fresh = plaus.check_plausibility(m.with_frames(bent), [ref], cache=cache)
    # (measured again where the knee moves only: the last motion checked stands for a base)
    assert len(calls) == 1
    assert fresh.to_dict() == plaus.check_plausibility(m.with_frames(bent), [ref]).to_dict()
    assert len(calls) == 2
    other = plaus.check_plausibility(m, [ref, m], cache=cache)  # (its bones measured before)
    assert len(calls) == 2 and other.to_dict() == plaus.check_plausibility(m, [ref, m]).to_dict()


def test_self_intersections_may_skip_pairs_a_body_apart():
    """``far="skip"`` leaves out pairs whose bones never come within the clearance of
    each other's bounding sphere: every flag and every distance under the clearance is
    as measured, the skipped ones read infinity (they are farther apart than that)."""
    walk = cc.datasets.make_periodic_capture(kind="walk", n_frames=120, random_state=3).motion
    for thr in (0.5, 2.0, 6.0):
        full = self_intersections(walk, thr)
        quick = self_intersections(walk, thr, far="skip")
        assert (quick.flagged == full.flagged).all()
        skipped = np.isinf(quick.distances)
        assert skipped.any() and (full.distances[skipped] >= thr).all()
        np.testing.assert_array_equal(quick.distances[~skipped], full.distances[~skipped])
        under = full.distances < thr
        np.testing.assert_array_equal(quick.distances[under], full.distances[under])
    with pytest.raises(ParameterError, match="far"):
        self_intersections(walk, 1.0, far="nowhere")


def test_check_plausibility_base_measures_only_the_pairs_a_changed_joint_moves(monkeypatch):
    """With ``base=`` (a motion checked before with the same cache), a motion that changes
    some joints' channels on some frames is measured again only on the bone pairs those
    joints move, on those frames: the report and every distance read as a fresh check's,
    while far fewer distances are computed."""
    import cyclecoord.quality.plausibility as plaus

    m = cc.datasets.make_periodic_capture(kind="walk", n_frames=90, random_state=2).motion
    ref = cc.datasets.make_periodic_capture(kind="walk", n_frames=90, random_state=5).motion
    cache: dict = {}
    plaus.check_plausibility(m, [ref], cache=cache)
    frames = m.frames.copy()
    frames[20:50, m.channel_index("ltibia", "rx")] += 35.0  # the left shin swings in ...
    frames[30:40, m.channel_index("lfemur", "rz")] -= 25.0  # ... and the thigh crosses
    trial = m.with_frames(frames)
    sizes = []
    real = plaus._element_distances
    monkeypatch.setattr(plaus, "_element_distances",
                        lambda mo, bn, which: sizes.append(int(which.sum())) or real(mo, bn, which))
    quick = plaus.check_plausibility(trial, [ref], cache=cache, base=m)
    assert quick.to_dict() == plaus.check_plausibility(trial, [ref]).to_dict()
    inter = cache[("intersections", plaus._signature(trial, True), None)][1]
    full = self_intersections(trial, inter.threshold)
    near = np.isfinite(inter.distances)
    np.testing.assert_array_equal(inter.distances[near], full.distances[near])
    assert (full.distances[~near] >= inter.threshold).all()
    assert (inter.flagged == full.flagged).all()
    fresh = plaus._near_elements(trial.positions().positions, inter.bones, inter.threshold).sum()
    assert 0 < sizes[0] < fresh / 3  # (the other frames and pairs are base's)
    # not comparable (another length): measured afresh, the same report
    short = m.window((0, 60))
    assert plaus.check_plausibility(short, [ref], cache=cache, base=m).to_dict() == (
        plaus.check_plausibility(short, [ref]).to_dict())


def test_check_plausibility_analysed_skips_finding_the_rig_and_reads_the_same():
    """``analysed=True`` (the motion and references already in the analysis rig) gives
    the report the rig search would give on such a motion."""
    m = cc.datasets.make_periodic_capture(kind="walk", n_frames=60, random_state=0).motion
    ref = cc.datasets.make_periodic_capture(kind="walk", n_frames=60, random_state=1).motion
    assert cc.rig.analysis_motion(m) is m
    plain = check_plausibility(m, [ref]).to_dict()
    assert check_plausibility(m, [ref], analysed=True).to_dict() == plain
    assert check_plausibility(m, [ref], cache={}, analysed=True).to_dict() == plain


def test_segment_parameters_give_the_closest_points():
    """The fractions along each segment give points as far apart as segment_distances
    says, inside both segments, and no sampled pair of points is closer."""
    from cyclecoord.quality.bones import segment_parameters

    rng = np.random.default_rng(3)
    p0, p1, q0, q1 = rng.normal(size=(4, 200, 3))
    p1[:5] = p0[:5]  # a point against a segment
    s, t = segment_parameters(p0, p1, q0, q1)
    assert ((s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)).all()
    gap = np.linalg.norm(p0 + s[:, None] * (p1 - p0) - q0 - t[:, None] * (q1 - q0), axis=1)
    np.testing.assert_allclose(gap, segment_distances(p0, p1, q0, q1), atol=1e-12)
    u = np.linspace(0, 1, 41)
    a = p0[:, None] + u[None, :, None] * (p1 - p0)[:, None]
    b = q0[:, None] + u[None, :, None] * (q1 - q0)[:, None]
    sampled = np.linalg.norm(a[:, :, None] - b[:, None, :], axis=-1).min(axis=(1, 2))
    assert (gap <= sampled + 1e-12).all()
