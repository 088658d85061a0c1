"""Tests of benchmarks/bench_extract.py: result structure and agreement measures (never speed)."""

from __future__ import annotations

import importlib.util
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from _skips import need_data
from _measured import at_most

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_extract.py"


def _load_bench():
    spec = importlib.util.spec_from_file_location("bench_extract", BENCH)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_extract"] = module  # dataclasses need the module registered
    spec.loader.exec_module(module)
    return module


bench = _load_bench()
# dreimac is in the 'test' extra: the DREiMac baseline runs wherever the suite does
HAVE_DREIMAC, DREIMAC_STATUS = bench.dreimac_status()


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
    need_data(bench.DATA_DIR / "cmu" / "69" / "69_01.amc")
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
    return bench.run_benchmark([case], repeat=1, with_dreimac=True, progress=False)


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
    assert r["cyclecoord_over_dreimac"] == pytest.approx(total / case["dreimac"]["total"])


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
    assert HAVE_DREIMAC, f'dreimac is in the test extra (pip install -e ".[test]"): {DREIMAC_STATUS}'
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


# ====================================================== benchmarks/bench_scaling.py
SCALING = BENCH.parent / "bench_scaling.py"


def _load_scaling():
    spec = importlib.util.spec_from_file_location("bench_scaling", SCALING)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_scaling"] = module  # dataclasses and child processes need the name
    spec.loader.exec_module(module)
    return module


scaling = _load_scaling()


def test_scaling_reuses_the_short_benchmark_helpers():
    assert scaling.bx is bench  # imported, not copied
    assert scaling.STAGES == bench.STAGES


def test_scaling_case_selection_without_data(tmp_path):
    cases, skipped = scaling.select_cases((4000, 1000, 1000), tmp_path)
    assert [c.name for c in cases] == ["synthetic 1000", "synthetic 4000"]
    assert all(c.kind == "synthetic" and c.seed == 0 for c in cases)
    assert len(skipped) == 2
    assert "01_09 skipped" in skipped[0] and "13_29 skipped" in skipped[1]
    assert all("not found" in s for s in skipped)
    with pytest.raises(ParameterError):
        scaling.synthetic(50)


def test_scaling_sizes_option():
    assert scaling._parse_sizes("1000, 4000,16000") == [1000, 4000, 16000]
    for bad in ("", "10", "1k"):
        with pytest.raises(Exception):
            scaling._parse_sizes(bad)


def test_full_ripser_rule():
    assert scaling.ripser_fits(4000, 3e8)[0]
    too_many, why = scaling.ripser_fits(4001, 1e6)
    assert not too_many and "4000" in why
    too_big, why = scaling.ripser_fits(1000, 3e9)
    assert not too_big and "GB" in why


def test_growth_exponent_and_table():
    assert scaling.growth_exponent(1000, 1.0, 4000, 4.0) == pytest.approx(1.0)
    assert scaling.growth_exponent(1000, 1.0, 4000, 16.0) == pytest.approx(2.0)
    assert scaling.growth_exponent(1000, 0.0, 4000, 1.0) is None

    def fake(n, total):
        stages = {s: total / 6 for s in scaling.STAGES}
        stages["total"] = total
        return {"case": {"name": f"synthetic {n}", "kind": "synthetic", "n_frames": n},
                "cyclecoord": {"status": "ok", "modes": {"default": {"outcome": "ok", "stages": stages}}}}

    rows = scaling.growth_table([fake(4000, 8.0), fake(1000, 2.0), fake(16000, 64.0)])
    assert [(r["from"], r["to"]) for r in rows] == [(1000, 4000), (4000, 16000)]
    assert rows[0]["exponents"]["total"] == pytest.approx(1.0)
    assert rows[1]["exponents"]["total"] == pytest.approx(1.5)


def test_stage_peaks_follow_the_stage_windows():
    timings = {"prepare": 0.1, "barcode": 1.0, "coordinate": 2.0, "density": 0.5, "total": 3.6}
    run = {"start": 10.0, "timings": timings}
    samples = [(10.05, 100.0), (10.5, 300.0), (10.9, 250.0), (12.0, 900.0), (13.3, 200.0)]
    peaks = scaling.stage_peaks([run], samples)
    assert peaks == {"prepare": 100.0, "barcode": 300.0, "coordinate": 900.0, "density": 200.0}
    assert scaling.stage_peaks([run], []) == {}


def test_targets_pass_fail_and_not_run():
    def case(name, n, total, rss):
        stages = dict.fromkeys(scaling.STAGES, 0.1)
        stages["total"] = total
        return {"case": {"name": name, "kind": "synthetic" if name.startswith("syn") else "cmu", "n_frames": n},
                "cyclecoord": {"status": "ok", "peak_rss_mb": rss, "load_seconds": 0.2,
                               "modes": {"default": {"outcome": "ok", "require_clear": True, "stages": stages}}}}

    t = scaling.evaluate_targets([case("01_09", 4242, 3.0, 300.0), case("synthetic 64000", 64000, 75.0, 900.0)])
    assert [x["passed"] for x in t] == [True, False, True]
    assert t[2]["value"] == pytest.approx(900.0 * 1024 * 1024 / 1e9)
    assert [x["passed"] for x in scaling.evaluate_targets([])] == [None, None, None]


@pytest.fixture(scope="module")
def scaling_tiny():
    # 1,500 frames: above the 1,000-frame limit, so extract uses 500 landmarks
    case = scaling.synthetic(1500)
    return scaling.run_case(case, repeat=1, with_dreimac=False, with_ripser=True, trace=True, isolate=False)


def test_scaling_tiny_case_structure(scaling_tiny):
    c = scaling_tiny
    assert c["case"]["n_frames"] == 1500
    ccr = c["cyclecoord"]
    assert ccr["status"] == "ok" and list(ccr["modes"]) == ["default"]
    mode = ccr["modes"]["default"]
    assert mode["outcome"] == "ok" and mode["repeat"] == 1
    assert set(mode["stages"]) == set(scaling.STAGES)
    parts = sum(v for k, v in mode["stages"].items() if k != "total")
    assert mode["stages"]["total"] == pytest.approx(parts)
    assert mode["landmarks"] == 500 and "landmarks" in mode["landmark_reason"]
    assert mode["threshold"] > 0 and mode["peak_python_mb"] > 0
    assert ccr["peak_rss_mb"] > 0
    assert c["dreimac"] == {"status": "skipped", "reason": "not requested (--no-dreimac)"}
    rp = c["ripser"]
    assert rp["status"] == "ok" and rp["threshold"] == mode["threshold"] and rp["n_h1"] >= 1
    assert rp["estimated_bytes"] >= 8 * 1500**2


def test_scaling_tiny_case_agreement_with_truth(scaling_tiny):
    a = scaling_tiny["agreement"]
    assert a["cycles_true"] == pytest.approx(1499 / 120)
    mode = scaling_tiny["cyclecoord"]["modes"]["default"]
    assert abs(mode["cycles"] - a["cycles_true"]) < 0.5
    assert a["cyclecoord_truth"]["bins_advancing"] >= 0.9
    assert a["cyclecoord_truth"]["mean_abs_error"] < 0.15


def test_scaling_report_prints_and_serialises(scaling_tiny, tmp_path):
    report = {"machine": bench.machine_info(),
              "settings": {"repeat": 1, "isolated": False, "baseline_timeout": 1.0, "sample_interval": 0.02,
                           "ripser_rule": "N <= 4000", "dreimac_max_frames": None},
              "skipped": ["01_09 skipped: test"], "cases": [scaling_tiny]}
    report["growth"] = scaling.growth_table(report["cases"])
    report["targets"] = scaling.evaluate_targets(report["cases"])
    text = scaling.format_report(report)
    assert "synthetic 1500" in text and "NOTE: 01_09 skipped" in text
    assert text.count("NOT RUN:") == 3 and "cc/ripser" in text
    out = tmp_path / "s.json"
    out.write_text(json.dumps(scaling._strip(report)))
    back = json.loads(out.read_text())
    assert back["cases"][0]["cyclecoord"]["modes"]["default"]["landmarks"] == 500


def test_scaling_child_process_and_timeout(tmp_path):
    case = scaling.asdict(scaling.synthetic(300))
    out = scaling.run_child({"method": "ripser", "case": case, "threshold": 30.0}, timeout=120, work_dir=tmp_path)
    assert out["status"] == "ok", out
    assert out["seconds"] > 0 and out["n_edges"] > 0
    assert out["peak_rss_mb"] >= out["rss_before_mb"] > 10  # a separate interpreter's own high-water mark
    slow = scaling.run_child({"method": "cyclecoord", "case": scaling.asdict(scaling.synthetic(4000))},
                             timeout=0.3, work_dir=tmp_path)
    assert slow["status"] == "timed out" and "killed after" in slow["reason"]
    assert slow["wall_seconds"] < 30


def test_scaling_mixed_capture_is_timed_both_ways():
    path = bench.DATA_DIR / "cmu" / "01" / "01_09.amc"
    need_data(path)
    case = scaling.Case("01_09", "cmu", 4242, str(path))
    c = scaling.run_case(case, with_dreimac=False, with_ripser=False, trace=False, isolate=False)
    modes = c["cyclecoord"]["modes"]
    assert list(modes) == ["default", "require_clear=False"]
    assert modes["default"]["outcome"] == "no periodic motion"
    assert set(modes["default"]["stages"]) <= {"prepare", "steady", "barcode", "total"}
    assert any(w in modes["default"]["message"] for w in ("does not stand clear", "turns only"))
    # without the clear-class test the pipeline goes on at least through the coordinate
    # (it may still stop there: 01_09 holds less than one cycle of any single motion)
    full = modes["require_clear=False"]
    # (the barcode and coordinate of the first pass over the moving frames are timed as "steady")
    assert {"prepare", "total"} <= set(full["stages"])
    assert {"barcode", "coordinate"} <= set(full["stages"]) or "steady" in full["stages"]
    assert full["outcome"] in ("ok", "no periodic motion")
    assert full["stages"]["total"] == pytest.approx(sum(v for k, v in full["stages"].items() if k != "total"))
    # 500 landmarks for the final fit, 150 when the first pass (which finds the steady
    # frames of a long take) already finds too few turns
    assert full["landmarks"] in (150, 500) and "cycles" in full
    (target, *_) = scaling.evaluate_targets([c])
    assert target["passed"] is not None and target["value"] == full["stages"]["total"]
    assert "require_clear=False" in target["note"]


# ======================================================= benchmarks/bench_detect.py
DETECT_BENCH = BENCH.parent / "bench_detect.py"


def _load_detect_bench():
    spec = importlib.util.spec_from_file_location("bench_detect", DETECT_BENCH)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_detect"] = module
    spec.loader.exec_module(module)
    return module


detect_bench = _load_detect_bench()


@pytest.fixture(scope="module")
def detect_smoke(tmp_path_factory):
    """One small chain (400 frames per motion); the real-data sections without data."""
    empty = tmp_path_factory.mktemp("no_data")
    return detect_bench.run_benchmark(parts=("synthetic", "13_29", "01_09", "timing"), quick=True, data_dir=empty,
                                      segment_frames=400, progress=False)


def test_detect_bench_small_chain(detect_smoke):
    syn = detect_smoke["synthetic"]
    (case,) = syn["cases"]
    assert case["kinds"] == ["walk", "jumping_jack", "arm_circles"] and case["seed"] == 0
    assert case["n_frames"] == 3 * 400 + 2 * 40
    assert [t[:2] for t in case["truth"]] == [[0, 400], [440, 840], [880, 1280]]
    # the detector finds the three motions, matched one to one to the three kinds
    assert case["n_motions"] == 3 and sorted(case["matching"].values()) == sorted(case["kinds"])
    # measured (tests/_measured.py RUN): 0.58 % of the frames mislabelled, boundaries within
    # 7 frames, segment periods within 5.9 % of their kind's
    assert 1 - case["accuracy"] <= at_most(0.0058, 0.005) and case["accuracy_ok"]
    assert case["max_boundary_error"] == max(case["boundary_errors"]) <= at_most(7, 5)
    assert case["boundaries_ok"]
    for seg in case["segment_periods"]:  # each segment's period close to its kind's true period
        assert abs(seg["period_frames"] / case["periods"][seg["kind"]] - 1) <= at_most(0.0586)
    for act in case["activities"].values():
        assert act["matched_fraction"] <= act["covered_fraction"] <= 1.0
    assert set(case["timings"]) == {"prepare", "barcode", "coordinates", "windows", "segments", "total"}
    s = syn["summary"]
    assert s["n_cases"] == 1 and s["min_accuracy"] == s["mean_accuracy"] == case["accuracy"]
    assert s["worst_boundary_error"] == case["max_boundary_error"] and s["both_ok"] == 1


def test_detect_bench_without_data_skips_with_reasons(detect_smoke, tmp_path):
    assert set(detect_smoke) >= {"machine", "skipped", "synthetic"}
    skipped = detect_smoke["skipped"]
    assert any(s.startswith("13_29 skipped") and "not found" in s for s in skipped)
    assert any(s.startswith("timing skipped") for s in skipped)
    assert any("01_09" in s and "--quick" in s for s in skipped)
    text = detect_bench.format_report(detect_smoke)
    assert "synthetic chains" in text and "walk/jumping_jack/arm_circles seed 0" in text
    assert "NOTE: 13_29 skipped" in text and "== 13_29" not in text
    out = tmp_path / "d.json"
    assert detect_bench.main(["--parts", "13_29", "concat", "--data", str(tmp_path), "--json", str(out),
                              "--no-progress"]) == 0
    back = json.loads(out.read_text())
    assert "13_29" in back and back["13_29"]["skipped"].startswith("13_29 skipped")
    assert any(s.startswith("concatenation skipped") for s in back["skipped"])
    with pytest.raises(ParameterError):
        detect_bench.run_benchmark(parts=("nonsense",), data_dir=tmp_path, progress=False)


def test_detect_bench_scoring_helpers(tmp_path):
    spans = [(0, 4, "a"), (4, 7, "b"), (8, 10, "a")]
    truth, names = detect_bench.frame_truth(spans, 11)
    assert names == ["a", "b"] and truth.tolist() == [0, 0, 0, 0, 1, 1, 1, -1, 0, 0, -1]
    assert detect_bench.segments_of(truth, names) == spans
    labels = np.array([5, 5, 5, -1, 2, 2, 5, 2, 5, 5, 2])
    sc = detect_bench.activity_scores(labels, truth, names)
    assert sc["matching"] == {2: "b", 5: "a"}
    assert sc["accuracy"] == pytest.approx(7 / 9)  # frames 7 and 10 unscored
    a, b = sc["activities"]["a"], sc["activities"]["b"]
    assert a["frames"] == 6 and a["matched_fraction"] == pytest.approx(5 / 6) and a["covered_fraction"] == pytest.approx(5 / 6)
    assert b["by_motion"] == {2: pytest.approx(2 / 3), 5: pytest.approx(1 / 3)}
    # Fig. 10 as printed is inclusive; frame 2745 is claimed twice and goes to the later entry
    fig = detect_bench.fig10_spans()
    t10, n10 = detect_bench.frame_truth(fig, 4242)
    assert n10 == ["walking", "climbing a ladder", "sitting, dangling feet", "jumping down"]
    assert t10[293] == 0 and t10[294] == 1 and t10[2745] == 2 and t10[3880] == 2 and t10[3881] == -1
    # label files: a good one, then errors naming the file and line
    good = tmp_path / "l.csv"
    good.write_text("start_frame,stop_frame,activity\n0,10,Jump\n10,20,Twist\n")
    assert detect_bench.load_activity_labels(good, 20) == [(0, 10, "Jump"), (10, 20, "Twist")]
    for body, line in (("start,stop\n", 1), ("start_frame,stop_frame,activity\n0,x,Jump\n", 2),
                       ("start_frame,stop_frame,activity\n0,10,Jump\n5,3,Twist\n", 3),
                       ("start_frame,stop_frame,activity\n0,30,Jump\n", 2)):
        bad = tmp_path / "bad.csv"
        bad.write_text(body)
        with pytest.raises(detect_bench.ParseError) as info:
            detect_bench.load_activity_labels(bad, 20)
        assert info.value.line == line and "bad.csv" in str(info.value)


def test_detect_bench_real_labels_match_capture():
    path = detect_bench.DATA_DIR / "labels" / "13_29.csv"
    need_data(path)
    spans = detect_bench.load_activity_labels(path, 4592)
    assert len(spans) == 6 and spans[0] == (0, 456, "JumpJack") and spans[-1][1] == 4584


# ===================================================== benchmarks/bench_synthesis.py
def test_synthesis_bench_prints_every_method_on_synthetic_walks(tmp_path, capsys):
    """Without the shared data the table runs on synthetic walks: every method and the
    captures get a row, ours its ratios against each baseline (never speed)."""
    spec = importlib.util.spec_from_file_location(
        "bench_synthesis", BENCH.parent / "bench_synthesis.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_synthesis"] = module
    spec.loader.exec_module(module)
    out = tmp_path / "s.json"
    assert module.main(["--data", str(tmp_path / "none"), "--frames", "240", "--no-limbs",
                        "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "synthetic walks" in text
    for label in (*module.METHODS, "captures (4)", "vs classic graph", "vs nearest-take replay"):
        assert label in text
    figures = json.loads(out.read_text())["sets"][0]["figures"]
    assert not figures["graph (ours)"]["freezes"]
    # the control: each capture's one-cycle windows, measured like a generated motion
    assert "control: the captures' own one-cycle windows" in text
    ctl = figures["stride windows"]
    assert len(ctl) >= 4 and max(ctl) <= 1.2 and 0.8 < float(np.median(ctl)) <= 1.05


def test_synthesis_bench_random_targets_split_pairs_by_stand(monkeypatch):
    """``random_targets``: seeded random start/target pairs on each set, ours and the
    paper's graph path measured alike, and the summary keeps pairs that start or end in
    a take's stand apart (no capture walks into a stand; a take that stands first is
    crossed through it)."""
    spec = importlib.util.spec_from_file_location(
        "bench_synthesis", BENCH.parent / "bench_synthesis.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_synthesis"] = module
    spec.loader.exec_module(module)
    walks = [cc.datasets.make_periodic_capture(kind="walk", n_frames=n, period=60,
                                               random_state=s).motion
             for s, n in enumerate((240, 260))]
    jog = cc.datasets.make_periodic_capture(kind="jog", n_frames=200, period=40,
                                            random_state=5).motion
    monkeypatch.setattr(module, "target_sets", lambda data: [("synthetic", walks + [jog])])
    rows = module.random_targets(Path("unused"), 6)
    again = module.random_targets(Path("unused"), 6)
    assert rows[0]["ours"] == again[0]["ours"]  # seeded
    r = rows[0]
    assert r["set"] == "synthetic" and len(r["ours"]) == len(r["graph path"]) == 6
    assert len(r["kinds"]) == len(r["stand"]) == 6 and not any(r["stand"])
    assert max(a for a, _ in r["ours"]) <= 1.5 and not any(f for _, f in r["ours"])
    (line,) = module._random_lines(rows)
    assert line.split()[:3] == ["synthetic", "6", "pairs:"] and "| graph path accel" in line
    r["stand"][0] = True  # a pair in a stand is summed apart
    lines = module._random_lines(rows)
    assert len(lines) == 2 and " 5 pairs:" in lines[0] and "with a stand" in lines[1]


def test_synthesis_bench_targets_ours_against_the_graph_path(cmu_dir, monkeypatch):
    """``targets``: one w1 pair and one walk-to-jog pair, ours (walked in step) against the
    paper's shortest graph path on the same takes: ours pops less on both (measured 0.65
    against 1.91 on w1, 0.70-0.94 against 2.0-2.9 into the jog)."""
    spec = importlib.util.spec_from_file_location(
        "bench_synthesis", BENCH.parent / "bench_synthesis.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_synthesis"] = module
    spec.loader.exec_module(module)
    monkeypatch.setattr(module, "W1_TARGETS", ((0, 50, 2, 200),))
    monkeypatch.setattr(module, "GAIT_TARGETS", ((2, 20, 1, 150),))
    rows = module.targets(cmu_dir.parent)
    assert [r["set"] for r in rows] == ["w1", "walks + jog"]
    for r in rows:
        assert r["ours"]["kind"].startswith("field:phase:")
        assert r["graph path"]["kind"].startswith("graph:")
        assert r["ours"]["accel"] < r["graph path"]["accel"]
        assert r["ours"]["accel"] <= 1.0 and r["ours"]["limbs"] == 0
