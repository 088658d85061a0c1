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
    from dataclasses import MISSING, fields

    from cyclecoord.quality.generated import GeneratedQuality

    required = [f for f in fields(GeneratedQuality)
                if f.default is MISSING and f.default_factory is MISSING]
    values = {f.name: 0.0 for f in required}
    values.update(frames=10, feet=("lfoot", "rfoot"), contact_fraction={}, freezes=[],
                  knee_range=(1.0, 1.0), hip_range=(1.0, 1.0), largest_step_frame=0,
                  largest_accel_frame=0)
    q = GeneratedQuality(**values)
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
