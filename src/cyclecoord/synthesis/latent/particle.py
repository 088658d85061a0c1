"""A particle in a model's latent space (Bailey et al. Sec. 5.1).

The particle (unit mass) follows a path ``p(t)`` under three forces, integrated by RK4
with one step a frame (never across a frame, where the piecewise linear path bends):

* the path constraint ``||x - p(t)||^2 <= r^2`` by a Lagrange multiplier with Baumgarte
  stabilisation (Eq. 9-10, ``beta = alpha^2``), applied only when it pulls towards the
  path (``lambda <= 0``);
* the likelihood force (Eq. 11-12): a sigmoid of the GPLVM's density proxy along its
  normalised gradient, strong where the particle leaves the training data;
* a random force drawn from a GP in time with covariance
  ``sigma^2 exp(-(t - t')^2 / (2 tau^2))``, seeded (random Fourier features, so it can
  be evaluated at RK4's half steps and stays one smooth function over a whole script).

Two additions the paper leaves open, both documented parameters: a drag towards the
path's velocity (``damping``; without it the random force winds the velocity up), and
the constraint acts only outside half the radius (near the path's point ``g`` is tiny
and Eq. 9's ``1 / g^T g`` would make the force stiff).

The sign of ``G`` in Eq. 9 follows Baumgarte's ``C'' + 2 alpha C' + beta^2 C = 0`` for
``C = (||g||^2 - r^2) / 2``: ``lambda = -(g^T F + G) / g^T g``; with the printed sign a
particle at rest outside the circle would not be pulled back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ...errors import ParameterError

__all__ = ["ParticleParams", "RandomForce", "simulate"]


#: Largest value of any particle parameter (seconds, gains): the integration squares the
#: radius (an OverflowError at 1e300) and larger forces leave finite values at once.
MAX_PARAMETER = 1e6


@dataclass(frozen=True)
class ParticleParams:
    """Particle settings; lengths and accelerations are in units of the model's speed.

    ``speed`` is the median latent speed of the model's training frames (latent units per
    second), so the same numbers suit every model.

    Attributes
    ----------
    radius : float, default 0.15
        Path radius ``r`` as seconds of travel (``r = radius * speed``).
    alpha : float, default 12
        Baumgarte's ``alpha`` (1/s); ``beta = alpha^2``.
    damping : float, default 3
        Drag towards the path's velocity (1/s).
    likelihood : float, default 8
        ``a`` of Eq. 11 (acceleration ``a * speed``).
    threshold : float, default 0.6
        ``v`` of Eq. 11 on the density proxy in [0, 1] (``LatentModel.density``).
    width : float, default 0.05
        ``l`` of Eq. 11.
    random : float, default 2
        Standard deviation of each random force component (``random * speed``).
    timescale : float, default 0.4
        Seconds: ``tau`` of the random force's covariance (``gamma = tau^2``).
    smooth : float, default 1/30
        Seconds: width of the Gaussian that smooths the particle's path in time before it
        is posed (0: none). The path a MOVE ahead follows is the training frames' latent
        trajectory, which a GPLVM without dynamics leaves jagged, and the particle kept
        its frame-to-frame kinks: on the subject-35 walk model the knee accelerated 3.2x
        the training 99th percentile in one frame. One 30 fps frame of width takes the
        largest joint acceleration of the benchmark script from 2.40x to 1.16x the
        sources' 99th percentile (walk) and 2.53x to 1.46x (run) while the knee and hip
        ranges keep 0.93-0.97 of the training takes' (1.5 frames cut the run's knee to
        0.84).
    """

    radius: float = 0.15
    alpha: float = 12.0
    damping: float = 3.0
    likelihood: float = 8.0
    threshold: float = 0.6
    width: float = 0.05
    random: float = 2.0
    timescale: float = 0.4
    smooth: float = 1.0 / 30.0

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if (
                not isinstance(v, (int, float))
                or isinstance(v, bool)
                or not abs(v) <= MAX_PARAMETER  # NaN, an infinity, an int of any size
            ):
                raise ParameterError(
                    f"particle parameter {f.name} must be a number of at most "
                    f"{MAX_PARAMETER:g}, got {str(v)[:40]}"
                )
            if v < 0 or (f.name in ("width", "timescale", "alpha") and v == 0):
                raise ParameterError(f"particle parameter {f.name} must be positive, got {v!r}")

    def replace(self, **changes) -> ParticleParams:
        known = {f.name for f in fields(self)}
        unknown = sorted(set(changes) - known)
        if unknown:
            raise ParameterError(f"unknown particle parameter(s) {unknown}; known: {sorted(known)}")
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        values.update(changes)
        return ParticleParams(**values)


class RandomForce:
    """A seeded draw of a zero-mean GP over time, one independent component per dimension.

    Parameters
    ----------
    dims : int
    timescale : float
        Seconds (``tau``).
    n_features : int, default 64
        Random Fourier features.
    random_state : int, default 0
    """

    def __init__(
        self, dims: int, timescale: float, n_features: int = 64, random_state: int = 0
    ) -> None:
        rng = np.random.default_rng(random_state)
        self.omega = rng.normal(0.0, 1.0 / timescale, size=n_features)
        self.phase = rng.uniform(0.0, 2 * np.pi, size=n_features)
        self.weights = rng.normal(size=(n_features, dims)) * np.sqrt(2.0 / n_features)

    def __call__(self, t: float) -> np.ndarray:
        """Force of unit variance per component at time ``t`` (seconds), shape (dims,)."""
        return np.cos(self.omega * t + self.phase) @ self.weights


#: A step whose particle ends over ``ESCAPE`` path radii from the path, or moving off it
#: by more than that in a frame, is taken again in each of these numbers of parts until
#: it does not (the last is kept).  One seed in twenty of a ten-second Bandai run script threw the
#: particle off to 1e9 latent units in three frames (the pose leapt to the model's
#: mean: 15x the run's p99 of acceleration); otherwise the particle strays at most
#: 2.8 radii there, 1.5 on the benchmark scripts, whose steps are never taken again.
ESCAPE = 4.0
SUBSTEPS = (4, 16)


def _rk4(accel, x, v, p0, p1, pd, t, dt):
    """One classic Runge-Kutta step of the particle over ``dt`` along the path segment
    ``p0 -> p1`` (velocity ``pd``)."""
    pm = 0.5 * (p0 + p1)
    k1x, k1v = v, accel(x, v, p0, pd, t)
    k2x, k2v = v + 0.5 * dt * k1v, accel(x + 0.5 * dt * k1x, v + 0.5 * dt * k1v, pm, pd,
                                         t + 0.5 * dt)
    k3x, k3v = v + 0.5 * dt * k2v, accel(x + 0.5 * dt * k2x, v + 0.5 * dt * k2v, pm, pd,
                                         t + 0.5 * dt)
    k4x, k4v = v + dt * k3v, accel(x + dt * k3x, v + dt * k3v, p1, pd, t + dt)
    return (x + dt / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x),
            v + dt / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v))


def simulate(
    model,
    path: np.ndarray,
    x0: np.ndarray,
    v0: np.ndarray,
    fps: float,
    params: ParticleParams,
    force: RandomForce | None,
    t0: float = 0.0,
    ride: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Move the particle along ``path``, one RK4 step a frame.

    Parameters
    ----------
    model : LatentModel
    path : ndarray, shape (T + 1, q)
        ``p(t)`` at frame times ``t0 + k / fps``, linear in between.
    x0, v0 : ndarray, shape (q,)
        Position and velocity at ``t0``.
    fps : float
    params : ParticleParams
    force : RandomForce or None
    t0 : float
        Time of ``path[0]`` in seconds (keeps the random force continuous across commands).
    ride : bool, default False
        The particle rides the path: each change of the path's velocity at a vertex is
        added to the particle's, so the forces act on its motion relative to the path.
        Without it a particle behind a fast, curving path (a run's latent loop, a cycle
        in 0.7 s) cut its corners and bounced off the radius: on the synthetic run the
        joints accelerated up to 3.3x the training 99th percentile (4.9x without the
        random and likelihood forces), 1.2x riding.

    Returns
    -------
    X, V : ndarray, shape (T, q)
        Position and velocity at the end of each frame.
    """
    path = np.asarray(path, dtype=float)
    dt = 1.0 / fps
    speed = model.speed_
    r2 = (params.radius * speed) ** 2
    half = 0.25 * r2
    al = params.alpha
    be = al * al
    a_lik = params.likelihood * speed
    a_rand = params.random * speed
    x, v = np.array(x0, dtype=float), np.array(v0, dtype=float)
    T = path.shape[0] - 1
    X = np.empty((T, x.size))
    V = np.empty((T, x.size))

    def accel(xx, vv, pp, pd, t):
        F = -params.damping * (vv - pd)
        if a_lik > 0:
            p, grad = model.density(xx)
            gn = math.sqrt(grad @ grad)
            if gn > 1e-12:
                z = min(50.0, max(-50.0, (p - params.threshold) / params.width))
                F = F + (a_lik / (1.0 + math.exp(z)) / gn) * grad
        if force is not None and a_rand > 0:
            F = F + a_rand * force(t)
        g = xx - pp
        gg = g @ g
        if gg > half:
            gd = vv - pd
            lam = -(g @ F + gd @ gd + 2.0 * al * (g @ gd) + 0.5 * be * (gg - r2)) / gg
            if lam < 0:
                F = F + lam * g
        return F

    before = None
    # a diverging integration overflows before it is refused below (one line, no warnings)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        for k in range(T):
            p0, p1 = path[k], path[k + 1]
            pd = (p1 - p0) * fps
            if ride and before is not None:
                v = v + (pd - before)
            before = pd
            t = t0 + k * dt
            x1, v1 = _rk4(accel, x, v, p0, p1, pd, t, dt)
            for n in SUBSTEPS:
                # a step that throws the particle far out is stiff (a fast particle held
                # at a small radius): taken again in parts
                s1 = max(float(np.linalg.norm(x1 - p1)), float(np.linalg.norm(v1 - pd)) * dt)
                if s1 <= ESCAPE * math.sqrt(r2):
                    break
                x1, v1 = x, v
                for j in range(n):
                    a, b = p0 + (p1 - p0) * (j / n), p0 + (p1 - p0) * ((j + 1) / n)
                    x1, v1 = _rk4(accel, x1, v1, a, b, pd, t + j * dt / n, dt / n)
            x, v = x1, v1
            if not (math.isfinite(float(x @ x)) and math.isfinite(float(v @ v))):
                # the integration diverged: every later frame would be NaN, and slow to make
                raise ParameterError(
                    f"the particle left finite values at frame {k + 1} of {T} (time step "
                    f"{dt:.3g} s, random force {params.random:g}): a higher frame rate or a "
                    "smaller random force keeps it stable"
                )
            X[k], V[k] = x, v
    return X, V
