"""The glTF writer's helpers, each with an answer worked out by hand: the default scale,
what is exportable, the skeleton's JSON and its checks, the buffer's accessors, sign-
continuous quaternions, the stick mesh's frame, and the document built for a small
motion (nodes, times, channels, skin, extras) (issue 27: known answers)."""

import numpy as np
import pygltflib as g
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.io import gltf as gw
from cyclecoord.io._checked import Invalid
from cyclecoord.io._limits import MAX_JOINTS
from cyclecoord.io.gltf_read import _accessor
from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton

S = np.sqrt(0.5)


def _arm(T=3, fps=10.0, start_frame=0, **skel):
    """A root (6 dofs) at (0, 0, 0) and an arm (rx rz) 2 up with an end site 1 along x."""
    sk = Skeleton(
        (
            Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
            Joint("arm", 0, [0, 2, 0], ("rx", "rz"), "ZX", end_site=[1, 0, 0]),
        ),
        name="arm", **skel,
    )
    frames = np.zeros((T, 8))
    frames[:, 0] = np.arange(T)  # root tx: 0, 1, 2
    frames[:, 1] = 5.0  # root ty
    return Motion(frames, sk.channels, fps=fps, skeleton=sk, source="/x/arm.bvh",
                  start_frame=start_frame)


# ----------------------------------------------------------------------------- scale, checks
def test_default_scale():
    """ASF: 0.0254 / length_unit metres a unit (CMU's 0.45: 1/0.45 inch); others 1."""
    asf = Skeleton(_arm().skeleton.joints, source_format="asf", length_unit=0.45)
    assert gw.default_scale(asf) == 0.0254 / 0.45
    assert gw.default_scale(Skeleton(asf.joints, source_format="bvh", length_unit=0.45)) == 1.0
    # an ASF skeleton without a usable unit (0 or negative): 1, not a division by it
    for unit in (0.0, -1.0):
        assert gw.default_scale(Skeleton(asf.joints, source_format="asf", length_unit=unit)) == 1.0


def test_check_exportable():
    m = _arm(T=4, start_frame=100)
    assert gw.check_exportable(m, "X") is m.skeleton
    with pytest.raises(ParameterError, match="^/x/arm.bvh: X export needs a skeleton"):
        gw.check_exportable(Motion(m.frames, m.channels, fps=10, source="/x/arm.bvh"), "X")
    with pytest.raises(ParameterError, match="^motion: X export needs a skeleton"):
        gw.check_exportable(Motion(m.frames, m.channels, fps=10), "X")
    with pytest.raises(ParameterError, match="^/x/arm.bvh: no frames to write"):
        gw.check_exportable(m.with_frames(m.frames[:0]), "X")
    assert gw.check_exportable(m.with_frames(m.frames[:1]), "X") is m.skeleton  # one is enough
    frames = m.frames.copy()
    frames[2, 3] = np.nan
    frames[3, 0] = -np.inf
    with pytest.raises(ParameterError, match=r"^/x/arm.bvh: frame 102 holds NaN or infinite "
                                             r"values \(2 such frames\)"):
        gw.check_exportable(m.with_frames(frames), "X")


# ----------------------------------------------------------------------------- skeleton JSON
def test_skeleton_dict_round_trip():
    sk = Skeleton(
        (
            Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
            Joint("arm", 0, [0, 2, 0], ("rx", "rz"), "ZX", axis=[[0, -1, 0], [1, 0, 0], [0, 0, 1]],
                  end_site=[1, 0, 0], limits={"rx": (-90.0, 45.0), "rz": (-np.inf, np.inf)}),
        ),
        name="arm", length_unit=0.45, source_format="asf",
    )
    d = gw.skeleton_to_dict(sk)
    assert d["name"] == "arm" and d["length_unit"] == 0.45 and d["source_format"] == "asf"
    assert d["joints"][1] == {"name": "arm", "parent": 0, "offset": [0, 2, 0], "dofs": ["rx", "rz"],
                              "rotation_order": "ZX", "axis": [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
                              "end_site": [1, 0, 0],
                              "limits": {"rx": [-90.0, 45.0], "rz": [-np.inf, np.inf]}}
    assert d["joints"][0]["end_site"] is None
    back = gw.skeleton_from_dict(d)
    assert back.names == ["root", "arm"] and back.length_unit == 0.45
    assert back.source_format == "asf" and back.name == "arm"
    assert back.joints[1].limits == {"rx": (-90.0, 45.0), "rz": (-np.inf, np.inf)}
    assert back.joints[1].axis.tolist() == [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    assert back.joints[1].end_site.tolist() == [1, 0, 0] and back.joints[0].end_site is None
    assert back.channels == sk.channels


def test_skeleton_dict_defaults():
    """What pygltflib drops when empty: parent -1, no dofs, offset 0, identity axis, no
    rotation order, no limits, name and format '', length unit 1."""
    sk = gw.skeleton_from_dict({"joints": [{"name": "a"}, {"name": "b", "parent": 0}]})
    a = sk.joints[0]
    assert a.parent == -1 and a.dofs == () and a.offset.tolist() == [0, 0, 0]
    assert a.axis.tolist() == np.eye(3).tolist() and a.rotation_order == "" and a.limits == {}
    assert a.end_site is None
    assert sk.name == "" and sk.source_format == "" and sk.length_unit == 1.0


@pytest.mark.parametrize(
    "joint, message",
    [
        ({"name": "b", "parent": 1}, r"s\.joints\[1\]\.parent: 1 is not in -1\.\.0"),
        ({"name": "b", "parent": -2}, r"s\.joints\[1\]\.parent: -2 is not in -1\.\.0"),
        ({"name": "b", "dofs": ["rx", "rx"]}, r"s\.joints\[1\]\.dofs: \['rx', 'rx'\] are not "
                                              "distinct"),
        ({"name": "b", "dofs": ["rw"]}, r"s\.joints\[1\]\.dofs: \['rw'\] are not distinct"),
        ({"name": "b", "dofs": ["tx", "ty", "tz", "rx", "ry", "rz", "tx"]},
         r"s\.joints\[1\]\.dofs: 7 items; at most 6"),
        ({"name": "b", "limits": {"rw": [0, 1]}}, r"s\.joints\[1\]\.limits: 'rw' is not one of"),
        ({"name": "b", "limits": {"rx": [0]}}, r"s\.joints\[1\]\.limits\.rx: expected 2 numbers"),
        ({"name": "b", "rotation_order": "XYZX"}, r"s\.joints\[1\]\.rotation_order: 4 characters"),
        ({"name": "b" * 1001}, r"s\.joints\[1\]\.name: 1,001 characters; at most 1,000"),
        ({"name": "a"}, r"^s: joint names in a skeleton must be unique"),
        ({"name": "b", "dofs": ["rx"], "rotation_order": "ZY"},
         r"^s\.joints\[1\]: joint 'b': rotation order 'ZY' does not match"),
        ({"name": "b", "axis": [[1, 0, 0], [0, 1, 0]]}, r"s\.joints\[1\]\.axis: expected 3x3"),
    ],
)
def test_skeleton_dict_refusals(joint, message):
    with pytest.raises(Invalid, match=message):
        gw.skeleton_from_dict({"joints": [{"name": "a"}, joint]}, "s")


def test_skeleton_dict_sizes():
    ok = {"joints": [{"name": "a", "rotation_order": "ZYX", "dofs": ["rx", "ry", "rz"]}],
          "name": "n" * 1000, "source_format": "f" * 100, "length_unit": 1e-300}
    sk = gw.skeleton_from_dict(ok, "s")
    assert sk.length_unit == 1e-300 and len(sk.name) == 1000
    long = gw.skeleton_from_dict({"joints": [{"name": "j" * 1000}]}, "s")
    assert long.names == ["j" * 1000]
    for key, value, message in (("name", "n" * 1001, r"s\.name: 1,001 characters"),
                                ("source_format", "f" * 101, r"s\.source_format: 101 characters"),
                                ("length_unit", 0.0, r"s\.length_unit: 0\.0 is not in 1e-300"),
                                ("joints", [], r"s\.joints: a skeleton needs at least one joint")):
        with pytest.raises(Invalid, match=message):
            gw.skeleton_from_dict(dict(ok, **{key: value}), "s")
    many = [{"name": f"j{k}", "parent": min(k - 1, 0)} for k in range(MAX_JOINTS + 1)]
    with pytest.raises(Invalid, match=r"s\.joints: 4,097 items; at most 4,096"):
        gw.skeleton_from_dict({"joints": many}, "s")


# ----------------------------------------------------------------------------- the buffer
def test_blob_aligns_views_and_records_bounds():
    """Each view starts on a multiple of 4 bytes; float accessors carry per-component
    float min/max, integer ones int min/max, MAT4 none."""
    doc = g.GLTF2()
    blob = gw._Blob(doc)
    a = blob.add(np.array([[1, 5], [3, 2], [2, 9]], np.uint16), "VEC2", 34962)  # 12 bytes
    b = blob.add(np.array([7], np.uint16), "SCALAR")  # 2 bytes, at 12
    c = blob.add(np.array([[0.5, -1.0, 2.0], [1.5, -3.0, 0.0]], np.float32), "VEC3")  # at 16
    d = blob.add(np.arange(16, dtype=np.float32).reshape(1, 16), "MAT4")  # at 40
    e = blob.add(np.array([4000000000], np.uint32), "SCALAR")  # at 104
    data = blob.finish()
    assert (a, b, c, d, e) == (0, 1, 2, 3, 4)
    assert [v.byteOffset for v in doc.bufferViews] == [0, 12, 16, 40, 104]
    assert [v.byteLength for v in doc.bufferViews] == [12, 2, 24, 64, 4]
    assert [v.target for v in doc.bufferViews] == [34962, None, None, None, None]
    assert len(data) == 108 and data[14:16] == b"\0\0"
    acc = doc.accessors
    assert [x.componentType for x in acc] == [5123, 5123, 5126, 5126, 5125]
    assert [x.count for x in acc] == [3, 1, 2, 1, 1]
    assert [x.bufferView for x in acc] == [0, 1, 2, 3, 4]
    assert (acc[0].min, acc[0].max) == ([1, 2], [3, 9])
    assert all(type(v) is int for v in acc[0].min + acc[0].max)
    assert (acc[2].min, acc[2].max) == ([0.5, -3.0, 0.0], [1.5, -1.0, 2.0])
    assert acc[3].min is None and acc[3].max is None
    assert (acc[4].min, acc[4].max) == ([4000000000], [4000000000])
    for k, values in enumerate([[[1, 5], [3, 2], [2, 9]], [[7]]]):
        assert _accessor(doc, [data], k, "x").tolist() == values


def test_blob_finish_pads_to_four_bytes():
    blob = gw._Blob(g.GLTF2())
    blob.add(np.array([1, 2, 3], np.uint16), "SCALAR")
    assert blob.finish() == np.array([1, 2, 3, 0], "<u2").tobytes()


# ----------------------------------------------------------------------------- quaternions
def test_continuous_quaternions_flip_against_the_previous_one():
    """Each quaternion is negated when its dot product with the (already continued)
    previous one is negative; a dot of 0 is left alone; the input is not changed."""
    q = np.array([[0, 0, 0, 1.0], [0, 0, 0.1, -1.0], [0, 0, -0.2, 1.0], [1.0, 0, 0, 0],
                  [-1.0, 0, 0, 0]])
    out = gw._continuous_quaternions(q)
    assert out.tolist() == [[0, 0, 0, 1], [0, 0, -0.1, 1], [0, 0, -0.2, 1], [1, 0, 0, 0],
                            [1, 0, 0, 0]]
    assert q[1].tolist() == [0, 0, 0.1, -1]
    one = np.array([[0, 0, 0, -1.0]])
    assert gw._continuous_quaternions(one).tolist() == [[0, 0, 0, -1]]


# ----------------------------------------------------------------------------- stick mesh
@pytest.mark.parametrize(
    "q, ring",
    [
        # along x (|d_x| >= 0.9): helper y, u = x x y = z, v = x x z = -y
        ([2.0, 0, 0], [[0, 0, 1], [0, -1, 0], [0, 0, -1], [0, 1, 0]]),
        # along y: helper x, u = y x x = -z, v = y x -z = -x
        ([0, 2.0, 0], [[0, 0, -1], [-1, 0, 0], [0, 0, 1], [1, 0, 0]]),
        # d = (0.9, sqrt(0.19), 0): |d_x| = 0.9 exactly, still helper y: u = z
        ([0.9, np.sqrt(0.19), 0], [[0, 0, 1], [np.sqrt(0.19), -0.9, 0], [0, 0, -1],
                                   [-np.sqrt(0.19), 0.9, 0]]),
    ],
)
def test_stick_mesh_ring_frame(q, ring):
    """The ring's corners: r (cos(k pi/2) u + sin(k pi/2) v), k = 0..3, around both ends."""
    rest = np.array([[0, 0, 0], q])
    verts, joints, tris = gw._stick_mesh(rest, [(5, (0, 1))], 0.1)
    np.testing.assert_allclose(verts[:4], 0.1 * np.array(ring), atol=1e-15)
    np.testing.assert_allclose(verts[4:], np.array(q) + 0.1 * np.array(ring), atol=1e-15)
    assert joints.tolist() == [5] * 8 and tris.shape == (12, 3)


def test_stick_mesh_skips_bones_shorter_than_a_nanometre():
    verts, _, _ = gw._stick_mesh(np.array([[0, 0, 0], [0, 0, 1e-9]]), [(0, (0, 1))], 1.0)
    assert verts.shape == (8, 3)  # exactly 1e-9 long: kept
    rest = np.array([[0, 0, 0], [0, 0, 2e-9], [0, 0, 0.5e-9]])
    verts, _, _ = gw._stick_mesh(rest, [(0, (0, 1)), (1, (0, 2))], 1.0)
    assert verts.shape == (8, 3)  # the 2e-9 bone kept, with corners 0.5e-9 away
    np.testing.assert_allclose(np.linalg.norm(verts[:4], axis=1), 0.5e-9, rtol=1e-12)
    verts, joints, tris = gw._stick_mesh(rest, [(1, (0, 2))], 1.0)
    assert verts.shape == (0,) and joints.shape == (0,) and tris.shape == (0,)


# ----------------------------------------------------------------------------- the document
def test_build_nodes_times_and_channels():
    m = _arm()
    doc, data = gw._build(m, 0.5, False, np.eye(3))
    names = [n.name for n in doc.nodes]
    assert names == ["root", "arm", "arm_end"]
    # node translations: offsets x 0.5, the root where the capture starts (tx 0, ty 5)
    assert [n.translation for n in doc.nodes] == [[0, 2.5, 0], [0, 1, 0], [0.5, 0, 0]]
    assert doc.nodes[0].children == [1] and doc.nodes[1].children == [2]
    assert doc.nodes[2].children == [] and doc.nodes[0].rotation is None
    anim = doc.animations[0]
    assert anim.name == "arm"
    times = _accessor(doc, [data], anim.samplers[0].input, "t")[:, 0]
    np.testing.assert_array_equal(times, np.float32([0, 0.1, 0.2]))
    targets = [(c.target.node, c.target.path) for c in anim.channels]
    assert targets == [(0, "translation"), (0, "rotation"), (1, "rotation")]
    assert [c.sampler for c in anim.channels] == [0, 1, 2]
    assert all(s.interpolation == "LINEAR" and s.input == anim.samplers[0].input
               for s in anim.samplers)
    tr = _accessor(doc, [data], anim.samplers[0].output, "t")
    np.testing.assert_array_equal(tr, [[0, 2.5, 0], [0.5, 2.5, 0], [1, 2.5, 0]])
    assert _accessor(doc, [data], anim.samplers[2].output, "q").tolist() == [[0, 0, 0, 1]] * 3
    assert doc.skins[0].joints == [0, 1, 2] and doc.skins[0].skeleton == 0
    assert doc.skins[0].name == "arm"
    ibm = _accessor(doc, [data], doc.skins[0].inverseBindMatrices, "m").reshape(3, 4, 4)
    # column-major: the translation is the last row; minus the rest pose x 0.5
    assert ibm[:, 3, :3].tolist() == [[0, 0, 0], [0, -1, 0], [-0.5, -1, 0]]
    assert (ibm[:, :3, :3] == np.eye(3)).all() and ibm[:, 3, 3].tolist() == [1, 1, 1]
    assert doc.scenes[0].nodes == [0] and doc.scene == 0 and doc.meshes == []
    assert doc.buffers[0].byteLength == len(data)


def test_build_extras():
    m = _arm(start_frame=7)
    doc, _ = gw._build(m, 0.5, False, np.eye(3))
    ours = doc.extras["cyclecoord"]
    assert ours["fps"] == 10.0 and ours["frames"] == 3 and ours["scale"] == 0.5
    assert ours["start_frame"] == 7 and ours["source"] == "/x/arm.bvh"
    assert "up_rotation" not in ours
    assert ours["channels"] == [list(c) for c in m.channels]
    assert ours["skeleton"] == gw.skeleton_to_dict(m.skeleton)


def test_build_turned_up():
    """A Z-up rig's root turned by ``up``: its rotation is up's quaternion, the root's
    translation keys (x, y, z) -> up (x, y, z), the bind matrices' rotation up^T, and the
    stored up_rotation undoes it."""
    up = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])  # Z_TO_Y: z up -> y up
    m = _arm()
    doc, data = gw._build(m, 1.0, False, up)
    assert doc.extras["cyclecoord"]["up_rotation"] == up.tolist()
    from scipy.spatial.transform import Rotation

    assert np.linalg.norm(doc.nodes[0].rotation) == pytest.approx(1.0, abs=1e-15)
    np.testing.assert_allclose(Rotation.from_quat(doc.nodes[0].rotation).as_matrix(), up,
                               atol=1e-15)
    assert doc.nodes[0].translation == [0, 0, -5]  # (0, 5, 0) turned
    tr = _accessor(doc, [data], doc.animations[0].samplers[0].output, "t")
    np.testing.assert_array_equal(tr, [[0, 0, -5], [1, 0, -5], [2, 0, -5]])
    ibm = _accessor(doc, [data], doc.skins[0].inverseBindMatrices, "m").reshape(3, 4, 4)
    np.testing.assert_array_equal(ibm[:, :3, :3], np.broadcast_to(up, (3, 3, 3)))  # up^T, stored
    # inverse of T(up rest) up = up^T T(-up rest): translation -up^T up rest = -rest, the
    # arm's rest (0, 2, 0) unturned
    assert ibm[1, 3, :3].tolist() == [0, -2, 0]


def test_build_mesh_and_names():
    m = _arm()
    doc, data = gw._build(m, 1.0, True, np.eye(3))
    assert [n.name for n in doc.nodes] == ["root", "arm", "arm_end", "sticks"]
    assert doc.nodes[3].mesh == 0 and doc.nodes[3].skin == 0 and doc.scenes[0].nodes == [0, 3]
    prim = doc.meshes[0].primitives[0]
    assert doc.meshes[0].name == "sticks"
    joints = _accessor(doc, [data], prim.attributes.JOINTS_0, "j")
    weights = _accessor(doc, [data], prim.attributes.WEIGHTS_0, "w")
    assert joints.tolist() == [[0, 0, 0, 0]] * 8 + [[1, 0, 0, 0]] * 8  # root->arm, arm->end
    assert weights.tolist() == [[1, 0, 0, 0]] * 16
    idx = _accessor(doc, [data], prim.indices, "i")[:, 0]
    assert idx.shape == (72,) and idx.min() == 0 and idx.max() == 15
    assert doc.bufferViews[doc.accessors[prim.indices].bufferView].target == 34963
    assert doc.bufferViews[doc.accessors[prim.attributes.POSITION].bufferView].target == 34962
    # a skeleton of one joint has no bone: no mesh, no sticks node
    one = Skeleton((Joint("r", -1, [0, 0, 0], ("tx", "ty", "tz"), ""),))
    doc, _ = gw._build(Motion(np.zeros((2, 3)), one.channels, fps=5, skeleton=one), 1.0, True,
                       np.eye(3))
    assert doc.meshes == [] and [n.name for n in doc.nodes] == ["r"]
    assert doc.scenes[0].name == "scene" and doc.skins[0].name == "skeleton"
    assert doc.animations[0].name == "motion"


# ----------------------------------------------------------------------------- write_gltf
def test_write_gltf_suffixes_and_scale(tmp_path):
    m = _arm()
    gw.write_gltf(m, tmp_path / "a.GLB", scale=1.0)
    assert (tmp_path / "a.GLB").read_bytes()[:4] == b"glTF"
    gw.write_gltf(m, tmp_path / "b.gltf", scale=1.0)
    doc = g.GLTF2.load(str(tmp_path / "b.gltf"))
    assert doc.buffers[0].uri == "b.bin"
    assert doc.buffers[0].byteLength == (tmp_path / "b.bin").stat().st_size
    with pytest.raises(ParameterError, match=r"glTF files end in \.glb or \.gltf, got '\.txt'"):
        gw.write_gltf(m, tmp_path / "c.txt")
    with pytest.raises(ParameterError, match=r"got '\(no suffix\)'"):
        gw.write_gltf(m, tmp_path / "c")
    for bad in (0.0, -1.0, np.nan, np.inf):
        with pytest.raises(ParameterError, match="scale must be a positive number"):
            gw.write_gltf(m, tmp_path / "d.glb", scale=bad)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.GLB", "b.bin", "b.gltf"]
    gw.write_gltf(m, tmp_path / "e.glb", scale=1e-3)
    assert g.GLTF2.load(str(tmp_path / "e.glb")).extras["cyclecoord"]["scale"] == 1e-3
