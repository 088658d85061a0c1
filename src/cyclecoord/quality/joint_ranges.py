"""Joint angles against the range the reference motions showed (:func:`joint_range_violations`,
used by :func:`~cyclecoord.quality.plausibility.check_plausibility`): each rotation channel
on the turn nearest its range, and a joint with three rotation channels judged by its
rotation, so an Euler triple's other solution or its trade near gimbal lock is no
violation."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..errors import ParameterError
from ..motion import Motion

__all__ = ["JointRangeViolation", "joint_range_violations"]


@dataclass(frozen=True)
class JointRangeViolation:
    """A joint angle channel leaving the range the reference motions showed.

    Attributes
    ----------
    channel : (str, str)
        ``(joint, dof)``.
    frames : int
        Number of frames outside the allowed range.
    first_frame : int
        First such frame (the motion's numbering).
    low, high : float
        Allowed range, degrees (reference min - margin, max + margin).
    worst : float
        Value furthest outside, degrees.
    excess : float
        How far outside, degrees.
    """

    channel: tuple
    frames: int
    first_frame: int
    low: float
    high: float
    worst: float
    excess: float

    def to_dict(self) -> dict[str, Any]:
        return {
            "channel": ".".join(self.channel),
            "frames": self.frames,
            "first_frame": self.first_frame,
            "allowed": [self.low, self.high],
            "worst": self.worst,
            "excess_deg": self.excess,
        }


def _joint_angle_columns(motion: Motion) -> list[int]:
    root = set(motion.root_channels())
    return [
        i for i, (_, d) in enumerate(motion.channels) if d in ("rx", "ry", "rz") and i not in root
    ]


def joint_range_violations(
    motion: Motion,
    reference_motions: Sequence[Motion],
    margin_deg: float = 5.0,
) -> list[JointRangeViolation]:
    """Joint angles outside ``[min - margin, max + margin]`` of the reference motions.

    Only joint rotation channels are checked (not the root's position or orientation).
    Angles are compared modulo 360: each value is taken on the turn nearest the
    middle of the reference range.

    Parameters
    ----------
    motion : Motion
    reference_motions : sequence of Motion
        Motions that define what is normal (e.g. the inputs of a blend); channels they
        lack are not checked.  References of a skeleton with the same joints in other
        conventions (ASF against BVH) are re-expressed in ``motion``'s first.
    margin_deg : float, default 5
        Tolerance in degrees.

    Returns
    -------
    list of JointRangeViolation
        Worst excess first.
    """
    if not isinstance(motion, Motion):
        raise ParameterError(f"expected a Motion, got {type(motion).__name__}")
    refs = list(reference_motions)
    if not refs or not all(isinstance(r, Motion) for r in refs):
        raise ParameterError("joint_range_violations needs at least one reference Motion")
    if not np.isfinite(margin_deg) or margin_deg < 0:
        raise ParameterError(f"margin_deg must be a non-negative number, got {margin_deg!r}")
    ranges = _channel_ranges(motion, refs, margin_deg)
    return _range_violations(motion, ranges, _near_rotations(motion, refs, ranges, margin_deg))


def _near_rotations(
    motion: Motion, refs: Sequence[Motion], ranges: list[tuple[int, float, float]],
    margin_deg: float, cache: dict | None = None, key: tuple = (),
) -> dict[int, np.ndarray]:
    """``column -> (T,) bool``: for the channels of a joint with three rotation channels
    (a ball joint), the frames whose rotation lies within ``margin_deg`` (geodesic) of a
    rotation the references show for that joint, whatever its Euler angles.  Near the
    middle angle's +-90 degrees the other two angles of an Euler triple trade off (gimbal
    lock): a Bandai spine within 0.8 degrees of its takes' rotations read 267 degrees on
    one channel against their -186 to 10, and the console said it left the inputs'
    range.  With ``cache``, the references' rotations are kept under ``key``."""
    from scipy.spatial.transform import Rotation

    from ..conventions import local_rotations

    skel = motion.skeleton
    if skel is None or motion.n_frames == 0:
        return {}
    if not ranges:
        return {}
    x, lo, hi = _on_turn(motion, ranges)
    outside = (x < lo) | (x > hi)  # (T, channels)
    by_joint: dict[str, list[int]] = {}
    for i, (c, _, _) in enumerate(ranges):
        by_joint.setdefault(motion.channels[c][0], []).append(i)
    near: dict[int, np.ndarray] = {}
    mine = None
    theirs: list = []
    for joint, idx in by_joint.items():
        j = skel.index(joint) if joint in skel.names else -1
        if j < 0 or len(skel.joints[j].rotation_order) != 3 or len(idx) != 3:
            continue
        bad = np.flatnonzero(outside[:, idx].any(axis=1))
        if not bad.size:
            continue
        if mine is None:
            mine = local_rotations(motion)
            theirs = None if cache is None else cache.get(key)
            if theirs is None:  # (the references' rotations: once per set, with a cache)
                theirs = [local_rotations(r)
                          for r in (_in_convention_of(r, motion) for r in refs)
                          if r.skeleton is not None and r.skeleton.names == skel.names]
                if cache is not None:
                    cache[key] = theirs
        if not theirs:
            return near
        q = Rotation.from_matrix(mine[j, bad]).as_quat()
        Q = Rotation.from_matrix(np.concatenate([t[j] for t in theirs])).as_quat()
        Q = Q[:: max(1, Q.shape[0] // 4000)]  # (at most some 4,000 reference rotations)
        dot = np.zeros(bad.size)
        for a in range(0, bad.size, 512):
            dot[a : a + 512] = np.abs(q[a : a + 512] @ Q.T).max(axis=1)
        ok = np.zeros(motion.n_frames, dtype=bool)
        ok[bad] = 2.0 * np.degrees(np.arccos(np.clip(dot, 0.0, 1.0))) <= margin_deg
        for i in idx:
            near[ranges[i][0]] = ok
    return near


def _channel_ranges(
    motion: Motion, refs: Sequence[Motion], margin_deg: float
) -> list[tuple[int, float, float]]:
    """``(column, low, high)`` of each joint angle channel of ``motion`` the references
    have: their range in ``motion``'s conventions, on one turn, widened by the margin."""
    refs = [_in_convention_of(r, motion) for r in refs]
    cols = _joint_angle_columns(motion)
    C = len(cols)
    mean, low, high = (np.full((len(refs), C), np.nan) for _ in range(3))
    for i, r in enumerate(refs):  # each reference's channels unwrapped at once
        have = [k for k, c in enumerate(cols) if motion.channels[c] in r.channels]
        if not have or r.n_frames == 0:
            continue
        rc = [r.channel_index(*motion.channels[cols[k]]) for k in have]
        v = np.unwrap(np.asarray(r.frames, float)[:, rc], period=360.0, axis=0)
        mean[i, have], low[i, have], high[i, have] = v.mean(axis=0), v.min(axis=0), v.max(axis=0)
    out = []
    for k, c in enumerate(cols):
        known = np.flatnonzero(np.isfinite(mean[:, k]))
        if not known.size:
            continue
        # bring every reference onto one turn (nearest the first's mean), then the range
        shift = 360.0 * np.round((mean[known, k] - mean[known[0], k]) / 360.0)
        lo = float((low[known, k] - shift).min()) - margin_deg
        hi = float((high[known, k] - shift).max()) + margin_deg
        out.append((c, lo, hi))
    return out


def _on_turn(
    motion: Motion, ranges: list[tuple[int, float, float]]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(x, low, high)``: the ranges' channels of ``motion`` ``(T, channels)``, each value
    on the turn nearest the middle of its range, and the ranges' ends."""
    lo = np.array([r[1] for r in ranges])
    hi = np.array([r[2] for r in ranges])
    x = motion.frames[:, [c for c, _, _ in ranges]]
    return x - 360.0 * np.round((x - 0.5 * (lo + hi)) / 360.0), lo, hi


def _range_violations(
    motion: Motion, ranges: list[tuple[int, float, float]],
    near: dict[int, np.ndarray] | None = None,
) -> list[JointRangeViolation]:
    """The channels of ``motion`` leaving ``ranges`` (:func:`_channel_ranges`), worst
    excess first; each value is taken on the turn nearest the middle of its range.  A
    frame ``near`` marks (its joint's rotation is a reference's) does not count."""
    out: list[JointRangeViolation] = []
    if not ranges:
        return out
    cols = np.array([c for c, _, _ in ranges], dtype=int)
    x, lo, hi = _on_turn(motion, ranges)
    excess = np.maximum(lo - x, x - hi)  # (T, channels)
    for i, c in enumerate(cols):
        if near and int(c) in near:
            excess[near[int(c)], i] = 0.0
    for i in np.flatnonzero((excess > 0).any(axis=0)):
        bad = np.flatnonzero(excess[:, i] > 0)
        k = bad[np.argmax(excess[bad, i])]
        out.append(JointRangeViolation(
            channel=motion.channels[cols[i]], frames=int(bad.size),
            first_frame=int(bad[0] + motion.start_frame),
            low=float(lo[i]), high=float(hi[i]), worst=float(x[k, i]),
            excess=float(excess[k, i]),
        ))
    out.sort(key=lambda v: -v.excess)
    return out


def _in_convention_of(reference: Motion, motion: Motion) -> Motion:
    """The reference written with ``motion``'s channels when the skeletons share joints.

    A blend of an AMC capture with a BVH cycle is written in one convention; comparing
    joint angles needs the references in the same one.
    """
    from ..conventions import in_conventions_of

    return in_conventions_of(reference, motion)
