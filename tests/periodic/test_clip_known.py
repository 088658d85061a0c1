"""periodic.clip by hand: the slowest frame of a loop, typical amplitude's gains and windows,
planted weights of feet that never move, and the capture-timed cycle's documented parts."""

import numpy as np
import pytest

import cyclecoord as cc
import cyclecoord.periodic.clip as clip_module
from cyclecoord.errors import ParameterError
from cyclecoord.periodic.clip import (
    CAPTURE_WIDTH,
    MAX_AMPLITUDE_GAIN,
    anchor_to_feet,
    capture_cycle,
    joint_columns,
    loop_cycle,
    planted_weights,
    slowest_frame,
    typical_amplitude,
)
from cyclecoord.periodic.preprocess import PreparedData, Preprocessor
from cyclecoord.periodic.root import heading, planted_ground, root_layout


def _smoothed_around(f, w):
    """Independent: cyclic step into and out of each frame, averaged over w frames centred
    as np.convolve(mode="same") centres them (offsets -(w // 2) .. (w - 1) // 2)."""
    T = len(f)
    step = [np.linalg.norm(f[(i + 1) % T] - f[i]) for i in range(T)]
    around = [step[i] + step[i - 1] for i in range(T)]
    offs = range(-(w // 2), (w - 1) // 2 + 1)
    return [sum(around[(i + o) % T] for o in offs) / w for i in range(T)]


def test_slowest_frame_by_hand():
    """Positions 0, 5, 10, 11, 12, 17, 22, 27 and back to 0: frame 3 sits between two
    steps of 1 (2 in and out), frame 0 between 5 and 27."""
    x = np.array([0, 5, 10, 11, 12, 17, 22, 27], dtype=float)[:, None]
    assert slowest_frame(x, window=1) == 3
    assert slowest_frame(x) == 3
    # a narrow dip (one small step) against a broad slow stretch: the window decides
    steps = np.array([6, 6, 0.2, 0.5, 6, 6, 2, 2, 2, 2, 2, 2, 6, 6])
    f = np.concatenate([[0.0], np.cumsum(steps)])
    f = np.column_stack([np.cos(2 * np.pi * f / f[-1]), np.sin(2 * np.pi * f / f[-1])]) * f[-1] / (2 * np.pi)
    f = f[:-1]  # the last point closes onto the first
    for w in (1, 2, 3, 4, 5, 7):
        want = int(np.argmin(_smoothed_around(f, min(w, len(f)))))
        assert slowest_frame(f, window=w) == want
    assert slowest_frame(f, window=1) == 3  # between the steps of 0.2 and 0.5
    assert slowest_frame(f, window=5) == 9  # the middle of the five frames between 2s
    assert slowest_frame(np.zeros((1, 2))) == 0


def test_joint_columns():
    prep = PreparedData(points=np.zeros((3, 2)), poses=np.zeros((3, 9)), root_columns=np.array([0, 1, 2, 3, 4, 5]))
    np.testing.assert_array_equal(joint_columns(None, prep), [6, 7, 8])
    only_root = PreparedData(points=np.zeros((3, 2)), poses=np.zeros((3, 6)), root_columns=np.arange(6))
    np.testing.assert_array_equal(joint_columns(None, only_root), np.arange(6))
    none = PreparedData(points=np.zeros((3, 2)), poses=np.zeros((3, 4)), root_columns=np.zeros(0, dtype=int))
    np.testing.assert_array_equal(joint_columns(None, none), np.arange(4))


CYC8 = np.array([0, 1, 2, 3, 4, 3, 2, 1], dtype=float)  # range 4, mean 2


def test_typical_amplitude_gains_by_hand():
    """Spike 1 (no running median): 16 phased frames ramping over 7, 5 and 2 give every
    window of 8 the ranges 7, 5 and 2; against the cycle's 4 the gains are 1.75 (kept at
    1.5), 1.25 and 0.5 (kept at 1: never narrowed); a flat cycle channel stays flat."""
    ramp = np.arange(16.0)  # 0 .. 15: every window of 8 spans 7
    poses = np.column_stack([ramp, ramp * 5 / 7, ramp * 2 / 7, ramp])
    cycle = np.column_stack([CYC8, CYC8, CYC8, np.full(8, 3.0)])
    out = typical_amplitude(cycle, np.zeros(16), poses, spike=1)
    np.testing.assert_allclose(out[:, 0], 2 + (CYC8 - 2) * MAX_AMPLITUDE_GAIN)
    np.testing.assert_allclose(out[:, 1], 2 + (CYC8 - 2) * 1.25)
    np.testing.assert_allclose(out[:, 2], CYC8)
    np.testing.assert_allclose(out[:, 3], 3.0)
    assert MAX_AMPLITUDE_GAIN == 1.5


def test_typical_amplitude_windows_start_every_eighth_of_a_period():
    """P = 16: a run of 17 frames holds windows starting at 0 only (the next would start
    at 2); the frame after the first window (a 1000) is outside every window: range 12
    over the cycle's 10, gain 1.2.  With two runs of 16 frames (ranges 11 and 13) the
    median of the two windows is 12 as well."""
    cyc = np.linspace(0.0, 10.0, 16)[:, None]  # range 10, mean 5
    run = np.concatenate([np.linspace(0.0, 12.0, 16), [1000.0]])[:, None]
    out = typical_amplitude(cyc, np.zeros(17), run, spike=1)
    np.testing.assert_allclose(out, 5 + (cyc - 5) * 1.2)
    two = np.concatenate([np.linspace(0, 11, 16), [0.0], np.linspace(0, 13, 16)])[:, None]
    ph = np.zeros(33)
    ph[16] = np.nan
    np.testing.assert_allclose(typical_amplitude(cyc, ph, two, spike=1), 5 + (cyc - 5) * 1.2)
    # P = 8, 10 frames: windows at 0, 1 and 2 (every frame: 8 // 8); ranges 7, 7, 20
    poses = np.array([0, 1, 2, 3, 4, 5, 6, 7, 7, 27], dtype=float)[:, None]
    cyc8 = (CYC8 * 7 / 4 / 1.2)[:, None]  # range 7 / 1.2: the median range 7 gives 1.2
    out = typical_amplitude(cyc8, np.zeros(10), poses, spike=1)
    m = cyc8.mean()
    np.testing.assert_allclose(out, m + (cyc8 - m) * 1.2)


def test_typical_amplitude_ignores_one_frame_glitches():
    """spike=5: a running median of 5 frames takes out a one-frame spike of 1000."""
    ramp = np.arange(16.0)
    glitch = ramp.copy()
    glitch[5] = 1000.0
    cycle = CYC8[:, None]
    a = typical_amplitude(cycle, np.zeros(16), glitch[:, None])
    b = typical_amplitude(cycle, np.zeros(16), ramp[:, None])
    np.testing.assert_allclose(a, b)
    assert np.ptp(a) == pytest.approx(4 * 1.5)


def test_typical_amplitude_needs_a_run_of_a_period_and_of_the_spike_filter():
    """Runs shorter than a period, or than spike + 1 frames, give no window: the cycle is
    returned as it is.  P = 4, spike 5: a run of 5 frames is too short for the filter, one
    of 6 is not (windows at 0, 1, 2 of the filtered 0 0 100 100 100 100: ranges 100,
    100, 0, median 100; the wrapped cycle 0 1 2 3 filters to 2 2 1 1, range 1: gain 1.5)."""
    cyc = np.array([0.0, 1.0, 2.0, 3.0])[:, None]
    poses = np.array([9, 9, 0, 0, 100, 100, 100, 100, 9, 9], dtype=float)[:, None]
    ph = np.full(10, np.nan)
    ph[2:7] = 0.0  # five frames
    assert typical_amplitude(cyc, ph, poses) is cyc
    ph[2:8] = 0.0  # six frames
    np.testing.assert_allclose(typical_amplitude(cyc, ph, poses), 1.5 + (cyc - 1.5) * 1.5)
    # a long run, but shorter than the cycle
    assert typical_amplitude(np.zeros((20, 1)), np.zeros(19), np.arange(19.0)[:, None]) is not None
    short = np.zeros((20, 1))
    assert typical_amplitude(short, np.zeros(19), np.arange(19.0)[:, None]) is short
    assert typical_amplitude(short, np.full(40, np.nan), np.arange(40.0)[:, None]) is short


# ------------------------------------------------------------------ feet


def _standing(T=60):
    from tests._legs import legs_skeleton, make_motion

    return make_motion(legs_skeleton(), T=T)


FEET = ("lfoot", "ltoes", "rfoot", "rtoes")


def test_planted_weights_of_feet_that_never_move():
    m = _standing()
    rows = np.arange(10, 50)
    phase = np.mod(np.arange(40) / 20.0, 1.0)
    feet, w = planted_weights(m, rows, phase, 7, 0.05, FEET)
    assert feet == FEET and w.shape == (7, 4)
    np.testing.assert_allclose(w, 1.0, atol=1e-9)
    found, w2 = planted_weights(m, rows, phase, 5, 0.05)  # found by name on the rig
    assert set(found) >= {"lfoot", "rfoot"} and w2.shape == (5, len(found))
    assert planted_weights(m, rows[:1], phase[:1], 7, 0.05, FEET) is None
    bare = cc.Motion(m.frames, m.channels, fps=m.fps)
    assert planted_weights(bare, rows, phase, 7, 0.05, FEET) is None


def test_anchor_without_rounds_is_the_planted_ground():
    m = _standing(30)
    f = m.frames.copy()
    f[:, m.channels.index(("root", "tz"))] = 0.1 * np.arange(30)
    clip = m.with_frames(f)
    lay = root_layout(clip)
    w = np.tile([0.5, 0.5, 0.0, 0.0], (30, 1))
    np.testing.assert_array_equal(anchor_to_feet(clip, lay, FEET, w, rounds=0), planted_ground(clip, lay, FEET, w))


# ------------------------------------------------------------------ capture_cycle


@pytest.fixture(scope="module")
def walk():
    cap = cc.datasets.example_capture()
    m = cap.motion
    f = m.frames.copy()
    ry, rx, rz = (m.channels.index(("root", d)) for d in ("ry", "rx", "rz"))
    f[:, ry] = 0.15 * np.arange(len(f))  # turning 0.15 degrees a frame (72 in all: clear of gimbal lock at 90)
    f[:, rx] = f[:, rz] = 0.0
    m = m.with_frames(f)
    prep = Preprocessor()
    return cap, m, prep.fit_transform(m), prep


def test_capture_cycle_documented_parts(walk):
    """120 frames a cycle; turning 0.15 degrees a frame, 18 degrees a cycle; the cycle in the
    prepared space is the written clip's own; cycle_start="first" keeps phase 0 first."""
    cap, m, prepared, prep = walk
    phase = np.mod(cap.phase, 1.0)
    typ, clip, turn = capture_cycle(phase, m, prepared, prep, 119.6, cycle_start="first", register_iter=0,
                                    metadata={"k": 1})
    assert typ.frames.shape == (120, m.n_channels) and clip.n_frames == 120
    np.testing.assert_allclose(typ.phases, np.arange(120) / 120)
    assert turn == pytest.approx(18.0, abs=1e-6)
    np.testing.assert_allclose(typ.frames, prep.transform(clip).poses, atol=1e-9)
    assert typ.bandwidth == CAPTURE_WIDTH and typ.bandwidth_selection is None
    assert clip.metadata == {"k": 1} and clip.start_frame == 0
    assert not typ.frames.flags.writeable and not typ.phases.flags.writeable
    lay = root_layout(m)
    h = heading(clip.frames, lay)
    np.testing.assert_allclose(np.diff(h), 0.15, atol=1e-6)
    # the heading starts at the first phased frame's
    assert h[0] == pytest.approx(heading(m.frames[:1], lay)[0], abs=1e-6)
    # in place: no ground travel, the first phased frame's ground and heading
    late = phase.copy()
    late[:10] = np.nan
    _, still, _ = capture_cycle(late, m, prepared, prep, 120.0, cycle_start="first", register_iter=0,
                                travel="in_place")
    for d in ("tx", "tz"):
        np.testing.assert_allclose(still.frames[:, lay.column(d)], m.frames[10, lay.column(d)])
    assert heading(still.frames[:1], lay)[0] == pytest.approx(1.5, abs=1e-6)  # 0.15 x frame 10
    # straight: the heading stays put
    _, straight, turn2 = capture_cycle(phase, m, prepared, prep, 120.0, cycle_start="first", register_iter=0,
                                       travel="straight")
    assert np.ptp(heading(straight.frames, lay)) < 1e-6 and turn2 == pytest.approx(18.0, abs=1e-6)


def test_capture_cycle_slowest_start_and_width(walk):
    cap, m, prepared, prep = walk
    phase = np.mod(cap.phase, 1.0)
    first, _, _ = capture_cycle(phase, m, prepared, prep, 120.0, cycle_start="first", register_iter=0,
                                amplitude="average", bandwidth=2.5)
    slow, _, _ = capture_cycle(phase, m, prepared, prep, 120.0, register_iter=0, amplitude="average",
                               bandwidth=2.5)
    assert first.bandwidth == 2.5
    joints = np.setdiff1d(np.arange(m.n_channels), prepared.root_columns)
    shift = slowest_frame(first.frames[:, joints])
    assert shift != 0
    np.testing.assert_allclose(slow.phases, np.mod((np.arange(120) + shift) / 120, 1.0))
    np.testing.assert_allclose(slow.frames[:, joints], np.roll(first.frames[:, joints], -shift, axis=0), atol=1e-6)
    # the typical amplitude widens the joints' average, never narrows it
    typical, _, _ = capture_cycle(phase, m, prepared, prep, 120.0, cycle_start="first", register_iter=0,
                                  bandwidth=2.5)
    assert np.all(np.ptp(typical.frames[:, joints], axis=0) >= np.ptp(first.frames[:, joints], axis=0) - 1e-9)
    assert np.ptp(typical.frames[:, joints], axis=0).sum() > 1.01 * np.ptp(first.frames[:, joints], axis=0).sum()


def test_capture_cycle_of_a_long_take_uses_its_middle_frames(walk, monkeypatch):
    cap, m, prepared, prep = walk
    phase = np.mod(cap.phase, 1.0)
    monkeypatch.setattr(clip_module, "MAX_CYCLE_FRAMES", 300)
    a, ca, _ = capture_cycle(phase, m, prepared, prep, 120.0, cycle_start="first", register_iter=0)
    middle = np.full_like(phase, np.nan)
    mid = len(phase) // 2
    middle[mid - 150: mid + 150] = phase[mid - 150: mid + 150]
    monkeypatch.setattr(clip_module, "MAX_CYCLE_FRAMES", 10_000)
    b, cb, _ = capture_cycle(middle, m, prepared, prep, 120.0, cycle_start="first", register_iter=0)
    np.testing.assert_allclose(a.frames, b.frames, atol=1e-9)
    np.testing.assert_allclose(ca.frames, cb.frames, atol=1e-9)


def test_capture_cycle_without_a_skeleton_integrates_the_root(walk):
    """No skeleton: the root's differenced channels are integrated from the first phased
    frame; in place, their mean change is taken out (the root returns where it started)."""
    cap, m, prepared, prep = walk
    bare = cc.Motion(m.frames, m.channels, fps=m.fps)
    bprep = Preprocessor()
    bprepared = bprep.fit_transform(bare)
    phase = np.mod(cap.phase, 1.0)
    phase[:7] = np.nan
    typ, clip, turn = capture_cycle(phase, bare, bprepared, bprep, 120.0, cycle_start="first", register_iter=0)
    assert np.isnan(turn)
    root = bprepared.root_columns
    np.testing.assert_allclose(clip.frames[0, root], m.frames[7, root], atol=1e-9)
    tz = m.channels.index(("root", "tz"))
    travel = clip.frames[-1, tz] - clip.frames[0, tz]
    assert abs(travel) > 10.0
    _, still, _ = capture_cycle(phase, bare, bprepared, bprep, 120.0, cycle_start="first", register_iter=0,
                                travel="in_place")
    np.testing.assert_allclose(still.frames[0, root], m.frames[7, root], atol=1e-9)
    assert abs(still.frames[-1, tz] - still.frames[0, tz]) < 0.05 * abs(travel)


def test_capture_cycle_automatic_width(walk):
    """bandwidth="auto": the width select_bandwidth finds on the phased frames with the
    paper's 10 neighbours by default."""
    from cyclecoord.periodic.cycle import select_bandwidth

    cap, m, prepared, prep = walk
    phase = np.mod(cap.phase, 1.0)
    typ, _, _ = capture_cycle(phase, m, prepared, prep, 120.0, bandwidth="auto", register_iter=0)
    assert typ.bandwidth_selection is not None
    assert typ.bandwidth == typ.bandwidth_selection.bandwidth != CAPTURE_WIDTH
    want = select_bandwidth(phase, prepared.poses, 120.0, k=10)
    assert typ.bandwidth == want.bandwidth
    # a short period over many frames, where the grid starts at k's width (10 / (480 sqrt(2 pi))
    # of a 20-frame period, 0.17 frames, under the half frame it starts at otherwise)
    fast = np.mod(cap.phase * 6.0, 1.0)
    typ, _, _ = capture_cycle(fast, m, prepared, prep, 20.0, bandwidth="auto", register_iter=0)
    want = select_bandwidth(fast, prepared.poses, 20.0, k=10).candidates
    assert want[0] == pytest.approx(10 / (480 * np.sqrt(2 * np.pi)) * 20.0)
    np.testing.assert_allclose(typ.bandwidth_selection.candidates, want)


# ------------------------------------------------------------------ loop_cycle


def test_loop_cycle_refuses_an_unknown_start(walk):
    cap, m, prepared, prep = walk
    with pytest.raises(ParameterError, match="cycle_start"):
        loop_cycle(None, m, prepared, prep, cycle_start="middle")


@pytest.fixture(scope="module")
def example():
    m = cc.datasets.example_capture().motion
    prep = Preprocessor()
    return m, prep.fit_transform(m), prep


def test_loop_cycle_of_one_captured_cycle_is_that_cycle(example):
    """A "typical" cycle that is frames 120..239 of the prepared capture itself, averaged
    from those rows: the clip is those frames of the capture (joints and root, whose
    differences integrate from frame 120 back to the captured track)."""
    from cyclecoord.periodic.cycle import TypicalCycle

    m, prepared, prep = example
    fr = prepared.poses[120:240]
    ph = np.arange(120) / 120
    typ = TypicalCycle(frames=fr, phases=ph, curve=fr, sample_phases=ph)
    rows = np.arange(120, 240)
    same, clip = loop_cycle(typ, m, prepared, prep, cycle_start="first", rows=rows, metadata={"a": 1})
    assert same is typ
    np.testing.assert_allclose(clip.frames, m.frames[120:240], atol=1e-9)
    assert clip.metadata == {"a": 1} and clip.start_frame == 0 and clip.source.startswith("cycle of ")
    # from the slowest pose: the joints rolled to start there, the phases with them, the
    # root still starting at the first row's
    joints = np.setdiff1d(np.arange(m.n_channels), prepared.root_columns)
    shift = slowest_frame(fr[:, joints])
    assert shift != 0
    rolled, clip2 = loop_cycle(typ, m, prepared, prep, rows=rows)
    np.testing.assert_allclose(rolled.phases, np.roll(ph, -shift))
    np.testing.assert_allclose(clip2.frames[:, joints], np.roll(m.frames[120:240], -shift, axis=0)[:, joints], atol=1e-9)
    root = prepared.root_columns
    np.testing.assert_allclose(clip2.frames[0, root], m.frames[120, root], atol=1e-9)
    # without rows: every frame's root changes, the root starting at frame 0's
    _, clip3 = loop_cycle(typ, m, prepared, prep, cycle_start="first")
    np.testing.assert_allclose(clip3.frames[0, root], m.frames[0, root], atol=1e-9)
    np.testing.assert_allclose(clip3.frames[:, joints], m.frames[120:240][:, joints], atol=1e-9)


def _scrambled(m, seed=0):
    """The same rotations written as wrapping, branch-flipping Euler numbers."""
    rng = np.random.default_rng(seed)
    f = m.frames.copy()
    for j in m.skeleton.joints[1:]:
        if len(j.rotation_order) != 3:
            continue
        cols = [m.channel_index(j.name, "r" + a.lower()) for a in j.rotation_order]
        a = f[:, cols]
        alt = np.column_stack([a[:, 0] + 180.0, 180.0 - a[:, 1], a[:, 2] + 180.0])
        a = np.where((rng.random(len(f)) < 0.5)[:, None], alt, a) + 360.0 * rng.integers(-2, 3, size=a.shape)
        f[:, cols] = a
    return m.with_frames(f)


def test_loop_cycle_writes_its_first_frame_as_the_first_row_was_written():
    """Euler numbers that flip and wrap from frame to frame: the clip's first frame takes
    the branch of the capture's first row (its exact numbers), later frames follow on."""
    from cyclecoord.periodic.cycle import TypicalCycle

    s = _scrambled(cc.datasets.example_capture().motion)
    prep = Preprocessor()
    prepared = prep.fit_transform(s)
    fr = prepared.poses[120:240]
    ph = np.arange(120) / 120
    typ = TypicalCycle(frames=fr, phases=ph, curve=fr, sample_phases=ph)
    _, clip = loop_cycle(typ, s, prepared, prep, cycle_start="first", rows=np.arange(120, 240))
    np.testing.assert_allclose(clip.frames[0], s.frames[120], atol=1e-6)
    np.testing.assert_allclose(clip.positions().positions, s[120:240].positions().positions, atol=1e-6)
    joints = np.setdiff1d(np.arange(s.n_channels), prepared.root_columns)
    assert np.abs(np.diff(clip.frames[:, joints], axis=0)).max() < 20


def test_planted_weights_follow_the_contacts_of_the_rows():
    """Rows 10..49 phased one frame per sample over one cycle, a kernel far narrower than a
    sample: each phase's weight is the contact of its own frame, found on frames 10..49
    (the left foot lifted on 20..29)."""
    from cyclecoord.quality.contacts import foot_contacts
    from tests._legs import legs_skeleton, make_motion

    m = make_motion(legs_skeleton(), T=60, lift_left=np.arange(20, 30))
    rows = np.arange(10, 50)
    feet, w = planted_weights(m, rows, (rows - 10) / 40.0, 40, 0.1 / 40, FEET)
    want = foot_contacts(m[10:50], FEET).planted.astype(float)
    assert want[:, 0].min() == 0.0 and want[:, 2].min() == 1.0  # the left foot lifts, the right does not
    np.testing.assert_allclose(w, want, atol=1e-6)


def test_loop_cycle_from_the_last_row_alone(example):
    """Rows holding only the last frame (whose root difference repeats the one before):
    that row gives the root's change and start, rather than no row at all."""
    from cyclecoord.periodic.cycle import TypicalCycle

    m, prepared, prep = example
    last = len(prepared.poses) - 1
    fr = prepared.poses[last - 3:]
    ph = np.arange(4) / 4
    typ = TypicalCycle(frames=fr, phases=ph, curve=fr, sample_phases=ph)
    _, clip = loop_cycle(typ, m, prepared, prep, cycle_start="first", rows=np.array([last]))
    root = prepared.root_columns
    np.testing.assert_allclose(clip.frames[0, root], m.frames[last, root], atol=1e-9)
    assert np.all(np.isfinite(clip.frames))


def test_typical_amplitude_leaves_a_channel_whose_range_is_exactly_the_floor():
    """A channel of the cycle whose range is exactly 1e-9 (the floor: a channel that
    still is not widened) is left as it is; one of 1.5e-9 is widened to the capture's
    range of 1.8e-9 (a gain of 1.2)."""
    from cyclecoord.periodic.clip import typical_amplitude

    cycle = np.zeros((4, 2))
    cycle[1, 0] = 1e-9
    cycle[1, 1] = 1.5e-9
    poses = np.tile(np.array([[0.0, 0.0], [1.8e-9, 1.8e-9], [0.0, 0.0], [0.0, 0.0]]), (3, 1))
    out = typical_amplitude(cycle, np.zeros(len(poses)), poses, spike=1)
    np.testing.assert_array_equal(out[:, 0], cycle[:, 0])
    assert np.ptp(out[:, 1]) == pytest.approx(1.8e-9, rel=1e-9)


def test_capture_cycle_with_no_phased_frame_is_a_clear_refusal():
    """Re-timing can leave no frame with a phase (a 50-frame half of the 143_01 jog with
    ``min_turns=0.75``): that was a ParameterError from deep inside ``phase_average``
    about array shapes; it is now a NoPeriodicMotionError saying what happened."""
    from cyclecoord.errors import NoPeriodicMotionError

    with pytest.raises(NoPeriodicMotionError, match="only 0 of the 50 frames"):
        capture_cycle(np.full(50, np.nan), None, None, None, 42.0)
