"""`cyclecoord latent fit` and `cyclecoord animate`: files, reports, and one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.cli.main import main


@pytest.fixture(scope="module")
def workdir(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("latent")
    walk = cc.datasets.make_periodic_capture(kind="walk", n_frames=240, random_state=0).motion
    walk2 = cc.datasets.make_periodic_capture(kind="walk", n_frames=160, random_state=5).motion
    cc.save(walk, d / "walk.bvh")
    cc.save(walk2, d / "walk2.bvh")
    assert (
        main(
            [
                "latent",
                "fit",
                f"{d / 'walk.bvh'}:0:120=a",
                f"{d / 'walk.bvh'}:120:240=b",
                "-o",
                str(d / "walk.npz"),
                "--max-iter",
                "40",
                "--report",
                str(d / "fit.json"),
            ]
        )
        == 0
    )
    assert (
        main(
            [
                "latent",
                "fit",
                str(d / "walk2.bvh") + "=w2",
                "-o",
                str(d / "walk2.npz"),
                "--max-iter",
                "40",
            ]
        )
        == 0
    )
    return d


def _script(d: Path, name: str, **changes) -> Path:
    spec = {
        "fps": 30,
        "seed": 1,
        "models": {"walk": "walk.npz", "other": "walk2.npz"},
        "start": {"model": "walk"},
        "commands": [
            {"command": "IDLE", "duration": 0.5},
            {"command": "MOVE", "to": {"segment": "b", "time": 0.3}, "path": "graph"},
            {"command": "TRANSITION", "to": "other", "blend": 0.3},
            {"command": "PLAY", "segment": "w2", "start": 0.0, "stop": 0.4},
        ],
    }
    spec.update(changes)
    p = d / name
    p.write_text(json.dumps(spec))
    return p


def test_fit_writes_model_and_report(workdir):
    rep = json.loads((workdir / "fit.json").read_text())
    assert rep["frames"] == 60 and rep["segments"] == ["a", "b"] and rep["latent_dims"] == 3
    # which seconds of each segment the gait (MOVE ahead, TRANSITION in step) uses
    gait = rep["gait"]
    assert [g["segment"] for g in gait] == ["a", "b"]
    model = cc.synthesis.latent.LatentModel.load(workdir / "walk.npz")
    for s, g in enumerate(gait):
        if not model.gait().has(s):  # (2 s segments: too few cycles for a gait)
            assert g["cycle_s"] is None and g["phase_from_s"] is None
            continue
        rows = model.gait().rows(s)
        start = model.times_[model.segments_ == s][0]
        assert g["cycle_s"] == pytest.approx(model.gait().period[s] / model.fps_)
        assert g["phase_from_s"] == pytest.approx(model.times_[rows[0]] - start)
        assert g["phase_to_s"] == pytest.approx(model.times_[rows[-1]] - start)
        assert 0 <= g["phase_from_s"] < g["phase_to_s"] <= g["seconds"]


def test_animate_writes_bvh_and_report_reproducibly(workdir):
    s = _script(workdir, "ok.json")
    out1, out2 = workdir / "o1.bvh", workdir / "o2.bvh"
    assert main(["animate", str(s), "-o", str(out1), "--report", str(workdir / "r1.json")]) == 0
    assert main(["animate", str(s), "-o", str(out2), "--no-check"]) == 0
    a, b = cc.load(out1), cc.load(out2)
    assert a.n_frames == b.n_frames > 30
    np.testing.assert_allclose(a.frames, b.frames, atol=1e-4)
    rep = json.loads((workdir / "r1.json").read_text())
    assert rep["transitions"][0]["transition"] == ["walk", "other"]
    assert rep["timing"]["frames_per_second"] > 0
    assert "plausibility" in rep
    # a different seed changes the motion
    s2 = _script(workdir, "seed2.json", seed=2)
    assert main(["animate", str(s2), "-o", str(workdir / "o3.bvh"), "--no-check"]) == 0
    c = cc.load(workdir / "o3.bvh").frames
    assert c.shape != a.frames.shape or not np.allclose(c, a.frames)


@pytest.mark.parametrize(
    "changes, message",
    [
        ({"models": {"walk": "walk.npz", "other": "missing.npz"}}, "models.other"),
        ({"commands": [{"command": "JUMP"}]}, r"commands\[0\] \(JUMP\): unknown command"),
        (
            {"commands": [{"command": "TRANSITION", "to": "nope"}]},
            r"commands\[0\] \(TRANSITION\): unknown model",
        ),
        (
            {"commands": [{"command": "MOVE", "to": [40, 40, 40]}]},
            r"commands\[0\] \(MOVE\): .*outside model",
        ),
        (
            {"commands": [{"command": "IDLE", "duration": 1, "speed": 2}]},
            r"commands\[0\] \(IDLE\): unknown key",
        ),
        ({"start": {"model": "ghost"}}, "start: unknown model"),
        ({"plant": "feet"}, "plant: must be"),
        (
            {"commands": [{"command": "PLAY", "segment": "zz"}]},
            r"commands\[0\] \(PLAY\): model 'walk' has no segment",
        ),
    ],
)
def test_bad_scripts_fail_with_one_line_and_no_output(workdir, capsys, changes, message):
    s = _script(workdir, "bad.json", **changes)
    out = workdir / "bad.bvh"
    rep = workdir / "bad_report.json"
    assert main(["animate", str(s), "-o", str(out), "--report", str(rep)]) == 1
    err = [
        ln for ln in capsys.readouterr().err.strip().splitlines() if "cmd/s" not in ln
    ]  # no tqdm bar
    assert len(err) == 1 and err[0].startswith("cyclecoord: error:")
    import re

    assert re.search(message, err[0]), err[0]
    assert not out.exists() and not rep.exists()


def test_transition_without_bridges_still_arrives_and_says_how(workdir, capsys):
    s = _script(workdir, "far.json", bridge_threshold=1e-9)
    out, rep = workdir / "far.bvh", workdir / "far.json.report"
    assert main(["animate", str(s), "-o", str(out), "--report", str(rep), "--no-check"]) == 0
    printed = capsys.readouterr().out
    assert "TRANSITION walk -> other" in printed and "closest poses" in printed
    (ev,) = json.loads(rep.read_text())["transitions"]
    assert ev["under_threshold"] is False and ev["bridge_distance"] > ev["threshold"]
    assert "skating_fraction" in json.loads(rep.read_text())["foot_skating"]


def test_models_of_different_skeletons_cannot_transition(workdir, capsys):
    m = cc.load(workdir / "walk2.bvh")
    keep = [c for c in m.channels if c[0] not in ("lhand", "lfingers", "lthumb")]
    cc.save(m.select(keep), workdir / "cut.npz")
    assert (
        main(
            [
                "latent",
                "fit",
                str(workdir / "cut.npz"),
                "-o",
                str(workdir / "cut_model.npz"),
                "--max-iter",
                "20",
            ]
        )
        == 0
    )
    s = _script(workdir, "skel.json", models={"walk": "walk.npz", "other": "cut_model.npz"})
    out = workdir / "skel.bvh"
    assert main(["animate", str(s), "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "commands[2] (TRANSITION)" in err and "different skeletons" in err
    assert not out.exists()


def test_fit_rejects_bad_takes(workdir, capsys):
    assert main(["latent", "fit", f"{workdir / 'walk.bvh'}:5", "-o", str(workdir / "x.npz")]) == 1
    assert "PATH:A:B" in capsys.readouterr().err
    assert not (workdir / "x.npz").exists()


def test_animate_feet_option_and_script_key(workdir, capsys):
    """``--feet`` (or the script's "feet") names the planted feet and the report's skating."""
    s = _script(workdir, "feet.json")
    rep = workdir / "feet_report.json"
    code = main(["animate", str(s), "-o", str(workdir / "feet.bvh"), "--no-check",
                 "--feet", "lfoot:ltoes,rfoot:rtoes", "--report", str(rep)])
    assert code == 0
    per_foot = json.loads(rep.read_text())["foot_skating"]["per_foot"]
    assert set(per_foot) == {"lfoot", "ltoes", "rfoot", "rtoes"}
    s = _script(workdir, "feet_key.json", feet=["ltoes", "rtoes"])
    code = main(["animate", str(s), "-o", str(workdir / "feet2.bvh"), "--no-check",
                 "--report", str(rep)])
    assert code == 0
    assert set(json.loads(rep.read_text())["foot_skating"]["per_foot"]) == {"ltoes", "rtoes"}
    for bad in (["--feet", "lfoot,rfot"], []):
        script = s if bad else _script(workdir, "feet_bad.json", feet=["lfoot", "nosuch"])
        out = workdir / "feet_bad.bvh"
        assert main(["animate", str(script), "-o", str(out), *bad]) == 1
        err = capsys.readouterr().err
        assert "feet: no joint" in err and "nearest" in err and not out.exists()


def test_fit_refuses_a_root_without_position_channels(tmp_path, capsys):
    """A glTF whose skeleton metadata lost the root's ``tx`` dof (fuzz_formats gltf case
    1002403): the model's root track reads the root's position, and fitting raised a
    KeyError; now one line naming the file and the missing channel, and no model."""
    walk = cc.datasets.make_periodic_capture(kind="walk", n_frames=60, random_state=0).motion
    path = tmp_path / "walk.gltf"
    cc.save(walk, path)
    doc = json.loads(path.read_text())
    dofs = doc["extras"]["cyclecoord"]["skeleton"]["joints"][0]["dofs"]
    assert dofs[0] == "tx"
    del dofs[0]
    path.write_text(json.dumps(doc))
    out = tmp_path / "m.npz"
    assert main(["latent", "fit", str(path), "-o", str(out), "--max-iter", "2",
                 "--no-progress"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "walk.gltf" in err[0] and "no tx channel" in err[0], err
    assert not out.exists()


def test_fit_says_the_rig_and_the_joints_it_models_about_their_mean(tmp_path, capsys):
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from _rigs import BANDAI, bandai

    bandai(2)  # skips without the shared data
    out = tmp_path / "walk.npz"
    assert main(["latent", "fit", str(BANDAI[2]), "-o", str(out), "--max-iter", "20",
                 "--no-progress", "--report", str(tmp_path / "r.json")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("rig: Bandai-style rig: static root joint_Root, Hips travels")
    assert "static root joint_Root folded into Hips" in lines[0]
    assert lines[1].endswith("gimbal lock in the takes): Spine")
    assert lines[2].startswith("gait: dataset-1_walk_normal_001: 1.0") and " s cycle, phase" in lines[2]
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["joints_about_their_mean_rotation"] == ["Spine"]
    model = cc.synthesis.latent.LatentModel.load(out)
    assert model.skeleton_.joints[0].name == "Hips"  # the analysis rig
    (g,) = report["gait"]  # the seconds of the take with a gait phase
    rows = model.gait().rows(0)
    assert g["phase_from_s"] == pytest.approx(model.times_[rows[0]])
    assert g["phase_to_s"] == pytest.approx(model.times_[rows[-1]])
    assert 0 <= g["phase_from_s"] < g["phase_to_s"] <= g["seconds"]
