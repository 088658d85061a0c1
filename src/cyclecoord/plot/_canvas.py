"""Figures to draw into, shared by the modules of :mod:`cyclecoord.plot`.

:func:`new_figure` is for the ``plot_*`` functions (a pyplot figure a notebook shows, or
the caller's own); :func:`detached_figure` for the functions that write files (an Agg
canvas pyplot never sees: headless, nothing left open).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["new_figure", "detached_figure"]


def new_figure(figsize: tuple[float, float], fig: "Figure | None" = None) -> "Figure":
    """``fig`` itself when given (drawn into as it is), else a new pyplot figure.

    Parameters
    ----------
    figsize : (float, float)
        Width and height in inches of a new figure.
    fig : Figure, optional
        A figure of the caller's to draw into.
    """
    if fig is not None:
        return fig
    import matplotlib.pyplot as plt

    return plt.figure(figsize=figsize)


def detached_figure(figsize: tuple[float, float], dpi: float = 100) -> "Figure":
    """A figure with an Agg canvas that pyplot does not know about (no GUI, no leak).

    Parameters
    ----------
    figsize : (float, float)
        Width and height in inches.
    dpi : float, default 100
        Dots per inch.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, dpi=dpi)
    FigureCanvasAgg(fig)
    return fig
