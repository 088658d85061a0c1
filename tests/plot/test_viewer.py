"""The interactive viewer page: self-contained, animated, with the skeleton where FK puts it."""

import json
import re

import numpy as np
import pytest

from cyclecoord.cli.main import main
from cyclecoord.errors import ParameterError
from cyclecoord.motion import Motion
from cyclecoord.plot.viewer import skeleton_figure, write_viewer
from _skips import need_program


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


_PROBE = """
var gd = document.getElementById('{plot_id}');
function probe(tag) {
  var el = document.createElement('pre');
  el.id = tag;
  el.textContent = JSON.stringify({x: Array.from(gd._fullData[0].x).slice(0, 6),
                                   frames: gd._transitionData._frames.length});
  document.body.appendChild(el);
}
probe('probe0');
Plotly.animate(gd, ['30'], {frame: {duration: 0, redraw: true}, mode: 'immediate',
                            transition: {duration: 0}}).then(function () {
  probe('probe30');
  var btn = Array.from(document.querySelectorAll('.updatemenu-button'))
    .find(function (b) { return b.textContent.indexOf('Play') >= 0; });
  btn.dispatchEvent(new MouseEvent('click', {bubbles: true}));
  setTimeout(function () { probe('probePlay'); }, 300);
});
"""


@pytest.mark.slow
def test_page_in_headless_chromium(walk, tmp_path):
    """Chromium (Debian's, when installed) draws the page offline: frame 30 puts the bones
    where forward kinematics does, and the Play button moves the animation on."""
    import subprocess

    browser = need_program("chromium")
    page = write_viewer(skeleton_figure(walk, max_fps=120), tmp_path / "probe.html", _PROBE)
    cmd = [
        browser,
        "--headless=new",
        "--no-sandbox",
        "--disable-gpu",
        "--enable-unsafe-swiftshader",
        "--use-angle=swiftshader",
        "--virtual-time-budget=3000",
        "--dump-dom",
        page.as_uri(),
    ]
    dom = subprocess.run(cmd, capture_output=True, text=True, timeout=180, check=False).stdout
    found = dict(re.findall(r'<pre id="(probe\w*)">([^<]*)</pre>', dom))
    assert set(found) == {"probe0", "probe30", "probePlay"}, dom[-2000:]
    fk = walk.positions()
    kids = np.flatnonzero(fk.parents >= 0)
    for tag, k in (("probe0", 0), ("probe30", 30)):
        x = json.loads(found[tag])["x"]
        assert json.loads(found[tag])["frames"] == 60
        assert x[2] is None
        assert x[0] == pytest.approx(fk.positions[k, fk.parents[kids[0]], 0])
        assert x[4] == pytest.approx(fk.positions[k, kids[1], 0])
    played = json.loads(found["probePlay"])["x"]
    assert played[0] != pytest.approx(json.loads(found["probe30"])["x"][0])
