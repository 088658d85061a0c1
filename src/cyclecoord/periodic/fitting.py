"""Fitting a take's circular coordinate: the first clear bar (judged by its real death),
another class when the most persistent one is a loop of the whole take, the steady frames,
and the class's birth on every frame.  :class:`TakeFit` runs these steps for
:func:`~cyclecoord.periodic.pipeline.extract`.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import NoPeriodicMotionError, ParameterError
from ..motion import Motion
from .barcode import (
    CLEAR_GAP,
    CLEAR_MIN_FRACTION,
    CLEAR_RATIO,
    Barcode,
    BarSelection,
    refine_birth,
    select_bar,
)
from .clip import joint_columns
from .coordinates import REFINE_BYTES_PER_EDGE, CircularCoordinates, unwrap
from .preprocess import Preprocessor
from .results import PartialExtraction
from .root import heading, root_layout
from .steady import moving_mask, period_speed, recurrence, steady_mask
from .windings import complete_windings, stretches

__all__ = [
    "TakeFit", "Fit", "first_clear", "not_clear_reason", "too_few_turns", "rows_of", "row_runs",
    "unwrap_runs", "steady_frames", "MAX_SPREAD", "ALIVE_RATIO", "FIRST_PASS_LANDMARKS",
]

#: Complete windings varying by more than this (p10-p90 over the median) are not steady.
MAX_SPREAD = 0.25
#: A bar alive at the threshold is followed until the threshold is this many times its birth.
ALIVE_RATIO = 4.0
#: Landmarks of the rough first pass over a long take (which finds its steady frames).
FIRST_PASS_LANDMARKS = 150


def first_clear(
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


def not_clear_reason(sel: BarSelection, barcode: Barcode) -> str:
    """Why a bar does not stand clear: its death/birth ratio and its gap to the next bar
    when they fall short, otherwise (neither does) its persistence against the threshold."""
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


def unwrap_runs(
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
class Fit:
    """One barcode + coordinate fit on some rows of a capture."""

    est: CircularCoordinates
    barcode: Barcode
    selection: BarSelection
    rows: np.ndarray
    unwrapped: np.ndarray  # (T,), NaN outside rows
    notes: list
    weak_gap: bool = False  # clear but for the gap to the next bar


class TakeFit:
    """One extraction's fitting steps on a windowed capture: preparation, the barcode and
    coordinate on some rows, the steady frames.  ``params`` are :func:`extract`'s (checked).

    ``moving`` holds the frames the first fit reads: with ``steady``, the moving frames
    (:func:`~cyclecoord.periodic.steady.moving_mask`), unless they are 95 % of the take or
    more (nothing to leave out) or fewer than ``max(10, 2 * n_neighbors)`` (too few to
    fit on); then, and without ``steady``, every frame.
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
                                 pca=p["pca"], root=p["root"], delay=lag,
                                 rotations=p.get("rotations", "auto"))
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
        self, msg: str, fit: Fit | None = None, barcode: Barcode | None = None
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

    def coordinate_of(self, est: CircularCoordinates, rows: np.ndarray) -> Fit:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            est.fit_coordinate()
        u = unwrap_runs(est.coordinates_, rows, row_runs(rows), self.T)
        return Fit(est=est, barcode=est.barcode_, selection=est.selection_, rows=rows,
                    unwrapped=u, notes=[str(w.message) for w in caught])

    def fit_rows(self, rows: np.ndarray, stage: str, first_pass: bool = False) -> Fit:
        """Barcode and coordinate on ``rows``; refuses a barcode with no clear bar."""
        p = self.p
        class_index, scale = p["class_index"], p["scale"]
        est = self.make_estimator(first_pass)
        t0 = time.perf_counter()
        barcode, sel = first_clear(
            est, rows_of(self.prepared.points, rows), class_index, scale, p["scale_fraction"]
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
            raise self.fail(f"no periodic motion found: {not_clear_reason(sel, barcode)}; "
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

    def _other_class(self, fit: Fit, est: CircularCoordinates, barcode: Barcode,
                     rows: np.ndarray) -> Fit:
        """The most persistent class of a long take can be a loop of the whole take (a
        circuit, a drift); a later clear class that winds regularly is the motion's.

        The first class stands when it turns at least ``min_turns`` times and its windings
        spread by no more than :data:`MAX_SPREAD`; otherwise the first of classes 1 to 3
        whose death/birth ratio is at least ``CLEAR_RATIO`` and that does both is taken."""
        min_turns = self.p["min_turns"]
        wind = complete_windings(fit.unwrapped, row_runs(rows))
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
                    complete_windings(alt.unwrapped, row_runs(rows)) if alt is not None else None
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

    def _refine_birth(self, fit: Fit, rows: np.ndarray) -> None:
        """The class's birth on every frame, for the report (landmarks are born later)."""
        budget = getattr(fit.est, "memory_budget_", None)
        max_edges = (
            3_000_000 if budget is None else int(min(3_000_000, budget / REFINE_BYTES_PER_EDGE))
        )
        full = (
            refine_birth(
                rows_of(self.prepared.points, rows),
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

    def fit_steady(self) -> tuple[Fit, np.ndarray]:
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
                used = steady_frames(self.motion, self.prepared, self.joints, fit.unwrapped,
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
                raise self.fail(too_few_turns(first.turns, int(moving.sum()), min_turns), fit)
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


def rows_of(x: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """``x[rows]``, as a view when the rows are one contiguous run (no copy of a long take)."""
    if rows.size and rows[-1] - rows[0] + 1 == rows.size:
        return x[rows[0] : rows[-1] + 1]
    return x[rows]


def row_runs(rows: np.ndarray) -> list[tuple[int, int]]:
    """Runs of consecutive frame indices in a sorted index array."""
    if rows.size == 0:
        return []
    breaks = np.flatnonzero(np.diff(rows) > 1)
    starts = np.concatenate([[0], breaks + 1])
    stops = np.concatenate([breaks + 1, [rows.size]])
    return [(int(rows[a]), int(rows[b - 1]) + 1) for a, b in zip(starts, stops)]


def steady_frames(motion, prepared, joints, unwrapped, moving, period) -> np.ndarray:
    """Steady frames of a take (see :mod:`~cyclecoord.periodic.steady`)."""
    rec = recurrence(prepared.poses, period, columns=joints)
    layout = root_layout(motion)
    hd = heading(motion.frames, layout) if layout is not None else None
    speed = period_speed(prepared.poses, motion.fps, period, columns=joints)
    return steady_mask(unwrapped, moving, period, recurrence_distance=rec, heading=hd, speed=speed)


def too_few_turns(turns: float, n_frames: int, min_turns: float) -> str:
    return (
        f"no periodic motion found: the coordinate turns only {turns:.2f} times over the "
        f"{n_frames} "
        f"steady frames (at least {min_turns:g} are needed to call a motion periodic); a longer "
        "take, "
        "--frames around the repeated part, or --pca 3 may help"
    )
