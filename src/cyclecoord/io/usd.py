"""USD export and import of a motion as a UsdSkel skeleton and animation.

Files: ``.usda`` (text), ``.usdc`` and ``.usd`` (binary crate).

Needs the optional ``usd-core`` package (``pip install cyclecoord[usd]``); it is imported
inside the functions so the rest of cyclecoord works without it.

The stage holds ``/Motion`` (a ``SkelRoot``), ``/Motion/Skeleton`` (a ``Skeleton``: one
joint per joint of ours and per end site, ``restTransforms`` = the rest offsets,
``bindTransforms`` = the rest pose in world space) and ``/Motion/Skeleton/Animation`` (a
``SkelAnimation`` with translations, rotations and scales of every joint at every frame,
one time code per frame).  Lengths stay in the skeleton's units with ``metersPerUnit``
saying what they are (``0.0254 / length_unit`` for an ASF skeleton, otherwise what
:func:`cyclecoord.rig.describe_rig` measures from the body's height), ``upAxis`` is the
rig's (Y, or Z for a Z-up rig) and ``timeCodesPerSecond`` the motion's frame rate.  The
original skeleton and channels are kept in the skeleton prim's ``customData`` so
:func:`read_usd` returns the motion's own channels.
"""

from __future__ import annotations

import contextlib
import functools
import io
import json
import os
import re
import sys
import tempfile
import threading
from pathlib import Path

import numpy as np

from ..errors import ParameterError, ParseError
from ..motion import Motion
from ..skeleton import Joint, Skeleton
from ._atomic import atomic_path
from ._limits import MAX_MAGNITUDE
from .gltf import check_exportable, skeleton_from_dict, skeleton_to_dict

__all__ = ["USD_SUFFIXES", "read_usd", "usd_joint_positions", "write_usd", "require_usd"]

USD_SUFFIXES = (".usda", ".usdc", ".usd")
_KEY = "cyclecoord"


def require_usd():
    """The usd-core modules (Gf, Sdf, Tf, Usd, UsdGeom, UsdSkel, Vt), or one clear
    ParameterError saying how to install them.

    Ctrl-C is held back while they load and raised once they have: usd-core catches a
    ``KeyboardInterrupt`` raised while it post-processes its modules, prints it as a
    warning and goes on (see ``cyclecoord._signals``).
    """
    from .._signals import deferred_interrupt

    try:
        with deferred_interrupt():
            from pxr import Gf, Sdf, Tf, Usd, UsdGeom, UsdSkel, Vt
    except ImportError:
        raise ParameterError(
            "USD files need the optional usd-core package: pip install 'cyclecoord[usd]'"
        ) from None
    return Gf, Sdf, Tf, Usd, UsdGeom, UsdSkel, Vt


def _joint_paths(skel: Skeleton, Tf) -> tuple[list[str], list[str], list[int]]:
    """USD joint paths (joints then end sites), original names, and parent indices."""
    ids: list[str] = []
    used: set[str] = set()
    for j in list(skel.joints) + [j for j in skel.joints if j.end_site is not None]:
        base = Tf.MakeValidIdentifier(j.name if len(ids) < len(skel.joints) else j.name + "_end")
        name, k = base, 1
        while name in used:
            k += 1
            name = f"{base}_{k}"
        used.add(name)
        ids.append(name)
    n = len(skel.joints)
    parents = [j.parent for j in skel.joints]
    names = [j.name for j in skel.joints]
    for j_index, j in enumerate(skel.joints):
        if j.end_site is not None:
            parents.append(j_index)
            names.append(f"{j.name}/end")
    paths: list[str] = []
    for i, p in enumerate(parents):
        paths.append(ids[i] if p < 0 else f"{paths[p]}/{ids[i]}")
    assert len(paths) == n + sum(j.end_site is not None for j in skel.joints)
    return paths, names, parents


def _matrices(trans: np.ndarray, rots: np.ndarray) -> np.ndarray:
    """USD (row-vector) 4x4 matrices ``(..., 4, 4)`` from translations and rotations."""
    m = np.zeros(trans.shape[:-1] + (4, 4))
    m[..., :3, :3] = np.swapaxes(rots, -1, -2)
    m[..., 3, :3] = trans
    m[..., 3, 3] = 1.0
    return m


def _interrupt_held(func):
    """``func`` with Ctrl-C held back until it returns, then raised
    (:func:`cyclecoord._signals.deferred_interrupt`): usd-core runs Python code from C++
    while it loads its modules and plugins (also lazily, at the first stage a fresh
    install opens) and can swallow a ``KeyboardInterrupt`` raised there; in a new virtual
    environment a Ctrl-C during ``convert x.bvh -o x.usda`` was lost (exit 0) after the
    modules had loaded."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        from .._signals import deferred_interrupt

        with deferred_interrupt():
            return func(*args, **kwargs)

    return wrapper


@_interrupt_held
def write_usd(
    motion: Motion,
    path: str | os.PathLike[str],
    *,
    meters_per_unit: float | None = None,
) -> None:
    """Write a motion with a skeleton as a UsdSkel skeleton and animation.

    Parameters
    ----------
    motion : Motion
        Frames, skeleton and frame rate to write.
    path : path-like
        ``.usda`` (text), ``.usdc`` or ``.usd`` (binary crate).  Written atomically.
    meters_per_unit : float, optional
        Stage ``metersPerUnit``; default ``0.0254 / length_unit`` for ASF skeletons, else
        measured (:func:`cyclecoord.rig.metres_per_unit`).  The stage's ``upAxis`` is the
        rig's up axis (:func:`cyclecoord.rig.describe_rig`).

    Raises
    ------
    ParameterError
        No skeleton, non-finite frames, a bad suffix, or usd-core missing.
    """
    from scipy.spatial.transform import Rotation

    from .._kinematics import global_transforms, local_transforms

    p = Path(path)
    if p.suffix.lower() not in USD_SUFFIXES:
        raise ParameterError(
            f"{p}: USD files end in {', '.join(USD_SUFFIXES)}, got {p.suffix or '(no suffix)'!r}"
        )
    from ..rig import describe_rig

    skel = check_exportable(motion, "USD")
    if meters_per_unit is not None and not (
        np.isfinite(float(meters_per_unit)) and float(meters_per_unit) > 0
    ):
        raise ParameterError(f"meters_per_unit must be a positive number, got {meters_per_unit!r}")
    info = describe_rig(motion, "auto" if meters_per_unit is None else float(meters_per_unit))
    mpu = info.metres_per_unit
    Gf, _Sdf, Tf, Usd, UsdGeom, UsdSkel, Vt = require_usd()

    trans, rots = local_transforms(motion)
    T, _n = trans.shape[:2]
    ends = [i for i, j in enumerate(skel.joints) if j.end_site is not None]
    paths, names, parents = _joint_paths(skel, Tf)
    # end-site joints: fixed translation, no rotation
    end_t = np.array([skel.joints[i].end_site for i in ends]).reshape(-1, 3)
    trans = np.concatenate([trans, np.broadcast_to(end_t, (T, len(ends), 3))], axis=1)
    rots = np.concatenate([rots, np.broadcast_to(np.eye(3), (T, len(ends), 3, 3))], axis=1)
    rest_t = np.array([j.offset for j in skel.joints] + list(end_t))
    rest_r = np.broadcast_to(np.eye(3), (len(paths), 3, 3))
    bind_p, bind_r = global_transforms(rest_t[None], rest_r[None], np.asarray(parents))

    stage = Usd.Stage.CreateInMemory()
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z if info.up_axis == "Z" else UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, mpu)
    stage.SetTimeCodesPerSecond(motion.fps)
    stage.SetFramesPerSecond(motion.fps)
    stage.SetStartTimeCode(0)
    stage.SetEndTimeCode(T - 1)
    root = UsdSkel.Root.Define(stage, "/Motion")
    stage.SetDefaultPrim(root.GetPrim())
    usd_skel = UsdSkel.Skeleton.Define(stage, "/Motion/Skeleton")
    usd_skel.CreateJointsAttr(Vt.TokenArray(paths))
    usd_skel.CreateJointNamesAttr(Vt.TokenArray(names))
    usd_skel.CreateRestTransformsAttr(Vt.Matrix4dArray.FromNumpy(_matrices(rest_t, rest_r)))
    usd_skel.CreateBindTransformsAttr(Vt.Matrix4dArray.FromNumpy(_matrices(bind_p[0], bind_r[0])))
    usd_skel.GetPrim().SetCustomDataByKey(
        _KEY,
        json.dumps(
            {
                "fps": motion.fps,
                "start_frame": motion.start_frame,
                "source": motion.source,
                "channels": [list(c) for c in motion.channels],
                "skeleton": skeleton_to_dict(skel),
            }
        ),
    )
    anim = UsdSkel.Animation.Define(stage, "/Motion/Skeleton/Animation")
    anim.CreateJointsAttr(Vt.TokenArray(paths))
    t_attr = anim.CreateTranslationsAttr()
    r_attr = anim.CreateRotationsAttr()
    anim.CreateScalesAttr().Set(Vt.Vec3hArray([Gf.Vec3h(1, 1, 1)] * len(paths)))
    q = Rotation.from_matrix(rots.reshape(-1, 3, 3)).as_quat().reshape(T, len(paths), 4)
    wxyz = q[..., [3, 0, 1, 2]].astype(np.float32)
    tf = trans.astype(np.float32)
    for t in range(T):
        t_attr.Set(Vt.Vec3fArray.FromNumpy(tf[t]), Usd.TimeCode(t))
        r_attr.Set(Vt.QuatfArray([Gf.Quatf(*map(float, w)) for w in wxyz[t]]), Usd.TimeCode(t))
    UsdSkel.BindingAPI.Apply(usd_skel.GetPrim()).CreateAnimationSourceRel().SetTargets(
        [anim.GetPath()]
    )
    with atomic_path(p, suffix=p.suffix) as tmp:
        if not stage.GetRootLayer().Export(str(tmp)):
            raise ParameterError(f"{p}: usd-core could not write the stage")


def _why(exc: BaseException) -> str:
    """The message of a usd-core error, without the C++ function, line and source file
    it names first (``Error in 'pxrInternal_...::CrateFile::_ReadX' at line 3472 in file
    .../crateFile.cpp : 'the message'``), on one line of at most 300 characters."""
    why = " ".join(line.strip() for line in str(exc).splitlines() if line.strip())
    why = re.sub(r"^Error in '[^']*' at line \d+ in file \S+ : ", "", why).strip("'")
    return why if len(why) <= 300 else why[:297] + "..."


#: Bytes per joint and frame while a stage is read (local matrices, translations,
#: quaternions, rotation matrices, their copies for the joints, the Euler angles).
_FRAME_JOINT_BYTES = 8 * 64


def _open(path: Path):
    """The stage, its first skeleton prim and query, the integer time codes to read and the
    frame rate, each checked (one ParseError naming the file and what was wrong)."""
    from ._limits import MAX_FPS, MAX_FRAMES, MAX_JOINTS, MIN_FPS, check_memory

    _Gf, Sdf, _Tf, Usd, _UsdGeom, UsdSkel, _Vt = require_usd()
    if not path.is_file():
        raise ParseError("no such USD file", str(path))
    try:
        cached = Sdf.Layer.Find(str(path))  # still held from an earlier read: read it again
        reloaded = cached.Reload(force=True) if cached else True
        stage = Usd.Stage.Open(str(path)) if reloaded else None
    except Exception as exc:  # noqa: BLE001 - pxr raises Tf errors of its own types
        raise ParseError(f"not a readable USD file ({_why(exc)})", str(path)) from None
    if stage is None:  # a failed reload keeps the earlier content: never read that instead
        raise ParseError("not a readable USD file (usd-core could not read it again)", str(path))
    skel_prim = next((p for p in stage.Traverse() if p.IsA(UsdSkel.Skeleton)), None)
    if skel_prim is None:
        raise ParseError("no UsdSkel Skeleton prim in the stage", str(path))
    skel = UsdSkel.Skeleton(skel_prim)
    query = UsdSkel.Cache().GetSkelQuery(skel)
    if not query:
        raise ParseError(f"skeleton {skel_prim.GetPath()} is not valid", str(path))
    n_joints = len(query.GetJointOrder())
    if n_joints == 0:
        raise ParseError(f"skeleton {skel_prim.GetPath()}: the joints array is empty", str(path))
    _check_topology(skel, n_joints, Sdf, path)
    if n_joints > 2 * MAX_JOINTS:  # joints and end sites
        raise ParseError(
            f"skeleton {skel_prim.GetPath()}: {n_joints:,} joints; at most "
            f"{2 * MAX_JOINTS:,} (joints and end sites) are supported",
            str(path),
        )
    start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
    for name, value in (("startTimeCode", start), ("endTimeCode", end)):
        if not np.isfinite(value) or abs(value) > MAX_FRAMES * 100:
            raise ParseError(f"{name} {value} is not a finite time code", str(path))
    if round(end) < round(start):
        raise ParseError(
            f"endTimeCode {end:g} comes before startTimeCode {start:g}", str(path)
        )
    n_frames = round(end) - round(start) + 1
    if n_frames > MAX_FRAMES:
        raise ParseError(
            f"time codes {start:g}..{end:g} are {n_frames:,} frames; at most {MAX_FRAMES:,} "
            "are supported",
            str(path),
        )
    fps = stage.GetTimeCodesPerSecond()
    if not np.isfinite(fps) or not MIN_FPS <= fps <= MAX_FPS:
        raise ParseError(
            f"timeCodesPerSecond {fps!r} is not a frame rate in {MIN_FPS:g}..{MAX_FPS:g}",
            str(path),
        )
    check_memory(
        _FRAME_JOINT_BYTES * n_frames * n_joints,
        f"{n_frames:,} frames of {n_joints:,} joints",
        path,
    )
    times = np.arange(round(start), round(end) + 1)
    return stage, skel_prim, query, times, fps


def _check_topology(skel, n_joints: int, Sdf, path: Path) -> None:
    """Every joint a well-formed path, and the rest and bind transforms one per joint:
    usd-core warns about either and goes on (a hierarchy that is not the file's, identity
    transforms), so a broken skeleton would read as another one."""
    where = skel.GetPrim().GetPath()
    from pxr import Vt

    expected = {"joints": Vt.TokenArray, "restTransforms": Vt.Matrix4dArray,
                "bindTransforms": Vt.Matrix4dArray}
    for name, kind in expected.items():
        # a value authored with another (or an unknown) type reads as one usd-core cannot
        # index or measure (the attribute's declared type is the schema's): refused first
        attr = skel.GetPrim().GetAttribute(name)
        value = attr.Get() if attr and attr.HasAuthoredValue() else None
        if value is not None and not isinstance(value, kind):
            raise ParseError(f"{where}.{name}: a {type(value).__name__} value, not the "
                             f"{kind.__name__} the skeleton needs", str(path))
    for k, token in enumerate(skel.GetJointsAttr().Get() or []):
        if not Sdf.Path.IsValidPathString(str(token)):
            raise ParseError(f"{where}.joints[{k}]: {str(token)[:80]!r} is not a joint path",
                             str(path))
    for name in ("restTransforms", "bindTransforms"):
        attr = skel.GetPrim().GetAttribute(name)
        value = attr.Get() if attr and attr.HasAuthoredValue() else None
        if value is not None and len(value) != n_joints:
            raise ParseError(
                f"{where}.{name}: {len(value)} transforms for the skeleton's {n_joints} joints",
                str(path),
            )


def _slerp(qa: np.ndarray, qb: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(..., 4)`` a fraction ``u`` (broadcast) of the way from ``qa`` to
    ``qb`` along the shorter arc."""
    dot = np.sum(qa * qb, axis=-1, keepdims=True)
    qb = np.where(dot < 0, -qb, qb)
    dot = np.clip(np.abs(dot), 0.0, 1.0)
    theta = np.arccos(dot)
    small = theta < 1e-6
    sin = np.where(small, 1.0, np.sin(theta))
    wa = np.where(small, 1.0 - u, np.sin((1.0 - u) * theta) / sin)
    wb = np.where(small, u, np.sin(u * theta) / sin)
    q = wa * qa + wb * qb
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _check_component_sizes(anim, keys: np.ndarray, path: Path) -> None:
    """One translation, rotation and scale per joint of the animation at every time code
    read: usd-core ignores an animation whose arrays disagree with its joints (a warning,
    then the rest pose), which would read as a motion that never moves."""
    from pxr import Usd

    joints = anim.GetJointsAttr().Get()
    n = len(joints) if joints is not None else 0
    for name in ("translations", "rotations", "scales"):
        attr = anim.GetPrim().GetAttribute(name)
        if not attr or not attr.HasAuthoredValue():
            continue
        for t in keys:
            value = attr.Get(Usd.TimeCode(float(t)))
            if value is None:
                continue
            try:
                got = len(value)
            except TypeError:
                raise ParseError(
                    f"{anim.GetPath()}.{name} at time code {t:g}: not an array", str(path)
                ) from None
            if got != n:
                raise ParseError(
                    f"{anim.GetPath()}.{name} at time code {t:g}: {got} values for the "
                    f"animation's {n} joints",
                    str(path),
                )


def _local_transforms(query, times: np.ndarray, path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Local translations ``(T, J, 3)`` and rotations ``(T, J, 3, 3)`` of every joint at the
    integer time codes ``times``.

    usd-core computes them at the animation's own time samples (and the first and last
    time code); between samples the translations are interpolated linearly and the
    rotations along the shorter arc, as USD interpolates them.  The authored rotations
    must be finite unit quaternions and every local transform a rotation and a
    translation (no scale), checked before anything is decomposed.  Samples outside
    ``times[0] .. times[-1]`` are not part of the motion: neither read nor checked.
    """
    from pxr import Usd, UsdSkel
    from scipy.spatial.transform import Rotation

    J = len(query.GetJointOrder())
    lo, hi = float(times[0]), float(times[-1])
    aq = query.GetAnimQuery()
    samples = [float(t) for t in (aq.GetJointTransformTimeSamples() if aq else [])]
    keys = np.unique(np.array([lo, hi] + [t for t in samples if lo <= t <= hi and np.isfinite(t)]))
    if aq:
        anim = UsdSkel.Animation(aq.GetPrim())
        if anim:
            _check_component_sizes(anim, keys, path)
        rot_attr = anim.GetRotationsAttr() if anim else None
        kind = str(rot_attr.GetTypeName()) if rot_attr else ""
        if rot_attr and kind not in ("quatf[]", "quath[]", "quatd[]"):
            raise ParseError(
                f"{anim.GetPath()}.rotations is of type {kind[:40]}, not an array of quaternions",
                str(path),
            )
        for t in keys if rot_attr else ():
            raw = rot_attr.Get(Usd.TimeCode(float(t)))
            if raw is None:
                continue
            try:
                q = np.array(raw, dtype=float).reshape(-1, 4)
            except (TypeError, ValueError):
                raise ParseError(
                    f"{anim.GetPath()}.rotations at time code {t:g}: not an array of "
                    "quaternions",
                    str(path),
                ) from None
            bad = ~np.isfinite(q).all(axis=1)
            length = np.linalg.norm(np.where(np.isfinite(q), q, 0.0), axis=1)
            bad |= np.abs(length - 1.0) > 1e-3
            if bad.any():
                j = int(np.argmax(bad))
                raise ParseError(
                    f"{anim.GetPath()}.rotations at time code {t:g}: joint {j} holds "
                    f"{q[j].tolist()}, not a unit quaternion",
                    str(path),
                )
    trans = np.empty((len(keys), J, 3))
    quats = np.empty((len(keys), J, 4))
    order = list(query.GetJointOrder())
    for k, t in enumerate(keys):
        m = np.array(query.ComputeJointLocalTransforms(Usd.TimeCode(float(t))), dtype=float)
        if m.shape != (J, 4, 4):
            raise ParseError(
                f"time code {t:g}: usd-core gives {m.shape[0] if m.ndim else 0} joint transforms "
                f"for the skeleton's {J} joints",
                str(path),
            )
        r = np.swapaxes(m[:, :3, :3], -1, -2)
        ok = np.isfinite(m).all(axis=(1, 2))
        with np.errstate(invalid="ignore"):
            err = np.abs(r @ np.swapaxes(r, -1, -2) - np.eye(3)).max(axis=(1, 2))
            ok &= (err < 1e-3) & (np.linalg.det(np.where(ok[:, None, None], r, np.eye(3))) > 0)
            ok &= np.abs(m[:, 3, :3]).max(axis=1) <= MAX_MAGNITUDE
        if not ok.all():
            j = int(np.argmin(ok))
            raise ParseError(
                f"time code {t:g}: joint {order[j]}: the animation's transform is not a finite "
                "rotation and translation (a scale, or values that are not numbers)",
                str(path),
            )
        trans[k] = m[:, 3, :3]
        u, _, vt = np.linalg.svd(r)
        quats[k] = Rotation.from_matrix(u @ vt).as_quat()
    if len(keys) == len(times) and np.array_equal(keys, times):
        rots = Rotation.from_quat(quats.reshape(-1, 4)).as_matrix().reshape(len(times), J, 3, 3)
        return trans, rots
    # here times holds two time codes or more (one was returned above: keys == [lo]), so
    # keys holds lo < hi at least and every segment has two ends
    seg = np.clip(np.searchsorted(keys, times, side="right") - 1, 0, len(keys) - 2)
    u = ((times - keys[seg]) / (keys[seg + 1] - keys[seg]))[:, None, None]
    tr = trans[seg] + u * (trans[seg + 1] - trans[seg])
    q = _slerp(quats[seg], quats[seg + 1], u)
    rots = Rotation.from_quat(q.reshape(-1, 4)).as_matrix().reshape(len(times), J, 3, 3)
    return tr, rots


@contextlib.contextmanager
def _held_stderr():
    """Hold back what is written to standard error in the body, on the Python side and on
    file descriptor 2 (usd-core's C++ code prints there directly: a failed ``madvise``,
    a value it cannot convert).  Yields a list that gets the held text; the caller
    decides whether to print it.  Only on the main thread (file descriptor 2 belongs to
    the whole process); elsewhere nothing is held."""
    held: list[str] = []
    if threading.current_thread() is not threading.main_thread():
        yield held
        return
    with tempfile.TemporaryFile() as fh:
        try:
            sys.stderr.flush()
            saved = os.dup(2)
        except (OSError, ValueError, AttributeError):  # no usable descriptor 2
            yield held
            return
        py_err = io.StringIO()
        os.dup2(fh.fileno(), 2)
        try:
            with contextlib.redirect_stderr(py_err):
                yield held
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            fh.seek(0)
            held.append(py_err.getvalue() + fh.read().decode("utf-8", "replace"))


def _refusing(func):
    """``func(path)``, a reader, with what usd-core does on a damaged stage turned into one
    ParseError naming the file: names it cannot give as text (invalid UTF-8 in a joint
    path, a token or customData) and the errors it raises when a corrupt crate's values
    are read (found then, not when the stage opens).  What usd-core prints meanwhile
    (warnings on sizes that disagree or joints out of order, C++ messages) is not shown
    with a refusal, whose one line says what was wrong; after a read that succeeds, or
    an error of another kind, it is printed as usual."""

    @functools.wraps(func)
    def wrapper(path):
        Tf = require_usd()[2]
        trap = getattr(Tf, "DiagnosticTrap", None)  # usd-core 25.2 and later
        refused = False
        held: list[str] = []
        try:
            # the trap closes first: the warnings it reposts are held too
            with _held_stderr() as held, (
                trap() if trap is not None else contextlib.nullcontext()
            ) as caught:
                try:
                    return func(path)
                except ParseError:
                    refused = True
                    raise
                except UnicodeDecodeError as exc:
                    refused = True
                    raise ParseError(
                        f"holds a name or text that is not UTF-8 ({exc.reason} at byte "
                        f"{exc.start})",
                        str(path),
                    ) from None
                except Exception as exc:
                    if not type(exc).__module__.startswith("pxr"):
                        raise
                    refused = True
                    raise ParseError(
                        f"not a readable USD file ({_why(exc)})", str(path)
                    ) from None
                finally:
                    if caught is not None and refused:
                        caught.Clear()
        finally:
            if not refused and held and held[0]:
                sys.stderr.write(held[0])
                sys.stderr.flush()

    return wrapper


@_interrupt_held
@_refusing
def usd_joint_positions(path: str | os.PathLike[str]) -> tuple[list[str], np.ndarray, float]:
    """Joint positions ``(T, J, 3)`` computed by usd-core (``ComputeJointSkelTransforms``).

    In the stage's units; names are the skeleton's ``jointNames`` (end sites
    ``<joint>/end``) when present, else the joint paths.
    """
    _stage, prim, query, times, fps = _open(Path(path))
    from pxr import Usd, UsdSkel

    skel = UsdSkel.Skeleton(prim)
    names = list(skel.GetJointNamesAttr().Get() or query.GetJointOrder())
    pos = np.array(
        [
            np.array(query.ComputeJointSkelTransforms(Usd.TimeCode(float(t))))[:, 3, :3]
            for t in times
        ]
    )
    return names, pos, fps


def _custom_data(prim, path: Path) -> dict | None:
    """Our ``customData`` entry of the skeleton prim, checked (None when there is none)."""
    from ._checked import Invalid, mapping, sequence, text, whole
    from ._limits import MAX_FRAME_NUMBER, MAX_JOINTS, metadata_problem

    meta = prim.GetCustomDataByKey(_KEY)
    if meta is None:
        return None
    where = f"customData.{_KEY}"
    try:
        raw = text(meta, where, 2**31)
        problem = metadata_problem(raw)
        if problem is not None:
            raise Invalid(f"{where}: {problem}")
        try:
            info = json.loads(raw)
        except (ValueError, RecursionError) as exc:
            raise Invalid(f"{where}: not valid JSON ({str(exc)[:100]})") from None
        info = mapping(info, where)
        out: dict = {"skeleton": skeleton_from_dict(info.get("skeleton"), f"{where}.skeleton")}
        out["start_frame"] = whole(
            info.get("start_frame", 0), f"{where}.start_frame", 0, MAX_FRAME_NUMBER
        )
        pairs = []
        for k, c in enumerate(sequence(info.get("channels", []), f"{where}.channels",
                                       6 * MAX_JOINTS)):
            c = sequence(c, f"{where}.channels[{k}]", 2)
            if len(c) != 2:
                raise Invalid(f"{where}.channels[{k}]: expected [joint, dof]")
            pairs.append(tuple(text(x, f"{where}.channels[{k}]", 1000) for x in c))
        out["channels"] = pairs
    except Invalid as exc:
        raise ParseError(str(exc), str(path)) from None
    return out


@_interrupt_held
@_refusing
def read_usd(path: str | os.PathLike[str]) -> Motion:
    """Read the first UsdSkel skeleton of a stage and its animation as a :class:`Motion`.

    A stage written by :func:`write_usd` gives back the original skeleton and channels;
    another gives one joint per USD joint with ``rx ry rz`` rotations (order ``ZYX``),
    ``tx ty tz`` on root joints, lengths in the stage's units.

    Raises
    ------
    ParseError
        One line naming the file and what was wrong: no skeleton or an empty joints
        array, time codes that are not finite or not ordered, more frames than
        ``MAX_FRAMES`` or than the memory limit allows, rotations that are
        not unit quaternions, a ``customData`` entry that is not the JSON this writer
        stores.
    """
    from .._kinematics import channels_from_local
    from ._limits import frames_problem, skeleton_problem

    p = Path(path)
    _stage, prim, query, times, fps = _open(p)  # loads usd-core (require_usd)
    trans, rots = _local_transforms(query, times, p)
    info = _custom_data(prim, p)
    if info is not None:
        skel = info["skeleton"]
        n = len(skel.joints)
        if n > trans.shape[1]:
            raise ParseError(
                f"customData.{_KEY}.skeleton has {n} joints, the stage's skeleton "
                f"{trans.shape[1]}",
                str(p),
            )
        frames = channels_from_local(skel, trans[:, :n], rots[:, :n])
    else:
        order = list(query.GetJointOrder())
        topo = query.GetTopology()
        joints = []
        try:
            for i, jp in enumerate(order):
                par = int(topo.GetParent(i))
                dofs = ("rx", "ry", "rz") if par >= 0 else ("tx", "ty", "tz", "rx", "ry", "rz")
                name = str(jp).rsplit("/", 1)[-1] if par >= 0 else str(jp)
                joints.append(Joint(name, par, trans[0, i], dofs, "ZYX"))
            skel = Skeleton(tuple(joints), name=p.stem, source_format="usd")
        except ParameterError as exc:
            raise ParseError(f"skeleton {prim.GetPath()}: {exc}", str(p)) from None
        problem = skeleton_problem(skel)
        if problem is not None:
            raise ParseError(f"skeleton {prim.GetPath()}: {problem}", str(p))
        frames = channels_from_local(skel, trans, rots)
    problem = frames_problem(frames, skel.channels)
    if problem is not None:
        raise ParseError(f"the animation gives {problem}", str(p))
    motion = Motion(
        frames,
        skel.channels,
        fps=fps,
        skeleton=skel,
        source=str(p),
        start_frame=0 if info is None else info["start_frame"],
    )
    wanted = [] if info is None else info["channels"]
    return motion.select(wanted) if wanted and set(wanted) == set(motion.channels) else motion
