"""Periodic density of circular coordinates: a wrapped Gaussian mixture (paper §5.2).

A circular coordinate does not advance at an even rate: a gait lingers in some poses and
hurries through others, so the histogram of the coordinate values is proportional to the
*time* the motion spends at each phase.  :class:`PeriodicDensity` estimates that density
as the paper does -- a one-dimensional Gaussian mixture (scikit-learn) fitted to three
tiled copies ``theta - 1, theta, theta + 1`` of the coordinates -- and then turns the fit
into an exactly periodic density on the circle ``[0, 1)``.

Wrapping instead of "use the middle copy"
-----------------------------------------
The paper fits the three copies and samples from the middle part ``[0, 1)`` of the
mixture.  That middle part is only *close* to periodic (the tails of the outer copies
leak in unevenly, so the density has a small step at 0 = 1) and it has mass of about
1/3, so it must be renormalised.  Here the mixture density ``f`` on the real line is
*wrapped* onto the circle instead::

    p(x) = sum over integers s of f(x + s),   x in [0, 1).

``p`` is exactly periodic (no seam at 0 = 1), integrates to exactly 1 over ``[0, 1)``
(because ``f`` integrates to 1 over the real line) and averages the three copies' fits
rather than trusting one of them.  Where the fit is good the two agree: each copy then
carries a third of the mass and the middle copy times three equals the wrapped sum.  Only
the shifts that matter are summed (a component contributes where it is within eight
standard deviations), so the evaluation is exact to double precision.

Sampling is exact too: a component is drawn by weight, a normal value from it, and the
result is taken modulo 1.
"""

from __future__ import annotations

from numbers import Integral, Real

import numpy as np
from scipy.special import ndtr

from ..errors import ParameterError
from ._estimator import ParamsMixin

__all__ = ["PeriodicDensity", "as_generator"]

#: Grid size used to tabulate the cdf for :meth:`PeriodicDensity.ppf`.
_PPF_GRID = 4096
#: Components are summed over the integer shifts that bring them within this many
#: standard deviations of [0, 1).
_TAIL_SIGMAS = 8.0
_INV_SQRT_2PI = 1.0 / np.sqrt(2.0 * np.pi)


def as_generator(random_state: None | int | np.random.Generator) -> np.random.Generator:
    """A numpy Generator from ``None``, an integer seed or a Generator."""
    if isinstance(random_state, np.random.Generator):
        return random_state
    if random_state is None or isinstance(random_state, Integral):
        if random_state is not None and int(random_state) < 0:
            raise ParameterError(f"random_state must be a non-negative integer, got {random_state}")
        return np.random.default_rng(random_state)
    raise ParameterError(
        "random_state must be None, an integer or a numpy Generator, got "
        f"{type(random_state).__name__}"
    )


def _consume_seed(random_state: None | int | np.random.Generator) -> None:
    """Validate ``random_state``; a Generator advances by one draw, as it did when it
    seeded scikit-learn's k-means start, so what is drawn from it next is unchanged."""
    if isinstance(random_state, np.random.Generator):
        random_state.integers(0, 2**31 - 1)
    elif random_state is not None:
        as_generator(random_state)  # validates


def _em_1d(x: np.ndarray, n_components: int, max_iter: int, reg_covar: float, tol: float = 3e-4):
    """Gaussian mixture on the line by EM, started from a deterministic k-means of ``x``.

    The EM steps are scikit-learn's ``GaussianMixture`` (diagonal covariances, ``reg_covar``
    added to every variance; stop when the mean log-likelihood changes by less than
    ``tol``, 3e-4 where scikit-learn stops at 1e-3: a few more steps, and on the test
    densities a closer fit than scikit-learn's), and so is the start (responsibilities
    of a k-means partition); only the k-means is deterministic: Lloyd's steps from
    ``n_components`` runs of equal size of the sorted values (in 1-D every k-means cluster
    is such a run, so a step costs ``n_components`` binary searches).  Returns weights,
    means, variances, whether EM converged and the iterations run.
    """
    x = np.sort(np.asarray(x, dtype=float))
    n, k = x.size, int(n_components)
    eps = 10 * np.finfo(float).eps
    csum = np.concatenate([[0.0], np.cumsum(x)])
    csq = np.concatenate([[0.0], np.cumsum(x * x)])
    # k-means (Lloyd) from equal-count runs: in 1-D each cluster is a run of the sorted
    # values between midpoints of the means, so a step is k binary searches
    bounds = np.round(np.linspace(0, n, k + 1)).astype(int)
    for _ in range(300):
        cnt = np.diff(bounds)
        means = (csum[bounds[1:]] - csum[bounds[:-1]]) / np.maximum(cnt, 1)
        means = np.where(cnt > 0, means, x[np.minimum(bounds[:-1], n - 1)])
        new = np.concatenate(
            [[0], np.searchsorted(x, 0.5 * (means[:-1] + means[1:]), side="right"), [n]]
        )
        new = np.maximum.accumulate(new)
        if np.array_equal(new, bounds):
            break
        bounds = new
    counts = np.diff(bounds).astype(float) + eps
    sums = csum[bounds[1:]] - csum[bounds[:-1]]
    sq = csq[bounds[1:]] - csq[bounds[:-1]]
    means = sums / counts
    var = sq / counts - 2 * means * sums / counts + means**2 + reg_covar
    weights = counts / n
    lower, converged, it = -np.inf, False, 0
    half_log_2pi = 0.5 * np.log(2 * np.pi)
    for it in range(1, int(max_iter) + 1):
        prev = lower
        # E step: log N(x | mean, var) + log weight, normalised over components
        logp = -0.5 * (x[:, None] - means[None, :]) ** 2 / var[None, :]
        logp += np.log(weights) - 0.5 * np.log(var) - half_log_2pi
        top = logp.max(axis=1, keepdims=True)
        np.exp(logp - top, out=logp)
        tot = logp.sum(axis=1, keepdims=True)
        lower = float(np.mean(np.log(tot[:, 0]) + top[:, 0]))
        resp = np.divide(logp, tot, out=logp)
        # M step
        nk = resp.sum(axis=0) + eps
        rx = x @ resp
        means = rx / nk
        var = (x * x) @ resp / nk - 2 * means * rx / nk + means**2 + reg_covar
        weights = nk / n
        if abs(lower - prev) < tol:
            converged = True
            break
    return weights / weights.sum(), means, var, converged, it


class PeriodicDensity(ParamsMixin):
    """Density of circular coordinates on ``[0, 1)``, fitted as a wrapped Gaussian mixture.

    A scikit-learn style estimator (``get_params``/``set_params`` and ``repr`` from
    :class:`~cyclecoord.periodic._estimator.ParamsMixin`, so :func:`sklearn.base.clone`
    works): parameters are stored untouched by ``__init__`` and checked by :meth:`fit`;
    learned state ends in an underscore.  The mixture is fitted by a deterministic EM of our own
    (:func:`_em_1d`: scikit-learn's steps, started from equal-count bins instead of a
    seeded k-means; importing scikit-learn cost a fresh process 1.5-2 s).

    Parameters
    ----------
    n_components : int, default 30
        Number of mixture components fitted to the three tiled copies (paper: 30).  With
        few points the number actually used, ``n_components_``, is capped at the number
        of distinct coordinate values (so every component sees at least three tiled
        points on average and the fit cannot collapse onto single points).
    max_iter : int, default 100
        Maximum number of EM iterations (paper: 100).
    reg_covar : float, default 1e-5
        Minimum variance added to every component (paper: 1e-5), in squared phase units.
    n_copies : int, default 3
        Number of tiled copies of the data, centred on the original: 3 gives
        ``theta - 1, theta, theta + 1`` (paper); must be odd and at least 1.
    random_state : None, int or numpy Generator, default 0
        Kept for compatibility: the fit itself is deterministic (a Generator is advanced
        by one draw, as when it seeded a k-means start).  The default 0 is the package's
        one ``random_state`` default (as :func:`cyclecoord.extract`'s): results are the
        same run to run unless a caller asks for fresh entropy with None.
    max_samples : int or None, default 20000
        Longer inputs are fitted on this many values evenly spaced in input (time)
        order; None fits every value.  EM's cost grows with the number of values while
        30 components need far fewer: on a 64,000-frame capture the fit on 20,000 takes
        a fifth of the time and moves the quantiles the typical cycle is sampled at by
        about a thousandth of a period.

    Attributes
    ----------
    n_components_ : int
        Number of mixture components used.
    weights_ : ndarray, shape (``n_components_``,)
        Mixture weights (sum to 1).
    means_ : ndarray, shape (``n_components_``,)
        Component means wrapped into ``[0, 1)``.
    stds_ : ndarray, shape (``n_components_``,)
        Component standard deviations (phase units).
    converged_ : bool
        Whether EM reached its tolerance within ``max_iter`` iterations.
    n_iter_ : int
        EM iterations run.
    n_samples_ : int
        Number of coordinate values fitted (at most ``max_samples``).
    """

    def __init__(
        self,
        n_components: int = 30,
        max_iter: int = 100,
        reg_covar: float = 1e-5,
        n_copies: int = 3,
        random_state: None | int | np.random.Generator = 0,
        max_samples: int | None = 20_000,
    ) -> None:
        self.n_components = n_components
        self.max_iter = max_iter
        self.reg_covar = reg_covar
        self.n_copies = n_copies
        self.random_state = random_state
        self.max_samples = max_samples

    # ------------------------------------------------------------------ fitting
    def _check_params(self) -> None:
        for name in ("n_components", "max_iter", "n_copies"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, Integral) or value < 1:
                raise ParameterError(f"{name} must be a positive integer, got {value!r}")
        if self.max_samples is not None and (
            isinstance(self.max_samples, bool)
            or not isinstance(self.max_samples, Integral)
            or self.max_samples < 2
        ):
            raise ParameterError(
                f"max_samples must be None or an integer >= 2, got {self.max_samples!r}"
            )
        if self.n_copies % 2 != 1:
            raise ParameterError(
                f"n_copies must be odd (copies centred on the data), got {self.n_copies}"
            )
        if (
            isinstance(self.reg_covar, bool)
            or not isinstance(self.reg_covar, Real)
            or not np.isfinite(self.reg_covar)
            or self.reg_covar <= 0
        ):
            raise ParameterError(f"reg_covar must be a positive number, got {self.reg_covar!r}")

    def fit(self, theta: np.ndarray) -> "PeriodicDensity":
        """Fit the density to circular coordinates.

        Parameters
        ----------
        theta : array_like, shape (T,)
            Circular coordinates (phase units, one turn = 1); values outside ``[0, 1)``
            are taken modulo 1.

        Returns
        -------
        PeriodicDensity
            ``self``, fitted.

        Raises
        ------
        ParameterError
            If ``theta`` is empty, not one-dimensional, or holds NaN or infinity, or a
            parameter is out of range.
        """
        self._check_params()
        try:
            values = np.asarray(theta, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"theta must be an array of numbers: {exc}") from None
        if values.ndim != 1:
            raise ParameterError(f"theta must be one-dimensional, got shape {values.shape}")
        if values.size == 0:
            raise ParameterError("theta is empty: no coordinates to fit a density to")
        if not np.all(np.isfinite(values)):
            raise ParameterError("theta holds NaN or infinite values")
        values = np.mod(values, 1.0)
        if self.max_samples is not None and values.size > self.max_samples:
            values = values[np.round(np.linspace(0, values.size - 1, self.max_samples)).astype(int)]

        n_distinct = int(np.unique(values).size)
        n_components = int(min(self.n_components, n_distinct))
        half = self.n_copies // 2
        shifts = np.arange(-half, half + 1, dtype=float)
        tiled = (values[None, :] + shifts[:, None]).reshape(-1, 1)

        _consume_seed(self.random_state)
        weights, means, var, converged, n_iter = _em_1d(
            tiled.ravel(), n_components, int(self.max_iter), float(self.reg_covar)
        )
        self.n_components_ = n_components
        self.n_samples_ = int(values.size)
        self.converged_ = bool(converged)
        self.n_iter_ = int(n_iter)
        self.weights_ = weights
        self.means_ = np.mod(means, 1.0)
        self.stds_ = np.sqrt(var)
        # The wrapped density on [0, 1) is a plain mixture of the shifted copies
        # (mean + s) of each component that come within _TAIL_SIGMAS deviations of
        # [0, 1); list those "pieces" once so evaluation is one (points x pieces) array.
        reach = int(np.ceil(_TAIL_SIGMAS * float(self.stds_.max()))) + 1
        shifts = np.arange(-reach, reach + 1, dtype=float)
        loc = self.means_[:, None] + shifts[None, :]
        scale = np.broadcast_to(self.stds_[:, None], loc.shape)
        weight = np.broadcast_to(self.weights_[:, None], loc.shape)
        keep = (loc + _TAIL_SIGMAS * scale > 0.0) & (loc - _TAIL_SIGMAS * scale < 1.0)
        self._loc = loc[keep]
        self._scale = scale[keep]
        self._weight = weight[keep]
        self._cdf_at_zero = ndtr(-self._loc / self._scale)
        self._total = float(
            self._weight @ (ndtr((1.0 - self._loc) / self._scale) - self._cdf_at_zero)
        )
        self._grid = None  # cdf table for ppf, built on first use
        return self

    def _check_fitted(self) -> None:
        if not hasattr(self, "weights_"):
            raise ParameterError("this PeriodicDensity is not fitted yet: call fit(theta) first")

    @staticmethod
    def _as_float_array(x: np.ndarray, name: str) -> np.ndarray:
        try:
            arr = np.asarray(x, dtype=float)
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"{name} must be numbers: {exc}") from None
        if not np.all(np.isfinite(arr)):
            raise ParameterError(f"{name} holds NaN or infinite values")
        return arr

    # --------------------------------------------------------------- evaluation
    def pdf(self, x: np.ndarray) -> np.ndarray:
        """Circular density at ``x``.

        Parameters
        ----------
        x : array_like, any shape
            Phases; taken modulo 1 (the density is periodic).

        Returns
        -------
        ndarray, same shape as ``x``
            Density values (per unit phase); they integrate to 1 over ``[0, 1)``.
        """
        self._check_fitted()
        arr = self._as_float_array(x, "x")
        flat = np.mod(arr.ravel(), 1.0)
        z = (flat[:, None] - self._loc[None, :]) / self._scale[None, :]
        dens = np.exp(-0.5 * z * z) @ (self._weight / self._scale) * (_INV_SQRT_2PI / self._total)
        return dens.reshape(arr.shape)

    def _cdf_unit(self, u: np.ndarray) -> np.ndarray:
        """Normalised cdf for ``u`` in [0, 1]: mass of the wrapped mixture on [0, u]."""
        z = (u[:, None] - self._loc[None, :]) / self._scale[None, :]
        return (ndtr(z) - self._cdf_at_zero[None, :]) @ self._weight / self._total

    def cdf(self, x: np.ndarray) -> np.ndarray:
        """Cumulative distribution, lifted to the real line.

        On ``[0, 1]`` this is the usual cdf of the circular density started at phase 0
        (``cdf(0) = 0``, ``cdf(1) = 1``); elsewhere ``cdf(x + n) = cdf(x) + n`` for
        integers ``n``, so the function is continuous and non-decreasing everywhere.

        Parameters
        ----------
        x : array_like, any shape
            Phases.

        Returns
        -------
        ndarray, same shape as ``x``
        """
        self._check_fitted()
        arr = self._as_float_array(x, "x")
        flat = arr.ravel()
        turns = np.floor(flat)
        frac = flat - turns
        values = self._cdf_unit(frac)
        return (turns + np.clip(values, 0.0, 1.0)).reshape(arr.shape)

    def _cdf_table(self) -> tuple[np.ndarray, np.ndarray]:
        if self._grid is None:
            grid = np.linspace(0.0, 1.0, _PPF_GRID + 1)
            values = self.cdf(grid)
            values[0], values[-1] = 0.0, 1.0
            values = np.maximum.accumulate(values)
            self._grid = (grid, values)
        return self._grid

    def ppf(self, q: np.ndarray) -> np.ndarray:
        """Inverse of :meth:`cdf` (percent-point function).

        The cdf is tabulated on 4097 equally spaced phases and inverted by linear
        interpolation, then polished with two safeguarded Newton steps on the exact cdf
        (kept inside the grid cell), so ``cdf(ppf(q))`` equals ``q`` to about 1e-9
        wherever the density is not vanishingly small.  Monotone in ``q``.

        Parameters
        ----------
        q : array_like, any shape
            Probabilities; ``q`` in ``[0, 1]`` gives phases in ``[0, 1]``, and like
            :meth:`cdf` the function is lifted: ``ppf(q + n) = ppf(q) + n``.

        Returns
        -------
        ndarray, same shape as ``q``
            Phases.
        """
        self._check_fitted()
        arr = self._as_float_array(q, "q")
        flat = arr.ravel()
        turns = np.floor(flat)
        frac = flat - turns
        grid, table = self._cdf_table()
        x = np.interp(frac, table, grid)
        cell = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, _PPF_GRID - 1)
        lo, hi = grid[cell], grid[cell + 1]
        for _ in range(2):
            dens = self.pdf(x)
            step = (self.cdf(x) - frac) / np.maximum(dens, 1e-300)
            x = np.clip(x - step, lo, hi)
        # keep exact monotonicity despite round-off in the Newton polish
        order = np.argsort(frac, kind="stable")
        x_sorted = np.maximum.accumulate(x[order])
        x[order] = x_sorted
        return (turns + x).reshape(arr.shape)

    # ----------------------------------------------------------------- sampling
    def sample(self, n: int, random_state: None | int | np.random.Generator = None) -> np.ndarray:
        """Draw ``n`` phases from the density (the paper's random sampling).

        Parameters
        ----------
        n : int
            Number of phases, at least 1.
        random_state : None, int or numpy Generator
            Seed; the same seed gives the same phases.

        Returns
        -------
        ndarray, shape (n,)
            Phases in ``[0, 1)``, sorted ascending.
        """
        self._check_fitted()
        n = self._check_count(n)
        rng = as_generator(random_state)
        comp = rng.choice(self.n_components_, size=n, p=self.weights_)
        draws = np.mod(self.means_[comp] + self.stds_[comp] * rng.standard_normal(n), 1.0)
        draws[draws >= 1.0] = 0.0  # -1e-17 % 1 == 1.0 in floating point
        return np.sort(draws)

    def quantiles(self, n: int) -> np.ndarray:
        """Deterministic phases ``ppf((i + 0.5) / n)``, ``i = 0 .. n-1``.

        They follow the density like :meth:`sample` does but without sampling jitter:
        consecutive phases hold equal probability mass, i.e. equal *time* in the motion.

        Parameters
        ----------
        n : int
            Number of phases, at least 1.

        Returns
        -------
        ndarray, shape (n,)
            Phases in ``(0, 1)``, sorted ascending.
        """
        self._check_fitted()
        n = self._check_count(n)
        return self.ppf((np.arange(n) + 0.5) / n)

    @staticmethod
    def _check_count(n: int) -> int:
        if isinstance(n, bool) or not isinstance(n, Integral) or n < 1:
            raise ParameterError(f"n must be a positive integer, got {n!r}")
        return int(n)
