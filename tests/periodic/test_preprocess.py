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
