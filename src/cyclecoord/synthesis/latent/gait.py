"""The gait phase of a latent model's training frames, from the periodic pipeline.

:func:`training_gait` runs :func:`cyclecoord.extract` on each training segment and keeps
its re-timed phase (the circular coordinate advancing at the capture's pace), so every
training frame knows where it is in the leg cycle, advancing evenly within a cycle
(:func:`even_phase`).  Each segment's phase is anchored to
the body, not to the coordinate's arbitrary zero: phase 0 is where the first leg's ankle
is furthest ahead of the other's (the first harmonic of their difference along its main
direction), so the phase of a walk and the phase of a run of the same skeleton mean the
same step.  Frames the pipeline left out (NaN) are filled by the segment's period.

A :class:`Gait` maps an unwrapped phase back to a (fractional) training frame of a
segment, wrapping by whole cycles at the segment's ends, which is what lets a MOVE go on
stepping past a segment's end (``{"ahead": seconds}``) and a TRANSITION between two gaits
blend them in step (:meth:`~.commands.Synthesizer.gait_hop`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ...errors import ParameterError
from ...periodic.windings import unwrap_across_gaps
from .influence import pose_points

__all__ = [
    "FADE_TIE", "GAIT_VERSION", "Gait", "MIN_CYCLES", "SEAM_FADE", "SEAM_FADES",
    "choose_seam_fade", "even_phase", "training_gait",
]

#: A segment needs at least this many cycles for its phase to be trusted.
MIN_CYCLES = 1.5
#: Cycles over which a path looping a segment cross-fades across the loop's seam (as far
#: as the segment has frames on both sides) when no other is asked.  Half a cycle before
#: the latent path and the detail looped at one seam; with one seam, a whole cycle took
#: the 143_01 jog's largest acceleration from 1.53x to 1.30x its p99 and its slip from
#: 1.00x to 0.78x the capture's (medians over 15 script seeds), the Bandai run's within
#: 0.04.  Each segment's fade is chosen between this and two cycles when the model is
#: fitted (:func:`choose_seam_fade`).
SEAM_FADE = 1.0
#: Seam cross-fades (cycles, :meth:`Gait.at` ``fade``) a segment's loop chooses between,
#: and the margin within which the shorter wins (:func:`choose_seam_fade`).
SEAM_FADES = (1.0, 2.0)
FADE_TIE = 0.02


@dataclass(frozen=True)
class Gait:
    """Unwrapped, body-anchored phase (cycles) of every training frame of a model.

    Attributes
    ----------
    phase : ndarray, shape (N,)
        NaN on segments without a gait, and on frames over a period before or after a
        segment's steady ones.
    period : ndarray, shape (S,)
        Frames per cycle of each segment (model frames; NaN without a gait).
    segments : ndarray of int, shape (N,)
    fade : ndarray, shape (S,), optional
        Each segment's seam cross-fade in cycles (:func:`choose_seam_fade`); None:
        chosen on use (a model file written before it was kept).
    """

    phase: np.ndarray
    period: np.ndarray
    segments: np.ndarray
    fade: np.ndarray | None = None
    #: ``(segment, id(values)) -> (values, loop)``: :meth:`_loop`'s search, kept while its
    #: values live (a script asks it about a thousand times for the same few arrays)
    _loops: dict = field(default_factory=dict, compare=False, repr=False)

    def has(self, segment: int) -> bool:
        return bool(np.isfinite(self.period[segment]))

    @property
    def usable(self) -> np.ndarray:
        """Segment numbers with a gait."""
        return np.flatnonzero(np.isfinite(self.period))

    def rows(self, segment: int) -> np.ndarray:
        """The segment's frames that have a phase (one stretch: :func:`training_gait`
        leaves frames over a period beyond the steady ones out)."""
        return np.flatnonzero((self.segments == segment) & np.isfinite(self.phase))

    def _loop(
        self, segment: int, values: np.ndarray | None = None
    ) -> tuple[np.ndarray, float, float]:
        """The segment's rows, the start ``s`` of its loop ``[s, s + K)`` and its whole
        cycles ``K``.  With ``values``, the loop is placed where stepping past its end
        jumps back least: the seam is the frame whose values, and the next frame's, are
        nearest the values at the same phases ``K`` cycles earlier (a pose and its
        motion), over ``K`` the segment's whole cycles and one cycle fewer, so that every
        phase of a cycle is a candidate (with ``K`` alone a take of 6.02 cycles had only
        its last half-frame to choose from: the Bandai run's seam jumped 2.2 median
        latent steps and popped at 2.4x the training 99th percentile of acceleration)."""
        if values is not None:
            hit = self._loops.get((segment, id(values)))
            if hit is not None and hit[0] is values:
                return hit[1]
            out = self._search_loop(segment, values)
            self._loops[(segment, id(values))] = (values, out)
            return out
        return self._search_loop(segment, None)

    def _search_loop(
        self, segment: int, values: np.ndarray | None
    ) -> tuple[np.ndarray, float, float]:
        rows = self.rows(segment)
        ph = self.phase[rows]
        lo, span = ph[0], ph[-1] - ph[0]
        K = max(np.floor(span), 1.0)
        if values is None or span < K:
            return rows, lo, K
        idx = np.arange(rows.size, dtype=float)
        best = (np.inf, lo, K)
        for k in (K, K - 1.0) if K >= 2 else (K,):
            late = np.flatnonzero(ph[:-1] >= lo + k)  # the next frame exists
            if not late.size:
                continue
            gap = np.zeros(late.size)
            for step in (0, 1):
                here = rows[late + step]
                early = self._lerp(values, rows[0] + np.interp(ph[late + step] - k, ph, idx))
                gap += np.linalg.norm((values[here] - early).reshape(late.size, -1), axis=1)
            j = int(np.argmin(gap))
            if gap[j] < best[0]:
                best = (float(gap[j]), float(ph[late[j]] - k), k)
        return rows, best[1], best[2]

    def frame_at(self, segment: int, u: np.ndarray, values: np.ndarray | None = None):
        """Fractional training-frame indices (into the model's frames) of unwrapped phases
        ``u`` on ``segment``: a phase the segment holds before its loop's end is played
        as it is; later ones (and any before the segment's start) are shifted by whole
        cycles into the loop, so a path only jumps where it crosses the loop's seam (not
        into the loop from a start before it: on subject 35's walks that first jump
        accelerated the joints 2.0x the training 99th percentile)."""
        rows, lo, K = self._loop(segment, values)
        u = np.asarray(u, dtype=float)
        inside = (u >= self.phase[rows[0]]) & (u < lo + K)
        v = np.where(inside, u, lo + np.mod(u - lo, K))
        return rows[0] + np.interp(v, self.phase[rows], np.arange(rows.size, dtype=float))

    def at(
        self,
        values: np.ndarray,
        segment: int,
        u: np.ndarray,
        fade: float = SEAM_FADE,
        seam: np.ndarray | None = None,
    ) -> np.ndarray:
        """Per-frame ``values`` (latent points, angles, ...) at unwrapped phases ``u``,
        linear between frames, looping the segment by whole cycles at its best seam.

        The seam is chosen on ``seam`` (default ``values``): the synthesizer passes the
        captured frames' angles (:meth:`~.model.LatentModel.frame_angles`) for the latent
        path and every part of the gait detail, so that all of them loop over the same
        strides at the seam where the captured pose jumps least.  (Each chose its own
        seam before: on the 143_01 jog the latent path looped the stride from phase 1.42,
        the captured angles' best seam is at 1.94; over 15 script seeds its slip went to
        at most 1.16x the capture's from 1.66x, subject 35's TRANSITION windows to at most
        1.20x from 1.50x.)

        Around each crossing of the seam (phase ``lo + n K``, ``n >= 1``) the path
        cross-fades over ``fade`` cycles, as far as the segment has frames on both sides,
        from the loop's end played on past the seam to its start played from before it:
        both are captured frames at the same phase, as near as the seam could find, so
        the blend stays between two neighbouring stretches of the data.  (Cross-fading the
        loop's two ends over a whole cycle passed between the cycles, off the data: on
        the synthetic run the particle's likelihood force then threw the pose 3.9x the
        training 99th percentile of acceleration; the jump itself, at the best seam,
        threw the Bandai run's toes 1.6x.)"""
        return self.sampler(segment, u, fade, values if seam is None else seam)(values)

    def sampler(
        self, segment: int, u: np.ndarray, fade: float = SEAM_FADE, seam: np.ndarray | None = None
    ) -> Callable[[np.ndarray], np.ndarray]:
        """:meth:`at` at phases ``u`` for any per-training-frame values: a function of
        the values ``(N, ...)``, the frames and the seam's cross-fade found once (a gait
        step samples a dozen arrays at one set of phases: the path, each part of the
        detail, the GP means).  ``seam`` as :meth:`at`'s (here required)."""
        n = len(self.segments)  # (values are per training frame)
        main = self._weights(self.frame_at(segment, u, seam), n)
        rows, lo, K = self._loop(segment, seam)
        ph = self.phase[rows]
        # how far the loop's end plays on past the seam, and its start back before it
        after = min(0.5 * fade, ph[-1] - (lo + K))
        before = min(0.5 * fade, lo - ph[0])
        near = late = early = w = None
        if after + before > 0:
            u = np.asarray(u, dtype=float)
            c = np.maximum(np.round((u - lo) / K), 1.0)
            d = u - (lo + c * K)  # from the nearest seam crossing
            near = (d >= -before) & (d < after)
            if near.any():
                idx = np.arange(rows.size, dtype=float)
                late = self._weights(rows[0] + np.interp(lo + K + d[near], ph, idx), n)
                early = self._weights(rows[0] + np.interp(lo + d[near], ph, idx), n)
                a = (d[near] + before) / (before + after)
                w = a * a * a * (a * (6.0 * a - 15.0) + 10.0)  # quintic: no jump in accel
            else:
                near = None

        def sample(values: np.ndarray) -> np.ndarray:
            if len(values) != n:
                raise ParameterError(f"gait values of {len(values)} frames; the model has {n}")
            out = self._mixed(values, main)
            if near is None:
                return out
            ww = w.reshape((-1,) + (1,) * (np.ndim(values) - 1))
            out = np.array(out, dtype=float, copy=True)
            out[near] = (1.0 - ww) * self._mixed(values, late) + ww * self._mixed(values, early)
            return out

        return sample

    def _weights(self, frames: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The two training frames either side of fractional ``frames`` (within one
        segment) and the weight of the later."""
        f = np.asarray(frames, dtype=float)
        a = np.floor(f).astype(int)
        b = np.minimum(a + 1, n - 1)
        b = np.where(self.segments[b] == self.segments[a], b, a)
        return a, b, f - a

    @staticmethod
    def _mixed(values: np.ndarray, abw) -> np.ndarray:
        a, b, w = abw
        w = w.reshape((-1,) + (1,) * (np.ndim(values) - 1))
        return (1.0 - w) * values[a] + w * values[b]

    def _lerp(self, values: np.ndarray, frames: np.ndarray) -> np.ndarray:
        return self._mixed(values, self._weights(frames, len(values)))

    def points(self, X: np.ndarray, frames: np.ndarray) -> np.ndarray:
        """Latent points ``(T, q)`` at fractional training frames (linear in between)."""
        return self._lerp(X, frames)


def choose_seam_fade(model, gait: Gait, segment: int) -> float:
    """The cross-fade over the seam of ``segment``'s loop (cycles): of
    :data:`SEAM_FADES`, the one whose looped path (the pose of the path plus the gait
    detail, as joint positions) accelerates least over the cycle each side of the seam,
    the shorter within :data:`FADE_TIE` (a segment without a gait: the first).  A longer
    fade reaches as far as the take has frames, up to a cycle each side.  On the 143_01
    jog (50 frames, its seam crossed every stride) two cycles took the path's largest
    acceleration there down a tenth, and the script's largest from 1.30 [1.23-1.61] to
    1.22 [1.16-1.40] its p99 over 15 seeds (4 seeds over 1.5x to none); on the Bandai run
    both fades read the same, and two cycles had put 2 seeds of 15 over 1.5x.  Chosen
    when the model is fitted and kept in its file: chosen afresh by every script, it was
    a tenth of a script's time."""
    if not np.isfinite(gait.period[segment]):
        return SEAM_FADES[0]  # (nothing loops)
    fa, det = model.frame_angles(), model.detail()["angles"]
    _, lo, K = gait._loop(segment, fa)
    u = lo + K + np.arange(-1.2, 1.2, 1.0 / gait.period[segment])
    costs = []
    for fade in SEAM_FADES:
        pose = model.pose(gait.at(model.X_, segment, u, fade, fa)) + gait.at(
            det, segment, u, fade, fa)
        pts = pose_points(model.to_channels(pose), model.channels_, model.skeleton_)
        costs.append(float(np.linalg.norm(np.diff(pts, 2, axis=0), axis=-1).max()))
    least = min(costs)
    return next(f for f, c in zip(SEAM_FADES, costs) if c <= least * (1.0 + FADE_TIE))


def even_phase(phase: np.ndarray, period: float) -> np.ndarray:
    """An unwrapped phase ``(n,)`` (cycles, one per frame) made to advance evenly within
    each cycle of ``period`` frames: its departure from the straight line through it is
    smoothed by a Gaussian of half a period, which removes what varies within a cycle and
    keeps the take's slower changes of pace.

    The pipeline's re-timed phase advances in stretches of a few frames whose rates differ
    by up to 15-20 % (0.86-1.26 frames a frame on the Bandai run); a MOVE steps the phase
    evenly, so it played the slow stretches up to 1.2x faster than they were captured, at
    the foot strikes, and the toes' acceleration went up with the square of it: 1.62x the
    training 99th percentile where the same path at the captured pace read 1.35x.  Over
    15 script seeds of ``benchmarks/bench_latent_gait.py`` the Bandai run's largest
    acceleration went 1.68x -> 1.56x (medians; its slip 0.88x -> 0.26x the capture's),
    the other gaits' within 0.02 (a straight line for the whole take did as well on the
    Bandai run but not where a take's pace changes: one seed of the subject 35 walks
    then popped at 7.1x).
    """
    phase = np.asarray(phase, dtype=float)
    n = phase.size
    if n < 3 or not np.isfinite(period) or period <= 0:
        return phase.copy()
    from scipy.ndimage import gaussian_filter1d

    k = np.arange(n, dtype=float)
    line = np.polyval(np.polyfit(k, phase, 1), k)
    return line + gaussian_filter1d(phase - line, 0.5 * period, mode="nearest")


def _anchor(model, rows: np.ndarray, phase: np.ndarray, leg_points: tuple[str, str]) -> float:
    """Phase at which the first ankle is furthest ahead of the second (cycles): the phase
    of the first harmonic of their difference along its main direction, ``s ~ cos(2 pi
    (phase - anchor))``.  Subtracting it puts that moment at phase 0 (and it is then 0)."""
    names = list(model.skeleton_.names)
    a, b = (names.index(n) for n in leg_points)
    pts = pose_points(
        model.to_channels(model.angles(model.frames_[rows])), model.channels_, model.skeleton_
    )
    d = pts[:, a] - pts[:, b]
    d = d - d.mean(axis=0)
    _, _, vt = np.linalg.svd(d, full_matrices=False)
    axis = vt[0] * np.sign(vt[0][np.argmax(np.abs(vt[0]))])  # the same sign on every model
    s = d @ axis
    c = np.sum(s * np.exp(2j * np.pi * phase))
    return float(np.angle(c) / (2 * np.pi))


#: The version of :func:`training_gait` a model file's phases come from (``gait_version``);
#: phases from an older one are computed again when first used.  Files without it (written
#: up to 2026-11-28 00:40 UTC) were anchored with the first harmonic's sign flipped, which
#: put phase 0 at a different step in each segment (a Bandai walk and run 0.33 cycles
#: apart, so an in-step TRANSITION blended a walk's left stride with a run's right one:
#: the blend's feet 4.1 units apart against the takes' closest 5.6, and ``animate``
#: refused the script on every seed); version 2 (``gait_anchor``, the same day) still took
#: a gap in the pipeline's steady frames as under a cycle
#: (:func:`~cyclecoord.periodic.windings.unwrap_across_gaps`); version 3 gave a phase to
#: frames any distance before or after the steady ones.
GAIT_VERSION = 4


def _legs(model) -> tuple[str, str] | None:
    from ...errors import CycleCoordError
    from ...quality.legs import find_legs

    try:
        legs = find_legs(model.skeleton_, model.training_motion()).legs
    except CycleCoordError:
        return None
    if len(legs) < 2:
        return None
    return legs[0].points[0], legs[1].points[0]


def training_gait(model) -> Gait:
    """The :class:`Gait` of a :class:`~.model.LatentModel` (segments the periodic pipeline
    finds no cycle in, or shorter than :data:`MIN_CYCLES` cycles, get NaN)."""
    import cyclecoord as cc

    from ...errors import CycleCoordError

    n = model.X_.shape[0]
    segs = np.unique(model.segments_)
    phase = np.full(n, np.nan)
    period = np.full(int(segs.max()) + 1, np.nan)
    legs = _legs(model)
    train = model.training_motion()
    for s in segs:
        rows = np.flatnonzero(model.segments_ == s)
        if legs is None or rows.size < 12:
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                take = train[rows[0] : rows[-1] + 1]
                res = cc.extract(take, require_clear=False)
        except (CycleCoordError, ValueError, np.linalg.LinAlgError):
            continue
        # one value per frame (extract drops a reference first frame, an Xsens T-pose:
        # 625 phases for 626 frames failed the model's fit)
        p = None if res.phase is None else res.on_frames(res.phase, take)
        P = float(res.period_frames)
        if p is None or not np.isfinite(P) or P <= 1 or rows.size < MIN_CYCLES * P:
            continue
        ok = np.isfinite(p)
        if ok.sum() < 3:
            continue
        k = np.arange(rows.size, dtype=float)
        # whole cycles across the gaps the pipeline left (an Xsens walk's turn)
        u = unwrap_across_gaps(p[ok], np.flatnonzero(ok), P)
        # fill the left-out frames along the segment's period, a period beyond the
        # steady frames at most: frames further out are not this gait (an Xsens take
        # stands for 11 s before it walks; looping them, a MOVE ahead from the walk
        # went on to play the standing frames at the walk's cadence)
        full = np.interp(k, k[ok], u)
        first, last = np.flatnonzero(ok)[[0, -1]]
        full[:first] = u[0] - (first - k[:first]) / P
        full[last + 1 :] = u[-1] + (k[last + 1 :] - last) / P
        keep = (k >= first - P) & (k <= last + P)
        if keep.sum() < MIN_CYCLES * P:
            continue
        full[~keep] = np.nan
        full[keep] = even_phase(full[keep], P)
        full[keep] -= _anchor(model, rows[keep], full[keep], legs)
        phase[rows] = full
        period[s] = P
    gait = Gait(phase=phase, period=period, segments=np.asarray(model.segments_))
    fade = np.array([choose_seam_fade(model, gait, k) for k in range(period.size)])
    return Gait(phase=phase, period=period, segments=gait.segments, fade=fade)
