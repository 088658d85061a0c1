"""Parameter validation from a constraint table (cyclecoord._validation) and extract's table."""

import numbers

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord._validation import Interval, Options, check_params, describe
from cyclecoord.errors import ParameterError

TABLE = {
    "mode": [Options("a", "b", "c")],
    "side": [Options("left", "right")],
    "k": [Interval(numbers.Integral, 1, None)],
    "frac": [Interval(numbers.Real, 0, 1, closed="right")],
    "limit": [Interval(numbers.Real, 0, None, closed="neither"), None],
    "flag": ["boolean"],
}


def test_values_inside_their_constraints_pass():
    check_params(
        {"mode": "b", "side": "left", "k": np.int64(3), "frac": 1.0, "limit": None, "flag": np.True_,
         "other": object()},
        TABLE,
        "f()",
    )


@pytest.mark.parametrize(
    ("name", "value", "message"),
    [
        ("mode", "d", "f(): mode must be one of 'a', 'b', 'c', got 'd'"),
        ("side", 1, "f(): side must be 'left' or 'right', got 1"),
        ("k", 0, "f(): k must be an integer >= 1, got 0"),
        ("k", 2.0, "f(): k must be an integer >= 1, got 2.0"),
        ("k", True, "f(): k must be an integer >= 1, got True"),
        ("frac", 0.0, "f(): frac must be a number > 0 and <= 1, got 0.0"),
        ("frac", float("nan"), "f(): frac must be a number > 0 and <= 1, got nan"),
        ("limit", -1, "f(): limit must be a number > 0 or None, got -1"),
        ("flag", 1, "f(): flag must be True or False, got 1"),
    ],
)
def test_a_value_outside_gets_one_line_naming_it(name, value, message):
    with pytest.raises(ParameterError) as info:
        check_params({name: value}, TABLE, "f()")
    assert str(info.value) == message


def test_describe_reads_like_the_docs():
    assert describe([Interval(numbers.Real, 0, 1), None]) == "a number >= 0 and <= 1 or None"


@pytest.mark.parametrize(
    ("option", "value", "words"),
    [
        ("travel", "sideways", "travel must be one of 'keep', 'straight', 'in_place'"),
        ("n_samples", 5, "n_samples must be an integer >= 10"),
        ("min_turns", 0, "min_turns must be a number > 0"),
        ("steady", "yes", "steady must be True or False"),
        ("scale_fraction", 1.5, "scale_fraction must be a number > 0 and <= 1"),
    ],
)
def test_extract_checks_its_table_before_any_work(option, value, words, monkeypatch):
    import cyclecoord.periodic.fitting as fitting

    def never(*args, **kwargs):
        raise AssertionError("the capture was prepared before the options were checked")

    monkeypatch.setattr(fitting, "Preprocessor", never)
    motion = cc.datasets.make_periodic_capture(n_frames=60, random_state=0).motion
    with pytest.raises(ParameterError, match=words):
        cc.extract(motion, **{option: value})


@pytest.mark.parametrize(
    ("option", "value", "words"),
    [
        ("method", "both", "method must be one of 'auto', 'global', 'windows'"),
        ("min_consistency", 0, "min_consistency must be a number > 0 and <= 1"),
        ("n_classes", 0, "n_classes must be an integer >= 1 or None"),
        ("window_points", 9, "window_points must be an integer >= 10"),
        ("window_lengths", (2.0, -1.0), "window_lengths must be positive numbers of seconds"),
    ],
)
def test_detect_checks_its_table(option, value, words):
    motion = cc.datasets.make_periodic_capture(n_frames=60, random_state=0).motion
    with pytest.raises(ParameterError, match=words):
        cc.detect(motion, progress=False, **{option: value})


def test_cycle_options_as_one_object():
    """extract and motion_cycles take the cycle's options as a CycleOptions too."""
    from cyclecoord.periodic.detection import motion_cycles

    m = cc.datasets.example_capture().motion
    opts = cc.CycleOptions(travel="straight", cycle_start="first")
    a = cc.extract(m, travel="straight", cycle_start="first")
    b = cc.extract(m, cycle=opts)
    np.testing.assert_array_equal(a.cycle.frames, b.cycle.frames)
    assert b.parameters["travel"] == "straight"
    with pytest.raises(ParameterError, match="travel either as keyword"):
        cc.extract(m, travel="in_place", cycle=opts)
    with pytest.raises(ParameterError, match="cycle must be a CycleOptions"):
        cc.extract(m, cycle={"travel": "straight"})
    chain = cc.datasets.make_motion_chain(random_state=0)
    res = cc.detect(chain.motion, progress=False)
    kw = motion_cycles(res, travel="in_place", min_cycles=1.5)
    ob = motion_cycles(res, cycle=cc.CycleOptions(travel="in_place"))
    assert [c.motion for c in kw] == [c.motion for c in ob]
    for x, y in zip(kw, ob):
        np.testing.assert_array_equal(x.cycle.frames, y.cycle.frames)


def test_extract_takes_a_configured_preprocessor_and_estimator():
    m = cc.datasets.example_capture().motion
    pre, est = cc.Preprocessor(pca=5), cc.CircularCoordinates(max_scale=30.0, prime=31)
    before = est.get_params()
    a = cc.extract(m, pca=5, delay=None, max_scale=30.0, prime=31)
    b = cc.extract(m, preprocessor=pre, estimator=est)
    np.testing.assert_array_equal(a.cycle.frames, b.cycle.frames)
    assert b.parameters["pca"] == 5 and b.parameters["max_scale"] == 30.0
    assert b.parameters["prime"] == 31 and b.parameters["delay"] is None
    # neither object is fitted or changed
    assert not hasattr(pre, "root_columns_") and not hasattr(est, "barcode_")
    assert est.get_params() == before
    with pytest.raises(ParameterError, match="pca either as keyword"):
        cc.extract(m, pca=3, preprocessor=pre)
    with pytest.raises(ParameterError, match="estimator must be a CircularCoordinates"):
        cc.extract(m, estimator=pre)


def test_detect_takes_configured_objects_too():
    chain = cc.datasets.make_motion_chain(random_state=0).motion
    a = cc.detect(chain, pca=8, delay=None, max_scale=None, progress=False)
    b = cc.detect(chain, preprocessor=cc.Preprocessor(pca=8), progress=False,
                  estimator=cc.CircularCoordinates())
    np.testing.assert_array_equal(a.labels, b.labels)
    assert b.parameters["pca"] == 8 and b.parameters["delay"] is None
    with pytest.raises(ParameterError, match="detect\\(\\): give pca"):
        cc.detect(chain, pca=3, preprocessor=cc.Preprocessor(pca=8), progress=False)
