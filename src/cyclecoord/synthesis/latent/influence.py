"""Scaling joint angles by their influence on the body (Bailey et al., Eq. 1-3).

The paper's rig parameters become a skeleton's joint angles and its mesh the joints'
positions from forward kinematics.  Each channel ``i`` gets the weight ``w_i``, a least
squares fit of how far the body's points move per degree when that one angle leaves the
mean pose by ``n`` standard deviations, ``n`` in {-2, -1, 0, 1, 2} (Eq. 3).  Scaled
angles ``z = W (p - mean)`` then move the body by about one unit per unit, so PCA does
not spend components on channels that vary a lot but hardly move anything (Eq. 1).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...errors import ParameterError
from ...motion import Motion
from ...skeleton import Skeleton, forward_kinematics

__all__ = ["STEPS", "influence_weights", "pose_points"]

#: Multiples of a channel's standard deviation probed around the mean pose (Eq. 3).
STEPS = (-2, -1, 0, 1, 2)


def pose_points(
    angles: np.ndarray, channels: Sequence[tuple[str, str]], skeleton: Skeleton
) -> np.ndarray:
    """Joint positions of poses with the root at the origin and unrotated.

    Parameters
    ----------
    angles : ndarray, shape (T, C)
        Joint-angle channels in degrees (no root channels).
    channels : sequence of (joint, dof)
        Names of the ``C`` columns.
    skeleton : Skeleton

    Returns
    -------
    ndarray, shape (T, P, 3)
        Every joint and end site, in the skeleton's length units.
    """
    angles = np.atleast_2d(np.asarray(angles, dtype=float))
    motion = Motion(frames=angles, channels=tuple(channels), skeleton=skeleton)
    return forward_kinematics(motion).positions


def influence_weights(
    angles: np.ndarray,
    channels: Sequence[tuple[str, str]],
    skeleton: Skeleton,
    steps: Sequence[int] = STEPS,
    to_channels=None,
) -> np.ndarray:
    """The weight ``w_i`` of every joint-angle channel (Eq. 3).

    Parameters
    ----------
    angles : ndarray, shape (N, C)
        Training poses, joint angles in degrees.
    channels : sequence of (joint, dof)
    skeleton : Skeleton
    steps : sequence of int
        Multiples ``n`` of the channel's standard deviation.
    to_channels : callable, optional
        Maps angles ``(T, C)`` to the channel values forward kinematics reads (a latent
        model's chart, :meth:`~.model.LatentModel.to_channels`); default the angles are
        the channels.

    Returns
    -------
    ndarray, shape (C,)
        Length units of joint movement (all points stacked, Euclidean norm) per degree.
        A channel that never changes in the training poses gets 0.
    """
    angles = np.asarray(angles, dtype=float)
    if angles.ndim != 2 or angles.shape[0] < 2:
        raise ParameterError(f"influence weights need at least 2 poses, got shape {angles.shape}")
    n_ch = angles.shape[1]
    mean = angles.mean(axis=0)
    sd = angles.std(axis=0)
    steps_arr = np.asarray([s for s in steps if s != 0], dtype=float)
    # one FK call: the mean pose, then every channel moved by every step
    probes = np.repeat(mean[None, :], 1 + n_ch * steps_arr.size, axis=0)
    for i in range(n_ch):
        rows = 1 + i * steps_arr.size + np.arange(steps_arr.size)
        probes[rows, i] += steps_arr * sd[i]
    pts = pose_points(probes if to_channels is None else to_channels(probes), channels, skeleton)
    moved = np.linalg.norm((pts[1:] - pts[0]).reshape(n_ch, steps_arr.size, -1), axis=2)
    delta = np.abs(steps_arr)[None, :] * sd[:, None]  # |n sigma_i|, (C, S)
    denom = (delta**2).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.where(denom > 0, (moved * delta).sum(axis=1) / denom, 0.0)
    return w
