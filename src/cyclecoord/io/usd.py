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

import json
import os
from pathlib import Path

import numpy as np

from ..errors import ParameterError, ParseError
from ..motion import Motion
from ..skeleton import Joint, Skeleton
from ._atomic import atomic_path
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


def _open(path: Path):
    _Gf, _Sdf, _Tf, Usd, _UsdGeom, UsdSkel, _Vt = require_usd()
    if not path.is_file():
        raise ParseError("no such USD file", str(path))
    try:
        stage = Usd.Stage.Open(str(path))
    except Exception as exc:  # noqa: BLE001 - pxr raises Tf errors of its own types
        raise ParseError(f"not a readable USD file ({exc})".splitlines()[0], str(path)) from None
    skel_prim = next((p for p in stage.Traverse() if p.IsA(UsdSkel.Skeleton)), None)
    if skel_prim is None:
        raise ParseError("no UsdSkel Skeleton prim in the stage", str(path))
    skel = UsdSkel.Skeleton(skel_prim)
    query = UsdSkel.Cache().GetSkelQuery(skel)
    if not query:
        raise ParseError(f"skeleton {skel_prim.GetPath()} is not valid", str(path))
    start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
    fps = stage.GetTimeCodesPerSecond()
    times = np.arange(round(start), round(end) + 1)
    return stage, skel_prim, query, times, fps


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


def read_usd(path: str | os.PathLike[str]) -> Motion:
    """Read the first UsdSkel skeleton of a stage and its animation as a :class:`Motion`.

    A stage written by :func:`write_usd` gives back the original skeleton and channels;
    another gives one joint per USD joint with ``rx ry rz`` rotations (order ``ZYX``),
    ``tx ty tz`` on root joints, lengths in the stage's units.
    """
    from .._kinematics import channels_from_local

    p = Path(path)
    _stage, prim, query, times, fps = _open(p)  # loads usd-core (require_usd)
    from pxr import Usd
    local = np.array(
        [np.array(query.ComputeJointLocalTransforms(Usd.TimeCode(float(t)))) for t in times]
    )  # (T, J, 4, 4), row vectors
    trans = local[..., 3, :3]
    rots = np.swapaxes(local[..., :3, :3], -1, -2)
    meta = prim.GetCustomDataByKey(_KEY)
    if meta:
        info = json.loads(meta)
        skel = skeleton_from_dict(info["skeleton"])
        n = len(skel.joints)
        frames = channels_from_local(skel, trans[:, :n], rots[:, :n])
        motion = Motion(
            frames,
            skel.channels,
            fps=fps,
            skeleton=skel,
            source=str(p),
            start_frame=int(info.get("start_frame", 0)),
        )
        wanted = [tuple(c) for c in info.get("channels", [])]
        return motion.select(wanted) if wanted and set(wanted) == set(motion.channels) else motion
    order = list(query.GetJointOrder())
    topo = query.GetTopology()
    joints = []
    for i, jp in enumerate(order):
        par = int(topo.GetParent(i))
        dofs = ("rx", "ry", "rz") if par >= 0 else ("tx", "ty", "tz", "rx", "ry", "rz")
        joints.append(
            Joint(
                str(jp).rsplit("/", 1)[-1] if par >= 0 else str(jp), par, trans[0, i], dofs, "ZYX"
            )
        )
    skel = Skeleton(tuple(joints), name=p.stem, source_format="usd")
    frames = channels_from_local(skel, trans, rots)
    return Motion(frames, skel.channels, fps=fps, skeleton=skel, source=str(p))
