"""periodic.landmarks by hand: greedy max-min landmarks on points on a line and a grid, the
memory budget's arithmetic on a machine of known size, the guard's shrinking sequence."""

from math import comb

import numpy as np
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.periodic import landmarks as lm
from cyclecoord.periodic._rips import DENSE_BYTES_PER_PAIR
from cyclecoord.periodic.landmarks import (
    ComplexEstimate,
    choose_landmarks,
    greedy_landmarks,
    memory_budget,
    run_bytes,
)

LINE = np.array([0.0, 1.0, 3.0, 7.0, 15.0])[:, None]


def dmat(x):
    return np.abs(x - x.T) if x.shape[1] == 1 else np.linalg.norm(x[:, None] - x[None], axis=2)


@pytest.mark.parametrize("matrix", [False, True])
def test_greedy_landmarks_on_a_line_by_hand(matrix):
    """0, 1, 3, 7, 15 from 0: 15 (farthest), then 7 (7 from 0, 8 from 15), then 3 (3 from
    0, 4 from 7), then 1; covering radius 7, 3, 1, then 0 with every point."""
    x = dmat(LINE) if matrix else LINE
    want = [0, 4, 3, 2, 1]
    for n, r in ((1, 15.0), (2, 7.0), (3, 3.0), (4, 1.0), (5, 0.0)):
        idx, radius = greedy_landmarks(x, n, distance_matrix=matrix)
        assert idx.tolist() == want[:n] and radius == r
    # from the far end: 0 (15 away), then 7 (7 from 0, 8 from 15), then 3, then 1 (1 from 0, 2 from 3)
    idx, radius = greedy_landmarks(x, 4, start=4, distance_matrix=matrix)
    assert idx.tolist() == [4, 0, 3, 2] and radius == 1.0
    # from 7: 15 is 8 away, then 0 (7 from 7), leaving 3 three from 0 (and 4 from 7)
    idx, radius = greedy_landmarks(x, 3, start=3, distance_matrix=matrix)
    assert idx.tolist() == [3, 4, 0] and radius == 3.0


def test_greedy_landmarks_on_a_grid_ties_go_to_the_first_point():
    """A 3x3 grid of spacing 1 from the centre (4): the four corners are all sqrt(2) away
    and the first, 0, wins; the other corners are still sqrt(2) from the centre, and 2
    then 6 win their ties by coming first; 8 is left sqrt(2) from the centre."""
    g = np.array([[i, j] for i in range(3) for j in range(3)], dtype=float)
    idx, radius = greedy_landmarks(g, 4, start=4)
    assert idx.tolist() == [4, 0, 2, 6]
    assert radius == pytest.approx(np.sqrt(2.0), rel=1e-15)
    idx, radius = greedy_landmarks(g, 5, start=4)
    assert idx.tolist() == [4, 0, 2, 6, 8] and radius == pytest.approx(1.0, rel=1e-15)
    nearest = np.min(np.linalg.norm(g[:, None] - g[idx][None], axis=2), axis=1)
    assert radius == pytest.approx(nearest.max())


def test_greedy_landmarks_stop_at_the_distinct_points():
    """0, 0, 5, 5: two distinct points; asked for 4 the choice stops at 2 (radius 0);
    asked for exactly 2 it gives them with radius 0; asked for 1 the radius is 5."""
    x = np.array([[0.0], [0.0], [5.0], [5.0]])
    for matrix in (False, True):
        pts = dmat(x) if matrix else x
        assert greedy_landmarks(pts, 4, distance_matrix=matrix)[0].tolist() == [0, 2]
        assert greedy_landmarks(pts, 4, distance_matrix=matrix)[1] == 0.0
        assert greedy_landmarks(pts, 3, distance_matrix=matrix)[0].tolist() == [0, 2]
        idx, r = greedy_landmarks(pts, 2, distance_matrix=matrix)
        assert idx.tolist() == [0, 2] and r == 0.0
        idx, r = greedy_landmarks(pts, 1, distance_matrix=matrix)
        assert idx.tolist() == [0] and r == 5.0
    # a single point: one landmark, nothing left to cover
    idx, r = greedy_landmarks(np.array([[3.0, 4.0]]), 1)
    assert idx.tolist() == [0] and r == 0.0


def test_greedy_landmarks_refuse_bad_arguments():
    with pytest.raises(ParameterError, match="distance matrix"):
        greedy_landmarks(np.zeros((3, 4)), 2, distance_matrix=True)
    with pytest.raises(ParameterError):
        greedy_landmarks(np.zeros(5), 2)
    for start in (-1, 5):
        with pytest.raises(ParameterError, match="start"):
            greedy_landmarks(LINE, 2, start=start)
    assert greedy_landmarks(LINE, 2, start=4)[0].tolist() == [4, 0]
    assert greedy_landmarks(LINE, 5.0)[0].size == 5  # a whole float is a count


def _brute_greedy(x, n):
    chosen = [0]
    nearest = np.linalg.norm(x - x[0], axis=1)
    for _ in range(n - 1):
        i = int(np.argmax(nearest))
        chosen.append(i)
        nearest = np.minimum(nearest, np.linalg.norm(x - x[i], axis=1))
    return chosen, float(nearest.max())


def test_projected_screening_gives_the_full_passs_landmarks(monkeypatch):
    """From 50,000 points of more than 4 dimensions each step is screened by a projection
    (documented): the landmarks are the plain greedy ones, and the projection is used
    exactly there."""
    calls = []
    real = lm._projection
    monkeypatch.setattr(lm, "_projection", lambda x, *a, **k: calls.append(x.shape) or real(x, *a, **k))
    rng = np.random.default_rng(5)
    x = rng.standard_normal((50_000, 5)) * [5.0, 3.0, 2.0, 1.0, 0.5]
    idx, radius = greedy_landmarks(x, 12)
    want, r = _brute_greedy(x, 12)
    assert idx.tolist() == want and radius == pytest.approx(r, rel=1e-12)
    assert calls == [(50_000, 5)]
    calls.clear()
    greedy_landmarks(x[:49_999], 3)
    greedy_landmarks(x[:, :4], 3)
    greedy_landmarks(dmat(x[:300]), 3, distance_matrix=True)
    assert calls == []


def test_projection_is_a_lower_bound_of_distances():
    rng = np.random.default_rng(1)
    x = rng.standard_normal((400, 7)) * np.arange(1, 8)
    p = lm._projection(x, block=64)  # blocks of 64 rows: the same as one product
    assert p.shape == (400, 4)
    np.testing.assert_allclose(p, lm._projection(x), atol=1e-12)
    d_full = np.linalg.norm(x[:, None] - x[None], axis=2)
    d_proj = np.linalg.norm(p[:, None] - p[None], axis=2)
    assert np.all(d_proj <= d_full + 1e-9)
    # the first principal directions: the projection keeps the large spread
    assert np.var(p, axis=0).sum() > 0.8 * np.var(x, axis=0).sum()


# ------------------------------------------------------------------ memory


def test_run_bytes_by_hand():
    em = 8 * 3 * 30 * 3
    assert run_bytes(100, 10) == 8.0 * (3 * 10 + 16) * 100 + em * 100 + 40 * 1024**2
    assert run_bytes(100, 10, 25) == 8.0 * (3 * 25 + 16) * 100 + em * 100 + 40 * 1024**2
    assert run_bytes(100, 25, 10) == run_bytes(100, 25)  # max(K, D)
    # the EM's part stops growing at 20,000 frames
    assert run_bytes(50_000, 1) == 8.0 * 19 * 50_000 + em * 20_000 + 40 * 1024**2
    assert run_bytes(0, 3) == 40 * 1024**2


def test_memory_budget_by_hand(monkeypatch):
    GiB = 1024**3
    monkeypatch.setattr(lm, "machine_memory", lambda: 10.0 * GiB)
    # no stated limit: the default 2 GiB for the filtration, within what is left
    b, note = memory_budget(None, 1.0 * GiB)
    assert b == 2.0 * GiB and note == "2.15 GB for the filtration"
    b, note = memory_budget(None, 9.0 * GiB)
    assert b == 1.0 * GiB and "what the machine's 10.74 GB leaves" in note
    b, note = memory_budget(None, 8.0 * GiB)  # exactly the default left: no remark
    assert b == 2.0 * GiB and "leaves" not in note
    # a stated limit covers the per-frame arrays too
    b, note = memory_budget(5.0 * GiB, 1.0 * GiB)
    assert b == 4.0 * GiB and "limit less" in note and "exceeds" not in note
    b, note = memory_budget(10.0 * GiB, 1.0 * GiB)  # the whole machine: not over it
    assert b == 9.0 * GiB and "exceeds" not in note
    b, note = memory_budget(20.0 * GiB, 1.0 * GiB)  # more than the machine has
    assert b == 9.0 * GiB and "exceeds the machine's 10.74 GB" in note
    # a limit of one byte is a positive limit: nothing else is reserved
    assert memory_budget(1.0, 0.0)[0] == 1.0
    assert memory_budget(0.5, 0.0)[0] == 0.5
    for bad in (0, 0.0, -1.0, float("nan"), float("inf"), True):
        with pytest.raises(ParameterError, match="positive number"):
            memory_budget(bad, 0.0)
    with pytest.raises(ParameterError, match="too small.*7 frames"):
        memory_budget(1.0 * GiB, 1.0 * GiB, "7 frames")
    with pytest.raises(ParameterError, match="too small"):
        memory_budget(1.0 * GiB, 2.0 * GiB)
    with pytest.raises(ParameterError, match=r"not enough memory.*\(7 frames\)"):
        memory_budget(None, 10.0 * GiB, "7 frames")
    with pytest.raises(ParameterError, match="not enough memory: the run's per-frame arrays need"):
        memory_budget(20.0 * GiB, 11.0 * GiB)


def test_complex_estimate_to_dict():
    d = ComplexEstimate(7, 3, 2, 11).to_dict()
    assert d == {"n_points": 7, "edges": 3.0, "triangles": 2.0, "bytes": 11.0}
    assert all(type(d[k]) is float for k in ("edges", "triangles", "bytes"))


# ------------------------------------------------------------------ choose_landmarks


def complete_bytes(m):
    return DENSE_BYTES_PER_PAIR * float(m) * m + 64 * comb(m, 2)


def test_choose_landmarks_decisions_by_hand():
    big = 1e18
    x1000, x1001 = np.zeros((1000, 2)), np.zeros((1001, 2))
    assert choose_landmarks(x1000, 1.0, memory_limit=big) == (None, None, "every frame (1000 <= 1000)")
    n, est, reason = choose_landmarks(x1001, 1.0, "AUTO", memory_limit=big)
    assert (n, est) == (500, None) and reason == "500 greedy landmarks of 1001 frames (automatic)"
    for off in (None, "none", "All", "FULL"):
        assert choose_landmarks(x1001, 1.0, off, memory_limit=big)[:2] == (None, None)
    assert choose_landmarks(x1001, 1.0, 10, memory_limit=big)[0] == 10
    assert choose_landmarks(x1001, 1.0, 25.0, memory_limit=big)[:2] == (25, None)
    assert choose_landmarks(x1001, 1.0, 1000, memory_limit=big)[0] == 1000
    n, _, reason = choose_landmarks(x1001, 1.0, 1001, memory_limit=big)
    assert n is None and reason == "every frame (1001 landmarks requested, 1001 frames)"
    with pytest.raises(ParameterError, match="at least 10"):
        choose_landmarks(x1001, 1.0, 9, memory_limit=big)
    for bad in ("some", "25", [3]):
        with pytest.raises(ParameterError, match="landmarks must be"):
            choose_landmarks(x1001, 1.0, bad, memory_limit=big)
    for bad in (None, 0, -5.0, float("nan")):
        with pytest.raises(ParameterError, match="memory budget"):
            choose_landmarks(x1001, 1.0, memory_limit=bad)


def test_the_guard_shrinks_by_seven_tenths_until_it_fits():
    """Every pair within the threshold (all points at one place): the estimate is the
    complete complex, so the sizes are known: int(0.7 m) from 500 is 350, 244 (0.7 x 350
    rounds below 245), 170, 118, 82, 57, then 50; a budget of the 244-landmark complex less
    a byte gives 170."""
    x = np.zeros((1200, 2))
    limit = complete_bytes(244) - 1
    n, est, reason = choose_landmarks(x, 1.0, memory_limit=limit)
    assert n == 170 and est == ComplexEstimate(170, comb(170, 2), comb(170, 3), complete_bytes(170))
    assert "using 170 greedy landmarks" in reason and "complex on 500 points" in reason
    # exactly the 244 complex fits
    assert choose_landmarks(x, 1.0, memory_limit=complete_bytes(244))[0] == 244
    # landmarks off on 600 frames: 600 does not fit, 500 does
    n, est, reason = choose_landmarks(x[:600], 1.0, None, memory_limit=complete_bytes(500))
    assert n == 500 and est.n_points == 500 and "complex on 600 points" in reason
    # below 50 it stops at 50 and refuses if that does not fit
    assert choose_landmarks(x, 1.0, memory_limit=complete_bytes(50))[0] == 50
    assert choose_landmarks(x, 1.0, memory_limit=complete_bytes(57))[0] == 57
    with pytest.raises(ParameterError, match="even 50 landmarks"):
        choose_landmarks(x, 1.0, memory_limit=complete_bytes(50) - 1)
    # 80 frames, landmarks off, a budget for 56: 80 -> 56, fewer than the frames
    n, est, _ = choose_landmarks(x[:80], 1.0, None, memory_limit=complete_bytes(56))
    assert n == 56


def test_what_counts_as_a_repeated_point():
    """Points: a squared distance within 1e-12 of the largest squared norm repeats a
    landmark (the product form's rounding); a distance matrix: within 1e-9 of its largest
    entry.  Points 1000 apart in scale: 1.2e-3 apart (squared 1.44e-6, over 1e-6) are two
    landmarks, 0.9e-3 apart (0.81e-6) one."""
    for gap, n in ((1.2e-3, 2), (0.9e-3, 1)):
        x = np.array([[1000.0], [1000.0 + gap], [1000.0]])
        assert len(greedy_landmarks(x, 3)[0]) == n
    for gap, n in ((1.5e-9, 2), (0.5e-9, 1)):
        d = np.array([[0.0, gap, 1.0], [gap, 0.0, 1.0], [1.0, 1.0, 0.0]])
        idx, r = greedy_landmarks(d, 3, distance_matrix=True)
        assert len(idx) == n + 1 and r == 0.0


def test_projected_screening_keeps_points_on_the_far_side_of_the_origin():
    """50,000 points on a line (in 5 dimensions): 49,997 at 2.232, one each at -1, 0.5 and
    3.832.  From 2.232 the farthest is -1 (3.232 away).  Then 0.5 is 1.5 from -1, nearer
    than the 1.732 to its first landmark, although its projection points away from -1's
    (a negative product); 3.832 stays 1.6 from its nearest, the farthest: it is the third
    landmark, and 0.5 is left 1.5 from -1."""
    x = np.zeros((50_000, 5))
    x[:, 0] = 2.232
    x[1, 0], x[2, 0], x[3, 0] = -1.0, 0.5, 3.832
    idx, radius = greedy_landmarks(x, 3)
    assert idx.tolist() == [0, 1, 3] and radius == pytest.approx(1.5, rel=1e-12)
    idx, radius = greedy_landmarks(x, 6)
    assert idx.tolist() == [0, 1, 3, 2] and radius == 0.0


def test_a_sampled_estimate_exactly_at_the_budget_fits():
    """The guard steps in only when the estimate exceeds the budget: at exactly the
    sampled estimate every frame is kept, with the estimate and the plain reason."""
    from cyclecoord.periodic.landmarks import estimate_complex

    x = np.random.default_rng(3).standard_normal((300, 3))
    est = estimate_complex(x, 0.5)
    assert est.edges < comb(300, 2)  # not every pair: the estimate is below the complete complex's
    assert choose_landmarks(x, 0.5, None, memory_limit=est.bytes) == (None, est, "every frame (landmarks off)")
