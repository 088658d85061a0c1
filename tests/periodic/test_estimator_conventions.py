"""scikit-learn conventions of the two estimators: parameters, clone, repr, fit returns self.

scikit-learn's full ``check_estimator`` does not apply: it feeds random blobs, one-feature
and shuffled data and expects any (n_samples, n_features) array to fit, while
``CircularCoordinates`` needs an ordered point cloud holding a loop (random blobs have no
H1 bar to read; shuffling the frames changes the coordinate's orientation by design) and
``PeriodicDensity`` fits a one-dimensional array of phases.  Its data-driven checks also
need ``__sklearn_tags__``, which only ``BaseEstimator`` supplies and the package does not
import (see ``cyclecoord.periodic._estimator``).  The parameter checks run here as they
are, and the data-driven conventions that matter (fit returns self and leaves the
parameters alone, a clone is unfitted) are checked on a noisy circle.
"""

import copy
import warnings

import numpy as np
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.periodic.coordinates import CircularCoordinates
from cyclecoord.periodic.density import PeriodicDensity

import sklearn.base as sklearn_base
import sklearn.utils.estimator_checks as estimator_checks

NON_DEFAULT = [
    CircularCoordinates(max_scale=2.5, class_index=1, prime=53, landmarks=None, memory_limit=1e9),
    PeriodicDensity(n_components=12, reg_covar=1e-4, random_state=7, max_samples=None),
]
PARAMETER_CHECKS = [
    "check_no_attributes_set_in_init",
    "check_parameters_default_constructible",
    "check_get_params_invariance",
    "check_set_params",
    "check_estimator_repr",
]


def circle(n=120, turns=3.0, noise=0.03, seed=0):
    rng = np.random.default_rng(seed)
    ang = 2 * np.pi * np.linspace(0, turns, n, endpoint=False)
    x = np.zeros((n, 4))
    x[:, 0], x[:, 1] = np.cos(ang), np.sin(ang)
    return x + noise * rng.standard_normal(x.shape)


@pytest.mark.parametrize("est", [CircularCoordinates(), PeriodicDensity()] + NON_DEFAULT, ids=repr)
@pytest.mark.parametrize("check", PARAMETER_CHECKS)
def test_scikit_learn_parameter_checks(est, check):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        getattr(estimator_checks, check)(type(est).__name__, est)


@pytest.mark.parametrize("est", NON_DEFAULT, ids=repr)
def test_get_params_round_trip_and_clone(est):
    params = est.get_params()
    assert sorted(params) == sorted(type(est)().get_params())
    rebuilt = type(est)(**params)
    assert all(rebuilt.get_params()[k] is v for k, v in params.items())
    twin = sklearn_base.clone(est)
    assert type(twin) is type(est) and twin is not est
    assert twin.get_params() == params
    assert type(est)().set_params(**params).get_params() == params


def test_set_params_refuses_unknown_names_and_sets_nothing():
    est = CircularCoordinates()
    with pytest.raises(ParameterError, match="no parameter 'primes'"):
        est.set_params(prime=53, primes=53)
    assert est.prime == 47
    with pytest.raises(ValueError):  # ParameterError is a ValueError, as scikit-learn raises
        PeriodicDensity().set_params(n_component=3)


def test_repr_lists_changed_parameters_only():
    assert repr(CircularCoordinates()) == "CircularCoordinates()"
    assert repr(CircularCoordinates(prime=53, landmarks=None)) == "CircularCoordinates(landmarks=None, prime=53)"
    assert repr(PeriodicDensity(n_components=12)) == "PeriodicDensity(n_components=12)"
    assert repr(PeriodicDensity(random_state=None)) == "PeriodicDensity(random_state=None)"


def test_one_random_state_default():
    # extract and motion_cycles use 0; so do the density and the typical cycle
    import inspect

    from cyclecoord.periodic.cycle import typical_cycle
    from cyclecoord.periodic.detection import motion_cycles
    from cyclecoord.periodic.pipeline import extract

    for func in (extract, motion_cycles, typical_cycle, PeriodicDensity):
        assert inspect.signature(func).parameters["random_state"].default == 0, func
    assert "random_state" not in CircularCoordinates().get_params()  # deterministic fit


def test_fit_returns_self_and_leaves_parameters_alone():
    x = circle()
    est = CircularCoordinates(landmarks=None)
    before = copy.deepcopy(est.get_params())
    assert est.fit(x) is est
    assert est.get_params() == before
    assert est.coordinates_.shape == (len(x),)
    unfitted = sklearn_base.clone(est)
    assert not hasattr(unfitted, "coordinates_") and not hasattr(unfitted, "barcode_")
    theta = np.mod(np.linspace(0, 5, 400), 1.0)
    dens = PeriodicDensity(n_components=8)
    assert dens.fit(theta) is dens and dens.get_params()["n_components"] == 8
    assert not hasattr(sklearn_base.clone(dens), "weights_")


def test_with_coordinate_params_reads_another_class_without_touching_the_original():
    # two loops of different sizes: two H1 classes in one barcode
    rng = np.random.default_rng(3)
    ang = 2 * np.pi * np.linspace(0, 3, 150, endpoint=False)
    big = np.column_stack([3 * np.cos(ang), 3 * np.sin(ang), np.zeros_like(ang)])
    small = np.column_stack([10 + np.cos(ang), np.sin(ang), np.zeros_like(ang)])
    x = np.vstack([big, small]) + 0.02 * rng.standard_normal((300, 3))
    est = CircularCoordinates(landmarks=None).fit(x)
    assert len(est.barcode_.h1) >= 2
    state = dict(est.__dict__)
    coords = est.coordinates_.copy()

    other = est.with_coordinate_params(class_index=1)
    assert other is not est and other.class_index == 1 and not hasattr(other, "coordinates_")
    assert other.barcode_ is est._stage_barcode and other.points_ is est.points_  # shared, not recomputed
    assert other.fit_coordinate() is other
    assert est.__dict__.keys() == state.keys() and all(est.__dict__[k] is v for k, v in state.items())
    np.testing.assert_array_equal(est.coordinates_, coords)
    assert est.class_index == 0 and est.selection_.index == 0 and other.selection_.index == 1
    fresh = CircularCoordinates(landmarks=None, class_index=1).fit(x)
    np.testing.assert_array_equal(other.coordinates_, fresh.coordinates_)

    with pytest.raises(ParameterError, match="the barcode depends on prime"):
        est.with_coordinate_params(prime=53)
    with pytest.raises(ParameterError, match="fit_barcode"):
        CircularCoordinates().with_coordinate_params(class_index=1)
