"""Feet and named joints on any rig (issue 23 part 3): the naming table, the geometric
fallback, quadrupeds, ``--feet`` parsing and every shared rig's feet found without options."""

from dataclasses import replace

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from cyclecoord.joint_names import (
    RIG_NAMINGS,
    JointRole,
    classify_joint,
    classify_skeleton,
    is_ignored_name,
    name_words,
)
from cyclecoord.motion import Motion
from cyclecoord.quality.contacts import find_feet, foot_contacts, foot_skating, leg_length
from cyclecoord.quality.legs import find_legs, legs_of_feet, resolve_feet
from cyclecoord.skeleton import Joint, Skeleton
from cyclecoord.synthesis.footlock import lock_feet
from _walkers import (  # tests/ is on the path (rootdir conftest)
    biped_names,
    biped_skeleton,
    biped_walk,
    quadruped_names,
    quadruped_skeleton,
    trot,
)


# ------------------------------------------------------------------ the naming table
def convention_skeleton(rig) -> Skeleton:
    """A minimal standing skeleton in a rig's naming convention: trunk up, legs down
    (toes forward, +z), arms out sideways; left at +x."""
    joints: list[Joint] = []
    index: dict[str, int] = {}

    def add(name, parent, offset, end=None):
        index[name] = len(joints)
        joints.append(Joint(name, -1 if parent is None else index[parent], offset,
                            end_site=end))

    prev = None
    for name, _ in rig.trunk:
        add(name, prev, [0, 0, 0] if prev is None else [0, 2.0, 0])
        prev = name
    # legs hang from the pelvis (or the first trunk joint when the root is a ground joint)
    pelvis = next(n for n, r in rig.trunk if r == "pelvis") if any(
        r == "pelvis" for _, r in rig.trunk) else rig.trunk[0][0]
    for side, x in (("left", 1.0), ("right", -1.0)):
        names = rig.names(side, "leg")
        parent = pelvis
        for k, name in enumerate(names):
            role = rig.roles("leg")[k]
            offset = {"pelvis": [x * 0.5, -0.5, 0], "hip": [x * 0.5, -0.5, 0],
                      "knee": [0, -4.0, 0], "ankle": [0, -4.0, 0], "toe": [0, -0.5, 1.0]}[role]
            add(name, parent, offset, end=[0, 0, 0.5] if role == "toe" else None)
            parent = name
        parent = rig.arm_parent
        for name in rig.names(side, "arm"):
            add(name, parent, [x * 1.5, 0, 0])
            parent = name
    return Skeleton(tuple(joints), name=rig.key)


@pytest.mark.parametrize("rig", RIG_NAMINGS, ids=lambda r: r.key)
def test_every_convention_classifies_its_joints(rig):
    skel = convention_skeleton(rig)
    roles = classify_skeleton(skel)
    for name, role in rig.trunk:
        got = roles.get(name)
        assert (got.role if got else "") == role, name
        assert got is None or got.side is None, name
    for side in ("left", "right"):
        for part in ("leg", "arm"):
            for name, role in zip(rig.names(side, part), rig.roles(part)):
                assert roles.get(name) == JointRole(role, side), (name, roles.get(name))


@pytest.mark.parametrize("rig", RIG_NAMINGS, ids=lambda r: r.key)
def test_every_convention_finds_its_feet(rig):
    skel = convention_skeleton(rig)
    legs = find_legs(skel)
    assert legs.method == "names"
    left, right = rig.names("left", "leg"), rig.names("right", "leg")
    assert legs.feet == (left[-2], left[-1], right[-2], right[-1])
    assert legs.sides == ("left", "left", "right", "right")
    assert leg_length(skel) == pytest.approx(8.0)
    # the same skeleton with its names taken away: the geometry gives the same joints
    anon = anonymous(skel)
    legs = find_legs(anon[0])
    back = {v: k for k, v in anon[1].items()}
    assert tuple(back[f] for f in legs.feet) == (left[-2], left[-1], right[-2], right[-1])
    assert legs.method == "geometry"


def anonymous(skel: Skeleton, motion: Motion | None = None):
    """``skel`` (and ``motion``) with joints renamed j0, j1, ...; returns the renaming too."""
    new = {n: f"j{i}" for i, n in enumerate(skel.names)}
    anon = Skeleton(tuple(replace(j, name=new[j.name]) for j in skel.joints), name="anon")
    if motion is None:
        return anon, new
    m = Motion(motion.frames, tuple((new[a], d) for a, d in motion.channels), fps=motion.fps,
               skeleton=anon)
    return anon, new, m


@pytest.mark.parametrize(
    "name, expected",
    [
        ("lfoot", JointRole("ankle", "left")),
        ("rtoes", JointRole("toe", "right")),
        ("lhipjoint", JointRole("pelvis", "left")),
        ("mixamorig:RightToeBase", JointRole("toe", "right")),
        ("mixamorig1:LeftUpLeg", JointRole("hip", "left")),
        ("Character1_LeftFoot", JointRole("ankle", "left")),
        ("Foot_L", JointRole("ankle", "left")),
        ("foot.R", JointRole("ankle", "right")),
        ("ball_r", JointRole("toe", "right")),
        ("calf_l", JointRole("knee", "left")),
        ("L_Ankle", JointRole("ankle", "left")),
        ("left_knee", JointRole("knee", "left")),
        ("RightAnkle", JointRole("ankle", "right")),
        ("Bip01 R Toe0", JointRole("toe", "right")),
        ("DEF-thigh.L", JointRole("hip", "left")),
        ("LEFTFOOT", None),  # one word in capitals: no side can be read off
        ("LeftFrontLeg", JointRole("knee", "left", "front")),
        ("RightHindFoot", JointRole("ankle", "right", "hind")),
        ("FrontLeftFoot", JointRole("ankle", "left", "front")),
        ("BackRightToe", JointRole("toe", "right", "hind")),
        ("LowerBack", JointRole("spine")),
        ("LeftForeArm", JointRole("elbow", "left")),
        ("LeftHandIndex1", JointRole("fingers", "left")),
        ("T12", JointRole("spine")),
        ("Hips", JointRole("pelvis")),
        ("j12", None),
        ("LeftToe_End", None),
        ("calf_twist_01_l", None),
        ("ik_foot_l", None),
        ("Prop1", None),
        ("Foot", None),  # a foot needs a side
    ],
)
def test_classify_joint(name, expected):
    assert classify_joint(name) == expected


def test_name_words_and_ignored():
    assert name_words("mixamorig:LeftToeBase") == ["left", "toe", "base"]
    assert name_words("LHipJoint") == ["l", "hip", "joint"]
    assert name_words("Bip01 L Toe0") == ["bip", "01", "l", "toe", "0"]
    assert is_ignored_name("HeadTop_End") and is_ignored_name("Prop2")
    assert not is_ignored_name("LeftToeBase")


def test_twist_and_ik_bones_are_not_feet():
    """The Unreal mannequin's ik_foot_l under the root and twist bones are left out."""
    rig = next(r for r in RIG_NAMINGS if r.key == "unreal")
    skel = convention_skeleton(rig)
    extra = (
        Joint("ik_foot_root", 0, [0, 0, 0]),
        Joint("ik_foot_l", len(skel.joints), [1, 0, 0]),
        Joint("calf_twist_01_l", skel.index("calf_l"), [0, -2, 0]),
    )
    skel = Skeleton(skel.joints + extra)
    assert find_feet(skel) == ("foot_l", "ball_l", "foot_r", "ball_r")


# ------------------------------------------------------------------ geometric fallback
@pytest.mark.parametrize("heading", [0.0, 90.0, 200.0])
def test_geometry_finds_legs_and_sides_ignoring_arms_and_prop(heading):
    """Joints named j0..j21 (a long prop in the right hand reaching below the knee): the
    legs and their sides come from the walk, whichever way it heads."""
    names = biped_names()
    skel = biped_skeleton(names)
    motion = biped_walk(skel, names, heading_deg=heading)
    legs = find_legs(skel, motion)
    assert legs.method == "geometry"
    assert legs.feet == (names["l_ankle"], names["l_toe"], names["r_ankle"], names["r_toe"])
    assert legs.sides == ("left", "left", "right", "right")
    c = foot_contacts(motion)
    assert c.feet == legs.feet
    assert 0.4 < c.side_planted("left").mean() < 0.8
    assert foot_skating(motion, c).skating_frames == 0


def test_geometry_in_the_rest_pose_and_right_leg_first():
    """Without a motion the rest pose decides; sides come from where the toes point, not
    from the order of the hierarchy."""
    names = biped_names()
    skel = biped_skeleton(names)
    legs = find_legs(skel)
    assert legs.feet == (names["l_ankle"], names["l_toe"], names["r_ankle"], names["r_toe"])
    # mirror: the toes point to -z, so the joint at +x is now the right leg
    flipped = Skeleton(tuple(
        replace(j, offset=j.offset * [1, 1, -1],
                end_site=None if j.end_site is None else j.end_site * [1, 1, -1])
        for j in skel.joints))
    legs = find_legs(flipped)
    assert legs.feet == (names["r_ankle"], names["r_toe"], names["l_ankle"], names["l_toe"])


def test_geometry_ankle_without_toe_joint():
    """A leg ending at the ankle (its end site the toe) gives the ankle alone."""
    joints = [Joint("j0", -1, [0, 0, 0], ("tx", "ty", "tz"), "")]
    for x in (1.0, -1.0):
        base = len(joints)
        joints += [Joint(f"j{base}", 0, [x, 0, 0]), Joint(f"j{base + 1}", base, [0, -4, 0]),
                   Joint(f"j{base + 2}", base + 1, [0, -4, 0], end_site=[0, -0.5, 1.0])]
    joints.append(Joint("j7", 0, [0, 5, 0], end_site=[0, 1, 0]))
    legs = find_legs(Skeleton(tuple(joints)))
    assert legs.feet == ("j3", "j6")
    assert legs.sides == ("left", "right")


def test_no_feet_message_lists_candidates_and_the_option():
    arm = Skeleton((Joint("j0", -1, [0, 0, 0]), Joint("j1", 0, [1, 0, 0]),
                    Joint("j2", 1, [1, 0, 0])))
    with pytest.raises(ParameterError) as err:
        find_legs(arm)
    text = str(err.value)
    assert "--feet LEFT,RIGHT" in text and "j2" in text and "foot joints" in text
    assert "e.g. --feet LEFT,RIGHT;" in text  # one end joint: no pair to suggest


def test_no_feet_message_suggests_the_two_lowest_end_joints():
    """With two or more end joints and no legs found, the example is the two lowest."""
    arms = Skeleton((Joint("j0", -1, [0, 0, 0]), Joint("j1", 0, [1, 1, 0]), Joint("j2", 1, [0, 1, 0]),
                     Joint("j3", 0, [-1, 1, 0]), Joint("j4", 3, [0, 3, 0])))
    with pytest.raises(ParameterError) as err:
        find_legs(arms)
    assert "e.g. --feet j2,j4;" in str(err.value)


# ------------------------------------------------------------------ quadrupeds
@pytest.mark.parametrize("style", ["anonymous", "dog", "front_first", "human"])
def test_quadruped_trot_four_feet(style):
    names = quadruped_names(style)
    skel = quadruped_skeleton(names)
    motion = trot(skel, names)
    legs = find_legs(skel, motion)
    expected = {
        "front left": "fl", "front right": "fr", "hind left": "hl", "hind right": "hr",
    }
    assert [g.label for g in legs.legs] == list(expected)
    for g in legs.legs:
        key = expected[g.label]
        assert g.points == (names[f"{key}_ankle"], names[f"{key}_toe"]), g
    assert legs.method == {"anonymous": "geometry", "human": "names and geometry"}.get(
        style, "names")
    c = foot_contacts(motion)
    assert c.feet == legs.feet
    assert c.leg_length == pytest.approx(8.0)
    fl, fr = c.side_planted("front left"), c.side_planted("front right")
    hl, hr = c.side_planted("hind left"), c.side_planted("hind right")
    # a trot: diagonal legs planted together, the two front legs in turn
    assert (fl == hr).mean() > 0.95 and (fr == hl).mean() > 0.95
    assert (fl & ~fr).any() and (fr & ~fl).any()
    # "left" covers both left legs
    assert np.array_equal(c.side_planted("left"), fl | hl)
    assert foot_skating(motion, c).skating_frames == 0


def test_quadruped_rest_pose_and_given_feet():
    names = quadruped_names("anonymous")
    skel = quadruped_skeleton(names)
    assert [g.label for g in find_legs(skel).legs] == [
        "front left", "front right", "hind left", "hind right"]
    motion = trot(skel, names)
    given = (names["hr_ankle"], names["fl_toe"], names["hl_ankle"], names["fr_ankle"])
    legs = legs_of_feet(skel, given, motion)
    assert [g.label for g in legs.legs] == ["hind right", "front left", "hind left",
                                            "front right"]


def test_lock_feet_on_a_quadruped():
    """Foot locking solves each of the four legs on its own."""
    names = quadruped_names("dog")
    skel = quadruped_skeleton(names)
    motion = trot(skel, names)
    frames = motion.frames.copy()
    col = motion.channel_index(names["pelvis"], "tx")
    frames[:, col] += 0.05 * np.arange(motion.n_frames)  # drift sideways: feet skate
    sliding = motion.with_frames(frames)
    result = lock_feet(sliding)
    assert result.before.skating_frames > 0
    assert result.after.skating_frames < 0.2 * result.before.skating_frames
    assert set(result.contacts.legs) == {"front left", "front right", "hind left",
                                         "hind right"}


# ------------------------------------------------------------------ --feet
def test_resolve_feet_forms_and_errors():
    rig = next(r for r in RIG_NAMINGS if r.key == "mixamo")
    skel = convention_skeleton(rig)
    assert resolve_feet(skel, "mixamorig:LeftFoot,mixamorig:RightFoot") == (
        "mixamorig:LeftFoot", "mixamorig:RightFoot")
    assert resolve_feet(
        skel, "mixamorig:LeftFoot:mixamorig:LeftToeBase,mixamorig:RightFoot:mixamorig:RightToeBase"
    ) == ("mixamorig:LeftFoot", "mixamorig:LeftToeBase", "mixamorig:RightFoot",
          "mixamorig:RightToeBase")
    with pytest.raises(ParameterError, match="nearest: mixamorig:LeftFoot"):
        resolve_feet(skel, "mixamorig:LeftFot,mixamorig:RightFoot")
    with pytest.raises(ParameterError, match="two .* or four"):
        resolve_feet(skel, "mixamorig:LeftFoot")
    with pytest.raises(ParameterError, match="not below"):
        resolve_feet(skel, "mixamorig:LeftToeBase:mixamorig:LeftFoot,mixamorig:RightFoot")
    cmu = convention_skeleton(RIG_NAMINGS[0])
    assert resolve_feet(cmu, "lfoot:ltoes, rfoot:rtoes") == ("lfoot", "ltoes", "rfoot", "rtoes")
    with pytest.raises(ParameterError, match=r"no joint 'lfot'.*nearest: lfoot"):
        resolve_feet(cmu, "lfot,rfoot")


def test_given_feet_get_sides_from_geometry():
    names = biped_names()
    skel = biped_skeleton(names)
    motion = biped_walk(skel, names, heading_deg=45)
    c = foot_contacts(motion, feet=(names["r_toe"], names["l_toe"]))
    assert c.sides == ("right", "left")
    # toes alone: the leg is measured from the ankle above them
    assert leg_length(skel, (names["r_toe"], names["l_toe"])) == pytest.approx(8.0)


# ------------------------------------------------------------------ shared captures
SHARED = {
    "bandai/dataset-1_walk_normal_001.bvh": ("Foot_L", "Toes_L", "Foot_R", "Toes_R"),
    "bandai/dataset-1_walk-back_sad_001.bvh": ("Foot_L", "Toes_L", "Foot_R", "Toes_R"),
    "bandai/dataset-1_run_happy_001.bvh": ("Foot_L", "Toes_L", "Foot_R", "Toes_R"),
    "bandai/dataset-2_walk-turn-left_normal_011.bvh": ("Foot_L", "Toes_L", "Foot_R", "Toes_R"),
    "bandai/dataset-2_walk-turn-right_normal_029.bvh": ("Foot_L", "Toes_L", "Foot_R",
                                                        "Toes_R"),
    "xsens/S02-Trial-Walk-1.bvh": ("LeftAnkle", "LeftToe", "RightAnkle", "RightToe"),
}


@pytest.mark.parametrize("path", sorted(SHARED))
def test_shared_bvh_feet_by_name_and_by_geometry(bvh_dir, path):
    motion = cc.load(bvh_dir / path)
    assert find_feet(motion.skeleton, motion) == SHARED[path]
    c = foot_contacts(motion)
    assert c.feet == SHARED[path] and c.sides == ("left", "left", "right", "right")
    assert c.planted.mean() > 0.1
    # names taken away: the motion's geometry finds the same joints and sides (the Xsens
    # prop under the right wrist is not a foot)
    _, new, anon = anonymous(motion.skeleton, motion)
    legs = find_legs(anon.skeleton, anon)
    assert legs.feet == tuple(new[f] for f in SHARED[path])
    assert legs.sides == ("left", "left", "right", "right")


@pytest.mark.parametrize("subject, take", [("69", "69_01"), ("143", "143_01"),
                                           ("01", "01_09"), ("35", "35_07")])
def test_shared_cmu_feet_by_name_and_by_geometry(cmu_dir, subject, take):
    motion = cc.load(cmu_dir / subject / f"{take}.amc")
    assert find_feet(motion.skeleton, motion) == ("lfoot", "ltoes", "rfoot", "rtoes")
    _, new, anon = anonymous(motion.skeleton, motion)
    assert find_feet(anon.skeleton, anon) == tuple(
        new[f] for f in ("lfoot", "ltoes", "rfoot", "rtoes"))


def test_person_on_all_fours_keeps_two_legs():
    """A rig named like a person whose hands reach the floor in the take (crawling) keeps
    two legs when its rest pose holds the arms up: only a rig that stands on four in its
    rest pose (a dog named like a person) gets front legs from the geometry."""
    names = quadruped_names("human")
    dog = quadruped_skeleton(names)
    arms = {names[f"{leg}_{p}"] for leg in ("fl", "fr") for p in ("knee", "ankle", "toe")}
    # the same body with the arms raised in the rest pose (bones pointing up and back) ...
    raised = Skeleton(tuple(
        replace(j, offset=j.offset * [1, -1, -1],
                end_site=None if j.end_site is None else j.end_site * [1, -1, -1])
        if j.name in arms else j
        for j in dog.joints))
    motion = trot(dog, names)
    frames = motion.frames.copy()
    for leg in ("fl", "fr"):  # ... turned down at the shoulder: the same crawl
        frames[:, motion.channel_index(names[f"{leg}_hip"], "rx")] += 180.0
    crawl = Motion(frames, motion.channels, fps=motion.fps, skeleton=raised)
    np.testing.assert_allclose(crawl.positions().positions, motion.positions().positions,
                               atol=1e-9)
    assert find_legs(dog, motion).method == "names and geometry"
    legs = find_legs(raised, crawl)
    assert legs.method == "names" and legs.feet == ("LeftFoot", "LeftToeBase", "RightFoot",
                                                    "RightToeBase")


def test_hands_mostly_off_the_floor_stay_arms():
    """A dog rig named like a person gets front legs from the geometry only when its
    hands stay low in the take (median within 0.15 of the body height): paws in the air
    80 % of the time, 4 units high (median 0.22 of the height), leave two legs."""
    from cyclecoord.quality.legs import _Geometry

    names = quadruped_names("human")
    dog = quadruped_skeleton(names)
    assert find_legs(dog, trot(dog, names)).method == "names and geometry"
    prancing = trot(dog, names, stance=0.2, lift=4.0)
    geo = _Geometry(dog, prancing, "y")
    hands = [e for e in geo.ends if e < len(dog.names) and "Hand" in dog.names[e]]
    assert len(hands) == 2
    assert all(0.2 < geo.median[e] / geo.height < 0.25 and geo.low[e] < 0.01 * geo.height
               for e in hands)
    legs = find_legs(dog, prancing)
    assert legs.method == "names" and [g.label for g in legs.legs] == ["left", "right"]


@pytest.mark.parametrize("trotting", [False, True])
def test_short_quadruped_pairs_legs_where_they_part_lowest(trotting):
    """A body of 4 (legs of about 8): a front and a hind leg are alike enough from the
    pelvis to pair, but the pairs are those whose chains part lowest in the tree (the
    front legs at the chest, the hind legs at the pelvis)."""
    names = quadruped_names("anonymous")
    skel = quadruped_skeleton(names, body=4.0)
    legs = find_legs(skel, trot(skel, names, body=4.0) if trotting else None)
    assert legs.method == "geometry"
    assert [(g.label, g.points) for g in legs.legs] == [
        (label, (names[f"{k}_ankle"], names[f"{k}_toe"]))
        for label, k in (("front left", "fl"), ("front right", "fr"), ("hind left", "hl"),
                         ("hind right", "hr"))
    ]


def test_forward_directions_are_unit_vectors_however_short_the_feet():
    """_Geometry.forward: where the feet point (ankle to toe, the up axis dropped), one unit
    vector a frame, on a frame whose feet point almost straight down too (1.5e-12 units
    forward); a frame on which they point exactly down has none (zeros, not NaN).  With no
    foot pointing anywhere on most frames, the root's travel; without travel, +z."""
    from cyclecoord.quality.legs import _Geometry

    geo = object.__new__(_Geometry)
    geo.up = 1
    pos = np.zeros((4, 3, 3))  # frames, (root, ankle, toe), xyz
    pos[:, 1] = [0.0, 1.0, 0.0]
    pos[:, 2] = [[0.0, 0.0, 3.0], [1.5e-12, 0.0, 0.0], [0.0, 0.0, 0.0], [-2.0, 0.5, 0.0]]
    geo.pos = pos
    fwd = geo.forward([(1, 2)])
    np.testing.assert_allclose(fwd, [[0, 0, 1], [1, 0, 0], [0, 0, 0], [-1, 0, 0]], atol=1e-15)
    # no foot direction: the root's travel from the first frame to the last, else +z
    pos[:, 1] = pos[:, 2] = [0.5, 1.0, 0.0]
    pos[:, 0] = [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 5.0], [3.0, 0.0, 1.0]]
    travel = np.array([2.0, 0.0, 1.0]) / np.sqrt(5.0)
    np.testing.assert_allclose(geo.forward([(1, 2)]), np.tile(travel, (4, 1)), atol=1e-15)
    geo.pos = pos[[0, 3]]  # two frames travel too
    np.testing.assert_allclose(geo.forward([(1, 2)]), np.tile(travel, (2, 1)), atol=1e-15)
    geo.pos = pos
    pos[:, 0] = [1.0, 0.0, 0.0]
    np.testing.assert_array_equal(geo.forward([(1, 2)]), np.tile([0.0, 0.0, 1.0], (4, 1)))
    pos[:, 0] = 0.0
    pos[-1, 0] = [1e-9, 0.0, 0.0]  # a travel of exactly 1e-9 units is none too
    assert np.linalg.norm(pos[-1, 0] - pos[0, 0]) == 1e-9
    np.testing.assert_array_equal(geo.forward([(1, 2)]), np.tile([0.0, 0.0, 1.0], (4, 1)))


def test_grounded_bounds_are_inclusive():
    """_Geometry.grounded: an end whose median height is at most 0.3 of the body height and
    whose 5 % low is at most _GROUND_LOW = 0.1 of it reaches the ground, both bounds included
    (body height 10: a low of exactly 1.0 counts, 1.0 + 1 ulp does not)."""
    from cyclecoord.quality.legs import _GROUND_LOW, _Geometry

    assert _GROUND_LOW * 10.0 == 1.0
    geo = object.__new__(_Geometry)
    geo.height = 10.0
    geo.ends = [0]
    geo.median = np.array([3.0])
    geo.low = np.array([1.0])
    assert geo.grounded() == [0]
    geo.low = np.array([np.nextafter(1.0, 2.0)])
    assert geo.grounded() == []


# ------------------------------------------------------------------ helpers, known answers
def rest_biped(shin_r: float = 4.0, heel: float | None = None) -> Skeleton:
    """Joints j0..j9 in a rest pose, y up, toes forward (+z), left at +x: j0 the pelvis at
    the origin; j1-j4 the left leg (hip [1, -1, 0], knee and ankle 4 down each, toe 0.5
    down and 1 forward, its end site 0.5 further); j5-j8 the right leg (shin ``shin_r``);
    j9 a head 3 up (end site 1 up).  ``heel``: a j10 under the left ankle at that height
    below it (0.4 back)."""
    j = [Joint("j0", -1, [0, 0, 0], ("tx", "ty", "tz"), "")]
    for x, shin in ((1.0, 4.0), (-1.0, shin_r)):
        b = len(j)
        j += [Joint(f"j{b}", 0, [x, -1.0, 0]), Joint(f"j{b + 1}", b, [0, -4.0, 0]),
              Joint(f"j{b + 2}", b + 1, [0, -shin, 0]),
              Joint(f"j{b + 3}", b + 2, [0, -0.5, 1.0], end_site=[0, 0, 0.5])]
    j.append(Joint("j9", 0, [0, 3.0, 0], end_site=[0, 1.0, 0]))
    if heel is not None:
        j.append(Joint("j10", 3, [0, -heel, -0.4]))
    return Skeleton(tuple(j))


def test_legs_feet_sides_labels_and_describe():
    legs = cc.quality.legs.Legs(
        (cc.quality.legs.Leg("front left", "left", "front", ("a", "b")),
         cc.quality.legs.Leg("leg 2", "?", None, ("c",))), "given")
    assert legs.feet == ("a", "b", "c")
    assert legs.sides == ("left", "left", "?")
    assert legs.labels == ("front left", "front left", "leg 2")
    assert legs.describe() == "feet by given: front left a+b, leg 2 c"


def test_nearest_joints_case_count_and_cutoff():
    """difflib's ratio 2 M / (|a| + |b|): "abcd" and "abxxxx" share 2 of 10 letters (0.4,
    over the cutoff 0.3), "abcd" and "axxxxx" 1 of 10 (0.2, under it)."""
    from cyclecoord.quality.legs import nearest_joints

    names = ["LFoot", "lfoot1", "lfoot2", "lfoot3", "lfoot4", "lfoot5", "abxxxx", "axxxxx"]
    skel = Skeleton(tuple(Joint(n, i - 1, [0, 1, 0]) for i, n in enumerate(names)))
    five = nearest_joints(skel, "LFOOT")  # original case, the five closest by default
    assert len(five) == 5 and five[0] == "LFoot" and set(five) < set(names[:6])
    two = nearest_joints(skel, "lfoot", n=2)
    assert len(two) == 2 and two[0] == "LFoot"
    assert nearest_joints(skel, "ABCD") == ["abxxxx"]
    assert nearest_joints(skel, "qqqq") == []


def test_check_feet_contract():
    from cyclecoord.quality.legs import check_feet, feet_names

    skel = rest_biped()
    assert check_feet(skel, ["j4", "j8"]) == ("j4", "j8")
    assert feet_names(skel, ["j4", "j8"]) == ("j4", "j8")
    assert feet_names(skel, "j3:j4,j7:j8") == ("j3", "j4", "j7", "j8")
    with pytest.raises(ParameterError, match="at least one"):
        check_feet(skel, [])
    with pytest.raises(ParameterError, match="twice"):
        check_feet(skel, ["j4", "j8", "j4"])
    with pytest.raises(ParameterError, match=r"no joint 'j44' in skeleton \(unnamed\) \(10 joints\)"):
        check_feet(skel, ["j44"])
    with pytest.raises(ParameterError, match="twice"):  # a sequence is not split at ':'
        feet_names(skel, ["j4", "j4"])


def test_resolve_feet_empty_halves_and_four_legs():
    skel = rest_biped()
    with pytest.raises(ParameterError, match="an empty name"):
        resolve_feet(skel, "j4,,j8")
    with pytest.raises(ParameterError, match="an empty name"):
        resolve_feet(skel, ["j4", ""])
    # one half a joint: the message names the other half; neither: the whole item
    with pytest.raises(ParameterError, match="no joint 'zz'"):
        resolve_feet(skel, "j3:zz,j8")
    with pytest.raises(ParameterError, match="no joint 'zz'"):
        resolve_feet(skel, "zz:j4,j8")
    with pytest.raises(ParameterError, match="no joint 'yy:zz'"):
        resolve_feet(skel, "yy:zz,j8")
    with pytest.raises(ParameterError, match="3 legs"):
        resolve_feet(skel, "j4,j8,j9")
    with pytest.raises(ParameterError, match="1 legs"):
        resolve_feet(skel, "j3:j4")
    # four chains are a quadruped's four legs
    names = quadruped_names("anonymous")
    quad = quadruped_skeleton(names)
    four = [names[f"{k}_toe"] for k in ("fl", "fr", "hl")] + [names["hr_ankle"]]
    assert resolve_feet(quad, ",".join(four)) == tuple(four)
    # the leg's points are checked like any (a joint named twice)
    with pytest.raises(ParameterError, match="twice"):
        resolve_feet(skel, "j3:j4,j4")


def test_group_joins_points_on_one_chain_and_sorts_them_down():
    from cyclecoord.quality.legs import _group

    skel = rest_biped()
    assert _group(skel, ("j4", "j7", "j2", "j9")) == [["j2", "j4"], ["j7"], ["j9"]]
    assert _group(skel, ("j8", "j6", "j5", "j4")) == [["j5", "j6", "j8"], ["j4"]]


def test_ordered_front_unnamed_hind_then_left_right_unknown():
    from cyclecoord.quality.legs import Leg, _ordered

    legs = [Leg("x", s, limb, ()) for limb in ("hind", None, "front") for s in ("?", "right", "left")]
    got = [(g.limb, g.side) for g in _ordered(legs)]
    assert got == [(limb, s) for limb in ("front", None, "hind") for s in ("left", "right", "?")]


def test_named_legs_toe_alone_and_toe_not_below_the_ankle():
    """A leg named by its toe alone gives the toe; an ankle whose named toe hangs elsewhere
    gives the ankle alone."""
    names = {"j3": "lfoot", "j4": "j4", "j8": "rtoes", "j7": "j7", "j10": "ltoes"}
    skel = rest_biped(heel=0.5)
    skel = Skeleton(tuple(replace(j, name=names.get(j.name, j.name)) for j in skel.joints))
    skel = Skeleton(tuple(replace(j, parent=0) if j.name == "ltoes" else j for j in skel.joints))
    legs = find_legs(skel)
    assert legs.method == "names"
    assert [(g.label, g.points) for g in legs.legs] == [("left", ("lfoot",)),
                                                        ("right", ("rtoes",))]


def test_find_legs_up_axis():
    """The same body with its up axis y turned to x (and to z) gives the same feet."""
    skel = rest_biped()
    assert find_legs(skel).feet == ("j3", "j4", "j7", "j8")
    for up, perm in (("x", [1, 0, 2]), ("z", [0, 2, 1])):
        turned = Skeleton(tuple(
            replace(j, offset=j.offset[perm],
                    end_site=None if j.end_site is None else j.end_site[perm])
            for j in skel.joints))
        legs = find_legs(turned, up=up)
        assert set(legs.feet) == {"j3", "j4", "j7", "j8"}, up
        assert legs.method == "geometry"
    with pytest.raises(ParameterError, match="up axis must be one of x, y, z, got 'w'"):
        find_legs(skel, up="w")


def test_geometry_of_the_rest_pose_by_hand():
    """rest_biped's rest pose summed bone by bone: floor at the toes (y -9.5), heights above
    it, body height 12.5 (the head joint at 3; end sites count for lows, not for the
    height), bone lengths the offsets' norms."""
    from cyclecoord.quality.legs import _Geometry

    geo = _Geometry(rest_biped(), None, "y")
    assert geo.in_motion is False
    expected = [[0, 0, 0], [1, -1, 0], [1, -5, 0], [1, -9, 0], [1, -9.5, 1],
                [-1, -1, 0], [-1, -5, 0], [-1, -9, 0], [-1, -9.5, 1], [0, 3, 0]]
    np.testing.assert_array_equal(geo.pos, [expected])
    assert geo.ends == [4, 8, 9]
    assert geo.floor == -9.5
    np.testing.assert_array_equal(geo.median, [9.5, 8.5, 4.5, 0.5, 0, 8.5, 4.5, 0.5, 0, 12.5])
    np.testing.assert_array_equal(geo.low, geo.median)
    assert geo.height == 12.5 and geo.usable
    s2, s125 = np.sqrt(2.0), np.sqrt(1.25)
    np.testing.assert_allclose(geo.bone, [0, s2, 4, 4, s125, s2, 4, 4, s125, 3], rtol=1e-15)
    assert geo.chain(4) == [0, 1, 2, 3, 4] and geo.chain(0) == [0]
    assert geo.part(4, 8) == 0 and geo.part(3, 4) == 3 and geo.part(4, 3) == 3
    assert geo.part(4, 4) == 4 and geo.part(2, 9) == 0
    assert geo.length(0, 4) == pytest.approx(s2 + 8 + s125, rel=1e-15)
    assert geo.length(2, 4) == pytest.approx(4 + s125, rel=1e-15)
    assert geo.length(4, 4) == 0.0
    np.testing.assert_allclose(geo.mean_position(0, 4), [[1, -24.5 / 4, 0.25]], rtol=1e-15)
    np.testing.assert_allclose(geo.mean_position(3, 4), [[1, -9.5, 1]], rtol=1e-15)
    assert geo.grounded() == [4, 8]
    assert geo.foot_points(0, 4) == (3, 4)  # the shin (4) is over a quarter of 10.5
    assert geo.candidates() == ["j4 (0)", "j8 (0)", "j9 (12.5)"]
    assert geo.candidates(1) == ["j4 (0)"]


def test_geometry_end_sites_lower_the_lows_each_its_own():
    """Each joint's low is itself or its own end site, whichever is lower: toe end sites
    0.5 and 0.25 down put the floor at -10 and the right toe at 0.25; the head's end site
    above it leaves the head at its joint (3, 13 above the floor)."""
    from cyclecoord.quality.legs import _Geometry

    skel = rest_biped()
    ends = {"j4": [0, -0.5, 0.5], "j8": [0, -0.25, 0.5]}
    skel = Skeleton(tuple(replace(j, end_site=ends.get(j.name, j.end_site)) for j in skel.joints))
    geo = _Geometry(skel, None, "y")
    assert geo.floor == -10.0
    np.testing.assert_array_equal(geo.median[[3, 4, 7, 8, 9]], [1.0, 0.0, 1.0, 0.25, 13.0])
    assert geo.height == 13.0


def _standing(skel: Skeleton, heights) -> Motion:
    """``skel`` (root dofs tx ty tz only) with its root at these heights, one a frame."""
    frames = np.zeros((len(heights), 3))
    frames[:, 1] = heights
    return Motion(frames, skel.channels, fps=30.0, skeleton=skel)


def test_geometry_in_motion_quantiles_and_frame_step():
    """The root at heights 0, 1, ..., 100: the toes' per-frame lows k - 9.5 put the floor
    at their 5 % quantile (5 - 9.5 = -4.5), a toe's median at 50 - 9.5 + 4.5 = 45 and its
    5 % low at 0, the body height at the head's median 53 + 4.5."""
    from cyclecoord.quality.legs import _Geometry

    skel = rest_biped()
    geo = _Geometry(skel, _standing(skel, np.arange(101.0)), "y")
    assert geo.in_motion is True and geo.pos.shape == (101, 10, 3)
    assert geo.floor == pytest.approx(-4.5, abs=1e-12)
    assert geo.median[4] == pytest.approx(45.0, abs=1e-12)
    assert geo.low[4] == pytest.approx(0.0, abs=1e-12)
    assert geo.low[9] == pytest.approx(12.5, abs=1e-12)
    assert geo.height == pytest.approx(57.5, abs=1e-12)
    # at most 400 frames: a step of ceil(T / 400)
    for T, used in ((400, 400), (401, 201), (1200, 400), (1201, 301)):
        geo = _Geometry(skel, _standing(skel, np.zeros(T)), "y")
        assert geo.pos.shape[0] == used, T
    # a motion with a NaN is not used: the rest pose instead
    h = np.zeros(5)
    h[2] = np.nan
    geo = _Geometry(skel, _standing(skel, h), "y")
    assert geo.in_motion is False and geo.pos.shape[0] == 1


def test_grounded_keeps_the_lower_of_two_ends_parting_low():
    """A heel under the left ankle (a second end of that leg): of the toe and the heel only
    the lower is a foot, as they part at the ankle (0.5 above the floor, under 0.3 of the
    body height); the right toe parts from either at the pelvis and stays."""
    from cyclecoord.quality.legs import _Geometry

    geo = _Geometry(rest_biped(heel=0.4), None, "y")  # heel at -9.4, over the toe
    assert geo.ends == [4, 8, 9, 10]
    assert geo.grounded() == [4, 8]
    geo = _Geometry(rest_biped(heel=0.6), None, "y")  # heel at -9.6: the floor
    assert geo.median[10] == 0.0 and geo.median[4] == pytest.approx(0.1)
    assert geo.grounded() == [10, 8]
    # lowest first, whatever the order of the ends
    geo = _Geometry(rest_biped(shin_r=3.8), None, "y")
    assert geo.grounded() == [4, 8]
    geo = _Geometry(rest_biped(shin_r=4.2), None, "y")
    assert geo.grounded() == [8, 4]


def test_grounded_median_bound_and_its_argument():
    """Median height at most 0.3 of the body height by default, or the bound given (both
    included): 3.0 of 10 passes 0.3, not 0.15; 1.5 passes 0.15."""
    from cyclecoord.quality.legs import _GROUND_MEDIAN, _Geometry

    assert _GROUND_MEDIAN * 10.0 == 3.0
    geo = object.__new__(_Geometry)
    geo.height = 10.0
    geo.ends = [0]
    geo.low = np.array([0.0])
    geo.median = np.array([3.0])
    assert geo.grounded() == [0]
    assert geo.grounded(0.15) == []
    geo.median = np.array([np.nextafter(3.0, 4.0)])
    assert geo.grounded() == []
    geo.median = np.array([1.5])
    assert geo.grounded(0.15) == [0]


def _two_legs(la: float, lb: float) -> Skeleton:
    """j0 with a leg j1 [1, 0, 0] -> j2 (la - 1 down) and j3 [-1, 0, 0] -> j4 (lb - 1 down),
    and a head j5 10 up."""
    return Skeleton((
        Joint("j0", -1, [0, 0, 0]), Joint("j1", 0, [1.0, 0, 0]), Joint("j2", 1, [0, 1 - la, 0]),
        Joint("j3", 0, [-1.0, 0, 0]), Joint("j4", 3, [0, 1 - lb, 0]), Joint("j5", 0, [0, 10, 0]),
    ))


def test_pair_score_closed_form_and_bounds():
    """(median_a + median_b) / height + |la - lb| / max(la, lb), None when the legs differ
    by more than 0.3 of the longer one or part at most 0.3 of the height up."""
    from cyclecoord.quality.legs import _Geometry

    # legs 10 and 7: a spread of exactly 0.3 is alike; the floor at -9, height 19
    geo = _Geometry(_two_legs(10.0, 7.0), None, "y")
    assert geo.height == 19.0
    assert geo.pair_score(2, 4) == pytest.approx(3.0 / 19.0 + 0.3, rel=1e-15)
    assert geo.pair_score(4, 2) == pytest.approx(3.0 / 19.0 + 0.3, rel=1e-15)
    geo = _Geometry(_two_legs(10.0, 6.99), None, "y")
    assert geo.pair_score(2, 4) is None
    # rest_biped with a right shin of 3: lengths sqrt 2 + 8 + sqrt 1.25 and 1 less
    geo = _Geometry(rest_biped(shin_r=3.0), None, "y")
    la = np.sqrt(2.0) + 8 + np.sqrt(1.25)
    assert geo.pair_score(4, 8) == pytest.approx(1.0 / 12.5 + 1.0 / la, rel=1e-14)
    assert geo.pair_score(4, 9) is None  # a head of 3 beside a leg of 10.5
    # parting at the ankle (0.5 above the floor): not two legs
    geo = _Geometry(rest_biped(heel=0.4), None, "y")
    assert geo.pair_score(4, 10) is None


def test_pair_score_part_height_and_zero_length_bounds():
    from cyclecoord.quality.legs import _PART_HEIGHT, _Geometry

    assert _PART_HEIGHT * 10.0 == 3.0
    geo = object.__new__(_Geometry)
    geo.skeleton = Skeleton((Joint("j0", -1, [0, 0, 0]), Joint("j1", 0, [0, -2, 0]),
                             Joint("j2", 0, [0, -2, 0])))
    geo.height = 10.0
    geo.bone = np.array([0.0, 2.0, 2.0])
    geo.median = np.array([3.0, 0.5, 1.5])
    assert geo.pair_score(1, 2) is None  # parting exactly 0.3 up is too low
    geo.median[0] = np.nextafter(3.0, 4.0)
    assert geo.pair_score(1, 2) == pytest.approx(0.2, rel=1e-15)
    geo.bone[:] = 0.0  # legs of no length are none
    assert geo.pair_score(1, 2) is None
    geo.bone[1:] = 0.5  # short legs are legs: (0.5 + 1.5) / 10
    assert geo.pair_score(1, 2) == pytest.approx(0.2, rel=1e-15)


def test_foot_points_shin_fraction_edges():
    """The ankle is the first joint up from the end whose bone is at least a quarter of the
    leg (exactly a quarter counts), else the joint just below where the leg parts."""
    from cyclecoord.quality.legs import _SHIN_FRACTION, _Geometry

    assert _SHIN_FRACTION == 0.25

    def chain(*drops):
        joints = [Joint("j0", -1, [0, 0, 0])]
        joints += [Joint(f"j{k + 1}", k, [0, -d, 0]) for k, d in enumerate(drops)]
        return _Geometry(Skeleton(tuple(joints)), None, "y")

    assert chain(4.0, 2.0, 2.0).foot_points(0, 3) == (3,)  # 2 of 8: an ankle, no toe
    assert chain(4.0, 2.0, 1.99).foot_points(0, 3) == (2, 3)  # 1.99 of 7.99: a toe
    assert chain(1.0, 1.0, 1.0, 1.0, 1.0).foot_points(0, 5) == (1, 2)  # all short
    assert chain(1.0, 1.0, 1.0, 1.0, 1.0).foot_points(2, 5) == (5,)  # 1 of 3 from j2


def test_usable_upright_left_ahead_by_hand():
    from cyclecoord.quality.legs import _Geometry

    flat = Skeleton((Joint("j0", -1, [0, 0, 0]), Joint("j1", 0, [1, 0, 0]),
                     Joint("j2", 0, [-1, 0, 0])))
    geo = _Geometry(flat, None, "y")
    assert geo.height == 0.0 and not geo.usable
    with pytest.raises(ParameterError, match="no foot joints"):
        find_legs(flat)
    geo.height = np.inf
    assert not geo.usable
    geo.height = 1e-300
    assert geo.usable
    # upright: the leg's top over its end by more than half the leg's length (> 0)
    geo = object.__new__(_Geometry)
    geo.skeleton = Skeleton((Joint("j0", -1, [0, 0, 0]), Joint("j1", 0, [0, -4, 0]),
                             Joint("j2", 0, [0, 0, 0])))
    geo.bone = np.array([0.0, 4.0, 0.0])
    geo.median = np.array([2.0, 0.0, 1.0])
    assert not geo.upright([(0, 1)])  # 2 over, half of 4: not more
    geo.median[0] = 2.5
    assert geo.upright([(0, 1)])
    geo.median[1] = 0.5  # the drop is 2.0 again, from higher up
    assert not geo.upright([(0, 1)])
    geo.median[1] = 0.0
    assert not geo.upright([(0, 1), (0, 2)])  # a leg of no length
    # left = up x forward: with y up and +z forward, left is +x; the median frame decides
    geo.up = 1
    fwd = np.tile([0.0, 0.0, 1.0], (3, 1))
    a = np.array([[1.0, 0, 0], [1.0, 0, 0], [-1.0, 0, 0]])
    b = np.zeros((3, 3))
    assert geo.left_of(a, b, fwd) and not geo.left_of(b, a, fwd)
    assert not geo.left_of(b, b, fwd)  # on the line: not left
    assert not geo.ahead_of(a, b, fwd)
    assert geo.ahead_of(a[:, [2, 1, 0]], b, fwd) and not geo.ahead_of(b, b, fwd)
    geo.up = 2  # z up, +x forward: left is +y
    fwd = np.tile([1.0, 0.0, 0.0], (3, 1))
    assert geo.left_of(np.tile([0.0, 1.0, 0.0], (3, 1)), b, fwd)
    assert not geo.left_of(np.tile([0.0, -1.0, 0.0], (3, 1)), b, fwd)


def test_forward_feet_of_exactly_1e9_units_are_none():
    """A median foot extent of exactly 1e-9 units is none: the root's travel decides."""
    from cyclecoord.quality.legs import _Geometry

    geo = object.__new__(_Geometry)
    geo.up = 1
    pos = np.zeros((3, 3, 3))
    pos[:, 1] = [0.0, 1.0, 0.0]
    pos[:, 2] = [1e-9, 0.0, 0.0]
    pos[-1, 0] = [0.0, 0.0, -2.0]
    geo.pos = pos
    np.testing.assert_array_equal(geo.forward([(1, 2)]), np.tile([0.0, 0.0, -1.0], (3, 1)))
    pos[:, 2] = [2e-9, 0.0, 0.0]
    np.testing.assert_allclose(geo.forward([(1, 2)]), np.tile([1.0, 0.0, 0.0], (3, 1)))


def _renamed(skel: Skeleton, names: dict) -> Skeleton:
    return Skeleton(tuple(replace(j, name=names.get(j.name, j.name)) for j in skel.joints))


def test_legs_of_feet_sides_from_names_before_geometry():
    """Sides come from the first named joint on each leg's chain, even against the
    geometry (hips named the other way round); without names, from the geometry."""
    skel = rest_biped()
    legs = legs_of_feet(skel, "j7:j8,j3:j4")
    assert legs.method == "given"
    assert [(g.label, g.side, g.limb, g.points) for g in legs.legs] == [
        ("right", "right", None, ("j7", "j8")), ("left", "left", None, ("j3", "j4"))]
    swapped = _renamed(skel, {"j1": "rhipjoint", "j5": "lhipjoint"})
    legs = legs_of_feet(swapped, ("j4", "j8"))
    assert legs.sides == ("right", "left")
    legs = legs_of_feet(_renamed(skel, {"j3": "rfoot"}), ("j4", "j8"))  # one side named
    assert legs.sides == ("left", "right")  # the geometry decides both


def test_legs_of_feet_labels_without_sides_and_twice_the_same():
    """A leg without a side is "leg k" (k from 1, in the order given); a label met twice
    gets its leg's number too; neither 2 nor 4 legs: no geometry is tried."""
    skel = rest_biped()
    legs = legs_of_feet(skel, ["j4", "j8", "j9"])
    assert [g.label for g in legs.legs] == ["leg 1", "leg 2", "leg 3"]
    assert legs.sides == ("?", "?", "?")
    named = _renamed(skel, {"j3": "lfoot", "j7": "lhand"})
    legs = legs_of_feet(named, ["lfoot", "lhand", "j9"])
    assert [g.label for g in legs.legs] == ["left", "left 2", "leg 3"]
    assert legs.sides == ("left", "left", "?")
    # two legs on a flat body (no height): no geometry either
    flat = Skeleton((Joint("j0", -1, [0, 0, 0]), Joint("j1", 0, [1, 0, 0]),
                     Joint("j2", 0, [-1, 0, 0])))
    legs = legs_of_feet(flat, ["j1", "j2"])
    assert [(g.label, g.side) for g in legs.legs] == [("leg 1", "?"), ("leg 2", "?")]


def _splayed() -> Skeleton:
    """rest_biped with the legs reaching forward from the hips (knee and ankle 1 down and
    4 forward each): they drop 3.5 over a length of about 10.8, not hanging down."""
    j = [Joint("j0", -1, [0, 0, 0], ("tx", "ty", "tz"), "")]
    for x in (1.0, -1.0):
        b = len(j)
        j += [Joint(f"j{b}", 0, [x, -1.0, 0]), Joint(f"j{b + 1}", b, [0, -1.0, 4.0]),
              Joint(f"j{b + 2}", b + 1, [0, -1.0, 4.0]),
              Joint(f"j{b + 3}", b + 2, [0, -0.5, 1.0], end_site=[0, 0, 0.5])]
    j.append(Joint("j9", 0, [0, 3.0, 0], end_site=[0, 1.0, 0]))
    return Skeleton(tuple(j))


def test_geometry_legs_must_hang_down_in_the_rest_pose_only():
    """A rest pose whose legs do not hang down (Bandai's lie along the floor) gives no legs;
    in a motion the same pose does (the motion shows where the feet are)."""
    skel = _splayed()
    with pytest.raises(ParameterError, match="no foot joints"):
        find_legs(skel)
    legs = find_legs(skel, _standing(skel, np.zeros(3)))
    assert legs.method == "geometry" and legs.feet == ("j3", "j4", "j7", "j8")


def test_leg_results_are_frozen_and_hashable():
    from dataclasses import FrozenInstanceError

    from cyclecoord.quality.legs import Leg, Legs

    leg = Leg("left", "left", None, ("a",))
    legs = Legs((leg,), "names")
    assert len({leg, Leg("left", "left", None, ("a",))}) == 1 and hash(legs) == hash(
        Legs((Leg("left", "left", None, ("a",)),), "names"))
    with pytest.raises(FrozenInstanceError):
        leg.side = "right"
    with pytest.raises(FrozenInstanceError):
        legs.method = "given"


def test_ancestors_reach_the_root_and_the_root_groups_with_its_chain():
    from cyclecoord.quality.legs import _ancestors, _group

    skel = rest_biped()
    assert _ancestors(skel, 4) == ["j3", "j2", "j1", "j0"] and _ancestors(skel, 0) == []
    assert _group(skel, ("j4", "j0")) == [["j0", "j4"]]
    # ANKLE:TOE with the root as the ankle: the toe is below it, and so is every joint
    with pytest.raises(ParameterError, match="1 legs"):
        resolve_feet(skel, "j0:j4,j8")


def test_geometry_of_an_empty_motion_is_the_rest_pose_and_the_root_is_no_end():
    from cyclecoord.quality.legs import _Geometry

    skel = rest_biped()
    geo = _Geometry(skel, _standing(skel, np.zeros(0)), "y")
    assert geo.in_motion is False and geo.pos.shape == (1, 10, 3)
    # a root whose only child is a prop is no end: ends are never the root
    lone = Skeleton((Joint("j0", -1, [0, 0, 0]), Joint("Prop1", 0, [0, -1, 0])))
    assert _Geometry(lone, None, "y").ends == []


def test_legs_too_unlike_to_pair_give_no_legs():
    """Two ends on the floor 9 below the root, one leg 10 long and one 17 (its hip 8 out
    to the side): 7 apart, over 0.3 of 17, so no pair and no legs."""
    skel = Skeleton((Joint("j0", -1, [0, 0, 0]), Joint("j1", 0, [8.0, 0, 0]),
                     Joint("j2", 1, [0, -9.0, 0]), Joint("j3", 0, [-1.0, 0, 0]),
                     Joint("j4", 3, [0, -9.0, 0]), Joint("j5", 0, [0, 5.0, 0])))
    with pytest.raises(ParameterError, match="no foot joints"):
        find_legs(skel)
    ok = Skeleton(tuple(replace(j, offset=[4.0, 0, 0]) if j.name == "j1" else j
                        for j in skel.joints))  # 13 and 10: 3 apart, within 0.3 of 13
    assert find_legs(ok).feet == ("j2", "j4")


def test_four_ends_of_which_only_one_pair_is_alike_give_two_legs():
    """The quadruped at rest with its hind right hip 8 out to the side (that leg 17 long
    from the pelvis, the hind left 10.6): no two pairs are both alike, so the pair that is
    (the front legs, parting at the chest, alike exactly) are the two legs."""
    names = quadruped_names("anonymous")
    skel = quadruped_skeleton(names)
    wide = Skeleton(tuple(replace(j, offset=[-8.0, 0, 0]) if j.name == names["hr_hip"] else j
                          for j in skel.joints))
    legs = find_legs(wide)
    assert legs.method == "geometry"
    assert legs.feet == (names["fl_ankle"], names["fl_toe"], names["fr_ankle"], names["fr_toe"])
    assert legs.sides == ("left", "left", "right", "right")


def test_extra_legs_need_a_motion_and_a_right_leg_of_one_point():
    """A dog rig named like a person gets its front legs from a motion, never from its rest
    pose alone; the named legs' chains are checked from the left leg's first point to the
    right leg's last, a right leg of its ankle alone included."""
    names = quadruped_names("human")
    dog = quadruped_skeleton(names)
    assert find_legs(dog).method == "names"
    motion = trot(dog, names)
    assert find_legs(dog, motion).method == "names and geometry"
    bare = {names["hr_toe"]: "j99"}
    dog1 = _renamed(dog, bare)
    motion1 = Motion(motion.frames, tuple((bare.get(a, a), d) for a, d in motion.channels),
                     fps=motion.fps, skeleton=dog1)
    legs = find_legs(dog1, motion1)
    assert legs.method == "names and geometry"
    assert [(g.label, g.points) for g in legs.legs][-1] == ("hind right", ("RightFoot",))


@pytest.mark.parametrize("heading", [0.0, 180.0])
def test_extra_legs_front_or_hind_whichever_way_the_dog_trots(heading):
    """Front and hind come from where the legs are along the way the feet point, far
    from the origin too (a trot of 16 units either way, 100 units behind the origin)."""
    names = quadruped_names("human")
    dog = quadruped_skeleton(names)
    motion = trot(dog, names, heading_deg=heading)
    frames = motion.frames.copy()
    frames[:, motion.channel_index(names["pelvis"], "tz")] -= 100.0 * np.cos(np.radians(heading))
    legs = find_legs(dog, motion.with_frames(frames))
    assert legs.method == "names and geometry"
    assert [(g.label, g.points[0]) for g in legs.legs] == [
        ("front left", "LeftHand"), ("front right", "RightHand"),
        ("hind left", "LeftFoot"), ("hind right", "RightFoot")]


def test_no_feet_message_without_end_joints():
    lone = Skeleton((Joint("j0", -1, [0, 0, 0]),))
    with pytest.raises(ParameterError, match=r"e\.g\. --feet LEFT,RIGHT; lowest end joints "
                                             r"\(height above the floor\): none$"):
        find_legs(lone)


def test_given_quadruped_feet_in_the_rest_pose():
    """Four given legs in any order: paired where their chains part lowest (front legs at
    the chest, hind legs at the pelvis), sides and front/hind from the rest pose."""
    names = quadruped_names("anonymous")
    skel = quadruped_skeleton(names)
    given = (names["hl_toe"], names["fr_ankle"], names["hr_ankle"], names["fl_toe"])
    legs = legs_of_feet(skel, given)
    assert [g.label for g in legs.legs] == ["hind left", "front right", "hind right",
                                            "front left"]
    assert legs.method == "given" and legs.feet == given


def test_grounded_keeps_ends_parting_strictly_over_0_3_of_the_height():
    """Of two ends on the floor, the second is another foot only when their chains part
    over 0.3 of the body height (exactly 0.3: the same foot)."""
    from cyclecoord.quality.legs import _Geometry

    geo = object.__new__(_Geometry)
    geo.skeleton = Skeleton((Joint("j0", -1, [0, 0, 0]), Joint("j1", 0, [1, -3, 0]),
                             Joint("j2", 0, [-1, -3, 0])))
    geo.height = 10.0
    geo.ends = [1, 2]
    geo.low = np.zeros(3)
    geo.median = np.array([3.0, 0.0, 0.1])
    assert geo.grounded() == [1]
    geo.median[0] = np.nextafter(3.0, 4.0)
    assert geo.grounded() == [1, 2]


def test_a_quadrupeds_front_pair_is_ahead_on_average_though_staggered():
    """Anonymous names, rest pose: the chest 0.5 ahead of the pelvis, its legs staggered
    (left hip 1 ahead of it, right 1 behind, so the right front leg is behind the hind
    legs).  The pair ahead is the one whose two legs are ahead on average: the chest's."""
    from _walkers import ROT, _leg

    names = quadruped_names("anonymous")
    j = [Joint(names["pelvis"], -1, [0, 0, 0], ("tx", "ty", "tz") + ROT, "ZYX")]
    j.append(Joint(names["spine"], 0, [0, 0, 0.25], ROT, "ZYX"))
    j.append(Joint(names["chest"], 1, [0, 0, 0.25], ROT, "ZYX"))
    j.append(Joint(names["neck"], 2, [0, 1.5, 1.0], ROT, "ZYX"))
    j.append(Joint(names["head"], 3, [0, 1.0, 1.0], ROT, "ZYX", end_site=[0, 0, 1.5]))
    j.append(Joint(names["tail"], 0, [0, 0.5, -1.0], ROT, "ZYX", end_site=[0, -1.0, -2.0]))
    for prefix, parent, hip in (("hl_", 0, [1.5, 0, 0]), ("hr_", 0, [-1.5, 0, 0]),
                                ("fl_", 2, [1.5, 0, 1.0]), ("fr_", 2, [-1.5, 0, -1.0])):
        _leg(j, names, prefix, parent, hip)
    legs = find_legs(Skeleton(tuple(j), name="staggered")).legs
    got = {g.label: g.points for g in legs}
    assert got == {
        "front left": (names["fl_ankle"], names["fl_toe"]),
        "front right": (names["fr_ankle"], names["fr_toe"]),
        "hind left": (names["hl_ankle"], names["hl_toe"]),
        "hind right": (names["hr_ankle"], names["hr_toe"]),
    }


def test_the_ends_are_the_leaves_below_the_root_the_first_child_included():
    """_Geometry's end joints: every joint without (unignored) children except the root;
    a leaf that is the root's very first child (joint 1, a tail here) is one of them."""
    from cyclecoord.quality.legs import _Geometry

    joints = (
        Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
        Joint("tail", 0, [0, 0, -3], ("rx",), "X"),
        Joint("thigh", 0, [1, -1, 0], ("rx",), "X"),
        Joint("shin", 2, [0, -4, 0], ("rx",), "X"),
    )
    geo = _Geometry(Skeleton(joints, name="t"), None, "y")
    assert geo.ends == [1, 3]
