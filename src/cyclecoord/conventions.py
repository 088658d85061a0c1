"""Re-express a motion in BVH skeleton conventions (identity axes, 3-channel Euler joints).

An ASF skeleton gives each joint a rest-frame rotation ``C`` (its ``axis``) and lets the
joint's rotation dofs act in that frame: ``local = C @ R(dofs) @ C.T``, with 0 to 3
rotation dofs composed in reversed listed order.  A BVH skeleton has identity axes and
every joint carries three rotation channels composed in listed order.  Both put offsets
and end sites in world-aligned rest frames, so converting only needs new channel values:
the Euler angles, in the target order, of each joint's local matrix.
"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
from scipy.spatial.transform import Rotation

from .errors import ParameterError
from .motion import Motion
from .skeleton import Joint, Skeleton

__all__ = ["to_bvh_convention", "local_rotations", "continuous_euler"]

_AXIS_INDEX = {"x": 0, "y": 1, "z": 2}


def check_order(order: str) -> str:
    """``order`` upper-cased, checked to be a permutation of ``"XYZ"`` (ParameterError if not)."""
    up = str(order).upper()
    if len(up) != 3 or sorted(up) != ["X", "Y", "Z"]:
        raise ParameterError(
            f"rotation_order must be a permutation of XYZ such as 'ZXY', got {order!r}"
        )
    return up


def local_rotations(motion: Motion, skeleton: Skeleton | None = None) -> np.ndarray:
    """Each joint's local rotation matrix per frame, ``axis @ R(channels) @ axis.T``.

    Parameters
    ----------
    motion : Motion
        Frames ``(T, D)``; rotation dofs the motion lacks count as 0 degrees.
    skeleton : Skeleton, optional
        Defaults to ``motion.skeleton``.

    Returns
    -------
    ndarray, shape (J, T, 3, 3)
        Local rotations, joints in skeleton order (identity for joints without rotation
        dofs).
    """
    skel = skeleton if skeleton is not None else motion.skeleton
    if skel is None:
        raise ParameterError("this motion has no skeleton")
    T = motion.n_frames
    col = {c: i for i, c in enumerate(motion.channels)}
    out = np.empty((len(skel.joints), T, 3, 3))
    for i, j in enumerate(skel.joints):
        if not j.rotation_order:
            out[i] = np.eye(3)
            continue
        vals = np.zeros((T, len(j.rotation_order)))
        for k, ax in enumerate(j.rotation_order.lower()):
            c = col.get((j.name, "r" + ax))
            if c is not None:
                vals[:, k] = motion.frames[:, c]
        if T == 0:
            continue
        mats = Rotation.from_euler(j.rotation_order, vals, degrees=True).as_matrix()
        out[i] = j.axis @ mats @ j.axis.T
    return out


def continuous_euler(matrices: np.ndarray, order: str) -> np.ndarray:
    """Intrinsic Euler angles (degrees) of rotation matrices, kept continuous over time.

    Every rotation has two Tait-Bryan solutions, ``(a, b, c)`` and
    ``(a + 180, 180 - b, c + 180)``, each only defined up to multiples of 360 per angle.
    Frame 0 takes SciPy's principal solution; each later frame takes whichever
    solution, shifted by multiples of 360 per angle, lies closest to the previous frame.
    Long turns therefore grow past +-180 and a middle angle passing +-90 keeps going
    instead of flipping the other two by 180.

    Parameters
    ----------
    matrices : ndarray, shape (T, J, 3, 3)
        Rotations per frame and joint.
    order : str
        Intrinsic order, a permutation of ``"XYZ"``.

    Returns
    -------
    ndarray, shape (T, J, 3)
        Angles in ``order``, degrees.
    """
    order = check_order(order)
    mats = np.asarray(matrices, dtype=float)
    if mats.ndim != 4 or mats.shape[2:] != (3, 3):
        raise ParameterError(f"expected matrices of shape (T, J, 3, 3), got {mats.shape}")
    T, J = mats.shape[:2]
    if T == 0 or J == 0:
        return np.zeros((T, J, 3))
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*[Gg]imbal.*")
        principal = (
            Rotation.from_matrix(mats.reshape(-1, 3, 3))
            .as_euler(order, degrees=True)
            .reshape(T, J, 3)
        )
    alternate = principal + np.array([180.0, 0.0, 180.0])
    alternate[..., 1] = 180.0 - principal[..., 1]
    out = np.empty_like(principal)
    out[0] = principal[0]
    prev = principal[0]
    for t in range(1, T):
        a = principal[t]
        a = a + 360.0 * np.round((prev - a) / 360.0)
        b = alternate[t]
        b = b + 360.0 * np.round((prev - b) / 360.0)
        use_b = np.abs(b - prev).sum(axis=-1) < np.abs(a - prev).sum(axis=-1)
        prev = np.where(use_b[:, None], b, a)
        out[t] = prev
    return out


def to_bvh_convention(motion: Motion, rotation_order: str = "ZXY") -> Motion:
    """Re-express a motion on an equivalent BVH-convention skeleton.

    Every joint gets an identity axis and three rotation channels in
    ``rotation_order`` (listed, i.e. composed, in that order); the root also gets
    ``tx ty tz`` (its own values, or its offset components where it has none), other
    joints keep the translation dofs they have.  Offsets and end sites are unchanged.
    Channel values are the Euler angles of each joint's local matrix
    ``axis @ R @ axis.T``, made continuous over time (see :func:`continuous_euler`), so
    forward kinematics gives the same positions as the input.

    Parameters
    ----------
    motion : Motion
        A motion with a skeleton in any convention (ASF axes, 0-3 rotation dofs per
        joint, any rotation order).
    rotation_order : str
        Intrinsic order for every joint, a permutation of ``"XYZ"`` (case-insensitive,
        read as the BVH listing order); default ``"ZXY"``.

    Returns
    -------
    Motion
        Frames ``(T, D')`` with channels in skeleton order, a skeleton with
        ``source_format="bvh"``; rate, source, start frame and metadata are kept.

    Raises
    ------
    ParameterError
        If the motion has no skeleton or ``rotation_order`` is not a permutation of XYZ.
    """
    order = check_order(rotation_order)
    skel = motion.skeleton
    if skel is None:
        raise ParameterError("converting to BVH conventions needs a skeleton; this motion has none")
    T = motion.n_frames
    col = {c: i for i, c in enumerate(motion.channels)}
    local = local_rotations(motion, skel)  # (J, T, 3, 3)
    angles = continuous_euler(local.transpose(1, 0, 2, 3), order)  # (T, J, 3)
    rot_dofs = tuple("r" + a.lower() for a in order)

    joints: list[Joint] = []
    columns: list[np.ndarray] = []
    channels: list[tuple[str, str]] = []
    for i, j in enumerate(skel.joints):
        if i == 0:
            t_dofs: tuple[str, ...] = ("tx", "ty", "tz")
        else:
            t_dofs = tuple(d for d in ("tx", "ty", "tz") if d in j.dofs)
        for d in t_dofs:
            k = col.get((j.name, d)) if d in j.dofs else None
            if k is not None:
                columns.append(motion.frames[:, k])
            else:
                columns.append(np.full(T, j.offset[_AXIS_INDEX[d[1]]]))
            channels.append((j.name, d))
        for a, d in enumerate(rot_dofs):
            columns.append(angles[:, i, a])
            channels.append((j.name, d))
        joints.append(
            Joint(
                name=j.name,
                parent=j.parent,
                offset=j.offset.copy(),
                dofs=t_dofs + rot_dofs,
                rotation_order=order,
                axis=np.eye(3),
                end_site=None if j.end_site is None else j.end_site.copy(),
            )
        )
    new_skel = Skeleton(
        joints=tuple(joints),
        name=skel.name,
        length_unit=skel.length_unit,
        source_format="bvh",
    )
    frames = np.column_stack(columns) if columns else np.zeros((T, 0))
    return replace(
        motion,
        frames=frames,
        channels=tuple(channels),
        skeleton=new_skel,
        metadata=dict(motion.metadata),
    )
