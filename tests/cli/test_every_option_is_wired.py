"""Every option of every ``cyclecoord`` command is run by a test that checks it reaches the
library (the registry: ``tests/cli/wired_options.py``, which says how to add one).

An option added without a test fails here.  The named test must exist, and its source (with
its decorators and the module-level tables it names) must spell the option and the command
as strings: a registry line cannot point at a test that never types the option.
"""

from __future__ import annotations

import argparse
import ast
import re
from functools import cache
from pathlib import Path

import pytest

from cyclecoord.cli.main import build_parser
from wired_options import WIRED

ROOT = Path(__file__).resolve().parents[2]


def _options():
    """(command, option strings) for every option of every parser, ``--help`` aside."""
    def walk(parser, name):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for sub, p in action.choices.items():
                    yield from walk(p, f"{name} {sub}".strip())
            elif action.option_strings and not isinstance(action, argparse._HelpAction):
                yield name, tuple(action.option_strings)

    return list(walk(build_parser(), ""))


OPTIONS = _options()


@cache
def _module(path: str) -> tuple[str, ast.Module]:
    text = (ROOT / path).read_text()
    return text, ast.parse(text)


def _test_text(test: str) -> str:
    """The test function's source with its decorators, and the module-level assignments it
    names (two levels deep: a table built from other tables)."""
    path, _, name = test.partition("::")
    assert (ROOT / path).is_file(), f"no test file {path}"
    text, tree = _module(path)
    funcs = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    assert name in funcs, f"{path} has no test {name}"
    assigned = {}
    for node in tree.body:
        if isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for t in targets:
                if isinstance(t, ast.Name):
                    assigned[t.id] = node
    parts, seen, todo = [], set(), [funcs[name]]
    for _ in range(3):
        names = set()
        for node in todo:
            parts.append(ast.get_source_segment(text, node) or "")
            for d in getattr(node, "decorator_list", []):
                parts.append(ast.get_source_segment(text, d) or "")
                names |= {n.id for n in ast.walk(d) if isinstance(n, ast.Name)}
            names |= {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
        todo = [assigned[n] for n in names - seen if n in assigned]
        seen |= names
    return "\n".join(parts)


def _spelled(word: str, text: str) -> bool:
    """``word`` as a string in the source: ``"--pca"``, ``"--pca=3"`` or ``"extract ..."``."""
    return re.search(r"""["']""" + re.escape(word) + r"""(?:["'= ]|$)""", text, re.M) is not None


@pytest.mark.parametrize("command, flags", OPTIONS,
                         ids=[f"{c} {f[0]}".strip() for c, f in OPTIONS])
def test_option_is_run_by_a_registered_test(command, flags):
    registered = WIRED.get(command, {})
    keys = [f for f in flags if f in registered]
    assert keys, (
        f"cyclecoord {command} {'/'.join(flags)} has no wiring test: write one that runs it and "
        f"checks what the library receives, and register it in tests/cli/wired_options.py"
    )
    tests = registered[keys[0]]
    for test in (tests,) if isinstance(tests, str) else tests:
        text = _test_text(test)
        assert any(_spelled(f, text) for f in flags), f"{test} never spells {'/'.join(flags)}"
        for word in command.split():
            assert _spelled(word, text), f"{test} never names the command {command!r}"


def test_registry_names_only_options_that_exist():
    exist = {(c, f) for c, flags in OPTIONS for f in flags}
    stale = [(c, f) for c, opts in WIRED.items() for f in opts if (c, f) not in exist]
    assert not stale, f"registered options no parser has (remove them): {stale}"


def test_the_check_refuses_a_test_that_never_types_the_option():
    """The check itself: an option registered to a test that never spells it fails."""
    text = _test_text("tests/cli/test_wiring.py::test_version_prints_the_package_version")
    assert _spelled("--version", text) and not _spelled("--pca", text)
    assert _spelled("extract", 'main(["extract", src])') and not _spelled("extract", "extracted")
    with pytest.raises(AssertionError, match="has no test"):
        _test_text("tests/cli/test_wiring.py::test_that_does_not_exist")
