"""glTF and USD files that once ended in a traceback, a hang or a huge allocation (issue 26
part 1), each built from a small file cyclecoord writes: now one ParseError naming the
file and the entry (``accessors[3]``, ``nodes[2].children``, ``extras.cyclecoord.fps``,
``endTimeCode``, ``customData.cyclecoord``, ...)."""

import json
import struct
import threading

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParseError


@pytest.fixture(scope="module")
def walk():
    return cc.datasets.example_capture().motion[:20]


def one_line(exc_info, path) -> str:
    text = str(exc_info.value)
    assert "\n" not in text and str(path) in text, text
    return text


# ------------------------------------------------------------------------------ glTF
def read_glb(path):
    data = path.read_bytes()
    (n,) = struct.unpack("<I", data[12:16])
    doc = json.loads(data[20 : 20 + n])
    (m,) = struct.unpack("<I", data[20 + n : 24 + n])
    return doc, bytearray(data[28 + n : 28 + n + m])


def write_glb(path, doc, blob):
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    blob = bytes(blob) + b"\0" * (-len(blob) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(blob), b"BIN\0")
    body += blob
    path.write_bytes(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)


@pytest.fixture
def glb(tmp_path, walk):
    path = tmp_path / "w.glb"
    cc.save(walk, path)
    return path


def _times_accessor(doc) -> int:
    return doc["animations"][0]["samplers"][0]["input"]


def _refused(path, *words):
    with pytest.raises(ParseError) as e:
        cc.load(path)
    text = one_line(e, path)
    for w in words:
        assert w in text, text
    return text


@pytest.mark.parametrize(
    "edit, words",
    [
        (lambda d: d["animations"][0]["samplers"][0].update(input=9999), ["samplers[0].input"]),
        (lambda d: d["accessors"][0].update(bufferView=9999), ["accessors[0].bufferView"]),
        (lambda d: d["bufferViews"][0].update(buffer=3), ["bufferViews[0].buffer"]),
        (lambda d: d["bufferViews"][0].update(byteLength=10**9), ["bufferViews[0].byteLength"]),
        (lambda d: d["accessors"][0].update(count=10**7), ["accessors[0]"]),
        (lambda d: d["animations"][0]["channels"][0]["target"].update(node=10**6), ["target.node"]),
    ],
)
def test_indices_and_byte_ranges_out_of_bounds(glb, edit, words):
    doc, blob = read_glb(glb)
    edit(doc)
    write_glb(glb, doc, blob)
    _refused(glb, *words)


def test_key_times_at_infinity_and_too_close(glb):
    doc, blob = read_glb(glb)
    view = doc["bufferViews"][doc["accessors"][_times_accessor(doc)]["bufferView"]]
    start = view.get("byteOffset", 0)
    times = np.frombuffer(bytes(blob[start : start + view["byteLength"]]), "<f4").copy()
    bad = times.copy()
    bad[-1] = np.inf
    blob[start : start + bad.nbytes] = bad.tobytes()
    del doc["extras"]["cyclecoord"]["fps"], doc["extras"]["cyclecoord"]["frames"]
    write_glb(glb, doc, blob)
    _refused(glb, "key time 19", "inf")
    bad = (np.arange(len(times)) * 1e-7).astype("<f4")  # 10 million frames a second
    blob[start : start + bad.nbytes] = bad.tobytes()
    write_glb(glb, doc, blob)
    _refused(glb, "frames per second")
    bad = times[::-1].copy()  # backwards
    blob[start : start + bad.nbytes] = bad.tobytes()
    write_glb(glb, doc, blob)
    _refused(glb, "does not come after")


@pytest.mark.parametrize(
    "key, value, words",
    [
        ("fps", float("inf"), ["extras.cyclecoord.fps"]),
        ("frames", 10**12, ["extras.cyclecoord.frames", "1,000,000,000,000"]),
        ("scale", "x", ["extras.cyclecoord.scale", "expected a number"]),
        ("start_frame", "x", ["extras.cyclecoord.start_frame"]),
        ("up_rotation", [[1, 0, 0], [0, 1, 0], [0, 0, 2]], ["up_rotation", "rotation"]),
        ("channels", [["root"]], ["extras.cyclecoord.channels[0]"]),
        ("skeleton", {"joints": [{"name": "a", "parent": 5}]}, ["skeleton.joints[0].parent"]),
        ("skeleton", {"joints": [{"name": "a", "offset": ["x", 0, 0]}]}, ["joints[0].offset"]),
    ],
)
def test_extras_of_the_wrong_types(glb, key, value, words):
    doc, blob = read_glb(glb)
    doc["extras"]["cyclecoord"][key] = value
    write_glb(glb, doc, blob)
    _refused(glb, *words)


def test_extras_that_are_a_string(glb):
    doc, blob = read_glb(glb)
    doc["extras"]["cyclecoord"] = "a string"
    write_glb(glb, doc, blob)
    _refused(glb, "extras.cyclecoord", "expected an object")
    doc["extras"] = {"cyclecoord": None, "other": "x"}  # not ours: read as a foreign file
    write_glb(glb, doc, blob)
    assert cc.load(glb).n_frames == 20
    doc["extras"] = "a string"  # pygltflib reads extras as an object
    write_glb(glb, doc, blob)
    _refused(glb, "not a readable glTF file")


def test_a_node_cycle_is_refused_not_followed(glb):
    doc, blob = read_glb(glb)
    doc["nodes"][2].setdefault("children", []).append(1)  # 1 is 2's parent
    del doc["extras"]
    write_glb(glb, doc, blob)
    result = {}

    def read():
        try:
            cc.load(glb)
        except ParseError as exc:
            result["error"] = exc

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(30)
    assert not reader.is_alive(), "reading a node cycle hangs"
    assert "nodes[2].children" in one_line(type("E", (), {"value": result["error"]}), glb)


def test_rotations_that_are_not_unit_quaternions(glb):
    doc, blob = read_glb(glb)
    s = next(c["sampler"] for c in doc["animations"][0]["channels"]
             if c["target"]["path"] == "rotation")
    acc = doc["accessors"][doc["animations"][0]["samplers"][s]["output"]]
    view = doc["bufferViews"][acc["bufferView"]]
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    blob[start : start + 16] = np.array([np.nan, 0, 0, 1], "<f4").tobytes()
    write_glb(glb, doc, blob)
    _refused(glb, f"samplers[{s}].output", "quaternion 0")
    blob[start : start + 16] = np.zeros(4, "<f4").tobytes()
    write_glb(glb, doc, blob)
    _refused(glb, f"samplers[{s}].output", "length 0")
    doc["nodes"][0]["rotation"] = [0, 0, 0, 2]
    write_glb(glb, doc, blob)
    _refused(glb, "nodes[0].rotation")


def test_a_gltf_buffer_in_a_bad_data_uri(tmp_path, walk):
    path = tmp_path / "w.gltf"
    cc.save(walk, path)
    doc = json.loads(path.read_text())
    doc["buffers"][0]["uri"] = "data:application/octet-stream;base64,@@@"
    path.write_text(json.dumps(doc))
    _refused(path, "buffers[0].uri", "base64")


# ------------------------------------------------------------------------------ USD
@pytest.fixture
def usda(tmp_path, walk):
    pytest.importorskip("pxr")
    path = tmp_path / "w.usda"
    cc.save(walk, path)
    return path


@pytest.mark.parametrize(
    "value, words",
    [("nan", ["endTimeCode nan"]), ("inf", ["endTimeCode inf"]), ("1e9", ["1,000,000,001 frames"]),
     ("-5", ["comes before startTimeCode"])],
)
def test_usd_end_time_codes(usda, value, words):
    usda.write_text(usda.read_text().replace("endTimeCode = 19", f"endTimeCode = {value}", 1))
    _refused(usda, *words)


def test_usd_custom_data_that_is_not_json(usda):
    text = usda.read_text()
    a = text.index("string cyclecoord = '") + len("string cyclecoord = '")
    usda.write_text(text[:a] + "{not json" + text[a:])
    _refused(usda, "customData.cyclecoord", "not valid JSON")
    usda.write_text(text[:a] + "[" * 100 + text[a:])
    _refused(usda, "customData.cyclecoord", "nested")
    b = text.index('"start_frame": 0')
    usda.write_text(text[:b] + '"start_frame": "x"' + text[b + len('"start_frame": 0'):])
    _refused(usda, "customData.cyclecoord.start_frame")


def test_usd_rotations_holding_nan(usda):
    text = usda.read_text()
    a = text.index("quatf[] rotations.timeSamples")
    b = text.index("3: [(", a) + len("3: [(")
    end = text.index(")", b)
    usda.write_text(text[:b] + "nan, 0, 0, 0" + text[end:])
    _refused(usda, "rotations at time code 3", "not a unit quaternion")


def test_usd_empty_joints(usda):
    text = usda.read_text()
    a = text.index("uniform token[] joints = [") + len("uniform token[] joints = [")
    usda.write_text(text[:a] + text[text.index("]", a):])
    _refused(usda, "joints array is empty")


def test_usd_sparse_time_samples_are_interpolated(usda, walk):
    # a time sample moved far away: usd-core is asked for the samples alone, the frames
    # between them are interpolated as USD does
    text = usda.read_text().replace("19: [", "49999: [")
    usda.write_text(text.replace("endTimeCode = 19", "endTimeCode = 49999", 1))
    m = cc.load(usda)
    assert m.n_frames == 50_000 and np.isfinite(m.frames).all()
    np.testing.assert_allclose(m.frames[:19], walk.frames[:19], atol=1e-3)


def test_usd_refusal_is_one_line_without_usd_core_warnings(usda, capfd):
    # joints array cut to 3 entries: usd-core warns about every size that disagrees
    text = usda.read_text()
    a = text.index("uniform token[] joints = [") + len("uniform token[] joints = [")
    b = text.index("]", a)
    usda.write_text(text[:a] + ", ".join(text[a:b].split(", ")[:3]) + text[b:])
    capfd.readouterr()
    with pytest.raises(ParseError) as e:
        cc.load(usda)
    one_line(e, usda)
    assert capfd.readouterr().err == ""


def test_usd_animation_arrays_that_disagree_with_its_joints(usda):
    # usd-core ignores such an animation (a warning and the rest pose): a motion that never
    # moved was read, and latent fit ended in a KeyError on it
    text = usda.read_text()
    key = "uniform token[] joints = ["
    a = text.index(key, text.index("def SkelAnimation")) + len(key)
    first = text[a : text.index(",", a)]
    usda.write_text(text[:a] + first + ", " + text[a:])
    _refused(usda, "Animation.translations at time code 0", "for the animation's")


def test_usd_rest_transforms_and_joint_paths_checked(usda):
    # usd-core warned and went on with identity transforms or another hierarchy: the
    # reader took a skeleton that was not the file's (fuzzer usd case 204058)
    text = usda.read_text()
    a = text.index("matrix4d[] restTransforms = [") + len("matrix4d[] restTransforms = [")
    usda.write_text(text[:a] + text[text.index("]", a):])
    _refused(usda, "restTransforms: 0 transforms for the skeleton's")
    a = text.index("uniform token[] joints = [") + len("uniform token[] joints = [")
    usda.write_text(text[:a] + '"a//b", ' + text[a:])
    _refused(usda, "joints[0]", "is not a joint path")


@pytest.mark.parametrize("attr", ["bindTransforms", "restTransforms"])
def test_usd_skeleton_value_of_an_unknown_type(usda, attr):
    # a digit of `matrix4d[]` changed: usd-core reads the value as an UnregisteredValue
    # (the attribute's declared type stays the schema's) and len() of it was a TypeError
    # (fuzzer usd cases 1001913, 1002852)
    text = usda.read_text()
    usda.write_text(text.replace(f"matrix4d[] {attr} =", f"matrix0d[] {attr} ="))
    _refused(usda, f"Skeleton.{attr}: a UnregisteredValue value", "Matrix4dArray")


def test_an_accessor_in_a_misaligned_buffer_view(glb):
    # the accessor's own offset is 0, but its view starts 2 bytes into a 4-byte float
    doc, blob = read_glb(glb)
    acc = doc["accessors"][_times_accessor(doc)]
    view = doc["bufferViews"][acc["bufferView"]]
    start = view.get("byteOffset", 0)
    data = bytes(blob[start : start + view["byteLength"]])
    blob += b"\0" * (-len(blob) % 4) + b"\0\0"
    view["byteOffset"] = len(blob)
    blob += data
    write_glb(glb, doc, blob)
    _refused(glb, "byteOffset", "not a multiple of its 4-byte components")


def test_channel_names_of_more_than_a_thousand_characters(glb):
    doc, blob = read_glb(glb)
    extras = doc["extras"]["cyclecoord"]
    extras["channels"][0][0] = "j" * 1001
    write_glb(glb, doc, blob)
    _refused(glb, "channels[0]", "1,001 characters; at most 1,000")


def test_usd_time_codes_far_from_zero(usda):
    # the frame count is endTimeCode - startTimeCode + 1, wherever the range starts
    text = usda.read_text().replace("endTimeCode = 19", "endTimeCode = 9000019", 1)
    usda.write_text(text.replace("startTimeCode = 0", "startTimeCode = 9000000", 1))
    m = cc.load(usda)
    assert m.n_frames == 20 and np.isfinite(m.frames).all()


def test_usd_animation_values_without_its_joints():
    # an animation that names no joints has 0 of them: any translation is one too many
    pytest.importorskip("pxr")
    from pxr import Gf, Usd, UsdSkel, Vt

    from cyclecoord.io.usd import _check_component_sizes

    stage = Usd.Stage.CreateInMemory()
    anim = UsdSkel.Animation.Define(stage, "/Anim")
    assert anim.GetJointsAttr().Get() is None
    anim.GetTranslationsAttr().Set(Vt.Vec3fArray([Gf.Vec3f(0, 0, 0)]), Usd.TimeCode(0))
    with pytest.raises(ParseError, match="1 values for the animation's 0 joints"):
        _check_component_sizes(anim, np.array([0]), "x.usda")


def test_gltf_of_exactly_max_frames_is_not_refused_for_its_frame_count(glb):
    # at 1 fps a last key at 9,999,999 s makes MAX_FRAMES (10 million) frames: the most
    # supported, so only the (here small) memory limit refuses it; one second more is
    # refused for its frame count
    from cyclecoord.io._limits import MAX_FRAMES, memory_limit

    doc, blob = read_glb(glb)
    view = doc["bufferViews"][doc["accessors"][_times_accessor(doc)]["bufferView"]]
    start = view.get("byteOffset", 0)
    times = np.frombuffer(bytes(blob[start : start + view["byteLength"]]), "<f4").copy()
    del doc["extras"]["cyclecoord"]["frames"]
    doc["extras"]["cyclecoord"]["fps"] = 1.0
    for last, words in [(MAX_FRAMES - 1, ["10,000,000 frames of", "memory"]),
                        (MAX_FRAMES, ["at most 10,000,000 are supported"])]:
        times[-1] = last
        blob[start : start + times.nbytes] = times.astype("<f4").tobytes()
        write_glb(glb, doc, blob)
        with memory_limit(1_000_000):
            _refused(glb, *words)
