"""Batch extraction over a folder: statuses, reports, summary.csv, resuming, pools, Dask, CLI."""

from __future__ import annotations

import csv
import hashlib
import json
import os
import shutil
from pathlib import Path

import pytest

import cyclecoord as cc
from _measured import at_most
from cyclecoord.batch import runner
from cyclecoord.batch import SUMMARY_COLUMNS, find_captures, run_batch
from cyclecoord.errors import ParameterError

_ORIGINAL_PROCESS_ONE = runner._process_one

# relative path -> (kind, seed); the two "walk" files share a stem on purpose
PERIODIC = {"walk.npz": ("walk", 1), "walk.bvh": ("walk", 2), "sub/deep/jog.bvh": ("jog", 3)}
EXPECTED = {
    "walk.npz": "ok", "walk.bvh": "ok", "sub/deep/jog.bvh": "ok",
    "sub/still.npz": "no_periodic", "sub/broken.bvh": "error",
}
N_FRAMES, PERIOD = 300, 120.0


def _capture(kind: str, seed: int) -> cc.Motion:
    return cc.datasets.make_periodic_capture(n_frames=N_FRAMES, period=PERIOD, kind=kind, random_state=seed).motion


def _build(folder: Path, periodic: dict = PERIODIC, static: bool = True, broken: bool = True) -> Path:
    for rel, (kind, seed) in periodic.items():
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        cc.save(_capture(kind, seed), folder / rel)
    (folder / "sub").mkdir(exist_ok=True)
    if static:
        cc.save(cc.datasets.make_static_capture(n_frames=N_FRAMES, random_state=0).motion, folder / "sub/still.npz")
    if broken:
        (folder / "sub/broken.bvh").write_text("this is not a BVH file\njust some garbage text\n")
    (folder / "notes.txt").write_text("not a capture: not matched by the default patterns\n")
    return folder


def _snapshot(folder: Path) -> dict:
    """Every file under ``folder`` (hidden ones included) -> content hash and mtime."""
    snap = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            snap[p.relative_to(folder).as_posix()] = (hashlib.sha256(p.read_bytes()).hexdigest(), p.stat().st_mtime_ns)
    return snap


def _figures(rows: list[dict]) -> list[dict]:
    """Rows without the wall time, which legitimately differs between runs."""
    return [{k: v for k, v in r.items() if k != "seconds"} for r in rows]


def _read_csv(path: Path) -> list[dict]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _strict_json(path: Path) -> dict:
    def no_constants(name):
        raise AssertionError(f"{path}: non-standard JSON constant {name}")

    return json.loads(path.read_text(encoding="utf-8"), parse_constant=no_constants)


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return _build(tmp_path_factory.mktemp("captures"))


@pytest.fixture(scope="module")
def first(folder, tmp_path_factory):
    """One in-process run over the folder, with the input folder's state before it."""
    before = _snapshot(folder)
    out = tmp_path_factory.mktemp("out") / "results"
    summary = run_batch(folder, out, progress=False)
    return summary, out, before


def test_discovery_is_sorted_recursive_and_filtered(folder):
    assert find_captures(folder) == sorted(EXPECTED)
    assert find_captures(folder, recursive=False) == ["walk.bvh", "walk.npz"]
    assert find_captures(folder, "*.BVH") == ["sub/broken.bvh", "sub/deep/jog.bvh", "walk.bvh"]
    assert find_captures(folder, ["sub/deep/*"]) == ["sub/deep/jog.bvh"]


def test_statuses_summary_and_reports(first, folder):
    summary, out, before = first
    assert {r["file"]: r["status"] for r in summary.rows} == EXPECTED
    assert [r["file"] for r in summary.rows] == sorted(EXPECTED)
    assert summary.counts == {"ok": 3, "no_periodic": 1, "error": 1}
    assert sorted(summary.processed) == sorted(EXPECTED) and summary.skipped == []

    table = _read_csv(out / "summary.csv")
    assert tuple(table[0]) == SUMMARY_COLUMNS
    assert [r["file"] for r in table] == sorted(EXPECTED)
    rows = {r["file"]: r for r in table}
    true_cycles = (N_FRAMES - 1) / PERIOD
    for rel in PERIODIC:
        r, row = rows[rel], summary.row(rel)
        # same-stem captures keep their suffix in the output names; others drop it
        base = rel if rel.startswith("walk.") else rel[: -len(".bvh")]
        report = _strict_json(out / f"{base}.report.json")
        assert report["batch"]["status"] == "ok" and report["batch"]["file"] == rel
        assert abs(float(r["cycles"]) - true_cycles) < 0.2
        assert float(r["cycles"]) == pytest.approx(report["cycles"], rel=1e-5)
        assert row["cycles"] == report["cycles"]
        # the period is the median complete winding (the capture's speed wobbles by up to 30%)
        assert float(r["period_frames"]) == pytest.approx(report["period_frames"], rel=1e-4)
        # measured 10.1-13.6 % from 120 (the capture's cadence wobbles by up to 30 %)
        assert abs(float(r["period_frames"]) / PERIOD - 1) <= at_most(0.136)
        assert float(r["period_seconds"]) == pytest.approx(float(r["period_frames"]) / 120.0, rel=1e-4)
        assert int(r["frames"]) == N_FRAMES and int(r["dims"]) == report["dims"] > 0
        assert 0 < float(r["birth"]) < float(r["scale"]) < float(r["death"])  # "inf" parses too
        assert float(r["birth"]) == pytest.approx(report["selected"]["birth"], rel=1e-5)
        # the typical cycle is smoother than the noisy capture: measured 0.090-0.095 of its
        # jerk (joint positions, as extract prints it)
        assert 0 < float(r["jerk_ratio"]) <= at_most(0.095)
        assert float(r["jerk_ratio"]) == pytest.approx(report["jerk"]["cycle"] / report["jerk"]["original"], rel=1e-5)
        assert float(r["loop_closure"]) == pytest.approx(report["loop_closure"], rel=1e-5)
        assert float(r["seconds"]) >= 0
        assert r["cycle_file"] == f"{base}.cycle.bvh"
        cycle = cc.load(out / r["cycle_file"])
        assert cycle.n_frames == report["cycle_length"]

    still = rows["sub/still.npz"]
    report = _strict_json(out / "sub/still.report.json")
    assert report["batch"]["status"] == "no_periodic" and report["selected"] is None
    assert len(report["barcode"]["h1"]) > 0 and "no periodic motion" in still["message"]
    assert int(still["frames"]) == N_FRAMES and still["cycles"] == "" and still["cycle_file"] == ""
    assert float(still["death"]) / float(still["birth"]) < 1.5  # its best bar is not clear
    assert not (out / "sub/still.cycle.bvh").exists()

    broken = rows["sub/broken.bvh"]
    report = _strict_json(out / "sub/broken.report.json")
    assert report["batch"]["status"] == "error" and report["batch"]["error_type"] == "ParseError"
    assert "broken.bvh:1:" in broken["message"] and "HIERARCHY" in broken["message"]
    assert broken["message"] == report["batch"]["message"] and broken["frames"] == ""

    # nothing else was written, no temporary file left behind
    written = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    assert written == sorted([
        "summary.csv", "walk.npz.report.json", "walk.npz.cycle.bvh", "walk.bvh.report.json",
        "walk.bvh.cycle.bvh", "sub/deep/jog.report.json", "sub/deep/jog.cycle.bvh",
        "sub/still.report.json", "sub/broken.report.json",
    ])
    assert _snapshot(folder) == before
    text = summary.describe()
    assert "3 ok, 1 no periodic motion, 1 error" in text and "sub/broken.bvh" in text and "summary.csv" in text


def test_rerun_skips_done_and_retries_errors_force_recomputes(first, folder):
    summary, out, before = first
    reports = sorted(out.rglob("*.report.json"))
    stamps = {p: p.stat().st_mtime_ns for p in reports}
    again = run_batch(folder, out, progress=False)
    assert again.processed == ["sub/broken.bvh"]  # errors are retried, the rest is done
    assert sorted(again.skipped) == sorted(set(EXPECTED) - {"sub/broken.bvh"})
    assert _figures(again.rows) == _figures(summary.rows)
    assert _read_csv(out / "summary.csv") and len(_read_csv(out / "summary.csv")) == len(EXPECTED)
    for p in reports:
        if p.name != "broken.report.json":
            assert p.stat().st_mtime_ns == stamps[p], p

    forced = run_batch(folder, out, force=True, progress=False)
    assert sorted(forced.processed) == sorted(EXPECTED) and forced.skipped == []
    assert all(p.stat().st_mtime_ns != stamps[p] for p in reports)
    assert _figures(forced.rows) == _figures(summary.rows)
    assert _snapshot(folder) == before


def test_resume_after_lost_report_rebuilds_a_complete_summary(first, folder, tmp_path):
    summary, out, _ = first
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    (copy / "sub/deep/jog.report.json").unlink()  # as if the run had been interrupted
    (copy / "summary.csv").unlink()
    resumed = run_batch(folder, copy, progress=False)
    assert sorted(resumed.processed) == ["sub/broken.bvh", "sub/deep/jog.bvh"]
    assert [r["file"] for r in _read_csv(copy / "summary.csv")] == sorted(EXPECTED)
    assert _figures(resumed.rows) == _figures(summary.rows)


def test_changed_input_options_or_format_recompute(tmp_path):
    src = _build(tmp_path / "in", {"a.bvh": ("walk", 4)}, static=False, broken=False)
    out = tmp_path / "out"
    first = run_batch(src, out, progress=False)
    assert first.processed == ["a.bvh"] and first.n_ok == 1
    assert run_batch(src, out, extract_options={"random_state": 0}, progress=False).processed == []  # the default
    st = (src / "a.bvh").stat()
    os.utime(src / "a.bvh", ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    assert run_batch(src, out, progress=False).processed == ["a.bvh"]
    changed = run_batch(src, out, extract_options={"n_samples": 200}, progress=False)
    assert changed.processed == ["a.bvh"]
    assert _strict_json(out / "a.report.json")["parameters"]["n_samples"] == 200
    assert (out / "a.cycle.bvh").exists()
    npz = run_batch(src, out, extract_options={"n_samples": 200}, write_cycles="npz", progress=False)
    assert npz.processed == ["a.bvh"] and npz.row("a.bvh")["cycle_file"] == "a.cycle.npz"
    assert (out / "a.cycle.npz").exists() and not (out / "a.cycle.bvh").exists()  # stale cycle removed
    none = run_batch(src, out, extract_options={"n_samples": 200}, write_cycles=None, progress=False)
    assert none.processed == ["a.bvh"] and not list(out.glob("a.cycle.*"))
    assert none.row("a.bvh")["cycle_file"] is None


def test_two_processes_give_the_same_numbers(first, folder, tmp_path):
    summary, _, before = first
    pooled = run_batch(folder, tmp_path / "out", jobs=2, progress=False)
    assert _figures(pooled.rows) == _figures(summary.rows)
    assert sorted(pooled.processed) == sorted(EXPECTED)
    assert _snapshot(folder) == before


def test_dask_local_cluster_gives_the_same_summary(first, folder, tmp_path):
    import distributed  # dask[distributed] is in the 'test' extra

    summary, _, before = first
    with distributed.LocalCluster(
        processes=False, n_workers=1, threads_per_worker=1, dashboard_address=None
    ) as cluster:
        on_dask = run_batch(folder, tmp_path / "out", scheduler=cluster.scheduler_address, progress=False)
    assert _figures(on_dask.rows) == _figures(summary.rows)
    got = [{k: v for k, v in r.items() if k != "seconds"} for r in _read_csv(tmp_path / "out/summary.csv")]
    want = [{k: v for k, v in r.items() if k != "seconds"} for r in _read_csv(first[1] / "summary.csv")]
    assert got == want
    assert _snapshot(folder) == before


def _crash_on_marker(task):
    """Worker stand-in that dies outright (as if killed by the OS) on files named crash*."""
    if Path(task.file).name.startswith("crash"):
        os._exit(3)
    return _ORIGINAL_PROCESS_ONE(task)


def test_a_dying_worker_fails_only_its_capture(tmp_path, monkeypatch):
    src = _build(tmp_path / "in", {"a.npz": ("walk", 1), "crash.npz": ("walk", 2), "z.npz": ("squat", 4)},
                 static=False, broken=False)
    monkeypatch.setattr(runner, "_process_one", _crash_on_marker)
    result = run_batch(src, tmp_path / "out", jobs=2, progress=False)
    assert {r["file"]: r["status"] for r in result.rows} == {"a.npz": "ok", "crash.npz": "error", "z.npz": "ok"}
    assert "worker process died" in result.row("crash.npz")["message"]
    report = _strict_json(tmp_path / "out/crash.report.json")
    assert report["batch"]["status"] == "error" and report["batch"]["file"] == "crash.npz"


def test_memory_error_is_recorded_and_the_batch_goes_on(tmp_path, monkeypatch):
    import cyclecoord.periodic.pipeline as pipeline

    src = _build(tmp_path / "in", {"b.npz": ("walk", 2)}, static=False, broken=False)
    cc.save(cc.datasets.make_periodic_capture(n_frames=250, random_state=1).motion, src / "a.npz")
    real = pipeline.extract

    def greedy(motion, **options):
        if motion.n_frames == 250:  # a.npz
            raise MemoryError("cannot allocate 80 GiB")
        return real(motion, **options)

    monkeypatch.setattr(pipeline, "extract", greedy)
    result = run_batch(src, tmp_path / "out", progress=False)
    assert result.row("a.npz")["status"] == "error" and result.row("b.npz")["status"] == "ok"
    assert result.row("a.npz")["message"] == "MemoryError: cannot allocate 80 GiB"
    assert "Traceback" in _strict_json(tmp_path / "out/a.report.json")["batch"]["traceback"]


def test_bad_arguments_raise_before_anything_is_written(folder, tmp_path):
    before = _snapshot(folder)
    with pytest.raises(ParameterError, match="inside"):
        run_batch(folder, folder / "results", progress=False)
    with pytest.raises(ParameterError, match="inside"):
        run_batch(folder, folder, progress=False)
    with pytest.raises(ParameterError, match="unknown extract option"):
        run_batch(folder, tmp_path / "o1", extract_options={"pcaa": 3}, progress=False)
    with pytest.raises(ParameterError, match="jobs"):
        run_batch(folder, tmp_path / "o2", jobs=-1, progress=False)
    with pytest.raises(ParameterError, match="write_cycles"):
        run_batch(folder, tmp_path / "o3", write_cycles="fbx", progress=False)
    with pytest.raises(ParameterError, match="no such folder"):
        run_batch(tmp_path / "missing", tmp_path / "o4", progress=False)
    assert _snapshot(folder) == before
    assert not any((tmp_path / f"o{i}").exists() for i in range(1, 5))


def test_cli_exit_codes_and_summary(tmp_path, capsys):
    from cyclecoord.cli import main

    good = _build(tmp_path / "good", {"a.npz": ("walk", 1)}, broken=False)
    code = main(["batch", str(good), "-o", str(tmp_path / "out_good"), "--jobs", "1", "--seed", "0"])
    out = capsys.readouterr().out
    assert code == 0
    assert "1 ok, 1 no periodic motion, 0 errors" in out and str(tmp_path / "out_good" / "summary.csv") in out
    rows = {r["file"]: r["status"] for r in _read_csv(tmp_path / "out_good/summary.csv")}
    assert rows == {"a.npz": "ok", "sub/still.npz": "no_periodic"}

    bad = _build(tmp_path / "bad", {"a.npz": ("walk", 1)}, static=False)
    before = _snapshot(bad)
    code = main(["batch", str(bad), "-o", str(tmp_path / "out_bad"), "--cycles", "none", "--pca", "8"])
    out = capsys.readouterr().out
    assert code == 1
    assert "1 ok, 0 no periodic motion, 1 error" in out and "sub/broken.bvh" in out
    assert _strict_json(tmp_path / "out_bad/a.report.json")["dims"] == 8
    assert not list((tmp_path / "out_bad").glob("*.cycle.*"))
    assert _snapshot(bad) == before

    code = main(["batch", str(bad), "-o", str(bad / "inside")])
    assert code == 1 and "inside" in capsys.readouterr().err
    assert not (bad / "inside").exists()


def test_a_changed_skeleton_makes_an_amc_report_stale(tmp_path):
    src = tmp_path / "in"
    src.mkdir()
    cc.save(_capture("walk", 5), src / "07_01.amc")  # writes 07.asf beside it
    assert (src / "07.asf").is_file()
    out = tmp_path / "out"
    assert run_batch(src, out, progress=False).processed == ["07_01.amc"]
    block = _strict_json(out / "07_01.report.json")["batch"]
    assert block["skeleton"][0] == str((src / "07.asf").resolve())
    assert run_batch(src, out, progress=False).processed == []  # nothing changed
    st = (src / "07.asf").stat()
    os.utime(src / "07.asf", ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    assert run_batch(src, out, progress=False).processed == ["07_01.amc"]
    assert run_batch(src, out, progress=False).processed == []
    # the skeleton gone: the capture is retried and fails with a message naming the problem
    (src / "07.asf").unlink()
    gone = run_batch(src, out, progress=False)
    assert gone.processed == ["07_01.amc"] and gone.row("07_01.amc")["status"] == "error"
    assert "no skeleton found" in gone.row("07_01.amc")["message"]


def test_cycles_in_the_formats_extract_writes(tmp_path):
    """--cycles glb/gltf/usda/csv: the cycle written by suffix as extract -o writes it; a
    capture without a skeleton falls back to .npz; a format change removes the old file."""
    import numpy as np

    src = _build(tmp_path / "in", {"a.bvh": ("walk", 1)}, static=False, broken=False)
    bare = _capture("jog", 3)
    cc.save(cc.Motion(bare.frames, bare.channels, fps=bare.fps), src / "bare.npz")
    out = tmp_path / "out"
    opts = {"n_samples": 200}
    ref = run_batch(src, out, extract_options=opts, write_cycles="npz", progress=False)
    assert ref.n_ok == 2
    cycle = cc.load(out / "a.cycle.npz")
    want = cycle.positions()
    for fmt in ("glb", "gltf", "usda", "csv"):
        s = run_batch(src, out, extract_options=opts, write_cycles=fmt, progress=False)
        assert s.processed == ["a.bvh", "bare.npz"]  # the format is part of the options
        assert s.row("a.bvh")["cycle_file"] == f"a.cycle.{fmt}"
        names = sorted(p.name for p in out.glob("a.cycle.*"))
        assert names == (["a.cycle.bin", "a.cycle.gltf"] if fmt == "gltf" else [f"a.cycle.{fmt}"])
        if fmt == "csv":
            back = cc.load(out / "a.cycle.csv", fps=cycle.fps)
            assert np.allclose(back.frames, cycle.frames, atol=1e-6)
        else:
            got = cc.load(out / f"a.cycle.{fmt}").positions()
            assert got.positions.shape[0] == cycle.n_frames
            for j in ("root", "lfoot", "rtoes", "head"):
                assert np.abs(got[j] - want[j]).max() < 1e-3, (fmt, j)
        # no skeleton: the cycle is written as .npz, and the report says why
        no_skel = s.row("bare.npz")["cycle_file"]
        skeleton_format = fmt != "csv"
        assert no_skel == ("bare.cycle.npz" if skeleton_format else "bare.cycle.csv")
        if skeleton_format:
            assert "no skeleton" in _strict_json(out / "bare.report.json")["batch"]["message"]
    assert run_batch(src, out, extract_options=opts, write_cycles="npz", progress=False).n_ok == 2
    assert sorted(p.name for p in out.glob("a.cycle.*")) == ["a.cycle.npz"]
    with pytest.raises(ParameterError, match="write_cycles must be one of"):
        run_batch(src, out, write_cycles="fbx", progress=False)
    from cyclecoord.cli import main

    assert main(["batch", str(src), "-o", str(tmp_path / "cli"), "--cycles", "glb", "--no-progress"]) == 0
    assert (tmp_path / "cli" / "a.cycle.glb").is_file()
