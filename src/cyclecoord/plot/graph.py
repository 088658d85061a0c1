"""Figures of the motion graph (Gauch & Peters Figs. 1-6): edges, vector field, generated paths.

All draw in the first two latent coordinates.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Sequence

import numpy as np

from ._canvas import detached_figure, new_figure

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "plot_graph_edges",
    "plot_vector_field",
    "plot_generated_path",
    "save_graph_figures",
    "save_crossval_figures",
]


def _axes(
    ax: "Axes | None", fig: "Figure | None", size: tuple[float, float]
) -> tuple["Figure", "Axes"]:
    if ax is not None:
        return ax.figure, ax
    f = new_figure(size, fig)
    return f, f.add_subplot(1, 1, 1)


def plot_graph_edges(
    graph: Any, *, ax: "Axes | None" = None, fig: "Figure | None" = None, title: str | None = None
) -> "Figure":
    """The graph's added edges (blue) over the training frames (red), as the paper's Figs. 1-2."""
    from matplotlib.collections import LineCollection

    fig, ax = _axes(ax, fig, (6, 5.5))
    p = graph.points[:, :2]
    n_own = graph.n_nodes - graph.n_takes
    e = graph.edges[n_own:]
    ax.add_collection(
        LineCollection(
            np.stack([p[e[:, 0]], p[e[:, 1]]], axis=1),
            colors="tab:blue",
            linewidths=0.3,
            alpha=0.5,
            label=f"{graph.method} edges ({len(e)})",
        )
    )
    ax.plot(
        p[:, 0], p[:, 1], ".", color="tab:red", ms=2, label=f"training frames ({graph.n_nodes})"
    )
    ax.set_xlabel("latent 1")
    ax.set_ylabel("latent 2")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title(title or f"{graph.method} motion graph")
    return fig


def plot_vector_field(
    field: Any,
    *,
    grid: int = 25,
    ax: "Axes | None" = None,
    fig: "Figure | None" = None,
    title: str | None = None,
) -> "Figure":
    """The interpolated field on a grid over the training frames (Figs. 3-4).

    In more than two dimensions the grid lies in the plane of the first two latent
    coordinates through the training mean (0), and the arrows are the field's first two
    components.  Arrows where a Delaunay field fell back to k-NN are grey.
    """
    fig, ax = _axes(ax, fig, (6, 5.5))
    g = field.graph
    p = g.points
    lo, hi = p[:, :2].min(axis=0), p[:, :2].max(axis=0)
    pad = 0.05 * (hi - lo)
    gx, gy = np.meshgrid(
        np.linspace(lo[0] - pad[0], hi[0] + pad[0], grid),
        np.linspace(lo[1] - pad[1], hi[1] + pad[1], grid),
    )
    x = np.zeros((gx.size, p.shape[1]))
    x[:, 0], x[:, 1] = gx.ravel(), gy.ravel()
    v, inside = field.evaluate(x)
    ax.plot(p[:, 0], p[:, 1], ".", color="tab:red", ms=1.5, alpha=0.4, label="training frames")
    ax.quiver(
        x[inside, 0],
        x[inside, 1],
        v[inside, 0],
        v[inside, 1],
        color="tab:blue",
        angles="xy",
        label=f"{field.name} field" + (" (no heading: plain weights)" if field.agree else ""),
    )
    if (~inside).any():
        ax.quiver(
            x[~inside, 0],
            x[~inside, 1],
            v[~inside, 0],
            v[~inside, 1],
            color="0.6",
            angles="xy",
            label="outside the hull (k-NN)",
        )
    ax.set_xlabel("latent 1")
    ax.set_ylabel("latent 2")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title(title or f"vector field ({field.name})")
    return fig


def plot_generated_path(
    training: np.ndarray,
    generated: np.ndarray,
    true: np.ndarray | None = None,
    *,
    ax: "Axes | None" = None,
    fig: "Figure | None" = None,
    title: str | None = None,
    label: str = "generated",
) -> "Figure":
    """A generated path (blue) against the left-out take (red) over the training frames
    (Figs. 5-6)."""
    fig, ax = _axes(ax, fig, (6, 5.5))
    ax.plot(training[:, 0], training[:, 1], ".", color="0.75", ms=1.5, label="training frames")
    if true is not None:
        ax.plot(true[:, 0], true[:, 1], "-", color="tab:red", lw=1, label="left-out take")
        ax.plot(true[-1, 0], true[-1, 1], "s", color="tab:red", ms=6, label="its final point")
    ax.plot(generated[:, 0], generated[:, 1], "-", color="tab:blue", lw=1.2, label=label)
    ax.plot(generated[0, 0], generated[0, 1], "o", color="k", ms=5, label="start")
    ax.plot(generated[-1, 0], generated[-1, 1], "x", color="tab:blue", ms=7)
    ax.set_xlabel("latent 1")
    ax.set_ylabel("latent 2")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=7, loc="upper right")
    ax.set_title(title or "generated path")
    return fig


def _save(fig: "Figure", folder: Path, name: str, dpi: float) -> Path:
    from ..io import atomic_path

    out = folder / name
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=dpi, format="png")
    return out


def save_graph_figures(
    synth: Any, generation: Any, folder: str | os.PathLike[str], *, dpi: float = 100
) -> list[Path]:
    """``graph.png``, ``field.png`` and ``path.png`` of a fitted synthesiser and its output."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    fig = detached_figure((6, 5.5), dpi)
    plot_graph_edges(synth.graph_, fig=fig)
    out.append(_save(fig, folder, "graph.png", dpi))
    fig = detached_figure((6, 5.5), dpi)
    plot_vector_field(synth.field_, fig=fig)
    out.append(_save(fig, folder, "field.png", dpi))
    fig = detached_figure((6, 5.5), dpi)
    plot_generated_path(
        synth.graph_.points,
        generation.path.points,
        fig=fig,
        title=f"{generation.path.kind} from {generation.start['take']}:{generation.start['frame']}",
    )
    out.append(_save(fig, folder, "path.png", dpi))
    return out


def save_crossval_figures(
    cv: Any, motions: Sequence[Any], folder: str | os.PathLike[str], *, dpi: float = 100
) -> list[Path]:
    """One ``fold_<take>.png`` per left-out take: every method's path against the take."""
    from ..synthesis.graph import PoseSpace
    from ..synthesis.graph.model import take_name

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    names = [take_name(m, i) for i, m in enumerate(motions)]
    methods = list(cv.median)
    out = []
    for i, name in enumerate(names):
        train = [m for j, m in enumerate(motions) if j != i]
        space = PoseSpace(cv.parameters["dims"]).fit(train)
        pts = np.vstack([space.transform(m) for m in train])
        true = space.transform(motions[i])
        fig = detached_figure((5.0 * len(methods), 5.0), dpi)
        for c, method in enumerate(methods):
            ax = fig.add_subplot(1, len(methods), c + 1)
            plot_generated_path(
                pts,
                cv.paths[(name, method)].points,
                true,
                ax=ax,
                title=f"{name} left out: {method}",
                label=method,
            )
        fig.tight_layout()
        out.append(_save(fig, folder, f"fold_{name}.png", dpi))
    return out
