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


# ------------------------------------------------- known answers, helper by helper
def brute_force_lloyd(x, k):
    """1-D k-means by plain Lloyd steps from equal-count runs of the sorted values (the
    documented start): assign each value to its nearest mean (ties to the lower), re-average."""
    x = np.sort(x)
    bounds = np.round(np.linspace(0, x.size, k + 1)).astype(int)
    label = np.repeat(np.arange(k), np.diff(bounds))
    for _ in range(1000):
        means = np.array([x[label == j].mean() for j in range(k)])
        new = np.argmin(np.abs(x[:, None] - means[None, :]), axis=1)
        if np.array_equal(new, label):
            break
        label = new
    return np.array([np.mean(label == j) for j in range(k)]), means, np.array([x[label == j].var() for j in range(k)])


@pytest.mark.parametrize("k", [1, 2, 3, 5])
def test_em_starts_from_the_k_means_of_equal_count_runs(k):
    """With max_iter=0 no EM step runs: the start itself is returned -- the k-means
    clusters' shares, means and (population) variances plus reg_covar."""
    from cyclecoord.periodic.density import _em_1d

    x = draw(200, seed=k)
    weights, means, var, converged, n_iter = _em_1d(x, k, 0, 1e-5)
    w, m, v = brute_force_lloyd(x, k)
    np.testing.assert_allclose(weights, w, rtol=1e-12)
    np.testing.assert_allclose(means, m, rtol=1e-10)
    np.testing.assert_allclose(var, v + 1e-5, rtol=1e-8)
    assert (converged, n_iter) == (False, 0)


def test_em_stops_at_the_first_log_likelihood_change_below_tol():
    """EM's iteration j measures the mean log-likelihood L_j of the parameters left by
    j - 1 iterations (recomputed here with scipy from ``_em_1d(..., max_iter=j - 1)``) and
    stops at the first j with |L_j - L_(j-1)| < tol, 3e-4 by default."""
    from scipy.stats import norm

    from cyclecoord.periodic.density import _em_1d

    x = draw(300, seed=1)  # four components take 30 steps to settle to 3e-4

    def loglik(j):
        w, m, v, _, _ = _em_1d(x, 4, j, 1e-5)
        return np.mean(np.log(norm.pdf(x[:, None], m[None, :], np.sqrt(v)[None, :]) @ w))

    n_iter = _em_1d(x, 4, 100, 1e-5)[4]
    steps = np.abs(np.diff([-np.inf] + [loglik(j) for j in range(n_iter)]))
    assert np.all(steps[:-1] >= 3e-4) and steps[-1] < 3e-4
    assert n_iter >= 4  # several steps: the test is not about the first ones only
    # a looser tolerance stops at the first step below it
    loose = _em_1d(x, 4, 100, 1e-5, tol=1e-2)[4]
    assert loose == 1 + np.flatnonzero(steps < 1e-2)[0] and loose < n_iter


@pytest.mark.parametrize("n_copies", [1, 3, 5])
def test_one_component_fit_is_the_moments_of_the_tiled_copies(n_copies):
    """One component over n tiled copies (shifts -h..h, h = (n - 1) / 2): its mean is the
    data's (mod 1) and its variance the data's plus the shifts' (n^2 - 1) / 12 plus
    reg_covar; EM is at its fixed point from the start, so it stops at step 2."""
    theta = 0.2 + 0.3 * np.random.default_rng(0).random(50)
    d = PeriodicDensity(n_components=1, n_copies=n_copies, reg_covar=2e-5).fit(theta + 3.0)
    assert d.n_components_ == 1 and d.n_samples_ == 50
    np.testing.assert_allclose(d.weights_, [1.0])
    np.testing.assert_allclose(d.means_, [theta.mean()], rtol=1e-12)
    np.testing.assert_allclose(d.stds_**2, [theta.var() + (n_copies**2 - 1) / 12 + 2e-5], rtol=1e-10)
    assert d.converged_ is True and d.n_iter_ == 2


def wrapped_mixture(d, x):
    """pdf and cdf on [0, 1] of the mixture wrapped onto the circle, summing 201 shifts."""
    s = np.arange(-100, 101)[None, None, :]
    loc = d.means_[None, :, None] + s
    sd = d.stds_[None, :, None]
    z = (np.asarray(x, dtype=float)[:, None, None] - loc) / sd
    pdf = (np.exp(-0.5 * z**2) / (sd * np.sqrt(2 * np.pi)) * d.weights_[None, :, None]).sum(axis=(1, 2))
    from scipy.special import ndtr

    cdf = ((ndtr(z) - ndtr(-loc / sd)) * d.weights_[None, :, None]).sum(axis=(1, 2))
    return pdf, cdf


@pytest.mark.parametrize("n_copies, n_components", [(1, 1), (3, 1), (1, 4), (3, 30)])
def test_pdf_and_cdf_are_the_wrapped_mixture(n_copies, n_components):
    """The density is sum over integers s of the mixture at x + s, exactly periodic; summed
    here over 201 shifts (every component's copies within 8 deviations of [0, 1) are what
    the fit keeps: the rest weigh < 1e-15)."""
    d = PeriodicDensity(n_components=n_components, n_copies=n_copies).fit(draw(300, seed=2))
    x = np.linspace(0.0, 1.0, 41)
    pdf, cdf = wrapped_mixture(d, x)
    np.testing.assert_allclose(d.pdf(x), pdf, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(d.cdf(x), cdf, rtol=1e-12, atol=1e-15)
    # lifted: cdf(x + n) = cdf(x) + n, for negative turns too; the pdf is periodic
    np.testing.assert_allclose(d.cdf(x[:-1] - 2.0), cdf[:-1] - 2.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(d.cdf(x[:-1] + 5.0), cdf[:-1] + 5.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(d.pdf(x - 3.0), pdf, rtol=1e-12, atol=1e-14)


def test_evaluation_keeps_the_input_shape():
    d = PeriodicDensity(n_components=2).fit(draw(100, seed=1))
    grid = np.linspace(0.1, 0.9, 6).reshape(2, 3)
    for f in (d.pdf, d.cdf, d.ppf):
        assert f(grid).shape == (2, 3)
        assert np.ndim(f(0.25)) == 0
        np.testing.assert_allclose(f(grid).ravel(), f(grid.ravel()))
    assert float(d.cdf(0.0)) == 0.0 and float(d.cdf(1.0)) == 1.0 and float(d.cdf(-1.0)) == -1.0


def test_ppf_inverts_the_cdf_of_a_known_single_gaussian():
    """One wide component (n_copies=1): the cdf has the closed form of the wrapped normal;
    ppf(q) solves cdf(x) = q to 1e-9 and ppf(0) = 0, ppf(1) = 1, ppf(q + n) = ppf(q) + n."""
    d = PeriodicDensity(n_components=1, n_copies=1).fit(draw(300, seed=3))
    q = np.linspace(0.0, 1.0, 101)
    x = d.ppf(q)
    np.testing.assert_allclose(wrapped_mixture(d, x)[1], q, atol=1e-9)
    assert x[0] == 0.0 and x[-1] == 1.0
    np.testing.assert_allclose(d.ppf(q[:-1] + 2.0), x[:-1] + 2.0, atol=1e-12)
    np.testing.assert_allclose(d.ppf(q[1:] - 1.0), x[1:] - 1.0, atol=1e-12)
    np.testing.assert_allclose(d.quantiles(1), d.ppf([0.5]))
    np.testing.assert_allclose(d.quantiles(4), d.ppf([0.125, 0.375, 0.625, 0.875]))


def test_sample_draws_components_by_weight():
    """Two narrow clusters at 0.2 (30 %) and 0.7 (70 %): the draws fall near each in those
    shares (binomial: 4 standard deviations of 0.005 at n = 8000), wrap into [0, 1) and are
    sorted; the same seed gives the same draws, one draw is an array of one."""
    theta = np.concatenate([0.2 + 0.01 * np.linspace(-1, 1, 30), 0.7 + 0.01 * np.linspace(-1, 1, 70)])
    d = PeriodicDensity(n_components=2, n_copies=1).fit(theta)
    s = d.sample(8000, random_state=1)
    assert s.shape == (8000,) and np.all(np.diff(s) >= 0) and np.all((s >= 0) & (s < 1))
    assert abs(np.mean(np.abs(s - 0.2) < 0.1) - 0.3) < 0.02
    assert abs(np.mean(np.abs(s - 0.7) < 0.1) - 0.7) < 0.02
    # the spread is the component's: about 0.0058 (the cluster's) for the first
    assert np.std(s[np.abs(s - 0.2) < 0.1]) == pytest.approx(np.sqrt(theta[:30].var() + 1e-5), rel=0.1)
    assert d.sample(1, random_state=0).shape == (1,)
    # a component at the seam wraps: draws on both sides of 0, none at 1
    seam = PeriodicDensity(n_components=1, n_copies=1).fit(np.array([0.99, 0.995, 1.005, 1.01]))
    w = seam.sample(2000, random_state=2)
    assert np.all((w >= 0) & (w < 1)) and np.any(w < 0.01) and np.any(w > 0.99)


def test_parameter_boundaries_are_accepted():
    theta = draw(60, seed=0)
    assert PeriodicDensity(n_components=1, max_iter=1, n_copies=1, max_samples=2).fit(theta).n_samples_ == 2
    assert PeriodicDensity(max_samples=None).fit(theta).n_samples_ == 60
    assert PeriodicDensity(max_samples=60).fit(theta).n_samples_ == 60
    assert PeriodicDensity(max_samples=59).fit(theta).n_samples_ == 59
    assert PeriodicDensity(reg_covar=1e-300).fit(theta).n_components_ == 30
    for bad in ({"n_components": True}, {"n_copies": 0}, {"n_copies": 4}, {"max_iter": 0},
                {"reg_covar": -1e-5}, {"reg_covar": float("inf")}, {"reg_covar": True}, {"reg_covar": "1e-5"},
                {"max_samples": 0}, {"n_components": 2.0}):
        with pytest.raises(ParameterError):
            PeriodicDensity(**bad).fit(theta)
    d = PeriodicDensity().fit(theta)
    for bad in (0, True, 2.5):
        with pytest.raises(ParameterError):
            d.sample(bad)
        with pytest.raises(ParameterError):
            d.quantiles(bad)
    for f in (d.pdf, d.cdf, d.ppf):
        with pytest.raises(ParameterError):
            f([0.1, np.inf])
        with pytest.raises(ParameterError):
            f(["a"])
    for f in (lambda u: u.cdf(0.5), lambda u: u.ppf(0.5), lambda u: u.sample(3), lambda u: u.quantiles(3)):
        with pytest.raises(ParameterError, match="not fitted"):
            f(PeriodicDensity())


def test_components_are_capped_at_the_distinct_values():
    """Seven values, five of them distinct (after mod 1): five components at most."""
    theta = np.array([0.1, 2.5, 0.3, 0.3, 0.5, 0.7, 0.9])
    assert PeriodicDensity().fit(theta).n_components_ == 5
    assert PeriodicDensity(n_components=4).fit(theta).n_components_ == 4
    assert PeriodicDensity(n_components=5).fit(theta).n_components_ == 5


def test_as_generator():
    from cyclecoord.periodic.density import as_generator

    g = np.random.default_rng(3)
    assert as_generator(g) is g
    assert as_generator(7).random() == np.random.default_rng(7).random()
    assert as_generator(np.int64(7)).random() == np.random.default_rng(7).random()
    assert as_generator(0).random() == np.random.default_rng(0).random()
    assert isinstance(as_generator(None), np.random.Generator)
    for bad in (-1, 1.5, "3", np.random.RandomState(0)):
        with pytest.raises(ParameterError):
            as_generator(bad)


def test_cdf_stays_within_its_turn_just_below_each_integer():
    """cdf(x + n) = n + (mass on [0, x]), which is at most n + 1: the phases just below 1
    (where summing the pieces can round to 1 + 2e-16) give at most 1, so the cdf does not
    step down into the next turn, where cdf(1) = 1 exactly."""
    u = np.nextafter(1.0, 0.0) - np.arange(50) * 1.1e-16
    for n_components in (3, 30):  # fits whose raw sum rounds above 1 there
        d = PeriodicDensity(n_components=n_components).fit(draw(200, seed=1))
        assert d._cdf_unit(u).max() > 1.0  # the rounding the bound is for
        assert d.cdf(u).max() <= 1.0 and float(d.cdf(1.0)) == 1.0
        assert d.cdf(u + 2.0).max() <= 3.0 and np.all(d.cdf(u - 1.0) <= 0.0)


def test_sample_wraps_a_draw_rounding_to_one_onto_zero():
    """A normal draw landing a hair below 0 (mean + std z = -1e-17) is 1.0 after mod 1 in
    floating point; the phases are in [0, 1), so it comes back as 0.0.  The draw is set with
    a Generator whose standard normal values are chosen."""
    d = PeriodicDensity(n_components=1, n_copies=1).fit(np.array([0.1, 0.2, 0.3]))
    mu, sd = float(d.means_[0]), float(d.stds_[0])
    z = -mu / sd
    while mu + sd * z >= 0.0:  # the largest z whose value is below 0
        z = np.nextafter(z, -np.inf)
    assert np.mod(mu + sd * z, 1.0) == 1.0

    class Chosen(np.random.Generator):
        def standard_normal(self, size=None, *args, **kwargs):
            return np.array([z, 0.0, 1.0])[:size]

    s = d.sample(3, random_state=Chosen(np.random.PCG64(0)))
    np.testing.assert_allclose(s, np.sort([0.0, mu, mu + sd]), rtol=1e-12)
    assert s[0] == 0.0


def test_em_from_an_equal_count_start_that_is_already_a_fixed_point():
    """Values 0..5 in two components: the start's equal-count runs {0, 1, 2} and {3, 4, 5}
    have means 1 and 4, whose midpoint 2.5 separates them, so k-means stops there at once
    (a start of other runs, e.g. {1, 2, 3} first, ends at {0..3} | {4, 5} instead)."""
    from cyclecoord.periodic.density import _em_1d

    weights, means, var, _, _ = _em_1d(np.arange(6.0), 2, 0, 1e-5)
    np.testing.assert_allclose(weights, [0.5, 0.5], rtol=1e-12)
    np.testing.assert_allclose(means, [1.0, 4.0], rtol=1e-12)
    np.testing.assert_allclose(var, [2 / 3 + 1e-5] * 2, rtol=1e-12)


def test_em_weights_sum_to_one():
    """Five values in five components (each its own): the weights are normalised to sum to
    1 to rounding, although each component's count carries a 1e-15 guard against 0."""
    from cyclecoord.periodic.density import _em_1d

    for x in (np.arange(5.0), np.array([0.1, 0.4, 0.45, 0.8])):
        weights = _em_1d(x, x.size, 100, 1e-5)[0]
        np.testing.assert_allclose(weights, 1.0 / x.size, rtol=1e-12)
        assert abs(weights.sum() - 1.0) < 1e-15


def test_max_samples_defaults_to_20000():
    """20,001 values are fitted on 20,000 of them by default, 20,000 on all (one component and
    one EM step: only the count is looked at here)."""
    theta = np.linspace(0.0, 1.0, 20001, endpoint=False)
    assert PeriodicDensity(n_components=1, max_iter=1).fit(theta).n_samples_ == 20000
    assert PeriodicDensity(n_components=1, max_iter=1).fit(theta[:20000]).n_samples_ == 20000


def test_the_default_density_is_seeded():
    """Without random_state the density is seeded with 0 (deterministic by default, as the
    pipeline's): two default fits agree with each other and with random_state=0."""
    x = draw(300, seed=2)
    assert PeriodicDensity().get_params()["random_state"] == 0
    a, b = PeriodicDensity(max_iter=20).fit(x), PeriodicDensity(max_iter=20, random_state=0).fit(x)
    np.testing.assert_array_equal(a.means_, b.means_)
