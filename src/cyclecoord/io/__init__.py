"""Motion file input/output: ``load``/``save``/``convert`` dispatching on the file suffix.

Supported formats: ``.amc`` (Acclaim motion, with its ``.asf`` skeleton), ``.bvh``
(Biovision Hierarchy), ``.npz`` (NumPy archive of a whole motion and skeleton), ``.csv``
(a ``joint.dof`` table), ``.glb``/``.gltf`` (glTF 2.0, :mod:`~cyclecoord.io.gltf`) and
``.usda``/``.usdc``/``.usd`` (UsdSkel through the optional usd-core,
:mod:`~cyclecoord.io.usd`).  The per-format readers and writers are re-exported here; the
ASF/AMC, glTF and USD ones are imported on first use.

The helpers every writer of the package uses live here too: :func:`atomic_write` /
:func:`atomic_path` (an output appears whole or not at all: it is written beside the
target and renamed over it), :class:`StagedOutputs` (every output of a run moved into
place together at the end, so an interrupted run changes none) and :func:`refuse_clobber`
/ :func:`input_files` / :func:`same_file` (no output is written over an input, however the
paths are spelled).
Import them from ``cyclecoord.io``; their modules ``_atomic`` and ``_paths`` are private.
"""

from __future__ import annotations

import math
import os
import re
import tempfile
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import ParameterError, ParseError
from ..motion import DEFAULT_FPS, Motion
from ..skeleton import Skeleton
from ._atomic import StagedOutputs, atomic_path, atomic_write
from ._limits import MAX_FPS
from ._paths import input_files, refuse_clobber, same_file
from .bvh import read_bvh, write_bvh
from .tabular import read_csv, read_npz, write_csv, write_npz

__all__ = [
    "load",
    "save",
    "convert",
    "SUPPORTED_FORMATS",
    "default_asf_path",
    "read_bvh",
    "write_bvh",
    "read_npz",
    "write_npz",
    "read_csv",
    "write_csv",
    "read_asf",
    "write_asf",
    "read_amc",
    "write_amc",
    "read_gltf",
    "write_gltf",
    "read_usd",
    "write_usd",
    "atomic_write",
    "atomic_path",
    "StagedOutputs",
    "refuse_clobber",
    "input_files",
    "same_file",
]

#: Suffix -> description, in the order error messages list them.
SUPPORTED_FORMATS = {
    ".amc": "Acclaim AMC motion (skeleton from an .asf)",
    ".bvh": "Biovision Hierarchy",
    ".npz": "NumPy archive written by cyclecoord",
    ".csv": "CSV table with a joint.dof header",
    ".glb": "glTF 2.0 binary",
    ".gltf": "glTF 2.0 JSON with a .bin beside it",
    ".usda": "USD (UsdSkel) text, needs usd-core",
    ".usdc": "USD (UsdSkel) binary crate, needs usd-core",
    ".usd": "USD (UsdSkel), crate encoding, needs usd-core",
}
_LAZY = {
    "read_asf": "asfamc",
    "write_asf": "asfamc",
    "read_amc": "asfamc",
    "write_amc": "asfamc",
    "read_gltf": "gltf",
    "write_gltf": "gltf",
    "read_usd": "usd",
    "write_usd": "usd",
}
_GLTF = (".glb", ".gltf")
_USD = (".usda", ".usdc", ".usd")


def __getattr__(name: str) -> Any:
    """Import the ASF/AMC, glTF and USD functions on first access (PEP 562)."""
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _formats() -> str:
    return ", ".join(SUPPORTED_FORMATS)


def _suffix(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix not in SUPPORTED_FORMATS:
        shown = f"suffix {path.suffix!r}" if path.suffix else "no suffix"
        raise ParseError(
            f"unknown motion format ({shown}); supported formats: {_formats()}", str(path)
        )
    return suffix


def _check_fps(fps: float | None) -> float | None:
    if fps is None:
        return None
    try:
        value = float(fps)
    except (TypeError, ValueError):
        raise ParameterError(f"fps must be a positive number, got {fps!r}") from None
    if not (value > 0 and value != float("inf")):
        raise ParameterError(f"fps must be a positive number, got {fps!r}")
    return value


def load(
    path: str | os.PathLike[str],
    skeleton: Skeleton | str | os.PathLike[str] | None = None,
    fps: float | None = None,
) -> Motion:
    """Read a motion file of any supported format, chosen by its suffix.

    Parameters
    ----------
    path : path-like
        ``.amc``, ``.bvh``, ``.npz``, ``.csv``, ``.glb``/``.gltf`` or ``.usda``/``.usdc``/``.usd``
        (case-insensitive suffix).
    skeleton : Skeleton or path, optional
        For AMC: the skeleton or ``.asf`` path (passed to
        :func:`~cyclecoord.io.asfamc.read_amc`).  For NPZ/CSV: attached to (or replacing
        the stored skeleton of) the motion.  Not allowed for BVH, which carries its own.
    fps : float, optional
        Overrides the file's frame rate (AMC files store none: 120 by default).

    Returns
    -------
    Motion

    Raises
    ------
    ParseError
        Missing file, unknown suffix (the message lists the supported formats) or a
        malformed file.
    ParameterError
        Bad ``fps`` or a ``skeleton`` given for a BVH file.
    """
    p = Path(path)
    suffix = _suffix(p)
    if not p.exists():
        raise ParseError(f"no such file (supported formats: {_formats()})", str(p))
    if p.is_dir():
        raise ParseError(f"is a directory, expected a motion file ({_formats()})", str(p))
    rate = _check_fps(fps)
    if suffix in _GLTF + _USD:
        if skeleton is not None:
            raise ParameterError(
                f"{p}: a {suffix} file carries its own skeleton; do not pass skeleton="
            )
        if suffix in _GLTF:
            from .gltf import read_gltf as reader
        else:
            from .usd import read_usd as reader
        motion = reader(p)
        return motion if rate is None else replace(motion, fps=rate)
    if suffix == ".amc":
        from .asfamc import read_amc

        if rate is None:
            rate = _amc_written_rate(p)
        return read_amc(p, skeleton=skeleton, fps=DEFAULT_FPS if rate is None else rate)
    if suffix == ".bvh":
        if skeleton is not None:
            raise ParameterError(
                f"{p}: a BVH file carries its own skeleton; a skeleton (--skeleton on the "
                "command line, skeleton= in Python) is only for AMC, NPZ and CSV inputs"
            )
        motion = read_bvh(p)
        return motion if rate is None else replace(motion, fps=rate)
    if suffix == ".npz":
        return read_npz(p, skeleton=skeleton, fps=rate)
    return read_csv(p, fps=rate, skeleton=skeleton)


def default_asf_path(amc_path: str | os.PathLike[str]) -> Path:
    """Where :func:`save` puts the skeleton of an AMC by default.

    ``<subject>.asf`` beside the AMC, the subject being the stem up to its first ``_``
    (``69_01.amc`` -> ``69.asf``, ``out.amc`` -> ``out.asf``): the name
    :func:`~cyclecoord.io.asfamc.read_amc` looks for when no skeleton is given.
    """
    p = Path(amc_path)
    subject = p.stem.split("_", 1)[0] or p.stem
    return p.with_name(subject + ".asf")


def _same_skeleton(a: Skeleton, b: Skeleton, tol: float = 1e-9) -> bool:
    """Same joints, hierarchy, dofs, orders, offsets, axes and end sites."""
    if len(a.joints) != len(b.joints) or abs(a.length_unit - b.length_unit) > tol:
        return False
    for ja, jb in zip(a.joints, b.joints):
        if (ja.name, ja.parent, ja.dofs, ja.rotation_order) != (
            jb.name,
            jb.parent,
            jb.dofs,
            jb.rotation_order,
        ):
            return False
        if not (np.allclose(ja.offset, jb.offset, rtol=0, atol=tol)
                and np.allclose(ja.axis, jb.axis, rtol=0, atol=tol)):
            return False
        if (ja.end_site is None) != (jb.end_site is None):
            return False
        if ja.end_site is not None and not np.allclose(ja.end_site, jb.end_site, rtol=0, atol=tol):
            return False
    return True


def _can_reuse_asf(asf: Path, skeleton: Skeleton) -> bool:
    """Whether the existing ``asf`` already describes ``skeleton`` (so need not be written)."""
    from .asfamc import read_asf, write_asf

    try:
        if _same_skeleton(read_asf(asf), skeleton):
            return True
    except ParseError:
        pass
    with tempfile.TemporaryDirectory() as tmp:
        fresh = Path(tmp) / asf.name
        write_asf(skeleton, fresh)
        try:
            return fresh.read_bytes() == asf.read_bytes()
        except OSError:
            return False


def _check_kwargs(suffix: str, kwargs: dict, allowed: tuple[str, ...]) -> None:
    unknown = sorted(set(kwargs) - set(allowed))
    if unknown:
        ok = ", ".join(allowed) if allowed else "none"
        raise ParameterError(
            f"unknown option(s) {unknown} for saving {suffix}; allowed: {ok}"
        )


#: The comment :func:`save` writes in an AMC whose rate is not CMU's 120 Hz.
_AMC_RATE = re.compile(r"^#\s*frame rate ([0-9.eE+]+) fps \(cyclecoord\)\s*$", re.M)


def _amc_written_rate(path: Path) -> float | None:
    """The frame rate an AMC written by :func:`save` names in its header comment, or None
    (AMC files carry no rate of their own)."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096).decode("latin-1")
    except OSError:
        return None  # read_amc says what is wrong with the file
    head = head.split(":FULLY-SPECIFIED")[0]
    found = _AMC_RATE.search(head)
    if found is None:
        return None
    try:
        rate = float(found.group(1))
    except ValueError:
        return None
    return rate if math.isfinite(rate) and 0 < rate <= MAX_FPS else None


def _acclaim_ready(motion: Motion) -> Motion:
    """A motion of another rig written as ASF/AMC: in its analysis rig and with its unit.

    An ASF has one root with position channels and bones that only turn, lengths in the
    unit ``:units length`` names.  A BVH rig with a static root above the travelling hips
    or constant position channels on its joints (the Bandai layout), or with Z up, is
    written as :func:`cyclecoord.rig.normalize_rig` reads it (the same joint positions,
    Y up), and the skeleton's length unit is the one :func:`cyclecoord.rig.describe_rig`
    found (a centimetre rig is ``length 2.54``: read back in centimetres, not inches).  An
    ASF skeleton, or a motion without one, is written as it is."""
    skel = motion.skeleton
    if skel is None or skel.source_format == "asf" or motion.n_frames < 2:
        return motion
    import dataclasses

    from ..rig import describe_rig, normalize_rig

    try:
        with np.errstate(all="ignore"):
            info = describe_rig(motion)
    except (ParameterError, ValueError, FloatingPointError):  # a rig too odd to read
        return motion
    if info.static_root or info.constant_position_joints or info.up_axis == "Z":
        motion, _ = normalize_rig(motion, info, drop_reference=False)
        skel = motion.skeleton
    if info.units_source != "given" and not (np.isfinite(info.metres_per_unit)
                                             and info.metres_per_unit > 0):
        return motion
    unit = 0.0254 / info.metres_per_unit  # ASF: inches = value / length
    return dataclasses.replace(motion, skeleton=dataclasses.replace(skel, length_unit=unit))


def _amc_default_skeleton(motion: Motion, amc_path: Path) -> Path | None:
    """Where :func:`save` writes the skeleton of an AMC at ``amc_path`` when no
    ``asf_path`` is given: :func:`default_asf_path`, or None when an equal skeleton is
    already there.  A different skeleton there is never overwritten (ParameterError)."""
    asf = default_asf_path(amc_path)
    if asf.exists() and _can_reuse_asf(asf, motion.skeleton):
        return None
    if asf.exists():
        raise ParameterError(
            f"{asf} already exists and holds a different skeleton; pass asf_path= "
            "to choose where this motion's skeleton goes (the existing file may "
            "belong to other AMC files and is not overwritten)"
        )
    return asf


def save(motion: Motion, path: str | os.PathLike[str], **kwargs: Any) -> None:
    """Write a motion in the format given by the suffix of ``path``.

    Parameters
    ----------
    motion : Motion
        The motion to write.
    path : path-like
        Any suffix of :data:`SUPPORTED_FORMATS`.
    **kwargs
        Per format:

        * ``.amc``: ``asf_path`` (where the skeleton goes, always written; default
          :func:`default_asf_path`, e.g. ``out.amc`` -> ``out.asf``,
          ``69_01.amc`` -> ``69.asf``) and ``write_skeleton`` (default True; False
          writes the AMC alone).  The ASF is written only when the motion has a
          skeleton.  An existing file at the default place is never overwritten: if it
          already describes the motion's skeleton it is reused, otherwise
          :class:`ParameterError` asks for ``asf_path``.
        * ``.bvh``: ``rotation_order`` (see :func:`~cyclecoord.io.bvh.write_bvh`).
        * ``.glb``, ``.gltf``: ``scale`` (metres per length unit) and ``mesh`` (see
          :func:`~cyclecoord.io.gltf.write_gltf`).
        * ``.usda``, ``.usdc``, ``.usd``: ``meters_per_unit`` (see
          :func:`~cyclecoord.io.usd.write_usd`).
        * ``.npz``, ``.csv``: none.
        * every format: ``lock_feet`` (default False): pin planted feet first with
          :func:`~cyclecoord.synthesis.footlock.lock_feet` (needs a skeleton).

    Raises
    ------
    ParseError
        Unknown suffix (the message lists the supported formats).
    ParameterError
        Unknown options, or a motion the format cannot hold (e.g. BVH without a
        skeleton).
    """
    p = Path(path)
    suffix = _suffix(p)
    if kwargs.pop("lock_feet", False):
        from ..synthesis.footlock import lock_feet

        motion = lock_feet(motion).motion
    if suffix in _GLTF:
        _check_kwargs(suffix, kwargs, ("scale", "mesh"))
        from .gltf import write_gltf

        write_gltf(motion, p, **kwargs)
        return
    if suffix in _USD:
        _check_kwargs(suffix, kwargs, ("meters_per_unit",))
        from .usd import write_usd

        write_usd(motion, p, **kwargs)
        return
    if suffix == ".amc":
        _check_kwargs(suffix, kwargs, ("asf_path", "write_skeleton"))
        from .asfamc import write_amc

        motion = _acclaim_ready(motion)

        asf = kwargs.get("asf_path")
        if motion.skeleton is None or not kwargs.get("write_skeleton", True):
            if asf is not None and motion.skeleton is None:
                raise ParameterError("asf_path given but the motion has no skeleton")
            write_amc(motion, p)
            return
        if asf is not None:
            asf = Path(asf)
            if asf.resolve() == p.resolve():
                raise ParameterError(f"asf_path {asf} is the AMC output itself")
            write_amc(motion, p, skeleton_path=asf)
            return
        asf = _amc_default_skeleton(motion, p)
        if asf is None:
            # an equivalent skeleton is already there (e.g. the one the motion was
            # read with): leave it untouched and write only the AMC
            write_amc(motion, p)
            return
        write_amc(motion, p, skeleton_path=asf)
    elif suffix == ".bvh":
        _check_kwargs(suffix, kwargs, ("rotation_order",))
        write_bvh(motion, p, **kwargs)
    elif suffix == ".npz":
        _check_kwargs(suffix, kwargs, ())
        write_npz(motion, p)
    else:
        _check_kwargs(suffix, kwargs, ())
        write_csv(motion, p)


def convert(
    src: str | os.PathLike[str],
    dst: str | os.PathLike[str],
    skeleton: Skeleton | str | os.PathLike[str] | None = None,
    fps: float | None = None,
    **kwargs: Any,
) -> Motion:
    """Load ``src`` and save it as ``dst`` (formats from the suffixes).

    Parameters
    ----------
    src, dst : path-like
        Input and output files; they must differ (inputs are never modified).
    skeleton, fps
        As for :func:`load`.
    **kwargs
        As for :func:`save`.

    Returns
    -------
    Motion
        The motion as loaded from ``src``.
    """
    s, d = Path(src), Path(dst)
    _suffix(d)  # fail on an unknown output format before reading anything
    for src in input_files(s, skeleton if isinstance(skeleton, (str, os.PathLike)) else None):
        if same_file(src, d):
            raise ParameterError(f"{d}: convert would overwrite its input {src}")
    motion = load(s, skeleton=skeleton, fps=fps)
    save(motion, d, **kwargs)
    return motion
