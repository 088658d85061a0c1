"""NPZ and CSV helpers of cyclecoord.io.tabular, each on a small input whose answer is
worked out by hand: the arrays written, every check of the skeleton arrays, the archive's
memory, the layout checks, the CSV comment, header, rows (and which problem is reported
first across chunks of rows) and channel names (issue 27: known answers)."""

import zipfile

import numpy as np
import pytest

from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io import tabular as tb
from cyclecoord.io._limits import MAX_JOINTS, memory_limit
from cyclecoord.io._stream import CHUNK_FRAMES
from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton


def _skeleton():
    return Skeleton(
        (
            Joint("root", -1, [0, 1, 0], ("tx", "ty", "tz", "rz", "rx", "ry"), "ZXY"),
            Joint("knee", 0, [0, -2, 0], ("rx",), "X", end_site=[0, -3, 0],
                  limits={"rx": (-5.0, 150.0)}),
        ),
        name="leg", length_unit=0.5, source_format="bvh",
    )


def _motion(T=3, skeleton=True, **kw):
    sk = _skeleton()
    frames = np.arange(T * 7, dtype=float).reshape(T, 7)
    return Motion(frames, sk.channels, fps=kw.pop("fps", 24.0),
                  skeleton=sk if skeleton else None, **kw)


def _arrays(tmp_path, m=None):
    path = tmp_path / "m.npz"
    tb.write_npz(m if m is not None else _motion(), path)
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def _read(tmp_path, arrays):
    path = tmp_path / "case.npz"
    np.savez(path, **arrays)
    return tb.read_npz(path)


# ----------------------------------------------------------------------------- small helpers
def test_str_array():
    a = tb._str_array([1, "ab"])
    assert a.tolist() == ["1", "ab"] and a.dtype.kind == "U"
    empty = tb._str_array([])
    assert empty.shape == (0,) and empty.dtype == np.dtype("<U1")


def test_check_fps():
    assert tb._check_fps("30") == 30.0 and tb._check_fps(1e6) == 1e6 and tb._check_fps(1e-6) == 1e-6
    for bad in ("fast", None, [1]):
        with pytest.raises(ParameterError, match="^fps must be a positive number, got"):
            tb._check_fps(bad)
    for bad in (0.0, -1.0, np.inf, 2e6):
        with pytest.raises(ParameterError, match="^frame rate .* is not a positive number"):
            tb._check_fps(bad)


def test_resolve_skeleton(tmp_path):
    sk = _skeleton()
    assert tb._resolve_skeleton(None) is None and tb._resolve_skeleton(sk) is sk
    tb.write_npz(_motion(), tmp_path / "m.npz")
    from cyclecoord.io import write_bvh

    write_bvh(_motion(), tmp_path / "m.BVH")  # the suffix in any case
    assert tb._resolve_skeleton(tmp_path / "m.BVH").names == ["root", "knee"]
    assert tb._resolve_skeleton(str(tmp_path / "m.BVH")).source_format == "bvh"
    with pytest.raises(ParameterError, match=r"skeleton file .*m\.npz must be an \.asf or \.bvh"):
        tb._resolve_skeleton(tmp_path / "m.npz")
    with pytest.raises(ParameterError, match="got int"):
        tb._resolve_skeleton(3)


# ----------------------------------------------------------------------------- NPZ written
def test_npz_arrays_as_documented(tmp_path):
    a = _arrays(tmp_path, _motion(start_frame=9, source="cap.bvh", metadata={"k": [1, 2]}))
    assert a["format"].item() == "cyclecoord-motion" and a["version"].item() == 1
    assert a["version"].dtype == np.int64 and a["start_frame"].dtype == np.int64
    assert a["fps"].item() == 24.0 and a["start_frame"].item() == 9
    assert a["source"].tolist() == ["cap.bvh"] and a["metadata_json"].item() == '{"k": [1, 2]}'
    assert a["has_skeleton"].item() is True
    assert a["channel_joints"].tolist() == ["root"] * 6 + ["knee"]
    assert a["channel_dofs"].tolist() == ["tx", "ty", "tz", "rz", "rx", "ry", "rx"]
    assert a["skeleton_name"].item() == "leg" and a["skeleton_length_unit"].item() == 0.5
    assert a["skeleton_source_format"].item() == "bvh"
    assert a["joint_parents"].tolist() == [-1, 0] and a["joint_dofs"].tolist() == [
        "tx ty tz rz rx ry", "rx"]
    assert a["joint_rotation_orders"].tolist() == ["ZXY", "X"]
    assert a["joint_offsets"].tolist() == [[0, 1, 0], [0, -2, 0]]
    assert np.isnan(a["joint_end_sites"][0]).all() and a["joint_end_sites"][1].tolist() == [0, -3, 0]
    assert a["joint_has_end_site"].tolist() == [False, True]
    assert a["limit_joints"].tolist() == [1] and a["limit_dofs"].tolist() == ["rx"]
    assert a["limit_ranges"].tolist() == [[-5.0, 150.0]]
    plain = _arrays(tmp_path, _motion(skeleton=False))
    assert plain["has_skeleton"].item() is False and "joint_names" not in plain
    assert plain["source"].shape == (0,)
    sk = Skeleton((Joint("r", -1, [0, 0, 0], ("tx",), ""),))  # no limits: (0, 2) ranges
    none = _arrays(tmp_path, Motion(np.zeros((2, 1)), sk.channels, fps=5, skeleton=sk))
    assert none["limit_ranges"].shape == (0, 2) and none["limit_joints"].shape == (0,)


# ----------------------------------------------------------------------------- NPZ read
def test_npz_layout_checks(tmp_path):
    a = _arrays(tmp_path, _motion(skeleton=False))
    del a["start_frame"]
    with pytest.raises(ParseError, match=r"missing array 'start_frame' \(an \.npz motion needs "
                                         r"frames, channel_joints, channel_dofs, fps, "
                                         r"start_frame\)"):
        _read(tmp_path, a)
    a = _arrays(tmp_path, _motion(skeleton=False))
    for key in ("format", "version", "source", "metadata_json", "has_skeleton"):
        del a[key]  # optional: a minimal archive reads
    m = _read(tmp_path, a)
    assert m.source is None and m.metadata == {} and m.skeleton is None and m.fps == 24.0
    a = _arrays(tmp_path, _motion(skeleton=False))
    a["format"] = np.array("other-motion")
    with pytest.raises(ParseError, match="array 'format': expected 'cyclecoord-motion', got "
                                         "'other-motion'"):
        _read(tmp_path, a)
    for version in (0, 2):
        a["format"] = np.array("cyclecoord-motion")
        a["version"] = np.array(version)
        with pytest.raises(ParseError, match=f"layout version {version}; this cyclecoord reads "
                                             "version 1"):
            _read(tmp_path, a)
    a["version"] = np.array(1)
    a["source"] = np.array(["a", "b"])
    with pytest.raises(ParseError, match="array 'source': expected at most one string, got 2"):
        _read(tmp_path, a)
    a["source"] = np.array(["a"])
    assert _read(tmp_path, a).source == "a"
    a["frames"] = np.zeros(7)
    with pytest.raises(ParseError, match=r"array 'frames': expected a 2-D array of real numbers, "
                                         r"got float64 \(7,\)"):
        _read(tmp_path, a)
    a["frames"] = np.zeros((2, 7), dtype=bool)
    with pytest.raises(ParseError, match="expected a 2-D array of real numbers, got bool"):
        _read(tmp_path, a)
    a["frames"] = np.ones((2, 7), dtype=np.int32)  # whole numbers read as they are
    assert _read(tmp_path, a).frames.tolist() == [[1] * 7] * 2


def test_npz_metadata(tmp_path):
    a = _arrays(tmp_path, _motion(skeleton=False, metadata={"x": 1}))
    assert _read(tmp_path, a).metadata == {"x": 1}
    a["metadata_json"] = np.array("{x")
    with pytest.raises(ParseError, match="array 'metadata_json': not valid JSON"):
        _read(tmp_path, a)
    a["metadata_json"] = np.array("3")
    with pytest.raises(ParseError, match="array 'metadata_json': must hold a JSON object, holds "
                                         "a int"):
        _read(tmp_path, a)


def test_npz_overrides(tmp_path):
    a = _arrays(tmp_path)
    path = tmp_path / "o.npz"
    np.savez(path, **a)
    assert tb.read_npz(path, fps=50).fps == 50.0
    other = Skeleton(_skeleton().joints, name="other")
    assert tb.read_npz(path, skeleton=other).skeleton is other
    with pytest.raises(ParameterError, match="fps must be a positive number"):
        tb.read_npz(path, fps="x")
    with pytest.raises(ParseError, match="not a file"):
        tb.read_npz(tmp_path)


def test_npz_skeleton_read_back(tmp_path):
    sk = _read(tmp_path, _arrays(tmp_path)).skeleton
    assert sk.names == ["root", "knee"] and sk.name == "leg" and sk.length_unit == 0.5
    assert sk.source_format == "bvh" and [j.parent for j in sk.joints] == [-1, 0]
    assert sk.joints[0].dofs == ("tx", "ty", "tz", "rz", "rx", "ry")
    assert sk.joints[0].rotation_order == "ZXY" and sk.joints[1].dofs == ("rx",)
    assert sk.joints[0].end_site is None and sk.joints[1].end_site.tolist() == [0, -3, 0]
    assert sk.joints[1].limits == {"rx": (-5.0, 150.0)} and sk.joints[0].limits == {}


@pytest.mark.parametrize(
    "key, value, message",
    [
        ("joint_names", np.zeros(0, "<U1"), "array 'joint_names': a skeleton needs at least one"),
        ("joint_parents", np.array([-1, 2]), "array 'joint_parents'"),
        ("joint_parents", np.array([-2, 0]), "array 'joint_parents'"),
        ("joint_has_end_site", np.array([0, 1]), r"array 'joint_has_end_site': expected 2 "
                                                 r"booleans, got int64 \(2,\)"),
        ("joint_has_end_site", np.array([True]), r"expected 2 booleans, got bool \(1,\)"),
        ("joint_has_end_site", np.array([True, True]), "array 'joint_end_sites': joint 'root' has "
                                                       "an end site of NaN"),
        ("limit_joints", np.array([[1]]), r"array 'limit_joints': expected a 1-D array, got shape "
                                          r"\(1, 1\)"),
        ("limit_joints", np.array([2]), "array 'limit_joints'"),
        ("limit_joints", np.array([-1]), "array 'limit_joints'"),
        ("joint_dofs", np.array(["tx"]), "array 'joint_dofs': expected 2 strings, one for each of "
                                         "the 2 joints, got 1"),
        ("joint_dofs", np.array(["tx ty tz rz rx ry", "rw"]), "malformed skeleton arrays: joint 1"),
    ],
)
def test_npz_skeleton_refusals(tmp_path, key, value, message):
    a = _arrays(tmp_path)
    a[key] = value
    with pytest.raises(ParseError, match=message):
        _read(tmp_path, a)


def test_npz_skeleton_edges(tmp_path):
    a = _arrays(tmp_path)
    a["joint_parents"] = np.array([-1, -1])  # two roots: each parent in -1..J-1
    with pytest.raises(ParseError, match="malformed skeleton arrays"):
        _read(tmp_path, a)
    a = _arrays(tmp_path)
    a["limit_joints"] = np.array([0])  # limit on joint 0 (the first one allowed)
    a["limit_dofs"] = np.array(["tx"])
    assert _read(tmp_path, a).skeleton.joints[0].limits == {"tx": (-5.0, 150.0)}
    for key in ("limit_joints", "limit_dofs"):
        a = _arrays(tmp_path)
        del a[key]
        with pytest.raises(ParseError, match=f"'has_skeleton' is set but array '{key}' is missing"):
            _read(tmp_path, a)
    a = _arrays(tmp_path)
    a["has_skeleton"] = np.array(False)  # the skeleton arrays are then not read
    a["joint_names"] = np.zeros(0, "<U1")
    assert _read(tmp_path, a).skeleton is None


def test_npz_at_most_max_joints(tmp_path):
    a = _arrays(tmp_path)
    a["joint_names"] = np.array([f"j{k}" for k in range(MAX_JOINTS + 1)])
    with pytest.raises(ParseError, match="array 'joint_names': 4,097 joints; at most 4,096"):
        _read(tmp_path, a)


def test_npz_memory_is_the_unpacked_size(tmp_path):
    """Before the arrays are read: the bytes they unpack to, summed over the members."""
    path = tmp_path / "m.npz"
    tb.write_npz(_motion(), path)
    with zipfile.ZipFile(path) as z:
        size = sum(i.file_size for i in z.infolist())
    with memory_limit(size):
        assert tb.read_npz(path).n_frames == 3
    with memory_limit(size - 1), pytest.raises(ParseError, match=f"the archive's arrays "
                                                                 f"\\({size:,} bytes unpacked\\)"):
        tb.read_npz(path)


# ----------------------------------------------------------------------------- CSV written
def test_csv_written_text(tmp_path):
    m = Motion(np.array([[0.1, -2.0], [1e-300, 3.0]]), [("a", "tx"), ("b", "")], fps=30.0)
    tb.write_csv(m, tmp_path / "a.csv")
    assert (tmp_path / "a.csv").read_text() == "# fps=30.0\na.tx,b\n0.1,-2.0\n1e-300,3.0\n"
    m2 = Motion(m.frames, m.channels, fps=30.0, start_frame=1)
    tb.write_csv(m2, tmp_path / "b.csv")
    assert (tmp_path / "b.csv").read_text().splitlines()[0] == "# fps=30.0 start_frame=1"


@pytest.mark.parametrize(
    "channels, message",
    [
        ([("#a", "tx"), ("b", "ty")], "would not read back as one header row"),
        ([("a\nb", "tx"), ("b", "ty")], "would not read back as one header row"),
        ([(" a", "tx"), ("b", "ty")], r"channel \(' a', 'tx'\) would read back as 'a\.tx'"),
        ([("a", "tx "), ("b", "ty")], r"would read back as 'a\.tx'"),
    ],
)
def test_csv_names_that_would_not_read_back(tmp_path, channels, message):
    m = Motion(np.zeros((2, 2)), channels, fps=30.0)
    with pytest.raises(ParameterError, match=message):
        tb.write_csv(m, tmp_path / "a.csv")
    assert not (tmp_path / "a.csv").exists()


def test_csv_names_with_commas_are_quoted_and_read_back(tmp_path):
    m = Motion(np.zeros((2, 2)), [("a,b", "tx"), ("c", "ty")], fps=30.0)
    tb.write_csv(m, tmp_path / "a.csv")
    assert (tmp_path / "a.csv").read_text().splitlines()[1] == '"a,b.tx",c.ty'
    assert tb.read_csv(tmp_path / "a.csv").channels == m.channels


# ----------------------------------------------------------------------------- CSV comment
def test_parse_comment():
    assert tb._parse_comment("# fps=24, start_frame=3", "f", 1) == {"fps": 24.0, "start_frame": 3}
    assert tb._parse_comment("#FPS=25 Start_Frame=0 other=1 words", "f", 1) == {
        "fps": 25.0, "start_frame": 0}
    assert tb._parse_comment("# made by hand", "f", 1) == {}
    assert tb._parse_comment("# start_frame=1000000000", "f", 1) == {"start_frame": 10**9}
    with pytest.raises(ParseError, match="start_frame") as e:
        tb._parse_comment("# start_frame=1000000001", "f", 4)
    assert e.value.line == 4
    with pytest.raises(ParseError, match="start_frame"):
        tb._parse_comment("# start_frame=-1", "f", 4)
    with pytest.raises(ParseError, match="expected a number after 'fps=', found 'x'") as e:
        tb._parse_comment("# fps=x", "f", 2)
    assert e.value.line == 2
    with pytest.raises(ParseError, match="frame rate 2000000.0 is not a positive number"):
        tb._parse_comment("# fps=2e6", "f", 2)


# ----------------------------------------------------------------------------- CSV read
def test_csv_defaults_and_comments_only_before_the_header(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("a.x,b\n1,2\n# fps=30 start_frame=5\n3,4\n")
    m = tb.read_csv(p)
    assert m.fps == 120.0 and m.start_frame == 0 and m.source == str(p)
    assert m.channels == (("a", "x"), ("b", "")) and m.frames.tolist() == [[1, 2], [3, 4]]
    p.write_text("\n# x\n# start_frame=5\n\n a.x , b \n1,2\n")
    m = tb.read_csv(p)
    assert m.start_frame == 5 and m.channels == (("a", "x"), ("b", ""))
    with pytest.raises(ParseError, match="is a directory"):
        tb.read_csv(tmp_path)


def test_csv_header_refusals(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("\n\n")
    with pytest.raises(ParseError, match="no header row") as e:
        tb.read_csv(p)
    assert e.value.line == 2  # the last line read
    p.write_text("")
    with pytest.raises(ParseError, match="no header row") as e:
        tb.read_csv(p)
    assert e.value.line is None
    p.write_text("\n" + "a" * 200_000 + "\n1\n")  # over the csv module's field limit
    with pytest.raises(ParseError, match="cannot read header row: field larger") as e:
        tb.read_csv(p)
    assert e.value.line == 2
    p.write_text("a,b,\n1,2,3\n")
    with pytest.raises(ParseError, match="empty channel name in column 3"):
        tb.read_csv(p)


def test_csv_channels():
    """Split at the last dot; no dot: (name, ""); a repeat refused naming the header line."""
    assert tb._csv_channels(["a.b.rx", "c", "d."], 1, "f") == [("a.b", "rx"), ("c", ""),
                                                              ("d", "")]
    with pytest.raises(ParseError, match="channel 'x.y' appears twice") as e:
        tb._csv_channels(["x.y", "z", "x.y"], 7, "f")
    assert e.value.line == 7


def test_csv_values_up_to_max_magnitude(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("a\n1e9\n-1e9\n")
    assert tb.read_csv(p).frames[:, 0].tolist() == [1e9, -1e9]
    p.write_text("a\n1e9\n1.0000001e9\n")
    with pytest.raises(ParseError, match=r"column 1 \(a\) is '1.0000001e9', expected a finite "
                                         r"number of at most 1e\+09") as e:
        tb.read_csv(p)
    assert e.value.line == 3


def _rows(n, d=2):
    return [",".join(["1"] * d) for _ in range(n)]


def test_csv_first_problem_across_chunks(tmp_path):
    """Rows are converted CHUNK_FRAMES (256) at a time; the error is the one a whole-file
    read gives: a row of the wrong length before any value problem, a value that is no
    number before one that is not finite, and of each kind the first."""
    assert CHUNK_FRAMES == 256
    p = tmp_path / "a.csv"
    rows = _rows(600)
    rows[10] = "1,inf"  # line 12 (the header is line 1)
    rows[300] = "1,x"  # line 302, in the second chunk (rows 257..512)
    rows[530] = "1,y"  # line 532, in the third
    rows[550] = "1,-inf"
    p.write_text("a,b\n" + "\n".join(rows) + "\n")
    with pytest.raises(ParseError, match=r"column 2 \(b\) is 'x', expected a number") as e:
        tb.read_csv(p)
    assert e.value.line == 302
    rows[300] = rows[530] = "1,1"
    p.write_text("a,b\n" + "\n".join(rows) + "\n")
    with pytest.raises(ParseError, match="is 'inf', expected a finite number") as e:
        tb.read_csv(p)
    assert e.value.line == 12
    rows[10] = "1,1"
    p.write_text("a,b\n" + "\n".join(rows) + "\n")
    with pytest.raises(ParseError, match="is '-inf', expected a finite number") as e:
        tb.read_csv(p)
    assert e.value.line == 552
    rows[590] = "1"
    rows[595] = "1,2,3"
    rows[20] = "1,z"
    p.write_text("a,b\n" + "\n".join(rows) + "\n")
    with pytest.raises(ParseError, match="row has 1 values, the header .line 1. names 2") as e:
        tb.read_csv(p)
    assert e.value.line == 592


def test_csv_rows_of_exactly_one_chunk_and_more(tmp_path):
    p = tmp_path / "a.csv"
    for n in (CHUNK_FRAMES - 1, CHUNK_FRAMES, CHUNK_FRAMES + 1, 3 * CHUNK_FRAMES):
        values = np.arange(2 * n, dtype=float).reshape(n, 2)
        p.write_text("a,b\n" + "\n".join(f"{x},{y}" for x, y in values.tolist()) + "\n")
        np.testing.assert_array_equal(tb.read_csv(p).frames, values)


def test_csv_frame_memory_counts_the_data_lines(tmp_path):
    """Room for the rows is made at once, before they are read: the lines that are neither
    blank nor a comment, less the header (10 rows of 2 values: 160 bytes; at least one
    row: 16 bytes for a file of one)."""
    p = tmp_path / "a.csv"
    rows = [f"{k},{-k}" for k in range(10)]
    p.write_text("# fps=10\n\na.x,a.y\n" + "\n# c\n  \n".join(rows) + "\n")
    with memory_limit(160):
        assert tb.read_csv(p).frames.tolist() == [[k, -k] for k in range(10)]
    with memory_limit(159), pytest.raises(ParseError, match="10 frames of 2 channels need 160 "
                                                            "bytes"):
        tb.read_csv(p)
    p.write_text("a.x,a.y\n1,2\n")
    with memory_limit(16):
        assert tb.read_csv(p).frames.tolist() == [[1, 2]]


def test_csv_row_count_limit(tmp_path, monkeypatch):
    """At most MAX_FRAMES rows (here patched to 5): 5 read, the 6th refused at its line."""
    monkeypatch.setattr(tb, "MAX_FRAMES", 5)
    p = tmp_path / "a.csv"
    p.write_text("a\n" + "".join(f"{k}\n" for k in range(5)))
    assert tb.read_csv(p).frames[:, 0].tolist() == [0, 1, 2, 3, 4]
    p.write_text("a\n" + "".join(f"{k}\n" for k in range(5)) + "# c\n5\n")
    with pytest.raises(ParseError, match="6 rows; at most 5 frames are supported") as e:
        tb.read_csv(p)
    assert e.value.line == 8
    # the count comes first: a bad row after the limit is not what is reported
    p.write_text("a\n" + "".join(f"{k}\n" for k in range(5)) + "x\n1,2\n")
    with pytest.raises(ParseError, match="7 rows; at most 5 frames"):
        tb.read_csv(p)


def test_csv_at_most_six_channels_a_joint(tmp_path):
    p = tmp_path / "a.csv"
    n = 6 * MAX_JOINTS
    p.write_text(",".join(f"c{k}" for k in range(n + 1)) + "\n")
    with pytest.raises(ParseError, match="24,577 columns; at most 24,576 channels") as e:
        tb.read_csv(p)
    assert e.value.line == 1
    p.write_text(",".join(f"c{k}" for k in range(n)) + "\n" + ",".join(["0"] * n) + "\n")
    assert tb.read_csv(p).frames.shape == (1, n)


# ----------------------------------------------------------------------------- more NPZ edges
def test_npz_refusals_of_the_motion_itself(tmp_path):
    a = _arrays(tmp_path, _motion(skeleton=False))
    a["channel_joints"] = np.array(["a"] * 7)
    a["channel_dofs"] = np.array(["x"] * 7)
    with pytest.raises(ParseError, match=r"duplicate channels: \[\('a', 'x'\)\] \(arrays "
                                         r"'frames', 'channel_joints', 'channel_dofs'\)"):
        _read(tmp_path, a)
    deep: dict = {}
    inner = deep
    for _ in range(100):
        inner["a"] = {}
        inner = inner["a"]
    with pytest.raises(ParameterError, match=r"m\.npz: cannot write NPZ: metadata entry 'x' is "
                                             r"nested 102 levels deep"):
        tb.write_npz(_motion(metadata={"x": deep}), tmp_path / "m.npz")


def _patched_size(tmp_path, total):
    """An archive of the motion whose central directory says its members unpack to
    ``total`` bytes (the first member's uncompressed size changed; nothing is read)."""
    path = tmp_path / "big.npz"
    tb.write_npz(_motion(), path)
    with zipfile.ZipFile(path) as z:
        infos = z.infolist()
    others = sum(i.file_size for i in infos[1:])
    data = bytearray(path.read_bytes())
    at = data.index(b"PK\x01\x02")  # the first central directory entry
    data[at + 24 : at + 28] = (total - others).to_bytes(4, "little")
    path.write_bytes(bytes(data))
    return path


def test_npz_unpacked_size_at_most_two_gib(tmp_path):
    """MAX_NPZ_BYTES (2 GiB) unpacked is the most: exactly that passes the cap (and is then
    refused for the memory it needs, here limited), one byte more is refused by the cap."""
    cap = 2 * 1024**3
    with memory_limit(1e6), pytest.raises(ParseError, match=f"the archive's arrays \\({cap:,} "
                                                            "bytes unpacked\\) need"):
        tb.read_npz(_patched_size(tmp_path, cap))
    with pytest.raises(ParseError, match=f"the archive unpacks to {cap + 1:,} bytes; at most "
                                         f"{cap:,} are supported"):
        tb.read_npz(_patched_size(tmp_path, cap + 1))


def test_csv_fps_override_checked(tmp_path):
    p = tmp_path / "a.csv"
    p.write_text("# fps=30\na\n1\n")
    assert tb.read_csv(p, fps="25").fps == 25.0
    with pytest.raises(ParameterError, match="fps must be a positive number, got 'x'"):
        tb.read_csv(p, fps="x")
    with pytest.raises(ParameterError, match="frame rate 0.0 is not a positive number"):
        tb.read_csv(p, fps=0)


def test_npz_corrupt_member(tmp_path):
    """A member whose bytes no longer match their CRC: refused naming the array."""
    path = tmp_path / "m.npz"
    np.savez(path, frames=np.arange(64.0).reshape(8, 8))  # stored, not compressed
    data = bytearray(path.read_bytes())
    at = data.index(np.arange(64.0).tobytes()[8:16])  # the second value's bytes
    data[at] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(ParseError, match="array 'frames': corrupt"):
        tb.read_npz(path)


def test_npz_version_and_start_frame_ranges(tmp_path):
    a = _arrays(tmp_path, _motion(skeleton=False))
    a["version"] = np.array(2**62)
    with pytest.raises(ParseError, match="layout version 4611686018427387904; this cyclecoord"):
        _read(tmp_path, a)
    for v in (2**62 + 1, -(2**62) - 1):
        a["version"] = np.array(v)
        with pytest.raises(ParseError, match="array 'version': expected a whole number in "
                                             "-4,611,686,018,427,387,904..4,611,686,018,"):
            _read(tmp_path, a)
    a["version"] = np.array(1)
    a["start_frame"] = np.array(10**9)
    assert _read(tmp_path, a).start_frame == 10**9
    for v in (10**9 + 1, -1):
        a["start_frame"] = np.array(v)
        with pytest.raises(ParseError, match="array 'start_frame': expected a whole number in "
                                             "0..1,000,000,000"):
            _read(tmp_path, a)


def test_csv_uncounted_rows_grow_the_array_a_chunk_at_a_time(tmp_path):
    """Rows the line count missed (U+2028 separates rows for the reader, not for the byte
    count: 1 row counted) grow the array as each chunk of CHUNK_FRAMES rows arrives: 1 row,
    then 256 for the first chunk, then max(300, 1.25 * 256) = 320 rows for the last 44, so
    300 rows of 2 channels need 320 * 2 * 8 = 5120 bytes and no more."""
    p = tmp_path / "g.csv"
    rows = "\u2028".join(f"{k},{2 * k}" for k in range(300))
    p.write_text("# fps=30\na.rx,a.ry\n" + rows + "\n", encoding="utf-8")
    with memory_limit(5120):
        m = tb.read_csv(p)
    assert m.frames.shape == (300, 2) and m.frames[-1, 1] == 598
    with memory_limit(5119), pytest.raises(ParseError, match="320 frames of 2 channels need"):
        tb.read_csv(p)
    with memory_limit(4096):  # the first chunk alone fits: 256 rows
        with pytest.raises(ParseError, match="320 frames"):
            tb.read_csv(p)
