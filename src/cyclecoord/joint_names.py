"""Joint names of common motion-capture rigs: which joint is which, in one table.

Rigs name the same joints differently.  :data:`RIG_NAMINGS` lists the conventions this
package knows, with each one's names for the pelvis, spine, head, left arm and left leg:

=================  ==========================================================================
convention         left leg (hip, knee, ankle, toe joints) and other names
=================  ==========================================================================
CMU ASF/AMC        ``lhipjoint`` (pelvis bone), ``lfemur``, ``ltibia``, ``lfoot``, ``ltoes``;
                   ``root``, ``lowerback``, ``thorax``, ``head``, ``lclavicle`` ... ``lhand``
CMU BVH            ``LHipJoint``, ``LeftUpLeg``, ``LeftLeg``, ``LeftFoot``, ``LeftToeBase``;
                   ``Hips``, ``LowerBack``, ``Spine1``, ``LeftShoulder`` ... ``LThumb``
Mixamo             ``mixamorig:LeftUpLeg``, ``LeftLeg``, ``LeftFoot``, ``LeftToeBase``
                   (also ``mixamorig1:`` and other ``namespace:`` prefixes)
LAFAN1 / Ubisoft   ``LeftUpLeg``, ``LeftLeg``, ``LeftFoot``, ``LeftToe``
Bandai Namco       ``UpperLeg_L``, ``LowerLeg_L``, ``Foot_L``, ``Toes_L``; ``joint_Root``,
                   ``Hips``, ``Chest``, ``Shoulder_L`` (clavicle), ``UpperArm_L``
Xsens MVN          ``LeftUpperLeg``, ``LeftLowerLeg``, ``LeftFoot``, ``LeftToe``; ``Pelvis``,
                   ``L5`` ``L3`` ``T12`` ``T8`` (spine)
Xsens MVN (older)  ``LeftHip``, ``LeftKnee``, ``LeftAnkle``, ``LeftToe``; ``LeftCollar``,
                   ``LeftShoulder`` (upper arm), ``LeftElbow``, ``LeftWrist``
SMPL / AMASS       ``L_Hip``, ``L_Knee``, ``L_Ankle``, ``L_Foot`` (the toes: SMPL's foot joint
                   is below its ankle); SMPL-X ``left_hip`` ... ``left_foot``
Rokoko (Newton)    ``LeftThigh``, ``LeftShin``, ``LeftFoot``, ``LeftToe`` (``LeftToeTip``)
Unreal mannequin   ``thigh_l``, ``calf_l``, ``foot_l``, ``ball_l`` (twist and ``ik_`` bones
                   are left out)
Blender / Rigify   ``thigh.L``, ``shin.L``, ``foot.L``, ``toe.L``
3ds Max Biped      ``Bip01 L Thigh``, ``Bip01 L Calf``, ``Bip01 L Foot``, ``Bip01 L Toe0``
=================  ==========================================================================

Names are not matched against that list but read word by word (:func:`classify_joint`), so
variants of the same patterns are understood too:

* a namespace (``mixamorig:``, ``Character1|``) is dropped, the rest is split into words
  at separators (``_ . - space``), case changes (``LeftUpLeg`` -> left, up, leg) and digits;
  a leading ``l``/``r`` glued to a body word (CMU's ``lfoot``, ``rhumerus``) is a side;
* the side is a word ``left``/``right``/``l``/``r`` anywhere (``LeftFoot``, ``Foot_L``,
  ``foot.L``, ``l_foot``, ``L_Foot``, ``Bip01 L Foot``), case-insensitive;
* the role comes from the longest run of the other words found in :data:`ROLE_WORDS`
  (``toe``, ``toes``, ``toebase`` and ``ball`` are toes; ``upleg``, ``upperleg``,
  ``thigh``, ``femur`` and ``hip`` the joint at the hip ...), and leading words that are
  not body words (``Bip01``, ``Character1_``, ``DEF-``) are skipped;
* ``front``/``fore`` or ``hind``/``back``/``rear`` with a leg word names a quadruped's
  leg (``LeftFrontLeg``, ``RightHindFoot``, ``FrontLeftFoot``);
* end, twist, roll, IK, control and prop joints (``LeftToe_End``, ``calf_twist_01_l``,
  ``ik_foot_l``, ``Prop1``) have no role.

Roles name where the joint's pivot is: ``"hip"`` is the thigh's joint (``LeftUpLeg``),
``"knee"`` the shin's, ``"ankle"`` the foot's and ``"toe"`` the toes'.  A few words mean
different joints in different rigs; :func:`classify_skeleton` settles them from the
hierarchy: a ``foot`` below an ``ankle`` is the toes (SMPL), a ``shoulder`` above an
upper arm is the clavicle (Mixamo, Bandai) and otherwise the upper arm (SMPL, older
Xsens), a ``hand`` below a ``wrist`` holds the fingers.

Which joints are the feet of a skeleton, with a geometric fallback when the names say
nothing, is :func:`cyclecoord.quality.legs.find_legs`.
"""

from __future__ import annotations

import functools
import re
import weakref
from dataclasses import dataclass
from types import MappingProxyType

from .skeleton import Skeleton

__all__ = [
    "JointRole",
    "RigNaming",
    "RIG_NAMINGS",
    "ROLES",
    "LEG_ROLES",
    "ROLE_WORDS",
    "classify_joint",
    "classify_skeleton",
    "is_ignored_name",
    "name_words",
]

#: Every role a joint can be given.
ROLES = (
    "root",
    "pelvis",
    "spine",
    "neck",
    "head",
    "tail",
    "clavicle",
    "shoulder",
    "elbow",
    "hand",
    "fingers",
    "hip",
    "knee",
    "ankle",
    "toe",
    "heel",
)
#: The roles of a leg's joints, from the hip down.
LEG_ROLES = ("hip", "knee", "ankle", "toe", "heel")

#: Body words (words of a joint name run together, lower case) and the role they name.
ROLE_WORDS = MappingProxyType(
    {
        # legs
        "hipjoint": "pelvis",
        "hip": "hip",
        "upleg": "hip",
        "upperleg": "hip",
        "thigh": "hip",
        "femur": "hip",
        "leg": "knee",
        "lowerleg": "knee",
        "lowleg": "knee",
        "knee": "knee",
        "shin": "knee",
        "calf": "knee",
        "tibia": "knee",
        "shank": "knee",
        "foot": "ankle",
        "ankle": "ankle",
        "paw": "ankle",
        "hoof": "ankle",
        "toe": "toe",
        "toes": "toe",
        "toebase": "toe",
        "ball": "toe",
        "bigtoe": "toe",
        "heel": "heel",
        # trunk
        "root": "root",
        "hips": "pelvis",
        "pelvis": "pelvis",
        "spine": "spine",
        "back": "spine",
        "lowerback": "spine",
        "upperback": "spine",
        "chest": "spine",
        "upperchest": "spine",
        "thorax": "spine",
        "abdomen": "spine",
        "torso": "spine",
        "waist": "spine",
        "neck": "neck",
        "lowerneck": "neck",
        "upperneck": "neck",
        "head": "head",
        "skull": "head",
        "tail": "tail",
        # arms
        "clavicle": "clavicle",
        "collar": "clavicle",
        "collarbone": "clavicle",
        "shoulder": "shoulder",  # the clavicle in some rigs: settled by classify_skeleton
        "arm": "shoulder",
        "upperarm": "shoulder",
        "uparm": "shoulder",
        "humerus": "shoulder",
        "forearm": "elbow",
        "lowerarm": "elbow",
        "elbow": "elbow",
        "radius": "elbow",
        "ulna": "elbow",
        "hand": "hand",
        "wrist": "hand",
    }
)
#: Words of finger joints (``LeftHandIndex1``, ``lthumb``, ``LeftFingerBase``).
FINGER_WORDS = frozenset(
    {"finger", "fingers", "fingerbase", "thumb", "index", "middle", "ring", "pinky", "little"}
)
#: Words of joints that are not part of the body's chain: end and tip joints, twist and
#: roll helpers, IK and control rigs, props.
IGNORED_WORDS = frozenset(
    {
        "end",
        "nub",
        "site",
        "tip",
        "top",
        "twist",
        "roll",
        "ik",
        "fk",
        "ctrl",
        "control",
        "pole",
        "target",
        "helper",
        "mch",
        "org",
        "prop",
        "weapon",
        "socket",
        "attach",
        "dummy",
        "null",
        "corrective",
    }
)
_SIDE_WORDS = MappingProxyType({"l": "left", "left": "left", "r": "right", "right": "right"})
_LIMB_WORDS = MappingProxyType(
    {"front": "front", "fore": "front", "hind": "hind", "back": "hind", "rear": "hind"}
)
_WORD = re.compile(r"[A-Z]+(?=[A-Z][a-z])|[A-Z]?[a-z]+|[A-Z]+|\d+")
_VERTEBRA = re.compile(r"[LTSC]\d{1,2}", re.IGNORECASE)


@dataclass(frozen=True)
class JointRole:
    """What a joint is, from its name.

    Attributes
    ----------
    role : str
        One of :data:`ROLES`.
    side : str or None
        ``"left"``, ``"right"``, or None for a joint on the body's midline.
    limb : str or None
        ``"front"`` or ``"hind"`` for a quadruped's leg named so, else None.
    """

    role: str
    side: str | None = None
    limb: str | None = None


@dataclass(frozen=True)
class RigNaming:
    """One rig's naming convention, with the names of a minimal skeleton in it.

    Attributes
    ----------
    key : str
        Short identifier, e.g. ``"mixamo"``.
    title : str
        Human-readable name.
    sides : (str, str)
        What replaces ``{s}`` in the templates for the left and the right side (``{L}``
        is always ``L`` or ``R``).
    trunk : tuple of (str, str)
        ``(name, role)`` from the root up to the head (role ``""``: the name says none).
    leg : tuple of str
        Templates of one leg's joints from the trunk down; the last four are the hip,
        knee, ankle and toe joints, any before them pelvis bones.
    arm : tuple of str
        Templates of one arm's joints: clavicle, shoulder, elbow, hand, then fingers.
    arm_parent : str
        The trunk joint the arms hang from.
    """

    key: str
    title: str
    sides: tuple[str, str]
    trunk: tuple[tuple[str, str], ...]
    leg: tuple[str, ...]
    arm: tuple[str, ...]
    arm_parent: str

    def names(self, side: str, part: str) -> tuple[str, ...]:
        """The leg's or arm's joint names (``part`` ``"leg"``/``"arm"``) on a side."""
        fill = self.sides[0 if side == "left" else 1]
        letter = "L" if side == "left" else "R"
        return tuple(t.format(s=fill, L=letter) for t in getattr(self, part))

    def roles(self, part: str) -> tuple[str, ...]:
        """The role of each joint of :meth:`names` (``part`` ``"leg"``/``"arm"``)."""
        if part == "leg":
            return ("pelvis",) * (len(self.leg) - 4) + ("hip", "knee", "ankle", "toe")
        return ("clavicle", "shoulder", "elbow", "hand") + ("fingers",) * (len(self.arm) - 4)


def _trunk(*pairs: str) -> tuple[tuple[str, str], ...]:
    return tuple(tuple(p.split("=")) for p in pairs)  # type: ignore[misc]


#: The naming conventions known (see the module docstring's table).
RIG_NAMINGS: tuple[RigNaming, ...] = (
    RigNaming(
        "cmu_asf", "CMU ASF/AMC", ("l", "r"),
        _trunk("root=root", "lowerback=spine", "upperback=spine", "thorax=spine",
               "lowerneck=neck", "upperneck=neck", "head=head"),
        ("{s}hipjoint", "{s}femur", "{s}tibia", "{s}foot", "{s}toes"),
        ("{s}clavicle", "{s}humerus", "{s}radius", "{s}wrist", "{s}hand", "{s}fingers"),
        "thorax",
    ),
    RigNaming(
        "cmu_bvh", "CMU BVH", ("Left", "Right"),
        _trunk("Hips=pelvis", "LowerBack=spine", "Spine=spine", "Spine1=spine", "Neck=neck",
               "Neck1=neck", "Head=head"),
        ("{L}HipJoint", "{s}UpLeg", "{s}Leg", "{s}Foot", "{s}ToeBase"),
        ("{s}Shoulder", "{s}Arm", "{s}ForeArm", "{s}Hand", "{s}FingerBase"),
        "Spine1",
    ),
    RigNaming(
        "mixamo", "Mixamo", ("Left", "Right"),
        _trunk("mixamorig:Hips=pelvis", "mixamorig:Spine=spine", "mixamorig:Spine1=spine",
               "mixamorig:Spine2=spine", "mixamorig:Neck=neck", "mixamorig:Head=head"),
        ("mixamorig:{s}UpLeg", "mixamorig:{s}Leg", "mixamorig:{s}Foot",
         "mixamorig:{s}ToeBase"),
        ("mixamorig:{s}Shoulder", "mixamorig:{s}Arm", "mixamorig:{s}ForeArm",
         "mixamorig:{s}Hand", "mixamorig:{s}HandIndex1"),
        "mixamorig:Spine2",
    ),
    RigNaming(
        "mixamo1", "Mixamo (second character)", ("Left", "Right"),
        _trunk("mixamorig1:Hips=pelvis", "mixamorig1:Spine=spine", "mixamorig1:Neck=neck",
               "mixamorig1:Head=head"),
        ("mixamorig1:{s}UpLeg", "mixamorig1:{s}Leg", "mixamorig1:{s}Foot",
         "mixamorig1:{s}ToeBase"),
        ("mixamorig1:{s}Shoulder", "mixamorig1:{s}Arm", "mixamorig1:{s}ForeArm",
         "mixamorig1:{s}Hand"),
        "mixamorig1:Spine",
    ),
    RigNaming(
        "lafan1", "LAFAN1 / Ubisoft", ("Left", "Right"),
        _trunk("Hips=pelvis", "Spine=spine", "Spine1=spine", "Spine2=spine", "Neck=neck",
               "Head=head"),
        ("{s}UpLeg", "{s}Leg", "{s}Foot", "{s}Toe"),
        ("{s}Shoulder", "{s}Arm", "{s}ForeArm", "{s}Hand"),
        "Spine2",
    ),
    RigNaming(
        "bandai", "Bandai Namco", ("L", "R"),
        _trunk("joint_Root=root", "Hips=pelvis", "Spine=spine", "Chest=spine", "Neck=neck",
               "Head=head"),
        ("UpperLeg_{s}", "LowerLeg_{s}", "Foot_{s}", "Toes_{s}"),
        ("Shoulder_{s}", "UpperArm_{s}", "LowerArm_{s}", "Hand_{s}"),
        "Chest",
    ),
    RigNaming(
        "xsens_mvn", "Xsens MVN", ("Left", "Right"),
        _trunk("Pelvis=pelvis", "L5=spine", "L3=spine", "T12=spine", "T8=spine", "Neck=neck",
               "Head=head"),
        ("{s}UpperLeg", "{s}LowerLeg", "{s}Foot", "{s}Toe"),
        ("{s}Shoulder", "{s}UpperArm", "{s}ForeArm", "{s}Hand"),
        "T8",
    ),
    RigNaming(
        "xsens_mvn_legacy", "Xsens MVN (older BVH export)", ("Left", "Right"),
        _trunk("Hips=pelvis", "Chest=spine", "Chest2=spine", "Chest3=spine", "Chest4=spine",
               "Neck=neck", "Head=head"),
        ("{s}Hip", "{s}Knee", "{s}Ankle", "{s}Toe"),
        ("{s}Collar", "{s}Shoulder", "{s}Elbow", "{s}Wrist"),
        "Chest4",
    ),
    RigNaming(
        "smpl", "SMPL / AMASS", ("L", "R"),
        _trunk("Pelvis=pelvis", "Spine1=spine", "Spine2=spine", "Spine3=spine", "Neck=neck",
               "Head=head"),
        ("{s}_Hip", "{s}_Knee", "{s}_Ankle", "{s}_Foot"),
        ("{s}_Collar", "{s}_Shoulder", "{s}_Elbow", "{s}_Wrist", "{s}_Hand"),
        "Spine3",
    ),
    RigNaming(
        "smplx", "SMPL-X (lower case)", ("left", "right"),
        _trunk("pelvis=pelvis", "spine1=spine", "spine2=spine", "spine3=spine", "neck=neck",
               "head=head"),
        ("{s}_hip", "{s}_knee", "{s}_ankle", "{s}_foot"),
        ("{s}_collar", "{s}_shoulder", "{s}_elbow", "{s}_wrist", "{s}_index1"),
        "spine3",
    ),
    RigNaming(
        "rokoko", "Rokoko (Newton)", ("Left", "Right"),
        _trunk("Hips=pelvis", "Spine1=spine", "Spine2=spine", "Spine3=spine", "Spine4=spine",
               "Neck=neck", "Head=head"),
        ("{s}Thigh", "{s}Shin", "{s}Foot", "{s}Toe"),
        ("{s}Shoulder", "{s}Arm", "{s}ForeArm", "{s}Hand"),
        "Spine4",
    ),
    RigNaming(
        "unreal", "Unreal Engine mannequin", ("l", "r"),
        _trunk("root=root", "pelvis=pelvis", "spine_01=spine", "spine_02=spine",
               "spine_03=spine", "neck_01=neck", "head=head"),
        ("thigh_{s}", "calf_{s}", "foot_{s}", "ball_{s}"),
        ("clavicle_{s}", "upperarm_{s}", "lowerarm_{s}", "hand_{s}", "thumb_01_{s}"),
        "spine_03",
    ),
    RigNaming(
        "blender", "Blender / Rigify", ("L", "R"),
        # Rigify numbers its neck and head as spine.004 and spine.006: spine by name
        _trunk("spine=spine", "spine.001=spine", "spine.003=spine", "spine.004=spine",
               "spine.006=spine"),
        ("thigh.{s}", "shin.{s}", "foot.{s}", "toe.{s}"),
        ("shoulder.{s}", "upper_arm.{s}", "forearm.{s}", "hand.{s}"),
        "spine.003",
    ),
    RigNaming(
        "biped", "3ds Max Biped", ("L", "R"),
        _trunk("Bip01=", "Bip01 Pelvis=pelvis", "Bip01 Spine=spine", "Bip01 Spine1=spine",
               "Bip01 Neck=neck", "Bip01 Head=head"),
        ("Bip01 {s} Thigh", "Bip01 {s} Calf", "Bip01 {s} Foot", "Bip01 {s} Toe0"),
        ("Bip01 {s} Clavicle", "Bip01 {s} UpperArm", "Bip01 {s} Forearm", "Bip01 {s} Hand",
         "Bip01 {s} Finger0"),
        "Bip01 Spine1",
    ),
)


def name_words(name: str) -> list[str]:
    """The lower-case words of a joint name, its namespace dropped.

    ``"mixamorig:LeftToeBase"`` -> ``["left", "toe", "base"]``, ``"calf_twist_01_l"`` ->
    ``["calf", "twist", "01", "l"]``, ``"LHipJoint"`` -> ``["l", "hip", "joint"]``.
    """
    base = re.split(r"[:|]", name)[-1]
    words: list[str] = []
    for part in re.split(r"[^A-Za-z0-9]+", base):
        words += [w.lower() for w in _WORD.findall(part)]
    return words


def is_ignored_name(name: str) -> bool:
    """Whether a joint is named as no part of the body's chain (:data:`IGNORED_WORDS`: end,
    tip, twist, IK, control and prop joints such as ``LeftToe_End`` or ``Prop1``)."""
    return any(w in IGNORED_WORDS for w in name_words(name))


def _split_glued_side(word: str) -> tuple[str, str] | None:
    """CMU's ``lfoot`` -> ``("left", "foot")``: a side letter glued to a body word."""
    if len(word) > 2 and word[0] in "lr":
        rest = word[1:]
        if rest in ROLE_WORDS or rest in FINGER_WORDS:
            return _SIDE_WORDS[word[0]], rest
    return None


def _match(words: list[str]) -> tuple[str, int, int] | None:
    """The role of the longest run of ``words`` that is a body word: ``(role, start, stop)``;
    among runs as long, the last (``Bip01 L Foot``: the body word comes last)."""
    for n in range(len(words), 0, -1):
        for start in range(len(words) - n, -1, -1):
            run = "".join(words[start : start + n])
            if run in ROLE_WORDS:
                return ROLE_WORDS[run], start, start + n
    return None


@functools.lru_cache(maxsize=4096)
def _classify(name: str) -> tuple[JointRole, str] | None:
    """:func:`classify_joint` and the body word that gave the role (a name's reading
    depends on the name alone, so each is read once)."""
    base = re.split(r"[:|]", name)[-1]
    if _VERTEBRA.fullmatch(base):  # Xsens MVN's L5, L3, T12, T8
        return JointRole("spine"), "vertebra"
    side = None
    body: list[str] = []
    for w in name_words(name):
        if w.isdigit():
            continue
        if w in IGNORED_WORDS:
            return None
        if side is None and w in _SIDE_WORDS:
            side = _SIDE_WORDS[w]
            continue
        glued = None if w in ROLE_WORDS else _split_glued_side(w)
        if side is None and glued is not None:
            side, w = glued
        body.append(w)
    if not body:
        return None
    if any(w in FINGER_WORDS for w in body):
        return (JointRole("fingers", side), "finger") if side else None
    found = _match(body)
    if found is None:
        return None
    role, start, stop = found
    word = "".join(body[start:stop])
    limbs = [_LIMB_WORDS[w] for i, w in enumerate(body) if w in _LIMB_WORDS
             and not start <= i < stop]
    limb = limbs[0] if limbs and role in LEG_ROLES and side else None
    if role == "hip" and side is None:
        role = "pelvis"  # a lone "Hip" is the body's hips
    if side is None and role in LEG_ROLES + ("clavicle", "shoulder", "elbow", "hand"):
        return None  # a limb joint needs a side
    return JointRole(role, side, limb), word


def classify_joint(name: str) -> JointRole | None:
    """The role and side of one joint from its name alone, or None when the name says nothing.

    Parameters
    ----------
    name : str
        A joint name in any of the conventions of :data:`RIG_NAMINGS` (or one like them).

    Returns
    -------
    JointRole or None
        E.g. ``JointRole("ankle", "left")`` for ``lfoot``, ``LeftFoot``, ``Foot_L``,
        ``foot_l``, ``L_Ankle``; ``JointRole("toe", "right")`` for ``RightToeBase``;
        ``JointRole("ankle", "left", "hind")`` for ``LeftHindFoot``; None for ``j12``,
        ``LeftToe_End`` or ``Prop1``.  Words that mean different joints in different
        rigs are read here in the commonest sense (``L_Foot``: an ankle); see
        :func:`classify_skeleton` for names read in their skeleton.
    """
    found = _classify(name)
    return None if found is None else found[0]


def classify_skeleton(skeleton: Skeleton) -> dict[str, JointRole]:
    """The role and side of every joint whose name says one, settled by the hierarchy.

    Parameters
    ----------
    skeleton : Skeleton

    Returns
    -------
    dict of str to JointRole
        Joint name to role, for the joints :func:`classify_joint` recognises; on each
        side's chain a ``foot`` below an ``ankle`` is read as the toes (SMPL's ``L_Foot``),
        a ``hand`` below a ``wrist`` or another hand as the fingers (SMPL's ``L_Hand``,
        CMU's ``lhand``), a ``shoulder`` with an upper arm below it as the clavicle
        (Mixamo's ``LeftShoulder``, Bandai's ``Shoulder_L``) and a hip joint with another
        below it as a pelvis bone.
    """
    key = tuple((j.name, j.parent) for j in skeleton.joints)
    cached = _SKELETON_ROLES.get(skeleton)
    if cached is None or cached[0] != key:
        cached = (key, _classify_skeleton(skeleton))
        _SKELETON_ROLES[skeleton] = cached
    return dict(cached[1])


#: classify_skeleton's answers by skeleton (with the names and parents they read)
_SKELETON_ROLES: "weakref.WeakKeyDictionary[Skeleton, tuple]" = weakref.WeakKeyDictionary()


def _classify_skeleton(skeleton: Skeleton) -> dict[str, JointRole]:
    found = {j.name: _classify(j.name) for j in skeleton.joints}
    roles = {n: f[0] for n, f in found.items() if f is not None}
    words = {n: f[1] for n, f in found.items() if f is not None}
    joints = skeleton.joints
    names = [j.name for j in joints]
    above: list[list[JointRole]] = []  # recognised ancestors of each joint
    for j in joints:
        up = [] if j.parent < 0 else list(above[j.parent])
        if j.parent >= 0 and names[j.parent] in roles:
            up.append(roles[names[j.parent]])
        above.append(up)
    below: list[list[JointRole]] = [[] for _ in joints]  # recognised descendants
    for i in range(len(joints) - 1, 0, -1):
        p = joints[i].parent
        below[p] += below[i] + ([roles[names[i]]] if names[i] in roles else [])

    def on_chain(r: JointRole, others: list[JointRole], role: str) -> bool:
        return any(o.role == role and o.side == r.side and o.limb == r.limb for o in others)

    out: dict[str, JointRole] = {}
    for i, name in enumerate(names):
        r = roles.get(name)
        if r is None:
            continue
        if r.role == "ankle" and words[name] == "foot" and on_chain(r, above[i], "ankle"):
            r = JointRole("toe", r.side, r.limb)
        elif r.role == "hand" and on_chain(r, above[i], "hand"):
            r = JointRole("fingers", r.side, r.limb)
        elif r.role == "shoulder" and words[name] == "shoulder" and on_chain(
            r, below[i], "shoulder"
        ):
            r = JointRole("clavicle", r.side, r.limb)
        elif r.role == "hip" and on_chain(r, below[i], "hip"):
            r = JointRole("pelvis", r.side, r.limb)
        out[name] = r
    return out
