"""Curves for commands: blend weights rising smoothly, eased arc-length fractions, a
root's travel scaled by its pace, a particle's path settling back to a pose, and
polylines resampled at constant speed (used by :mod:`.commands`)."""

from __future__ import annotations

import numpy as np

__all__ = [
    "smootherstep", "smoothstep", "eased", "mix_rows", "paced_root", "resample", "settle",
]


def smootherstep(n: int) -> np.ndarray:
    """Quintic blend weights ``6u^5 - 15u^4 + 10u^3`` over ``n`` frames (ends excluded): zero
    velocity and acceleration at both ends, so a blend adds no jump in acceleration."""
    u = (np.arange(n) + 1.0) / (n + 1.0)
    return u * u * u * (u * (6.0 * u - 15.0) + 10.0)


def carried(n: int) -> np.ndarray:
    """How far a velocity of one unit a frame carries over ``n`` frames as it dies away
    (ends excluded, as :func:`smootherstep`): the quintic ``t - 6t^3 + 8t^4 - 3t^5`` in
    frames, slope 1 and no acceleration at the start, at rest at the end.  Added to
    ``(1 - smootherstep(n)) d``, an offset ``d`` that moved by ``r`` a frame keeps that
    rate at the first frame and reaches 0 at rest."""
    t = (np.arange(n) + 1.0) / (n + 1.0)
    return (t - 6.0 * t**3 + 8.0 * t**4 - 3.0 * t**5) * (n + 1.0)


def mix_rows(a: np.ndarray, b: np.ndarray, w: np.ndarray) -> np.ndarray:
    """``(1 - w) a + w b`` row by row: ``a`` and ``b`` ``(T, ...)``, ``w`` one weight per
    row (``(T,)`` or ``(T, 1)``)."""
    w = np.reshape(w, (-1,) + (1,) * (np.ndim(a) - 1))
    return (1.0 - w) * a + w * b


def smooth(u):
    """The smoothstep ``u^2 (3 - 2u)`` of ``u`` in [0, 1] (a number or an array)."""
    return u * u * (3.0 - 2.0 * u)


def smoothstep(n: int) -> np.ndarray:
    """Blend weights rising smoothly from 0 to 1 over ``n`` frames (ends excluded)."""
    return smooth((np.arange(n) + 1.0) / (n + 1.0))


def eased(n: int, ramp: int, ramp_out: int | None = None) -> np.ndarray:
    """Arc-length fractions ``(n + 1,)`` from 0 to 1: constant speed with a smooth start
    over ``ramp`` frames and a smooth stop over ``ramp_out`` (default ``ramp``; speed
    rising as a smoothstep; 0: none), so a MOVE does not jerk the particle into motion or
    stop it dead, and one MOVE of a chain flows into the next."""
    k = np.arange(n, dtype=float) + 0.5
    ramp_out = ramp if ramp_out is None else ramp_out
    r = max(1e-9, min(float(ramp), n / 2.0))
    r2 = max(1e-9, min(float(ramp_out), n / 2.0))
    rise = np.clip(k / r, 0, 1) if ramp > 0 else np.ones(n)
    fall = np.clip((n - k) / r2, 0, 1) if ramp_out > 0 else np.ones(n)
    v = np.minimum(smooth(rise), smooth(fall))
    c = np.concatenate([[0.0], np.cumsum(v)])
    return c / c[-1]


def paced_root(root: dict[str, np.ndarray], pace: np.ndarray) -> dict[str, np.ndarray]:
    """A latent root motion (``velocity`` ``(T, 2)``, ``turn`` ``(T,)``, ...) with its
    travel and turn scaled by ``pace`` ``(T,)`` (how fast its frames play the takes)."""
    return {**root, "velocity": root["velocity"] * pace[:, None], "turn": root["turn"] * pace}


def resample(points: np.ndarray, step: float) -> np.ndarray:
    """A polyline ``(M, q)`` resampled at constant arc length ``step``; ends kept."""
    seg = np.linalg.norm(np.diff(points, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    total = s[-1]
    if total <= 1e-12:
        return points[:1].copy()
    n = max(1, int(np.ceil(total / step)))
    u = np.linspace(0.0, total, n + 1)
    return np.stack([np.interp(u, s, points[:, k]) for k in range(points.shape[1])], axis=1)


def settle(
    X: np.ndarray, V: np.ndarray, target: np.ndarray, k: int, amount: float = 1.0
) -> tuple[np.ndarray, np.ndarray]:
    """Positions ``X`` and velocities ``V`` ``(T, q)`` eased ``amount`` of the way to
    ``target`` (a smoothstep) over their last ``k`` frames (at most half of them), the
    velocities as much towards 0."""
    k = min(int(k), X.shape[0] // 2)
    u = np.clip((np.arange(X.shape[0]) - (X.shape[0] - k)) / max(k - 1, 1), 0.0, 1.0)
    w = amount * smooth(u)[:, None]
    return X + w * (np.asarray(target, dtype=float) - X), V * (1.0 - w)
