"""Cochains on the Rips graph of the centres, and the extension of their coordinate to every
frame: Rips edges, integer lift and cocycle check, the harmonic (least-squares) smoothing,
orientation along time, and the partition-of-unity extension (see
:mod:`cyclecoord.periodic.coordinates`, whose estimator strings these together and which
re-exports the public functions).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree



__all__ = [
    "CocycleCheck",
    "rips_edges",
    "lift_cocycle",
    "check_cocycle",
    "cocycle_on_edges",
    "harmonic_coordinate",
    "mod_one",
    "orient_with_time",
    "extend_coordinate",
    "unwrap",
]


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


def cocycle_on_edges(
    edges: np.ndarray, cocycle: np.ndarray, values: np.ndarray, n: int
) -> tuple[np.ndarray, int]:
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
    z_bc = _lookup(edges, z, n, eb, c)
    z_ca = _lookup(edges, z, n, c, ea)
    val = z[support][common.row] + z_bc + z_ca
    bad = np.abs(val) > 0.5
    # A triangle holding k support edges is seen once from each of them (k = 1 + the
    # other two edges in the support), with the same |coboundary| every time: the
    # distinct triangles are sum over k of (rows seen with k) / k -- no sort, no unique.
    k = 1 + (z_bc != 0).astype(np.int64) + (z_ca != 0).astype(np.int64)
    seen = np.bincount(k, minlength=4)
    seen_bad = np.bincount(k[bad], minlength=4)
    n_tri = int(seen[1] + seen[2] // 2 + seen[3] // 3)
    nbad = int(seen_bad[1] + seen_bad[2] // 2 + seen_bad[3] // 3)
    return CocycleCheck(n_triangles=n_tri, n_violations=nbad)


def harmonic_coordinate(
    edges: np.ndarray, z: np.ndarray, n: int, weights: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Solve ``argmin_w ||z + δw||₂`` and return the circle map ``-w mod 1``.

    Parameters
    ----------
    edges : ndarray, shape (E, 2)
        Oriented ``i -> j`` with ``i < j``.
    z : ndarray, shape (E,)
        Real (lifted) cocycle values.
    n : int
        Number of vertices.
    weights : ndarray, shape (E,), optional
        Edge weights of a weighted least-squares problem ``argmin_w Σ_e weights_e (z + δw)_e²``
        (used with landmarks: the product of the two landmarks' cell sizes, so that the
        landmark problem approximates the one on every point).

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
    w = _least_squares_potential(delta, edges, z, n, weights)
    harmonic = z + delta @ w
    theta = mod_one(-w)
    return theta, harmonic


def _least_squares_potential(
    delta: sp.csr_matrix, edges: np.ndarray, z: np.ndarray, n: int, weights: np.ndarray | None
) -> np.ndarray:
    """The minimum-norm ``w`` minimising ``sum_e weights_e (z + δw)_e²``.

    A direct solve of the normal equations instead of LSQR: ``L w = -δᵀ W z`` with the
    weighted graph Laplacian ``L = δᵀ W δ``, one vertex of each connected component held
    at 0 (``L`` is singular only along each component's constants), one sparse LU
    factorisation; then each component's mean is removed, which gives the minimum-norm
    solution LSQR converges to.  Agrees with LSQR (``atol = btol = 1e-12``) to about
    1e-10 (tested) and costs one factorisation instead of hundreds of products.  Used for
    the unweighted problem (every point, and detect's windows); the weighted landmark
    problem is still solved by LSQR (see the comment below).
    """
    from scipy.sparse.linalg import lsqr, splu

    if weights is not None:
        # the landmark problem keeps LSQR: on CMU-like chains detect's segment boundaries
        # sit on an edge that a 1e-12 change of a landmark coordinate can tip (a synthetic
        # walk/jog/squat chain moved a boundary 16 frames); its landmarks are few (500),
        # so this costs little, and every landmark result stays as it was, bit for bit
        sw = np.sqrt(np.asarray(weights, dtype=float))
        return lsqr(sp.diags(sw) @ delta, -sw * z, atol=1e-12, btol=1e-12, iter_lim=20 * n + 1000)[
            0
        ]
    wts = np.ones(len(z))
    a, b = edges[:, 0], edges[:, 1]
    wz = wts * z
    rhs = np.bincount(a, weights=wz, minlength=n) - np.bincount(
        b, weights=wz, minlength=n
    )  # -δᵀ W z
    ncomp, label = connected_components(
        sp.csr_matrix((np.ones(len(edges)), (a, b)), shape=(n, n)), directed=False
    )
    first = np.full(ncomp, -1)
    first[label[::-1]] = np.arange(n)[::-1]  # lowest vertex of each component
    free = np.ones(n, dtype=bool)
    free[first] = False
    w = np.zeros(n)
    if free.any():
        # the Laplacian δᵀ W δ restricted to the free vertices, assembled from the edges
        pos = np.cumsum(free) - 1
        deg = np.bincount(a, weights=wts, minlength=n) + np.bincount(b, weights=wts, minlength=n)
        both = free[a] & free[b]
        fv = np.flatnonzero(free)
        rows = np.concatenate([pos[fv], pos[a[both]], pos[b[both]]])
        cols = np.concatenate([pos[fv], pos[b[both]], pos[a[both]]])
        vals = np.concatenate([deg[fv], -wts[both], -wts[both]])
        lap = sp.csc_matrix((vals, (rows, cols)), shape=(fv.size, fv.size))
        w[fv] = splu(lap, permc_spec="COLAMD").solve(rhs[fv])
    w -= (np.bincount(label, weights=w, minlength=ncomp) / np.bincount(label, minlength=ncomp))[
        label
    ]
    return w


def mod_one(x: np.ndarray) -> np.ndarray:
    """``x mod 1`` in [0, 1): ``np.mod(-1e-17, 1.0)`` is 1.0 in floating point, which is 0."""
    out = np.mod(x, 1.0)
    out[out >= 1.0] = 0.0
    return out


def orient_with_time(theta: np.ndarray, return_transform: bool = False):
    """Flip the coordinate if it runs backwards in frame order, and put frame 0 at 0.

    With ``return_transform`` also returns ``(sign, offset)`` such that the result is
    ``(sign * theta - offset) mod 1``, to apply the same change to other points.
    """
    steps = np.mod(np.diff(theta) + 0.5, 1.0) - 0.5
    sign = -1.0 if steps.sum() < 0 else 1.0
    t = mod_one(sign * theta)
    offset = float(t[0])
    out = mod_one(t - offset)
    return (out, sign, offset) if return_transform else out


def extend_coordinate(
    points: np.ndarray,
    centers: np.ndarray,
    center_theta: np.ndarray,
    edges: np.ndarray,
    harmonic: np.ndarray,
    radius: float,
    max_neighbors: int = 48,
    chunk: int = 4_000,
) -> tuple[np.ndarray, np.ndarray]:
    """Circular coordinate of arbitrary points from a solution on ``centers``.

    A partition of unity over the balls of ``radius`` around the centers (weights
    ``(radius - d)²``, normalised) blends the harmonic cocycle: a point ``x`` whose
    nearest center is ``j`` gets ``θ_j + Σ_k φ_k(x) Δ(j → k)``, where ``Δ(j → k)`` is the
    coordinate's increment along the edge ``j -> k`` of the complex at scale
    ``2 * radius`` (every pair of centers whose balls both hold ``x`` is such an edge).
    This is the sparse circular-coordinate construction of Perea (2020); for a center
    itself it returns (nearly) its own value.

    Parameters
    ----------
    points : ndarray, shape (N, K)
    centers : ndarray, shape (L, K)
    center_theta : ndarray, shape (L,)
        Raw (unoriented) coordinate ``-w mod 1`` of the centers.
    edges, harmonic : ndarray
        Sorted edges ``(i, j)``, ``i < j``, between centers and the harmonic cocycle on them.
    radius : float
        Ball radius, half the scale of the complex.

    Returns
    -------
    theta : ndarray, shape (N,)
        Raw coordinate in [0, 1).
    covered : ndarray of bool, shape (N,)
        Whether the point lay inside at least one ball (others take the nearest center's
        value).
    """
    x = np.asarray(points, dtype=float)
    L = len(centers)
    tree = cKDTree(centers)
    k = int(min(L, max_neighbors))
    theta = np.empty(len(x))
    covered = np.empty(len(x), dtype=bool)
    table = _increment_table(edges, harmonic, L) if L <= _TABLE_MAX_CENTERS else None
    for a in range(0, len(x), chunk):
        q = x[a : a + chunk]
        d, idx = tree.query(q, k=k, distance_upper_bound=radius)
        d = np.asarray(d).reshape(len(q), k)
        idx = np.asarray(idx).reshape(len(q), k)
        valid = np.isfinite(d)
        phi = np.where(valid, (radius - np.where(valid, d, radius)) ** 2, 0.0)
        tot = phi.sum(axis=1)
        cov = tot > 0
        nearest = np.where(valid[:, 0], idx[:, 0], 0)
        out = np.empty(len(q))
        if cov.any():
            jj = np.repeat(nearest[cov][:, None], k, axis=1)
            kk = np.where(
                valid[cov], idx[cov], jj
            )  # padded slots point at j itself: zero increment
            if table is not None:
                inc = -table[jj, kk]
            else:
                inc = -_lookup(edges, harmonic, L, jj.ravel(), kk.ravel()).reshape(jj.shape)
            w = phi[cov] / tot[cov][:, None]
            out[cov] = center_theta[nearest[cov]] + (w * inc).sum(axis=1)
        if (~cov).any():
            _, nn = tree.query(q[~cov], k=1)
            out[~cov] = center_theta[np.asarray(nn).ravel()]
        theta[a : a + chunk] = mod_one(out)
        covered[a : a + chunk] = cov
    return theta, covered


#: Up to this many centers the cochain is held as an (L, L) table (8 L² bytes: 72 MB at
#: 3,000) for the extension's lookups, instead of a binary search per lookup.
_TABLE_MAX_CENTERS = 3000


def _increment_table(edges: np.ndarray, z: np.ndarray, n: int) -> np.ndarray:
    """``table[u, v] == _lookup(edges, z, n, u, v)`` for every pair, bit for bit (signed
    zeros included: ``+0.0`` above the diagonal, ``-0.0`` on and below it)."""
    table = np.where(np.triu(np.ones((n, n), dtype=bool), k=1), 0.0, -0.0)
    table[edges[:, 0], edges[:, 1]] = z
    table[edges[:, 1], edges[:, 0]] = -z
    return table


def unwrap(theta: np.ndarray) -> np.ndarray:
    """Unwrap a circular coordinate along frame order (steps wrapped into [-0.5, 0.5))."""
    steps = np.mod(np.diff(theta) + 0.5, 1.0) - 0.5
    return np.concatenate([[theta[0]], theta[0] + np.cumsum(steps)])
