"""The pipeline runs its linear algebra on one BLAS thread and restores the setting."""

import numpy as np

import threadpoolctl

import cyclecoord as cc
from cyclecoord._blas import one_blas_thread


def blas_threads():
    return [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]


def test_decorated_call_sees_one_thread_and_the_setting_comes_back():
    np.ones((2, 2)) @ np.ones((2, 2))  # make sure a BLAS is loaded
    before = blas_threads()
    assert before, "numpy's BLAS was not found by threadpoolctl"

    @one_blas_thread
    def inside():
        return blas_threads()

    assert set(inside()) == {1}
    assert blas_threads() == before


def test_harmonic_solve_inside_extract_runs_on_one_thread(monkeypatch):
    import cyclecoord.periodic.coordinates as coords

    seen = []
    real = coords.harmonic_coordinate

    def spy(*args, **kwargs):
        seen.append(blas_threads())
        return real(*args, **kwargs)

    monkeypatch.setattr(coords, "harmonic_coordinate", spy)
    cap = cc.datasets.make_periodic_capture(n_frames=300, noise=0.5, random_state=0)
    cc.extract(cap.motion)
    assert seen and all(set(s) == {1} for s in seen)


def test_every_stage_of_extract_runs_on_one_thread(monkeypatch):
    """Each stage, as extract calls it (before any inner decorator), sees the limit."""
    import cyclecoord.periodic.fitting as fitting
    import cyclecoord.periodic.pipeline as pipe

    seen: dict[str, list] = {}

    def spy(name, real):
        def wrapped(*args, **kwargs):
            seen.setdefault(name, []).append(blas_threads())
            return real(*args, **kwargs)

        return wrapped

    for name in ("capture_cycle", "retime", "complete_windings", "jerk_summary", "loop_closure",
                 "distance_to_cycle", "unwrap"):
        for module in (pipe, fitting):  # the fitting steps live in periodic.fitting
            if hasattr(module, name):
                monkeypatch.setattr(module, name, spy(name, getattr(module, name)))

    class Prep(pipe.Preprocessor):
        def fit_transform(self, motion):
            seen.setdefault("prepare", []).append(blas_threads())
            return super().fit_transform(motion)

    class Coords(pipe.CircularCoordinates):
        def fit_barcode(self, X):
            seen.setdefault("barcode", []).append(blas_threads())
            return super().fit_barcode(X)

        def fit_coordinate(self):
            seen.setdefault("coordinate", []).append(blas_threads())
            return super().fit_coordinate()

    class Density(pipe.PeriodicDensity):
        def fit(self, theta):
            seen.setdefault("density", []).append(blas_threads())
            return super().fit(theta)

    monkeypatch.setattr(fitting, "Preprocessor", Prep)
    monkeypatch.setattr(fitting, "CircularCoordinates", Coords)
    monkeypatch.setattr(pipe, "PeriodicDensity", Density)
    before = blas_threads()
    cap = cc.datasets.make_periodic_capture(n_frames=300, noise=0.5, random_state=0)
    cc.extract(cap.motion)
    stages = {"prepare", "barcode", "coordinate", "density", "capture_cycle", "retime", "complete_windings",
              "jerk_summary", "loop_closure", "distance_to_cycle", "unwrap"}
    assert set(seen) == stages
    for name, calls in seen.items():
        assert all(set(s) == {1} for s in calls), f"stage {name} ran with BLAS threads {calls}"
    assert blas_threads() == before


def test_nested_decorated_calls_keep_the_limit_and_restore_it():
    np.ones((2, 2)) @ np.ones((2, 2))
    before = blas_threads()

    @one_blas_thread
    def inner():
        return blas_threads()

    @one_blas_thread
    def outer():
        return inner(), blas_threads()

    got_inner, got_outer = outer()
    assert set(got_inner) == {1} and set(got_outer) == {1}
    assert blas_threads() == before
    assert set(inner()) == {1}  # a call on its own still sets the limit
    assert blas_threads() == before
