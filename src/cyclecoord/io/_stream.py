"""Reading large text captures a block at a time, and the frame array they fill.

The AMC, BVH and CSV readers never hold a whole file, its lines or its values as Python
objects: :func:`text_lines` yields one line at a time from blocks of the file (decoded as
the readers always did, invalid UTF-8 replaced), :func:`count_lines` counts lines that
match a pattern at the speed of the regular expression engine (how many frames a file
holds, before its values are read), and :class:`FrameArray` is the ``(T, D)`` float
array the values go into, allocated once after the memory rule of
:func:`cyclecoord.io._limits.check_memory` allowed it.  Reading a capture so costs about
the array itself (8 bytes a value) and a block of text.
"""

from __future__ import annotations

import codecs
import os
import re
from collections.abc import Iterator

import numpy as np

from ._limits import MAX_FRAMES, check_memory, format_bytes

__all__ = ["BLOCK", "FirstBad", "FrameArray", "count_lines", "text_lines"]

#: Bytes read at a time.
BLOCK = 1 << 22
#: Frames parsed at a time (their text tokens are the only per-value Python objects).
CHUNK_FRAMES = 256
# str.splitlines() boundaries: a line that ends in one of these is complete (a "\r" may
# still be the first half of "\r\n" and waits for the next block)
_BREAKS = "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"


def _decoded_blocks(path: os.PathLike | str, bom: bool) -> Iterator[str]:
    decoder = codecs.getincrementaldecoder("utf-8")(errors="replace")
    first = True
    with open(path, "rb") as fh:
        while True:
            data = fh.read(BLOCK)
            text = decoder.decode(data, final=not data)
            if first and text:
                if bom and text.startswith("\ufeff"):
                    text = text[1:]
                first = False
            if text:
                yield text
            if not data:
                return


def text_lines(path: os.PathLike | str, newlines_only: bool = False, bom: bool = True
               ) -> Iterator[str]:
    """The lines of a text file without their line ends, read a block at a time.

    Parameters
    ----------
    path : path-like
    newlines_only : bool, default False
        Break lines at ``\\n``, ``\\r\\n`` and ``\\r`` only (the Acclaim readers'
        ``text.split("\\n")`` after normalising line ends, which yields a last empty line
        after a final line end); otherwise where :meth:`str.splitlines` breaks them.
    bom : bool, default True
        Drop a byte order mark at the start.

    Raises ``OSError`` as :func:`open` does.
    """
    carry = ""
    for text in _decoded_blocks(path, bom):
        text = carry + text
        if newlines_only:
            hold = text.endswith("\r")
            if hold:
                text = text[:-1]
            parts = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
            carry = parts.pop() + ("\r" if hold else "")
            yield from parts
            continue
        parts = text.splitlines(keepends=True)
        last = parts[-1] if parts else ""
        if last and (last[-1] not in _BREAKS or last[-1] == "\r"):
            carry = parts.pop()
        else:
            carry = ""
        for part in parts:
            yield part[:-2] if part.endswith("\r\n") else part[:-1]
    if newlines_only:
        parts = carry.replace("\r\n", "\n").replace("\r", "\n").split("\n")
        yield from parts
    elif carry:
        yield carry[:-1] if carry[-1] in _BREAKS else carry


def count_lines(path: os.PathLike | str, pattern: bytes) -> int:
    """How many ``\\n``-separated lines of the file ``pattern`` matches (a multiline bytes
    regular expression anchored with ``^``), counted a block at a time."""
    rx = re.compile(pattern, re.MULTILINE)
    count = 0
    carry = b""
    with open(path, "rb") as fh:
        while True:
            data = fh.read(BLOCK)
            if not data:
                break
            data = carry + data
            cut = data.rfind(b"\n") + 1
            carry = data[cut:]
            count += sum(1 for _ in rx.finditer(data, 0, cut))
    if carry:
        count += sum(1 for _ in rx.finditer(carry))
    return count


class FrameArray:
    """A ``(T, D)`` float array filled a chunk of frames at a time.

    ``expected`` frames (a count of the file's lines, or what it declares) are allocated
    at once once :func:`check_memory` allows them; a file that holds more than it seemed
    grows the array (checked again), one that holds fewer gives its first rows.

    Parameters
    ----------
    expected : int
        Frames to make room for.
    n_channels : int
    path : path-like
        The file (named by a refusal).
    size : int, optional
        The file's size in bytes, for the refusal's message.
    """

    def __init__(self, expected: int, n_channels: int, path, size: int | None = None) -> None:
        self.path = path
        self.size = size
        self.n_channels = int(n_channels)
        self.n = 0
        self.array = self._allocate(max(int(expected), 1))

    def _allocate(self, rows: int) -> np.ndarray:
        rows = min(rows, MAX_FRAMES)
        file = f"a {format_bytes(self.size)} file: " if self.size is not None else ""
        check_memory(
            8.0 * rows * self.n_channels,
            f"{file}{rows:,} frames of {self.n_channels:,} channels",
            self.path,
        )
        return np.empty((rows, self.n_channels))

    def rows(self, k: int) -> np.ndarray:
        """The next ``k`` rows to fill (the array grows when they do not fit)."""
        if self.n + k > self.array.shape[0]:
            bigger = self._allocate(max(self.n + k, self.array.shape[0] + self.array.shape[0] // 4))
            bigger[: self.n] = self.array[: self.n]
            self.array = bigger
        out = self.array[self.n : self.n + k]
        self.n += k
        return out

    def result(self) -> np.ndarray:
        """The filled rows, read-only (a :class:`~cyclecoord.motion.Motion` keeps them without
        a copy)."""
        a = self.array
        if self.n < a.shape[0]:
            a.resize((self.n, self.n_channels), refcheck=False)
        a.flags.writeable = False
        return a


class FirstBad:
    """While converting frames a chunk at a time: the first value that is no number and
    the first that is not finite or too big (each a ParseError, raised after the whole
    file's count is checked, in a whole-file read's order)."""

    number = None  # ParseError | None
    value = None  # ParseError | None
    frame = 0  # frames converted so far
