"""A refusal says which options find a clean cycle on this capture (tried, not guessed)."""

import json
import sys
from pathlib import Path

import cyclecoord as cc
from cyclecoord.cli import main
from cyclecoord.periodic.suggest import what_would_help

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_rotations import scrambled  # noqa: E402


def test_refusal_names_what_helps(tmp_path, capsys):
    """Euler numbers that wrap and flip refuse in the paper's Euler space; rotation vectors
    read the same capture, and the refusal says so."""
    m = scrambled(cc.datasets.example_capture().motion)
    path = tmp_path / "scrambled.npz"
    cc.save(m, path)
    rep = tmp_path / "r.json"
    code = main(["extract", str(path), "--rotations", "euler", "--report", str(rep)])
    err = capsys.readouterr().err
    assert code == 3
    assert "would help here (tried): --rotations rotvec (period" in err
    sugg = json.loads(rep.read_text())["suggestions"]
    assert sugg[0]["option"] == "--rotations rotvec"
    # the example's period is 120 frames: measured 119.6, as extract finds on the clean walk
    assert abs(sugg[0]["period_frames"] - 120) <= 1


def test_nothing_is_tried_that_was_already_given(monkeypatch):
    import cyclecoord.periodic.pipeline as pipeline

    calls = []

    def refuse(motion, **kw):
        calls.append(kw)
        raise cc.errors.ParameterError("refused")

    monkeypatch.setattr(pipeline, "extract", refuse)
    m = cc.datasets.example_capture().motion
    given = {"rotations": "rotvec", "steady": False, "pca": 3, "normalize": True}
    assert what_would_help(m, given) == []
    assert calls == []
    what_would_help(m, {"rotations": "rotvec"})
    assert [c.get("rotations") for c in calls] == ["rotvec", "rotvec", "rotvec"]
    assert {k for c in calls for k, v in c.items() if v in (False, 3, True)} == {
        "steady", "pca", "normalize"}
