"""What to blend: a capture or a cycle made into one loop, and a cycle's figures.

:func:`as_cycle` decides whether an input is already one loop or a capture of several
(by its metadata, its loop closure and its estimated period, :func:`estimate_period`)
and runs :func:`cyclecoord.extract` on a capture; :func:`cycle_summary` gives a
cycle's frames, length, loop closure and jerk.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ..quality.metrics import jerk_summary, loop_closure
from .align import mean_heading, root_rotation, rotate_heading
from .curve import angle_columns, check_motion, pose_columns, prepare_cycle, root_columns

__all__ = [
    "CycleSource",
    "as_cycle",
    "estimate_period",
    "cycle_summary",
    "CYCLE_CLOSURE_LIMIT",
    "CYCLE_LENGTH_LIMIT",
]


#: An input loops when its last-to-first step is at most this many median steps.
CYCLE_CLOSURE_LIMIT = 1.5


#: An input is one cycle when it is at most this many estimated periods long.
CYCLE_LENGTH_LIMIT = 1.5


#: An input must reach this many median steps from its mean pose to count as moving.
_MIN_SPREAD = 3.0


#: Autocorrelation an input must reach at some lag to count as repeating itself.
_REPEAT_CORRELATION = 0.6


#: Metadata keys :func:`cyclecoord.extract` writes into its cycle.
_EXTRACT_KEYS = ("period_frames", "cycles_in_source")


def cycle_of(x: object, name: str) -> Motion:
    """The cycle to blend from a Motion, an :class:`ExtractionResult` or a :class:`CycleSource`.

    A Motion that does not look like one loop (see :func:`as_cycle`'s rule) is still
    used as it is, with a warning saying what to pass instead.
    """
    cycle = getattr(x, "cycle", None)
    if not isinstance(x, Motion) and isinstance(cycle, Motion):
        return check_motion(cycle, f"{name} (its .cycle)")
    if not isinstance(x, Motion):
        raise ParameterError(
            f"{name} must be a cycle: a Motion, the result of cyclecoord.extract (or its "
            f".cycle), or a CycleSource from as_cycle; got {type(x).__name__}"
        )
    m = check_motion(x, name)
    why = _capture_signs(m)
    if why:
        warnings.warn(
            f"{name} looks like a whole capture rather than one loop ({'; '.join(why)}); it is "
            "blended as it is. Pass cyclecoord.extract(capture) (or its .cycle), or "
            "as_cycle(capture), to blend its typical cycle",
            UserWarning,
            stacklevel=3,
        )
    return m


def _capture_signs(motion: Motion) -> list[str]:
    """Why ``motion`` is a capture of several loops (:func:`as_cycle`'s repeat rule; the
    loop-closure rule is left out: a cycle shifted in phase can fail it)."""
    meta = motion.metadata if isinstance(motion.metadata, dict) else {}
    if meta.get("cycle") is True or all(k in meta for k in _EXTRACT_KEYS):
        return []
    period = estimate_period(motion)
    why = []
    if period is not None and motion.n_frames > CYCLE_LENGTH_LIMIT * period:
        why.append(
            f"it repeats every {period:.0f} frames ({motion.n_frames / period:.1f} periods long)"
        )
    return why


def cycle_summary(motion: Motion) -> dict[str, Any]:
    """Figures of a cycle: frames, seconds, loop closure, jerk and steps.

    With a skeleton they are :func:`cyclecoord.quality.pose_space.cycle_figures`, the
    figures ``extract`` reports: joint positions in the root's frame, so the same cycle
    read from AMC, BVH, NPZ or glTF gives the same numbers.  Without one they are taken
    on the channels (the root as steps, :func:`~cyclecoord.synthesis.curve.prepare_cycle`).

    Returns
    -------
    dict
        ``frames``, ``seconds``, ``loop_closure`` (last-to-first step over the median
        step; up to about 1.5 loops cleanly), ``jerk`` (mean jerk norm around the loop),
        ``largest_step`` and ``median_step``, ``unit`` (``"m"`` on joint positions, else
        ``"channel units"``: degrees for joint angles) and ``space`` (``"joint
        positions"`` or ``"channels"``).
    """
    from ..quality.pose_space import cycle_figures

    out: dict[str, Any] = {
        "frames": int(motion.n_frames),
        "seconds": float(motion.n_frames / motion.fps),
    }
    fig = cycle_figures(motion) if motion.skeleton is not None else None
    if fig is not None:
        out.update(
            loop_closure=fig.loop_closure, jerk=fig.jerk, largest_step=fig.largest_step,
            median_step=fig.median_step, unit="m", space="joint positions",
        )
        return out
    prep = prepare_cycle(motion)
    steps = np.linalg.norm(np.roll(prep, -1, axis=0) - prep, axis=1)
    out.update(
        loop_closure=float(loop_closure(prep)),
        jerk=float(jerk_summary(prep, motion.fps, cyclic=True))
        if motion.n_frames >= 7 else float("nan"),
        largest_step=float(steps.max()),
        median_step=float(np.median(steps)),
        unit="channel units",
        space="channels",
    )
    return out


@dataclass
class CycleSource:
    """An input resolved to one cycle.

    Attributes
    ----------
    cycle : Motion
        The cycle (the input itself, or the typical cycle extracted from it).
    extracted : bool
        Whether :func:`cyclecoord.extract` was run.
    reason : str
        Why the input was (not) taken as a cycle.
    loop_closure : float
        Last-to-first step over the median step of the input (joint positions, as
        :func:`cycle_summary`).
    period_estimate : float or None
        Repeat found by autocorrelation, frames (``None``: no repeat within the input).
    extraction : ExtractionResult or None
    """

    cycle: Motion
    extracted: bool
    reason: str
    loop_closure: float
    period_estimate: float | None
    extraction: Any = None

    def to_dict(self) -> dict[str, Any]:
        out = {
            "source": self.cycle.source,
            "frames": int(self.cycle.n_frames),
            "fps": float(self.cycle.fps),
            "extracted": bool(self.extracted),
            "reason": self.reason,
            "input_loop_closure": float(self.loop_closure),
            "input_period_estimate": None
            if self.period_estimate is None
            else float(self.period_estimate),
        }
        if self.extraction is not None:
            r = self.extraction
            out["extraction"] = {
                "frames": [
                    int(r.motion.start_frame),
                    int(r.motion.start_frame + r.motion.n_frames),
                ],
                "period_frames": float(r.period_frames),
                "cycles": float(r.cycles),
                "loop_closure": float(r.loop_closure),
                "warnings": list(r.warnings),
            }
        return out


def estimate_period(motion: Motion) -> float | None:
    """The lag (frames) at which a capture repeats itself, by autocorrelation.

    The pose channels (all but the root's, mean removed) are correlated with
    themselves shifted by every lag ``L`` up to ``T / 1.5`` (normalised over the
    overlapping frames).  After the correlation has first fallen below 0.3, the first
    stretch of lags where it is back above 0.6 holds the period: the lag of its highest
    value there is returned.  ``None`` when it never gets back above 0.6 (the input does
    not repeat within 1.5 of its own periods).

    Returns
    -------
    float or None
        Frames per repeat.
    """
    m = check_motion(motion, "the input")
    x = np.array(m.frames[:, pose_columns(m)], dtype=float)
    x -= x.mean(axis=0)
    T = x.shape[0]
    max_lag = int(np.floor(T / CYCLE_LENGTH_LIMIT))
    if max_lag < 3:
        return None
    n = 1
    while n < 2 * T:
        n *= 2
    spec = np.fft.rfft(x, n=n, axis=0)
    corr = np.fft.irfft(np.sum(np.abs(spec) ** 2, axis=1), n=n)[: max_lag + 1]
    energy = np.concatenate([[0.0], np.cumsum(np.sum(x * x, axis=1))])
    lags = np.arange(max_lag + 1)
    head = energy[T - lags]  # frames 0 .. T-L-1
    tail = energy[T] - energy[lags]  # frames L .. T-1
    with np.errstate(invalid="ignore", divide="ignore"):
        r = corr / np.sqrt(head * tail)
    r = np.nan_to_num(r, nan=0.0)
    below = np.flatnonzero(r < 0.3)
    if below.size == 0:
        return None
    start = int(below[0])
    if start >= max_lag:
        return None
    high = np.flatnonzero(r[start:] >= _REPEAT_CORRELATION)
    if high.size == 0:
        return None
    first = start + int(high[0])
    low_again = np.flatnonzero(r[first:] < _REPEAT_CORRELATION)
    stop = first + int(low_again[0]) if low_again.size else r.size
    best = first + int(np.argmax(r[first:stop]))
    if best == r.size - 1:
        return None  # still rising at T / 1.5: the repeat, if any, lies beyond
    return float(best)


def _pose_spread(motion: Motion) -> float:
    """Largest distance of a pose from the mean pose, in median frame-to-frame steps.

    A loop of real motion reaches many steps away from its mean (about 24 for the
    144-frame CMU walk cycle of 69_01, 8 for the 45-frame jog cycle of 143_01, 7 to 19
    for noisy synthetic cycles); a still capture's noise only about 1.
    """
    x = np.asarray(motion.frames[:, pose_columns(motion)], dtype=float)
    step = float(np.median(np.linalg.norm(np.diff(x, axis=0), axis=1)))
    reach = float(np.linalg.norm(x - x.mean(axis=0), axis=1).max())
    if step == 0.0:
        return 0.0 if reach == 0.0 else float("inf")
    return reach / step


def _input_closure(motion: Motion) -> float:
    """Last-to-first step over the median step: on joint positions with a skeleton (as
    :func:`cycle_summary`), else on the channels with the root as steps."""
    from ..periodic.preprocess import difference_root
    from ..quality.pose_space import cycle_figures

    fig = cycle_figures(motion) if motion.skeleton is not None else None
    if fig is not None:
        return float(fig.loop_closure)

    root = root_columns(motion)
    rot = angle_columns([motion.channels[c] for c in root])
    prep = difference_root(np.asarray(motion.frames, dtype=float), root, rot)
    # the last prepared row repeats the one before; compare the true first and last poses
    return float(loop_closure(prep[:-1] if motion.n_frames > 3 else prep))


def as_cycle(
    motion: Motion,
    mode: str = "auto",
    frames: tuple[int | None, int | None] | None = None,
    *,
    turn: bool = True,
    up: str = "y",
    **extract_options: Any,
) -> CycleSource:
    """Take an input as one cycle, extracting its typical cycle first when it is a capture.

    The rule (``mode="auto"``):

    1. an input whose metadata says it was written by :func:`cyclecoord.extract`
       (``period_frames`` and ``cycles_in_source``; kept by NPZ files) or by
       :func:`blend` (``cycle: true``) is a cycle, unless ``frames`` cuts it;
    2. otherwise it is a cycle when all hold: its last-to-first step is at most
       :data:`CYCLE_CLOSURE_LIMIT` (1.5) times its median step (on joint positions in
       the root's frame, :func:`cycle_summary`; in the prepared space without a
       skeleton: it loops); it does not repeat itself within its length: the autocorrelation of
       its pose channels (:func:`estimate_period`) finds no period ``L`` with
       ``T > 1.5 L`` (it is at most about 1.5 periods long); and it moves: some pose is
       at least 3 median steps from the mean pose (a still capture's noise "loops" too);
    3. anything else is a capture, and :func:`cyclecoord.extract` runs on it with its
       default settings (or ``extract_options``).

    Before extracting, a capture is turned about the vertical axis to face heading 0
    (``turn=True``) and its cycle turned back afterwards.  Root orientation is stored as
    Euler angles, and a CMU root (order ZYX, heading in the middle angle) facing near
    ±90 degrees is at gimbal lock: its rx and rz channels jump by tens of degrees
    between frames although the body barely turns, and their differences would swamp
    the prepared space.  Facing heading 0 the same rotations have smooth angles (on
    143_01 the H1 class is then born at 25.1, as in the paper's table, instead of 33.0).

    Parameters
    ----------
    motion : Motion
    mode : {"auto", "cycle", "extract"}
        Force one answer with ``"cycle"`` or ``"extract"``.
    frames : (start, stop), optional
        0-based half-open frame window applied first.
    turn : bool, default True
        Turn a capture to heading 0 for the extraction (needs a skeleton whose root has
        three rotation channels; skipped otherwise).
    up : {"x", "y", "z"}
        Vertical axis for ``turn``.
    **extract_options
        Passed to :func:`cyclecoord.extract` (e.g. ``max_scale=50``).

    Returns
    -------
    CycleSource

    Raises
    ------
    ParameterError
        For a bad mode or window.
    NoPeriodicMotionError
        When extraction finds no periodic motion.
    """
    from ..periodic.pipeline import extract

    if mode not in ("auto", "cycle", "extract"):
        raise ParameterError(f"mode must be 'auto', 'cycle' or 'extract', got {mode!r}")
    if not isinstance(motion, Motion):
        raise ParameterError(f"expected a Motion, got {type(motion).__name__}")
    if frames is not None:
        windowed = motion.window(frames)
        if windowed is motion:
            frames = None  # the whole input: no window
        motion = windowed
    motion = check_motion(motion, "the input")
    closure = _input_closure(motion)
    period = estimate_period(motion)
    meta = motion.metadata if isinstance(motion.metadata, dict) else {}
    if mode == "cycle":
        return CycleSource(motion, False, "taken as a cycle (forced)", closure, period)
    if mode == "auto":
        if frames is None and (meta.get("cycle") is True or all(k in meta for k in _EXTRACT_KEYS)):
            return CycleSource(
                motion, False, "a cycle written by cyclecoord (metadata)", closure, period
            )
        loops = closure <= CYCLE_CLOSURE_LIMIT
        single = period is None or motion.n_frames <= CYCLE_LENGTH_LIMIT * period
        spread = _pose_spread(motion)
        moves = spread >= _MIN_SPREAD
        if loops and single and moves:
            return CycleSource(
                motion,
                False,
                f"taken as a cycle: loop closure {closure:.2f} <= {CYCLE_CLOSURE_LIMIT} "
                "and no repeat within its "
                f"{motion.n_frames} frames",
                closure,
                period,
            )
        why = []
        if not loops:
            why.append(f"loop closure {closure:.2f} > {CYCLE_CLOSURE_LIMIT}")
        if not single:
            why.append(
                f"it repeats every {period:.0f} frames "
                f"({motion.n_frames / period:.1f} periods long)"
            )
        if not moves:
            why.append(
                f"its poses stay within {spread:.1f} median steps of their mean (it barely moves)"
            )
        reason = "extracted: " + " and ".join(why)
    else:
        reason = "extracted (forced)"
    heading = float("nan")
    if turn:
        try:
            heading = mean_heading(motion, up)
        except ParameterError:
            heading = float("nan")
    work = motion
    if np.isfinite(heading) and heading != 0.0:
        work = rotate_heading(motion, -heading, up)
    result = extract(work, **extract_options)
    cycle = result.cycle
    if work is not motion:
        _, _, rcols = root_rotation(motion)
        cycle = rotate_heading(cycle, heading, up, near=motion.frames[0, rcols])
        reason += f"; extracted facing heading 0 (turned by {-heading:.1f} degrees) and turned back"
    return CycleSource(cycle, True, reason, closure, period, extraction=result)
