"""Frame runs and segment periods shared by the stages of detection (private to the package).

:func:`mask_runs` cuts a mask into half-open runs, :func:`class_period` measures a class's
period over a segment, :func:`drop_unsteady` takes pauses and turns out of segments.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...motion import Motion
from ..coordinates import unwrap

__all__ = ["mask_runs", "class_period", "drop_unsteady", "MAX_TURN", "MIN_SPEED"]


def mask_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Half-open (start, stop) runs of True."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def class_period(coordinate: np.ndarray, mask: np.ndarray, a: int, b: int) -> tuple[float, float]:
    """Turns of a class's coordinate over frames ``a:b`` and the period they give.

    The period is the median length of the coordinate's complete windings on the frames
    where the class is excited (``mask``) inside the segment
    (:func:`~cyclecoord.periodic.windings.complete_windings`), so a segment running past
    its motion (into a pause or a transition where the coordinate stands still) does not
    lengthen it.  Without a complete winding there: frames per turn over the excited
    stretches, or over the whole segment with fewer than 0.75 turns there.
    """
    from ..windings import complete_windings

    def turns(lo: int, hi: int) -> float:
        u = unwrap(coordinate[lo:hi])
        return abs(float(u[-1] - u[0]))

    cyc = turns(a, b)
    runs = [(a + lo, a + hi) for lo, hi in mask_runs(mask[a:b]) if hi - lo > 1]
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


def drop_unsteady(
    labels: np.ndarray, segments: list, joints: np.ndarray, motion: Motion, min_run: int
) -> tuple[np.ndarray, list]:
    """Label pauses and turns inside segments ``-1`` and split the segments around them.

    A frame of a segment is a pause when its joints move at under a fifth of the
    segment's own moving level (:data:`MIN_SPEED`) for over half a second
    (:func:`~cyclecoord.periodic.steady.moving_mask`), and a turn when the root's heading
    changes by more than :data:`MAX_TURN` degrees over one period around it.  Pieces
    shorter than ``min_run`` frames are dropped.
    """
    from ..root import heading, root_layout
    from ..steady import centred_window, moving_mask

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
        for x, y in mask_runs(labels[seg.start:seg.stop] == seg.motion):
            x, y = seg.start + x, seg.start + y
            if y - x < min_run:
                labels[x:y] = -1
                continue
            out.append(
                replace(
                    seg,
                    start=int(x),
                    stop=int(y),
                    cycles=float(seg.cycles) * (y - x) / max(length, 1),
                )
            )
    out.sort(key=lambda s: s.start)
    return labels, out
