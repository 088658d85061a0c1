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

import base64
import os
from pathlib import Path

import numpy as np

from ..errors import ParameterError, ParseError
from ..motion import Motion
from ..skeleton import Joint, Skeleton
from ._atomic import atomic_path

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


def skeleton_from_dict(d: dict) -> Skeleton:
    """The skeleton :func:`skeleton_to_dict` described (pygltflib drops empty values)."""
    joints = tuple(
        Joint(
            name=j["name"],
            parent=int(j.get("parent", -1)),
            offset=np.asarray(j.get("offset", (0.0, 0.0, 0.0)), float),
            dofs=tuple(j.get("dofs", ())),
            rotation_order=j.get("rotation_order", ""),
            axis=np.asarray(j.get("axis", np.eye(3)), float),
            end_site=None if j.get("end_site") is None else np.asarray(j["end_site"], float),
            limits={k: tuple(v) for k, v in j.get("limits", {}).items()},
        )
        for j in d["joints"]
    )
    return Skeleton(
        joints,
        name=d.get("name", ""),
        length_unit=float(d.get("length_unit", 1.0)),
        source_format=d.get("source_format", ""),
    )


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
            lo, hi = flat.min(axis=0).tolist(), flat.max(axis=0).tolist()
        if comp != _FLOAT and lo is not None:
            lo, hi = [int(v) for v in lo], [int(v) for v in hi]
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
        Add a skinned stick mesh (one prism per bone).

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


# ------------------------------------------------------------------------------- read
def _load(path: Path):
    import pygltflib as g

    if not path.is_file():
        raise ParseError("no such glTF file", str(path))
    try:
        gltf = g.GLTF2.load(str(path))
    except Exception as exc:  # noqa: BLE001 - pygltflib raises assorted errors on bad files
        raise ParseError(
            f"not a readable glTF file ({type(exc).__name__}: {exc})", str(path)
        ) from None
    if gltf is None:
        raise ParseError("not a readable glTF file", str(path))
    buffers = []
    for k, b in enumerate(gltf.buffers):
        if b.uri is None:
            data = gltf.binary_blob()
        elif b.uri.startswith("data:"):
            data = base64.b64decode(b.uri.split(",", 1)[1])
        else:
            f = path.parent / b.uri
            if not f.is_file():
                raise ParseError(f"buffer {k}: missing file {b.uri}", str(path))
            data = f.read_bytes()
        if data is None or len(data) < b.byteLength:
            raise ParseError(f"buffer {k} holds fewer than its {b.byteLength} bytes", str(path))
        buffers.append(data)
    return gltf, buffers


_NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
_DTYPE = {
    5126: np.float32,
    5123: np.uint16,
    5125: np.uint32,
    5121: np.uint8,
    5122: np.int16,
    5120: np.int8,
}


def _accessor(gltf, buffers, index: int) -> np.ndarray:
    """The values ``(count, components)`` of accessor ``index`` as floats."""
    acc = gltf.accessors[index]
    if acc.sparse is not None or acc.bufferView is None:
        raise ParseError(f"accessor {index}: sparse or view-less accessors are not supported")
    view = gltf.bufferViews[acc.bufferView]
    dtype = np.dtype(_DTYPE[acc.componentType]).newbyteorder("<")
    ncomp = _NCOMP[acc.type]
    start = (view.byteOffset or 0) + (acc.byteOffset or 0)
    width = dtype.itemsize * ncomp
    stride = view.byteStride or width
    data = buffers[view.buffer]
    if acc.count and start + stride * (acc.count - 1) + width > len(data):
        raise ParseError(f"accessor {index} runs past the end of buffer {view.buffer}")
    if stride == width:
        out = np.frombuffer(data, dtype=dtype, count=acc.count * ncomp, offset=start)
    else:
        raw = np.frombuffer(data, dtype=np.uint8)
        rows = [raw[start + k * stride : start + k * stride + width] for k in range(acc.count)]
        out = np.frombuffer(b"".join(r.tobytes() for r in rows), dtype=dtype)
    out = out.reshape(acc.count, ncomp)
    if acc.normalized and dtype.kind in "iu":
        out = out / np.iinfo(dtype).max
    return out.astype(float)


def _sample(
    times: np.ndarray, values: np.ndarray, interp: str, at: np.ndarray, quat: bool
) -> np.ndarray:
    if interp == "CUBICSPLINE":
        values = values.reshape(len(times), 3, -1)[:, 1]
    if interp == "STEP":
        k = np.clip(np.searchsorted(times, at + 1e-9, side="right") - 1, 0, len(times) - 1)
        return values[k]
    out = np.stack([np.interp(at, times, values[:, c]) for c in range(values.shape[1])], axis=1)
    if quat:
        out /= np.linalg.norm(out, axis=1, keepdims=True)
    return out


def _node_tracks(gltf, buffers, anim_index: int = 0):
    """Local translations ``(T, N, 3)`` and rotation matrices ``(T, N, 3, 3)`` of every node,
    sampled at the animation's frame rate, and that rate."""
    from scipy.spatial.transform import Rotation

    extras = (gltf.extras or {}).get(_EXTRAS_KEY, {}) if isinstance(gltf.extras, dict) else {}
    N = len(gltf.nodes)
    anim = gltf.animations[anim_index] if gltf.animations else None
    inputs = (
        [] if anim is None else [_accessor(gltf, buffers, s.input)[:, 0] for s in anim.samplers]
    )
    if extras.get("fps"):
        fps = float(extras["fps"])
    elif inputs and max(len(t) for t in inputs) > 1:
        longest = max(inputs, key=len)
        fps = float((len(longest) - 1) / (longest[-1] - longest[0]))
        if abs(fps - round(fps)) < 1e-4 * fps:  # float32 key times: 120.0001 -> 120
            fps = float(round(fps))
    else:
        fps = 30.0
    end = max((float(t[-1]) for t in inputs), default=0.0)
    T = int(extras.get("frames") or round(end * fps) + 1)
    at = np.arange(T) / fps
    trans = np.empty((T, N, 3))
    quats = np.empty((T, N, 4))
    for k, node in enumerate(gltf.nodes):
        if node.matrix is not None and node.matrix != [
            1,
            0,
            0,
            0,
            0,
            1,
            0,
            0,
            0,
            0,
            1,
            0,
            0,
            0,
            0,
            1,
        ]:
            m = np.asarray(node.matrix, float).reshape(4, 4).T
            trans[:, k] = m[:3, 3]
            quats[:, k] = Rotation.from_matrix(m[:3, :3]).as_quat()
        else:
            trans[:, k] = node.translation if node.translation is not None else (0, 0, 0)
            quats[:, k] = node.rotation if node.rotation is not None else (0, 0, 0, 1)
    if anim is not None:
        for ch in anim.channels:
            if ch.target.node is None or ch.target.path not in ("translation", "rotation"):
                continue
            s = anim.samplers[ch.sampler]
            vals = _accessor(gltf, buffers, s.output)
            times = inputs[ch.sampler]
            quat = ch.target.path == "rotation"
            sampled = _sample(times, vals, s.interpolation or "LINEAR", at, quat)
            (quats if quat else trans)[:, ch.target.node] = sampled
    rots = Rotation.from_quat(quats.reshape(-1, 4)).as_matrix().reshape(T, N, 3, 3)
    return trans, rots, fps


def _tracks(gltf, buffers, path: Path):
    """:func:`_node_tracks`, with malformed files reported as one ParseError naming ``path``."""
    try:
        return _node_tracks(gltf, buffers)
    except ParseError as exc:
        if exc.path is None:
            raise ParseError(exc.message, str(path)) from None
        raise
    except (IndexError, KeyError, TypeError, ValueError) as exc:
        raise ParseError(
            f"malformed glTF animation ({type(exc).__name__}: {exc})", str(path)
        ) from None


def _joint_nodes(gltf) -> tuple[list[int], list[int]]:
    """Node indices of the skeleton (skin joints, else every node without a mesh) in an order
    where parents come first, and each one's parent position in that list (-1 at roots)."""
    parent = {c: k for k, node in enumerate(gltf.nodes) for c in (node.children or [])}
    if gltf.skins:
        members = set(gltf.skins[0].joints)
    else:
        members = {k for k, node in enumerate(gltf.nodes) if node.mesh is None}
    roots = [k for k in sorted(members) if parent.get(k) not in members]
    order: list[int] = []
    stack = list(reversed(roots))
    while stack:
        k = stack.pop()
        order.append(k)
        stack.extend(reversed([c for c in (gltf.nodes[k].children or []) if c in members]))
    pos = {k: i for i, k in enumerate(order)}
    return order, [pos.get(parent.get(k), -1) for k in order]


def gltf_joint_positions(path: str | os.PathLike[str]) -> tuple[list[str], np.ndarray, float]:
    """World positions of the skeleton's nodes computed from the glTF's own nodes and animation.

    Returns
    -------
    names : list of str
        Node names (joints, then end sites in hierarchy order).
    positions : ndarray, shape (T, J, 3)
        In the file's units (metres) and axes (y up), sampled at the animation's rate.
    fps : float
    """
    from .._kinematics import global_transforms

    p = Path(path)
    gltf, buffers = _load(p)
    trans, rots, fps = _tracks(gltf, buffers, p)
    order, parents = _joint_nodes(gltf)
    pos, _ = global_transforms(trans[:, order], rots[:, order], np.asarray(parents))
    return [gltf.nodes[k].name or f"node{k}" for k in order], pos, fps


def read_gltf(path: str | os.PathLike[str]) -> Motion:
    """Read a glTF 2.0 skeleton animation (``.glb`` or ``.gltf``) as a :class:`Motion`.

    A file written by :func:`write_gltf` gives back the original skeleton, channels and
    units; any other file gives one joint per skeleton node (skin joints when there is a
    skin) with ``rx ry rz`` rotations (order ``ZYX``) and ``tx ty tz`` on the root and on
    nodes whose translation is animated, lengths in metres.
    """
    from .._kinematics import channels_from_local

    p = Path(path)
    gltf, buffers = _load(p)
    if not gltf.nodes:
        raise ParseError("the file holds no nodes (no skeleton to read)", str(p))
    trans, rots, fps = _tracks(gltf, buffers, p)
    extras = gltf.extras.get(_EXTRAS_KEY) if isinstance(gltf.extras, dict) else None
    if extras and "skeleton" in extras:
        skel = skeleton_from_dict(extras["skeleton"])
        by_name = {node.name: k for k, node in enumerate(gltf.nodes)}
        missing = [j.name for j in skel.joints if j.name not in by_name]
        if missing:
            raise ParseError(f"joints {missing[:3]} of the stored skeleton have no node", str(p))
        cols = [by_name[j.name] for j in skel.joints]
        scale = float(extras.get("scale", 1.0))
        trans, rots = trans[:, cols] / scale, rots[:, cols]
        if "up_rotation" in extras:  # undo the turn that made the file y-up
            up = np.asarray(extras["up_rotation"], dtype=float)
            trans[:, 0] = trans[:, 0] @ up
            rots[:, 0] = np.einsum("ba,tbc->tac", up, rots[:, 0])
        frames = channels_from_local(skel, trans, rots)
        motion = Motion(
            frames,
            skel.channels,
            fps=fps,
            skeleton=skel,
            source=str(p),
            start_frame=int(extras.get("start_frame", 0)),
        )
        wanted = [tuple(c) for c in extras.get("channels", [])]
        if wanted and set(wanted) == set(motion.channels):
            motion = motion.select(wanted)
        return motion
    order, parents = _joint_nodes(gltf)
    animated = set()
    if gltf.animations:
        animated = {
            c.target.node for c in gltf.animations[0].channels if c.target.path == "translation"
        }
    joints = []
    for i, (k, par) in enumerate(zip(order, parents)):
        dofs: tuple[str, ...] = ("rx", "ry", "rz")
        if par < 0 or k in animated:
            dofs = ("tx", "ty", "tz") + dofs
        name = gltf.nodes[k].name or f"node{k}"
        joints.append(Joint(name, par, trans[0, k], dofs, "ZYX"))
    skel = Skeleton(tuple(joints), name=p.stem, source_format="gltf")
    frames = channels_from_local(skel, trans[:, order], rots[:, order])
    return Motion(frames, skel.channels, fps=fps, skeleton=skel, source=str(p))
