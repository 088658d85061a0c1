"""Foot locking: sliding feet are pinned, only the legs move, and by little."""

from dataclasses import replace

import numpy as np
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.motion import Motion
from cyclecoord.quality.contacts import contact_runs, foot_contacts, foot_skating
from cyclecoord.synthesis.carry import carry_by_feet
from cyclecoord.synthesis.footlock import lock_feet


from _legs import legs_skeleton, make_motion, pins_pop_at, swaying_legs  # tests/ is on the path (rootdir conftest)


def _walkish(T=120, fps=60.0):
    """Legs swinging so each foot in turn slides slowly on the floor while the other swings."""
    skel = legs_skeleton()
    m = make_motion(skel, T=T, fps=fps, root_speed=2.0)
    frames = m.frames.copy()
    col = {c: i for i, c in enumerate(m.channels)}
    t = np.arange(T) / fps
    phase = 2 * np.pi * t / 1.0
    frames[:, col[("lfemur", "rx")]] = -25 * np.clip(np.sin(phase), 0, None)
    frames[:, col[("rfemur", "rx")]] = -25 * np.clip(-np.sin(phase), 0, None)
    return m.with_frames(frames)


def test_lock_removes_skating_and_touches_only_legs():
    m = _walkish()
    c = foot_contacts(m)
    assert c.planted.any()
    before = foot_skating(m, c)
    assert before.skating_frames > 0  # the root slides at 0.25 leg lengths/s
    r = lock_feet(m, c)
    assert r.after.skating_frames == 0
    assert r.max_error < 1e-3 * c.leg_length
    root_cols = [i for i, (j, _) in enumerate(m.channels) if j == "root"]
    assert np.array_equal(r.motion.frames[:, root_cols], m.frames[:, root_cols])
    changed = {k for k, v in r.joint_change.items() if v > 0}
    assert changed <= {"lfemur", "ltibia", "lfoot", "rfemur", "rtibia", "rfoot"}
    assert r.joint_change["ltoes"] == 0 and r.joint_change["root"] == 0
    # locked feet are pinned: horizontal positions constant over each contact
    pos = r.motion.positions()["ltoes"]
    runs = np.flatnonzero(c.planted[:, 1])
    assert np.ptp(pos[runs[:5]][:, [0, 2]], axis=0).max() < 1e-3


def test_lock_errors():
    m = _walkish()
    bare = Motion(m.frames, m.channels, fps=m.fps)
    with pytest.raises(ParameterError, match="skeleton"):
        lock_feet(bare)
    with pytest.raises(ParameterError, match="blend"):
        lock_feet(m, blend=-1)
    with pytest.raises(ParameterError, match="cover"):
        lock_feet(m[:50], foot_contacts(m))


LEGS = ("lfemur", "ltibia", "lfoot", "rfemur", "rtibia", "rfoot")


def test_lock_69_01_window(walk_69_01):
    """The raw capture: stance runs are long, heel and toe locks nearly agree."""
    m = walk_69_01[200:450]
    r = lock_feet(m)
    assert r.before.skating_frames > 100
    assert r.after.skating_frames == 0
    assert all(v == 0 for k, v in r.joint_change.items() if k not in LEGS)
    assert r.mean_joint_change < 1.0


def _leg_columns(motion):
    return [i for i, (j, _) in enumerate(motion.channels) if j in LEGS]


@pytest.mark.slow
@pytest.mark.parametrize("frames", [(200, 450), None], ids=["frames200-450", "whole"])
def test_lock_69_01_extracted_cycle(walk_69_01, frames):
    """The issue's target: the extracted cycle skates; locked, no frame does (on its own
    contacts nor on contacts found afresh on the result), every joint outside the legs
    keeps its angles and the legs move a few degrees on average."""
    from cyclecoord.periodic.pipeline import extract

    options = {"frames": frames, "max_scale": 50} if frames else {}
    cycle = extract(walk_69_01, **options).cycle
    r = lock_feet(cycle, cyclic=True)
    assert r.before.skating_frames > 20  # 35 (200:450) and 51 (whole) of 140
    assert r.after.skating_frames == 0
    assert r.after_redetected.skating_frames == 0
    assert all(v == 0 for k, v in r.joint_change.items() if k not in LEGS)
    assert r.mean_joint_change < 1.0  # over all 31 joints: 0.3-0.4 degrees
    # per leg joint 0.7-4.3 degrees on average over the frames (lfoot most)
    assert max(r.joint_change[k] for k in LEGS) < 6.0
    # no leg flips between two inverse-kinematics solutions from one frame to the next
    # and no foot slapped flat in one frame (the earlier solver moved a leg channel up to
    # 93 degrees in one frame); captured steps reach 4.3 degrees, locked ones 4.8-6.5
    cols = _leg_columns(cycle)
    assert np.abs(np.diff(r.motion.frames[:, cols], axis=0)).max() < 10.0


def test_lock_passes_checked():
    m = _walkish()
    with pytest.raises(ParameterError, match="passes"):
        lock_feet(m, passes=0)
    one = lock_feet(m, passes=1)
    assert one.after.skating_frames == 0


def _largest_leg_step(motion, cyclic=False):
    """Largest frame-to-frame change of a leg rotation channel (degrees, wrapped), across
    the seam too when ``cyclic``."""
    x = motion.frames[:, _leg_columns(motion)]
    d = np.diff(np.concatenate([x, x[:1]]) if cyclic else x, axis=0)
    return float(np.abs((d + 180.0) % 360.0 - 180.0).max())


def test_lock_toe_first_landing_no_pop(cmu_dir):
    """Jumping jacks land on the balls of the feet: the toe's contact starts about ten frames
    before the heel's.  The toe used to be let go of (no horizontal target, pulled up to the
    flat foot's height) where the heel's ease began inside its own ease, then snapped to its
    lock on the held frame: rfoot.rx stepped 23 degrees in one frame on this stretch of
    the capture (rtibia.rx 17.7 on the cycle) against captured steps of at most 4."""
    import cyclecoord as cc

    take = cc.load(cmu_dir / "13" / "13_29.amc")[0:200]
    r = lock_feet(take)
    assert r.after.skating_frames == 0 and r.after_redetected.skating_frames == 0
    captured = _largest_leg_step(take)  # 4.0
    assert _largest_leg_step(r.motion) < 2.5 * captured  # 23.3 before the fix, 8.0 after


@pytest.mark.slow
def test_lock_jumping_jack_cycle_no_pop(cmu_dir):
    """The jumping-jack cycle: the locked legs step at most 1.5 times the cycle's own
    largest leg step (3.45 times before the toe-first fix, 1.39 after), nothing skates."""
    import cyclecoord as cc

    cycle = cc.extract(cc.load(cmu_dir / "13" / "13_29.amc"), frames=(0, 456)).cycle
    r = lock_feet(cycle, cyclic=True)
    assert r.after.skating_frames == 0 and r.after_redetected.skating_frames == 0
    assert r.mean_joint_change < 1.0
    own = _largest_leg_step(cycle, cyclic=True)  # 5.1
    assert _largest_leg_step(r.motion, cyclic=True) < 1.5 * own  # 17.7 before, 7.1 after


def test_targets_close_contacts_hand_over_smoothly():
    """Two contacts 6 frames apart (a toe re-touching after toe-off): the ease out of the
    first runs into the ease into the second.  The target used to jump where the nearer
    contact changes (1.15 of the 1.63 between the locks in one frame; on the 69_01
    200:450 cycle a 6.3 degree rfoot.rx step, 5.7 after); now it moves from one lock to
    the other over the frames between them (at most 0.41 a frame)."""
    from cyclecoord.synthesis.footlock import _targets

    T = 60
    x = np.linspace(0.0, 6.0, T)  # the point slides 0.1 per frame
    points = np.stack([x, np.zeros(T), np.zeros(T)], axis=1)
    planted = np.zeros(T, bool)
    planted[10:20] = planted[26:36] = True
    tgt, ease, label, _ = _targets(points, planted, up=1, nb=12, cyclic=False)
    assert (label[10:36] >= 0).all() and ease[20:26].min() > 0.5
    np.testing.assert_allclose(tgt[9:21, 0], points[10:20, 0].mean())  # held at the locks
    np.testing.assert_allclose(tgt[25:37, 0], points[26:36, 0].mean())
    # from one lock (1.47) to the next (3.10) over 5 frames; the jump was 1.15
    assert np.abs(np.diff(tgt[:, 0])).max() < 0.6


def test_carry_by_feet_holds_the_body_on_still_feet_but_not_on_landing_ones():
    """Legs that never move against the root, sliding forward at 8 units/s: with the feet
    at one height they are planted and carry the body, which then stays put; bobbing
    0.2 units at 4 Hz (inside the contact band, up to 0.6 leg lengths/s up and down) they
    carry it only as far as their vertical speed is under VERTICAL_SPEED, by hand: each
    step keeps its own travel times one minus the lowest point's grounded weight (the
    heights smoothed over VERTICAL_SMOOTH first)."""
    from scipy.ndimage import gaussian_filter1d

    from cyclecoord.synthesis.carry import (
        CONTACT_BAND,
        VERTICAL_SMOOTH,
        VERTICAL_SPEED,
        carry_by_feet,
    )

    skel = legs_skeleton()
    tz = skel.channels.index(("root", "tz"))
    still = make_motion(skel, T=120, fps=60.0, root_speed=8.0)
    out = carry_by_feet(still)
    assert np.ptp(out.frames[:, tz]) < 1e-9 * 8.0  # planted feet: the root does not glide
    bob = make_motion(skel, T=120, fps=60.0, root_speed=8.0, bob=(0.2, 4.0))
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    c = foot_contacts(bob, feet, speed=None, height=CONTACT_BAND)
    assert np.all(c.height.min(axis=1) <= CONTACT_BAND * c.leg_length)  # always in the band
    ty = bob.frames[:, skel.channels.index(("root", "ty"))]
    ty = gaussian_filter1d(ty, VERTICAL_SMOOTH * bob.fps, mode="nearest")  # 2 frames
    vy = np.abs(np.gradient(ty)) * bob.fps / c.leg_length
    g = np.exp(-np.maximum(vy - VERTICAL_SPEED, 0.0) / VERTICAL_SPEED)
    want = np.r_[0.0, np.cumsum(8.0 / 60.0 * (1.0 - 0.5 * (g[1:] + g[:-1])))]
    got = carry_by_feet(bob, feet).frames[:, tz]
    np.testing.assert_allclose(got, want, atol=1e-6)
    assert 0.1 * 8.0 * 119 / 60 < got[-1] < 0.9 * 8.0 * 119 / 60  # partly carried (25 %)


def _right_leg_up(T, fps, speed):
    """Legs sliding forward at ``speed``, the right leg held up and forward; and a table
    of the left thigh angle (degrees) giving each z of the straight left foot against
    the root, by forward kinematics: ``(motion, frames, columns, angle_of_z)``."""
    m = make_motion(legs_skeleton(), T=T, fps=fps, root_speed=speed)
    col = {c: i for i, c in enumerate(m.channels)}
    frames = m.frames.copy()
    frames[:, col[("rfemur", "rx")]] = -40.0
    frames[:, col[("rtibia", "rx")]] = 60.0
    grid = np.linspace(-25.0, 25.0, 201)
    probe = np.repeat(frames[:1], grid.size, axis=0)
    probe[:, col[("lfemur", "rx")]] = grid
    probe[:, col[("root", "tz")]] = 0.0
    z = m.with_frames(probe).positions()["lfoot"][:, 2]
    order = np.argsort(z)
    return m, frames, col, lambda want: np.interp(want, z[order], grid[order])


def _stance_then_swing(fps=30.0, speed=8.0, T=60, stance=(20, 24), forward=False):
    """Right leg held up and forward; the left foot on the floor for ``stance`` frames,
    still in the world (its thigh swinging back at the root's speed) or, ``forward``,
    swinging forward against the root (a foot landing); lifted (knee bent) elsewhere."""
    m, frames, col, angle = _right_leg_up(T, fps, speed)
    frames[:, col[("ltibia", "rx")]] = 60.0
    a, b = stance
    t = np.arange(a, b)
    root_z = frames[t, col[("root", "tz")]]
    mid = root_z.mean()
    want = -(root_z - mid) if not forward else 3.0 * (root_z - mid)
    frames[t, col[("lfemur", "rx")]] = angle(want)
    frames[t, col[("ltibia", "rx")]] = 0.0
    return m.with_frames(frames)


def _sliding_foot(slide, T=45, fps=30.0, speed=2.0, step=1.0):
    """Right leg held up and forward; the left foot always on the floor: still in the
    world, except over the frames ``slide = (a, b)`` where it goes forward by ``step``
    units over the ground (its thigh turning against the root's travel)."""
    m, frames, col, angle = _right_leg_up(T, fps, speed)
    a, b = slide
    world = np.interp(np.arange(T), [a, b], [0.0, step])  # the foot's ground position
    root_z = frames[:, col[("root", "tz")]]
    frames[:, col[("lfemur", "rx")]] = angle(world - root_z + 0.5 * root_z[-1])
    return m.with_frames(frames)


def test_support_leaves_out_a_foot_that_goes_with_the_root_faster_than_agreement():
    """A foot on the floor still in the world bears weight and carries the body; one that
    goes over the ground faster than AGREEMENT of the root's speed for a few frames (a foot
    landing, swinging forward) does not, and the root keeps its own step there; one that
    does so for longer than GLIDE_SECONDS while it is the grounded lowest point (a stride
    shorter than the root's step) carries."""
    from cyclecoord.synthesis.carry import GLIDE_SECONDS, support

    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    tz = legs_skeleton().channels.index(("root", "tz"))
    landing = _sliding_foot((20, 23))  # 1 unit in 0.1 s: 10 units/s, 5x the root's
    s = support(landing, feet)
    on = s.carry[:, :2].sum(axis=1)
    assert np.all(on[5:18] > 0.99) and np.all(on[25:40] > 0.99)  # standing: carries
    assert np.all(on[21:23] < 1e-3)  # landing (central differences inside it): does not
    assert not s.planted[20:23, :2].any()
    out = carry_by_feet(landing, feet)
    own = np.diff(landing.frames[:, tz])
    np.testing.assert_allclose(np.diff(out.frames[:, tz])[21], own[21], rtol=1e-3)
    still = out.positions()["ltoes"][:, 2]  # the lowest point carries
    assert np.ptp(still[5:18]) < 1e-3 and np.ptp(still[25:40]) < 1e-3
    # the same speed over the ground for 0.5 s: a short stride, carried
    n = int(round(0.5 * 30))
    assert n > GLIDE_SECONDS * 30
    short = _sliding_foot((15, 15 + n), step=2.5 * 2.0 * n / 30)
    assert np.all(support(short, feet).carry[17 : 13 + n, :2].sum(axis=1) > 0.9)
    # ... and for 0.23 s, over GLIDE_SECONDS but under twice it
    n = 7
    assert GLIDE_SECONDS * 30 < n - 1 < 2 * GLIDE_SECONDS * 30
    short = _sliding_foot((15, 15 + n), step=2.5 * 2.0 * n / 30)
    assert np.all(support(short, feet).carry[17 : 13 + n, :2].sum(axis=1) > 0.9)


def test_lock_where_clean_pins_a_stance_of_a_tenth_of_a_second():
    """A run's stance at 30 fps is a handful of frames: the 3-5 weight-bearing frames of a
    foot that slides at 0.3x the root's speed (under AGREEMENT) are pinned by default;
    with the earlier 0.2 s minimum they were not."""
    from cyclecoord.synthesis.carry import lock_where_clean, support

    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    m = _stance_then_swing(stance=(20, 27))
    col = {c: i for i, c in enumerate(m.channels)}
    frames = m.frames.copy()  # let the standing foot slide slowly: 0.3x the root's speed
    frames[20:27, col[("lfemur", "rx")]] *= 0.7
    m = m.with_frames(frames)
    planted = support(m, feet).planted[:, :2].any(axis=1)
    assert 3 <= planted.sum() < 6  # its first and last two frames land and lift
    on = np.flatnonzero(planted)
    slid = np.ptp(m.positions()["ltoes"][on, 2])
    assert slid > 0.1
    out = lock_where_clean(m, 1e12, feet)
    assert out.locked >= 1
    assert np.ptp(out.motion.positions()["ltoes"][on, 2]) < 0.05 * slid
    old = lock_where_clean(m, 1e12, feet, min_duration=0.2).motion
    assert np.ptp(old.positions()["ltoes"][on, 2]) == pytest.approx(slid)


def test_lock_where_clean_stands_the_feet_of_an_asked_hold():
    """A body standing (root held) whose legs sway three times a second: each foot slides
    0.3 leg lengths/s at most, over AGREEMENT of the still body's pace, for under
    GLIDE_SECONDS at a time, so it bears no weight; on frames of an asked hold every
    point in the contact band is pinned too, and the feet stand."""
    from cyclecoord.synthesis.carry import lock_where_clean, support

    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    m = swaying_legs(1.0, 3.0)
    z = m.positions()["lfoot"][:, 2]
    leg = support(m, feet).contacts.leg_length
    speed = np.abs(np.gradient(z)) * 30 / leg
    assert 0.25 < speed.max() < 0.5  # slow, but not still
    fast = np.flatnonzero(speed > 0.25)
    assert not support(m, feet).planted[fast][:, :2].any()  # bears no weight there
    free = lock_where_clean(m, 1e12, feet).motion.positions()["lfoot"][:, 2]
    np.testing.assert_allclose(free[fast], z[fast], atol=1e-6)
    hold = np.zeros(90, bool)
    hold[20:] = True
    held = lock_where_clean(m, 1e12, feet, hold=hold)
    assert held.locked >= 2
    for f in ("lfoot", "rfoot"):
        assert np.ptp(held.motion.positions()[f][30:60, 2]) < 0.02 * np.ptp(z[30:60])


def test_lock_where_clean_keeps_what_is_clear_of_a_pop(monkeypatch):
    """A pin that pops at one frame is taken off around that frame (the ease and two
    frames either side), not over its whole contact: the stance's two ends stay pinned."""
    from cyclecoord.synthesis import carry

    m = _walkish(T=120, fps=60.0)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    planted = carry.support(m, feet).planted[:, 1]  # ltoes
    runs = [(a, b) for a, b in contact_runs(planted) if b - a >= 24]
    assert runs, "a long stance of the left toes"
    a, b = runs[0]
    k = (a + b) // 2
    real = carry._accel
    pins_pop_at(monkeypatch, k)  # the unpinned motion is clean; every pinned one pops at k
    out = carry.lock_where_clean(m, 1.0, feet)
    monkeypatch.setattr(carry, "_accel", real)
    pad = int(round(0.1 * 60)) + 2
    assert any(s <= k - pad and e >= k + pad for s, e in out.skipped)
    toes = out.motion.positions()["ltoes"][:, [0, 2]]
    for lo, hi in ((a + 1, k - pad - 1), (k + pad + 2, b - 1)):
        assert hi - lo >= 3
        assert np.ptp(toes[lo:hi], axis=0).max() < 1e-3  # pinned
    assert np.ptp(toes[k - 2 : k + 3], axis=0).max() > 1e-3  # free around the pop


def test_pin_feet_reuse_keeps_the_frames_asked_the_same_and_reads_as_fresh(monkeypatch):
    """``pin_feet(..., reuse=)`` pinning one motion twice on contacts that differ in one
    stretch solves only the frames whose targets changed; both results read as pins
    without ``reuse`` (each frame is solved on its own)."""
    import cyclecoord.synthesis.footlock as fl

    m = _walkish()
    contacts = foot_contacts(m, feet=("lfoot", "ltoes", "rfoot", "rtoes"))
    assert contacts.planted.any()
    solved = []
    real = fl._solve
    monkeypatch.setattr(fl, "_solve", lambda ik, rows, *a, **k: solved.append(rows.size)
                        or real(ik, rows, *a, **k))
    kept: dict = {}
    first = fl.pin_feet(m, contacts, reuse=kept)
    planted = contacts.planted.copy()
    runs = contact_runs(planted[:, 0])
    a, b = runs[len(runs) // 2]
    planted[a:b, 0] = False  # one stretch of the left foot let go
    fewer = fl.pin_feet(m, replace(contacts, planted=planted), reuse=kept)
    monkeypatch.setattr(fl, "_solve", real)
    np.testing.assert_array_equal(first.frames, fl.pin_feet(m, contacts).frames)
    np.testing.assert_array_equal(
        fewer.frames, fl.pin_feet(m, replace(contacts, planted=planted)).frames)
    assert len(solved) == 3 and 0 < solved[2] < solved[0] / 2  # the left leg, near a-b
    other = m.with_frames(m.frames + 0.0)  # another motion: nothing of the last kept
    fl.pin_feet(other, contacts, reuse=kept)
    assert kept["motion"] is other


def test_pinned_legs_keep_their_angles_within_the_bounds_given():
    """Pinning the sliding feet bends the knees; with bounds holding each knee within a
    quarter degree of straight (and every other channel free), the solve keeps them there and
    reaches the locks with the hips and ankles instead."""
    from cyclecoord.synthesis.carry import channel_bounds
    from cyclecoord.synthesis.footlock import pin_feet

    m = _walkish()
    c = foot_contacts(m)
    free = pin_feet(m, c)
    knees = [m.channels.index((j, "rx")) for j in ("ltibia", "rtibia")]
    assert np.abs(free.frames[:, knees] - m.frames[:, knees]).max() > 1.0
    lo, hi, angle = channel_bounds([m], margin=0.0)
    lo[:], hi[:] = -np.inf, np.inf
    lo[knees], hi[knees] = -0.25, 0.25
    held = pin_feet(m, c, bounds=(lo, hi, angle))
    assert held.frames[:, knees].min() >= -0.25 - 1e-9
    assert held.frames[:, knees].max() <= 0.25 + 1e-9
    assert not np.allclose(held.frames, m.frames)  # the feet were still pinned


def test_pin_feet_asks_a_pinned_ankle_for_the_heights_given():
    """``heights``: where finite, a pinned ankle is asked for that height (a stand's foot
    kept on the floor; the toe follows the ankle and is asked for nothing); a wrong shape
    is refused."""
    from cyclecoord.synthesis.footlock import _KEPT_HEIGHT, pin_feet

    m = _walkish()
    frames = m.frames.copy()
    for knee in ("ltibia", "rtibia"):  # (a straight knee cannot lower its ankle a little)
        frames[:, m.channels.index((knee, "rx"))] = 20.0
    m = m.with_frames(frames)
    c = foot_contacts(m)
    i = c.feet.index("lfoot")
    on = c.planted[:, i]
    y = m.positions()["lfoot"][:, c.up]
    want = np.full(c.planted.shape, np.nan)
    want[on, i] = y[on] - 0.05 * c.leg_length  # a little lower than it is
    free = pin_feet(m, c).positions()["lfoot"][:, c.up]
    asked = pin_feet(m, c, heights=want).positions()["lfoot"][:, c.up]
    miss_free = np.abs(free[on] - want[on, i]).mean()
    miss_asked = np.abs(asked[on] - want[on, i]).mean()
    assert 0 < _KEPT_HEIGHT <= 1
    assert miss_asked < 0.8 * miss_free  # (asked at a weight: 0.40 -> 0.28 units here)
    np.testing.assert_allclose(  # NaN everywhere asks for nothing
        pin_feet(m, c, heights=np.full(c.planted.shape, np.nan)).frames, pin_feet(m, c).frames)
    with pytest.raises(ParameterError, match="heights has shape"):
        pin_feet(m, c, heights=np.zeros((3, 3)))
