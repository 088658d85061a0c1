"""Stick-figure animations of captures: :func:`render` writes a GIF or MP4 of one motion, or of
two side by side (e.g. a capture and its extracted cycle), posed by forward kinematics.

The figure is built without pyplot (Agg canvas), so rendering works headless and leaves no
open figures behind.
"""

from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Sequence

import numpy as np

from ..errors import ParameterError
from ._canvas import detached_figure, drawn

if TYPE_CHECKING:  # pragma: no cover

    from ..motion import Motion

__all__ = ["gif_delays", "render"]


# ------------------------------------------------------------------- render
_VIEWS = ("side", "front", "3d")


@dataclass
class _Track:
    """World positions of one motion prepared for drawing (y up)."""

    positions: np.ndarray  # (T, P, 3)
    parents: np.ndarray
    colours: list
    fps: float
    title: str
    start_frame: int

    def at_times(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions at the given times (s); a shorter motion loops, its root carried on.

        Returns positions ``(K, P, 3)`` and the frame index used per time.
        """
        T = self.positions.shape[0]
        idx = np.floor(np.asarray(times) * self.fps + 1e-6).astype(int)
        loops, frame = np.divmod(idx, T)
        pos = self.positions[frame]
        if np.any(loops > 0) and T >= 2:
            root = self.positions[:, 0]
            per_loop = root[-1] - root[0] + (root[-1] - root[-2])
            per_loop[1] = 0.0  # carry on over the floor only
            pos = pos + loops[:, None, None] * per_loop[None, None, :]
        return pos, frame


def _side_colours(names: list[str], parents: np.ndarray) -> list:
    """Left limbs blue, right limbs red, the rest dark grey.  A joint's side is read from
    its name in any of the common conventions (:func:`~cyclecoord.joint_names.classify_joint`:
    ``lfoot``, ``LeftFoot``, ``mixamorig:LeftFoot``, Bandai's ``Foot_L``, ``foot_l``), else
    from a left/right pair of names (``lhipjoint`` / ``rhipjoint``), else from the joint
    it hangs from (an end site, a toe's end, a finger a name does not place)."""
    from ..joint_names import classify_joint

    base = [n.split("/")[0] for n in names]
    lower = {b.lower() for b in base}

    def side(b: str) -> str:
        role = classify_joint(b)
        if role is not None and role.side is not None:
            return "L" if role.side == "left" else "R"
        s = b.lower()
        for lp, rp in (("left", "right"), ("l", "r")):
            if s.startswith(lp) and rp + s[len(lp):] in lower:
                return "L"
            if s.startswith(rp) and lp + s[len(rp):] in lower:
                return "R"
        return "C"

    sides = [side(b) for b in base]
    for i in range(len(sides)):  # (parents come before their children)
        p = int(parents[i])
        if sides[i] == "C" and 0 <= p < i and sides[p] != "C":
            sides[i] = sides[p]
    pick = {"L": "#1f77b4", "R": "#d62728", "C": "#333333"}
    return [pick[x] for x in sides]


def _make_track(motion: "Motion", title: str | None) -> _Track:
    from ..motion import Motion

    if not isinstance(motion, Motion):
        raise ParameterError(f"render takes a Motion, got {type(motion).__name__}")
    if motion.skeleton is None:
        raise ParameterError(
            "render needs a skeleton to pose the figure; this "
            "motion has none (load an AMC with its ASF, or a BVH)"
        )
    if motion.n_frames < 1:
        raise ParameterError("nothing to render: the motion has no frames")
    jp = drawn(motion).positions()
    pos = np.asarray(jp.positions, dtype=float)
    if not np.all(np.isfinite(pos)):
        raise ParameterError(
            "forward kinematics gave non-finite positions; check the motion's values"
        )
    if title is None:
        src = motion.source or "motion"
        title = Path(src).name if ("/" in src or os.sep in src) else src
        if len(title) > 40:
            title = title[:37] + "..."
    return _Track(
        positions=pos,
        parents=np.asarray(jp.parents),
        colours=_side_colours(jp.names, jp.parents),
        fps=float(motion.fps),
        title=title,
        start_frame=int(motion.start_frame),
    )


def _smooth_track(xz: np.ndarray, width: int) -> np.ndarray:
    """Moving average of a (K, 2) path over ``width`` samples, edges padded."""
    if width <= 1 or xz.shape[0] < 3:
        return xz
    w = min(width, xz.shape[0])
    kernel = np.ones(w) / w
    pad = np.pad(xz, ((w // 2, w - 1 - w // 2), (0, 0)), mode="edge")
    return np.stack(
        [np.convolve(pad[:, i], kernel, mode="valid") for i in range(xz.shape[1])], axis=1
    )


def _view_basis(tracks_pos: list[np.ndarray], view: str) -> tuple[np.ndarray, np.ndarray]:
    """Unit floor vectors (x, z): direction of travel and its perpendicular."""
    disp = np.zeros(2)
    for p in tracks_pos:
        r = p[:, 0]
        disp += np.array([r[-1, 0] - r[0, 0], r[-1, 2] - r[0, 2]])
    body = max(float(np.ptp(p[..., 1])) for p in tracks_pos) or 1.0
    if np.linalg.norm(disp) < 0.25 * body:
        fwd = np.array([0.0, 1.0])  # no clear travel: world z
    else:
        fwd = disp / np.linalg.norm(disp)
    perp = np.array([fwd[1], -fwd[0]])
    return fwd, perp


def render(
    motion: "Motion",
    path: str | os.PathLike[str],
    fps: float | None = None,
    other: "Motion | None" = None,
    view: str | tuple[float, float] = "side",
    *,
    step: int | None = None,
    follow: bool | None = None,
    titles: Sequence[str] | None = None,
    dpi: float = 80,
    size: float = 4.0,
    max_frames: int = 2000,
    progress: bool = False,
) -> Path:
    """Animate a capture as a stick figure (forward kinematics) and write a GIF or MP4.

    Parameters
    ----------
    motion : Motion
        A capture with a skeleton, drawn as :func:`cyclecoord.rig.normalize_rig` gives it
        (every frame kept): a static root is left out (no bone from the origin to the
        hips) and a Z-up rig is turned y up.
    path : path-like
        ``.gif`` (Pillow, always available) or ``.mp4`` (needs ffmpeg on the PATH).  The
        file is rendered beside the target under a temporary name and renamed, so a
        failed render leaves nothing behind.
    fps : float, optional
        Playback rate of the animation; default real time (``motion.fps / step``).  A
        GIF's frame delays are whole centiseconds: they alternate so that they average
        to this rate (:func:`gif_delays`; at most 50 fps, the fastest GIF browsers
        play).  An MP4 keeps the rate exactly.
    other : Motion, optional
        A second capture drawn side by side (e.g. the extracted cycle next to the
        original).  The animation lasts as long as the longer one; the shorter one loops,
        its root carried on over the floor by one loop's displacement per repeat.
        Motions at different rates are matched by time.
    view : {"side", "front", "3d"} or (elevation, azimuth)
        ``"side"``: orthographic, looking across the direction of travel; ``"front"``:
        along it; ``"3d"`` or an ``(elev, azim)`` pair in degrees: a 3-D view.
    step : int, optional
        Draw every ``step``-th frame.  Default: enough to keep the animation near
        30 frames per second and under ``max_frames`` frames.
    follow : bool, optional
        Keep the figure centred by moving the floor under it (the camera follows the
        root, smoothed over about a second) instead of fixed axes covering the whole
        motion.  Default: follow only when the root travels more than about three body
        sizes.
    titles : sequence of str, optional
        Panel titles (default: file names of the sources).
    dpi : float, default 80
    size : float, default 4
        Height of each panel in inches (width likewise; the output is ``size * dpi``
        pixels tall).
    max_frames : int, default 2000
        Upper bound on drawn frames when ``step`` is automatic.
    progress : bool, default False
        A tqdm bar on stderr over the drawn frames (shown after 1 s).

    Returns
    -------
    Path
        The written file.

    Raises
    ------
    ParameterError
        For a motion without skeleton, an unknown suffix or view, a bad step or rate, or
        an ``.mp4`` request when ffmpeg is not available.
    """
    out = Path(path)
    suffix, view, elev_azim = _check_render_args(out, view, step, fps, max_frames)
    tracks = [_make_track(motion, titles[0] if titles else None)]
    if other is not None:
        tracks.append(_make_track(other, titles[1] if titles and len(titles) > 1 else None))
    rate = tracks[0].fps
    duration = max(t.positions.shape[0] / t.fps for t in tracks)
    n_total = max(1, int(round(duration * rate)))
    if step is None:
        step = max(1, int(np.ceil(rate / 30.0 - 1e-9)), int(np.ceil(n_total / max_frames)))
    times = np.arange(0, n_total, step) / rate
    play_fps = float(fps) if fps is not None else rate / step

    sampled = [t.at_times(times) for t in tracks]
    frames_used = [f for _, f in sampled]
    st = _stage([p for p, _ in sampled], view, follow, play_fps)

    n_panels = len(tracks)
    if st.is3d:
        width_in = size * n_panels
    else:
        horiz = 2 * st.half
        aspect = horiz / st.height if view in ("side", "front") else 1.0
        width_in = size * n_panels * float(np.clip(aspect, 0.6, 2.5))
    # even pixel sizes: H.264 in yuv420p needs them, and GIFs do not mind
    px_w = max(2, 2 * int(round(width_in * dpi / 2)))
    px_h = max(2, 2 * int(round(size * dpi / 2)))
    fig = detached_figure((px_w / dpi, px_h / dpi), dpi)
    artists = []
    for k, tr in enumerate(tracks):
        if st.is3d:
            ax, floor, bones, dots = _panel_3d(fig, k, n_panels, tr, st, elev_azim)
        else:
            ax, floor, bones, dots = _panel_2d(fig, k, n_panels, tr, st)
        text = ax.set_title(tr.title, fontsize=9)
        artists.append((floor, bones, dots, text))

    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=0.92, wspace=0.02)
    spacing = _grid_spacing(st.body)
    child = [np.flatnonzero(tr.parents >= 0) for tr in tracks]

    def draw_frame(i: int) -> None:
        for k, tr in enumerate(tracks):
            floor, bones, dots, text = artists[k]
            q = st.project(k, i)
            bones.set_segments(np.stack([q[tr.parents[child[k]]], q[child[k]]], axis=1))
            if st.follow or i == 0:
                floor.set_segments(st.floor_lines(st.centres[k][i], spacing))
            if st.is3d:
                dots.set_data_3d(q[:, 0], q[:, 1], q[:, 2])
            else:
                dots.set_data(q[:, 0], q[:, 1])
            text.set_text(f"{tr.title}  frame {tr.start_frame + int(frames_used[k][i])}")

    _write_frames(fig, out, suffix, play_fps, dpi, len(times), draw_frame, progress)
    return out


def _check_render_args(
    out: Path,
    view: str | tuple[float, float],
    step: int | None,
    fps: float | None,
    max_frames: int,
) -> tuple[str, str, tuple[float, float] | None]:
    """Validate :func:`render`'s arguments; the suffix, the view name and ``(elev, azim)``."""
    from matplotlib import animation

    suffix = out.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise ParameterError(
            f"{out}: render writes .gif or .mp4 animations, got suffix {out.suffix or '(none)'!r}"
        )
    if suffix == ".mp4" and not animation.FFMpegWriter.isAvailable():
        raise ParameterError(
            f"{out}: writing .mp4 needs ffmpeg, which matplotlib cannot find on this machine; "
            "install ffmpeg or write a .gif instead"
        )
    folder = out.parent if str(out.parent) else Path(".")
    if not folder.is_dir():
        raise ParameterError(f"{out}: folder {folder} does not exist")
    if isinstance(view, str):
        if view not in _VIEWS:
            raise ParameterError(
                f"view must be one of {', '.join(_VIEWS)} or "
                f"an (elevation, azimuth) pair, got {view!r}"
            )
        elev_azim = None
    else:
        try:
            elev_azim = (float(view[0]), float(view[1]))
        except (TypeError, ValueError, IndexError):
            raise ParameterError(
                f"view must be one of {', '.join(_VIEWS)} or "
                f"an (elevation, azimuth) pair, got {view!r}"
            ) from None
        view = "3d"
    if step is not None and (
        isinstance(step, bool) or not isinstance(step, (int, np.integer)) or step < 1
    ):
        raise ParameterError(f"step must be a whole number >= 1, got {step!r}")
    if fps is not None and (not np.isfinite(fps) or fps <= 0):
        raise ParameterError(f"fps must be a positive number, got {fps!r}")
    if not isinstance(max_frames, (int, np.integer)) or max_frames < 1:
        raise ParameterError(f"max_frames must be a whole number >= 1, got {max_frames!r}")
    return suffix, view, elev_azim


@dataclass
class _Stage:
    """Where the drawn motions sit: floor, height, panel half-width and the camera centres."""

    pos_list: list  # per motion: world positions (K, P, 3) at the drawn times
    hpos: list  # per motion: drawing floor coordinates (K, P, 2 in 3-D, 1 in 2-D)
    centres: list  # per motion: panel centre (K, h) in drawing floor coordinates
    body: float
    floor_y: float
    height: float
    pad: float
    half: float
    perp: np.ndarray
    is3d: bool
    follow: bool

    def project(self, k: int, i: int) -> np.ndarray:
        """Drawing coordinates (P, 2 or 3) of panel ``k`` at drawn frame ``i``."""
        h = self.hpos[k][i] - self.centres[k][i]
        return np.concatenate([h, self.pos_list[k][i][:, 1:2]], axis=1)

    def floor_lines(self, centre: np.ndarray, spacing: float) -> list:
        """Floor grid lines inside the panel at round world positions, moving with the world."""
        half, floor_y = self.half, self.floor_y
        offsets = []
        for c in centre:
            m = np.arange(np.ceil((c - half) / spacing), np.floor((c + half) / spacing) + 1)
            offsets.append(m * spacing - c)
        if self.is3d:
            lines = [[(o, -half, floor_y), (o, half, floor_y)] for o in offsets[0]]
            lines += [[(-half, o, floor_y), (half, o, floor_y)] for o in offsets[1]]
            return lines
        tick = 0.04 * self.body
        return [[(o, floor_y), (o - tick, floor_y - tick)] for o in offsets[0]]


def _stage(pos_list: list, view: str, follow: bool | None, play_fps: float) -> _Stage:
    """Body size, floor, the drawing's floor coordinates and the camera centres per frame."""
    body = max(float(np.median(np.ptp(p[..., 1], axis=1))) for p in pos_list) or 1.0
    floor_y = min(float(p[..., 1].min()) for p in pos_list)
    top_y = max(float(p[..., 1].max()) for p in pos_list)
    fwd, perp = _view_basis(pos_list, view)

    is3d = view == "3d"
    view_dir = fwd if view == "side" else perp

    def horizontal(xz: np.ndarray) -> np.ndarray:
        """Floor coordinates (..., 2) world (x, z) -> drawing (..., 2) in 3-D, (..., 1) in 2-D."""
        if is3d:  # right-handed z-up drawing frame: (x, -z, y)
            return xz * np.array([1.0, -1.0])
        return (xz @ view_dir)[..., None]

    hpos = [horizontal(p[..., [0, 2]]) for p in pos_list]  # (K, P, h)
    # horizontal extent of the pose around its root, and of the root's travel
    reach = max(float(np.max(np.abs(h - h[:, :1]))) for h in hpos)
    box = 2.0 * max(reach, 0.35 * body) * 1.15
    travel = max(float(np.max(np.ptp(h[:, 0], axis=0))) for h in hpos)
    if follow is None:
        follow = travel > 3.0 * max(box, body)
    centres = []
    for h in hpos:
        if follow:
            c = _smooth_track(h[:, 0], max(1, int(round(play_fps))))
        else:
            flat = h.reshape(-1, h.shape[-1])
            c = np.broadcast_to(
                (flat.min(axis=0) + flat.max(axis=0)) / 2, (h.shape[0], h.shape[-1])
            )
        centres.append(np.asarray(c, dtype=float))
    if follow:
        half = box / 2
    else:
        half = (
            max(float(np.max(np.abs(h - c[:, None, :]))) for h, c in zip(hpos, centres))
            + 0.1 * body
        )
    return _Stage(
        pos_list=pos_list,
        hpos=hpos,
        centres=centres,
        body=body,
        floor_y=floor_y,
        height=(top_y - floor_y) + 0.15 * body,
        pad=0.05 * body,
        half=half,
        perp=perp,
        is3d=is3d,
        follow=bool(follow),
    )


def _panel_3d(fig, k: int, n_panels: int, tr: _Track, st: _Stage, elev_azim) -> tuple:
    """Axes, floor grid, bones and joint dots of 3-D panel ``k``."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    half, floor_y, height, pad, perp = st.half, st.floor_y, st.height, st.pad, st.perp
    ax = fig.add_subplot(1, n_panels, k + 1, projection="3d")
    ax.set_axis_off()
    ax.set_xlim(-half, half)
    ax.set_ylim(-half, half)
    ax.set_zlim(floor_y - pad, floor_y + height)
    ax.set_box_aspect((2 * half, 2 * half, height + pad), zoom=1.35)
    if elev_azim is not None:
        ax.view_init(*elev_azim)
    else:
        # look from the side of the travel, a little from the front and above
        ang = np.degrees(np.arctan2(-perp[1], perp[0]))
        ax.view_init(elev=12.0, azim=ang - 25.0)
    dummy = [[(0.0, 0.0, floor_y), (0.0, 0.0, floor_y)]]
    floor = Line3DCollection(dummy, colors="0.75", linewidths=0.6)
    ax.add_collection3d(floor)
    bones = Line3DCollection(
        dummy,
        colors=[tr.colours[i] for i in range(len(tr.parents)) if tr.parents[i] >= 0],
        linewidths=2.0,
    )
    ax.add_collection3d(bones)
    (dots,) = ax.plot(
        [], [], [], linestyle="none", marker="o", markersize=2.5, color="#222222"
    )
    return ax, floor, bones, dots


def _panel_2d(fig, k: int, n_panels: int, tr: _Track, st: _Stage) -> tuple:
    """Axes, floor ticks, bones and joint dots of 2-D (side or front) panel ``k``."""
    from matplotlib.collections import LineCollection

    half, floor_y, body = st.half, st.floor_y, st.body
    ax = fig.add_subplot(1, n_panels, k + 1)
    ax.set_axis_off()
    ax.set_xlim(-half, half)
    ax.set_ylim(floor_y - st.pad - 0.02 * body, floor_y + st.height)
    ax.set_aspect("equal")
    ax.axhline(floor_y, color="0.45", linewidth=1.2)
    floor = LineCollection([], colors="0.7", linewidths=0.8)
    ax.add_collection(floor)
    bones = LineCollection(
        [],
        colors=[tr.colours[i] for i in range(len(tr.parents)) if tr.parents[i] >= 0],
        linewidths=2.2,
        capstyle="round",
    )
    ax.add_collection(bones)
    (dots,) = ax.plot([], [], linestyle="none", marker="o", markersize=2.5, color="#222222")
    return ax, floor, bones, dots


def _write_frames(fig, out: Path, suffix: str, play_fps: float, dpi: float, n: int,
                  draw_frame, progress: bool = False) -> None:
    """Draw the ``n`` frames one by one into a GIF or MP4 written atomically at ``out``."""
    import matplotlib as mpl
    from matplotlib import animation as anim
    from tqdm import tqdm

    from ..io import atomic_path

    if suffix == ".gif":
        writer = _gif_writer(anim.PillowWriter)(fps=play_fps)
    else:
        # ffmpeg reads the rate as text: a fraction keeps 30000/1001 or 120/7 exact, where
        # str(float) would hand it 17 digits to round
        writer = anim.FFMpegWriter(
            fps=_rate_fraction(play_fps), codec="libx264", extra_args=["-pix_fmt", "yuv420p"]
        )
    with atomic_path(out, suffix=f".tmp{suffix}") as tmp, mpl.rc_context({"savefig.bbox": None}):
        # (a 'tight' bbox would change the frame size)
        writer.setup(fig, str(tmp), dpi)
        try:
            for i in tqdm(range(n), desc="drawing", unit="frame", disable=not progress,
                          delay=1.0, leave=False):
                draw_frame(i)
                writer.grab_frame()
        except BaseException:
            with contextlib.suppress(
                Exception
            ):  # stop the encoder; atomic_path removes the partial file
                writer.finish()
            raise
        writer.finish()


def gif_delays(n: int, fps: float) -> list[int]:
    """Per-frame delays in milliseconds, whole centiseconds, that average to ``1 / fps``.

    A GIF stores each frame's delay in centiseconds, so 30 fps cannot be one delay: 3 cs
    plays 10 % fast, 4 cs 17 % slow.  Frame ``k`` is shown from ``round(100 k / fps)`` cs,
    so the delays alternate (3, 4, 3, 3, 4, 3, ... at 30 fps) and frame ``k`` is never
    more than half a centisecond from its time.  Browsers show a delay under 2 cs as
    10 cs, so a GIF cannot play faster than 50 frames per second: a delay is at least
    2 cs (a rate above 50 fps is played at 50; write an MP4 for those).

    Parameters
    ----------
    n : int
        Number of frames.
    fps : float
        Playback rate in frames per second.

    Returns
    -------
    list of int
        ``n`` delays in milliseconds, each a multiple of 10.

    Examples
    --------
    >>> gif_delays(6, 30)
    [30, 40, 30, 30, 40, 30]
    >>> sum(gif_delays(63, 30))  # 63 frames at 30 fps: 2.1 s
    2100
    """
    if not np.isfinite(fps) or fps <= 0:
        raise ParameterError(f"fps must be a positive number, got {fps!r}")
    rate = min(float(fps), 50.0)
    ends = np.round(np.arange(1, n + 1) * 100.0 / rate + 1e-9).astype(int)
    cs = np.diff(ends, prepend=0)
    return [int(10 * max(2, c)) for c in cs]


def _rate_fraction(fps: float):
    """``fps`` as a fraction with a denominator of at most 1001 (30000/1001, 120/7)."""
    from fractions import Fraction

    return Fraction(float(fps)).limit_denominator(1001)


def _gif_writer(base):
    """matplotlib's PillowWriter, saving with :func:`gif_delays` instead of one delay.

    matplotlib saves every frame with ``int(1000 / fps)`` ms, which the GIF stores as
    whole centiseconds (33 ms -> 3 cs): a 30 fps motion played 10 % fast.
    """

    class GifWriter(base):
        def finish(self):
            frames = self._frames
            frames[0].save(self.outfile, save_all=True, append_images=frames[1:],
                           duration=gif_delays(len(frames), self.fps), loop=0)

    return GifWriter


def _grid_spacing(body: float) -> float:
    """A round floor-grid spacing of about a third of the body size."""
    target = max(body / 3.0, 1e-9)
    mag = 10 ** np.floor(np.log10(target))
    for m in (1, 2, 5, 10):
        if m * mag >= target:
            return float(m * mag)
    return float(10 * mag)
