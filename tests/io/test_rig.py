"""Rig conventions: found on real and synthetic rigs, normalised for the analysis and restored."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cyclecoord.errors import ParameterError
from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton
from cyclecoord.rig import (
    CMU_UNIT,
    UNITS,
    Z_TO_Y,
    describe_rig,
    metres_per_unit,
    normalize_rig,
    parse_units,
    rig_summary,
)
from cyclecoord.conventions import to_bvh_convention
from _rigs import (  # tests/ is on the path (rootdir conftest)
    BVH,
    XSENS,
    bandai,
    in_units,
    shared,
    static_root,
    turn_root,
    walk,
    z_up,
)

def _check_round_trip(m: Motion) -> None:
    analysis, adapter = normalize_rig(m)
    back = adapter.restore(analysis)
    assert back.channels == m.channels and back.skeleton is m.skeleton
    want = m.positions().positions[adapter.dropped_frames :]
    got = back.positions().positions
    size = float(np.ptp(want.reshape(-1, 3), axis=0).max())
    assert np.abs(got - want).max() <= 1e-6 * size


# ------------------------------------------------------------------------ finding
@pytest.mark.parametrize("k", range(5))
def test_bandai_rig_found(k):
    m = bandai(k)
    info = describe_rig(m)
    assert info.style == "Bandai-style" and info.static_root
    assert info.root == "joint_Root" and info.travelling_joint == "Hips"
    assert info.n_joints == 22 and info.position_channels_everywhere
    assert len(info.constant_position_joints) == 20 and "Hips" not in info.constant_position_joints
    assert (info.units, info.units_source, info.metres_per_unit) == ("cm", "measured", 0.01)
    assert info.up_axis == "Y" and info.fps == 30 and not info.reference_frame
    # the nodes end at the head joint (zero end site): about 1.33 m for a ~1.6 m performer
    assert 1.2 < info.height_m < 1.5
    assert info.summary().startswith(
        "Bandai-style rig: static root joint_Root, Hips travels, 22 joints with 6 channels "
        "(positions constant below Hips), cm ("
    )
    assert info.summary().endswith("m tall), Y-up, 30 fps")


def test_xsens_rig_found():
    m = shared(XSENS)
    info = describe_rig(m)
    assert not info.static_root and info.travelling_joint == "Hips"
    assert info.channel_counts[0] == 6 and set(info.channel_counts[1:]) == {3}
    assert (info.units, info.metres_per_unit) == ("mm", 0.001)
    assert 1.6 < info.height_m < 1.9
    assert info.up_axis == "Y" and info.fps == 100
    assert info.reference_frame and info.first_step_ratio > 100
    assert "frame 0 a reference pose" in info.summary()
    d = info.to_dict()
    assert d["reference_frame"] is True and d["units"] == "mm" and d["summary"] == info.summary()


def test_the_head_over_the_feet_names_the_up_axis():
    """``_head_over_feet``: Y on the Xsens performer's stand (also turned a quarter turn,
    facing along x: 1,740 mm tall, some 890 deep), Z on the synthetic walk on a Z-up rig,
    None on a skeleton that names no head.  (A latent model's Xsens stand read under
    twice as tall as deep and had the head and both hands at its back: the chain-end
    count took Z and every quality figure read the feet 6 cm under the floor.)"""
    import cyclecoord.rig.describe as describe

    m = shared(XSENS)[1:300]
    f = m.frames.copy()
    col = {c: i for i, c in enumerate(m.channels)}
    x, z = f[:, col[("Hips", "tx")]].copy(), f[:, col[("Hips", "tz")]].copy()
    f[:, col[("Hips", "tx")]], f[:, col[("Hips", "tz")]] = z, -x
    f[:, col[("Hips", "ry")]] += 90.0  # (YXZ: the first rotation, about the world's y)
    turned = m.with_frames(f)
    every = np.arange(0, 299, 7)
    assert describe._head_over_feet(m, every) == "Y"
    assert describe._head_over_feet(turned, every) == "Y"
    info = describe_rig(turned)
    assert info.extents[1] < 2.0 * info.extents[2] and info.up_axis == "Y"
    up = z_up()
    assert describe._head_over_feet(up, np.arange(up.n_frames)) == "Z"
    joints = [Joint(f"j{k}", k - 1, [0.0, 10.0 * (k > 0), 0.0], ("rx", "ry", "rz"), "XYZ")
              for k in range(4)]
    plain = Motion(np.zeros((3, 12)), Skeleton(tuple(joints)).channels,
                   skeleton=Skeleton(tuple(joints)))
    assert describe._head_over_feet(plain, np.arange(3)) is None


def test_cmu_rig_found(walk_69_01):
    info = describe_rig(walk_69_01)
    assert info.style == "ASF" and info.units == "asf" and info.units_source == "skeleton"
    assert info.metres_per_unit == pytest.approx(0.0254 / 0.45)
    assert info.up_axis == "Y" and info.fps == 120 and not info.reference_frame
    assert not info.static_root and info.travelling_joint == "root"
    assert 1.5 < info.height_m < 1.8
    assert rig_summary(walk_69_01).startswith(
        "ASF rig: root travels, 31 joints, ASF units of 1/0.45 in ("
    )


@pytest.mark.parametrize("unit", ["m", "cm", "mm", "in"])
def test_units_from_height(unit):
    m = in_units(walk(), UNITS[unit])
    info = describe_rig(m)
    assert info.units == unit and info.units_source == "measured"
    assert info.height_m == pytest.approx(describe_rig(walk()).height_m, rel=1e-9)
    assert metres_per_unit(m) == UNITS[unit]


def test_cmu_unit_guessed_on_a_bvh_without_length_unit():
    info = describe_rig(in_units(walk(), CMU_UNIT))
    assert info.units == "cmu" and info.metres_per_unit == pytest.approx(CMU_UNIT)


def test_units_given():
    m = in_units(walk(), 0.01)
    info = describe_rig(m, "in")
    assert (info.units, info.units_source, info.metres_per_unit) == ("in", "given", 0.0254)
    assert "in as given" in info.summary()
    assert describe_rig(m, 0.5).units == "custom"
    assert parse_units("0.0254") == 0.0254 and parse_units("auto") is None
    with pytest.raises(ParameterError, match="units"):
        parse_units("furlong")
    with pytest.raises(ParameterError, match="positive"):
        parse_units(-1.0)


def test_z_up_found():
    info = describe_rig(z_up())
    assert info.up_axis == "Z" and info.units == "cm"


def test_no_skeleton():
    m = Motion(np.zeros((5, 2)), [("a", "x"), ("b", "y")], fps=60)
    assert rig_summary(m).startswith("no skeleton: 2 channels, 60 fps")
    with pytest.raises(ParameterError, match="skeleton"):
        describe_rig(m)


# ---------------------------------------------------------------- normalising
def test_bandai_analysis_motion():
    m = bandai(0)
    analysis, adapter = normalize_rig(m)
    skel = analysis.skeleton
    assert skel.names[0] == "Hips" and "joint_Root" not in skel.names
    assert skel.joints[0].dofs == ("tx", "ty", "tz", "rz", "rx", "ry")
    assert all(j.dofs == ("rz", "rx", "ry") for j in skel.joints[1:])
    assert analysis.n_channels == 6 + 3 * 20 and analysis.n_frames == m.n_frames
    want = m.positions().positions[:, 1:]  # the static root's point is gone
    assert np.abs(analysis.positions().positions - want).max() < 1e-9
    # the root's rotation is unchanged: its channels are the capture's own
    for d in ("rz", "rx", "ry"):
        assert np.array_equal(
            analysis.frames[:, analysis.channel_index("Hips", d)],
            m.frames[:, m.channel_index("Hips", d)],
        )
    assert adapter.folded_root and not adapter.rotates_root
    assert describe_rig(analysis).summary().startswith("BVH rig: Hips travels, 21 joints")


def test_xsens_reference_frame_dropped():
    m = shared(XSENS)
    analysis, adapter = normalize_rig(m)
    assert adapter.dropped_frames == 1 and analysis.n_frames == m.n_frames - 1
    assert analysis.start_frame == m.start_frame + 1
    assert analysis.channels == m.channels
    assert not describe_rig(analysis).reference_frame


def test_cmu_unchanged(walk_69_01):
    analysis, adapter = normalize_rig(walk_69_01)
    assert analysis is walk_69_01 and adapter.identity and adapter.changes() == []
    assert adapter.restore(analysis) is walk_69_01


def test_z_up_turned_y_up_and_continuous():
    m = z_up()
    analysis, adapter = normalize_rig(m)
    assert adapter.changes() == ["turned Z-up to Y-up"]
    want = m.positions().positions @ Z_TO_Y.T
    size = float(np.ptp(want[..., 1]))
    assert np.abs(analysis.positions().positions - want).max() < 1e-9 * size
    assert describe_rig(analysis).up_axis == "Y"
    root = [analysis.channel_index("root", d) for d in ("rz", "rx", "ry")]
    assert np.abs(np.diff(analysis.frames[:, root], axis=0)).max() < 10.0


def test_root_turning_round_stays_continuous():
    """A root turning twice round on a Z-up rig: its Euler channels never jump."""
    m = in_units(walk(), 0.01)
    frames = np.array(m.frames)
    frames[:, m.channel_index("root", "ry")] = np.linspace(0, 720, m.n_frames)
    m = turn_root(m.with_frames(frames), Z_TO_Y.T)
    analysis, adapter = normalize_rig(m)
    root = [analysis.channel_index("root", d) for d in ("rz", "rx", "ry")]
    assert np.abs(np.diff(analysis.frames[:, root], axis=0)).max() < 10.0
    # written back on the capture's own branch (near gimbal lock there: rx about 90)
    back = adapter.restore(analysis)
    assert np.abs(back.frames - m.frames).max() < 1e-9


def test_static_root_with_rotation_folded():
    """A static root turned +90 about x (a Z-up world) and shifted: folded, then turned Y-up."""
    w = in_units(walk(), 0.01)
    m = static_root(w, Z_TO_Y.T, (12.0, -3.0, 4.0), positions_everywhere=True)
    info = describe_rig(m)
    assert info.static_root and info.travelling_joint == "root" and info.up_axis == "Z"
    assert info.style == "Bandai-style"
    analysis, adapter = normalize_rig(m)
    assert analysis.skeleton.names == w.skeleton.names
    assert set(analysis.channels) == set(w.channels)
    # analysis world = Z_TO_Y (t0 + R0 p) with R0 = Z_TO_Y.T: the walk shifted
    shift = Z_TO_Y @ np.array([12.0, -3.0, 4.0])
    want = w.positions().positions + shift
    assert np.abs(analysis.positions().positions - want).max() < 1e-9 * info.height


@pytest.mark.parametrize(
    "build",
    [
        pytest.param(lambda: bandai(0), id="bandai-walk"),
        pytest.param(lambda: bandai(3), id="bandai-turn"),
        pytest.param(lambda: shared(XSENS), id="xsens"),
        pytest.param(lambda: shared(BVH.parent / "cmu" / "69" / "69_01.amc"), id="cmu-69_01"),
        pytest.param(z_up, id="synthetic-z-up"),
        pytest.param(
            lambda: static_root(in_units(walk(), 0.01), np.eye(3), (0, 0, 0), True),
            id="synthetic-static-root",
        ),
        pytest.param(
            lambda: static_root(
                in_units(walk(), 0.001), Z_TO_Y.T, (120.0, -30.0, 40.0), True
            ),
            id="synthetic-static-root-turned",
        ),
        pytest.param(
            lambda: static_root(
                z_up(), Rotation.from_euler("ZXY", [30, 10, -20], degrees=True).as_matrix(),
                (5.0, 1.0, 2.0), False,
            ),
            id="synthetic-static-root-tilted-z-up",
        ),
    ],
)
def test_restore_gives_back_the_capture(build):
    _check_round_trip(build())


def test_restore_a_clip_of_the_analysis_motion():
    m = static_root(in_units(walk(), 0.001), Z_TO_Y.T, (120.0, -30.0, 40.0), True)
    analysis, adapter = normalize_rig(m)
    back = adapter.restore(analysis[20:70])
    assert back.n_frames == 50 and back.start_frame == 20
    want = m.positions().positions[20:70]
    assert np.abs(back.positions().positions - want).max() < 1e-6 * describe_rig(m).height
    # the static root's channels are re-added with their constant values
    assert np.allclose(back.frames[:, back.channel_index("joint_Root", "tx")], 120.0)


def test_restore_refuses_other_channels():
    m = bandai(0)
    _, adapter = normalize_rig(m)
    with pytest.raises(ParameterError, match="analysis rig"):
        adapter.restore(m)


def _dog_turned(rot: np.ndarray) -> Motion:
    """The synthetic trot (a dog longer than it is tall) with its root premultiplied by ``rot``."""
    from _walkers import quadruped_names, quadruped_skeleton, trot

    names = quadruped_names()
    m = trot(quadruped_skeleton(names), names, n_frames=120)
    root = m.skeleton.joints[0]
    order = root.rotation_order
    r = [m.channel_index(root.name, "r" + a.lower()) for a in order]
    t = [m.channel_index(root.name, d) for d in ("tx", "ty", "tz")]
    frames = np.array(m.frames)
    turned = Rotation.from_matrix(rot) * Rotation.from_euler(order, frames[:, r], degrees=True)
    frames[:, r] = np.unwrap(turned.as_euler(order, degrees=True), period=360, axis=0)
    frames[:, t] = frames[:, t] @ rot.T
    return m.with_frames(frames)


def test_up_axis_of_a_dog_longer_than_tall():
    """A trotting dog is 14.5 long and 10 tall: its feet at the bottom, not its length, say
    which way is up, in a Y-up and in a Z-up world (it read Z-up in a Y-up world before)."""
    dog = _dog_turned(np.eye(3))
    extents = describe_rig(dog).extents
    assert extents[2] > extents[1]  # longer than tall: the extent alone would say Z
    assert describe_rig(dog).up_axis == "Y"
    assert describe_rig(_dog_turned(Z_TO_Y.T)).up_axis == "Z"


@pytest.mark.parametrize("name", ["bandai/dataset-1_walk_normal_001.bvh",
                                  "bandai/dataset-2_walk-turn-left_normal_011.bvh",
                                  "xsens/S02-Trial-Walk-1.bvh"])
def test_the_up_axis_is_found_whichever_way_the_capture_faces(name):
    """Each shared rig in its analysis form, re-expressed with ZXY channels, turned to four
    headings about the vertical and also laid into a Z-up world: Y, then Z, every time."""
    from cyclecoord.rig import analysis_motion

    m = analysis_motion(shared(BVH / name)[1:301])
    b = to_bvh_convention(m, "ZXY")
    for deg in (0, 90, 180, 270):
        turn = Rotation.from_euler("y", deg, degrees=True).as_matrix()
        assert describe_rig(turn_root(b, turn)).up_axis == "Y", deg
        lay = Rotation.from_euler("x", 90, degrees=True).as_matrix() @ turn  # y -> z
        assert describe_rig(turn_root(b, lay)).up_axis == "Z", deg
