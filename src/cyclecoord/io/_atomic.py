"""Atomic file output: write to a temporary file beside the target, then rename.

:func:`atomic_write` and :func:`atomic_path` make one file appear whole or not at all.
:class:`StagedOutputs` does it for every output of a run together: the files are written
into hidden staging folders beside their targets and moved into place only at the end, so
a run that fails or is interrupted (Ctrl-C) leaves every existing output as it was and no
new folder behind.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any, Iterator

__all__ = ["StagedOutputs", "atomic_path", "atomic_write"]

#: Names of the staging folders (hidden; left behind only by a killed process).
STAGING_PREFIX = ".cyclecoord-staged-"


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


class StagedOutputs:
    """Every output of one run, written aside and moved into place together at the end.

    :meth:`file` gives the path to write an output to: a file of the same name in a hidden
    staging folder beside the target (so a writer that puts a file beside its output, an
    AMC's ``.asf`` or a ``.gltf``'s ``.bin``, stages that one too, under the name it refers
    to).  :meth:`folder` gives a staging folder whose files all go into a folder (created,
    with its parents, only at the end).  :meth:`commit` moves everything into place with
    Ctrl-C held back over the renames; :meth:`discard` removes it all.  As a context
    manager it commits when the block ends normally and discards when it raises, so an
    exception or a Ctrl-C leaves every existing output as it was and no new folder.

    Examples
    --------
    >>> with StagedOutputs() as out:                      # doctest: +SKIP
    ...     save(cycle, out.file("cycle.bvh"))
    ...     save_figures(result, out.folder("figures"))
    """

    def __init__(self) -> None:
        self._staging: dict[str, tuple[Path, Path]] = {}  # target folder -> (staging, target)

    def _staging_for(self, folder: Path) -> Path:
        key = os.path.abspath(folder)
        if key not in self._staging:
            anchor = Path(key)
            while not anchor.exists() and anchor != anchor.parent:
                anchor = anchor.parent  # a folder to create: stage in its nearest ancestor
            if not anchor.is_dir():
                from ..errors import ParameterError

                raise ParameterError(f"{folder}: {anchor} exists and is not a folder")
            staging = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=anchor))
            self._staging[key] = (staging, folder)
        return self._staging[key][0]

    def file(self, path: str | os.PathLike[str]) -> Path:
        """Where to write the output ``path`` now; it moves to ``path`` on :meth:`commit`."""
        target = Path(path)
        return self._staging_for(target.parent if str(target.parent) else Path(".")) / target.name

    def folder(self, path: str | os.PathLike[str]) -> Path:
        """A folder to write into now; its files move into ``path`` on :meth:`commit`."""
        return self._staging_for(Path(path))

    def save(self, motion: Any, path: str | os.PathLike[str], **kwargs: Any) -> None:
        """:func:`cyclecoord.io.save` of ``motion`` to ``path``, staged.

        An AMC's skeleton is staged too and follows the rule of :func:`~cyclecoord.io.save`
        as applied at ``path``: an equal skeleton already at the default place is kept,
        a different one is never overwritten.
        """
        from . import _amc_default_skeleton, save

        target = Path(path)
        if (
            target.suffix.lower() == ".amc"
            and getattr(motion, "skeleton", None) is not None
            and kwargs.get("write_skeleton", True)
        ):
            asf = kwargs.pop("asf_path", None)
            if asf is None:
                asf = _amc_default_skeleton(motion, target)
            if asf is None:
                kwargs["write_skeleton"] = False
            else:
                kwargs["asf_path"] = self.file(asf)
        save(motion, self.file(target), **kwargs)

    def commit(self) -> list[Path]:
        """Move every staged file into place (Ctrl-C waits for the last rename).

        Returns the files moved, at their final places.
        """
        from .._signals import deferred_interrupt

        staged = list(self._staging.values())
        moves = [(entry, target / entry.name) for staging, target in staged
                 for entry in sorted(staging.iterdir())]
        for entry, dest in moves:
            if dest.is_dir() and not dest.is_symlink():
                from ..errors import ParameterError

                self.discard()
                raise ParameterError(f"{dest}: is a folder; cannot write {entry.name} there")
        with deferred_interrupt():
            for _staging, target in staged:
                target.mkdir(parents=True, exist_ok=True)
            for entry, dest in moves:
                try:
                    mode = dest.stat().st_mode & 0o7777  # a replaced file keeps its permissions
                except OSError:
                    pass
                else:
                    os.chmod(entry, mode)
                os.replace(entry, dest)
            self._remove_staging()
        return [dest for _entry, dest in moves]

    def discard(self) -> None:
        """Remove everything staged; no target is touched."""
        self._remove_staging()

    def _remove_staging(self) -> None:
        for staging, _target in self._staging.values():
            shutil.rmtree(staging, ignore_errors=True)
        self._staging.clear()

    def __enter__(self) -> "StagedOutputs":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.discard()
