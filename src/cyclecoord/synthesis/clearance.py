"""Limbs turned apart at the shoulder or hip where they come closer than the captures do.

A generated frame can bring a hand into the thigh or one shin through the other: a latent
blend of two performers' arm swings, a pose between two captured frames.
:func:`~cyclecoord.quality.plausibility.check_plausibility` finds such *new* contacts
against the training takes.  :func:`push_limbs_apart` moves the limb out the way an
animator would: the whole arm (or leg) turned about its shoulder (hip) joint, by the small
angle that puts the touching bone back at the takes' closest approach, eased in and out
over a fraction of a second so that no pop replaces the contact.  The rest of the pose,
the root and the other limbs are untouched.  Which limb moves:

* an arm against the trunk or a leg: the arm (a leg carries the body);
* a leg against the other leg: the leg whose foot is higher on that frame (the swinging
  one), and not while its foot is planted (given ``feet``): a planted foot stays put;
* an arm against the other arm: both, half the angle each.

A contact that needs more than :data:`PUSH_MAX_DEG` at the pivot is left as it is (the
caller refuses or reports it), as are joints with fewer than three rotation channels.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from ..motion import Motion

__all__ = ["PUSH_MAX_DEG", "PUSH_WIDTH", "Pushed", "push_limbs_apart"]

#: Seconds each side of a contact frame over which a limb's turn eases in and out.
PUSH_WIDTH = 0.3
#: Largest turn (degrees) at a shoulder or hip; a contact needing more is left alone.
PUSH_MAX_DEG = 12.0
#: Passes that look again after turning (a turn can bring the limb near another bone).
PUSH_ROUNDS = 3
#: The turn aims this fraction of the clearance threshold beyond the point where a
#: contact counts as new (the takes' closest approach minus 10 % of the threshold).
_AIM = 0.06


@dataclass
class Pushed:
    """What :func:`push_limbs_apart` turned.

    Attributes
    ----------
    turns : dict
        Pivot joint name -> ``(spans, largest_deg)``: the ``[first, last]`` frame spans
        (the motion's numbering) it turned on, and its largest turn in degrees.
    left : list of str
        Contacts it could not undo, as ``"bone/bone"``.
    """

    turns: dict = field(default_factory=dict)
    left: list = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "turned": [
                {"joint": j, "frames": [list(r) for r in spans], "largest_deg": round(d, 2)}
                for j, (spans, d) in self.turns.items()
            ],
            "left": list(self.left),
        }

    def line(self) -> str | None:
        """One console line, or None when nothing turned."""
        if not self.turns:
            return None
        parts = [f"{j} by up to {d:.1f} deg on frames "
                 + ", ".join(f"{a}-{b}" for a, b in spans)
                 for j, (spans, d) in self.turns.items()]
        return ("limbs turned apart where they came closer than the training takes: "
                + "; ".join(parts))


def _pivots(motion: Motion) -> tuple[np.ndarray, list[str]]:
    """Per forward-kinematics point, the joint index of the shoulder or hip above it (or
    itself), -1 for the trunk; and per joint its limb kind ``"arm"``/``"leg"``/``""``."""
    from ..joint_names import classify_skeleton

    skel = motion.skeleton
    roles = classify_skeleton(skel)
    fk = motion.positions()
    n_joints = len(skel.joints)
    index = {j.name: i for i, j in enumerate(skel.joints)}
    pivot = np.full(len(fk.names), -1)
    kind = [""] * n_joints
    for p, name in enumerate(fk.names):  # parents come before their children
        base = name.split("/")[0]
        role = roles.get(base)
        i = index.get(base, -1)
        if role is not None and role.role in ("shoulder", "hip") and name == base:
            j = skel.joints[i]
            if len(j.rotation_order) == 3 and all(
                (j.name, "r" + a.lower()) in motion.channels for a in j.rotation_order
            ):
                pivot[p] = i
                kind[i] = "arm" if role.role == "shoulder" else "leg"
                continue
        par = fk.parents[p]
        pivot[p] = pivot[par] if par >= 0 else -1
    return pivot, kind


def _closest(p0, p1, q0, q1) -> tuple[np.ndarray, np.ndarray]:
    """Closest points ``(T, 3)`` on segments ``p0-p1`` and ``q0-q1`` per row
    (:func:`~cyclecoord.quality.bones.segment_parameters`)."""
    from ..quality.bones import segment_parameters

    s, t = segment_parameters(p0, p1, q0, q1)
    return p0 + s[:, None] * (p1 - p0), q0 + t[:, None] * (q1 - q0)


def _wanted_turns(motion, contacts, thr, pivot, kind, feet_height) -> dict[int, tuple]:
    """Per pivot joint, on each frame the turn that undoes the contact needing the most:
    its angle ``(T,)`` (radians, 0 where no contact is short of room) and axis ``(T, 3)``
    (world), the smallest turn about the pivot that moves the limb bone's closest point
    straight away from the other bone to the aimed distance."""
    from ..quality.bones import bones

    fk = motion.positions().positions
    bn = bones(motion)
    name_of = {n: b for b, n in enumerate(bn.names)}
    T = motion.n_frames
    want: dict[int, tuple] = {}
    for c in contacts:
        ia, ib = (name_of.get(n) for n in c["bones"])
        if ia is None or ib is None:
            continue
        rmin = c["reference_min_distance"]
        aim = min(thr, np.inf if rmin is None else rmin) - (0.1 - _AIM) * thr
        pa, pb = pivot[bn.start[ia]], pivot[bn.start[ib]]
        if pa < 0 and pb < 0:
            continue
        A = _closest(fk[:, bn.start[ia]], fk[:, bn.end[ia]], fk[:, bn.start[ib]], fk[:, bn.end[ib]])
        gap = A[0] - A[1]
        dist = np.linalg.norm(gap, axis=1)
        if not (dist < aim).any():
            continue
        away = gap / np.maximum(dist, 1e-9)[:, None]
        if pa >= 0 and pb >= 0 and kind[pa] == kind[pb] == "arm":
            movers = [(pa, A[0], away, 0.5), (pb, A[1], -away, 0.5)]
        elif pa >= 0 and pb >= 0 and kind[pa] != kind[pb]:
            movers = [(pa, A[0], away, 1.0)] if kind[pa] == "arm" else [(pb, A[1], -away, 1.0)]
        elif pa >= 0 and pb >= 0:  # two legs: the one whose foot is higher, per frame
            higher = feet_height.get(pa, np.zeros(T)) >= feet_height.get(pb, np.zeros(T))
            movers = [(pa, A[0], away, higher.astype(float)),
                      (pb, A[1], -away, (~higher).astype(float))]
        else:
            movers = [(pa, A[0], away, 1.0)] if pa >= 0 else [(pb, A[1], -away, 1.0)]
        for j, point, u, share in movers:
            deficit = np.clip(aim - dist, 0.0, None) * np.broadcast_to(share, (T,))
            axis = np.cross(point - fk[:, j], u)
            reach = np.linalg.norm(axis, axis=1)
            angle = np.where(reach > 1e-9, deficit / np.maximum(reach, 1e-9), 0.0)
            have = want.setdefault(j, (np.zeros(T), np.zeros((T, 3))))
            more = angle > have[0]
            have[0][more] = angle[more]
            have[1][more] = axis[more] / reach[more, None]
    return want


def _legs_free(motion: Motion, feet: Sequence[str], pivot: np.ndarray, width: int
               ) -> dict[int, np.ndarray]:
    """Per leg (its hip joint's index), a weight ``(T,)`` from 0 to 1 of how far it may
    turn: 0 where one of its ``feet`` is planted
    (:func:`~cyclecoord.quality.contacts.foot_contacts`: low and still), easing to 1 over
    a third of ``width`` frames from each planted run (eased over the frames about a
    contact, a leg's turn would slide its planted foot).  Empty when the contacts cannot
    be found."""
    from ..errors import CycleCoordError
    from ..quality.contacts import foot_contacts

    names = list(motion.positions().names)
    try:
        planted = foot_contacts(motion, tuple(feet)).planted
    except CycleCoordError:
        return {}
    T = motion.n_frames
    ramp = max(1, width // 3)
    out: dict[int, np.ndarray] = {}
    for j in {int(pivot[names.index(f)]) for f in feet if f in names} - {-1}:
        cols = [c for c, f in enumerate(feet) if f in names and pivot[names.index(f)] == j]
        down = np.flatnonzero(planted[:, cols].any(axis=1))
        if not down.size:
            continue
        t = np.arange(T)
        at = np.clip(np.searchsorted(down, t), 1, down.size) - 1
        gap = np.minimum(np.abs(t - down[at]), np.abs(t - down[np.minimum(at + 1,
                                                                            down.size - 1)]))
        u = np.clip(gap / (ramp + 1.0), 0.0, 1.0)  # frames from the nearest planted one
        out[j] = u * u * (3.0 - 2.0 * u)
    return out


def _eased_turn(angle: np.ndarray, axis: np.ndarray, width: int) -> np.ndarray:
    """The turns ``angle`` about ``axis`` (in the pivot's parent's axes) of the frames
    short of room as one turn eased over ``width`` frames each side (rotation vectors
    ``(T, 3)``, radians).

    Short frames less than ``width`` apart are one run, which turns about one axis, their
    axes' angle-weighted mean (each frame's own axis swings as the closest points slide
    along the bones, and a turn following it would wobble): a frame whose axis is
    ``c`` (cosine) off it needs its angle over ``c`` (at most twice), and the largest
    such angle eases in and out."""
    T = angle.shape[0]
    on = np.flatnonzero(angle > 0)
    out = np.zeros((T, 3))
    k = np.arange(-width, width + 1)
    u = 1.0 - np.abs(k) / (width + 1.0)
    bump = u * u * (3.0 - 2.0 * u)
    for run in np.split(on, np.flatnonzero(np.diff(on) > width) + 1) if on.size else ():
        mean = (angle[run, None] * axis[run]).sum(axis=0)
        if np.linalg.norm(mean) < 1e-12:
            continue
        mean /= np.linalg.norm(mean)
        need = angle[run] / np.maximum(axis[run] @ mean, 0.5)
        env = np.zeros(T)
        for f, a in zip(run, need):
            lo, hi = max(f - width, 0), min(f + width + 1, T)
            env[lo:hi] = np.maximum(env[lo:hi], a * bump[lo - f + width: hi - f + width])
        out += env[:, None] * mean
    return out


def _turned(motion: Motion, turns: dict[int, np.ndarray]) -> Motion:
    """``motion`` with each pivot joint's local rotation premultiplied by its turn
    (rotation vectors ``(T, 3)`` in its parent's axes)."""
    from scipy.spatial.transform import Rotation

    from .._kinematics import local_transforms
    from ..conventions import continuous_euler

    skel = motion.skeleton
    _, local = local_transforms(motion)
    frames = np.array(motion.frames, dtype=float)
    for j, vec in turns.items():
        rows = np.flatnonzero(np.linalg.norm(vec, axis=1) > 1e-9)
        if not rows.size:
            continue
        joint = skel.joints[j]
        new = Rotation.from_rotvec(vec[rows]).as_matrix() @ local[rows, j]
        ax = np.asarray(joint.axis, dtype=float)
        own = np.einsum("ji,njk,kl->nil", ax, new, ax)
        cols = [motion.channel_index(joint.name, "r" + a.lower()) for a in joint.rotation_order]
        runs = np.split(rows, np.flatnonzero(np.diff(rows) > 1) + 1)
        for run in runs:
            pos = np.searchsorted(rows, run)
            eul = continuous_euler(own[pos][:, None], joint.rotation_order,
                                   near=frames[run[0], cols][None, :])[:, 0]
            frames[np.ix_(run, cols)] = eul
    return motion.with_frames(frames)


def push_limbs_apart(
    motion: Motion,
    references: Sequence[Motion],
    *,
    cache: dict | None = None,
    analysed: bool = True,
    feet: Sequence[str] = (),
    width: float = PUSH_WIDTH,
    max_deg: float = PUSH_MAX_DEG,
    rounds: int = PUSH_ROUNDS,
) -> tuple[Motion, Pushed]:
    """Turn limbs apart at their shoulder or hip where they come closer than the
    references' closest approach (the new contacts of
    :func:`~cyclecoord.quality.plausibility.check_plausibility`).

    Parameters
    ----------
    motion : Motion
        With a skeleton whose shoulders and hips are named
        (:func:`~cyclecoord.joint_names.classify_skeleton`).
    references : sequence of Motion
        The captures the motion is judged against (a latent model's training takes).
    cache, analysed
        Passed to :func:`~cyclecoord.quality.plausibility.check_plausibility`.
    feet : sequence of str
        Foot joint names: with two legs touching, the leg whose foot is higher turns, and
        a leg does not turn where one of its feet is planted.
    width : float, default :data:`PUSH_WIDTH`
        Seconds each side of a contact over which the turn eases in and out.
    max_deg : float, default :data:`PUSH_MAX_DEG`
        Contacts needing a larger turn at their pivot on any frame are left alone.
    rounds : int, default :data:`PUSH_ROUNDS`

    Returns
    -------
    motion : Motion
        The motion with limbs turned (the same object when nothing was turned).
    pushed : Pushed
    """
    from .._kinematics import world_transforms
    from ..quality.plausibility import check_plausibility

    out = motion
    result = Pushed()
    if motion.skeleton is None or motion.n_frames < 3:
        return motion, result
    pivot, kind = _pivots(motion)
    if not (pivot >= 0).any():
        return motion, result
    names = list(motion.positions().names)
    parents = motion.positions().parents
    n = max(1, int(round(width * motion.fps)))
    total: dict[int, np.ndarray] = {}
    largest: dict[int, np.ndarray] = {}
    rep, checked = None, None
    for _ in range(rounds):
        rep, checked = check_plausibility(out, references, cache=cache, analysed=analysed), out
        new = [c for c in rep.contacts if c["new"]]
        if not new:
            break
        pos = out.positions().positions
        heights = {}
        for f in feet:
            if f in names:
                j = pivot[names.index(f)]
                if j >= 0:
                    heights[j] = pos[:, names.index(f), 1]
        want = _wanted_turns(out, new, rep.threshold, pivot, kind, heights)
        free = _legs_free(out, feet, pivot, n) if feet else {}
        step = {}
        world = world_transforms(out)[1] if want else None
        for j, (angle, axis) in want.items():
            parent = int(parents[j])
            rot = world[:, parent] if parent >= 0 else np.broadcast_to(np.eye(3), world[:, j].shape)
            vec = _eased_turn(angle, np.einsum("nji,nj->ni", rot, axis), n)
            if j in free:  # a leg: not while its foot is planted
                vec *= free[j][:, None]
            deg = np.degrees(np.linalg.norm(vec, axis=1))
            if not deg.any() or deg.max() > max_deg:
                continue
            step[j] = vec
        if not step:
            break
        out = _turned(out, step)
        for j, vec in step.items():
            total[j] = total.get(j, 0.0) + vec
            largest[j] = np.maximum(largest.get(j, 0.0), np.linalg.norm(total[j], axis=1))
    if rep is None:  # no rounds asked
        return motion, result
    if checked is not out:
        rep = check_plausibility(out, references, cache=cache, analysed=analysed)
    result.left = ["/".join(c["bones"]) for c in rep.contacts if c["new"]]
    start = int(motion.start_frame)
    for j, size in largest.items():
        on = np.flatnonzero(np.degrees(size) > 0.05)
        if on.size:
            runs = np.split(on, np.flatnonzero(np.diff(on) > 1) + 1)
            result.turns[motion.skeleton.joints[j].name] = (
                [(int(r[0]) + start, int(r[-1]) + start) for r in runs],
                float(np.degrees(size.max())))
    return out, result
