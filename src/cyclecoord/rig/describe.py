"""Finding a capture's rig conventions: travelling joint, channels, units, up axis, rate.

:func:`describe_rig` reads a capture and returns a :class:`RigInfo`; the length unit
(:func:`parse_units`, :func:`metres_per_unit`) and the up axis are found here, from the
body's geometry by forward kinematics.  Undoing the conventions for the analysis is
:mod:`cyclecoord.rig.normalize`'s job.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Union

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ..skeleton import AXIS_INDEX, Joint, Skeleton, forward_kinematics

__all__ = [
    "CMU_UNIT",
    "UNITS",
    "Z_TO_Y",
    "RigInfo",
    "describe_rig",
    "metres_per_unit",
    "parse_units",
    "rig_summary",
]

#: Metres per unit of the length units ``--units`` names.
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001, "in": 0.0254}
#: One CMU ASF unit (``:units length 0.45``: 1/0.45 inch) in metres; a candidate when
#: guessing the unit of a BVH written from CMU data.
CMU_UNIT = 0.0254 / 0.45
_CANDIDATES = {**UNITS, "cmu": CMU_UNIT}
#: A human's height in metres; guessed units put the measured height closest to it (in
#: ratio), so heights of about 1.1-2.5 m are read right.
_HUMAN_HEIGHT = 1.7
#: Rotation taking a Z-up world to a Y-up one (-90 degrees about x: z -> y, y -> -z).
Z_TO_Y = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])

Units = Union[str, float, None]


def parse_units(units: Units) -> float | None:
    """Metres per unit for a units option, ``None`` for ``"auto"``.

    Parameters
    ----------
    units : {"auto", "m", "cm", "mm", "in"} or float or None
        A unit name, a positive number of metres per unit (also as text, e.g.
        ``"0.0254"``), or ``"auto"``/``None`` to measure it.

    Returns
    -------
    float or None

    Raises
    ------
    ParameterError
        For an unknown name or a number that is not positive and finite.
    """
    if units is None:
        return None
    if isinstance(units, str):
        key = units.strip().lower()
        if key == "auto":
            return None
        if key in UNITS:
            return UNITS[key]
        try:
            value = float(key)
        except ValueError:
            raise ParameterError(
                f"units must be auto, {', '.join(UNITS)} or a number of metres per unit, "
                f"got {units!r}"
            ) from None
    else:
        value = float(units)
    if not (np.isfinite(value) and value > 0):
        raise ParameterError(f"metres per unit must be a positive number, got {units!r}")
    return value


@dataclass(frozen=True)
class RigInfo:
    """What :func:`describe_rig` found about a capture's rig.

    Attributes
    ----------
    style : str
        ``"Bandai-style"`` (static root, positions on every joint) or the source format
        (``"BVH"``, ``"ASF"``, ``"glTF"``, ...).
    source_format : str
        The skeleton's ``source_format``.
    n_joints : int
        Joints of the skeleton as written (a static root included).
    root : str
        The skeleton's root joint.
    travelling_joint : str
        The joint that carries the travel: the root, or the child of a static root.
    static_root : bool
        The root's channels are constant and it has one child (which travels).
    channel_counts : tuple of int, shape (n_joints,)
        Channels per joint, skeleton order.
    constant_position_joints : tuple of str
        Joints other than the travelling one whose position channels are all constant
        (they are offsets written as channels).
    units : str
        ``"m"``, ``"cm"``, ``"mm"``, ``"in"``, ``"cmu"`` (1/0.45 inch), ``"asf"`` (the
        ASF ``:units length``) or ``"custom"`` (a number given).
    units_source : str
        ``"measured"`` (guessed from the height), ``"skeleton"`` (the ASF length unit, or
        a glTF's metres) or ``"given"``.
    metres_per_unit : float
        Metres per skeleton length unit.
    height : float
        The body's extent along the up axis (lowest to highest joint or end site), median
        over frames, in skeleton length units.
    up_axis : str
        ``"Y"`` or ``"Z"``.
    extents : tuple of float, shape (3,)
        Median extent of the body along x, y and z, skeleton length units.
    fps : float
        Frames per second.
    n_frames : int
        Frames of the capture.
    reference_frame : bool
        The first frame is a reference pose, discontinuous with the second.
    first_step_ratio : float
        Largest joint move from the first frame to the second over the largest move
        between later frames (among the next 200); ``nan`` for fewer than 10 frames.
    start_frame : int
        The motion's ``start_frame`` (the first frame's number in the capture).
    """

    style: str
    source_format: str
    n_joints: int
    root: str
    travelling_joint: str
    static_root: bool
    channel_counts: tuple[int, ...]
    constant_position_joints: tuple[str, ...]
    units: str
    units_source: str
    metres_per_unit: float
    height: float
    up_axis: str
    extents: tuple[float, float, float]
    fps: float
    n_frames: int
    reference_frame: bool
    first_step_ratio: float
    start_frame: int = 0

    @property
    def height_m(self) -> float:
        """The measured height in metres."""
        return self.height * self.metres_per_unit

    @property
    def position_channels_everywhere(self) -> bool:
        """Every joint has 6 channels (positions and rotations)."""
        return bool(self.channel_counts) and all(c == 6 for c in self.channel_counts)

    def _units_text(self) -> str:
        if self.units == "custom":
            text = f"{self.metres_per_unit:.4g} m per unit"
        elif self.units == "asf":
            lu = 0.0254 / self.metres_per_unit
            lead = "ASF units" if self.source_format == "asf" else "units"
            text = f"{lead} of " + ("1 in" if abs(lu - 1) < 1e-9 else f"1/{lu:g} in")
        elif self.units == "cmu":
            text = "CMU units of 1/0.45 in"
        else:
            text = self.units
        if self.units_source == "given":
            text += " as given"
        return f"{text} ({self.height_m:.2f} m tall)"

    def _channels_text(self) -> str:
        counts = self.channel_counts
        n = self.n_joints
        if counts and len(set(counts)) == 1:
            text = f"{n} joints with {counts[0]} channels"
            if self.constant_position_joints and counts[0] == 6:
                below = f" below {self.travelling_joint}" if self.static_root else ""
                text += f" (positions constant{below})"
            return text
        if len(counts) > 1 and len(set(counts[1:])) == 1:
            return f"{n} joints ({counts[0]} channels on the root, {counts[1]} on the others)"
        return f"{n} joints"

    def summary(self) -> str:
        """One line saying what was found, e.g. ``"Bandai-style rig: static root
        joint_Root, Hips travels, 22 joints with 6 channels (positions constant below
        Hips), cm (1.33 m tall), Y-up, 30 fps"``."""
        if self.static_root:
            travel = f"static root {self.root}, {self.travelling_joint} travels"
        else:
            travel = f"{self.travelling_joint} travels"
        parts = [
            travel,
            self._channels_text(),
            self._units_text(),
            f"{self.up_axis}-up",
            f"{self.fps:g} fps",
        ]
        if self.reference_frame:
            parts.append(f"frame {self.start_frame} a reference pose (discontinuous with the next)")
        return f"{self.style} rig: " + ", ".join(parts)

    def to_dict(self) -> dict:
        """A JSON-ready description (plain lists, floats and strings)."""
        return {
            "summary": self.summary(),
            "style": self.style,
            "source_format": self.source_format,
            "joints": self.n_joints,
            "root": self.root,
            "travelling_joint": self.travelling_joint,
            "static_root": self.static_root,
            "channels_per_joint": list(self.channel_counts),
            "position_channels_everywhere": self.position_channels_everywhere,
            "constant_position_joints": list(self.constant_position_joints),
            "units": self.units,
            "units_source": self.units_source,
            "metres_per_unit": float(self.metres_per_unit),
            "height": float(self.height),
            "height_m": float(self.height_m),
            "up_axis": self.up_axis,
            "extents": [float(e) for e in self.extents],
            "fps": float(self.fps),
            "frames": int(self.n_frames),
            "reference_frame": bool(self.reference_frame),
            "first_step_ratio": None
            if not np.isfinite(self.first_step_ratio)
            else float(self.first_step_ratio),
        }


# ------------------------------------------------------------------------ finding
def _skeleton_of(motion: Motion) -> Skeleton:
    if not isinstance(motion, Motion):
        raise ParameterError(f"expected a Motion, got {type(motion).__name__}")
    if motion.skeleton is None:
        raise ParameterError(
            "rig conventions need a skeleton; this motion has none (load it from ASF/AMC, "
            "BVH, glTF, USD or an .npz with a skeleton)"
        )
    if motion.n_frames < 1:
        raise ParameterError("rig conventions need at least one frame")
    return motion.skeleton


def _length_tolerance(skel: Skeleton) -> float:
    """Largest spread of a length channel that still counts as constant."""
    return 1e-8 * max(skel.total_length(), 1e-12)


#: Largest spread (degrees) of an angle channel that still counts as constant.
_ANGLE_TOLERANCE = 1e-8


def _constant(motion: Motion, channels: list[tuple[str, str]]) -> bool:
    """Whether every listed channel the motion has keeps one value over all frames."""
    tol_len = _length_tolerance(motion.skeleton)
    col = {c: i for i, c in enumerate(motion.channels)}
    for c in channels:
        k = col.get(c)
        if k is None:
            continue
        tol = tol_len if c[1].startswith("t") else _ANGLE_TOLERANCE
        if np.ptp(motion.frames[:, k]) > tol:
            return False
    return True


def _joint_channels(motion: Motion, joint: Joint, kind: str = "") -> list[tuple[str, str]]:
    return [(joint.name, d) for d in joint.dofs if d.startswith(kind)]


def _static_root(motion: Motion) -> bool:
    """Root with constant channels over two frames or more, no end site and exactly one
    child joint."""
    skel = motion.skeleton
    root = skel.joints[0]
    if (
        motion.n_frames < 2
        or len(skel.joints) < 2
        or root.end_site is not None
        or len(skel.children(0)) != 1
    ):
        return False
    return _constant(motion, _joint_channels(motion, root))


def _constant_position_joints(motion: Motion, first: int) -> tuple[str, ...]:
    """Joints after index ``first`` with position channels that are all constant (none
    for a single frame, where nothing can be seen to move)."""
    out: list[str] = []
    if motion.n_frames < 2:
        return ()
    for j in motion.skeleton.joints[first + 1 :]:
        chans = _joint_channels(motion, j, "t")
        if chans and _constant(motion, chans):
            out.append(j.name)
    return tuple(out)


def _sample(n: int, most: int) -> np.ndarray:
    return np.unique(np.linspace(0, n - 1, min(n, most)).round().astype(int))


def _spans(pos: np.ndarray) -> np.ndarray:
    """``np.ptp(pos, axis=1)`` of points ``(K, P, 3)``: the body's extent per frame and
    axis, ``(K, 3)`` (reduced along a contiguous last axis, three times faster)."""
    p = np.ascontiguousarray(pos.transpose(0, 2, 1))
    return p.max(axis=-1) - p.min(axis=-1)


def _body_points(motion: Motion, frames: np.ndarray, skip_root: bool) -> np.ndarray:
    """World positions ``(K, P, 3)`` of joints and end sites at ``frames``."""
    every = frames.size == motion.n_frames and np.array_equal(frames, np.arange(frames.size))
    pos = (motion if every else motion[frames]).positions().positions  # (kept: read only)
    return pos[:, 1:] if skip_root else pos


def _ends_at_bottom(motion: Motion, frames: np.ndarray) -> np.ndarray:
    """Per axis, the median over ``frames`` of how many chain ends (end sites and joints
    without children) lie within a tenth of the body's extent of its lowest point, ``(3,)``.
    Along the up axis the feet are those ends; along a horizontal axis one end (a tail,
    a hand, a snout) usually leads alone."""
    fk = forward_kinematics(motion[frames])
    par = fk.parents
    ends = np.setdiff1d(np.arange(len(par)), par[par >= 0])
    pos = fk.positions
    low = pos.min(axis=1, keepdims=True)
    reach = 0.1 * np.ptp(pos, axis=1, keepdims=True)
    near = (pos[:, ends] - low <= reach).sum(axis=1)
    return np.median(near, axis=0)


#: The head lies this many times further from the feet along the up axis than along the
#: other candidate (median over frames) for :func:`_head_over_feet` to decide.
_HEAD_OVER_FEET = 3.0


def _head_over_feet(motion: Motion, frames: np.ndarray) -> str | None:
    """Y or Z when the skeleton names a head and a left and a right ankle (or foot, or
    toe) and, over ``frames``, the head lies :data:`_HEAD_OVER_FEET` times further from
    the feet' midpoint along one of the two axes than along the other; else None.

    A person standing or walking keeps the head over the feet whichever way they face;
    the extents alone do not tell when something reaches out across the other axis
    (arms, a prop: a latent model's Xsens stand read 1,740 mm tall and 891 mm deep,
    under twice, and three chain ends, the head and both hands, lay at its back along
    z against the two feet at the bottom of y: Z was taken)."""
    from ..joint_names import classify_skeleton

    skel = motion.skeleton
    roles = classify_skeleton(skel)
    head = [j for j, r in roles.items() if r.role == "head"]
    for kind in ("ankle", "foot", "toe"):
        feet = {r.side: j for j, r in roles.items() if r.role == kind and r.side}
        if {"left", "right"} <= set(feet):
            break
    else:
        return None
    if not head:
        return None
    fk = forward_kinematics(motion[frames])
    pos = fk.positions
    h = pos[:, fk.names.index(head[0])]
    f = 0.5 * (pos[:, fk.names.index(feet["left"])] + pos[:, fk.names.index(feet["right"])])
    sep = np.median(np.abs(h - f), axis=0)
    if sep[1] >= _HEAD_OVER_FEET * sep[2]:
        return "Y"
    if sep[2] >= _HEAD_OVER_FEET * sep[1]:
        return "Z"
    return None


def _up_of(motion: Motion, frames: np.ndarray, extents: np.ndarray, static: bool) -> str:
    """Y or Z, the up axis of a capture.

    A body at least twice as tall as it is deep or long: the axis of its larger extent (a
    biped).  Then a skeleton that names a head and two feet: the axis along which the
    head keeps clearly furthest from the feet (:func:`_head_over_feet`).  Otherwise (a
    dog, whose body can be longer than it is tall) the axis along
    which more chain ends reach the bottom (the feet stand on the floor), then the axis the
    body travels less along, then the larger extent."""
    y, z = float(extents[1]), float(extents[2])
    if max(y, z) >= 2.0 * min(y, z):
        return "Z" if z > y else "Y"
    named = _head_over_feet(motion, frames)
    if named is not None:
        return named
    at_bottom = _ends_at_bottom(motion, frames)
    if at_bottom[1] != at_bottom[2]:
        return "Z" if at_bottom[2] > at_bottom[1] else "Y"
    root = forward_kinematics(motion[frames]).positions[:, 1 if static else 0]
    travel = np.ptp(root, axis=0)
    if max(travel[1], travel[2]) > max(y, z):
        return "Y" if travel[2] > travel[1] else "Z"
    return "Z" if z > y else "Y"


def _first_step_ratio(
    motion: Motion, skip_root: bool, pos: np.ndarray | None = None
) -> tuple[float, float]:
    """Largest point move frame 0 -> 1, and its ratio to the largest later move (200
    frames); ``pos``: the body points of those frames, already found."""
    T = motion.n_frames
    if T < 10:
        return float("nan"), float("nan")
    if pos is None:
        pos = _body_points(motion, np.arange(min(T, 202)), skip_root)
    d = np.diff(pos, axis=0)
    steps = np.sqrt(np.einsum("tpi,tpi->tp", d, d)).max(axis=1)
    later = float(steps[1:].max())
    ratio = float("inf") if later <= 0 else float(steps[0] / later)
    return float(steps[0]), ratio


def _guess_units(height: float) -> tuple[str, float]:
    """The candidate unit putting ``height`` nearest a human's height (in ratio)."""
    if not (np.isfinite(height) and height > 0):
        return "m", 1.0
    name = min(_CANDIDATES, key=lambda u: abs(np.log(height * _CANDIDATES[u] / _HUMAN_HEIGHT)))
    return name, _CANDIDATES[name]


def describe_rig(motion: Motion, units: Units = "auto") -> RigInfo:
    """Find a capture's rig conventions: travelling joint, channels, units, up axis, rate.

    Parameters
    ----------
    motion : Motion
        A capture with a skeleton, frames ``(T, D)``.
    units : {"auto", "m", "cm", "mm", "in"} or float, default "auto"
        Length unit of the skeleton, or a number of metres per unit.  ``"auto"`` uses the
        ASF ``:units length`` when the skeleton has one (ASF: ``0.0254 / length_unit``
        metres per unit, CMU 0.0564) and metres for a glTF from elsewhere, otherwise
        guesses from the body's height: the unit among m, cm, mm, in and CMU's 1/0.45 in
        that makes it closest to 1.7 m (right for bodies of about 1.1 to 2.5 m).

    Returns
    -------
    RigInfo

    Notes
    -----
    The height is the median over (up to 400 evenly spread) frames of the body's extent
    along the up axis, lowest to highest joint or end site, a static root left out: a
    standing or walking pose.  It is where the skeleton's points reach: a rig whose head
    ends at the skull's base (Bandai: the ``Head`` end site has zero offset) measures some
    20 cm shorter than the performer.  The up axis is whichever of y and z that median
    extent is larger along when it is at least twice the other (a biped); for a body as
    long as it is tall (a dog) it is the axis along which more chain ends reach the
    bottom (the feet), then the one the body travels less along (see ``_up_of``).
    The first frame is a reference pose when its largest joint
    move to the second frame exceeds 5 times the largest move between the next 200 frames
    and 2 % of the height.  Only ratios of lengths are used, so the findings do not
    depend on the unit.
    """
    skel = _skeleton_of(motion)
    static = _static_root(motion)
    travel_index = 1 if static else 0
    T = motion.n_frames
    # one forward kinematics for the sampled frames and the first 202 (often all of them)
    sample, first = _sample(T, 400), np.arange(min(T, 202))
    union = np.union1d(sample, first)
    points = _body_points(motion, union, static)
    pos = points[np.searchsorted(union, sample)]
    extents = np.median(_spans(pos), axis=0)
    up = _up_of(motion, sample, extents, static)
    height = float(extents[AXIS_INDEX[up.lower()]])
    step0, ratio = _first_step_ratio(motion, static, points[np.searchsorted(union, first)])
    reference = bool(np.isfinite(ratio) and ratio > 5.0 and step0 > 0.02 * height)
    if reference:  # measure the body without the reference pose
        pos = _body_points(motion, 1 + _sample(T - 1, 400), static)
        extents = np.median(_spans(pos), axis=0)
        up = _up_of(motion, 1 + _sample(T - 1, 400), extents, static)
        height = float(extents[AXIS_INDEX[up.lower()]])

    given = parse_units(units)
    if given is not None:
        named = [u for u, v in UNITS.items() if v == given]
        unit, source, mpu = (named[0] if named else "custom"), "given", given
    elif _unit_from_skeleton(skel) is not None:
        unit, source, mpu = _unit_from_skeleton(skel)
    else:
        unit, mpu = _guess_units(height)
        source = "measured"

    constant = _constant_position_joints(motion, travel_index)
    counts = tuple(len(j.dofs) for j in skel.joints)
    label = {"asf": "ASF", "bvh": "BVH", "gltf": "glTF", "usd": "USD", "synthetic": "synthetic"}
    everywhere = all(c == 6 for c in counts)
    if static and everywhere and len(constant) == len(skel.joints) - 2:
        style = "Bandai-style"
    else:
        style = label.get(skel.source_format, skel.source_format or "unnamed")
    return RigInfo(
        style=style,
        source_format=skel.source_format,
        n_joints=len(skel.joints),
        root=skel.joints[0].name,
        travelling_joint=skel.joints[travel_index].name,
        static_root=static,
        channel_counts=counts,
        constant_position_joints=constant,
        units=unit,
        units_source=source,
        metres_per_unit=float(mpu),
        height=height,
        up_axis=up,
        extents=(float(extents[0]), float(extents[1]), float(extents[2])),
        fps=float(motion.fps),
        n_frames=T,
        reference_frame=reference,
        first_step_ratio=ratio,
        start_frame=int(motion.start_frame),
    )


def _unit_from_skeleton(skel: Skeleton) -> tuple[str, str, float] | None:
    """``(units, units_source, metres per unit)`` when the skeleton or its format says it:
    an ASF ``:units length`` (``0.0254 / length_unit``; also kept by skeletons converted
    from ASF), or glTF's metres."""
    if skel.source_format == "asf" or (skel.length_unit != 1.0 and skel.length_unit > 0):
        return "asf", "skeleton", 0.0254 / skel.length_unit
    if skel.source_format == "gltf":
        return "m", "skeleton", 1.0
    return None


def metres_per_unit(motion: Motion, units: Units = "auto") -> float:
    """Metres per skeleton length unit, what glTF and USD exports scale by.

    Parameters
    ----------
    motion : Motion
        A capture with a skeleton.
    units : {"auto", "m", "cm", "mm", "in"} or float, default "auto"
        A given unit is returned without looking at the motion; ``"auto"`` takes an ASF
        skeleton's ``0.0254 / length_unit`` (as exports always did) and measures the others
        (:func:`describe_rig`).

    Returns
    -------
    float
        Metres per unit.
    """
    given = parse_units(units)
    if given is not None:
        return given
    known = _unit_from_skeleton(_skeleton_of(motion))
    if known is not None:
        return known[2]
    return describe_rig(motion).metres_per_unit


def rig_summary(motion: Motion, units: Units = "auto") -> str:
    """The console's first line: what :func:`describe_rig` found, in one sentence.

    Parameters
    ----------
    motion : Motion
        A capture, frames ``(T, D)``.
    units : {"auto", "m", "cm", "mm", "in"} or float, default "auto"
        As for :func:`describe_rig`.

    Returns
    -------
    str
        :meth:`RigInfo.summary`, e.g. ``"BVH rig: Hips travels, 25 joints (6 channels on
        the root, 3 on the others), mm (1.74 m tall), Y-up, 100 fps"``; for a motion
        without a skeleton (or frames) a line saying so, with its channels and rate.
    """
    if not isinstance(motion, Motion):
        raise ParameterError(f"expected a Motion, got {type(motion).__name__}")
    if motion.skeleton is None or motion.n_frames < 1:
        return (
            f"no skeleton: {motion.n_channels} channels, {motion.fps:g} fps "
            "(rig, units and up axis unknown)"
        )
    return describe_rig(motion, units).summary()
