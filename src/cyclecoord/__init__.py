"""cyclecoord: find, parameterise and reuse periodic motion in motion capture.

The package follows the data: :mod:`~cyclecoord.motion` and :mod:`~cyclecoord.io` get a
capture in and out, :mod:`~cyclecoord.skeleton` poses it, :mod:`~cyclecoord.rig` finds and
undoes its rig conventions, :mod:`~cyclecoord.preprocess` prepares it,
:mod:`~cyclecoord.barcode` computes the persistent cohomology barcode,
:mod:`~cyclecoord.coordinates` turns a cocycle into a circular coordinate,
:mod:`~cyclecoord.density` and :mod:`~cyclecoord.cycle` build the typical cycle,
:mod:`~cyclecoord.metrics` measures it and :mod:`~cyclecoord.pipeline` runs it all.

>>> import cyclecoord as cc
>>> motion = cc.datasets.example_capture().motion
>>> result = cc.extract(motion)
>>> round(result.cycles)
4
"""

from typing import TYPE_CHECKING

# Public names and the module each lives in.  They are imported on first use (PEP 562)
# so that `import cyclecoord` and `cyclecoord --help` stay fast: scikit-learn, SciPy's
# statistics and ripser load only when the pipeline runs.
_LAZY = {
    "Barcode": "periodic.barcode",
    "BarSelection": "periodic.barcode",
    "compute_barcode": "periodic.barcode",
    "CircularCoordinates": "periodic.coordinates",
    "TypicalCycle": "periodic.cycle",
    "typical_cycle": "periodic.cycle",
    "PeriodicDensity": "periodic.density",
    "CycleCoordError": "errors",
    "NoPeriodicMotionError": "errors",
    "ParameterError": "errors",
    "ParseError": "errors",
    "convert": "io",
    "load": "io",
    "save": "io",
    "DEFAULT_FPS": "motion",
    "Motion": "motion",
    "ExtractionResult": "periodic.pipeline",
    "PartialExtraction": "periodic.pipeline",
    "CycleOptions": "periodic.pipeline",
    "extract": "periodic.pipeline",
    "PreparedData": "periodic.preprocess",
    "Preprocessor": "periodic.preprocess",
    "Joint": "skeleton",
    "JointPositions": "skeleton",
    "Skeleton": "skeleton",
    "forward_kinematics": "skeleton",
    "PhaseModel": "periodic.phase_model",
    "detect": "periodic.detection",
    "DetectionResult": "periodic.detection",
    "blend": "synthesis.blend",
    "transition": "synthesis.blend",
    "BlendResult": "synthesis.blend",
    "TransitionResult": "synthesis.blend",
    "align": "synthesis.align",
    "run_batch": "batch",
    "RigAdapter": "rig",
    "RigInfo": "rig",
    "describe_rig": "rig",
    "normalize_rig": "rig",
}
_SUBMODULES = {
    "batch",
    "cli",
    "conventions",
    "datasets",
    "io",
    "periodic",
    "plot",
    "quality",
    "rig",
    "skeleton",
    "synthesis",
}


def __getattr__(name: str):
    import importlib

    if name in _LAZY:
        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    if name in _SUBMODULES:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'cyclecoord' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY) | _SUBMODULES)


if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs
    from . import datasets
    from .periodic.barcode import Barcode, BarSelection, compute_barcode
    from .periodic.coordinates import CircularCoordinates
    from .periodic.cycle import TypicalCycle, typical_cycle
    from .periodic.density import PeriodicDensity
    from .errors import CycleCoordError, NoPeriodicMotionError, ParameterError, ParseError
    from .io import convert, load, save
    from .motion import DEFAULT_FPS, Motion
    from .periodic.pipeline import CycleOptions, ExtractionResult, PartialExtraction, extract
    from .periodic.preprocess import PreparedData, Preprocessor
    from .skeleton import Joint, JointPositions, Skeleton, forward_kinematics
    from .periodic.phase_model import PhaseModel
    from .periodic.detection import DetectionResult, detect
    from .synthesis.align import align
    from .synthesis.blend import BlendResult, TransitionResult, blend, transition
    from .batch import run_batch
    from .rig import RigAdapter, RigInfo, describe_rig, normalize_rig

__version__ = "0.1.0"

__all__ = [
    "Barcode",
    "BarSelection",
    "BlendResult",
    "CircularCoordinates",
    "CycleCoordError",
    "CycleOptions",
    "DEFAULT_FPS",
    "DetectionResult",
    "ExtractionResult",
    "Joint",
    "JointPositions",
    "Motion",
    "NoPeriodicMotionError",
    "ParameterError",
    "ParseError",
    "PartialExtraction",
    "PeriodicDensity",
    "PhaseModel",
    "PreparedData",
    "Preprocessor",
    "RigAdapter",
    "RigInfo",
    "Skeleton",
    "TransitionResult",
    "TypicalCycle",
    "align",
    "blend",
    "compute_barcode",
    "convert",
    "datasets",
    "describe_rig",
    "detect",
    "extract",
    "forward_kinematics",
    "load",
    "normalize_rig",
    "run_batch",
    "save",
    "transition",
    "typical_cycle",
    "__version__",
]
