"""Atomic file output: write to a temporary file beside the target, then rename."""

from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Iterator

__all__ = ["atomic_path", "atomic_write"]


def _umask() -> int:
    """The process's file-creation mask, read without changing it where possible."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)  # elsewhere: the usual set-and-restore
    os.umask(mask)
    return mask


def _final_mode(target: Path) -> int:
    """Permissions for the new file: those of the file it replaces, else what ``open`` gives.

    :func:`tempfile.mkstemp` creates files readable by their owner alone (0600); an output
    should be readable like any file the user's tools write (0666 less the umask).
    """
    try:
        return target.stat().st_mode & 0o7777
    except OSError:
        return 0o666 & ~_umask()


@contextmanager
def atomic_path(path: str | os.PathLike[str], suffix: str = ".tmp") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success move it over ``path``.

    For writers that want a file name rather than an open file (matplotlib's animation
    writers).  The temporary name ends in ``suffix`` (a writer may choose its format by
    it).  On success the file gets the permissions an ordinary write would give (or
    those of the file it replaces) and is renamed over ``path``; if the body raises, the
    temporary file is removed and ``path`` is untouched.

    Parameters
    ----------
    path : path-like
        Final destination.  Its folder must exist.
    suffix : str, default ".tmp"
        Ending of the temporary file's name.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise FileNotFoundError(f"{target}: folder {folder} does not exist")
    fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix, dir=folder)
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        os.chmod(tmp, _final_mode(target))
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


@contextmanager
def atomic_write(path: str | os.PathLike[str], mode: str = "w", **kwargs) -> Iterator[IO]:
    """Open a temporary file next to ``path``; on success move it over ``path``.

    If the body raises, the temporary file is removed and ``path`` is untouched, so a
    failed write never leaves a truncated file or destroys an existing one.

    Parameters
    ----------
    path : path-like
        Final destination.  Its folder must exist.
    mode : {"w", "wb"}
        Text or binary.
    **kwargs
        Passed to :func:`open` (e.g. ``newline=""`` or ``encoding``).
    """
    if "b" not in mode:
        kwargs.setdefault("encoding", "utf-8")
    with atomic_path(path) as tmp:
        with open(tmp, mode, **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
