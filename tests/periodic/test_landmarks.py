"""Landmarks, the memory guard, coordinates of new frames and saved phase models."""

import json
import warnings

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.cli import main
from cyclecoord.periodic.coordinates import CircularCoordinates
from cyclecoord.errors import ParameterError
from cyclecoord.periodic.landmarks import AUTO_FULL_LIMIT, AUTO_LANDMARKS, choose_landmarks, estimate_complex
from cyclecoord.periodic.phase_model import PhaseModel
from cyclecoord.periodic.preprocess import Preprocessor
from _measured import at_most


def median_circular_difference(a, b):
    """Median |a - b| on the circle after the best rotation and reflection of ``a``."""
    best = np.inf
    for sign in (1, -1):
        d = np.mod(sign * a - b, 1.0)
        shift = np.angle(np.mean(np.exp(2j * np.pi * d))) / (2 * np.pi)
        best = min(best, float(np.median(np.abs(np.mod(d - shift + 0.5, 1.0) - 0.5))))
    return best


@pytest.fixture(scope="module")
def synthetic_2000():
    cap = cc.datasets.make_periodic_capture(n_frames=2000, noise=0.5, random_state=0)
    return Preprocessor().fit_transform(cap.motion).points


def test_estimate_matches_the_real_edge_count():
    x = np.random.default_rng(0).standard_normal((800, 4))
    est = estimate_complex(x, 1.5)
    from scipy.spatial.distance import pdist

    real = int(np.sum(pdist(x) <= 1.5))
    assert est.edges == pytest.approx(real, rel=0.1)
    assert est.triangles > 0 and est.bytes > 8 * 800 * 800


def test_choice_of_landmarks():
    small = np.random.default_rng(0).standard_normal((AUTO_FULL_LIMIT, 3))
    big = np.random.default_rng(0).standard_normal((AUTO_FULL_LIMIT + 1, 3))
    assert choose_landmarks(small, 1.0)[0] is None
    assert choose_landmarks(big, 1.0)[0] == AUTO_LANDMARKS
    assert choose_landmarks(big, 1.0, landmarks=None)[0] is None
    assert choose_landmarks(big, 1.0, landmarks=300)[0] == 300
    assert choose_landmarks(big, 1.0, landmarks=10)[0] == 10  # the fewest allowed
    with pytest.raises(cc.ParameterError, match="at least 10 landmarks, got 9"):
        choose_landmarks(big, 1.0, landmarks=9)
    with pytest.raises(cc.ParameterError):
        choose_landmarks(big, 1.0, landmarks="many")


def test_memory_guard_switches_before_building(monkeypatch, synthetic_2000):
    from cyclecoord.periodic import _rips

    calls = []
    real = _rips.rips_cohomology

    def spy(*args, **kwargs):
        calls.append(len(args[0]))  # points handed to ripser
        return real(*args, **kwargs)

    monkeypatch.setattr(_rips, "rips_cohomology", spy)
    from cyclecoord.periodic.landmarks import run_bytes

    # a stated limit covers the per-frame arrays too: leave 5 MB for the filtration
    limit = run_bytes(*synthetic_2000.shape) + 5e6
    est = CircularCoordinates(landmarks=None, memory_limit=limit)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est.fit_barcode(synthetic_2000)
    assert "memory guard" in est.landmark_reason_
    assert est.landmarks_ is not None and len(est.landmarks_) < 2000
    assert est.complex_estimate_.bytes <= 5e6
    assert calls and all(n == len(est.landmarks_) for n in calls)  # the full complex was never asked for


def test_refine_birth_refuses_a_dense_complex_from_a_sample(monkeypatch):
    """A complex far over ``max_edges`` is refused before any exact pair count.

    Counting every pair within the scale costs as much as the pairs (quadratic when the
    complex is dense); the sampled estimate decides first.
    """
    import scipy.spatial

    from cyclecoord.periodic.barcode import refine_birth

    def no_tree(*args, **kwargs):
        raise AssertionError("the exact count ran for a complex the sample already refused")

    monkeypatch.setattr(scipy.spatial, "cKDTree", no_tree)
    x = np.random.default_rng(0).standard_normal((3000, 3))  # scale 1.0 links ~10% of pairs
    assert refine_birth(x, 1.0, max_edges=10_000) is None


def test_refine_birth_budget_is_the_edge_count(monkeypatch):
    """Over budget by a clear margin: refused from the sample; within it: counted exactly."""
    import scipy.spatial

    from cyclecoord.periodic.barcode import refine_birth

    x = np.random.default_rng(1).standard_normal((3000, 3))
    edges = estimate_complex(x, 1.05).edges  # refine_birth looks at 1.05 x the birth
    real_tree = scipy.spatial.cKDTree
    built = []

    def counting_tree(*args, **kwargs):
        built.append(1)
        return real_tree(*args, **kwargs)

    monkeypatch.setattr(scipy.spatial, "cKDTree", counting_tree)
    assert refine_birth(x, 1.0, max_edges=int(edges / 1.6)) is None  # 1.6 x over
    assert built == []
    # 10 % over: the sample cannot tell, the exact count refuses it
    assert refine_birth(x, 1.0, max_edges=int(edges / 1.1)) is None
    assert built == [1]


def test_refine_birth_finds_the_full_birth_of_a_circle():
    from cyclecoord.periodic.barcode import refine_birth

    t = np.linspace(0, 1, 400, endpoint=False)
    x = np.c_[np.cos(2 * np.pi * t), np.sin(2 * np.pi * t)]
    step = 2 * np.sin(np.pi / 400)  # neighbour distance: the full Rips loop is born there
    # a landmark birth larger than the full one: the class is still alive at 1.05x it
    assert refine_birth(x, 0.2) == pytest.approx(step, rel=1e-6)


def test_landmarks_match_full_on_69_01(walk_69_01):
    x = Preprocessor().fit_transform(walk_69_01[200:450]).points
    full = CircularCoordinates(max_scale=50, landmarks=None).fit(x)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lm = CircularCoordinates(max_scale=50, landmarks=150).fit(x)
    assert lm.landmarks_ is not None and len(lm.landmarks_) == 150
    assert lm.selection_.full_birth == pytest.approx(full.selection_.birth, rel=0.05)
    assert median_circular_difference(lm.coordinates_, full.coordinates_) < 0.01


def test_landmarks_match_full_on_2000_synthetic_frames(synthetic_2000):
    full = CircularCoordinates(landmarks=None).fit(synthetic_2000)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lm = CircularCoordinates(landmarks="auto").fit(synthetic_2000)
    assert len(lm.landmarks_) == AUTO_LANDMARKS
    assert lm.covering_radius_ > 0 and lm.covered_.all()
    assert lm.selection_.full_birth == pytest.approx(full.selection_.birth, rel=0.05)
    assert median_circular_difference(lm.coordinates_, full.coordinates_) < 0.01


@pytest.fixture(scope="module")
def walk_1200():
    """A walk whose poses move unevenly (slow near its turning points, as real walks):
    150 landmarks of 1200 frames stand for very different numbers of frames each."""
    cap = cc.datasets.make_periodic_capture(kind="walk", n_frames=1200, random_state=0)
    x = Preprocessor().fit_transform(cap.motion).points
    return x, CircularCoordinates(landmarks=None).fit(x)


def test_landmark_weights_make_the_landmark_coordinate_the_full_one(walk_1200):
    """Known answer: the coordinate on every frame.  Each landmark edge is weighted by the
    frames its two landmarks stand for (their cells), so the landmark problem is the full
    one in small; unweighted (or summed) cells put the coordinate's change where the
    landmarks are: unweighted 0.022 of a turn from it, summed or square-rooted 0.011-0.012."""
    x, full = walk_1200
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lm = CircularCoordinates(landmarks=150).fit(x)
    assert len(lm.landmarks_) == 150 and lm.covered_.all()
    # measured (tests/_measured.py RUN) 0.00195 of a turn
    assert median_circular_difference(lm.coordinates_, full.coordinates_) <= at_most(0.00195)


@pytest.mark.parametrize("n_frames", [600, 2400])
def test_transform_of_held_back_frames(n_frames):
    cap = cc.datasets.make_periodic_capture(n_frames=n_frames, noise=0.5, random_state=2)
    m = cap.motion
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full = cc.extract(m)
        part = cc.extract(m[np.arange(0, n_frames, 2)])
    phase = part.model.phase(m[np.arange(1, n_frames, 2)])
    assert median_circular_difference(phase, full.coordinate[1::2]) < 0.02


def test_model_round_trip(tmp_path):
    m = cc.datasets.example_capture().motion
    res = cc.extract(m)
    path = tmp_path / "walk.npz"
    res.model.save(path)
    back = PhaseModel.load(path)
    other = cc.datasets.make_periodic_capture(n_frames=300, random_state=9).motion
    np.testing.assert_allclose(back.phase(other), res.model.phase(other), atol=1e-12)
    # the saved model re-derives training frames by the extension: the same phases, circularly
    d = np.abs(np.mod(back.phase(m) - res.coordinate + 0.5, 1.0) - 0.5)
    assert np.median(d) < 0.01 and d.max() < 0.05
    assert back.period_frames == pytest.approx(res.period_frames)


def test_model_errors(tmp_path):
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a zip")
    with pytest.raises(cc.ParseError, match="bad.npz"):
        PhaseModel.load(bad)
    res = cc.extract(cc.datasets.example_capture().motion)
    few = res.motion.select(res.motion.channels[:20])
    with pytest.raises(cc.ParameterError, match="lacks"):
        res.model.phase(few)


def test_cli_save_and_apply(tmp_path, capsys):
    model, rep = tmp_path / "m.npz", tmp_path / "phase.json"
    take = tmp_path / "take.npz"
    cc.save(cc.datasets.make_periodic_capture(n_frames=600, random_state=4).motion, take)
    assert main(["extract", "example", "--save-model", str(model)]) == 0
    assert main(["extract", str(take), "--apply", str(model), "--report", str(rep)]) == 0
    r = json.loads(rep.read_text())
    assert len(r["coordinate"]) == 600
    assert r["cycles"] == pytest.approx(599 / 120, abs=0.25)
    capsys.readouterr()
    assert main(["extract", "example", "--landmarks", "200", "--memory-limit", "1G", "--report", str(rep)]) == 0
    r = json.loads(rep.read_text())
    assert r["landmarks"]["n_landmarks"] == 200 and r["selected"]["full_birth"] is not None


@pytest.mark.parametrize("shape", [(3000, 8), (1500, 3)])
def test_greedy_landmarks_make_ripsers_choice(shape):
    import ripser
    from scipy.spatial.distance import pdist, squareform

    from cyclecoord.periodic.landmarks import greedy_landmarks

    x = np.random.default_rng(shape[1]).standard_normal(shape)
    res = ripser.ripser(x, maxdim=0, thresh=1e-3, n_perm=150)
    idx, radius = greedy_landmarks(x, 150)
    np.testing.assert_array_equal(idx, res["idx_perm"])
    assert radius == pytest.approx(res["r_cover"], rel=1e-12)
    # the same choice from a distance matrix
    idx_d, radius_d = greedy_landmarks(squareform(pdist(x)), 150, distance_matrix=True)
    np.testing.assert_array_equal(idx_d, idx)
    assert radius_d == pytest.approx(radius, rel=1e-12)
    # every point is within the covering radius of a landmark, and one is exactly at it
    nearest = np.min(np.linalg.norm(x[:, None, :] - x[idx][None, :, :], axis=2), axis=1)
    assert nearest.max() == pytest.approx(radius, rel=1e-12)
    full, r0 = greedy_landmarks(x[:20], 20)
    assert sorted(full) == list(range(20)) and r0 == 0.0
    # one landmark: the start, covering every point at its farthest distance
    one, r1 = greedy_landmarks(x[:20], 1, start=7)
    assert one.tolist() == [7]
    assert r1 == pytest.approx(np.linalg.norm(x[:20] - x[7], axis=1).max(), rel=1e-12)
    for bad in (0, len(x) + 1, 2.5, True):
        with pytest.raises(ParameterError):
            greedy_landmarks(x, bad)


def test_winding_birth_follows_the_class_past_a_loop_of_noise():
    """A small loop elsewhere closes first, but the coordinate does not wind around it."""
    from cyclecoord.periodic.barcode import refine_birth, winding_birth

    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0, 1, 300))
    circle = np.c_[np.cos(2 * np.pi * t), np.sin(2 * np.pi * t)]
    gaps = np.diff(np.r_[t, t[0] + 1])
    born = 2 * np.sin(np.pi * gaps.max())  # the circle's loop closes across its widest gap
    # a small ring (radius 0.2, 40 points) beside it: born at its spacing, alive until
    # about its radius times sqrt(3), beyond the big circle's birth
    s = np.arange(40) / 40
    ring = 0.2 * np.c_[np.cos(2 * np.pi * s), np.sin(2 * np.pi * s)] + [3.0, 3.0]
    x = np.vstack([circle, ring])
    theta = np.r_[t, np.zeros(len(ring))]
    assert born > 0.1
    # the bars alone (no coordinate) take the ring, alive at that scale and born first
    assert refine_birth(x, born * 1.01) == pytest.approx(0.4 * np.sin(np.pi / 40), rel=1e-6)
    assert refine_birth(x, born * 1.01, coordinate=theta) == pytest.approx(born, rel=1e-9)
    pairs = np.array([[i, (i + 1) % 300] for i in range(300)])
    lengths = np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=1)
    assert winding_birth(pairs, lengths, theta) == pytest.approx(born, rel=1e-9)
    assert winding_birth(pairs[:-1], lengths[:-1], theta) is None  # an open chain never winds


def test_full_birth_follows_the_selected_class_on_joined_walks(cmu_dir):
    """Issue 12's case: landmarks on ~900 frames of walking in 3 PCA dimensions; the
    bars of the sparse full complex alone gave 2.73 (a loop of noise) for a bar born at
    3.59 on every frame."""
    import cyclecoord as cc

    a, b = (cc.load(cmu_dir / "35" / f"35_{k}.amc") for k in ("08", "13"))
    joined = a.with_frames(np.vstack([a.frames, b.frames]))
    full = cc.extract(joined, pca=3, landmarks=None, steady=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        lm = cc.extract(joined, pca=3, landmarks=500, steady=False)
    # landmarks are born later: 1.098x with rotation vectors (3.826 against 3.484), 1.1x+ in Euler
    assert lm.selection.birth > 1.05 * full.selection.birth
    assert lm.selection.full_birth == pytest.approx(full.selection.birth, rel=1e-5)


def test_a_capture_that_loops_exactly_gets_one_landmark_per_pose():
    """30 poses played over 400 frames (a keyframed clip looped): the greedy choice stops
    at the 30 distinct poses instead of repeating them (repeated landmarks tied the
    coordinate's least squares in knots: it turned 0.01 times over 13 strides)."""
    from cyclecoord.periodic.landmarks import greedy_landmarks

    t = np.arange(400) % 30 * (2 * np.pi / 30)
    x = np.column_stack([np.cos(t), np.sin(t), 0.3 * np.cos(2 * t)]) * 20.0 + 100.0
    idx, radius = greedy_landmarks(x, 150)
    assert len(idx) == 30 and radius == 0.0
    assert len(np.unique(x[idx].round(9), axis=0)) == 30
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    idx_d, radius_d = greedy_landmarks(d, 150, distance_matrix=True)
    assert len(idx_d) == 30 and radius_d == 0.0
    idx, _ = greedy_landmarks(x + np.random.default_rng(0).normal(0, 1e-3, x.shape), 150)
    assert len(idx) == 150  # poses that differ are all candidates


def test_memory_guard_estimate_is_estimate_complex_of_what_it_chose():
    """choose_landmarks's estimate is documented as the one estimate_complex gives for the
    landmarks it chose (the same sample: n_samples and random_state at their defaults),
    and the guard shrinks the landmarks until that estimate fits the budget."""
    x = np.random.default_rng(2).standard_normal((3000, 3))
    full = estimate_complex(x, 1.0)  # every point
    limit = estimate_complex(x, 1.0, n_vertices=AUTO_LANDMARKS).bytes / 3
    n, est, reason = choose_landmarks(x, 1.0, landmarks=None, memory_limit=limit)
    assert n is not None and 50 < n < AUTO_LANDMARKS and "memory guard" in reason
    assert est == estimate_complex(x, 1.0, n_vertices=n)
    assert est.bytes <= limit
    # the same sample for any vertex count: the edge fraction is the full complex's
    assert est.edges / (n * (n - 1) / 2) == pytest.approx(full.edges / (3000 * 2999 / 2), rel=1e-12)


def test_estimate_complex_known_answers():
    """Points whose pairs all lie exactly at the threshold (a simplex: e_i + 0.5, every
    pair sqrt(2) apart) are all linked ("within" includes the threshold): every pair is an
    edge and every triple a triangle, whatever the sample.  Memory: the dense distance
    matrix and the edge columns."""
    from math import comb

    from cyclecoord.periodic._rips import DENSE_BYTES_PER_PAIR
    from cyclecoord.periodic.landmarks import _BYTES_PER_EDGE, ComplexEstimate

    x = np.eye(6) + 0.5
    thr = float(np.linalg.norm(x[0] - x[1]))
    est = estimate_complex(x, thr)
    assert est == ComplexEstimate(6, comb(6, 2), comb(6, 3),
                                  DENSE_BYTES_PER_PAIR * 36.0 + _BYTES_PER_EDGE * comb(6, 2))
    four = estimate_complex(x, thr, n_vertices=4)  # the same fractions on 4 vertices
    assert (four.n_points, four.edges, four.triangles) == (4, 6, 4)
    assert estimate_complex(x, 0.99 * thr).edges == 0.0
    # one point far from two close ones: a third of the pairs is an edge, no triangle (the
    # sample draws every point alike)
    three = np.array([[0.0, 0.0], [0.0, 1.0], [50.0, 0.0]])
    est = estimate_complex(three, 2.0)
    assert est.edges == pytest.approx(1.0, rel=0.05) and est.triangles == 0.0
    none = estimate_complex(three, 2.0, n_samples=0)  # no sample, nothing seen
    assert none.edges == 0.0 and none.triangles == 0.0
    # too few points for a triangle: nothing estimated
    assert estimate_complex(three[:2], 2.0) == ComplexEstimate(2, 0.0, 0.0, 0.0)


def test_memory_guard_at_the_edge_of_the_budget():
    """The complete complex is left alone when its distance matrix and every possible edge
    fit the budget exactly; a byte less and the guard estimates it; three points whose
    edges do not fit cannot be thinned further (at least 50 landmarks would be needed)."""
    from math import comb

    from cyclecoord.periodic._rips import DENSE_BYTES_PER_PAIR
    from cyclecoord.periodic.landmarks import _BYTES_PER_EDGE

    x = np.random.default_rng(3).standard_normal((300, 3))
    complete = DENSE_BYTES_PER_PAIR * 300.0 * 300 + _BYTES_PER_EDGE * comb(300, 2)
    assert choose_landmarks(x, 0.5, landmarks=None, memory_limit=complete) == (
        None, None, "every frame (landmarks off)")
    n, est, _ = choose_landmarks(x, 0.5, landmarks=None, memory_limit=complete - 1)
    assert n is None and est == estimate_complex(x, 0.5)  # the sampled estimate fits
    three = np.eye(3) + 0.5  # every pair linked at the threshold: 3 edges
    thr = float(np.linalg.norm(three[0] - three[1]))
    with pytest.raises(cc.ParameterError, match="even 3 landmarks need"):
        choose_landmarks(three, thr, landmarks=None, memory_limit=DENSE_BYTES_PER_PAIR * 9.0 + 1)
    # two points: nothing estimated, as estimate_complex says
    two = three[:2]
    assert choose_landmarks(two, thr, landmarks=None, memory_limit=1.0)[1] == estimate_complex(two, thr)


def test_summary_period_is_frame_steps_per_cycle():
    """101 frames winding 4 times: 100 steps over 4 cycles, a period of 25 frames."""
    model = object.__new__(PhaseModel)
    model.phase = lambda motion: (np.arange(101) / 25.0) % 1.0
    s = model.summary(None)
    assert s["cycles"] == pytest.approx(4.0) and s["period_frames"] == pytest.approx(25.0)


def test_run_bytes_counts_float64_words_per_frame():
    """Past the EM's 20,000 values, a frame of K=10 points and D=12 channels adds
    8 bytes x (3 copies x 12 values + 16 words) = 416 bytes."""
    from cyclecoord.periodic.landmarks import run_bytes

    assert run_bytes(30_001, 10, 12) - run_bytes(30_000, 10, 12) == pytest.approx(416.0)
    assert run_bytes(30_001, 12) - run_bytes(30_000, 12) == pytest.approx(416.0)
