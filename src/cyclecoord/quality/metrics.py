"""Quality measures: jerk, loop closure, distance to a cycle and phase agreement.

* :func:`jerk` / :func:`jerk_summary` -- third time derivative by 4th-order-accurate
  forward finite differences, as the paper uses to judge smoothness (§6.3); the
  coefficients come from solving the Taylor (Vandermonde) system
  (:func:`finite_difference_coefficients`).
* :func:`loop_closure` -- how big the seam of a loop is compared with its ordinary steps.
* :func:`distance_to_cycle` -- distance of frames to the closed polyline of a cycle.
* :func:`circular_distance` and :func:`monotonicity` -- how well a circular coordinate
  follows a known phase, up to rotation and reflection of the circle.

One definition of a cycle's quality is used everywhere (``extract``'s console and report,
``channels.png``, ``blend``/``transition`` and their reports), always on the cycle's frames
in the *prepared space*: every channel as it is, except the root's translation and
rotation taken as per-frame steps (:func:`cyclecoord.synthesis.curve.prepare_cycle`,
the space :func:`cyclecoord.extract` builds the cycle in).

* **loop closure** (no unit): the seam step, last frame to first, over the median step
  between consecutive frames (:func:`loop_closure`).  About 1 or less loops cleanly; above
  about 1.5 the seam shows.
* **jerk** (channel units per s³: degrees / s³ for joint angles): the mean over frames of
  the norm, across all channels, of the third time derivative by 4th-order forward
  differences, the cycle looped so its seam counts (:func:`jerk_summary`).

The figures depend on the channels a file holds: the same cycle written as AMC or NPZ reads
back the same figures, written as BVH (three Euler channels a joint) slightly different
ones (on CMU 69_01: loop closure 0.078 as AMC, 0.071 as BVH).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from numbers import Integral, Real

import numpy as np

from ..errors import ParameterError

__all__ = [
    "finite_difference_coefficients",
    "jerk",
    "jerk_summary",
    "frame_steps",
    "loop_closure",
    "largest_steps",
    "distance_to_cycle",
    "circular_distance",
    "PhaseAgreement",
    "monotonicity",
]

#: Largest stencil finite_difference_coefficients will build (beyond this the
#: formulas are numerically useless anyway).
_MAX_STENCIL = 32
#: Elements of the work arrays per block of frames (distance_to_cycle: frames x segments;
#: jerk_summary, frame_steps: frames x channels).
_CHUNK_ELEMENTS = 500_000


def _frames_array(x: object, name: str) -> np.ndarray:
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be an array of numbers: {exc}") from None
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise ParameterError(f"{name} must be a (T, D) array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"{name} holds NaN or infinite values")
    return arr


def _check_int(value: object, name: str, minimum: int) -> int:
    if isinstance(value, bool) or not isinstance(value, Integral) or value < minimum:
        raise ParameterError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _check_fps(fps: object) -> float:
    if isinstance(fps, bool) or not isinstance(fps, Real) or not np.isfinite(fps) or fps <= 0:
        raise ParameterError(f"fps must be a positive number, got {fps!r}")
    return float(fps)


# ------------------------------------------------------------------------------ jerk
def finite_difference_coefficients(derivative: int, accuracy: int) -> np.ndarray:
    """Forward finite-difference coefficients for a derivative of given accuracy order.

    The stencil is the ``n = derivative + accuracy`` points ``0, 1, ..., n - 1`` (in
    steps of ``h``).  The coefficients ``c`` solve the Taylor-expansion (Vandermonde)
    system ``sum_j c_j j**m / m! = [m == derivative]`` for ``m = 0 .. n - 1``
    (Fornberg 1988), solved exactly in rational arithmetic, so that
    ``f^(derivative)(x) ~ sum_j c_j f(x + j h) / h**derivative`` with error
    ``O(h**accuracy)``.

    Parameters
    ----------
    derivative : int
        Order of the derivative, ``>= 0``.
    accuracy : int
        Order of accuracy, ``>= 1``.

    Returns
    -------
    ndarray, shape (derivative + accuracy,)
        Coefficients for the points ``x, x + h, ..., x + (n - 1) h``.

    Raises
    ------
    ParameterError
        For negative orders or a stencil longer than 32 points.

    Examples
    --------
    >>> finite_difference_coefficients(3, 1)
    array([-1.,  3., -3.,  1.])
    """
    derivative = _check_int(derivative, "derivative", 0)
    accuracy = _check_int(accuracy, "accuracy", 1)
    n = derivative + accuracy
    if n > _MAX_STENCIL:
        raise ParameterError(f"stencil of {n} points is too long (at most {_MAX_STENCIL})")
    return np.array(_exact_coefficients(derivative, accuracy))


@lru_cache(maxsize=64)
def _exact_coefficients(derivative: int, accuracy: int) -> tuple:
    """The stencil of :func:`finite_difference_coefficients`, solved once per pair
    (exact rational arithmetic costs a few milliseconds a call)."""
    n = derivative + accuracy
    # Augmented system [A | b] with A[m][j] = j**m, b[m] = derivative! * [m == derivative]
    factorial = 1
    for i in range(2, derivative + 1):
        factorial *= i
    rows = [
        [Fraction(j**m) for j in range(n)] + [Fraction(factorial if m == derivative else 0)]
        for m in range(n)
    ]
    # Gauss-Jordan elimination in exact arithmetic (the Vandermonde matrix is regular)
    for col in range(n):
        pivot = next(r for r in range(col, n) if rows[r][col] != 0)
        rows[col], rows[pivot] = rows[pivot], rows[col]
        inv = 1 / rows[col][col]
        rows[col] = [v * inv for v in rows[col]]
        for r in range(n):
            if r != col and rows[r][col] != 0:
                factor = rows[r][col]
                rows[r] = [a - factor * b for a, b in zip(rows[r], rows[col])]
    return tuple(float(rows[m][n]) for m in range(n))


def jerk(frames: np.ndarray, fps: float, accuracy: int = 4, cyclic: bool = False) -> np.ndarray:
    """Third time derivative of every channel by forward finite differences.

    Parameters
    ----------
    frames : array_like, shape (T, D) or (T,)
        Channel values per frame (any units ``u``).
    fps : float
        Frames per second.
    accuracy : int, default 4
        Accuracy order of the forward-difference formula (paper: 4th order, a 7-point
        stencil).
    cyclic : bool, default False
        Treat the frames as a loop (frame ``T - 1`` followed by frame 0), so the seam of
        a loop is measured too.

    Returns
    -------
    ndarray, shape (T - n + 1, D), or (T, D) when ``cyclic``
        Jerk in ``u / s**3``; row ``t`` is the jerk at frame ``t``.  ``n = 3 + accuracy``
        is the stencil length.

    Raises
    ------
    ParameterError
        For bad arrays, a non-positive ``fps`` or fewer than ``n`` frames.
    """
    x = _frames_array(frames, "frames")
    fps = _check_fps(fps)
    coef = finite_difference_coefficients(3, accuracy) * fps**3
    n = coef.size
    t = x.shape[0]
    if t < n:
        raise ParameterError(
            f"jerk with accuracy {accuracy} needs at least {n} frames, got {t}"
        )
    if cyclic:
        out = np.zeros_like(x)
        for j, c in enumerate(coef):  # loop over the short stencil, not over frames
            out += c * np.roll(x, -j, axis=0)
        return out
    m = t - n + 1
    out = np.zeros((m, x.shape[1]))
    for j, c in enumerate(coef):
        out += c * x[j : j + m]
    return out


def jerk_summary(frames: np.ndarray, fps: float, cyclic: bool = False) -> float:
    """One smoothness figure: the mean over frames of the norm of the jerk vector.

    Parameters
    ----------
    frames : array_like, shape (T, D)
        Channel values per frame.
    fps : float
        Frames per second.
    cyclic : bool, default False
        Treat the frames as a loop (see :func:`jerk`).

    Returns
    -------
    float
        ``mean_t ||jerk[t]||_2`` in channel units per s**3 (degrees / s**3 for joint
        angles; mixing translation and angle channels mixes units, so compare like with
        like).  Uses the 4th-order-accurate formula.
    """
    if cyclic:
        j = jerk(frames, fps, accuracy=4, cyclic=True)
        return float(np.linalg.norm(j, axis=1).mean())
    # in blocks of frames (each row's jerk and norm are computed alone, so the result is
    # the whole-array one bit for bit) to hold O(block) rather than three (T, D) arrays
    x = _frames_array(frames, "frames")
    fps = _check_fps(fps)
    coef = finite_difference_coefficients(3, 4) * fps**3
    n = coef.size
    if x.shape[0] < n:
        jerk(x, fps, accuracy=4)  # raises the usual error
    m = x.shape[0] - n + 1
    norms = np.empty(m)
    block = max(1, _CHUNK_ELEMENTS // max(x.shape[1], 1))
    for lo in range(0, m, block):
        hi = min(m, lo + block)
        out = np.zeros((hi - lo, x.shape[1]))
        for j, c in enumerate(coef):
            out += c * x[lo + j : hi + j]
        norms[lo:hi] = np.linalg.norm(out, axis=1)
    return float(norms.mean())


def frame_steps(frames: np.ndarray) -> np.ndarray:
    """Euclidean length of each step ``frames[t + 1] - frames[t]``, shape (T - 1,),
    computed in blocks of frames (no (T, D) temporary)."""
    x = np.asarray(frames, dtype=float)
    m = max(x.shape[0] - 1, 0)
    out = np.empty(m)
    block = max(1, _CHUNK_ELEMENTS // max(x.shape[1], 1))
    for lo in range(0, m, block):
        hi = min(m, lo + block)
        out[lo:hi] = np.linalg.norm(x[lo + 1 : hi + 1] - x[lo:hi], axis=1)
    return out


# ---------------------------------------------------------------------- loop quality
def loop_closure(cycle: np.ndarray) -> float:
    """Size of a loop's seam relative to its ordinary steps.

    Parameters
    ----------
    cycle : array_like, shape (P, D)
        One cycle of frames, ``P >= 2``, meant to loop (frame ``P - 1`` then frame 0).

    Returns
    -------
    float
        ``|cycle[0] - cycle[-1]|`` divided by the median of ``|cycle[i+1] - cycle[i]|``.
        A clean loop gives about 1; above about 1.5 the seam shows as a hitch.  A
        constant cycle gives 1.0; a still cycle with a jump at the seam gives ``inf``.
    """
    x = _frames_array(cycle, "cycle")
    if x.shape[0] < 2:
        raise ParameterError(f"a cycle needs at least 2 frames, got {x.shape[0]}")
    steps = np.linalg.norm(np.diff(x, axis=0), axis=1)
    seam = float(np.linalg.norm(x[0] - x[-1]))
    typical = float(np.median(steps))
    if typical == 0.0:
        return 1.0 if seam == 0.0 else float("inf")
    return seam / typical


def largest_steps(
    cycle: np.ndarray, frames: np.ndarray, mask: np.ndarray | None = None
) -> tuple[float, float]:
    """A cycle's largest frame step and the 99th-percentile step of the frames it loops.

    Parameters
    ----------
    cycle : array_like, shape (P, D)
        One cycle; its steps are taken around the loop (the seam included).
    frames : array_like, shape (T, D)
        The capture, same channels.
    mask : array_like of bool, shape (T,), optional
        Frames taking part: only steps between two consecutive masked frames count.

    Returns
    -------
    (float, float)
        ``(largest cycle step, capture's 99th-percentile step)``, in the channels' units;
        NaN where there is no step.  Their ratio over about 2 is a pop: a jump the
        capture hardly ever makes.
    """
    x = np.asarray(cycle, dtype=float)
    cyc = np.linalg.norm(np.roll(x, -1, axis=0) - x, axis=1)
    step = frame_steps(frames)
    if mask is not None:
        m = np.asarray(mask, dtype=bool)
        step = step[m[1:] & m[:-1]]
    return (
        float(cyc.max()) if cyc.size else float("nan"),
        float(np.percentile(step, 99)) if step.size else float("nan"),
    )


def distance_to_cycle(frames: np.ndarray, cycle: np.ndarray) -> np.ndarray:
    """Euclidean distance of every frame to the closed polyline through a cycle.

    The polyline has the segments ``cycle[i] -> cycle[i + 1]`` and the closing segment
    ``cycle[P - 1] -> cycle[0]``.  Distances to all segments come from matrix products
    (no ``T x P x D`` array; frames are processed in chunks), and the distance to the
    nearest segment is then recomputed directly, free of cancellation.

    Parameters
    ----------
    frames : array_like, shape (T, D)
        Points to measure.
    cycle : array_like, shape (P, D)
        Cycle frames, same ``D``; ``P = 1`` is a single point.

    Returns
    -------
    ndarray, shape (T,)
        Distances, in the units of the frames.
    """
    x = _frames_array(frames, "frames")
    c = _frames_array(cycle, "cycle")
    if c.shape[0] == 0:
        raise ParameterError("cycle is empty")
    if x.shape[1] != c.shape[1]:
        raise ParameterError(f"frames have {x.shape[1]} channels but the cycle has {c.shape[1]}")
    centre = c.mean(axis=0)  # work near the origin to keep the expansion accurate
    a = c - centre
    v = np.roll(a, -1, axis=0) - a  # segment vectors
    vv = np.einsum("pd,pd->p", v, v)
    aa = np.einsum("pd,pd->p", a, a)
    av = np.einsum("pd,pd->p", a, v)
    inv_vv = np.where(vv > 0, 1.0 / np.where(vv > 0, vv, 1.0), 0.0)
    n_seg = a.shape[0]
    chunk = max(1, _CHUNK_ELEMENTS // max(n_seg, 1))
    out = np.empty(x.shape[0])
    for lo in range(0, x.shape[0], chunk):
        xs = x[lo : lo + chunk] - centre
        xa = xs @ a.T  # (t, P)
        xv = xs @ v.T
        xx = np.einsum("td,td->t", xs, xs)
        proj = np.clip((xv - av) * inv_vv, 0.0, 1.0)  # position along each segment
        # |x - a - s v|^2 = |x|^2 - 2 x.a + |a|^2 - 2 s (x.v - a.v) + s^2 |v|^2
        sq = xx[:, None] - 2.0 * xa + aa - 2.0 * proj * (xv - av) + proj * proj * vv
        best = np.argmin(sq, axis=1)
        rows = np.arange(xs.shape[0])
        nearest = a[best] + proj[rows, best][:, None] * v[best]
        out[lo : lo + chunk] = np.linalg.norm(xs - nearest, axis=1)
    return out


# ------------------------------------------------------------------ phase agreement
def circular_distance(a: np.ndarray | float, b: np.ndarray | float) -> np.ndarray:
    """Distance on the circle of circumference 1: ``min(|a - b| mod 1, 1 - ...)``.

    Parameters
    ----------
    a, b : array_like
        Phases (broadcast together).

    Returns
    -------
    ndarray
        Distances in ``[0, 0.5]``.
    """
    d = np.mod(np.asarray(a, dtype=float) - np.asarray(b, dtype=float), 1.0)
    return np.minimum(d, 1.0 - d)


def _wrap_half(x: np.ndarray) -> np.ndarray:
    """Wrap into (-0.5, 0.5]."""
    return 0.5 - np.mod(0.5 - x, 1.0)


@dataclass(frozen=True)
class PhaseAgreement:
    """How well a circular coordinate follows a known phase.

    Attributes
    ----------
    fraction_monotone : float
        Fraction of consecutive frame pairs whose coordinate step (wrapped into
        ``(-0.5, 0.5]``) has the sign ``orientation`` times the sign of the true step
        (pairs with a zero true step are left out).  1.0 means the coordinate advances
        with the phase at every frame; about 0.5 means no relation.
    max_abs_error_after_alignment : float
        Largest circular distance between ``orientation * theta + offset`` and the true
        phase, with ``offset`` chosen to make this as small as possible (phase units,
        in ``[0, 0.5]``).  Small for a coordinate that equals the phase up to rotation or
        reflection of the circle; a monotone but uneven coordinate (a time warp) shows
        its largest warp here.
    mean_abs_error_after_alignment : float
        Mean circular distance under the same alignment.
    orientation : int
        ``+1`` if the coordinate runs with the phase, ``-1`` if against it (reflection).
    offset : float
        The best rotation ``c`` in ``[0, 1)``.
    """

    fraction_monotone: float
    max_abs_error_after_alignment: float
    mean_abs_error_after_alignment: float
    orientation: int
    offset: float


def _minimax_offset(residual: np.ndarray) -> tuple[float, float]:
    """Centre of the shortest arc holding every residual, and its half length."""
    r = np.sort(np.mod(residual, 1.0))
    gaps = np.diff(np.concatenate([r, [r[0] + 1.0]]))
    i = int(np.argmax(gaps))
    # the arc runs from r[i + 1] (after the largest gap) round to r[i]
    start = r[(i + 1) % r.size]
    length = 1.0 - float(gaps[i])
    return float(np.mod(start + 0.5 * length, 1.0)), 0.5 * length


def monotonicity(theta: np.ndarray, true_phase: np.ndarray) -> PhaseAgreement:
    """Agreement of a circular coordinate with a known phase, up to rotation/reflection.

    The alignment looks for the orientation ``s`` (+1 or -1) and offset ``c`` that
    minimise the largest circular error ``max_i d(s * theta_i + c, phase_i)``: for each
    ``s`` the residuals ``phase - s * theta`` are placed on the circle and ``c`` is the
    centre of the shortest arc containing them all (exact, ``O(T log T)``); the
    orientation with the smaller error wins.  The fraction of monotone steps is counted
    in that orientation.

    Parameters
    ----------
    theta : array_like, shape (T,)
        Circular coordinate per frame (phase units; modulo 1).
    true_phase : array_like, shape (T,)
        Known phase per frame (phase units; may be unwrapped, it is used modulo 1).
        Consecutive frames should advance by less than half a turn.

    Returns
    -------
    PhaseAgreement

    Raises
    ------
    ParameterError
        For mismatched or too short (< 2) arrays, or non-finite values.
    """
    th = np.asarray(theta, dtype=float)
    ph = np.asarray(true_phase, dtype=float)
    if th.ndim != 1 or ph.ndim != 1 or th.shape != ph.shape:
        raise ParameterError(
            "theta and true_phase must be 1-D arrays of "
            f"equal length, got {th.shape} and {ph.shape}"
        )
    if th.size < 2:
        raise ParameterError("monotonicity needs at least 2 frames")
    if not (np.all(np.isfinite(th)) and np.all(np.isfinite(ph))):
        raise ParameterError("theta or true_phase holds NaN or infinite values")

    best = None
    for s in (1, -1):
        offset, err = _minimax_offset(ph - s * th)
        if best is None or err < best[2] - 1e-12:
            best = (s, offset, err)
    s, offset, max_err = best
    mean_err = float(circular_distance(s * th + offset, ph).mean())

    d_theta = _wrap_half(np.diff(th))
    d_phase = _wrap_half(np.diff(ph))
    moving = d_phase != 0
    if np.any(moving):
        agree = np.sign(d_theta[moving]) == s * np.sign(d_phase[moving])
        fraction = float(agree.mean())
    else:
        fraction = float("nan")
    return PhaseAgreement(
        fraction_monotone=fraction,
        max_abs_error_after_alignment=float(max_err),
        mean_abs_error_after_alignment=mean_err,
        orientation=int(s),
        offset=float(offset),
    )
