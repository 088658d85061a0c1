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
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.ndimage import uniform_filter1d

from .barcode import CLEAR_RATIO, DEFAULT_PRIME, Barcode
from .coordinates import CircularCoordinates
from .errors import NoPeriodicMotionError, ParameterError
from .motion import Motion
from .preprocess import Preprocessor

__all__ = [
    "detect",
    "DetectionResult",
    "DetectedClass",
    "Segment",
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
    warnings : list of str
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
            "n_motions": self.n_motions,
            "segments": [s.to_dict() for s in self.segments],
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
        region are one motion.

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
    params = dict(
        frames=None if frames is None else list(frames), pca=pca, normalize=normalize, temporal=temporal,
        difference_root=difference_root, prime=prime, max_scale=max_scale, landmarks=landmarks,
        delay=delay, n_classes=n_classes, max_classes=max_classes, min_persistence=min_persistence,
        scale_fraction=scale_fraction, window=window, max_period=max_period,
        min_consistency=min_consistency, min_cycles=min_cycles, merge_overlap=merge_overlap,
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
    for i in cand:
        est.class_index = i
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                est.fit_coordinate()
            except ParameterError as exc:
                notes.append(f"H1 class {i} skipped: {exc}")
                continue
        theta = est.coordinates_.copy()
        speed, cons = excitation(theta, w)
        excited = (np.abs(speed) >= v_min) & (cons >= min_consistency)
        mask = _stretches(theta, excited, gap=w, min_cycles=min_cycles)
        sel = est.selection_
        classes.append(
            DetectedClass(
                index=i, birth=sel.birth, death=sel.death, scale=sel.scale, coordinate=theta,
                speed=speed, consistency=cons, mask=mask,
                status="kept" if mask.any() else f"never completes {min_cycles:g} steady cycles",
            )
        )
        est.barcode_ = barcode  # a prime retry may have replaced it; keep indices consistent
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
            cyc = abs(float(np.sum(np.mod(np.diff(lead.coordinate[a:b]) + 0.5, 1.0) - 0.5)))
            segments.append(
                Segment(
                    start=int(a), stop=int(b), motion=mid,
                    classes=(lead.index,) + tuple(c.index for c in members if c is not lead),
                    birth=lead.birth, death=lead.death, scale=lead.scale, cycles=cyc,
                    period_frames=(b - a - 1) / cyc if cyc > 0 else float("nan"),
                )
            )
    segments.sort(key=lambda s: s.start)
    timings["segments"] = time.perf_counter() - t0
    timings["total"] = sum(timings.values())
    result = DetectionResult(
        motion=motion, barcode=barcode, classes=classes, segments=segments, labels=labels,
        n_motions=n_motions, timings=timings, parameters=params, warnings=notes, estimator=est,
    )
    if not segments:
        raise NoPeriodicMotionError(
            f"no periodic motion found: {len(cand)} candidate H1 class(es), none completes "
            f"{min_cycles:g} steady cycles anywhere in the capture",
            result=result,
        )
    return result
