"""Preparation: root differencing (with angle wrap), scaling and PCA."""

import numpy as np
import pytest

from cyclecoord import Motion
from cyclecoord.errors import ParameterError
from cyclecoord.periodic.preprocess import Preprocessor

ROOT = [("root", d) for d in ("tx", "ty", "tz", "rx", "ry", "rz")]


def make(frames):
    ch = ROOT + [(f"j{i}", "rx") for i in range(frames.shape[1] - 6)]
    return Motion(frames, ch)


def test_root_is_differenced_and_wrapped():
    t = np.arange(10, dtype=float)
    f = np.zeros((10, 8))
    f[:, 2] = 3.0 * t  # tz walks forward
    f[:, 4] = np.mod(170 + 5 * t + 180, 360) - 180  # heading crosses +180 -> -180
    f[:, 6] = np.sin(t)
    prep = Preprocessor().fit_transform(make(f))
    np.testing.assert_allclose(prep.poses[:, 2], 3.0)
    np.testing.assert_allclose(prep.poses[:, 4], 5.0)  # no 360 jump
    np.testing.assert_allclose(prep.poses[:, 6], np.sin(t))  # joints untouched
    assert prep.root_columns.tolist() == [0, 1, 2, 3, 4, 5]
    np.testing.assert_array_equal(prep.points, prep.poses)


def test_input_is_not_modified():
    f = np.random.default_rng(0).standard_normal((20, 9))
    keep = f.copy()
    m = make(f)
    Preprocessor(normalize=True, pca=3).fit_transform(m)
    np.testing.assert_array_equal(m.frames, keep)
    np.testing.assert_array_equal(f, keep)


def test_normalize_and_pca():
    rng = np.random.default_rng(1)
    f = rng.standard_normal((100, 10)) * np.arange(1, 11)
    prep = Preprocessor(difference_root=False, normalize=True)
    out = prep.fit_transform(make(f))
    np.testing.assert_allclose(out.points.std(axis=0), 1.0)
    p = Preprocessor(difference_root=False, pca=2)
    out = p.fit_transform(make(f))
    assert out.points.shape == (100, 2)
    assert p.explained_variance_ratio_[0] >= p.explained_variance_ratio_[1]
    # PCA is a projection: variance captured equals the sum of the top singular values squared
    z = f - f.mean(0)
    s = np.linalg.svd(z, compute_uv=False)
    assert out.points.var(axis=0, ddof=0).sum() * 100 == pytest.approx((s[:2] ** 2).sum())


def test_bad_settings():
    f = np.zeros((10, 8))
    with pytest.raises(ParameterError, match="pca"):
        Preprocessor(pca=50).fit(make(f))
    f[3, 7] = np.nan
    with pytest.raises(ParameterError, match="frame 3"):
        Preprocessor().fit(make(f))


def test_delay_embedding_turns_an_out_and_back_motion_into_a_loop():
    t = np.arange(400)
    f = np.zeros((400, 8))
    f[:, 6] = 30 * np.sin(2 * np.pi * t / 100)  # a joint swinging out and back: a segment
    f[:, 7] = 0.5 * f[:, 6]
    plain = Preprocessor().fit_transform(make(f)).points
    emb = Preprocessor(delay=25).fit_transform(make(f)).points
    assert emb.shape == (400, 16)
    np.testing.assert_array_equal(emb[25:, 8:], plain[:-25])
    np.testing.assert_array_equal(emb[:25, 8:], np.repeat(plain[:1], 25, axis=0))
    from cyclecoord.periodic.barcode import select_bar
    from cyclecoord.periodic.coordinates import CircularCoordinates, unwrap

    # the segment has no loop; with its past (a quarter period back) it is an ellipse
    flat = CircularCoordinates().fit_barcode(plain)
    assert flat.h1.size == 0 or not select_bar(flat, 0).clear
    est = CircularCoordinates().fit(emb)
    u = unwrap(est.coordinates_)
    # frames before the first delay have no real past: count from there
    assert est.selection_.clear and u[-1] - u[25] == pytest.approx(374 / 100, abs=0.1)
    two = Preprocessor(delay=[10, 25]).fit_transform(make(f)).points
    assert two.shape == (400, 24)
    with pytest.raises(ParameterError):
        Preprocessor(delay=2.5).fit(make(f))


def _walker(order="ZYX", channels=None):
    """A root that walks, turns past 180 degrees, pitches and rolls, and one joint."""
    from cyclecoord.skeleton import Joint, Skeleton

    root_dofs = ("tx", "ty", "tz") + tuple("r" + a.lower() for a in order)
    sk = Skeleton((
        Joint("root", -1, [0, 0, 0], root_dofs, order),
        Joint("leg", 0, [0, -1, 0], ("rx",), "X", end_site=[0, -1, 0]),
    ))
    T = 40
    t = np.arange(T) / 10.0
    cols = {"tx": 3 * np.sin(t), "ty": 1 + 0.1 * t, "tz": 2 * t, "rx": 10 * np.sin(2 * t),
            "ry": 15 * np.cos(t), "rz": 60 * t}  # the middle (Y) angle stays small
    channels = channels or sk.channels
    frames = np.column_stack([cols[d] if j == "root" else 20 * np.sin(3 * t) for j, d in channels])
    return Motion(frames, channels, fps=10, skeleton=sk)


def test_body_root_differences_integrate_back_to_the_capture():
    """integrate_root inverts the body-frame differences: from the first frame's root
    values, the per-frame changes rebuild every frame's root channels."""
    from cyclecoord.periodic.preprocess import body_frame_differences, _root_layout

    m = _walker()
    prep = Preprocessor(root="body").fit(m)
    assert prep.root_mode_ == "body"
    cols = prep.root_columns_
    deltas = body_frame_differences(m.frames, cols, *_root_layout(m, cols))
    want = m.frames[:, cols]
    got = prep.integrate_root(deltas, want[0], None, m)
    np.testing.assert_allclose(got, want, atol=1e-9)
    # the mean change it is asked for is the one it has: nothing moves
    got = prep.integrate_root(deltas, want[0], deltas.mean(axis=0), m)
    np.testing.assert_allclose(got, want, atol=1e-9)


def test_body_root_needs_the_skeleton_to_order_every_root_rotation():
    """Root channels rx ry rz over a skeleton whose root only orders ZY: the body frame
    is undefined, so the plain Euler differences are used."""
    chans = [("root", d) for d in ("tx", "ty", "tz", "rx", "ry", "rz")] + [("leg", "rx")]
    m = _walker("ZY", channels=chans)
    assert len(m.root_channels()) == 6
    assert Preprocessor(root="body").fit(m).root_mode_ == "euler"
    assert Preprocessor(root="body").fit(_walker("ZYX")).root_mode_ == "body"


# ------------------------------------------------- known answers, helper by helper
def test_wrap_degrees_into_minus_180_to_180():
    """Angles wrapped into [-180, 180): +180 becomes -180, 190 is -170, -190 is 170."""
    from cyclecoord.periodic.preprocess import _wrap_degrees

    x = np.array([0.0, 179.0, 180.0, -180.0, 190.0, -190.0, 540.0, -359.0, 360.0, -0.5])
    np.testing.assert_allclose(_wrap_degrees(x), [0, 179, -180, -180, -170, 170, -180, 1, 0, -0.5])


def test_difference_root_known_answer():
    """Column 0 (a translation) 0, 1, 3, 6 gives steps 1, 2, 3 and the last repeated;
    column 2 (an angle) 170, -170, -150, 175 gives raw steps -340, 20, 325, wrapped 20, 20,
    -35 and -35 again; the other columns and the input are left alone."""
    from cyclecoord.periodic.preprocess import difference_root

    f = np.array([[0.0, 5.0, 170.0, 7.0], [1.0, 6.0, -170.0, 8.0], [3.0, 7.0, -150.0, 9.0], [6.0, 8.0, 175.0, 10.0]])
    keep = f.copy()
    out = difference_root(f, np.array([0, 2]), np.array([False, True]))
    np.testing.assert_allclose(out, [[1, 5, 20, 7], [2, 6, 20, 8], [3, 7, -35, 9], [3, 8, -35, 10]])
    np.testing.assert_array_equal(f, keep)
    # translations are not wrapped
    big = difference_root(f * 100, np.array([0]), np.array([False]))
    np.testing.assert_allclose(big[:, 0], [100, 200, 300, 300])
    # no root columns: an unchanged copy, even of one frame; with root columns one frame is refused
    none = difference_root(f[:1], np.array([], dtype=int), np.array([], dtype=bool))
    np.testing.assert_array_equal(none, f[:1])
    assert none is not f
    two = difference_root(f[:2], np.array([0]), np.array([False]))
    np.testing.assert_allclose(two[:, 0], [1.0, 1.0])
    with pytest.raises(ParameterError):
        difference_root(f[:1], np.array([0]), np.array([False]))


def _turning_walker(axis=np.eye(3), order=("rz", "tx", "ry", "tz", "rx", "ty")):
    """A root turning 30 degrees a frame about its own z axis while stepping 2 along its own
    x axis and 0.5 along its own z: in the body frame every step is (2, 0, 0.5) and every
    turn the rotation vector 30 (axis z) -- seen through the skeleton's ``axis`` A, the
    turn is about A z."""
    from scipy.spatial.transform import Rotation

    from cyclecoord.skeleton import Joint, Skeleton

    sk = Skeleton((Joint("root", -1, [0, 0, 0], order, "ZYX", axis=axis),
                   Joint("leg", 0, [0, -1, 0], ("rx",), "X", end_site=[0, -1, 0])))
    T = 8
    heading = 30.0 * np.arange(T)
    R = axis @ Rotation.from_euler("ZYX", np.column_stack([heading, 0 * heading, 0 * heading]),
                                   degrees=True).as_matrix() @ axis.T
    p = np.zeros((T, 3))
    for t in range(1, T):
        p[t] = p[t - 1] + R[t - 1] @ np.array([2.0, 0.0, 0.5])
    vals = {"tx": p[:, 0], "ty": p[:, 1], "tz": p[:, 2], "rx": 0 * heading, "ry": 0 * heading,
            "rz": heading}
    frames = np.column_stack([vals[d] for d in order] + [np.full(T, 5.0)])
    return Motion(frames, sk.channels, fps=10, skeleton=sk)


@pytest.mark.parametrize("tilted", [False, True])
def test_body_frame_differences_known_answer(tilted):
    from scipy.spatial.transform import Rotation

    from cyclecoord.periodic.preprocess import _root_layout, body_frame_differences

    axis = Rotation.from_euler("X", 90, degrees=True).as_matrix() if tilted else np.eye(3)
    m = _turning_walker(axis)
    cols = np.arange(6)
    layout = _root_layout(m, cols)
    assert layout[1] == ["rz", "tx", "ry", "tz", "rx", "ty"]
    out = body_frame_differences(m.frames, cols, *layout)
    turn = 30.0 * (axis @ [0.0, 0.0, 1.0])  # A z: (0, -1, 0) when tilted
    want = {"tx": 2.0, "ty": 0.0, "tz": 0.5, "rx": turn[0], "ry": turn[1], "rz": turn[2]}
    np.testing.assert_allclose(out, np.tile([want[d] for d in layout[1]], (8, 1)), atol=1e-9)
    # and the preprocessor puts them in the root columns, the leg channel as it is
    prep = Preprocessor(rotations="euler").fit_transform(m)
    np.testing.assert_allclose(prep.poses[:, :6], out, atol=1e-12)
    np.testing.assert_array_equal(prep.poses[:, 6], 5.0)


def test_root_layout_needs_the_six_root_dofs_and_a_skeleton():
    from cyclecoord.periodic.preprocess import _root_layout

    m = _turning_walker()
    assert _root_layout(m, np.arange(6)) is not None
    assert _root_layout(m, np.arange(5)) is None
    assert _root_layout(m, np.array([0, 1, 2, 3, 4, 6])) is None  # the leg's rx is not a root dof
    plain = Motion(m.frames, m.channels)
    assert _root_layout(plain, np.arange(6)) is None
    assert Preprocessor().fit(plain).root_mode_ == "euler"
    assert Preprocessor(root="euler").fit(m).root_mode_ == "euler"


def test_euler_integrate_root_known_answer():
    """root='euler': the rows are start, start + d0, start + d0 + d1, ...; a mean change
    shifts every delta by the same constant (here 5 - 2 = 3 in the first channel: deltas
    4, 5, 6, rows 0, 4, 9)."""
    f = np.random.default_rng(0).standard_normal((10, 8))
    prep = Preprocessor(root="euler", rotations="euler").fit(make(f))
    assert prep.root_mode_ == "euler"
    d = np.zeros((3, 6))
    d[:, 0] = [1.0, 2.0, 3.0]
    d[:, 5] = [-10.0, 0.0, 10.0]
    start = np.arange(6.0)
    out = prep.integrate_root(d, start, None, make(f))
    np.testing.assert_allclose(out[:, 0], [0.0, 1.0, 3.0])
    np.testing.assert_allclose(out[:, 5], [5.0, -5.0, -5.0])
    np.testing.assert_allclose(out[:, 1:5], np.tile(start[1:5], (3, 1)))
    mean = np.zeros(6)
    mean[0] = 5.0
    out = prep.integrate_root(d, start, mean, make(f))
    np.testing.assert_allclose(out[:, 0], [0.0, 4.0, 9.0])
    np.testing.assert_allclose(out[:, 5], [5.0, -5.0, -5.0])


def test_body_integrate_root_keeps_the_first_frame_angles_as_given():
    """A start heading of 360 degrees is the same rotation as the capture's 0: the rebuilt
    rows start at exactly 360 and continue from there (no 360 jump), the positions as in the
    capture."""
    m = _turning_walker()
    prep = Preprocessor(rotations="euler").fit(m)
    deltas = prep.transform(m).poses[:, :6]
    start = m.frames[0, :6].copy()
    start[0] += 360.0  # rz is column 0
    out = prep.integrate_root(deltas, start, None, m)
    np.testing.assert_allclose(out[:, 0], 360.0 + 30.0 * np.arange(8), atol=1e-9)
    np.testing.assert_allclose(out[:, [1, 3, 5]], m.frames[:, [1, 3, 5]], atol=1e-9)  # tx tz ty
    np.testing.assert_allclose(out[:, [2, 4]], 0.0, atol=1e-9)


def test_delays_are_validated_and_zero_dropped():
    from cyclecoord.periodic.preprocess import _delays

    assert _delays(3) == [3]
    assert _delays(0) == []
    assert _delays([0, 2, 5.0]) == [2, 5]
    assert _delays(np.array([1, 4])) == [1, 4]
    for bad in (-1, 2.5, [3, -2]):
        with pytest.raises(ParameterError):
            _delays(bad)


def test_delay_embedding_known_answer():
    """Points p(t) with delays 2 and 10 (longer than the 5 frames): [p(t), p(t - 2), p(0)],
    frames before a delay repeating the first; a delay of 0 adds nothing."""
    f = np.zeros((5, 7))
    f[:, 6] = [1.0, 2.0, 3.0, 4.0, 5.0]
    pts = Preprocessor(difference_root=False, delay=[2, 0, 10], rotations="euler").fit_transform(make(f)).points
    assert pts.shape == (5, 21)
    np.testing.assert_array_equal(pts[:, 6], [1, 2, 3, 4, 5])
    np.testing.assert_array_equal(pts[:, 13], [1, 1, 1, 2, 3])
    np.testing.assert_array_equal(pts[:, 20], [1, 1, 1, 1, 1])
    for delay in (0, [0]):
        out = Preprocessor(difference_root=False, delay=delay, rotations="euler").fit_transform(make(f)).points
        np.testing.assert_array_equal(out, f)
    with pytest.raises(ParameterError):
        Preprocessor(delay=-3).fit(make(f))


def test_pca_and_scaling_known_answers():
    """PCA on the channels scaled by their standard deviation: the components are the top
    eigenvectors of the scaled covariance, the explained ratios its eigenvalues over their
    sum, the points the centred scaled poses projected; a constant channel is not scaled
    (its divisor is 1) and scaling alone does not centre."""
    rng = np.random.default_rng(4)
    f = rng.standard_normal((60, 9)) @ rng.standard_normal((9, 9)) + 3.0
    f[:, 8] = 2.0  # constant
    p = Preprocessor(difference_root=False, normalize=True, pca=3, rotations="euler")
    out = p.fit_transform(make(f))
    sd = f.std(axis=0)
    np.testing.assert_allclose(p.scale_, np.where(np.arange(9) == 8, 1.0, sd), rtol=1e-12)
    np.testing.assert_allclose(p.mean_, f.mean(axis=0), rtol=1e-12)
    z = (f - f.mean(axis=0)) / p.scale_
    vals, vecs = np.linalg.eigh(z.T @ z)
    vals, vecs = vals[::-1], vecs[:, ::-1]
    np.testing.assert_allclose(p.explained_variance_ratio_, vals[:3] / vals.sum(), rtol=1e-9)
    np.testing.assert_allclose(np.abs(p.components_ @ vecs[:, :3]), np.eye(3), atol=1e-9)
    np.testing.assert_allclose(out.points, z @ p.components_.T, atol=1e-12)
    scaled = Preprocessor(difference_root=False, normalize=True, rotations="euler").fit_transform(make(f))
    np.testing.assert_allclose(scaled.points, f / p.scale_, rtol=1e-12)
    plain = Preprocessor(difference_root=False, rotations="euler").fit(make(f))
    np.testing.assert_array_equal(plain.scale_, 1.0)
    assert plain.components_ is None and plain.explained_variance_ratio_ is None
    # as many components as the smaller side is the most; constant poses explain nothing
    assert Preprocessor(difference_root=False, pca=9, rotations="euler").fit(make(f)).components_.shape == (9, 9)
    for bad in (0, 10):
        with pytest.raises(ParameterError, match="pca"):
            Preprocessor(difference_root=False, pca=bad).fit(make(f))
    flat = Preprocessor(difference_root=False, pca=2, rotations="euler").fit(make(np.ones((5, 7))))
    np.testing.assert_array_equal(flat.explained_variance_ratio_, [0.0, 0.0])


def test_preprocessor_checks_and_messages():
    f = np.random.default_rng(1).standard_normal((3, 8))
    p = Preprocessor(root="euler").fit(make(f))  # three frames are the fewest
    assert p.n_channels_ == 8
    with pytest.raises(ParameterError, match="at least 3 frames"):
        Preprocessor().fit(make(f[:2]))
    with pytest.raises(ParameterError, match="Motion"):
        Preprocessor().fit(f)
    for bad in ({"root": "world"}, {"rotations": "quaternion"}):
        with pytest.raises(ParameterError):
            Preprocessor(**bad).fit(make(f))
    with pytest.raises(ParameterError, match="8"):
        p.transform(make(np.zeros((3, 9))))
    for call in (lambda q: q.transform(make(f)), lambda q: q.channel_values(f)):
        with pytest.raises(ParameterError, match="not fitted"):
            call(Preprocessor())
    # channel_values without a rotation map: the poses, as a new array
    e = Preprocessor(rotations="euler").fit(make(f))
    assert e.rotation_map_ is None
    got = e.channel_values(f)
    np.testing.assert_array_equal(got, f)
    assert got is not f
    # a non-finite value is reported in the capture's own frame numbers
    g = f.copy()
    g[1, 7] = np.inf
    with pytest.raises(ParameterError, match=r"frame 101 channel \('j1', 'rx'\)"):
        Preprocessor().fit(Motion(g, make(f).channels, start_frame=100))


def test_fit_then_transform_equals_fit_transform():
    f = np.random.default_rng(2).standard_normal((30, 9))
    for kwargs in ({}, {"normalize": True, "pca": 4}, {"root": "euler", "delay": 3}):
        a = Preprocessor(**kwargs).fit(make(f)).transform(make(f))
        b = Preprocessor(**kwargs).fit_transform(make(f))
        np.testing.assert_array_equal(a.points, b.points)
        np.testing.assert_array_equal(a.poses, b.poses)
        np.testing.assert_array_equal(a.root_columns, [0, 1, 2, 3, 4, 5])
    off = Preprocessor(difference_root=False).fit_transform(make(f))
    assert off.root_columns.size == 0
    np.testing.assert_allclose(off.poses[:, :6], f[:, :6])


def test_one_principal_component_is_allowed():
    f = np.random.default_rng(3).standard_normal((20, 8))
    out = Preprocessor(difference_root=False, pca=1, rotations="euler").fit_transform(make(f))
    assert out.points.shape == (20, 1)
