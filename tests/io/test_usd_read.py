"""The USD module's helpers, each on a small stage built here with usd-core, the answer
worked out by hand: joint paths, slerp, the time codes and frame rate a stage gives, the
memory it needs, the animation's checks and its interpolation between sparse samples,
customData, and a stage from elsewhere (issue 27: known answers)."""

import json

import numpy as np
import pytest
from pxr import Gf, Usd, UsdSkel, Vt

from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io import usd
from cyclecoord.io._limits import MAX_FRAMES, MAX_JOINTS, memory_limit
from cyclecoord.skeleton import Joint, Skeleton

S = np.sqrt(0.5)
IDENTITY = (1.0, 0.0, 0.0, 0.0)  # w x y z


def _stage(path, joints, samples, *, start=0, end=None, fps=24.0, scales=None, custom=None):
    """A stage of one skeleton with ``joints`` (paths), identity rest and bind transforms,
    and an animation whose ``samples`` map a time code to (translations (J, 3),
    quaternions (J, 4) as w x y z); scales 1 unless given (J, 3)."""
    stage = Usd.Stage.CreateInMemory()
    stage.SetTimeCodesPerSecond(fps)
    stage.SetStartTimeCode(start)
    stage.SetEndTimeCode(max(samples) if end is None else end)
    UsdSkel.Root.Define(stage, "/R")
    skel = UsdSkel.Skeleton.Define(stage, "/R/Skel")
    skel.CreateJointsAttr(Vt.TokenArray(joints))
    eye = Vt.Matrix4dArray([Gf.Matrix4d(1.0)] * len(joints))
    skel.CreateRestTransformsAttr(eye)
    skel.CreateBindTransformsAttr(eye)
    anim = UsdSkel.Animation.Define(stage, "/R/Skel/Anim")
    anim.CreateJointsAttr(Vt.TokenArray(joints))
    t_attr, r_attr = anim.CreateTranslationsAttr(), anim.CreateRotationsAttr()
    for t, (tr, q) in samples.items():
        t_attr.Set(Vt.Vec3fArray.FromNumpy(np.asarray(tr, np.float32).reshape(-1, 3)),
                   Usd.TimeCode(t))
        r_attr.Set(Vt.QuatfArray([Gf.Quatf(*map(float, w)) for w in q]), Usd.TimeCode(t))
    sc = np.ones((len(joints), 3)) if scales is None else np.asarray(scales, float)
    anim.CreateScalesAttr().Set(Vt.Vec3hArray([Gf.Vec3h(*map(float, s)) for s in sc]))
    UsdSkel.BindingAPI.Apply(skel.GetPrim()).CreateAnimationSourceRel().SetTargets(
        [anim.GetPath()])
    if custom is not None:
        skel.GetPrim().SetCustomDataByKey("cyclecoord", custom)
    stage.GetRootLayer().Export(str(path))
    return path


def _still(joints, times=(0,)):
    """Every joint at the origin, unturned, at each of ``times``."""
    n = len(joints)
    return {t: (np.zeros((n, 3)), [IDENTITY] * n) for t in times}


# ----------------------------------------------------------------------------- joint paths
def test_joint_paths_unique_identifiers_and_end_sites():
    """Names made identifiers (``a b`` -> ``a_b``); a repeat gets _2, _3; end sites are
    joints named <joint>_end under their joint, named <joint>/end."""
    from pxr import Tf

    skel = Skeleton((
        Joint("hips", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
        Joint("a b", 0, [0, 1, 0], ("rx",), "X"),
        Joint("a_b", 1, [0, 1, 0], ("rx",), "X", end_site=[0, 1, 0]),
        Joint("a-b", 0, [1, 0, 0], ("rx",), "X", end_site=[1, 0, 0]),
    ))
    paths, names, parents = usd._joint_paths(skel, Tf)
    assert paths == ["hips", "hips/a_b", "hips/a_b/a_b_2", "hips/a_b_3", "hips/a_b/a_b_2/a_b_end",
                     "hips/a_b_3/a_b_end_2"]
    assert names == ["hips", "a b", "a_b", "a-b", "a_b/end", "a-b/end"]
    assert parents == [-1, 0, 1, 0, 2, 3]


# ----------------------------------------------------------------------------- slerp
def test_slerp_known_angles():
    """Between the identity and a quarter turn about z, a fraction u of the way is a turn of
    u x 90 degrees: (0, 0, sin(u pi / 4), cos(u pi / 4)) (x y z w)."""
    qa = np.array([0, 0, 0, 1.0])
    qb = np.array([0, 0, S, S])
    u = np.array([0.0, 0.25, 0.5, 1.0])[:, None]
    expected = np.stack([0 * u[:, 0], 0 * u[:, 0], np.sin(u[:, 0] * np.pi / 4),
                         np.cos(u[:, 0] * np.pi / 4)], axis=1)
    np.testing.assert_allclose(usd._slerp(qa, qb, u), expected, atol=1e-15)
    # -qb is the same rotation: the shorter arc gives the same quaternions
    np.testing.assert_allclose(usd._slerp(qa, -qb, u), expected, atol=1e-15)
    # a half turn about z from the identity, a third of the way: 60 degrees
    out = usd._slerp(qa, np.array([0, 0, 1.0, 0]), np.array([[1 / 3]]))
    np.testing.assert_allclose(out, [[0, 0, np.sin(np.pi / 6), np.cos(np.pi / 6)]], atol=1e-15)


def test_slerp_of_nearly_equal_quaternions_is_linear_and_unit():
    """Under 1e-6 rad apart (theta = 2e-7 here) the weights are 1 - u and u, renormalised;
    both ends are returned exactly."""
    qa = np.array([0, 0, 0, 1.0])
    qb = np.array([0, 0, np.sin(1e-7), np.cos(1e-7)])
    out = usd._slerp(qa, qb, np.array([[0.0], [0.5], [1.0]]))
    assert np.isfinite(out).all()
    np.testing.assert_allclose(out[0], qa, atol=0)
    np.testing.assert_allclose(out[2], qb, atol=1e-16)
    np.testing.assert_allclose(out[1], [0, 0, np.sin(5e-8), np.cos(5e-8)], atol=1e-16)
    np.testing.assert_allclose(np.linalg.norm(out, axis=1), 1.0, atol=1e-15)


# ----------------------------------------------------------------------------- _open
def test_time_codes_and_frame_rate(tmp_path):
    """Frames at the whole time codes round(start) .. round(end), timeCodesPerSecond the
    rate."""
    path = _stage(tmp_path / "a.usda", ["r"], _still(["r"], (0,)), start=1.4, end=4.6, fps=25)
    _stage_, prim, _query, times, fps = usd._open(path)
    assert times.tolist() == [1, 2, 3, 4, 5] and fps == 25.0
    assert str(prim.GetPath()) == "/R/Skel"
    path = _stage(tmp_path / "b.usda", ["r"], _still(["r"]), start=3, end=3)
    assert usd._open(path)[3].tolist() == [3]
    path = _stage(tmp_path / "c.usda", ["r"], _still(["r"]), start=3, end=2)
    with pytest.raises(ParseError, match="endTimeCode 2 comes before startTimeCode 3"):
        usd._open(path)


@pytest.mark.parametrize("code, ok", [(1e9, True), (-1e9, True), (1.005e9, False),
                                      (-1.005e9, False)])
def test_time_codes_at_most_a_hundred_times_max_frames(tmp_path, code, ok):
    path = _stage(tmp_path / "a.usda", ["r"], _still(["r"]), start=code, end=code)
    if ok:
        assert usd._open(path)[3].tolist() == [code]
    else:
        with pytest.raises(ParseError, match="startTimeCode .* is not a finite time code"):
            usd._open(path)


def test_frame_count_limit(tmp_path):
    """Time codes 0 .. 9,999,999 are MAX_FRAMES frames (then refused only for the memory
    they need), 0 .. 10,000,000 one too many."""
    path = _stage(tmp_path / "a.usda", ["r"], _still(["r"]), end=MAX_FRAMES - 1)
    with memory_limit(1e6), pytest.raises(ParseError, match="10,000,000 frames of 1 joints need"):
        usd._open(path)
    path = _stage(tmp_path / "b.usda", ["r"], _still(["r"]), end=MAX_FRAMES)
    with pytest.raises(ParseError, match="time codes 0..1e\\+07 are 10,000,001 frames; at most "
                                         "10,000,000"):
        usd._open(path)


@pytest.mark.parametrize("fps, ok", [(1e-6, True), (1e6, True), (5e-7, False), (2e6, False),
                                     (0.0, False)])
def test_frame_rate_bounds(tmp_path, fps, ok):
    path = _stage(tmp_path / "a.usda", ["r"], _still(["r"]), fps=fps)
    if ok:
        assert usd._open(path)[4] == fps
    else:
        with pytest.raises(ParseError, match="timeCodesPerSecond .* is not a frame rate in "
                                             "1e-06..1e\\+06"):
            usd._open(path)


def test_memory_is_512_bytes_a_joint_and_frame(tmp_path):
    path = _stage(tmp_path / "a.usda", ["r", "r/a"], _still(["r", "r/a"], (0, 2)))  # 3 frames
    with memory_limit(512 * 3 * 2):
        assert usd._open(path)[3].tolist() == [0, 1, 2]
    with memory_limit(512 * 3 * 2 - 1), pytest.raises(
        ParseError, match="3 frames of 2 joints need 3.07 kB of memory, over the memory limit"
    ):
        usd._open(path)


def test_at_most_twice_max_joints(tmp_path):
    """Joints and end sites: 2 x MAX_JOINTS = 8,192 at most."""
    n = 2 * MAX_JOINTS
    names = [f"j{k}" for k in range(n + 1)]
    for count, path in ((n, tmp_path / "a.usda"), (n + 1, tmp_path / "b.usda")):
        stage = Usd.Stage.CreateInMemory()  # a skeleton of joints alone: all _open reads
        UsdSkel.Skeleton.Define(stage, "/Skel").CreateJointsAttr(Vt.TokenArray(names[:count]))
        stage.GetRootLayer().Export(str(path))
    assert len(usd._open(tmp_path / "a.usda")[2].GetJointOrder()) == n
    with pytest.raises(ParseError, match="8,193 joints; at most 8,192"):
        usd._open(tmp_path / "b.usda")


# ----------------------------------------------------------------------------- local transforms
def test_sparse_samples_interpolated_as_usd_does(tmp_path):
    """Samples at time codes 0 and 4 only: translations linear between them, rotations
    along the arc (a quarter turn about z at 4: u x 90 degrees at u = t / 4), the frames
    of the stage range 0 .. 5 after the last sample held."""
    joints = ["r", "r/a"]
    samples = {0: (np.zeros((2, 3)), [IDENTITY, IDENTITY]),
               4: ([[4, 8, 0], [0, 0, -4]], [(S, S, 0, 0), IDENTITY])}  # w x y z: about x
    path = _stage(tmp_path / "a.usda", joints, samples, end=5)
    _s, _p, query, times, _f = usd._open(path)
    trans, rots = usd._local_transforms(query, times, path)
    assert trans.shape == (6, 2, 3) and rots.shape == (6, 2, 3, 3)
    np.testing.assert_allclose(trans[:, 0], [[t, 2 * t, 0] for t in (0, 1, 2, 3, 4, 4)],
                               atol=1e-6)
    np.testing.assert_allclose(trans[:, 1, 2], [0, -1, -2, -3, -4, -4], atol=1e-6)
    for t in range(6):
        a = np.radians(90 * min(t, 4) / 4)
        rx = [[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]]
        np.testing.assert_allclose(rots[t, 0], rx, atol=1e-6)
        np.testing.assert_allclose(rots[t, 1], np.eye(3), atol=1e-6)


def test_one_time_code_between_samples(tmp_path):
    """A range of one time code (5) between samples at 0 and 10: the one frame is usd-core's
    value there, half way."""
    samples = {0: ([[0, 0, 0]], [IDENTITY]), 10: ([[10, 0, 0]], [IDENTITY])}
    path = _stage(tmp_path / "a.usda", ["r"], samples, start=5, end=5)
    _s, _p, query, times, _f = usd._open(path)
    trans, rots = usd._local_transforms(query, times, path)
    assert times.tolist() == [5] and trans.shape == (1, 1, 3) and rots.shape == (1, 1, 3, 3)
    np.testing.assert_allclose(trans[0, 0], [5, 0, 0], atol=1e-6)


def test_samples_between_time_codes_and_segments_away_from_zero(tmp_path):
    """Samples at 2, 2.5 and 4 for the range 2 .. 4: three keys for three frames, yet frame
    3 is not the sample at 2.5 but between it and 4: x = 1 + (4 - 1) (0.5 / 1.5) = 2.
    Samples at 2 and 6 for the range 2 .. 6: frame 3 is a quarter of the way, x = 1."""
    samples = {2: ([[0, 0, 0]], [IDENTITY]), 2.5: ([[1, 0, 0]], [IDENTITY]),
               4: ([[4, 0, 0]], [IDENTITY])}
    path = _stage(tmp_path / "a.usda", ["r"], samples, start=2, end=4)
    _s, _p, query, times, _f = usd._open(path)
    trans, _ = usd._local_transforms(query, times, path)
    np.testing.assert_allclose(trans[:, 0, 0], [0, 2, 4], atol=1e-6)
    samples = {2: ([[0, 0, 0]], [IDENTITY]), 6: ([[4, 0, 0]], [(0, 0, 0, 1.0)])}
    path = _stage(tmp_path / "b.usda", ["r"], samples, start=2, end=6)
    _s, _p, query, times, _f = usd._open(path)
    trans, rots = usd._local_transforms(query, times, path)
    np.testing.assert_allclose(trans[:, 0, 0], [0, 1, 2, 3, 4], atol=1e-6)
    for k in range(5):  # a half turn about z over 4 time codes: 45 degrees a code
        a = np.radians(45 * k)
        np.testing.assert_allclose(rots[k, 0], [[np.cos(a), -np.sin(a), 0],
                                                [np.sin(a), np.cos(a), 0], [0, 0, 1]],
                                   atol=1e-6)


def test_samples_at_every_frame_are_read_as_they_are(tmp_path):
    samples = {t: ([[t, 0, 0]], [(np.cos(t / 4), 0, 0, np.sin(t / 4))]) for t in range(4)}
    path = _stage(tmp_path / "a.usda", ["r"], samples)
    _s, _p, query, times, _f = usd._open(path)
    trans, rots = usd._local_transforms(query, times, path)
    assert trans[:, 0, 0].tolist() == [0, 1, 2, 3]
    for t in range(4):  # a turn of t / 2 rad about z
        c, s = np.cos(t / 2), np.sin(t / 2)
        np.testing.assert_allclose(rots[t, 0], [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-6)


def test_a_sample_after_the_range_shapes_the_last_frame_only_through_usd(tmp_path):
    """A sample at 8 with the range 0 .. 4: usd-core interpolates 0 -> 8 for the last frame
    (4: half way), the frames between are interpolated from there."""
    samples = {0: ([[0, 0, 0]], [IDENTITY]), 8: ([[8, 0, 0]], [IDENTITY])}
    path = _stage(tmp_path / "a.usda", ["r"], samples, end=4)
    _s, _p, query, times, _f = usd._open(path)
    trans, _ = usd._local_transforms(query, times, path)
    np.testing.assert_allclose(trans[:, 0, 0], [0, 1, 2, 3, 4], atol=1e-6)


@pytest.mark.parametrize("length, ok", [(1.0009, True), (0.9991, True), (1.0011, False),
                                        (0.9989, False)])
def test_rotations_unit_within_a_thousandth(tmp_path, length, ok):
    samples = {0: ([[0, 0, 0]], [(length, 0, 0, 0)]), 1: ([[0, 0, 0]], [IDENTITY])}
    path = _stage(tmp_path / "a.usda", ["r"], samples)
    _s, _p, query, times, _f = usd._open(path)
    if ok:
        _, rots = usd._local_transforms(query, times, path)
        np.testing.assert_allclose(rots, np.broadcast_to(np.eye(3), (2, 1, 3, 3)), atol=1e-6)
    else:
        with pytest.raises(ParseError, match="rotations at time code 0: joint 0 holds "
                                             r"\[0\.0, 0\.0, 0\.0, (1\.00|0\.99)"):
            usd._local_transforms(query, times, path)


@pytest.mark.parametrize(
    "scale, ok",
    [((1, 1, 1), True), ((1.0009765625, 1, 1), False), ((-1, 1, 1), False), ((-1, -1, -1), False),
     ((0.5, 0.5, 0.5), False)],
)
def test_transforms_with_a_scale_are_refused(tmp_path, scale, ok):
    """R R^T within 1e-3 of I and det R > 0: a half-float scale of 1 + 2^-10 makes
    (1 + 2^-10)^2 - 1 = 1.95e-3 (refused), a mirror a determinant of -1."""
    path = _stage(tmp_path / "a.usda", ["r", "r/a"], _still(["r", "r/a"], (0, 1)),
                  scales=[(1, 1, 1), scale])
    _s, _p, query, times, _f = usd._open(path)
    if ok:
        usd._local_transforms(query, times, path)
    else:
        with pytest.raises(ParseError, match="time code 0: joint r/a: the animation's transform "
                                             "is not a finite rotation and translation"):
            usd._local_transforms(query, times, path)


@pytest.mark.parametrize("x, ok", [(1e9, True), (-1e9, True), (2e9, False)])
def test_translations_at_most_max_magnitude(tmp_path, x, ok):
    samples = {0: ([[0, 0, 0], [0, x, 0]], [IDENTITY] * 2)}
    path = _stage(tmp_path / "a.usda", ["r", "r/a"], samples)
    _s, _p, query, times, _f = usd._open(path)
    if ok:
        assert usd._local_transforms(query, times, path)[0][0, 1, 1] == x
    else:
        with pytest.raises(ParseError, match="joint r/a: the animation's transform"):
            usd._local_transforms(query, times, path)


# ----------------------------------------------------------------------------- customData
def _skeleton_dict():
    from cyclecoord.io.gltf import skeleton_to_dict

    return skeleton_to_dict(Skeleton((
        Joint("r", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),)))


def test_custom_data_read_and_checked(tmp_path):
    base = {"skeleton": _skeleton_dict()}
    path = _stage(tmp_path / "a.usda", ["r"], _still(["r"]), custom=json.dumps(base))
    opened = usd._open(path)  # (the stage must live while its prim is read)
    info = usd._custom_data(opened[1], path)
    assert info["start_frame"] == 0 and info["channels"] == []  # the defaults
    assert info["skeleton"].names == ["r"]
    full = dict(base, start_frame=1_000_000_000, channels=[["r", "ty"], ["r", "tx"]])
    path = _stage(tmp_path / "b.usda", ["r"], _still(["r"]), custom=json.dumps(full))
    opened = usd._open(path)
    info = usd._custom_data(opened[1], path)
    assert info["start_frame"] == 1_000_000_000 and info["channels"] == [("r", "ty"), ("r", "tx")]
    path = _stage(tmp_path / "c.usda", ["r"], _still(["r"]))
    opened = usd._open(path)
    assert usd._custom_data(opened[1], path) is None
    for bad, words in (({"start_frame": -1}, r"start_frame: -1 is not in 0\.\."),
                       ({"start_frame": 1_000_000_001}, r"start_frame: 1,000,000,001 is not in"),
                       ({"channels": [["r", "tx", "x"]]}, r"channels\[0\]: 3 items; at most 2"),
                       ({"channels": [["r"]]}, r"channels\[0\]: expected \[joint, dof\]"),
                       ({"channels": [["r" * 1001, "tx"]]}, r"channels\[0\]: 1,001 characters")):
        path = _stage(tmp_path / "d.usda", ["r"], _still(["r"]), custom=json.dumps(dict(base,
                                                                                        **bad)))
        opened = usd._open(path)
        with pytest.raises(ParseError, match="customData.cyclecoord." + words):
            usd._custom_data(opened[1], path)


def test_stored_channels_in_their_order(tmp_path):
    """The stored channels (all of the skeleton's, another order) are the motion's order;
    a list that is not all of them is not used."""
    chans = [["r", c] for c in ("rz", "ry", "rx", "tz", "ty", "tx")]
    samples = {0: ([[1, 2, 3]], [IDENTITY])}
    custom = {"skeleton": _skeleton_dict(), "channels": chans, "start_frame": 7}
    path = _stage(tmp_path / "a.usda", ["r"], samples, custom=json.dumps(custom))
    m = usd.read_usd(path)
    assert m.channels == tuple(tuple(c) for c in chans) and m.start_frame == 7
    np.testing.assert_allclose(m.frames[0], [0, 0, 0, 3, 2, 1], atol=1e-6)
    custom["channels"] = chans[:3]
    path = _stage(tmp_path / "b.usda", ["r"], samples, custom=json.dumps(custom))
    assert usd.read_usd(path).channels[0] == ("r", "tx")


def test_stored_skeleton_with_more_joints_than_the_stage(tmp_path):
    from cyclecoord.io.gltf import skeleton_to_dict

    two = Skeleton((Joint("r", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
                    Joint("a", 0, [0, 1, 0], ("rx",), "X")))
    custom = json.dumps({"skeleton": skeleton_to_dict(two)})
    path = _stage(tmp_path / "a.usda", ["r"], _still(["r"]), custom=custom)
    with pytest.raises(ParseError, match="customData.cyclecoord.skeleton has 2 joints, the "
                                         "stage's skeleton 1"):
        usd.read_usd(path)
    path = _stage(tmp_path / "b.usda", ["r", "r/a"], _still(["r", "r/a"]), custom=custom)
    assert usd.read_usd(path).skeleton.names == ["r", "a"]


# ----------------------------------------------------------------------------- a stage from elsewhere
def test_foreign_stage_one_joint_a_usd_joint(tmp_path):
    """No customData: tx ty tz only on roots, the root named by its path and the others by
    their last path component, rest offsets the first frame's translations, ZYX degrees,
    start frame 0, the stage's rate."""
    joints = ["hips", "hips/spine", "hips/spine/head"]
    samples = {0: ([[0, 1, 0], [0, 0.5, 0], [0, 0.25, 0]], [IDENTITY, (S, S, 0, 0), IDENTITY]),
               1: ([[2, 1, 0], [0, 0.5, 0], [0, 0.25, 0]], [IDENTITY, IDENTITY, IDENTITY])}
    path = _stage(tmp_path / "walk.usda", joints, samples, fps=50)
    m = usd.read_usd(path)
    skel = m.skeleton
    assert skel.names == ["hips", "spine", "head"] and skel.name == "walk"
    assert skel.source_format == "usd" and [j.parent for j in skel.joints] == [-1, 0, 1]
    move, turn = ("tx", "ty", "tz", "rx", "ry", "rz"), ("rx", "ry", "rz")
    assert [j.dofs for j in skel.joints] == [move, turn, turn]
    assert all(j.rotation_order == "ZYX" for j in skel.joints)
    np.testing.assert_allclose([j.offset for j in skel.joints], [[0, 1, 0], [0, 0.5, 0],
                                                                 [0, 0.25, 0]], atol=1e-7)
    assert m.fps == 50 and m.n_frames == 2 and m.start_frame == 0
    assert m.frames[:, m.channels.index(("hips", "tx"))].tolist() == pytest.approx([0, 2])
    assert m.frames[:, m.channels.index(("spine", "rx"))].tolist() == pytest.approx([90, 0])


def test_why_strips_the_cpp_location():
    exc = RuntimeError("Error in 'pxrInternal_v0_24::Crate::_Read' at line 3472 in file "
                       "/src/crateFile.cpp : 'bad\n  magic'")
    assert usd._why(exc) == "bad magic"
    long = RuntimeError("x" * 301)
    assert usd._why(long) == "x" * 297 + "..."
    assert usd._why(RuntimeError("y" * 300)) == "y" * 300


# ----------------------------------------------------------------------------- write_usd
def _arm(T=3):
    """Root (6 dofs) and an arm 2 up (rz) with an end site 1 along x; the root moves 1 a
    frame along x, the arm turns 0, 45, 90 degrees about z."""
    from cyclecoord.motion import Motion

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
                   Joint("arm", 0, [0, 2, 0], ("rz",), "Z", end_site=[1, 0, 0])), name="arm")
    frames = np.zeros((T, 7))
    frames[:, 0] = np.arange(T)
    frames[:, 6] = 45.0 * np.arange(T)
    return Motion(frames, sk.channels, fps=12.0, skeleton=sk, start_frame=4, source="s.bvh")


def test_write_usd_stage(tmp_path):
    from pxr import UsdGeom

    m = _arm()
    usd.write_usd(m, tmp_path / "a.USDA", meters_per_unit=0.01)  # the suffix in any case
    stage = Usd.Stage.Open(str(tmp_path / "a.USDA"))
    assert UsdGeom.GetStageMetersPerUnit(stage) == 0.01
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
    assert stage.GetTimeCodesPerSecond() == 12.0 and stage.GetFramesPerSecond() == 12.0
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (0, 2)
    assert str(stage.GetDefaultPrim().GetPath()) == "/Motion"
    skel = UsdSkel.Skeleton(stage.GetPrimAtPath("/Motion/Skeleton"))
    assert list(skel.GetJointsAttr().Get()) == ["root", "root/arm", "root/arm/arm_end"]
    assert list(skel.GetJointNamesAttr().Get()) == ["root", "arm", "arm/end"]
    rest = np.array(skel.GetRestTransformsAttr().Get())
    bind = np.array(skel.GetBindTransformsAttr().Get())
    assert rest[:, 3, :3].tolist() == [[0, 0, 0], [0, 2, 0], [1, 0, 0]]  # row-vector: last row
    assert bind[:, 3, :3].tolist() == [[0, 0, 0], [0, 2, 0], [1, 2, 0]]  # world rest pose
    assert (rest[:, :3, :3] == np.eye(3)).all() and (bind[:, :3, :3] == np.eye(3)).all()
    info = json.loads(skel.GetPrim().GetCustomDataByKey("cyclecoord"))
    assert info["fps"] == 12.0 and info["start_frame"] == 4 and info["source"] == "s.bvh"
    assert info["channels"] == [list(c) for c in m.channels]
    anim = UsdSkel.Animation(stage.GetPrimAtPath("/Motion/Skeleton/Animation"))
    assert list(anim.GetJointsAttr().Get()) == ["root", "root/arm", "root/arm/arm_end"]
    assert [tuple(s) for s in anim.GetScalesAttr().Get()] == [(1, 1, 1)] * 3
    for t in range(3):
        tr = np.array(anim.GetTranslationsAttr().Get(Usd.TimeCode(t)))
        assert tr.tolist() == [[t, 0, 0], [0, 2, 0], [1, 0, 0]]
        q = anim.GetRotationsAttr().Get(Usd.TimeCode(t))
        a = np.radians(45 * t) / 2  # the arm's turn about z: (cos a, 0, 0, sin a) as w x y z
        assert q[1].GetReal() == pytest.approx(np.cos(a), abs=1e-7)
        assert list(q[1].GetImaginary()) == pytest.approx([0, 0, np.sin(a)], abs=1e-7)
        assert q[0].GetReal() == 1 and q[2].GetReal() == 1
    targets = UsdSkel.BindingAPI(skel.GetPrim()).GetAnimationSourceRel().GetTargets()
    assert [str(t) for t in targets] == ["/Motion/Skeleton/Animation"]
    back = usd.read_usd(tmp_path / "a.USDA")
    assert back.channels == m.channels and back.start_frame == 4
    np.testing.assert_allclose(back.frames, m.frames, atol=1e-4)


def test_write_usd_refusals(tmp_path):
    m = _arm()
    with pytest.raises(ParameterError, match=r"USD files end in \.usda, \.usdc, \.usd, got "
                                             r"'\.txt'"):
        usd.write_usd(m, tmp_path / "a.txt")
    with pytest.raises(ParameterError, match=r"got '\(no suffix\)'"):
        usd.write_usd(m, tmp_path / "a")
    for bad in (0.0, -1.0, np.nan, np.inf):
        with pytest.raises(ParameterError, match="meters_per_unit must be a positive number"):
            usd.write_usd(m, tmp_path / "a.usda", meters_per_unit=bad)
    assert list(tmp_path.iterdir()) == []
    usd.write_usd(m, tmp_path / "b.usdc", meters_per_unit=1e-9)
    assert usd.read_usd(tmp_path / "b.usdc").n_frames == 3


def test_joint_positions_by_usd_core(tmp_path):
    """Skeleton-space positions: the root at (1, 0, 0) turned a quarter about z carries its
    child's (0, 2, 0) to (1, 0, 0) + (-2, 0, 0); names are the joint paths when the stage
    has no jointNames, and jointNames when it has them."""
    samples = {0: ([[1, 0, 0], [0, 2, 0]], [(S, 0, 0, S), IDENTITY]),
               1: ([[1, 0, 3], [0, 2, 0]], [(S, 0, 0, S), IDENTITY])}
    path = _stage(tmp_path / "a.usda", ["r", "r/a"], samples, fps=5)
    names, pos, fps = usd.usd_joint_positions(path)
    assert names == ["r", "r/a"] and fps == 5.0
    np.testing.assert_allclose(pos, [[[1, 0, 0], [-1, 0, 0]], [[1, 0, 3], [-1, 0, 3]]],
                               atol=1e-6)
    stage = Usd.Stage.Open(str(path))
    UsdSkel.Skeleton(stage.GetPrimAtPath("/R/Skel")).CreateJointNamesAttr(
        Vt.TokenArray(["root", "arm"]))
    stage.GetRootLayer().Save()
    assert usd.usd_joint_positions(path)[0] == ["root", "arm"]


def test_standard_error_is_given_back_after_a_read(capfd):
    """While a USD reader runs, file descriptor 2 is held; afterwards it is the process's
    standard error again (what is written there is seen)."""
    import os

    from cyclecoord.io.usd import _refusing

    capfd.readouterr()
    assert _refusing(lambda path: 7)("f.usda") == 7
    os.write(2, b"after the read\n")
    with pytest.raises(ParseError):
        _refusing(lambda path: (_ for _ in ()).throw(ParseError("bad", "f.usda")))("f.usda")
    os.write(2, b"after the refusal\n")
    assert capfd.readouterr().err == "after the read\nafter the refusal\n"


def test_open_refuses_a_missing_file_and_a_stage_without_a_skeleton(tmp_path):
    with pytest.raises(ParseError, match="no such USD file"):
        usd._open(tmp_path / "none.usda")
    stage = Usd.Stage.CreateInMemory()
    UsdSkel.Root.Define(stage, "/R")
    stage.GetRootLayer().Export(str(tmp_path / "empty.usda"))
    with pytest.raises(ParseError, match="no UsdSkel Skeleton prim in the stage"):
        usd._open(tmp_path / "empty.usda")
    stage = Usd.Stage.CreateInMemory()
    UsdSkel.Skeleton.Define(stage, "/Skel").CreateJointsAttr(Vt.TokenArray([]))
    stage.GetRootLayer().Export(str(tmp_path / "nojoints.usda"))
    with pytest.raises(ParseError, match="skeleton /Skel: the joints array is empty"):
        usd._open(tmp_path / "nojoints.usda")
