"""Steady frames of a take: pace, heading and the speed ramps out of standing (periodic.steady)."""

import numpy as np
import pytest
from _measured import at_most

from cyclecoord.periodic.steady import period_speed, steady_mask
from cyclecoord.periodic.windings import stretches


def _take(T=1000, period=100.0, still=200, ramp=150):
    """A coordinate turning once per period after ``still`` standing frames; the joint
    speed ramps up linearly over the first ``ramp`` moving frames."""
    t = np.arange(T, dtype=float)
    moving = t >= still
    u = np.where(moving, (t - still) / period, np.nan)
    speed = np.where(moving, np.clip((t - still) / ramp, 0.2, 1.0), 0.0)
    return u, moving, speed


def test_the_ramp_out_of_a_standing_start_is_not_steady():
    u, moving, speed = _take()
    without = steady_mask(u, moving, 100.0)
    assert stretches(without) == [(200, 1000)]
    with_speed = steady_mask(u, moving, 100.0, speed=speed)
    (a, b), = stretches(with_speed)
    # trimmed while slower than the median / 1.3 (speed 1 / 1.3 is reached 115 frames in)
    assert b == 1000 and 200 + 110 <= a <= 200 + 120


def test_the_takes_own_first_frames_and_the_inside_are_not_judged_by_speed():
    u, moving, speed = _take(still=0)
    assert stretches(steady_mask(u, moving, 100.0, speed=speed)) == [(0, 1000)]
    # a slow stretch inside a moving run (arm circles that grow, then shrink) stays steady
    u, moving, _ = _take()
    inside = np.where(moving, 1.0, 0.0)
    inside[500:600] = 0.3
    assert stretches(steady_mask(u, moving, 100.0, speed=inside)) == [(200, 1000)]


def test_period_speed_averages_the_smoothed_steps_over_a_period():
    rng = np.random.default_rng(0)
    x = np.cumsum(np.r_[np.zeros((300, 3)), np.full((300, 3), 0.5)], axis=0) + rng.normal(0, 1e-3, (600, 3))
    v = period_speed(x, fps=120.0, period=60.0)
    assert v.shape == (600,)
    assert v[:200].max() < 0.05 and np.allclose(v[400:550], 0.5 * np.sqrt(3), rtol=0.02)
    cols = period_speed(np.c_[x, 100 * x], 120.0, 60.0, columns=np.array([0, 1, 2]))
    np.testing.assert_allclose(cols, v)


def test_recurrence_is_the_nearest_pose_one_period_away_either_way():
    from cyclecoord.periodic.steady import recurrence

    rng = np.random.default_rng(1)
    x = rng.normal(size=(700, 4))
    period = 50.0
    got = recurrence(x, period, chunk=64)  # blocks smaller than the lags
    lags = range(35, 74)  # floor(0.7 * 50) to ceil(1.45 * 50)
    want = np.full(len(x), np.inf)
    for t in range(len(x)):
        for lag in lags:
            for s in (t - lag, t + lag):
                if 0 <= s < len(x):
                    want[t] = min(want[t], np.linalg.norm(x[s] - x[t]))
    np.testing.assert_allclose(got, want, rtol=1e-12)
    assert np.isinf(recurrence(x[:30], period)).all()  # no pose a period away


def test_recurrence_of_some_columns_reads_them_block_by_block():
    from cyclecoord.periodic.steady import recurrence

    rng = np.random.default_rng(2)
    x = rng.normal(size=(900, 6))
    cols = np.array([0, 2, 5])
    np.testing.assert_array_equal(
        recurrence(x, 40.0, columns=cols, chunk=100), recurrence(x[:, cols], 40.0, chunk=100)
    )


# ------------------------------------------------------------------ curved paths (issue 23)
def curved(m, degrees_per_frame, start=0):
    """The capture walked on a circle: from frame ``start`` on, the root's heading turns at
    a constant rate and its ground steps turn with it."""
    from scipy.spatial.transform import Rotation

    from cyclecoord.conventions import continuous_euler
    from cyclecoord.periodic.root import root_layout, root_rotations

    lay = root_layout(m)
    f = m.frames.copy()
    R = root_rotations(f, lay)  # world rotations (T, 3, 3)
    theta = np.radians(degrees_per_frame) * np.maximum(np.arange(m.n_frames) - start, 0)
    turn = Rotation.from_rotvec(np.outer(theta, [0.0, 1.0, 0.0])).as_matrix()
    p = f[:, [lay.column(t) for t in ("tx", "ty", "tz")]]
    step = np.diff(p, axis=0)
    new_step = np.einsum("tij,tj->ti", turn[:-1], step)
    newp = np.vstack([p[:1], p[:1] + np.cumsum(new_step, axis=0)])
    G = np.einsum("tij,tjk->tik", turn, R)
    local = np.einsum("ji,tjk,kl->til", lay.axis, G, lay.axis)
    ang = continuous_euler(local[:, None], lay.order)[:, 0]
    for k, a in enumerate(lay.order.lower()):
        f[:, lay.column("r" + a)] = ang[:, k]
    for k, t in enumerate(("tx", "ty", "tz")):
        f[:, lay.column(t)] = newp[:, k]
    return m.with_frames(f)


def test_a_walk_on_a_circle_is_steady():
    """45 degrees of turn per cycle (an 8-cycle circle) is a walk, not a disturbance (the
    old rule, at most 30 degrees of turn over a period, kept no frame of it)."""
    import cyclecoord as cc
    from cyclecoord.datasets import make_periodic_capture

    m = make_periodic_capture(n_frames=720, period=120.0, speed_variation=0.05,
                              random_state=1).motion
    straight = cc.extract(m)
    circle = cc.extract(curved(m, 45.0 / 120.0))
    # measured (tests/_measured.py RUN): the straight walk's period to 2e-6, every frame the
    # straight walk uses, 44.91 degrees a cycle
    assert abs(circle.period_frames / straight.period_frames - 1) <= 1.0 / 120  # a frame
    used = sum(b - a for a, b in circle.used_frames)
    assert used >= 0.95 * sum(b - a for a, b in straight.used_frames)
    assert circle.heading_per_cycle == pytest.approx(45.0, abs=at_most(0.09, 0.5))


def test_steady_turning_rejects_the_start_of_a_turn_and_a_u_turn():
    from cyclecoord.periodic.steady import steady_turning

    P = 100
    t = np.arange(1000)
    circle = 0.3 * t  # 30 degrees a period, all along
    assert steady_turning(circle, P).all()
    corner = np.interp(t, [0, 450, 550, 999], [0, 0, 90, 90])  # a 90-degree corner in a period
    ok = steady_turning(corner, P)
    assert not ok[420:580].any() and ok[:350].all() and ok[650:].all()
    u_turn = np.interp(t, [0, 450, 550, 999], [0, 0, 180, 180])
    assert not steady_turning(u_turn, P)[450:550].any()


def test_a_fast_shake_at_30_fps_is_motion():
    """The poses are smoothed only lightly (0.04 s: 1.2 frames at 30 fps) before their
    speed is read: a 6 Hz shake of 10 degrees moves as much as a slow 30-degree swing."""
    from cyclecoord.periodic.steady import moving_mask

    t = np.arange(180)
    swing_then_shake = np.where(t < 90, 30 * np.sin(2 * np.pi * t / 60), 10 * np.sin(2 * np.pi * t / 5))
    assert moving_mask(np.repeat(swing_then_shake[:, None], 3, axis=1), 30.0).all()


def test_centred_window_stays_inside():
    from cyclecoord.periodic.steady import centred_window

    lo, hi = centred_window(10, 2)
    assert lo.tolist() == [0, 0, 0, 1, 2, 3, 4, 5, 5, 5]
    assert hi.tolist() == [4, 4, 4, 5, 6, 7, 8, 9, 9, 9]
    lo, hi = centred_window(5, 2)  # exactly as wide as the frames
    assert lo.tolist() == [0] * 5 and hi.tolist() == [4] * 5
    lo, hi = centred_window(3, 5)  # wider than the frames: all of them
    assert lo.tolist() == [0, 0, 0] and hi.tolist() == [2, 2, 2]


def test_a_two_frame_stretch_at_pace_is_steady():
    """Pace over the frames a stretch has: two candidate frames half a turn apart with a
    period of 2 frames turn once a period (a stretch this short is kept only when it is
    as long as the period: runs under a period are dropped)."""
    u = np.full(8, np.nan)
    u[3:5] = [0.3, 0.8]
    cand = ~np.isnan(u)
    assert np.flatnonzero(steady_mask(u, cand, 2.0)).tolist() == [3, 4]
    u[4] = 0.4  # 0.2 turns per period: too slow
    assert not steady_mask(u, cand, 2.0).any()


def test_moving_mask_finds_the_motion_between_still_stretches():
    """3 s still, 6 s of a 1 Hz swing with a 1 s hold in the middle, 3 s still, a 0.5 s
    burst, still to the end (30 fps): the swing is moving (the hold splits it, a second is
    more than the half second bridged), the burst is shorter than a second: still."""
    from cyclecoord.periodic.steady import moving_mask

    fps, t = 30.0, np.arange(540)
    swing = 20 * np.sin(2 * np.pi * t / 30)
    s = np.where(((t >= 90) & (t < 270)) | ((t >= 300) & (t < 360)) | ((t >= 450) & (t < 465)),
                 swing, 0.0)
    mask = moving_mask(np.c_[s, 0.5 * s, -s], fps)
    assert mask.shape == (540,)
    (a0, b0), (a1, b1) = stretches(mask)
    # the speed's 0.5 s moving average blurs each end by at most 15 / 2 frames
    for got, want in ((a0, 90), (b0, 270), (a1, 300), (b1, 360)):
        assert abs(got - want) <= 8, (got, want)
    assert not mask[400:].any()  # the burst
    # only the named columns are read: the same answer from them inside wider poses
    wide = np.c_[np.zeros((540, 2)), s, 0.5 * s, -s, 100 * np.cos(t)]
    np.testing.assert_array_equal(moving_mask(wide, fps, columns=np.array([2, 3, 4])), mask)
    # a still take has no moving frame; too short or no joints to judge: all moving
    assert not moving_mask(np.ones((540, 3)), fps).any()
    assert not moving_mask(np.ones((3, 3)), fps).any()  # three frames are judged
    # the level is the take's own: the same motion a hundred times smaller moves alike
    np.testing.assert_array_equal(moving_mask(np.c_[s, 0.5 * s, -s] / 100, fps), mask)
    assert moving_mask(np.c_[s, s][:2], fps).all()
    assert moving_mask(np.zeros((540, 0)), fps).all()
    assert moving_mask(wide, fps, columns=np.array([], dtype=int)).all()


def test_pace_is_read_over_a_whole_period():
    """A coordinate that stalls 90 % of each cycle and jumps through the turn in the last
    10 % still turns exactly once over every period-long window: every frame is at pace.
    A steady pace is kept between 1 / max_pace and max_pace turns a period."""
    P, t = 100, np.arange(1000)
    phase = (t % P) / P
    u = t // P + np.where(phase < 0.9, 0.0, (phase - 0.9) / 0.1)
    cand = np.ones(t.size, dtype=bool)
    assert stretches(steady_mask(u, cand, float(P), pace_window=1.0)) == [(0, 1000)]
    for rate, steady in ((0.6, False), (0.65, True), (1.5, True), (1.7, False)):
        got = steady_mask(t * rate / P, cand, float(P), pace_window=1.0)
        assert got.all() if steady else not got.any(), rate
    # the bounds are kept (exact paces: 128 frames a period, multiples of 1/256 a frame)
    assert steady_mask(t * 1.5 / 128, cand, 128.0, max_pace=1.5).all()
    assert steady_mask(t * 0.5 / 128, cand, 128.0, max_pace=2.0).all()
    # a pace that jumps from 1 to 1.8 turns a period at frame 500: the one-period window
    # reads 1.6 at frame 525, the two-period one at 550; a frame is at pace when either is
    u = np.where(t < 500, t / P, 5 + 1.8 * (t - 500) / P)
    assert stretches(steady_mask(u, cand, float(P))) == [(0, 551)]


def test_clean_runs_bridges_short_gaps_then_drops_short_runs():
    from cyclecoord.periodic.steady import clean_runs

    m = np.array([1, 1, 0, 0, 1, 1, 0, 0, 0, 1, 1, 1, 1, 0, 1], bool)
    # gaps of 2 bridged (not the 3-frame one); then runs under 4 frames dropped
    want = np.array([1, 1, 1, 1, 1, 1, 0, 0, 0, 1, 1, 1, 1, 1, 1], bool)
    np.testing.assert_array_equal(clean_runs(m, min_run=4, max_gap=2), want)
    assert not clean_runs(m, min_run=7, max_gap=2).any()  # two runs of 6 left: dropped
    assert clean_runs(m, min_run=7, max_gap=3).all()  # every gap bridged: one run of 15
    only = np.zeros(15, bool)
    only[9:13] = True  # nothing bridged: the one run of 4
    np.testing.assert_array_equal(clean_runs(m, min_run=3, max_gap=0), only)


def test_steady_turning_keeps_a_turn_of_exactly_max_curve():
    """A heading turning 1 degree a frame turns 20 degrees over a 20-frame period."""
    from cyclecoord.periodic.steady import steady_turning

    heading = np.arange(100.0)
    assert steady_turning(heading, 20.0, max_curve=20.0).all()
    assert not steady_turning(heading, 20.0, max_curve=19.5).any()


def test_gaps_of_a_quarter_period_are_bridged():
    """Period 100: a 25-frame gap (frames whose recurrence distance is over the limit)
    inside a steady stretch is bridged, a 26-frame one is not."""
    t = np.arange(1000)
    u = t / 100.0
    cand = np.ones(1000, bool)
    for gap, bridged in ((25, True), (26, False)):
        r = np.ones(1000)
        r[500 : 500 + gap] = 10.0
        got = steady_mask(u, cand, 100.0, recurrence_distance=r)
        assert got.all() == bridged, gap
        assert got[:500].all() and got[500 + gap :].all()


def test_a_tight_curve_is_steady_and_a_corner_within_a_cycle_is_not():
    """The default ``max_curve`` is 90 degrees a period: a walk on a circle of four to
    five cycles (Bandai's turning walks take their corners at 51 and 65 degrees a period)
    is steady all along; a steady spin faster than a quarter turn a cycle is not."""
    from cyclecoord.periodic.steady import steady_turning

    P = 30
    t = np.arange(600)
    assert steady_turning(65.0 / P * t, P).all()
    assert steady_turning(89.0 / P * t, P).all()
    assert not steady_turning(91.0 / P * t, P).any()


def test_steady_mask_keeps_a_curve_up_to_its_default_limit():
    """steady_mask's own default max_curve is 90 degrees a period, as steady_turning's: a
    heading turning 89 degrees a period is steady, 91 is not (a corner taken within a
    cycle); the coordinate winds at the period's pace all along."""
    P, T = 30.0, 600
    t = np.arange(T)
    u = t / P
    cand = np.ones(T, dtype=bool)
    assert steady_mask(u, cand, P, heading=89.0 / P * t).all()
    assert not steady_mask(u, cand, P, heading=91.0 / P * t).any()
