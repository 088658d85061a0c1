"""UsdSkel export: joint positions computed by usd-core match our forward kinematics."""

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.motion import Motion

from cyclecoord.io.usd import read_usd, usd_joint_positions, write_usd


@pytest.mark.parametrize("suffix", [".usda", ".usdc"])
def test_69_01_round_trip_every_frame(walk_69_01, tmp_path, suffix):
    out = tmp_path / ("walk" + suffix)
    cc.save(walk_69_01, out)
    fk = walk_69_01.positions()
    names, pos, fps = usd_joint_positions(out)
    assert fps == 120 and pos.shape[0] == walk_69_01.n_frames
    assert names == fk.names
    assert np.abs(pos - fk.positions).max(axis=(1, 2)).max() < 1e-3
    back = read_usd(out)
    assert back.channels == walk_69_01.channels
    assert np.abs(back.positions().positions - fk.positions).max() < 1e-3


def test_stage_metadata(walk_69_01, tmp_path):
    from pxr import Usd, UsdGeom, UsdSkel

    out = tmp_path / "w.usda"
    write_usd(walk_69_01[:10], out)
    stage = Usd.Stage.Open(str(out))
    assert UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y
    assert UsdGeom.GetStageMetersPerUnit(stage) == pytest.approx(0.0254 / 0.45)
    assert stage.GetTimeCodesPerSecond() == 120
    assert (stage.GetStartTimeCode(), stage.GetEndTimeCode()) == (0, 9)
    skel = UsdSkel.Skeleton(stage.GetPrimAtPath("/Motion/Skeleton"))
    assert len(skel.GetJointsAttr().Get()) == len(walk_69_01.positions().names)


def test_bad_input_writes_nothing(walk_69_01, tmp_path):
    m = walk_69_01[:5]
    bare = Motion(m.frames, m.channels, fps=m.fps)
    with pytest.raises(ParameterError, match="skeleton"):
        cc.save(bare, tmp_path / "a.usda")
    frames = m.frames.copy()
    frames[2, 7] = np.inf
    with pytest.raises(ParameterError, match="frame 2"):
        cc.save(m.with_frames(frames), tmp_path / "b.usdc")
    assert list(tmp_path.iterdir()) == []
    bad = tmp_path / "bad.usda"
    bad.write_text("#usda 1.0\n(\n broken")
    with pytest.raises(ParseError, match="bad.usda"):
        cc.load(bad)


def test_matrices_are_row_vector_transforms():
    """USD matrices act on row vectors: ``[p, 1] @ M = [R p + t, 1]``, for one matrix per
    joint and for a (frames, joints) batch alike."""
    from scipy.spatial.transform import Rotation

    from cyclecoord.io.usd import _matrices

    rots = Rotation.from_rotvec([[0, 0, np.pi / 2], [0.3, -0.2, 0.5]]).as_matrix()
    trans = np.array([[1.0, 2.0, 3.0], [-0.5, 0.0, 4.0]])
    p = np.array([0.7, -1.1, 0.4])
    for m in (_matrices(trans, rots), _matrices(trans[None], rots[None])[0]):
        assert m.shape == (2, 4, 4)
        for k in range(2):
            np.testing.assert_allclose(np.append(p, 1.0) @ m[k],
                                       np.append(rots[k] @ p + trans[k], 1.0), atol=1e-12)


def test_time_samples_outside_the_stage_range_are_not_read(walk_69_01, tmp_path):
    """Only the time codes from startTimeCode to endTimeCode are the motion: a sample
    after endTimeCode is neither read nor checked (here it is not a unit quaternion)."""
    out = tmp_path / "w.usda"
    write_usd(walk_69_01[:6], out)
    text = out.read_text()
    a = text.index("quatf[] rotations.timeSamples")
    b = text.index("5: [(", a) + len("5: [(")
    end = text.index(")", b)
    out.write_text(text[:b] + "2, 0, 0, 0" + text[end:])
    with pytest.raises(ParseError, match="rotations at time code 5"):
        read_usd(out)
    out.write_text(out.read_text().replace("endTimeCode = 5", "endTimeCode = 4", 1))
    back = read_usd(out)
    assert back.n_frames == 5
    np.testing.assert_allclose(back.positions().positions,
                               walk_69_01[:5].positions().positions, atol=1e-3)


def test_refusals_hold_back_what_was_printed_meanwhile(capfd):
    """A USD reader's refusal is its one-line ParseError (a usd-core error or text that
    is not UTF-8 turned into one): what was printed on standard error while reading
    (Python's, file descriptor 2's, usd-core's warnings) is not shown; after a read that
    succeeds, or an error other than a refusal, it is printed as usual."""
    import os
    import sys

    from pxr import Tf

    from cyclecoord.io.usd import _refusing

    class PxrError(RuntimeError):
        pass

    PxrError.__module__ = "pxr.Tf"

    def reader(outcome):
        def read(path):
            sys.stderr.write("python says\n")
            sys.stderr.flush()
            os.write(2, b"C++ says\n")
            Tf.Warn("usd-core says")
            if outcome == "refuse":
                raise ParseError("bad", str(path))
            if outcome == "utf8":
                raise UnicodeDecodeError("utf-8", b"\xff", 0, 1, "invalid start byte")
            if outcome == "pxr":
                raise PxrError("Error in 'f' at line 3 in file x.cpp : 'corrupt'")
            if outcome == "fail":
                raise KeyError("bug")
            return 7
        return _refusing(read)

    capfd.readouterr()
    for outcome, words in [("refuse", "bad"), ("utf8", "not UTF-8 .invalid start byte at byte 0"),
                           ("pxr", "not a readable USD file .corrupt.")]:
        with pytest.raises(ParseError, match=words):
            reader(outcome)("f.usda")
        assert capfd.readouterr().err == "", outcome
    assert reader("succeed")("f.usda") == 7
    err = capfd.readouterr().err
    assert err.startswith("python says\nC++ says\n") and "usd-core says" in err
    with pytest.raises(KeyError):
        reader("fail")("f.usda")
    err = capfd.readouterr().err
    assert err.startswith("python says\nC++ says\n") and "usd-core says" in err
