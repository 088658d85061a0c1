"""No command writes over one of its inputs: every output option, through symlinks, hard
links and relative paths (issues 18 and 26).  Every refusal happens before any computation."""

import argparse
import json
import os
import re
from pathlib import Path

import pytest

import cyclecoord as cc
from cyclecoord.cli import main
from cyclecoord.cli._outputs import OUTPUT_FLAGS, Paths
from cyclecoord.cli.main import build_parser
from cyclecoord.errors import ParameterError
from cyclecoord.io import input_files, refuse_clobber, same_file


@pytest.fixture(scope="module")
def captures(tmp_path_factory):
    """A short BVH walk, the same as AMC + ASF, in their own folder."""
    d = tmp_path_factory.mktemp("captures")
    walk = cc.datasets.example_capture().motion[:150]
    cc.save(walk, d / "walk.bvh")
    cc.save(walk, d / "s_01.amc")  # its skeleton goes to s.asf
    return d


def digest(folder: Path) -> dict:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


def refused(capsys, cwd, monkeypatch, *argv) -> str:
    monkeypatch.chdir(cwd)
    before = digest(cwd)
    code = main([str(a) for a in argv])
    err = capsys.readouterr().err
    assert code == 1, err
    assert "would overwrite" in err or "would write" in err, err
    assert "\n" not in err.strip(), err
    assert digest(cwd) == before  # nothing written, nothing changed
    return err


def test_extract_outputs(captures, capsys, monkeypatch):
    def run(*argv):
        return refused(capsys, captures, monkeypatch, *argv)

    # the issue's cases: -o onto the input, as given and through a relative detour
    run("extract", "walk.bvh", "-o", "walk.bvh")
    run("extract", "walk.bvh", "-o", f"../{captures.name}/walk.bvh")
    run("extract", "s_01.amc", "--frames", "0:100", "-o", "s_01.amc")
    run("extract", "s_01.amc", "-o", str(captures / "s_01.amc"))
    os.symlink("walk.bvh", captures / "link.npz")
    try:
        err = run("extract", "walk.bvh", "--save-model", "link.npz")
        assert "--save-model" in err
    finally:
        (captures / "link.npz").unlink()
    # the AMC's skeleton is an input too (reached through a symlinked name)
    os.symlink("s.asf", captures / "sk.json")
    try:
        err = run("extract", "s_01.amc", "--report", "sk.json")
        assert "s.asf" in err and "--report" in err
    finally:
        (captures / "sk.json").unlink()


def test_extract_plot_folder_and_outputs_naming_one_file(captures, tmp_path, capsys, monkeypatch):
    # a symlinked input whose real file sits in the --plot folder under a figure's name
    figs = tmp_path / "figs"
    figs.mkdir()
    (figs / "barcode.png").write_bytes((captures / "walk.bvh").read_bytes())
    os.symlink(figs / "barcode.png", tmp_path / "in.bvh")
    refused(capsys, tmp_path, monkeypatch, "extract", "in.bvh", "--plot", "figs")
    code = main(["extract", str(captures / "walk.bvh"), "-o", str(tmp_path / "a.npz"),
                 "--save-model", str(tmp_path / "a.npz")])
    assert code == 1 and "name the same file" in capsys.readouterr().err


def test_detect_outputs(captures, tmp_path, capsys, monkeypatch):
    os.symlink(captures / "walk.bvh", tmp_path / "walk.json")
    refused(capsys, tmp_path, monkeypatch, "detect", str(captures / "walk.bvh"),
            "--report", "walk.json")
    (tmp_path / "walk.json").unlink()
    # --extract writes motion<k>_cycle.bvh: an input of that name in the folder is refused
    (tmp_path / "motion0_cycle.bvh").write_bytes((captures / "walk.bvh").read_bytes())
    refused(capsys, tmp_path, monkeypatch, "detect", "motion0_cycle.bvh", "--extract", ".")


def test_render_convert_and_hard_links(captures, tmp_path, capsys, monkeypatch):
    os.symlink(captures / "walk.bvh", tmp_path / "walk.gif")
    refused(capsys, tmp_path, monkeypatch, "render", str(captures / "walk.bvh"), "-o", "walk.gif")
    refused(capsys, tmp_path, monkeypatch, "render", str(captures / "s_01.amc"),
            "--side-by-side", str(captures / "walk.bvh"), "-o", "walk.gif")
    refused(capsys, captures, monkeypatch, "convert", "walk.bvh", "-o", "walk.bvh")
    os.link(captures / "walk.bvh", tmp_path / "hard.bvh")
    refused(capsys, tmp_path, monkeypatch, "convert", str(captures / "walk.bvh"), "-o", "hard.bvh")
    with pytest.raises(ParameterError, match="overwrite its input"):
        cc.io.convert(captures / "walk.bvh", tmp_path / "hard.bvh")


def test_blend_and_transition(captures, tmp_path, capsys, monkeypatch):
    os.symlink(captures / "walk.bvh", tmp_path / "w.bvh")
    refused(capsys, tmp_path, monkeypatch, "blend", "w.bvh", str(captures / "walk.bvh"), "-o",
            str(captures / "walk.bvh"))
    os.symlink(captures / "walk.bvh", tmp_path / "w.json")
    err = refused(capsys, tmp_path, monkeypatch, "transition", "w.bvh", str(captures / "s_01.amc"),
                  "--frames", "10", "--report", "w.json")
    assert "--report" in err


def test_batch_never_writes_over_a_capture(tmp_path, capsys):
    src, out = tmp_path / "in", tmp_path / "out"
    src.mkdir()
    out.mkdir()
    # a capture whose real file sits in the output folder where its own report would go
    cc.save(cc.datasets.example_capture().motion[:150], tmp_path / "a.bvh")
    os.replace(tmp_path / "a.bvh", out / "a.report.json")
    os.symlink(out / "a.report.json", src / "a.bvh")
    before = (out / "a.report.json").read_bytes()
    code = main(["batch", str(src), "-o", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 1 and "would overwrite the input" in err, err
    assert (out / "a.report.json").read_bytes() == before


def test_the_shared_check(tmp_path):
    a = tmp_path / "a.bvh"
    a.write_text("x")
    assert same_file(a, tmp_path / "sub" / ".." / "a.bvh")
    assert not same_file(a, tmp_path / "b.bvh")
    assert input_files("example") == [] and input_files(tmp_path / "missing.amc") == []
    refuse_clobber([a, None, "example"], [("-o", tmp_path / "b.bvh"), ("--report", None)])
    with pytest.raises(ParameterError, match=r"-o would overwrite the input"):
        refuse_clobber([a], [("-o", a)])
    with pytest.raises(ParameterError, match="would write a.bvh over the input"):
        refuse_clobber([a], [], [("--extract", tmp_path, r"a\.bvh")])


def test_a_folder_output_holding_a_link_to_an_input(tmp_path):
    """A file the folder output would write that is an input by another name: a hard or a
    symbolic link (the input itself lies elsewhere)."""
    a = tmp_path / "a.bvh"
    a.write_text("x")
    figs = tmp_path / "figs"
    figs.mkdir()
    os.link(a, figs / "pca.png")
    with pytest.raises(ParameterError, match=r"--plot would write pca.png over the input .*a\.bvh"):
        refuse_clobber([a], [], [("--plot", figs, r".*\.png")])
    (figs / "pca.png").unlink()
    os.symlink(a, figs / "pca.png")
    with pytest.raises(ParameterError, match="would write pca.png over the input"):
        refuse_clobber([a], [], [("--plot", figs, r".*\.png")])
    refuse_clobber([a], [], [("--plot", figs, r".*\.svg")])  # not a name it writes
    refuse_clobber([a], [], [("--plot", tmp_path / "missing", r".*\.png")])


# --- issue 26: one output rule for every command, declared with its parser -------------


@pytest.fixture(scope="module")
def model(captures):
    """A small latent model of the walk and a script that reads it, beside the captures."""
    assert main(["latent", "fit", str(captures / "walk.bvh"), "-o", str(captures / "Model.npz"),
                 "--max-iter", "5"]) == 0
    (captures / "script.json").write_text(json.dumps({
        "fps": 30, "models": {"walk": "Model.npz"},
        "commands": [{"command": "IDLE", "duration": 0.3}],
    }))
    return captures / "Model.npz"


def _commands():
    """Every (sub)command's parser, by its name (``latent fit``)."""
    def walk(parser, name):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for sub, p in action.choices.items():
                    yield from walk(p, f"{name} {sub}".strip())
        if parser.get_default("func") is not None:
            yield name, parser

    return dict(walk(build_parser(), ""))


#: Options that take a value and say they write, but name no file.
NOT_OUTPUTS = {("batch", "--cycles"): "the cycles' format",
               **{(c, "--units"): "the length unit written" for c in ("convert", "feet", "extract")}}


def test_every_command_declares_what_it_reads_and_writes():
    commands = _commands()
    assert {"extract", "barcode", "convert", "detect", "render", "blend", "transition", "batch",
            "view", "feet", "graph", "latent", "latent fit", "animate"} <= set(commands)
    for name, parser in commands.items():
        paths = parser.get_default("paths")
        assert isinstance(paths, Paths), f"{name}: no declare(...) of its inputs and outputs"
        for action in parser._actions:
            flags = set(action.option_strings)
            if not flags or action.nargs == 0:
                continue
            says = re.search(r"\b(write|writes|save|saves)\b", (action.help or "").lower())
            if flags & set(OUTPUT_FLAGS) or says:
                if any((name, f) in NOT_OUTPUTS for f in flags):
                    continue
                assert flags & paths.flags, f"{name} {sorted(flags)}: an output nobody checks"


#: One refused run per declared output: the output is a hard link to an input (for a
#: folder, the folder holds one under a name the command writes there).  {out} is
#: replaced by the link's name, the other fields by the captures' paths.
HARD_LINKS = {
    ("extract", "-o"): (["extract", "{walk}", "-o", "{out}"], "hard.bvh", "walk"),
    ("extract", "--report"): (["extract", "{walk}", "--report", "{out}"], "hard.json", "walk"),
    ("extract", "--save-model"): (["extract", "{amc}", "--save-model", "{out}"], "hard.npz", "asf"),
    ("extract", "--plot"): (["extract", "{walk}", "--plot", "figs"], "figs/pca.png", "walk"),
    ("detect", "--report"): (["detect", "{amc}", "--report", "{out}"], "hard.json", "amc"),
    ("detect", "--extract"): (["detect", "{walk}", "--extract-format", "npz", "--extract", "cyc"],
                              "cyc/motion1_cycle.npz", "walk"),
    ("detect", "--plot"): (["detect", "{walk}", "--plot", "figs"], "figs/windows.png", "walk"),
    ("convert", "-o"): (["convert", "{amc}", "-o", "{out}"], "hard.bvh", "asf"),
    ("render", "-o"): (["render", "{walk}", "--side-by-side", "{amc}", "-o", "{out}"],
                       "hard.gif", "asf"),
    ("blend", "-o"): (["blend", "{walk}", "{amc}", "-o", "{out}"], "hard.bvh", "amc"),
    ("blend", "--report"): (["blend", "{walk}", "{amc}", "--report", "{out}"], "hard.json", "asf"),
    ("transition", "-o"): (["transition", "{walk}", "{amc}", "--frames", "9", "-o", "{out}"],
                           "hard.bvh", "walk"),
    ("transition", "--report"): (["transition", "{walk}", "{amc}", "--frames", "9", "--report",
                                  "{out}"], "hard.json", "asf"),
    ("view", "-o"): (["view", "{walk}", "--side-by-side", "{amc}", "-o", "{out}"], "hard.html",
                     "asf"),
    ("feet", "-o"): (["feet", "{walk}", "-o", "{out}"], "hard.bvh", "walk"),
    ("feet", "--report"): (["feet", "{amc}", "--report", "{out}"], "hard.json", "asf"),
    ("graph", "-o"): (["graph", "{walk}", "{amc}", "-o", "{out}"], "hard.bvh", "walk"),
    ("graph", "--report"): (["graph", "crossval", "{walk}", "{amc}", "{walk}", "--report",
                             "{out}"], "hard.json", "asf"),
    ("graph", "--plot"): (["graph", "{walk}", "{walk}", "--start", "{amc}:3", "--plot", "figs"],
                          "figs/field.png", "amc"),
    ("latent fit", "-o"): (["latent", "fit", "{walk}", "-o", "{out}"], "hard.npz", "walk"),
    ("latent fit", "--report"): (["latent", "fit", "{amc}:0:99", "-o", "m.npz", "--report",
                                  "{out}"], "hard.json", "asf"),
    ("animate", "-o"): (["animate", "{script}", "-o", "{out}"], "hard.npz", "model"),
    ("animate", "--report"): (["animate", "{script}", "-o", "a.bvh", "--report", "{out}"],
                              "hard.json", "script"),
}


def test_every_declared_output_has_a_hard_link_case():
    declared = {
        (name, flag)
        for name, parser in _commands().items()
        for flag in {f for f, _d in parser.get_default("paths").files}
        | {f for f, _d, _p in parser.get_default("paths").folders}
    }
    assert declared == set(HARD_LINKS), "add the new output to HARD_LINKS"


@pytest.mark.parametrize("case", sorted(HARD_LINKS), ids=" ".join)
def test_a_hard_link_to_an_input_is_refused(case, captures, model, tmp_path, capsys,
                                             monkeypatch):
    argv, link, target = HARD_LINKS[case]
    inputs = {"walk": captures / "walk.bvh", "amc": captures / "s_01.amc",
              "asf": captures / "s.asf", "model": model, "script": captures / "script.json"}
    (tmp_path / link).parent.mkdir(exist_ok=True)
    os.link(inputs[target], tmp_path / link)
    before = digest(captures)
    argv = [a.format(out=link, **inputs) for a in argv]
    err = refused(capsys, tmp_path, monkeypatch, *argv)
    assert case[1] in err and inputs[target].name in err, err
    assert digest(captures) == before
    assert not [p for p in tmp_path.rglob("*") if p.name.startswith(".cyclecoord")]


def test_issue_26_inputs_overwritten(captures, model, tmp_path, capsys, monkeypatch):
    """The issue's cases, each of which replaced an input and exited 0."""
    def run(*argv):
        return refused(capsys, captures, monkeypatch, *argv)

    # latent fit --report naming one of its inputs: the take, the AMC or the ASF beside it
    assert "--report" in run("latent", "fit", "walk.bvh", "-o", str(tmp_path / "m.npz"),
                             "--report", "walk.bvh")
    assert "--report" in run("latent", "fit", "s_01.amc:0:99", "-o", str(tmp_path / "m.npz"),
                             "--report", "s_01.amc")
    assert "s.asf" in run("latent", "fit", "s_01.amc", "-o", str(tmp_path / "m.npz"),
                          "--report", "s.asf")
    # latent fit -o naming the skeleton
    assert "-o would overwrite the input s.asf" in run("latent", "fit", "s_01.amc", "-o", "s.asf")
    # animate -o / --report naming a model the script reads (another spelling, too)
    assert "Model.npz" in run("animate", "script.json", "-o", "Model.npz")
    assert "Model.npz" in run("animate", "script.json", "-o", str(tmp_path / "a.bvh"),
                              "--report", f"../{captures.name}/Model.npz")
    assert "script.json" in run("animate", "script.json", "-o", "./script.json")
    # feet, view and graph through a symbolic link, graph --start's take included
    os.symlink(captures / "s.asf", tmp_path / "sk.json")
    try:
        assert "s.asf" in run("feet", "s_01.amc", "--report", str(tmp_path / "sk.json"))
        assert "s.asf" in run("graph", "walk.bvh", "walk.bvh", "--start", "s_01.amc:0",
                              "--report", str(tmp_path / "sk.json"))
    finally:
        (tmp_path / "sk.json").unlink()
    assert "walk.bvh" in run("view", "walk.bvh", "-o", "./x/../walk.bvh")
    assert (tmp_path / "m.npz").exists() is False


def test_batch_refuses_a_hard_link_to_a_capture(tmp_path, capsys):
    src, out = tmp_path / "in", tmp_path / "out"
    src.mkdir()
    out.mkdir()
    cc.save(cc.datasets.example_capture().motion[:150], src / "a.bvh")
    os.link(src / "a.bvh", out / "a.report.json")
    before = (src / "a.bvh").read_bytes()
    code = main(["batch", str(src), "-o", str(out), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 1 and "would overwrite the input" in err, err
    assert (src / "a.bvh").read_bytes() == before
