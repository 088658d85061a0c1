"""glTF 2.0 export and import (``.glb`` and ``.gltf`` + ``.bin``) of a motion with a skeleton.

The container (JSON, buffers, GLB chunks) is pygltflib's; the skeleton and animation are
built here:

* one node per joint (and per end site, named ``<joint>_end``) whose rest translation is
  the joint's offset and whose rest rotation is the identity (an ASF rest pose);
* one animation sampled at the motion's frame rate (``LINEAR``), with a translation
  channel for every joint that has translation degrees of freedom (the root) and a
  rotation channel for every joint, quaternions in glTF's ``(x, y, z, w)`` order made
  continuous in sign;
* a skin over those nodes and, optionally, a stick mesh (one square prism per bone,
  skinned rigidly to it) so viewers that show only meshes show the figure;
* every accessor with ``min``/``max``, every buffer view 4-byte aligned.

glTF lengths are metres and its up axis is y: an ASF skeleton (CMU: ``:units length 0.45``,
1/0.45 inch a unit) is scaled by ``0.0254 / length_unit``; other skeletons by the metres
per unit :func:`cyclecoord.rig.describe_rig` finds from the body's height (a centimetre,
millimetre or inch BVH comes out at its real size) unless ``scale`` is given; a Z-up rig
has its root turned by :data:`cyclecoord.rig.Z_TO_Y`.  The scale, that rotation, the frame
rate and the original skeleton (axes, degrees of freedom, rotation orders, limits) are
kept in the file's ``extras`` so :func:`read_gltf` gives back the motion's own channels.
A glTF from elsewhere is read with three rotation degrees of
freedom per joint (``rx ry rz``, order ``ZYX``) and translations on animated nodes.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ..skeleton import Joint, Skeleton
from ._atomic import atomic_path
from ._limits import MAX_JOINTS, skeleton_problem

__all__ = ["default_scale", "gltf_joint_positions", "read_gltf", "write_gltf"]

_EXTRAS_KEY = "cyclecoord"
_FLOAT, _UINT16, _UINT32 = 5126, 5123, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963


def default_scale(skeleton: Skeleton) -> float:
    """Metres per skeleton length unit from the skeleton alone: ``0.0254 / length_unit`` for
    ASF, else 1.  Exports measure the unit of other skeletons instead
    (:func:`cyclecoord.rig.metres_per_unit`)."""
    if skeleton.source_format == "asf" and skeleton.length_unit > 0:
        return 0.0254 / skeleton.length_unit
    return 1.0


def check_exportable(motion: Motion, what: str) -> Skeleton:
    """The skeleton of a motion that can be exported, or one clear ParameterError."""
    name = motion.source or "motion"
    if motion.skeleton is None:
        raise ParameterError(
            f"{name}: {what} export needs a skeleton; this motion has none "
            "(load it from ASF/AMC, BVH or an .npz with a skeleton)"
        )
    if motion.n_frames < 1:
        raise ParameterError(f"{name}: no frames to write")
    bad = np.flatnonzero(~np.isfinite(motion.frames).all(axis=1))
    if bad.size:
        raise ParameterError(
            f"{name}: frame {motion.start_frame + int(bad[0])} holds NaN or infinite values "
            f"({bad.size} such frames); nothing written"
        )
    return motion.skeleton


# ------------------------------------------------------------------ skeleton <-> json
def skeleton_to_dict(skel: Skeleton) -> dict:
    """A JSON-able description of a skeleton (for ``extras``)."""
    return {
        "name": skel.name,
        "length_unit": skel.length_unit,
        "source_format": skel.source_format,
        "joints": [
            {
                "name": j.name,
                "parent": j.parent,
                "offset": j.offset.tolist(),
                "dofs": list(j.dofs),
                "rotation_order": j.rotation_order,
                "axis": j.axis.tolist(),
                "end_site": None if j.end_site is None else j.end_site.tolist(),
                "limits": {k: list(v) for k, v in j.limits.items()},
            }
            for j in skel.joints
        ],
    }


def skeleton_from_dict(d: dict, where: str = "skeleton") -> Skeleton:
    """The skeleton :func:`skeleton_to_dict` described (pygltflib drops empty values).

    Every entry is checked for its type and range (names, parents before children, finite
    offsets, rotation axes, known degrees of freedom, limits, at most
    :data:`~._limits.MAX_JOINTS` joints): a problem raises :class:`~._checked.Invalid`
    naming the entry under ``where`` (``skeleton.joints[3].offset``).
    """
    from ..skeleton import DOF_NAMES
    from ._checked import Invalid, mapping, number, numbers, sequence, text, whole

    d = mapping(d, where)
    items = sequence(d.get("joints"), f"{where}.joints", MAX_JOINTS)
    if not items:
        raise Invalid(f"{where}.joints: a skeleton needs at least one joint")
    joints = []
    for i, j in enumerate(items):
        at = f"{where}.joints[{i}]"
        j = mapping(j, at)
        parent = whole(j.get("parent", -1), f"{at}.parent", -1, i - 1)
        dofs = tuple(text(x, f"{at}.dofs") for x in sequence(j.get("dofs", ()), f"{at}.dofs", 6))
        unknown = [x for x in dofs if x not in DOF_NAMES]
        if unknown or len(set(dofs)) != len(dofs):
            raise Invalid(f"{at}.dofs: {list(dofs)} are not distinct ones of {' '.join(DOF_NAMES)}")
        limits = {}
        for k, v in mapping(j.get("limits", {}), f"{at}.limits").items():
            if k not in DOF_NAMES:
                raise Invalid(f"{at}.limits: {k!r} is not one of {' '.join(DOF_NAMES)}")
            lo, hi = numbers(v, (2,), f"{at}.limits.{k}", allow_inf=True)
            limits[k] = (float(lo), float(hi))
        end = j.get("end_site")
        try:
            joints.append(
                Joint(
                    name=text(j.get("name"), f"{at}.name", 1000),
                    parent=parent,
                    offset=numbers(j.get("offset", (0.0, 0.0, 0.0)), (3,), f"{at}.offset"),
                    dofs=dofs,
                    rotation_order=text(j.get("rotation_order", ""), f"{at}.rotation_order", 3),
                    axis=numbers(j.get("axis", np.eye(3).tolist()), (3, 3), f"{at}.axis"),
                    end_site=None if end is None else numbers(end, (3,), f"{at}.end_site"),
                    limits=limits,
                )
            )
        except ParameterError as exc:
            raise Invalid(f"{at}: {exc}") from None
    try:
        skel = Skeleton(
            tuple(joints),
            name=text(d.get("name", ""), f"{where}.name", 1000),
            length_unit=number(d.get("length_unit", 1.0), f"{where}.length_unit", 1e-300),
            source_format=text(d.get("source_format", ""), f"{where}.source_format", 100),
        )
    except ParameterError as exc:
        raise Invalid(f"{where}: {exc}") from None
    problem = skeleton_problem(skel)
    if problem is not None:
        raise Invalid(f"{where}: {problem}")
    return skel


# --------------------------------------------------------------------- buffer building
class _Blob:
    """Accumulates buffer views and accessors into one 4-byte aligned binary buffer."""

    def __init__(self, gltf) -> None:
        self.gltf = gltf
        self.data = bytearray()

    def add(self, array: np.ndarray, kind: str, target: int | None = None) -> int:
        import pygltflib as g

        array = np.ascontiguousarray(array)
        comp = {
            np.dtype(np.float32): _FLOAT,
            np.dtype(np.uint16): _UINT16,
            np.dtype(np.uint32): _UINT32,
        }[array.dtype]
        while len(self.data) % 4:
            self.data.append(0)
        offset = len(self.data)
        self.data += array.tobytes()
        self.gltf.bufferViews.append(
            g.BufferView(buffer=0, byteOffset=offset, byteLength=array.nbytes, target=target)
        )
        flat = array.reshape(array.shape[0], -1)
        if kind == "MAT4":
            lo = hi = None
        else:
            # tolist() gives Python floats for float32 and Python ints for the integer
            # types: the JSON min/max are of the accessor's own kind as they are
            lo, hi = flat.min(axis=0).tolist(), flat.max(axis=0).tolist()
        self.gltf.accessors.append(
            g.Accessor(
                bufferView=len(self.gltf.bufferViews) - 1,
                componentType=comp,
                count=int(array.shape[0]),
                type=kind,
                min=lo,
                max=hi,
            )
        )
        return len(self.gltf.accessors) - 1

    def finish(self) -> bytes:
        while len(self.data) % 4:
            self.data.append(0)
        return bytes(self.data)


def _continuous_quaternions(q: np.ndarray) -> np.ndarray:
    """Flip signs so consecutive quaternions ``(T, 4)`` lie in one hemisphere."""
    q = q.copy()
    for t in range(1, q.shape[0]):
        if np.dot(q[t], q[t - 1]) < 0:
            q[t] = -q[t]
    return q


def _stick_mesh(rest: np.ndarray, bones: list[tuple[int, int]], radius: float):
    """Vertices, joint indices and triangles of square prisms along ``bones`` (a, b)."""
    verts, joints, tris = [], [], []
    for owner, (a, b) in bones:
        p, q = rest[a], rest[b]
        d = q - p
        length = float(np.linalg.norm(d))
        if length < 1e-9:
            continue
        d /= length
        helper = np.array([1.0, 0, 0]) if abs(d[0]) < 0.9 else np.array([0, 1.0, 0])
        u = np.cross(d, helper)
        u /= np.linalg.norm(u)
        v = np.cross(d, u)
        r = min(radius, 0.25 * length)
        ring = [r * (np.cos(k * np.pi / 2) * u + np.sin(k * np.pi / 2) * v) for k in range(4)]
        base = len(verts)
        verts += [p + o for o in ring] + [q + o for o in ring]
        joints += [owner] * 8
        for k in range(4):
            k2 = (k + 1) % 4
            tris += [(base + k, base + k2, base + 4 + k2), (base + k, base + 4 + k2, base + 4 + k)]
        tris += [
            (base, base + 2, base + 1),
            (base, base + 3, base + 2),
            (base + 4, base + 5, base + 6),
            (base + 4, base + 6, base + 7),
        ]
    return np.array(verts), np.array(joints), np.array(tris)


# ------------------------------------------------------------------------------ write
def _build(motion: Motion, scale: float, mesh: bool, up: np.ndarray):
    """The pygltflib document and its binary buffer; ``up`` (3, 3) turns the root."""
    import pygltflib as g

    from .._kinematics import local_transforms
    from ..skeleton import forward_kinematics

    skel = motion.skeleton
    trans, rots = local_transforms(motion)
    turned = not np.array_equal(up, np.eye(3))
    if turned:  # the root's transform premultiplied: the file is y-up
        trans[:, 0] = trans[:, 0] @ up.T
        rots[:, 0] = np.einsum("ab,tbc->tac", up, rots[:, 0])
    T, n = trans.shape[:2]
    gltf = g.GLTF2(asset=g.Asset(version="2.0", generator="cyclecoord"))
    blob = _Blob(gltf)

    # nodes: joints, then end sites
    children: list[list[int]] = [[] for _ in range(n)]
    for i, j in enumerate(skel.joints):
        gltf.nodes.append(g.Node(name=j.name, translation=(j.offset * scale).tolist()))
        if j.parent >= 0:
            children[j.parent].append(i)
    end_parent = []
    for i, j in enumerate(skel.joints):
        if j.end_site is not None:
            children[i].append(len(gltf.nodes))
            end_parent.append(i)
            gltf.nodes.append(
                g.Node(name=f"{j.name}_end", translation=(j.end_site * scale).tolist())
            )
    for i, ch in enumerate(children):
        if ch:
            gltf.nodes[i].children = ch
    gltf.nodes[0].translation = (trans[0, 0] * scale).tolist()  # where the capture starts
    n_nodes = len(gltf.nodes)

    # animation
    times = (np.arange(T) / motion.fps).astype(np.float32)
    t_acc = blob.add(times, "SCALAR")
    samplers, channels = [], []
    from scipy.spatial.transform import Rotation

    for i, j in enumerate(skel.joints):
        if any(d.startswith("t") for d in j.dofs):
            acc = blob.add((trans[:, i] * scale).astype(np.float32), "VEC3")
            samplers.append(g.AnimationSampler(input=t_acc, output=acc, interpolation="LINEAR"))
            channels.append(
                g.AnimationChannel(
                    sampler=len(samplers) - 1,
                    target=g.AnimationChannelTarget(node=i, path="translation"),
                )
            )
        q = _continuous_quaternions(Rotation.from_matrix(rots[:, i]).as_quat())  # x y z w
        acc = blob.add(q.astype(np.float32), "VEC4")
        samplers.append(g.AnimationSampler(input=t_acc, output=acc, interpolation="LINEAR"))
        channels.append(
            g.AnimationChannel(
                sampler=len(samplers) - 1, target=g.AnimationChannelTarget(node=i, path="rotation")
            )
        )
    anim_name = Path(motion.source).stem if motion.source else "motion"
    gltf.animations.append(g.Animation(name=str(anim_name), samplers=samplers, channels=channels))

    # skin over every node; bind pose = rest pose with the root at the origin
    rest_motion = motion.with_frames(np.zeros((1, motion.n_channels)))
    rest = forward_kinematics(rest_motion).positions[0] * scale  # joints then end sites
    ibm = np.tile(np.eye(4), (n_nodes, 1, 1))
    ibm[:, :3, 3] = -rest
    if turned:  # bind pose turned with the root: inverse of T(up @ rest) @ up
        ibm[:, :3, :3] = up.T
        rest = rest @ up.T
        gltf.nodes[0].rotation = Rotation.from_matrix(up).as_quat().tolist()
    ibm_acc = blob.add(ibm.transpose(0, 2, 1).reshape(n_nodes, 16).astype(np.float32), "MAT4")
    gltf.skins.append(
        g.Skin(
            name=skel.name or "skeleton",
            joints=list(range(n_nodes)),
            skeleton=0,
            inverseBindMatrices=ibm_acc,
        )
    )
    scene_nodes = [0]
    if mesh:
        bones = [(j.parent, (j.parent, i)) for i, j in enumerate(skel.joints) if j.parent >= 0]
        bones += [(p, (p, n + k)) for k, p in enumerate(end_parent)]
        radius = 0.01 * skel.total_length() * scale
        verts, vj, tris = _stick_mesh(rest, bones, radius)
        if len(verts):
            attrs = g.Attributes(
                POSITION=blob.add(verts.astype(np.float32), "VEC3", _ARRAY_BUFFER),
                JOINTS_0=blob.add(
                    np.stack([vj, 0 * vj, 0 * vj, 0 * vj], 1).astype(np.uint16),
                    "VEC4",
                    _ARRAY_BUFFER,
                ),
                WEIGHTS_0=blob.add(
                    np.tile([1.0, 0, 0, 0], (len(verts), 1)).astype(np.float32),
                    "VEC4",
                    _ARRAY_BUFFER,
                ),
            )
            idx = blob.add(tris.reshape(-1).astype(np.uint32), "SCALAR", _ELEMENT_ARRAY_BUFFER)
            gltf.meshes.append(
                g.Mesh(name="sticks", primitives=[g.Primitive(attributes=attrs, indices=idx)])
            )
            gltf.nodes.append(g.Node(name="sticks", mesh=0, skin=0))
            scene_nodes.append(len(gltf.nodes) - 1)
    gltf.scenes.append(g.Scene(name=skel.name or "scene", nodes=scene_nodes))
    gltf.scene = 0
    gltf.extras = {
        _EXTRAS_KEY: {
            "fps": motion.fps,
            "frames": T,
            "scale": scale,
            **({"up_rotation": up.tolist()} if turned else {}),
            "start_frame": motion.start_frame,
            "source": motion.source,
            "channels": [list(c) for c in motion.channels],
            "skeleton": skeleton_to_dict(skel),
        }
    }
    data = blob.finish()
    gltf.buffers.append(g.Buffer(byteLength=len(data)))
    return gltf, data


def write_gltf(
    motion: Motion,
    path: str | os.PathLike[str],
    *,
    scale: float | None = None,
    mesh: bool = True,
) -> None:
    """Write a motion with a skeleton as glTF 2.0.

    Parameters
    ----------
    motion : Motion
        Frames, skeleton and frame rate to write.
    path : path-like
        ``.glb`` (one binary file) or ``.gltf`` (JSON, with its buffer in a ``.bin`` of
        the same stem beside it).  Written atomically: on any error nothing is left.
    scale : float, optional
        Metres per skeleton length unit; default ``0.0254 / length_unit`` for ASF, else
        measured (:func:`cyclecoord.rig.metres_per_unit`).
    mesh : bool, default True
        Add a skinned stick mesh: one square prism per bone, its corners 1 % of the
        skeleton's total bone length from the bone (at most a quarter of the bone's length).

    Raises
    ------
    ParameterError
        No skeleton, non-finite frames, a bad scale or suffix.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in (".glb", ".gltf"):
        raise ParameterError(
            f"{p}: glTF files end in .glb or .gltf, got {p.suffix or '(no suffix)'!r}"
        )
    from ..rig import Z_TO_Y, describe_rig

    check_exportable(motion, "glTF")
    if scale is not None and not (np.isfinite(float(scale)) and float(scale) > 0):
        raise ParameterError(f"scale must be a positive number of metres per unit, got {scale!r}")
    info = describe_rig(motion, "auto" if scale is None else float(scale))
    s = info.metres_per_unit
    up = Z_TO_Y if info.up_axis == "Z" else np.eye(3)
    gltf, data = _build(motion, s, mesh, up)
    if suffix == ".glb":
        gltf.set_binary_blob(data)
        with atomic_path(p, suffix=".glb") as tmp:
            if not gltf.save_binary(str(tmp)):
                raise ParameterError(f"{p}: pygltflib could not write the GLB")
        return
    binp = p.with_suffix(".bin")
    gltf.buffers[0].uri = binp.name
    with atomic_path(binp, suffix=".bin") as tbin, atomic_path(p, suffix=".gltf") as tj:
        tbin.write_bytes(data)
        tj.write_text(gltf.gltf_to_json(), encoding="utf-8")


# the reader lives in gltf_read (imported last: it imports this module's helpers lazily)
from .gltf_read import gltf_joint_positions, read_gltf  # noqa: E402
