"""Writing Acclaim ASF skeletons and AMC motions (conventions and the mapping of non-ASF
skeletons in :mod:`cyclecoord.io.asfamc`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..motion import DEFAULT_FPS, Motion
from ..skeleton import Skeleton
from ._acclaim import (
    PathLike,
    asf_layout,
    axis_angles,
    fmt_float,
)
from ._atomic import atomic_write
from ._limits import (
    MAX_MAGNITUDE,
    check_writable,
    skeleton_problem,
)

__all__ = ["write_asf", "write_amc"]


# --------------------------------------------------------------------------- ASF write
def _asf_text(skel: Skeleton) -> str:
    if not isinstance(skel, Skeleton):
        raise ParameterError(f"expected a Skeleton, got {type(skel).__name__}")
    # the length unit, every offset, end site and axis: positive, finite, within
    # MAX_MAGNITUDE, rotations; so every layout vector (a difference of two of them) and
    # axis below is finite
    problem = skeleton_problem(skel)
    if problem is not None:
        raise ParameterError(f"cannot write ASF: skeleton: {problem}")
    unit = float(skel.length_unit)
    layout = asf_layout(skel)
    for b in layout:
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
        f"  length {fmt_float(unit)}",
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
        "  position " + " ".join(fmt_float(x) for x in root.position),
        "  orientation " + " ".join(fmt_float(x) for x in axis_angles(root.axis)),
        ":bonedata",
    ]
    for k, b in enumerate(layout[1:], start=1):
        length = float(np.linalg.norm(b.vector))
        direction = b.vector / length if length > 0 else np.array([0.0, 0.0, 1.0])
        out += [
            "  begin",
            f"    id {k}",
            f"    name {b.asf_name}",
            "    direction " + " ".join(fmt_float(x) for x in direction),
            f"    length {fmt_float(length)}",
            "    axis " + " ".join(fmt_float(x) for x in axis_angles(b.axis)) + " XYZ",
        ]
        if b.dofs:
            out.append("    dof " + " ".join(b.dofs))
            if b.limits:
                pairs = [
                    f"({fmt_float(b.limits[d][0])} {fmt_float(b.limits[d][1])})" for d in b.dofs
                ]
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
        values written with full (round-trip exact) precision.  AMC has no frame rate:
        a motion's rate is named in a ``# frame rate ... fps (cyclecoord)`` header
        comment (read back by :func:`cyclecoord.load`) unless it is CMU's 120 Hz to
        within 1e-9 fps.
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
    check_writable(motion, path, "AMC")  # frames and channels present, every value finite
    frames = np.asarray(motion.frames, dtype=float)
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
        by_joint = {b.joint: b for b in asf_layout(skel) if b.joint is not None}
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
    if abs(float(motion.fps) - DEFAULT_FPS) > 1e-9:  # AMC has no rate; CMU's is 120 Hz
        out.append(f"# frame rate {fmt_float(float(motion.fps))} fps (cyclecoord)")
    out += [":FULLY-SPECIFIED", ":DEGREES"]
    for t, row in enumerate(data.tolist(), start=1):
        strs = [fmt_float(x) for x in row]
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
