"""Reading Acclaim ASF skeletons (conventions in :mod:`cyclecoord.io.asfamc`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ..errors import ParameterError, ParseError
from ..skeleton import DOF_NAMES, Joint, Skeleton, rotation_order_from_dofs
from ._acclaim import (
    DEG_PER_RAD,
    PathLike,
    axis_matrix,
    parse_number,
    parse_numbers,
    read_text,
    strip_comment,
)
from ._limits import (
    MAX_DEPTH,
    MAX_JOINTS,
    MAX_MAGNITUDE,
    depths,
)

__all__ = ["read_asf"]

_ASF_SECTIONS = (
    ":version",
    ":name",
    ":units",
    ":documentation",
    ":root",
    ":bonedata",
    ":hierarchy",
    ":skin",
)


# --------------------------------------------------------------------------- ASF read
@dataclass
class _AsfBone:
    line: int
    name: str | None = None
    name_line: int = 0
    direction: np.ndarray | None = None
    length: float | None = None
    axis_angles: np.ndarray = field(default_factory=lambda: np.zeros(3))
    axis_order: str = "XYZ"
    dofs: tuple[str, ...] = ()
    dof_line: int = 0
    limits: list = field(default_factory=list)
    limits_line: int = 0
    seen: dict = field(default_factory=dict)


def _parse_dofs(toks: Sequence[str], path: PathLike, line: int, who: str) -> tuple[str, ...]:
    dofs: list[str] = []
    for t in toks:
        d = t.lower()
        if d == "l":
            raise ParseError(
                f"{who}: degree of freedom 'l' (bone stretching) is not supported; "
                "expected tx ty tz rx ry rz",
                path,
                line,
            )
        if d not in DOF_NAMES:
            raise ParseError(
                f"{who}: unknown degree of freedom {t!r}, expected one of tx ty tz rx ry rz",
                path,
                line,
            )
        if d in dofs:
            raise ParseError(f"{who}: degree of freedom {t!r} listed twice", path, line)
        dofs.append(d)
    return tuple(dofs)


def _parse_axis_order(tok: str, path: PathLike, line: int, who: str) -> str:
    order = tok.upper()
    if sorted(order) != ["X", "Y", "Z"]:
        raise ParseError(
            f"{who}: axis order must be a permutation of XYZ, got {tok!r}", path, line
        )
    return order


def _parse_limits(text: str, path: PathLike, line: int) -> list[tuple[float, float]]:
    toks = text.replace("(", " ( ").replace(")", " ) ").split()
    if len(toks) % 4 != 0 or not toks:
        raise ParseError(f"expected limits as '(low high)', got {text.strip()!r}", path, line)
    pairs = []
    for k in range(0, len(toks), 4):
        a, lo, hi, b = toks[k : k + 4]
        if a != "(" or b != ")" or lo in "()" or hi in "()":
            raise ParseError(
                f"expected limits as '(low high)', got {text.strip()!r}", path, line
            )
        pairs.append(
            (
                parse_number(lo, path, line, "a lower limit", allow_inf=True),
                parse_number(hi, path, line, "an upper limit", allow_inf=True),
            )
        )
    return pairs


@dataclass
class _AsfScan:
    """What the line-by-line scan of an ASF file has gathered so far."""

    seen: dict = field(default_factory=dict)  # section keyword -> line
    section: str | None = None
    name: str = ""
    version: str = ""
    units: dict = field(default_factory=lambda: {"mass": 1.0, "length": 1.0, "angle": "deg"})
    root: dict = field(
        default_factory=lambda: {
            "order": (),
            "axis": "XYZ",
            "position": np.zeros(3),
            "orientation": np.zeros(3),
        }
    )
    root_seen: dict = field(default_factory=dict)
    bones: list = field(default_factory=list)
    block: _AsfBone | None = None
    last_field: str = ""
    hier_state: str = "outside"
    hier_entries: list = field(default_factory=list)  # (line, parent, children)
    hier_begin: int = 0


def _section_line(st: _AsfScan, s: str, toks: list[str], path: PathLike, ln: int) -> None:
    """A ``:keyword`` line: close nothing open, then enter the section."""
    key = toks[0]
    low = key.lower()
    if st.block is not None:
        raise ParseError(
            f"bone block opened at line {st.block.line} has no 'end' before {key}",
            path,
            ln,
        )
    if st.section == ":hierarchy" and st.hier_state == "inside":
        raise ParseError(
            f"hierarchy block opened at line {st.hier_begin} has no 'end' before {key}",
            path,
            ln,
        )
    if low not in _ASF_SECTIONS:
        raise ParseError(
            f"unknown section {key!r}; expected one of {', '.join(_ASF_SECTIONS)}",
            path,
            ln,
        )
    if low in st.seen and low != ":skin":
        raise ParseError(
            f"section {key} appears twice (first at line {st.seen[low]})", path, ln
        )
    st.seen[low] = ln
    st.section = low
    if low == ":version":
        st.version = " ".join(toks[1:])
    elif low == ":name":
        st.name = s[len(key) :].strip()
    elif len(toks) > 1:
        raise ParseError(f"unexpected text after {key}: {' '.join(toks[1:])!r}", path, ln)


def _units_line(units: dict, s: str, toks: list[str], path: PathLike, ln: int) -> None:
    """A line under ``:units`` (mass, length and angle are read; others are ignored)."""
    low = toks[0].lower()
    if len(toks) != 2:
        raise ParseError(f"expected 'unit value' under :units, got {s!r}", path, ln)
    if low in ("mass", "length"):
        v = parse_number(toks[1], path, ln, f"units {low}")
        if v <= 0:
            raise ParseError(f"units {low} must be positive, got {toks[1]!r}", path, ln)
        units[low] = v
    elif low == "angle":
        a = toks[1].lower()
        if a in ("deg", "degree", "degrees"):
            units["angle"] = "deg"
        elif a in ("rad", "radian", "radians"):
            units["angle"] = "rad"
        else:
            raise ParseError(
                f"units angle must be 'deg' or 'rad', got {toks[1]!r}", path, ln
            )
    # other unit keys carry nothing cyclecoord uses


def _root_line(st: _AsfScan, s: str, toks: list[str], path: PathLike, ln: int) -> None:
    """A line under ``:root``: order, axis, position or orientation."""
    key = toks[0]
    low = key.lower()
    root = st.root
    if low in st.root_seen:
        raise ParseError(
            f"root field {key!r} given twice (first at line {st.root_seen[low]})", path, ln
        )
    st.root_seen[low] = ln
    if low == "order":
        root["order"] = _parse_dofs(toks[1:], path, ln, "root order")
    elif low == "axis":
        if len(toks) != 2:
            raise ParseError(f"root axis needs one order such as XYZ, got {s!r}", path, ln)
        root["axis"] = _parse_axis_order(toks[1], path, ln, "root")
    elif low == "position":
        root["position"] = parse_numbers(toks[1:], 3, path, ln, "root position")
    elif low == "orientation":
        root["orientation"] = parse_numbers(toks[1:], 3, path, ln, "root orientation")
    else:
        raise ParseError(
            f"unknown root field {key!r}; expected order, axis, position or orientation",
            path,
            ln,
        )


def _bonedata_line(st: _AsfScan, s: str, toks: list[str], path: PathLike, ln: int) -> None:
    """A line under ``:bonedata``: opens or closes a bone block, or sets one of its fields."""
    key = toks[0]
    low = key.lower()
    block = st.block
    if block is None:
        if low == "begin" and len(toks) == 1:
            st.block = _AsfBone(line=ln)
            st.last_field = ""
            return
        raise ParseError(f"expected 'begin' to open a bone block, got {s!r}", path, ln)
    if low == "end" and len(toks) == 1:
        st.bones.append(_finish_bone(block, path, ln))
        st.block = None
        if len(st.bones) >= MAX_JOINTS:
            raise ParseError(
                f"more than {MAX_JOINTS - 1:,} bones; at most {MAX_JOINTS:,} joints "
                "(the root and its bones) are supported",
                path,
                ln,
            )
        return
    if s.startswith("("):
        if st.last_field != "limits":
            raise ParseError(f"limits line {s!r} does not follow 'limits'", path, ln)
        block.limits.extend(_parse_limits(s, path, ln))
        return
    if low in block.seen:
        raise ParseError(
            f"bone field {key!r} given twice (first at line {block.seen[low]})", path, ln
        )
    block.seen[low] = ln
    st.last_field = low
    _bone_field(block, s, toks, path, ln)


def _bone_field(block: _AsfBone, s: str, toks: list[str], path: PathLike, ln: int) -> None:
    """One field line of an open bone block (``name``, ``direction``, ``dof``, ...)."""
    key = toks[0]
    low = key.lower()
    who = f"bone {block.name!r}" if block.name else "bone"
    if low == "begin":
        raise ParseError(
            f"bone block opened at line {block.line} has no 'end' before a new 'begin'",
            path,
            ln,
        )
    elif low == "id":
        pass
    elif low == "name":
        if len(toks) != 2:
            raise ParseError(f"bone name must be one word, got {s!r}", path, ln)
        block.name = toks[1]
        block.name_line = ln
    elif low == "direction":
        block.direction = parse_numbers(toks[1:], 3, path, ln, f"{who} direction")
    elif low == "length":
        v = parse_numbers(toks[1:], 1, path, ln, f"{who} length")[0]
        if v < 0:
            raise ParseError(
                f"{who} length must not be negative, got {toks[1]!r}", path, ln
            )
        block.length = float(v)
    elif low == "axis":
        if len(toks) == 5:
            block.axis_order = _parse_axis_order(toks[4], path, ln, who)
            block.axis_angles = parse_numbers(toks[1:4], 3, path, ln, f"{who} axis")
        elif len(toks) == 4:
            block.axis_angles = parse_numbers(toks[1:4], 3, path, ln, f"{who} axis")
        else:
            raise ParseError(
                f"{who} axis needs 3 angles and an order such as XYZ, got {s!r}", path, ln
            )
    elif low == "dof":
        block.dofs = _parse_dofs(toks[1:], path, ln, who)
        block.dof_line = ln
    elif low == "limits":
        block.limits_line = ln
        block.limits.extend(_parse_limits(s[len(key) :], path, ln))
    elif low in ("bodymass", "cofmass"):
        pass
    else:
        raise ParseError(
            f"unknown bone field {key!r}; expected id, name, direction, length, "
            "axis, dof or limits",
            path,
            ln,
        )


def _hierarchy_line(st: _AsfScan, s: str, toks: list[str], path: PathLike, ln: int) -> None:
    """A line under ``:hierarchy``: ``begin``, ``end`` or ``parent child...``."""
    low = toks[0].lower()
    if st.hier_state == "outside":
        if low == "begin" and len(toks) == 1:
            st.hier_state = "inside"
            st.hier_begin = ln
            return
        raise ParseError(f"expected 'begin' to open the hierarchy, got {s!r}", path, ln)
    if st.hier_state == "inside":
        if low == "end" and len(toks) == 1:
            st.hier_state = "done"
            return
        st.hier_entries.append((ln, toks[0], toks[1:]))
        return
    raise ParseError(f"unexpected line after the hierarchy's 'end': {s!r}", path, ln)


def _scan_asf(lines: list[str], path: PathLike) -> _AsfScan:
    """Read every line into an :class:`_AsfScan`, section by section."""
    st = _AsfScan()
    for ln, raw in enumerate(lines, 1):
        s = strip_comment(raw)
        if not s:
            continue
        toks = s.split()
        key = toks[0]
        if key.startswith(":"):
            _section_line(st, s, toks, path, ln)
            continue
        section = st.section
        if section is None:
            raise ParseError(
                f"expected an ASF section keyword such as ':version' or ':root', got {key!r}",
                path,
                ln,
            )
        if section in (":documentation", ":skin", ":version", ":name"):
            if section in (":version", ":name"):
                raise ParseError(
                    f"unexpected line after {section}: {s!r}; expected a section keyword",
                    path,
                    ln,
                )
            continue
        if section == ":units":
            _units_line(st.units, s, toks, path, ln)
        elif section == ":root":
            _root_line(st, s, toks, path, ln)
        elif section == ":bonedata":
            _bonedata_line(st, s, toks, path, ln)
        elif section == ":hierarchy":
            _hierarchy_line(st, s, toks, path, ln)
    return st


def _check_complete(st: _AsfScan, path: PathLike, last_line: int) -> None:
    """Every block closed and every needed section present once the file ends."""
    if st.block is not None:
        raise ParseError(
            f"bone block opened at line {st.block.line} has no 'end' (file ends)",
            path,
            last_line,
        )
    if st.hier_state == "inside":
        raise ParseError(
            f"hierarchy block opened at line {st.hier_begin} has no 'end' (file ends)",
            path,
            last_line,
        )
    seen = st.seen
    if ":root" not in seen:
        raise ParseError("missing :root section (reached the end of the file)", path, last_line)
    if ":bonedata" not in seen:
        raise ParseError("missing :bonedata section (reached the end of the file)", path, last_line)
    if st.bones and ":hierarchy" not in seen:
        raise ParseError(
            "missing :hierarchy section (reached the end of the file)", path, last_line
        )


def _link_hierarchy(
    bones: list[_AsfBone], hier_entries: list, path: PathLike
) -> tuple[dict, dict, dict, list[str]]:
    """Bones by name, children and parent (with its line) of each, depth-first order."""
    defined: dict[str, _AsfBone] = {}
    for b in bones:
        assert b.name is not None
        if b.name == "root":
            raise ParseError(
                "a bone may not be named 'root' (the root is implicit)", path, b.name_line
            )
        if b.name in defined:
            raise ParseError(
                f"bone {b.name!r} defined twice (first at line {defined[b.name].name_line})",
                path,
                b.name_line,
            )
        defined[b.name] = b
    children: dict[str, list[str]] = {"root": []}
    parent_of: dict[str, tuple[str, int]] = {}
    for ln, par, kids in hier_entries:
        if par != "root" and par not in defined:
            raise ParseError(
                f"hierarchy names parent {par!r}, which is not defined in :bonedata", path, ln
            )
        for k in kids:
            if k == "root":
                raise ParseError("the root cannot be a child in the hierarchy", path, ln)
            if k not in defined:
                raise ParseError(
                    f"hierarchy names bone {k!r}, which is not defined in :bonedata", path, ln
                )
            if k in parent_of:
                raise ParseError(
                    f"bone {k!r} already has parent {parent_of[k][0]!r} (line {parent_of[k][1]})",
                    path,
                    ln,
                )
            parent_of[k] = (par, ln)
            children.setdefault(par, []).append(k)
    order: list[str] = []
    stack = ["root"]
    while stack:
        cur = stack.pop()
        order.append(cur)
        stack.extend(reversed(children.get(cur, [])))
    reached = set(order)
    for b in bones:
        if b.name not in reached:
            if b.name not in parent_of:
                raise ParseError(
                    f"bone {b.name!r} is not placed in :hierarchy", path, b.name_line
                )
            raise ParseError(
                f"bone {b.name!r} is not connected to the root (the hierarchy has a cycle)",
                path,
                parent_of[b.name][1],
            )
    return defined, children, parent_of, order


def _build_skeleton(
    st: _AsfScan,
    defined: dict,
    children: dict,
    parent_of: dict,
    order: list[str],
    path: PathLike,
) -> Skeleton:
    """The Skeleton of the linked bones: depth and size checks, then one joint per bone."""
    root = st.root
    scale = DEG_PER_RAD if st.units["angle"] == "rad" else 1.0
    index = {n: i for i, n in enumerate(order)}
    level = depths([-1] + [index[parent_of[n][0]] for n in order[1:]])
    for n, lv in zip(order, level):
        if lv > MAX_DEPTH:
            raise ParseError(
                f"bone {n!r} hangs {lv} levels below the root; at most {MAX_DEPTH} are supported",
                path,
                parent_of[n][1],
            )
    for b in st.bones:
        vec = b.direction * b.length
        if not np.all(np.abs(vec) <= MAX_MAGNITUDE):
            raise ParseError(
                f"bone {b.name!r}: direction times length reaches {np.max(np.abs(vec)):g}, "
                f"beyond the largest supported magnitude {MAX_MAGNITUDE:g}",
                path,
                b.line,
            )
    try:
        joints = [
            Joint(
                name="root",
                parent=-1,
                offset=root["position"],
                dofs=root["order"],
                rotation_order=rotation_order_from_dofs(root["order"], reverse=True),
                axis=axis_matrix(root["orientation"] * scale, root["axis"]),
            )
        ]
        for bname in order[1:]:
            b = defined[bname]
            par = parent_of[bname][0]
            vec = b.direction * b.length
            offset = np.zeros(3) if par == "root" else defined[par].direction * defined[par].length
            limits = {}
            for d, (lo, hi) in zip(b.dofs, b.limits):
                f = scale if d.startswith("r") else 1.0
                limits[d] = (lo * f, hi * f)
            joints.append(
                Joint(
                    name=bname,
                    parent=index[par],
                    offset=offset,
                    dofs=b.dofs,
                    rotation_order=rotation_order_from_dofs(b.dofs, reverse=True),
                    axis=axis_matrix(b.axis_angles * scale, b.axis_order),
                    end_site=None if children.get(bname) else vec,
                    limits=limits,
                )
            )
        return Skeleton(
            joints=tuple(joints), name=st.name, length_unit=st.units["length"], source_format="asf"
        )
    except ParameterError as exc:  # pragma: no cover - guarded by the checks above
        raise ParseError(f"inconsistent skeleton: {exc}", path) from None


def parse_asf(text: str, path: PathLike) -> tuple[Skeleton, dict]:
    """Parse ASF text into a Skeleton plus ``{"angle", "mass", "version"}``."""
    lines = text.split("\n")
    if not text.strip():
        raise ParseError("file is empty; expected an ASF skeleton", path, 1)
    last_line = len(lines)
    while last_line > 1 and not lines[last_line - 1].strip():
        last_line -= 1
    st = _scan_asf(lines, path)
    _check_complete(st, path, last_line)
    defined, children, parent_of, order = _link_hierarchy(st.bones, st.hier_entries, path)
    skeleton = _build_skeleton(st, defined, children, parent_of, order, path)
    units = st.units
    return skeleton, {"angle": units["angle"], "mass": units["mass"], "version": st.version}


def _finish_bone(b: _AsfBone, path: PathLike, end_line: int) -> _AsfBone:
    where = f"bone block starting at line {b.line}"
    if b.name is None:
        raise ParseError(f"{where} has no 'name'", path, end_line)
    if b.direction is None:
        raise ParseError(f"bone {b.name!r} has no 'direction'", path, end_line)
    if b.length is None:
        raise ParseError(f"bone {b.name!r} has no 'length'", path, end_line)
    if b.limits and len(b.limits) != len(b.dofs):
        raise ParseError(
            f"bone {b.name!r} has {len(b.dofs)} dofs ({' '.join(b.dofs) or 'none'}) "
            f"but {len(b.limits)} limits",
            path,
            b.limits_line or end_line,
        )
    return b


def read_asf(path: PathLike) -> Skeleton:
    """Read an Acclaim ASF skeleton.

    Parameters
    ----------
    path : path-like
        The ``.asf`` file (LF or CRLF line ends, ``#`` comments allowed).

    Returns
    -------
    Skeleton
        ``source_format="asf"``, ``length_unit`` from ``:units length``; joint 0 is the
        root, then one joint per bone in depth-first hierarchy order.  Offsets and end
        sites in the file's length units, axes and limits in degrees (see the module
        docstring for the conventions).

    Raises
    ------
    ParseError
        Naming the file, the line and what was expected (missing sections, undefined
        bones in the hierarchy, bad dof names, malformed numbers, ...).
    """
    skeleton, _ = parse_asf(read_text(path), path)
    return skeleton
