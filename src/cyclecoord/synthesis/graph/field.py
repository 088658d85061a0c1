"""The vector field over the latent space (Gauch & Peters §III-C to III-E).

Each training frame carries its training vector (:func:`~.build.training_vectors`).  At a
point ``x`` the field is the inverse-square-distance weighted mean of the vectors of its
neighbourhood:

* ``"delaunay"``: the vertices of the simplex containing ``x`` (plus any frame Qhull
  dropped as coplanar inside that simplex).  Outside the convex hull of the training
  points the Delaunay field is undefined and falls back to the k nearest frames; the
  returned ``inside`` flag lets callers count those evaluations;
* ``"knn"``: the ``k`` nearest training frames;
* ``"union"``: both sets together (k-Delaunay).

Weights are ``1 / D**2`` normalised to sum to 1; a point on a training frame takes that
frame's vector.
"""

from __future__ import annotations

import numpy as np

from ...errors import ParameterError
from .build import MotionGraph, check_method

__all__ = ["VectorField"]


def _idw(points: np.ndarray, x: np.ndarray, idx: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Inverse-square-distance weights ``(m, K)`` of neighbours ``idx`` of points ``x``.

    ``valid`` masks the real entries of ``idx`` (padding is ignored); a point on a
    neighbour gives that neighbour all the weight.
    """
    d2 = ((points[idx] - x[:, None, :]) ** 2).sum(axis=2)
    zero = (d2 <= 1e-24) & valid
    with np.errstate(divide="ignore"):
        w = np.where(valid, 1.0 / np.where(valid, d2, 1.0), 0.0)
    hit = zero.any(axis=1)
    if hit.any():
        w[hit] = zero[hit].astype(float)
    return w / w.sum(axis=1, keepdims=True)


class VectorField:
    """The graph's interpolated vector field.

    Parameters
    ----------
    graph : MotionGraph
    neighbourhood : {"delaunay", "knn", "union"}, optional
        Defaults to the graph's method.
    k : int, optional
        Neighbours for k-NN (and the fallback); defaults to the graph's ``k``.
    """

    def __init__(
        self, graph: MotionGraph, neighbourhood: str | None = None, k: int | None = None
    ) -> None:
        self.graph = graph
        self.neighbourhood = check_method(neighbourhood or graph.method)
        self.k = int(min(graph.k if k is None else k, graph.n_nodes))
        if self.k < 1:
            raise ParameterError(f"k must be >= 1, got {k}")
        if self.neighbourhood != "knn" and graph.delaunay is None:
            raise ParameterError(
                f"a {self.neighbourhood!r} field needs a graph built with a Delaunay triangulation"
            )
        self._extra: dict[int, np.ndarray] = {}
        if graph.delaunay is not None and graph.delaunay.coplanar.size:
            cop = graph.delaunay.coplanar
            for s in np.unique(cop[:, 1]):
                self._extra[int(s)] = cop[cop[:, 1] == s, 0]

    @property
    def dims(self) -> int:
        return int(self.graph.points.shape[1])

    def neighbours(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Neighbour indices, weights and inside-hull flags of points ``x`` ``(m, d)``.

        Returns
        -------
        idx : ndarray of int, shape (m, K)
            Training frames; unused slots (weight 0) hold 0.
        weights : ndarray, shape (m, K)
            Sum to 1 per row.
        inside : ndarray of bool, shape (m,)
            False where a Delaunay (or union) neighbourhood fell back to k-NN; always True
            for k-NN.
        """
        x = np.atleast_2d(np.asarray(x, dtype=float))
        if x.shape[1] != self.dims:
            raise ParameterError(f"points have {x.shape[1]} coordinates; the field has {self.dims}")
        g = self.graph
        m = x.shape[0]
        inside = np.ones(m, dtype=bool)
        if self.neighbourhood == "knn":
            idx = self._knn(x)
            valid = np.ones(idx.shape, dtype=bool)
        else:
            tri = g.delaunay
            s = tri.find_simplex(x)
            inside = s >= 0
            if self.neighbourhood == "delaunay":  # k-NN only where the point is outside
                knn = np.zeros((m, self.k), dtype=int)
                if not inside.all():
                    knn[~inside] = self._knn(x[~inside])
            else:
                knn = self._knn(x)
            verts = tri.simplices[np.maximum(s, 0)]
            n_extra = 0
            if self._extra:
                n_extra = max((len(self._extra.get(int(j), ())) for j in s[inside]), default=0)
            if n_extra:
                pad = np.full((m, n_extra), -1)
                for r in np.flatnonzero(inside):
                    e = self._extra.get(int(s[r]))
                    if e is not None:
                        pad[r, : len(e)] = e
                verts = np.concatenate([verts, pad], axis=1)
            vvalid = (verts >= 0) & inside[:, None]
            if self.neighbourhood == "delaunay":
                kvalid = np.broadcast_to(~inside[:, None], knn.shape)
            else:  # union: k-NN plus the simplex, each frame once
                dup = (knn[:, :, None] == np.where(vvalid, verts, -2)[:, None, :]).any(axis=2)
                kvalid = ~dup
            idx = np.concatenate([np.maximum(verts, 0), knn], axis=1)
            valid = np.concatenate([vvalid, kvalid], axis=1)
        w = _idw(g.points, x, idx, valid)
        return idx, w, inside

    def _knn(self, x: np.ndarray) -> np.ndarray:
        _, idx = self.graph.tree.query(x, k=self.k)
        return np.asarray(idx, dtype=int).reshape(x.shape[0], self.k)

    def evaluate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Field vectors ``(m, d)`` at points ``x`` and the inside-hull flags ``(m,)``."""
        idx, w, inside = self.neighbours(x)
        v = np.einsum("mk,mkd->md", w, self.graph.velocities[idx])
        return v, inside

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """The field at one point ``(d,)`` or many ``(m, d)``."""
        x = np.asarray(x, dtype=float)
        v, _ = self.evaluate(x)
        return v[0] if x.ndim == 1 else v
