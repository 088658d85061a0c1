"""Tests of benchmarks/bench_extract.py: result structure and agreement measures (never speed)."""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from cyclecoord.errors import ParameterError

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_extract.py"


def _load_bench():
    spec = importlib.util.spec_from_file_location("bench_extract", BENCH)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_extract"] = module  # dataclasses need the module registered
    spec.loader.exec_module(module)
    return module


bench = _load_bench()
HAVE_DREIMAC = bench.dreimac_status()[0]


# ----------------------------------------------------------------- agreement measures
def test_circular_agreement_sees_rotation_and_reflection():
    rng = np.random.default_rng(1)
    a = rng.random(300)
    rotated = np.mod(a + 0.37, 1.0)
    same = bench.circular_agreement(a, rotated)
    assert same["correlation"] == pytest.approx(1.0)
    assert same["median_difference"] == pytest.approx(0.0, abs=1e-12)
    assert not same["reflected"]
    mirrored = bench.circular_agreement(a, np.mod(0.2 - a, 1.0))
    assert mirrored["reflected"]
    assert mirrored["correlation"] == pytest.approx(1.0)
    unrelated = bench.circular_agreement(a, rng.random(300))
    assert unrelated["correlation"] < 0.25
    assert unrelated["median_difference"] > 0.15
    with pytest.raises(ParameterError):
        bench.circular_agreement(a, a[:10])


def test_phase_agreement_of_truth_and_of_noise():
    phase = np.linspace(0.0, 4.0, 481)  # 4 cycles, 120 frames each
    perfect = bench.phase_agreement(np.mod(phase, 1.0), phase)
    assert perfect["bins_advancing"] == 1.0
    assert perfect["cycles"] == pytest.approx(4.0)
    assert perfect["cycles_true"] == pytest.approx(4.0)
    assert perfect["mean_abs_error"] == pytest.approx(0.0, abs=1e-9)
    # a reflected coordinate is oriented with time first, so it counts the same
    backwards = bench.phase_agreement(np.mod(0.3 - phase, 1.0), phase)
    assert backwards["bins_advancing"] == 1.0
    assert backwards["cycles"] == pytest.approx(4.0)
    noise = bench.phase_agreement(np.random.default_rng(2).random(481), phase)
    assert noise["bins_advancing"] < 0.8
    assert abs(noise["cycles"] - 4.0) > 1.0


# ------------------------------------------------------------------------ case choice
def test_quick_selection_without_data(tmp_path):
    cases, skipped = bench.select_cases(quick=True, data_dir=tmp_path, synthetic_sizes=(500, 1000))
    assert [c.motion.n_frames for c in cases] == [500]
    assert cases[0].true_phase is not None and cases[0].max_scale is None
    assert any("69_01" in s and "skipped" in s for s in skipped)
    full, _ = bench.select_cases(quick=False, data_dir=tmp_path, synthetic_sizes=(300, 400))
    assert [c.motion.n_frames for c in full] == [300, 400]


def test_quick_selection_with_data():
    if not (bench.DATA_DIR / "cmu" / "69" / "69_01.amc").is_file():
        pytest.skip(f"real CMU captures not found under {bench.DATA_DIR}")
    cases, skipped = bench.select_cases(quick=True)
    assert len(cases) == 1 and skipped == []
    assert cases[0].frames == (200, 450) and cases[0].max_scale == 50.0
    assert cases[0].paper_seconds == pytest.approx(25.78)


def test_missing_dreimac_is_reported_not_raised(monkeypatch):
    monkeypatch.setattr(bench, "dreimac_status", lambda: (False, "ModuleNotFoundError: no dreimac"))
    out = bench.time_dreimac(np.random.default_rng(0).random((20, 3)), repeat=1)
    assert set(out) == {"skipped"}
    assert 'pip install -e ".[bench]"' in out["skipped"]


# ---------------------------------------------------------------- a tiny real run
@pytest.fixture(scope="module")
def tiny_report():
    case = bench.synthetic_case(200, seed=0)
    return bench.run_benchmark([case], repeat=1, with_dreimac=HAVE_DREIMAC, progress=False)


def test_report_structure_and_stage_timings(tiny_report):
    assert tiny_report["repeat"] == 1
    assert tiny_report["paper"]["total"] == pytest.approx(25.78)
    (case,) = tiny_report["cases"]
    assert "error" not in case
    assert case["n_frames"] == 200 and case["dims"] > 0 and case["threshold"] > 0
    assert 3 <= case["cyclecoord"]["filtration_points"] <= case["n_frames"]
    stages = case["cyclecoord"]["stages"]
    assert set(stages) == set(bench.STAGES)
    assert all(v >= 0 for v in stages.values())
    parts = sum(v for k, v in stages.items() if k != "total")
    assert stages["total"] == pytest.approx(parts, rel=0.5)  # medians of each stage vs median total
    assert case["ripser"]["seconds"] > 0 and case["ripser"]["threshold"] == case["threshold"]
    assert case["ripser"]["n_h1"] >= 1
    for method in ("cyclecoord", "ripser"):
        assert case[method]["peak_python_mb"] >= 0
        assert case[method]["maxrss_mb"] > 0


def test_report_ratios(tiny_report):
    (case,) = tiny_report["cases"]
    r = case["ratios"]
    assert set(r) == {"cyclecoord_over_ripser", "barcode_over_ripser", "cyclecoord_over_dreimac", "cyclecoord_over_paper"}
    total = case["cyclecoord"]["stages"]["total"]
    assert r["cyclecoord_over_ripser"] == pytest.approx(total / case["ripser"]["seconds"])
    assert r["cyclecoord_over_paper"] is None  # the paper timed only the 69_01 window
    if HAVE_DREIMAC:
        assert r["cyclecoord_over_dreimac"] == pytest.approx(total / case["dreimac"]["total"])
    else:
        assert r["cyclecoord_over_dreimac"] is None


def test_agreement_with_truth(tiny_report):
    (case,) = tiny_report["cases"]
    truth = case["agreement"]["truth"]
    true_cycles = 199 / 120
    assert case["agreement"]["cycles_true"] == pytest.approx(true_cycles)
    cc_truth = truth["cyclecoord"]
    assert 0.9 <= cc_truth["bins_advancing"] <= 1.0
    assert abs(cc_truth["cycles"] - true_cycles) < 0.35
    assert 0.0 <= cc_truth["mean_abs_error"] < 0.2


def test_dreimac_baseline(tiny_report):
    if not HAVE_DREIMAC:
        pytest.skip('dreimac not installed (pip install -e ".[bench]")')
    (case,) = tiny_report["cases"]
    d = case["dreimac"]
    assert d["n_landmarks"] == 200 and d["all_points"]
    assert d["total"] == pytest.approx(d["construct"] + d["coordinates"], rel=0.5)
    assert d["settings"]["cocycle_idx"] == 0 and d["settings"]["perc"] == 0.5
    vs = case["agreement"]["cyclecoord_vs_dreimac"]
    assert 0.9 <= vs["correlation"] <= 1.0
    assert 0.0 <= vs["median_difference"] < 0.05
    dm_truth = case["agreement"]["truth"]["dreimac"]
    assert 0.9 <= dm_truth["bins_advancing"] <= 1.0


def test_report_prints_and_serialises(tiny_report, tmp_path):
    text = bench.format_report(tiny_report)
    assert "synthetic 200 frames" in text and "cc/ripser" in text and "published" in text
    out = tmp_path / "r.json"
    out.write_text(json.dumps(bench._jsonable(tiny_report)))
    back = json.loads(out.read_text())
    assert back["cases"][0]["cyclecoord"]["stages"]["total"] > 0


def test_main_quick_path_without_data(tmp_path, capsys):
    out = tmp_path / "quick.json"
    status = bench.main([
        "--quick", "--data", str(tmp_path / "absent"), "--sizes", "200", "--no-dreimac",
        "--no-progress", "--json", str(out),
    ])
    assert status == 0
    printed = capsys.readouterr().out
    assert "69_01 skipped" in printed and "synthetic 200 frames" in printed
    report = json.loads(out.read_text())
    (case,) = report["cases"]
    assert case["n_frames"] == 200 and report["repeat"] == 1
    assert case["dreimac"] == {"skipped": "DREiMac baseline not requested (--no-dreimac)"}
    assert math.isfinite(case["ratios"]["cyclecoord_over_ripser"])
