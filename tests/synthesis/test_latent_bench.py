"""benchmarks/bench_latent.py: its measures on synthetic data (never speed)."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

import cyclecoord as cc
from cyclecoord.synthesis.latent import LatentModel

BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_latent.py"


def _bench():
    spec = importlib.util.spec_from_file_location("bench_latent", BENCH)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_latent"] = module
    spec.loader.exec_module(module)
    return module


bench = _bench()


def test_coverage_counts_frames_with_a_start_within_a_second():
    walk = cc.datasets.make_periodic_capture(kind="walk", n_frames=480, random_state=0).motion
    m = LatentModel(gplvm={"max_iter": 10}).fit([walk[:240:4], walk[240::4]], ["a", "b"])
    # 60 frames per segment at 30 fps; one start at frame 40 of segment a
    cov = bench.coverage_play(m, np.array([40]))
    assert cov == (31 / 120)  # frames 10..40 reach it within 30 frames
    assert bench.coverage_play(m, np.array([], int)) == 0.0


def test_derivatives_and_skating():
    t = np.arange(60) / 30.0
    local = np.zeros((60, 2, 3))
    local[:, 1, 0] = 0.5 * 9.0 * t**2  # constant acceleration 9 units/s^2
    acc, jerk = bench.derivatives(local, 30.0)
    np.testing.assert_allclose(acc, 9.0, rtol=1e-9)
    np.testing.assert_allclose(jerk, 0.0, atol=1e-6)
    walk = cc.datasets.make_periodic_capture(kind="walk", n_frames=240, random_state=0).motion
    low_everywhere = bench.foot_skating(walk, low=1e9)
    assert low_everywhere > 0
    assert bench.foot_skating(walk, low=-1e9) == 0.0
