"""No command writes over one of its inputs: every output option, through symlinks, hard
links and relative paths (issue 18).  Every refusal happens before any computation."""

import os
from pathlib import Path

import pytest

import cyclecoord as cc
from cyclecoord.cli import main
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

    # the cases: -o onto the input, as given and through a relative detour
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
