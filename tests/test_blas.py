"""The pipeline runs its linear algebra on one BLAS thread and restores the setting."""

import numpy as np
import pytest

threadpoolctl = pytest.importorskip("threadpoolctl")

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
