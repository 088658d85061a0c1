"""The root of a loop: what must close (tilt, height) and what may travel (heading, ground).

A walk's root moves forward and may turn, so its translation and heading are not
periodic; its height, pitch and roll are.  :func:`decompose_root` splits the root of every
frame into

* *periodic* features, kept absolute: height (the up coordinate) and tilt (the rotation
  left once the heading is taken out, as a rotation vector in degrees);
* *travel* features, kept as per-frame changes: the heading's change (degrees per frame,
  about the vertical) and the ground step expressed in the heading's frame.

Averaged over repetitions, the periodic features close exactly (a loop's first and last
frames lean the same way), and the travel features give the mean heading change and
ground step of one cycle.  :func:`compose_root` rebuilds root channel values from them,
optionally without the heading change (a cycle that walks straight) or without travel
(in place).  The up axis is y and the heading is the direction of the root's local z
axis projected on the ground, as in the CMU ASF convention.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ..motion import Motion

__all__ = [
    "RootLayout",
    "root_layout",
    "root_rotations",
    "decompose_root",
    "compose_root",
    "heading",
]

_AXES = "xyz"


@dataclass(frozen=True)
class RootLayout:
    """Where a motion keeps its root and how the root's rotation is written.

    Attributes
    ----------
    columns : ndarray of int, shape (6,)
        Channel indices of the root's dofs.
    dofs : list of str
        The dof of each column (``"tx"`` ... ``"rz"``).
    order : str
        Euler rotation order of the root (e.g. ``"XYZ"``).
    axis : ndarray, shape (3, 3)
        The root's joint axis matrix (ASF ``axis``; identity for BVH).
    """

    columns: np.ndarray
    dofs: list
    order: str
    axis: np.ndarray

    def column(self, dof: str) -> int:
        return int(self.columns[self.dofs.index(dof)])


def root_layout(motion: Motion) -> RootLayout | None:
    """The root layout of a motion, or None unless the root has six dofs and a skeleton."""
    sk = motion.skeleton
    cols = np.asarray(motion.root_channels(), dtype=int)
    if sk is None or cols.size != 6:
        return None
    root = sk.joints[0]
    dofs = [motion.channels[c][1] for c in cols]
    if (
        sorted(dofs) != sorted(["tx", "ty", "tz", "rx", "ry", "rz"])
        or len(root.rotation_order) != 3
    ):
        return None
    return RootLayout(
        columns=cols, dofs=dofs, order=root.rotation_order, axis=np.asarray(root.axis, dtype=float)
    )


def root_rotations(frames: np.ndarray, layout: RootLayout) -> np.ndarray:
    """World rotation matrices of the root, shape (T, 3, 3)."""
    vals = np.column_stack([frames[:, layout.column("r" + a.lower())] for a in layout.order])
    local = Rotation.from_euler(layout.order, vals, degrees=True).as_matrix()
    return layout.axis @ local @ layout.axis.T


def _yaw_matrices(h: np.ndarray) -> np.ndarray:
    c, s = np.cos(np.radians(h)), np.sin(np.radians(h))
    out = np.zeros((h.size, 3, 3))
    out[:, 0, 0] = c
    out[:, 0, 2] = s
    out[:, 1, 1] = 1.0
    out[:, 2, 0] = -s
    out[:, 2, 2] = c
    return out


def heading(frames: np.ndarray, layout: RootLayout) -> np.ndarray:
    """Heading of the root per frame in degrees, continuous in time (unwrapped)."""
    R = root_rotations(np.asarray(frames, dtype=float), layout)
    fwd = R[:, :, 2]
    h = np.degrees(np.arctan2(fwd[:, 0], fwd[:, 2]))
    return np.degrees(np.unwrap(np.radians(h)))


def decompose_root(frames: np.ndarray, layout: RootLayout) -> np.ndarray:
    """Root features per frame: ``[height, tilt (3), heading step, ground step (2)]``.

    Parameters
    ----------
    frames : ndarray, shape (T, D)
        Channel values of a motion (root rotations in degrees).
    layout : RootLayout

    Returns
    -------
    ndarray, shape (T, 7)
        Column 0: height (the root's y); 1-3: tilt as a rotation vector in degrees (the
        root's rotation with its heading removed); 4: heading change to the next frame
        in degrees; 5-6: ground step to the next frame in the heading's frame (sideways
        x, forward z).  The last frame repeats the previous frame's changes.
    """
    f = np.asarray(frames, dtype=float)
    R = root_rotations(f, layout)
    h = heading(f, layout)
    yaw = _yaw_matrices(h)
    tilt = Rotation.from_matrix(np.einsum("tji,tjk->tik", yaw, R)).as_rotvec(degrees=True)
    pos = np.column_stack([f[:, layout.column(t)] for t in ("tx", "ty", "tz")])
    out = np.empty((len(f), 7))
    out[:, 0] = pos[:, 1]
    out[:, 1:4] = tilt
    if len(f) > 1:
        dpos = np.diff(pos, axis=0)
        local = np.einsum("tji,tj->ti", yaw[:-1], dpos)
        out[:-1, 4] = np.diff(h)
        out[:-1, 5] = local[:, 0]
        out[:-1, 6] = local[:, 2]
        out[-1, 4:] = out[-2, 4:]
    else:
        out[:, 4:] = 0.0
    return out


def compose_root(
    features: np.ndarray,
    layout: RootLayout,
    start_heading: float,
    start_ground: tuple[float, float],
    *,
    travel: str = "keep",
) -> np.ndarray:
    """Root channel values from per-frame features (the inverse of :func:`decompose_root`).

    Parameters
    ----------
    features : ndarray, shape (P, 7)
        As returned by :func:`decompose_root` (typically averaged over repetitions).
    layout : RootLayout
    start_heading : float
        Heading of the first frame in degrees.
    start_ground : (float, float)
        Ground position (x, z) of the first frame.
    travel : {"keep", "straight", "in_place"}
        ``"keep"``: heading and ground steps as given (a cycle that turns as the capture
        did); ``"straight"``: the mean heading change removed, so the loop walks along a
        line; ``"in_place"``: no heading change and no ground travel.

    Returns
    -------
    ndarray, shape (P, 6)
        Values for ``layout.columns`` (rotations in degrees, continuous in time).
    """
    x = np.asarray(features, dtype=float)
    P = x.shape[0]
    dh = x[:, 4].copy()
    step = x[:, 5:7].copy()
    if travel in ("straight", "in_place"):
        dh -= dh.mean()
    if travel == "in_place":
        step[:] = 0.0
    h = float(start_heading) + np.concatenate([[0.0], np.cumsum(dh[:-1])])
    yaw = _yaw_matrices(h)
    world = np.einsum("tij,tj->ti", yaw, np.column_stack([step[:, 0], np.zeros(P), step[:, 1]]))
    ground = np.asarray(start_ground, dtype=float) + np.vstack(
        [[0.0, 0.0], np.cumsum(world[:-1][:, [0, 2]], axis=0)]
    )
    R = yaw @ Rotation.from_rotvec(x[:, 1:4], degrees=True).as_matrix()
    local = np.einsum("ji,tjk,kl->til", layout.axis, R, layout.axis)
    ang = Rotation.from_matrix(local).as_euler(layout.order, degrees=True)
    ang = np.degrees(np.unwrap(np.radians(ang), axis=0))
    out = np.empty((P, 6))
    for k, a in enumerate(layout.order.lower()):
        out[:, layout.dofs.index("r" + a)] = ang[:, k]
    out[:, layout.dofs.index("tx")] = ground[:, 0]
    out[:, layout.dofs.index("ty")] = x[:, 0]
    out[:, layout.dofs.index("tz")] = ground[:, 1]
    return out


def planted_ground(
    clip: Motion,
    layout: RootLayout,
    points: list[str] | tuple[str, ...],
    weights: np.ndarray,
) -> np.ndarray:
    """Root ground positions that keep the planted foot points of a clip still.

    A walk cycle averaged over repetitions moves its feet relative to the root by the
    average stride, while its root travels by the average ground step; the two disagree
    (and more so once the strides are widened to their typical amplitude), so the
    planted foot slides.  Here the root follows the feet instead, as an animator does
    when extracting root motion: on each step from frame t to t+1 the root moves by
    minus the horizontal displacement, relative to the root, of the points that are
    planted, weighted by how surely they are; the weights' shortfall from 1 (a flight
    phase) takes the clip's own ground step.

    Parameters
    ----------
    clip : Motion
        The cycle with its composed root (heading and tilt as they will be written).
    layout : RootLayout
    points : sequence of str
        Foot point joint names (e.g. ``lfoot ltoes rfoot rtoes``).
    weights : ndarray, shape (P, F)
        How surely each point is planted on each frame, in ``[0, 1]``.

    Returns
    -------
    ndarray, shape (P, 2)
        Values for the root's ``tx`` and ``tz`` channels (y up), the first frame's kept.
    """
    pos = clip.positions()
    cols = [pos.names.index(p) for p in points]
    root = pos.positions[:, 0, :][:, [0, 2]]
    rel = pos.positions[:, cols][:, :, [0, 2]] - root[:, None, :]  # (P, F, 2)
    w = np.clip(np.asarray(weights, dtype=float), 0.0, 1.0)
    w = 0.5 * (w[1:] + w[:-1])  # a step's weight: the mean of its two frames
    total = w.sum(axis=1, keepdims=True)
    share = np.where(total > 1.0, w / np.maximum(total, 1e-12), w)
    free = 1.0 - share.sum(axis=1, keepdims=True)
    own = np.diff(root, axis=0)
    follow = -np.einsum("tf,tfk->tk", share, np.diff(rel, axis=0))
    steps = follow + free * own
    tx, tz = layout.column("tx"), layout.column("tz")
    # the root channels' translation reaches the world unscaled in ASF and BVH alike, but
    # measure it rather than assume it
    scale = 1.0
    moved = clip.frames[:1].copy()
    moved[0, tx] += 1.0
    probe = clip.with_frames(np.vstack([clip.frames[:1], moved])).positions().positions[:, 0, 0]
    if abs(probe[1] - probe[0]) > 1e-9:
        scale = float(probe[1] - probe[0])
    start = clip.frames[0, [tx, tz]]
    return start + np.vstack([[0.0, 0.0], np.cumsum(steps, axis=0)]) / scale
