"""Cycles brought into one frame before they are blended or ramped into each other.

:func:`common_frame` re-expresses cycles of one skeleton written in different
conventions in one (:func:`cyclecoord.conventions.common_channels`), scales root
translations to the reference skeleton's size, turns every cycle about the vertical to
the reference's heading, maps joint rotations to rotation vectors about each joint's mean
(:mod:`cyclecoord.periodic.rotations`) and aligns every cycle's phase to the reference's
(:func:`~cyclecoord.synthesis.align.align_curves`).  :func:`turn_back` undoes the turn and
the rotation map on the result.  Used by :func:`cyclecoord.synthesis.blend.blend` and
:func:`cyclecoord.synthesis.blend.transition`.
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


def _skeleton_size(m: Motion) -> float | None:
    if m.skeleton is None:
        return None
    size = m.skeleton.total_length()
    return size if size > 0 else None


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
    extended = [_with_next_frame(m) for m in motions]
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
            scale = ref_size / size
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
    )


def _with_next_frame(cycle: Motion) -> Motion:
    """The cycle with one more frame: the next loop's first (root moved by its drift)."""
    nxt = np.array(cycle.frames[:1], dtype=float)
    root = root_columns(cycle)
    if root.size:
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
    if prep.rotations is not None:
        frames = prep.rotations.to_channels(frames, near=original.frames[0])
    if not prep.turned or prep.reference_heading == 0.0:
        return frames
    m = prep.reference.with_frames(frames)
    _, _, rcols = root_rotation(original)
    back = rotate_heading(m, prep.reference_heading, "xyz"[prep.up], near=original.frames[0, rcols])
    return np.array(back.frames)
