"""Read and write motions as NumPy ``.npz`` archives and plain CSV tables.

NPZ layout (every entry a plain array, so ``np.load(path, allow_pickle=False)`` works):

==========================  =================  =============================================
key                         shape / dtype      meaning
==========================  =================  =============================================
``format``                  () str             ``"cyclecoord-motion"``
``version``                 () int             layout version, currently 1
``frames``                  (T, D) float       channel values
``channel_joints``          (D,) str           joint of each column
``channel_dofs``            (D,) str           dof of each column
``fps``                     () float           frames per second
``start_frame``             () int             index of frame 0 in the original capture
``source``                  (0,) or (1,) str   the source string, empty array for ``None``
``metadata_json``           () str             JSON of the JSON-serialisable metadata
``has_skeleton``            () bool            whether the ``skeleton_*``/``joint_*`` follow
``skeleton_name``           () str             :attr:`Skeleton.name`
``skeleton_length_unit``    () float           :attr:`Skeleton.length_unit`
``skeleton_source_format``  () str             :attr:`Skeleton.source_format`
``joint_names``             (J,) str           joint names
``joint_parents``           (J,) int           parent indices (``-1`` for the root)
``joint_offsets``           (J, 3) float       offsets
``joint_dofs``              (J,) str           dofs joined by spaces (``"tx ty tz rz rx ry"``)
``joint_rotation_orders``   (J,) str           e.g. ``"ZXY"``, ``""`` for none
``joint_axes``              (J, 3, 3) float    rest-frame rotations
``joint_end_sites``         (J, 3) float       end sites, NaN rows where there is none
``joint_has_end_site``      (J,) bool          which joints have an end site
``limit_joints``            (L,) int           joint index of each limit
``limit_dofs``              (L,) str           dof of each limit
``limit_ranges``            (L, 2) float       ``(low, high)`` of each limit
==========================  =================  =============================================

CSV layout: an optional leading comment line ``# fps=120`` (also ``start_frame=N``), a
header row naming the channels ``joint.dof``, then one row of values per frame.  Lines
starting with ``#`` are comments anywhere; blank lines are skipped.
"""

from __future__ import annotations

import csv
import io
import json
import os
from pathlib import Path

import numpy as np

from ..errors import ParameterError, ParseError
from ..motion import DEFAULT_FPS, Motion
from ..skeleton import Joint, Skeleton
from ._atomic import atomic_write
from ._checked import NpzArrays as _Arrays  # (also the latent model reader's)
from ._stream import CHUNK_FRAMES, FirstBad, FrameArray, count_lines, text_lines
from ._limits import (
    MAX_FRAME_NUMBER,
    MAX_FRAMES,
    MAX_JOINTS,
    MAX_MAGNITUDE,
    MAX_NPZ_BYTES,
    check_memory,
    check_writable,
    fps_problem,
    frames_problem,
    metadata_json,
    metadata_problem,
    parse_int,
    skeleton_problem,
)

__all__ = ["read_npz", "write_npz", "read_csv", "write_csv"]

_NPZ_FORMAT = "cyclecoord-motion"
_NPZ_VERSION = 1
_MOTION_KEYS = ("frames", "channel_joints", "channel_dofs", "fps", "start_frame")
_SKELETON_KEYS = (
    "skeleton_name",
    "skeleton_length_unit",
    "skeleton_source_format",
    "joint_names",
    "joint_parents",
    "joint_offsets",
    "joint_dofs",
    "joint_rotation_orders",
    "joint_axes",
    "joint_end_sites",
    "joint_has_end_site",
    "limit_joints",
    "limit_dofs",
    "limit_ranges",
)


def _str_array(values) -> np.ndarray:
    values = [str(v) for v in values]
    return np.array(values, dtype=str) if values else np.zeros(0, dtype="<U1")


def _resolve_skeleton(skeleton) -> Skeleton | None:
    """A Skeleton from a Skeleton, an ``.asf``/``.bvh`` path, or ``None``."""
    if skeleton is None or isinstance(skeleton, Skeleton):
        return skeleton
    if isinstance(skeleton, (str, os.PathLike)):
        p = Path(skeleton)
        suffix = p.suffix.lower()
        if suffix == ".asf":
            from .asfamc import read_asf

            return read_asf(p)
        if suffix == ".bvh":
            from .bvh import read_bvh

            return read_bvh(p).skeleton
        raise ParameterError(f"skeleton file {p} must be an .asf or .bvh file")
    raise ParameterError(
        f"skeleton must be a Skeleton or a path to an .asf/.bvh file, got {type(skeleton).__name__}"
    )


def _check_fps(fps) -> float:
    try:
        value = float(fps)
    except (TypeError, ValueError):
        raise ParameterError(f"fps must be a positive number, got {fps!r}") from None
    problem = fps_problem(value)
    if problem is not None:
        raise ParameterError(problem)
    return value


# ----------------------------------------------------------------------------- NPZ
def write_npz(motion: Motion, path: str | os.PathLike[str]) -> None:
    """Save a motion (and its skeleton) as a compressed ``.npz`` archive.

    Parameters
    ----------
    motion : Motion
        Any motion :func:`read_npz` would accept; frames are stored bitwise (float64).
        Metadata entries that are not JSON-serialisable are dropped.
    path : path-like
        Output file, written atomically (no ``.npz`` suffix is appended).

    Raises
    ------
    ParameterError
        For a motion the reader would refuse (no frames, non-finite or huge values,
        metadata too large or too deeply nested, ...), naming the output.
    """
    check_writable(motion, path, "NPZ")
    try:
        meta = metadata_json(motion.metadata)
    except ParameterError as exc:
        raise ParameterError(f"{path}: cannot write NPZ: {exc}") from None
    arrays: dict[str, np.ndarray] = {
        "format": np.array(_NPZ_FORMAT),
        "version": np.array(_NPZ_VERSION, dtype=np.int64),
        "frames": np.asarray(motion.frames, dtype=np.float64),
        "channel_joints": _str_array(j for j, _ in motion.channels),
        "channel_dofs": _str_array(d for _, d in motion.channels),
        "fps": np.array(motion.fps, dtype=np.float64),
        "start_frame": np.array(motion.start_frame, dtype=np.int64),
        "source": _str_array([] if motion.source is None else [motion.source]),
        "metadata_json": np.array(meta),
        "has_skeleton": np.array(motion.skeleton is not None),
    }
    skel = motion.skeleton
    if skel is not None:
        joints = skel.joints
        limit_joints, limit_dofs, limit_ranges = [], [], []
        for i, j in enumerate(joints):
            for dof, rng in j.limits.items():
                limit_joints.append(i)
                limit_dofs.append(dof)
                limit_ranges.append([float(rng[0]), float(rng[1])])
        end_sites = np.full((len(joints), 3), np.nan)
        for i, j in enumerate(joints):
            if j.end_site is not None:
                end_sites[i] = j.end_site
        arrays.update(
            {
                "skeleton_name": np.array(str(skel.name)),
                "skeleton_length_unit": np.array(skel.length_unit, dtype=np.float64),
                "skeleton_source_format": np.array(str(skel.source_format)),
                "joint_names": _str_array(j.name for j in joints),
                "joint_parents": np.array([j.parent for j in joints], dtype=np.int64),
                "joint_offsets": np.array([j.offset for j in joints], dtype=np.float64),
                "joint_dofs": _str_array(" ".join(j.dofs) for j in joints),
                "joint_rotation_orders": _str_array(j.rotation_order for j in joints),
                "joint_axes": np.array([j.axis for j in joints], dtype=np.float64),
                "joint_end_sites": end_sites,
                "joint_has_end_site": np.array([j.end_site is not None for j in joints]),
                "limit_joints": np.array(limit_joints, dtype=np.int64),
                "limit_dofs": _str_array(limit_dofs),
                "limit_ranges": np.array(limit_ranges, dtype=np.float64).reshape(-1, 2),
            }
        )
    with atomic_write(path, "wb") as fh:
        np.savez_compressed(fh, **arrays)


def _npz_skeleton(arr: _Arrays) -> Skeleton:
    missing = [k for k in _SKELETON_KEYS if k not in arr.data]
    if missing:
        raise ParseError(f"'has_skeleton' is set but array {missing[0]!r} is missing", arr.spath)
    names = arr.strings("joint_names")
    J = len(names)
    if J == 0:
        raise arr.error("joint_names", "a skeleton needs at least one joint")
    if J > MAX_JOINTS:
        raise arr.error("joint_names", f"{J:,} joints; at most {MAX_JOINTS:,} are supported")
    parents = arr.integers("joint_parents", J, -1, J - 1)
    offsets = arr.reals("joint_offsets", (J, 3))
    per = f", one for each of the {J} joints"
    dofs = arr.strings("joint_dofs", J, per)
    orders = arr.strings("joint_rotation_orders", J, per)
    axes = arr.reals("joint_axes", (J, 3, 3))
    has_end = arr.get("joint_has_end_site")
    if has_end.dtype.kind != "b" or has_end.shape != (J,):
        raise arr.error("joint_has_end_site", f"expected {J} booleans, got {has_end.dtype} "
                        f"{has_end.shape}")
    ends = arr.reals("joint_end_sites", (J, 3), allow_nan=True)
    for i in np.flatnonzero(has_end):
        if np.isnan(ends[i]).any():
            raise arr.error("joint_end_sites", f"joint {names[i]!r} has an end site of NaN")
    lj = arr.get("limit_joints")
    L = lj.shape[0] if lj.ndim == 1 else -1
    if L < 0:
        raise arr.error("limit_joints", f"expected a 1-D array, got shape {lj.shape}")
    limit_joints = arr.integers("limit_joints", L, 0, J - 1)
    limit_dofs = arr.strings("limit_dofs", L)
    ranges = arr.reals("limit_ranges", (L, 2), allow_inf=True)
    limits: list[dict] = [{} for _ in range(J)]
    for ji, dof, rng in zip(limit_joints, limit_dofs, ranges):
        limits[ji][dof] = (float(rng[0]), float(rng[1]))
    joints = []
    for i in range(J):
        try:
            joints.append(Joint(
                name=names[i], parent=parents[i], offset=offsets[i], dofs=tuple(dofs[i].split()),
                rotation_order=orders[i], axis=axes[i],
                end_site=ends[i] if bool(has_end[i]) else None, limits=limits[i],
            ))
        except ParameterError as exc:
            raise ParseError(f"malformed skeleton arrays: joint {i}: {exc}", arr.spath) from None
    try:
        skel = Skeleton(
            joints=tuple(joints),
            name=arr.text("skeleton_name"),
            length_unit=arr.real("skeleton_length_unit"),
            source_format=arr.text("skeleton_source_format"),
        )
    except ParameterError as exc:
        raise ParseError(f"malformed skeleton arrays: {exc}", arr.spath) from None
    problem = skeleton_problem(skel)
    if problem is not None:
        raise ParseError(f"malformed skeleton arrays: {problem}", arr.spath)
    return skel


def _open_npz(p: Path, spath: str) -> dict[str, np.ndarray]:
    """Every array of the archive, read without pickling and within the size cap."""
    try:
        fh = open(p, "rb")
    except OSError as exc:
        raise ParseError(f"cannot read file: {exc.strerror or exc}", spath) from None
    with fh:  # numpy leaves the file open when the archive is broken: close it here
        try:
            loaded = np.load(fh, allow_pickle=False)
        except ValueError as exc:  # not zip/npy: numpy would need pickle to go further
            raise ParseError(f"not an .npz archive ({exc})", spath) from None
        except Exception as exc:  # BadZipFile, EOFError, OSError, unsupported zip features...
            raise ParseError(
                f"not a readable .npz archive ({type(exc).__name__}: {exc})", spath
            ) from None
        if not isinstance(loaded, np.lib.npyio.NpzFile):
            raise ParseError(
                "holds a single .npy array, expected an .npz archive written by write_npz", spath
            )
        with loaded as npz:
            size = sum(info.file_size for info in npz.zip.infolist())
            if size > MAX_NPZ_BYTES:
                raise ParseError(
                    f"the archive unpacks to {size:,} bytes; at most {MAX_NPZ_BYTES:,} are "
                    "supported",
                    spath,
                )
            check_memory(size, f"the archive's arrays ({size:,} bytes unpacked)", spath)
            data = {}
            for k in npz.files:
                try:
                    data[k] = npz[k]
                except ValueError as exc:
                    raise ParseError(
                        f"array {k!r}: cannot load without pickling ({exc})", spath
                    ) from None
                except Exception as exc:  # corrupt members: zlib, zip or format errors
                    raise ParseError(
                        f"array {k!r}: corrupt ({type(exc).__name__}: {exc})", spath
                    ) from None
    return data


def _npz_metadata(arr: _Arrays) -> dict:
    if "metadata_json" not in arr.data:
        return {}
    text = arr.text("metadata_json")
    problem = metadata_problem(text)
    if problem is not None:
        raise arr.error("metadata_json", problem)
    try:
        metadata = json.loads(text)
    except (ValueError, RecursionError):
        raise arr.error("metadata_json", "not valid JSON") from None
    if not isinstance(metadata, dict):
        kind = type(metadata).__name__
        raise arr.error("metadata_json", f"must hold a JSON object, holds a {kind}")
    return metadata


def read_npz(
    path: str | os.PathLike[str],
    skeleton: Skeleton | str | os.PathLike[str] | None = None,
    fps: float | None = None,
) -> Motion:
    """Load a motion saved by :func:`write_npz`.

    Parameters
    ----------
    path : path-like
        The ``.npz`` archive (read with ``allow_pickle=False``).
    skeleton : Skeleton or path, optional
        Replaces the stored skeleton (an ``.asf`` or ``.bvh`` path is read).
    fps : float, optional
        Overrides the stored rate.

    Returns
    -------
    Motion
        Frames ``(T, D)`` bitwise as saved, with channels, rate, start frame, source,
        metadata and skeleton.

    Raises
    ------
    ParseError
        Naming the file and the key: a missing file, not an NPZ archive, a missing key,
        an array of the wrong kind or shape, non-finite or huge values (frames counted
        from 1), metadata too large or too deeply nested, or an inconsistent skeleton.
    """
    p = Path(path)
    spath = str(p)
    if not p.is_file():
        raise ParseError("no such file" if not p.exists() else "not a file", spath)
    return npz_motion(_Arrays(_open_npz(p, spath), spath), skeleton, fps)


def npz_motion(arr: _Arrays, skeleton=None, fps: float | None = None) -> Motion:
    """The motion the arrays of ``arr`` describe (:func:`read_npz`'s layout), checked."""
    data, spath = arr.data, arr.spath
    missing = [k for k in _MOTION_KEYS if k not in data]
    if missing:
        raise ParseError(
            f"missing array {arr.prefix + missing[0]!r} (an .npz motion needs "
            f"{', '.join(arr.prefix + k for k in _MOTION_KEYS)})",
            spath,
        )
    if "format" in data and arr.text("format") != _NPZ_FORMAT:
        raise arr.error("format", f"expected {_NPZ_FORMAT!r}, got {arr.text('format')[:40]!r}")
    if "version" in data:
        version = arr.integer("version", -(2**62), 2**62)
        if version != _NPZ_VERSION:
            raise arr.error(
                "version", f"layout version {version}; this cyclecoord reads version {_NPZ_VERSION}"
            )
    frames = data["frames"]
    if frames.ndim != 2 or frames.dtype.kind not in "iuf":
        raise arr.error("frames", f"expected a 2-D array of real numbers, got {frames.dtype} "
                        f"{frames.shape}")
    per = f", one for each of the {frames.shape[1]} columns of 'frames'"
    channels = tuple(zip(arr.strings("channel_joints", frames.shape[1], per),
                         arr.strings("channel_dofs", frames.shape[1], per)))
    problem = frames_problem(frames, channels)
    if problem is not None:
        raise arr.error("frames", problem)
    stored_fps = arr.real("fps")
    problem = fps_problem(stored_fps)
    if problem is not None:
        raise arr.error("fps", problem)
    start = arr.integer("start_frame", 0, MAX_FRAME_NUMBER)
    source = None
    if "source" in data:
        src = arr.strings("source")
        if len(src) > 1:
            raise arr.error("source", f"expected at most one string, got {len(src)}")
        source = src[0] if src else None
    metadata = _npz_metadata(arr)
    skel = None
    if "has_skeleton" in data and arr.flag("has_skeleton"):
        skel = _npz_skeleton(arr)
    if skeleton is not None:
        skel = _resolve_skeleton(skeleton)
    rate = _check_fps(fps) if fps is not None else stored_fps
    try:
        return Motion(
            frames=frames,
            channels=channels,
            fps=rate,
            skeleton=skel,
            source=source,
            start_frame=start,
            metadata=metadata,
        )
    except ParameterError as exc:
        keys = ("frames", "channel_joints", "channel_dofs")
        names = ", ".join(repr(arr.prefix + k) for k in keys)
        raise ParseError(f"{exc} (arrays {names})", spath) from None


# ----------------------------------------------------------------------------- CSV
def write_csv(motion: Motion, path: str | os.PathLike[str]) -> None:
    """Save the frames as CSV: ``# fps=...`` comment, ``joint.dof`` header, one row per frame.

    Values are written with :func:`repr`, so they read back exactly.  The skeleton is
    not stored (save it as ASF/BVH, or use :func:`write_npz`), nor checked.
    The header names split at the last dot, so joint names may hold dots.

    Parameters
    ----------
    motion : Motion
        Any motion :func:`read_csv` would accept.
    path : path-like
        Output file, written atomically.

    Raises
    ------
    ParameterError
        For a motion the reader would refuse, or channel names that would not read back
        as the same channels (commas, line breaks, a leading ``#``, surrounding spaces),
        naming the output and the channel.
    """
    check_writable(motion, path, "CSV", skeleton=False)
    names = [f"{j}.{d}" if d else j for j, d in motion.channels]
    buf = io.StringIO()
    csv.writer(buf, lineterminator="\n").writerow(names)
    header = buf.getvalue()
    back = next(csv.reader(io.StringIO(header))) if header.count("\n") == 1 else []
    back = [h.strip() for h in back]
    if len(back) != len(names) or header.lstrip().startswith("#"):
        raise ParameterError(
            f"{path}: cannot write CSV: the channel names {names[:3]}... would not read back "
            "as one header row (line breaks, or a leading '#'); write .npz instead"
        )
    for name, ch, got in zip(names, motion.channels, back):
        if got != name:
            raise ParameterError(
                f"{path}: cannot write CSV: channel {ch} would read back as {got!r} "
                "(surrounding spaces or an empty name); write .npz instead"
            )
    comment = f"# fps={motion.fps!r}"
    if motion.start_frame:
        comment += f" start_frame={motion.start_frame}"
    with atomic_write(path, "w", newline="") as fh:
        fh.write(comment + "\n")
        fh.write(header)
        for row in motion.frames.tolist():
            fh.write(",".join(map(repr, row)))
            fh.write("\n")


def _parse_comment(text: str, spath: str, line: int) -> dict[str, float]:
    """``# fps=120 start_frame=3`` -> ``{"fps": 120.0, "start_frame": 3}``."""
    found: dict[str, float] = {}
    for item in text.lstrip("#").replace(",", " ").split():
        if "=" not in item:
            continue
        key, _, value = item.partition("=")
        key = key.strip().lower()
        if key == "fps":
            try:
                fps = float(value)
            except ValueError:
                raise ParseError(
                    f"expected a number after 'fps=', found {value!r}", spath, line
                ) from None
            problem = fps_problem(fps)
            if problem is not None:
                raise ParseError(problem, spath, line)
            found["fps"] = fps
        elif key == "start_frame":
            try:
                found["start_frame"] = parse_int(value, "start_frame", 0, MAX_FRAME_NUMBER)
            except ValueError as exc:
                raise ParseError(str(exc), spath, line) from None
    return found


def read_csv(
    path: str | os.PathLike[str],
    fps: float | None = None,
    skeleton: Skeleton | str | os.PathLike[str] | None = None,
) -> Motion:
    """Read a CSV motion table.

    Parameters
    ----------
    path : path-like
        Leading ``#`` comment lines (``# fps=120``) are optional; then a header row of
        channel names ``joint.dof`` (a name without a dot becomes ``(name, "")``), then
        one row of numbers per frame.  Blank lines are skipped.
    fps : float, optional
        Frame rate; overrides the file's ``# fps=`` comment.  Without either, 120.
    skeleton : Skeleton or path, optional
        Attached to the motion (an ``.asf`` or ``.bvh`` path is read).

    Returns
    -------
    Motion
        Frames ``(T, D)``.

    Raises
    ------
    ParseError
        Naming the line for a missing header, a row with the wrong number of columns,
        a value that is not a finite number, or duplicate channel names.
    """
    p = Path(path)
    spath = str(p)
    if p.is_dir():
        raise ParseError("is a directory, expected a CSV file", spath)
    try:
        lines = enumerate(text_lines(p), start=1)
        info, header, header_line = _csv_header(lines, spath)
        frames = _csv_frames(header, header_line, lines, spath, p)
    except FileNotFoundError:
        raise ParseError("no such file", spath) from None
    except OSError as exc:
        raise ParseError(f"cannot read file: {exc.strerror or exc}", spath) from None
    channels = _csv_channels(header, header_line, spath)
    if fps is not None:
        rate = _check_fps(fps)
    else:
        rate = float(info.get("fps", DEFAULT_FPS))
    skel = _resolve_skeleton(skeleton)
    try:
        return Motion(
            frames=frames,
            channels=tuple(channels),
            fps=rate,
            skeleton=skel,
            source=spath,
            start_frame=int(info.get("start_frame", 0)),
        )
    except ParameterError as exc:
        raise ParseError(str(exc), spath) from None


def _csv_header(lines, spath: str) -> tuple[dict[str, float], list[str], int]:
    """The ``key=value`` comments before the header and the header row (and its line), read
    from ``(line number, line)`` pairs up to the header."""
    info: dict[str, float] = {}
    n_lines = 0
    for i, line in lines:
        n_lines = i
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):  # comments: key=value pairs count before the header
            info.update(_parse_comment(stripped, spath, i))
            continue
        try:
            header = next(csv.reader(io.StringIO(line)))
        except csv.Error as exc:
            raise ParseError(f"cannot read header row: {exc}", spath, i) from None
        header = [h.strip() for h in header]
        if any(not h for h in header):
            raise ParseError(
                f"empty channel name in column {header.index('') + 1} of the header row",
                spath,
                i,
            )
        return info, header, i
    raise ParseError(
        "no header row; expected channel names such as 'root.tx,root.ty,...'", spath,
        n_lines or None,
    )


#: A line that is neither blank nor a comment (a row of values, or the header).
_DATA_LINE = rb"^[ \t\r\f\v]*[^#\s]"


def _csv_frames(header: list[str], header_line: int, lines, spath: str, path: Path
                ) -> np.ndarray:
    """Frames ``(T, D)`` of the value rows after the header, their shape and every value
    checked, a chunk of rows at a time into an array allocated once (for the rows a first
    count of the file's lines found).

    Problems are reported as a whole-file read would: too many columns or rows first,
    then the first row with a wrong number of values, the first value that is no number,
    the first beyond the magnitude cap.
    """
    D = len(header)
    if D > 6 * MAX_JOINTS:
        raise ParseError(
            f"{D:,} columns; at most {6 * MAX_JOINTS:,} channels are supported", spath, header_line
        )
    expected = max(count_lines(path, _DATA_LINE) - 1, 1)
    out = FrameArray(min(expected, MAX_FRAMES), D, spath, path.stat().st_size)
    n_rows = 0
    last_line = header_line
    wrong_count: ParseError | None = None
    bad = FirstBad()
    chunk: list[tuple[int, list[str]]] = []

    def convert() -> None:
        if wrong_count is None and bad.number is None and n_rows <= MAX_FRAMES:
            _convert_rows(chunk, out.rows(len(chunk)), header, spath, bad)
        chunk.clear()

    for lno, line in lines:
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        n_rows += 1
        last_line = lno
        if n_rows > MAX_FRAMES or wrong_count is not None:
            continue
        vals = stripped.split(",")
        if len(vals) != D:
            wrong_count = ParseError(
                f"row has {len(vals)} values, the header (line {header_line}) names {D} columns",
                spath,
                lno,
            )
            continue
        chunk.append((lno, vals))
        if len(chunk) >= CHUNK_FRAMES:
            convert()
    convert()
    if not n_rows:
        raise ParseError(
            f"no frames: the header row (line {header_line}) is followed by no rows of values",
            spath,
            header_line,
        )
    if n_rows > MAX_FRAMES:
        raise ParseError(
            f"{n_rows:,} rows; at most {MAX_FRAMES:,} frames are supported", spath, last_line
        )
    for problem in (wrong_count, bad.number, bad.value):
        if problem is not None:
            raise problem
    return out.result()


def _convert_rows(
    chunk: list[tuple[int, list[str]]], rows: np.ndarray, header: list[str], spath: str,
    bad: FirstBad,
) -> None:
    """One chunk of value rows into ``rows``; its problems into ``bad`` (first ones kept)."""
    try:
        rows.reshape(-1)[:] = np.fromiter(
            (float(v) for _, vals in chunk for v in vals), dtype=float, count=rows.size
        )
    except ValueError:
        for lno, vals in chunk:
            for c, v in enumerate(vals):
                try:
                    float(v)
                except ValueError:
                    bad.number = ParseError(
                        f"column {c + 1} ({header[c]}) is {v.strip()!r}, expected a number",
                        spath,
                        lno,
                    )
                    return
        raise  # pragma: no cover
    if bad.value is not None:
        return
    with np.errstate(invalid="ignore"):
        wrong = ~np.isfinite(rows) | (np.abs(rows) > MAX_MAGNITUDE)
    if wrong.any():
        r, c = (int(v) for v in np.argwhere(wrong)[0])
        bad.value = ParseError(
            f"column {c + 1} ({header[c]}) is {chunk[r][1][c].strip()!r}, expected a finite "
            f"number of at most {MAX_MAGNITUDE:g} in magnitude",
            spath,
            chunk[r][0],
        )


def _csv_channels(header: list[str], header_line: int, spath: str) -> list[tuple[str, str]]:
    """``(joint, dof)`` of each header name (``joint.dof``; no dot: ``(name, "")``), unique."""
    channels = []
    for h in header:
        if "." in h:
            j, d = h.rsplit(".", 1)
            channels.append((j, d))
        else:
            channels.append((h, ""))
    seen: set = set()
    for c, ch in enumerate(channels):
        if ch in seen:
            raise ParseError(
                f"channel {header[c]!r} appears twice in the header row", spath, header_line
            )
        seen.add(ch)
    return channels
