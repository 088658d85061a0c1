"""The house stays in order (issue 25 item 6): no function over 120 code lines, no module
over 800 lines, and ``motion`` and ``skeleton`` do not import each other in a circle.

Code lines are a function's lines (decorators and signature included) less blank lines,
comment lines and docstrings.  ``KNOWN`` lists the few places over a limit in areas
another piece of work is changing; an entry that no longer exceeds its limit fails too,
so the list only shrinks.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "cyclecoord"
MAX_FUNCTION = 120
MAX_MODULE = 800

#: (path under src/cyclecoord, function name or None for the module) -> why it is allowed.
#: Empty: the last two (synthesis/latent/commands.py, 837 lines, and
#: synthesis/graph/crossval.py's cross_validate, 126 code lines) were split on main.
KNOWN: dict[tuple[str, str | None], str] = {}


def _modules():
    return sorted(SRC.rglob("*.py"))


def _docstring_lines(tree: ast.AST) -> set[int]:
    out: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                    and isinstance(body[0].value.value, str):
                out.update(range(body[0].lineno, body[0].end_lineno + 1))
    return out


def code_lines(lines: list[str], node: ast.AST, docstrings: set[int]) -> int:
    """Lines of ``node`` that are neither blank, nor comments, nor docstrings."""
    start = min([d.lineno for d in node.decorator_list] + [node.lineno])
    return sum(
        1
        for i in range(start, node.end_lineno + 1)
        if lines[i - 1].strip() and not lines[i - 1].strip().startswith("#")
        and i not in docstrings
    )


def _measure() -> tuple[dict, dict]:
    functions, modules = {}, {}
    for path in _modules():
        rel = path.relative_to(SRC).as_posix()
        text = path.read_text(encoding="utf-8")
        lines = text.splitlines()
        modules[rel] = len(lines)
        tree = ast.parse(text)
        docs = _docstring_lines(tree)
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                key = (rel, node.name)
                functions[key] = max(functions.get(key, 0), code_lines(lines, node, docs))
    return functions, modules


@pytest.fixture(scope="module")
def sizes():
    return _measure()


def test_no_function_over_120_code_lines(sizes):
    functions, _ = sizes
    over = {k: n for k, n in functions.items() if n > MAX_FUNCTION and k not in KNOWN}
    assert not over, f"functions over {MAX_FUNCTION} code lines (split them): {over}"


def test_no_module_over_800_lines(sizes):
    _, modules = sizes
    over = {k: n for k, n in modules.items() if n > MAX_MODULE and (k, None) not in KNOWN}
    assert not over, f"modules over {MAX_MODULE} lines (split them): {over}"


def test_known_exceptions_still_exceed(sizes):
    functions, modules = sizes
    for (rel, name), why in KNOWN.items():
        n = modules.get(rel, 0) if name is None else functions.get((rel, name), 0)
        limit = MAX_MODULE if name is None else MAX_FUNCTION
        assert n > limit, (
            f"{rel}{'' if name is None else ':' + name} is now {n} lines, within the limit "
            f"of {limit}: remove it from KNOWN in tests/test_structure.py ({why})"
        )


def _imports(path: Path) -> set[str]:
    """Absolute names of the cyclecoord modules ``path`` imports, anywhere in it
    (function-level imports included), ``TYPE_CHECKING`` blocks left out."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = ["cyclecoord", *path.relative_to(SRC).with_suffix("").parts[:-1]]
    if path.name == "__init__.py":
        package = ["cyclecoord", *path.relative_to(SRC).parts[:-1]]
    skip: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for sub in node.body:
                skip.update(id(n) for n in ast.walk(sub))
    out: set[str] = set()
    for node in ast.walk(tree):
        if id(node) in skip:
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.add(mod)
            out.update(f"{mod}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return {m for m in out if m.startswith("cyclecoord")}


def test_motion_and_skeleton_do_not_import_each_other_in_a_circle():
    motion = _imports(SRC / "motion.py")
    skeleton = _imports(SRC / "skeleton.py")
    assert "cyclecoord.motion" not in skeleton, "skeleton imports motion (motion imports skeleton)"
    assert "cyclecoord.skeleton" in motion  # the one direction


def test_the_checker_counts_code_lines():
    text = '''def f(x):
    """Doc
    string."""
    # a comment

    y = x  # trailing comment counts
    return y
'''
    tree = ast.parse(text)
    node = tree.body[0]
    assert code_lines(text.splitlines(), node, _docstring_lines(tree)) == 3
