"""Known-answer tests of ``periodic.fitting``: the row helpers, the reasons and messages,
:func:`first_clear`'s raising of a threshold that cuts the chosen bar short, and
:class:`TakeFit`'s estimator, refusals and failures on small synthetic inputs.

Regular polygons give the bars by hand: N points on a unit circle hold one H1 bar born
at the neighbour chord 2 sin(pi/N); for N = 12 it dies at 2 sin(pi/3) = sqrt 3.
"""

from types import SimpleNamespace as NS

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import NoPeriodicMotionError, ParameterError
from cyclecoord.periodic import fitting
from cyclecoord.periodic.barcode import CLEAR_GAP, CLEAR_RATIO, default_max_scale
from cyclecoord.periodic.coordinates import CircularCoordinates
from cyclecoord.periodic.fitting import (
    ALIVE_RATIO,
    FIRST_PASS_LANDMARKS,
    MAX_SPREAD,
    first_clear,
    not_clear_reason,
    row_runs,
    rows_of,
    too_few_turns,
    unwrap_runs,
)


def circle(n, r=1.0):
    a = 2 * np.pi * np.arange(n) / n
    return np.column_stack([r * np.cos(a), r * np.sin(a)])


def chord(n, k=1):
    return 2 * np.sin(np.pi * k / n)


def test_constants():
    assert (MAX_SPREAD, ALIVE_RATIO, FIRST_PASS_LANDMARKS) == (0.25, 4.0, 150)


# ---------------------------------------------------------------- rows
def test_row_runs_by_hand():
    assert row_runs(np.array([], dtype=int)) == []
    assert row_runs(np.array([5])) == [(5, 6)]
    assert row_runs(np.array([0, 1, 2])) == [(0, 3)]
    assert row_runs(np.array([0, 1, 3, 4, 9])) == [(0, 2), (3, 5), (9, 10)]
    assert row_runs(np.array([2, 4, 6])) == [(2, 3), (4, 5), (6, 7)]
    out = row_runs(np.array([7, 8]))
    assert all(type(v) is int for ab in out for v in ab)


def test_rows_of_single_and_empty():
    x = np.arange(10.0)[:, None]
    one = rows_of(x, np.array([4]))
    assert one.tolist() == [[4.0]] and np.shares_memory(one, x)
    assert rows_of(x, np.array([], dtype=int)).shape == (0, 1)
    # sorted but not contiguous: the rows themselves
    assert rows_of(x, np.array([0, 2])).ravel().tolist() == [0.0, 2.0]


def test_unwrap_runs_by_hand():
    # rows 1, 2, 3 and 6, 7 of 9 frames; each run unwrapped on its own, NaN elsewhere
    rows = np.array([1, 2, 3, 6, 7])
    theta = np.array([0.8, 0.95, 0.1, 0.9, 0.05])
    out = unwrap_runs(theta, rows, row_runs(rows), 9)
    want = [np.nan, 0.8, 0.95, 1.1, np.nan, np.nan, 0.9, 1.05, np.nan]
    np.testing.assert_allclose(out, want, atol=1e-12)
    # an empty run (b == a) leaves NaN; a one-frame run is its value
    out = unwrap_runs(np.array([0.3]), np.array([2]), [(2, 2), (2, 3)], 4)
    np.testing.assert_allclose(out, [np.nan, np.nan, 0.3, np.nan])


# ---------------------------------------------------------------- messages
def _sel(**kw):
    base = dict(index=0, birth=1.0, death=2.0, ratio=CLEAR_RATIO, gap=CLEAR_GAP)
    return NS(**{**base, **kw})


def test_not_clear_reason_at_the_bounds():
    bc = NS(threshold=4.0)
    # exactly at both bounds: neither falls short, so the persistence is named
    why = not_clear_reason(_sel(), bc)
    assert why == ("H1 bar #0 [1, 2) does not stand clear (persistence under 5% of the "
                   "threshold 4)")
    why = not_clear_reason(_sel(ratio=1.2, gap=1.5, death=np.inf, index=2, birth=0.25), bc)
    assert why == ("H1 bar #2 [0.25, inf) does not stand clear (death/birth 1.20 < 1.5; "
                   "persistence only 1.50x the next bar's (< 2.0x))")
    why = not_clear_reason(_sel(gap=1.99), bc)
    assert "death/birth" not in why and "only 1.99x" in why and "under" not in why


def test_too_few_turns_message():
    msg = too_few_turns(1.234, 250, 1.5)
    assert msg.startswith("no periodic motion found: the coordinate turns only 1.23 times over "
                          "the 250 steady frames (at least 1.5 are needed")
    assert "--pca 3" in msg


# ---------------------------------------------------------------- first_clear
def test_first_clear_raises_a_threshold_that_cuts_the_bar_short():
    # 12-gon, threshold 0.8: the bar [0.518, 1.732) is alive and 0.8 < 4 x 0.518, so the
    # threshold is raised 1.6x: 1.28 (still alive), 2.048 (the bar dies at sqrt 3)
    x = circle(12)
    est = CircularCoordinates(landmarks=None, max_scale=0.8)
    bc, sel = first_clear(est, x, 0, None, 0.9)
    assert bc.threshold == pytest.approx(0.8 * 1.6 * 1.6)
    assert sel.death == pytest.approx(np.sqrt(3), rel=1e-6)
    assert sel.birth == pytest.approx(chord(12), rel=1e-6)
    assert sel.scale == pytest.approx(sel.birth + 0.9 * (sel.death - sel.birth))
    assert est.max_scale == 0.8  # restored
    assert est.barcode_ is bc and est.class_index == 0


def test_first_clear_stops_at_alive_ratio_and_at_the_diameter():
    # 24-gon born at 0.261: 0.5 -> 0.8 (0.8 < 4 x 0.261 = 1.044) -> 1.28 (alive, clear and
    # at least 4x its birth: kept)
    x = circle(24)
    est = CircularCoordinates(landmarks=None, max_scale=0.5)
    bc, sel = first_clear(est, x, 0, None, 0.9)
    assert bc.threshold == pytest.approx(1.28) and sel.death == np.inf
    assert bc.threshold >= ALIVE_RATIO * sel.birth and sel.clear
    # 12-gon from 1.5: 2.4 would pass the diameter (2 x default_max_scale), so it stops there
    x = circle(12)
    est = CircularCoordinates(landmarks=None, max_scale=1.5)
    bc, sel = first_clear(est, x, 0, None, 0.9)
    assert bc.threshold == pytest.approx(2.0 * default_max_scale(x))
    assert sel.death == pytest.approx(np.sqrt(3), rel=1e-6)


def test_first_clear_alive_ratio_bound_itself_stops():
    # a threshold exactly 4x the birth with the bar alive and clear is not raised
    x = circle(24)
    birth = float(cc.periodic.barcode.compute_barcode(x, max_scale=1.0).h1[0, 0])
    est = CircularCoordinates(landmarks=None, max_scale=ALIVE_RATIO * birth)
    bc, sel = first_clear(est, x, 0, None, 0.9)
    assert bc.threshold == ALIVE_RATIO * birth and sel.death == np.inf


def test_first_clear_keeps_a_dead_bar_and_an_explicit_scale():
    x = circle(12)
    est = CircularCoordinates(landmarks=None, max_scale=2.0)  # the bar dies at 1.732 < 2
    bc, sel = first_clear(est, x, 0, None, 0.9)
    assert bc.threshold == 2.0
    est = CircularCoordinates(landmarks=None, max_scale=0.8)
    bc, sel = first_clear(est, x, 0, 0.7, 0.9)
    assert bc.threshold == 0.8 and sel.scale == 0.7 and sel.death == np.inf


def test_first_clear_without_the_class():
    x = circle(12)
    est = CircularCoordinates(landmarks=None, max_scale=0.8)
    bc, sel = first_clear(est, x, 1, None, 0.9)  # one bar only
    assert sel is None and len(bc.h1) == 1
    est = CircularCoordinates(landmarks=None, max_scale=0.4)  # below the birth: no bar
    bc, sel = first_clear(est, x, 0, None, 0.9)
    assert sel is None and len(bc.h1) == 0


# ---------------------------------------------------------------- TakeFit
PARAMS = dict(frames=None, pca=None, normalize=False, temporal=False, delay=None,
              difference_root=True, root="body", prime=47, rotations="auto", max_scale=None,
              scale=None, class_index=0, scale_fraction=0.9, n_neighbors=10, landmarks="auto",
              memory_limit=None, steady=False, min_turns=1.5)


@pytest.fixture(scope="module")
def motion():
    return cc.datasets.make_periodic_capture(n_frames=120, period=40.0, random_state=0).motion


def test_make_estimator(motion):
    run = fitting.TakeFit(motion, {**PARAMS, "prime": 53, "scale_fraction": 0.7}, True)
    est = run.make_estimator()
    assert est.landmarks == "auto" and est.prime == 53 and est.scale_fraction == 0.7
    assert est.refine_birth is False
    assert est.landmarks == "auto"
    assert run.make_estimator(first_pass=True).landmarks == FIRST_PASS_LANDMARKS
    p = run.prepared
    assert est.memory_reserved == 8.0 * max(0, p.poses.size - p.points.size)
    run = fitting.TakeFit(motion, {**PARAMS, "landmarks": 40}, True)
    assert run.make_estimator(first_pass=True).landmarks == 40
    run = fitting.TakeFit(motion, {**PARAMS, "landmarks": None}, True)
    assert run.make_estimator(first_pass=True).landmarks is None


def test_delay_is_read_in_seconds(motion):
    run = fitting.TakeFit(motion, {**PARAMS, "delay": 0.1}, True)
    assert run.prep.delay == int(round(0.1 * motion.fps))
    assert fitting.TakeFit(motion, PARAMS, True).prep.delay is None


def test_fit_rows_refusals(motion):
    run = fitting.TakeFit(motion, {**PARAMS, "class_index": 500}, True)
    with pytest.raises(ParameterError, match="class index 500 out of range: the barcode has"):
        run.fit_rows(np.arange(run.T), "")
    run = fitting.TakeFit(motion, {**PARAMS, "max_scale": 1e-6}, True)
    with pytest.raises(NoPeriodicMotionError, match="no H1 bar up to scale 1e-06") as info:
        run.fit_rows(np.arange(run.T), "")
    assert info.value.result.barcode is not None and info.value.result.selection is None


def test_fit_rows_refuses_a_bar_that_is_not_clear(motion, monkeypatch):
    real = fitting.first_clear

    def unclear(*a, **k):
        bc, sel = real(*a, **k)
        return bc, fitting.BarSelection(**{**sel.__dict__, "clear": False, "ratio": 1.2})

    monkeypatch.setattr(fitting, "first_clear", unclear)
    run = fitting.TakeFit(motion, PARAMS, True)
    with pytest.raises(NoPeriodicMotionError, match="death/birth 1.20 < 1.5.*--max-scale"):
        run.fit_rows(np.arange(run.T), "")
    # not required: the coordinate is fitted all the same, and its weak gap noted
    run = fitting.TakeFit(motion, PARAMS, False)
    fit = run.fit_rows(np.arange(run.T), "")
    assert fit.weak_gap is False and np.isfinite(fit.unwrapped).all()
    # a first pass is never refused
    run = fitting.TakeFit(motion, PARAMS, True)
    fit = run.fit_rows(np.arange(run.T), " (first pass)", first_pass=True)
    assert fit.est.landmarks == FIRST_PASS_LANDMARKS
    assert set(run.timings) >= {"barcode (first pass)", "coordinate (first pass)"}


def test_fit_rows_takes_a_bar_clear_but_for_its_gap(motion, monkeypatch):
    real = fitting.first_clear

    def gap_only(*a, **k):
        bc, sel = real(*a, **k)
        return bc, fitting.BarSelection(**{**sel.__dict__, "clear": False, "gap": CLEAR_GAP / 2})

    monkeypatch.setattr(fitting, "first_clear", gap_only)
    run = fitting.TakeFit(motion, PARAMS, True)
    fit = run.fit_rows(np.arange(run.T), "")  # not refused: judged by its windings later
    assert set(run.timings) >= {"barcode", "coordinate"}
    assert np.isfinite(fit.unwrapped).all()


def test_fit_rows_unwraps_the_coordinate_on_its_rows(motion):
    run = fitting.TakeFit(motion, PARAMS, True)
    rows = np.r_[0:50, 60:120]
    fit = run.fit_rows(rows, "")
    assert np.isnan(fit.unwrapped[50:60]).all() and np.isfinite(fit.unwrapped[rows]).all()
    # unwrapped inside each run, each run starting at its own frame's coordinate
    c = fit.est.coordinates_  # the coordinate of rows, in their order
    for (a, b), seg in (((0, 50), c[:50]), ((60, 120), c[50:])):
        want = np.unwrap(2 * np.pi * seg) / (2 * np.pi)
        np.testing.assert_allclose(fit.unwrapped[a:b], want, atol=1e-12)
    assert fit.rows is rows and fit.barcode is fit.est.barcode_


def test_fail_builds_a_partial_result(motion):
    run = fitting.TakeFit(motion, PARAMS, True)
    err = run.fail("nothing here")
    assert str(err).endswith(": nothing here")
    assert err.result.reason == "nothing here" and err.result.selection is None
    assert err.result.estimator is None and err.result.preprocessor is run.prep


def test_refine_birth_budget(motion, monkeypatch):
    seen = {}

    def spy(points, birth, prime, max_edges, covering_radius, coordinate):
        seen["max_edges"] = max_edges
        return 0.5

    monkeypatch.setattr(fitting, "refine_birth", spy)
    run = fitting.TakeFit(motion, PARAMS, True)
    sel = fitting.BarSelection(0, 1.0, 2.0, 1.5, True, 2.0, 3.0)
    for budget, want in ((None, 3_000_000), (256 * 1000, 1000), (1e12, 3_000_000)):
        est = NS(memory_budget_=budget, prime_=47, covering_radius_=0.1, coordinates_=np.zeros(3))
        if budget is None:
            del est.memory_budget_
        fit = NS(est=est, selection=sel)
        fitting.TakeFit._refine_birth(run, fit, np.arange(3))
        assert seen.pop("max_edges") == want and fit.selection.full_birth == 0.5
        assert est.selection_ is fit.selection
    est = NS(memory_budget_=100.0, prime_=47, covering_radius_=0.1, coordinates_=np.zeros(3))
    fit = NS(est=est, selection=sel)
    fitting.TakeFit._refine_birth(run, fit, np.arange(3))  # under one edge: not computed
    assert "max_edges" not in seen and fit.selection.full_birth is None


def test_first_clear_follows_its_bar_to_a_new_index():
    # a 12-gon of radius 1 (bar [0.518, 1.732)) and a 30-gon of radius 3 far away (bar
    # [0.627, 5.2)): at threshold 1 the 12-gon's bar is the most persistent; it is alive,
    # so the threshold is raised to 1.6, then 2.56, where the 12-gon's bar has died and the
    # 30-gon's (alive) is longer: the 12-gon's bar, followed by its birth, is now #1
    big = 3 * circle(30) + np.array([20.0, 0.0])
    x = np.concatenate([big, circle(12)])
    est = CircularCoordinates(landmarks=None, max_scale=1.0)
    bc, sel = first_clear(est, x, 0, None, 0.9)
    assert bc.threshold == pytest.approx(2.56)
    assert sel.index == 1 and est.class_index == 1
    assert sel.birth == pytest.approx(chord(12), rel=1e-6)
    assert sel.death == pytest.approx(np.sqrt(3), rel=1e-6)
    assert bc.h1[0, 0] == pytest.approx(3 * chord(30), rel=1e-6)


def test_coordinate_of_keeps_the_fit_warnings_as_notes(motion):
    run = fitting.TakeFit(motion, PARAMS, True)
    assert run.T == 120
    est = CircularCoordinates(landmarks=10, scale_fraction=0.01, refine_birth=False)
    est.fit_barcode(circle(60))
    fit = run.coordinate_of(est, np.arange(60))
    assert np.isfinite(fit.unwrapped[:60]).all() and np.isnan(fit.unwrapped[60:]).all()
    assert any(n.startswith("scale raised to") for n in fit.notes)
    assert fit.selection is est.selection_ and fit.est is est


# ---------------------------------------------------------------- fit_steady
def _steady_run(motion, monkeypatch, used_frames, **params):
    """TakeFit with steady on, frames 0-99 of 120 moving, and steady_frames giving
    ``used_frames`` (a slice of frames, or None for every moving frame)."""
    def moving(poses, fps, columns=None):
        out = np.zeros(len(poses), dtype=bool)
        out[:100] = True
        return out

    fitted = []

    def steady(motion_, prepared, joints, unwrapped, moving_, period):
        assert np.isfinite(period) and moving_.sum() == 100
        out = np.zeros(len(moving_), dtype=bool)
        out[used_frames] = True
        return out

    monkeypatch.setattr(fitting, "moving_mask", moving)
    monkeypatch.setattr(fitting, "steady_frames", steady)
    real = fitting.TakeFit.fit_rows

    def spy(self, rows, stage, first_pass=False):
        fitted.append((rows[0], rows[-1] + 1, stage, first_pass))
        return real(self, rows, stage, first_pass)

    monkeypatch.setattr(fitting.TakeFit, "fit_rows", spy)
    run = fitting.TakeFit(motion, {**PARAMS, "steady": True, **params}, True)
    assert run.moving.sum() == 100
    return run, fitted


def test_fit_steady_refits_on_the_steady_frames(motion, monkeypatch):
    run, fitted = _steady_run(motion, monkeypatch, slice(10, 90))
    fit, used = run.fit_steady()
    assert np.flatnonzero(used).tolist() == list(range(10, 90))
    assert fitted == [(0, 100, " (first pass)", False), (10, 90, "", False)]
    assert fit.rows.tolist() == list(range(10, 90))
    assert set(run.timings) >= {"prepare", "steady", "barcode", "coordinate"}
    assert "barcode (first pass)" not in run.timings
    # "steady" counts the first pass (tens of ms) and the steady frames' search (stubbed)
    assert run.timings["steady"] > 0 and all(t >= 0 for t in run.timings.values())
    assert not any("cyclecoord detect" in n for n in run.notes)


def test_fit_steady_keeps_the_first_fit_when_nearly_every_frame_is_steady(motion, monkeypatch):
    run, fitted = _steady_run(motion, monkeypatch, slice(0, 95))  # 95 % of the moving frames
    fit, used = run.fit_steady()
    assert used.sum() == 100 and fitted == [(0, 100, " (first pass)", False)]
    assert set(run.timings) >= {"steady", "barcode", "coordinate"}
    run, fitted = _steady_run(motion, monkeypatch, slice(0, 94))  # under 95 %: refitted
    fit, used = run.fit_steady()
    assert used.sum() == 94 and len(fitted) == 2


def test_fit_steady_notes_when_most_moving_frames_are_not_the_motion(motion, monkeypatch):
    run, _ = _steady_run(motion, monkeypatch, slice(0, 49))  # 51 of 100 not used: noted
    run.fit_steady()
    note = [n for n in run.notes if "cyclecoord detect" in n]
    assert note and note[0].startswith("only 49 of the take's 100 moving frames")
    run, _ = _steady_run(motion, monkeypatch, slice(0, 50))  # exactly half: not noted
    run.fit_steady()
    assert not any("cyclecoord detect" in n for n in run.notes)


def test_fit_steady_failures(motion, monkeypatch):
    run, _ = _steady_run(motion, monkeypatch, slice(0, 0))
    with pytest.raises(NoPeriodicMotionError, match="no stretch of the take repeats steadily"):
        run.fit_steady()
    run, _ = _steady_run(motion, monkeypatch, slice(10, 90), min_turns=1000)
    with pytest.raises(NoPeriodicMotionError, match="turns only .* over the 100 steady frames"):
        run.fit_steady()


def test_fit_steady_without_steady_fits_every_frame_once(motion, monkeypatch):
    calls = []
    real = fitting.TakeFit.fit_rows

    def spy(self, rows, stage, first_pass=False):
        calls.append((len(rows), stage, first_pass))
        return real(self, rows, stage, first_pass)

    monkeypatch.setattr(fitting.TakeFit, "fit_rows", spy)
    run = fitting.TakeFit(motion, PARAMS, True)
    fit, used = run.fit_steady()
    assert calls == [(120, "", False)] and used.all() and "steady" not in run.timings


def test_first_clear_raises_the_threshold_at_most_six_times():
    # two equal 90-gons far apart: equal bars, so neither is clear (gap 1); born at 0.0698
    # and dying at sqrt 3, they are cut short at every threshold from 0.07 up to
    # 0.07 x 1.6^6 = 1.17, where the sixth raise stops
    a = circle(90)
    x = np.concatenate([a, a + np.array([10.0, 0.0])])
    est = CircularCoordinates(landmarks=None, max_scale=0.07)
    bc, sel = first_clear(est, x, 0, None, 0.9)
    assert bc.threshold == pytest.approx(0.07 * 1.6**6)
    assert sel.death == np.inf and not sel.clear and est.max_scale == 0.07
