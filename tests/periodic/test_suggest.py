"""A refusal says which options find a clean cycle on this capture (tried, not guessed)."""

import json
import sys
from pathlib import Path

import pytest

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


def test_only_clean_cycles_are_suggested_and_at_most_two(monkeypatch):
    """what_would_help on stand-in extractions: a refusal or a cycle with a pop or a stray
    pose is no suggestion, one without a pose-quality figure or with a clean one is; it
    stops after ``most`` and tries nothing on a capture over MAX_FRAMES frames (that many
    are still tried)."""
    from types import SimpleNamespace as NS

    import cyclecoord.periodic.pipeline as pipeline
    from cyclecoord.periodic import suggest

    clean, pop, stray = NS(pops=[], strays=[]), NS(pops=[3], strays=[]), NS(pops=[], strays=[7])
    m = cc.datasets.example_capture().motion

    def found(outcomes, most=None):
        it = iter(outcomes)

        def extract(motion, **kw):
            q = next(it)
            if q == "refused":
                raise cc.errors.NoPeriodicMotionError("refused")
            return NS(pose_quality=q, period_frames=120, cycles=4.5)

        monkeypatch.setattr(pipeline, "extract", extract)
        kw = {} if most is None else {"most": most}
        return [s.option for s in what_would_help(m, {}, **kw)]

    names = [option for option, _ in suggest.ALTERNATIVES]
    assert found(["refused", pop, stray, clean]) == [names[3]]
    assert found([None, pop, clean, clean]) == [names[0], names[2]]  # most=2 by default
    monkeypatch.setattr(pipeline, "extract",
                        lambda motion, **kw: NS(pose_quality=None, period_frames=120, cycles=4.5))
    first = what_would_help(m, {}, most=1)[0]
    assert first.to_dict() == {"option": names[0], "period_frames": 120.0, "cycles": 4.5}
    with pytest.raises(AttributeError):  # a frozen record
        first.cycles = 1.0
    assert found([clean, clean, clean, clean], most=3) == names[:3]
    assert found([stray, None, "refused", pop], most=1) == [names[1]]
    monkeypatch.setattr(suggest, "MAX_FRAMES", m.n_frames)
    assert found([clean] * 4) == names[:2]
    monkeypatch.setattr(suggest, "MAX_FRAMES", m.n_frames - 1)
    assert found([clean] * 4) == []
