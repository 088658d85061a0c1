"""The documentation site builds with no warning, and what it shows runs (issue 25).

* the site builds with ``sphinx-build -W --keep-going`` (nitpicky: a broken
  cross-reference fails it), every gallery example run afresh;
* a broken cross-reference does fail a build;
* the command-line reference is the parsers' own ``--help``;
* every Python block of the pages runs, on the shared captures where a page loads one;
* the console output shown on the getting-started page is what the command prints.

The build tests are skipped, with the reason, when Sphinx, numpydoc, sphinx-gallery or
the theme are not installed (``pip install -e ".[docs]"``; the ``test`` extra has them).
"""

from __future__ import annotations

import html
import importlib.util
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from conftest import SHARED_DATA

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = sorted(p for p in DOCS.rglob("*.rst")
               if not {"_build", "generated", "auto_examples"} & set(p.relative_to(DOCS).parts))

pytestmark = pytest.mark.slow

_MISSING = [m for m in ("sphinx", "numpydoc", "sphinx_gallery", "pydata_sphinx_theme")
            if importlib.util.find_spec(m) is None]
needs_sphinx = pytest.mark.skipif(
    bool(_MISSING),
    reason=f"{', '.join(_MISSING)} not installed: pip install -e \".[docs]\" to build the docs",
)


def _sphinx(src: Path, out: Path, *extra: str, env: dict | None = None,
            timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html",
         "-d", str(out / "doctrees"), *extra, str(src), str(out / "html")],
        capture_output=True, text=True, timeout=timeout,
        env={**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT / "src"), **(env or {})},
    )


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site built as the README says, every gallery example run (about 30 s)."""
    out = tmp_path_factory.mktemp("docs")
    proc = _sphinx(DOCS, out, env={"CYCLECOORD_DOCS_RERUN": "1"})
    assert proc.returncode == 0, f"docs build failed:\n{proc.stderr[-6000:]}"
    assert "WARNING" not in proc.stderr and "ERROR" not in proc.stderr, proc.stderr
    return out / "html"


@needs_sphinx
def test_the_site_builds_with_no_warning(site):
    for page in ("index", "getting_started", "api", "cli", "guide/index", "guide/quality",
                 "auto_examples/index"):
        assert (site / f"{page}.html").is_file(), page
    for name in ("extract", "detect", "blend"):  # API pages from the docstrings
        assert list((site / "generated").glob("cyclecoord.*.html"))
        assert name in (site / "api.html").read_text(encoding="utf-8")
    examples = sorted(p.stem for p in (ROOT / "examples").glob("plot_*.py"))
    assert len(examples) >= 5
    images = {p.name for p in (site / "_images").glob("sphx_glr_plot_*.png")}
    for stem in examples:  # every gallery example ran and made its figure
        assert any(name.startswith(f"sphx_glr_{stem}_") and "thumb" not in name
                   for name in images), stem


@needs_sphinx
def test_a_broken_cross_reference_fails_the_build(tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    (src / "conf.py").write_text(
        f"__file__ = {str(DOCS / 'conf.py')!r}\nexec(open(__file__).read())\n"
        "extensions.remove('sphinx_gallery.gen_gallery')\n"
    )
    (src / "index.rst").write_text(
        "Broken\n======\n\n:func:`cyclecoord.no_such_thing` names nothing.\n"
    )
    proc = _sphinx(src, tmp_path / "out", timeout=120)
    assert proc.returncode != 0
    assert "cyclecoord.no_such_thing" in proc.stderr and "not found" in proc.stderr


def _text_of(page: Path) -> str:
    text = re.sub(r"<[^>]+>", "", page.read_text(encoding="utf-8"))
    return html.unescape(text)


@needs_sphinx
def test_the_cli_reference_is_the_parsers_help(site):
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        from cli_reference import help_pages
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    pages = help_pages()
    commands = {words for words, _, _ in pages}
    for sub in ("extract", "barcode", "convert", "detect", "render", "blend", "transition",
                "batch", "view", "feet", "graph", "latent", "latent fit", "animate"):
        assert f"cyclecoord {sub}" in commands, sub
    shown = _text_of(site / "cli.html")
    for words, _, text in pages:
        assert text.strip() in shown, f"{words}: the page is not the parser's help"


# ------------------------------------------------------------------ Python blocks
def python_blocks(page: Path) -> list[str]:
    """The ``.. code-block:: python`` blocks of an .rst page, dedented."""
    out = []
    lines = page.read_text(encoding="utf-8").splitlines()
    i = 0
    while i < len(lines):
        if lines[i].strip() == ".. code-block:: python":
            i += 1
            block = []
            while i < len(lines) and (not lines[i].strip() or lines[i].startswith("   ")):
                block.append(lines[i])
                i += 1
            out.append(textwrap.dedent("\n".join(block)).strip() + "\n")
        else:
            i += 1
    return out


#: Files the pages load, as a reader would have them in the working folder.
SHARED_FILES = {
    **{f"{t}.amc": f"cmu/{t.split('_')[0]}/{t}.amc"
       for t in ("69_01", "143_01", "13_29", "01_09", "35_07", "35_08", "35_13", "35_16")},
    **{f"{s}.asf": f"cmu/{s}/{s}.asf" for s in ("69", "143", "13", "01", "35")},
    "dataset-1_walk_normal_001.bvh": "bvh/bandai/dataset-1_walk_normal_001.bvh",
}


def test_the_pages_have_python_blocks():
    counted = {p.relative_to(DOCS).as_posix(): len(python_blocks(p)) for p in PAGES}
    assert counted["getting_started.rst"] >= 1
    assert sum(counted.values()) >= 15, counted


@pytest.mark.parametrize("page", [p for p in PAGES if python_blocks(p)],
                         ids=lambda p: p.relative_to(DOCS).as_posix())
def test_every_python_block_runs(page, tmp_path, monkeypatch):
    code = python_blocks(page)
    needed = sorted({name for name in SHARED_FILES if any(name in c for c in code)})
    missing = [n for n in needed if not (SHARED_DATA / SHARED_FILES[n]).is_file()]
    if missing:
        pytest.skip(f"{page.name} loads {', '.join(missing)}: shared captures not found at "
                    f"{SHARED_DATA}")
    for name, rel in SHARED_FILES.items():
        if (SHARED_DATA / rel).is_file():
            (tmp_path / name).symlink_to(SHARED_DATA / rel)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict = {"__name__": "__main__"}
    for k, block in enumerate(code):
        try:
            exec(compile(block, f"{page.name}[python block {k}]", "exec"), namespace)  # noqa: S102
        except Exception as exc:  # pragma: no cover - the message names the block
            raise AssertionError(f"{page.name}, Python block {k} fails:\n{block}") from exc


def test_the_console_shown_is_what_extract_prints(tmp_path, monkeypatch, capsys):
    """getting_started.rst shows the output of ``cyclecoord extract example``; it is that
    output (generated from a run, and checked against one)."""
    from cyclecoord.cli import main

    text = (DOCS / "getting_started.rst").read_text(encoding="utf-8")
    shown = re.search(r"``cyclecoord extract example -o walk_cycle.bvh`` prints.*?::\n\n"
                      r"((?:    [^\n]*\n)+)", text, flags=re.DOTALL).group(1)
    monkeypatch.chdir(tmp_path)
    assert main(["extract", "example", "-o", "walk_cycle.bvh"]) == 0
    printed = capsys.readouterr().out
    assert textwrap.dedent(shown).strip() == printed.strip()


def test_the_latent_page_shows_the_example_script():
    text = (DOCS / "guide" / "latent.rst").read_text(encoding="utf-8")
    assert ".. literalinclude:: ../../examples/latent_script.json" in text
    assert (DOCS / "../examples/latent_script.json").resolve().is_file()


def test_getting_started_has_the_readme_set_up_commands():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    setup = readme[readme.index("## Set up\n"):readme.index("\n## ", readme.index("## Set up\n") + 1)]
    commands = [ln for b in re.findall(r"```bash\n(.*?)```", setup, flags=re.DOTALL)
                for ln in b.splitlines() if ln.strip()]
    page = (DOCS / "getting_started.rst").read_text(encoding="utf-8")
    shown = [ln.strip() for ln in page[page.index(".. code-block:: bash"):].splitlines()[2:4]]
    assert commands == shown
