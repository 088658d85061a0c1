"""Per-joint local transforms of a motion, and back to channel values.

:func:`cyclecoord.skeleton.forward_kinematics` gives world positions; exporters need the
pieces it multiplies: each joint's local translation (its rest offset with translation
channels substituted) and local rotation ``axis @ R(channels) @ axis.T``, so that
``G_j = G_parent @ T(translation_j) @ rotation_j``.  :func:`channels_from_local` inverts
that for a skeleton's own degrees of freedom (used when reading exports back).
"""

from __future__ import annotations

import warnings

import numpy as np

from .errors import ParameterError
from .motion import Motion
from .skeleton import AXIS_INDEX, Skeleton, _levels, _plan, _world

__all__ = ["channels_from_local", "global_transforms", "local_transforms", "world_transforms"]


def local_transforms(
    motion: Motion, skeleton: Skeleton | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Local translations ``(T, J, 3)`` and rotations ``(T, J, 3, 3)`` of every joint."""
    skel = skeleton if skeleton is not None else motion.skeleton
    if skel is None:
        raise ParameterError("local transforms need a skeleton; this motion has none")
    frames = np.asarray(motion.frames, dtype=float)
    trans, rots = _plan(skel, motion.channels).local(frames, exact=True)
    return np.ascontiguousarray(trans.transpose(2, 1, 0)), np.ascontiguousarray(
        rots.transpose(3, 2, 0, 1)
    )


def world_transforms(motion: Motion) -> tuple[np.ndarray, np.ndarray]:
    """World positions ``(T, J, 3)`` and rotations ``(T, J, 3, 3)`` of every joint:
    :func:`global_transforms` of :func:`local_transforms`, in one pass."""
    if motion.skeleton is None:
        raise ParameterError("world transforms need a skeleton; this motion has none")
    plan = _plan(motion.skeleton, motion.channels)
    pos, rot = plan.world(*plan.local(np.asarray(motion.frames, dtype=float), exact=True))
    return np.ascontiguousarray(pos.transpose(2, 1, 0)), np.ascontiguousarray(
        rot.transpose(3, 2, 0, 1)
    )


def global_transforms(
    translations: np.ndarray, rotations: np.ndarray, parents: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World positions ``(T, J, 3)`` and rotations ``(T, J, 3, 3)`` from local transforms."""
    pos, rot = _world(
        np.ascontiguousarray(np.swapaxes(translations, 0, 1), dtype=float),
        np.ascontiguousarray(np.swapaxes(rotations, 0, 1), dtype=float),
        _levels(parents),
    )
    return np.ascontiguousarray(pos.swapaxes(0, 1)), np.ascontiguousarray(rot.swapaxes(0, 1))


def _euler(matrices: np.ndarray, order: str) -> np.ndarray:
    """Intrinsic Euler angles in degrees ``(T, len(order))`` of rotations ``(T, 3, 3)``.

    Orders with fewer than three axes are completed with the missing axis, whose angle
    is dropped (it is zero for rotations the joint can make).
    """
    from scipy.spatial.transform import Rotation

    if len(order) == 1:
        i = "XYZ".index(order)
        j, k = (i + 1) % 3, (i + 2) % 3
        return np.degrees(np.arctan2(matrices[:, k, j], matrices[:, j, j]))[:, None]
    full = order + "".join(a for a in "XYZ" if a not in order)[: 3 - len(order)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # gimbal lock: angles still valid
        angles = Rotation.from_matrix(matrices).as_euler(full, degrees=True)
    return angles[:, : len(order)]


def channels_from_local(
    skeleton: Skeleton, translations: np.ndarray, rotations: np.ndarray
) -> np.ndarray:
    """Frames ``(T, D)`` in ``skeleton.channels`` order from local transforms.

    Angles are unwrapped over time so curves do not jump by 360 degrees.
    """
    T = translations.shape[0]
    out = np.zeros((T, len(skeleton.channels)))
    k = 0
    for i, j in enumerate(skeleton.joints):
        if not j.dofs:
            continue
        angles = {}
        if j.rotation_order:
            r = j.axis.T @ rotations[:, i] @ j.axis
            eul = np.unwrap(_euler(r, j.rotation_order), period=360.0, axis=0)
            angles = {"r" + a.lower(): eul[:, m] for m, a in enumerate(j.rotation_order)}
        for d in j.dofs:
            if d.startswith("t"):
                out[:, k] = translations[:, i, AXIS_INDEX[d[1]]]
            else:
                out[:, k] = angles[d]
            k += 1
    return out
