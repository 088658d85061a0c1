"""Leave-one-take-out cross-validation of field-following (Gauch & Peters §IV).

For each take: fit the latent space and build the graph on the other takes, start at the
left-out take's first frame, follow the field for as many frames as the take has, and
compare the generated path with the take.  The methods are the graph's, optionally with
the field options of :mod:`.field` (``"delaunay+ring+agree"``); the default set
(:data:`DEFAULT_METHODS`) holds the paper's two, that fix of the Delaunay field,
k-Delaunay and the phase-aware field (:mod:`.phase`) that ``cyclecoord graph`` generates
with, cross-validated as that command generates.

* **Error F**: distance from the generated path to the take's final point at their
  closest approach.
* **Error A**: the mean over the take's frames of the distance to the nearest generated
  frame, and the mean over generated frames of the distance to the nearest take frame,
  averaged.

Both are measured in three spaces:

* latent (``error_a``, ``error_f``): the fold's PCA space, divided by the longest side of
  the training points' bounding box (:attr:`PoseSpace.scale_`), which puts them on the
  scale of the paper's values (0.02-0.1);
* joint angles (``*_deg``): the generated points mapped back to the 56 angles (inverse
  PCA) against the take's own unwrapped angles, as the RMS over channels in degrees
  (Euclidean distance / sqrt(56)); this includes what PCA loses;
* joint positions (``*_pos``): forward kinematics with the root at the origin facing
  its rest direction, the RMS over joints of their distances (skeleton units; 5.64 cm
  on CMU).

``error_topo`` is the bottleneck distance (gudhi) between the H1 barcodes (alpha filtration, radii)
of the generated and the true take in the normalised latent space (first 3
coordinates): does
the generated motion loop like the real one?  Two baselines: standing still at the start
pose, and replaying the training take nearest the start pose from its nearest frame
(cut where that take ends).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from scipy.spatial.distance import cdist

from ...errors import ParameterError
from ...motion import Motion
from .build import build_graph
from .field import VectorField
from .latent import PoseSpace, check_takes
from ..._blas import one_blas_thread
from .paths import follow_field

__all__ = [
    "path_errors",
    "h1_diagram",
    "bottleneck",
    "CrossValidation",
    "cross_validate",
    "PAPER_W1",
    "PAPER",
    "PAPER_LENGTHS",
    "HORIZON",
    "paper_set",
    "ERROR_KEYS",
    "DEFAULT_METHODS",
]

#: The paper's Table II, set w1 (medians over the 4 folds; latent units).
PAPER_W1 = {
    "delaunay": {"error_a": 0.023, "error_f": 0.02},
    "knn": {"error_a": 0.022, "error_f": 0.057},
}
#: The paper's Table II, every set (w1, w2 walks; r1, r2 runs; k-NN with k = 16).
PAPER = {
    "w1": PAPER_W1,
    "w2": {
        "delaunay": {"error_a": 0.073, "error_f": 0.043},
        "knn": {"error_a": 0.105, "error_f": 0.114},
    },
    "r1": {
        "delaunay": {"error_a": 0.749, "error_f": 0.038},
        "knn": {"error_a": 0.099, "error_f": 0.044},
    },
    "r2": {
        "delaunay": {"error_a": 0.068, "error_f": 0.067},
        "knn": {"error_a": 0.118, "error_f": 0.024},
    },
}
#: The paper's Table I: each set's take lengths in frames.
PAPER_LENGTHS = {
    "w1": (443, 360, 455, 454),
    "w2": (347, 520, 269, 282),
    "r1": (167, 167, 175, 160),
    "r2": (258, 139, 200, 163),
}
#: The longer horizon: the field followed for this many times the left-out take.
HORIZON = 3


def paper_set(motions: Sequence[Motion]) -> str | None:
    """The paper's set whose take lengths (Table I) these takes have (within 2 frames,
    in any order), else None."""
    have = sorted(m.n_frames for m in motions)
    for name, lengths in PAPER_LENGTHS.items():
        want = sorted(lengths)
        if len(have) == len(want) and all(abs(a - b) <= 2 for a, b in zip(have, want)):
            return name
    return None


#: The paper's two, our fix of the Delaunay field (see :mod:`.field`), k-Delaunay, and
#: the phase-aware field (:mod:`.phase`) ``cyclecoord graph`` generates with.
DEFAULT_METHODS = ("delaunay", "delaunay+ring+agree", "knn", "union", "delaunay+phase")
#: Latent coordinates the H1 barcodes are computed in.
TOPO_DIMS = 3
ERROR_KEYS = (
    "error_a",
    "error_f",
    "error_a_deg",
    "error_f_deg",
    "error_a_pos",
    "error_f_pos",
    "error_topo",
)


def path_errors(dist: np.ndarray) -> tuple[float, float]:
    """Errors A and F from the distance matrix ``(T_true, N_generated)``."""
    a = 0.5 * (dist.min(axis=1).mean() + dist.min(axis=0).mean())
    f = dist[-1].min()
    return float(a), float(f)


def h1_diagram(points: np.ndarray) -> np.ndarray:
    """H1 bars ``(m, 2)`` of the alpha filtration of ``points`` (gudhi), as radii.

    The alpha complex (a subcomplex of the Delaunay triangulation) gives the same
    persistence as the Cech filtration, exactly and in milliseconds in 2-5 dimensions,
    where a full Vietoris-Rips filtration of 450 points takes most of a second.  Only the
    first :data:`TOPO_DIMS` coordinates are used (an alpha complex of 450 points costs
    1.5 s in 4 dimensions and 14 s in 5; the loop's bar hardly changes: 0.328 in 2
    dimensions, 0.341 in 5 on 35_16).
    """
    import gudhi

    x = np.unique(np.asarray(points, dtype=float)[:, :TOPO_DIMS], axis=0)
    if x.shape[0] < x.shape[1] + 2:
        return np.zeros((0, 2))
    st = gudhi.AlphaComplex(points=x).create_simplex_tree()
    st.compute_persistence()
    bars = np.asarray(st.persistence_intervals_in_dimension(1), dtype=float).reshape(-1, 2)
    bars = bars[np.isfinite(bars[:, 1]) & (bars[:, 1] > bars[:, 0])]
    return np.sqrt(bars)


def bottleneck(a: np.ndarray, b: np.ndarray) -> float:
    """Bottleneck distance between two persistence diagrams (gudhi)."""
    import gudhi

    return float(gudhi.bottleneck_distance(a, b))


def _joint_distance_matrix(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """RMS over joints of the joint distances between every pose of ``p`` (T, J, 3) and
    of ``q`` (N, J, 3): one Euclidean distance over all coordinates, over sqrt(J)."""
    return cdist(p.reshape(p.shape[0], -1), q.reshape(q.shape[0], -1)) / np.sqrt(p.shape[1])


class _Evaluator:
    """Distances between a generated path and the left-out take in the three spaces."""

    def __init__(self, space: PoseSpace, take: Motion, topo: bool) -> None:
        self.space = space
        self.take = take
        self.root = take.root_channels()
        self.angles = space.angles(take)
        self.latent = space.transform(self.angles)
        self.rms = np.sqrt(self.angles.shape[1])
        self.pos = self._positions(self.angles)
        self.topo = topo
        self.h1 = h1_diagram(self.latent / space.scale_) if topo else None

    def _positions(self, angles: np.ndarray) -> np.ndarray:
        frames = np.zeros((angles.shape[0], self.take.n_channels))
        frames[:, self.space.columns_] = angles
        return self.take.with_frames(frames).positions().positions

    def errors(self, latent: np.ndarray, angles: np.ndarray) -> dict[str, float]:
        a, f = path_errors(cdist(self.latent, latent))
        ad, fd = path_errors(cdist(self.angles, angles) / self.rms)
        ap, fp = path_errors(_joint_distance_matrix(self.pos, self._positions(angles)))
        out = {
            "error_a": a / self.space.scale_,
            "error_f": f / self.space.scale_,
            "error_a_deg": ad,
            "error_f_deg": fd,
            "error_a_pos": ap,
            "error_f_pos": fp,
        }
        out["error_topo"] = (
            bottleneck(self.h1, h1_diagram(latent / self.space.scale_))
            if self.topo
            else float("nan")
        )
        return out


@dataclass
class CrossValidation:
    """Per-fold errors, medians, baselines and graph sizes (see :func:`cross_validate`).

    Attributes
    ----------
    folds : list of dict
        ``held_out, method, dims, error_a, error_f, error_a_deg, error_f_deg, error_topo,
        outside_hull_steps`` (plus ``error_a_pos, error_f_pos``).
    median : dict
        ``{method: {error key: median over folds}}``.
    baselines : dict
        ``{"standing_still" | "nearest_take": {"folds": [...], "median": {...}}}``.
    graph : dict
        Graphs over all the takes: ``nodes`` and, per method, ``edges``,
        ``weak_components``, ``strong_components``.
    paths : dict
        ``{(held_out, method): GraphPath}`` for figures.
    parameters : dict
    long : dict
        The longer horizon's medians (``horizon`` times each left-out take).
    notes : list of str
        Takes of another actor put on the first take's skeleton.
    """

    folds: list
    median: dict
    baselines: dict
    graph: dict
    paths: dict = field(default_factory=dict)
    fold_graphs: list = field(default_factory=list)
    parameters: dict = field(default_factory=dict)
    long: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    def to_report(self) -> dict[str, Any]:
        return {
            "folds": self.folds,
            "median": self.median,
            "baselines": self.baselines,
            "graph": self.graph,
            "fold_graphs": self.fold_graphs,
            "parameters": self.parameters,
            "paper_w1": PAPER_W1,
            "paper_set": self.parameters.get("paper_set"),
            "paper": PAPER.get(self.parameters.get("paper_set") or "", None),
            "long_horizon": self.long,
            "notes": self.notes,
        }

    def table(self, paper: bool = True) -> str:
        """A Table II-style table of medians, the baselines and (optionally) the paper's w1 row."""
        cols = [
            ("error_a", "A", "{:.3f}"),
            ("error_f", "F", "{:.3f}"),
            ("error_a_deg", "A deg", "{:.2f}"),
            ("error_f_deg", "F deg", "{:.2f}"),
            ("error_a_pos", "A pos", "{:.2f}"),
            ("error_f_pos", "F pos", "{:.2f}"),
            ("error_topo", "topo", "{:.2f}"),
        ]
        head = (
            f"{'median over ' + str(len({f['held_out'] for f in self.folds})) + ' folds':<26}"
            + "".join(f"{c[1]:>9}" for c in cols)
        )
        lines = [head, "-" * len(head)]

        def row(name: str, vals: dict) -> str:
            return f"{name:<26}" + "".join(
                f"{(fmt.format(vals[k]) if k in vals and np.isfinite(vals[k]) else '-'):>9}"
                for k, _, fmt in cols
            )

        for m, vals in self.median.items():
            lines.append(row(m, vals))
        for b, res in self.baselines.items():
            lines.append(row(f"baseline: {b.replace('_', ' ')}", res["median"]))
        which = self.parameters.get("paper_set")
        if paper and which:
            for m, vals in PAPER[which].items():
                lines.append(row(f"paper {which}: {m}", vals))
        elif paper:
            lines.append(
                "(no paper row: these takes' lengths are not one of the paper's sets "
                + ", ".join(PAPER_LENGTHS)
                + ")"
            )
        return "\n".join(lines)

    def long_table(self) -> str:
        """The longer horizon: errors over :data:`HORIZON` times the left-out take, the
        longest freeze and the support-foot slip (quality.generated; root carried by the
        feet as ``cyclecoord graph`` writes it, no foot locking), medians over the folds."""
        if not self.long:
            return ""
        h = self.parameters.get("horizon", HORIZON)
        cols = [
            ("error_a_deg", "A deg", "{:.2f}"),
            ("error_f_deg", "F deg", "{:.2f}"),
            ("longest_freeze_s", "freeze s", "{:.2f}"),
            ("freeze_folds", "folds fz", "{:.0f}"),
            ("support_slip", "slip m/s", "{:.2f}"),
            ("slip_ratio", "slip x", "{:.1f}"),
        ]
        head = f"{str(h) + 'x the left-out take':<26}" + "".join(f"{c[1]:>9}" for c in cols)
        lines = [head, "-" * len(head)]
        for m, vals in self.long.items():
            lines.append(
                f"{m:<26}" + "".join(f"{_cell(vals.get(k), fmt):>9}" for k, _, fmt in cols)
            )
        return "\n".join(lines)


def _median(rows: list[dict]) -> dict[str, float]:
    keys = [k for k in ERROR_KEYS if rows and k in rows[0]]
    out = {}
    for k in keys:
        vals = np.array([r[k] for r in rows], dtype=float)
        out[k] = (
            float(np.median(vals[np.isfinite(vals)])) if np.isfinite(vals).any() else float("nan")
        )
    return out


def _baseline_rows(
    ev: _Evaluator, space: PoseSpace, train: list, train_names: list, n: int
) -> dict:
    """Standing still at the true start pose; replaying the nearest take from its nearest
    frame (cut where that take ends)."""
    still = np.repeat(ev.angles[:1], n, axis=0)
    train_angles = [space.angles(m) for m in train]
    d = [np.linalg.norm(a - ev.angles[0], axis=1) for a in train_angles]
    j = int(np.argmin([x.min() for x in d]))
    f0 = int(np.argmin(d[j]))
    replay = train_angles[j][f0 : f0 + n]
    return {
        "standing_still": ev.errors(space.transform(still), still),
        "nearest_take": {
            "replayed": f"{train_names[j]}:{f0}",
            "frames": int(replay.shape[0]),
            **ev.errors(space.transform(replay), replay),
        },
    }


def _graph_summary(takes: list, methods: list, dims: int, k: int, names: list) -> dict[str, Any]:
    """Nodes, and per method edges and components, of the graphs over all the takes."""
    full = PoseSpace(dims).fit(takes)
    latent_all = [full.transform(m) for m in takes]
    graph: dict[str, Any] = {
        "nodes": int(sum(len(z) for z in latent_all)),
        "edges": {},
        "weak_components": {},
        "strong_components": {},
    }
    from .model import _parse

    for method in dict.fromkeys(_parse(m)[0] for m in methods):
        c = build_graph(latent_all, method, k, names).connectivity()
        for key in ("edges", "weak_components", "strong_components"):
            graph[key][method] = c[key]
    return graph


#: A fold graph's connectivity figures kept in :attr:`CrossValidation.fold_graphs`.
_GRAPH_KEYS = ("nodes", "edges", "weak_components", "strong_components", "coplanar_dropped")
#: The longer horizon's figures, medians over the folds per method.
_LONG_KEYS = ("error_a_deg", "error_f_deg", "longest_freeze_s", "support_slip", "slip_ratio")


def _long_medians(folds: list, methods: Sequence[str]) -> dict:
    """Per method, the medians of the longer horizon's figures and the folds that froze."""
    long = {}
    for m in methods:
        rows = [r["long"] for r in folds if r["method"] == m and "long" in r]
        long[m] = {k: _nanmedian([r.get(k) for r in rows]) for k in _LONG_KEYS}
        long[m]["freeze_folds"] = float(sum(1 for r in rows if r.get("freezes")))
    return long


@one_blas_thread
def cross_validate(
    motions: Sequence[Motion],
    methods: Sequence[str] = DEFAULT_METHODS,
    dims: int = 2,
    k: int = 16,
    integrator: str = "euler",
    step_scale: float = 1.0,
    topo: bool = True,
    progress: bool = False,
    horizon: int = HORIZON,
) -> CrossValidation:
    """Leave-one-take-out cross-validation (the paper's Table II, with baselines).

    Parameters
    ----------
    motions : sequence of Motion
        At least 3 takes of one rig (another actor's put on the first's skeleton).
    methods : sequence of str
        ``"delaunay"``, ``"knn"``, ``"union"``, each optionally with the field options
        ``+ring`` and ``+agree`` (:func:`~.field.parse_variant`); one graph per fold
        serves every variant of a method.  With ``+phase`` (``"delaunay+phase"``, what
        ``cyclecoord graph`` generates with) the fold is generated as that command
        does (:func:`_phase_row`), the root neither carried nor the feet pinned for the
        errors.
    dims : int or "auto", default 2
        Latent dimensions of each fold's space (``"auto"``: :func:`~.model.auto_dims` of
        the fold's training takes).
    k : int, default 16
    integrator : {"euler", "rk4"}
    step_scale : float, default 1 (the paper's step)
    topo : bool, default True
        Compute the bottleneck distances (about half the time).
    progress : bool
        Show a tqdm bar over the folds.
    horizon : int, default 3
        Also follow the field for this many times the left-out take and measure the
        motion (:mod:`cyclecoord.quality.generated`: longest freeze, support-foot slip,
        root carried by the feet) with the angle errors over that length; 0 skips it.

    Returns
    -------
    CrossValidation
    """
    from .model import _parse, auto_dims

    notes: list[str] = []
    takes = check_takes(motions, minimum=3, notes=notes)
    methods = list(dict.fromkeys(str(m).strip() for m in methods))
    variants = {m: _parse(m) for m in methods}
    if dims != "auto" and (isinstance(dims, bool) or not isinstance(dims, (int, np.integer))
                           or dims < 1):
        raise ParameterError(f"dims must be a whole number >= 1 or 'auto', got {dims!r}")
    if not methods:
        raise ParameterError("give at least one method")
    names = [
        m.source.rsplit("/", 1)[-1].rsplit(".", 1)[0] if m.source else f"take {i}"
        for i, m in enumerate(takes)
    ]
    folds, paths, fold_graphs = [], {}, []
    base: dict[str, list] = {"standing_still": [], "nearest_take": []}
    order = range(len(takes))
    if progress:
        from tqdm import tqdm

        order = tqdm(order, desc="folds", unit="fold")
    for i in order:
        train = [m for j, m in enumerate(takes) if j != i]
        fold_dims = auto_dims(train) if dims == "auto" else int(dims)
        space = PoseSpace(fold_dims).fit(train)
        ev = _Evaluator(space, takes[i], topo)
        latent_train = [space.transform(m) for m in train]
        start, n = ev.latent[0], takes[i].n_frames
        graphs: dict = {}
        for method in methods:
            kind, ring, agree, phase = variants[method]
            if phase:
                row, path, c = _phase_row(method, ev, space, train, takes[i], fold_dims, k,
                                          integrator, step_scale, horizon)
                row = {"held_out": names[i], "method": method, "dims": fold_dims, **row}
                folds.append(row)
                paths[(names[i], method)] = path
                fold_graphs.append(
                    {"held_out": names[i], "method": method,
                     **{key: c[key] for key in _GRAPH_KEYS}, "H_connected": c["H"]["connected"]}
                )
                continue
            if kind not in graphs:
                g = build_graph(
                    latent_train, kind, k, [names[j] for j in range(len(takes)) if j != i]
                )
                graphs[kind] = (g, g.connectivity())
            graph, c = graphs[kind]
            field_ = VectorField(graph, ring=ring, agree=agree)
            path = follow_field(field_, start, n, integrator, step_scale)
            row = {"held_out": names[i], "method": method, "dims": fold_dims}
            row.update(ev.errors(path.points, space.inverse_transform(path.points)))
            row["outside_hull_steps"] = path.outside_hull_steps
            if horizon and horizon > 1:
                row["long"] = _long_row(
                    ev,
                    space,
                    train,
                    takes[i],
                    field_,
                    start,
                    n * int(horizon),
                    integrator,
                    step_scale,
                )
            folds.append(row)
            paths[(names[i], method)] = path
            fold_graphs.append(
                {"held_out": names[i], "method": method, **{key: c[key] for key in _GRAPH_KEYS},
                 "H_connected": c["H"]["connected"]}
            )
        train_names = [names[q] for q in range(len(takes)) if q != i]
        for key, row in _baseline_rows(ev, space, train, train_names, n).items():
            base[key].append({"held_out": names[i], **row})
    median = {m: _median([r for r in folds if r["method"] == m]) for m in methods}
    long = _long_medians(folds, methods) if horizon and horizon > 1 else {}
    baselines = {b: {"folds": rows, "median": _median(rows)} for b, rows in base.items()}
    graph = _graph_summary(takes, methods, auto_dims(takes) if dims == "auto" else dims, k,
                           names)
    params = {
        "methods": methods,
        "dims": dims,
        "k": k,
        "integrator": integrator,
        "step_scale": step_scale,
        "takes": names,
        "frames": [m.n_frames for m in takes],
        "paper_set": paper_set(takes),
        "horizon": int(horizon or 0),
        "units": {
            "error_a/error_f": "latent distance / longest side of the training points' box",
            "*_deg": "RMS over the joint-angle channels, degrees",
            "*_pos": "RMS joint distance, skeleton units (root at the origin)",
            "error_topo": "bottleneck distance of H1 barcodes (alpha radii), units of error_a",
        },
    }
    return CrossValidation(
        folds=folds,
        median=median,
        baselines=baselines,
        graph=graph,
        paths=paths,
        fold_graphs=fold_graphs,
        parameters=params,
        long=long,
        notes=notes,
    )


def _cell(value, fmt: str) -> str:
    return fmt.format(value) if value is not None and np.isfinite(value) else "-"


def _nanmedian(vals: list) -> float:
    a = np.array([np.nan if v is None else v for v in vals], dtype=float)
    return float(np.median(a[np.isfinite(a)])) if np.isfinite(a).any() else float("nan")


def _long_row(ev, space, train, take, field_, start, n, integrator, step_scale) -> dict:
    """Errors over ``n`` frames of the field from the take's start, and the measure of the
    motion made of them (root carried by the feet)."""
    from ...errors import CycleCoordError
    from ...quality.generated import measure_generated
    from ..carry import carry_by_feet
    from .model import CARRY_SMOOTH
    from .paths import root_trajectory

    path = follow_field(field_, start, n, integrator, step_scale)
    errs = ev.errors(path.points, space.inverse_transform(path.points))
    row = {k: errs[k] for k in ("error_a_deg", "error_f_deg") if k in errs}
    row["frames"] = n
    try:
        root = root_trajectory(train, path, take, 0)
        motion = carry_by_feet(space.motion(path.points, train[0], root), smooth=CARRY_SMOOTH)
        q = measure_generated(motion, train)
    except CycleCoordError as exc:
        row["not_measured"] = str(exc)
        return row
    row.update(
        longest_freeze_s=q.longest_freeze_s,
        freezes=[list(f) for f in q.freezes],
        support_slip=q.support_slip,
        slip_ratio=q.slip_ratio,
    )
    return row


def _phase_row(method, ev, space, train, take, dims, k, integrator, step_scale, horizon):
    """A fold of a phase-aware method (``delaunay+phase``): :class:`~.model.MotionGraphSynth`
    as ``cyclecoord graph`` generates (the path's pose with the neighbours' detail and the
    strides widened back), without the root carried or the feet pinned for the errors; its
    angles measured against the take's in the fold's space.  Returns the row (errors,
    outside-hull steps, and the longer horizon's with the root carried), the path and the
    graph's connectivity."""
    import warnings

    from ...errors import CycleCoordError
    from ...quality.generated import measure_generated
    from .model import MotionGraphSynth

    n = take.n_frames
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        synth = MotionGraphSynth(
            method=method, dims=dims, k=k, integrator=integrator, step_scale=step_scale,
            carry=False, lock=False,
        ).fit(train)
    gen = synth.generate(n, take, 0)
    angles = space.angles(gen.motion)
    row: dict[str, Any] = dict(ev.errors(space.transform(angles), angles))
    row["outside_hull_steps"] = gen.path.outside_hull_steps
    if horizon and horizon > 1:
        long_gen = synth.generate(n * int(horizon), take, 0)
        a = space.angles(long_gen.motion)
        errs = ev.errors(space.transform(a), a)
        lrow: dict[str, Any] = {key: errs[key] for key in ("error_a_deg", "error_f_deg")}
        lrow["frames"] = n * int(horizon)
        try:
            from ..carry import carry_by_feet
            from .model import CARRY_SMOOTH

            q = measure_generated(carry_by_feet(long_gen.motion, smooth=CARRY_SMOOTH), train)
            lrow.update(longest_freeze_s=q.longest_freeze_s,
                        freezes=[list(f) for f in q.freezes],
                        support_slip=q.support_slip, slip_ratio=q.slip_ratio)
        except CycleCoordError as exc:
            lrow["not_measured"] = str(exc)
        row["long"] = lrow
    return row, gen.path, synth.graph_.connectivity()
