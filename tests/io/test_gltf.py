"""glTF 2.0 export: round trips through our reader and through the file's own nodes."""

import json
import struct
import subprocess
import sys

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io.gltf import (
    default_scale,
    gltf_joint_positions,
    read_gltf,
    write_gltf,
)
from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton


def _arm(T=5, fps=30.0):
    skel = Skeleton(
        (
            Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
            Joint("arm", 0, [0, 1, 0], ("rx", "rz"), "ZX", end_site=[1, 0, 0]),
        ),
        name="arm",
        source_format="bvh",
    )
    frames = np.zeros((T, 8))
    frames[:, 1] = 2.0  # root ty
    frames[:, 4] = np.linspace(0, 90, T)  # root ry
    frames[:, 7] = 30.0  # arm rz
    return Motion(frames, skel.channels, fps=fps, skeleton=skel, source="arm")


def _glb_json(path):
    data = path.read_bytes()
    magic, version, length = struct.unpack("<4sII", data[:12])
    assert magic == b"glTF" and version == 2 and length == len(data)
    n, kind = struct.unpack("<I4s", data[12:20])
    assert kind == b"JSON" and (20 + n) % 4 == 0
    return json.loads(data[20 : 20 + n])


def _names_to_fk(names):
    return [n[: -len("_end")] + "/end" if n.endswith("_end") else n for n in names]


@pytest.mark.parametrize("suffix", [".glb", ".gltf"])
def test_69_01_round_trip_every_frame(walk_69_01, tmp_path, suffix):
    out = tmp_path / ("walk" + suffix)
    cc.save(walk_69_01, out)
    if suffix == ".gltf":
        assert (tmp_path / "walk.bin").is_file()
    fk = walk_69_01.positions()
    names, pos, fps = gltf_joint_positions(out)
    assert fps == 120 and pos.shape[0] == walk_69_01.n_frames
    cols = [fk.names.index(n) for n in _names_to_fk(names)]
    scale = default_scale(walk_69_01.skeleton)
    err = np.abs(pos / scale - fk.positions[:, cols]).max(axis=(1, 2))
    assert err.max() < 1e-3  # every frame, in ASF length units
    back = cc.load(out)
    assert back.channels == walk_69_01.channels and back.fps == 120
    assert np.abs(back.positions().positions - fk.positions).max() < 1e-3


def test_document_structure(tmp_path):
    m = _arm()
    out = tmp_path / "arm.glb"
    write_gltf(m, out)
    doc = _glb_json(out)
    assert doc["asset"]["version"] == "2.0"
    for view in doc["bufferViews"]:
        assert view.get("byteOffset", 0) % 4 == 0
    for acc in doc["accessors"]:
        if acc["type"] != "MAT4":
            assert "min" in acc and "max" in acc
    anim = doc["animations"][0]
    paths = sorted((c["target"]["node"], c["target"]["path"]) for c in anim["channels"])
    assert paths == [(0, "rotation"), (0, "translation"), (1, "rotation")]
    times = doc["accessors"][anim["samplers"][0]["input"]]
    assert times["count"] == 5 and times["max"][0] == pytest.approx(4 / 30)
    # the root's last rotation is 90 degrees about y: (x, y, z, w) = (0, s, 0, s)
    g = read_gltf(out)
    assert np.allclose(g.frames, m.frames, atol=1e-4)
    names = [n["name"] for n in doc["nodes"]]
    assert names[:3] == ["root", "arm", "arm_end"] and "sticks" in names
    assert doc["skins"][0]["joints"] == [0, 1, 2]


def test_quaternion_order(tmp_path):
    import pygltflib

    m = _arm()
    out = tmp_path / "arm.glb"
    write_gltf(m, out, mesh=False)
    gltf = pygltflib.GLTF2.load(str(out))
    anim = gltf.animations[0]
    ch = next(c for c in anim.channels if c.target.node == 0 and c.target.path == "rotation")
    acc = gltf.accessors[anim.samplers[ch.sampler].output]
    view = gltf.bufferViews[acc.bufferView]
    q = np.frombuffer(
        gltf.binary_blob()[view.byteOffset : view.byteOffset + view.byteLength], np.float32
    ).reshape(-1, 4)
    s = np.sqrt(0.5)
    assert np.allclose(q[-1], [0, s, 0, s], atol=1e-6)
    assert np.allclose(q[0], [0, 0, 0, 1], atol=1e-6)


def test_foreign_gltf_without_extras(tmp_path):
    """A file from elsewhere (no cyclecoord extras) still reads, in metres."""
    import pygltflib

    m = _arm()
    out = tmp_path / "arm.gltf"
    write_gltf(m, out, mesh=False)
    gltf = pygltflib.GLTF2.load(str(out))
    gltf.extras = {}
    (tmp_path / "plain.gltf").write_text(gltf.gltf_to_json())
    back = read_gltf(tmp_path / "plain.gltf")
    assert back.skeleton.names == ["root", "arm", "arm_end"]
    fk = m.positions().positions  # root, arm, arm/end
    assert np.abs(back.positions().positions[:, :3] - fk).max() < 1e-5
    # translations on the root and on nodes with a translation channel only
    rot, move = ("rx", "ry", "rz"), ("tx", "ty", "tz", "rx", "ry", "rz")
    assert [j.dofs for j in back.skeleton.joints] == [move, rot, rot]
    # the root's translation channel moved to the arm: the root (no parent) keeps its
    # translations, the arm gets them, and both read as the file's own nodes place them
    for c in gltf.animations[0].channels:
        if c.target.path == "translation":
            c.target.node = 1
    (tmp_path / "moved.gltf").write_text(gltf.gltf_to_json())
    back = read_gltf(tmp_path / "moved.gltf")
    assert [j.dofs for j in back.skeleton.joints] == [move, move, rot]
    _, own, _ = gltf_joint_positions(tmp_path / "moved.gltf")
    assert np.abs(back.positions().positions[:, :3] - own).max() < 1e-5


def test_bad_input_writes_nothing(tmp_path):
    m = _arm()
    bare = Motion(m.frames, m.channels, fps=m.fps)
    with pytest.raises(ParameterError, match="^motion: .*needs a skeleton"):  # no source
        cc.save(bare, tmp_path / "a.glb")
    frames = m.frames.copy()
    frames[3, 2] = np.nan
    with pytest.raises(ParameterError, match="^arm: frame 3"):  # the message names the source
        cc.save(m.with_frames(frames), tmp_path / "b.gltf")
    with pytest.raises(ParameterError, match="scale"):
        write_gltf(m, tmp_path / "c.glb", scale=0)
    with pytest.raises(ParameterError, match="unknown option"):
        cc.save(m, tmp_path / "d.glb", rotation_order="XYZ")
    assert list(tmp_path.iterdir()) == []


def test_unreadable_files(tmp_path):
    bad = tmp_path / "bad.glb"
    bad.write_bytes(b"not a gltf at all")
    with pytest.raises(ParseError, match="bad.glb"):
        cc.load(bad)
    with pytest.raises(ParseError, match="no such"):
        read_gltf(tmp_path / "missing.gltf")
    m = _arm()
    write_gltf(m, tmp_path / "x.gltf")
    (tmp_path / "x.bin").unlink()
    with pytest.raises(ParseError, match="missing file x.bin"):
        cc.load(tmp_path / "x.gltf")


def test_cli_convert_to_glb(walk_69_01, tmp_path):
    src = walk_69_01.source
    out = tmp_path / "69_01.glb"
    r = subprocess.run(
        [sys.executable, "-m", "cyclecoord", "convert", src, "-o", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert r.returncode == 0, r.stderr
    assert read_gltf(out).n_frames == walk_69_01.n_frames


def test_truncated_buffer_is_one_parse_error(tmp_path):
    m = _arm()
    write_gltf(m, tmp_path / "t.gltf", mesh=False)
    data = (tmp_path / "t.bin").read_bytes()
    (tmp_path / "t.bin").write_bytes(data[: len(data) // 2])
    with pytest.raises(ParseError, match=r"t\.gltf"):
        cc.load(tmp_path / "t.gltf")


def test_save_with_lock_feet(walk_69_01, tmp_path):
    from cyclecoord.quality.contacts import foot_contacts, foot_skating

    m = walk_69_01[200:330]
    contacts = foot_contacts(m)
    assert foot_skating(m, contacts).skating_frames > 0
    cc.save(m, tmp_path / "locked.glb", lock_feet=True)
    back = cc.load(tmp_path / "locked.glb")
    assert foot_skating(back, contacts).skating_frames <= 1


def _foreign(tmp_path, m):
    """``m`` written without a mesh and loaded back as a pygltflib document, extras dropped."""
    import pygltflib

    out = tmp_path / "arm.gltf"
    write_gltf(m, out, mesh=False)
    gltf = pygltflib.GLTF2.load(str(out))
    gltf.extras = {}
    return gltf


def _cubic(tmp_path, m, in_tangent=7.0, out_tangent=-5.0):
    """``m`` as a foreign glTF whose samplers are CUBICSPLINE, tangents value + offset."""
    import base64

    import pygltflib

    gltf = _foreign(tmp_path, m)
    blob = bytearray()
    for s in gltf.animations[0].samplers:
        acc = gltf.accessors[s.output]
        view = gltf.bufferViews[acc.bufferView]
        data = (tmp_path / gltf.buffers[view.buffer].uri).read_bytes()
        ncomp = {"VEC3": 3, "VEC4": 4}[acc.type]
        start = (view.byteOffset or 0) + (acc.byteOffset or 0)
        v = np.frombuffer(data, np.float32, acc.count * ncomp, start).reshape(-1, ncomp)
        # tangents far from the values (a reader taking them would be far off)
        keys = np.stack([v + in_tangent, v, v + out_tangent], axis=1).astype(np.float32)
        gltf.bufferViews.append(pygltflib.BufferView(buffer=len(gltf.buffers),
                                                     byteOffset=len(blob),
                                                     byteLength=keys.nbytes))
        gltf.accessors.append(pygltflib.Accessor(bufferView=len(gltf.bufferViews) - 1,
                                                 componentType=5126, count=3 * acc.count,
                                                 type=acc.type))
        blob += keys.tobytes()
        s.output = len(gltf.accessors) - 1
        s.interpolation = "CUBICSPLINE"
    uri = "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()
    gltf.buffers.append(pygltflib.Buffer(byteLength=len(blob), uri=uri))
    (tmp_path / "cubic.gltf").write_text(gltf.gltf_to_json())
    return tmp_path / "cubic.gltf"


def test_cubic_spline_samplers_read_their_values_not_tangents(tmp_path):
    """A CUBICSPLINE sampler holds (in-tangent, value, out-tangent) per key; the reader
    takes the values (between keys it interpolates linearly, as for LINEAR)."""
    m = _arm()
    back = read_gltf(_cubic(tmp_path, m))
    assert back.n_frames == m.n_frames
    assert np.abs(back.positions().positions[:, :3] - m.positions().positions).max() < 1e-5


@pytest.mark.parametrize("in_tangent, out_tangent", [(np.nan, -5.0), (7.0, np.inf)])
def test_cubic_spline_tangents_must_be_finite(tmp_path, in_tangent, out_tangent):
    path = _cubic(tmp_path, _arm(), in_tangent, out_tangent)
    with pytest.raises(ParseError, match="tangents that are not finite"):
        read_gltf(path)


def test_identity_matrix_beside_trs_is_no_matrix(tmp_path):
    """Some exporters write the identity ``matrix`` beside the node's translation and
    rotation: the reader then uses the translation and rotation."""
    m = _arm()
    gltf = _foreign(tmp_path, m)
    assert gltf.nodes[1].translation is not None and np.linalg.norm(gltf.nodes[1].translation) > 0
    gltf.nodes[1].matrix = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    (tmp_path / "identity.gltf").write_text(gltf.gltf_to_json())
    back = read_gltf(tmp_path / "identity.gltf")
    assert np.abs(back.positions().positions[:, :3] - m.positions().positions).max() < 1e-5


def test_stick_mesh_prisms_are_closed_and_outward():
    """Each bone's prism: 8 vertices, 12 triangles, every edge shared by two triangles in
    opposite directions (closed, consistently wound), outward normals (positive volume
    2 r^2 L for a square of half-diagonal r)."""
    from cyclecoord.io.gltf import _stick_mesh

    rest = np.array([[0, 0, 0], [0, 2.0, 0], [3.0, 2.0, 0], [3.0, 2.0, 0]])
    verts, joints, tris = _stick_mesh(rest, [(0, (0, 1)), (1, (1, 2)), (2, (2, 3))], 0.1)
    assert verts.shape == (16, 3) and tris.shape == (24, 3)  # the zero-length bone is skipped
    assert joints.tolist() == [0] * 8 + [1] * 8
    for b, length in enumerate([2.0, 3.0]):
        own = tris[12 * b : 12 * (b + 1)]
        assert (own // 8 == b).all()
        directed = [(t[i], t[(i + 1) % 3]) for t in own.tolist() for i in range(3)]
        assert len(set(directed)) == 36
        assert all((y, x) in directed for x, y in directed)
        p = verts[own]
        volume = np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6
        assert volume == pytest.approx(2 * 0.1**2 * length, rel=1e-12)


def _accessor(gltf, folder, index, ncomp):
    acc = gltf.accessors[index]
    view = gltf.bufferViews[acc.bufferView]
    data = (folder / gltf.buffers[view.buffer].uri).read_bytes()
    start = (view.byteOffset or 0) + (acc.byteOffset or 0)
    return np.frombuffer(data, np.float32, acc.count * ncomp, start).reshape(-1, ncomp)


def test_stick_mesh_radius_is_a_hundredth_of_the_bone_length(tmp_path):
    """Each bone's prism has its corners 1 % of the skeleton's total bone length from the
    bone (documented in :func:`write_gltf`): the arm's two bones of 1 unit at 0.5 m a unit
    make a skeleton 1 m long, so corners 1 cm from the bone, the bones 0.5 m long; a
    radius over a quarter of a bone's length is cut to that quarter."""
    import pygltflib

    from cyclecoord.io.gltf import _stick_mesh

    out = tmp_path / "arm.gltf"
    write_gltf(_arm(), out, scale=0.5)
    gltf = pygltflib.GLTF2.load(str(out))
    verts = _accessor(gltf, tmp_path, gltf.meshes[0].primitives[0].attributes.POSITION, 3)
    rings = verts.reshape(-1, 4, 3).astype(float)  # per bone: the ring at p, the ring at q
    assert rings.shape[0] == 4  # two bones
    centres = rings.mean(axis=1)
    np.testing.assert_allclose(np.linalg.norm(rings - centres[:, None], axis=2), 0.01, rtol=1e-5)
    np.testing.assert_allclose(np.linalg.norm(centres[1::2] - centres[::2], axis=1), 0.5, rtol=1e-6)
    # a bone of length 2 given a radius of 1: corners at a quarter of its length
    verts, _, _ = _stick_mesh(np.array([[0.0, 0, 0], [0, 0, 2.0]]), [(0, (0, 1))], 1.0)
    assert np.linalg.norm(verts[:4] - [0, 0, 0], axis=1) == pytest.approx([0.5] * 4)
    assert np.linalg.norm(verts[4:] - [0, 0, 2.0], axis=1) == pytest.approx([0.5] * 4)


def test_unit_quaternions_are_normalised_within_the_tolerance():
    """Rotation keys are unit quaternions to within UNIT_TOLERANCE (1e-3) in length, and
    are divided by their length; longer or shorter ones, or values that are not
    finite, are refused."""
    from cyclecoord.io._checked import Invalid
    from cyclecoord.io.gltf_read import UNIT_TOLERANCE, _unit_quaternions

    assert UNIT_TOLERANCE == 1e-3
    s = np.sqrt(0.5)
    q = np.array([[0, 0, 0, 1.0009], [0, 0.9991 * s, 0, 0.9991 * s], [0.5, 0.5, 0.5, 0.5]])
    np.testing.assert_allclose(
        _unit_quaternions(q, "x"), [[0, 0, 0, 1], [0, s, 0, s], [0.5, 0.5, 0.5, 0.5]],
        atol=1e-15,
    )
    for bad in ([0, 0, 0, 1.0011], [0, 0, 0, 0.9989], [0, 0, 0, 0], [0, 0, 0, 2.0]):
        with pytest.raises(Invalid, match="has length"):
            _unit_quaternions(np.array([[0, 0, 0, 1.0], bad]), "x")
    with pytest.raises(Invalid, match="quaternion 1 holds .*not finite"):
        _unit_quaternions(np.array([[0, 0, 0, 1.0], [0, np.nan, 0, 1]]), "x")
