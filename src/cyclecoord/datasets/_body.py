"""The synthetic body of :mod:`cyclecoord.datasets`: skeleton, poses, style, timing, noise.

Private to the package: :mod:`~cyclecoord.datasets.captures` and
:mod:`~cyclecoord.datasets.whole_take` build their captures from these pieces.  The
skeleton's conventions are described in :mod:`cyclecoord.datasets`.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ..skeleton import Joint, Skeleton, rotation_order_from_dofs

__all__ = [
    "capture_pair",
    "TAU",
    "KINDS",
    "DEFAULT_PERIODS",
    "AMC_JOINT_ORDER",
    "CHANNELS",
    "COL",
    "ANGLE_COLS",
    "TRANSLATION_NOISE_PER_DEGREE",
    "cmu_skeleton",
    "STRIDE",
    "POSES",
    "standing_pose",
    "draw_style",
    "pose_to_frames",
    "ground",
    "render_kind",
    "draw_phase_law",
    "add_noise",
    "seed_text",
    "check_int",
    "check_float",
    "check_kind",
    "check_random_state",
    "smoothstep",
]

TAU = 2.0 * np.pi

#: Periodic motions :func:`make_periodic_capture` can generate.
KINDS = ("walk", "jog", "jumping_jack", "arm_circles", "squat")

#: Natural period (frames at 120 fps) of each kind, used by :func:`make_motion_chain`.
DEFAULT_PERIODS = {
    "walk": 120.0,
    "jog": 80.0,
    "jumping_jack": 90.0,
    "arm_circles": 100.0,
    "squat": 150.0,
}

#: Joints in the order a CMU AMC frame lists them, with their degrees of freedom.
_AMC_LAYOUT: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("root", ("tx", "ty", "tz", "rx", "ry", "rz")),
    ("lowerback", ("rx", "ry", "rz")),
    ("upperback", ("rx", "ry", "rz")),
    ("thorax", ("rx", "ry", "rz")),
    ("lowerneck", ("rx", "ry", "rz")),
    ("upperneck", ("rx", "ry", "rz")),
    ("head", ("rx", "ry", "rz")),
    ("rclavicle", ("ry", "rz")),
    ("rhumerus", ("rx", "ry", "rz")),
    ("rradius", ("rx",)),
    ("rwrist", ("ry",)),
    ("rhand", ("rx", "rz")),
    ("rfingers", ("rx",)),
    ("rthumb", ("rx", "rz")),
    ("lclavicle", ("ry", "rz")),
    ("lhumerus", ("rx", "ry", "rz")),
    ("lradius", ("rx",)),
    ("lwrist", ("ry",)),
    ("lhand", ("rx", "rz")),
    ("lfingers", ("rx",)),
    ("lthumb", ("rx", "rz")),
    ("rfemur", ("rx", "ry", "rz")),
    ("rtibia", ("rx",)),
    ("rfoot", ("rx", "rz")),
    ("rtoes", ("rx",)),
    ("lfemur", ("rx", "ry", "rz")),
    ("ltibia", ("rx",)),
    ("lfoot", ("rx", "rz")),
    ("ltoes", ("rx",)),
)

#: Joint names in CMU AMC frame order (the order of :data:`CHANNELS`' joints).
AMC_JOINT_ORDER: tuple[str, ...] = tuple(name for name, _ in _AMC_LAYOUT)

#: The 62 channels of every generated motion, in CMU AMC order.
CHANNELS: tuple[tuple[str, str], ...] = tuple(
    (name, dof) for name, dofs in _AMC_LAYOUT for dof in dofs
)

COL = {c: i for i, c in enumerate(CHANNELS)}

_TRANSLATION_COLS = np.array([COL[("root", d)] for d in ("tx", "ty", "tz")])

ANGLE_COLS = np.array([i for i, (_, d) in enumerate(CHANNELS) if d.startswith("r")])

#: Translation noise (length units) per degree of angle noise: 0.5 deg -> 0.02 units (~1 mm).
TRANSLATION_NOISE_PER_DEGREE = 0.04

#: Points that can touch the floor: ankles, balls of the feet, toe tips.
_CONTACT_POINTS = ("lfoot", "ltoes", "ltoes/end", "rfoot", "rtoes", "rtoes/end")

# Bone vectors (joint -> the start of its children) in the rest pose: standing upright,
# arms hanging at the sides, facing +z.  Left is +x.
_BONES: dict[str, tuple[float, float, float]] = {
    "lhipjoint": (1.5, -1.8, 0.0),
    "lfemur": (0.0, -7.4, 0.0),
    "ltibia": (0.0, -7.5, 0.0),
    "lfoot": (0.0, -0.6, 1.9),
    "ltoes": (0.0, 0.0, 1.0),
    "lowerback": (0.0, 2.1, -0.1),
    "upperback": (0.0, 2.1, 0.0),
    "thorax": (0.0, 2.2, 0.1),
    "lowerneck": (0.0, 1.6, 0.2),
    "upperneck": (0.0, 1.7, -0.1),
    "head": (0.0, 1.9, 0.0),
    "lclavicle": (3.2, 0.9, -0.2),
    "lhumerus": (0.0, -5.3, 0.0),
    "lradius": (0.0, -3.6, 0.0),
    "lwrist": (0.0, -1.8, 0.0),
    "lhand": (0.0, -0.55, 0.0),
    "lfingers": (0.0, -0.45, 0.0),
    "lthumb": (0.0, -0.45, 0.45),
}

# (joint, parent) in hierarchy order (parents first), as an ASF :hierarchy would give.
_HIERARCHY: tuple[tuple[str, str | None], ...] = (
    ("root", None),
    ("lhipjoint", "root"),
    ("lfemur", "lhipjoint"),
    ("ltibia", "lfemur"),
    ("lfoot", "ltibia"),
    ("ltoes", "lfoot"),
    ("rhipjoint", "root"),
    ("rfemur", "rhipjoint"),
    ("rtibia", "rfemur"),
    ("rfoot", "rtibia"),
    ("rtoes", "rfoot"),
    ("lowerback", "root"),
    ("upperback", "lowerback"),
    ("thorax", "upperback"),
    ("lowerneck", "thorax"),
    ("upperneck", "lowerneck"),
    ("head", "upperneck"),
    ("lclavicle", "thorax"),
    ("lhumerus", "lclavicle"),
    ("lradius", "lhumerus"),
    ("lwrist", "lradius"),
    ("lhand", "lwrist"),
    ("lfingers", "lhand"),
    ("lthumb", "lwrist"),
    ("rclavicle", "thorax"),
    ("rhumerus", "rclavicle"),
    ("rradius", "rhumerus"),
    ("rwrist", "rradius"),
    ("rhand", "rwrist"),
    ("rfingers", "rhand"),
    ("rthumb", "rwrist"),
)


def capture_pair(
    noisy: np.ndarray,
    clean: np.ndarray,
    channels,
    skeleton: Skeleton,
    source: str,
    metadata: dict,
    fps: float | None = None,
) -> dict[str, Motion]:
    """The noisy capture and its clean twin (``source + ":clean"``, its own copy of the
    metadata), as the ``motion`` and ``clean`` of a synthetic capture."""
    rate = {} if fps is None else {"fps": fps}
    return {
        "motion": Motion(noisy, channels, skeleton=skeleton, source=source, metadata=metadata,
                         **rate),
        "clean": Motion(clean, channels, skeleton=skeleton, source=source + ":clean",
                        metadata=dict(metadata), **rate),
    }


def _bone(name: str) -> np.ndarray:
    """Rest bone vector of a joint; right-side bones mirror the left ones (x -> -x)."""
    if name in _BONES:
        return np.array(_BONES[name], dtype=float)
    if name.startswith("r") and "l" + name[1:] in _BONES:
        v = np.array(_BONES["l" + name[1:]], dtype=float)
        v[0] = -v[0]
        return v
    raise KeyError(name)  # pragma: no cover - internal tables are complete


# --------------------------------------------------------------------------- skeleton
def cmu_skeleton() -> Skeleton:
    """A CMU-like 31-joint, 62-DOF skeleton built in code.

    Joint names, hierarchy and degrees of freedom follow the CMU ASF files (root with
    6 dofs, zero-dof ``lhipjoint``/``rhipjoint``, ``rx ry rz`` spine and neck, ``ry rz``
    clavicles, ...); bone vectors are of this module's choosing with human proportions
    (see the module docstring for units and sign conventions).  Joint axes are the
    identity and the rotation order is the ASF one (``rx ry rz`` -> intrinsic
    ``"ZYX"``).  Leaves (toes, head, fingers, thumbs) carry end sites.

    Returns
    -------
    Skeleton
        ``source_format="synthetic"``, ``length_unit=0.45``; zero channels give the rest
        pose: upright, arms hanging, facing +z, pelvis at the origin.
    """
    dofs = dict(_AMC_LAYOUT)
    index: dict[str, int] = {}
    has_children = {parent for _, parent in _HIERARCHY if parent is not None}
    joints = []
    for name, parent in _HIERARCHY:
        jd = dofs.get(name, ())
        offset = np.zeros(3) if parent is None or parent == "root" else _bone(parent)
        joints.append(
            Joint(
                name=name,
                parent=-1 if parent is None else index[parent],
                offset=offset,
                dofs=jd,
                rotation_order=rotation_order_from_dofs(jd, reverse=True),
                end_site=None if name in has_children else _bone(name),
            )
        )
        index[name] = len(joints) - 1
    return Skeleton(
        tuple(joints), name="synthetic-cmu", length_unit=0.45, source_format="synthetic"
    )


# ------------------------------------------------------------------- shape helpers
def _wave(phi: np.ndarray, amplitude: float, k: int, peak: float) -> np.ndarray:
    """``amplitude * cos(2 pi k (phi - peak))``: k-th harmonic peaking at phase ``peak``."""
    return amplitude * np.cos(TAU * k * (phi - peak))


def _bump(phi: np.ndarray, center: float, kappa: float) -> np.ndarray:
    """Periodic bump (von Mises shape) of height 1 at ``center``, width ~ 1/sqrt(kappa)."""
    return np.exp(kappa * (np.cos(TAU * (phi - center)) - 1.0))


def _smooth_open(phi: np.ndarray) -> np.ndarray:
    """0 at phase 0, 1 at phase 0.5, with flattened extremes (three harmonics)."""
    return 0.5 - 0.5625 * np.cos(TAU * phi) + 0.0625 * np.cos(3 * TAU * phi)


Pose = dict[tuple[str, str], "np.ndarray | float"]


def _set_both(
    pose: Pose, joint: str, dof: str, right: np.ndarray | float, left: np.ndarray | float
) -> None:
    pose[("r" + joint, dof)] = right
    pose[("l" + joint, dof)] = left


def _hands(pose: Pose, n: int) -> None:
    """Relaxed wrists, hands, fingers and thumbs (mirrored constants)."""
    one = np.ones(n)
    _set_both(pose, "wrist", "ry", 6 * one, -6 * one)
    _set_both(pose, "hand", "rx", -6 * one, -6 * one)
    _set_both(pose, "hand", "rz", 3 * one, -3 * one)
    _set_both(pose, "fingers", "rx", -10 * one, -10 * one)
    _set_both(pose, "thumb", "rx", -12 * one, -12 * one)
    _set_both(pose, "thumb", "rz", 15 * one, -15 * one)


_GAIT = {
    "walk": dict(
        hip_mean=10.0, hip_amp=21.0, knee_rest=3.0, knee_swing=55.0, swing_at=0.72,
        swing_kappa=6.0, knee_stance=14.0, ankle=(5.0, 10.0, 18.0), toe=20.0,
        arm_mean=4.0, arm_amp=14.0, elbow_mean=15.0, elbow_amp=8.0, arm_abd=7.0,
        pelvis_yaw=4.0, pelvis_roll=3.0, lean=3.0, pitch_amp=1.5, back_lean=2.0,
        sway=0.7, flight=0.0, wobble=0.25,
    ),
    "jog": dict(
        hip_mean=15.0, hip_amp=32.0, knee_rest=12.0, knee_swing=80.0, swing_at=0.68,
        swing_kappa=5.0, knee_stance=28.0, ankle=(4.0, 15.0, 22.0), toe=25.0,
        arm_mean=8.0, arm_amp=28.0, elbow_mean=85.0, elbow_amp=12.0, arm_abd=12.0,
        pelvis_yaw=7.0, pelvis_roll=4.0, lean=8.0, pitch_amp=2.5, back_lean=6.0,
        sway=0.4, flight=1.0, wobble=0.4,
    ),
}

#: Forward progression of the root per cycle (length units).
STRIDE = {"walk": 26.0, "jog": 42.0, "jumping_jack": 0.5, "arm_circles": 0.3, "squat": 0.2}


def _gait_pose(phi: np.ndarray, amp: float, p: dict) -> Pose:
    """Walk or jog: phase 0 is the right heel strike; the left side runs half a cycle later."""
    pose: Pose = {}
    for side, shift, s in (("r", 0.0, -1.0), ("l", 0.5, 1.0)):
        psi = phi + shift
        hip = p["hip_mean"] + amp * (
            _wave(psi, p["hip_amp"], 1, 0.92) + _wave(psi, 0.12 * p["hip_amp"], 2, 0.1)
        )
        knee = p["knee_rest"] + amp * (
            p["knee_swing"] * _bump(psi, p["swing_at"], p["swing_kappa"])
            + p["knee_stance"] * _bump(psi, 0.14, 18.0)
        )
        a1, a2, a3 = p["ankle"]
        plantar = amp * (
            a1 * _bump(psi, 0.07, 20.0) - a2 * _bump(psi, 0.42, 8.0) + a3 * _bump(psi, 0.62, 20.0)
        )
        pose[(side + "femur", "rx")] = -hip
        pose[(side + "femur", "ry")] = -s * amp * _wave(psi, 3.0, 1, 0.3)
        pose[(side + "femur", "rz")] = s * (1.5 + amp * _wave(psi, 3.0, 1, 0.6))
        pose[(side + "tibia", "rx")] = knee
        pose[(side + "foot", "rx")] = plantar
        pose[(side + "foot", "rz")] = -s * (2.0 + _wave(psi, 2.0, 1, 0.0))
        pose[(side + "toes", "rx")] = -amp * p["toe"] * _bump(psi, 0.58, 15.0)
        # the arm swings with the opposite leg, a little late
        arm_psi = psi + 0.5
        flex = p["arm_mean"] + amp * (
            _wave(arm_psi, p["arm_amp"], 1, 0.97) + _wave(arm_psi, 0.1 * p["arm_amp"], 2, 0.2)
        )
        elbow = p["elbow_mean"] + amp * _wave(arm_psi, p["elbow_amp"], 1, 0.0)
        pose[(side + "humerus", "rx")] = -flex
        pose[(side + "humerus", "ry")] = -s * 5.0
        pose[(side + "humerus", "rz")] = s * (p["arm_abd"] + amp * _wave(psi, 1.5, 2, 0.3))
        pose[(side + "radius", "rx")] = -elbow
    _hands(pose, phi.shape[0])
    yaw = amp * _wave(phi, p["pelvis_yaw"], 1, 0.0)
    roll = amp * _wave(phi, p["pelvis_roll"], 1, 0.2)
    pose[("root", "rx")] = p["lean"] + amp * _wave(phi, p["pitch_amp"], 2, 0.1)
    pose[("root", "ry")] = yaw
    pose[("root", "rz")] = roll
    pose[("lowerback", "rx")] = p["back_lean"] + amp * _wave(phi, 1.0, 2, 0.35)
    pose[("lowerback", "ry")] = -0.4 * yaw
    pose[("lowerback", "rz")] = -0.5 * roll
    pose[("upperback", "rx")] = 0.5 * p["back_lean"]
    pose[("upperback", "ry")] = -0.4 * yaw
    pose[("thorax", "ry")] = -0.4 * yaw
    pose[("thorax", "rz")] = -0.3 * roll
    # the neck brings the gaze back to level; the head bobs slightly twice per cycle
    pose[("lowerneck", "rx")] = -0.6 * (p["lean"] + 1.5 * p["back_lean"])
    pose[("upperneck", "rx")] = amp * _wave(phi, 1.0, 2, 0.3)
    pose[("head", "ry")] = 0.2 * yaw
    pose[("root", "tx")] = -amp * _wave(phi, p["sway"], 1, 0.25)
    pose[("root", "ty")] = amp * p["flight"] * (_bump(phi, 0.45, 10.0) + _bump(phi, 0.95, 10.0))
    pose[("root", "tz")] = amp * _wave(phi, p["wobble"], 2, 0.125)
    return pose


def _walk_pose(phi: np.ndarray, amp: float) -> Pose:
    return _gait_pose(phi, amp, _GAIT["walk"])


def _jog_pose(phi: np.ndarray, amp: float) -> Pose:
    return _gait_pose(phi, amp, _GAIT["jog"])


def _jumping_jack_pose(phi: np.ndarray, amp: float) -> Pose:
    """Phase 0: feet together, arms down; ~0.5: feet apart, arms overhead; jumps at 0.25, 0.75.

    The legs lead the arms slightly and the elbows bend on the way down, so the cycle
    traces a loop rather than the same path out and back.
    """
    pose: Pose = {}
    legs = _smooth_open(phi + 0.04)
    arms = _smooth_open(phi - 0.04)
    elbows = _smooth_open(phi - 0.16)
    landing = _bump(phi, 0.38, 14.0) + 0.7 * _bump(phi, 0.88, 14.0)
    pushoff = _bump(phi, 0.14, 14.0) + 0.7 * _bump(phi, 0.64, 14.0)
    airborne = _bump(phi, 0.25, 12.0) + 0.7 * _bump(phi, 0.75, 12.0)
    knee = 6.0 + amp * (22.0 * landing + 12.0 * pushoff)
    for side, s in (("r", -1.0), ("l", 1.0)):
        pose[(side + "humerus", "rz")] = s * (8.0 + amp * 150.0 * arms)
        pose[(side + "humerus", "rx")] = -amp * (4.0 * arms + _wave(phi, 6.0, 1, 0.3))
        pose[(side + "humerus", "ry")] = -s * (5.0 + 10.0 * arms)
        pose[(side + "radius", "rx")] = -(8.0 + amp * 25.0 * elbows)
        pose[(side + "femur", "rz")] = s * (2.0 + amp * 13.0 * legs)
        pose[(side + "femur", "rx")] = -0.6 * knee
        pose[(side + "femur", "ry")] = -s * amp * 6.0 * legs
        pose[(side + "tibia", "rx")] = knee
        pose[(side + "foot", "rx")] = -0.4 * knee + amp * 25.0 * airborne
        pose[(side + "foot", "rz")] = -s * amp * 10.0 * legs
        pose[(side + "toes", "rx")] = -amp * 10.0 * pushoff
    _hands(pose, phi.shape[0])
    pose[("lowerback", "rx")] = 2.0 + amp * (3.0 * landing - 2.0 * arms)
    pose[("thorax", "rx")] = -amp * 2.0 * arms
    pose[("lowerneck", "rx")] = -2.0 + amp * 2.0 * arms
    pose[("head", "rx")] = amp * (-3.0 * landing + _wave(phi, 1.0, 2, 0.2))
    pose[("root", "rx")] = 2.0 + amp * 4.0 * landing
    pose[("root", "ty")] = amp * 1.6 * airborne
    pose[("root", "tz")] = amp * _wave(phi, 0.1, 2, 0.25)
    return pose


def _arm_circles_pose(phi: np.ndarray, amp: float) -> Pose:
    """Arms held out sideways tracing forward circles; legs and trunk nearly still."""
    pose: Pose = {}
    c = np.cos(TAU * phi)
    sn = np.sin(TAU * phi)
    for side, s in (("r", -1.0), ("l", 1.0)):
        pose[(side + "humerus", "rz")] = s * (88.0 + amp * (22.0 * c + _wave(phi, 3.0, 2, 0.05)))
        pose[(side + "humerus", "rx")] = -amp * (22.0 * sn + _wave(phi, 2.0, 2, 0.2))
        pose[(side + "humerus", "ry")] = -s * (10.0 + amp * 8.0 * sn)
        pose[(side + "radius", "rx")] = -(4.0 + amp * 3.0 * (1.0 + c))
        pose[(side + "femur", "rx")] = -(3.0 + amp * _wave(phi, 1.0, 1, 0.1))
        pose[(side + "femur", "rz")] = s * 4.0
        pose[(side + "tibia", "rx")] = 4.0 + amp * _wave(phi, 1.5, 2, 0.0)
        pose[(side + "foot", "rx")] = -2.0
        pose[(side + "foot", "rz")] = -s * 3.0
    _hands(pose, phi.shape[0])
    pose[("thorax", "rx")] = amp * _wave(phi, 1.5, 1, 0.75)
    pose[("upperback", "rx")] = amp * _wave(phi, 1.0, 1, 0.7)
    pose[("lowerneck", "rx")] = -amp * _wave(phi, 1.5, 1, 0.75)
    pose[("head", "rx")] = amp * _wave(phi, 0.8, 2, 0.1)
    pose[("root", "rx")] = 1.0 + amp * _wave(phi, 1.0, 1, 0.8)
    pose[("root", "tx")] = amp * _wave(phi, 0.15, 1, 0.3)
    pose[("root", "tz")] = amp * _wave(phi, 0.2, 1, 0.75)
    return pose


def _squat_pose(phi: np.ndarray, amp: float) -> Pose:
    """Phase 0 standing, about 0.5 deepest; going down takes longer than coming up.

    The arms rise ahead of the descent and the trunk lean lags it, so the cycle traces
    a loop rather than the same path down and up.
    """
    pose: Pose = {}
    warped = phi + 0.04 * np.sin(TAU * phi)
    depth = amp * _smooth_open(warped)
    hips = amp * _smooth_open(warped - 0.03)
    arms = amp * _smooth_open(warped + 0.1)
    trunk = amp * _smooth_open(warped - 0.08)
    pelvis = 15.0 * hips
    femur = -(5.0 + 85.0 * hips)
    tibia = 5.0 + 105.0 * depth
    for side, s in (("r", -1.0), ("l", 1.0)):
        pose[(side + "femur", "rx")] = femur
        pose[(side + "femur", "rz")] = s * (3.0 + 8.0 * depth)
        pose[(side + "femur", "ry")] = -s * 6.0 * depth
        pose[(side + "tibia", "rx")] = tibia
        # keep the sole flat: undo the pitch of the shin
        pose[(side + "foot", "rx")] = -(pelvis + femur + tibia)
        pose[(side + "foot", "rz")] = -s * 3.0
        pose[(side + "humerus", "rx")] = -(5.0 + 75.0 * arms)
        pose[(side + "humerus", "rz")] = s * (6.0 + 4.0 * arms)
        pose[(side + "humerus", "ry")] = -s * 5.0
        pose[(side + "radius", "rx")] = -(10.0 + 10.0 * arms)
    _hands(pose, phi.shape[0])
    pose[("root", "rx")] = pelvis
    pose[("lowerback", "rx")] = 2.0 + 10.0 * trunk
    pose[("upperback", "rx")] = 8.0 * trunk
    pose[("thorax", "rx")] = 5.0 * trunk
    pose[("lowerneck", "rx")] = -2.0 - 15.0 * trunk
    pose[("upperneck", "rx")] = -8.0 * trunk
    pose[("head", "rx")] = -5.0 * trunk + amp * _wave(phi, 1.0, 2, 0.3)
    # the pelvis moves back as the hips sink (balance over the feet)
    pose[("root", "tz")] = -3.0 * hips
    return pose


POSES: dict[str, Callable[[np.ndarray, float], Pose]] = {
    "walk": _walk_pose,
    "jog": _jog_pose,
    "jumping_jack": _jumping_jack_pose,
    "arm_circles": _arm_circles_pose,
    "squat": _squat_pose,
}


def standing_pose(n: int) -> Pose:
    """Quiet standing: arms hanging, knees and elbows slightly bent."""
    pose: Pose = {}
    one = np.ones(n)
    for side, s in (("r", -1.0), ("l", 1.0)):
        pose[(side + "femur", "rx")] = -3.0 * one
        pose[(side + "femur", "rz")] = s * 3.0 * one
        pose[(side + "tibia", "rx")] = 4.0 * one
        pose[(side + "foot", "rx")] = -1.0 * one
        pose[(side + "foot", "rz")] = -s * 3.0 * one
        pose[(side + "humerus", "rx")] = -4.0 * one
        pose[(side + "humerus", "rz")] = s * 7.0 * one
        pose[(side + "humerus", "ry")] = -s * 5.0 * one
        pose[(side + "radius", "rx")] = -12.0 * one
    _hands(pose, n)
    pose[("root", "rx")] = 2.0 * one
    pose[("lowerback", "rx")] = 2.0 * one
    pose[("lowerneck", "rx")] = -3.0 * one
    return pose


# ------------------------------------------------------------------ generator core
@dataclass(frozen=True)
class _Style:
    """Per-seed variation of one performer: overall amplitude and posture offsets."""

    amp: float
    posture: np.ndarray  # (62,) degrees added to the non-root angle channels


def draw_style(rng: np.random.Generator) -> _Style:
    posture = np.zeros(len(CHANNELS))
    for i, (joint, dof) in enumerate(CHANNELS):
        if joint != "root" and dof.startswith("r"):
            posture[i] = rng.normal(0.0, 1.0)
    return _Style(amp=float(rng.uniform(0.92, 1.08)), posture=posture)


def pose_to_frames(pose: Pose, n: int) -> np.ndarray:
    frames = np.zeros((n, len(CHANNELS)))
    for channel, values in pose.items():
        frames[:, COL[channel]] = values
    return frames


def ground(frames: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """Root height that puts the lowest foot point on the floor (y = 0), per frame."""
    probe = frames.copy()
    probe[:, _TRANSLATION_COLS] = 0.0
    pos = Motion(probe, CHANNELS, skeleton=skeleton).positions()
    idx = [pos.names.index(p) for p in _CONTACT_POINTS]
    return -pos.positions[:, idx, 1].min(axis=1)


def render_kind(kind: str, phase: np.ndarray, style: _Style, skeleton: Skeleton) -> np.ndarray:
    """Noise-free frames ``(T, 62)`` of ``kind`` at the given unwrapped phases.

    Every channel but root ``tz`` is a function of ``phase % 1`` alone; root ``tz``
    adds one stride per cycle of ``phase``.
    """
    phase = np.asarray(phase, dtype=float)
    phi = np.mod(phase, 1.0)
    frames = pose_to_frames(POSES[kind](phi, style.amp), phi.shape[0])
    frames += style.posture
    lift = frames[:, COL[("root", "ty")]].copy()
    frames[:, COL[("root", "ty")]] = ground(frames, skeleton) + lift
    frames[:, COL[("root", "tz")]] += STRIDE[kind] * phase
    return frames


@dataclass(frozen=True)
class _PhaseLaw:
    """Phase of time ``c * (t / P + w(t) - w(0))`` with a slow, bounded speed wobble.

    The instantaneous rate ``c / P * (1 + v * sum_i a_i sin(2 pi t / (P r_i) + th_i))``
    stays positive for ``v < 1``; ``c`` makes the phase advance exactly
    ``(n - 1) / P`` cycles over ``n`` frames, so the mean period is exactly ``P``.
    """

    period: float
    variation: float
    ratios: tuple[float, float]
    weights: tuple[float, float]
    offsets: tuple[float, float]
    scale: float = 1.0

    def raw(self, t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        out = t / self.period
        for r, a, th in zip(self.ratios, self.weights, self.offsets):
            wob = r / TAU * (np.cos(th) - np.cos(TAU * t / (self.period * r) + th))
            out = out + self.variation * a * wob
        return out

    def __call__(self, t: np.ndarray) -> np.ndarray:
        return self.scale * self.raw(t)


def draw_phase_law(rng: np.random.Generator, period: float, variation: float, n: int) -> _PhaseLaw:
    law = _PhaseLaw(
        period=period,
        variation=variation,
        ratios=(float(rng.uniform(1.6, 2.6)), float(rng.uniform(4.0, 7.0))),
        weights=(0.7, 0.3),
        offsets=(float(rng.uniform(0, TAU)), float(rng.uniform(0, TAU))),
    )
    span = float(law.raw(np.array([n - 1.0]))[0])
    return replace(law, scale=((n - 1) / period) / span)


def add_noise(clean: np.ndarray, noise: float, rng: np.random.Generator) -> np.ndarray:
    noisy = clean.copy()
    noisy[:, ANGLE_COLS] += rng.normal(0.0, noise, size=(clean.shape[0], ANGLE_COLS.size))
    noisy[:, _TRANSLATION_COLS] += rng.normal(
        0.0, noise * TRANSLATION_NOISE_PER_DEGREE, size=(clean.shape[0], 3)
    )
    return noisy


def seed_text(random_state: object) -> str:
    if random_state is None or isinstance(random_state, (int, np.integer)):
        return str(random_state)
    return type(random_state).__name__


# ----------------------------------------------------------------------- validation
def check_int(name: str, value: object, minimum: int) -> int:
    if isinstance(value, bool):
        raise ParameterError(f"{name} must be an integer, got {value!r}")
    try:
        out = operator.index(value)  # type: ignore[arg-type]
    except TypeError:
        raise ParameterError(f"{name} must be an integer, got {value!r}") from None
    if out < minimum:
        raise ParameterError(f"{name} must be at least {minimum}, got {out}")
    return out


def check_float(
    name: str, value: object, low: float, *, low_open: bool = False, high: float | None = None
) -> float:
    try:
        out = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError(f"{name} must be a number, got {value!r}") from None
    if not np.isfinite(out):
        raise ParameterError(f"{name} must be finite, got {value!r}")
    if out < low or (low_open and out == low):
        rel = ">" if low_open else ">="
        raise ParameterError(f"{name} must be {rel} {low:g}, got {out:g}")
    if high is not None and out >= high:
        raise ParameterError(f"{name} must be < {high:g}, got {out:g}")
    return out


def check_kind(kind: object) -> str:
    if not isinstance(kind, str) or kind not in POSES:
        raise ParameterError(f"unknown motion kind {kind!r}; choose one of {', '.join(KINDS)}")
    return kind


def check_random_state(random_state: object) -> np.random.Generator:
    try:
        return np.random.default_rng(random_state)  # type: ignore[arg-type]
    except (TypeError, ValueError) as exc:
        raise ParameterError(
            f"random_state must be None, an int or a numpy Generator: {exc}"
        ) from None


def smoothstep(x: np.ndarray) -> np.ndarray:
    """C2 ramp from 0 (x <= 0) to 1 (x >= 1)."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x))
