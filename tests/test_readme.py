"""Every command and library line of the README runs as written (issue 18).

The README speaks of CMU captures (69_01.amc, 143_01.amc, 13_29.amc, 01_09.amc); here they are
stood in for by the built-in synthetic captures written under those names (walk, jog,
a chain of three motions), so the test needs no data and checks what a reader types.
"""

import re
import shlex
from pathlib import Path

import pytest

import cyclecoord as cc
from cyclecoord import datasets
from cyclecoord.cli import main

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")

pytestmark = pytest.mark.slow


def blocks(language: str, section: str | None = None) -> list[str]:
    text = README
    if section is not None:
        start = text.index(f"## {section}\n")
        end = text.find("\n## ", start + 1)
        text = text[start:end if end > 0 else None]
    return re.findall(rf"```{language}\n(.*?)```", text, flags=re.DOTALL)


#: Sections whose commands run here on the stand-ins; the motion-graph and latent sections
#: train on the subject 35 walks and are run by their own tests (tests/synthesis).
SECTIONS = ("Set up", "Command line")


def commands() -> list[str]:
    """The ``cyclecoord ...`` commands of the README's set-up and command-line sections."""
    out = []
    for block in (b for s in SECTIONS for b in blocks("bash", s)):
        for line in block.replace("\\\n", " ").splitlines():
            line = line.split("  #")[0].strip()
            for part in line.split("&&"):
                words = shlex.split(part)
                if words and Path(words[0]).name == "cyclecoord":
                    out.append(part.strip())
    return out


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    d = tmp_path_factory.mktemp("readme")
    walk = datasets.example_capture().motion
    # like CMU 143_01: 100 frames of a jog of about 43 frames a cycle
    jog = datasets.make_periodic_capture(kind="jog", n_frames=480, period=43.0, random_state=0).motion[:100]
    chain = datasets.make_motion_chain(("walk", "jumping_jack"), segment_frames=360,
                                       random_state=0).motion
    # like CMU 01_09 (a playground): nothing periodic
    playground = datasets.make_random_walk_capture(n_frames=400, random_state=1).motion
    for motion, name in ((walk, "69_01.amc"), (jog, "143_01.amc"), (chain, "13_29.amc"),
                         (playground, "01_09.amc")):
        cc.save(motion, d / name)  # with 69.asf, 143.asf, 13.asf beside
    (d / "captures").mkdir()
    cc.save(walk[:360], d / "captures" / "walk.bvh")
    cc.save(jog, d / "captures" / "jog.bvh")
    return d


def test_the_readme_has_what_this_test_runs():
    cmds = commands()
    assert any(c.startswith(".venv/bin/cyclecoord extract example") for c in cmds)
    subs = ("extract", "barcode", "detect", "blend", "transition", "render", "convert", "batch")
    for sub in subs:
        assert any(c.split()[1] == sub for c in cmds), sub
    assert len(blocks("python", "Library")) >= 2


def test_every_command_runs_as_written(workdir, monkeypatch, capsys):
    monkeypatch.chdir(workdir)
    for line in commands():
        code = main(shlex.split(line)[1:])
        err = capsys.readouterr().err
        assert code == 0, f"{line}\n{err}"
    for name in ("walk_cycle.bvh", "walk_report.json", "jog_cycle.bvh", "blend.bvh",
                 "walk_to_jog.bvh", "compare.gif", "69_01.bvh", "results/summary.csv"):
        assert (workdir / name).is_file(), name
    assert list((workdir / "cycles").glob("motion*_cycle.bvh"))


def test_every_library_line_runs_as_written(workdir, monkeypatch):
    monkeypatch.chdir(workdir)
    namespace: dict = {}
    for code in blocks("python", "Library"):
        exec(compile(code, "README.md", "exec"), namespace)  # noqa: S102 - the README's own lines
    fk = namespace["fk"]
    result = namespace["result"]
    assert fk.positions.shape == (result.cycle.n_frames, len(fk.names), 3)  # as the comment says
    assert fk["lfoot"].shape == (result.cycle.n_frames, 3)
    assert namespace["both"].n_frames > 0 and namespace["clip"].n_frames > 0
    assert len(namespace["phase"]) == namespace["motion"].n_frames


def test_the_notebook_line_and_its_extra():
    line = next(ln for ln in README.replace("\n  ", " ").splitlines() if "jupyter nbconvert" in ln)
    notebook = re.search(r"notebooks/\S+\.ipynb", line).group(0)
    assert (ROOT / notebook).is_file()  # tests/test_notebooks.py executes it (nbclient)
    pyproject = (ROOT / "pyproject.toml").read_text()
    assert re.search(r'^notebooks = \[[^]]*"nbconvert', pyproject, flags=re.MULTILINE)
    for ignored in ("/out/", "/walk_cycle.bvh", "/walk_report.json"):
        assert ignored in (ROOT / ".gitignore").read_text().splitlines()


# ---------------------------------------------------------------- issue 25: no drift
#: Every ``python`` block of the README and the test that runs it: the Library blocks run
#: here on stand-ins (test_every_library_line_runs_as_written), the motion-graph block on
#: the shared subject-35 walks (below).
PYTHON_SECTIONS = {"Library": 2, "Motion graph": 1}


def test_every_python_block_is_run_by_a_test():
    assert len(blocks("python")) == sum(PYTHON_SECTIONS.values())
    for section, n in PYTHON_SECTIONS.items():
        assert len(blocks("python", section)) == n, section


def test_the_motion_graph_block_runs_as_written(cmu_dir, tmp_path, monkeypatch):
    for n in ("16", "07", "08", "13"):
        (tmp_path / f"35_{n}.amc").symlink_to(cmu_dir / "35" / f"35_{n}.amc")
    (tmp_path / "35.asf").symlink_to(cmu_dir / "35" / "35.asf")
    monkeypatch.chdir(tmp_path)
    (code,) = blocks("python", "Motion graph")
    namespace: dict = {}
    exec(compile(code, "README.md", "exec"), namespace)  # noqa: S102 - the README's own lines
    assert namespace["gen"].motion.n_frames == 450
    assert (tmp_path / "walk.bvh").is_file()


def test_the_latent_script_shown_is_the_example_file():
    import json

    (shown,) = blocks("json", "Latent-space synthesis: models, scripts, `animate`")
    example = json.loads((ROOT / "examples" / "latent_script.json").read_text())
    assert json.loads(shown) == example


def test_no_figure_without_a_named_run():
    """Test counts and suite times drift with every commit: the README gives none."""
    assert not re.search(r"\b\d[\d,]* tests\b", README)
    assert not re.search(r"suite[^.]*\b\d+ min\b", README)


def test_the_docs_build_line_and_its_extra():
    line = next(ln for ln in README.splitlines() if ln.startswith("sphinx-build"))
    assert line == "sphinx-build -W --keep-going -b html docs docs/_build/html"
    assert 'pip install -e ".[docs]"' in README
    tomllib = pytest.importorskip("tomllib", reason="tomllib is Python 3.11+")
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    for extra in ("docs", "test"):  # the test suite builds the docs, so CI has the tools
        names = {re.split(r"[<>=\[ ]", d)[0] for d in extras[extra]}
        assert {"sphinx", "numpydoc", "sphinx-gallery", "pydata-sphinx-theme"} <= names, extra
    assert "/docs/_build/" in (ROOT / ".gitignore").read_text().splitlines()
