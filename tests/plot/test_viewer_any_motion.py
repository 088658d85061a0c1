"""`view` on any motion the readers accept (issue 26 part 6): one joint, one frame, a
motion in millimetres, a figure that never moves."""

from dataclasses import replace

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.cli.main import main
from cyclecoord.motion import Motion
from cyclecoord.plot.viewer import skeleton_figure
from cyclecoord.skeleton import Joint, Skeleton


def _one_joint(frames: np.ndarray) -> Motion:
    skel = Skeleton(
        (Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),),
        name="one",
        source_format="bvh",
    )
    return Motion(frames, skel.channels, fps=30, skeleton=skel)


def _walk_in_mm() -> Motion:
    m = cc.datasets.example_capture().motion[:60]
    mm = 25.4 / m.skeleton.length_unit  # ASF units -> millimetres
    joints = tuple(
        replace(j, offset=j.offset * mm, end_site=None if j.end_site is None else j.end_site * mm)
        for j in m.skeleton.joints
    )
    frames = m.frames.copy()
    frames[:, :3] *= mm
    return Motion(frames, m.channels, fps=m.fps,
                  skeleton=replace(m.skeleton, joints=joints, source_format="bvh"))


@pytest.mark.parametrize(
    "motion",
    [
        _one_joint(np.zeros((5, 6))),  # one joint that never moves: a one-node figure
        _one_joint(np.c_[np.linspace(0, 1, 5), np.zeros((5, 5))]),
        _one_joint(np.zeros((1, 6))),
        cc.datasets.example_capture().motion[:1],
        _walk_in_mm(),
    ],
    ids=["one-still-joint", "one-moving-joint", "one-joint-one-frame", "one-frame", "mm"],
)
def test_every_motion_gets_a_figure(motion):
    fig = skeleton_figure(motion)
    scene = fig.layout.scene
    for axis in (scene.xaxis, scene.yaxis, scene.zaxis):
        lo, hi = axis.range
        assert np.isfinite([lo, hi]).all() and hi > lo
    ratio = scene.aspectratio
    assert all(np.isfinite(v) and v > 0 for v in (ratio.x, ratio.y, ratio.z))


def test_view_of_a_one_node_gltf(tmp_path, capsys):
    glb = tmp_path / "one.glb"
    cc.save(_one_joint(np.zeros((3, 6))), glb)
    out = tmp_path / "one.html"
    assert main(["view", str(glb), "-o", str(out)]) == 0 and out.stat().st_size > 0
