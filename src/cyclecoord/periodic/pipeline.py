"""The periodic pipeline end to end: capture -> barcode -> circular coordinate -> typical cycle.

:func:`extract` runs every stage and returns an
:class:`~cyclecoord.periodic.results.ExtractionResult` holding each stage's output, the
quality figures and per-stage timings; ``result.cycle`` is the typical cycle as a
loopable :class:`~cyclecoord.motion.Motion`.
"""

from __future__ import annotations

import numbers
import time
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from .._blas import one_blas_thread
from .._validation import Interval, Options, check_params
from .barcode import (
    CLEAR_GAP,
    DEFAULT_PRIME,
)
from .coordinates import CircularCoordinates
from .cycle import check_bandwidth, typical_cycle
from .density import PeriodicDensity
from ..errors import NoPeriodicMotionError, ParameterError
from ..quality.metrics import distance_to_cycle, frame_steps, jerk_summary, loop_closure
from ..motion import Motion
from .preprocess import Preprocessor
from ..quality.pose_space import MAX_POP as POSE_MAX_POP, pose_quality
from .clip import capture_cycle, loop_cycle
from .windings import Windings, complete_windings, retime, stretches

__all__ = [
    "extract", "ExtractionResult", "PartialExtraction", "CycleOptions", "cycle_lengths",
    "MIN_TURNS", "TIMINGS", "TRAVELS",
]

#: Delay embedding (seconds) tried when a take's poses alone show no periodic motion.
AUTO_DELAY = 0.25
#: A cycle step over this many times the capture's 99th-percentile frame step is a warning
#: (one threshold with the console's words: quality.pose_space.MAX_POP).
MAX_POP = POSE_MAX_POP

# the result types live in .results; re-exported here, where they have always been imported
from .results import MIN_TURNS, TIMINGS, TRAVELS, CycleOptions, ExtractionResult  # noqa: E402
from .results import PartialExtraction, configured_keywords, take_cycle_options  # noqa: E402
from .fitting import MAX_SPREAD, TakeFit, not_clear_reason, rows_of, too_few_turns  # noqa: E402

def cycle_lengths(unwrapped: np.ndarray) -> np.ndarray:
    """Frames taken by each complete cycle counted from the first frame.

    The unwrapped coordinate ``u`` starts at ``u[0]``; cycle ``k`` ends where ``u`` first
    reaches ``u[0] + k`` (linearly interpolated between frames).  Returns the differences
    between successive crossing times, starting from frame 0.
    """
    u = np.asarray(unwrapped, dtype=float)
    if u.size < 2 or u[-1] - u[0] < 1:
        return np.zeros(0)
    m = np.maximum.accumulate(u)
    levels = u[0] + np.arange(1, int(np.floor(m[-1] - u[0])) + 1)
    i = np.searchsorted(m, levels, side="left")
    lo, hi = m[i - 1], m[i]
    ends = i - 1 + np.where(hi > lo, (levels - lo) / np.where(hi > lo, hi - lo, 1.0), 0.0)
    return np.diff(np.concatenate([[0.0], ends]))


@one_blas_thread
def extract(
    motion: Motion,
    frames: tuple[int | None, int | None] | None = None,
    *,
    pca: int | None = None,
    normalize: bool = False,
    temporal: bool = False,
    delay: float | str | None = "auto",
    difference_root: bool = True,
    root: str = "body",
    rotations: str = "auto",
    rig: bool = True,
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
    steady: bool = True,
    timing: str = "capture",
    travel: str = "keep",
    min_turns: float = MIN_TURNS,
    feet: Sequence[str] | str | None = None,
    cycle: CycleOptions | None = None,
    preprocessor: Preprocessor | None = None,
    estimator: CircularCoordinates | None = None,
) -> ExtractionResult:
    """Find the dominant periodic motion of a capture and its typical cycle.

    On a whole take (a standing start, a pause, a turn, a stop) the cycle is built from
    the steady stretches only (:mod:`~cyclecoord.periodic.steady`): the barcode and the
    coordinate are computed on the moving frames, the steady frames are found from the
    coordinate's pace, the poses' recurrence one period later and the heading, and the
    coordinate is fitted again on them.  The period is the median length of the
    complete windings (:mod:`~cyclecoord.periodic.windings`) and the cycle is averaged in
    a phase re-timed to the capture's pace, so each part of it takes the time it takes
    in the capture.

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
    delay : "auto", float or None, default "auto"
        Delay embedding in seconds for the filtration (out-and-back motions such as
        squats and jumping jacks then form loops); the cycle is still averaged from the
        poses.  ``"auto"``: none, and when that finds no periodic motion, once more with
        :data:`AUTO_DELAY` (a note says so); None or 0: none.
    difference_root : bool, default True
        Replace root translation/orientation by per-frame changes.
    root : {"body", "euler"}, default "body"
        Root changes as rotation vectors and steps in the root's own frame (gimbal-free,
        heading-invariant; needs the skeleton) or as Euler-channel differences (paper).
    rotations : {"auto", "rotvec", "euler"}, default "auto"
        Joint rotations as rotation vectors about each joint's mean (``"rotvec"``: Euler
        wraps and flips change nothing), the Euler channels as written (``"euler"``: the
        paper's space), or rotation vectors for just the joints whose Euler channels wrap,
        flip or near gimbal lock (``"auto"``; a CMU capture reads exactly as in the paper).
        See :class:`~cyclecoord.periodic.preprocess.Preprocessor`.
    rig : bool, default True
        Read the rig's conventions first (:func:`cyclecoord.rig.normalize_rig`): a static
        root whose child travels is folded into it, constant position channels become
        offsets, a Z-up rig is turned Y-up and a reference first frame is dropped; the
        analysis runs on that motion (``result.motion``) and the cycle is written back in
        the capture's own rig.  False analyses the channels as they are.
    prime : int, default 47
        Coefficient field Z/p, a prime greater than 11.
    max_scale : float, optional
        Filtration threshold in the analysed space's units (default: half the point
        cloud's diameter).  A bar still alive there that the cut would make fail the
        clear test is followed to its real death.
    scale : float, optional
        Scale to read the cocycle at (default: ``scale_fraction`` of the way up the bar).
    class_index : int, default 0
        Which H1 class by decreasing persistence.
    n_samples, n_neighbors, weighting, sampling, n_components
        Settings of the paper's cycle (``timing="coordinate"``): phases sampled from the
        periodic density, frames averaged per phase and how, mixture components.
        ``n_neighbors`` also bounds how short a capture may be.
    bandwidth : None, "auto" or float
        Width of the average that builds the cycle, in frames of time: None for the
        default (1 frame with ``timing="capture"``), ``"auto"`` for leave-one-out
        cross-validation, or a positive number.
    cycle_start : {"slowest", "first"}
        Where the written cycle begins: at its slowest pose (default) or at phase 0.
    landmarks : "auto", int or None
        Build the filtration on greedy max-min landmarks (``"auto"``: every frame up to
        1,000 frames, 500 landmarks beyond) and extend the coordinate to every frame.
        With ``steady``, a take of more than 300 moving frames is first read roughly, on
        150 landmarks with ``"auto"`` (:data:`~cyclecoord.periodic.fitting.FIRST_PASS_LANDMARKS`),
        to find its steady frames; the coordinate is then fitted again on those.
    memory_limit : float, optional
        Bytes the run's large arrays may take, the per-frame arrays and the filtration
        (whose landmarks are reduced to fit); default 2 GiB for the filtration alone.
        Never more than the machine's memory; a run that cannot fit is refused with a
        :class:`ParameterError` before anything large is allocated.
    require_clear : bool, default True
        Raise :class:`NoPeriodicMotionError` when the chosen bar does not stand clear.
    random_state : int, optional
        Seed for the density fit and sampling.
    steady : bool, default True
        Build the cycle from the steady stretches only (False: every frame, as the paper
        on hand-picked windows).
    timing : {"capture", "coordinate"}
        ``"capture"`` (default): the cycle is averaged in the re-timed phase and moves at
        the capture's pace; ``"coordinate"``: the paper's density-sampled coordinate.
    travel : {"keep", "straight", "in_place"}
        The cycle's root: turn and travel as the capture did on average, walk straight
        (heading change per cycle removed) or stay in place.
    min_turns : float, default 1.5
        Fewer turns of the coordinate over the steady frames is no periodic motion.
    feet : sequence of str, or str, optional
        Foot point joint names (ankle then toe of each leg, e.g. ``("Foot_L", "Toes_L",
        "Foot_R", "Toes_R")``, or the command line's ``"Foot_L:Toes_L,Foot_R:Toes_R"``)
        whose contacts carry the cycle's root and whose skating the report gives; default
        :func:`~cyclecoord.quality.legs.find_legs` (names of the common rigs, else the
        geometry).
    cycle : CycleOptions, optional
        The cycle's options as one object (timing, travel, bandwidth, cycle_start,
        n_samples, n_neighbors, weighting, sampling, min_turns), instead of keywords.
    preprocessor : Preprocessor, optional
        A configured (not necessarily fitted) :class:`Preprocessor` whose parameters
        (difference_root, normalize, pca, root, delay in frames) replace the keywords of
        the same meaning; its delay is used as given (no automatic retry).
    estimator : CircularCoordinates, optional
        A configured :class:`CircularCoordinates` whose parameters (max_scale, scale,
        class_index, prime, scale_fraction, temporal, landmarks, memory_limit) replace
        the keywords of the same names.  Neither object is fitted or changed.

    Returns
    -------
    ExtractionResult

    Raises
    ------
    NoPeriodicMotionError
        When no bar stands clear or the steady frames hold under ``min_turns`` turns (its
        ``result`` attribute holds a :class:`PartialExtraction`).
    ParameterError
        For invalid arguments.
    """
    if preprocessor is not None or estimator is not None:
        chosen = configured_keywords(motion, preprocessor, estimator, dict(
            difference_root=difference_root, normalize=normalize, pca=pca, root=root, delay=delay,
            rotations=rotations, max_scale=max_scale, scale=scale, class_index=class_index,
            prime=prime,
            scale_fraction=scale_fraction, temporal=temporal, landmarks=landmarks,
            memory_limit=memory_limit))
        options = {k: v for k, v in locals().items() if k not in (
            "motion", "frames", "preprocessor", "estimator", "chosen", *chosen)}
        return extract(motion, frames=frames, **options, **chosen)
    if cycle is not None:
        given = dict(timing=timing, travel=travel, bandwidth=bandwidth, cycle_start=cycle_start,
                     n_samples=n_samples, n_neighbors=n_neighbors, weighting=weighting,
                     sampling=sampling, min_turns=min_turns)
        chosen = take_cycle_options(cycle, given, "extract()")
        options = {k: v for k, v in locals().items()
                   if k not in ("motion", "frames", "cycle", "given", "chosen", *chosen)}
        return extract(motion, frames=frames, **options, **chosen)
    if isinstance(delay, str):
        if delay != "auto":
            raise ParameterError(
                f"delay must be 'auto', a number of seconds or None, got {delay!r}"
            )
        options = {k: v for k, v in locals().items() if k not in ("motion", "frames", "delay")}
        return _with_auto_delay(motion, frames, options)
    opts = _check_options(
        motion,
        weighting=weighting,
        sampling=sampling,
        cycle_start=cycle_start,
        n_samples=n_samples,
        n_neighbors=n_neighbors,
        bandwidth=bandwidth,
        timing=timing,
        travel=travel,
        min_turns=min_turns,
        normalize=normalize,
        temporal=temporal,
        difference_root=difference_root,
        rotations=rotations,
        steady=steady,
        pca=pca,
        class_index=class_index,
        scale_fraction=scale_fraction,
        random_state=random_state,
    )
    bandwidth = opts["bandwidth"]
    if feet is not None:
        from ..quality.legs import feet_names

        if motion.skeleton is None:
            raise ParameterError("feet= needs a motion with a skeleton")
        feet = feet_names(motion.skeleton, feet)
    params = dict(
        frames=None if frames is None else list(frames), pca=pca, normalize=normalize,
        temporal=temporal, delay=delay, difference_root=difference_root, root=root, prime=prime,
        rotations=rotations, rig=rig, max_scale=max_scale, scale=scale,
        class_index=class_index, scale_fraction=scale_fraction,
        n_samples=n_samples, n_neighbors=n_neighbors, bandwidth=bandwidth, weighting=weighting,
        sampling=sampling, n_components=n_components, cycle_start=cycle_start,
        landmarks=landmarks, memory_limit=memory_limit, random_state=random_state, steady=steady,
        timing=timing, travel=travel, min_turns=min_turns,
        feet=None if feet is None else list(feet),
    )
    motion, info, adapter = _analysis_motion(motion.window(frames), n_neighbors, rig)
    run = TakeFit(motion, params, require_clear)
    fit, used = run.fit_steady()
    res = _finish(
        motion, run.prepared, run.prep, fit, used, run.notes, run.timings, params, run.fail,
        n_components=n_components, n_samples=n_samples, n_neighbors=n_neighbors,
        weighting=weighting, sampling=sampling, bandwidth=bandwidth, random_state=random_state,
        cycle_start=cycle_start, timing=timing, travel=travel, min_turns=min_turns,
        feet=feet,
    )
    if adapter is not None:
        # the cycle in the capture's own rig (static root, position channels, up axis)
        res = replace(res, cycle=adapter.restore(res.cycle), rig_changes=adapter.changes())
    return replace(res, rig=info)


def _analysis_motion(motion: Motion, n_neighbors: int, rig: bool):
    """The window to analyse in the analysis rig: ``(motion, rig info, adapter)``, the
    adapter None when nothing changed (or ``rig`` is False), info None without a
    skeleton; too few frames are refused."""
    if motion.n_frames < 2 * n_neighbors or motion.n_frames < 10:
        raise ParameterError(
            f"{motion.source or 'capture'}: {motion.n_frames} frames are too few to find a cycle "
            f"(need at least {max(10, 2 * n_neighbors)})"
        )
    adapter = info = None
    if motion.skeleton is not None:
        from ..rig import describe_rig, normalize_rig

        info = describe_rig(motion)
        if rig:
            motion, adapter = normalize_rig(motion, info)
            if adapter.identity:
                adapter = None
    return motion, info, adapter


def _with_auto_delay(motion: Motion, frames, options: dict) -> ExtractionResult:
    """``delay="auto"``: :func:`extract` without a delay embedding, and when that finds no
    periodic motion, once more with :data:`AUTO_DELAY` (a warning says what the poses
    alone showed); the first refusal is raised when both refuse."""
    try:
        return extract(motion, frames=frames, delay=None, **options)
    except NoPeriodicMotionError as first:
        try:
            res = extract(motion, frames=frames, delay=AUTO_DELAY, **options)
        except NoPeriodicMotionError:
            raise first from None
        # what the poses alone showed: the refusal's reason, without the file it names
        # and without its advice (the delay was what helped)
        reason = getattr(first.result, "reason", None) or str(first)
        seen = reason.removeprefix("no periodic motion found: ").split("; ")[0]
        res.warnings.insert(
            0,
            f"read with a {AUTO_DELAY:g} s delay embedding (each pose joined by the pose "
            f"{AUTO_DELAY:g} s later), because the poses alone showed no periodic motion: "
            f"{seen}",
        )
        return res


#: What :func:`extract`'s options may be (:mod:`cyclecoord._validation`); the scale and
#: landmark options are checked where they are used (their messages name the data).
EXTRACT_CONSTRAINTS = {
    "weighting": [Options("kernel", "mean", "gaussian")],
    "sampling": [Options("quantile", "random")],
    "cycle_start": [Options("slowest", "first")],
    "timing": [Options(*TIMINGS)],
    "travel": [Options(*TRAVELS)],
    "min_turns": [Interval(numbers.Real, 0, None, closed="neither")],
    "n_samples": [Interval(numbers.Integral, 10, None)],
    "n_neighbors": [Interval(numbers.Integral, 1, None)],
    "normalize": ["boolean"],
    "temporal": ["boolean"],
    "difference_root": ["boolean"],
    "rotations": [Options("auto", "rotvec", "euler")],
    "steady": ["boolean"],
    "pca": [Interval(numbers.Integral, 1, None), None],
    "class_index": [Interval(numbers.Integral, 0, None)],
    "scale_fraction": [Interval(numbers.Real, 0, 1, closed="right")],
    "random_state": [Interval(numbers.Integral, 0, None), None],
}


def _check_options(motion, **o) -> dict:
    if not isinstance(motion, Motion):
        raise ParameterError(f"extract() takes a Motion, got {type(motion).__name__}")
    check_params(o, EXTRACT_CONSTRAINTS, "extract()")
    weighting = o["weighting"] if o["timing"] == "coordinate" else "kernel"
    o["bandwidth"] = check_bandwidth(o["bandwidth"], weighting)  # before any work is done
    return o


def _run_jerk(poses: np.ndarray, runs: list[tuple[int, int]], fps: float) -> float:
    """Mean jerk over runs of frames (each run differentiated on its own)."""
    vals, weights = [], []
    for a, b in runs:
        if b - a >= 8:
            vals.append(jerk_summary(poses[a:b], fps))
            weights.append(b - a)
    return float(np.average(vals, weights=weights)) if vals else float("nan")


def _finish(
    motion, prepared, prep, fit, used, notes, timings, params, fail, **o
) -> ExtractionResult:
    """Windings, period, cycle and figures of a fitted coordinate on the used frames."""
    T = motion.n_frames
    runs = stretches(used)
    u = np.where(used, fit.unwrapped, np.nan)
    wind, period = _windings(fit, used, u, runs, notes, fail, o["min_turns"])
    theta = np.full(T, np.nan)
    theta[fit.rows] = fit.est.coordinates_
    theta[~used] = np.nan
    rows = np.flatnonzero(used)
    t0 = time.perf_counter()
    density = PeriodicDensity(n_components=o["n_components"], random_state=o["random_state"]).fit(
        theta[rows]
    )
    timings["density"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    typ, cycle_motion, phase, heading_change = _make_cycle(
        motion, prepared, prep, theta, rows, u, runs, wind, period, density, o
    )
    timings["cycle"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    jerk, closure, distance = _cycle_figures(prepared, typ, runs, rows, motion.fps)
    poses = pose_quality(cycle_motion, motion, runs, period)
    if poses is not None and poses.figures is not None:
        # the figures every command prints, on joint positions (quality.pose_space)
        jerk = {"original": poses.capture_jerk, "cycle": poses.figures.jerk}
        closure = poses.figures.loop_closure
    pop = poses.pop if poses is not None else (
        distance["largest_cycle_step"] / distance["p99_frame_step"])
    if np.isfinite(pop) and pop > MAX_POP:
        notes.append(
            f"the cycle pops: its largest frame step is {pop:.1f}x the capture's "
            "99th-percentile step (its repetitions disagree there); look at the channels "
            "figure, and try --bandwidth 2 or --frames on a steadier stretch"
        )
    if poses is not None and poses.strays:
        notes.append(
            f"some cycle poses are {poses.nearest_max:.1f}x the capture's own spread from the "
            "nearest captured pose (a pose the actor never held); try --rotations rotvec, "
            "--frames on a steadier stretch or --bandwidth 2"
        )
    timings["metrics"] = time.perf_counter() - t0
    timings["total"] = sum(v for k, v in timings.items())
    return ExtractionResult(
        motion=motion,
        prepared=prepared,
        barcode=fit.barcode,
        selection=fit.selection,
        coordinate=theta,
        unwrapped=u,
        cycles=float(wind.turns),
        period_frames=float(period),
        cycle_frames=wind.lengths,
        density=density,
        typical=typ,
        cycle=cycle_motion,
        jerk=jerk,
        loop_closure=closure,
        distance=distance,
        timings=timings,
        parameters=params,
        warnings=notes,
        estimator=fit.est,
        preprocessor=prep,
        used=used,
        phase=phase,
        windings=wind,
        heading_per_cycle=heading_change,
        pose_quality=poses,
    )


def _windings(fit, used, u, runs, notes, fail, min_turns) -> tuple[Windings, float]:
    """The complete windings on the used frames and the period; refuses too few turns and a
    bar clear only but for its gap whose coordinate winds irregularly."""
    wind = complete_windings(u, runs)
    if wind.turns < min_turns:
        raise fail(too_few_turns(wind.turns, int(used.sum()), min_turns), fit)
    if fit.weak_gap:
        if wind.spread > MAX_SPREAD or not np.isfinite(wind.period_frames):
            raise fail(
                f"no periodic motion found: {not_clear_reason(fit.selection, fit.barcode)}, and "
                "its coordinate "
                f"winds irregularly (complete windings spread {wind.spread:.0%} of the period); "
                "try --max-scale, --pca or --frames",
                fit,
            )
        notes.append(
            f"the H1 bar stands only {fit.selection.gap:.2f}x the next bar's persistence (under "
            f"{CLEAR_GAP}x); "
            f"accepted because its coordinate winds {wind.turns:.1f} times, regularly (spread "
            f"{wind.spread:.0%})"
        )
    period = wind.period_frames
    if not np.isfinite(period):
        period = float(np.sum(used) - len(runs)) / wind.turns
    if wind.spread > MAX_SPREAD:
        notes.append(
            f"the complete windings vary by {wind.spread:.0%} of the period (p10-p90); the motion "
            "is not "
            "steady: use --frames to pick one steady stretch, or check the coordinate figure"
        )
    if fit.est.n_components_ > 1:
        notes.append(
            f"the complex at scale {fit.selection.scale:.4g} has {fit.est.n_components_} "
            "connected components: "
            "frames in different components get unrelated coordinates; raise --max-scale or --scale"
        )
    return wind, period


def _make_cycle(motion, prepared, prep, theta, rows, u, runs, wind, period, density, o):
    """The typical cycle and its clip, timed by the capture (default) or the coordinate;
    also the re-timed phase per frame and the heading change per cycle."""
    phase = np.full(motion.n_frames, np.nan)
    heading_change = float("nan")
    meta = {"period_frames": period, "cycles_in_source": wind.turns}
    if o["timing"] == "coordinate":
        typ = typical_cycle(
            theta[rows],
            prepared.poses[rows],
            period,
            density=density,
            n_samples=o["n_samples"],
            k=min(o["n_neighbors"], rows.size),
            weighting=o["weighting"],
            sampling=o["sampling"],
            random_state=o["random_state"],
            bandwidth=o["bandwidth"],
        )
        typ, cycle_motion = loop_cycle(
            typ, motion, prepared, prep, cycle_start=o["cycle_start"], rows=rows, metadata=meta
        )
    else:
        phase = retime(u, runs, wind)
        typ, cycle_motion, heading_change = capture_cycle(
            phase,
            motion,
            prepared,
            prep,
            period,
            bandwidth=o["bandwidth"],
            cycle_start=o["cycle_start"],
            travel=o["travel"],
            k=o["n_neighbors"],
            feet=o["feet"],
            metadata=meta,
        )
    return typ, cycle_motion, phase, heading_change


def _cycle_figures(prepared, typ, runs, rows, fps) -> tuple[dict, float, dict]:
    """Jerk (capture and cycle), loop closure and the distance of the used frames to the
    cycle."""
    jerk = {
        "original": _run_jerk(prepared.poses, runs, fps),
        "cycle": float(jerk_summary(typ.frames, fps, cyclic=True)),
    }
    closure = float(loop_closure(typ.frames))
    dist = distance_to_cycle(rows_of(prepared.poses, rows), typ.frames)
    step = np.concatenate([frame_steps(prepared.poses[a:b]) for a, b in runs])
    cyc = np.linalg.norm(np.roll(typ.frames, -1, axis=0) - typ.frames, axis=1)
    distance = {
        "median": float(np.median(dist)),
        "p90": float(np.percentile(dist, 90)),
        "max": float(np.max(dist)),
        "median_frame_step": float(np.median(step)) if step.size else float("nan"),
        "p99_frame_step": float(np.percentile(step, 99)) if step.size else float("nan"),
        "largest_cycle_step": float(cyc.max()) if cyc.size else float("nan"),
    }
    return jerk, closure, distance
