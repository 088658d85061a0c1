"""Latent synthesis: GPLVM gradients, models, particle, bridges, commands, Kovar distances."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from cyclecoord.synthesis.latent import LatentModel, Synthesizer, find_bridges
from cyclecoord.synthesis.latent.commands import CommandGraph, eased, resample
from cyclecoord.synthesis.latent.gplvm import GPLVM, objective
from cyclecoord.synthesis.latent.influence import influence_weights
from cyclecoord.synthesis.latent.particle import ParticleParams, RandomForce, simulate
from cyclecoord.synthesis.transitions import (
    aligned_transform,
    transition_points,
    window_distances,
)


def _capture(kind: str, seed: int = 0, n: int = 240):
    return cc.datasets.make_periodic_capture(kind=kind, n_frames=n, random_state=seed).motion


@pytest.fixture(scope="module")
def walk_model():
    m = _capture("walk")
    return LatentModel(gplvm={"max_iter": 60}).fit([m[0:120:4], m[120:240:4]], ["a", "b"])


@pytest.fixture(scope="module")
def jog_model():
    # another performance of the walk (its own style and noise), standing in for a second kind
    m = _capture("walk", seed=5)
    return LatentModel(gplvm={"max_iter": 60}).fit([m[::4]], ["jog"])


# ------------------------------------------------------------------------ GPLVM
@pytest.mark.parametrize("weight", [0.0, 1.0])
def test_objective_gradient_matches_finite_differences(weight):
    rng = np.random.default_rng(0)
    n, q = 30, 3
    t = np.linspace(0, 2, n)
    Y = np.c_[np.sin(3 * t), np.cos(3 * t), np.sin(6 * t), t, t**2] + 0.05 * rng.normal(size=(n, 5))
    Y -= Y.mean(0)
    seg = (np.arange(n) >= 15).astype(int)
    times = np.where(seg == 0, t, t - t[15])
    g = GPLVM(connectivity_weight=weight, connectivity_points=20)
    X0 = Y[:, :q] / Y[:, 0].std() + 0.02 * rng.normal(size=(n, q))
    st = g.settings(Y, seg, times, X0)
    theta = np.concatenate([X0.ravel(), np.log([0.7, 1.3, 0.05])])
    f, grad = objective(theta, st, q)
    num = optimize.approx_fprime(theta, lambda x: objective(x, st, q)[0], 1e-6)
    assert np.isfinite(f)
    assert np.abs(grad - num).max() < 1e-4 * max(1.0, np.abs(grad).max())


def test_connectivity_prior_penalises_separated_segments():
    # the same two curves, near each other or far apart: the negative log prior is
    # larger when the graph falls apart into two clusters
    from cyclecoord.synthesis.latent.gplvm import _connectivity

    t = np.linspace(0, 2 * np.pi, 20, endpoint=False)
    curve = np.c_[np.cos(t), np.sin(t), 0.3 * np.cos(2 * t)]
    costs = []
    for gap in (0.3, 3.0):
        X = np.vstack([curve, curve + [gap, 0, 0]])
        costs.append(_connectivity(X, 1.0, 2.0, 4.0, 0.01)[0])
    assert costs[0] < costs[1]


def test_influence_weights_ignore_channels_that_do_not_move_the_body():
    m = _capture("walk", n=60)
    root = set(m.root_channels())
    ch = [c for i, c in enumerate(m.channels) if i not in root]
    angles = m.frames[:, [m.channel_index(*c) for c in ch]]
    w = influence_weights(angles, ch, m.skeleton)
    assert w.shape == (len(ch),)
    assert np.all(w >= 0)
    # a constant channel gets 0; the hip's flexion moves the whole leg, a toe the least
    const = np.flatnonzero(angles.std(0) == 0)
    assert np.all(w[const] == 0)
    hip = ch.index(("rfemur", "rx"))
    moving = np.flatnonzero(angles.std(0) > 0)
    assert w[hip] >= np.median(w[moving])


# ------------------------------------------------------------------------ model
def test_model_rebuilds_training_frames_and_round_trips(walk_model, tmp_path):
    m = walk_model
    train = m.angles(m.frames_)
    err = np.sqrt(((m.pose(m.X_) - train) ** 2).mean())
    assert err < 0.5 * train.std(0).mean()
    assert m.X_.shape[1] == 3
    assert m.explained_variance_ >= 0.85
    path = tmp_path / "walk.npz"
    m.save(path)
    back = LatentModel.load(path)
    np.testing.assert_allclose(back.pose(m.X_[:7]), m.pose(m.X_[:7]), atol=1e-8)
    np.testing.assert_array_equal(back.frames_, m.frames_)
    assert back.segment_names_ == ["a", "b"]
    p, grad = back.density(m.X_[3])
    assert 0 < p <= 1 and grad.shape == (3,)
    far = back.densities(m.X_[:1] + 100.0)
    assert far[0] < 0.05


def test_density_gradient_matches_finite_differences(walk_model):
    x = walk_model.X_[5] + 0.05
    _, g = walk_model.density(x)
    h = 1e-3  # central differences: the variance is a small difference of large numbers
    num = [
        (walk_model.density(x + h * e)[0] - walk_model.density(x - h * e)[0]) / (2 * h)
        for e in np.eye(3)
    ]
    np.testing.assert_allclose(g, num, rtol=1e-3, atol=1e-4)


def test_load_rejects_other_files(tmp_path):
    bad = tmp_path / "x.npz"
    np.savez(bad, a=np.zeros(3))
    with pytest.raises(cc.ParseError, match="not a latent model"):
        LatentModel.load(bad)


# --------------------------------------------------------------------- particle
def test_particle_stays_near_its_path_and_is_seeded(walk_model):
    m = walk_model
    path = np.linspace(m.X_[0], m.X_[20], 61)
    params = ParticleParams(random=6.0)
    runs = [
        simulate(m, path, m.X_[0], np.zeros(3), 30.0, params, RandomForce(3, 0.4, random_state=s))[
            0
        ]
        for s in (0, 0, 1)
    ]
    np.testing.assert_array_equal(runs[0], runs[1])
    assert not np.allclose(runs[0], runs[2])
    r = params.radius * m.speed_
    dist = np.linalg.norm(runs[0] - path[1:], axis=1)
    assert dist.max() < 2.0 * r


def test_particle_params_are_checked():
    with pytest.raises(ParameterError, match="unknown particle parameter"):
        ParticleParams().replace(radiuss=1)
    with pytest.raises(ParameterError, match="positive"):
        ParticleParams(width=0)


def test_path_helpers():
    pts = np.array([[0.0, 0, 0], [1, 0, 0], [1, 2, 0]])
    r = resample(pts, 0.5)
    steps = np.linalg.norm(np.diff(r, axis=0), axis=1)
    np.testing.assert_allclose(steps, 0.5)
    u = eased(20, 5)
    assert u[0] == 0 and u[-1] == pytest.approx(1) and np.all(np.diff(u) > 0)
    assert np.diff(u)[0] < np.diff(u)[10]


def test_command_graph_path_follows_the_data(walk_model):
    g = CommandGraph(walk_model)
    a, b = walk_model.X_[0], walk_model.X_[25]
    poly = g.path(a, b)
    assert np.allclose(poly[0], a) and np.allclose(poly[-1], b)
    # hops are short: no edge longer than the straight jump
    assert np.linalg.norm(np.diff(poly, axis=0), axis=1).max() <= np.linalg.norm(b - a) + 1e-12


# ---------------------------------------------------------------------- bridges
def test_bridges_of_a_model_to_itself_match_poses(walk_model):
    br = find_bridges(walk_model, walk_model, names=("w", "w"))
    assert len(br) > 0.8 * walk_model.X_.shape[0]
    assert np.all(br.distances < br.threshold)
    assert br.to_dict()["count"] == len(br)


def test_invert_finds_the_latent_point_of_a_pose(walk_model):
    from cyclecoord.synthesis.latent import invert, project

    X = walk_model.X_
    mid = 0.5 * (X[3:20] + X[4:21])  # between training points: not where any start is
    target = walk_model.pose(mid)
    Xi, cost = invert(walk_model, target)
    err = np.sqrt(((walk_model.pose(Xi) - target) ** 2).mean())
    spread = np.sqrt(((target - target.mean(0)) ** 2).mean())
    assert err < 0.05 * spread and np.allclose(cost, ((walk_model.pose(Xi) - target) ** 2).sum(1))
    # least squares in the angles: no worse than Eq. 15's search in the scaled PCA space
    noisy = target + np.random.default_rng(0).normal(0, 2.0, target.shape)
    Xp, _ = project(walk_model, walk_model.pca_coordinates(noisy))
    Xi, _ = invert(walk_model, noisy)
    sq = lambda x: ((walk_model.pose(x) - noisy) ** 2).sum()  # noqa: E731
    assert sq(Xi) <= sq(Xp) + 1e-9
    with pytest.raises(ParameterError, match="channels"):
        invert(walk_model, target[:, :5])


def test_synthesizer_transition_and_output(walk_model, jog_model):
    syn = Synthesizer({"walk": walk_model, "jog": jog_model}, fps=30, seed=3)
    syn.start("walk")
    syn.idle(duration=0.5)
    syn.move({"segment": "b", "time": 0.5}, path="graph")
    syn.transition("jog", blend=0.3)
    syn.play("jog", 0.0, 0.5)
    motion = syn.motion()
    assert motion.n_frames == syn.n_frames and motion.fps == 30
    assert syn.events and syn.events[0]["transition"] == ["walk", "jog"]
    assert np.isfinite(motion.frames).all()
    # walking moves the root forward
    assert (
        np.ptp(motion.frames[:, motion.channel_index("root", "tz")])
        + np.ptp(motion.frames[:, motion.channel_index("root", "tx")])
        > 1.0
    )
    again = Synthesizer({"walk": walk_model, "jog": jog_model}, fps=30, seed=3)
    again.start("walk")
    again.idle(duration=0.5)
    again.move({"segment": "b", "time": 0.5}, path="graph")
    again.transition("jog", blend=0.3)
    again.play("jog", 0.0, 0.5)
    np.testing.assert_array_equal(again.motion().frames, motion.frames)


def test_a_played_segment_carries_its_detail_into_the_move_after_it(walk_model):
    """PLAY's frames are the captured ones (re-timed to ease from rest, where its approach
    stopped, to the captured pace), which hold what the model leaves out of them: marked
    as detail, that fades into the MOVE after it over DETAIL_FADE seconds instead of
    stepping at the join (the README's script popped at 3.6x there)."""
    from cyclecoord.synthesis.latent.output import DETAIL_FADE

    def made(detail):
        syn = Synthesizer({"walk": walk_model}, fps=30, seed=0, plant="off", lock=False,
                          detail=detail)
        syn.start("walk")
        syn.play("b", 0.0, 0.5)
        syn.move({"segment": "b", "time": 0.9})
        return syn

    syn, bare = made(True), made(False)
    played = syn.chunks[-2]
    idx = np.flatnonzero(walk_model.segments_ == walk_model.segment_index("b"))
    # 0.5 s of frames, the playback easing from rest over the synthesizer's ease
    ramp = int(round(syn.ease * 30))
    assert played.X.shape[0] == 15 + ramp // 2
    np.testing.assert_allclose(played.detail["angles"][0], walk_model.detail()["angles"][idx[0]],
                               atol=1e-9)
    steps = np.linalg.norm(np.diff(played.X, axis=0), axis=1)
    captured = np.linalg.norm(np.diff(walk_model.X_[idx[:16]], axis=0), axis=1)
    assert steps[0] < 0.2 * captured[0]  # from rest ...
    assert np.median(steps[ramp:]) == pytest.approx(np.median(captured[ramp // 2 :]), rel=0.1)
    # (at a captured frame the pose of its latent point plus its detail is the frame)
    np.testing.assert_allclose(played.angles[0],
                               walk_model.pose(played.X[:1])[0] + played.detail["angles"][0],
                               atol=1e-6)
    assert bare.chunks[-2].detail is None
    # the MOVE's first frames: the played frames' last detail, fading
    a, _ = syn._posed()
    b, _ = bare._posed()
    n = sum(c.X.shape[0] for c in syn.chunks[:-1])
    F = int(round(DETAIL_FADE * 30))
    k = np.arange(1, F + 1)
    u = 1.0 - k / (F + 1.0)
    fade = (u * u * (3 - 2 * u))[:, None] * played.detail["angles"][-1]
    np.testing.assert_allclose(a[n : n + F] - b[n : n + F],
                               fade, atol=1e-6)
    np.testing.assert_allclose(a[n + F :], b[n + F :], atol=1e-9)
    # and the join steps less than without it
    assert np.abs(a[n] - a[n - 1]).max() < np.abs(b[n] - b[n - 1]).max()


def test_transition_without_bridges_crosses_at_the_closest_poses(walk_model, jog_model):
    # a threshold no pair can meet: the transition still happens, at the closest pair
    syn = Synthesizer({"walk": walk_model, "jog": jog_model}, fps=30, seed=1, bridge_threshold=1e-9)
    syn.start("walk")
    syn.transition("jog", blend=0.2)
    (ev,) = syn.events
    assert ev["route"] == ["walk", "jog"] and ev["under_threshold"] is False
    c = syn.crossings("walk", "jog")
    assert ev["bridge_distance"] <= 1.1 * c.distances.min() + 1e-12
    assert ev["blend_frames"] >= ev["blend_asked_frames"] == 6
    assert syn.current == "jog" and np.isfinite(syn.motion().frames).all()
    # the reversed search (jog's training points into walk) is among the crossings
    assert (c.target_frames >= 0).any() and (c.source_frames >= 0).any()


def test_route_prefers_a_chain_of_bridges_to_a_far_jump(walk_model):
    from cyclecoord.synthesis.latent.commands import Crossings

    syn = Synthesizer({k: walk_model for k in "abc"}, fps=30)
    x = walk_model.X_[:1]

    def cross(s, t, d):
        return Crossings(s, t, x, x, np.array([d]), np.array([0]), np.array([0]), 1.0)

    far = {("a", "b"): 3.0, ("a", "c"): 0.5, ("c", "b"): 0.9}
    for s in "abc":
        for t in "abc":
            if s != t:
                syn._crossings[(s, t)] = cross(s, t, far.get((s, t), 5.0))
    assert syn.route("a", "b") == ["a", "c", "b"]
    syn._crossings[("a", "b")] = cross("a", "b", 1.2)  # 1.44 < 2 hops of cost 1
    assert syn.route("a", "b") == ["a", "b"]


def test_blend_lengthens_with_the_pose_gap(walk_model):
    syn = Synthesizer({"w": walk_model, "v": walk_model}, fps=30)
    X = walk_model.X_
    gaps = np.linalg.norm(walk_model.pose(X) - walk_model.pose(X[:1]), axis=1)
    far = int(np.argmax(gaps))
    assert syn.blend_frames("w", "v", X[0], X[0]) <= 1
    assert syn.blend_frames("w", "v", X[0], X[far]) > syn.blend_frames("w", "v", X[0], X[1])


def test_root_follows_planted_feet_in_blend_windows(cmu_dir):
    from cyclecoord.quality.contacts import foot_contacts

    take = cc.load(cmu_dir / "13" / "13_29.amc")
    fit = dict(gplvm={"max_iter": 40})
    models = {
        "jj": LatentModel(**fit).fit([take[0:456:4]], ["JumpJack"]),
        "tw": LatentModel(**fit).fit([take[456:1200:4]], ["Twist"]),
    }

    def run(plant, lock=False):
        # (the IDLEs at the full random force: the particle wanders, and the feet with it)
        syn = Synthesizer(models, fps=30, seed=2, plant=plant, lock=lock)
        syn.start("jj")
        syn.idle(duration=0.4, sway=1.0)
        syn.transition("tw", blend=0.4)
        syn.idle(duration=0.6, sway=1.0)
        return syn, syn.motion()

    syn, planted = run("transitions")
    _, free = run("off")
    share = syn.plant_spans(free.n_frames)
    mask = share > 0
    assert mask.any() and not mask.all() and share.max() == 1.0
    assert np.all((share >= 0) & (share <= 1)) and np.abs(np.diff(share)).max() < 0.5
    cols = [free.channel_index("root", d) for d in ("tx", "tz")]
    # outside the spans the root takes the same steps; only the ground track changes
    np.testing.assert_allclose(
        np.diff(planted.frames[:, cols], axis=0)[~mask],
        np.diff(free.frames[:, cols], axis=0)[~mask],
    )
    other = [i for i in range(free.frames.shape[1]) if i not in cols]
    np.testing.assert_array_equal(planted.frames[:, other], free.frames[:, other])
    # feet planted (found on the uncorrected motion, lax speed) slide less in the spans
    fc = foot_contacts(free, speed=2.0)
    rows = np.r_[mask, False] | np.r_[False, mask]
    sel = fc.planted & rows[:, None]
    assert sel.sum() > 5

    def slide(m):
        names = m.positions().names
        pos = m.positions().positions[:, [names.index(f) for f in fc.feet]]
        return np.linalg.norm(np.gradient(pos[..., [0, 2]], axis=0), axis=2)[sel].mean()

    assert slide(planted) < 0.8 * slide(free)

    def root_acc(m):
        p = m.positions().positions[:, 0, [0, 2]]
        return np.linalg.norm(np.diff(p, 2, axis=0), axis=1) * m.fps**2

    # the root following the feet does not shake: within the takes' own accelerations
    train = np.concatenate(
        [root_acc(cc.Motion(frames=m.frames_, channels=m.all_channels_, fps=m.fps_,
                            skeleton=m.skeleton_)) for m in models.values()]
    )
    assert root_acc(planted).max() < np.percentile(train, 99)
    # the optional leg IK changes leg channels only, and only near the spans
    _, locked = run("transitions", lock=True)
    changed = np.abs(locked.frames - planted.frames) > 1e-9
    legs = {"lfemur", "ltibia", "lfoot", "rfemur", "rtibia", "rfoot"}
    assert changed.any()
    assert all(locked.channels[i][0] in legs for i in np.flatnonzero(changed.any(axis=0)))
    near = np.convolve(rows.astype(float), np.ones(9), "same") > 0  # lock easing: 0.1 s
    assert not changed[~near].any()
    with pytest.raises(ParameterError, match="plant"):
        Synthesizer(models, plant="feet")


def test_synthesizer_errors(walk_model):
    syn = Synthesizer({"walk": walk_model}, fps=30)
    with pytest.raises(ParameterError, match="before the particle"):
        syn.idle(duration=1)
    syn.start("walk")
    with pytest.raises(ParameterError, match="outside model"):
        syn.move([50.0, 50.0, 50.0])
    with pytest.raises(ParameterError, match="unknown model"):
        syn.transition("nope")
    with pytest.raises(ParameterError, match="no segment"):
        syn.play("zzz")


# ------------------------------------------------------------------- Kovar
def test_window_distance_is_invariant_to_turns_and_floor_moves():
    rng = np.random.default_rng(0)
    pa = rng.normal(size=(15, 6, 3))
    th = 0.9
    c, s = np.cos(th), np.sin(th)
    R = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    pb = pa @ R.T + np.array([2.0, 0.0, -1.0])
    D = window_distances(pa, pb, 5)
    assert np.abs(np.diag(D)).max() < 1e-6
    theta, t = aligned_transform(pa[:5], pb[:5])
    c, s = np.cos(theta), np.sin(theta)
    R2 = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    np.testing.assert_allclose(pb[:5] @ R2.T + t, pa[:5], atol=1e-9)
    # against a brute-force search over angles for an unrelated pair
    i, j, k = 2, 7, 5
    best = np.inf
    for a in np.linspace(-np.pi, np.pi, 7201):
        c, s = np.cos(a), np.sin(a)
        q = pb[j : j + k] @ np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]).T
        shift = (pa[i : i + k] - q).mean((0, 1))
        shift[1] = 0
        best = min(best, np.sqrt(((pa[i : i + k] - q - shift) ** 2).sum(-1).mean()))
    assert D[i, j] == pytest.approx(best, abs=1e-4)
    tr = transition_points(pa, pb, 5, threshold=1e-3)
    assert len(tr) >= 1 and np.all(tr.pairs[:, 0] == tr.pairs[:, 1])


def test_figures(walk_model, jog_model):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cyclecoord.plot.latent import plot_bridges, plot_latent, plot_pose_strip

    fig = plot_latent(walk_model, path=walk_model.X_[:10] + 0.01)
    assert len(fig.axes) == 1
    br = find_bridges(walk_model, jog_model, names=("w", "j"))
    fig2 = plot_bridges(walk_model, jog_model, br, ("w", "j"))
    assert len(fig2.axes) == 2
    motion = cc.Motion(frames=walk_model.frames_[:20], channels=walk_model.all_channels_,
                       skeleton=walk_model.skeleton_)
    fig3 = plot_pose_strip(motion, [0, 10, 19])
    assert fig3.axes
    plt.close("all")


def test_kinv_times_is_the_inverse_kernel_product(walk_model):
    """The particle's ``K^-1 k`` by a symmetric BLAS product equals the plain product (to
    rounding) and solving ``K u = k`` with the kernel itself."""
    g = walk_model.gp_
    k = walk_model.kernel(walk_model.X_[3:4] + 0.02)[0]
    u = g.kinv_times(k)
    np.testing.assert_allclose(u, g.kinv_ @ k, rtol=0, atol=1e-9 * np.abs(g.kinv_ @ k).max())
    K = walk_model.kernel(walk_model.X_) + g.noise_ * np.eye(len(k))
    np.testing.assert_allclose(K @ u, k, rtol=0, atol=1e-6 * np.abs(k).max())
