"""The global stage of detection: candidate H1 classes, their excitation, motions from classes.

Steps 1-5 of :mod:`cyclecoord.periodic.detection`, on the one barcode of the whole
capture: :func:`candidate_classes` picks the long bars, :func:`read_classes` reads each
one's circular coordinate and where it is excited (:func:`excitation`), and
:func:`motions_from_classes` joins classes exciting the same frames into motions, labels
the frames and cuts the segments.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.ndimage import uniform_filter1d

from ...errors import ParameterError
from ..barcode import CLEAR_RATIO, Barcode
from ..coordinates import CircularCoordinates
from ._segments import class_period, mask_runs
from .result import DetectedClass, Segment

__all__ = ["excitation", "candidate_classes", "read_classes", "motions_from_classes"]


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


def _stretches(theta: np.ndarray, excited: np.ndarray, gap: int, min_cycles: float) -> np.ndarray:
    """Excited frames grouped into stretches (gaps shorter than ``gap`` bridged) that
    complete at least ``min_cycles`` cycles."""
    runs = mask_runs(excited)
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


def candidate_classes(
    barcode: Barcode, n_classes: int | None, max_classes: int, min_persistence: float
) -> list[int]:
    """Step 1: the H1 bars read as candidate motions, by decreasing persistence.

    Parameters
    ----------
    barcode : Barcode
    n_classes : int or None
        Take exactly the ``n_classes`` most persistent bars (fewer if there are fewer).
    max_classes : int
        Otherwise at most this many of the bars with death/birth of at least
        :data:`~cyclecoord.periodic.barcode.CLEAR_RATIO` (death capped at the threshold) ...
    min_persistence : float
        ... and at least this fraction of the longest bar's persistence.

    Returns
    -------
    list of int
        Indices into ``barcode.h1``.
    """
    pers = barcode.persistence(1)
    if not pers.size:
        return []
    if n_classes is not None:
        return list(range(min(n_classes, len(pers))))
    top = np.minimum(barcode.h1[:, 1], barcode.threshold)
    ratio = np.where(barcode.h1[:, 0] > 0, top / np.maximum(barcode.h1[:, 0], 1e-300), np.inf)
    ok = (ratio >= CLEAR_RATIO) & (pers >= min_persistence * pers[0])
    return [int(i) for i in np.flatnonzero(ok)[:max_classes]]


def read_classes(
    est: CircularCoordinates,
    candidates: list[int],
    window: int,
    min_speed: float,
    min_consistency: float,
    min_cycles: float,
    notes: list[str],
) -> list[DetectedClass]:
    """Steps 2-4: each candidate's coordinate, excitation and excited stretches.

    Parameters
    ----------
    est : CircularCoordinates
        Holds the barcode (after :meth:`~CircularCoordinates.fit_barcode`); each class is
        read on its own estimator sharing that barcode
        (:meth:`~CircularCoordinates.with_coordinate_params`), so ``est`` is not changed.
    candidates : list of int
        H1 bar indices (:func:`candidate_classes`).
    window : int
        Frames the coordinate's speed is averaged over (odd).
    min_speed : float
        Cycles per frame an excited frame needs at least.
    min_consistency : float
        Direction consistency an excited frame needs at least.
    min_cycles : float
        Cycles an excited stretch must complete.
    notes : list of str
        Classes whose coordinate fails are skipped with a note appended here.

    Returns
    -------
    list of DetectedClass
        One per class read, ``status`` ``"kept"`` when it has an excited stretch.
    """
    classes: list[DetectedClass] = []
    for i in candidates:
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
        speed, cons = excitation(theta, window)
        excited = (np.abs(speed) >= min_speed) & (cons >= min_consistency)
        mask = _stretches(theta, excited, gap=window, min_cycles=min_cycles)
        sel = class_est.selection_
        classes.append(
            DetectedClass(
                index=i, birth=sel.birth, death=sel.death, scale=sel.scale, coordinate=theta,
                speed=speed, consistency=cons, mask=mask,
                status="kept" if mask.any() else f"never completes {min_cycles:g} steady cycles",
            )
        )
    return classes


def motions_from_classes(
    classes: list[DetectedClass], n_frames: int, window: int, merge_overlap: float
) -> tuple[list[DetectedClass], np.ndarray, list[Segment], int]:
    """Step 5: kept classes exciting the same frames are one motion; labels and segments.

    Classes whose excited frames overlap by more than ``merge_overlap`` of the smaller
    region are joined (union-find); motions are numbered by their first excited frame and
    ``motion`` is set on every kept class.  Each frame takes the motion exciting it most
    strongly (speed times consistency), ``-1`` where none does; label runs shorter than
    half the ``window`` are dropped.  A segment is a run of one label, described by its
    motion's lead (most persistent) class.

    Returns
    -------
    kept : list of DetectedClass
        The classes with ``status == "kept"``.
    labels : ndarray of int, shape (n_frames,)
    segments : list of Segment
        By start frame.
    n_motions : int
    """
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
    labels = np.full(n_frames, -1, dtype=int)
    if n_motions:
        strength = np.zeros((n_motions, n_frames))
        for c in kept:
            s = np.where(c.mask, np.abs(c.speed) * c.consistency, 0.0)
            strength[c.motion] = np.maximum(strength[c.motion], s)
        best = np.argmax(strength, axis=0)
        labels = np.where(strength.max(axis=0) > 0, best, -1)
        # drop flicker: label runs shorter than half the smoothing window
        for mid in range(n_motions):
            for a, b in mask_runs(labels == mid):
                if b - a < window // 2:
                    labels[a:b] = -1

    # segments: runs of each label, described by the motion's lead (most persistent) class
    segments: list[Segment] = []
    for mid in range(n_motions):
        members = [c for c in kept if c.motion == mid]
        lead = min(members, key=lambda c: c.index)
        for a, b in mask_runs(labels == mid):
            cyc, period = class_period(lead.coordinate, lead.mask, a, b)
            segments.append(
                Segment(
                    start=int(a), stop=int(b), motion=mid,
                    classes=(lead.index,) + tuple(c.index for c in members if c is not lead),
                    birth=lead.birth, death=lead.death, scale=lead.scale, cycles=cyc,
                    period_frames=period,
                )
            )
    segments.sort(key=lambda s: s.start)
    return kept, labels, segments, n_motions
