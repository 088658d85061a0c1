"""Forward kinematics of a motion as the measure of generated motion reads it
(:mod:`cyclecoord.quality.generated`): its legs, the pose relative to the root with the
heading removed, the leg cycle, the support foot, the frames where a take moves, the
channels that turn a leg."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from ..errors import CycleCoordError, ParameterError
from ..motion import Motion
from .contacts import leg_length
from .legs import Legs, find_legs, legs_of_feet

#: Window of the root speed, seconds.
ROOT_WINDOW = 0.5
#: Seconds the root's horizontal velocity is averaged over before its acceleration is
#: taken: 3 frames at 30 fps, the same time at any rate (a window in frames would judge
#: a 120 fps motion and its captures over 25 ms, where their frame-to-frame noise lies).
ROOT_ACCEL_WINDOW = 0.1
#: A take's frames count as moving where its pose speed, averaged over a second, is at
#: least this fraction of that average's 90th percentile (:func:`_moving`): the sources'
#: root speed, support foot, pose speeds and accelerations are theirs while they move.
MOVING_FRACTION = 0.5
#: Cadence search window, seconds.
CYCLE_RANGE = (0.4, 2.5)
#: The leg cycle is the first autocorrelation peak at least this fraction of the highest.
CYCLE_PEAK = 0.85


@dataclass(frozen=True)
class _Rig:
    """Joint indices the measure needs, found once per skeleton."""

    legs: Legs
    feet: tuple[str, ...]
    foot_cols: list[int]
    hips: list[int]
    knees: list[int]
    ankles: list[int]
    trunk: int | None
    leg_length: float


def _rig(motion: Motion, feet: Sequence[str] | None) -> _Rig:
    skel = motion.skeleton
    if skel is None:
        raise ParameterError("the measure of generated motion needs a skeleton")
    legs = find_legs(skel, motion) if feet is None else legs_of_feet(skel, tuple(feet), motion)
    names = list(skel.names)
    hips, knees, ankles = [], [], []
    for leg in legs.legs[:2] if len(legs.legs) > 2 else legs.legs:
        ankle = names.index(leg.points[0])
        knee = skel.joints[ankle].parent
        hip = skel.joints[knee].parent if knee > 0 else -1
        if knee <= 0 or hip < 0:
            raise ParameterError(f"leg {leg.label}: no knee and hip above {leg.points[0]}")
        hips.append(hip)
        knees.append(knee)
        ankles.append(ankle)
    from ..joint_names import classify_skeleton

    roles = classify_skeleton(skel)
    spine = [i for i, n in enumerate(names) if getattr(roles.get(n), "role", None) == "spine"]
    trunk = spine[1] if len(spine) > 1 else (spine[0] if spine else None)
    return _Rig(
        legs=legs,
        feet=legs.feet,
        foot_cols=[names.index(f) for f in legs.feet],
        hips=hips,
        knees=knees,
        ankles=ankles,
        trunk=trunk,
        leg_length=leg_length(skel, legs.feet),
    )


def _angle(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    nu = np.linalg.norm(u, axis=-1)
    nv = np.linalg.norm(v, axis=-1)
    c = np.einsum("...k,...k->...", u, v) / np.maximum(nu * nv, 1e-12)
    return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))


@dataclass
class _Kin:
    """Positions and the derived per-frame signals of one motion."""

    fps: float
    pos: np.ndarray  # (T, J, 3) every joint and end site
    local: np.ndarray  # root-relative, heading removed
    knee: np.ndarray  # (T, L) flexion, degrees (0 straight)
    hip: np.ndarray  # (T, L) thigh against the trunk line, degrees
    names: list = field(default_factory=list)
    parents: list = field(default_factory=list)

    @property
    def n(self) -> int:
        return int(self.pos.shape[0])

    def pose_speed(self) -> np.ndarray:
        """(T-1,) RMS joint speed relative to the root, heading removed (units/s)."""
        d = np.diff(self.local, axis=0)
        return np.sqrt((d**2).sum(-1).mean(-1)) * self.fps

    def accel(self) -> np.ndarray:
        """(T-2,) largest joint acceleration relative to the root (units/s^2)."""
        a = np.diff(self.local, 2, axis=0) * self.fps**2
        return np.linalg.norm(a, axis=-1).max(-1)

    def root_speed(self) -> np.ndarray:
        """Horizontal root speed over :data:`ROOT_WINDOW` windows (units/s)."""
        r = self.pos[:, 0, :][:, [0, 2]]
        k = max(1, int(round(ROOT_WINDOW * self.fps)))
        if r.shape[0] <= k:
            k = max(1, r.shape[0] - 1)
        return np.linalg.norm(r[k:] - r[:-k], axis=-1) * self.fps / k

    def root_accel(self) -> np.ndarray:
        """(T-2,) horizontal root acceleration (units/s^2), its velocity averaged over
        :data:`ROOT_ACCEL_WINDOW`: the root's own lurches, which :meth:`accel`
        (relative to the root) does not see."""
        from scipy.ndimage import uniform_filter1d

        v = np.diff(self.pos[:, 0, :][:, [0, 2]], axis=0) * self.fps
        k = max(1, int(round(ROOT_ACCEL_WINDOW * self.fps)))
        v = uniform_filter1d(v, k, axis=0, mode="nearest")
        return np.linalg.norm(np.diff(v, axis=0), axis=-1) * self.fps

    def cycle(self) -> float:
        """Leg cycle in seconds (NaN when too short or aperiodic)."""
        return _cycle(self.knee[:, 0], self.fps)


def _kin(motion: Motion, rig: _Rig) -> _Kin:
    fk = motion.positions()
    pos = fk.positions
    lr = pos[:, rig.hips[0]] - pos[:, rig.hips[-1]]
    h = np.arctan2(lr[:, 2], lr[:, 0])
    c, s = np.cos(h), np.sin(h)
    rel = pos - pos[:, :1, :]
    x, z = rel[..., 0], rel[..., 2]
    local = np.stack(
        [c[:, None] * x + s[:, None] * z, rel[..., 1], -s[:, None] * x + c[:, None] * z], -1
    )
    thigh = pos[:, rig.knees] - pos[:, rig.hips]
    shin = pos[:, rig.ankles] - pos[:, rig.knees]
    if rig.trunk is not None:
        up = (pos[:, rig.trunk] - pos[:, 0])[:, None, :]
    else:
        up = np.broadcast_to(np.array([0.0, 1.0, 0.0]), thigh.shape)
    return _Kin(
        fps=float(motion.fps),
        pos=pos,
        local=local,
        knee=_angle(thigh, shin),
        hip=_angle(thigh, -up),
        names=list(fk.names),
        parents=[int(p) for p in fk.parents],
    )


def _peak_cycle(k: np.ndarray, fps: float) -> float:
    """Leg cycle of a take too short for the autocorrelation (under two cycles): the
    median spacing of its knee's flexion peaks, one per stretch above the mean by half
    a standard deviation (its highest frame, not at the take's ends); NaN with fewer
    than two or a spacing outside ``CYCLE_RANGE``."""
    above = np.r_[False, k > 0.5 * float(np.std(k)), False].astype(int)
    edges = np.flatnonzero(np.diff(above))
    peaks = []
    for a, b in zip(edges[::2], edges[1::2]):
        top = a + int(np.argmax(k[a:b]))
        if 0 < top < k.size - 1:
            peaks.append(top)
    if len(peaks) < 2:
        return float("nan")
    c = float(np.median(np.diff(peaks))) / fps
    return c if CYCLE_RANGE[0] <= c <= CYCLE_RANGE[1] else float("nan")


def _cycle(signal: np.ndarray, fps: float) -> float:
    k = np.asarray(signal, dtype=float) - np.mean(signal)
    n = k.size
    lo, hi = int(CYCLE_RANGE[0] * fps), min(int(CYCLE_RANGE[1] * fps), n // 2)
    if not np.any(k):
        return float("nan")
    if hi <= lo + 1:
        return _peak_cycle(k, fps)
    spec = np.fft.rfft(k, 2 * n)
    ac = np.fft.irfft(spec * np.conj(spec))[:n] / np.arange(n, 0, -1)
    ac = ac / ac[0]
    win = ac[lo:hi]
    # the first local peak within CYCLE_PEAK of the highest: a clean capture's two cycles
    # correlate as well as one (the synthetic walk of 1.1 s read 2.23 s by the highest)
    top = float(win.max())
    for k in range(1, win.size - 1):
        if win[k] >= win[k - 1] and win[k] >= win[k + 1] and win[k] >= CYCLE_PEAK * top:
            return (lo + k) / fps
    return (lo + int(np.argmax(win))) / fps


def _support(kin: _Kin, rig: _Rig) -> np.ndarray:
    """(T-2,) horizontal speed (units/s) of the lowest foot point, central differences."""
    p = kin.pos[:, rig.foot_cols]
    low = p[1:-1, :, 1].argmin(axis=1)
    v = np.linalg.norm(p[2:, :, :][:, :, [0, 2]] - p[:-2, :, :][:, :, [0, 2]], axis=-1)
    return v[np.arange(v.shape[0]), low] * kin.fps / 2.0


def _moving(kin: _Kin) -> np.ndarray:
    """(T,) the frames where a take moves: its pose speed, averaged over a second, at
    least :data:`MOVING_FRACTION` of that average's 90th percentile (every frame when
    under a second would be left).  The Xsens walk stands still for 14 of its 25 s:
    over every frame its root speed read 0.01 m/s, and a script walking it 51x the
    sources'."""
    from scipy.ndimage import uniform_filter1d

    ps = kin.pose_speed()
    every = np.ones(kin.n, dtype=bool)
    if ps.size < 2:
        return every
    avg = uniform_filter1d(ps, size=max(1, min(ps.size, int(round(kin.fps)))), mode="nearest")
    keep = avg >= MOVING_FRACTION * np.percentile(avg, 90)
    keep = np.r_[keep, keep[-1]]
    return keep if keep.sum() >= kin.fps else every


def _windows(mask: np.ndarray, n: int) -> np.ndarray:
    """``mask`` (T,) at the ``n`` windows of :meth:`_Kin.root_speed` (each flagged by its
    middle frame)."""
    k = mask.size - n
    return mask[k // 2 : k // 2 + n]


def _ranges(a: np.ndarray) -> np.ndarray:
    lo, hi = np.percentile(a, [1, 99], axis=0)
    return hi - lo


def _over(value: float, reference: float) -> float:
    """``value / reference`` for a pop figure: 0 when neither moves (sources that never
    move and a motion that does not either), infinite when only the motion does."""
    if reference > 0:
        return value / reference
    return 0.0 if value <= 0 else float("inf")


def _resampled(source: Motion, fps: float) -> Motion:
    k = int(round(source.fps / fps))
    if k > 1 and abs(source.fps / k - fps) < 0.05 * fps:
        return source.with_frames(source.frames[::k], fps=source.fps / k)
    return source


def _lowest(kin: _Kin, rig: _Rig) -> np.ndarray:
    """(T,) height of the lowest foot point (the end sites below them included)."""
    cols = list(rig.foot_cols) + [
        i for i, p in enumerate(kin.parents) if kin.names[i].endswith("/end") and p in rig.foot_cols
    ]
    return kin.pos[:, cols, 1].min(axis=1)


def leg_channels(motion: Motion, channels: Sequence) -> np.ndarray:
    """Which ``(joint, dof)`` channels turn a leg ``(C,)`` bool: the hip joint (the
    knee's parent) of each of the first two legs and every joint below it; none without
    a skeleton or legs."""
    out = np.zeros(len(channels), dtype=bool)
    try:
        rig = _rig(motion, None)
    except CycleCoordError:
        return out
    skel = motion.skeleton
    below: set[str] = set()
    todo = list(rig.hips)
    while todo:
        j = todo.pop()
        below.add(skel.names[j])
        todo.extend(skel.children(j))
    for i, ch in enumerate(channels):
        out[i] = ch[0] in below
    return out
