"""The periodic pipeline end to end: capture -> barcode -> circular coordinate -> typical cycle.

:func:`extract` runs every stage and returns an
:class:`~cyclecoord.periodic.results.ExtractionResult` holding each stage's output, the
quality figures and per-stage timings; ``result.cycle`` is the typical cycle as a
loopable :class:`~cyclecoord.motion.Motion`.
"""

from __future__ import annotations

import numbers
import time
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._blas import one_blas_thread
from .._validation import Interval, Options, check_params
from .barcode import (
    CLEAR_GAP,
    CLEAR_MIN_FRACTION,
    CLEAR_RATIO,
    DEFAULT_PRIME,
    Barcode,
    BarSelection,
    refine_birth,
    select_bar,
)
from .coordinates import REFINE_BYTES_PER_EDGE, CircularCoordinates, unwrap
from .cycle import check_bandwidth, typical_cycle
from .density import PeriodicDensity
from ..errors import NoPeriodicMotionError, ParameterError
from ..quality.metrics import distance_to_cycle, frame_steps, jerk_summary, loop_closure
from ..motion import Motion
from .preprocess import Preprocessor
from .clip import capture_cycle, joint_columns, loop_cycle
from .root import heading, root_layout
from .steady import moving_mask, period_speed, recurrence, steady_mask
from .windings import Windings, complete_windings, retime, stretches

__all__ = [
    "extract", "ExtractionResult", "PartialExtraction", "CycleOptions", "cycle_lengths",
    "MIN_TURNS", "TIMINGS", "TRAVELS",
]

# the result types live in .results; re-exported here, where they have always been imported
from .results import MIN_TURNS, TIMINGS, TRAVELS, CycleOptions, ExtractionResult  # noqa: E402
from .results import PartialExtraction, _take_cycle_options  # noqa: E402

#: Complete windings varying by more than this (p10-p90 over the median) are not steady.
MAX_SPREAD = 0.25
#: A bar alive at the threshold is followed until the threshold is this many times its birth.
ALIVE_RATIO = 4.0
#: Delay embedding (seconds) tried when a take's poses alone show no periodic motion.
AUTO_DELAY = 0.25
#: Landmarks of the rough first pass over a long take (which finds its steady frames).
FIRST_PASS_LANDMARKS = 150


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


def _first_clear(
    est: CircularCoordinates, points: np.ndarray, class_index: int, scale, scale_fraction: float
):
    """Barcode of ``points`` and the chosen bar, judged by its real death.

    A bar still alive at the threshold reads a death/birth ratio and a gap cut by the
    threshold, and its cocycle would be read low in the bar.  While the chosen bar is
    alive at the threshold and either fails the clear test or lives less than
    :data:`ALIVE_RATIO` times its birth, the threshold is raised (1.6x at a time, at most
    6 times, never past the point cloud's diameter), and the bar is judged, and read, on
    the longer filtration.  ``--max-scale 12`` on CMU 69_01 200:450 (bar born at 9.955)
    is so raised to 49.2 and gives the coordinate of ``--max-scale 50``.
    """
    from .barcode import default_max_scale

    barcode = est.fit_barcode(points)
    if len(barcode.h1) == 0 or class_index >= len(barcode.h1):
        return barcode, None
    sel = select_bar(barcode, class_index, scale, scale_fraction)
    diameter = 2.0 * default_max_scale(points)
    tries = 0
    def cut_short(s: BarSelection, bc: Barcode) -> bool:
        return s.death >= bc.threshold and (not s.clear or bc.threshold < ALIVE_RATIO * s.birth)

    while scale is None and cut_short(sel, barcode) and tries < 6 and barcode.threshold < diameter:
        birth = sel.birth
        old = est.max_scale
        est.max_scale = min(barcode.threshold * 1.6, diameter)
        try:
            longer = est.fit_barcode(points)
        finally:
            est.max_scale = old
        match = (
            np.flatnonzero(np.isclose(longer.h1[:, 0], birth, rtol=1e-9, atol=1e-12))
            if len(longer.h1)
            else []
        )
        if not len(match):
            break
        barcode = longer
        est.class_index = int(match[0])
        sel = select_bar(barcode, int(match[0]), scale, scale_fraction)
        tries += 1
    return barcode, sel


def _not_clear_reason(sel: BarSelection, barcode: Barcode) -> str:
    why = []
    if sel.ratio < CLEAR_RATIO:
        why.append(f"death/birth {sel.ratio:.2f} < {CLEAR_RATIO}")
    if sel.gap < CLEAR_GAP:
        why.append(f"persistence only {sel.gap:.2f}x the next bar's (< {CLEAR_GAP}x)")
    if not why:
        why.append(
            f"persistence under {CLEAR_MIN_FRACTION:.0%} of the threshold {barcode.threshold:.4g}"
        )
    ds = "inf" if not np.isfinite(sel.death) else f"{sel.death:.4g}"
    return f"H1 bar #{sel.index} [{sel.birth:.4g}, {ds}) does not stand clear ({'; '.join(why)})"


def _unwrap_runs(
    theta: np.ndarray, rows: np.ndarray, runs: list[tuple[int, int]], n: int
) -> np.ndarray:
    """The coordinate of ``rows`` unwrapped inside each run, NaN elsewhere (length ``n``)."""
    full = np.full(n, np.nan)
    full[rows] = theta
    out = np.full(n, np.nan)
    for a, b in runs:
        if b > a:
            out[a:b] = unwrap(full[a:b])
    return out


@dataclass
class _Fit:
    """One barcode + coordinate fit on some rows of a capture."""

    est: CircularCoordinates
    barcode: Barcode
    selection: BarSelection
    rows: np.ndarray
    unwrapped: np.ndarray  # (T,), NaN outside rows
    notes: list
    weak_gap: bool = False  # clear but for the gap to the next bar


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
        chosen = _configured(motion, preprocessor, estimator, dict(
            difference_root=difference_root, normalize=normalize, pca=pca, root=root, delay=delay,
            max_scale=max_scale, scale=scale, class_index=class_index, prime=prime,
            scale_fraction=scale_fraction, temporal=temporal, landmarks=landmarks,
            memory_limit=memory_limit))
        options = {k: v for k, v in locals().items() if k not in (
            "motion", "frames", "preprocessor", "estimator", "chosen", *chosen)}
        return extract(motion, frames=frames, **options, **chosen)
    if cycle is not None:
        given = dict(timing=timing, travel=travel, bandwidth=bandwidth, cycle_start=cycle_start,
                     n_samples=n_samples, n_neighbors=n_neighbors, weighting=weighting,
                     sampling=sampling, min_turns=min_turns)
        chosen = _take_cycle_options(cycle, given, "extract()")
        options = {k: v for k, v in locals().items()
                   if k not in ("motion", "frames", "cycle", "given", "chosen", *chosen)}
        return extract(motion, frames=frames, **options, **chosen)
    if isinstance(delay, str):
        if delay != "auto":
            raise ParameterError(
                f"delay must be 'auto', a number of seconds or None, got {delay!r}"
            )
        options = {k: v for k, v in locals().items() if k not in ("motion", "frames", "delay")}
        try:
            return extract(motion, frames=frames, delay=None, **options)
        except NoPeriodicMotionError as first:
            try:
                res = extract(motion, frames=frames, delay=AUTO_DELAY, **options)
            except NoPeriodicMotionError:
                raise first from None
            res.warnings.insert(
                0,
                f"read with a {AUTO_DELAY:g} s delay embedding: the poses alone show no "
                "periodic motion (an out-and-back movement, such as a squat)",
            )
            return res
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
        steady=steady,
        pca=pca,
        class_index=class_index,
        scale_fraction=scale_fraction,
        random_state=random_state,
    )
    bandwidth = opts["bandwidth"]
    params = dict(
        frames=None if frames is None else list(frames), pca=pca, normalize=normalize,
        temporal=temporal, delay=delay, difference_root=difference_root, root=root, prime=prime,
        max_scale=max_scale, scale=scale, class_index=class_index, scale_fraction=scale_fraction,
        n_samples=n_samples, n_neighbors=n_neighbors, bandwidth=bandwidth, weighting=weighting,
        sampling=sampling, n_components=n_components, cycle_start=cycle_start,
        landmarks=landmarks, memory_limit=memory_limit, random_state=random_state, steady=steady,
        timing=timing, travel=travel, min_turns=min_turns,
    )
    motion = motion.window(frames)
    if motion.n_frames < 2 * n_neighbors or motion.n_frames < 10:
        raise ParameterError(
            f"{motion.source or 'capture'}: {motion.n_frames} frames are too few to find a cycle "
            f"(need at least {max(10, 2 * n_neighbors)})"
        )
    run = _Run(motion, params, require_clear)
    fit, used = run.fit_steady()
    return _finish(
        motion, run.prepared, run.prep, fit, used, run.notes, run.timings, params, run.fail,
        n_components=n_components, n_samples=n_samples, n_neighbors=n_neighbors,
        weighting=weighting, sampling=sampling, bandwidth=bandwidth, random_state=random_state,
        cycle_start=cycle_start, timing=timing, travel=travel, min_turns=min_turns,
    )


#: extract's defaults for the settings a Preprocessor or CircularCoordinates can carry.
_CONFIGURED_DEFAULTS = dict(
    difference_root=True, normalize=False, pca=None, root="body", delay="auto",
    max_scale=None, scale=None, class_index=0, prime=DEFAULT_PRIME, scale_fraction=0.9,
    temporal=False, landmarks="auto", memory_limit=None,
)


def _configured(
    motion,
    preprocessor,
    estimator,
    given: dict[str, Any],
    defaults: dict[str, Any] = _CONFIGURED_DEFAULTS,
    where: str = "extract()",
) -> dict[str, Any]:
    """Keywords of ``where`` (extract or detect) from configured objects; a keyword changed
    from its default beside the object that carries it is an error.  Only the estimator's
    parameters named in ``given`` are taken."""
    chosen: dict[str, Any] = {}
    if preprocessor is not None:
        if not isinstance(preprocessor, Preprocessor):
            raise ParameterError(
                f"{where}: preprocessor must be a Preprocessor, got {type(preprocessor).__name__}"
            )
        lag = preprocessor.delay
        fps = getattr(motion, "fps", None) or 1.0
        chosen.update(difference_root=preprocessor.difference_root,
                      normalize=preprocessor.normalize, pca=preprocessor.pca,
                      root=preprocessor.root, delay=None if not lag else float(lag) / fps)
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


class _Run:
    """One extraction's fitting steps on a windowed capture: preparation, the barcode and
    coordinate on some rows, the steady frames.  ``params`` are :func:`extract`'s (checked).
    """

    def __init__(self, motion: Motion, params: dict[str, Any], require_clear: bool) -> None:
        self.motion, self.p, self.require_clear = motion, params, require_clear
        self.T = motion.n_frames
        self.timings: dict[str, float] = {}
        self.notes: list[str] = []
        t0 = time.perf_counter()
        p = params
        lag = int(round(p["delay"] * motion.fps)) if p["delay"] else None
        self.prep = Preprocessor(difference_root=p["difference_root"], normalize=p["normalize"],
                                 pca=p["pca"], root=p["root"], delay=lag)
        self.prepared = self.prep.fit_transform(motion)
        self.joints = joint_columns(motion, self.prepared)
        T, steady = self.T, p["steady"]
        moving = (
            moving_mask(self.prepared.poses, motion.fps, columns=self.joints)
            if steady
            else np.ones(T, dtype=bool)
        )
        if not steady or moving.sum() >= 0.95 * T or moving.sum() < max(10, 2 * p["n_neighbors"]):
            moving = np.ones(T, dtype=bool)
        self.moving = moving
        self.timings["prepare"] = time.perf_counter() - t0

    def make_estimator(self, first_pass: bool = False) -> CircularCoordinates:
        p = self.p
        lm = p["landmarks"]
        if first_pass and isinstance(lm, str) and lm == "auto":
            lm = FIRST_PASS_LANDMARKS
        return CircularCoordinates(
            max_scale=p["max_scale"], scale=p["scale"], class_index=p["class_index"],
            prime=p["prime"], scale_fraction=p["scale_fraction"], temporal=p["temporal"],
            landmarks=lm, refine_birth=False, memory_limit=p["memory_limit"],
            # poses beyond the points
            memory_reserved=8.0 * max(0, self.prepared.poses.size - self.prepared.points.size),
        )

    def fail(
        self, msg: str, fit: _Fit | None = None, barcode: Barcode | None = None
    ) -> NoPeriodicMotionError:
        partial = PartialExtraction(
            motion=self.motion,
            prepared=self.prepared,
            reason=msg,
            barcode=barcode if fit is None else fit.barcode,
            selection=None if fit is None else fit.selection,
            timings=self.timings,
            parameters=self.p,
            warnings=self.notes,
            estimator=None if fit is None else fit.est,
            preprocessor=self.prep,
        )
        where = self.motion.source or "capture"
        return NoPeriodicMotionError(f"{where}: {msg}", result=partial)

    def coordinate_of(self, est: CircularCoordinates, rows: np.ndarray) -> _Fit:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            est.fit_coordinate()
        u = _unwrap_runs(est.coordinates_, rows, _row_runs(rows), self.T)
        return _Fit(est=est, barcode=est.barcode_, selection=est.selection_, rows=rows,
                    unwrapped=u, notes=[str(w.message) for w in caught])

    def fit_rows(self, rows: np.ndarray, stage: str, first_pass: bool = False) -> _Fit:
        """Barcode and coordinate on ``rows``; refuses a barcode with no clear bar."""
        p = self.p
        class_index, scale = p["class_index"], p["scale"]
        est = self.make_estimator(first_pass)
        t0 = time.perf_counter()
        barcode, sel = _first_clear(
            est, _rows_of(self.prepared.points, rows), class_index, scale, p["scale_fraction"]
        )
        self.timings[f"barcode{stage}"] = time.perf_counter() - t0
        if sel is None:
            if len(barcode.h1) and class_index >= len(barcode.h1):
                raise ParameterError(
                    f"class index {class_index} out of range: the barcode has {len(barcode.h1)} "
                    "H1 bars"
                )
            raise self.fail(
                "no periodic motion found: the barcode has no H1 bar up to scale "
                f"{barcode.threshold:.4g}",
                barcode=barcode,
            )
        # a bar that is clear but for its gap to the next one (long takes hold several
        # loops) is judged by its coordinate's windings instead (see _finish)
        gap_only = sel.ratio >= CLEAR_RATIO and sel.gap < CLEAR_GAP and (
            barcode.persistence(1)[sel.index] >= CLEAR_MIN_FRACTION * barcode.threshold)
        if self.require_clear and not sel.clear and not first_pass and not gap_only:
            raise self.fail(f"no periodic motion found: {_not_clear_reason(sel, barcode)}; "
                            "try --max-scale, --pca or --frames", barcode=barcode)
        t0 = time.perf_counter()
        fit = self.coordinate_of(est, rows)
        if class_index == 0 and scale is None and len(barcode.h1) > 1:
            fit = self._other_class(fit, est, barcode, rows)
        if not first_pass and fit.est.landmarks_ is not None and not p["temporal"]:
            self._refine_birth(fit, rows)
        self.timings[f"coordinate{stage}"] = time.perf_counter() - t0
        fit.weak_gap = bool(self.require_clear and not fit.selection.clear)
        return fit

    def _other_class(self, fit: _Fit, est: CircularCoordinates, barcode: Barcode,
                     rows: np.ndarray) -> _Fit:
        """The most persistent class of a long take can be a loop of the whole take (a
        circuit, a drift); a later clear class that winds regularly is the motion's."""
        min_turns = self.p["min_turns"]
        wind = complete_windings(fit.unwrapped, _row_runs(rows))
        j = 1
        while (wind.turns < min_turns or not wind.spread <= MAX_SPREAD) and j < min(
            4, len(barcode.h1)
        ):
            other = select_bar(barcode, j, None, self.p["scale_fraction"])
            if other.ratio >= CLEAR_RATIO:
                try:
                    alt = self.coordinate_of(est.with_coordinate_params(class_index=j), rows)
                except ParameterError:
                    alt = None
                alt_wind = (
                    complete_windings(alt.unwrapped, _row_runs(rows)) if alt is not None else None
                )
                if alt_wind is not None and alt_wind.turns >= min_turns and (
                    alt_wind.spread <= MAX_SPREAD
                ):
                    alt.notes.append(
                        f"H1 class #{j} chosen: the most persistent class turns "
                        f"{wind.turns:.2f} times over the frames (spread {wind.spread:.0%}), "
                        f"class #{j} {alt_wind.turns:.2f} times, regularly"
                    )
                    return alt
            j += 1
        return fit

    def _refine_birth(self, fit: _Fit, rows: np.ndarray) -> None:
        """The class's birth on every frame, for the report (landmarks are born later)."""
        budget = getattr(fit.est, "memory_budget_", None)
        max_edges = (
            3_000_000 if budget is None else int(min(3_000_000, budget / REFINE_BYTES_PER_EDGE))
        )
        full = (
            refine_birth(
                _rows_of(self.prepared.points, rows),
                fit.selection.birth,
                fit.est.prime_,
                max_edges=max_edges,
                covering_radius=fit.est.covering_radius_,
                coordinate=fit.est.coordinates_,
            )
            if max_edges > 0
            else None
        )
        fit.selection = BarSelection(**{**fit.selection.__dict__, "full_birth": full})
        fit.est.selection_ = fit.selection

    def fit_steady(self) -> tuple[_Fit, np.ndarray]:
        """The coordinate fitted on the take's steady frames, and those frames.

        A long take is first read on a few landmarks (enough to find its steady frames);
        the coordinate is fitted again on the steady frames when they are not all the
        moving frames.
        """
        steady, moving, timings = self.p["steady"], self.moving, self.timings
        min_turns = self.p["min_turns"]
        rows = np.flatnonzero(moving)
        rough = steady and rows.size > FIRST_PASS_LANDMARKS * 2
        fit = self.fit_rows(rows, " (first pass)" if steady else "", first_pass=rough)
        used = moving
        if steady:
            t0 = time.perf_counter()
            first = complete_windings(fit.unwrapped, stretches(moving))
            if np.isfinite(first.period_frames):
                used = _steady_frames(self.motion, self.prepared, self.joints, fit.unwrapped,
                                      moving, first.period_frames)
            if used.sum() >= 0.95 * moving.sum():
                used = moving
            refit = rough or used.sum() < moving.sum()
            first_pass = [
                timings.pop(k) for k in ("barcode (first pass)", "coordinate (first pass)")
            ]
            # stages: "steady" is the time spent finding the steady frames (a first pass when
            # the coordinate is fitted again on them); "barcode" and "coordinate" the final fit
            timings["steady"] = time.perf_counter() - t0 + (sum(first_pass) if refit else 0.0)
            if not refit:
                timings["barcode"], timings["coordinate"] = first_pass
            if first.turns < min_turns:
                raise self.fail(_too_few_turns(first.turns, int(moving.sum()), min_turns), fit)
            if not used.any():
                raise self.fail(
                    "no periodic motion found: no stretch of the take repeats steadily for a "
                    f"whole period (the coordinate turns {first.turns:.2f} times over the moving "
                    "frames); check the coordinate figure (--plot), or try --no-steady or --frames",
                    fit,
                )
            if refit:
                fit = self.fit_rows(np.flatnonzero(used), "")
        self.notes.extend(fit.notes)
        if steady and moving.sum() - (used & moving).sum() > 0.5 * moving.sum():
            # most of the moving frames are not this motion: a routine of several exercises,
            # or a dance whose one steady figure is not the take
            self.notes.append(
                f"only {int(used.sum())} of the take's {int(moving.sum())} moving frames repeat "
                "this motion steadily; the rest may be other motions: `cyclecoord detect` finds "
                "each motion of a take that holds several"
            )
        return fit, used


def _rows_of(x: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``x[rows]``, as a view when the rows are one contiguous run (no copy of a long take)."""
    if rows.size and rows[-1] - rows[0] + 1 == rows.size:
        return x[rows[0] : rows[-1] + 1]
    return x[rows]


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


def _row_runs(rows: np.ndarray) -> list[tuple[int, int]]:
    """Runs of consecutive frame indices in a sorted index array."""
    if rows.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(rows) > 1)
    starts = np.concatenate([[0], breaks + 1])
    stops = np.concatenate([breaks + 1, [rows.size]])
    return [(int(rows[a]), int(rows[b - 1]) + 1) for a, b in zip(starts, stops)]


def _steady_frames(motion, prepared, joints, unwrapped, moving, period) -> np.ndarray:
    """Steady frames of a take (see :mod:`~cyclecoord.periodic.steady`)."""
    rec = recurrence(prepared.poses, period, columns=joints)
    layout = root_layout(motion)
    hd = heading(motion.frames, layout) if layout is not None else None
    speed = period_speed(prepared.poses, motion.fps, period, columns=joints)
    return steady_mask(unwrapped, moving, period, recurrence_distance=rec, heading=hd, speed=speed)


def _too_few_turns(turns: float, n_frames: int, min_turns: float) -> str:
    return (
        f"no periodic motion found: the coordinate turns only {turns:.2f} times over the "
        f"{n_frames} "
        f"steady frames (at least {min_turns:g} are needed to call a motion periodic); a longer "
        "take, "
        "--frames around the repeated part, or --pca 3 may help"
    )


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
    )


def _windings(fit, used, u, runs, notes, fail, min_turns) -> tuple[Windings, float]:
    """The complete windings on the used frames and the period; refuses too few turns and a
    bar clear only but for its gap whose coordinate winds irregularly."""
    wind = complete_windings(u, runs)
    if wind.turns < min_turns:
        raise fail(_too_few_turns(wind.turns, int(used.sum()), min_turns), fit)
    if fit.weak_gap:
        if wind.spread > MAX_SPREAD or not np.isfinite(wind.period_frames):
            raise fail(
                f"no periodic motion found: {_not_clear_reason(fit.selection, fit.barcode)}, and "
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
    dist = distance_to_cycle(_rows_of(prepared.poses, rows), typ.frames)
    step = np.concatenate([frame_steps(prepared.poses[a:b]) for a, b in runs])
    distance = {
        "median": float(np.median(dist)),
        "p90": float(np.percentile(dist, 90)),
        "max": float(np.max(dist)),
        "median_frame_step": float(np.median(step)) if step.size else float("nan"),
    }
    return jerk, closure, distance
