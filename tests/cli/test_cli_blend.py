"""The blend and transition commands: outputs, reports, refusals and exit codes."""

import json

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.cli import main
from _measured import at_most


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def one_loop(kind, period, seed):
    cap = cc.datasets.make_periodic_capture(kind=kind, n_frames=period, period=period, noise=0.0,
                                            speed_variation=0.0, random_state=seed)
    return cap.motion


@pytest.fixture()
def cycles(tmp_path):
    """A walk cycle (120 frames) as NPZ and a jog cycle (80 frames) as BVH."""
    walk, jog = tmp_path / "walk.npz", tmp_path / "jog.bvh"
    cc.save(one_loop("walk", 120, 0), walk)
    cc.save(one_loop("jog", 80, 3), jog)
    return walk, jog


def test_blend_writes_a_loop_and_a_report(cycles, tmp_path, capsys):
    walk, jog = cycles
    out, rep = tmp_path / "mix.bvh", tmp_path / "mix.json"
    code, stdout, err = run(capsys, "blend", walk, jog, "--weights", "0.25,0.75", "-o", out, "--report", rep)
    assert code == 0, err
    assert "taken as a cycle" in stdout and "aligned" in stdout and "plausibility: clean" in stdout
    mix = cc.load(out)
    assert mix.n_frames == round(0.25 * 120 + 0.75 * 80)
    report = json.loads(rep.read_text())
    assert report["weights"] == [0.25, 0.75]
    assert [i["extracted"] for i in report["inputs"]] == [False, False]
    assert report["output"]["frames"] == mix.n_frames
    assert report["output"]["loop_closure"] <= at_most(0.406)  # measured 0.406
    assert report["plausibility"]["clean"] is True and report["written"] == str(out)
    assert len(report["blend"]["alignments"]) == 2
    # the jog was written in BVH conventions: the blend says how it shared channels
    assert any("conventions" in n for n in report["blend"]["notes"])
    # foot skating of the blend and of each input, in the report and on one console line
    from cyclecoord.quality.contacts import skating_report

    sk = report["foot_skating"]
    assert sk["skating_frames"] == skating_report(mix)["skating_frames"]
    assert set(sk["per_foot"]) == {"lfoot", "ltoes", "rfoot", "rtoes"}
    walk_sk = report["inputs"][0]["foot_skating"]
    assert walk_sk["skating_frames"] == skating_report(cc.load(walk))["skating_frames"] > 0
    line = [ln for ln in stdout.splitlines() if "foot skating" in ln]
    assert len(line) == 1 and line[0].startswith("blend foot skating: ")
    share = f"{100 * walk_sk['skating_fraction']:.0f}%"
    assert f"(inputs: {walk_sk['skating_frames']} ({share}), " in line[0]


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--weights", "0.5,0.6"], "sum to 1"),
        (["--weights", "1.2,-0.2"], "non-negative"),
        (["--weights", "1"], "one weight per cycle"),
        (["--window", "0:10", "--window", "0:20", "--window", "0:30"], "once per input"),
    ],
)
def test_blend_refuses_bad_options(cycles, tmp_path, capsys, extra, message):
    walk, jog = cycles
    out = tmp_path / "never.bvh"
    code, stdout, err = run(capsys, "blend", walk, jog, *extra, "-o", out)
    assert code == 1
    assert message in err and "Traceback" not in err
    assert not out.exists()


def test_blend_refuses_to_overwrite_an_input(cycles, capsys):
    walk, jog = cycles
    before = walk.read_bytes()
    code, _, err = run(capsys, "blend", walk, jog, "-o", walk)
    assert code == 1 and "overwrite" in err
    assert walk.read_bytes() == before


def test_strict_refuses_an_implausible_blend(tmp_path, capsys):
    walk = one_loop("walk", 120, 0)
    arm = {("lhumerus", "ry"): 0.0, ("lhumerus", "rz"): -45.0, ("lradius", "rx"): 120.0}

    def posed(rx):
        f = np.array(walk.frames)
        for (j, d), v in {**arm, ("lhumerus", "rx"): rx}.items():
            f[:, walk.channel_index(j, d)] = v
        return walk.with_frames(f)

    # each arm pose is clear of the body; half way between them the forearm is in the chest
    a, b = tmp_path / "a.npz", tmp_path / "b.npz"
    cc.save(posed(30.0), a)
    cc.save(posed(-90.0), b)
    out, rep = tmp_path / "mix.bvh", tmp_path / "r.json"
    code, stdout, err = run(capsys, "blend", a, b, "--strict", "-o", out, "--report", rep)
    assert code == 1
    assert "plausibility" in err and "--strict" in err
    assert not out.exists()
    report = json.loads(rep.read_text())
    assert report["plausibility"]["clean"] is False and report["written"] is None
    assert report["plausibility"]["new_contact_frames"]
    # without --strict the same blend is written, with the warning
    code, stdout, err = run(capsys, "blend", a, b, "-o", out)
    assert code == 0 and out.exists() and "new limb contacts" in stdout


def test_transition_writes_a_continuous_clip(cycles, tmp_path, capsys):
    walk, jog = cycles
    out, rep = tmp_path / "t.bvh", tmp_path / "t.json"
    code, stdout, err = run(capsys, "transition", walk, jog, "--cycles", "2", "-o", out, "--report", rep)
    assert code == 0, err
    assert "transition:" in stdout
    clip = cc.load(out)
    report = json.loads(rep.read_text())
    t = report["transition"]
    assert clip.n_frames == t["lead_in_frames"] + t["ramp_frames"] + t["lead_out_frames"]
    assert t["continuity"]["max_ratio"] <= t["continuity"]["limit"] == 1.5
    assert len(report["weight"]) == clip.n_frames and report["weight"][-1] == 1.0
    from cyclecoord.quality.contacts import skating_report

    sk = report["foot_skating"]
    assert sk["skating_frames"] == skating_report(clip)["skating_frames"]
    assert [i["foot_skating"] is not None for i in report["inputs"]] == [True, True]
    assert "transition foot skating: " in stdout


def test_transition_too_short_is_refused_under_strict(cycles, tmp_path, capsys):
    walk, jog = cycles
    out = tmp_path / "t.bvh"
    code, stdout, err = run(capsys, "transition", walk, jog, "--frames", "3", "--lead-in", "0",
                            "--lead-out", "0", "--strict", "-o", out)
    assert code == 1 and "typical step" in err and not out.exists()
    assert "a ramp of" in stdout  # the note says how long a ramp would do
    with pytest.raises(SystemExit) as stop:  # the ramp length is required: a usage error
        main(["transition", str(walk), str(jog), "-o", str(out)])
    assert stop.value.code == 2 and "--frames" in capsys.readouterr().err


def test_captures_are_extracted_first(tmp_path, capsys):
    rep = tmp_path / "r.json"
    code, stdout, err = run(capsys, "blend", "example", "example:jog", "--report", rep)
    assert code == 0, err
    report = json.loads(rep.read_text())
    assert [i["extracted"] for i in report["inputs"]] == [True, True]
    assert all("repeats every" in i["reason"] for i in report["inputs"])
    assert report["inputs"][0]["extraction"]["period_frames"] > 0
    code, stdout, err = run(capsys, "blend", "example", "example:jog", "--as-cycle", "--report", rep)
    assert code == 0, err
    assert [i["extracted"] for i in json.loads(rep.read_text())["inputs"]] == [False, False]


def test_help_lists_the_commands(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    assert "blend" in out and "transition" in out
