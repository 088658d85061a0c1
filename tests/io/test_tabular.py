"""Tests for NPZ and CSV motion files (cyclecoord.io.tabular)."""

from __future__ import annotations

import numpy as np
import pytest

from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io import read_csv, read_npz, write_bvh, write_csv, write_npz
from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton


def skeleton_with_everything() -> Skeleton:
    c = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    joints = (
        Joint("root", -1, [0.1, 0.2, 0.3], ("tx", "ty", "tz", "rx", "ry", "rz"), "ZYX"),
        Joint("left femur", 0, [1, -1, 0.5], ("rx", "rz"), "ZX", c,
              limits={"rx": (-160.0, 20.0), "rz": (-60.0, np.inf)}),
        Joint("ltibia", 1, [0, -7, 0], ("rx",), "X", end_site=[0, -7.25, 1e-17],
              limits={"rx": (-10.0, 170.0)}),
        Joint("neck", 0, [0, 5, 0], (), ""),
    )
    return Skeleton(joints, name="subject 7", length_unit=0.45, source_format="asf")


def sample_motion(seed: int = 0, T: int = 25, skeleton: bool = True) -> Motion:
    sk = skeleton_with_everything()
    rng = np.random.default_rng(seed)
    frames = rng.normal(scale=100.0, size=(T, len(sk.channels)))
    frames[0, 0] = 1e-300
    frames[1, 1] = -0.0
    frames[2, 2] = 123456789.123456789
    return Motion(
        frames=frames,
        channels=sk.channels,
        fps=119.88,
        skeleton=sk if skeleton else None,
        source="synthetic:tabular",
        start_frame=42,
        metadata={"amc_header": [":FULLY-SPECIFIED", ":DEGREES"], "first_frame_number": 1},
    )


# --------------------------------------------------------------------------- NPZ
def test_npz_round_trip_is_bitwise(tmp_path):
    m = sample_motion()
    write_npz(m, tmp_path / "m.npz")
    b = read_npz(tmp_path / "m.npz")
    assert b.frames.dtype == np.float64
    assert b.frames.tobytes() == m.frames.tobytes()
    assert b.channels == m.channels
    assert (b.fps, b.start_frame, b.source) == (m.fps, m.start_frame, m.source)
    assert b.metadata == m.metadata
    sa, sb = m.skeleton, b.skeleton
    assert (sb.name, sb.length_unit, sb.source_format) == (sa.name, sa.length_unit, sa.source_format)
    for ja, jb in zip(sa.joints, sb.joints, strict=True):
        assert (jb.name, jb.parent, jb.dofs, jb.rotation_order) == (ja.name, ja.parent, ja.dofs, ja.rotation_order)
        assert jb.offset.tobytes() == ja.offset.tobytes()
        assert jb.axis.tobytes() == ja.axis.tobytes()
        assert (jb.end_site is None) == (ja.end_site is None)
        if ja.end_site is not None:
            assert jb.end_site.tobytes() == ja.end_site.tobytes()
        assert jb.limits == ja.limits
    np.testing.assert_array_equal(b.positions().positions, m.positions().positions)


def test_npz_loads_without_pickle(tmp_path):
    m = sample_motion()
    write_npz(m, tmp_path / "m.npz")
    with np.load(tmp_path / "m.npz", allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    assert all(a.dtype != object for a in arrays.values())
    assert arrays["frames"].shape == (25, len(m.channels))
    assert list(arrays["joint_names"]) == ["root", "left femur", "ltibia", "neck"]
    assert list(arrays["joint_dofs"]) == ["tx ty tz rx ry rz", "rx rz", "rx", ""]
    assert list(arrays["joint_has_end_site"]) == [False, False, True, False]


def test_npz_without_skeleton_or_source(tmp_path):
    m = Motion(np.arange(6.0).reshape(3, 2), [("a", "x"), ("b", "")], fps=30)
    write_npz(m, tmp_path / "plain.npz")
    b = read_npz(tmp_path / "plain.npz")
    assert b.skeleton is None and b.source is None and b.fps == 30.0
    assert b.channels == (("a", "x"), ("b", ""))
    np.testing.assert_array_equal(b.frames, m.frames)
    # the loader's options: override the rate, attach a skeleton (object or file)
    sk_motion = sample_motion(T=3)
    write_bvh(sk_motion, tmp_path / "sk.bvh")
    assert read_npz(tmp_path / "plain.npz", fps=10).fps == 10.0
    assert read_npz(tmp_path / "plain.npz", skeleton=sk_motion.skeleton).skeleton is sk_motion.skeleton
    from_file = read_npz(tmp_path / "plain.npz", skeleton=tmp_path / "sk.bvh").skeleton
    assert from_file.source_format == "bvh" and from_file.names[0] == "root"
    with pytest.raises(ParameterError):
        read_npz(tmp_path / "plain.npz", fps=-1)


def test_npz_errors(tmp_path):
    with pytest.raises(ParseError, match="no such file"):
        read_npz(tmp_path / "missing.npz")
    (tmp_path / "junk.npz").write_bytes(b"this is not a zip archive at all")
    with pytest.raises(ParseError, match="not an .npz archive"):
        read_npz(tmp_path / "junk.npz")
    (tmp_path / "empty.npz").write_bytes(b"")
    with pytest.raises(ParseError):
        read_npz(tmp_path / "empty.npz")
    np.save(tmp_path / "single.npy", np.zeros(3))
    with pytest.raises(ParseError, match="single .npy array"):
        read_npz(tmp_path / "single.npy")
    np.savez(tmp_path / "partial.npz", frames=np.zeros((2, 1)), fps=np.array(120.0))
    with pytest.raises(ParseError, match="missing array 'channel_joints'") as e:
        read_npz(tmp_path / "partial.npz")
    assert e.value.path == str(tmp_path / "partial.npz")
    np.savez(tmp_path / "shape.npz", frames=np.zeros((2, 3)), channel_joints=np.array(["a"]),
             channel_dofs=np.array(["x"]), fps=np.array(120.0), start_frame=np.array(0))
    with pytest.raises(ParseError, match="3 columns of 'frames'"):
        read_npz(tmp_path / "shape.npz")
    np.savez(tmp_path / "obj.npz", frames=np.array([None, 1], dtype=object))
    with pytest.raises(ParseError, match="pickl"):
        read_npz(tmp_path / "obj.npz")
    # a skeleton flagged but incomplete
    write_npz(sample_motion(T=3), tmp_path / "full.npz")
    with np.load(tmp_path / "full.npz") as z:
        arrays = {k: z[k] for k in z.files if k != "joint_axes"}
    np.savez(tmp_path / "noaxes.npz", **arrays)
    with pytest.raises(ParseError, match="'joint_axes' is missing"):
        read_npz(tmp_path / "noaxes.npz")
    arrays["joint_axes"] = np.zeros((2, 3, 3))
    np.savez(tmp_path / "badaxes.npz", **arrays)
    with pytest.raises(ParseError, match=r"array 'joint_axes': expected shape \(4, 3, 3\), got \(2, 3, 3\)"):
        read_npz(tmp_path / "badaxes.npz")


def test_npz_whole_numbers_stored_as_floats(tmp_path):
    """A frame number written as a float reads when it is whole (7.0), and is refused
    naming the key when it is not (7.5, nan)."""
    m = Motion(np.arange(6.0).reshape(3, 2), [("a", "x"), ("b", "")], fps=30)
    write_npz(m, tmp_path / "plain.npz")
    with np.load(tmp_path / "plain.npz") as z:
        arrays = {k: z[k] for k in z.files}
    for value, start in [(7.0, 7), (7.5, None), (np.nan, None)]:
        arrays["start_frame"] = np.array(value)
        np.savez(tmp_path / "f.npz", **arrays)
        if start is None:
            with pytest.raises(ParseError, match=r"array 'start_frame': expected a whole number"):
                read_npz(tmp_path / "f.npz")
        else:
            assert read_npz(tmp_path / "f.npz").start_frame == start


# --------------------------------------------------------------------------- CSV
def test_csv_round_trip(tmp_path):
    m = sample_motion(skeleton=False)
    write_csv(m, tmp_path / "m.csv")
    lines = (tmp_path / "m.csv").read_text().splitlines()
    assert lines[0] == "# fps=119.88 start_frame=42"
    assert lines[1].startswith("root.tx,root.ty,root.tz,root.rx,")
    assert '"left femur.rx"' in lines[1] or "left femur.rx" in lines[1]
    assert len(lines) == 2 + m.n_frames
    b = read_csv(tmp_path / "m.csv")
    assert b.channels == m.channels
    assert b.fps == 119.88 and b.start_frame == 42
    np.testing.assert_allclose(b.frames, m.frames, rtol=1e-9, atol=1e-9)
    assert b.frames.tobytes() == m.frames.tobytes()  # repr is exact


def test_csv_fps_sources(tmp_path):
    body = "hips.tx,hips.rx,free\n1,2,3\n4,5,6\n"
    (tmp_path / "plain.csv").write_text(body)
    (tmp_path / "rated.csv").write_text("# fps=30\n" + body)
    plain = read_csv(tmp_path / "plain.csv")
    assert plain.fps == 120.0
    assert plain.channels == (("hips", "tx"), ("hips", "rx"), ("free", ""))
    np.testing.assert_array_equal(plain.frames, [[1, 2, 3], [4, 5, 6]])
    assert read_csv(tmp_path / "plain.csv", fps=50).fps == 50.0
    assert read_csv(tmp_path / "rated.csv").fps == 30.0
    assert read_csv(tmp_path / "rated.csv", fps=60).fps == 60.0
    # CRLF, blank lines, a comment among the rows
    (tmp_path / "crlf.csv").write_bytes(b"# fps=25\r\na.tx,a.ty\r\n\r\n1,2\r\n# note\r\n3,4\r\n")
    c = read_csv(tmp_path / "crlf.csv")
    assert c.fps == 25.0
    np.testing.assert_array_equal(c.frames, [[1, 2], [3, 4]])


def test_csv_attaches_skeleton(tmp_path):
    m = sample_motion(T=3)
    bvh = tmp_path / "sk.bvh"
    write_bvh(m.select(m.channels), bvh)
    write_csv(m, tmp_path / "m.csv")
    b = read_csv(tmp_path / "m.csv", skeleton=m.skeleton)
    assert b.skeleton is m.skeleton
    np.testing.assert_allclose(b.positions().positions, m.positions().positions)
    b2 = read_csv(tmp_path / "m.csv", skeleton=bvh)
    assert b2.skeleton.source_format == "bvh"
    # BVH names cannot hold spaces: the writer made 'left femur' BVH-safe
    assert b2.skeleton.names == ["root", "left_femur", "ltibia", "neck"]
    with pytest.raises(ParameterError, match=r"\.asf or \.bvh"):
        read_csv(tmp_path / "m.csv", skeleton=tmp_path / "m.csv")


@pytest.mark.parametrize(
    "text, line, fragment",
    [
        ("a.tx,a.ty\n1,2\n3\n", 3, "row has 1 values, the header (line 1) names 2 columns"),
        ("# fps=24\na.tx,a.ty\n1,2\n3,4,5\n", 4, "row has 3 values"),
        ("a.tx,a.ty\n1,2\n\n3,abc\n", 4, "column 2 (a.ty) is 'abc', expected a number"),
        ("a.tx,a.ty\n1,nan\n", 2, "expected a finite number"),
        ("a.tx,a.ty\n1,\n", 2, "column 2 (a.ty) is '', expected a number"),
        ("# fps=fast\na.tx\n1\n", 1, "after 'fps='"),
        ("# fps=0\na.tx\n1\n", 1, "positive"),
        ("a.tx,a.tx\n1,2\n", 1, "appears twice"),
        ("a.tx,,a.ty\n1,2,3\n", 1, "empty channel name in column 2"),
        ("# only a comment\n", 1, "no header row"),
    ],
)
def test_csv_errors(tmp_path, text, line, fragment):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(ParseError) as e:
        read_csv(p)
    assert e.value.path == str(p)
    assert e.value.line == line, str(e.value)
    assert fragment in e.value.message, str(e.value)


def test_csv_missing_and_empty(tmp_path):
    with pytest.raises(ParseError, match="no such file"):
        read_csv(tmp_path / "none.csv")
    (tmp_path / "empty.csv").write_text("")
    with pytest.raises(ParseError, match="no header row"):
        read_csv(tmp_path / "empty.csv")
    (tmp_path / "header.csv").write_text("a.tx,a.ty\n")
    with pytest.raises(ParseError, match="no frames"):  # as every reader: no frames, no capture
        read_csv(tmp_path / "header.csv")


def test_csv_ignores_the_skeleton_it_does_not_store(tmp_path):
    # the skeleton is not written, so one no skeleton file would take does not stop a CSV
    sk = Skeleton((Joint("root", -1, [0, 0, 0], ("rx",), "X"), Joint("far", 0, [1e12, 0, 0], ("ry",), "Y")))
    m = Motion(np.zeros((3, 2)), sk.channels, fps=30.0, skeleton=sk)
    with pytest.raises(ParameterError, match="skeleton"):
        write_npz(m, tmp_path / "m.npz")
    write_csv(m, tmp_path / "m.csv")
    back = read_csv(tmp_path / "m.csv")
    assert back.channels == m.channels and np.array_equal(back.frames, m.frames)


def test_csv_joint_names_with_dots_read_back(tmp_path):
    # the header splits at the last dot: joint "a.b.c" with dof "rx" is "a.b.c.rx"
    m = Motion(np.arange(6.0).reshape(3, 2), [("a.b.c", "rx"), ("hips", "ty")], fps=30.0)
    write_csv(m, tmp_path / "m.csv")
    back = read_csv(tmp_path / "m.csv")
    assert back.channels == m.channels and np.array_equal(back.frames, m.frames)
