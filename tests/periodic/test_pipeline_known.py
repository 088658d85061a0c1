"""Known answers of the pipeline's helpers and every extract option reaching its stage
(issue 27: mutation score).

The helpers are run on hand-made coordinates and stand-ins; the options on a short
synthetic walk (240 frames, a 40-frame period), each checked against the documented
direction of its effect.
"""

from types import SimpleNamespace as NS

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import NoPeriodicMotionError, ParameterError
from cyclecoord.periodic import pipeline
from cyclecoord.periodic.pipeline import cycle_lengths
from cyclecoord.quality.metrics import jerk_summary, loop_closure


# ------------------------------------------------------------------ cycle_lengths
def test_cycle_lengths_by_hand():
    assert cycle_lengths(np.array([])).size == 0
    assert cycle_lengths(np.array([0.3])).size == 0
    assert cycle_lengths(np.array([0.0, 0.5, 0.99])).size == 0  # under one turn
    # exactly one turn: it ends at the last frame
    np.testing.assert_allclose(cycle_lengths(np.array([0.0, 0.5, 1.0])), [2.0])
    # from u[0] = 0.25: levels 1.25 and 2.25, crossed at 2.5 and 6.5 (0.25 a frame... by
    # hand: u = 0.25 + 0.4 t reaches 1.25 at t = 2.5, 2.25 at t = 5)
    u = 0.25 + 0.4 * np.arange(7)
    np.testing.assert_allclose(cycle_lengths(u), [2.5, 2.5])
    # the count of levels is of the turns from u[0] (2.4 here), not of u's last value (3.0)
    u = 0.6 + 0.4 * np.arange(7)
    np.testing.assert_allclose(cycle_lengths(u), [2.5, 2.5])
    # a step back is not a crossing: the running maximum is read
    u = np.array([0.0, 0.6, 0.2, 0.8, 1.2, 1.6, 2.1])
    # 1.0 crossed between frames 3 (0.8) and 4 (1.2): 3.5; 2.0 between 5 (1.6) and 6 (2.1): 5.8
    np.testing.assert_allclose(cycle_lengths(u), [3.5, 5.8 - 3.5])
    # a level reached exactly on a frame after a plateau
    u = np.array([0.0, 0.5, 0.5, 1.0, 1.0, 2.0])
    np.testing.assert_allclose(cycle_lengths(u), [3.0, 2.0])
    # turns over u[0] + 1 at the first frame past it
    np.testing.assert_allclose(cycle_lengths(np.array([0.0, 2.0])), [0.5, 0.5])


# ------------------------------------------------------------------ _run_jerk
def test_run_jerk_weights_runs_of_eight_frames_or_more_by_length():
    rng = np.random.default_rng(0)
    x = np.cumsum(rng.normal(size=(40, 2)), axis=0)
    a = jerk_summary(x[0:8], 30.0)
    b = jerk_summary(x[20:32], 30.0)
    got = pipeline._run_jerk(x, [(0, 8), (10, 17), (20, 32)], 30.0)
    assert got == pytest.approx((8 * a + 12 * b) / 20)
    assert np.isnan(pipeline._run_jerk(x, [(0, 7), (10, 12)], 30.0))
    assert np.isnan(pipeline._run_jerk(x, [], 30.0))


# ------------------------------------------------------------------ _windings
def _fit(weak_gap=False, n_components=1):
    return NS(weak_gap=weak_gap, selection=NS(gap=1.7, scale=2.5), barcode=None,
              est=NS(n_components_=n_components))


class _Refused(Exception):
    pass


def _fail(msg, fit):
    return _Refused(msg)


def test_windings_refuse_under_min_turns_and_accept_exactly_it():
    t = np.arange(81, dtype=float)
    u = t / 20.0  # 4 turns exactly over 81 frames, period 20
    used = np.ones(81, bool)
    notes = []
    wind, period = pipeline._windings(_fit(), used, u, [(0, 81)], notes, _fail, 4.0)
    assert wind.turns == pytest.approx(4.0) and period == pytest.approx(20.0)
    assert notes == []
    with pytest.raises(_Refused, match="turns only 4.00 times over the 81 steady frames"):
        pipeline._windings(_fit(), used, u, [(0, 81)], [], _fail, 4.01)


def test_windings_a_weak_gap_is_accepted_when_the_coordinate_winds_regularly(monkeypatch):
    monkeypatch.setattr(pipeline, "not_clear_reason", lambda sel, bc: "the bar is weak")
    t = np.arange(200, dtype=float)
    u = t / 20.0
    used = np.ones(200, bool)
    notes = []
    wind, period = pipeline._windings(_fit(weak_gap=True), used, u, [(0, 200)], notes, _fail, 1.5)
    assert period == pytest.approx(20.0)
    assert len(notes) == 1 and notes[0].startswith("the H1 bar stands only 1.70x")
    assert "winds 9.9 times, regularly (spread 0%)" in notes[0]
    # irregular windings (lengths 10 and 40 alternating): refused, with the reason
    inc = np.concatenate([np.full(10, 0.1) if k % 2 == 0 else np.full(40, 0.025) for k in range(8)])
    u = np.r_[0.0, np.cumsum(inc)]
    used = np.ones(u.size, bool)
    with pytest.raises(_Refused, match="the bar is weak, and its coordinate winds irregularly"):
        pipeline._windings(_fit(weak_gap=True), used, u, [(0, u.size)], [], _fail, 1.5)
    # the same windings on a clear bar: accepted with a note that they vary
    notes = []
    pipeline._windings(_fit(), used, u, [(0, u.size)], notes, _fail, 1.5)
    assert len(notes) == 1 and notes[0].startswith("the complete windings vary by")


def test_windings_without_a_complete_winding_count_frames_per_turn(monkeypatch):
    """Two runs of 0.9 turns each (no complete winding in either): the period is the used
    frames less one per run over the turns, (2 x 37 - 2) / 1.8 = 40; a weak gap then has
    no period to trust and is refused."""
    monkeypatch.setattr(pipeline, "not_clear_reason", lambda sel, bc: "weak")
    u = np.full(100, np.nan)
    u[0:37] = np.arange(37) * 0.025
    u[50:87] = 5.0 + np.arange(37) * 0.025
    used = ~np.isnan(u)
    runs = [(0, 37), (50, 87)]
    notes = []
    wind, period = pipeline._windings(_fit(), used, u, runs, notes, _fail, 1.5)
    assert np.isnan(wind.period_frames) and wind.turns == pytest.approx(1.8)
    assert period == pytest.approx(72 / 1.8)
    with pytest.raises(_Refused, match="winds irregularly"):
        pipeline._windings(_fit(weak_gap=True), used, u, runs, [], _fail, 1.5)


def test_windings_note_several_connected_components():
    u = np.arange(100, dtype=float) / 20.0
    notes = []
    pipeline._windings(_fit(n_components=3), np.ones(100, bool), u, [(0, 100)], notes, _fail, 1.5)
    assert len(notes) == 1 and "scale 2.5 has 3 connected components" in notes[0]
    notes = []
    pipeline._windings(_fit(n_components=1), np.ones(100, bool), u, [(0, 100)], notes, _fail, 1.5)
    assert notes == []


# ------------------------------------------------------------------ _cycle_figures
def test_cycle_figures_by_hand():
    poses = np.array([[0.0], [1.0], [2.0], [3.0], [10.0]])
    typ = NS(frames=np.array([0.0, 0.5, 1.0, 1.5, 2.0, 1.5, 1.0, 0.5])[:, None])  # 0 to 2 and back
    runs = [(0, 3), (3, 5)]
    rows = np.arange(5)
    jerk, closure, d = pipeline._cycle_figures(NS(poses=poses), typ, runs, rows, 10.0)
    assert np.isnan(jerk["original"])  # no run of 8 frames
    assert jerk["cycle"] == pytest.approx(jerk_summary(typ.frames, 10.0, cyclic=True))
    assert closure == pytest.approx(loop_closure(typ.frames))
    # distances to the segment 0-2: 0, 0, 0, 1, 8
    assert d["median"] == pytest.approx(0.0) and d["max"] == pytest.approx(8.0)
    assert d["p90"] == pytest.approx(np.percentile([0, 0, 0, 1, 8], 90))
    # steps inside runs: 1, 1 and 7 (not the 1 between frames 2 and 3)
    assert d["median_frame_step"] == pytest.approx(1.0)
    assert d["p99_frame_step"] == pytest.approx(np.percentile([1, 1, 7], 99))
    assert d["largest_cycle_step"] == pytest.approx(0.5)


# ------------------------------------------------------------------ _with_auto_delay
def test_auto_delay_retries_with_the_delay_and_says_why(monkeypatch):
    calls = []

    def fake(motion, frames=None, delay=None, **options):
        calls.append((delay, options))
        if delay is None:
            raise NoPeriodicMotionError(
                "no periodic motion found: no bar stands clear; try --delay",
                result=NS(reason="no periodic motion found: no bar stands clear; try --delay"))
        return NS(warnings=["later"])

    monkeypatch.setattr(pipeline, "extract", fake)
    res = pipeline._with_auto_delay("m", (1, 9), {"pca": 3})
    assert [c[0] for c in calls] == [None, pipeline.AUTO_DELAY] and calls[1][1] == {"pca": 3}
    assert res.warnings[0] == (
        "read with a 0.25 s delay embedding (each pose joined by the pose 0.25 s later), "
        "because the poses alone showed no periodic motion: no bar stands clear")
    assert res.warnings[1] == "later"

    def refuse(motion, frames=None, delay=None, **options):
        raise NoPeriodicMotionError(f"refused with {delay}", result=None)

    monkeypatch.setattr(pipeline, "extract", refuse)
    with pytest.raises(NoPeriodicMotionError, match="refused with None"):
        pipeline._with_auto_delay("m", None, {})


def test_auto_delay_is_a_quarter_second():
    assert pipeline.AUTO_DELAY == 0.25


# ------------------------------------------------------------------ extract's checks
def _bare(T):
    t = np.arange(T)
    return cc.Motion(np.c_[np.sin(t / 5.0), np.cos(t / 5.0)], [("a", "rx"), ("b", "rx")], fps=30.0)


@pytest.mark.parametrize(
    "name,value",
    [("n_samples", 9), ("n_neighbors", 0), ("pca", 0), ("class_index", -1),
     ("scale_fraction", 0.0), ("scale_fraction", 1.01), ("random_state", -1), ("steady", 1),
     ("min_turns", 0.0), ("normalize", "no"), ("temporal", 0), ("difference_root", None),
     ("rotations", "quat"), ("cycle_start", "last"), ("sampling", "sobol")],
)
def test_extract_refuses_each_bad_option(name, value):
    with pytest.raises(ParameterError, match=name):
        cc.extract(_bare(9), **{name: value})


@pytest.mark.parametrize(
    "name,value",
    [("n_samples", 10), ("n_neighbors", 1), ("pca", 1), ("class_index", 0),
     ("scale_fraction", 1.0), ("random_state", 0), ("random_state", None), ("min_turns", 0.01),
     ("weighting", "gaussian"), ("sampling", "random"), ("travel", "in_place"),
     ("cycle_start", "first"), ("timing", "coordinate"), ("delay", None), ("delay", 0.5)],
)
def test_extract_accepts_each_option_at_its_bound(name, value):
    """Accepted: the run goes on to refuse 9 frames (n_neighbors 1 needs 10 all the same)."""
    with pytest.raises(ParameterError, match=r"9 frames are too few to find a cycle \(need at least 10\)"):
        cc.extract(_bare(9), n_neighbors=1 if name != "n_neighbors" else value, **(
            {} if name == "n_neighbors" else {name: value}))


def test_extract_needs_twice_n_neighbors_and_ten_frames():
    with pytest.raises(ParameterError, match=r"19 frames are too few .*need at least 20"):
        cc.extract(_bare(19), n_neighbors=10)
    with pytest.raises(ParameterError, match=r"need at least 10"):
        cc.extract(_bare(9), n_neighbors=4)
    with pytest.raises(NoPeriodicMotionError):  # 20 frames are looked at
        cc.extract(_bare(20), n_neighbors=10)
    with pytest.raises(NoPeriodicMotionError):
        cc.extract(_bare(10), n_neighbors=4, delay=None)


def test_extract_refusals_of_delay_feet_and_non_motions():
    with pytest.raises(ParameterError, match="delay must be 'auto', a number of seconds or None, got 'x'"):
        cc.extract(_bare(30), delay="x")
    with pytest.raises(ParameterError, match="feet= needs a motion with a skeleton"):
        cc.extract(_bare(30), feet=("a", "b"))
    with pytest.raises(ParameterError, match="extract\\(\\) takes a Motion, got list"):
        cc.extract([1, 2, 3])


def test_analysis_motion_reads_the_rig_only_with_a_skeleton(walk, monkeypatch):
    m, info, adapter = pipeline._analysis_motion(_bare(30), 10, True)
    assert info is None and adapter is None and m.n_frames == 30
    m, info, adapter = pipeline._analysis_motion(walk, 10, False)
    assert info is not None and adapter is None and m is walk
    import cyclecoord.rig

    seen = []
    real = cyclecoord.rig.normalize_rig
    monkeypatch.setattr(cyclecoord.rig, "normalize_rig",
                        lambda motion, info=None: seen.append(1) or real(motion, info))
    pipeline._analysis_motion(walk, 10, True)
    assert seen == [1]


# ------------------------------------------------------------------ extract's options
@pytest.fixture(scope="module")
def walk():
    from cyclecoord.datasets import make_periodic_capture

    return make_periodic_capture(n_frames=240, period=40.0, speed_variation=0.0,
                                 random_state=0).motion


@pytest.fixture(scope="module")
def base(walk):
    return cc.extract(walk)


def test_extract_result_fields(walk, base):
    assert base.period_frames == pytest.approx(40.0, abs=0.5)
    assert base.cycle.n_frames == int(round(base.period_frames))
    assert base.cycles == pytest.approx(base.windings.turns)
    np.testing.assert_array_equal(base.cycle_frames, base.windings.lengths)
    assert base.to_report()["period_spread"] == pytest.approx(base.windings.spread)
    assert base.used.all() and np.isfinite(base.phase).all()
    assert set(base.distance) == {"median", "p90", "max", "median_frame_step", "p99_frame_step",
                                  "largest_cycle_step"}
    assert base.distance["median"] <= base.distance["p90"] <= base.distance["max"]
    t = base.timings
    assert {"density", "cycle", "metrics", "total"} <= set(t)
    assert t["total"] == pytest.approx(sum(v for k, v in t.items() if k != "total"))
    p = base.parameters
    assert p["frames"] is None and p["delay"] is None and p["steady"] is True and p["feet"] is None
    assert p["n_components"] == 30 and p["timing"] == "capture" and p["min_turns"] == 1.5
    assert base.density.n_components == 30
    assert set(base.jerk) == {"original", "cycle"} and base.jerk["cycle"] > 0


def test_extract_timing_coordinate_has_no_retimed_phase(walk, base):
    r = cc.extract(walk, timing="coordinate", n_components=3)
    assert np.isnan(r.phase).all() and r.density.n_components == 3
    assert r.cycle.n_frames == base.cycle.n_frames
    assert not np.allclose(r.cycle.frames, base.cycle.frames)
    assert np.isnan(r.heading_per_cycle)


def test_extract_a_wider_bandwidth_smooths_the_cycle(walk, base):
    r = cc.extract(walk, bandwidth=3.0)
    assert r.jerk["cycle"] < 0.5 * base.jerk["cycle"]
    assert r.parameters["bandwidth"] == 3.0


def test_extract_cycle_start_first_is_the_same_loop_turned(walk, base):
    r = cc.extract(walk, cycle_start="first")
    cols = [i for i, (j, d) in enumerate(walk.channels) if j != "root"]
    a, b = base.cycle.frames[:, cols], r.cycle.frames[:, cols]
    assert not np.allclose(a, b)
    shifts = [np.abs(np.roll(b, -k, axis=0) - a).max() for k in range(len(a))]
    assert min(shifts) < 1e-6


def test_extract_travel_in_place_keeps_the_root_still(walk, base):
    r = cc.extract(walk, travel="in_place")
    ix, iz = walk.channels.index(("root", "tx")), walk.channels.index(("root", "tz"))
    assert np.ptp(r.cycle.frames[:, [ix, iz]], axis=0).max() < 1e-6
    assert np.ptp(base.cycle.frames[:, [ix, iz]], axis=0).max() > 1.0


def test_extract_steady_false_uses_a_standing_start(walk, base):
    f = walk.frames.copy()
    f = np.r_[np.repeat(f[:1], 80, axis=0), f]
    m = walk.with_frames(f)
    steady = cc.extract(m)
    every = cc.extract(m, steady=False)
    assert every.used.all() and every.used.size == 320
    assert not steady.used[:60].any() and steady.used[100:].all()
    assert every.parameters["steady"] is False


def test_extract_min_turns_is_inclusive(walk, base):
    turns = base.cycles  # about 6
    with pytest.raises(NoPeriodicMotionError, match="turns only"):
        cc.extract(walk, min_turns=turns + 0.01)
    ok = cc.extract(walk, min_turns=turns)
    assert ok.cycles == pytest.approx(turns)


def test_extract_frames_window(walk):
    w = cc.extract(walk, frames=(20, 220))
    assert w.motion.n_frames == 200 and w.parameters["frames"] == [20, 220]
    assert w.used.size == 200


def test_extract_cycle_options_object_reaches_the_cycle(walk, base):
    from cyclecoord.periodic.results import CycleOptions

    r = cc.extract(walk, cycle=CycleOptions(timing="coordinate"))
    assert np.isnan(r.phase).all() and r.parameters["timing"] == "coordinate"
    with pytest.raises(ParameterError, match="either as keyword"):
        cc.extract(walk, cycle=CycleOptions(), timing="coordinate")


@pytest.fixture(scope="module")
def coord(walk):
    return cc.extract(walk, timing="coordinate")


def test_extract_coordinate_timing_options_reach_the_average(walk, coord):
    a = cc.extract(walk, timing="coordinate", n_neighbors=1)
    b = coord  # n_neighbors 10
    assert not np.allclose(a.cycle.frames, b.cycle.frames)
    c = cc.extract(walk, timing="coordinate", weighting="mean")
    assert not np.allclose(c.cycle.frames, b.cycle.frames)
    assert c.parameters["weighting"] == "mean"


def test_extract_timings_are_each_stages_seconds(base):
    t = base.timings
    assert all(0.0 <= v < 600.0 for v in t.values()), t


def _pq(pop, strays=False, nearest=3.04):
    return NS(figures=None, pop=pop, strays=strays, nearest_max=nearest)


def test_extract_says_when_the_cycle_pops_or_holds_stray_poses(walk, monkeypatch):
    monkeypatch.setattr(pipeline, "pose_quality", lambda *a, **k: _pq(2.5 * pipeline.MAX_POP, True))
    r = cc.extract(walk)
    pops = [w for w in r.warnings if "pops" in w]
    assert len(pops) == 1 and pops[0].startswith(
        f"the cycle pops: its largest frame step is {2.5 * pipeline.MAX_POP:.1f}x")
    strays = [w for w in r.warnings if w.startswith("some cycle poses are 3.0x")]
    assert len(strays) == 1 and "--rotations rotvec" in strays[0]
    monkeypatch.setattr(pipeline, "pose_quality", lambda *a, **k: _pq(pipeline.MAX_POP))
    r = cc.extract(walk)  # exactly at the limit: no pop, no stray
    assert not any("pops" in w or "some cycle poses" in w for w in r.warnings)


def test_extract_without_pose_figures_reads_the_pop_in_the_prepared_space(walk, monkeypatch):
    monkeypatch.setattr(pipeline, "pose_quality", lambda *a, **k: None)
    r = cc.extract(walk)
    ratio = r.distance["largest_cycle_step"] / r.distance["p99_frame_step"]
    assert r.pose_quality is None and not any("pops" in w for w in r.warnings)
    assert set(r.jerk) == {"original", "cycle"} and np.isfinite(r.jerk["original"])
    monkeypatch.setattr(pipeline, "MAX_POP", 0.99 * ratio)
    r = cc.extract(walk)
    assert any(f"its largest frame step is {ratio:.1f}x" in w for w in r.warnings)
    monkeypatch.setattr(pipeline, "MAX_POP", ratio)
    assert not any("pops" in w for w in cc.extract(walk).warnings)


class _Stop(Exception):
    pass


@pytest.mark.parametrize("kw,clear", [({}, True), ({"require_clear": False}, False)])
def test_extract_require_clear_reaches_the_fit(walk, monkeypatch, kw, clear):
    seen = []

    def spy(motion, params, require_clear):
        seen.append((motion.n_frames, params["steady"], params["min_turns"], require_clear))
        raise _Stop

    monkeypatch.setattr(pipeline, "TakeFit", spy)
    with pytest.raises(_Stop):
        cc.extract(walk, frames=(10, 210), **kw)
    assert seen == [(200, True, 1.5, clear)]


def test_extract_feet_reach_the_fit_as_joint_names(walk, monkeypatch):
    seen = []

    def spy(motion, params, require_clear):
        seen.append(params["feet"])
        raise _Stop

    monkeypatch.setattr(pipeline, "TakeFit", spy)
    with pytest.raises(_Stop):
        cc.extract(walk, feet="lfoot:ltoes,rfoot:rtoes")
    with pytest.raises(_Stop):
        cc.extract(walk, feet=("lfoot", "ltoes", "rfoot", "rtoes"))
    assert seen == [["lfoot", "ltoes", "rfoot", "rtoes"]] * 2


def test_extract_blanks_the_coordinate_outside_the_used_frames(walk):
    f = np.r_[np.repeat(walk.frames[:1], 80, axis=0), walk.frames]
    r = cc.extract(walk.with_frames(f))
    unused = ~r.used
    assert unused[:60].all()
    assert np.isnan(r.coordinate[unused]).all() and np.isnan(r.unwrapped[unused]).all()
    assert np.isfinite(r.coordinate[r.used]).all() and np.isfinite(r.unwrapped[r.used]).all()
    assert np.isnan(r.phase[unused]).all() and np.isfinite(r.heading_per_cycle)


def test_extract_coordinate_sampling_options_reach_the_average(walk, coord):
    q = coord  # sampling "quantile"
    r = cc.extract(walk, timing="coordinate", sampling="random", random_state=1)
    s = cc.extract(walk, timing="coordinate", sampling="random", random_state=2)
    assert not np.allclose(q.cycle.frames, r.cycle.frames)
    assert not np.allclose(r.cycle.frames, s.cycle.frames)
    few = cc.extract(walk, timing="coordinate", n_samples=10)
    assert not np.allclose(few.cycle.frames, q.cycle.frames)


def test_extract_auto_bandwidth_needs_kernel_weighting_only_in_coordinate_timing():
    with pytest.raises(ParameterError, match="too few"):  # capture timing: weighting unused
        cc.extract(_bare(9), bandwidth="auto", weighting="mean", n_neighbors=1)
    with pytest.raises(ParameterError, match="needs weighting='kernel'"):
        cc.extract(_bare(9), bandwidth="auto", weighting="mean", timing="coordinate",
                   n_neighbors=1)
    with pytest.raises(ParameterError, match="too few"):
        cc.extract(_bare(9), bandwidth="auto", timing="coordinate", n_neighbors=1)
