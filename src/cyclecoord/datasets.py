"""Built-in synthetic captures (walk, jog, jumping jacks, ...) with known phase and labels.

Every generator returns a :class:`SyntheticCapture`: the noisy :class:`~cyclecoord.motion.Motion`
a user would load, the noise-free signal it was made from, and the ground truth the
pipeline's tests compare against (true phase, mean period, per-frame motion labels,
segment boundaries).  Nothing here reads a file, so the README's example and the tests
of the periodic pipeline need no data.

Conventions of :func:`cmu_skeleton` (all joint axes are the identity, so the rotation
channels act about world-aligned axes of the parent's frame; y is up, the character faces
+z and its left is +x):

* ``rx`` on a leg or arm bone: positive swings it backward (hip/shoulder extension),
  negative forward (flexion).  Knee flexion is positive ``tibia rx``; elbow flexion is
  *negative* ``radius rx``; ankle plantar flexion (toes down) is positive ``foot rx``.
* ``rz`` on the left limbs is abduction (away from the body), on the right limbs
  adduction; ``ry`` is rotation about the bone's long axis (vertical at rest).
* ``rx`` on the spine and neck leans forward; root ``ry`` is the heading (yaw).

Angles are in degrees; lengths in CMU-like units (``length_unit`` 0.45, i.e. one unit
is 1/0.45 inch): thigh 7.4, shin 7.5, standing pelvis height about 17.3, total height
about 29.
"""

from __future__ import annotations

import operator
from dataclasses import dataclass, replace
from typing import Callable, Sequence

import numpy as np

from .errors import ParameterError
from .motion import DEFAULT_FPS, Motion
from .skeleton import Joint, Skeleton, rotation_order_from_dofs

__all__ = [
    "KINDS",
    "AMC_JOINT_ORDER",
    "SyntheticCapture",
    "cmu_skeleton",
    "make_periodic_capture",
    "make_motion_chain",
    "make_whole_take",
    "PART_NAMES",
    "make_static_capture",
    "make_random_walk_capture",
    "example_capture",
]

TAU = 2.0 * np.pi

#: Periodic motions :func:`make_periodic_capture` can generate.
KINDS = ("walk", "jog", "jumping_jack", "arm_circles", "squat")

#: Natural period (frames at 120 fps) of each kind, used by :func:`make_motion_chain`.
_DEFAULT_PERIODS = {
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

#: Joint names in CMU AMC frame order (the order of :data:`_CHANNELS`' joints).
AMC_JOINT_ORDER: tuple[str, ...] = tuple(name for name, _ in _AMC_LAYOUT)

#: The 62 channels of every generated motion, in CMU AMC order.
_CHANNELS: tuple[tuple[str, str], ...] = tuple(
    (name, dof) for name, dofs in _AMC_LAYOUT for dof in dofs
)
_COL = {c: i for i, c in enumerate(_CHANNELS)}
_TRANSLATION_COLS = np.array([_COL[("root", d)] for d in ("tx", "ty", "tz")])
_ANGLE_COLS = np.array([i for i, (_, d) in enumerate(_CHANNELS) if d.startswith("r")])

#: Translation noise (length units) per degree of angle noise: 0.5 deg -> 0.02 units (~1 mm).
_TRANSLATION_NOISE_PER_DEGREE = 0.04

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


# ----------------------------------------------------------------------- result type
@dataclass(frozen=True, eq=False)
class SyntheticCapture:
    """A generated capture with its ground truth.

    Attributes
    ----------
    motion : Motion
        The noisy capture (what a user would load): 62 CMU channels, skeleton
        :func:`cmu_skeleton`.
    clean : Motion
        The noise-free signal, same channels and skeleton.
    phase : ndarray, shape (T,)
        True phase in cycles, unwrapped and strictly increasing within each periodic
        segment (``phase % 1`` is the circular truth); NaN where nothing is periodic
        (transitions, static and random-walk captures).
    period : float
        Mean period in frames (frame-weighted mean over segments for a chain; NaN when
        nothing is periodic).
    labels : ndarray of int, shape (T,)
        Motion id per frame (index of the kind in order of first appearance); -1 for
        transitions and non-periodic frames.
    boundaries : list of (int, int, str)
        Half-open frame ranges ``(start, stop, kind)`` of the periodic segments.
    name : str
        Short name, e.g. ``"synthetic-walk"``.
    parts : list of (str, int, int) or None
        Whole takes (:func:`make_whole_take`) only: every scripted part as a half-open
        range ``(name, start, stop)``, ``name`` one of :data:`PART_NAMES`, in frame order,
        covering all frames; None for the other generators.
    part_labels : ndarray of int, shape (T,), or None
        Whole takes only: per frame, the index in :data:`PART_NAMES` of its part.
    steady : list of (int, int) or None
        Whole takes only: half-open frame ranges of the steady parts (constant amplitude,
        straight heading, the period's own speed wobble); the same ranges as
        ``boundaries``.
    heading : ndarray, shape (T,), or None
        Whole takes only: the body's heading in degrees (yaw of the facing direction about
        the vertical, 0 = +z, positive towards +x, i.e. turning left), unwrapped.
    """

    motion: Motion
    clean: Motion
    phase: np.ndarray
    period: float
    labels: np.ndarray
    boundaries: list[tuple[int, int, str]]
    name: str
    parts: list[tuple[str, int, int]] | None = None
    part_labels: np.ndarray | None = None
    steady: list[tuple[int, int]] | None = None
    heading: np.ndarray | None = None

    def __post_init__(self) -> None:
        phase = np.array(self.phase, dtype=float)
        labels = np.array(self.labels, dtype=int)
        phase.flags.writeable = False
        labels.flags.writeable = False
        object.__setattr__(self, "phase", phase)
        object.__setattr__(self, "labels", labels)
        for name, dtype in (("part_labels", int), ("heading", float)):
            value = getattr(self, name)
            if value is not None:
                arr = np.array(value, dtype=dtype)
                arr.flags.writeable = False
                object.__setattr__(self, name, arr)


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


# ------------------------------------------------------------------------ the kinds
# Each kind maps the phase (cycles, any real) and an amplitude scale to joint angles,
# root rotation, root sway (tx), extra height above the floor (ty: flight) and a forward
# wobble (tz).  The generator adds the floor contact and the forward progression.

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
_STRIDE = {"walk": 26.0, "jog": 42.0, "jumping_jack": 0.5, "arm_circles": 0.3, "squat": 0.2}


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


_POSES: dict[str, Callable[[np.ndarray, float], Pose]] = {
    "walk": _walk_pose,
    "jog": _jog_pose,
    "jumping_jack": _jumping_jack_pose,
    "arm_circles": _arm_circles_pose,
    "squat": _squat_pose,
}


def _standing_pose(n: int) -> Pose:
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


def _draw_style(rng: np.random.Generator) -> _Style:
    posture = np.zeros(len(_CHANNELS))
    for i, (joint, dof) in enumerate(_CHANNELS):
        if joint != "root" and dof.startswith("r"):
            posture[i] = rng.normal(0.0, 1.0)
    return _Style(amp=float(rng.uniform(0.92, 1.08)), posture=posture)


def _pose_to_frames(pose: Pose, n: int) -> np.ndarray:
    frames = np.zeros((n, len(_CHANNELS)))
    for channel, values in pose.items():
        frames[:, _COL[channel]] = values
    return frames


def _ground(frames: np.ndarray, skeleton: Skeleton) -> np.ndarray:
    """Root height that puts the lowest foot point on the floor (y = 0), per frame."""
    probe = frames.copy()
    probe[:, _TRANSLATION_COLS] = 0.0
    pos = Motion(probe, _CHANNELS, skeleton=skeleton).positions()
    idx = [pos.names.index(p) for p in _CONTACT_POINTS]
    return -pos.positions[:, idx, 1].min(axis=1)


def _render(kind: str, phase: np.ndarray, style: _Style, skeleton: Skeleton) -> np.ndarray:
    """Noise-free frames ``(T, 62)`` of ``kind`` at the given unwrapped phases.

    Every channel but root ``tz`` is a function of ``phase % 1`` alone; root ``tz``
    adds one stride per cycle of ``phase``.
    """
    phase = np.asarray(phase, dtype=float)
    phi = np.mod(phase, 1.0)
    frames = _pose_to_frames(_POSES[kind](phi, style.amp), phi.shape[0])
    frames += style.posture
    lift = frames[:, _COL[("root", "ty")]].copy()
    frames[:, _COL[("root", "ty")]] = _ground(frames, skeleton) + lift
    frames[:, _COL[("root", "tz")]] += _STRIDE[kind] * phase
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


def _draw_phase_law(rng: np.random.Generator, period: float, variation: float, n: int) -> _PhaseLaw:
    law = _PhaseLaw(
        period=period,
        variation=variation,
        ratios=(float(rng.uniform(1.6, 2.6)), float(rng.uniform(4.0, 7.0))),
        weights=(0.7, 0.3),
        offsets=(float(rng.uniform(0, TAU)), float(rng.uniform(0, TAU))),
    )
    span = float(law.raw(np.array([n - 1.0]))[0])
    return replace(law, scale=((n - 1) / period) / span)


def _add_noise(clean: np.ndarray, noise: float, rng: np.random.Generator) -> np.ndarray:
    noisy = clean.copy()
    noisy[:, _ANGLE_COLS] += rng.normal(0.0, noise, size=(clean.shape[0], _ANGLE_COLS.size))
    noisy[:, _TRANSLATION_COLS] += rng.normal(
        0.0, noise * _TRANSLATION_NOISE_PER_DEGREE, size=(clean.shape[0], 3)
    )
    return noisy


def _seed_text(random_state: object) -> str:
    if random_state is None or isinstance(random_state, (int, np.integer)):
        return str(random_state)
    return type(random_state).__name__


# ----------------------------------------------------------------------- validation
def _check_int(name: str, value: object, minimum: int) -> int:
    if isinstance(value, bool):
        raise ParameterError(f"{name} must be an integer, got {value!r}")
    try:
        out = operator.index(value)  # type: ignore[arg-type]
    except TypeError:
        raise ParameterError(f"{name} must be an integer, got {value!r}") from None
    if out < minimum:
        raise ParameterError(f"{name} must be at least {minimum}, got {out}")
    return out


def _check_float(
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


def _check_kind(kind: object) -> str:
    if not isinstance(kind, str) or kind not in _POSES:
        raise ParameterError(f"unknown motion kind {kind!r}; choose one of {', '.join(KINDS)}")
    return kind


def _check_random_state(random_state: object) -> np.random.Generator:
    try:
        return np.random.default_rng(random_state)  # type: ignore[arg-type]
    except (TypeError, ValueError) as exc:
        raise ParameterError(
            f"random_state must be None, an int or a numpy Generator: {exc}"
        ) from None


# ------------------------------------------------------------------- public makers
def make_periodic_capture(
    n_frames: int = 600,
    period: float = 120.0,
    noise: float = 0.5,
    speed_variation: float = 0.3,
    kind: str = "walk",
    fps: float = DEFAULT_FPS,
    random_state: int | np.random.Generator | None = None,
) -> SyntheticCapture:
    """One periodic motion at uneven speed, with measurement noise.

    Every joint angle is a fixed periodic function of the true phase (several harmonics
    with joint-specific amplitudes and timing); the phase advances at a speed that
    wanders slowly by up to ``speed_variation`` around its mean, so single cycles last
    longer or shorter than ``period`` while the mean over the capture is exactly
    ``period``.  The root height keeps the lowest foot on the floor (plus a flight phase
    for jog and jumping jacks) and the root moves forward by one stride per cycle, so the
    root translation is not periodic.

    Parameters
    ----------
    n_frames : int
        Number of frames ``T`` (>= 2).
    period : float
        Mean period in frames (> 1).
    noise : float
        Standard deviation of the i.i.d. Gaussian noise on every angle channel, degrees
        (>= 0); root translation gets ``0.04 * noise`` length units.
    speed_variation : float
        Relative amplitude of the phase-speed wobble, ``0 <= speed_variation < 1`` (0 gives
        a constant speed: frame ``t`` has phase exactly ``t / period``).
    kind : str
        One of :data:`KINDS`: ``"walk"``, ``"jog"`` (faster, larger, flight phases, bent
        elbows), ``"jumping_jack"``, ``"arm_circles"``, ``"squat"``.
    fps : float
        Frame rate stored in the motion.
    random_state : int, numpy Generator or None
        Seed; the same seed gives identical arrays.  It sets the performer's style
        (amplitude within +-8 %, posture offsets of about 1 degree), the speed wobble and
        the noise.

    Returns
    -------
    SyntheticCapture
        ``phase`` starts at 0 and ends at ``(n_frames - 1) / period``; ``labels`` all 0;
        ``boundaries`` ``[(0, n_frames, kind)]``.

    Raises
    ------
    ParameterError
        On an unknown kind or an argument out of range.
    """
    kind = _check_kind(kind)
    n = _check_int("n_frames", n_frames, 2)
    period = _check_float("period", period, 1.0, low_open=True)
    noise = _check_float("noise", noise, 0.0)
    variation = _check_float("speed_variation", speed_variation, 0.0, high=1.0)
    fps = _check_float("fps", fps, 0.0, low_open=True)
    rng = _check_random_state(random_state)

    skeleton = cmu_skeleton()
    style = _draw_style(rng)
    law = _draw_phase_law(rng, period, variation, n)
    phase = law(np.arange(n, dtype=float))
    clean = _render(kind, phase, style, skeleton)
    noisy = _add_noise(clean, noise, rng)
    source = f"synthetic:{kind}(seed={_seed_text(random_state)})"
    meta = {"kind": kind, "period": period, "noise": noise, "speed_variation": variation}
    return SyntheticCapture(
        motion=Motion(noisy, _CHANNELS, fps=fps, skeleton=skeleton, source=source, metadata=meta),
        clean=Motion(
            clean,
            _CHANNELS,
            fps=fps,
            skeleton=skeleton,
            source=source + ":clean",
            metadata=dict(meta),
        ),
        phase=phase,
        period=period,
        labels=np.zeros(n, dtype=int),
        boundaries=[(0, n, kind)],
        name=f"synthetic-{kind}",
    )


def _smoothstep(x: np.ndarray) -> np.ndarray:
    """C2 ramp from 0 (x <= 0) to 1 (x >= 1)."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x))


def make_motion_chain(
    kinds: Sequence[str] = ("walk", "jumping_jack", "arm_circles"),
    segment_frames: int | Sequence[int] = 600,
    periods: Sequence[float] | None = None,
    transition_frames: int = 40,
    noise: float = 0.5,
    fps: float = DEFAULT_FPS,
    random_state: int | np.random.Generator | None = None,
    *,
    speed_variation: float = 0.2,
) -> SyntheticCapture:
    """Several periodic motions one after another, joined by short smooth transitions.

    Segment ``k`` is ``kinds[k]`` performed for ``segment_frames`` frames with its own
    period and phase (starting at 0); between segments, ``transition_frames`` frames
    cross-fade (C2 ramp) from the previous motion, continued, into the next one, started
    early.  The root translation is continuous: each segment's forward progression is
    shifted to meet the previous one in the middle of the transition.

    Parameters
    ----------
    kinds : sequence of str
        Motions in order, each one of :data:`KINDS` (a single string is one segment).
    segment_frames : int or sequence of int
        Frames per segment (>= 2), one number for all or one per segment.
    periods : sequence of float, optional
        Period per segment in frames (> 1); default each kind's natural period (walk 120,
        jog 80, jumping_jack 90, arm_circles 100, squat 150).
    transition_frames : int
        Frames between consecutive segments (>= 0; 0 switches abruptly).
    noise : float
        Angle noise in degrees (>= 0), as in :func:`make_periodic_capture`.
    fps : float
        Frame rate stored in the motion.
    random_state : int, numpy Generator or None
        Seed (one performer's style for the whole chain, a speed wobble per segment, the
        noise).
    speed_variation : float, keyword-only
        Phase-speed wobble of every segment, ``0 <= speed_variation < 1``.

    Returns
    -------
    SyntheticCapture
        ``boundaries`` lists ``(start, stop, kind)`` per segment; ``labels`` holds the
        index of the segment's kind among the distinct kinds (first appearance order) and
        -1 in transitions; ``phase`` is each segment's own phase (NaN in transitions);
        ``period`` is the frame-weighted mean of the segment periods (all of them are in
        ``motion.metadata["periods"]``).

    Raises
    ------
    ParameterError
        On an unknown kind, mismatched lengths or an argument out of range.
    """
    if isinstance(kinds, str):
        kinds = (kinds,)
    try:
        kinds = tuple(kinds)
    except TypeError:
        raise ParameterError(f"kinds must be a sequence of motion kinds, got {kinds!r}") from None
    if not kinds:
        raise ParameterError("kinds must name at least one motion")
    kinds = tuple(_check_kind(k) for k in kinds)
    m = len(kinds)
    if isinstance(segment_frames, (int, np.integer)) and not isinstance(segment_frames, bool):
        lengths = [_check_int("segment_frames", segment_frames, 2)] * m
    else:
        try:
            seq = list(segment_frames)  # type: ignore[arg-type]
        except TypeError:
            raise ParameterError(
                f"segment_frames must be an integer or a sequence, got {segment_frames!r}"
            ) from None
        if len(seq) != m:
            raise ParameterError(f"segment_frames has {len(seq)} entries for {m} kinds")
        lengths = [_check_int("segment_frames", s, 2) for s in seq]
    if periods is None:
        pers = [_DEFAULT_PERIODS[k] for k in kinds]
    else:
        try:
            seq = list(periods)
        except TypeError:
            raise ParameterError(
                f"periods must be a sequence of numbers, got {periods!r}"
            ) from None
        if len(seq) != m:
            raise ParameterError(f"periods has {len(seq)} entries for {m} kinds")
        pers = [_check_float("periods", p, 1.0, low_open=True) for p in seq]
    gap = _check_int("transition_frames", transition_frames, 0)
    noise = _check_float("noise", noise, 0.0)
    variation = _check_float("speed_variation", speed_variation, 0.0, high=1.0)
    fps = _check_float("fps", fps, 0.0, low_open=True)
    rng = _check_random_state(random_state)

    skeleton = cmu_skeleton()
    style = _draw_style(rng)
    starts = [sum(lengths[:k]) + k * gap for k in range(m)]
    total = starts[-1] + lengths[-1]
    ids = {k: i for i, k in enumerate(dict.fromkeys(kinds))}

    # Each segment rendered on its own frames plus the neighbouring transitions (and one
    # frame beyond, for the tz hand-over when gap == 0).
    renders = []
    for k in range(m):
        law = _draw_phase_law(rng, pers[k], variation, lengths[k])
        first = starts[k] - (gap + 1 if k > 0 else 0)
        last = starts[k] + lengths[k] + (gap + 1 if k < m - 1 else 0)
        t = np.arange(first, last)
        local_phase = law((t - starts[k]).astype(float))
        renders.append((first, _render(kinds[k], local_phase, style, skeleton), local_phase))

    tz = _COL[("root", "tz")]
    clean = np.empty((total, len(_CHANNELS)))
    phase = np.full(total, np.nan)
    labels = np.full(total, -1, dtype=int)
    shift = 0.0
    for k in range(m):
        first, frames, local_phase = renders[k]
        frames = frames.copy()
        if k > 0:
            # meet the previous segment's progression in the middle of the transition
            pfirst, pframes, _ = renders[k - 1]
            mid = starts[k] - gap + gap // 2 if gap else starts[k]
            shift = pframes[mid - pfirst, tz] - frames[mid - first, tz]
            frames[:, tz] += shift
            renders[k] = (first, frames, local_phase)
        s, e = starts[k], starts[k] + lengths[k]
        clean[s:e] = frames[s - first : e - first]
        phase[s:e] = local_phase[s - first : e - first]
        labels[s:e] = ids[kinds[k]]
    for k in range(m - 1):
        if gap == 0:
            continue
        a0, a, _ = renders[k]
        b0, b, _ = renders[k + 1]
        t = np.arange(starts[k] + lengths[k], starts[k + 1])
        w = _smoothstep((t - t[0] + 1.0) / (gap + 1.0))[:, None]
        clean[t] = (1.0 - w) * a[t - a0] + w * b[t - b0]

    noisy = _add_noise(clean, noise, rng)
    seed = _seed_text(random_state)
    source = f"synthetic:chain({','.join(kinds)}; seed={seed})"
    boundaries = [(starts[k], starts[k] + lengths[k], kinds[k]) for k in range(m)]
    meta = {
        "kinds": list(kinds),
        "periods": list(pers),
        "boundaries": list(boundaries),
        "noise": noise,
    }
    mean_period = float(np.dot(lengths, pers) / sum(lengths))
    return SyntheticCapture(
        motion=Motion(noisy, _CHANNELS, fps=fps, skeleton=skeleton, source=source, metadata=meta),
        clean=Motion(
            clean,
            _CHANNELS,
            fps=fps,
            skeleton=skeleton,
            source=source + ":clean",
            metadata=dict(meta),
        ),
        phase=phase,
        period=mean_period,
        labels=labels,
        boundaries=boundaries,
        name="synthetic-chain(" + "+".join(kinds) + ")",
    )


def _non_periodic(
    clean: np.ndarray, noisy: np.ndarray, kind: str, random_state: object, skeleton: Skeleton
) -> SyntheticCapture:
    n = clean.shape[0]
    source = f"synthetic:{kind}(seed={_seed_text(random_state)})"
    return SyntheticCapture(
        motion=Motion(noisy, _CHANNELS, skeleton=skeleton, source=source, metadata={"kind": kind}),
        clean=Motion(
            clean, _CHANNELS, skeleton=skeleton, source=source + ":clean", metadata={"kind": kind}
        ),
        phase=np.full(n, np.nan),
        period=float("nan"),
        labels=np.full(n, -1, dtype=int),
        boundaries=[],
        name=f"synthetic-{kind}",
    )


def make_static_capture(
    n_frames: int = 600,
    noise: float = 0.5,
    random_state: int | np.random.Generator | None = None,
) -> SyntheticCapture:
    """A person standing still: one posture plus measurement noise, nothing periodic.

    Parameters
    ----------
    n_frames : int
        Number of frames (>= 2).
    noise : float
        Angle noise in degrees (>= 0); translation noise ``0.04 * noise`` units.
    random_state : int, numpy Generator or None
        Seed for the posture offsets and the noise.

    Returns
    -------
    SyntheticCapture
        ``clean`` is the constant posture; ``phase`` NaN, ``period`` NaN, ``labels`` all
        -1, ``boundaries`` empty.
    """
    n = _check_int("n_frames", n_frames, 2)
    noise = _check_float("noise", noise, 0.0)
    rng = _check_random_state(random_state)
    skeleton = cmu_skeleton()
    style = _draw_style(rng)
    clean = _pose_to_frames(_standing_pose(n), n) + style.posture
    clean[:, _COL[("root", "ty")]] = _ground(clean[:1], skeleton)[0]
    noisy = _add_noise(clean, noise, rng)
    return _non_periodic(clean, noisy, "static", random_state, skeleton)


def make_random_walk_capture(
    n_frames: int = 600,
    step: float = 0.5,
    random_state: int | np.random.Generator | None = None,
) -> SyntheticCapture:
    """Posture drifting as a Gaussian random walk: moving, but nothing periodic.

    Every angle channel starts from a standing posture and takes i.i.d. Gaussian steps
    of ``step`` degrees per frame; the root wanders horizontally by ``0.04 * step`` units
    per frame and its height keeps the lowest foot on the floor.

    Parameters
    ----------
    n_frames : int
        Number of frames (>= 2).
    step : float
        Standard deviation of the per-frame angle steps, degrees (>= 0).
    random_state : int, numpy Generator or None
        Seed.

    Returns
    -------
    SyntheticCapture
        No separate noise: ``clean`` equals ``motion``.  ``phase`` NaN, ``period`` NaN,
        ``labels`` all -1, ``boundaries`` empty.
    """
    n = _check_int("n_frames", n_frames, 2)
    step = _check_float("step", step, 0.0)
    rng = _check_random_state(random_state)
    skeleton = cmu_skeleton()
    style = _draw_style(rng)
    frames = _pose_to_frames(_standing_pose(n), n) + style.posture
    steps = np.zeros_like(frames)
    steps[1:, _ANGLE_COLS] = rng.normal(0.0, step, size=(n - 1, _ANGLE_COLS.size))
    for d in ("tx", "tz"):
        steps[1:, _COL[("root", d)]] = rng.normal(
            0.0, step * _TRANSLATION_NOISE_PER_DEGREE, size=n - 1
        )
    frames += np.cumsum(steps, axis=0)
    frames[:, _COL[("root", "ty")]] = _ground(frames, skeleton)
    return _non_periodic(frames, frames, "random_walk", random_state, skeleton)


def example_capture() -> SyntheticCapture:
    """The README's built-in example: four cycles of a noisy synthetic walk.

    Returns
    -------
    SyntheticCapture
        ``make_periodic_capture(n_frames=480, period=120.0, noise=0.5, random_state=0)``,
        named ``"synthetic-walk"``.
    """
    cap = make_periodic_capture(n_frames=480, period=120.0, noise=0.5, random_state=0)
    return replace(cap, name="synthetic-walk")


# The whole-take generator lives in its own module (it uses the helpers above); imported
# last so that module can import this one.
from ._whole_take import PART_NAMES, make_whole_take
