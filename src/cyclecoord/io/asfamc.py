"""Acclaim ASF (skeleton) and AMC (motion) reading and writing.

Conventions (see :mod:`cyclecoord.skeleton` for the shared skeleton model):

* The ASF root becomes a joint named ``"root"`` whose offset is the ASF root
  ``position``; its dofs follow the root ``order`` line in file order and its rest axis is
  built from the root ``axis`` letters and ``orientation`` angles.
* Every ASF bone becomes one joint placed at the bone's *start* (the end of its parent
  bone).  Its offset is the parent bone's vector ``direction * length`` (ASF directions
  are global and the rest pose is world aligned, so no change of frame is needed); bones
  hanging from the root start at the root (offset zero).  A leaf bone keeps its own
  vector as ``end_site``.  A bone's own vector is therefore always recoverable: it is the
  offset of any of its children, or its end site.
* Rotation dofs listed ``rx ry rz`` are applied first listed first, i.e. the motion
  matrix is ``Rz @ Ry @ Rx`` and the intrinsic ``rotation_order`` is ``"ZYX"`` (CMU's
  mocapPlayer convention).  ``axis a b c XYZ`` pairs each angle with the letter at the
  same position and also applies the first letter first: ``C = Rz(c) @ Ry(b) @ Rx(a)``.
  The root ``orientation`` is read the same way with the root ``axis`` letters.
* Angles are degrees unless the ASF says ``:units angle rad`` or the AMC says
  ``:RADIANS``; skeletons and motions always hold degrees.  An AMC with neither
  ``:DEGREES`` nor ``:RADIANS`` uses the ASF's angle unit when the ASF is read from a
  file, degrees otherwise.
* Translation dofs on a bone (``tx ty tz``) replace the matching component of the joint's
  offset, as everywhere in cyclecoord.

Writing any :class:`~cyclecoord.skeleton.Skeleton` (for instance one read from BVH) as
ASF uses this mapping:

* the first joint is written as the ASF ``root`` (whatever its name); other names are
  made ASF-safe (whitespace, ``#`` and parentheses become ``_``; names that could be read
  as numbers, ``begin``, ``end`` or ``root`` get a ``j_`` prefix; clashes get a numeric
  suffix).  The AMC written for the same skeleton uses the same names;
* a joint whose children all sit at the same offset becomes a bone with that vector; a
  leaf becomes a bone whose vector is its end site (zero length without one);
* a joint whose children sit at *different* offsets (common in BVH) becomes a
  zero-length bone, and every child with a non-zero offset ``o`` is hung from a
  zero-dof helper bone named ``<parent>_to_<child>`` whose vector is ``o``.  The root is
  always treated this way because an ASF root has no bone.  Helper bones carry no
  rotation, so every original joint keeps exactly its forward-kinematics position and
  rotation (also when it has translation channels), and helper bones never appear in
  AMC files;
* rotation dofs are listed in reverse intrinsic order (so ``rotation_order`` survives);
  translation dofs come first when the listing had to change; ``axis`` and the root
  orientation are written as ``XYZ`` angles; end sites of joints that have children and
  limits of the root are not representable and are dropped.
"""

from __future__ import annotations

import bisect
import math
import os
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import ParameterError, ParseError
from ..motion import Motion
from ..skeleton import DOF_NAMES, Joint, Skeleton, rotation_order_from_dofs
from ._atomic import atomic_write
from ._limits import (
    MAX_DEPTH,
    MAX_FRAME_NUMBER,
    MAX_FRAMES,
    MAX_JOINTS,
    MAX_MAGNITUDE,
    check_writable,
    depths,
    parse_int,
    skeleton_problem,
)

__all__ = ["read_asf", "write_asf", "read_amc", "write_amc", "find_skeleton"]

PathLike = str | os.PathLike

_INT_RE = re.compile(r"[+-]?[0-9]+")
_DEG_PER_RAD = 180.0 / math.pi
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
_RESERVED = {"begin", "end", "root"}


# --------------------------------------------------------------------------- helpers
def _read_text(path: PathLike) -> str:
    """Whole file as text with ``\\n`` line ends (CRLF and CR normalised)."""
    try:
        data = Path(path).read_bytes()
    except IsADirectoryError:
        raise ParseError("is a folder, expected a file", path) from None
    except OSError as exc:
        raise ParseError(f"cannot read file: {exc.strerror or exc}", path) from None
    text = data.decode("utf-8", errors="replace")
    if text.startswith("\ufeff"):
        text = text[1:]
    if "\r" in text:
        text = text.replace("\r\n", "\n").replace("\r", "\n")
    return text


def _strip_comment(raw: str) -> str:
    if "#" in raw:
        raw = raw[: raw.index("#")]
    return raw.strip()


def _number(tok: str, path: PathLike, line: int, what: str, allow_inf: bool = False) -> float:
    """Parse one number token or raise a ParseError naming ``what`` it was for."""
    try:
        value = float(tok)
    except ValueError:
        raise ParseError(f"expected a number for {what}, got {tok!r}", path, line) from None
    if math.isnan(value) or (not allow_inf and math.isinf(value)):
        raise ParseError(f"expected a finite number for {what}, got {tok!r}", path, line)
    if math.isfinite(value) and abs(value) > MAX_MAGNITUDE:
        raise ParseError(
            f"{what} is {tok!r}, beyond the largest supported magnitude {MAX_MAGNITUDE:g}",
            path,
            line,
        )
    return value


def _numbers(
    toks: Sequence[str], count: int, path: PathLike, line: int, what: str
) -> np.ndarray:
    if len(toks) != count:
        raise ParseError(
            f"{what} needs {count} number{'s' if count != 1 else ''}, got {len(toks)} "
            f"({' '.join(toks) or 'nothing'})",
            path,
            line,
        )
    return np.array([_number(t, path, line, what) for t in toks], dtype=float)


def _axis_matrix(angles_deg: np.ndarray, order: str) -> np.ndarray:
    """``C`` from angles paired with the letters of ``order``, first letter applied first."""
    # extrinsic (lower-case) Euler: first letter rotates first about the fixed axes,
    # which gives e.g. Rz(c) @ Ry(b) @ Rx(a) for "xyz".
    return Rotation.from_euler(order.lower(), angles_deg, degrees=True).as_matrix()


def _axis_angles(matrix: np.ndarray) -> np.ndarray:
    """XYZ angles (degrees) with ``matrix == Rz(c) @ Ry(b) @ Rx(a)``.

    Angles are rounded to 1e-9 degrees when that changes the matrix by less than 1e-13,
    so ``20`` is written rather than ``19.999999999999996``.
    """
    matrix = np.asarray(matrix, dtype=float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # gimbal lock is harmless here: the matrix is kept
        angles = Rotation.from_matrix(matrix).as_euler("xyz", degrees=True)
    rounded = np.round(angles, 9)
    if np.max(np.abs(_axis_matrix(rounded, "XYZ") - matrix)) <= 1e-13:
        return rounded
    return angles


def _fmt(x: float) -> str:
    """Shortest text that reads back to exactly the same float."""
    x = float(x)
    if x == 0.0:
        return "0"
    return repr(x)


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
                _number(lo, path, line, "a lower limit", allow_inf=True),
                _number(hi, path, line, "an upper limit", allow_inf=True),
            )
        )
    return pairs


def _parse_asf(text: str, path: PathLike) -> tuple[Skeleton, dict]:
    """Parse ASF text into a Skeleton plus ``{"angle", "mass", "version"}``."""
    lines = text.split("\n")
    if not text.strip():
        raise ParseError("file is empty; expected an ASF skeleton", path, 1)
    last_line = len(lines)
    while last_line > 1 and not lines[last_line - 1].strip():
        last_line -= 1

    seen: dict[str, int] = {}
    section: str | None = None
    name = ""
    version = ""
    units = {"mass": 1.0, "length": 1.0, "angle": "deg"}
    root: dict = {"order": (), "axis": "XYZ", "position": np.zeros(3), "orientation": np.zeros(3)}
    root_seen: dict[str, int] = {}
    bones: list[_AsfBone] = []
    block: _AsfBone | None = None
    last_field = ""
    hier_state = "outside"
    hier_entries: list[tuple[int, str, list[str]]] = []
    hier_begin = 0

    for ln, raw in enumerate(lines, 1):
        s = _strip_comment(raw)
        if not s:
            continue
        toks = s.split()
        key = toks[0]
        low = key.lower()
        if key.startswith(":"):
            if block is not None:
                raise ParseError(
                    f"bone block opened at line {block.line} has no 'end' before {key}",
                    path,
                    ln,
                )
            if section == ":hierarchy" and hier_state == "inside":
                raise ParseError(
                    f"hierarchy block opened at line {hier_begin} has no 'end' before {key}",
                    path,
                    ln,
                )
            if low not in _ASF_SECTIONS:
                raise ParseError(
                    f"unknown section {key!r}; expected one of {', '.join(_ASF_SECTIONS)}",
                    path,
                    ln,
                )
            if low in seen and low != ":skin":
                raise ParseError(
                    f"section {key} appears twice (first at line {seen[low]})", path, ln
                )
            seen[low] = ln
            section = low
            if low == ":version":
                version = " ".join(toks[1:])
            elif low == ":name":
                name = s[len(key) :].strip()
            elif len(toks) > 1:
                raise ParseError(f"unexpected text after {key}: {' '.join(toks[1:])!r}", path, ln)
            continue

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
            if len(toks) != 2:
                raise ParseError(f"expected 'unit value' under :units, got {s!r}", path, ln)
            if low in ("mass", "length"):
                v = _number(toks[1], path, ln, f"units {low}")
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
            continue

        if section == ":root":
            if low in root_seen:
                raise ParseError(
                    f"root field {key!r} given twice (first at line {root_seen[low]})", path, ln
                )
            root_seen[low] = ln
            if low == "order":
                root["order"] = _parse_dofs(toks[1:], path, ln, "root order")
            elif low == "axis":
                if len(toks) != 2:
                    raise ParseError(f"root axis needs one order such as XYZ, got {s!r}", path, ln)
                root["axis"] = _parse_axis_order(toks[1], path, ln, "root")
            elif low == "position":
                root["position"] = _numbers(toks[1:], 3, path, ln, "root position")
            elif low == "orientation":
                root["orientation"] = _numbers(toks[1:], 3, path, ln, "root orientation")
            else:
                raise ParseError(
                    f"unknown root field {key!r}; expected order, axis, position or orientation",
                    path,
                    ln,
                )
            continue

        if section == ":bonedata":
            if block is None:
                if low == "begin" and len(toks) == 1:
                    block = _AsfBone(line=ln)
                    last_field = ""
                    continue
                raise ParseError(f"expected 'begin' to open a bone block, got {s!r}", path, ln)
            if low == "end" and len(toks) == 1:
                bones.append(_finish_bone(block, path, ln))
                block = None
                if len(bones) >= MAX_JOINTS:
                    raise ParseError(
                        f"more than {MAX_JOINTS - 1:,} bones; at most {MAX_JOINTS:,} joints "
                        "(the root and its bones) are supported",
                        path,
                        ln,
                    )
                continue
            if s.startswith("("):
                if last_field != "limits":
                    raise ParseError(f"limits line {s!r} does not follow 'limits'", path, ln)
                block.limits.extend(_parse_limits(s, path, ln))
                continue
            if low in block.seen:
                raise ParseError(
                    f"bone field {key!r} given twice (first at line {block.seen[low]})", path, ln
                )
            block.seen[low] = ln
            last_field = low
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
                block.direction = _numbers(toks[1:], 3, path, ln, f"{who} direction")
            elif low == "length":
                v = _numbers(toks[1:], 1, path, ln, f"{who} length")[0]
                if v < 0:
                    raise ParseError(
                        f"{who} length must not be negative, got {toks[1]!r}", path, ln
                    )
                block.length = float(v)
            elif low == "axis":
                if len(toks) == 5:
                    block.axis_order = _parse_axis_order(toks[4], path, ln, who)
                    block.axis_angles = _numbers(toks[1:4], 3, path, ln, f"{who} axis")
                elif len(toks) == 4:
                    block.axis_angles = _numbers(toks[1:4], 3, path, ln, f"{who} axis")
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
            continue

        if section == ":hierarchy":
            if hier_state == "outside":
                if low == "begin" and len(toks) == 1:
                    hier_state = "inside"
                    hier_begin = ln
                    continue
                raise ParseError(f"expected 'begin' to open the hierarchy, got {s!r}", path, ln)
            if hier_state == "inside":
                if low == "end" and len(toks) == 1:
                    hier_state = "done"
                    continue
                hier_entries.append((ln, key, toks[1:]))
                continue
            raise ParseError(f"unexpected line after the hierarchy's 'end': {s!r}", path, ln)

    if block is not None:
        raise ParseError(
            f"bone block opened at line {block.line} has no 'end' (file ends)", path, last_line
        )
    if hier_state == "inside":
        raise ParseError(
            f"hierarchy block opened at line {hier_begin} has no 'end' (file ends)",
            path,
            last_line,
        )
    if ":root" not in seen:
        raise ParseError("missing :root section (reached the end of the file)", path, last_line)
    if ":bonedata" not in seen:
        raise ParseError("missing :bonedata section (reached the end of the file)", path, last_line)
    if bones and ":hierarchy" not in seen:
        raise ParseError(
            "missing :hierarchy section (reached the end of the file)", path, last_line
        )

    # ------------------------------------------------------------ hierarchy
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

    # ------------------------------------------------------------ joints
    scale = _DEG_PER_RAD if units["angle"] == "rad" else 1.0
    index = {n: i for i, n in enumerate(order)}
    level = depths([-1] + [index[parent_of[n][0]] for n in order[1:]])
    for n, lv in zip(order, level):
        if lv > MAX_DEPTH:
            raise ParseError(
                f"bone {n!r} hangs {lv} levels below the root; at most {MAX_DEPTH} are supported",
                path,
                parent_of[n][1],
            )
    for b in bones:
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
                axis=_axis_matrix(root["orientation"] * scale, root["axis"]),
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
                    axis=_axis_matrix(b.axis_angles * scale, b.axis_order),
                    end_site=None if children.get(bname) else vec,
                    limits=limits,
                )
            )
        skeleton = Skeleton(
            joints=tuple(joints), name=name, length_unit=units["length"], source_format="asf"
        )
    except ParameterError as exc:  # pragma: no cover - guarded by the checks above
        raise ParseError(f"inconsistent skeleton: {exc}", path) from None
    return skeleton, {"angle": units["angle"], "mass": units["mass"], "version": version}


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
    skeleton, _ = _parse_asf(_read_text(path), path)
    return skeleton


# --------------------------------------------------------------------------- layout
@dataclass
class _LayoutBone:
    """One ASF bone (or the root) as written for a Skeleton."""

    asf_name: str
    joint: str | None  # original joint name; None for helper bones
    parent: str | None  # ASF name of the parent bone; None for the root
    vector: np.ndarray  # direction * length; zeros for the root
    axis: np.ndarray
    dofs: tuple[str, ...]  # in ASF/AMC listing order
    limits: dict
    position: np.ndarray | None = None  # root only


def _is_number(s: str) -> bool:
    try:
        float(s)
    except ValueError:
        return False
    return True


def _safe_name(name: str) -> str:
    s = re.sub(r"[\s#()]+", "_", name)
    if not s:
        s = "joint"
    if s.startswith(":") or s.lower() in _RESERVED or _is_number(s):
        s = "j_" + s
    return s


def _asf_listing(j: Joint) -> tuple[str, ...]:
    """Dof order for an ASF/AMC: rotation dofs listed in reverse intrinsic order."""
    if rotation_order_from_dofs(j.dofs, reverse=True) == j.rotation_order:
        return tuple(j.dofs)
    trans = tuple(d for d in j.dofs if d.startswith("t"))
    return trans + tuple("r" + a.lower() for a in reversed(j.rotation_order))


def _asf_layout(skel: Skeleton) -> list[_LayoutBone]:
    """Map a Skeleton onto ASF bones (root first); see the module docstring."""
    joints = skel.joints
    n = len(joints)
    taken: set[str] = {"root"}
    names = ["root"]
    for j in joints[1:]:
        base = _safe_name(j.name)
        cand, k = base, 2
        while cand in taken:
            cand, k = f"{base}_{k}", k + 1
        taken.add(cand)
        names.append(cand)

    kids: list[list[int]] = [[] for _ in range(n)]
    for i, j in enumerate(joints[1:], start=1):
        kids[j.parent].append(i)
    size = max(
        [1.0]
        + [float(np.max(np.abs(j.offset))) for j in joints]
        + [float(np.max(np.abs(j.end_site))) for j in joints if j.end_site is not None]
    )
    tol = 1e-12 * size

    vectors: list[np.ndarray] = []
    for i, j in enumerate(joints):
        if i == 0:
            v = np.zeros(3)
        elif kids[i]:
            first = joints[kids[i][0]].offset
            shared = all(np.max(np.abs(joints[c].offset - first)) <= tol for c in kids[i])
            v = first.copy() if shared else np.zeros(3)
        elif j.end_site is not None:
            v = j.end_site.copy()
        else:
            v = np.zeros(3)
        vectors.append(v)

    root = joints[0]
    out = [
        _LayoutBone(
            asf_name="root",
            joint=root.name,
            parent=None,
            vector=np.zeros(3),
            axis=root.axis,
            dofs=_asf_listing(root),
            limits={},
            position=root.offset.copy(),
        )
    ]
    for i, j in enumerate(joints[1:], start=1):
        p = j.parent
        parent_name = names[p]
        if np.max(np.abs(j.offset - vectors[p])) > tol:
            base = f"{names[p]}_to_{names[i]}"
            cand, k = base, 2
            while cand in taken:
                cand, k = f"{base}_{k}", k + 1
            taken.add(cand)
            out.append(
                _LayoutBone(
                    asf_name=cand,
                    joint=None,
                    parent=parent_name,
                    vector=j.offset - vectors[p],
                    axis=np.eye(3),
                    dofs=(),
                    limits={},
                )
            )
            parent_name = cand
        dofs = _asf_listing(j)
        limits = {}
        if j.limits:
            limits = {d: tuple(j.limits.get(d, (-math.inf, math.inf))) for d in dofs}
        out.append(
            _LayoutBone(
                asf_name=names[i],
                joint=j.name,
                parent=parent_name,
                vector=vectors[i],
                axis=j.axis,
                dofs=dofs,
                limits=limits,
            )
        )
    return out


# --------------------------------------------------------------------------- ASF write
def _asf_text(skel: Skeleton) -> str:
    if not isinstance(skel, Skeleton):
        raise ParameterError(f"expected a Skeleton, got {type(skel).__name__}")
    problem = skeleton_problem(skel)
    if problem is not None:
        raise ParameterError(f"cannot write ASF: skeleton: {problem}")
    unit = float(skel.length_unit)
    if not math.isfinite(unit) or unit <= 0:
        raise ParameterError(f"skeleton length_unit must be a positive number, got {unit}")
    layout = _asf_layout(skel)
    for b in layout:
        arrays = [b.vector, b.axis] + ([b.position] if b.position is not None else [])
        if not all(np.all(np.isfinite(a)) for a in arrays):
            raise ParameterError(f"joint {b.joint or b.asf_name!r} has non-finite geometry")
        if np.max(np.abs(b.axis @ b.axis.T - np.eye(3))) > 1e-6 or np.linalg.det(b.axis) < 0:
            raise ParameterError(f"joint {b.joint or b.asf_name!r}: axis is not a rotation matrix")
        if np.linalg.norm(b.vector) > MAX_MAGNITUDE:
            raise ParameterError(
                f"cannot write ASF: bone {b.asf_name!r} would be {np.linalg.norm(b.vector):g} "
                f"long, beyond the largest supported magnitude {MAX_MAGNITUDE:g}"
            )
    name = " ".join(skel.name.replace("#", "_").split()) or "cyclecoord"
    root = layout[0]
    out = [
        "# ASF written by cyclecoord",
        ":version 1.10",
        f":name {name}",
        ":units",
        "  mass 1.0",
        f"  length {_fmt(unit)}",
        "  angle deg",
        ":documentation",
        "  Directions are global unit vectors, angles in degrees.",
        f"  Source skeleton format: {skel.source_format or 'unknown'}.",
        ":root",
    ]
    if root.dofs:
        out.append("  order " + " ".join(d.upper() for d in root.dofs))
    out += [
        "  axis XYZ",
        "  position " + " ".join(_fmt(x) for x in root.position),
        "  orientation " + " ".join(_fmt(x) for x in _axis_angles(root.axis)),
        ":bonedata",
    ]
    for k, b in enumerate(layout[1:], start=1):
        length = float(np.linalg.norm(b.vector))
        direction = b.vector / length if length > 0 else np.array([0.0, 0.0, 1.0])
        out += [
            "  begin",
            f"    id {k}",
            f"    name {b.asf_name}",
            "    direction " + " ".join(_fmt(x) for x in direction),
            f"    length {_fmt(length)}",
            "    axis " + " ".join(_fmt(x) for x in _axis_angles(b.axis)) + " XYZ",
        ]
        if b.dofs:
            out.append("    dof " + " ".join(b.dofs))
            if b.limits:
                pairs = [f"({_fmt(b.limits[d][0])} {_fmt(b.limits[d][1])})" for d in b.dofs]
                out.append("    limits " + pairs[0])
                out += ["           " + p for p in pairs[1:]]
        out.append("  end")
    children: dict[str, list[str]] = {}
    for b in layout[1:]:
        children.setdefault(b.parent, []).append(b.asf_name)
    out += [":hierarchy", "  begin"]
    for b in layout:
        if b.asf_name in children:
            out.append(f"    {b.asf_name} " + " ".join(children[b.asf_name]))
    out += ["  end", ""]
    return "\n".join(out)


def write_asf(skeleton: Skeleton, path: PathLike) -> None:
    """Write a skeleton as an Acclaim ASF file (atomically).

    Parameters
    ----------
    skeleton : Skeleton
        Any skeleton (ASF, BVH or synthetic).  Non-ASF skeletons are mapped as the module
        docstring describes (zero-dof helper bones where a joint's children sit at
        different offsets); forward-kinematics positions of every original joint are
        preserved.
    path : path-like
        Destination; written with ``\\n`` line ends, ``:units angle deg``.

    Raises
    ------
    ParameterError
        When the skeleton holds non-finite geometry or a bad ``length_unit``.
    """
    try:
        text = _asf_text(skeleton)
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from None
    with atomic_write(path, "w", newline="") as fh:
        fh.write(text)


# --------------------------------------------------------------------------- AMC read
def find_skeleton(amc_path: Path) -> Path:
    """The .asf that :func:`read_amc` uses for ``amc_path`` when no skeleton is given.

    The only .asf in the AMC's folder, else ``<subject>.asf`` for ``<subject>_<trial>.amc``.

    Raises
    ------
    ParseError
        When neither rule finds exactly one file (the message says what was looked for).
    """
    folder = amc_path.parent
    try:
        asfs = sorted(
            p for p in folder.iterdir() if p.suffix.lower() == ".asf" and p.is_file()
        )
    except OSError as exc:
        raise ParseError(f"cannot list folder {folder}: {exc.strerror or exc}", amc_path) from None
    if len(asfs) == 1:
        return asfs[0]
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
    skel, info = _parse_asf(_read_text(asf), asf)
    return skel, info["angle"]


def _parse_amc(
    text: str, path: PathLike, skel: Skeleton, default_angle: str | None, fps: float,
    skel_file: PathLike | None = None,
) -> Motion:
    # where the skeleton's side of a mismatch comes from, for the messages
    per = f" (dofs per the skeleton {skel_file})" if skel_file is not None else ""
    if not text.strip():
        raise ParseError("file is empty; expected an AMC header and frames", path, 1)
    # AMC bone name -> (joint name, dofs in listing order)
    bone_map: dict[str, tuple[str, tuple[str, ...]]] = {}
    layout = [b for b in _asf_layout(skel) if b.joint is not None]
    for b in layout:
        bone_map[b.asf_name] = (b.joint, b.dofs)
    for b in layout:  # also accept the skeleton's own joint names where unambiguous
        if _safe_name(b.joint) == b.joint:
            bone_map.setdefault(b.joint, (b.joint, b.dofs))

    lines = text.split("\n")
    header: list[str] = []
    angle: str | None = None
    angle_line = 0
    frame_no: int | None = None
    frame_line = 0
    first_number: int | None = None
    first_bones: list[str] | None = None
    entries: list[tuple[str, int, list[str]]] = []
    flat: list[str] = []
    rec_start: list[int] = []
    rec_info: list[tuple[int, int, str]] = []  # (line, frame, bone)
    n_frames = 0
    last_line = 0

    def emit(frame: int, items) -> None:
        for bone, ln, parts in items:
            rec_start.append(len(flat))
            rec_info.append((ln, frame, bone))
            flat.extend(parts[1:])

    def close_frame() -> None:
        nonlocal first_bones, n_frames
        assert frame_no is not None
        if n_frames >= MAX_FRAMES:
            raise ParseError(
                f"more than {MAX_FRAMES:,} frames; at most {MAX_FRAMES:,} are supported",
                path,
                frame_line,
                frame_no,
            )
        if first_bones is None:
            names = [e[0] for e in entries]
            if not names:
                raise ParseError(
                    f"frame {frame_no} has no bone values; expected lines '<bone> <values>'",
                    path,
                    frame_line,
                    frame_no,
                )
            owners: dict[str, str] = {}
            for bone, ln, _ in entries:
                joint = bone_map[bone][0]
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
            first_bones = names
            emit(frame_no, entries)
        elif len(entries) == len(first_bones) and all(
            e[0] == b for e, b in zip(entries, first_bones)
        ):
            emit(frame_no, entries)
        else:
            by_name: dict[str, tuple[str, int, list[str]]] = {}
            wanted = set(first_bones)
            for e in entries:
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
                    f"frame {frame_no} (starting at line {frame_line}) is missing bone "
                    f"{listed}{more}; expected the {len(first_bones)} bones of the first frame",
                    path,
                    frame_line,
                    frame_no,
                )
            emit(frame_no, [by_name[b] for b in first_bones])
        n_frames += 1

    for ln, raw in enumerate(lines, 1):
        if "#" in raw:
            if frame_no is None and raw.lstrip().startswith("#"):
                header.append(raw.strip())
                continue
            raw = raw[: raw.index("#")]
        parts = raw.split()
        if not parts:
            continue
        last_line = ln
        head = parts[0]
        if len(parts) == 1 and _INT_RE.fullmatch(head):
            try:
                number = parse_int(head, "a frame number", -MAX_FRAME_NUMBER, MAX_FRAME_NUMBER)
            except ValueError as exc:
                raise ParseError(str(exc), path, ln, frame_no) from None
            if frame_no is None:
                first_number = number
            else:
                close_frame()
                if number != frame_no + 1:
                    raise ParseError(
                        f"frame number {number} out of sequence: expected {frame_no + 1}",
                        path,
                        ln,
                        number,
                    )
            frame_no = number
            frame_line = ln
            entries = []
            continue
        if head.startswith(":"):
            if frame_no is not None:
                raise ParseError(
                    f"header line {raw.strip()!r} after the first frame; expected a frame "
                    "number or a bone line",
                    path,
                    ln,
                    frame_no,
                )
            key = head.upper()
            if key in (":DEGREES", ":RADIANS"):
                this = "deg" if key == ":DEGREES" else "rad"
                if angle is not None and angle != this:
                    raise ParseError(
                        f"{head} contradicts the angle unit given at line {angle_line}",
                        path,
                        ln,
                    )
                angle, angle_line = this, ln
            header.append(raw.strip())
            continue
        if frame_no is None:
            raise ParseError(
                f"expected a frame number before bone values, got {raw.strip()!r}", path, ln
            )
        spec = bone_map.get(head)
        if spec is None:
            if _INT_RE.fullmatch(head):
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
            raise ParseError(
                f"bone {head!r} has {nd} dof{'s' if nd != 1 else ''} "
                f"({' '.join(spec[1]) or 'none'}), got {got} value{'s' if got != 1 else ''}{per}",
                path,
                ln,
                frame_no,
            )
        if nd:
            entries.append((head, ln, parts))

    if frame_no is None:
        raise ParseError(
            "no frames: expected a frame number after the header", path, last_line or 1
        )
    close_frame()
    assert first_bones is not None

    n_cols = sum(len(bone_map[b][1]) for b in first_bones)
    try:
        values = np.array(flat, dtype=float)
    except ValueError:
        values = None
    if values is None or not np.all(np.isfinite(values)):
        _locate_bad_value(flat, rec_start, rec_info, path)
    assert values is not None
    frames = values.reshape(n_frames, n_cols)
    channels = [(bone_map[b][0], d) for b in first_bones for d in bone_map[b][1]]
    unit = angle or default_angle or "deg"
    if unit == "rad":
        rot = [i for i, (_, d) in enumerate(channels) if d.startswith("r")]
        frames[:, rot] *= _DEG_PER_RAD
    big = np.abs(frames) > MAX_MAGNITUDE
    if big.any():
        k = int(np.argmax(big.reshape(-1)))
        rec = bisect.bisect_right(rec_start, k) - 1
        ln, frame, bone = rec_info[rec]
        raise ParseError(
            f"value {flat[k]!r} for bone {bone!r} is beyond the largest supported magnitude "
            f"{MAX_MAGNITUDE:g}" + (" degrees" if unit == "rad" else ""),
            path,
            ln,
            frame,
        )
    return Motion(
        frames=frames,
        channels=tuple(channels),
        fps=fps,
        skeleton=skel,
        source=str(path),
        start_frame=0,
        metadata={"amc_header": header, "first_frame_number": first_number},
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
    text = _read_text(amc_path)
    if not text.strip():
        raise ParseError("file is empty; expected an AMC header and frames", path, 1)
    skel, default_angle = _resolve_skeleton(amc_path, skeleton)
    if isinstance(skeleton, Skeleton):
        skel_file = None
    else:
        skel_file = find_skeleton(amc_path) if skeleton is None else Path(skeleton)
    return _parse_amc(text, path, skel, default_angle, fps, skel_file)


# --------------------------------------------------------------------------- AMC write
def _check_token(name: str) -> None:
    if not name or any(c.isspace() for c in name) or "#" in name or name.startswith(":"):
        raise ParameterError(
            f"joint name {name!r} cannot be written to an AMC without a skeleton "
            "(names must be single words without '#')"
        )


def write_amc(
    motion: Motion, path: PathLike, skeleton_path: PathLike | None = None
) -> None:
    """Write a motion as an Acclaim AMC file (atomically).

    Parameters
    ----------
    motion : Motion
        Frames in degrees / length units.  Only joints with channels in the motion are
        written, in the order of their first channel.  With a skeleton, each bone's
        values are written in its ASF dof order (reordered if the motion's channels
        differ; dofs the motion lacks are written as 0, which is how forward kinematics
        treats them) under its ASF bone name (see :func:`write_asf`).  Without one,
        channels are grouped per joint in the motion's order.
    path : path-like
        Destination ``.amc``; ``:FULLY-SPECIFIED``, ``:DEGREES``, frames numbered from 1,
        values written with full (round-trip exact) precision.
    skeleton_path : path-like, optional
        Also write the motion's skeleton there as ASF (see :func:`write_asf`); bone
        names in the AMC match it.

    Raises
    ------
    ParameterError
        For non-finite values, channels the skeleton does not have, an empty motion,
        or ``skeleton_path`` without a skeleton.
    """
    if not isinstance(motion, Motion):
        raise ParameterError(f"expected a Motion, got {type(motion).__name__}")
    check_writable(motion, path, "AMC")
    frames = np.asarray(motion.frames, dtype=float)
    if motion.n_channels == 0:
        raise ParameterError("the motion has no channels; an AMC needs at least one bone")
    bad = ~np.isfinite(frames)
    if bad.any():
        t, c = np.argwhere(bad)[0]
        raise ParameterError(
            f"non-finite value at frame {t}, channel {motion.channels[c]}; AMC needs numbers"
        )
    groups: list[tuple[str, list[int]]] = []
    col = {c: i for i, c in enumerate(motion.channels)}
    zero_col = motion.n_channels
    joint_order: list[str] = []
    for j, _ in motion.channels:
        if j not in joint_order:
            joint_order.append(j)
    skel = motion.skeleton
    if skel is None:
        if skeleton_path is not None:
            raise ParameterError("skeleton_path given but the motion has no skeleton")
        for j in joint_order:
            _check_token(j)
            groups.append((j, [i for i, c in enumerate(motion.channels) if c[0] == j]))
    else:
        by_joint = {b.joint: b for b in _asf_layout(skel) if b.joint is not None}
        for j in joint_order:
            b = by_joint.get(j)
            if b is None:
                raise ParameterError(
                    f"{path}: cannot write AMC: channel joint {j!r} is not in the motion's "
                    "skeleton (an AMC holds only the skeleton's channels)"
                )
            for jj, d in motion.channels:
                if jj == j and d not in b.dofs:
                    raise ParameterError(
                        f"{path}: cannot write AMC: channel ({j!r}, {d!r}) is not a degree "
                        "of freedom of that joint "
                        f"(it has {' '.join(b.dofs) or 'none'})"
                    )
            groups.append((b.asf_name, [col.get((j, d), zero_col) for d in b.dofs]))
    order = [i for _, cols in groups for i in cols]
    data = np.concatenate([frames, np.zeros((frames.shape[0], 1))], axis=1)[:, order]
    spans = []
    start = 0
    for name, cols in groups:
        spans.append((name + " ", start, start + len(cols)))
        start += len(cols)

    out: list[str] = []
    if skeleton_path is not None:
        out.append(f"#!OML:ASF {Path(skeleton_path).name}")
    out += [":FULLY-SPECIFIED", ":DEGREES"]
    for t, row in enumerate(data.tolist(), start=1):
        strs = [_fmt(x) for x in row]
        out.append(str(t))
        for prefix, a, b in spans:
            out.append(prefix + " ".join(strs[a:b]))
    out.append("")
    text = "\n".join(out)
    if skeleton_path is not None:
        assert skel is not None
        write_asf(skel, skeleton_path)
    with atomic_write(path, "w", newline="") as fh:
        fh.write(text)
