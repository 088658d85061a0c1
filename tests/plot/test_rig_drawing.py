"""Stick figures draw the analysis rig: no bone from the origin to a static root's hips, y up."""

import numpy as np

from cyclecoord.plot import render
from cyclecoord.plot.animation import _make_track
from cyclecoord.plot.viewer import skeleton_figure
from cyclecoord.rig import Z_TO_Y
from _rigs import bandai, z_up  # tests/ is on the path (rootdir conftest)


def _bones(pos: np.ndarray, parents: np.ndarray) -> np.ndarray:
    """Bone ends ``(T, B, 2, 3)``."""
    kids = np.flatnonzero(parents >= 0)
    return np.stack([pos[:, parents[kids]], pos[:, kids]], axis=2)


def test_render_track_has_no_bone_from_the_origin():
    m = bandai(0)[:30]
    track = _make_track(m, None)
    assert track.positions.shape[1] == len(m.positions().names) - 1  # joint_Root left out
    bones = _bones(track.positions, track.parents)
    # every bone starts on the body: the hips are about 90 cm above the floor, metres away
    # from the origin (the static root), which no bone reaches any more
    assert np.linalg.norm(bones[..., 0, :], axis=-1).min() > 100.0
    assert np.allclose(track.positions, m.positions().positions[:, 1:])


def test_render_a_static_root_rig(tmp_path):
    out = render(bandai(0)[:12], tmp_path / "bandai.gif", step=4)
    assert out.is_file() and out.stat().st_size > 0


def test_render_track_of_a_z_up_rig_stands_y_up():
    m = z_up()[:20]
    track = _make_track(m, None)
    assert np.allclose(track.positions, m.positions().positions @ Z_TO_Y.T)
    extent = np.median(np.ptp(track.positions, axis=1), axis=0)
    assert extent[1] > 2 * max(extent[0], extent[2])


def test_viewer_has_no_bone_from_the_origin():
    m = bandai(0)[:9]
    fig = skeleton_figure(m, contacts=False)
    bones = fig.frames[0].data[0]
    xyz = np.stack([bones.x, bones.y, bones.z], axis=1)
    ends = xyz[~np.isnan(xyz).any(axis=1)]
    assert np.linalg.norm(ends, axis=1).min() > 1.0
    assert len(ends) == 2 * (len(m.skeleton.joints) - 2 + 5)  # 20 bones + 5 end sites


def test_limbs_are_coloured_by_side_in_every_naming_convention():
    """Left blue, right red, midline grey: CMU's glued letters, Mixamo's prefixed words,
    Bandai's suffixes; an end site or a joint the names do not place takes its parent's
    side; a midline joint stays grey."""
    from cyclecoord.plot.animation import _side_colours

    L, R, C = "#1f77b4", "#d62728", "#333333"
    cases = [
        (["root", "lfemur", "ltibia", "rfemur", "rtibia", "lowerback"], [-1, 0, 1, 0, 3, 0],
         [C, L, L, R, R, C]),
        (["mixamorig:Hips", "mixamorig:LeftUpLeg", "mixamorig:RightUpLeg",
          "mixamorig:Spine"], [-1, 0, 0, 0], [C, L, R, C]),
        (["joint_Root", "Hips", "UpperLeg_L", "Foot_L", "UpperLeg_R", "Toes_R",
          "Toes_R/end", "Prop1"], [-1, 0, 1, 2, 1, 4, 5, 3], [C, C, L, L, R, R, R, L]),
    ]
    for names, parents, want in cases:
        assert _side_colours(names, np.array(parents)) == want, names
