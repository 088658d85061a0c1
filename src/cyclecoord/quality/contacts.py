"""Foot contacts and foot skating from forward kinematics.

A foot point (ankle/heel or toe joint) is *planted* on a frame when it is close to the
level it rests at on the floor and barely moves horizontally.  Both thresholds are scaled
to the skeleton (its leg length), so the same defaults serve CMU's ASF units (about
5.6 cm), BVH centimetres or metres.

The foot points come from :func:`~cyclecoord.quality.legs.find_legs` (joint names of the
common rigs, else the skeleton's geometry): two legs, or four on a quadruped, each with its
ankle and toe point.  Given foot points are grouped into legs by the hierarchy.

The floor is not assumed at height 0 (CMU root heights are not): :func:`foot_contacts`
estimates it as a low quantile of the lowest foot point over the motion, and each foot
point's own contact level (an ankle rests higher than a toe) as a low quantile of that
point's height, kept within a band above the floor so that a foot that never touches down
is not called planted at the top of its swing.

:func:`foot_skating` measures how much planted feet slide: their mean horizontal speed
and the fraction of frames on which a planted foot moves faster than a small threshold.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ..joint_names import classify_skeleton
from ..skeleton import Skeleton
from .legs import Legs, find_feet, find_legs, legs_of_feet

__all__ = [
    "FootContacts",
    "FootSkating",
    "contact_runs",
    "contact_skeleton",
    "find_feet",
    "foot_contacts",
    "foot_skating",
    "leg_length",
    "skating_line",
    "skating_report",
]

#: Height band (fraction of leg length) above a point's contact level counted as "down".
DEFAULT_HEIGHT = 0.05
#: Horizontal speed (leg lengths per second) under which a low foot point is planted.
DEFAULT_SPEED = 0.5
#: Horizontal speed (leg lengths per second) above which a planted point skates.
DEFAULT_SKATE_SPEED = 0.1
#: Shortest contact kept and longest gap closed, in seconds.
DEFAULT_MIN_DURATION = 0.03
#: Quantile of heights taken as the floor / a point's contact level.
_LOW_QUANTILE = 0.05
#: A point's contact level may lie at most this many leg lengths above the floor.
_MAX_LEVEL = 0.25

_UP = {"x": 0, "y": 1, "z": 2}


# --------------------------------------------------------------------- results
@dataclass(frozen=True)
class FootContacts:
    """Per-frame contact state of the foot points of a motion.

    Attributes
    ----------
    feet : tuple of str
        Joint names of the foot points, e.g. ``("lfoot", "ltoes", "rfoot", "rtoes")``
        (ankle then toe of each leg).
    sides : tuple of str
        ``"left"`` or ``"right"`` per foot point (``"?"`` when unknown).
    planted : ndarray of bool, shape (T, F)
        Whether each foot point is planted on each frame.
    height : ndarray, shape (T, F)
        Height of each point above its own contact level (length units).
    speed : ndarray, shape (T, F)
        Horizontal speed of each point (length units per second, central differences).
    floor : float
        Estimated floor height along the up axis (length units), from the lowest foot
        points including the toe end sites.
    contact_level : ndarray, shape (F,)
        Absolute height each point rests at when planted (``height`` is relative to it).
    leg_length : float
        Hip-to-ankle length of the skeleton (thigh plus shin), the scale of thresholds.
    height_threshold, speed_threshold : float
        Thresholds used, in length units and length units per second.
    fps : float
        Frame rate of the motion.
    up : int
        Index of the up axis (1 for y).
    legs : tuple of str
        Leg label per foot point: ``"left"``/``"right"``, or ``"front left"`` ...
        ``"hind right"`` on a quadruped (empty: the sides are the legs).
    """

    feet: tuple[str, ...]
    sides: tuple[str, ...]
    planted: np.ndarray
    height: np.ndarray
    speed: np.ndarray
    floor: float
    contact_level: np.ndarray
    leg_length: float
    height_threshold: float
    speed_threshold: float
    fps: float
    up: int = 1
    legs: tuple[str, ...] = ()

    @property
    def n_frames(self) -> int:
        return int(self.planted.shape[0])

    @property
    def leg_labels(self) -> tuple[str, ...]:
        """Leg label per foot point (the sides when no legs were recorded)."""
        return self.legs if self.legs else self.sides

    def side_planted(self, side: str) -> np.ndarray:
        """Frames ``(T,)`` on which any point of a side or a leg is planted.

        ``side`` is ``"left"`` or ``"right"`` (every leg on that side: both left legs of
        a quadruped) or a leg label such as ``"front left"``.
        """
        cols = [
            i for i, (s, g) in enumerate(zip(self.sides, self.leg_labels)) if side in (s, g)
        ]
        if not cols:
            raise ParameterError(f"no {side} foot among {self.feet}")
        return self.planted[:, cols].any(axis=1)

    def summary(self) -> str:
        """One line: fraction of frames each foot point is planted."""
        parts = [f"{n} {100 * self.planted[:, i].mean():.0f}%" for i, n in enumerate(self.feet)]
        return "planted: " + ", ".join(parts)


@dataclass(frozen=True)
class FootSkating:
    """How much planted feet slide.

    Attributes
    ----------
    feet : tuple of str
        Foot point names, as in :class:`FootContacts`.
    mean_speed : float
        Mean horizontal speed of planted foot points over all planted (frame, point)
        pairs, in length units per second (0 when nothing is planted).
    mean_speed_legs : float
        The same in leg lengths per second.
    skating_fraction : float
        Fraction of frames on which at least one planted point moves faster than the
        skate threshold.
    skating_frames : int
        Number of such frames.
    foot_mean_speed : ndarray, shape (F,)
        Mean horizontal speed of each point while planted (NaN for a point never
        planted), length units per second.
    foot_skating_fraction : ndarray, shape (F,)
        Fraction of frames each point skates.
    skating : ndarray of bool, shape (T, F)
        Which point skates on which frame.
    skate_threshold : float
        Speed above which a planted point skates, length units per second.
    leg_length : float
        The scale used, length units.
    """

    feet: tuple[str, ...]
    mean_speed: float
    mean_speed_legs: float
    skating_fraction: float
    skating_frames: int
    foot_mean_speed: np.ndarray
    foot_skating_fraction: np.ndarray
    skating: np.ndarray
    skate_threshold: float
    leg_length: float

    def to_dict(self) -> dict:
        """JSON-ready figures (per foot point as name -> value)."""
        return {
            "mean_speed_units_per_s": self.mean_speed,
            "mean_speed_leg_lengths_per_s": self.mean_speed_legs,
            "skating_frames": self.skating_frames,
            "skating_fraction": self.skating_fraction,
            "skate_threshold_units_per_s": self.skate_threshold,
            "leg_length": self.leg_length,
            "per_foot": {
                f: {
                    "mean_speed_units_per_s": (None if not np.isfinite(v) else float(v)),
                    "skating_fraction": float(r),
                }
                for f, v, r in zip(self.feet, self.foot_mean_speed, self.foot_skating_fraction)
            },
        }

    def summary(self) -> str:
        """One line for reports."""
        return _summary_line(
            self.mean_speed, self.mean_speed_legs, self.skating_frames, self.skating_fraction
        )


def _summary_line(speed: float, speed_legs: float, frames: int, fraction: float) -> str:
    return (
        f"foot skating: {speed:.3g} units/s ({speed_legs:.3g} leg lengths/s) while planted, "
        f"{frames} frames skating ({100 * fraction:.1f}%)"
    )


# ---------------------------------------------------------------- skeleton help
def _ankle_of(skeleton: Skeleton, feet: tuple[str, ...], foot: str) -> int:
    """Index of the ankle of ``foot``'s leg: the highest foot point on its chain, or its
    parent when that point is a toe (named so, or its bone under half its parent's): a
    leg given by its toe alone."""
    idx = skeleton.index(foot)
    members = {skeleton.index(f) for f in feet}
    ankle = idx
    p = skeleton.joints[idx].parent
    while p >= 0:
        if p in members:
            ankle = p
        p = skeleton.joints[p].parent
    parent = skeleton.joints[ankle].parent
    if parent > 0:
        role = classify_skeleton(skeleton).get(skeleton.joints[ankle].name)
        bone = np.linalg.norm(skeleton.joints[ankle].offset)
        if (role is not None and role.role == "toe") or bone < 0.5 * np.linalg.norm(
            skeleton.joints[parent].offset
        ):
            ankle = parent
    return ankle


def leg_length(skeleton: Skeleton, feet: tuple[str, ...] | None = None) -> float:
    """Mean hip-to-ankle length (thigh plus shin bone) over the legs, in length units.

    The ankle is the highest foot point of each leg (two legs or four); its offset is
    the shin and its parent's offset the thigh.
    """
    feet = find_feet(skeleton) if feet is None else tuple(feet)
    ankles = sorted({_ankle_of(skeleton, feet, f) for f in feet})
    lengths = []
    for a in ankles:
        shin = float(np.linalg.norm(skeleton.joints[a].offset))
        parent = skeleton.joints[a].parent
        thigh = float(np.linalg.norm(skeleton.joints[parent].offset)) if parent > 0 else 0.0
        lengths.append(shin + thigh)
    value = float(np.mean(lengths)) if lengths else 0.0
    if not value > 0:
        raise ParameterError(
            "cannot measure the leg length: the foot joints have no bones above them"
        )
    return value


def contact_skeleton(motion: Motion) -> Skeleton:
    """The skeleton of a motion checked fit for foot-contact analysis.

    Parameters
    ----------
    motion : Motion

    Returns
    -------
    Skeleton
        ``motion.skeleton``.

    Raises
    ------
    ParameterError
        When the motion has no skeleton, fewer than 2 frames, or a frame holding NaN or
        infinite values (the message names the source and the first such frame).
    """
    if motion.skeleton is None:
        raise ParameterError(
            f"{motion.source or 'motion'}: foot contacts need a skeleton "
            "(forward kinematics); this motion has none"
        )
    if motion.n_frames < 2:
        raise ParameterError(
            f"{motion.source or 'motion'}: foot contacts need at least 2 frames, "
            f"got {motion.n_frames}"
        )
    bad = np.flatnonzero(~np.isfinite(motion.frames).all(axis=1))
    if bad.size:
        raise ParameterError(
            f"{motion.source or 'motion'}: frame {motion.start_frame + int(bad[0])} holds "
            f"NaN or infinite values ({bad.size} such frames)"
        )
    return motion.skeleton


def contact_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open ``(start, stop)`` frame ranges where a boolean ``(T,)`` mask is true."""
    m = np.asarray(mask, dtype=bool).astype(np.int8)
    d = np.diff(np.concatenate([[0], m, [0]]))
    starts = np.flatnonzero(d == 1)
    stops = np.flatnonzero(d == -1)
    return list(zip(starts.tolist(), stops.tolist()))


def _clean(mask: np.ndarray, min_frames: int) -> np.ndarray:
    """Close gaps and drop runs shorter than ``min_frames`` in a ``(T,)`` mask.

    Gaps between two runs (not at either end) are closed first, then the runs still
    shorter are dropped; ``min_frames`` 1 or less leaves the mask as it is."""
    out = mask.copy()
    if min_frames <= 1:
        return out
    for a, b in contact_runs(~out):
        if 0 < a and b < out.size and b - a < min_frames:
            out[a:b] = True
    for a, b in contact_runs(out):
        if b - a < min_frames:
            out[a:b] = False
    return out


# -------------------------------------------------------------------- contacts
def foot_contacts(
    motion: Motion,
    feet: tuple[str, ...] | list[str] | None = None,
    *,
    height: float = DEFAULT_HEIGHT,
    speed: float | None = DEFAULT_SPEED,
    min_duration: float = DEFAULT_MIN_DURATION,
    up: str = "y",
    floor: float | None = None,
) -> FootContacts:
    """Which foot points are planted on each frame.

    Parameters
    ----------
    motion : Motion
        Any motion with a skeleton.
    feet : sequence of str, optional
        Foot joint names; default :func:`~cyclecoord.quality.legs.find_legs` on this
        motion (``lfoot ltoes rfoot rtoes`` on a CMU skeleton, ``Foot_L Toes_L Foot_R
        Toes_R`` on Bandai's, four legs on a quadruped).  Given names are grouped into
        legs by the hierarchy (points on one chain make one leg).
    height : float
        Height band above a point's contact level, as a fraction of the leg length
        (0.05: about 4 cm on an adult).
    speed : float or None
        Horizontal speed limit of a planted point, in leg lengths per second (0.5:
        about 0.4 m/s).  None: contact from height alone, not gated by speed (what
        :mod:`cyclecoord.quality.generated` judges generated motion by: a foot that
        glides along the floor is on the floor, and its speed is the slip).
    min_duration : float
        Contacts shorter than this (seconds) are dropped and gaps shorter than this
        closed.
    up : {"x", "y", "z"}
        Up axis of the skeleton's world frame (``"y"`` for ASF and BVH).
    floor : float, optional
        Floor height when known; estimated from the motion otherwise.

    Returns
    -------
    FootContacts

    Raises
    ------
    ParameterError
        A motion without a skeleton, fewer than 2 frames, non-finite frames, unknown
        foot joints or non-positive thresholds.
    """
    skel = contact_skeleton(motion)
    if up not in _UP:
        raise ParameterError(f"up axis must be one of x, y, z, got {up!r}")
    gates = (("height", height),) if speed is None else (("height", height), ("speed", speed))
    for label, value in gates:
        if not (np.isfinite(value) and value > 0):
            raise ParameterError(f"{label} threshold must be a positive number, got {value!r}")
    if not (np.isfinite(min_duration) and min_duration >= 0):
        raise ParameterError(f"min_duration must be >= 0 seconds, got {min_duration!r}")
    legs: Legs = (
        find_legs(skel, motion, up=up) if feet is None else legs_of_feet(skel, feet, motion, up=up)
    )
    # once per motion and settings (a latent script measured its takes' contacts twice)
    key = ("contacts", legs.legs, float(height), speed, float(min_duration), up, floor)
    return motion.derived(key, lambda: _contacts(
        motion, skel, legs, height, speed, min_duration, up, floor))


def _contacts(motion: Motion, skel, legs: Legs, height: float, speed: float | None,
              min_duration: float, up: str, floor: float | None) -> FootContacts:
    feet = legs.feet
    axis = _UP[up]
    horiz = [k for k in range(3) if k != axis]
    scale = leg_length(skel, feet)

    pos = motion.positions()
    cols = [pos.names.index(f) for f in feet]
    # lowest points of the feet: the foot points and the end sites below them
    low_cols = list(cols)
    for i, n in enumerate(pos.names):
        if n.endswith("/end") and pos.parents[i] in cols:
            low_cols.append(i)
    y = pos.positions[:, cols, axis]
    if floor is None:
        lowest = pos.positions[:, low_cols, axis].min(axis=1)
        floor_level = float(np.quantile(lowest, _LOW_QUANTILE))
    else:
        floor_level = float(floor)
    level = np.quantile(y, _LOW_QUANTILE, axis=0)
    level = np.clip(level, floor_level, floor_level + _MAX_LEVEL * scale)
    rel = y - level

    xz = pos.positions[:, cols][:, :, horiz]
    vel = np.gradient(xz, axis=0) * motion.fps
    spd = np.linalg.norm(vel, axis=2)

    h_thr = height * scale
    v_thr = np.inf if speed is None else speed * scale
    planted = (rel < h_thr) & (spd < v_thr)
    min_frames = round(min_duration * motion.fps)
    planted = np.stack([_clean(planted[:, i], min_frames) for i in range(len(feet))], axis=1)
    return FootContacts(
        feet=feet,
        sides=legs.sides,
        planted=planted,
        height=rel,
        speed=spd,
        floor=floor_level,
        contact_level=level,
        leg_length=scale,
        height_threshold=h_thr,
        speed_threshold=v_thr,
        fps=motion.fps,
        up=axis,
        legs=legs.labels,
    )


def foot_skating(
    motion: Motion,
    contacts: FootContacts | None = None,
    *,
    skate_speed: float = DEFAULT_SKATE_SPEED,
    **contact_options,
) -> FootSkating:
    """Horizontal sliding of planted feet.

    Parameters
    ----------
    motion : Motion
        Any motion with a skeleton.
    contacts : FootContacts, optional
        Contacts to measure on (computed with :func:`foot_contacts` and
        ``contact_options`` when not given).  Speeds are always taken from ``motion``,
        so contacts of an original motion can be used to measure an edited one.
    skate_speed : float
        A planted point moving faster than this (leg lengths per second; 0.1 is about
        8 cm/s) skates.

    Returns
    -------
    FootSkating
    """
    if not (np.isfinite(skate_speed) and skate_speed >= 0):
        raise ParameterError(
            f"skate_speed must be >= 0 leg lengths per second, got {skate_speed!r}"
        )
    if contacts is None:
        contacts = foot_contacts(motion, **contact_options)
    elif contact_options:
        raise ParameterError("pass either contacts or contact options, not both")
    else:
        contact_skeleton(motion)
    if contacts.n_frames != motion.n_frames:
        raise ParameterError(
            f"contacts cover {contacts.n_frames} frames, the motion has {motion.n_frames}"
        )
    pos = motion.positions()
    cols = [pos.names.index(f) for f in contacts.feet]
    horiz = [k for k in range(3) if k != contacts.up]
    xz = pos.positions[:, cols][:, :, horiz]
    spd = np.linalg.norm(np.gradient(xz, axis=0), axis=2) * motion.fps
    planted = contacts.planted
    thr = skate_speed * contacts.leg_length
    skating = planted & (spd > thr)
    n_planted = planted.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        foot_mean = np.where(n_planted > 0, (spd * planted).sum(axis=0) / n_planted, np.nan)
    total = int(planted.sum())
    mean = float((spd * planted).sum() / total) if total else 0.0
    frames = int(skating.any(axis=1).sum())
    return FootSkating(
        feet=contacts.feet,
        mean_speed=mean,
        mean_speed_legs=mean / contacts.leg_length,
        skating_fraction=frames / motion.n_frames,
        skating_frames=frames,
        foot_mean_speed=foot_mean,
        foot_skating_fraction=skating.mean(axis=0),
        skating=skating,
        skate_threshold=thr,
        leg_length=contacts.leg_length,
    )


def skating_report(motion: Motion, **options) -> dict | None:
    """Foot skating of ``motion`` as a JSON-ready dict for reports, or ``None`` when it
    cannot be measured (no skeleton, no recognisable feet, fewer than 2 frames)."""
    try:
        contacts = foot_contacts(motion, **options)
    except ParameterError:
        return None
    out = foot_skating(motion, contacts).to_dict()
    out["planted_fraction"] = {
        f: float(contacts.planted[:, i].mean()) for i, f in enumerate(contacts.feet)
    }
    out["floor"] = contacts.floor
    return out


def skating_line(report: dict | None, label: str = "") -> str:
    """One console line for a :func:`skating_report` dict (``None``: not measured).

    ``label`` (e.g. ``"blend"``) is put in front: ``"blend foot skating: ..."``.
    """
    head = f"{label} " if label else ""
    if report is None:
        return f"{head}foot skating: not measured (no skeleton with recognisable feet)"
    return head + _summary_line(
        report["mean_speed_units_per_s"],
        report["mean_speed_leg_lengths_per_s"],
        report["skating_frames"],
        report["skating_fraction"],
    )
