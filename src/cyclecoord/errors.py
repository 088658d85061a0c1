"""The project's exceptions: every error a user can cause is one of these.

Parsers raise :class:`ParseError` naming the file, the line (or frame) and what was
expected; invalid arguments raise :class:`ParameterError`; the pipeline raises
:class:`NoPeriodicMotionError` when the barcode holds no clear circle.  The CLI turns
any :class:`CycleCoordError` into a one-line message and a non-zero exit code.
"""

from __future__ import annotations

from os import PathLike

__all__ = [
    "CycleCoordError",
    "ParseError",
    "ParameterError",
    "NoPeriodicMotionError",
    "ImplausibleMotionError",
]


class CycleCoordError(Exception):
    """Base class of every error cyclecoord raises on purpose."""


class ParseError(CycleCoordError, ValueError):
    """A file could not be read.

    Parameters
    ----------
    message : str
        What was wrong and, where it helps, what was expected.
    path : path-like, optional
        The file being read.
    line : int, optional
        1-based line number in that file.
    frame : int, optional
        Frame number (as written in the file) where the problem is.
    """

    def __init__(
        self,
        message: str,
        path: str | PathLike[str] | None = None,
        line: int | None = None,
        frame: int | None = None,
    ) -> None:
        self.message = message
        self.path = None if path is None else str(path)
        self.line = line
        self.frame = frame
        super().__init__(str(self))

    def __str__(self) -> str:
        where = self.path or "<input>"
        if self.line is not None:
            where += f":{self.line}"
        if self.frame is not None:
            where += f" (frame {self.frame})"
        return f"{where}: {self.message}"

    def __reduce__(self):  # keep picklable for process pools
        return (type(self), (self.message, self.path, self.line, self.frame))


class ParameterError(CycleCoordError, ValueError):
    """An argument is out of range or inconsistent with the data."""


class NoPeriodicMotionError(CycleCoordError):
    """The barcode shows no H1 class standing clear of the rest.

    The partial result (barcode, timings) is attached as ``result`` when available so a
    caller can still report it.
    """

    def __init__(self, message: str, result: object | None = None) -> None:
        super().__init__(message)
        self.result = result


class ImplausibleMotionError(CycleCoordError):
    """Raised (by the CLI's ``--strict``) when a motion fails its plausibility checks."""
