"""Align, blend and transition between periodic motion cycles (paper §4.5 and §7).

A cycle is a :class:`~cyclecoord.motion.Motion` holding one loop: ``P`` frames, frame
``P - 1`` followed by frame 0 of the next loop, the root travelling a fixed displacement
per loop (what :func:`cyclecoord.extract` writes).  Everything here treats a cycle as a
closed curve of its phase ``θ`` (in cycles):

* every channel is ``x(θ) = drift · θ + p(θ)`` with ``p`` periodic.  The drift is the
  change per loop: the root's travel and turn for root channels, a multiple of 360
  degrees for joint angles that wind round (normally 0);
* ``p`` is the trigonometric interpolant of the ``P`` frames (:class:`CycleCurve`), so
  the curve passes exactly through every frame, can be evaluated at any phase, shifted by
  any fraction of a frame and resampled to any length without loss: resampling ``P -> N
  -> P`` (``N >= P``) returns the frames to rounding error.  This is the "common phase
  grid" on which cycles of different lengths are compared and blended;
* the root's wrap step (last frame to the next loop's first) is not stored in a cycle
  file; :func:`root_drift` explains how it is recovered.

:func:`align` finds the phase shift (and optionally the reversal) that best matches two
cycles' joint angles, exactly for all shifts at once by an FFT circular
cross-correlation, then refined to a fraction of a frame by Newton's method on the
(trigonometric) cost.  :func:`blend` forms the paper's convex combination
``y(θ) = Σ w_i x_i(θ)`` of any number of aligned cycles; :func:`transition` ramps the
weight from one cycle to another while the phase keeps advancing (the paper's homotopy).

Before blending, cycles are brought into a common frame: cycles of one skeleton written
in different conventions (an AMC capture, a BVH cycle) are re-expressed in one
(:func:`common_channels`), root translations are scaled to the reference skeleton's
size, every cycle is turned about the vertical axis so that it faces the same way
(otherwise a walk heading north and a jog heading east would have their velocities
cancel, and a CMU root facing east sits at the gimbal lock of its Euler angles), and
joint angles are moved by multiples of 360 degrees to lie within 180 degrees of the
reference's, so that 179 and -179 do not average to 0.

Between frames the trigonometric interpolant is the band-limited curve through the
frames.  On a noisy cycle it keeps the noise's size, so a cycle resampled half a frame
off its own grid can show a somewhat larger jerk (about 1.4x on the CMU cycles), where
linear interpolation would smooth the noise away instead; in exchange nothing is lost
and alignment and resampling are exact.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, replace
from numbers import Integral, Real
from typing import Any, Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import ParameterError
from ..quality.metrics import jerk_summary, loop_closure
from ..motion import Motion

__all__ = [
    "Alignment",
    "CycleCurve",
    "common_channels",
    "in_conventions_of",
    "CycleSource",
    "align",
    "as_cycle",
    "blend",
    "transition",
    "transition_steps",
    "prepare_cycle",
    "root_drift",
    "estimate_period",
    "mean_heading",
    "rotate_heading",
    "cycle_summary",
    "CYCLE_CLOSURE_LIMIT",
    "CYCLE_LENGTH_LIMIT",
    "STEP_LIMIT",
]

#: An input loops when its last-to-first step is at most this many median steps.
CYCLE_CLOSURE_LIMIT = 1.5
#: An input is one cycle when it is at most this many estimated periods long.
CYCLE_LENGTH_LIMIT = 1.5
#: A transition is continuous when no step exceeds this many typical steps.
STEP_LIMIT = 1.5
#: An input must reach this many median steps from its mean pose to count as moving.
_MIN_SPREAD = 3.0
#: Autocorrelation an input must reach at some lag to count as repeating itself.
_REPEAT_CORRELATION = 0.6
#: Metadata keys :func:`cyclecoord.extract` writes into its cycle.
_EXTRACT_KEYS = ("period_frames", "cycles_in_source")
_ANGLE_DOFS = ("rx", "ry", "rz")
_AXES = "xyz"


# ------------------------------------------------------------------------ helpers
def _wrap(x: np.ndarray) -> np.ndarray:
    """Angles wrapped into [-180, 180) degrees."""
    return (np.asarray(x, dtype=float) + 180.0) % 360.0 - 180.0


def _smoothstep(u: np.ndarray) -> np.ndarray:
    """C2 ramp from 0 (u <= 0) to 1 (u >= 1): 6u^5 - 15u^4 + 10u^3."""
    u = np.clip(np.asarray(u, dtype=float), 0.0, 1.0)
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u))


def _check_motion(m: object, name: str) -> Motion:
    if not isinstance(m, Motion):
        raise ParameterError(f"{name} must be a Motion, got {type(m).__name__}")
    if m.n_frames < 4:
        raise ParameterError(f"{name} has {m.n_frames} frames; a cycle needs at least 4")
    if not np.all(np.isfinite(m.frames)):
        raise ParameterError(f"{name} holds NaN or infinite values")
    return m


def _cycle_of(x: object, name: str) -> Motion:
    """The cycle to blend from a Motion, an :class:`ExtractionResult` or a :class:`CycleSource`.

    A Motion that does not look like one loop (see :func:`as_cycle`'s rule) is still
    used as it is, with a warning saying what to pass instead.
    """
    cycle = getattr(x, "cycle", None)
    if not isinstance(x, Motion) and isinstance(cycle, Motion):
        return _check_motion(cycle, f"{name} (its .cycle)")
    if not isinstance(x, Motion):
        raise ParameterError(
            f"{name} must be a cycle: a Motion, the result of cyclecoord.extract (or its "
            f".cycle), or a CycleSource from as_cycle; got {type(x).__name__}"
        )
    m = _check_motion(x, name)
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
        why.append(f"it repeats every {period:.0f} frames ({motion.n_frames / period:.1f} periods long)")
    return why


def _check_up(up: str) -> int:
    if not isinstance(up, str) or up.lower() not in ("x", "y", "z"):
        raise ParameterError(f"up must be 'x', 'y' or 'z', got {up!r}")
    return _AXES.index(up.lower())


def _angle_columns(channels: Sequence[tuple[str, str]]) -> np.ndarray:
    return np.array([d in _ANGLE_DOFS for _, d in channels], dtype=bool)


def _root_columns(m: Motion) -> np.ndarray:
    return np.asarray(m.root_channels(), dtype=int)


def _horizontal_columns(m: Motion, up_index: int) -> np.ndarray:
    """Root translation columns across the ground (every root t* but the up axis)."""
    up = "t" + _AXES[up_index]
    return np.array(
        [c for c in _root_columns(m) if m.channels[c][1] in ("tx", "ty", "tz") and m.channels[c][1] != up],
        dtype=int,
    )


def _pose_columns(m: Motion) -> np.ndarray:
    """Columns compared by :func:`align`: every channel but the root's (all if none)."""
    root = set(_root_columns(m).tolist())
    cols = np.array([i for i in range(m.n_channels) if i not in root], dtype=int)
    return cols if cols.size else np.arange(m.n_channels)


# ---------------------------------------------------------------- trigonometric curves
def _coefficients(samples: np.ndarray) -> np.ndarray:
    """Coefficients ``a`` (K + 1, D) of the trigonometric interpolant of ``P`` samples.

    ``p(θ) = Re Σ_k a_k exp(2πikθ)``, ``k = 0 .. K = P // 2``, passes through
    ``samples[j]`` at ``θ = j / P``.  For even ``P`` the highest term is a cosine.
    """
    n = samples.shape[0]
    a = np.fft.rfft(samples, axis=0) / n
    a[1:] *= 2.0
    if n % 2 == 0:
        a[-1] *= 0.5
    return a


def _sample_coefficients(a: np.ndarray, n: int) -> np.ndarray:
    """Values ``(n, D)`` of the curve at ``θ = j / n``, low-passed to what ``n`` samples hold.

    Harmonics at or above ``n / 2`` cannot be represented by ``n`` samples; they are
    dropped (the ``n / 2`` one keeps its cosine part, its exact value on this grid).
    With ``n > 2K`` the values are exact samples of the curve.
    """
    K = a.shape[0] - 1
    half = n // 2
    y = np.zeros((half + 1, a.shape[1]), dtype=complex)
    m = min(K, half)
    y[: m + 1] = a[: m + 1]
    y[1:] *= 0.5
    if n % 2 == 0 and m == half:
        y[half] = a[half].real  # the n/2 harmonic is (-1)^j on this grid: once, real
    y *= n
    return np.fft.irfft(y, n=n, axis=0)


def _evaluate_coefficients(a: np.ndarray, phases: np.ndarray) -> np.ndarray:
    """Values ``(M, D)`` of the periodic part at arbitrary phases (cycles)."""
    theta = np.mod(np.asarray(phases, dtype=float), 1.0)
    k = np.arange(a.shape[0])
    e = np.exp(2j * np.pi * np.outer(theta, k))
    return (e @ a).real


@dataclass(frozen=True, eq=False)
class CycleCurve:
    """One cycle as a continuous closed curve of its phase.

    ``x(θ) = drift · θ + Re Σ_k coefficients[k] · exp(2πikθ)``; ``θ`` in cycles, any
    real value (``x(θ + 1) = x(θ) + drift``).  Frame ``j`` of the source cycle is
    ``x(j / n_frames)``.

    Attributes
    ----------
    coefficients : ndarray of complex, shape (K + 1, D)
        Trigonometric coefficients of the periodic part, channel units.
    drift : ndarray, shape (D,)
        Change per loop (root travel and turn; multiples of 360 for winding angles).
    n_frames : int
        Frames in the source cycle (``P``).
    fps : float
        Frame rate of the source cycle; the period lasts ``n_frames / fps`` seconds.
    channels : tuple of (str, str)
        ``(joint, dof)`` per column.
    root_columns : tuple of int
        Columns holding root translation and rotation.
    """

    coefficients: np.ndarray
    drift: np.ndarray
    n_frames: int
    fps: float
    channels: tuple
    root_columns: tuple = ()

    # ------------------------------------------------------------ construction
    @classmethod
    def from_motion(cls, motion: Motion, displacement: np.ndarray | None = None) -> "CycleCurve":
        """The curve through a cycle's frames.

        Joint angles are first made continuous (no jump over 180 degrees between frames,
        nor across the loop's seam, where a whole turn becomes drift); root channels get
        their per-loop drift from :func:`root_drift` (or ``displacement``).

        Parameters
        ----------
        motion : Motion
            One cycle, at least 4 frames.
        displacement : array_like, shape (R,), optional
            Known per-loop change of the root channels (``motion.root_channels()``
            order); default: ``motion.metadata["root_displacement"]`` when present, else
            estimated.
        """
        motion = _check_motion(motion, "the cycle")
        x = np.array(motion.frames, dtype=float)
        n, d = x.shape
        root = _root_columns(motion)
        angles = _angle_columns(motion.channels)
        drift = np.zeros(d)
        is_root = np.zeros(d, dtype=bool)
        is_root[root] = True
        for c in np.flatnonzero(angles & ~is_root):
            x[:, c] = np.unwrap(x[:, c], period=360.0)
            seam = _wrap(x[0, c] - x[-1, c])
            drift[c] = np.round((x[-1, c] + seam - x[0, c]) / 360.0) * 360.0
        if root.size:
            x[:, root] = _continuous_root(motion.frames[:, root], angles[root])
            drift[root] = root_drift(motion, displacement)
        theta = np.arange(n) / n
        periodic = x - np.outer(theta, drift)
        return cls(
            coefficients=_coefficients(periodic),
            drift=drift,
            n_frames=int(n),
            fps=float(motion.fps),
            channels=tuple(motion.channels),
            root_columns=tuple(int(c) for c in root),
        )

    # -------------------------------------------------------------- evaluation
    @property
    def n_channels(self) -> int:
        return int(self.coefficients.shape[1])

    @property
    def period_seconds(self) -> float:
        """Duration of one loop in seconds."""
        return self.n_frames / self.fps

    def __call__(self, phases: np.ndarray | float) -> np.ndarray:
        """Channel values at the given phases (cycles), shape ``(M, D)``."""
        th = np.atleast_1d(np.asarray(phases, dtype=float))
        return _evaluate_coefficients(self.coefficients, th) + np.outer(th, self.drift)

    def sample(self, n_frames: int) -> np.ndarray:
        """The loop at ``n_frames`` evenly spaced phases ``j / n_frames``, shape ``(n, D)``.

        Harmonics too fast for ``n_frames`` samples are dropped (band-limited
        resampling), so shortening a cycle does not alias.
        """
        n = int(n_frames)
        if n < 2:
            raise ParameterError(f"a cycle needs at least 2 frames, got {n_frames}")
        theta = np.arange(n) / n
        return _sample_coefficients(self.coefficients, n) + np.outer(theta, self.drift)

    # ----------------------------------------------------------- transforms
    def shifted(self, shift: float) -> "CycleCurve":
        """The curve ``θ -> x(θ + shift)`` (shift in cycles)."""
        k = np.arange(self.coefficients.shape[0])
        a = self.coefficients * np.exp(2j * np.pi * k * float(shift))[:, None]
        a[0] = a[0] + self.drift * float(shift)
        return replace(self, coefficients=a)

    def reversed(self) -> "CycleCurve":
        """The curve played backwards, ``θ -> x(-θ)`` (root travel reverses too)."""
        return replace(self, coefficients=np.conj(self.coefficients), drift=-self.drift)

    def offset(self, values: np.ndarray) -> "CycleCurve":
        """The curve plus a constant per channel."""
        a = self.coefficients.copy()
        a[0] = a[0] + np.asarray(values, dtype=float)
        return replace(self, coefficients=a)

    def padded(self, n_harmonics: int) -> np.ndarray:
        """Coefficients padded with zeros to ``n_harmonics + 1`` rows."""
        K = self.coefficients.shape[0] - 1
        if n_harmonics <= K:
            return self.coefficients[: n_harmonics + 1]
        out = np.zeros((n_harmonics + 1, self.n_channels), dtype=complex)
        out[: K + 1] = self.coefficients
        return out


def _continuous_root(values: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Root channels with rotation steps wrapped into ±180 (continuous angles)."""
    x = np.array(values, dtype=float)
    if rotation.any():
        steps = _wrap(np.diff(x[:, rotation], axis=0))
        x[1:, rotation] = x[0, rotation] + np.cumsum(steps, axis=0)
    return x


def _seam_estimate(steps: np.ndarray) -> np.ndarray:
    """The unseen step between frame P-1 and the next loop's frame 0.

    ``steps[i]`` is frame ``i`` -> ``i + 1`` for ``i < P - 1``.  The root velocity is
    periodic, so the missing step sits between ``steps[P - 2]`` (before) and
    ``steps[0]`` (after); it is interpolated from the two steps on either side with
    the 4-point Lagrange weights (-1/6, 2/3, 2/3, -1/6) (exact for cubic velocity
    profiles), or as the mean of the two neighbours for very short cycles.
    """
    n = steps.shape[0]
    if n >= 4:
        return (-steps[-2] + 4.0 * steps[-1] + 4.0 * steps[0] - steps[1]) / 6.0
    return 0.5 * (steps[-1] + steps[0])


def root_drift(motion: Motion, displacement: np.ndarray | None = None) -> np.ndarray:
    """Per-loop change of a cycle's root channels (travel, turn).

    A cycle written by :func:`cyclecoord.extract` travels ``D`` per loop: its per-frame
    root steps over one loop (``P`` steps, the last one from frame ``P - 1`` to the next
    loop's frame 0) sum to ``D``.  The ``P - 1`` steps inside the file give
    ``x[P-1] - x[0]``; the wrap step is not stored, so ``D = x[P-1] - x[0] + wrap``
    with ``wrap`` recovered as follows, channel by channel:

    * **closed channel** -- when going straight back to frame 0
      (``x[0] - x[P-1]``, wrapped into ±180 for angles) is as plausible a step as its
      neighbours (within half the larger neighbouring or median step plus twice the
      median change between consecutive steps), the channel does not drift: ``wrap``
      is that step (``D = 0``, or a whole turn for a spinning angle).  Root height
      and tilt are such channels;
    * **travelling channel** -- otherwise the wrap step is interpolated from the
      steps on either side of the seam (:func:`_seam_estimate`; exact for a cubic
      velocity profile, in particular for constant speed).

    Parameters
    ----------
    motion : Motion
        One cycle with absolute root channels.
    displacement : array_like, shape (R,), optional
        The answer when known (e.g. ``motion.metadata["root_displacement"]``, which
        :func:`blend` writes); returned as given.

    Returns
    -------
    ndarray, shape (R,)
        Change per loop of each ``motion.root_channels()`` column, in channel units
        (degrees for rotations).
    """
    root = _root_columns(motion)
    if displacement is None:
        displacement = motion.metadata.get("root_displacement") if isinstance(motion.metadata, dict) else None
    if displacement is not None:
        disp = np.asarray(displacement, dtype=float).reshape(-1)
        if disp.shape[0] != root.size or not np.all(np.isfinite(disp)):
            raise ParameterError(
                f"root displacement needs {root.size} finite values (one per root channel), got {disp.shape[0]}"
            )
        return disp
    if root.size == 0:
        return np.zeros(0)
    if motion.n_frames < 3:
        raise ParameterError("estimating a cycle's root travel needs at least 3 frames")
    rot = _angle_columns([motion.channels[c] for c in root])
    x = _continuous_root(motion.frames[:, root], rot)
    steps = np.diff(x, axis=0)  # (P-1, R)
    closed = x[0] - x[-1]
    closed[rot] = _wrap(closed[rot])
    estimate = _seam_estimate(steps)
    med_step = np.median(np.abs(steps), axis=0)
    med_change = np.median(np.abs(np.diff(steps, axis=0)), axis=0) if steps.shape[0] > 1 else np.zeros(root.size)
    neighbour = np.maximum(np.abs(steps[-1]), np.abs(steps[0]))
    tol = 0.5 * np.maximum(neighbour, med_step) + 2.0 * med_change + 1e-9
    wrap = np.where(np.abs(closed - estimate) <= tol, closed, estimate)
    return x[-1] - x[0] + wrap


def prepare_cycle(motion: Motion, displacement: np.ndarray | None = None) -> np.ndarray:
    """A cycle in the prepared space, with the loop's wrap step.

    Root channels become per-frame steps ``x[i+1] - x[i]`` (rotations wrapped into
    ±180), the last one being the step from frame ``P - 1`` into the next loop (see
    :func:`root_drift`); other channels are unchanged.  This is the space in which
    :func:`cyclecoord.extract` builds its typical cycle, so loop closure and jerk
    (with ``cyclic=True``) can be compared with its figures.

    Parameters
    ----------
    motion : Motion
        One cycle.
    displacement : array_like, optional
        Known per-loop root change (see :func:`root_drift`).

    Returns
    -------
    ndarray, shape (P, D)
    """
    motion = _check_motion(motion, "the cycle")
    out = np.array(motion.frames, dtype=float)
    root = _root_columns(motion)
    if root.size:
        rot = _angle_columns([motion.channels[c] for c in root])
        x = _continuous_root(motion.frames[:, root], rot)
        drift = root_drift(motion, displacement)
        nxt = np.vstack([x[1:], x[:1] + drift])
        out[:, root] = nxt - x
    return out


def cycle_summary(motion: Motion) -> dict[str, float]:
    """Figures of a cycle: frames, seconds, loop closure and jerk in the prepared space.

    Returns
    -------
    dict
        ``frames``, ``seconds``, ``loop_closure`` (last-to-first step over the median
        step; up to about 1.5 loops cleanly; see :func:`cyclecoord.quality.metrics.loop_closure`), ``jerk``
        (mean jerk norm, looping, channel units / s³) and ``median_step``.
    """
    prep = prepare_cycle(motion)
    steps = np.linalg.norm(np.roll(prep, -1, axis=0) - prep, axis=1)
    return {
        "frames": int(motion.n_frames),
        "seconds": float(motion.n_frames / motion.fps),
        "loop_closure": float(loop_closure(prep)),
        "jerk": float(jerk_summary(prep, motion.fps, cyclic=True)) if motion.n_frames >= 7 else float("nan"),
        "median_step": float(np.median(steps)),
    }


# ---------------------------------------------------------------------- alignment
@dataclass(frozen=True)
class Alignment:
    """How to shift (and possibly reverse) cycle ``b`` to match cycle ``a``.

    ``b(shift + θ)`` (or ``b(shift - θ)`` when ``reversed``) is closest to ``a(θ)``.

    Attributes
    ----------
    shift : float
        Phase offset in cycles, in ``[0, 1)``.
    reversed : bool
        Whether ``b`` runs the other way round.
    cost : float
        Root mean square difference of the compared channels after alignment,
        ``sqrt(∫ |a(θ) - b(...)|² dθ / C)`` over the ``C`` compared channels, in
        channel units (degrees for joint angles).
    shift_frames : float
        The same offset in frames of ``b``, as the nearest way round: in
        ``(-P_b / 2, P_b / 2]``.
    cost_unaligned : float
        The same figure without shifting or reversing, for comparison.
    """

    shift: float
    reversed: bool
    cost: float
    shift_frames: float = 0.0
    cost_unaligned: float = float("nan")

    def to_dict(self) -> dict[str, Any]:
        return {
            "shift": float(self.shift),
            "shift_frames": float(self.shift_frames),
            "reversed": bool(self.reversed),
            "cost": float(self.cost),
            "cost_unaligned": float(self.cost_unaligned),
        }


def _cross_terms(fa: np.ndarray, fb: np.ndarray) -> tuple[np.ndarray, float]:
    """``h_k = Σ_channels conj(a_k) b_k`` and the shift-independent part of the cost."""
    K = max(fa.shape[0], fb.shape[0]) - 1

    def pad(a: np.ndarray) -> np.ndarray:
        if a.shape[0] == K + 1:
            return a
        out = np.zeros((K + 1, a.shape[1]), dtype=complex)
        out[: a.shape[0]] = a
        return out

    fa, fb = pad(fa), pad(fb)
    h = np.einsum("kd,kd->k", np.conj(fa), fb)
    energy = (
        np.sum(fa[0].real ** 2) + np.sum(fb[0].real ** 2) - 2.0 * np.sum(fa[0].real * fb[0].real)
        + 0.5 * np.sum(np.abs(fa[1:]) ** 2) + 0.5 * np.sum(np.abs(fb[1:]) ** 2)
    )
    return h, float(energy)


def _best_shift(h: np.ndarray, energy: float) -> tuple[float, float]:
    """Shift ``s`` in [0, 1) maximising ``g(s) = Σ_{k>=1} Re(h_k e^{2πiks})`` and the cost there.

    The squared distance between the curves is ``energy - g(s)``.  ``g`` is evaluated
    at ``M`` equally spaced shifts at once by an inverse FFT (the circular
    cross-correlation), then the best one is refined by safeguarded Newton steps on
    ``g'(s) = 0`` inside the bracket of its grid neighbours.
    """
    K = h.shape[0] - 1
    if K < 1:
        return 0.0, max(energy, 0.0)
    M = 256
    while M < 4 * (K + 1):
        M *= 2
    spec = np.zeros(M // 2 + 1, dtype=complex)
    spec[1 : K + 1] = 0.5 * M * h[1:]
    g_grid = np.fft.irfft(spec, n=M)
    j = int(np.argmax(g_grid))
    k = np.arange(1, K + 1)
    hk = h[1:]

    def derivs(s: float) -> tuple[float, float, float]:
        e = hk * np.exp(2j * np.pi * k * s)
        return (
            float(np.sum(e.real)),
            float(np.sum((2j * np.pi * k * e).real)),
            float(np.sum((-(2 * np.pi * k) ** 2 * e).real)),
        )

    lo, hi = (j - 1) / M, (j + 1) / M
    s = j / M
    g_lo, g_hi = derivs(lo)[1], derivs(hi)[1]
    if g_lo > 0.0 > g_hi:
        for _ in range(60):
            _, g1, g2 = derivs(s)
            if g1 > 0:
                lo = s
            else:
                hi = s
            step = -g1 / g2 if g2 < 0 else np.inf
            new = s + step
            if not (lo < new < hi):
                new = 0.5 * (lo + hi)
            if abs(new - s) < 1e-15:
                s = new
                break
            s = new
    g_best = derivs(s)[0]
    return float(np.mod(s, 1.0)), max(energy - g_best, 0.0)


def _harmonise_angles(curve: CycleCurve, reference: CycleCurve) -> CycleCurve:
    """Move each angle channel by whole turns so its mean is within 180 of the reference's."""
    angles = _angle_columns(curve.channels)
    if not angles.any():
        return curve
    diff = reference.coefficients[0].real - curve.coefficients[0].real
    turns = np.where(angles, np.round(diff / 360.0), 0.0)
    if not np.any(turns):
        return curve
    return curve.offset(360.0 * turns)


def _align_curves(a: CycleCurve, b: CycleCurve, columns: np.ndarray, allow_reverse: bool) -> Alignment:
    fa = a.coefficients[:, columns]
    fb = b.coefficients[:, columns]
    n_cols = max(int(columns.size), 1)
    h, energy = _cross_terms(fa, fb)
    unaligned = max(energy - float(np.sum(h[1:].real)), 0.0)
    shift, cost = _best_shift(h, energy)
    rev = False
    if allow_reverse:
        h_r, energy_r = _cross_terms(fa, np.conj(fb))
        shift_r, cost_r = _best_shift(h_r, energy_r)
        if cost_r < cost:
            shift, cost, rev = shift_r, cost_r, True
    # b reversed then shifted by s: b(-(θ + s)) = b(-s - θ); report the offset in b's phase
    phase = float(np.mod(-shift, 1.0)) if rev else shift
    if phase >= 1.0 - 1e-12:
        phase = 0.0
    return Alignment(
        shift=phase,
        reversed=rev,
        cost=float(np.sqrt(cost / n_cols)),
        shift_frames=(phase - 1.0 if phase > 0.5 else phase) * b.n_frames,
        cost_unaligned=float(np.sqrt(unaligned / n_cols)),
    )


def _apply_alignment(curve: CycleCurve, al: Alignment) -> CycleCurve:
    """``b(shift + θ)``, or ``b(shift - θ)`` when reversed."""
    if al.reversed:
        return curve.reversed().shifted(-al.shift)
    return curve.shifted(al.shift)


def _as_curve(x: Motion | CycleCurve, name: str) -> CycleCurve:
    if isinstance(x, CycleCurve):
        return x
    if isinstance(x, Motion):
        return CycleCurve.from_motion(_check_motion(x, name))
    raise ParameterError(f"{name} must be a Motion or a CycleCurve, got {type(x).__name__}")


def align(a: Motion | CycleCurve, b: Motion | CycleCurve, allow_reverse: bool = True) -> Alignment:
    """The phase offset (and direction) that best matches cycle ``b`` to cycle ``a``.

    Both cycles are taken as closed curves of their phase (:class:`CycleCurve`; cycles
    of different lengths are compared on the common phase circle, exactly).  The
    compared channels are the pose: every channel but the root's (root travel and
    heading say nothing about the phase of a gait), with ``b``'s angles moved by whole
    turns to within 180 degrees of ``a``'s.  The squared distance
    ``∫ |a(θ) - b(s + θ)|² dθ`` is computed for all shifts on a fine grid at once by an
    FFT circular cross-correlation and the best shift refined by Newton's method on
    the exact (trigonometric) cost, so whole and fractional frame offsets are found
    to rounding error.

    Parameters
    ----------
    a, b : Motion or CycleCurve
        Cycles with the same channels (``b``'s may be in another order).
    allow_reverse : bool, default True
        Also try ``b`` played backwards and keep it when it matches better.

    Returns
    -------
    Alignment
        ``shift`` in cycles of ``b``'s phase, ``reversed``, and the residual ``cost``.

    Raises
    ------
    ParameterError
        For inputs that are not cycles or do not share channels.

    Examples
    --------
    >>> import numpy as np, cyclecoord as cc
    >>> from cyclecoord.synthesis.interpolate import align
    >>> cap = cc.datasets.make_periodic_capture(n_frames=100, period=100, noise=0,
    ...                                           speed_variation=0, random_state=0)
    >>> cycle = cap.motion
    >>> al = align(cycle, cycle.with_frames(np.roll(cycle.frames, -25, axis=0)))
    >>> round(al.shift, 6), round(al.shift_frames, 6), al.reversed
    (0.75, -25.0, False)
    """
    if isinstance(a, Motion) and isinstance(b, Motion):
        a, b = common_channels([_check_motion(a, "a"), _check_motion(b, "b")])
    ca = _as_curve(a, "a")
    cb = _as_curve(b, "b")
    cb = _reorder_curve(cb, ca.channels)
    cb = _harmonise_angles(cb, ca)
    root = set(ca.root_columns)
    cols = np.array([i for i in range(ca.n_channels) if i not in root], dtype=int)
    if cols.size == 0:
        cols = np.arange(ca.n_channels)
    return _align_curves(ca, cb, cols, bool(allow_reverse))


def _reorder_curve(curve: CycleCurve, channels: tuple) -> CycleCurve:
    if curve.channels == tuple(channels):
        return curve
    _check_same_channels(curve.channels, channels, "b")
    idx = [curve.channels.index(c) for c in channels]
    root = tuple(idx.index(c) for c in curve.root_columns)
    return replace(
        curve,
        coefficients=curve.coefficients[:, idx],
        drift=curve.drift[idx],
        channels=tuple(channels),
        root_columns=tuple(sorted(root)),
    )


def _check_same_channels(have: Sequence, want: Sequence, name: str) -> None:
    if set(have) != set(want) or len(have) != len(want):
        missing = sorted(set(want) - set(have))[:4]
        extra = sorted(set(have) - set(want))[:4]
        raise ParameterError(
            f"{name} does not have the same channels as the reference cycle "
            f"(missing {missing}, extra {extra})"
        )



def _bvh_ready(skeleton) -> str | None:
    """The shared Euler order when every joint is BVH-style (identity axis, 3 rotations)."""
    orders = {j.rotation_order for j in skeleton.joints}
    if len(orders) == 1 and all(np.allclose(j.axis, np.eye(3)) for j in skeleton.joints):
        order = orders.pop()
        return order if len(order) == 3 else None
    return None


def _reexpress(motion: Motion, conventions) -> Motion:
    """``motion`` with another skeleton's joint conventions (axis, dofs, Euler order).

    Each joint keeps its own offset and end site; its local rotation is written with
    the conventions' axis ``C`` and rotation dofs: ``C.T @ local @ C`` decomposed in the
    joint's order, with the missing axes placed so that a rotation the dofs can make is
    recovered exactly (a hinge stays a hinge); what they cannot make is dropped.
    """
    from ..conventions import continuous_euler, local_rotations
    from ..skeleton import Joint, Skeleton

    skel = motion.skeleton
    local = local_rotations(motion)  # (J, T, 3, 3)
    col = {c: i for i, c in enumerate(motion.channels)}
    T = motion.n_frames
    joints, columns, channels = [], [], []
    for i, (mine, conv) in enumerate(zip(skel.joints, conventions.joints)):
        order = conv.rotation_order
        t_dofs = [d for d in conv.dofs if d.startswith("t")]
        values = {}
        for d in t_dofs:
            k = col.get((mine.name, d))
            values[d] = motion.frames[:, k] if k is not None else np.full(T, mine.offset["xyz".index(d[1])])
        if order:
            missing = [a for a in "XYZ" if a not in order]
            full = order[0] + "".join(missing) + order[1:] if len(order) == 2 else order + "".join(missing)
            keep = [0, 2] if len(order) == 2 else list(range(len(order)))
            rel = conv.axis.T @ local[i] @ conv.axis
            angles = continuous_euler(rel[:, None], full)[:, 0, keep]
            for a, ax in zip(angles.T, order.lower()):
                values["r" + ax] = a
        for d in conv.dofs:
            columns.append(values[d])
            channels.append((mine.name, d))
        joints.append(Joint(
            name=mine.name, parent=mine.parent, offset=mine.offset.copy(), dofs=tuple(conv.dofs),
            rotation_order=order, axis=conv.axis.copy(),
            end_site=None if mine.end_site is None else mine.end_site.copy(), limits=dict(conv.limits),
        ))
    new = Skeleton(joints=tuple(joints), name=skel.name, length_unit=skel.length_unit,
                   source_format=conventions.source_format)
    frames = np.column_stack(columns) if columns else np.zeros((T, 0))
    return replace(motion, frames=frames, channels=tuple(channels), skeleton=new)


def _same_conventions(a, b) -> bool:
    """Same joints with the same axes, dofs and Euler orders."""
    return a.names == b.names and all(
        x.dofs == y.dofs and x.rotation_order == y.rotation_order and np.allclose(x.axis, y.axis)
        for x, y in zip(a.joints, b.joints)
    )


def _match_branches(motion: Motion, target: Motion) -> Motion:
    """Per joint, the Euler solution closest to ``target``'s angles.

    Three Euler angles ``(a, b, c)`` and ``(a + 180, 180 - b, c + 180)`` give the same
    rotation; two motions written on different solutions would blend into nonsense.
    For every joint but the root with three rotation channels, the whole sequence is
    moved to the solution (and whole turns) nearest the target's mean angles.
    """
    if motion.skeleton is None:
        return motion
    frames = np.array(motion.frames, dtype=float)
    changed = False
    for j in motion.skeleton.joints[1:]:  # the root's heading is matched by turning instead
        if len(j.rotation_order) != 3:
            continue
        chans = [(j.name, "r" + ax.lower()) for ax in j.rotation_order]
        if not all(c in target.channels for c in chans):
            continue
        cols = [motion.channel_index(*c) for c in chans]
        goal = np.array([np.mean(target.frames[:, target.channel_index(*c)]) for c in chans])
        x = frames[:, cols]
        alt = x + np.array([180.0, 0.0, 180.0])
        alt[:, 1] = 180.0 - x[:, 1]

        def nearest(v: np.ndarray) -> tuple[np.ndarray, float]:
            v = v - 360.0 * np.round((v.mean(axis=0) - goal) / 360.0)
            return v, float(np.abs(_wrap(v - goal)).sum() + 1e-9 * np.abs(v.mean(axis=0) - goal).sum())

        x1, d1 = nearest(x)
        x2, d2 = nearest(alt)
        best = x2 if d2 < d1 else x1
        if not np.array_equal(best, x):
            frames[:, cols] = best
            changed = True
    return motion.with_frames(frames) if changed else motion


def in_conventions_of(motion: Motion, template: Motion) -> Motion:
    """``motion`` written with ``template``'s channels (same joints, other conventions).

    Returns ``motion`` itself when the channels already match (reordered if needed) or
    the skeletons do not have the same joints.
    """
    if set(motion.channels) == set(template.channels) and motion.n_channels == template.n_channels:
        return motion if motion.channels == template.channels else motion.select(template.channels)
    sk, tk = motion.skeleton, template.skeleton
    if sk is None or tk is None or sk.names != tk.names or _same_conventions(sk, tk):
        return motion
    out = _match_branches(_reexpress(motion, tk), template)
    return out.select(template.channels) if set(out.channels) == set(template.channels) else out


def common_channels(motions: Sequence[Motion]) -> list[Motion]:
    """The motions with one set of channels, in one order.

    Motions whose channels are the same set are only reordered to the first one's.
    Motions of skeletons with the same joints written in different conventions (an
    ASF/AMC capture and a BVH cycle :func:`cyclecoord.extract` wrote: ASF axes and 1-3
    rotations per joint against identity axes and 3 Euler angles) are re-expressed in
    one convention so that equal channels mean equal joint rotations: the first
    ASF-style input's (anatomical axes, hinges stay hinges, which blend better), or the
    first input's Euler order when all are BVH-style.

    Raises
    ------
    ParameterError
        When the channels differ and the skeletons do not have the same joints.
    """
    motions = list(motions)
    ref = motions[0]
    if all(set(m.channels) == set(ref.channels) and m.n_channels == ref.n_channels for m in motions):
        return [m if m.channels == ref.channels else m.select(ref.channels) for m in motions]
    skels = [m.skeleton for m in motions]
    if (
        any(sk is None for sk in skels)
        or any(sk.names != skels[0].names for sk in skels)
        or all(_same_conventions(sk, skels[0]) for sk in skels)
    ):
        for i, m in enumerate(motions[1:], start=1):
            _check_same_channels(m.channels, ref.channels, f"cycle {i}")
    asf = [i for i, sk in enumerate(skels) if _bvh_ready(sk) is None]
    if asf:
        anchor = motions[asf[0]]
        out = [m if m.skeleton is anchor.skeleton else _reexpress(m, anchor.skeleton) for m in motions]
    else:
        from ..conventions import to_bvh_convention

        order = _bvh_ready(skels[0])
        anchor = motions[0]
        out = [m if _bvh_ready(m.skeleton) == order else to_bvh_convention(m, order) for m in motions]
    # converted motions take the Euler solutions nearest the unconverted anchor's
    out = [m if m is orig else _match_branches(m, anchor) for m, orig in zip(out, motions)]
    first = out[0].channels
    return [m if m.channels == first else m.select(first) for m in out]

# ----------------------------------------------------------------------- heading
def _root_rotation(motion: Motion) -> tuple[np.ndarray, str, np.ndarray]:
    """World rotation of the root per frame ``(T, 3, 3)``, its Euler order and columns."""
    skel = motion.skeleton
    if skel is None:
        raise ParameterError("turning a motion needs its skeleton; this motion has none")
    root = skel.joints[0]
    order = root.rotation_order
    if len(order) != 3:
        raise ParameterError(
            f"turning a motion needs a root with three rotation channels; {root.name!r} has {order or 'none'}"
        )
    try:
        cols = np.array([motion.channel_index(root.name, "r" + ax.lower()) for ax in order], dtype=int)
    except KeyError as exc:
        raise ParameterError(f"turning a motion needs every root rotation channel: {exc}") from None
    local = Rotation.from_euler(order, motion.frames[:, cols], degrees=True).as_matrix()
    if not np.allclose(root.axis, np.eye(3)):
        local = root.axis @ local @ root.axis.T
    return local, order, cols


def mean_heading(motion: Motion, up: str = "y") -> float:
    """Direction the root faces on average, as an angle about the vertical axis.

    The root's forward proxy is its rest frame's axis following ``up`` cyclically
    (``z`` when ``up`` is ``y``, as in CMU and BVH data: a CMU walker faces its root's
    ``+z``), turned by the root's rotation each frame, projected on the ground and
    averaged over the frames.  The heading is its angle from that world axis, positive
    turning towards the next one (from ``+z`` towards ``+x`` for ``up="y"``).

    Parameters
    ----------
    motion : Motion
        With a skeleton whose root has three rotation channels.
    up : {"x", "y", "z"}
        The vertical axis of the skeleton's world (default ``"y"``).

    Returns
    -------
    float
        Degrees in (-180, 180]; ``nan`` when the averaged forward vector is shorter
        than 0.1 (a motion spinning round has no mean heading).
    """
    u = _check_up(up)
    mats, _, _ = _root_rotation(motion)
    fwd_axis = np.zeros(3)
    fwd_axis[(u + 1) % 3] = 1.0
    fwd = mats @ fwd_axis  # the rest pose faces +fwd_axis; the root's world rotation turns it
    f = fwd[:, (u + 1) % 3].mean()
    s = fwd[:, (u + 2) % 3].mean()
    if np.hypot(f, s) < 0.1:
        return float("nan")
    return float(np.degrees(np.arctan2(s, f)))


def _continuous_euler(mats: np.ndarray, order: str, near: np.ndarray | None) -> np.ndarray:
    """Euler angles ``(T, 3)`` of rotations, continuous over time.

    Each rotation has two solutions, ``(a, b, c)`` and ``(a + 180, 180 - b, c + 180)``,
    each up to whole turns per angle.  Frame 0 takes the one nearest ``near`` (or the
    principal one); each later frame the one nearest the previous frame.
    """
    import warnings

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*[Gg]imbal.*")
        first = Rotation.from_matrix(mats).as_euler(order, degrees=True)
    second = first + np.array([180.0, 0.0, 180.0])
    second[:, 1] = 180.0 - first[:, 1]
    out = np.empty_like(first)
    prev = near
    for t in range(first.shape[0]):
        if prev is None:
            out[t] = prev = first[t]
            continue
        a = first[t] + 360.0 * np.round((prev - first[t]) / 360.0)
        b = second[t] + 360.0 * np.round((prev - second[t]) / 360.0)
        out[t] = prev = b if np.abs(b - prev).sum() < np.abs(a - prev).sum() else a
    return out


def rotate_heading(
    motion: Motion,
    angle: float,
    up: str = "y",
    near: np.ndarray | None = None,
) -> Motion:
    """Turn a motion about the vertical line through its first root position.

    The root's world rotation is pre-multiplied by the turn and converted back to its
    Euler channels (kept continuous over time); its ground-plane translation is turned
    about the frame-0 position.  Joint channels are unchanged.

    Parameters
    ----------
    motion : Motion
        With a skeleton whose root has three rotation channels and translation
        channels on both ground axes.
    angle : float
        Degrees, positive as :func:`mean_heading` counts.
    up : {"x", "y", "z"}
        Vertical axis.
    near : array_like, shape (3,), optional
        Root rotation channel values (in the root's Euler order) the first frame's
        solution should lie closest to; default SciPy's principal solution (middle
        angle within ±90 degrees).

    Returns
    -------
    Motion
        Same channels, skeleton and rate; ``angle == 0`` returns ``motion`` itself.
    """
    u = _check_up(up)
    if not isinstance(angle, Real) or not np.isfinite(angle):
        raise ParameterError(f"angle must be a finite number of degrees, got {angle!r}")
    if angle == 0.0:
        return motion
    mats, order, rcols = _root_rotation(motion)
    skel = motion.skeleton
    assert skel is not None
    root = skel.joints[0]
    axis_vec = np.zeros(3)
    axis_vec[u] = 1.0
    turn = Rotation.from_rotvec(np.radians(float(angle)) * axis_vec).as_matrix()
    new_world = turn @ mats
    if not np.allclose(root.axis, np.eye(3)):
        new_world = root.axis.T @ new_world @ root.axis
    frames = np.array(motion.frames, dtype=float)
    if near is not None:
        near = np.asarray(near, dtype=float).reshape(3)
    frames[:, rcols] = _continuous_euler(new_world, order, near)
    ground = [(u + 1) % 3, (u + 2) % 3]
    tcols = []
    for ax in ground:
        try:
            tcols.append(motion.channel_index(root.name, "t" + _AXES[ax]))
        except KeyError:
            raise ParameterError(
                f"turning a motion needs the root's t{_AXES[ax]} channel; it has none"
            ) from None
    pos = np.zeros((motion.n_frames, 3))
    pos[:, ground[0]] = frames[:, tcols[0]]
    pos[:, ground[1]] = frames[:, tcols[1]]
    centre = pos[0].copy()
    pos = (pos - centre) @ turn.T + centre
    frames[:, tcols[0]] = pos[:, ground[0]]
    frames[:, tcols[1]] = pos[:, ground[1]]
    return motion.with_frames(frames)


# ---------------------------------------------------------------- input handling
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
        Last-to-first step over the median step of the input (prepared space).
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
            "input_period_estimate": None if self.period_estimate is None else float(self.period_estimate),
        }
        if self.extraction is not None:
            r = self.extraction
            out["extraction"] = {
                "frames": [int(r.motion.start_frame), int(r.motion.start_frame + r.motion.n_frames)],
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
    m = _check_motion(motion, "the input")
    x = np.array(m.frames[:, _pose_columns(m)], dtype=float)
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
    x = np.asarray(motion.frames[:, _pose_columns(motion)], dtype=float)
    step = float(np.median(np.linalg.norm(np.diff(x, axis=0), axis=1)))
    reach = float(np.linalg.norm(x - x.mean(axis=0), axis=1).max())
    if step == 0.0:
        return 0.0 if reach == 0.0 else float("inf")
    return reach / step


def _input_closure(motion: Motion) -> float:
    from ..periodic.preprocess import difference_root

    root = _root_columns(motion)
    rot = _angle_columns([motion.channels[c] for c in root])
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
       :data:`CYCLE_CLOSURE_LIMIT` (1.5) times its median step in the prepared space
       (it loops); it does not repeat itself within its length: the autocorrelation of
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
    motion = _check_motion(motion, "the input")
    closure = _input_closure(motion)
    period = estimate_period(motion)
    meta = motion.metadata if isinstance(motion.metadata, dict) else {}
    if mode == "cycle":
        return CycleSource(motion, False, "taken as a cycle (forced)", closure, period)
    if mode == "auto":
        if frames is None and (meta.get("cycle") is True or all(k in meta for k in _EXTRACT_KEYS)):
            return CycleSource(motion, False, "a cycle written by cyclecoord (metadata)", closure, period)
        loops = closure <= CYCLE_CLOSURE_LIMIT
        single = period is None or motion.n_frames <= CYCLE_LENGTH_LIMIT * period
        spread = _pose_spread(motion)
        moves = spread >= _MIN_SPREAD
        if loops and single and moves:
            return CycleSource(
                motion, False,
                f"taken as a cycle: loop closure {closure:.2f} <= {CYCLE_CLOSURE_LIMIT} and no repeat within its "
                f"{motion.n_frames} frames", closure, period,
            )
        why = []
        if not loops:
            why.append(f"loop closure {closure:.2f} > {CYCLE_CLOSURE_LIMIT}")
        if not single:
            why.append(f"it repeats every {period:.0f} frames ({motion.n_frames / period:.1f} periods long)")
        if not moves:
            why.append(f"its poses stay within {spread:.1f} median steps of their mean (it barely moves)")
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
        _, _, rcols = _root_rotation(motion)
        cycle = rotate_heading(cycle, heading, up, near=motion.frames[0, rcols])
        reason += f"; extracted facing heading 0 (turned by {-heading:.1f} degrees) and turned back"
    return CycleSource(cycle, True, reason, closure, period, extraction=result)


# ----------------------------------------------------------------------- weights
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
        raise ParameterError(f"weights must be non-negative (a convex combination), got {w.tolist()}")
    total = float(w.sum())
    if abs(total - 1.0) > 1e-6:
        raise ParameterError(
            f"weights must sum to 1 (a convex combination), got {' + '.join(f'{v:g}' for v in w)} = {total:g}"
        )
    return w


# --------------------------------------------------------------- common frame
@dataclass
class _Prepared:
    curves: list
    alignments: list
    headings: list
    root_scales: list
    notes: list
    reference: Motion
    reference_heading: float
    turned: bool
    up: int
    base: Motion  # the reference in the common channels, not turned


def _skeleton_size(m: Motion) -> float | None:
    if m.skeleton is None:
        return None
    size = m.skeleton.total_length()
    return size if size > 0 else None


def _common_frame(
    motions: Sequence[Motion],
    *,
    allow_reverse: bool,
    align_heading: bool,
    scale_root: bool,
    up: str,
) -> _Prepared:
    """Bring cycles into the reference's (``motions[0]``) frame as aligned curves."""
    u = _check_up(up)
    notes: list[str] = []
    # every cycle carries the next loop's first frame through the conversions below, so
    # its per-loop root change stays exact in whatever frame it ends up in
    extended = [_with_next_frame(m) for m in motions]
    converted = common_channels(extended)
    if any(set(c.channels) != set(m.channels) for c, m in zip(converted, motions)):
        style = _bvh_ready(converted[0].skeleton)
        notes.append(
            "the cycles store their joints in different conventions; all were re-expressed in "
            + (f"BVH conventions ({style} Euler order)" if style else "the ASF conventions (axes, dofs)")
            + " to share channels"
        )
    motions = converted
    ref = motions[0]
    fixed: list[Motion] = []
    scales: list[float] = []
    ref_size = _skeleton_size(ref)
    for i, m in enumerate(motions):
        scale = 1.0
        size = _skeleton_size(m)
        if i and scale_root and ref_size is not None and size is not None and abs(size - ref_size) > 1e-9 * ref_size:
            scale = ref_size / size
            frames = np.array(m.frames, dtype=float)
            tcols = [c for c in _root_columns(m) if m.channels[c][1] in ("tx", "ty", "tz")]
            frames[:, tcols] *= scale
            m = m.with_frames(frames)
        scales.append(scale)
        fixed.append(m)

    headings: list[float] = [0.0] * len(fixed)
    turned = False
    if align_heading:
        try:
            hs = [mean_heading(m[:-1], up) for m in fixed]
        except ParameterError as exc:
            notes.append(f"cycles not turned to a common heading: {exc}")
            hs = []
        if hs and all(np.isfinite(h) for h in hs):
            if max(abs(_wrap(h - hs[0])) for h in hs) > 1e-9:
                turned = True
                headings = hs
                fixed = [rotate_heading(m, -h, up, near=None) if abs(h) > 0 else m for m, h in zip(fixed, hs)]
        elif hs:
            notes.append("cycles not turned to a common heading: a cycle spins round (no mean heading)")

    curves = [_curve_of_extended(m) for m in fixed]
    ref_curve = curves[0]
    pose = np.array([i for i in range(ref_curve.n_channels) if i not in set(ref_curve.root_columns)], dtype=int)
    if pose.size == 0:
        pose = np.arange(ref_curve.n_channels)
    alignments: list[Alignment] = [Alignment(0.0, False, 0.0, 0.0, 0.0)]
    out = [ref_curve]
    horiz = _horizontal_columns(ref, u)
    start_ref = ref_curve(0.0)[0]
    for c in curves[1:]:
        c = _harmonise_angles(c, ref_curve)
        al = _align_curves(ref_curve, c, pose, allow_reverse)
        c = _apply_alignment(c, al)
        if horiz.size:
            delta = np.zeros(c.n_channels)
            delta[horiz] = start_ref[horiz] - c(0.0)[0, horiz]
            c = c.offset(delta)
        alignments.append(al)
        out.append(c)
    return _Prepared(
        curves=out, alignments=alignments, headings=[float(h) for h in headings], root_scales=scales,
        notes=notes, reference=fixed[0][:-1], reference_heading=float(headings[0]), turned=turned, up=u,
        base=ref[:-1],
    )


def _with_next_frame(cycle: Motion) -> Motion:
    """The cycle with one more frame: the next loop's first (root moved by its drift)."""
    nxt = np.array(cycle.frames[:1], dtype=float)
    root = _root_columns(cycle)
    if root.size:
        nxt[0, root] = cycle.frames[0, root] + root_drift(cycle)
    meta = {k: v for k, v in cycle.metadata.items() if k != "root_displacement"}
    return replace(cycle, frames=np.vstack([cycle.frames, nxt]), metadata=meta)


def _curve_of_extended(extended: Motion) -> CycleCurve:
    """The curve of a cycle carrying its next loop's first frame (see :func:`_with_next_frame`)."""
    root = _root_columns(extended)
    rot = _angle_columns([extended.channels[c] for c in root])
    x = _continuous_root(extended.frames[:, root], rot)
    return CycleCurve.from_motion(extended[:-1], displacement=x[-1] - x[0])


def _turn_back(frames: np.ndarray, prep: _Prepared, original: Motion) -> np.ndarray:
    """Frames from the common heading back to the reference's, root Euler near the original's."""
    if not prep.turned or prep.reference_heading == 0.0:
        return frames
    m = prep.reference.with_frames(frames)
    _, _, rcols = _root_rotation(original)
    back = rotate_heading(m, prep.reference_heading, "xyz"[prep.up], near=original.frames[0, rcols])
    return np.array(back.frames)


# --------------------------------------------------------------------------- blend
def blend(
    cycles: Sequence[Motion],
    weights: Sequence[float],
    *,
    allow_reverse: bool = False,
    align_heading: bool = True,
    scale_root: bool = True,
    up: str = "y",
    n_frames: int | None = None,
) -> Motion:
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

    Returns
    -------
    Motion
        One loop, ``metadata`` holding ``cycle: True``, ``period_frames``,
        ``root_displacement`` (exact per-loop root change) and ``blend`` (weights,
        sources, alignments, headings, scales, notes).

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
    motions = [_cycle_of(m, f"cycle {i}") for i, m in enumerate(cycles)]
    w = _check_weights(weights, len(motions))
    if n_frames is not None and (isinstance(n_frames, bool) or not isinstance(n_frames, Integral) or n_frames < 4):
        raise ParameterError(f"n_frames must be an integer >= 4, got {n_frames!r}")
    prep = _common_frame(
        motions, allow_reverse=allow_reverse, align_heading=align_heading, scale_root=scale_root, up=up,
    )
    ref = prep.base
    seconds = float(sum(wi * c.period_seconds for wi, c in zip(w, prep.curves)))
    n_out = int(n_frames) if n_frames is not None else max(4, int(round(seconds * ref.fps)))
    K = max(c.coefficients.shape[0] for c in prep.curves) - 1
    coef = sum(wi * c.padded(K) for wi, c in zip(w, prep.curves))
    drift = sum(wi * c.drift for wi, c in zip(w, prep.curves))
    mixed = replace(prep.curves[0], coefficients=coef, drift=drift, n_frames=n_out, fps=ref.fps)
    # one frame more than the loop: the next loop's first frame gives the exact displacement
    loop = mixed.sample(n_out)
    values = np.vstack([loop, loop[:1] + drift])
    values = _turn_back(values, prep, ref)
    root = _root_columns(ref)
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
    return replace(
        ref, frames=frames, start_frame=0, source=f"blend of {label}", metadata=meta,
    )


# ---------------------------------------------------------------------- transition
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


def _curve_steps(curve: CycleCurve, phases: np.ndarray, dphase: float, root: np.ndarray) -> np.ndarray:
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
    grid = np.arange(4 * int(np.ceil(max(period_a, period_b)))) / (4 * int(np.ceil(max(period_a, period_b))))
    med_a = float(np.median(_curve_steps(a, grid, 1.0 / period_a, root)))
    med_b = float(np.median(_curve_steps(b, grid, 1.0 / period_b, root)))
    local = np.maximum(_curve_steps(a, ph, 1.0 / period_a, root), _curve_steps(b, ph, 1.0 / period_b, root))
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
        "max_ratio_to_median": float(steps.max() / max(med_a, med_b)) if steps.size and max(med_a, med_b) > 0 else 0.0,
        "limit": STEP_LIMIT,
    }


def _transition_frames(
    prep: "_Prepared", p_a: float, p_b: float, n_ramp: int, n_in: int, n_out: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Values ``(T, D)`` (common frame), phase and weight per frame of a transition clip."""
    ca, cb = prep.curves
    inc = np.concatenate([
        np.full(n_in, 1.0 / p_a),
        _phase_increments(p_a, p_b, n_ramp),
        np.full(n_out, 1.0 / p_b),
    ])
    phases = np.concatenate([[0.0], np.cumsum(inc)])  # the clip starts at a's frame 0
    weight = np.concatenate([
        np.zeros(n_in),
        _smoothstep(np.arange(n_ramp) / (n_ramp - 1)),
        np.ones(n_out),
    ])
    va = ca(phases)
    vb = cb(phases)
    w = weight[:, None]
    values = (1.0 - w) * va + w * vb
    horiz = _horizontal_columns(prep.reference, prep.up)
    if horiz.size:
        # the ground position integrates the blended steps instead of blending positions
        w_mid = 0.5 * (weight[1:] + weight[:-1])[:, None]
        step = (1.0 - w_mid) * np.diff(va[:, horiz], axis=0) + w_mid * np.diff(vb[:, horiz], axis=0)
        values[0, horiz] = va[0, horiz]
        values[1:, horiz] = va[0, horiz] + np.cumsum(step, axis=0)
    return values, phases, weight


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
) -> Motion:
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

    Returns
    -------
    Motion
        At ``a``'s rate and skeleton; ``metadata["transition"]`` holds the ramp's frame
        range, the per-frame weight and phase, the alignment and the continuity figures.

    Raises
    ------
    ParameterError
        For bad lengths, cycles with different channels or too few frames.
    """
    a = _cycle_of(a, "cycle a")
    b = _cycle_of(b, "cycle b")
    if (frames is None) == (cycles is None):
        raise ParameterError("give exactly one of frames= and cycles= for the transition's length")
    for name, v in (("lead_in", lead_in), ("lead_out", lead_out)):
        if isinstance(v, bool) or not isinstance(v, Integral) or v < 0:
            raise ParameterError(f"{name} must be a whole number of cycles >= 0, got {v!r}")
    prep = _common_frame(
        [a, b], allow_reverse=allow_reverse, align_heading=align_heading, scale_root=scale_root, up=up,
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
        if isinstance(cycles, bool) or not isinstance(cycles, Real) or not np.isfinite(cycles) or cycles <= 0:
            raise ParameterError(f"cycles must be a positive number, got {cycles!r}")
        n_ramp = max(2, _ramp_frames_for_cycles(p_a, p_b, float(cycles)))
    n_in = int(lead_in) * a.n_frames
    n_out = int(round(int(lead_out) * p_b))
    values, phases, weight = _transition_frames(prep, p_a, p_b, n_ramp, n_in, n_out)
    continuity = transition_steps(values, phases, ca, cb, p_a, p_b)
    notes = list(prep.notes)
    if continuity["max_ratio"] > STEP_LIMIT:
        longer = None
        for factor in 1.25 ** np.arange(1, 17):
            n_try = int(np.ceil(n_ramp * factor))
            v, ph, _ = _transition_frames(prep, p_a, p_b, n_try, n_in, n_out)
            if transition_steps(v, ph, ca, cb, p_a, p_b)["max_ratio"] <= STEP_LIMIT:
                longer = n_try
                break
        continuity["suggested_ramp_frames"] = longer
        notes.append(
            f"a step is {continuity['max_ratio']:.2f}x the typical step at its phase (limit {STEP_LIMIT}): "
            + (f"a ramp of {longer} frames or more keeps every step within the limit" if longer
               else "even a ramp 35x longer does not keep every step within the limit")
        )
    values = _turn_back(values, prep, a)
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
    return replace(
        a, frames=values, start_frame=0,
        source=f"transition {a.source or 'a'} -> {b.source or 'b'}", metadata=meta,
    )
