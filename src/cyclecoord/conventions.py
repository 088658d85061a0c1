"""Re-express a motion in BVH skeleton conventions (identity axes, 3-channel Euler joints).

An ASF skeleton gives each joint a rest-frame rotation ``C`` (its ``axis``) and lets the
joint's rotation dofs act in that frame: ``local = C @ R(dofs) @ C.T``, with 0 to 3
rotation dofs composed in reversed listed order.  A BVH skeleton has identity axes and
every joint carries three rotation channels composed in listed order.  Both put offsets
and end sites in world-aligned rest frames, so converting only needs new channel values:
the Euler angles, in the target order, of each joint's local matrix.

:func:`continuous_euler` keeps Euler angles continuous over time;
:func:`in_conventions_of` and :func:`common_channels` write motions of one skeleton
captured in different conventions (an AMC capture, a BVH cycle) with one set of
channels, so that equal channels mean equal joint rotations.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from typing import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from .errors import ParameterError
from .motion import Motion
from .skeleton import AXIS_INDEX, Joint, Skeleton

__all__ = [
    "to_bvh_convention",
    "local_rotations",
    "continuous_euler",
    "continuous_channels",
    "nearest_rotations",
    "check_order",
    "wrap_degrees",
    "in_conventions_of",
    "common_channels",
]


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


def nearest_rotations(mats: np.ndarray) -> np.ndarray:
    """The rotation nearest each matrix ``(T, 3, 3)`` (a weighted mean of rotations, such
    as a latent model's root tilt mixed over training frames), never a reflection."""
    U, _, Vt = np.linalg.svd(mats)
    U[:, :, 2] *= np.sign(np.linalg.det(U @ Vt))[:, None]
    return U @ Vt


def continuous_euler(
    matrices: np.ndarray, order: str, near: np.ndarray | None = None
) -> np.ndarray:
    """Intrinsic Euler angles (degrees) of rotation matrices, kept continuous over time.

    Every rotation has two Tait-Bryan solutions, ``(a, b, c)`` and
    ``(a + 180, 180 - b, c + 180)``, each only defined up to multiples of 360 per angle.
    Frame 0 takes SciPy's principal solution (or, given ``near``, the solution nearest
    ``near``); each later frame takes whichever solution, shifted by multiples of 360 per
    angle, lies closest to the previous frame.
    Long turns therefore grow past +-180 and a middle angle passing +-90 keeps going
    instead of flipping the other two by 180.

    Parameters
    ----------
    matrices : ndarray, shape (T, J, 3, 3)
        Rotations per frame and joint.
    order : str
        Intrinsic order, a permutation of ``"XYZ"``.
    near : array_like, shape (J, 3) or (3,), optional
        Angles (degrees, in ``order``) the first frame's solution should lie closest to.

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
    if near is None:
        out[0] = prev = principal[0]
        start = 1
    else:
        prev = np.broadcast_to(np.asarray(near, dtype=float), (J, 3))
        start = 0
    if J <= _SCALAR_JOINTS:
        _continue_scalar(principal, alternate, out, np.asarray(prev, dtype=float), start)
        return out
    for t in range(start, T):
        a = principal[t]
        a = a + 360.0 * np.round((prev - a) / 360.0)
        b = alternate[t]
        b = b + 360.0 * np.round((prev - b) / 360.0)
        use_b = np.abs(b - prev).sum(axis=-1) < np.abs(a - prev).sum(axis=-1)
        prev = np.where(use_b[:, None], b, a)
        out[t] = prev
    return out


#: Up to this many joints, :func:`continuous_euler` walks the frames in plain Python
#: floats: the same choices, five to ten times faster than a dozen NumPy calls on
#: three values a frame (a latent script makes some twenty such one-joint calls).
_SCALAR_JOINTS = 2


def _continue_scalar(
    principal: np.ndarray, alternate: np.ndarray, out: np.ndarray, prev: np.ndarray,
    start: int,
) -> None:
    """:func:`continuous_euler`'s frame loop, joint by joint, on Python floats."""
    P, A = principal.tolist(), alternate.tolist()
    for j in range(principal.shape[1]):
        p0, p1, p2 = (float(v) for v in prev[j])
        for t in range(start, principal.shape[0]):
            a0, a1, a2 = P[t][j]
            a0 += 360.0 * round((p0 - a0) / 360.0)
            a1 += 360.0 * round((p1 - a1) / 360.0)
            a2 += 360.0 * round((p2 - a2) / 360.0)
            b0, b1, b2 = A[t][j]
            b0 += 360.0 * round((p0 - b0) / 360.0)
            b1 += 360.0 * round((p1 - b1) / 360.0)
            b2 += 360.0 * round((p2 - b2) / 360.0)
            to_b = abs(b0 - p0) + abs(b1 - p1) + abs(b2 - p2)
            if to_b < abs(a0 - p0) + abs(a1 - p1) + abs(a2 - p2):
                p0, p1, p2 = b0, b1, b2
            else:
                p0, p1, p2 = a0, a1, a2
            out[t, j] = (p0, p1, p2)


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
                columns.append(np.full(T, j.offset[AXIS_INDEX[d[1]]]))
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


# ------------------------------------------ one skeleton in another's conventions
def wrap_degrees(x: np.ndarray) -> np.ndarray:
    """Angles wrapped into [-180, 180) degrees."""
    return (np.asarray(x, dtype=float) + 180.0) % 360.0 - 180.0


def check_same_channels(have: Sequence, want: Sequence, name: str) -> None:
    if set(have) != set(want) or len(have) != len(want):
        missing = sorted(set(want) - set(have))[:4]
        extra = sorted(set(have) - set(want))[:4]
        raise ParameterError(
            f"{name} does not have the same channels as the reference cycle "
            f"(missing {missing}, extra {extra})"
        )


def bvh_ready(skeleton) -> str | None:
    """The shared Euler order when every joint is BVH-style (identity axis, 3 rotations)."""
    orders = {j.rotation_order for j in skeleton.joints}
    if len(orders) == 1 and all(np.allclose(j.axis, np.eye(3)) for j in skeleton.joints):
        order = orders.pop()
        return order if len(order) == 3 else None
    return None


def _reexpress(motion: Motion, conventions) -> Motion:
    """``motion`` with another skeleton's joint conventions (axis, dofs, Euler order).

    Each joint keeps its own offset and end site; its local rotation is written with
    the conventions' axis ``C`` and rotation dofs: ``C.T @ local @ C`` decomposed in the
    joint's order, with the missing axes placed so that a rotation the dofs can make is
    recovered exactly (a hinge stays a hinge); what they cannot make is dropped.
    """
    skel = motion.skeleton
    local = local_rotations(motion)  # (J, T, 3, 3)
    col = {c: i for i, c in enumerate(motion.channels)}
    T = motion.n_frames
    joints, columns, channels = [], [], []
    for i, (mine, conv) in enumerate(zip(skel.joints, conventions.joints)):
        order = conv.rotation_order
        t_dofs = [d for d in conv.dofs if d.startswith("t")]
        values = {}
        for d in t_dofs:
            k = col.get((mine.name, d))
            values[d] = (
                motion.frames[:, k] if k is not None else np.full(T, mine.offset["xyz".index(d[1])])
            )
        if order:
            missing = [a for a in "XYZ" if a not in order]
            full = (
                order[0] + "".join(missing) + order[1:]
                if len(order) == 2
                else order + "".join(missing)
            )
            keep = [0, 2] if len(order) == 2 else list(range(len(order)))
            rel = conv.axis.T @ local[i] @ conv.axis
            angles = continuous_euler(rel[:, None], full)[:, 0, keep]
            for a, ax in zip(angles.T, order.lower()):
                values["r" + ax] = a
        for d in conv.dofs:
            columns.append(values[d])
            channels.append((mine.name, d))
        joints.append(
            Joint(
                name=mine.name,
                parent=mine.parent,
                offset=mine.offset.copy(),
                dofs=tuple(conv.dofs),
                rotation_order=order,
                axis=conv.axis.copy(),
                end_site=None if mine.end_site is None else mine.end_site.copy(),
                limits=dict(conv.limits),
            )
        )
    new = Skeleton(
        joints=tuple(joints),
        name=skel.name,
        length_unit=skel.length_unit,
        source_format=conventions.source_format,
    )
    frames = np.column_stack(columns) if columns else np.zeros((T, 0))
    return replace(motion, frames=frames, channels=tuple(channels), skeleton=new)


def _same_conventions(a, b) -> bool:
    """Same joints with the same axes, dofs and Euler orders."""
    return a.names == b.names and all(
        x.dofs == y.dofs and x.rotation_order == y.rotation_order and np.allclose(x.axis, y.axis)
        for x, y in zip(a.joints, b.joints)
    )


def _match_branches(motion: Motion, target: Motion) -> Motion:
    """Per joint, the Euler solution closest to ``target``'s angles.

    Three Euler angles ``(a, b, c)`` and ``(a + 180, 180 - b, c + 180)`` give the same
    rotation; two motions written on different solutions would blend into nonsense.
    For every joint but the root with three rotation channels, the whole sequence is
    moved to the solution (and whole turns) nearest the target's mean angles.
    """
    if motion.skeleton is None:
        return motion
    frames = np.array(motion.frames, dtype=float)
    changed = False
    for j in motion.skeleton.joints[1:]:  # the root's heading is matched by turning instead
        if len(j.rotation_order) != 3:
            continue
        chans = [(j.name, "r" + ax.lower()) for ax in j.rotation_order]
        if not all(c in target.channels for c in chans):
            continue
        cols = [motion.channel_index(*c) for c in chans]
        goal = np.array([np.mean(target.frames[:, target.channel_index(*c)]) for c in chans])
        x = frames[:, cols]
        alt = x + np.array([180.0, 0.0, 180.0])
        alt[:, 1] = 180.0 - x[:, 1]

        def nearest(v: np.ndarray) -> tuple[np.ndarray, float]:
            v = v - 360.0 * np.round((v.mean(axis=0) - goal) / 360.0)
            return v, float(
                np.abs(wrap_degrees(v - goal)).sum() + 1e-9 * np.abs(v.mean(axis=0) - goal).sum()
            )

        x1, d1 = nearest(x)
        x2, d2 = nearest(alt)
        best = x2 if d2 < d1 else x1
        if not np.array_equal(best, x):
            frames[:, cols] = best
            changed = True
    return motion.with_frames(frames) if changed else motion


#: A frame-to-frame step in an Euler channel over this (degrees) is a wrap or a flip.
JUMP_DEGREES = 90.0


def continuous_channels(motion: Motion) -> Motion:
    """``motion`` with each joint's Euler channels continuous over frames.

    Joints with three rotation channels whose values jump by more than
    :data:`JUMP_DEGREES` between two frames (a wrap past +-180, a flip to the other
    Tait-Bryan solution) are rewritten with :func:`continuous_euler`, starting from the
    first frame's own solution: the same rotations, numbers that never jump.  Other joints
    keep their values exactly (a motion without jumps is returned as it is).

    Parameters
    ----------
    motion : Motion
        With a skeleton (without one, the motion is returned unchanged).

    Returns
    -------
    Motion
    """
    sk = motion.skeleton
    if sk is None or motion.n_frames < 2:
        return motion
    frames = None
    for j in sk.joints:
        order = j.rotation_order
        if len(order) != 3:
            continue
        cols = [motion.channels.index((j.name, "r" + a.lower()))
                if (j.name, "r" + a.lower()) in motion.channels else -1 for a in order]
        if min(cols) < 0:
            continue
        vals = motion.frames[:, cols]
        if np.abs(np.diff(vals, axis=0)).max() <= JUMP_DEGREES:
            continue
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=".*[Gg]imbal.*")
            mats = Rotation.from_euler(order, vals, degrees=True).as_matrix()
        if frames is None:
            frames = np.array(motion.frames, dtype=float)
        frames[:, cols] = continuous_euler(mats[:, None], order, vals[0])[:, 0]
    return motion if frames is None else motion.with_frames(frames)


def in_conventions_of(motion: Motion, template: Motion) -> Motion:
    """``motion`` written with ``template``'s channels (same joints, other conventions).

    Returns ``motion`` itself when the channels already match (reordered if needed) or
    the skeletons do not have the same joints.
    """
    if set(motion.channels) == set(template.channels) and motion.n_channels == template.n_channels:
        return motion if motion.channels == template.channels else motion.select(template.channels)
    sk, tk = motion.skeleton, template.skeleton
    if sk is None or tk is None or sk.names != tk.names or _same_conventions(sk, tk):
        return motion
    out = _match_branches(_reexpress(motion, tk), template)
    return out.select(template.channels) if set(out.channels) == set(template.channels) else out


def common_channels(motions: Sequence[Motion]) -> list[Motion]:
    """The motions with one set of channels, in one order.

    Motions whose channels are the same set are only reordered to the first one's.
    Motions of skeletons with the same joints written in different conventions (an
    ASF/AMC capture and a BVH cycle :func:`cyclecoord.extract` wrote: ASF axes and 1-3
    rotations per joint against identity axes and 3 Euler angles) are re-expressed in
    one convention so that equal channels mean equal joint rotations: the first
    ASF-style input's (anatomical axes, hinges stay hinges, which blend better), or the
    first input's Euler order when all are BVH-style.

    Raises
    ------
    ParameterError
        When the channels differ and the skeletons do not have the same joints.
    """
    motions = list(motions)
    ref = motions[0]
    if all(
        set(m.channels) == set(ref.channels) and m.n_channels == ref.n_channels for m in motions
    ):
        return [m if m.channels == ref.channels else m.select(ref.channels) for m in motions]
    skels = [m.skeleton for m in motions]
    if (
        any(sk is None for sk in skels)
        or any(sk.names != skels[0].names for sk in skels)
        or all(_same_conventions(sk, skels[0]) for sk in skels)
    ):
        for i, m in enumerate(motions[1:], start=1):
            check_same_channels(m.channels, ref.channels, f"cycle {i}")
    asf = [i for i, sk in enumerate(skels) if bvh_ready(sk) is None]
    if asf:
        anchor = motions[asf[0]]
        out = [
            m if m.skeleton is anchor.skeleton else _reexpress(m, anchor.skeleton) for m in motions
        ]
    else:
        order = bvh_ready(skels[0])
        anchor = motions[0]
        out = [
            m if bvh_ready(m.skeleton) == order else to_bvh_convention(m, order) for m in motions
        ]
    # converted motions take the Euler solutions nearest the unconverted anchor's
    out = [m if m is orig else _match_branches(m, anchor) for m, orig in zip(out, motions)]
    first = out[0].channels
    return [m if m.channels == first else m.select(first) for m in out]
