"""Kernel averages on the circle for :func:`cyclecoord.periodic.cycle.kernel_centroids`:
a dense (phases x frames) sum, and the same sum over each phase's window of frames."""

from __future__ import annotations

import numpy as np

__all__: list[str] = []


# Weights exp(-x²/2) are exactly 0.0 in float64 beyond x = 38.6 widths: a window of 40
# widths around each phase holds every frame with a non-zero weight.
KERNEL_REACH = 40.0


def kernel_dense(theta, poses, phases, sigma, chunk_elements):
    """Kernel averages with a (phases x frames) weight matrix, in chunks."""
    T = theta.shape[0]
    out = np.empty((phases.shape[0], poses.shape[1]))
    step = max(1, chunk_elements // max(T, 1))
    for a in range(0, phases.shape[0], step):
        q = phases[a : a + step]
        d = np.mod(q[:, None] - theta[None, :] + 0.5, 1.0) - 0.5
        w = np.exp(-0.5 * (d / sigma) ** 2)
        tot = w.sum(axis=1, keepdims=True)
        # a phase far from every frame (a gap in the coordinate): fall back to the nearest
        empty = tot[:, 0] < 1e-300
        if empty.any():
            near = np.argmin(np.abs(d[empty]), axis=1)
            w[empty] = 0.0
            w[np.flatnonzero(empty), near] = 1.0
            tot[empty] = 1.0
        out[a : a + step] = (w / tot) @ poses
    return out


def kernel_windowed(theta, poses, phases, sigma, chunk_elements):
    """The same averages over only the frames within ``KERNEL_REACH`` widths of each phase.

    Frames sorted by phase once; each phase's window is a run of them (found by binary
    search on the sorted phases extended by one period either side), and the normalised
    weights form a sparse (phases x frames) matrix multiplied into the poses.  Cost
    O(T log T + window entries · D) instead of O(N · T · D): at a million frames the
    windows hold a few hundred frames each.  Equal to :func:`kernel_dense` up to the
    order of summation (relative differences of order 1e-15).
    """
    import scipy.sparse as sp

    T = theta.shape[0]
    order = np.argsort(theta, kind="stable")
    st = theta[order]
    ext = np.concatenate([st - 1.0, st, st + 1.0])
    reach = KERNEL_REACH * sigma  # < 0.5: no frame can fall in a window twice
    lo = np.searchsorted(ext, phases - reach, side="left")
    hi = np.searchsorted(ext, phases + reach, side="right")
    counts = (hi - lo).astype(np.int64)
    out = np.empty((phases.shape[0], poses.shape[1]))
    n = phases.shape[0]
    a = 0
    while a < n:
        # as many phases as keep the chunk's window entries under chunk_elements
        csum = np.cumsum(counts[a:])
        b = a + max(1, int(np.searchsorted(csum, chunk_elements, side="right")))
        cnt = counts[a:b]
        nnz = int(cnt.sum())
        indptr = np.zeros(b - a + 1, dtype=np.int64)
        np.cumsum(cnt, out=indptr[1:])
        rows = np.repeat(np.arange(b - a), cnt)
        pos = np.repeat(lo[a:b], cnt) + (np.arange(nnz) - np.repeat(indptr[:-1], cnt))
        frame = order[pos % T]
        q = phases[a:b]
        d = np.mod(q[rows] - theta[frame] + 0.5, 1.0) - 0.5
        w = np.exp(-0.5 * (d / sigma) ** 2)
        tot = np.bincount(rows, weights=w, minlength=b - a)
        empty = tot < 1e-300
        tot[empty] = 1.0
        mat = sp.csr_matrix((w / tot[rows], frame, indptr), shape=(b - a, T))
        out[a:b] = mat @ poses
        if empty.any():
            # a phase far from every frame (a gap in the coordinate): the nearest frame
            for r in np.flatnonzero(empty):
                dd = np.abs(np.mod(q[r] - theta + 0.5, 1.0) - 0.5)
                out[a + r] = poses[int(np.argmin(dd))]
        a = b
    return out
