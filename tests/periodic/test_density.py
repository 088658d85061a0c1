"""Tests of the periodic (wrapped Gaussian mixture) density of circular coordinates."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.stats import vonmises

from cyclecoord.periodic.density import PeriodicDensity
from cyclecoord.errors import ParameterError

# A bimodal circular distribution on [0, 1): two von Mises bumps of unequal width.
_MIX = ((0.6, 0.25, 8.0), (0.4, 0.70, 15.0))  # (weight, centre, concentration)


def true_pdf(x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    return sum(w * 2 * np.pi * vonmises.pdf(2 * np.pi * x, kappa, loc=2 * np.pi * mu) for w, mu, kappa in _MIX)


def draw(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    first = rng.random(n) < _MIX[0][0]
    angles = np.where(
        first,
        rng.vonmises(2 * np.pi * _MIX[0][1], _MIX[0][2], n),
        rng.vonmises(2 * np.pi * _MIX[1][1], _MIX[1][2], n),
    )
    return np.mod(angles / (2 * np.pi), 1.0)


@pytest.fixture(scope="module")
def fitted() -> PeriodicDensity:
    return PeriodicDensity(random_state=0).fit(draw(750, seed=1))


GRID = (np.arange(20000) + 0.5) / 20000  # midpoint rule on [0, 1)


def test_pdf_integrates_to_one(fitted):
    assert fitted.pdf(GRID).mean() == pytest.approx(1.0, abs=1e-6)
    assert np.all(fitted.pdf(GRID) >= 0)


def test_pdf_is_periodic_without_seam(fitted):
    eps = 1e-7
    assert fitted.pdf(0.0) == pytest.approx(float(fitted.pdf(1.0 - eps)), rel=1e-4)
    # values outside [0, 1) are taken modulo 1
    np.testing.assert_allclose(fitted.pdf(GRID + 1.0), fitted.pdf(GRID), rtol=1e-9)
    np.testing.assert_allclose(fitted.pdf(GRID - 3.0), fitted.pdf(GRID), rtol=1e-9)


def test_pdf_close_to_true_density(fitted):
    l1 = np.abs(fitted.pdf(GRID) - true_pdf(GRID)).mean()
    assert l1 < 0.15
    # the two modes are found where they are
    peaks = GRID[np.argmax(fitted.pdf(GRID))]
    assert abs(peaks - 0.70) < 0.03 or abs(peaks - 0.25) < 0.03


def test_cdf_and_ppf(fitted):
    assert float(fitted.cdf(0.0)) == 0.0
    assert float(fitted.cdf(1.0)) == pytest.approx(1.0, abs=1e-12)
    x = np.linspace(0, 1, 501)
    c = fitted.cdf(x)
    assert np.all(np.diff(c) >= 0)
    # cdf is the integral of the pdf
    np.testing.assert_allclose(fitted.cdf(0.5), fitted.pdf(GRID[GRID < 0.5]).sum() / GRID.size, atol=1e-6)
    # inverse both ways, accurate to 1e-4
    np.testing.assert_allclose(fitted.ppf(c), x, atol=1e-4)
    q = np.linspace(0, 1, 777)
    np.testing.assert_allclose(fitted.cdf(fitted.ppf(q)), q, atol=1e-9)
    assert np.all(np.diff(fitted.ppf(q)) >= 0)
    # lifted to the real line
    assert float(fitted.cdf(2.3)) == pytest.approx(2.0 + float(fitted.cdf(0.3)))
    assert float(fitted.ppf(1.4)) == pytest.approx(1.0 + float(fitted.ppf(0.4)))


def test_quantiles_sorted_and_follow_density(fitted):
    q = fitted.quantiles(500)
    assert q.shape == (500,)
    assert np.all(np.diff(q) > 0)
    assert q[0] > 0 and q[-1] < 1
    np.testing.assert_allclose(fitted.cdf(q), (np.arange(500) + 0.5) / 500, atol=1e-9)
    # denser where the density is high: each bin holds its probability mass times n
    edges = np.linspace(0, 1, 21)
    counts = np.histogram(q, bins=edges)[0]
    expected = 500 * np.diff(fitted.cdf(edges))
    assert np.all(np.abs(counts - expected) <= 1.0 + 1e-9)
    assert counts.max() > 4 * counts.min() + 1  # and the density is far from uniform


def test_sample_follows_density(fitted):
    s = fitted.sample(4000, random_state=3)
    assert s.shape == (4000,)
    assert np.all((s >= 0) & (s < 1))
    assert np.all(np.diff(s) >= 0)
    # Kolmogorov-Smirnov distance to the fitted cdf
    ks = np.abs(fitted.cdf(s) - (np.arange(4000) + 0.5) / 4000).max()
    assert ks < 0.03
    np.testing.assert_array_equal(s, fitted.sample(4000, random_state=3))
    assert not np.array_equal(s, fitted.sample(4000, random_state=4))


def test_same_seed_same_fit():
    theta = draw(300, seed=5)
    a = PeriodicDensity(random_state=7).fit(theta)
    b = PeriodicDensity(random_state=7).fit(theta)
    np.testing.assert_array_equal(a.pdf(GRID), b.pdf(GRID))
    np.testing.assert_array_equal(a.quantiles(100), b.quantiles(100))


def test_values_outside_unit_interval_are_wrapped():
    theta = draw(300, seed=5)
    a = PeriodicDensity(random_state=2).fit(theta)
    b = PeriodicDensity(random_state=2).fit(theta + 2.0)
    np.testing.assert_allclose(a.pdf(GRID), b.pdf(GRID), rtol=1e-6, atol=1e-9)


def test_few_points_cap_components_and_no_warning_noise():
    theta = np.array([0.1, 0.4, 0.45, 0.8])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # any warning (e.g. ConvergenceWarning) fails
        d = PeriodicDensity(random_state=0, max_iter=1).fit(theta)
    assert d.n_components_ == 4
    assert d.converged_ in (True, False)
    assert d.pdf(GRID).mean() == pytest.approx(1.0, abs=1e-6)
    one = PeriodicDensity(random_state=0).fit(np.full(10, 0.3))
    assert one.n_components_ == 1
    assert one.pdf(GRID).mean() == pytest.approx(1.0, abs=1e-6)


def test_not_converged_is_recorded():
    d = PeriodicDensity(random_state=0, max_iter=1).fit(draw(300, seed=5))
    assert d.converged_ is False
    assert d.n_iter_ == 1


@pytest.mark.parametrize(
    "theta",
    [np.array([]), np.array([0.1, np.nan]), np.array([0.2, np.inf]), np.zeros((3, 2)), ["a", "b"]],
)
def test_bad_theta(theta):
    with pytest.raises(ParameterError):
        PeriodicDensity().fit(theta)


@pytest.mark.parametrize(
    "kwargs",
    [{"n_components": 0}, {"max_iter": -1}, {"reg_covar": 0.0}, {"reg_covar": float("nan")}, {"n_copies": 2},
     {"max_samples": 1}, {"max_samples": 2.5}, {"max_samples": True}],
)
def test_bad_parameters(kwargs):
    with pytest.raises(ParameterError):
        PeriodicDensity(**kwargs).fit(draw(50, seed=0))


def test_unfitted_and_bad_counts(fitted):
    with pytest.raises(ParameterError):
        PeriodicDensity().pdf(0.5)
    with pytest.raises(ParameterError):
        fitted.quantiles(0)
    with pytest.raises(ParameterError):
        fitted.sample(-3)
    with pytest.raises(ParameterError):
        fitted.ppf([0.2, np.nan])


def test_long_inputs_are_fitted_on_an_even_subsample():
    theta = draw(60000, seed=3)
    sub = PeriodicDensity(random_state=0, max_samples=5000).fit(theta)
    assert sub.n_samples_ == 5000
    # the same as fitting the evenly spaced values by hand
    by_hand = PeriodicDensity(random_state=0, max_samples=None).fit(theta[np.round(np.linspace(0, 59999, 5000)).astype(int)])
    np.testing.assert_allclose(sub.quantiles(200), by_hand.quantiles(200))
    # and close to the fit on every value, and to the truth
    full = PeriodicDensity(random_state=0, max_samples=None).fit(theta)
    assert full.n_samples_ == 60000
    assert np.max(np.abs(sub.cdf(GRID[::50]) - full.cdf(GRID[::50]))) < 0.01
    err_sub = np.mean(np.abs(sub.pdf(GRID[::50]) - true_pdf(GRID[::50])))
    err_full = np.mean(np.abs(full.pdf(GRID[::50]) - true_pdf(GRID[::50])))
    assert err_sub < 0.08 and err_full < 0.05  # mean |pdf - truth|; the pdf peaks near 3


@pytest.mark.parametrize("n, seed", [(300, 5), (750, 1), (5000, 2)])
def test_deterministic_start_fits_as_scikit_learns_k_means_start_did(n, seed):
    """The cdf (where the typical cycle samples) moves by under 0.01 of a period."""
    from sklearn import mixture

    theta = draw(n, seed=seed)
    ours = PeriodicDensity(random_state=0).fit(theta)
    tiled = (theta[None, :] + np.arange(-1.0, 2.0)[:, None]).reshape(-1, 1)
    gm = mixture.GaussianMixture(30, covariance_type="diag", reg_covar=1e-5, random_state=0).fit(tiled)
    from scipy.special import ndtr

    # the wrapped scikit-learn mixture's cdf on [0, 1], by hand
    w, mu, sd = gm.weights_ / gm.weights_.sum(), gm.means_.ravel(), np.sqrt(gm.covariances_.ravel())
    x = np.linspace(0.0, 1.0, 201)
    sh = np.arange(-4.0, 5.0)
    zx = (x[:, None, None] + sh[None, :, None] - mu[None, None, :]) / sd
    z0 = (sh[None, :, None] - mu[None, None, :]) / sd
    cdf_ref = ((ndtr(zx) - ndtr(z0)) * w).sum(axis=(1, 2))
    cdf_ref /= cdf_ref[-1]
    assert np.max(np.abs(ours.cdf(x) - cdf_ref)) < 0.01
    assert ours.converged_


def test_fit_ignores_the_seed_and_leaves_a_generator_where_it_was():
    theta = draw(500, seed=4)
    a = PeriodicDensity(random_state=0).fit(theta)
    b = PeriodicDensity(random_state=123).fit(theta)
    np.testing.assert_array_equal(a.means_, b.means_)
    for seed, word in [(9, None), (0, None), (2, None), (1, 12345), (1, 2**31 - 1)]:
        g1, g2 = np.random.default_rng(seed), np.random.default_rng(seed)
        if word is not None:  # the next 32-bit word of both; 2^31 - 1 is one that the
            # bounded draw (Lemire's method) rejects for [0, 2^31 - 1), taking another
            for g in (g1, g2):
                g.bit_generator.state = {**g.bit_generator.state, "has_uint32": 1, "uinteger": word}
        PeriodicDensity(random_state=g1).fit(theta)
        g2.integers(0, 2**31 - 1)  # one draw, as when the generator seeded scikit-learn
        # the whole state (a 32-bit draw keeps half of a 64-bit one for the next), so the
        # next draws of every kind are unchanged
        assert g1.bit_generator.state == g2.bit_generator.state
        assert g1.integers(0, 2**31 - 1, size=3).tolist() == g2.integers(0, 2**31 - 1, size=3).tolist()
        assert g1.random() == g2.random()


def test_em_on_two_separate_clusters_is_their_sample_moments():
    """Two clusters far apart (0.5 between, widths 0.02 and 0.04): the k-means start is
    the two clusters, EM's responsibilities are 0 or 1, so the fit is each cluster's
    share, mean and (population) variance plus ``reg_covar``; started at that fixed
    point EM stops at its second step, the first whose log-likelihood change (here 0)
    is below ``tol``."""
    from cyclecoord.periodic.density import _em_1d

    a = 0.2 + 0.01 * np.linspace(-1, 1, 30)
    b = 0.7 + 0.02 * np.linspace(-1, 1, 70) ** 3
    x = np.random.default_rng(0).permutation(np.concatenate([b, a]))
    weights, means, var, converged, n_iter = _em_1d(x, 2, 100, 1e-5)
    np.testing.assert_allclose(weights, [0.3, 0.7], rtol=1e-12)
    np.testing.assert_allclose(means, [a.mean(), b.mean()], rtol=1e-12)
    np.testing.assert_allclose(var, [a.var() + 1e-5, b.var() + 1e-5], rtol=1e-9)
    assert converged and n_iter == 2
    # stopped by max_iter: not converged, and the iterations run are counted
    assert _em_1d(x, 2, 1, 1e-5)[3:] == (False, 1)


def test_ppf_inverts_the_cdf_in_the_first_and_last_cells_of_its_table():
    """ppf's table spans [0, 1] in 4096 cells; phases inside the first and the last cell
    (where the table is pinned to 0 and 1) come back from their cdf to 1e-9 too, on a
    density of about 1 there."""
    d = PeriodicDensity().fit((np.arange(400) + 0.5) / 400)
    x = np.array([0.25, 0.75, 4095.25, 4095.75]) / 4096
    assert np.all(d.pdf(x) > 0.5)
    q = d.cdf(x)
    np.testing.assert_allclose(d.ppf(q), x, rtol=0, atol=1e-9)
    np.testing.assert_allclose(d.cdf(d.ppf(q)), q, rtol=0, atol=1e-9)


def test_em_with_a_k_means_run_left_empty_stays_finite():
    """Six equal values and one other in three components: a k-means run comes out empty
    (two means meet); its component keeps a weight of about 0 and the fit is finite, the
    others the two values' shares."""
    from cyclecoord.periodic.density import _em_1d

    weights, means, var, converged, _ = _em_1d(np.array([0.0] * 6 + [1.0]), 3, 100, 1e-5)
    assert np.all(np.isfinite(weights)) and np.all(np.isfinite(means)) and converged
    np.testing.assert_allclose(weights, [6 / 7, 1 / 7, 0.0], atol=1e-12)
    np.testing.assert_allclose(means[:2], [0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(var, 1e-5, rtol=1e-9)
