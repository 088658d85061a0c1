"""`cyclecoord feet`: contacts and skating printed, locked motion and report written."""

import json

from cyclecoord.cli.main import main


def test_feet_lock_writes_glb_and_report(walk_69_01, tmp_path, capsys):
    out, report = tmp_path / "locked.glb", tmp_path / "feet.json"
    code = main(
        [
            "feet",
            walk_69_01.source,
            "--frames",
            "200:450",
            "--lock",
            "-o",
            str(out),
            "--report",
            str(report),
        ]
    )
    assert code == 0
    text = capsys.readouterr().out
    assert "lfoot: planted" in text and "locked: foot skating" in text
    data = json.loads(report.read_text())
    assert data["feet"] == ["lfoot", "ltoes", "rfoot", "rtoes"]
    assert data["skating"]["skating_frames"] > 100
    assert data["locked"]["skating"]["skating_frames"] <= 2
    assert data["locked"]["joint_change_deg"]["thorax"] == 0
    import cyclecoord as cc

    assert cc.load(out).n_frames == 250


def test_feet_errors(walk_69_01, tmp_path, capsys):
    assert main(["feet", walk_69_01.source, "--lock"]) == 1
    assert "-o OUT" in capsys.readouterr().err
    assert main(["feet", walk_69_01.source, "-o", str(tmp_path / "x.xyz")]) == 1
    assert "unknown output format" in capsys.readouterr().err
