"""The GPLVM of Bailey et al. (Eq. 4-7): RBF + white kernel, dynamics and connectivity priors.

The negative log posterior of latent points ``X`` (N, q) and kernel hyperparameters
given data ``Y`` (N, d) is::

    D/2 log|K| + 1/2 tr(K^-1 Y Y^T)                      (Eq. 4, RBF + white kernel, Eq. 5)
  + 1/2 tr(X^T K_t^-1 X)                                 (dynamics prior, Eq. 6)
  - c N / M^2 sum_ij log [exp(beta H)]_ij                (connectivity prior, Levine et al. 2012)
  + log sigma_rbf^2 + log l^2 + log sigma_white^2        (1/theta hyperpriors)

``K_t`` is block diagonal: an RBF over time per training segment with fixed
hyperparameters (Lawrence 2007), zero between segments.  ``H = T^-1/2 W T^-1/2 - I`` is
the negated normalised Laplacian of the complete graph with weights
``W_ij = (||x_i - x_j||^2 + eps)^(-p/2)``, ``p = 4``, so the diffusion kernel
``exp(beta H)`` is small between poorly connected points and the prior pulls similar
frames of different segments together.  It is evaluated on at most
``connectivity_points`` points spread over the training frames (an eigendecomposition
each evaluation; the likelihood and the dynamics use every point).

Everything has an analytic gradient (checked against finite differences in the tests)
and the MAP estimate is found by L-BFGS-B, initialised from PCA.  No library offers
this combination of priors (GPy has no GPDM and is barely maintained), so it is written
here with NumPy and SciPy.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import linalg, optimize
from scipy.linalg import blas, lapack

from ..._blas import one_blas_thread
from ...errors import ParameterError

__all__ = ["GPLVM", "ObjectiveSettings", "dynamics_precision", "objective", "rbf", "sqdist"]


def sqdist(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Squared Euclidean distances ``(len(a), len(b))``, never negative."""
    d = (a * a).sum(1)[:, None] + (b * b).sum(1)[None, :] - 2.0 * a @ b.T
    return np.maximum(d, 0.0)


def rbf(a: np.ndarray, b: np.ndarray, variance: float, lengthscale2: float) -> np.ndarray:
    """RBF kernel ``variance * exp(-||a - b||^2 / (2 l^2))`` (Eq. 5 without the white term)."""
    return variance * np.exp(-0.5 * sqdist(a, b) / lengthscale2)


def dynamics_precision(
    segments: np.ndarray, times: np.ndarray, lengthscale: float, noise: float
) -> np.ndarray:
    """Inverse of the block-diagonal time kernel ``K_t`` of the dynamics prior (Eq. 6).

    Parameters
    ----------
    segments : ndarray of int, shape (N,)
        Segment of each training frame.
    times : ndarray, shape (N,)
        Time of each frame in seconds within its segment.
    lengthscale : float
        RBF length scale over time, seconds.
    noise : float
        White variance added to each block (the RBF block alone is near singular).

    Returns
    -------
    ndarray, shape (N, N)
    """
    n = segments.shape[0]
    prec = np.zeros((n, n))
    for s in np.unique(segments):
        idx = np.flatnonzero(segments == s)
        t = times[idx][:, None]
        k = np.exp(-0.5 * (t - t.T) ** 2 / lengthscale**2) + noise * np.eye(idx.size)
        prec[np.ix_(idx, idx)] = linalg.cho_solve(linalg.cho_factor(k), np.eye(idx.size))
    return prec


@dataclass(frozen=True)
class ObjectiveSettings:
    """Fixed parts of the objective: data, priors and where connectivity is evaluated."""

    Y: np.ndarray
    dyn_precision: np.ndarray
    conn_index: np.ndarray
    conn_weight: float
    conn_beta: float
    conn_power: float
    conn_eps: float


def _inverse(K: np.ndarray) -> tuple[np.ndarray | None, float]:
    """``K^-1`` and ``log|K|`` of a positive definite matrix by Cholesky (LAPACK potrf/potri)."""
    c, info = lapack.dpotrf(K, lower=1, clean=1)
    if info != 0:
        return None, np.inf
    logdet = 2.0 * np.log(np.diag(c)).sum()
    inv, info = lapack.dpotri(c, lower=1)
    if info != 0:
        return None, np.inf
    inv = np.tril(inv) + np.tril(inv, -1).T
    return inv, float(logdet)


def _likelihood(X, Y, s, l2, w):
    n, d = Y.shape
    r2 = sqdist(X, X)
    krbf = s * np.exp(-0.5 * r2 / l2)
    K = krbf + w * np.eye(n)
    kinv, logdet = _inverse(K)
    if kinv is None:
        return np.inf, None, None
    alpha = kinv @ Y
    f = 0.5 * d * logdet + 0.5 * (Y * alpha).sum()
    G = 0.5 * (d * kinv - alpha @ alpha.T)  # dF/dK
    M = G * krbf
    gX = -2.0 / l2 * (M.sum(1)[:, None] * X - M @ X)
    g_hyp = np.array([M.sum(), (M * r2).sum() / (2.0 * l2), w * np.trace(G)])
    return f, gX, g_hyp


def _connectivity(Xs, weight, beta, power, eps):
    m = Xs.shape[0]
    r2 = sqdist(Xs, Xs)
    base = r2 + eps
    W = base ** (-power / 2.0)
    np.fill_diagonal(W, 0.0)
    deg = W.sum(1)
    a = deg**-0.5
    H = a[:, None] * W * a[None, :] - np.eye(m)
    lam, V = linalg.eigh(H, check_finite=False, driver="evd")
    E = np.exp(beta * lam)
    Kd = (V * E) @ V.T
    Kd = np.maximum(Kd, 1e-300)
    f = -weight * np.log(Kd).sum()
    G = -weight / Kd
    dl = lam[:, None] - lam[None, :]
    same = np.abs(dl) < 1e-10
    phi = np.where(same, beta * E[:, None], (E[:, None] - E[None, :]) / np.where(same, 1.0, dl))
    S = V @ (phi * (V.T @ G @ V)) @ V.T
    S = 0.5 * (S + S.T)
    dfa = 2.0 * (S * W) @ a
    c = dfa * (-0.5) * deg**-1.5
    Gw = S * a[:, None] * a[None, :] + c[:, None]
    np.fill_diagonal(Gw, 0.0)
    fprime = -(power / 2.0) * base ** (-power / 2.0 - 1.0)
    np.fill_diagonal(fprime, 0.0)
    M = (Gw + Gw.T) * fprime
    gX = 2.0 * (M.sum(1)[:, None] * Xs - M @ Xs)
    return f, gX


def objective(theta: np.ndarray, st: ObjectiveSettings, q: int) -> tuple[float, np.ndarray]:
    """Negative log posterior and its gradient.

    Parameters
    ----------
    theta : ndarray
        ``X.ravel()`` (N q values) then log sigma_rbf^2, log l^2, log sigma_white^2.
    st : ObjectiveSettings
    q : int
        Latent dimension.
    """
    n = st.Y.shape[0]
    X = theta[: n * q].reshape(n, q)
    ls, ll, lw = theta[n * q :]
    s, l2, w = np.exp(ls), np.exp(ll), np.exp(lw)
    f, gX, gh = _likelihood(X, st.Y, s, l2, w)
    if gX is None:
        return 1e300, np.zeros_like(theta)
    # hyperpriors p(theta) ~ 1/theta: + log theta each, gradient 1 in log space
    f += ls + ll + lw
    gh = gh + 1.0
    PX = st.dyn_precision @ X
    f += 0.5 * (X * PX).sum()
    gX = gX + PX
    if st.conn_weight > 0 and st.conn_index.size > 2:
        idx = st.conn_index
        fc, gc = _connectivity(X[idx], st.conn_weight, st.conn_beta, st.conn_power, st.conn_eps)
        f += fc
        np.add.at(gX, idx, gc)
    return float(f), np.concatenate([gX.ravel(), gh])


class GPLVM:
    """MAP GPLVM with dynamics and connectivity priors.

    Parameters
    ----------
    n_components : int, default 3
        Latent dimension ``q``.
    dynamics_lengthscale : float, default 0.2
        Time length scale of the dynamics prior, seconds (fixed, not optimised).
    dynamics_noise : float, default 0.01
        White variance of the dynamics prior's blocks.
    connectivity_weight : float, default 1.0
        ``c`` in the connectivity term (0 turns it off).
    connectivity_beta : float, default 2.0
        Diffusion time ``beta`` of the graph kernel.
    connectivity_power : float, default 4.0
        ``p`` in ``W_ij = ||x_i - x_j||^-p``.
    connectivity_points : int, default 100
        At most this many points (evenly spread) enter the connectivity prior.
    max_iter : int, default 200
        L-BFGS-B iterations.
    random_state : int, default 0
        Unused by the optimiser (deterministic); kept for the estimator convention.

    Attributes
    ----------
    X_ : ndarray, shape (N, q)
        Latent points.
    variance_, lengthscale_, noise_ : float
        sigma_rbf^2, l (not squared) and sigma_white^2.
    kinv_ : ndarray, shape (N, N)
        ``K^-1``.
    alpha_ : ndarray, shape (N, d)
        ``K^-1 Y`` (the predictive mean is ``k(x)^T alpha_``, Eq. 8).
    objective_ : float
        Final negative log posterior.
    n_iter_ : int
    """

    def __init__(
        self,
        n_components: int = 3,
        dynamics_lengthscale: float = 0.2,
        dynamics_noise: float = 0.01,
        connectivity_weight: float = 1.0,
        connectivity_beta: float = 2.0,
        connectivity_power: float = 4.0,
        connectivity_points: int = 100,
        max_iter: int = 200,
        random_state: int = 0,
    ) -> None:
        self.n_components = n_components
        self.dynamics_lengthscale = dynamics_lengthscale
        self.dynamics_noise = dynamics_noise
        self.connectivity_weight = connectivity_weight
        self.connectivity_beta = connectivity_beta
        self.connectivity_power = connectivity_power
        self.connectivity_points = connectivity_points
        self.max_iter = max_iter
        self.random_state = random_state

    def settings(
        self, Y: np.ndarray, segments: np.ndarray, times: np.ndarray, X0: np.ndarray
    ) -> ObjectiveSettings:
        """The fixed parts of the objective for data ``Y`` (also used by the tests)."""
        n = Y.shape[0]
        m = min(n, int(self.connectivity_points))
        idx = np.unique(np.round(np.linspace(0, n - 1, m)).astype(int))
        nn = np.sqrt(sqdist(X0, X0) + np.diag(np.full(n, np.inf))).min(1)
        eps = float(max(np.median(nn), 1e-6) ** 2)
        return ObjectiveSettings(
            Y=Y,
            dyn_precision=dynamics_precision(
                segments, times, self.dynamics_lengthscale, self.dynamics_noise
            ),
            conn_index=idx,
            conn_weight=float(self.connectivity_weight) * n / idx.size**2,
            conn_beta=float(self.connectivity_beta),
            conn_power=float(self.connectivity_power),
            conn_eps=eps,
        )

    @one_blas_thread
    def fit(
        self, Y: np.ndarray, segments: Sequence[int], times: Sequence[float], *,
        progress: bool = False,
    ) -> GPLVM:
        """Fit to ``Y`` (N, d), centred PCA coordinates, with each frame's segment and time (s).

        ``progress`` shows a tqdm bar on stderr over the optimiser's iterations (at most
        ``max_iter``; shown after 1 s).
        """
        Y = np.asarray(Y, dtype=float)
        seg = np.asarray(segments, dtype=int)
        t = np.asarray(times, dtype=float)
        n, d = Y.shape
        q = int(self.n_components)
        if q < 1 or q > d:
            raise ParameterError(
                f"latent dimension {q} must be between 1 and the {d} PCA components"
            )
        if n < q + 2:
            raise ParameterError(f"a GPLVM needs more than {q + 1} training frames, got {n}")
        if seg.shape != (n,) or t.shape != (n,):
            raise ParameterError("segments and times need one value per training frame")
        X0 = Y[:, :q] / max(Y[:, 0].std(), 1e-12)
        st = self.settings(Y, seg, t, X0)
        s0 = float(Y.var(axis=0).mean())
        if not np.isfinite(s0) or s0 <= 0:
            raise ParameterError(f"the training frames' variance is {s0:g}; a GPLVM needs motion")
        theta0 = np.concatenate([X0.ravel(), np.log([s0, 1.0, 0.05 * s0])])
        bounds = [(None, None)] * (n * q) + [
            (np.log(s0) - 10, np.log(s0) + 5),
            (np.log(1e-3), np.log(1e3)),
            (np.log(1e-4 * s0), np.log(s0)),
        ]
        from tqdm import tqdm

        with tqdm(total=int(self.max_iter), desc="fitting the GPLVM", unit="iteration",
                  disable=not progress, delay=1.0, leave=False) as bar:
            res = optimize.minimize(
                objective,
                theta0,
                args=(st, q),
                jac=True,
                method="L-BFGS-B",
                bounds=bounds,
                options={"maxiter": int(self.max_iter)},
                callback=lambda *_: bar.update(1),
            )
        theta = res.x
        self.X_ = theta[: n * q].reshape(n, q).copy()
        s, l2, w = np.exp(theta[n * q :])
        self.variance_, self.lengthscale_, self.noise_ = float(s), float(np.sqrt(l2)), float(w)
        self.objective_ = float(res.fun)
        self.n_iter_ = int(res.nit)
        self._finish(Y)
        return self

    def _finish(self, Y: np.ndarray) -> None:
        K = rbf(self.X_, self.X_, self.variance_, self.lengthscale_**2) + self.noise_ * np.eye(
            len(Y)
        )
        kinv, _ = _inverse(K)
        if kinv is None:
            raise ParameterError("the fitted kernel matrix is not positive definite")
        self.kinv_ = kinv
        self.alpha_ = self.kinv_ @ Y

    def kinv_times(self, k: np.ndarray) -> np.ndarray:
        """``K^-1 @ k`` for one vector ``k`` (N,): a symmetric product (BLAS ``dsymv``)
        reads half the matrix, a third faster than ``@`` at the particle's thousand
        calls a script (the same to 1e-10 of the result's size)."""
        # K^-1 is symmetric: its C-ordered array read as Fortran order is itself
        return blas.dsymv(1.0, self.kinv_.T, k, lower=1)

    @classmethod
    def from_arrays(cls, X, variance, lengthscale, noise, Y) -> GPLVM:
        """A fitted model from stored values (``K^-1`` is recomputed)."""
        g = cls(n_components=np.asarray(X).shape[1])
        g.X_ = np.asarray(X, dtype=float)
        g.variance_, g.lengthscale_, g.noise_ = float(variance), float(lengthscale), float(noise)
        g.objective_, g.n_iter_ = float("nan"), 0
        g._finish(np.asarray(Y, dtype=float))
        return g
