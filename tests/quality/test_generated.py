"""The measure of generated motion (quality.generated) against the independent checker.

``/work/shared/tools/motioncheck`` (its own ASF/AMC/BVH readers and forward kinematics)
prints support-foot slip, the longest freeze, knee ranges, the largest acceleration and the
root speed; ours must give the same figures on a graph output and on a captured take.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.io import load, save
from cyclecoord.quality.contacts import foot_skating
from cyclecoord.quality.generated import measure_generated

CMU = Path("/work/shared/data/cmu")
CHECKER = Path("/work/shared/tools/motioncheck/motioncheck.py")
WALKS = [CMU / "35" / f"35_{k}.amc" for k in ("07", "08", "13", "16")]

needs_data = pytest.mark.skipif(
    not (CHECKER.exists() and all(p.exists() for p in WALKS)),
    reason="needs the shared CMU walks and motioncheck",
)


def _checker(path: Path) -> dict[str, float]:
    out = subprocess.run(
        [
            sys.executable,
            str(CHECKER),
            str(path),
            "--sources",
            *map(str, WALKS),
            "--asf",
            str(CMU / "35" / "35.asf"),
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    num = r"([0-9.]+)"
    return {
        "slip": float(re.search(r"support-foot slip\s+" + num, out).group(1)),
        "freeze": float(re.search(r"longest freeze\s+" + num, out).group(1)),
        "lknee": float(re.search(r"l knee range\s+" + num, out).group(1)),
        "rknee": float(re.search(r"r knee range\s+" + num, out).group(1)),
        "accel": float(re.search(r"largest accel\s+" + num, out).group(1)),
        "root": float(re.search(r"root speed\s+" + num, out).group(1)),
    }


def _agree(q, ref: dict[str, float]) -> None:
    assert q.support_slip == pytest.approx(ref["slip"], abs=0.011)
    assert q.longest_freeze_s == pytest.approx(ref["freeze"], abs=0.02)
    # ours: the sources' median over both legs; the checker's: the left knee's
    assert q.knee_ratio[0] == pytest.approx(ref["lknee"], abs=0.04)
    assert q.knee_ratio[1] == pytest.approx(ref["rknee"], abs=0.04)
    assert q.largest_accel == pytest.approx(ref["accel"], abs=0.011)
    assert q.root_speed == pytest.approx(ref["root"], abs=0.011)


@pytest.fixture(scope="module")
def walks():
    return [load(p) for p in WALKS]


@needs_data
def test_agrees_with_motioncheck_on_a_captured_take(walks, tmp_path):
    out = tmp_path / "35_07.bvh"  # the checker reads a motion as BVH
    save(walks[0], out)
    q = measure_generated(walks[0], walks)
    _agree(q, _checker(out))
    assert q.feet_word == "planted" and not q.freezes


@needs_data
def test_agrees_with_motioncheck_on_a_graph_output(walks, tmp_path):
    from cyclecoord.synthesis.graph import MotionGraphSynth

    gen = MotionGraphSynth(step_scale=2.0).fit(walks).generate(480, walks[0], 0)
    out = tmp_path / "walk.bvh"
    save(gen.motion, out)
    q = measure_generated(load(out), walks)
    _agree(q, _checker(out))


@needs_data
def test_gliding_feet_are_called_gliding(walks):
    """Root travel tripled: the feet slide with the body.  The old speed-gated contact
    test never counts a foot that fast; this measure calls it gliding."""
    m = walks[0]
    frames = m.frames.copy()
    cols = [m.channel_index("root", d) for d in ("tx", "tz")]
    frames[:, cols] = frames[:1, cols] + 3.0 * (frames[:, cols] - frames[:1, cols])
    glide = m.with_frames(frames)
    q = measure_generated(glide, walks)
    assert q.feet_word == "gliding"
    assert q.support_slip > 1.5 and q.slip_ratio > 10
    assert foot_skating(glide).skating_fraction < 0.25  # what the old figure said
    assert "gliding" in q.summary()[0]
    d = q.to_dict()
    assert d["feet_verdict"] == "gliding" and np.isfinite(d["support_slip_m_per_s"])


@needs_data
def test_freezes_and_held_frames(walks):
    m = walks[0]
    frames = m.frames.copy()
    frames[100:160] = frames[100]  # a held pose for half a second
    frozen = m.with_frames(frames)
    q = measure_generated(frozen, walks)
    assert len(q.freezes) == 1 and q.freezes[0][0] == 100 and q.longest_freeze_s >= 0.45
    hold = np.zeros(m.n_frames, dtype=bool)
    hold[100:161] = True
    assert not measure_generated(frozen, walks, hold=hold).freezes


@needs_data
def test_graph_feet_carry_the_body(walks):
    """cyclecoord graph's defaults (auto dims, root carried by the feet, feet pinned where
    that adds no pop) plant the feet; the paper's 2 dims with the mean root step glide."""
    from cyclecoord.synthesis.graph import MotionGraphSynth

    old = MotionGraphSynth(dims=2, step_scale=2.0, carry=False).fit(walks)
    glide = measure_generated(old.generate(360, walks[0], 0).motion, walks)
    assert glide.feet_word == "gliding"
    synth = MotionGraphSynth(dims="auto", step_scale=2.0).fit(walks)
    gen = synth.generate(360, walks[0], 0)
    q = measure_generated(gen.motion, walks)
    assert synth.dims_ == 4
    assert q.feet_word == "planted" and q.support_slip < 0.05
    assert q.penetration_m < 0.01 and not q.freezes
    assert min(q.knee_ratio) > 0.85 and q.largest_accel < 1.5
    assert 0.7 < q.root_ratio < 1.2
    assert any(n.startswith("foot locking:") for n in gen.notes)


def test_ratios_against_sources_that_never_move():
    # a model trained on hostile frames gave sources with no knee swing and no cadence:
    # animate ended in a ZeroDivisionError in its report (fuzzer model case 200139)
    q = _quality()
    assert all(np.isfinite(q.knee_ratio + q.hip_ratio)) and np.isfinite(q.cadence_ratio)


def test_fast_contact_fraction_counts_feet_faster_than_half_a_leg_a_second():
    """sliding_fraction: the frames on which a foot in contact (height alone) moves faster
    than FAST_CONTACT = 0.5 leg lengths/s.  Synthetic legs (leg 8 units, 64 fps, every
    position a multiple of 1/64: exact speeds) slide on the floor at exactly 4 units/s
    (0.5 leg/s: not faster) for 32 frames, then at 6: half the frames."""
    from _legs import legs_skeleton, make_motion

    from cyclecoord.quality.generated import FAST_CONTACT

    assert FAST_CONTACT == 0.5
    skel = legs_skeleton()
    src = make_motion(skel, T=128, fps=64.0)
    f = src.frames.copy()
    for knee in ("ltibia", "rtibia"):  # sources that move their knees (no 0 / 0 figures)
        f[:, src.channels.index((knee, "rx"))] = 10 * np.sin(2 * np.pi * np.arange(128) / 64)
    sources = [src.with_frames(f)]
    at_limit = make_motion(skel, T=64, fps=64.0, root_speed=4.0)
    q = measure_generated(at_limit, sources)
    assert all(v == 1.0 for v in q.contact_fraction.values())  # every foot on the floor
    assert q.sliding_fraction == 0.0
    f = at_limit.frames.copy()
    k = np.arange(64)
    f[:, at_limit.channels.index(("root", "tz"))] = np.where(k < 32, 4.0 * k / 64,
                                                             2.0 + 6.0 * (k - 32) / 64)
    q = measure_generated(at_limit.with_frames(f), sources)
    # frame 31's central difference still reads 4 units/s; frames 32 on read 5 and 6
    assert q.sliding_fraction == 0.5 and q.to_dict()["fast_contact_fraction"] == 0.5
    assert measure_generated(make_motion(skel, T=64, fps=64.0, root_speed=4.5),
                             sources).sliding_fraction == 1.0


def test_cycle_is_the_first_autocorrelation_peak_near_the_highest():
    """_cycle (the module's cadence): the first peak of the autocorrelation between 0.4 and
    2.5 s that reaches CYCLE_PEAK of the highest there.  A 1.1 s sine reads 1.1 s; a 0.38 s
    one (under the window) reads its first peak inside, two cycles (0.76 s), not the
    window's edge; a weak 2.2 s undertone leaves 1.1 s (its peak is within 85 % of the
    2.2 s one), a strong one makes it 2.2 s; without a peak the highest lag is taken; a
    flat or too short signal has none."""
    from cyclecoord.quality.generated import CYCLE_PEAK, CYCLE_RANGE, _cycle

    assert CYCLE_RANGE == (0.4, 2.5) and CYCLE_PEAK == 0.85
    fps, t = 100.0, np.arange(600)
    assert _cycle(np.sin(2 * np.pi * t / 110), fps) == pytest.approx(1.1, abs=0.011)
    assert _cycle(np.sin(2 * np.pi * t / 38), fps) == pytest.approx(0.76, abs=0.011)
    weak = np.sin(2 * np.pi * t / 110) + 0.2 * np.sin(2 * np.pi * t / 220)
    strong = np.sin(2 * np.pi * t / 110) + 0.5 * np.sin(2 * np.pi * t / 220)
    assert _cycle(weak, fps) == pytest.approx(1.1, abs=0.011)
    assert _cycle(strong, fps) == pytest.approx(2.2, abs=0.011)
    # no peak inside the window (a drift: the autocorrelation only falls): its highest lag
    assert _cycle(np.arange(600.0), fps) == pytest.approx(0.4)
    assert np.isnan(_cycle(np.full(600, 3.0), fps))
    assert np.isnan(_cycle(np.sin(2 * np.pi * t[:79] / 20), fps))  # 39 lags: under 0.4 s


def test_cycle_of_a_take_under_two_cycles_is_its_knee_peaks_spacing():
    """A take of 0.8 s at 60 fps (each half of the 143_01 jog) is too short for the
    autocorrelation to reach a 0.7 s cycle; its two flexion peaks 0.7 s apart give it
    (the console said "the sources' nan s" before).  A double bump (the stance flexion,
    under the mean) is not a peak; one peak, or peaks 0.2 s apart, give none."""
    from cyclecoord.quality.generated import _cycle

    fps, t = 60.0, np.arange(48)
    knee = 40 + 35 * np.sin(2 * np.pi * (t + 6) / 42) + 10 * np.sin(4 * np.pi * (t + 6) / 42)
    assert _cycle(knee, fps) == pytest.approx(0.7, abs=1 / 60)
    assert np.isnan(_cycle(knee[:30], fps))
    assert np.isnan(_cycle(np.sin(2 * np.pi * t / 12), fps))


def _knee_sources():
    """Synthetic legs at 64 fps (128 frames) and, as sources, the same legs bending both
    knees 10 deg at 1 Hz: (motion, knee columns, [sources])."""
    from _legs import legs_skeleton, make_motion

    src = make_motion(legs_skeleton(), T=128, fps=64.0)
    f = src.frames.copy()
    knees = [src.channels.index((knee, "rx")) for knee in ("ltibia", "rtibia")]
    f[:, knees] = 10 * np.sin(2 * np.pi * np.arange(128) / 64)[:, None]
    return src, knees, [src.with_frames(f)]


def test_longest_freeze_is_zero_without_slow_frames():
    """longest_freeze_s is the longest run of slow frames (pose speed under FREEZE_FRACTION
    of the sources' median), 0 when there is none; runs over FREEZE_SECONDS are freezes.
    Synthetic legs at 64 fps whose knees bend at a steady 40 deg/s have no slow frame;
    holding frame 20 for 32 frames makes steps 20-50 still: one run of 31 frames."""
    src, knees, sources = _knee_sources()
    g = src.frames[:96].copy()
    g[:, knees] = (40.0 * np.arange(96) / 64)[:, None]
    q = measure_generated(src[:96].with_frames(g), sources)
    assert q.freezes == [] and q.longest_freeze_s == 0.0
    g[20:52] = g[20]
    q = measure_generated(src[:96].with_frames(g), sources)
    assert q.freezes == [(20, 51)] and q.longest_freeze_s == pytest.approx(31 / 64)


def test_a_motion_at_a_twentieth_of_the_sources_pose_speed_is_one_freeze():
    """Slow frames are those under FREEZE_FRACTION (10 %) of the sources' median pose speed.
    Synthetic legs at 64 fps: sources bend the knees 10 deg at 1 Hz; a motion bending them
    the same way at 1/20 Hz moves at most 1/20 of the sources' fastest, under 10 % of
    their median (about 0.7 of the fastest) on every frame: one freeze of the whole take."""
    src, knees, sources = _knee_sources()
    g = src.frames[:96].copy()
    g[:, knees] = 10 * np.sin(2 * np.pi * np.arange(96) / (64 * 20))[:, None]
    q = measure_generated(src[:96].with_frames(g), sources)
    assert q.freezes == [(0, 96)] and q.longest_freeze_s == pytest.approx(96 / 64)


def test_sources_are_resampled_by_a_whole_step_within_five_percent():
    """125 fps to 30: every 4th frame gives 31.25 fps, within 5 % of 30 (1.5): taken.
    100 fps to 30: every 3rd gives 33.3, 3.3 off: the source is kept as it is."""
    from _legs import legs_skeleton, make_motion

    from cyclecoord.quality.generated import _resampled

    skel = legs_skeleton()
    m = make_motion(skel, T=120, fps=125.0)
    r = _resampled(m, 30.0)
    assert r.fps == 31.25 and r.n_frames == 30
    np.testing.assert_array_equal(r.frames, m.frames[::4])
    m = make_motion(skel, T=120, fps=100.0)
    assert _resampled(m, 30.0) is m
    assert _resampled(m, 100.0) is m  # a step of 1: nothing to do


@pytest.mark.parametrize("rig", ["static root", "z up"])
def test_the_measure_reads_any_rig_as_the_plain_one(rig):
    """A static root above travelling hips (the Bandai layout) or a Z-up world: the same
    figures as the plain rig. Before, the measure took the static root for the body's:
    the hips' travel entered every pose (accelerations 27x the sources') and the root
    speed was the static root's (0)."""
    from _rigs import static_root, walk, z_up

    from cyclecoord.rig import metres_per_unit

    plain = walk()
    if rig == "static root":
        turn = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])
        other = static_root(plain, turn, [5.0, 0.0, -3.0], True)
        other = other.with_frames(other.frames, fps=plain.fps)
    else:
        plain = plain.with_frames(plain.frames)
        other = z_up()
        # z_up is in centimetres: compare with the plain walk in the same unit
        from _rigs import in_units

        plain = in_units(walk(), 0.01)
    a, b = measure_generated(other[20:120], [other]), measure_generated(plain[20:120], [plain])
    assert metres_per_unit(other) == pytest.approx(metres_per_unit(plain))
    for key in ("support_slip", "largest_accel", "largest_step", "root_speed",
                "source_root_speed", "penetration_m", "cycle_s"):
        assert getattr(a, key) == pytest.approx(getattr(b, key), rel=1e-6, abs=1e-9), key
    assert a.knee_range == pytest.approx(b.knee_range) and a.root_speed > 0.3


def test_a_motion_on_a_bigger_body_is_compared_per_leg_length():
    """The sources' walk played on a body 1.25x as big (every bone and the root's travel
    scaled, the unit kept): the same slip, root speed, steps, accelerations and cadence
    ratios as the walk against itself, and the console says the body differs. Compared in
    units, the same joint angles on longer bones read 1.25x on each."""
    from _rigs import CMU_UNIT, in_units, walk

    plain = walk()
    big = in_units(plain, CMU_UNIT / 1.25)
    big = big.with_frames(big.frames, fps=plain.fps)
    a, b = measure_generated(big[20:120], [plain]), measure_generated(plain[20:120], [plain])
    assert b.body_scale == 1.0 and a.body_scale == pytest.approx(1.25)
    assert a.leg_length_m == pytest.approx(1.25 * b.leg_length_m)
    # in the sources' unit the big body's figures are 1.25x ...
    assert a.largest_accel * a.body_scale == pytest.approx(1.25 * b.largest_accel, rel=1e-6)
    assert a.support_slip == pytest.approx(1.25 * b.support_slip, rel=1e-6)
    assert a.root_speed == pytest.approx(1.25 * b.root_speed, rel=1e-6)
    # ... and per leg length they are the walk's
    for key in ("slip_ratio", "root_ratio", "largest_accel", "largest_step", "cadence_ratio",
                "longest_freeze_s"):
        assert getattr(a, key) == pytest.approx(getattr(b, key), rel=1e-6), key
    assert b.root_ratio > 0.5 and b.largest_accel > 0.5
    assert any("legs 1.25x the sources'" in line for line in a.summary())
    assert not any("legs" in line and "the sources'" in line for line in b.summary()[1:])
    assert a.to_dict()["body_scale"] == pytest.approx(1.25)


def test_plausibility_has_no_bone_from_a_static_root_to_the_hips():
    """The Bandai rig's static ``joint_Root`` sits on the floor where the walk passes it:
    measured as the capture's rig, a "bone" from it to the travelling hips met the legs
    (``joint_Root``/``LowerLeg_R`` 1.4 units apart in walk_normal, 0.25 from an arm in the
    turn) and graph outputs were refused for limbs passing through each other."""
    from _rigs import BANDAI, bandai

    from cyclecoord.quality.plausibility import check_plausibility

    for k in range(len(BANDAI) or 1):
        m = bandai(k)
        r = check_plausibility(m, [m])
        assert not any("joint_Root" in c["bones"] for c in r.contacts), BANDAI[k].name
        assert not r.new_contact_frames


# ------------------------------------------------------------ helpers, known answers
def _quality(**values):
    """A GeneratedQuality with every figure 0 but those given."""
    from dataclasses import MISSING, fields

    from cyclecoord.quality.generated import GeneratedQuality

    required = [f for f in fields(GeneratedQuality)
                if f.default is MISSING and f.default_factory is MISSING]
    base = {f.name: 0.0 for f in required}
    base.update(frames=10, feet=("lfoot", "rfoot"), contact_fraction={}, freezes=[],
                knee_range=(1.0, 1.0), hip_range=(1.0, 1.0), largest_step_frame=0,
                largest_accel_frame=0)
    base.update(values)
    return GeneratedQuality(**base)


def test_feet_word_bounds_and_ratios():
    """Slip up to 1.5x the sources' is planted, up to 4x slipping (both included), beyond
    gliding; a ratio's denominator is at least 1e-9."""
    from cyclecoord.quality.generated import GLIDING_RATIO, PLANTED_RATIO

    assert (PLANTED_RATIO, GLIDING_RATIO) == (1.5, 4.0)
    word = lambda slip: _quality(support_slip=slip, source_support_slip=2.0).feet_word  # noqa: E731
    assert [word(s) for s in (3.0, np.nextafter(3.0, 4.0), 8.0, np.nextafter(8.0, 9.0))] == [
        "planted", "slipping", "slipping", "gliding"]
    q = _quality(support_slip=3.0, source_support_slip=2.0, knee_range=(30.0, 45.0),
                 source_knee_range=60.0, hip_range=(10.0, 20.0), source_hip_range=40.0,
                 cycle_s=1.2, source_cycle_s=1.0, root_speed=1.5, source_root_speed=1.0)
    assert q.slip_ratio == 1.5
    assert q.knee_ratio == (0.5, 0.75) and q.hip_ratio == (0.25, 0.5)
    assert q.cadence_ratio == pytest.approx(1.2) and q.root_ratio == 1.5
    z = _quality(support_slip=1e-9, cycle_s=2e-9, root_speed=3e-9, knee_range=(4e-9, 0.0))
    assert (z.slip_ratio, z.cadence_ratio, z.root_ratio) == pytest.approx((1.0, 2.0, 3.0))
    assert z.knee_ratio == pytest.approx((4.0, 0.0))
    assert _quality(hip_range=(4e-9, 1e-9)).hip_ratio == pytest.approx((4.0, 1.0))
    # with the sources' ranges leg by leg, each leg is judged against its own
    legs = _quality(knee_range=(30.0, 45.0), source_knee_range=60.0, source_knee_legs=(40.0, 90.0),
                    hip_range=(10.0, 20.0), source_hip_range=40.0, source_hip_legs=(20.0,))
    assert legs.knee_ratio == (0.75, 0.5)
    assert legs.hip_ratio == (0.25, 0.5)  # one source leg for two: the pooled range


def test_a_limping_capture_measured_against_itself_reads_one_on_each_leg():
    """Synthetic legs whose left knee bends 10 deg and right 6 deg: against itself, each
    leg's range ratio is 1 (against the range pooled over legs it would read 1.25 and
    0.75); the sources' figures keep the pooled median for the summary."""
    src, knees, _ = _knee_sources()
    f = src.frames.copy()
    wave = np.sin(2 * np.pi * np.arange(128) / 64)
    f[:, knees[0]], f[:, knees[1]] = 10 * wave, 6 * wave
    limp = src.with_frames(f)
    q = measure_generated(limp, [limp])
    assert q.knee_ratio == pytest.approx((1.0, 1.0))
    assert q.source_knee_legs == pytest.approx(q.knee_range)
    assert q.source_knee_range == pytest.approx(np.median(q.knee_range))
    assert q.knee_range[0] == pytest.approx(q.knee_range[1] * 10 / 6, rel=0.05)


def test_to_dict_and_summary_lines():
    q = _quality(support_slip=0.5, source_support_slip=0.25, cycle_s=float("nan"),
                 freezes=[(1, 9), (12, 20), (30, 40), (50, 60), (70, 80)], held_frames=3,
                 notes=["a note"], knee_p99=(80.0, 81.0))
    d = q.to_dict()
    assert d["feet_verdict"] == "slipping" and d["support_slip_ratio"] == 2.0
    assert d["cycle_s"] is None and d["cadence_ratio"] is None
    assert d["freezes"][0] == [1, 9] and d["held_frames"] == 3 and d["knee_p99_deg"] == [80, 81]
    lines = q.summary()
    assert lines[0] == q.headline() and lines[-1] == "  a note"
    assert "frames 1-9, 12-20, 30-40, 50-60 and 1 more; 3 held frames asked for" in lines[3]
    assert _quality().summary()[3] == "  freezes: none"
    assert _quality(held_frames=2).summary()[3] == "  freezes: none (2 held frames asked for)"


def test_angle_by_hand():
    from cyclecoord.quality.generated import _angle

    u = np.array([[1.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0], [1.0, 1.0, 0], [0.0, 0, 0]])
    v = np.array([[0.0, 3, 0], [5.0, 0, 0], [-1.0, 0, 0], [1.0, 0, 0], [1.0, 0, 0]])
    np.testing.assert_allclose(_angle(u, v), [90, 0, 180, 45, 90], atol=1e-6)


def _kin_of(local=None, pos=None, fps=10.0):
    from cyclecoord.quality.generated import _Kin

    local = pos if local is None else local
    pos = local if pos is None else pos
    return _Kin(fps=fps, pos=pos, local=local, knee=np.zeros((len(pos), 2)),
                hip=np.zeros((len(pos), 2)))


def test_kin_pose_speed_accel_and_root_speed_by_hand():
    """Two joints, one moving 1 unit a frame along x (then 1 + 2 t at frame 3), the other
    still: RMS speed sqrt(1 / 2) unit a frame, times fps; the largest acceleration the
    second difference times fps^2; the root's horizontal speed over 0.5 s (5 frames at
    10 fps, rounded; 1 at 1 fps, never more than the take)."""
    T = 6
    local = np.zeros((T, 2, 3))
    local[:, 0, 0] = [0.0, 1.0, 2.0, 3.0, 5.0, 7.0]
    local[:, 1, 1] = 4.0  # height: still
    kin = _kin_of(local)
    assert kin.n == 6
    np.testing.assert_allclose(kin.pose_speed(), 10 * np.sqrt([0.5, 0.5, 0.5, 2.0, 2.0]))
    np.testing.assert_allclose(kin.accel(), [0, 0, 100, 0])
    pos = np.zeros((12, 1, 3))
    pos[:, 0, 0] = 3.0 * np.arange(12)  # 3 units a frame along x, 4 along z
    pos[:, 0, 2] = 4.0 * np.arange(12)
    pos[:, 0, 1] = np.arange(12) ** 2  # height does not count
    speed = _kin_of(pos=pos, fps=10.0).root_speed()
    assert speed.shape == (7,)
    np.testing.assert_allclose(speed, 50.0)
    assert _kin_of(pos=pos, fps=3.0).root_speed().shape == (10,)  # round(1.5) = 2
    assert _kin_of(pos=pos, fps=1.0).root_speed().shape == (11,)  # round(0.5) = 0: 1
    np.testing.assert_allclose(_kin_of(pos=pos[:4], fps=10.0).root_speed(), [50.0])  # k = 3


def test_support_is_the_lowest_foot_points_horizontal_speed():
    """Central differences of the foot point lowest on the middle frame: (p[t+1] -
    p[t-1]) fps / 2, heights left out."""
    from cyclecoord.quality.generated import _Rig, _support

    pos = np.zeros((4, 3, 3))
    pos[:, 1] = [[0, 1, 0], [1, 0, 0], [3, 2, 0], [6, 0, 0]]  # foot A
    pos[:, 2] = [[0, 0.5, 0], [0, 0.5, 4], [0, 1, 8], [0, 0, 8]]  # foot B
    rig = _Rig(legs=None, feet=("a", "b"), foot_cols=[1, 2], hips=[], knees=[], ankles=[],
               trunk=None, leg_length=1.0)
    # frame 1: A lowest (0), moving 3 in x over two frames; frame 2: B (1 < 2), 4 in z
    np.testing.assert_allclose(_support(_kin_of(pos=pos, fps=10.0), rig), [15.0, 20.0])


def test_ranges_and_lowest_by_hand():
    from cyclecoord.quality.generated import _Rig, _lowest, _ranges

    a = np.column_stack([np.arange(101.0), 2 * np.arange(101.0)])
    np.testing.assert_allclose(_ranges(a), [98, 196])  # p99 - p1 of 0..100
    pos = np.zeros((2, 4, 3))
    pos[:, :, 1] = [[5, 1, 2, 0.5], [5, 1, 0.2, 3]]
    kin = _kin_of(pos=pos)
    kin.names = ["root", "foot", "other/end", "foot/end"]
    kin.parents = [-1, 0, 0, 1]
    rig = _Rig(legs=None, feet=("foot",), foot_cols=[1], hips=[], knees=[], ankles=[],
               trunk=None, leg_length=1.0)
    # the foot's own end site counts, not another joint's
    np.testing.assert_allclose(_lowest(kin, rig), [0.5, 1.0])


def test_source_figures_root_speed_and_cycle_at():
    """The sources' cycle at a speed: linear between the takes sorted by speed, flat beyond,
    takes without a cycle (NaN) left out; NaN when none has one."""
    from cyclecoord.quality.generated import SourceFigures

    def figures(speeds, cycles):
        return SourceFigures(*([0.0] * 10), take_speed=np.array(speeds),
                             take_cycle=np.array(cycles), penetration=0.0, contact_slide=0.0)

    s = figures([3.0, 1.0, 2.0, 5.0], [1.0, 2.0, np.nan, 0.5])
    assert s.root_speed == 2.5
    assert s.cycle_at(2.0) == 1.5 and s.cycle_at(0.0) == 2.0 and s.cycle_at(9.0) == 0.5
    assert s.cycle_at(4.0) == 0.75
    assert np.isnan(figures([1.0], [np.nan]).cycle_at(1.0))


def test_rig_joints_of_two_legs():
    """legs_skeleton: ankles lfoot (3) and rfoot (7), their knees (2, 6) and hips (1, 5);
    no spine named: no trunk; the leg 4 + 4 long.  A leg whose knee would be the root has
    no hip."""
    from _legs import legs_skeleton, make_motion

    from cyclecoord.errors import ParameterError
    from cyclecoord.motion import Motion
    from cyclecoord.quality.generated import _rig

    m = make_motion(legs_skeleton(), T=8)
    rig = _rig(m, None)
    assert (rig.ankles, rig.knees, rig.hips, rig.trunk) == ([3, 7], [2, 6], [1, 5], None)
    assert rig.feet == ("lfoot", "ltoes", "rfoot", "rtoes") and rig.foot_cols == [3, 4, 7, 8]
    assert rig.leg_length == 8.0
    rig = _rig(m, ("ltoes", "rtoes"))  # toes given: their parent is the ankle
    assert (rig.ankles, rig.knees, rig.hips) == ([4, 8], [3, 7], [2, 6])
    rig = _rig(m, ("ltibia", "rtibia"))  # the hip may be the root
    assert (rig.ankles, rig.knees, rig.hips) == ([2, 6], [1, 5], [0, 0])
    with pytest.raises(ParameterError, match="no knee and hip above lfemur"):
        _rig(m, ("lfemur", "rfemur"))  # the knee would be the root
    with pytest.raises(ParameterError, match="needs a skeleton"):
        _rig(Motion(m.frames, m.channels, fps=m.fps), None)


def test_rig_trunk_is_the_second_spine_joint():
    from _legs import legs_skeleton, make_motion

    from cyclecoord.quality.generated import _rig
    from cyclecoord.skeleton import Joint, Skeleton

    base = legs_skeleton()
    for spine, trunk in (((), None), (("LowerBack",), 9), (("LowerBack", "Spine", "Spine1"), 10)):
        joints = list(base.joints)
        for k, name in enumerate(spine):
            joints.append(Joint(name, 0 if k == 0 else len(joints) - 1, [0, 2.0, 0]))
        m = make_motion(Skeleton(tuple(joints)), T=8)
        assert _rig(m, None).trunk == trunk, spine


def _bending(src, knees):
    """The synthetic legs bending both knees at a steady 40 deg/s for 96 frames."""
    g = src.frames[:96].copy()
    g[:, knees] = (40.0 * np.arange(96) / 64)[:, None]
    return g


def test_freeze_runs_longer_than_freeze_seconds_and_at_the_end():
    """At 64 fps FREEZE_SECONDS = 0.2 s is 12.8 frames: a still run of 13 frames is a
    freeze, one of 12 only the longest run; a still end runs to the last frame (the last
    frame copies the last step's flag); held frames split a run."""
    from cyclecoord.quality.generated import FREEZE_FRACTION, FREEZE_SECONDS

    assert (FREEZE_FRACTION, FREEZE_SECONDS) == (0.1, 0.2)
    src, knees, sources = _knee_sources()
    ref = None
    for still, freezes in ((14, [(20, 33)]), (13, [])):
        g = _bending(src, knees)
        g[20 : 20 + still] = g[20]  # still - 1 still steps, flagged on their first frame
        q = measure_generated(src[:96].with_frames(g), sources)
        assert q.freezes == freezes and q.longest_freeze_s == pytest.approx((still - 1) / 64)
        ref = q
    assert ref.held_frames == 0
    g = _bending(src, knees)
    g[80:] = g[80]
    assert measure_generated(src[:96].with_frames(g), sources).freezes == [(80, 96)]
    hold = np.zeros(96, dtype=bool)
    hold[86] = True
    q = measure_generated(src[:96].with_frames(g), sources, hold=hold)
    assert q.freezes == [] and q.longest_freeze_s == pytest.approx(9 / 64) and q.held_frames == 1
    with pytest.raises(ParameterError, match=r"one flag per frame \(96\)"):
        measure_generated(src[:96].with_frames(g), sources, hold=hold[:95])


def test_measure_needs_three_frames_and_sources():
    src, knees, sources = _knee_sources()
    with pytest.raises(ParameterError, match="at least 3 frames, got 2"):
        measure_generated(src[:2], sources)
    assert measure_generated(src[:3], sources).frames == 3
    with pytest.raises(ParameterError, match="needs the source captures"):
        measure_generated(src[:10], [])


def test_penetration_pops_units_and_notes():
    """The lowest foot point (the toes' end sites) stands at 0.5 (hip 9, knee 5, ankle 1, toe
    0.5), over the sources' floor (0.31: their knees bend).  Lowered 0.8 on frames 40-49 and
    0.5 on 50-59 it goes 0.61 and 0.31 under it: the deepest 0.61 units, and only the
    first 10 frames deeper than 0.02 m (0.35 units at 0.056 m a unit); a knee jumping 10 deg at frame 60 makes the largest
    pose step the step 59-60 and the largest acceleration frame 59's (the first of the
    two equal second differences, 58-60 and 59-61: frame 59 and 60; the first wins)."""
    from cyclecoord.quality.generated import PENETRATION_M, source_figures

    assert PENETRATION_M == 0.02
    src, knees, sources = _knee_sources()
    g = src.frames[:96].copy()
    ty = src.channels.index(("root", "ty"))
    g[40:50, ty] -= 0.8
    g[50:60, ty] -= 0.5
    g[60:, knees[0]] += 10.0
    ref = source_figures(sources, 64.0)
    m = ref.metres
    assert 0.3 < ref.floor < 0.32 and 0.35 < PENETRATION_M / m < 0.36
    q = measure_generated(src[:96].with_frames(g), reference=ref)
    assert q.penetration_m == pytest.approx((ref.floor + 0.3) * m, rel=1e-9)
    assert q.penetration_fraction == pytest.approx(10 / 96)
    assert q.leg_length_m == pytest.approx(8.0 * m) and q.feet == ("lfoot", "ltoes", "rfoot",
                                                                   "rtoes")
    assert q.largest_step_frame == 59 and q.largest_accel_frame == 59
    assert q.notes == []
    # sources at another rate than the motion's: said in a note
    q = measure_generated(src[:96:2].with_frames(g[::2], fps=32.0), reference=ref)
    assert q.notes == ["sources measured at 64 fps, the motion at 32"]
    # never under the floor: a penetration of 0, not negative
    q = measure_generated(src[:96], reference=ref)
    assert q.penetration_m == 0.0 and q.penetration_fraction == 0.0


def test_angle_of_parallel_vectors_rounding_over_one():
    """(0.54, 0.21, 0.36) against 3 times itself: the cosine rounds to 1 + 2^-52; clipped,
    the angle is 0, not NaN."""
    from cyclecoord.quality.generated import _angle

    u = np.array([0.54, 0.21, 0.36])
    assert _angle(u, 3 * u) == 0.0


def test_cycle_first_peak_at_the_window_start_and_rising_windows():
    """At 100 fps the window starts at lag 40: a 0.41 s sine peaks at the window's second
    lag (0.41, not its second peak 0.82); 200 samples cap the window at lag 100, where a
    1.1 s sine still rises: no peak inside, the highest lag (99: 0.99 s) is taken."""
    from cyclecoord.quality.generated import _cycle

    t = np.arange(600)
    assert _cycle(np.sin(2 * np.pi * t / 41), 100.0) == pytest.approx(0.41)
    assert _cycle(np.sin(2 * np.pi * t[:200] / 110), 100.0) == pytest.approx(0.99)


def test_contact_band_is_three_hundredths_of_the_leg():
    """Contact from height alone: within CONTACT_HEIGHT = 0.03 leg lengths (0.24 units for
    legs of 8) of each point's own low level.  The legs raised 0.23 on the second half of
    the take stay in contact; raised 0.25 they leave it on that half."""
    from cyclecoord.quality.generated import CONTACT_HEIGHT

    assert CONTACT_HEIGHT == 0.03
    src, knees, sources = _knee_sources()
    ty = src.channels.index(("root", "ty"))
    for lift, fraction in ((0.23, 1.0), (0.25, 0.5)):
        g = src.frames[:96].copy()
        g[48:, ty] += lift
        q = measure_generated(src[:96].with_frames(g), sources)
        assert q.contact_fraction == dict.fromkeys(("lfoot", "ltoes", "rfoot", "rtoes"),
                                                   fraction), lift


def test_rig_and_source_figures_are_frozen():
    from dataclasses import FrozenInstanceError

    from cyclecoord.quality.generated import _rig, source_figures

    src, knees, sources = _knee_sources()
    ref = source_figures(sources, 64.0)
    with pytest.raises(FrozenInstanceError):
        ref.floor = 0.0
    with pytest.raises(FrozenInstanceError):
        _rig(src, None).trunk = 1


def test_rig_of_three_or_four_legs_uses_the_first_two():
    from _legs import legs_skeleton, make_motion
    from _walkers import quadruped_names, quadruped_skeleton, trot

    from cyclecoord.quality.generated import _rig
    from cyclecoord.skeleton import Joint, Skeleton

    names = quadruped_names("dog")
    skel = quadruped_skeleton(names)
    rig = _rig(trot(skel, names), None)
    assert len(rig.legs.legs) == 4
    assert [skel.names[i] for i in rig.ankles] == [names["fl_ankle"], names["fr_ankle"]]
    assert len(rig.feet) == 8  # the feet are all the legs'
    # three legs given (the third a spine joint on the root, no knee): the first two
    base = legs_skeleton()
    skel = Skeleton(base.joints + (Joint("LowerBack", 0, [0, 2.0, 0]),))
    rig = _rig(make_motion(skel, T=8), ("lfoot", "rfoot", "LowerBack"))
    assert len(rig.legs.legs) == 3 and rig.ankles == [3, 7] and rig.hips == [1, 5]


def test_kin_removes_the_heading_and_measures_hips_from_the_trunk():
    """_kin: positions relative to the root with the heading (the hips' left-right line)
    turned to +x, so a body spinning in place has one local pose; the hip angle is the
    thigh against the trunk's downward line, 0 for legs hanging straight under an upright
    trunk wherever the body stands (or against -y without a trunk)."""
    from _legs import legs_skeleton

    from cyclecoord.motion import Motion
    from cyclecoord.quality.generated import _kin, _rig
    from cyclecoord.skeleton import Joint, Skeleton

    base = legs_skeleton()
    for spine in ((), ("LowerBack", "Spine")):
        joints = list(base.joints)
        for k, name in enumerate(spine):
            joints.append(Joint(name, 0 if k == 0 else len(joints) - 1, [0, 2.0, 0]))
        skel = Skeleton(tuple(joints))
        ch = skel.channels
        f = np.zeros((5, len(ch)))
        f[:, ch.index(("root", "tx"))] = 100.0
        f[:, ch.index(("root", "ty"))] = 10.0
        f[:, ch.index(("root", "ry"))] = [0.0, 30.0, 90.0, 200.0, -45.0]
        m = Motion(f, ch, fps=10.0, skeleton=skel)
        kin = _kin(m, _rig(m, None))
        np.testing.assert_allclose(kin.local, np.broadcast_to(kin.local[0], kin.local.shape),
                                   atol=1e-9)
        np.testing.assert_allclose(kin.local[0, 1], [1.0, -1.0, 0.0], atol=1e-12)  # lfemur
        np.testing.assert_allclose(kin.local[0, 5], [-1.0, -1.0, 0.0], atol=1e-12)
        np.testing.assert_allclose(kin.hip, 0.0, atol=1e-6)
        np.testing.assert_allclose(kin.knee, 0.0, atol=1e-6)
        np.testing.assert_allclose(kin.pose_speed(), 0.0, atol=1e-8)


def test_summary_says_more_only_past_four_freezes():
    four = _quality(freezes=[(0, 20), (30, 50), (60, 80), (90, 110)]).summary()[3]
    assert four.endswith("frames 0-20, 30-50, 60-80, 90-110")


def test_sliding_feet_slip_in_units_and_leg_lengths_and_knee_p99():
    """Standing legs slid forward at 4 units/s (64 fps, positions multiples of 1/16): the
    lowest foot points (the toes) move 4 units/s, half a leg of 8 a second, times the
    sources' metres per unit; the knees held bent 30 and 10 deg give those p99 flexions."""
    from _legs import legs_skeleton, make_motion

    from cyclecoord.quality.generated import source_figures

    src, knees, sources = _knee_sources()
    ref = source_figures(sources, 64.0)
    m = make_motion(legs_skeleton(), T=64, fps=64.0, root_speed=4.0)
    f = m.frames.copy()
    f[:, knees[0]] = 30.0
    f[:, knees[1]] = -10.0
    q = measure_generated(m.with_frames(f), reference=ref)
    assert q.support_slip == pytest.approx(4.0 * ref.metres, rel=1e-9)
    assert q.support_slip_legs == pytest.approx(0.5, rel=1e-9)
    # every foot point is on the floor, moving 4 units/s: so is the median one in contact
    assert q.contact_slide == pytest.approx(4.0 * ref.metres, rel=1e-9)
    assert q.knee_p99 == pytest.approx((30.0, 10.0), abs=1e-6)
    assert q.knee_range == pytest.approx((0.0, 0.0), abs=1e-6)


def test_still_sources_make_no_frame_a_freeze():
    """Slow is strictly under a tenth of the sources' median pose speed: sources that never
    move (median 0) leave a still motion without freezes, and without pops (0 / 0 was a
    NaN with a RuntimeWarning); any motion against them pops infinitely."""
    import warnings

    from _legs import legs_skeleton, make_motion

    still = make_motion(legs_skeleton(), T=64, fps=64.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        q = measure_generated(still, [still])
    assert q.freezes == [] and q.longest_freeze_s == 0.0
    assert q.largest_step == 0.0 and q.largest_accel == 0.0
    frames = np.array(still.frames)
    frames[32:, :] += 1.0  # one jump
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        q = measure_generated(still.with_frames(frames), [still])
    assert q.largest_step == np.inf and q.largest_accel == np.inf


def test_resampling_tolerance_is_strictly_under_five_percent():
    """42 fps to 20: every 2nd frame gives 21, exactly 5 % (1.0) off: kept as it is; 41
    fps gives 20.5: taken."""
    from _legs import legs_skeleton, make_motion

    from cyclecoord.quality.generated import _resampled

    skel = legs_skeleton()
    m = make_motion(skel, T=40, fps=42.0)
    assert 42.0 / 2 - 20.0 == 0.05 * 20.0
    assert _resampled(m, 20.0) is m
    r = _resampled(make_motion(skel, T=40, fps=41.0), 20.0)
    assert r.fps == 20.5 and r.n_frames == 20


def test_source_penetration_is_the_fraction_of_frames_under_the_floor():
    """Sources dipping 1 unit on 2 of their 128 frames (too few to move the floor, a low
    quantile): their lowest point goes about 0.7 units under it, over 0.02 m (0.35
    units), on those 2 frames (the floor moves by 0.002)."""
    from cyclecoord.quality.generated import source_figures

    src, knees, sources = _knee_sources()
    f = sources[0].frames.copy()
    ty = src.channels.index(("root", "ty"))
    f[[40, 90], ty] -= 1.0
    ref = source_figures([sources[0].with_frames(f)], 64.0)
    assert ref.floor == pytest.approx(source_figures(sources, 64.0).floor, abs=0.01)
    assert ref.penetration == 2 / 128
    assert source_figures(sources, 64.0).penetration == 0.0


def test_source_figures_cache_finds_each_takes_figures_once_and_reads_the_same(monkeypatch):
    """``source_figures(..., cache=)`` on overlapping sets of takes (each model's and all
    of them, as a latent script asks): each take's own figures are found once, and every
    figure reads as without the cache."""
    import cyclecoord.datasets as ds
    import cyclecoord.quality.generated as gen

    walks = [ds.make_periodic_capture(kind="walk", n_frames=100, random_state=s).motion
             for s in (0, 1)]
    runs = [ds.make_periodic_capture(kind="jog", n_frames=90, random_state=s).motion
            for s in (2, 3)]
    made = []
    real = gen._take_figures
    monkeypatch.setattr(gen, "_take_figures", lambda s, rig: made.append(1) or real(s, rig))
    cache: dict = {}
    for takes in (walks + runs, walks, runs, walks):
        got = gen.source_figures(takes, 30.0, cache=cache)
        plain = gen.source_figures(takes, 30.0)
        for f in ("floor", "pose_speed_median", "accel_p99", "support_slip", "knee_range",
                  "contact_slide", "penetration"):
            assert getattr(got, f) == getattr(plain, f), f
        np.testing.assert_array_equal(got.take_cycle, plain.take_cycle)
    # 4 takes once with the cache, then 4 + 2 + 2 + 2 without it
    assert len(made) == 4 + 10


def test_a_mixed_reference_weights_each_models_figures_by_the_frames_it_made():
    """Scalars are frame-weighted means of the models' figures, the takes' speeds and
    cycles are joined, per-leg ranges weighted leg by leg (none when the leg counts
    differ); the rate, units and leg length are the first's."""
    from dataclasses import replace

    from cyclecoord.quality.generated import SourceFigures, mixed_reference

    def ref(x, legs=(1.0, 2.0)):
        return SourceFigures(
            fps=30.0, metres=0.01, leg_length=80.0, floor=x, pose_speed_median=x,
            step_p99=x, accel_p99=x, support_slip=x, knee_range=x, hip_range=x,
            take_speed=np.array([x]), take_cycle=np.array([x]), penetration=x,
            contact_slide=x, knee_range_legs=tuple(x * v for v in legs),
            hip_range_legs=tuple(x * v for v in legs))

    walk, run = ref(1.0), ref(4.0)
    mixed = mixed_reference([(walk, 30), (run, 10)])
    for name in ("floor", "pose_speed_median", "step_p99", "accel_p99", "support_slip",
                 "knee_range", "hip_range", "penetration", "contact_slide"):
        assert getattr(mixed, name) == pytest.approx(1.75), name
    assert mixed.knee_range_legs == pytest.approx((1.75, 3.5))
    np.testing.assert_array_equal(mixed.take_speed, [1.0, 4.0])
    assert (mixed.fps, mixed.metres, mixed.leg_length) == (30.0, 0.01, 80.0)
    odd = mixed_reference([(walk, 1), (replace(run, knee_range_legs=(4.0,)), 1)])
    assert odd.knee_range_legs == () and odd.hip_range_legs == pytest.approx((2.5, 5.0))


def test_lead_lines_with_shares_judge_each_source_by_its_share():
    """A blend's weights or a transition's frames of each cycle: the motion is judged
    against each source's own figures mixed by those shares (pooled, a walk-to-jog
    transition's jog read against the walk's slip as gliding); one share of 0 leaves the
    other source's figures alone."""
    import cyclecoord as cc
    from cyclecoord.quality.generated import lead_lines, mixed_reference, source_figures

    walk = cc.datasets.make_periodic_capture(kind="walk", n_frames=480, period=120,
                                             random_state=0).motion[::4]
    jog = cc.datasets.make_periodic_capture(kind="jog", n_frames=320, period=80,
                                            random_state=1).motion[::4]
    only_walk, _ = lead_lines(jog, [walk, jog], shares=[1.0, 0.0])
    alone, _ = lead_lines(jog, [walk])
    assert only_walk["sources_support_slip_m_per_s"] == alone["sources_support_slip_m_per_s"]
    mixed, _ = lead_lines(jog, [walk, jog], shares=[3.0, 1.0])
    want = mixed_reference([(source_figures([walk], jog.fps), 3.0),
                            (source_figures([jog], jog.fps), 1.0)])
    assert mixed["sources_support_slip_m_per_s"] == pytest.approx(
        want.support_slip * want.metres)
    pooled, _ = lead_lines(jog, [walk, jog])
    assert pooled["sources_support_slip_m_per_s"] != pytest.approx(
        mixed["sources_support_slip_m_per_s"])


def test_a_source_that_stands_before_it_walks_is_judged_by_its_walk():
    """The sources' root speed, support foot, pose speeds and accelerations are theirs
    while they move: the synthetic walk with 6 s of standing before it (more than half
    the take, as the Xsens walk stands for 14 of its 25 s) reads as the walk alone, not
    about 0 m/s.  A motion's asked hold does not count in its root speed either."""
    import cyclecoord as cc
    from cyclecoord.quality.generated import source_figures

    walk = cc.datasets.make_periodic_capture(
        kind="walk", n_frames=600, period=120, noise=0.3, random_state=0).motion[::4]
    stand = np.repeat(walk.frames[:1], int(6 * walk.fps), axis=0)
    both = walk.with_frames(np.vstack([stand, walk.frames]))
    alone, joined = (source_figures([s], walk.fps) for s in (walk, both))
    assert alone.root_speed > 0.5 / alone.metres  # (a walk: over 0.5 m/s)
    assert joined.root_speed == pytest.approx(alone.root_speed, rel=0.05)
    assert joined.pose_speed_median == pytest.approx(alone.pose_speed_median, rel=0.05)
    assert joined.accel_p99 == pytest.approx(alone.accel_p99, rel=0.05)
    assert joined.support_slip == pytest.approx(alone.support_slip, rel=0.25, abs=1e-3)
    # a generated walk that then holds its last pose for 6 s: its walk's speed
    then = walk.with_frames(np.vstack([walk.frames, np.repeat(walk.frames[-1:], len(stand), 0)]))
    hold = np.r_[np.zeros(walk.n_frames, bool), np.ones(len(stand), bool)]
    q, q_walk = measure_generated(then, [walk], hold=hold), measure_generated(walk, [walk])
    assert q.root_speed == pytest.approx(q_walk.root_speed, rel=0.05)
    assert measure_generated(then, [walk]).root_speed < 0.5 * q_walk.root_speed  # unasked


def test_the_fast_contact_fraction_is_given_beside_the_sources():
    """A foot in contact (by height) moving faster than FAST_CONTACT is counted for the
    sources too (a capture's heel strikes and toe-offs make 40 % of the Bandai walks'
    frames), and a take measured against itself reads its own fraction there."""
    import cyclecoord as cc

    walk = cc.datasets.make_periodic_capture(
        kind="walk", n_frames=600, period=120, noise=0.3, random_state=0).motion[::4]
    q = measure_generated(walk, [walk])
    assert 0.0 < q.source_sliding_fraction < 1.0
    assert q.sliding_fraction == pytest.approx(q.source_sliding_fraction)
    assert q.to_dict()["sources_fast_contact_fraction"] == pytest.approx(q.sliding_fraction)
    assert f"(sources {100 * q.sliding_fraction:.0f}%" in "\n".join(q.summary())


def test_strides_are_judged_where_the_motion_does_not_stand_as_asked():
    """A walk that then stands 6 s as asked: its knee and hip ranges and leg cycle are the
    walk's (a stand is no stride: counted with it, a script that stood half its frames read
    its knees at 0.39 of the sources'), and the console says over which frames; a motion
    that stands nearly throughout is measured over all its frames and says it stands."""
    import cyclecoord as cc
    from cyclecoord.quality.generated import STRIDE_SECONDS

    walk = cc.datasets.make_periodic_capture(
        kind="walk", n_frames=600, period=120, noise=0.3, random_state=0).motion[::4]
    stand = np.repeat(walk.frames[-1:], int(6 * walk.fps), axis=0)
    then = walk.with_frames(np.vstack([walk.frames, stand]))
    hold = np.r_[np.zeros(walk.n_frames, bool), np.ones(len(stand), bool)]
    q, q_walk = measure_generated(then, [walk], hold=hold), measure_generated(walk, [walk])
    np.testing.assert_allclose(q.knee_range, q_walk.knee_range)
    np.testing.assert_allclose(q.hip_range, q_walk.hip_range)
    assert q.cycle_s == pytest.approx(q_walk.cycle_s)
    assert q.stride_frames == walk.n_frames and q.to_dict()["stride_frames"] == walk.n_frames
    assert f"strides (over the {walk.n_frames} frames outside the holds)" in "\n".join(
        q.summary())
    unasked = measure_generated(then, [walk])  # the stand counted: other ranges
    assert not np.allclose(unasked.knee_range, q.knee_range)
    # standing nearly throughout: all frames, and said
    short = int(0.5 * STRIDE_SECONDS * walk.fps)
    mostly = walk.with_frames(np.vstack([walk.frames[:short], stand]))
    held = np.r_[np.zeros(short, bool), np.ones(len(stand), bool)]
    q2 = measure_generated(mostly, [walk], hold=held)
    assert q2.stride_frames == mostly.n_frames
    np.testing.assert_allclose(q2.knee_range, measure_generated(mostly, [walk]).knee_range)
    assert f"stands on {len(stand)} of its {mostly.n_frames} frames, as asked" in "\n".join(
        q2.summary())


def test_the_roots_own_lurch_is_a_pop_the_joints_cannot_see():
    """Sources walking at 1 unit/s give or take 0.2 at 1 Hz: their root accelerates at
    most 0.2 * 2 pi units/s^2 (times sin(6 w / 2) / (6 sin(w / 2)), w = 2 pi / 64: the
    average over 0.1 s, 6 frames at 64 fps, of a 64-frame sine).  The same legs standing
    for 32 frames, then at 1 unit/s from one frame to the next: averaged over 6 frames
    the speed takes a sixth of it a frame, 64 / 6 units/s^2 on six steps (reported
    within them: equal but for rounding).  The joints, measured against the root, are
    the sources' own (1x)."""
    src, knees, _ = _knee_sources()
    tz = src.channels.index(("root", "tz"))
    t = np.arange(128) / 64
    f = src.frames.copy()
    f[:, knees] = 10 * np.sin(2 * np.pi * t)[:, None]
    f[:, tz] = t - 0.2 * np.cos(2 * np.pi * t) / (2 * np.pi)  # speed 1 + 0.2 sin
    sources = [src.with_frames(f)]
    g = f.copy()
    g[:, tz] = np.maximum(np.arange(128) - 32, 0) / 64
    q = measure_generated(src.with_frames(g), sources)
    w = 2 * np.pi / 64
    peak = 0.2 * 2 * np.pi * np.sin(3 * w) / (6 * np.sin(w / 2))
    assert q.largest_root_accel == pytest.approx((64 / 6) / peak, rel=0.02)
    assert 28 <= q.largest_root_accel_frame <= 35
    assert q.largest_accel == pytest.approx(1.0, abs=0.02)
    assert any(f"root acceleration {q.largest_root_accel:.2f}x" in s for s in q.summary())
    assert q.to_dict()["largest_root_accel_ratio"] == pytest.approx(q.largest_root_accel,
                                                                     rel=1e-3)
    # the sources themselves: 1x
    assert measure_generated(sources[0], sources).largest_root_accel == pytest.approx(
        1.0, rel=0.02)
