"""Motion graphs over training frames in the latent space (Gauch & Peters §III-B).

Every training frame is a node (keeping its take and frame number).  Each take's
consecutive frames are joined by directed edges; then undirected edges are added by

* ``"knn"``: ``p2`` is among ``p1``'s ``k`` nearest frames or vice versa;
* ``"delaunay"``: ``p1`` and ``p2`` are vertices of one simplex of the Delaunay
  triangulation (Qhull).  Qhull drops points it finds coplanar with a facet (exact
  duplicates, mostly); such a frame is joined to the vertices of the simplex holding it;
* ``"union"``: both, the "k-Delaunay" the paper names as future work.

Each added edge keeps the direction whose dot product with the mean velocity of its two
ends is positive (neither when it is zero).  Weights are latent distances.
:meth:`MotionGraph.connectivity` reports weak and strong components, the paper's
bipartite start/end graph ``H`` and which takes cannot reach which.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import Delaunay, cKDTree

from ...errors import ParameterError

__all__ = [
    "METHODS",
    "MotionGraph",
    "build_graph",
    "training_vectors",
    "check_delaunay_dims",
    "MAX_DELAUNAY_DIMS",
    "MAX_SIMPLICES",
]

METHODS = ("delaunay", "knn", "union")
#: Delaunay triangulations beyond this many dimensions are refused outright.
MAX_DELAUNAY_DIMS = 7
#: Simplices per point of a Delaunay triangulation of walking frames (measured on CMU
#: 35, 1,712 frames: 2.0, 6.4, 28, 144 and 813 for d = 2..6; 7 extrapolated).
SIMPLICES_PER_POINT = {1: 1.0, 2: 2.0, 3: 6.5, 4: 28.0, 5: 145.0, 6: 815.0, 7: 4600.0}
#: Largest triangulation built (estimated simplices): about 3 s of Qhull and 1 GB at most.
MAX_SIMPLICES = 400_000


def check_method(method: str) -> str:
    if method not in METHODS:
        raise ParameterError(f"unknown graph method {method!r}; choose from {', '.join(METHODS)}")
    return method


def check_delaunay_dims(d: int, n_points: int) -> None:
    """Raise one line when a Delaunay triangulation in ``d`` dimensions is unaffordable."""
    estimate = SIMPLICES_PER_POINT.get(d, np.inf) * n_points
    if d > MAX_DELAUNAY_DIMS or estimate > MAX_SIMPLICES:
        raise ParameterError(
            f"a Delaunay triangulation of {n_points} frames in {d} dimensions would hold about "
            f"{estimate:.3g} simplices, more than the {MAX_SIMPLICES:,} it can afford; "
            "use method 'knn' or fewer dimensions"
        )
    if d < 2:
        raise ParameterError(f"a Delaunay triangulation needs at least 2 dimensions, got {d}")
    if n_points < d + 2:
        raise ParameterError(
            f"a Delaunay triangulation in {d} dimensions needs at least {d + 2} frames, "
            f"got {n_points}"
        )


def training_vectors(points: np.ndarray, take: np.ndarray) -> np.ndarray:
    """The paper's training vectors: ``(x[i+1] - x[i]) / 2``, backward at a take's end."""
    v = np.zeros_like(points)
    same = take[1:] == take[:-1]
    fwd = (points[1:] - points[:-1]) / 2.0
    v[:-1][same] = fwd[same]
    last = np.flatnonzero(np.append(~same, True))  # last frame of each take
    v[last] = (points[last] - points[last - 1]) / 2.0
    return v


def _knn_pairs(tree: cKDTree, points: np.ndarray, k: int) -> np.ndarray:
    k = min(k, points.shape[0] - 1)
    _, idx = tree.query(points, k=k + 1)
    rows = np.repeat(np.arange(points.shape[0]), k)
    cols = idx[:, 1:].reshape(-1)
    return np.stack([rows, cols], axis=1)


def _delaunay_pairs(tri: Delaunay) -> np.ndarray:
    s = tri.simplices
    m = s.shape[1]
    pairs = [s[:, [a, b]] for a in range(m) for b in range(a + 1, m)]
    if tri.coplanar.size:  # dropped points: join them to the vertices of their simplex
        pts, simp = tri.coplanar[:, 0], tri.coplanar[:, 1]
        for a in range(m):
            pairs.append(np.stack([pts, s[simp, a]], axis=1))
    return np.concatenate(pairs, axis=0)


def _undirected_unique(pairs: np.ndarray, n: int) -> np.ndarray:
    """Distinct unordered pairs ``(a < b)`` of ``pairs`` (one sort of integer keys)."""
    lo, hi = np.minimum(pairs[:, 0], pairs[:, 1]), np.maximum(pairs[:, 0], pairs[:, 1])
    keys = np.unique(lo[lo != hi].astype(np.int64) * n + hi[lo != hi])
    return np.stack([keys // n, keys % n], axis=1)


@dataclass
class MotionGraph:
    """A directed motion graph over training frames.

    Attributes
    ----------
    method : str
    points : ndarray, shape (n, d)
        Latent training points.
    velocities : ndarray, shape (n, d)
        Training vectors (:func:`training_vectors`).
    take : ndarray of int, shape (n,)
    frame : ndarray of int, shape (n,)
        Frame number within its take (0-based).
    edges : ndarray of int, shape (E, 2)
        Directed edges ``(from, to)``; the first ``n - r`` are the takes' own.
    k : int
    tree : cKDTree
    delaunay : scipy.spatial.Delaunay or None
    take_names : list of str
    """

    method: str
    points: np.ndarray
    velocities: np.ndarray
    take: np.ndarray
    frame: np.ndarray
    edges: np.ndarray
    k: int
    tree: cKDTree
    delaunay: Delaunay | None = None
    take_names: list = field(default_factory=list)

    @property
    def n_nodes(self) -> int:
        return int(self.points.shape[0])

    @property
    def n_takes(self) -> int:
        return int(self.take.max()) + 1

    @property
    def n_coplanar(self) -> int:
        """Frames Qhull left out of the triangulation (0 without one)."""
        return 0 if self.delaunay is None else int(self.delaunay.coplanar.shape[0])

    def adjacency(self, power: float = 1.0) -> sparse.csr_matrix:
        """Weighted adjacency for :mod:`scipy.sparse.csgraph`: latent edge lengths raised to
        ``power`` (2 makes one long jump cost more than several short steps)."""
        a, b = self.edges[:, 0], self.edges[:, 1]
        w = np.linalg.norm(self.points[b] - self.points[a], axis=1) ** float(power)
        w = np.maximum(w, 1e-12)  # csgraph reads an explicit 0 as "no edge"
        return sparse.csr_matrix((w, (a, b)), shape=(self.n_nodes, self.n_nodes))

    def to_networkx(self):
        """The graph as a ``networkx.DiGraph``: nodes ``0..n-1`` with ``take``, ``frame`` and
        ``pos`` attributes, edges with ``weight`` (latent length) and ``kind`` (``"take"``
        for a take's consecutive frames, else the method)."""
        import networkx as nx

        g = nx.DiGraph(method=self.method)
        g.add_nodes_from(
            (i, {"take": int(t), "frame": int(f), "pos": self.points[i]})
            for i, (t, f) in enumerate(zip(self.take, self.frame))
        )
        n_own = self.n_nodes - self.n_takes
        w = np.linalg.norm(self.points[self.edges[:, 1]] - self.points[self.edges[:, 0]], axis=1)
        kinds = np.where(np.arange(len(self.edges)) < n_own, "take", self.method)
        g.add_edges_from(
            (int(a), int(b), {"weight": float(x), "kind": str(k)})
            for (a, b), x, k in zip(self.edges, w, kinds)
        )
        return g

    def take_ends(self) -> tuple[np.ndarray, np.ndarray]:
        """Node index of each take's first and last frame."""
        first = np.flatnonzero(np.r_[True, self.take[1:] != self.take[:-1]])
        last = np.flatnonzero(np.r_[self.take[1:] != self.take[:-1], True])
        return first, last

    def connectivity(self) -> dict[str, Any]:
        """Components, the paper's start/end graph ``H`` and reachability between takes.

        Returns
        -------
        dict
            ``nodes``, ``edges``, ``weak_components``, ``strong_components``,
            ``coplanar_dropped``, ``H`` (``edges``: pairs ``[a, b]`` of names ``"start:i"``
            / ``"end:i"`` with a path from a to b in the graph; ``connected``: H is
            strongly connected, the paper's criterion for a strongly connected graph),
            ``cannot_reach`` (pairs ``[i, j]``: no path from any frame of take ``i`` to
            any frame of take ``j``) and ``cannot_enter_at_start`` (pairs ``[i, j]``: take
            ``i`` cannot reach take ``j``'s first frame).
        """
        adj = self.adjacency()
        n_weak = csgraph.connected_components(adj, directed=True, connection="weak")[0]
        n_strong = csgraph.connected_components(adj, directed=True, connection="strong")[0]
        first, last = self.take_ends()
        ends = np.concatenate([first, last])
        names = [f"start:{i}" for i in range(len(first))] + [f"end:{i}" for i in range(len(last))]
        dist = csgraph.dijkstra(adj, directed=True, indices=ends, unweighted=True)
        reach = np.isfinite(dist[:, ends])
        h_edges = [
            [names[a], names[b]]
            for a in range(len(ends))
            for b in range(len(ends))
            if a != b and reach[a, b]
        ]
        h = sparse.csr_matrix(reach.astype(float) - np.eye(len(ends)))
        h_strong = csgraph.connected_components(h, directed=True, connection="strong")[0]
        r = len(first)
        cannot = [[i, j] for i in range(r) for j in range(r) if i != j and not reach[i, r + j]]
        cannot_start = [
            [i, j] for i in range(r) for j in range(r) if i != j and not reach[r + i, j]
        ]
        return {
            "nodes": self.n_nodes,
            "edges": int(len(self.edges)),
            "weak_components": int(n_weak),
            "strong_components": int(n_strong),
            "coplanar_dropped": self.n_coplanar,
            "H": {"edges": h_edges, "connected": bool(h_strong == 1)},
            "cannot_reach": cannot,
            "cannot_enter_at_start": cannot_start,
            "takes": list(self.take_names),
        }


def build_graph(
    takes: Sequence[np.ndarray],
    method: str = "delaunay",
    k: int = 16,
    take_names: Sequence[str] | None = None,
) -> MotionGraph:
    """The motion graph of latent training takes.

    Parameters
    ----------
    takes : sequence of ndarray, each shape (T_i, d)
        Latent points of each training take, in frame order.
    method : {"delaunay", "knn", "union"}
    k : int, default 16
        Neighbours for ``"knn"`` and ``"union"`` (and the field's k-NN fallback).
    take_names : sequence of str, optional

    Returns
    -------
    MotionGraph
    """
    check_method(method)
    if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
        raise ParameterError(f"k must be a whole number >= 1, got {k!r}")
    pts = [np.asarray(t, dtype=float) for t in takes]
    if not pts or any(p.ndim != 2 or p.shape[0] < 2 for p in pts):
        raise ParameterError("every take needs at least 2 latent points in a (T, d) array")
    points = np.vstack(pts)
    n, d = points.shape
    take = np.concatenate([np.full(len(p), i) for i, p in enumerate(pts)])
    frame = np.concatenate([np.arange(len(p)) for p in pts])
    vel = training_vectors(points, take)
    tree = cKDTree(points)
    tri = None
    extra = []
    if method in ("delaunay", "union"):
        check_delaunay_dims(d, n)
        try:
            tri = Delaunay(points)
        except Exception as exc:  # Qhull errors: flat data and the like
            raise ParameterError(
                f"Qhull could not triangulate the {n} training frames in {d} dimensions: "
                f"{str(exc).splitlines()[0]}"
            ) from None
        extra.append(_delaunay_pairs(tri))
    if method in ("knn", "union"):
        extra.append(_knn_pairs(tree, points, k))
    und = _undirected_unique(np.concatenate(extra, axis=0), n)
    a, b = und[:, 0], und[:, 1]
    vt = (vel[a] + vel[b]) / 2.0
    dot = np.einsum("ij,ij->i", vt, points[b] - points[a])
    added = np.concatenate([und[dot > 0], und[dot < 0][:, ::-1]], axis=0)
    own_from = np.flatnonzero(take[1:] == take[:-1])
    own = np.stack([own_from, own_from + 1], axis=1)
    # an added edge equal to a take's own edge is not repeated
    keep = ~np.isin(added[:, 0] * n + added[:, 1], own[:, 0] * n + own[:, 1])
    edges = np.concatenate([own, added[keep]], axis=0).astype(int)
    names = list(take_names) if take_names is not None else [f"take {i}" for i in range(len(pts))]
    return MotionGraph(
        method=method,
        points=points,
        velocities=vel,
        take=take,
        frame=frame,
        edges=edges,
        k=int(k),
        tree=tree,
        delaunay=tri,
        take_names=names,
    )
