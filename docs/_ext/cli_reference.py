"""The command-line reference, generated from ``cyclecoord.cli``'s argparse parsers.

``.. cyclecoord-cli::`` writes one section per command (``cyclecoord``, ``cyclecoord
extract``, ``cyclecoord graph crossval`` ...) holding the exact text ``--help`` prints,
then a table of its options.  It is rebuilt from the parsers on every build, so the
reference cannot drift from the command.  :func:`help_pages` is also what
``tests/test_docs.py`` compares the built pages with.
"""

from __future__ import annotations

import argparse
import os
from contextlib import contextmanager

from docutils import nodes
from docutils.parsers.rst import Directive

#: Width the help is wrapped to, so the pages do not depend on the terminal of the build.
COLUMNS = 79


@contextmanager
def _columns(width: int):
    old = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = str(width)
    try:
        yield
    finally:
        if old is None:
            os.environ.pop("COLUMNS", None)
        else:
            os.environ["COLUMNS"] = old


def _subparsers(parser: argparse.ArgumentParser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            seen = set()
            for name, sub in action.choices.items():
                if id(sub) not in seen:  # aliases name the same parser
                    seen.add(id(sub))
                    yield name, sub


def help_pages(width: int = COLUMNS) -> list[tuple[str, argparse.ArgumentParser, str]]:
    """``(command line, parser, help text)`` of ``cyclecoord`` and each of its commands."""
    from cyclecoord.cli.main import build_parser

    out = []
    with _columns(width):
        def walk(words: list[str], parser: argparse.ArgumentParser) -> None:
            out.append((" ".join(words), parser, parser.format_help()))
            for name, sub in _subparsers(parser):
                walk(words + [name], sub)

        walk(["cyclecoord"], build_parser())
    return out


def _options_table(parser: argparse.ArgumentParser) -> nodes.Node | None:
    rows = []
    for action in parser._actions:
        if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        names = ", ".join(action.option_strings) or (action.metavar or action.dest)
        text = (action.help or "") % {**vars(action), "prog": parser.prog} \
            if action.help and action.help != argparse.SUPPRESS else ""
        rows.append((str(names), text))
    if not rows:
        return None
    table = nodes.table(classes=["cli-options"])
    group = nodes.tgroup(cols=2)
    table += group
    group += nodes.colspec(colwidth=30)
    group += nodes.colspec(colwidth=70)
    head = nodes.thead()
    group += head
    row = nodes.row()
    for title in ("option", "meaning"):
        row += nodes.entry("", nodes.paragraph(text=title))
    head += row
    body = nodes.tbody()
    group += body
    for names, text in rows:
        row = nodes.row()
        row += nodes.entry("", nodes.paragraph("", "", nodes.literal(text=names)))
        row += nodes.entry("", nodes.paragraph(text=text))
        body += row
    return table


class CycleCoordCLI(Directive):
    """``.. cyclecoord-cli::``: every command's help and options, from the parsers."""

    has_content = False

    def run(self):
        result = []
        for words, parser, text in help_pages():
            ident = nodes.make_id(words)
            section = nodes.section(ids=[ident], names=[nodes.fully_normalize_name(words)])
            section += nodes.title(text=words)
            literal = nodes.literal_block(text, text)
            literal["language"] = "text"
            section += literal
            table = _options_table(parser)
            if table is not None:
                section += table
            self.state.document.note_implicit_target(section, section)
            result.append(section)
        return result


def setup(app):
    app.add_directive("cyclecoord-cli", CycleCoordCLI)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
