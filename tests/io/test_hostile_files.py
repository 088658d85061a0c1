"""Files that once ended in a traceback, a hang or an unreadable output (issue 18's fuzzer
cases, made small): each is now one ParseError naming the file and the line, frame or
NPZ key, and every writer refuses what its reader would refuse."""

import json
import time
from dataclasses import replace

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io import read_npz, write_amc, write_asf, write_bvh, write_csv, write_npz
from cyclecoord.io._limits import MAX_DEPTH, MAX_JOINTS, MAX_METADATA_DEPTH
from cyclecoord.skeleton import Joint, Skeleton


@pytest.fixture(scope="module")
def walk():
    return cc.datasets.example_capture().motion[:20]


def one_line(exc_info, path) -> str:
    text = str(exc_info.value)
    assert "\n" not in text and str(path) in text, text
    return text


# ------------------------------------------------------------------------------ ASF, AMC
def test_asf_direction_of_1e308_is_refused(tmp_path, walk):
    cc.save(walk, tmp_path / "w_01.amc")  # writes w.asf
    asf = tmp_path / "w.asf"
    lines = asf.read_text().splitlines()
    k = next(i for i, s in enumerate(lines) if s.strip().startswith("direction"))
    lines[k] = "    direction 1e308 1e308 1e308"
    asf.write_text("\n".join(lines) + "\n")
    with pytest.raises(ParseError) as e:
        cc.load(tmp_path / "w_01.amc")
    assert e.value.line == k + 1 and "1e308" in one_line(e, asf)
    # two allowed numbers whose product passes the cap: the bone's block is named
    j = next(i for i, s in enumerate(lines[k:], start=k) if s.strip().startswith("length"))
    lines[k], lines[j] = "    direction 1e5 0 0", "    length 1e5"
    asf.write_text("\n".join(lines) + "\n")
    with pytest.raises(ParseError, match="direction times length") as e:
        cc.load(tmp_path / "w_01.amc")
    one_line(e, asf)


def test_amc_frame_number_of_5001_digits(tmp_path, walk):
    cc.save(walk, tmp_path / "w_01.amc")
    amc = tmp_path / "w_01.amc"
    text = amc.read_text().replace("\n2\n", "\n" + "9" * 5001 + "\n", 1)
    amc.write_text(text)
    with pytest.raises(ParseError, match="5,001 digits|5001 digits") as e:
        cc.load(amc)
    one_line(e, amc)


def test_amc_value_beyond_the_cap_names_frame_and_bone(tmp_path, walk):
    cc.save(walk, tmp_path / "w_01.amc")
    amc = tmp_path / "w_01.amc"
    lines = amc.read_text().splitlines()
    k = next(i for i, s in enumerate(lines) if s == "3") + 2
    parts = lines[k].split()
    lines[k] = " ".join([parts[0], "1e308"] + parts[2:])
    amc.write_text("\n".join(lines) + "\n")
    with pytest.raises(ParseError) as e:
        cc.load(amc)
    assert e.value.frame == 3 and e.value.line == k + 1 and parts[0] in one_line(e, amc)


# ------------------------------------------------------------------------------ BVH
def chain_bvh(n: int, duplicate: bool = False) -> str:
    out = ["HIERARCHY", "ROOT j0", "{", "OFFSET 0 0 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    for i in range(1, n):
        name = "j0" if duplicate and i == n - 1 else f"j{i}"
        out += [f"JOINT {name}", "{", "OFFSET 0 1 0", "CHANNELS 1 Zrotation"]
    out += ["End Site", "{", "OFFSET 0 1 0", "}"] + ["}"] * n
    out += ["MOTION", "Frames: 1", "Frame Time: 0.01", " ".join(["0"] * (n + 2))]
    return "\n".join(out) + "\n"


def test_bvh_huge_chains_fail_fast(tmp_path):
    path = tmp_path / "chain.bvh"
    path.write_text(chain_bvh(16_000))  # took 18.6 s in the quadratic name check
    t0 = time.process_time()
    with pytest.raises(ParseError, match=f"at most {MAX_DEPTH} are supported") as e:
        cc.load(path)
    one_line(e, path)
    # a bushy hierarchy with too many joints (shallow): the joint cap
    lines = ["HIERARCHY", "ROOT r", "{", "OFFSET 0 0 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    for i in range(MAX_JOINTS + 5):
        lines += [f"JOINT j{i}", "{", "OFFSET 0 1 0", "CHANNELS 1 Zrotation", "}"]
    lines += ["}", "MOTION", "Frames: 1", "Frame Time: 0.01", "0"]
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ParseError, match=f"at most {MAX_JOINTS:,}"):
        cc.load(path)
    # a duplicate at the end of a long (allowed) chain is found without a quadratic scan
    path.write_text(chain_bvh(MAX_DEPTH, duplicate=True))
    with pytest.raises(ParseError, match="used twice"):
        cc.load(path)
    assert time.process_time() - t0 < 30  # generous: a guard against the quadratic scan only


@pytest.mark.parametrize("header, fragment", [
    ("Frames: 0", "number of frames"),
    ("Frames: " + "9" * 5000, "digits"),
    ("Frames: -3", "number of frames"),
])
def test_bvh_frame_counts(tmp_path, walk, header, fragment):
    path = tmp_path / "w.bvh"
    write_bvh(walk, path)
    text = path.read_text()
    path.write_text(text.replace(f"Frames: {walk.n_frames}", header).split(header)[0] + header
                    + "\nFrame Time: 0.01\n")
    with pytest.raises(ParseError, match=fragment) as e:
        cc.load(path)
    one_line(e, path)


def test_bvh_one_huge_value_names_the_frame(tmp_path, walk):
    path = tmp_path / "w.bvh"
    write_bvh(walk, path)
    lines = path.read_text().splitlines()
    k = lines.index("MOTION") + 3 + 4  # frame 5
    vals = lines[k].split()
    vals[7] = "1e308"
    lines[k] = " ".join(vals)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ParseError) as e:
        cc.load(path)
    assert e.value.line == k + 1 and "frame 5" in one_line(e, path) and "1e308" in str(e.value)


# ------------------------------------------------------------------------------ CSV
def test_csv_start_frame_above_int64(tmp_path, walk):
    path = tmp_path / "w.csv"
    write_csv(walk, path)
    text = path.read_text().replace("# fps=", f"# start_frame={2**70} fps=", 1)
    path.write_text(text)
    with pytest.raises(ParseError, match="start_frame") as e:
        cc.load(path)
    assert e.value.line == 1
    one_line(e, path)


# ------------------------------------------------------------------------------ NPZ
@pytest.mark.parametrize("key, value, fragment", [
    ("frames", "nan", "non-finite value nan"),
    ("frames", "huge", "1e+308"),
    ("frames", "complex", "real numbers"),
    ("frames", "timedelta", "real numbers"),
    ("frames", "empty", "no frames"),
    ("joint_axes", "zero", "axis is not a rotation"),
    ("joint_offsets", "inf", "finite number"),
    ("metadata_json", "deep", f"at most {MAX_METADATA_DEPTH}"),
    ("metadata_json", "list", "JSON object"),
    ("has_skeleton", "array", "single boolean"),
    ("fps", "tiny", "frame rate"),
    ("start_frame", "huge", "whole number"),
    ("limit_ranges", "nan", "finite number"),
    ("joint_parents", "cycle", "earlier joint"),
    ("version", "newer", "layout version 2"),
])
def test_npz_bad_arrays_name_the_key(tmp_path, walk, key, value, fragment):
    with np.load(_base(tmp_path, walk)) as z:
        arrays = {k: z[k] for k in z.files}
    a = arrays.get(key)
    if key == "frames":
        f = a.copy()
        if value == "nan":
            f[3, 4] = np.nan
        elif value == "huge":
            f[3, 4] = 1e308
        elif value == "complex":
            f = f.astype(complex)
        elif value == "timedelta":
            f = f.astype("timedelta64[s]")
        else:
            f = f[:0]
        new = f
    elif key == "joint_axes":
        new = a.copy()
        new[2] = 0
    elif key == "joint_offsets":
        new = a.copy()
        new[1, 1] = np.inf
    elif key == "metadata_json":
        new = np.array('{"a":' * 5000 + "1" + "}" * 5000 if value == "deep" else "[]")
    elif key == "has_skeleton":
        new = np.array([True, False])
    elif key == "fps":
        new = np.array(5e-324)
    elif key == "start_frame":
        new = np.array(np.uint64(2**64 - 1))
    elif key == "limit_ranges":
        new = np.array([[np.nan, 1.0]])
        arrays["limit_joints"] = np.array([1])
        arrays["limit_dofs"] = np.array(["rx"])
    elif key == "joint_parents":
        new = a.copy()
        new[1] = len(new) - 1
    else:
        new = np.array(2)
    arrays[key] = new
    path = tmp_path / "case.npz"
    np.savez(path, **arrays)
    with pytest.raises(ParseError) as e:
        read_npz(path)
    text = one_line(e, path)
    assert fragment in text
    if key not in ("joint_parents", "joint_axes"):
        assert repr(key) in text


def _base(tmp_path, walk):
    base = tmp_path / "base.npz"
    write_npz(walk, base)
    return base


# ------------------------------------------------------------------------------ writers
def test_writers_refuse_what_their_readers_refuse(tmp_path, walk):
    empty = walk[0:0]
    big = walk.with_frames(np.where(np.arange(walk.n_channels) == 5, 1e300, walk.frames))
    j = walk.skeleton.joints
    far = replace(walk, skeleton=Skeleton(
        joints=(j[0], replace_joint(j[1], offset=[1e300, 0, 0])) + j[2:],
        name=walk.skeleton.name, source_format=walk.skeleton.source_format,
    ))
    slow = replace(walk, fps=5e-324)
    cases = ((empty, "no frames"), (big, "1e+300"), (far, "offset"), (slow, "frame rate"))
    for motion, why in cases:
        for suffix in (".bvh", ".amc", ".npz", ".csv"):
            if suffix == ".csv" and why == "offset":
                continue  # CSV stores no skeleton
            out = tmp_path / f"out{suffix}"
            with pytest.raises(ParameterError) as e:
                extra = {"asf_path": tmp_path / "o.asf"} if suffix == ".amc" else {}
                cc.save(motion, out, **extra)
            assert why in str(e.value) and str(out) in str(e.value), (suffix, str(e.value))
            assert not out.exists() and not (tmp_path / "o.asf").exists()
    nan_limit = Skeleton(joints=(j[0], replace_joint(j[1], limits={"rx": (np.nan, 1.0)})) + j[2:])
    with pytest.raises(ParameterError, match="limit"):
        write_asf(nan_limit, tmp_path / "x.asf")
    with pytest.raises(ParameterError, match="x.bvh.*skeleton.*--skeleton"):
        write_bvh(replace(walk, skeleton=None), tmp_path / "x.bvh")
    deep = dict(walk.metadata, nested=json.loads("[" * 100 + "]" * 100))
    with pytest.raises(ParameterError, match="'nested'"):
        write_npz(replace(walk, metadata=deep), tmp_path / "x.npz")
    with pytest.raises(ParameterError, match="no frames"):
        write_amc(empty, tmp_path / "x.amc")


def replace_joint(joint: Joint, **changes) -> Joint:
    fields = dict(name=joint.name, parent=joint.parent, offset=joint.offset, dofs=joint.dofs,
                  rotation_order=joint.rotation_order, axis=joint.axis, end_site=joint.end_site,
                  limits=joint.limits)
    fields.update(changes)
    return Joint(**fields)


def test_joint_checks_geometry():
    with pytest.raises(ParameterError, match="not finite"):
        Joint(name="a", parent=-1, offset=[np.nan, 0, 0])
    with pytest.raises(ParameterError, match="rotation matrix"):
        Joint(name="a", parent=-1, offset=[0, 0, 0], axis=np.zeros((3, 3)))
    with pytest.raises(ParameterError, match="rotation matrix"):
        Joint(name="a", parent=-1, offset=[0, 0, 0], axis=np.diag([1.0, 1.0, -1.0]))


def test_bvh_hierarchy_past_its_word_limit_names_the_line(tmp_path):
    """A hierarchy of more than 64 words a supported joint (64 * MAX_JOINTS) without
    MOTION is refused at the first line read once the words already read exceed that:
    the error names that line (1-based)."""
    limit = 64 * MAX_JOINTS
    per_line = 1000
    path = tmp_path / "words.bvh"
    # line 1 is HIERARCHY (1 word), lines 2.. hold 1000 words each
    full = (limit - 1) // per_line + 1  # word lines that take the count past the limit
    path.write_text("HIERARCHY\n" + ("x " * per_line + "\n") * (full + 5))
    with pytest.raises(ParseError, match=f"runs past {limit:,} words") as e:
        cc.load(path)
    one_line(e, path)
    assert e.value.line == full + 2  # the line after HIERARCHY and the `full` word lines
    # exactly at the limit: still read on (refused later for what the words are)
    path.write_text("HIERARCHY\n" + "x\n" * (limit - 1) + "x y\n")
    with pytest.raises(ParseError) as e:
        cc.load(path)
    assert "runs past" not in str(e.value)
