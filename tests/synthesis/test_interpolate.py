"""Alignment, blending and transitions between cycles (cyclecoord.synthesis: curve, align, sources, blend)."""

from dataclasses import replace
from _measured import at_least, at_most

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from cyclecoord.synthesis.align import align, mean_heading, rotate_heading
from cyclecoord.synthesis.blend import STEP_LIMIT, blend, transition
from cyclecoord.synthesis.curve import CycleCurve, prepare_cycle, root_drift
from cyclecoord.synthesis.sources import as_cycle, cycle_summary, estimate_period
from cyclecoord.quality.metrics import jerk_summary


# ------------------------------------------------------------------ synthetic cycles
def make_cycle(kind="walk", period=120, seed=0, noise=0.0):
    """One exact loop of a synthetic capture and its true per-loop root change.

    With a constant phase speed frame ``t`` is at phase ``t / period``; rendering one
    frame more than a loop gives the next loop's first frame, hence the displacement.
    """
    cap = cc.datasets.make_periodic_capture(
        kind=kind, n_frames=period + 1, period=period, noise=noise, speed_variation=0.0, random_state=seed
    )
    m = cap.motion
    disp = m.frames[period] - m.frames[0]
    return m[:period], disp


def rolled(cycle, k, disp):
    """The same loop started ``k`` frames later (the wrapped frames travel one loop on)."""
    f = np.asarray(cycle.frames)
    return cycle.with_frames(np.vstack([f[k:], f[:k] + disp]))


def played_backwards(cycle):
    return cycle.with_frames(np.asarray(cycle.frames)[::-1])


def pose_columns(m):
    root = set(m.root_channels())
    return [i for i in range(m.n_channels) if i not in root]


@pytest.fixture(scope="module")
def walk():
    return make_cycle("walk", 120, seed=0)


@pytest.fixture(scope="module")
def jog():
    return make_cycle("jog", 80, seed=3)


# ------------------------------------------------------------------ curves
def test_curve_passes_through_frames_and_resamples_losslessly(walk):
    cycle, _ = walk
    curve = CycleCurve.from_motion(cycle)
    assert np.abs(curve.sample(120) - cycle.frames).max() < 1e-9
    assert np.abs(curve(np.arange(120) / 120) - cycle.frames).max() < 1e-9
    # P -> N -> P, for N above P (odd and even): the frames come back
    for n in (121, 256, 301):
        up = cycle.with_frames(curve.sample(n))
        back = CycleCurve.from_motion(up, displacement=curve.drift[list(cycle.root_channels())]).sample(120)
        assert np.abs(back - cycle.frames).max() < 1e-8, n
    # one loop later the root has travelled the drift
    assert np.allclose(curve(1.0)[0] - curve(0.0)[0], curve.drift)


def test_root_drift_recovers_the_travel_per_loop(walk, jog):
    for cycle, disp in (walk, jog):
        root = cycle.root_channels()
        est = root_drift(cycle)
        assert est == pytest.approx(disp[root], abs=1e-5)
        assert est[2] > 10  # travels along +z, one stride per loop
        # a known displacement is used as given
        known = replace(cycle, metadata={"root_displacement": [0, 0, 5, 0, 0, 0]})
        assert list(root_drift(known)) == [0, 0, 5, 0, 0, 0]
        prep = prepare_cycle(cycle)
        assert prep[:, root].sum(axis=0) == pytest.approx(est)


def test_align_finds_whole_fractional_and_reversed_shifts(walk):
    cycle, disp = walk
    al = align(cycle, rolled(cycle, 37, disp))
    assert not al.reversed
    assert al.shift == pytest.approx((120 - 37) / 120, abs=1e-9)
    assert al.shift_frames == pytest.approx(-37, abs=1e-6)
    assert al.cost < 1e-6 < al.cost_unaligned
    # a fraction of a frame: b(θ) = a(θ - 0.1234) is matched by shifting b by +0.1234
    curve = CycleCurve.from_motion(cycle)
    frac = cycle.with_frames(curve.shifted(-0.1234).sample(120))
    al = align(cycle, frac)
    assert al.shift == pytest.approx(0.1234, abs=1e-9)
    # played backwards: found as reversed with zero cost, unless reversal is not allowed
    back = played_backwards(cycle)
    al = align(cycle, back)
    assert al.reversed and al.cost < 1e-6
    forward_only = align(cycle, back, allow_reverse=False)
    assert not forward_only.reversed and forward_only.cost > 1.0
    # cycles of different lengths are compared on the phase circle
    long = cycle.with_frames(curve.sample(203))
    al = align(cycle, long)
    assert al.cost < 1e-6 and min(al.shift, 1 - al.shift) < 1e-9


def test_blend_with_itself_and_shifted_copies_returns_the_cycle(walk):
    cycle, disp = walk
    same = blend([cycle, cycle], [0.5, 0.5])
    assert same.n_frames == 120
    assert np.abs(same.frames - cycle.frames).max() < 1e-6
    shifted = blend([cycle, rolled(cycle, 45, disp)], [0.3, 0.7])
    assert np.abs(shifted.frames - cycle.frames).max() < 1e-6
    three = blend(
        [cycle, rolled(cycle, 7, disp), played_backwards(rolled(cycle, 90, disp))],
        [0.2, 0.3, 0.5],
        allow_reverse=True,
    )
    assert np.abs(three.frames - cycle.frames).max() < 1e-6
    assert three.metadata["blend"]["alignments"][2]["reversed"] is True
    assert three.metadata["root_displacement"] == pytest.approx(disp[cycle.root_channels()], abs=1e-5)


@pytest.mark.parametrize(
    "weights, message",
    [
        ([0.5, 0.6], "sum to 1"),
        ([1.2, -0.2], "non-negative"),
        ([1.0], "one weight per cycle"),
        ([0.5, float("nan")], "finite"),
        (["a", "b"], "numbers"),
    ],
)
def test_bad_weights_are_refused(walk, weights, message):
    cycle, _ = walk
    with pytest.raises(ParameterError, match=message):
        blend([cycle, cycle], weights)


def test_bad_inputs_are_refused(walk):
    cycle, _ = walk
    with pytest.raises(ParameterError, match="non-empty"):
        blend([], [])
    with pytest.raises(ParameterError, match="same channels"):
        blend([cycle, cycle.select(cycle.channels[:-1])], [0.5, 0.5])
    with pytest.raises(ParameterError, match="at least 4"):
        blend([cycle, cycle[:3]], [0.5, 0.5])
    with pytest.raises(ParameterError, match="exactly one"):
        transition(cycle, cycle)
    with pytest.raises(ParameterError, match="exactly one"):
        transition(cycle, cycle, frames=10, cycles=1)
    with pytest.raises(ParameterError, match="frames must be"):
        transition(cycle, cycle, frames=1)
    # channels in another order are matched by name
    order = list(reversed(cycle.channels))
    same = blend([cycle, cycle.select(order)], [0.5, 0.5])
    assert np.abs(same.frames - cycle.frames).max() < 1e-6


def test_angles_near_180_do_not_average_to_zero(walk):
    cycle, _ = walk
    c = cycle.channel_index("lhumerus", "ry")
    f = np.array(cycle.frames)
    f[:, c] = (f[:, c] + 180.0 + 180.0) % 360.0 - 180.0  # now crosses +-180 inside the file
    wrapped = cycle.with_frames(f)
    g = f.copy()
    g[:, c] -= 360.0  # the same rotations written one turn lower
    lower = cycle.with_frames(g)
    out = blend([wrapped, lower], [0.5, 0.5])
    diff = (out.frames[:, c] - f[:, c] + 180.0) % 360.0 - 180.0
    assert np.abs(diff).max() < 1e-6
    assert np.abs(np.diff(out.frames[:, c])).max() < 20  # continuous, no jump through 0


def test_blend_faces_the_reference_and_keeps_its_speed(walk):
    cycle, disp = walk
    assert mean_heading(cycle) == pytest.approx(0.0, abs=5.0)  # the synthetic walker faces +z
    turned = rotate_heading(cycle, 120.0)
    assert mean_heading(turned) == pytest.approx(mean_heading(cycle) + 120.0, abs=1e-6)
    # same bodies, positions turned: forward kinematics agrees after turning back
    back = rotate_heading(turned, -120.0)
    assert np.abs(back.positions().positions - cycle.positions().positions).max() < 1e-9
    out = blend([cycle, turned], [0.5, 0.5])
    # without turning, the velocities of the two would partly cancel
    assert out.metadata["root_displacement"][2] == pytest.approx(disp[2], rel=1e-6)
    assert np.abs(out.frames - cycle.frames).max() < 1e-6
    naive = blend([cycle, turned], [0.5, 0.5], align_heading=False)
    assert naive.metadata["root_displacement"][2] < 0.5 * disp[2]


#: Measured blends of the synthetic walk and jog (tests/_measured.py RUN), per jog weight:
#: loop closure, and the jerk of the pose channels and the cycle_summary jerk (joint
#: positions, issue 25), each over the weighted mean of the inputs' (held within 30 % either
#: way).
BLENDS = {0.0: (0.473, 1.0, 1.0), 0.25: (0.417, 0.651, 0.649), 0.5: (0.373, 0.617, 0.650),
          0.75: (0.337, 0.718, 0.773), 1.0: (0.312, 1.0, 1.016)}


def test_walk_jog_blends_move_period_and_stay_smooth(walk, jog):
    (w, w_disp), (j, j_disp) = walk, jog
    inputs = [cycle_summary(w), cycle_summary(j)]
    jerks = [jerk_summary(m.frames[:, pose_columns(m)], m.fps, cyclic=True) for m in (w, j)]
    lengths = []
    for wt in (0.0, 0.25, 0.5, 0.75, 1.0):
        out = blend([w, j], [1 - wt, wt])
        s = cycle_summary(out)
        lengths.append(out.n_frames)
        closure, pose_jerk, summary_jerk = BLENDS[wt]
        assert out.n_frames == round((1 - wt) * 120 + wt * 80)
        assert s["loop_closure"] <= at_most(closure)
        pj = jerk_summary(out.frames[:, pose_columns(out)], out.fps, cyclic=True)
        mean = (1 - wt) * jerks[0] + wt * jerks[1]
        assert at_least(pose_jerk) <= pj / mean <= at_most(pose_jerk)
        mean = (1 - wt) * inputs[0]["jerk"] + wt * inputs[1]["jerk"]
        assert at_least(summary_jerk) <= s["jerk"] / mean <= at_most(summary_jerk)
        # travel per loop is the weighted mean of the strides (blended in the heading's
        # frame and turned back along the blended heading: 1.3e-4 of the stride off it)
        assert out.metadata["root_displacement"][2] == pytest.approx(
            (1 - wt) * w_disp[2] + wt * j_disp[2], rel=5e-4)
        if wt == 0.0:
            assert np.abs(out.frames - w.frames).max() < 1e-6
        if wt == 1.0:
            al = out.metadata["blend"]["alignments"][1]
            expect = CycleCurve.from_motion(j).shifted(al["shift"]).sample(80)
            cols = pose_columns(j)
            assert np.abs(out.frames[:, cols] - expect[:, cols]).max() < 1e-6
    assert lengths == sorted(lengths, reverse=True) and lengths[0] > lengths[-1]


def test_transition_is_continuous_and_exports_to_bvh(walk, jog, tmp_path):
    (w, _), (j, _) = walk, jog
    clip = transition(w, j, cycles=2)
    info = clip.metadata["transition"]
    start, stop = info["ramp"]
    assert start == 120 and stop == 120 + info["ramp_frames"]
    assert clip.n_frames == stop + 80
    assert info["ramp_cycles"] == pytest.approx(2.0, abs=0.02)
    # starts with the walk's own frames, ends with weight 1
    assert np.abs(clip.frames[:120] - w.frames).max() < 1e-6
    weight = np.array(info["weight"])
    assert weight[0] == 0 and weight[-1] == 1 and np.all(np.diff(weight) >= 0)
    # phase advances at the walk's rate at first and the jog's at the end
    ph = np.diff(info["phase"])
    assert ph[0] == pytest.approx(1 / 120) and ph[-1] == pytest.approx(1 / 80)
    cont = info["continuity"]
    assert cont["max_ratio"] <= STEP_LIMIT
    # the ramp has no step larger than the larger of the two cycles' steps (x1.5)
    steps_w = np.linalg.norm(np.diff(prepare_cycle(w), axis=0), axis=1).max()
    steps_j = np.linalg.norm(np.diff(prepare_cycle(j), axis=0), axis=1).max()
    assert cont["max_step"] <= STEP_LIMIT * max(steps_w, steps_j)
    # a ramp far too short is reported with a longer suggestion
    quick = transition(w, j, frames=3, lead_in=0, lead_out=0)
    qc = quick.metadata["transition"]["continuity"]
    assert qc["max_ratio"] > STEP_LIMIT and qc["suggested_ramp_frames"] > 3
    # BVH round trip
    path = tmp_path / "walk_to_jog.bvh"
    cc.save(clip, path)
    back = cc.load(path)
    assert back.n_frames == clip.n_frames and back.fps == pytest.approx(clip.fps)
    assert np.abs(back.positions().positions - clip.positions().positions).max() < 1e-6


def test_typed_results_carry_what_the_metadata_files(walk, jog):
    (w, _), (j, _) = walk, jog
    res = cc.blend([w, j], [0.25, 0.75], full_output=True)
    assert isinstance(res, cc.BlendResult)
    plain = cc.blend([w, j], [0.25, 0.75])
    np.testing.assert_array_equal(res.motion.frames, plain.frames)
    info = plain.metadata["blend"]
    np.testing.assert_allclose(res.weights, [0.25, 0.75])
    assert res.period_frames == plain.metadata["period_frames"] == plain.n_frames
    np.testing.assert_allclose(res.root_displacement, plain.metadata["root_displacement"])
    assert res.alignments == info["alignments"] and res.sources == info["sources"]
    tr = cc.transition(w, j, cycles=2, full_output=True)
    assert isinstance(tr, cc.TransitionResult)
    clip = cc.transition(w, j, cycles=2)
    t = clip.metadata["transition"]
    np.testing.assert_array_equal(tr.motion.frames, clip.frames)
    assert list(tr.ramp) == t["ramp"] and tr.ramp_frames == t["ramp_frames"]
    np.testing.assert_allclose(tr.weight, t["weight"])
    np.testing.assert_allclose(tr.phase, t["phase"])
    assert tr.continuity["max_ratio"] == t["continuity"]["max_ratio"] <= STEP_LIMIT
    assert tr.weight.shape == (tr.motion.n_frames,)


def test_transition_by_frames_and_without_leads(walk, jog):
    (w, _), (j, _) = walk, jog
    clip = transition(w, j, frames=150, lead_in=0, lead_out=0)
    assert clip.n_frames == 150
    info = clip.metadata["transition"]
    assert info["weight"][0] == 0 and info["weight"][-1] == 1
    assert info["continuity"]["max_ratio"] <= STEP_LIMIT
    # the ground position keeps advancing (never jumps back between the two cycles)
    tz = clip.frames[:, clip.channel_index("root", "tz")]
    assert np.all(np.diff(tz) > 0)


def test_as_cycle_rule(walk, tmp_path):
    cycle, _ = walk
    src = as_cycle(cycle)
    assert not src.extracted and src.cycle is cycle and "taken as a cycle" in src.reason
    cap = cc.datasets.make_periodic_capture(n_frames=400, period=100, noise=0.3, random_state=1).motion
    assert estimate_period(cap) == pytest.approx(100, rel=0.1)
    assert estimate_period(cycle) is None
    src = as_cycle(cap)
    assert src.extracted and "repeats every" in src.reason
    assert src.cycle.n_frames == pytest.approx(100, rel=0.1)
    assert as_cycle(cap, mode="cycle").cycle is cap
    # what extract writes is recognised by its metadata after an NPZ round trip
    path = tmp_path / "cycle.npz"
    cc.save(src.cycle, path)
    again = as_cycle(cc.load(path))
    assert not again.extracted and "metadata" in again.reason
    # a still capture "loops" (its seam is one more noisy step) but does not move
    still = cc.datasets.make_static_capture(random_state=0).motion
    with pytest.raises(cc.NoPeriodicMotionError):
        as_cycle(still)
    with pytest.raises(ParameterError, match="mode"):
        as_cycle(cycle, mode="maybe")
    with pytest.raises(ParameterError, match="frame range"):
        as_cycle(cap, frames=(300, 500))


# --------------------------------------------------------------- real captures
@pytest.fixture(scope="module")
def cmu_cycles(cmu_dir):
    walk = as_cycle(cc.load(cmu_dir / "69" / "69_01.amc"), frames=(200, 450), max_scale=50)
    # 143_01: the paper's window and threshold; the cocycle read at 40 (inside the bar
    # [25, 50)) follows the strides (period ~45 frames, as the hip angles show)
    jog = as_cycle(cc.load(cmu_dir / "143" / "143_01.amc"), frames=(0, 96), max_scale=50, scale=40)
    assert walk.extracted and jog.extracted
    return walk.cycle, jog.cycle


def test_cmu_walk_and_jog_blends(cmu_cycles):
    from cyclecoord.quality.plausibility import check_plausibility

    w, j = cmu_cycles
    assert 130 <= w.n_frames <= 160 and 38 <= j.n_frames <= 55
    jerks = [jerk_summary(m.frames[:, pose_columns(m)], m.fps, cyclic=True) for m in (w, j)]
    periods = []
    # measured per jog weight: loop closure, pose jerk over the inputs' weighted mean
    measured = {0.0: (0.695, 1.0), 0.25: (0.790, 0.863), 0.5: (0.922, 0.866), 0.75: (1.011, 0.762),
                1.0: (1.120, 1.02)}
    for wt in (0.0, 0.25, 0.5, 0.75, 1.0):
        out = blend([w, j], [1 - wt, wt])
        periods.append(out.n_frames)
        s = cycle_summary(out)
        closure, pose_jerk = measured[wt]
        assert s["loop_closure"] <= min(1.5, at_most(closure))
        pj = jerk_summary(out.frames[:, pose_columns(out)], out.fps, cyclic=True)
        assert at_least(pose_jerk) <= pj / ((1 - wt) * jerks[0] + wt * jerks[1]) <= at_most(pose_jerk)
        report = check_plausibility(out, [w, j])
        assert report.notes
        if not report.clean:  # it explains itself: which bones, how close, against what
            new = [c for c in report.contacts if c["new"]]
            assert new and all(c["reference_min_distance"] is not None for c in new)
            assert any(new[0]["bones"][0] in n for n in report.notes) or report.joint_range
    assert all(a > b for a, b in zip(periods, periods[1:]))


def test_cmu_walk_to_jog_transition(cmu_cycles, tmp_path):
    w, j = cmu_cycles
    clip = transition(w, j, cycles=2)
    assert clip.metadata["transition"]["continuity"]["max_ratio"] <= STEP_LIMIT
    path = tmp_path / "t.bvh"
    cc.save(clip, path)
    back = cc.load(path)
    assert np.abs(back.positions().positions - clip.positions().positions).max() < 1e-6


def test_blend_is_on_rotations_not_euler_numbers():
    """A cycle blended with itself written as flipped, wrapped Euler numbers is the cycle
    (averaging the numbers would fold every joint on the flipped frames)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "periodic"))
    from test_rotations import scrambled

    import cyclecoord as cc
    from cyclecoord.synthesis.blend import blend

    cycle = cc.extract(cc.datasets.example_capture().motion).cycle
    mixed = blend([cycle, scrambled(cycle, seed=3)], [0.5, 0.5], align_heading=False)
    a = cycle.positions().positions
    b = mixed.positions().positions
    a = a - a[:, :1]
    b = b - b[:, :1]
    assert np.abs(a - b).max() < 1e-3 * np.ptp(a)
    joints = np.setdiff1d(np.arange(cycle.n_channels), np.asarray(cycle.root_channels()))
    assert np.abs(np.diff(mixed.frames[:, joints], axis=0)).max() < 20  # written continuous


# ------------------------------------------------- a root facing along X, turning each loop
def _curving(period=120, turn=5.0, heading=88.0, loops=1):
    """``loops`` loops of a synthetic walk whose root is written in XYZ order (a CMU root:
    Y, the vertical, in the middle) facing ``heading`` degrees from +Z (near the order's
    gimbal lock at 90) and turning ``turn`` degrees a loop, its travel turning with it."""
    from scipy.spatial.transform import Rotation

    from cyclecoord.conventions import continuous_euler
    from cyclecoord.synthesis.align import root_rotation

    n = loops * period
    m = cc.datasets.make_periodic_capture(kind="walk", n_frames=n + 1, period=period,
                                          noise=0.0, speed_variation=0.0,
                                          random_state=0).motion
    mats, _, _ = root_rotation(m)
    skel = m.skeleton
    root = skel.joints[0]
    psi = np.radians(heading + turn * np.arange(m.n_frames) / period)
    up = np.array([0.0, 1.0, 0.0])
    world = Rotation.from_rotvec(psi[:, None] * up).as_matrix() @ mats
    pos = np.stack([m.frames[:, m.channel_index(root.name, "t" + a)] for a in "xyz"], 1)
    mid = Rotation.from_rotvec(0.5 * (psi[1:] + psi[:-1])[:, None] * up)
    steps = mid.apply(np.diff(pos, axis=0))
    pos = np.vstack([pos[:1], pos[:1] + np.cumsum(steps, axis=0)])
    dofs = ("tx", "ty", "tz", "rx", "ry", "rz")
    joints = (replace(root, dofs=dofs, rotation_order="XYZ"),) + tuple(skel.joints[1:])
    xyz = replace(skel, joints=joints)
    frames = np.zeros((m.n_frames, len(xyz.channels)))
    for c, (j, d) in enumerate(xyz.channels):
        if j != root.name:
            frames[:, c] = m.frames[:, m.channel_index(j, d)]
    frames[:, :3] = pos
    frames[:, 3:6] = continuous_euler(world[:, None], "XYZ")[:, 0]
    return cc.Motion(frames, xyz.channels, m.fps, xyz, "curving")[:n]


def test_a_transitions_lead_out_goes_on_as_a_turning_cycle_does():
    """A cycle whose root (XYZ, facing 88 degrees from +Z) turns 5 degrees a loop, into
    itself: the lead-out, three loops on, is the capture's own fourth loop (feet within a
    5 mm), facing and travelling 15 degrees round.  The curves extrapolated the
    root's Euler channels loop by loop (at the middle angle's gimbal lock that is no
    rotation) and its travel along a straight line while the body turned: subject 143's
    jog (87 degrees, 4.6 a loop) faced 14 degrees off its path there and its stance
    foot slid 0.7-1.1 m/s (0.13 in the cycle)."""
    period = 120
    c = _curving(period)
    truth = _curving(period, loops=4)
    assert c.skeleton.joints[0].rotation_order == "XYZ"
    clip = transition(c, c, cycles=2)
    info = clip.metadata["transition"]
    assert info["lead_in_frames"] == period and info["lead_out_frames"] == period
    assert clip.n_frames == 4 * period + 1  # (a ramp of two loops and a frame)
    feet = ["lfoot", "rfoot", "ltoes", "rtoes"]
    got = np.stack([clip.positions()[f] for f in feet], 1)[: 4 * period]
    want = np.stack([truth.positions()[f] for f in feet], 1)
    err = np.linalg.norm(got - want, axis=2).max(axis=1) * cc.rig.metres_per_unit(c)
    assert err.max() < 0.005, (err[:period].max(), err[-period:].max())  # 1.8 mm


def test_another_actors_travel_is_scaled_by_the_legs(walk):
    """A cycle of an actor with legs 1.2x as long (arms and spine as they were) ramped
    into from ours: its travel and hip height are scaled by the legs' ratio, so its feet
    stay on the floor.  By the summed bone lengths (the legs are a third of them) the
    hips stood too high for the legs or too low: subject 143's jog after subject 35's
    walk put a foot 4.4 cm under the floor on 23 % of the frames."""
    w, _ = walk
    skel = w.skeleton
    below = set()
    for name in ("lfemur", "rfemur"):
        todo = [skel.index(name)]
        while todo:
            j = todo.pop()
            below.add(j)
            todo += skel.children(j)
    joints = tuple(replace(j, offset=np.asarray(j.offset) * (1.2 if i in below else 1.0),
                           end_site=None if j.end_site is None else
                           np.asarray(j.end_site) * (1.2 if i in below else 1.0))
                   for i, j in enumerate(skel.joints))
    frames = np.array(w.frames)
    root = skel.joints[0].name
    for d in ("tx", "ty", "tz"):
        frames[:, w.channel_index(root, d)] *= 1.2
    tall = w.with_frames(frames, skeleton=replace(skel, joints=joints))
    clip = transition(w, tall, cycles=1)
    assert clip.metadata["transition"]["root_scales"][1] == pytest.approx(1 / 1.2, rel=1e-3)

    def lowest(m):
        J = m.positions()
        return np.min([J[f][:, 1] for f in ("lfoot", "rfoot", "ltoes", "rtoes")], axis=0)

    n_out = clip.metadata["transition"]["lead_out_frames"]
    gap = (np.percentile(lowest(clip[-n_out:]), 5) - np.percentile(lowest(w), 5))
    assert abs(gap) * cc.rig.metres_per_unit(w) < 0.005


def test_a_static_root_rig_blends_and_transitions_as_the_plain_one(walk, jog):
    """The Bandai layout (a static ``joint_Root`` above the travelling hips, 6 channels on
    every joint): blend and transition work on the rig's analysis form and write back in
    the inputs' own, so the joints land where the plain rig's result puts them.  The
    static root was the root the curves moved and the hips' travel a periodic joint
    channel: a Bandai walk-to-run transition's support foot glided 0.23 m/s (0.07 now;
    the cycles' 0.05), a blend of its turning walks 0.40 m/s (0.01)."""
    from _rigs import static_root

    from cyclecoord.conventions import to_bvh_convention

    plain = [replace(to_bvh_convention(m, "ZXY"), fps=30.0) for m, _ in (walk, jog)]
    static = [static_root(m, np.eye(3), (0.0, 0.0, 0.0), positions_everywhere=True)
              for m in plain]
    assert static[0].skeleton.joints[0].name == "joint_Root"
    for made in (lambda ms: blend(ms, [0.5, 0.5]), lambda ms: transition(*ms, cycles=2)):
        want, got = made(plain), made(static)
        assert got.channels == static[0].channels  # written back in the inputs' rig
        a, b = want.positions(), got.positions()
        names = [n for n in a.names if n in b.names]
        err = max(np.abs(a[n] - b[n]).max() for n in names)
        assert err * cc.rig.metres_per_unit(want) < 1e-3, err
        assert "root_displacement" not in got.metadata  # (the static root does not travel)
        if "blend" in got.metadata:  # the hips' per-loop travel
            assert got.metadata["travel_displacement"] == pytest.approx(
                want.metadata["root_displacement"], abs=1e-6)


def test_a_z_up_rig_blends_as_its_y_up_original(walk, jog):
    """A Z-up rig is blended in its analysis form (Y up) whatever ``up`` names: the joints
    land where the Y-up rig's result puts them, turned to Z up."""
    from _rigs import turn_root

    from cyclecoord.conventions import to_bvh_convention
    from cyclecoord.rig import Z_TO_Y

    plain = [replace(to_bvh_convention(m, "ZXY"), fps=30.0) for m, _ in (walk, jog)]
    zup = [turn_root(m, Z_TO_Y.T) for m in plain]
    want = blend(plain, [0.5, 0.5]).positions()
    for up in ("z", "y"):
        got = blend(zup, [0.5, 0.5], up=up)
        assert got.channels == zup[0].channels
        pos = got.positions()
        err = max(np.abs(pos[n] @ Z_TO_Y.T - want[n]).max() for n in want.names)
        assert err * cc.rig.metres_per_unit(got) < 1e-3, (up, err)


def test_a_blend_of_opposed_travels_says_its_strides_cancel(walk, jog):
    """A walk forwards and the same walk backwards: the blend notes that they travel half
    a turn apart (the Bandai walk and backward walk blended stepped nearly in place, feet
    gliding 0.24 m/s); a walk and a jog going the same way get no such note."""
    (w, _), (j, _) = walk, jog
    back = blend([w, played_backwards(w)], [0.5, 0.5])
    said = [n for n in back.metadata["blend"]["notes"] if "travel" in n]
    assert said and "180 degrees apart" in said[0]
    assert not [n for n in blend([w, j], [0.5, 0.5]).metadata["blend"]["notes"]
                if "apart" in n]
    # a weight of 0 leaves that cycle out
    assert not [n for n in blend([w, played_backwards(w)], [1.0, 0.0]).metadata["blend"]["notes"]
                if "apart" in n]
