"""Known answers for the pieces of ``synthesis.carry`` (the root's scale, the hold's ease,
the channel bounds, a lock that pins nothing)."""

import numpy as np
import pytest

from cyclecoord.synthesis import carry

from _legs import legs_skeleton, make_motion, pins_pop_at, swaying_legs  # tests/ is on the path (rootdir conftest)


def test_translation_scale_is_one_world_unit_per_channel_unit():
    m = make_motion(legs_skeleton(), T=5, fps=30.0, root_speed=3.0)
    for dof in ("tx", "ty", "tz"):
        col = m.channels.index(("root", dof))
        assert carry._translation_scale(m, col) == pytest.approx(1.0)


def test_the_floor_lifts_the_root_by_the_depth_of_the_lowest_foot():
    """Feet 0.3 units under the given floor on every frame: the root rises by exactly 0.3
    (a constant depth, so the smoothing of the lift changes nothing)."""
    m = make_motion(legs_skeleton(), T=30, fps=30.0)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    low = carry._lowest_points(m, feet)
    out = carry.carry_by_feet(m, feet, floor=float(low.min()) + 0.3)
    ty = m.channels.index(("root", "ty"))
    np.testing.assert_allclose(out.frames[:, ty] - m.frames[:, ty], 0.3, atol=1e-9)


def test_a_stand_is_lowered_onto_the_floor_over_stand_after_seconds():
    """A body standing 0.4 units over the given floor (a run stopped in its flight): on
    an asked hold it comes down onto the floor over STAND_AFTER s (a smoothstep) and
    back up as long after it; outside holds, or without a floor, nothing changes."""
    m = make_motion(legs_skeleton(), T=90, fps=30.0)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    floor = float(carry._lowest_points(m, feet).min()) - 0.4
    hold = np.zeros(90, bool)
    hold[20:60] = True
    out = carry.carry_by_feet(m, feet, floor=floor, hold=hold)
    low = carry._lowest_points(out, feet)
    n = int(round(carry.STAND_AFTER * 30))
    np.testing.assert_allclose(low[:20], floor + 0.4, atol=1e-9)
    np.testing.assert_allclose(low[20 + n : 60], floor, atol=1e-9)
    np.testing.assert_allclose(low[60 + n :], floor + 0.4, atol=1e-9)
    u = 7 / n
    assert low[27] == pytest.approx(floor + 0.4 * (1 - u * u * (3 - 2 * u)))
    np.testing.assert_allclose(carry._standing(hold, 30.0)[20 + n : 60], 1.0)
    np.testing.assert_allclose(carry.carry_by_feet(m, feet, hold=hold).frames, m.frames)


def test_lowest_points_are_the_feet_and_their_end_sites():
    m = make_motion(legs_skeleton(), T=3, fps=30.0)
    pos = m.positions()
    want = min(pos["ltoes"][0, 1], pos["rtoes"][0, 1], pos["ltoes/end"][0, 1])
    assert carry._lowest_points(m, ("lfoot", "ltoes", "rfoot", "rtoes"))[0] == pytest.approx(want)
    # a foot list without the toes: the ankles only (the toes' end sites are not theirs)
    ankles = carry._lowest_points(m, ("lfoot", "rfoot"))
    np.testing.assert_allclose(ankles, np.minimum(pos["lfoot"][:, 1], pos["rfoot"][:, 1]))


def test_a_hold_eases_its_steps_to_nothing_over_stand_after_seconds():
    """The factor on each step: 1 outside the hold, a smoothstep from 1 to 0 over
    STAND_AFTER s into it (by hand at a quarter of the way: 1 - (3u^2 - 2u^3))."""
    fps = 30.0
    hold = np.zeros(90, dtype=bool)
    hold[30:] = True
    f = carry._moving(hold, fps)
    n = int(round(carry.STAND_AFTER * fps))  # 15 frames
    assert f.shape == (89,)
    np.testing.assert_allclose(f[:29], 1.0)
    frame = np.ones(90)
    u = np.clip((np.arange(30, 90) - 30) / n, 0, 1)
    frame[30:] = 1 - u * u * (3 - 2 * u)
    np.testing.assert_allclose(f, 0.5 * (frame[1:] + frame[:-1]))
    assert 0.5 < f[32] < 0.95  # easing, not a stop within a frame
    np.testing.assert_allclose(f[30 + n :], 0.0)


def test_channel_bounds_leave_the_root_free_and_widen_the_rest():
    m = make_motion(legs_skeleton(), T=10, fps=30.0, root_speed=5.0)
    lo, hi, angle = carry.channel_bounds([m], margin=5.0)
    for c in m.root_channels():
        assert lo[c] == -np.inf and hi[c] == np.inf and not angle[c]
    other = [i for i in range(len(m.channels)) if i not in m.root_channels()]
    np.testing.assert_allclose(lo[other], m.frames[:, other].min(axis=0) - 5.0)
    np.testing.assert_allclose(hi[other], m.frames[:, other].max(axis=0) + 5.0)
    assert all(angle[i] == (m.channels[i][1] in ("rx", "ry", "rz")) for i in other)


def test_angles_are_in_bounds_on_any_turn_and_each_channel_is_judged_alone():
    """A take whose knee swings 170-190 degrees written as 170..180, -180..-170 (the
    Euler branch flips): its range is 165-195 on one turn, and a motion at 545 degrees
    (a turn up) or -170 is inside, 200 and -150 are not; a translation channel is
    never wrapped.  Each channel is judged alone (``_outside`` is per channel)."""
    m = make_motion(legs_skeleton(), T=21, fps=30.0)
    k = m.channels.index(("ltibia", "rx"))
    f = m.frames.copy()
    swing = np.linspace(170.0, 190.0, 21)
    f[:, k] = (swing + 180.0) % 360.0 - 180.0
    take = m.with_frames(f)
    lo, hi, angle = carry.channel_bounds([take], margin=5.0)
    assert angle[k] and lo[k] == pytest.approx(165.0, abs=1e-9)
    assert hi[k] == pytest.approx(195.0, abs=1e-9)
    test = np.repeat(f[:1], 4, axis=0)
    test[:, k] = [545.0, -170.0, 200.0, -150.0]
    out = carry._outside(test, (lo, hi, angle))
    assert out.shape == test.shape
    assert out[:, k].tolist() == [False, False, True, True]
    others = [c for c in range(test.shape[1]) if c != k]
    assert not out[:, others].any()
    tx = m.channels.index(("root", "tx"))
    plain = (np.zeros_like(lo), np.ones_like(hi), np.zeros_like(angle))
    row = np.full((1, test.shape[1]), 0.5)
    row[0, tx] = 360.5  # 0.5 a turn away, but a length: outside
    assert carry._outside(row, plain)[0, tx]


def test_a_pin_that_takes_a_channel_out_of_range_is_refused_though_another_was_out():
    """The frames before pinning have one channel out of its range everywhere; a pin that
    twists a second channel out is still a pin that left the range (the frame-wide test
    let every such pin through on a Bandai script: a knee twisted 21 degrees)."""
    from test_footlock import _walkish  # noqa: E402

    m = _walkish(T=120, fps=60.0)
    lo, hi, angle = carry.channel_bounds([m], margin=5.0)
    out_col = m.channels.index(("rfoot", "rx"))
    lo[out_col] = hi[out_col] = m.frames[:, out_col].min() - 50.0  # out on every frame
    twist = m.channels.index(("ltibia", "rx"))
    import cyclecoord.synthesis.footlock as F

    real = F.pin_feet

    def twisting(motion, contacts, **kw):
        got = real(motion, contacts, **kw)
        f = got.frames.copy()
        f[contacts.planted.any(axis=1), twist] += 40.0  # far out of the knee's range
        return got.with_frames(f)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(F, "pin_feet", twisting)
        res = carry.lock_where_clean(m, 1e12, bounds=(lo, hi, angle))
    assert res.locked == 0
    assert "left the training range" in res.line or res.line.startswith("foot locking: not")


def test_a_lock_whose_every_pin_pops_pins_nothing_and_says_so(monkeypatch):
    from test_footlock import _walkish  # noqa: E402  (tests/synthesis on the path)

    m = _walkish(T=120, fps=60.0)
    calls = []

    def popping(motion):  # clean before, popping everywhere once anything is pinned
        calls.append(1)
        return np.zeros(motion.n_frames) if len(calls) == 1 else np.full(motion.n_frames, 9.0)

    monkeypatch.setattr(carry, "_accel", popping)
    out = carry.lock_where_clean(m, 1.0)
    assert out.locked == 0
    assert out.motion is m
    assert out.line.startswith("foot locking: not done")


def test_motions_it_cannot_carry_come_back_as_they_are():
    m = make_motion(legs_skeleton(), T=30, fps=30.0, root_speed=3.0)
    assert carry.carry_by_feet(m[:2]).frames.tolist() == m[:2].frames.tolist()
    from cyclecoord.motion import Motion

    bare = Motion(m.frames, m.channels, fps=m.fps)  # no skeleton
    assert carry.carry_by_feet(bare) is bare


def test_smoothing_the_carried_steps_is_a_gaussian_of_smooth_seconds():
    from scipy.ndimage import gaussian_filter1d

    from test_footlock import _walkish  # noqa: E402

    m = _walkish(T=120, fps=60.0)
    cols = [m.channels.index(("root", d)) for d in ("tx", "tz")]
    raw = np.diff(carry.carry_by_feet(m).frames[:, cols], axis=0)
    got = np.diff(carry.carry_by_feet(m, smooth=0.05).frames[:, cols], axis=0)
    np.testing.assert_allclose(got, gaussian_filter1d(raw, 0.05 * 60, axis=0, mode="nearest"),
                               atol=1e-9)


def test_the_floor_lift_at_a_low_frame_rate_by_hand():
    """At 10 fps the lift's half-width is one frame (0.1 s): one frame 0.5 under the floor
    lifts the root by the running maximum over 3 frames, smoothed by a Gaussian of half
    a frame, and at least 0.5 on that frame."""
    from scipy.ndimage import gaussian_filter1d, maximum_filter1d

    m = make_motion(legs_skeleton(), T=20, fps=10.0)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    ty = m.channels.index(("root", "ty"))
    frames = m.frames.copy()
    frames[10, ty] -= 0.5  # one frame sinks
    m = m.with_frames(frames)
    floor = float(carry._lowest_points(m, feet)[0])
    depth = np.maximum(floor - carry._lowest_points(m, feet), 0.0)
    want = np.maximum(gaussian_filter1d(maximum_filter1d(depth, 3), 0.5, mode="nearest"), depth)
    out = carry.carry_by_feet(m, feet, floor=floor)
    np.testing.assert_allclose(out.frames[:, ty] - m.frames[:, ty], want, atol=1e-9)


def test_a_lock_without_feet_it_can_find_says_so_and_pins_nothing():
    m = make_motion(legs_skeleton(), T=30, fps=30.0)
    out = carry.lock_where_clean(m, 1e12, ("nofoot",))
    assert out.locked == 0 and out.motion is m
    assert out.line.startswith("foot locking: not done (")


def test_a_pop_exactly_an_ease_and_two_frames_before_a_contact_takes_its_first_frame(
    monkeypatch,
):
    from test_footlock import _walkish  # noqa: E402

    m = _walkish(T=120, fps=60.0)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    planted = carry.support(m, feet).planted
    from cyclecoord.quality.contacts import contact_runs

    pad = int(round(0.1 * 60)) + 2
    a, b = next((a, b) for a, b in contact_runs(planted[:, 1]) if a >= pad + 1)
    pins_pop_at(monkeypatch, a - pad)
    out = carry.lock_where_clean(m, 1.0, feet)
    assert (a, a + 1) in out.skipped


def test_channel_bounds_default_margin_and_the_range_edges():
    m = make_motion(legs_skeleton(), T=10, fps=30.0, root_speed=5.0)
    lo, hi, angle = carry.channel_bounds([m])
    other = [i for i in range(len(m.channels)) if i not in m.root_channels()]
    np.testing.assert_allclose(lo[other], m.frames[:, other].min(axis=0) - carry.RANGE_MARGIN)
    assert carry.RANGE_MARGIN == 5.0
    edge = np.array([hi, lo])  # exactly on the bounds: inside
    edge[~np.isfinite(edge)] = 0.0
    assert not carry._outside(edge, (lo, hi, angle)).any()
    assert carry._outside(edge + 1e-6, (lo, hi, angle))[0].any()
    assert not carry._outside(edge, (lo, hi)).any()  # without the angles: plain ranges


def test_accel_is_the_largest_root_relative_joint_acceleration_by_hand():
    """One thigh swinging with constant angular acceleration while the root glides:
    the knee's acceleration, by hand from its positions, is the largest."""
    m = make_motion(legs_skeleton(), T=9, fps=30.0, root_speed=4.0)
    frames = m.frames.copy()
    t = np.arange(9) / 30.0
    frames[:, m.channels.index(("lfemur", "rx"))] = 200.0 * t**2
    m = m.with_frames(frames)
    pos = m.positions()
    rel = {n: pos[n] - pos["root"] for n in pos.names}
    acc = np.zeros(7)
    for n, p in rel.items():
        a2 = (p[2:] - 2 * p[1:-1] + p[:-2]) * 30.0**2
        acc = np.maximum(acc, np.sqrt((a2**2).sum(axis=1)))
    got = carry._accel(m)
    np.testing.assert_allclose(got[1:-1], acc)
    assert got[0] == got[1] and got[-1] == got[-2]


def test_support_shares_fall_off_with_height_over_the_lowest_point_by_hand():
    """Standing still, the right foot raised a little (its thigh turned 2 degrees): each
    point's share of carrying is exp(-(its height - the lowest) / leg length / LOWNESS),
    normalised over the points (every point grounded, none moving)."""
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    m = make_motion(legs_skeleton(), T=12, fps=30.0)
    frames = m.frames.copy()
    frames[:, m.channels.index(("rfemur", "rx"))] = -2.0
    m = m.with_frames(frames)
    s = carry.support(m, feet)
    y = np.stack([m.positions()[f][:, 1] for f in feet], axis=1)
    w = np.exp(-(y - y.min(axis=1, keepdims=True)) / s.contacts.leg_length / carry.LOWNESS)
    np.testing.assert_allclose(s.carry[5], w[5] / w[5].sum(), rtol=1e-9)
    assert 0.0 < s.carry[5, 3] < s.carry[5, 1]  # the raised toes carry less, not nothing


def test_tidy_closes_short_gaps_then_drops_short_stretches():
    x = np.zeros((20, 1), dtype=bool)
    x[2:6, 0] = x[7:10, 0] = x[11:13, 0] = True  # gaps of 1 and 1 frame
    x[16:17, 0] = True  # a lone frame
    got = carry._tidy(x, 2.0)[:, 0]
    want = np.zeros(20, dtype=bool)
    want[2:13] = True
    np.testing.assert_array_equal(got, want)


def test_support_and_lock_outcomes_are_frozen_records():
    import dataclasses

    m = make_motion(legs_skeleton(), T=6, fps=30.0)
    s = carry.support(m, ("lfoot", "rfoot"))
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.carry = None
    out = carry.lock_where_clean(m, 1e12, ("nofoot",))
    with pytest.raises(dataclasses.FrozenInstanceError):
        out.locked = 3


def test_limit_words_name_one_limit_only_when_they_are_all_but_equal():
    assert carry._limit_words(np.array([1000.0, 1000.4])) == "1e+03"
    assert carry._limit_words(np.array([1000.0, 1500.0])) == "1e+03-1.5e+03"


def test_the_feet_share_of_each_step_is_clipped_to_one():
    from test_footlock import _walkish  # noqa: E402

    m = _walkish(T=60, fps=60.0)
    one = carry.carry_by_feet(m, share=np.ones(59))
    two = carry.carry_by_feet(m, share=np.full(59, 2.0))
    np.testing.assert_array_equal(one.frames, two.frames)
    half = carry.carry_by_feet(m, share=np.full(59, 0.5))
    none = carry.carry_by_feet(m, share=np.zeros(59))
    cols = [m.channels.index(("root", d)) for d in ("tx", "tz")]
    np.testing.assert_allclose(none.frames[:, cols], m.frames[:, cols])  # its own steps
    want = 0.5 * np.diff(one.frames[:, cols], axis=0) + 0.5 * np.diff(m.frames[:, cols], axis=0)
    np.testing.assert_allclose(np.diff(half.frames[:, cols], axis=0), want, atol=1e-9)


def test_a_lock_with_no_contact_long_enough_pins_nothing():
    from test_footlock import _walkish  # noqa: E402

    m = _walkish(T=30, fps=60.0)  # half a second
    out = carry.lock_where_clean(m, 1e12, min_duration=1.0)
    assert out.locked == 0 and out.motion is m
    assert out.line == "foot locking: no contact long enough to pin"


def _hold_popping_at(monkeypatch, frame: int):
    """Legs swaying six times a second under a body held from frame 20 of 90, locked with
    every pinning after the first making a pop at ``frame``: the lock's outcome, the lfoot
    depth per frame, the legs' sway (its range unlocked) and the first settled frame."""
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    m = swaying_legs(0.5, 6.0)
    hold = np.zeros(90, dtype=bool)
    hold[20:] = True
    pins_pop_at(monkeypatch, frame)
    out = carry.lock_where_clean(m, 1.0, feet, hold=hold)
    z = out.motion.positions()["lfoot"][:, 2]
    sway = np.ptp(m.positions()["lfoot"][:, 2])
    return out, z, sway, 20 + int(round(carry.STAND_AFTER * 30))


def test_a_hold_whose_pin_pops_early_keeps_its_settled_part(monkeypatch):
    """On the hold every foot point in the band is pinned; a pop two frames into the hold
    takes its stretch back to the part after STAND_AFTER seconds, and the feet stand
    there."""
    out, z, sway, settled = _hold_popping_at(monkeypatch, 22)
    assert np.ptp(z[settled + 4 :]) < 0.02 * sway
    assert out.locked >= 2
    # the frames between the pop and the settled part are not pinned (the legs sway)
    assert np.ptp(z[26:31]) > 0.5 * sway


def test_a_hold_whose_settled_pin_pops_keeps_what_is_clear_of_the_pop(monkeypatch):
    """The same hold with a pop inside its settled part (at frame 60, on every pinning):
    the settled stretch is cut around the pop (an ease and two frames each way), not
    dropped, and the feet stand before and after it. (Dropped, one IDLE in five of the
    Bandai and subject 35 scripts let its feet glide 0.2-0.4 m/s.)"""
    out, z, sway, settled = _hold_popping_at(monkeypatch, 60)
    pad = int(round(0.1 * 30)) + 2
    # pinned before the pop (from the settled part's ease on) and after it
    assert np.ptp(z[settled + 4 : 60 - pad - 4]) < 0.02 * sway
    assert np.ptp(z[60 + pad + 4 :]) < 0.02 * sway
    assert out.locked >= 4  # two pieces a foot
    assert "not at frames" in out.line


def test_a_pop_the_motion_had_before_pinning_does_not_unpin(monkeypatch):
    """Past the limit, but no more than 5 % over what the frame had before pinning: the pop
    is the motion's own, and every pin stays; 6 % over: the pin around it comes off."""
    from test_footlock import _walkish  # noqa: E402

    m = _walkish(T=120, fps=60.0)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    k = 60

    def run(ratio):
        calls = []

        def fake(motion):
            calls.append(1)
            out = np.zeros(motion.n_frames)
            out[k] = 10.0 if len(calls) == 1 else 10.0 * ratio
            return out

        monkeypatch.setattr(carry, "_accel", fake)
        return carry.lock_where_clean(m, 1.0, feet)

    kept = run(1.04)
    assert not kept.skipped and kept.locked > 0
    assert carry.support(m, feet).planted[k - 8 : k + 9].any()  # a pin near the pop ...
    assert run(1.06).skipped  # ... comes off at 6 % over


def test_in_flight_the_root_keeps_its_own_step():
    """Legs held still against a root that glides at 2 units/s: on the ground the feet
    carry (a held pose: the root stays); lifted 1 unit (11 % of the leg, past the 5 %
    contact band) for 20 frames, nothing carries and the root keeps its own step there
    (the share falls off over LOWNESS leg lengths above the band: exp(-6) here)."""
    m = make_motion(legs_skeleton(), T=60, fps=30.0, root_speed=2.0)
    ty, tz = (m.channels.index(("root", d)) for d in ("ty", "tz"))
    frames = m.frames.copy()
    frames[20:40, ty] += 1.0
    m = m.with_frames(frames)
    out = carry.carry_by_feet(m, ("lfoot", "ltoes", "rfoot", "rtoes"))
    steps = np.diff(out.frames[:, tz])
    own = 2.0 / 30.0
    np.testing.assert_allclose(steps[24:35], own, rtol=1e-2)  # flying: its own step
    np.testing.assert_allclose(steps[5:15], 0.0, atol=1e-6 * own)  # standing: held


def test_pops_that_move_with_every_trim_unpin_their_contact_whole_not_every_contact(
    monkeypatch,
):
    """A contact whose every trimmed piece pops again at its new first frame (an IDLE's
    stand on the Bandai benchmark script popped at 222, 226, 228, ... 242) is unpinned
    whole after the rounds of trimming, and the other contacts stay pinned: before, the
    lock gave up and pinned nothing anywhere."""
    from test_footlock import _walkish  # noqa: E402

    import cyclecoord.synthesis.footlock as F
    from cyclecoord.quality.contacts import contact_runs

    m = _walkish(T=120, fps=60.0)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    planted = carry.support(m, feet).planted
    runs = [(i, a, b) for i in range(4) for a, b in contact_runs(planted[:, i]) if b - a > 12]
    i0, a0, b0 = max(runs, key=lambda r: r[2] - r[1])
    seen = {}
    real = F.pin_feet

    def recording(motion, contacts, **kw):
        seen["planted"] = contacts.planted.copy()
        return real(motion, contacts, **kw)

    def popping(motion):
        out = np.zeros(motion.n_frames)
        p = seen.get("planted")
        if p is not None and p[a0:b0, i0].any():  # pops where that contact now starts
            out[a0 + int(np.flatnonzero(p[a0:b0, i0])[0])] = 10.0
        return out

    monkeypatch.setattr(F, "pin_feet", recording)
    monkeypatch.setattr(carry, "_accel", popping)
    out = carry.lock_where_clean(m, 1.0, feet, min_duration=0.05, blend=0.0)
    assert b0 - a0 > 6 * 3 + 3  # longer than six trims of 3 frames (pad 2) can clear
    assert not out.line.startswith("foot locking: not done"), out.line
    assert out.locked > 0 and not seen["planted"][a0:b0, i0].any()
    assert seen["planted"].any()
