"""Feet that carry the body: the root's ground track of a generated motion from its feet.

A generated pose sequence (a motion graph's path, a latent particle's) comes with a root
velocity taken from the training frames nearest it; the feet, made by the pose alone,
do not agree with it and glide.  :func:`carry_by_feet` moves the root instead as the foot
on the ground carries it, as the periodic pipeline's cycles do
(:func:`~cyclecoord.periodic.root.planted_ground`,
:func:`~cyclecoord.periodic.clip.anchor_to_feet`):

* contact is the height of each foot point above its own ground level, not its speed
  (:func:`~cyclecoord.quality.contacts.foot_contacts` with ``speed=None``): a gliding foot
  is on the ground and must stop gliding.  Height is unchanged by the ground track, so one
  search serves;
* among the points in contact the lowest carry the body (weights fall off over
  :data:`LOWNESS` leg lengths above the lowest point), so a stride flattened by the latent
  space does not let the swinging foot drag the root back;
* where no point is in contact (a run's flight), or the lowest point moves up or down
  faster than :data:`VERTICAL_SPEED` (a foot landing or lifting off a few centimetres
  above the floor), the root keeps its own step;
* so it does where the low point goes over the ground, with the root's own step, faster
  than :data:`AGREEMENT` of the root's speed for a moment: a foot still swinging forward
  as it lands is not yet bearing weight (:func:`support`);
* frames of an asked hold (``hold``) stand: their ground steps fade to 0 over
  :data:`STAND_AFTER` seconds;
* no foot below the floor: the root is raised, smoothly, where the lowest foot point
  (toe end sites included) would go under ``floor``.

:func:`lock_where_clean` then pins the weight-bearing points (:attr:`Support.planted`)
by a leg IK (:func:`~cyclecoord.synthesis.footlock.lock_feet`) where it makes no joint
accelerate past the limit, and says where it could not.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from ..errors import CycleCoordError
from ..motion import Motion
from ..quality.contacts import FootContacts

__all__ = [
    "AGREEMENT",
    "carry_by_feet",
    "channel_bounds",
    "lock_where_clean",
    "LockOutcome",
    "LOWNESS",
    "STAND_AFTER",
    "Support",
    "support",
    "VERTICAL_SPEED",
]

#: Height (leg lengths) over the lowest foot point at which a point's share of carrying
#: the body falls to 1/e (and over the contact band at which the feet's share does).
LOWNESS = 0.01
#: Height band (leg lengths) above a point's ground level that counts as contact.
CONTACT_BAND = 0.05
#: Vertical speed (leg lengths/s) of the lowest foot point above which its share of
#: carrying the body falls off (to 1/e at twice this speed): a foot coming down to land
#: or lifting off is not yet, or no longer, planted.  Chosen on the shared runs (root
#: speed over the capture's and support-foot slip over the captures', latent runs as
#: medians over five script seeds):
#:
#: ======  ====================  ====================  ===================  ===================
#: gate    captured Bandai run   143_01 graph 600 fr   143_01 latent run    Bandai latent run
#:         carried: root         slip / root           slip / root          slip / root
#: ======  ====================  ====================  ===================  ===================
#: none    0.59                  0.02 / 0.80           1.90 / 0.37          1.75 / 0.49
#: 0.5     0.60                  1.04 / 0.92           1.69 / 0.59          1.94 / 0.51
#: 0.3     0.69                  1.47 / 0.97           1.55 / 0.72          2.11 / 0.56
#: 0.15    0.83                  1.65 / 0.98           1.82 / 0.84          2.22 / 0.66
#: ======  ====================  ====================  ===================  ===================
#:
#: Walks change little (root 0.72-0.88 of the captures' at every gate, slip at most 0.12x).
VERTICAL_SPEED = 0.3
#: Gaussian width (s) of the smoothing of the foot points' heights before their vertical
#: speed is read (a generated pose's frame-to-frame jitter is not a foot lifting).
VERTICAL_SMOOTH = 1.0 / 30.0
#: A foot point bears weight only while it goes over the ground (its horizontal speed in
#: the world, with the root's own step) at most this fraction of the root's speed; its
#: share falls off above (to 1/e at 1.5 times it).  The Bandai run carried by its own
#: feet travelled at 0.67x its captured speed: at each foot strike the lowest point is
#: the landing foot, a few centimetres up and still swinging forward, and it held the
#: root back (0.92x with this gate).  Root speed over the captures' and support-foot
#: slip over the captures' (latent runs: medians over five script seeds of
#: ``benchmarks/bench_latent_gait.py``; 143_01 read at 60 fps):
#:
#: ======  ==================  ==================  ==================  =================
#: gate    Bandai latent run   143_01 latent run   Bandai latent walk  143_01 graph
#:         slip / root         slip / root         slip / root         slip / root
#: ======  ==================  ==================  ==================  =================
#: none    2.15 / 0.56         2.36 / 0.61         0.06 / 0.74         0.84 / 0.87
#: 0.8     2.30 / 0.80         2.11 / 0.94         0.06 / 0.89         --
#: 0.5     2.66 / 0.90         2.32 / 1.00         0.07 / 0.92         0.86 / 0.95
#: ======  ==================  ==================  ==================  =================
#:
#: With the lock pinning the weight-bearing points (:class:`Support`, 0.1 s stances),
#: MOVE ahead's tighter path and :data:`GLIDE_SECONDS`, the 0.5 row reads 2.18 / 0.87,
#: 1.86 / 1.01, 0.00 / 0.93 and 0.90 / 0.95.
AGREEMENT = 0.5
#: A point that goes over the ground faster than :data:`AGREEMENT` for longer than this
#: (s) while it is the grounded lowest point, or low and still against the root, is not
#: a landing foot but a stride shorter than the root's step or a held pose: it carries.
#: Without it the paper's 2-D Delaunay field, followed for three times each left-out
#: take of w1 (``graph crossval``), slid 0.67 m/s (0.02 before the agreement gate; 0.30
#: with it).
GLIDE_SECONDS = 0.15
#: Root speed (leg lengths/s) under which :data:`AGREEMENT` is read against this speed
#: instead (a body standing or turning on the spot).
STILL_SPEED = 0.3
#: A point whose weight-bearing figure (lowness, grounded, going with the body; each in
#: 0-1) is over this is pinned by :func:`lock_where_clean`.
LOCK_SUPPORT = 0.5
#: :func:`lock_where_clean` trims the contacts near pops for this many rounds, then
#: unpins whole contacts near them for up to this many more.
TRIM_ROUNDS = 6
WHOLE_ROUNDS = 3
#: An asked hold stands still after this many seconds.
STAND_AFTER = 0.5
#: Gaussian width (s) of the smoothing of the carried track's steps.
SMOOTH = 0.0


def _with_end_sites(pos, names) -> list[int]:
    """Columns of ``pos`` (joint positions) for the joints ``names`` and the end sites
    under them (a toe's tip)."""
    cols = [pos.names.index(f) for f in names]
    return cols + [
        i for i, n in enumerate(pos.names) if n.endswith("/end") and int(pos.parents[i]) in cols
    ]


def _lowest_points(motion: Motion, feet: tuple[str, ...]) -> np.ndarray:
    pos = motion.positions()
    return pos.positions[:, _with_end_sites(pos, feet), 1].min(axis=1)


def carry_by_feet(
    motion: Motion,
    feet: tuple[str, ...] | None = None,
    *,
    floor: float | None = None,
    hold: np.ndarray | None = None,
    share: np.ndarray | None = None,
    smooth: float = SMOOTH,
) -> Motion:
    """The motion with its root's ground track carried by the feet on the ground.

    Parameters
    ----------
    motion : Motion
        A generated motion with a skeleton and a 6-channel root (else returned as is).
    feet : tuple of str, optional
        Foot points (default found, :func:`~cyclecoord.quality.legs.find_legs`).
    floor : float, optional
        Floor height (length units, e.g. the training takes' contact floor): no foot
        point goes under it.  None: the motion's own estimate, and nothing is raised.
    hold : ndarray of bool, shape (T,), optional
        Frames where a hold was asked: the root stands after :data:`STAND_AFTER` s.
    share : ndarray, shape (T - 1,), optional
        How much of each ground step the feet carry (default 1 everywhere).
    smooth : float
        Gaussian width (s) of the smoothing of the carried steps.

    Returns
    -------
    Motion
        Same channels; only the root's translation changes.
    """
    from scipy.ndimage import gaussian_filter1d, maximum_filter1d

    from ..periodic.root import planted_ground, root_layout
    from ..quality.legs import find_feet

    layout = root_layout(motion)
    if layout is None or motion.skeleton is None or motion.n_frames < 3:
        return motion
    try:
        feet = find_feet(motion.skeleton, motion) if feet is None else tuple(feet)
        weights = support(motion, feet, floor).carry
    except CycleCoordError:
        return motion
    cols = [layout.column("tx"), layout.column("tz")]
    own = np.diff(motion.frames[:, cols], axis=0)
    steps = np.diff(planted_ground(motion, layout, feet, weights), axis=0)
    if smooth > 0:
        steps = gaussian_filter1d(steps, smooth * motion.fps, axis=0, mode="nearest")
    w = np.ones(len(steps)) if share is None else np.clip(np.asarray(share, float), 0, 1)
    steps = w[:, None] * steps + (1.0 - w[:, None]) * own
    if hold is not None:
        steps = steps * _moving(np.asarray(hold, bool), motion.fps)[:, None]
    frames = motion.frames.copy()
    frames[:, cols] = motion.frames[0, cols] + np.vstack([[0.0, 0.0], np.cumsum(steps, 0)])
    out = motion.with_frames(frames)
    if floor is not None and hold is not None and np.any(hold):
        ty = layout.column("ty")
        gap = np.maximum(_lowest_points(out, feet) - floor, 0.0)
        frames[:, ty] -= _standing(np.asarray(hold, bool), motion.fps) * gaussian_filter1d(
            gap, STAND_AFTER * motion.fps / 4.0, mode="nearest") / _translation_scale(out, ty)
        out = out.with_frames(frames)
    if floor is not None:
        depth = np.maximum(floor - _lowest_points(out, feet), 0.0)
        if depth.any():
            k = max(1, int(round(0.1 * motion.fps)))
            lift = gaussian_filter1d(maximum_filter1d(depth, 2 * k + 1), k / 2.0, mode="nearest")
            lift = np.maximum(lift, depth)
            ty = layout.column("ty")
            frames[:, ty] += lift / _translation_scale(out, ty)
            out = out.with_frames(frames)
    return out


@dataclass(frozen=True)
class Support:
    """Which foot points carry the body on each frame (:func:`support`).

    Attributes
    ----------
    carry : ndarray, shape (T, F)
        Each point's share of carrying the body (a row sums to at most 1; the rest of
        the step is the root's own).
    planted : ndarray of bool, shape (T, F)
        Points that bear weight on the frame (low, grounded and going with the body):
        what :func:`lock_where_clean` pins.
    contacts : FootContacts
        The height-only contacts the two are read from.
    """

    carry: np.ndarray
    planted: np.ndarray
    contacts: FootContacts


def support(motion: Motion, feet: tuple[str, ...], floor: float | None = None) -> Support:
    """The foot points that carry the body of ``motion`` on each frame.

    A point carries the body while it is among the lowest (its share falls off over
    :data:`LOWNESS` leg lengths above the lowest point), the lowest point is in the
    contact band and not moving up or down faster than :data:`VERTICAL_SPEED`, and the
    point goes over the ground at most :data:`AGREEMENT` of the root's own speed, or
    faster for longer than :data:`GLIDE_SECONDS` as the grounded lowest point or still
    against the root (a short stride, a held pose; a landing foot is a few frames).
    """
    from scipy.ndimage import gaussian_filter1d

    from ..quality.contacts import contact_runs, foot_contacts

    contacts = foot_contacts(motion, feet, speed=None, height=CONTACT_BAND, floor=floor)
    leg = contacts.leg_length
    # the lowest points carry the body (what the support foot is); a point's share falls
    # off with its height over the lowest, and all shares with the lowest point's height
    # over its own ground level once it leaves the contact band (a run's flight)
    y = contacts.height + contacts.contact_level  # absolute heights
    low_share = np.exp(-(y - y.min(axis=1, keepdims=True)) / leg / LOWNESS)
    rel = contacts.height / leg
    low = y.argmin(axis=1)
    rows = np.arange(rel.shape[0])
    grounded = np.exp(-np.maximum(rel[rows, low] - CONTACT_BAND, 0.0) / LOWNESS)
    # ... and with its vertical speed: in a run's flight the lowest point is a foot a few
    # centimetres up, coming down or lifting off, and carrying the body by it held the
    # root back (the Bandai run, carried by its own feet, travelled at 0.59x its speed)
    ys = gaussian_filter1d(y, VERTICAL_SMOOTH * motion.fps, axis=0, mode="nearest")
    vy = np.abs(np.gradient(ys, axis=0))[rows, low] * motion.fps / leg
    grounded = grounded * np.exp(-np.maximum(vy - VERTICAL_SPEED, 0.0) / VERTICAL_SPEED)
    # ... and a point that goes over the ground with the root's own step faster than
    # AGREEMENT of the root's speed is a foot landing or lifting, not one bearing weight
    pos = motion.positions()
    cols = [pos.names.index(f) for f in feet]
    root = pos.positions[:, 0][:, [0, 2]]
    rel_xz = pos.positions[:, cols][:, :, [0, 2]] - root[:, None, :]
    v_root = np.gradient(root, axis=0) * motion.fps
    v_world = np.gradient(rel_xz, axis=0) * motion.fps + v_root[:, None, :]
    pace = np.maximum(np.linalg.norm(v_root, axis=-1), STILL_SPEED * leg)
    over = np.linalg.norm(v_world, axis=-1) / pace[:, None]
    goes_with = np.exp(-np.maximum(over - AGREEMENT, 0.0) / (0.5 * AGREEMENT))
    # a foot landing is a few frames; a point that stays the grounded lowest, or low and
    # still against the root, for longer while it goes over the ground is a stride
    # shorter than the root's step or a held pose (a stalled path): it carries
    still = (rel <= CONTACT_BAND) & (
        np.linalg.norm(v_world - v_root[:, None, :], axis=-1) < AGREEMENT * pace[:, None]
    )
    held = (still | (low_share * grounded[:, None] > LOCK_SUPPORT)) & (goes_with < 0.5)
    for i in range(goes_with.shape[1]):
        for a, b in contact_runs(held[:, i]):
            if b - a > GLIDE_SECONDS * motion.fps:
                goes_with[a:b, i] = 1.0
    on = grounded[:, None] * goes_with
    carry = low_share / low_share.sum(axis=1, keepdims=True) * on
    return Support(carry=carry, planted=low_share * on > LOCK_SUPPORT, contacts=contacts)


def _drop_near(planted: np.ndarray, bad: np.ndarray, pad: int) -> list[tuple[int, int]]:
    """Unpin, in place, every contact of ``planted`` ``(T, P)`` within ``pad`` frames of
    a frame in ``bad``; the spans unpinned."""
    from ..quality.contacts import contact_runs

    spans = []
    for i in range(planted.shape[1]):
        for a, b in contact_runs(planted[:, i]):
            if ((bad >= a - pad) & (bad < b + pad)).any():
                planted[a:b, i] = False
                spans.append((a, b))
    return spans


def _lost(kept: np.ndarray, start: int) -> tuple[int, int]:
    """The frames ``[first, last + 1)`` of a pinned stretch starting at ``start`` that
    ``kept`` (its frames still pinned) unpins."""
    lost = np.flatnonzero(~np.asarray(kept, dtype=bool)) + start
    return int(lost[0]), int(lost[-1]) + 1


def _stays_down(planted: np.ndarray, hold: np.ndarray, late: int | None = None) -> np.ndarray:
    """``planted`` (T, F) with each point, once down within a run of ``hold`` frames,
    down to the run's end: a stand's feet do not lift.  (Left to the contact test, a
    foot came and went with the stand's sway: on an IDLE of a Bandai walk model the pin
    let go where the sway lifted a toe 1-3 cm, the released foot snapped over 0.1 s to
    where the pose had drifted, 3-10 times the acceleration before, and was then left
    unpinned, gliding 0.3-0.7 m/s under a still body.)  With ``late`` (frames), a point
    that first comes down over ``late`` frames into the run (the sway lowering a toe
    after the stand has settled) is not pinned there: pinned, the foot was pressed flat
    within the lock's ease, the toe end at 1.1x the limit of acceleration."""
    from ..quality.contacts import contact_runs

    out = np.array(planted, dtype=bool)
    for a, b in contact_runs(hold):
        for i in range(out.shape[1]):
            down = np.flatnonzero(out[a:b, i])
            if not down.size:
                continue
            if late is not None and down[0] > late and not (a > 0 and out[a - 1, i]):
                out[a:b, i] = False
            else:
                out[a + down[0] : b, i] = True
    return out


#: A leg raised when a stand begins is brought down only from under this height
#: (leg lengths) of its ankle over its contact level (higher, it was lifted on purpose).
LAND_HIGHEST = 0.5


def _landings(motion: Motion, contacts: FootContacts, planted: np.ndarray,
              asked: np.ndarray, low: np.ndarray | None = None,
              floor: float | None = None) -> np.ndarray:
    """(T, F) bool: the stand frames on which a raised leg's ankle is set down.

    A leg none of whose points is pinned once a stand has settled (:data:`STAND_AFTER`
    s in: a run stopped in its flight or swing, a run model has no double support), or
    whose lowest point (``low``, :func:`_leg_lowest`) is then over the contact band above
    ``floor`` (the motion's own contact estimate counted a Bandai heel 13 cm up as down)
    has its ankle lowered to its contact level and held there
    (:func:`_stand_heights`): stopped as they were, the 143_01 jog's stands held a leg
    up for the whole IDLE (median 14 cm over 12 stops; 8 cm set down)."""
    from ..io._limits import depths
    from ..quality.contacts import contact_runs

    land = np.zeros(planted.shape, dtype=bool)
    n = max(1, int(round(STAND_AFTER * motion.fps)))
    skel = motion.skeleton
    tree = depths([j.parent for j in skel.joints])
    depth = {f: tree[skel.index(f)] for f in contacts.feet}
    labels = np.array(contacts.leg_labels)
    for a, b in contact_runs(asked):
        if b - a <= n:
            continue
        for g in dict.fromkeys(contacts.leg_labels):
            cols = np.flatnonzero(labels == g)
            if planted[a + n, cols].any() and (  # (a foot down once the stand settles,
                low is None or floor is None  # and on the floor, not 10 cm over it)
                or low[a + n, cols[0]] - floor <= CONTACT_BAND * contacts.leg_length
            ):
                continue
            i = int(min(cols, key=lambda c: depth[contacts.feet[c]]))
            if 0 < contacts.height[a, i] <= LAND_HIGHEST * contacts.leg_length:
                land[a:b, i] = True
    return land


def _leg_lowest(motion: Motion, contacts: FootContacts) -> np.ndarray:
    """(T, F): for each foot point, the lowest height (along the up axis) of its leg's
    foot points and the end sites under them."""
    pos = motion.positions()
    labels = np.array(contacts.leg_labels)
    out = np.empty(contacts.planted.shape)
    for g in dict.fromkeys(contacts.leg_labels):
        mine = np.flatnonzero(labels == g)
        cols = _with_end_sites(pos, [contacts.feet[i] for i in mine])
        out[:, mine] = pos.positions[:, cols, contacts.up].min(axis=1)[:, None]
    return out


def _stand_heights(contacts: FootContacts, planted: np.ndarray, asked: np.ndarray,
                   land: np.ndarray, low: np.ndarray | None,
                   floor: float | None = None) -> np.ndarray:
    """(T, F) heights asked of a stand's pinned points (:func:`pin_feet`'s ``heights``;
    NaN elsewhere):

    * each run of pinned stand frames: the lowest height it has had since the run began
      (the sway lifted a pinned foot of a walk model's stand 10-20 cm off the floor, held
      only horizontally, while the other bore the body);
    * a landing leg (``land``, :func:`_landings`): lowered from where it is to its
      contact level over :data:`STAND_AFTER` s from where its pin begins (a smoothstep);

    but never lower than puts its leg's lowest point (``low``, :func:`_leg_lowest`: a toe
    end, a heel) on ``floor`` (default the motion's own estimate), nor lower than it is
    where that point is already under it: a point's own height says nothing of the
    foot's pitch, and held at it a foot pitched toe down went on through the floor (on
    subject 35's walk model toe ends 2 cm or more under the training takes' floor on
    15 % of the frames of its stops, 4 % without the heights)."""
    from ..quality.contacts import contact_runs

    out = np.full(planted.shape, np.nan)
    if low is None or not np.any(asked):
        return out
    own = contacts.height + contacts.contact_level[None, :]
    floor = contacts.floor if floor is None else floor
    deepest = own - np.maximum(low - floor, 0.0)
    n = max(1, int(round(STAND_AFTER * contacts.fps)))
    for i in range(planted.shape[1]):
        level = contacts.contact_level[i]
        for a, b in contact_runs(planted[:, i] & asked):
            if land[a, i]:
                u = np.clip(np.arange(b - a) / n, 0.0, 1.0)
                want = level + (1.0 - u * u * (3 - 2 * u)) * contacts.height[a:b, i]
            else:  # (no higher than it has been since: the stand's body is lowered)
                want = np.minimum.accumulate(own[a:b, i])
            out[a:b, i] = np.maximum(want, deepest[a:b, i])
    return out


def _tidy(planted: np.ndarray, shortest: float) -> np.ndarray:
    """``planted`` (T, F) with gaps under ``shortest`` frames closed, then stretches under
    it dropped (short touches toggle and make the legs jitter)."""
    from ..quality.contacts import contact_runs

    out = np.array(planted, dtype=bool)
    for i in range(out.shape[1]):
        runs = contact_runs(out[:, i])
        for (_, b), (a, _) in zip(runs[:-1], runs[1:]):
            if a - b < shortest:
                out[b:a, i] = True
        for a, b in contact_runs(out[:, i]):
            if b - a < shortest:
                out[a:b, i] = False
    return out


def _translation_scale(motion: Motion, col: int) -> float:
    """World units per unit of a root translation channel (1 on ASF and BVH; measured)."""
    moved = motion.frames[:1].copy()
    moved[0, col] += 1.0
    probe = motion.with_frames(np.vstack([motion.frames[:1], moved])).positions().positions
    d = float(np.linalg.norm(probe[1, 0] - probe[0, 0]))
    return d if d > 1e-9 else 1.0


def _standing(hold: np.ndarray, fps: float) -> np.ndarray:
    """(T,) how far each frame stands on the floor: 0 outside holds, easing to 1 over
    :data:`STAND_AFTER` s into each hold and back to 0 over as long after it.  The body
    of a stand is lowered by that share of its lowest foot point's height over the floor:
    a run stopped in its flight stood 10 cm over the floor on both feet (the synthetic
    run; the 143_01 jog's 5-8 cm), the legs too straight for the lock to reach it."""
    from ..quality.contacts import contact_runs

    n = max(1, int(round(STAND_AFTER * fps)))
    out = np.zeros(hold.size)
    t = np.arange(hold.size)
    for a, b in contact_runs(hold):
        rise = np.clip((t - a) / n, 0.0, 1.0) * (t >= a)
        fall = np.clip(1.0 - (t - b + 1) / n, 0.0, 1.0) if b < hold.size else 1.0
        u = np.minimum(rise, np.where(t < b, 1.0, fall))
        out = np.maximum(out, u * u * (3.0 - 2.0 * u))
    return out


def _moving(hold: np.ndarray, fps: float) -> np.ndarray:
    """(T-1,) factor on each ground step: 1 outside holds, easing to 0 over
    :data:`STAND_AFTER` s into each hold (and back to 1 as it ends)."""
    from ..quality.contacts import contact_runs

    factor = np.ones(hold.size)
    n = max(1, int(round(STAND_AFTER * fps)))
    for a, b in contact_runs(hold):
        u = np.clip((np.arange(a, b) - a) / n, 0.0, 1.0)
        factor[a:b] = 1.0 - u * u * (3.0 - 2.0 * u)
    return 0.5 * (factor[1:] + factor[:-1])


@dataclass(frozen=True)
class LockOutcome:
    """What :func:`lock_where_clean` did."""

    motion: Motion
    locked: int  # contacts pinned
    skipped: list[tuple[int, int]]  # frame ranges of contacts left unlocked (a pop)
    line: str


def lock_where_clean(
    motion: Motion,
    limit: float | np.ndarray,
    feet: tuple[str, ...] | None = None,
    *,
    min_duration: float = 0.1,
    blend: float = 0.1,
    bounds: tuple[np.ndarray, ...] | None = None,
    hold: np.ndarray | None = None,
    floor: float | None = None,
    references: Sequence[Motion] | None = None,
    plausibility_cache: dict | None = None,
    analysed: bool = False,
) -> LockOutcome:
    """Pin the planted feet (leg IK) except where the pin makes a pop.

    The weight-bearing points (:attr:`Support.planted`: low, grounded and going with the
    body; on a carried motion the support foot), and on ``hold`` frames (a stand asked
    for, ``(T,)`` bool) every point in the contact band too,
    gaps under ``min_duration`` s closed, are pinned for stretches of at least
    ``min_duration`` s (a run's stance at 30 fps is 5-7 frames: low-and-slow contacts of
    0.2 s pinned none of the Bandai run's).  After locking, where the largest joint
    acceleration (relative to the root) exceeds both ``limit`` (length units/s^2, e.g.
    1.5x the sources' 99th percentile; a number, or one per frame where the frames come
    from sources of different pace, a walk and a run) and what it was before, or a
    channel leaves ``bounds`` (per-channel low and high values and, optionally, which
    channels are angles compared modulo 360: :func:`channel_bounds`, the training takes'
    range widened by :data:`RANGE_MARGIN` degrees) that it kept before, the contact
    around it is unpinned there (its frames within the ease and two frames of it; a
    hold's contact keeps only its frames after :data:`STAND_AFTER`, then what of those is
    clear of the pops; one the hold lengthened falls back to its weight-bearing frames
    first) and the rest locked again, up to :data:`TRIM_ROUNDS` times, then contacts near
    the pops left are unpinned whole (:data:`WHOLE_ROUNDS`).  On a hold's frames the pinned
    points are kept down too and a raised leg is set down (:func:`_stand_heights`),
    no foot point lower than ``floor`` (e.g. the training takes' contact floor; default
    the motion's own estimate).  With ``references`` (the
    captures the motion came from), a pin that brings two limbs closer than those ever
    come (:func:`~cyclecoord.quality.plausibility.check_plausibility`'s new contacts,
    where the motion before pinning had none) counts as a pop: pinned on an IDLE of
    subject 35's walk model, two script seeds in five crossed the feet (toes 0.06 units
    apart against the captures' closest 1.23).  ``plausibility_cache`` is passed to those
    checks (:func:`~cyclecoord.quality.plausibility.check_plausibility` ``cache``), and
    ``analysed`` (the motion and references are in the analysis rig) too.
    """
    from ..quality.contacts import contact_runs
    from ..quality.legs import find_feet
    from .footlock import pin_feet

    asked = np.zeros(motion.n_frames, bool) if hold is None else np.asarray(hold, dtype=bool)
    try:
        feet = find_feet(motion.skeleton, motion) if feet is None else tuple(feet)
        held = support(motion, feet)
        planted = held.planted.copy()
        if asked.any():
            # where a stand was asked, every point in the contact band too: the root is
            # held, so every sway of the pose is a foot speed over the ground (an IDLE's
            # feet glided 0.35 m/s on the Bandai script with the weight-bearing points
            # alone; with the low, slow contacts, 0.41 m/s on subject 35's: they came
            # and went with the sway)
            planted |= held.contacts.planted & asked[:, None]
            planted = _stays_down(planted, asked, late=int(round(STAND_AFTER * motion.fps)))
    except CycleCoordError as exc:
        return LockOutcome(motion, 0, [], f"foot locking: not done ({exc})")
    contacts = held.contacts
    shortest = min_duration * motion.fps
    planted = _tidy(planted, shortest)
    # a stretch the hold's contacts lengthened that pops falls back to its weight-bearing
    # frames before it is dropped
    fallback = _tidy(held.planted, shortest) & planted
    settled = asked.copy()  # a hold's frames once its root stands (STAND_AFTER)
    for a, b in contact_runs(asked):
        settled[a : min(b, a + int(round(STAND_AFTER * motion.fps)))] = False
    low = _leg_lowest(motion, contacts) if asked.any() else None
    # (a stand's raised legs come down)
    land = _landings(motion, contacts, planted, asked, low, floor)
    planted |= land
    if not planted.any():
        return LockOutcome(motion, 0, [], "foot locking: no contact long enough to pin")
    before = _accel(motion)
    limit = np.broadcast_to(np.asarray(limit, dtype=float), before.shape)
    outside_before = _outside(motion.frames, bounds)
    crossed_before = _crossed(motion, references, plausibility_cache, analysed=analysed)
    skipped: list[tuple[int, int]] = []
    result = None
    solved: dict = {}  # the trials' leg solutions: frames asked the same are not solved again
    trials: list[Motion] = []  # the last trial
    pad = int(round(blend * motion.fps)) + 2

    def attempt() -> tuple[Motion, np.ndarray]:
        """``planted`` pinned (on a stand's frames in height too, :func:`_stand_heights`),
        and the frames where that pops, leaves the bounds or crosses limbs anew."""
        trial = pin_feet(motion, replace(contacts, planted=planted), blend=blend, reuse=solved,
                         bounds=bounds, heights=_stand_heights(contacts, planted, asked, land, low,
                                                         floor))
        # from the last trial, which differs on a few frames: positions found on those only
        trial = trials.pop().with_frames(trial.frames) if trials else trial
        trials.append(trial)
        after = _accel(trial)
        bad = (after > limit) & (after > before * 1.05)
        bad |= (_outside(trial.frames, bounds) & ~outside_before).any(axis=1)
        bad |= _crossed(trial, references, plausibility_cache, motion,
                        analysed) & ~crossed_before
        return trial, np.flatnonzero(bad)

    bad = np.zeros(0, dtype=int)  # the last trial's bad frames
    for round_ in range(TRIM_ROUNDS + WHOLE_ROUNDS):
        if round_ >= TRIM_ROUNDS:
            # the rounds of trimming still popped somewhere (each trim's new ease can): the
            # contacts near the last pops go whole, and the rest is pinned if that is clean
            # (seed 5 of the Bandai benchmark script pinned no foot at all, its IDLE
            # gliding 0.12 m/s)
            skipped += _drop_near(planted, bad, pad)
        if not planted.any():
            break
        trial, bad = attempt()
        if not bad.size:
            result = trial
            break
        if round_ >= TRIM_ROUNDS:
            continue
        dropped = False
        for i in range(planted.shape[1]):
            for a, b in contact_runs(planted[:, i]):
                near = bad[(bad >= a - pad) & (bad < b + pad)]
                if not near.size:
                    continue
                dropped = True  # a pop or out of range: ...
                part = (settled[a:b] | fallback[a:b, i]) & planted[a:b, i]
                if part.all():
                    part = settled[a:b] & planted[a:b, i]
                early = not settled[np.clip(near, 0, len(settled) - 1)].any()
                if early and part.any() and not part.all():
                    # ... before a stand settles: the stand's settled part whole, and before
                    # it what bears weight (then the settled part alone)
                    planted[a:b, i] = part
                    fallback[a:b, i] &= part
                    skipped.append(_lost(part, a))
                    continue
                alt = fallback[a:b, i].copy()
                fallback[a:b, i] = False
                if alt.any() and not alt.all():  # ... a lengthened stretch: its own part
                    planted[a:b, i] = alt
                    continue
                if asked[a:b].any():  # ... a stand's stretch: its settled part, ...
                    part = settled[a:b] & planted[a:b, i]
                    if not part.all():
                        planted[a:b, i] = part
                        skipped.append(_lost(part, a))
                        continue
                    # ... then what of it is clear of the pops (below)
                keep = np.ones(b - a, dtype=bool)  # ... else what is clear of the pops
                for f in near:
                    keep[max(f - pad - a, 0) : max(f + pad + 1 - a, 0)] = False
                piece = np.zeros((len(planted), 1), dtype=bool)
                piece[a:b, 0] = keep
                planted[a:b, i] = _tidy(piece, shortest)[a:b, 0]
                skipped.append(_lost(planted[a:b, i], a))
        if not dropped:  # the pops are not at a pin
            result = trial
            break
    spans = sorted(set(skipped))
    where = ", ".join(f"{a}-{b}" for a, b in spans[:6]) + (" ..." if len(spans) > 6 else "")
    if result is None:
        why = (f"pinning made joints accelerate past {_limit_words(limit)} units/s^2 or leave "
               "the training range" + (f" at frames {where}" if spans else ""))
        return LockOutcome(motion, 0, spans, f"foot locking: not done ({why})")
    n_locked = sum(len(contact_runs(planted[:, i])) for i in range(planted.shape[1]))
    line = f"foot locking: {n_locked} contacts pinned"
    if spans:
        line += f"; not at frames {where} (pinning there made a pop or left the training range)"
    return LockOutcome(result, n_locked, spans, line)


#: Degrees a pinned leg's channels may go beyond the training range (as the plausibility
#: check allows).
RANGE_MARGIN = 5.0


def channel_bounds(
    takes, margin: float = RANGE_MARGIN
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-channel range of the takes' frames widened by ``margin`` (root channels free),
    and which channels are joint angles.  An angle's range is taken as the plausibility
    check takes it (:func:`~cyclecoord.quality.plausibility.joint_range_violations`):
    each take unwrapped, all on one turn; :func:`_outside` compares angles modulo 360.
    Plain minima and maxima of the Euler channels let nothing through on a Bandai
    script, whose continuous output sat a turn away from the takes on some joint on
    every frame: the range check was off, and a pinned knee twisted 21 degrees about
    its long axis (the takes' range -0.8 to 0.1)."""
    from ..quality.joint_ranges import _channel_ranges

    frames = np.concatenate([m.frames for m in takes])
    lo, hi = frames.min(axis=0) - margin, frames.max(axis=0) + margin
    for c in takes[0].root_channels():
        lo[c], hi[c] = -np.inf, np.inf
    angle = np.zeros(frames.shape[1], dtype=bool)
    for c, a, b in _channel_ranges(takes[0], takes, margin):
        lo[c], hi[c], angle[c] = a, b, True
    return lo, hi, angle


def _outside(frames: np.ndarray, bounds) -> np.ndarray:
    """(T, C) the channels of ``frames`` out of ``bounds`` (:func:`channel_bounds`; an
    angle on the turn nearest its range's middle)."""
    if bounds is None:
        return np.zeros(frames.shape, dtype=bool)
    lo, hi = bounds[0], bounds[1]
    x = frames
    if len(bounds) > 2 and np.any(bounds[2]):
        a = np.asarray(bounds[2], dtype=bool)
        x = np.array(frames, dtype=float)
        x[:, a] -= 360.0 * np.round((x[:, a] - 0.5 * (lo[a] + hi[a])) / 360.0)
    return (x < lo) | (x > hi)


def _crossed(
    motion: Motion, references, cache: dict | None = None, base: Motion | None = None,
    analysed: bool = False,
) -> np.ndarray:
    """(T,) frames where two limbs come closer than ``references`` ever do (none
    without references); ``base``: the motion ``motion`` pins, checked before with
    ``cache`` (only the legs' bone pairs are measured again); ``analysed`` as
    :func:`~cyclecoord.quality.plausibility.check_plausibility`'s."""
    out = np.zeros(motion.n_frames, dtype=bool)
    if not references:
        return out
    from ..quality.plausibility import check_plausibility

    frames = np.asarray(
        check_plausibility(motion, references, cache=cache, base=base,
                           analysed=analysed).new_contact_frames,
        dtype=int,
    )
    out[frames - int(motion.start_frame)] = True
    return out


def _limit_words(limit: np.ndarray) -> str:
    lo, hi = float(limit.min()), float(limit.max())
    return f"{lo:.3g}" if hi <= lo * 1.0005 else f"{lo:.3g}-{hi:.3g}"


def _accel(motion: Motion) -> np.ndarray:
    """(T,) largest joint acceleration relative to the root, per frame (length units/s^2)."""
    return _joint_accel(motion.positions().positions, motion.fps)


def _joint_accel(points: np.ndarray, fps: float) -> np.ndarray:
    """(T,) largest acceleration relative to the root (point 0) of points ``(T, P, 3)``
    per frame, length units/s^2 (the first and last frame repeat their neighbour's)."""
    rel = points - points[:, :1]
    a = np.linalg.norm(np.diff(rel, 2, axis=0), axis=-1).max(-1) * fps**2
    return np.r_[a[:1], a, a[-1:]]
