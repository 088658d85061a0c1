"""The windowed stage of detection: local barcodes, window cycles, motions and labels.

Steps 6-8 of :mod:`cyclecoord.periodic.detection`: sliding windows each get their own
barcode and, when their longest bar is clear, a coordinate and a small typical cycle
(:func:`window_table`); looping windows with alike cycles are grouped into motions, joined
to the global stage's motions where they excite the same frames, and every frame is
labelled by a Viterbi path over the motions' cycle distances (:func:`windowed_motions`).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..barcode import DEFAULT_PRIME, compute_barcode, select_bar
from ..coordinates import CircularCoordinates, unwrap
from ._segments import class_period, mask_runs
from .result import DetectedClass, Segment, WindowInfo

__all__ = [
    "CYCLE_BINS",
    "NONE_COST",
    "window_table",
    "binned_cycle",
    "cycle_distance",
    "autocorrelation_period",
    "windowed_motions",
]

#: Phase bins of a window's typical cycle (its phase-invariant descriptor).
CYCLE_BINS = 16

#: Labelling cost of "nothing periodic" per frame, in units of a cycle's own typical
#: distance to the frames that made it: a frame more than this many times farther from
#: every motion's cycle than those frames are is left unlabelled.
NONE_COST = 2.0


def binned_cycle(theta: np.ndarray, poses: np.ndarray, bins: int = CYCLE_BINS) -> np.ndarray:
    """Mean pose per phase bin of a circular coordinate (a small typical cycle).

    Parameters
    ----------
    theta : ndarray, shape (N,)
        Circular coordinate in cycles (used modulo 1).
    poses : ndarray, shape (N, D)
        The frames' poses.
    bins : int, default 16
        Phase bins.

    Returns
    -------
    ndarray, shape (bins, D)
        Empty bins are interpolated linearly (around the circle) from their neighbours.
    """
    x = np.asarray(poses, dtype=float)
    b = np.minimum((np.mod(np.asarray(theta, dtype=float), 1.0) * bins).astype(int), bins - 1)
    count = np.bincount(b, minlength=bins)
    sums = np.zeros((bins, x.shape[1]))
    np.add.at(sums, b, x)
    have = np.flatnonzero(count > 0)
    out = np.zeros_like(sums)
    out[have] = sums[have] / count[have, None]
    for k in np.flatnonzero(count == 0):
        if have.size == 0:
            break
        nxt = have[np.argmin((have - k) % bins)]
        prv = have[np.argmin((k - have) % bins)]
        dn, dp = (nxt - k) % bins, (k - prv) % bins  # both >= 1: bin k is empty, they are not
        out[k] = (out[prv] * dn + out[nxt] * dp) / (dn + dp)
    return out


def cycle_distance(a: np.ndarray, b: np.ndarray) -> float:
    """RMS pose distance between two binned cycles after the best rotation and reflection.

    Every circular shift of ``b`` and of ``b`` reversed is tried (``2 * bins`` cases), so
    the result does not depend on where either coordinate put its zero or which way it
    runs.

    Parameters
    ----------
    a, b : ndarray, shape (bins, D)

    Returns
    -------
    float
        In the poses' units (degrees for joint angles).
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    n = len(a)
    shifts = np.arange(n)
    idx = (np.arange(n)[None, :] - shifts[:, None]) % n  # (shift, bin)
    best = np.inf
    for bb in (b, b[::-1]):
        d = np.sqrt(np.mean(np.sum((a[None] - bb[idx]) ** 2, axis=2), axis=1))
        best = min(best, float(d.min()))
    return best


def _amplitude(cycle: np.ndarray) -> float:
    """RMS distance of a binned cycle's poses from their mean."""
    return float(np.sqrt(np.mean(np.sum((cycle - cycle.mean(axis=0)) ** 2, axis=1))))


def _fit_window(
    points: np.ndarray, prime: int, scale_fraction: float
) -> tuple[dict, np.ndarray | None]:
    """Barcode of one window and, when its longest bar stands clear, the coordinate."""
    bc = compute_barcode(points, prime=prime)
    info: dict[str, Any] = {"threshold": bc.threshold, "birth": float("nan"), "death": float("nan")}
    if len(bc.h1) == 0:
        return info, None
    sel = select_bar(bc, 0, scale_fraction=scale_fraction)
    info.update(birth=sel.birth, death=sel.death, clear=sel.clear)
    if not sel.clear:
        return info, None
    est = CircularCoordinates(
        prime=prime, scale_fraction=scale_fraction, landmarks=None, refine_birth=False
    )
    est.use_barcode(points, bc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est.fit_coordinate()
    u = unwrap(est.coordinates_)
    net = float(u[-1] - u[0])
    steps = np.diff(u)
    info.update(
        scale=est.selection_.scale, cycles=abs(net),
        steadiness=float(np.mean(np.sign(steps) == np.sign(net))) if net and steps.size else 0.0,
    )
    return info, est.coordinates_


def window_table(
    points: np.ndarray,
    poses: np.ndarray,
    fps: float,
    lengths: tuple = (2.0, 4.0, 6.0),
    stride: float = 0.5,
    max_points: int = 100,
    prime: int = DEFAULT_PRIME,
    scale_fraction: float = 0.9,
    min_cycles: float = 0.9,
    min_steadiness: float = 0.5,
    progress: bool = True,
) -> list[WindowInfo]:
    """Sliding windows over prepared points: local barcode, coordinate and typical cycle.

    Parameters
    ----------
    points : ndarray, shape (T, K)
        The analysed points (after the delay embedding).
    poses : ndarray, shape (T, D)
        Poses the typical cycles are averaged from (root channels left out).
    fps : float
        Frames per second.
    lengths : sequence of float, default (2, 4, 6)
        Window lengths in seconds (longer than the capture: skipped).
    stride : float, default 0.5
        Seconds between window starts, at least; a window of length ``L`` is stepped by
        ``max(stride, L / 8)``.  The last window ends at the last frame.
    max_points : int, default 100
        At most this many frames per window (every ``ceil(L / max_points)``-th frame).
    prime, scale_fraction
        As for :class:`~cyclecoord.periodic.coordinates.CircularCoordinates`.
    min_cycles : float, default 0.9
        A window loops when its coordinate completes at least this many turns ...
    min_steadiness : float, default 0.5
        ... with at least this fraction of its steps going one way, on a clear bar.
    progress : bool, default True
        Show a tqdm bar on stderr (only once the windows take more than 2 s).

    Returns
    -------
    list of WindowInfo
        Every window, by length then start; ``cycle`` is set for looping windows.
    """
    from tqdm import tqdm

    T = len(points)
    plan = []
    for length in lengths:
        n = int(round(float(length) * fps))
        if n < 10 or n > T:
            continue
        hop = max(1, int(round(max(stride, float(length) / 8.0) * fps)))
        starts = list(range(0, T - n + 1, hop))
        if starts[-1] != T - n:
            starts.append(T - n)
        step = max(1, int(np.ceil(n / max_points)))
        plan.extend((a, a + n, step) for a in starts)
    out: list[WindowInfo] = []
    with tqdm(
        total=len(plan),
        desc="detect windows",
        unit="window",
        disable=not progress or not plan,
        delay=2.0,
        leave=False,
    ) as bar:
        for a, b, step in plan:
            idx = np.arange(a, b, step)
            info, theta = _fit_window(points[idx], prime, scale_fraction)
            w = WindowInfo(start=a, stop=b, step=step, **info)
            if w.cycles > 0:
                w.period_frames = (b - a) / w.cycles
            if theta is not None and w.cycles >= min_cycles and w.steadiness >= min_steadiness:
                w.looping = True
                w.cycle = binned_cycle(theta, poses[idx])
            out.append(w)
            bar.update(1)
    return out


def _cluster_windows(windows: list[WindowInfo], similarity: float) -> list[list[WindowInfo]]:
    """Group looping windows whose typical cycles are alike (average linkage).

    The distance between two windows is :func:`cycle_distance` over the geometric mean of
    their cycles' amplitudes (RMS spread of the binned poses round their mean), so the
    cut ``similarity`` is relative to the size of the motions compared.
    """
    from scipy.cluster.hierarchy import fcluster, linkage
    from scipy.spatial.distance import squareform

    loops = [w for w in windows if w.looping]
    if len(loops) < 2:
        return [loops] if loops else []
    amp = np.array([max(_amplitude(w.cycle), 1e-9) for w in loops])
    n = len(loops)
    d = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1, n):
            d[i, j] = d[j, i] = cycle_distance(loops[i].cycle, loops[j].cycle) / np.sqrt(
                amp[i] * amp[j]
            )
    groups = fcluster(linkage(squareform(d, checks=False), "average"), similarity, "distance")
    return [[w for w, g in zip(loops, groups) if g == k] for k in np.unique(groups)]


def _viterbi(cost: np.ndarray, switch: float) -> np.ndarray:
    """Cheapest state path through per-frame costs, paying ``switch`` per change of state."""
    T, K = cost.shape
    acc = cost[0].copy()
    back = np.zeros((T, K), dtype=np.int32)
    states = np.arange(K)
    for t in range(1, T):
        best = int(np.argmin(acc))
        move = acc[best] + switch
        stay = acc <= move
        back[t] = np.where(stay, states, best)
        acc = np.where(stay, acc, move) + cost[t]
    path = np.empty(T, dtype=int)
    path[-1] = int(np.argmin(acc))
    for t in range(T - 1, 0, -1):
        path[t - 1] = back[t, path[t]]
    return path


@dataclass
class _Candidate:
    """A motion before labelling: its cycles, where it may label frames, its sources."""

    cycles: list
    scales: list
    allowed: np.ndarray
    classes: list = field(default_factory=list)
    windows: list = field(default_factory=list)


def _candidate_cost(c: _Candidate, poses: np.ndarray) -> np.ndarray:
    from ...quality.metrics import distance_to_cycle

    cost = np.min([distance_to_cycle(poses, cyc) / s for cyc, s in zip(c.cycles, c.scales)], axis=0)
    return np.where(c.allowed, cost, np.inf)


def _dilate(mask: np.ndarray, margin: int) -> np.ndarray:
    if margin <= 0 or not mask.any():
        return mask.copy()
    from scipy.ndimage import binary_dilation

    return binary_dilation(mask, iterations=int(margin))


def _typical_distance(poses: np.ndarray, cycle: np.ndarray) -> float:
    """Median distance of the frames a cycle was made from to that cycle (its scale)."""
    from ...quality.metrics import distance_to_cycle

    return max(float(np.median(distance_to_cycle(poses, cycle))), 1e-9)


def autocorrelation_period(poses: np.ndarray, guess: float, min_correlation: float = 0.3) -> float:
    """Refine a period estimate by the autocorrelation of a stretch of poses.

    The poses (mean removed) are correlated with themselves shifted by every lag in
    ``[guess / 2, min(1.5 guess, 0.8 T)]``; the lag of the highest correlation is the
    period when it is an interior maximum of at least ``min_correlation``.  A windowed
    segment's first estimate is the median of its windows' ``frames / turns``, which is
    the window's length when the windows turn about once (a slow motion performed for
    under two cycles); the stretch's own repetition fixes that.

    Parameters
    ----------
    poses : ndarray, shape (T, D)
        The frames of one segment.
    guess : float
        First estimate of the period, in frames.
    min_correlation : float, default 0.3
        Smallest normalised correlation accepted.

    Returns
    -------
    float
        The refined period in frames, or ``guess`` when no lag qualifies.
    """
    x = np.asarray(poses, dtype=float)
    T = x.shape[0]
    if not np.isfinite(guess) or guess <= 0:
        return float(guess)
    lo = max(2, int(np.floor(0.5 * guess)))
    hi = min(int(np.ceil(1.5 * guess)), int(0.8 * T))
    if hi - lo < 2:
        return float(guess)
    x = x - x.mean(axis=0)
    lags = np.arange(lo - 1, hi + 2)
    corr = np.empty(lags.size)
    for i, lag in enumerate(lags):
        a, b = x[: T - lag], x[lag:]
        den = np.sqrt(np.sum(a * a) * np.sum(b * b))
        corr[i] = np.sum(a * b) / den if den > 0 else -np.inf
    j = int(np.argmax(corr[1:-1])) + 1
    if corr[j] < min_correlation or corr[j] < corr[j - 1] or corr[j] < corr[j + 1]:
        return float(guess)
    return float(lags[j])


def windowed_motions(
    windows: list[WindowInfo],
    kept: list[DetectedClass],
    global_labels: np.ndarray,
    n_global: int,
    poses: np.ndarray,
    window: int,
    min_cycles: float,
    similarity: float,
    merge_overlap: float,
) -> tuple[np.ndarray, list[Segment], int]:
    """Steps 6-8 of the module notes: motions from windows (and global classes), labels, segments.

    ``n_global`` global motions (their classes in ``kept``) come first; with
    ``n_global == 0`` only windows are used.  Sets ``motion`` on windows and classes.
    """
    T = len(poses)
    cands: list[_Candidate] = []
    for mid in range(n_global):
        members = [c for c in kept if c.motion == mid]
        mask = np.zeros(T, dtype=bool)
        cycles, scales = [], []
        for c in members:
            mask |= c.mask
            fr = np.flatnonzero(c.mask)
            cyc = binned_cycle(c.coordinate[fr], poses[fr])
            cycles.append(cyc)
            scales.append(_typical_distance(poses[fr], cyc))
        cands.append(_Candidate(cycles, scales, mask, classes=members))
    excited = [c.allowed.copy() for c in cands]  # the global motions' own frames
    for group in _cluster_windows(windows, similarity):
        cover = np.zeros(T, dtype=bool)
        for w in group:
            cover[w.start : w.stop] = True
        span = cover.sum() / float(np.median([w.period_frames for w in group]))
        if max(w.cycles for w in group) < min_cycles and (len(group) < 3 or span < min_cycles):
            continue  # loops, but neither one window nor the group's frames hold min_cycles turns
        cycles = [w.cycle for w in group]
        scales = [_typical_distance(poses[w.start : w.stop : w.step], w.cycle) for w in group]
        target, best = None, 0.0
        for k in range(n_global):
            inter = np.sum(cover & excited[k])
            share = inter / max(1, min(cover.sum(), excited[k].sum()))
            if share > merge_overlap and share > best:
                target, best = k, share
        if target is None:
            cands.append(_Candidate(cycles, scales, cover, windows=list(group)))
        else:
            c = cands[target]
            c.cycles += cycles
            c.scales += scales
            c.allowed = c.allowed | cover
            c.windows += list(group)

    labels = np.full(T, -1, dtype=int)
    K = len(cands)
    if K == 0:
        return labels, [], 0
    cost = np.full((T, K + 1), NONE_COST)
    for k, c in enumerate(cands):
        c.allowed = _dilate(c.allowed, window)
        cost[:, k] = _candidate_cost(c, poses)
    path = _viterbi(cost, switch=window / 2.0)
    labels = np.where(path == K, -1, path)
    if n_global:
        labels = np.where(global_labels >= 0, global_labels, labels)
    for k in range(K):
        for a, b in mask_runs(labels == k):
            if b - a < window // 2:
                labels[a:b] = -1

    # number motions by first labelled frame (global motions that label nothing go last)
    with_frames = sorted(
        (int(np.flatnonzero(labels == k)[0]), k) for k in range(K) if np.any(labels == k)
    )
    rest = [
        (int(np.flatnonzero(cands[k].classes[0].mask)[0]), k)
        for k in range(n_global)
        if not np.any(labels == k)
    ]
    order = [k for _, k in with_frames] + [k for _, k in sorted(rest)]
    new_id = {k: i for i, k in enumerate(order)}
    labels = np.array([new_id.get(int(v), -1) for v in labels], dtype=int)
    for k, c in enumerate(cands):
        mid = new_id.get(k, -1)
        for cl in c.classes:
            cl.motion = mid
        for w in c.windows:
            w.motion = mid

    segments: list[Segment] = []
    for k in order:
        c, mid = cands[k], new_id[k]
        lead = min(c.classes, key=lambda cl: cl.index) if c.classes else None
        for a, b in mask_runs(labels == mid):
            if lead is not None and (not c.windows or np.mean(lead.mask[a:b]) >= 0.5):
                cyc, period = class_period(lead.coordinate, lead.mask, a, b)
                classes = (lead.index,) + tuple(cl.index for cl in c.classes if cl is not lead)
                birth, death, scale = lead.birth, lead.death, lead.scale
            else:
                inside = [w for w in c.windows if w.stop > a and w.start < b] or c.windows
                multi = [w for w in inside if w.cycles >= min_cycles] or inside
                period = autocorrelation_period(
                    poses[a:b], float(np.median([w.period_frames for w in multi]))
                )
                cyc = (b - a) / period
                classes = tuple(cl.index for cl in sorted(c.classes, key=lambda cl: cl.index))
                birth = float(np.median([w.birth for w in inside]))
                death = float(np.median([w.death for w in inside]))
                scale = float(np.median([w.scale for w in inside]))
            segments.append(
                Segment(
                    start=int(a),
                    stop=int(b),
                    motion=mid,
                    classes=classes,
                    birth=birth,
                    death=death,
                    scale=scale,
                    cycles=cyc,
                    period_frames=period,
                )
            )
    segments.sort(key=lambda sg: sg.start)
    return labels, segments, len(order)
