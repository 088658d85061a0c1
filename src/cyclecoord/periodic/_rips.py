"""ripser's persistent cohomology, called without ripser.py's Python layer.

``ripser.ripser`` imports scikit-learn (``sklearn.base``, ``sklearn.metrics.pairwise``)
only to compute a Euclidean distance matrix, which costs a fresh process 0.9-1.9 s of
imports before any work is done.  The compiled filtration (ripser.py's ``pyRipser``
extension, the same package) is called here directly, with the distances computed the
way scikit-learn computes them for float64 points (``|x|² + |y|² - 2 x·y``, clipped at
0, zero diagonal), so the results are those of ``ripser.ripser(..., maxdim=1,
do_cocycles=True)`` bit for bit (tested against it).  The dense path also skips
ripser.py's two (n, n) index grids: it needs the distances once in float64 and once,
halved, in float32.
"""

from __future__ import annotations

import numpy as np

__all__ = ["rips_cohomology", "sparse_rips_cohomology", "DENSE_BYTES_PER_PAIR"]

#: Peak bytes per ordered pair of points on the dense path: the float64 distance matrix,
#: the boolean upper-triangle mask and the float32 condensed copy (two copies: ours and
#: ripser's C++ one).
DENSE_BYTES_PER_PAIR = 8 + 1 + 2 + 2


def _euclidean_distances(x: np.ndarray) -> np.ndarray:
    """scikit-learn's ``euclidean_distances(x, x)`` for float64 ``x``, bit for bit."""
    xx = np.einsum("ij,ij->i", x, x)[:, None]
    d = -2 * (x @ x.T)
    d += xx
    d += xx.T
    np.maximum(d, 0.0, out=d)
    np.fill_diagonal(d, 0.0)
    return np.sqrt(d, out=d)


def _unpack(res: dict, coeff: int) -> dict:
    dgms = []
    for dim in res["births_and_deaths_by_dim"]:
        dgms.append(np.reshape(np.array(dim), [len(dim) // 2, 2]))
    cocycles = []
    for d, by_dim in enumerate(res["cocycles_by_dim"]):
        out = []
        for ccl in by_dim:
            c = np.reshape(np.array(ccl, dtype=np.int64), [len(ccl) // (d + 2), d + 2])
            c[:, -1] = np.mod(c[:, -1], coeff)
            out.append(c)
        cocycles.append(out)
    return {"dgms": dgms, "cocycles": cocycles, "num_edges": res["num_edges"]}


def rips_cohomology(
    x: np.ndarray, thresh: float, coeff: int, distance_matrix: bool = False
) -> dict:
    """H0 and H1 with cocycles of the Rips filtration up to ``thresh``.

    Parameters
    ----------
    x : ndarray, shape (n, K) or (n, n)
        Points (Euclidean metric) or, with ``distance_matrix``, a distance matrix.
    thresh : float
    coeff : int
        Prime of the coefficient field.

    Returns
    -------
    dict
        ``dgms`` (two (m, 2) arrays), ``cocycles`` (``[[], [ (k, 3) int arrays ]]``
        with values mod ``coeff``) and ``num_edges``, as ``ripser.ripser`` returns them.
    """
    try:
        from pyRipser import doRipsFiltrationDM
    except ImportError:  # a ripser build without the extension at top level: its own wrapper
        import ripser

        return ripser.ripser(x, maxdim=1, thresh=thresh, coeff=coeff, do_cocycles=True,
                             distance_matrix=distance_matrix)

    x = np.asarray(x, dtype=float)
    dm = x if distance_matrix else _euclidean_distances(x)
    n = dm.shape[0]
    if np.any(np.diagonal(dm) != 0):  # ripser.py sends such matrices down the sparse path
        from scipy.sparse import coo_matrix

        c = coo_matrix(dm)
        order = np.lexsort((c.col, c.row))
        return sparse_rips_cohomology(c.row[order], c.col[order], c.data[order], n, thresh, coeff)
    # ripser.py passes dm[j > i] in row-major order: the upper triangle, row by row
    condensed = np.array(dm[np.triu(np.ones((n, n), dtype=bool), k=1)], dtype=np.float32)
    if not distance_matrix:
        del dm
    res = doRipsFiltrationDM(condensed, 1, thresh, coeff, True)
    return _unpack(res, coeff)


def sparse_rips_cohomology(
    row: np.ndarray, col: np.ndarray, data: np.ndarray, n: int, thresh: float, coeff: int
) -> dict:
    """As :func:`rips_cohomology` from a sparse distance matrix's entries, which must be
    sorted by (row, col) (``scipy.sparse`` COO after ``tocsr().tocoo()`` is)."""
    try:
        from pyRipser import doRipsFiltrationDMSparse
    except ImportError:
        import ripser
        from scipy.sparse import coo_matrix

        mat = coo_matrix((data, (row, col)), shape=(int(n), int(n)))
        return ripser.ripser(
            mat, maxdim=1, thresh=thresh, coeff=coeff, do_cocycles=True, distance_matrix=True
        )

    res = doRipsFiltrationDMSparse(
        np.asarray(row).astype(np.int32, order="C"),
        np.asarray(col).astype(np.int32, order="C"),
        np.array(data, dtype=np.float32, order="C"),
        int(n), 1, thresh, coeff, True,
    )
    return _unpack(res, coeff)
