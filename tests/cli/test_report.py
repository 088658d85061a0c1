"""``extract`` and ``batch`` write the same partial report for a capture with nothing
periodic: both build it with :func:`cyclecoord.periodic.report.partial_report`."""

import json

import cyclecoord as cc
from cyclecoord.cli import main
from cyclecoord.errors import NoPeriodicMotionError
from cyclecoord.periodic.report import partial_report


def test_extract_and_batch_write_the_same_partial_report(tmp_path):
    captures = tmp_path / "captures"
    captures.mkdir()
    src = captures / "static.npz"
    cc.save(cc.datasets.make_static_capture(random_state=0).motion, src)
    rep = tmp_path / "r.json"
    assert main(["extract", str(src), "--report", str(rep)]) == 3
    single = json.loads(rep.read_text())
    assert main(["batch", str(captures), "-o", str(tmp_path / "out"), "--no-progress"]) == 0
    (written,) = (tmp_path / "out").glob("static*.report.json")
    batched = json.loads(written.read_text())
    shared = {k: v for k, v in batched.items() if k != "batch"}
    # extract alone tries the options that might help after a refusal (batch does not: it
    # would multiply a batch's cost by the refusals)
    assert single.pop("suggestions") == []
    assert set(single) == set(shared)
    for key in ("source", "frames", "n_frames", "fps", "dims", "prime"):
        assert single[key] == shared[key], key
    assert single["selected"] is None and shared["selected"] is None
    assert single["barcode"]["h1"] and shared["barcode"]["h1"]


def test_partial_report_without_a_partial_result():
    exc = NoPeriodicMotionError("nothing to read", result=None)
    assert partial_report(exc) == {"selected": None, "error": "nothing to read"}
