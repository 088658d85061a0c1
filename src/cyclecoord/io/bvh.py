"""Read and write Biovision Hierarchy (BVH) motion files.

A BVH file has a ``HIERARCHY`` section (nested ``ROOT``/``JOINT`` blocks with ``OFFSET``
and ``CHANNELS``, leaves closed by ``End Site`` blocks) and a ``MOTION`` section
(``Frames:``, ``Frame Time:`` and one line of channel values per frame).

Conventions (see :mod:`cyclecoord.skeleton`): a joint's rotation channels compose in the
order they are listed, so ``Zrotation Xrotation Yrotation`` gives the intrinsic order
``"ZXY"``; position channels replace the matching components of the joint's offset; joint
axes are the identity.  Channel names map to dofs as ``Xposition -> tx`` ...
``Zrotation -> rz``.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import ParameterError, ParseError
from ..motion import Motion
from ..skeleton import AXIS_INDEX, Joint, Skeleton, rotation_order_from_dofs
from ..conventions import check_order
from ._atomic import atomic_write
from ._stream import CHUNK_FRAMES, FirstBad, FrameArray, text_lines
from ._limits import (
    MAX_DEPTH,
    MAX_FPS,
    MAX_FRAMES,
    MAX_JOINTS,
    MAX_MAGNITUDE,
    MIN_FPS,
    check_writable,
    parse_int,
)

__all__ = ["read_bvh", "write_bvh", "BVH_CHANNEL_NAMES"]

#: BVH channel name (lower case) -> cyclecoord dof name.
BVH_CHANNEL_NAMES = {
    "xposition": "tx",
    "yposition": "ty",
    "zposition": "tz",
    "xrotation": "rx",
    "yrotation": "ry",
    "zrotation": "rz",
}
_DOF_TO_BVH = {
    "tx": "Xposition",
    "ty": "Yposition",
    "tz": "Zposition",
    "rx": "Xrotation",
    "ry": "Yrotation",
    "rz": "Zrotation",
}
_CHANNEL_LIST = "Xposition Yposition Zposition Xrotation Yrotation Zrotation"
# tokens that end a CHANNELS list (lower case)
_STRUCTURE_WORDS = {"offset", "channels", "joint", "end", "{", "}", "root", "hierarchy"}
_FRAMES_RE = re.compile(r"^frames\s*:\s*(.*)$", re.IGNORECASE)
_FRAME_TIME_RE = re.compile(r"^frame\s+time\s*:\s*(.*)$", re.IGNORECASE)
#: Words of a hierarchy: MAX_JOINTS joints of about 20 words each, with room to spare.
_MAX_HIERARCHY_TOKENS = 64 * MAX_JOINTS


# ----------------------------------------------------------------------------- reading
@dataclass
class _JointBuild:
    """Mutable joint record while the hierarchy is being parsed."""

    name: str
    parent: int
    line: int
    offset: np.ndarray | None = None
    dofs: tuple[str, ...] | None = None
    end_site: np.ndarray | None = None
    children: list[int] = field(default_factory=list)


class _HierarchyParser:
    """Parse the HIERARCHY token stream into joints (iterative: no recursion limit)."""

    def __init__(self, tokens: list[tuple[str, int]], path: str, end_line: int) -> None:
        self.tokens = tokens
        self.path = path
        self.end_line = end_line  # line of MOTION (or last line): where "ran out" errors point
        self.pos = 0
        self.joints: list[_JointBuild] = []
        self.names: dict[str, int] = {}  # name -> line, for the duplicate check

    # -- token helpers
    def error(self, message: str, line: int | None) -> ParseError:
        return ParseError(message, self.path, line)

    def peek(self) -> tuple[str, int] | None:
        return self.tokens[self.pos] if self.pos < len(self.tokens) else None

    def next(self, expected: str) -> tuple[str, int]:
        tok = self.peek()
        if tok is None:
            raise self.error(f"hierarchy ended early: expected {expected}", self.end_line)
        self.pos += 1
        return tok

    def number(self, what: str, line_hint: int) -> float:
        tok, line = self.next(what)
        try:
            value = float(tok)
        except ValueError:
            raise self.error(f"expected {what}, found {tok!r}", line) from None
        if not np.isfinite(value):
            raise self.error(f"expected {what}, found non-finite value {tok!r}", line)
        if abs(value) > MAX_MAGNITUDE:
            raise self.error(
                f"expected {what}, found {tok!r}, beyond the largest supported magnitude "
                f"{MAX_MAGNITUDE:g}",
                line,
            )
        return value

    def vector(self, keyword: str, line: int) -> np.ndarray:
        return np.array(
            [self.number(f"3 numbers after {keyword}", line) for _ in range(3)], dtype=float
        )

    # -- grammar
    def open_joint(self, keyword: str, line: int, parent: int, depth: int = 0) -> int:
        """After ROOT/JOINT: read the name and the opening brace, register the joint."""
        if len(self.joints) >= MAX_JOINTS:
            raise self.error(
                f"more than {MAX_JOINTS:,} joints; at most {MAX_JOINTS:,} are supported", line
            )
        if depth > MAX_DEPTH:
            raise self.error(
                f"the hierarchy is more than {MAX_DEPTH} levels deep; at most {MAX_DEPTH} are "
                "supported",
                line,
            )
        name_parts = []
        while True:
            tok = self.peek()
            if tok is None or tok[1] != line or tok[0] == "{":
                break
            name_parts.append(tok[0])
            self.pos += 1
        if not name_parts:
            raise self.error(f"expected a joint name after {keyword}", line)
        name = " ".join(name_parts)
        if name in self.names:
            raise self.error(
                f"joint name {name!r} is used twice (first at line {self.names[name]})", line
            )
        self.names[name] = line
        tok, tline = self.next(f"'{{' opening joint {name!r}")
        if tok != "{":
            raise self.error(f"expected '{{' after {keyword} {name}, found {tok!r}", tline)
        self.joints.append(_JointBuild(name=name, parent=parent, line=line))
        index = len(self.joints) - 1
        if parent >= 0:
            self.joints[parent].children.append(index)
        return index

    def channels(self, joint: _JointBuild, line: int) -> tuple[str, ...]:
        tok, cline = self.next("the number of channels after CHANNELS")
        try:
            count = parse_int(tok, "the number of channels after CHANNELS", 0, 6)
        except ValueError as exc:
            raise self.error(str(exc), cline) from None
        names: list[tuple[str, int]] = []
        while True:
            nxt = self.peek()
            if nxt is None or nxt[0].lower() in _STRUCTURE_WORDS:
                break
            if nxt[0].lower() not in BVH_CHANNEL_NAMES:
                raise self.error(
                    f"unknown channel name {nxt[0]!r} in joint {joint.name!r}; "
                    f"expected one of {_CHANNEL_LIST}",
                    nxt[1],
                )
            names.append(nxt)
            self.pos += 1
        if len(names) != count:
            listed = " ".join(n for n, _ in names) or "none"
            raise self.error(
                f"CHANNELS declares {count} channels for joint {joint.name!r} but lists "
                f"{len(names)} ({listed})",
                line,
            )
        dofs = tuple(BVH_CHANNEL_NAMES[n.lower()] for n, _ in names)
        for (n, nline), d in zip(names, dofs):
            if dofs.count(d) > 1:
                raise self.error(f"channel {n} listed twice in joint {joint.name!r}", nline)
        return dofs

    def end_site(self, joint: _JointBuild, line: int) -> np.ndarray:
        tok, tline = self.next("'Site' after 'End'")
        if tok.lower() != "site":
            raise self.error(f"expected 'End Site', found 'End {tok}'", tline)
        tok, tline = self.next("'{' opening End Site")
        if tok != "{":
            raise self.error(f"expected '{{' after End Site, found {tok!r}", tline)
        tok, tline = self.next("OFFSET in End Site")
        if tok.lower() != "offset":
            raise self.error(f"expected OFFSET in End Site of {joint.name!r}, found {tok!r}", tline)
        vec = self.vector("OFFSET", tline)
        tok, tline = self.next("'}' closing End Site")
        if tok != "}":
            raise self.error(
                f"expected '}}' closing End Site of {joint.name!r}, found {tok!r}", tline
            )
        if joint.end_site is not None:
            raise self.error(f"joint {joint.name!r} has more than one End Site", line)
        return vec

    def parse(self) -> list[_JointBuild]:
        tok, line = self.next("HIERARCHY")
        if tok.upper() != "HIERARCHY":
            raise self.error(f"expected HIERARCHY at the start of the file, found {tok!r}", line)
        tok, line = self.next("ROOT")
        if tok.upper() != "ROOT":
            raise self.error(f"expected ROOT after HIERARCHY, found {tok!r}", line)
        stack = [self.open_joint("ROOT", line, -1)]
        while stack:
            current = self.joints[stack[-1]]
            nxt = self.peek()
            if nxt is None:
                raise self.error(
                    f"unbalanced braces: joint {current.name!r} opened at line "
                    f"{current.line} is not closed (expected '}}' before MOTION)",
                    self.end_line,
                )
            tok, line = self.next("")
            word = tok.lower()
            if word == "offset":
                if current.offset is not None:
                    raise self.error(f"joint {current.name!r} has a second OFFSET", line)
                current.offset = self.vector("OFFSET", line)
            elif word == "channels":
                if current.dofs is not None:
                    raise self.error(f"joint {current.name!r} has a second CHANNELS line", line)
                current.dofs = self.channels(current, line)
            elif word == "joint":
                stack.append(self.open_joint("JOINT", line, stack[-1], len(stack)))
            elif word == "end":
                current.end_site = self.end_site(current, line)
            elif tok == "}":
                if current.offset is None:
                    raise self.error(
                        f"joint {current.name!r} (line {current.line}) has no OFFSET", line
                    )
                stack.pop()
            elif word == "root":
                raise self.error(
                    "a second ROOT inside a joint block; braces are unbalanced", line
                )
            else:
                raise self.error(
                    f"unexpected {tok!r} in joint {current.name!r}; expected OFFSET, "
                    "CHANNELS, JOINT, End Site or '}'",
                    line,
                )
        rest = self.peek()
        if rest is not None:
            tok, line = rest
            if tok == "}":
                raise self.error("unbalanced braces: '}' after the root joint was closed", line)
            if tok.upper() == "ROOT":
                raise self.error(
                    "a second ROOT: only single-rooted hierarchies are supported", line
                )
            raise self.error(f"unexpected {tok!r} after the root joint; expected MOTION", line)
        return self.joints


def _lines(path: Path):
    """The file's lines (``str.splitlines``), read a block at a time; ParseError when the
    file cannot be read."""
    if path.is_dir():
        raise ParseError("is a directory, expected a BVH file", path)
    if not path.exists():
        raise ParseError("no such file", path)
    try:
        yield from text_lines(path)
    except FileNotFoundError:
        raise ParseError("no such file", path) from None
    except OSError as exc:
        raise ParseError(f"cannot read file: {exc.strerror or exc}", path) from None


def _round_fps(fps: float) -> float:
    """Snap to an integer rate when within 1e-4 relative (0.0083333 s -> 120 fps)."""
    nearest = round(fps)
    if nearest > 0 and abs(fps - nearest) <= 1e-4 * fps:
        return float(nearest)
    return float(fps)


def read_bvh(path: str | os.PathLike[str]) -> Motion:
    """Read a BVH file.

    Parameters
    ----------
    path : path-like
        The ``.bvh`` file.  CRLF line ends, a UTF-8 byte order mark, tabs and extra
        whitespace are accepted.

    Returns
    -------
    Motion
        Frames of shape ``(T, D)`` with ``D`` the total channel count, channels in file
        order as ``(joint, dof)``; ``fps = 1 / Frame Time`` (snapped to an integer rate
        when within 1e-4 relative); a :class:`~cyclecoord.skeleton.Skeleton` with
        ``source_format="bvh"``, identity axes and per-joint rotation orders taken from
        the listed rotation channels.

    Raises
    ------
    ParseError
        Naming file and line for anything malformed: empty file, missing HIERARCHY or
        MOTION, unbalanced braces, unknown channel names, CHANNELS count not matching
        the names, frame lines with the wrong number of values, ``Frames:`` not matching
        the frame lines present (too few or too many), non-numbers, non-finite values,
        ``Frame Time <= 0``.  Frames are counted from 1 in messages.
    """
    path = Path(path)
    spath = str(path)
    lines = enumerate(_lines(path))
    builds, motion_line = _read_hierarchy(lines, spath)
    skeleton = _bvh_skeleton(builds, path.stem, spath)
    channels = skeleton.channels
    body = ((i + 1, ln.strip()) for i, ln in lines if ln.strip())
    head = [line for _, line in zip(range(2), body)]
    n_frames, frame_time, tline = _motion_header(
        head, len(channels), builds[0].line, motion_line, spath
    )
    frames = _frame_values(body, n_frames, channels, tline, spath, path.stat().st_size)
    return Motion(
        frames=frames,
        channels=channels,
        fps=_round_fps(1.0 / frame_time),
        skeleton=skeleton,
        source=spath,
        metadata={"frame_time": frame_time},
    )


def _read_hierarchy(lines, spath: str) -> tuple[list, int]:
    """The joints of the HIERARCHY section and the 0-based index of the MOTION line, from
    ``(index, line)`` pairs (read up to the MOTION line)."""
    tokens: list[tuple[str, int]] = []
    motion_line: int | None = None  # 0-based index of the MOTION line
    n_lines = 0
    for i, raw in lines:
        n_lines = i + 1
        parts = raw.replace("{", " { ").replace("}", " } ").split()
        if not parts:
            continue
        if parts[0].upper() == "MOTION":
            motion_line = i
            break
        if len(tokens) > _MAX_HIERARCHY_TOKENS:
            raise ParseError(
                f"the hierarchy runs past {_MAX_HIERARCHY_TOKENS:,} words without MOTION; "
                f"at most {MAX_JOINTS:,} joints are supported",
                spath,
                i + 1,
            )
        tokens.extend((p, i + 1) for p in parts)
    end_line = motion_line + 1 if motion_line is not None else n_lines
    if not tokens and motion_line is None:
        raise ParseError("file is empty; expected a BVH file starting with HIERARCHY", spath)
    if not tokens:
        raise ParseError(
            "expected HIERARCHY at the start of the file, found MOTION", spath, end_line
        )
    builds = _HierarchyParser(tokens, spath, end_line).parse()
    if motion_line is None:
        raise ParseError(
            "missing MOTION section after the hierarchy (expected a line 'MOTION')",
            spath,
            n_lines,
        )
    return builds, motion_line


def _bvh_skeleton(builds: list, name: str, spath: str) -> Skeleton:
    """The Skeleton of the parsed joints (identity axes, rotation order from the channels)."""
    joints = []
    for b in builds:
        dofs = b.dofs or ()
        try:
            joints.append(
                Joint(
                    name=b.name,
                    parent=b.parent,
                    offset=b.offset,
                    dofs=dofs,
                    rotation_order=rotation_order_from_dofs(dofs, reverse=False),
                    axis=np.eye(3),
                    end_site=b.end_site,
                )
            )
        except ParameterError as exc:  # defensive: the parser checks these already
            raise ParseError(str(exc), spath, b.line) from None
    try:
        return Skeleton(joints=tuple(joints), name=name, source_format="bvh")
    except ParameterError as exc:  # defensive, as above
        raise ParseError(str(exc), spath, builds[0].line) from None


def _motion_header(
    body: list[tuple[int, str]], n_channels: int, root_line: int, motion_line: int, spath: str
) -> tuple[int, float, int]:
    """``Frames:`` and ``Frame Time:`` of the MOTION section: count, seconds and the line."""
    if not body:
        raise ParseError(
            "MOTION section ends early: expected 'Frames: <count>'", spath, motion_line + 1
        )
    fline, ftext = body[0]
    m = _FRAMES_RE.match(ftext)
    if m is None:
        raise ParseError(f"expected 'Frames: <count>', found {ftext[:40]!r}", spath, fline)
    try:
        n_frames = parse_int(m.group(1), "the number of frames after 'Frames:'", 1, MAX_FRAMES)
    except ValueError as exc:
        raise ParseError(str(exc), spath, fline) from None
    if n_channels == 0:
        raise ParseError(
            "the hierarchy declares no channels (every CHANNELS line is 0): nothing moves",
            spath,
            root_line,
        )
    if len(body) < 2:
        raise ParseError(
            "MOTION section ends early: expected 'Frame Time: <seconds>'", spath, fline
        )
    tline, ttext = body[1]
    m = _FRAME_TIME_RE.match(ttext)
    if m is None:
        raise ParseError(f"expected 'Frame Time: <seconds>', found {ttext[:40]!r}", spath, tline)
    try:
        frame_time = float(m.group(1).strip())
    except ValueError:
        raise ParseError(
            f"expected a number after 'Frame Time:', found {m.group(1).strip()!r}", spath, tline
        ) from None
    if not np.isfinite(frame_time) or not 1 / MAX_FPS <= frame_time <= 1 / MIN_FPS:
        raise ParseError(
            f"Frame Time must be a positive number of seconds in {1 / MAX_FPS:g}..{1 / MIN_FPS:g}, "
            f"found {m.group(1).strip()}",
            spath,
            tline,
        )
    return n_frames, frame_time, tline


def _frame_values(
    frame_lines, n_frames: int, channels: tuple, tline: int, spath: str, size: int
) -> np.ndarray:
    """Frames ``(T, D)`` from the ``(line number, text)`` frame lines, their count and every
    value checked, a chunk of lines at a time into an array allocated once.

    Problems are reported as a whole-file read would: a frame count that differs from
    ``Frames:`` first, then the first line with a wrong number of values, the first value
    that is no number, the first beyond the magnitude cap.
    """
    n_channels = len(channels)
    # a frame line holds at least two bytes a value ("0 "): the file bounds the frames
    out = FrameArray(min(n_frames, size // (2 * n_channels) + 1), n_channels, spath, size)
    found = 0
    last_line = tline
    extra_line = None  # the line of frame n_frames + 1
    wrong_count: ParseError | None = None
    bad = FirstBad()
    chunk: list[tuple[int, list[str]]] = []

    def convert() -> None:
        if wrong_count is None and bad.number is None:
            _convert(chunk, out.rows(len(chunk)), channels, spath, bad)
        chunk.clear()

    for lno, txt in frame_lines:
        found += 1
        last_line = lno
        if found > n_frames:
            if extra_line is None:
                extra_line = lno
            continue
        vals = txt.split()
        if len(vals) != n_channels:
            if wrong_count is None:
                wrong_count = ParseError(
                    f"frame {found} has {len(vals)} values, the hierarchy declares "
                    f"{n_channels} channels",
                    spath,
                    lno,
                )
            continue
        chunk.append((lno, vals))
        if len(chunk) >= CHUNK_FRAMES:
            convert()
    convert()
    if found < n_frames:
        raise ParseError(
            f"'Frames: {n_frames}' declared but only {found} frame lines found",
            spath,
            last_line if found else tline,
        )
    if found > n_frames:
        raise ParseError(
            f"'Frames: {n_frames}' declared but {found} frame lines found "
            f"(line {extra_line} is frame {n_frames + 1})",
            spath,
            extra_line,
        )
    for problem in (wrong_count, bad.number, bad.value):
        if problem is not None:
            raise problem
    return out.result()


def _convert(
    chunk: list[tuple[int, list[str]]], rows: np.ndarray, channels: tuple, spath: str,
    bad: FirstBad,
) -> None:
    """One chunk of frame lines into ``rows``; its problems into ``bad`` (first ones kept)."""
    first = bad.frame
    bad.frame += len(chunk)
    try:
        rows.reshape(-1)[:] = np.fromiter(
            (float(tok) for _, vals in chunk for tok in vals), dtype=float, count=rows.size
        )
    except ValueError:
        for k, (lno, vals) in enumerate(chunk, start=first + 1):
            for c, tok in enumerate(vals):
                try:
                    float(tok)
                except ValueError:
                    j, d = channels[c]
                    bad.number = ParseError(
                        f"frame {k}: value {c + 1} ({j} {_DOF_TO_BVH[d]}) is {tok!r}, "
                        "expected a number",
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
        k, c = (int(v) for v in np.argwhere(wrong)[0])
        j, d = channels[c]
        lno, vals = chunk[k]
        bad.value = ParseError(
            f"frame {first + k + 1}: value {c + 1} ({j} {_DOF_TO_BVH[d]}) is "
            f"{vals[c]!r}, expected a finite number of at most {MAX_MAGNITUDE:g} "
            "in magnitude",
            spath,
            lno,
        )


# ----------------------------------------------------------------------------- writing
def _is_subsequence(short: str, long: str) -> bool:
    it = iter(long)
    return all(c in it for c in short)


def _complete_order(order: str, preferred: str = "ZXY") -> str:
    """A three-axis order that lists ``order``'s axes in the same relative order."""
    if len(order) == 3:
        return order
    if _is_subsequence(order, preferred):
        return preferred
    return order + "".join(c for c in "XYZ" if c not in order)


def _bvh_ready_orders(skeleton: Skeleton, forced: str | None) -> list[str] | None:
    """Per-joint 3-axis orders if the skeleton can be written as is, else ``None``."""
    orders = []
    for j in skeleton.joints:
        if not np.allclose(j.axis, np.eye(3), rtol=0.0, atol=1e-12):
            return None
        if forced is not None:
            if not _is_subsequence(j.rotation_order, forced):
                return None
            orders.append(forced)
        else:
            orders.append(_complete_order(j.rotation_order))
    return orders


def _bvh_names(names: list[str]) -> list[str]:
    """BVH-safe joint names: whitespace and braces become ``_``, clashes get a suffix."""
    out: list[str] = []
    used: set[str] = set()
    for name in names:
        base = re.sub(r"[\s{}]+", "_", name.strip()) or "joint"
        safe, k = base, 2
        while safe in used:
            safe, k = f"{base}_{k}", k + 1
        used.add(safe)
        out.append(safe)
    return out


def _fmt(values) -> str:
    return " ".join(f"{v:.8f}" for v in values)


def write_bvh(
    motion: Motion,
    path: str | os.PathLike[str],
    rotation_order: str | None = None,
    continuous: bool = True,
) -> None:
    """Write a motion as a BVH file.

    The hierarchy is tab-indented; the root gets ``CHANNELS 6 Xposition Yposition
    Zposition`` plus three rotation channels, every other joint ``CHANNELS 3`` rotation
    channels (six if it has translation dofs); leaves with an end site get ``End Site``
    blocks.  Rotation channels a joint lacks are written as 0, position channels it lacks
    as its offset component, so forward kinematics is unchanged.  Euler channels that wrap
    or flip between frames are written continuous (the same rotations; each frame on the
    solution nearest the previous one: :func:`cyclecoord.conventions.continuous_channels`).
    Values are written with 8 decimals.

    Parameters
    ----------
    motion : Motion
        Must have a skeleton.  Channel columns may be in any order (mapped by
        ``(joint, dof)``).  A skeleton with non-identity joint axes (ASF conventions), or
        whose rotation orders do not fit ``rotation_order``, is first converted with
        :func:`cyclecoord.conventions.to_bvh_convention`.
    path : path-like
        Output file, written atomically.
    rotation_order : str, optional
        Force one intrinsic order (a permutation of ``"XYZ"``, e.g. ``"ZXY"``) for every
        joint.  By default a BVH-convention skeleton keeps each joint's own order and
        other skeletons are converted to ``"ZXY"``.
    continuous : bool, default True
        Rewrite Euler channels that wrap or flip between frames on the solution nearest
        the previous frame (same rotations); False writes the values exactly as given.

    Raises
    ------
    ParameterError
        If the motion has no skeleton or ``rotation_order`` is not a permutation of XYZ.

    Notes
    -----
    BVH names are single words: whitespace and braces in joint names are written as
    ``_`` (a numeric suffix keeps names unique), so such joints read back renamed.
    """
    if motion.skeleton is None:
        raise ParameterError(
            f"{path}: writing BVH needs a skeleton and this motion has none; give the capture "
            "its skeleton (--skeleton ASF on the command line, skeleton= in Python) or write "
            ".npz or .csv"
        )
    check_writable(motion, path, "BVH")
    forced = None if rotation_order is None else check_order(rotation_order)
    orders = _bvh_ready_orders(motion.skeleton, forced)
    if orders is None:
        from ..conventions import to_bvh_convention

        motion = to_bvh_convention(motion, rotation_order=forced or "ZXY")
        orders = _bvh_ready_orders(motion.skeleton, forced)
        assert orders is not None
    from ..conventions import continuous_channels

    if continuous:
        motion = continuous_channels(motion)  # no written file flips or wraps between frames
    skel = motion.skeleton
    assert skel is not None
    safe_names = _bvh_names([j.name for j in skel.joints])

    # ---- output channel layout and values, in depth-first (file) order
    children: dict[int, list[int]] = {i: [] for i in range(len(skel.joints))}
    for i, j in enumerate(skel.joints):
        if j.parent >= 0:
            children[j.parent].append(i)
    dfs: list[tuple[int, int]] = []  # (joint index, depth)
    todo = [(0, 0)]
    while todo:
        i, depth = todo.pop()
        dfs.append((i, depth))
        todo.extend((c, depth + 1) for c in reversed(children[i]))

    col = {c: k for k, c in enumerate(motion.channels)}
    T = motion.n_frames
    out_dofs: dict[int, tuple[str, ...]] = {}
    columns: list[np.ndarray] = []
    for i, _ in dfs:
        j = skel.joints[i]
        has_t = i == 0 or any(d.startswith("t") for d in j.dofs)
        dofs = (("tx", "ty", "tz") if has_t else ()) + tuple("r" + a.lower() for a in orders[i])
        out_dofs[i] = dofs
        for d in dofs:
            k = col.get((j.name, d)) if d in j.dofs else None
            if k is not None:
                columns.append(motion.frames[:, k])
            elif d.startswith("t"):
                columns.append(np.full(T, j.offset[AXIS_INDEX[d[1]]]))
            else:
                columns.append(np.zeros(T))
    data = np.column_stack(columns) if columns else np.zeros((T, 0))

    # ---- text
    out: list[str] = ["HIERARCHY"]
    stack_close: list[int] = []  # depths of open blocks

    def close_to(depth: int) -> None:
        while stack_close and stack_close[-1] >= depth:
            d = stack_close.pop()
            out.append("\t" * d + "}")

    for i, depth in dfs:
        close_to(depth)
        j = skel.joints[i]
        ind = "\t" * depth
        out.append(f"{ind}{'ROOT' if depth == 0 else 'JOINT'} {safe_names[i]}")
        out.append(f"{ind}{{")
        out.append(f"{ind}\tOFFSET {_fmt(j.offset)}")
        names = " ".join(_DOF_TO_BVH[d] for d in out_dofs[i])
        out.append(f"{ind}\tCHANNELS {len(out_dofs[i])} {names}")
        if j.end_site is not None:
            out.append(f"{ind}\tEnd Site")
            out.append(f"{ind}\t{{")
            out.append(f"{ind}\t\tOFFSET {_fmt(j.end_site)}")
            out.append(f"{ind}\t}}")
        stack_close.append(depth)
    close_to(0)
    out.append("MOTION")
    out.append(f"Frames: {T}")
    out.append(f"Frame Time: {1.0 / motion.fps:.10g}")
    row_fmt = " ".join(["%.8f"] * data.shape[1])
    with atomic_write(path, "w", newline="\n") as fh:
        fh.write("\n".join(out))
        fh.write("\n")
        for row in data.tolist():
            fh.write(row_fmt % tuple(row))
            fh.write("\n")
