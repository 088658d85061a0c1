"""Latent models and animation scripts are inputs too (issue 26 part 2): a broken model or
script, and a graph asked for too much, end in one line naming the file and the array,
the script entry or the option; never in a traceback or an unbounded allocation."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.cli.main import main
from cyclecoord.errors import ParseError
from cyclecoord.synthesis.latent.model import LatentModel


@pytest.fixture(scope="module")
def model(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("model")
    walk = cc.datasets.make_periodic_capture(kind="walk", n_frames=160, random_state=0).motion
    cc.save(walk, d / "walk.bvh")
    args = ["latent", "fit", f"{d / 'walk.bvh'}:0:80=a", f"{d / 'walk.bvh'}:80:160=b"]
    assert main(args + ["-o", str(d / "walk.npz"), "--max-iter", "20"]) == 0
    return d / "walk.npz"


def _arrays(path: Path) -> dict:
    with np.load(path, allow_pickle=False) as data:
        return {k: data[k] for k in data.files}


def _error(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("cyclecoord: error: "), err
    assert "Traceback" not in err
    return err


# ------------------------------------------------------------------------------ models
def test_a_truncated_or_corrupted_model(model, tmp_path):
    data = model.read_bytes()
    bad = tmp_path / "cut.npz"
    bad.write_bytes(data[: len(data) // 2])
    with pytest.raises(ParseError, match="cut.npz"):
        LatentModel.load(bad)
    flipped = bytearray(data)
    with zipfile.ZipFile(model) as z:  # inside the compressed data of array 'X'
        info = z.getinfo("X.npy")
    n, extra = np.frombuffer(data, "<u2", 2, info.header_offset + 26)
    at = info.header_offset + 30 + int(n) + int(extra) + info.compress_size // 2
    flipped[at] ^= 0xFF
    bad.write_bytes(bytes(flipped))
    with pytest.raises(ParseError, match="cut.npz"):
        LatentModel.load(bad)


@pytest.mark.parametrize(
    "key, value, words",
    [
        ("X", np.zeros((3, 2)), ["'X'", "shape"]),
        ("Y", np.zeros((5,)), ["'Y'"]),
        ("hyper", np.array([1.0, np.nan, 1.0]), ["'hyper'"]),
        ("hyper", np.array([1.0, -1.0, 1.0]), ["'hyper'", "positive"]),
        ("segments", np.full(40, 7), ["'segments'"]),
        ("mean", np.array(["a", "b"]), ["'mean'"]),
        ("segment_names", np.array("[not json"), ["'segment_names'", "JSON"]),
        ("segment_names", np.array("[" * 200 + "]" * 200), ["'segment_names'", "nested"]),
        ("params", np.array('{"unknown": 1}'), ["'params'", "unknown"]),
        # a name twice: a segment with no frames, an IndexError in animate (fuzzer, model
        # cases 100995 and 102743)
        ("segment_names", np.array('["a", "a", "b"]'), ["'segment_names'", "repeat"]),
        ("segment_names", np.array('["a", "b", "c"]'), ["'segments'", "no frames"]),
        ("gait_phase", np.zeros(3), ["'gait_phase'", "shape"]),
        ("gait_fade", np.zeros(7), ["'gait_fade'", "shape"]),
        ("gait_fade", "inf", ["'gait_fade'", "inf"]),
        ("gait_fade", np.array(["a"]), ["'gait_fade'"]),
        ("gait_version", np.array(99), ["'gait_version'"]),
        ("gait_version", np.array(["a"]), ["'gait_version'"]),
        ("gait_version", np.zeros(4), ["'gait_version'"]),
        ("motion_frames", "inf", ["'motion_frames'", "inf"]),
        ("format", np.array("something else"), ["not a latent model"]),
    ],
)
def test_arrays_of_the_wrong_shape_dtype_or_value(model, tmp_path, key, value, words):
    arrays = _arrays(model)
    arrays[key] = np.full(arrays[key].shape, np.inf) if isinstance(value, str) else value
    bad = tmp_path / "bad.npz"
    np.savez(bad, **arrays)
    with pytest.raises(ParseError) as e:
        LatentModel.load(bad)
    text = str(e.value)
    assert "\n" not in text and str(bad) in text
    for w in words:
        assert w in text, text


def test_a_missing_array(model, tmp_path):
    arrays = _arrays(model)
    del arrays["components"]
    np.savez(tmp_path / "bad.npz", **arrays)
    with pytest.raises(ParseError, match="missing array 'components'"):
        LatentModel.load(tmp_path / "bad.npz")


# ------------------------------------------------------------------------------ scripts
def _script(folder: Path, model: Path, commands, **top) -> Path:
    spec = {"fps": 30, "models": {"walk": str(model)}, "commands": commands, **top}
    p = folder / "s.json"
    p.write_text(json.dumps(spec))
    return p


@pytest.mark.parametrize(
    "command, words",
    [
        ({"command": "IDLE", "duration": 1e300}, ["commands[0] (IDLE)", "duration"]),
        ({"command": "IDLE", "duration": 2e6}, ["commands[0] (IDLE)"]),
        ({"command": "MOVE", "to": {"frame": 3}, "duration": float("nan")}, ["commands[0] (MOVE)"]),
        ({"command": "MOVE", "to": {"frame": 3}, "speed": 1e-300}, ["commands[0] (MOVE)"]),
        ({"command": "MOVE", "to": [1, {"a": 1}, 2]}, ["commands[0] (MOVE)", "latent target"]),
        ({"command": "MOVE", "to": [[1, 2], 3, 4]}, ["commands[0] (MOVE)", "latent target"]),
        ({"command": "PLAY", "segment": "a", "start": "x"}, ["commands[0] (PLAY)", "start"]),
        ({"command": "TRANSITION", "to": "walk", "blend": float("inf")}, ["commands[0]"]),
        ({"command": "IDLE", "duration": 1, "hover": float("nan")}, ["hover"]),
        ({"command": "IDLE", "duration": 1, "sway": 1.5}, ["commands[0] (IDLE)", "sway"]),
        ({"command": "IDLE", "duration": 1, "sway": "x"}, ["commands[0] (IDLE)", "sway"]),
        ({"command": "IDLE", "duration": 1, "sway": False}, ["commands[0] (IDLE)", "sway"]),
        ({"command": "PLAY", "segment": ["a"]}, ["commands[0] (PLAY)", "segment"]),
    ],
)
def test_script_values_are_checked(model, tmp_path, capsys, command, words):
    script = _script(tmp_path, model, [command])
    assert main(["animate", str(script), "-o", str(tmp_path / "o.bvh")]) == 1
    err = _error(capsys)
    assert str(script) in err
    for w in words:
        assert w in err, err
    assert not (tmp_path / "o.bvh").exists()


def test_a_deeply_nested_script(model, tmp_path, capsys):
    script = tmp_path / "s.json"
    script.write_text("[" * 100_000 + "]" * 100_000)
    assert main(["animate", str(script), "-o", str(tmp_path / "o.bvh")]) == 1
    assert "nested" in _error(capsys)


def test_models_that_do_not_exist_or_are_not_models(model, tmp_path, capsys):
    idle = [{"command": "IDLE", "duration": 0.2}]
    (tmp_path / "folder.npz").mkdir()
    (tmp_path / "text.npz").write_text("not a zip")
    for entry in ("folder.npz", "text.npz", "nul\u0000.npz", str(tmp_path / "missing.npz")):
        script = tmp_path / "s.json"
        script.write_text(json.dumps({"models": {"walk": entry}, "commands": idle}))
        assert main(["animate", str(script), "-o", str(tmp_path / "o.bvh")]) == 1
        assert "models.walk" in _error(capsys)


def test_a_long_script_is_bounded_by_the_memory_limit(model, tmp_path, capsys):
    script = _script(tmp_path, model, [{"command": "IDLE", "duration": 30_000}])
    out = str(tmp_path / "o.bvh")
    assert main(["animate", str(script), "-o", out, "--memory-limit", "50M"]) == 1
    err = _error(capsys)
    assert "commands[0] (IDLE)" in err and "over the memory limit" in err


# ------------------------------------------------------------------------------ graph
@pytest.fixture(scope="module")
def takes(tmp_path_factory):
    d = tmp_path_factory.mktemp("graph")
    m = cc.datasets.example_capture().motion
    cc.save(m[:200], d / "w1.bvh")
    cc.save(m[200:], d / "w2.bvh")
    return [str(d / "w1.bvh"), str(d / "w2.bvh")]


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--step-scale", "1e300"], ["step_scale"]),
        (["--frames", "100000000"], ["100,000,000 frames", "10,000,000"]),
        (["--frames", "5000000", "--memory-limit", "1G"], ["over the memory limit"]),
    ],
)
def test_graph_refuses_what_it_cannot_make(takes, tmp_path, capsys, extra, words):
    out = tmp_path / "g.bvh"
    assert main(["graph", *takes, "--frames", "30", "-o", str(out), *extra]) == 1
    err = _error(capsys)
    for w in words:
        assert w in err, err
    assert not out.exists()


def test_a_duration_too_large_for_a_float(model, tmp_path, capsys):
    # JSON integers have no limit; np.isfinite(10**30) raised a TypeError
    for value in (10**30, 10**400):
        script = _script(tmp_path, model, [{"command": "IDLE", "duration": value}])
        assert main(["animate", str(script), "-o", str(tmp_path / "o.bvh")]) == 1
        assert "commands[0] (IDLE)" in _error(capsys)


def test_a_model_of_a_motion_that_never_moves(tmp_path, capsys):
    first = cc.datasets.example_capture().motion[:1]
    still = first.with_frames(np.repeat(first.frames, 30, axis=0))
    cc.save(still, tmp_path / "still.bvh")
    args = ["latent", "fit", str(tmp_path / "still.bvh"), "-o", str(tmp_path / "m.npz")]
    assert main(args + ["--step", "1", "--max-iter", "5"]) == 1
    assert "no joint angle changes" in _error(capsys)
    assert not (tmp_path / "m.npz").exists()


def test_a_particle_that_diverges_is_refused_at_once(model, tmp_path, capsys):
    # steps of 33 s (0.03 fps): the integration overflowed within frames, then made NaN
    # frames for over a minute
    script = _script(tmp_path, model, [{"command": "IDLE", "duration": 40000}], fps=0.03)
    assert main(["animate", str(script), "-o", str(tmp_path / "o.bvh"), "--no-check"]) == 1
    err = _error(capsys)
    assert "commands[0] (IDLE)" in err and "left finite values" in err


@pytest.mark.parametrize("value", [1e300, 10**30, 2e9])
def test_particle_parameters_are_bounded(model, tmp_path, capsys, value):
    # a radius of 1e300 was squared into an OverflowError
    script = _script(tmp_path, model, [{"command": "IDLE", "duration": 1}],
                     particle={"radius": value})
    assert main(["animate", str(script), "-o", str(tmp_path / "o.bvh")]) == 1
    err = _error(capsys)
    assert "particle" in err and "at most 1e+06" in err
