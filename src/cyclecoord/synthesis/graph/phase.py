"""A phase-aware field: the gait's circular coordinate keeps the path moving (issue 24).

The paper's field stalls where a walk's trajectory folds over itself in the latent space:
frames going out and frames coming back share a neighbourhood and their velocities
cancel (on set w1 the 2-D paths sat still for 80 frames while the root glided on).  Only
this project has the remedy at hand: the periodic pipeline's circular coordinate
(:func:`cyclecoord.extract`; its re-timed ``phase``, which advances at the capture's
pace) gives every training frame a phase in the gait cycle, and
two frames at one pose but opposite phases are far apart once the phase is part of the
state.

:class:`PhaseField` follows a state ``(x, phase)``:

* every training frame is lifted to ``(x_i, r cos 2 pi phi_i, r sin 2 pi phi_i)`` with
  ``r`` the RMS radius of the latent points times ``weight`` (0.5), so the fold opens into a
  helix-like curve whose strands no longer meet;
* the neighbourhood is the ``k`` nearest lifted frames, weighted by a smooth kernel
  ``(1 - (D / D_k+1)**2)**2`` that reaches 0 at the next frame out: the field changes
  continuously as frames enter and leave the neighbourhood (the paper's ``1 / D**2``
  weights jump from one frame to the next, which made the 4-D paths pop);
* the state moves by the neighbours' training vector and phase rate (never below a
  quarter of the median rate, so the phase always advances), and is pulled by ``pull``
  towards the neighbours' own next states, which keeps it on the training data.

Phases of different takes are put on one origin: each take's coordinate is shifted by
the offset that best matches its poses to the first take's at the same phase.  A take
whose own coordinate fails (a take of little more than one cycle) is matched to the
other takes' cycle instead (:func:`match_phase`): the monotone phase,
advancing about as fast as theirs, whose poses best fit their mean pose at each phase.
The angle of the first two latent coordinates, which dwells and jumps where the latent
curve is not round, is the last resort: for a take with no coordinate whose poses do
not follow the others' cycle, or when no take has one.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.spatial import cKDTree

from ...errors import CycleCoordError, ParameterError
from ...motion import Motion
from ...periodic.windings import unwrap_across_gaps
from .build import MotionGraph
from .paths import MAX_STEP_SCALE, GraphPath

__all__ = [
    "PhaseField", "TakePhases", "take_phases", "align_phases", "match_phase", "match_misfit",
    "follow_phase", "phase_to_target", "phase_across", "phase_to_stand", "stand_at",
    "standing", "amplitude_gain",
]

#: Neighbours of the phase-aware field, the pull per frame towards their next states
#: and the phase circle's radius against the latent points' RMS radius.  Chosen on set
#: w1 (4 starts x 1,200 frames, dims auto) over k 4-16, pull 0.05-0.3 and weight 0.5-2
#: (with the circular coordinate: largest accel 0.54x the sources' p99, knee and hip
#: ranges 0.92-0.93 of theirs; weight 1 or 2 gave 1.2-3.8x, k under 8 up to 2.5x); with
#: the re-timed phase 0.75-0.76x and 0.94-0.97.
K = 12
PULL = 0.1
WEIGHT = 0.5
#: Gaussian width (frames) of the smoothing of a phase-aware path's latent points: each
#: step moves by its own neighbourhood's velocities, and a neighbour entering or leaving
#: kicks the path.  On the Bandai turning walks (dataset-2 011 and 029, 600 frames) the
#: left toe end accelerated 1.57x the takes' 99th percentile once a stride (1.34x at 0.5,
#: knees 0.98 -> 0.96 of the takes' range; 1.04x at 0.75 with knees 0.93); on set w1
#: 0.76 -> 0.58x, legs 0.94 -> 0.93; the 143_01 jog 1.17 -> 1.16x, legs 0.86 unchanged.
PATH_SMOOTH = 0.5
#: Phase bins used to align the takes' phase origins.
BINS = 48
#: Turns of the coordinate a take shorter than two cycles may have (extract asks 1.5).
SHORT_TURNS = 0.75
#: Slowest phase rate kept, as a fraction of the median.
MIN_RATE = 0.25
#: :func:`match_phase`: phase bins, the largest advance per frame against the takes'
#: median one, and the penalty on an advance away from the median (per squared relative
#: deviation, against a pose cost normalised by the cycle's spread).
MATCH_BINS = 96
MATCH_MAX_RATE = 3.0
MATCH_RATE_PENALTY = 0.05
#: A matched phase is kept when the take's poses lie this close to the others' mean pose
#: at their matched phases (:func:`match_misfit`, against the cycle's spread): a gait
#: the others do not have, such as a walk played backwards, matches far off.
MATCH_MAX_MISFIT = 0.25


@dataclass
class TakePhases:
    """Per-take phases (in cycles, unwrapped along frame order) and where they came from."""

    phases: list  # ndarray (T_i,) per take
    source: list  # "coordinate" or "latent angle" per take
    notes: list


def _fill(c: np.ndarray) -> np.ndarray | None:
    """Unwrapped cycles from a coordinate in [0, 1) with NaNs: interpolated inside,
    extrapolated at the median rate outside; None with under 3 known frames."""
    t = np.arange(c.size)
    ok = np.isfinite(c)
    if ok.sum() < 3:
        return None
    # whole cycles across the gaps the pipeline left (a turn it did not count as steady)
    u = unwrap_across_gaps(c[ok], t[ok], forwards=False)
    rate = float(np.median(np.diff(u) / np.diff(t[ok])))
    out = np.interp(t, t[ok], u)
    first, last = t[ok][0], t[ok][-1]
    out[:first] = u[0] - rate * (first - t[:first])
    out[last + 1 :] = u[-1] + rate * (t[last + 1 :] - last)
    return out


def _latent_angle(z: np.ndarray) -> np.ndarray:
    """Fallback phase: the angle of the first two latent coordinates about their mean."""
    a = np.unwrap(np.arctan2(z[:, 1] - z[:, 1].mean(), z[:, 0] - z[:, 0].mean())) / (2 * np.pi)
    return a if a[-1] >= a[0] else -a


def _phase_of(result) -> np.ndarray:
    """The pipeline's re-timed phase (advancing at the capture's pace); its circular
    coordinate where there is none.  The coordinate itself can dwell: on a synthetic walk
    it sat within 0.01 of a turn for 20 frames while the pose moved on, and a path
    following it stalled there for 0.9 s."""
    phase = getattr(result, "phase", None)
    phase = np.asarray([] if phase is None else phase, dtype=float)
    if np.isfinite(phase).sum() >= 3:
        return phase
    return np.asarray(result.coordinate, dtype=float)


def take_phases(takes: Sequence[Motion], latent: Sequence[np.ndarray]) -> TakePhases:
    """Each take's gait phase from the periodic pipeline's circular coordinate.

    A take without a clear circle (:class:`~cyclecoord.errors.NoPeriodicMotionError` and
    the like; each half of the 143_01 jog, about one stride) is matched to the other
    takes' cycle (:func:`match_phase`), with a note; where its poses do not follow that
    cycle (the match stands still) or no take has a coordinate, it gets the angle of its
    first two latent coordinates.  A take's own coordinate is kept even where it dwells
    or jumps for a frame or two (the Bandai backward walk's jumps 6x its median rate
    twice; matched to the forward walk's cycle it would stand still).
    """
    from ...periodic.pipeline import extract

    own: list = []
    notes: list = []
    for i, m in enumerate(takes):
        u, why = None, ""
        for turns in (None, SHORT_TURNS):  # a short take: fewer turns than extract asks
            try:
                kw = {} if turns is None else {"min_turns": turns, "steady": False}
                res = extract(m, random_state=0, **kw)
                # one value per frame of the take (extract drops a reference first frame)
                u = _fill(res.on_frames(_phase_of(res), m))
            except CycleCoordError as exc:
                why = str(exc)
                continue
            if u is None:
                why = "under 3 frames with a phase"
                continue
            if turns is not None:
                notes.append(f"phase of take {i}: circular coordinate of a short take "
                             f"({turns} turns accepted, extract asks 1.5)")
            break
        own.append((u, why))
    good = [i for i, (u, _) in enumerate(own) if u is not None]
    if not good:
        for i, (_, why) in enumerate(own):
            notes.append(f"phase of take {i}: no circular coordinate ({why}); latent angle")
        phases = [_latent_angle(z) for z in latent]
        return TakePhases(align_phases(phases, latent), ["latent angle"] * len(takes), notes)
    aligned = align_phases([own[i][0] for i in good], [latent[i] for i in good])
    phases: list = [None] * len(takes)
    source = ["coordinate"] * len(takes)
    for i, u in zip(good, aligned):
        phases[i] = u
    ref_phase = np.concatenate(aligned)
    ref_z = np.vstack([latent[i] for i in good])
    rate = float(np.median(np.concatenate([np.diff(u) for u in aligned])))
    for i, (u, why) in enumerate(own):
        if u is not None:
            continue
        m = match_phase(latent[i], ref_phase, ref_z, rate)
        if match_misfit(latent[i], m, ref_phase, ref_z) <= MATCH_MAX_MISFIT:
            phases[i], source[i] = m, "matched"
            notes.append(f"phase of take {i}: matched to the other takes' cycle ({why})")
        else:  # not the others' gait (a walk backwards against walks forwards)
            phases[i] = align_phases([ref_phase, _latent_angle(latent[i])],
                                     [ref_z, latent[i]])[1]
            source[i] = "latent angle"
            notes.append(f"phase of take {i}: no circular coordinate ({why}) and its poses "
                         "do not follow the other takes' cycle; latent angle")
    return TakePhases(phases, source, notes)


def match_misfit(
    z: np.ndarray, phase: np.ndarray, ref_phase: np.ndarray, ref_z: np.ndarray,
    bins: int = MATCH_BINS,
) -> float:
    """Mean squared distance of a take's latent points ``z`` from the reference frames'
    mean point at their phases, over the mean squared spread of those mean points about
    their centre (0: on the cycle; about 1 or more: anywhere else)."""
    ref = _binned(np.asarray(ref_phase, dtype=float), np.asarray(ref_z, dtype=float), bins)
    spread = float(((ref - ref.mean(axis=0)) ** 2).sum(axis=1).mean()) or 1.0
    b = np.floor((np.asarray(phase, dtype=float) % 1.0) * bins).astype(int) % bins
    return float(((np.asarray(z, dtype=float) - ref[b]) ** 2).sum(axis=1).mean() / spread)


def match_phase(
    z: np.ndarray,
    ref_phase: np.ndarray,
    ref_z: np.ndarray,
    rate: float,
    bins: int = MATCH_BINS,
) -> np.ndarray:
    """A take's phase matched to other takes' cycle: monotone, in cycles.

    The phase, advancing between 0 and :data:`MATCH_MAX_RATE` times ``rate`` per frame,
    whose poses best fit the reference frames' mean latent point at each phase (a
    dynamic-programming alignment over ``bins`` phase bins; an advance away from
    ``rate`` costs :data:`MATCH_RATE_PENALTY` per squared relative deviation), then
    smoothed over two frames.

    Parameters
    ----------
    z : ndarray, shape (T, d)
        The take's latent points.
    ref_phase : ndarray, shape (N,)
        Phases (in cycles, on the origin wanted) of the reference frames.
    ref_z : ndarray, shape (N, d)
        Their latent points.
    rate : float
        The reference frames' median phase advance per frame (cycles).
    """
    from scipy.ndimage import gaussian_filter1d

    z = np.asarray(z, dtype=float)
    T = z.shape[0]
    ref = _binned(np.asarray(ref_phase, dtype=float), np.asarray(ref_z, dtype=float), bins)
    spread = float(((ref - ref.mean(axis=0)) ** 2).sum(axis=1).mean()) or 1.0

    def cost(t: int) -> np.ndarray:  # (bins,): frame t's pose against each bin's
        return ((ref - z[t]) ** 2).sum(axis=1) / spread

    r = max(float(rate) * bins, 1e-6)  # expected advance, bins a frame
    steps = np.arange(min(int(np.ceil(MATCH_MAX_RATE * r)), bins - 1) + 1)
    pen = MATCH_RATE_PENALTY * ((steps - r) / r) ** 2
    total = cost(0)
    back = np.zeros((T, bins), dtype=np.int16)  # the step taken into each bin
    cols = np.arange(bins)
    for t in range(1, T):
        # arriving at bin b from b - s
        cand = np.stack([np.roll(total, s) + pen[j] for j, s in enumerate(steps)])
        back[t] = np.argmin(cand, axis=0)
        total = cand[back[t], cols] + cost(t)
    b = int(np.argmin(total))
    adv = np.zeros(T)
    for t in range(T - 1, 0, -1):
        s = int(steps[back[t, b]])
        adv[t] = s
        b = (b - s) % bins
    u = (b + 0.5 + np.cumsum(adv)) / bins
    if T > 2:
        u = np.maximum.accumulate(gaussian_filter1d(u, 2.0, mode="nearest"))
    return u


def _binned(phase: np.ndarray, z: np.ndarray, bins: int) -> np.ndarray:
    """Mean latent point per phase bin ``(bins, d)``, empty bins filled circularly."""
    b = np.floor((phase % 1.0) * bins).astype(int) % bins
    out = np.full((bins, z.shape[1]), np.nan)
    for j in range(bins):
        if (b == j).any():
            out[j] = z[b == j].mean(axis=0)
    ok = np.flatnonzero(np.isfinite(out[:, 0]))
    for c in range(z.shape[1]):
        out[:, c] = np.interp(np.arange(bins), ok, out[ok, c], period=bins)
    return out


def align_phases(
    phases: Sequence[np.ndarray], latent: Sequence[np.ndarray], bins: int = BINS
) -> list[np.ndarray]:
    """Shift every take's phase so its poses match the first take's at the same phase."""
    ref = _binned(phases[0], latent[0], bins)
    out = [np.asarray(phases[0], dtype=float)]
    for p, z in zip(phases[1:], latent[1:]):
        b = np.floor((np.asarray(p) % 1.0) * bins).astype(int) % bins
        cost = [np.mean(((z - ref[(b + s) % bins]) ** 2).sum(axis=1)) for s in range(bins)]
        best = int(np.argmin(cost))
        # refine within the bin: a parabola through the neighbouring costs
        c0, c1, c2 = (cost[(best + d) % bins] for d in (-1, 0, 1))
        den = c0 - 2 * c1 + c2
        frac = 0.5 * (c0 - c2) / den if den > 0 else 0.0
        out.append(np.asarray(p, dtype=float) + (best + float(np.clip(frac, -0.5, 0.5))) / bins)
    return out


class PhaseField:
    """The phase-aware field over a motion graph's training frames.

    Parameters
    ----------
    graph : MotionGraph
    phases : sequence of ndarray
        Per take, its frames' phases in cycles (:func:`take_phases`), in the graph's take
        order.
    k : int
    weight : float
        Radius of the phase circle relative to the latent points' RMS radius.
    pull : float
        Fraction per frame by which the state moves to the neighbours' next states.
    """

    name = "phase"

    def __init__(
        self,
        graph: MotionGraph,
        phases: Sequence[np.ndarray],
        k: int = K,
        weight: float = WEIGHT,
        pull: float = PULL,
    ) -> None:
        phi = np.concatenate([np.asarray(p, dtype=float) for p in phases])
        if phi.shape[0] != graph.n_nodes:
            raise ParameterError(
                f"{phi.shape[0]} phases for the graph's {graph.n_nodes} training frames"
            )
        if not 0.0 <= pull < 1.0 or weight <= 0:
            raise ParameterError(f"pull must be in [0, 1) and weight > 0, got {pull}, {weight}")
        self.graph = graph
        self.k = int(min(max(k, 1), graph.n_nodes - 1))
        self.pull = float(pull)
        take = graph.take
        rate = np.zeros_like(phi)
        same = take[1:] == take[:-1]
        fwd = (phi[1:] - phi[:-1]) / 2.0  # half a frame's change, as the training vectors
        rate[:-1][same] = fwd[same]
        last = np.flatnonzero(np.append(~same, True))
        rate[last] = (phi[last] - phi[last - 1]) / 2.0
        med = float(np.median(rate))
        if not med > 0:
            raise ParameterError("the training takes' phases do not advance")
        self.min_rate = MIN_RATE * med
        self.rate = np.maximum(rate, self.min_rate)
        self.unwrapped = phi
        self.phase = phi % 1.0
        z = graph.points
        self.radius = float(weight * np.sqrt(((z - z.mean(axis=0)) ** 2).sum(axis=1).mean()))
        self.tree = cKDTree(self._lift(z, self.phase))

    @property
    def dims(self) -> int:
        return int(self.graph.points.shape[1])

    def _lift(self, x: np.ndarray, phase: np.ndarray) -> np.ndarray:
        a = 2 * np.pi * np.asarray(phase, dtype=float)
        return np.column_stack([x, self.radius * np.cos(a), self.radius * np.sin(a)])

    def neighbours(self, x: np.ndarray, phase: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Indices ``(m, k)`` and kernel weights ``(m, k)`` (rows sum to 1) at states."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        d, idx = self.tree.query(self._lift(x, np.atleast_1d(phase)), k=self.k + 1)
        h = d[:, -1:]
        u = np.where(h > 0, d[:, :-1] / np.where(h > 0, h, 1.0), 0.0)
        w = (1.0 - u**2) ** 2
        w[w.sum(axis=1) <= 0] = 1.0
        return idx[:, :-1], w / w.sum(axis=1, keepdims=True)

    def phase_of(self, x: np.ndarray) -> float:
        """The phase of the training frame nearest a latent point (a start's phase)."""
        i = int(self.graph.tree.query(np.asarray(x, dtype=float).reshape(-1))[1])
        return float(self.phase[i])

    def step(self, x: np.ndarray, phase: float, s: float):
        """One step ``(x', phase', idx, w)`` of length ``s`` (training vectors)."""
        g = self.graph
        idx, w = self.neighbours(x[None], np.array([phase]))
        idx, w = idx[0], w[0]
        v = w @ g.velocities[idx]
        om = float(w @ self.rate[idx])
        nx = x + s * v
        np_ = phase + s * om
        if self.pull:
            tx = w @ (g.points[idx] + s * g.velocities[idx])
            nx = nx + self.pull * (tx - nx)
            a = 2 * np.pi * (self.phase[idx] + s * self.rate[idx])
            tp = np.arctan2(w @ np.sin(a), w @ np.cos(a)) / (2 * np.pi)
            np_ = np_ + self.pull * (((tp - np_ + 0.5) % 1.0) - 0.5)
        return nx, max(np_, phase + s * self.min_rate), idx, w  # the phase always advances


def follow_phase(
    field: PhaseField, start: np.ndarray, n_frames: int, step_scale: float = 2.0,
    phase: float | None = None,
) -> GraphPath:
    """Follow the phase-aware field for ``n_frames`` from a latent start point.

    ``phase`` defaults to the phase of the training frame nearest ``start``.  The path's
    points are smoothed over :data:`PATH_SMOOTH` frames once it is followed (its steps,
    phases and neighbourhoods are the field's own).
    """
    x = np.asarray(start, dtype=float).reshape(-1)
    if x.shape[0] != field.dims or not np.all(np.isfinite(x)):
        raise ParameterError(f"the start must be {field.dims} finite latent coordinates")
    if isinstance(n_frames, bool) or not isinstance(n_frames, (int, np.integer)) or n_frames < 1:
        raise ParameterError(f"n_frames must be a whole number >= 1, got {n_frames!r}")
    s = float(step_scale)
    if not np.isfinite(s) or not 0 < s <= MAX_STEP_SCALE:
        raise ParameterError(
            f"step_scale must be a positive number of at most {MAX_STEP_SCALE:g} training "
            f"steps, got {step_scale!r}"
        )
    from ...io._limits import MAX_FRAMES, check_memory

    if n_frames > MAX_FRAMES:
        raise ParameterError(f"{n_frames:,} frames; at most {MAX_FRAMES:,} are supported")
    # the path, the phases, each step's neighbours and weights
    check_memory(n_frames * (8.0 * field.dims + 8.0 + 16.0 * field.k),
                 f"a path of {n_frames:,} frames")
    p = field.phase_of(x) if phase is None else float(phase)
    pts = np.empty((n_frames, field.dims))
    phases = np.empty(n_frames)
    nbrs = np.zeros((n_frames, field.k), dtype=int)
    wts = np.zeros((n_frames, field.k))
    for t in range(n_frames):
        pts[t], phases[t] = x, p
        x, p, nbrs[t], wts[t] = field.step(x, p, s)
        if not (np.all(np.isfinite(x)) and np.isfinite(p)):
            raise ParameterError(
                f"the path left every finite value at frame {t + 1} (step scale {s:g})"
            )
    if PATH_SMOOTH > 0 and n_frames > 1:
        from scipy.ndimage import gaussian_filter1d

        pts = gaussian_filter1d(pts, PATH_SMOOTH, axis=0, mode="nearest")
    return GraphPath(
        points=pts,
        neighbours=nbrs,
        weights=wts,
        inside=np.ones(n_frames, dtype=bool),
        speed=s / 2.0,
        kind="field:phase:euler",
        phases=phases,
    )


#: :func:`phase_to_target`: the path walks at least this many cycles before it may stop,
#: looks for the target over one more cycle, and eases onto it over the last fraction of
#: a cycle; the target is "in reach" when that ease moves the path by at most
#: :data:`TARGET_REACH` of the latent points' RMS radius.
TARGET_LEAD = 0.25
TARGET_EASE = 0.3
TARGET_REACH = 0.25


def _cycle_frames(field: PhaseField, x: np.ndarray, step_scale: float) -> int:
    """Generated frames per cycle of the gait at latent point ``x`` (its nearest training
    frames' phase rate: a walk's and a jog's cadences differ)."""
    idx = field.graph.tree.query(np.asarray(x, dtype=float).reshape(-1), k=field.k)[1]
    rate = float(np.median(field.rate[np.atleast_1d(idx)])) * float(step_scale)
    return max(2, int(np.ceil(1.0 / rate)))


def phase_to_target(
    field: PhaseField, start: np.ndarray, target: np.ndarray, target_phase: float,
    step_scale: float = 2.0, lead: float = TARGET_LEAD,
) -> tuple[GraphPath | None, float]:
    """A path that walks the gait from ``start`` to the pose ``target`` at
    ``target_phase``: :func:`follow_phase` for a little over a cycle, cut where its state
    (pose and phase, as the field lifts them) comes nearest the target's, its last
    :data:`TARGET_EASE` of a cycle eased onto the target (latent point and phase).

    The paper's shortest graph path (:func:`~.paths.path_to_target`) hops between takes
    and phases through poses that lie near in the latent space: on set w1 a path from one
    take's frame 50 to another's frame 200 went back and forth among four takes in 31
    frames (0.26 s for 1.25 s of the walk between the two poses) and popped 1.91x the
    takes' 99th percentile of acceleration.  This path steps at the captured cadence.
    ``lead``: cycles the path walks at least.

    Returns
    -------
    path : GraphPath or None
        None when the nearest approach is farther than :data:`TARGET_REACH` (a target in
        another gait: the field does not leave the gait it follows).
    miss : float
        The nearest approach, in the latent points' RMS radius.
    """
    x1 = np.asarray(target, dtype=float).reshape(-1)
    cycle = _cycle_frames(field, start, step_scale)
    lead = max(1, int(round(lead * cycle)))
    path = follow_phase(field, start, lead + cycle + 1, step_scale)
    lifted = field._lift(path.points, path.phases)
    goal = field._lift(x1[None], np.array([target_phase]))[0]
    d = np.linalg.norm(lifted[lead:] - goal, axis=1)
    t = lead + int(np.argmin(d))
    scale = field.radius / WEIGHT  # the latent points' RMS radius
    miss = float(np.linalg.norm(path.points[t] - x1)) / scale
    if miss > TARGET_REACH:
        return None, miss
    n = t + 1
    pts, phases = path.points[:n].copy(), path.phases[:n].copy()
    ease = max(1, min(n - 1, int(round(TARGET_EASE * cycle))))
    u = np.clip((np.arange(n) - (n - 1 - ease)) / ease, 0.0, 1.0)
    w = u * u * u * (u * (6.0 * u - 15.0) + 10.0)
    pts += w[:, None] * (x1 - pts[-1])
    dp = ((target_phase - phases[-1] + 0.5) % 1.0) - 0.5
    phases += w * dp
    idx, wts = field.neighbours(pts, phases)
    return GraphPath(
        points=pts, neighbours=idx, weights=wts, inside=np.ones(n, dtype=bool),
        speed=path.speed, kind="field:phase:to-target", phases=phases,
    ), miss


#: A take's frames where it moves (:func:`moving_frames`): its latent speed, averaged over
#: a cycle, at least this fraction of that average's 90th percentile.
MOVING_FRACTION = 0.5


def moving_frames(points: np.ndarray, rate: np.ndarray) -> np.ndarray:
    """``(T,)`` bool: the frames of one take (latent points ``(T, d)`` in frame order, phase
    rate per frame ``(T,)``, cycles per frame) where its pose moves, its latent speed
    averaged over a cycle at least :data:`MOVING_FRACTION` of that average's 90th
    percentile; every frame when that would leave under a cycle.  A phase is extrapolated
    over the stand a take begins with (CMU 69_01 stands for its first 1.3 s): a path
    crossing into the take "in step" there stood still for 0.28 s."""
    from scipy.ndimage import uniform_filter1d

    T = points.shape[0]
    every = np.ones(T, dtype=bool)
    if T < 3:
        return every
    speed = np.linalg.norm(np.gradient(np.asarray(points, dtype=float), axis=0), axis=1)
    cycle = int(round(1.0 / max(float(np.median(rate)), 1e-9)))
    avg = uniform_filter1d(speed, size=max(1, min(T, cycle)), mode="nearest")
    keep = avg >= MOVING_FRACTION * np.percentile(avg, 90)
    return keep if keep.sum() >= min(T, cycle) else every


def standing(field: PhaseField) -> np.ndarray:
    """``(n,)`` bool: the graph's frames where their take stands (not
    :func:`moving_frames`, take by take)."""
    g = field.graph
    still = np.zeros(g.n_nodes, dtype=bool)
    for t in np.unique(g.take):
        rows = np.flatnonzero(g.take == t)
        still[rows] = ~moving_frames(g.points[rows], field.rate[rows])
    return still


def stand_at(field: PhaseField, x: np.ndarray) -> tuple[int, int, int] | None:
    """``(take, first, last)``: the take and frames (its own numbering) of the stand that
    holds the graph frame nearest latent point ``x`` (a stretch where the take's pose
    holds still, :func:`moving_frames`); None where the take moves there."""
    g = field.graph
    node = int(g.tree.query(np.asarray(x, dtype=float).reshape(-1))[1])
    take = np.flatnonzero(g.take == g.take[node])
    moving = ~standing(field)[take]
    i = int(np.flatnonzero(take == node)[0])
    if moving[i]:
        return None
    a = i
    while a > 0 and not moving[a - 1]:
        a -= 1
    b = i
    while b + 1 < take.size and not moving[b + 1]:
        b += 1
    return int(g.take[node]), int(g.frame[take[a]]), int(g.frame[take[b]])


def phase_to_stand(
    field: PhaseField, start: np.ndarray, target: np.ndarray, step_scale: float = 2.0
) -> tuple[GraphPath, int]:
    """A path that walks the start's gait into the stand of pose ``target``, and the
    frame its stand begins: at least one cycle along the gait to the frame of the next
    cycle nearest the target's pose, then, over one more cycle, the gait going on with its
    latent point, neighbours and weights fading (quintic) into the target's: the strides
    shorten, the feet come together and the root's steps fade to the stand's.  A stand no
    capture walks into (CMU 69_01 begins with one) is reached so, not by a jump; the
    caller closes feet the fade leaves apart
    (:func:`~cyclecoord.synthesis.stance.close_stands` over the stand's frames)."""
    x1 = np.asarray(target, dtype=float).reshape(-1)
    cycle = _cycle_frames(field, start, step_scale)
    a = follow_phase(field, start, 3 * cycle + 1, step_scale)
    stop = cycle + int(np.argmin(np.linalg.norm(a.points[cycle : 2 * cycle + 1] - x1, axis=1)))
    v = np.arange(1, cycle + 1) / cycle
    w = v * v * v * (v * (6.0 * v - 15.0) + 10.0)
    nb, wt = field.neighbours(x1[None], np.array([field.phase_of(x1)]))
    keep, n = stop + 1, stop + 1 + cycle
    fade = np.r_[np.zeros(keep), w]
    # the gait goes on under the fade (its pose and steps fading out): frozen at the stop,
    # its latent point halted at once and the joints jerked (1.52x the p99 on 69_01)
    return GraphPath(
        points=(1.0 - fade)[:, None] * a.points[:n] + fade[:, None] * x1,
        neighbours=np.hstack([a.neighbours[:n], np.repeat(nb, n, 0)]),
        weights=np.hstack([(1.0 - fade)[:, None] * a.weights[:n],
                           fade[:, None] * np.repeat(wt, n, 0)]),
        inside=np.ones(n, dtype=bool),
        speed=a.speed,
        kind="field:phase:stop-to-stand",
        phases=a.phases[:n],
    ), keep


def phase_across(
    field: PhaseField, start: np.ndarray, target: np.ndarray, step_scale: float = 2.0,
    later: float = 0.0,
) -> GraphPath | None:
    """A path from ``start`` on one gait to the pose ``target`` on another, in step: the
    start's gait is followed for half a cycle or more (until its phase is one the
    target's take holds early enough), then cross-faded over half a cycle (quintic
    weights, the two paths at one phase) into the target's take, walked to the target
    (:func:`phase_to_target` from that take's frame at the phase the fade begins: where
    the take moves (:func:`moving_frames`), at least three quarters of a cycle before the
    target, else a quarter; else from a stand the take begins with, as late in it as the
    start's next cycle meets a phase there; else, for a target
    under a quarter cycle into its take, from a later cycle, cut at the nearest pose at
    the target's phase and eased onto it).  None when no such walk reaches the target.

    The cross-fade mixes the two gaits' latent points and neighbours (so their roots and
    detail), as the latent method's in-step TRANSITION mixes its two models' poses.
    ``later``: cycles more the start's gait is followed before the fade may begin (another
    try where one fade brought two limbs too close)."""
    g = field.graph
    x1 = np.asarray(target, dtype=float).reshape(-1)
    node = int(g.tree.query(x1)[1])
    cycle = _cycle_frames(field, start, step_scale)
    half = max(1, int(round(0.5 * cycle)))
    first = half + int(round(later * cycle))
    a = follow_phase(field, start, first + half + cycle + 1, step_scale)
    take = np.flatnonzero(g.take == g.take[node])
    u_target = float(field.unwrapped[node])
    u = field.unwrapped[take]
    moving = moving_frames(g.points[take], field.rate[take])
    tol = 1.5 / _cycle_frames(field, x1, step_scale)
    b = None
    # b walks the take to the target: three quarters of a cycle where it moves; a quarter
    # where it moved no longer before the target (a take that stands first); else from as
    # late in its stand as the start's next cycle meets; else (a target under a quarter
    # cycle into its take) from a later cycle, to the nearest pose at the target's phase,
    # eased onto the target
    for n, early in enumerate((moving & (u <= u_target - 0.75),
                               moving & (u <= u_target - 0.25),
                               u <= u_target - 0.75, moving & (u > u_target))):
        found = []  # (join, b0)
        for join in range(first, first + cycle + 1):  # the fade begins once phases meet
            ok = early & (np.abs(((u - float(a.phases[join]) + 0.5) % 1.0) - 0.5) <= tol)
            if ok.any():  # the take's latest frame at the fade's phase (a later cycle's first)
                found.append((join, int(take[ok][np.argmin(u[ok]) if n == 3
                                                 else np.argmax(u[ok])])))
                if n != 2:
                    break
        if not found:
            continue
        # from a stand, the latest of its frames any join meets: the start's gait walks up
        # to a cycle longer, the path stands less (from the first join met, the paths into
        # CMU 69_01 just after its stand stood 0.22-0.28 s from 6 of 10 start and target pairs)
        join, b0 = max(found, key=lambda jb: (float(field.unwrapped[jb[1]]), -jb[0]))
        # (b0 under a cycle before the target: the cut is looked for from before it)
        if n < 3:
            lead = min(0.6, max(0.1, u_target - float(field.unwrapped[b0]) - 0.15))
        else:  # (long enough for the fade: a walk's half cycle is more than a jog's)
            lead = max(0.6, (half + 2) / _cycle_frames(field, g.points[b0], step_scale))
        b, _ = phase_to_target(field, g.points[b0], x1, field.phase[node], step_scale,
                               lead=lead)
        if b is not None and b.points.shape[0] > half + 1:
            break
        b = None
    if b is None:
        return None
    a = GraphPath(points=a.points[: join + half + 1], neighbours=a.neighbours[: join + half + 1],
                  weights=a.weights[: join + half + 1], inside=a.inside[: join + half + 1],
                  speed=a.speed, kind=a.kind, phases=a.phases[: join + half + 1])
    # a's frames join .. join + half and b's 0 .. half are the fade, at one phase
    n = join + b.points.shape[0]
    w = np.ones(n)
    w[:join] = 0.0
    v = np.arange(half + 1) / half
    w[join : join + half + 1] = v * v * v * (v * (6.0 * v - 15.0) + 10.0)

    def padded(x, before, after):
        return np.concatenate([np.repeat(x[:1], before, axis=0), x,
                               np.repeat(x[-1:], after, axis=0)])

    after = n - a.points.shape[0]
    pa, pb = padded(a.points, 0, after), padded(b.points, join, 0)
    ph_a = a.phases[0] + (a.phases[-1] - a.phases[0]) / (a.phases.size - 1) * np.arange(n)
    ph_b = padded(b.phases, join, 0)
    ph_b = ph_b + np.round(ph_a[join] - ph_b[join])  # (b's cycles numbered as a's)
    return GraphPath(
        points=(1.0 - w)[:, None] * pa + w[:, None] * pb,
        neighbours=np.hstack([padded(a.neighbours, 0, after), padded(b.neighbours, join, 0)]),
        weights=np.hstack([(1.0 - w)[:, None] * padded(a.weights, 0, after),
                           w[:, None] * padded(b.weights, join, 0)]),
        inside=np.ones(n, dtype=bool),
        speed=a.speed,
        kind="field:phase:across-to-target",
        phases=(1.0 - w) * ph_a + w * ph_b,
    )


def amplitude_gain(
    field: PhaseField, angles: np.ndarray, fps: float, frames: np.ndarray | None = None
) -> np.ndarray:
    """Per joint angle, how much the field's neighbour averaging narrows the strides.

    A path's pose is a kernel average over its neighbours, which lie on different
    repetitions; where repetitions differ in the size and timing of their extremes, the
    average is narrower than any of them (on the 143_01 jog, two and a half strides,
    the knees came out at 0.87 of the take's range).  Every training frame is averaged
    over its own neighbourhood as a path's pose would be; the gain is the median range
    of the takes over windows of one period over that of the averages
    (:func:`cyclecoord.periodic.clip.window_ranges`, as the periodic pipeline widens its
    averaged cycle), kept in ``[1, MAX_AMPLITUDE_GAIN]``.

    Parameters
    ----------
    field : PhaseField
    angles : ndarray, shape (N, A)
        The training frames' joint angles, in the graph's take order.
    fps : float
        Frame rate (the running median's length against marker glitches).
    frames : ndarray of bool, shape (N,), optional
        Only these training frames (one gait's takes) are measured, over their own period.

    Returns
    -------
    ndarray, shape (A,)
    """
    from ...periodic.clip import MAX_AMPLITUDE_GAIN, spike_frames, window_ranges

    g = field.graph
    idx, w = field.neighbours(g.points, field.phase)
    avg = np.einsum("nk,nka->na", w, np.asarray(angles, dtype=float)[idx])
    keep = np.ones(g.take.size, dtype=bool) if frames is None else np.asarray(frames, bool)
    rate = np.asarray(field.rate, dtype=float)
    rate = rate[keep] if rate.shape == keep.shape else rate
    period = int(round(1.0 / (2.0 * float(np.median(rate)))))  # rate: half a frame's
    take = g.take
    cut = np.flatnonzero(take[1:] != take[:-1]) + 1
    runs = [(a, b) for a, b in zip(np.r_[0, cut].tolist(), np.r_[cut, take.size].tolist())
            if keep[a]]
    spike = spike_frames(fps)
    have = window_ranges(avg, runs, period, spike)
    want = window_ranges(np.asarray(angles, dtype=float), runs, period, spike)
    if have is None or want is None:
        return np.ones(np.asarray(angles).shape[1])
    return np.clip(
        np.where(have > 1e-9, want / np.maximum(have, 1e-9), 1.0), 1.0, MAX_AMPLITUDE_GAIN
    )
