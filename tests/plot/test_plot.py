"""Figures (cyclecoord.plot), stick-figure rendering, the render/--plot CLI and the examples."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402

import cyclecoord as cc  # noqa: E402
from cyclecoord.plot import figures as plot  # noqa: E402
from cyclecoord.errors import NoPeriodicMotionError, ParameterError  # noqa: E402

from PIL import Image  # noqa: E402  (Pillow ships with matplotlib)
from _skips import need_program  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


@pytest.fixture(scope="module")
def capture():
    return cc.datasets.example_capture()


@pytest.fixture(scope="module")
def result(capture):
    return cc.extract(capture.motion)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _collection(fig, label):
    found = [c for ax in fig.axes for c in ax.collections if c.get_label() == label]
    assert found, f"no collection labelled {label!r}"
    return found[0]


def _lines(fig, label):
    return [ln for ax in fig.axes for ln in ax.get_lines() if ln.get_label() == label]


def _check_image(path: Path, min_size=(200, 150)):
    """Open an image written by the library and check it is a real picture."""
    assert path.is_file() and path.stat().st_size > 1000
    with Image.open(path) as im:
        im.load()
        assert im.size[0] >= min_size[0] and im.size[1] >= min_size[1]
        rgb = np.asarray(im.convert("RGB"), dtype=float)
    colours = np.unique(rgb.reshape(-1, 3), axis=0)
    assert len(colours) > 20, f"{path.name}: only {len(colours)} colours"
    assert rgb.std() > 10, f"{path.name}: nearly uniform image"
    return rgb


def _gif_frames(path: Path) -> list[np.ndarray]:
    frames = []
    with Image.open(path) as im:
        assert im.format == "GIF"
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(np.asarray(im.convert("RGB"), dtype=float))
    return frames


# ------------------------------------------------------------------ barcode
def test_barcode_draws_every_bar_and_highlights_the_selected_one(result):
    bc, sel = result.barcode, result.selection
    fig = plot.plot_barcode(bc, sel)
    h0 = _collection(fig, "H0")
    h1 = _collection(fig, "H1")
    assert len(h0.get_segments()) == len(bc.h0)
    assert len(h1.get_segments()) == len(bc.h1)
    # every H1 segment spans its bar (deaths capped at the threshold), first bar on top
    segs = np.array(h1.get_segments())
    births = np.sort(segs[:, 0, 0])
    np.testing.assert_allclose(births, np.sort(bc.h1[:, 0]))
    top = segs[np.argmax(segs[:, 0, 1])]
    np.testing.assert_allclose(top[:, 0], [bc.h1[0, 0], min(bc.h1[0, 1], bc.threshold)])
    # the selected bar alone has the highlight colour and is thicker
    colours = h1.get_colors()
    red = np.array(to_rgba(plot._HIGHLIGHT))
    is_red = np.all(np.isclose(colours, red), axis=1)
    assert is_red.sum() == 1 and is_red[sel.index]
    widths = np.asarray(h1.get_linewidths())
    assert widths[sel.index] > np.delete(widths, sel.index).max()
    (chosen,) = _lines(fig, "selected class")
    np.testing.assert_allclose(chosen.get_xdata(), [sel.birth, min(sel.death, bc.threshold)])
    scale = _lines(fig, "scale")
    assert len(scale) == 2 and all(np.allclose(s.get_xdata(), sel.scale) for s in scale)
    # infinite bars end in an arrow marker at the threshold
    inf_h0 = _lines(fig, "H0 alive at threshold")
    assert len(inf_h0) == 1 and len(inf_h0[0].get_xdata()) == int(np.sum(~np.isfinite(bc.h0[:, 1])))
    np.testing.assert_allclose(inf_h0[0].get_xdata(), bc.threshold)


def test_barcode_without_selection_options_and_errors(result):
    bc = result.barcode
    fig = plot.plot_barcode(bc)
    assert not _lines(fig, "selected class") and not _lines(fig, "scale")
    assert not np.any(np.all(np.isclose(_collection(fig, "H1").get_colors(), to_rgba(plot._HIGHLIGHT)), axis=1))
    fig = plot.plot_barcode(bc, result.selection, max_h0=10)
    assert len(_collection(fig, "H0").get_segments()) == 10
    # one shared axes holds both diagrams
    fig2, ax = plt.subplots()
    out = plot.plot_barcode(bc, result.selection, ax=ax)
    assert out is fig2 and len(fig2.axes) == 1
    labels = {c.get_label() for c in ax.collections}
    assert {"H0", "H1"} <= labels
    with pytest.raises(ParameterError):
        plot.plot_barcode(result)  # not a Barcode
    with pytest.raises(ParameterError):
        plot.plot_barcode(bc, max_h0=0)


# ---------------------------------------------------------------------- PCA
def test_pca_points_coloured_by_coordinate_and_closed_cycle(result):
    fig = plot.plot_pca(result)
    sc = _collection(fig, "frames")
    xy = sc.get_offsets()
    assert xy.shape == (result.motion.n_frames, 2)
    np.testing.assert_allclose(sc.get_array(), result.coordinate)
    assert sc.get_clim() == (0.0, 1.0)
    # PCA: first axis carries more variance than the second, both centred
    assert xy[:, 0].var() >= xy[:, 1].var()
    np.testing.assert_allclose(xy.mean(axis=0), 0.0, atol=1e-6)
    (cyc,) = _lines(fig, "typical cycle")
    x, y = cyc.get_xdata(), cyc.get_ydata()
    assert len(x) == result.typical.n_frames + 1
    assert x[0] == x[-1] and y[0] == y[-1]
    # the cycle runs through the cloud: every cycle point is near some frame
    d = np.min(np.hypot(xy[:, 0][:, None] - x[None], xy[:, 1][:, None] - y[None]), axis=0)
    assert np.max(d) < 0.2 * np.ptp(xy[:, 0])


def test_pca_3d_and_bad_arguments(result):
    fig = plot.plot_pca(result, dims=3)
    ax3 = [a for a in fig.axes if a.name == "3d"]
    assert len(ax3) == 1
    (cyc,) = [ln for ln in ax3[0].get_lines() if ln.get_label() == "typical cycle"]
    xs, ys, zs = cyc.get_data_3d()
    assert len(zs) == result.typical.n_frames + 1 and np.ptp(zs) > 0
    with pytest.raises(ParameterError):
        plot.plot_pca(result, dims=4)
    _, ax2 = plt.subplots()
    with pytest.raises(ParameterError):
        plot.plot_pca(result, dims=3, ax=ax2)
    with pytest.raises(ParameterError):
        plot.plot_pca(result.barcode)


# ------------------------------------------------------------------ density
def test_density_histogram_and_pdf(result):
    fig = plot.plot_density(result, bins=25)
    ax = fig.axes[0]
    bars = ax.patches
    assert len(bars) == 25
    area = sum(b.get_height() * b.get_width() for b in bars)
    assert area == pytest.approx(1.0, rel=1e-6)
    (line,) = _lines(fig, "periodic density")
    x, y = line.get_xdata(), line.get_ydata()
    np.testing.assert_allclose(y, result.density.pdf(np.mod(x, 1.0)))
    assert np.trapezoid(y, x) == pytest.approx(1.0, abs=0.02)
    (ticks,) = _lines(fig, "cycle frames")
    np.testing.assert_allclose(ticks.get_xdata(), result.typical.phases)
    with pytest.raises(ParameterError):
        plot.plot_density(result, bins=1)


# --------------------------------------------------------------- coordinate
def test_coordinate_over_frames_with_segments(result):
    segs = [(0, 100, "walk"), (100, 250, "jog"), (300, 480, "walk")]
    fig = plot.plot_coordinate(result, segments=segs)
    ax = fig.axes[0]
    (line,) = _lines(fig, "coordinate")
    x, y = line.get_xdata(), line.get_ydata()
    wraps = int(np.sum(np.abs(np.diff(result.coordinate)) > 0.5))
    assert wraps >= 3  # four cycles
    assert int(np.isnan(y).sum()) == wraps  # broken at every wrap, no vertical jumps drawn
    base = 1.25  # the coordinate's strip sits above the re-timed phase's
    np.testing.assert_allclose(y[~np.isnan(y)] - base, result.coordinate)
    (phase,) = _lines(fig, "phase (re-timed)")
    ok = np.isfinite(result.phase)
    np.testing.assert_allclose(phase.get_ydata()[~np.isnan(phase.get_ydata())], result.phase[ok])
    np.testing.assert_allclose(x[~np.isnan(x)], np.arange(result.motion.n_frames) + result.motion.start_frame)
    spans = [p for p in ax.patches if p.get_label() in ("walk", "jog")]
    assert len(spans) == 3
    assert spans[0].get_facecolor() == spans[2].get_facecolor() != spans[1].get_facecolor()
    assert [t.get_text() for t in ax.texts] == ["walk", "jog", "walk"]


def test_coordinate_several_series_and_errors():
    t = np.arange(200)
    a = (t / 50.0) % 1.0
    b = np.where(t < 100, np.nan, (t / 30.0) % 1.0)
    fig = plot.plot_coordinate({"slow": a, "fast": b}, start_frame=1000)
    ax = fig.axes[0]
    assert [tl.get_text() for tl in ax.get_yticklabels()] == ["slow", "fast"]
    (slow,) = _lines(fig, "slow")
    assert np.nanmin(slow.get_xdata()) == 1000
    fig = plot.plot_coordinate(np.vstack([a, a]))
    assert len(_lines(fig, "coordinate 1")) == 1
    with pytest.raises(ParameterError):
        plot.plot_coordinate("not data")
    with pytest.raises(ParameterError):
        plot.plot_coordinate(a, segments=[(10, 5, "empty")])
    with pytest.raises(ParameterError):
        plot.plot_coordinate(np.zeros((2, 2, 2)))


# ----------------------------------------------------------------- channels
def test_channels_cycle_follows_original_and_jerk(result):
    fig = plot.plot_channels(result)
    ax_c, ax_j = fig.axes
    originals = [ln for ln in ax_c.get_lines() if not ln.get_label().endswith("(cycle)")]
    cycles = [ln for ln in ax_c.get_lines() if ln.get_label().endswith("(cycle)")]
    assert len(originals) == len(cycles) == 6
    root = {f"{j}.{d}" for j, d in result.motion.channels if j == "root"}
    assert not root & {ln.get_label() for ln in originals}
    P = result.cycle.n_frames
    first, whole = [], []
    for o, c in zip(originals, cycles):
        assert c.get_label() == o.get_label() + " (cycle)"
        assert c.get_linestyle() == "--"
        first.append(np.corrcoef(o.get_ydata()[:P], c.get_ydata()[:P])[0, 1])
        whole.append(np.corrcoef(o.get_ydata(), c.get_ydata())[0, 1])
    # each frame shows the cycle at its own phase: in step over the first period and, though
    # the synthetic walk's speed wobbles by 30 %, over the whole capture too (played at a
    # constant rate the cycle drifted out of step: whole-capture median correlation 0.3)
    assert np.median(first) > 0.9 and min(first) > 0.7, first
    assert np.median(whole) > 0.9 and min(whole) > 0.7, whole
    n = len(originals[0].get_ydata())
    assert n == round(3 * result.period_frames)
    (jo,) = [ln for ln in ax_j.get_lines() if ln.get_label() == "original"]
    (jc,) = [ln for ln in ax_j.get_lines() if ln.get_label() == "cycle"]
    # the jerk shown is the one reported: joint positions in the root's frame, metres / s³
    # (quality.pose_space, one computation for every command; issue 25)
    from cyclecoord.quality.pose_space import point_jerk, root_frame_points
    from cyclecoord.rig import describe_rig

    points = root_frame_points(result.motion, describe_rig(result.motion))
    expected = point_jerk(points, result.motion.fps, False) * result.pose_quality.figures.metres_per_unit
    np.testing.assert_allclose(jo.get_ydata(), expected[: len(jo.get_ydata())])
    assert f"cycle {result.jerk['cycle']:.3g}" in ax_j.get_title()
    # the averaged cycle is smoother than the noisy synthetic capture
    assert np.mean(jc.get_ydata()) < np.mean(jo.get_ydata())


def test_channels_selection_and_errors(result):
    fig = plot.plot_channels(result, channels=["lfemur.rx", ("rfemur", "rx")], periods=1)
    labels = [ln.get_label() for ln in fig.axes[0].get_lines()]
    assert labels == ["lfemur.rx", "lfemur.rx (cycle)", "rfemur.rx", "rfemur.rx (cycle)"]
    assert len(fig.axes[0].get_lines()[0].get_ydata()) == round(result.period_frames)
    fig = plot.plot_channels(result, channels="all")
    assert len(fig.axes[0].get_lines()) == 2 * (result.motion.n_channels - 6)
    with pytest.raises(ParameterError, match="nojoint"):
        plot.plot_channels(result, channels=["nojoint.rx"])
    with pytest.raises(ParameterError):
        plot.plot_channels(result, channels=["lfemur"])
    with pytest.raises(ParameterError):
        plot.plot_channels(result, periods=0)


def test_partial_result_is_refused(capture, tmp_path):
    motion = cc.datasets.make_random_walk_capture(n_frames=120, random_state=1).motion
    with pytest.raises(NoPeriodicMotionError) as refused:  # seeded: this walk has no loop
        cc.extract(motion)
    partial = refused.value.result
    plot.plot_barcode(partial.barcode)  # the barcode is still drawable
    for fn in (plot.plot_pca, plot.plot_density, plot.plot_channels):
        with pytest.raises(ParameterError, match="no periodic motion"):
            fn(partial)
    written = plot.save_figures(partial, tmp_path / "figs", dpi=40)
    assert [p.name for p in written] == ["barcode.png"]
    _check_image(written[0], min_size=(200, 150))


# ------------------------------------------------------------ save_figures
def test_save_figures_writes_five_real_pngs(result, tmp_path):
    folder = tmp_path / "new" / "figs"
    paths = plot.save_figures(result, folder, dpi=60)
    assert [p.name for p in paths] == list(plot.FIGURE_NAMES)
    sizes = {}
    for p in paths:
        rgb = _check_image(p, min_size=(300, 150))
        sizes[p.name] = rgb.shape[1::-1]
    assert sizes["barcode.png"] == (420, 300)  # 7 x 5 inches at 60 dpi
    assert sizes["channels.png"] == (660, 252)
    assert sorted(os.listdir(folder)) == sorted(plot.FIGURE_NAMES)  # no temporary files left
    assert not plt.get_fignums()  # nothing left open in pyplot
    (tmp_path / "afile").write_text("x")
    with pytest.raises(ParameterError):
        plot.save_figures(result, tmp_path / "afile")


# ------------------------------------------------------------------ windows (detect)
def test_windows_one_bar_per_window_coloured_by_motion(tmp_path):
    from cyclecoord.periodic.detection import detect

    m = cc.datasets.make_motion_chain(kinds=("walk", "squat"), segment_frames=400, random_state=0).motion
    res = detect(m, progress=False)
    fig = plot.plot_windows(res)
    ax = fig.axes[0]
    bars = [c for c in ax.collections if c.get_paths()]
    assert len(bars) == len(res.windows)
    lengths = sorted({w.stop - w.start for w in res.windows})
    assert [t.get_text() for t in ax.get_yticklabels()] == [f"{n / m.fps:.3g} s" for n in lengths]
    for w, bar in zip(res.windows, bars):
        want = f"C{w.motion % 10}" if w.motion >= 0 else ("0.6" if w.looping else "0.92")
        assert np.allclose(bar.get_facecolor()[0][:3], to_rgba(want)[:3])
    assert any(w.motion >= 0 for w in res.windows)
    fig.savefig(tmp_path / "w.png")
    _check_image(tmp_path / "w.png")
    with pytest.raises(ParameterError, match="method='global'"):
        plot.plot_windows(detect(m, method="global", progress=False))
    with pytest.raises(ParameterError, match="DetectionResult"):
        plot.plot_windows(m)


# ------------------------------------------------------------------ render
def test_render_gif_frames_and_motion(capture, tmp_path):
    m = capture.motion[:48]
    out = plot.render(m, tmp_path / "walk.gif", step=4, dpi=50, size=3)
    assert out == tmp_path / "walk.gif"
    frames = _gif_frames(out)
    assert len(frames) == 12
    h, w, _ = frames[0].shape
    assert h == 150 and w >= 90
    _check_image(out, min_size=(90, 150))
    # the figure moves: first and last frames differ, and each frame holds the skeleton's colours
    assert np.abs(frames[0] - frames[-1]).mean() > 0.5
    for f in (frames[0], frames[-1]):
        reds = np.sum((f[..., 0] > 150) & (f[..., 1] < 110) & (f[..., 2] < 110))
        blues = np.sum((f[..., 2] > 130) & (f[..., 0] < 100))
        assert reds > 20 and blues > 20  # right limbs red, left limbs blue
    with Image.open(out) as im:
        assert abs(im.info["duration"] - 1000 / 30) <= 4  # real time: 120 fps / 4
    assert os.listdir(tmp_path) == ["walk.gif"]
    if os.name == "posix":  # readable like any file the user writes, not mkstemp's 0600
        mask = os.umask(0)
        os.umask(mask)
        assert (out.stat().st_mode & 0o777) == 0o666 & ~mask


def test_render_side_by_side_loops_the_shorter(result, tmp_path):
    single = plot.render(result.motion[:60], tmp_path / "one.gif", step=6, dpi=40, size=3)
    both = plot.render(result.motion[:60], tmp_path / "two.gif", other=result.cycle[:30], step=6, dpi=40,
                       size=3, view="3d", titles=("original", "cycle"))
    f1, f2 = _gif_frames(single), _gif_frames(both)
    assert len(f1) == len(f2) == 10
    assert f2[0].shape[1] == 2 * 3 * 40  # two 3-inch 3-D panels at 40 dpi
    # the right half is drawn too (the looped cycle)
    right = f2[-1][:, f2[-1].shape[1] // 2 :]
    assert len(np.unique(right.reshape(-1, 3), axis=0)) > 5
    from cyclecoord.plot import animation

    track = animation._make_track(result.cycle[:30], None)
    pos, idx = track.at_times(np.array([0.0, 29 / 120, 30 / 120, 45 / 120]))
    assert list(idx) == [0, 29, 0, 15]
    root = track.positions[:, 0]
    step_disp = root[-1] - root[0] + root[-1] - root[-2]
    np.testing.assert_allclose(pos[2, 0, [0, 2]], root[0, [0, 2]] + step_disp[[0, 2]])
    np.testing.assert_allclose(pos[2, 0, 1], root[0, 1])


def test_render_follow_views_and_errors(capture, tmp_path):
    m = capture.motion
    out = plot.render(m[:40], tmp_path / "f.gif", step=10, follow=True, view="front", dpi=40)
    assert len(_gif_frames(out)) == 4
    out = plot.render(m[:40], tmp_path / "v.gif", step=10, view=(20, -60), dpi=40)
    assert len(_gif_frames(out)) == 4
    with pytest.raises(ParameterError, match=".gif or .mp4"):
        plot.render(m, tmp_path / "x.avi")
    with pytest.raises(ParameterError, match="view"):
        plot.render(m, tmp_path / "x.gif", view="top")
    with pytest.raises(ParameterError, match="step"):
        plot.render(m, tmp_path / "x.gif", step=0)
    with pytest.raises(ParameterError, match="skeleton"):
        plot.render(m.with_frames(m.frames, skeleton=None), tmp_path / "x.gif")
    with pytest.raises(ParameterError, match="does not exist"):
        plot.render(m, tmp_path / "missing" / "x.gif")
    assert not (tmp_path / "x.gif").exists()


def test_render_is_atomic(capture, tmp_path, monkeypatch):
    from matplotlib import animation

    target = tmp_path / "keep.gif"
    target.write_bytes(b"old contents")

    def boom(self, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(animation.PillowWriter, "grab_frame", boom)
    with pytest.raises(RuntimeError, match="disk full"):
        plot.render(capture.motion[:20], target, step=10, dpi=30)
    assert target.read_bytes() == b"old contents"
    assert os.listdir(tmp_path) == ["keep.gif"]


def _gif_delays_read_back(path: Path) -> list[int]:
    from PIL import Image

    with Image.open(path) as im:
        out = []
        for i in range(im.n_frames):
            im.seek(i)
            out.append(im.info["duration"])
    return out


def test_gif_plays_at_the_motion_rate(capture, tmp_path):
    """Issue 25: a 63-frame 30 fps GIF played 10 % fast (30 ms a frame); the delays,
    whole centiseconds, now alternate 3 and 4 cs and sum to the motion's duration."""
    from cyclecoord.plot.animation import gif_delays

    m = capture.motion
    m30 = m.with_frames(m.frames[::4][:63], fps=30.0)
    out = plot.render(m30, tmp_path / "walk30.gif", dpi=30, size=2)
    delays = _gif_delays_read_back(out)
    assert sum(delays) == 2100  # 63 frames / 30 fps = 2.1 s
    assert set(delays) <= {30, 40}
    # every frame starts within half a centisecond of its time
    starts = np.cumsum([0] + delays[:-1])
    assert np.abs(starts - np.arange(len(delays)) * 1000 / 30).max() <= 5 + 1e-9
    # 120 fps drawn every 4th frame plays in real time too
    out = plot.render(m[:120], tmp_path / "walk120.gif", dpi=30, size=2)
    assert sum(_gif_delays_read_back(out)) == 1000
    assert gif_delays(4, 25) == [40, 40, 40, 40]
    assert gif_delays(3, 100) == [20, 20, 20]  # GIF's fastest is 50 fps


def test_mp4_rate_is_passed_as_an_exact_fraction():
    from cyclecoord.plot.animation import _rate_fraction

    assert str(_rate_fraction(30.0)) == "30"
    assert str(_rate_fraction(30000 / 1001)) == "30000/1001"
    assert str(_rate_fraction(120 / 7)) == "120/7"


def test_mp4_keeps_the_rate_exactly(capture, tmp_path):
    import shutil

    from matplotlib import animation

    if not animation.FFMpegWriter.isAvailable() or shutil.which("ffprobe") is None:
        pytest.skip("ffmpeg/ffprobe are not installed; the MP4 rate cannot be read back here")
    m = capture.motion
    m = m.with_frames(m.frames[::4][:63], fps=30000 / 1001)
    out = plot.render(m, tmp_path / "ntsc.mp4", dpi=30, size=2)
    probe = subprocess.run(
        ["ffprobe", "-v", "error", "-select_streams", "v:0", "-show_entries",
         "stream=avg_frame_rate,nb_frames", "-of", "default=nw=1", str(out)],
        capture_output=True, text=True, check=True,
    ).stdout
    assert "avg_frame_rate=30000/1001" in probe and "nb_frames=63" in probe


def test_render_mp4_needs_ffmpeg(capture, tmp_path, monkeypatch):
    from matplotlib import animation

    monkeypatch.setattr(animation.FFMpegWriter, "isAvailable", classmethod(lambda cls: False))
    with pytest.raises(ParameterError, match="ffmpeg.*\\.gif"):
        plot.render(capture.motion[:20], tmp_path / "a.mp4")
    assert not list(tmp_path.iterdir())


def test_render_mp4_when_ffmpeg_is_there(capture, tmp_path):
    need_program("ffmpeg")
    out = plot.render(capture.motion[:40], tmp_path / "a.mp4", step=4, dpi=40)
    data = out.read_bytes()
    assert len(data) > 1000 and data[4:8] == b"ftyp"


# --------------------------------------------------------------------- CLI
def test_cli_extract_plot_and_render_side_by_side(tmp_path, capsys):
    from cyclecoord.cli import main

    figs = tmp_path / "figs"
    cycle = tmp_path / "cycle.bvh"
    code = main(["extract", "example", "-o", str(cycle), "--plot", str(figs)])
    assert code == 0
    for name in plot.FIGURE_NAMES:
        _check_image(figs / name)
    gif = tmp_path / "walk.gif"
    code = main(["render", "example", "-o", str(gif), "--frames", "0:60", "--step", "12",
                 "--side-by-side", str(cycle)])
    assert code == 0
    assert str(gif) in capsys.readouterr().out
    frames = _gif_frames(gif)
    n_cycle = cc.load(cycle).n_frames  # about 120: the animation lasts as long as the longer one
    assert len(frames) == -(-max(60, n_cycle) // 12)
    _check_image(gif, min_size=(300, 200))
    assert frames[0].shape[1] > frames[0].shape[0]  # two panels side by side


def test_cli_render_errors(tmp_path, capsys):
    from cyclecoord.cli import main

    assert main(["render", "example", "-o", str(tmp_path / "x.avi"), "--frames", "0:10"]) == 1
    assert ".gif or .mp4" in capsys.readouterr().err
    assert main(["render", "example", "-o", str(tmp_path / "x.gif"), "--frames", "0:9999"]) == 1
    assert "frame" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["render", "example", "-o", str(tmp_path / "x.gif"), "--step", "0"])
    assert exc.value.code == 2
    assert not list(tmp_path.iterdir())


# ---------------------------------------------------------------- examples
@pytest.mark.slow
@pytest.mark.parametrize(
    "script, args, outputs",
    [
        ("extract_cycle.py", ["-o", "cycle.bvh"], ["cycle.bvh"]),
        ("phase_per_frame.py", ["-o", "phase.csv"], ["phase.csv"]),
        ("render_comparison.py", ["-o", "cmp.gif", "--step", "12"], ["cmp.gif"]),
    ],
)
def test_examples_run_on_the_builtin_capture(script, args, outputs, tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run([sys.executable, str(EXAMPLES / script), *args], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    for name in outputs:
        assert (tmp_path / name).stat().st_size > 100
    if script == "extract_cycle.py":
        back = cc.load(tmp_path / "cycle.bvh")
        assert back.n_frames == 120  # one period of the synthetic walk: measured 119.6 frames
    if script == "phase_per_frame.py":
        rows = (tmp_path / "phase.csv").read_text().splitlines()
        assert rows[0] == "frame,phase,cycle" and len(rows) == 481
        phase = np.array([float(r.split(",")[1]) for r in rows[1:]])
        cycle = np.array([int(r.split(",")[2]) for r in rows[1:]])
        assert phase.min() >= 0 and phase.max() < 1
        assert cycle[0] == 0 and cycle[-1] in (3, 4) and np.all(np.diff(cycle) >= 0)
    if script == "render_comparison.py":
        assert len(_gif_frames(tmp_path / "cmp.gif")) == 40
