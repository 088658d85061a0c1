"""Motion-graph transitions (Kovar, Gleicher and Pighin 2002), the baseline of the latent models.

The distance between frame ``i`` of motion A and frame ``j`` of motion B compares the
point clouds of the joints' positions over a window of ``k`` frames (A's frames
``i..i+k-1`` against B's ``j..j+k-1``, the frames a blend would mix), after aligning B's
cloud to A's by the best rotation about the vertical axis and translation on the floor
(closed form, Kovar et al. Sec. 3.1).  Candidate transitions are the local minima of
that distance over ``(i, j)`` that lie under a threshold.  Every window sum is computed
for all pairs at once from per-frame inner products (matrix products).

Distances are reported as RMS point distances (square root of the aligned sum of
squares over the window's points), in skeleton units, so one threshold serves this and
the latent bridges alike.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..errors import ParameterError

__all__ = ["Transitions", "aligned_transform", "transition_points", "window_distances"]


def _window_sum(M: np.ndarray, k: int) -> np.ndarray:
    """``S[i, j] = sum_m M[i + m, j + m]`` for the windows that fit, ``(n_a - k + 1, n_b - k + "
    "1)``."""
    na, nb = M.shape[0] - k + 1, M.shape[1] - k + 1
    out = np.zeros((na, nb))
    for m in range(k):
        out += M[m : m + na, m : m + nb]
    return out


def _frame_sum(v: np.ndarray, k: int) -> np.ndarray:
    c = np.concatenate([[0.0], np.cumsum(v)])
    return c[k:] - c[:-k]


def window_distances(pa: np.ndarray, pb: np.ndarray, k: int, up: int = 1) -> np.ndarray:
    """RMS aligned point-cloud distance of every window pair.

    Parameters
    ----------
    pa, pb : ndarray, shape (T_a, P, 3), (T_b, P, 3)
        Joint positions (the same points) of the two motions.
    k : int
        Window length in frames.
    up : int, default 1
        Index of the vertical axis (y for ASF/AMC).

    Returns
    -------
    ndarray, shape (T_a - k + 1, T_b - k + 1)
    """
    if pa.shape[1:] != pb.shape[1:]:
        raise ParameterError(f"point clouds differ: {pa.shape[1:]} and {pb.shape[1:]}")
    if k < 1 or k > min(len(pa), len(pb)):
        raise ParameterError(
            f"window of {k} frames does not fit motions of {len(pa)} and {len(pb)} frames"
        )
    h1, h2 = [i for i in range(3) if i != up]
    P = pa.shape[1]
    n = k * P
    xa, za, ya = pa[..., h1], pa[..., h2], pa[..., up]
    xb, zb, yb = pb[..., h1], pb[..., h2], pb[..., up]
    dot = _window_sum(xa @ xb.T + za @ zb.T, k)  # sum x x' + z z'
    cross = _window_sum(xa @ zb.T - za @ xb.T, k)  # sum x z' - z x'
    yy = _window_sum(ya @ yb.T, k)
    sxa, sza = _frame_sum(xa.sum(1), k), _frame_sum(za.sum(1), k)
    sxb, szb = _frame_sum(xb.sum(1), k), _frame_sum(zb.sum(1), k)
    na2 = _frame_sum((pa**2).sum((1, 2)), k) - (sxa**2 + sza**2) / n
    nb2 = _frame_sum((pb**2).sum((1, 2)), k) - (sxb**2 + szb**2) / n
    a = dot - (np.outer(sxa, sxb) + np.outer(sza, szb)) / n
    b = cross - (np.outer(sxa, szb) - np.outer(sza, sxb)) / n
    d2 = na2[:, None] + nb2[None, :] - 2.0 * yy - 2.0 * np.hypot(a, b)
    return np.sqrt(np.maximum(d2, 0.0) / n)


def aligned_transform(wa: np.ndarray, wb: np.ndarray, up: int = 1) -> tuple[float, np.ndarray]:
    """Rotation about the vertical (radians) and floor translation taking window ``wb`` onto ``wa``.

    ``wa``, ``wb``: ``(k, P, 3)``.  Returns ``(theta, t)`` with ``t`` a 3-vector (0 on the
    vertical) such that ``R(theta) @ p_b + t`` matches ``p_a`` best.
    """
    h1, h2 = [i for i in range(3) if i != up]
    xa, za = wa[..., h1].ravel(), wa[..., h2].ravel()
    xb, zb = wb[..., h1].ravel(), wb[..., h2].ravel()
    mxa, mza, mxb, mzb = xa.mean(), za.mean(), xb.mean(), zb.mean()
    a = ((xa - mxa) * (xb - mxb) + (za - mza) * (zb - mzb)).sum()
    b = ((xa - mxa) * (zb - mzb) - (za - mza) * (xb - mxb)).sum()
    theta = float(np.arctan2(b, a))
    c, s = np.cos(theta), np.sin(theta)
    t = np.zeros(3)
    t[h1] = mxa - (c * mxb + s * mzb)
    t[h2] = mza - (-s * mxb + c * mzb)
    return theta, t


@dataclass(frozen=True)
class Transitions:
    """Candidate transitions from motion A to motion B.

    Attributes
    ----------
    pairs : ndarray of int, shape (M, 2)
        ``(i, j)``: leave A at frame ``i``, blend A's ``i..i+k-1`` into B's ``j..j+k-1``.
    distances : ndarray, shape (M,)
    window : int
    threshold : float
    """

    pairs: np.ndarray
    distances: np.ndarray
    window: int
    threshold: float

    def __len__(self) -> int:
        return int(self.pairs.shape[0])


def transition_points(
    pa: np.ndarray,
    pb: np.ndarray,
    window: int,
    threshold: float,
    up: int = 1,
    valid_a: np.ndarray | None = None,
    valid_b: np.ndarray | None = None,
) -> Transitions:
    """Local minima of the window distance under ``threshold`` (Kovar et al. Sec. 3.2).

    Parameters
    ----------
    pa, pb : ndarray, shape (T, P, 3)
    window : int
    threshold : float
        RMS distance, skeleton units.
    up : int
    valid_a, valid_b : ndarray of bool, optional
        Which window starts are allowed (e.g. windows that stay inside one training
        segment when several are concatenated).
    """
    D = window_distances(pa, pb, window, up)
    if valid_a is not None:
        D[~np.asarray(valid_a)[: D.shape[0]], :] = np.inf
    if valid_b is not None:
        D[:, ~np.asarray(valid_b)[: D.shape[1]]] = np.inf
    local = D == ndimage.minimum_filter(D, size=3, mode="nearest")
    hit = np.argwhere(local & (D < threshold))
    return Transitions(
        pairs=hit, distances=D[hit[:, 0], hit[:, 1]], window=int(window), threshold=float(threshold)
    )
