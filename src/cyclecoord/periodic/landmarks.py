"""Landmarks and the memory guard: how big a Rips complex will be, and how many points to keep.

Full Vietoris-Rips on every frame grows quadratically in memory (ripser keeps a dense
distance matrix) and faster than that in time.  Before a filtration is built its size at
the chosen threshold is estimated from random pairs and triples of points; when the
estimate is over budget, or the capture is long, the barcode is computed on greedy
max-min landmarks (:func:`greedy_landmarks`, the same choice as ripser's ``n_perm``) and
the coordinate extended to every frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np

from ..errors import ParameterError

__all__ = [
    "greedy_landmarks",
    "ComplexEstimate",
    "estimate_complex",
    "choose_landmarks",
    "AUTO_FULL_LIMIT",
    "AUTO_LANDMARKS",
    "DEFAULT_MEMORY_LIMIT",
]

#: With ``landmarks="auto"`` captures up to this many frames use every frame ...
AUTO_FULL_LIMIT = 1000
#: ... and longer ones this many greedy landmarks (fewer if the memory guard says so).
AUTO_LANDMARKS = 500
#: Default memory budget for one filtration, in bytes (a laptop-friendly 2 GiB).
DEFAULT_MEMORY_LIMIT = 2 * 1024**3

# ripser.py keeps an (n_used x n_all) float64 distance array; the reduction keeps a
# handful of 8-byte words per edge column.
_BYTES_PER_DISTANCE = 8
_BYTES_PER_EDGE = 64


@dataclass(frozen=True)
class ComplexEstimate:
    """Estimated size of a Rips complex.

    Attributes
    ----------
    n_points : int
        Vertices (points or landmarks).
    edges : float
        Expected number of edges at the threshold.
    triangles : float
        Expected number of triangles at the threshold.
    bytes : float
        Estimated peak memory of the persistent cohomology computation.
    """

    n_points: int
    edges: float
    triangles: float
    bytes: float

    def to_dict(self) -> dict:
        return {
            "n_points": self.n_points,
            "edges": float(self.edges),
            "triangles": float(self.triangles),
            "bytes": float(self.bytes),
        }


def greedy_landmarks(
    points: np.ndarray, n: int, start: int = 0, distance_matrix: bool = False
) -> tuple[np.ndarray, float]:
    """Greedy max-min (farthest point) subsample, as ripser's ``n_perm`` makes it.

    Starting from point ``start``, each next landmark is the point farthest from those
    already chosen.  Distances to a new landmark come from one matrix-vector product
    (``|x|² + |l|² - 2 x·l``), so a step costs one pass over the points: on 64,000
    frames of 62 channels 500 landmarks take about a second, where ripser's own
    greedy step (one ``pairwise_distances`` call per landmark) took about four.

    Parameters
    ----------
    points : ndarray, shape (T, K)
    n : int
        Number of landmarks, ``1 <= n <= T``.
    start : int, default 0
        First landmark (ripser starts at point 0).
    distance_matrix : bool, default False
        ``points`` is a (T, T) matrix of distances.

    Returns
    -------
    indices : ndarray of int, shape (n,)
        Landmarks in the order chosen.
    covering_radius : float
        Largest distance from any point to its nearest landmark (ripser's ``r_cover``).
    """
    x = np.asarray(points, dtype=float)
    if x.ndim != 2 or (distance_matrix and x.shape[0] != x.shape[1]):
        raise ParameterError(f"points must be a (T, K) array or a (T, T) distance matrix, got shape {x.shape}")
    T = x.shape[0]
    if isinstance(n, bool) or int(n) != n or not 1 <= n <= T:
        raise ParameterError(f"the number of landmarks must be between 1 and {T}, got {n!r}")
    if not 0 <= start < T:
        raise ParameterError(f"start must index a point (0..{T - 1}), got {start}")
    sq = None if distance_matrix else np.einsum("ij,ij->i", x, x)
    idx = np.empty(int(n), dtype=np.int64)
    nearest = np.full(T, np.inf)  # squared distances for points, distances for a matrix
    i = int(start)
    for k in range(int(n)):
        idx[k] = i
        d = x[i] if distance_matrix else sq + sq[i] - 2.0 * (x @ x[i])
        np.minimum(nearest, d, out=nearest)
        nearest[i] = 0.0
        i = int(np.argmax(nearest))
    if n == T:
        return idx, 0.0
    # the farthest point's distance, exactly (the product form loses digits near 0)
    radius = x[i, idx].min() if distance_matrix else np.linalg.norm(x[i] - x[idx], axis=1).min()
    return idx, float(radius)


def estimate_complex(
    points: np.ndarray,
    threshold: float,
    n_vertices: int | None = None,
    n_samples: int = 20_000,
    random_state: int = 0,
) -> ComplexEstimate:
    """Estimate edges, triangles and memory of the Rips complex at ``threshold``.

    The fraction of random pairs (and triples) of points within ``threshold`` of each
    other, times the number of pairs (triples), estimates the edge (triangle) count —
    without building anything.

    Parameters
    ----------
    points : ndarray, shape (T, K)
    threshold : float
    n_vertices : int, optional
        Number of vertices the complex will have (landmarks); default all ``T`` points.
        Landmarks spread out more evenly than random points, so this is a slight
        overestimate for them.
    n_samples : int
        Random pairs and triples drawn.
    """
    x = np.asarray(points, dtype=float)
    T = x.shape[0]
    n = T if n_vertices is None else int(min(n_vertices, T))
    if T < 3:
        return ComplexEstimate(T, 0.0, 0.0, 0.0)
    rng = np.random.default_rng(random_state)
    i = rng.integers(0, T, n_samples)
    j = rng.integers(0, T, n_samples)
    k = rng.integers(0, T, n_samples)
    ok = (i != j) & (j != k) & (i != k)
    i, j, k = i[ok], j[ok], k[ok]
    dij = np.linalg.norm(x[i] - x[j], axis=1) <= threshold
    djk = np.linalg.norm(x[j] - x[k], axis=1) <= threshold
    dik = np.linalg.norm(x[i] - x[k], axis=1) <= threshold
    p_edge = float(dij.mean()) if dij.size else 0.0
    p_tri = float((dij & djk & dik).mean()) if dij.size else 0.0
    edges = p_edge * comb(n, 2)
    triangles = p_tri * comb(n, 3)
    mem = _BYTES_PER_DISTANCE * n * T + _BYTES_PER_EDGE * edges
    return ComplexEstimate(n_points=n, edges=edges, triangles=triangles, bytes=mem)


def choose_landmarks(
    points: np.ndarray,
    threshold: float,
    landmarks: int | str | None = "auto",
    memory_limit: float = DEFAULT_MEMORY_LIMIT,
) -> tuple[int | None, ComplexEstimate, str]:
    """Decide how many points the filtration is built on.

    Parameters
    ----------
    landmarks : "auto", int or None
        ``"auto"``: every frame up to :data:`AUTO_FULL_LIMIT` frames, otherwise
        :data:`AUTO_LANDMARKS` landmarks; an int: that many; ``None`` or ``"none"``:
        every frame.
    memory_limit : float
        Bytes.  When the estimate exceeds it, the landmark count is reduced until it
        fits (down to 50); ``landmarks=None`` then switches to landmarks as well.

    Returns
    -------
    n_landmarks : int or None
        ``None`` means every point.
    estimate : ComplexEstimate
        For the complex that will be built.
    reason : str
        Human-readable account of the decision (for the report).
    """
    T = len(points)
    if memory_limit is None or not np.isfinite(memory_limit) or memory_limit <= 0:
        raise ParameterError(f"memory limit must be a positive number of bytes, got {memory_limit}")
    if landmarks is None or (isinstance(landmarks, str) and landmarks.lower() in ("none", "all", "full")):
        n, reason = None, "every frame (landmarks off)"
    elif isinstance(landmarks, str):
        if landmarks.lower() != "auto":
            raise ParameterError(f"landmarks must be 'auto', 'none' or a number, got {landmarks!r}")
        if T <= AUTO_FULL_LIMIT:
            n, reason = None, f"every frame ({T} <= {AUTO_FULL_LIMIT})"
        else:
            n, reason = AUTO_LANDMARKS, f"{AUTO_LANDMARKS} greedy landmarks of {T} frames (automatic)"
    else:
        try:
            n = int(landmarks)
        except (TypeError, ValueError):
            raise ParameterError(f"landmarks must be 'auto', 'none' or a number, got {landmarks!r}") from None
        if n < 10:
            raise ParameterError(f"need at least 10 landmarks, got {n}")
        if n >= T:
            n, reason = None, f"every frame ({landmarks} landmarks requested, {T} frames)"
        else:
            reason = f"{n} greedy landmarks of {T} frames (requested)"
    est = estimate_complex(points, threshold, n_vertices=n)
    if est.bytes > memory_limit:
        before = est
        m = n if n is not None else min(T, AUTO_LANDMARKS)
        est = estimate_complex(points, threshold, n_vertices=m)
        while est.bytes > memory_limit and m > 50:
            m = max(50, int(m * 0.7))
            est = estimate_complex(points, threshold, n_vertices=m)
        reason = (
            f"memory guard: the complex on {before.n_points} points was estimated at "
            f"{before.bytes / 1e9:.2f} GB ({before.edges:.3g} edges) over the {memory_limit / 1e9:.2f} GB "
            f"limit; using {m} greedy landmarks ({est.bytes / 1e9:.2f} GB)"
        )
        n = m if m < T else None
    return n, est, reason
