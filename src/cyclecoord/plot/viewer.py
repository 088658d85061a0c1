"""Interactive 3-D viewer: one self-contained HTML page (plotly) or an inline Jupyter figure.

:func:`skeleton_figure` draws one or more motions as stick figures animated over their
frames, with play/pause buttons and a frame slider.  For a cycle (a loop such as the
typical cycle ``extract`` writes) a phase dial beside the figure shows the phase of the
current frame and the seam (phase 0, where the last frame joins the first), and the
slider labels say which frame is the seam.  Planted foot points
(:func:`~cyclecoord.quality.contacts.foot_contacts`) are marked and the estimated floor
is drawn.  :func:`write_viewer` writes the page with plotly.js inlined, so it opens with
no network; in Jupyter the figure itself displays inline.

Coordinates: motions are drawn as :func:`cyclecoord.rig.normalize_rig` gives them (every
frame kept): a static root is left out and a Z-up rig is turned y up.  Their y axis is
then up; plotly's scene has z up, so the page shows ``(x, -z, y)`` (a rotation, not a
mirror).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ._canvas import drawn

__all__ = ["ViewerInput", "skeleton_figure", "write_viewer"]

_COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd")
#: Frames per second the page animates at, at most (browsers redraw 3-D scenes slowly).
DEFAULT_MAX_FPS = 30.0


@dataclass(frozen=True)
class ViewerInput:
    """One motion to show.

    Attributes
    ----------
    motion : Motion
        With a skeleton.
    label : str
        Legend name.
    cycle : bool
        Whether the motion is a loop (phase ``k / T``, seam between the last frame and
        the first); it then repeats when a longer motion plays beside it.
    feet : tuple of str, optional
        Foot points whose contacts are marked (default found:
        :func:`~cyclecoord.quality.legs.find_legs`).
    """

    motion: Motion
    label: str
    cycle: bool = False
    feet: tuple[str, ...] | None = None


def _to_plot(p: np.ndarray) -> np.ndarray:
    """Skeleton (x, y up, z) -> plotly scene (x, -z, y up)."""
    return np.stack([p[..., 0], -p[..., 2], p[..., 1]], axis=-1)


def _segments(pos: np.ndarray, parents: np.ndarray) -> np.ndarray:
    """Bone polyline ``(T, 3 B, 3)``: each bone's two ends then a NaN break."""
    kids = np.flatnonzero(parents >= 0)
    T = pos.shape[0]
    seg = np.full((T, 3 * kids.size, 3), np.nan)
    seg[:, 0::3] = pos[:, parents[kids]]
    seg[:, 1::3] = pos[:, kids]
    return seg


def _prepare(item: ViewerInput, offset: float, contacts: bool, center: bool):
    m = item.motion
    if m.skeleton is None:
        raise ParameterError(
            f"{item.label}: the viewer needs a skeleton (forward kinematics); this motion has none"
        )
    bad = np.flatnonzero(~np.isfinite(m.frames).all(axis=1))
    if bad.size:
        raise ParameterError(
            f"{item.label}: frame {m.start_frame + int(bad[0])} holds NaN or infinite values"
        )
    m = drawn(m)
    fk = m.positions()
    pos = fk.positions.copy()
    if center:  # start above the origin, so motions stand side by side whatever their capture
        pos[..., [0, 2]] -= pos[0, 0, [0, 2]]
    pos[..., 0] += offset
    feet = None
    floor = float(np.quantile(pos[..., 1].min(axis=1), 0.05))
    if contacts and m.n_frames >= 2:
        from ..quality.contacts import foot_contacts

        try:
            c = foot_contacts(m, feet=item.feet)
        except ParameterError:
            c = None
        if c is not None:
            cols = [fk.names.index(f) for f in c.feet]
            feet = (_to_plot(pos[:, cols]), c.planted)
            floor = c.floor
    return _to_plot(pos), fk.parents, feet, floor


def _frame_index(k: int, n: int, cycle: bool) -> int:
    return k % n if cycle else min(k, n - 1)


def skeleton_figure(
    motions: Motion | ViewerInput | Sequence[Motion | ViewerInput],
    *,
    labels: Sequence[str] | None = None,
    cycle: bool | Sequence[bool] = False,
    contacts: bool = True,
    max_fps: float = DEFAULT_MAX_FPS,
    spacing: float | None = None,
    title: str | None = None,
):
    """An animated plotly figure of one or more motions side by side.

    Parameters
    ----------
    motions : Motion, ViewerInput or a sequence of them
        Motions with skeletons; several are placed side by side along x.
    labels : sequence of str, optional
        Legend names (default: the motions' file names).
    cycle : bool or sequence of bool
        Which motions are loops (phase dial, seam marks, repetition).
    contacts : bool
        Mark planted foot points.
    max_fps : float
        Highest animation rate; longer motions are shown every ``k``-th frame.
    spacing : float, optional
        Distance between figures along x (default: 0.6 of the first skeleton's height).
        With several motions each starts with its root above the origin before that
        shift; a single motion is shown in its own coordinates.
    title : str, optional

    Returns
    -------
    plotly.graph_objects.Figure
    """
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    items = _as_inputs(motions, labels, cycle)
    fps = items[0].motion.fps
    if not (np.isfinite(max_fps) and max_fps > 0):
        raise ParameterError(f"max_fps must be a positive number, got {max_fps!r}")
    step = max(1, int(np.ceil(fps / max_fps)))
    height = float(np.ptp(items[0].motion.positions().positions[0, :, 1])) or 1.0
    gap = 0.6 * height if spacing is None else float(spacing)
    center = len(items) > 1
    prepared = [_prepare(it, i * gap, contacts, center) for i, it in enumerate(items)]
    n_total = max(it.motion.n_frames for it in items)
    shown = list(range(0, n_total, step))
    has_cycle = any(it.cycle for it in items)
    phase_of = next((it for it in items if it.cycle), None)

    if has_cycle:
        fig = make_subplots(
            rows=1,
            cols=2,
            column_widths=[0.78, 0.22],
            specs=[[{"type": "scene"}, {"type": "xy"}]],
            subplot_titles=("", "phase"),
        )
    else:
        fig = make_subplots(rows=1, cols=1, specs=[[{"type": "scene"}]])

    def traces_at(k: int) -> list:
        return _traces_at(go, items, prepared, phase_of, k)

    first = traces_at(0)
    n_anim = len(first)
    for tr in first:
        if isinstance(tr, go.Scatter):
            fig.add_trace(tr, row=1, col=2)
        else:
            fig.add_trace(tr, row=1, col=1)
    animated = list(range(n_anim))
    if has_cycle:
        _add_dial(fig, go)
    _add_floor(fig, go, prepared)

    frames = [go.Frame(data=traces_at(k), traces=animated, name=str(k)) for k in shown]
    fig.frames = frames
    slider, buttons = _controls(shown, step, fps, phase_of)
    heading = title or " | ".join(
        f"{it.label}: {it.motion.n_frames} frames at {it.motion.fps:g} fps"
        + (" (cycle)" if it.cycle else "")
        for it in items
    )
    fig.update_layout(
        title=heading,
        sliders=[slider],
        height=650,
        updatemenus=[
            {
                "type": "buttons",
                "buttons": buttons,
                "direction": "left",
                "x": 0.0,
                "y": 0.0,
                "xanchor": "left",
                "yanchor": "top",
                "pad": {"t": 60},
            }
        ],
        legend={"x": 0.0, "y": 1.0},
        margin={"l": 10, "r": 10, "t": 60, "b": 10},
    )
    fig.layout.meta = {
        "cyclecoord": {
            "frames_shown": shown,
            "step": step,
            "fps": fps,
            "labels": [it.label for it in items],
            "cycle": [it.cycle for it in items],
        }
    }
    return fig


def _controls(shown: list, step: int, fps: float, phase_of):
    """The frame slider (seam frames labelled) and the play/pause buttons."""

    def label(k: int) -> str:
        if phase_of is None:
            return str(k)
        t = _frame_index(k, phase_of.motion.n_frames, True)
        return f"{k} seam" if t == 0 else str(k)

    duration = 1000.0 * step / fps
    play = {
        "args": [
            None,
            {
                "frame": {"duration": duration, "redraw": True},
                "fromcurrent": True,
                "transition": {"duration": 0},
                "mode": "immediate",
            },
        ],
        "label": "Play",
        "method": "animate",
    }
    pause = {
        "args": [
            [None],
            {
                "frame": {"duration": 0, "redraw": False},
                "mode": "immediate",
                "transition": {"duration": 0},
            },
        ],
        "label": "Pause",
        "method": "animate",
    }
    slider = {
        "active": 0,
        "currentvalue": {"prefix": "frame "},
        "x": 0.14,
        "len": 0.86,
        "pad": {"t": 40},
        "steps": [
            {
                "args": [
                    [str(k)],
                    {
                        "frame": {"duration": 0, "redraw": True},
                        "mode": "immediate",
                        "transition": {"duration": 0},
                    },
                ],
                "label": label(k),
                "method": "animate",
            }
            for k in shown
        ],
    }
    return slider, [play, pause]


def _traces_at(go, items, prepared, phase_of, k: int) -> list:
    """The animated traces of animation frame ``k``: bones and planted feet per motion, and
    the phase dial's marker."""
    out = []
    for it, (pos, parents, feet, _), colour in zip(items, prepared, _COLOURS * 4):
        t = _frame_index(k, it.motion.n_frames, it.cycle)
        seg = _segments(pos[t : t + 1], parents)[0]
        out.append(
            go.Scatter3d(
                x=seg[:, 0],
                y=seg[:, 1],
                z=seg[:, 2],
                mode="lines+markers",
                line={"color": colour, "width": 6},
                marker={"size": 2.5, "color": colour},
                name=it.label,
                legendgroup=it.label,
                hoverinfo="skip",
            )
        )
        if feet is not None:
            fpos, planted = feet
            pts = fpos[t][planted[t]]
            out.append(
                go.Scatter3d(
                    x=pts[:, 0],
                    y=pts[:, 1],
                    z=pts[:, 2],
                    mode="markers",
                    marker={"size": 6, "color": "#ff7f0e", "symbol": "square"},
                    name=f"{it.label}: planted feet",
                    legendgroup=it.label,
                    showlegend=k == 0,
                    hoverinfo="skip",
                )
            )
    if phase_of is not None:
        n = phase_of.motion.n_frames
        ph = _frame_index(k, n, True) / n
        out.append(
            go.Scatter(
                x=[np.sin(2 * np.pi * ph)],
                y=[np.cos(2 * np.pi * ph)],
                mode="markers+text",
                marker={"size": 14, "color": _COLOURS[items.index(phase_of) % 4]},
                text=[f"{ph:.2f}"],
                textposition="bottom center",
                showlegend=False,
                hoverinfo="skip",
            )
        )
    return out


def _add_dial(fig, go) -> None:
    """The phase dial's circle and seam tick (static traces in the second panel)."""
    a = np.linspace(0, 2 * np.pi, 121)
    fig.add_trace(
        go.Scatter(
            x=np.sin(a),
            y=np.cos(a),
            mode="lines",
            line={"color": "#999"},
            showlegend=False,
            hoverinfo="skip",
        ),
        row=1,
        col=2,
    )
    fig.add_trace(
        go.Scatter(
            x=[0, 0],
            y=[0.8, 1.2],
            mode="lines+text",
            line={"color": "black", "width": 3},
            text=["", "seam"],
            textposition="top center",
            showlegend=False,
            hoverinfo="skip",
        ),
        row=1,
        col=2,
    )
    fig.update_xaxes(range=[-1.5, 1.5], visible=False, row=1, col=2)
    fig.update_yaxes(range=[-1.5, 1.5], visible=False, scaleanchor="x", row=1, col=2)


def _add_floor(fig, go, prepared) -> None:
    """The floor plane and fixed scene ranges covering every frame of every motion."""
    allpos = np.concatenate([p[0].reshape(-1, 3) for p in prepared])
    lo, hi = np.nanmin(allpos, axis=0), np.nanmax(allpos, axis=0)
    extent = float(np.max(hi - lo))
    if not np.isfinite(extent) or extent <= 0:  # one joint that never moves: a unit box
        extent = max(1.0, float(np.max(np.abs(lo))) * 1e-3)
    pad = 0.1 * extent
    lo, hi = lo - pad, hi + pad
    floor = min(p[3] for p in prepared)
    lo[2] = min(lo[2], floor)
    hi[2] = max(hi[2], floor + pad)
    fig.add_trace(
        go.Mesh3d(
            x=[lo[0], hi[0], hi[0], lo[0]],
            y=[lo[1], lo[1], hi[1], hi[1]],
            z=[floor] * 4,
            i=[0, 0],
            j=[1, 2],
            k=[2, 3],
            color="#cccccc",
            opacity=0.35,
            name="floor",
            hoverinfo="skip",
            showlegend=False,
        ),
        row=1,
        col=1,
    )
    span = hi - lo
    fig.update_scenes(
        xaxis={"range": [lo[0], hi[0]], "title": "x"},
        yaxis={"range": [lo[1], hi[1]], "title": "-z"},
        zaxis={"range": [lo[2], hi[2]], "title": "y (up)"},
        aspectmode="manual",
        aspectratio={
            "x": span[0] / span.max(),
            "y": span[1] / span.max(),
            "z": span[2] / span.max(),
        },
        camera={"eye": {"x": 1.6, "y": -1.6, "z": 0.6}},
    )


def _as_inputs(motions, labels, cycle) -> list[ViewerInput]:
    if isinstance(motions, (Motion, ViewerInput)):
        motions = [motions]
    motions = list(motions)
    if not motions:
        raise ParameterError("nothing to view: give at least one motion")
    if labels is not None and len(labels) != len(motions):
        raise ParameterError(f"{len(labels)} labels for {len(motions)} motions")
    cycles = [cycle] * len(motions) if isinstance(cycle, bool) else list(cycle)
    if len(cycles) != len(motions):
        raise ParameterError(f"{len(cycles)} cycle flags for {len(motions)} motions")
    out = []
    for i, m in enumerate(motions):
        if isinstance(m, ViewerInput):
            out.append(m)
            continue
        name = (
            labels[i]
            if labels is not None
            else (Path(m.source).name if m.source else f"motion {i + 1}")
        )
        out.append(ViewerInput(m, name, bool(cycles[i])))
    return out


def write_viewer(figure, path: str | os.PathLike[str], post_script: str | None = None) -> Path:
    """Write ``figure`` as one self-contained HTML page (plotly.js inlined), atomically.

    ``post_script`` is JavaScript run once the figure is drawn (``{plot_id}`` names its
    element), as in :meth:`plotly.graph_objects.Figure.to_html`.
    """
    from ..io import atomic_write

    p = Path(path)
    if p.suffix.lower() not in (".html", ".htm"):
        raise ParameterError(
            f"{p}: the viewer writes an .html page, got {p.suffix or '(no suffix)'!r}"
        )
    html = figure.to_html(
        include_plotlyjs=True,
        full_html=True,
        auto_play=False,
        post_script=post_script,
        config={"displaylogo": False, "responsive": True},
    )
    with atomic_write(p, "w") as fh:
        fh.write(html)
    return p
