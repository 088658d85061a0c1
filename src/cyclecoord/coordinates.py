"""Circular coordinates from an H1 cocycle: integer lift, least squares, ``w mod 1``.

Given a cocycle ``z`` over Z/p that represents a persistent class alive at scale
``eps``, the edges of the Rips complex at ``eps`` form a graph; ``z`` is lifted to integer
values (centred in ``(-p/2, p/2]``), checked to be a cocycle on every triangle that
touches its support, and smoothed by the least-squares problem
``argmin_w ||z + δw||₂`` (de Silva, Morozov, Vejdemo-Johansson 2011).  The smoothed
cocycle ``z + δw`` is the harmonic representative; ``-w mod 1`` is a map to the circle
whose increments along edges follow ``z``.  The coordinate is oriented to increase with
frame order and rotated so the first frame sits at 0.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.sparse.linalg import lsqr
from scipy.spatial import cKDTree

from .barcode import DEFAULT_PRIME, Barcode, BarSelection, compute_barcode, select_bar, temporal_distance_matrix
from .errors import ParameterError

__all__ = [
    "CircularCoordinates",
    "CocycleCheck",
    "rips_edges",
    "lift_cocycle",
    "check_cocycle",
    "harmonic_coordinate",
    "orient_with_time",
    "unwrap",
    "RETRY_PRIMES",
]

#: Primes tried, in order, when a cocycle's integer lift fails the cocycle condition.
RETRY_PRIMES = (47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97)


def rips_edges(points: np.ndarray, scale: float, distances: np.ndarray | None = None) -> np.ndarray:
    """Edges ``(i, j)``, ``i < j``, of the Rips complex at ``scale``.

    Parameters
    ----------
    points : ndarray, shape (T, K)
    scale : float
    distances : ndarray, shape (T, T), optional
        Use this distance matrix instead of Euclidean distances between ``points``.

    Returns
    -------
    ndarray of int, shape (E, 2), sorted lexicographically.
    """
    if distances is not None:
        i, j = np.nonzero(np.triu(distances <= scale, k=1))
        edges = np.column_stack([i, j])
    else:
        edges = cKDTree(points).query_pairs(r=scale, output_type="ndarray")
        edges = np.sort(edges, axis=1)
    if edges.size == 0:
        return np.zeros((0, 2), dtype=np.int64)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    return edges[order].astype(np.int64)


def lift_cocycle(cocycle: np.ndarray, prime: int) -> np.ndarray:
    """Centred integer lift of Z/p values: ``v`` if ``v <= p // 2`` else ``v - p``."""
    v = np.asarray(cocycle)[:, 2].astype(np.int64) % prime
    return np.where(v > prime // 2, v - prime, v)


@dataclass(frozen=True)
class CocycleCheck:
    """Result of checking the lifted cocycle on the triangles at the chosen scale.

    Attributes
    ----------
    n_triangles : int
        Triangles checked (those with at least one edge in the cocycle's support).
    n_violations : int
        Triangles on which the integer coboundary ``z(ab) + z(bc) - z(ac)`` is not zero.
    n_outside : int
        Support edges longer than the scale.  ripser returns the representative on the
        complex at the threshold; its restriction to the complex at the chosen scale is
        a cocycle of the same persistent class, so these edges are simply left out.
    """

    n_triangles: int
    n_violations: int
    n_outside: int = 0

    @property
    def ok(self) -> bool:
        return self.n_violations == 0


def _edge_values(edges: np.ndarray, cocycle: np.ndarray, values: np.ndarray, n: int) -> tuple[np.ndarray, int]:
    """Spread cocycle values onto ``edges`` (zero elsewhere); count support edges not found."""
    key = edges[:, 0] * n + edges[:, 1]
    ckey = cocycle[:, 0].astype(np.int64) * n + cocycle[:, 1].astype(np.int64)
    pos = np.searchsorted(key, ckey)
    pos = np.minimum(pos, len(key) - 1) if len(key) else pos
    found = (len(key) > 0) & (key[pos] == ckey) if len(key) else np.zeros(len(ckey), bool)
    z = np.zeros(len(edges))
    np.add.at(z, pos[found], values[found])
    return z, int(np.sum(~found))


def _lookup(edges: np.ndarray, z: np.ndarray, n: int, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Value of the cochain on the oriented edges ``u -> v`` (zero where no such edge)."""
    lo, hi = np.minimum(u, v), np.maximum(u, v)
    key = edges[:, 0] * n + edges[:, 1]
    q = lo.astype(np.int64) * n + hi
    pos = np.minimum(np.searchsorted(key, q), len(key) - 1)
    val = np.where(key[pos] == q, z[pos], 0.0)
    return np.where(u < v, val, -val)


def check_cocycle(edges: np.ndarray, z: np.ndarray, n: int) -> CocycleCheck:
    """Verify ``δz = 0`` on every triangle of the flag complex touching the support of ``z``.

    ``edges`` must be sorted lexicographically (as :func:`rips_edges` returns them).
    """
    support = np.flatnonzero(z)
    if support.size == 0:
        return CocycleCheck(0, 0)
    i, j = edges[:, 0], edges[:, 1]
    adj = sp.csr_matrix((np.ones(len(edges)), (i, j)), shape=(n, n))
    adj = (adj + adj.T).tocsr()
    a, b = i[support], j[support]
    common = adj[a].multiply(adj[b]).tocoo()  # row r: a support edge, col: third vertex c
    if common.nnz == 0:
        return CocycleCheck(0, 0)
    ea, eb, c = a[common.row], b[common.row], common.col.astype(np.int64)
    # oriented cycle a -> b -> c -> a
    val = z[support][common.row] + _lookup(edges, z, n, eb, c) + _lookup(edges, z, n, c, ea)
    bad = np.abs(val) > 0.5
    # a triangle holding k support edges is seen k times: count distinct triangles
    tri = np.sort(np.column_stack([ea, eb, c]), axis=1)
    key = (tri[:, 0] * n + tri[:, 1]) * n + tri[:, 2]
    nbad = len(np.unique(key[bad])) if bad.any() else 0
    return CocycleCheck(n_triangles=int(len(np.unique(key))), n_violations=int(nbad))


def harmonic_coordinate(edges: np.ndarray, z: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Solve ``argmin_w ||z + δw||₂`` and return the circle map ``-w mod 1``.

    Parameters
    ----------
    edges : ndarray, shape (E, 2)
        Oriented ``i -> j`` with ``i < j``.
    z : ndarray, shape (E,)
        Real (lifted) cocycle values.
    n : int
        Number of vertices.

    Returns
    -------
    theta : ndarray, shape (n,)
        Values in [0, 1).
    harmonic : ndarray, shape (E,)
        The harmonic representative ``z + δw`` (small where the coordinate is smooth).
    """
    e = len(edges)
    rows = np.repeat(np.arange(e), 2)
    cols = edges.ravel()
    vals = np.tile([-1.0, 1.0], e)
    delta = sp.csr_matrix((vals, (rows, cols)), shape=(e, n))
    w = lsqr(delta, -z, atol=1e-12, btol=1e-12, iter_lim=20 * n + 1000)[0]
    harmonic = z + delta @ w
    theta = np.mod(-w, 1.0)
    return theta, harmonic


def orient_with_time(theta: np.ndarray) -> np.ndarray:
    """Flip the coordinate if it runs backwards in frame order, and put frame 0 at 0."""
    steps = np.mod(np.diff(theta) + 0.5, 1.0) - 0.5
    if steps.sum() < 0:
        theta = np.mod(-theta, 1.0)
    return np.mod(theta - theta[0], 1.0)


def unwrap(theta: np.ndarray) -> np.ndarray:
    """Unwrap a circular coordinate along frame order (steps wrapped into [-0.5, 0.5))."""
    steps = np.mod(np.diff(theta) + 0.5, 1.0) - 0.5
    return np.concatenate([[theta[0]], theta[0] + np.cumsum(steps)])


class CircularCoordinates:
    """Circle-valued coordinate of a point cloud from its persistent cohomology.

    scikit-learn style estimator: parameters in ``__init__``; :meth:`fit` computes the
    barcode, chooses a class and a scale, and solves for the coordinate; learned state
    lives in attributes ending in ``_``.

    Parameters
    ----------
    max_scale : float, optional
        Filtration threshold (see :func:`cyclecoord.barcode.default_max_scale`).
    scale : float, optional
        Scale at which the cocycle is read; default is high inside the bar.
    class_index : int, default 0
        Which H1 class, by decreasing persistence.
    prime : int, default 47
        Coefficient field; a prime greater than 11.
    scale_fraction : float, default 0.9
        Where in the bar the default scale sits (0 = birth, 1 = death).
    temporal : bool, default False
        Use the time-aware metric where consecutive frames are at distance 0.
    n_landmarks : int, optional
        Greedy landmark subsample for the barcode (every point by default).

    Attributes
    ----------
    barcode_ : Barcode
    selection_ : BarSelection
    prime_ : int
        The prime finally used (another is tried if the lift fails the cocycle check).
    edges_ : ndarray, shape (E, 2)
        Rips edges at the chosen scale.
    cocycle_ : ndarray, shape (E,)
        Integer-lifted cocycle on ``edges_``.
    harmonic_cocycle_ : ndarray, shape (E,)
        Its harmonic (least-squares) representative.
    cocycle_check_ : CocycleCheck
    coordinates_ : ndarray, shape (T,)
        Circular coordinate of the training points, in [0, 1).
    n_components_ : int
        Connected components of the graph at the chosen scale (1 is expected).
    """

    def __init__(
        self,
        max_scale: float | None = None,
        scale: float | None = None,
        class_index: int = 0,
        prime: int = DEFAULT_PRIME,
        scale_fraction: float = 0.9,
        temporal: bool = False,
        n_landmarks: int | None = None,
    ) -> None:
        self.max_scale = max_scale
        self.scale = scale
        self.class_index = class_index
        self.prime = prime
        self.scale_fraction = scale_fraction
        self.temporal = temporal
        self.n_landmarks = n_landmarks

    # ------------------------------------------------------------------
    def _validate(self, X) -> np.ndarray:
        x = np.asarray(X, dtype=float)
        if x.ndim != 2:
            raise ParameterError(f"expected a (T, K) array of points, got shape {x.shape}")
        if x.shape[0] < 3:
            raise ParameterError(f"need at least 3 points, got {x.shape[0]}")
        if not np.all(np.isfinite(x)):
            raise ParameterError("points contain NaN or infinite values")
        return x

    def fit_barcode(self, X) -> Barcode:
        """Compute (only) the barcode; sets ``barcode_`` and returns it."""
        x = self._validate(X)
        self._dist_ = temporal_distance_matrix(x) if self.temporal else None
        src = self._dist_ if self.temporal else x
        self.barcode_ = compute_barcode(
            src,
            max_scale=self.max_scale,
            prime=self.prime,
            distance_matrix=self.temporal,
            n_landmarks=self.n_landmarks,
        )
        self.points_ = x
        return self.barcode_

    def fit(self, X, y=None) -> "CircularCoordinates":
        """Barcode, class and scale selection, cocycle check and the coordinate.

        Parameters
        ----------
        X : array-like, shape (T, K)
            Points (one per frame, in frame order: the orientation follows it).
        """
        self.fit_barcode(X)
        return self.fit_coordinate()

    def fit_coordinate(self) -> "CircularCoordinates":
        """Second half of :meth:`fit`: select the class and solve for the coordinate,
        reusing the barcode from :meth:`fit_barcode` (so a caller can inspect the
        barcode first without computing it twice)."""
        if not hasattr(self, "barcode_"):
            raise ParameterError("call fit_barcode() before fit_coordinate()")
        barcode = self.barcode_
        x = self.points_
        selection = select_bar(barcode, self.class_index, self.scale, self.scale_fraction)
        n = len(x)
        edges = rips_edges(x, selection.scale, self._dist_)
        # Lift and check; when the lift is not an integer cocycle, retry with other primes.
        tried = []
        best = None
        primes = [barcode.prime] + [p for p in RETRY_PRIMES if p != barcode.prime]
        for k, p in enumerate(primes):
            if k == 0:
                bc, sel = barcode, selection
            else:
                bc = compute_barcode(
                    self._dist_ if self.temporal else x,
                    max_scale=barcode.threshold,
                    prime=p,
                    distance_matrix=self.temporal,
                    n_landmarks=self.n_landmarks,
                )
                # the same class: nearest bar in (birth, capped death)
                if len(bc.h1) == 0:
                    continue
                cap = np.minimum(bc.h1[:, 1], bc.threshold)
                ref = (selection.birth, min(selection.death, barcode.threshold))
                idx = int(np.argmin(np.abs(bc.h1[:, 0] - ref[0]) + np.abs(cap - ref[1])))
                try:
                    sel = select_bar(bc, idx, selection.scale if selection.scale < bc.h1[idx, 1] else None, self.scale_fraction)
                except ParameterError:
                    continue
            cocycle = bc.cocycles[sel.index]
            z, outside = _edge_values(edges, cocycle, lift_cocycle(cocycle, p).astype(float), n)
            check = check_cocycle(edges, z, n)
            check = CocycleCheck(check.n_triangles, check.n_violations, outside)
            tried.append((p, check.n_violations))
            if best is None or check.n_violations < best[3].n_violations:
                best = (p, bc, sel, check, z)
            if check.ok:
                break
        p, bc, sel, check, z = best
        if not check.ok:
            warnings.warn(
                f"the integer lift of the cocycle fails the cocycle condition on {check.n_violations} "
                f"of {check.n_triangles} triangles for every prime tried; using p={p}",
                RuntimeWarning,
                stacklevel=2,
            )
        ncomp, _ = connected_components(
            sp.csr_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(n, n)), directed=False
        )
        theta, harmonic = harmonic_coordinate(edges, z, n)
        self.barcode_ = bc
        self.selection_ = sel
        self.prime_ = p
        self.primes_tried_ = tried
        self.edges_ = edges
        self.cocycle_ = z
        self.harmonic_cocycle_ = harmonic
        self.cocycle_check_ = check
        self.n_components_ = int(ncomp)
        self.coordinates_ = orient_with_time(theta)
        # remember orientation/rotation relative to the raw solution, for transform()
        self._tree_ = cKDTree(x) if not self.temporal else None
        return self

    def transform(self, X) -> np.ndarray:
        """Circular coordinate of points.

        The training points get their fitted coordinate.  Other points get the
        circular mean of the coordinates of the training points within the chosen
        scale, weighted by ``1 - d/scale`` (or of their 5 nearest training points when
        none is that close): a partition-of-unity extension of the fitted map.
        """
        if not hasattr(self, "coordinates_"):
            raise ParameterError("this CircularCoordinates is not fitted yet; call fit() first")
        x = self._validate(X)
        if x.shape == self.points_.shape and np.array_equal(x, self.points_):
            return self.coordinates_.copy()
        if x.shape[1] != self.points_.shape[1]:
            raise ParameterError(f"points have {x.shape[1]} dimensions, the model was fitted on {self.points_.shape[1]}")
        tree = self._tree_ if self._tree_ is not None else cKDTree(self.points_)
        k = min(32, len(self.points_))
        d, idx = tree.query(x, k=k)
        d = np.atleast_2d(d)
        idx = np.atleast_2d(idx)
        s = self.selection_.scale
        w = np.clip(1.0 - d / s, 0.0, None)
        none = w.sum(axis=1) == 0
        w[none, :5] = 1.0 / (1e-12 + d[none, :5])
        ang = 2 * np.pi * self.coordinates_[idx]
        c = (w * np.cos(ang)).sum(axis=1)
        si = (w * np.sin(ang)).sum(axis=1)
        return np.mod(np.arctan2(si, c) / (2 * np.pi), 1.0)

    def fit_transform(self, X, y=None) -> np.ndarray:
        return self.fit(X).coordinates_.copy()
