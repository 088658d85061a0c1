"""The glTF reader's helpers, each on a small document built here, with the answer worked
out by hand: accessors (component types, strides, offsets, normalised integers, every
byte range), key times, sampling, node matrices, the node graph, buffers, extras, the
node tracks and the skeleton's nodes (issue 27: known answers)."""

import base64

import numpy as np
import pygltflib as g
import pytest

from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io import gltf_read as gr
from cyclecoord.io._checked import Invalid
from cyclecoord.io._limits import MAX_DEPTH, MAX_FRAMES, MAX_JOINTS, memory_limit

FLOAT, UBYTE, BYTE, USHORT, SHORT, UINT = 5126, 5121, 5120, 5123, 5122, 5125


def _doc(*arrays, **gltf_fields):
    """A document whose one buffer holds ``arrays`` (each ``(values, componentType, type)``
    or ``(values, componentType, type, accessor fields)``), each in its own 4-aligned view
    with one accessor over it: accessor k reads array k."""
    blob = bytearray()
    views, accessors = [], []
    for item in arrays:
        values, ctype, kind = item[:3]
        extra = item[3] if len(item) > 3 else {}
        data = np.ascontiguousarray(values).tobytes()
        views.append(g.BufferView(buffer=0, byteOffset=len(blob), byteLength=len(data)))
        ncomp = gr._NCOMP[kind]
        accessors.append(g.Accessor(bufferView=len(views) - 1, componentType=ctype,
                                    count=np.asarray(values).size // ncomp, type=kind, **extra))
        blob += data + b"\0" * (-len(data) % 4)
    doc = g.GLTF2(accessors=accessors, bufferViews=views,
                  buffers=[g.Buffer(byteLength=len(blob))], **gltf_fields)
    return doc, [bytes(blob)]


# ----------------------------------------------------------------------------- accessors
@pytest.mark.parametrize(
    "ctype, dtype, values",
    [
        (FLOAT, "<f4", [1.5, -2.25, 3e5]),
        (UBYTE, "u1", [0, 200, 255]),
        (BYTE, "i1", [-128, -3, 127]),
        (USHORT, "<u2", [0, 40000, 65535]),
        (SHORT, "<i2", [-32768, -300, 32767]),
        (UINT, "<u4", [0, 70000, 4294967295]),
    ],
)
def test_accessor_reads_each_component_type_as_floats(ctype, dtype, values):
    """Each componentType of the glTF table (5126 float, 5121/5120 unsigned/signed byte,
    5123/5122 short, 5125 unsigned int), little-endian, read as float64 unchanged."""
    gltf, buffers = _doc((np.array(values, dtype), ctype, "SCALAR"))
    out = gr._accessor(gltf, buffers, 0, "x")
    assert out.dtype == np.float64 and out.shape == (3, 1)
    assert out[:, 0].tolist() == values


@pytest.mark.parametrize("kind, ncomp", [("SCALAR", 1), ("VEC2", 2), ("VEC3", 3), ("VEC4", 4),
                                         ("MAT4", 16)])
def test_accessor_shape_is_count_by_components(kind, ncomp):
    values = np.arange(2 * ncomp, dtype="<f4")
    gltf, buffers = _doc((values, FLOAT, kind))
    out = gr._accessor(gltf, buffers, 0, "x")
    np.testing.assert_array_equal(out, values.reshape(2, ncomp))


@pytest.mark.parametrize(
    "ctype, dtype, stored, expected",
    [
        (UBYTE, "u1", [0, 51, 255], [0.0, 0.2, 1.0]),  # / 255
        (USHORT, "<u2", [0, 65535], [0.0, 1.0]),  # / 65535
        (BYTE, "i1", [-128, -127, 0, 127], [-1.0, -1.0, 0.0, 1.0]),  # / 127, floored at -1
        (SHORT, "<i2", [-32768, 16383, 32767], [-1.0, 16383 / 32767, 1.0]),
    ],
)
def test_normalised_integers_divide_by_the_type_maximum(ctype, dtype, stored, expected):
    """glTF's normalised integers: c / max for unsigned, max(c / max, -1) for signed
    (so the most negative value is -1, not -128/127)."""
    gltf, buffers = _doc((np.array(stored, dtype), ctype, "SCALAR", {"normalized": True}))
    np.testing.assert_allclose(gr._accessor(gltf, buffers, 0, "x")[:, 0], expected, rtol=1e-15)
    gltf.accessors[0].normalized = False  # the same bytes, read as plain integers
    assert gr._accessor(gltf, buffers, 0, "x")[:, 0].tolist() == stored


def test_normalised_floats_are_not_rescaled():
    gltf, buffers = _doc((np.array([0.5, 2.0], "<f4"), FLOAT, "SCALAR", {"normalized": True}))
    assert gr._accessor(gltf, buffers, 0, "x")[:, 0].tolist() == [0.5, 2.0]


def test_interleaved_view_with_stride_and_accessor_offset():
    """Two VEC3 accessors interleaved in one view of stride 24: position at byte 0,
    normal at byte 12 of each 24-byte vertex."""
    pos = np.array([[1, 2, 3], [4, 5, 6], [7, 8, 9]], "<f4")
    nrm = -pos
    blob = np.concatenate([pos, nrm], axis=1).tobytes()  # 3 vertices of 24 bytes
    view = g.BufferView(buffer=0, byteOffset=0, byteLength=len(blob), byteStride=24)
    gltf = g.GLTF2(bufferViews=[view], buffers=[g.Buffer(byteLength=len(blob))], accessors=[
        g.Accessor(bufferView=0, componentType=FLOAT, count=3, type="VEC3"),
        g.Accessor(bufferView=0, byteOffset=12, componentType=FLOAT, count=3, type="VEC3"),
    ])
    np.testing.assert_array_equal(gr._accessor(gltf, [blob], 0, "x"), pos)
    np.testing.assert_array_equal(gr._accessor(gltf, [blob], 1, "x"), nrm)
    # the last vertex's normal ends exactly at the view's end: 12 + 24 * 2 + 12 = 72
    assert len(blob) == 72
    view.byteLength = 71
    with pytest.raises(Invalid, match=r"accessors\[1\]: 3 values of 12 bytes from byte 12 run "
                                      r"past the 71 bytes of bufferViews\[0\]"):
        gr._accessor(gltf, [blob], 1, "x")
    np.testing.assert_array_equal(gr._accessor(gltf, [blob], 0, "x"), pos)  # ends at 60


def test_view_and_accessor_offsets_add_up():
    """The values start at view.byteOffset + accessor.byteOffset in the buffer."""
    values = np.array([10, 20, 30, 40, 50], "<f4")
    blob = values.tobytes()
    gltf = g.GLTF2(
        bufferViews=[g.BufferView(buffer=0, byteOffset=4, byteLength=16)],  # 20 30 40 50
        accessors=[g.Accessor(bufferView=0, byteOffset=8, componentType=FLOAT, count=2,
                              type="SCALAR")],  # 40 50
        buffers=[g.Buffer(byteLength=20)],
    )
    assert gr._accessor(gltf, [blob], 0, "x")[:, 0].tolist() == [40.0, 50.0]
    gltf.accessors[0].count = 3  # one more value runs past the 16 bytes of the view
    with pytest.raises(Invalid, match="3 values of 4 bytes from byte 8 run past the 16 bytes"):
        gr._accessor(gltf, [blob], 0, "x")
    gltf.accessors[0].count = 0  # no values: an empty (0, 1), whatever the offset
    assert gr._accessor(gltf, [blob], 0, "x").shape == (0, 1)


def test_view_byte_ranges_inside_the_buffer():
    blob = np.arange(4, dtype="<f4").tobytes()  # 16 bytes
    gltf = g.GLTF2(bufferViews=[g.BufferView(buffer=0, byteOffset=16, byteLength=0)],
                   accessors=[g.Accessor(bufferView=0, componentType=FLOAT, count=0,
                                         type="SCALAR")],
                   buffers=[g.Buffer(byteLength=16)])
    assert gr._accessor(gltf, [blob], 0, "x").shape == (0, 1)  # an empty view at the end
    gltf.bufferViews[0].byteOffset = 17
    with pytest.raises(Invalid, match=r"bufferViews\[0\]\.byteOffset: 17 is not in 0\.\.16"):
        gr._accessor(gltf, [blob], 0, "x")
    gltf.bufferViews[0].byteOffset, gltf.bufferViews[0].byteLength = 4, 12  # bytes 4..16
    gltf.accessors[0].count = 3
    assert gr._accessor(gltf, [blob], 0, "x")[:, 0].tolist() == [1.0, 2.0, 3.0]
    gltf.bufferViews[0].byteLength = 13
    with pytest.raises(Invalid, match=r"bufferViews\[0\]\.byteLength: 13 is not in 0\.\.12"):
        gr._accessor(gltf, [blob], 0, "x")
    gltf.bufferViews[0].byteLength = 12
    gltf.accessors[0].byteOffset = 13  # past the view's 12 bytes
    with pytest.raises(Invalid, match=r"accessors\[0\]\.byteOffset: 13 is not in 0\.\.12"):
        gr._accessor(gltf, [blob], 0, "x")
    gltf.accessors[0].byteOffset, gltf.accessors[0].count = 0, 17  # more values than bytes
    with pytest.raises(Invalid, match=r"accessors\[0\]\.count: 17 is not in 0\.\.16"):
        gr._accessor(gltf, [blob], 0, "x")


def test_byte_stride_bounds():
    """A stride is at least the value's width and at most 252 bytes (glTF's limits)."""
    blob = np.zeros(64, "<f4").tobytes()  # 256 bytes
    gltf = g.GLTF2(bufferViews=[g.BufferView(buffer=0, byteLength=256, byteStride=12)],
                   accessors=[g.Accessor(bufferView=0, componentType=FLOAT, count=1,
                                         type="VEC3")],
                   buffers=[g.Buffer(byteLength=256)])
    for stride in (12, 252):
        gltf.bufferViews[0].byteStride = stride
        assert gr._accessor(gltf, [blob], 0, "x").shape == (1, 3)
    for stride in (11, 253):
        gltf.bufferViews[0].byteStride = stride
        with pytest.raises(Invalid, match=rf"byteStride: {stride} is not in 12\.\.252"):
            gr._accessor(gltf, [blob], 0, "x")


def test_components_must_be_aligned():
    """A 2-byte component must start at an even byte of the view and of the buffer."""
    blob = np.arange(8, dtype="<u2").tobytes()
    gltf = g.GLTF2(bufferViews=[g.BufferView(buffer=0, byteOffset=0, byteLength=16)],
                   accessors=[g.Accessor(bufferView=0, byteOffset=2, componentType=USHORT,
                                         count=2, type="SCALAR")],
                   buffers=[g.Buffer(byteLength=16)])
    assert gr._accessor(gltf, [blob], 0, "x")[:, 0].tolist() == [1.0, 2.0]
    gltf.accessors[0].byteOffset = 1
    with pytest.raises(Invalid, match="not a multiple of its 2-byte components"):
        gr._accessor(gltf, [blob], 0, "x")
    gltf.accessors[0].byteOffset = 0
    gltf.bufferViews[0].byteOffset, gltf.bufferViews[0].byteLength = 1, 15  # the view is odd
    with pytest.raises(Invalid, match="not a multiple of its 2-byte components"):
        gr._accessor(gltf, [blob], 0, "x")
    gltf.bufferViews[0].byteOffset = 3
    gltf.accessors[0].byteOffset = 1  # 3 + 1: even in the buffer, odd in the view
    gltf.bufferViews[0].byteLength = 13
    with pytest.raises(Invalid, match="not a multiple of its 2-byte components"):
        gr._accessor(gltf, [blob], 0, "x")


def test_accessor_type_names():
    """The type is a string of at most 10 characters naming one of the five kinds."""
    gltf, buffers = _doc((np.zeros(4, "<f4"), FLOAT, "SCALAR"))
    gltf.accessors[0].type = "VEC4VEC4VE"  # 10 characters: read, and not a kind
    with pytest.raises(Invalid, match=r"accessors\[0\]\.type: 'VEC4VEC4VE' is not one of"):
        gr._accessor(gltf, buffers, 0, "x")
    gltf.accessors[0].type = "VEC4VEC4VEC"
    with pytest.raises(Invalid, match=r"accessors\[0\]\.type: 11 characters; at most 10"):
        gr._accessor(gltf, buffers, 0, "x")
    gltf.accessors[0].type = 4
    with pytest.raises(Invalid, match=r"accessors\[0\]\.type: expected a string"):
        gr._accessor(gltf, buffers, 0, "x")


def test_accessor_references_checked():
    gltf, buffers = _doc((np.zeros(3, "<f4"), FLOAT, "SCALAR"))
    with pytest.raises(Invalid, match="^x: 1 is not in 0..0$"):
        gr._accessor(gltf, buffers, 1, "x")
    with pytest.raises(Invalid, match="^x: -1 is not in 0..0$"):
        gr._accessor(gltf, buffers, -1, "x")
    assert gr._accessor(gltf, buffers, 0, "x").shape == (3, 1)
    gltf.accessors[0].componentType = 5124  # signed int: not a glTF component type
    with pytest.raises(Invalid, match=r"componentType: 5124 is not one of \[5120, 5121, 5122, "
                                      r"5123, 5125, 5126\]"):
        gr._accessor(gltf, buffers, 0, "x")
    gltf.accessors[0].componentType, gltf.accessors[0].type = FLOAT, "MAT3"
    with pytest.raises(Invalid, match="type: 'MAT3' is not one of SCALAR, VEC2, VEC3, VEC4, MAT4"):
        gr._accessor(gltf, buffers, 0, "x")
    gltf.accessors[0].type = "SCALAR"
    gltf.accessors[0].bufferView = 1
    with pytest.raises(Invalid, match=r"accessors\[0\]\.bufferView: 1 is not in 0\.\.0"):
        gr._accessor(gltf, buffers, 0, "x")
    gltf.accessors[0].bufferView = None
    with pytest.raises(Invalid, match="view-less"):
        gr._accessor(gltf, buffers, 0, "x")
    gltf.accessors[0].bufferView = 0
    gltf.accessors[0].sparse = g.Sparse(count=1)
    with pytest.raises(Invalid, match="sparse"):
        gr._accessor(gltf, buffers, 0, "x")
    gltf.accessors[0].sparse = None
    gltf.bufferViews[0].buffer = 1
    with pytest.raises(Invalid, match=r"bufferViews\[0\]\.buffer: 1 is not in 0\.\.0"):
        gr._accessor(gltf, buffers, 0, "x")
    with pytest.raises(Invalid, match="names a buffer, and the file has none"):
        gr._accessor(gltf, [], 0, "x")
    gltf.bufferViews = []
    with pytest.raises(Invalid, match="names a buffer view, and the file has none"):
        gr._accessor(gltf, buffers, 0, "x")
    gltf.accessors = []
    with pytest.raises(Invalid, match="^x: names an accessor, and the file has none"):
        gr._accessor(gltf, buffers, 0, "x")
    gltf.accessors = [None]
    with pytest.raises(Invalid, match=r"accessors\[0\]: expected an object"):
        gr._accessor(gltf, buffers, 0, "x")


def test_at_most_a_million_accessors():
    """MAX_ITEMS (1,000,000) accessors, buffer views, buffers... a document may hold."""
    assert gr.MAX_ITEMS == 1_000_000
    gltf = g.GLTF2(accessors=[None] * 1_000_000)
    with pytest.raises(Invalid, match=r"accessors\[0\]: expected an object"):  # the count is fine
        gr._accessor(gltf, [], 0, "x")
    gltf.accessors.append(None)
    with pytest.raises(Invalid, match="accessors: 1,000,001 items; at most 1,000,000"):
        gr._accessor(gltf, [], 0, "x")


def test_accessor_memory_is_eight_bytes_a_value():
    """Before the values are copied: 8 bytes (a float64) for each of count x components."""
    gltf, buffers = _doc((np.zeros(30, "<f4"), FLOAT, "VEC3"))  # 10 values of 3: 240 bytes
    with memory_limit(240):
        assert gr._accessor(gltf, buffers, 0, "x").shape == (10, 3)
    with memory_limit(239), pytest.raises(
        ParameterError, match=r"10 values of 3 need 240 bytes of memory, over the memory limit of 239"
    ):
        gr._accessor(gltf, buffers, 0, "x")


# ----------------------------------------------------------------------------- key times
def test_key_times_start_at_zero_or_later_and_increase():
    t = gr._key_times(np.array([[0.0], [0.5], [2.0]]), "w")
    assert t.tolist() == [0.0, 0.5, 2.0] and t.ndim == 1
    assert gr._key_times(np.array([[3.0]]), "w").tolist() == [3.0]  # one key, late
    assert gr._key_times(np.array([[0.0], [1e9]]), "w").tolist() == [0.0, 1e9]  # MAX_MAGNITUDE
    with pytest.raises(Invalid, match="^w: no key times$"):
        gr._key_times(np.zeros((0, 1)), "w")
    with pytest.raises(Invalid, match="^w: key time 0 is -0.5; key times start at 0"):
        gr._key_times(np.array([[-0.5], [1.0]]), "w")
    with pytest.raises(Invalid, match=r"^w: key time 2 \(1\.0 s\) does not come after key time 1 "
                                      r"\(1\.0 s\)"):
        gr._key_times(np.array([[0.0], [1.0], [1.0], [2.0]]), "w")
    with pytest.raises(Invalid, match=r"^w: key time 1 \(0\.5 s\) does not come after key time 0"):
        gr._key_times(np.array([[1.0], [0.5]]), "w")
    for bad, k in ((np.nan, 1), (np.inf, 1), (1.5e9, 1), (-np.inf, 1)):
        with pytest.raises(Invalid, match=f"^w: key time {k} is .*not a finite number"):
            gr._key_times(np.array([[0.0], [bad], [2e9]]), "w")
    with pytest.raises(Invalid, match="^w: key time 0 is -1500000000.0, not a finite"):
        gr._key_times(np.array([[-1.5e9], [0.0]]), "w")
    # a key of exactly 1e9 is fine: the error names the first one beyond
    with pytest.raises(Invalid, match="^w: key time 2 is inf, not a finite"):
        gr._key_times(np.array([[0.0], [1e9], [np.inf]]), "w")


# ----------------------------------------------------------------------------- sampling
def test_step_sampling_holds_the_last_key_at_or_before():
    """STEP: the value of the last key at or before each time (a time within 1e-9 s
    before a key counts as the key: float32 key times), the first before the first key,
    the last after the last."""
    times = np.array([0.0, 1.0, 2.0])
    values = np.array([[10.0], [20.0], [30.0]])
    at = np.array([-1.0, 0.0, 0.5, 1 - 5e-10, 1 - 1.5e-9, 1.0, 1.5, 2.0, 3.0])
    out = gr._sample(times, values, "STEP", at, False)
    assert out[:, 0].tolist() == [10, 10, 10, 20, 10, 20, 20, 30, 30]
    times = np.array([0.5, 1.0])  # a first key after 0: the first value before it
    assert gr._sample(times, values[:2], "STEP", np.array([0.0, 0.75]), False)[:, 0].tolist() == [
        10, 10]


def test_linear_sampling_interpolates_each_component():
    times = np.array([0.0, 1.0, 3.0])
    values = np.array([[0.0, 10.0, 1.0], [2.0, 20.0, 1.0], [6.0, -20.0, 1.0]])
    at = np.array([-1.0, 0.0, 0.25, 1.0, 2.0, 3.0, 4.0])
    out = gr._sample(times, values, "LINEAR", at, False)
    np.testing.assert_allclose(out, [[0, 10, 1], [0, 10, 1], [0.5, 12.5, 1], [2, 20, 1],
                                     [4, 0, 1], [6, -20, 1], [6, -20, 1]], rtol=1e-15)


def test_linear_quaternions_are_renormalised():
    """Halfway between the identity and a half turn about z, (0, 0, 1/2, 1/2) renormalised
    is a quarter turn (0, 0, s, s); opposite keys average to 0, which keeps the first key."""
    s = np.sqrt(0.5)
    times = np.array([0.0, 1.0])
    q = np.array([[0, 0, 0, 1.0], [0, 0, 1.0, 0]])
    out = gr._sample(times, q, "LINEAR", np.array([0.0, 0.5, 1.0]), True)
    np.testing.assert_allclose(out, [[0, 0, 0, 1], [0, 0, s, s], [0, 0, 1, 0]], atol=1e-15)
    assert gr._sample(times, q, "LINEAR", np.array([0.5]), False).tolist() == [[0, 0, 0.5, 0.5]]
    # halfway between w = 1 and w = -1 the interpolation is (x, 0, 0, 0) with x = half of
    # the second key's x: of length 1.5e-12 it is still normalised, of 1e-12 or less it is
    # taken as zero (the first key kept)
    for x, expected in ((3e-12, [1, 0, 0, 0]), (2e-12, [0, 0, 0, 1]), (0.0, [0, 0, 0, 1])):
        q = np.array([[0, 0, 0, 1.0], [x, 0, 0, -1.0]])
        out = gr._sample(times, q, "LINEAR", np.array([0.5]), True)
        assert out.tolist() == [expected], x


# ----------------------------------------------------------------------------- unit quaternions
def test_unit_quaternion_error_names_the_first_bad_one():
    q = np.array([[0, 0, 0, 1.0], [0, 0, 0, 1.0], [0, 0, 0, 3.0], [0, 0, 0, 5.0]])
    with pytest.raises(Invalid, match="^w: quaternion 2 has length 3;"):
        gr._unit_quaternions(q, "w")
    q[2, 3] = np.inf
    with pytest.raises(Invalid, match=r"^w: quaternion 2 holds \[0\.0, 0\.0, 0\.0, inf\]"):
        gr._unit_quaternions(q, "w")


# ----------------------------------------------------------------------------- node matrices
def _column_major(m44):
    return np.asarray(m44, float).T.ravel()


def test_node_matrix_gives_translation_and_rotation():
    """A column-major matrix: rotation R (90 degrees about z) and translation (1, 2, 3)."""
    r = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = r, [1, 2, 3]
    t, rot = gr._node_matrix(_column_major(m), "w")
    assert t.tolist() == [1, 2, 3]
    np.testing.assert_allclose(rot, r, atol=1e-15)
    assert gr._node_matrix(_column_major(np.eye(4)), "w") is None
    m[:3, :3] = 2.5 * r  # a uniform scale is divided out
    t, rot = gr._node_matrix(_column_major(m), "w")
    assert t.tolist() == [1, 2, 3]
    np.testing.assert_allclose(rot, r, atol=1e-15)
    m[:3, :3] = np.eye(3)  # a pure translation is not the identity
    t, rot = gr._node_matrix(_column_major(m), "w")
    assert t.tolist() == [1, 2, 3] and rot.tolist() == np.eye(3).tolist()


def test_node_matrix_refusals():
    m = np.eye(4)
    m[3] = [0, 0, 1, 1]  # projective
    with pytest.raises(Invalid, match="^w: the last row is not 0 0 0 1"):
        gr._node_matrix(_column_major(m), "w")
    for r, what in ((np.diag([1.0, 1, -1]), "determinant -1"), (np.diag([1.0, 1, 0]), "determinant 0"),
                    (np.diag([0.9e-4] * 3), "determinant 7.29e-13")):
        m = np.eye(4)
        m[:3, :3] = r
        with pytest.raises(Invalid, match=f"^w: {what};"):
            gr._node_matrix(_column_major(m), "w")
    m[:3, :3] = np.diag([1.1e-4] * 3)  # det 1.331e-12: a tiny scale, still a rotation
    np.testing.assert_allclose(gr._node_matrix(_column_major(m), "w")[1], np.eye(3), atol=1e-12)


def test_node_matrix_uneven_scale_within_the_unit_tolerance():
    """After the scale is divided out R R^T is I within UNIT_TOLERANCE (1e-3): diag(1, 1, b)
    over b^(1/3) has R R^T - I = diag(b^(-2/3) - 1, b^(-2/3) - 1, b^(4/3) - 1), so 1.5e-3 off
    for b^(4/3) = 1.0015 (refused), 0.5e-3 for 1.0005 (taken: its nearest rotation is I)."""
    for off, ok in ((1.5e-3, False), (0.5e-3, True)):
        b = (1 + off) ** 0.75
        m = np.eye(4)
        m[:3, :3] = np.diag([1.0, 1.0, b])
        if ok:
            np.testing.assert_allclose(gr._node_matrix(_column_major(m), "w")[1], np.eye(3),
                                       atol=1e-15)
        else:
            with pytest.raises(Invalid, match="shear or uneven scale"):
                gr._node_matrix(_column_major(m), "w")
    m = np.eye(4)
    m[0, 1] = 0.01  # a shear
    with pytest.raises(Invalid, match="shear or uneven scale"):
        gr._node_matrix(_column_major(m), "w")


# ----------------------------------------------------------------------------- the node graph
def _nodes(children, **fields):
    """Nodes ``0..len(children) - 1`` with those children lists (``None``: no field)."""
    return g.GLTF2(nodes=[g.Node(name=f"n{k}", children=c, **fields)
                          for k, c in enumerate(children)])


def test_check_nodes_gives_each_childs_parent():
    gltf = _nodes([[1, 3], [2], None, []])
    assert gr._check_nodes(gltf) == {1: 0, 3: 0, 2: 1}
    assert gr._check_nodes(_nodes([None, None])) == {}


def test_check_nodes_refuses_a_second_parent_itself_or_out_of_range():
    with pytest.raises(Invalid, match=r"^nodes\[2\]\.children: node 1 is already a child of node 0"):
        gr._check_nodes(_nodes([[1], [], [1]]))
    with pytest.raises(Invalid, match=r"^nodes\[1\]\.children: node 1 is already a child of node 1"):
        gr._check_nodes(_nodes([[], [1]]))  # its own child
    with pytest.raises(Invalid, match=r"^nodes\[0\]\.children: 3 is not in 0\.\.2"):
        gr._check_nodes(_nodes([[3], [], []]))
    with pytest.raises(Invalid, match=r"^nodes\[0\]\.children: 3 items; at most 2"):
        gr._check_nodes(_nodes([[1, 1, 1], []]))  # more children than nodes


def test_check_nodes_refuses_a_cycle():
    """0 -> 1 -> 2 -> 0: each node has one parent, and following them never ends."""
    with pytest.raises(Invalid, match=r"^nodes\[0\]: its ancestors form a cycle"):
        gr._check_nodes(_nodes([[1], [2], [0]]))
    with pytest.raises(Invalid, match=r"^nodes\[1\]: its ancestors form a cycle"):
        gr._check_nodes(_nodes([None, [2], [1]]))  # a cycle beside a lone root


def test_check_nodes_depth_limit():
    """A chain of MAX_DEPTH + 1 nodes puts its last MAX_DEPTH levels below the root (taken);
    one node more is one level too deep, and the error names that node."""
    n = MAX_DEPTH + 1
    chain = [[k + 1] for k in range(n - 1)] + [[]]
    assert len(gr._check_nodes(_nodes(chain))) == n - 1
    # the same chain listed leaves first (node k's parent is k + 1): depths found top down
    rev = [[]] + [[k - 1] for k in range(1, n)]
    assert gr._check_nodes(_nodes(rev))[0] == 1
    chain = [[k + 1] for k in range(n)] + [[]]
    with pytest.raises(Invalid, match=rf"^nodes\[{n}\]: {n} levels below its root; at most "
                                      rf"{MAX_DEPTH}"):
        gr._check_nodes(_nodes(chain))
    rev = [[]] + [[k - 1] for k in range(1, n + 1)]  # the deep one is node 0, found first
    with pytest.raises(Invalid, match=rf"^nodes\[0\]: {n} levels below its root"):
        gr._check_nodes(_nodes(rev))


def test_check_nodes_fields():
    gltf = _nodes([None])
    gltf.nodes[0].name = "x" * 1000
    gr._check_nodes(gltf)
    gltf.nodes[0].name = "x" * 1001
    with pytest.raises(Invalid, match=r"^nodes\[0\]\.name: 1,001 characters; at most 1,000"):
        gr._check_nodes(gltf)
    gltf = _nodes([None], mesh=1_000_000)
    gr._check_nodes(gltf)
    gltf.nodes[0].mesh = 1_000_001
    with pytest.raises(Invalid, match=r"^nodes\[0\]\.mesh: 1,000,001 is not in 0\.\.1,000,000"):
        gr._check_nodes(gltf)
    gltf = _nodes([None], translation=[1, 2])
    with pytest.raises(Invalid, match=r"^nodes\[0\]\.translation: expected 3 numbers"):
        gr._check_nodes(gltf)
    gltf = _nodes([None], rotation=[0, 0, 0, 1.0005])  # within the unit tolerance
    gr._check_nodes(gltf)
    gltf.nodes[0].rotation = [0, 0, 0, 1.002]
    with pytest.raises(Invalid, match=r"^nodes\[0\]\.rotation: quaternion 0 has length 1\.002"):
        gr._check_nodes(gltf)
    gltf = _nodes([None], matrix=[2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])
    with pytest.raises(Invalid, match=r"^nodes\[0\]\.matrix: not a rotation with a uniform"):
        gr._check_nodes(gltf)
    gltf = g.GLTF2(nodes=[g.Node(), "x"])
    with pytest.raises(Invalid, match=r"^nodes\[1\]: expected an object"):
        gr._check_nodes(gltf)


def test_at_most_four_nodes_a_joint():
    assert gr.MAX_NODES == 4 * MAX_JOINTS == 16384
    nodes = [g.Node()] * gr.MAX_NODES  # (one object: it has no children)
    assert gr._check_nodes(g.GLTF2(nodes=nodes)) == {}
    with pytest.raises(Invalid, match="^nodes: 16,385 items; at most 16,384"):
        gr._check_nodes(g.GLTF2(nodes=nodes + [g.Node()]))


# ----------------------------------------------------------------------------- buffers
def test_buffers_from_the_glb_chunk_a_data_uri_and_a_file(tmp_path):
    data = bytes(range(10))
    (tmp_path / "b.bin").write_bytes(data)
    gltf = g.GLTF2(buffers=[
        g.Buffer(byteLength=3),  # the GLB's binary chunk
        g.Buffer(byteLength=10, uri="data:application/octet-stream;base64,"
                 + base64.b64encode(data).decode()),
        g.Buffer(byteLength=10, uri="b.bin"),
        g.Buffer(uri="b.bin"),  # no byteLength: 0 bytes needed
        g.Buffer(uri="data:,"),  # no bytes at all, and none needed
    ])
    assert gltf.buffers[4].byteLength is None
    gltf.set_binary_blob(b"abc")
    assert gr._buffers(gltf, tmp_path / "x.gltf") == [b"abc", data, data, data, b""]
    gltf.buffers[2].byteLength = 11  # a buffer shorter than it says
    with pytest.raises(Invalid, match=r"^buffers\[2\]: holds fewer than its 11 bytes"):
        gr._buffers(gltf, tmp_path / "x.gltf")
    gltf.buffers[2].byteLength = 10
    gltf.buffers[0].byteLength = 4
    with pytest.raises(Invalid, match=r"^buffers\[0\]: holds fewer than its 4 bytes"):
        gr._buffers(gltf, tmp_path / "x.gltf")
    gltf.set_binary_blob(None)  # a .gltf whose buffer names no file: no bytes
    gltf.buffers[0].byteLength = 0
    with pytest.raises(Invalid, match=r"^buffers\[0\]: holds fewer than its 0 bytes"):
        gr._buffers(gltf, tmp_path / "x.gltf")


def test_buffer_byte_length_at_most_2_to_the_53(tmp_path):
    """byteLength is a whole number in 0..2^53 (JSON's exact integers)."""
    gltf = g.GLTF2(buffers=[g.Buffer(byteLength=2**53, uri="data:,")])
    with pytest.raises(Invalid, match=r"^buffers\[0\]: holds fewer than its 9007199254740992 "):
        gr._buffers(gltf, tmp_path / "x.gltf")
    gltf.buffers[0].byteLength = 2**53 + 1
    with pytest.raises(Invalid, match=r"^buffers\[0\]\.byteLength: 9,007,199,254,740,993 is not "
                                      r"in 0\.\.9,007,199,254,740,992"):
        gr._buffers(gltf, tmp_path / "x.gltf")


def test_buffer_uri_refusals(tmp_path):
    for uri, words in (("data:application/octet-stream;base64", r"buffers\[0\]\.uri: a data URI "
                                                                 "without ','"),
                       ("data:,@@", r"buffers\[0\]\.uri: not base64 data"),
                       ("data:,AAAA,AAAA", r"buffers\[0\]\.uri: not base64 data"),  # all after 1st ,
                       ("gone.bin", r"buffers\[0\]: missing file gone\.bin"),
                       (".", r"buffers\[0\]: missing file \.")):  # a folder is not a file
        gltf = g.GLTF2(buffers=[g.Buffer(byteLength=0, uri=uri)])
        with pytest.raises(Invalid, match="^" + words):
            gr._buffers(gltf, tmp_path / "x.gltf")
    gltf = g.GLTF2(buffers=[g.Buffer(byteLength=-1, uri="data:,")])
    with pytest.raises(Invalid, match=r"^buffers\[0\]\.byteLength: -1 is not in 0\.\."):
        gr._buffers(gltf, tmp_path / "x.gltf")


# ----------------------------------------------------------------------------- loading
def test_loading_needs_six_bytes_a_byte_of_file(tmp_path):
    """Before a file is parsed: 6 bytes of memory for each byte of it."""
    path = tmp_path / "a.gltf"
    path.write_text(g.GLTF2(nodes=[g.Node(name="a")]).gltf_to_json())
    size = path.stat().st_size
    with memory_limit(6 * size):
        gltf, buffers = gr._load(path)
    assert gltf.nodes[0].name == "a" and buffers == []
    with memory_limit(6 * size - 1), pytest.raises(ParseError, match="glTF file need"):
        gr._load(path)


# ----------------------------------------------------------------------------- extras
def _extras(**ours):
    return g.GLTF2(extras={"cyclecoord": ours})


def test_extras_read_and_checked():
    r90 = [[0, 0, 1], [0, 1, 0], [-1, 0, 0]]
    out = gr._extras(_extras(fps=24, frames=7, scale=0.01, up_rotation=r90, start_frame=0,
                             channels=[["root", "tx"], ["arm", "rz"]]))
    assert out.pop("up_rotation").tolist() == r90
    assert out == {"fps": 24.0, "frames": 7, "scale": 0.01, "start_frame": 0,
                   "channels": [("root", "tx"), ("arm", "rz")]}
    assert gr._extras(_extras(fps=0, frames=0)) == {}  # 0 is "not stored"
    assert gr._extras(g.GLTF2(extras={"other": 1})) == {}
    assert gr._extras(g.GLTF2(extras={"cyclecoord": None})) == {}
    assert gr._extras(g.GLTF2()) == {}
    assert gr._extras(_extras(start_frame=1_000_000_000))["start_frame"] == 1_000_000_000
    assert gr._extras(_extras(scale=1e-12))["scale"] == 1e-12


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("fps", 2e6, r"extras\.cyclecoord\.fps: 2000000\.0 is not in 1e-06\.\.1e\+06"),
        ("frames", -1, r"extras\.cyclecoord\.frames: -1 is not in 1\.\."),
        ("frames", 10_000_001, r"extras\.cyclecoord\.frames: 10,000,001 is not in 1\.\.10,000,000"),
        ("scale", 1e-13, r"extras\.cyclecoord\.scale: 1e-13 is not in 1e-12\.\.1e\+09"),
        ("scale", 0.0, r"extras\.cyclecoord\.scale: 0\.0 is not in 1e-12"),
        ("start_frame", -1, r"extras\.cyclecoord\.start_frame: -1 is not in 0\.\."),
        ("channels", [["a", "b", "c"]], r"extras\.cyclecoord\.channels\[0\]: 3 items; at most 2"),
        ("channels", [["a", 1]], r"extras\.cyclecoord\.channels\[0\]: expected a string"),
    ],
)
def test_extras_refusals(key, value, message):
    with pytest.raises(Invalid, match="^" + message):
        gr._extras(_extras(**{key: value}))


# ----------------------------------------------------------------------------- node tracks
def _animated(nodes, tracks, interpolation="LINEAR", **fields):
    """A document of ``nodes`` whose animation has one sampler and one channel per track
    ``(node, path, times, values)``; sampler k reads accessors 2k (times) and 2k + 1."""
    arrays, samplers, channels = [], [], []
    for k, (node, path, times, values) in enumerate(tracks):
        values = np.asarray(values, "<f4")
        kind = {1: "SCALAR", 3: "VEC3", 4: "VEC4"}[values.shape[-1]]
        arrays += [(np.asarray(times, "<f4"), FLOAT, "SCALAR"), (values, FLOAT, kind)]
        samplers.append(g.AnimationSampler(input=2 * k, output=2 * k + 1,
                                           interpolation=interpolation))
        channels.append(g.AnimationChannel(
            sampler=k, target=g.AnimationChannelTarget(node=node, path=path)))
    animations = [g.Animation(samplers=samplers, channels=channels)] if tracks else []
    return _doc(*arrays, nodes=nodes, animations=animations, **fields)


def _save(doc, buffers, path):
    doc.buffers[0].uri = "data:application/octet-stream;base64," + base64.b64encode(
        buffers[0]).decode()
    path.write_text(doc.gltf_to_json())
    return path


S = np.sqrt(0.5)


def test_tracks_without_animation_are_one_frame_of_the_rest_pose():
    """No animation: one frame at 30 fps; each node's translation (default 0) and rotation
    (default identity, a near-unit one normalised), or its matrix."""
    m = np.eye(4)
    m[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    m[:3, 3] = [4, 5, 6]
    nodes = [g.Node(translation=[1, 2, 3], rotation=[0, 0, S, S]), g.Node(),
             g.Node(rotation=[0, 0, 0, 1.0008]), g.Node(matrix=m.T.ravel().tolist())]
    doc, buffers = _animated(nodes, [])
    trans, rots, fps = gr._node_tracks(doc, buffers)
    assert fps == 30.0 and trans.shape == (1, 4, 3) and rots.shape == (1, 4, 3, 3)
    assert trans[0].tolist() == [[1, 2, 3], [0, 0, 0], [0, 0, 0], [4, 5, 6]]
    rz90 = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    np.testing.assert_allclose(rots[0], [rz90, np.eye(3), np.eye(3), rz90], atol=1e-15)


def test_frame_rate_and_count_from_the_key_times():
    """Keys 0, 0.25 .. 1 s: (5 - 1) / (1 - 0) = 4 fps, round(1 s x 4) + 1 = 5 frames, each
    a key; the longest sampler sets the rate, the latest key the length."""
    times = [0, 0.25, 0.5, 0.75, 1.0]
    values = [[k, 2 * k, 0] for k in range(5)]
    doc, buffers = _animated([g.Node(), g.Node()], [(0, "translation", times, values),
                                                    (1, "translation", [0, 1.5], [[0] * 3] * 2)])
    trans, rots, fps = gr._node_tracks(doc, buffers)
    assert fps == 4.0 and trans.shape == (7, 2, 3)  # 1.5 s at 4 fps: 7 frames
    assert trans[:, 0].tolist() == values + [values[-1]] * 2  # held after the last key
    np.testing.assert_array_equal(rots, np.broadcast_to(np.eye(3), (7, 2, 3, 3)))


def test_frame_rate_from_keys_that_start_late():
    """Keys at 0.5, 1, 1.5 s: 2 keys a second; 4 frames (0 to 1.5 s), the first before
    the first key takes its value, then 0.5 s apart read each key."""
    doc, buffers = _animated([g.Node()], [(0, "translation", [0.5, 1, 1.5],
                                           [[1, 0, 0], [2, 0, 0], [3, 0, 0]])])
    trans, _, fps = gr._node_tracks(doc, buffers)
    assert fps == 2.0 and trans[:, 0, 0].tolist() == [1, 1, 2, 3]


@pytest.mark.parametrize("true_fps, read", [(120.0, 120.0), (10.0009, 10.0), (10.0011, None)])
def test_frame_rate_rounded_when_within_a_ten_thousandth(true_fps, read):
    """float32 key times k / 120 give 120.0000x fps, rounded to 120; a rate within 1e-4 of
    its own size of a whole number is that number (10.0009 -> 10), one further is kept."""
    n = 121 if true_fps == 120 else 2
    times = np.arange(n) / true_fps
    doc, buffers = _animated([g.Node()], [(0, "translation", times, np.zeros((n, 3)))])
    _, _, fps = gr._node_tracks(doc, buffers)
    t32 = times.astype(np.float32).astype(float)
    if read is None:
        assert fps == (n - 1) / (t32[-1] - t32[0])
        assert abs(fps - 10.0011) < 1e-5
    else:
        assert fps == read


def test_frame_rate_bounds_and_defaults():
    # keys 1e6 s apart: 1e-6 fps, MIN_FPS itself (2 frames: 0 and 1e6 s)
    doc, buffers = _animated([g.Node()], [(0, "translation", [0, 1e6], np.zeros((2, 3)))])
    trans, _, fps = gr._node_tracks(doc, buffers)
    assert fps == 1e-6 and trans.shape[0] == 2
    # keys float32(1e-6) s apart: 999,999.99 fps, within 1e-4 of 1e6: MAX_FPS itself
    doc, buffers = _animated([g.Node()], [(0, "translation", [0, 1e-6], np.zeros((2, 3)))])
    trans, _, fps = gr._node_tracks(doc, buffers)
    assert fps == 1e6 and trans.shape[0] == 2
    doc, buffers = _animated([g.Node()], [(0, "translation", [0, 2e6], np.zeros((2, 3)))])
    with pytest.raises(Invalid, match=r"^animations\[0\]: key times 2e\+06 s apart over 2 keys "
                                      r"make 5e-07 frames per second; 1e-06\.\.1e\+06"):
        gr._node_tracks(doc, buffers)
    # a single key: no rate in the keys, 30 fps; round(0.5 x 30) + 1 = 16 frames
    doc, buffers = _animated([g.Node()], [(0, "translation", [0.5], [[1, 2, 3]])])
    trans, _, fps = gr._node_tracks(doc, buffers)
    assert fps == 30.0 and trans.shape[0] == 16 and (trans[:, 0] == [1, 2, 3]).all()
    # the stored rate and frame count win over the keys
    doc, buffers = _animated([g.Node()], [(0, "translation", [0, 1], [[0, 0, 0], [6, 0, 0]])])
    trans, _, fps = gr._node_tracks(doc, buffers, {"fps": 3.0, "frames": 5})
    assert fps == 3.0 and trans[:, 0, 0].tolist() == pytest.approx([0, 2, 4, 6, 6])


def test_frame_count_limit():
    """end x fps + 1 frames: 9,999,999 s at 1 fps make MAX_FRAMES (then the memory for
    them is checked), 10,000,000 s one too many."""
    doc, buffers = _animated([g.Node()], [(0, "translation", [0, MAX_FRAMES - 1],
                                           np.zeros((2, 3)))])
    with memory_limit(1e6), pytest.raises(ParameterError, match="^10,000,000 frames of 1 nodes "
                                                                "need 3.84 GB"):
        gr._node_tracks(doc, buffers, {"fps": 1.0})
    doc, buffers = _animated([g.Node()], [(0, "translation", [0, MAX_FRAMES], np.zeros((2, 3)))])
    with pytest.raises(Invalid, match=r"^animations\[0\]: 1e\+07 s at 1 fps are 1e\+07 frames; "
                                      r"at most 10,000,000"):
        gr._node_tracks(doc, buffers, {"fps": 1.0})


def test_track_memory_is_384_bytes_a_node_and_frame():
    doc, buffers = _animated([g.Node(), g.Node()], [(0, "translation", [0, 0.1, 0.2, 0.3, 0.4],
                                                     np.zeros((5, 3)))])
    with memory_limit(384 * 5 * 2):  # 5 frames at 10 fps, 2 nodes
        assert gr._node_tracks(doc, buffers)[0].shape == (5, 2, 3)
    with memory_limit(384 * 5 * 2 - 1), pytest.raises(ParameterError, match="^5 frames of 2 nodes"):
        gr._node_tracks(doc, buffers)
    empty = g.GLTF2(nodes=[])  # no node still counts as one
    with memory_limit(383), pytest.raises(ParameterError, match="^1 frames of 0 nodes need 384"):
        gr._node_tracks(empty, [])
    with memory_limit(384):
        assert gr._node_tracks(empty, [])[0].shape == (1, 0, 3)


def test_rotation_channels_step_linear_and_cubic():
    """A quarter turn about z between keys 0 and 1 s (at 2 fps: frames 0, 0.5, 1 s): STEP
    holds, LINEAR passes through an eighth of a turn, CUBICSPLINE reads the middle of each
    (in-tangent, value, out-tangent) triple and goes as LINEAR."""
    q = [[0, 0, 0, 1], [0, 0, S, S]]
    c8, s8 = np.cos(np.pi / 8), np.sin(np.pi / 8)
    eighth = [[c8 * c8 - s8 * s8, -2 * s8 * c8, 0], [2 * s8 * c8, c8 * c8 - s8 * s8, 0],
              [0, 0, 1]]
    quarter = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    for interp, middle in (("STEP", np.eye(3)), ("LINEAR", eighth), ("CUBICSPLINE", eighth)):
        values = q if interp != "CUBICSPLINE" else [[9, 9, 9, 9], q[0], [7, 7, 7, 7],
                                                     [-9, 0, 0, 0], q[1], [0, 5, 0, 0]]
        doc, buffers = _animated([g.Node()], [(0, "rotation", [0, 1], values)], interp)
        _, rots, fps = gr._node_tracks(doc, buffers, {"fps": 2.0})
        np.testing.assert_allclose(rots[:, 0], [np.eye(3), middle, quarter], atol=1e-7)


def test_channels_that_are_not_read_or_are_refused():
    base = [(0, "translation", [0, 1], [[1, 0, 0], [2, 0, 0]])]
    doc, buffers = _animated([g.Node(), g.Node()], base)
    doc.animations[0].channels.append(g.AnimationChannel(  # scale and weights: not read
        sampler=0, target=g.AnimationChannelTarget(node=1, path="scale")))
    doc.animations[0].channels.append(g.AnimationChannel(
        sampler=0, target=g.AnimationChannelTarget(node=None, path="translation")))
    trans, _, _ = gr._node_tracks(doc, buffers)
    assert trans[:, 1].tolist() == [[0, 0, 0]] * 2 and trans[:, 0, 0].tolist() == [1, 2]
    doc.animations[0].channels[0].target.node = 2
    with pytest.raises(Invalid, match=r"^animations\[0\]\.channels\[0\]\.target\.node: 2 is not "
                                      r"in 0\.\.1"):
        gr._node_tracks(doc, buffers)
    doc.animations[0].channels[0].target.node = 0
    doc.animations[0].channels[0].sampler = 1
    with pytest.raises(Invalid, match=r"^animations\[0\]\.channels\[0\]\.sampler: 1 is not in "
                                      r"0\.\.0"):
        gr._node_tracks(doc, buffers)
    doc.animations[0].samplers = []
    with pytest.raises(Invalid, match=r"channels\[0\]\.sampler: the animation has no samplers"):
        gr._node_tracks(doc, buffers)
    doc, buffers = _animated([g.Node()], base, "CUBIC")
    with pytest.raises(Invalid, match=r"samplers\[0\]\.interpolation: 'CUBIC' is not LINEAR"):
        gr._node_tracks(doc, buffers)
    doc, buffers = _animated([g.Node()], base)
    doc.animations[0].samplers[0].input = 1  # VEC3 key times
    with pytest.raises(Invalid, match=r"samplers\[0\]\.input: key times are scalars, accessor "
                                      r"has 3"):
        gr._node_tracks(doc, buffers)


def test_output_values_checked():
    """Outputs hold one value (three for a cubic spline) a key, of 3 (translation) or 4
    (rotation) components; translations and tangents finite and at most 1e9."""
    doc, buffers = _animated([g.Node()], [(0, "translation", [0, 1], [[1, 0, 0]] * 3)])
    with pytest.raises(Invalid, match=r"samplers\[0\]\.output: 3 values of 3 for the "
                                      r"translation of 2 keys; expected 2 of 3"):
        gr._node_tracks(doc, buffers)
    doc, buffers = _animated([g.Node()], [(0, "rotation", [0, 1], [[1, 0, 0]] * 2)])
    with pytest.raises(Invalid, match="2 values of 3 for the rotation of 2 keys; expected 2 of 4"):
        gr._node_tracks(doc, buffers)
    doc, buffers = _animated([g.Node()], [(0, "translation", [0, 1], [[1, 0, 0]] * 2)],
                             "CUBICSPLINE")
    with pytest.raises(Invalid, match="2 values of 3 for the translation of 2 keys; expected 6"):
        gr._node_tracks(doc, buffers)
    for big, ok in ((1e9, True), (-1e9, True), (2e9, False), (np.inf, False), (np.nan, False)):
        doc, buffers = _animated([g.Node()], [(0, "translation", [0, 1],
                                               [[0, 0, 0], [0, big, 0]])])
        if ok:
            assert gr._node_tracks(doc, buffers)[0][-1, 0, 1] == big
        else:
            with pytest.raises(Invalid, match="translations that are not finite"):
                gr._node_tracks(doc, buffers)
        doc, buffers = _animated([g.Node()], [(0, "translation", [0], [[big, 0, 0], [0, 0, 0],
                                                                      [0, 0, big]])],
                                 "CUBICSPLINE")
        if ok:
            assert gr._node_tracks(doc, buffers)[0].tolist() == [[[0, 0, 0]]]
        else:
            with pytest.raises(Invalid, match="tangents that are not finite"):
                gr._node_tracks(doc, buffers)


# ----------------------------------------------------------------------------- skeleton nodes
def test_joint_nodes_parents_first_in_child_order():
    """Without a skin every node but the meshes: roots in index order, each followed by its
    children's subtrees in the order the node lists them."""
    nodes = [g.Node(children=[3, 5, 1]), g.Node(children=[2]), g.Node(), g.Node(mesh=0),
             g.Node(), g.Node()]
    order, parents = gr._joint_nodes(g.GLTF2(nodes=nodes))
    assert order == [0, 5, 1, 2, 4] and parents == [-1, 0, 0, 2, -1]


def test_joint_nodes_of_a_skin():
    """A skin's joints (any order), whatever else the nodes hold; a joint whose parent is
    not a joint is a root."""
    nodes = [g.Node(children=[1]), g.Node(children=[2, 3]), g.Node(), g.Node(children=[4]),
             g.Node(mesh=0)]
    order, parents = gr._joint_nodes(g.GLTF2(nodes=nodes, skins=[g.Skin(joints=[4, 3, 1])]))
    assert order == [1, 3, 4] and parents == [-1, 0, 1]
    with pytest.raises(Invalid, match=r"^skins\[0\]\.joints: 5 is not in 0\.\.4"):
        gr._joint_nodes(g.GLTF2(nodes=nodes, skins=[g.Skin(joints=[5])]))
    with pytest.raises(Invalid, match="^no skeleton nodes"):
        gr._joint_nodes(g.GLTF2(nodes=nodes, skins=[g.Skin(joints=[])]))
    with pytest.raises(Invalid, match=r"^skins\[0\]: expected an object"):
        gr._joint_nodes(g.GLTF2(nodes=nodes, skins=["x"]))
    with pytest.raises(Invalid, match="^no skeleton nodes"):
        gr._joint_nodes(g.GLTF2(nodes=[g.Node(mesh=0)]))


def test_at_most_max_joints_skeleton_nodes():
    nodes = [g.Node() for _ in range(MAX_JOINTS)]
    assert len(gr._joint_nodes(g.GLTF2(nodes=nodes))[0]) == MAX_JOINTS
    with pytest.raises(Invalid, match="^4,097 skeleton nodes; at most 4,096"):
        gr._joint_nodes(g.GLTF2(nodes=nodes + [g.Node()]))


def test_joint_positions_compose_the_nodes(tmp_path):
    """World positions by hand: the root at (1, 0, 0) turned a quarter about z puts its
    child's offset (2, 0, 0) along y: (1, 2, 0); its grandchild (0, 0, 3) at (1, 2, 3).
    The root's translation animated to (1, 0, 5) at 1 s moves all three up 5."""
    nodes = [g.Node(name="root", translation=[1, 0, 0], rotation=[0, 0, S, S], children=[1]),
             g.Node(translation=[2, 0, 0], children=[2]), g.Node(translation=[0, 0, 3])]
    doc, buffers = _animated(nodes, [(0, "translation", [0, 1], [[1, 0, 0], [1, 0, 5]])])
    names, pos, fps = gr.gltf_joint_positions(_save(doc, buffers, tmp_path / "a.gltf"))
    assert names == ["root", "node1", "node2"] and fps == 1.0
    np.testing.assert_allclose(pos, [[[1, 0, 0], [1, 2, 0], [1, 2, 3]],
                                     [[1, 0, 5], [1, 2, 5], [1, 2, 8]]], atol=1e-12)


def test_foreign_file_reads_one_joint_a_node(tmp_path):
    """A glTF from elsewhere: joints named after the nodes (node<k> when unnamed), rest
    offsets their first frame's translations, tx ty tz on the root and on nodes whose
    translation is animated, rotations ZYX in degrees."""
    nodes = [g.Node(name="hips", translation=[0, 1, 0], children=[1, 2]),
             g.Node(translation=[0.2, 0, 0], rotation=[0, 0, S, S]),
             g.Node(name="leg", translation=[-0.2, 0, 0])]
    doc, buffers = _animated(nodes, [(2, "translation", [0, 1], [[-0.2, 0, 0], [-0.2, -1, 0]])])
    m = gr.read_gltf(_save(doc, buffers, tmp_path / "a.gltf"))
    skel = m.skeleton
    assert skel.names == ["hips", "node1", "leg"] and skel.source_format == "gltf"
    assert skel.name == "a" and [j.parent for j in skel.joints] == [-1, 0, 0]
    move, turn = ("tx", "ty", "tz", "rx", "ry", "rz"), ("rx", "ry", "rz")
    assert [j.dofs for j in skel.joints] == [move, turn, move]
    assert all(j.rotation_order == "ZYX" for j in skel.joints)
    np.testing.assert_allclose([j.offset for j in skel.joints], [[0, 1, 0], [0.2, 0, 0],
                                                                 [-0.2, 0, 0]], atol=1e-7)
    assert m.fps == 1.0 and m.n_frames == 2
    rz = m.channels.index(("node1", "rz"))
    assert m.frames[:, rz].tolist() == pytest.approx([90, 90])
    ty = m.channels.index(("leg", "ty"))
    assert m.frames[:, ty].tolist() == pytest.approx([0, -1])


def test_foreign_file_refusals(tmp_path):
    doc, buffers = _animated([g.Node(name="a"), g.Node(name="b")], [])
    with pytest.raises(ParseError, match="the skeleton nodes have 2 roots; one is supported"):
        gr.read_gltf(_save(doc, buffers, tmp_path / "two.gltf"))
    doc, buffers = _animated([], [])
    with pytest.raises(ParseError, match="the file holds no nodes"):
        gr.read_gltf(_save(doc, buffers, tmp_path / "none.gltf"))


# ----------------------------------------------------------------------------- our own files
def _ours(tmp_path, **write):
    """A 3-frame arm written by write_gltf (start frame 7, root channels reordered), as a
    pygltflib document to edit; the motion."""
    from cyclecoord.io.gltf import write_gltf
    from cyclecoord.motion import Motion
    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
                   Joint("arm", 0, [0, 2, 0], ("rx", "rz"), "ZX", end_site=[1, 0, 0])),
                  name="arm")
    frames = np.zeros((3, 8))
    frames[:, 0] = [0, 1, 2]
    frames[:, 7] = [0, 30, 60]  # arm rz
    m = Motion(frames, sk.channels, fps=10, skeleton=sk, start_frame=7)
    m = m.select([m.channels[k] for k in (7, 6, 0, 1, 2, 3, 4, 5)])
    write_gltf(m, tmp_path / "a.gltf", mesh=False, **write)
    return g.GLTF2.load(str(tmp_path / "a.gltf")), m


def test_our_file_gives_back_the_motion(tmp_path):
    """The stored skeleton, channels in their order, start frame, scale divided out."""
    doc, m = _ours(tmp_path, scale=0.5)
    assert doc.nodes[0].translation == [0, 0, 0] and doc.nodes[1].translation == [0, 1, 0]
    back = gr.read_gltf(tmp_path / "a.gltf")
    assert back.channels == m.channels and back.start_frame == 7 and back.fps == 10
    assert back.skeleton.joints[1].offset.tolist() == [0, 2, 0]
    np.testing.assert_allclose(back.frames, m.frames, atol=1e-4)
    # without a start frame stored: 0; with a channel list that is not all of them: the
    # skeleton's own order
    del doc.extras["cyclecoord"]["start_frame"]
    doc.extras["cyclecoord"]["channels"] = [["arm", "rz"]]
    (tmp_path / "b.gltf").write_text(doc.gltf_to_json())
    back = gr.read_gltf(tmp_path / "b.gltf")
    assert back.start_frame == 0 and back.channels == m.skeleton.channels
    # a stored joint without its node
    doc.nodes[1].name = "elbow"
    (tmp_path / "c.gltf").write_text(doc.gltf_to_json())
    with pytest.raises(ParseError, match=r"joints \['arm'\] of the stored skeleton have no node"):
        gr.read_gltf(tmp_path / "c.gltf")


def test_our_file_without_a_stored_scale_is_in_metres(tmp_path):
    doc, m = _ours(tmp_path, scale=0.5)
    del doc.extras["cyclecoord"]["scale"]
    (tmp_path / "b.gltf").write_text(doc.gltf_to_json())
    back = gr.read_gltf(tmp_path / "b.gltf")
    tx = back.channels.index(("root", "tx"))
    np.testing.assert_allclose(back.frames[:, tx], [0, 0.5, 1], atol=1e-6)  # scale 1


def test_animation_entries_must_be_objects():
    doc, buffers = _animated([g.Node()], [(0, "translation", [0, 1], np.zeros((2, 3)))])
    doc.animations[0].channels.append(g.AnimationChannel(sampler=0, target=None))
    with pytest.raises(Invalid, match=r"^animations\[0\]\.channels\[1\]: expected an object with "
                                      r"a target"):
        gr._node_tracks(doc, buffers)
    doc.animations[0].channels[1] = "x"
    with pytest.raises(Invalid, match=r"^animations\[0\]\.channels\[1\]: expected an object"):
        gr._node_tracks(doc, buffers)
    doc.animations[0].samplers.append("x")
    with pytest.raises(Invalid, match=r"^animations\[0\]\.samplers\[1\]: expected an object"):
        gr._node_tracks(doc, buffers)
    doc.animations = ["x"]
    with pytest.raises(Invalid, match=r"^animations\[0\]: expected an object"):
        gr._node_tracks(doc, buffers)


def test_our_turned_file_is_turned_back(tmp_path):
    """A file whose root the writer turned (a Z-up rig made y-up, up_rotation stored): the
    reader undoes the turn, translations and rotations, and gives back the frames."""
    from cyclecoord.io.gltf import _build

    _, m = _ours(tmp_path)
    frames = m.frames.copy()
    frames[:, m.channels.index(("root", "rx"))] = [10, 20, 30]
    frames[:, m.channels.index(("root", "ty"))] = [1, 2, 3]
    m = m.with_frames(frames)
    up = np.array([[1.0, 0, 0], [0, 0, 1], [0, -1, 0]])
    doc, data = _build(m, 1.0, False, up)
    path = _save(doc, [data], tmp_path / "turned.gltf")
    names, pos, _ = gr.gltf_joint_positions(path)  # the file's own nodes: turned
    fk = m.positions().positions  # root, arm, arm/end
    np.testing.assert_allclose(pos, fk @ up.T, atol=1e-5)
    back = gr.read_gltf(path)
    np.testing.assert_allclose(back.frames, m.frames, atol=1e-4)
