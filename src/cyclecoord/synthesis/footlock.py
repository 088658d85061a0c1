"""Foot locking: pin planted feet in place with a small inverse-kinematics fix of each leg.

For every contact (a run of frames where a foot point is planted, from
:func:`cyclecoord.quality.contacts.foot_contacts`) the point's horizontal position is
fixed at its mean over the run; a window of ``blend`` seconds on each side eases the point
from its captured path into the lock and out again (``target = orig + w (lock - orig)``
with a smoothstep ``w``), so the foot decelerates instead of jumping.  Each leg's rotation
channels from the hip down to the foot (thigh, shin, foot: six degrees of freedom on a CMU
skeleton) are then solved frame by frame, all frames at once, by damped Gauss-Newton with
a small pull towards the captured angles.  Only frames with a target are touched and only
the leg chains change: the root, spine, arms and the toes' own rotation keep their values.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ..quality.contacts import (
    FootContacts,
    FootSkating,
    contact_runs,
    contact_skeleton,
    foot_contacts,
    foot_skating,
)
from ..skeleton import Skeleton, rotation_matrices

__all__ = ["FootLockResult", "lock_feet"]

#: Weight of the captured angles (per radian) relative to target errors (per leg length).
_REGULARISATION = 1e-3
#: Weight of the height of a locked point, and of the horizontal position of a free one.
_SOFT = 0.05


@dataclass(frozen=True)
class FootLockResult:
    """A motion with its feet locked, and what that changed.

    Attributes
    ----------
    motion : Motion
        The edited motion (same channels, rate and skeleton).
    contacts : FootContacts
        The contacts that were locked (found on the input motion).
    before, after : FootSkating
        Foot skating of the input and of the output, both measured on ``contacts``.
    after_redetected : FootSkating
        Foot skating of the output with contacts found afresh on it.
    joint_change : dict of str to float
        Mean angle (degrees, over frames) between each joint's input and output local
        rotation; every joint is listed (zero for joints outside the legs).
    max_error : float
        Largest horizontal distance (length units) between a locked point and its lock.
    """

    motion: Motion
    contacts: FootContacts
    before: FootSkating
    after: FootSkating
    after_redetected: FootSkating
    joint_change: dict = field(default_factory=dict)
    max_error: float = 0.0

    @property
    def mean_joint_change(self) -> float:
        """Mean over all joints of :attr:`joint_change` (degrees)."""
        return float(np.mean(list(self.joint_change.values()))) if self.joint_change else 0.0

    def summary(self) -> str:
        legs = {k: v for k, v in self.joint_change.items() if v > 0}
        worst = max(legs.items(), key=lambda kv: kv[1]) if legs else ("-", 0.0)
        return (
            f"foot locking: skating frames {self.before.skating_frames} -> "
            f"{self.after.skating_frames} (re-detected contacts: "
            f"{self.after_redetected.skating_frames}); joints changed {len(legs)}, "
            f"mean over all joints {self.mean_joint_change:.3f} deg, most {worst[0]} "
            f"{worst[1]:.2f} deg; lock error {self.max_error:.2g}"
        )


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def _lock_weights(planted: np.ndarray, nb: int, cyclic: bool):
    """Weights ``(T,)`` easing into each run, the run label of each frame (-1: none), the
    runs and the frame shift of the timeline they index.

    A frame gets the label of its nearest run within ``nb + 1`` frames, ``w = 1`` inside
    runs and on the frame either side, then a smoothstep down to 0 over ``nb`` frames.
    A cyclic motion is tiled three times so runs and blends wrap around; the middle copy
    is returned.
    """
    T = planted.size
    reps = 3 if cyclic else 1
    ext = np.tile(planted, reps)
    runs = contact_runs(ext)
    label = -np.ones(ext.size, dtype=int)
    dist = np.full(ext.size, np.inf)
    idx = np.arange(ext.size)
    for k, (a, b) in enumerate(runs):
        d = np.where(idx < a, a - idx, np.where(idx >= b, idx - b + 1, 0)).astype(float)
        closer = d < dist
        dist[closer] = d[closer]
        label[closer] = k
    # the frame either side of a run is held too, so central differences (speeds) on the
    # run's own frames see the pinned position only
    w = np.where(dist <= 1, 1.0, _smoothstep(1.0 - (dist - 1) / (nb + 1)))
    label[w <= 0] = -1
    if cyclic:
        return w[T : 2 * T], label[T : 2 * T], runs, T
    return w, label, runs, 0


def _next_loop(points: np.ndarray, loop, shift) -> np.ndarray:
    """Positions moved by ``loop`` loops of a travelling cycle.

    ``shift`` is ``(origin (3,), step (3,), turn (degrees), up)``: the next loop is this one
    turned by ``turn`` about the vertical through ``origin`` and moved by ``step``.
    """
    origin, step, turn, up = shift
    out = np.array(points, dtype=float)
    a, b = [k for k in range(3) if k != up]
    for c in (-1, 1):
        rows = loop == c
        if not rows.any():
            continue
        ang = np.radians(turn * c)
        ca, sa = np.cos(ang), np.sin(ang)
        if c == 1:
            rel = out[rows] - origin
            x, z = rel[:, b], rel[:, a]
            out[rows, a] = origin[a] + sa * x + ca * z + step[a]
            out[rows, b] = origin[b] + ca * x - sa * z + step[b]
        else:
            # the inverse: undo the step, then turn back
            rel = out[rows] - origin - step
            x, z = rel[:, b], rel[:, a]
            out[rows, a] = origin[a] + sa * x + ca * z
            out[rows, b] = origin[b] + ca * x - sa * z
    return out


def _loop_shift(root: np.ndarray, rot: np.ndarray, up: int) -> tuple:
    """How a travelling loop's next repetition sits: ``(origin, step, turn, up)``.

    Extrapolated from the root's first and last frames: the step and the heading turn
    (about the vertical, degrees; with y up, from the root's z axis) of ``T`` frames.
    """
    T = root.shape[0]
    k = T / max(T - 1, 1)
    step = (root[-1] - root[0]) * k
    step[up] = 0.0
    turn = 0.0
    if up == 1:
        h = np.degrees(np.arctan2(rot[:, 0, 2], rot[:, 2, 2]))
        turn = float((np.degrees(np.unwrap(np.radians(h)))[-1] - h[0]) * k)
    return root[0].astype(float), step, turn, up


def _targets(
    points: np.ndarray,
    planted: np.ndarray,
    up: int,
    nb: int,
    cyclic: bool,
    loop_shift: tuple | None = None,
):
    """Targets ``(T, 3)`` (horizontal components eased into locks), weights ``(T,)`` and run
    labels for one foot point.

    A cyclic motion that travels moves by ``loop_shift`` from one loop to the next: a
    contact that runs across the seam reads the frames of the neighbouring loop there
    (its own frames shifted by it), not the far end of this one.
    """
    T = planted.size
    horiz = [k for k in range(3) if k != up]
    w, label, runs, shift = _lock_weights(planted, nb, cyclic)
    target = points.copy()
    locks = {}
    for k in np.unique(label[label >= 0]):
        a, b = runs[k]
        frames = np.arange(a, b) - shift
        if cyclic:
            loop = np.floor_divide(frames, T)  # -1, 0 or 1: the loop before, this one, the next
            frames = np.mod(frames, T)
            pos = points[frames]
            if loop_shift is not None:
                pos = _next_loop(pos, loop, loop_shift)
            locks[k] = pos[:, horiz].mean(axis=0)
        else:
            locks[k] = points[frames][:, horiz].mean(axis=0)
    for t in np.flatnonzero(label >= 0):
        lock = locks[label[t]]
        target[t, horiz] = points[t, horiz] + w[t] * (lock - points[t, horiz])
    return target, np.where(label >= 0, w, 0.0), label


def _chain(skel: Skeleton, ankle: int, deepest: int) -> list[int]:
    """Joints from the thigh (the ankle's grandparent) down to ``deepest``'s parent."""
    path = []
    j = skel.joints[deepest].parent
    while j >= 0:
        path.append(j)
        if len(path) > 64:
            break
        j = skel.joints[j].parent
    thigh = skel.joints[skel.joints[ankle].parent].parent
    if thigh < 0 or thigh not in path:
        raise ParameterError(f"joint {skel.joints[ankle].name!r} has no thigh above it to solve")
    return list(reversed(path[: path.index(thigh) + 1]))


class _LegIK:
    """Forward kinematics of one leg chain as a function of its rotation channels."""

    def __init__(self, motion: Motion, chain: list[int], points: list[int], world_rot, world_pos):
        skel = motion.skeleton
        self.skel = skel
        self.chain = chain
        self.points = points
        col = {c: i for i, c in enumerate(motion.channels)}
        self.vars: list[tuple[int, int, int]] = []  # (chain position, order position, column)
        for ci, j in enumerate(chain):
            joint = skel.joints[j]
            for k, ax in enumerate(joint.rotation_order.lower()):
                c = col.get((joint.name, "r" + ax))
                if c is not None:
                    self.vars.append((ci, k, c))
        if not self.vars:
            raise ParameterError("the leg chain has no rotation channels to solve")
        parent = skel.joints[chain[0]].parent
        self.base_rot = world_rot[:, parent]
        self.base_pos = world_pos[:, parent]
        self.frames = np.asarray(motion.frames, float)

    def values(self) -> np.ndarray:
        return self.frames[:, [c for _, _, c in self.vars]].copy()

    def positions(self, q: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Positions ``(n, P, 3)`` of the foot points for variables ``q`` (n, V) on ``rows``."""
        skel = self.skel
        rot = self.base_rot[rows]
        pos = self.base_pos[rows]
        out = {}
        for ci, j in enumerate(self.chain + [None]):
            if j is None:
                break
            joint = skel.joints[j]
            pos = pos + np.einsum("tab,b->ta", rot, joint.offset)
            vals = np.zeros((len(rows), len(joint.rotation_order)))
            for v, (cj, k, c) in enumerate(self.vars):
                if cj == ci:
                    vals[:, k] = q[:, v]
            if joint.rotation_order:
                local = joint.axis @ rotation_matrices(vals, joint.rotation_order) @ joint.axis.T
                rot = rot @ local
            out[j] = (pos, rot)
        res = []
        for p in self.points:
            if p in out:
                res.append(out[p][0])
            else:  # a point one bone below the chain (the toe below the foot)
                pj = skel.joints[p]
                ppos, prot = out[pj.parent]
                res.append(ppos + np.einsum("tab,b->ta", prot, pj.offset))
        return np.stack(res, axis=1)


def _solve(ik: _LegIK, rows, targets, weights, scale, iterations=30):
    """Damped Gauss-Newton on all ``rows`` at once; returns the new variables (n, V)."""
    q0 = ik.values()[rows]
    q = q0.copy()
    reg = _REGULARISATION * scale * np.degrees(1.0) ** -1  # per degree
    eps = 1e-3

    def residual(qq):
        p = ik.positions(qq, rows)
        r = (p - targets) * weights
        return np.concatenate([r.reshape(len(rows), -1), reg * (qq - q0)], axis=1)

    mu = 1e-6 * scale**2
    for _ in range(iterations):
        r = residual(q)
        J = np.empty(r.shape + (q.shape[1],))
        for v in range(q.shape[1]):
            dq = q.copy()
            dq[:, v] += eps
            J[:, :, v] = (residual(dq) - r) / eps
        JT = np.swapaxes(J, 1, 2)
        A = JT @ J + mu * np.eye(q.shape[1])
        step = np.linalg.solve(A, -(JT @ r[..., None]))[..., 0]
        q = q + step
        if np.abs(step).max() < 1e-7:
            break
    return q


def _lock_once(
    motion: Motion, contacts: FootContacts, nb: int, cyclic: bool
) -> tuple[Motion, float]:
    """One locking pass: the edited motion and the largest horizontal lock error."""
    from .._kinematics import global_transforms, local_transforms

    skel = motion.skeleton
    trans, rots = local_transforms(motion)
    wpos, wrot = global_transforms(trans, rots, skel.parents)
    frames = np.array(motion.frames, dtype=float)
    scale = contacts.leg_length
    worst = 0.0
    for side in sorted(set(contacts.sides)):
        cols = [i for i, s in enumerate(contacts.sides) if s == side]
        pts = [skel.index(contacts.feet[i]) for i in cols]
        depth = {p: 0 for p in pts}
        for p in pts:
            j = p
            while skel.joints[j].parent >= 0:
                depth[p] += 1
                j = skel.joints[j].parent
        ankle = min(pts, key=lambda p: depth[p])
        deepest = max(pts, key=lambda p: depth[p])
        chain = _chain(skel, ankle, deepest)
        ik = _LegIK(motion, chain, pts, wrot, wpos)
        T = motion.n_frames
        targets = wpos[:, pts].copy()
        weights = np.full((T, len(pts), 3), _SOFT)
        active = np.zeros(T, bool)
        horiz = [k for k in range(3) if k != contacts.up]
        loop_shift = _loop_shift(wpos[:, 0], wrot[:, 0], contacts.up) if cyclic and T > 1 else None
        for m, i in enumerate(cols):
            tgt, _, label = _targets(
                wpos[:, pts[m]], contacts.planted[:, i], contacts.up, nb, cyclic, loop_shift
            )
            targets[:, m] = tgt
            locked = label >= 0
            for k in horiz:
                weights[locked, m, k] = 1.0
            active |= locked
        rows = np.flatnonzero(active)
        if rows.size == 0:
            continue
        q = _solve(ik, rows, targets[rows], weights[rows], scale)
        for v, (_, _, c) in enumerate(ik.vars):
            frames[rows, c] = q[:, v]
        new = ik.positions(q, rows)
        for m, i in enumerate(cols):
            lock_rows = contacts.planted[rows, i]
            if lock_rows.any():
                err = np.linalg.norm(
                    (new[lock_rows, m] - targets[rows][lock_rows, m])[:, horiz], axis=1
                )
                worst = max(worst, float(err.max()))
    return motion.with_frames(frames), worst


def lock_feet(
    motion: Motion,
    contacts: FootContacts | None = None,
    *,
    blend: float = 0.1,
    cyclic: bool = False,
    passes: int = 1,
    **contact_options,
) -> FootLockResult:
    """Remove foot skating by pinning planted feet and re-solving the legs.

    Parameters
    ----------
    motion : Motion
        A motion with a skeleton (CMU ASF, BVH, ...).
    contacts : FootContacts, optional
        Contacts to lock; found with :func:`foot_contacts` (and ``contact_options``)
        when not given.
    blend : float
        Seconds over which a foot eases into and out of each lock.
    cyclic : bool
        Treat the motion as a loop (a typical cycle): a contact running over the last
        frame continues at the first, and blends wrap around.
    passes : int
        Locking slows feet down near their contacts, so contacts found afresh on the
        result can be longer; up to ``passes`` rounds lock those too (each round solves
        the legs again from the previous round's result).

    Returns
    -------
    FootLockResult
    """
    from .._kinematics import local_transforms

    if not (np.isfinite(blend) and blend >= 0):
        raise ParameterError(f"blend must be >= 0 seconds, got {blend!r}")
    if contacts is None:
        contacts = foot_contacts(motion, **contact_options)
    else:
        contact_skeleton(motion)
    if contacts.n_frames != motion.n_frames:
        raise ParameterError(
            f"contacts cover {contacts.n_frames} frames, the motion has {motion.n_frames}"
        )
    nb = round(blend * motion.fps)
    out, worst = _lock_once(motion, contacts, nb, cyclic)
    locked = contacts
    for _ in range(max(0, int(passes) - 1)):
        again = foot_contacts(out, contacts.feet, **contact_options)
        extra = again.planted & ~locked.planted
        if not (foot_skating(out, again).skating & extra).any():
            break
        locked = replace(locked, planted=locked.planted | again.planted)
        out, worst = _lock_once(out, locked, nb, cyclic)
    _, rots = local_transforms(motion)
    _, rots2 = local_transforms(out)
    cosang = (np.einsum("tjab,tjab->tj", rots, rots2) - 1.0) / 2.0
    angle = np.degrees(np.arccos(np.clip(cosang, -1.0, 1.0)))
    angle = np.where(angle < 1e-4, 0.0, angle).mean(axis=0)  # arccos near 1: rounding noise
    return FootLockResult(
        motion=out,
        contacts=contacts,
        before=foot_skating(motion, contacts),
        after=foot_skating(out, contacts),
        after_redetected=foot_skating(out),
        joint_change=dict(zip(motion.skeleton.names, angle.tolist())),
        max_error=worst,
    )
