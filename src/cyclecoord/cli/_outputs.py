"""One output rule for every command: what it reads and writes, declared beside its options.

Each subcommand calls :func:`declare` on its parser with

* ``inputs``: a function of the parsed arguments giving every file the command reads (the
  capture and an AMC's ``.asf``, every take, a script and the models it reads);
* ``files``: the options that name a file it writes (``-o``, ``--report``, ...);
* ``folders``: the options that name a folder it writes into, with a regular expression
  for the names of the files it writes there (``--plot DIR``: ``.*\\.png``);
* ``derived``: outputs that follow from the arguments (``animate -o x.amc`` writes
  ``x.asf``);
* ``elsewhere``: output options checked by the code that knows their files (``batch -o``).

:func:`cyclecoord.cli.main.main` checks the declaration with
:func:`cyclecoord.io.refuse_clobber` before the command runs, so no output, through another
spelling, a symbolic link or a hard link, replaces an input, and nothing is computed first.
``tests/cli/test_clobber.py`` walks every parser and fails on an output option that is not
declared.

:class:`Outputs` is the command side of the rule that an interrupted run changes nothing:
a :class:`cyclecoord.io.StagedOutputs` whose "wrote ..." lines are printed once the files
are in place.
"""

from __future__ import annotations

import argparse
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable

from ..io import StagedOutputs, input_files, refuse_clobber

__all__ = [
    "OUTPUT_FLAGS",
    "Outputs",
    "Paths",
    "capture_inputs",
    "check_paths",
    "crossing_refusal",
    "declare",
]

#: Option names that write what they name (when they take a value: blend's --extract is a
#: switch); a command that has one must declare it.
OUTPUT_FLAGS = ("-o", "--output", "--report", "--plot", "--save-model", "--extract")

Inputs = Callable[[argparse.Namespace], Iterable[Any]]


@dataclass(frozen=True)
class Paths:
    """What one command reads and writes (see the module notes); set by :func:`declare`."""

    inputs: Inputs
    files: tuple[tuple[str, str], ...] = ()
    folders: tuple[tuple[str, str, str], ...] = ()
    derived: Callable[[argparse.Namespace], Iterable[tuple[str, Any]]] | None = None
    elsewhere: tuple[tuple[str, str], ...] = ()

    def check(self, args: argparse.Namespace) -> None:
        """:class:`ParameterError` when an output would replace an input or another output."""
        outputs = [(flag, getattr(args, dest, None)) for flag, dest in self.files]
        if self.derived is not None:
            outputs += list(self.derived(args))
        folders = [(flag, getattr(args, dest, None), pat) for flag, dest, pat in self.folders]
        if any(path is not None for _flag, path in outputs) or any(
            folder is not None for _flag, folder, _pattern in folders
        ):
            refuse_clobber(list(self.inputs(args)), outputs, folders)

    @property
    def flags(self) -> set[str]:
        """Every output option the declaration covers."""
        return (
            {f for f, _d in self.files}
            | {f for f, _d, _p in self.folders}
            | {f for f, _w in self.elsewhere}
        )


def declare(
    parser: argparse.ArgumentParser,
    inputs: Inputs,
    files: Iterable[str] = (),
    folders: dict[str, str] | None = None,
    derived: Callable[[argparse.Namespace], Iterable[tuple[str, Any]]] | None = None,
    elsewhere: dict[str, str] | None = None,
) -> None:
    """Record what the command of ``parser`` reads and writes (options by their flag).

    Raises ``ValueError`` for a flag the parser does not have: the declaration and the
    options cannot drift apart.
    """
    dests = {s: a.dest for a in parser._actions for s in a.option_strings}

    def dest(flag: str) -> str:
        if flag not in dests:
            raise ValueError(f"{parser.prog}: declared output {flag} is not one of its options")
        return dests[flag]

    for flag in elsewhere or {}:
        dest(flag)
    parser.set_defaults(
        paths=Paths(
            inputs=inputs,
            files=tuple((f, dest(f)) for f in files),
            folders=tuple((f, dest(f), pattern) for f, pattern in (folders or {}).items()),
            derived=derived,
            elsewhere=tuple((elsewhere or {}).items()),
        )
    )


def capture_inputs(input_dest: str = "input", skeleton_dest: str | None = "skeleton") -> Inputs:
    """``inputs`` for a command that reads one capture (with its AMC's ``.asf``)."""

    def inputs(args: argparse.Namespace) -> list[Path]:
        skeleton = getattr(args, skeleton_dest, None) if skeleton_dest else None
        return input_files(getattr(args, input_dest, None), skeleton)

    return inputs


def check_paths(args: argparse.Namespace) -> None:
    """The output rule for the parsed command line (see the module notes)."""
    paths = getattr(args, "paths", None)
    if paths is not None:
        paths.check(args)


class Outputs(StagedOutputs):
    """The outputs of one command: staged, moved into place at the end, then announced.

    :meth:`wrote` queues a ``wrote PATH`` line; the lines are printed after
    :meth:`commit`, so a run interrupted before the end prints none and changes nothing.
    """

    def __init__(self) -> None:
        super().__init__()
        self._lines: list[str] = []

    def wrote(self, path: Any, detail: str = "") -> None:
        """Print ``wrote PATH`` (and ``detail``) once the outputs are in place."""
        self._lines.append(f"wrote {path}{detail}")

    def save(self, motion: Any, path: Any, announce: bool = True, **kwargs: Any) -> None:
        """Stage ``motion`` as ``path`` (see :meth:`StagedOutputs.save`) and, unless
        ``announce`` is False, print ``wrote PATH`` at the end."""
        super().save(motion, path, **kwargs)
        if announce:
            self.wrote(path)

    def commit(self) -> list[Path]:
        moved = super().commit()
        for line in self._lines:
            print(line)
        self._lines.clear()
        return moved

    def discard(self) -> None:
        super().discard()
        self._lines.clear()


def crossing_refusal(what: str, frames: list[int], hint: str) -> str:
    """Why a motion whose limbs pass through each other in ``frames`` is not written."""
    where = f"frames {frames[0]}-{frames[-1]}" if len(frames) > 1 else f"frame {frames[0]}"
    return (
        f"{what} has limbs passing through each other in {len(frames)} frames ({where}); "
        f"nothing written (--allow-contacts writes it anyway; {hint})"
    )
