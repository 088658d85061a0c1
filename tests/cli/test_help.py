"""Help and console that tell the truth (issue 25 item 3)."""

from __future__ import annotations

import argparse
import os

import pytest

import cyclecoord as cc
from cyclecoord import datasets
from cyclecoord.cli import main
from cyclecoord.cli.main import build_parser
from cyclecoord.errors import ParameterError

FORMATS = ("ASF/AMC", "BVH", "NPZ", "CSV", ".glb", ".gltf", ".usda", ".usdc", ".usd")


def _commands(parser: argparse.ArgumentParser, words=("cyclecoord",)):
    yield " ".join(words), parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _commands(sub, (*words, name))


def _help(argv: list[str], capsys) -> str:
    os.environ["COLUMNS"] = "200"
    try:
        with pytest.raises(SystemExit):
            main([*argv, "--help"])
    finally:
        del os.environ["COLUMNS"]
    return capsys.readouterr().out


def test_every_option_of_every_command_has_help():
    missing = []
    commands = dict(_commands(build_parser()))
    assert {"cyclecoord extract", "cyclecoord latent fit", "cyclecoord animate",
            "cyclecoord transition", "cyclecoord graph"} <= set(commands)
    for words, parser in commands.items():
        for action in parser._actions:
            if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
                continue
            if not action.help or action.help == argparse.SUPPRESS or not action.help.strip():
                missing.append(f"{words} {'/'.join(action.option_strings) or action.dest}")
    assert not missing, f"options without help: {missing}"


@pytest.mark.parametrize("argv", [[], ["convert"]], ids=["cyclecoord", "convert"])
def test_help_lists_every_format(argv, capsys):
    text = _help(argv, capsys)
    for fmt in FORMATS:
        assert fmt in text, f"{' '.join(['cyclecoord', *argv])} --help does not list {fmt}"


def test_latent_fit_and_animate_say_what_o_writes(capsys):
    assert "model file to write" in _help(["latent", "fit"], capsys)
    assert "synthesised motion" in _help(["animate"], capsys)


@pytest.mark.parametrize("argv", [["detect"], ["batch"], ["graph"], ["latent", "fit"],
                                  ["animate"], ["render"]])
def test_commands_that_draw_a_progress_bar_take_no_progress(argv, capsys):
    assert "--no-progress" in _help(argv, capsys)


# ------------------------------------------------------------ graph --start as a file
def test_graph_start_is_matched_as_a_file(tmp_path, monkeypatch):
    from cyclecoord.cli.graph import _find

    (tmp_path / "data").mkdir()
    (tmp_path / "other").mkdir()
    for rel in ("data/35_16.amc", "data/35_07.amc", "other/35_07.amc"):
        (tmp_path / rel).write_text("")
    monkeypatch.chdir(tmp_path)
    inputs = ["data/35_16.amc", "data/35_07.amc"]
    motions = ["take 16", "take 07"]
    assert _find("35_16.amc", inputs, motions) == "take 16"  # a bare name matching one input
    assert _find("./data/35_16.amc", inputs, motions) == "take 16"  # the same file, two ways
    assert _find(str(tmp_path / "data" / "35_07.amc"), inputs, motions) == "take 07"
    (tmp_path / "link.amc").symlink_to(tmp_path / "data" / "35_16.amc")
    assert _find("link.amc", inputs, motions) == "take 16"
    two = ["data/35_07.amc", "other/35_07.amc"]
    with pytest.raises(ParameterError, match="data/35_07.amc, other/35_07.amc"):
        _find("35_07.amc", two, motions)
    assert _find("data/35_07.amc", two, motions) == "take 16"  # the path picks one


@pytest.mark.slow
def test_graph_start_names_a_take_given_with_a_folder(tmp_path, monkeypatch, capsys):
    (tmp_path / "takes").mkdir()
    for seed, name in ((0, "a.bvh"), (1, "b.bvh")):
        m = datasets.make_periodic_capture(n_frames=240, random_state=seed).motion
        cc.save(m, tmp_path / "takes" / name)
    monkeypatch.chdir(tmp_path)
    code = main(["graph", "takes/a.bvh", "takes/b.bvh", "--start", "b.bvh:10", "--frames", "60",
                 "-o", "out.bvh"])
    assert code == 0, capsys.readouterr().err
    assert (tmp_path / "out.bvh").is_file()


# ------------------------------------------------------------------ words and numbers
def test_plurals_and_si_prefixes():
    from cyclecoord._words import plural, si

    assert plural(1, "segment") == "1 segment" and plural(2, "segment") == "2 segments"
    assert plural(1.5, "cycle") == "1.50 cycles"
    assert si(4.453e7, "deg/s³") == "44.5 Mdeg/s³"
    assert si(999.96, "deg/s³") == "1 kdeg/s³"
    assert si(0.5, "m") == "500 mm"


@pytest.mark.slow
def test_blend_prints_jerk_as_a_ratio_and_with_a_prefix(tmp_path, capsys):
    walk, jog = tmp_path / "w.bvh", tmp_path / "j.bvh"
    assert main(["extract", "example", "-o", str(walk)]) == 0
    assert main(["extract", "example:jog", "-o", str(jog)]) == 0
    capsys.readouterr()
    assert main(["blend", str(walk), str(jog), "-o", str(tmp_path / "b.bvh")]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("blend "))
    # joint positions (the cycles have skeletons): metres per second cubed, as extract
    assert "x the inputs' mean" in line and "m/s³" in line and "largest step" in line
    assert "e+" not in line and "e-" not in line
