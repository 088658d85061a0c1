"""periodic.phase_model: a saved model reads back as the model it was, for either rotation
space; every malformed file is refused with a reason; channels are matched by name."""

import json

import numpy as np
import pytest

import cyclecoord as cc
from cyclecoord.errors import ParameterError, ParseError
from cyclecoord.periodic.phase_model import PhaseModel


@pytest.fixture(scope="module")
def models():
    m = cc.datasets.example_capture().motion
    # the Euler model projected to 4 dimensions and scaled, the rotvec one neither: between
    # them every part of the preparation is saved (components or none, scale, flags)
    return m, {"euler": cc.extract(m, rotations="euler", pca=4, normalize=True).model,
               "rotvec": cc.extract(m, rotations="rotvec").model}


@pytest.fixture(scope="module")
def other():
    return cc.datasets.make_periodic_capture(n_frames=200, random_state=9).motion


@pytest.mark.parametrize("rotations", ["euler", "rotvec"])
def test_round_trip_in_either_rotation_space(models, other, rotations, tmp_path):
    m, by = models
    model = by[rotations]
    path = tmp_path / "m.npz"
    model.save(path)
    back = PhaseModel.load(path)
    assert back.preprocessor.rotations == rotations
    p, q = model.preprocessor, back.preprocessor
    if rotations == "euler":
        assert q.rotation_map_ is None
        assert q.pca == 4 and q.normalize is True and q.components_.shape[0] == 4
        np.testing.assert_array_equal(q.components_, p.components_)
        assert q.transform(other).points.shape[1] == 4
    else:
        rmap = back.preprocessor.rotation_map_
        assert rmap is not None and len(rmap.groups) == len(model.preprocessor.rotation_map_.groups) > 0
        np.testing.assert_array_equal(rmap.columns, model.preprocessor.rotation_map_.columns)
        assert q.pca is None and q.components_ is None and q.normalize is False
    np.testing.assert_array_equal(q.scale_, p.scale_)
    np.testing.assert_array_equal(q.mean_, p.mean_)
    assert q.difference_root == p.difference_root and q.root_mode_ == p.root_mode_
    np.testing.assert_allclose(back.phase(other), model.phase(other), atol=1e-12)
    assert back.channels == tuple(m.channels) and back.fps == m.fps
    assert back.period_frames == model.period_frames
    header = json.loads(str(np.load(path)["header"]))
    assert header["version"] == 2 and header["rotations"] == rotations
    # the two spaces do differ on this capture: the map is read, not ignored
    assert np.abs(by["euler"].phase(other) - by["rotvec"].phase(other)).max() > 0


def _rewrite(path, out, **changes):
    with np.load(path) as data:
        arrays = {k: data[k] for k in data.files}
    header = json.loads(str(arrays["header"]))
    for k, v in changes.items():
        if k.startswith("header_"):
            header[k[7:]] = v
        elif v is None:
            arrays.pop(k)
        else:
            arrays[k] = v
    arrays["header"] = np.array(json.dumps(header))
    np.savez(out, **arrays)
    return out


def test_model_files_that_are_refused(models, other, tmp_path):
    _, by = models
    good = tmp_path / "good.npz"
    by["euler"].save(good)
    v1 = PhaseModel.load(_rewrite(good, tmp_path / "v1.npz", header_version=1))
    np.testing.assert_allclose(v1.phase(other), by["euler"].phase(other), atol=1e-12)
    with pytest.raises(ParseError, match="version 3 is not supported"):
        PhaseModel.load(_rewrite(good, tmp_path / "v3.npz", header_version=3))
    with pytest.raises(ParseError, match="format 'other'"):
        PhaseModel.load(_rewrite(good, tmp_path / "f.npz", header_format="other"))
    with pytest.raises(ParseError, match="incomplete"):
        PhaseModel.load(_rewrite(good, tmp_path / "i.npz", pre_mean=None))
    noh = tmp_path / "noh.npz"
    np.savez(noh, x=np.zeros(2))
    with pytest.raises(ParseError, match="no header"):
        PhaseModel.load(noh)
    with pytest.raises(ParseError, match="no such file"):
        PhaseModel.load(tmp_path / "missing.npz")
    rv = tmp_path / "rv.npz"
    by["rotvec"].save(rv)
    with pytest.raises(ParseError, match="incomplete"):
        PhaseModel.load(_rewrite(rv, tmp_path / "rv2.npz", rot_group_means=None))


def test_channels_are_matched_by_name(models, other):
    m, by = models
    model = by["euler"]
    reordered = other.select(list(reversed(other.channels)))
    np.testing.assert_allclose(model.phase(reordered), model.phase(other), atol=1e-12)
    with pytest.raises(ParameterError, match="expected a Motion"):
        model.phase(other.frames)
    with pytest.raises(ParameterError, match=r"lacks 2 channel"):
        model.phase(other.select(other.channels[2:]))


def test_from_result_needs_a_fitted_model():
    class R:
        estimator = None
        preprocessor = object()

    with pytest.raises(ParameterError, match="no fitted model"):
        PhaseModel.from_result(R())


def test_summary_of_frames_that_do_not_wind():
    model = object.__new__(PhaseModel)
    model.phase = lambda motion: np.full(10, 0.25)
    s = model.summary(None)
    assert s["cycles"] == 0.0 and np.isnan(s["period_frames"])
    model.phase = lambda motion: np.mod(-np.arange(11) / 5.0, 1.0)  # backwards twice
    s = model.summary(None)
    assert s["cycles"] == pytest.approx(-2.0) and np.isnan(s["period_frames"])



def test_a_model_file_with_a_pickled_array_is_refused(models, tmp_path):
    """Model files are plain arrays: one holding a pickled object is not read (loading it
    would run code), even beside every array a model needs."""
    _, by = models
    good = tmp_path / "good.npz"
    by["euler"].save(good)
    with np.load(good) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["extra"] = np.array([{"a": 1}], dtype=object)
    evil = tmp_path / "evil.npz"
    np.savez(evil, **arrays)
    with pytest.raises(ParseError, match="not a cyclecoord model file"):
        PhaseModel.load(evil)
