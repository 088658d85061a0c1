"""Any rig: a static root above travelling hips, 6 channels on every joint, Z up, and the
shared BVH captures from other datasets (issue 23)."""

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.conventions import to_bvh_convention
from cyclecoord.rig import Z_TO_Y

from _rigs import BANDAI, BVH, XSENS, static_root, turn_root  # tests/ is on the path
from _skips import need_data


def bvh_walk():
    return to_bvh_convention(cc.datasets.example_capture().motion, "ZXY")


def test_static_root_rig_reads_as_its_hips():
    """The Bandai layout built from the synthetic walk: the cycle is the plain walk's."""
    plain = bvh_walk()
    rig = static_root(plain, np.eye(3), [0.0, 0.0, 0.0], positions_everywhere=True)
    rig = rig.with_frames(rig.frames, fps=plain.fps)
    a = cc.extract(plain)
    b = cc.extract(rig)
    assert b.rig.static_root and b.rig_changes
    assert b.period_frames == pytest.approx(a.period_frames, rel=0.01)
    # written in the capture's own rig: every channel of the input, the static root included
    assert b.cycle.channels == rig.channels
    assert b.pose_quality.pop <= 2.0 and b.pose_quality.seam <= 1.5


def test_z_up_rig_gives_the_same_cycle():
    plain = bvh_walk()
    tipped = turn_root(plain, Z_TO_Y.T)
    a = cc.extract(plain)
    b = cc.extract(tipped)
    assert b.rig.up_axis == "Z"
    assert b.period_frames == pytest.approx(a.period_frames, rel=0.01)
    assert b.heading_per_cycle == pytest.approx(a.heading_per_cycle, abs=1.0)


@pytest.mark.parametrize("k", range(5))
def test_shared_bandai_walks_get_an_honest_cycle(k):
    """Measured at this commit: periods 23.0-43.0 frames, pop 0.96-1.06, seam 0.52-0.76
    (benchmarks/bench_rigs.py gives the same from its own forward kinematics)."""
    need_data(BVH / "bandai")  # five walks: a folder with fewer fails here
    m = cc.load(BANDAI[k])
    res = cc.extract(m)
    q = res.pose_quality
    assert q.pop <= 2.0 and q.seam <= 1.5 and q.nearest_max <= 1.0
    assert 20 < res.period_frames < 50  # 0.7-1.6 s at 30 fps
    assert res.rig.units == "cm" and res.rig.static_root


def test_shared_xsens_walk_drops_its_reference_pose():
    need_data(XSENS)
    res = cc.extract(cc.load(XSENS))
    assert res.rig.units == "mm" and res.rig.reference_frame
    assert "reference first frame dropped" in res.rig_changes
    # foot strikes from forward kinematics give 146.8 frames (bench_rigs)
    assert res.period_frames == pytest.approx(146.8, rel=0.03)
