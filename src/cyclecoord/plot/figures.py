"""Figures of the periodic pipeline and stick-figure animations of captures (matplotlib).

Every figure function draws into the axes or figure it is given, or into a new pyplot
figure, and returns the :class:`~matplotlib.figure.Figure`; none of them calls
``plt.show()``.  :func:`save_figures` and :func:`render` build their figures without
pyplot (Agg canvas), so they work headless and leave no open figures behind.

The channels figure lives in :mod:`~cyclecoord.plot.channels` and the animations in
:mod:`~cyclecoord.plot.animation`; both are re-exported here.

>>> import cyclecoord as cc
>>> from cyclecoord import plot
>>> result = cc.extract(cc.datasets.example_capture().motion)
>>> fig = plot.plot_barcode(result.barcode, result.selection)      # doctest: +SKIP
>>> plot.save_figures(result, "figures")                         # doctest: +SKIP
>>> plot.render(result.motion, "walk.gif", other=result.cycle)   # doctest: +SKIP
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping, Sequence

import numpy as np

from ..errors import ParameterError
from ._canvas import check_result, detached_figure, new_figure
from .animation import render
from .channels import plot_channels

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..periodic.barcode import Barcode, BarSelection
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

    fig, ax0, ax1, shared = _barcode_axes(ax, fig, len(h0), len(h1))
    sel_index = None if selection is None else int(selection.index)
    n0 = len(h0)
    offset1 = n0 + 1 if shared else 0  # rows of H1 above H0 on a shared axes

    _draw_bars(ax0, h0, "H0", 0, None, thr)
    _draw_bars(ax1, h1, "H1", offset1, sel_index, thr)
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


def _barcode_axes(
    ax: Any, fig: "Figure | None", n_h0: int, n_h1: int
) -> tuple["Figure", "Axes", "Axes", bool]:
    """The figure and the (H0, H1) axes of :func:`plot_barcode`; True when both are one axes."""
    if ax is None:
        fig = new_figure((7.0, 5.0), fig)
        n0, n1 = max(n_h0, 1), max(n_h1, 1)
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
    return fig, ax0, ax1, shared


def _draw_bars(
    a: "Axes", bars: np.ndarray, label: str, base: int, highlight: int | None, thr: float
) -> None:
    """One barcode's bars as a LineCollection, rows from ``base`` up, ``highlight`` in red."""
    from matplotlib.collections import LineCollection

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
    res = check_result(result, "plot_pca")
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
    res = check_result(result, "plot_density")
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
