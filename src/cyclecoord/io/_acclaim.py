"""Helpers shared by the Acclaim ASF/AMC reader and writer: text, numbers, angles, and the
mapping of any Skeleton onto ASF bones (see :mod:`cyclecoord.io.asfamc`)."""

from __future__ import annotations

import math
import os
import re
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import ParseError
from ..skeleton import Joint, Skeleton, rotation_order_from_dofs
from ._limits import (
    MAX_MAGNITUDE,
)

PathLike = str | os.PathLike

INT_RE = re.compile(r"[+-]?[0-9]+")
DEG_PER_RAD = 180.0 / math.pi
_RESERVED = {"begin", "end", "root"}

# --------------------------------------------------------------------------- helpers
def read_text(path: PathLike) -> str:
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


def strip_comment(raw: str) -> str:
    if "#" in raw:
        raw = raw[: raw.index("#")]
    return raw.strip()


def parse_number(tok: str, path: PathLike, line: int, what: str, allow_inf: bool = False) -> float:
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


def parse_numbers(
    toks: Sequence[str], count: int, path: PathLike, line: int, what: str
) -> np.ndarray:
    if len(toks) != count:
        raise ParseError(
            f"{what} needs {count} number{'s' if count != 1 else ''}, got {len(toks)} "
            f"({' '.join(toks) or 'nothing'})",
            path,
            line,
        )
    return np.array([parse_number(t, path, line, what) for t in toks], dtype=float)


def axis_matrix(angles_deg: np.ndarray, order: str) -> np.ndarray:
    """``C`` from angles paired with the letters of ``order``, first letter applied first."""
    # extrinsic (lower-case) Euler: first letter rotates first about the fixed axes,
    # which gives e.g. Rz(c) @ Ry(b) @ Rx(a) for "xyz".
    return Rotation.from_euler(order.lower(), angles_deg, degrees=True).as_matrix()


def axis_angles(matrix: np.ndarray) -> np.ndarray:
    """XYZ angles (degrees) with ``matrix == Rz(c) @ Ry(b) @ Rx(a)``.

    Angles are rounded to 1e-9 degrees when that changes the matrix by less than 1e-13,
    so ``20`` is written rather than ``19.999999999999996``.
    """
    matrix = np.asarray(matrix, dtype=float)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # gimbal lock is harmless here: the matrix is kept
        angles = Rotation.from_matrix(matrix).as_euler("xyz", degrees=True)
    rounded = np.round(angles, 9)
    if np.max(np.abs(axis_matrix(rounded, "XYZ") - matrix)) <= 1e-13:
        return rounded
    return angles


def fmt_float(x: float) -> str:
    """Shortest text that reads back to exactly the same float."""
    x = float(x)
    if x == 0.0:
        return "0"
    return repr(x)


# --------------------------------------------------------------------------- layout
@dataclass
class LayoutBone:
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


def safe_name(name: str) -> str:
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


def asf_layout(skel: Skeleton) -> list[LayoutBone]:
    """Map a Skeleton onto ASF bones (root first); see the module docstring."""
    joints = skel.joints
    n = len(joints)
    taken: set[str] = {"root"}
    names = ["root"]
    for j in joints[1:]:
        base = safe_name(j.name)
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
        LayoutBone(
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
                LayoutBone(
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
            LayoutBone(
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
