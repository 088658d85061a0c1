"""A small range of benchmarks/fuzz_formats.py (issue 26 part 3) in CI: a few dozen mutated
glTF, USD, latent-model and script cases through the commands that read them, with no
traceback, hang, crash, changed input or refusal of more than one line."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

FUZZ = Path(__file__).resolve().parents[1] / "benchmarks" / "fuzz_formats.py"


def _load():
    spec = importlib.util.spec_from_file_location("fuzz_formats", FUZZ)
    module = importlib.util.module_from_spec(spec)
    sys.modules["fuzz_formats"] = module  # dataclasses need the module registered
    spec.loader.exec_module(module)
    return module


fuzz = _load()


@pytest.mark.parametrize("fmt, n", [("gltf", 30), ("usd", 40), ("model", 40), ("script", 40)])
def test_a_small_range_of_each_format(fmt, n, tmp_path):
    if fmt == "usd":
        pytest.importorskip("pxr")
    summary = fuzz.run(fmt, start=0, n=n, workers=2, timeout=60, out=tmp_path, quiet=True)
    assert sum(summary["counts"].values()) == n, summary
    assert summary["failures"] == 0, summary


def test_cases_are_the_same_for_the_same_index(tmp_path):
    seeds = fuzz.make_seeds(tmp_path / "seeds")
    for fmt in ("gltf", "script"):
        a = fuzz.make_case(fmt, 7, seeds, tmp_path / "w")
        b = fuzz.make_case(fmt, 7, seeds, tmp_path / "w")
        assert a.files == b.files and a.commands == b.commands and a.log == b.log
        assert a.files != fuzz.make_case(fmt, 8, seeds, tmp_path / "w").files
