"""Figures to draw into, shared by the modules of :mod:`cyclecoord.plot`.

:func:`new_figure` is for the ``plot_*`` functions (a pyplot figure a notebook shows, or
the caller's own); :func:`detached_figure` for the functions that write files (an Agg
canvas pyplot never sees: headless, nothing left open); :func:`check_result` is the
argument check of the figures that need a complete extraction; :func:`drawn` is the motion
the stick figures draw (the capture in the analysis rig, every frame kept).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..errors import ParameterError

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..motion import Motion
    from ..periodic.pipeline import ExtractionResult

__all__ = ["new_figure", "detached_figure", "check_result", "drawn"]


def drawn(motion: "Motion") -> "Motion":
    """The motion a stick figure draws: :func:`cyclecoord.rig.normalize_rig` with every
    frame kept, so a static root draws no bone from the origin to the hips and a Z-up rig
    stands y up.  ``motion`` needs a skeleton and at least one frame."""
    from ..rig import normalize_rig

    return normalize_rig(motion, drop_reference=False)[0]


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


def check_result(result: Any, what: str) -> "ExtractionResult":
    """``result`` itself when it is a complete ExtractionResult, else a ParameterError naming
    ``what`` (the calling function).
    """
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
