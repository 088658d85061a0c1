"""Known-answer tests of the Acclaim ASF/AMC reader and writer (cyclecoord.io._acclaim,
asf_read, amc_read, asfamc_write): a tiny hand-made skeleton and motion whose joints,
axes, limits, values and error lines are known, and each helper at its edges."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io._limits import memory_limit
from cyclecoord.io._acclaim import (
    _asf_listing,
    asf_layout,
    axis_angles,
    axis_matrix,
    fmt_float,
    parse_number,
    parse_numbers,
    read_text,
    safe_name,
    strip_comment,
)
from cyclecoord.io.amc_read import _header_skeleton, find_skeleton
from cyclecoord.io.asf_read import parse_asf
from cyclecoord.io.asfamc import read_amc, read_asf, write_amc, write_asf
from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton


def rx(a):
    c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a):
    c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a):
    c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


# line numbers in the comments
TINY_ASF = """\
:version 1.10
:name tiny
:units
  mass 2.0
  length 0.45
  angle deg
:root
  order TX TY TZ RX RY RZ
  axis XYZ
  position 1 2 3
  orientation 0 0 90
:bonedata
  begin
    id 1
    name upper
    direction 0 -1 0
    length 2
    axis 0 0 0 XYZ
    dof rx rz
    limits (-90 90)
           (-inf inf)
  end
  begin
    id 2
    name lower
    direction 1 0 0
    length 3
    axis 90 0 0 XYZ
    dof rx
  end
:hierarchy
  begin
    root upper
    upper lower
  end
"""
TINY_LINES = TINY_ASF.split("\n")


def line_of(needle: str, text: str = TINY_ASF) -> int:
    return next(i for i, ln in enumerate(text.split("\n"), 1) if needle in ln)


def put(folder: Path, name: str, text: str) -> Path:
    p = folder / name
    p.write_bytes(text.encode("utf-8"))
    return p


TINY_AMC = """\
# a comment
:FULLY-SPECIFIED
:DEGREES
1
root 1 2 3 10 20 30
upper 40 50
lower 60
2
root -1 -2 -3 -10 -20 -30
upper -40 -50
lower -60
"""
TINY_CHANNELS = (
    ("root", "tx"), ("root", "ty"), ("root", "tz"), ("root", "rx"), ("root", "ry"),
    ("root", "rz"), ("upper", "rx"), ("upper", "rz"), ("lower", "rx"),
)


# --------------------------------------------------------------------- _acclaim helpers
def test_read_text_normalises_line_ends_and_bom(tmp_path):
    p = tmp_path / "t.asf"
    p.write_bytes(b"\xef\xbb\xbfa\r\nb\rc\n")
    assert read_text(p) == "a\nb\nc\n"
    p.write_bytes(b"\xff x\n")
    assert read_text(p) == "\ufffd x\n"
    with pytest.raises(ParseError, match="is a folder"):
        read_text(tmp_path)
    with pytest.raises(ParseError, match="cannot read file") as info:
        read_text(tmp_path / "none.asf")
    assert info.value.path == str(tmp_path / "none.asf")


def test_strip_comment():
    assert strip_comment("  a b  # c # d") == "a b"
    assert strip_comment("# all") == ""
    assert strip_comment("\tx\t") == "x"


def test_parse_number_edges():
    assert parse_number("1e9", "f", 3, "w") == 1e9
    assert parse_number("-1e9", "f", 3, "w") == -1e9
    with pytest.raises(ParseError, match=r"w is '1.5e9', beyond the largest supported magnitude 1e\+09") as info:
        parse_number("1.5e9", "f", 3, "w")
    assert (info.value.path, info.value.line) == ("f", 3)
    with pytest.raises(ParseError, match="expected a number for w, got 'x'"):
        parse_number("x", "f", 3, "w")
    with pytest.raises(ParseError, match="expected a finite number for w, got 'inf'"):
        parse_number("inf", "f", 3, "w")
    assert parse_number("inf", "f", 3, "w", allow_inf=True) == math.inf
    assert parse_number("-inf", "f", 3, "w", allow_inf=True) == -math.inf
    with pytest.raises(ParseError, match="finite number"):
        parse_number("nan", "f", 3, "w", allow_inf=True)
    with pytest.raises(ParseError, match="beyond"):
        parse_number("2e9", "f", 3, "w", allow_inf=True)


def test_parse_numbers_counts():
    np.testing.assert_array_equal(parse_numbers(["1", "2", "3"], 3, "f", 1, "v"), [1, 2, 3])
    with pytest.raises(ParseError, match=r"^f:4: v needs 1 number, got 2 \(1 2\)$"):
        parse_numbers(["1", "2"], 1, "f", 4, "v")
    with pytest.raises(ParseError, match=r"v needs 3 numbers, got 0 \(nothing\)"):
        parse_numbers([], 3, "f", 4, "v")


def test_axis_matrix_is_extrinsic_first_letter_first():
    a, b, c = 10.0, -20.0, 30.0
    np.testing.assert_allclose(axis_matrix(np.array([a, b, c]), "XYZ"), rz(c) @ ry(b) @ rx(a), atol=1e-12)
    np.testing.assert_allclose(axis_matrix(np.array([a, b, c]), "ZYX"), rx(c) @ ry(b) @ rz(a), atol=1e-12)
    np.testing.assert_allclose(axis_matrix(np.array([a, b, c]), "yzx"), rx(c) @ rz(b) @ ry(a), atol=1e-12)


def test_axis_angles_round_only_when_exact():
    m = rz(30.0) @ ry(-20.0) @ rx(10.0)
    got = axis_angles(m)
    np.testing.assert_array_equal(got, [10.0, -20.0, 30.0])  # rounded to 1e-9 exactly
    off = axis_matrix(np.array([10.0000000001, 0.0, 0.0]), "XYZ")
    g = axis_angles(off)
    assert g[0] != 10.0 and g[0] == pytest.approx(10.0000000001, abs=1e-12)
    np.testing.assert_array_equal(axis_angles(np.eye(3)), [0.0, 0.0, 0.0])


def test_fmt_float():
    assert fmt_float(0.0) == "0" and fmt_float(-0.0) == "0"
    assert fmt_float(1) == "1.0" and fmt_float(-2.5) == "-2.5"
    assert fmt_float(0.1) == "0.1" and fmt_float(1 / 3) == repr(1 / 3)
    assert float(fmt_float(1e-300)) == 1e-300


@pytest.mark.parametrize(
    "name, safe",
    [
        ("LeftArm", "LeftArm"),
        ("left arm", "left_arm"),
        ("a # b", "a_b"),
        ("f(x)", "f_x_"),
        ("a\t\n b", "a_b"),
        ("", "joint"),
        (":x", "j_:x"),
        ("root", "j_root"),
        ("Begin", "j_Begin"),
        ("END", "j_END"),
        ("12", "j_12"),
        ("1e5", "j_1e5"),
        ("-3.5", "j_-3.5"),
        ("nan", "j_nan"),
        ("x:", "x:"),
        ("rooted", "rooted"),
    ],
)
def test_safe_name(name, safe):
    assert safe_name(name) == safe


def test_asf_listing():
    # ASF joints list rotations in reverse intrinsic order: kept as they are
    j = Joint("a", 0, [0, 0, 0], ("rx", "ry", "rz"), "ZYX")
    assert _asf_listing(j) == ("rx", "ry", "rz")
    # a BVH joint listing ZXY in intrinsic order: written reversed, translations first
    j = Joint("b", -1, [0, 0, 0], ("tx", "ty", "tz", "rz", "rx", "ry"), "ZXY")
    assert _asf_listing(j) == ("tx", "ty", "tz", "ry", "rx", "rz")
    j = Joint("c", 0, [0, 0, 0], ("rz", "ty"), "Z")
    assert _asf_listing(j) == ("rz", "ty")
    j = Joint("d", 0, [0, 0, 0], ("rx", "rz"), "XZ")
    assert _asf_listing(j) == ("rz", "rx")


def test_asf_layout_helper_bones_and_vectors():
    sk = Skeleton(joints=(
        Joint("Hips", -1, [0, 5, 0], ("tx", "ty", "tz", "rz", "rx", "ry"), "ZXY"),
        Joint("L", 0, [1, 0, 0], ("rx",), "X"),  # the root's children differ: helpers
        Joint("R", 0, [-1, 0, 0], ("rx",), "X"),
        Joint("Lk", 1, [0, -2, 0], ("rx",), "X", end_site=[0, -3, 0]),
        Joint("Rk", 2, [0, -2, 0], (), "", limits={}),  # leaf without an end site
    ))
    lay = asf_layout(sk)
    assert [b.asf_name for b in lay] == ["root", "root_to_L", "L", "root_to_R", "R", "Lk", "Rk"]
    assert [b.joint for b in lay] == ["Hips", None, "L", None, "R", "Lk", "Rk"]
    assert [b.parent for b in lay] == [None, "root", "root_to_L", "root", "root_to_R", "L", "R"]
    vec = {b.asf_name: b.vector for b in lay}
    np.testing.assert_array_equal(vec["root"], [0, 0, 0])
    np.testing.assert_array_equal(vec["root_to_L"], [1, 0, 0])
    np.testing.assert_array_equal(vec["root_to_R"], [-1, 0, 0])
    np.testing.assert_array_equal(vec["L"], [0, -2, 0])  # its only child's offset
    np.testing.assert_array_equal(vec["Lk"], [0, -3, 0])  # its end site
    np.testing.assert_array_equal(vec["Rk"], [0, 0, 0])
    np.testing.assert_array_equal(lay[0].position, [0, 5, 0])
    assert lay[0].dofs == ("tx", "ty", "tz", "ry", "rx", "rz")
    assert lay[1].dofs == () and lay[2].dofs == ("rx",)


def test_asf_layout_shares_offsets_within_a_relative_tolerance():
    def two_kids(d):
        return Skeleton(joints=(
            Joint("r", -1, [0, 0, 0], (), ""),
            Joint("a", 0, [0, 0, 0], ("rx",), "X"),
            Joint("b", 1, [0, 100, 0], (), "", end_site=[0, 1, 0]),
            Joint("c", 1, [0, 100 + d, 0], (), "", end_site=[0, 1, 0]),
        ))
    # size 100: tolerance 1e-10
    assert [b.asf_name for b in asf_layout(two_kids(5e-11))] == ["root", "a", "b", "c"]
    names = [b.asf_name for b in asf_layout(two_kids(5e-10))]
    assert names == ["root", "a", "a_to_b", "b", "a_to_c", "c"]  # 'a' points nowhere
    lay = asf_layout(two_kids(5e-10))
    np.testing.assert_array_equal(lay[1].vector, [0, 0, 0])
    np.testing.assert_array_equal(lay[2].vector, [0, 100, 0])
    np.testing.assert_array_equal(lay[4].vector, [0, 100 + 5e-10, 0])
    # the size counts end sites too: a far end site widens the tolerance
    sk = Skeleton(joints=(
        Joint("r", -1, [0, 0, 0], (), ""),
        Joint("a", 0, [0, 0, 0], ("rx",), "X"),
        Joint("b", 1, [0, 1, 0], (), "", end_site=[0, 1e4, 0]),
        Joint("c", 1, [0, 1 + 5e-9, 0], (), "", end_site=[0, 1, 0]),
    ))
    assert [b.asf_name for b in asf_layout(sk)] == ["root", "a", "b", "c"]


def test_asf_layout_names_and_limits():
    sk = Skeleton(joints=(
        Joint("my root", -1, [0, 0, 0], ("rx",), "X"),
        Joint("a b", 0, [0, 0, 0], ("rx", "rz"), "ZX", limits={"rx": (-10.0, 20.0)}),
        Joint("a_b", 1, [0, 0, 0], ("rx",), "X", end_site=[0, 1, 0]),
        Joint("root", 0, [0, 0, 0], ("ry",), "Y", end_site=[1, 0, 0]),
    ))
    lay = asf_layout(sk)
    assert [b.asf_name for b in lay] == ["root", "a_b", "a_b_2", "j_root"]
    assert lay[1].limits == {"rx": (-10.0, 20.0), "rz": (-math.inf, math.inf)}
    assert lay[2].limits == {} and lay[3].limits == {}


# --------------------------------------------------------------------- ASF reading
def test_tiny_asf_known_skeleton(tmp_path):
    sk, info = parse_asf(TINY_ASF, "t.asf")
    assert info == {"angle": "deg", "mass": 2.0, "version": "1.10"}
    assert sk.name == "tiny" and sk.length_unit == 0.45 and sk.source_format == "asf"
    assert sk.names == ["root", "upper", "lower"]
    assert [j.parent for j in sk.joints] == [-1, 0, 1]
    root, upper, lower = sk.joints
    assert root.dofs == ("tx", "ty", "tz", "rx", "ry", "rz") and root.rotation_order == "ZYX"
    np.testing.assert_array_equal(root.offset, [1, 2, 3])
    np.testing.assert_allclose(root.axis, rz(90), atol=1e-12)
    assert upper.dofs == ("rx", "rz") and upper.rotation_order == "ZX"
    np.testing.assert_array_equal(upper.offset, [0, 0, 0])
    np.testing.assert_allclose(upper.axis, np.eye(3), atol=0)
    assert upper.end_site is None
    assert upper.limits == {"rx": (-90.0, 90.0), "rz": (-math.inf, math.inf)}
    assert lower.dofs == ("rx",) and lower.rotation_order == "X"
    np.testing.assert_array_equal(lower.offset, [0, -2, 0])  # the parent's direction * length
    np.testing.assert_allclose(lower.axis, rx(90), atol=1e-12)
    np.testing.assert_array_equal(lower.end_site, [3, 0, 0])
    assert lower.limits == {}
    assert read_asf(put(tmp_path, "t.asf", TINY_ASF)).names == ["root", "upper", "lower"]


def test_radian_asf_scales_axes_and_rotation_limits_only(tmp_path):
    h = math.pi / 2
    text = (TINY_ASF.replace("angle deg", "angle radians")
            .replace("orientation 0 0 90", f"orientation 0 0 {h!r}")
            .replace("axis 90 0 0 XYZ", f"axis {h!r} 0 0 XYZ")
            .replace("(-90 90)", f"({-h!r} {h!r})")
            .replace("dof rx rz\n", "dof rx tz\n").replace("(-inf inf)", "(-0.5 0.5)"))
    sk, info = parse_asf(text, "r.asf")
    assert info["angle"] == "rad"
    np.testing.assert_allclose(sk.joints[0].axis, rz(90), atol=1e-12)
    np.testing.assert_allclose(sk.joints[2].axis, rx(90), atol=1e-12)
    lim = sk.joints[1].limits
    assert lim["rx"] == pytest.approx((-90.0, 90.0), abs=1e-12)
    assert lim["tz"] == (-0.5, 0.5)


def test_asf_fields_read_loosely():
    text = (TINY_ASF.replace(":name tiny", ":NAME  two words ")
            .replace("axis 90 0 0 XYZ", "axis 90 0 0 zyx")
            .replace("    id 2\n", "    id 2\n    bodymass 3\n    cofmass 0.5\n")
            .replace("  angle deg", "  angle degrees\n  time 1")
            .replace("length 3", "length 0")
            .replace("limits (-90 90)\n           (-inf inf)", "limits (-90 90) ( -1 +1 )")
            .replace(":version 1.10", ":version 1.10 beta\n# comment\n:documentation\n  free text : here\n:skin\n:skin"))
    sk, info = parse_asf(text, "x.asf")
    assert sk.name == "two words" and info["version"] == "1.10 beta"
    np.testing.assert_allclose(sk.joints[2].axis, rz(90), atol=1e-12)  # 90 pairs with z
    np.testing.assert_array_equal(sk.joints[2].end_site, [0, 0, 0])  # length 0 is allowed
    assert sk.joints[1].limits == {"rx": (-90.0, 90.0), "rz": (-1.0, 1.0)}
    # the order letters decide the axis: ZYX with the z angle first
    t2 = TINY_ASF.replace("axis 90 0 0 XYZ", "axis 10 20 30 ZYX")
    np.testing.assert_allclose(parse_asf(t2, "x")[0].joints[2].axis, rx(30) @ ry(20) @ rz(10), atol=1e-12)
    t3 = TINY_ASF.replace("axis 90 0 0 XYZ", "axis 10 20 30")
    np.testing.assert_allclose(parse_asf(t3, "x")[0].joints[2].axis, rz(30) @ ry(20) @ rx(10), atol=1e-12)
    t4 = TINY_ASF.replace("axis XYZ\n", "axis zyx\n").replace("orientation 0 0 90", "orientation 10 20 30")
    np.testing.assert_allclose(parse_asf(t4, "x")[0].joints[0].axis, rx(30) @ ry(20) @ rz(10), atol=1e-12)


def test_root_only_asf_and_default_root():
    text = ":root\n:bonedata\n"
    sk, info = parse_asf(text, "r.asf")
    assert sk.names == ["root"] and sk.joints[0].dofs == ()
    np.testing.assert_array_equal(sk.joints[0].offset, [0, 0, 0])
    np.testing.assert_array_equal(sk.joints[0].axis, np.eye(3))
    assert info == {"angle": "deg", "mass": 1.0, "version": ""} and sk.length_unit == 1.0


def _swap(old: str, new: str) -> str:
    assert old in TINY_ASF, old
    return TINY_ASF.replace(old, new, 1)


L = line_of
ASF_CASES = [
    ("text before a section", "hello\n" + TINY_ASF, 1, "expected an ASF section keyword such as ':version' or ':root', got 'hello'"),
    ("text after version", _swap(":name tiny", "  1.2\n:name tiny"), 2, "unexpected line after :version: '1.2'; expected a section keyword"),
    ("text after name", _swap(":units", "  more\n:units"), 3, "unexpected line after :name"),
    ("words after units", _swap(":units", ":units metric"), 3, "unexpected text after :units: 'metric'"),
    ("section twice", _swap(":hierarchy", ":units\n:hierarchy"), 31, "section :units appears twice (first at line 3)"),
    ("units one word", _swap("mass 2.0", "mass"), 4, "expected 'unit value' under :units, got 'mass'"),
    ("units three words", _swap("mass 2.0", "mass 2 kg"), 4, "expected 'unit value'"),
    ("length zero", _swap("length 0.45", "length 0"), 5, "units length must be positive, got '0'"),
    ("mass negative", _swap("mass 2.0", "mass -1"), 4, "units mass must be positive"),
    ("length word", _swap("length 0.45", "length long"), 5, "expected a number for units length, got 'long'"),
    ("root field twice", _swap("position 1 2 3", "position 1 2 3\n  position 1 2 3"), 11, "root field 'position' given twice (first at line 10)"),
    ("root axis two words", _swap("  axis XYZ\n", "  axis X YZ\n"), 9, "root axis needs one order such as XYZ"),
    ("root axis bad", _swap("  axis XYZ\n", "  axis XYX\n"), 9, "root: axis order must be a permutation of XYZ, got 'XYX'"),
    ("root position short", _swap("position 1 2 3", "position 1 2"), 10, "root position needs 3 numbers, got 2"),
    ("root orientation word", _swap("orientation 0 0 90", "orientation 0 a 90"), 11, "expected a number for root orientation, got 'a'"),
    ("root unknown field", _swap("position 1 2 3", "place 1 2 3"), 10, "unknown root field 'place'; expected order, axis, position or orientation"),
    ("root order twice", _swap("order TX TY TZ RX RY RZ", "order TX TX"), 8, "root order: degree of freedom 'TX' listed twice"),
    ("section inside a bone", _swap("    id 2\n", "    id 2\n:hierarchy\n"), 25, "bone block opened at line 23 has no 'end' before :hierarchy"),
    ("section inside hierarchy", TINY_ASF.rstrip("\n").rsplit("\n", 1)[0] + "\n:skin\n", 35, "hierarchy block opened at line 32 has no 'end' before :skin"),
    ("bone name two words", _swap("name lower", "name low er"), 25, "bone name must be one word"),
    ("bone length two numbers", _swap("length 3", "length 3 4"), 27, "bone 'lower' length needs 1 number, got 2"),
    ("bone length negative", _swap("length 3", "length -0.5"), 27, "bone 'lower' length must not be negative, got '-0.5'"),
    ("bone axis short", _swap("axis 90 0 0 XYZ", "axis 90 0"), 28, "bone 'lower' axis needs 3 angles and an order"),
    ("bone axis order bad", _swap("axis 90 0 0 XYZ", "axis 90 0 0 XY"), 28, "bone 'lower': axis order must be a permutation of XYZ"),
    ("bone axis word", _swap("axis 90 0 0 XYZ", "axis 90 x 0 XYZ"), 28, "expected a number for bone 'lower' axis, got 'x'"),
    ("dof unknown unnamed", _swap("    id 1\n    name upper\n", "    id 1\n    dof rq\n    name upper\n"), 15, "bone: unknown degree of freedom 'rq'"),
    ("limits not after limits", _swap("    dof rx\n", "    dof rx\n    (0 1)\n"), 30, "limits line '(0 1)' does not follow 'limits'"),
    ("limits empty", _swap("limits (-90 90)", "limits"), 20, "expected limits as '(low high)', got ''"),
    ("limits three numbers", _swap("(-inf inf)", "(-1 0 1)"), 21, "expected limits as '(low high)', got '(-1 0 1)'"),
    ("limits nan", _swap("(-inf inf)", "(nan 1)"), 21, "expected a finite number for a lower limit"),
    ("limits upper word", _swap("(-inf inf)", "(1 up)"), 21, "expected a number for an upper limit, got 'up'"),
    ("limits parens swapped", _swap("(-inf inf)", "(-1 1("), 21, "(low high)"),
    ("limits too many", _swap("(-inf inf)", "(-inf inf)\n           (0 1)"), 20, "bone 'upper' has 2 dofs (rx rz) but 3 limits"),
    ("limits without dofs", _swap("    dof rx\n", "    limits (0 1)\n"), 29, "bone 'lower' has 0 dofs (none) but 1 limits"),
    ("bone without name", _swap("    name lower\n", ""), 29, "bone block starting at line 23 has no 'name'"),
    ("bone without direction", _swap("    direction 1 0 0\n", ""), 29, "bone 'lower' has no 'direction'"),
    ("bone without length", _swap("    length 3\n", ""), 29, "bone 'lower' has no 'length'"),
    ("bone direction too big", _swap("length 3", "length 1e9").replace("direction 1 0 0", "direction 2 0 0"), 23, "bone 'lower': direction times length reaches 2e+09"),
    ("hierarchy without begin", _swap("  begin\n    root upper", "    root upper"), 32, "expected 'begin' to open the hierarchy, got 'root upper'"),
    ("line after hierarchy end", TINY_ASF + "  root lower\n", 36, "unexpected line after the hierarchy's 'end': 'root lower'"),
    ("root as a child", _swap("upper lower", "upper lower root"), 34, "the root cannot be a child in the hierarchy"),
    ("no root section", TINY_ASF.replace(":root", ":documentation").replace("  order TX TY TZ RX RY RZ\n  axis XYZ\n  position 1 2 3\n  orientation 0 0 90\n", ""), 31, "missing :root section"),
    ("no hierarchy section", TINY_ASF[: TINY_ASF.index(":hierarchy")] + "\n\n", 30, "missing :hierarchy section"),
    ("bone unclosed at end", TINY_ASF[: TINY_ASF.index("  end\n:hierarchy")] + "\n  \n", 29, "bone block opened at line 23 has no 'end' (file ends)"),
    ("unknown section", _swap(":units", ":unit"), 3, "unknown section ':unit'; expected one of :version"),
]


@pytest.mark.parametrize("text, line, fragment", [c[1:] for c in ASF_CASES], ids=[c[0] for c in ASF_CASES])
def test_asf_errors_name_line_and_problem(tmp_path, text, line, fragment):
    p = put(tmp_path, "bad.asf", text)
    with pytest.raises(ParseError) as info:
        read_asf(p)
    err = info.value
    assert err.path == str(p)
    assert err.line == line, str(err)
    assert fragment in err.message, str(err)


def test_asf_empty_and_whitespace(tmp_path):
    for text in ("", " \n\n\t"):
        with pytest.raises(ParseError, match="file is empty; expected an ASF skeleton") as info:
            read_asf(put(tmp_path, "e.asf", text))
        assert info.value.line == 1


# --------------------------------------------------------------------- AMC reading
def test_tiny_amc_known_values(tmp_path):
    put(tmp_path, "tiny.asf", TINY_ASF)
    m = read_amc(put(tmp_path, "tiny.amc", TINY_AMC))
    assert m.channels == TINY_CHANNELS
    np.testing.assert_array_equal(m.frames, [[1, 2, 3, 10, 20, 30, 40, 50, 60], [-1, -2, -3, -10, -20, -30, -40, -50, -60]])
    assert m.fps == 120.0 and m.start_frame == 0
    assert m.metadata == {"amc_header": ["# a comment", ":FULLY-SPECIFIED", ":DEGREES"], "first_frame_number": 1}
    assert m.skeleton.names == ["root", "upper", "lower"]
    m2 = read_amc(tmp_path / "tiny.amc", fps=30)
    assert m2.fps == 30.0


def test_amc_rows_allocated_are_the_frame_lines_counted(tmp_path):
    put(tmp_path, "tiny.asf", TINY_ASF)
    p = put(tmp_path, "tiny.amc", TINY_AMC + "# 3\n 4 x\n")  # neither line is a frame number
    with memory_limit(1), pytest.raises(ParseError) as info:
        read_amc(p)
    assert "2 frames of 9 channels need 144 bytes" in info.value.message
    assert info.value.path == str(p)


def test_amc_radians_scale_rotations_only(tmp_path):
    put(tmp_path, "tiny.asf", TINY_ASF)
    text = TINY_AMC.replace(":DEGREES", ":RADIANS").replace("root 1 2 3 10 20 30", f"root 1 2 3 {math.pi!r} 0 {-math.pi / 2!r}")
    m = read_amc(put(tmp_path, "tiny.amc", text))
    np.testing.assert_allclose(m.frames[0, :6], [1, 2, 3, 180, 0, -90], atol=1e-12)
    np.testing.assert_allclose(m.frames[0, 6:], np.degrees([40, 50, 60]), rtol=1e-15)
    # no unit in the AMC: the ASF's radians decide; a :DEGREES line overrides them
    put(tmp_path, "tiny.asf", TINY_ASF.replace("angle deg", "angle rad"))
    plain = TINY_AMC.replace(":DEGREES\n", "")
    m = read_amc(put(tmp_path, "tiny.amc", plain))
    np.testing.assert_allclose(m.frames[0], [1, 2, 3] + list(np.degrees([10, 20, 30, 40, 50, 60])))
    m = read_amc(put(tmp_path, "tiny.amc", TINY_AMC))
    np.testing.assert_array_equal(m.frames[0], [1, 2, 3, 10, 20, 30, 40, 50, 60])
    # a repeated, agreeing unit line is fine
    m = read_amc(put(tmp_path, "tiny.amc", TINY_AMC.replace(":DEGREES", ":degrees\n:DEGREES")))
    assert m.frames[0, 3] == 10


def test_amc_radian_magnitude_is_checked_in_degrees(tmp_path):
    put(tmp_path, "tiny.asf", TINY_ASF)
    text = TINY_AMC.replace(":DEGREES", ":RADIANS").replace("lower -60", "lower 2e7")
    with pytest.raises(ParseError) as info:
        read_amc(put(tmp_path, "tiny.amc", text))
    err = info.value
    assert (err.line, err.frame) == (11, 2)
    assert "value '2e7' for bone 'lower' is beyond the largest supported magnitude 1e+09 degrees" in err.message
    # 2e7 degrees is fine, and 1e9 exactly too
    m = read_amc(put(tmp_path, "tiny.amc", TINY_AMC.replace("lower -60", "lower 2e7").replace("upper 40 50", "upper 1e9 -1e9")))
    assert m.frames[1, 8] == 2e7 and m.frames[0, 7] == -1e9
    with pytest.raises(ParseError) as info:
        read_amc(put(tmp_path, "tiny.amc", TINY_AMC.replace("upper -40 -50", "upper -40 -1.01e9")))
    assert (info.value.line, info.value.frame) == (10, 2)
    assert "value '-1.01e9' for bone 'upper' is beyond" in info.value.message
    assert "degrees" not in info.value.message


def test_amc_frames_across_chunks(tmp_path):
    put(tmp_path, "tiny.asf", TINY_ASF)
    out = [":DEGREES"]
    for t in range(300):
        out += [str(t + 1), f"root {t} 0 0 0 0 0", f"upper {t} 0", f"lower {-t}"]
    text = "\n".join(out) + "\n"
    m = read_amc(put(tmp_path, "tiny.amc", text))
    assert m.n_frames == 300
    np.testing.assert_array_equal(m.frames[:, 0], np.arange(300))
    np.testing.assert_array_equal(m.frames[:, 8], -np.arange(300))
    # a bad value in the second chunk: its line and frame number
    bad = text.replace("upper 280 0", "upper 280 zz")
    with pytest.raises(ParseError) as info:
        read_amc(put(tmp_path, "tiny.amc", bad))
    assert (info.value.line, info.value.frame) == (2 + 280 * 4 + 2, 281)
    assert "expected a number for bone 'upper', got 'zz'" in info.value.message
    # a too-big value in the first chunk and a non-number in the second: the non-number wins
    both = bad.replace("lower -3\n", "lower -3e10\n")
    with pytest.raises(ParseError) as info:
        read_amc(put(tmp_path, "tiny.amc", both))
    assert info.value.frame == 281 and "got 'zz'" in info.value.message
    big = text.replace("lower -3\n", "lower -3e10\n").replace("lower -290\n", "lower -4e10\n")
    with pytest.raises(ParseError) as info:
        read_amc(put(tmp_path, "tiny.amc", big))
    assert (info.value.line, info.value.frame) == (2 + 3 * 4 + 3, 4)


def test_amc_frame_numbers_and_zero_dof_bones(tmp_path):
    asf = TINY_ASF.replace("    dof rx\n", "")  # 'lower' has no dofs
    put(tmp_path, "tiny.asf", asf)
    text = ":DEGREES\n-1\nroot 1 2 3 4 5 6\nupper 7 8\nlower\n+0\nupper 9 10\nroot 1 1 1 1 1 1\n"
    m = read_amc(put(tmp_path, "tiny.amc", text))
    assert m.metadata["first_frame_number"] == -1
    assert m.channels == TINY_CHANNELS[:8]
    np.testing.assert_array_equal(m.frames, [[1, 2, 3, 4, 5, 6, 7, 8], [1, 1, 1, 1, 1, 1, 9, 10]])


def test_amc_joint_names_are_accepted_beside_asf_names(tmp_path):
    sk = Skeleton(joints=(
        Joint("Hips", -1, [0, 0, 0], ("tx", "ty", "tz", "rz", "rx", "ry"), "ZXY"),
        Joint("Left Leg", 0, [0, -1, 0], ("rx",), "X", end_site=[0, -1, 0]),
    ))
    p = put(tmp_path, "a.amc", "1\nHips 1 2 3 4 5 6\nLeft_Leg 7\n2\nHips 1 2 3 4 5 6\nLeft_Leg 8\n")
    m = read_amc(p, skeleton=sk)
    # ASF listing of a ZXY joint: ry rx rz after the translations
    assert m.channels == (("Hips", "tx"), ("Hips", "ty"), ("Hips", "tz"), ("Hips", "ry"),
                          ("Hips", "rx"), ("Hips", "rz"), ("Left Leg", "rx"))
    np.testing.assert_array_equal(m.frames[:, 6], [7, 8])
    both = put(tmp_path, "b.amc", "1\nroot 1 2 3 4 5 6\nHips 1 2 3 4 5 6\nLeft_Leg 7\n")
    with pytest.raises(ParseError, match="bones 'root' and 'Hips' name the same joint") as info:
        read_amc(both, skeleton=sk)
    assert (info.value.line, info.value.frame) == (3, 1)
    # an unsafe joint name is not an AMC bone name
    with pytest.raises(ParseError, match="bone 'Left' is not in the skeleton") as info:
        read_amc(put(tmp_path, "c.amc", "1\nroot 1 2 3 4 5 6\nLeft Leg 7\n"), skeleton=sk)
    assert "(" not in info.value.message  # a Skeleton object: no skeleton file is named


def test_amc_errors_name_line_frame_and_skeleton(tmp_path):
    asf = put(tmp_path, "tiny.asf", TINY_ASF)

    def err(text, **kw):
        p = put(tmp_path, "tiny.amc", text)
        with pytest.raises(ParseError) as info:
            read_amc(p, **kw)
        assert info.value.path == str(p)
        return info.value

    e = err(TINY_AMC.replace("lower -60", "lower 1 2"))
    assert (e.line, e.frame) == (11, 2)
    assert e.message == f"bone 'lower' has 1 dof (rx), got 2 values (dofs per the skeleton {asf})"
    e = err(TINY_AMC.replace("upper 40 50", "upper"))
    assert e.message == f"bone 'upper' has 2 dofs (rx rz), got 0 values (dofs per the skeleton {asf})"
    e = err(TINY_AMC.replace("lower -60", "leg 1"))
    assert e.message == f"bone 'leg' is not in the skeleton 'tiny' ({asf})" and (e.line, e.frame) == (11, 2)
    e = err(TINY_AMC.replace("lower -60", "17 1"))
    assert "expected a frame number alone on its line, got '17 1'" in e.message
    e = err(TINY_AMC.replace("\n2\n", "\n2\nlower 5\n"))
    assert e.message == "bone 'lower' appears twice in frame 2" and (e.line, e.frame) == (12, 2)
    e = err(TINY_AMC.replace("lower 60\n", ""))
    assert "bone 'lower' does not appear in the first frame" in e.message and e.line == 10
    e = err(TINY_AMC.replace("upper -40 -50\nlower -60\n", ""))
    assert e.message == ("frame 2 (starting at line 8) is missing bone 'upper', 'lower'; expected "
                         "the 3 bones of the first frame")
    assert (e.line, e.frame) == (8, 2)
    e = err(":DEGREES\n1\n2\nroot 1 2 3 4 5 6\n")
    assert e.message == "frame 1 has no bone values; expected lines '<bone> <values>'" and e.line == 2
    e = err(":DEGREES\n# only a comment\n")
    assert e.line == 1 and "no frames" in e.message  # the last line that is no comment
    e = err(":DEGREES\n\n:FULLY-SPECIFIED\n\n")
    assert e.line == 3 and e.message == "no frames: expected a frame number after the header"
    e = err(TINY_AMC.replace("\n2\n", "\n999999999999\n"))
    assert "a frame number" in e.message and e.line == 8
    e = err(TINY_AMC.replace(":DEGREES", ":RADIANS\n:DEGREES"))
    assert e.line == 4 and ":DEGREES contradicts the angle unit given at line 3" in e.message
    for bad in (0, -1, math.nan, math.inf):
        with pytest.raises(ParameterError, match="fps must be a positive number"):
            read_amc(tmp_path / "tiny.amc", fps=bad)


def test_amc_bone_lines_with_comments(tmp_path):
    put(tmp_path, "tiny.asf", TINY_ASF)
    text = TINY_AMC.replace("upper 40 50", "upper 40 50 # note").replace("\n2\n", "\n2 # frame two\n")
    m = read_amc(put(tmp_path, "tiny.amc", text))
    np.testing.assert_array_equal(m.frames[:, 7], [50, -50])
    # a '#' line after the frames began is not a header line
    m = read_amc(put(tmp_path, "tiny.amc", TINY_AMC + "# trailing\n"))
    assert m.metadata["amc_header"] == ["# a comment", ":FULLY-SPECIFIED", ":DEGREES"]


def test_missing_bones_beyond_five_are_counted(tmp_path):
    names = [f"b{k}" for k in range(7)]
    joints = [Joint("r", -1, [0, 0, 0], ("rx",), "X")] + [
        Joint(n, 0, [0, 0, 0], ("rx",), "X", end_site=[0, 1, 0]) for n in names
    ]
    sk = Skeleton(joints=tuple(joints))
    first = "1\nroot 0\n" + "".join(f"{n} 1\n" for n in names)
    p = put(tmp_path, "m.amc", first + "2\nroot 0\n")
    with pytest.raises(ParseError) as info:
        read_amc(p, skeleton=sk)
    assert "missing bone 'b0', 'b1', 'b2', 'b3', 'b4' and 2 more; expected the 8 bones" in info.value.message
    p = put(tmp_path, "m.amc", first + "2\nroot 0\n" + "".join(f"{n} 1\n" for n in names[:2]))
    with pytest.raises(ParseError) as info:
        read_amc(p, skeleton=sk)
    assert "missing bone 'b2', 'b3', 'b4', 'b5', 'b6'; expected" in info.value.message


# --------------------------------------------------------------------- finding the ASF
def test_header_skeleton_line(tmp_path):
    put(tmp_path, "named.asf", TINY_ASF)
    put(tmp_path, "other.asf", TINY_ASF)
    amc = put(tmp_path, "x_1.amc", "# c\n#!OML:ASF named.asf\n:DEGREES\n1\n")
    assert _header_skeleton(amc) == tmp_path / "named.asf"
    assert find_skeleton(amc) == tmp_path / "named.asf"
    for head in ("#!OML:ASF sub/named.asf", "#!OML:ASF named.txt", "#!OML:ASF missing.asf", "#!OML:ASF"):
        amc = put(tmp_path, "x_1.amc", head + "\n1\n")
        assert _header_skeleton(amc) is None, head
    # after the first frame began the header is not read
    amc = put(tmp_path, "x_1.amc", ":DEGREES\n1\n#!OML:ASF named.asf\n")
    assert _header_skeleton(amc) is None
    assert _header_skeleton(tmp_path / "none.amc") is None
    amc = put(tmp_path, "x_1.amc", "\n  #!OML:ASF NAMED.ASF  \n")
    assert _header_skeleton(amc) is None  # a case-different name: no such file here... or the file
    (tmp_path / "NAMED.ASF").write_text(TINY_ASF)
    assert _header_skeleton(amc) == tmp_path / "NAMED.ASF"


def test_find_skeleton_rules(tmp_path):
    only = tmp_path / "only"
    only.mkdir()
    put(only, "whatever.asf", TINY_ASF)
    (only / "dir.asf").mkdir()  # a folder named .asf is not a skeleton
    assert find_skeleton(only / "a_01.amc") == only / "whatever.asf"
    two = tmp_path / "two"
    two.mkdir()
    put(two, "walk.asf", TINY_ASF)
    put(two, "run.ASF", TINY_ASF)
    assert find_skeleton(two / "walk.amc") == two / "walk.asf"  # <stem>.asf
    assert find_skeleton(two / "RUN_07.amc") == two / "run.ASF"  # <subject>.asf, any case
    with pytest.raises(ParseError) as info:
        find_skeleton(two / "jog_01.amc")
    assert info.value.message.startswith(
        "no skeleton found: looked for 'jog.asf' (from the <subject>_<trial>.amc name) or a "
        f"folder holding exactly one .asf, but {two} holds 2 .asf file(s) (run.ASF, walk.asf); "
    )
    with pytest.raises(ParseError) as info:
        find_skeleton(two / "jog.amc")
    assert info.value.message.startswith("no skeleton found: looked for a folder holding")
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(ParseError) as info:
        find_skeleton(empty / "a_1.amc")
    assert "holds 0 .asf file(s); give the skeleton" in info.value.message


def test_read_amc_file_problems(tmp_path):
    put(tmp_path, "tiny.asf", TINY_ASF)
    with pytest.raises(ParseError, match="is a folder") as info:
        read_amc(tmp_path)
    for text in ("", "\n\n  \n"):
        with pytest.raises(ParseError, match="file is empty; expected an AMC header and frames") as info:
            read_amc(put(tmp_path, "e.amc", text))
        assert info.value.line == 1


# --------------------------------------------------------------------- writing
def test_write_asf_text_of_the_tiny_skeleton(tmp_path):
    sk, _ = parse_asf(TINY_ASF, "t.asf")
    write_asf(sk, tmp_path / "w.asf")
    text = (tmp_path / "w.asf").read_text()
    assert text.split("\n") == [
        "# ASF written by cyclecoord",
        ":version 1.10",
        ":name tiny",
        ":units",
        "  mass 1.0",
        "  length 0.45",
        "  angle deg",
        ":documentation",
        "  Directions are global unit vectors, angles in degrees.",
        "  Source skeleton format: asf.",
        ":root",
        "  order TX TY TZ RX RY RZ",
        "  axis XYZ",
        "  position 1.0 2.0 3.0",
        "  orientation 0 0 90.0",
        ":bonedata",
        "  begin",
        "    id 1",
        "    name upper",
        "    direction 0 -1.0 0",
        "    length 2.0",
        "    axis 0 0 0 XYZ",
        "    dof rx rz",
        "    limits (-90.0 90.0)",
        "           (-inf inf)",
        "  end",
        "  begin",
        "    id 2",
        "    name lower",
        "    direction 1.0 0 0",
        "    length 3.0",
        "    axis 90.0 0 0 XYZ",
        "    dof rx",
        "  end",
        ":hierarchy",
        "  begin",
        "    root upper",
        "    upper lower",
        "  end",
        "",
    ]
    back = read_asf(tmp_path / "w.asf")
    assert back.names == sk.names and back.joints[1].limits == sk.joints[1].limits


def test_write_asf_zero_length_bone_and_rootless_dofs(tmp_path):
    sk = Skeleton(joints=(
        Joint("r", -1, [0, 0, 0], (), ""),
        Joint("a", 0, [0, 0, 0], (), "", end_site=[0, 0, 0]),
    ), name="  my # skel  ")
    write_asf(sk, tmp_path / "z.asf")
    lines = (tmp_path / "z.asf").read_text().split("\n")
    assert ":name my _ skel" in lines
    assert "  order" not in "\n".join(lines)  # no dofs: no order line
    assert "    direction 0 0 1.0" in lines and "    length 0" in lines
    assert not any(ln.strip().startswith("dof") for ln in lines)
    back = read_asf(tmp_path / "z.asf")
    np.testing.assert_array_equal(back.joints[1].end_site, [0, 0, 0])


def test_write_asf_refusals(tmp_path):
    sk, _ = parse_asf(TINY_ASF, "t.asf")
    with pytest.raises(ParameterError, match="expected a Skeleton, got int"):
        write_asf(42, tmp_path / "x.asf")
    far = Skeleton(joints=(
        Joint("r", -1, [0, 0, 0], (), ""),
        Joint("a", 0, [0, 0, 0], ("rx",), "X", end_site=[8e8, 8e8, 0]),
    ))
    with pytest.raises(ParameterError, match=r"bone 'a' would be 1.13137e\+09 long") as info:
        write_asf(far, tmp_path / "x.asf")
    assert str(info.value).startswith(str(tmp_path / "x.asf"))
    near = Skeleton(joints=(
        Joint("r", -1, [0, 0, 0], (), ""),
        Joint("a", 0, [0, 0, 0], ("rx",), "X", end_site=[6e8, 8e8, 0]),  # exactly 1e9 long
    ))
    write_asf(near, tmp_path / "n.asf")
    assert "    length 1000000000.0" in (tmp_path / "n.asf").read_text().split("\n")
    assert not (tmp_path / "x.asf").exists()


def test_write_amc_text_and_rate(tmp_path):
    sk, _ = parse_asf(TINY_ASF, "t.asf")
    vals = np.array([[1, 2, 3, 10, 20, 30, 40, 50, 60.5], [0, -0.0, 0.1, 0, 0, 0, 0, 0, 1e-300]])
    m = Motion(vals, TINY_CHANNELS, fps=120.0, skeleton=sk)
    write_amc(m, tmp_path / "w.amc")
    assert (tmp_path / "w.amc").read_text() == (
        ":FULLY-SPECIFIED\n:DEGREES\n1\nroot 1.0 2.0 3.0 10.0 20.0 30.0\nupper 40.0 50.0\n"
        "lower 60.5\n2\nroot 0 0 0.1 0 0 0\nupper 0 0\nlower 1e-300\n"
    )
    m = Motion(vals, TINY_CHANNELS, fps=120.0 + 2e-9, skeleton=sk)
    write_amc(m, tmp_path / "r.amc", skeleton_path=tmp_path / "s.asf")
    lines = (tmp_path / "r.amc").read_text().split("\n")
    assert lines[0] == "#!OML:ASF s.asf"
    assert lines[1] == f"# frame rate {120.0 + 2e-9!r} fps (cyclecoord)"
    assert lines[2:4] == [":FULLY-SPECIFIED", ":DEGREES"]
    assert read_asf(tmp_path / "s.asf").names == ["root", "upper", "lower"]
    back = read_amc(tmp_path / "r.amc")  # the header names the ASF written beside it
    np.testing.assert_array_equal(back.frames, vals)
    m = Motion(vals, TINY_CHANNELS, fps=120.0 + 5e-10, skeleton=sk)
    write_amc(m, tmp_path / "q.amc")
    assert (tmp_path / "q.amc").read_text().startswith(":FULLY-SPECIFIED\n")


def test_write_amc_without_a_skeleton_groups_channels(tmp_path):
    m = Motion(np.array([[1.0, 2.0, 3.0]]), [("b", "rx"), ("a", "ty"), ("b", "rz")], fps=120.0)
    write_amc(m, tmp_path / "n.amc")
    assert (tmp_path / "n.amc").read_text() == ":FULLY-SPECIFIED\n:DEGREES\n1\nb 1.0 3.0\na 2.0\n"
    for bad in ("a b", "a#b", ":a", "x\ty"):
        with pytest.raises(ParameterError, match="cannot be written to an AMC without a skeleton"):
            write_amc(Motion(np.zeros((1, 1)), [(bad, "rx")]), tmp_path / "x.amc")
    with pytest.raises(ParameterError, match="expected a Motion, got list"):
        write_amc([1], tmp_path / "x.amc")
    with pytest.raises(ParameterError, match=r"frame 2, channel b.rz: non-finite value inf"):
        write_amc(Motion(np.array([[1.0, 2.0, 3.0], [0, 0, np.inf]]), m.channels), tmp_path / "x.amc")
    assert not (tmp_path / "x.amc").exists()


def _asf_bones(n: int, chain: bool) -> str:
    """n bones (lines 3 + 6k .. 8 + 6k for bone k), hung from the root or as a chain."""
    out = [":root", ":bonedata"]
    for k in range(1, n + 1):
        out += ["begin", f"name b{k}", "direction 0 1 0", "length 1", "dof rx", "end"]
    out += [":hierarchy", "begin"]
    if chain:
        out += ["root b1"] + [f"b{k} b{k + 1}" for k in range(1, n)]
    else:
        out += ["root " + " ".join(f"b{k}" for k in range(1, n + 1))]
    out += ["end"]
    return "\n".join(out) + "\n"


def test_asf_bone_and_depth_caps_at_their_boundary(tmp_path):
    from cyclecoord.io._limits import MAX_DEPTH, MAX_JOINTS

    # MAX_JOINTS joints: the root and MAX_JOINTS - 1 bones
    sk, _ = parse_asf(_asf_bones(MAX_JOINTS - 1, chain=False), "b.asf")
    assert len(sk.joints) == MAX_JOINTS
    with pytest.raises(ParseError) as info:
        parse_asf(_asf_bones(MAX_JOINTS, chain=False), "b.asf")
    assert info.value.line == 2 + 6 * MAX_JOINTS  # the 'end' of the bone one too many
    assert f"more than {MAX_JOINTS - 1:,} bones" in info.value.message
    # a chain whose last bone hangs MAX_DEPTH levels below the root
    sk, _ = parse_asf(_asf_bones(MAX_DEPTH, chain=True), "c.asf")
    assert len(sk.joints) == MAX_DEPTH + 1
    text = _asf_bones(MAX_DEPTH + 1, chain=True)
    with pytest.raises(ParseError) as info:
        parse_asf(text, "c.asf")
    hier = 2 + 6 * (MAX_DEPTH + 1) + 3  # the 'root b1' line
    assert info.value.line == hier + MAX_DEPTH  # the line that hangs the last bone
    assert f"bone 'b{MAX_DEPTH + 1}' hangs {MAX_DEPTH + 1} levels below the root" in info.value.message


def test_asf_layout_tolerance_of_a_small_skeleton_is_absolute_1e_12():
    def two_kids(d):
        return Skeleton(joints=(
            Joint("r", -1, [0, 0, 0], (), ""),
            Joint("a", 0, [0, 0, 0], ("rx",), "X"),
            Joint("b", 1, [0, 0.5, 0], (), "", end_site=[0, 0.25, 0]),
            Joint("c", 1, [0, 0.5 + d, 0], (), "", end_site=[0, 0.25, 0]),
        ))
    # every length below 1: the tolerance is 1e-12 (the size never drops below 1)
    assert [b.asf_name for b in asf_layout(two_kids(0.6e-12))] == ["root", "a", "b", "c"]
    assert [b.asf_name for b in asf_layout(two_kids(1.5e-12))] == [
        "root", "a", "a_to_b", "b", "a_to_c", "c"
    ]


def test_amc_asf_names_win_over_joint_names(tmp_path):
    # joint 'a b' is ASF bone 'a_b'; joint 'a_b' is ASF bone 'a_b_2': the AMC name 'a_b'
    # is the ASF bone (joint 'a b'), not joint 'a_b'
    sk = Skeleton(joints=(
        Joint("r", -1, [0, 0, 0], ("rx",), "X"),
        Joint("a b", 0, [0, 1, 0], ("rx",), "X", end_site=[0, 1, 0]),
        Joint("a_b", 0, [0, 1, 0], ("ry",), "Y", end_site=[0, 1, 0]),
    ))
    m = read_amc(put(tmp_path, "n.amc", "1\nroot 1\na_b 2\na_b_2 3\n"), skeleton=sk)
    assert m.channels == (("r", "rx"), ("a b", "rx"), ("a_b", "ry"))
    np.testing.assert_array_equal(m.frames, [[1, 2, 3]])


def test_more_asf_edges():
    with pytest.raises(ParseError, match=r"expected limits as '\(low high\)', got '\( \( \) \)'"):
        parse_asf(_swap("(-inf inf)", "( ( ) )"), "x")
    # direction * length of exactly 1e9 is within the cap
    sk, _ = parse_asf(_swap("length 3", "length 1e9"), "x")
    np.testing.assert_array_equal(sk.joints[2].end_site, [1e9, 0, 0])
    # ':name' alone: an empty name
    sk, _ = parse_asf(_swap(":name tiny", ":name"), "x")
    assert sk.name == ""


def test_header_skeleton_after_unit_lines(tmp_path):
    put(tmp_path, "named.asf", TINY_ASF)
    amc = put(tmp_path, "x.amc", ":FULLY-SPECIFIED\n:DEGREES\n\n#!OML:ASF named.asf\n1\n")
    assert _header_skeleton(amc) == tmp_path / "named.asf"


def test_amc_frame_lines_are_counted_with_signs_and_blanks(tmp_path):
    put(tmp_path, "tiny.asf", TINY_ASF)
    text = TINY_AMC.replace("\n1\n", "\n +1 \t\n").replace("\n2\n", "\n2\r\n")
    m = read_amc(put(tmp_path, "tiny.amc", text))
    assert m.n_frames == 2 and m.metadata["first_frame_number"] == 1
    with memory_limit(1), pytest.raises(ParseError, match="2 frames of 9 channels"):
        read_amc(tmp_path / "tiny.amc")


def test_write_asf_unnamed_skeleton_of_no_format(tmp_path):
    sk = Skeleton(joints=(Joint("r", -1, [0, 0, 0], ("rx",), "X"),))
    write_asf(sk, tmp_path / "u.asf")
    lines = (tmp_path / "u.asf").read_text().split("\n")
    assert ":name cyclecoord" in lines
    assert "  Source skeleton format: unknown." in lines
    assert lines[lines.index(":hierarchy") + 1 : lines.index(":hierarchy") + 3] == ["  begin", "  end"]
    assert read_asf(tmp_path / "u.asf").names == ["root"]


def test_amc_frame_numbers_at_their_bounds(tmp_path):
    put(tmp_path, "tiny.asf", TINY_ASF)
    one = "1\nroot 1 2 3 4 5 6\nupper 7 8\nlower 9\n"
    for first in ("1000000000", "-1000000000"):
        m = read_amc(put(tmp_path, "tiny.amc", one.replace("1\n", first + "\n", 1)))
        assert m.metadata["first_frame_number"] == int(first)
    for first in ("1000000001", "-1000000001"):
        with pytest.raises(ParseError, match="a frame number must lie in -1,000,000,000..1,000,000,000") as info:
            read_amc(put(tmp_path, "tiny.amc", one.replace("1\n", first + "\n", 1)))
        assert info.value.line == 1


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda j: j.offset.__setitem__(0, np.nan), "joint 'a': offset component nan"),
        (lambda j: j.end_site.__setitem__(1, -np.inf), "joint 'a': end site component -inf"),
        (lambda j: j.axis.__setitem__((2, 2), -1.0), "joint 'a': axis is not a rotation matrix"),
    ],
)
def test_write_asf_refuses_geometry_changed_in_place(tmp_path, change, message):
    sk = Skeleton(joints=(
        Joint("r", -1, [0, 0, 0], ("rx",), "X"),
        Joint("a", 0, [0, 1, 0], ("rx",), "X", end_site=[0, 1, 0]),
    ))
    change(sk.joints[1])
    with pytest.raises(ParameterError, match=f"cannot write ASF: skeleton: {message}"):
        write_asf(sk, tmp_path / "x.asf")
    assert not (tmp_path / "x.asf").exists()


@pytest.mark.parametrize("unit", [0.0, -1.0, math.nan, math.inf, 2e9])
def test_write_asf_refuses_a_bad_length_unit(tmp_path, unit):
    sk = Skeleton(joints=(Joint("r", -1, [0, 0, 0], ("rx",), "X"),), length_unit=unit)
    with pytest.raises(ParameterError, match=f"length unit {unit!r} is not a positive number"):
        write_asf(sk, tmp_path / "x.asf")


def test_amc_uncounted_frames_grow_the_array_a_chunk_at_a_time(tmp_path):
    """CR-only line ends (old Mac files) read as lines, but the byte count of frame lines
    finds none: the array starts at 1 frame and grows as each chunk of 256 frames is
    converted, to 256 and then max(300, 1.25 * 256) = 320 frames: 300 frames of 9 channels
    need 320 * 9 * 8 = 23,040 bytes and no more."""
    put(tmp_path, "tiny.asf", TINY_ASF)
    out = [":DEGREES"]
    for t in range(300):
        out += [str(t + 1), f"root {t} 0 0 0 0 0", "upper 0 0", f"lower {t}"]
    p = tmp_path / "tiny.amc"
    p.write_bytes("\r".join(out).encode() + b"\r")
    with memory_limit(23_040):
        m = read_amc(p)
    assert m.n_frames == 300 and m.frames[299, 0] == 299 and m.frames[299, 8] == 299
    with memory_limit(23_039), pytest.raises(ParseError, match="320 frames of 9 channels need"):
        read_amc(p)
