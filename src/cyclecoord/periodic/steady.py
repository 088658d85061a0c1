"""Where a take is steady: moving, repeating itself, at its own pace, not turning.

People record whole takes: a standing start, a few steps to reach speed, the motion, a
pause or a turn, a stop.  An animator cutting a loop by hand works on the steady part
only.  This module finds it from three per-frame signals:

* **moving** (:func:`moving_mask`): the speed of the (lightly smoothed) joint angles,
  averaged over half a second,
  is at least ``min_speed`` of the take's moving level (its 80th percentile); standing
  still and pauses fall below it;
* **repeating** (:func:`recurrence`): the pose comes back one period later (or came one
  period before): its distance to the nearest pose 0.7-1.45 periods away, over the
  take's median of that distance;
* **at the take's pace and heading** (:func:`steady_mask`): the circular coordinate
  advances between 1/1.6 and 1.6 turns per period over a two-period window, and the
  heading turns at a steady rate (:func:`steady_turning`: a circle or a figure-8 is a
  walk; a corner, its start and end, and a U-turn are not).

Frames passing all three, in runs of at least one period (gaps shorter than a quarter
period inside a run are bridged), are the steady frames the cycle is built from.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter1d, uniform_filter1d

from .windings import stretches

__all__ = [
    "moving_mask",
    "recurrence",
    "steady_mask",
    "steady_turning",
    "period_speed",
    "clean_runs",
    "centred_window",
]


def _smooth(x: np.ndarray, width: int) -> np.ndarray:
    return uniform_filter1d(np.asarray(x, dtype=float), size=max(1, int(width)), mode="nearest")


def clean_runs(mask: np.ndarray, min_run: int, max_gap: int) -> np.ndarray:
    """Bridge gaps of at most ``max_gap`` frames between runs, then drop runs under ``min_run``."""
    m = np.asarray(mask, dtype=bool).copy()
    runs = stretches(m)
    for (a0, b0), (a1, _) in zip(runs[:-1], runs[1:]):
        if a1 - b0 <= max_gap:
            m[b0:a1] = True
    for a, b in stretches(m):
        if b - a < min_run:
            m[a:b] = False
    return m


def _smoothed_steps(
    joints: np.ndarray, sigma: float, columns: np.ndarray | None, block: int = 32768
) -> np.ndarray:
    """Norm of each frame step of the Gaussian-smoothed poses, computed in blocks of frames.

    Each block is smoothed with a margin of the kernel's radius, so the steps equal those
    of smoothing the whole array at once (the same sums), while memory stays
    O(block x channels) beside the output instead of three copies of the take.
    """
    T = len(joints)
    # a kernel wider than the take smooths no more than one as wide (and its weights would
    # take memory in proportion to the frame rate)
    sigma = min(float(sigma), float(max(T, 1)))
    radius = int(4.0 * sigma + 0.5)  # gaussian_filter1d's default truncation
    out = np.empty(T - 1)
    for a in range(0, T - 1, block):
        b = min(T - 1, a + block)  # steps a .. b-1 need smoothed frames a .. b
        lo, hi = max(0, a - radius), min(T, b + 1 + radius)
        part = joints[lo:hi] if columns is None else joints[lo:hi][:, columns]
        sm = gaussian_filter1d(np.asarray(part, dtype=float), sigma=sigma, axis=0, mode="nearest")
        out[a:b] = np.linalg.norm(np.diff(sm[a - lo : b + 1 - lo], axis=0), axis=1)
    return out


def moving_mask(
    joints: np.ndarray,
    fps: float,
    *,
    min_speed: float = 0.35,
    smooth_seconds: float = 0.5,
    columns: np.ndarray | None = None,
) -> np.ndarray:
    """Frames whose joints move at a good fraction of the take's moving level.

    Parameters
    ----------
    joints : ndarray, shape (T, J)
        Joint-angle channels (degrees), root excluded.
        With ``columns``, any (T, D) poses of which those columns are the joints.
    fps : float
    min_speed : float
        Fraction of the 80th percentile of the smoothed speed below which a frame is
        still.
    smooth_seconds : float
        Width of the moving average of the speed.
    columns : ndarray of int, optional
        Joint columns of ``joints`` (read block by block, never copied whole).

    Returns
    -------
    ndarray of bool, shape (T,)
        Still stretches shorter than half a second inside motion count as moving; moving
        stretches shorter than a second count as still.
    """
    j = np.asarray(joints)
    width = j.shape[1] if columns is None else len(columns)
    if len(j) < 3 or width == 0:
        return np.ones(len(j), dtype=bool)
    # measurement noise adds a constant to the norm of raw frame steps (0.5 degrees of noise
    # on 56 channels reads as 5 degrees a frame); steps of lightly smoothed poses do not
    step = _smoothed_steps(
        j, max(1.0, 0.04 * fps), None if columns is None else np.asarray(columns)
    )
    step = np.concatenate([step, step[-1:]])
    speed = _smooth(step, round(smooth_seconds * fps))
    level = np.percentile(speed, 80)
    if level <= 0:
        return np.zeros(len(j), dtype=bool)
    mask = speed >= min_speed * level
    return clean_runs(mask, min_run=int(round(fps)), max_gap=int(round(0.5 * fps)))


def recurrence(
    poses: np.ndarray,
    period: float,
    *,
    shortest: float = 0.7,
    longest: float = 1.45,
    chunk: int = 2048,
    columns: np.ndarray | None = None,
) -> np.ndarray:
    """Distance from each pose to its nearest pose one period earlier or later.

    Parameters
    ----------
    poses : ndarray, shape (T, D)
    period : float
        Period in frames.
    shortest, longest : float
        Lags from ``shortest`` to ``longest`` periods are searched (repetitions of a
        real take vary in length; a synthetic one may vary by 30%).
    chunk : int
        Frames per block.
    columns : ndarray of int, optional
        Only these columns of ``poses`` (read block by block: the take is never copied).

    Returns
    -------
    ndarray, shape (T,)
        The smallest distance over the lags, both directions; ``inf`` for a frame with
        no pose at those lags (a take shorter than a period).
    """
    x = np.asarray(poses)
    cols = None if columns is None else np.asarray(columns)
    T = len(x)
    lo = max(1, int(np.floor(shortest * period)))
    hi = max(lo, int(np.ceil(longest * period)))
    best = np.full(T, np.inf)
    # blocks of frames outside, lags inside: a block and its partners stay in cache
    # (2.6x faster than lags outside at 250k frames), einsum without a squared temporary
    for a in range(0, T, chunk):
        b = min(T, a + chunk)
        part = x[a : min(T, b + hi)]  # the block and every partner it has
        part = np.ascontiguousarray(part if cols is None else part[:, cols], dtype=float)
        for lag in range(lo, min(hi, T - 1) + 1):
            e = min(b, T - lag)
            if e <= a:
                break
            n = e - a
            diff = part[lag : lag + n] - part[:n]
            d = np.sqrt(np.einsum("ij,ij->i", diff, diff))
            np.minimum(best[a:e], d, out=best[a:e])  # forward partner
            np.minimum(best[a + lag : e + lag], d, out=best[a + lag : e + lag])  # backward partner
    return best


def period_speed(
    poses: np.ndarray, fps: float, period: float, columns: np.ndarray | None = None
) -> np.ndarray:
    """Joint speed (norm of the lightly smoothed frame steps) averaged over one period
    around each frame, shape (T,); the steps of :func:`moving_mask`."""
    x = np.asarray(poses)
    if len(x) < 3:
        return np.ones(len(x))
    step = _smoothed_steps(
        x, max(1.0, 0.04 * fps), None if columns is None else np.asarray(columns)
    )
    return _smooth(np.concatenate([step, step[-1:]]), max(1, int(round(period))))


def centred_window(n: int, half: int) -> tuple[np.ndarray, np.ndarray]:
    """Ends of a window of ``2 * half`` frames around each of ``n`` frames, kept inside."""
    idx = np.arange(n)
    lo = np.clip(idx - half, 0, max(0, n - 1 - 2 * half))
    hi = np.minimum(lo + 2 * half, n - 1)
    return lo, hi


def steady_turning(
    heading: np.ndarray, period: float, max_turn: float = 30.0, max_curve: float = 90.0
) -> np.ndarray:
    """Frames whose heading turns at a steady rate (see :func:`steady_mask`).

    Parameters
    ----------
    heading : ndarray, shape (T,)
        Continuous heading, degrees.
    period : float
        Frames per cycle.
    max_turn : float
        Largest change, in degrees per period, between a frame's turn over the period
        around it and the turns over the periods centred half a period before and after
        (a frame whose window reaches into a turn's start or end).
    max_curve : float
        Largest turn over the period around a frame, degrees (a turn of
        exactly ``max_curve`` is steady).

    Returns
    -------
    ndarray of bool, shape (T,)
    """
    h = np.asarray(heading, dtype=float)
    n = h.size
    lo, hi = centred_window(n, max(1, int(round(period / 2))))
    rate = (h[hi] - h[lo]) / np.maximum(hi - lo, 1) * period  # degrees per period
    shift = max(1, int(round(period / 2)))
    idx = np.arange(n)
    before = rate[np.clip(idx - shift, 0, n - 1)]
    after = rate[np.clip(idx + shift, 0, n - 1)]
    change = np.maximum(np.abs(rate - before), np.abs(rate - after))
    return (change <= max_turn) & (np.abs(rate) <= max_curve)


def steady_mask(
    unwrapped: np.ndarray,
    candidates: np.ndarray,
    period: float,
    *,
    recurrence_distance: np.ndarray | None = None,
    heading: np.ndarray | None = None,
    max_pace: float = 1.6,
    pace_window: float = 2.0,
    max_recurrence: float = 2.0,
    max_turn: float = 30.0,
    max_curve: float = 90.0,
    speed: np.ndarray | None = None,
    max_speed_ratio: float = 1.3,
) -> np.ndarray:
    """Frames where the periodic motion is steady.

    Parameters
    ----------
    unwrapped : ndarray, shape (T,)
        The circular coordinate unwrapped along the frames (NaN outside ``candidates``).
    candidates : ndarray of bool, shape (T,)
        Frames that may be steady (moving frames).
    period : float
        Period in frames (from the complete windings).
    recurrence_distance : ndarray, shape (T,), optional
        From :func:`recurrence`; a frame whose distance is over ``max_recurrence`` times
        the median over candidate frames is not steady.
    heading : ndarray, shape (T,), optional
        Heading in degrees (continuous).  Turning at a steady rate is steady (a walk on a
        circle or a figure-8 repeats itself in the body's own frame, where the root's
        changes are measured): a frame is not steady where its period-long window turns
        more than ``max_turn`` degrees more or less than the windows half a period before
        and after it (the start or end of a turn), or more than ``max_curve`` degrees in
        all (a corner taken within a cycle, a U-turn, a turn on the spot).  90 degrees a
        period is a circle walked in four cycles, about 0.8 m in radius at a 1.3 m
        stride: people walk tighter curves than the 60 degrees that was the limit until
        the Bandai turning walks, which take their 90-degree turns at up to 51 (left) and
        65 (right) degrees a period with the cadence of a walk.
    max_turn, max_curve : float
        Degrees per period (see ``heading``).
    max_pace : float
        Turns per period over a period-long window must lie between ``1 / max_pace``
        and ``max_pace`` (starting, stopping and standing turn far slower).
    pace_window : float
        A second, longer window the pace is also measured over, in periods; a frame is
        at pace when either window says so (a coordinate that stalls for part of a
        cycle and then jumps reads its true pace over two periods).
    speed : ndarray, shape (T,), optional
        Joint speed averaged over a period around each frame (:func:`period_speed`).  Where
        a stretch of candidate frames meets still frames, the frames slower than the median
        over all candidates by more than a factor ``max_speed_ratio`` are not steady: the
        first steps out of a standing start (69_01: 35-75 % of the walk's speed over its
        first 90 moving frames) and the last into a stop repeat the gait's shape at a pace
        of their own.  Inside a stretch, and at the take's first and last frames, the
        speed is not judged (arm circles that grow in a window cut from a routine).
    max_speed_ratio : float

    Returns
    -------
    ndarray of bool, shape (T,)
        Gaps of at most a quarter period (rounded) between steady frames are bridged,
        then steady runs under a period (rounded) are dropped (:func:`clean_runs`).
    """
    cand = np.asarray(candidates, dtype=bool)
    ok = cand.copy()
    for a, b in stretches(cand):
        u = np.asarray(unwrapped[a:b], dtype=float)
        h = None if heading is None else np.asarray(heading[a:b], dtype=float)
        good_pace = np.zeros(b - a, dtype=bool)
        for periods in sorted({1.0, float(pace_window)}):
            lo, hi = centred_window(b - a, max(1, int(round(periods * period / 2))))
            span = np.maximum(hi - lo, 1)
            pace = (u[hi] - u[lo]) / span * period
            good_pace |= (pace >= 1.0 / max_pace) & (pace <= max_pace)
        good = good_pace
        if h is not None:
            good &= steady_turning(h, period, max_turn, max_curve)
        ok[a:b] &= good
    if speed is not None:
        v = np.asarray(speed, dtype=float)
        ref = np.median(v[cand]) if cand.any() else np.nan
        if np.isfinite(ref) and ref > 0:
            slow = v < ref / max_speed_ratio
            for a, b in stretches(cand):
                # trim the ramps where a moving stretch meets still frames (speeding up out
                # of a standing start, slowing into a stop or a pause); the take's own ends
                # and the speed inside a stretch are the motion's own
                i = a
                while a > 0 and i < b and slow[i]:
                    i += 1
                j = b
                while b < cand.size and j > i and slow[j - 1]:
                    j -= 1
                ok[a:i] = False
                ok[j:b] = False
    if recurrence_distance is not None:
        r = np.asarray(recurrence_distance, dtype=float)
        ref = np.median(r[cand & np.isfinite(r)]) if np.any(cand & np.isfinite(r)) else np.inf
        ok &= ~(r > max_recurrence * ref)
    return clean_runs(ok, min_run=int(round(period)), max_gap=int(round(period / 4)))
