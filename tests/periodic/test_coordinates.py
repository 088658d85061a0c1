"""Barcode, cocycle lift and check, and circular coordinates on point clouds with known answers."""

import numpy as np
import pytest

from cyclecoord.periodic.barcode import check_prime, compute_barcode, select_bar, temporal_distance_matrix
from cyclecoord.periodic.coordinates import (
    CircularCoordinates,
    check_cocycle,
    harmonic_coordinate,
    lift_cocycle,
    orient_with_time,
    rips_edges,
    unwrap,
)
from cyclecoord.errors import ParameterError
from cyclecoord.periodic._cochain import cocycle_on_edges


def circular_error(a, b):
    """Largest circular distance between two coordinates after the best rotation."""
    d = np.mod(a - b, 1.0)
    shift = np.angle(np.mean(np.exp(2j * np.pi * d))) / (2 * np.pi)
    r = np.mod(d - shift + 0.5, 1.0) - 0.5
    return float(np.max(np.abs(r)))


def noisy_circle(n=300, turns=3.0, noise=0.03, dim=5, seed=0, uneven=0.0):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, turns, n, endpoint=False)
    phase = t + uneven / (2 * np.pi) * np.sin(2 * np.pi * t)
    ang = 2 * np.pi * phase
    x = np.zeros((n, dim))
    x[:, 0], x[:, 1] = np.cos(ang), np.sin(ang)
    x += noise * rng.standard_normal(x.shape)
    return x, np.mod(phase, 1.0)


@pytest.mark.parametrize("p", [2, 3, 11, 12, 49, 1.5, "x", -13])
def test_bad_primes_are_refused(p):
    with pytest.raises(ParameterError):
        check_prime(p)


@pytest.mark.parametrize("p", [13, 47, 97])
def test_good_primes(p):
    assert check_prime(p) == p


def test_retry_primes_are_the_primes_from_47_to_97():
    """The primes a failed lift is retried with: each a valid coefficient prime, in order."""
    from cyclecoord.periodic.coordinates import RETRY_PRIMES

    assert RETRY_PRIMES == tuple(p for p in range(47, 98) if all(p % d for d in range(2, p)))
    assert all(check_prime(p) == p for p in RETRY_PRIMES)


def test_circle_has_one_clear_bar_and_recovers_the_angle():
    x, phase = noisy_circle()
    est = CircularCoordinates().fit(x)
    bc = est.barcode_
    sel = est.selection_
    assert sel.index == 0 and sel.clear
    assert sel.birth < 0.3  # born at the sampling gap, far below the radius
    assert bc.persistence(1)[0] > 5 * bc.persistence(1)[1]
    assert est.cocycle_check_.ok
    theta = est.coordinates_
    assert theta.min() >= 0 and theta.max() < 1
    assert theta[0] == 0.0
    assert circular_error(theta, phase) < 0.03
    u = unwrap(theta)
    assert u[-1] - u[0] == pytest.approx(3.0 * 299 / 300, abs=0.05)


def test_uneven_sampling_gives_a_monotone_coordinate():
    # The harmonic coordinate follows the geometry, not time: with uneven sampling it is
    # a monotone (not linear) function of the angle.
    x, phase = noisy_circle(uneven=0.5, noise=0.01)
    theta = CircularCoordinates().fit(x).coordinates_
    assert circular_error(theta, phase) < 0.2
    ut, up = unwrap(theta), unwrap(phase)
    assert np.corrcoef(ut, up)[0, 1] > 0.99
    order = np.argsort(phase[:100])  # first turn: coordinate sorted by true phase rises
    steps = np.diff(np.unwrap(2 * np.pi * theta[:100][order]))
    assert np.mean(steps > 0) > 0.95


def test_reversed_time_gives_increasing_coordinate():
    x, phase = noisy_circle()
    theta = CircularCoordinates().fit(x[::-1]).coordinates_
    u = unwrap(theta)
    assert u[-1] - u[0] > 2.5  # increases with frame order although the points run backwards


def test_lift_is_centred():
    c = np.array([[0, 1, 0], [0, 2, 1], [0, 3, 23], [0, 4, 24], [0, 5, 46]])
    assert lift_cocycle(c, 47).tolist() == [0, 1, 23, -23, -1]


def test_cocycle_check_finds_a_broken_lift():
    x, _ = noisy_circle(n=120, turns=1.0, dim=2)
    bc = compute_barcode(x, prime=47)
    sel = select_bar(bc, 0)
    edges = rips_edges(x, sel.scale)
    z, _ = cocycle_on_edges(edges, bc.cocycles[0], lift_cocycle(bc.cocycles[0], 47).astype(float), len(x))
    ok = check_cocycle(edges, z, len(x))
    assert ok.ok and ok.n_triangles > 0
    broken = z.copy()
    k = np.flatnonzero(broken)[0]
    broken[k] += 47  # still a cocycle mod 47, no longer over the integers
    bad = check_cocycle(edges, broken, len(x))
    assert bad.n_violations > 0


def test_harmonic_coordinate_on_a_polygon_is_uniform():
    n = 12
    edges = np.array([[i, i + 1] for i in range(n - 1)] + [[0, n - 1]])
    z = np.zeros(len(edges))
    z[-1] = 1.0  # the closing edge 0 -> n-1 carries the winding
    theta, harmonic = harmonic_coordinate(edges, z, n)
    theta = orient_with_time(theta)
    np.testing.assert_allclose(theta, np.arange(n) / n, atol=1e-9)
    np.testing.assert_allclose(np.abs(harmonic), 1.0 / n, atol=1e-9)


def test_temporal_metric_zeroes_consecutive_frames():
    x, _ = noisy_circle(n=50, turns=1.0)
    d = temporal_distance_matrix(x)
    assert np.all(np.diagonal(d, 1) == 0)
    assert d[0, 2] > 0
    # Euclidean distances, symmetric, with 0 between consecutive frames (both ways)
    pts = np.array([[0.0, 0.0], [3.0, 4.0], [6.0, 0.0], [0.0, 8.0]])
    want = np.array([[0, 0, 6, 8], [0, 0, 0, 5], [6, 0, 0, 0], [8, 5, 0, 0]], float)
    np.testing.assert_array_equal(temporal_distance_matrix(pts), want)
    est = CircularCoordinates(temporal=True).fit(x)
    assert est.selection_.clear


def test_scale_outside_the_bar_is_refused():
    x, _ = noisy_circle(n=100, turns=1.0)
    bc = compute_barcode(x)
    b, d = bc.h1[0]
    with pytest.raises(ParameterError, match="outside"):
        select_bar(bc, 0, scale=b / 2)
    with pytest.raises(ParameterError, match="out of range"):
        select_bar(bc, len(bc.h1))


def test_select_bar_figures_on_a_known_barcode():
    """Gap to the next-longest bar (the last bar has none: infinite), ratio, scale and
    clearness on hand-made bars; deaths are capped at the threshold."""
    from cyclecoord.periodic.barcode import Barcode

    h1 = np.array([[1.0, np.inf], [1.0, 2.0], [0.5, 1.0]])  # persistence 4, 1, 0.5
    bc = Barcode(h0=np.zeros((0, 2)), h1=h1, cocycles=[], threshold=5.0, prime=47, n_points=9)
    figures = [(s.gap, s.ratio, s.scale, s.clear) for s in (select_bar(bc, k) for k in range(3))]
    assert figures == [
        (4.0, 5.0, pytest.approx(4.6), True),
        (2.0, 2.0, pytest.approx(1.9), True),
        (np.inf, 2.0, pytest.approx(0.95), True),
    ]
    # a bar shorter than 5 % of the threshold is not clear, however isolated
    short = Barcode(h0=np.zeros((0, 2)), h1=np.array([[0.1, 0.3]]), cocycles=[], threshold=5.0,
                    prime=47, n_points=9)
    s = select_bar(short, 0)
    assert (s.gap, s.ratio, s.clear) == (np.inf, pytest.approx(3.0), False)


def test_noise_has_no_clear_bar():
    rng = np.random.default_rng(3)
    x = rng.standard_normal((200, 6))
    bc = compute_barcode(x)
    assert not select_bar(bc, 0).clear


def test_transform_of_new_points_matches_fit():
    x, phase = noisy_circle(n=600, turns=4.0, noise=0.02, seed=1)
    train, test = x[::2], x[1::2]
    est = CircularCoordinates().fit(train)
    np.testing.assert_array_equal(est.transform(train), est.coordinates_)
    pred = est.transform(test)
    # neighbours in time: each held-back frame lies between two training frames
    ref = est.coordinates_
    mid = np.angle(np.exp(2j * np.pi * ref[:-1]) + np.exp(2j * np.pi * ref[1:])) / (2 * np.pi)
    err = np.abs(np.mod(pred[:-1] - mid + 0.5, 1.0) - 0.5)
    assert np.median(err) < 0.02


def test_invalid_points():
    with pytest.raises(ParameterError):
        CircularCoordinates().fit(np.array([[0.0, np.nan], [1, 2], [3, 4]]))
    with pytest.raises(ParameterError, match="need at least 3 points, got 2"):
        CircularCoordinates().fit(np.zeros((2, 3)))
    with pytest.raises(ParameterError, match="not fitted"):
        CircularCoordinates().transform(np.zeros((5, 3)))


def test_three_points_are_enough_for_a_barcode():
    """Three points are the fewest accepted: their barcode has no H1 bar (a triangle is
    filled as soon as its edges are there); a fourth point on a unit square makes the one
    loop, born at the side and dead at the diagonal."""
    tri = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    assert len(CircularCoordinates().fit_barcode(tri).h1) == 0
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    np.testing.assert_allclose(CircularCoordinates().fit_barcode(square).h1, [[1.0, np.sqrt(2)]],
                               rtol=1e-6)


def _check_by_unique(edges, z, n):
    """Reference: distinct triangles by sorting their vertex keys (the former method)."""
    import scipy.sparse as sp

    from cyclecoord.periodic._cochain import _lookup

    support = np.flatnonzero(z)
    i, j = edges[:, 0], edges[:, 1]
    adj = sp.csr_matrix((np.ones(len(edges)), (i, j)), shape=(n, n))
    adj = (adj + adj.T).tocsr()
    a, b = i[support], j[support]
    common = adj[a].multiply(adj[b]).tocoo()
    ea, eb, c = a[common.row], b[common.row], common.col.astype(np.int64)
    val = z[support][common.row] + _lookup(edges, z, n, eb, c) + _lookup(edges, z, n, c, ea)
    bad = np.abs(val) > 0.5
    tri = np.sort(np.column_stack([ea, eb, c]), axis=1)
    key = (tri[:, 0] * n + tri[:, 1]) * n + tri[:, 2]
    return len(np.unique(key)), len(np.unique(key[bad]))


def test_rips_edges_known_answer_and_empty():
    """Edges i < j within the scale, sorted, from points or a distance matrix; none at a
    scale below every distance is still an (0, 2) integer array."""
    x = np.array([[0.0, 0.0], [3.0, 0.0], [1.0, 0.0], [0.0, 1.5]])
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    for edges in (rips_edges(x, 2.0), rips_edges(x, 2.0, d)):
        assert edges.dtype == np.int64 and edges.tolist() == [[0, 2], [0, 3], [1, 2], [2, 3]]
    for edges in (rips_edges(x, 0.5), rips_edges(x, 0.5, d)):
        assert edges.shape == (0, 2) and edges.dtype == np.int64


@pytest.mark.parametrize("seed", range(4))
def test_cocycle_check_counts_distinct_triangles_as_sorting_does(seed):
    from cyclecoord.periodic.coordinates import check_cocycle, rips_edges

    rng = np.random.default_rng(seed)
    x = rng.normal(size=(80, 3))
    edges = rips_edges(x, 1.2)
    z = np.where(rng.random(len(edges)) < 0.3, rng.integers(-3, 4, len(edges)), 0).astype(float)
    got = check_cocycle(edges, z, 80)
    want = _check_by_unique(edges, z, 80)
    assert got.n_triangles > 50 and got.n_violations > 10
    assert (got.n_triangles, got.n_violations) == want
    # a true coboundary has no violations
    w = rng.integers(-2, 3, 80).astype(float)
    cob = w[edges[:, 1]] - w[edges[:, 0]]
    got = check_cocycle(edges, cob, 80)
    assert got.n_violations == 0 and got.n_triangles == _check_by_unique(edges, cob, 80)[0]


@pytest.mark.parametrize("seed, weighted", [(0, False), (1, False), (2, True)])
def test_direct_harmonic_solve_matches_lsqr(seed, weighted):
    """The factorised normal equations give LSQR's minimum-norm solution (to 1e-9)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import lsqr

    from cyclecoord.periodic.coordinates import harmonic_coordinate, rips_edges

    rng = np.random.default_rng(seed)
    t = rng.random(150) * 2 * np.pi
    x = np.column_stack([np.cos(t), np.sin(t)]) * 3 + rng.normal(0, 0.1, (150, 2))
    x = np.concatenate([x, x[:30] + 50.0])  # a second component
    edges = rips_edges(x, 0.9)
    n, e = len(x), len(edges)
    z = np.where(rng.random(e) < 0.1, 1.0, 0.0)
    wts = rng.uniform(1.0, 20.0, e) if weighted else None
    theta, harmonic = harmonic_coordinate(edges, z, n, wts)
    delta = sp.csr_matrix((np.tile([-1.0, 1.0], e), (np.repeat(np.arange(e), 2), edges.ravel())), shape=(e, n))
    sw = np.ones(e) if wts is None else np.sqrt(wts)
    w = lsqr(sp.diags(sw) @ delta, -sw * z, atol=1e-12, btol=1e-12, iter_lim=20 * n + 1000)[0]
    np.testing.assert_allclose(harmonic, z + delta @ w, atol=1e-9)
    d = np.mod(theta - np.mod(-w, 1.0) + 0.5, 1.0) - 0.5
    assert np.max(np.abs(d)) < 1e-9


def test_extension_table_gives_the_binary_search_lookups_bit_for_bit(monkeypatch):
    import cyclecoord.periodic._cochain as co

    rng = np.random.default_rng(4)
    t = rng.random(2000) * 2 * np.pi
    pts = np.column_stack([np.cos(t), np.sin(t), 0.2 * np.cos(3 * t)]) * 4 + rng.normal(0, 0.2, (2000, 3))
    centers = pts[:150]
    edges = co.rips_edges(centers, 2.0)
    harmonic = rng.normal(0, 0.1, len(edges))
    ctheta = rng.random(150)
    u = rng.integers(0, 150, 500)
    v = rng.integers(0, 150, 500)
    table = co._increment_table(edges, harmonic, 150)
    want = co._lookup(edges, harmonic, 150, u, v)
    assert np.array_equal(table[u, v], want) and np.array_equal(np.signbit(table[u, v]), np.signbit(want))
    fast = co.extend_coordinate(pts, centers, ctheta, edges, harmonic, 1.0, chunk=700)
    monkeypatch.setattr(co, "_TABLE_MAX_CENTERS", 0)
    slow = co.extend_coordinate(pts, centers, ctheta, edges, harmonic, 1.0, chunk=700)
    assert np.array_equal(fast[0], slow[0]) and np.array_equal(fast[1], slow[1])


def test_coordinates_stay_below_one():
    """A value a hair below the first frame's wraps to 0, not to 1.0 (np.mod(-1e-17, 1))."""
    import cyclecoord as cc

    res = cc.extract(cc.datasets.example_capture().motion)
    assert res.coordinate.min() >= 0.0 and res.coordinate.max() < 1.0
    from cyclecoord.periodic.coordinates import orient_with_time

    out = orient_with_time(np.array([0.3, np.nextafter(0.3, 0.0), 0.5, 0.7]))
    assert out.max() < 1.0 and out[1] == 0.0


def test_extend_coordinate_point_in_one_ball_takes_that_center_value():
    # a point inside the ball of one center only (not the first) gets that center's value;
    # one in no ball, its nearest center's (the docstring's `covered`)
    from cyclecoord.periodic._cochain import extend_coordinate

    centers = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]])
    theta = np.array([0.1, 0.6, 0.85])
    pts = np.array([[10.5, 0.0], [0.0, 9.7], [0.2, 0.0], [8.0, 1.0]])
    out, covered = extend_coordinate(
        pts, centers, theta, np.zeros((0, 2), int), np.zeros(0), radius=1.0
    )
    np.testing.assert_allclose(out, [0.6, 0.85, 0.1, 0.6], atol=1e-12)
    assert covered.tolist() == [True, True, True, False]
