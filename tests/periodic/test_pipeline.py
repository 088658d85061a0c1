"""The periodic pipeline end to end: the issue's evidence on synthetic and real captures."""

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.quality.metrics import distance_to_cycle, loop_closure
from cyclecoord.periodic.clip import slowest_frame
from cyclecoord.periodic.pipeline import cycle_lengths
from cyclecoord.periodic.preprocess import Preprocessor
from cyclecoord.periodic.windings import crossing_times
from _measured import at_least, at_most, frame  # tests/_measured.py: the run and the margin


def true_median_winding(phase) -> float:
    """Median length in frames of the complete windings of a true phase (every level)."""
    u = np.unwrap(2 * np.pi * np.asarray(phase, dtype=float)) / (2 * np.pi)
    lengths = np.concatenate([np.diff(c) for c in crossing_times(u, np.arange(32) / 32)])
    return float(np.median(lengths))


def bins_advance(theta, true_phase, n_bins=20):
    """Monotonicity measure: bin frames by true phase; the circular mean of the coordinate
    in each bin must advance from bin to bin and go round exactly once (steps in
    (-0.5, 0.5) summing to 1).  Returns (fraction of bins advancing, total turn)."""
    b = np.floor(np.mod(true_phase, 1.0) * n_bins).astype(int)
    means = np.array([np.angle(np.mean(np.exp(2j * np.pi * theta[b == i]))) / (2 * np.pi) for i in range(n_bins)])
    steps = np.mod(np.diff(np.r_[means, means[0]]) + 0.5, 1.0) - 0.5
    return float(np.mean(steps > 0)), float(abs(steps.sum()))


CASES = [(kind, seed, noise) for kind in ("walk", "jog", "squat", "arm_circles") for seed in (0, 1) for noise in (0.5, 2.0)]

#: Measured (tests/_measured.py RUN) on each synthetic capture: the period's error against the
#: true median winding, |cycles - 599/120|, loop closure, the cycle's jerk over the capture's,
#: and the cycle's mean distance to the noise-free truth over the noisy frames'.  Loop
#: closure and jerk are on joint positions (quality.pose_space, issue 25; re-measured on
#: i25rest: on the prepared channels they were 0.20-0.92 and 0.035-0.038).
MEASURED = {
    ("walk", 0, 0.5): (0.0085, 0.0074, 0.412, 0.0617, 0.374),
    ("walk", 0, 2.0): (0.0018, 0.0068, 0.744, 0.0653, 0.368),
    ("walk", 1, 0.5): (0.0130, 0.0077, 0.434, 0.0650, 0.373),
    ("walk", 1, 2.0): (0.0138, 0.0083, 0.590, 0.0673, 0.378),
    ("jog", 0, 0.5): (0.0106, 0.0077, 0.357, 0.0656, 0.371),
    ("jog", 0, 2.0): (0.0135, 0.0068, 0.686, 0.0651, 0.370),
    ("jog", 1, 0.5): (0.0141, 0.0075, 0.348, 0.0664, 0.380),
    ("jog", 1, 2.0): (0.0129, 0.0078, 0.641, 0.0677, 0.377),
    ("squat", 0, 0.5): (0.0045, 0.0083, 0.177, 0.0648, 0.384),
    ("squat", 0, 2.0): (0.0072, 0.0076, 0.465, 0.0683, 0.395),
    ("squat", 1, 0.5): (0.0253, 0.0083, 0.492, 0.0668, 0.383),
    ("squat", 1, 2.0): (0.0218, 0.0086, 0.920, 0.0702, 0.386),
    ("arm_circles", 0, 0.5): (0.0242, 0.0033, 0.711, 0.0737, 0.353),
    ("arm_circles", 0, 2.0): (0.0272, 0.0104, 0.850, 0.0751, 0.352),
    ("arm_circles", 1, 0.5): (0.0194, 0.0006, 0.755, 0.0680, 0.364),
    ("arm_circles", 1, 2.0): (0.0122, 0.0037, 0.639, 0.0666, 0.356),
}


@pytest.mark.parametrize("kind,seed,noise", CASES)
def test_synthetic_phase_cycles_and_cycle_quality(kind, seed, noise):
    cap = cc.datasets.make_periodic_capture(n_frames=600, period=120.0, noise=noise, kind=kind, random_state=seed)
    res = cc.extract(cap.motion)
    period_err, cycles_err, closure, jerk_ratio, distance_ratio = MEASURED[kind, seed, noise]
    # the coordinate is a monotone function of the true phase
    assert res.used_frames == [(0, 600)]  # a steady capture is used whole
    frac, turn = bins_advance(res.coordinate, cap.phase)
    assert frac == 1.0 and turn == pytest.approx(1.0)
    # a 600-frame clip of period 120 holds (600 - 1) / 120 cycles from first to last frame
    assert abs(res.cycles - 599 / 120) <= at_most(cycles_err, frame(120))
    # the period is the median complete winding (the speed wobbles by up to 30%)
    truth = true_median_winding(cap.phase)
    assert abs(res.period_frames / truth - 1) <= at_most(period_err, frame(truth))
    # the extracted cycle is closer to the noise-free truth than the noisy frames are
    clean = Preprocessor().fit(cap.clean).transform(cap.clean).poses
    joints = np.arange(6, 62)
    d_cycle = distance_to_cycle(clean[:, joints], res.typical.frames[:, joints]).mean()
    d_noisy = np.linalg.norm(res.prepared.poses[:, joints] - clean[:, joints], axis=1).mean()
    assert d_cycle / d_noisy <= at_most(distance_ratio)
    # it loops, and it is as smooth as measured (a Gaussian sqrt(2) narrower than stated
    # raised the jerk 3.2-3.9x; the capture's own jerk is about 28x the cycle's)
    assert res.loop_closure <= at_most(closure)
    assert res.jerk["cycle"] / res.jerk["original"] <= at_most(jerk_ratio)
    assert res.cycle.n_frames == round(res.period_frames)


def test_cycle_travels_like_the_original():
    cap = cc.datasets.make_periodic_capture(n_frames=600, period=120.0, noise=0.5, random_state=0)
    res = cc.extract(cap.motion)
    tz = cap.motion.channel_index("root", "tz")
    per_cycle = (cap.motion.frames[-1, tz] - cap.motion.frames[0, tz]) / res.cycles
    cyc = res.cycle.frames[:, tz]
    # one loop of P frames plus the step back to frame 0 of the next loop covers per_cycle
    steps = np.diff(cyc)
    loop = steps.sum() + np.median(steps)
    # the cycle moves at the capture's mean speed for its own length (the median winding)
    per_frame = (cap.motion.frames[-1, tz] - cap.motion.frames[0, tz]) / (cap.motion.n_frames - 1)
    assert loop == pytest.approx(per_frame * res.cycle.n_frames, rel=0.05)
    assert per_cycle == pytest.approx(per_frame * 599 / res.cycles)
    assert res.cycle.skeleton is cap.motion.skeleton
    assert res.cycle.channels == cap.motion.channels


def test_report_has_the_documented_fields():
    res = cc.extract(cc.datasets.example_capture().motion)
    rep = res.to_report()
    for key in ("frames", "dims", "barcode", "selected", "coordinate", "cycles", "period_frames",
                "cycle_frames", "jerk", "loop_closure", "timings"):
        assert key in rep
    assert set(rep["barcode"]) == {"h0", "h1"}
    assert len(rep["coordinate"]) == res.motion.n_frames
    assert rep["selected"]["birth"] < rep["selected"]["scale"]
    assert set(rep["jerk"]) == {"original", "cycle"}
    assert rep["barcode"]["h0"][-1][1] is None  # the infinite H0 bar
    d = rep["distance_to_cycle"]
    assert 0 < d["largest_cycle_step"] <= 2.0 * d["p99_frame_step"]  # no pop, no warning
    assert not any("pops" in w for w in res.warnings)
    pq = rep["pose_quality"]  # the same figures on joint positions
    # measured: pop 0.523, seam 0.518, nearest 0.847 (the warnings: pop 2, seam 1.5, stray 1)
    assert pq["pop"] <= at_most(0.523) and pq["seam"] <= at_most(0.518)
    assert pq["nearest_max"] <= min(1.0, at_most(0.847))
    assert not any("some cycle poses" in w for w in res.warnings)  # no stray pose, no warning
    # the report's loop closure and jerk are pose_quality's (joint positions, one value)
    assert rep["loop_closure"] == pytest.approx(pq["seam"]) and pq["figures"]["jerk"] > 0
    assert rep["loop_closure"] <= at_most(0.518)  # measured 0.518
    assert rep["jerk"]["cycle"] / rep["jerk"]["original"] <= at_most(0.0636)  # measured 0.0636


def test_a_pop_in_the_cycle_is_a_warning(monkeypatch):
    """Over MAX_POP times the capture's 99th-percentile step is said, with what to do
    (here the threshold is lowered so that the example's largest step passes it)."""
    import cyclecoord.periodic.pipeline as pipeline

    m = cc.datasets.example_capture().motion
    pop = cc.extract(m).pose_quality.pop
    monkeypatch.setattr(pipeline, "MAX_POP", 0.5 * pop)
    (note,) = [w for w in cc.extract(m).warnings if "pops" in w]
    assert "99th-percentile step" in note and "--bandwidth 2" in note


def test_deterministic_for_a_seed():
    m = cc.datasets.example_capture().motion
    a = cc.extract(m, sampling="random", random_state=3)
    b = cc.extract(m, sampling="random", random_state=3)
    np.testing.assert_array_equal(a.cycle.frames, b.cycle.frames)
    np.testing.assert_array_equal(a.coordinate, b.coordinate)


@pytest.mark.parametrize("make", [cc.datasets.make_static_capture, cc.datasets.make_random_walk_capture])
def test_nothing_periodic_is_refused(make):
    with pytest.raises(cc.NoPeriodicMotionError, match="no periodic motion") as info:
        cc.extract(make(random_state=0).motion)
    partial = info.value.result
    assert isinstance(partial, cc.PartialExtraction) and partial.barcode is not None
    # honest about what it lacks: no coordinate, period or cycle fields to find None in
    assert partial.reason in str(info.value)
    assert not hasattr(partial, "coordinate") and not hasattr(partial, "cycle")


def test_bad_arguments():
    m = cc.datasets.example_capture().motion
    with pytest.raises(cc.ParameterError, match="prime"):
        cc.extract(m, prime=12)
    with pytest.raises(cc.ParameterError, match="frame range"):
        cc.extract(m, frames=(400, 2000))
    with pytest.raises(cc.ParameterError, match="weighting"):
        cc.extract(m, weighting="median")
    with pytest.raises(cc.ParameterError, match="outside"):
        cc.extract(m, scale=0.01)
    for bad in (-1.0, 0, "wide", float("nan"), True):
        with pytest.raises(cc.ParameterError, match="bandwidth"):
            cc.extract(m, bandwidth=bad)
    with pytest.raises(cc.ParameterError, match="needs weighting='kernel'"):
        cc.extract(m, bandwidth="auto", weighting="mean", timing="coordinate")
    for name, bad in (("timing", "fast"), ("travel", "sideways"), ("min_turns", 0)):
        with pytest.raises(cc.ParameterError, match=name):
            cc.extract(m, **{name: bad})


def test_cycle_lengths_and_slowest_frame():
    u = np.linspace(0, 3.5, 351)  # 100 frames per cycle
    np.testing.assert_allclose(cycle_lengths(u), [100, 100, 100])
    t = np.linspace(0, 1, 50, endpoint=False)
    speed = 1 + 0.9 * np.cos(2 * np.pi * (t - 0.3))  # slowest near t = 0.8
    ang = 2 * np.pi * np.cumsum(speed) / speed.sum()
    loop = np.column_stack([np.cos(ang), np.sin(ang)])
    assert abs(slowest_frame(loop) - 40) <= 2
    assert loop_closure(np.roll(loop, -slowest_frame(loop), axis=0)) < 1.0


# ------------------------------------------------------------------ real capture (paper Fig. 7)
def autocorrelation_period(frames, lo=60, hi=250):
    """Independent period estimate: first autocorrelation peak of the joint angles."""
    x = frames[:, 6:] - frames[:, 6:].mean(axis=0)
    n = len(x)
    ac = np.array([np.sum(x[: n - k] * x[k:]) / (n - k) for k in range(hi)])
    return lo + int(np.argmax(ac[lo:hi]))


def test_69_01_walk_matches_the_paper(walk_69_01):
    res = cc.extract(walk_69_01, frames=(200, 450), max_scale=50)
    assert res.selection.index == 0 and res.selection.clear
    assert res.selection.birth == pytest.approx(9.95, abs=0.3)  # paper Fig. 7
    assert res.selection.birth < res.selection.scale < 50
    assert 1.5 < res.cycles < 2.0  # a little under two strides
    ref = autocorrelation_period(walk_69_01.frames)
    assert ref == 143  # the take's first autocorrelation peak
    # measured: period 139.8 (2.2 % under the autocorrelation's whole-frame 143), loop
    # closure 0.696, the cycle's jerk 0.729 of the capture's (joint positions; 0.224 on the
    # prepared channels, where the capture's noise weighs more)
    assert abs(res.period_frames / ref - 1) <= at_most(0.0221, frame(ref))
    assert res.loop_closure <= at_most(0.696)
    assert res.jerk["cycle"] / res.jerk["original"] <= at_most(0.729)
    assert res.estimator.cocycle_check_.ok


def test_69_01_default_threshold_agrees(walk_69_01):
    a = cc.extract(walk_69_01, frames=(200, 450), max_scale=50)
    b = cc.extract(walk_69_01, frames=(200, 450))
    assert b.selection.birth == pytest.approx(a.selection.birth)
    # measured 0.17 % apart: within a frame
    assert abs(b.period_frames / a.period_frames - 1) <= at_most(0.0017, frame(a.period_frames))


def test_69_01_cut_bar_is_followed_to_its_death(walk_69_01):
    """--max-scale 12 cuts the 9.95 bar (12 / 9.95 < 1.5): it is followed until it stands clear."""
    from cyclecoord.quality.metrics import circular_distance

    a = cc.extract(walk_69_01, frames=(200, 450), max_scale=50)
    b = cc.extract(walk_69_01, frames=(200, 450), max_scale=12)
    assert b.selection.birth == pytest.approx(a.selection.birth)
    assert b.barcode.threshold > 4 * b.selection.birth
    # measured: coordinates 0.0042 apart (median), periods 0.10 % (within a frame)
    assert np.median(circular_distance(a.coordinate, b.coordinate)) <= at_most(0.0042)
    assert abs(b.period_frames / a.period_frames - 1) <= at_most(0.0010, frame(a.period_frames))


def leg_range_ratio(res, joint):
    """Range of a joint's flexion (rx) in the cycle over its median range in real cycles."""
    i = res.motion.channel_index(joint, "rx")
    P = res.cycle.n_frames
    real = [np.ptp(res.motion.frames[s : s + P, i]) for a, b in res.used_frames for s in range(a, b - P, P // 4)]
    return np.ptp(res.cycle.frames[:, i]) / np.median(real)


def test_69_01_whole_take(walk_69_01):
    """The issue's whole take: standing start left out, both legs swing, the period is right."""
    res = cc.extract(walk_69_01)
    (a, b), = res.used_frames
    assert 100 < a < 200 and b == 469  # the standing start has no phase
    assert np.all(np.isnan(res.coordinate[:a])) and np.all(np.isfinite(res.coordinate[a:]))
    ref = autocorrelation_period(walk_69_01.frames[a:b])
    # measured: used 180-469, period 139.8 against 141 (0.86 %), loop closure 0.884, windings
    # spread 0.0375, leg ranges 1.00-1.09 of the real cycles' (0.85: issue 12's target,
    # tighter than measured / 1.3)
    assert abs(res.period_frames / ref - 1) <= at_most(0.0086, frame(ref))
    assert res.cycle.n_frames == round(res.period_frames)
    for joint in ("lfemur", "rfemur", "ltibia", "rtibia"):
        assert leg_range_ratio(res, joint) >= max(0.85, at_least(1.00)), joint
    assert res.loop_closure <= at_most(0.884)
    assert res.windings.spread <= at_most(0.0375) and res.to_report()["used_frames"] == [[a, b]]


def test_root_pitch_and_roll_close_and_heading_is_reported(walk_69_01):
    res = cc.extract(walk_69_01, frames=(200, 450), max_scale=50)
    f = res.cycle.frames
    step = np.median(np.abs(np.diff(f, axis=0)), axis=0)
    for dof in ("rx", "rz"):  # the CMU root's tilt channels (ry is the heading)
        i = res.cycle.channel_index("root", dof)
        assert abs(f[-1, i] - f[0, i]) <= max(0.5, 1.5 * step[i]), dof
    assert np.isfinite(res.heading_per_cycle) and abs(res.heading_per_cycle) < 10
    straight = cc.extract(walk_69_01, frames=(200, 450), max_scale=50, travel="straight")
    from cyclecoord.periodic.root import heading, root_layout

    h = heading(straight.cycle.frames, root_layout(straight.cycle))
    step_h = np.median(np.diff(h))
    assert abs(h[-1] + step_h - h[0]) < 0.2  # one loop turns by nothing


def test_short_clip_is_refused_with_the_reason():
    cap = cc.datasets.make_periodic_capture(n_frames=150, period=120.0, speed_variation=0.0, random_state=0)
    with pytest.raises(cc.NoPeriodicMotionError, match="turns only .*at least 1.5") as info:
        cc.extract(cap.motion)
    assert info.value.result is not None


@pytest.mark.parametrize("n_frames", [300, 301])
def test_a_take_of_over_300_moving_frames_is_first_read_on_150_landmarks(monkeypatch, n_frames):
    """extract's ``landmarks`` documentation: with ``steady`` and ``"auto"``, over 300
    moving frames are first read on 150 landmarks, then fitted again (as asked); 300 are
    fitted once."""
    from cyclecoord.periodic import fitting

    asked = []
    make = fitting.TakeFit.make_estimator

    def spy(self, first_pass=False):
        est = make(self, first_pass)
        asked.append((int(self.moving.sum()), first_pass, est.landmarks))
        return est

    monkeypatch.setattr(fitting.TakeFit, "make_estimator", spy)
    cap = cc.datasets.make_periodic_capture(n_frames=n_frames, period=60.0, random_state=0)
    cc.extract(cap.motion)
    if n_frames == 300:
        assert asked == [(300, False, "auto")]
    else:
        assert asked == [(301, True, 150), (301, False, "auto")]


def test_a_later_class_is_taken_when_the_first_does_not_wind_steadily(monkeypatch):
    """TakeFit._other_class on stand-in windings and bars: the first class stands when it
    turns min_turns times or more with a spread of at most MAX_SPREAD (more is not
    steady), else the first of classes 1-3 with a death/birth ratio of at least
    CLEAR_RATIO that does both; each bound itself passes."""
    from types import SimpleNamespace as NS

    from cyclecoord.periodic import fitting
    from cyclecoord.periodic.barcode import CLEAR_RATIO

    monkeypatch.setattr(fitting, "complete_windings", lambda windings, runs: windings)
    monkeypatch.setattr(fitting, "select_bar", lambda bc, j, scale, fraction: NS(ratio=bc.ratios[j]))

    def chosen(first, others, ratios=None):
        ratios = ratios or [9.0] + [CLEAR_RATIO] * len(others)
        fits = {j: NS(unwrapped=w, notes=[]) for j, w in enumerate(others, 1)}
        run = NS(p={"min_turns": 1.5, "scale_fraction": 0.5},
                 coordinate_of=lambda j, rows: fits[j])
        fit = NS(unwrapped=first, notes=[])
        out = fitting.TakeFit._other_class(
            run, fit, NS(with_coordinate_params=lambda class_index: class_index),
            NS(h1=np.zeros((len(ratios), 2)), ratios=ratios), np.arange(10))
        return 0 if out is fit else next(j for j, f in fits.items() if f is out)

    spread, good = fitting.MAX_SPREAD, NS(turns=3.0, spread=0.1)
    assert chosen(NS(turns=1.5, spread=spread), [good]) == 0
    assert chosen(NS(turns=1.49, spread=0.1), [good]) == 1
    assert chosen(NS(turns=3.0, spread=spread + 0.01), [good]) == 1
    assert chosen(NS(turns=1.0, spread=0.1), [NS(turns=1.5, spread=spread)]) == 1
    assert chosen(NS(turns=1.0, spread=0.1), [NS(turns=1.49, spread=0.1), NS(turns=2.0, spread=spread + 0.01),
                                              good]) == 3
    assert chosen(NS(turns=1.0, spread=0.1), [good, good], [9.0, CLEAR_RATIO - 0.01, CLEAR_RATIO]) == 2
    assert chosen(NS(turns=1.0, spread=0.1), [NS(turns=1.0, spread=0.1)] * 3 + [good]) == 0


def test_synthetic_whole_take():
    cap = cc.datasets.make_whole_take(random_state=0)
    res = cc.extract(cap.motion)
    still = np.isnan(cap.phase)
    assert not np.any(np.isfinite(res.coordinate[still]))  # standing frames get no phase
    # measured 0.13 % from the truth; the used frames over the net turns say 116.6 (2.6 %)
    assert abs(res.period_frames / cap.period - 1) <= at_most(0.0013, frame(cap.period))
    steady = np.zeros(cap.motion.n_frames, dtype=bool)
    for a, b in cap.steady:
        steady[a:b] = True
    used = res.used
    # measured: 5.9 % of the used frames are not steady walking, 7.8 % of the steady
    # walking is not used
    assert 1 - np.mean(steady[used]) <= at_most(0.059)
    assert 1 - np.mean(used[steady]) <= at_most(0.078)
    # the cycle (joint positions): loop closure 0.402, jerk 0.0400 of the capture's
    assert res.loop_closure <= at_most(0.402)
    assert res.jerk["cycle"] / res.jerk["original"] <= at_most(0.0400)


def test_long_whole_take_with_turns_and_pauses_is_not_refused():
    """Issue 12: whole walks of 5,000+ frames with pauses are read, not refused."""
    cap = cc.datasets.make_whole_take(n_frames=6000, random_state=1)
    assert [p[0] for p in cap.parts].count("stand") >= 4  # a start, pauses and a stop
    res = cc.extract(cap.motion)
    # measured 0.27 % from the truth (within a frame), loop closure 0.401
    assert abs(res.period_frames / cap.period - 1) <= at_most(0.0027, frame(cap.period))
    assert res.loop_closure <= at_most(0.401)
    standing = np.zeros(cap.motion.n_frames, dtype=bool)
    for name, a, b in cap.parts:
        standing[a:b] |= name == "stand"
    assert not np.isfinite(res.coordinate[standing]).any()
    assert len(res.used_frames) >= 4  # several steady stretches between the pauses and turns


def test_out_and_back_motion_is_read_with_a_delay(cmu_dir):
    """13_29's jumping jacks are a segment in pose space; the automatic delay makes a loop."""
    m = cc.load(cmu_dir / "13" / "13_29.amc")
    with pytest.raises(cc.NoPeriodicMotionError, match="turns only"):
        cc.extract(m, frames=(0, 456), delay=None)
    res = cc.extract(m, frames=(0, 456))
    assert "delay embedding" in res.warnings[0]
    # issue 25: the warning says what the poses alone showed, not a guess at the movement
    assert "the poses alone showed no periodic motion: the coordinate turns only" in res.warnings[0]
    assert "squat" not in res.warnings[0]
    ref = autocorrelation_period(m.frames[0:456], lo=90, hi=200)
    assert abs(res.period_frames / ref - 1) <= at_most(0.0018, frame(ref))  # measured 133.75 / 134
    # no pop: the take's first repetition, still getting going, dwells a dozen frames on one
    # cycle sample (arms down while the others' are up); counted frame by frame it pulled
    # the average's wrists 23 degrees down and back within 4 frames (2.5x the take's p99 step)
    from cyclecoord.quality.cycle_quality import joint_angles, largest_step

    take = m.window((0, 456))
    x = joint_angles(take)
    assert largest_step(joint_angles(res.cycle, like=x.mean(axis=0)), x) <= at_most(0.717)  # measured


def test_a_take_of_several_motions_points_to_detect():
    """Extract reads one motion; when most moving frames are something else it says so."""
    chain = cc.datasets.make_motion_chain(random_state=0)
    res = cc.extract(chain.motion)
    assert sum(b - a for a, b in res.used_frames) < 0.5 * chain.motion.n_frames
    assert any("cyclecoord detect" in w for w in res.warnings)
    # one steady motion alone does not get the note
    assert not any("cyclecoord detect" in w for w in cc.extract(cc.datasets.example_capture().motion).warnings)


def test_configured_estimator_gives_its_parameters():
    """extract(estimator=...) takes the estimator's parameters for the keywords left at
    their defaults, refuses one given both ways, and refuses what is no estimator."""
    from cyclecoord.periodic.coordinates import CircularCoordinates
    from cyclecoord.periodic.results import EXTRACT_CONFIGURED_DEFAULTS, configured_keywords

    given = dict(EXTRACT_CONFIGURED_DEFAULTS)
    est = CircularCoordinates(prime=53, scale_fraction=0.7)
    chosen = configured_keywords(None, None, est, given)
    assert chosen["prime"] == 53 and chosen["scale_fraction"] == 0.7
    assert set(chosen) == {"max_scale", "scale", "class_index", "prime", "scale_fraction",
                           "temporal", "landmarks", "memory_limit"}
    with pytest.raises(cc.ParameterError, match="give prime either as keyword"):
        configured_keywords(None, None, est, {**given, "prime": 59})
    with pytest.raises(cc.ParameterError, match="estimator must be a CircularCoordinates, got str"):
        configured_keywords(None, None, "ripser", given)


def test_configured_preprocessor_delay_in_frames_becomes_seconds():
    """A Preprocessor's delay counts frames, extract's counts seconds: 12 frames at
    120 fps are 0.1 s (which extract turns back into round(0.1 * 120) = 12 frames)."""
    from cyclecoord.periodic.results import EXTRACT_CONFIGURED_DEFAULTS, configured_keywords

    given = dict(EXTRACT_CONFIGURED_DEFAULTS)
    m = cc.datasets.make_periodic_capture(n_frames=50, fps=120.0, random_state=0).motion
    prep = Preprocessor(delay=12, difference_root=False, normalize=True, pca=3)
    chosen = configured_keywords(m, prep, None, given)
    assert chosen == dict(difference_root=False, normalize=True, pca=3, root="body",
                          delay=pytest.approx(0.1, rel=1e-12), rotations="auto")
    assert round(chosen["delay"] * m.fps) == 12
    at_30 = configured_keywords(m.with_frames(m.frames, fps=30.0), Preprocessor(delay=12), None,
                                given)
    assert at_30["delay"] == pytest.approx(0.4, rel=1e-12)
    for none in (None, 0):  # no delay embedding either way
        assert configured_keywords(m, Preprocessor(delay=none), None, given)["delay"] is None
    with pytest.raises(cc.ParameterError, match="give delay either as keyword"):
        configured_keywords(m, prep, None, {**given, "delay": 0.2})
    # several delays: detect takes them all (seconds), extract takes one
    assert configured_keywords(m, Preprocessor(delay=[12]), None, given)["delay"] == pytest.approx(0.1)
    two = configured_keywords(m, Preprocessor(delay=[12, 30]), None, given, several_delays=True)
    assert two["delay"] == pytest.approx((0.1, 0.25))
    with pytest.raises(cc.ParameterError, match="takes one delay, the preprocessor has 2"):
        configured_keywords(m, Preprocessor(delay=[12, 30]), None, given)
    for bad in (2.5, -3):  # refused as the Preprocessor refuses them, not rounded
        with pytest.raises(cc.ParameterError, match="whole numbers of frames"):
            configured_keywords(m, Preprocessor(delay=bad), None, given)


def test_the_first_fit_reads_the_moving_frames_unless_too_many_or_too_few(monkeypatch):
    """TakeFit.moving (its docstring): the moving frames, unless they are 95 % of the take
    or more, or fewer than max(10, 2 * n_neighbors); then, and without steady, every frame.
    Each bound itself keeps the moving frames."""
    from cyclecoord.periodic import fitting

    motion = cc.datasets.make_periodic_capture(n_frames=100, period=40.0, random_state=0).motion
    count = {}

    def mask(poses, fps, columns=None):
        out = np.zeros(len(poses), dtype=bool)
        out[5 : 5 + count["n"]] = True
        return out

    monkeypatch.setattr(fitting, "moving_mask", mask)

    def moving(n, n_neighbors=10, steady=True):
        count["n"] = n
        params = dict(delay=None, difference_root=True, normalize=False, pca=None, root="body",
                      rotations="auto", steady=steady, n_neighbors=n_neighbors)
        return int(fitting.TakeFit(motion, params, True).moving.sum())

    assert moving(20) == 20 and moving(19) == 100  # 2 * 10 neighbours
    assert moving(16, n_neighbors=8) == 16 and moving(15, n_neighbors=8) == 100
    assert moving(10, n_neighbors=3) == 10 and moving(9, n_neighbors=3) == 100  # at least 10
    assert moving(94) == 94 and moving(95) == 100  # 95 % of 100 frames
    assert moving(50, steady=False) == 100


def test_a_configured_object_alone_is_read_and_checked():
    """extract reads a configured preprocessor without an estimator, and an estimator
    without a preprocessor: each alone is checked (a wrong type, a keyword given both
    ways) before any fitting, and its settings are used."""
    m = cc.datasets.make_periodic_capture(n_frames=200, period=40.0, random_state=0).motion
    with pytest.raises(cc.ParameterError, match="preprocessor must be a Preprocessor"):
        cc.extract(m, preprocessor="body")
    with pytest.raises(cc.ParameterError, match="give pca either as keyword"):
        cc.extract(m, pca=3, preprocessor=Preprocessor(pca=5))
    with pytest.raises(cc.ParameterError, match="estimator must be a CircularCoordinates"):
        cc.extract(m, estimator=Preprocessor())
    with pytest.raises(cc.ParameterError, match="give prime either as keyword"):
        cc.extract(m, prime=59, estimator=cc.CircularCoordinates(prime=53))
    # alone, each object's settings are the extraction's (the preprocessor's delay None:
    # no delay embedding), as CycleOptions' are
    m = cc.datasets.make_periodic_capture(n_frames=240, period=60.0, random_state=0).motion
    res = cc.extract(m, preprocessor=Preprocessor(pca=5))
    assert res.parameters["pca"] == 5 and res.parameters["delay"] is None
    assert cc.extract(m, cycle=cc.CycleOptions(n_samples=50)).parameters["n_samples"] == 50


def test_rows_of_is_a_view_for_one_contiguous_run():
    from cyclecoord.periodic.fitting import rows_of

    x = np.arange(20.0).reshape(10, 2)
    run = rows_of(x, np.arange(3, 7))
    assert np.array_equal(run, x[3:7]) and np.shares_memory(run, x)
    gap = rows_of(x, np.array([1, 2, 5]))
    assert np.array_equal(gap, x[[1, 2, 5]]) and not np.shares_memory(gap, x)


def test_a_long_takes_cycle_is_averaged_from_its_middle_frames(monkeypatch):
    """Over MAX_CYCLE_FRAMES phased frames only the middle ones are averaged; with the
    limit lowered to two periods a steady 600-frame walk still gives its 120-frame cycle."""
    import cyclecoord.periodic.clip as clip

    cap = cc.datasets.make_periodic_capture(n_frames=600, period=120.0, noise=0.5, random_state=0)
    monkeypatch.setattr(clip, "MAX_CYCLE_FRAMES", 240)
    res = cc.extract(cap.motion)
    assert abs(res.cycle.n_frames - 120) <= 6  # the period within 5 %
    assert np.all(np.isfinite(res.cycle.frames))


def test_not_clear_reason_names_what_falls_short():
    from types import SimpleNamespace

    from cyclecoord.periodic.barcode import CLEAR_GAP, CLEAR_RATIO
    from cyclecoord.periodic.fitting import not_clear_reason

    bc = SimpleNamespace(threshold=2.0)
    short = SimpleNamespace(index=0, birth=1.0, death=1.2, ratio=CLEAR_RATIO / 2, gap=2 * CLEAR_GAP)
    why = not_clear_reason(short, bc)
    assert "death/birth" in why and "persistence" not in why
    low = SimpleNamespace(index=1, birth=0.1, death=0.5, ratio=5.0, gap=2 * CLEAR_GAP)
    why = not_clear_reason(low, bc)
    assert "persistence under" in why and "death/birth" not in why and "H1 bar #1" in why


def test_a_landmark_fit_reports_its_class_birth_on_every_frame():
    """On landmarks the report carries the class's birth on all the frames as well
    (``selection.full_birth``), which is no later than the landmarks' birth; 400 frames
    are first read on 150 landmarks and fitted again on 100."""
    cap = cc.datasets.make_periodic_capture(n_frames=400, period=60.0, random_state=0)
    res = cc.extract(cap.motion, landmarks=100)
    fb = res.selection.full_birth
    assert fb is not None and 0 < fb <= res.selection.birth + 1e-12
