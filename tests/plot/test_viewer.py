"""The interactive viewer page: self-contained, animated, with the skeleton where FK puts it."""

import json
import re

import numpy as np
import pytest

from cyclecoord.cli.main import main
from cyclecoord.errors import ParameterError
from cyclecoord.motion import Motion
from cyclecoord.plot.viewer import skeleton_figure, write_viewer


@pytest.fixture(scope="module")
def walk(walk_69_01):
    return walk_69_01[200:260]


def test_figure_frames_follow_forward_kinematics(walk):
    fig = skeleton_figure(walk, max_fps=40)
    meta = fig.layout.meta["cyclecoord"]
    assert meta["step"] == 3 and meta["frames_shown"] == list(range(0, 60, 3))
    assert len(fig.frames) == 20
    fk = walk.positions()
    k = 9  # animation frame 3
    bones = fig.frames[3].data[0]
    xyz = np.stack([bones.x, bones.y, bones.z], axis=1)
    kids = np.flatnonzero(fk.parents >= 0)
    child = fk.positions[k, kids]
    assert np.allclose(xyz[1::3, 0], child[:, 0])
    assert np.allclose(xyz[1::3, 1], -child[:, 2])  # scene (x, -z, y): y is up
    assert np.allclose(xyz[1::3, 2], child[:, 1])
    assert np.isnan(xyz[2::3]).all()
    labels = [s["label"] for s in fig.layout.sliders[0]["steps"]]
    assert labels[0] == "0" and len(labels) == 20
    buttons = [b["label"] for b in fig.layout.updatemenus[0]["buttons"]]
    assert buttons == ["Play", "Pause"]


def test_cycle_side_by_side_marks_phase_and_seam(walk):
    cycle = walk[:24]
    fig = skeleton_figure([cycle, walk], cycle=[True, False], labels=["cycle", "walk"], max_fps=120)
    assert len(fig.frames) == 60  # the longer motion sets the length; the cycle repeats
    labels = [s["label"] for s in fig.layout.sliders[0]["steps"]]
    assert [i for i, lab in enumerate(labels) if lab.endswith("seam")] == [0, 24, 48]
    dial = fig.frames[6].data[-1]  # phase 6/24 = 0.25: a quarter turn
    assert dial.x[0] == pytest.approx(1.0) and dial.y[0] == pytest.approx(0.0, abs=1e-12)
    assert any(getattr(t, "text", None) and "seam" in t.text for t in fig.data)
    # the cycle repeats: frame 30 shows cycle frame 6
    a = np.array(fig.frames[30].data[0].x, float)
    b = np.array(fig.frames[6].data[0].x, float)
    assert np.allclose(a, b, equal_nan=True)


def test_page_is_self_contained(walk, tmp_path):
    out = write_viewer(skeleton_figure(walk[:10]), tmp_path / "v.html")
    html = out.read_text()
    assert not re.search(r"<script[^>]*\bsrc=", html)  # plotly.js inlined, nothing fetched
    assert "Plotly.newPlot" in html or "Plotly.react" in html
    with pytest.raises(ParameterError, match="html"):
        write_viewer(skeleton_figure(walk[:10]), tmp_path / "v.png")


def test_errors(walk):
    bare = Motion(walk.frames, walk.channels, fps=walk.fps)
    with pytest.raises(ParameterError, match="skeleton"):
        skeleton_figure(bare)
    with pytest.raises(ParameterError, match="nothing"):
        skeleton_figure([])
    with pytest.raises(ParameterError, match="labels"):
        skeleton_figure([walk], labels=["a", "b"])


def test_cli_view(walk_69_01, tmp_path, capsys):
    out = tmp_path / "walk.html"
    code = main(["view", walk_69_01.source, "--frames", "200:260", "--cycle", "-o", str(out)])
    assert code == 0
    text = capsys.readouterr().out
    assert "foot skating" in text and "wrote" in text
    html = out.read_text()
    spec = re.search(r'"frames_shown":\s*(\[[^\]]*\])', html)
    assert spec and json.loads(spec.group(1))[:3] == [0, 4, 8]
    assert main(["view", walk_69_01.source, "-o", str(tmp_path / "x.png")]) == 1
    assert "html" in capsys.readouterr().err
