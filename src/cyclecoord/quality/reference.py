"""What an animator does by hand: the best loop cut, the plain average cycle, the period.

These are the references :mod:`cyclecoord.quality.cycle_quality` measures our cycle
against (issue 12, item 7):

* :func:`best_loop_cut` -- frames ``i .. j-1`` of the take, ``j - i`` near the period,
  chosen so that pose ``i`` is as close as possible to pose ``j`` (the loop's seam is then
  one ordinary step), among stretches that actually move.
* :func:`average_cycle` -- the take cut at the wraps of a phase, every piece stretched to
  the same number of frames and averaged.
* :func:`autocorrelation_period` -- the first strong peak of the joint angles'
  autocorrelation over lags of 0.3-3 s, needing no first guess.

All work on *joint angles* (:func:`joint_angles`): every channel not of the root joint
(the 56 non-root channels of a CMU capture), rotations unwrapped along time so that a
channel crossing +-180 degrees does not jump by 360.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..motion import Motion

__all__ = [
    "LoopCut",
    "joint_columns",
    "joint_angles",
    "median_step",
    "used_mask",
    "wrap_times",
    "best_loop_cut",
    "average_cycle",
    "autocorrelation_period",
]

#: Lags searched by :func:`autocorrelation_period`, in seconds.
MIN_LAG_SECONDS = 0.3
MAX_LAG_SECONDS = 3.0


# ------------------------------------------------------------------ joint angles
def joint_columns(motion: Motion) -> np.ndarray:
    """Columns of every channel not of the root joint (all columns when there is no root)."""
    root = set(motion.root_channels())
    if root:
        root_joint = motion.channels[min(root)][0]
        return np.array(
            [i for i, (j, _) in enumerate(motion.channels) if j != root_joint], dtype=int
        )
    return np.arange(motion.n_channels, dtype=int)


def joint_angles(motion: Motion, like: np.ndarray | None = None) -> np.ndarray:
    """Joint angles of a motion, unwrapped along time.

    Parameters
    ----------
    motion : Motion
        Any motion; its non-root channels are taken (:func:`joint_columns`).
    like : ndarray, shape (D,), optional
        Per-channel reference values (e.g. the take's mean joint angles): each rotation
        channel is then shifted by a whole number of turns so that its mean lies within
        180 degrees of ``like``, so a cycle and its take are compared in one branch.

    Returns
    -------
    ndarray, shape (T, D)
        Degrees for rotation channels (dof starting with ``r``), other channels as stored.
    """
    cols = joint_columns(motion)
    x = np.array(motion.frames[:, cols], dtype=float)
    rot = np.array([motion.channels[c][1].startswith("r") for c in cols], dtype=bool)
    if x.shape[0] > 1 and rot.any():
        x[:, rot] = np.unwrap(x[:, rot], period=360.0, axis=0)
    if like is not None:
        like = np.asarray(like, dtype=float)
        if like.shape != (x.shape[1],):
            raise ParameterError(
                f"like must have {x.shape[1]} values (one per joint channel), got {like.shape}"
            )
        turns = np.round((like - x.mean(axis=0)) / 360.0)
        x[:, rot] += 360.0 * turns[rot]
    return x


def median_step(angles: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Median frame-to-frame step ``|x[t+1] - x[t]|`` (degrees), over steps whose two
    frames are both in ``mask`` when given."""
    x = np.asarray(angles, dtype=float)
    steps = np.linalg.norm(np.diff(x, axis=0), axis=1)
    if mask is not None:
        m = np.asarray(mask, dtype=bool)
        steps = steps[m[:-1] & m[1:]]
    return float(np.median(steps)) if steps.size else float("nan")


def used_mask(n_frames: int, used_frames: list | None) -> np.ndarray:
    """Boolean mask of the frames in ``used_frames`` (``[[start, stop], ...]``, half-open,
    0-based in the motion's own frames); all frames when None."""
    if used_frames is None:
        return np.ones(n_frames, dtype=bool)
    mask = np.zeros(n_frames, dtype=bool)
    for pair in used_frames:
        a, b = int(pair[0]), int(pair[1])
        if not 0 <= a < b <= n_frames:
            raise ParameterError(
                f"used frames {a}:{b} are not inside the motion's {n_frames} frames"
            )
        mask[a:b] = True
    return mask


# ---------------------------------------------------------------------- loop cut
@dataclass(frozen=True)
class LoopCut:
    """The best hand-made loop: frames ``start .. stop-1`` of the take.

    Attributes
    ----------
    start, stop : int
        Half-open frame range in the motion given (0-based); ``stop - start`` frames.
    clip : Motion
        Those frames (all channels), to be played as a loop.
    distance : float
        ``|pose(start) - pose(stop)|`` in degrees (joint angles): the seam is this far
        from one ordinary step.
    period_frames : float
        The period the cut's length was searched around.
    median_step : float
        The whole take's median frame step (degrees) that a cut's mean step had to reach.
    """

    start: int
    stop: int
    clip: Motion
    distance: float
    period_frames: float
    median_step: float

    @property
    def n_frames(self) -> int:
        return self.stop - self.start


def best_loop_cut(
    motion: Motion,
    period_frames: float,
    tolerance: float = 0.15,
    used_frames: list | None = None,
) -> LoopCut:
    """The loop an animator would cut: ``j - i`` near the period, pose ``i`` closest to ``j``.

    Every pair ``i < j`` with ``|j - i - period| <= tolerance * period`` is tried, among
    stretches that move: the cut's mean frame step must be at least the median step of
    the whole take (so a standing start, whose poses match trivially, is never chosen
    while the take moves on most of its frames), and frames ``i .. j`` must all lie in
    ``used_frames`` when given.

    Parameters
    ----------
    motion : Motion
        The take.
    period_frames : float
        The period to cut around, in frames (e.g. from :func:`autocorrelation_period`).
    tolerance : float, default 0.15
        Allowed relative deviation of the cut's length from the period.
    used_frames : list of [start, stop], optional
        Restrict the cut to these frame ranges.

    Returns
    -------
    LoopCut

    Raises
    ------
    ParameterError
        When the period is not positive or no cut fits (take too short, nothing moves).
    """
    if not np.isfinite(period_frames) or period_frames < 2:
        raise ParameterError(
            f"period_frames must be a number of frames >= 2, got {period_frames!r}"
        )
    if not 0 <= tolerance < 1:
        raise ParameterError(f"tolerance must be in [0, 1), got {tolerance!r}")
    x = joint_angles(motion)
    T = x.shape[0]
    mask = used_mask(T, used_frames)
    steps = np.linalg.norm(np.diff(x, axis=0), axis=1)
    med = median_step(x)
    csum = np.concatenate([[0.0], np.cumsum(steps)])
    bad = np.concatenate([[0], np.cumsum(~mask)])  # frames outside the used ranges
    lo = max(2, int(np.ceil(period_frames * (1 - tolerance))))
    hi = int(np.floor(period_frames * (1 + tolerance)))
    best = (np.inf, -1, -1)
    for n in range(lo, hi + 1):
        if n >= T:
            break
        i = np.arange(T - n)
        j = i + n
        moving = (csum[j] - csum[i]) / n >= med
        inside = bad[j + 1] - bad[i] == 0
        ok = moving & inside
        if not ok.any():
            continue
        d = np.linalg.norm(x[j[ok]] - x[i[ok]], axis=1)
        k = int(np.argmin(d))
        if d[k] < best[0]:
            best = (float(d[k]), int(i[ok][k]), int(j[ok][k]))
    if best[1] < 0:
        raise ParameterError(
            f"no loop cut of {lo}-{hi} frames fits in {motion.source or 'the take'} "
            f"({T} frames, {int(mask.sum())} used) over stretches moving at least the median step"
        )
    dist, i, j = best
    clip = motion[i:j]
    return LoopCut(
        start=i,
        stop=j,
        clip=clip,
        distance=dist,
        period_frames=float(period_frames),
        median_step=med,
    )


# ------------------------------------------------------------------ average cycle
def wrap_times(coordinate: np.ndarray) -> list[np.ndarray]:
    """Times (fractional frames) at which a circular coordinate completes a turn.

    The coordinate is unwrapped within each run of finite values (NaN frames have no
    phase and split runs); a turn ends where the running maximum of the unwrapped
    coordinate first reaches the next whole number (linear interpolation between frames),
    so jitter backwards across 0 is not counted twice.

    Parameters
    ----------
    coordinate : ndarray, shape (T,)
        Circular coordinate in ``[0, 1)`` per frame, NaN where a frame has no phase.

    Returns
    -------
    list of ndarray
        One array of increasing wrap times per run of finite values.
    """
    c = np.asarray(coordinate, dtype=float)
    if c.ndim != 1:
        raise ParameterError(f"coordinate must be one value per frame, got shape {c.shape}")
    finite = np.isfinite(c)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], finite.astype(int), [0]])))
    out = []
    for a, b in zip(edges[::2], edges[1::2]):
        u = np.unwrap(c[a:b], period=1.0)
        env = np.maximum.accumulate(u)
        times = []
        for level in np.arange(np.ceil(env[0]), np.floor(env[-1]) + 1):
            k = int(np.argmax(env >= level))
            if k == 0:  # the run starts exactly on a wrap
                times.append(float(a))
                continue
            prev = env[k - 1]  # < level <= env[k]: k is the first frame reaching the level
            f = (level - prev) / (env[k] - prev)
            times.append(a + k - 1 + f)
        out.append(np.asarray(times, dtype=float))
    return out


def _sample(x: np.ndarray, times: np.ndarray) -> np.ndarray:
    """Rows of ``x`` at fractional frame times by linear interpolation."""
    k = np.clip(np.floor(times).astype(int), 0, len(x) - 2)
    f = (times - k)[:, None]
    return (1 - f) * x[k] + f * x[k + 1]


def _rot_y(dx: np.ndarray, dz: np.ndarray, deg: float) -> tuple[np.ndarray, np.ndarray]:
    """Rotate horizontal (x, z) displacements about the vertical y axis by ``deg``."""
    a = np.radians(deg)
    c, s = np.cos(a), np.sin(a)
    return c * dx + s * dz, -s * dx + c * dz


def average_cycle(
    motion: Motion,
    coordinate_or_wraps: np.ndarray | list,
    length: int,
) -> Motion:
    """The plain average cycle: the take cut at a phase's wraps, time-normalised, averaged.

    Every piece between consecutive wraps is resampled to ``length`` frames (linear
    interpolation at ``start + k (stop - start) / length``, ``k = 0 .. length - 1``) and
    the pieces are averaged channel by channel -- no alignment, no weighting.  Joint
    angles are unwrapped along the take before averaging.  The root is averaged as an
    animator would: height, pitch and roll as they are; translation and heading
    relative to each piece's first frame, translation turned into that frame's heading;
    the result starts at the first piece's root position and heading.

    Parameters
    ----------
    motion : Motion
        The take.
    coordinate_or_wraps : ndarray of shape (T,), or list of wrap frames
        The per-frame circular coordinate in ``[0, 1)`` (NaN for frames without phase;
        pieces never span a NaN), or the increasing wrap frames (int or fractional).
    length : int
        Frames of the averaged cycle.

    Returns
    -------
    Motion
        ``length`` frames with the take's channels, skeleton and rate;
        ``metadata["pieces"]`` lists the ``(start, stop)`` times averaged.

    Raises
    ------
    ParameterError
        When fewer than one complete piece is found or ``length < 2``.
    """
    if int(length) != length or length < 2:
        raise ParameterError(f"length must be an integer >= 2, got {length!r}")
    length = int(length)
    T = motion.n_frames
    arr = np.asarray(coordinate_or_wraps, dtype=float)
    if (
        arr.ndim == 1
        and arr.size == T
        and np.all((np.isnan(arr)) | ((arr >= 0) & (arr < 1)))
        and T > 2
    ):
        runs = wrap_times(arr)
    else:
        runs = [np.sort(arr.ravel())]
    pieces = [
        (a, b) for w in runs for a, b in zip(w[:-1], w[1:]) if b > a and 0 <= a and b <= T - 1
    ]
    if not pieces:
        raise ParameterError(
            f"no complete cycle between wraps in {motion.source or 'the take'}: "
            "the phase must wrap at least twice"
        )
    cols = joint_columns(motion)
    frames = np.array(motion.frames, dtype=float)
    frames[:, cols] = joint_angles(motion)
    root = np.array(motion.root_channels(), dtype=int)
    rcol = {motion.channels[c][1]: c for c in root}
    heading = "ry" in rcol
    if heading:
        frames[:, rcol["ry"]] = np.unwrap(frames[:, rcol["ry"]], period=360.0)
    acc = np.zeros((length, motion.n_channels))
    k = np.arange(length)
    for a, b in pieces:
        s = _sample(frames, a + k * (b - a) / length)
        if "tx" in rcol and "tz" in rcol:
            dx, dz = s[:, rcol["tx"]] - s[0, rcol["tx"]], s[:, rcol["tz"]] - s[0, rcol["tz"]]
            if heading:
                dx, dz = _rot_y(dx, dz, -s[0, rcol["ry"]])
            s[:, rcol["tx"]], s[:, rcol["tz"]] = dx, dz
        if heading:
            s[:, rcol["ry"]] -= s[0, rcol["ry"]]
        acc += s
    avg = acc / len(pieces)
    first = _sample(frames, np.array([pieces[0][0]]))[0]
    if heading:
        avg[:, rcol["ry"]] += first[rcol["ry"]]
    if "tx" in rcol and "tz" in rcol:
        dx, dz = avg[:, rcol["tx"]], avg[:, rcol["tz"]]
        if heading:
            dx, dz = _rot_y(dx, dz, first[rcol["ry"]])
        avg[:, rcol["tx"]] = first[rcol["tx"]] + dx
        avg[:, rcol["tz"]] = first[rcol["tz"]] + dz
    meta = {"pieces": [(float(a), float(b)) for a, b in pieces]}
    return motion.with_frames(
        avg, start_frame=0, source=f"average cycle of {motion.source or 'take'}", metadata=meta
    )


# ---------------------------------------------------------------------- period
def autocorrelation_period(
    motion: Motion,
    used_frames: list | None = None,
    min_lag: float = MIN_LAG_SECONDS,
    max_lag: float = MAX_LAG_SECONDS,
    strong: float = 0.8,
    min_correlation: float = 0.3,
) -> float:
    """The period of a take by the autocorrelation of its joint angles, no guess needed.

    The joint angles (:func:`joint_angles`, mean over the used frames removed) are
    correlated with themselves at every lag of ``min_lag .. max_lag`` seconds, using only
    pairs of frames both inside one used range.  The peak is chosen on the biased
    autocorrelation ``sum a.b / sum x.x`` (normalised by the energy of all used frames,
    so long lags with few pairs cannot win by chance): the first local maximum at least
    ``strong`` times the highest.  It is then located on the normalised correlation
    ``r(L) = sum a.b / sqrt(sum a.a * sum b.b)`` (its maximum within 10 % of that lag,
    which must reach ``min_correlation``), refined to a fraction of a frame by a parabola
    through it and its neighbours.  Taking the *first* strong peak avoids multiples of
    the period; for gaits the half period is no peak (left and right legs are in
    anti-phase).

    Parameters
    ----------
    motion : Motion
        The take.
    used_frames : list of [start, stop], optional
        Only these frames (e.g. the pipeline's steady stretches).
    min_lag, max_lag : float
        Lags searched, seconds (default 0.3-3 s; capped at 80 % of the longest range).
    strong : float, default 0.8
        A peak counts when at least this fraction of the highest peak.
    min_correlation : float, default 0.3
        Smallest normalised correlation accepted.

    Returns
    -------
    float
        Period in frames; NaN when no lag qualifies (too short or not periodic).
    """
    x = joint_angles(motion)
    mask = used_mask(len(x), used_frames)
    x = x - x[mask].mean(axis=0)
    x[~mask] = 0.0
    T = len(x)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    longest = int(np.max(edges[1::2] - edges[::2])) if edges.size else 0
    lo = max(2, int(np.floor(min_lag * motion.fps)))
    hi = min(int(np.ceil(max_lag * motion.fps)), int(0.8 * longest))
    if hi - lo < 2:
        return float("nan")
    lags = np.arange(lo - 1, hi + 2)
    energy = float(np.sum(x * x))
    if energy == 0:
        return float("nan")
    corr = np.full(lags.size, -np.inf)  # normalised over the overlapping pairs
    biased = np.full(lags.size, -np.inf)  # over all used frames' energy: favours short lags
    for n, lag in enumerate(lags):
        if lag >= T:
            break
        both = mask[: T - lag] & mask[lag:]
        a, b = x[: T - lag][both], x[lag:][both]
        den = np.sqrt(np.sum(a * a) * np.sum(b * b))
        if den > 0:
            corr[n] = np.sum(a * b) / den
            biased[n] = np.sum(a * b) / energy
    inner = np.arange(1, lags.size - 1)
    peaks = inner[(biased[inner] >= biased[inner - 1]) & (biased[inner] > biased[inner + 1])]
    peaks = peaks[corr[peaks] >= min_correlation]
    if peaks.size == 0:
        return float("nan")
    top = biased[peaks].max()
    k = int(peaks[np.argmax(biased[peaks] >= strong * top)])
    # locate the peak on the unbiased curve, near the one chosen on the biased curve
    near = np.arange(
        max(1, k - max(1, int(0.1 * lags[k]))),
        min(lags.size - 1, k + max(1, int(0.1 * lags[k])) + 1),
    )
    k = int(near[np.argmax(corr[near])])
    y0, y1, y2 = corr[k - 1], corr[k], corr[k + 1]
    den = y0 - 2 * y1 + y2
    shift = 0.5 * (y0 - y2) / den if np.isfinite(den) and den < 0 else 0.0
    return float(lags[k] + np.clip(shift, -0.5, 0.5))
