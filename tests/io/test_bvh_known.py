"""Known-answer tests of cyclecoord.io.bvh: tiny hand-made files whose joints, channels,
values, rates and error lines are known, and the writer's helpers at their edges."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io import read_bvh, write_bvh
from cyclecoord.io._limits import memory_limit
from cyclecoord.io.bvh import (
    BVH_CHANNEL_NAMES,
    _bvh_names,
    _bvh_ready_orders,
    _complete_order,
    _fmt,
    _is_subsequence,
    _round_fps,
)
from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton

# line numbers:       1          2         3   4               5
HEAD = "HIERARCHY\nROOT Hips\n{\n\tOFFSET 1 2 3\n" \
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
# 6 JOINT Leg, 7 {, 8 OFFSET, 9 CHANNELS, 10 End Site, 11 {, 12 OFFSET, 13 }, 14 }, 15 }
LEG = "\tJOINT Leg\n\t{\n\t\tOFFSET 0 -4 0\n\t\tCHANNELS 2 Xrotation Zrotation\n" \
    "\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 -5 0\n\t\t}\n\t}\n}\n"
# 16 MOTION, 17 Frames, 18 Frame Time, 19.. frames
MOTION = "MOTION\nFrames: 2\nFrame Time: 0.04\n"
ROWS = "0.5 1 1.5 10 20 30 40 50\n-1 -2 -3 -10 -20 -30 -40 -50\n"
TINY = HEAD + LEG + MOTION + ROWS


def put(tmp_path: Path, text: str, name: str = "tiny.bvh") -> Path:
    p = tmp_path / name
    p.write_bytes(text.encode("utf-8"))
    return p


def parse_error(tmp_path: Path, text: str) -> ParseError:
    p = put(tmp_path, text)
    with pytest.raises(ParseError) as info:
        read_bvh(p)
    assert info.value.path == str(p)
    return info.value


# ----------------------------------------------------------------------------- reading
def test_tiny_file_is_read_as_written(tmp_path):
    m = read_bvh(put(tmp_path, TINY))
    assert m.channels == (
        ("Hips", "tx"), ("Hips", "ty"), ("Hips", "tz"), ("Hips", "rz"), ("Hips", "rx"),
        ("Hips", "ry"), ("Leg", "rx"), ("Leg", "rz"),
    )
    np.testing.assert_array_equal(
        m.frames, [[0.5, 1, 1.5, 10, 20, 30, 40, 50], [-1, -2, -3, -10, -20, -30, -40, -50]]
    )
    assert m.fps == 25.0 and m.metadata["frame_time"] == 0.04
    sk = m.skeleton
    assert sk.name == "tiny" and sk.source_format == "bvh"
    assert [j.name for j in sk.joints] == ["Hips", "Leg"]
    assert [j.parent for j in sk.joints] == [-1, 0]
    assert [j.rotation_order for j in sk.joints] == ["ZXY", "XZ"]
    assert sk.joints[0].dofs == ("tx", "ty", "tz", "rz", "rx", "ry")
    assert sk.joints[1].dofs == ("rx", "rz")
    np.testing.assert_array_equal(sk.joints[0].offset, [1, 2, 3])
    np.testing.assert_array_equal(sk.joints[1].offset, [0, -4, 0])
    assert sk.joints[0].end_site is None
    np.testing.assert_array_equal(sk.joints[1].end_site, [0, -5, 0])
    for j in sk.joints:
        np.testing.assert_array_equal(j.axis, np.eye(3))


def test_names_channels_and_keywords_are_read_loosely(tmp_path):
    # lower-case keywords, a brace on the name's line, a two-word joint name, lower-case
    # channel names, no space after 'Frames:', 'Frame   Time :' and blank lines in MOTION
    text = (
        "hierarchy\nroot Hips {\n OFFSET 0 0 0\n channels 3 zrotation XROTATION yRotation\n"
        " joint Left Leg\n {\n  offset 0 -1 0\n  channels 1 Yrotation\n  end site\n  {\n"
        "   offset 0 -1 0\n  }\n }\n}\nmotion\n\nframes:1\n\nFrame   Time :  0.5\n\n1 2 3 4\n\n"
    )
    m = read_bvh(put(tmp_path, text))
    assert m.skeleton.names == ["Hips", "Left Leg"]
    assert m.channels == (("Hips", "rz"), ("Hips", "rx"), ("Hips", "ry"), ("Left Leg", "ry"))
    np.testing.assert_array_equal(m.frames, [[1, 2, 3, 4]])
    assert m.fps == 2.0


def test_zero_channel_joints_and_channel_count_zero(tmp_path):
    text = HEAD + "\tJOINT Still\n\t{\n\t\tOFFSET 0 1 0\n\t\tCHANNELS 0\n\t}\n" \
        "\tJOINT Bare\n\t{\n\t\tOFFSET 0 2 0\n\t}\n}\n" + MOTION + "1 2 3 4 5 6\n7 8 9 10 11 12\n"
    m = read_bvh(put(tmp_path, text))
    assert m.skeleton.names == ["Hips", "Still", "Bare"]
    assert m.skeleton.joints[1].dofs == () and m.skeleton.joints[2].dofs == ()
    assert m.n_channels == 6 and m.frames[1, 5] == 12


@pytest.mark.parametrize(
    "frame_time, fps",
    [
        ("0.04", 25.0),
        (repr(1 / 120.01), 120.0),  # 0.01 / 120 = 8.3e-5 relative: snapped
        (repr(1 / 120.02), 120.02),  # 1.7e-4 relative: kept
        ("2.5", 0.4),  # nearest integer 0: kept
        ("1e-6", 1e6),  # the fastest rate allowed
        ("1e6", 1e-6),  # the slowest rate allowed
    ],
)
def test_frame_time_gives_the_rate(tmp_path, frame_time, fps):
    m = read_bvh(put(tmp_path, HEAD + LEG + f"MOTION\nFrames: 2\nFrame Time: {frame_time}\n" + ROWS))
    assert m.fps == pytest.approx(fps, rel=1e-12)
    assert m.metadata["frame_time"] == float(frame_time)


def test_round_fps_known_values():
    assert _round_fps(120.0) == 120.0
    assert _round_fps(119.995) == 120.0  # 0.005 <= 1e-4 * 119.995
    assert _round_fps(119.98) == 119.98  # 0.02 > 0.012
    assert _round_fps(29.97) == 29.97
    assert _round_fps(0.3) == 0.3  # round() gives 0: no snapping to a zero rate
    assert _round_fps(1.00005) == 1.0
    assert _round_fps(1.0002) == 1.0002
    assert isinstance(_round_fps(24), float)


def test_values_up_to_the_magnitude_cap_are_read(tmp_path):
    rows = "1e9 -1e9 0 0 0 0 0 0\n0 0 0 0 0 0 0 0\n"
    text = HEAD.replace("OFFSET 1 2 3", "OFFSET 1e9 -1e9 0") + LEG + MOTION + rows
    m = read_bvh(put(tmp_path, text))
    assert m.frames[0, 0] == 1e9 and m.frames[0, 1] == -1e9
    np.testing.assert_array_equal(m.skeleton.joints[0].offset, [1e9, -1e9, 0])


def _n_frames(values_per_line: list[str]) -> str:
    return HEAD + LEG + f"MOTION\nFrames: {len(values_per_line)}\nFrame Time: 0.04\n" + \
        "".join(v + "\n" for v in values_per_line)


def test_frames_across_chunks_are_numbered_from_one(tmp_path):
    # more frames than a chunk (256): the frame number in a message counts across chunks
    rows = [f"{k} 0 0 0 0 0 0 {k}" for k in range(300)]
    m = read_bvh(put(tmp_path, _n_frames(rows)))
    assert m.n_frames == 300
    np.testing.assert_array_equal(m.frames[:, 0], np.arange(300))
    np.testing.assert_array_equal(m.frames[:, 7], np.arange(300))
    bad = list(rows)
    bad[289] = "0 abc 0 0 0 0 0 0"
    err = parse_error(tmp_path, _n_frames(bad))
    assert err.line == 19 + 289
    assert "frame 290: value 2 (Hips Yposition) is 'abc', expected a number" in err.message
    big = list(rows)
    big[269] = "0 0 0 0 0 0 0 2e9"
    err = parse_error(tmp_path, _n_frames(big))
    assert err.line == 19 + 269
    assert "frame 270: value 8 (Leg Zrotation) is '2e9', expected a finite number" in err.message
    both = list(rows)
    both[9] = "0 0 0 inf 0 0 0 0"  # a non-finite value in the first chunk
    both[279] = "0 0 0 0 0 x 0 0"  # and a non-number in the second: the non-number wins
    err = parse_error(tmp_path, _n_frames(both))
    assert err.line == 19 + 279 and "frame 280: value 6 (Hips Yrotation) is 'x'" in err.message
    two = list(rows)
    two[4] = "0 0 nan 0 0 0 0 0"
    two[260] = "0 0 0 0 0 0 -inf 0"
    err = parse_error(tmp_path, _n_frames(two))
    assert err.line == 19 + 4 and "frame 5: value 3 (Hips Zposition) is 'nan'" in err.message


def test_frame_problems_are_reported_in_a_whole_file_order(tmp_path):
    # the count against 'Frames:' first, then the first wrong-length line, then the first
    # non-number, then the first non-finite value
    rows = ["0 0 0 0 0 0 0 0"] * 4
    r = list(rows)
    r[1] = "0 0 0"
    r[2] = "0 0"
    err = parse_error(tmp_path, _n_frames(r))
    assert err.line == 20 and "frame 2 has 3 values, the hierarchy declares 8 channels" in err.message
    r[3] = "x 0 0 0 0 0 0 0"
    err = parse_error(tmp_path, _n_frames(r))
    assert err.line == 20
    text = _n_frames(r).replace("Frames: 4", "Frames: 3")
    err = parse_error(tmp_path, text)
    assert err.line == 22
    assert "'Frames: 3' declared but 4 frame lines found (line 22 is frame 4)" in err.message
    r2 = list(rows)
    r2[0] = "inf 0 0 0 0 0 0 0"
    r2[2] = "0 0 0 0 0 0 0 y"
    err = parse_error(tmp_path, _n_frames(r2))
    assert err.line == 21 and "frame 3: value 8 (Leg Zrotation) is 'y'" in err.message


def test_rows_allocated_are_bounded_by_the_file(tmp_path):
    # a frame line holds at least 2 bytes a value ("0 "): a file declaring a huge
    # 'Frames:' gets room for size // (2 * channels) + 1 frames, the declared count when
    # that is smaller; under a 1-byte memory limit the refusal names the rows it wanted
    big = put(tmp_path, HEAD + LEG + "MOTION\nFrames: 9000000\nFrame Time: 0.04\n" + ROWS)
    size = big.stat().st_size
    with memory_limit(1), pytest.raises(ParseError) as info:
        read_bvh(big)
    assert f"{size // 16 + 1:,} frames of 8 channels need" in info.value.message
    with memory_limit(1), pytest.raises(ParseError) as info:
        read_bvh(put(tmp_path, TINY))
    assert "2 frames of 8 channels need 128 bytes" in info.value.message


def test_frames_declared_but_missing(tmp_path):
    err = parse_error(tmp_path, HEAD + LEG + "MOTION\nFrames: 5\nFrame Time: 0.04\n" + ROWS)
    assert err.line == 20 and "'Frames: 5' declared but only 2 frame lines found" in err.message
    # no frame line at all: the error points at the Frame Time line
    err = parse_error(tmp_path, HEAD + LEG + "MOTION\nFrames: 1\nFrame Time: 0.04\n\n\n")
    assert err.line == 18 and "only 0 frame lines found" in err.message
    # extra frames: the first one past the count is named
    err = parse_error(tmp_path, HEAD + LEG + "MOTION\nFrames: 1\nFrame Time: 0.04\n\n" + ROWS + "1 1 1 1 1 1 1 1\n")
    assert err.line == 21
    assert "'Frames: 1' declared but 3 frame lines found (line 21 is frame 2)" in err.message


M = HEAD + LEG  # lines 1..15; MOTION at 16
HEADER_CASES = [
    ("motion then nothing", M + "MOTION\n", 16, "MOTION section ends early: expected 'Frames: <count>'"),
    ("motion then blanks", M + "MOTION\n\n  \n", 16, "expected 'Frames: <count>'"),
    ("frames then nothing", M + "MOTION\n\nFrames: 2\n", 18, "expected 'Frame Time: <seconds>'"),
    ("frames is not first", M + "MOTION\nFrame Time: 0.04\nFrames: 2\n", 17, "expected 'Frames: <count>', found 'Frame Time: 0.04'"),
    ("frames line cut at 40", M + "MOTION\nFramez: " + "1234567890" * 6 + "\n", 17, "found 'Framez: 12345678901234567890123456789012'"),
    ("frames zero", M + "MOTION\nFrames: 0\nFrame Time: 0.04\n", 17, "must lie in 1.."),
    ("frames negative", M + "MOTION\nFrames: -2\nFrame Time: 0.04\n", 17, "found -2"),
    ("frames decimal", M + "MOTION\nFrames: 2.0\nFrame Time: 0.04\n", 17, "whole number"),
    ("frame time missing", M + "MOTION\nFrames: 2\n" + ROWS, 18, "expected 'Frame Time: <seconds>', found '0.5 1 1.5"),
    ("frame time word", M + "MOTION\nFrames: 2\nFrame Time: fast\n" + ROWS, 18, "expected a number after 'Frame Time:', found 'fast'"),
    ("frame time empty", M + "MOTION\nFrames: 2\nFrame Time:\n" + ROWS, 18, "found ''"),
    ("frame time too short", M + "MOTION\nFrames: 2\nFrame Time: 9e-7\n" + ROWS, 18, "in 1e-06..1e+06, found 9e-7"),
    ("frame time too long", M + "MOTION\nFrames: 2\nFrame Time: 1.1e6\n" + ROWS, 18, "found 1.1e6"),
    ("frame time nan", M + "MOTION\nFrames: 2\nFrame Time: nan\n" + ROWS, 18, "positive number of seconds"),
    ("frame time inf", M + "MOTION\nFrames: 2\nFrame Time: inf\n" + ROWS, 18, "positive number of seconds"),
    ("no channels at all", HEAD.replace("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation", "CHANNELS 0")
     + "}\nMOTION\nFrames: 1\nFrame Time: 0.04\n\n", 2, "declares no channels"),
]


@pytest.mark.parametrize("text, line, fragment", [c[1:] for c in HEADER_CASES], ids=[c[0] for c in HEADER_CASES])
def test_motion_header_errors(tmp_path, text, line, fragment):
    err = parse_error(tmp_path, text)
    assert err.line == line, str(err)
    assert fragment in err.message, str(err)


def test_no_channels_is_reported_only_after_a_good_frames_line(tmp_path):
    zero = HEAD.replace("CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation", "CHANNELS 0") + "}\n"
    err = parse_error(tmp_path, zero + "MOTION\nFrames: x\n")
    assert err.line == 8 and "whole number" in err.message
    err = parse_error(tmp_path, zero + "MOTION\nFrames: 1\n")
    assert err.line == 2 and "no channels" in err.message


def _leg(body: str) -> str:
    return HEAD + "\tJOINT Leg\n\t{\n" + body + "\t}\n}\n" + MOTION + ROWS


HIERARCHY_CASES = [
    ("only motion", "\n\nMOTION\nFrames: 1\n", 3, "expected HIERARCHY at the start of the file, found MOTION"),
    ("no hierarchy word", "ROOT Hips\n{\n}\nMOTION\n", 1, "expected HIERARCHY at the start of the file, found 'ROOT'"),
    ("no root word", "HIERARCHY\nJOINT Hips\n{\n}\nMOTION\n", 2, "expected ROOT after HIERARCHY, found 'JOINT'"),
    ("hierarchy alone", "HIERARCHY\n", 1, "hierarchy ended early: expected ROOT"),
    ("root without name", "HIERARCHY\nROOT\n{\n\tOFFSET 0 0 0\n}\nMOTION\n", 2, "expected a joint name after ROOT"),
    ("root without brace", "HIERARCHY\nROOT Hips\nOFFSET 0 0 0\n}\nMOTION\n", 3, "expected '{' after ROOT Hips, found 'OFFSET'"),
    ("root name at end", "HIERARCHY\nROOT Hips\nMOTION\n", 3, "hierarchy ended early: expected '{' opening joint 'Hips'"),
    ("joint without name", _leg("").replace("JOINT Leg", "JOINT"), 6, "expected a joint name after JOINT"),
    ("offset short at motion", "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0\nMOTION\n", 5, "hierarchy ended early: expected 3 numbers after OFFSET"),
    ("offset word", _leg("\t\tOFFSET 0 x 0\n"), 8, "expected 3 numbers after OFFSET, found 'x'"),
    ("offset inf", _leg("\t\tOFFSET 0 inf 0\n"), 8, "found non-finite value 'inf'"),
    ("offset nan", _leg("\t\tOFFSET nan 0 0\n"), 8, "non-finite value 'nan'"),
    ("offset too big", _leg("\t\tOFFSET 0 0 -1.5e9\n"), 8, "found '-1.5e9', beyond the largest supported magnitude 1e+09"),
    ("second offset", _leg("\t\tOFFSET 0 0 0\n\t\tOFFSET 0 0 0\n"), 9, "joint 'Leg' has a second OFFSET"),
    ("second channels", _leg("\t\tOFFSET 0 0 0\n\t\tCHANNELS 1 Xrotation\n\t\tCHANNELS 1 Yrotation\n"), 10, "joint 'Leg' has a second CHANNELS line"),
    ("channels count word", _leg("\t\tOFFSET 0 0 0\n\t\tCHANNELS three Xrotation\n"), 9, "whole number for the number of channels after CHANNELS"),
    ("channels seven", _leg("\t\tOFFSET 0 0 0\n\t\tCHANNELS 7\n"), 9, "must lie in 0..6, found 7"),
    ("channels negative", _leg("\t\tOFFSET 0 0 0\n\t\tCHANNELS -1\n"), 9, "found -1"),
    ("channels fewer listed", _leg("\t\tOFFSET 0 0 0\n\t\tCHANNELS 2 Xrotation\n"), 9, "CHANNELS declares 2 channels for joint 'Leg' but lists 1 (Xrotation)"),
    ("channels none listed", _leg("\t\tOFFSET 0 0 0\n\t\tCHANNELS 1\n"), 9, "lists 0 (none)"),
    ("channels on two lines", _leg("\t\tOFFSET 0 0 0\n\t\tCHANNELS 2 Xrotation\n\t\tYrotation\n"), 0, None),
    ("channel twice", _leg("\t\tOFFSET 0 0 0\n\t\tCHANNELS 2 Xrotation\n\t\tXROTATION\n"), 9, "channel Xrotation listed twice in joint 'Leg'"),
    ("unknown channel", _leg("\t\tOFFSET 0 0 0\n\t\tCHANNELS 1\n\t\tWrotation\n"), 10, "unknown channel name 'Wrotation' in joint 'Leg'; expected one of Xposition"),
    ("end not site", _leg("\t\tOFFSET 0 0 0\n\t\tEnd Zone\n"), 9, "expected 'End Site', found 'End Zone'"),
    ("end site no brace", _leg("\t\tOFFSET 0 0 0\n\t\tEnd Site\n\t\tOFFSET 0 1 0\n"), 10, "expected '{' after End Site, found 'OFFSET'"),
    ("end site no offset", _leg("\t\tOFFSET 0 0 0\n\t\tEnd Site\n\t\t{\n\t\tCHANNELS 0\n\t\t}\n"), 11, "expected OFFSET in End Site of 'Leg', found 'CHANNELS'"),
    ("end site unclosed", _leg("\t\tOFFSET 0 0 0\n\t\tEnd Site\n\t\t{\n\t\tOFFSET 0 1 0\n\t\tOFFSET\n"), 12, "expected '}' closing End Site of 'Leg', found 'OFFSET'"),
    ("end site twice", _leg("\t\tOFFSET 0 0 0\n\t\tEnd Site { OFFSET 0 1 0 }\n\t\tEnd Site { OFFSET 0 2 0 }\n"), 10, "joint 'Leg' has more than one End Site"),
    ("end at motion", "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nEnd\nMOTION\n", 6, "hierarchy ended early: expected 'Site' after 'End'"),
    ("joint unclosed", "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\n\n\nMOTION\n", 7, "joint 'Hips' opened at line 2 is not closed"),
    ("root without offset", "HIERARCHY\nROOT Hips\n{\nCHANNELS 1 Xrotation\n}\nMOTION\n", 5, "joint 'Hips' (line 2) has no OFFSET"),
    ("root inside a joint", _leg("\t\tOFFSET 0 0 0\n\t\tROOT Other\n"), 9, "a second ROOT inside a joint block"),
    ("junk in a joint", _leg("\t\tOFFSET 0 0 0\n\t\tSCALE 2\n"), 9, "unexpected 'SCALE' in joint 'Leg'; expected OFFSET"),
    ("junk after root", HEAD + "}\nJUNK\nMOTION\n", 7, "unexpected 'JUNK' after the root joint; expected MOTION"),
    ("second root", HEAD + "}\nroot Other\n{\n}\nMOTION\n", 7, "a second ROOT: only single-rooted"),
    ("extra brace", HEAD + "}\n\n}\nMOTION\n", 8, "unbalanced braces: '}' after the root joint was closed"),
    ("duplicate name", _leg("\t\tOFFSET 0 0 0\n\t\tJOINT Hips\n\t\t{\n\t\tOFFSET 0 0 0\n\t\t}\n"), 9, "joint name 'Hips' is used twice (first at line 2)"),
    ("no motion", HEAD + "}\n\n", 7, "missing MOTION section"),
]


@pytest.mark.parametrize("text, line, fragment", [c[1:] for c in HIERARCHY_CASES], ids=[c[0] for c in HIERARCHY_CASES])
def test_hierarchy_errors(tmp_path, text, line, fragment):
    if fragment is None:  # a well-formed variant: it reads
        read_bvh(put(tmp_path, text))
        return
    err = parse_error(tmp_path, text)
    assert err.line == line, str(err)
    assert fragment in err.message, str(err)


def test_empty_and_missing_files(tmp_path):
    for text in ("", "\n \n\t\n"):
        err = parse_error(tmp_path, text)
        assert err.line is None and "file is empty" in err.message
    with pytest.raises(ParseError, match="is a directory"):
        read_bvh(tmp_path)
    with pytest.raises(ParseError, match="no such file"):
        read_bvh(tmp_path / "none.bvh")


def test_channel_names_map_to_dofs():
    assert BVH_CHANNEL_NAMES == {
        "xposition": "tx", "yposition": "ty", "zposition": "tz",
        "xrotation": "rx", "yrotation": "ry", "zrotation": "rz",
    }


# ----------------------------------------------------------------------------- writing
def test_is_subsequence():
    assert _is_subsequence("", "ZXY")
    assert _is_subsequence("ZY", "ZXY")
    assert _is_subsequence("ZXY", "ZXY")
    assert not _is_subsequence("YZ", "ZXY")
    assert not _is_subsequence("XX", "ZXY")
    assert not _is_subsequence("XYZ", "XY")


@pytest.mark.parametrize(
    "order, full",
    [
        ("XYZ", "XYZ"), ("YXZ", "YXZ"),  # three axes: kept
        ("", "ZXY"), ("X", "ZXY"), ("Y", "ZXY"), ("Z", "ZXY"),  # fit ZXY
        ("ZX", "ZXY"), ("ZY", "ZXY"), ("XY", "ZXY"),
        ("XZ", "XZY"), ("YX", "YXZ"), ("YZ", "YZX"),  # do not fit: missing axis last
    ],
)
def test_complete_order(order, full):
    assert _complete_order(order) == full


def test_complete_order_with_another_preference():
    assert _complete_order("XZ", preferred="XYZ") == "XYZ"
    assert _complete_order("ZX", preferred="XYZ") == "ZXY"


def _skel(order="XZ", axis=None) -> Skeleton:
    dofs = tuple("r" + a.lower() for a in order)
    return Skeleton(joints=(
        Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rz", "rx", "ry"), "ZXY"),
        Joint("leg", 0, [0, -1, 0], dofs, order, axis=np.eye(3) if axis is None else axis,
              end_site=[0, -1, 0]),
    ))


def test_bvh_ready_orders():
    assert _bvh_ready_orders(_skel("XZ"), None) == ["ZXY", "XZY"]
    assert _bvh_ready_orders(_skel("XZ"), "XYZ") is None  # the root's ZXY does not fit
    assert _bvh_ready_orders(_skel("ZY"), "ZXY") == ["ZXY", "ZXY"]
    assert _bvh_ready_orders(_skel("XZ"), "ZXY") is None  # XZ does not fit ZXY
    tilted = np.eye(3)
    tilted[0, 1] = 1e-11  # not identity to 1e-12: an ASF-style axis
    assert _bvh_ready_orders(_skel("XZ", axis=tilted), None) is None
    tilted[0, 1] = 1.5e-12  # just past the 1e-12 tolerance
    assert _bvh_ready_orders(_skel("XZ", axis=tilted), None) is None
    nearly = np.eye(3)
    nearly[0, 1] = 1e-12  # at the tolerance: identity
    assert _bvh_ready_orders(_skel("XZ", axis=nearly), None) == ["ZXY", "XZY"]


def test_bvh_names():
    assert _bvh_names(["a b", "a_b", "a\tb", "{x}", "", "  "]) == [
        "a_b", "a_b_2", "a_b_3", "_x_", "joint", "joint_2"
    ]
    assert _bvh_names(["j", "j", "j_2", "j"]) == ["j", "j_2", "j_2_2", "j_3"]


def test_fmt_eight_decimals():
    assert _fmt([1, -0.5, 1 / 3]) == "1.00000000 -0.50000000 0.33333333"


def test_two_axis_joint_is_written_with_its_missing_axis_last(tmp_path):
    sk = _skel("XZ")
    vals = np.array([[1.0, 2.0, 3.0, 10.0, 20.0, 30.0, 40.0, 50.0]])
    m = Motion(vals, sk.channels, fps=30.0, skeleton=sk)
    write_bvh(m, tmp_path / "w.bvh")
    lines = (tmp_path / "w.bvh").read_text().split("\n")
    assert lines == [
        "HIERARCHY",
        "ROOT root",
        "{",
        "\tOFFSET 0.00000000 0.00000000 0.00000000",
        "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
        "\tJOINT leg",
        "\t{",
        "\t\tOFFSET 0.00000000 -1.00000000 0.00000000",
        "\t\tCHANNELS 3 Xrotation Zrotation Yrotation",
        "\t\tEnd Site",
        "\t\t{",
        "\t\t\tOFFSET 0.00000000 -1.00000000 0.00000000",
        "\t\t}",
        "\t}",
        "}",
        "MOTION",
        "Frames: 1",
        "Frame Time: 0.03333333333",
        "1.00000000 2.00000000 3.00000000 10.00000000 20.00000000 30.00000000 "
        "40.00000000 50.00000000 0.00000000",
        "",
    ]
    back = read_bvh(tmp_path / "w.bvh")
    assert back.skeleton.joints[1].rotation_order == "XZY"
    assert back.fps == 30.0


def test_missing_channels_are_written_as_offset_and_zero(tmp_path):
    # a root with rotations only gets position channels holding its offset; a non-root
    # joint with a translation dof gets six channels; children are written in order
    sk = Skeleton(joints=(
        Joint("r", -1, [5, 6, 7], ("ry",), "Y"),
        Joint("a", 0, [1, 0, 0], ("tx", "rz"), "Z", end_site=[1, 0, 0]),
        Joint("b", 0, [0, 1, 0], (), "", end_site=[0, 1, 0]),
        Joint("c", 1, [0, 0, 1], ("rx",), "X"),
    ))
    vals = np.array([[11.0, 0.25, 33.0, 44.0], [12.0, 0.5, 34.0, 45.0]])
    m = Motion(vals, sk.channels, fps=10.0, skeleton=sk)
    write_bvh(m, tmp_path / "w.bvh", continuous=False)
    text = (tmp_path / "w.bvh").read_text()
    lines = text.split("\n")
    assert [ln.strip() for ln in lines if ln.strip().startswith(("ROOT", "JOINT"))] == [
        "ROOT r", "JOINT a", "JOINT c", "JOINT b"
    ]
    chans = [ln.strip() for ln in lines if "CHANNELS" in ln]
    assert chans == [
        "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
        "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
        "CHANNELS 3 Zrotation Xrotation Yrotation",
        "CHANNELS 3 Zrotation Xrotation Yrotation",
    ]
    # depth of each block: JOINT c is inside a, b back at depth 1
    assert "\t\tJOINT c" in lines and "\tJOINT b" in lines
    i = lines.index("MOTION")
    assert lines[i + 2] == "Frame Time: 0.1"
    row = [float(x) for x in lines[i + 3].split()]
    # r: 5 6 7 | 0 0 11 ; a: 0.25 0 0 | 33 0 0 ; c: 0 44 0 ; b: 0 0 0
    assert row == [5, 6, 7, 0, 0, 11, 0.25, 0, 0, 33, 0, 0, 0, 44, 0, 0, 0, 0]
    back = read_bvh(tmp_path / "w.bvh")
    assert back.skeleton.names == ["r", "a", "c", "b"]
    got, want = back.positions().positions, m.positions().positions
    np.testing.assert_allclose(got[:, [0, 1, 3, 2]], want[:, :4], atol=1e-7)  # joints
    np.testing.assert_allclose(got[:, 4:], want[:, 4:], atol=1e-7)  # end sites of a, b


def test_continuous_rewrites_a_wrap_and_false_keeps_it(tmp_path):
    sk = Skeleton(joints=(Joint("r", -1, [0, 0, 0], ("tx", "ty", "tz", "rz", "rx", "ry"), "ZXY"),))
    vals = np.zeros((2, 6))
    vals[:, 3] = [170.0, -170.0]
    m = Motion(vals, sk.channels, fps=10.0, skeleton=sk)
    write_bvh(m, tmp_path / "kept.bvh", continuous=False)
    write_bvh(m, tmp_path / "cont.bvh")
    np.testing.assert_allclose(read_bvh(tmp_path / "kept.bvh").frames[:, 3], [170, -170])
    np.testing.assert_allclose(read_bvh(tmp_path / "cont.bvh").frames[:, 3], [170, 190])


def test_forced_order_and_writer_refusals(tmp_path):
    sk = _skel("XZ")
    m = Motion(np.zeros((1, 8)), sk.channels, skeleton=sk)
    write_bvh(m, tmp_path / "f.bvh", rotation_order="xzy")
    back = read_bvh(tmp_path / "f.bvh")
    assert [j.rotation_order for j in back.skeleton.joints] == ["XZY", "XZY"]
    with pytest.raises(ParameterError, match="needs a skeleton"):
        write_bvh(Motion(np.zeros((1, 1)), [("a", "rx")]), tmp_path / "n.bvh")
    assert not (tmp_path / "n.bvh").exists()


def test_a_byte_order_mark_is_not_part_of_the_first_word(tmp_path):
    # Windows editors save UTF-8 with a BOM; the AMC, ASF and CSV readers drop it, and
    # the BVH reader did not ("expected HIERARCHY ..., found '\ufeffHIERARCHY'")
    p = tmp_path / "bom.bvh"
    p.write_bytes(b"\xef\xbb\xbf" + TINY.replace("\n", "\r\n").encode("utf-8"))
    m = read_bvh(p)
    np.testing.assert_array_equal(m.frames[0], [0.5, 1, 1.5, 10, 20, 30, 40, 50])
    assert m.skeleton.names == ["Hips", "Leg"]
    # only a leading one: a BOM later in the file is text
    p.write_bytes(TINY.replace("ROOT Hips", "ROOT \ufeffHips").encode("utf-8"))
    assert read_bvh(p).skeleton.names == ["\ufeffHips", "Leg"]


def _chain(n: int) -> str:
    """A chain of n joints (the deepest at depth n - 1), one channel each."""
    out = ["HIERARCHY", "ROOT j0", "{", "OFFSET 0 0 0", "CHANNELS 1 Zrotation"]
    for i in range(1, n):
        out += [f"JOINT j{i}", "{", "OFFSET 0 1 0", "CHANNELS 1 Zrotation"]
    out += ["}"] * n + ["MOTION", "Frames: 1", "Frame Time: 0.01", " ".join(["0"] * n)]
    return "\n".join(out) + "\n"


def _bush(n: int) -> str:
    """A root and n - 1 children: n joints."""
    out = ["HIERARCHY", "ROOT r", "{", "OFFSET 0 0 0", "CHANNELS 1 Zrotation"]
    for i in range(1, n):
        out += [f"JOINT j{i}", "{", "OFFSET 0 1 0", "}"]
    out += ["}", "MOTION", "Frames: 1", "Frame Time: 0.01", "0"]
    return "\n".join(out) + "\n"


def test_depth_and_joint_caps_at_their_boundary(tmp_path):
    from cyclecoord.io._limits import MAX_DEPTH, MAX_JOINTS

    m = read_bvh(put(tmp_path, _chain(MAX_DEPTH + 1)))  # the deepest joint at MAX_DEPTH
    assert len(m.skeleton.joints) == MAX_DEPTH + 1
    err = parse_error(tmp_path, _chain(MAX_DEPTH + 2))
    assert err.line == 6 + 4 * MAX_DEPTH  # the JOINT line of the joint one level too deep
    assert f"more than {MAX_DEPTH} levels deep" in err.message
    m = read_bvh(put(tmp_path, _bush(MAX_JOINTS)))
    assert len(m.skeleton.joints) == MAX_JOINTS
    err = parse_error(tmp_path, _bush(MAX_JOINTS + 1))
    assert err.line == 6 + 4 * (MAX_JOINTS - 1)  # the JOINT line of joint MAX_JOINTS + 1
    assert f"more than {MAX_JOINTS:,} joints" in err.message
