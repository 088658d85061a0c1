"""Several periodic motions in one capture: significant classes, excitation, segments, labels.

The paper (§4.6, §6.4) reads several long H1 bars as several periodic motions: each
class's circular coordinate sweeps round steadily while its motion is performed and
stays put elsewhere (its *excitation region*).  :func:`detect` automates the choices the
paper made by hand:

1. **Candidate classes**: H1 bars with death/birth at least 1.5 (death capped at the
   threshold) and at least ``min_persistence`` of the longest bar's persistence (at most
   ``max_classes``), or exactly the ``n_classes`` longest when forced.
2. **Scale per class**: each class is read at its own scale, high inside its own bar,
   so motions born at different scales (a walk and a hop) are all kept.
3. **Excitation**: per frame, the coordinate's signed speed averaged over a short window
   (cycles per frame) together with the consistency of its direction.  A frame is
   excited when the coordinate advances steadily, faster than one cycle per
   ``max_period`` seconds.
4. **Validation**: a class counts only where it completes at least ``min_cycles``
   cycles in an excited stretch; classes that never do are dropped (this is the rule
   that decides significance when the barcode shows no clear gap).
5. **Motions**: classes that excite the same frames (overlap over half of the smaller
   region) are one motion; each frame is labelled with the motion whose excitation is
   strongest there, ``-1`` where none is excited.

The global barcode's long classes are often large-scale loops (the drift from one
exercise to the next) while each exercise's own loop is small and lives in a short
stretch of time; on CMU 13_29 (six exercises) steps 1-5 label 28% of the frames
correctly.  A **windowed stage** looks locally:

6. **Windows**: sliding windows of 2, 4 and 6 s (``window_lengths``; a window of length
   ``L`` steps by ``max(0.5 s, L / 8)``) over the same prepared points, at most 100
   frames each.  Each gets its full Rips barcode; when its longest bar is clear
   (:func:`cyclecoord.periodic.barcode.select_bar`), its circular coordinate.  The window
   *loops* when the coordinate turns at least 0.9 times with at least half its steps
   the same way; its typical cycle is then the mean pose (root channels left out) in 16
   phase bins of the coordinate (:func:`binned_cycle`).
7. **Motions from windows**: looping windows are grouped by average linkage on
   :func:`cycle_distance` (best rotation and reflection) relative to the cycles'
   amplitudes, cut at ``similarity``; non-adjacent windows of the same motion fall into
   the same group.  A group is a motion when one of its windows completes
   ``min_cycles`` turns, or when at least three of its windows together cover
   ``min_cycles`` of their median period (a slow motion performed for under two of its
   cycles, which no single window holds one and a half times: 13_29's alternating toe
   touches take about 4.1 s a cycle and are performed for 6.5 s).
8. **Labels**: every frame within ``window`` seconds of a motion's windows may take that
   motion; the cost of a frame is its :func:`~cyclecoord.quality.metrics.distance_to_cycle` to the
   motion's nearest window cycle, over that cycle's typical distance to its own frames,
   and :data:`NONE_COST` for "nothing periodic".  The cheapest labelling that pays half
   a ``window`` of frames per change (Viterbi) gives the labels; runs shorter than half
   a window are dropped.  A windowed segment's period is the median of its windows'
   ``frames / cycles`` (those completing ``min_cycles`` when there are any), refined by
   the segment's own autocorrelation (:func:`autocorrelation_period`).

``method="auto"`` (the default) runs both: a group of windows whose frames overlap a
global motion's excited frames by more than ``merge_overlap`` of the smaller region
joins it, other groups become motions of their own, and frames the global stage
labelled keep their global label.  Measured (``benchmarks/bench_detect.py``): on 25
synthetic chains ``auto`` keeps the global method's accuracy (mean 99.4%, min 97.9%)
with boundaries within 27 frames, while windows alone merge jumping jacks with arm
circles in some chains; on 13_29 ``auto`` labels 95% of frames correctly and finds all
six exercises (global 28%).
``method="global"`` is the paper's method alone, ``method="windows"`` the windowed stage
alone.

:func:`motion_cycles` then gives each motion a typical cycle with the phase detection
found (its class's coordinate, or time over the segment's period), rather than a fresh
barcode of the segment whose most persistent class may be one pass through it.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.ndimage import uniform_filter1d

from .._blas import one_blas_thread
from .barcode import CLEAR_RATIO, DEFAULT_PRIME, Barcode, compute_barcode, select_bar
from .coordinates import CircularCoordinates, unwrap
from ..errors import NoPeriodicMotionError, ParameterError
from ..motion import Motion
from .preprocess import Preprocessor

__all__ = [
    "detect",
    "DetectionResult",
    "DetectedClass",
    "Segment",
    "WindowInfo",
    "METHODS",
    "window_table",
    "binned_cycle",
    "cycle_distance",
    "autocorrelation_period",
    "motion_cycles",
    "MotionCycle",
    "excitation",
    "best_match_accuracy",
    "boundary_errors",
]


@dataclass(frozen=True)
class Segment:
    """A frame range where one motion is performed (0-based, half-open)."""

    start: int
    stop: int
    motion: int
    classes: tuple
    birth: float
    death: float
    scale: float
    cycles: float
    period_frames: float

    def to_dict(self) -> dict:
        return {
            "start": self.start,
            "stop": self.stop,
            "motion": self.motion,
            "classes": list(self.classes),
            "birth": self.birth,
            "death": None if not np.isfinite(self.death) else self.death,
            "scale": self.scale,
            "cycles": self.cycles,
            "period_frames": self.period_frames,
        }


@dataclass
class DetectedClass:
    """One candidate H1 class and what its coordinate did.

    Attributes
    ----------
    index : int
        Position in the barcode's H1 bars (by decreasing persistence).
    birth, death, scale : float
    coordinate : ndarray, shape (T,)
        Circular coordinate of every frame.
    speed : ndarray, shape (T,)
        Smoothed signed speed of the coordinate (cycles per frame).
    consistency : ndarray, shape (T,)
        How steadily it moves one way, in [0, 1].
    mask : ndarray of bool, shape (T,)
        Excited frames that belong to stretches of at least ``min_cycles`` cycles.
    motion : int
        Motion id, ``-1`` when the class was dropped.
    status : str
        ``"kept"`` or why it was dropped.
    """

    index: int
    birth: float
    death: float
    scale: float
    coordinate: np.ndarray
    speed: np.ndarray
    consistency: np.ndarray
    mask: np.ndarray
    motion: int = -1
    status: str = "kept"

    def to_dict(self) -> dict:
        return {
            "index": self.index,
            "birth": self.birth,
            "death": None if not np.isfinite(self.death) else self.death,
            "scale": self.scale,
            "motion": self.motion,
            "status": self.status,
            "excited_frames": int(self.mask.sum()),
        }


@dataclass
class DetectionResult:
    """What :func:`detect` found.

    Attributes
    ----------
    motion : Motion
        The analysed frames.
    barcode : Barcode
    classes : list of DetectedClass
        Every candidate, kept or dropped.
    segments : list of Segment
    labels : ndarray of int, shape (T,)
        Motion id per frame, ``-1`` where nothing periodic happens.
    n_motions : int
    timings : dict
        Seconds per stage: ``prepare``, ``barcode``, ``coordinates`` (global classes),
        ``windows`` (windowed stage, when run), ``segments`` (grouping and labelling),
        ``total``.
    parameters : dict
        The arguments of :func:`detect`.
    warnings : list of str
    estimator : CircularCoordinates or None
        The estimator whose barcode the global classes were read from (barcode stage
        only: each class's coordinate is in ``classes``).
    windows : list of WindowInfo
        Every window of the windowed stage (empty with ``method="global"``).
    method : str
        The method that ran (``"auto"``, ``"global"`` or ``"windows"``).
    """

    motion: Motion
    barcode: Barcode
    classes: list
    segments: list
    labels: np.ndarray
    n_motions: int
    timings: dict
    parameters: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    estimator: CircularCoordinates | None = None
    windows: list = field(default_factory=list)
    method: str = "global"

    def to_report(self) -> dict[str, Any]:
        bc = self.barcode.to_dict()
        chosen = {c.index: c.motion for c in self.classes if c.motion >= 0}
        return {
            "source": self.motion.source,
            "frames": [int(self.motion.start_frame), int(self.motion.start_frame + self.motion.n_frames)],
            "n_frames": int(self.motion.n_frames),
            "fps": self.motion.fps,
            "parameters": self.parameters,
            "threshold": self.barcode.threshold,
            "barcode": bc,
            "chosen_classes": [{"index": k, "motion": v} for k, v in sorted(chosen.items())],
            "classes": [c.to_dict() for c in self.classes],
            "method": self.method,
            "n_motions": self.n_motions,
            "segments": [s.to_dict() for s in self.segments],
            "windows": [w.to_dict() for w in self.windows],
            "labels": [int(v) for v in self.labels],
            "timings": {k: round(float(v), 6) for k, v in self.timings.items()},
            "warnings": list(self.warnings),
        }


def excitation(theta: np.ndarray, window: int) -> tuple[np.ndarray, np.ndarray]:
    """Smoothed signed speed (cycles/frame) and direction consistency of a coordinate.

    Steps between frames are wrapped into [-0.5, 0.5); their mean over a centred window
    of ``window`` frames is the speed, and the absolute mean of their signs the
    consistency (1 when every step goes the same way, near 0 for jitter).
    """
    t = np.asarray(theta, dtype=float)
    v = np.mod(np.diff(t) + 0.5, 1.0) - 0.5
    v = np.concatenate([v, v[-1:]]) if v.size else np.zeros(1)
    w = max(1, int(window))
    speed = uniform_filter1d(v, size=w, mode="reflect")
    consistency = np.abs(uniform_filter1d(np.sign(v), size=w, mode="reflect"))
    return speed, consistency


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open (start, stop) runs of True."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def _stretches(theta: np.ndarray, excited: np.ndarray, gap: int, min_cycles: float) -> np.ndarray:
    """Excited frames grouped into stretches (gaps shorter than ``gap`` bridged) that
    complete at least ``min_cycles`` cycles."""
    runs = _runs(excited)
    merged: list[list[int]] = []
    for a, b in runs:
        if merged and a - merged[-1][1] < gap:
            merged[-1][1] = b
        else:
            merged.append([a, b])
    v = np.mod(np.diff(theta) + 0.5, 1.0) - 0.5
    out = np.zeros(len(theta), dtype=bool)
    for a, b in merged:
        if abs(v[a : max(a, b - 1)].sum()) >= min_cycles:
            out[a:b] = True
    return out


def boundary_errors(segments: list, truth: list, n_frames: int) -> list[int]:
    """Boundary errors in frames, both ways.

    True boundaries are the gaps between consecutive true segments ``(start, stop,
    name)``; a transition between them counts as the boundary as a whole (error 0 inside
    it).  Returned: for every true boundary the distance to the nearest predicted segment
    boundary, then for every predicted boundary the distance to the nearest true one.  The
    capture's first and last frames are not boundaries.
    """
    tr = sorted(truth)
    spans = [(tr[i][1], tr[i + 1][0]) for i in range(len(tr) - 1)]
    spans += [(a, a) for a, _, _ in tr[:1] if a > 0] + [(b, b) for _, b, _ in tr[-1:] if b < n_frames]
    pred = sorted({b for s in segments for b in (s.start, s.stop) if 0 < b < n_frames})

    def dist(p: int, span: tuple) -> int:
        lo, hi = min(span), max(span)
        return 0 if lo <= p <= hi else int(min(abs(p - lo), abs(p - hi)))

    errs = [min((dist(p, sp) for p in pred), default=n_frames) for sp in spans]
    ends = spans + [(0, 0), (n_frames, n_frames)]  # a segment may stop a little before the end
    errs += [min(dist(p, sp) for sp in ends) for p in pred]
    return errs


def best_match_accuracy(predicted: np.ndarray, truth: np.ndarray) -> tuple[float, dict]:
    """Frame accuracy after the best one-to-one matching of predicted motions to true ones.

    Frames whose truth is negative (transitions, unlabelled) are not scored; a predicted
    ``-1`` on a labelled frame counts as wrong.  Returns the accuracy and the matching
    ``{predicted_id: true_id}`` (Hungarian algorithm on the confusion matrix).
    """
    from scipy.optimize import linear_sum_assignment

    p = np.asarray(predicted)
    t = np.asarray(truth)
    keep = t >= 0
    p, t = p[keep], t[keep]
    if t.size == 0:
        return float("nan"), {}
    pids = np.unique(p[p >= 0])
    tids = np.unique(t)
    if pids.size == 0:
        return 0.0, {}
    conf = np.array([[np.sum((p == a) & (t == b)) for b in tids] for a in pids])
    rows, cols = linear_sum_assignment(-conf)
    match = {int(pids[r]): int(tids[c]) for r, c in zip(rows, cols)}
    return float(conf[rows, cols].sum() / t.size), match


# ------------------------------------------------------------------ windowed stage
#: Detection methods of :func:`detect`.
METHODS = ("auto", "global", "windows")

#: Phase bins of a window's typical cycle (its phase-invariant descriptor).
CYCLE_BINS = 16

#: Labelling cost of "nothing periodic" per frame, in units of a cycle's own typical
#: distance to the frames that made it: a frame more than this many times farther from
#: every motion's cycle than those frames are is left unlabelled.
NONE_COST = 2.0


@dataclass
class WindowInfo:
    """One time window of the windowed stage and what its barcode showed.

    Attributes
    ----------
    start, stop : int
        Half-open frame range (0-based, in the analysed frames).
    step : int
        Every ``step``-th frame of the range went into the window's filtration.
    birth, death : float
        The window's most persistent H1 bar (``death`` is ``inf`` when alive at the
        window's threshold); NaN when the window has no H1 bar.
    threshold : float
        The window's filtration threshold (half its diameter), analysed-space units.
    scale : float
        Scale the cocycle was read at (NaN when no coordinate was computed).
    clear : bool
        Whether the bar stands clear (:func:`cyclecoord.periodic.barcode.select_bar`).
    cycles : float
        Unwrapped turns of its circular coordinate from the first frame to the last.
    steadiness : float
        Fraction of coordinate steps going the way of the net advance, in [0, 1].
    period_frames : float
        Window frames per completed cycle (``(stop - start) / cycles``).
    looping : bool
        Clear bar, at least ``window_cycles`` cycles and ``window_steadiness``.
    motion : int
        Motion id the window ended up in, ``-1`` otherwise.
    cycle : ndarray, shape (CYCLE_BINS, D) or None
        Mean pose (root channels left out) per phase bin of the coordinate: the window's
        typical cycle, compared between windows up to rotation and reflection.
    """

    start: int
    stop: int
    step: int
    birth: float
    death: float
    threshold: float
    scale: float = float("nan")
    clear: bool = False
    cycles: float = 0.0
    steadiness: float = 0.0
    period_frames: float = float("nan")
    looping: bool = False
    motion: int = -1
    cycle: np.ndarray | None = field(default=None, repr=False)

    def to_dict(self) -> dict:
        def num(v: float) -> float | None:
            return float(v) if np.isfinite(v) else None

        return {
            "start": int(self.start), "stop": int(self.stop), "step": int(self.step),
            "birth": num(self.birth), "death": num(self.death), "threshold": num(self.threshold),
            "scale": num(self.scale), "clear": bool(self.clear), "cycles": float(self.cycles),
            "steadiness": float(self.steadiness), "period_frames": num(self.period_frames),
            "looping": bool(self.looping), "motion": int(self.motion),
        }


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
        dn, dp = (nxt - k) % bins, (k - prv) % bins
        out[k] = out[prv] if dn + dp == 0 else (out[prv] * dn + out[nxt] * dp) / (dn + dp)
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


def _fit_window(points: np.ndarray, prime: int, scale_fraction: float) -> tuple[dict, np.ndarray | None]:
    """Barcode of one window and, when its longest bar stands clear, the coordinate."""
    bc = compute_barcode(points, prime=prime)
    info: dict[str, Any] = {"threshold": bc.threshold, "birth": float("nan"), "death": float("nan")}
    if len(bc.h1) == 0:
        return info, None
    sel = select_bar(bc, 0, scale_fraction=scale_fraction)
    info.update(birth=sel.birth, death=sel.death, clear=sel.clear)
    if not sel.clear:
        return info, None
    est = CircularCoordinates(prime=prime, scale_fraction=scale_fraction, landmarks=None, refine_birth=False)
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
    with tqdm(total=len(plan), desc="detect windows", unit="window", disable=not progress or not plan,
              delay=2.0, leave=False) as bar:
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
            d[i, j] = d[j, i] = cycle_distance(loops[i].cycle, loops[j].cycle) / np.sqrt(amp[i] * amp[j])
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
    from ..quality.metrics import distance_to_cycle

    cost = np.min([distance_to_cycle(poses, cyc) / s for cyc, s in zip(c.cycles, c.scales)], axis=0)
    return np.where(c.allowed, cost, np.inf)


def _dilate(mask: np.ndarray, margin: int) -> np.ndarray:
    if margin <= 0 or not mask.any():
        return mask.copy()
    from scipy.ndimage import binary_dilation

    return binary_dilation(mask, iterations=int(margin))


def _typical_distance(poses: np.ndarray, cycle: np.ndarray) -> float:
    """Median distance of the frames a cycle was made from to that cycle (its scale)."""
    from ..quality.metrics import distance_to_cycle

    return max(float(np.median(distance_to_cycle(poses, cycle))), 1e-9)


def _class_period(coordinate: np.ndarray, mask: np.ndarray, a: int, b: int) -> tuple[float, float]:
    """Turns of a class's coordinate over frames ``a:b`` and the period they give.

    The period is the median length of the coordinate's complete windings on the frames
    where the class is excited (``mask``) inside the segment
    (:func:`~cyclecoord.periodic.windings.complete_windings`), so a segment running past
    its motion (into a pause or a transition where the coordinate stands still) does not
    lengthen it.  Without a complete winding there: frames per turn over the excited
    stretches, or over the whole segment with fewer than 0.75 turns there.
    """
    from .windings import complete_windings

    def turns(lo: int, hi: int) -> float:
        u = unwrap(coordinate[lo:hi])
        return abs(float(u[-1] - u[0]))

    cyc = turns(a, b)
    runs = [(a + lo, a + hi) for lo, hi in _runs(mask[a:b]) if hi - lo > 1]
    excited = sum(turns(lo, hi) for lo, hi in runs)
    if excited >= 0.75:
        u = np.full(coordinate.shape, np.nan)
        for lo, hi in runs:
            part = unwrap(coordinate[lo:hi])
            u[lo:hi] = part if part[-1] >= part[0] else -part
        wind = complete_windings(u, runs)
        if np.isfinite(wind.period_frames):
            return cyc, float(wind.period_frames)
        return cyc, sum(hi - lo - 1 for lo, hi in runs) / excited
    return cyc, (b - a - 1) / cyc if cyc > 0 else float("nan")


#: Heading change per period (degrees) above which detect labels a stretch as turning.
MAX_TURN = 45.0
#: Joint speed, as a fraction of a segment's moving level, below which detect sees a pause.
MIN_SPEED = 0.2


def _drop_unsteady(
    labels: np.ndarray, segments: list, joints: np.ndarray, motion: Motion, min_run: int
) -> tuple[np.ndarray, list]:
    """Label pauses and turns inside segments ``-1`` and split the segments around them.

    A frame of a segment is a pause when its joints move at under a fifth of the
    segment's own moving level (:data:`MIN_SPEED`) for over half a second
    (:func:`~cyclecoord.periodic.steady.moving_mask`), and a turn when the root's heading
    changes by more than :data:`MAX_TURN` degrees over one period around it.  Pieces
    shorter than ``min_run`` frames are dropped.
    """
    from dataclasses import replace

    from .root import heading, root_layout
    from .steady import centred_window, moving_mask

    layout = root_layout(motion)
    hd = heading(motion.frames, layout) if layout is not None else None
    keep = np.ones(labels.size, dtype=bool)
    for seg in segments:
        a, b = seg.start, seg.stop
        bad = ~moving_mask(joints[a:b], motion.fps, min_speed=MIN_SPEED)
        if hd is not None and np.isfinite(seg.period_frames) and b - a > 2:
            lo, hi = centred_window(b - a, max(1, int(round(seg.period_frames / 2))))
            turn = np.abs(hd[a:b][hi] - hd[a:b][lo]) / np.maximum(hi - lo, 1) * seg.period_frames
            bad |= turn > MAX_TURN
        keep[a:b] &= ~bad
    labels = np.where(keep, labels, -1)
    out = []
    for seg in segments:
        length = seg.stop - seg.start
        for x, y in _runs(labels[seg.start:seg.stop] == seg.motion):
            x, y = seg.start + x, seg.start + y
            if y - x < min_run:
                labels[x:y] = -1
                continue
            out.append(replace(seg, start=int(x), stop=int(y), cycles=float(seg.cycles) * (y - x) / max(length, 1)))
    out.sort(key=lambda s: s.start)
    return labels, out


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


def _windowed_motions(
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
        for a, b in _runs(labels == k):
            if b - a < window // 2:
                labels[a:b] = -1

    # number motions by first labelled frame (global motions that label nothing go last)
    with_frames = sorted((int(np.flatnonzero(labels == k)[0]), k) for k in range(K) if np.any(labels == k))
    rest = [(int(np.flatnonzero(cands[k].classes[0].mask)[0]), k) for k in range(n_global) if not np.any(labels == k)]
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
        for a, b in _runs(labels == mid):
            if lead is not None and (not c.windows or np.mean(lead.mask[a:b]) >= 0.5):
                cyc, period = _class_period(lead.coordinate, lead.mask, a, b)
                classes = (lead.index,) + tuple(cl.index for cl in c.classes if cl is not lead)
                birth, death, scale = lead.birth, lead.death, lead.scale
            else:
                inside = [w for w in c.windows if w.stop > a and w.start < b] or c.windows
                multi = [w for w in inside if w.cycles >= min_cycles] or inside
                period = autocorrelation_period(poses[a:b], float(np.median([w.period_frames for w in multi])))
                cyc = (b - a) / period
                classes = tuple(cl.index for cl in sorted(c.classes, key=lambda cl: cl.index))
                birth = float(np.median([w.birth for w in inside]))
                death = float(np.median([w.death for w in inside]))
                scale = float(np.median([w.scale for w in inside]))
            segments.append(Segment(start=int(a), stop=int(b), motion=mid, classes=classes, birth=birth,
                                    death=death, scale=scale, cycles=cyc, period_frames=period))
    segments.sort(key=lambda sg: sg.start)
    return labels, segments, len(order)


@dataclass
class MotionCycle:
    """The typical cycle of one detected motion (see :func:`motion_cycles`).

    Attributes
    ----------
    motion : int
        Motion id.
    start, stop : int
        The segment it was taken from (the motion's longest; 0-based, half-open).
    phase_from : str
        ``"class I"`` when the phase is H1 class ``I``'s coordinate on its excited
        frames, ``"time"`` when it is time over the segment's period.
    n_frames_used : int
        Frames averaged into the cycle.
    period_frames : float
        The segment's period; the cycle has ``round(period_frames)`` frames.
    cycle : Motion
        The loopable clip, with the capture's channels, skeleton and frame rate.
    loop_closure : float
        Seam step over median step (:func:`~cyclecoord.quality.metrics.loop_closure`).
    """

    motion: int
    start: int
    stop: int
    phase_from: str
    n_frames_used: int
    period_frames: float
    cycle: Motion
    loop_closure: float


def motion_cycles(
    result: DetectionResult,
    n_samples: int = 500,
    n_neighbors: int = 10,
    bandwidth: str | float | None = None,
    cycle_start: str = "slowest",
    random_state: int | None = 0,
    timing: str = "capture",
    travel: str = "keep",
) -> list[MotionCycle]:
    """A typical cycle for every motion :func:`detect` found, with the phase it found.

    For each motion's longest segment the phase of a frame is, when the motion has a
    global H1 class, that class's circular coordinate on the frames it excites inside
    the segment (the class the motion was detected by, so the cycle has the segment's
    period); for a motion found by the windows alone, time over the segment's period
    (:func:`autocorrelation_period`), which is accurate for the one to three cycles such
    segments hold.  The typical cycle is then built as :func:`cyclecoord.extract` builds
    it: by default (``timing="capture"``) in a phase re-timed to the capture's pace
    between the coordinate's crossings and aligned by time warping
    (:func:`~cyclecoord.periodic.clip.capture_cycle`), slowest pose first, root tilt
    averaged and heading integrated; with ``timing="coordinate"`` by the paper's density
    sampling.  No fresh barcode is computed.  (A fresh
    ``extract`` on the segment picks the segment's most persistent class, which is often
    one pass through the whole segment: on CMU 13_29 it gave the arm circles an
    840-frame "cycle" for a 220-frame period.)

    Parameters
    ----------
    result : DetectionResult
    n_samples, n_neighbors, bandwidth, cycle_start, random_state, timing, travel
        As for :func:`cyclecoord.extract`.

    Returns
    -------
    list of MotionCycle
        One per motion that labels frames, by motion id.
    """
    from .cycle import typical_cycle
    from .density import PeriodicDensity
    from ..quality.metrics import loop_closure
    from .clip import capture_cycle, loop_cycle
    from .pipeline import TIMINGS
    from .windings import complete_windings, retime, stretches

    if not isinstance(result, DetectionResult):
        raise ParameterError(f"motion_cycles() takes a DetectionResult, got {type(result).__name__}")
    if timing not in TIMINGS:
        raise ParameterError(f"timing must be one of {TIMINGS}, got {timing!r}")
    motion = result.motion
    prep = Preprocessor(difference_root=result.parameters.get("difference_root", True))
    prepared = prep.fit_transform(motion)
    out: list[MotionCycle] = []
    for mid in range(result.n_motions):
        segs = [sg for sg in result.segments if sg.motion == mid]
        if not segs:
            continue
        seg = max(segs, key=lambda sg: sg.stop - sg.start)
        a, b, period = seg.start, seg.stop, float(seg.period_frames)
        if not np.isfinite(period) or period < 2:
            continue
        rows = np.arange(a, b)
        lead = next((cl for cl in result.classes if cl.index == seg.classes[0]), None) if seg.classes else None
        if lead is not None and lead.mask[a:b].sum() >= period:  # at least one full turn
            rows = a + np.flatnonzero(lead.mask[a:b])
            theta, source = np.mod(lead.coordinate[rows], 1.0), f"class {lead.index}"
        else:
            theta, source = np.mod((rows - a) / period, 1.0), "time"
        meta = {"period_frames": period, "motion": mid, "segment": [a, b], "phase_from": source}
        if timing == "capture":
            mask = np.zeros(motion.n_frames, dtype=bool)
            mask[rows] = True
            runs = stretches(mask)
            u = np.full(motion.n_frames, np.nan)
            for lo, hi in runs:
                part = unwrap(np.asarray(theta[np.searchsorted(rows, lo):np.searchsorted(rows, hi)]))
                u[lo:hi] = part if part[-1] >= part[0] else -part
            wind = complete_windings(u, runs)
            phase = retime(u, runs, wind)
            if not np.isfinite(phase).any():
                phase = np.full(motion.n_frames, np.nan)
                phase[rows] = np.mod((rows - a) / period, 1.0)
            typ, clip, _ = capture_cycle(phase, motion, prepared, prep, period, bandwidth=bandwidth,
                                         cycle_start=cycle_start, travel=travel, k=n_neighbors, metadata=meta)
        else:
            density = PeriodicDensity(random_state=random_state).fit(theta)
            typ = typical_cycle(
                theta, prepared.poses[rows], period, density=density, n_samples=n_samples,
                k=min(n_neighbors, rows.size), bandwidth=bandwidth, random_state=random_state,
            )
            typ, clip = loop_cycle(typ, motion, prepared, prep, cycle_start=cycle_start, rows=rows, metadata=meta)
        out.append(MotionCycle(
            motion=mid, start=a, stop=b, phase_from=source, n_frames_used=int(rows.size),
            period_frames=period, cycle=clip, loop_closure=float(loop_closure(typ.frames)),
        ))
    return out


@one_blas_thread
def detect(
    motion: Motion,
    frames: tuple[int | None, int | None] | None = None,
    *,
    pca: int | None = None,
    normalize: bool = False,
    temporal: bool = False,
    difference_root: bool = True,
    prime: int = DEFAULT_PRIME,
    max_scale: float | None = None,
    delay: float | tuple | None = 0.25,
    landmarks: int | str | None = "auto",
    memory_limit: float | None = None,
    n_classes: int | None = None,
    max_classes: int = 30,
    min_persistence: float = 0.1,
    scale_fraction: float = 0.9,
    window: float = 1.0,
    max_period: float = 4.0,
    min_consistency: float = 0.4,
    min_cycles: float = 1.5,
    merge_overlap: float = 0.5,
    method: str = "auto",
    window_lengths: tuple = (2.0, 4.0, 6.0),
    window_stride: float = 0.5,
    window_points: int = 100,
    window_cycles: float = 0.9,
    window_steadiness: float = 0.5,
    similarity: float = 1.5,
    progress: bool = True,
) -> DetectionResult:
    """Find the periodic motions in a capture and the frames where each happens.

    Parameters
    ----------
    motion : Motion
    frames : (start, stop), optional
        0-based half-open frame range to analyse.
    pca, normalize, temporal, difference_root, prime, max_scale, landmarks, memory_limit
        As for :func:`cyclecoord.extract`.
    delay : float, sequence of float, or None, default 0.25
        Delay embedding in seconds (each pose joined by the poses this long before), so
        that out-and-back movements (squats, jumping jacks, knee raises) form loops.
        ``None`` or 0 analyses the poses alone, as the paper did.  A delay of half a
        motion's period folds that motion's loop flat; several delays can be given.
        Measured: 0.25 s keeps synthetic boundaries within 30 frames; 0.5 s finds more of
        CMU 13_29's slow exercises (42% against 28% of frames) but blurs boundaries.
    n_classes : int, optional
        Use exactly the ``n_classes`` most persistent H1 classes (still validated by
        excitation for the segments).
    max_classes : int, default 30
        At most this many candidate classes.
    min_persistence : float, default 0.1
        Candidates need at least this fraction of the longest bar's persistence.
    scale_fraction : float, default 0.9
        Each class is read this far up its own bar.
    window : float, default 1.0
        Seconds over which the coordinate's speed is averaged.
    max_period : float, default 4.0
        Slowest periodic motion looked for, in seconds: excitation needs at least one
        cycle per ``max_period``.
    min_consistency : float, default 0.4
        Excited frames need the coordinate to move one way this consistently.
    min_cycles : float, default 1.5
        An excited stretch must complete this many cycles.
    merge_overlap : float, default 0.5
        Classes whose excited frames overlap by more than this fraction of the smaller
        region are one motion (and, with ``method="auto"``, a group of windows joins the
        global motion whose excited frames hold more than this fraction of its frames).
    method : {"auto", "global", "windows"}, default "auto"
        ``"global"``: the classes of the one barcode on the whole capture (steps 1-5
        above, the paper's method).  ``"windows"``: the windowed stage alone (steps
        6-8).  ``"auto"``: both; windowed motions that excite a global motion's frames
        join it, the others are added, and the global labels are kept where the global
        stage labelled a frame.  See the module notes for the measured reasons.
    window_lengths : sequence of float, default (2, 4, 6)
        Window lengths in seconds.  A window must hold about a cycle of a motion to see
        its loop, so the longest should exceed the slowest period looked for.
    window_stride : float, default 0.5
        Smallest step between window starts, seconds (a window of length ``L`` steps by
        ``max(window_stride, L / 8)``).
    window_points : int, default 100
        At most this many frames per window go into its filtration (evenly spaced).
    window_cycles : float, default 0.9
        A window *loops* when its clear bar's coordinate completes this many turns ...
    window_steadiness : float, default 0.5
        ... with at least this fraction of its steps going the same way.  A group of
        looping windows becomes a motion when one of its windows completes
        ``min_cycles`` turns, or when three or more of them cover ``min_cycles`` of
        their median period.
    similarity : float, default 1.5
        Looping windows whose typical cycles differ by less than this (RMS pose distance
        after the best rotation and reflection, over the geometric mean of the two
        cycles' amplitudes; average linkage) are one motion.
    progress : bool, default True
        tqdm bar on stderr over the windows, shown only when they take over 2 s.

    Returns
    -------
    DetectionResult

    Raises
    ------
    NoPeriodicMotionError
        When no class is excited anywhere (``result`` holds the partial detection).
    """
    if not isinstance(motion, Motion):
        raise ParameterError(f"detect() takes a Motion, got {type(motion).__name__}")
    for name, val in (("window", window), ("max_period", max_period), ("min_cycles", min_cycles)):
        if not np.isfinite(val) or val <= 0:
            raise ParameterError(f"{name} must be a positive number, got {val}")
    if not 0 < min_consistency <= 1 or not 0 < merge_overlap <= 1 or not 0 <= min_persistence <= 1:
        raise ParameterError("min_consistency and merge_overlap must be in (0, 1], min_persistence in [0, 1]")
    if n_classes is not None and n_classes < 1:
        raise ParameterError(f"n_classes must be at least 1, got {n_classes}")
    if method not in METHODS:
        raise ParameterError(f"method must be one of {list(METHODS)}, got {method!r}")
    try:
        window_lengths = tuple(float(v) for v in np.atleast_1d(window_lengths))
    except (TypeError, ValueError):
        raise ParameterError(f"window_lengths must be numbers of seconds, got {window_lengths!r}") from None
    if not window_lengths or not all(np.isfinite(v) and v > 0 for v in window_lengths):
        raise ParameterError(f"window_lengths must be positive numbers of seconds, got {window_lengths}")
    for name, val in (("window_stride", window_stride), ("window_cycles", window_cycles), ("similarity", similarity)):
        if not np.isfinite(val) or val <= 0:
            raise ParameterError(f"{name} must be a positive number, got {val}")
    if not 0 <= window_steadiness <= 1:
        raise ParameterError(f"window_steadiness must be in [0, 1], got {window_steadiness}")
    if int(window_points) != window_points or window_points < 10:
        raise ParameterError(f"window_points must be a whole number >= 10, got {window_points}")
    params = dict(
        frames=None if frames is None else list(frames), pca=pca, normalize=normalize, temporal=temporal,
        difference_root=difference_root, prime=prime, max_scale=max_scale, landmarks=landmarks,
        delay=delay, n_classes=n_classes, max_classes=max_classes, min_persistence=min_persistence,
        scale_fraction=scale_fraction, window=window, max_period=max_period,
        min_consistency=min_consistency, min_cycles=min_cycles, merge_overlap=merge_overlap,
        method=method, window_lengths=list(window_lengths), window_stride=window_stride,
        window_points=int(window_points), window_cycles=window_cycles, window_steadiness=window_steadiness,
        similarity=similarity,
    )
    motion = motion.window(frames)
    T = motion.n_frames
    if T < 20:
        raise ParameterError(f"{T} frames are too few to look for periodic motion")
    timings: dict[str, float] = {}
    notes: list[str] = []

    t0 = time.perf_counter()
    lag = [int(round(d * motion.fps)) for d in np.atleast_1d(delay) if d] if delay is not None else None
    lag = lag or None
    prepared = Preprocessor(difference_root=difference_root, normalize=normalize, pca=pca, delay=lag).fit_transform(motion)
    timings["prepare"] = time.perf_counter() - t0

    est = CircularCoordinates(
        max_scale=max_scale, prime=prime, scale_fraction=scale_fraction, temporal=temporal,
        landmarks=landmarks, refine_birth=False,
        **({} if memory_limit is None else {"memory_limit": memory_limit}),
    )
    t0 = time.perf_counter()
    barcode = est.fit_barcode(prepared.points)
    timings["barcode"] = time.perf_counter() - t0
    if est.landmarks_ is not None:
        notes.append(f"barcode on {len(est.landmarks_)} landmarks: {est.landmark_reason_}")

    # 1. candidates
    pers = barcode.persistence(1)
    if pers.size:
        top = np.minimum(barcode.h1[:, 1], barcode.threshold)
        ratio = np.where(barcode.h1[:, 0] > 0, top / np.maximum(barcode.h1[:, 0], 1e-300), np.inf)
        if n_classes is not None:
            cand = list(range(min(n_classes, len(pers))))
        else:
            ok = (ratio >= CLEAR_RATIO) & (pers >= min_persistence * pers[0])
            cand = [int(i) for i in np.flatnonzero(ok)[:max_classes]]
    else:
        cand = []

    # 2-4. coordinate, excitation and validation per class
    fps = motion.fps
    w = max(3, int(round(window * fps)) | 1)
    v_min = 1.0 / (max_period * fps)
    classes: list[DetectedClass] = []
    t0 = time.perf_counter()
    for i in cand if method != "windows" else ():
        # each class on its own estimator sharing est's barcode (est itself is not changed)
        class_est = est.with_coordinate_params(class_index=i)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                class_est.fit_coordinate()
            except ParameterError as exc:
                notes.append(f"H1 class {i} skipped: {exc}")
                continue
        theta = class_est.coordinates_
        speed, cons = excitation(theta, w)
        excited = (np.abs(speed) >= v_min) & (cons >= min_consistency)
        mask = _stretches(theta, excited, gap=w, min_cycles=min_cycles)
        sel = class_est.selection_
        classes.append(
            DetectedClass(
                index=i, birth=sel.birth, death=sel.death, scale=sel.scale, coordinate=theta,
                speed=speed, consistency=cons, mask=mask,
                status="kept" if mask.any() else f"never completes {min_cycles:g} steady cycles",
            )
        )
    timings["coordinates"] = time.perf_counter() - t0

    # 5. motions: union of classes exciting the same frames
    t0 = time.perf_counter()
    kept = [c for c in classes if c.status == "kept"]
    parent = list(range(len(kept)))

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a in range(len(kept)):
        for b in range(a + 1, len(kept)):
            inter = np.sum(kept[a].mask & kept[b].mask)
            small = min(kept[a].mask.sum(), kept[b].mask.sum())
            if small and inter / small > merge_overlap:
                parent[find(b)] = find(a)
    groups: dict[int, list[DetectedClass]] = {}
    for a, c in enumerate(kept):
        groups.setdefault(find(a), []).append(c)
    # number motions by first excited frame
    order = sorted(groups, key=lambda r: min(int(np.flatnonzero(c.mask)[0]) for c in groups[r]))
    for mid, r in enumerate(order):
        for c in groups[r]:
            c.motion = mid
    n_motions = len(order)

    # labels: strongest excitation among motions covering the frame
    labels = np.full(T, -1, dtype=int)
    if n_motions:
        strength = np.zeros((n_motions, T))
        for c in kept:
            s = np.where(c.mask, np.abs(c.speed) * c.consistency, 0.0)
            strength[c.motion] = np.maximum(strength[c.motion], s)
        best = np.argmax(strength, axis=0)
        labels = np.where(strength.max(axis=0) > 0, best, -1)
        # drop flicker: label runs shorter than half the smoothing window
        for mid in range(n_motions):
            for a, b in _runs(labels == mid):
                if b - a < w // 2:
                    labels[a:b] = -1

    # segments: runs of each label, described by the motion's lead (most persistent) class
    segments: list[Segment] = []
    for mid in range(n_motions):
        members = [c for c in kept if c.motion == mid]
        lead = min(members, key=lambda c: c.index)
        for a, b in _runs(labels == mid):
            cyc, period = _class_period(lead.coordinate, lead.mask, a, b)
            segments.append(
                Segment(
                    start=int(a), stop=int(b), motion=mid,
                    classes=(lead.index,) + tuple(c.index for c in members if c is not lead),
                    birth=lead.birth, death=lead.death, scale=lead.scale, cycles=cyc,
                    period_frames=period,
                )
            )
    segments.sort(key=lambda s: s.start)
    timings["segments"] = time.perf_counter() - t0

    # 6-8. windowed stage
    windows: list[WindowInfo] = []
    if method != "global":
        keep_cols = np.setdiff1d(np.arange(prepared.poses.shape[1]), prepared.root_columns)
        poses = prepared.poses[:, keep_cols] if keep_cols.size else prepared.poses
        t0 = time.perf_counter()
        windows = window_table(
            prepared.points, poses, fps, window_lengths, window_stride, int(window_points), prime,
            scale_fraction, window_cycles, window_steadiness, progress,
        )
        timings["windows"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        n_global = n_motions if method == "auto" else 0
        if method == "windows":
            for c in kept:
                c.motion = -1
        labels, segments, n_motions = _windowed_motions(
            windows, kept if n_global else [], labels, n_global, poses, w, min_cycles, similarity, merge_overlap,
        )
        timings["segments"] += time.perf_counter() - t0
    t0 = time.perf_counter()
    joint_cols = np.setdiff1d(np.arange(prepared.poses.shape[1]), prepared.root_columns)
    labels, segments = _drop_unsteady(
        labels, segments, prepared.poses[:, joint_cols] if joint_cols.size else prepared.poses, motion,
        min_run=max(w // 2, 1),
    )
    timings["segments"] = timings.get("segments", 0.0) + time.perf_counter() - t0
    timings["total"] = sum(timings.values())
    result = DetectionResult(
        motion=motion, barcode=barcode, classes=classes, segments=segments, labels=labels,
        n_motions=n_motions, timings=timings, parameters=params, warnings=notes, estimator=est,
        windows=windows, method=method,
    )
    if not segments:
        looping = sum(wi.looping for wi in windows)
        local = (f"; {len(windows)} window(s), {looping} looping, no group of them holds {min_cycles:g} "
                 "cycles" if method != "global" else "")
        raise NoPeriodicMotionError(
            f"no periodic motion found: {len(cand)} candidate H1 class(es), none completes "
            f"{min_cycles:g} steady cycles anywhere in the capture" + local,
            result=result,
        )
    return result
