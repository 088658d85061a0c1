"""The command line: outputs, reports, exit codes and error messages."""

import json

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.cli import main


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_extract_example_writes_cycle_and_report(tmp_path, capsys):
    bvh, rep = tmp_path / "cycle.bvh", tmp_path / "r.json"
    code, out, err = run(capsys, "extract", "example", "-o", bvh, "--report", rep)
    assert code == 0, err
    assert "cycles over the steady frames" in out and "last-to-first step" in out
    cycle = cc.load(bvh)
    report = json.loads(rep.read_text())
    assert cycle.n_frames == report["cycle_length"] == round(report["period_frames"])
    assert report["cycles"] == pytest.approx(479 / 120, abs=0.1)
    assert len(report["coordinate"]) == report["n_frames"] == 480
    assert report["selected"]["index"] == 0
    assert report["dims"] == 62
    assert all(v >= 0 for v in report["timings"].values())


def test_extract_lock_feet_writes_a_cycle_whose_feet_stay(tmp_path, capsys):
    from cyclecoord.quality.contacts import foot_skating

    plain, locked, rep = tmp_path / "plain.bvh", tmp_path / "locked.bvh", tmp_path / "r.json"
    code, out, err = run(capsys, "extract", "example", "-o", plain)
    assert code == 0, err
    assert "feet: planted feet slide" in out and "--lock-feet" in out
    code, out, err = run(capsys, "extract", "example", "-o", locked, "--lock-feet", "--report", rep)
    assert code == 0, err
    report = json.loads(rep.read_text())
    lock = report["foot_lock"]
    assert lock["before"]["skating_frames"] > 0 and lock["after"]["skating_frames"] == 0
    assert f"skating frames {lock['before']['skating_frames']} -> 0" in out
    a, b = cc.load(plain), cc.load(locked)
    assert foot_skating(b).skating_frames < foot_skating(a).skating_frames
    # only the legs moved: every channel of the other joints is as extracted
    legs = ("femur", "tibia", "foot", "toes")
    others = [i for i, (j, _) in enumerate(a.channels) if not j.lower().endswith(legs)]
    np.testing.assert_allclose(b.frames[:, others], a.frames[:, others], atol=1e-4)
    moved = {k for k, v in lock["joint_change_degrees"].items() if v > 0}
    assert moved and all(k.lower().endswith(legs) for k in moved)


def test_extract_options_reach_the_pipeline(tmp_path, capsys):
    rep = tmp_path / "r.json"
    code, out, err = run(capsys, "extract", "example", "--frames", "0:300", "--pca", "5", "--max-scale", "30",
                         "--samples", "200", "--neighbors", "8", "--timing", "coordinate", "--report", rep)
    assert code == 0, err
    r = json.loads(rep.read_text())
    assert r["frames"] == [0, 300] and r["dims"] == 5 and r["threshold"] == 30
    assert r["parameters"]["timing"] == "coordinate" and r["parameters"]["n_neighbors"] == 8
    assert r["bandwidth_frames"] == pytest.approx(8 / (300 * np.sqrt(2 * np.pi)) * r["period_frames"])
    code, out, err = run(capsys, "extract", "example", "--travel", "straight", "--no-steady", "--min-turns", "2",
                         "--report", rep)
    assert code == 0, err
    r = json.loads(rep.read_text())
    assert r["parameters"]["travel"] == "straight" and r["parameters"]["steady"] is False
    assert r["parameters"]["min_turns"] == 2 and r["used_frames"] == [[0, 480]]


def test_extract_bandwidth_option(tmp_path, capsys):
    rep = tmp_path / "r.json"
    code, out, err = run(capsys, "extract", "example", "--bandwidth", "auto", "--report", rep)
    assert code == 0, err
    assert "(cross-validated)" in out
    chosen = json.loads(rep.read_text())["bandwidth_frames"]
    assert chosen > 0 and f"kernel width {chosen:.3g} frame" in out  # "1 frame", "2.5 frames"
    code, out, err = run(capsys, "extract", "example", "--bandwidth", "3.5", "--report", rep)
    assert code == 0 and json.loads(rep.read_text())["bandwidth_frames"] == 3.5
    with pytest.raises(SystemExit):
        run(capsys, "extract", "example", "--bandwidth", "wide")
    code, out, err = run(capsys, "extract", "example", "--bandwidth", "auto", "--weighting", "mean",
                         "--timing", "coordinate")
    assert code == 1 and "needs weighting='kernel'" in err and "Traceback" not in err


def test_no_periodic_motion_exits_3_and_still_reports(tmp_path, capsys):
    src = tmp_path / "static.npz"
    cc.save(cc.datasets.make_static_capture(random_state=0).motion, src)
    rep = tmp_path / "r.json"
    code, out, err = run(capsys, "extract", src, "--report", rep, "-o", tmp_path / "never.bvh")
    assert code == 3
    assert "no periodic motion" in err
    report = json.loads(rep.read_text())
    assert report["selected"] is None and report["barcode"]["h1"]
    assert not (tmp_path / "never.bvh").exists()


def test_bad_input_names_file_and_line(tmp_path, capsys):
    bad = tmp_path / "bad.bvh"
    bad.write_text("HIERARCHY\nROOT hips\n{\n  OFFSET 0 0 zero\n")
    code, out, err = run(capsys, "extract", bad)
    assert code == 1
    assert "bad.bvh:4" in err and "Traceback" not in err


def test_missing_file_and_bad_options(tmp_path, capsys):
    code, _, err = run(capsys, "extract", tmp_path / "nope.amc")
    assert code == 1 and "nope.amc" in err
    code, _, err = run(capsys, "extract", "example", "--prime", "11")
    assert code == 1 and "prime" in err
    code, _, err = run(capsys, "extract", "example", "-o", tmp_path / "out.xyz")
    assert code == 1 and ".xyz" in err
    with pytest.raises(SystemExit) as exc:
        main(["extract", "example", "--frames", "12"])
    assert exc.value.code == 2


def test_failed_run_keeps_an_existing_output(tmp_path, capsys):
    out = tmp_path / "cycle.npz"
    out.write_bytes(b"precious")
    src = tmp_path / "static.npz"
    cc.save(cc.datasets.make_static_capture(random_state=1).motion, src)
    code, _, _ = run(capsys, "extract", src, "-o", out)
    assert code == 3 and out.read_bytes() == b"precious"


def test_barcode_json(capsys):
    code, out, _ = run(capsys, "barcode", "example", "--json")
    assert code == 0
    bc = json.loads(out)
    assert bc["h0"][-1][1] is None
    pers = [(d if d is not None else bc["threshold"]) - b for b, d in bc["h1"]]
    assert pers[0] > 5 * pers[1]  # the walk's loop stands out


def test_convert_round_trip_and_refuses_to_overwrite(tmp_path, capsys):
    src = tmp_path / "walk.npz"
    m = cc.datasets.example_capture().motion
    cc.save(m, src)
    code, out, err = run(capsys, "convert", src, "-o", tmp_path / "walk.bvh")
    assert code == 0, err
    code, out, err = run(capsys, "convert", tmp_path / "walk.bvh", "-o", tmp_path / "walk.csv")
    assert code == 0, err
    back = cc.load(tmp_path / "walk.csv")
    pos_a = m.positions().positions
    pos_b = cc.load(tmp_path / "walk.bvh").positions().positions
    np.testing.assert_allclose(pos_b, pos_a, atol=1e-3 * m.skeleton.total_length())
    assert back.n_frames == m.n_frames
    code, _, err = run(capsys, "convert", src, "-o", src)
    assert code == 1 and "overwrite" in err


def test_convert_cmu_amc_to_bvh_and_back(cmu_dir, tmp_path, capsys):
    src = cmu_dir / "69" / "69_01.amc"
    code, _, err = run(capsys, "convert", src, "-o", tmp_path / "69_01.bvh")
    assert code == 0, err
    code, _, err = run(capsys, "convert", tmp_path / "69_01.bvh", "-o", tmp_path / "back.amc")
    assert code == 0, err
    a = cc.load(src).positions()
    b = cc.load(tmp_path / "back.amc").positions()
    common = [n for n in a.names if n in b.names]
    assert len(common) >= 31
    ia = [a.names.index(n) for n in common]
    ib = [b.names.index(n) for n in common]
    np.testing.assert_allclose(b.positions[:, ib], a.positions[:, ia], atol=1e-3)


def test_help_teaches(capsys):
    with pytest.raises(SystemExit):
        main(["extract", "--help"])
    out = capsys.readouterr().out
    for opt in ("--frames", "--pca", "--max-scale", "--scale", "--class", "--report", "--temporal", "--normalize"):
        assert opt in out
