"""Takes of one rig worn by actors of other proportions, put on one skeleton.

Two CMU subjects (or two actors in one studio's suit) share the joints, their channels
and their rest axes; only the bone lengths differ.  A joint's rotation then means the
same pose on either skeleton, so a take is put on another actor's skeleton by keeping its
rotation channels and scaling its travel by the ratio of the two actors' leg lengths
(thigh plus shin, :func:`cyclecoord.quality.contacts.leg_length`): strides and the hips'
height grow with the legs, so the feet stay on the floor and step as far as the legs
reach.  Position channels that never change (a rig storing every bone's offset as a
channel) take the target's values.

This is what an animator does with takes of two performers on one rig before mixing
them; takes whose joints, channels or rest axes differ are another rig and are left to
a retargeting tool.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ..skeleton import Skeleton

__all__ = [
    "Proportions",
    "leg_scale",
    "onto_skeleton",
    "proportions_differ",
    "same_rig",
]

#: Offsets (and constant position channels) agreeing to this fraction of the skeleton's
#: summed bone length are the same actor's.
TOLERANCE = 1e-3


def _placed(skel: Skeleton) -> np.ndarray:
    """Joints placed by their OFFSET: those without translation channels (in BVH the
    channels replace the OFFSET)."""
    return np.array([not any(d.startswith("t") for d in j.dofs) for j in skel.joints])


def same_rig(a: Skeleton | None, b: Skeleton | None) -> str:
    """What makes ``b`` another rig than ``a`` ("" when they are one rig): joints, their
    channels or their rest axes."""
    if a is None or b is None:
        return "" if a is None and b is None else "one take has no skeleton"
    if a.names != b.names:
        return "other joints"
    if any(x.dofs != y.dofs for x, y in zip(a.joints, b.joints)):
        return "other channels on a joint"
    axes = np.array([j.axis for j in a.joints]) - np.array([j.axis for j in b.joints])
    if axes.size and np.abs(axes).max() > 1e-6:
        return "other joint axes"
    return ""


def proportions_differ(a: Skeleton | None, b: Skeleton | None) -> bool:
    """Whether two skeletons of one rig (:func:`same_rig`) have other bone lengths: an
    offset of a joint without translation channels differs by more than
    :data:`TOLERANCE` of the skeleton's size."""
    if a is None or b is None:
        return False
    keep = _placed(a)
    off_a = np.array([j.offset for j in a.joints])[keep]
    off_b = np.array([j.offset for j in b.joints])[keep]
    tol = TOLERANCE * max(a.total_length(), 1e-9)
    return bool(off_a.size and np.abs(off_a - off_b).max() > tol)


def _legs(skel: Skeleton, motion: Motion) -> float:
    """Leg length, or the summed bone length on a rig whose feet cannot be found."""
    from ..quality.contacts import leg_length
    from ..quality.legs import find_feet

    try:
        return leg_length(skel, find_feet(skel, motion))
    except ParameterError:
        return skel.total_length()


def leg_scale(motion: Motion, target: Motion) -> float:
    """``target``'s leg length over ``motion``'s (each skeleton's summed bone length where
    its feet cannot be found): what ``motion``'s travel and hip height are scaled by to
    fit ``target``'s legs."""
    if motion.skeleton is None or target.skeleton is None:
        raise ParameterError("scaling travel between actors needs both skeletons")
    return _legs(target.skeleton, target) / _legs(motion.skeleton, motion)


@dataclass(frozen=True)
class Proportions:
    """How a take was put on another skeleton.

    Attributes
    ----------
    scale : float
        Its travel (root and other moving position channels) was multiplied by this: the
        target's leg length over the take's.
    legs : float
        The take's leg length over the target's (``1 / scale``).
    """

    scale: float
    legs: float

    def describe(self, name: str, target: str) -> str:
        return (
            f"{name}: another actor on the same rig (legs {self.legs:.2f}x {target}'s); "
            f"its rotations put on {target}'s skeleton, its travel scaled {self.scale:.2f}x"
        )


def onto_skeleton(motion: Motion, target: Motion) -> tuple[Motion, Proportions]:
    """``motion`` on ``target``'s skeleton: rotations kept, travel scaled by the ratio of
    leg lengths, constant position channels taken from ``target``.

    Parameters
    ----------
    motion : Motion
        A take of the same rig as ``target`` (:func:`same_rig`).
    target : Motion
        The take whose skeleton (and constant position channels) the result has.

    Returns
    -------
    motion : Motion
        Same frames, channels and frame rate, ``target.skeleton``.
    proportions : Proportions

    Raises
    ------
    ParameterError
        When the two takes are not one rig or their channels differ.
    """
    src, dst = motion.skeleton, target.skeleton
    why = same_rig(dst, src)
    if why or src is None:
        raise ParameterError(
            f"{motion.source or 'this take'}: {why or 'no skeleton'}; cannot put it on "
            f"{target.source or 'the target'}'s skeleton"
        )
    if motion.channels != target.channels:
        raise ParameterError(
            f"{motion.source or 'this take'}: its channels differ from "
            f"{target.source or 'the target'}'s"
        )
    scale = leg_scale(motion, target)
    frames = np.array(motion.frames, dtype=float)
    tol = TOLERANCE * max(dst.total_length(), 1e-9)
    for i, (_, dof) in enumerate(motion.channels):
        if not dof.startswith("t"):
            continue
        own, theirs = frames[:, i], target.frames[:, i]
        if np.ptp(own) <= tol and np.ptp(theirs) <= tol:
            frames[:, i] = theirs.mean()  # a bone's offset stored as a channel
        else:
            frames[:, i] = own * scale
    out = Motion(
        frames, motion.channels, motion.fps, dst, motion.source, motion.start_frame,
        dict(motion.metadata),
    )
    return out, Proportions(scale=float(scale), legs=float(1.0 / scale))
