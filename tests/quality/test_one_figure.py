"""One figure, one value (issue 25 item 4): a cycle's loop closure, jerk and largest step
are measured on joint positions in the root's frame, so the same cycle saved as AMC, BVH,
NPZ and glTF reads them within 2 % of each other, and as ``extract`` reported them."""

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.quality.pose_space import cycle_figures
from cyclecoord.synthesis.sources import cycle_summary

FORMATS = (".amc", ".bvh", ".npz", ".glb")
FIGURES = ("loop_closure", "jerk", "largest_step")


def _read_back(cycle, folder, suffix):
    path = folder / f"cycle{suffix}"
    cc.save(cycle, path)
    if suffix == ".amc":  # AMC holds no frame rate
        return cc.load(path, skeleton=path.with_suffix(".asf"), fps=cycle.fps)
    return cc.load(path)


def _reported(result):
    """What extract reported (the console, the result, the report)."""
    return {
        "loop_closure": result.loop_closure,
        "jerk": result.jerk["cycle"],
        "largest_step": result.pose_quality.figures.largest_step,
    }


def _table(cycle, reference, folder, suffixes=FORMATS):
    rows = {"extract": reference}
    for suffix in suffixes:
        rows[suffix] = {k: cycle_summary(_read_back(cycle, folder, suffix))[k]
                        for k in FIGURES}
    return rows


def _assert_within(rows, rel=0.02):
    ref = rows["extract"]
    for name, row in rows.items():
        for k in FIGURES:
            assert row[k] == pytest.approx(ref[k], rel=rel), (name, k, rows)


@pytest.fixture(scope="module")
def synthetic():
    cap = cc.datasets.make_periodic_capture(n_frames=600, period=100, noise=0.3,
                                            random_state=3)
    return cc.extract(cap.motion)


def test_synthetic_cycle_reads_the_same_in_every_format(synthetic, tmp_path):
    _assert_within(_table(synthetic.cycle, _reported(synthetic), tmp_path))


def test_a_cycle_facing_backwards_reads_the_same_in_every_format(synthetic, tmp_path):
    # turned to face about 180 degrees: the root's yaw channel sits where Euler angles
    # wrap and each format writes its rotations its own way; joint positions do not care
    from cyclecoord.synthesis.align import rotate_heading

    turned = rotate_heading(synthetic.cycle, 179.0)
    fig = cycle_figures(turned)
    reference = {k: getattr(fig, k) for k in FIGURES}
    _assert_within(_table(turned, reference, tmp_path))


def test_figures_are_on_joint_positions_in_metres(synthetic):
    fig = cycle_figures(synthetic.cycle)
    assert fig.metres_per_unit == pytest.approx(0.0254 / 0.45)  # the CMU ASF unit
    assert fig.loop_closure == pytest.approx(synthetic.loop_closure)
    assert fig.largest_step >= fig.median_step > 0
    # a walk's body points move a few centimetres a frame at 120 fps, not metres
    assert 0.001 < fig.median_step < 0.05


def test_a_heading_turned_cycle_reads_the_same(synthetic):
    # the whole cycle turned about the vertical: root Euler channels change, the figures not
    from cyclecoord.synthesis.align import rotate_heading

    turned = rotate_heading(synthetic.cycle, 170.0)
    a, b = cycle_figures(synthetic.cycle), cycle_figures(turned)
    for k in FIGURES:
        assert getattr(b, k) == pytest.approx(getattr(a, k), rel=0.02)


def test_blend_summary_is_extracts_figures(synthetic):
    s = cycle_summary(synthetic.cycle)
    assert s["space"] == "joint positions" and s["unit"] == "m"
    assert s["loop_closure"] == pytest.approx(synthetic.loop_closure, rel=1e-9)
    assert s["jerk"] == pytest.approx(synthetic.jerk["cycle"], rel=1e-9)


def test_without_a_skeleton_the_channels_are_measured(synthetic):
    bare = cc.Motion(synthetic.cycle.frames, synthetic.cycle.channels, fps=synthetic.cycle.fps)
    s = cycle_summary(bare)
    assert s["space"] == "channels" and np.isfinite(s["loop_closure"])


def test_bandai_walk_reads_the_same_in_every_format(bvh_dir, tmp_path):
    """The issue's walk: extract read its loop closure 0.70 and blend, reading back the
    BVH extract wrote, 1.30 (channels).  Now one value, also from its AMC: the ASF is
    written in the rig extract read (static root folded into the hips, constant position
    channels as offsets) with the Bandai rig's centimetres (``length 2.54``), the AMC
    names its 30 fps, and a place of the body counts once in every format (an AMC read it
    1.33 m -> 9.43 m tall, Z-up, jerk 11,073 m/s^3 against 144 before)."""
    res = cc.extract(cc.load(bvh_dir / "bandai" / "dataset-1_walk_normal_001.bvh"))
    _assert_within(_table(res.cycle, _reported(res), tmp_path))
    path = tmp_path / "plain.amc"
    cc.save(res.cycle, path)
    back = cc.load(path)  # no fps given: the AMC's own comment says 30
    assert back.fps == 30.0 and back.skeleton.length_unit == pytest.approx(2.54)
    from cyclecoord.rig import describe_rig

    info = describe_rig(back)
    assert (info.units, info.up_axis) == ("asf", "Y")
    assert info.height * info.metres_per_unit == pytest.approx(1.33, abs=0.01)
