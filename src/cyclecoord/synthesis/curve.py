"""Cycles as closed curves of their phase: trigonometric interpolation and resampling.

A cycle is a :class:`~cyclecoord.motion.Motion` holding one loop: ``P`` frames, frame
``P - 1`` followed by frame 0 of the next loop, the root travelling a fixed displacement
per loop (what :func:`cyclecoord.extract` writes).  Everything in :mod:`cyclecoord.synthesis`
treats a cycle as a closed curve of its phase ``θ`` (in cycles):

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

Between frames the trigonometric interpolant is the band-limited curve through the
frames.  On a noisy cycle it keeps the noise's size, so a cycle resampled half a frame
off its own grid can show a somewhat larger jerk (about 1.4x on the CMU cycles), where
linear interpolation would smooth the noise away instead; in exchange nothing is lost
and alignment and resampling are exact.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ..conventions import wrap_degrees

__all__ = [
    "CycleCurve",
    "root_drift",
    "prepare_cycle",
]


_ANGLE_DOFS = ("rx", "ry", "rz")


AXES = "xyz"


def check_motion(m: object, name: str) -> Motion:
    if not isinstance(m, Motion):
        raise ParameterError(f"{name} must be a Motion, got {type(m).__name__}")
    if m.n_frames < 4:
        raise ParameterError(f"{name} has {m.n_frames} frames; a cycle needs at least 4")
    if not np.all(np.isfinite(m.frames)):
        raise ParameterError(f"{name} holds NaN or infinite values")
    return m


def angle_columns(channels: Sequence[tuple[str, str]]) -> np.ndarray:
    return np.array([d in _ANGLE_DOFS for _, d in channels], dtype=bool)


def root_columns(m: Motion) -> np.ndarray:
    return np.asarray(m.root_channels(), dtype=int)


def horizontal_columns(m: Motion, up_index: int) -> np.ndarray:
    """Root translation columns across the ground (every root t* but the up axis)."""
    up = "t" + AXES[up_index]
    return np.array(
        [
            c
            for c in root_columns(m)
            if m.channels[c][1] in ("tx", "ty", "tz") and m.channels[c][1] != up
        ],
        dtype=int,
    )


def pose_columns(m: Motion) -> np.ndarray:
    """Columns compared by :func:`align`: every channel but the root's (all if none)."""
    root = set(root_columns(m).tolist())
    cols = np.array([i for i in range(m.n_channels) if i not in root], dtype=int)
    return cols if cols.size else np.arange(m.n_channels)


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
        motion = check_motion(motion, "the cycle")
        x = np.array(motion.frames, dtype=float)
        n, d = x.shape
        root = root_columns(motion)
        angles = angle_columns(motion.channels)
        drift = np.zeros(d)
        is_root = np.zeros(d, dtype=bool)
        is_root[root] = True
        for c in np.flatnonzero(angles & ~is_root):
            x[:, c] = np.unwrap(x[:, c], period=360.0)
            seam = wrap_degrees(x[0, c] - x[-1, c])
            drift[c] = np.round((x[-1, c] + seam - x[0, c]) / 360.0) * 360.0
        if root.size:
            x[:, root] = continuous_root(motion.frames[:, root], angles[root])
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


def continuous_root(values: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Root channels with rotation steps wrapped into ±180 (continuous angles)."""
    x = np.array(values, dtype=float)
    if rotation.any():
        steps = wrap_degrees(np.diff(x[:, rotation], axis=0))
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
    root = root_columns(motion)
    if displacement is None:
        displacement = (
            motion.metadata.get("root_displacement") if isinstance(motion.metadata, dict) else None
        )
    if displacement is not None:
        disp = np.asarray(displacement, dtype=float).reshape(-1)
        if disp.shape[0] != root.size or not np.all(np.isfinite(disp)):
            raise ParameterError(
                f"root displacement needs {root.size} finite values (one per root channel), "
                f"got {disp.shape[0]}"
            )
        return disp
    if root.size == 0:
        return np.zeros(0)
    if motion.n_frames < 3:
        raise ParameterError("estimating a cycle's root travel needs at least 3 frames")
    rot = angle_columns([motion.channels[c] for c in root])
    x = continuous_root(motion.frames[:, root], rot)
    steps = np.diff(x, axis=0)  # (P-1, R)
    closed = x[0] - x[-1]
    closed[rot] = wrap_degrees(closed[rot])
    estimate = _seam_estimate(steps)
    med_step = np.median(np.abs(steps), axis=0)
    med_change = (
        np.median(np.abs(np.diff(steps, axis=0)), axis=0)
        if steps.shape[0] > 1
        else np.zeros(root.size)
    )
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
    motion = check_motion(motion, "the cycle")
    out = np.array(motion.frames, dtype=float)
    root = root_columns(motion)
    if root.size:
        rot = angle_columns([motion.channels[c] for c in root])
        x = continuous_root(motion.frames[:, root], rot)
        drift = root_drift(motion, displacement)
        nxt = np.vstack([x[1:], x[:1] + drift])
        out[:, root] = nxt - x
    return out
