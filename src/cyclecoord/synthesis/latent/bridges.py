"""Bridges between two latent models (Bailey et al. Sec. 5.2, Eq. 13-15).

For each training latent point ``x1`` of model 1, its pose ``z1 = g(x1; M1)`` is taken
into model 2's PCA space (Eq. 13) and the latent point ``x2`` of model 2 whose GP mean
comes closest to it is searched (Eq. 15) from several starts: the model-2 training
points nearest ``z1`` in PCA space plus one drawn at random.  The search is a batched
gradient descent with small, capped steps (the paper warns that the gradient vanishes
away from the training points, so large steps get lost).  Pairs whose poses lie closer
than a threshold (RMS distance of the joints' positions, root fixed) and whose point in
model 2 lies near its training points (density proxy >= ``min_density``, default 0.1;
training points have about 0.8) are bridges.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from .gplvm import sqdist
from .influence import pose_points

__all__ = [
    "DEFAULT_THRESHOLD",
    "Bridges",
    "find_bridges",
    "invert",
    "pose_distance",
    "project",
]

#: Default bridge threshold: RMS joint distance as a fraction of the skeleton's total
#: bone length (about 1.4 units, 8 cm, on a CMU skeleton).
DEFAULT_THRESHOLD = 0.015


def check_compatible(m1, m2, what: str = "") -> None:
    """Two models can be bridged only over the same joint-angle channels."""
    if tuple(m1.channels_) != tuple(m2.channels_):
        diff = sorted(set(m1.channels_) ^ set(m2.channels_))[:3]
        raise ParameterError(
            f"{what}models of different skeletons: their joint-angle channels differ"
            + (f" (e.g. {diff})" if diff else " (order differs)")
        )


def pose_distance(skeleton, channels, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """RMS distance of the joints' positions between poses ``a`` and ``b`` ``(T, C)``."""
    pa = pose_points(a, channels, skeleton)
    pb = pose_points(b, channels, skeleton)
    return np.sqrt(((pa - pb) ** 2).sum(axis=2).mean(axis=1))


def project(
    model,
    Y: np.ndarray,
    n_starts: int = 3,
    n_iter: int = 80,
    max_step: float = 0.1,
    random_state: int = 0,
    every_start: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Latent points whose GP mean is nearest ``Y`` (Eq. 15), by multi-start descent.

    Parameters
    ----------
    model : LatentModel
    Y : ndarray, shape (B, d_pca)
        Targets in the model's PCA space.
    n_starts : int
        Starts per target: the ``n_starts - 1`` nearest training points in PCA space and
        one random training point.
    n_iter : int
        Descent iterations.
    max_step : float
        Longest step, as a fraction of the kernel's length scale.
    random_state : int
    every_start : bool
        Return the end of every start, ``(B, S, q)`` and ``(B, S)``, not only the best.

    Returns
    -------
    X : ndarray, shape (B, q)
    cost : ndarray, shape (B,)
        ``||y - mean(x)||^2``.
    """
    rng = np.random.default_rng(random_state)
    Y = np.atleast_2d(np.asarray(Y, dtype=float))
    B = Y.shape[0]
    N = model.X_.shape[0]
    k_near = max(1, min(n_starts - 1, N))
    near = np.argsort(sqdist(Y, model.Y_), axis=1)[:, :k_near]
    starts = np.concatenate([near, rng.integers(0, N, size=(B, 1))], axis=1)
    X, f = _descend(model, Y, model.gp_.alpha_, starts, n_iter, max_step)
    if every_start:
        return X, f
    best = np.argmin(f, axis=1)
    return X[np.arange(B), best], f[np.arange(B), best]


def invert(
    model, angles: np.ndarray, n_starts: int = 8, n_iter: int = 200, max_step: float = 0.1
) -> tuple[np.ndarray, np.ndarray]:
    """Latent points whose pose (Eq. 8's mean) is nearest joint angles, least squares.

    The inverse mapping of frames the model has not seen: :func:`project` measures in
    the model's influence-scaled PCA space (Eq. 15, what bridges compare), this in the
    joint angles themselves, as PCA's own projection does, so the two reconstructions
    are compared on the same footing.  Starts: the training frames whose angles are
    nearest.

    Parameters
    ----------
    model : LatentModel
    angles : ndarray, shape (B, C)
        Modelled joint-angle channels, degrees.
    n_starts, n_iter, max_step
        As :func:`project`.

    Returns
    -------
    X : ndarray, shape (B, q)
    cost : ndarray, shape (B,)
        ``||angles - pose(x)||^2``, degrees squared.
    """
    A = np.atleast_2d(np.asarray(angles, dtype=float))
    if A.shape[1] != len(model.channels_):
        raise ParameterError(
            f"angles have {A.shape[1]} channels, the model {len(model.channels_)}"
        )
    train = model.angles(model.frames_)
    k = max(1, min(int(n_starts), train.shape[0]))
    starts = np.argsort(sqdist(A, train), axis=1)[:, :k]
    X, f = _descend(model, A - model.mean_, model._B, starts, n_iter, max_step)
    best = np.argmin(f, axis=1)
    B = A.shape[0]
    return X[np.arange(B), best], f[np.arange(B), best]


def _descend(model, Y, A, starts, n_iter, max_step):
    """Minimise ``||y - k(x) A||^2`` from training points ``starts`` (B, S) by a batched
    descent with capped steps; the ends ``(B, S, q)`` and their costs ``(B, S)``."""
    B, S = starts.shape
    Yr = np.repeat(Y, S, axis=0)
    X = model.X_[starts.reshape(-1)].copy()
    l2 = model.gp_.lengthscale_**2
    cap = max_step * model.gp_.lengthscale_

    def cost_grad(x):
        K = model.kernel(x)
        R = Yr - K @ A
        f = (R * R).sum(1)
        u = (R @ A.T) * K
        g = (2.0 / l2) * (u.sum(1)[:, None] * x - u @ model.X_)
        return f, g

    f, g = cost_grad(X)
    eta = np.full(X.shape[0], cap / max(np.median(np.linalg.norm(g, axis=1)), 1e-12))
    for _ in range(n_iter):
        step = -eta[:, None] * g
        norm = np.linalg.norm(step, axis=1)
        step *= np.minimum(1.0, cap / np.maximum(norm, 1e-300))[:, None]
        fn, gn = cost_grad(X + step)
        ok = fn < f
        X[ok] += step[ok]
        f[ok], g[ok] = fn[ok], gn[ok]
        eta = np.where(ok, eta * 1.3, eta * 0.5)
    return X.reshape(B, S, -1), f.reshape(B, S)


@dataclass(frozen=True)
class Bridges:
    """Matching points from one model into another.

    Attributes
    ----------
    source, target : str
        Model names.
    frames : ndarray of int, shape (B,)
        Training frames of the source model that start a bridge.
    source_points, target_points : ndarray, shape (B, q)
    distances : ndarray, shape (B,)
        RMS joint distance of the two reconstructed poses, skeleton units.
    best : ndarray, shape (N1,)
        Best distance found from every source training frame (bridges are those under
        ``threshold``).
    threshold : float
        Skeleton units.
    best_raw : ndarray, shape (N1,), optional
        Best distance from every source frame before the density filter.
    best_points, raw_points : ndarray, shape (N1, q), optional
        The model-2 point of ``best`` (NaN where no start passed the density filter)
        and of ``best_raw``, so the closest pair can be used when no bridge is under
        the threshold.
    """

    source: str
    target: str
    frames: np.ndarray
    source_points: np.ndarray
    target_points: np.ndarray
    distances: np.ndarray
    best: np.ndarray
    threshold: float
    best_raw: np.ndarray | None = None
    best_points: np.ndarray | None = None
    raw_points: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.frames.size)

    def nearest(self, x: np.ndarray) -> int:
        """Index of the bridge whose source point is nearest latent point ``x``."""
        if not len(self):
            raise ParameterError(f"no bridges from {self.source!r} to {self.target!r}")
        return int(np.argmin(((self.source_points - x) ** 2).sum(1)))

    def to_dict(self) -> dict:
        return {
            "source": self.source,
            "target": self.target,
            "count": len(self),
            "threshold": self.threshold,
            "frames": self.frames.tolist(),
            "median_distance": float(np.median(self.distances)) if len(self) else None,
        }


def find_bridges(
    m1,
    m2,
    names: tuple[str, str] = ("model1", "model2"),
    threshold: float | None = None,
    n_starts: int = 3,
    random_state: int = 0,
    min_density: float = 0.1,
) -> Bridges:
    """Bridges from every training latent point of ``m1`` into ``m2`` (Eq. 13-15).

    Parameters
    ----------
    m1, m2 : LatentModel
        Same joint-angle channels (bone lengths may differ: poses are compared on
        ``m1``'s skeleton).
    names : (str, str)
    threshold : float, optional
        RMS joint distance in skeleton units; default :data:`DEFAULT_THRESHOLD` of
        ``m1``'s total bone length.
    n_starts : int
    random_state : int
    min_density : float, default 0.1
        A target point must have at least this density proxy in ``m2``
        (:meth:`~.model.LatentModel.density`): far from the training points the GP mean
        decays to the mean pose, which can match a pose of ``m1`` without being a pose
        ``m2`` ever makes.
    """
    check_compatible(m1, m2, f"bridging {names[0]!r} to {names[1]!r}: ")
    if threshold is None:
        threshold = DEFAULT_THRESHOLD * m1.skeleton_.total_length()
    pose1 = m1.to_channels(m1.pose(m1.X_))  # the rig's channels: each model has its chart
    n1 = pose1.shape[0]
    XS, _ = project(
        m2,
        m2.pca_coordinates(m2.to_model(pose1)),
        n_starts=n_starts,
        random_state=random_state,
        every_start=True,
    )
    # Eq. 15 measures in model 2's PCA space, blind to what model 1's pose does outside
    # it: of every start's optimum, keep the one whose pose is really nearest
    S = XS.shape[1]
    flat = XS.reshape(n1 * S, -1)
    d_all = pose_distance(
        m1.skeleton_, m1.channels_, np.repeat(pose1, S, axis=0), m2.to_channels(m2.pose(flat))
    ).reshape(n1, S)
    raw = d_all.min(axis=1)
    raw_points = XS[np.arange(n1), np.argmin(d_all, axis=1)]
    d_all[(m2.densities(flat) < min_density).reshape(n1, S)] = np.inf
    pick = np.argmin(d_all, axis=1)
    X2 = XS[np.arange(n1), pick]
    dist = d_all[np.arange(n1), pick]
    keep = np.flatnonzero(dist < threshold)
    return Bridges(
        source=names[0],
        target=names[1],
        frames=keep,
        source_points=m1.X_[keep].copy(),
        target_points=X2[keep],
        distances=dist[keep],
        best=dist,
        threshold=float(threshold),
        best_raw=raw,
        best_points=np.where(np.isfinite(dist)[:, None], X2, np.nan),
        raw_points=raw_points,
    )
