"""periodic.rotations against known answers: rotation vectors of rotations built from known
vectors about a known mean (scipy.spatial.transform builds them here), circular means by
hand, the safety thresholds at their edges, the map's file arrays and their checks."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from cyclecoord.motion import Motion
from cyclecoord.periodic.rotations import (
    RotationMap,
    _Group,
    circular_mean_degrees,
    euler_is_safe,
    fit_rotation_map,
)


def test_circular_mean_by_hand():
    np.testing.assert_allclose(circular_mean_degrees([[350.0, 90.0], [10.0, 180.0]]), [0.0, 135.0], atol=1e-12)
    np.testing.assert_allclose(circular_mean_degrees([[270.0]]), [-90.0], atol=1e-12)
    np.testing.assert_allclose(circular_mean_degrees([[170.0], [-170.0], [180.0]]), [180.0], atol=1e-9)
    np.testing.assert_allclose(circular_mean_degrees([[0.0], [60.0], [120.0]]), [60.0], atol=1e-12)


def test_euler_safety_at_its_thresholds():
    base = np.zeros((3, 3))
    assert euler_is_safe(np.zeros((0, 3)))
    assert euler_is_safe(base)
    step = base.copy()
    step[1:, 0] = 45.0  # a step of exactly 45 is allowed
    assert euler_is_safe(step)
    step[2, 0] = 90.0 + 1e-9  # one a hair over 45
    assert not euler_is_safe(step)
    mid = base.copy()
    mid[:, 1] = 85.0  # the middle angle at exactly 85 (no step)
    assert euler_is_safe(mid)
    mid[:, 1] = -85.0 - 1e-9
    assert not euler_is_safe(mid)
    assert not euler_is_safe(np.array([[0.0, 86.0, 0.0]]))  # one frame: no steps, still checked
    assert euler_is_safe(np.array([[500.0, 10.0, -400.0]]))  # one frame spans nothing
    # a slow pass over 270 degrees in 40-degree steps: span 270 allowed, more not
    ramp = np.zeros((28, 3))
    ramp[:, 2] = np.linspace(0.0, 270.0, 28)
    assert euler_is_safe(ramp)
    ramp[:, 2] = np.linspace(0.0, 270.0 + 1e-6, 28)
    assert not euler_is_safe(ramp)


MEAN = Rotation.from_euler("xyz", [20.0, -30.0, 40.0], degrees=True)
V = np.array([[10.0, -20.0, 5.0], [0.0, 0.0, 0.0], [-3.0, 7.0, 30.0]])


def _map(order="ZXY", cols=(2, 0, 4), hinge=(1,), centre=(0.0,)):
    return RotationMap(groups=(_Group(columns=np.array(cols), order=order, mean=MEAN),),
                       hinge_columns=np.array(hinge, dtype=int), hinge_centres=np.array(centre, dtype=float))


def test_to_vectors_gives_the_rotation_vector_about_the_mean():
    """Channels of mean * exp(v) read back v, its x, y, z in the group's columns in turn;
    other columns are copied."""
    rmap = _map()
    R = MEAN * Rotation.from_rotvec(V, degrees=True)
    frames = np.zeros((3, 6))
    frames[:, [2, 0, 4]] = R.as_euler("ZXY", degrees=True)
    frames[:, 3] = [7.0, 8.0, 9.0]
    frames[:, 5] = [1.0, 2.0, 3.0]
    frames[:, 1] = [10.0, 200.0, -190.0]  # hinge, centre 0: kept within 180 of it
    out = rmap.to_vectors(frames)
    np.testing.assert_allclose(out[:, [2, 0, 4]], V, atol=1e-9)
    np.testing.assert_array_equal(out[:, [3, 5]], frames[:, [3, 5]])
    np.testing.assert_allclose(out[:, 1], [10.0, -160.0, 170.0])
    # wrapped and flipped Euler numbers of the same rotations read the same vectors
    a = frames[:, [2, 0, 4]]
    alt = np.column_stack([a[:, 0] + 180.0 + 360.0, 180.0 - a[:, 1], a[:, 2] - 180.0])
    flipped = frames.copy()
    flipped[:, [2, 0, 4]] = alt
    np.testing.assert_allclose(rmap.to_vectors(flipped)[:, [2, 0, 4]], V, atol=1e-9)
    with pytest.raises(ValueError, match=r"\(T, D\)"):
        rmap.to_vectors(np.zeros(6))
    np.testing.assert_array_equal(rmap.columns, [2, 0, 4, 1])


def test_to_channels_inverts_and_takes_the_reference_branch():
    rmap = _map()
    vec = np.zeros((3, 6))
    vec[:, [2, 0, 4]] = V
    vec[:, 1] = [10.0, 20.0, 30.0]
    vec[:, 3] = 5.0
    ch = rmap.to_channels(vec)
    want = (MEAN * Rotation.from_rotvec(V, degrees=True)).as_matrix()
    got = Rotation.from_euler("ZXY", ch[:, [2, 0, 4]], degrees=True).as_matrix()
    np.testing.assert_allclose(got, want, atol=1e-9)
    np.testing.assert_array_equal(ch[:, 1], [10.0, 20.0, 30.0])  # no reference: as given
    np.testing.assert_array_equal(ch[:, 3], 5.0)
    # a reference frame: hinges move by whole turns to its branch, Euler angles near it
    near = np.zeros(6)
    near[1] = 725.0  # two turns up: 10 -> 730
    near[[2, 0, 4]] = ch[0, [2, 0, 4]] + [360.0, 0.0, -360.0]
    ch2 = rmap.to_channels(vec, near=near)
    np.testing.assert_allclose(ch2[:, 1], [730.0, 740.0, 750.0])
    np.testing.assert_allclose(ch2[0, [2, 0, 4]], near[[2, 0, 4]], atol=1e-9)
    near[1] = -170.0 - 180.0 + 1.0  # -349: nearer -350 than 10, one turn down
    np.testing.assert_allclose(rmap.to_channels(vec, near=near)[:, 1], [-350.0, -340.0, -330.0])
    # the turns are counted from the first row's angle to the reference's
    vec[:, 1] = [100.0, 110.0, 120.0]
    for ref, want in ((460.0, 460.0), (-250.0, -260.0), (-100.0, -260.0), (-70.0, 100.0), (640.0, 820.0)):
        near[1] = ref
        np.testing.assert_allclose(rmap.to_channels(vec, near=near)[:, 1], want + np.array([0.0, 10.0, 20.0]))


def _skeleton_motion(T=50, seed=0):
    from tests._legs import legs_skeleton

    sk = legs_skeleton()
    rng = np.random.default_rng(seed)
    f = np.zeros((T, len(sk.channels)))
    col = {c: i for i, c in enumerate(sk.channels)}
    for d in ("rx", "ry", "rz"):
        f[:, col[("lfemur", d)]] = rng.uniform(-30, 30, T)
        f[:, col[("rfemur", d)]] = 5.0 * np.sin(np.arange(T) / 5.0)  # small and smooth: safe
    f[:, col[("ltibia", "rx")]] = 170.0 + rng.uniform(0, 20, T)  # passes +-180
    return Motion(f, sk.channels, fps=30.0, skeleton=sk), col


def test_fit_rotation_map_means_groups_and_hinges():
    m, col = _skeleton_motion()
    root = np.asarray(m.root_channels())
    rmap = fit_rotation_map(m, exclude=root)
    names = {tuple(m.channels[c][0] for c in g.columns) for g in rmap.groups}
    assert names == {("lfemur",) * 3, ("rfemur",) * 3}
    g = next(g for g in rmap.groups if m.channels[g.columns[0]][0] == "lfemur")
    assert g.order == "ZYX" and [m.channels[c][1] for c in g.columns] == ["rz", "ry", "rx"]
    want = Rotation.from_euler("ZYX", m.frames[:, g.columns], degrees=True).mean()
    np.testing.assert_allclose(g.mean.as_matrix(), want.as_matrix(), atol=1e-12)
    hinges = [c for c in range(m.n_channels) if m.channels[c][1] == "rx" and m.channels[c][0] in
              ("ltibia", "lfoot", "ltoes", "rtibia", "rfoot", "rtoes")]
    np.testing.assert_array_equal(rmap.hinge_columns, sorted(hinges))
    i = list(rmap.hinge_columns).index(col[("ltibia", "rx")])
    a = np.radians(m.frames[:, col[("ltibia", "rx")]])
    assert rmap.hinge_centres[i] == pytest.approx(np.degrees(np.arctan2(np.sin(a).mean(), np.cos(a).mean())))
    # "auto": the small smooth right thigh keeps its channels, the jumping left one does not
    auto = fit_rotation_map(m, exclude=root, mode="auto")
    assert [m.channels[g.columns[0]][0] for g in auto.groups] == ["lfemur"]
    # frames: the means are fitted on the frames given
    shifted = m.frames.copy()
    shifted[:, g.columns] = [10.0, 0.0, 0.0]
    other = fit_rotation_map(m, exclude=root, frames=shifted)
    go = next(h for h in other.groups if m.channels[h.columns[0]][0] == "lfemur")
    np.testing.assert_allclose(go.mean.as_matrix(), Rotation.from_euler("ZYX", [10.0, 0, 0], degrees=True).as_matrix(),
                               atol=1e-12)
    # without exclusion the root is a group as well
    assert len(fit_rotation_map(m).groups) == 3


def test_map_arrays_round_trip_and_checks():
    rmap = _map()
    arrays = rmap.to_arrays()
    assert arrays["group_columns"].tolist() == [[2, 0, 4]] and arrays["group_orders"].tolist() == ["ZXY"]
    back = RotationMap.from_arrays(arrays, 5)  # columns up to 4 of 5 channels
    frames = np.random.default_rng(0).uniform(-60, 60, (4, 6))
    np.testing.assert_allclose(back.to_vectors(frames[:, :5]), rmap.to_vectors(frames[:, :5]), atol=1e-12)
    lower = dict(arrays, group_orders=np.array(["zxy"]))
    assert RotationMap.from_arrays(lower, 5).groups[0].order == "ZXY"
    empty = RotationMap(groups=(), hinge_columns=np.zeros(0, dtype=int), hinge_centres=np.zeros(0))
    again = RotationMap.from_arrays(empty.to_arrays(), 3)
    assert again.groups == () and again.columns.size == 0
    bad = {
        "different lengths": dict(arrays, group_orders=np.array(["ZXY", "XYZ"])),
        "different lengths ": dict(arrays, hinge_centres=np.zeros(2)),
        "outside": dict(arrays, hinge_columns=np.array([5])),
        "outside ": dict(arrays, hinge_columns=np.array([-1])),
        "not finite": dict(arrays, hinge_centres=np.array([np.nan])),
        "not finite ": dict(arrays, group_means=np.full((1, 4), np.inf)),
        "unit": dict(arrays, group_means=arrays["group_means"] * (1 + 2e-6)),
        "permutation": dict(arrays, group_orders=np.array(["ZXZ"])),
    }
    for reason, a in bad.items():
        with pytest.raises(ValueError, match=reason.strip()):
            RotationMap.from_arrays(a, 5)
    near_unit = dict(arrays, group_means=arrays["group_means"] * (1 + 5e-7))
    RotationMap.from_arrays(near_unit, 5)
