"""Foot locking: pin planted feet in place with a small inverse-kinematics fix of each leg.

For every contact (a run of frames where a foot point is planted, from
:func:`cyclecoord.quality.contacts.foot_contacts`) the point's horizontal position is
fixed at its mean over the run, and held there on the frame either side too.  The toe's
lock is placed where the ankle's lock carries it on the frames both rest flat, so the two
locks fit the rigid foot between them.  Over ``blend`` seconds on each side the point's
captured path is shifted towards the lock (``target = orig + w (lock - orig_held)`` with
a smoothstep ``w``), so it reaches and leaves the lock at its captured speed.

Each leg's rotation channels from the hip down to the foot (thigh, shin, foot: six
degrees of freedom on a CMU skeleton) are then solved for every frame with a target, all
frames at once, by Levenberg-Marquardt: horizontal lock errors weigh 1, the locked
point's captured height :data:`_HEIGHT` (heights give way where the leg cannot reach a
lock at them, e.g. the straight leg at heel strike) and the change of the angles a
little (:data:`_REGULARISATION`), so the legs move as little as the locks need.  After
heel strike, with heel and toe both held, the foot cannot pitch: a held toe still coming
down is asked for the flat foot's height under the ankle (so the solver does not jump
between pitching the foot up and down), and before its lock the toe is carried by the
foot and lowered to that height over its ease (so the foot does not slap down in one
frame); a toe that lands before its heel (jumping, hopping) keeps its own ease, since its
lock does not begin with that height.  Only the leg chains change: the root, spine,
arms and the toes' own rotation keep their values.
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
from ..skeleton import Skeleton, _mix

__all__ = ["FootLockResult", "leg_chain", "lock_feet", "pin_feet"]

#: Weight of the change of the leg's angles (per radian) relative to target errors (per leg
#: length): small enough that locks hold to about 1e-3 leg lengths even where the leg is
#: nearly straight, large enough to pick the smallest change among the leg poses that
#: reach a lock (and to keep neighbouring frames on the same one).
_REGULARISATION = 0.01
#: Weight of a locked point's height (kept at its captured height) relative to its
#: horizontal lock: heights give way first where heel and toe locks disagree.
_HEIGHT = 0.1
#: Weight of a height asked for explicitly (``heights``: a stand's foot kept on the floor)
#: relative to the horizontal lock.  At 1 the ankle was held in all three directions and
#: the solve flipped the knee between frames as the stand's hip swayed (6,000-11,000 cm/s^2
#: on a Bandai stand; the lock then let go of those frames and the feet snapped and slid
#: on 6 of 15 benchmark scripts); at 0.3 (0.1 reads the same) the feet stay down as well
#: and slide on 2, as without it.
_KEPT_HEIGHT = 0.3
#: Levenberg-Marquardt iterations (at most): most frames stop within ten; those still
#: moving after thirty crawl along a flat valley of the cost (50 changed one frame of a
#: latent script's 268 by under a degree, at a quarter more solving time).
_ITERATIONS = 30
#: A frame's solve also stops once a step lowers its cost by less than this fraction:
#: the last frames of a solve crawled for forty steps along a valley of the cost, some
#: 1e-6 of it per step, at a fifth of the locking's time (their angles differ by under
#: half a degree).
_FTOL = 1e-5


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

    def to_dict(self) -> dict:
        """JSON-ready: skating before, after and with contacts found afresh, each joint's
        mean change (degrees) and the largest lock error."""
        return {
            "before": self.before.to_dict(),
            "after": self.after.to_dict(),
            "after_redetected": self.after_redetected.to_dict(),
            "joint_change_degrees": {k: float(v) for k, v in self.joint_change.items()},
            "mean_joint_change_degrees": self.mean_joint_change,
            "max_lock_error": float(self.max_error),
        }

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
    """Weights, run labels (-1: none) and runs of one foot point, over the extended timeline.

    A frame gets the label of its nearest run within ``nb + 1`` frames, ``w = 1`` inside
    runs and on the frame either side, then a smoothstep down to 0 over ``nb`` frames.
    A cyclic motion is tiled three times (``3 T`` frames; the middle copy is the motion)
    so runs and blends wrap around.
    """
    ext = np.tile(planted, 3 if cyclic else 1)
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
    return w, label, runs


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


def _extended(points: np.ndarray, cyclic: bool, loop_shift: tuple | None) -> np.ndarray:
    """Positions ``(T, 3)`` over the extended timeline of :func:`_lock_weights`: a cyclic
    motion's loop before and after it, moved by ``loop_shift`` when it travels."""
    if not cyclic:
        return points
    T = points.shape[0]
    ext = np.tile(points, (3, 1))
    if loop_shift is None:
        return ext
    return _next_loop(ext, np.repeat([-1, 0, 1], T), loop_shift)


def _targets(
    points: np.ndarray,
    planted: np.ndarray,
    up: int,
    nb: int,
    cyclic: bool,
    loop_shift: tuple | None = None,
    carry: np.ndarray | None = None,
):
    """Targets ``(T, 3)`` (horizontal components eased into locks), ease weights ``(T,)``,
    run labels (-1: free) and the side of the contact ``(T,)`` (-1 before it, held frame
    included; 0 on it; 1 after it) for one foot point.

    Each contact is pinned at its mean horizontal position; with ``carry`` ``(T, 3)``
    (finite on some frames of the contact) at the mean of ``points + carry`` over those
    frames instead (the toe carried by the ankle's correction).  Around a lock the point
    keeps its captured velocity: its path is shifted by ``w`` times the offset between
    the lock and the held frame beside it, so it leaves and reaches the lock at the speed
    it was captured with (easing the position itself would leave slow, low frames that a
    fresh contact search calls skating).  Between two contacts whose eases meet, the
    offset passes smoothly from the first lock's to the next's.  A cyclic motion that
    travels moves by ``loop_shift`` from one loop to the next: a contact that runs across
    the seam reads the frames of the neighbouring loop there (its own frames shifted by
    it), not the far end of this one.
    """
    T = planted.size
    horiz = [k for k in range(3) if k != up]
    w, label, runs = _lock_weights(planted, nb, cyclic)
    mid = slice(T, 2 * T) if cyclic else slice(0, T)
    pts = _extended(points, cyclic, loop_shift)
    if carry is not None:
        car = np.tile(carry, (3, 1)) if cyclic else carry
        if cyclic and loop_shift is not None:  # displacements turn with the loops
            turn_only = (np.zeros(3), np.zeros(3), loop_shift[2], loop_shift[3])
            car = _next_loop(car, np.repeat([-1, 0, 1], T), turn_only)
    target = pts.copy()
    n_ext = pts.shape[0]
    side = np.zeros(n_ext, dtype=int)
    locks = np.zeros((len(runs), len(horiz)))
    for k, (a, b) in enumerate(runs):
        locks[k] = pts[a:b][:, horiz].mean(axis=0)
        if carry is not None:
            flat = np.isfinite(car[a:b, 0])
            if flat.any():
                locks[k] = (pts[a:b][flat] + car[a:b][flat])[:, horiz].mean(axis=0)
    # offset of each frame's path from its lock: the lock minus the held frame beside it
    off = np.zeros((n_ext, len(horiz)))
    held = np.zeros(n_ext, bool)
    for k in np.unique(label[label >= 0]):
        a, b = runs[k]
        rows = np.flatnonzero(label == k)
        before, after = rows < a - 1, rows > b
        off[rows[before]] = locks[k] - pts[max(a - 1, 0), horiz]
        off[rows[after]] = locks[k] - pts[min(b, n_ext - 1), horiz]
        held[rows[~(before | after)]] = True
        side[rows[rows < a]] = -1
        side[rows[rows >= b]] = 1
    # two contacts so close that the ease out of one runs into the ease into the next (no
    # free frame between): the offset passes smoothly from the first lock's to the next's
    # over the frames between their held frames, instead of jumping where the nearer run
    # changes (at an ease weight near 1 that jump is a pop of the leg)
    for k in range(len(runs) - 1):
        b1, a2 = runs[k][1], runs[k + 1][0]
        gap = np.arange(b1 + 1, a2 - 1)
        if gap.size and (label[gap] >= 0).all():
            u = _smoothstep((gap - b1) / (a2 - 1 - b1))[:, None]
            off[gap] = (1 - u) * (locks[k] - pts[b1, horiz]) + u * (
                locks[k + 1] - pts[a2 - 1, horiz]
            )
    eased = pts[:, horiz] + w[:, None] * off
    eased[held] = locks[label[held]]
    rows = np.flatnonzero(label >= 0)
    target[rows[:, None], horiz] = eased[rows]
    return target[mid], np.where(label >= 0, w, 0.0)[mid], label[mid], side[mid]


def _lock_start(ease: np.ndarray, side: np.ndarray, cyclic: bool) -> np.ndarray:
    """For each frame ``(T,)`` on the way into a lock (``side < 0``), the held frame its lock
    begins with: the first frame at or after it with ``ease >= 1``, wrapping round a
    cyclic motion; -1 elsewhere (or where no held frame follows)."""
    T = ease.size
    out = -np.ones(T, dtype=int)
    nxt = -1
    # backwards, twice round a loop so an ease before the seam sees the lock after it
    for t in range(2 * T - 1 if cyclic else T - 1, -1, -1):
        f = t % T
        if side[f] >= 0:
            nxt = -1
        elif ease[f] >= 1:
            nxt = f
        if t < T and side[f] < 0:
            out[f] = nxt
    return out


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


def leg_chain(skel: Skeleton, points: list[int]) -> tuple[list[int], list[int]]:
    """The IK chain of one leg whose foot points are the joints ``points`` (from the thigh
    down to the deepest point's parent, :func:`_chain`) and the points' order from the
    least deep (the ankle) to the deepest (the toe)."""
    depth = []
    for p in points:
        d, j = 0, p
        while skel.joints[j].parent >= 0 and d <= len(skel.joints):
            d += 1
            j = skel.joints[j].parent
        depth.append(d)
    order = sorted(range(len(points)), key=lambda k: (depth[k], k))
    deepest = max(range(len(points)), key=lambda k: depth[k])  # (the first of equals)
    return _chain(skel, points[order[0]], points[deepest]), order


class _LegIK:
    """Forward kinematics of one leg chain as a function of its rotation channels, with
    the exact Jacobian of the foot points (each angle turns the points below its joint
    about the elementary rotation's axis in the world)."""

    def __init__(self, motion: Motion, chain: list[int], points: list[int], world_rot, world_pos):
        skel = motion.skeleton
        self.skel = skel
        self.chain = chain
        self.points = points
        col = {c: i for i, c in enumerate(motion.channels)}
        self.vars: list[tuple[int, int, int]] = []  # (chain position, order position, column)
        #: per chain joint: its offset, rest axis (None: identity) and (axis index, variable)
        #: for each rotation channel the motion has (a missing one is 0: no rotation)
        self.steps: list[tuple[np.ndarray, np.ndarray | None, list[tuple[int, int]]]] = []
        for ci, j in enumerate(chain):
            joint = skel.joints[j]
            turns = []
            for k, ax in enumerate(joint.rotation_order.lower()):
                c = col.get((joint.name, "r" + ax))
                if c is not None:
                    turns.append(("xyz".index(ax), len(self.vars)))
                    self.vars.append((ci, k, c))
            rest = None if np.array_equal(joint.axis, np.eye(3)) else joint.axis
            self.steps.append((joint.offset, rest, turns))
        if not self.vars:
            raise ParameterError("the leg chain has no rotation channels to solve")
        #: each point: (chain position it hangs from, offset below that joint or None for
        #: the joint itself) and how many of the chain's joints turn it
        self.where: list[tuple[int, np.ndarray | None]] = []
        reach = []
        for p in points:
            if p in chain:
                self.where.append((chain.index(p), None))
                reach.append(chain.index(p))
            else:  # a point one bone below the chain (the toe below the foot)
                ci = chain.index(skel.joints[p].parent)
                self.where.append((ci, skel.joints[p].offset))
                reach.append(ci + 1)
        #: (P, V): variable v moves point p
        self.moves = np.array([[ci < r for ci, _, _ in self.vars] for r in reach])
        parent = skel.joints[chain[0]].parent
        self.base_rot = world_rot[:, parent]
        self.base_pos = world_pos[:, parent]
        self.frames = np.asarray(motion.frames, float)

    def values(self) -> np.ndarray:
        return self.frames[:, [c for _, _, c in self.vars]].copy()

    def positions(self, q: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Positions ``(n, P, 3)`` of the foot points for variables ``q`` (n, V) on ``rows``."""
        return self.kinematics(q, self.base_rot[rows], self.base_pos[rows])[0]

    def kinematics(self, q: np.ndarray, rot: np.ndarray, pos: np.ndarray, jacobian: bool = False):
        """Positions ``(n, P, 3)`` of the foot points for variables ``q`` (n, V) below the
        chain's parent at ``rot`` (n, 3, 3) and ``pos`` (n, 3); with ``jacobian`` also
        their derivatives ``(n, P, 3, V)`` per degree."""
        n = q.shape[0]
        rad = np.radians(q)
        cos, sin = np.cos(rad), np.sin(rad)
        pivots, axes, at = [], [], []
        for offset, rest, turns in self.steps:
            pos = pos + rot @ offset
            if turns:  # (no channel: no rotation)
                m = rot.copy() if rest is None else rot @ rest
                for axis, v in turns:
                    if jacobian:  # the elementary rotation's axis in the world
                        axes.append(m[:, :, axis].copy())
                        pivots.append(pos)
                    _mix(m, axis, cos[:, v], sin[:, v])
                rot = m if rest is None else m @ rest.T
            at.append((pos, rot))
        out = np.empty((n, len(self.points), 3))
        for i, (ci, offset) in enumerate(self.where):
            jpos, jrot = at[ci]
            out[:, i] = jpos if offset is None else jpos + jrot @ offset
        if not jacobian:
            return out, None
        # each variable's axis (per degree) times the lever arm to each point it moves,
        # all at once: (n, P, V, 3) -> (n, P, 3, V)
        w = np.stack(axes, axis=1) * (np.pi / 180.0)  # (n, V, 3)
        d = out[:, :, None, :] - np.stack(pivots, axis=1)[:, None]  # (n, P, V, 3)
        J = np.empty(d.shape)
        J[..., 0] = w[:, None, :, 1] * d[..., 2] - w[:, None, :, 2] * d[..., 1]
        J[..., 1] = w[:, None, :, 2] * d[..., 0] - w[:, None, :, 0] * d[..., 2]
        J[..., 2] = w[:, None, :, 0] * d[..., 1] - w[:, None, :, 1] * d[..., 0]
        J *= self.moves[None, :, :, None]
        return out, J.transpose(0, 1, 3, 2)


def _box(ik, rows: np.ndarray, bounds) -> tuple[np.ndarray, np.ndarray] | None:
    """Per row and variable ``(n, V)`` the range the solve keeps each angle in: ``bounds``
    (:func:`~cyclecoord.synthesis.carry.channel_bounds`) on the turn nearest the
    angle's own value, widened to include that value (a pose already outside keeps it)."""
    if bounds is None:
        return None
    cols = [c for _, _, c in ik.vars]
    lo, hi = np.asarray(bounds[0], float)[cols], np.asarray(bounds[1], float)[cols]
    q0 = ik.values()[rows]
    if len(bounds) > 2:
        turn = np.asarray(bounds[2], bool)[cols] & np.isfinite(lo) & np.isfinite(hi)
        mid = 0.5 * (np.where(turn, lo, 0.0) + np.where(turn, hi, 0.0))
        k = np.where(turn, np.round((q0 - mid) / 360.0), 0.0)
        lo, hi = lo + 360.0 * k, hi + 360.0 * k
    return np.minimum(lo, q0), np.maximum(hi, q0)


def _solve(ik, rows, targets, weights, scale, iterations=_ITERATIONS, box=None):
    """Levenberg-Marquardt on all ``rows`` at once; returns the new variables (n, V).

    Minimises, per frame, ``sum (weights * (p(q) - targets) / scale)^2 +
    (_REGULARISATION * |q - q0| in radians)^2``: the weighted target errors in leg lengths
    and the change of the chain's angles.  Each frame keeps its own damping, raised when a
    step would not lower its cost (steps are only taken downhill, also near a straight
    knee where the linearisation is poor), and stops once its step is under 1e-6 degrees
    or an accepted step lowers its cost by less than :data:`_FTOL` of it.
    The Jacobian is exact (:meth:`_LegIK.kinematics`), from the same forward kinematics
    pass as the residuals.  With ``box`` (:func:`_box`), every step is clipped into it:
    with all three of a knee's channels free, a standing leg (nearly straight, where
    bending about any axis moves the foot alike) was pinned by twisting the knee 21
    degrees about its long axis, outside anything captured.
    """
    q0 = ik.values()[rows]
    q = q0.copy()
    reg2 = (_REGULARISATION * np.radians(1.0)) ** 2  # the variables are in degrees
    base_rot, base_pos = ik.base_rot[rows], ik.base_pos[rows]
    wt = weights / scale

    def evaluate(qq, idx):
        """Residuals (n, 3P) of the targets, costs (n,) and the residuals' Jacobian
        (n, 3P, V) on rows ``idx``."""
        p, J = ik.kinematics(qq, base_rot[idx], base_pos[idx], jacobian=True)
        r = ((p - targets[idx]) * wt[idx]).reshape(len(idx), -1)
        J = (J * wt[idx][..., None]).reshape(len(idx), r.shape[1], -1)
        d = qq - q0[idx]
        return r, np.einsum("ij,ij->i", r, r) + reg2 * np.einsum("ij,ij->i", d, d), J

    n, V = q.shape
    mu = np.full(n, 1e-3)
    r, c, J = evaluate(q, np.arange(n))
    live = np.arange(n)  # rows still moving
    eye = np.eye(V)
    for _ in range(iterations):
        if live.size == 0:
            break
        Jl, rl = J[live], r[live]
        JT = np.swapaxes(Jl, 1, 2)
        A = JT @ Jl + reg2 * eye
        g = (JT @ rl[..., None])[..., 0] + reg2 * (q[live] - q0[live])
        A += mu[live, None, None] * (np.einsum("nvv->nv", A)[:, :, None] * eye)
        step = np.linalg.solve(A, -g[..., None])[..., 0]
        trial = q[live] + step
        if box is not None:
            trial = np.clip(trial, box[0][live], box[1][live])
        r_new, c_new, J_new = evaluate(trial, live)
        better = c_new <= c[live]
        gain = np.where(better, c[live] - c_new, np.inf)  # a refused step: try again
        take = live[better]
        q[take], r[take] = trial[better], r_new[better]
        c[take], J[take] = c_new[better], J_new[better]
        mu[live] = np.where(better, mu[live] * 0.3, mu[live] * 10.0)
        live = live[(np.abs(step).max(axis=1) >= 1e-6) & (gain >= _FTOL * c[live])]
    return q


def _solve_reusing(ik, rows, targets, weights, scale, known: dict | None, bounds=None):
    """:func:`_solve` within ``bounds`` (:func:`_box`); with ``known`` (the last solve of
    this leg on the same motion and bounds: its rows, targets, weights and solution),
    rows asked the same keep their answer."""
    box = _box(ik, rows, bounds)
    if known is None:
        return _solve(ik, rows, targets, weights, scale, box=box)
    q = np.empty((rows.size, len(ik.vars)))
    todo = np.ones(rows.size, dtype=bool)
    if known:
        at = {int(r): i for i, r in enumerate(known["rows"])}
        old = np.array([at.get(int(r), -1) for r in rows])
        have = old >= 0
        same = np.zeros(rows.size, dtype=bool)
        same[have] = (
            (known["targets"][old[have]] == targets[have]).all(axis=(1, 2))
            & (known["weights"][old[have]] == weights[have]).all(axis=(1, 2))
        )
        q[same] = known["q"][old[same]]
        todo = ~same
    if todo.any():
        sub = None if box is None else (box[0][todo], box[1][todo])
        q[todo] = _solve(ik, rows[todo], targets[todo], weights[todo], scale, box=sub)
    known.update(rows=rows.copy(), targets=targets.copy(), weights=weights.copy(), q=q.copy())
    return q


def _lock_once(
    motion: Motion, contacts: FootContacts, nb: int, cyclic: bool, reuse: dict | None = None,
    bounds=None, heights: np.ndarray | None = None,
) -> tuple[Motion, float]:
    """One locking pass: the edited motion and the largest horizontal lock error.

    ``heights`` (T, F): where finite, the height a leg's ankle point (the least deep of its
    points; the toe follows it) is asked for, at :data:`_KEPT_HEIGHT`, on frames it is
    pinned (a stand's foot stays on the floor).

    ``reuse`` (a dict kept between passes on the same ``motion``): its world transforms
    are found once, and a frame whose leg targets and weights match the last pass's
    keeps that pass's solution (each frame is solved on its own, so it is the same)."""
    from .._kinematics import world_transforms

    skel = motion.skeleton
    if reuse is not None and reuse.get("motion") is not motion:
        reuse.clear()
        reuse["motion"] = motion
    if reuse is not None and "world" in reuse:
        wpos, wrot = reuse["world"]
    else:
        wpos, wrot = world_transforms(motion)
        if reuse is not None:
            reuse["world"] = (wpos, wrot)
    frames = np.array(motion.frames, dtype=float)
    scale = contacts.leg_length
    worst = 0.0
    labels = contacts.leg_labels
    for leg in sorted(set(labels)):
        cols = [i for i, g in enumerate(labels) if g == leg]
        pts = [skel.index(contacts.feet[i]) for i in cols]
        chain, by_depth = leg_chain(skel, pts)
        depth = {pts[k]: d for d, k in enumerate(by_depth)}
        ik = _LegIK(motion, chain, pts, wrot, wpos)
        T = motion.n_frames
        targets = wpos[:, pts].copy()
        # a point eased into or held at a lock: its horizontal target weighs its ease
        # weight (1 when held), its height _HEIGHT times that; a free point has no target
        # (the small-change term keeps it where the leg carries it)
        weights = np.zeros((T, len(pts), 3))
        active = np.zeros(T, bool)
        horiz = [k for k in range(3) if k != contacts.up]
        loop_shift = _loop_shift(wpos[:, 0], wrot[:, 0], contacts.up) if cyclic and T > 1 else None
        carry = None
        first = None
        for m in sorted(range(len(cols)), key=lambda m: depth[pts[m]]):
            i = cols[m]
            if first is not None:
                # a deeper point (the toe) is locked where the ankle's lock carries it on
                # the frames both rest flat, so the two locks fit the foot between them
                a_col, a_tgt, a_pos = first[:3]
                low = 0.5 * contacts.height_threshold
                low_a = contacts.planted[:, a_col] & (contacts.height[:, a_col] < low)
                low_here = contacts.planted[:, i] & (contacts.height[:, i] < low)
                flat = low_a & low_here
                carry = np.where(flat[:, None], a_tgt - a_pos, np.nan)
            tgt, ease, label, side = _targets(
                wpos[:, pts[m]],
                contacts.planted[:, i],
                contacts.up,
                nb,
                cyclic,
                loop_shift,
                carry=carry,
            )
            locked = label >= 0
            weights[locked, m, horiz[0]] = weights[locked, m, horiz[1]] = ease[locked]
            weights[locked, m, contacts.up] = _HEIGHT * ease[locked]
            if first is not None:
                # (the ankle held: planted low, or on the held frame before its contact)
                a_ease, a_side = first[3], first[4]
                a_held = (a_ease >= 1) & (low_a | (a_side < 0))
                # the frame each ease reaches its lock: the toe is carried by the foot over
                # its ease only where the ankle is already held when its own lock begins
                # (heel strike); a toe landing first keeps its own ease, or it would be
                # let go of and then snapped to its lock on the held frame
                start = _lock_start(ease, side, cyclic)
                easing = (label >= 0) & (side < 0) & (ease < 1) & (a_ease > 0) & (a_side <= 0)
            if first is not None and flat.any():
                # the toe under an ankle with a target: held at both locks the foot cannot
                # pitch, so the toe is asked for the flat foot's height under the ankle
                # wherever it is held but still coming down after heel strike (its captured
                # height would leave the solver two pitches to choose between, and it would
                # jump between them); while it eases towards its lock it is carried by
                # the foot and only comes down to that height, so the foot lowers over the
                # ease instead of slapping down on the frame the lock begins
                rel_flat = (wpos[flat, pts[m], contacts.up] - a_pos[flat, contacts.up]).mean()
                flat_height = a_tgt[:, contacts.up] + rel_flat
                down = (ease >= 1) & (side <= 0) & a_held & ~low_here
                tgt[down, contacts.up] = flat_height[down]
                easing &= (start >= 0) & down[np.maximum(start, 0)]
                y = tgt[easing, contacts.up]
                tgt[easing, contacts.up] = y + ease[easing] * (flat_height[easing] - y)
                weights[easing, m, horiz[0]] = weights[easing, m, horiz[1]] = 0.0
                weights[easing, m, contacts.up] = _HEIGHT
            elif first is not None:
                easing &= (start >= 0) & a_held[np.maximum(start, 0)]
                weights[easing, m] = 0.0
            if heights is not None and first is None:  # (the ankle; the toe follows it)
                kept = np.isfinite(heights[:, i]) & locked
                tgt[kept, contacts.up] = heights[kept, i]
                weights[kept, m, contacts.up] = _KEPT_HEIGHT
            targets[:, m] = tgt
            if first is None:
                first = (i, tgt, wpos[:, pts[m]], ease, side)
            active |= locked
        rows = np.flatnonzero(active)
        if rows.size == 0:
            continue
        q = _solve_reusing(ik, rows, targets[rows], weights[rows], scale,
                           None if reuse is None else reuse.setdefault(("leg", leg), {}),
                           bounds)
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


def pin_feet(
    motion: Motion, contacts: FootContacts, *, blend: float = 0.1, cyclic: bool = False,
    reuse: dict | None = None, bounds: tuple[np.ndarray, ...] | None = None,
    heights: np.ndarray | None = None,
) -> Motion:
    """:func:`lock_feet`'s motion alone, one pass on ``contacts`` (no skating figures, no
    joint changes, no fresh contact search): for callers that judge the result their
    own way (:func:`~cyclecoord.synthesis.carry.lock_where_clean`, latent planting).

    ``reuse``: a dict kept by a caller that pins one motion several times on contacts
    that differ here and there (lock, judge, drop the contacts that popped, lock
    again): frames asked the same as last time keep their solution, the same numbers.
    ``bounds``: per-channel ranges the legs' angles are solved within
    (:func:`~cyclecoord.synthesis.carry.channel_bounds`; an angle already outside may
    stay where it is).  ``heights`` (T, F): where finite, the height each leg's ankle
    point is asked for where it is pinned, at :data:`_KEPT_HEIGHT` (a stand's feet stay
    on the floor; NaN: its own height, at :data:`_HEIGHT`)."""
    if heights is not None:
        heights = np.asarray(heights, dtype=float)
        if heights.shape != contacts.planted.shape:
            raise ParameterError(
                f"heights has shape {heights.shape}, the contacts {contacts.planted.shape}"
            )
    return _pinned(motion, contacts, blend, cyclic, 1, {}, reuse, bounds, heights)[0]


def _pinned(motion, contacts, blend, cyclic, passes, contact_options, reuse=None,
            bounds=None, heights=None):
    """The locked motion, the contacts it was given (found when None), the options for
    finding contacts afresh and the largest lock error."""
    if not (np.isfinite(blend) and blend >= 0):
        raise ParameterError(f"blend must be >= 0 seconds, got {blend!r}")
    if isinstance(passes, bool) or not isinstance(passes, (int, np.integer)) or passes < 1:
        raise ParameterError(f"passes must be a whole number >= 1, got {passes!r}")
    feet = contact_options.pop("feet", None)
    if contacts is None:
        contacts = foot_contacts(motion, feet=feet, **contact_options)
    elif feet is not None:
        raise ParameterError("pass either contacts or feet, not both")
    else:
        contact_skeleton(motion)
    if contacts.n_frames != motion.n_frames:
        raise ParameterError(
            f"contacts cover {contacts.n_frames} frames, the motion has {motion.n_frames}"
        )
    nb = round(blend * motion.fps)
    if not contact_options:  # find contacts afresh with the thresholds of the given ones
        contact_options = {
            "height": contacts.height_threshold / contacts.leg_length,
            "speed": (
                contacts.speed_threshold / contacts.leg_length
                if np.isfinite(contacts.speed_threshold)
                else None
            ),
            "up": "xyz"[contacts.up],
        }
    out, worst = _lock_once(motion, contacts, nb, cyclic, reuse, bounds, heights)
    locked = contacts
    for _ in range(int(passes) - 1):
        again = foot_contacts(out, contacts.feet, **contact_options)
        extra = again.planted & ~locked.planted
        if not (foot_skating(out, again).skating & extra).any():
            break
        locked = replace(locked, planted=locked.planted | again.planted)
        out, worst = _lock_once(out, locked, nb, cyclic, bounds=bounds)
    return out, contacts, contact_options, worst


def lock_feet(
    motion: Motion,
    contacts: FootContacts | None = None,
    *,
    blend: float = 0.1,
    cyclic: bool = False,
    passes: int = 5,
    **contact_options,
) -> FootLockResult:
    """Remove foot skating by pinning planted feet and re-solving the legs.

    Parameters
    ----------
    motion : Motion
        A motion with a skeleton (CMU ASF, BVH, ...).
    contacts : FootContacts, optional
        Contacts to lock; found with :func:`foot_contacts` (and ``contact_options``,
        ``feet=`` among them to name the foot points) when not given.
    blend : float
        Seconds over which a foot eases into and out of each lock.
    cyclic : bool
        Treat the motion as a loop (a typical cycle): a contact running over the last
        frame continues at the first, and blends wrap around.
    passes : int
        Contacts found afresh on the result can be a frame or two longer than the locked
        ones (a foot reaching its lock is slowed or steered a little); up to ``passes``
        rounds lock those too when they skate, stopping as soon as none does (each round
        solves the legs again from the previous round's result, so the locked motion
        measured on its own contacts skates no more than on the input's; 69_01's cycle
        needs 4).  1 locks the input's contacts only.

    Returns
    -------
    FootLockResult
    """
    from .._kinematics import local_transforms

    out, contacts, contact_options, worst = _pinned(
        motion, contacts, blend, cyclic, passes, contact_options
    )
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
        after_redetected=foot_skating(out, foot_contacts(out, contacts.feet, **contact_options)),
        joint_change=dict(zip(motion.skeleton.names, angle.tolist())),
        max_error=worst,
    )
