"""Complete windings of a circular coordinate: crossing times, period, re-timed phase.

A circular coordinate found by persistent cohomology goes round once per repetition,
but not at an even pace: the harmonic smoothing of a cocycle concentrates its change
where the loop is thin, so on real walks it can stay almost flat for 40-60 frames and
then jump (a staircase).  Its *crossings* are what it gets right: every time the
unwrapped coordinate passes a level ``k + l`` the motion is at the same place of its
cycle.  This module reads those crossings:

* :func:`crossing_times` gives, for each level, the (fractional) frames at which the
  coordinate first reaches it on each turn (a running maximum makes backward jitter
  harmless; one ``searchsorted`` per level);
* :func:`complete_windings` turns them into the lengths of complete windings (from one
  crossing of a level to the next, inside one stretch of frames), and the period is the
  median of those lengths;
* :func:`retime` gives every frame a phase that is piecewise linear in *time* between the
  crossings of sharp levels (levels the coordinate passes quickly, whose crossing time is
  well defined), each level placed at the fraction of the cycle at which the capture
  reaches it on average.  This phase advances at the capture's own pace: a cycle
  averaged in it takes, in each part, the time the capture takes (no hold-and-snap).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

__all__ = [
    "Windings",
    "crossing_times",
    "complete_windings",
    "retime",
    "edge_taper",
    "phase_average",
    "stretches",
    "unwrap_across_gaps",
]

#: Levels of the coordinate examined for crossings.
N_LEVELS = 32


def stretches(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open runs ``(start, stop)`` of True in a boolean mask."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist()))


def crossing_times(unwrapped: np.ndarray, levels: np.ndarray) -> list[np.ndarray]:
    """Frames (fractional) at which an unwrapped coordinate first reaches ``k + level``.

    Parameters
    ----------
    unwrapped : ndarray, shape (T,)
        Coordinate unwrapped along the frames of one stretch (cycles).
    levels : ndarray, shape (L,)
        Levels in ``[0, 1)``.

    Returns
    -------
    list of ndarray
        For each level, the increasing crossing times in frames from the stretch's first
        frame, linearly interpolated between frames.  The running maximum of the
        coordinate is used, so a crossing is the first time a level is reached.
    """
    u = np.maximum.accumulate(np.asarray(unwrapped, dtype=float))
    out = []
    if u.size < 2:
        return [np.zeros(0) for _ in levels]
    for lv in np.asarray(levels, dtype=float):
        first = np.ceil(u[0] - lv)
        last = np.floor(u[-1] - lv)
        if last < first:
            out.append(np.zeros(0))
            continue
        targets = np.arange(first, last + 1) + lv
        # u is non-decreasing: the first index with u >= target
        i = np.searchsorted(u, targets, side="left")
        i = np.clip(i, 1, u.size - 1)
        lo, hi = u[i - 1], u[i]
        span = np.where(hi > lo, hi - lo, 1.0)
        frac = np.clip((targets - lo) / span, 0.0, 1.0)
        t = i - 1 + frac
        # a target reached exactly at frame 0 is not a crossing inside the stretch
        out.append(t[targets > u[0]])
    return out


@dataclass(frozen=True)
class Windings:
    """The complete windings of a coordinate over one or more stretches of frames.

    Attributes
    ----------
    levels : ndarray, shape (L,)
        Levels examined, in ``[0, 1)``.
    anchors : ndarray of int
        Indices into ``levels`` of the sharp levels the phase is pinned to.
    reference : int
        Index into ``levels`` of the sharpest level; :attr:`lengths` are measured there.
    lengths : ndarray
        Frames taken by each complete winding at the reference level, in time order.
    pooled : ndarray
        Complete winding lengths at every level (the period is their median; a level
        the coordinate passes slowly has a blurred crossing time, which the median
        shrugs off).
    period_frames : float
        Median of :attr:`pooled` (NaN when there is no complete winding).
    spread : float
        ``(p90 - p10) / median`` of :attr:`pooled`: 0 for perfectly regular windings.
    turns : float
        Net turns of the coordinate over all stretches.
    positions : ndarray, shape (A,)
        Fraction of the cycle (from the reference level) at which each anchor is reached
        on average.
    """

    levels: np.ndarray
    anchors: np.ndarray
    reference: int
    lengths: np.ndarray
    pooled: np.ndarray
    period_frames: float
    spread: float
    turns: float
    positions: np.ndarray

    @property
    def n_complete(self) -> int:
        """Number of complete windings at the reference level."""
        return int(self.lengths.size)


def _sharpness(u: np.ndarray, times: list[np.ndarray]) -> float:
    """Mean coordinate speed (cycles per frame) where a level is crossed."""
    if not len(times) or not sum(t.size for t in times):
        return 0.0
    d = np.gradient(np.maximum.accumulate(u)) if u.size > 1 else np.zeros(1)
    idx = np.clip(np.round(np.concatenate(times)).astype(int), 0, u.size - 1)
    return float(np.mean(d[idx]))


def complete_windings(
    unwrapped: np.ndarray,
    runs: list[tuple[int, int]],
    *,
    n_levels: int = N_LEVELS,
    min_anchor_gap: float = 0.04,
) -> Windings:
    """Complete windings of a coordinate over stretches of frames.

    Parameters
    ----------
    unwrapped : ndarray, shape (T,)
        The coordinate unwrapped along all frames (only the frames inside ``runs`` are
        read; each run is re-unwrapped from its own first frame).
    runs : list of (start, stop)
        The stretches of frames to read (half-open, in frame indices).
    n_levels : int
        Levels examined.
    min_anchor_gap : float
        Anchors closer than this (in phase) to a sharper one are dropped.

    Returns
    -------
    Windings
    """
    u_all = np.asarray(unwrapped, dtype=float)
    levels = np.arange(n_levels) / n_levels
    per_run = []
    for a, b in runs:
        u = u_all[a:b] - np.floor(u_all[a]) if b - a > 1 else np.zeros(0)
        per_run.append(
            (a, u, crossing_times(u, levels) if u.size > 1 else [np.zeros(0)] * n_levels)
        )
    turns = float(sum(u[-1] - u[0] for _, u, _ in per_run if u.size > 1))
    lengths_by_level = []
    sharp = np.zeros(n_levels)
    for j in range(n_levels):
        ls = [np.diff(c[j]) for _, _, c in per_run]
        lengths_by_level.append(np.concatenate(ls) if ls else np.zeros(0))
        speeds = [_sharpness(u, [c[j]]) * c[j].size for _, u, c in per_run]
        count = sum(c[j].size for _, _, c in per_run)
        sharp[j] = sum(speeds) / count if count else 0.0
    # anchors: sharp levels, sharpest first, at least `min_anchor_gap` apart
    order = np.argsort(-sharp, kind="stable")
    cutoff = np.median(sharp[sharp > 0]) if np.any(sharp > 0) else 0.0
    anchors: list[int] = []
    for j in order:
        if sharp[j] <= 0 or (anchors and sharp[j] < cutoff):
            continue
        if all(
            min(abs(levels[j] - levels[k]), 1 - abs(levels[j] - levels[k])) >= min_anchor_gap
            for k in anchors
        ):
            anchors.append(int(j))
    ref = anchors[0] if anchors else 0
    pooled = np.concatenate(lengths_by_level) if anchors else np.zeros(0)
    pooled = pooled[pooled > 0]
    period = float(np.median(pooled)) if pooled.size else float("nan")
    spread = (
        float((np.percentile(pooled, 90) - np.percentile(pooled, 10)) / period)
        if pooled.size > 1
        else 0.0
    )
    # where each anchor sits in the cycle: mean time fraction after the reference crossing
    positions = []
    for j in anchors:
        fr = []
        for _, _, c in per_run:
            r, t = c[ref], c[j]
            for k in range(r.size - 1):
                inside = t[(t >= r[k]) & (t < r[k + 1])]
                if inside.size:
                    fr.append((inside[0] - r[k]) / (r[k + 1] - r[k]))
        if not fr and np.isfinite(period):
            # no complete reference winding holds this anchor: its offset after any crossing
            for _, _, c in per_run:
                r, t = c[ref], c[j]
                for x in t:
                    before = r[r <= x]
                    if before.size:
                        fr.append(((x - before[-1]) / period) % 1.0)
        positions.append(float(np.median(fr)) if fr else (levels[j] - levels[ref]) % 1.0)
    return Windings(
        levels=levels,
        anchors=np.asarray(anchors, dtype=int),
        reference=int(ref),
        lengths=lengths_by_level[ref] if anchors else np.zeros(0),
        pooled=pooled,
        period_frames=period,
        spread=spread,
        turns=turns,
        positions=np.asarray(positions, dtype=float),
    )


def retime(unwrapped: np.ndarray, runs: list[tuple[int, int]], windings: Windings) -> np.ndarray:
    """A phase per frame that advances evenly in time between the coordinate's sharp crossings.

    Every crossing of an anchor level inside a run is pinned to the anchor's average
    place in the cycle (:attr:`Windings.positions`, counted in whole turns from the
    run's first reference crossing); frames between pins get a phase linear in time,
    and frames before the first or after the last pin continue at one cycle per
    :attr:`Windings.period_frames`.

    Parameters
    ----------
    unwrapped : ndarray, shape (T,)
    runs : list of (start, stop)
    windings : Windings
        From :func:`complete_windings` on the same coordinate and runs.

    Returns
    -------
    ndarray, shape (T,)
        Phase in ``[0, 1)`` on the frames inside ``runs`` (0 where the reference level is
        crossed), NaN elsewhere.
    """
    u_all = np.asarray(unwrapped, dtype=float)
    out = np.full(u_all.shape, np.nan)
    period = windings.period_frames
    if not windings.anchors.size or not np.isfinite(period) or period <= 0:
        return out
    lv = windings.levels[windings.anchors]
    ref_level = windings.levels[windings.reference]
    pos = windings.positions
    for a, b in runs:
        if b - a < 2:
            continue
        u = np.maximum.accumulate(u_all[a:b] - np.floor(u_all[a]))
        times, targets = [], []
        crossings = crossing_times(u, lv)
        for j, c in enumerate(crossings):
            # turn index of each crossing, counted from the reference level's turns
            first = np.ceil(u[0] - lv[j])
            if first + lv[j] <= u[0]:  # a level on frame 0 is not crossed there (crossing_times)
                first += 1.0
            base = first + np.arange(c.size)  # the k in u = k + level
            turn = base + np.floor(lv[j] - ref_level)  # same turn as the reference before it
            times.append(c)
            targets.append(turn + pos[j])
        t = np.concatenate(times)
        y = np.concatenate(targets)
        if t.size == 0:
            continue
        order = np.argsort(t, kind="stable")
        t, y = t[order], y[order]
        # pins must advance with time; drop those that would run the phase backwards
        keep = y > np.maximum.accumulate(np.concatenate([[-np.inf], y[:-1]]))
        t, y = t[keep], y[keep]
        frames = np.arange(b - a, dtype=float)
        if t.size == 1:
            phase = y[0] + (frames - t[0]) / period
        else:
            phase = np.interp(frames, t, y)
            phase[frames < t[0]] = y[0] + (frames[frames < t[0]] - t[0]) / period
            phase[frames > t[-1]] = y[-1] + (frames[frames > t[-1]] - t[-1]) / period
        out[a:b] = np.mod(phase, 1.0)
    return out


def edge_taper(mask: np.ndarray, length: float) -> np.ndarray:
    """Weights that fade each run of ``mask`` in and out over ``length`` frames.

    A phase averaged from several repetitions changes the number of frames it averages
    where a run starts or stops part-way through a cycle (a take that holds two and a
    half repetitions).  With equal weights the average jumps there, from the mean of the
    repetitions to one of them; fading every run's first and last ``length`` frames
    (raised cosine) spreads that change over ``length`` frames of the cycle.

    Parameters
    ----------
    mask : ndarray of bool, shape (T,)
        Frames that take part (each maximal run of True is one stretch).
    length : float
        Frames over which a run's weight rises from near 0 to 1 (``<= 0``: no taper).

    Returns
    -------
    ndarray, shape (T,)
        Weight per frame in ``(0, 1]`` inside the runs, 0 outside.
    """
    mask = np.asarray(mask, dtype=bool)
    out = np.zeros(mask.size)
    for a, b in stretches(mask):
        if length <= 0:
            out[a:b] = 1.0
            continue
        k = np.arange(b - a, dtype=float)
        edge = np.minimum(k, (b - a - 1) - k) + 0.5
        out[a:b] = 0.5 - 0.5 * np.cos(np.pi * np.minimum(1.0, edge / float(length)))
    return out


def phase_average(
    phase: np.ndarray,
    values: np.ndarray,
    n_out: int,
    width: float,
    weights: np.ndarray | None = None,
) -> np.ndarray:
    """Periodic Gaussian-kernel average of ``values`` at ``n_out`` evenly spaced phases.

    Parameters
    ----------
    phase : ndarray, shape (N,)
        Phase of each row in ``[0, 1)`` (finite).
    values : ndarray, shape (N, D)
    n_out : int
        Output phases ``j / n_out``.
    width : float
        Kernel standard deviation in phase units.
    weights : ndarray, shape (N,), optional
        Non-negative weight of each row, multiplying its kernel weight (default 1 each;
        see :func:`edge_taper`).

    Returns
    -------
    ndarray, shape (n_out, D)
        Rows beyond four widths get no weight; a phase with no row within four widths
        takes the nearest row's value.  Memory is O(N + n_out * D): rows are sorted by
        phase and each output phase reads only the rows inside its window.
    """
    phase = np.asarray(phase, dtype=float)
    values = np.asarray(values, dtype=float)
    if phase.ndim != 1 or values.ndim != 2 or values.shape[0] != phase.size or phase.size == 0:
        raise ParameterError(
            f"phase_average needs (N,) phases and (N, D) values, got {phase.shape}, {values.shape}"
        )
    if not (np.isfinite(width) and width > 0):
        raise ParameterError(f"width must be a positive number, got {width!r}")
    if weights is not None:
        weights = np.asarray(weights, dtype=float)
        if weights.shape != phase.shape or not np.all(np.isfinite(weights)) or np.any(weights < 0):
            raise ParameterError(
                f"weights must be {phase.shape} finite non-negative numbers, got {weights.shape}"
            )
    order = np.argsort(phase, kind="stable")
    ph = phase[order]
    val = values[order]
    # tile one copy on each side so windows that wrap read a contiguous slice
    ph3 = np.concatenate([ph - 1.0, ph, ph + 1.0])
    val3 = np.concatenate([val, val, val])
    u3 = None if weights is None else np.tile(weights[order], 3)
    half = min(4.0 * width, 0.5)
    out = np.empty((n_out, values.shape[1]))
    for j in range(n_out):
        c = j / n_out
        lo, hi = np.searchsorted(ph3, [c - half, c + half])
        d = ph3[lo:hi] - c
        w = np.exp(-0.5 * (d / width) ** 2)
        if u3 is not None:
            w = w * u3[lo:hi]
        if w.size == 0 or w.sum() <= 0:
            k = int(np.argmin(np.abs(ph3 - c)))
            out[j] = val3[k]
        else:
            out[j] = w @ val3[lo:hi] / w.sum()
    return out


def unwrap_across_gaps(
    values: np.ndarray, frames: np.ndarray, period: float | None = None,
    forwards: bool = True,
) -> np.ndarray:
    """A circular coordinate ``values`` (cycles, in [0, 1)) on increasing ``frames``
    unwrapped, each gap between frames advanced by the whole number of cycles that
    brings its pace nearest ``period`` frames a cycle (default: the pace between
    neighbouring frames, their median), in the direction the coordinate runs; with
    ``forwards``, turned round first when it runs backwards.

    ``np.unwrap`` alone takes every step as under half a cycle: a gap of 135 frames (an
    Xsens walk's turn, left out of the pipeline's steady frames) read as 0.19 of a cycle
    instead of 2.74, and a gait phase built on it stalled and ran backwards over the
    walk (a latent MOVE ahead then crossed those frames four times too fast).
    """
    values = np.asarray(values, dtype=float)
    frames = np.asarray(frames, dtype=float)
    u = np.unwrap(2 * np.pi * values) / (2 * np.pi)
    if u.size < 2:
        return u
    step = np.diff(frames)
    du = np.diff(u)
    near = step == 1
    sign = float(np.sign(np.median(du[near]))) if near.any() else float(np.sign(u[-1] - u[0]))
    if period is None:
        rate = float(np.median(np.abs(du[near]))) if near.any() else 0.0
        period = 1.0 / rate if rate > 0 else np.inf
    if np.isfinite(period) and period > 0:
        for j in np.flatnonzero(step > 1):
            u[j + 1 :] += np.round(sign * step[j] / period - (u[j + 1] - u[j]))
    if forwards and sign < 0:
        u = -u
    return u
