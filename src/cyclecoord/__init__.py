"""cyclecoord: find, parameterise and reuse periodic motion in motion capture.

The package follows the data: :mod:`~cyclecoord.motion` and :mod:`~cyclecoord.io` get a
capture in and out, :mod:`~cyclecoord.skeleton` poses it, :mod:`~cyclecoord.preprocess`
prepares it, :mod:`~cyclecoord.barcode` computes the persistent cohomology barcode,
:mod:`~cyclecoord.coordinates` turns a cocycle into a circular coordinate,
:mod:`~cyclecoord.density` and :mod:`~cyclecoord.cycle` build the typical cycle,
:mod:`~cyclecoord.metrics` measures it and :mod:`~cyclecoord.pipeline` runs it all.

>>> import cyclecoord as cc
>>> motion = cc.datasets.example_capture().motion
>>> result = cc.extract(motion)
>>> round(result.cycles)
4
"""

from . import datasets
from .barcode import Barcode, BarSelection, compute_barcode
from .coordinates import CircularCoordinates
from .cycle import TypicalCycle, typical_cycle
from .density import PeriodicDensity
from .errors import CycleCoordError, NoPeriodicMotionError, ParameterError, ParseError
from .io import convert, load, save
from .motion import DEFAULT_FPS, Motion
from .pipeline import ExtractionResult, extract
from .preprocess import PreparedData, Preprocessor
from .skeleton import Joint, JointPositions, Skeleton, forward_kinematics

__version__ = "0.1.0"

__all__ = [
    "Barcode",
    "BarSelection",
    "CircularCoordinates",
    "CycleCoordError",
    "DEFAULT_FPS",
    "ExtractionResult",
    "Joint",
    "JointPositions",
    "Motion",
    "NoPeriodicMotionError",
    "ParameterError",
    "ParseError",
    "PeriodicDensity",
    "PreparedData",
    "Preprocessor",
    "Skeleton",
    "TypicalCycle",
    "compute_barcode",
    "convert",
    "datasets",
    "extract",
    "forward_kinematics",
    "load",
    "save",
    "typical_cycle",
    "__version__",
]
