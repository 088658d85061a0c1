"""The synthetic captures: one motion, a chain of motions, standing still, a random walk."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Sequence

import numpy as np

from ..errors import ParameterError
from ..motion import DEFAULT_FPS, Motion
from ..skeleton import Skeleton
from ._body import (
    capture_pair,
    ANGLE_COLS,
    CHANNELS,
    COL,
    DEFAULT_PERIODS,
    TRANSLATION_NOISE_PER_DEGREE,
    add_noise,
    check_float,
    check_int,
    check_kind,
    check_random_state,
    cmu_skeleton,
    draw_phase_law,
    draw_style,
    ground,
    pose_to_frames,
    render_kind,
    seed_text,
    smoothstep,
    standing_pose,
)

__all__ = [
    "SyntheticCapture",
    "make_periodic_capture",
    "make_motion_chain",
    "make_static_capture",
    "make_random_walk_capture",
    "example_capture",
]


# ----------------------------------------------------------------------- result type
@dataclass(frozen=True, eq=False)
class SyntheticCapture:
    """A generated capture with its ground truth.

    Attributes
    ----------
    motion : Motion
        The noisy capture (what a user would load): 62 CMU channels, skeleton
        :func:`cmu_skeleton`.
    clean : Motion
        The noise-free signal, same channels and skeleton.
    phase : ndarray, shape (T,)
        True phase in cycles, unwrapped and strictly increasing within each periodic
        segment (``phase % 1`` is the circular truth); NaN where nothing is periodic
        (transitions, static and random-walk captures).
    period : float
        Mean period in frames (frame-weighted mean over segments for a chain; NaN when
        nothing is periodic).
    labels : ndarray of int, shape (T,)
        Motion id per frame (index of the kind in order of first appearance); -1 for
        transitions and non-periodic frames.
    boundaries : list of (int, int, str)
        Half-open frame ranges ``(start, stop, kind)`` of the periodic segments.
    name : str
        Short name, e.g. ``"synthetic-walk"``.
    parts : list of (str, int, int) or None
        Whole takes (:func:`make_whole_take`) only: every scripted part as a half-open
        range ``(name, start, stop)``, ``name`` one of :data:`PART_NAMES`, in frame order,
        covering all frames; None for the other generators.
    part_labels : ndarray of int, shape (T,), or None
        Whole takes only: per frame, the index in :data:`PART_NAMES` of its part.
    steady : list of (int, int) or None
        Whole takes only: half-open frame ranges of the steady parts (constant amplitude,
        straight heading, the period's own speed wobble); the same ranges as
        ``boundaries``.
    heading : ndarray, shape (T,), or None
        Whole takes only: the body's heading in degrees (yaw of the facing direction about
        the vertical, 0 = +z, positive towards +x, i.e. turning left), unwrapped.
    """

    motion: Motion
    clean: Motion
    phase: np.ndarray
    period: float
    labels: np.ndarray
    boundaries: list[tuple[int, int, str]]
    name: str
    parts: list[tuple[str, int, int]] | None = None
    part_labels: np.ndarray | None = None
    steady: list[tuple[int, int]] | None = None
    heading: np.ndarray | None = None

    def __post_init__(self) -> None:
        phase = np.array(self.phase, dtype=float)
        labels = np.array(self.labels, dtype=int)
        phase.flags.writeable = False
        labels.flags.writeable = False
        object.__setattr__(self, "phase", phase)
        object.__setattr__(self, "labels", labels)
        for name, dtype in (("part_labels", int), ("heading", float)):
            value = getattr(self, name)
            if value is not None:
                arr = np.array(value, dtype=dtype)
                arr.flags.writeable = False
                object.__setattr__(self, name, arr)


# ------------------------------------------------------------------- public makers
def make_periodic_capture(
    n_frames: int = 600,
    period: float = 120.0,
    noise: float = 0.5,
    speed_variation: float = 0.3,
    kind: str = "walk",
    fps: float = DEFAULT_FPS,
    random_state: int | np.random.Generator | None = None,
) -> SyntheticCapture:
    """One periodic motion at uneven speed, with measurement noise.

    Every joint angle is a fixed periodic function of the true phase (several harmonics
    with joint-specific amplitudes and timing); the phase advances at a speed that
    wanders slowly by up to ``speed_variation`` around its mean, so single cycles last
    longer or shorter than ``period`` while the mean over the capture is exactly
    ``period``.  The root height keeps the lowest foot on the floor (plus a flight phase
    for jog and jumping jacks) and the root moves forward by one stride per cycle, so the
    root translation is not periodic.

    Parameters
    ----------
    n_frames : int
        Number of frames ``T`` (>= 2).
    period : float
        Mean period in frames (> 1).
    noise : float
        Standard deviation of the i.i.d. Gaussian noise on every angle channel, degrees
        (>= 0); root translation gets ``0.04 * noise`` length units.
    speed_variation : float
        Relative amplitude of the phase-speed wobble, ``0 <= speed_variation < 1`` (0 gives
        a constant speed: frame ``t`` has phase exactly ``t / period``).
    kind : str
        One of :data:`cyclecoord.datasets.KINDS`: ``"walk"``, ``"jog"`` (faster, larger, flight
        phases, bent elbows), ``"jumping_jack"``, ``"arm_circles"``, ``"squat"``.
    fps : float
        Frame rate stored in the motion.
    random_state : int, numpy Generator or None
        Seed; the same seed gives identical arrays.  It sets the performer's style
        (amplitude within +-8 %, posture offsets of about 1 degree), the speed wobble and
        the noise.

    Returns
    -------
    SyntheticCapture
        ``phase`` starts at 0 and ends at ``(n_frames - 1) / period``; ``labels`` all 0;
        ``boundaries`` ``[(0, n_frames, kind)]``.

    Raises
    ------
    ParameterError
        On an unknown kind or an argument out of range.
    """
    kind = check_kind(kind)
    n = check_int("n_frames", n_frames, 2)
    period = check_float("period", period, 1.0, low_open=True)
    noise = check_float("noise", noise, 0.0)
    variation = check_float("speed_variation", speed_variation, 0.0, high=1.0)
    fps = check_float("fps", fps, 0.0, low_open=True)
    rng = check_random_state(random_state)

    skeleton = cmu_skeleton()
    style = draw_style(rng)
    law = draw_phase_law(rng, period, variation, n)
    phase = law(np.arange(n, dtype=float))
    clean = render_kind(kind, phase, style, skeleton)
    noisy = add_noise(clean, noise, rng)
    source = f"synthetic:{kind}(seed={seed_text(random_state)})"
    meta = {"kind": kind, "period": period, "noise": noise, "speed_variation": variation}
    return SyntheticCapture(
        **capture_pair(noisy, clean, CHANNELS, skeleton, source, meta, fps),
        phase=phase,
        period=period,
        labels=np.zeros(n, dtype=int),
        boundaries=[(0, n, kind)],
        name=f"synthetic-{kind}",
    )


def make_motion_chain(
    kinds: Sequence[str] = ("walk", "jumping_jack", "arm_circles"),
    segment_frames: int | Sequence[int] = 600,
    periods: Sequence[float] | None = None,
    transition_frames: int = 40,
    noise: float = 0.5,
    fps: float = DEFAULT_FPS,
    random_state: int | np.random.Generator | None = None,
    *,
    speed_variation: float = 0.2,
) -> SyntheticCapture:
    """Several periodic motions one after another, joined by short smooth transitions.

    Segment ``k`` is ``kinds[k]`` performed for ``segment_frames`` frames with its own
    period and phase (starting at 0); between segments, ``transition_frames`` frames
    cross-fade (C2 ramp) from the previous motion, continued, into the next one, started
    early.  The root translation is continuous: each segment's forward progression is
    shifted to meet the previous one in the middle of the transition.

    Parameters
    ----------
    kinds : sequence of str
        Motions in order, each one of :data:`cyclecoord.datasets.KINDS` (a single string is one
        segment).
    segment_frames : int or sequence of int
        Frames per segment (>= 2), one number for all or one per segment.
    periods : sequence of float, optional
        Period per segment in frames (> 1); default each kind's natural period (walk 120,
        jog 80, jumping_jack 90, arm_circles 100, squat 150).
    transition_frames : int
        Frames between consecutive segments (>= 0; 0 switches abruptly).
    noise : float
        Angle noise in degrees (>= 0), as in :func:`make_periodic_capture`.
    fps : float
        Frame rate stored in the motion.
    random_state : int, numpy Generator or None
        Seed (one performer's style for the whole chain, a speed wobble per segment, the
        noise).
    speed_variation : float, keyword-only
        Phase-speed wobble of every segment, ``0 <= speed_variation < 1``.

    Returns
    -------
    SyntheticCapture
        ``boundaries`` lists ``(start, stop, kind)`` per segment; ``labels`` holds the
        index of the segment's kind among the distinct kinds (first appearance order) and
        -1 in transitions; ``phase`` is each segment's own phase (NaN in transitions);
        ``period`` is the frame-weighted mean of the segment periods (all of them are in
        ``motion.metadata["periods"]``).

    Raises
    ------
    ParameterError
        On an unknown kind, mismatched lengths or an argument out of range.
    """
    kinds, lengths, pers = _chain_segments(kinds, segment_frames, periods)
    m = len(kinds)
    gap = check_int("transition_frames", transition_frames, 0)
    noise = check_float("noise", noise, 0.0)
    variation = check_float("speed_variation", speed_variation, 0.0, high=1.0)
    fps = check_float("fps", fps, 0.0, low_open=True)
    rng = check_random_state(random_state)

    skeleton = cmu_skeleton()
    style = draw_style(rng)
    starts = [sum(lengths[:k]) + k * gap for k in range(m)]
    ids = {k: i for i, k in enumerate(dict.fromkeys(kinds))}

    # Each segment rendered on its own frames plus the neighbouring transitions (and one
    # frame beyond, for the tz hand-over when gap == 0).
    renders = []
    for k in range(m):
        law = draw_phase_law(rng, pers[k], variation, lengths[k])
        first = starts[k] - (gap + 1 if k > 0 else 0)
        last = starts[k] + lengths[k] + (gap + 1 if k < m - 1 else 0)
        t = np.arange(first, last)
        local_phase = law((t - starts[k]).astype(float))
        renders.append((first, render_kind(kinds[k], local_phase, style, skeleton), local_phase))

    clean, phase, labels = _stitch_chain(renders, starts, lengths, gap, [ids[k] for k in kinds])

    noisy = add_noise(clean, noise, rng)
    seed = seed_text(random_state)
    source = f"synthetic:chain({','.join(kinds)}; seed={seed})"
    boundaries = [(starts[k], starts[k] + lengths[k], kinds[k]) for k in range(m)]
    meta = {
        "kinds": list(kinds),
        "periods": list(pers),
        "boundaries": list(boundaries),
        "noise": noise,
    }
    mean_period = float(np.dot(lengths, pers) / sum(lengths))
    return SyntheticCapture(
        **capture_pair(noisy, clean, CHANNELS, skeleton, source, meta, fps),
        phase=phase,
        period=mean_period,
        labels=labels,
        boundaries=boundaries,
        name="synthetic-chain(" + "+".join(kinds) + ")",
    )


def _chain_segments(
    kinds: Any, segment_frames: Any, periods: Any
) -> tuple[tuple[str, ...], list[int], list[float]]:
    """The checked kinds of :func:`make_motion_chain` with the length and period of each."""
    if isinstance(kinds, str):
        kinds = (kinds,)
    try:
        kinds = tuple(kinds)
    except TypeError:
        raise ParameterError(f"kinds must be a sequence of motion kinds, got {kinds!r}") from None
    if not kinds:
        raise ParameterError("kinds must name at least one motion")
    kinds = tuple(check_kind(k) for k in kinds)
    m = len(kinds)
    if isinstance(segment_frames, (int, np.integer)) and not isinstance(segment_frames, bool):
        lengths = [check_int("segment_frames", segment_frames, 2)] * m
    else:
        try:
            seq = list(segment_frames)  # type: ignore[arg-type]
        except TypeError:
            raise ParameterError(
                f"segment_frames must be an integer or a sequence, got {segment_frames!r}"
            ) from None
        if len(seq) != m:
            raise ParameterError(f"segment_frames has {len(seq)} entries for {m} kinds")
        lengths = [check_int("segment_frames", s, 2) for s in seq]
    if periods is None:
        pers = [DEFAULT_PERIODS[k] for k in kinds]
    else:
        try:
            seq = list(periods)
        except TypeError:
            raise ParameterError(
                f"periods must be a sequence of numbers, got {periods!r}"
            ) from None
        if len(seq) != m:
            raise ParameterError(f"periods has {len(seq)} entries for {m} kinds")
        pers = [check_float("periods", p, 1.0, low_open=True) for p in seq]
    return kinds, lengths, pers


def _stitch_chain(
    renders: list, starts: list[int], lengths: list[int], gap: int, label_of: list[int]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Clean frames, phase and labels of the chain: each segment shifted along tz to meet the
    previous one mid-transition, transitions blended by a smoothstep.

    ``renders`` holds ``(first frame, frames, local phase)`` per segment and is updated with
    the shifted frames.
    """
    m = len(starts)
    total = starts[-1] + lengths[-1]
    tz = COL[("root", "tz")]
    clean = np.empty((total, len(CHANNELS)))
    phase = np.full(total, np.nan)
    labels = np.full(total, -1, dtype=int)
    shift = 0.0
    for k in range(m):
        first, frames, local_phase = renders[k]
        frames = frames.copy()
        if k > 0:
            # meet the previous segment's progression in the middle of the transition
            pfirst, pframes, _ = renders[k - 1]
            mid = starts[k] - gap + gap // 2 if gap else starts[k]
            shift = pframes[mid - pfirst, tz] - frames[mid - first, tz]
            frames[:, tz] += shift
            renders[k] = (first, frames, local_phase)
        s, e = starts[k], starts[k] + lengths[k]
        clean[s:e] = frames[s - first : e - first]
        phase[s:e] = local_phase[s - first : e - first]
        labels[s:e] = label_of[k]
    for k in range(m - 1):
        if gap == 0:
            continue
        a0, a, _ = renders[k]
        b0, b, _ = renders[k + 1]
        t = np.arange(starts[k] + lengths[k], starts[k + 1])
        w = smoothstep((t - t[0] + 1.0) / (gap + 1.0))[:, None]
        clean[t] = (1.0 - w) * a[t - a0] + w * b[t - b0]
    return clean, phase, labels


def _non_periodic(
    clean: np.ndarray, noisy: np.ndarray, kind: str, random_state: object, skeleton: Skeleton
) -> SyntheticCapture:
    n = clean.shape[0]
    source = f"synthetic:{kind}(seed={seed_text(random_state)})"
    return SyntheticCapture(
        **capture_pair(noisy, clean, CHANNELS, skeleton, source, {"kind": kind}),
        phase=np.full(n, np.nan),
        period=float("nan"),
        labels=np.full(n, -1, dtype=int),
        boundaries=[],
        name=f"synthetic-{kind}",
    )


def make_static_capture(
    n_frames: int = 600,
    noise: float = 0.5,
    random_state: int | np.random.Generator | None = None,
) -> SyntheticCapture:
    """A person standing still: one posture plus measurement noise, nothing periodic.

    Parameters
    ----------
    n_frames : int
        Number of frames (>= 2).
    noise : float
        Angle noise in degrees (>= 0); translation noise ``0.04 * noise`` units.
    random_state : int, numpy Generator or None
        Seed for the posture offsets and the noise.

    Returns
    -------
    SyntheticCapture
        ``clean`` is the constant posture; ``phase`` NaN, ``period`` NaN, ``labels`` all
        -1, ``boundaries`` empty.
    """
    n = check_int("n_frames", n_frames, 2)
    noise = check_float("noise", noise, 0.0)
    rng = check_random_state(random_state)
    skeleton = cmu_skeleton()
    style = draw_style(rng)
    clean = pose_to_frames(standing_pose(n), n) + style.posture
    clean[:, COL[("root", "ty")]] = ground(clean[:1], skeleton)[0]
    noisy = add_noise(clean, noise, rng)
    return _non_periodic(clean, noisy, "static", random_state, skeleton)


def make_random_walk_capture(
    n_frames: int = 600,
    step: float = 0.5,
    random_state: int | np.random.Generator | None = None,
) -> SyntheticCapture:
    """Posture drifting as a Gaussian random walk: moving, but nothing periodic.

    Every angle channel starts from a standing posture and takes i.i.d. Gaussian steps
    of ``step`` degrees per frame; the root wanders horizontally by ``0.04 * step`` units
    per frame and its height keeps the lowest foot on the floor.

    Parameters
    ----------
    n_frames : int
        Number of frames (>= 2).
    step : float
        Standard deviation of the per-frame angle steps, degrees (>= 0).
    random_state : int, numpy Generator or None
        Seed.

    Returns
    -------
    SyntheticCapture
        No separate noise: ``clean`` equals ``motion``.  ``phase`` NaN, ``period`` NaN,
        ``labels`` all -1, ``boundaries`` empty.
    """
    n = check_int("n_frames", n_frames, 2)
    step = check_float("step", step, 0.0)
    rng = check_random_state(random_state)
    skeleton = cmu_skeleton()
    style = draw_style(rng)
    frames = pose_to_frames(standing_pose(n), n) + style.posture
    steps = np.zeros_like(frames)
    steps[1:, ANGLE_COLS] = rng.normal(0.0, step, size=(n - 1, ANGLE_COLS.size))
    for d in ("tx", "tz"):
        steps[1:, COL[("root", d)]] = rng.normal(
            0.0, step * TRANSLATION_NOISE_PER_DEGREE, size=n - 1
        )
    frames += np.cumsum(steps, axis=0)
    frames[:, COL[("root", "ty")]] = ground(frames, skeleton)
    return _non_periodic(frames, frames, "random_walk", random_state, skeleton)


def example_capture() -> SyntheticCapture:
    """The README's built-in example: four cycles of a noisy, steady synthetic walk.

    Its tempo wanders by 5 % (a real walk's repetitions differ by a few per cent: CMU
    69_01's complete windings spread 4 %); the generator's default 30 % made the example's
    repetitions last 103-152 frames, and the main command's first run warn that the
    motion is not steady.

    Returns
    -------
    SyntheticCapture
        ``make_periodic_capture(n_frames=480, period=120.0, noise=0.5,
        speed_variation=0.05, random_state=0)``, named ``"synthetic-walk"``.
    """
    cap = make_periodic_capture(
        n_frames=480, period=120.0, noise=0.5, speed_variation=0.05, random_state=0
    )
    return replace(cap, name="synthetic-walk")
