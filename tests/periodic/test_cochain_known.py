"""Known-answer tests of the cochain helpers (``periodic._cochain``): edges, lift, cocycle
check, harmonic smoothing, orientation, unwrapping and the partition-of-unity extension.

Every expected value is worked out by hand (in the comments) or by an independent
computation in the test (brute force, ``numpy.linalg.lstsq``); none comes from the code
under test.
"""

import numpy as np
import pytest

from cyclecoord.periodic import _cochain
from cyclecoord.periodic._cochain import (
    CocycleCheck,
    _increment_table,
    _lookup,
    check_cocycle,
    cocycle_on_edges,
    extend_coordinate,
    harmonic_coordinate,
    lift_cocycle,
    mod_one,
    orient_with_time,
    rips_edges,
    unwrap,
)


# ---------------------------------------------------------------- rips_edges
def test_rips_edges_include_the_scale_itself():
    x = np.array([[0.0], [1.0], [2.0], [4.0]])
    # |0-1| = |1-2| = 1 (<= 1: edges), |2-4| = 2, |0-2| = 2
    assert rips_edges(x, 1.0).tolist() == [[0, 1], [1, 2]]
    assert rips_edges(x, 2.0).tolist() == [[0, 1], [0, 2], [1, 2], [2, 3]]
    d = np.abs(x - x.T)
    assert rips_edges(x, 1.0, d).tolist() == [[0, 1], [1, 2]]
    assert rips_edges(x, 2.0, d).tolist() == [[0, 1], [0, 2], [1, 2], [2, 3]]


def test_rips_edges_from_a_distance_matrix_ignore_the_points():
    x = np.zeros((3, 1))  # all at one place: every pair would be an edge
    d = np.array([[0.0, 5.0, 0.5], [5.0, 0.0, 0.7], [0.5, 0.7, 0.0]])
    e = rips_edges(x, 0.6, d)
    assert e.tolist() == [[0, 2]] and e.dtype == np.int64


def test_rips_edges_empty_is_an_int_array_of_shape_0_2():
    x = np.array([[0.0], [1.0], [3.0]])
    for d in (None, np.abs(x - x.T)):
        e = rips_edges(x, 0.5, d)
        assert e.shape == (0, 2) and e.dtype == np.int64


@pytest.mark.parametrize("seed", [0, 1])
def test_rips_edges_match_brute_force_sorted(seed):
    rng = np.random.default_rng(seed)
    x = rng.random((30, 2))
    want = [[i, j] for i in range(30) for j in range(i + 1, 30)
            if np.linalg.norm(x[i] - x[j]) <= 0.3]
    got = rips_edges(x, 0.3)
    assert got.tolist() == want and got.dtype == np.int64
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    assert rips_edges(x, 0.3, d).tolist() == want


# ---------------------------------------------------------------- lift_cocycle
def test_lift_is_centred_at_half_the_prime():
    c = np.array([[0, 1, v] for v in (0, 1, 23, 24, 46, 47, 48, -1)])
    # p = 47, p // 2 = 23: 23 stays, 24 -> -23, 46 -> -1, 47 -> 0, 48 -> 1, -1 -> 46 -> -1
    assert lift_cocycle(c, 47).tolist() == [0, 1, 23, -23, -1, 0, 1, -1]
    # p = 13, p // 2 = 6: 6 stays, 7 -> -6
    c13 = np.array([[0, 1, v] for v in (6, 7, 12)])
    assert lift_cocycle(c13, 13).tolist() == [6, -6, -1]


def test_cocycle_check_ok_is_no_violation():
    assert CocycleCheck(3, 0).ok and not CocycleCheck(3, 1).ok
    assert CocycleCheck(3, 0).n_outside == 0


# ---------------------------------------------------------------- cocycle_on_edges
def test_cocycle_on_edges_spreads_values_and_counts_missing_support():
    edges = np.array([[0, 1], [0, 2], [1, 2], [2, 3]])
    cocycle = np.array([[0, 2, 9], [1, 3, 9], [2, 3, 9], [0, 1, 9]])
    values = np.array([5.0, 2.0, -1.0, 4.0])
    z, missing = cocycle_on_edges(edges, cocycle, values, 4)
    assert z.tolist() == [4.0, 5.0, 0.0, -1.0]
    assert missing == 1  # (1, 3) is not an edge


def test_cocycle_on_edges_past_the_last_edge_and_without_edges():
    edges = np.array([[0, 1], [1, 2]])
    cocycle = np.array([[2, 3, 1], [0, 1, 1]])  # (2, 3) sorts after every edge
    z, missing = cocycle_on_edges(edges, cocycle, np.array([7.0, 3.0]), 4)
    assert z.tolist() == [3.0, 0.0] and missing == 1
    z, missing = cocycle_on_edges(np.zeros((0, 2), np.int64), cocycle, np.array([7.0, 3.0]), 4)
    assert z.shape == (0,) and missing == 2


def test_cocycle_on_edges_all_found():
    edges = np.array([[0, 1], [1, 2]])
    z, missing = cocycle_on_edges(edges, np.array([[1, 2, 1]]), np.array([2.5]), 3)
    assert z.tolist() == [0.0, 2.5] and missing == 0


# ---------------------------------------------------------------- _lookup, table
def test_lookup_is_signed_by_orientation_and_zero_off_the_edges():
    edges = np.array([[0, 1], [0, 2], [1, 3]])
    z = np.array([0.5, -2.0, 3.0])
    u = np.array([0, 1, 2, 0, 3, 2, 3])
    v = np.array([1, 0, 0, 2, 1, 3, 3])
    got = _lookup(edges, z, 4, u, v)
    assert got.tolist() == [0.5, -0.5, 2.0, -2.0, -3.0, 0.0, 0.0]


def test_increment_table_by_hand():
    edges = np.array([[0, 1], [1, 2]])
    t = _increment_table(edges, np.array([0.25, -1.0]), 3)
    assert t.tolist() == [[0.0, 0.25, 0.0], [-0.25, 0.0, -1.0], [0.0, 1.0, 0.0]]
    # the signed zeros of _lookup: +0 above the diagonal, -0 on and below it
    assert not np.signbit(t[0, 2]) and np.signbit(t[2, 0]) and np.signbit(t[1, 1])


# ---------------------------------------------------------------- check_cocycle
TRI = np.array([[0, 1], [0, 2], [1, 2]])  # lexicographic: z(01), z(02), z(12)


def test_check_cocycle_of_zero_is_empty_and_ok():
    c = check_cocycle(TRI, np.zeros(3), 3)
    assert (c.n_triangles, c.n_violations, c.ok) == (0, 0, True)


def test_check_cocycle_on_a_triangle_by_hand():
    # coboundary on triangle 012: z(01) + z(12) - z(02)
    c = check_cocycle(TRI, np.array([1.0, 0.0, 0.0]), 3)  # 1 + 0 - 0 = 1
    assert (c.n_triangles, c.n_violations) == (1, 1)
    c = check_cocycle(TRI, np.array([1.0, 1.0, 0.0]), 3)  # 1 + 0 - 1 = 0, seen twice
    assert (c.n_triangles, c.n_violations) == (1, 0)
    c = check_cocycle(TRI, np.array([1.0, 2.0, 1.0]), 3)  # 1 + 1 - 2 = 0, seen 3 times
    assert (c.n_triangles, c.n_violations) == (1, 0)
    c = check_cocycle(TRI, np.array([1.0, 1.0, 1.0]), 3)  # 1 + 1 - 1 = 1
    assert (c.n_triangles, c.n_violations) == (1, 1)
    c = check_cocycle(TRI, np.array([0.0, 2.0, 1.0]), 3)  # 0 + 1 - 2 = -1
    assert (c.n_triangles, c.n_violations) == (1, 1)


def test_check_cocycle_half_is_not_a_violation():
    # |coboundary| > 0.5 is a violation; exactly 0.5 is not (integer lifts are 0 or >= 1)
    c = check_cocycle(TRI, np.array([0.5, 0.0, 0.0]), 3)
    assert (c.n_triangles, c.n_violations) == (1, 0)
    c = check_cocycle(TRI, np.array([0.75, 0.0, 0.0]), 3)
    assert (c.n_triangles, c.n_violations) == (1, 1)


def test_check_cocycle_square_without_triangles_and_with_a_diagonal():
    square = np.array([[0, 1], [0, 3], [1, 2], [2, 3]])
    c = check_cocycle(square, np.array([1.0, 0.0, 0.0, 0.0]), 4)
    assert (c.n_triangles, c.n_violations) == (0, 0)
    # the diagonal 0-2 makes triangles 012 and 023; z only on the diagonal breaks both
    diag = np.array([[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]])
    c = check_cocycle(diag, np.array([0.0, 1.0, 0.0, 0.0, 0.0]), 4)
    assert (c.n_triangles, c.n_violations) == (2, 2)
    # z(02) = z(01) + z(12) = 1 and z(03) = z(02) + z(23) = 1: a cocycle
    c = check_cocycle(diag, np.array([1.0, 1.0, 1.0, 0.0, 0.0]), 4)
    assert (c.n_triangles, c.n_violations) == (2, 0)
    # z(01) alone: only triangle 012 touches the support
    c = check_cocycle(diag, np.array([1.0, 0.0, 0.0, 0.0, 0.0]), 4)
    assert (c.n_triangles, c.n_violations) == (1, 1)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_check_cocycle_matches_brute_force_over_triangles(seed):
    rng = np.random.default_rng(seed)
    n = 9
    x = rng.random((n, 2))
    edges = rips_edges(x, 0.55)
    z = rng.integers(-1, 2, len(edges)).astype(float) * (rng.random(len(edges)) < 0.4)
    val = {(int(a), int(b)): z[k] for k, (a, b) in enumerate(edges)}
    tri = bad = 0
    for a in range(n):
        for b in range(a + 1, n):
            for c in range(b + 1, n):
                if (a, b) in val and (a, c) in val and (b, c) in val:
                    if val[a, b] or val[a, c] or val[b, c]:
                        tri += 1
                        bad += abs(val[a, b] + val[b, c] - val[a, c]) > 0.5
    got = check_cocycle(edges, z, n)
    assert (got.n_triangles, got.n_violations) == (tri, bad)


# ---------------------------------------------------------------- harmonic_coordinate
def _delta(edges, n):
    d = np.zeros((len(edges), n))
    d[np.arange(len(edges)), edges[:, 0]] = -1.0
    d[np.arange(len(edges)), edges[:, 1]] = 1.0
    return d


@pytest.mark.parametrize("n", [3, 5, 8])
def test_harmonic_on_a_cycle_graph_by_hand(n):
    # cycle 0-1-...-(n-1)-0, z = 1 on the closing edge (0, n-1): the harmonic flow is
    # -1/n on each path edge i -> i+1 and +1/n on 0 -> n-1; w_i = -i/n + (n-1)/(2n)
    # (mean 0), theta = -w mod 1
    edges = np.array(sorted([[i, i + 1] for i in range(n - 1)] + [[0, n - 1]]))
    z = np.array([1.0 if (a, b) == (0, n - 1) else 0.0 for a, b in edges])
    theta, harm = harmonic_coordinate(edges, z, n)
    want_h = np.array([1.0 / n if (a, b) == (0, n - 1) else -1.0 / n for a, b in edges])
    np.testing.assert_allclose(harm, want_h, atol=1e-12)
    w = -np.arange(n) / n + (n - 1) / (2 * n)
    np.testing.assert_allclose(theta, np.mod(-w, 1.0), atol=1e-12)


def test_harmonic_of_a_coboundary_is_zero_and_theta_the_potential():
    # z = δf for f = (0, 0.1, 0.3) on the triangle: harmonic 0, theta = f - mean(f) mod 1
    f = np.array([0.0, 0.1, 0.3])
    z = f[TRI[:, 1]] - f[TRI[:, 0]]
    theta, harm = harmonic_coordinate(TRI, z, 3)
    np.testing.assert_allclose(harm, 0.0, atol=1e-12)
    np.testing.assert_allclose(theta, np.mod(f - f.mean(), 1.0), atol=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("weighted", [False, True])
def test_harmonic_matches_minimum_norm_lstsq(seed, weighted):
    rng = np.random.default_rng(seed)
    n = 14
    x = rng.random((n, 2))
    edges = rips_edges(x, 0.45)
    z = rng.normal(0, 1, len(edges))
    wts = rng.uniform(0.5, 3.0, len(edges)) if weighted else np.ones(len(edges))
    sw = np.sqrt(wts)
    w = np.linalg.lstsq(sw[:, None] * _delta(edges, n), -sw * z, rcond=None)[0]  # minimum norm
    theta, harm = harmonic_coordinate(edges, z, n, wts if weighted else None)
    np.testing.assert_allclose(harm, z + _delta(edges, n) @ w, atol=1e-7)
    d = np.mod(theta - np.mod(-w, 1.0) + 0.5, 1.0) - 0.5
    np.testing.assert_allclose(d, 0.0, atol=1e-7)


def test_weighted_harmonic_on_a_small_cycle_by_hand():
    # triangle, z = 1 on (0, 2), weights 1: the weighted solve (LSQR) gives the same flow
    # as the unweighted one, -1/3 on 0->1 and 1->2, +1/3 on 0->2; w has mean 0
    z = np.array([0.0, 1.0, 0.0])
    theta, harm = harmonic_coordinate(TRI, z, 3, np.ones(3))
    np.testing.assert_allclose(harm, [-1 / 3, 1 / 3, -1 / 3], atol=1e-10)
    np.testing.assert_allclose(theta, np.mod([-1 / 3, 0.0, 1 / 3], 1.0), atol=1e-10)


def test_harmonic_with_several_components_and_an_isolated_vertex():
    # two triangles {0,1,2}, {3,4,5}, vertex 6 alone; each component's w has mean 0
    edges = np.array([[0, 1], [0, 2], [1, 2], [3, 4], [3, 5], [4, 5]])
    f = np.array([0.0, 0.2, 0.5, 0.1, 0.1, 0.4, 0.0])
    z = f[edges[:, 1]] - f[edges[:, 0]]
    z[5] += 1.0  # a winding on the second triangle: flow 1/3 around it
    theta, harm = harmonic_coordinate(edges, z, 7)
    want = np.zeros(7)
    want[:3] = f[:3] - f[:3].mean()
    # second triangle: z = δf + 1 on (4,5) -> w = -(f - mean) + circulation part
    d = _delta(edges, 7)
    w = np.linalg.lstsq(d, -z, rcond=None)[0]
    np.testing.assert_allclose(harm, z + d @ w, atol=1e-10)
    np.testing.assert_allclose(np.mod(theta - np.mod(-w, 1.0) + 0.5, 1) - 0.5, 0, atol=1e-10)
    np.testing.assert_allclose(np.mod(theta[:3] - np.mod(want[:3], 1) + 0.5, 1) - 0.5, 0,
                               atol=1e-10)
    assert theta[6] == 0.0
    np.testing.assert_allclose(harm[3:], [1 / 3, -1 / 3, 1 / 3], atol=1e-10)


# ---------------------------------------------------------------- mod_one, unwrap, orient
def test_mod_one_values():
    out = mod_one(np.array([-1e-17, 1.25, -0.25, 1.0, 0.0, 2.5, -3.0]))
    assert out.tolist() == [0.0, 0.25, 0.75, 0.0, 0.0, 0.5, 0.0]
    assert np.all(out < 1.0)


def test_unwrap_by_hand():
    np.testing.assert_allclose(unwrap(np.array([0.9, 0.1, 0.3])), [0.9, 1.1, 1.3])
    np.testing.assert_allclose(unwrap(np.array([0.1, 0.9, 0.7])), [0.1, -0.1, -0.3])
    # a step of exactly one half reads as -0.5 (steps wrapped into [-0.5, 0.5))
    np.testing.assert_allclose(unwrap(np.array([0.0, 0.5])), [0.0, -0.5])
    assert unwrap(np.array([0.25])).tolist() == [0.25]


def test_orient_with_time_forward_and_backward():
    out, sign, offset = orient_with_time(np.array([0.3, 0.4, 0.6]), return_transform=True)
    np.testing.assert_allclose(out, [0.0, 0.1, 0.3], atol=1e-12)
    assert sign == 1.0 and offset == pytest.approx(0.3)
    out, sign, offset = orient_with_time(np.array([0.9, 0.8, 0.7]), return_transform=True)
    np.testing.assert_allclose(out, [0.0, 0.1, 0.2], atol=1e-12)
    assert sign == -1.0 and offset == pytest.approx(0.1)
    # across the wrap: 0.95 -> 0.05 is +0.1
    out = orient_with_time(np.array([0.95, 0.05, 0.15]))
    np.testing.assert_allclose(out, [0.0, 0.1, 0.2], atol=1e-12)
    assert isinstance(out, np.ndarray)


def test_orient_with_time_zero_net_step_keeps_the_sign():
    out, sign, offset = orient_with_time(np.array([0.2, 0.3, 0.2]), return_transform=True)
    assert sign == 1.0
    np.testing.assert_allclose(out, [0.0, 0.1, 0.0], atol=1e-12)
    # transform identity: out == (sign * theta - offset) mod 1
    out, sign, offset = orient_with_time(np.array([0.7, 0.5, 0.45]), return_transform=True)
    np.testing.assert_allclose(out, np.mod(sign * np.array([0.7, 0.5, 0.45]) - offset, 1.0),
                               atol=1e-12)


# ---------------------------------------------------------------- extend_coordinate
TWO = np.array([[0.0], [1.0]])
EDGE = np.array([[0, 1]])


@pytest.mark.parametrize("table", [True, False])
def test_extend_coordinate_by_hand(monkeypatch, table):
    if not table:
        monkeypatch.setattr(_cochain, "_TABLE_MAX_CENTERS", 0)
    ct = np.array([0.3, 0.2])
    h = np.array([0.1])
    pts = np.array([[0.25], [0.75], [5.0], [0.0], [-0.5]])
    theta, cov = extend_coordinate(pts, TWO, ct, EDGE, h, radius=1.0)
    # x = 0.25: d = 0.25, 0.75; phi = 0.5625, 0.0625 -> weights 0.9, 0.1; nearest 0:
    #   0.3 + 0.1 * (-h(0->1)) = 0.29
    # x = 0.75: nearest 1, weights 0.1 (centre 0), 0.9: 0.2 + 0.1 * (-h(1->0)) = 0.21
    # x = 5: in no ball: nearest centre's value 0.2
    # x = 0: on centre 0, centre 1 at the radius (weight 0): 0.3
    # x = -0.5: only centre 0's ball: 0.3
    np.testing.assert_allclose(theta, [0.29, 0.21, 0.2, 0.3, 0.3], atol=1e-12)
    assert cov.tolist() == [True, True, False, True, True]


def test_extend_coordinate_wraps_into_zero_one_and_chunks_agree():
    ct = np.array([0.005, 0.9])
    h = np.array([0.1])
    pts = np.array([[0.25], [0.75], [2.5]])
    theta, cov = extend_coordinate(pts, TWO, ct, EDGE, h, radius=1.0)
    # 0.005 - 0.01 = -0.005 -> 0.995; 0.9 + 0.01 = 0.91; uncovered: nearest centre 1
    np.testing.assert_allclose(theta, [0.995, 0.91, 0.9], atol=1e-12)
    assert cov.tolist() == [True, True, False]
    t1, c1 = extend_coordinate(pts, TWO, ct, EDGE, h, radius=1.0, chunk=1)
    t2, c2 = extend_coordinate(pts, TWO, ct, EDGE, h, radius=1.0, chunk=2)
    assert np.array_equal(t1, theta) and np.array_equal(t2, theta)
    assert np.array_equal(c1, cov) and np.array_equal(c2, cov)


def test_extend_coordinate_max_neighbors_one_takes_the_nearest_value():
    ct = np.array([0.3, 0.2])
    theta, cov = extend_coordinate(np.array([[0.25], [0.75]]), TWO, ct, EDGE, np.array([0.1]),
                                   radius=1.0, max_neighbors=1)
    np.testing.assert_allclose(theta, [0.3, 0.2], atol=1e-12)
    assert cov.all()


def test_extend_coordinate_three_centres_two_edges():
    # centres at 0, 1, 2 with edges 0-1 (h 0.1) and 1-2 (h -0.2); x = 1.25, radius 1:
    # d = 1.25 (out), 0.25, 0.75: weights 0.9 (centre 1), 0.1 (centre 2); nearest 1:
    # 0.5 + 0.1 * (-h(1->2)) = 0.5 + 0.02
    c = np.array([[0.0], [1.0], [2.0]])
    theta, cov = extend_coordinate(np.array([[1.25]]), c, np.array([0.4, 0.5, 0.6]),
                                   np.array([[0, 1], [1, 2]]), np.array([0.1, -0.2]), 1.0)
    np.testing.assert_allclose(theta, [0.52], atol=1e-12)
    assert cov.tolist() == [True]


def test_harmonic_without_edges_is_zero():
    theta, harm = harmonic_coordinate(np.zeros((0, 2), np.int64), np.zeros(0), 3)
    assert theta.tolist() == [0.0, 0.0, 0.0] and harm.shape == (0,)
    theta, harm = harmonic_coordinate(np.zeros((0, 2), np.int64), np.zeros(0), 3, np.zeros(0))
    assert theta.tolist() == [0.0, 0.0, 0.0] and harm.shape == (0,)


def test_harmonic_on_a_path_with_uneven_potential_by_hand():
    # path 0-1-2-3 (a tree): every cochain is a coboundary, so harmonic = 0 and
    # theta = potential f (f(0) = 0, f(j) = f(i) + z(ij)) less its mean, mod 1
    edges = np.array([[0, 1], [1, 2], [2, 3]])
    z = np.array([0.4, -0.1, 0.3])
    f = np.array([0.0, 0.4, 0.3, 0.6])
    theta, harm = harmonic_coordinate(edges, z, 4)
    np.testing.assert_allclose(harm, 0.0, atol=1e-12)
    np.testing.assert_allclose(theta, np.mod(f - f.mean(), 1.0), atol=1e-12)
