"""Tests of the quality measures: jerk, loop closure, distance to cycle, phase agreement."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from cyclecoord.errors import ParameterError
from cyclecoord.quality.metrics import (
    PhaseAgreement,
    circular_distance,
    distance_to_cycle,
    finite_difference_coefficients,
    jerk,
    jerk_summary,
    loop_closure,
    monotonicity,
)


# ------------------------------------------------------------ finite differences
def test_known_third_derivative_rows():
    np.testing.assert_allclose(finite_difference_coefficients(3, 1), [-1, 3, -3, 1], atol=1e-14)
    np.testing.assert_allclose(finite_difference_coefficients(3, 2), [-5 / 2, 9, -12, 7, -3 / 2], atol=1e-14)


@pytest.mark.parametrize("derivative,accuracy", [(1, 1), (1, 2), (2, 3), (3, 4), (4, 2)])
def test_coefficients_satisfy_taylor_conditions(derivative, accuracy):
    c = finite_difference_coefficients(derivative, accuracy)
    j = np.arange(c.size, dtype=float)
    moments = np.array([(c * j**m).sum() for m in range(c.size)])
    expected = np.zeros(c.size)
    expected[derivative] = float(np.prod(np.arange(1, derivative + 1)))
    np.testing.assert_allclose(moments, expected, atol=1e-8)
    assert c.size == derivative + accuracy
    assert abs(c.sum()) < 1e-10 or derivative == 0


def test_first_derivative_rows():
    np.testing.assert_allclose(finite_difference_coefficients(1, 1), [-1, 1])
    np.testing.assert_allclose(finite_difference_coefficients(1, 2), [-1.5, 2, -0.5])


@pytest.mark.parametrize("args", [(-1, 2), (3, 0), (3, 40), (2.5, 2)])
def test_bad_coefficient_orders(args):
    with pytest.raises(ParameterError):
        finite_difference_coefficients(*args)


def test_the_longest_stencil_is_32_points():
    """A stencil of 32 points is built (the 31st forward difference: alternating binomial
    coefficients, exactly); one of 33 is refused."""
    from math import comb

    c = finite_difference_coefficients(31, 1)
    np.testing.assert_array_equal(c, [(-1) ** (31 - j) * comb(31, j) for j in range(32)])
    for derivative, accuracy in ((32, 1), (1, 32), (0, 33)):
        with pytest.raises(ParameterError, match="stencil of 33 points is too long"):
            finite_difference_coefficients(derivative, accuracy)


# --------------------------------------------------------------------------- jerk
def test_jerk_exact_on_cubics_and_zero_on_quadratics():
    fps = 120.0
    t = np.arange(50) / fps
    cubic = np.stack([2.0 * t**3 - t**2 + 5, -0.5 * t**3 + 3 * t], axis=1)
    j = jerk(cubic, fps)
    assert j.shape == (50 - 7 + 1, 2)
    np.testing.assert_allclose(j[:, 0], 12.0, rtol=1e-6)
    np.testing.assert_allclose(j[:, 1], -3.0, rtol=1e-6)
    quad = 4 * t**2 - t + 1
    np.testing.assert_allclose(jerk(quad, fps), 0.0, atol=1e-5)
    # other accuracies are exact on cubics too
    np.testing.assert_allclose(jerk(cubic, fps, accuracy=1)[:, 0], 12.0, rtol=1e-6)


def test_cyclic_jerk_of_a_sine_matches_analytic():
    fps = 120.0
    n = 96  # one period of 0.8 s
    t = np.arange(n) / fps
    omega = 2 * np.pi * fps / n
    x = 3.0 * np.sin(omega * t)
    analytic = -3.0 * omega**3 * np.cos(omega * t)
    j = jerk(x, fps, cyclic=True)
    assert j.shape == (n, 1)
    assert np.abs(j[:, 0] - analytic).max() < 0.01 * np.abs(analytic).max()
    # the seam counts: an open arc of the same sine has a huge jerk at the wrap
    arc = 3.0 * np.sin(0.8 * omega * t)
    assert np.abs(jerk(arc, fps, cyclic=True)).max() > 10 * np.abs(analytic).max()


def test_jerk_summary_units():
    fps = 100.0
    t = np.arange(30) / fps
    frames = np.stack([t**3, 2 * t**3], axis=1)  # jerk (6, 12): norm 6 sqrt 5
    assert jerk_summary(frames, fps) == pytest.approx(6 * np.sqrt(5), rel=1e-5)
    # doubling the frame rate of the same motion leaves the jerk unchanged (units / s^3)
    t2 = np.arange(60) / (2 * fps)
    frames2 = np.stack([t2**3, 2 * t2**3], axis=1)
    assert jerk_summary(frames2, 2 * fps) == pytest.approx(6 * np.sqrt(5), rel=1e-5)


def test_jerk_bad_input():
    with pytest.raises(ParameterError):
        jerk(np.zeros((6, 2)), 120.0)  # 7-point stencil
    with pytest.raises(ParameterError):
        jerk(np.zeros((20, 2)), 0.0)
    with pytest.raises(ParameterError):
        jerk(np.full((20, 2), np.nan), 120.0)


# --------------------------------------------------------------------- loop closure
def test_loop_closure_circle_and_arc():
    a = 2 * np.pi * np.arange(60) / 60
    circle = np.stack([np.cos(a), np.sin(a)], axis=1)
    assert loop_closure(circle) == pytest.approx(1.0, abs=1e-9)
    arc = circle[:40]
    assert loop_closure(arc) > 10
    assert loop_closure(np.ones((5, 3))) == 1.0
    with pytest.raises(ParameterError):
        loop_closure(np.zeros((1, 3)))


# ---------------------------------------------------------------- distance to cycle
def test_distance_to_cycle_on_and_off_the_polyline():
    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]) + 100.0
    on = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 1.3], [0.0, 0.5], [0.7, 2.0]]) + 100.0
    np.testing.assert_allclose(distance_to_cycle(on, square), 0.0, atol=1e-12)
    # the closing segment (last -> first) counts: (0, 1) lies on it
    assert distance_to_cycle([[100.0, 101.0]], square)[0] == pytest.approx(0.0, abs=1e-12)
    off = np.array([[1.0, 1.0], [3.0, 3.0], [1.0, -0.5], [-1.0, 1.0]]) + 100.0
    np.testing.assert_allclose(distance_to_cycle(off, square), [1.0, np.sqrt(2), 0.5, 1.0], atol=1e-12)


def test_distance_to_cycle_matches_brute_force_in_chunks(monkeypatch):
    import cyclecoord.quality.metrics as metrics

    rng = np.random.default_rng(0)
    cycle = rng.standard_normal((17, 6))
    frames = rng.standard_normal((300, 6))
    monkeypatch.setattr(metrics, "_CHUNK_ELEMENTS", 17 * 7)  # force many chunks
    got = distance_to_cycle(frames, cycle)
    a, b = cycle, np.roll(cycle, -1, axis=0)
    v = b - a
    s = np.clip(np.einsum("tpd,pd->tp", frames[:, None] - a, v) / (v * v).sum(1), 0, 1)
    brute = np.linalg.norm(frames[:, None] - a - s[..., None] * v, axis=2).min(axis=1)
    np.testing.assert_allclose(got, brute, atol=1e-12)


def test_distance_to_cycle_bad_input():
    with pytest.raises(ParameterError):
        distance_to_cycle(np.zeros((3, 2)), np.zeros((4, 3)))
    with pytest.raises(ParameterError):
        distance_to_cycle(np.zeros((3, 2)), np.zeros((0, 2)))


# ------------------------------------------------------------------ phase agreement
def test_circular_distance():
    np.testing.assert_allclose(circular_distance([0.05, 0.5, 0.3], [0.95, 0.0, 2.3]), [0.1, 0.5, 0.0], atol=1e-12)


def _warped(phase):
    return np.mod(phase + 0.06 * np.sin(2 * np.pi * phase), 1.0)  # monotone warp, max 0.06


def test_monotonicity_of_a_warped_phase():
    phase = np.arange(500) / 97.3  # ~5 periods, unwrapped
    res = monotonicity(np.mod(_warped(phase) + 0.37, 1.0), phase)
    assert isinstance(res, PhaseAgreement)
    assert res.fraction_monotone == 1.0
    assert res.orientation == 1
    assert 0.03 < res.max_abs_error_after_alignment < 0.061
    assert res.mean_abs_error_after_alignment < res.max_abs_error_after_alignment
    exact = monotonicity(np.mod(phase + 0.37, 1.0), phase)
    assert exact.max_abs_error_after_alignment < 1e-9
    assert exact.offset == pytest.approx(0.63, abs=1e-9)


def test_monotonicity_handles_reflection():
    phase = np.arange(500) / 97.3
    res = monotonicity(np.mod(0.2 - _warped(phase), 1.0), phase)
    assert res.orientation == -1
    assert res.fraction_monotone == 1.0
    assert res.max_abs_error_after_alignment < 0.061


def test_monotonicity_is_low_for_random_theta():
    rng = np.random.default_rng(0)
    phase = np.arange(500) / 97.3
    res = monotonicity(rng.random(500), phase)
    assert res.fraction_monotone < 0.65
    assert res.max_abs_error_after_alignment > 0.4
    assert res.mean_abs_error_after_alignment > 0.15


def test_monotonicity_counts_backward_steps():
    phase = np.arange(100) / 25.0
    theta = np.mod(phase, 1.0)
    theta[[10, 40, 70]] -= 0.05  # three glitches: the step into each goes back
    res = monotonicity(theta, phase)
    assert res.fraction_monotone == pytest.approx(1 - 3 / 99)


def test_monotonicity_bad_input():
    with pytest.raises(ParameterError):
        monotonicity(np.zeros(5), np.zeros(4))
    with pytest.raises(ParameterError):
        monotonicity(np.zeros(1), np.zeros(1))
    with pytest.raises(ParameterError):
        monotonicity(np.array([0.1, np.nan]), np.zeros(2))


def test_blockwise_figures_equal_whole_array_ones_bit_for_bit(monkeypatch):
    import cyclecoord.quality.metrics as qm

    rng = np.random.default_rng(3)
    x = np.cumsum(rng.normal(size=(1000, 7)), axis=0)
    whole_jerk = float(np.linalg.norm(qm.jerk(x, 120.0), axis=1).mean())
    whole_steps = np.linalg.norm(np.diff(x, axis=0), axis=1)
    monkeypatch.setattr(qm, "_CHUNK_ELEMENTS", 7 * 33)  # blocks of 33 frames
    assert qm.jerk_summary(x, 120.0) == whole_jerk
    np.testing.assert_array_equal(qm.frame_steps(x), whole_steps)
    with pytest.raises(ParameterError):
        qm.jerk_summary(x[:5], 120.0)


def test_cyclic_jerk_summary_is_the_open_one_over_the_loop_continued():
    """jerk_summary uses the 4th-order formula (a 7-point stencil) with or without
    ``cyclic``: over a loop it equals the open figure over the loop followed by its first
    6 frames, i.e. the mean norm of jerk(accuracy=4, cyclic=True); another order differs."""
    from cyclecoord.quality.metrics import jerk, jerk_summary

    t = np.arange(40) / 40
    x = np.column_stack([np.sin(2 * np.pi * t), np.cos(6 * np.pi * t), 0.3 * np.sin(10 * np.pi * t)])
    loop = jerk_summary(x, 30.0, cyclic=True)
    assert loop == pytest.approx(jerk_summary(np.vstack([x, x[:6]]), 30.0), rel=1e-12)
    j4 = np.linalg.norm(jerk(x, 30.0, accuracy=4, cyclic=True), axis=1).mean()
    j5 = np.linalg.norm(jerk(x, 30.0, accuracy=5, cyclic=True), axis=1).mean()
    assert loop == pytest.approx(j4, rel=1e-12) and abs(j5 / j4 - 1) > 1e-3


# ------------------------------------------------------------ helpers, known answers
def test_argument_checks():
    from cyclecoord.quality.metrics import _check_fps, _check_int, _frames_array

    assert _frames_array([1.0, 2.0], "x").shape == (2, 1)
    assert _frames_array([[1, 2]], "x").dtype == float
    with pytest.raises(ParameterError, match="x must be an array of numbers"):
        _frames_array(["a"], "x")
    with pytest.raises(ParameterError, match=r"x must be a \(T, D\) array, got shape \(1, 1, 1\)"):
        _frames_array(np.zeros((1, 1, 1)), "x")
    with pytest.raises(ParameterError, match="NaN or infinite"):
        _frames_array([0.0, np.inf], "x")
    assert _check_int(np.int64(3), "n", 3) == 3 and type(_check_int(np.int64(3), "n", 3)) is int
    for bad in (2, True, 3.0, "3"):
        with pytest.raises(ParameterError, match="n must be an integer >= 3"):
            _check_int(bad, "n", 3)
    assert _check_fps(np.float32(0.5)) == 0.5 and _check_fps(30) == 30.0
    for bad in (0, -1.0, np.inf, np.nan, True, "30"):
        with pytest.raises(ParameterError, match="fps must be a positive number"):
            _check_fps(bad)


def test_coefficients_of_order_zero_and_as_floats():
    """The 0th derivative to accuracy 3 is the point itself; the 2nd to accuracy 1 the
    classic 1, -2, 1 (Fornberg's table)."""
    np.testing.assert_array_equal(finite_difference_coefficients(0, 3), [1, 0, 0])
    np.testing.assert_array_equal(finite_difference_coefficients(2, 1), [1, -2, 1])
    np.testing.assert_allclose(finite_difference_coefficients(2, 2), [2, -5, 4, -1])


def test_jerk_rows_and_the_cyclic_wrap_by_hand():
    """accuracy 1 at 1 fps: jerk[t] = -x[t] + 3 x[t+1] - 3 x[t+2] + x[t+3]; cyclic, the
    frames after the last are the first ones again; at 2 fps 8 times that."""
    x = np.array([0.0, 1.0, 0.0, 0.0, 2.0])
    np.testing.assert_allclose(jerk(x, 1.0, accuracy=1), [[3], [1]])
    np.testing.assert_allclose(jerk(x, 2.0, accuracy=1), [[24], [8]])
    loop = np.array([-x[t] + 3 * x[(t + 1) % 5] - 3 * x[(t + 2) % 5] + x[(t + 3) % 5]
                     for t in range(5)])
    np.testing.assert_allclose(jerk(x, 1.0, accuracy=1, cyclic=True)[:, 0], loop)
    assert jerk(x[:4], 1.0, accuracy=1).shape == (1, 1)
    with pytest.raises(ParameterError, match="accuracy 2 needs at least 5 frames, got 4"):
        jerk(x[:4], 1.0, accuracy=2)
    assert jerk(x, 1.0, accuracy=2, cyclic=True).shape == (5, 1)
    # the summary: the mean of the rows' norms, 4th order (7 points), open or looped
    y = np.column_stack([np.arange(9.0) ** 3, np.zeros(9)])  # jerk 6 everywhere
    assert jerk_summary(y, 1.0) == pytest.approx(6.0, rel=1e-9)
    assert jerk_summary(y, 2.0) == pytest.approx(48.0, rel=1e-9)
    with pytest.raises(ParameterError, match="fps"):
        jerk_summary(y, 0.0)
    with pytest.raises(ParameterError, match="accuracy 4 needs at least 7 frames, got 6"):
        jerk_summary(y[:6], 1.0)


def test_frame_steps_and_largest_steps_by_hand():
    from cyclecoord.quality.metrics import frame_steps, largest_steps

    x = np.array([[0.0, 0.0], [3.0, 4.0], [3.0, 4.0], [3.0, 5.0]])
    np.testing.assert_array_equal(frame_steps(x), [5.0, 0.0, 1.0])
    assert frame_steps(x[:1]).shape == (0,) and frame_steps(np.zeros((0, 2))).shape == (0,)
    # the cycle's steps go round the loop: the seam (3, 5) -> (0, 0) is the largest
    cyc, p99 = largest_steps(x, x)
    assert cyc == pytest.approx(np.sqrt(34.0))
    assert p99 == pytest.approx(np.percentile([5.0, 0.0, 1.0], 99))
    # masked frames: only steps between two consecutive frames in the mask
    assert largest_steps(x, x, [False, True, True, True])[1] == pytest.approx(
        np.percentile([0.0, 1.0], 99))
    assert largest_steps(x, x, [True, False, True, True])[1] == 1.0
    cyc, p99 = largest_steps(np.zeros((0, 2)), x, [True, False, True, False])
    assert np.isnan(cyc) and np.isnan(p99)


def test_distance_to_cycle_single_point_and_repeated_frames():
    """A cycle of one point: distances to it; a repeated frame (a segment of no length)
    is a point too."""
    np.testing.assert_allclose(distance_to_cycle([[3.0, 4.0], [0.0, 0.0]], [[0.0, 0.0]]),
                               [5.0, 0.0])
    seg = [[0.0, 0.0], [0.0, 0.0], [4.0, 0.0]]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no division by the zero-length segment
        got = distance_to_cycle([[2.0, 3.0], [-1.0, 0.0], [5.0, 0.0]], seg)
    np.testing.assert_allclose(got, [3.0, 1.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(distance_to_cycle([2.0, -1.0], [0.0, 4.0]), [0.0, 1.0])


def test_loop_closure_by_hand():
    # steps 1, 1, 2: median 1; the seam (3, 0) -> (0, 0) is 3
    assert loop_closure([[0.0, 0], [1, 0], [2, 0], [3, 0]]) == 1.5 * 2
    assert loop_closure([[0.0], [1.0], [1.0], [1.0]]) == np.inf
    assert loop_closure([[0.0], [0.0]]) == 1.0
    assert loop_closure([[0.0], [2.0]]) == 1.0  # one step, there and back


def test_wrap_half_and_minimax_offset():
    from cyclecoord.quality.metrics import _minimax_offset, _wrap_half

    np.testing.assert_allclose(_wrap_half(np.array([0.5, -0.5, 0.7, -0.7, 0.0, 1.2])),
                               [0.5, 0.5, -0.3, 0.3, 0.0, 0.2], atol=1e-15)
    # residuals 0.9, 0.1, 0.2 on the circle: the shortest arc holding them runs 0.9 -> 0.2
    # (0.3 long), centred at 0.05
    c, half = _minimax_offset(np.array([0.1, -0.1, 1.2]))
    assert c == pytest.approx(0.05) and half == pytest.approx(0.15)
    c, half = _minimax_offset(np.array([0.3, 0.3]))
    assert c == pytest.approx(0.3) and half == 0.0
    c, half = _minimax_offset(np.array([0.2, 0.4]))
    assert c == pytest.approx(0.3) and half == pytest.approx(0.1)


def test_monotonicity_by_hand():
    """theta = 0.2 - phase: reflected, offset 0.2 (phase = 0.2 - theta); a true phase that
    never moves gives no monotone fraction; a tie between the orientations keeps +1."""
    phase = np.array([0.0, 0.1, 0.2, 0.3])
    res = monotonicity(np.mod(0.2 - phase, 1.0), phase)
    assert res.orientation == -1 and res.offset == pytest.approx(0.2)
    assert res.fraction_monotone == 1.0 and res.max_abs_error_after_alignment < 1e-12
    still = monotonicity(np.array([0.1, 0.3]), np.array([0.5, 0.5]))
    assert np.isnan(still.fraction_monotone) and still.orientation == 1
    assert still.max_abs_error_after_alignment == pytest.approx(0.1)
    assert still.mean_abs_error_after_alignment == pytest.approx(0.1)
    # one step back of four: 3 / 4 monotone; errors after the best offset by hand
    theta = np.array([0.0, 0.1, 0.3, 0.25, 0.4])
    ph = np.array([0.0, 0.1, 0.2, 0.3, 0.4])
    res = monotonicity(theta, ph)
    assert res.orientation == 1 and res.fraction_monotone == 0.75
    # residuals phase - theta: 0, 0, -0.1, 0.05, 0: arc -0.1 .. 0.05, centre -0.025
    assert res.offset == pytest.approx(0.975) and res.max_abs_error_after_alignment == pytest.approx(0.075)
    assert res.mean_abs_error_after_alignment == pytest.approx((0.025 * 3 + 0.075 + 0.075) / 5)


def test_phase_agreement_is_frozen():
    from dataclasses import FrozenInstanceError

    res = monotonicity(np.array([0.0, 0.1, 0.2]), np.array([0.0, 0.1, 0.2]))
    with pytest.raises(FrozenInstanceError):
        res.orientation = -1
    assert hash(res) == hash(monotonicity(np.array([0.0, 0.1, 0.2]), np.array([0.0, 0.1, 0.2])))


def test_distance_to_a_small_cycle_scales():
    """The square of side 2 and its points scaled by 1/100 (segments of length 0.02):
    distances scale by 1/100 too, the segments' interiors counted however short."""
    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    pts = np.array([[1.0, 1.0], [3.0, 3.0], [1.0, -0.5], [1.0, 0.0], [2.0, 1.3]])
    np.testing.assert_allclose(distance_to_cycle(pts / 100, square / 100),
                               [0.01, np.sqrt(2) / 100, 0.005, 0.0, 0.0], atol=1e-15)
