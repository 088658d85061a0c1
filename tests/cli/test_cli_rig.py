"""The rig line the commands print first, and --units."""

import numpy as np
import pytest

from cyclecoord.cli import main
from cyclecoord.io.gltf import gltf_joint_positions
from _rigs import XSENS, bandai, shared  # tests/ is on the path (rootdir conftest)


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def _height(path) -> float:
    names, pos, _ = gltf_joint_positions(path)
    keep = [i for i, n in enumerate(names) if n != "joint_Root"]
    return float(np.median(np.ptp(pos[:, keep, 1], axis=1)))


def test_convert_prints_the_rig_first_and_writes_metres(tmp_path, capsys):
    m = bandai(0)
    out = tmp_path / "walk.glb"
    code, text, err = run(capsys, "convert", m.source, "-o", out)
    assert code == 0, err
    first = text.splitlines()[0]
    assert first.startswith("Bandai-style rig: static root joint_Root, Hips travels")
    assert "cm (1.3" in first and first.endswith("Y-up, 30 fps")
    assert 1.25 < _height(out) < 1.5


def test_convert_units_option(tmp_path, capsys):
    m = bandai(0)
    out = tmp_path / "walk.glb"
    code, text, err = run(capsys, "convert", m.source, "-o", out, "--units", "in")
    assert code == 0, err
    assert "in as given" in text.splitlines()[0]
    assert _height(out) == pytest.approx(2.54 * 1.33, rel=0.05)
    code, text, err = run(capsys, "convert", m.source, "-o", out, "--units", "0.01")
    assert code == 0, err
    assert 1.25 < _height(out) < 1.5


def test_units_option_refuses_unknown_units(tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["convert", "example", "-o", str(tmp_path / "a.glb"), "--units", "furlong"])
    assert "units must be auto, m, cm, mm, in" in capsys.readouterr().err


def test_convert_without_skeleton_says_so(tmp_path, capsys):
    csv = tmp_path / "a.csv"
    csv.write_text("a.x,b.y\n1,2\n3,4\n")
    code, text, err = run(capsys, "convert", csv, "-o", tmp_path / "b.npz")
    assert code == 0, err
    assert text.startswith("no skeleton: 2 channels")


def test_feet_prints_the_rig_first(capsys):
    m = shared(XSENS)
    code, text, err = run(capsys, "feet", m.source, "--frames", "1200:1500")
    assert code == 0, err
    assert text.splitlines()[0].startswith("BVH rig: Hips travels, 25 joints")
    assert "mm (1.7" in text.splitlines()[0]


def test_feet_on_a_z_up_rig(walk_69_01, tmp_path, capsys):
    """Contacts measured along the rig's own up axis: the same on 69_01 and on it turned Z-up."""
    import cyclecoord as cc
    from cyclecoord.conventions import to_bvh_convention
    from cyclecoord.rig import Z_TO_Y
    from _rigs import turn_root

    y_up = to_bvh_convention(walk_69_01[200:450], "ZXY")
    texts = []
    for name, m in (("y.bvh", y_up), ("z.bvh", turn_root(y_up, Z_TO_Y.T))):
        cc.save(m, tmp_path / name)
        code, text, err = run(capsys, "feet", tmp_path / name)
        assert code == 0, err
        texts.append(text.splitlines())
    assert "Z-up" in texts[1][0] and "Y-up" in texts[0][0]
    first = next(i for i, line in enumerate(texts[1]) if "planted" in line)
    assert "planted   0.0%" not in texts[1][first]
    assert texts[0][2:] == texts[1][2:]  # feet found, contacts and skating alike
