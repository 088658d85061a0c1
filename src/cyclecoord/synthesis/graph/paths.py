"""Paths through the latent space: following the field, or shortest paths to a target.

:func:`follow_field` is the paper's generator (§III-F): from a start point, repeatedly
sample the field and move by that vector (``"euler"``), or by a classical fourth-order
Runge-Kutta step (``"rk4"``).  The paper's training vectors are half a frame's change,
so with ``step_scale=1`` a generated frame advances half as far as a captured one and
the motion plays at about half the captured speed; ``step_scale=2`` plays at about the
captured speed.

:func:`path_to_target` is the paper's future work (§V-A): the shortest path on the
motion graph (Dijkstra in :mod:`scipy.sparse.csgraph`, edge weights = latent lengths)
from the frame nearest a start pose to the frame nearest a target pose, resampled to
the median step of the training frames.

:func:`root_trajectory` makes the result move through space.  For every training frame
it takes the root's heading (yaw of its forward axis about the vertical), its per-frame
step in the heading's frame, its heading change, its height and its tilt (the root's
rotation with the heading removed, as a rotation vector).  A generated frame takes the
weighted mean of these over the training frames that weigh on it in the field (the
simplex's vertices or the k nearest frames, weights ``1/D**2``); steps are scaled by the
path's speed, and headings and positions are integrated from the start frame's root.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.sparse import csgraph
from scipy.spatial.transform import Rotation

from ...errors import ParameterError
from ...motion import Motion
from .build import MotionGraph
from .field import VectorField

__all__ = [
    "GraphPath",
    "follow_field",
    "path_to_target",
    "shortest_path",
    "root_trajectory",
    "INTEGRATORS",
]

INTEGRATORS = ("euler", "rk4")


@dataclass
class GraphPath:
    """A generated path in the latent space.

    Attributes
    ----------
    points : ndarray, shape (N, d)
        Latent points, frame 0 the start.
    neighbours : ndarray of int, shape (N, K)
        Training frames weighing on each point (the field's neighbourhood).
    weights : ndarray, shape (N, K)
        Their weights (rows sum to 1).
    inside : ndarray of bool, shape (N,)
        False where the step fell back from Delaunay to k-NN outside the hull.
    speed : float
        Latent advance per frame relative to a captured frame (0.5 for the paper's step).
    kind : str
        ``"field:<variant>:<integrator>"`` (e.g. ``field:delaunay+ring+agree:euler``) or
        ``"graph:<method>"``.
    nodes : ndarray of int or None
        The graph nodes a shortest path visits.
    phases : ndarray or None
        The gait phase (cycles) of each point on a phase-aware path
        (:mod:`~cyclecoord.synthesis.graph.phase`).
    """

    points: np.ndarray
    neighbours: np.ndarray
    weights: np.ndarray
    inside: np.ndarray
    speed: float
    kind: str
    nodes: np.ndarray | None = None
    phases: np.ndarray | None = None

    @property
    def n_frames(self) -> int:
        return int(self.points.shape[0])

    @property
    def outside_hull_steps(self) -> int:
        return int((~self.inside).sum())


def _check_start(field: VectorField, start: np.ndarray) -> np.ndarray:
    x = np.asarray(start, dtype=float).reshape(-1)
    if x.shape[0] != field.dims or not np.all(np.isfinite(x)):
        raise ParameterError(
            f"the start must be {field.dims} finite latent coordinates, got {start!r}"
        )
    return x


#: Largest step, in training steps: beyond it a step leaves the training data at once.
MAX_STEP_SCALE = 1e3


def follow_field(
    field: VectorField,
    start: np.ndarray,
    n_frames: int,
    integrator: str = "euler",
    step_scale: float = 1.0,
) -> GraphPath:
    """Follow the field from ``start`` for ``n_frames`` frames (start included).

    Parameters
    ----------
    field : VectorField
    start : array_like, shape (d,)
        Latent start point (e.g. ``space.transform(take)[frame]``).
    n_frames : int
    integrator : {"euler", "rk4"}
        ``"euler"`` is the paper's step ``x + s v(x)``; ``"rk4"`` the classical Runge-Kutta
        step of the same length ``s``.
    step_scale : float, default 1
        ``s``: 1 is the paper's step (half the captured speed), 2 the captured speed.

    Returns
    -------
    GraphPath

    Notes
    -----
    An ``agree`` field (:class:`VectorField`) is given the path's previous step as its
    heading; the first step has none and takes the plain field.
    """
    x = _check_start(field, start)
    if isinstance(n_frames, bool) or not isinstance(n_frames, (int, np.integer)) or n_frames < 1:
        raise ParameterError(f"n_frames must be a whole number >= 1, got {n_frames!r}")
    if integrator not in INTEGRATORS:
        raise ParameterError(
            f"unknown integrator {integrator!r}; choose from {', '.join(INTEGRATORS)}"
        )
    s = float(step_scale)
    if not np.isfinite(s) or not 0 < s <= MAX_STEP_SCALE:
        raise ParameterError(
            f"step_scale must be a positive number of at most {MAX_STEP_SCALE:g} training "
            f"steps, got {step_scale!r}"
        )
    from ...io._limits import MAX_FRAMES, check_memory

    if n_frames > MAX_FRAMES:
        raise ParameterError(f"{n_frames:,} frames; at most {MAX_FRAMES:,} are supported")
    d = field.dims
    # the path, each step's neighbours and weights (Python lists of arrays)
    check_memory(n_frames * (8.0 * d + 400.0 + 24.0 * field.k), f"a path of {n_frames:,} frames")
    pts = np.empty((n_frames, d))
    inside = np.ones(n_frames, dtype=bool)
    nbrs, wts = [], []
    vel = field.graph.velocities
    h = None  # the heading (previous step) an "agree" field weighs its neighbours by
    for t in range(n_frames):
        pts[t] = x
        idx, w, ins = field.neighbours(x[None], h)
        nbrs.append(idx[0])
        wts.append(w[0])
        if t == n_frames - 1:
            inside[t] = bool(ins[0])
            break
        k1 = np.einsum("k,kd->d", w[0], vel[idx[0]])  # no BLAS call per step
        if integrator == "euler":
            inside[t] = bool(ins[0])
            step = s * k1
        else:
            k2, i2 = field.evaluate((x + 0.5 * s * k1)[None], h)
            k3, i3 = field.evaluate((x + 0.5 * s * k2[0])[None], h)
            k4, i4 = field.evaluate((x + s * k3[0])[None], h)
            inside[t] = bool(ins[0] and i2[0] and i3[0] and i4[0])
            step = s * (k1 + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]) / 6.0
        x = x + step
        if not np.all(np.isfinite(x)):
            raise ParameterError(
                f"the path left every finite value at frame {t + 1} (step scale {s:g})"
            )
        if field.agree and np.any(step):
            h = step[None]
    width = max(len(a) for a in nbrs)
    neighbours = np.zeros((n_frames, width), dtype=int)
    weights = np.zeros((n_frames, width))
    for t, (a, b) in enumerate(zip(nbrs, wts)):
        neighbours[t, : len(a)] = a
        weights[t, : len(b)] = b
    return GraphPath(
        points=pts,
        neighbours=neighbours,
        weights=weights,
        inside=inside,
        speed=s / 2.0,
        kind=f"field:{field.name}:{integrator}",
    )


def shortest_path(graph: MotionGraph, source: int, target: int, power: float = 2.0) -> np.ndarray:
    """Graph nodes of the shortest directed path from ``source`` to ``target``.

    Edge costs are latent lengths to the ``power``: with 1 (plain length) a Delaunay path
    crosses the hole of a walk's loop on one long hull edge, through poses no take holds;
    the default 2 prefers many short steps along the data.

    Raises
    ------
    ParameterError
        When ``target`` cannot be reached from ``source``.
    """
    n = graph.n_nodes
    for name, v in (("source", source), ("target", target)):
        if not 0 <= int(v) < n:
            raise ParameterError(f"{name} node {v} is not one of the graph's {n} nodes")
    dist, pred = csgraph.dijkstra(
        graph.adjacency(power), directed=True, indices=int(source), return_predecessors=True
    )
    if not np.isfinite(dist[int(target)]):
        t, f = graph.take[target], graph.frame[target]
        s, g = graph.take[source], graph.frame[source]
        raise ParameterError(
            f"no path in the {graph.method} graph from {graph.take_names[s]} frame {g} "
            f"to {graph.take_names[t]} frame {f}"
        )
    nodes = [int(target)]
    while nodes[-1] != int(source):
        nodes.append(int(pred[nodes[-1]]))
    return np.asarray(nodes[::-1], dtype=int)


def path_to_target(
    graph: MotionGraph,
    start: np.ndarray,
    target: np.ndarray,
    speed: float = 1.0,
    power: float = 2.0,
) -> GraphPath:
    """Shortest graph path from the frame nearest ``start`` to the frame nearest ``target``.

    Edge costs are latent lengths to the ``power`` (see :func:`shortest_path`).

    The node sequence is resampled by arc length with the median latent step of the
    training frames times ``speed`` (1: the captured speed); each resampled point takes its
    two bracketing nodes as neighbours, weighted linearly.
    """
    a = int(graph.tree.query(np.asarray(start, dtype=float).reshape(-1))[1])
    b = int(graph.tree.query(np.asarray(target, dtype=float).reshape(-1))[1])
    nodes = shortest_path(graph, a, b, power)
    p = graph.points[nodes]
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    step = float(np.median(np.linalg.norm(2.0 * graph.velocities, axis=1))) * float(speed)
    m = max(int(np.ceil(arc[-1] / step)) + 1, 2) if arc[-1] > 0 else 1
    u = np.linspace(0.0, arc[-1], m)
    j = np.clip(np.searchsorted(arc, u, side="right") - 1, 0, max(len(nodes) - 2, 0))
    if len(nodes) == 1:
        frac = np.zeros(m)
        j2 = j
    else:
        frac = np.where(seg[j] > 0, (u - arc[j]) / np.where(seg[j] > 0, seg[j], 1.0), 0.0)
        j2 = j + 1
    pts = p[j] + frac[:, None] * (p[j2] - p[j])
    return GraphPath(
        points=pts,
        neighbours=np.stack([nodes[j], nodes[j2]], axis=1),
        weights=np.stack([1.0 - frac, frac], axis=1),
        inside=np.ones(m, dtype=bool),
        speed=float(speed),
        kind=f"graph:{graph.method}",
        nodes=nodes,
    )


# ----------------------------------------------------------------------------- root
def _root_features(motion: Motion) -> dict[str, np.ndarray]:
    """Per-frame heading, local step, heading change, height and tilt of a take's root."""
    from ..align import root_rotation

    mats, order, rcols = root_rotation(motion)
    root = motion.skeleton.joints[0].name  # type: ignore[union-attr]
    pos = np.zeros((motion.n_frames, 3))
    for ax in range(3):
        name = (root, "t" + "xyz"[ax])
        if name in motion.channels:
            pos[:, ax] = motion.frames[:, motion.channel_index(*name)]
    fwd = mats[:, :, 2]  # the rest pose faces +z (CMU, BVH: y up)
    heading = np.unwrap(np.arctan2(fwd[:, 0], fwd[:, 2]))
    yaw = Rotation.from_rotvec(heading[:, None] * np.array([0.0, 1.0, 0.0]))
    tilt = (yaw.inv() * Rotation.from_matrix(mats)).as_rotvec()
    delta = np.diff(pos, axis=0)
    delta = np.vstack([delta, delta[-1:]])
    dh = np.diff(heading)
    dh = np.append(dh, dh[-1:])
    local = yaw.inv().apply(delta)
    return {
        "heading": heading,
        "step": local,
        "turn": dh,
        "height": pos[:, 1],
        "tilt": tilt,
        "pos": pos,
        "order": order,
        "rcols": rcols,
    }


def root_trajectory(
    takes: Sequence[Motion],
    path: GraphPath,
    start_motion: Motion | None = None,
    start_frame: int = 0,
) -> np.ndarray:
    """Root channels ``(N, R)`` (``takes[0].root_channels()`` order) for a generated path.

    Parameters
    ----------
    takes : sequence of Motion
        The training takes, in the order the graph's nodes were built from.
    path : GraphPath
    start_motion : Motion, optional
        The take the path starts from: its root at ``start_frame`` gives the start
        position and heading (default: the origin, heading 0).
    start_frame : int

    Returns
    -------
    ndarray, shape (N, R)
    """
    from ...conventions import continuous_euler

    feats = [_root_features(m) for m in takes]
    cat = {k: np.concatenate([f[k] for f in feats]) for k in ("step", "turn", "height", "tilt")}
    w, idx = path.weights, path.neighbours

    def mean(a: np.ndarray) -> np.ndarray:
        return np.einsum("nk,nk...->n...", w, a[idx])

    step, turn = mean(cat["step"]) * path.speed, mean(cat["turn"]) * path.speed
    height, tilt = mean(cat["height"]), mean(cat["tilt"])
    n = path.n_frames
    if start_motion is not None:
        f0 = _root_features(start_motion)
        h0, p0 = float(f0["heading"][start_frame]), f0["pos"][start_frame].copy()
    else:
        h0, p0 = 0.0, np.zeros(3)
    heading = h0 + np.concatenate([[0.0], np.cumsum(turn[:-1])])
    yaw = Rotation.from_rotvec(heading[:, None] * np.array([0.0, 1.0, 0.0]))
    world_step = yaw.apply(step)
    pos = p0 + np.vstack([np.zeros((1, 3)), np.cumsum(world_step[:-1], axis=0)])
    pos[:, 1] = height
    rot = (yaw * Rotation.from_rotvec(tilt)).as_matrix()
    template = takes[0]
    root_joint = template.skeleton.joints[0]  # type: ignore[union-attr]
    if not np.allclose(root_joint.axis, np.eye(3)):
        rot = root_joint.axis.T @ rot @ root_joint.axis
    order, rcols = feats[0]["order"], feats[0]["rcols"]
    near = start_motion.frames[start_frame, rcols] if start_motion is not None else None
    euler = continuous_euler(rot[:, None], order, near)[:, 0]
    cols = template.root_channels()
    out = np.zeros((n, len(cols)))
    for j, c in enumerate(cols):
        _, dof = template.channels[c]
        if dof.startswith("t"):
            out[:, j] = pos[:, "xyz".index(dof[1])]
        else:
            out[:, j] = euler[:, order.lower().index(dof[1])]
    return out
