"""Phase alignment of cycles (paper §4.5) and turning a motion about the vertical.

:func:`align` finds the phase shift (and optionally the reversal) that best matches two
cycles' joint angles, exactly for all shifts at once by an FFT circular
cross-correlation, then refined to a fraction of a frame by Newton's method on the
(trigonometric) cost.  :func:`mean_heading` and :func:`rotate_heading` measure and turn
the direction a motion's root faces.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from numbers import Real
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import ParameterError
from ..motion import Motion
from ..conventions import check_same_channels, common_channels
from .curve import AXES, CycleCurve, angle_columns, check_motion
from ..conventions import continuous_euler

__all__ = [
    "Alignment",
    "align",
    "mean_heading",
    "rotate_heading",
]


def check_up(up: str) -> int:
    if not isinstance(up, str) or up.lower() not in ("x", "y", "z"):
        raise ParameterError(f"up must be 'x', 'y' or 'z', got {up!r}")
    return AXES.index(up.lower())


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
        np.sum(fa[0].real ** 2)
        + np.sum(fb[0].real ** 2)
        - 2.0 * np.sum(fa[0].real * fb[0].real)
        + 0.5 * np.sum(np.abs(fa[1:]) ** 2)
        + 0.5 * np.sum(np.abs(fb[1:]) ** 2)
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
            float(np.sum((-((2 * np.pi * k) ** 2) * e).real)),
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


def harmonise_angles(curve: CycleCurve, reference: CycleCurve) -> CycleCurve:
    """Move each angle channel by whole turns so its mean is within 180 of the reference's."""
    angles = angle_columns(curve.channels)
    if not angles.any():
        return curve
    diff = reference.coefficients[0].real - curve.coefficients[0].real
    turns = np.where(angles, np.round(diff / 360.0), 0.0)
    if not np.any(turns):
        return curve
    return curve.offset(360.0 * turns)


def align_curves(
    a: CycleCurve, b: CycleCurve, columns: np.ndarray, allow_reverse: bool
) -> Alignment:
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


def apply_alignment(curve: CycleCurve, al: Alignment) -> CycleCurve:
    """``b(shift + θ)``, or ``b(shift - θ)`` when reversed."""
    if al.reversed:
        return curve.reversed().shifted(-al.shift)
    return curve.shifted(al.shift)


def _as_curve(x: Motion | CycleCurve, name: str) -> CycleCurve:
    if isinstance(x, CycleCurve):
        return x
    if isinstance(x, Motion):
        return CycleCurve.from_motion(check_motion(x, name))
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
    >>> from cyclecoord.synthesis.align import align
    >>> cap = cc.datasets.make_periodic_capture(n_frames=100, period=100, noise=0,
    ...                                           speed_variation=0, random_state=0)
    >>> cycle = cap.motion
    >>> al = align(cycle, cycle.with_frames(np.roll(cycle.frames, -25, axis=0)))
    >>> round(al.shift, 6), round(al.shift_frames, 6), al.reversed
    (0.75, -25.0, False)
    """
    if isinstance(a, Motion) and isinstance(b, Motion):
        a, b = common_channels([check_motion(a, "a"), check_motion(b, "b")])
    ca = _as_curve(a, "a")
    cb = _as_curve(b, "b")
    cb = _reorder_curve(cb, ca.channels)
    cb = harmonise_angles(cb, ca)
    root = set(ca.root_columns)
    cols = np.array([i for i in range(ca.n_channels) if i not in root], dtype=int)
    if cols.size == 0:
        cols = np.arange(ca.n_channels)
    return align_curves(ca, cb, cols, bool(allow_reverse))


def _reorder_curve(curve: CycleCurve, channels: tuple) -> CycleCurve:
    if curve.channels == tuple(channels):
        return curve
    check_same_channels(curve.channels, channels, "b")
    idx = [curve.channels.index(c) for c in channels]
    root = tuple(idx.index(c) for c in curve.root_columns)
    return replace(
        curve,
        coefficients=curve.coefficients[:, idx],
        drift=curve.drift[idx],
        channels=tuple(channels),
        root_columns=tuple(sorted(root)),
    )


def root_rotation(motion: Motion) -> tuple[np.ndarray, str, np.ndarray]:
    """World rotation of the root per frame ``(T, 3, 3)``, its Euler order and columns."""
    skel = motion.skeleton
    if skel is None:
        raise ParameterError("turning a motion needs its skeleton; this motion has none")
    root = skel.joints[0]
    order = root.rotation_order
    if len(order) != 3:
        raise ParameterError(
            "turning a motion needs a root with three rotation channels; "
            f"{root.name!r} has {order or 'none'}"
        )
    try:
        cols = np.array(
            [motion.channel_index(root.name, "r" + ax.lower()) for ax in order], dtype=int
        )
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
    u = check_up(up)
    mats, _, _ = root_rotation(motion)
    fwd_axis = np.zeros(3)
    fwd_axis[(u + 1) % 3] = 1.0
    fwd = mats @ fwd_axis  # the rest pose faces +fwd_axis; the root's world rotation turns it
    f = fwd[:, (u + 1) % 3].mean()
    s = fwd[:, (u + 2) % 3].mean()
    if np.hypot(f, s) < 0.1:
        return float("nan")
    return float(np.degrees(np.arctan2(s, f)))


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
    u = check_up(up)
    if not isinstance(angle, Real) or not np.isfinite(angle):
        raise ParameterError(f"angle must be a finite number of degrees, got {angle!r}")
    if angle == 0.0:
        return motion
    mats, order, rcols = root_rotation(motion)
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
    frames[:, rcols] = continuous_euler(new_world[:, None], order, near)[:, 0]
    ground = [(u + 1) % 3, (u + 2) % 3]
    tcols = []
    for ax in ground:
        try:
            tcols.append(motion.channel_index(root.name, "t" + AXES[ax]))
        except KeyError:
            raise ParameterError(
                f"turning a motion needs the root's t{AXES[ax]} channel; it has none"
            ) from None
    pos = np.zeros((motion.n_frames, 3))
    pos[:, ground[0]] = frames[:, tcols[0]]
    pos[:, ground[1]] = frames[:, tcols[1]]
    centre = pos[0].copy()
    pos = (pos - centre) @ turn.T + centre
    frames[:, tcols[0]] = pos[:, ground[0]]
    frames[:, tcols[1]] = pos[:, ground[1]]
    return motion.with_frames(frames)
