"""Read and write motions as NumPy ``.npz`` archives and plain CSV tables.

NPZ layout (every entry a plain array, so ``np.load(path, allow_pickle=False)`` works):

==========================  ===============  =============================================
key                         shape / dtype    meaning
==========================  ===============  =============================================
``format``                  () str           ``"cyclecoord-motion"``
``version``                 () int           layout version, currently 1
``frames``                  (T, D) float     channel values
``channel_joints``          (D,) str         joint of each column
``channel_dofs``            (D,) str         dof of each column
``fps``                     () float         frames per second
``start_frame``             () int           index of frame 0 in the original capture
``source``                  (0,) or (1,) str the source string, empty array for ``None``
``metadata_json``           () str           JSON of the JSON-serialisable metadata
``has_skeleton``            () bool          whether the ``skeleton_*``/``joint_*`` follow
``skeleton_name``           () str           :attr:`Skeleton.name`
``skeleton_length_unit``    () float         :attr:`Skeleton.length_unit`
``skeleton_source_format``  () str           :attr:`Skeleton.source_format`
``joint_names``             (J,) str         joint names
``joint_parents``           (J,) int         parent indices (``-1`` for the root)
``joint_offsets``           (J, 3) float     offsets
``joint_dofs``              (J,) str         dofs joined by spaces (``"tx ty tz rz rx ry"``)
``joint_rotation_orders``   (J,) str         e.g. ``"ZXY"``, ``""`` for none
``joint_axes``              (J, 3, 3) float  rest-frame rotations
``joint_end_sites``         (J, 3) float     end sites, NaN rows where there is none
``joint_has_end_site``      (J,) bool        which joints have an end site
``limit_joints``            (L,) int         joint index of each limit
``limit_dofs``              (L,) str         dof of each limit
``limit_ranges``            (L, 2) float     ``(low, high)`` of each limit
==========================  ===============  =============================================

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


def _json_metadata(metadata: dict) -> str:
    """JSON of the metadata entries that can be serialised (others are dropped)."""
    kept = {}
    for key, value in metadata.items():
        try:
            json.dumps(value, allow_nan=True)
        except (TypeError, ValueError):
            continue
        kept[str(key)] = value
    return json.dumps(kept, allow_nan=True)


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
    if not np.isfinite(value) or value <= 0:
        raise ParameterError(f"fps must be a positive number, got {fps!r}")
    return value


# ----------------------------------------------------------------------------- NPZ
def write_npz(motion: Motion, path: str | os.PathLike[str]) -> None:
    """Save a motion (and its skeleton) as a compressed ``.npz`` archive.

    Parameters
    ----------
    motion : Motion
        Any motion; frames are stored bitwise (float64).  Metadata entries that are not
        JSON-serialisable are dropped.
    path : path-like
        Output file, written atomically (no ``.npz`` suffix is appended).
    """
    arrays: dict[str, np.ndarray] = {
        "format": np.array(_NPZ_FORMAT),
        "version": np.array(_NPZ_VERSION, dtype=np.int64),
        "frames": np.asarray(motion.frames, dtype=np.float64),
        "channel_joints": _str_array(j for j, _ in motion.channels),
        "channel_dofs": _str_array(d for _, d in motion.channels),
        "fps": np.array(motion.fps, dtype=np.float64),
        "start_frame": np.array(motion.start_frame, dtype=np.int64),
        "source": _str_array([] if motion.source is None else [motion.source]),
        "metadata_json": np.array(_json_metadata(motion.metadata)),
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


def _npz_skeleton(data: dict[str, np.ndarray], spath: str) -> Skeleton:
    def bad(msg: str) -> ParseError:
        return ParseError(f"malformed skeleton arrays: {msg}", spath)

    names = [str(n) for n in data["joint_names"].reshape(-1)]
    J = len(names)
    parents = data["joint_parents"].reshape(-1)
    offsets = data["joint_offsets"]
    dofs = data["joint_dofs"].reshape(-1)
    orders = data["joint_rotation_orders"].reshape(-1)
    axes = data["joint_axes"]
    ends = data["joint_end_sites"]
    has_end = data["joint_has_end_site"].reshape(-1)
    expected = {
        "joint_parents": (parents.shape, (J,)),
        "joint_offsets": (offsets.shape, (J, 3)),
        "joint_dofs": (dofs.shape, (J,)),
        "joint_rotation_orders": (orders.shape, (J,)),
        "joint_axes": (axes.shape, (J, 3, 3)),
        "joint_end_sites": (ends.shape, (J, 3)),
        "joint_has_end_site": (has_end.shape, (J,)),
    }
    for key, (got, want) in expected.items():
        if tuple(got) != want:
            raise bad(f"{key} has shape {tuple(got)}, expected {want} for {J} joints")
    lj = data["limit_joints"].reshape(-1)
    ld = data["limit_dofs"].reshape(-1)
    lr = data["limit_ranges"]
    if not (lj.shape[0] == ld.shape[0] and lr.shape == (lj.shape[0], 2)):
        raise bad("limit_joints, limit_dofs and limit_ranges do not have matching lengths")
    limits: list[dict] = [{} for _ in range(J)]
    for ji, dof, rng in zip(lj, ld, lr):
        if not 0 <= int(ji) < J:
            raise bad(f"limit for joint index {int(ji)} out of range")
        limits[int(ji)][str(dof)] = (float(rng[0]), float(rng[1]))
    try:
        joints = tuple(
            Joint(
                name=names[i],
                parent=int(parents[i]),
                offset=offsets[i].astype(float),
                dofs=tuple(str(dofs[i]).split()),
                rotation_order=str(orders[i]),
                axis=axes[i].astype(float),
                end_site=ends[i].astype(float) if bool(has_end[i]) else None,
                limits=limits[i],
            )
            for i in range(J)
        )
        return Skeleton(
            joints=joints,
            name=str(data["skeleton_name"]),
            length_unit=float(data["skeleton_length_unit"]),
            source_format=str(data["skeleton_source_format"]),
        )
    except (ParameterError, ValueError, TypeError) as exc:
        raise bad(str(exc)) from None


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
        If the file is missing, not an NPZ archive, lacks a key, or holds inconsistent
        arrays.
    """
    p = Path(path)
    spath = str(p)
    if not p.is_file():
        raise ParseError("no such file" if not p.exists() else "not a file", spath)
    try:
        loaded = np.load(p, allow_pickle=False)
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
    try:
        with loaded as npz:
            data = {k: npz[k] for k in npz.files}
    except ValueError as exc:
        raise ParseError(f"cannot load arrays without pickling ({exc})", spath) from None
    except Exception as exc:  # corrupt members: zlib, zip or format errors
        raise ParseError(f"corrupt .npz archive ({type(exc).__name__}: {exc})", spath) from None
    missing = [k for k in _MOTION_KEYS if k not in data]
    if missing:
        raise ParseError(
            f"missing array {missing[0]!r} (an .npz motion needs {', '.join(_MOTION_KEYS)})",
            spath,
        )
    frames = data["frames"]
    if frames.ndim != 2 or not np.issubdtype(frames.dtype, np.number):
        raise ParseError(
            f"'frames' must be a 2-D numeric array, got shape {frames.shape} dtype {frames.dtype}",
            spath,
        )
    cj = data["channel_joints"].reshape(-1)
    cd = data["channel_dofs"].reshape(-1)
    if cj.shape[0] != frames.shape[1] or cd.shape[0] != frames.shape[1]:
        raise ParseError(
            f"{cj.shape[0]} channel joints and {cd.shape[0]} channel dofs for "
            f"{frames.shape[1]} columns of 'frames'",
            spath,
        )
    try:
        stored_fps = float(data["fps"])
        start = int(data["start_frame"])
    except (TypeError, ValueError):
        raise ParseError("'fps' and 'start_frame' must be single numbers", spath) from None
    source = None
    if "source" in data and data["source"].size:
        source = str(data["source"].reshape(-1)[0])
    metadata: dict = {}
    if "metadata_json" in data:
        try:
            metadata = json.loads(str(data["metadata_json"]))
        except ValueError:
            raise ParseError("'metadata_json' is not valid JSON", spath) from None
        if not isinstance(metadata, dict):
            raise ParseError("'metadata_json' must hold a JSON object", spath)
    skel = None
    if "has_skeleton" in data and bool(data["has_skeleton"]):
        missing = [k for k in _SKELETON_KEYS if k not in data]
        if missing:
            raise ParseError(
                f"'has_skeleton' is set but array {missing[0]!r} is missing", spath
            )
        skel = _npz_skeleton(data, spath)
    if skeleton is not None:
        skel = _resolve_skeleton(skeleton)
    rate = _check_fps(fps) if fps is not None else stored_fps
    try:
        return Motion(
            frames=frames,
            channels=tuple(zip((str(j) for j in cj), (str(d) for d in cd))),
            fps=rate,
            skeleton=skel,
            source=source,
            start_frame=start,
            metadata=metadata,
        )
    except ParameterError as exc:
        raise ParseError(str(exc), spath) from None


# ----------------------------------------------------------------------------- CSV
def write_csv(motion: Motion, path: str | os.PathLike[str]) -> None:
    """Save the frames as CSV: ``# fps=...`` comment, ``joint.dof`` header, one row per frame.

    Values are written with :func:`repr`, so they read back exactly.  The skeleton is
    not stored (save it as ASF/BVH, or use :func:`write_npz`).

    Parameters
    ----------
    motion : Motion
        Any motion.
    path : path-like
        Output file, written atomically.
    """
    comment = f"# fps={motion.fps!r}"
    if motion.start_frame:
        comment += f" start_frame={motion.start_frame}"
    header = [f"{j}.{d}" if d else j for j, d in motion.channels]
    with atomic_write(path, "w", newline="") as fh:
        fh.write(comment + "\n")
        writer = csv.writer(fh, lineterminator="\n")
        writer.writerow(header)
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
            if not np.isfinite(fps) or fps <= 0:
                raise ParseError(f"fps must be a positive number, found {value!r}", spath, line)
            found["fps"] = fps
        elif key == "start_frame":
            try:
                found["start_frame"] = int(value)
            except ValueError:
                raise ParseError(
                    f"expected a whole number after 'start_frame=', found {value!r}", spath, line
                ) from None
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
    try:
        text = p.read_bytes().decode("utf-8", errors="replace")
    except FileNotFoundError:
        raise ParseError("no such file", spath) from None
    except IsADirectoryError:
        raise ParseError("is a directory, expected a CSV file", spath) from None
    except OSError as exc:
        raise ParseError(f"cannot read file: {exc.strerror or exc}", spath) from None
    if text.startswith("\ufeff"):
        text = text[1:]
    lines = text.splitlines()
    info: dict[str, float] = {}
    header: list[str] | None = None
    header_line = 0
    rows: list[tuple[int, list[str]]] = []
    for i, line in enumerate(lines, start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):  # comments: key=value pairs count before the header
            if header is None:
                info.update(_parse_comment(stripped, spath, i))
            continue
        if header is None:
            try:
                header = next(csv.reader(io.StringIO(line)))
            except csv.Error as exc:
                raise ParseError(f"cannot read header row: {exc}", spath, i) from None
            header = [h.strip() for h in header]
            header_line = i
            if any(not h for h in header):
                raise ParseError(
                    f"empty channel name in column {header.index('') + 1} of the header row",
                    spath,
                    i,
                )
            continue
        rows.append((i, stripped.split(",")))
    if header is None:
        raise ParseError(
            "no header row; expected channel names such as 'root.tx,root.ty,...'", spath,
            len(lines) or None,
        )
    D = len(header)
    for lno, vals in rows:
        if len(vals) != D:
            raise ParseError(
                f"row has {len(vals)} values, the header (line {header_line}) names {D} columns",
                spath,
                lno,
            )
    try:
        numbers = [float(v) for _, vals in rows for v in vals]
    except ValueError:
        for lno, vals in rows:
            for c, v in enumerate(vals):
                try:
                    float(v)
                except ValueError:
                    raise ParseError(
                        f"column {c + 1} ({header[c]}) is {v.strip()!r}, expected a number",
                        spath,
                        lno,
                    ) from None
        raise ParseError("values are not all numbers", spath)  # pragma: no cover
    frames = np.asarray(numbers, dtype=float).reshape(len(rows), D)
    bad = ~np.isfinite(frames)
    if bad.any():
        r, c = (int(v) for v in np.argwhere(bad)[0])
        raise ParseError(
            f"column {c + 1} ({header[c]}) is {rows[r][1][c].strip()!r}, expected a finite number",
            spath,
            rows[r][0],
        )
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
