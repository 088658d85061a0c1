"""Reading Acclaim AMC motions, and finding the ASF beside them (conventions in
:mod:`cyclecoord.io.asfamc`)."""

from __future__ import annotations

import bisect
import math
import os
from pathlib import Path

import numpy as np

from ..errors import ParameterError, ParseError
from ..motion import Motion
from ..skeleton import Skeleton
from ._acclaim import (
    DEG_PER_RAD,
    INT_RE,
    PathLike,
    asf_layout,
    read_text,
    safe_name,
)
from ._stream import CHUNK_FRAMES, FrameArray, count_lines, text_lines
from ._limits import (
    MAX_FRAME_NUMBER,
    MAX_FRAMES,
    MAX_MAGNITUDE,
    parse_int,
)
from .asf_read import parse_asf

__all__ = ["read_amc", "find_skeleton"]


# --------------------------------------------------------------------------- AMC read
def _header_skeleton(amc_path: Path) -> Path | None:
    """The file an ``#!OML:ASF NAME`` line before the first frame names, if it is a file
    beside the AMC (a bare name only: a path in the header is not followed)."""
    try:
        with open(amc_path, "rb") as fh:
            head = fh.read(4096).decode("latin-1")
    except OSError:
        return None
    for line in head.splitlines():
        line = line.strip()
        if line.startswith("#!OML:ASF"):
            name = line[len("#!OML:ASF"):].strip()
            if name and Path(name).name == name and name.lower().endswith(".asf"):
                p = amc_path.parent / name
                return p if p.is_file() else None
            return None
        if line and not line.startswith("#") and not line.startswith(":"):
            return None  # the frames have begun
    return None


def find_skeleton(amc_path: Path) -> Path:
    """The .asf that :func:`read_amc` uses for ``amc_path`` when no skeleton is given.

    The .asf the AMC's ``#!OML:ASF NAME`` header line names, when it lies beside the AMC
    (:func:`cyclecoord.io.save` writes that line); else the only .asf in the AMC's
    folder; else ``<stem>.asf`` for ``<stem>.amc`` (where :func:`cyclecoord.io.save` puts
    it) or ``<subject>.asf`` for ``<subject>_<trial>.amc``.

    Raises
    ------
    ParseError
        When neither rule finds exactly one file (the message says what was looked for).
    """
    folder = amc_path.parent
    named = _header_skeleton(amc_path)
    if named is not None:
        return named
    try:
        asfs = sorted(
            p for p in folder.iterdir() if p.suffix.lower() == ".asf" and p.is_file()
        )
    except OSError as exc:
        raise ParseError(f"cannot list folder {folder}: {exc.strerror or exc}", amc_path) from None
    if len(asfs) == 1:
        return asfs[0]
    for p in asfs:
        if p.stem == amc_path.stem:
            return p
    subject = amc_path.stem.split("_", 1)[0] if "_" in amc_path.stem else None
    if subject:
        for p in asfs:
            if p.name.lower() == f"{subject}.asf".lower():
                return p
    looked = f"'{subject}.asf' (from the <subject>_<trial>.amc name) or " if subject else ""
    raise ParseError(
        f"no skeleton found: looked for {looked}a folder holding exactly one .asf, "
        f"but {folder} holds {len(asfs)} .asf file(s)"
        + (f" ({', '.join(p.name for p in asfs[:5])})" if asfs else "")
        + "; give the skeleton explicitly (--skeleton ASF on the command line, skeleton= "
        "in Python)",
        amc_path,
    )


def _resolve_skeleton(
    amc_path: Path, skeleton: Skeleton | PathLike | None
) -> tuple[Skeleton, str | None]:
    if isinstance(skeleton, Skeleton):
        return skeleton, None
    if skeleton is None:
        asf = find_skeleton(amc_path)
    elif isinstance(skeleton, (str, os.PathLike)):
        asf = Path(skeleton)
    else:
        raise ParameterError(
            f"skeleton must be a Skeleton, a path to an .asf file or None, "
            f"got {type(skeleton).__name__}"
        )
    skel, info = parse_asf(read_text(asf), asf)
    return skel, info["angle"]


def _amc_bone_map(skel: Skeleton) -> dict[str, tuple[str, tuple[str, ...]]]:
    """AMC bone name -> (joint name, dofs in listing order).

    The ASF names of the skeleton's bones, and also its own joint names where unambiguous.
    """
    bone_map: dict[str, tuple[str, tuple[str, ...]]] = {}
    layout = [b for b in asf_layout(skel) if b.joint is not None]
    for b in layout:
        bone_map[b.asf_name] = (b.joint, b.dofs)
    for b in layout:  # also accept the skeleton's own joint names where unambiguous
        if safe_name(b.joint) == b.joint:
            bone_map.setdefault(b.joint, (b.joint, b.dofs))
    return bone_map


class _AmcScan:
    """What the line-by-line scan of an AMC file has gathered so far.

    The values of the frames not yet converted stay text tokens in ``flat``, record after
    record (one record: one bone of one frame, in the bone order of the first frame);
    ``rec_start`` is where each record starts in ``flat`` and ``rec_info`` its ``(line,
    frame, bone)``, for the messages.  Every :data:`~._stream.CHUNK_FRAMES` frames they
    are converted into ``out`` (:meth:`flush`), allocated for ``expected`` frames when the
    first frame has been read.
    """

    def __init__(
        self, path: PathLike, bone_map: dict, expected: int = 1, size: int | None = None,
        default_angle: str | None = None,
    ) -> None:
        self.path = path
        self.bone_map = bone_map
        self.expected = expected
        self.size = size
        self.default_angle = default_angle
        self.out: FrameArray | None = None
        self.pending = 0
        # the first value that is no finite number, and the first beyond the magnitude cap:
        # raised once every line is read, as a whole-file read would (a malformed line
        # anywhere comes first)
        self.bad_value: ParseError | None = None
        self.big_value: ParseError | None = None
        self.header: list[str] = []
        self.angle: str | None = None
        self.angle_line = 0
        self.frame_no: int | None = None
        self.frame_line = 0
        self.first_number: int | None = None
        self.first_bones: list[str] | None = None
        self.entries: list[tuple[str, int, list[str]]] = []
        self.flat: list[str] = []
        self.rec_start: list[int] = []
        self.rec_info: list[tuple[int, int, str]] = []  # (line, frame, bone)
        self.n_frames = 0
        self.last_line = 0

    def emit(self, frame: int, items) -> None:
        """Append the records of one frame."""
        for bone, ln, parts in items:
            self.rec_start.append(len(self.flat))
            self.rec_info.append((ln, frame, bone))
            self.flat.extend(parts[1:])

    def close_frame(self) -> None:
        """Check the frame just read against the first one and append its records."""
        path, frame_no, frame_line = self.path, self.frame_no, self.frame_line
        entries, first_bones = self.entries, self.first_bones
        assert frame_no is not None
        if self.n_frames >= MAX_FRAMES:
            raise ParseError(
                f"more than {MAX_FRAMES:,} frames; at most {MAX_FRAMES:,} are supported",
                path,
                frame_line,
                frame_no,
            )
        if first_bones is None:
            self.first_bones = self._first_frame_bones()
            n_cols = sum(len(self.bone_map[b][1]) for b in self.first_bones)
            self.out = FrameArray(self.expected, n_cols, path, self.size)
            self.emit(frame_no, entries)
        elif len(entries) == len(first_bones) and all(
            e[0] == b for e, b in zip(entries, first_bones)
        ):
            self.emit(frame_no, entries)
        else:
            self.emit(frame_no, self._in_first_frame_order())
        self.n_frames += 1
        self.pending += 1
        if self.pending >= CHUNK_FRAMES:
            self.flush()

    def unit(self) -> str:
        """``"deg"`` or ``"rad"``: the header's, else the skeleton's (fixed at the first frame)."""
        return self.angle or self.default_angle or "deg"

    def flush(self) -> None:
        """Convert the pending frames' tokens into rows of ``out`` (values checked)."""
        if not self.pending:
            return
        assert self.out is not None
        rows = self.out.rows(self.pending)
        if self.bad_value is None:
            try:
                _amc_values(self, self.path, self.unit(), rows)
            except _BadValue as exc:
                self.bad_value = exc.error
            except ParseError as exc:
                self.big_value = self.big_value or exc
        self.flat.clear()
        self.rec_start.clear()
        self.rec_info.clear()
        self.pending = 0

    def _first_frame_bones(self) -> list[str]:
        """The bones of the first frame, each naming a different joint."""
        path, frame_no, entries = self.path, self.frame_no, self.entries
        names = [e[0] for e in entries]
        if not names:
            raise ParseError(
                f"frame {frame_no} has no bone values; expected lines '<bone> <values>'",
                path,
                self.frame_line,
                frame_no,
            )
        owners: dict[str, str] = {}
        for bone, ln, _ in entries:
            joint = self.bone_map[bone][0]
            if joint in owners:
                raise ParseError(
                    f"bone {bone!r} appears twice in frame {frame_no}"
                    if owners[joint] == bone
                    else f"bones {owners[joint]!r} and {bone!r} name the same joint",
                    path,
                    ln,
                    frame_no,
                )
            owners[joint] = bone
        return names

    def _in_first_frame_order(self) -> list[tuple[str, int, list[str]]]:
        """This frame's entries in the first frame's bone order, each bone once."""
        path, frame_no, first_bones = self.path, self.frame_no, self.first_bones
        assert first_bones is not None
        by_name: dict[str, tuple[str, int, list[str]]] = {}
        wanted = set(first_bones)
        for e in self.entries:
            if e[0] in by_name:
                raise ParseError(
                    f"bone {e[0]!r} appears twice in frame {frame_no}", path, e[1], frame_no
                )
            if e[0] not in wanted:
                raise ParseError(
                    f"bone {e[0]!r} does not appear in the first frame; every frame must "
                    "hold the same bones",
                    path,
                    e[1],
                    frame_no,
                )
            by_name[e[0]] = e
        missing = [b for b in first_bones if b not in by_name]
        if missing:
            listed = ", ".join(repr(b) for b in missing[:5])
            more = f" and {len(missing) - 5} more" if len(missing) > 5 else ""
            raise ParseError(
                f"frame {frame_no} (starting at line {self.frame_line}) is missing bone "
                f"{listed}{more}; expected the {len(first_bones)} bones of the first frame",
                path,
                self.frame_line,
                frame_no,
            )
        return [by_name[b] for b in first_bones]

    def frame_number(self, head: str, ln: int) -> None:
        """A line holding only a frame number: close the previous frame, open this one."""
        path = self.path
        try:
            number = parse_int(head, "a frame number", -MAX_FRAME_NUMBER, MAX_FRAME_NUMBER)
        except ValueError as exc:
            raise ParseError(str(exc), path, ln, self.frame_no) from None
        if self.frame_no is None:
            self.first_number = number
        else:
            self.close_frame()
            if number != self.frame_no + 1:
                raise ParseError(
                    f"frame number {number} out of sequence: expected {self.frame_no + 1}",
                    path,
                    ln,
                    number,
                )
        self.frame_no = number
        self.frame_line = ln
        self.entries = []

    def header_line(self, head: str, raw: str, ln: int) -> None:
        """A ``:keyword`` line before the first frame (``:DEGREES``/``:RADIANS`` are read)."""
        path = self.path
        if self.frame_no is not None:
            raise ParseError(
                f"header line {raw.strip()!r} after the first frame; expected a frame "
                "number or a bone line",
                path,
                ln,
                self.frame_no,
            )
        key = head.upper()
        if key in (":DEGREES", ":RADIANS"):
            this = "deg" if key == ":DEGREES" else "rad"
            if self.angle is not None and self.angle != this:
                raise ParseError(
                    f"{head} contradicts the angle unit given at line {self.angle_line}",
                    path,
                    ln,
                )
            self.angle, self.angle_line = this, ln
        self.header.append(raw.strip())

    def bone_line(
        self, parts: list[str], raw: str, ln: int, skel: Skeleton, skel_file: PathLike | None
    ) -> None:
        """A ``<bone> <values>`` line of the current frame."""
        path, frame_no, head = self.path, self.frame_no, parts[0]
        if frame_no is None:
            raise ParseError(
                f"expected a frame number before bone values, got {raw.strip()!r}", path, ln
            )
        spec = self.bone_map.get(head)
        if spec is None:
            if INT_RE.fullmatch(head):
                raise ParseError(
                    f"expected a frame number alone on its line, got {raw.strip()!r}",
                    path,
                    ln,
                    frame_no,
                )
            raise ParseError(
                f"bone {head!r} is not in the skeleton"
                + (f" {skel.name!r}" if skel.name else "")
                + (f" ({skel_file})" if skel_file is not None else ""),
                path,
                ln,
                frame_no,
            )
        nd = len(spec[1])
        if len(parts) - 1 != nd:
            got = len(parts) - 1
            # where the skeleton's side of a mismatch comes from, for the messages
            per = f" (dofs per the skeleton {skel_file})" if skel_file is not None else ""
            raise ParseError(
                f"bone {head!r} has {nd} dof{'s' if nd != 1 else ''} "
                f"({' '.join(spec[1]) or 'none'}), got {got} value{'s' if got != 1 else ''}{per}",
                path,
                ln,
                frame_no,
            )
        if nd:
            self.entries.append((head, ln, parts))


def _scan_amc(
    lines, path: PathLike, skel: Skeleton, bone_map: dict, skel_file: PathLike | None,
    expected: int = 1, size: int | None = None, default_angle: str | None = None,
) -> _AmcScan:
    """Read every line of an AMC into an :class:`_AmcScan`, every frame closed and its
    values converted."""
    scan = _AmcScan(path, bone_map, expected, size, default_angle)
    for ln, raw in enumerate(lines, 1):
        if "#" in raw:
            if scan.frame_no is None and raw.lstrip().startswith("#"):
                scan.header.append(raw.strip())
                continue
            raw = raw[: raw.index("#")]
        parts = raw.split()
        if not parts:
            continue
        scan.last_line = ln
        head = parts[0]
        if len(parts) == 1 and INT_RE.fullmatch(head):
            scan.frame_number(head, ln)
        elif head.startswith(":"):
            scan.header_line(head, raw, ln)
        else:
            scan.bone_line(parts, raw, ln, skel, skel_file)
    if scan.frame_no is None:
        raise ParseError(
            "no frames: expected a frame number after the header", path, scan.last_line or 1
        )
    scan.close_frame()
    scan.flush()
    assert scan.first_bones is not None
    if scan.bad_value is not None or scan.big_value is not None:
        raise scan.bad_value or scan.big_value
    return scan


class _BadValue(Exception):
    """A value that is no finite number (its ParseError in ``error``)."""

    def __init__(self, error: ParseError) -> None:
        super().__init__(str(error))
        self.error = error


def _channels(scan: _AmcScan) -> list:
    """The ``(joint, dof)`` channels of the columns (the first frame's bones)."""
    bone_map = scan.bone_map
    return [(bone_map[b][0], d) for b in scan.first_bones for d in bone_map[b][1]]


def _amc_values(scan: _AmcScan, path: PathLike, unit: str, frames: np.ndarray) -> None:
    """The pending frames' values, in degrees, into ``frames`` ``(k, D)``, checked."""
    flat = scan.flat
    try:
        frames.reshape(-1)[:] = np.fromiter(map(float, flat), dtype=float, count=len(flat))
        ok = bool(np.isfinite(frames).all())
    except ValueError:
        ok = False
    if not ok:
        try:
            _locate_bad_value(flat, scan.rec_start, scan.rec_info, path)
        except ParseError as exc:
            raise _BadValue(exc) from None
    if unit == "rad":
        rot = [i for i, (_, d) in enumerate(_channels(scan)) if d.startswith("r")]
        frames[:, rot] *= DEG_PER_RAD
    big = np.abs(frames) > MAX_MAGNITUDE
    if big.any():
        k = int(np.argmax(big.reshape(-1)))
        rec = bisect.bisect_right(scan.rec_start, k) - 1
        ln, frame, bone = scan.rec_info[rec]
        raise ParseError(
            f"value {flat[k]!r} for bone {bone!r} is beyond the largest supported magnitude "
            f"{MAX_MAGNITUDE:g}" + (" degrees" if unit == "rad" else ""),
            path,
            ln,
            frame,
        )


#: A line holding a frame number alone (how many frames the file holds, counted first).
_FRAME_LINE = rb"^[ \t]*[+-]?[0-9]+[ \t\r]*$"


def _parse_amc(
    amc_path: Path, path: PathLike, skel: Skeleton, default_angle: str | None, fps: float,
    skel_file: PathLike | None = None,
) -> Motion:
    try:
        expected = count_lines(amc_path, _FRAME_LINE)
        size = amc_path.stat().st_size
        scan = _scan_amc(
            text_lines(amc_path, newlines_only=True), path, skel, _amc_bone_map(skel),
            skel_file, expected, size, default_angle,
        )
    except OSError as exc:
        raise ParseError(f"cannot read file: {exc.strerror or exc}", path) from None
    assert scan.out is not None
    return Motion(
        frames=scan.out.result(),
        channels=tuple(_channels(scan)),
        fps=fps,
        skeleton=skel,
        source=str(path),
        start_frame=0,
        metadata={"amc_header": scan.header, "first_frame_number": scan.first_number},
    )


def _locate_bad_value(flat, rec_start, rec_info, path) -> None:
    """Raise the ParseError for the first token that is not a finite number."""
    bounds = rec_start + [len(flat)]
    for k, (ln, frame, bone) in enumerate(rec_info):
        for tok in flat[bounds[k] : bounds[k + 1]]:
            try:
                v = float(tok)
            except ValueError:
                raise ParseError(
                    f"expected a number for bone {bone!r}, got {tok!r}", path, ln, frame
                ) from None
            if not math.isfinite(v):
                raise ParseError(
                    f"non-finite value {tok!r} for bone {bone!r}; expected a finite number",
                    path,
                    ln,
                    frame,
                )
    raise ParseError("could not convert the frame values to numbers", path)  # pragma: no cover


def read_amc(
    path: PathLike,
    skeleton: Skeleton | PathLike | None = None,
    fps: float = 120.0,
) -> Motion:
    """Read an Acclaim AMC motion.

    Parameters
    ----------
    path : path-like
        The ``.amc`` file.
    skeleton : Skeleton, path-like or None
        The skeleton, or its ``.asf`` file.  ``None`` looks beside the AMC: the folder's
        only ``.asf``, else ``<subject>.asf`` for a ``<subject>_<trial>.amc``.
    fps : float
        Frame rate (AMC files carry none; CMU captures are 120 Hz).

    Returns
    -------
    Motion
        ``frames`` of shape ``(T, D)``: one row per frame, columns the ``(bone, dof)``
        pairs in the order the bones appear in the first frame (dofs in ASF order).
        Angles in degrees, translations in skeleton length units.  ``metadata`` holds
        ``amc_header`` (header lines) and ``first_frame_number``.

    Raises
    ------
    ParseError
        Naming file, line and frame: empty file, no frames, missing or unknown bones,
        wrong value counts, non-numbers or non-finite values, frame numbers out of
        sequence, or a skeleton that cannot be found or read.
    ParameterError
        For a bad ``skeleton`` argument type or ``fps``.
    """
    fps = float(fps)
    if not math.isfinite(fps) or fps <= 0:
        raise ParameterError(f"fps must be a positive number, got {fps}")
    amc_path = Path(path)
    if _blank(amc_path, path):
        raise ParseError("file is empty; expected an AMC header and frames", path, 1)
    skel, default_angle = _resolve_skeleton(amc_path, skeleton)
    if isinstance(skeleton, Skeleton):
        skel_file = None
    else:
        skel_file = find_skeleton(amc_path) if skeleton is None else Path(skeleton)
    return _parse_amc(amc_path, path, skel, default_angle, fps, skel_file)


def _blank(amc_path: Path, path: PathLike) -> bool:
    """Whether the file holds nothing but white space (read until it holds something)."""
    if amc_path.is_dir():
        raise ParseError("is a folder, expected a file", path)
    try:
        return all(not line.strip() for line in text_lines(amc_path, newlines_only=True))
    except OSError as exc:
        raise ParseError(f"cannot read file: {exc.strerror or exc}", path) from None
