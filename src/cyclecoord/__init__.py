"""cyclecoord: find, parameterise and reuse periodic motion in motion capture.

The package follows the data: :mod:`~cyclecoord.motion` and :mod:`~cyclecoord.io` get a
capture in and out, :mod:`~cyclecoord.skeleton` poses it, and the pipeline modules turn
it into a barcode, a circular coordinate and a loopable typical cycle.
"""

from .errors import CycleCoordError, NoPeriodicMotionError, ParameterError, ParseError
from .motion import DEFAULT_FPS, Motion
from .skeleton import Joint, JointPositions, Skeleton, forward_kinematics

__version__ = "0.1.0"

__all__ = [
    "CycleCoordError",
    "NoPeriodicMotionError",
    "ParameterError",
    "ParseError",
    "DEFAULT_FPS",
    "Motion",
    "Joint",
    "JointPositions",
    "Skeleton",
    "forward_kinematics",
    "__version__",
]
