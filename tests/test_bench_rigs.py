"""Tests of benchmarks/bench_rigs.py's own measures on data with known answers (never speed)."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import sys
from pathlib import Path

import numpy as np
import pytest

import cyclecoord as cc

BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_rigs.py"


def _load_bench():
    spec = importlib.util.spec_from_file_location("bench_rigs", BENCH)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_rigs"] = module  # dataclasses need the module registered
    spec.loader.exec_module(module)
    return module


bench = _load_bench()

PERIOD = 60  # frames; whole, so an exactly periodic capture repeats frame for frame


def _walk(noise: float = 0.0, kind: str = "walk", period: float = PERIOD, n: int = 600):
    return cc.datasets.make_periodic_capture(
        n_frames=n, period=period, noise=noise, speed_variation=0.0, kind=kind, random_state=0
    )


def _capture(motion):
    case = bench.Case("synthetic", None, "synthetic", motion)
    rig, frames, fps = bench.load_own(case)
    return rig, frames, bench.prepare_capture(rig, frames, fps)


# ------------------------------------------------------------------ parsers and FK
BVH = """HIERARCHY
ROOT Base
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Hips
  {
    OFFSET 0 90 0
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    JOINT Leg
    {
      OFFSET 0 -40 0
      CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 0 10
      }
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
0 0 0 0 0 0  1 90 3 0 0 0  0 -40 0 0 0 0
0 0 0 0 0 0  1 90 3 0 0 90  5 -40 0 0 90 0
"""


def test_bvh_parser_and_fk_known_answer(tmp_path):
    rig, frames, fps = bench.parse_bvh(BVH)
    assert fps == pytest.approx(30.0, rel=1e-5)
    assert [j.name for j in rig.joints] == ["Base", "Hips", "Leg"]
    assert rig.joints[2].compose == "ZXY"
    assert rig.point_names == ["Base", "Hips", "Leg", "Leg/end"]
    pts = bench.forward_kinematics(rig, frames).points
    # frame 0: position channels replace the offsets (Hips at 1, 90, 3)
    np.testing.assert_allclose(pts[0, 1], [1, 90, 3], atol=1e-12)
    np.testing.assert_allclose(pts[0, 3], [1, 50, 13], atol=1e-12)
    # frame 1: Hips turned 90 deg about y, so Leg's (5, -40, 0) becomes (0, -40, -5);
    # Leg turned 90 deg about x, so its end site (0, 0, 10) becomes (0, -10, 0), then y
    np.testing.assert_allclose(pts[1, 2], [1, 50, -2], atol=1e-12)
    np.testing.assert_allclose(pts[1, 3], [1, 40, -2], atol=1e-12)
    # the library reads the same file to the same points
    path = tmp_path / "tiny.bvh"
    path.write_text(BVH)
    assert bench.fk_check(cc.load(path), rig, pts) == pytest.approx(0.0, abs=1e-9)


ASF = """:version 1.10
:name tiny
:units
  mass 1.0
  length 0.45
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name bone
     direction 0 0 1
     length 2
     axis 0 0 90 XYZ
    dof rx
  end
:hierarchy
  begin
    root bone
  end
"""
AMC = """:FULLY-SPECIFIED
:DEGREES
1
root 1 2 3 0 0 0
bone 0
2
root 1 2 3 0 0 0
bone 90
"""


def test_asf_parser_and_fk_known_answer(tmp_path):
    rig = bench.parse_asf(ASF)
    frames = bench.parse_amc(AMC, rig)
    assert rig.length_unit == 0.45 and frames.shape == (2, 7)
    pts = bench.forward_kinematics(rig, frames).points
    np.testing.assert_allclose(pts[0], [[1, 2, 3], [1, 2, 5]], atol=1e-12)
    # axis: C = Rz(90); the dof turns 90 deg about C x = world y: (0, 0, 2) -> (2, 0, 0)
    np.testing.assert_allclose(pts[1], [[1, 2, 3], [3, 2, 3]], atol=1e-12)
    (tmp_path / "tiny.asf").write_text(ASF)
    (tmp_path / "tiny.amc").write_text(AMC)
    lib = cc.load(tmp_path / "tiny.amc", skeleton=tmp_path / "tiny.asf")
    assert bench.fk_check(lib, rig, pts) == pytest.approx(0.0, abs=1e-9)


def test_asf_written_by_the_library_reads_back_to_the_same_points(tmp_path):
    motion = _walk(noise=0.5, n=120).motion
    cc.save(motion, tmp_path / "walk.amc")
    case = bench.Case("walk", tmp_path / "walk.amc", "cmu")
    rig, frames, _ = bench.load_own(case)
    pts = bench.forward_kinematics(rig, frames).points
    assert bench.fk_check(cc.load(tmp_path / "walk.amc"), rig, pts) < 1e-9


# -------------------------------------------------------------------- body layout
def test_body_layout_of_the_synthetic_walk():
    rig, _, cap = _capture(_walk().motion)
    body = cap.body
    assert body.up == 1 and body.root_joint == 0
    assert [leg["name"] for leg in body.legs] == ["lfemur", "rfemur"]
    for leg in body.legs:
        names = [rig.point_names[leg[k]] for k in ("hip", "knee", "ankle", "ball")]
        assert names[1:] == [names[0].replace("femur", k) for k in ("tibia", "foot", "toes")]
    assert rig.point_names[body.head].startswith("head")


def _leg(side: str, x: float) -> str:
    return f"""    JOINT Thigh{side}
    {{
      OFFSET {x} 0 0
      CHANNELS 3 Zrotation Xrotation Yrotation
      JOINT Shin{side}
      {{
        OFFSET 0 -40 0
        CHANNELS 3 Zrotation Xrotation Yrotation
        JOINT Foot{side}
        {{
          OFFSET 0 -40 0
          CHANNELS 3 Zrotation Xrotation Yrotation
          End Site
          {{
            OFFSET 0 -5 10
          }}
        }}
      }}
    }}
"""


BANDAI_LIKE = (
    "HIERARCHY\nROOT Base\n{\n  OFFSET 0 0 0\n"
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    "  JOINT Hips\n  {\n    OFFSET 0 90 0\n"
    "    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
    + _leg("L", 10) + _leg("R", -10)
    + "    JOINT Spine\n    {\n      OFFSET 0 10 0\n      CHANNELS 3 Zrotation Xrotation Yrotation\n"
    "      JOINT Head\n      {\n        OFFSET 0 50 0\n        CHANNELS 3 Zrotation Xrotation Yrotation\n"
    "        End Site\n        {\n          OFFSET 0 10 0\n        }\n      }\n    }\n  }\n}\n"
    "MOTION\nFrames: 3\nFrame Time: 0.0333333\n"
    + "".join("0 0 0 0 0 0 0 90 %d 0 0 0 " % z + "0 " * 24 + "\n" for z in (0, 400, 800))
)


def test_static_root_is_skipped_to_the_travelling_hips():
    rig, frames, _ = bench.parse_bvh(BANDAI_LIKE)
    body = bench.body_layout(rig, bench.forward_kinematics(rig, frames))
    assert rig.joints[body.root_joint].name == "Hips"
    assert body.up == 1  # the 8 m of travel along z is not the figure's extent
    assert body.height == pytest.approx(90 + 60 + 5)
    assert [leg["name"] for leg in body.legs] == ["ThighL", "ThighR"]
    left = body.legs[0]
    assert [rig.point_names[left[k]] for k in ("hip", "knee", "ankle", "ball", "toe")] == [
        "ThighL", "ShinL", "FootL", "FootL/end", "FootL/end"]
    assert rig.point_names[body.head] == "Head/end"


def test_units_guess():
    rig = bench.Rig([], [], [], [], "bvh")
    assert bench.units_guess(170.0, rig).startswith("cm")
    assert bench.units_guess(1700.0, rig).startswith("mm")
    assert bench.units_guess(1.7, rig).startswith("m ")
    assert bench.units_guess(67.0, rig).startswith("inch")
    assert bench.units_guess(17000.0, rig) == "unknown"


# --------------------------------------------------------------- the two periods
@pytest.mark.parametrize("noise", [0.0, 0.5])
def test_reference_periods_of_a_synthetic_walk(noise):
    _, _, cap = _capture(_walk(noise=noise).motion)
    ref = bench.references(cap)
    assert ref["ac_period"] == pytest.approx(PERIOD, rel=0.02)
    assert ref["strike_period"] == pytest.approx(PERIOD, rel=0.02)
    assert ref["strikes"] >= 2 * (600 // PERIOD - 1)


def test_reference_periods_of_a_synthetic_jog():
    _, _, cap = _capture(_walk(kind="jog", period=45.0).motion)
    ref = bench.references(cap)
    assert ref["ac_period"] == pytest.approx(45.0, rel=0.02)
    assert ref["strike_period"] == pytest.approx(45.0, rel=0.02)


def test_autocorrelation_treats_rotations_as_rotations():
    # one joint turning about y around 180 deg: its Euler angle wraps at +-180 every
    # half cycle, its rotation matrix does not
    t = np.arange(400)
    angle = 180.0 + 40.0 * np.sin(2 * np.pi * t / 50.0)
    wrapped = (angle + 180.0) % 360.0 - 180.0
    local = bench._elementary("y", wrapped)[:, None]
    assert bench.rotation_autocorrelation_period(local, [0], fps=30.0) == pytest.approx(50, rel=0.01)


def test_foot_strikes_of_a_clean_step_pattern():
    fps, period = 60.0, 40
    t = np.arange(400)
    phase = (t % period) / period
    height = np.where(phase < 0.6, 0.0, np.sin(np.pi * (phase - 0.6) / 0.4))  # 60 % stance
    speed = np.where(phase < 0.6, 0.0, 3.0)
    strikes = bench.foot_strikes(height, speed, fps)
    assert np.diff(strikes) == pytest.approx(np.full(len(strikes) - 1, period))
    assert len(strikes) == 400 // period - 1  # the first stance began before frame 0


def test_steady_frames_drop_standing():
    x = np.zeros((300, 3))
    x[100:220, 0] = np.sin(np.arange(120) / 5.0)
    a, b = bench.steady_frames(x, fps=30.0)
    assert 85 <= a <= 105 and 215 <= b <= 235


# ------------------------------------------------------------------ cycle quality
def test_a_copy_of_one_captured_period_measures_as_the_capture():
    rig, frames, cap = _capture(_walk().motion)
    a = 130
    q = bench.measure_cycle(cap, frames[a : a + PERIOD], cap.fps, float(PERIOD))
    assert "cut_error" not in q
    assert q["near_max_units"] == pytest.approx(0.0, abs=1e-6)
    # the seam is the step the capture makes there
    capture_step = np.linalg.norm(cap.poses[a + PERIOD] - cap.poses[a + PERIOD - 1])
    assert q["seam_units"] == pytest.approx(capture_step, rel=1e-6)
    assert q["seam"] == pytest.approx(capture_step / np.median(bench.steps(cap.poses[a : a + PERIOD])), rel=1e-6)
    assert q["step_over_p99"] <= 1.05
    # an exactly periodic capture: every one-period loop has the same ranges and jerk
    assert q["legs_min"] == pytest.approx(1.0, abs=1e-6)
    assert all(r == pytest.approx(1.0, abs=1e-6) for r in q["leg_ratios"].values())
    assert len(q["leg_ratios"]) == 6
    assert q["jerk_over_cut"] == pytest.approx(1.0, rel=1e-6)
    assert q["cut_stop"] - q["cut_start"] == PERIOD
    # and every one-period window has the range of any other: the median window's too
    assert q["legs_median_min"] == pytest.approx(1.0, abs=1e-6)


def test_window_leg_ranges_are_one_per_starting_frame_and_see_a_wide_stride():
    rig, frames, cap = _capture(_walk().motion)
    a, b = cap.steady
    ranges = bench.window_leg_ranges(cap, PERIOD)
    assert len(ranges) == 6
    assert all(len(v) == b - a - PERIOD + 1 for v in ranges.values())
    # an exactly periodic capture: every window's range is the one-period range, by hand
    knee = bench.leg_angles(cap.points[a : a + PERIOD], cap.body)
    for k, v in ranges.items():
        assert np.allclose(v, bench.angle_range(knee[k]), atol=1e-6)
    # one stride made wider shows in the windows that hold it, and only in those
    wide = np.array(frames)
    col = rig.channels.index(("lfemur", "rx"))
    stride = slice(a + 2 * PERIOD, a + 3 * PERIOD)
    wide[stride, col] = wide[stride, col].mean() + 1.5 * (wide[stride, col] - wide[stride, col].mean())
    cap2 = dataclasses.replace(bench.prepare_capture(rig, wide, cap.fps), steady=cap.steady)
    hip = np.asarray(bench.window_leg_ranges(cap2, PERIOD)["lfemur hip"])
    base = ranges["lfemur hip"][0]
    touching = np.arange(len(hip)) + PERIOD > 2 * PERIOD
    touching &= np.arange(len(hip)) < 3 * PERIOD
    assert np.all(hip[~touching] == pytest.approx(base, abs=1e-6))
    assert hip[2 * PERIOD] > 1.2 * base


def test_a_copy_of_one_period_of_a_noisy_capture_is_at_distance_0():
    rig, frames, cap = _capture(_walk(noise=0.5).motion)
    q = bench.measure_cycle(cap, frames[200 : 200 + PERIOD], cap.fps, float(PERIOD))
    assert q["spread"] > 0
    assert q["near_max"] == pytest.approx(0.0, abs=1e-6)
    assert q["near_median"] == pytest.approx(0.0, abs=1e-6)
    assert 0.5 < q["seam"] < 2.0
    assert q["legs_min"] > 0.8


def test_a_cycle_with_a_jump_and_a_foreign_pose_is_caught():
    rig, frames, cap = _capture(_walk(noise=0.5).motion)
    cyc = np.array(frames[130 : 130 + PERIOD])
    knee = rig.channels.index(("ltibia", "rx"))
    cyc[PERIOD // 2 :, knee] += 40.0  # the left knee snaps 40 deg more bent half-way
    q = bench.measure_cycle(cap, cyc, cap.fps, float(PERIOD))
    assert q["step_over_p99"] > 2.0
    assert q["near_max"] > 1.0
    assert q["seam"] > 1.5


def test_loop_cut_skips_standing_and_takes_one_period():
    t = np.arange(400)
    x = np.zeros((400, 2))
    x[150:, 0] = np.sin(2 * np.pi * (t[150:] - 150) / 37.0)
    x[150:, 1] = np.cos(2 * np.pi * (t[150:] - 150) / 37.0) - 1.0
    i, j, gap = bench.loop_cut(x, 37.0, (0, 400))
    assert i >= 150 and j - i == 37 and gap == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(ValueError, match="no loop cut"):
        bench.loop_cut(x, 37.0, (0, 30))


def test_verdicts():
    row = {"status": "ok", "kind": "cmu", "strike_pct": -2.9, "ac_pct": 2.5,
           "quality": {"step_over_p99": 2.0, "near_max": 1.2, "seam": 1.0,
                       "legs_min": 0.9, "jerk_over_cut": 0.4}}
    v = bench.verdicts(row)
    assert v == {"not refused": True, "period~strikes": True, "step": True, "near": False,
                 "seam": True, "legs": True, "period~ac": False, "jerk": True}
    refused = bench.verdicts({"status": "refused", "kind": "bvh"})
    assert refused["not refused"] is False
    assert all(refused[k] is None for k in bench.TARGETS if k != "not refused")


# ----------------------------------------------------------------------- the run
def test_run_on_a_synthetic_walk_prints_and_serialises(tmp_path):
    motion = _walk(noise=0.5, n=480).motion
    report = bench.run_benchmark([bench.Case("synthetic walk", None, "synthetic", motion)])
    (row,) = report["rows"]
    assert row["status"] == "ok", row.get("reason")
    assert row["rig_source"] in ("fallback", "cyclecoord.rig")
    assert row["fk_check"] == pytest.approx(0.0, abs=1e-9)
    assert abs(row["strike_pct"]) < 5 and abs(row["ac_pct"]) < 5
    assert set(row["targets"]) == set(bench.TARGETS)
    text = bench.format_report(report)
    assert "synthetic walk" in text and "summary:" in text and "not refused" in text
    out = tmp_path / "r.json"
    out.write_text(json.dumps(bench._jsonable(report)))
    assert json.loads(out.read_text())["rows"][0]["file"] == "synthetic walk"


def test_main_without_data(tmp_path, capsys):
    assert bench.main(["--data", str(tmp_path)]) == 1
    assert "no files to run" in capsys.readouterr().out
    cases, skipped = bench.cases(tmp_path)
    assert cases == [] and len(skipped) == 1 + len(bench.CMU_TAKES)
