"""``--feet LEFT,RIGHT`` on every command that finds foot contacts, and feet found without it
on rigs whose joints say nothing (issue 23 part 3)."""

import json

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.cli import main
from cyclecoord.cli.main import build_parser
from _walkers import (  # tests/ is on the path (rootdir conftest)
    biped_names,
    biped_skeleton,
    biped_walk,
    quadruped_names,
    quadruped_skeleton,
    trot,
)

#: Every command that measures contacts or skating, with the arguments it needs.
COMMANDS = {
    "extract": ["in.bvh"],
    "detect": ["in.bvh"],
    "feet": ["in.bvh"],
    "blend": ["a.bvh", "b.bvh"],
    "transition": ["a.bvh", "b.bvh", "--cycles", "1"],
    "view": ["in.bvh", "-o", "v.html"],
    "batch": ["folder", "-o", "out"],
    "animate": ["script.json", "-o", "out.bvh"],
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_feet_command_takes_the_option(command):
    args = build_parser().parse_args([command, *COMMANDS[command], "--feet", "Foot_L,Foot_R"])
    assert args.feet == "Foot_L,Foot_R"


@pytest.fixture(scope="module")
def walker(tmp_path_factory):
    """A biped with joints named j0..j18 (a prop in the right hand) walking, as BVH."""
    names = biped_names()
    path = tmp_path_factory.mktemp("walker") / "walker.bvh"
    cc.save(biped_walk(biped_skeleton(names), names, n_frames=240, heading_deg=30), path)
    return path, names


def test_feet_on_anonymous_biped(walker, capsys):
    path, names = walker
    assert main(["feet", str(path)]) == 0
    out = capsys.readouterr().out
    assert "feet by geometry: left j3+j4, right j7+j8" in out
    assert "0 frames skating" in out


def test_feet_option_and_its_errors(walker, tmp_path, capsys):
    path, _ = walker
    report = tmp_path / "feet.json"
    assert main(["feet", str(path), "--feet", "j4,j8", "--report", str(report)]) == 0
    out = capsys.readouterr().out
    assert "feet given: left j4, right j8" in out
    data = json.loads(report.read_text())
    assert data["feet"] == ["j4", "j8"] and data["legs"] == {"left": ["j4"], "right": ["j8"]}
    assert main(["feet", str(path), "--feet", "j3,j77"]) == 1
    err = capsys.readouterr().err
    assert "no joint 'j77'" in err and "nearest: j7" in err
    assert len(err.strip().splitlines()) == 1
    assert main(["feet", str(path), "--feet", "j3"]) == 1
    assert "two (LEFT,RIGHT) or four" in capsys.readouterr().err


def test_extract_with_feet(walker, tmp_path, capsys):
    path, _ = walker
    report = tmp_path / "r.json"
    cycle = tmp_path / "cycle.bvh"
    code = main(["extract", str(path), "--feet", "j3:j4,j7:j8", "--lock-feet", "-o", str(cycle),
                 "--report", str(report)])
    assert code == 0
    out = capsys.readouterr().out
    assert "feet: planted feet slide" in out and "foot locking" in out
    data = json.loads(report.read_text())
    assert data["parameters"]["feet"] == ["j3", "j4", "j7", "j8"]
    assert set(data["foot_skating"]["per_foot"]) == {"j3", "j4", "j7", "j8"}
    assert main(["extract", str(path), "--feet", "j3,jj8"]) == 1
    assert "nearest" in capsys.readouterr().err


def test_extract_says_why_feet_are_not_measured():
    """A skeleton with no legs at all: extract says so instead of leaving the line out."""
    from cyclecoord.cli.extract import _feet_line
    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    skel = Skeleton((Joint("j0", -1, [0, 0, 0], ("tx", "ty", "tz"), ""),
                     Joint("j1", 0, [1, 0, 0], ("rx",), "X"),
                     Joint("j2", 1, [1, 0, 0], ("rx",), "X")))
    m = Motion(np.zeros((10, len(skel.channels))), skel.channels, fps=30.0, skeleton=skel)
    line = _feet_line(m)
    assert line.startswith("feet: not measured:") and "--feet LEFT,RIGHT" in line


def test_quadruped_feet_command(tmp_path, capsys):
    names = quadruped_names()
    path = tmp_path / "trot.bvh"
    cc.save(trot(quadruped_skeleton(names), names, n_frames=120), path)
    assert main(["feet", str(path)]) == 0
    out = capsys.readouterr().out
    assert ("feet by geometry: front left j16+j17, front right j20+j21, hind left j8+j9, "
            "hind right j12+j13") in out
    assert main(["feet", str(path), "--feet", "j16,j20,j8,j12"]) == 0
    assert "feet given: front left j16, front right j20, hind left j8, hind right j12" in (
        capsys.readouterr().out)


def test_view_and_transition_take_feet(walker, tmp_path, capsys):
    path, _ = walker
    page = tmp_path / "v.html"
    assert main(["view", str(path), "-o", str(page), "--feet", "j3,j7"]) == 0
    assert "walker.bvh: foot skating" in capsys.readouterr().out
    clip = tmp_path / "t.bvh"
    report = tmp_path / "t.json"
    code = main(["transition", str(path), str(path), "--cycles", "1", "--feet", "j3:j4,j7:j8",
                 "-o", str(clip), "--report", str(report)])
    assert code == 0
    data = json.loads(report.read_text())
    assert set(data["foot_skating"]["per_foot"]) == {"j3", "j4", "j7", "j8"}


def test_bandai_feet_command(bvh_dir, capsys):
    path = bvh_dir / "bandai" / "dataset-1_walk_normal_001.bvh"
    assert main(["feet", str(path)]) == 0
    out = capsys.readouterr().out
    assert "feet by names: left Foot_L+Toes_L, right Foot_R+Toes_R" in out
    assert main(["feet", str(path), "--feet", "Foot_L,Foot_X"]) == 1
    err = capsys.readouterr().err
    assert "no joint 'Foot_X'" in err and "nearest: Foot_R, Foot_L" in err
