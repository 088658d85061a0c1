"""Tests for Acclaim ASF/AMC reading and writing (cyclecoord.io.asfamc)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.io.asfamc import read_amc, read_asf, write_amc, write_asf
from cyclecoord.motion import Motion
from cyclecoord.skeleton import Joint, Skeleton, forward_kinematics
from _skips import need_data

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data"
CMU = DATA / "cmu"

CMU_TRIALS = {
    "69/69_01.amc": 469,
    "143/143_01.amc": 100,
    "01/01_09.amc": 4242,
    "13/13_29.amc": 4592,
}


def need_cmu() -> Path:
    return need_data(CMU)


# --------------------------------------------------------------------- synthetic data
MINI_ASF = """\
# a tiny hand-made test skeleton
:version 1.10
:name mini
:units
  mass 1.0
  length 0.5
  angle deg
:documentation
  Two legs are too many: one leg, a spine, an arm and a head.
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 1 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name hip
     direction 0 -1 0
     length 2
     axis 0 0 0  XYZ
  end
  begin
     id 2
     name thigh
     direction 0.6 -0.8 0
     length 5
     axis 0 0 30 XYZ
    dof rx ry rz
    limits (-160.0 20.0)
           (-70.0 70.0)
           (-60.0 70.0)
  end
  begin
     id 3
     name shin
     direction 0 -1 0
     length 4
     axis 10 -20 30 XYZ
    dof rx
    limits (-10.0 170.0)
  end
  begin
     id 4
     name spine
     direction 0 1 0
     length 3
     axis 0 0 0 XYZ
    dof rx rz
  end
  begin
     id 5
     name arm
     direction 1 0 0
     length 2.5
     axis 0 0 -90 XYZ
    dof ry rz
  end
  begin
     id 6
     name head
     direction 0 0.6 0.8
     length 1
     axis 45 0 0 XYZ
    dof rx
  end
:hierarchy
  begin
    root hip spine
    hip thigh
    thigh shin
    spine arm head
  end
"""

# the same skeleton with every angle in radians
MINI_ASF_RAD = (
    MINI_ASF.replace("angle deg", "angle rad")
    .replace("axis 0 0 30 XYZ", f"axis 0 0 {math.radians(30)!r} XYZ")
    .replace(
        "axis 10 -20 30 XYZ",
        f"axis {math.radians(10)!r} {math.radians(-20)!r} {math.radians(30)!r} XYZ",
    )
    .replace("axis 0 0 -90 XYZ", f"axis 0 0 {math.radians(-90)!r} XYZ")
    .replace("axis 45 0 0 XYZ", f"axis {math.radians(45)!r} 0 0 XYZ")
    .replace("(-160.0 20.0)", f"({math.radians(-160)!r} {math.radians(20)!r})")
    .replace("(-70.0 70.0)", f"({math.radians(-70)!r} {math.radians(70)!r})")
    .replace("(-60.0 70.0)", f"({math.radians(-60)!r} {math.radians(70)!r})")
    .replace("(-10.0 170.0)", f"({math.radians(-10)!r} {math.radians(170)!r})")
)

# bones in AMC order and their dofs (as listed in the ASF)
MINI_BONES = [
    ("root", ("tx", "ty", "tz", "rx", "ry", "rz")),
    ("thigh", ("rx", "ry", "rz")),
    ("shin", ("rx",)),
    ("spine", ("rx", "rz")),
    ("arm", ("ry", "rz")),
    ("head", ("rx",)),
]
MINI_CHANNELS = tuple((b, d) for b, dofs in MINI_BONES for d in dofs)


def mini_values(n_frames: int = 3, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    vals = rng.uniform(-60.0, 60.0, size=(n_frames, len(MINI_CHANNELS)))
    vals[:, :3] = rng.normal(0.0, 3.0, size=(n_frames, 3))
    return vals


def amc_text(values: np.ndarray, radians: bool = False, first: int = 1, header=None) -> str:
    """AMC text for the mini skeleton (values in degrees; converted when radians)."""
    if header is None:
        header = [":FULLY-SPECIFIED", ":RADIANS" if radians else ":DEGREES"]
    out = ["# mini motion"] + list(header)
    rot = np.array([d.startswith("r") for _, d in MINI_CHANNELS])
    for t, row in enumerate(values):
        row = np.where(rot, np.radians(row), row) if radians else row
        out.append(str(first + t))
        k = 0
        for bone, dofs in MINI_BONES:
            out.append(bone + " " + " ".join(repr(float(x)) for x in row[k : k + len(dofs)]))
            k += len(dofs)
    return "\n".join(out) + "\n"


MINI_AMC = amc_text(mini_values())


def put(folder: Path, name: str, text: str, crlf: bool = False) -> Path:
    path = folder / name
    data = text.replace("\n", "\r\n") if crlf else text
    path.write_bytes(data.encode("utf-8"))
    return path


def line_of(text: str, needle: str, occurrence: int = 1) -> int:
    """1-based number of the line holding ``needle`` (its n-th occurrence).

    ``needle`` of the form ``"=x"`` matches a line that is exactly ``x`` (stripped).
    """
    seen = 0
    for i, line in enumerate(text.split("\n"), start=1):
        if (line.strip() == needle[1:]) if needle.startswith("=") else (needle in line):
            seen += 1
            if seen == occurrence:
                return i
    raise AssertionError(f"{needle!r} not in text")


def assert_same_skeleton(a: Skeleton, b: Skeleton, tol: float = 1e-9) -> None:
    assert a.names == b.names
    assert a.length_unit == pytest.approx(b.length_unit, abs=tol)
    for ja, jb in zip(a.joints, b.joints):
        assert ja.parent == jb.parent, ja.name
        assert ja.dofs == jb.dofs, ja.name
        assert ja.rotation_order == jb.rotation_order, ja.name
        np.testing.assert_allclose(ja.offset, jb.offset, atol=tol, err_msg=ja.name)
        np.testing.assert_allclose(ja.axis, jb.axis, atol=tol, err_msg=ja.name)
        assert (ja.end_site is None) == (jb.end_site is None), ja.name
        if ja.end_site is not None:
            np.testing.assert_allclose(ja.end_site, jb.end_site, atol=tol, err_msg=ja.name)
        assert set(ja.limits) == set(jb.limits), ja.name
        for d in ja.limits:
            np.testing.assert_allclose(ja.limits[d], jb.limits[d], atol=tol, err_msg=ja.name)


# --------------------------------------------------------------------- CMU captures
@pytest.mark.parametrize("rel, n_frames", sorted(CMU_TRIALS.items()))
def test_cmu_captures_parse(rel: str, n_frames: int) -> None:
    path = need_cmu() / rel
    motion = read_amc(path)  # the subject's ASF is found beside the AMC
    assert motion.n_frames == n_frames
    assert motion.n_channels == 62
    assert motion.channels[:6] == tuple(("root", d) for d in ("tx", "ty", "tz", "rx", "ry", "rz"))
    assert motion.channels[6:9] == (("lowerback", "rx"), ("lowerback", "ry"), ("lowerback", "rz"))
    assert motion.source == str(path)
    assert motion.fps == 120.0
    assert ":FULLY-SPECIFIED" in motion.metadata["amc_header"]
    assert motion.skeleton is not None and len(motion.skeleton.joints) == 31
    assert motion.skeleton.source_format == "asf"
    assert np.all(np.isfinite(motion.frames))
    # the channels are exactly the dofs the ASF declares
    assert set(motion.channels) == set(motion.skeleton.channels)


def test_cmu_first_values_and_asf_fields() -> None:
    cmu = need_cmu()
    motion = read_amc(cmu / "01" / "01_09.amc", skeleton=cmu / "01" / "01.asf")
    # from the file: "root 11.6562 17.3847 13.933 70.2373 -88.5734 -66.0737", "rradius 27.5902"
    np.testing.assert_allclose(
        motion.frames[0, :6], [11.6562, 17.3847, 13.933, 70.2373, -88.5734, -66.0737]
    )
    assert motion.frames[0, motion.channel_index("rradius", "rx")] == pytest.approx(27.5902)

    skel = read_asf(cmu / "69" / "69.asf")
    assert skel.length_unit == pytest.approx(0.45)
    assert skel.name == "VICON"
    assert skel.names[:6] == ["root", "lhipjoint", "lfemur", "ltibia", "lfoot", "ltoes"]
    lfemur, ltibia, ltoes = skel["lfemur"], skel["ltibia"], skel["ltoes"]
    assert lfemur.dofs == ("rx", "ry", "rz") and lfemur.rotation_order == "ZYX"
    assert skel["lfoot"].rotation_order == "ZX"
    assert lfemur.limits == {"rx": (-160.0, 20.0), "ry": (-70.0, 70.0), "rz": (-60.0, 70.0)}
    c, s = math.cos(math.radians(20)), math.sin(math.radians(20))
    np.testing.assert_allclose(lfemur.axis, [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-12)
    # ltibia starts at the end of lfemur: direction 0.34202 -0.939693 0, length 7.48822
    np.testing.assert_allclose(ltibia.offset, np.array([0.34202, -0.939693, 0]) * 7.48822)
    np.testing.assert_allclose(skel["lhipjoint"].offset, 0.0)
    assert ltoes.end_site is not None and lfemur.end_site is None
    np.testing.assert_allclose(ltoes.end_site, np.array([1.5356e-011, -4.21729e-011, 1]) * 1.02897)


def test_cmu_large_file_loads() -> None:
    # its load time is measured by benchmarks/bench_scaling.py, not asserted here
    path = need_cmu() / "01" / "01_09.amc"
    motion = read_amc(path)
    assert motion.n_frames == 4242 and motion.frames.shape == (4242, 62)
    assert np.all(np.isfinite(motion.frames))


def test_cmu_round_trip(tmp_path: Path) -> None:
    cmu = need_cmu()
    motion = read_amc(cmu / "69" / "69_01.amc")
    write_amc(motion, tmp_path / "69_01.amc", skeleton_path=tmp_path / "69.asf")
    again = read_amc(tmp_path / "69_01.amc")
    assert again.channels == motion.channels
    np.testing.assert_allclose(again.frames, motion.frames, atol=1e-6, rtol=0)
    assert_same_skeleton(motion.skeleton, again.skeleton)


@pytest.mark.parametrize("subject", ["01", "13", "69", "143"])
def test_cmu_asf_round_trip(tmp_path: Path, subject: str) -> None:
    skel = read_asf(need_cmu() / subject / f"{subject}.asf")
    write_asf(skel, tmp_path / "s.asf")
    assert_same_skeleton(skel, read_asf(tmp_path / "s.asf"))


def test_cmu_forward_kinematics_sanity() -> None:
    motion = read_amc(need_cmu() / "69" / "69_01.amc")
    fk = motion.positions()
    pos = fk.positions
    assert pos.shape == (469, len(fk.names), 3)
    assert np.all(np.isfinite(pos[0]))
    up = 1  # CMU skeletons are y-up
    head = fk["head"][0, up]
    for foot in ("ltoes/end", "rtoes/end", "lfoot", "rfoot"):
        assert fk[foot][0, up] < head - 10.0, foot  # feet well below the head
    # rigid bones: joint-to-parent distances are constant over all frames
    skel = motion.skeleton
    for i, parent in enumerate(fk.parents):
        if parent < 0:
            continue
        dist = np.linalg.norm(pos[:, i] - pos[:, parent], axis=1)
        assert np.ptp(dist) < 1e-6, fk.names[i]
        if i < len(skel.joints) and parent > 0:
            assert dist[0] == pytest.approx(np.linalg.norm(skel.joints[i].offset), abs=1e-9)


# --------------------------------------------------------------------- synthetic round trips
def test_mini_read(tmp_path: Path) -> None:
    put(tmp_path, "mini.asf", MINI_ASF)
    amc = put(tmp_path, "mini_01.amc", MINI_AMC)
    motion = read_amc(amc)
    assert motion.channels == MINI_CHANNELS
    np.testing.assert_allclose(motion.frames, mini_values(), rtol=0, atol=1e-12)
    assert motion.metadata["amc_header"] == ["# mini motion", ":FULLY-SPECIFIED", ":DEGREES"]
    skel = motion.skeleton
    assert skel.names == ["root", "hip", "thigh", "shin", "spine", "arm", "head"]
    assert list(skel.parents) == [-1, 0, 1, 2, 0, 4, 4]
    assert skel.length_unit == 0.5 and skel.name == "mini"
    np.testing.assert_allclose(skel["root"].offset, [0, 1, 0])
    np.testing.assert_allclose(skel["thigh"].offset, [0, -2, 0])  # hip's vector
    np.testing.assert_allclose(skel["shin"].offset, [3, -4, 0])  # thigh: (0.6,-0.8,0)*5
    np.testing.assert_allclose(skel["shin"].end_site, [0, -4, 0])
    np.testing.assert_allclose(skel["arm"].offset, [0, 3, 0])
    np.testing.assert_allclose(skel["head"].offset, [0, 3, 0])
    assert skel["spine"].end_site is None
    assert skel["arm"].rotation_order == "ZY"
    assert skel["shin"].limits == {"rx": (-10.0, 170.0)}


def _rx(a):
    c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _ry(a):
    c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rz(a):
    c, s = math.cos(math.radians(a)), math.sin(math.radians(a))
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def test_mini_forward_kinematics_matches_acclaim_formula(tmp_path: Path) -> None:
    """Independent Acclaim FK: Q_b = Q_parent C M C^-1 with M = R_last ... R_first."""
    put(tmp_path, "mini.asf", MINI_ASF)
    motion = read_amc(put(tmp_path, "mini_01.amc", MINI_AMC))
    fk = forward_kinematics(motion)
    elem = {"rx": _rx, "ry": _ry, "rz": _rz}
    bones = {  # name: (parent, direction*length, axis angles, dofs)
        "hip": ("root", np.array([0, -2.0, 0]), (0, 0, 0), ()),
        "thigh": ("hip", np.array([0.6, -0.8, 0]) * 5, (0, 0, 30), ("rx", "ry", "rz")),
        "shin": ("thigh", np.array([0, -4.0, 0]), (10, -20, 30), ("rx",)),
        "spine": ("root", np.array([0, 3.0, 0]), (0, 0, 0), ("rx", "rz")),
        "arm": ("spine", np.array([2.5, 0, 0]), (0, 0, -90), ("ry", "rz")),
        "head": ("spine", np.array([0, 0.6, 0.8]), (45, 0, 0), ("rx",)),
    }
    for t, row in enumerate(mini_values()):
        val = dict(zip(MINI_CHANNELS, row))
        q = {"root": _rz(val["root", "rz"]) @ _ry(val["root", "ry"]) @ _rx(val["root", "rx"])}
        start = {"root": np.array([val["root", d] for d in ("tx", "ty", "tz")])}
        end = {"root": start["root"]}
        for name, (parent, vec, (a, b, c), dofs) in bones.items():
            C = _rz(c) @ _ry(b) @ _rx(a)
            M = np.eye(3)
            for d in dofs:  # first listed dof is applied first
                M = elem[d](val[name, d]) @ M
            q[name] = q[parent] @ C @ M @ C.T
            start[name] = end[parent]
            end[name] = start[name] + q[name] @ vec
        for name in bones:
            np.testing.assert_allclose(fk[name][t], start[name], atol=1e-9, err_msg=name)
        for leaf in ("shin", "arm", "head"):
            np.testing.assert_allclose(fk[f"{leaf}/end"][t], end[leaf], atol=1e-9, err_msg=leaf)


def test_first_listed_dof_is_applied_first(tmp_path: Path) -> None:
    asf = (
        ":version 1.10\n:name one\n:units\n  length 1\n  angle deg\n:root\n"
        "  order TX TY TZ\n  axis XYZ\n  position 0 0 0\n  orientation 0 0 0\n"
        ":bonedata\n  begin\n    id 1\n    name shin\n    direction 0 0 1\n"
        "    length 4\n    axis 0 0 0 XYZ\n    dof rx ry\n"
        "    limits (-10.0 170.0) (-10 10)\n  end\n"
        ":hierarchy\n  begin\n    root shin\n  end\n"
    )
    skel = read_asf(put(tmp_path, "a.asf", asf))
    assert skel["shin"].rotation_order == "YX"
    frames = np.zeros((1, 2))
    frames[0] = [90.0, 90.0]
    m = Motion(frames, (("shin", "rx"), ("shin", "ry")), skeleton=skel)
    fk = forward_kinematics(m)
    # Ry(90) @ Rx(90) @ (0,0,4) = (0,-4,0); the other order would give (4,0,0)
    np.testing.assert_allclose(fk["shin/end"][0] - fk["shin"][0], [0, -4, 0], atol=1e-12)


def test_mini_amc_round_trip(tmp_path: Path) -> None:
    put(tmp_path, "mini.asf", MINI_ASF)
    values = mini_values(20, seed=3)
    values[5, 7] = 1e-300
    values[6, 8] = -123456.789012345678
    motion = read_amc(put(tmp_path, "mini_01.amc", amc_text(values)))
    out = tmp_path / "out"
    out.mkdir()
    write_amc(motion, out / "mini_01.amc", skeleton_path=out / "mini.asf")
    text = (out / "mini_01.amc").read_text()
    assert text.split("\n")[1:4] == [":FULLY-SPECIFIED", ":DEGREES", "1"]
    again = read_amc(out / "mini_01.amc")
    assert again.channels == motion.channels
    np.testing.assert_allclose(again.frames, motion.frames, rtol=1e-15, atol=1e-6)
    assert again.frames[5, 7] == 1e-300
    assert_same_skeleton(motion.skeleton, again.skeleton)
    # and once more: the second write is byte-identical to the first
    write_amc(again, out / "again.amc")
    assert (out / "again.amc").read_text().split("\n") == text.split("\n")[1:]


def test_mini_asf_round_trip(tmp_path: Path) -> None:
    skel = read_asf(put(tmp_path, "mini.asf", MINI_ASF))
    write_asf(skel, tmp_path / "copy.asf")
    again = read_asf(tmp_path / "copy.asf")
    assert_same_skeleton(skel, again)
    write_asf(again, tmp_path / "copy2.asf")
    assert (tmp_path / "copy.asf").read_text() == (tmp_path / "copy2.asf").read_text()


def test_crlf_and_lf_are_identical(tmp_path: Path) -> None:
    lf, crlf = tmp_path / "lf", tmp_path / "crlf"
    lf.mkdir()
    crlf.mkdir()
    put(lf, "mini.asf", MINI_ASF)
    put(crlf, "mini.asf", MINI_ASF, crlf=True)
    a = read_amc(put(lf, "mini_01.amc", MINI_AMC))
    b = read_amc(put(crlf, "mini_01.amc", MINI_AMC, crlf=True))
    assert b"\r\n" in (crlf / "mini_01.amc").read_bytes()
    assert a.channels == b.channels
    np.testing.assert_array_equal(a.frames, b.frames)
    assert a.metadata["amc_header"] == b.metadata["amc_header"]
    assert_same_skeleton(a.skeleton, b.skeleton, tol=0.0)


def test_radians_equal_degrees(tmp_path: Path) -> None:
    deg, rad = tmp_path / "deg", tmp_path / "rad"
    deg.mkdir()
    rad.mkdir()
    put(deg, "mini.asf", MINI_ASF)
    put(rad, "mini.asf", MINI_ASF_RAD)
    values = mini_values(5, seed=7)
    a = read_amc(put(deg, "mini_01.amc", amc_text(values)))
    b = read_amc(put(rad, "mini_01.amc", amc_text(values, radians=True)))
    assert a.channels == b.channels
    np.testing.assert_allclose(b.frames, a.frames, rtol=0, atol=1e-9)
    assert_same_skeleton(a.skeleton, b.skeleton, tol=1e-9)
    # an AMC stating no unit follows the ASF's ':units angle rad'
    c = read_amc(put(rad, "mini_02.amc", amc_text(values, radians=True, header=[])))
    np.testing.assert_allclose(c.frames, a.frames, rtol=0, atol=1e-9)
    # a radian AMC with a degree-holding Skeleton object: the header decides
    d = read_amc(put(rad, "mini_03.amc", amc_text(values, radians=True)), skeleton=a.skeleton)
    np.testing.assert_allclose(d.frames, a.frames, rtol=0, atol=1e-9)


def test_first_frame_number_and_later_bone_order(tmp_path: Path) -> None:
    put(tmp_path, "mini.asf", MINI_ASF)
    values = mini_values(3)
    text = amc_text(values, first=0)
    # swap the 'shin' and 'thigh' lines of the last frame: allowed, values follow the names
    lines = text.split("\n")
    i, j = line_of(text, "thigh ", 3) - 1, line_of(text, "shin ", 3) - 1
    lines[i], lines[j] = lines[j], lines[i]
    motion = read_amc(put(tmp_path, "mini_01.amc", "\n".join(lines)))
    assert motion.metadata["first_frame_number"] == 0
    np.testing.assert_allclose(motion.frames, values, atol=1e-12)


def test_write_amc_reorders_channels_per_bone(tmp_path: Path) -> None:
    put(tmp_path, "mini.asf", MINI_ASF)
    motion = read_amc(put(tmp_path, "mini_01.amc", MINI_AMC))
    front = [("arm", "rz"), ("root", "ry"), ("thigh", "rz"), ("arm", "ry")]
    shuffled = front + [c for c in MINI_CHANNELS if c not in front]
    m2 = motion.select(shuffled)
    out = tmp_path / "out"
    out.mkdir()
    write_amc(m2, out / "x.amc")
    text = (out / "x.amc").read_text()
    # bones in order of first appearance; each bone's values in its ASF dof order
    bone_lines = text.split("\n")[3:9]
    assert [ln.split()[0] for ln in bone_lines] == ["arm", "root", "thigh", "shin", "spine", "head"]
    assert [float(x) for x in bone_lines[0].split()[1:]] == pytest.approx(
        [motion.frames[0, motion.channel_index("arm", d)] for d in ("ry", "rz")], abs=0
    )
    again = read_amc(out / "x.amc", skeleton=tmp_path / "mini.asf")
    assert set(again.channels) == set(MINI_CHANNELS)
    for ch in MINI_CHANNELS:
        np.testing.assert_array_equal(
            again.frames[:, again.channel_index(*ch)], motion.frames[:, motion.channel_index(*ch)]
        )
    # a dof the motion lacks is written as zero (as forward kinematics treats it)
    partial = motion.select([c for c in MINI_CHANNELS if c != ("thigh", "ry")])
    write_amc(partial, out / "p.amc")
    p = read_amc(out / "p.amc", skeleton=motion.skeleton)
    assert np.all(p.frames[:, p.channel_index("thigh", "ry")] == 0.0)
    np.testing.assert_allclose(
        forward_kinematics(p).positions, forward_kinematics(partial).positions, atol=1e-9
    )


def test_write_amc_rejects_bad_motions(tmp_path: Path) -> None:
    skel = read_asf(put(tmp_path, "mini.asf", MINI_ASF))
    bad = mini_values(2)
    bad[1, 4] = np.nan
    with pytest.raises(ParameterError, match="non-finite"):
        write_amc(Motion(bad, MINI_CHANNELS, skeleton=skel), tmp_path / "x.amc")
    with pytest.raises(ParameterError, match="not a degree of freedom"):
        write_amc(Motion(np.zeros((2, 1)), [("shin", "rz")], skeleton=skel), tmp_path / "x.amc")
    with pytest.raises(ParameterError, match="not in the motion's skeleton"):
        write_amc(Motion(np.zeros((2, 1)), [("tail", "rx")], skeleton=skel), tmp_path / "x.amc")
    with pytest.raises(ParameterError, match="no skeleton"):
        no_skel = Motion(np.zeros((2, 1)), [("a", "rx")])
        write_amc(no_skel, tmp_path / "x.amc", skeleton_path=tmp_path / "s.asf")
    assert not (tmp_path / "x.amc").exists()


# --------------------------------------------------------------------- skeleton discovery
def test_skeleton_discovery(tmp_path: Path) -> None:
    # two ASFs in the folder: <subject>_<trial>.amc picks <subject>.asf
    put(tmp_path, "mini.asf", MINI_ASF)
    put(tmp_path, "other.asf", MINI_ASF.replace(":name mini", ":name other"))
    m = read_amc(put(tmp_path, "mini_07.amc", MINI_AMC))
    assert m.skeleton.name == "mini"
    # no matching subject: a clear error naming what was looked for
    with pytest.raises(ParseError, match=r"no skeleton found.*'walk\.asf'") as info:
        read_amc(put(tmp_path, "walk_01.amc", MINI_AMC))
    assert info.value.path == str(tmp_path / "walk_01.amc")
    # skeleton given as a path or as a Skeleton object
    m2 = read_amc(tmp_path / "walk_01.amc", skeleton=tmp_path / "mini.asf")
    m3 = read_amc(tmp_path / "walk_01.amc", skeleton=m2.skeleton)
    np.testing.assert_array_equal(m2.frames, m3.frames)
    assert m3.skeleton is m2.skeleton
    with pytest.raises(ParameterError):
        read_amc(tmp_path / "walk_01.amc", skeleton=42)
    # errors in the ASF name the ASF
    bad = tmp_path / "bad"
    bad.mkdir()
    put(bad, "x.asf", MINI_ASF.replace("dof rx rz", "dof rx rq"))
    with pytest.raises(ParseError) as info:
        read_amc(put(bad, "y.amc", MINI_AMC))
    assert info.value.path == str(bad / "x.asf")
    assert info.value.line == line_of(MINI_ASF, "dof rx rz")


# --------------------------------------------------------------------- error cases
def _replace_line(text: str, needle: str, new: str, occurrence: int = 1) -> tuple[str, int]:
    n = line_of(text, needle, occurrence)
    lines = text.split("\n")
    lines[n - 1] = new
    return "\n".join(lines), n


def _amc_error_cases():
    t = MINI_AMC
    cases = []
    cases.append(("empty", "", 1, "empty", None))
    cases.append(("whitespace only", "\n  \n", 1, "empty", None))
    cases.append(("no frames", ":FULLY-SPECIFIED\n:DEGREES\n", 2, "no frames", None))
    lines = t.rstrip("\n").split("\n")
    trunc = "\n".join(lines[:-2]) + "\n"  # frame 3 loses 'arm' and 'head'
    cases.append(("truncated last frame", trunc, line_of(t, "=3"), "missing bone 'arm'", 3))
    s, n = _replace_line(t, "thigh", "thigh 1.0 abc 3.0", 2)
    cases.append(("not a number", s, n, "expected a number for bone 'thigh', got 'abc'", 2))
    s, n = _replace_line(t, "shin", "shin 1 2 3", 2)
    cases.append(("too many values", s, n, "bone 'shin' has 1 dof (rx), got 3 values", 2))
    s, n = _replace_line(t, "arm", "arm 5", 1)
    cases.append(("too few values", s, n, "bone 'arm' has 2 dofs (ry rz), got 1 value", 1))
    s, n = _replace_line(t, "head", "tail 1 2", 3)
    cases.append(("unknown bone", s, n, "bone 'tail' is not in the skeleton", 3))
    s, n = _replace_line(t, "=2", "3")
    cases.append(("frame gap", s, n, "frame number 3 out of sequence: expected 2", 3))
    s, n = _replace_line(t, "=3", "2")
    cases.append(("frame repeat", s, n, "frame number 2 out of sequence: expected 3", 2))
    s, n = _replace_line(t, "spine", "spine nan 1", 2)
    cases.append(("nan", s, n, "non-finite value 'nan' for bone 'spine'", 2))
    s, n = _replace_line(t, "root", "root 1 2 3 4 inf 6", 3)
    cases.append(("inf", s, n, "non-finite value 'inf'", 3))
    s, n = _replace_line(t, "root", "root 1 2 3 4 1e999 6", 1)
    cases.append(("overflow", s, n, "non-finite value '1e999'", 1))
    s, n = _replace_line(t, "=1", "root 1 2 3 4 5 6")
    cases.append(("bone before first frame", s, n, "expected a frame number before bone", None))
    s, n = _replace_line(t, "shin", "", 2)
    cases.append(("bone missing mid-file", s, line_of(t, "=2"), "frame 2 (starting at line", 2))
    s, n = _replace_line(t, "head", "thigh 1 2 3", 2)
    cases.append(("bone twice", s, n, "bone 'thigh' appears twice in frame 2", 2))
    s, n = _replace_line(t, "head", ":DEGREES", 1)
    cases.append(("header after frames", s, n, "after the first frame", 1))
    s, n = _replace_line(t, "=2", "2 extra")
    cases.append(("frame number with extra text", s, n, "frame number alone", 1))
    s, n = _replace_line(t, ":DEGREES", ":DEGREES\n:RADIANS")
    cases.append(("contradicting units", s, n + 1, "contradicts", None))
    return cases


@pytest.mark.parametrize(
    "text, line, phrase, frame",
    [c[1:] for c in _amc_error_cases()],
    ids=[c[0] for c in _amc_error_cases()],
)
def test_amc_errors(tmp_path: Path, text: str, line: int, phrase: str, frame) -> None:
    put(tmp_path, "mini.asf", MINI_ASF)
    path = put(tmp_path, "mini_01.amc", text)
    with pytest.raises(ParseError) as info:
        read_amc(path)
    err = info.value
    assert err.path == str(path)
    assert err.line == line, str(err)
    assert phrase in err.message, str(err)
    if frame is not None:
        assert err.frame == frame, str(err)
    assert str(err).startswith(f"{path}:{line}")


def _asf_error_cases():
    t = MINI_ASF
    cases = []
    cases.append(("empty", "", 1, "empty"))
    head = t[: t.index(":bonedata")]
    cases.append(("no bonedata", head, len(head.rstrip("\n").split("\n")), "missing :bonedata"))
    s, n = _replace_line(t, "thigh shin", "    thigh shin tail")
    cases.append(("undefined bone in hierarchy", s, n, "'tail', which is not defined in :bonedata"))
    s, n = _replace_line(t, "hip thigh", "    pelvis thigh")
    cases.append(("undefined parent in hierarchy", s, n, "parent 'pelvis'"))
    s, n = _replace_line(t, "dof rx rz", "    dof rx rq")
    cases.append(("bad dof", s, n, "unknown degree of freedom 'rq'"))
    s, n = _replace_line(t, "dof rx rz", "    dof rx l")
    cases.append(("length dof", s, n, "'l'"))
    s, n = _replace_line(t, "direction 0.6 -0.8 0", "     direction 0.6 -0.8")
    cases.append(("short direction", s, n, "direction needs 3 numbers, got 2"))
    s, n = _replace_line(t, "direction 0.6 -0.8 0", "     direction 0.6 x 0")
    cases.append(
        ("direction not a number", s, n, "expected a number for bone 'thigh' direction, got 'x'")
    )
    s, n = _replace_line(t, "length 4", "     length -4")
    cases.append(("negative length", s, n, "must not be negative"))
    s, n = _replace_line(t, "(-60.0 70.0)", "")
    n = line_of(t, "limits (-160.0 20.0)")
    cases.append(("too few limits", s, n, "3 dofs (rx ry rz) but 2 limits"))
    s, n = _replace_line(t, "(-60.0 70.0)", "           (-60.0 70.0")
    cases.append(("malformed limits", s, n, "(low high)"))
    s, n = _replace_line(t, "spine arm head", "    spine arm")
    n = line_of(t, "name head")
    cases.append(("bone not in hierarchy", s, n, "'head' is not placed in :hierarchy"))
    s, n = _replace_line(t, "hip thigh", "    hip thigh\n    shin hip")
    cases.append(("bone with two parents", s, n + 1, "already has parent 'root'"))
    s, n = _replace_line(t, "root hip spine", "    root spine")
    s, n = _replace_line(s, "hip thigh", "    hip thigh\n    shin hip")
    cases.append(("cycle", s, n + 1, "not connected to the root"))
    s, n = _replace_line(t, "name shin", "     name thigh")
    cases.append(("duplicate bone", s, n, "defined twice"))
    s, n = _replace_line(t, "name hip", "     name root")
    cases.append(("bone named root", s, n, "may not be named 'root'"))
    s, n = _replace_line(t, ":hierarchy", ":skeleton")
    cases.append(("unknown section", s, n, "unknown section ':skeleton'"))
    s, n = _replace_line(t, "=end", "", 1)
    cases.append(("unclosed bone block", s, n + 1, "has no 'end' before a new 'begin'"))
    s, n = _replace_line(t, "axis 0 0 30 XYZ", "     axis 0 0 30 XYY")
    cases.append(("bad axis order", s, n, "permutation of XYZ"))
    s, n = _replace_line(t, "angle deg", "  angle grad")
    cases.append(("bad angle unit", s, n, "'deg' or 'rad'"))
    s, n = _replace_line(t, "order TX", "   order TX TY TZ RX RY RW")
    cases.append(("bad root order", s, n, "unknown degree of freedom 'RW'"))
    s, n = _replace_line(t, "id 2", "     colour red")
    cases.append(("unknown bone field", s, n, "unknown bone field 'colour'"))
    s, n = _replace_line(t, "direction 0 1 0", "     direction 0 1 0\n     direction 0 1 0")
    cases.append(("field twice", s, n + 1, "given twice"))
    cut = t[: t.rindex("  end")]
    n = len(cut.rstrip("\n").split("\n"))
    cases.append(("unclosed hierarchy", cut, n, "hierarchy block opened"))
    # 'begin' and 'end' are keywords only alone on their line
    s, n = _replace_line(t, "=end", "  end\n  end", 1)
    cases.append(("end outside a bone block", s, n + 1, "expected 'begin' to open a bone block"))
    s, n = _replace_line(t, "=begin", "  begin bone", 1)
    cases.append(("begin with a word", s, n, "got 'begin bone'"))
    s, n = _replace_line(t, "spine arm head", "    spine arm head\n  end here")
    cases.append(("hierarchy end with a word", s, n + 1, "parent 'end', which is not defined"))
    return cases


@pytest.mark.parametrize(
    "text, line, phrase",
    [c[1:] for c in _asf_error_cases()],
    ids=[c[0] for c in _asf_error_cases()],
)
def test_asf_errors(tmp_path: Path, text: str, line: int, phrase: str) -> None:
    path = put(tmp_path, "bad.asf", text)
    with pytest.raises(ParseError) as info:
        read_asf(path)
    err = info.value
    assert err.path == str(path)
    assert err.line == line, str(err)
    assert phrase in err.message, str(err)


def test_missing_file_is_parse_error(tmp_path: Path) -> None:
    with pytest.raises(ParseError, match="cannot read"):
        read_asf(tmp_path / "nope.asf")
    with pytest.raises(ParseError, match="cannot read"):
        read_amc(tmp_path / "nope.amc", skeleton=tmp_path / "nope.asf")


# --------------------------------------------------------------------- non-ASF skeletons
def bvh_like_skeleton() -> Skeleton:
    """BVH-style: identity axes, children at different offsets, translations, odd names."""
    return Skeleton(
        joints=(
            Joint("Hips", -1, [0, 90, 0], ("tx", "ty", "tz", "rz", "rx", "ry"), "ZXY"),
            Joint("Spine", 0, [0, 10, 0], ("rz", "rx", "ry"), "ZXY"),
            Joint("LeftUpLeg", 0, [8, -2, 0], ("rz", "rx", "ry"), "ZXY"),
            Joint("Right Leg", 0, [-8, -2, 0], ("rx", "ry", "rz"), "XYZ"),
            Joint("Head", 1, [0, 20, 1], ("rz", "rx", "ry"), "ZXY", end_site=[0, 5, 0]),
            Joint(
                "LeftArm", 1, [5, 15, 0], ("tx", "ty", "tz", "rz", "ry"), "ZY", end_site=[10, 0, 0]
            ),
            Joint("LeftFoot", 2, [0, -40, 0], ("ry",), "Y", end_site=[0, 0, 5]),
            Joint("root", 3, [0, -40, 0], ("rx",), "X"),
        ),
        name="bvh test",
        source_format="bvh",
    )


ASF_NAMES = {
    "Hips": "root",
    "Spine": "Spine",
    "LeftUpLeg": "LeftUpLeg",
    "Right Leg": "Right_Leg",
    "Head": "Head",
    "LeftArm": "LeftArm",
    "LeftFoot": "LeftFoot",
    "root": "j_root",
}


def test_bvh_skeleton_to_asf_preserves_fk(tmp_path: Path) -> None:
    skel = bvh_like_skeleton()
    rng = np.random.default_rng(11)
    chans = skel.channels
    frames = rng.uniform(-90, 90, size=(6, len(chans)))
    motion = Motion(frames, chans, skeleton=skel)
    write_amc(motion, tmp_path / "bvh_01.amc", skeleton_path=tmp_path / "bvh.asf")
    back = read_amc(tmp_path / "bvh_01.amc")
    asf = back.skeleton
    # helper bones: zero dofs, one per child at a new offset (root: all three; Spine: both)
    helpers = [j for j in asf.joints if "_to_" in j.name]
    assert sorted(j.name for j in helpers) == sorted(
        ["root_to_Spine", "root_to_LeftUpLeg", "root_to_Right_Leg"]
        + ["Spine_to_Head", "Spine_to_LeftArm"]
    )
    assert all(j.dofs == () for j in helpers)
    assert not any("_to_" in j for j, _ in back.channels)
    # every original joint sits where it did, in every frame
    fk0, fk1 = forward_kinematics(motion), forward_kinematics(back)
    for orig, new in ASF_NAMES.items():
        np.testing.assert_allclose(fk1[new], fk0[orig], atol=1e-9, err_msg=orig)
    for leaf in ("Head", "LeftArm", "LeftFoot"):
        np.testing.assert_allclose(fk1[ASF_NAMES[leaf] + "/end"], fk0[leaf + "/end"], atol=1e-9)
    # rotation orders survive (listing reversed where needed)
    assert asf["root"].rotation_order == "ZXY"
    assert asf["root"].dofs == ("tx", "ty", "tz", "ry", "rx", "rz")
    assert asf["Right_Leg"].rotation_order == "XYZ" and asf["Right_Leg"].dofs == ("rz", "ry", "rx")
    # reading the AMC against the original skeleton gives the original names and values
    same = read_amc(tmp_path / "bvh_01.amc", skeleton=skel)
    assert set(same.channels) == set(chans)
    for ch in chans:
        np.testing.assert_array_equal(
            same.frames[:, same.channel_index(*ch)], frames[:, chans.index(ch)]
        )


# --------------------------------------------------------------------- property tests
NO_FIXTURE_CHECK = [HealthCheck.function_scoped_fixture]  # tmp_path is reused on purpose

JUNK = st.one_of(
    st.sampled_from(
        ["abc", "nan", "inf", "-inf", "1e999", "", "(", ")", "()", ":", "#", ":bonedata",
         ":hierarchy", "begin", "end", "root", "0", "-1", "99999999999999999999", "rx", "l",
         "XYZ", "dof", "limits", "\x00", "é", "1,5", "(1", "2)", "½", "²"]
    ),
    st.text(max_size=6),
)


@st.composite
def mangled(draw, text: str) -> bytes:
    lines = text.split("\n")
    for _ in range(draw(st.integers(1, 4))):
        if not lines:
            break
        op = draw(st.sampled_from(["delete", "duplicate", "swap", "junk", "junk", "insert"]))
        i = draw(st.integers(0, len(lines) - 1))
        if op == "delete":
            del lines[i]
        elif op == "duplicate":
            lines.insert(i, lines[i])
        elif op == "swap":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == "insert":
            lines.insert(i, draw(JUNK))
        else:
            toks = lines[i].split()
            if toks:
                k = draw(st.integers(0, len(toks) - 1))
                toks[k] = draw(JUNK)
                lines[i] = " ".join(toks)
    data = "\n".join(lines).encode("utf-8")
    if draw(st.booleans()):
        data = data[: draw(st.integers(0, len(data)))]
    if draw(st.booleans()):
        data = data.replace(b"\n", b"\r\n")
    return data


SMALL_AMC = amc_text(mini_values(3, seed=5))


@settings(max_examples=200, deadline=None, suppress_health_check=NO_FIXTURE_CHECK)
@given(data=mangled(MINI_ASF))
def test_mangled_asf_parses_or_raises_parse_error(tmp_path: Path, data: bytes) -> None:
    path = tmp_path / "m.asf"
    path.write_bytes(data)
    try:
        skel = read_asf(path)
    except ParseError as err:
        assert err.path == str(path) and err.line is not None
        return
    assert isinstance(skel, Skeleton)
    assert skel.names[0] == "root"
    assert all(np.all(np.isfinite(j.offset)) and np.all(np.isfinite(j.axis)) for j in skel.joints)


@settings(max_examples=200, deadline=None, suppress_health_check=NO_FIXTURE_CHECK)
@given(data=mangled(SMALL_AMC))
def test_mangled_amc_parses_or_raises_parse_error(tmp_path: Path, data: bytes) -> None:
    asf = tmp_path / "mini.asf"
    if not asf.exists():
        put(tmp_path, "mini.asf", MINI_ASF)
    path = tmp_path / "mini_01.amc"
    path.write_bytes(data)
    try:
        motion = read_amc(path)
    except ParseError as err:
        assert err.path == str(path) and err.line is not None
        return
    assert isinstance(motion, Motion)
    assert motion.n_frames >= 1
    assert motion.frames.shape == (motion.n_frames, len(motion.channels))
    assert np.all(np.isfinite(motion.frames))


@settings(max_examples=100, deadline=None, suppress_health_check=NO_FIXTURE_CHECK)
@given(data=st.binary(max_size=300))
def test_random_bytes_never_crash(tmp_path: Path, data: bytes) -> None:
    put(tmp_path, "mini.asf", MINI_ASF)
    path = tmp_path / "r.amc"
    path.write_bytes(data)
    for reader in (read_asf, lambda p: read_amc(p, skeleton=tmp_path / "mini.asf")):
        try:
            reader(path)
        except ParseError:
            pass


@settings(max_examples=40, deadline=None, suppress_health_check=NO_FIXTURE_CHECK)
@given(
    offsets=st.lists(
        st.tuples(*[st.floats(-50, 50, allow_nan=False) for _ in range(3)]), min_size=2, max_size=4
    ),
    seed=st.integers(0, 2**32 - 1),
)
def test_any_skeleton_round_trips_fk(tmp_path: Path, offsets, seed: int) -> None:
    """A root with children at arbitrary offsets keeps every joint's FK position."""
    joints = [Joint("base", -1, [1, 2, 3], ("tx", "ty", "tz", "ry", "rx", "rz"), "YXZ")]
    for k, off in enumerate(offsets):
        parent = 0 if k < 2 else 1
        joints.append(Joint(f"j{k}", parent, off, ("rx", "rz"), "XZ", end_site=[0, 1, 0]))
    skel = Skeleton(tuple(joints), source_format="synthetic")
    rng = np.random.default_rng(seed)
    frames = rng.uniform(-180, 180, size=(3, len(skel.channels)))
    motion = Motion(frames, skel.channels, skeleton=skel)
    write_amc(motion, tmp_path / "s_1.amc", skeleton_path=tmp_path / "s.asf")
    back = read_amc(tmp_path / "s_1.amc")
    fk0, fk1 = forward_kinematics(motion), forward_kinematics(back)
    for j in skel.joints:
        new = "root" if j.parent < 0 else j.name
        np.testing.assert_allclose(fk1[new], fk0[j.name], atol=1e-8)


@pytest.mark.parametrize(
    "fps, named",
    [(120.0, False), (120.0 + 0.5e-9, False), (120.0 - 0.5e-9, False), (120.0 + 1.5e-9, True),
     (120.0 - 1.5e-9, True), (60.0, True), (240.0, True)],
)
def test_amc_names_its_rate_unless_it_is_120(tmp_path, fps, named):
    """AMC has no frame rate: write_amc names the motion's in a header comment (the exact
    float) unless it is CMU's 120 Hz to within 1e-9 fps (documented in write_amc)."""
    m = Motion(np.zeros((2, 3)), [("root", "tx"), ("root", "ty"), ("root", "tz")], fps=fps)
    write_amc(m, tmp_path / "m.amc")
    lines = (tmp_path / "m.amc").read_text().splitlines()
    rate_lines = [s for s in lines if s.startswith("# frame rate")]
    assert rate_lines == ([f"# frame rate {fps!r} fps (cyclecoord)"] if named else [])


def test_bone_axis_without_letters_means_xyz(tmp_path: Path) -> None:
    plain = MINI_ASF.replace("axis 10 -20 30 XYZ", "axis 10 -20 30")
    assert plain != MINI_ASF
    a = read_asf(put(tmp_path, "a.asf", MINI_ASF))
    b = read_asf(put(tmp_path, "b.asf", plain))
    assert_same_skeleton(a, b)


def test_numbers_up_to_the_largest_magnitude_are_read() -> None:
    from cyclecoord.io._acclaim import parse_number
    from cyclecoord.io._limits import MAX_MAGNITUDE

    assert parse_number(repr(MAX_MAGNITUDE), "x.asf", 1, "length") == MAX_MAGNITUDE
    assert parse_number(repr(-MAX_MAGNITUDE), "x.asf", 1, "length") == -MAX_MAGNITUDE
    with pytest.raises(ParseError, match="beyond the largest supported magnitude"):
        parse_number(repr(MAX_MAGNITUDE * (1 + 1e-15)), "x.asf", 1, "length")


def test_helper_bone_names_count_up_past_taken_ones() -> None:
    # a helper bone is "<parent>_to_<child>", then _2, _3... while that name is taken
    from cyclecoord.io._acclaim import asf_layout

    skel = Skeleton(
        joints=(
            Joint("Hips", -1, [0, 0, 0], ("rx",), "X"),
            Joint("Spine", 0, [0, 10, 0], ("rx",), "X"),
            Joint("Head", 1, [0, 20, 1], ("rx",), "X"),
            Joint("Arm", 1, [5, 15, 0], ("rx",), "X"),
            Joint("Spine_to_Head", 0, [1, 0, 0], ("rx",), "X"),
            Joint("Spine_to_Head_2", 0, [2, 0, 0], ("rx",), "X"),
        ),
        name="taken",
    )
    names = [b.asf_name for b in asf_layout(skel)]
    assert len(set(names)) == len(names)
    assert "Spine_to_Head_3" in names and "Spine_to_Arm" in names
