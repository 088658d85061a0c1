"""Several motions in one capture: classes, excitation, segments, labels and the CLI."""

import json

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.cli import main
from cyclecoord.detection import Segment, best_match_accuracy, boundary_errors, detect, excitation


@pytest.fixture(scope="module", params=[(("walk", "jumping_jack", "arm_circles"), 0), (("walk", "jog", "squat"), 1), (("squat", "arm_circles", "jog"), 2)])
def chain(request):
    kinds, seed = request.param
    cap = cc.datasets.make_motion_chain(kinds=kinds, random_state=seed)
    return cap, detect(cap.motion)


def test_chain_motions_are_found_and_segmented(chain):
    cap, res = chain
    acc, match = best_match_accuracy(res.labels, cap.labels)
    assert acc >= 0.90
    assert res.n_motions == 3 and sorted(match.values()) == [0, 1, 2]
    assert max(boundary_errors(res.segments, cap.boundaries, cap.motion.n_frames)) <= 30
    # every segment counts its cycles like the truth: segment length / true period
    periods = dict(zip([k for _, _, k in cap.boundaries], cap.motion.metadata["periods"]))
    for sg in res.segments:
        kind = cap.boundaries[match[sg.motion]][2]
        assert sg.period_frames == pytest.approx(periods[kind], rel=0.25)


def test_report_and_labels(chain):
    cap, res = chain
    rep = res.to_report()
    assert len(rep["labels"]) == cap.motion.n_frames
    assert set(rep["labels"]) <= {-1, 0, 1, 2}
    for s in rep["segments"]:
        assert set(s) >= {"start", "stop", "motion", "classes", "birth", "death", "scale", "cycles", "period_frames"}
    assert {c["index"] for c in rep["chosen_classes"]} <= {c["index"] for c in rep["classes"]}


@pytest.mark.parametrize("make", [cc.datasets.make_static_capture, cc.datasets.make_random_walk_capture])
def test_nothing_periodic_gives_no_segments(make):
    with pytest.raises(cc.NoPeriodicMotionError) as info:
        detect(make(n_frames=800, random_state=0).motion)
    assert info.value.result.segments == []
    assert np.all(info.value.result.labels == -1)


def test_excitation_measures_steady_advance():
    t = np.arange(600)
    theta = np.where(t < 300, 0.3, np.mod((t - 300) / 100.0 + 0.3, 1.0))
    speed, cons = excitation(theta, 31)
    assert np.all(np.abs(speed[:250]) < 1e-12)
    np.testing.assert_allclose(speed[350:550], 0.01, atol=1e-9)
    assert np.all(cons[350:550] == 1.0)
    jitter = np.mod(0.5 + 0.01 * np.random.default_rng(0).standard_normal(600), 1.0)
    s2, c2 = excitation(jitter, 31)
    assert np.median(c2) < 0.4 and np.max(np.abs(s2[40:-40])) < 0.002


def test_scoring_helpers():
    truth = np.array([0] * 10 + [-1] * 5 + [1] * 10)
    pred = np.array([5] * 12 + [-1] * 3 + [7] * 10)
    acc, match = best_match_accuracy(pred, truth)
    assert acc == 1.0 and match == {5: 0, 7: 1}
    segs = [Segment(0, 12, 0, (0,), 1, 2, 1.5, 1, 10), Segment(15, 25, 1, (1,), 1, 2, 1.5, 1, 10)]
    # a boundary inside the transition (10-15) is exact; one 2 frames short of it is off by 2
    assert boundary_errors(segs, [(0, 10, "a"), (15, 25, "b")], 25) == [0, 0, 0]
    early = [Segment(0, 8, 0, (0,), 1, 2, 1.5, 1, 10), Segment(15, 25, 1, (1,), 1, 2, 1.5, 1, 10)]
    assert boundary_errors(early, [(0, 10, "a"), (15, 25, "b")], 25) == [0, 2, 0]


def test_cli_detect(tmp_path, capsys):
    rep, out = tmp_path / "d.json", tmp_path / "cycles"
    code = main(["detect", "example:chain", "--report", str(rep), "--extract", str(out)])
    assert code == 0
    r = json.loads(rep.read_text())
    assert r["n_motions"] == 3 and len(r["labels"]) == r["n_frames"]
    cycles = sorted(out.glob("motion*_cycle.bvh"))
    assert len(cycles) == 3 and all(cc.load(p).n_frames > 50 for p in cycles)
    src = tmp_path / "still.npz"
    cc.save(cc.datasets.make_static_capture(n_frames=600, random_state=1).motion, src)
    capsys.readouterr()
    assert main(["detect", str(src), "--report", str(rep)]) == 3
    assert json.loads(rep.read_text())["segments"] == []
