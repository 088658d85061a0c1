"""Known-answer tests of the barcode (``periodic.barcode``), the direct ripser call
(``periodic._rips``) and the circular-coordinate estimator (``periodic.coordinates``).

Regular polygons give the answers by hand: the H1 bar of N points on a unit circle is
born at the chord between neighbours, 2 sin(pi/N), and (for N = 6 and 12) dies at the
chord 2 sin(pi k/N) of the first k with k/N >= 1/3, where the Rips complex fills the
circle; ripser itself, called through its own Python layer, is the independent check.
"""

import warnings

import numpy as np
import pytest
import ripser

from cyclecoord.errors import ParameterError
from cyclecoord.periodic import coordinates as co_mod
from cyclecoord.periodic._cochain import CocycleCheck
from cyclecoord.periodic._rips import _euclidean_distances, rips_cohomology
from cyclecoord.periodic.barcode import (
    Barcode,
    _diameter,
    _distances_to,
    check_prime,
    compute_barcode,
    default_max_scale,
    refine_birth,
    select_bar,
    temporal_distance_matrix,
    winding_birth,
)
from cyclecoord.periodic.coordinates import CircularCoordinates


def circle(n, r=1.0, phase=0.0, centre=(0.0, 0.0)):
    a = 2 * np.pi * np.arange(n) / n + phase
    return np.column_stack([centre[0] + r * np.cos(a), centre[1] + r * np.sin(a)])


def chord(n, k=1, r=1.0):
    return 2 * r * np.sin(np.pi * k / n)


# ---------------------------------------------------------------- _rips
def test_euclidean_distances_are_scikit_learns_bit_for_bit():
    from sklearn.metrics.pairwise import euclidean_distances

    x = np.random.default_rng(0).normal(0, 3, (40, 5))
    d = _euclidean_distances(x)
    assert np.array_equal(d, euclidean_distances(x, x))
    assert np.all(np.diagonal(d) == 0) and np.all(d >= 0)


def test_rips_cohomology_of_a_hexagon_by_hand_and_as_ripser():
    x = circle(6)
    res = rips_cohomology(x, 3.0, 47)
    want = ripser.ripser(x, maxdim=1, thresh=3.0, coeff=47, do_cocycles=True)
    for a, b in zip(res["dgms"], want["dgms"]):
        assert np.array_equal(a, b)
    h1 = res["dgms"][1]
    assert h1.shape == (1, 2)
    np.testing.assert_allclose(h1[0], [chord(6), chord(6, 2)], rtol=1e-6)  # [1, sqrt 3]
    h0 = res["dgms"][0]
    assert h0.shape == (6, 2) and np.isinf(h0[:, 1]).sum() == 1
    c = res["cocycles"][1][0]
    assert c.shape[1] == 3 and np.all((c[:, 2] >= 0) & (c[:, 2] < 47))
    assert res["num_edges"] == want["num_edges"]


# ---------------------------------------------------------------- check_prime
@pytest.mark.parametrize("p", [13, 17, 47, 97, 13.0, np.int64(53)])
def test_primes_accepted(p):
    assert check_prime(p) == int(p) and isinstance(check_prime(p), int)


@pytest.mark.parametrize("p", [11, 7, 2, 12, 49, 121, 169, 91, 13.5, "x", None, -13])
def test_primes_refused(p):
    with pytest.raises(ParameterError):
        check_prime(p)


def test_prime_string_of_digits_is_refused_as_not_equal():
    with pytest.raises(ParameterError, match="integer"):
        check_prime("13")  # int("13") == 13 != "13"


# ---------------------------------------------------------------- Barcode
def _bc(h1, threshold=10.0, h0=None):
    h1 = np.asarray(h1, dtype=float).reshape(-1, 2)
    h0 = np.zeros((0, 2)) if h0 is None else np.asarray(h0, dtype=float)
    return Barcode(h0=h0, h1=h1, cocycles=[np.zeros((0, 3), np.int64)] * len(h1),
                   threshold=threshold, prime=47, n_points=10)


def test_persistence_caps_deaths_at_the_threshold():
    b = _bc([[1.0, 4.0], [2.0, np.inf]], threshold=5.0,
            h0=[[0.0, 0.5], [0.0, 1.0], [0.0, np.inf]])
    assert b.persistence(1).tolist() == [3.0, 3.0]
    assert b.persistence().tolist() == [3.0, 3.0]
    assert b.persistence(0).tolist() == [0.5, 1.0, 5.0]
    assert b.long_h0(1.0) == 1  # strictly longer: 1.0 is not
    assert b.long_h0(0.9) == 2
    assert b.long_h0(0.0) == 3
    assert _bc([]).persistence(1).shape == (0,)
    assert _bc([]).long_h0(0.1) == 0


def test_barcode_to_dict():
    b = _bc([[1.0, np.inf], [0.5, 2.0]], h0=[[0.0, 1.5], [0.0, np.inf]])
    assert b.to_dict() == {"h0": [[0.0, 1.5], [0.0, None]], "h1": [[1.0, None], [0.5, 2.0]]}


# ---------------------------------------------------------------- distances, diameter
def test_temporal_distance_matrix_by_hand():
    x = np.array([[0.0], [1.0], [3.0], [6.0]])
    d = temporal_distance_matrix(x)
    want = np.array([[0, 0, 3, 6], [0, 0, 0, 5], [3, 0, 0, 0], [6, 5, 0, 0]], dtype=float)
    assert np.array_equal(d, want)


def test_diameter_exact_and_by_sweeps():
    x = np.array([[0.0, 0.0], [1.0, 0.0], [-1.5, 0.0]])
    assert _diameter(x) == 2.5
    assert _diameter(x, exact_limit=3) == 2.5  # n <= limit: exact
    # beyond the limit: sweeps from point 0 (farthest: -1.5 at 1.5), then from there
    assert _diameter(x, exact_limit=2, sweeps=1) == 1.5
    assert _diameter(x, exact_limit=2, sweeps=2) == 2.5
    assert _diameter(x[:1]) == 0.0 and _diameter(x[:0]) == 0.0
    assert _diameter(x[:2]) == 1.0


def test_diameter_sweeps_stop_when_no_longer():
    # from point 0 the farthest is 3 (distance 2); from 3 the farthest is 0 again: 2 <= 2 stops
    x = np.array([[0.0], [0.5], [1.0], [2.0]])
    assert _diameter(x, exact_limit=1, sweeps=10) == 2.0


def test_distances_to_in_blocks():
    x = np.random.default_rng(1).normal(0, 1, (23, 4))
    want = np.linalg.norm(x - x[5], axis=1)
    for block in (1, 4, 7, 1_000_000):
        assert np.array_equal(_distances_to(x, 5, block=block), want)


def test_default_max_scale_by_hand():
    x = np.arange(11, dtype=float)[:, None]  # diameter 10, steps 1
    assert default_max_scale(x) == 5.0
    y = np.array([[0.0], [1.0], [2.0], [20.0]])  # diameter 20, steps 1, 1, 18
    step = np.percentile([1.0, 1.0, 18.0], 99.5)
    assert default_max_scale(y) == pytest.approx(max(10.0, 2 * step))
    assert default_max_scale(y) > 10.0
    d = np.abs(y - y.T)
    assert default_max_scale(y, d) == pytest.approx(2 * step)
    dt = temporal_distance_matrix(y)  # steps 0: half the largest distance
    assert default_max_scale(y, dt) == 10.0
    assert default_max_scale(np.zeros((4, 2))) == 1e-9


# ---------------------------------------------------------------- compute_barcode
def test_compute_barcode_of_a_hexagon():
    b = compute_barcode(circle(6), max_scale=3.0)
    assert b.h1.shape == (1, 2) and b.prime == 47 and b.threshold == 3.0
    np.testing.assert_allclose(b.h1[0], [1.0, np.sqrt(3)], rtol=1e-6)
    assert b.n_points == 6 and b.point_indices is None and b.extras == {}
    assert b.h0.shape == (6, 2)
    want = ripser.ripser(circle(6), maxdim=1, thresh=3.0, coeff=47, do_cocycles=True)
    assert b.n_edges == want["num_edges"] == 15


def test_compute_barcode_default_threshold_and_prime():
    x = circle(12)
    b = compute_barcode(x)
    assert b.threshold == pytest.approx(max(1.0, 2 * chord(12)))
    b = compute_barcode(x, max_scale=3, prime=13)
    assert b.prime == 13 and b.threshold == 3.0 and isinstance(b.threshold, float)


def test_compute_barcode_two_circles_sorted_by_persistence_with_oriented_cocycles():
    small = circle(10, r=1.0, centre=(0.0, 0.0))
    big = circle(14, r=3.0, centre=(20.0, 0.0))
    x = np.concatenate([small, big])  # the small circle first in index order
    b = compute_barcode(x, max_scale=8.0)
    want = ripser.ripser(x, maxdim=1, thresh=8.0, coeff=47, do_cocycles=True)
    assert b.h1.shape == (2, 2)
    pers = np.minimum(b.h1[:, 1], 8.0) - b.h1[:, 0]
    assert pers[0] > pers[1]
    np.testing.assert_allclose(b.h1[0, 0], chord(14, r=3.0), rtol=1e-6)
    np.testing.assert_allclose(b.h1[1, 0], chord(10), rtol=1e-6)
    got = sorted(map(tuple, b.h1.tolist()))
    assert got == sorted(map(tuple, want["dgms"][1].tolist()))
    # the cocycle of bar 0 lives on the big circle's points, bar 1's on the small one's
    c0, c1 = b.cocycles
    assert np.all(c0[:, :2] >= 10) and np.all(c1[:, :2] < 10)
    for c in b.cocycles:
        assert np.all(c[:, 0] < c[:, 1]) and np.all((c[:, 2] >= 0) & (c[:, 2] < 47))
    # orienting flips the value: ripser's (j, i, v) is our (i, j, -v mod p)
    k = int(np.argmax([abs(r[0] - b.h1[0, 0]) < 1e-9 for r in want["dgms"][1]]))
    theirs = {}
    for i, j, v in want["cocycles"][1][k]:
        theirs[(min(i, j), max(i, j))] = v % 47 if i < j else (-v) % 47
    assert {(int(i), int(j)): int(v) for i, j, v in c0} == theirs


def test_compute_barcode_refuses_bad_input():
    with pytest.raises(ParameterError, match="3 points"):
        compute_barcode(np.zeros((2, 2)))
    with pytest.raises(ParameterError):
        compute_barcode(np.zeros(5))
    x = circle(6)
    x[2, 0] = np.nan
    with pytest.raises(ParameterError, match="NaN"):
        compute_barcode(x)
    x[2, 0] = np.inf
    with pytest.raises(ParameterError, match="NaN"):
        compute_barcode(x)
    for s in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(ParameterError, match="max scale"):
            compute_barcode(circle(6), max_scale=s)
    with pytest.raises(ParameterError):
        compute_barcode(circle(6), prime=11)
    assert compute_barcode(circle(3), max_scale=2.0).n_points == 3


def test_compute_barcode_on_a_distance_matrix():
    x = circle(8)
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    b = compute_barcode(d, max_scale=3.0, distance_matrix=True)
    np.testing.assert_allclose(b.h1[0], [chord(8), chord(8, 3)], rtol=1e-6)
    # default threshold from the matrix: half its largest entry (2) vs twice its steps
    assert compute_barcode(d, distance_matrix=True).threshold == pytest.approx(
        max(1.0, 2 * chord(8)))


def test_compute_barcode_with_landmarks_names_the_original_points():
    x = circle(40)
    b = compute_barcode(x, max_scale=3.0, n_landmarks=10)
    idx = b.point_indices
    assert idx is not None and len(idx) == 10 and b.n_points == 10
    assert set(np.unique(b.cocycles[0][:, :2])) <= set(idx.tolist())
    assert b.extras["covering_radius"] > 0
    # the landmarks' loop closes at the chord of their widest gap around the 40-gon
    s = np.sort(idx)
    gap = int(np.max(np.diff(np.r_[s, s[0] + 40])))
    np.testing.assert_allclose(b.h1[0, 0], chord(40, gap), rtol=1e-6)
    # as many landmarks as points (or more): every point, no landmarks
    for n in (40, 41):
        full = compute_barcode(x, max_scale=3.0, n_landmarks=n)
        assert full.point_indices is None and full.n_points == 40 and full.extras == {}


# ---------------------------------------------------------------- select_bar
def test_select_bar_by_hand():
    b = _bc([[1.0, 4.0], [1.0, 1.5]], threshold=10.0)
    s = select_bar(b)
    assert (s.index, s.birth, s.death) == (0, 1.0, 4.0)
    assert s.scale == pytest.approx(1.0 + 0.9 * 3.0)
    assert s.ratio == 4.0 and s.gap == 6.0 and s.clear and s.full_birth is None
    s = select_bar(b, 0, scale_fraction=0.5)
    assert s.scale == pytest.approx(2.5)
    s = select_bar(b, 1)
    assert s.ratio == 1.5 and s.gap == float("inf") and s.scale == pytest.approx(1.45)
    assert s.clear  # ratio 1.5 >= 1.5, gap inf, persistence 0.5 >= 0.05 * 10
    d = s.to_dict()
    assert d["gap"] is None and d["death"] == 1.5 and d["index"] == 1


def test_select_bar_clear_boundaries():
    # ratio exactly 1.5, gap exactly 2, persistence exactly 5 % of the threshold: clear
    b = _bc([[2.0, 3.0], [1.0, 1.5]], threshold=20.0)
    s = select_bar(b)
    assert s.ratio == 1.5 and s.gap == 2.0 and s.clear
    # persistence just under 5 % of the threshold: not clear
    assert not select_bar(_bc([[2.0, 3.0], [1.0, 1.5]], threshold=20.01)).clear
    # ratio under 1.5
    assert not select_bar(_bc([[2.0, 2.99], [1.0, 1.4]], threshold=5.0)).clear
    # gap under 2
    assert not select_bar(_bc([[2.0, 3.0], [1.0, 1.51]], threshold=5.0)).clear
    # each alone is enough to fail; all three pass
    assert select_bar(_bc([[2.0, 3.0], [1.0, 1.4]], threshold=5.0)).clear


def test_select_bar_inf_death_zero_birth_and_zero_next():
    b = _bc([[0.0, np.inf], [1.0, 1.0]], threshold=4.0)
    s = select_bar(b)
    assert s.ratio == float("inf") and s.gap == float("inf")
    assert s.scale == pytest.approx(0.9 * 4.0) and s.death == float("inf")
    assert s.to_dict()["death"] is None and s.clear
    b = _bc([[1.0, np.inf]], threshold=4.0)
    s = select_bar(b)
    assert s.ratio == 4.0 and s.scale == pytest.approx(1 + 0.9 * 3)


def test_select_bar_gap_is_to_the_bar_after_the_index():
    b = _bc([[1.0, 9.0], [1.0, 5.0], [1.0, 2.0]], threshold=10.0)
    assert select_bar(b, 1).gap == 4.0
    assert select_bar(b, 0).gap == 2.0


def test_select_bar_refusals_and_explicit_scales():
    b = _bc([[1.0, 4.0], [1.0, 1.5]], threshold=3.0)
    with pytest.raises(ParameterError, match="no H1 bar"):
        select_bar(_bc([]))
    for k in (-1, 2):
        with pytest.raises(ParameterError, match="out of range"):
            select_bar(b, k)
    for f in (0.0, 1.0, -0.1, 1.5):
        with pytest.raises(ParameterError, match="fraction"):
            select_bar(b, 0, scale_fraction=f)
    assert select_bar(b, 0, scale=1.0).scale == 1.0  # the birth itself is inside
    assert select_bar(b, 0, scale=3.0).scale == 3.0  # the threshold itself
    for s in (0.99, 3.01, 4.0):
        with pytest.raises(ParameterError, match="outside"):
            select_bar(b, 0, scale=s)
    with pytest.raises(ParameterError, match="outside"):
        select_bar(b, 1, scale=1.5)  # the death is outside
    assert select_bar(b, 1, scale=1.25).scale == 1.25


# ---------------------------------------------------------------- winding_birth
def test_winding_birth_of_a_polygon():
    n = 12
    x = circle(n)
    theta = np.arange(n) / n
    i, j = np.triu_indices(n, 1)
    d = np.linalg.norm(x[i] - x[j], axis=1)
    pairs = np.column_stack([i, j])
    assert winding_birth(pairs, d, theta) == pytest.approx(chord(n))
    # a coordinate that does not wind: no class
    assert winding_birth(pairs, d, np.zeros(n)) is None
    assert winding_birth(np.zeros((0, 2), np.int64), np.zeros(0), theta) is None


def test_winding_birth_ignores_a_small_loop_that_does_not_wind():
    # a 12-gon of radius 1 (winds once) and a triangle far away whose coordinate is constant
    big = circle(12)
    tri = circle(3, r=0.1, centre=(10.0, 0.0))
    x = np.concatenate([big, tri])
    theta = np.r_[np.arange(12) / 12, [0.5, 0.5, 0.5]]
    i, j = np.triu_indices(15, 1)
    d = np.linalg.norm(x[i] - x[j], axis=1)
    keep = d < 5
    got = winding_birth(np.column_stack([i, j])[keep], d[keep], theta)
    assert got == pytest.approx(chord(12))


def test_winding_birth_reversed_pairs_and_wrap():
    # the loop 0-1-2-3 given as (j, i) pairs, coordinate 0, .25, .5, .75: winds once,
    # closes at the longest edge (length 2)
    pairs = np.array([[1, 0], [2, 1], [3, 2], [0, 3]])
    got = winding_birth(pairs, np.array([1.0, 1.0, 1.0, 2.0]), np.array([0, 0.25, 0.5, 0.75]))
    assert got == 2.0


# ---------------------------------------------------------------- refine_birth
def test_refine_birth_of_a_polygon_on_every_point():
    x = circle(40)
    # landmark birth (every 4th point) -> on all points the class is born at the neighbour chord
    lb = chord(40, 4)
    got = refine_birth(x, lb)
    assert got == pytest.approx(chord(40), rel=1e-6)
    got = refine_birth(x, lb, coordinate=np.arange(40) / 40)
    assert got == pytest.approx(chord(40), rel=1e-12)
    # margin: below the full birth nothing is alive
    assert refine_birth(x, chord(40) * 0.9, margin=1.0) is None
    # too many edges
    assert refine_birth(x, lb, max_edges=10) is None


def test_refine_birth_covering_radius_skips_older_loops():
    # a small circle (born early) and a big one; the landmark class is the big one's
    small = circle(8, r=0.5, centre=(0.0, 0.0))
    big = circle(30, r=3.0, centre=(20.0, 0.0))
    x = np.concatenate([small, big])
    lb = chord(30, r=3.0) * 1.3
    assert refine_birth(x, lb) == pytest.approx(chord(8, r=0.5), rel=1e-6)  # oldest alive
    got = refine_birth(x, lb, covering_radius=0.5 * (lb - chord(30, r=3.0)) * 1.01)
    assert got == pytest.approx(chord(30, r=3.0), rel=1e-6)
    # a covering radius too small to reach back to the big circle's birth: nothing
    assert refine_birth(x, lb, covering_radius=0.01) is None
    # 2 r reaching 2/3 of the way down to the small circle's birth: only the big one
    cs = chord(8, r=0.5)
    got = refine_birth(x, lb, covering_radius=(lb - cs) / 3)
    assert got == pytest.approx(chord(30, r=3.0), rel=1e-6)
    # a bar born exactly 2 r below the landmark birth is taken (0.1 % slack)
    assert refine_birth(x, lb, covering_radius=(lb - cs) / 2) == pytest.approx(cs, rel=1e-6)


def test_refine_birth_sample_refuses_before_counting(monkeypatch):
    # 10 points, 45 pairs: over 1.25 x 20 = 25, so the sample is asked; when it says the
    # complex is too big the answer is None even though the exact count (10 edges) fits
    import cyclecoord.periodic.landmarks as lm

    x = circle(10)
    assert refine_birth(x, chord(10), max_edges=20) == pytest.approx(chord(10), rel=1e-6)

    class Big:
        edges = 1e9

    calls = []
    monkeypatch.setattr(lm, "estimate_complex", lambda *a, **k: calls.append(1) or Big())
    assert refine_birth(x, chord(10), max_edges=20) is None and calls
    # with no more pairs than 1.25 x the budget the sample is not asked
    calls.clear()
    assert refine_birth(x, chord(10), max_edges=36) == pytest.approx(chord(10), rel=1e-6)
    assert not calls


# ---------------------------------------------------------------- CircularCoordinates
def _angle_steps(theta):
    return np.mod(np.diff(theta) + 0.5, 1.0) - 0.5


@pytest.mark.parametrize("reverse", [False, True])
def test_coordinate_of_a_12_gon_is_the_angle(reverse):
    x = circle(12, phase=0.3)
    if reverse:
        x = x[::-1]
    est = CircularCoordinates(landmarks=None).fit(x)
    # oriented along frame order, 0 at the first frame: theta_i = i / 12
    np.testing.assert_allclose(est.coordinates_, np.arange(12) / 12, atol=1e-9)
    assert est.n_components_ == 1 and est.cocycle_check_.ok and est.prime_ == 47
    assert est.landmarks_ is None and est.covering_radius_ == 0.0
    s = est.selection_
    assert s.birth == pytest.approx(chord(12), rel=1e-6)
    # default threshold 1 (half the diameter): the bar is alive, scale 0.9 up to it
    assert est.threshold_ == pytest.approx(max(1.0, 2 * chord(12)))
    assert s.scale == pytest.approx(s.birth + 0.9 * (est.threshold_ - s.birth), rel=1e-6)
    assert est.radius_ == pytest.approx(s.scale / 2)
    # the harmonic cocycle is 1/12 along each step
    np.testing.assert_allclose(np.abs(est.harmonic_cocycle_), 1 / 12, atol=1e-9)
    assert len(est.edges_) == 12


def test_coordinate_of_two_turns_of_a_noisy_polygon_is_the_angle():
    rng = np.random.default_rng(3)
    x = np.concatenate([circle(30), circle(30)]) + rng.normal(0, 1e-3, (60, 2))
    est = CircularCoordinates(landmarks=None).fit(x)
    d = np.mod(est.coordinates_ - np.arange(60) / 30 + 0.5, 1.0) - 0.5
    assert np.max(np.abs(d)) < 1e-6  # measured 1e-15
    assert est.coordinates_[0] == 0.0
    np.testing.assert_allclose(np.sum(_angle_steps(est.coordinates_)), 59 / 30, atol=1e-6)


def test_transform_places_new_points_at_their_angle():
    est = CircularCoordinates(landmarks=None).fit(circle(24))
    new = circle(24, phase=np.pi / 24)  # half-way between the training points
    got = est.transform(new)
    want = (np.arange(24) + 0.5) / 24
    d = np.mod(got - want + 0.5, 1) - 0.5
    assert np.max(np.abs(d)) < 0.01
    assert np.array_equal(est.transform(circle(24)), est.coordinates_)
    with pytest.raises(ParameterError, match="dimensions"):
        est.transform(np.zeros((5, 3)))
    with pytest.raises(ParameterError, match="not fitted"):
        CircularCoordinates().transform(circle(5))


def test_to_and_from_arrays_keep_transform():
    est = CircularCoordinates(landmarks=None).fit(circle(24))
    arrays = est.to_arrays()
    assert set(arrays) == {"centers", "center_theta", "edges", "harmonic_cocycle", "radius",
                           "orientation", "selection", "prime"}
    back = CircularCoordinates.from_arrays(arrays)
    new = circle(24, phase=0.1)
    assert np.array_equal(back.transform(new), est.transform(new))
    assert back.prime_ == 47 and back.selection_.index == 0
    assert back.selection_.scale == est.selection_.scale
    arrays.pop("radius")
    with pytest.raises(ParameterError, match="radius"):
        CircularCoordinates.from_arrays(arrays)


def test_validate_refuses():
    est = CircularCoordinates(landmarks=None)
    with pytest.raises(ParameterError, match="shape"):
        est.fit(np.zeros(5))
    with pytest.raises(ParameterError, match="at least 3"):
        est.fit(np.zeros((2, 2)))
    bad = circle(6)
    bad[0, 0] = np.nan
    with pytest.raises(ParameterError, match="NaN"):
        est.fit(bad)
    with pytest.raises(ParameterError, match="fit_barcode"):
        CircularCoordinates().fit_coordinate()
    with pytest.raises(ParameterError, match="fit_barcode"):
        CircularCoordinates().with_coordinate_params(class_index=1)


def test_with_coordinate_params_shares_the_barcode():
    x = np.concatenate([circle(10), circle(14, r=3.0, centre=(20.0, 0.0))])
    est = CircularCoordinates(landmarks=None, max_scale=8.0)
    est.fit(x)
    other = est.with_coordinate_params(class_index=1)
    assert other.barcode_ is est.barcode_ and other.class_index == 1
    other.fit_coordinate()
    assert est.selection_.index == 0 and other.selection_.index == 1
    # class 0 is the big circle: its coordinate turns on points 10..23
    assert np.ptp(est.coordinates_[:10]) < 1e-9
    assert np.ptp(other.coordinates_[10:]) < 1e-9
    with pytest.raises(ParameterError, match="barcode depends"):
        est.with_coordinate_params(prime=53)


def test_use_barcode():
    x = circle(12)
    b = compute_barcode(x, max_scale=1.0)
    est = CircularCoordinates().use_barcode(x, b)
    assert est.threshold_ == 1.0 and est.landmarks_ is None and est.covering_radius_ == 0.0
    est.fit_coordinate()
    np.testing.assert_allclose(est.coordinates_, np.arange(12) / 12, atol=1e-9)
    with pytest.raises(ParameterError, match="every point"):
        CircularCoordinates().use_barcode(x[:-1], b)
    with pytest.raises(ParameterError, match="Euclidean"):
        CircularCoordinates(temporal=True).use_barcode(x, b)


def test_temporal_metric_on_a_polygon():
    est = CircularCoordinates(landmarks=None, temporal=True).fit(circle(12))
    np.testing.assert_allclose(est.coordinates_, np.arange(12) / 12, atol=1e-9)
    assert est._dist_[0, 1] == 0.0


def test_cocycle_on_centers_maps_to_landmark_positions():
    est = CircularCoordinates()
    est.points_ = np.zeros((6, 1))
    est.landmarks_ = None
    c = np.array([[1, 4, 3]])
    assert est._cocycle_on_centers(c) is c
    est.landmarks_ = np.array([4, 1, 5])
    got = est._cocycle_on_centers(np.array([[1, 4, 3], [1, 5, 2], [0, 4, 1]]))
    # 1 -> 1, 4 -> 0, 5 -> 2: (1, 0) is swapped to (0, 1) with value -3; point 0 is no landmark
    assert got.tolist() == [[0, 1, -3], [1, 2, 2], [-1, 0, 1]]


def test_coordinates_with_landmarks_on_a_polygon():
    x = circle(60)
    est = CircularCoordinates(landmarks=15, refine_birth=True).fit(x)
    assert len(est.landmarks_) == 15 and est.covering_radius_ > 0
    # the landmarks' loop is born at the chord of their widest gap
    s = np.sort(est.landmarks_)
    gap = int(np.max(np.diff(np.r_[s, s[0] + 60])))
    assert est.selection_.birth == pytest.approx(chord(60, gap), rel=1e-6)
    # the extended coordinate follows the angle (measured within 0.042) and never runs back
    d = np.mod(est.coordinates_ - np.arange(60) / 60 + 0.5, 1.0) - 0.5
    assert np.max(np.abs(d)) < 0.06
    assert np.all(_angle_steps(est.coordinates_) > -1e-9)
    assert est.covered_.all() and est.coordinates_[0] == 0.0
    assert est.selection_.full_birth == pytest.approx(chord(60), rel=1e-5)
    est2 = CircularCoordinates(landmarks=15, refine_birth=False).fit(x)
    assert est2.selection_.full_birth is None


def test_lift_failing_for_every_prime_warns_with_the_first_prime(monkeypatch):
    monkeypatch.setattr(co_mod, "check_cocycle", lambda edges, z, n: CocycleCheck(5, 2))
    est = CircularCoordinates(landmarks=None)
    with pytest.warns(RuntimeWarning, match="on 2 of 5 triangles for every prime tried; using p=47"):
        est.fit(circle(12))
    assert est.prime_ == 47
    assert [p for p, _ in est.primes_tried_] == list(co_mod.RETRY_PRIMES)
    assert not est.cocycle_check_.ok


def test_lift_retry_stops_at_the_first_prime_that_works(monkeypatch):
    seen = []

    def check(edges, z, n):
        seen.append(1)
        return CocycleCheck(5, 1 if len(seen) < 3 else 0)

    monkeypatch.setattr(co_mod, "check_cocycle", check)
    est = CircularCoordinates(landmarks=None)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        est.fit(circle(12))
    assert est.prime_ == co_mod.RETRY_PRIMES[2] and len(seen) == 3
    assert est.cocycle_check_.ok and est.barcode_.prime == est.prime_
    np.testing.assert_allclose(est.coordinates_, np.arange(12) / 12, atol=1e-9)


def test_fit_coordinate_warnings_point_at_the_caller(monkeypatch):
    """fit_coordinate is wrapped by one_blas_thread: its warnings skip that wrapper and
    name the line that called fit_coordinate (they named cyclecoord/_blas.py)."""
    monkeypatch.setattr(co_mod, "check_cocycle", lambda edges, z, n: CocycleCheck(5, 2))
    est = CircularCoordinates(landmarks=None)
    est.fit_barcode(circle(12))
    with pytest.warns(RuntimeWarning, match="fails the cocycle condition") as rec:
        est.fit_coordinate()
    assert [w.filename for w in rec] == [__file__]
    # the landmark note (scale raised to cover every frame) likewise
    monkeypatch.undo()
    est = CircularCoordinates(landmarks=10, refine_birth=False, scale_fraction=0.01)
    est.fit_barcode(circle(60))
    with pytest.warns(RuntimeWarning, match="scale raised to") as rec:
        est.fit_coordinate()
    assert [w.filename for w in rec] == [__file__]


def test_landmark_scale_is_raised_so_the_balls_cover_every_point():
    est = CircularCoordinates(landmarks=10, refine_birth=False, scale_fraction=0.01)
    with pytest.warns(RuntimeWarning, match="scale raised to"):
        est.fit(circle(60))
    want = 2.0 * est.covering_radius_ * 1.02
    assert est.selection_.scale == pytest.approx(want, rel=1e-12)
    assert est.radius_ == pytest.approx(want / 2, rel=1e-12)
    assert est.selection_.birth < want
    # a scale already high enough is kept, without a note
    est = CircularCoordinates(landmarks=10, refine_birth=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        est.fit(circle(60))
    s = est.selection_
    assert s.scale == pytest.approx(s.birth + 0.9 * (min(s.death, est.threshold_) - s.birth))


def test_landmark_problem_is_weighted_by_the_cells_of_both_ends():
    # each landmark stands for the points nearest to it; edge weight = product of the two
    # cells' sizes; the centres' coordinate is -w mod 1 of that weighted least squares
    x = circle(60)
    est = CircularCoordinates(landmarks=12, refine_birth=False).fit(x)
    c = est.centers_
    owner = np.argmin(np.linalg.norm(x[:, None] - c[None], axis=2), axis=1)
    mass = np.bincount(owner, minlength=len(c)).astype(float)
    e, z = est.edges_, est.cocycle_
    wts = mass[e[:, 0]] * mass[e[:, 1]]
    d = np.zeros((len(e), len(c)))
    d[np.arange(len(e)), e[:, 0]] = -1.0
    d[np.arange(len(e)), e[:, 1]] = 1.0
    sw = np.sqrt(wts)
    w = np.linalg.lstsq(sw[:, None] * d, -sw * z, rcond=None)[0]
    diff = np.mod(est.center_theta_ - np.mod(-w, 1.0) + 0.5, 1.0) - 0.5
    np.testing.assert_allclose(diff, 0.0, atol=1e-7)
    np.testing.assert_allclose(est.harmonic_cocycle_, z + d @ w, atol=1e-7)
    # the centres are the landmark points, and the training coordinate is oriented
    assert np.array_equal(c, x[est.landmarks_])
    assert est.coordinates_[0] == 0.0


def test_transform_uses_the_fitted_orientation():
    # the same polygon in both frame orders: new points half-way sit half a step along
    # frame order
    for order in (slice(None), slice(None, None, -1)):
        x = circle(24)[order]
        est = CircularCoordinates(landmarks=None).fit(x)
        new = circle(24, phase=np.pi / 24)[order]
        got = est.transform(new)
        # counter-clockwise: new i lies between frames i and i + 1; clockwise: i - 1 and i
        want = (np.arange(24) + (0.5 if order.step is None else -0.5)) / 24
        d = np.mod(got - want + 0.5, 1) - 0.5
        assert np.max(np.abs(d)) < 0.01
        out = est.fit_transform(x)
        assert np.array_equal(out, est.coordinates_) and out is not est.coordinates_
    # transform is (sign * raw - offset) mod 1: the flipped orientation (-1, -offset) of a
    # fitted (1, offset) gives minus the coordinate
    sign, offset = est.orientation_
    assert sign == 1.0
    arrays = est.to_arrays()
    arrays["orientation"] = np.array([-1.0, -offset])
    flipped = CircularCoordinates.from_arrays(arrays).transform(new)
    d = np.mod(flipped + got + 0.5, 1) - 0.5
    np.testing.assert_allclose(d, 0.0, atol=1e-12)


def test_temporal_metric_memory_bound():
    from cyclecoord.periodic.landmarks import run_bytes

    x = circle(200)
    need = (8.0 + 13) * 200**2  # the distance matrix and the filtration's copies
    limit = run_bytes(200, 2) + need
    CircularCoordinates(landmarks=None, temporal=True, memory_limit=limit).fit_barcode(x)
    with pytest.raises(ParameterError, match="temporal metric needs a full 200 x 200"):
        CircularCoordinates(landmarks=None, temporal=True, memory_limit=limit - 1).fit_barcode(x)
    with pytest.raises(ParameterError, match="temporal metric"):
        CircularCoordinates(landmarks=None, temporal=True, memory_limit=limit,
                            memory_reserved=1.0).fit_barcode(x)
    # the Euclidean metric needs no matrix
    CircularCoordinates(landmarks=None, memory_limit=limit - 1).fit_barcode(x)


def test_complex_estimate_is_computed_when_first_asked_for():
    est = CircularCoordinates(landmarks=None)
    est.fit_barcode(circle(30))
    e = est.complex_estimate_
    assert e is not None and e.edges > 0 and est._complex_deferred is False
    assert est.complex_estimate_ is e  # once


def test_temporal_metric_with_landmarks_reads_their_distances():
    x = circle(120)
    est = CircularCoordinates(landmarks=20, temporal=True).fit(x)
    idx = est.landmarks_
    d = temporal_distance_matrix(x)[np.ix_(idx, idx)]
    s = est.selection_.scale
    want = [[i, j] for i in range(20) for j in range(i + 1, 20) if d[i, j] <= s]
    assert est.edges_.tolist() == want
    assert est.selection_.full_birth is None  # not refined for the temporal metric


def test_default_max_scale_of_one_point_is_the_floor():
    assert default_max_scale(np.zeros((1, 3))) == 1e-9
    assert default_max_scale(np.array([[0.0], [1e-12]])) == 1e-9


def test_landmarks_on_a_distance_matrix_are_those_on_the_points():
    # angles jittered so that no two distances tie
    a = np.sort(np.random.default_rng(5).uniform(0, 2 * np.pi, 40))
    x = np.column_stack([np.cos(a), np.sin(a)])
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    one = compute_barcode(x, max_scale=3.0, n_landmarks=12)
    two = compute_barcode(d, max_scale=3.0, n_landmarks=12, distance_matrix=True)
    assert np.array_equal(one.point_indices, two.point_indices) and two.n_points == 12
    np.testing.assert_allclose(two.h1, one.h1, rtol=1e-6)
    # the landmarks' loop closes at their widest gap's chord
    s = np.sort(a[two.point_indices])
    gap = np.max(np.diff(np.r_[s, s[0] + 2 * np.pi]))
    np.testing.assert_allclose(two.h1[0, 0], 2 * np.sin(gap / 2), rtol=1e-6)


def test_winding_birth_of_two_loops_is_the_first_to_close():
    a = circle(10)  # closes at chord(10) = 0.618
    b = circle(8, r=0.5) + np.array([10.0, 0.0])  # closes at 0.5 * chord(8) = 0.383
    x = np.concatenate([a, b])
    theta = np.r_[np.arange(10) / 10, np.arange(8) / 8]
    i, j = np.triu_indices(18, 1)
    d = np.linalg.norm(x[i] - x[j], axis=1)
    keep = d < 2.5
    got = winding_birth(np.column_stack([i, j])[keep], d[keep], theta)
    assert got == pytest.approx(0.5 * chord(8))
    # the second loop's coordinate constant: only the first winds
    theta[10:] = 0.25
    got = winding_birth(np.column_stack([i, j])[keep], d[keep], theta)
    assert got == pytest.approx(chord(10))


def test_primes_tried_record_the_violations(monkeypatch):
    seen = []

    def check(edges, z, n):
        seen.append(1)
        return CocycleCheck(5, [3, 1, 0][len(seen) - 1])

    monkeypatch.setattr(co_mod, "check_cocycle", check)
    est = CircularCoordinates(landmarks=None).fit(circle(12))
    assert est.primes_tried_ == [(47, 3), (53, 1), (59, 0)]
    assert est.selection_.index == 0
    assert est.selection_.birth == pytest.approx(chord(12), rel=1e-6)


def test_a_better_later_prime_is_kept_when_none_is_clean(monkeypatch):
    v = iter([3, 1, 2] + [2] * 8)
    monkeypatch.setattr(co_mod, "check_cocycle", lambda e, z, n: CocycleCheck(5, next(v)))
    est = CircularCoordinates(landmarks=None)
    with pytest.warns(RuntimeWarning, match="on 1 of 5 triangles .* using p=53"):
        est.fit(circle(12))
    assert est.prime_ == 53 and est.barcode_.prime == 53
    assert est.cocycle_check_.n_violations == 1


def test_full_birth_budget_follows_the_memory_limit(monkeypatch):
    from cyclecoord.periodic.landmarks import run_bytes

    seen = []

    def spy(points, birth, prime, max_edges, covering_radius):
        seen.append(max_edges)
        return 0.125

    monkeypatch.setattr(co_mod, "refine_birth", spy)
    x = circle(60)
    est = CircularCoordinates(landmarks=15).fit(x)
    assert seen == [3_000_000] and est.selection_.full_birth == 0.125
    est = CircularCoordinates(landmarks=15, memory_limit=run_bytes(60, 2) + 256 * 1000).fit(x)
    assert seen[1] == 1000
    monkeypatch.setattr(co_mod, "REFINE_BYTES_PER_EDGE", 1e12)  # under one edge: not computed
    est = CircularCoordinates(landmarks=15).fit(x)
    assert len(seen) == 2 and est.selection_.full_birth is None


def test_sparse_rips_cohomology_computes_h0_and_h1_only():
    from scipy.sparse import coo_matrix

    from cyclecoord.periodic._rips import sparse_rips_cohomology

    x = circle(6)
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    c = coo_matrix(np.where(d <= 1.9, d, 0.0)).tocsr().tocoo()
    res = sparse_rips_cohomology(c.row, c.col, c.data, 6, 1.9, 47)
    assert len(res["dgms"]) == 2 and len(res["cocycles"]) == 2
    np.testing.assert_allclose(res["dgms"][1], [[1.0, np.sqrt(3)]], rtol=1e-6)
    assert len(res["cocycles"][1]) == 1


def test_diameter_sweeps_of_a_small_cloud():
    # all distances under 1: the sweeps still find the largest, 0.5
    x = np.array([[0.0], [0.1], [0.5], [0.3]])
    assert _diameter(x, exact_limit=2) == 0.5
    assert _diameter(x * 1e-6, exact_limit=2) == pytest.approx(0.5e-6)


def test_winding_birth_orders_edges_shorter_than_a_picometre():
    # a triangle with edges 0, 1.5e-12 and 1.7e-12 whose coordinate winds once: the
    # loop closes at the longest edge (a zero length is stored as 1e-12, still the shortest)
    pairs = np.array([[0, 1], [1, 2], [0, 2]])
    got = winding_birth(pairs, np.array([0.0, 1.5e-12, 1.7e-12]), np.array([0.0, 1 / 3, 2 / 3]))
    assert got == 1.7e-12


def test_retry_primes_accept_a_scale_at_the_birth(monkeypatch):
    # an explicit scale equal to the bar's birth is inside the bar (birth <= scale): a
    # retry with another prime reads the same bar there
    x = circle(12)
    birth = float(compute_barcode(x, max_scale=1.0).h1[0, 0])
    v = iter([1, 0])
    monkeypatch.setattr(co_mod, "check_cocycle", lambda e, z, n: CocycleCheck(5, next(v)))
    est = CircularCoordinates(landmarks=None, max_scale=1.0, scale=birth)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        est.fit(x)
    assert est.prime_ == 53 and est.primes_tried_ == [(47, 1), (53, 0)]
    assert est.selection_.scale == birth
