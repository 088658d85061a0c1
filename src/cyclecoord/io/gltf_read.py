"""glTF 2.0 import (``.glb`` and ``.gltf`` + ``.bin``): :func:`read_gltf` and
:func:`gltf_joint_positions` (re-exported by :mod:`cyclecoord.io.gltf`, which writes).

Everything read is checked before it is used: accessor, buffer view and buffer indices and
byte ranges, one parent per node and no cycle, the depth, key times finite and increasing,
the resampled frame count and the memory it needs, rotations unit quaternions, and the
``extras`` the writer keeps; each refusal is one ParseError naming the file and the entry.
"""

from __future__ import annotations

import base64
import os
from pathlib import Path

import numpy as np

from ..errors import ParameterError, ParseError
from ..motion import Motion
from ..skeleton import Joint, Skeleton
from ._limits import MAX_JOINTS, MAX_MAGNITUDE, skeleton_problem

__all__ = ["gltf_joint_positions", "read_gltf"]

_NCOMP = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
_DTYPE = {
    5126: np.float32,
    5123: np.uint16,
    5125: np.uint32,
    5121: np.uint8,
    5122: np.int16,
    5120: np.int8,
}
#: Nodes a document may hold (joints, end sites, meshes and what else a scene has).
MAX_NODES = 4 * MAX_JOINTS
#: Accessors, buffer views, buffers, skins, samplers or channels a document may hold.
MAX_ITEMS = 1_000_000
#: How far a stored quaternion's length may be from 1 (float32 and normalised integers).
UNIT_TOLERANCE = 1e-3
#: Bytes a loaded document takes per byte of file (the bytes, the JSON and its objects).
_LOAD_BYTES_PER_BYTE = 6
#: Bytes per sampled node and frame while the tracks are built (translations, quaternions,
#: rotation matrices, their copies for the joints, the Euler angles).
_TRACK_BYTES = 8 * 48


def _check_nodes(gltf) -> dict[int, int]:
    """Every node's fields checked, and each child's parent; one parent each, no cycle, at
    most :data:`~._limits.MAX_DEPTH` levels."""
    import pygltflib as g

    from ._checked import Invalid, numbers, sequence, text, whole
    from ._limits import MAX_DEPTH

    nodes = sequence(gltf.nodes, "nodes", MAX_NODES)
    n = len(nodes)
    parent: dict[int, int] = {}
    for k, node in enumerate(nodes):
        at = f"nodes[{k}]"
        if not isinstance(node, g.Node):
            raise Invalid(f"{at}: expected an object")
        if node.name is not None:
            text(node.name, f"{at}.name", 1000)
        if node.mesh is not None:
            whole(node.mesh, f"{at}.mesh", 0, MAX_ITEMS)
        if node.translation is not None:
            numbers(node.translation, (3,), f"{at}.translation")
        if node.rotation is not None:
            q = numbers(node.rotation, (4,), f"{at}.rotation")
            _unit_quaternions(q[None], f"{at}.rotation")
        if node.matrix is not None:
            _node_matrix(numbers(node.matrix, (16,), f"{at}.matrix"), f"{at}.matrix")
        for c in sequence(node.children if node.children is not None else [], f"{at}.children", n):
            c = whole(c, f"{at}.children", 0, n - 1)
            if c in parent or c == k:
                other = parent.get(c, k)
                raise Invalid(
                    f"{at}.children: node {c} is already a child of node {other}; a node has "
                    "one parent"
                )
            parent[c] = k
    depth: dict[int, int] = {}
    for k in range(n):
        chain = []
        j = k
        while j not in depth and j in parent:
            chain.append(j)
            if len(chain) > n:
                raise Invalid(f"nodes[{k}]: its ancestors form a cycle")
            j = parent[j]
        base = depth.get(j, 0)
        for m, j2 in enumerate(reversed(chain), start=1):
            depth[j2] = base + m
        depth.setdefault(k, 0)
        if depth[k] > MAX_DEPTH:
            raise Invalid(
                f"nodes[{k}]: {depth[k]} levels below its root; at most {MAX_DEPTH} are supported"
            )
    return parent


def _unit_quaternions(q: np.ndarray, where: str) -> np.ndarray:
    """Quaternions ``(K, 4)``, finite and of length 1 within :data:`UNIT_TOLERANCE`,
    normalised."""
    from ._checked import Invalid

    if not np.all(np.isfinite(q)):
        k = int(np.argmax(~np.isfinite(q).all(axis=1)))
        raise Invalid(f"{where}: quaternion {k} holds {q[k].tolist()}, not finite numbers")
    length = np.linalg.norm(q, axis=1)
    off = np.abs(length - 1.0) > UNIT_TOLERANCE
    if off.any():
        k = int(np.argmax(off))
        raise Invalid(
            f"{where}: quaternion {k} has length {length[k]:.6g}; a rotation is a unit "
            "quaternion"
        )
    return q / length[:, None]


def _node_matrix(m: np.ndarray, where: str) -> tuple[np.ndarray, np.ndarray] | None:
    """The translation and rotation of a node's column-major ``matrix`` (16 numbers), or
    ``None`` for the identity; a uniform scale is divided out, shear refused."""
    from ._checked import Invalid

    if np.array_equal(m, np.eye(4).ravel()):
        return None
    mat = m.reshape(4, 4).T
    if not np.allclose(mat[3], [0, 0, 0, 1]):
        raise Invalid(f"{where}: the last row is not 0 0 0 1 (not an affine transform)")
    r = mat[:3, :3]
    det = float(np.linalg.det(r))
    if not np.isfinite(det) or det <= 1e-12:
        raise Invalid(f"{where}: determinant {det:.6g}; expected a rotation (and a scale)")
    r = r / np.cbrt(det)
    if np.max(np.abs(r @ r.T - np.eye(3))) > UNIT_TOLERANCE:
        raise Invalid(f"{where}: not a rotation with a uniform scale (shear or uneven scale)")
    u, _, vt = np.linalg.svd(r)
    return mat[:3, 3].copy(), u @ vt


def _buffers(gltf, path: Path) -> list[bytes]:
    """The bytes of every buffer: the GLB's binary chunk, a data URI or a file beside it."""
    import binascii

    import pygltflib as g

    from ._checked import Invalid, sequence, text, whole
    from ._limits import check_memory, format_bytes

    out = []
    for k, b in enumerate(sequence(gltf.buffers, "buffers", MAX_ITEMS)):
        at = f"buffers[{k}]"
        if not isinstance(b, g.Buffer):
            raise Invalid(f"{at}: expected an object")
        length = whole(b.byteLength if b.byteLength is not None else 0, f"{at}.byteLength",
                       0, 2**53)
        if b.uri is None:
            data = gltf.binary_blob()
        else:
            uri = text(b.uri, f"{at}.uri", 2**31)
            if uri.startswith("data:"):
                if "," not in uri:
                    raise Invalid(f"{at}.uri: a data URI without ',' before its data")
                try:
                    data = base64.b64decode(uri.split(",", 1)[1], validate=True)
                except (binascii.Error, ValueError) as exc:
                    raise Invalid(f"{at}.uri: not base64 data ({exc})") from None
            else:
                try:
                    f = path.parent / uri
                    found = f.is_file()
                except (OSError, ValueError):
                    found = False
                if not found:
                    raise Invalid(f"{at}: missing file {uri[:200]}")
                size = f.stat().st_size
                check_memory(size, f"buffer file {uri[:200]} of {format_bytes(size)}", path)
                data = f.read_bytes()
        if data is None or len(data) < length:
            raise Invalid(f"{at}: holds fewer than its {length} bytes")
        out.append(data)
    return out


def _load(path: Path):
    import pygltflib as g

    from ._checked import Invalid
    from ._limits import check_memory, format_bytes

    if not path.is_file():
        raise ParseError("no such glTF file", str(path))
    size = path.stat().st_size
    check_memory(_LOAD_BYTES_PER_BYTE * size, f"a {format_bytes(size)} glTF file", path)
    try:
        gltf = g.GLTF2.load(str(path))
    except Exception as exc:  # noqa: BLE001 - pygltflib raises assorted errors on bad files
        raise ParseError(
            f"not a readable glTF file ({type(exc).__name__}: {str(exc)[:200]})", str(path)
        ) from None
    if gltf is None:
        raise ParseError("not a readable glTF file", str(path))
    try:
        _check_nodes(gltf)
        buffers = _buffers(gltf, path)
    except Invalid as exc:
        raise ParseError(str(exc), str(path)) from None
    return gltf, buffers


def _accessor(gltf, buffers, index, where: str) -> np.ndarray:
    """The values ``(count, components)`` of accessor ``index`` (``where`` names who uses
    it) as floats, every index and byte range checked."""
    import pygltflib as g

    from ._checked import Invalid, sequence, text, whole
    from ._limits import check_memory

    accessors = sequence(gltf.accessors, "accessors", MAX_ITEMS)
    index = whole(index, where, 0, len(accessors) - 1) if accessors else None
    if index is None:
        raise Invalid(f"{where}: names an accessor, and the file has none")
    at = f"accessors[{index}]"
    acc = accessors[index]
    if not isinstance(acc, g.Accessor):
        raise Invalid(f"{at}: expected an object")
    if acc.sparse is not None or acc.bufferView is None:
        raise Invalid(f"{at}: sparse or view-less accessors are not supported")
    views = sequence(gltf.bufferViews, "bufferViews", MAX_ITEMS)
    if not views:
        raise Invalid(f"{at}.bufferView: names a buffer view, and the file has none")
    v = whole(acc.bufferView, f"{at}.bufferView", 0, len(views) - 1)
    view = views[v]
    if not isinstance(view, g.BufferView):
        raise Invalid(f"bufferViews[{v}]: expected an object")
    if acc.componentType not in _DTYPE:
        raise Invalid(f"{at}.componentType: {acc.componentType!r} is not one of {sorted(_DTYPE)}")
    kind = text(acc.type, f"{at}.type", 10)
    if kind not in _NCOMP:
        raise Invalid(f"{at}.type: {kind!r} is not one of {', '.join(_NCOMP)}")
    dtype = np.dtype(_DTYPE[acc.componentType]).newbyteorder("<")
    ncomp = _NCOMP[kind]
    width = dtype.itemsize * ncomp
    b = whole(view.buffer, f"bufferViews[{v}].buffer", 0, len(buffers) - 1) if buffers else None
    if b is None:
        raise Invalid(f"bufferViews[{v}].buffer: names a buffer, and the file has none")
    data = buffers[b]
    v_off = whole(view.byteOffset or 0, f"bufferViews[{v}].byteOffset", 0, len(data))
    v_len = whole(view.byteLength, f"bufferViews[{v}].byteLength", 0, len(data) - v_off)
    stride = width
    if view.byteStride is not None:
        stride = whole(view.byteStride, f"bufferViews[{v}].byteStride", width, 252)
    count = whole(acc.count, f"{at}.count", 0, len(data))
    a_off = whole(acc.byteOffset or 0, f"{at}.byteOffset", 0, v_len)
    if count and a_off + stride * (count - 1) + width > v_len:
        raise Invalid(
            f"{at}: {count} values of {width} bytes from byte {a_off} run past the "
            f"{v_len} bytes of bufferViews[{v}]"
        )
    if a_off % dtype.itemsize or (v_off + a_off) % dtype.itemsize:
        raise Invalid(f"{at}.byteOffset: not a multiple of its {dtype.itemsize}-byte components")
    check_memory(8.0 * count * ncomp, f"{at}: {count:,} values of {ncomp}", None)
    out = np.ndarray(
        (count, ncomp), dtype=dtype, buffer=data, offset=v_off + a_off,
        strides=(stride, dtype.itemsize),
    ).astype(float)
    if acc.normalized and dtype.kind in "iu":
        out = np.maximum(out / np.iinfo(dtype).max, -1.0)
    return out


def _sample(
    times: np.ndarray, values: np.ndarray, interp: str, at: np.ndarray, quat: bool
) -> np.ndarray:
    """``values`` at the key ``times`` sampled at ``at`` by ``interp``, ``"STEP"`` or
    ``"LINEAR"`` (a CUBICSPLINE sampler's values are taken out of its triples and read as
    LINEAR by the caller); rotations are renormalised after the linear interpolation."""
    if interp == "STEP":
        k = np.clip(np.searchsorted(times, at + 1e-9, side="right") - 1, 0, len(times) - 1)
        return values[k]
    out = np.stack([np.interp(at, times, values[:, c]) for c in range(values.shape[1])], axis=1)
    if quat:
        norm = np.linalg.norm(out, axis=1, keepdims=True)
        out /= np.where(norm > 1e-12, norm, 1.0)  # opposite keys average to 0: keep the first
        out[norm[:, 0] <= 1e-12] = values[0]
    return out


def _extras(gltf) -> dict:
    """Our entry of the document's ``extras``, checked (``{}`` for a glTF from elsewhere)."""
    from ._checked import Invalid, mapping, number, numbers, rotation, sequence, text, whole
    from ._limits import MAX_FPS, MAX_FRAME_NUMBER, MAX_FRAMES, MIN_FPS
    from .gltf import _EXTRAS_KEY, skeleton_from_dict  # (gltf imports this module)

    extras = gltf.extras
    if not isinstance(extras, dict) or extras.get(_EXTRAS_KEY) is None:
        return {}  # another application's extras
    where = f"extras.{_EXTRAS_KEY}"
    raw = mapping(extras[_EXTRAS_KEY], where)
    out: dict = {}
    if raw.get("fps"):
        out["fps"] = number(raw["fps"], f"{where}.fps", MIN_FPS, MAX_FPS)
    if raw.get("frames"):
        out["frames"] = whole(raw["frames"], f"{where}.frames", 1, MAX_FRAMES)
    if raw.get("scale") is not None:
        out["scale"] = number(raw["scale"], f"{where}.scale", 1e-12, MAX_MAGNITUDE)
    if raw.get("up_rotation") is not None:
        out["up_rotation"] = rotation(
            numbers(raw["up_rotation"], (3, 3), f"{where}.up_rotation"), f"{where}.up_rotation"
        )
    if raw.get("start_frame") is not None:
        out["start_frame"] = whole(raw["start_frame"], f"{where}.start_frame", 0, MAX_FRAME_NUMBER)
    if raw.get("channels") is not None:
        pairs = []
        for k, c in enumerate(sequence(raw["channels"], f"{where}.channels", 6 * MAX_JOINTS)):
            c = sequence(c, f"{where}.channels[{k}]", 2)
            if len(c) != 2:
                raise Invalid(f"{where}.channels[{k}]: expected [joint, dof]")
            pairs.append(tuple(text(x, f"{where}.channels[{k}]", 1000) for x in c))
        out["channels"] = pairs
    if raw.get("skeleton") is not None:
        out["skeleton"] = skeleton_from_dict(raw["skeleton"], f"{where}.skeleton")
    return out


def _key_times(times: np.ndarray, where: str) -> np.ndarray:
    from ._checked import Invalid

    t = times[:, 0]
    if not t.size:
        raise Invalid(f"{where}: no key times")
    if not np.all(np.isfinite(t)) or np.any(np.abs(t) > MAX_MAGNITUDE):
        k = int(np.argmax(~np.isfinite(t) | (np.abs(t) > MAX_MAGNITUDE)))
        raise Invalid(f"{where}: key time {k} is {t[k]}, not a finite number of seconds")
    if t[0] < 0:
        raise Invalid(f"{where}: key time 0 is {float(t[0])!r}; key times start at 0 or later")
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        k = int(back[0]) + 1
        raise Invalid(
            f"{where}: key time {k} ({float(t[k])!r} s) does not come after key time {k - 1} "
            f"({float(t[k - 1])!r} s); key times increase"
        )
    return t


def _node_tracks(gltf, buffers, extras: dict | None = None, anim_index: int = 0):
    """Local translations ``(T, N, 3)`` and rotation matrices ``(T, N, 3, 3)`` of every node,
    sampled at the animation's frame rate, and that rate."""
    import pygltflib as g
    from scipy.spatial.transform import Rotation

    from ._checked import Invalid, sequence, whole
    from ._limits import MAX_FPS, MAX_FRAMES, MIN_FPS, check_memory

    extras = _extras(gltf) if extras is None else extras
    nodes = gltf.nodes
    N = len(nodes)
    animations = sequence(gltf.animations, "animations", MAX_ITEMS)
    anim = animations[anim_index] if animations else None
    where = f"animations[{anim_index}]"
    samplers: list = []
    if anim is not None:
        if not isinstance(anim, g.Animation):
            raise Invalid(f"{where}: expected an object")
        samplers = sequence(anim.samplers, f"{where}.samplers", MAX_ITEMS)
    inputs = []
    for k, smp in enumerate(samplers):
        at = f"{where}.samplers[{k}]"
        if not isinstance(smp, g.AnimationSampler):
            raise Invalid(f"{at}: expected an object")
        interp = smp.interpolation or "LINEAR"
        if interp not in ("LINEAR", "STEP", "CUBICSPLINE"):
            raise Invalid(f"{at}.interpolation: {interp!r} is not LINEAR, STEP or CUBICSPLINE")
        times = _accessor(gltf, buffers, smp.input, f"{at}.input")
        if times.shape[1] != 1:
            raise Invalid(f"{at}.input: key times are scalars, accessor has {times.shape[1]}")
        inputs.append(_key_times(times, f"{at}.input"))
    if extras.get("fps"):
        fps = float(extras["fps"])
    elif inputs and max(len(t) for t in inputs) > 1:
        longest = max(inputs, key=len)
        fps = float((len(longest) - 1) / (longest[-1] - longest[0]))
        if abs(fps - round(fps)) < 1e-4 * fps:  # float32 key times: 120.0001 -> 120
            fps = float(round(fps))
        if not MIN_FPS <= fps <= MAX_FPS:
            raise Invalid(
                f"{where}: key times {longest[-1] - longest[0]:.6g} s apart over "
                f"{len(longest)} keys make {fps:.6g} frames per second; "
                f"{MIN_FPS:g}..{MAX_FPS:g} are supported"
            )
    else:
        fps = 30.0
    end = max((float(t[-1]) for t in inputs), default=0.0)
    if extras.get("frames"):
        T = int(extras["frames"])
    else:
        if end * fps + 1 > MAX_FRAMES:
            raise Invalid(
                f"{where}: {end:.6g} s at {fps:g} fps are {end * fps + 1:.4g} frames; "
                f"at most {MAX_FRAMES:,} are supported"
            )
        T = int(round(end * fps)) + 1
    check_memory(_TRACK_BYTES * T * max(N, 1), f"{T:,} frames of {N:,} nodes", None)
    at_times = np.arange(T) / fps
    trans = np.empty((T, N, 3))
    quats = np.empty((T, N, 4))
    for k, node in enumerate(nodes):
        fixed = None
        if node.matrix is not None:
            fixed = _node_matrix(np.asarray(node.matrix, float), f"nodes[{k}].matrix")
        if fixed is not None:
            trans[:, k] = fixed[0]
            quats[:, k] = Rotation.from_matrix(fixed[1]).as_quat()
        else:
            trans[:, k] = node.translation if node.translation is not None else (0, 0, 0)
            q = np.asarray(node.rotation if node.rotation is not None else (0, 0, 0, 1), float)
            quats[:, k] = q / np.linalg.norm(q)
    if anim is not None:
        channels = sequence(anim.channels, f"{where}.channels", MAX_ITEMS)
        for c, ch in enumerate(channels):
            at = f"{where}.channels[{c}]"
            if not isinstance(ch, g.AnimationChannel) or not isinstance(
                ch.target, g.AnimationChannelTarget
            ):
                raise Invalid(f"{at}: expected an object with a target")
            path = ch.target.path
            if ch.target.node is None or path not in ("translation", "rotation"):
                continue
            node = whole(ch.target.node, f"{at}.target.node", 0, N - 1)
            if not samplers:
                raise Invalid(f"{at}.sampler: the animation has no samplers")
            k = whole(ch.sampler, f"{at}.sampler", 0, len(samplers) - 1)
            s = samplers[k]
            vals = _accessor(gltf, buffers, s.output, f"{where}.samplers[{k}].output")
            times = inputs[k]
            quat = path == "rotation"
            interp = s.interpolation or "LINEAR"
            width, keys = (4 if quat else 3), len(times) * (3 if interp == "CUBICSPLINE" else 1)
            if vals.shape != (keys, width):
                raise Invalid(
                    f"{where}.samplers[{k}].output: {vals.shape[0]} values of "
                    f"{vals.shape[1]} for the {path} of {len(times)} keys; expected {keys} of "
                    f"{width}"
                )
            if interp == "CUBICSPLINE":
                # (in-tangent, value, out-tangent) per key: the tangents need not be unit
                # quaternions, only finite; the values are read (and interpolated linearly)
                triples = vals.reshape(len(times), 3, width)
                tangents = triples[:, [0, 2]]
                if not np.all(np.isfinite(tangents)) or np.abs(tangents).max(
                    initial=0
                ) > MAX_MAGNITUDE:
                    raise Invalid(
                        f"{where}.samplers[{k}].output: tangents that are not finite numbers of "
                        f"at most {MAX_MAGNITUDE:g} in magnitude"
                    )
                vals, interp = triples[:, 1], "LINEAR"
            if quat:
                vals = _unit_quaternions(vals, f"{where}.samplers[{k}].output")
            elif not np.all(np.isfinite(vals)) or np.abs(vals).max(initial=0) > MAX_MAGNITUDE:
                raise Invalid(
                    f"{where}.samplers[{k}].output: translations that are not finite numbers of "
                    f"at most {MAX_MAGNITUDE:g} in magnitude"
                )
            sampled = _sample(times, vals, interp, at_times, quat)
            (quats if quat else trans)[:, node] = sampled
    rots = Rotation.from_quat(quats.reshape(-1, 4)).as_matrix().reshape(T, N, 3, 3)
    return trans, rots, fps


def _tracks(gltf, buffers, path: Path, extras: dict | None = None):
    """:func:`_node_tracks`, with malformed files reported as one ParseError naming ``path``."""
    from ._checked import Invalid

    try:
        return _node_tracks(gltf, buffers, extras)
    except Invalid as exc:
        raise ParseError(str(exc), str(path)) from None
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
    import pygltflib as g

    from ._checked import Invalid, sequence, whole

    n = len(gltf.nodes)
    parent = {c: k for k, node in enumerate(gltf.nodes) for c in (node.children or [])}
    skins = sequence(gltf.skins, "skins", MAX_ITEMS)
    if skins:
        if not isinstance(skins[0], g.Skin):
            raise Invalid("skins[0]: expected an object")
        members = {
            whole(j, "skins[0].joints", 0, n - 1)
            for j in sequence(skins[0].joints, "skins[0].joints", MAX_NODES)
        }
    else:
        members = {k for k, node in enumerate(gltf.nodes) if node.mesh is None}
    if not members:
        raise Invalid("no skeleton nodes (an empty skin, or every node a mesh)")
    if len(members) > MAX_JOINTS:
        raise Invalid(f"{len(members):,} skeleton nodes; at most {MAX_JOINTS:,} are supported")
    roots = [k for k in sorted(members) if parent.get(k) not in members]
    order: list[int] = []
    stack = list(reversed(roots))
    while stack:  # the nodes form a forest (checked on loading): this ends
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
    from ._checked import Invalid

    p = Path(path)
    gltf, buffers = _load(p)
    trans, rots, fps = _tracks(gltf, buffers, p)
    try:
        order, parents = _joint_nodes(gltf)
    except Invalid as exc:
        raise ParseError(str(exc), str(p)) from None
    pos, _ = global_transforms(trans[:, order], rots[:, order], np.asarray(parents))
    return [gltf.nodes[k].name or f"node{k}" for k in order], pos, fps


def read_gltf(path: str | os.PathLike[str]) -> Motion:
    """Read a glTF 2.0 skeleton animation (``.glb`` or ``.gltf``) as a :class:`Motion`.

    A file written by :func:`write_gltf` gives back the original skeleton, channels and
    units; any other file gives one joint per skeleton node (skin joints when there is a
    skin) with ``rx ry rz`` rotations (order ``ZYX``) and ``tx ty tz`` on the root and on
    nodes whose translation is animated, lengths in metres.

    Raises
    ------
    ParseError
        One line naming the file and the entry (``accessors[3].count``,
        ``nodes[5].children``, ``extras.cyclecoord.fps``, ...): indices or byte ranges out
        of bounds, accessors not aligned to their components (the accessor's and its
        buffer view's byte offsets together), a node graph with a cycle or too deep, key
        times that are not finite or do not increase, more frames than ``MAX_FRAMES`` or
        than the memory limit allows, rotations that are not unit quaternions, spline
        tangents (in or out) that are not finite, node or channel names longer than 1,000
        characters, extras of the wrong types.
    """
    from ._checked import Invalid

    p = Path(path)
    gltf, buffers = _load(p)
    try:
        return _read_gltf(gltf, buffers, p)
    except Invalid as exc:
        raise ParseError(str(exc), str(p)) from None
    except ParameterError as exc:
        raise ParseError(str(exc), str(p)) from None


def _read_gltf(gltf, buffers, p: Path) -> Motion:
    from .._kinematics import channels_from_local
    from ._checked import Invalid
    from ._limits import frames_problem

    if not gltf.nodes:
        raise ParseError("the file holds no nodes (no skeleton to read)", str(p))
    extras = _extras(gltf)
    trans, rots, fps = _tracks(gltf, buffers, p, extras)
    if "skeleton" in extras:
        skel = extras["skeleton"]
        by_name = {node.name: k for k, node in enumerate(gltf.nodes)}
        missing = [j.name for j in skel.joints if j.name not in by_name]
        if missing:
            raise ParseError(f"joints {missing[:3]} of the stored skeleton have no node", str(p))
        cols = [by_name[j.name] for j in skel.joints]
        scale = float(extras.get("scale", 1.0))
        trans, rots = trans[:, cols] / scale, rots[:, cols]
        if "up_rotation" in extras:  # undo the turn that made the file y-up
            up = extras["up_rotation"]
            trans[:, 0] = trans[:, 0] @ up
            rots[:, 0] = np.einsum("ba,tbc->tac", up, rots[:, 0])
        frames = channels_from_local(skel, trans, rots)
        problem = frames_problem(frames, skel.channels)
        if problem is not None:
            raise Invalid(f"the animation gives {problem}")
        motion = Motion(
            frames,
            skel.channels,
            fps=fps,
            skeleton=skel,
            source=str(p),
            start_frame=int(extras.get("start_frame", 0)),
        )
        wanted = extras.get("channels", [])
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
    if sum(par < 0 for par in parents) > 1:
        raise Invalid(
            f"the skeleton nodes have {sum(par < 0 for par in parents)} roots; one is supported"
        )
    skel = Skeleton(tuple(joints), name=p.stem, source_format="gltf")
    problem = skeleton_problem(skel)
    if problem is not None:
        raise Invalid(f"skeleton nodes: {problem}")
    frames = channels_from_local(skel, trans[:, order], rots[:, order])
    problem = frames_problem(frames, skel.channels)
    if problem is not None:
        raise Invalid(f"the animation gives {problem}")
    return Motion(frames, skel.channels, fps=fps, skeleton=skel, source=str(p))
