"""Tests of the built-in synthetic captures (cyclecoord.datasets)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cyclecoord import datasets as ds
from cyclecoord.errors import ParameterError
from cyclecoord.motion import Motion
from _skips import need_data

SHARED = Path(__file__).resolve().parents[2].parent / "shared" / "data"

CMU_ORDER = [
    ("root", ("tx", "ty", "tz", "rx", "ry", "rz")),
    ("lowerback", ("rx", "ry", "rz")),
    ("upperback", ("rx", "ry", "rz")),
    ("thorax", ("rx", "ry", "rz")),
    ("lowerneck", ("rx", "ry", "rz")),
    ("upperneck", ("rx", "ry", "rz")),
    ("head", ("rx", "ry", "rz")),
    ("rclavicle", ("ry", "rz")),
    ("rhumerus", ("rx", "ry", "rz")),
    ("rradius", ("rx",)),
    ("rwrist", ("ry",)),
    ("rhand", ("rx", "rz")),
    ("rfingers", ("rx",)),
    ("rthumb", ("rx", "rz")),
    ("lclavicle", ("ry", "rz")),
    ("lhumerus", ("rx", "ry", "rz")),
    ("lradius", ("rx",)),
    ("lwrist", ("ry",)),
    ("lhand", ("rx", "rz")),
    ("lfingers", ("rx",)),
    ("lthumb", ("rx", "rz")),
    ("rfemur", ("rx", "ry", "rz")),
    ("rtibia", ("rx",)),
    ("rfoot", ("rx", "rz")),
    ("rtoes", ("rx",)),
    ("lfemur", ("rx", "ry", "rz")),
    ("ltibia", ("rx",)),
    ("lfoot", ("rx", "rz")),
    ("ltoes", ("rx",)),
]
CMU_CHANNELS = tuple((j, d) for j, dofs in CMU_ORDER for d in dofs)


def col(motion: Motion, joint: str, dof: str) -> np.ndarray:
    return motion.frames[:, motion.channel_index(joint, dof)]


def angle_cols(motion: Motion) -> list[int]:
    return [i for i, (_, d) in enumerate(motion.channels) if d.startswith("r")]


def max_autocorrelation(x: np.ndarray, min_lag: int, max_lag: int) -> float:
    """Largest normalised autocorrelation of the (T, k) series over a lag range."""
    x = x - x.mean(axis=0)
    energy = float(np.sum(x * x))
    return max(float(np.sum(x[:-lag] * x[lag:])) / energy for lag in range(min_lag, max_lag))


def main_channels(motion: Motion, k: int = 8) -> np.ndarray:
    """The k non-root angle channels that vary most."""
    cols = [i for i, (j, d) in enumerate(motion.channels) if j != "root" and d.startswith("r")]
    var = motion.frames[:, cols].var(axis=0)
    pick = [cols[i] for i in np.argsort(var)[::-1][:k]]
    return motion.frames[:, pick]


# ------------------------------------------------------------------------- skeleton
def test_skeleton_layout():
    sk = ds.cmu_skeleton()
    assert sk.source_format == "synthetic"
    assert len(sk.joints) == 31
    assert sorted(sk.channels) == sorted(CMU_CHANNELS)
    assert sk["lhipjoint"].dofs == () and sk["rhipjoint"].dofs == ()
    assert sk["lhipjoint"].parent == sk.index("root")
    assert sk.joints[sk["lfemur"].parent].name == "lhipjoint"
    assert sk.joints[sk["lthumb"].parent].name == "lwrist"
    assert sk.joints[sk["rclavicle"].parent].name == "thorax"
    assert sk["rhumerus"].rotation_order == "ZYX"
    assert sk["rclavicle"].rotation_order == "ZY"
    assert sk["rfoot"].rotation_order == "ZX"
    leaves = {j.name for i, j in enumerate(sk.joints) if not sk.children(i)}
    assert leaves == {"ltoes", "rtoes", "head", "lfingers", "lthumb", "rfingers", "rthumb"}
    assert {j.name for j in sk.joints if j.end_site is not None} == leaves
    # proportions: thigh and shin about 7 units, standing height about 30
    assert 6.5 < np.linalg.norm(sk["ltibia"].offset) < 8.0
    assert 6.5 < np.linalg.norm(sk["lfoot"].offset) < 8.0
    rest = Motion(np.zeros((1, 62)), CMU_CHANNELS, skeleton=sk).positions()
    height = rest["head/end"][0, 1] - rest["ltoes/end"][0, 1]
    assert 27.0 < height < 32.0
    # left is +x, the character faces +z
    assert rest["lfemur"][0, 0] > 0 > rest["rfemur"][0, 0]
    assert rest["ltoes/end"][0, 2] > rest["lfoot"][0, 2]


def test_channels_are_cmu_amc_order():
    cap = ds.make_periodic_capture(n_frames=10, random_state=0)
    assert cap.motion.channels == CMU_CHANNELS
    assert cap.clean.channels == CMU_CHANNELS
    assert cap.motion.frames.shape == (10, 62)
    assert ds.AMC_JOINT_ORDER == tuple(j for j, _ in CMU_ORDER)


def test_channel_order_matches_real_amc():
    amc = SHARED / "cmu" / "69" / "69_01.amc"
    need_data(amc)
    names, counts, in_frame = [], [], False
    for line in amc.read_text().splitlines():
        words = line.split()
        if not words or words[0].startswith((":", "#")):
            continue
        if words[0].isdigit():
            if in_frame:
                break
            in_frame = True
            continue
        if in_frame:
            names.append(words[0])
            counts.append(len(words) - 1)
    assert names == [j for j, _ in CMU_ORDER]
    assert counts == [len(d) for _, d in CMU_ORDER]
    assert sum(counts) == 62


# --------------------------------------------------------------- periodic capture
def test_same_seed_same_arrays_different_seed_different_noise():
    a = ds.make_periodic_capture(n_frames=200, random_state=3)
    b = ds.make_periodic_capture(n_frames=200, random_state=3)
    c = ds.make_periodic_capture(n_frames=200, random_state=4)
    assert np.array_equal(a.motion.frames, b.motion.frames)
    assert np.array_equal(a.clean.frames, b.clean.frames)
    assert np.array_equal(a.phase, b.phase)
    na = a.motion.frames - a.clean.frames
    nc = c.motion.frames - c.clean.frames
    assert not np.allclose(na, nc)
    assert abs(np.corrcoef(na[:, 10], nc[:, 10])[0, 1]) < 0.3
    assert a.motion.source == "synthetic:walk(seed=3)"
    gen = ds.make_periodic_capture(n_frames=200, random_state=np.random.default_rng(3))
    assert np.array_equal(gen.motion.frames, a.motion.frames)


def test_phase_is_monotone_with_exact_mean_period():
    cap = ds.make_periodic_capture(n_frames=600, period=120.0, speed_variation=0.3, random_state=1)
    d = np.diff(cap.phase)
    assert np.all(d > 0)
    assert cap.phase[0] == 0.0
    assert cap.phase[-1] == pytest.approx(599 / 120.0, abs=1e-9)
    assert cap.period == 120.0
    # the speed really varies: the fastest frame is clearly faster than the slowest
    assert d.max() / d.min() > 1.5
    # and no more than (1 + v) / (1 - v) allows
    assert d.max() / d.min() < 1.3 / 0.7 + 1e-9
    steady = ds.make_periodic_capture(n_frames=300, period=100.0, speed_variation=0.0, random_state=1)
    assert np.allclose(steady.phase, np.arange(300) / 100.0, atol=1e-12)
    assert np.all(cap.labels == 0) and cap.labels.dtype.kind == "i"
    assert cap.boundaries == [(0, 600, "walk")]


def test_clean_is_exactly_periodic_in_the_phase():
    cap = ds.make_periodic_capture(n_frames=400, period=100.0, speed_variation=0.0, random_state=2)
    tz = cap.clean.channel_index("root", "tz")
    others = [i for i in range(62) if i != tz]
    f = cap.clean.frames
    for shift in (100, 200, 300):
        assert np.allclose(f[shift:, others], f[:-shift, others], atol=1e-9, rtol=0)
    # not trivially periodic at other lags
    assert np.abs(f[50:, others] - f[:-50, others]).max() > 10.0
    # the forward progression is not periodic: one stride per cycle
    stride = f[100:, tz] - f[:-100, tz]
    assert np.allclose(stride, stride[0], atol=1e-9) and stride[0] > 10.0


@pytest.mark.parametrize("kind", ds.KINDS)
def test_generator_depends_only_on_phase_mod_one(kind):
    rng = np.random.default_rng(5)
    from cyclecoord.datasets._body import draw_style, render_kind

    style = draw_style(rng)
    sk = ds.cmu_skeleton()
    phase = rng.uniform(0, 1, size=40)
    a = render_kind(kind, phase, style, sk)
    b = render_kind(kind, phase + 3.0, style, sk)
    tz = CMU_CHANNELS.index(("root", "tz"))
    others = [i for i in range(62) if i != tz]
    assert np.allclose(a[:, others], b[:, others], atol=1e-9, rtol=0)
    assert np.all(b[:, tz] > a[:, tz])


@pytest.mark.parametrize("noise", [0.5, 2.0])
def test_noise_level(noise):
    cap = ds.make_periodic_capture(n_frames=600, noise=noise, random_state=0)
    resid = cap.motion.frames - cap.clean.frames
    ang = resid[:, angle_cols(cap.motion)]
    assert ang.std() == pytest.approx(noise, rel=0.1)
    assert abs(ang.mean()) < 0.1 * noise
    trans = resid[:, :3]
    assert 0 < trans.std() < 0.1 * noise
    quiet = ds.make_periodic_capture(n_frames=50, noise=0.0, random_state=0)
    assert np.array_equal(quiet.motion.frames, quiet.clean.frames)


def test_root_moves_forward_and_is_not_periodic():
    walk = ds.make_periodic_capture(n_frames=600, period=120.0, random_state=0)
    tz = col(walk.motion, "root", "tz")
    # monotone on average: one-period moving means strictly increase
    means = np.convolve(tz, np.ones(120) / 120, mode="valid")
    assert np.all(np.diff(means) > 0)
    assert tz[-1] - tz[0] > 4 * 15.0  # more than ~15 units per cycle
    jog = ds.make_periodic_capture(n_frames=600, period=120.0, kind="jog", random_state=0)
    assert col(jog.clean, "root", "tz")[-1] > 1.3 * col(walk.clean, "root", "tz")[-1]
    # height bobs twice per walking cycle
    ty = col(ds.make_periodic_capture(n_frames=480, period=120.0, speed_variation=0.0,
                                      noise=0.0, random_state=0).clean, "root", "ty")
    spectrum = np.abs(np.fft.rfft(ty - ty.mean()))
    assert np.argmax(spectrum) == 8  # 480 frames / 120 = 4 cycles -> 8 bobs


@pytest.mark.parametrize("kind", ds.KINDS)
def test_forward_kinematics_is_plausible(kind):
    cap = ds.make_periodic_capture(n_frames=300, period=100.0, noise=0.5, kind=kind, random_state=0)
    for motion in (cap.motion, cap.clean):
        pos = motion.positions()
        P = pos.positions
        assert np.all(np.isfinite(P))
        hips = np.minimum(pos["lfemur"][:, 1], pos["rfemur"][:, 1])
        pelvis = pos["root"][:, 1]
        for foot in ("lfoot", "rfoot", "ltoes/end", "rtoes/end"):
            assert np.all(pos[foot][:, 1] < hips)
        assert np.all(pos["head"][:, 1] > pelvis)
        assert np.all(pos["head/end"][:, 1] > pelvis + 5.0)
        # bone lengths are constant
        for i, parent in enumerate(pos.parents):
            if parent < 0:
                continue
            length = np.linalg.norm(P[:, i] - P[:, parent], axis=1)
            assert np.ptp(length) < 1e-9
    # the clean motion stands on the floor: the lowest foot point is at y = 0 except in flight
    pos = cap.clean.positions()
    low = np.min([pos[p][:, 1] for p in ("lfoot", "rfoot", "ltoes", "rtoes", "ltoes/end", "rtoes/end")], axis=0)
    assert np.all(low > -1e-9)
    if kind in ("walk", "arm_circles", "squat"):
        assert np.allclose(low, 0.0, atol=1e-9)
    else:
        assert low.max() > 0.5  # airborne at times


def test_walk_looks_like_a_walk():
    cap = ds.make_periodic_capture(n_frames=480, period=120.0, noise=0.0, speed_variation=0.0, random_state=0)
    m = cap.clean
    rhip, lhip = col(m, "rfemur", "rx"), col(m, "lfemur", "rx")
    assert np.corrcoef(rhip, lhip)[0, 1] < -0.8  # legs in antiphase
    assert 15.0 < np.ptp(rhip) / 2 < 35.0  # swing of +-20-30 degrees
    knee = col(m, "rtibia", "rx")
    assert knee.min() > -2.0 and 45.0 < knee.max() < 75.0
    # the big knee bend comes once per cycle
    big = knee > 35.0
    assert np.count_nonzero(np.diff(big.astype(int)) == 1) in (3, 4, 5)
    # arms swing against the legs: the right arm goes forward with the left leg
    rarm = col(m, "rhumerus", "rx")
    assert np.corrcoef(rarm, lhip)[0, 1] > 0.7
    assert np.corrcoef(rarm, rhip)[0, 1] < -0.7
    assert 8.0 < np.ptp(rarm) / 2 < 25.0
    # small spine and head movement
    for joint in ("lowerback", "upperback", "thorax", "head"):
        for dof in ("rx", "ry", "rz"):
            assert np.ptp(col(m, joint, dof)) < 8.0


@pytest.mark.parametrize("kind", ds.KINDS)
def test_each_kind_traces_one_clear_loop(kind):
    """One cycle is a loop in angle space (not the same path out and back), so H1 shows it."""
    from ripser import ripser

    cap = ds.make_periodic_capture(n_frames=100, period=100.0, noise=0.0, speed_variation=0.0,
                                   kind=kind, random_state=0)
    dgm = ripser(cap.clean.frames[:, angle_cols(cap.clean)], maxdim=1)["dgms"][1]
    life = np.sort(dgm[:, 1] - dgm[:, 0])[::-1]
    assert life[0] > 10.0
    assert len(life) == 1 or life[0] > 3.0 * life[1]


def _stats(motion: Motion) -> np.ndarray:
    cols = angle_cols(motion)
    return np.concatenate([motion.frames[:, cols].std(axis=0), motion.frames[:, cols].mean(axis=0)])


def test_kinds_are_distinct():
    caps = {k: ds.make_periodic_capture(n_frames=300, period=100.0, kind=k, random_state=0) for k in ds.KINDS}
    stats = {k: _stats(c.clean) for k, c in caps.items()}
    for a in ds.KINDS:
        for b in ds.KINDS:
            if a < b:
                assert np.abs(stats[a] - stats[b]).max() > 15.0, (a, b)
    amp = lambda k, j, d: np.ptp(col(caps[k].clean, j, d))  # noqa: E731
    assert amp("jog", "rfemur", "rx") > 1.3 * amp("walk", "rfemur", "rx")
    assert amp("jog", "rtibia", "rx") > 1.3 * amp("walk", "rtibia", "rx")
    assert amp("jumping_jack", "lhumerus", "rz") > 120.0
    assert amp("jumping_jack", "lfemur", "rz") > 8.0
    assert amp("arm_circles", "lfemur", "rx") < 5.0
    assert col(caps["arm_circles"].clean, "lhumerus", "rz").mean() > 70.0
    assert amp("squat", "ltibia", "rx") > 90.0
    assert amp("squat", "lhumerus", "rz") < 10.0
    assert np.ptp(col(caps["squat"].clean, "root", "ty")) > 5.0


# ------------------------------------------------------------------------- chains
def test_chain_boundaries_labels_and_phase():
    ch = ds.make_motion_chain(random_state=0)
    T = ch.motion.n_frames
    assert T == 3 * 600 + 2 * 40
    assert ch.boundaries == [(0, 600, "walk"), (640, 1240, "jumping_jack"), (1280, 1880, "arm_circles")]
    assert ch.motion.channels == CMU_CHANNELS and ch.clean.n_frames == T
    periods = ch.motion.metadata["periods"]
    assert periods == [120.0, 90.0, 100.0]
    assert ch.period == pytest.approx(np.mean(periods))
    for k, (s, e, kind) in enumerate(ch.boundaries):
        assert np.all(ch.labels[s:e] == k)
        seg = ch.phase[s:e]
        assert seg[0] == 0.0 and np.all(np.diff(seg) > 0)
        assert seg[-1] == pytest.approx((e - s - 1) / periods[k], abs=1e-9)
    gaps = np.ones(T, dtype=bool)
    for s, e, _ in ch.boundaries:
        gaps[s:e] = False
    assert np.all(ch.labels[gaps] == -1) and np.all(np.isnan(ch.phase[gaps]))
    assert not np.any(np.isnan(ch.phase[~gaps]))
    assert ch.motion.source == "synthetic:chain(walk,jumping_jack,arm_circles; seed=0)"


def test_chain_is_continuous_and_segments_differ():
    ch = ds.make_motion_chain(random_state=1)
    f = ch.clean.frames
    step = np.abs(np.diff(f, axis=0))
    gaps = np.ones(len(f) - 1, dtype=bool)
    for s, e, _ in ch.boundaries:
        gaps[s : e - 1] = False
    # transitions are no jerkier than the motions themselves (per channel, with slack)
    assert np.all(step[gaps].max(axis=0) <= 1.5 * step[~gaps].max(axis=0) + 0.5)
    tz = f[:, 2]
    assert np.abs(np.diff(tz)).max() < 1.0
    assert tz[-1] > tz[600] > tz[0]
    # kinds have visibly different joint-angle statistics
    seg = [_stats(ch.clean[s:e]) for s, e, _ in ch.boundaries]
    for i in range(3):
        for j in range(i + 1, 3):
            assert np.abs(seg[i] - seg[j]).max() > 15.0
    walk, jack, circles = (ch.clean[s:e] for s, e, _ in ch.boundaries)
    assert np.std(col(walk, "lfemur", "rx")) > 2 * np.std(col(jack, "lfemur", "rx"))
    assert np.std(col(jack, "lhumerus", "rz")) > 3 * np.std(col(circles, "lhumerus", "rz"))
    assert np.mean(col(circles, "lhumerus", "rz")) > 60.0 > np.mean(col(walk, "lhumerus", "rz"))


def test_chain_options():
    ch = ds.make_motion_chain(
        kinds=("walk", "squat", "walk"), segment_frames=[200, 300, 150], periods=[100, 150, 80],
        transition_frames=0, noise=0.0, random_state=0,
    )
    assert ch.boundaries == [(0, 200, "walk"), (200, 500, "squat"), (500, 650, "walk")]
    assert list(ch.labels[[0, 199, 200, 499, 500, 649]]) == [0, 0, 1, 1, 0, 0]
    assert not np.any(np.isnan(ch.phase))
    assert np.array_equal(ch.motion.frames, ch.clean.frames)
    assert np.abs(np.diff(ch.clean.frames[:, 2])).max() < 1.0  # root tz still continuous
    single = ds.make_motion_chain(kinds="jog", segment_frames=100, random_state=0)
    assert single.boundaries == [(0, 100, "jog")] and np.all(single.labels == 0)


# ------------------------------------------------------------ nothing periodic
def test_static_and_random_walk_have_no_periodic_structure():
    walk = ds.make_periodic_capture(n_frames=600, period=120.0, random_state=0)
    assert max_autocorrelation(main_channels(walk.motion), 10, 300) > 0.5  # the check can fire

    static = ds.make_static_capture(n_frames=600, noise=0.5, random_state=0)
    rw = ds.make_random_walk_capture(n_frames=600, step=0.5, random_state=0)
    for cap in (static, rw):
        assert cap.motion.channels == CMU_CHANNELS
        assert np.all(cap.labels == -1)
        assert np.all(np.isnan(cap.phase)) and np.isnan(cap.period)
        assert cap.boundaries == []
        pos = cap.motion.positions()
        assert np.all(pos["head"][:, 1] > pos["root"][:, 1])
    assert max_autocorrelation(main_channels(static.motion), 10, 300) < 0.3
    assert np.allclose(static.clean.frames, static.clean.frames[0])
    assert static.motion.source == "synthetic:static(seed=0)"
    diffs = np.diff(main_channels(rw.motion), axis=0)
    assert max_autocorrelation(diffs, 10, 300) < 0.3
    # the random walk really wanders (unlike the static capture)
    assert np.ptp(main_channels(rw.motion), axis=0).min() > 5.0
    assert np.ptp(main_channels(static.motion), axis=0).max() < 5.0
    assert np.array_equal(rw.motion.frames,
                          ds.make_random_walk_capture(n_frames=600, step=0.5, random_state=0).motion.frames)


def test_example_capture():
    ex = ds.example_capture()
    assert ex.name == "synthetic-walk"
    assert ex.motion.n_frames == 480 and ex.period == 120.0
    assert ex.motion.source == "synthetic:walk(seed=0)"
    assert ex.phase[-1] == pytest.approx(479 / 120.0)
    assert ex.motion.fps == 120.0 and ex.motion.skeleton is not None


# ------------------------------------------------------------------ bad arguments
@pytest.mark.parametrize(
    "kwargs",
    [
        dict(n_frames=1),
        dict(n_frames=10.5),
        dict(n_frames="600"),
        dict(period=1.0),
        dict(period=float("nan")),
        dict(noise=-0.1),
        dict(speed_variation=1.0),
        dict(speed_variation=-0.1),
        dict(fps=0),
        dict(kind="swim"),
        dict(random_state="seed"),
    ],
)
def test_bad_periodic_arguments(kwargs):
    with pytest.raises(ParameterError):
        ds.make_periodic_capture(**kwargs)


def test_unknown_kind_lists_the_kinds():
    with pytest.raises(ParameterError, match="walk, jog, jumping_jack, arm_circles, squat"):
        ds.make_periodic_capture(kind="moonwalk")


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(kinds=()),
        dict(kinds=("walk", "fly")),
        dict(segment_frames=1),
        dict(segment_frames=[100, 100]),
        dict(periods=[100, 90]),
        dict(periods=[100, 90, 0.5]),
        dict(transition_frames=-1),
        dict(noise=-1),
        dict(speed_variation=1.5),
    ],
)
def test_bad_chain_arguments(kwargs):
    with pytest.raises(ParameterError):
        ds.make_motion_chain(**kwargs)


@pytest.mark.parametrize(
    "call",
    [
        lambda: ds.make_static_capture(n_frames=0),
        lambda: ds.make_static_capture(noise=-1),
        lambda: ds.make_random_walk_capture(n_frames=1),
        lambda: ds.make_random_walk_capture(step=float("inf")),
    ],
)
def test_bad_non_periodic_arguments(call):
    with pytest.raises(ParameterError):
        call()


# ------------------------------------------------------------------- whole takes
TURN_SCRIPT = (
    ("stand", 1.0), ("start", 1), ("steady", 3), ("turn", 1.5, 120), ("steady", 3),
    ("turn", 1.2, -150), ("steady", 3), ("stop", 1), ("stand", 1.0),
)


@pytest.fixture(scope="module")
def take():
    return ds.make_whole_take(random_state=0)


@pytest.fixture(scope="module")
def turning_take():
    return ds.make_whole_take(script=TURN_SCRIPT, noise=0.0, random_state=3)


def moving_runs(cap) -> list[tuple[int, int]]:
    """Maximal runs of consecutive frames that are not standing."""
    moving = cap.part_labels != ds.PART_NAMES.index("stand")
    edges = np.flatnonzero(np.diff(np.r_[0, moving.astype(int), 0]))
    return list(zip(edges[::2], edges[1::2]))


def facing(cap) -> np.ndarray:
    """Facing direction (degrees, 0 = +z, positive towards +x) from the hips, unwrapped."""
    pos = cap.clean.positions()
    left = pos["lfemur"] - pos["rfemur"]  # points to the body's left
    return np.degrees(np.unwrap(np.arctan2(-left[:, 2], left[:, 0])))


def test_whole_take_default_script_and_ground_truth(take):
    n = take.motion.n_frames
    names = [p[0] for p in take.parts]
    assert names == [
        "stand", "start", "steady", "turn", "steady", "stop",
        "stand", "start", "steady", "stop", "stand",
    ]
    assert take.parts[0][1] == 0 and take.parts[-1][2] == n
    assert all(a[2] == b[1] for a, b in zip(take.parts, take.parts[1:]))
    for name, s, e in take.parts:
        assert (take.part_labels[s:e] == ds.PART_NAMES.index(name)).all()
    steady = [(s, e) for name, s, e in take.parts if name == "steady"]
    assert take.steady == steady and take.boundaries == [(s, e, "walk") for s, e in steady]
    in_steady = np.zeros(n, bool)
    for s, e in steady:
        in_steady[s:e] = True
    assert ((take.labels == 0) == in_steady).all() and set(np.unique(take.labels)) == {-1, 0}
    assert 2000 < n < 3200 and take.motion.fps == 120.0
    assert take.period == pytest.approx(120.0, rel=0.03)
    assert np.isfinite(take.motion.frames).all() and np.isfinite(take.clean.frames).all()
    assert take.motion.channels == take.clean.channels == CMU_CHANNELS
    # phase: NaN exactly where the person stands, strictly increasing while moving
    standing = take.part_labels == ds.PART_NAMES.index("stand")
    assert (np.isnan(take.phase) == standing).all()
    for s, e in moving_runs(take):
        assert (np.diff(take.phase[s:e]) > 0).all()
    turn = take.parts[3]
    assert 90 <= abs(take.heading[turn[2] - 1] - take.heading[turn[1]]) <= 180
    assert take.name == "synthetic-take(walk)"
    assert take.motion.source == "synthetic:take(walk; seed=0)"


def test_whole_take_standing_is_still_and_moving_is_not(take):
    clean = take.clean
    speed = np.linalg.norm(np.diff(clean.positions().positions, axis=0), axis=2).max(axis=1)
    stand_code = ds.PART_NAMES.index("stand")
    for name, s, e in take.parts:
        if name == "stand":
            assert np.ptp(clean.frames[s:e], axis=0).max() < 1e-9
            assert speed[s : e - 1].max() < 1e-9
    steady = take.labels[1:] == 0
    assert np.median(speed[steady]) > 0.2  # a walk moves its feet about 0.2-0.5 units a frame
    # the noise is on top of still frames too
    noisy = take.motion.frames[take.part_labels == stand_code][:, angle_cols(take.motion)]
    resid = noisy - clean.frames[take.part_labels == stand_code][:, angle_cols(clean)]
    assert resid.std() == pytest.approx(0.5, rel=0.1)


def test_whole_take_is_smooth_across_parts(take):
    """No jump where parts meet, and nowhere a change larger than walking makes."""
    frames = take.clean.frames
    joints = [i for i, (j, d) in enumerate(take.clean.channels) if j != "root" and d[0] == "r"]
    step = np.abs(np.diff(frames[:, joints], axis=0))
    accel = np.abs(np.diff(frames[:, joints], 2, axis=0))
    for _, _, b in take.parts[:-1]:
        around = np.r_[b - 21 : b - 2, b + 1 : b + 20]
        assert (step[b - 1] <= 1.1 * step[around].max(axis=0) + 1e-3).all()
        assert (accel[b - 2 : b].max(axis=0) <= 1.5 * accel[around].max(axis=0) + 1e-3).all()
    not_turning = take.part_labels[1:] != ds.PART_NAMES.index("turn")
    steady_step = step[take.labels[1:] == 0].max(axis=0)
    assert (step[not_turning].max(axis=0) <= 1.1 * steady_step + 0.05).all()
    assert accel.max() <= 1.1 * accel[take.labels[2:] == 0].max()


def test_whole_take_start_and_stop_ramp_the_gait(take):
    hip = col(take.clean, "rfemur", "rx")
    root = take.clean.frames[:, [take.clean.channel_index("root", d) for d in ("tx", "tz")]]
    travel = np.linalg.norm(np.diff(root, axis=0), axis=1)
    for name, s, e in take.parts:
        if name not in ("start", "stop"):
            continue
        third = (e - s) // 3
        first, last = np.ptp(hip[s : s + third]), np.ptp(hip[e - third : e])
        v_first, v_last = travel[s : s + third].mean(), travel[e - third - 1 : e - 1].mean()
        if name == "start":
            assert first < 0.3 * last and v_first < 0.3 * v_last
        else:
            assert last < 0.3 * first and v_last < 0.3 * v_first
    # steady walking travels about one stride (26 units) per cycle
    s, e = take.steady[0]
    cycles = take.phase[e - 1] - take.phase[s]
    assert np.linalg.norm(root[e - 1] - root[s]) / cycles == pytest.approx(26.0 * 1.0, rel=0.15)


def test_whole_take_heading_turns_by_the_scripted_amount(turning_take):
    cap = turning_take
    face = facing(cap)
    assert np.abs(((face - cap.heading + 180) % 360) - 180).max() < 6.0  # pelvis yaw only
    period = int(round(cap.period))
    steady = cap.steady
    for (s0, e0), (s1, e1), degrees in zip(steady, steady[1:], (120.0, -150.0)):
        before = face[e0 - period : e0].mean()  # one cycle: the pelvis yaw averages out
        after = face[s1 : s1 + period].mean()
        assert after - before == pytest.approx(degrees, abs=2.0)
        assert cap.heading[s1] - cap.heading[e0 - 1] == pytest.approx(degrees)
    # the root travels along the heading
    root = cap.clean.frames[:, [cap.clean.channel_index("root", d) for d in ("tx", "tz")]]
    for s, e in steady:
        d = root[e - 1] - root[s]
        travel = np.degrees(np.arctan2(d[0], d[1]))
        assert ((travel - cap.heading[s] + 180) % 360) - 180 == pytest.approx(0.0, abs=3.0)
    # AMC root angles: rx, rz wrapped and small away from headings of +-90 degrees (the
    # Euler singularity), ry unwrapped and following the heading
    rot = cap.clean.frames[:, [cap.clean.channel_index("root", d) for d in ("rx", "ry", "rz")]]
    assert (np.abs(rot[:, [0, 2]]) <= 180.0).all()
    far = np.abs((cap.heading % 180.0) - 90.0) > 30.0  # heading 30+ degrees from +-90
    far &= cap.part_labels != ds.PART_NAMES.index("turn")  # (turns lean into the curve)
    assert far.mean() > 0.3
    assert np.abs(rot[far][:, [0, 2]]).max() < 10.0
    assert np.abs(rot[far, 1] - cap.heading[far]).max() < 8.0
    # and the lean into the turn: the head moves to the inside of the curve
    pos = cap.clean.positions()
    left = pos["lfemur"] - pos["rfemur"]
    left[:, 1] = 0.0
    inward = np.sum((pos["head"] - pos["root"]) * left, axis=1) / np.linalg.norm(left, axis=1)
    for name, s, e in cap.parts:
        middle = inward[s + (e - s) // 3 : e - (e - s) // 3].mean()
        if name == "turn":
            assert np.sign(cap.heading[e - 1] - cap.heading[s]) * middle > 0.5
        elif name == "steady":
            assert abs(middle) < 0.2


def test_whole_take_curve_drifts_the_heading_per_cycle():
    cap = ds.make_whole_take(script=(("steady", 6),), curve=5.0, noise=0.0, random_state=4)
    n, period = cap.motion.n_frames, int(round(cap.period))
    assert cap.heading[-1] - cap.heading[0] == pytest.approx(5.0 * (n - 1) / 120.0)
    face = facing(cap)
    drift = face[n - period :].mean() - face[:period].mean()
    assert drift == pytest.approx(5.0 * (n - period) / 120.0, abs=1.0)
    straight = ds.make_whole_take(script=(("steady", 6),), noise=0.0, random_state=4)
    assert np.ptp(straight.heading) == 0.0


def test_whole_take_steady_parts_have_the_true_period(turning_take):
    cap = turning_take
    cols = [i for i, (j, d) in enumerate(cap.clean.channels) if j != "root" and d[0] == "r"]
    joints = cap.clean.frames[:, cols]
    for s, e in cap.steady:
        part = joints[s:e] - joints[s:e].mean(axis=0)
        lags = np.arange(int(0.8 * cap.period), int(1.2 * cap.period))
        score = [np.sum(part[:-lag] * part[lag:]) / np.sum(part[:-lag] ** 2) for lag in lags]
        true = (e - 1 - s) / (cap.phase[e - 1] - cap.phase[s])
        assert lags[int(np.argmax(score))] == pytest.approx(true, abs=2.0)
        assert true == pytest.approx(cap.period, rel=0.05)
    assert cap.period == pytest.approx(120.0, rel=0.03)
    # steady frames are the plain gait: the joint angles depend on the phase alone
    s0, e0 = cap.steady[0]
    s1, e1 = cap.steady[-1]
    phi0, phi1 = np.mod(cap.phase[s0:e0], 1.0), np.mod(cap.phase[s1:e1], 1.0)
    for k in range(0, e0 - s0, 17):
        j = int(np.argmin(np.abs(((phi1 - phi0[k] + 0.5) % 1.0) - 0.5)))
        gap = abs(((phi1[j] - phi0[k] + 0.5) % 1.0) - 0.5)
        assert np.abs(joints[s1 + j] - joints[s0 + k]).max() < 1.0 + 400.0 * gap


def test_whole_take_of_6000_frames_repeats_turns_and_pauses():
    cap = ds.make_whole_take(n_frames=6000, random_state=1)
    assert cap.motion.n_frames == 6000 and np.isfinite(cap.motion.frames).all()
    names = [p[0] for p in cap.parts]
    assert names[:2] == ["stand", "start"] and names[-2:] == ["stop", "stand"]
    assert names.count("turn") >= 2 and names.count("stand") - 2 >= 2  # pauses
    assert all(e - s >= 3 * 120 - 1 for s, e in cap.steady)
    assert cap.period == pytest.approx(120.0, rel=0.03)
    for s, e in moving_runs(cap):
        assert (np.diff(cap.phase[s:e]) > 0).all()
    turns = [cap.heading[e - 1] - cap.heading[s] for name, s, e in cap.parts if name == "turn"]
    assert all(85 <= abs(t) <= 180 for t in turns)


def test_whole_take_is_deterministic_and_jogs():
    a = ds.make_whole_take(script=(("steady", 2), ("pause", 1.0), ("steady", 2)), random_state=5)
    b = ds.make_whole_take(script=(("steady", 2), ("pause", 1.0), ("steady", 2)), random_state=5)
    assert np.array_equal(a.motion.frames, b.motion.frames)
    assert [p[0] for p in a.parts] == ["steady", "stop", "stand", "start", "steady"]
    script = (("stand", 0.5), ("start", 1), ("steady", 3), ("stop", 1))
    jog = ds.make_whole_take("jog", script=script)
    assert jog.period == pytest.approx(80.0, rel=0.05)
    assert np.isfinite(jog.motion.frames).all() and np.isnan(jog.phase[:60]).all()


def test_whole_take_is_the_cli_example(take):
    from cyclecoord.cli.report import load_input

    motion = load_input("example:take")
    assert np.array_equal(motion.frames, take.motion.frames)


def test_other_generators_have_no_take_fields():
    cap = ds.make_periodic_capture(n_frames=50, random_state=0)
    assert cap.parts is None and cap.part_labels is None
    assert cap.steady is None and cap.heading is None


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(kind="squat"), "gait"),
        (dict(script=[("steady", 3)], n_frames=3000), "not both"),
        (dict(n_frames=300), "at least"),
        (dict(script=[]), "at least one"),
        (dict(script="stand"), "sequence"),
        (dict(script=[("fly", 2)]), "entry 0: unknown part 'fly'"),
        (dict(script=[("stand", 1), ("steady", 3)]), "entry 1 .'steady'. .*start"),
        (dict(script=[("steady", 3), ("stand", 1)]), "entry 1 .'stand'. .*stop"),
        (dict(script=[("steady", 3), ("start", 1)]), "entry 1"),
        (dict(script=[("steady", -1)]), "entry 0"),
        (dict(script=[("steady", "x")]), "entry 0"),
        (dict(script=[("steady", 3), ("turn", 1, "left")]), "entry 1"),
        (dict(script=[("steady", 3, 90)]), "entry 0"),
        (dict(script=[("steady",)]), "entry 0"),
        (dict(script=[("stand", 0.001)]), "under 2 frames"),
        (dict(period=0.5), "period"),
        (dict(noise=-1), "noise"),
        (dict(speed_variation=1.0), "speed_variation"),
        (dict(curve=float("nan")), "curve"),
    ],
)
def test_bad_whole_take_arguments(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        ds.make_whole_take(**kwargs)
