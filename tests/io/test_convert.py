"""Tests for converting between conventions and formats (retarget, io.load/save/convert)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io import convert, default_asf_path, load, save
from cyclecoord.motion import Motion
from cyclecoord.conventions import continuous_euler, to_bvh_convention
from cyclecoord.skeleton import Joint, Skeleton, forward_kinematics
from _skips import data_reason

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data"
CMU69 = DATA / "cmu" / "69"


def _axis(*deg: float) -> np.ndarray:
    return Rotation.from_euler("XYZ", deg, degrees=True).as_matrix()


def asf_like_skeleton() -> Skeleton:
    """ASF conventions: non-identity axes; 3-, 1-, 2- and 0-dof joints; reversed orders."""
    joints = (
        Joint("root", -1, [0.3, 0.2, -0.1], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX",
              _axis(5, -10, 15)),
        Joint("lfemur", 0, [1.0, -1.0, 0.5], ("rx", "ry", "rz"), "ZYX", _axis(0, 0, 20)),
        Joint("ltibia", 1, [2.5, -6.9, 0.0], ("rx",), "X", _axis(0, 0, 20)),
        Joint("lfoot", 2, [2.6, -7.1, 0.0], ("rx", "rz"), "ZX", _axis(-90, 0, 20),
              end_site=[0.1, -0.4, 2.0]),
        Joint("lowerback", 0, [0.0, 2.0, -0.1], ("ry", "rz", "rx"), "XZY", _axis(30, 40, 50)),
        Joint("neck", 4, [0.0, 5.0, 0.2], (), "", _axis(12, 0, -7)),
        Joint("head", 5, [0.0, 1.5, 0.3], ("ry", "rx"), "XY", _axis(0, 90, 0),
              end_site=[0.0, 2.0, 0.0]),
        Joint("lclavicle", 5, [1.0, 0.0, 0.0], ("tx", "rz"), "Z", np.eye(3),
              end_site=[3.0, 0.0, 0.0]),
    )
    return Skeleton(joints, name="synthetic-asf", source_format="asf")


def asf_like_motion(seed: int = 0, T: int = 40) -> Motion:
    sk = asf_like_skeleton()
    rng = np.random.default_rng(seed)
    frames = rng.uniform(-179, 179, size=(T, len(sk.channels)))
    return Motion(frames=frames, channels=sk.channels, skeleton=sk, fps=60, start_frame=7,
                  source="synthetic:asf", metadata={"note": "x"})


# ----------------------------------------------------------------- to_bvh_convention
@pytest.mark.parametrize("order", ["ZXY", "ZYX", "XYZ", "XZY", "YXZ", "YZX"])
def test_to_bvh_convention_preserves_positions(order):
    m = asf_like_motion(seed=3)
    b = to_bvh_convention(m, rotation_order=order)
    size = m.skeleton.total_length()
    pa, pb = forward_kinematics(m), forward_kinematics(b)
    assert pb.names == pa.names
    err = np.abs(pb.positions - pa.positions).max()
    assert err <= 1e-9 * size, err
    # the local rotations agree too, not just positions (0-dof and leaf joints included)
    from cyclecoord.conventions import local_rotations

    np.testing.assert_allclose(local_rotations(b), local_rotations(m), atol=1e-12)


def test_to_bvh_convention_structure():
    m = asf_like_motion()
    b = to_bvh_convention(m)
    sk = b.skeleton
    assert sk.source_format == "bvh" and sk.name == m.skeleton.name
    assert sk.names == m.skeleton.names
    for old, new in zip(m.skeleton.joints, sk.joints):
        np.testing.assert_array_equal(new.axis, np.eye(3))
        np.testing.assert_array_equal(new.offset, old.offset)
        assert new.parent == old.parent
        assert new.rotation_order == "ZXY"
        if old.end_site is None:
            assert new.end_site is None
        else:
            np.testing.assert_array_equal(new.end_site, old.end_site)
    assert sk["root"].dofs == ("tx", "ty", "tz", "rz", "rx", "ry")
    assert sk["lfemur"].dofs == ("rz", "rx", "ry")
    assert sk["neck"].dofs == ("rz", "rx", "ry")
    assert sk["lclavicle"].dofs == ("tx", "rz", "rx", "ry")  # keeps its translation dof
    assert b.channels == sk.channels
    assert (b.fps, b.start_frame, b.source, b.metadata) == (60.0, 7, "synthetic:asf", {"note": "x"})
    # translations are copied, zero-dof joints get zero angles
    np.testing.assert_array_equal(b.select(["root.tx", "root.ty", "root.tz"]).frames,
                                  m.select(["root.tx", "root.ty", "root.tz"]).frames)
    np.testing.assert_allclose(b.select(["neck"]).frames, 0.0, atol=1e-12)


def test_to_bvh_convention_fills_missing_root_translation():
    sk = Skeleton((Joint("r", -1, [1, 2, 3], ("rx",), "X", _axis(0, 30, 0)),
                   Joint("c", 0, [0, 1, 0], (), "", end_site=[0, 1, 0])), source_format="asf")
    m = Motion(np.array([[10.0], [20.0]]), sk.channels, skeleton=sk)
    b = to_bvh_convention(m)
    np.testing.assert_array_equal(b.select(["r.tx", "r.ty", "r.tz"]).frames, [[1, 2, 3]] * 2)
    np.testing.assert_allclose(b.positions().positions, m.positions().positions, atol=1e-12)


def test_euler_angles_stay_continuous():
    # one X hinge swinging 0 -> 170 degrees and back: in ZXY, X is the middle angle,
    # whose principal range is [-90, 90]; the curve must keep going instead of flipping
    theta = np.concatenate([np.linspace(0, 170, 60), np.linspace(170, -30, 60)])
    # and a root spinning two full turns about its vertical axis
    yaw = np.linspace(0, 720, 120)
    sk = Skeleton((
        Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "ry"), "Y"),
        Joint("hinge", 0, [0, 1, 0], ("rx",), "X", end_site=[0, 1, 0]),
    ), source_format="asf")
    frames = np.column_stack([np.zeros((120, 3)), yaw, theta])
    m = Motion(frames, sk.channels, skeleton=sk)
    b = to_bvh_convention(m, "ZXY")
    np.testing.assert_allclose(b.select(["hinge.rx"]).frames[:, 0], theta, atol=1e-9)
    np.testing.assert_allclose(b.select(["hinge.rz", "hinge.ry"]).frames, 0.0, atol=1e-9)
    np.testing.assert_allclose(b.select(["root.ry"]).frames[:, 0], yaw, atol=1e-9)
    assert np.abs(np.diff(b.frames, axis=0)).max() < 7.0
    np.testing.assert_allclose(b.positions().positions, m.positions().positions, atol=1e-9)


def test_continuous_euler_matches_scipy_up_to_equivalence():
    rng = np.random.default_rng(5)
    mats = Rotation.random(50, random_state=rng).as_matrix().reshape(25, 2, 3, 3)
    ang = continuous_euler(mats, "YXZ")
    back = Rotation.from_euler("YXZ", ang.reshape(-1, 3), degrees=True).as_matrix()
    np.testing.assert_allclose(back.reshape(mats.shape), mats, atol=1e-12)
    np.testing.assert_allclose(ang[0], Rotation.from_matrix(mats[0]).as_euler("YXZ", degrees=True))


def test_continuous_euler_near_picks_the_first_frames_solution():
    rng = np.random.default_rng(6)
    rv = np.cumsum(rng.normal(scale=0.2, size=(40, 3)), axis=0)
    mats = Rotation.from_rotvec(rv).as_matrix()[:, None]
    plain = continuous_euler(mats, "ZXY")
    # the other Tait-Bryan solution of frame 0, one whole turn up on the first angle
    other = plain[0, 0] + np.array([540.0, 0.0, 180.0])
    other[1] = 180.0 - plain[0, 0, 1]
    near = continuous_euler(mats, "ZXY", near=other + 10.0)
    np.testing.assert_allclose(near[0, 0], other, atol=1e-9)
    back = Rotation.from_euler("ZXY", near[:, 0], degrees=True).as_matrix()
    np.testing.assert_allclose(back, mats[:, 0], atol=1e-12)
    assert np.abs(np.diff(near[:, 0], axis=0)).max() < 60.0
    # near the principal solution: the same angles as without near
    np.testing.assert_array_equal(continuous_euler(mats, "ZXY", near=plain[0]), plain)


def test_to_bvh_convention_bad_input():
    m = asf_like_motion()
    with pytest.raises(ParameterError, match="permutation of XYZ"):
        to_bvh_convention(m, "ZXZ")
    with pytest.raises(ParameterError, match="skeleton"):
        to_bvh_convention(Motion(m.frames, m.channels))
    empty = to_bvh_convention(m[0:0])
    assert empty.frames.shape == (0, len(empty.skeleton.channels))


# ------------------------------------------------------------------ load/save dispatch
def test_load_unknown_suffix_and_missing_file(tmp_path):
    p = tmp_path / "motion.fbx"
    p.write_text("x")
    with pytest.raises(ParseError, match=r"unknown motion format.*\.amc, \.bvh, \.npz, \.csv") as e:
        load(p)
    assert e.value.path == str(p)
    with pytest.raises(ParseError, match="no such file") as e:
        load(tmp_path / "nothing.bvh")
    assert e.value.path == str(tmp_path / "nothing.bvh")
    with pytest.raises(ParseError, match="unknown motion format"):
        save(asf_like_motion(), tmp_path / "out.txt")


def test_save_load_bvh_npz_csv(tmp_path):
    m = asf_like_motion(seed=1)
    save(m, tmp_path / "m.bvh")
    b = load(tmp_path / "m.bvh")
    np.testing.assert_allclose(b.positions().positions, m.positions().positions, atol=1e-6)
    assert load(tmp_path / "m.bvh", fps=30).fps == 30.0
    with pytest.raises(ParameterError, match="own skeleton"):
        load(tmp_path / "m.bvh", skeleton=m.skeleton)
    with pytest.raises(ParameterError, match="unknown option"):
        save(m, tmp_path / "m.csv", rotation_order="ZXY")
    save(b, tmp_path / "m.npz")
    n = load(tmp_path / "m.NPZ".lower())
    np.testing.assert_array_equal(n.frames, b.frames)
    c = convert(tmp_path / "m.npz", tmp_path / "m.csv", fps=24)
    assert c.fps == 24.0
    back = load(tmp_path / "m.csv")
    assert back.fps == 24.0 and back.channels == b.channels
    np.testing.assert_array_equal(back.frames, b.frames)
    with pytest.raises(ParameterError, match="overwrite its input"):
        convert(tmp_path / "m.csv", tmp_path / "m.csv")


def test_default_asf_path():
    assert default_asf_path("dir/out.amc") == Path("dir/out.asf")
    assert default_asf_path("dir/69_01.amc") == Path("dir/69.asf")


needs_data = pytest.mark.skipif(
    not (CMU69 / "69_01.amc").is_file(), reason=data_reason(CMU69 / "69_01.amc")
)


def _compare_fk(a: Motion, b: Motion, tol: float, same_points: bool = True) -> float:
    pa, pb = forward_kinematics(a), forward_kinematics(b)
    if same_points:
        assert sorted(pa.names) == sorted(pb.names)
    common = [n for n in pa.names if n in pb.names]
    assert len(common) >= len(pa.names) if same_points else len(common) > 0
    ia = [pa.names.index(n) for n in common]
    ib = [pb.names.index(n) for n in common]
    err = float(np.abs(pa.positions[:, ia] - pb.positions[:, ib]).max())
    assert err <= tol, err
    return err


def test_save_amc_writes_asf_beside(tmp_path):
    m = asf_like_motion(seed=2, T=10)
    save(m, tmp_path / "out.amc")
    assert (tmp_path / "out.asf").is_file()
    back = load(tmp_path / "out.amc")
    _compare_fk(m, back, 1e-9 * m.skeleton.total_length(), same_points=False)
    # a second save of the same motion reuses the ASF; a different skeleton refuses to
    # overwrite it unless asf_path is given
    before = (tmp_path / "out.asf").read_bytes()
    save(m, tmp_path / "out_2.amc")
    assert (tmp_path / "out.asf").read_bytes() == before
    other = to_bvh_convention(m)
    with pytest.raises(ParameterError, match="already exists"):
        save(other, tmp_path / "out_3.amc")
    assert (tmp_path / "out.asf").read_bytes() == before
    save(other, tmp_path / "out_3.amc", asf_path=tmp_path / "other.asf")
    back3 = load(tmp_path / "out_3.amc", skeleton=tmp_path / "other.asf")
    _compare_fk(other, back3, 1e-6 * m.skeleton.total_length(), same_points=False)


@needs_data
def test_cmu_amc_to_bvh_and_back(tmp_path):
    amc = load(CMU69 / "69_01.amc")
    assert amc.n_frames == 469 and amc.fps == 120.0
    convert(CMU69 / "69_01.amc", tmp_path / "69_01.bvh")
    bvh = load(tmp_path / "69_01.bvh")
    assert bvh.n_frames == 469 and bvh.fps == 120.0
    assert all(j.rotation_order == "ZXY" for j in bvh.skeleton.joints)
    # same points (every joint and every end site), positions within 1e-3 length units
    _compare_fk(amc, bvh, 1e-3)
    # and on to AMC again: the BVH skeleton is written as ASF (with helper bones for
    # joints whose children sit at different offsets); the original points must match
    convert(tmp_path / "69_01.bvh", tmp_path / "69_01.amc")
    assert (tmp_path / "69.asf").is_file()
    again = load(tmp_path / "69_01.amc")
    assert again.n_frames == 469
    _compare_fk(amc, again, 1e-3, same_points=False)
    missing = set(forward_kinematics(amc).names) - set(forward_kinematics(again).names)
    assert not missing


@needs_data
def test_amc_to_amc_keeps_source_skeleton(tmp_path):
    shutil.copy(CMU69 / "69.asf", tmp_path / "69.asf")
    shutil.copy(CMU69 / "69_01.amc", tmp_path / "69_01.amc")
    before = (tmp_path / "69.asf").read_bytes()
    m = convert(tmp_path / "69_01.amc", tmp_path / "69_02.amc")
    assert (tmp_path / "69.asf").read_bytes() == before  # inputs are never modified
    again = load(tmp_path / "69_02.amc")
    np.testing.assert_allclose(again.select(m.channels).frames, m.frames, atol=1e-9)


@pytest.mark.parametrize("seed", range(6))
def test_continuous_euler_walks_few_joints_in_python_floats_with_the_same_choices(seed):
    """One or two joints go through the plain-float frame loop: the same angles, to the
    bit, as the vectorised loop, on slow and on tumbling rotations."""
    import cyclecoord.conventions as conv

    rng = np.random.default_rng(seed)
    T, J = 150, 1 + seed % 2
    rotvec = np.cumsum(rng.normal(size=(T, J, 3)) * [0.05, 0.3, 1.0][seed % 3], axis=0)
    mats = Rotation.from_rotvec(rotvec.reshape(-1, 3)).as_matrix().reshape(T, J, 3, 3)
    order = "".join(rng.permutation(list("XYZ")))
    near = rng.normal(size=(J, 3)) * 200.0 if seed % 2 else None
    fast = conv.continuous_euler(mats, order, near)
    try:
        conv._SCALAR_JOINTS, kept = 0, conv._SCALAR_JOINTS
        slow = conv.continuous_euler(mats, order, near)
    finally:
        conv._SCALAR_JOINTS = kept
    np.testing.assert_array_equal(fast, slow)
    if seed % 3 == 0:  # small steps: no flip between frames
        assert np.abs(np.diff(fast, axis=0)).max() < 30.0
