"""The typical cycle: one loopable period averaged from all repetitions (paper §4.4).

Given each frame's circular coordinate ``theta`` (phase in ``[0, 1)``) and its pose, the
typical cycle is built in three steps:

1. phases are drawn from the periodic density of ``theta``
   (:class:`~cyclecoord.periodic.density.PeriodicDensity`); the density is proportional to the time
   the motion spends at each phase, so the drawn phases are (about) equally spaced in
   *time*;
2. each phase gets an average pose: by default a periodic Gaussian kernel average over
   all frames whose width holds about ``k`` frames (:func:`kernel_centroids`), which is
   smooth in the phase; or, as in the paper, the centroid of the ``k`` frames nearest in
   circular distance (:func:`knn_centroids`), whose neighbour set changes abruptly and
   so adds jerk where repetitions differ;
3. the centroid curve is resampled, as a closed curve, to the capture's frame rate
   (:func:`resample_cyclic`).

Root channels stay as per-frame differences throughout (the prepared space);
:func:`integrate_root` turns them back into absolute values.
"""

from __future__ import annotations

from dataclasses import dataclass
from numbers import Integral, Real

import numpy as np

from ._kernel import KERNEL_REACH, kernel_dense, kernel_windowed
from .density import PeriodicDensity, as_generator
from ..errors import ParameterError

__all__ = [
    "TypicalCycle",
    "knn_centroids",
    "kernel_centroids",
    "BandwidthSelection",
    "select_bandwidth",
    "resample_cyclic",
    "integrate_root",
    "typical_cycle",
]

_WEIGHTINGS = ("kernel", "mean", "gaussian")
_SAMPLINGS = ("quantile", "random")


# --------------------------------------------------------------------------- helpers
def _finite_array(x: object, name: str, ndim: int | tuple[int, ...]) -> np.ndarray:
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParameterError(f"{name} must be an array of numbers: {exc}") from None
    allowed = (ndim,) if isinstance(ndim, int) else ndim
    if arr.ndim not in allowed:
        raise ParameterError(
            f"{name} must have {' or '.join(map(str, allowed))} dimension(s), got shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"{name} holds NaN or infinite values")
    return arr


def _positive_int(value: object, name: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, Integral) or value < minimum:
        raise ParameterError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _positive_float(value: object, name: str) -> float:
    if (
        isinstance(value, bool)
        or not isinstance(value, Real)
        or not np.isfinite(value)
        or value <= 0
    ):
        raise ParameterError(f"{name} must be a positive finite number, got {value!r}")
    return float(value)


def _wrap01(x: np.ndarray) -> np.ndarray:
    """``x mod 1`` guaranteed to lie in [0, 1) (``-1e-17 % 1`` is 1.0 in floating point)."""
    out = np.mod(x, 1.0)
    out[out >= 1.0] = 0.0
    return out


# ------------------------------------------------------------------------ centroids
def knn_centroids(
    theta: np.ndarray,
    poses: np.ndarray,
    phases: np.ndarray,
    k: int = 10,
    weighting: str = "mean",
    bandwidth: float | None = None,
) -> np.ndarray:
    """Centroid of the ``k`` frames nearest in circular coordinate to each phase.

    Distances are circular: ``min(|a - b|, 1 - |a - b|)``, so phases near 0 find
    neighbours just below 1 and vice versa.  The ``k`` nearest frames of a phase are
    always a run of consecutive frames in ``theta``-sorted order (cyclically), so after
    one sort the best run is chosen among the ``k + 1`` runs that contain the phase's
    insertion point -- all phases at once, no loop.

    Parameters
    ----------
    theta : array_like, shape (T,)
        Circular coordinate of every frame (phase units, taken modulo 1).
    poses : array_like, shape (T, D) or (T,)
        The frames (any units); a 1-D array is one channel.
    phases : array_like, shape (N,)
        Phases at which to compute centroids (taken modulo 1).
    k : int, default 10
        Number of neighbours, ``1 <= k <= T`` (paper: 10).
    weighting : {"mean", "gaussian"}
        ``"mean"``: coordinate-wise arithmetic mean (paper).  ``"gaussian"``: mean
        weighted by ``exp(-d**2 / (2 * bandwidth**2))`` of the circular distance ``d``.
    bandwidth : float, optional
        Gaussian bandwidth in phase units; default the median, over the phases, of the
        distance to the ``k``-th neighbour.  Ignored for ``"mean"``.

    Returns
    -------
    ndarray, shape (N, D)
        One centroid pose per phase, in the units of ``poses``.

    Raises
    ------
    ParameterError
        For mismatched shapes, non-finite values, ``k`` outside ``1..T``, an unknown
        weighting or a non-positive bandwidth.
    """
    theta = _finite_array(theta, "theta", 1)
    poses = _finite_array(poses, "poses", (1, 2))
    if poses.ndim == 1:
        poses = poses[:, None]
    phases = _finite_array(phases, "phases", 1)
    n_frames = theta.shape[0]
    if poses.shape[0] != n_frames:
        raise ParameterError(f"theta has {n_frames} values but poses has {poses.shape[0]} frames")
    if isinstance(k, bool) or not isinstance(k, Integral) or k < 1:
        raise ParameterError(f"k must be a positive integer, got {k!r}")
    if k > n_frames:
        raise ParameterError(f"k={k} neighbours requested but only {n_frames} frames are available")
    if weighting not in _WEIGHTINGS:
        raise ParameterError(f"weighting must be one of {_WEIGHTINGS}, got {weighting!r}")
    if bandwidth is not None and (
        isinstance(bandwidth, bool)
        or not isinstance(bandwidth, Real)
        or not np.isfinite(bandwidth)
        or bandwidth <= 0
    ):
        raise ParameterError(f"bandwidth must be a positive number, got {bandwidth!r}")
    k = int(k)

    theta = _wrap01(theta)
    phases = _wrap01(phases)
    order = np.argsort(theta, kind="stable")
    sorted_theta = theta[order]
    # extended sorted coordinates: k values wrapped from the top below 0, k from the
    # bottom above 1; position e of `ext` is sorted frame (e - k) mod T.
    ext = np.concatenate(
        [sorted_theta[n_frames - k :] - 1.0, sorted_theta, sorted_theta[:k] + 1.0]
    )
    insert = np.searchsorted(ext, phases)  # in [k, T + k]
    # candidate runs ext[s : s + k] with s = insert - k .. insert
    starts = insert[:, None] + np.arange(-k, 1)[None, :]  # (N, k + 1)
    left = phases[:, None] - ext[starts]
    right = ext[starts + (k - 1)] - phases[:, None]
    reach = np.maximum(left, right)
    best = starts[np.arange(phases.size), np.argmin(reach, axis=1)]  # (N,)
    ext_idx = best[:, None] + np.arange(k)[None, :]  # (N, k)
    frames = order[(ext_idx - k) % n_frames]
    neighbours = poses[frames]  # (N, k, D)

    if weighting == "mean":
        return neighbours.mean(axis=1)

    # already circular: the chosen run has the least reach, at most the k-th nearest
    # frame's circular distance (<= 0.5), so no |ext - phase| in it exceeds 0.5
    dist = np.abs(ext[ext_idx] - phases[:, None])
    if bandwidth is None:
        bandwidth = float(np.median(dist.max(axis=1)))
    if bandwidth <= 0.0:  # every neighbour sits exactly on its phase
        return neighbours.mean(axis=1)
    sq = dist * dist
    weights = np.exp(-(sq - sq.min(axis=1, keepdims=True)) / (2.0 * bandwidth * bandwidth))
    weights /= weights.sum(axis=1, keepdims=True)
    return np.einsum("nk,nkd->nd", weights, neighbours)


# ------------------------------------------------------------------------ resampling
def kernel_centroids(
    theta: np.ndarray,
    poses: np.ndarray,
    phases: np.ndarray,
    k: int = 10,
    chunk_elements: int = 250_000,
    bandwidth: float | None = None,
) -> np.ndarray:
    """Kernel-weighted average pose at each phase (Nadaraya-Watson on the circle).

    Every frame contributes with weight ``exp(-d² / (2 σ²))``, ``d`` its circular phase
    distance to the query; ``σ = k / (T √(2π))`` so that, for evenly spread coordinates,
    the weights add up to about ``k`` frames — the same amount of averaging as ``k``
    nearest neighbours, but varying smoothly with the phase (no frame enters or leaves
    the average abruptly), so the curve adds no jerk of its own.  Weights beyond 38.6
    widths are exactly 0.0 in double precision, so when 40 widths are less than half a
    period only the frames within them are visited (sorted by phase: O(T log T) rather
    than O(N T)); the result is the dense sum's up to rounding.

    Parameters
    ----------
    theta : array_like, shape (T,)
    poses : array_like, shape (T, D)
    phases : array_like, shape (N,)
    k : int, default 10
        Effective number of frames per average; sets the width when ``bandwidth`` is
        None.
    chunk_elements : int, default 250,000
        Largest number of weights held at once.
    bandwidth : float, optional
        Kernel width ``σ`` in *phase units* (a fraction of one period, ``0 < σ``);
        default ``k / (T √(2π))``.  :func:`select_bandwidth` chooses one from the data
        (it reports frames of the period; divide by the period in frames).

    Returns
    -------
    ndarray, shape (N, D)
        One average pose per phase, in the units of ``poses``.

    Raises
    ------
    ParameterError
        For mismatched shapes, non-finite values, ``k`` outside ``1..T`` or a
        non-positive bandwidth.
    """
    theta = _wrap01(_finite_array(theta, "theta", 1))
    poses = _finite_array(poses, "poses", 2)
    phases = _wrap01(_finite_array(phases, "phases", 1))
    T = theta.shape[0]
    if poses.shape[0] != T:
        raise ParameterError(f"theta has {T} values but poses has {poses.shape[0]} rows")
    k = _positive_int(k, "k")
    if k > T:
        raise ParameterError(f"k must be between 1 and the number of frames ({T}), got {k}")
    if bandwidth is None:
        sigma = k / (T * np.sqrt(2.0 * np.pi))
    else:
        sigma = _positive_float(bandwidth, "bandwidth")
    if 2.0 * KERNEL_REACH * sigma >= 1.0:  # the kernel spans the circle: every frame counts
        return kernel_dense(theta, poses, phases, sigma, chunk_elements)
    return kernel_windowed(theta, poses, phases, sigma, chunk_elements)


@dataclass(frozen=True, eq=False)
class BandwidthSelection:
    """Result of :func:`select_bandwidth`.

    Attributes
    ----------
    bandwidth : float
        Chosen kernel width ``σ``, in frames of one period (``σ`` in phase units times
        the period in frames).
    candidates : ndarray, shape (G,)
        Widths tried, in frames of one period, ascending.
    cv_error : ndarray, shape (G,)
        Mean leave-out squared prediction error per candidate, in squared pose units
        (summed over channels, averaged over validation frames).
    cv_se : ndarray, shape (G,)
        Standard error of ``cv_error`` over the validation frames.
    rule : str
        ``"min"`` or ``"1se"``.
    exclude : int
        Frames on each side (in time) left out with the predicted frame.
    n_validation : int
        Number of frames whose prediction error was averaged.
    """

    bandwidth: float
    candidates: np.ndarray
    cv_error: np.ndarray
    cv_se: np.ndarray
    rule: str
    exclude: int
    n_validation: int

    @property
    def index(self) -> int:
        """Position of the chosen width in ``candidates``."""
        return int(np.argmin(np.abs(self.candidates - self.bandwidth)))


_RULES = ("min", "1se")
# what bandwidth="auto" uses (see select_bandwidth)
_AUTO_RULE = "min"
_AUTO_EXCLUDE = 0


def select_bandwidth(
    theta: np.ndarray,
    poses: np.ndarray,
    period_frames: float,
    k: int = 10,
    candidates: np.ndarray | None = None,
    n_candidates: int = 14,
    max_width: float | None = None,
    rule: str = "min",
    exclude: int = 0,
    max_validation: int = 2000,
    chunk_elements: int = 4_000_000,
    query: np.ndarray | None = None,
) -> BandwidthSelection:
    """Kernel width for :func:`kernel_centroids` by leave-out cross-validation.

    Each validation frame ``i`` is predicted by the Nadaraya-Watson average at its own
    phase ``theta[i]`` over the *other* frames -- frame ``i`` and, with ``exclude > 0``,
    the frames within ``exclude`` frames of it in time are given weight 0 -- and the
    squared error ``||poses[i] - prediction||²`` is averaged over the validation frames.
    Leaving out time neighbours guards against noise that is correlated from frame to
    frame (it would otherwise reward widths that only copy the neighbours).

    The cost is ``O(n_val · T · (D + 1))`` per candidate, in chunks of at most
    ``chunk_elements`` weights.

    Parameters
    ----------
    theta : array_like, shape (T,)
        Circular coordinate of every frame (phase units, taken modulo 1), in frame
        (time) order.
    poses : array_like, shape (T, D)
        The frames (any units; the error is summed over channels in these units).
    period_frames : float
        Length of one period in frames (> 0); converts widths between frames of the
        period and phase units.
    k : int, default 10
        The default grid starts at :func:`kernel_centroids`' ``k``-based width,
        ``k / (T √(2π))`` in phase units, or at half a frame if that is narrower.
    candidates : array_like, optional
        Widths to try, in frames of one period (positive); overrides the grid.
    n_candidates : int, default 14
        Size of the default log-spaced grid.
    max_width : float, optional
        Widest width of the default grid, in frames of one period; default
        ``period_frames / 8``.
    rule : {"min", "1se"}
        ``"min"``: the width of least error; ``"1se"``: the widest width whose error is
        within one standard error of the least.
    exclude : int, default 0
        Frames on each side of ``i`` (in time) left out with it; 0 is plain
        leave-one-out.  Needs at least ``2 * exclude + 2`` frames, so that every frame
        keeps one other frame to be predicted from.
    max_validation : int, default 2000
        At most this many validation frames, evenly spaced in time.
    chunk_elements : int, default 4,000,000
        Largest weight matrix (validation frames x frames) built at once.
    query : array_like, shape (T,), optional
        Where frame ``i`` is predicted (phase units); default ``theta[i]``.  A position
        not computed from frame ``i`` itself (e.g. interpolated from its time
        neighbours) keeps a coordinate estimated from the noisy poses from favouring
        narrow widths.

    Returns
    -------
    BandwidthSelection

    Raises
    ------
    ParameterError
        For mismatched shapes, non-finite values, non-positive widths or period, an
        unknown rule, or too few frames left after exclusion.
    """
    theta = _wrap01(_finite_array(theta, "theta", 1))
    poses = _finite_array(poses, "poses", (1, 2))
    if poses.ndim == 1:
        poses = poses[:, None]
    T = theta.shape[0]
    if poses.shape[0] != T:
        raise ParameterError(f"theta has {T} values but poses has {poses.shape[0]} rows")
    period = _positive_float(period_frames, "period_frames")
    k = _positive_int(k, "k")
    if k > T:
        raise ParameterError(f"k must be between 1 and the number of frames ({T}), got {k}")
    if rule not in _RULES:
        raise ParameterError(f"rule must be one of {_RULES}, got {rule!r}")
    exclude = _positive_int(exclude, "exclude", 0)
    if T < 2 * exclude + 2:
        raise ParameterError(f"{T} frames are too few to leave out {2 * exclude + 1} at a time")
    max_validation = _positive_int(max_validation, "max_validation")
    if query is None:
        query = theta
    else:
        query = _wrap01(_finite_array(query, "query", 1))
        if query.shape[0] != T:
            raise ParameterError(f"query has {query.shape[0]} values for {T} frames")
    widths = _candidate_widths(candidates, n_candidates, max_width, k, T, period)
    sig2 = (widths / period) ** 2  # phase units, squared

    n_val = min(T, max_validation)
    val = np.unique(np.round(np.linspace(0, T - 1, n_val)).astype(int))
    n_val = val.size
    err = _held_out_errors(theta, query, poses, val, sig2, exclude, chunk_elements)
    mean = err.mean(axis=0)
    se = err.std(axis=0, ddof=1) / np.sqrt(n_val) if n_val > 1 else np.zeros_like(mean)
    best = int(np.argmin(mean))
    if rule == "1se":
        best = int(np.flatnonzero(mean <= mean[best] + se[best]).max())
    for arr in (widths, mean, se):
        arr.flags.writeable = False
    return BandwidthSelection(
        bandwidth=float(widths[best]), candidates=widths, cv_error=mean, cv_se=se,
        rule=rule, exclude=exclude, n_validation=int(n_val),
    )


def _candidate_widths(
    candidates, n_candidates: int, max_width, k: int, T: int, period: float
) -> np.ndarray:
    """Kernel widths (frames of one period) to try: the given ones, checked and sorted, or a
    geometric grid from about one frame's spacing times ``k`` up to an eighth of a period."""
    if candidates is None:
        n_candidates = _positive_int(n_candidates, "n_candidates")
        lo = min(k / (T * np.sqrt(2.0 * np.pi)) * period, 0.5)
        hi = period / 8.0 if max_width is None else _positive_float(max_width, "max_width")
        widths = (
            np.geomspace(lo, hi, n_candidates) if hi > lo else np.array([lo])  # n = 1: [lo] too
        )
    else:
        widths = _finite_array(candidates, "candidates", 1)
        if widths.size == 0 or np.any(widths <= 0):
            raise ParameterError("candidates must be positive widths in frames of one period")
        widths = np.unique(widths)
    return widths


def _held_out_errors(
    theta: np.ndarray,
    query: np.ndarray,
    poses: np.ndarray,
    val: np.ndarray,
    sig2: np.ndarray,
    exclude: int,
    chunk_elements: int,
) -> np.ndarray:
    """Squared error ``(len(val), len(sig2))`` of predicting each validation frame's pose from
    the others (its ``exclude`` time neighbours left out) by a Gaussian kernel in phase."""
    T = theta.shape[0]
    n_val = val.size
    err = np.empty((n_val, sig2.size))
    offsets = np.arange(-exclude, exclude + 1)
    poses32 = poses.astype(np.float32)
    step = max(1, chunk_elements // max(T, 1))
    for a in range(0, n_val, step):
        rows = val[a : a + step]
        d = np.mod(query[rows, None] - theta[None, :] + 0.5, 1.0) - 0.5
        d2 = d * d
        cols = rows[:, None] + offsets[None, :]
        ok = (cols >= 0) & (cols < T)
        r_idx = np.broadcast_to(np.arange(rows.size)[:, None], cols.shape)
        d2[r_idx[ok], cols[ok]] = np.inf
        d2 -= d2.min(axis=1, keepdims=True)  # nearest kept frame at weight 1: no underflow
        d2 = d2.astype(np.float32)  # single precision halves the cost; ample for a choice
        target = poses[rows]
        for g, s2 in enumerate(sig2):
            w = np.exp(d2 * np.float32(-0.5 / s2))
            pred = (w @ poses32) / w.sum(axis=1, keepdims=True, dtype=float)
            err[a : a + step, g] = np.sum((target - pred) ** 2, axis=1)
    return err


def resample_cyclic(curve: np.ndarray, n_out: int, times: np.ndarray | None = None) -> np.ndarray:
    """Resample a closed curve at ``n_out`` equally spaced times by linear interpolation.

    Parameters
    ----------
    curve : array_like, shape (N, D) or (N,)
        Samples of a closed curve; after the last sample (in time) the curve runs on to
        the first.
    n_out : int
        Number of output frames, at least 2.
    times : array_like, shape (N,), optional
        Time of each sample as a fraction of the period, in ``[0, 1)`` (taken modulo 1;
        need not be sorted).  Default ``i / N``.

    Returns
    -------
    ndarray, shape (n_out, D)
        The curve at times ``j / n_out``, ``j = 0 .. n_out - 1``; a 1-D ``curve`` gives
        shape (n_out, 1).

    Raises
    ------
    ParameterError
        For an empty curve, mismatched ``times``, non-finite values or ``n_out < 2``.
    """
    curve = _finite_array(curve, "curve", (1, 2))
    if curve.ndim == 1:
        curve = curve[:, None]
    n_in = curve.shape[0]
    if n_in == 0:
        raise ParameterError("curve is empty")
    n_out = _positive_int(n_out, "n_out", 2)
    if times is None:
        t = np.arange(n_in) / n_in
        c = curve
    else:
        t = _finite_array(times, "times", 1)
        if t.shape[0] != n_in:
            raise ParameterError(f"times has {t.shape[0]} values for {n_in} curve samples")
        t = _wrap01(t)
        order = np.argsort(t, kind="stable")
        t, c = t[order], curve[order]
    # closed curve: one wrapped sample before the start and one after the end
    ext_t = np.concatenate([[t[-1] - 1.0], t, [t[0] + 1.0]])
    ext_c = np.concatenate([c[-1:], c, c[:1]], axis=0)
    query = np.arange(n_out) / n_out
    # t is in [0, 1), so ext_t[0] = t[-1] - 1 < 0 <= query < 1 <= t[0] + 1 = ext_t[-1]: lo is
    # in [0, ext_t.size - 2] with ext_t[lo] <= q < ext_t[lo + 1], so w is in [0, 1)
    lo = np.searchsorted(ext_t, query, side="right") - 1
    w = ((query - ext_t[lo]) / (ext_t[lo + 1] - ext_t[lo]))[:, None]
    return ext_c[lo] * (1.0 - w) + ext_c[lo + 1] * w


# --------------------------------------------------------------------- root channels
def integrate_root(
    deltas: np.ndarray,
    start: np.ndarray,
    displacement: np.ndarray | None = None,
    convention: str = "forward",
) -> np.ndarray:
    """Absolute root channels from per-frame differences over one cycle.

    Parameters
    ----------
    deltas : array_like, shape (P, R)
        Per-frame differences of ``R`` root channels over one cycle of ``P`` frames.
        With ``convention="forward"`` (default) ``deltas[i]`` is the step from frame
        ``i`` to frame ``i + 1``, and ``deltas[P - 1]`` the step from the last frame to
        the next cycle's first frame.  With ``"backward"`` ``deltas[i]`` is the step
        *into* frame ``i`` (``x[i] - x[i - 1]``), so ``deltas[0]`` is the wrap step.
    start : array_like, shape (R,)
        Value of frame 0.
    displacement : array_like, shape (R,), optional
        Wanted travel per cycle.  When given, the same constant is added to every
        delta so that the ``P`` deltas sum to exactly ``displacement``: looping the
        cycle then advances by ``displacement`` per cycle.

    Returns
    -------
    ndarray, shape (P, R)
        Absolute values; ``result[0] == start``.

    Raises
    ------
    ParameterError
        For mismatched shapes, non-finite values or an unknown convention.
    """
    deltas = _finite_array(deltas, "deltas", (1, 2))
    if deltas.ndim == 1:
        deltas = deltas[:, None]
    n, r = deltas.shape
    if n == 0:
        raise ParameterError("deltas is empty")
    start = _finite_array(start, "start", (0, 1)).reshape(-1)
    if start.shape[0] != r:
        raise ParameterError(f"start has {start.shape[0]} values for {r} root channels")
    if convention not in ("forward", "backward"):
        raise ParameterError(f"convention must be 'forward' or 'backward', got {convention!r}")
    steps = deltas if convention == "forward" else np.roll(deltas, -1, axis=0)
    if displacement is not None:
        target = _finite_array(displacement, "displacement", (0, 1)).reshape(-1)
        if target.shape[0] != r:
            raise ParameterError(f"displacement has {target.shape[0]} values for {r} root channels")
        steps = steps + (target - steps.sum(axis=0)) / n
    out = np.empty((n, r))
    out[0] = start
    np.cumsum(steps[:-1], axis=0, out=out[1:])
    out[1:] += start
    return out


# --------------------------------------------------------------------- typical cycle
def _heldout_times(theta: np.ndarray, density: PeriodicDensity, exclude: int = 0) -> np.ndarray:
    """Time (fraction of the period) of each frame interpolated from its time neighbours.

    The coordinate of frame ``i`` is computed from frame ``i``'s own noisy pose, so
    frames near it in coordinate tend to share its noise; predicting frame ``i`` at the
    midpoint of frames ``i - exclude - 1`` and ``i + exclude + 1`` (on the unwrapped,
    density-warped coordinate, which advances about linearly in time) removes that
    dependence.  The two end frames are extrapolated from their one-sided neighbours.
    """
    n = theta.shape[0]
    lifted = density.cdf(np.unwrap(2.0 * np.pi * _wrap01(theta)) / (2.0 * np.pi))
    if n < 2 * exclude + 4:
        return _wrap01(lifted)
    g = exclude + 1
    out = lifted.copy()
    out[g : n - g] = 0.5 * (lifted[: n - 2 * g] + lifted[2 * g :])
    i = np.arange(g)  # first frames: extrapolate from frames i + g and i + g + 1
    out[:g] = lifted[i + g] - g * (lifted[i + g + 1] - lifted[i + g])
    j = np.arange(n - g, n)  # last frames: from frames j - g and j - g - 1
    out[n - g :] = lifted[j - g] + g * (lifted[j - g] - lifted[j - g - 1])
    return _wrap01(out)


@dataclass(frozen=True, eq=False)
class TypicalCycle:
    """One typical period of a motion.

    Attributes
    ----------
    frames : ndarray, shape (P, D)
        The cycle at the capture's frame rate, in the *prepared* space (root channels
        still as per-frame differences).  Frame ``j`` is at time ``j / P`` of the period;
        frame ``P - 1`` is followed by frame 0 when looping.
    phases : ndarray, shape (P,)
        Circular coordinate of each frame, in ``[0, 1)``, increasing; ``phases[0] = 0``.
    curve : ndarray, shape (N, D)
        Centroid curve at the sampled phases.
    sample_phases : ndarray, shape (N,)
        The sampled phases, sorted ascending, in ``[0, 1)``.
    bandwidth : float
        Width ``σ`` of the kernel average, in frames of one period (NaN for the
        ``"mean"`` and ``"gaussian"`` weightings).
    bandwidth_selection : BandwidthSelection or None
        The cross-validation behind ``bandwidth`` when it was chosen with
        ``bandwidth="auto"``.
    """

    frames: np.ndarray
    phases: np.ndarray
    curve: np.ndarray
    sample_phases: np.ndarray
    bandwidth: float = float("nan")
    bandwidth_selection: BandwidthSelection | None = None

    @property
    def n_frames(self) -> int:
        """Number of frames ``P`` in one cycle."""
        return int(self.frames.shape[0])


def check_bandwidth(bandwidth: object, weighting: str = "kernel") -> None | str | float:
    """Validate a ``bandwidth`` argument (see :func:`typical_cycle`); return it normalised.

    Raises
    ------
    ParameterError
        Unless it is None, ``"auto"`` or a positive finite number, or when it is not None
        and ``weighting`` is not ``"kernel"``.
    """
    if bandwidth is not None and not (isinstance(bandwidth, str) and bandwidth == "auto"):
        if isinstance(bandwidth, str):
            raise ParameterError(
                f"bandwidth must be None, 'auto' or a positive number of frames, got {bandwidth!r}"
            )
        bandwidth = _positive_float(bandwidth, "bandwidth")
    if bandwidth is not None and weighting != "kernel":
        raise ParameterError(f"bandwidth={bandwidth!r} needs weighting='kernel', got {weighting!r}")
    return bandwidth


def typical_cycle(
    theta: np.ndarray,
    poses: np.ndarray,
    period_frames: float,
    density: PeriodicDensity | None = None,
    n_samples: int = 500,
    k: int = 10,
    weighting: str = "kernel",
    sampling: str = "quantile",
    random_state: None | int | np.random.Generator = 0,
    bandwidth: None | str | float = None,
) -> TypicalCycle:
    """Build the typical cycle of a motion from its circular coordinate.

    Parameters
    ----------
    theta : array_like, shape (T,)
        Circular coordinate of each frame (phase units, taken modulo 1).
    poses : array_like, shape (T, D)
        The frames in the prepared space.
    period_frames : float
        Length of one period in frames; the cycle has ``P = round(period_frames)``
        frames (at least 2).
    density : PeriodicDensity, optional
        A density fitted to ``theta``; by default one is fitted with the paper's
        settings (and ``random_state``).
    n_samples : int, default 500
        Number of sampled phases ``N`` (paper: 500).
    k : int, default 10
        Neighbours per centroid (paper: 10).
    weighting : {"kernel", "mean", "gaussian"}
        ``"kernel"`` (default): smooth periodic kernel average holding about ``k`` frames
        (:func:`kernel_centroids`); ``"mean"``: the paper's centroid of the ``k`` nearest
        frames; ``"gaussian"``: those ``k`` frames Gaussian-weighted
        (:func:`knn_centroids`).
    sampling : {"quantile", "random"}
        ``"quantile"`` (default): deterministic phases ``ppf((i + 0.5) / N)``, which are
        at times ``(i + 0.5) / N`` of the period.  ``"random"``: the paper's random
        draws from the density, placed in time by the density's cdf.
    random_state : None, int or numpy Generator, default 0
        Seed for the density fit and the random sampling (0, the package's one default,
        as for :func:`cyclecoord.extract`; None for fresh entropy).
    bandwidth : None, "auto" or float
        Width ``σ`` of the ``"kernel"`` weighting, in frames of one period.  None:
        ``k`` frames' worth, ``k / (T √(2π))`` in phase units (a fraction of a frame
        when the capture holds many cycles); ``"auto"``: chosen by leave-one-out
        cross-validation (:func:`select_bandwidth`); a positive number: that width.
        The other weightings take only None.

    Returns
    -------
    TypicalCycle

    Raises
    ------
    ParameterError
        For bad shapes or values, ``period_frames < 2``, an unfitted density, an unknown
        sampling or weighting, ``k`` larger than the number of frames, or a bandwidth
        that is not None, ``"auto"`` or a positive number (or a number with a weighting
        other than ``"kernel"``).
    """
    if (
        isinstance(period_frames, bool)
        or not isinstance(period_frames, Real)
        or not np.isfinite(period_frames)
    ):
        raise ParameterError(f"period_frames must be a finite number, got {period_frames!r}")
    n_cycle = int(round(float(period_frames)))
    if period_frames < 2 or n_cycle < 2:
        raise ParameterError(f"period_frames must be at least 2, got {period_frames!r}")
    n_samples = _positive_int(n_samples, "n_samples", 2)
    if sampling not in _SAMPLINGS:
        raise ParameterError(f"sampling must be one of {_SAMPLINGS}, got {sampling!r}")
    if weighting not in _WEIGHTINGS:
        raise ParameterError(f"weighting must be one of {_WEIGHTINGS}, got {weighting!r}")
    theta = _finite_array(theta, "theta", 1)
    if isinstance(k, bool) or not isinstance(k, Integral) or not 1 <= k <= theta.shape[0]:
        raise ParameterError(
            f"k must be an integer between 1 and the number of frames ({theta.shape[0]}), got {k!r}"
        )
    bandwidth = check_bandwidth(bandwidth, weighting)
    rng = as_generator(random_state)

    if density is None:
        density = PeriodicDensity(random_state=rng).fit(theta)
    elif not isinstance(density, PeriodicDensity):
        raise ParameterError(f"density must be a PeriodicDensity, got {type(density).__name__}")
    elif not hasattr(density, "weights_"):
        raise ParameterError("density is not fitted: call density.fit(theta) first")

    if sampling == "quantile":
        sample_phases = density.quantiles(n_samples)
        times = (np.arange(n_samples) + 0.5) / n_samples
    else:
        sample_phases = density.sample(n_samples, random_state=rng)
        times = density.cdf(sample_phases)
    sample_phases = _wrap01(sample_phases)

    selection = None
    width = float("nan")
    if weighting == "kernel" and bandwidth is None:
        # the default: k frames' worth of width in the phase
        width = k / (theta.shape[0] * np.sqrt(2.0 * np.pi)) * float(period_frames)
        curve = kernel_centroids(theta, poses, sample_phases, k=k)
    elif weighting == "kernel":
        # the kernel runs in time: frame i sits at time cdf(theta_i) of the period, the
        # sampled phases at `times`, so a width in frames means the same everywhere on
        # the cycle however unevenly the coordinate advances
        tau = _wrap01(density.cdf(_wrap01(theta)))
        if bandwidth == "auto":
            selection = select_bandwidth(
                tau, poses, float(period_frames), k=k, rule=_AUTO_RULE, exclude=_AUTO_EXCLUDE,
                query=_heldout_times(theta, density, _AUTO_EXCLUDE),
            )
            width = selection.bandwidth
        else:
            width = bandwidth
        curve = kernel_centroids(tau, poses, _wrap01(np.asarray(times, dtype=float)), k=k,
                                 bandwidth=width / float(period_frames))
    else:
        curve = knn_centroids(theta, poses, sample_phases, k=k, weighting=weighting)
    frames = resample_cyclic(curve, n_cycle, times=times)
    phases = _wrap01(density.ppf(np.arange(n_cycle) / n_cycle))
    for arr in (frames, phases, curve, sample_phases):
        arr.flags.writeable = False
    return TypicalCycle(
        frames=frames, phases=phases, curve=curve, sample_phases=sample_phases,
        bandwidth=float(width), bandwidth_selection=selection,
    )
