"""One check that no output is written over an input (or over another output).

Paths are compared as the files they reach: relative paths, ``..``, symbolic links (of
the file or of any folder above it) and hard links all count, so ``-o ./x/../walk.bvh``,
``-o link.bvh`` (a link to the input) and the input itself are refused alike, and so is a
folder output (``--plot DIR``) holding an input, or a link to one, under a name it writes.
Every command and every output option goes through :func:`refuse_clobber` before anything
is computed: the command line declares each command's inputs and outputs
(:mod:`cyclecoord.cli._outputs`) and checks them before running it.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Iterable, Sequence

from ..errors import ParameterError

__all__ = ["same_file", "refuse_clobber", "input_files"]

PathLike = str | os.PathLike


def _real(path: PathLike) -> str:
    return os.path.realpath(os.fspath(path))


def same_file(a: PathLike, b: PathLike) -> bool:
    """Whether ``a`` and ``b`` reach the same file (symlinks and hard links followed)."""
    if _real(a) == _real(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:  # either does not exist (yet)
        return False


def input_files(path: PathLike | None, skeleton: PathLike | None = None) -> list[Path]:
    """The files a command reads for ``path``: the file itself and, for an AMC, its ASF.

    Names that are not files (``example``, a missing path) give nothing: the loader
    reports them.  The ASF of an AMC is ``skeleton`` when given, else the one
    :func:`cyclecoord.io.asfamc.find_skeleton` would use.
    """
    if path is None or not Path(path).is_file():
        return []
    files = [Path(path)]
    if skeleton is not None:
        if Path(skeleton).is_file():
            files.append(Path(skeleton))
    elif Path(path).suffix.lower() == ".amc":
        from ..errors import ParseError
        from .asfamc import find_skeleton

        try:
            files.append(find_skeleton(Path(path)))
        except ParseError:
            pass  # the loader reports it
    return files


def refuse_clobber(
    inputs: Iterable[PathLike | None],
    outputs: Sequence[tuple[str, PathLike | None]] = (),
    folders: Sequence[tuple[str, PathLike | None, str]] = (),
) -> None:
    """Raise :class:`ParameterError` if an output would replace an input or another output.

    Parameters
    ----------
    inputs : iterable of path-like or None
        Every file the command reads (``None`` and names that are not files are skipped).
    outputs : sequence of (option, path or None)
        Files the command writes, with the option that names each (e.g. ``"-o"``).
    folders : sequence of (option, folder or None, pattern)
        Folders the command writes into, with a regular expression matching the names of
        the files it writes there (e.g. ``r".*\\.png"``).

    Raises
    ------
    ParameterError
        ``"<output>: <option> would overwrite the input <input>; ..."`` or, for two
        outputs naming one file, ``"<output>: <option> and <other option> name the same
        file"``.
    """
    by_path: dict[str, Path] = {}
    by_inode: dict[tuple[int, int], Path] = {}
    for p in inputs:
        if p is None or not Path(p).exists():
            continue
        by_path.setdefault(_real(p), Path(p))
        by_path.setdefault(os.path.abspath(p), Path(p))
        st = os.stat(p)
        by_inode.setdefault((st.st_dev, st.st_ino), Path(p))
    seen: dict[str, str] = {}
    for option, out in outputs:
        if out is None:
            continue
        key = _real(out)
        src = by_path.get(key)
        if src is None:
            try:
                st = os.stat(out)
            except OSError:
                pass
            else:
                src = by_inode.get((st.st_dev, st.st_ino))
        if src is not None:
            raise ParameterError(
                f"{out}: {option} would overwrite the input {src}; inputs are never "
                "modified, choose another output name"
            )
        if key in seen:
            raise ParameterError(f"{out}: {option} and {seen[key]} name the same file")
        seen[key] = option
    for option, folder, pattern in folders:
        if folder is None:
            continue
        where = _real(folder)
        names = re.compile(pattern)
        for key, src in by_path.items():
            parent, name = os.path.split(key)
            if _real(parent) == where and names.fullmatch(name):
                raise ParameterError(
                    f"{folder}: {option} would write {name} over the input {src}; "
                    "inputs are never modified, choose another folder"
                )
        # a file already there under such a name that is an input by another link
        try:
            present = [n for n in os.listdir(folder) if names.fullmatch(n)]
        except OSError:  # no such folder (yet)
            present = []
        for name in present:
            try:
                st = os.stat(os.path.join(folder, name))
            except OSError:
                continue
            src = by_inode.get((st.st_dev, st.st_ino))
            if src is not None:
                raise ParameterError(
                    f"{folder}: {option} would write {name} over the input {src}; "
                    "inputs are never modified, choose another folder"
                )
        for key, other in seen.items():
            parent, name = os.path.split(key)
            if parent == where and names.fullmatch(name):
                raise ParameterError(f"{folder}: {option} would write {name} over the {other} file")
