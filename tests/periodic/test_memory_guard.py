"""The memory guard trusts no limit, and a stated limit covers the whole run."""

import tracemalloc
import warnings

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from cyclecoord.periodic import landmarks as lm
from cyclecoord.periodic.coordinates import CircularCoordinates


@pytest.fixture(scope="module")
def walk3000():
    return cc.datasets.make_periodic_capture(n_frames=3000, noise=0.5, random_state=0).motion


def test_machine_memory_is_a_positive_number_below_physical_memory():
    m = lm.machine_memory()
    assert 0 < m < float("inf")
    import os

    assert m <= os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def test_a_limit_beyond_the_machine_does_not_build_a_matrix_that_cannot_fit(monkeypatch):
    monkeypatch.setattr(lm, "machine_memory", lambda: 80e6)  # an 80 MB machine
    t = np.linspace(0, 2 * np.pi, 3000, endpoint=False)
    x = np.column_stack([np.cos(t), np.sin(t)])
    est = CircularCoordinates(landmarks=None, memory_limit=1e15, max_scale=0.3)  # "1000T"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est.fit_barcode(x)
    # the full complex (3000^2 distances, ~117 MB) was never attempted
    assert est.landmarks_ is not None and est.complex_estimate_.bytes < 80e6
    assert "memory guard" in est.landmark_reason_
    assert est.memory_budget_ <= 80e6 - lm.run_bytes(3000, 2)


def test_per_frame_arrays_beyond_the_machine_are_refused_in_one_line(monkeypatch):
    monkeypatch.setattr(lm, "machine_memory", lambda: 30e6)
    x = np.zeros((200_000, 3))
    with pytest.raises(ParameterError, match=r"not enough memory: .*200000 frames of 3 dimensions.*machine allows"):
        CircularCoordinates(memory_limit=1e15).fit_barcode(x)


def test_temporal_matrix_beyond_the_machine_is_refused(monkeypatch):
    monkeypatch.setattr(lm, "machine_memory", lambda: 60e6)
    x = np.random.default_rng(0).normal(size=(3000, 3))
    with pytest.raises(ParameterError, match="temporal metric needs a full 3000 x 3000"):
        CircularCoordinates(temporal=True, memory_limit=1e15).fit_barcode(x)


def test_a_limit_smaller_than_the_per_frame_arrays_is_refused(walk3000):
    with pytest.raises(ParameterError, match="memory limit 0.01 GB is too small"):
        cc.extract(walk3000, memory_limit=1e7)
    with pytest.raises(ParameterError, match="positive number of bytes"):
        cc.extract(walk3000, memory_limit=float("inf"))


def _peak(motion, **kw):
    tracemalloc.start()
    try:
        res = cc.extract(motion, **kw)
        return tracemalloc.get_traced_memory()[1], res
    finally:
        tracemalloc.stop()


def test_a_stated_limit_covers_the_whole_run():
    """Every array the run allocates (tracemalloc sees numpy's) stays within the limit;
    without it the birth refinement's sparse complex alone goes past it."""
    walk = cc.datasets.make_periodic_capture(n_frames=2000, noise=0.5, random_state=0).motion
    free, res_free = _peak(walk)
    limit = 60e6
    assert free > limit  # the limit binds
    peak, res = _peak(walk, memory_limit=limit)
    assert peak <= limit
    assert len(res.estimator.landmarks_) == len(res_free.estimator.landmarks_)
    np.testing.assert_array_equal(res.coordinate, res_free.coordinate)


@pytest.mark.parametrize("seed", [0, 1])
def test_projected_screening_picks_the_same_landmarks(seed):
    """Above 50,000 points each greedy step measures only points the projection cannot
    rule out; the landmarks and covering radius are those of the full pass."""
    rng = np.random.default_rng(seed)
    t = rng.random(60_000) * 6 * np.pi
    x = np.zeros((60_000, 20))
    x[:, 0], x[:, 1], x[:, 2] = 10 * np.cos(t), 10 * np.sin(t), 3 * np.cos(2 * t)
    x += rng.normal(0, 0.5, x.shape)
    sq = np.einsum("ij,ij->i", x, x)
    idx, nearest, i = [], np.full(len(x), np.inf), 0
    for _ in range(150):  # the plain algorithm: one full pass a step
        idx.append(i)
        np.minimum(nearest, sq + sq[i] - 2.0 * (x @ x[i]), out=nearest)
        nearest[i] = 0.0
        i = int(np.argmax(nearest))
    radius = float(np.linalg.norm(x[i] - x[idx], axis=1).min())
    got, got_radius = lm.greedy_landmarks(x, 150)
    np.testing.assert_array_equal(got, idx)
    assert got_radius == radius
