"""Outputs are written atomically, with the permissions an ordinary write would give."""

import os
import stat

import pytest

from cyclecoord.io import atomic_path, atomic_write


@pytest.mark.skipif(os.name != "posix", reason="POSIX permissions")
def test_new_file_gets_the_umask_permissions(tmp_path):
    old = os.umask(0o027)
    try:
        with atomic_write(tmp_path / "out.txt") as fh:
            fh.write("x")
        with open(tmp_path / "plain.txt", "w") as fh:
            fh.write("x")
    finally:
        os.umask(old)
    mode = stat.S_IMODE((tmp_path / "out.txt").stat().st_mode)
    assert mode == stat.S_IMODE((tmp_path / "plain.txt").stat().st_mode) == 0o640


@pytest.mark.skipif(os.name != "posix", reason="POSIX permissions")
def test_replaced_file_keeps_its_permissions(tmp_path):
    target = tmp_path / "out.bin"
    target.write_bytes(b"old")
    target.chmod(0o604)
    with atomic_write(target, "wb") as fh:
        fh.write(b"new")
    assert target.read_bytes() == b"new"
    assert stat.S_IMODE(target.stat().st_mode) == 0o604


def test_failed_write_leaves_the_target_and_no_temporary(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("keep")
    with pytest.raises(RuntimeError):
        with atomic_write(target) as fh:
            fh.write("partial")
            raise RuntimeError("boom")
    assert target.read_text() == "keep"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt"]


def test_missing_folder_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="does not exist"):
        with atomic_write(tmp_path / "nope" / "out.txt") as fh:
            fh.write("x")


def test_atomic_path_for_writers_that_want_a_name(tmp_path):
    target = tmp_path / "anim.gif"
    with atomic_path(target, suffix=".tmp.gif") as tmp:
        assert tmp.parent == tmp_path and tmp.name.endswith(".tmp.gif") and not target.exists()
        tmp.write_bytes(b"GIF89a")
    assert target.read_bytes() == b"GIF89a"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["anim.gif"]
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_bytes(b"partial")
            raise RuntimeError("encoder died")
    assert target.read_bytes() == b"GIF89a"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["anim.gif"]


# --- StagedOutputs: every output of a run moves into place together (issue 26) ----------


def _tree(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() if p.is_file() else None
            for p in folder.rglob("*")}


def test_staged_outputs_move_into_place_together_at_the_end(tmp_path):
    from cyclecoord.io import StagedOutputs

    (tmp_path / "out.txt").write_text("old")
    with StagedOutputs() as out:
        out.file(tmp_path / "out.txt").write_text("new")
        figs = out.folder(tmp_path / "a" / "figs")
        (figs / "one.png").write_bytes(b"1")
        # nothing is in place yet, and no folder has been created
        assert (tmp_path / "out.txt").read_text() == "old" and not (tmp_path / "a").exists()
    assert _tree(tmp_path) == {"out.txt": b"new", "a": None, "a/figs": None,
                               "a/figs/one.png": b"1"}


@pytest.mark.parametrize("error", [RuntimeError, KeyboardInterrupt])
def test_staged_outputs_of_a_failed_run_change_nothing(tmp_path, error):
    from cyclecoord.io import StagedOutputs

    (tmp_path / "out.txt").write_text("old")
    with pytest.raises(error):
        with StagedOutputs() as out:
            out.file(tmp_path / "out.txt").write_text("new")
            (out.folder(tmp_path / "figs") / "one.png").write_bytes(b"1")
            raise error
    assert _tree(tmp_path) == {"out.txt": b"old"}


@pytest.mark.skipif(os.name != "posix", reason="POSIX permissions")
def test_staged_outputs_keep_the_permissions_of_the_files_they_replace(tmp_path):
    from cyclecoord.io import StagedOutputs

    target = tmp_path / "out.bvh"
    target.write_text("old")
    target.chmod(0o604)
    with StagedOutputs() as out:
        with atomic_write(out.file(target)) as fh:
            fh.write("new")
    assert target.read_text() == "new" and stat.S_IMODE(target.stat().st_mode) == 0o604


def test_staged_amc_follows_the_skeleton_rule_where_it_lands(tmp_path):
    """An AMC's .asf is staged with it; an equal skeleton at its place is kept, a different
    one is refused, as :func:`cyclecoord.io.save` does."""
    import cyclecoord as cc
    from cyclecoord.errors import ParameterError
    from cyclecoord.io import StagedOutputs

    walk = cc.datasets.example_capture().motion[:20]
    with StagedOutputs() as out:
        out.save(walk, tmp_path / "s_01.amc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.asf", "s_01.amc"]
    asf = (tmp_path / "s.asf").stat().st_mtime_ns
    with StagedOutputs() as out:
        out.save(walk[:10], tmp_path / "s_02.amc")  # the same skeleton: s.asf is kept
    assert (tmp_path / "s.asf").stat().st_mtime_ns == asf
    from dataclasses import replace

    longer = replace(walk.skeleton, length_unit=walk.skeleton.length_unit * 2)
    with pytest.raises(ParameterError, match="different skeleton"):
        with StagedOutputs() as out:
            out.save(replace(walk, skeleton=longer), tmp_path / "s_03.amc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.asf", "s_01.amc", "s_02.amc"]
