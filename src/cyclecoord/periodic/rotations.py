"""Joint rotations as vectors for the analysis, and back to Euler channels for the file.

Euler channels are not a good space to measure poses in: an angle near +-180 degrees
wraps to the other end, two triples such as ``(a, b, c)`` and ``(a + 180, 180 - b,
c + 180)`` describe one rotation, and near gimbal lock a small turn moves two channels
by tens of degrees.  A capture that contains any of these (BVH hips near 180, LAFAN1
files with 360-degree jumps, a root facing sideways) becomes a broken point cloud, its
average a pose nobody held, and every step figure measures the wrap, not the motion.

:class:`RotationMap` gives the analysis a representation in which a wrap or a flip
changes nothing:

* a joint with three rotation channels becomes the **rotation vector** (axis times
  angle, degrees) of its rotation relative to the joint's mean rotation over the
  capture, ``log(M_j^T R_j(t))``.  This is the log map about the mean, the standard
  chart for averaging rotations: it is an isometry of the rotation angle near the
  mean, straight lines in it are slerps from the mean, and an average of vectors is one
  Gauss-Newton step of the Karcher mean, exact to second order in the spread.  A joint's
  rotations stay well within 180 degrees of their mean in every capture we know, so the
  chart does not fold;
* a joint with one or two rotation channels (an ASF hinge or a clavicle) keeps its
  angles, each moved onto the branch within 180 degrees of its circular mean, so a
  hinge passing +-180 does not jump.

Rotation vectors in degrees keep the numbers of the paper's space for small motions (a
few degrees about the mean read almost as the Euler channels do), so thresholds,
bandwidths and figures carry over.

``rotations="euler"`` in :class:`~cyclecoord.periodic.preprocess.Preprocessor` keeps the
channels as written: the paper's space, bit for bit.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ..conventions import continuous_euler
from ..motion import Motion

__all__ = ["RotationMap", "fit_rotation_map", "circular_mean_degrees", "euler_is_safe"]


def circular_mean_degrees(angles: np.ndarray) -> np.ndarray:
    """Circular mean of angles in degrees, per column; shape ``(T, K) -> (K,)``."""
    a = np.radians(np.asarray(angles, dtype=float))
    return np.degrees(np.arctan2(np.sin(a).mean(axis=0), np.cos(a).mean(axis=0)))


@dataclass(frozen=True)
class _Group:
    """One joint's three rotation columns: ``columns[k]`` holds Euler letter ``order[k]``."""

    columns: np.ndarray
    order: str
    mean: Rotation


@dataclass(frozen=True)
class RotationMap:
    """A fitted map between Euler channels and the analysis's rotation vectors.

    Attributes
    ----------
    groups : tuple
        Joints with three rotation channels: their columns (in Euler order), the order and
        the joint's mean rotation.
    hinge_columns : ndarray of int
        Rotation columns of joints with one or two rotation channels.
    hinge_centres : ndarray, shape (len(hinge_columns),)
        Their circular means (degrees): each angle is kept within 180 degrees of it.
    """

    groups: tuple
    hinge_columns: np.ndarray
    hinge_centres: np.ndarray

    @property
    def columns(self) -> np.ndarray:
        """Every column the map rewrites."""
        parts = [g.columns for g in self.groups] + [self.hinge_columns]
        return np.concatenate(parts).astype(int) if parts else np.zeros(0, dtype=int)

    def to_arrays(self) -> dict:
        """Plain arrays for a model file (:meth:`from_arrays` reads them back)."""
        return {
            "group_columns": np.array([g.columns for g in self.groups], dtype=int).reshape(-1, 3),
            "group_orders": np.array([g.order for g in self.groups], dtype="U3"),
            "group_means": np.array([g.mean.as_quat() for g in self.groups]).reshape(-1, 4),
            "hinge_columns": np.asarray(self.hinge_columns, dtype=int),
            "hinge_centres": np.asarray(self.hinge_centres, dtype=float),
        }

    @classmethod
    def from_arrays(cls, arrays: dict, n_channels: int) -> "RotationMap":
        """The map :meth:`to_arrays` stored; ValueError when the arrays do not fit."""
        cols = np.asarray(arrays["group_columns"]).astype(int).reshape(-1, 3)
        orders = [str(o).upper() for o in np.asarray(arrays["group_orders"]).reshape(-1)]
        quats = np.asarray(arrays["group_means"], dtype=float).reshape(-1, 4)
        hinge = np.asarray(arrays["hinge_columns"]).astype(int).reshape(-1)
        centres = np.asarray(arrays["hinge_centres"], dtype=float).reshape(-1)
        if not (len(cols) == len(orders) == len(quats)) or hinge.size != centres.size:
            raise ValueError("rotation map arrays of different lengths")
        every = np.concatenate([cols.ravel(), hinge])
        if every.size and (every.min() < 0 or every.max() >= n_channels):
            raise ValueError("rotation map columns outside the channels")
        if not (np.all(np.isfinite(quats)) and np.all(np.isfinite(centres))):
            raise ValueError("rotation map values are not finite")
        norms = np.linalg.norm(quats, axis=1)
        if np.any(np.abs(norms - 1.0) > 1e-6):
            raise ValueError("rotation map means are not unit quaternions")
        for o in orders:
            if sorted(o) != ["X", "Y", "Z"]:
                raise ValueError(f"rotation order {o!r} is not a permutation of XYZ")
        groups = tuple(
            _Group(columns=c, order=o, mean=Rotation.from_quat(q))
            for c, o, q in zip(cols, orders, quats)
        )
        return cls(groups=groups, hinge_columns=hinge, hinge_centres=centres)

    def to_vectors(self, frames: np.ndarray) -> np.ndarray:
        """Channel values ``(T, D)`` to the analysis representation (other columns copied).

        Each three-channel joint's columns receive its rotation vector about the mean
        (degrees, components x, y, z in the order of the joint's columns in Euler order);
        hinge angles are moved within 180 degrees of their centres.
        """
        out = np.array(frames, dtype=float)
        if out.ndim != 2:
            raise ValueError("frames must be (T, D)")
        for g in self.groups:
            R = Rotation.from_euler(g.order, out[:, g.columns], degrees=True)
            out[:, g.columns] = (g.mean.inv() * R).as_rotvec(degrees=True)
        if self.hinge_columns.size:
            c = self.hinge_centres
            x = out[:, self.hinge_columns]
            # whole turns only, so an angle already on the branch keeps its exact value
            out[:, self.hinge_columns] = x - 360.0 * np.floor((x - c + 180.0) / 360.0)
        return out

    def to_channels(self, vectors: np.ndarray, near: np.ndarray | None = None) -> np.ndarray:
        """The inverse of :meth:`to_vectors`: Euler channels, continuous over frames.

        Parameters
        ----------
        vectors : ndarray, shape (T, D)
            Rows in the analysis representation (other columns are copied).
        near : ndarray, shape (D,), optional
            Channel values the first row's Euler angles should lie closest to (e.g. a
            captured frame), so the written numbers look like the capture's; later rows
            take the solution nearest the row before (no wraps, no flips).
        """
        out = np.array(vectors, dtype=float)
        for g in self.groups:
            R = g.mean * Rotation.from_rotvec(out[:, g.columns], degrees=True)
            ref = None if near is None else np.asarray(near, dtype=float)[g.columns]
            out[:, g.columns] = continuous_euler(R.as_matrix()[:, None], g.order, ref)[:, 0]
        if self.hinge_columns.size and near is not None:
            # the same branch as the reference frame's angle
            ref = np.asarray(near, dtype=float)[self.hinge_columns]
            first = out[0, self.hinge_columns]
            out[:, self.hinge_columns] += np.round((ref - first) / 360.0) * 360.0
        return out


#: In ``mode="auto"`` a joint's Euler channels are kept when no frame-to-frame step exceeds
#: this (degrees; a wrap or a branch flip jumps by 180-360, a real joint turns under 20
#: degrees a frame even at 24 fps) ...
SAFE_STEP = 45.0
#: ... its middle angle stays within this of 0 (gimbal lock at 90; CMU 13_29's right
#: humerus reaches 80.8 degrees in the toe touches without a jump, and keeping its channels
#: keeps that take's detection as measured) ...
SAFE_MIDDLE = 85.0
#: ... and no channel spans more than this (a slow pass through +-180).
SAFE_SPAN = 270.0


def euler_is_safe(angles: np.ndarray) -> bool:
    """Whether Euler angles ``(T, 3)`` (degrees, in order) never wrap, flip or near gimbal
    lock, so that they measure the rotation as well as a rotation vector does."""
    a = np.asarray(angles, dtype=float)
    if len(a) == 0:
        return True
    if len(a) > 1 and np.abs(np.diff(a, axis=0)).max() > SAFE_STEP:
        return False
    return bool(np.abs(a[:, 1]).max() <= SAFE_MIDDLE and np.ptp(a, axis=0).max() <= SAFE_SPAN)


def fit_rotation_map(motion: Motion, exclude: np.ndarray | None = None,
                     frames: np.ndarray | None = None, mode: str = "rotvec") -> RotationMap:
    """Find each joint's rotation channels and its mean rotation over ``frames``.

    Parameters
    ----------
    motion : Motion
        Gives the channels and the skeleton (each joint's Euler order).  Without a
        skeleton every rotation channel is treated as a hinge (its order is unknown).
    exclude : ndarray of int, optional
        Columns to leave alone (the differenced root).
    frames : ndarray, shape (T, D), optional
        Values to fit the means on (default ``motion.frames``).
    mode : {"rotvec", "auto"}
        ``"rotvec"``: every three-channel joint becomes a rotation vector.  ``"auto"``:
        only the joints whose Euler channels are not safe (:func:`euler_is_safe`: a wrap,
        a branch flip or a middle angle near 90 degrees anywhere in the capture); the
        others keep their channels, which then already measure the rotation faithfully.

    Returns
    -------
    RotationMap
    """
    vals = motion.frames if frames is None else np.asarray(frames, dtype=float)
    skip = set(int(c) for c in (exclude if exclude is not None else []))
    by_joint: dict[str, dict[str, int]] = {}
    for i, (j, d) in enumerate(motion.channels):
        if i in skip or len(d) != 2 or d[0] != "r" or d[1] not in "xyz":
            continue
        by_joint.setdefault(j, {})[d[1]] = i
    sk = motion.skeleton
    orders = {}
    if sk is not None:
        orders = {j.name: j.rotation_order for j in sk.joints}
    groups, hinges = [], []
    for name, cols in by_joint.items():
        order = (orders.get(name) or "").upper()
        if len(cols) == 3 and len(order) == 3 and sorted(order) == ["X", "Y", "Z"]:
            columns = np.array([cols[a.lower()] for a in order], dtype=int)
            if mode == "auto" and euler_is_safe(vals[:, columns]):
                continue
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message=".*[Gg]imbal.*")
                R = Rotation.from_euler(order, vals[:, columns], degrees=True)
            groups.append(_Group(columns=columns, order=order, mean=R.mean()))
        else:
            hinges.extend(cols.values())
    hinge_columns = np.array(sorted(hinges), dtype=int)
    centres = (
        circular_mean_degrees(vals[:, hinge_columns]) if hinge_columns.size else np.zeros(0)
    )
    return RotationMap(groups=tuple(groups), hinge_columns=hinge_columns, hinge_centres=centres)
