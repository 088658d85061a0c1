"""Hand-made references (loop cut, average cycle, autocorrelation period) and the cycle
figures of cyclecoord.quality.cycle_quality, on synthetic captures and tiny arrays."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from cyclecoord.quality.cycle_quality import (
    CycleQuality,
    coverage,
    cycle_jerk,
    cycle_quality,
    foot_skating_speed,
    heading_change,
    leg_joint_ranges,
    leg_ranges,
    period_error,
    root_closure,
    seam,
    step_spread,
    largest_step,
    targets,
)
from cyclecoord.quality.reference import (
    autocorrelation_period,
    average_cycle,
    best_loop_cut,
    joint_angles,
    wrap_times,
)

BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_quality.py"
ROOT = [("root", d) for d in ("tx", "ty", "tz", "rx", "ry", "rz")]


@pytest.fixture(scope="module")
def steady():
    """A walk at constant speed: period exactly 100 frames, phase t / 100."""
    return cc.datasets.make_periodic_capture(
        n_frames=600, period=100.0, noise=0.5, speed_variation=0.0, random_state=3
    )


def _motion(joint_cols: dict, root: np.ndarray | None = None, fps: float = 10.0) -> cc.Motion:
    names = list(joint_cols)
    n = len(next(iter(joint_cols.values())))
    root = np.zeros((n, 6)) if root is None else root
    frames = np.column_stack([root] + [np.asarray(joint_cols[k], dtype=float) for k in names])
    return cc.Motion(frames, ROOT + [tuple(k.split(".")) for k in names], fps=fps)


# ------------------------------------------------------------------ joint angles
def test_joint_angles_drop_the_root_and_unwrap():
    m = _motion({"lfemur.rx": [170.0, 179.0, -172.0, -165.0], "lhumerus.rz": [1.0, 2.0, 3.0, 4.0]})
    x = joint_angles(m)
    assert x.shape == (4, 2)
    np.testing.assert_allclose(x[:, 0], [170, 179, 188, 195])
    shifted = joint_angles(m, like=np.array([-180.0, 0.0]))  # the same branch as a take near -180
    np.testing.assert_allclose(shifted[:, 0], [-190, -181, -172, -165])


# ----------------------------------------------------------------------- period
def test_autocorrelation_period_finds_the_true_period(steady):
    p = autocorrelation_period(steady.motion)
    assert p == pytest.approx(100.0, rel=0.02)
    # only some frames used: still the period, and NaN when the used frames are too short
    assert autocorrelation_period(
        steady.motion, used_frames=[[0, 250], [300, 600]]
    ) == pytest.approx(100.0, rel=0.02)
    assert np.isnan(autocorrelation_period(steady.motion, used_frames=[[0, 40]]))


@pytest.mark.parametrize("period", [100.4, 37.3])
def test_autocorrelation_period_to_a_fraction_of_a_frame(period):
    """The parabola through the peak and its neighbours finds a period between whole
    frames (measured errors 0.0011 and 0.0056 frames, noise-free; whole lags are 0.3-0.4
    off)."""
    m = cc.datasets.make_periodic_capture(n_frames=600, period=period, noise=0.0,
                                          speed_variation=0.0, random_state=3).motion
    assert abs(autocorrelation_period(m) - period) < 0.02


def test_autocorrelation_period_of_noise_is_nan():
    rng = np.random.default_rng(0)
    m = _motion({"lfemur.rx": rng.normal(size=400), "ltibia.rx": rng.normal(size=400)}, fps=120.0)
    assert np.isnan(autocorrelation_period(m))


# --------------------------------------------------------------------- loop cut
def test_loop_cut_is_one_period_long_and_closes(steady):
    cut = best_loop_cut(steady.motion, 100.0)
    assert abs(cut.n_frames - 100) <= 3
    assert cut.clip.n_frames == cut.n_frames
    np.testing.assert_array_equal(cut.clip.frames, steady.motion.frames[cut.start : cut.stop])
    # pose(i) and pose(j) differ by about the noise only, well under a typical step
    assert cut.distance < 0.5 * cut.median_step * 10


def test_loop_cut_skips_a_standing_start(steady):
    m = steady.motion
    rng = np.random.default_rng(1)
    still = np.repeat(m.frames[:1], 200, axis=0) + rng.normal(0, 0.05, size=(200, m.n_channels))
    take = m.with_frames(np.vstack([still, m.frames]))
    cut = best_loop_cut(take, 100.0)
    assert cut.start >= 200  # the still poses match best but do not move
    assert abs(cut.n_frames - 100) <= 3
    with pytest.raises(ParameterError):
        best_loop_cut(take, 100.0, used_frames=[[0, 150]])
    with pytest.raises(ParameterError):
        best_loop_cut(take, float("nan"))


# ---------------------------------------------------------------- average cycle
def test_wrap_times_unwrap_split_at_nan_and_ignore_jitter():
    c = np.mod(np.arange(25) / 10.0, 1.0)
    (w,) = wrap_times(c)
    np.testing.assert_allclose(w, [0.0, 10.0, 20.0])  # a run starting on a wrap counts it
    jitter = np.array([0.8, 0.9, 0.02, 0.97, 0.05, 0.3, 0.6, 0.9, 0.1])  # back across 0 once
    (w,) = wrap_times(jitter)
    assert len(w) == 2
    with_gap = np.concatenate([c[:15], [np.nan] * 3, c[:15]])
    runs = wrap_times(with_gap)
    assert len(runs) == 2
    np.testing.assert_allclose(runs[1], [18.0, 28.0])


def test_average_cycle_recovers_the_noise_free_cycle(steady):
    phase = np.mod(steady.phase, 1.0)
    avg = average_cycle(steady.motion, phase, 100)
    assert avg.n_frames == 100 and avg.channels == steady.motion.channels
    assert len(avg.metadata["pieces"]) == 5
    clean = joint_angles(steady.clean[:100])
    err = joint_angles(avg) - clean
    assert np.abs(err).mean() < 0.35  # noise 0.5 deg averaged over 5 pieces: about 0.2
    assert np.abs(joint_angles(steady.motion[:100]) - clean).mean() > 0.35  # one piece is noisier
    # the list of wraps gives the same average; the root starts where the first piece starts
    by_wraps = average_cycle(steady.motion, [0, 100, 200, 300, 400, 500], 100)
    np.testing.assert_allclose(by_wraps.frames[:, 6:], avg.frames[:, 6:], atol=1e-9)
    tz = steady.motion.channel_index("root", "tz")
    assert avg.frames[0, tz] == pytest.approx(steady.motion.frames[0, tz])
    with pytest.raises(ParameterError):
        average_cycle(steady.motion, [50.0], 100)


# ---------------------------------------------------------------------- figures
def test_figures_against_hand_computed_values():
    assert period_error(105.0, 100.0) == pytest.approx(0.05)
    assert np.isnan(period_error(105.0, float("nan")))
    # cyclic third differences of 0,0,0,1: 1, -3, 3, -1 -> mean norm 2, times fps^3
    assert cycle_jerk(np.array([[0.0], [0.0], [0.0], [1.0]]), fps=10.0) == pytest.approx(2000.0)
    assert seam(np.array([[0.0, 0], [1, 0], [2, 0], [3, 0]])) == pytest.approx(3.0)
    # steps around the loop: nine of 1 and the seam of 9: p90 = 1.8 (interpolated), p10 = 1
    ramp = np.arange(11.0)[:, None]
    assert step_spread(ramp[:-1]) == pytest.approx(1.8)
    held = np.array([[0.0]] * 9 + [[1.0]])  # holds, then one snap: zero steps
    assert step_spread(held) == np.inf
    # largest step around the loop (the seam of 9) over the take's p99 step (1)
    assert largest_step(ramp[:-1], ramp) == pytest.approx(9.0)
    mask = np.ones(11, dtype=bool)
    mask[5] = False  # steps touching frame 5 are not the take's
    assert largest_step(ramp[:-1], ramp ** 2, mask) == pytest.approx(9.0 / np.percentile(
        [1, 3, 5, 7, 13, 15, 17, 19], 99))
    square = np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]])
    take = np.array([[0.5, 0], [0.5, 0.5], [2, 0]])
    assert coverage(take, square) == pytest.approx(0.5)
    assert coverage(take, square, mask=np.array([True, False, True])) == pytest.approx(0.5)


def test_leg_ranges_root_closure_and_heading():
    n = 10
    root = np.zeros((n, 6))
    root[:, 3] = np.arange(n) * 0.1  # rx: 0 .. 0.9, does not close
    root[:, 4] = np.arange(n) * 1.0  # ry: turns 1 degree a frame
    m = _motion(
        {
            "lfemur.rx": np.linspace(-10, 20, n),
            "rtibia.rx": [0, 5] * 5,
            "lhumerus.rx": np.arange(n) * 9.0,
        },
        root,
    )
    assert leg_ranges(m) == {"lfemur.rx": pytest.approx(30.0), "rtibia.rx": pytest.approx(5.0)}
    gap, steps = root_closure(m)
    assert gap == pytest.approx(0.9) and steps == pytest.approx(9.0)
    assert heading_change(m) == pytest.approx(10.0)


@pytest.mark.parametrize("facing", [0.0, 90.0])
def test_root_pitch_is_free_of_the_heading(steady, facing):
    """Facing 90 degrees the Euler rx and rz of a ZYX root are degenerate; pitch is not."""
    n = 10
    frames = np.repeat(steady.clean.frames[:1], n, axis=0)
    m = steady.clean.with_frames(frames)
    frames[:, m.channel_index("root", "rz")] = 0.0
    frames[:, m.channel_index("root", "ry")] = facing + np.arange(n) * 0.5  # turns 0.5 deg a frame
    frames[:, m.channel_index("root", "rx")] = np.arange(n) * 0.1  # pitches 0.1 deg a frame
    m = m.with_frames(frames)
    gap, steps = root_closure(m)
    assert gap == pytest.approx(0.9, abs=1e-6) and steps == pytest.approx(9.0, rel=1e-4)
    assert heading_change(m) == pytest.approx(5.0, abs=1e-6)


def test_foot_skating_of_a_sliding_stand(steady):
    pose = steady.clean.frames[:1]
    n = 60
    still = steady.clean.with_frames(np.repeat(pose, n, axis=0))
    assert foot_skating_speed(still) == pytest.approx(0.0, abs=1e-9)
    frames = np.repeat(pose, n, axis=0)
    frames[:, still.channel_index("root", "tx")] += 2.0 * np.arange(n) / still.fps  # 2 units/s
    assert foot_skating_speed(still.with_frames(frames)) == pytest.approx(2.0)
    assert np.isnan(foot_skating_speed(cc.Motion(frames, still.channels)))  # no skeleton


def test_cycle_quality_and_targets(steady):
    take = steady.motion
    cut = best_loop_cut(take, 100.0)
    q0 = cycle_quality(cut.clip, take, method="loop cut", reference_period=100.0)
    q = cycle_quality(cut.clip, take, method="loop cut", reference_period=100.0, reference=q0)
    assert q.jerk_ratio == pytest.approx(1.0) and q.min_leg_range_ratio == pytest.approx(1.0)
    assert q.coverage_ratio == pytest.approx(1.0)
    assert q.seam < 1.5 * 10
    d = q.to_dict()
    assert d["method"] == "loop cut" and isinstance(d["leg_ranges"], dict)
    # a frozen cycle (one pose held) loses the legs' range and the coverage
    frozen = cut.clip.with_frames(np.repeat(cut.clip.frames[:1], cut.n_frames, axis=0))
    qf = cycle_quality(frozen, take, method="frozen", reference_period=100.0, reference=q)
    verdict = targets(qf)
    assert verdict["legs"] is False and verdict["coverage"] is False and verdict["period"] is True
    assert targets(q)["legs"] is True


def test_targets_thresholds():
    base = dict(
        method="x",
        n_frames=100,
        period_frames=100.0,
        reference_period=100.0,
        period_error=0.04,
        jerk=1.0,
        jerk_ratio=1.5,
        leg_ranges={},
        leg_range_ratios={},
        min_leg_range_ratio=0.85,
        min_leg_channel="lfemur.rx",
        min_femur_tibia_ratio=0.9,
        joint_ranges={},
        joint_range_ratios={},
        min_joint_range_ratio=0.85,
        min_joint="lfemur",
        step_spread=2.0,
        largest_step=1.0,
        seam=1.5,
        coverage=1.0,
        coverage_ratio=1.0,
        skating=1.0,
        skating_take=1.0,
        skating_ratio=1.0,
        root_closure_degrees=0.4,
        root_closure_steps=3.0,
        heading_change=0.0,
    )
    assert all(targets(CycleQuality(**base)).values())
    bad = targets(
        CycleQuality(**{**base, "period_error": -0.06, "root_closure_degrees": 0.6, "seam": 1.6})
    )
    assert (
        bad["period"] is False
        and bad["root"] is False
        and bad["seam"] is False
        and bad["jerk"] is True
    )
    assert targets(CycleQuality(**{**base, "jerk_ratio": float("nan")}))["jerk"] is None


# -------------------------------------------------------------------- benchmark
def test_benchmark_smoke_on_one_synthetic_walk(tmp_path):
    spec = importlib.util.spec_from_file_location("bench_quality", BENCH)
    bench = importlib.util.module_from_spec(spec)
    sys.modules["bench_quality"] = bench
    spec.loader.exec_module(bench)
    cases = bench.synthetic_cases(n_frames=240, period=60.0)
    report = bench.run_benchmark(cases, progress=False, plot_dir=tmp_path)
    (row,) = report["rows"]
    assert row["status"] == "ok"
    assert set(row["methods"]) == {"ours", "loop cut", "average"}
    assert row["autocorrelation_period"] == pytest.approx(60.0, rel=0.1)
    assert abs(row["methods"]["loop cut"]["period_error"]) < 0.16
    assert set(row["targets"]) == {"period", "root", "jerk", "legs", "seam", "coverage", "skating"}
    assert Path(row["figure"]).is_file() and Path(row["figure"]).parent == tmp_path
    text = bench.format_report(report)
    assert "loop cut" in text and "average" in text and "load average" in text


def test_benchmark_uses_used_frames_and_a_phase_with_gaps(steady, monkeypatch):
    """When extract reports used_frames and a phase with NaN outside them, they are used."""
    from types import SimpleNamespace

    spec = importlib.util.spec_from_file_location("bench_quality_used", BENCH)
    bench = importlib.util.module_from_spec(spec)
    sys.modules["bench_quality_used"] = bench
    spec.loader.exec_module(bench)
    m = steady.motion
    still = np.repeat(m.frames[:1], 150, axis=0)
    take = m.with_frames(np.vstack([still, m.frames]))
    phase = np.concatenate([np.full(150, np.nan), np.mod(steady.phase, 1.0)])
    cycle = m[100:200].with_frames(m.frames[100:200])
    fake = SimpleNamespace(
        cycle=cycle,
        period_frames=100.0,
        coordinate=np.nan_to_num(phase),
        phase=phase,
        used_frames=[[150, 750]],
        warnings=[],
    )
    monkeypatch.setattr(bench.cc, "extract", lambda motion: fake)
    row = bench.run_case(bench.Case("standing start", take))
    assert row["used_frames"] == [[150, 750]]
    assert row["autocorrelation_period"] == pytest.approx(100.0, rel=0.02)
    cut = row["methods"]["loop cut"]["extra"]
    assert cut["start"] >= 150
    avg = row["methods"]["average"]
    assert avg["extra"]["pieces"] == 5 and avg["period_frames"] == pytest.approx(100.0)
    assert row["methods"]["ours"]["period_error"] == pytest.approx(0.0, abs=0.02)


def test_leg_joint_ranges_ignore_marker_spikes_but_keep_held_extremes():
    cap = cc.datasets.make_periodic_capture(n_frames=240, period=120.0, noise=0.0, speed_variation=0.0,
                                            random_state=0)
    clip = cap.motion.window((0, 120))
    base = leg_joint_ranges(clip)
    i = clip.channel_index("ltoes", "rx")
    spiked = clip.frames.copy()
    spiked[60, i] += 40.0  # a one-frame marker glitch
    assert leg_joint_ranges(clip.with_frames(spiked))["ltoes"] == pytest.approx(base["ltoes"], rel=0.05)
    held = clip.frames.copy()
    held[60:64, i] += 40.0  # an extreme held for four frames is motion
    assert leg_joint_ranges(clip.with_frames(held))["ltoes"] > base["ltoes"] + 20
    # a joint's range spans its dofs: at least the largest single-dof range
    j = clip.channel_index("lfemur", "rx")
    assert base["lfemur"] >= np.ptp(clip.frames[:, j]) * 0.95


def test_coverage_simulation_bounds_what_an_average_can_reach(capsys):
    """benchmarks/sim_coverage.py: with two repetitions an average and a loop cut tie on
    smooth deviations and the cut wins on frame noise; with six the average wins on both."""
    path = Path(__file__).resolve().parents[2] / "benchmarks" / "sim_coverage.py"
    spec = importlib.util.spec_from_file_location("sim_coverage", path)
    sim = importlib.util.module_from_spec(spec)
    sys.modules["sim_coverage"] = sim
    spec.loader.exec_module(sim)
    table = {k: float(np.mean(v)) for k, v in sim.ratios(takes=3, seed=1).items()}
    assert table[(2, "smooth")] == pytest.approx(1.0, abs=0.03)
    assert table[(2, "noise")] < 0.8
    assert table[(6, "smooth")] > 1.15 and table[(6, "noise")] > 1.03
    assert table[(3, "smooth")] > 1.05 and table[(3, "noise")] < 0.95
    assert sim.main(["--takes", "1"]) == 0
    assert "repetitions" in capsys.readouterr().out


@pytest.mark.parametrize("order", ["ZYX", "XYZ"])
def test_root_orientation_of_single_turns(order):
    """A turn about y alone is heading, about x alone pitch, about z alone roll, each
    with its sign (right-handed, y up, z forward), whatever the Euler order."""
    from cyclecoord.motion import Motion
    from cyclecoord.quality.cycle_quality import root_orientation
    from cyclecoord.skeleton import Joint, Skeleton

    dofs = ("tx", "ty", "tz") + tuple("r" + a.lower() for a in order)
    sk = Skeleton((Joint("root", -1, [0, 0, 0], dofs, order, end_site=[0, 1, 0]),))
    rows = [{"ry": 30.0}, {"rx": 20.0}, {"rz": 20.0}, {"rz": -15.0}]
    frames = np.array([[r.get(d, 0.0) for _, d in sk.channels] for r in rows])
    hpr = root_orientation(Motion(frames, sk.channels, fps=30, skeleton=sk))
    np.testing.assert_allclose(hpr, [[30, 0, 0], [0, 20, 0], [0, 0, 20], [0, 0, -15]], atol=1e-9)


def test_foot_skating_leaves_out_a_foot_swinging_in_the_air():
    """Heights are read on the up axis (y): the left leg raised 60 to 80 degrees out to the
    side and swinging there (its feet 5 to 7.6 units over a floor at 0.5, beyond a quarter
    leg) is never in contact, though its depth (z) stays that of the standing right foot.
    Standing still the figure is 0; the whole body sliding 2 units/s it is 2, the
    standing foot's speed, whatever the swinging foot does."""
    from _legs import legs_skeleton, make_motion

    m = make_motion(legs_skeleton(), T=60, fps=30.0)
    f = m.frames.copy()
    f[:, m.channels.index(("lfemur", "rz"))] = 60.0 + 20.0 * np.arange(60) / 60
    assert foot_skating_speed(m.with_frames(f)) == pytest.approx(0.0, abs=1e-12)
    f[:, m.channels.index(("root", "tx"))] = 2.0 * np.arange(60) / 30.0
    assert foot_skating_speed(m.with_frames(f)) == pytest.approx(2.0, rel=1e-12)
    # the floor is the motion's own: the same 20 units higher reads the same
    high = f.copy()
    high[:, m.channels.index(("root", "ty"))] += 20.0
    assert foot_skating_speed(m.with_frames(high)) == pytest.approx(2.0, rel=1e-12)
    # three frames are measured, two are too few; feet faster than a leg (10.5 units) a
    # second are never in contact: 0
    assert foot_skating_speed(m.with_frames(f[:3])) == pytest.approx(2.0, rel=1e-12)
    assert np.isnan(foot_skating_speed(m.with_frames(f[:2])))
    f[:, m.channels.index(("root", "tx"))] = 12.0 * np.arange(60) / 30.0
    assert foot_skating_speed(m.with_frames(f)) == 0.0


def test_leg_range_ratios_keep_a_reference_range_of_exactly_min_leg_range():
    """Channels whose reference range is below MIN_LEG_RANGE (2 degrees) are left out of
    the ratios; a range of exactly 2 degrees is not below it and is kept."""
    from cyclecoord.quality.cycle_quality import MIN_LEG_RANGE

    assert MIN_LEG_RANGE == 2.0
    n = 40
    square = np.where(np.arange(n) % 20 < 10, 0.0, 1.0)  # held 10 frames: kept by the median
    m = _motion({"lfemur.rx": 2.0 * square, "ltibia.rx": 1.5 * square,
                 "rfemur.rx": 10.0 * square})
    ref = cycle_quality(m, m)
    assert ref.leg_ranges == {"lfemur.rx": 2.0, "ltibia.rx": 1.5, "rfemur.rx": 10.0}
    assert ref.joint_ranges == {"lfemur": 2.0, "ltibia": 1.5, "rfemur": 10.0}
    q = cycle_quality(m, m, reference=ref)
    assert q.leg_range_ratios == {"lfemur.rx": 1.0, "rfemur.rx": 1.0}
    assert q.joint_range_ratios == {"lfemur": 1.0, "rfemur": 1.0}


def test_autocorrelation_period_takes_a_peak_at_the_first_lag_searched(monkeypatch):
    """A peak exactly at min_lag is a local maximum like any other (the lags examined run
    one past each end).  Joint angles cos(2 pi t / 32) + 0.7 cos(2 pi t / 64) at 64 fps,
    lags 0.5-63/64 s (32-63 frames): the autocorrelation peaks at 32 (normalised about
    (1 - 0.49) / 1.49 = 0.34, over min_correlation) and rises again only towards 64,
    outside the range: the period is lag 32, refined by at most half a frame (the slower
    component tilts the parabola towards shorter lags)."""
    import types

    from cyclecoord.quality import reference

    t = np.arange(640)
    x = (np.cos(2 * np.pi * t / 32) + 0.7 * np.cos(2 * np.pi * t / 64))[:, None]
    monkeypatch.setattr(reference, "joint_angles", lambda motion: x.copy())
    take = types.SimpleNamespace(fps=64.0)
    p = autocorrelation_period(take, min_lag=0.5, max_lag=63 / 64)
    assert 31.5 <= p <= 32.5


# ------------------------------------------------------------ helpers, known answers
def test_joint_columns_with_and_without_a_root():
    from cyclecoord.quality.reference import joint_columns

    m = _motion({"lfemur.rx": [0.0, 1.0], "lfemur.tx": [2.0, 3.0]})
    np.testing.assert_array_equal(joint_columns(m), [6, 7])
    bare = cc.Motion(np.zeros((2, 3)), [("a", "rx"), ("b", "rx"), ("b", "ry")], fps=10.0)
    np.testing.assert_array_equal(joint_columns(bare), [0, 1, 2])


def test_joint_angles_unwrap_rotations_only_and_two_frames():
    """Rotation channels (dof r...) are unwrapped from two frames on; a translation channel
    of a joint is left as stored; ``like`` shifts rotations by whole turns towards it."""
    m = _motion({"a.rx": [170.0, -170.0], "a.tx": [170.0, -170.0]})
    np.testing.assert_allclose(joint_angles(m), [[170, 170], [190, -170]])
    # means 180 and 0: like 500 is 320 from the first (one turn up), 100 from the second's 0
    # (no turn: translations never move)
    np.testing.assert_allclose(joint_angles(m, like=np.array([500.0, 500.0])),
                               [[530, 170], [550, -170]])
    # (-200 - 180) / 360 = -1.06 rounds to one turn down; (-10 - 180) / 360 = -0.53 too
    np.testing.assert_allclose(joint_angles(m, like=np.array([-200.0, 0.0])),
                               [[-190, 170], [-170, -170]])
    np.testing.assert_allclose(joint_angles(m, like=np.array([-10.0, 0.0])),
                               [[-190, 170], [-170, -170]])
    # (10 - 180) / 360 = -0.47: no turn
    np.testing.assert_allclose(joint_angles(m, like=np.array([10.0, 0.0])),
                               [[170, 170], [190, -170]])
    with pytest.raises(ParameterError, match="like must have 2 values"):
        joint_angles(m, like=np.zeros(3))
    one = _motion({"a.rx": [-170.0]})
    np.testing.assert_allclose(joint_angles(one), [[-170.0]])


def test_median_step_and_its_mask():
    from cyclecoord.quality.reference import median_step

    x = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 4.0], [6.0, 8.0], [6.0, 9.0]])  # 5, 0, 5, 1
    assert median_step(x) == 3.0  # the mean of the middle two of 0, 1, 5, 5
    assert median_step(x, [True, True, False, True, True]) == 3.0  # steps 5 and 1
    assert median_step(x, [False, True, True, False, False]) == 0.0  # step 1 -> 2 only
    assert median_step(x, [True, False, True, False, True]) != median_step(x, None)
    assert np.isnan(median_step(x, [True, False, True, False, True]))  # no two in a row
    assert np.isnan(median_step(x[:1]))


def test_used_mask_half_open_ranges_and_bounds():
    from cyclecoord.quality.reference import used_mask

    np.testing.assert_array_equal(used_mask(3, None), [True, True, True])
    np.testing.assert_array_equal(used_mask(6, [[1, 3], [4, 5]]),
                                  [False, True, True, False, True, False])
    np.testing.assert_array_equal(used_mask(4, [(0, 4)]), [True] * 4)
    np.testing.assert_array_equal(used_mask(4, [[3, 4]]), [False, False, False, True])
    for bad in ([-1, 2], [2, 2], [3, 2], [0, 5]):
        with pytest.raises(ParameterError, match="not inside the motion's 4 frames"):
            used_mask(4, [bad])


def _brute_loop_cut(x, period, tol, mask):
    """Every cut by loops: lengths n from ceil(period (1 - tol)) (at least 2) to
    floor(period (1 + tol)), shorter than the take; the cut's mean step at least the take's
    median step; frames i..j in the mask; the smallest |x[j] - x[i]|, the first found on
    ties (shortest, then earliest)."""
    T = len(x)
    steps = [float(np.linalg.norm(x[t + 1] - x[t])) for t in range(T - 1)]
    med = float(np.median(steps))
    best = None
    for n in range(max(2, int(np.ceil(period * (1 - tol)))), int(np.floor(period * (1 + tol))) + 1):
        for i in range(T - n):
            j = i + n
            if sum(steps[i:j]) / n < med or not all(mask[i : j + 1]):
                continue
            d = float(np.linalg.norm(x[j] - x[i]))
            if best is None or d < best[0]:
                best = (d, i, j)
    return best, med


@pytest.mark.parametrize("seed", range(4))
def test_best_loop_cut_equals_brute_force(seed):
    rng = np.random.default_rng(seed)
    T = 40
    t = np.arange(T)
    a = 30 * np.sin(2 * np.pi * t / 9.0) + rng.normal(0, 3, T)
    b = 20 * np.cos(2 * np.pi * t / 9.0) + rng.normal(0, 3, T)
    a[:6] = a[6]  # a still start
    m = _motion({"lfemur.rx": a, "ltibia.rx": b})
    x = joint_angles(m)
    for period, tol, used in ((9.0, 0.15, None), (9.4, 0.3, [[0, 20], [22, 40]]),
                              (2.0, 0.0, None), (33.0, 0.1, None), (38.0, 0.1, None)):
        mask = np.ones(T, bool)
        if used is not None:
            mask[:] = False
            for s, e in used:
                mask[s:e] = True
        want, med = _brute_loop_cut(x, period, tol, mask)
        if want is None:
            with pytest.raises(ParameterError, match="no loop cut"):
                best_loop_cut(m, period, tol, used)
            continue
        cut = best_loop_cut(m, period, tol, used)
        assert (cut.start, cut.stop) == (want[1], want[2]), (period, tol)
        assert cut.distance == pytest.approx(want[0], rel=1e-12)
        assert cut.median_step == pytest.approx(med, rel=1e-12)
        assert cut.period_frames == period and type(cut.period_frames) is float
        assert cut.n_frames == want[2] - want[1] == cut.clip.n_frames
        np.testing.assert_array_equal(cut.clip.frames, m.frames[want[1] : want[2]])
    # the default tolerance, 0.15: a period of 6 frames allows 6 alone (5.1 to 6.9)
    want, _ = _brute_loop_cut(x, 6.0, 0.15, np.ones(T, bool))
    cut = best_loop_cut(m, 6.0)
    assert (cut.start, cut.stop) == (want[1], want[2]) and cut.n_frames == 6


def test_best_loop_cut_arguments_and_no_fit():
    t = np.arange(12)
    m = _motion({"lfemur.rx": 10 * np.sin(2 * np.pi * t / 4)})
    with pytest.raises(ParameterError, match=">= 2"):
        best_loop_cut(m, 1.99)
    assert best_loop_cut(m, 2.0, 0.0).n_frames == 2
    with pytest.raises(ParameterError, match=r"tolerance must be in \[0, 1\)"):
        best_loop_cut(m, 4.0, 1.0)
    with pytest.raises(ParameterError, match="tolerance"):
        best_loop_cut(m, 4.0, -0.01)
    assert best_loop_cut(m, 4.0, 0.0).n_frames == 4
    # 11 frames at most between the first and the last of 12: a period of 12 fits none
    with pytest.raises(ParameterError, match=r"no loop cut of 12-12 frames .*\(12 frames, 12 used\)"):
        best_loop_cut(m, 12.0, 0.0)
    assert best_loop_cut(m, 11.0, 0.0).n_frames == 11


def test_wrap_times_interpolate_and_offset_runs():
    """0.6, 0.9, then 0.2 (1.2 unwrapped): the turn ends a third of the way from frame 1 to
    frame 2; a run after a NaN counts its frames from the take's start; levels from the
    first whole number reached to the last."""
    (w,) = wrap_times(np.array([0.6, 0.9, 0.2, 0.5]))
    np.testing.assert_allclose(w, [1 + 1 / 3], rtol=1e-14)
    runs = wrap_times(np.array([np.nan, np.nan, 0.6, 0.9, 0.2, 0.5, np.nan, 0.0, 0.5]))
    assert len(runs) == 2
    np.testing.assert_allclose(runs[0], [3 + 1 / 3], rtol=1e-14)
    np.testing.assert_array_equal(runs[1], [7.0])  # starts on a wrap
    (w,) = wrap_times(np.array([0.5, 0.75, 0.0, 0.25, 0.5, 0.75, 0.0]))  # on frames exactly
    np.testing.assert_allclose(w, [2.0, 6.0], rtol=1e-14)
    (w,) = wrap_times(np.array([0.1, 0.4, 0.7]))  # no turn completed
    assert w.size == 0 and w.dtype == float
    assert wrap_times(np.array([np.nan, np.nan])) == []
    with pytest.raises(ParameterError, match="one value per frame"):
        wrap_times(np.zeros((3, 2)))


def test_sample_and_rot_y_by_hand():
    from cyclecoord.quality.reference import _rot_y, _sample

    x = np.array([[0.0, 10.0], [1.0, 20.0], [3.0, 40.0]])
    np.testing.assert_allclose(_sample(x, np.array([0.0, 0.25, 1.5, 2.0])),
                               [[0, 10], [0.25, 12.5], [2, 30], [3, 40]])
    # +90 degrees about y takes +x to -z and +z to +x
    dx, dz = _rot_y(np.array([1.0, 0.0]), np.array([0.0, 1.0]), 90.0)
    np.testing.assert_allclose(dx, [0, 1], atol=1e-15)
    np.testing.assert_allclose(dz, [-1, 0], atol=1e-15)


def _walk_pieces(headings, starts, heights, n=4):
    """A root walking one unit a frame straight ahead (local +x, world (cos h, -sin h) in x, z)
    for ``n`` frames per piece, each piece its own heading, start and height; a joint
    channel counting frames."""
    rows = []
    for h, (x0, z0), y in zip(headings, starts, heights):
        a = np.radians(h)
        for k in range(n):
            rows.append([x0 + k * np.cos(a), y, z0 - k * np.sin(a), 5.0, h, -5.0])
    rows.append(rows[-1])
    root = np.array(rows)
    return _motion({"lfemur.rx": np.arange(len(rows), dtype=float)}, root=root)


def test_average_cycle_root_relative_to_each_piece_by_hand():
    """Two pieces of 4 frames walking straight ahead at headings 30 and 120 from different
    places: the average walks straight ahead from the first piece's start at its heading;
    height averaged (1 and 3: 2); the joint channel's frames 0-3 and 4-7 average to 2-5."""
    m = _walk_pieces([30.0, 120.0], [(5.0, 2.0), (7.0, -3.0)], [1.0, 3.0])
    avg = average_cycle(m, [0, 4, 8], 4)
    k = np.arange(4)
    a = np.radians(30.0)
    np.testing.assert_allclose(avg.frames[:, 0], 5 + k * np.cos(a), atol=1e-12)
    np.testing.assert_allclose(avg.frames[:, 2], 2 - k * np.sin(a), atol=1e-12)
    np.testing.assert_allclose(avg.frames[:, 1], 2.0)
    np.testing.assert_allclose(avg.frames[:, [3, 4, 5]], np.tile([5.0, 30.0, -5.0], (4, 1)),
                               atol=1e-12)
    np.testing.assert_allclose(avg.frames[:, 6], [2, 3, 4, 5])
    assert avg.metadata["pieces"] == [(0.0, 4.0), (4.0, 8.0)]
    assert avg.start_frame == 0 and avg.source.startswith("average cycle of")
    # the wraps sorted first; a piece must end by the last frame (8 of 9 frames)
    assert average_cycle(m, [8, 0, 4], 4).metadata["pieces"] == [(0.0, 4.0), (4.0, 8.0)]
    short = m[:8]
    assert average_cycle(short, [0, 4, 8], 4).metadata["pieces"] == [(0.0, 4.0)]
    assert average_cycle(m, [-1, 0, 0, 4], 4).metadata["pieces"] == [(0.0, 4.0)]


def test_average_cycle_resamples_fractional_pieces():
    """Piece (0.5, 4.5) in 2 frames: times 0.5 and 2.5; piece (4.5, 6.5): 4.5 and 5.5."""
    m = _motion({"lfemur.rx": np.arange(9.0) ** 2})
    avg = average_cycle(m, [0.5, 4.5, 6.5], 2)
    lin = lambda t: np.interp(t, np.arange(9.0), np.arange(9.0) ** 2)  # noqa: E731
    np.testing.assert_allclose(avg.frames[:, 6], [(lin(0.5) + lin(4.5)) / 2,
                                                 (lin(2.5) + lin(5.5)) / 2])


def test_average_cycle_coordinate_or_wraps_and_length():
    """An array of one value in [0, 1) per frame is a coordinate; other arrays are wraps."""
    m = _motion({"lfemur.rx": np.arange(9.0)})
    phase = np.mod(np.arange(9) / 4.0, 1.0)  # wraps at 0, 4, 8
    assert average_cycle(m, phase, 4).metadata["pieces"] == [(0.0, 4.0), (4.0, 8.0)]
    phase[3] = np.nan  # the first piece spans a NaN: dropped; the run 4..8 gives one
    assert average_cycle(m, phase, 4).metadata["pieces"] == [(4.0, 8.0)]
    nine = np.array([0.0, 4.0, 8.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0])  # T values, not in [0, 1)
    assert average_cycle(m, nine, 4).metadata["pieces"] == [(0.0, 1.0), (1.0, 4.0), (4.0, 8.0)]
    halves = np.array([0.0, 0.5, 1.0, 1.5, 1.5, 1.5, 1.5, 1.5, 1.5])  # 1.0 and 1.5 >= 1
    assert average_cycle(m, halves, 2).metadata["pieces"] == [(0.0, 0.5), (0.5, 1.0), (1.0, 1.5)]
    ones = np.array([0.0, 0.5, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0])  # 1.0 is not in [0, 1)
    assert average_cycle(m, ones, 2).metadata["pieces"] == [(0.0, 0.5), (0.5, 1.0)]
    for bad in (1, 2.5, 0):
        with pytest.raises(ParameterError, match="integer >= 2"):
            average_cycle(m, [0, 4, 8], bad)
    assert average_cycle(m, [0, 4, 8], 2.0).n_frames == 2
    with pytest.raises(ParameterError, match="wrap at least twice"):
        average_cycle(m, [0, 9], 4)


def _cosines(T: int, *terms) -> cc.Motion:
    """One joint channel, a sum of ``(amplitude, period in frames)`` cosines, at 10 fps."""
    t = np.arange(T)
    return _motion({"lfemur.rx": sum(a * np.cos(2 * np.pi * t / p) for a, p in terms)})


def test_autocorrelation_period_lag_bounds():
    """At 10 fps the lags searched are 0.3-3 s (3-30 frames), and at most 80 % of the
    longest used range: a cosine of 40 frames (4 s) is found only when max_lag allows
    it and 40 <= 0.8 T (no lag past hi + 0.5 is returned); one of 4 frames (0.4 s) only
    when min_lag is under 0.4 s; the search needs at least two lags beyond its first
    (hi - lo >= 2); a constant take has no period."""
    assert np.isnan(autocorrelation_period(_cosines(200, (10, 40))))
    forty = autocorrelation_period(_cosines(200, (10, 40)), max_lag=6.0)
    assert forty == pytest.approx(40, abs=0.05)
    forty = autocorrelation_period(_cosines(50, (10, 40)), max_lag=10.0)
    assert forty == pytest.approx(40, abs=0.1)
    # 0.8 of 49 frames is 39: no lag past 39 and a half (the parabola's half frame)
    assert autocorrelation_period(_cosines(49, (10, 40)), max_lag=10.0) <= 39.5
    used = [[0, 50], [60, 109]]  # the longest range 50 frames: 0.8 of it is 40
    assert autocorrelation_period(_cosines(110, (10, 40)), used, max_lag=10.0) == pytest.approx(
        40, abs=0.05)
    assert autocorrelation_period(_cosines(110, (10, 40)), [[0, 49], [60, 109]],
                                  max_lag=10.0) <= 39.5
    four = _cosines(200, (10, 4))
    assert autocorrelation_period(four) == pytest.approx(4, abs=0.05)
    assert autocorrelation_period(four, min_lag=0.6) == pytest.approx(8, abs=0.05)
    assert autocorrelation_period(four, max_lag=0.5) == pytest.approx(4, abs=0.05)  # lags 3-5
    assert np.isnan(autocorrelation_period(four, max_lag=0.4))  # lags 3-4
    assert np.isnan(autocorrelation_period(_motion({"lfemur.rx": np.full(200, 7.0)})))


def test_autocorrelation_period_first_strong_peak_and_min_correlation():
    """cos(2 pi t / 20) + c cos(2 pi t / 10) autocorrelates as (cos(2 pi L / 20) + c^2
    cos(2 pi L / 10)) / (1 + c^2): peaks at lag 10, (c^2 - 1) / (c^2 + 1) of the one at
    20.  c = 2: 0.6 of it, under 0.8 (strong): the period is 20; c = 4: 0.88, so 10,
    (0.9 on the biased curve: its sums hold 390 and 380 pairs), unless ``strong`` is 0.95 or the peak's correlation 0.88 is under ``min_correlation``."""
    two = _cosines(400, (1, 20), (2, 10))
    assert autocorrelation_period(two) == pytest.approx(20, abs=0.05)
    four = _cosines(400, (1, 20), (4, 10))
    assert autocorrelation_period(four) == pytest.approx(10, abs=0.05)
    assert autocorrelation_period(four, strong=0.95) == pytest.approx(20, abs=0.05)
    assert autocorrelation_period(four, min_correlation=0.95) == pytest.approx(20, abs=0.05)
    assert autocorrelation_period(four, min_correlation=0.85) == pytest.approx(10, abs=0.05)


def test_average_cycle_heading_unwrapped_and_roots_without_heading():
    """A turn in place crossing 180 degrees (170, 175, 180, -175: +5 a frame) averages as a
    steady turn from the first heading; a root without ry averages its translation
    relative to each piece's start, unturned; a root without tx/tz as it is."""
    rows = np.zeros((9, 6))
    rows[:, 4] = [170.0, 175.0, 180.0, -175.0, 10.0, 15.0, 20.0, 25.0, 25.0]
    rows[:, 0] = [0, 0, 0, 0, 50, 51, 52, 53, 53]
    m = _motion({"a.rx": np.zeros(9)}, root=rows)
    avg = average_cycle(m, [0, 4, 8], 4)
    np.testing.assert_allclose(avg.frames[:, 4], [170, 175, 180, 185])
    # the first piece stands; the second moves 1 a frame along world x, which its first
    # heading (10) turns into local (cos 10, sin 10); the mean is half that, turned into
    # the first piece's heading (170)
    a = np.radians(10.0)
    local = np.array([np.cos(a), np.sin(a)]) * np.arange(4)[:, None] / 2  # (dx, dz) local
    b = np.radians(170.0)
    np.testing.assert_allclose(avg.frames[:, 0], np.cos(b) * local[:, 0] + np.sin(b) * local[:, 1],
                               atol=1e-12)
    np.testing.assert_allclose(avg.frames[:, 2], -np.sin(b) * local[:, 0] + np.cos(b) * local[:, 1],
                               atol=1e-12)
    # no heading channel: translations relative to each piece's start, not turned
    flat = cc.Motion(np.column_stack([rows[:, 0], rows[:, 2] + 3.0, np.arange(9.0)]),
                     [("root", "tx"), ("root", "tz"), ("a", "rx")], fps=10.0)
    avg = average_cycle(flat, [0, 4, 8], 4)
    np.testing.assert_allclose(avg.frames[:, 0], np.arange(4) / 2)
    np.testing.assert_allclose(avg.frames[:, 1], 3.0)
    np.testing.assert_allclose(avg.frames[:, 2], [2, 3, 4, 5])
    # only tx: no relative translation (both tx and tz are needed)
    onlyx = cc.Motion(np.column_stack([rows[:, 0], np.arange(9.0)]),
                      [("root", "tx"), ("a", "rx")], fps=10.0)
    np.testing.assert_allclose(average_cycle(onlyx, [0, 4, 8], 4).frames[:, 0],
                               [25, 25.5, 26, 26.5])


def test_autocorrelation_period_first_lag_and_a_unit_energy_take():
    """The lags start at min_lag (0.5 s: lag 5 at 10 fps, with lag 4 only as its left
    neighbour): a 0.4 s cosine reads its second peak, 8.  A square wave of +-1/8 and
    period 8 over 64 frames has energy exactly 1 (and every overlap's product under 1):
    its period is still 8."""
    four = _cosines(200, (10, 4))
    assert autocorrelation_period(four, min_lag=0.5) == pytest.approx(8, abs=0.05)
    square = np.where(np.arange(64) % 8 < 4, 0.125, -0.125)
    assert float(np.sum(square**2)) == 1.0 and square.mean() == 0.0
    m = _motion({"lfemur.rx": square})
    assert autocorrelation_period(m) == pytest.approx(8, abs=0.1)


def test_average_cycle_reads_two_values_as_wraps_and_three_as_a_coordinate():
    """A coordinate needs three frames to be told from wrap times: two values in [0, 1)
    for a 2-frame take are the wraps 0 and 0.5 (one piece); three for a 3-frame take are a
    coordinate, which never wraps there (refused)."""
    two = _motion({"lfemur.rx": [0.0, 4.0]})
    assert average_cycle(two, np.array([0.0, 0.5]), 2).metadata["pieces"] == [(0.0, 0.5)]
    three = _motion({"lfemur.rx": [0.0, 4.0, 8.0]})
    with pytest.raises(ParameterError, match="wrap at least twice"):
        average_cycle(three, np.array([0.0, 0.5, 0.9]), 2)


def test_autocorrelation_period_looks_one_frame_either_side_of_a_short_biased_peak():
    """18 frames at 10 fps, lags 2-14 searched (neighbours 1 and 15): the biased curve's only
    peak whose normalised correlation reaches 0.3 is at lag 4 (0.236 against 0.221 and
    0.029); 10 % of 4 frames is under one, so the normalised curve is read at lags 3-5 only
    -- not at lag 2, where it is higher (0.401 against 0.339) -- and the parabola through
    lags 3, 4, 5 gives the period."""
    x = np.array([1, 1, 2, 2, 1, 2, 0, 1, 1, 1, 0, 0, 1, -1, -1, -1, 1, 0], dtype=float)
    y = x - x.mean()

    def r(lag):
        a, b = y[:-lag], y[lag:]
        return float(np.sum(a * b) / np.sqrt(np.sum(a * a) * np.sum(b * b)))

    def biased(lag):
        return float(np.sum(y[:-lag] * y[lag:]) / np.sum(y * y))

    assert biased(3) < biased(4) > biased(5) and r(4) >= 0.3 and r(2) > r(4)
    want = 4 + 0.5 * (r(3) - r(5)) / (r(3) - 2 * r(4) + r(5))
    got = autocorrelation_period(_motion({"lfemur.rx": x}), min_lag=0.2, max_lag=1.5)
    assert got == pytest.approx(want, abs=1e-9)
