"""Finding the captures a batch runs over: file-name patterns and the folder scan
(:func:`find_captures`, used by :func:`cyclecoord.batch.run_batch`)."""

from __future__ import annotations

import fnmatch
import os
from pathlib import Path
from typing import Sequence

from ..errors import ParameterError

__all__ = ["find_captures", "as_patterns", "DEFAULT_PATTERNS"]

#: File-name patterns scanned by default (matched case-insensitively).
DEFAULT_PATTERNS = ("*.amc", "*.bvh", "*.npz", "*.csv")


def as_patterns(pattern: str | Sequence[str]) -> tuple[str, ...]:
    pats = (pattern,) if isinstance(pattern, str) else tuple(pattern)
    if not pats or not all(isinstance(p, str) and p for p in pats):
        raise ParameterError(
            f"pattern must be a glob or a non-empty list of globs, got {pattern!r}"
        )
    return pats


def _matches(rel: str, name: str, patterns: Sequence[str]) -> bool:
    for pat in patterns:
        subject = rel if "/" in pat else name
        if fnmatch.fnmatchcase(subject.lower(), pat.lower()):
            return True
    return False


def find_captures(
    folder: str | os.PathLike[str],
    pattern: str | Sequence[str] = DEFAULT_PATTERNS,
    recursive: bool = True,
) -> list[str]:
    """Captures under ``folder`` whose names match a pattern, sorted.

    Parameters
    ----------
    folder : path-like
        Folder to scan.
    pattern : str or sequence of str
        Globs matched case-insensitively against the file name (or, for a glob holding
        ``/``, against the path relative to ``folder``).
    recursive : bool, default True
        Descend into subfolders.  Hidden files and folders (name starting with ``.``)
        are skipped; symbolic links to folders are not followed.

    Returns
    -------
    list of str
        Paths relative to ``folder`` with ``/`` separators, in sorted order.
    """
    root = Path(folder)
    if not root.is_dir():
        raise ParameterError(f"{folder}: not a folder")
    pats = as_patterns(pattern)
    found: list[str] = []
    for here, dirs, files in os.walk(root):
        dirs[:] = sorted(d for d in dirs if not d.startswith(".")) if recursive else []
        rel_dir = Path(here).relative_to(root)
        for name in files:
            if name.startswith("."):
                continue
            rel = (rel_dir / name).as_posix()
            if _matches(rel, name, pats) and (Path(here) / name).is_file():
                found.append(rel)
    return sorted(found)
