"""A stand after a gait: the closing step that brings the feet together.

A gait that comes to a stop does so at double support, the feet a stride apart; held
there, a stand is a walk frozen mid-stride (on subject 35's walk model the ankles stood
0.56-0.72 leg lengths apart for the whole IDLE after a MOVE).  People stopping take one
more, shorter step: the trailing foot swings forward and sets down beside the leading one,
and the pelvis comes over the middle of the feet.  :func:`close_stands` makes that step at
the start of each stand, by the leg IK of :mod:`.footlock` (both legs, every frame of the
stand, within the training takes' joint ranges), the root moved forward by half the gap
and raised back towards its mid-stance height as far as the legs reach.  A stand that more
frames follow ends with the opening step: the leading foot steps out by the same gap and
the rest of the motion is moved forward by it, so the next stride starts from where the
feet now are.  A step the legs cannot reach, or that brings two limbs closer than the
training takes ever do, is not made: that stand keeps its stance, and says why.  A stand
that did not travel before it and ends the motion (a script that starts on a frame
mid-stride and stands there) takes the same closing step, forward being where the toes
point and each foot point set at the height it rests at when planted; with frames after
it, its opening step would have to start their stride again, and it is left alone (seven
random scripts popped there, up to 3.7x).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._words import plural
from ..errors import CycleCoordError
from ..motion import Motion

__all__ = [
    "REACH_TOLERANCE", "STEP_CLEARANCE", "STEP_LIMITS", "TOE_FREEDOM", "TOGETHER",
    "StandOutcome", "close_stands",
]

#: Seconds the closing (and opening) step takes at the least and at the most: half the
#: gait's leg cycle (one step) within these.
STEP_LIMITS = (0.3, 0.5)
#: Height the stepping foot clears the floor by, in leg lengths, at the step's middle.
STEP_CLEARANCE = 0.06
#: Feet closer than this along the travel (leg lengths) already stand together.
TOGETHER = 0.12
#: Weight of the toe's horizontal target against the ankle's (its height weighs 1).
TOE_FREEDOM = 0.2
#: A stand whose ankles miss their targets by more than this (leg lengths) after the IK
#: (three times this for a foot in the air), or whose toes miss theirs by twice as much,
#: keeps its stance.
REACH_TOLERANCE = 0.02


@dataclass(frozen=True)
class StandOutcome:
    """What :func:`close_stands` did.

    Attributes
    ----------
    motion : Motion
        The motion with the steps made (the input where none was).
    closed : list of (int, int)
        The stands (frame ranges) given a closing step.
    kept : list of (int, str)
        Stands left in their stance: first frame and why.
    gaps : list of float
        The feet's distance along the travel closed at each closed stand (leg lengths).
    """

    motion: Motion
    closed: list[tuple[int, int]] = field(default_factory=list)
    kept: list[tuple[int, str]] = field(default_factory=list)
    gaps: list[float] = field(default_factory=list)

    def to_dict(self) -> list[dict]:
        """One entry per stand after a stride, for JSON reports: ``start``, ``stop``,
        ``closed`` and the ``gap`` closed (leg lengths) or ``why`` it was not."""
        out = [{"start": int(a), "stop": int(b), "closed": True, "gap": float(g)}
               for (a, b), g in zip(self.closed, self.gaps)]
        out += [{"start": int(a), "closed": False, "why": why} for a, why in self.kept]
        return sorted(out, key=lambda e: e["start"])

    @property
    def line(self) -> str:
        """One console line, or "" when there was no stand after a stride."""
        if not self.closed and not self.kept:
            return ""
        parts = []
        if self.closed:
            gaps = ", ".join(f"{g:.2f}" for g in self.gaps)
            n = len(self.closed)
            parts.append(f"{plural(n, 'stand')} closed {'its' if n == 1 else 'their'} feet "
                         f"with one more step (gap {gaps} leg lengths)")
        for a, why in self.kept:
            parts.append(f"the stand at frame {a} kept its stance ({why})")
        return "stands: " + "; ".join(parts)


def _ease(u: np.ndarray) -> np.ndarray:
    u = np.clip(u, 0.0, 1.0)
    return u * u * u * (u * (6.0 * u - 15.0) + 10.0)


def _legs(motion: Motion, contacts) -> list[tuple[list[int], list[int], list[int]]]:
    """Per leg: the contacts' columns, the foot points' joint indices (ankle first) and
    the IK chain (:func:`.footlock.leg_chain`)."""
    from .footlock import leg_chain

    skel = motion.skeleton
    out = []
    for leg in dict.fromkeys(contacts.leg_labels):
        cols = [i for i, g in enumerate(contacts.leg_labels) if g == leg]
        pts = [skel.index(contacts.feet[i]) for i in cols]
        chain, order = leg_chain(skel, pts)
        out.append(([cols[k] for k in order], [pts[k] for k in order], chain))
    return out


def _channel_map(motion: Motion, cols: list[int]) -> np.ndarray:
    """(3, 3): the root's world displacement per unit of each translation channel."""
    base = motion.frames[:1]
    probe = np.repeat(base, 4, axis=0)
    for k, c in enumerate(cols):
        probe[k + 1, c] += 1.0
    p = motion.with_frames(probe).positions().positions[:, 0]
    return (p[1:] - p[0]).T


def close_stands(
    motion: Motion,
    feet: tuple[str, ...],
    stands: list[tuple[int, int]],
    *,
    cycle: float,
    bounds: tuple[np.ndarray, ...] | None = None,
    references: list[Motion] | None = None,
    plausibility_cache: dict | None = None,
    analysed: bool = False,
    limit: float | np.ndarray | None = None,
) -> StandOutcome:
    """Close the feet of each stand that follows a stride (see the module's text).

    Parameters
    ----------
    motion : Motion
        A generated motion with a 6-channel root, its feet carried and pinned.
    feet : tuple of str
        Foot points, two per leg (:func:`~cyclecoord.quality.legs.find_feet`).
    stands : list of (int, int)
        Frame ranges ``[a, b)`` of the stands (IDLEs at one pose).
    cycle : float
        The gait's leg cycle (seconds) before the stands: a step takes half of it,
        within :data:`STEP_LIMITS`.
    bounds : tuple of ndarray, optional
        Joint ranges the IK keeps to (:func:`~cyclecoord.synthesis.carry.channel_bounds`).
    references : list of Motion, optional
        The training takes: a step that brings two limbs closer than they ever come is
        not taken (the stand keeps its stance).  Without them no limb is checked.
    plausibility_cache : dict, optional
        Shared with the caller's other checks of this motion
        (:func:`~cyclecoord.quality.plausibility.check_plausibility`'s ``cache``).
    analysed : bool, default False
        ``motion`` and ``references`` are in the analysis rig (a latent model's are).
    limit : float or ndarray of shape (T,), optional
        Joint acceleration relative to the root (length units/s^2, as
        :func:`~cyclecoord.synthesis.carry.lock_where_clean` takes it): a step that takes a
        frame past it, and past what the motion given had there, is not made (the stand
        keeps its stance).  Without it no acceleration is checked.

    Returns
    -------
    StandOutcome
    """
    from ..periodic.root import root_layout
    from ..quality.contacts import foot_contacts

    layout = root_layout(motion)
    if layout is None or not stands or motion.skeleton is None:
        return StandOutcome(motion)
    try:
        contacts = foot_contacts(motion, feet)
        legs = _legs(motion, contacts)
    except CycleCoordError:
        return StandOutcome(motion)
    if len(legs) != 2 or any(len(pts) < 1 for _, pts, _ in legs):
        return StandOutcome(motion)  # (a quadruped's stop is not a biped's closing step)
    fps = motion.fps
    span = 0.5 * cycle if np.isfinite(cycle) and cycle > 0 else STEP_LIMITS[1]
    n_step = int(round(np.clip(span, *STEP_LIMITS) * fps))
    merged: list[list[int]] = []  # (stands one after another are one stand)
    for a, b in sorted(stands):
        if merged and a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], b)
        else:
            merged.append([a, b])
    out = motion
    closed, kept, gaps = [], [], []
    for a, b in merged:
        b = min(b, out.n_frames)
        got = _close_one(out, contacts, legs, layout, a, b, n_step, bounds)
        if isinstance(got, str):
            if got:
                kept.append((a, got))
            continue
        if limit is not None and (why := _pops(out, got[0], limit, a, b)):
            kept.append((a, why))
            continue
        if references:
            from .carry import _crossed

            before = _crossed(out, references, plausibility_cache, analysed=analysed)
            after = _crossed(got[0], references, plausibility_cache, out, analysed=analysed)
            if (after & ~before)[a:].any():
                kept.append((a, "its step brought two limbs closer than the training takes "
                                "ever do"))
                continue
        out, gap = got
        closed.append((a, b))
        gaps.append(gap / contacts.leg_length)
    return StandOutcome(out, closed, kept, gaps)


def _pops(given: Motion, stepped: Motion, limit, a: int, b: int) -> str:
    """Why the step of the stand ``[a, b)`` is not made when it takes a frame from the
    stand's to two after it past ``limit`` and past the motion given there ("" when it
    does not).  The legs' solve can meet a joint's range at the end of a near-straight
    leg and leave it in one frame: a Bandai walk's knee held straight at its bound for
    three frames of a closing step bent 30 degrees in the next (2.0x its p99)."""
    from .carry import _accel

    lo, hi = max(0, a - 1), min(b + 2, given.n_frames)
    before, after = _accel(given)[lo:hi], _accel(stepped)[lo:hi]
    lim = np.broadcast_to(np.asarray(limit, dtype=float), (given.n_frames,))[lo:hi]
    bad = np.flatnonzero((after > lim) & (after > 1.05 * before))
    if not bad.size:
        return ""
    k = int(bad[np.argmax(after[bad] / lim[bad])])
    return (f"its step made a joint accelerate {after[k] / lim[k]:.1f}x the limit at frame "
            f"{lo + k}")


def _close_one(motion, contacts, legs, layout, a, b, n_step, bounds):
    """One stand's closing (and opening) step: ``(motion, gap)``, or why not ("" when
    the stand does not follow a stride).  Worked out on the stand and the second and a
    half before it; the frames after it are moved by what the feet stepped."""
    before = int(round(0.5 * motion.fps))
    follows = b < motion.n_frames
    if b - a < n_step * (2 if follows else 1) + int(round(0.2 * motion.fps)):
        return ""
    w0 = max(0, a - 3 * before)
    got = _close_part(motion[w0:b], contacts, legs, layout, a - w0, n_step, bounds, follows)
    if isinstance(got, str):
        return got
    part, gap_len, move = got
    frames = np.array(motion.frames, dtype=float)
    frames[w0:b] = part.frames
    if follows:
        cols = [layout.column("t" + ax) for ax in "xyz"]
        per = _channel_map(motion, cols)
        frames[b:, cols] += np.linalg.lstsq(per, move, rcond=None)[0]
    return motion.with_frames(frames), gap_len


def _close_part(motion, contacts, legs, layout, a, n_step, bounds, follows):
    """:func:`_close_one` on ``motion`` whose stand runs from ``a`` to its end:
    ``(motion, gap, move)`` or why not."""
    from .._kinematics import world_transforms
    from .carry import STAND_AFTER

    T, fps, up = motion.n_frames, motion.fps, contacts.up
    b = T
    horiz = [k for k in range(3) if k != up]
    before = int(round(0.5 * fps))
    wpos, wrot = world_transforms(motion)
    root = wpos[:, 0]
    travel = np.zeros(3)
    travel[horiz] = root[a, horiz] - root[max(0, a - 2 * before), horiz]
    moving = np.linalg.norm(travel) >= 0.1 * contacts.leg_length
    if not moving and (follows or len(legs[0][1]) < 2):
        return ""  # (not stepping before the stand, and frames after it: see the module)
    # where the feet stand once the stand has settled (the body still travels, easing to
    # a stop, over its first STAND_AFTER s, and a run stopped in its flight lands there)
    settled = min(a + int(round(STAND_AFTER * fps)), b - 1)
    # forward: square to the hips, the way the body travelled (the root's last half
    # second of a synthetic walk's stop swayed more sideways than it went on), or where
    # the toes point for a stand that did not travel before it
    across = wpos[settled, legs[1][2][0]] - wpos[settled, legs[0][2][0]]
    f = np.zeros(3)
    f[horiz] = [-across[horiz[1]], across[horiz[0]]]
    way = travel if moving else sum(
        wpos[settled, pts[-1]] - wpos[settled, pts[0]] for _, pts, _ in legs)
    if np.linalg.norm(f) < 1e-9 or abs(f @ way) < 1e-9:
        return ""
    f *= np.sign(f @ way) / np.linalg.norm(f)
    ankles = [wpos[settled, pts[0]] for _, pts, _ in legs]
    ahead = [float(p @ f) for p in ankles]
    lead = int(np.argmax(ahead))
    trail = 1 - lead
    gap_len = ahead[lead] - ahead[trail]
    if gap_len < TOGETHER * contacts.leg_length:
        return ""  # already together
    gap = gap_len * f
    # side by side at least the hips' width apart, each foot on its own side (stepped
    # straight forward, a narrow walk's trailing foot ran into the other shin)
    side = np.zeros(3)
    side[horiz] = [-f[horiz[1]], f[horiz[0]]]
    hips = [float(wpos[settled, chain[0]] @ side) for _, _, chain in legs]
    lat = float((ankles[trail] - ankles[lead]) @ side)
    sign = np.sign(hips[trail] - hips[lead]) or np.sign(lat) or 1.0
    wide = sign * max(abs(lat), abs(hips[trail] - hips[lead])) - lat
    move = gap + wide * side  # what the trailing foot travels, and the motion after
    # flat heights: each foot point's lowest (5th percentile) over the stride before
    lo = max(0, a - 3 * before)
    if moving:
        flat = {p: float(np.percentile(wpos[lo:a, p, up], 5)) for _, pts, _ in legs
                for p in pts}
    else:  # (no stride before: the height each point rests at when planted)
        flat = {p: float(contacts.contact_level[c]) for cols, pts, _ in legs
                for c, p in zip(cols, pts)}
    t = np.arange(T)
    close = _ease((t - a) / n_step)  # 0 -> 1 over the closing step
    # (the opening step lands on the stand's last frame, in the pose the motion after it
    # goes on from: landing on the frame after, the last frame's foot hung 1 % of a leg
    # above it, and a leg near straight there bent its knee 13 degrees more than that
    # frame's)
    u_open = (t - (b - n_step)) / (n_step - 1.0)
    opening = _ease(u_open) if follows else np.zeros(T)
    # sideways the closing foot moves out early and the opening one in late: each passes
    # the other leg beside it
    close_side = _ease(2.0 * (t - a) / n_step)
    opening_side = _ease(2.0 * u_open - 1.0) if follows else np.zeros(T)
    settle = close * (1.0 - opening)  # heights flat and pelvis raised, then back
    swing = np.sin(np.pi * np.clip((t - a) / n_step, 0, 1))
    swing_out = np.sin(np.pi * np.clip(u_open, 0, 1)) if follows else 0 * t
    # the feet's targets (they do not depend on the root)
    rows = np.arange(a, b)
    targets = []
    for k, (_, pts, _) in enumerate(legs):
        own = wpos[rows][:, pts]  # (n, P, 3): where the foot is, eased to its stand
        base = wpos[settled, pts][None]
        if k == trail:
            tg = own + close[rows, None, None] * (base + gap - own) + close_side[
                rows, None, None] * (move - gap)
            clear = swing[rows]
        else:
            tg = own + close[rows, None, None] * (base - own) + opening[
                rows, None, None] * gap + opening_side[rows, None, None] * (move - gap)
            clear = swing_out[rows]
        # the opening step ends where the motion after the stand has the foot (moved by
        # the step): a foot that shifted over the stand in the motion given jumped there
        # (7.9x the median acceleration at a random subject 35 script's IDLE's end)
        tg = tg + opening[rows, None, None] * (own - base)
        for m, p in enumerate(pts):  # heights: eased to the flat foot's, the step's lift
            y = own[:, m, up]
            tg[:, m, up] = y + settle[rows] * (flat[p] - y) + (
                STEP_CLEARANCE * contacts.leg_length * clear)
        targets.append((tg, clear))
    # the root: half the gap over the closing step, the other half over the opening one
    # (and the rest of the motion by the whole gap), raised towards its mid-stance height
    # as far as the legs reach (their longest hip-to-ankle span in the stride before)
    world = (0.5 * close + 0.5 * opening)[:, None] * move[None, :]
    stride = root[max(0, a - before) : a, up]
    rise = max(0.0, float(stride.max() - root[a, up])) if moving and stride.size else 0.0
    world[:, up] += rise * settle
    cols = [layout.column("t" + ax) for ax in "xyz"]
    per = _channel_map(motion, cols)
    frames = np.array(motion.frames, dtype=float)
    frames[a:, cols] += np.linalg.lstsq(per, world[a:].T, rcond=None)[0].T
    mpos, _ = world_transforms(motion.with_frames(frames))
    over = np.zeros(rows.size)
    reach = slice(lo, a) if a > lo else slice(a, a + 1)  # (the stride before, or the stand)
    for (_, pts, chain), (tg, _) in zip(legs, targets):
        span = np.linalg.norm(wpos[reach, pts[0]] - wpos[reach, chain[0]], axis=1).max()
        hip = mpos[rows, chain[0]]
        flat_d = np.linalg.norm((tg[:, 0] - hip)[:, horiz], axis=1)
        top = tg[:, 0, up] + np.sqrt(np.maximum((0.99 * span) ** 2 - flat_d**2, 0.0))
        over = np.maximum(over, hip[:, up] - top)
    if over.max() > 0:
        from scipy.ndimage import gaussian_filter1d, maximum_filter1d

        w = max(1, n_step // 4)
        drop = gaussian_filter1d(maximum_filter1d(over, 2 * w + 1), w / 2.0, mode="nearest")
        # eased in from the stand's first frame, whose pose is the motion's own and
        # reaches its feet: a leg straight there is over the margin's 0.99 of its span,
        # and a Bandai walk stopped from an in-step blend had its pelvis lowered 0.9 cm
        # in a frame, its knee bent 15 degrees (1.6x the walk's p99 of acceleration)
        lower = np.zeros((T, 3))
        lower[rows, up] = -np.maximum(drop, over) * _ease((rows - a + 1) / (w + 1.0))
        if follows:  # (and out to its last frame, which the motion after goes on from)
            lower[rows, up] *= _ease((b - rows) / (w + 1.0))
        frames[:, cols] += np.linalg.lstsq(per, lower.T, rcond=None)[0].T
    moved = motion.with_frames(frames)
    held = (rows >= a + n_step) & (rows < (b - n_step if follows else b))
    worst = _solve_legs(moved, frames, legs, targets, rows, held, horiz, contacts.leg_length,
                        bounds, motion.frames[b - 1])
    if worst > REACH_TOLERANCE:
        return f"the legs could not reach the closed stance: {worst:.2f} leg lengths short"
    return motion.with_frames(frames), gap_len, move


#: Degrees a leg's angle may turn per frame (at 30 fps) in a stand's opening step,
#: solved frame by frame: a Bandai run's knee and ankle, at the edge of the training
#: range, otherwise hopped to another solution in one frame (the ankle 35 degrees).
OPENING_TURN = 8.0


def _miss(got, tg, wt, clear) -> np.ndarray:
    """Per frame and foot point, how far ``got`` is from the targets ``tg`` (length
    units; a toe within the ankle's range and a foot in the air weigh less)."""
    miss = np.linalg.norm((got - tg) * (wt >= 1), axis=-1)
    miss[:, 1:] *= 0.5  # (a toe within the ankle's range pitches the foot a little)
    return miss / np.where(clear > 0.1, 3.0, 1.0)[:, None]  # (in the air, off its path)


def _solve_legs(moved, frames, legs, targets, rows, held, horiz, scale, bounds, end) -> float:
    """Both legs of ``moved`` (its root placed) solved onto their ``targets`` on ``rows``,
    written into ``frames``; the held frames kept on the landing's foot points, the
    opening step ending on the stand's own last pose ``end`` (a frame of channel values).
    Returns the worst miss (leg lengths; a foot in the air and a toe weigh less)."""
    from .._kinematics import world_transforms
    from .footlock import _box, _LegIK, _solve

    mpos, mrot = world_transforms(moved)
    worst = 0.0
    for (_, pts, chain), (tg, clear) in zip(legs, targets):
        ik = _LegIK(moved, chain, pts, mrot, mpos)
        # the ankle is placed; the toe is asked for its flat height, its direction left a
        # little free (the foot's pitch in the stride made it nearer the ankle)
        wt = np.ones(tg.shape)
        wt[:, 1:, horiz] = TOE_FREEDOM
        # the steps' frames (and the first held one); the held frames from that one's pose
        first = int(np.argmax(held)) if held.any() else -1
        moving = ~held
        if first >= 0:
            moving[first] = True
        late = moving & (rows > rows[held][-1]) if first >= 0 else np.zeros_like(held)
        some = rows[moving]
        q = _solve(ik, some, tg[moving], wt[moving], scale,
                   box=_box(ik, some, bounds))
        for v, (_, _, c) in enumerate(ik.vars):
            frames[some, c] = q[:, v]
        got = ik.positions(q, some)
        miss = _miss(got, tg[moving], wt[moving], clear[moving])[~late[moving]]
        worst = max(worst, float(miss.max()) / scale)
        if first < 0:
            continue
        # between the steps the foot stays exactly where it landed: every point held
        # (the toe's loose direction let the foot swivel a centimetre as the body
        # swayed, read as a slide), solved from the landing's pose
        k = int(np.flatnonzero(rows[moving] == rows[first])[0])
        sub = rows[held]
        for v, (_, _, c) in enumerate(ik.vars):
            frames[sub, c] = q[k, v]
        ik = _LegIK(moved.with_frames(frames), chain, pts, mrot, mpos)
        land = np.repeat(got[k][None], sub.size, axis=0)
        q = _solve(ik, sub, land, np.ones(land.shape), scale, box=_box(ik, sub, bounds))
        for v, (_, _, c) in enumerate(ik.vars):
            frames[sub, c] = q[:, v]
        worst = max(worst, float(np.linalg.norm(ik.positions(q, sub) - land, axis=-1).max())
                    / scale)
        if late.any():
            worst = max(worst, _opening(moved, frames, ik, chain, pts, mrot, mpos, rows,
                                        late, q[-1], tg, wt, clear, scale, bounds, end))
    return worst


def _opening(moved, frames, ik, chain, pts, mrot, mpos, rows, late, prev, tg, wt, clear,
             scale, bounds, end) -> float:
    """The opening step after the held frames, as solved with the closing one from the
    motion's own poses, but a frame that hops from the one before (a loose toe bent
    another way; a knee and ankle at the edge of the training range taking another
    solution: a Bandai run's ankle turned 35 degrees in one frame, 2.4x its p99), or
    strays from the way to the stand's own last pose ``end`` (the legs the motion after
    the stand goes on from), solved again within a box: at most :data:`OPENING_TURN`
    from the frame before, and within reach of ``end`` at that rate.  Capped from the
    frame before alone, a Bandai run's step lagged and its leg turned the rest of the
    way into the frame after (1.36x its p99; 1.21x kept within reach of ``end``).
    Written into ``frames``; returns the worst miss of the step's frames (leg lengths).
    """
    from .footlock import _box, _LegIK, _solve

    cols = [c for _, _, c in ik.vars]
    idx = np.flatnonzero(late)
    home = np.asarray(end, dtype=float)[cols]
    # frames from the one before the step's first to the frame after the stand
    n = rows[-1] + 1 - (rows[idx[0]] - 1)
    rate = np.maximum(OPENING_TURN * 30.0 / moved.fps, np.abs(prev - home) / n)
    for i in idx:
        row = rows[i : i + 1]
        got = frames[row[0], cols]
        left = rows[-1] + 1 - row[0]  # frames to the one after the stand
        lo = np.maximum(prev - rate, home - rate * left)
        hi = np.minimum(prev + rate, home + rate * left)
        if (got < lo).any() or (got > hi).any():
            frames[row[0], cols] = np.clip(got, lo, hi)
            ik = _LegIK(moved.with_frames(frames), chain, pts, mrot, mpos)
            box = _box(ik, row, bounds) or (np.full((1, prev.size), -np.inf),
                                            np.full((1, prev.size), np.inf))
            box = (np.clip(box[0], lo, hi), np.clip(box[1], lo, hi))
            got = _solve(ik, row, tg[i : i + 1], wt[i : i + 1], scale, box=box)[0]
            frames[row[0], cols] = got
        prev = got
    # in the air, each frame a quarter of the way to its neighbours: re-solved within the
    # box, a foot's loose roll hopped from edge to edge (8 degrees back and forth)
    air = idx[(clear[idx] > 0.1) & (idx > idx[0]) & (idx < idx[-1])]
    if air.size:
        q = frames[np.ix_(rows, cols)]
        frames[np.ix_(rows[air], cols)] = 0.25 * q[air - 1] + 0.5 * q[air] + 0.25 * q[air + 1]
    ik = _LegIK(moved.with_frames(frames), chain, pts, mrot, mpos)
    steps = rows[late]
    got = ik.positions(frames[np.ix_(steps, cols)], steps)
    return float(_miss(got, tg[late], wt[late], clear[late]).max()) / scale
