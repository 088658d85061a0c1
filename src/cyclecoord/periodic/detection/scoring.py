"""Scores of a detection against ground truth: frame accuracy and boundary errors.

Used by the tests, ``benchmarks/bench_detect.py`` and the notebooks to compare
:func:`~cyclecoord.periodic.detection.detect` with the scripted segments of a synthetic
chain (:func:`cyclecoord.datasets.make_motion_chain`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["best_match_accuracy", "boundary_errors"]


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
    spans += [(a, a) for a, _, _ in tr[:1] if a > 0] + [
        (b, b) for _, b, _ in tr[-1:] if b < n_frames
    ]
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
