"""Tests for BVH reading and writing (cyclecoord.io.bvh)."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io import read_bvh, write_bvh
from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton, forward_kinematics

# Mixed 6- and 3-channel joints, ZXY and ZYX joints, a 1-channel joint, End Sites, and
# a 6-channel non-root joint with positions after rotations.
SAMPLE = """\
HIERARCHY
ROOT Hips
{
\tOFFSET 0.0 0.0 0.0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT Chest
\t{
\t\tOFFSET 0 10 0
\t\tCHANNELS 3 Zrotation Yrotation Xrotation
\t\tJOINT Head
\t\t{
\t\t\tOFFSET 0 6 0.5
\t\t\tCHANNELS 3 Zrotation Xrotation Yrotation
\t\t\tEnd Site
\t\t\t{
\t\t\t\tOFFSET 0 3 0
\t\t\t}
\t\t}
\t}
\tJOINT LeftLeg
\t{
\t\tOFFSET 2 -1 0
\t\tCHANNELS 6 Zrotation Xrotation Yrotation Xposition Yposition Zposition
\t\tJOINT LeftKnee
\t\t{
\t\t\tOFFSET 0 -4 0
\t\t\tCHANNELS 1 Xrotation
\t\t\tEnd Site
\t\t\t{
\t\t\t\tOFFSET 0 -4 0.25
\t\t\t}
\t\t}
\t}
}
MOTION
Frames: 3
Frame Time: 0.0083333
1 2 3 10 20 30 1 2 3 4 5 6 7 8 9 2.5 -1 0.5 45
1.5 2.5 3.5 -10 -20 -30 0 0 0 0 0 0 0 0 0 2 -1 0 -45.25
0 90 -0.001 179.5 -89.9 0.125 5 5 5 -5 -5 -5 1 1 1 0 0 0 0
"""
SAMPLE_LINES = SAMPLE.splitlines()
LINE_OF: dict[str, int] = {}  # first line (1-based) of each stripped text
for _i, _text in enumerate(SAMPLE_LINES):
    LINE_OF.setdefault(_text.strip(), _i + 1)
N_CHANNELS = 19


def write_text(tmp_path: Path, text: str, name: str = "t.bvh") -> Path:
    p = tmp_path / name
    p.write_bytes(text.encode("utf-8"))
    return p


def sample_values() -> np.ndarray:
    rows = SAMPLE_LINES[-3:]
    return np.array([[float(v) for v in r.split()] for r in rows])


# ------------------------------------------------------------------------- parsing
def test_parse_sample_skeleton(tmp_path):
    m = read_bvh(write_text(tmp_path, SAMPLE))
    sk = m.skeleton
    assert sk.source_format == "bvh"
    assert sk.names == ["Hips", "Chest", "Head", "LeftLeg", "LeftKnee"]
    assert list(sk.parents) == [-1, 0, 1, 0, 3]
    by = {j.name: j for j in sk.joints}
    assert by["Hips"].dofs == ("tx", "ty", "tz", "rz", "rx", "ry")
    assert by["Hips"].rotation_order == "ZXY"
    assert by["Chest"].dofs == ("rz", "ry", "rx")
    assert by["Chest"].rotation_order == "ZYX"
    assert by["Head"].rotation_order == "ZXY"
    assert by["LeftLeg"].dofs == ("rz", "rx", "ry", "tx", "ty", "tz")
    assert by["LeftKnee"].dofs == ("rx",) and by["LeftKnee"].rotation_order == "X"
    np.testing.assert_array_equal(by["Head"].offset, [0, 6, 0.5])
    np.testing.assert_array_equal(by["LeftLeg"].offset, [2, -1, 0])
    np.testing.assert_array_equal(by["Head"].end_site, [0, 3, 0])
    np.testing.assert_array_equal(by["LeftKnee"].end_site, [0, -4, 0.25])
    assert by["Hips"].end_site is None and by["Chest"].end_site is None
    for j in sk.joints:
        np.testing.assert_array_equal(j.axis, np.eye(3))


def test_parse_sample_values(tmp_path):
    m = read_bvh(write_text(tmp_path, SAMPLE))
    assert m.fps == 120.0
    assert m.n_frames == 3 and m.n_channels == N_CHANNELS
    assert m.channels[:6] == (
        ("Hips", "tx"), ("Hips", "ty"), ("Hips", "tz"),
        ("Hips", "rz"), ("Hips", "rx"), ("Hips", "ry"),
    )
    assert m.channels[-1] == ("LeftKnee", "rx")
    np.testing.assert_array_equal(m.frames, sample_values())
    assert m.frames[1, m.channel_index("LeftKnee", "rx")] == -45.25
    assert m.frames[2, m.channel_index("Hips", "ty")] == 90.0


def test_crlf_tabs_and_extra_whitespace(tmp_path):
    messy = "\r\n".join("   " + ln.replace("\t", " \t ") + "  " for ln in SAMPLE_LINES)
    messy = messy.replace("Frames: 3", "Frames:   3").replace("{", "{ ")
    m1 = read_bvh(write_text(tmp_path, SAMPLE, "a.bvh"))
    m2 = read_bvh(write_text(tmp_path, messy + "\r\n\r\n", "b.bvh"))
    assert m2.channels == m1.channels
    np.testing.assert_array_equal(m2.frames, m1.frames)
    assert m2.skeleton.names == m1.skeleton.names


@pytest.mark.parametrize(
    "frame_time, fps",
    [("0.0083333", 120.0), ("0.033333", 30.0), ("0.0416667", 24.0), ("0.01", 100.0),
     ("0.03", 1 / 0.03)],
)
def test_fps_rounding(tmp_path, frame_time, fps):
    text = SAMPLE.replace("Frame Time: 0.0083333", f"Frame Time: {frame_time}")
    m = read_bvh(write_text(tmp_path, text))
    assert m.fps == pytest.approx(fps, rel=1e-12)


CHAIN = """\
HIERARCHY
ROOT root
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT child
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.04
1 2 3 90 0 0 0 90 0
0 0 0 90 90 0 0 0 0
0 0 0 0 0 0 0 0 0
"""


def test_forward_kinematics_of_a_chain(tmp_path):
    m = read_bvh(write_text(tmp_path, CHAIN))
    assert m.fps == 25.0
    fk = forward_kinematics(m)
    assert fk.names == ["root", "child", "child/end"]
    p = fk.positions
    # frame 0: Rz(90) sends the child offset (0,10,0) to (-10,0,0); the child's Rx(90)
    # sends the end site (0,5,0) to (0,0,5), which Rz(90) leaves alone.
    np.testing.assert_allclose(p[0], [[1, 2, 3], [-9, 2, 3], [-9, 2, 8]], atol=1e-12)
    # frame 1: listed order Z then X means Rz(90) @ Rx(90): (0,10,0) -> (0,0,10)
    # (the other order would give (-10,0,0))
    np.testing.assert_allclose(p[1], [[0, 0, 0], [0, 0, 10], [0, 0, 15]], atol=1e-12)
    np.testing.assert_allclose(p[2], [[0, 0, 0], [0, 10, 0], [0, 15, 0]], atol=1e-12)


# ------------------------------------------------------------------------- writing
def test_round_trip_exact(tmp_path):
    """continuous=False writes the numbers as given (the sample's frames jump by 180)."""
    m = read_bvh(write_text(tmp_path, SAMPLE))
    out = tmp_path / "out.bvh"
    write_bvh(m, out, continuous=False)
    m2 = read_bvh(out)
    assert m2.skeleton.names == m.skeleton.names
    assert m2.fps == m.fps
    for j1, j2 in zip(m.skeleton.joints, m2.skeleton.joints):
        assert j2.parent == j1.parent
        np.testing.assert_allclose(j2.offset, j1.offset, atol=1e-9)
        # each joint keeps its own rotation order
        if len(j1.rotation_order) == 3:
            assert j2.rotation_order == j1.rotation_order
        assert (j2.end_site is None) == (j1.end_site is None)
    # the 1-channel knee gets three rotation channels, its X in the same place
    assert m2.skeleton["LeftKnee"].rotation_order == "ZXY"
    np.testing.assert_allclose(m2.select(m.channels).frames, m.frames, atol=1e-6)
    extra = [c for c in m2.channels if c not in m.channels]
    assert sorted(extra) == [("LeftKnee", "ry"), ("LeftKnee", "rz")]
    np.testing.assert_array_equal(m2.select(extra).frames, 0.0)
    np.testing.assert_allclose(m2.positions().positions, m.positions().positions, atol=1e-6)
    # and once more: a BVH-convention file written by us reads back unchanged
    write_bvh(m2, tmp_path / "again.bvh", continuous=False)
    m3 = read_bvh(tmp_path / "again.bvh")
    assert m3.channels == m2.channels
    np.testing.assert_allclose(m3.frames, m2.frames, atol=1e-6)


def test_written_text_layout(tmp_path):
    m = read_bvh(write_text(tmp_path, SAMPLE))
    out = tmp_path / "out.bvh"
    write_bvh(m, out)
    lines = out.read_text().splitlines()
    assert lines[0] == "HIERARCHY" and lines[1] == "ROOT Hips" and lines[2] == "{"
    assert lines[3].startswith("\tOFFSET ")
    assert lines[4] == "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
    assert "\t\tCHANNELS 3 Zrotation Yrotation Xrotation" in lines
    assert "\t\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation" in lines
    assert "\t\t\tEnd Site" in lines
    assert lines.count("MOTION") == 1
    i = lines.index("MOTION")
    assert lines[i + 1] == "Frames: 3"
    assert lines[i + 2].startswith("Frame Time: 0.00833333")
    assert all(len(r.split()) == N_CHANNELS + 2 for r in lines[i + 3:])
    assert sum(ln.count("{") for ln in lines) == sum(ln.count("}") for ln in lines)


def test_writer_maps_columns_by_name(tmp_path):
    m = read_bvh(write_text(tmp_path, SAMPLE))
    rng = np.random.default_rng(0)
    perm = rng.permutation(m.n_channels)
    shuffled = m.select([m.channels[k] for k in perm])
    write_bvh(shuffled, tmp_path / "s.bvh", continuous=False)
    m2 = read_bvh(tmp_path / "s.bvh")
    np.testing.assert_allclose(m2.select(m.channels).frames, m.frames, atol=1e-6)


def test_random_values_round_trip_and_forced_order(tmp_path):
    m = read_bvh(write_text(tmp_path, SAMPLE))
    rng = np.random.default_rng(1)
    vals = rng.uniform(-170, 170, size=(40, m.n_channels))
    m = m.with_frames(vals)
    write_bvh(m, tmp_path / "r.bvh", continuous=False)
    back = read_bvh(tmp_path / "r.bvh")
    np.testing.assert_allclose(back.select(m.channels).frames, vals, atol=1e-6)
    # forcing one order re-expresses joints with other orders; positions unchanged
    write_bvh(m, tmp_path / "xyz.bvh", rotation_order="XYZ")
    forced = read_bvh(tmp_path / "xyz.bvh")
    assert {j.rotation_order for j in forced.skeleton.joints} == {"XYZ"}
    size = m.skeleton.total_length()
    np.testing.assert_allclose(
        forced.positions().positions, m.positions().positions, atol=1e-6 * size
    )


def asf_like_motion(rng: np.random.Generator, T: int = 30) -> Motion:
    from scipy.spatial.transform import Rotation

    def axis(*deg):
        return Rotation.from_euler("XYZ", deg, degrees=True).as_matrix()

    joints = (
        Joint("root", -1, [0, 0, 0], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX", axis(0, 0, 0)),
        Joint("femur", 0, [1, -1, 0.5], ("rx", "ry", "rz"), "ZYX", axis(0, 0, 20)),
        Joint("tibia", 1, [0, -7, 0], ("rx",), "X", axis(10, 0, 20)),
        Joint("foot", 2, [0, -7, 0], ("rx", "rz"), "ZX", axis(-90, 0, 20), end_site=[0, 0, 2]),
        Joint("neck", 0, [0, 5, 0], (), "", axis(30, 40, 50), end_site=[0, 2, 0]),
    )
    sk = Skeleton(joints, name="synthetic", source_format="asf")
    frames = rng.uniform(-120, 120, size=(T, len(sk.channels)))
    return Motion(frames=frames, channels=sk.channels, skeleton=sk, fps=60)


def test_writer_converts_asf_conventions(tmp_path):
    m = asf_like_motion(np.random.default_rng(2))
    write_bvh(m, tmp_path / "asf.bvh")
    back = read_bvh(tmp_path / "asf.bvh")
    assert back.fps == 60.0
    assert all(j.rotation_order == "ZXY" for j in back.skeleton.joints)
    a, b = forward_kinematics(m), forward_kinematics(back)
    assert b.names == a.names
    np.testing.assert_allclose(b.positions, a.positions, atol=1e-6 * m.skeleton.total_length())


def test_writer_makes_names_bvh_safe(tmp_path):
    sk = Skeleton((
        Joint("my root", -1, [0, 0, 0], ("rx",), "X"),
        Joint("my{root}", 0, [0, 1, 0], ("rx",), "X", end_site=[0, 1, 0]),
        # names that clash once made safe get _2, _3, ... in order
        Joint("my\troot", 0, [1, 0, 0], ("rx",), "X", end_site=[0, 1, 0]),
        Joint(" my root ", 0, [0, 0, 1], ("rx",), "X", end_site=[0, 1, 0]),
    ))
    m = Motion(np.array([[10.0, 20.0, 30.0, 40.0]]), sk.channels, skeleton=sk)
    write_bvh(m, tmp_path / "n.bvh")
    back = read_bvh(tmp_path / "n.bvh")
    assert back.skeleton.names == ["my_root", "my_root_", "my_root_2", "my_root_3"]
    np.testing.assert_allclose(back.positions().positions, m.positions().positions, atol=1e-9)


def test_writer_rejects_bad_input(tmp_path):
    m = read_bvh(write_text(tmp_path, SAMPLE))
    with pytest.raises(ParameterError, match="skeleton"):
        write_bvh(Motion(m.frames, m.channels), tmp_path / "x.bvh")
    with pytest.raises(ParameterError, match="permutation of XYZ"):
        write_bvh(m, tmp_path / "x.bvh", rotation_order="ZZY")
    assert not (tmp_path / "x.bvh").exists()


# ---------------------------------------------------------------------------- errors
def mutate(old: str, new: str, count: int = 1) -> str:
    assert old in SAMPLE, old
    return SAMPLE.replace(old, new, count)


FRAME1 = SAMPLE_LINES[-3]
FRAME1_LINE = len(SAMPLE_LINES) - 2
ERROR_CASES = [
    ("empty", "", None, "empty"),
    ("blank", "  \n\t\n", None, "empty"),
    ("no hierarchy", SAMPLE.replace("HIERARCHY\n", ""), 1, "expected HIERARCHY"),
    (
        "no motion",
        SAMPLE[: SAMPLE.index("MOTION")],
        len(SAMPLE[: SAMPLE.index("MOTION")].splitlines()),
        "missing MOTION",
    ),
    (
        "missing close brace",
        mutate("\t\t\t\tOFFSET 0 3 0\n\t\t\t}\n\t\t}\n", "\t\t\t\tOFFSET 0 3 0\n\t\t\t}\n"),
        LINE_OF["MOTION"] - 1,
        "unbalanced braces",
    ),
    ("extra close brace", mutate("}\nMOTION", "}\n}\nMOTION"), LINE_OF["MOTION"], "unbalanced braces"),
    (
        "unknown channel",
        mutate("CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 3 Zrotation Wrotation Xrotation"),
        LINE_OF["CHANNELS 3 Zrotation Yrotation Xrotation"],
        "unknown channel name 'Wrotation'",
    ),
    (
        "channel count",
        mutate("CHANNELS 3 Zrotation Yrotation Xrotation", "CHANNELS 4 Zrotation Yrotation Xrotation"),
        LINE_OF["CHANNELS 3 Zrotation Yrotation Xrotation"],
        "declares 4 channels",
    ),
    (
        "short frame",
        mutate(FRAME1, FRAME1.rsplit(" ", 1)[0]),
        FRAME1_LINE,
        f"frame 1 has {N_CHANNELS - 1} values, the hierarchy declares {N_CHANNELS} channels",
    ),
    (
        "long frame",
        SAMPLE.replace(SAMPLE_LINES[-1], SAMPLE_LINES[-1] + " 7"),
        FRAME1_LINE + 2,
        f"frame 3 has {N_CHANNELS + 1} values",
    ),
    ("frames too many", mutate("Frames: 3", "Frames: 5"), FRAME1_LINE + 2, "only 3 frame lines found"),
    ("frames too few", mutate("Frames: 3", "Frames: 2"), FRAME1_LINE + 2, "3 frame lines found"),
    ("not a number", mutate("45.25", "4x5"), FRAME1_LINE + 1, "is '-4x5', expected a number"),
    ("nan", mutate("45.25", "nan"), FRAME1_LINE + 1, "expected a finite number"),
    ("inf", mutate(" 179.5 ", " -inf "), FRAME1_LINE + 2, "expected a finite number"),
    ("zero frame time", mutate("Frame Time: 0.0083333", "Frame Time: 0"), FRAME1_LINE - 1, "positive"),
    ("negative frame time", mutate("Frame Time: 0.0083333", "Frame Time: -1"), FRAME1_LINE - 1, "positive"),
    ("bad frame count", mutate("Frames: 3", "Frames: three"), FRAME1_LINE - 2, "whole number"),
    ("no frames line", mutate("Frames: 3\n", ""), FRAME1_LINE - 2, "Frames: <count>"),
    ("bad offset", mutate("OFFSET 0 6 0.5", "OFFSET 0 six 0.5"), LINE_OF["OFFSET 0 6 0.5"], "3 numbers after OFFSET"),
    ("duplicate joint", mutate("JOINT Head", "JOINT Chest"), LINE_OF["JOINT Head"], "used twice"),
    ("two roots", SAMPLE.replace("MOTION", SAMPLE[SAMPLE.index("ROOT"):SAMPLE.index("MOTION")] + "MOTION", 1), LINE_OF["MOTION"], "second ROOT"),
    ("end without site", mutate("End Site\n\t\t\t{\n\t\t\t\tOFFSET 0 3 0", "End Zone\n\t\t\t{\n\t\t\t\tOFFSET 0 3 0"), LINE_OF["End Site"], "End Site"),
    ("missing offset", mutate("\t\tOFFSET 0 10 0\n", ""), LINE_OF["JOINT LeftLeg"] - 2, "no OFFSET"),
    ("junk keyword", mutate("\t\tOFFSET 0 10 0\n", "\t\tOFFSET 0 10 0\n\t\tBONE x\n"), LINE_OF["OFFSET 0 10 0"] + 1, "unexpected 'BONE'"),
]


@pytest.mark.parametrize("name, text, line, fragment", ERROR_CASES, ids=[c[0] for c in ERROR_CASES])
def test_parse_errors(tmp_path, name, text, line, fragment):
    p = write_text(tmp_path, text)
    with pytest.raises(ParseError) as info:
        read_bvh(p)
    err = info.value
    assert err.path == str(p)
    assert err.line == line, str(err)
    assert fragment in err.message, str(err)
    assert str(err).startswith(str(p))


def test_missing_file(tmp_path):
    with pytest.raises(ParseError, match="no such file"):
        read_bvh(tmp_path / "nope.bvh")


# ----------------------------------------------------------------------- robustness
@st.composite
def mangled(draw) -> str:
    lines = list(SAMPLE_LINES)
    for _ in range(draw(st.integers(1, 4))):
        if not lines:
            break
        op = draw(st.sampled_from(["delete", "duplicate", "junk", "replace", "truncate", "swap"]))
        i = draw(st.integers(0, len(lines) - 1))
        if op == "delete":
            del lines[i]
        elif op == "duplicate":
            lines.insert(i, lines[i])
        elif op == "junk":
            junk = draw(
                st.sampled_from(["{", "}", "JOINT", "End", "CHANNELS", "OFFSET", "-", "1e999",
                                 "nan", "MOTION", "Frames:", "3", "ROOT x", "\x00", "é", "Site"])
            )
            toks = lines[i].split()
            toks.insert(draw(st.integers(0, len(toks))), junk)
            lines[i] = " ".join(toks)
        elif op == "replace":
            toks = lines[i].split()
            if toks:
                k = draw(st.integers(0, len(toks) - 1))
                toks[k] = draw(st.text(min_size=0, max_size=5))
                lines[i] = " ".join(toks)
        elif op == "swap":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        else:
            text = "\n".join(lines)
            cut = draw(st.integers(0, len(text)))
            lines = text[:cut].split("\n")
    return "\n".join(lines)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(text=mangled())
def test_mangled_files_parse_or_raise_parse_error(text):
    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "m.bvh"
        p.write_bytes(text.encode("utf-8", errors="surrogatepass"))
        try:
            m = read_bvh(p)
        except ParseError as err:
            assert err.path == str(p)
            return
        assert isinstance(m, Motion)
        assert m.frames.shape == (m.n_frames, len(m.skeleton.channels))
        assert np.isfinite(m.frames).all()


def test_written_euler_channels_never_jump(tmp_path):
    """A capture whose Euler numbers wrap and flip is written with continuous channels that
    pose the same body (issue 23: no written file flips)."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "periodic"))
    from test_rotations import scrambled

    import cyclecoord as cc
    from cyclecoord.conventions import to_bvh_convention

    m = scrambled(to_bvh_convention(cc.datasets.example_capture().motion[:120], "ZXY"))
    joints = np.setdiff1d(np.arange(m.n_channels), np.asarray(m.root_channels()))
    assert np.abs(np.diff(m.frames[:, joints], axis=0)).max() > 100
    cc.save(m, tmp_path / "w.bvh")
    back = cc.load(tmp_path / "w.bvh")
    assert np.abs(np.diff(back.frames[:, joints], axis=0)).max() < 20
    np.testing.assert_allclose(back.positions().positions, m.positions().positions, atol=1e-4)
