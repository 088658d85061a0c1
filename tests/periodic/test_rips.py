"""Our direct call of ripser's filtration gives ripser.ripser's results bit for bit."""

import numpy as np
import pytest

import ripser

from cyclecoord.periodic._rips import rips_cohomology, sparse_rips_cohomology
from cyclecoord.periodic.barcode import temporal_distance_matrix


def _same(ours, theirs):
    for a, b in zip(ours["dgms"], theirs["dgms"]):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    assert len(ours["cocycles"][1]) == len(theirs["cocycles"][1])
    for a, b in zip(ours["cocycles"][1], theirs["cocycles"][1]):
        assert np.array_equal(a, b)
    assert ours["num_edges"] == theirs["num_edges"]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_points_and_distance_matrices_match_ripser(seed):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.random(120)) * 4 * np.pi
    x = np.column_stack([np.cos(t), np.sin(t), 0.3 * np.cos(3 * t)]) * 10 + rng.normal(0, 0.4, (120, 3))
    x = np.concatenate([x, rng.normal(0, 3, (20, 3))])
    for thresh in (4.0, 9.0, np.inf):
        want = ripser.ripser(x, maxdim=1, thresh=thresh, coeff=47, do_cocycles=True)
        _same(rips_cohomology(x, thresh, 47), want)
    d = temporal_distance_matrix(x)
    want = ripser.ripser(d, maxdim=1, thresh=9.0, coeff=53, do_cocycles=True, distance_matrix=True)
    _same(rips_cohomology(d, 9.0, 53, distance_matrix=True), want)
    d2 = d.copy()
    d2[3, 3] = 0.5  # a non-zero diagonal goes down ripser's sparse path
    want = ripser.ripser(d2, maxdim=1, thresh=9.0, coeff=47, do_cocycles=True, distance_matrix=True)
    _same(rips_cohomology(d2, 9.0, 47, distance_matrix=True), want)


def test_sparse_matches_ripser():
    from scipy.sparse import coo_matrix
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(5)
    t = rng.random(300) * 2 * np.pi
    x = np.column_stack([np.cos(t), np.sin(t)]) * 5 + rng.normal(0, 0.2, (300, 2))
    pairs = cKDTree(x).query_pairs(1.5, output_type="ndarray")
    d = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    i, j = np.r_[pairs[:, 0], pairs[:, 1]], np.r_[pairs[:, 1], pairs[:, 0]]
    mat = coo_matrix((np.r_[d, d], (i, j)), shape=(300, 300)).tocsr()
    want = ripser.ripser(mat, maxdim=1, thresh=1.5, coeff=47, do_cocycles=True, distance_matrix=True)
    c = mat.tocoo()
    _same(sparse_rips_cohomology(c.row, c.col, c.data, 300, 1.5, 47), want)


def test_long_h0_counts_h0_bars_not_h1_bars():
    from cyclecoord.periodic.barcode import Barcode

    bc = Barcode(
        h0=np.array([[0.0, 0.1], [0.0, 1.0], [0.0, np.inf]]),
        h1=np.array([[0.2, 0.3]]),
        cocycles=[np.zeros((0, 3), int)],
        threshold=2.0,
        prime=47,
        n_points=3,
    )
    # H0 lengths 0.1, 1 and 2 (the infinite bar capped at the threshold); the H1 bar is 0.1
    assert bc.long_h0(0.5) == 2
    assert bc.long_h0(0.05) == 3
    assert bc.long_h0(1.5) == 1


@pytest.mark.parametrize("scale", [0.0, -1.0, np.inf, np.nan])
def test_compute_barcode_refuses_a_max_scale_that_is_not_positive(scale):
    from cyclecoord.errors import ParameterError
    from cyclecoord.periodic.barcode import compute_barcode

    x = np.random.default_rng(0).normal(size=(10, 2))
    with pytest.raises(ParameterError, match="max scale must be a positive number"):
        compute_barcode(x, max_scale=scale)
