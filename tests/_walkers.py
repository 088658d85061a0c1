"""Synthetic walkers with exactly planted feet: a biped or a trotting quadruped built in code.

Each leg is hip -> knee -> ankle -> toe (thigh 4, shin 4, foot 1 forward and 0.5 down, toe
end site 0.5 forward); the hip and knee pitch are solved (two-link inverse kinematics) so
the ankle follows its target: fixed in the world during stance, lifted forward in swing.
The body walks along its heading (``heading_deg`` about y; 0 walks towards +z, so left is
+x).  Joint names come from a ``names`` mapping, so one body serves every convention.
"""

from __future__ import annotations

import numpy as np

from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton

THIGH = SHIN = 4.0
ANKLE_HEIGHT = 0.5  # ankle above the floor when planted (toe end site on the floor)
HIP_HEIGHT = 7.5
ROT = ("rx", "ry", "rz")


def _leg(joints, names, prefix, parent, hip_offset):
    """Append hip, knee, ankle, toe joints of one leg; return their names."""
    hip, knee, ankle, toe = (names[f"{prefix}{k}"] for k in ("hip", "knee", "ankle", "toe"))
    base = len(joints)
    joints += [
        Joint(hip, parent, hip_offset, ROT, "ZYX"),
        Joint(knee, base, [0, -THIGH, 0], ROT, "ZYX"),
        Joint(ankle, base + 1, [0, -SHIN, 0], ROT, "ZYX"),
        Joint(toe, base + 2, [0, -ANKLE_HEIGHT, 1.0], ROT, "ZYX", end_site=[0, 0, 0.5]),
    ]
    return hip, knee, ankle


def quadruped_skeleton(names: dict, width: float = 1.5, body: float = 8.0) -> Skeleton:
    """Pelvis root, spine to a chest ``body`` ahead, neck and head, tail, four legs."""
    j = [Joint(names["pelvis"], -1, [0, 0, 0], ("tx", "ty", "tz") + ROT, "ZYX")]
    j.append(Joint(names["spine"], 0, [0, 0, body / 2], ROT, "ZYX"))
    j.append(Joint(names["chest"], 1, [0, 0, body / 2], ROT, "ZYX"))
    j.append(Joint(names["neck"], 2, [0, 1.5, 1.0], ROT, "ZYX"))
    j.append(Joint(names["head"], 3, [0, 1.0, 1.0], ROT, "ZYX", end_site=[0, 0, 1.5]))
    j.append(Joint(names["tail"], 0, [0, 0.5, -1.0], ROT, "ZYX", end_site=[0, -1.0, -2.0]))
    for prefix, parent, x in (("hl_", 0, width), ("hr_", 0, -width)):
        _leg(j, names, prefix, parent, [x, 0, 0])
    for prefix, parent, x in (("fl_", 2, width), ("fr_", 2, -width)):
        _leg(j, names, prefix, parent, [x, 0, 0])
    return Skeleton(tuple(j), name="quadruped")


def biped_skeleton(names: dict, width: float = 1.0, prop: bool = True) -> Skeleton:
    """Pelvis root, left and right legs, spine, head, two arms hanging (and a long prop
    held in the right hand, reaching down towards the knee)."""
    j = [Joint(names["pelvis"], -1, [0, 0, 0], ("tx", "ty", "tz") + ROT, "ZYX")]
    _leg(j, names, "l_", 0, [width, 0, 0])
    _leg(j, names, "r_", 0, [-width, 0, 0])
    spine = len(j)
    j.append(Joint(names["spine"], 0, [0, 3.0, 0], ROT, "ZYX"))
    j.append(Joint(names["chest"], spine, [0, 3.0, 0], ROT, "ZYX"))
    j.append(Joint(names["head"], spine + 1, [0, 2.0, 0], ROT, "ZYX", end_site=[0, 1.5, 0]))
    for side, x in (("l_", 1), ("r_", -1)):
        base = len(j)
        j.append(Joint(names[f"{side}shoulder"], spine + 1, [x * 2.0, 1.0, 0], ROT, "ZYX"))
        j.append(Joint(names[f"{side}elbow"], base, [0, -3.0, 0], ROT, "ZYX"))
        j.append(Joint(names[f"{side}hand"], base + 1, [0, -3.0, 0], ROT, "ZYX",
                       end_site=[0, -0.8, 0]))
        if prop and side == "r_":
            j.append(Joint(names["prop"], base + 2, [0, -0.5, 0.5], ROT, "ZYX",
                           end_site=[0, -5.5, 2.0]))
    return Skeleton(tuple(j), name="biped")


def _two_link(dz, dy):
    """Hip and knee pitch (degrees, rx) putting the ankle at (dz, dy) from the hip."""
    r = np.hypot(dz, dy)
    cos_knee = np.clip((r**2 - THIGH**2 - SHIN**2) / (2 * THIGH * SHIN), -1.0, 1.0)
    beta = -np.arccos(cos_knee)  # knee bends forward
    phi = np.arctan2(-dz, -dy)  # direction of the ankle from straight down (+: backwards)
    gamma = np.arctan2(SHIN * np.sin(beta), THIGH + SHIN * np.cos(beta))
    alpha = phi - gamma
    return np.degrees(alpha), np.degrees(beta)


def walk(
    skeleton: Skeleton,
    legs: dict,
    *,
    n_frames: int = 120,
    fps: float = 30.0,
    period: float = 30.0,
    speed: float = 4.0,
    stance: float = 0.6,
    heading_deg: float = 0.0,
    lift: float = 1.0,
) -> Motion:
    """A walk (or trot) of ``skeleton``; ``legs`` maps each hip joint name to
    ``(knee, ankle, phase, hip_z)``: the leg's knee and ankle, its phase in ``[0, 1)`` and
    the hip's forward position in the body.  Stance feet stay fixed in the world."""
    ch = skeleton.channels
    col = {c: i for i, c in enumerate(ch)}
    root = skeleton.joints[0].name
    t = np.arange(n_frames) / fps
    frames = np.zeros((n_frames, len(ch)))
    travel = speed * t
    psi = np.radians(heading_deg)
    frames[:, col[(root, "tx")]] = np.sin(psi) * travel
    frames[:, col[(root, "tz")]] = np.cos(psi) * travel
    frames[:, col[(root, "ty")]] = HIP_HEIGHT
    frames[:, col[(root, "ry")]] = heading_deg
    T = period / fps  # seconds per cycle
    stride = speed * T
    for hip, (knee, ankle, phase, hip_z) in legs.items():
        s = np.mod(t / T + phase, 1.0)  # 0..stance: planted; stance..1: swing
        cycle = np.floor(t / T + phase)
        # the foot is planted under the hip at mid-stance: world z of its plant in cycle k
        mid = (cycle + 0.5 * stance - phase) * T
        plant = speed * mid + hip_z
        in_swing = s >= stance
        u = np.where(in_swing, (s - stance) / (1 - stance), 0.0)
        foot_z = np.where(in_swing, plant + u * stride, plant)
        foot_y = ANKLE_HEIGHT + np.where(in_swing, lift * np.sin(np.pi * u), 0.0)
        dz = foot_z - (travel + hip_z)
        dy = foot_y - HIP_HEIGHT
        a, b = _two_link(dz, dy)
        frames[:, col[(hip, "rx")]] = a
        frames[:, col[(knee, "rx")]] = b
        frames[:, col[(ankle, "rx")]] = -(a + b)
    return Motion(frames, ch, fps=fps, skeleton=skeleton, source="synthetic:walker")


def quadruped_names(style: str = "anonymous") -> dict:
    """Joint names of the quadruped: ``"anonymous"`` (j0, j1, ...), ``"dog"``
    (LeftFrontLeg ... RightHindToe), ``"front_first"`` (FrontLeftFoot ...) or ``"human"``
    (a dog rig named like a person: front legs are arms)."""
    keys = ["pelvis", "spine", "chest", "neck", "head", "tail"] + [
        f"{leg}_{part}" for leg in ("hl", "hr", "fl", "fr") for part in ("hip", "knee", "ankle", "toe")
    ]
    if style == "anonymous":
        return {k: f"j{i}" for i, k in enumerate(keys)}
    trunk = {"pelvis": "Hips", "spine": "Spine", "chest": "Chest", "neck": "Neck",
             "head": "Head", "tail": "Tail"}
    side = {"l": "Left", "r": "Right"}
    out = dict(trunk)
    for leg in ("hl", "hr", "fl", "fr"):
        s = side[leg[1]]
        if style == "dog":
            end = "Front" if leg[0] == "f" else "Hind"
            parts = (f"{s}{end}UpperLeg", f"{s}{end}Leg", f"{s}{end}Foot", f"{s}{end}Toe")
        elif style == "front_first":
            end = "Front" if leg[0] == "f" else "Back"
            parts = (f"{end}{s}Thigh", f"{end}{s}Shin", f"{end}{s}Foot", f"{end}{s}Toe")
        elif style == "human":
            if leg[0] == "f":
                parts = (f"{s}Arm", f"{s}ForeArm", f"{s}Hand", f"{s}HandIndex1")
            else:
                parts = (f"{s}UpLeg", f"{s}Leg", f"{s}Foot", f"{s}ToeBase")
        else:
            raise ValueError(style)
        for part, name in zip(("hip", "knee", "ankle", "toe"), parts):
            out[f"{leg}_{part}"] = name
    return out


def trot(skeleton: Skeleton, names: dict, body: float = 8.0, **options) -> Motion:
    """A trot: diagonal legs together (front left with hind right)."""
    legs = {}
    for leg, phase, z in (("fl", 0.0, body), ("hr", 0.0, 0.0), ("fr", 0.5, body),
                          ("hl", 0.5, 0.0)):
        legs[names[f"{leg}_hip"]] = (names[f"{leg}_knee"], names[f"{leg}_ankle"], phase, z)
    return walk(skeleton, legs, **options)


def biped_names(style: str = "anonymous") -> dict:
    """Joint names of the biped: ``"anonymous"`` (j0, j1, ...) or ``"mixamo"``."""
    keys = ["pelvis"] + [f"{s}_{p}" for s in ("l", "r") for p in ("hip", "knee", "ankle", "toe")]
    keys += ["spine", "chest", "head"]
    keys += [f"{s}_{p}" for s in ("l", "r") for p in ("shoulder", "elbow", "hand")] + ["prop"]
    if style == "anonymous":
        return {k: f"j{i}" for i, k in enumerate(keys)}
    raise ValueError(style)


def biped_walk(skeleton: Skeleton, names: dict, **options) -> Motion:
    legs = {
        names["l_hip"]: (names["l_knee"], names["l_ankle"], 0.0, 0.0),
        names["r_hip"]: (names["r_knee"], names["r_ankle"], 0.5, 0.0),
    }
    return walk(skeleton, legs, **options)
