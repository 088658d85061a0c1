"""Cycles brought into one frame before they are blended or ramped into each other.

:func:`common_frame` re-expresses cycles of one skeleton written in different
conventions in one (:func:`cyclecoord.conventions.common_channels`), scales root
translations to the reference skeleton's size, turns every cycle about the vertical to
the reference's heading, maps joint rotations to rotation vectors about each joint's mean
(:mod:`cyclecoord.periodic.rotations`) and aligns every cycle's phase to the reference's
(:func:`~cyclecoord.synthesis.align.align_curves`), the root's rotation curved as
heading-first Euler angles (a turn per loop is then a drift of one angle) and its ground
travel in the heading's frame.  :func:`turn_back` undoes the turn, the travel's frame, the
root's chart and the rotation map on the result.  Used by
:func:`cyclecoord.synthesis.blend.blend` and :func:`cyclecoord.synthesis.blend.transition`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Sequence

import numpy as np

from ..conventions import bvh_ready, common_channels, wrap_degrees
from ..errors import ParameterError
from ..motion import Motion
from ..periodic.rotations import fit_rotation_map
from .align import (
    Alignment,
    align_curves,
    apply_alignment,
    check_up,
    harmonise_angles,
    mean_heading,
    root_rotation,
    rotate_heading,
)
from .curve import (
    CycleCurve,
    angle_columns,
    continuous_root,
    horizontal_columns,
    root_columns,
    root_drift,
)

__all__ = ["Prepared", "common_frame", "turn_back"]


@dataclass
class Prepared:
    """Cycles in the reference's frame (:func:`common_frame`): aligned curves and how
    they were turned, scaled and aligned."""

    curves: list
    alignments: list
    headings: list
    root_scales: list
    notes: list
    reference: Motion
    reference_heading: float
    turned: bool
    up: int
    base: Motion  # the reference in the common channels, not turned
    rotations: Any = None  # RotationMap: joints blended as rotation vectors about a mean
    root_chart: str = ""  # Euler order (up axis first) the root's rotation is curved in
    local_travel: bool = False  # the ground travel curved in the root's heading frame


def _skeleton_size(m: Motion) -> float | None:
    if m.skeleton is None:
        return None
    size = m.skeleton.total_length()
    return size if size > 0 else None


def _travel_scale(m: Motion, ref: Motion, fallback: float) -> float:
    """What ``m``'s root translation is scaled by to fit ``ref``'s skeleton: the ratio of
    their leg lengths, which set the hips' height and the stride
    (:func:`cyclecoord.rig.retarget.leg_scale`; ``fallback``, the summed bone lengths'
    ratio, where no legs are found).  By the summed bone lengths a transition from
    subject 35's walk to subject 143's jog (legs 0.84x, arms and spine less) put a foot
    4.4 cm under the floor on 23 % of its frames."""
    from ..errors import CycleCoordError
    from ..rig.retarget import leg_scale

    try:
        return leg_scale(m, ref)
    except CycleCoordError:
        return fallback


def common_frame(
    motions: Sequence[Motion],
    *,
    allow_reverse: bool,
    align_heading: bool,
    scale_root: bool,
    up: str,
) -> Prepared:
    """Bring cycles into the reference's (``motions[0]``) frame as aligned curves."""
    u = check_up(up)
    notes: list[str] = []
    # every cycle carries the next loop's first frame through the conversions below, so
    # its per-loop root change stays exact in whatever frame it ends up in
    extended = [_with_next_frame(m, u) for m in motions]
    converted = common_channels(extended)
    if any(set(c.channels) != set(m.channels) for c, m in zip(converted, motions)):
        style = bvh_ready(converted[0].skeleton)
        notes.append(
            "the cycles store their joints in different conventions; all were re-expressed in "
            + (
                f"BVH conventions ({style} Euler order)"
                if style
                else "the ASF conventions (axes, dofs)"
            )
            + " to share channels"
        )
    motions = converted
    ref = motions[0]
    fixed: list[Motion] = []
    scales: list[float] = []
    ref_size = _skeleton_size(ref)
    for i, m in enumerate(motions):
        scale = 1.0
        size = _skeleton_size(m)
        if (
            i
            and scale_root
            and ref_size is not None
            and size is not None
            and abs(size - ref_size) > 1e-9 * ref_size
        ):
            scale = _travel_scale(m, ref, ref_size / size)
            frames = np.array(m.frames, dtype=float)
            tcols = [c for c in root_columns(m) if m.channels[c][1] in ("tx", "ty", "tz")]
            frames[:, tcols] *= scale
            m = m.with_frames(frames)
        scales.append(scale)
        fixed.append(m)

    headings: list[float] = [0.0] * len(fixed)
    turned = False
    if align_heading:
        try:
            hs = [mean_heading(m[:-1], up) for m in fixed]
        except ParameterError as exc:
            notes.append(f"cycles not turned to a common heading: {exc}")
            hs = []
        if hs and all(np.isfinite(h) for h in hs):
            if max(abs(wrap_degrees(h - hs[0])) for h in hs) > 1e-9:
                turned = True
                headings = hs
                fixed = [
                    rotate_heading(m, -h, up, near=None) if abs(h) > 0 else m
                    for m, h in zip(fixed, hs)
                ]
        elif hs:
            notes.append(
                "cycles not turned to a common heading: a cycle spins round (no mean heading)"
            )

    chart = _chart_order(fixed[0], u)
    local = False
    if chart:
        fixed = [m.with_frames(_to_chart(m, chart)) for m in fixed]
        ground = horizontal_columns(fixed[0], u)
        if ground.size == 2:  # the travel in the heading's frame: a turn per loop turns it
            local = True
            fixed = [m.with_frames(_travel(m.frames, fixed[0], u, inverse=False))
                     for m in fixed]

    # joint rotations are blended as rotations: rotation vectors about each joint's mean
    # over all the cycles (a weighted sum of them is a weighted mean of rotations to second
    # order, and a wrap or Euler flip in one input changes nothing); the root keeps its own
    # treatment (heading turned, travel per loop)
    rotations = fit_rotation_map(
        fixed[0].with_frames(np.vstack([m.frames for m in fixed])),
        exclude=np.asarray(root_columns(fixed[0]), dtype=int),
    )
    if rotations.columns.size:
        fixed = [m.with_frames(rotations.to_vectors(m.frames)) for m in fixed]
    else:
        rotations = None
    curves = [_curve_of_extended(m) for m in fixed]
    ref_curve = curves[0]
    pose = np.array(
        [i for i in range(ref_curve.n_channels) if i not in set(ref_curve.root_columns)], dtype=int
    )
    if pose.size == 0:
        pose = np.arange(ref_curve.n_channels)
    alignments: list[Alignment] = [Alignment(0.0, False, 0.0, 0.0, 0.0)]
    out = [ref_curve]
    horiz = horizontal_columns(ref, u)
    start_ref = ref_curve(0.0)[0]
    for c in curves[1:]:
        c = harmonise_angles(c, ref_curve)
        al = align_curves(ref_curve, c, pose, allow_reverse)
        c = apply_alignment(c, al)
        if horiz.size:
            delta = np.zeros(c.n_channels)
            delta[horiz] = start_ref[horiz] - c(0.0)[0, horiz]
            c = c.offset(delta)
        alignments.append(al)
        out.append(c)
    return Prepared(
        curves=out,
        alignments=alignments,
        headings=[float(h) for h in headings],
        root_scales=scales,
        notes=notes,
        reference=fixed[0][:-1],
        reference_heading=float(headings[0]),
        turned=turned,
        up=u,
        base=ref[:-1],
        rotations=rotations,
        root_chart=chart,
        local_travel=local,
    )


def _chart_order(m: Motion, up: int) -> str:
    """The heading-first Euler order (the up axis first: ``"YXZ"`` for Y up) in which the
    root's rotation is curved, or ``""`` for a root without three rotation channels.

    The curves extrapolate a cycle's root channels linearly from loop to loop (its turn
    per loop); in the root's own Euler order that is no rotation where the middle angle
    nears 90 degrees, and a CMU root (``XYZ``, Y up) is there whenever the body faces
    along X: subject 143's jog (heading 87 degrees) drifted -32, 3 and -32 degrees a loop
    in its three channels, and a transition's lead-out, three loops on, stood 6-8
    degrees off the jog's own rotation with its stance foot sliding 1.1 m/s (0.13 in the
    cycle).  With the up axis first, a turn about the vertical changes the first angle
    alone and an upright body keeps the middle one small."""
    skel = m.skeleton
    if skel is None or len(skel.joints[0].rotation_order) != 3:
        return ""
    try:
        root_rotation(m)
    except ParameterError:
        return ""
    axes = "XYZ"
    return axes[up] + axes[(up + 2) % 3] + axes[(up + 1) % 3]


def _travel(frames: np.ndarray, like: Motion, up: int, inverse: bool) -> np.ndarray:
    """Frames whose ground travel is re-integrated between the world and the root's
    heading frame (the chart's first angle, :func:`_chart_order`): each step turned by
    minus the heading (``inverse=False``: into the heading's frame) or by it (back),
    from the first frame's position.

    A curve repeats its travel along a straight line (``x(θ + 1) = x(θ) + drift``) while
    its heading turns by the heading's drift each loop; in the world a turning cycle's
    body then faced off its path beyond its first loop, the stance foot sliding (subject
    143's jog turns 4.6 degrees a loop: a transition's lead-out, three loops on, faced
    14 degrees off its path and slid 0.7 m/s, 0.13 in the cycle).  In the heading's
    frame the travel repeats, and turned back it follows the heading: a circling walk
    goes on circling, a blend of two travels along the blended heading."""
    from scipy.spatial.transform import Rotation

    _, _, cols = root_rotation(like)
    ground = horizontal_columns(like, up)
    axes = ["xyz".index(like.channels[c][1][1]) for c in ground]
    heading = np.asarray(frames[:, cols[0]], dtype=float)
    turn = 0.5 * (heading[1:] + heading[:-1]) * (1.0 if inverse else -1.0)
    axis = np.zeros(3)
    axis[up] = 1.0
    steps = np.zeros((frames.shape[0] - 1, 3))
    steps[:, axes] = np.diff(frames[:, ground], axis=0)
    steps = Rotation.from_rotvec(np.radians(turn)[:, None] * axis[None, :]).apply(steps)
    out = np.array(frames, dtype=float)
    out[1:, ground] = frames[0, ground] + np.cumsum(steps[:, axes], axis=0)
    return out


def _to_chart(m: Motion, chart: str) -> np.ndarray:
    """``m``'s frames with its root rotation columns holding the world rotation's angles in
    ``chart`` (:func:`_chart_order`), continuous over time."""
    from ..conventions import continuous_euler

    mats, _, cols = root_rotation(m)
    frames = np.array(m.frames, dtype=float)
    frames[:, cols] = continuous_euler(mats[:, None], chart)[:, 0]
    return frames


def _from_chart(
    frames: np.ndarray, chart: str, original: Motion, near: np.ndarray | None = None
) -> np.ndarray:
    """Frames whose root rotation columns hold ``chart`` angles back in the root's own
    Euler channels, continuous and near ``near`` (default ``original``'s first frame)."""
    from scipy.spatial.transform import Rotation

    from ..conventions import continuous_euler

    _, order, cols = root_rotation(original)
    root = original.skeleton.joints[0]
    mats = Rotation.from_euler(chart, frames[:, cols], degrees=True).as_matrix()
    if not np.allclose(root.axis, np.eye(3)):
        mats = root.axis.T @ mats @ root.axis
    out = np.array(frames, dtype=float)
    start = original.frames[0] if near is None else np.asarray(near, dtype=float)
    out[:, cols] = continuous_euler(mats[:, None], order, start[cols])[:, 0]
    return out


def _with_next_frame(cycle: Motion, up: int = 1) -> Motion:
    """The cycle with one more frame: the next loop's first (root moved by its drift).

    Where the drift is not known (``metadata["root_displacement"]``, exact), the root's
    rotation drift is estimated in the heading-first chart (:func:`_chart_order`): per
    Euler channel, near the middle angle's 90 degrees, the estimate of the next loop's
    rotation was off by degrees (subject 143's jog, facing along X)."""
    nxt = np.array(cycle.frames[:1], dtype=float)
    root = root_columns(cycle)
    if root.size:
        chart = "" if "root_displacement" in cycle.metadata else _chart_order(cycle, up)
        if chart:
            charted = cycle.with_frames(_to_chart(cycle, chart))
            nxt[0, root] = charted.frames[0, root] + root_drift(charted)
            nxt = _from_chart(nxt, chart, cycle, near=cycle.frames[-1])
        else:
            nxt[0, root] = cycle.frames[0, root] + root_drift(cycle)
    meta = {k: v for k, v in cycle.metadata.items() if k != "root_displacement"}
    return replace(cycle, frames=np.vstack([cycle.frames, nxt]), metadata=meta)


def _curve_of_extended(extended: Motion) -> CycleCurve:
    """The curve of a cycle carrying its next loop's first frame (see :func:`_with_next_frame`)."""
    root = root_columns(extended)
    rot = angle_columns([extended.channels[c] for c in root])
    x = continuous_root(extended.frames[:, root], rot)
    return CycleCurve.from_motion(extended[:-1], displacement=x[-1] - x[0])


def turn_back(frames: np.ndarray, prep: Prepared, original: Motion) -> np.ndarray:
    """Frames from the common heading back to the reference's, root Euler near the original's;
    joint rotation vectors back to Euler channels, continuous and near the original's."""
    if prep.local_travel:
        frames = _travel(frames, prep.reference, prep.up, inverse=True)
    if prep.root_chart:
        frames = _from_chart(frames, prep.root_chart, original)
    if prep.rotations is not None:
        frames = prep.rotations.to_channels(frames, near=original.frames[0])
    if not prep.turned or prep.reference_heading == 0.0:
        return frames
    m = prep.reference.with_frames(frames)
    _, _, rcols = root_rotation(original)
    back = rotate_heading(m, prep.reference_heading, "xyz"[prep.up], near=original.frames[0, rcols])
    return np.array(back.frames)
