"""Tolerances from measurements (issue 27).

Each quality assertion (period, jerk, seam and loop closure, pop, coverage, skating,
detection accuracy) sits at the figure the code measured, plus :data:`MARGIN`: a figure
that gets a third worse fails its test.  The measurement is named beside each assertion,
from the run :data:`RUN`; re-measure and update them together when the code is meant to
change a figure.

Figures that are errors near zero get a floor at the data's resolution instead (a period
within one frame, a label error of half a percent of the frames): below it, a third of
the figure is noise, not a regression.
"""

#: The run the measured figures in the tests come from.
RUN = "3c7347a (main, 2026-11-27), 2 cores"

#: A figure may be this much worse than measured: a regression of a third fails.
MARGIN = 1.3


def at_most(measured: float, floor: float = 0.0) -> float:
    """Upper limit of a lower-is-better figure measured at ``measured``."""
    return max(MARGIN * measured, floor)


def at_least(measured: float) -> float:
    """Lower limit of a higher-is-better figure measured at ``measured``."""
    return measured / MARGIN


def frame(period: float) -> float:
    """One frame as a fraction of a period: the floor of a relative period error."""
    return 1.0 / period
