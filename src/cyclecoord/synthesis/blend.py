"""Blends and transitions between periodic motion cycles (paper §4.5 and §7).

:func:`blend` forms the paper's convex combination ``y(θ) = Σ w_i x_i(θ)`` of any number
of aligned cycles; :func:`transition` ramps the weight from one cycle to another while
the phase keeps advancing (the paper's homotopy).

Before blending, cycles are brought into a common frame
(:mod:`cyclecoord.synthesis.common_frame`): cycles of one skeleton written
in different conventions (an AMC capture, a BVH cycle) are re-expressed in one
(:func:`cyclecoord.conventions.common_channels`), root translations are scaled to the
reference skeleton's size, every cycle is turned about the vertical axis so that it faces
the same way (otherwise a walk heading north and a jog heading east would have their
velocities cancel, and a CMU root facing east sits at the gimbal lock of its Euler
angles), and joint rotations are blended as rotations: each joint's rotation becomes its rotation
vector about the joint's mean over all the cycles
(:mod:`cyclecoord.periodic.rotations`), the weighted sum is taken there (a weighted mean
of the rotations, exact to second order in their spread) and turned back into Euler
channels that are continuous over frames, so 179 and -179 do not average to 0 and an
Euler flip in one input changes nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from numbers import Integral, Real
from typing import Any, Sequence

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from .curve import CycleCurve, horizontal_columns, root_columns
from .common_frame import Prepared, common_frame, turn_back
from .sources import cycle_of

__all__ = [
    "blend",
    "transition",
    "transition_steps",
    "BlendResult",
    "TransitionResult",
    "STEP_LIMIT",
]


#: A transition is continuous when no step exceeds this many typical steps.
STEP_LIMIT = 1.5


@dataclass(frozen=True)
class BlendResult:
    """A blended loop and how it was made (``blend(..., full_output=True)``).

    The same figures are filed in ``motion.metadata["blend"]`` so that they travel with
    the clip into files; this object gives them typed, without reading a dict.

    Attributes
    ----------
    motion : Motion
        The blended loop (as ``blend`` returns by default).
    weights : ndarray, shape (n,)
    sources : list of str
        The inputs' names.
    period_frames : float
        The loop's length in frames.
    periods_frames, periods_seconds : list of float
        The inputs' periods.
    root_displacement : ndarray, shape (R,)
        Root channel change over one loop (the next loop starts there).
    alignments : list of dict
        Phase shift, direction and match of each input against the first
        (:func:`~cyclecoord.synthesis.align.align`).
    headings_deg : list of float or None
        The inputs' mean headings before they were turned to the first's (None: not turned).
    root_scales : list of float
        Root translation scale per input (skeleton sizes).
    notes : list of str
    """

    motion: Motion
    weights: np.ndarray
    sources: list
    period_frames: float
    periods_frames: list
    periods_seconds: list
    root_displacement: np.ndarray
    alignments: list
    headings_deg: list | None
    root_scales: list
    notes: list


@dataclass(frozen=True)
class TransitionResult:
    """A transition clip and how it was made (``transition(..., full_output=True)``).

    The same figures are filed in ``motion.metadata["transition"]``.

    Attributes
    ----------
    motion : Motion
        Lead-in cycles of ``a``, the ramp, lead-out cycles of ``b``.
    sources : list of str
    ramp : (int, int)
        The ramp's frames, half-open.
    ramp_cycles : float
        Cycles of phase the ramp spans.
    periods_frames : list of float
        ``a``'s and ``b``'s periods at ``a``'s rate.
    lead_in_frames, lead_out_frames : int
    alignment : dict
        ``b``'s phase shift and match against ``a``.
    headings_deg : list of float or None
    root_scales : list of float
    continuity : dict
        :func:`transition_steps`: the largest step over the typical step at its phase,
        and a longer ramp that would keep every step within :data:`STEP_LIMIT` when one
        is needed.
    notes : list of str
    weight, phase : ndarray, shape (T,)
        ``b``'s weight and the phase (cycles) of every frame.
    """

    motion: Motion
    sources: list
    ramp: tuple
    ramp_cycles: float
    periods_frames: list
    lead_in_frames: int
    lead_out_frames: int
    alignment: dict
    headings_deg: list | None
    root_scales: list
    continuity: dict
    notes: list
    weight: np.ndarray
    phase: np.ndarray

    @property
    def ramp_frames(self) -> int:
        return int(self.ramp[1] - self.ramp[0])


def _smoothstep(u: np.ndarray) -> np.ndarray:
    """C2 ramp from 0 (u <= 0) to 1 (u >= 1): 6u^5 - 15u^4 + 10u^3."""
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u))


def _check_weights(weights: object, n: int) -> np.ndarray:
    try:
        w = np.asarray(weights, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ParameterError(f"weights must be numbers, got {weights!r}") from None
    if w.shape[0] != n:
        raise ParameterError(f"{w.shape[0]} weights for {n} cycles; give one weight per cycle")
    if not np.all(np.isfinite(w)):
        raise ParameterError(f"weights must be finite numbers, got {w.tolist()}")
    if np.any(w < 0):
        raise ParameterError(
            f"weights must be non-negative (a convex combination), got {w.tolist()}"
        )
    total = float(w.sum())
    if abs(total - 1.0) > 1e-6:
        raise ParameterError(
            "weights must sum to 1 (a convex combination), got "
            f"{' + '.join(f'{v:g}' for v in w)} = {total:g}"
        )
    return w


def blend(
    cycles: Sequence[Motion],
    weights: Sequence[float],
    *,
    allow_reverse: bool = False,
    align_heading: bool = True,
    scale_root: bool = True,
    up: str = "y",
    n_frames: int | None = None,
    full_output: bool = False,
) -> Motion | BlendResult:
    """Convex combination of cycles, ``y(θ) = Σ w_i x_i(θ)`` after alignment (paper §4.5).

    The first cycle is the reference: the result starts at its phase 0, faces its
    heading, starts where it starts, uses its skeleton and frame rate.  Each other cycle
    is brought into the reference's frame (root translation scaled by the ratio of
    skeleton sizes, turned to the same mean heading about ``up``, angles within 180
    degrees of the reference's, shifted in phase by :func:`align`, ground position moved
    to the reference's start), then every channel is blended on the phase circle:
    joint angles and root height/orientation as values, the root's travel per loop as
    the weighted mean of the inputs' (so the root's velocity along the loop is the
    weighted mean of theirs, in distance per cycle).  The blended loop lasts
    ``Σ w_i T_i`` seconds (``T_i`` the inputs' periods), i.e.
    ``round(Σ w_i P_i)`` frames for inputs at the same rate, and is resampled to that
    length without aliasing (:meth:`CycleCurve.sample`).

    Parameters
    ----------
    cycles : sequence of Motion or ExtractionResult
        One loop each, with the same channels, or skeletons with the same joints in
        other conventions (see :func:`common_channels`).  The result of
        :func:`cyclecoord.extract` (or a :class:`CycleSource`) stands for its ``.cycle``;
        a Motion that looks like a whole capture is used as it is with a warning (turn
        captures into cycles with :func:`cyclecoord.extract` or :func:`as_cycle`).
    weights : sequence of float
        One per cycle, non-negative, summing to 1 (within 1e-6); anything else is
        refused.
    allow_reverse : bool, default False
        Let :func:`align` play a cycle backwards when that matches better (cycles from
        :func:`cyclecoord.extract` always run forward in time).
    align_heading : bool, default True
        Turn every cycle to the reference's heading (needs skeletons whose root has 3
        rotation channels; otherwise skipped with a note in the metadata).
    scale_root : bool, default True
        Scale root translations by the reference skeleton's size over each cycle's
        (total bone length), so strides keep their proportion to the legs.
    up : {"x", "y", "z"}
        Vertical axis (``"y"`` for CMU and BVH data).
    n_frames : int, optional
        Force the output length (default from the blended period).
    full_output : bool, default False
        Return a :class:`BlendResult` (the loop and its figures, typed) instead of the
        loop alone.

    Returns
    -------
    Motion or BlendResult
        One loop, ``metadata`` holding ``cycle: True``, ``period_frames``,
        ``root_displacement`` (exact per-loop root change) and ``blend`` (weights,
        sources, alignments, headings, scales, notes); with ``full_output`` the same in
        a :class:`BlendResult`.

    Raises
    ------
    ParameterError
        For no cycles, bad weights, cycles with different channels or too few frames.
    """
    if isinstance(cycles, Motion) or not isinstance(cycles, Sequence) or len(cycles) == 0:
        raise ParameterError(
            "blend() needs a non-empty sequence of cycles (Motion objects or the results of "
            "cyclecoord.extract)"
        )
    motions = [cycle_of(m, f"cycle {i}") for i, m in enumerate(cycles)]
    motions, rig = _analysis_cycles(motions)
    up = _analysis_up(rig, up)
    w = _check_weights(weights, len(motions))
    if n_frames is not None and (
        isinstance(n_frames, bool) or not isinstance(n_frames, Integral) or n_frames < 4
    ):
        raise ParameterError(f"n_frames must be an integer >= 4, got {n_frames!r}")
    prep = common_frame(
        motions,
        allow_reverse=allow_reverse,
        align_heading=align_heading,
        scale_root=scale_root,
        up=up,
    )
    ref = prep.base
    prep.notes.extend(_opposed_travel(prep, w))
    seconds = float(sum(wi * c.period_seconds for wi, c in zip(w, prep.curves)))
    n_out = int(n_frames) if n_frames is not None else max(4, int(round(seconds * ref.fps)))
    K = max(c.coefficients.shape[0] for c in prep.curves) - 1
    coef = sum(wi * c.padded(K) for wi, c in zip(w, prep.curves))
    drift = sum(wi * c.drift for wi, c in zip(w, prep.curves))
    mixed = replace(prep.curves[0], coefficients=coef, drift=drift, n_frames=n_out, fps=ref.fps)
    # one frame more than the loop: the next loop's first frame gives the exact displacement
    loop = mixed.sample(n_out)
    values = np.vstack([loop, loop[:1] + drift])
    values = turn_back(values, prep, ref)
    root = root_columns(ref)
    displacement = values[-1, root] - values[0, root]
    frames = values[:-1]
    names = [m.source or f"cycle {i}" for i, m in enumerate(motions)]
    meta = {
        "cycle": True,
        "period_frames": float(n_out),
        "root_displacement": [float(v) for v in displacement],
        "blend": {
            "weights": [float(v) for v in w],
            "sources": names,
            "periods_frames": [float(c.n_frames) for c in prep.curves],
            "periods_seconds": [float(c.period_seconds) for c in prep.curves],
            "alignments": [a.to_dict() for a in prep.alignments],
            "headings_deg": prep.headings if prep.turned else None,
            "root_scales": prep.root_scales,
            "notes": prep.notes,
        },
    }
    label = " + ".join(f"{wi:g}*{n}" for wi, n in zip(w, names))
    out = _restored(replace(
        ref,
        frames=frames,
        start_frame=0,
        source=f"blend of {label}",
        metadata=meta,
    ), rig)
    if not full_output:
        return out
    info = meta["blend"]
    return BlendResult(
        motion=out,
        weights=np.array(w, dtype=float),
        sources=list(names),
        period_frames=float(n_out),
        periods_frames=list(info["periods_frames"]),
        periods_seconds=list(info["periods_seconds"]),
        root_displacement=np.array(displacement, dtype=float),
        alignments=list(info["alignments"]),
        headings_deg=info["headings_deg"],
        root_scales=list(info["root_scales"]),
        notes=list(info["notes"]),
    )


def _opposed_travel(prep: Prepared, weights) -> list[str]:
    """A note when two weighted cycles travel over 90 degrees apart in their headings'
    frames (a walk forwards and one backwards): their strides cancel in the blend, which
    steps nearly in place while its feet slide (the Bandai walk and backward walk at 0.5
    each: root 0.27 m/s, support foot 0.24 m/s against their 0.02-0.03)."""
    horiz = horizontal_columns(prep.reference, prep.up)
    if horiz.size != 2:
        return []
    travel = [np.asarray(c.drift, dtype=float)[horiz] for c in prep.curves]
    used = [i for i, wi in enumerate(weights) if wi > 0 and np.linalg.norm(travel[i]) > 0]
    for i in used:
        for j in used:
            if j <= i:
                continue
            a, b = travel[i], travel[j]
            cos = float(a @ b / (np.linalg.norm(a) * np.linalg.norm(b)))
            if cos < 0.0:
                angle = float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
                return [f"cycles {i} and {j} travel {angle:.0f} degrees apart in their "
                        "headings' frames (one goes backwards or sideways): their strides "
                        "partly cancel, and the blend's feet slide"]
    return []


def _analysis_cycles(motions: list[Motion]) -> tuple[list[Motion], Any]:
    """The cycles in their analysis rig (:func:`cyclecoord.rig.normalize_rig`, every frame
    kept) and the first one's adapter that writes a result back (None when nothing
    changes, or the cycles' rigs read differently: then they are blended as given).

    On the Bandai rig the static ``joint_Root`` was the root the curves moved and the
    travelling ``Hips`` a joint whose position was blended as a periodic channel: a
    Bandai walk-to-run transition's support foot glided 0.23 m/s (its cycles' 0.05), a
    blend of its walk and backward walk 0.81 m/s."""
    from ..errors import CycleCoordError
    from ..rig import normalize_rig

    if any(m.skeleton is None for m in motions):
        return motions, None
    try:
        done = [normalize_rig(m, drop_reference=False) for m in motions]
    except CycleCoordError:
        return motions, None
    first = done[0][1]
    if first.identity or any(a.changes() != first.changes() for _, a in done[1:]):
        return motions, None
    return [m for m, _ in done], first


def _analysis_up(rig: Any, up: str) -> str:
    """The vertical axis in the analysis rig: Y where :func:`~cyclecoord.rig.normalize_rig`
    turned a Z-up rig Y-up (``up`` names the inputs' own), else ``up``."""
    if rig is not None and not np.array_equal(rig.up_rotation, np.eye(3)):
        return "y"
    return up


def _restored(out: Motion, rig: Any) -> Motion:
    """A result on the analysis rig written back in the inputs' own (``rig`` None: as it
    is); its ``root_displacement`` is the travelling joint's, not the restored (static)
    root's, and is kept as ``travel_displacement``."""
    if rig is None:
        return out
    back = rig.restore(out)
    meta = {k: v for k, v in back.metadata.items() if k != "root_displacement"}
    if "root_displacement" in back.metadata:
        meta["travel_displacement"] = back.metadata["root_displacement"]
    return replace(back, metadata=meta)


def _phase_increments(p_a: float, p_b: float, n: int) -> np.ndarray:
    """Phase advanced between ramp frames ``t`` and ``t + 1`` (``n - 1`` values).

    The weight is ``w(u) = smoothstep(u)``, ``u = t / (n - 1)``; the phase advances at
    ``dθ/dt = 1 / P(w)``, ``P(w) = (1 - w) P_a + w P_b`` frames, integrated over each
    frame interval by Simpson's rule.
    """
    u0 = np.arange(n - 1) / (n - 1)
    du = 1.0 / (n - 1)

    def rate(u: np.ndarray) -> np.ndarray:
        w = _smoothstep(u)
        return 1.0 / ((1.0 - w) * p_a + w * p_b)

    return (rate(u0) + 4.0 * rate(u0 + 0.5 * du) + rate(u0 + du)) / 6.0


def _ramp_frames_for_cycles(p_a: float, p_b: float, cycles: float) -> int:
    u = (np.arange(4000) + 0.5) / 4000
    w = _smoothstep(u)
    mean_rate = float(np.mean(1.0 / ((1.0 - w) * p_a + w * p_b)))  # cycles per frame
    return int(round(cycles / mean_rate)) + 1


def _prepared_steps(values: np.ndarray, root: np.ndarray) -> np.ndarray:
    """Step norms ``(T - 2,)`` of a clip in the prepared space (root as per-frame steps)."""
    prep = np.array(values[:-1], dtype=float)
    prep[:, root] = np.diff(values[:, root], axis=0)
    return np.linalg.norm(np.diff(prep, axis=0), axis=1)


def _curve_steps(
    curve: CycleCurve, phases: np.ndarray, dphase: float, root: np.ndarray
) -> np.ndarray:
    """Step norm of a cycle played at its own rate, from each phase (prepared space)."""
    x0 = curve(phases)
    x1 = curve(phases + dphase)
    x2 = curve(phases + 2 * dphase)
    p0 = x0.copy()
    p1 = x1.copy()
    p0[:, root] = x1[:, root] - x0[:, root]
    p1[:, root] = x2[:, root] - x1[:, root]
    return np.linalg.norm(p1 - p0, axis=1)


def transition_steps(
    values: np.ndarray,
    phases: np.ndarray,
    a: CycleCurve,
    b: CycleCurve,
    period_a: float,
    period_b: float,
) -> dict[str, Any]:
    """Continuity of a transition clip, step by step.

    A step is the norm of the change between consecutive frames in the prepared space
    (root channels as per-frame steps, angles as values).  A gait's own step varies a
    lot along its loop (fast swing, slow stance), so each clip step is compared with
    the *typical step at the same phase*: the larger of the steps ``a`` and ``b`` take
    there at their own rates, and never less than the smaller of their median steps.
    The clip is continuous when no ratio exceeds :data:`STEP_LIMIT` (1.5).

    Parameters
    ----------
    values : ndarray, shape (T, D)
        The clip (absolute root), in the same frame as the curves.
    phases : ndarray, shape (T,)
        Phase of each frame.
    a, b : CycleCurve
        The aligned cycles.
    period_a, period_b : float
        Their periods in the clip's frames.

    Returns
    -------
    dict
        ``max_step``, ``median_step_a``, ``median_step_b``, ``max_ratio`` (clip step over
        the typical step at its phase), ``worst_frame`` and ``max_ratio_to_median``
        (largest step over the larger median step).
    """
    root = np.asarray(a.root_columns, dtype=int)
    steps = _prepared_steps(values, root)
    ph = np.asarray(phases, dtype=float)[: steps.shape[0]]
    grid = np.arange(4 * int(np.ceil(max(period_a, period_b)))) / (
        4 * int(np.ceil(max(period_a, period_b)))
    )
    med_a = float(np.median(_curve_steps(a, grid, 1.0 / period_a, root)))
    med_b = float(np.median(_curve_steps(b, grid, 1.0 / period_b, root)))
    local = np.maximum(
        _curve_steps(a, ph, 1.0 / period_a, root), _curve_steps(b, ph, 1.0 / period_b, root)
    )
    typical = np.maximum(local, min(med_a, med_b))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(typical > 0, steps / typical, np.where(steps > 0, np.inf, 0.0))
    worst = int(np.argmax(ratio)) if ratio.size else 0
    return {
        "max_step": float(steps.max()) if steps.size else 0.0,
        "median_step_a": med_a,
        "median_step_b": med_b,
        "max_ratio": float(ratio.max()) if ratio.size else 0.0,
        "worst_frame": worst,
        "max_ratio_to_median": float(steps.max() / max(med_a, med_b))
        if steps.size and max(med_a, med_b) > 0
        else 0.0,
        "limit": STEP_LIMIT,
    }


def _transition_frames(
    prep: "Prepared", p_a: float, p_b: float, n_ramp: int, n_in: int, n_out: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Values ``(T, D)`` (common frame), phase and weight per frame of a transition clip."""
    ca, cb = prep.curves
    inc = np.concatenate(
        [
            np.full(n_in, 1.0 / p_a),
            _phase_increments(p_a, p_b, n_ramp),
            np.full(n_out, 1.0 / p_b),
        ]
    )
    phases = np.concatenate([[0.0], np.cumsum(inc)])  # the clip starts at a's frame 0
    weight = np.concatenate(
        [
            np.zeros(n_in),
            _smoothstep(np.arange(n_ramp) / (n_ramp - 1)),
            np.ones(n_out),
        ]
    )
    va = ca(phases)
    vb = cb(phases)
    w = weight[:, None]
    values = (1.0 - w) * va + w * vb
    horiz = horizontal_columns(prep.reference, prep.up)
    if horiz.size:
        # the ground position integrates the blended steps instead of blending positions
        w_mid = 0.5 * (weight[1:] + weight[:-1])[:, None]
        step = (1.0 - w_mid) * np.diff(va[:, horiz], axis=0) + w_mid * np.diff(vb[:, horiz], axis=0)
        values[0, horiz] = va[0, horiz]
        values[1:, horiz] = va[0, horiz] + np.cumsum(step, axis=0)
    return values, phases, weight


def _longer_ramp(
    prep: Prepared, p_a: float, p_b: float, n_ramp: int, n_in: int, n_out: int
) -> int | None:
    """The shortest ramp, ``n_ramp`` times a power of 1.25 up to 1.25^16 (about 35x), whose
    steps all stay within :data:`STEP_LIMIT`; None when none does."""
    ca, cb = prep.curves
    for factor in 1.25 ** np.arange(1, 17):
        n_try = int(np.ceil(n_ramp * factor))
        v, ph, _ = _transition_frames(prep, p_a, p_b, n_try, n_in, n_out)
        if transition_steps(v, ph, ca, cb, p_a, p_b)["max_ratio"] <= STEP_LIMIT:
            return n_try
    return None


def transition(
    a: Motion,
    b: Motion,
    frames: int | None = None,
    cycles: float | None = None,
    *,
    lead_in: int = 1,
    lead_out: int = 1,
    allow_reverse: bool = False,
    align_heading: bool = True,
    scale_root: bool = True,
    up: str = "y",
    full_output: bool = False,
) -> Motion | TransitionResult:
    """A clip that turns cycle ``a`` into cycle ``b`` without a hitch (the paper's homotopy).

    ``b`` is brought into ``a``'s frame and phase exactly as in :func:`blend`.  Over
    the ramp the pose is ``(1 - w) a(θ) + w b(θ)`` with ``w`` rising smoothly
    (smoothstep, zero slope at both ends) from 0 to 1 while the phase keeps advancing
    at ``dθ/dt = 1 / P(w)``, ``P(w) = (1 - w) P_a + w P_b`` frames: the cadence slides
    from ``a``'s to ``b``'s.  Root height and orientation are blended as values; the
    root's ground position integrates the blended per-frame steps, so the character
    keeps going instead of jumping between where ``a`` and ``b`` would be.  ``lead_in``
    whole cycles of ``a`` come first (exactly ``a``'s frames) and ``lead_out`` cycles
    of ``b`` last, so the clip starts in ``a`` and ends in ``b``.

    Continuity is measured by :func:`transition_steps` and stored in
    ``metadata["transition"]["continuity"]``.

    Parameters
    ----------
    a, b : Motion or ExtractionResult
        Cycles with the same channels; an extraction result stands for its ``.cycle``
        (see :func:`blend` and :func:`as_cycle`).
    frames : int, optional
        Length of the ramp in frames (>= 2).
    cycles : float, optional
        Length of the ramp in cycles of phase (> 0); exactly one of ``frames`` and
        ``cycles``.
    lead_in, lead_out : int, default 1
        Whole cycles of ``a`` before and of ``b`` after the ramp (>= 0).
    allow_reverse, align_heading, scale_root, up
        As in :func:`blend`.
    full_output : bool, default False
        Return a :class:`TransitionResult` (the clip and its figures, typed) instead of
        the clip alone.

    Returns
    -------
    Motion or TransitionResult
        At ``a``'s rate and skeleton; ``metadata["transition"]`` holds the ramp's frame
        range, the per-frame weight and phase, the alignment and the continuity figures;
        with ``full_output`` the same in a :class:`TransitionResult`.

    Raises
    ------
    ParameterError
        For bad lengths, cycles with different channels or too few frames.
    """
    (a, b), rig = _analysis_cycles([cycle_of(a, "cycle a"), cycle_of(b, "cycle b")])
    up = _analysis_up(rig, up)
    if (frames is None) == (cycles is None):
        raise ParameterError("give exactly one of frames= and cycles= for the transition's length")
    for name, v in (("lead_in", lead_in), ("lead_out", lead_out)):
        if isinstance(v, bool) or not isinstance(v, Integral) or v < 0:
            raise ParameterError(f"{name} must be a whole number of cycles >= 0, got {v!r}")
    prep = common_frame(
        [a, b],
        allow_reverse=allow_reverse,
        align_heading=align_heading,
        scale_root=scale_root,
        up=up,
    )
    ca, cb = prep.curves
    a = prep.base
    p_a = float(a.n_frames)
    p_b = cb.period_seconds * a.fps
    if frames is not None:
        if isinstance(frames, bool) or not isinstance(frames, Integral) or frames < 2:
            raise ParameterError(f"frames must be an integer >= 2, got {frames!r}")
        n_ramp = int(frames)
    else:
        if (
            isinstance(cycles, bool)
            or not isinstance(cycles, Real)
            or not np.isfinite(cycles)
            or cycles <= 0
        ):
            raise ParameterError(f"cycles must be a positive number, got {cycles!r}")
        n_ramp = max(2, _ramp_frames_for_cycles(p_a, p_b, float(cycles)))
    n_in = int(lead_in) * a.n_frames
    n_out = int(round(int(lead_out) * p_b))
    values, phases, weight = _transition_frames(prep, p_a, p_b, n_ramp, n_in, n_out)
    continuity = transition_steps(values, phases, ca, cb, p_a, p_b)
    notes = list(prep.notes)
    if continuity["max_ratio"] > STEP_LIMIT:
        longer = _longer_ramp(prep, p_a, p_b, n_ramp, n_in, n_out)
        continuity["suggested_ramp_frames"] = longer
        notes.append(
            f"a step is {continuity['max_ratio']:.2f}x the typical step at its phase "
            f"(limit {STEP_LIMIT}): "
            + (
                f"a ramp of {longer} frames or more keeps every step within the limit"
                if longer
                else "even a ramp 35x longer does not keep every step within the limit"
            )
        )
    values = turn_back(values, prep, a)
    meta = {
        "transition": {
            "sources": [a.source or "cycle a", b.source or "cycle b"],
            "ramp": [n_in, n_in + n_ramp],
            "ramp_frames": n_ramp,
            "ramp_cycles": float(phases[n_in + n_ramp - 1] - phases[n_in]),
            "periods_frames": [p_a, p_b],
            "lead_in_frames": n_in,
            "lead_out_frames": n_out,
            "alignment": prep.alignments[1].to_dict(),
            "headings_deg": prep.headings if prep.turned else None,
            "root_scales": prep.root_scales,
            "continuity": continuity,
            "notes": notes,
            "weight": [float(v) for v in weight],
            "phase": [float(v) for v in phases],
        }
    }
    out = _restored(replace(
        a,
        frames=values,
        start_frame=0,
        source=f"transition {a.source or 'a'} -> {b.source or 'b'}",
        metadata=meta,
    ), rig)
    if not full_output:
        return out
    info = meta["transition"]
    return TransitionResult(
        motion=out,
        sources=list(info["sources"]),
        ramp=(int(n_in), int(n_in + n_ramp)),
        ramp_cycles=float(info["ramp_cycles"]),
        periods_frames=list(info["periods_frames"]),
        lead_in_frames=int(n_in),
        lead_out_frames=int(n_out),
        alignment=dict(info["alignment"]),
        headings_deg=info["headings_deg"],
        root_scales=list(info["root_scales"]),
        continuity=dict(continuity),
        notes=list(notes),
        weight=np.array(weight, dtype=float),
        phase=np.array(phases, dtype=float),
    )
