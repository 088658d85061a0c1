"""Reading within memory (issue 26 part 5): AMC, BVH and CSV are parsed a chunk of frames
at a time into one float array, at a cost near the array itself, and a file that would
not fit in the memory limit is refused before its values are read, naming its size and
the limit."""

import tracemalloc

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParseError
from cyclecoord.io import _stream
from cyclecoord.io._limits import memory_limit


@pytest.fixture(scope="module")
def walk():
    m = cc.datasets.example_capture().motion
    reps = int(np.ceil(3000 / m.n_frames))
    return m.with_frames(np.tile(m.frames, (reps, 1))[:3000])


@pytest.fixture(scope="module")
def files(walk, tmp_path_factory):
    d = tmp_path_factory.mktemp("big")
    out = {}
    for suffix in (".amc", ".bvh", ".csv"):
        path = d / f"w_01{suffix}"
        cc.save(walk, path)
        out[suffix] = path
    return out


@pytest.mark.parametrize("suffix", [".amc", ".bvh", ".csv"])
def test_reading_costs_about_the_array(files, walk, suffix, monkeypatch):
    monkeypatch.setattr(_stream, "BLOCK", 1 << 16)
    first = cc.load(files[suffix])  # modules imported, skeleton cached: only the read counts
    tracemalloc.start()
    try:
        m = cc.load(files[suffix])
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    array = m.frames.nbytes
    assert m.n_frames == walk.n_frames and np.array_equal(m.frames, first.frames)
    # a whole-file read held every value as text and as a Python float: 14 KB a frame of
    # 62 channels (42 MB here); now the array, a block of text and a chunk of frames' text
    assert peak < array + 6e6, (peak, array)


@pytest.mark.parametrize("suffix", [".amc", ".bvh", ".csv"])
def test_a_file_over_the_memory_limit_is_refused_before_reading(files, suffix):
    with memory_limit(1_000_000), pytest.raises(ParseError) as e:
        cc.load(files[suffix])
    text = str(e.value)
    assert "\n" not in text and str(files[suffix]) in text
    assert "3,000 frames of" in text and "over the memory limit of 1 MB" in text
    assert "MB file" in text  # the file's size


def test_the_command_line_refuses_under_its_memory_limit(files, tmp_path, capsys):
    from cyclecoord.cli.main import main

    out = tmp_path / "o.npz"
    code = main(["convert", str(files[".csv"]), "-o", str(out), "--memory-limit", "1M"])
    err = capsys.readouterr().err
    assert code == 1 and "over the memory limit" in err and not out.exists()
    assert main(["convert", str(files[".csv"]), "-o", str(out), "--memory-limit", "1G"]) == 0


def test_more_lines_than_counted_grow_the_array(tmp_path):
    # U+2028 ends a line for the CSV reader but not for the byte count of its lines
    path = tmp_path / "m.csv"
    rows = "\u2028".join(f"{k},{2 * k}" for k in range(3000))
    path.write_text("# fps=30\na.rx,a.ry\n" + rows + "\n", encoding="utf-8")
    m = cc.load(path)
    assert m.frames.shape == (3000, 2) and m.frames[-1, 1] == 5998


@pytest.mark.parametrize(
    "text",
    ["a\r\nb\rc\n\nd", "a\n", "\ufeffx\u2028y\x85z\r", "", "\r\n\r\n", "a\rb\r\nc"],
)
@pytest.mark.parametrize("newlines_only", [False, True])
def test_text_lines_split_as_the_whole_text_did(tmp_path, monkeypatch, text, newlines_only):
    monkeypatch.setattr(_stream, "BLOCK", 1)  # every byte a block: every boundary split
    path = tmp_path / "t.txt"
    path.write_bytes(text.encode("utf-8"))
    body = text[1:] if text.startswith("\ufeff") else text
    if newlines_only:
        want = body.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    else:
        want = body.splitlines()
    assert list(_stream.text_lines(path, newlines_only=newlines_only)) == want
