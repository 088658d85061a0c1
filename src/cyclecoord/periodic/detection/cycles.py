"""A typical cycle for every motion :func:`~cyclecoord.periodic.detection.detect` found."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import ParameterError
from ...motion import Motion
from ..coordinates import unwrap
from ..preprocess import Preprocessor
from .result import DetectionResult

if TYPE_CHECKING:
    from ..pipeline import CycleOptions

__all__ = ["MotionCycle", "motion_cycles"]


@dataclass
class MotionCycle:
    """The typical cycle of one detected motion (see :func:`motion_cycles`).

    Attributes
    ----------
    motion : int
        Motion id.
    start, stop : int
        The segment it was taken from (the motion's longest; 0-based, half-open).
    phase_from : str
        ``"class I"`` when the phase is H1 class ``I``'s coordinate on its excited
        frames, ``"time"`` when it is time over the segment's period.
    n_frames_used : int
        Frames averaged into the cycle.
    period_frames : float
        The segment's period; the cycle has ``round(period_frames)`` frames.
    cycle : Motion
        The loopable clip, with the capture's channels, skeleton and frame rate.
    loop_closure : float
        Seam step over median step (:func:`~cyclecoord.quality.metrics.loop_closure`).
    largest_step : float
        The cycle's largest frame step (seam included) over the 99th-percentile step
        between consecutive used frames of the capture, in the prepared space; over
        :data:`~cyclecoord.periodic.pipeline.MAX_POP` is a pop (``extract`` warns).
    """

    motion: int
    start: int
    stop: int
    phase_from: str
    n_frames_used: int
    period_frames: float
    cycle: Motion
    loop_closure: float
    largest_step: float = float("nan")


def _pop(cycle: np.ndarray, poses: np.ndarray, rows: np.ndarray) -> float:
    """The cycle's largest step over the capture's 99th-percentile step on ``rows``."""
    from ...quality.metrics import largest_steps

    mask = np.zeros(poses.shape[0], dtype=bool)
    mask[rows] = True
    big, ref = largest_steps(cycle, poses, mask)
    return big / ref if ref > 0 else float("nan")


def motion_cycles(
    result: DetectionResult,
    n_samples: int = 500,
    n_neighbors: int = 10,
    bandwidth: str | float | None = None,
    cycle_start: str = "slowest",
    random_state: int | None = 0,
    timing: str = "capture",
    travel: str = "keep",
    min_cycles: float = 1.5,
    cycle: CycleOptions | None = None,
    feet: tuple[str, ...] | None = None,
) -> list[MotionCycle]:
    """A typical cycle for every motion :func:`detect` found, with the phase it found.

    For each motion's longest segment the phase of a frame is, when the motion has a
    global H1 class, that class's circular coordinate on the frames it excites inside
    the segment (the class the motion was detected by, so the cycle has the segment's
    period); for a motion found by the windows alone, time over the segment's period
    (:func:`~cyclecoord.periodic.detection.windows.autocorrelation_period`), which is accurate for
    the one to three cycles such segments hold.  The typical cycle is then built as
    :func:`cyclecoord.extract` builds
    it: by default (``timing="capture"``) in a phase re-timed to the capture's pace
    between the coordinate's crossings and aligned by time warping
    (:func:`~cyclecoord.periodic.clip.capture_cycle`), slowest pose first, root tilt
    averaged and heading integrated; with ``timing="coordinate"`` by the paper's density
    sampling.  No fresh barcode is computed.  (A fresh
    ``extract`` on the segment picks the segment's most persistent class, which is often
    one pass through the whole segment: on CMU 13_29 it gave the arm circles an
    840-frame "cycle" for a 220-frame period.)

    Parameters
    ----------
    result : DetectionResult
    n_samples, n_neighbors, bandwidth, cycle_start, random_state, timing, travel
        As for :func:`cyclecoord.extract`.
    cycle : CycleOptions, optional
        The cycle options as one object (as :func:`cyclecoord.extract` takes them); its
        ``min_turns`` is ``min_cycles`` here, its ``weighting`` and ``sampling`` apply to
        ``timing="coordinate"`` only and are not used.
    min_cycles : float, default 1.5
        A motion whose longest segment holds fewer cycles gets no cycle: one repetition
        and a part is no typical cycle (the rule :func:`cyclecoord.extract` applies with
        ``min_turns``; 13_29's twist holds 1.4).
    feet : tuple of str, optional
        Foot points whose contacts carry each cycle's root (default found, as
        :func:`cyclecoord.extract` finds them).

    Returns
    -------
    list of MotionCycle
        One per motion that labels frames and holds ``min_cycles``, by motion id.
    """
    from ...quality.metrics import loop_closure
    from ..clip import capture_cycle, loop_cycle
    from ..cycle import typical_cycle
    from ..density import PeriodicDensity
    from ..pipeline import TIMINGS
    from ..windings import complete_windings, retime, stretches

    if cycle is not None:
        from ..results import take_cycle_options

        given = dict(n_samples=n_samples, n_neighbors=n_neighbors, bandwidth=bandwidth,
                     cycle_start=cycle_start, timing=timing, travel=travel, min_turns=min_cycles)
        chosen = take_cycle_options(cycle, given, "motion_cycles()")
        return motion_cycles(
            result, n_samples=chosen["n_samples"], n_neighbors=chosen["n_neighbors"],
            bandwidth=chosen["bandwidth"], cycle_start=chosen["cycle_start"],
            random_state=random_state, timing=chosen["timing"], travel=chosen["travel"],
            min_cycles=chosen["min_turns"], feet=feet,
        )
    if not isinstance(result, DetectionResult):
        raise ParameterError(
            f"motion_cycles() takes a DetectionResult, got {type(result).__name__}"
        )
    if timing not in TIMINGS:
        raise ParameterError(f"timing must be one of {TIMINGS}, got {timing!r}")
    motion = result.motion
    prep = Preprocessor(difference_root=result.parameters.get("difference_root", True),
                        rotations=result.parameters.get("rotations", "auto"))
    prepared = prep.fit_transform(motion)
    out: list[MotionCycle] = []
    for mid in range(result.n_motions):
        segs = [sg for sg in result.segments if sg.motion == mid]
        if not segs:
            continue
        seg = max(segs, key=lambda sg: sg.stop - sg.start)
        a, b, period = seg.start, seg.stop, float(seg.period_frames)
        if not np.isfinite(period) or period < 2 or not seg.cycles >= min_cycles:
            continue
        rows = np.arange(a, b)
        lead = (
            next((cl for cl in result.classes if cl.index == seg.classes[0]), None)
            if seg.classes
            else None
        )
        if lead is not None and lead.mask[a:b].sum() >= period:  # at least one full turn
            rows = a + np.flatnonzero(lead.mask[a:b])
            theta, source = np.mod(lead.coordinate[rows], 1.0), f"class {lead.index}"
        else:
            theta, source = np.mod((rows - a) / period, 1.0), "time"
        meta = {"period_frames": period, "motion": mid, "segment": [a, b], "phase_from": source}
        if timing == "capture":
            mask = np.zeros(motion.n_frames, dtype=bool)
            mask[rows] = True
            runs = stretches(mask)
            u = np.full(motion.n_frames, np.nan)
            for lo, hi in runs:
                part = unwrap(
                    np.asarray(theta[np.searchsorted(rows, lo) : np.searchsorted(rows, hi)])
                )
                u[lo:hi] = part if part[-1] >= part[0] else -part
            wind = complete_windings(u, runs)
            phase = retime(u, runs, wind)
            if not np.isfinite(phase).any():
                phase = np.full(motion.n_frames, np.nan)
                phase[rows] = np.mod((rows - a) / period, 1.0)
            typ, clip, _ = capture_cycle(
                phase,
                motion,
                prepared,
                prep,
                period,
                bandwidth=bandwidth,
                cycle_start=cycle_start,
                travel=travel,
                k=n_neighbors,
                metadata=meta,
                feet=feet,
            )
        else:
            density = PeriodicDensity(random_state=random_state).fit(theta)
            typ = typical_cycle(
                theta, prepared.poses[rows], period, density=density, n_samples=n_samples,
                k=min(n_neighbors, rows.size), bandwidth=bandwidth, random_state=random_state,
            )
            typ, clip = loop_cycle(
                typ, motion, prepared, prep, cycle_start=cycle_start, rows=rows, metadata=meta
            )
        if result.rig_adapter is not None:
            clip = result.rig_adapter.restore(clip)  # in the capture's own rig
        out.append(MotionCycle(
            motion=mid, start=a, stop=b, phase_from=source, n_frames_used=int(rows.size),
            period_frames=period, cycle=clip, loop_closure=float(loop_closure(typ.frames)),
            largest_step=_pop(typ.frames, prepared.poses, rows),
        ))
    return out
