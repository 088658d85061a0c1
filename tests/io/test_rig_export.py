"""glTF and USD exports in metres and y up, whatever the capture's unit and up axis."""

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.io.gltf import gltf_joint_positions, read_gltf
from cyclecoord.rig import UNITS, Z_TO_Y, describe_rig
from _rigs import XSENS, bandai, in_units, shared, walk, z_up  # tests/ is on the path


def _height(path, skip: tuple[str, ...] = ()) -> float:
    """Median over frames of the y extent of the file's own nodes (but ``skip``), metres."""
    names, pos, _ = gltf_joint_positions(path)
    keep = [i for i, n in enumerate(names) if n not in skip]
    return float(np.median(np.ptp(pos[:, keep, 1], axis=1)))


@pytest.mark.parametrize("k", [0, 2])
def test_bandai_glb_in_metres(tmp_path, k):
    m = bandai(k)
    out = tmp_path / "bandai.glb"
    cc.save(m, out)
    h = _height(out, skip=("joint_Root",))  # the static root's node stays at the origin
    # the nodes stop at the head joint (the Head end site has zero offset): ~1.33 m for a
    # performer of ~1.6 m; in centimetres taken as metres it was 133 m
    assert 1.25 < h < 1.5
    assert h == pytest.approx(describe_rig(m).height * 0.01, rel=0.02)
    back = cc.load(out)
    assert back.channels == m.channels
    assert np.abs(back.positions().positions - m.positions().positions).max() < 1e-3


def test_xsens_glb_in_metres(tmp_path):
    m = shared(XSENS)[:300]
    out = tmp_path / "xsens.glb"
    cc.save(m, out)
    h = _height(out)
    assert 1.6 < h < 1.9  # a 1.74 m performer, written in millimetres
    assert h == pytest.approx(describe_rig(m).height * 0.001, rel=0.02)


@pytest.mark.parametrize("unit", ["cm", "mm", "in", "m"])
def test_glb_height_in_any_unit(tmp_path, unit):
    m = in_units(walk(), UNITS[unit])
    out = tmp_path / f"walk_{unit}.glb"
    cc.save(m, out)
    assert 1.4 < _height(out) < 2.1


def test_units_given_to_the_glb(tmp_path):
    m = in_units(walk(), 0.01)
    out = tmp_path / "w.glb"
    cc.save(m, out, scale=0.0254)  # "these are inches", whatever the height says
    assert _height(out) == pytest.approx(describe_rig(m).height * 0.0254, rel=0.02)


def test_z_up_glb_is_y_up(tmp_path):
    m = z_up()
    out = tmp_path / "z.glb"
    cc.save(m, out)
    names, pos, _ = gltf_joint_positions(out)
    fk = m.positions()
    cols = [fk.names.index(n[: -len("_end")] + "/end" if n.endswith("_end") else n) for n in names]
    want = (fk.positions[:, cols] @ Z_TO_Y.T) * 0.01
    assert np.abs(pos - want).max() < 1e-5
    assert 1.4 < _height(out) < 2.1
    back = read_gltf(out)  # the capture's own Z-up channels back
    assert back.channels == m.channels
    assert np.abs(back.positions().positions - fk.positions).max() < 1e-3


def test_usd_metres_per_unit_and_up_axis(tmp_path):
    from pxr import Usd, UsdGeom

    out = tmp_path / "cm.usda"
    cc.save(in_units(walk(), 0.01)[:5], out)
    stage = Usd.Stage.Open(str(out))
    assert UsdGeom.GetStageMetersPerUnit(stage) == pytest.approx(0.01)
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
    out = tmp_path / "z.usda"
    cc.save(z_up()[:5], out)
    stage = Usd.Stage.Open(str(out))
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z
    assert UsdGeom.GetStageMetersPerUnit(stage) == pytest.approx(0.01)
