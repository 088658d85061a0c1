"""The notebooks in notebooks/ are committed without outputs and run top to bottom without error."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest

NOTEBOOKS = Path(__file__).resolve().parents[1] / "notebooks"
PATHS = sorted(NOTEBOOKS.glob("*.ipynb"))
IDS = [p.name for p in PATHS]


def test_notebooks_exist():
    names = {p.name for p in PATHS}
    assert {"01_quickstart.ipynb", "02_walk_cycle_69_01.ipynb"} <= names


@pytest.mark.parametrize("path", PATHS, ids=IDS)
def test_committed_without_outputs(path: Path):
    nb = json.loads(path.read_text(encoding="utf-8"))
    assert nb["nbformat"] == 4
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert code, "a notebook without code"
    for i, cell in enumerate(code):
        assert cell.get("outputs", []) == [], f"{path.name}: code cell {i} has saved outputs (strip them)"
        assert cell.get("execution_count") is None, f"{path.name}: code cell {i} has an execution count"
    assert nb["metadata"]["kernelspec"]["name"] == "python3"


@pytest.mark.slow
@pytest.mark.parametrize("path", PATHS, ids=IDS)
def test_notebook_runs(path: Path):
    import ipykernel  # noqa: F401  (the kernel the client starts; all three in the 'test' extra)
    import nbclient
    import nbformat

    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(
        nb,
        timeout=180,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOKS)}},
        allow_errors=False,
    )
    t0 = time.perf_counter()
    try:
        client.execute()
    except nbclient.exceptions.CellExecutionError as exc:  # name the cell that failed
        pytest.fail(f"{path.name} failed:\n{exc}")
    elapsed = time.perf_counter() - t0
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert not errors
    # every figure cell ("fig = plot....") displayed a picture, and the GIF cell showed its animation
    for c in nb.cells:
        if c.cell_type != "code":
            continue
        kinds = {k for o in c.get("outputs", []) for k in o.get("data", {})}
        if "fig = plot." in c.source:
            assert "image/png" in kinds, f"{path.name}: figure cell shows no image:\n{c.source}"
        if "plot.render(" in c.source:
            assert "image/gif" in kinds or "image/png" in kinds, f"{path.name}: render cell shows no animation"
    assert elapsed < 120, f"{path.name} took {elapsed:.0f} s"
