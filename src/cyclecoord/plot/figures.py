"""Figures of the periodic pipeline and stick-figure animations of captures (matplotlib).

Every figure function draws into the axes or figure it is given, or into a new pyplot
figure, and returns the :class:`~matplotlib.figure.Figure`; none of them calls
``plt.show()``.  :func:`save_figures` and :func:`render` build their figures without
pyplot (Agg canvas), so they work headless and leave no open figures behind.

>>> import cyclecoord as cc
>>> from cyclecoord import plot
>>> result = cc.extract(cc.datasets.example_capture().motion)
>>> fig = plot.plot_barcode(result.barcode, result.selection)      # doctest: +SKIP
>>> plot.save_figures(result, "figures")                         # doctest: +SKIP
>>> plot.render(result.motion, "walk.gif", other=result.cycle)   # doctest: +SKIP
"""

from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping, Sequence

import numpy as np

from ..errors import ParameterError
from ._canvas import detached_figure, new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..periodic.barcode import Barcode, BarSelection
    from ..motion import Motion
    from ..periodic.pipeline import ExtractionResult

__all__ = [
    "plot_barcode",
    "plot_pca",
    "plot_density",
    "plot_coordinate",
    "plot_channels",
    "plot_windows",
    "render",
    "save_figures",
    "FIGURE_NAMES",
    "CYCLIC_CMAP",
]

#: Colormap for circular coordinates: equal colours at 0 and 1.
CYCLIC_CMAP = "twilight_shifted"
#: Files written by :func:`save_figures`, in order.
FIGURE_NAMES = ("barcode.png", "pca.png", "density.png", "coordinate.png", "channels.png")

_HIGHLIGHT = "#d62728"
_BAR = "#1f4e79"
_SCALE = "#ff7f0e"
_ORIGINAL = "#1f77b4"
_CYCLE = "#d62728"


# ------------------------------------------------------------------ helpers
def _check_result(result: Any, what: str) -> "ExtractionResult":
    from ..periodic.pipeline import ExtractionResult, PartialExtraction

    if isinstance(result, PartialExtraction):
        raise ParameterError(
            f"{what} needs a complete extraction; this partial result has no circular "
            f"coordinate (no periodic motion was found: {result.reason})"
        )
    if not isinstance(result, ExtractionResult):
        raise ParameterError(
            f"{what} takes an ExtractionResult (from cyclecoord.extract), got "
            f"{type(result).__name__}"
        )
    if result.coordinate is None or result.typical is None:
        raise ParameterError(
            f"{what} needs a complete extraction; this result has no circular coordinate "
            "(no periodic motion was found)"
        )
    return result


# ------------------------------------------------------------------ barcode
def plot_barcode(
    barcode: "Barcode",
    selection: "BarSelection | None" = None,
    *,
    ax: "Axes | Sequence[Axes] | None" = None,
    fig: "Figure | None" = None,
    max_h0: int | None = None,
) -> "Figure":
    """Draw the H0 and H1 bars of a barcode, the chosen class and scale highlighted.

    Bars are horizontal segments from birth to death (analysed-space units), H1 bars
    sorted by decreasing persistence from the top.  A bar alive at the threshold is drawn
    up to the threshold and ends in an arrow head.  The selected H1 bar is drawn thicker
    in red and the scale the cocycle is read at is a dashed vertical line; the threshold
    is a dotted grey line.

    Parameters
    ----------
    barcode : Barcode
    selection : BarSelection, optional
        The chosen class (``result.selection``).
    ax : Axes or pair of Axes, optional
        Two axes ``(H0, H1)``, or one axes holding both (H1 above H0).  By default a new
        figure with two stacked panels.
    fig : Figure, optional
        Figure to draw the two panels into (ignored when ``ax`` is given).
    max_h0 : int, optional
        Draw only the ``max_h0`` longest H0 bars (all by default).

    Returns
    -------
    Figure
        Bars are :class:`~matplotlib.collections.LineCollection` artists labelled
        ``"H0"`` and ``"H1"`` with one segment per bar; the highlighted bar and scale
        line are labelled ``"selected class"`` and ``"scale"``.
    """
    from matplotlib.collections import LineCollection

    from ..periodic.barcode import Barcode

    if not isinstance(barcode, Barcode):
        raise ParameterError(f"plot_barcode takes a Barcode, got {type(barcode).__name__}")
    if max_h0 is not None and (not isinstance(max_h0, (int, np.integer)) or max_h0 < 1):
        raise ParameterError(f"max_h0 must be a whole number >= 1, got {max_h0!r}")
    thr = float(barcode.threshold)
    h0 = np.asarray(barcode.h0, dtype=float).reshape(-1, 2)
    h1 = np.asarray(barcode.h1, dtype=float).reshape(-1, 2)
    if max_h0 is not None and len(h0) > max_h0:
        order = np.argsort(-barcode.persistence(0), kind="stable")[:max_h0]
        h0 = h0[np.sort(order)]
    # H0 in decreasing death order (the infinite bar on top), H1 as stored (by persistence)
    h0 = h0[np.argsort(-np.minimum(h0[:, 1], thr), kind="stable")] if len(h0) else h0

    if ax is None:
        fig = new_figure((7.0, 5.0), fig)
        n0, n1 = max(len(h0), 1), max(len(h1), 1)
        w0 = float(np.clip(np.log1p(n0), 1.0, 3.0))
        w1 = float(np.clip(np.log1p(n1), 1.0, 3.0))
        ax0, ax1 = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [w0, w1]})
        shared = False
    elif isinstance(ax, (list, tuple)):
        if len(ax) != 2:
            raise ParameterError(f"ax must be one Axes or a pair (H0, H1), got {len(ax)} axes")
        ax0, ax1 = ax
        fig = ax0.figure
        shared = False
    else:
        ax0 = ax1 = ax
        fig = ax.figure
        shared = True

    sel_index = None if selection is None else int(selection.index)
    n0 = len(h0)
    offset1 = n0 + 1 if shared else 0  # rows of H1 above H0 on a shared axes

    def draw(a: "Axes", bars: np.ndarray, label: str, base: int, highlight: int | None) -> None:
        n = len(bars)
        if n == 0:
            a.text(
                0.5,
                0.5,
                f"no {label} bars",
                transform=a.transAxes,
                ha="center",
                va="center",
                color="0.4",
            )
            return
        ends = np.minimum(bars[:, 1], thr)
        rows = base + (n - 1 - np.arange(n))  # first bar on top
        segs = np.stack([np.c_[bars[:, 0], rows], np.c_[ends, rows]], axis=1)
        colors = np.tile(np.array([[0.12, 0.31, 0.47, 1.0]]), (n, 1))
        widths = np.full(n, 1.2 if n > 60 else 2.5)
        if highlight is not None and 0 <= highlight < n:
            from matplotlib.colors import to_rgba

            colors[highlight] = to_rgba(_HIGHLIGHT)
            widths[highlight] = max(4.0, widths[highlight] * 2)
        lc = LineCollection(segs, colors=colors, linewidths=widths, label=label, capstyle="butt")
        a.add_collection(lc)
        inf = ~np.isfinite(bars[:, 1])
        if inf.any():
            a.plot(np.full(inf.sum(), thr), rows[inf], linestyle="none", marker=">", markersize=6,
                   color=_BAR, label=f"{label} alive at threshold")
        if highlight is not None and 0 <= highlight < n:
            b, d = bars[highlight]
            a.plot(
                [b, min(d, thr)],
                [rows[highlight]] * 2,
                color=_HIGHLIGHT,
                linewidth=widths[highlight],
                solid_capstyle="butt",
                label="selected class",
                zorder=3,
            )

    draw(ax0, h0, "H0", 0, None)
    draw(ax1, h1, "H1", offset1, sel_index)
    if shared:
        ax0.set_ylim(-1, n0 + len(h1) + 1)
    else:
        ax0.set_ylim(-1, max(n0, 1))
        ax1.set_ylim(-1, max(len(h1), 1))
    for a in {id(ax0): ax0, id(ax1): ax1}.values():
        a.axvline(thr, color="0.5", linestyle=":", linewidth=1, label="threshold")
        if selection is not None:
            a.axvline(
                float(selection.scale), color=_SCALE, linestyle="--", linewidth=1.5, label="scale"
            )
        a.set_xlim(0, thr * 1.04)
        a.set_yticks([])
    if shared:
        ax0.axhline(n0 + 0.5, color="0.7", linewidth=0.8)
        ax0.set_ylabel("H0 (below) / H1 (above)")
    else:
        ax0.set_ylabel(f"H0 ({len(barcode.h0)})")
        ax1.set_ylabel(f"H1 ({len(barcode.h1)})")
    ax1.set_xlabel("filtration scale (analysed-space units)")
    title = f"barcode up to {thr:.3g} (Z/{barcode.prime})"
    if selection is not None:
        d = "inf" if not np.isfinite(selection.death) else f"{selection.death:.3g}"
        title += f"; class #{selection.index} [{selection.birth:.3g}, {d}) at {selection.scale:.3g}"
    ax0.set_title(title, fontsize=10)
    handles, labels = ax1.get_legend_handles_labels()
    keep = [(h, lab) for h, lab in zip(handles, labels) if lab in ("selected class", "scale")]
    if keep:
        ax1.legend(*zip(*keep), loc="lower right", fontsize=8)
    return fig


# ---------------------------------------------------------------------- PCA
@dataclass(frozen=True)
class _Projection:
    mean: np.ndarray
    components: np.ndarray  # (k, D)
    explained: np.ndarray  # fraction of variance per component

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return (np.asarray(x, dtype=float) - self.mean) @ self.components.T


def _pca(x: np.ndarray, k: int) -> _Projection:
    x = np.asarray(x, dtype=float)
    mean = x.mean(axis=0)
    _, s, vt = np.linalg.svd(x - mean, full_matrices=False)
    var = s**2
    total = var.sum() if var.sum() > 0 else 1.0
    comps = vt[:k]
    # sign convention: the largest loading of each component positive (stable pictures)
    signs = np.sign(comps[np.arange(len(comps)), np.argmax(np.abs(comps), axis=1)])
    signs[signs == 0] = 1.0
    comps = comps * signs[:, None]
    if comps.shape[0] < k:  # fewer samples/dims than asked: pad with zero components
        comps = np.vstack([comps, np.zeros((k - comps.shape[0], x.shape[1]))])
    explained = np.zeros(k)
    explained[: min(k, var.size)] = (var / total)[:k]
    return _Projection(mean=mean, components=comps, explained=explained)


def plot_pca(
    result: "ExtractionResult",
    dims: int = 2,
    *,
    ax: "Axes | None" = None,
    fig: "Figure | None" = None,
    cmap: str = CYCLIC_CMAP,
    trajectory: bool = True,
) -> "Figure":
    """Poses in their first principal components, coloured by circular coordinate.

    The frames (``result.prepared.poses``: root channels as per-frame differences) are
    projected onto their first ``dims`` principal components and drawn as points
    coloured by the circular coordinate with a cyclic colormap; the typical cycle
    (``result.typical.frames``, same projection) is drawn through them as a closed black
    line (paper Figs. 3-5).

    Parameters
    ----------
    result : ExtractionResult
    dims : {2, 3}
    ax : Axes, optional
        Must be a 3-D axes when ``dims == 3``.
    fig : Figure, optional
    cmap : str
        A cyclic matplotlib colormap (default ``"twilight_shifted"``).
    trajectory : bool, default True
        Join consecutive frames with a faint line.

    Returns
    -------
    Figure
        The scatter is labelled ``"frames"``, the cycle line ``"typical cycle"``.
    """
    res = _check_result(result, "plot_pca")
    if dims not in (2, 3):
        raise ParameterError(f"dims must be 2 or 3, got {dims!r}")
    poses = np.asarray(res.prepared.poses, dtype=float)
    proj = _pca(poses, dims)
    pts = proj(poses)
    cyc = proj(res.typical.frames)
    cyc = np.vstack([cyc, cyc[:1]])
    if ax is None:
        fig = new_figure((6.0, 5.0), fig)
        ax = fig.add_subplot(projection="3d" if dims == 3 else None)
    else:
        fig = ax.figure
        if dims == 3 and getattr(ax, "name", "") != "3d":
            raise ParameterError("plot_pca(dims=3) needs a 3-D axes (projection='3d')")
        if dims == 2 and getattr(ax, "name", "") == "3d":
            raise ParameterError("plot_pca(dims=2) needs a 2-D axes, got a 3-D one")
    coords = [pts[:, i] for i in range(dims)]
    if trajectory:
        ax.plot(*coords, color="0.75", linewidth=0.6, zorder=1, label="trajectory")
    sc = ax.scatter(
        *coords,
        c=res.coordinate,
        cmap=cmap,
        vmin=0.0,
        vmax=1.0,
        s=12,
        zorder=2,
        label="frames",
        edgecolors="none",
    )
    ax.plot(
        *[cyc[:, i] for i in range(dims)],
        color="black",
        linewidth=2.0,
        zorder=3,
        label="typical cycle",
    )
    labels = [f"PC{i + 1} ({100 * proj.explained[i]:.0f}%)" for i in range(dims)]
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    if dims == 3:
        ax.set_zlabel(labels[2])
    else:
        ax.set_aspect("equal", adjustable="datalim")
    cb = fig.colorbar(sc, ax=ax, shrink=0.8, pad=0.1 if dims == 3 else 0.04)
    cb.set_label("circular coordinate")
    ax.set_title(f"PCA of {len(pts)} poses; typical cycle of {len(cyc) - 1} frames", fontsize=10)
    ax.legend(
        handles=[h for h in ax.get_legend_handles_labels()[0] if h.get_label() == "typical cycle"],
        loc="best",
        fontsize=8,
    )
    return fig


# ------------------------------------------------------------------ density
def plot_density(
    result: "ExtractionResult",
    *,
    ax: "Axes | None" = None,
    fig: "Figure | None" = None,
    bins: int = 40,
    show_cycle: bool = True,
) -> "Figure":
    """Histogram of the circular coordinate with the fitted periodic density over it.

    Parameters
    ----------
    result : ExtractionResult
    ax, fig : optional
    bins : int, default 40
        Histogram bins on ``[0, 1)``.
    show_cycle : bool, default True
        Mark the phases of the typical cycle's frames as ticks along the bottom: they are
        dense where the motion is slow (the density is high there).

    Returns
    -------
    Figure
        The histogram bars are the axes' patches; the density line is labelled
        ``"periodic density"``.
    """
    res = _check_result(result, "plot_density")
    if not isinstance(bins, (int, np.integer)) or bins < 2:
        raise ParameterError(f"bins must be a whole number >= 2, got {bins!r}")
    if ax is None:
        fig = new_figure((6.0, 3.5), fig)
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    theta = np.asarray(res.coordinate, dtype=float)
    ax.hist(
        theta,
        bins=int(bins),
        range=(0.0, 1.0),
        density=True,
        color="#9ecae1",
        edgecolor="white",
        label=f"{len(theta)} frames",
    )
    x = np.linspace(0.0, 1.0, 501)
    pdf = res.density.pdf(np.mod(x, 1.0))
    ax.plot(x, pdf, color=_HIGHLIGHT, linewidth=2.0, label="periodic density")
    if show_cycle:
        ph = np.asarray(res.typical.phases, dtype=float)
        ax.plot(ph, np.zeros_like(ph), linestyle="none", marker="|", markersize=8, color="black",
                label="cycle frames", clip_on=False)
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("circular coordinate")
    ax.set_ylabel("density")
    ax.set_title("coordinate histogram and periodic mixture density", fontsize=10)
    ax.legend(loc="upper right", fontsize=8)
    return fig


# --------------------------------------------------------------- coordinate
def _coordinate_series(
    data: Any, start_frame: int | None
) -> tuple[list[tuple[str, np.ndarray]], int]:
    from ..periodic.pipeline import ExtractionResult, PartialExtraction

    if isinstance(data, PartialExtraction):
        raise ParameterError(
            f"this extraction has no circular coordinate (no periodic motion was found: "
            f"{data.reason})"
        )
    if isinstance(data, ExtractionResult):
        start = data.motion.start_frame if start_frame is None else start_frame
        series = [("coordinate", np.asarray(data.coordinate, dtype=float))]
        phase = getattr(data, "phase", None)
        if phase is not None and np.isfinite(phase).any():
            # the phase the cycle is averaged in: the coordinate re-timed to the capture's pace
            series.append(("phase (re-timed)", np.asarray(phase, dtype=float)))
        return series, int(start)
    if isinstance(data, (str, bytes)):
        items = None
    elif isinstance(data, Mapping):
        items = [(str(k), v) for k, v in data.items()]
    elif isinstance(data, np.ndarray) and data.ndim == 2:
        items = [(f"coordinate {i}", row) for i, row in enumerate(data)]
    elif isinstance(data, np.ndarray) or (
        isinstance(data, Sequence) and data and np.isscalar(data[0])
    ):
        items = [("coordinate", data)]
    elif isinstance(data, Sequence):
        items = [(f"coordinate {i}", v) for i, v in enumerate(data)]
    else:
        items = None
    if items is None:
        raise ParameterError(
            "plot_coordinate takes an ExtractionResult, an array of coordinates, a "
            f"list of arrays or a dict of name -> array, got {type(data).__name__}"
        )
    out = []
    for name, v in items:
        try:
            arr = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"coordinate {name!r} is not an array of numbers") from None
        if arr.ndim != 1 or arr.size == 0:
            raise ParameterError(
                f"coordinate {name!r} must be a non-empty 1-D array, got shape {arr.shape}"
            )
        out.append((name, arr))
    if not out:
        raise ParameterError("no coordinates to plot")
    return out, int(start_frame or 0)


def _break_wraps(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices and values with NaN inserted where the coordinate wraps (jump > 1/2)."""
    x = np.arange(y.size, dtype=float)
    jumps = np.flatnonzero(np.abs(np.diff(y)) > 0.5) + 1
    return np.insert(x, jumps, np.nan), np.insert(y, jumps, np.nan)


def plot_coordinate(
    data: Any,
    segments: Sequence[tuple[int, int, str | None]] | None = None,
    *,
    ax: "Axes | None" = None,
    fig: "Figure | None" = None,
    start_frame: int | None = None,
    cmap: str = CYCLIC_CMAP,
) -> "Figure":
    """Circular coordinate(s) over time, with optional shaded frame ranges.

    Parameters
    ----------
    data : ExtractionResult, array (T,), array (n, T), list of arrays or dict name -> array
        One or several coordinates in ``[0, 1)`` per frame (NaN where undefined).  Several
        coordinates are drawn in stacked strips (paper Figs. 8-12).
    segments : list of (start, stop, label), optional
        Half-open frame ranges to shade (same label, same colour), e.g. detected motions
        or :attr:`cyclecoord.datasets.SyntheticCapture.boundaries`.  In the same frame
        numbers as the x axis.
    ax, fig : optional
    start_frame : int, optional
        Frame number of the first value (default: the result's ``motion.start_frame``,
        else 0).
    cmap : str
        Cyclic colormap colouring the points by value.

    Returns
    -------
    Figure
        One line per coordinate labelled with its name; one shaded span per segment.
    """
    series, start = _coordinate_series(data, start_frame)
    if ax is None:
        fig = new_figure((8.0, 1.2 + 1.3 * len(series)), fig)
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    n = len(series)
    gap = 1.25
    longest = 0
    for i, (name, y) in enumerate(series):
        base = (n - 1 - i) * gap
        x, yy = _break_wraps(y)
        ax.plot(x + start, yy + base, color="0.35", linewidth=0.8, label=name)
        ok = np.isfinite(y)
        ax.scatter(
            np.flatnonzero(ok) + start,
            y[ok] + base,
            c=y[ok],
            cmap=cmap,
            vmin=0,
            vmax=1,
            s=6,
            zorder=3,
            edgecolors="none",
        )
        longest = max(longest, y.size)
    if n > 1:
        ax.set_yticks([(n - 1 - i) * gap + 0.5 for i in range(n)], [name for name, _ in series])
        ax.set_ylim(-0.1, (n - 1) * gap + 1.1)
    else:
        ax.set_ylim(-0.05, 1.05)
        ax.set_ylabel(series[0][0])
    if segments:
        import matplotlib as mpl

        palette = mpl.colormaps["tab10"]
        colour_of: dict[str, Any] = {}
        for seg in segments:
            try:
                a, b = int(seg[0]), int(seg[1])
                label = None if len(seg) < 3 or seg[2] is None else str(seg[2])
            except (TypeError, ValueError, IndexError):
                raise ParameterError(
                    f"segments must be (start, stop, label) tuples, got {seg!r}"
                ) from None
            if b <= a:
                raise ParameterError(f"segment {seg!r} is empty: stop must exceed start")
            key = label if label is not None else f"#{len(colour_of)}"
            if key not in colour_of:
                colour_of[key] = palette(len(colour_of) % 10)
            ax.axvspan(a - 0.5, b - 0.5, color=colour_of[key], alpha=0.18, linewidth=0, label=label)
            if label:
                ax.text(
                    (a + b - 1) / 2,
                    1.0,
                    label,
                    transform=ax.get_xaxis_transform(),
                    ha="center",
                    va="bottom",
                    fontsize=8,
                    color=colour_of[key],
                    clip_on=False,
                )
    ax.set_xlim(start - 0.5, start + longest - 0.5)
    ax.set_xlabel("frame")
    ax.set_title("circular coordinate per frame", fontsize=10, pad=14 if segments else 6)
    return fig


def plot_windows(result: Any, *, ax: "Axes | None" = None, fig: "Figure | None" = None) -> "Figure":
    """The windowed stage of :func:`cyclecoord.periodic.detection.detect`: every window as a bar.

    One row per window length; each window is a bar over its frames, coloured by the
    motion it joined (the colours of ``plot_coordinate``'s segments, ``motion k`` ->
    ``Ck``), grey when it loops but joined no motion, pale when its barcode showed no
    clear loop.

    Parameters
    ----------
    result : DetectionResult
        With windows (``method`` ``"auto"`` or ``"windows"``).
    ax, fig : optional

    Returns
    -------
    Figure
    """
    windows = getattr(result, "windows", None)
    motion = getattr(result, "motion", None)
    if motion is None or windows is None:
        raise ParameterError(f"plot_windows() takes a DetectionResult, got {type(result).__name__}")
    if not windows:
        raise ParameterError("the detection ran no windows (method='global'); nothing to draw")
    if ax is None:
        fig = new_figure((9.0, 2.6), fig)
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    lengths = sorted({w.stop - w.start for w in windows})
    start = motion.start_frame
    for w in windows:
        row = lengths.index(w.stop - w.start)
        colour = f"C{w.motion % 10}" if w.motion >= 0 else ("0.6" if w.looping else "0.92")
        ax.broken_barh(
            [(start + w.start - 0.5, w.stop - w.start)],
            (row + 0.15, 0.7),
            facecolor=colour,
            alpha=0.35,
            edgecolor="none",
        )
    ax.set_yticks(
        [r + 0.5 for r in range(len(lengths))], [f"{n / motion.fps:.3g} s" for n in lengths]
    )
    ax.set_ylim(0, len(lengths))
    ax.set_xlim(start - 0.5, start + motion.n_frames - 0.5)
    ax.set_xlabel("frame")
    ax.set_ylabel("window")
    ax.set_title(
        "windows: coloured by motion, grey = loops but no motion, pale = no clear loop", fontsize=10
    )
    return fig


# ----------------------------------------------------------------- channels
def _resolve_channels(
    motion: "Motion", channels: Any, exclude: set[int], default_count: int
) -> list[int]:
    if channels is None or (isinstance(channels, str) and channels == "all"):
        cols = [i for i in range(motion.n_channels) if i not in exclude]
        if not cols:
            cols = list(range(motion.n_channels))
        if channels is None:
            var = motion.frames[:, cols].var(axis=0)
            order = np.argsort(-var, kind="stable")[:default_count]
            cols = sorted(cols[i] for i in order)
        return cols
    single_pair = (
        isinstance(channels, tuple) and len(channels) == 2
        and all(isinstance(x, str) and "." not in x for x in channels)
    )
    if isinstance(channels, (str, int, np.integer)) or single_pair:
        channels = [channels]
    cols = []
    for c in channels:
        if isinstance(c, (int, np.integer)):
            if not 0 <= int(c) < motion.n_channels:
                raise ParameterError(
                    f"channel index {c} out of range for {motion.n_channels} channels"
                )
            cols.append(int(c))
            continue
        if isinstance(c, str):
            if "." not in c:
                raise ParameterError(
                    f"channel names look like 'joint.dof' (e.g. 'lfemur.rx'), got {c!r}"
                )
            j, d = c.rsplit(".", 1)
        else:
            try:
                j, d = c
            except (TypeError, ValueError):
                raise ParameterError(
                    f"a channel is 'joint.dof', (joint, dof) or a column index, got {c!r}"
                ) from None
        try:
            cols.append(motion.channel_index(str(j), str(d)))
        except KeyError:
            raise ParameterError(f"no channel {j}.{d} in this motion") from None
    return cols


def _best_offset(motion: "Motion", cycle: "Motion", root: set[int]) -> int:
    """Cycle frame that best matches the clip's first frame, judged over one period.

    The looped cycle is compared with the clip's first ``P`` frames at every offset
    (non-root channels, angle differences wrapped) and the closest offset is returned;
    a phase lookup would be ambiguous where the coordinate plateaus (slow poses).
    """
    cols = [i for i in range(motion.n_channels) if i not in root] or list(range(motion.n_channels))
    ccols = [cycle.channel_index(*motion.channels[c]) for c in cols]
    P = cycle.n_frames
    n = min(P, motion.n_frames)
    a = motion.frames[:n, cols]
    c = np.asarray(cycle.frames[:, ccols], dtype=float)
    rot = np.array([motion.channels[i][1].startswith("r") for i in cols])
    costs = np.empty(P)
    for j in range(P):
        d = a - c[(j + np.arange(n)) % P]
        d[:, rot] = (d[:, rot] + 180.0) % 360.0 - 180.0
        costs[j] = float(np.mean(d**2))
    return int(np.argmin(costs))


def _cycle_frames_at_phase(res: Any, s0: int, n: int, P: int) -> np.ndarray | None:
    """Cycle frame index at the capture's phase of frames ``s0 .. s0 + n - 1`` (-1 where a
    frame has no phase), or None when the result has no capture-timed phase."""
    phase = getattr(res, "phase", None)
    phases = np.asarray(getattr(res.typical, "phases", []), dtype=float)
    if phase is None or phases.size != P or res.parameters.get("timing", "capture") != "capture":
        return None
    seg = np.asarray(phase, dtype=float)[s0 : s0 + n]
    ok = np.isfinite(seg)
    if not ok.any():
        return None
    k = np.full(seg.size, -1)
    k[ok] = np.mod(np.round((seg[ok] - phases[0]) * P).astype(int), P)
    return k


def plot_channels(
    result: "ExtractionResult",
    channels: Any = None,
    *,
    periods: float = 3.0,
    fig: "Figure | None" = None,
    ax: "Sequence[Axes] | None" = None,
    max_channels: int = 6,
) -> "Figure":
    """Original channels against the typical cycle over a few periods, and their jerk.

    Each frame of the clip shows the cycle's frame at that frame's phase (the capture-timed
    ``result.phase``), so the curves stay in step over repetitions of different lengths;
    frames without a phase, and results timed by the coordinate, play the cycle at its
    own constant rate from the phase of the clip's first frame (paper Fig. 6).  The right panel is
    the jerk as the console and the report give it (:func:`cyclecoord.quality.metrics.
    jerk_summary`: third derivative by 4th-order finite differences of every prepared
    channel, root as per-frame steps, norm over channels; the cycle looped so its seam
    counts), per frame over one period of each; the title gives the means over the whole
    clip and the whole cycle, ``result.jerk``.

    Parameters
    ----------
    result : ExtractionResult
    channels : None, "all", or list of "joint.dof" / (joint, dof) / column index
        Default: the ``max_channels`` non-root channels varying most in the clip.
    periods : float, default 3
        How many periods of the clip to show (capped at the clip's length).
    fig : Figure, optional
    ax : pair of Axes, optional
        ``(channels axes, jerk axes)``.
    max_channels : int, default 6

    Returns
    -------
    Figure
        Channel axes: for every channel a solid line (original) labelled
        ``"<joint>.<dof>"`` and a dashed one (cycle) labelled ``"<joint>.<dof> (cycle)"``.
        Jerk axes: lines labelled ``"original"`` and ``"cycle"``.
    """
    from ..quality.metrics import jerk

    res = _check_result(result, "plot_channels")
    if not np.isfinite(periods) or periods <= 0:
        raise ParameterError(f"periods must be a positive number, got {periods!r}")
    motion = res.motion
    cycle = res.cycle
    root = set(int(i) for i in motion.root_channels())
    cols = _resolve_channels(motion, channels, root, max_channels)
    names = [f"{motion.channels[c][0]}.{motion.channels[c][1]}" for c in cols]
    ccols = [cycle.channel_index(*motion.channels[c]) for c in cols]
    fps = motion.fps
    period = float(res.period_frames)
    # the capture from its first steady frame (a whole take's standing start is not the cycle's)
    used = getattr(res, "used_frames", None) or [(0, motion.n_frames)]
    s0 = int(used[0][0])
    n_show = int(min(motion.n_frames - s0, max(8, round(periods * period))))
    orig = motion.frames[s0 : s0 + n_show, cols]
    cyc_frames = np.asarray(cycle.frames[:, ccols], dtype=float)
    P = cyc_frames.shape[0]
    j0 = _best_offset(motion.window((s0, None)) if s0 else motion, cycle, root)
    idx = (j0 + np.arange(n_show)) % P
    at_phase = _cycle_frames_at_phase(res, s0, n_show, P)
    if at_phase is not None:
        # each frame shows the cycle's frame at its own phase: the two stay in step over
        # repetitions of different lengths (a constant rate drifts by their differences)
        idx = np.where(at_phase >= 0, at_phase, idx)
    cyc = cyc_frames[idx]
    # angles: the cycle and the clip may sit a whole turn apart; align each channel to the clip
    for k, c in enumerate(cols):
        if motion.channels[c][1].startswith("r"):
            turn = np.round((orig[0, k] - cyc[0, k]) / 360.0) * 360.0
            cyc[:, k] += turn

    if ax is None:
        fig = new_figure((11.0, 4.2), fig)
        ax_c, ax_j = fig.subplots(1, 2, gridspec_kw={"width_ratios": [2.2, 1.0]})
    else:
        if len(ax) != 2:
            raise ParameterError("ax must be a pair (channels axes, jerk axes)")
        ax_c, ax_j = ax
        fig = ax_c.figure
    import matplotlib as mpl

    palette = mpl.colormaps["tab10"] if len(cols) <= 10 else mpl.colormaps["turbo"]
    t = np.arange(n_show) + motion.start_frame + s0
    for k, name in enumerate(names):
        colour = palette(k % 10) if len(cols) <= 10 else palette(k / max(1, len(cols) - 1))
        lw = 1.4 if len(cols) <= 10 else 0.7
        ax_c.plot(t, orig[:, k], color=colour, linewidth=lw, label=name)
        ax_c.plot(t, cyc[:, k], color=colour, linewidth=lw, linestyle="--", label=f"{name} (cycle)")
    ax_c.set_xlabel("frame")
    ax_c.set_ylabel("channel value (degrees / length units)")
    ax_c.set_title(
        f"original (solid) vs cycle (dashed, at each frame's phase), {n_show / period:.1f} periods",
        fontsize=10,
    )
    if len(cols) <= 10:
        ax_c.legend(handles=[h for h in ax_c.get_lines() if not h.get_label().endswith("(cycle)")],
                    fontsize=7, loc="upper right", ncol=2)

    # jerk in the space result.jerk is measured in (one definition everywhere), one period
    n_j = int(min(motion.n_frames - s0, max(8, round(period))))
    stencil = 7
    poses = np.asarray(res.prepared.poses, dtype=float)[s0:]
    typ = np.asarray(res.typical.frames, dtype=float)
    seg_o = poses[: n_j + stencil - 1]
    jo = (
        np.linalg.norm(jerk(seg_o, fps), axis=1)[:n_j] if seg_o.shape[0] >= stencil else np.zeros(0)
    )
    Pt = typ.shape[0]
    jc_all = np.linalg.norm(jerk(typ, fps, cyclic=True), axis=1) if Pt >= stencil else np.zeros(Pt)
    jc = jc_all[(j0 * Pt // max(P, 1) + np.arange(min(n_j, Pt))) % Pt] if Pt else np.zeros(0)
    ax_j.plot(
        np.arange(jo.size) + motion.start_frame + s0,
        jo,
        color=_ORIGINAL,
        linewidth=1.2,
        label="original",
    )
    ax_j.plot(
        np.arange(jc.size) + motion.start_frame + s0, jc, color=_CYCLE, linewidth=1.2, label="cycle"
    )
    ax_j.set_xlabel("frame")
    ax_j.set_ylabel("jerk norm, all channels (units / s³)")
    jr = res.jerk
    ratio = jr["cycle"] / jr["original"] if jr.get("original", 0) > 0 else float("nan")
    ax_j.set_title(
        f"jerk: cycle {jr['cycle']:.3g} vs original {jr['original']:.3g}\n(ratio {ratio:.2f})",
        fontsize=9,
    )
    ax_j.legend(fontsize=8, loc="upper right")
    if jo.size and jc.size and min(jo.min(), jc.min()) > 0:
        ax_j.set_yscale("log")
    return fig


# ----------------------------------------------------------- save figures
def save_figures(
    result: "ExtractionResult", folder: str | os.PathLike[str], *, dpi: float = 100
) -> list[Path]:
    """Write the standard figures of an extraction as PNG files.

    Parameters
    ----------
    result : ExtractionResult
    folder : path-like
        Created (with parents) when missing.
    dpi : float, default 100

    Returns
    -------
    list of Path
        ``barcode.png, pca.png, density.png, coordinate.png, channels.png`` inside
        ``folder``; each written atomically.  For the partial result of a failed
        extraction (``NoPeriodicMotionError.result``, no coordinate) only
        ``barcode.png`` is written: the barcode shows why nothing stood clear.
    """
    from ..io import atomic_write
    from ..periodic.pipeline import ExtractionResult, PartialExtraction

    if not isinstance(result, (ExtractionResult, PartialExtraction)):
        raise ParameterError(f"save_figures takes an ExtractionResult, got {type(result).__name__}")
    complete = isinstance(result, ExtractionResult)
    if not complete and result.barcode is None:
        raise ParameterError("this partial extraction stopped before its barcode: nothing to draw")
    res = result
    out = Path(folder)
    if out.exists() and not out.is_dir():
        raise ParameterError(f"{out}: exists and is not a folder")
    out.mkdir(parents=True, exist_ok=True)
    makers = {
        "barcode.png": ((7.0, 5.0), lambda f: plot_barcode(res.barcode, res.selection, fig=f)),
        "pca.png": ((6.5, 5.0), lambda f: plot_pca(res, 2, fig=f)),
        "density.png": ((6.5, 3.5), lambda f: plot_density(res, fig=f)),
        "coordinate.png": ((9.0, 2.8), lambda f: plot_coordinate(res, fig=f)),
        "channels.png": ((11.0, 4.2), lambda f: plot_channels(res, fig=f)),
    }
    written = []
    for name in FIGURE_NAMES if complete else FIGURE_NAMES[:1]:
        size, make = makers[name]
        fig = detached_figure(size, dpi)
        make(fig)
        fig.tight_layout()
        path = out / name
        with atomic_write(path, "wb") as fh:
            fig.savefig(fh, format="png", dpi=dpi)
        written.append(path)
    return written


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
    """Left limbs blue, right limbs red, the rest dark grey (by joint-name pairs)."""
    base = [n.split("/")[0] for n in names]
    lower = {b.lower() for b in base}

    def side(b: str) -> str:
        s = b.lower()
        for lp, rp in (("left", "right"), ("l", "r")):
            if s.startswith(lp) and rp + s[len(lp):] in lower:
                return "L"
            if s.startswith(rp) and lp + s[len(rp):] in lower:
                return "R"
        return "C"

    pick = {"L": "#1f77b4", "R": "#d62728", "C": "#333333"}
    return [pick[side(b)] for b in base]


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
    jp = motion.positions()
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
) -> Path:
    """Animate a capture as a stick figure (forward kinematics) and write a GIF or MP4.

    Parameters
    ----------
    motion : Motion
        A capture with a skeleton (y up, as ASF and BVH are).
    path : path-like
        ``.gif`` (Pillow, always available) or ``.mp4`` (needs ffmpeg on the PATH).  The
        file is rendered beside the target under a temporary name and renamed, so a
        failed render leaves nothing behind.
    fps : float, optional
        Playback rate of the animation; default real time (``motion.fps / step``).
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
    from matplotlib import animation

    out = Path(path)
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
    pos_list = [p for p, _ in sampled]
    frames_used = [f for _, f in sampled]
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
    height = (top_y - floor_y) + 0.15 * body
    pad = 0.05 * body

    n_panels = len(tracks)
    if is3d:
        width_in = size * n_panels
    else:
        horiz = 2 * half
        aspect = horiz / height if view in ("side", "front") else 1.0
        width_in = size * n_panels * float(np.clip(aspect, 0.6, 2.5))
    # even pixel sizes: H.264 in yuv420p needs them, and GIFs do not mind
    px_w = max(2, 2 * int(round(width_in * dpi / 2)))
    px_h = max(2, 2 * int(round(size * dpi / 2)))
    fig = detached_figure((px_w / dpi, px_h / dpi), dpi)
    axes = []
    artists = []
    spacing = _grid_spacing(body)
    for k, tr in enumerate(tracks):
        if is3d:
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
            from mpl_toolkits.mplot3d.art3d import Line3DCollection

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
        else:
            from matplotlib.collections import LineCollection

            ax = fig.add_subplot(1, n_panels, k + 1)
            ax.set_axis_off()
            ax.set_xlim(-half, half)
            ax.set_ylim(floor_y - pad - 0.02 * body, floor_y + height)
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
        text = ax.set_title(tr.title, fontsize=9)
        axes.append(ax)
        artists.append((floor, bones, dots, text))

    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=0.92, wspace=0.02)

    def project(k: int, i: int) -> np.ndarray:
        """Drawing coordinates (P, 2 or 3) of panel ``k`` at drawn frame ``i``."""
        h = hpos[k][i] - centres[k][i]
        return np.concatenate([h, pos_list[k][i][:, 1:2]], axis=1)

    def floor_lines(centre: np.ndarray) -> list:
        """Floor grid lines inside the panel at round world positions, moving with the world."""
        offsets = []
        for c in centre:
            m = np.arange(np.ceil((c - half) / spacing), np.floor((c + half) / spacing) + 1)
            offsets.append(m * spacing - c)
        if is3d:
            lines = [[(o, -half, floor_y), (o, half, floor_y)] for o in offsets[0]]
            lines += [[(-half, o, floor_y), (half, o, floor_y)] for o in offsets[1]]
            return lines
        tick = 0.04 * body
        return [[(o, floor_y), (o - tick, floor_y - tick)] for o in offsets[0]]

    child = [np.flatnonzero(tr.parents >= 0) for tr in tracks]

    def draw_frame(i: int) -> None:
        for k, tr in enumerate(tracks):
            floor, bones, dots, text = artists[k]
            q = project(k, i)
            bones.set_segments(np.stack([q[tr.parents[child[k]]], q[child[k]]], axis=1))
            if follow or i == 0:
                floor.set_segments(floor_lines(centres[k][i]))
            if is3d:
                dots.set_data_3d(q[:, 0], q[:, 1], q[:, 2])
            else:
                dots.set_data(q[:, 0], q[:, 1])
            text.set_text(f"{tr.title}  frame {tr.start_frame + int(frames_used[k][i])}")

    from matplotlib import animation as anim

    if suffix == ".gif":
        writer = anim.PillowWriter(fps=play_fps)
    else:
        writer = anim.FFMpegWriter(
            fps=play_fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"]
        )
    import matplotlib as mpl

    from ..io import atomic_path

    with atomic_path(out, suffix=f".tmp{suffix}") as tmp, mpl.rc_context({"savefig.bbox": None}):
        # (a 'tight' bbox would change the frame size)
        writer.setup(fig, str(tmp), dpi)
        try:
            for i in range(len(times)):
                draw_frame(i)
                writer.grab_frame()
        except BaseException:
            with contextlib.suppress(
                Exception
            ):  # stop the encoder; atomic_path removes the partial file
                writer.finish()
            raise
        writer.finish()
    return out


def _grid_spacing(body: float) -> float:
    """A round floor-grid spacing of about a third of the body size."""
    target = max(body / 3.0, 1e-9)
    mag = 10 ** np.floor(np.log10(target))
    for m in (1, 2, 5, 10):
        if m * mag >= target:
            return float(m * mag)
    return float(10 * mag)
