"""What :func:`~cyclecoord.periodic.detection.detect` returns: segments, classes, windows."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...motion import Motion
from ..barcode import Barcode
from ..coordinates import CircularCoordinates

__all__ = ["Segment", "DetectedClass", "WindowInfo", "DetectionResult"]


@dataclass(frozen=True)
class Segment:
    """A frame range where one motion is performed (0-based, half-open)."""

    start: int
    stop: int
    motion: int
    classes: tuple
    birth: float
    death: float
    scale: float
    cycles: float
    period_frames: float

    def to_dict(self) -> dict:
        return {
            "start": self.start,
            "stop": self.stop,
            "motion": self.motion,
            "classes": list(self.classes),
            "birth": self.birth,
            "death": None if not np.isfinite(self.death) else self.death,
            "scale": self.scale,
            "cycles": self.cycles,
            "period_frames": self.period_frames,
        }


@dataclass
class DetectedClass:
    """One candidate H1 class and what its coordinate did.

    Attributes
    ----------
    index : int
        Position in the barcode's H1 bars (by decreasing persistence).
    birth, death, scale : float
    coordinate : ndarray, shape (T,)
        Circular coordinate of every frame.
    speed : ndarray, shape (T,)
        Smoothed signed speed of the coordinate (cycles per frame).
    consistency : ndarray, shape (T,)
        How steadily it moves one way, in [0, 1].
    mask : ndarray of bool, shape (T,)
        Excited frames that belong to stretches of at least ``min_cycles`` cycles.
    motion : int
        Motion id, ``-1`` when the class was dropped.
    status : str
        ``"kept"`` or why it was dropped.
    """

    index: int
    birth: float
    death: float
    scale: float
    coordinate: np.ndarray
    speed: np.ndarray
    consistency: np.ndarray
    mask: np.ndarray
    motion: int = -1
    status: str = "kept"

    def to_dict(self) -> dict:
        return {
            "index": self.index,
            "birth": self.birth,
            "death": None if not np.isfinite(self.death) else self.death,
            "scale": self.scale,
            "motion": self.motion,
            "status": self.status,
            "excited_frames": int(self.mask.sum()),
        }


@dataclass
class WindowInfo:
    """One time window of the windowed stage and what its barcode showed.

    Attributes
    ----------
    start, stop : int
        Half-open frame range (0-based, in the analysed frames).
    step : int
        Every ``step``-th frame of the range went into the window's filtration.
    birth, death : float
        The window's most persistent H1 bar (``death`` is ``inf`` when alive at the
        window's threshold); NaN when the window has no H1 bar.
    threshold : float
        The window's filtration threshold (half its diameter), analysed-space units.
    scale : float
        Scale the cocycle was read at (NaN when no coordinate was computed).
    clear : bool
        Whether the bar stands clear (:func:`cyclecoord.periodic.barcode.select_bar`).
    cycles : float
        Unwrapped turns of its circular coordinate from the first frame to the last.
    steadiness : float
        Fraction of coordinate steps going the way of the net advance, in [0, 1].
    period_frames : float
        Window frames per completed cycle (``(stop - start) / cycles``).
    looping : bool
        Clear bar, at least ``window_cycles`` cycles and ``window_steadiness``.
    motion : int
        Motion id the window ended up in, ``-1`` otherwise.
    cycle : ndarray, shape (CYCLE_BINS, D) or None
        Mean pose (root channels left out) per phase bin of the coordinate: the window's
        typical cycle, compared between windows up to rotation and reflection.
    """

    start: int
    stop: int
    step: int
    birth: float
    death: float
    threshold: float
    scale: float = float("nan")
    clear: bool = False
    cycles: float = 0.0
    steadiness: float = 0.0
    period_frames: float = float("nan")
    looping: bool = False
    motion: int = -1
    cycle: np.ndarray | None = field(default=None, repr=False)

    def to_dict(self) -> dict:
        def num(v: float) -> float | None:
            return float(v) if np.isfinite(v) else None

        return {
            "start": int(self.start), "stop": int(self.stop), "step": int(self.step),
            "birth": num(self.birth), "death": num(self.death), "threshold": num(self.threshold),
            "scale": num(self.scale), "clear": bool(self.clear), "cycles": float(self.cycles),
            "steadiness": float(self.steadiness), "period_frames": num(self.period_frames),
            "looping": bool(self.looping), "motion": int(self.motion),
        }


@dataclass
class DetectionResult:
    """What :func:`detect` found.

    Attributes
    ----------
    motion : Motion
        The analysed frames.
    barcode : Barcode
    classes : list of DetectedClass
        Every candidate, kept or dropped.
    segments : list of Segment
    labels : ndarray of int, shape (T,)
        Motion id per frame, ``-1`` where nothing periodic happens.
    n_motions : int
    timings : dict
        Seconds per stage: ``prepare``, ``barcode``, ``coordinates`` (global classes),
        ``windows`` (windowed stage, when run), ``segments`` (grouping and labelling),
        ``total``.
    parameters : dict
        The arguments of :func:`detect`.
    warnings : list of str
    estimator : CircularCoordinates or None
        The estimator whose barcode the global classes were read from (barcode stage
        only: each class's coordinate is in ``classes``).
    windows : list of WindowInfo
        Every window of the windowed stage (empty with ``method="global"``).
    rig_adapter : RigAdapter or None
        How the capture's rig was read (:func:`cyclecoord.rig.normalize_rig`); None when
        it was analysed as it is.
    method : str
        The method that ran (``"auto"``, ``"global"`` or ``"windows"``).
    """

    motion: Motion
    barcode: Barcode
    classes: list
    segments: list
    labels: np.ndarray
    n_motions: int
    timings: dict
    parameters: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    estimator: CircularCoordinates | None = None
    windows: list = field(default_factory=list)
    method: str = "global"
    rig_adapter: Any = None

    def to_report(self) -> dict[str, Any]:
        bc = self.barcode.to_dict()
        chosen = {c.index: c.motion for c in self.classes if c.motion >= 0}
        from ..report import capture_header

        return {
            **capture_header(self.motion),
            "parameters": self.parameters,
            "threshold": self.barcode.threshold,
            "barcode": bc,
            "chosen_classes": [{"index": k, "motion": v} for k, v in sorted(chosen.items())],
            "classes": [c.to_dict() for c in self.classes],
            "method": self.method,
            "n_motions": self.n_motions,
            "segments": [s.to_dict() for s in self.segments],
            "windows": [w.to_dict() for w in self.windows],
            "labels": [int(v) for v in self.labels],
            "timings": {k: round(float(v), 6) for k, v in self.timings.items()},
            "warnings": list(self.warnings),
        }
