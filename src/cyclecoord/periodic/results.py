"""What an extraction returns and how its options are given: its result, a failed run's
partial result, the cycle options and the keywords read from configured objects
(:func:`~cyclecoord.periodic.pipeline.extract` uses them)."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from .barcode import (
    CLEAR_GAP,
    CLEAR_MIN_FRACTION,
    CLEAR_RATIO,
    DEFAULT_PRIME,
    Barcode,
    BarSelection,
)
from .coordinates import CircularCoordinates
from .cycle import TypicalCycle
from .density import PeriodicDensity
from .preprocess import PreparedData, Preprocessor, _delays
from .windings import Windings, stretches

__all__ = [
    "ExtractionResult", "PartialExtraction", "CycleOptions", "MIN_TURNS", "TIMINGS", "TRAVELS",
    "take_cycle_options", "configured_keywords", "EXTRACT_CONFIGURED_DEFAULTS",
]

#: Fewer turns of the coordinate over the steady frames than this is no periodic motion
#: (the rule :func:`~cyclecoord.periodic.detection.detect` applies to its segments).
MIN_TURNS = 1.5
#: How the cycle is timed: at the capture's pace (re-timed phase) or by the coordinate.
TIMINGS = ("capture", "coordinate")
#: What the cycle's root does: travel and turn as captured, walk straight, stay in place.
TRAVELS = ("keep", "straight", "in_place")

@dataclass(frozen=True)
class CycleOptions:
    """How the typical cycle is made: one object for :func:`extract`,
    :func:`~cyclecoord.periodic.detection.motion_cycles` and a pipeline's own settings.

    Each field is the keyword of the same name of :func:`extract` (see there), with the
    same default; ``extract(m, cycle=CycleOptions(travel="straight"))`` equals
    ``extract(m, travel="straight")``.
    """

    timing: str = "capture"
    travel: str = "keep"
    bandwidth: str | float | None = None
    cycle_start: str = "slowest"
    n_samples: int = 500
    n_neighbors: int = 10
    weighting: str = "kernel"
    sampling: str = "quantile"
    min_turns: float = MIN_TURNS

    def as_dict(self) -> dict[str, Any]:
        """The options as keyword arguments."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


def take_cycle_options(cycle: Any, given: dict[str, Any], where: str) -> dict[str, Any]:
    """``given`` (a function's cycle keywords) overridden by ``cycle``; a keyword changed
    from its default beside ``cycle`` is an error (which one would win is not obvious)."""
    if cycle is None:
        return given
    if not isinstance(cycle, CycleOptions):
        raise ParameterError(f"{where}: cycle must be a CycleOptions, got {type(cycle).__name__}")
    default = CycleOptions().as_dict()
    clash = [k for k, v in given.items() if k in default and v != default[k]]
    if clash:
        raise ParameterError(
            f"{where}: give {', '.join(clash)} either as keyword(s) or in cycle=CycleOptions(...), "
            "not both"
        )
    return {**given, **cycle.as_dict()}


@dataclass
class PartialExtraction:
    """What an extraction that found no periodic motion got as far as
    (``NoPeriodicMotionError.result``).

    It holds only what was computed: the capture, its preparation and, when the run got
    that far, the barcode, the bar looked at and the estimator; there is no coordinate,
    period or cycle.  Figures of it show the barcode (why nothing stood clear), and
    ``cyclecoord extract --report`` writes it with ``selected: null`` and the reason.

    Attributes
    ----------
    motion : Motion
    prepared : PreparedData
    reason : str
        Why the extraction stopped (the error's message without the source).
    barcode : Barcode or None
    selection : BarSelection or None
        The bar that was judged (None when no bar was).
    timings, parameters : dict
    warnings : list of str
    estimator : CircularCoordinates or None
    preprocessor : Preprocessor or None
    """

    motion: Motion
    prepared: PreparedData
    reason: str
    barcode: Barcode | None = None
    selection: BarSelection | None = None
    timings: dict = field(default_factory=dict)
    parameters: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    estimator: CircularCoordinates | None = None
    preprocessor: Preprocessor | None = None

    def __repr__(self) -> str:  # one line, not the arrays it holds
        bars = "no barcode" if self.barcode is None else f"{len(self.barcode.h1)} H1 bars"
        return f"PartialExtraction({self.motion!r}, {bars}, reason={self.reason!r})"


@dataclass
class ExtractionResult:
    """Everything :func:`extract` computed.

    Attributes
    ----------
    motion : Motion
        The analysed frames (after ``frames`` selection).
    prepared : PreparedData
        Points (T, K) analysed and poses (T, D) with differenced root channels.
    barcode : Barcode
    selection : BarSelection
        Chosen H1 class and scale.
    coordinate : ndarray, shape (T,)
        Circular coordinate per analysed frame, in [0, 1), increasing with time; NaN on
        frames outside the steady stretches (:attr:`used_frames`).
    unwrapped : ndarray, shape (T,)
        The coordinate unwrapped along frame order inside each steady stretch (in cycles).
    cycles : float
        Turns of the coordinate over the steady stretches.
    period_frames : float
        Median length in frames of the complete windings (:attr:`windings`).
    cycle_frames : ndarray
        Length in frames of each complete winding (at the sharpest level).
    density : PeriodicDensity
    typical : TypicalCycle
        The cycle in the prepared space (root as differences).
    cycle : Motion
        The typical cycle as a motion at the capture's rate, root re-integrated so it
        travels like the original; loops.
    jerk : dict
        ``{"original": ..., "cycle": ...}`` mean jerk norm: with a skeleton on joint
        positions in the root's frame, metres / s³ (the capture's on the frames the cycle
        was made from; :func:`cyclecoord.quality.pose_space.cycle_figures`), without one
        on the prepared channels (channel units / s³).
    loop_closure : float
        Last-to-first step of the cycle over its median step: on joint positions with a
        skeleton (``pose_quality.seam``), the prepared space without.
    distance : dict
        Distance of the clip's frames to the cycle (median, 90th percentile, max), in
        the prepared space's units, next to the capture's median and 99th-percentile
        frame-to-frame steps and the cycle's largest step (the seam included; over 2x the
        capture's 99th percentile is a warning: a pop).
    timings : dict
        Seconds per stage.
    warnings : list of str
        Anything the user should know (H0 components, cocycle repairs, ...).
    used : ndarray of bool, shape (T,)
        The steady frames the cycle was built from.
    phase : ndarray, shape (T,)
        Re-timed phase (advancing at the capture's pace) on the used frames, NaN
        elsewhere (all NaN with ``timing="coordinate"``).
    windings : Windings
        The complete windings: lengths, spread, anchors.
    heading_per_cycle : float
        Heading change of one cycle in degrees (as captured, before ``travel``).
    pose_quality : PoseQuality or None
        Seam, pop, nearest-pose distance and jerk measured on joint positions in the root's
        frame (:mod:`cyclecoord.quality.pose_space`): the same whatever file the cycle is
        read from.  None without a skeleton.
    rig : RigInfo or None
        What :func:`cyclecoord.rig.describe_rig` found on the capture (None without a
        skeleton).
    rig_changes : list of str
        What :func:`cyclecoord.rig.normalize_rig` changed before the analysis (empty when
        the capture was analysed as it is); ``motion`` is the analysed motion and
        ``cycle`` is written back in the capture's own rig.
    """

    motion: Motion
    prepared: PreparedData
    barcode: Barcode
    selection: BarSelection
    coordinate: np.ndarray
    unwrapped: np.ndarray
    cycles: float
    period_frames: float
    cycle_frames: np.ndarray
    density: PeriodicDensity
    typical: TypicalCycle
    cycle: Motion
    jerk: dict
    loop_closure: float
    distance: dict
    timings: dict
    parameters: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    estimator: CircularCoordinates | None = None
    preprocessor: Preprocessor | None = None
    used: np.ndarray | None = None
    phase: np.ndarray | None = None
    windings: Windings | None = None
    heading_per_cycle: float = float("nan")
    pose_quality: Any = None
    rig: Any = None
    rig_changes: list = field(default_factory=list)

    def __repr__(self) -> str:  # one line, not the arrays it holds
        return (
            f"ExtractionResult({self.motion!r}, period {self.period_frames:.1f} frames, "
            f"{self.cycles:.2f} cycles over frames {self.used_frames})"
        )

    def _rig_dict(self) -> dict | None:
        if self.rig is None:
            return None
        return {**self.rig.to_dict(), "changes": list(self.rig_changes)}

    def on_frames(self, values: np.ndarray, take: Motion) -> np.ndarray:
        """Per-frame ``values`` of the analysed frames (``coordinate``, ``phase``, ...)
        placed on the frames of ``take``, the capture passed to :func:`extract`: NaN on
        frames the analysis left out before or after its own (a reference first frame
        it dropped, such as an Xsens T-pose; a ``frames=`` selection).

        Parameters
        ----------
        values : ndarray, shape (T,)
        take : Motion
            With ``T_take`` frames.

        Returns
        -------
        ndarray, shape (T_take,)
        """
        v = np.asarray(values, dtype=float).reshape(-1)
        off = int(self.motion.start_frame) - int(take.start_frame)
        off = min(max(off, 0), take.n_frames)
        out = np.full(take.n_frames, np.nan)
        n = min(v.size, take.n_frames - off)
        out[off : off + n] = v[:n]
        return out

    @property
    def used_frames(self) -> list[tuple[int, int]]:
        """The steady stretches the cycle was built from, ``[(start, stop), ...]`` (0-based)."""
        return [] if self.used is None else stretches(self.used)

    @property
    def model(self):
        """The fitted :class:`~cyclecoord.periodic.phase_model.PhaseModel` (phase of new
        frames, save/load)."""
        from .phase_model import PhaseModel

        return PhaseModel.from_result(self)

    def to_report(self) -> dict[str, Any]:
        """JSON-ready summary (see the CLI's ``--report``)."""
        from .report import capture_header

        return {
            **capture_header(self.motion),
            "dims": int(self.prepared.points.shape[1]),
            "parameters": self.parameters,
            "threshold": self.barcode.threshold,
            "prime": int(self.barcode.prime),
            "barcode": self.barcode.to_dict(),
            "selected": self.selection.to_dict(),
            "clear_criterion": {
                "min_ratio": CLEAR_RATIO,
                "min_gap": CLEAR_GAP,
                "min_fraction_of_threshold": CLEAR_MIN_FRACTION,
            },
            "coordinate": _nullable(self.coordinate),
            "phase": _nullable(self.phase),
            "used_frames": [[int(a), int(b)] for a, b in self.used_frames],
            "cycles": float(self.cycles),
            "period_frames": float(self.period_frames),
            "period_seconds": float(self.period_frames / self.motion.fps),
            "cycle_frames": [float(v) for v in self.cycle_frames],
            "period_spread": None if self.windings is None else float(self.windings.spread),
            "heading_per_cycle_degrees": None
            if not np.isfinite(self.heading_per_cycle)
            else float(self.heading_per_cycle),
            "cycle_length": int(self.cycle.n_frames),
            "jerk": self.jerk,
            "loop_closure": float(self.loop_closure),
            "bandwidth_frames": float(self.typical.bandwidth)
            if np.isfinite(self.typical.bandwidth)
            else None,
            "foot_skating": _cycle_skating(self.cycle, self.parameters.get("feet")),
            "distance_to_cycle": self.distance,
            "pose_quality": None if self.pose_quality is None else self.pose_quality.to_dict(),
            "rig": self._rig_dict(),
            "landmarks": _landmark_report(self.estimator),
            "cocycle_check": {
                "triangles": int(self.estimator.cocycle_check_.n_triangles)
                if self.estimator
                else None,
                "violations": int(self.estimator.cocycle_check_.n_violations)
                if self.estimator
                else None,
                "primes_tried": [int(p) for p, _ in self.estimator.primes_tried_]
                if self.estimator
                else [],
            },
            "timings": {k: round(float(v), 6) for k, v in self.timings.items()},
            "warnings": list(self.warnings),
        }


def _cycle_skating(cycle: Motion, feet=None) -> dict | None:
    """Foot skating of the cycle (:func:`~cyclecoord.quality.contacts.skating_report`) on
    ``feet`` (None: found)."""
    from ..quality.contacts import skating_report

    if cycle is None or cycle.skeleton is None:
        return None
    return skating_report(cycle, feet=None if feet is None else tuple(feet))


def _nullable(values: np.ndarray | None) -> list | None:
    """A list of floats with None where a value is NaN."""
    if values is None:
        return None
    return [float(v) if np.isfinite(v) else None for v in np.asarray(values, dtype=float)]


def _landmark_report(est: CircularCoordinates | None) -> dict | None:
    if est is None or not hasattr(est, "landmark_reason_"):
        return None
    lm = getattr(est, "landmarks_", None)
    return {
        "n_landmarks": None if lm is None else int(len(lm)),
        "reason": est.landmark_reason_,
        "covering_radius": float(getattr(est, "covering_radius_", 0.0)),
        "complex_estimate": est.complex_estimate_.to_dict(),
        "frames_outside_landmark_balls": int(np.sum(~est.covered_))
        if hasattr(est, "covered_")
        else None,
    }


#: extract's defaults for the settings a Preprocessor or CircularCoordinates can carry.
EXTRACT_CONFIGURED_DEFAULTS = dict(
    difference_root=True, normalize=False, pca=None, root="body", delay="auto", rotations="auto",
    max_scale=None, scale=None, class_index=0, prime=DEFAULT_PRIME, scale_fraction=0.9,
    temporal=False, landmarks="auto", memory_limit=None,
)


def configured_keywords(
    motion,
    preprocessor,
    estimator,
    given: dict[str, Any],
    defaults: dict[str, Any] = EXTRACT_CONFIGURED_DEFAULTS,
    where: str = "extract()",
    several_delays: bool = False,
) -> dict[str, Any]:
    """Keywords of ``where`` (extract or detect) from configured objects; a keyword changed
    from its default beside the object that carries it is an error.  Only the estimator's
    parameters named in ``given`` are taken.

    The preprocessor's delays (frames) become seconds at the motion's rate: one delay a
    number, several (only when ``where`` takes them, ``several_delays``) a tuple."""
    chosen: dict[str, Any] = {}
    if preprocessor is not None:
        if not isinstance(preprocessor, Preprocessor):
            raise ParameterError(
                f"{where}: preprocessor must be a Preprocessor, got {type(preprocessor).__name__}"
            )
        fps = getattr(motion, "fps", None) or 1.0
        # validated as the preprocessor does (whole frames >= 0; zeros dropped)
        lags = [] if preprocessor.delay is None else _delays(preprocessor.delay)
        if len(lags) > 1 and not several_delays:
            raise ParameterError(
                f"{where}: takes one delay, the preprocessor has {len(lags)} ({lags} frames)"
            )
        seconds = [float(k) / fps for k in lags]
        chosen.update(difference_root=preprocessor.difference_root,
                      normalize=preprocessor.normalize, pca=preprocessor.pca,
                      root=preprocessor.root,
                      delay=None if not seconds else seconds[0] if len(seconds) == 1
                      else tuple(seconds),
                      rotations=preprocessor.rotations)
    if estimator is not None:
        if not isinstance(estimator, CircularCoordinates):
            raise ParameterError(
                f"{where}: estimator must be a CircularCoordinates, got "
                f"{type(estimator).__name__}"
            )
        params = estimator.get_params()
        chosen.update({k: params[k] for k in (
            "max_scale", "scale", "class_index", "prime", "scale_fraction", "temporal",
            "landmarks", "memory_limit") if k in given})
    chosen = {k: v for k, v in chosen.items() if k in given}
    clash = [k for k in chosen if given[k] != defaults[k]]
    if clash:
        raise ParameterError(
            f"{where}: give {', '.join(clash)} either as keyword(s) or in the configured "
            "preprocessor/estimator, not both"
        )
    return chosen
