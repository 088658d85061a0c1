"""Landmarks and the memory guard: how big a Rips complex will be, and how many points to keep.

Full Vietoris-Rips on every frame grows quadratically in memory (ripser keeps a dense
distance matrix) and faster than that in time.  Before a filtration is built its size at
the chosen threshold is estimated from random pairs and triples of points; when the
estimate is over budget, or the capture is long, the barcode is computed on greedy
max-min landmarks (:func:`greedy_landmarks`, the same choice as ripser's ``n_perm``) and
the coordinate extended to every frame.

The budget trusts no limit: it is never more than the machine can hold
(:func:`machine_memory`: physical memory, a cgroup limit, an address-space rlimit).  A
limit the caller states covers the run's large arrays -- the per-frame arrays
(:func:`run_bytes`) as well as the filtration -- and a run whose per-frame arrays alone
do not fit is refused before anything is allocated.  Without a stated limit the
filtration gets :data:`DEFAULT_MEMORY_LIMIT`, within what the machine has left.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np

from ..errors import ParameterError
from ..io._limits import machine_memory
from ._rips import DENSE_BYTES_PER_PAIR

__all__ = [
    "greedy_landmarks",
    "ComplexEstimate",
    "estimate_complex",
    "choose_landmarks",
    "AUTO_FULL_LIMIT",
    "AUTO_LANDMARKS",
    "DEFAULT_MEMORY_LIMIT",
    "machine_memory",
    "run_bytes",
    "memory_budget",
]

#: With ``landmarks="auto"`` captures up to this many frames use every frame ...
AUTO_FULL_LIMIT = 1000
#: ... and longer ones this many greedy landmarks (fewer if the memory guard says so).
AUTO_LANDMARKS = 500
#: Default memory budget for one filtration, in bytes (a laptop-friendly 2 GiB).
DEFAULT_MEMORY_LIMIT = 2 * 1024**3

# The filtration on n points: a float64 (n, n) distance matrix and its float32 condensed
# copies (periodic._rips), then a handful of 8-byte words per edge column in the reduction.
_BYTES_PER_EDGE = 64
# Per-frame arrays of a run (extract / CircularCoordinates): the points, the poses and one
# (T, K) temporary at a time, plus about sixteen float64 or int64 values per frame
# (coordinates, unwrapped phase, nearest landmark, greedy distances, phase sort, ...) ...
_COPIES_PER_VALUE = 3
_WORDS_PER_FRAME = 16
# ... and work arrays of bounded size: the density's EM (30 components, on three copies
# of at most 20,000 values: three (values x components) arrays at its peak), the kernel
# average's, the metrics' and the coordinate extension's blocks.
_EM_BYTES_PER_VALUE = 8 * 3 * 30 * 3
_EM_MAX_VALUES = 20_000
_FIXED_SCRATCH = 40 * 1024**2


def run_bytes(n_frames: int, n_dims: int, n_channels: int | None = None) -> float:
    """Estimated peak bytes of a run's per-frame arrays (everything but the filtration).

    Parameters
    ----------
    n_frames : int
        Frames analysed ``T``.
    n_dims : int
        Dimensions ``K`` of the analysed points.
    n_channels : int, optional
        Channels ``D`` of the poses the cycle is averaged from (default ``K``).

    Each frame counts three float64 copies of its ``max(K, D)`` values and 16 float64
    words, ``8 * (3 * max(K, D) + 16)`` bytes; the density's EM work grows with the
    frames up to 20,000 and 40 MiB of bounded scratch is added once.
    """
    d = n_dims if n_channels is None else n_channels
    per_frame = 8.0 * (_COPIES_PER_VALUE * max(n_dims, d) + _WORDS_PER_FRAME)
    em = _EM_BYTES_PER_VALUE * min(int(n_frames), _EM_MAX_VALUES)
    return per_frame * float(n_frames) + em + _FIXED_SCRATCH


def _gb(b: float) -> str:
    return f"{b / 1e9:.2f} GB"


def memory_budget(memory_limit: float | None, reserved: float, what: str = "") -> tuple[float, str]:
    """Bytes left for the filtration, and a note on where the figure came from.

    Parameters
    ----------
    memory_limit : float or None
        A stated limit for the run's large arrays (bytes), or None for the default
        (:data:`DEFAULT_MEMORY_LIMIT` for the filtration alone).
    reserved : float
        Bytes of the run's other arrays (:func:`run_bytes`).
    what : str
        Names the run in messages (e.g. ``"64000 frames of 62 dimensions"``).

    Raises
    ------
    ParameterError
        When the run's other arrays alone exceed the stated limit or the machine's memory.
    """
    if memory_limit is not None and (
        isinstance(memory_limit, bool) or not np.isfinite(memory_limit) or memory_limit <= 0
    ):
        raise ParameterError(f"memory limit must be a positive number of bytes, got {memory_limit}")
    machine = machine_memory()
    run = f" ({what})" if what else ""
    if reserved >= machine:
        raise ParameterError(
            f"not enough memory: the run's per-frame arrays{run} need about "
            f"{_gb(reserved)} and this machine allows {_gb(machine)}; "
            "analyse fewer frames (--frames) or fewer dimensions (--pca)"
        )
    if memory_limit is None:
        budget = min(float(DEFAULT_MEMORY_LIMIT), machine - reserved)
        note = f"{_gb(budget)} for the filtration"
    else:
        if reserved >= memory_limit:
            raise ParameterError(
                f"memory limit {_gb(memory_limit)} is too small: the run's "
                f"per-frame arrays{run} need about {_gb(reserved)} before the "
                "filtration; raise --memory-limit or analyse fewer frames"
            )
        budget = min(float(memory_limit), machine) - reserved
        note = (
            f"{_gb(budget)} for the filtration: the {_gb(memory_limit)} limit less "
            f"{_gb(reserved)} of per-frame arrays"
        )
    if memory_limit is not None and memory_limit > machine:
        note += f" (the stated limit exceeds the machine's {_gb(machine)}; that is used)"
    elif memory_limit is None and machine - reserved < DEFAULT_MEMORY_LIMIT:
        note += f" (what the machine's {_gb(machine)} leaves)"
    return budget, note


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
    greedy step (one ``pairwise_distances`` call per landmark) took about four.  From
    50,000 points on, each step first screens every point by its distance in a
    4-dimensional principal projection (a lower bound of the true distance, one cheap
    pass) and measures in full only the points that bound cannot rule out: at 200,000
    frames 6.2 -> 1.5 CPU-s, the same landmarks (tested against the full pass).

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
    indices : ndarray of int, shape (n,) or fewer
        Landmarks in the order chosen; fewer than ``n`` when every point repeats one of
        them (a capture that loops exactly, e.g. a keyframed clip played several times:
        repeated landmarks tied the coordinate's least squares in knots).
    covering_radius : float
        Largest distance from any point to its nearest landmark (ripser's ``r_cover``).
    """
    x = np.asarray(points, dtype=float)
    if x.ndim != 2 or (distance_matrix and x.shape[0] != x.shape[1]):
        raise ParameterError(
            f"points must be a (T, K) array or a (T, T) distance matrix, got shape {x.shape}"
        )
    T = x.shape[0]
    if isinstance(n, bool) or int(n) != n or not 1 <= n <= T:
        raise ParameterError(f"the number of landmarks must be between 1 and {T}, got {n!r}")
    if not 0 <= start < T:
        raise ParameterError(f"start must index a point (0..{T - 1}), got {start}")
    sq = None if distance_matrix else np.einsum("ij,ij->i", x, x)
    # a point this near a landmark repeats it (the product form's rounding for points)
    same = 1e-9 * float(np.abs(x).max()) if distance_matrix else 1e-12 * float(sq.max())
    idx = np.empty(int(n), dtype=np.int64)
    nearest = np.full(T, np.inf)  # squared distances for points, distances for a matrix
    i = int(start)
    bound = None
    if not distance_matrix and T >= _PROJECTED_FROM and x.shape[1] > _PROJECTED_DIMS:
        bound = _projection(x)
        bsq = np.einsum("ij,ij->i", bound, bound)
        slack = 1e-12 * float(sq.max())  # far above either product form's rounding
    for k in range(int(n)):
        idx[k] = i
        if bound is not None and k > 0:
            # only points whose projected distance (a lower bound) might beat their nearest
            lower = bsq + bsq[i] - 2.0 * (bound @ bound[i])
            cand = np.flatnonzero(lower < nearest + slack)
            d = sq[cand] + sq[i] - 2.0 * (x[cand] @ x[i])
            nearest[cand] = np.minimum(nearest[cand], d)
        else:
            d = x[i] if distance_matrix else sq + sq[i] - 2.0 * (x @ x[i])
            np.minimum(nearest, d, out=nearest)
        nearest[i] = 0.0
        i = int(np.argmax(nearest))
        if k + 1 < n and nearest[i] <= same:  # every point repeats a landmark
            return idx[: k + 1], 0.0
    if n == T:
        return idx, 0.0
    # the farthest point's distance, exactly (the product form loses digits near 0)
    radius = x[i, idx].min() if distance_matrix else np.linalg.norm(x[i] - x[idx], axis=1).min()
    return idx, float(radius)


#: From this many points on, greedy_landmarks screens each step with a projection of the
#: points on their first principal directions: the projected distance is a lower bound
#: of the true one, so only points it cannot rule out are measured in full.
_PROJECTED_FROM = 50_000
_PROJECTED_DIMS = 4


def _projection(x: np.ndarray, block: int = 65_536) -> np.ndarray:
    """Coordinates of ``x`` on its first principal directions (orthonormal: distances
    between projections never exceed the true ones), from a sample of at most 20,000."""
    T = x.shape[0]
    sub = x[:: max(1, T // 20_000)]
    _, _, vt = np.linalg.svd(sub - sub.mean(axis=0), full_matrices=False)
    basis = vt[:_PROJECTED_DIMS].T
    out = np.empty((T, basis.shape[1]))
    for a in range(0, T, block):
        out[a : a + block] = x[a : a + block] @ basis
    return out


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
    return _estimate(n, *_pair_fractions(x, threshold, n_samples, random_state))


def _pair_fractions(
    x: np.ndarray, threshold: float, n_samples: int, random_state: int
) -> tuple[float, float]:
    """Fractions of random pairs (triples) of points within ``threshold`` (of each other)."""
    T = x.shape[0]
    rng = np.random.default_rng(random_state)
    i = rng.integers(0, T, n_samples)
    j = rng.integers(0, T, n_samples)
    k = rng.integers(0, T, n_samples)
    ok = (i != j) & (j != k) & (i != k)
    i, j, k = i[ok], j[ok], k[ok]
    if not i.size:
        return 0.0, 0.0
    dij = np.linalg.norm(x[i] - x[j], axis=1) <= threshold
    # the other two sides only where the first is an edge (the same triangles, less work)
    e = np.flatnonzero(dij)
    tri = (np.linalg.norm(x[j[e]] - x[k[e]], axis=1) <= threshold) & (
        np.linalg.norm(x[i[e]] - x[k[e]], axis=1) <= threshold
    )
    return float(dij.mean()), float(np.count_nonzero(tri) / dij.size)


def _estimate(n: int, p_edge: float, p_tri: float) -> ComplexEstimate:
    edges = p_edge * comb(n, 2)
    triangles = p_tri * comb(n, 3)
    # the distance matrix of the n vertices (landmarks are chosen in O(T) memory, counted
    # with the run's per-frame arrays, see run_bytes) and the reduction's edge columns
    mem = DENSE_BYTES_PER_PAIR * float(n) * n + _BYTES_PER_EDGE * edges
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
        Bytes for the filtration (see :func:`memory_budget`).  When the estimate
        exceeds it, the landmark count is reduced until it fits (down to 50);
        ``landmarks=None`` then switches to landmarks as well.

    Returns
    -------
    n_landmarks : int or None
        ``None`` means every point.
    estimate : ComplexEstimate or None
        For the complex that will be built; None when even the complete complex fits the
        budget (then ``estimate_complex(points, threshold, n_landmarks)`` gives it; the
        sampled estimate costs more than a small filtration).
    reason : str
        Human-readable account of the decision (for the report).
    """
    T = len(points)
    if memory_limit is None or not np.isfinite(memory_limit) or memory_limit <= 0:
        raise ParameterError(
            f"memory budget must be a positive number of bytes, got {memory_limit}"
        )
    if landmarks is None or (
        isinstance(landmarks, str) and landmarks.lower() in ("none", "all", "full")
    ):
        n, reason = None, "every frame (landmarks off)"
    elif isinstance(landmarks, str):
        if landmarks.lower() != "auto":
            raise ParameterError(f"landmarks must be 'auto', 'none' or a number, got {landmarks!r}")
        if T <= AUTO_FULL_LIMIT:
            n, reason = None, f"every frame ({T} <= {AUTO_FULL_LIMIT})"
        else:
            n, reason = (
                AUTO_LANDMARKS,
                f"{AUTO_LANDMARKS} greedy landmarks of {T} frames (automatic)",
            )
    else:
        try:
            n = int(landmarks)
        except (TypeError, ValueError):
            raise ParameterError(
                f"landmarks must be 'auto', 'none' or a number, got {landmarks!r}"
            ) from None
        if n < 10:
            raise ParameterError(f"need at least 10 landmarks, got {n}")
        if n >= T:
            n, reason = None, f"every frame ({landmarks} landmarks requested, {T} frames)"
        else:
            reason = f"{n} greedy landmarks of {T} frames (requested)"
    m0 = T if n is None else min(int(n), T)
    if DENSE_BYTES_PER_PAIR * float(m0) * m0 + _BYTES_PER_EDGE * comb(m0, 2) <= memory_limit:
        # even the complete complex fits: the estimate cannot change the decision, so it is
        # left to whoever asks (estimate_complex(points, threshold, n) gives the same figures)
        return n, None, reason
    x = np.asarray(points, dtype=float)
    fractions = _pair_fractions(x, threshold, 20_000, 0) if T >= 3 else (0.0, 0.0)

    def size(m: int | None) -> ComplexEstimate:  # estimate_complex(points, threshold, m)
        m = T if m is None else int(min(m, T))
        return _estimate(m, *fractions) if T >= 3 else ComplexEstimate(T, 0.0, 0.0, 0.0)

    est = size(n)
    if est.bytes > memory_limit:
        before = est
        m = n if n is not None else min(T, AUTO_LANDMARKS)
        est = size(m)
        while est.bytes > memory_limit and m > 50:
            m = max(50, int(m * 0.7))
            est = size(m)
        if est.bytes > memory_limit:
            raise ParameterError(
                f"not enough memory: even {m} landmarks need about {est.bytes / 1e9:.2f} GB for "
                f"the filtration at scale {threshold:.4g}, over the {memory_limit / 1e9:.2f} GB "
                "left for it; lower --max-scale or raise --memory-limit"
            )
        reason = (
            f"memory guard: the complex on {before.n_points} points was estimated at "
            f"{before.bytes / 1e9:.2f} GB ({before.edges:.3g} edges) over the "
            f"{memory_limit / 1e9:.2f} GB "
            f"budget; using {m} greedy landmarks ({est.bytes / 1e9:.2f} GB)"
        )
        n = m if m < T else None
    return n, est, reason
