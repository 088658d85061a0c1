"""The periodic pipeline end to end: capture -> barcode -> circular coordinate -> typical cycle.

:func:`extract` runs every stage and returns an :class:`ExtractionResult` holding each
stage's output, the quality figures and per-stage timings; ``result.cycle`` is the
typical cycle as a loopable :class:`~cyclecoord.motion.Motion`.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._blas import one_blas_thread
from .barcode import CLEAR_GAP, CLEAR_MIN_FRACTION, CLEAR_RATIO, DEFAULT_PRIME, Barcode, BarSelection
from .coordinates import CircularCoordinates, unwrap
from .cycle import TypicalCycle, check_bandwidth, typical_cycle
from .density import PeriodicDensity
from ..errors import NoPeriodicMotionError, ParameterError
from ..quality.metrics import distance_to_cycle, frame_steps, jerk_summary, loop_closure
from ..motion import Motion
from .preprocess import PreparedData, Preprocessor

__all__ = ["extract", "ExtractionResult", "loop_cycle", "cycle_lengths", "slowest_frame", "MIN_CYCLES"]

#: A clip whose coordinate goes round fewer times than this holds no measurable period.
MIN_CYCLES = 0.75


def slowest_frame(frames: np.ndarray, window: int = 5) -> int:
    """Index of the frame where a closed cycle moves least.

    Step sizes around the loop are smoothed over ``window`` frames (cyclically); the frame
    between the two smallest smoothed steps is returned.  Starting a loop there hides the
    seam best, as animators cut loops at a rest pose.
    """
    f = np.asarray(frames, dtype=float)
    steps = np.linalg.norm(np.roll(f, -1, axis=0) - f, axis=1)  # step i: frame i -> i+1
    around = steps + np.roll(steps, 1)  # motion entering and leaving frame i
    w = max(1, min(window, len(f)))
    kernel = np.ones(w) / w
    smooth = np.convolve(np.concatenate([around[-w:], around, around[:w]]), kernel, mode="same")[w:-w]
    return int(np.argmin(smooth))


def cycle_lengths(unwrapped: np.ndarray) -> np.ndarray:
    """Frames taken by each complete cycle.

    The unwrapped coordinate ``u`` starts at ``u[0]``; cycle ``k`` ends where ``u`` first
    reaches ``u[0] + k`` (linearly interpolated between frames).  Returns the differences
    between successive crossing times, starting from frame 0.
    """
    u = np.asarray(unwrapped, dtype=float)
    if u.size < 2:
        return np.zeros(0)
    total = u[-1] - u[0]
    ends = []
    for k in range(1, int(np.floor(total)) + 1):
        level = u[0] + k
        i = int(np.argmax(u >= level))
        if u[i] < level:
            break
        if i == 0:
            ends.append(0.0)
            continue
        f = (level - u[i - 1]) / (u[i] - u[i - 1]) if u[i] != u[i - 1] else 0.0
        ends.append(i - 1 + f)
    return np.diff(np.concatenate([[0.0], ends])) if ends else np.zeros(0)


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
        Circular coordinate per analysed frame, in [0, 1), increasing with time.
    unwrapped : ndarray, shape (T,)
        The coordinate unwrapped along frame order (in cycles).
    cycles : float
        Number of cycles in the clip (unwrapped change from first to last frame).
    period_frames : float
        Mean period in frames, ``(T - 1) / cycles``.
    cycle_frames : ndarray
        Length in frames of each complete cycle.
    density : PeriodicDensity
    typical : TypicalCycle
        The cycle in the prepared space (root as differences).
    cycle : Motion
        The typical cycle as a motion at the capture's rate, root re-integrated so it
        travels like the original; loops.
    jerk : dict
        ``{"original": ..., "cycle": ...}`` mean jerk norm (channel units / s³).
    loop_closure : float
        Last-to-first step of the cycle over its median step (prepared space).
    distance : dict
        Distance of the clip's frames to the cycle (median, 90th percentile, max), in
        the prepared space's units, next to the median frame-to-frame step.
    timings : dict
        Seconds per stage.
    warnings : list of str
        Anything the user should know (H0 components, cocycle repairs, ...).
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

    @property
    def model(self):
        """The fitted :class:`~cyclecoord.periodic.phase_model.PhaseModel` (phase of new frames, save/load)."""
        from .phase_model import PhaseModel

        return PhaseModel.from_result(self)

    def to_report(self) -> dict[str, Any]:
        """JSON-ready summary (see the CLI's ``--report``)."""
        return {
            "source": self.motion.source,
            "frames": [int(self.motion.start_frame), int(self.motion.start_frame + self.motion.n_frames)],
            "n_frames": int(self.motion.n_frames),
            "fps": self.motion.fps,
            "dims": int(self.prepared.points.shape[1]),
            "parameters": self.parameters,
            "threshold": self.barcode.threshold,
            "prime": int(self.barcode.prime),
            "barcode": self.barcode.to_dict(),
            "selected": self.selection.to_dict(),
            "clear_criterion": {"min_ratio": CLEAR_RATIO, "min_gap": CLEAR_GAP, "min_fraction_of_threshold": CLEAR_MIN_FRACTION},
            "coordinate": [float(v) for v in self.coordinate],
            "cycles": float(self.cycles),
            "period_frames": float(self.period_frames),
            "period_seconds": float(self.period_frames / self.motion.fps),
            "cycle_frames": [float(v) for v in self.cycle_frames],
            "cycle_length": int(self.cycle.n_frames),
            "jerk": self.jerk,
            "loop_closure": float(self.loop_closure),
            "bandwidth_frames": float(self.typical.bandwidth) if np.isfinite(self.typical.bandwidth) else None,
            "distance_to_cycle": self.distance,
            "landmarks": _landmark_report(self.estimator),
            "cocycle_check": {
                "triangles": int(self.estimator.cocycle_check_.n_triangles) if self.estimator else None,
                "violations": int(self.estimator.cocycle_check_.n_violations) if self.estimator else None,
                "primes_tried": [int(p) for p, _ in self.estimator.primes_tried_] if self.estimator else [],
            },
            "timings": {k: round(float(v), 6) for k, v in self.timings.items()},
            "warnings": list(self.warnings),
        }


def _landmark_report(est: CircularCoordinates | None) -> dict | None:
    if est is None or not hasattr(est, "landmark_reason_"):
        return None
    lm = getattr(est, "landmarks_", None)
    return {
        "n_landmarks": None if lm is None else int(len(lm)),
        "reason": est.landmark_reason_,
        "covering_radius": float(getattr(est, "covering_radius_", 0.0)),
        "complex_estimate": est.complex_estimate_.to_dict(),
        "frames_outside_landmark_balls": int(np.sum(~est.covered_)) if hasattr(est, "covered_") else None,
    }


def loop_cycle(
    typical: TypicalCycle,
    motion: Motion,
    prepared: PreparedData,
    preprocessor: Preprocessor,
    cycle_start: str = "slowest",
    rows: np.ndarray | None = None,
    metadata: dict | None = None,
) -> tuple[TypicalCycle, Motion]:
    """Turn a typical cycle in the prepared space into a loopable clip of the capture.

    The cycle is rotated to begin at its slowest pose (``cycle_start="slowest"``, where
    a loop's seam is least visible), and its root channels, per-frame differences in the
    prepared space, are integrated so that the clip travels and turns per frame as the
    capture did on average.

    Parameters
    ----------
    typical : TypicalCycle
        From :func:`~cyclecoord.periodic.cycle.typical_cycle` on ``prepared.poses`` (or rows of it).
    motion : Motion
        The capture ``prepared`` was made from.
    prepared : PreparedData
    preprocessor : Preprocessor
        The fitted preprocessor that made ``prepared``.
    cycle_start : {"slowest", "first"}
    rows : ndarray of int, optional
        The frames the cycle was averaged from (default all); their root differences
        give the travel per frame.
    metadata : dict, optional
        Stored on the returned clip.

    Returns
    -------
    (TypicalCycle, Motion)
        The cycle (rotated when ``cycle_start="slowest"``) and the clip, with the
        capture's channels, skeleton and frame rate.
    """
    if cycle_start not in ("slowest", "first"):
        raise ParameterError(f"cycle_start must be 'slowest' or 'first', got {cycle_start!r}")
    root = prepared.root_columns
    if cycle_start == "slowest":
        joints = np.delete(typical.frames, root, axis=1) if root.size < typical.frames.shape[1] else typical.frames
        shift = slowest_frame(joints)
        if shift:
            from dataclasses import replace

            typical = replace(
                typical,
                frames=np.roll(typical.frames, -shift, axis=0),
                phases=np.roll(typical.phases, -shift),
            )
    cyc = np.array(typical.frames, dtype=float)
    if root.size:
        last = len(prepared.poses) - 1  # the last row repeats the one before (see difference_root)
        used = np.arange(last) if rows is None else np.asarray(rows, dtype=int)
        used = used[used < last] if np.any(used < last) else used
        mean_delta = prepared.poses[used][:, root].mean(axis=0)
        cyc[:, root] = preprocessor.integrate_root(typical.frames[:, root], motion.frames[int(used.min()), root], mean_delta, motion)
    clip = motion.with_frames(
        cyc, start_frame=0, source=f"cycle of {motion.source or 'capture'}", metadata=dict(metadata or {}),
    )
    return typical, clip


@one_blas_thread
def extract(
    motion: Motion,
    frames: tuple[int | None, int | None] | None = None,
    *,
    pca: int | None = None,
    normalize: bool = False,
    temporal: bool = False,
    delay: float | None = None,
    difference_root: bool = True,
    root: str = "body",
    prime: int = DEFAULT_PRIME,
    max_scale: float | None = None,
    scale: float | None = None,
    class_index: int = 0,
    scale_fraction: float = 0.9,
    n_samples: int = 500,
    n_neighbors: int = 10,
    bandwidth: str | float | None = None,
    weighting: str = "kernel",
    sampling: str = "quantile",
    n_components: int = 30,
    cycle_start: str = "slowest",
    landmarks: int | str | None = "auto",
    memory_limit: float | None = None,
    require_clear: bool = True,
    random_state: int | None = 0,
) -> ExtractionResult:
    """Find the dominant periodic motion of a capture and its typical cycle.

    Parameters
    ----------
    motion : Motion
        The capture (angles in degrees).
    frames : (start, stop), optional
        0-based half-open frame range to analyse.
    pca : int, optional
        Project onto this many principal components before the filtration.
    normalize : bool
        Scale each channel by its standard deviation first.
    temporal : bool
        Use the time-aware metric (consecutive frames at distance 0).
    delay : float, optional
        Delay embedding in seconds for the filtration (out-and-back motions such as
        squats then form loops); the cycle is still averaged from the poses.
    difference_root : bool, default True
        Replace root translation/orientation by per-frame changes.
    root : {"body", "euler"}, default "body"
        Root changes as rotation vectors and steps in the root's own frame (gimbal-free,
        heading-invariant; needs the skeleton) or as Euler-channel differences (paper).
    prime : int, default 47
        Coefficient field Z/p, a prime greater than 11.
    max_scale : float, optional
        Filtration threshold in the analysed space's units (default: half the point
        cloud's diameter, see :func:`cyclecoord.periodic.barcode.default_max_scale`).
    scale : float, optional
        Scale to read the cocycle at (default: ``scale_fraction`` of the way up the bar).
    class_index : int, default 0
        Which H1 class by decreasing persistence.
    n_samples : int, default 500
        Phases sampled from the periodic density for the centroid curve.
    n_neighbors : int, default 10
        Frames averaged per sampled phase (sets the kernel width when ``bandwidth`` is
        None).
    bandwidth : None, "auto" or float
        Width of the kernel average in frames of one period: None for ``n_neighbors``
        frames' worth, ``"auto"`` for leave-one-out cross-validation, or a positive
        number (see :func:`~cyclecoord.periodic.cycle.typical_cycle`); the width used is
        ``result.typical.bandwidth``.
    weighting : {"kernel", "mean", "gaussian"}
        How frames near a phase are averaged: a smooth periodic kernel holding about
        ``n_neighbors`` frames (default), the paper's plain mean of the ``n_neighbors``
        nearest, or those Gaussian-weighted.
    sampling : {"quantile", "random"}
        Deterministic density quantiles (default, less jitter) or random draws (paper).
    n_components : int, default 30
        Gaussian mixture components of the periodic density.
    cycle_start : {"slowest", "first"}
        Where the written cycle begins: at its slowest pose (default; the seam of the
        loop is least visible there) or at the phase of the clip's first frame.
    landmarks : "auto", int or None
        Build the filtration on greedy max-min landmarks (``"auto"``: every frame up to
        1,000 frames, 500 landmarks beyond) and extend the coordinate to every frame;
        ``None`` uses every frame.
    memory_limit : float, optional
        Bytes the run's large arrays may take, the per-frame arrays and the filtration
        (whose landmarks are reduced to fit); default 2 GiB for the filtration alone.
        Never more than the machine's memory; a run that cannot fit is refused with a
        :class:`ParameterError` before anything large is allocated.
    require_clear : bool, default True
        Raise :class:`NoPeriodicMotionError` when the chosen bar does not stand clear.
    random_state : int, optional
        Seed for the density fit and sampling.

    Returns
    -------
    ExtractionResult

    Raises
    ------
    NoPeriodicMotionError
        When the chosen H1 bar does not stand clear (its ``result`` attribute holds a
        partial :class:`ExtractionResult` with ``cycle`` None and the barcode).
    ParameterError
        For invalid arguments.
    """
    if not isinstance(motion, Motion):
        raise ParameterError(f"extract() takes a Motion, got {type(motion).__name__}")
    if weighting not in ("kernel", "mean", "gaussian"):
        raise ParameterError(f"weighting must be 'kernel', 'mean' or 'gaussian', got {weighting!r}")
    if sampling not in ("quantile", "random"):
        raise ParameterError(f"sampling must be 'quantile' or 'random', got {sampling!r}")
    if cycle_start not in ("slowest", "first"):
        raise ParameterError(f"cycle_start must be 'slowest' or 'first', got {cycle_start!r}")
    if n_samples < 10:
        raise ParameterError(f"n_samples must be at least 10, got {n_samples}")
    if n_neighbors < 1:
        raise ParameterError(f"n_neighbors must be at least 1, got {n_neighbors}")
    bandwidth = check_bandwidth(bandwidth, weighting)  # before any work is done
    timings: dict[str, float] = {}
    notes: list[str] = []
    params = dict(
        frames=None if frames is None else list(frames), pca=pca, normalize=normalize, temporal=temporal,
        delay=delay, difference_root=difference_root, root=root, prime=prime, max_scale=max_scale, scale=scale,
        class_index=class_index, scale_fraction=scale_fraction, n_samples=n_samples,
        n_neighbors=n_neighbors, bandwidth=bandwidth, weighting=weighting, sampling=sampling, n_components=n_components,
        cycle_start=cycle_start, landmarks=landmarks, memory_limit=memory_limit, random_state=random_state,
    )
    motion = motion.window(frames)
    if motion.n_frames < 2 * n_neighbors or motion.n_frames < 10:
        raise ParameterError(
            f"{motion.n_frames} frames are too few to find a cycle (need at least {max(10, 2 * n_neighbors)})"
        )

    t0 = time.perf_counter()
    lag = int(round(delay * motion.fps)) if delay else None
    prep = Preprocessor(difference_root=difference_root, normalize=normalize, pca=pca, root=root, delay=lag)
    prepared = prep.fit_transform(motion)
    timings["prepare"] = time.perf_counter() - t0

    est = CircularCoordinates(
        max_scale=max_scale, scale=scale, class_index=class_index, prime=prime,
        scale_fraction=scale_fraction, temporal=temporal, landmarks=landmarks, memory_limit=memory_limit,
        memory_reserved=8.0 * max(0, prepared.poses.size - prepared.points.size),  # poses beyond the points
    )
    t0 = time.perf_counter()
    barcode = est.fit_barcode(prepared.points)
    timings["barcode"] = time.perf_counter() - t0
    if est.landmarks_ is not None:
        notes.append(f"barcode on {len(est.landmarks_)} landmarks: {est.landmark_reason_}")

    from .barcode import select_bar

    def fail(msg: str) -> NoPeriodicMotionError:
        partial = ExtractionResult(
            motion=motion, prepared=prepared, barcode=barcode, selection=None, coordinate=None,
            unwrapped=None, cycles=float("nan"), period_frames=float("nan"), cycle_frames=np.zeros(0),
            density=None, typical=None, cycle=None, jerk={}, loop_closure=float("nan"), distance={},
            timings=timings, parameters=params, warnings=notes, estimator=est, preprocessor=prep,
        )
        return NoPeriodicMotionError(msg, result=partial)

    if len(barcode.h1) == 0:
        raise fail(f"no periodic motion found: the barcode has no H1 bar up to scale {barcode.threshold:.4g}")
    if class_index >= len(barcode.h1):
        raise ParameterError(f"class index {class_index} out of range: the barcode has {len(barcode.h1)} H1 bars")
    pre_sel = select_bar(barcode, class_index, scale, scale_fraction)
    if require_clear and not pre_sel.clear:
        why = []
        if pre_sel.ratio < CLEAR_RATIO:
            why.append(f"death/birth {pre_sel.ratio:.2f} < {CLEAR_RATIO}")
        if pre_sel.gap < CLEAR_GAP:
            why.append(f"persistence only {pre_sel.gap:.2f}x the next bar's (< {CLEAR_GAP}x)")
        if not why:
            why.append(f"persistence under {CLEAR_MIN_FRACTION:.0%} of the threshold {barcode.threshold:.4g}")
        ds = "inf" if not np.isfinite(pre_sel.death) else f"{pre_sel.death:.4g}"
        raise fail(
            f"no periodic motion found: H1 bar #{class_index} [{pre_sel.birth:.4g}, {ds}) does not stand "
            f"clear ({'; '.join(why)}); try --max-scale, --pca or --frames"
        )

    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        est.fit_coordinate()
    for w in caught:
        notes.append(str(w.message))
    timings["coordinate"] = time.perf_counter() - t0
    sel = est.selection_
    barcode = est.barcode_
    if est.n_components_ > 1:
        notes.append(
            f"the complex at scale {sel.scale:.4g} has {est.n_components_} connected components: "
            "frames in different components get unrelated coordinates; raise --max-scale or --scale"
        )
    long_h0 = int(np.sum(np.isfinite(barcode.h0[:, 1]) & (barcode.h0[:, 1] > sel.birth)))
    if long_h0:
        notes.append(
            f"H0 shows {long_h0 + 1} components still apart when the H1 class is born (at {sel.birth:.4g}); "
            "the capture may hold separate pieces"
        )
    theta = est.coordinates_
    u = unwrap(theta)
    cycles = float(u[-1] - u[0])
    if cycles < MIN_CYCLES:
        raise fail(
            f"no periodic motion found: the circular coordinate covers only {cycles:.2f} cycles over the "
            f"clip (at least {MIN_CYCLES} are needed to measure a period)"
        )
    if cycles < 1.5:
        notes.append(f"the coordinate covers only {cycles:.2f} cycles over the clip; the period estimate is rough")
    period = (motion.n_frames - 1) / cycles
    lengths = cycle_lengths(u)

    t0 = time.perf_counter()
    density = PeriodicDensity(n_components=n_components, random_state=random_state).fit(theta)
    timings["density"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    k = min(n_neighbors, motion.n_frames)
    typ = typical_cycle(
        theta, prepared.poses, period, density=density, n_samples=n_samples, k=k,
        weighting=weighting, sampling=sampling, random_state=random_state, bandwidth=bandwidth,
    )
    typ, cycle_motion = loop_cycle(
        typ, motion, prepared, prep, cycle_start=cycle_start,
        metadata={"period_frames": period, "cycles_in_source": cycles},
    )
    timings["cycle"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    fps = motion.fps
    jerk = {
        "original": float(jerk_summary(prepared.poses, fps)),
        "cycle": float(jerk_summary(typ.frames, fps, cyclic=True)),
    }
    closure = float(loop_closure(typ.frames))
    dist = distance_to_cycle(prepared.poses, typ.frames)
    step = frame_steps(prepared.poses)
    distance = {
        "median": float(np.median(dist)),
        "p90": float(np.percentile(dist, 90)),
        "max": float(np.max(dist)),
        "median_frame_step": float(np.median(step)),
    }
    timings["metrics"] = time.perf_counter() - t0
    timings["total"] = sum(timings.values())
    return ExtractionResult(
        motion=motion, prepared=prepared, barcode=barcode, selection=sel, coordinate=theta,
        unwrapped=u, cycles=cycles, period_frames=float(period), cycle_frames=lengths, density=density,
        typical=typ, cycle=cycle_motion, jerk=jerk, loop_closure=closure, distance=distance,
        timings=timings, parameters=params, warnings=notes, estimator=est, preprocessor=prep,
    )
