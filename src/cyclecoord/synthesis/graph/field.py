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

Two options of ours (off by default, the paper's field) for the Delaunay neighbourhoods,
written as suffixes of the method (:func:`parse_variant`: ``"delaunay+ring+agree"``):

* ``ring``: the containing simplex's vertices plus the vertex across each of its facets
  (the ``d + 1`` simplices adjacent to it): ``2 d + 2`` frames instead of ``d + 1``,
  still taken from the complex, so the neighbourhood still follows the local frame
  spacing, as k-NN does not;
* ``agree``: inside the hull, a neighbour's weight is multiplied by
  ``max(0, cos(v_i, h))``, the agreement of its training vector with the path's heading
  ``h`` (its previous step; :func:`~.paths.follow_field` passes it).  Frames moving
  against the path are dropped: in a 2-D projection a walk's trajectory folds over
  itself at the loop's two cusps, where frames that go out and frames that come back
  lie in one simplex with velocities that cancel (on set w1 the stalled paths sat in
  simplices half a frame step wide whose vertices' velocities had cosines of -0.8 to
  -1.0).  When no neighbour agrees, and outside the hull, the weights are the plain
  ones: the heading cannot carry a path away from the data.
"""

from __future__ import annotations

import numpy as np

from ..._blas import one_blas_thread
from ...errors import ParameterError
from .build import METHODS, MotionGraph, check_method

__all__ = ["VectorField", "FIELD_OPTIONS", "parse_variant", "variant_name"]

#: Field options of ours, written after the method: ``"delaunay+ring+agree"``.
FIELD_OPTIONS = ("ring", "agree")


def parse_variant(text: str) -> tuple[str, bool, bool]:
    """``"METHOD[+ring][+agree]"`` -> ``(method, ring, agree)``.

    Raises
    ------
    ParameterError
        An unknown method or option, or an option its method cannot take (both need the
        Delaunay triangulation: ``knn`` has no simplices and no hull).
    """
    parts = [p.strip() for p in str(text).split("+")]
    method = check_method(parts[0])
    opts = parts[1:]
    bad = [o for o in opts if o not in FIELD_OPTIONS]
    if bad or len(set(opts)) != len(opts):
        raise ParameterError(
            f"{text!r}: a method is one of {', '.join(METHODS)}, optionally followed by "
            f"+ring and/or +agree (once each), e.g. 'delaunay+ring+agree'"
        )
    if opts and method == "knn":
        raise ParameterError(
            f"{text!r}: +ring and +agree need the Delaunay triangulation (its simplices and "
            "hull); use them with delaunay or union"
        )
    return method, "ring" in opts, "agree" in opts


def variant_name(method: str, ring: bool = False, agree: bool = False) -> str:
    """The inverse of :func:`parse_variant`."""
    return method + ("+ring" if ring else "") + ("+agree" if agree else "")


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


@one_blas_thread
def _barycentric(tri) -> None:
    """Compute Qhull's per-simplex barycentric transforms (``find_simplex`` needs them).

    SciPy solves one small LAPACK system per simplex; a multi-threaded BLAS wakes its
    threads for each, which on 2 busy cores made the first point location 6-100x slower
    than on one thread (1,712 random points: 0.38 s against 0.014 s in 3 dims, 1.7 s
    against 0.066 s in 4; medians of 5).
    """
    tri.transform  # noqa: B018 (a lazily computed property)


def _ring(tri) -> np.ndarray:
    """Per simplex ``(S, 2 d + 2)``: its vertices, then the vertex across each facet (-1 on
    the hull, or when two facets' opposite vertices are one frame)."""
    s, nb = tri.simplices, tri.neighbors
    rows = np.arange(s.shape[0])
    across = np.full(nb.shape, -1)
    for i in range(nb.shape[1]):
        n = nb[:, i]
        ok = n >= 0
        # the neighbour's vertex opposite the shared facet: where its neighbour is this one
        pos = np.argmax(nb[n[ok]] == rows[ok, None], axis=1)
        across[ok, i] = s[n[ok], pos]
    for i in range(1, across.shape[1]):
        dup = (across[:, i : i + 1] == across[:, :i]).any(axis=1) & (across[:, i] >= 0)
        across[dup, i] = -1
    return np.concatenate([s, across], axis=1)


class VectorField:
    """The graph's interpolated vector field.

    Parameters
    ----------
    graph : MotionGraph
    neighbourhood : {"delaunay", "knn", "union"}, optional
        Defaults to the graph's method.
    k : int, optional
        Neighbours for k-NN (and the fallback); defaults to the graph's ``k``.
    ring : bool, default False
        Delaunay neighbourhoods widened to the simplices adjacent to the containing one.
    agree : bool, default False
        Inside the hull, weights times the agreement of each neighbour's training vector
        with the path's heading (see the module notes); needs ``heading`` in
        :meth:`neighbours`.
    """

    def __init__(
        self,
        graph: MotionGraph,
        neighbourhood: str | None = None,
        k: int | None = None,
        ring: bool = False,
        agree: bool = False,
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
        self.ring, self.agree = bool(ring), bool(agree)
        if (self.ring or self.agree) and self.neighbourhood == "knn":
            raise ParameterError(
                "ring and agree need the Delaunay triangulation; use a delaunay or union field"
            )
        self._extra: dict[int, np.ndarray] = {}
        if graph.delaunay is not None and graph.delaunay.coplanar.size:
            cop = graph.delaunay.coplanar
            for s in np.unique(cop[:, 1]):
                self._extra[int(s)] = cop[cop[:, 1] == s, 0]
        self._cells = None
        if graph.delaunay is not None:
            _barycentric(graph.delaunay)
            self._cells = _ring(graph.delaunay) if self.ring else graph.delaunay.simplices

    @property
    def dims(self) -> int:
        return int(self.graph.points.shape[1])

    @property
    def name(self) -> str:
        """The variant, e.g. ``"delaunay+ring+agree"`` (:func:`parse_variant`)."""
        return variant_name(self.neighbourhood, self.ring, self.agree)

    def neighbours(
        self, x: np.ndarray, heading: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Neighbour indices, weights and inside-hull flags of points ``x`` ``(m, d)``.

        Parameters
        ----------
        x : ndarray, shape (m, d) or (d,)
        heading : ndarray, shape (m, d) or (d,), optional
            The path's direction at each point, used by an ``agree`` field (ignored
            otherwise; a zero heading leaves the plain weights).

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
            s = g.delaunay.find_simplex(x)
            inside = s >= 0
            if self.neighbourhood == "delaunay":  # k-NN only where the point is outside
                knn = np.zeros((m, self.k), dtype=int)
                if not inside.all():
                    knn[~inside] = self._knn(x[~inside])
            else:
                knn = self._knn(x)
            verts = self._cells[np.maximum(s, 0)]
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
        if self.agree and heading is not None:
            w = self._agreeing(w, idx, inside, np.atleast_2d(np.asarray(heading, dtype=float)))
        return idx, w, inside

    def _agreeing(
        self, w: np.ndarray, idx: np.ndarray, inside: np.ndarray, h: np.ndarray
    ) -> np.ndarray:
        """Weights times ``max(0, cos(v_i, h))`` where inside and some neighbour agrees."""
        v = self.graph.velocities[idx]
        nv = np.linalg.norm(v, axis=2) * np.linalg.norm(h, axis=1)[:, None]
        cos = np.einsum("mkd,md->mk", v, h) / np.where(nv > 0, nv, 1.0)
        wa = w * np.maximum(cos, 0.0)
        total = wa.sum(axis=1, keepdims=True)
        use = inside & (total[:, 0] > 0)
        out = w.copy()
        out[use] = wa[use] / total[use]
        return out

    def _knn(self, x: np.ndarray) -> np.ndarray:
        _, idx = self.graph.tree.query(x, k=self.k)
        return np.asarray(idx, dtype=int).reshape(x.shape[0], self.k)

    def evaluate(
        self, x: np.ndarray, heading: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Field vectors ``(m, d)`` at points ``x`` and the inside-hull flags ``(m,)``."""
        idx, w, inside = self.neighbours(x, heading)
        v = np.einsum("mk,mkd->md", w, self.graph.velocities[idx])
        return v, inside

    def __call__(self, x: np.ndarray, heading: np.ndarray | None = None) -> np.ndarray:
        """The field at one point ``(d,)`` or many ``(m, d)``."""
        x = np.asarray(x, dtype=float)
        v, _ = self.evaluate(x, heading)
        return v[0] if x.ndim == 1 else v
