"""Vietoris-Rips filtration and persistent cohomology barcode (with cocycles) via ripser.

The barcode holds H0 and H1 bars and, for every H1 bar, a representative cocycle over
Z/p.  Bars are reported in the units of the analysed point cloud; deaths beyond the
threshold are ``inf``.  This module also decides which class to use and at which scale
(paper §4.2: high in the bar, below its death) and whether any class stands clear.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.distance import pdist, squareform

from ..errors import ParameterError

__all__ = [
    "Barcode",
    "BarSelection",
    "compute_barcode",
    "default_max_scale",
    "check_prime",
    "select_bar",
    "DEFAULT_PRIME",
    "temporal_distance_matrix",
    "refine_birth",
    "winding_birth",
    "REFINE_BYTES_PER_EDGE",
]

#: Coefficient field used by default: a prime well above 11 (the paper asks for p > 11).
DEFAULT_PRIME = 47

#: A bar is "clear" when death/birth (death capped at the threshold) reaches this ...
CLEAR_RATIO = 1.5
#: ... and its persistence is at least this many times the next-longest H1 bar's ...
CLEAR_GAP = 2.0
#: ... and at least this fraction of the threshold (bars between repeated frames are born
#: at 0, so their death/birth is infinite however short they are).
CLEAR_MIN_FRACTION = 0.05


def check_prime(p: int) -> int:
    """Validate the coefficient prime: an integer prime strictly greater than 11."""
    try:
        q = int(p)
    except (TypeError, ValueError):
        raise ParameterError(f"prime must be an integer, got {p!r}") from None
    if q != p:
        raise ParameterError(f"prime must be an integer, got {p!r}")
    if q <= 11:
        raise ParameterError(
            f"prime must be greater than 11 (circular coordinates need a field Z/p whose lift "
            f"to the integers is unambiguous), got {q}"
        )
    if any(q % d == 0 for d in range(2, int(q**0.5) + 1)):
        raise ParameterError(f"prime must be a prime number, {q} is not")
    return q


@dataclass(frozen=True)
class Barcode:
    """Persistence barcode of a Vietoris-Rips filtration, with H1 cocycles.

    Attributes
    ----------
    h0, h1 : ndarray, shape (n, 2)
        ``(birth, death)`` per bar in the analysed space's units; ``death`` is ``inf`` when
        the class is still alive at ``threshold``.  H1 bars are sorted by decreasing
        persistence (death capped at the threshold).
    cocycles : list of ndarray, each (m, 3) int
        Representative cocycle of each H1 bar: rows ``(i, j, value)`` with ``i < j``
        point indices and ``value`` in ``[0, prime)`` on the edge oriented ``i -> j``.
    threshold : float
        Largest filtration value built.
    prime : int
        The coefficient field Z/p.
    n_points : int
        Number of points in the filtration (landmarks, when subsampled).
    n_edges : int
        Edges ripser added.
    """

    h0: np.ndarray
    h1: np.ndarray
    cocycles: list
    threshold: float
    prime: int
    n_points: int
    n_edges: int = 0
    point_indices: np.ndarray | None = None
    extras: dict = field(default_factory=dict)

    def persistence(self, dim: int = 1) -> np.ndarray:
        """Bar lengths with deaths capped at the threshold."""
        bars = self.h1 if dim == 1 else self.h0
        if bars.size == 0:
            return np.zeros(0)
        return np.minimum(bars[:, 1], self.threshold) - bars[:, 0]

    def long_h0(self, min_length: float) -> int:
        """Number of H0 bars (the infinite one included) longer than ``min_length``."""
        return int(np.sum(self.persistence(0) > min_length))

    def to_dict(self) -> dict:
        """JSON-ready form: ``{"h0": [[b, d], ...], "h1": [...]}`` with ``None`` for inf."""

        def bars(a: np.ndarray) -> list:
            return [[float(b), None if not np.isfinite(d) else float(d)] for b, d in a]

        return {"h0": bars(self.h0), "h1": bars(self.h1)}


def temporal_distance_matrix(points: np.ndarray) -> np.ndarray:
    """Euclidean distances with consecutive frames set to distance 0 (paper §3.2).

    Adjacent frames are then always joined first, so the filtration follows the time
    series and only the loop's closing has to be found geometrically.
    """
    d = squareform(pdist(points))
    i = np.arange(len(points) - 1)
    d[i, i + 1] = 0.0
    d[i + 1, i] = 0.0
    return d


def _diameter(points: np.ndarray, exact_limit: int = 2000, sweeps: int = 4) -> float:
    """Diameter of a point cloud: exact up to ``exact_limit`` points, otherwise by
    repeated farthest-point sweeps (a lower bound within a factor 2, in practice within
    a few per cent), in linear time and memory."""
    n = len(points)
    if n < 2:
        return 0.0
    if n <= exact_limit:
        return float(pdist(points).max())
    best, i = 0.0, 0
    for _ in range(sweeps):
        d = _distances_to(points, i)
        j = int(np.argmax(d))
        if d[j] <= best:
            break
        best, i = float(d[j]), j
    return best


def _distances_to(points: np.ndarray, i: int, block: int = 1_000_000) -> np.ndarray:
    """``np.linalg.norm(points - points[i], axis=1)`` in blocks of rows (the same values,
    each row is computed alone; no (T, K) temporary)."""
    out = np.empty(len(points))
    step = max(1, block // max(points.shape[1], 1))
    for a in range(0, len(points), step):
        out[a : a + step] = np.linalg.norm(points[a : a + step] - points[i], axis=1)
    return out


def default_max_scale(points: np.ndarray, distances: np.ndarray | None = None) -> float:
    """Automatic filtration threshold.

    Half the diameter of the point cloud (exact up to 2,000 points, by farthest-point
    sweeps beyond), and never less than twice the 99.5th percentile of the steps between
    consecutive frames, so the trajectory is connected in the complex.

    For a loop of radius ``r`` sampled densely, the dominant H1 class is born near the
    sampling gap and dies near ``r * sqrt(3)``; a threshold of about ``r`` keeps the class
    alive (its bar is reported as infinite) while building only the edges that matter.
    """
    if distances is not None:
        diam = float(np.max(distances))
        steps = np.diagonal(
            distances, offset=1
        )  # zero for the temporal metric: connected by design
    else:
        from ..quality.metrics import frame_steps

        diam = _diameter(points)
        steps = frame_steps(points)  # |points[t + 1] - points[t]|, in blocks
    # a high percentile, not the maximum: an Euler flip in one joint (a 360-degree jump)
    # must not inflate the threshold
    step = float(np.percentile(steps, 99.5)) if steps.size else 0.0
    return max(0.5 * diam, 2.0 * step, 1e-9)


def compute_barcode(
    points: np.ndarray,
    max_scale: float | None = None,
    prime: int = DEFAULT_PRIME,
    distance_matrix: bool = False,
    n_landmarks: int | None = None,
) -> Barcode:
    """Vietoris-Rips persistent cohomology in dimensions 0 and 1 with cocycles.

    Parameters
    ----------
    points : ndarray, shape (T, K) or (T, T)
        Point cloud, or a distance matrix when ``distance_matrix`` is True.
    max_scale : float, optional
        Filtration threshold; :func:`default_max_scale` when omitted.
    prime : int, default 47
        Coefficient field Z/p; must be a prime greater than 11.
    n_landmarks : int, optional
        Greedy max-min subsample size (:func:`cyclecoord.periodic.landmarks.greedy_landmarks`,
        the choice ripser's ``n_perm`` makes); ``None`` uses every point.

    Returns
    -------
    Barcode
    """
    from ._rips import rips_cohomology  # ripser's filtration without scikit-learn's imports

    p = check_prime(prime)
    x = np.asarray(points, dtype=float)
    if x.ndim != 2 or x.shape[0] < 3:
        raise ParameterError(f"need at least 3 points in a (T, K) array, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ParameterError("points contain NaN or infinite values")
    if max_scale is None:
        max_scale = default_max_scale(x, x if distance_matrix else None)
    max_scale = float(max_scale)
    if not np.isfinite(max_scale) or max_scale <= 0:
        raise ParameterError(f"max scale must be a positive number, got {max_scale}")
    idx = cover = None
    if n_landmarks is not None and n_landmarks < x.shape[0]:
        from .landmarks import greedy_landmarks

        # ripser's n_perm makes the same greedy choice, two to four times slower at 64k frames
        idx, cover = greedy_landmarks(x, int(n_landmarks), distance_matrix=distance_matrix)
        x = x[np.ix_(idx, idx)] if distance_matrix else x[idx]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = rips_cohomology(x, max_scale, p, distance_matrix=distance_matrix)
    h0 = np.asarray(res["dgms"][0], dtype=float).reshape(-1, 2)
    h1 = np.asarray(res["dgms"][1], dtype=float).reshape(-1, 2)
    cocycles = [np.asarray(c, dtype=np.int64).reshape(-1, 3) for c in res["cocycles"][1]]
    if idx is not None:  # name the original points, as ripser's n_perm does
        for c in cocycles:
            c[:, :2] = idx[c[:, :2]]
    # orient every cocycle entry i < j, value mod p
    oriented = []
    for c in cocycles:
        c = c.copy()
        swap = c[:, 0] > c[:, 1]
        c[swap, 0], c[swap, 1] = c[swap, 1], c[swap, 0].copy()
        c[swap, 2] = -c[swap, 2]
        c[:, 2] %= p
        oriented.append(c)
    pers = np.minimum(h1[:, 1], max_scale) - h1[:, 0] if h1.size else np.zeros(0)
    order = np.argsort(-pers, kind="stable")
    h1 = h1[order]
    oriented = [oriented[k] for k in order]
    extras = {} if cover is None else {"covering_radius": cover}
    return Barcode(
        h0=h0,
        h1=h1,
        cocycles=oriented,
        threshold=max_scale,
        prime=p,
        n_points=int(x.shape[0]),
        n_edges=int(res.get("num_edges", 0)),
        point_indices=idx,
        extras=extras,
    )


@dataclass(frozen=True)
class BarSelection:
    """The H1 class chosen for a circular coordinate and the scale it is read at.

    Attributes
    ----------
    index : int
        Position in :attr:`Barcode.h1` (0 = most persistent).
    birth, death : float
        The bar (``death`` is ``inf`` when alive at the threshold).
    scale : float
        Filtration value at which the cocycle is used, ``birth < scale < death``.
    clear : bool
        Whether the bar stands clear of the rest (see :func:`select_bar`).
    ratio : float
        ``min(death, threshold) / birth``.
    gap : float
        Its persistence over the next-longest bar's persistence (``inf`` if alone).
    full_birth : float or None
        With landmarks, the class's birth in the filtration on every point when it could
        be computed (see :func:`refine_birth`); landmark filtrations are born later.
    """

    index: int
    birth: float
    death: float
    scale: float
    clear: bool
    ratio: float
    gap: float
    full_birth: float | None = None

    def to_dict(self) -> dict:
        return {
            "index": self.index,
            "birth": self.birth,
            "full_birth": self.full_birth,
            "death": None if not np.isfinite(self.death) else self.death,
            "scale": self.scale,
            "clear": self.clear,
            "ratio": self.ratio,
            "gap": None if not np.isfinite(self.gap) else self.gap,
        }


def select_bar(
    barcode: Barcode,
    class_index: int = 0,
    scale: float | None = None,
    scale_fraction: float = 0.9,
) -> BarSelection:
    """Choose an H1 class and the scale at which to read its cocycle.

    Parameters
    ----------
    class_index : int, default 0
        Which bar, by decreasing persistence (death capped at the threshold).
    scale : float, optional
        Explicit scale; must lie inside the bar (``birth <= scale < death``) and not above
        the threshold.
    scale_fraction : float, default 0.9
        Otherwise ``scale = birth + scale_fraction * (min(death, threshold) - birth)``: high
        in the bar as the paper recommends, strictly below the death where the cocycle is
        still valid.  Lower scales read a thinner complex whose coordinate can wind once
        around several repetitions that drift apart (CMU 143_01 at 0.3 of its bar counts
        1.6 strides where the hips show 2.1).

    Notes
    -----
    The bar is *clear* when both hold:

    * ``min(death, threshold) / birth >= 1.5`` — the class lives well beyond the scale
      at which it appears (bars of sampling noise in Rips filtrations stay closer to 1);
    * its persistence is at least twice that of the next-longest H1 bar (for
      ``class_index > 0``, of the next-longest bar after it);
    * its persistence is at least 5% of the threshold (repeated frames make bars born at
      0 whose ratio is infinite however short they are).
    """
    n = len(barcode.h1)
    if n == 0:
        raise ParameterError("the barcode has no H1 bar at this threshold")
    if not 0 <= class_index < n:
        raise ParameterError(f"class index {class_index} out of range: the barcode has {n} H1 bars")
    birth, death = (float(v) for v in barcode.h1[class_index])
    top = min(death, barcode.threshold)
    pers = barcode.persistence(1)
    nxt = pers[class_index + 1] if class_index + 1 < n else 0.0
    gap = float(pers[class_index] / nxt) if nxt > 0 else float("inf")
    ratio = float(top / birth) if birth > 0 else float("inf")
    if scale is None:
        if not 0.0 < scale_fraction < 1.0:
            raise ParameterError(f"scale fraction must be in (0, 1), got {scale_fraction}")
        s = birth + scale_fraction * (top - birth)
    else:
        s = float(scale)
        if not (birth <= s < death) or s > barcode.threshold:
            raise ParameterError(
                f"scale {s:g} is outside H1 bar {class_index} [{birth:g}, {death:g}) "
                f"(threshold {barcode.threshold:g}); the cocycle is only valid inside its bar"
            )
    return BarSelection(
        index=int(class_index),
        birth=birth,
        death=death,
        scale=float(s),
        clear=bool(
            ratio >= CLEAR_RATIO
            and gap >= CLEAR_GAP
            and pers[class_index] >= CLEAR_MIN_FRACTION * barcode.threshold
        ),
        ratio=ratio,
        gap=gap,
    )


#: Peak bytes per edge of :func:`refine_birth`'s sparse complex (the pairs, their
#: distances, the symmetric COO/CSR copies, ripser's own copy).
REFINE_BYTES_PER_EDGE = 256


def refine_birth(
    points: np.ndarray,
    landmark_birth: float,
    prime: int = DEFAULT_PRIME,
    max_edges: int = 3_000_000,
    margin: float = 1.05,
    covering_radius: float | None = None,
    coordinate: np.ndarray | None = None,
) -> float | None:
    """Birth of a landmark class in the Rips filtration on *every* point.

    With ``coordinate`` (the class's circular coordinate on every point, in turns) the
    class is followed exactly: its birth is the first scale at which the edges of all
    points close a loop around which the coordinate winds (:func:`winding_birth`).
    Without it, the bars of the sparse full complex are read as below.

    A Rips filtration on landmarks is born later than on all points (its loop closes
    only when the gaps between landmarks are spanned).  Building the full filtration
    only up to ``margin * landmark_birth`` is cheap — a sparse complex far below the
    threshold — and the class is there the H1 bar alive at that scale that was born
    first (bars of noise alive at that scale were born just below it).

    With ``covering_radius`` (the landmarks' covering radius ``r``) only bars born within
    ``2 r`` below the landmark birth can be the class (moving every point to its landmark
    changes a distance by at most ``2 r``); an older loop alive at that scale (a small
    loop elsewhere in the data) is not taken for it.

    Returns ``None`` when the sparse complex would exceed ``max_edges`` edges or no bar
    is alive there.
    """
    from ._rips import sparse_rips_cohomology

    x = np.asarray(points, dtype=float)
    t = float(landmark_birth) * margin
    from scipy.spatial import cKDTree

    # Random pairs first: counting every pair within t costs as much as the pairs
    # themselves (quadratic for a dense complex; 25 s at 64k frames), so a complex that
    # is too big is refused from a sample before anything is counted.  20,000 pairs put
    # the edge count within a few per cent (4 % at 16k frames and 4.6 million edges),
    # so 1.25 x the budget is a wide margin.
    from .landmarks import estimate_complex

    n_pairs = len(x) * (len(x) - 1) / 2
    if (
        n_pairs > 1.25 * max_edges
        and estimate_complex(x, t, n_samples=20_000).edges > 1.25 * max_edges
    ):
        return None  # (with fewer pairs than that the sample could never refuse)
    tree = cKDTree(x)
    # then count exactly (ordered pairs and self-pairs): query_pairs materialises every pair
    if (tree.count_neighbors(tree, t) - len(x)) / 2 > max_edges:
        return None
    pairs = tree.query_pairs(t, output_type="ndarray")
    if len(pairs) == 0:
        return None
    d = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    if coordinate is not None:
        return winding_birth(pairs, d, coordinate)
    d = np.maximum(d, 1e-12)  # a stored zero would read as a missing edge
    from scipy.sparse import coo_matrix

    n = len(x)
    mat = coo_matrix(
        (np.r_[d, d], (np.r_[pairs[:, 0], pairs[:, 1]], np.r_[pairs[:, 1], pairs[:, 0]])),
        shape=(n, n),
    )
    mat = mat.tocsr().tocoo()  # sorted by (row, col), as ripser.py hands it over
    res = sparse_rips_cohomology(mat.row, mat.col, mat.data, n, t, check_prime(prime))
    h1 = np.asarray(res["dgms"][1]).reshape(-1, 2)
    alive = h1[~np.isfinite(h1[:, 1])] if h1.size else h1
    if covering_radius is not None and alive.size:
        alive = alive[alive[:, 0] >= float(landmark_birth) - 2.0 * float(covering_radius) * 1.001]
    if alive.size == 0:
        return None
    return float(alive[:, 0].min())


def winding_birth(pairs: np.ndarray, lengths: np.ndarray, coordinate: np.ndarray) -> float | None:
    """The first edge length at which a graph's edges close a loop the coordinate winds around.

    A circular coordinate ``theta`` (turns) gives each edge ``(i, j)`` the short way round
    ``wrap(theta_j - theta_i)`` in ``[-0.5, 0.5]``.  Adding edges by length, an edge whose
    ends are already connected closes a loop; its winding number is the sum of the wraps
    around it.  A loop that winds cannot be filled by triangles of short edges (each such
    triangle's wraps sum to zero), so the first edge closing one is where the class is
    born in the Rips filtration: found without building the complex, and without
    mistaking a small loop of noise (winding zero) for the class.  The lifts are taken
    along the minimum spanning forest of the edges, whose path between an edge's ends has
    no longer edge than it.

    Parameters
    ----------
    pairs : ndarray of int, shape (E, 2)
    lengths : ndarray, shape (E,)
    coordinate : ndarray, shape (N,)
        Circular coordinate of every point, in turns.

    Returns
    -------
    float or None
        The birth scale, or None when no loop with winding closes among the edges.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import (
        breadth_first_order,
        connected_components,
        minimum_spanning_tree,
    )

    theta = np.asarray(coordinate, dtype=float)
    n = theta.size
    a, b = np.asarray(pairs[:, 0]), np.asarray(pairs[:, 1])
    lengths = np.asarray(lengths, dtype=float)
    if a.size == 0:
        return None
    # Kruskal's order is the filtration's: a loop first closes at an edge e outside the
    # minimum spanning forest, and the forest's path between e's ends has no longer edge,
    # so the loop's winding is read from lifts along the forest (one pass, no union-find)
    graph = coo_matrix((np.maximum(lengths, 1e-12), (a, b)), shape=(n, n)).tocsr()
    forest = minimum_spanning_tree(graph)
    forest = forest + forest.T
    lift = np.full(n, np.nan)
    _, labels = connected_components(forest, directed=False)
    _, roots = np.unique(labels, return_index=True)
    th = theta.tolist()
    for root in roots:
        order, pred = breadth_first_order(
            forest, int(root), directed=False, return_predecessors=True
        )
        lift[root] = theta[root]
        lf = lift  # local alias; parents come before children in breadth-first order
        for v, u in zip(order[1:].tolist(), pred[order[1:]].tolist()):
            w = th[v] - th[u]
            lf[v] = lf[u] + (w - round(w))
    wrap = theta[b] - theta[a]
    wrap -= np.round(wrap)
    winds = np.abs(lift[b] - lift[a] - wrap) > 0.5
    return float(lengths[winds].min()) if winds.any() else None
