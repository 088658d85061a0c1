"""A centimetre, millimetre or inch capture exported to glTF is life-size in Blender.

Blender's own glTF importer (the real program, ``apt-get install -y blender
python3-numpy``) reads what :func:`cyclecoord.save` writes; the armature's height is the
vertical extent of its bone heads (``blender/measure_height.py``).
"""

import json
import subprocess
from pathlib import Path

import pytest

import cyclecoord as cc
from _rigs import BANDAI, BVH, XSENS, in_units, walk
from _skips import need_data, needs_program, program

BLENDER = program("blender")
SCRIPT = Path(__file__).resolve().parent / "blender" / "measure_height.py"
pytestmark = needs_program("blender")


def blender_height(motion, tmp_path, name):
    glb = tmp_path / f"{name}.glb"
    cc.save(motion, glb)
    out = tmp_path / f"{name}.json"
    run = subprocess.run([BLENDER, "-b", "--factory-startup", "--python", str(SCRIPT), "--",
                          str(glb), str(out)], capture_output=True, text=True, timeout=300)
    assert out.is_file(), run.stdout[-2000:] + run.stderr[-2000:]
    return json.loads(out.read_text())["median_height_m"]


@pytest.mark.parametrize("unit,mpu", [("cm", 0.01), ("mm", 0.001), ("in", 0.0254), ("m", 1.0)])
def test_synthetic_walk_in_any_unit_is_life_size(tmp_path, unit, mpu):
    h = blender_height(in_units(walk(), mpu), tmp_path, unit)
    assert 1.4 <= h <= 2.1, f"{unit}: {h:.3f} m"


def test_xsens_millimetres_is_life_size(tmp_path):
    need_data(XSENS)
    h = blender_height(cc.load(XSENS), tmp_path, "xsens")
    assert 1.4 <= h <= 2.1  # measured 1.74 m


def test_bandai_centimetres_keeps_its_scale(tmp_path):
    """The Bandai skeleton ends at its head joint (the head's end site has no length): its
    bone heads span 1.33 m in the file's own centimetres, and so they must in Blender."""
    need_data(BVH / "bandai")
    m = cc.load(BANDAI[2])
    h = blender_height(m, tmp_path, "bandai")
    info = cc.rig.describe_rig(m)
    assert info.units == "cm"
    assert h == pytest.approx(info.height_m, rel=0.03)
