"""What a motion file may make cyclecoord do, and what a writer may put in a file.

Every reader caps what a file can declare (joints, hierarchy depth, frames, metadata size
and nesting, the digits of a whole number) and refuses values no capture holds
(non-finite numbers, magnitudes beyond :data:`MAX_MAGNITUDE`); every writer refuses what
its reader would refuse (:func:`check_writable`), so cyclecoord never writes a file it
cannot read back.  Readers raise :class:`~cyclecoord.errors.ParseError` naming the file,
the line, frame or NPZ key; writers raise :class:`~cyclecoord.errors.ParameterError`
naming the output.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

import numpy as np

from ..errors import ParameterError

__all__ = [
    "MAX_JOINTS",
    "MAX_DEPTH",
    "MAX_FRAMES",
    "MAX_FRAME_NUMBER",
    "MAX_MAGNITUDE",
    "MAX_FPS",
    "MIN_FPS",
    "fps_problem",
    "MAX_INT_DIGITS",
    "MAX_METADATA_BYTES",
    "MAX_METADATA_DEPTH",
    "MAX_NPZ_BYTES",
    "parse_int",
    "depths",
    "skeleton_problem",
    "frames_problem",
    "metadata_problem",
    "metadata_json",
    "check_writable",
    "machine_memory",
    "memory_limit",
    "stated_memory_limit",
    "memory_problem",
    "check_memory",
    "format_bytes",
]

#: Joints in one skeleton (rigs with fingers and a face have a few hundred).
MAX_JOINTS = 4096
#: Levels from the root to the deepest joint (real skeletons stay below 60).
MAX_DEPTH = 512
#: Frames in one capture (23 hours at 120 fps).
MAX_FRAMES = 10_000_000
#: Largest frame number (AMC frame numbers, ``start_frame``).
MAX_FRAME_NUMBER = 1_000_000_000
#: Largest absolute channel value, offset, length or limit.  Beyond it angles lose all
#: precision (one float step exceeds a degree near 1e16) and squared distances overflow.
MAX_MAGNITUDE = 1e9
#: Highest frame rate, and the lowest (one frame every 11.6 days).
MAX_FPS = 1e6
MIN_FPS = 1e-6
#: Digits of a whole number in a text file (Python refuses beyond 4,300).
MAX_INT_DIGITS = 12
#: Size of stored metadata (the NPZ ``metadata_json``), in bytes of JSON text.
MAX_METADATA_BYTES = 16 * 1024 * 1024
#: Unpacked size of an NPZ archive (4 million frames of 62 channels take 2 GB).
MAX_NPZ_BYTES = 2 * 1024**3
#: Nesting of stored metadata (lists and objects within each other).
MAX_METADATA_DEPTH = 64

_INT_TEXT = re.compile(r"[+-]?[0-9]+")
_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)


def parse_int(text: str, what: str, low: int = 0, high: int = MAX_FRAME_NUMBER) -> int:
    """A whole number written as text, within ``[low, high]``.

    Raises ``ValueError`` with a message saying what was wrong (the caller adds the
    file and the line); never reads more than :data:`MAX_INT_DIGITS` digits.
    """
    s = text.strip()
    if not _INT_TEXT.fullmatch(s):
        raise ValueError(f"expected a whole number for {what}, found {s[:40]!r}")
    digits = len(s.lstrip("+-").lstrip("0"))
    if digits > MAX_INT_DIGITS:
        raise ValueError(f"{what} has {digits} digits; at most {high:,} is supported")
    value = int(s)
    if not low <= value <= high:
        raise ValueError(f"{what} must lie in {low:,}..{high:,}, found {value:,}")
    return value


def depths(parents: list[int] | np.ndarray) -> list[int]:
    """Depth of every joint (root 0) given parents that come before their children."""
    out: list[int] = []
    for i, p in enumerate(parents):
        out.append(0 if p < 0 or p >= i else out[p] + 1)
    return out


def fps_problem(fps: float) -> str | None:
    """What makes a frame rate unfit for a file, or ``None``."""
    if not np.isfinite(fps) or not MIN_FPS <= fps <= MAX_FPS:
        return (
            f"frame rate {fps!r} is not a positive number of frames per second in "
            f"{MIN_FPS:g}..{MAX_FPS:g}"
        )
    return None


def _bad_values(a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, dtype=float)
    with np.errstate(invalid="ignore"):
        return ~np.isfinite(a) | (np.abs(a) > MAX_MAGNITUDE)


def _describe(value: float) -> str:
    return f"{value!r}" if np.isfinite(value) else str(value)


def skeleton_problem(skeleton: Any) -> str | None:
    """What makes ``skeleton`` unfit for a file, or ``None``.

    Checks the joint count, the depth, and every offset, end site, limit and axis
    (finite, within :data:`MAX_MAGNITUDE`, axes rotations).
    """
    joints = skeleton.joints
    if len(joints) > MAX_JOINTS:
        return f"{len(joints):,} joints; at most {MAX_JOINTS:,} are supported"
    deep = max(depths([j.parent for j in joints]))
    if deep > MAX_DEPTH:
        return f"hierarchy {deep} levels deep; at most {MAX_DEPTH} are supported"
    if not np.isfinite(skeleton.length_unit) or not 0 < skeleton.length_unit <= MAX_MAGNITUDE:
        return f"length unit {skeleton.length_unit!r} is not a positive number"
    for j in joints:
        for what, vec in (("offset", j.offset), ("end site", j.end_site)):
            if vec is None:
                continue
            bad = _bad_values(vec)
            if bad.any():
                v = float(np.asarray(vec, dtype=float)[np.argmax(bad)])
                return (
                    f"joint {j.name!r}: {what} component {_describe(v)} is not a finite "
                    f"number of at most {MAX_MAGNITUDE:g} in magnitude"
                )
        axis = np.asarray(j.axis, dtype=float)
        if not np.all(np.isfinite(axis)) or (
            np.max(np.abs(axis @ axis.T - np.eye(3))) > 1e-6 or np.linalg.det(axis) <= 0
        ):
            return f"joint {j.name!r}: axis is not a rotation matrix"
        for dof, (lo, hi) in j.limits.items():
            if np.isnan(lo) or np.isnan(hi) or (np.isfinite(lo) and abs(lo) > MAX_MAGNITUDE) or (
                np.isfinite(hi) and abs(hi) > MAX_MAGNITUDE
            ):
                return f"joint {j.name!r}: limit of {dof} ({lo}, {hi}) is not a pair of numbers"
    return None


#: Values checked at a time by :func:`frames_problem` (32 MB of float64).
_CHECK_BLOCK_VALUES = 1 << 22


def frames_problem(frames: np.ndarray, channels) -> str | None:
    """What makes a ``(T, D)`` frame array unfit for a file (frames counted from 1)."""
    frames = np.asarray(frames)
    T = frames.shape[0]
    if T == 0:
        return "no frames"
    if T > MAX_FRAMES:
        return f"{T:,} frames; at most {MAX_FRAMES:,} are supported"
    if frames.ndim != 2 or frames.shape[1] == 0:
        return "no channels"
    # a block of rows at a time: checking the whole array at once took twice its size
    # again (np.abs's copy and the masks), 2 GB more for a 2-million-frame motion
    step = max(1, _CHECK_BLOCK_VALUES // frames.shape[1])
    for a in range(0, T, step):
        bad = _bad_values(frames[a : a + step])
        if bad.any():
            t, c = (int(v) for v in np.argwhere(bad)[0])
            v = float(frames[a + t, c])
            kind = "value" if np.isfinite(v) else "non-finite value"
            return (
                f"frame {a + t + 1}, channel {'.'.join(channels[c])}: {kind} {_describe(v)}; "
                f"expected a finite number of at most {MAX_MAGNITUDE:g} in magnitude"
            )
    return None


def metadata_problem(text: str) -> str | None:
    """What makes JSON metadata text too large or too deeply nested, or ``None``.

    Looks at the text only (strings removed, brackets counted), so a hostile file is
    refused before the JSON parser recurses into it.
    """
    size = len(text.encode("utf-8", errors="surrogatepass"))
    if size > MAX_METADATA_BYTES:
        return f"{size:,} bytes; at most {MAX_METADATA_BYTES:,} are supported"
    bare = _JSON_STRING.sub("", text)
    if not bare:
        return None
    codes = np.frombuffer(bare.encode("utf-8", errors="replace"), dtype=np.uint8)
    step = np.zeros(codes.shape, dtype=np.int64)
    step[(codes == ord("[")) | (codes == ord("{"))] = 1
    step[(codes == ord("]")) | (codes == ord("}"))] = -1
    deepest = int(np.cumsum(step).max(initial=0))
    if deepest > MAX_METADATA_DEPTH:
        return f"nested {deepest} levels deep; at most {MAX_METADATA_DEPTH} are supported"
    return None


def metadata_json(metadata: dict) -> str:
    """JSON of the serialisable metadata entries (others dropped), checked for size and depth.

    Raises
    ------
    ParameterError
        When an entry alone nests deeper than :data:`MAX_METADATA_DEPTH` or the whole
        exceeds :data:`MAX_METADATA_BYTES` (the message names the entry).
    """
    kept = {}
    for key, value in metadata.items():
        try:
            text = json.dumps(value, allow_nan=True)
        except (TypeError, ValueError, RecursionError):
            continue
        problem = metadata_problem("[" + text + "]")
        if problem is not None:
            raise ParameterError(f"metadata entry {str(key)!r} is {problem}")
        kept[str(key)] = value
    text = json.dumps(kept, allow_nan=True)
    problem = metadata_problem(text)
    if problem is not None:
        raise ParameterError(f"the metadata is {problem}")
    return text


def check_writable(motion: Any, path: Any, fmt: str, skeleton: bool = True) -> None:
    """Refuse, before anything is written, a motion the ``fmt`` reader would refuse.

    Parameters
    ----------
    motion : Motion
        What is about to be written.
    path : path-like
        The output (named in the message).
    fmt : str
        The format's name for the message, e.g. ``"BVH"``.
    skeleton : bool, default True
        Whether the format stores the skeleton (then it is checked too).

    Raises
    ------
    ParameterError
        ``"<path>: cannot write <fmt>: <what is wrong>"``.
    """
    def fail(why: str) -> ParameterError:
        return ParameterError(f"{path}: cannot write {fmt}: {why}")

    problem = frames_problem(motion.frames, motion.channels)
    if problem is not None:
        raise fail(problem if problem.startswith("frame ") else f"the motion has {problem}")
    problem = fps_problem(motion.fps)
    if problem is not None:
        raise fail(problem)
    if not 0 <= int(motion.start_frame) <= MAX_FRAME_NUMBER:
        raise fail(f"start frame {motion.start_frame} is not in 0..{MAX_FRAME_NUMBER:,}")
    if skeleton and motion.skeleton is not None:
        problem = skeleton_problem(motion.skeleton)
        if problem is not None:
            raise fail(f"skeleton: {problem}")


# ----------------------------------------------------------------------------- memory
#: The memory limit a command runs under (``--memory-limit``, bytes), set by
#: :func:`memory_limit`; ``None``: what the machine allows (:func:`machine_memory`).
_STATED_LIMIT: ContextVar[float | None] = ContextVar("cyclecoord_memory_limit", default=None)


def _mapped_bytes() -> float:
    """Virtual memory this process has mapped already (Linux; 0 elsewhere)."""
    try:
        with open("/proc/self/statm") as fh:
            return float(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError, AttributeError):
        return 0.0


def machine_memory() -> float:
    """Bytes this process can allocate at most: physical memory, lowered by a cgroup
    memory limit and by an address-space or data rlimit (less what is mapped already).
    ``inf`` when nothing can be read."""
    found = []
    try:
        found.append(float(os.sysconf("SC_PAGE_SIZE")) * float(os.sysconf("SC_PHYS_PAGES")))
    except (ValueError, OSError, AttributeError):
        pass
    for path in ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"):
        try:
            with open(path) as fh:
                text = fh.read().strip()
        except OSError:
            continue
        if text.isdigit() and int(text) < 2**60:  # "max" or a huge number: no limit
            found.append(float(text))
    try:
        import resource

        for which in (resource.RLIMIT_AS, resource.RLIMIT_DATA):
            soft, _ = resource.getrlimit(which)
            if soft != resource.RLIM_INFINITY and soft > 0:
                found.append(max(float(soft) - _mapped_bytes(), 0.0))
    except (ImportError, ValueError, OSError):
        pass
    return min(found) if found else float("inf")


def format_bytes(n: float) -> str:
    """``123 MB``, ``2.15 GB``: decimal units, three significant figures."""
    n = float(n)
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} bytes"


@contextmanager
def memory_limit(limit: float | None) -> Iterator[None]:
    """Run the body under a stated memory limit (bytes; ``None`` leaves the machine's).

    The command line wraps every command in it with the command's ``--memory-limit``;
    readers and generators then refuse, before allocating, what would not fit
    (:func:`check_memory`).
    """
    if limit is not None and (
        isinstance(limit, bool) or not np.isfinite(float(limit)) or float(limit) <= 0
    ):
        raise ParameterError(f"memory limit must be a positive number of bytes, got {limit!r}")
    token = _STATED_LIMIT.set(None if limit is None else float(limit))
    try:
        yield
    finally:
        _STATED_LIMIT.reset(token)


def stated_memory_limit() -> float | None:
    """The limit :func:`memory_limit` set, or ``None``."""
    return _STATED_LIMIT.get()


def memory_problem(nbytes: float, what: str) -> str | None:
    """Why ``nbytes`` for ``what`` (e.g. ``"1,000,000 frames of 62 channels"``) would not
    fit, or ``None``: over the stated limit, or over what the machine allows."""
    need = float(nbytes)
    stated = _STATED_LIMIT.get()
    if stated is not None and need > stated:
        return (
            f"{what} need {format_bytes(need)} of memory, over the memory limit of "
            f"{format_bytes(stated)} (--memory-limit)"
        )
    machine = machine_memory()
    if need > machine:
        return (
            f"{what} need {format_bytes(need)} of memory; this machine allows "
            f"{format_bytes(machine)}"
        )
    return None


def check_memory(nbytes: float, what: str, path: Any = None) -> None:
    """Refuse, before allocating, ``nbytes`` that would not fit (see :func:`memory_problem`).

    Raises :class:`~cyclecoord.errors.ParseError` naming ``path`` when one is given (a
    reader), else :class:`~cyclecoord.errors.ParameterError`.
    """
    problem = memory_problem(nbytes, what)
    if problem is None:
        return
    if path is not None:
        from ..errors import ParseError

        raise ParseError(problem, str(path))
    raise ParameterError(problem)
