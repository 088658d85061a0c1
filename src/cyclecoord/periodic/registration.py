"""Registration of repetitions: each frame's phase refined against the typical cycle.

Repetitions of a real motion differ in timing inside the cycle (a longer stance, an
earlier toe-off).  Averaged at a phase that is linear in time between a few crossings,
their sharp features (the toe's flick, the knee's peak) land at slightly different
phases and the average flattens them.  :func:`register` aligns every run of frames to the
current typical cycle by dynamic time warping inside a band around the phase it has,
with steps of 0, 1 or 2 cycle samples per frame (the 0 and 2 steps cost a penalty, so the
phase keeps the capture's pace unless the poses ask otherwise), and repeats with the
cycle averaged at the new phases.  Frames held on one sample share one frame's weight in
that average (:func:`hold_weights`).

Cost: O(frames x band) distances (in blocks, so memory is O(frames x band)) and one
vectorised dynamic-programming row per frame.
"""

from __future__ import annotations

import numpy as np

from .windings import phase_average

__all__ = ["hold_weights", "register"]

#: Frames whose band of distances is computed at once.
_BLOCK = 256


def _align_run(
    poses: np.ndarray, psi: np.ndarray, template: np.ndarray, band: int, penalty: float
) -> np.ndarray:
    """Template sample index (unwrapped, integer) of every frame of one run."""
    P = template.shape[0]
    n = poses.shape[0]
    centre = np.round(psi * P).astype(np.int64)  # unwrapped sample index per frame
    offsets = np.arange(-band, band + 1)
    idx = centre[:, None] + offsets[None, :]  # (n, W)
    cost = np.empty(idx.shape)
    for a in range(0, n, _BLOCK):  # (block, W, D) at a time: memory O(n W), not O(n W D)
        b = min(n, a + _BLOCK)
        cost[a:b] = np.linalg.norm(template[np.mod(idx[a:b], P)] - poses[a:b, None, :], axis=2)
    scale = float(np.median(cost)) if cost.size else 1.0
    pen = penalty * (scale if scale > 0 else 1.0)
    W = offsets.size
    acc = np.empty((n, W))
    back = np.zeros((n, W), dtype=np.int8)
    acc[0] = cost[0]
    inf = np.inf
    for i in range(1, n):
        delta = int(centre[i] - centre[i - 1])
        best = np.full(W, inf)
        arg = np.zeros(W, dtype=np.int8)
        for s, extra in ((1, 0.0), (0, pen), (2, pen)):
            # previous column j' with absolute step s: j' = j + delta - s
            shift = delta - s
            prev = np.full(W, inf)
            if shift >= 0:
                if shift < W:
                    prev[: W - shift] = acc[i - 1, shift:]
            else:
                if -shift < W:
                    prev[-shift:] = acc[i - 1, : W + shift]
            cand = prev + extra
            better = cand < best
            best[better] = cand[better]
            arg[better] = s
        acc[i] = cost[i] + best
        back[i] = arg
    j = int(np.argmin(acc[-1]))
    out = np.empty(n, dtype=np.int64)
    for i in range(n - 1, -1, -1):
        out[i] = idx[i, j]
        if i:
            s = int(back[i, j])
            j = j + int(centre[i] - centre[i - 1]) - s
            j = min(max(j, 0), W - 1)
    return out


def hold_weights(phase: np.ndarray) -> np.ndarray:
    """One vote per repetition and cycle sample: ``1 / n`` for each of ``n`` consecutive
    frames that registration put on the same sample (a hold).

    A run that dwells on one sample for a dozen frames (the take's first repetition,
    still getting going) would otherwise outvote every other repetition at that phase, and
    the average would jump there and back.

    Parameters
    ----------
    phase : ndarray, shape (T,)
        Phase per frame (NaN where there is none).

    Returns
    -------
    ndarray, shape (T,)
        Weight per frame in ``(0, 1]``, 0 where the phase is NaN.
    """
    ph = np.asarray(phase, dtype=float)
    out = np.zeros(ph.size)
    ok = np.isfinite(ph)
    if not ok.any():
        return out
    # a new group starts at every frame whose phase differs from the previous frame's
    # (or that follows a frame without phase)
    same = np.zeros(ph.size, dtype=bool)
    same[1:] = ok[1:] & ok[:-1] & (ph[1:] == ph[:-1])
    group = np.cumsum(~same)
    counts = np.bincount(group)
    out[ok] = 1.0 / counts[group[ok]]
    return out


def register(
    phase: np.ndarray,
    poses: np.ndarray,
    runs: list[tuple[int, int]],
    n_samples: int,
    width: float,
    *,
    n_iter: int = 2,
    band: float = 0.12,
    penalty: float = 0.15,
) -> np.ndarray:
    """Refine a per-frame phase by aligning each run of frames to the typical cycle.

    Parameters
    ----------
    phase : ndarray, shape (T,)
        Phase per frame in ``[0, 1)``, NaN outside ``runs``.
    poses : ndarray, shape (T, D)
        What is aligned (joint angles).
    runs : list of (start, stop)
        Runs of consecutive frames with a phase.
    n_samples : int
        Samples of the typical cycle (its length in frames).
    width : float
        Kernel width (phase units) of the average that builds the cycle.
    n_iter : int
        Rounds of alignment and averaging.
    band : float
        How far (in cycles) a frame's phase may move from the one it has, per round:
        ``round(band * n_samples)`` samples, at least one.
    penalty : float
        Cost of a frame that holds or skips a sample, as a fraction of the median
        pose-to-cycle distance.

    Returns
    -------
    ndarray, shape (T,)
        The refined phase in ``[0, 1)``, NaN where ``phase`` is NaN.
    """
    ph = np.asarray(phase, dtype=float).copy()
    x = np.asarray(poses, dtype=float)
    P = int(n_samples)
    b = max(1, int(round(band * P)))
    for _ in range(max(0, int(n_iter))):
        rows = np.flatnonzero(np.isfinite(ph))
        if rows.size < 2:
            break
        template = phase_average(ph[rows], x[rows], P, width, weights=hold_weights(ph)[rows])
        new = np.full_like(ph, np.nan)
        for a, e in runs:
            if e - a < 3:
                new[a:e] = ph[a:e]
                continue
            psi = np.unwrap(ph[a:e] * 2 * np.pi) / (2 * np.pi)
            k = _align_run(x[a:e], psi, template, b, penalty)
            new[a:e] = np.mod(k / P, 1.0)
        ph = new
    return ph
