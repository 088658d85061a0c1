"""The motion graph: latent space, graphs, field, paths and cross-validation on small inputs."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial import Delaunay

import cyclecoord as cc
from cyclecoord.errors import ParameterError
from cyclecoord.synthesis.graph import (
    MotionGraphSynth,
    PoseSpace,
    VectorField,
    bottleneck,
    build_graph,
    check_takes,
    cross_validate,
    follow_field,
    h1_diagram,
    parse_variant,
    path_errors,
    path_to_target,
    shortest_path,
    training_vectors,
)


def circle(n: int, radius: float = 1.0, phase: float = 0.0, turns: float = 1.0) -> np.ndarray:
    t = phase + 2 * np.pi * turns * np.arange(n) / n
    return np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)


@pytest.fixture(scope="module")
def walks():
    return [
        cc.datasets.make_periodic_capture(kind="walk", n_frames=n, period=60, random_state=s).motion
        for s, n in ((0, 150), (1, 130), (2, 140))
    ]


# ---------------------------------------------------------------------- latent space
def test_pose_space_round_trip_and_turns(walks):
    full = PoseSpace(56).fit(walks)
    a = full.angles(walks[0])
    assert a.shape == (150, 56)
    assert np.allclose(full.inverse_transform(full.transform(a)), a, atol=1e-6)
    space = PoseSpace(2).fit(walks)
    assert space.components_.shape == (2, 56)
    assert np.allclose(space.components_ @ space.components_.T, np.eye(2), atol=1e-9)
    # a take written a whole turn away in one channel is the same pose
    frames = np.array(walks[1].frames)
    frames[:, space.columns_[5]] += 360.0
    shifted = walks[1].with_frames(frames)
    assert np.allclose(space.transform(shifted), space.transform(walks[1]), atol=1e-9)


def test_check_takes_errors(walks):
    with pytest.raises(ParameterError, match="at least 2 training takes, got one take"):
        check_takes(walks[:1])
    other = walks[1].select([c for c in walks[1].channels if c != ("lfemur", "rz")])
    with pytest.raises(ParameterError, match="channels differ"):
        check_takes([walks[0], other])
    with pytest.raises(ParameterError, match="at least 3 training takes"):
        check_takes(walks[:2], minimum=3)


# --------------------------------------------------------------------------- graphs
def test_training_vectors_half_forward_difference_backward_at_end():
    p = np.array([[0.0, 0], [1, 0], [3, 0], [10, 0], [10, 2]])
    take = np.array([0, 0, 0, 1, 1])
    v = training_vectors(p, take)
    assert np.allclose(v, [[0.5, 0], [1, 0], [1, 0], [0, 1], [0, 1]])


def test_delaunay_edges_are_simplex_pairs_directed_along_velocity():
    takes = [circle(40, 1.0), circle(40, 1.3, 0.1), circle(35, 0.8, 0.2)]
    g = build_graph(takes, "delaunay")
    pts = np.vstack(takes)
    tri = Delaunay(pts)
    pairs = {
        tuple(sorted((int(s[a]), int(s[b]))))
        for s in tri.simplices
        for a in range(3)
        for b in range(a + 1, 3)
    }
    n_own = g.n_nodes - g.n_takes
    got = {tuple(sorted(e)) for e in g.edges[n_own:].tolist()}
    own = {tuple(sorted(e)) for e in g.edges[:n_own].tolist()}
    assert got | (pairs & own) == pairs
    v = g.velocities
    for a, b in g.edges[n_own:]:
        assert (v[a] + v[b]) @ (g.points[b] - g.points[a]) > 0
    nxg = g.to_networkx()
    assert nxg.number_of_nodes() == g.n_nodes and nxg.number_of_edges() == len(g.edges)
    assert nxg.nodes[45]["take"] == 1 and nxg.nodes[45]["frame"] == 5
    c = g.connectivity()
    assert c["weak_components"] == 1 and c["strong_components"] == 1 and c["H"]["connected"]


def test_knn_graph_reports_takes_that_cannot_reach_each_other():
    a = np.stack([np.linspace(0, 1, 20), np.zeros(20)], axis=1)
    b = a + [0.0, 50.0]
    g = build_graph([a, b], "knn", k=3)
    c = g.connectivity()
    assert c["weak_components"] == 2
    assert c["strong_components"] == 40  # straight lines: nothing comes back
    assert sorted(c["cannot_reach"]) == [[0, 1], [1, 0]]
    assert not c["H"]["connected"]
    # every frame has its 3 nearest as neighbours (one direction or the other)
    und = {tuple(sorted(e)) for e in g.edges.tolist()}
    assert (0, 1) in und and (0, 3) in und


def test_delaunay_keeps_qhull_dropped_duplicates():
    pts = circle(30, 1.0)
    dup = np.vstack([pts, pts[:1]])  # frame 30 repeats frame 0
    g = build_graph([dup, circle(25, 1.4, 0.05)], "delaunay")
    assert g.n_coplanar >= 1
    und = {tuple(sorted(e)) for e in g.edges.tolist()}
    assert any(30 in e for e in und - {(29, 30)})


def test_union_contains_both():
    takes = [circle(40, 1.0), circle(40, 1.2, 0.1)]
    e = {
        m: {tuple(sorted(x)) for x in build_graph(takes, m, k=4).edges.tolist()}
        for m in ("delaunay", "knn", "union")
    }
    assert e["delaunay"] | e["knn"] == e["union"]


def test_too_many_delaunay_dims_is_one_clear_line():
    pts = np.random.default_rng(0).normal(size=(2000, 6))
    with pytest.raises(ParameterError, match="6 dimensions would hold about .* use method 'knn'"):
        build_graph([pts[:1000], pts[1000:]], "delaunay")
    build_graph([pts[:1000], pts[1000:]], "knn")  # k-NN is fine


# ---------------------------------------------------------------------------- field
def test_field_weights_and_fallback():
    takes = [circle(60, 1.0), circle(60, 1.3, 0.05)]
    g = build_graph(takes, "delaunay")
    f = VectorField(g)
    idx, w, inside = f.neighbours(np.array([[1.1, 0.05], [5.0, 5.0]]))
    assert np.allclose(w.sum(axis=1), 1.0)
    assert inside.tolist() == [True, False]
    assert (w[0] > 0).sum() == 3  # a triangle's vertices
    knn = VectorField(build_graph(takes, "knn"))
    assert np.allclose(f(np.array([5.0, 5.0])), knn(np.array([5.0, 5.0])))
    # on a training frame the field is that frame's vector
    assert np.allclose(f(g.points[7]), g.velocities[7])
    # inverse-square weights
    x = np.array([[1.1, 0.05]])
    d2 = ((g.points[idx[0]] - x) ** 2).sum(axis=1)
    expect = (1 / d2) * (w[0] > 0)
    assert np.allclose(w[0], expect / expect.sum())


def test_parse_variant_names_and_errors():
    assert parse_variant("delaunay") == ("delaunay", False, False)
    assert parse_variant("delaunay+ring+agree") == ("delaunay", True, True)
    assert parse_variant("union+agree") == ("union", False, True)
    for bad, msg in (
        ("knn+agree", "need the Delaunay triangulation"),
        ("delaunay+ring+ring", "once each"),
        ("delaunay+smooth", "optionally followed by"),
        ("voronoi", "unknown graph method"),
    ):
        with pytest.raises(ParameterError, match=msg):
            parse_variant(bad)
    g = build_graph([circle(30), circle(30, 1.2, 0.1)], "knn")
    with pytest.raises(ParameterError, match="ring and agree need"):
        VectorField(g, agree=True)


def test_ring_neighbourhood_is_the_simplex_and_the_vertices_across_its_facets():
    takes = [circle(60, 1.0), circle(60, 1.3, 0.05), circle(50, 0.8, 0.1)]
    g = build_graph(takes, "delaunay")
    tri = g.delaunay
    f = VectorField(g, ring=True)
    assert f.name == "delaunay+ring"
    x = np.array([[0.0, 1.12], [-0.7, -0.75], [5.0, 5.0]])
    idx, w, inside = f.neighbours(x)
    assert inside.tolist() == [True, True, False]
    for r in range(2):
        s = int(tri.find_simplex(x[r]))
        expect = set(tri.simplices[s].tolist())
        for n in tri.neighbors[s]:
            if n >= 0:
                expect |= set(tri.simplices[n].tolist())
        got = idx[r][w[r] > 0]
        assert len(got) == len(set(got.tolist())) == len(expect) > 3
        assert set(got.tolist()) == expect
        d2 = ((g.points[got] - x[r]) ** 2).sum(axis=1)
        assert np.allclose(w[r][w[r] > 0], (1 / d2) / (1 / d2).sum())
    assert (w[2] > 0).sum() == f.k  # outside the hull: k-NN, as the plain field


def test_agree_weights_drop_neighbours_moving_against_the_heading():
    takes = [circle(60, 1.0), circle(60, 1.3, 0.05)]
    g = build_graph(takes, "delaunay")
    plain, agree = VectorField(g), VectorField(g, agree=True)
    x = np.array([[1.1, 0.05]])
    idx, w0, _ = plain.neighbours(x)
    v = g.velocities[idx[0]]
    h = v[np.argmax(w0[0])]  # the heaviest neighbour's direction
    _, w, _ = agree.neighbours(x, h)
    cos = v @ h / (np.linalg.norm(v, axis=1) * np.linalg.norm(h))
    expect = w0[0] * np.maximum(cos, 0)
    assert np.allclose(w[0], expect / expect.sum())
    # a heading against every neighbour, none, or a point outside the hull: plain weights
    for args in ((x, -h), (x, None), (np.array([[5.0, 5.0]]), h)):
        assert np.allclose(agree.neighbours(*args)[1], plain.neighbours(args[0])[1])
    # one neighbour against the heading, the others with it: that one gets no weight
    vel = g.velocities.copy()
    vel[idx[0][0]] = -h
    g2 = build_graph(takes, "delaunay")
    g2.velocities = vel
    _, w2, _ = VectorField(g2, agree=True).neighbours(x, h)
    assert w2[0][0] == 0 and w2[0].sum() == pytest.approx(1.0)


def hairpin_takes(sigma: float = 0.01, height: float = 0.05, seed: int = 0) -> list:
    """Three noisy takes of a flat loop that dwells at its two tips: each tip a hairpin
    where frames going out and frames coming back lie in one simplex (as at the CMU
    walks' cusps in a 2-D PCA plane)."""
    out = []
    for i in range(3):
        u = 0.1 * i + 2 * np.pi * np.arange(90) / 90
        t = u - 0.45 * np.sin(2 * u)
        p = np.stack([np.cos(t), height * np.sin(t)], axis=1)
        out.append(p + np.random.default_rng(seed + i).normal(scale=sigma, size=p.shape))
    return out


def test_paper_field_stalls_at_a_noisy_hairpin_ring_agree_goes_round():
    takes = hairpin_takes()
    turns = {}
    for variant in ("delaunay", "knn", "delaunay+ring+agree"):
        method, ring, agree = parse_variant(variant)
        f = VectorField(build_graph(takes, method), ring=ring, agree=agree)
        p = follow_field(f, takes[0][0], 180)  # the paper's step: two loops' frames, one loop
        ang = np.unwrap(np.arctan2(p.points[:, 1] / 0.05, p.points[:, 0]))
        turns[variant] = (ang[-1] - ang[0]) / (2 * np.pi)
        assert p.kind == f"field:{variant}:euler"
    assert abs(turns["delaunay"]) < 0.25 and abs(turns["knn"]) < 0.25  # stuck at a tip
    assert turns["delaunay+ring+agree"] > 0.9


def test_follow_field_goes_round_the_loop():
    takes = [circle(80, 1.0), circle(80, 1.1, 0.3), circle(80, 0.9, 0.6)]
    for method in ("delaunay", "knn", "union"):
        f = VectorField(build_graph(takes, method))
        for integ in ("euler", "rk4"):
            p = follow_field(f, takes[0][0], 120, integ, step_scale=2.0)
            r = np.linalg.norm(p.points, axis=1)
            assert p.points.shape == (120, 2)
            ang = np.unwrap(np.arctan2(p.points[:, 1], p.points[:, 0]))
            assert ang[-1] - ang[0] > 2 * np.pi  # more than a full turn, anticlockwise
            assert p.outside_hull_steps == 0
            if integ == "euler":  # full steps along chords retrace the polygon
                assert 0.95 < r.min() and r.max() < 1.05
            else:  # the continuous flow of chord vectors (pointing inwards) spirals in
                assert r[-1] < 0.9 and r.max() <= 1.0 + 1e-9
    with pytest.raises(ParameterError, match="n_frames"):
        follow_field(f, takes[0][0], 0)
    with pytest.raises(ParameterError, match="integrator"):
        follow_field(f, takes[0][0], 5, "midpoint")


def test_shortest_path_and_target():
    takes = [circle(40, 1.0), circle(40, 1.2, 0.1)]
    g = build_graph(takes, "delaunay")
    nodes = shortest_path(g, 0, 60)
    edges = {tuple(e) for e in g.edges.tolist()}
    assert nodes[0] == 0 and nodes[-1] == 60
    assert all((a, b) in edges for a, b in zip(nodes[:-1], nodes[1:]))
    p = path_to_target(g, g.points[0], g.points[60])
    assert np.allclose(p.points[0], g.points[0]) and np.allclose(p.points[-1], g.points[60])
    lines = build_graph(
        [np.stack([np.linspace(0, 1, 10), np.zeros(10)], 1)] * 1
        + [np.stack([np.linspace(0, 1, 10), np.full(10, 9.0)], 1)],
        "knn",
        k=2,
    )
    with pytest.raises(ParameterError, match="no path"):
        shortest_path(lines, 0, 15)


# --------------------------------------------------------------------- errors, topology
def test_path_errors_and_bottleneck():
    true = circle(100)
    a, f = path_errors(np.linalg.norm(true[:, None] - true[None], axis=2))
    assert a == 0 and f == 0
    still = true[:1]
    a, f = path_errors(np.linalg.norm(true[:, None] - still[None], axis=2))
    assert f == pytest.approx(np.linalg.norm(true[-1] - true[0]))
    d1, d2 = h1_diagram(true), h1_diagram(circle(100, 1.2))
    assert len(d1) >= 1 and d1[:, 1].max() == pytest.approx(1.0, abs=0.01)
    assert bottleneck(d1, d2) == pytest.approx(0.2, abs=0.02)  # deaths 1 and 1.2
    assert bottleneck(d1, np.zeros((0, 2))) == pytest.approx(0.5 * np.ptp(d1[np.argmax(d1[:, 1])]))
    assert bottleneck(d1, d1) == pytest.approx(0.0, abs=1e-12)


def test_cross_validate_report_keys(walks):
    cv = cross_validate(walks, methods=("delaunay", "delaunay+ring+agree", "knn"), dims=2)
    assert len(cv.folds) == 9
    assert set(cv.median) == {"delaunay", "delaunay+ring+agree", "knn"}
    assert set(cv.graph["edges"]) == {"delaunay", "knn"}  # one graph per method
    keys = {
        "held_out",
        "method",
        "error_a",
        "error_f",
        "error_a_deg",
        "error_f_deg",
        "error_topo",
        "outside_hull_steps",
    }
    assert all(keys <= set(f) for f in cv.folds)
    for m in ("delaunay", "knn"):
        assert {"error_a", "error_f", "error_a_deg", "error_f_deg", "error_topo"} <= set(
            cv.median[m]
        )
        assert cv.median[m]["error_f_deg"] < cv.baselines["standing_still"]["median"]["error_f_deg"]
    assert set(cv.baselines) == {"standing_still", "nearest_take"}
    assert {"nodes", "edges", "weak_components", "strong_components"} <= set(cv.graph)
    # the synthetic takes are none of the paper's sets: no paper row (w1's was printed for any)
    assert "paper w1: delaunay" not in cv.table() and "no paper row" in cv.table()


def test_synth_generates_a_playable_walk(walks):
    # the root as the training frames' mean step (carry=False): the synthetic walker's own
    # feet glide (support foot 2.08 m/s on the take itself), so carried by them it would
    # travel a third as far
    synth = MotionGraphSynth(dims=2, step_scale=2.0, carry=False).fit(walks)
    gen = synth.generate(120, walks[0], 10)
    m = gen.motion
    assert m.n_frames == 120 and m.channels == walks[0].channels
    root = walks[0].frames[10, :3]
    assert np.allclose(m.frames[0, [0, 2]], root[[0, 2]], atol=1e-6)
    travel = np.linalg.norm(m.frames[-1, [0, 2]] - m.frames[0, [0, 2]])
    real = np.linalg.norm(walks[0].frames[129, [0, 2]] - walks[0].frames[10, [0, 2]])
    assert 0.5 * real < travel < 1.5 * real
    with pytest.raises(ParameterError, match="start frame 500 is outside its 150 frames"):
        synth.generate(10, walks[0], 500)


def test_target_path_keeps_to_the_data_with_squared_costs():
    takes = [circle(60, 1.0), circle(60, 1.1, 0.05), circle(60, 0.9, 0.1)]
    g = build_graph(takes, "delaunay")
    start, target = g.points[0], g.points[30]  # opposite sides of the ring
    near = lambda p: g.tree.query(p.points)[0].max()  # noqa: E731
    p = path_to_target(g, start, target)
    assert near(p) < 0.1
    # along the takes' direction of travel (anticlockwise), not back against it
    ang = np.unwrap(np.arctan2(p.points[:, 1], p.points[:, 0]))
    assert np.all(np.diff(ang) > -0.05) and ang[-1] - ang[0] == pytest.approx(np.pi, abs=0.2)


def test_cross_validate_phase_aware_method_and_auto_dims(walks):
    """``delaunay+phase`` (what ``cyclecoord graph`` generates with) is cross-validated as
    that command generates, and ``dims="auto"`` picks each fold's dimensions from its
    training takes (the command line passed 2 for ``--dims auto`` before)."""
    import warnings

    from cyclecoord.synthesis.graph.model import auto_dims

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cv = cross_validate(walks, methods=("delaunay", "delaunay+phase"), dims="auto",
                            topo=False, horizon=2)
    assert set(cv.median) == {"delaunay", "delaunay+phase"} and len(cv.folds) == 6
    assert cv.parameters["dims"] == "auto"
    for i, name in enumerate(dict.fromkeys(f["held_out"] for f in cv.folds)):
        want = auto_dims([m for j, m in enumerate(walks) if j != i])
        assert {f["dims"] for f in cv.folds if f["held_out"] == name} == {want}
    still = cv.baselines["standing_still"]["median"]
    ours = cv.median["delaunay+phase"]
    assert np.isfinite(ours["error_a_deg"]) and ours["error_f_deg"] < still["error_f_deg"]
    assert ours["error_a_deg"] < cv.median["delaunay"]["error_a_deg"]
    assert cv.long["delaunay+phase"]["freeze_folds"] == 0
    with pytest.raises(ParameterError, match="dims"):
        cross_validate(walks, methods=("delaunay",), dims=0)


def test_crossval_prints_the_papers_row_for_its_set_and_a_longer_horizon(walks):
    from cyclecoord.synthesis.graph import PAPER, paper_set

    long_take = cc.datasets.make_periodic_capture(kind="walk", n_frames=460, random_state=0).motion
    lengths = lambda ns: [long_take[:n] for n in ns]  # noqa: E731
    assert paper_set(lengths((167, 167, 175, 160))) == "r1"
    assert paper_set(lengths((443, 360, 455, 454))) == "w1"
    assert paper_set(lengths((100, 120, 130))) is None
    assert PAPER["r1"]["delaunay"] == {"error_a": 0.749, "error_f": 0.038}
    assert PAPER["r1"]["knn"] == {"error_a": 0.099, "error_f": 0.044}
    cv = cross_validate(walks, methods=("delaunay", "knn"), dims=2, topo=False, horizon=3)
    assert "no paper row" in cv.table() and "paper w1" not in cv.table()
    cv.parameters["paper_set"] = "r1"
    table = cv.table()
    rows = {line[:26].strip(): line[26:].split()[:2] for line in table.splitlines()}
    assert rows["paper r1: delaunay"] == ["0.749", "0.038"]
    assert rows["paper r1: knn"] == ["0.099", "0.044"]
    long = cv.long_table()
    assert "3x the left-out take" in long and "freeze s" in long and "slip m/s" in long
    assert set(cv.long) == {"delaunay", "knn"}
    fold = cv.folds[0]["long"]
    assert fold["frames"] == 3 * walks[0].n_frames
    assert {"longest_freeze_s", "support_slip", "error_f_deg"} <= set(fold)
    assert cv.to_report()["long_horizon"] == cv.long


def test_synth_on_a_static_root_rig_is_the_same_walk_written_back_in_that_rig(walks):
    """A static ``joint_Root`` above travelling hips, 6 channels on every joint (the Bandai
    layout): the graph is built in the analysis rig and its output written back in the
    takes' own rig, the same motion as on the plain rig (issue 24 on any rig). Before,
    the hips' heading was a joint angle of the pose space and their travel was not the
    root's: the measure read the feet 4 m under the floor and the root still."""
    from _rigs import static_root

    from cyclecoord.conventions import to_bvh_convention
    from cyclecoord.quality.generated import measure_generated

    walks = [to_bvh_convention(w, "ZXY") for w in walks]
    turn = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])  # 90 deg about y
    bandai = [static_root(w, turn, [5.0, 0.0, -3.0], True) for w in walks]
    bandai = [b.with_frames(b.frames, fps=w.fps) for b, w in zip(bandai, walks)]
    plain = MotionGraphSynth(dims=2).fit(walks).generate(90, 0, 10).motion
    gen = MotionGraphSynth(dims=2).fit(bandai).generate(90, 0, 10).motion
    assert gen.channels == bandai[0].channels and gen.skeleton.names == bandai[0].skeleton.names
    # the static root stays where it was; the same body poses as on the plain rig
    root = [gen.channel_index("joint_Root", d) for d in ("tx", "ty", "tz")]
    np.testing.assert_allclose(gen.frames[:, root], [[5.0, 0.0, -3.0]] * 90, atol=1e-9)
    for c in walks[0].channels[6:]:  # degrees: the legs' IK lock converges to ~1e-6
        np.testing.assert_allclose(
            gen.frames[:, gen.channel_index(*c)], plain.frames[:, plain.channel_index(*c)],
            atol=1e-5,
        )
    # world positions: the plain walk turned and shifted as the static root turns it
    p_gen, p_plain = gen.positions().positions[:, 1:], plain.positions().positions
    np.testing.assert_allclose(p_gen, p_plain @ turn.T + [5.0, 0.0, -3.0], atol=1e-6)
    a, b = measure_generated(gen, bandai), measure_generated(plain, walks)
    for key in ("support_slip", "largest_accel", "root_speed", "source_root_speed"):
        assert getattr(a, key) == pytest.approx(getattr(b, key), rel=1e-6, abs=1e-9), key


def test_synth_refuses_takes_whose_rigs_read_differently(walks):
    from _rigs import static_root

    from cyclecoord.conventions import to_bvh_convention

    walks = [to_bvh_convention(w, "ZXY") for w in walks]
    other = static_root(walks[1], np.eye(3), [0.0, 0.0, 0.0], True)
    with pytest.raises(ParameterError, match="differ"):
        MotionGraphSynth(dims=2).fit([static_root(walks[0], np.eye(3), [0, 0, 0], False),
                                      other])
