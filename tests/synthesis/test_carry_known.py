"""Known answers for the pieces of ``synthesis.carry`` (the root's scale, the hold's ease,
the channel bounds, a lock that pins nothing)."""

import numpy as np
import pytest

from cyclecoord.synthesis import carry

from _legs import legs_skeleton, make_motion  # tests/ is on the path (rootdir conftest)


def test_translation_scale_is_one_world_unit_per_channel_unit():
    m = make_motion(legs_skeleton(), T=5, fps=30.0, root_speed=3.0)
    for dof in ("tx", "ty", "tz"):
        col = m.channels.index(("root", dof))
        assert carry._translation_scale(m, col) == pytest.approx(1.0)


def test_the_floor_lifts_the_root_by_the_depth_of_the_lowest_foot():
    """Feet 0.3 units under the given floor on every frame: the root rises by exactly 0.3
    (a constant depth, so the smoothing of the lift changes nothing)."""
    m = make_motion(legs_skeleton(), T=30, fps=30.0)
    feet = ("lfoot", "ltoes", "rfoot", "rtoes")
    low = carry._lowest_points(m, feet)
    out = carry.carry_by_feet(m, feet, floor=float(low.min()) + 0.3)
    ty = m.channels.index(("root", "ty"))
    np.testing.assert_allclose(out.frames[:, ty] - m.frames[:, ty], 0.3, atol=1e-9)


def test_lowest_points_are_the_feet_and_their_end_sites():
    m = make_motion(legs_skeleton(), T=3, fps=30.0)
    pos = m.positions()
    want = min(pos["ltoes"][0, 1], pos["rtoes"][0, 1], pos["ltoes/end"][0, 1])
    assert carry._lowest_points(m, ("lfoot", "ltoes", "rfoot", "rtoes"))[0] == pytest.approx(want)
    # a foot list without the toes: the ankles only (the toes' end sites are not theirs)
    ankles = carry._lowest_points(m, ("lfoot", "rfoot"))
    np.testing.assert_allclose(ankles, np.minimum(pos["lfoot"][:, 1], pos["rfoot"][:, 1]))


def test_a_hold_eases_its_steps_to_nothing_over_stand_after_seconds():
    """The factor on each step: 1 outside the hold, a smoothstep from 1 to 0 over
    STAND_AFTER s into it (by hand at a quarter of the way: 1 - (3u^2 - 2u^3))."""
    fps = 30.0
    hold = np.zeros(90, dtype=bool)
    hold[30:] = True
    f = carry._moving(hold, fps)
    n = int(round(carry.STAND_AFTER * fps))  # 15 frames
    assert f.shape == (89,)
    np.testing.assert_allclose(f[:29], 1.0)
    frame = np.ones(90)
    u = np.clip((np.arange(30, 90) - 30) / n, 0, 1)
    frame[30:] = 1 - u * u * (3 - 2 * u)
    np.testing.assert_allclose(f, 0.5 * (frame[1:] + frame[:-1]))
    assert 0.5 < f[32] < 0.95  # easing, not a stop within a frame
    np.testing.assert_allclose(f[30 + n :], 0.0)


def test_channel_bounds_leave_the_root_free_and_widen_the_rest():
    m = make_motion(legs_skeleton(), T=10, fps=30.0, root_speed=5.0)
    lo, hi = carry.channel_bounds([m], margin=5.0)
    for c in m.root_channels():
        assert lo[c] == -np.inf and hi[c] == np.inf
    other = [i for i in range(len(m.channels)) if i not in m.root_channels()]
    np.testing.assert_allclose(lo[other], m.frames[:, other].min(axis=0) - 5.0)
    np.testing.assert_allclose(hi[other], m.frames[:, other].max(axis=0) + 5.0)


def test_a_lock_whose_every_pin_pops_pins_nothing_and_says_so(monkeypatch):
    from test_footlock import _walkish  # noqa: E402  (tests/synthesis on the path)

    m = _walkish(T=120, fps=60.0)
    calls = []

    def popping(motion):  # clean before, popping everywhere once anything is pinned
        calls.append(1)
        return np.zeros(motion.n_frames) if len(calls) == 1 else np.full(motion.n_frames, 9.0)

    monkeypatch.setattr(carry, "_accel", popping)
    out = carry.lock_where_clean(m, 1.0)
    assert out.locked == 0
    assert out.motion is m
    assert out.line.startswith("foot locking: not done")
