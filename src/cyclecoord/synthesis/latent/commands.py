"""Commands that steer the particle (Bailey et al. Sec. 5.3): MOVE, IDLE, TRANSITION, PLAY.

:class:`Synthesizer` holds the named models, the particle's state and the frames made
so far.  MOVE follows a straight line or the shortest path through the command graph
(the training latent points, complete, edge cost ``||x_i - x_j||^p`` with ``p = 4``),
resampled to constant speed.  The paper writes the weight as ``||x_i - x_j||^-p``, the
affinity of the connectivity prior; as a shortest-path *cost* that would favour the
longest jumps, so the cost here is its reciprocal, which keeps paths on the data.
IDLE hovers within ``r`` of one or several poses, TRANSITION moves to the nearest bridge
and blends into the other model while both particles idle (always: without a bridge it
takes the cheapest route of crossings over the models, crossing at the closest poses
with a longer blend where no bridge is under the threshold), PLAY replays a training
segment as it was.  Root motion comes from the training frames nearest the particle.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import networkx as nx
import numpy as np

from ...errors import ParameterError
from ...motion import Motion
from .bridges import Bridges, check_compatible, find_bridges
from .easing import eased, resample, smootherstep, smoothstep
from .gplvm import sqdist
from .influence import pose_points
from .model import LatentModel, heading_matrix
from .particle import ParticleParams, RandomForce, simulate

__all__ = ["CommandGraph", "Crossings", "Synthesizer", "resample", "smootherstep", "smoothstep"]

#: A latent target whose density proxy is below this lies outside the model.
OUTSIDE_DENSITY = 0.05
#: A blend alone may accelerate a joint by at most this fraction of the two models'
#: training 99th percentile (the pose's own motion comes on top).
BLEND_ACCELERATION = 0.5
#: Speed of the MOVE to a crossing, as a fraction of the model's training speed: a
#: straight line to a far crossing can leave the data, where the pose changes fast (on
#: the shared-data models 1.0 made joints accelerate up to 1.74x the training 99th
#: percentile on the way, 0.6 at most 1.44x).
APPROACH_SPEED = 0.6
#: Seconds either side of a blend in which the root follows the planted feet.
PLANT_MARGIN = 0.2
#: Seconds over which a foot eases into and out of an IK lock.
LOCK_BLEND = 0.1
#: Shortest contact (s) the IK lock pins (shorter ones toggle and make the legs jitter).
LOCK_MIN_CONTACT = 0.2
#: Gaussian width (s) of the smoothing of the planted track's steps.
PLANT_SMOOTH = 0.07
#: Contact searches on the corrected motion.
PLANT_ROUNDS = 2
#: Longest blend, seconds.
MAX_BLEND = 4.0
#: Bytes of one edge of a networkx graph (its weight dict in both directions).
_EDGE_BYTES = 400
#: Bytes a synthesised frame takes until the motion is written, besides a training frame
#: (latent point, pose, root motion, the motion's frames, forward kinematics of the
#: checks) and per training frame (the kernel and root weights of the frame).
_FRAME_BYTES = 8 * 16
_FRAME_BYTES_PER_TRAINING_FRAME = 8 * 4

#: Without a bridge, pairs within this factor of the closest distance are candidates
#: (the one nearest the particle is taken).
CLOSE_ENOUGH = 1.1


def _isfinite(value: Any) -> bool:
    """``math.isfinite`` of a JSON or Python number; False, not an error as from
    ``np.isfinite``, for an integer too large for a float."""
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


@dataclass(frozen=True)
class Crossings:
    """Pairs of matching points from one model into another (see
    :meth:`Synthesizer.crossings`).

    Attributes
    ----------
    source, target : str
    source_points, target_points : ndarray, shape (K, q)
    distances : ndarray, shape (K,)
        RMS joint distance of the two poses, skeleton units.
    source_frames, target_frames : ndarray of int, shape (K,)
        The training frame each point is (-1 where it is a searched point).
    threshold : float
        The bridge threshold, skeleton units.
    """

    source: str
    target: str
    source_points: np.ndarray
    target_points: np.ndarray
    distances: np.ndarray
    source_frames: np.ndarray
    target_frames: np.ndarray
    threshold: float


class CommandGraph:
    """Shortest paths over a model's training latent points (complete graph, cost ``d^p``)."""

    def __init__(self, model: LatentModel, power: float = 4.0) -> None:
        from ...io._limits import check_memory

        self.model = model
        self.power = power
        X = model.X_
        n = X.shape[0]
        # networkx keeps every edge of the complete graph as Python objects
        check_memory(_EDGE_BYTES * n * (n - 1) / 2, f"the command graph of {n:,} latent points")
        i, j = np.triu_indices(n, 1)
        cost = np.sqrt(sqdist(X, X))[i, j] ** power
        self.graph = nx.Graph()
        self.graph.add_weighted_edges_from(zip(i.tolist(), j.tolist(), cost.tolist()))

    def path(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Polyline from ``a`` to ``b`` through training points, ``(M, q)``."""
        X = self.model.X_
        g = self.graph
        da = np.sqrt(((X - a) ** 2).sum(1)) ** self.power
        db = np.sqrt(((X - b) ** 2).sum(1)) ** self.power
        g.add_weighted_edges_from(("a", k, float(c)) for k, c in enumerate(da))
        g.add_weighted_edges_from(("b", k, float(c)) for k, c in enumerate(db))
        g.add_edge("a", "b", weight=float(np.linalg.norm(a - b) ** self.power))
        try:
            nodes = nx.dijkstra_path(g, "a", "b")
        finally:
            g.remove_nodes_from(["a", "b"])
        return np.vstack([a] + [X[k] for k in nodes[1:-1]] + [b])


@dataclass
class _Chunk:
    model: str
    X: np.ndarray
    angles: np.ndarray
    root: dict[str, np.ndarray]
    command: int


@dataclass
class Synthesizer:
    """Runs commands over named latent models and collects the frames.

    Parameters
    ----------
    models : dict of str to LatentModel
        Same joint-angle channels for any two models a TRANSITION joins.
    fps : float
        Output frame rate (one particle step a frame).
    seed : int
        Seeds the random force and IDLE's choice of poses.
    params : ParticleParams
    bridge_threshold : float, optional
        See :func:`~.bridges.find_bridges`.
    ease : float, default 0.25
        Seconds over which a MOVE's path speeds up and slows down (0: the paper's
        constant speed throughout).
    clamp : bool, default True
        Clip joint angles to the training range of the model(s) making each frame (the
        count and largest clip are kept in ``clamped``).
    plant : {"all", "transitions", "off"}, default "all"
        Where :meth:`motion` moves the root as the planted feet carry it.  ``"all"``:
        everywhere, by :func:`~cyclecoord.synthesis.carry.carry_by_feet` (contact from
        height, not speed, the lowest foot carrying the body; IDLE stands after 0.5 s; no
        foot under the training frames' floor), then, with ``lock``, the planted feet
        pinned where that makes no pop
        (:func:`~cyclecoord.synthesis.carry.lock_where_clean`, limit 1.5x the models'
        99th percentile of joint acceleration; the ``notes`` attribute says where not).
        ``"transitions"``: the blend windows and
        :data:`PLANT_MARGIN` around them only, with the speed-gated contacts of before
        (the feet elsewhere glide with the training frames' root velocity); ``"off"``.
    lock : bool, default True
        Also pin the planted feet in those spans by a leg IK
        (:func:`~cyclecoord.synthesis.footlock.lock_feet`).  On the shared-data models'
        56 transitions it leaves planted feet sliding on 11 % of the blend windows'
        frames instead of 54 %, but the locks' easing makes joints accelerate up to 3.1x
        the training 99th percentile (4 of 56 blend windows over 1.5x, 8 of 56 whole
        transitions), so it is off.
    feet : tuple of str, optional
        Foot point joint names the planting and locking use (default
        :func:`~cyclecoord.quality.legs.find_legs` on the motion: names of the common
        rigs, else its geometry).
    """

    models: dict[str, LatentModel]
    fps: float = 30.0
    seed: int = 0
    params: ParticleParams = field(default_factory=ParticleParams)
    bridge_threshold: float | None = None
    clamp: bool = True
    ease: float = 0.25
    plant: str = "all"
    lock: bool = True
    feet: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        if not self.models:
            raise ParameterError("no models")
        if not _isfinite(self.fps) or self.fps <= 0:
            raise ParameterError(f"fps must be positive, got {self.fps}")
        if self.plant not in ("transitions", "all", "off"):
            raise ParameterError(
                f"plant must be 'transitions', 'all' or 'off', got {self.plant!r}"
            )
        dims = {m.X_.shape[1] for m in self.models.values()}
        self.force = RandomForce(max(dims), self.params.timescale, random_state=self.seed)
        self.rng = np.random.default_rng(self.seed)
        self.chunks: list[_Chunk] = []
        self.current: str | None = None
        self.x = self.v = None
        self.t = 0.0
        self.command = -1
        self.events: list[dict[str, Any]] = []
        self._graphs: dict[str, CommandGraph] = {}
        self._bridges: dict[tuple[str, str], Bridges] = {}
        self._crossings: dict[tuple[str, str], Crossings] = {}
        self._acc: dict[str, float] = {}
        self.sim_seconds = 0.0
        self.sim_cpu_seconds = 0.0
        self.clamped = {"values": 0, "max_deg": 0.0}
        self.held: list[tuple[int, int]] = []  # frame ranges of IDLE commands
        self.notes: list[str] = []
        self._ranges: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._made = 0  # frames emitted so far
        widest = max(m.X_.shape[0] for m in self.models.values())
        channels = max(len(m.all_channels_) for m in self.models.values())
        self.frame_bytes = _FRAME_BYTES * channels + _FRAME_BYTES_PER_TRAINING_FRAME * widest

    def reserve(self, n: float, what: str = "") -> int:
        """``n`` more frames as a whole number, or ParameterError when the script's frames
        would pass :data:`~cyclecoord.io._limits.MAX_FRAMES` or the memory limit."""
        from ...io._limits import MAX_FRAMES, check_memory

        total = self._made + float(n)
        if not np.isfinite(total) or total > MAX_FRAMES:
            raise ParameterError(
                f"{what or 'the script'} would make {total:.4g} frames in all at {self.fps:g} "
                f"fps; at most {MAX_FRAMES:,} are supported"
            )
        check_memory(total * self.frame_bytes, f"{int(total):,} synthesised frames")
        return int(n)

    def _range(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        if name not in self._ranges:
            a = self.models[name].angles(self.models[name].frames_)
            self._ranges[name] = (a.min(axis=0), a.max(axis=0))
        return self._ranges[name]

    # ---------------------------------------------------------------- helpers
    def model(self, name: str) -> LatentModel:
        if name not in self.models:
            raise ParameterError(
                f"unknown model {name!r}; the script defines {sorted(self.models)}"
            )
        return self.models[name]

    def target(self, spec: Any, name: str | None = None) -> np.ndarray:
        """A latent point of model ``name`` from a spec: ``[x, y, z]``, ``{"frame": k}`` or
        ``{"segment": s, "time": seconds}``."""
        name = name or self.current
        m = self.model(name)
        q = m.X_.shape[1]
        if isinstance(spec, _Point):
            return np.asarray(spec, dtype=float)
        if isinstance(spec, (list, tuple)) and (
            len(spec) != q or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in spec
            )
        ):
            raise ParameterError(
                f"a latent target of {name!r} must be {q} numbers or a frame/segment, "
                f"got {str(spec)[:80]}"
            )
        if isinstance(spec, dict):
            unknown = sorted(set(spec) - {"frame", "segment", "time"})
            if unknown:
                raise ParameterError(
                    f"unknown target key(s) {unknown}; use frame, or segment and time"
                )
            if "frame" in spec:
                k = spec["frame"]
                if not isinstance(k, int) or isinstance(k, bool) or not 0 <= k < m.X_.shape[0]:
                    raise ParameterError(
                        f"target frame {k!r} is not a training frame of {name!r} "
                        f"(0..{m.X_.shape[0] - 1})"
                    )
                return m.X_[k].copy()
            if "segment" in spec:
                try:
                    s = m.segment_index(str(spec["segment"]))
                except KeyError:
                    raise ParameterError(
                        f"model {name!r} has no segment {spec['segment']!r}; it has "
                        f"{m.segment_names_}"
                    ) from None
                idx = np.flatnonzero(m.segments_ == s)
                t = spec.get("time", 0.0)
                end = float(m.times_[idx][-1])
                if (
                    not isinstance(t, (int, float))
                    or isinstance(t, bool)
                    or not 0 <= t <= end + 1e-9
                ):
                    raise ParameterError(
                        f"time {t!r} is not inside segment {spec['segment']!r} (0..{end:.3g} s)"
                    )
                return m.X_[idx[np.argmin(np.abs(m.times_[idx] - t))]].copy()
            raise ParameterError("a target needs frame, or segment (and time)")
        arr = np.asarray(spec, dtype=float) if isinstance(spec, (list, tuple)) else None
        if arr is None or arr.shape != (q,) or not np.isfinite(arr).all():
            raise ParameterError(
                f"a latent target of {name!r} must be {q} numbers or a frame/segment, got {spec!r}"
            )
        if m.density(arr)[0] < OUTSIDE_DENSITY:
            raise ParameterError(
                f"target {spec} lies outside model {name!r} (no training frame near it)"
            )
        return arr

    def _need_start(self, what: str) -> LatentModel:
        if self.current is None:
            raise ParameterError(
                f"{what} before the particle was placed (start it in a model first)"
            )
        return self.models[self.current]

    def _run(self, path: np.ndarray, radius: float | None = None) -> None:
        m = self._need_start("moving")
        params = self.params if radius is None else self.params.replace(radius=radius)
        t0, c0 = time.perf_counter(), time.process_time()
        self.reserve(path.shape[0] - 1)
        X, V = simulate(m, path, self.x, self.v, self.fps, params, self.force, self.t)
        self._emit(self.current, X, m.pose(X), self._root(m, X))
        self.sim_seconds += time.perf_counter() - t0
        self.sim_cpu_seconds += time.process_time() - c0
        self.x, self.v = X[-1], V[-1]

    def _clip(self, name: str, angles: np.ndarray) -> np.ndarray:
        """Joint limits: clip to the training range of model ``name`` (counted)."""
        if not self.clamp:
            return angles
        lo, hi = self._range(name)
        clipped = np.clip(angles, lo, hi)
        over = np.abs(clipped - angles)
        self.clamped["values"] += int((over > 1e-9).sum())
        self.clamped["max_deg"] = max(self.clamped["max_deg"], float(over.max(initial=0.0)))
        return clipped

    def _emit(self, name, X, angles, root, clip: bool = True) -> None:
        if clip:
            angles = self._clip(name, angles)
        self.chunks.append(_Chunk(name, X, angles, root, self.command))
        self._made += X.shape[0]
        self.t += X.shape[0] / self.fps

    @staticmethod
    def _root(m: LatentModel, X: np.ndarray) -> dict[str, np.ndarray]:
        w = m.root_weights(X)
        r = m.root_
        return {
            "height": w @ r.height,
            "velocity": w @ r.velocity,
            "turn": w @ r.turn,
            "tilt": np.einsum("tn,nab->tab", w, r.tilt),
        }

    def bridges_found(self) -> dict[tuple[str, str], Bridges]:
        """The bridges looked up so far (by :meth:`bridges`), by ``(from, to)`` model names."""
        return dict(self._bridges)

    def bridges(self, a: str, b: str) -> Bridges:
        key = (a, b)
        if key not in self._bridges:
            self._bridges[key] = find_bridges(
                self.model(a),
                self.model(b),
                names=key,
                threshold=self.bridge_threshold,
                random_state=self.seed,
            )
        return self._bridges[key]

    # --------------------------------------------------------------- commands
    def start(self, model: str, at: Any = None) -> None:
        """Place the particle in ``model`` (at a target, default its first training frame)."""
        m = self.model(model)
        self.current = model
        self.x = self.target(at, model) if at is not None else m.X_[0].copy()
        self.v = np.zeros_like(self.x)

    def move(
        self,
        to: Any,
        path: str = "line",
        duration: float | None = None,
        speed: float = 1.0,
        radius: float | None = None,
    ) -> None:
        """MOVE to a target along a line or the command graph's shortest path."""
        m = self._need_start("MOVE")
        goal = self.target(to)
        if path == "line":
            poly = np.vstack([self.x, goal])
        elif path == "graph":
            if self.current not in self._graphs:
                self._graphs[self.current] = CommandGraph(m)
            poly = self._graphs[self.current].path(self.x, goal)
        else:
            raise ParameterError(f"MOVE path must be 'line' or 'graph', got {path!r}")
        if not (
            isinstance(speed, (int, float)) and not isinstance(speed, bool)
            and _isfinite(speed) and speed > 0
        ):
            raise ParameterError(f"MOVE speed must be a positive number, got {speed!r}")
        length = float(np.linalg.norm(np.diff(poly, axis=0), axis=1).sum())
        if duration is None:
            with np.errstate(all="ignore"):
                frames = np.ceil(length / (m.speed_ * speed) * self.fps)
        else:
            if not (
                isinstance(duration, (int, float)) and not isinstance(duration, bool)
                and _isfinite(duration) and duration > 0
            ):
                raise ParameterError(
                    f"MOVE duration must be a positive number of seconds, got {duration!r}"
                )
            frames = round(duration * self.fps)
        n = max(1, self.reserve(frames if np.isfinite(frames) else np.inf, "MOVE"))
        ramp = int(round(self.ease * self.fps))
        if ramp:
            n += ramp  # the ramps lose about half their length each
        dense = resample(poly, max(length / (4 * n), 1e-12))
        s = (eased(n, ramp) if ramp else np.linspace(0, 1, n + 1)) * (dense.shape[0] - 1)
        samples = np.stack(
            [np.interp(s, np.arange(dense.shape[0]), dense[:, k]) for k in range(dense.shape[1])], 1
        )
        self._run(samples, radius)

    def idle(
        self, at: Any = None, duration: float = 1.0, radius: float | None = None, hover: float = 1.0
    ) -> None:
        """IDLE within ``radius`` of one point (default: where the particle is) or several."""
        self._need_start("IDLE")
        if not (
            isinstance(duration, (int, float)) and not isinstance(duration, bool)
            and _isfinite(duration) and duration > 0
        ):
            raise ParameterError(
                f"IDLE duration must be a positive number of seconds, got {duration!r}"
            )
        if not (
            isinstance(hover, (int, float)) and not isinstance(hover, bool)
            and _isfinite(hover) and hover > 0
        ):
            raise ParameterError(f"IDLE hover must be a positive number of seconds, got {hover!r}")
        self.reserve(duration * self.fps, "IDLE")
        many = isinstance(at, list) and at and all(isinstance(a, (dict, list)) for a in at)
        points = (
            [self.target(a) for a in at]
            if many
            else [self.target(at) if at is not None else self.x.copy()]
        )
        end = self.t + duration
        first = self.n_frames
        try:
            self._idle(points, end, radius, hover)
        finally:
            self.held.append((first, self.n_frames))

    def _idle(self, points, end: float, radius, hover: float) -> None:
        duration = end - self.t
        while self.t < end - 0.5 / self.fps:
            p = points[int(self.rng.integers(len(points)))] if len(points) > 1 else points[0]
            m = self.models[self.current]
            gap = float(np.linalg.norm(p - self.x))
            if gap > self.params.radius * m.speed_:
                self.move(_Point(p), radius=radius)
                if self.t >= end:
                    break
            n = max(
                1, int(round(min(hover if len(points) > 1 else duration, end - self.t) * self.fps))
            )
            self._run(np.repeat(p[None, :], n + 1, axis=0), radius)

    # ------------------------------------------------------------ crossings
    def crossings(self, src: str, to: str) -> Crossings:
        """Every way found from model ``src`` into ``to``, bridge or not.

        A matching pair of points is symmetric, so the bridges searched from ``to``'s
        training points into ``src`` serve as well as those from ``src`` into ``to``.
        Each source frame's closest pair is kept even above the threshold (the
        fallback when no bridge is under it); when no pair passes the density filter,
        the unfiltered closest pairs are used.
        """
        key = (src, to)
        if key in self._crossings:
            return self._crossings[key]
        m1, m2 = self.model(src), self.model(to)
        fw, bw = self.bridges(src, to), self.bridges(to, src)
        parts = []
        for raw in (False, True):
            d_fw = fw.best_raw if raw else fw.best
            d_bw = bw.best_raw if raw else bw.best
            t_fw = fw.raw_points if raw else fw.best_points
            s_bw = bw.raw_points if raw else bw.best_points
            a = np.flatnonzero(np.isfinite(d_fw))
            b = np.flatnonzero(np.isfinite(d_bw))
            parts = [
                (m1.X_[a], t_fw[a], d_fw[a], a, np.full(a.size, -1)),
                (s_bw[b], m2.X_[b], d_bw[b], np.full(b.size, -1), b),
            ]
            if a.size + b.size:
                break
        S, T, d, fs, ft = (np.concatenate([p[k] for p in parts]) for k in range(5))
        if not d.size:
            raise ParameterError(f"no pose of {src!r} could be matched in {to!r}")
        out = Crossings(src, to, S, T, d, fs.astype(int), ft.astype(int), fw.threshold)
        self._crossings[key] = out
        return out

    def route(self, src: str, to: str) -> list[str]:
        """Models from ``src`` to ``to`` along the cheapest chain of crossings.

        The paper (Sec. 7): two models with no matching poses may be joined through a
        third that has matching points with both.  Each hop costs
        ``max(1, d / threshold)^2`` for the closest pair ``d`` it can use, so a hop over
        a bridge costs 1, a direct bridge is always taken, and a chain of bridges is
        preferred to a single jump between poses far apart.  Crossings between every
        pair of the script's models (with the same channels) are computed when needed.
        """
        g = nx.DiGraph()
        g.add_nodes_from(self.models)
        for a in self.models:
            for b in self.models:
                if a != b and tuple(self.models[a].channels_) == tuple(self.models[b].channels_):
                    c = self.crossings(a, b)
                    g.add_edge(a, b, weight=max(1.0, float(c.distances.min()) / c.threshold) ** 2)
        return nx.dijkstra_path(g, src, to)

    def _acc99(self, name: str) -> float:
        """99th percentile of the largest root-relative joint acceleration per training
        frame of model ``name`` (units/s^2)."""
        if name not in self._acc:
            m = self.models[name]
            pts = pose_points(m.angles(m.frames_), m.channels_, m.skeleton_)
            acc = [
                np.linalg.norm(np.diff(pts[m.segments_ == s], 2, axis=0), axis=2).max(axis=1)
                for s in np.unique(m.segments_)
                if (m.segments_ == s).sum() > 2
            ]
            self._acc[name] = float(np.percentile(np.concatenate(acc), 99)) * m.fps_**2
        return self._acc[name]

    def blend_frames(self, src: str, to: str, x1: np.ndarray, x2: np.ndarray) -> int:
        """Frames a blend from pose ``x1`` of ``src`` to ``x2`` of ``to`` needs so that the
        blend alone accelerates no joint by more than :data:`BLEND_ACCELERATION` of the
        two models' training 99th percentile (a quintic blend over ``T`` seconds moving
        a joint by ``D`` peaks at ``5.78 D / T^2``)."""
        m1, m2 = self.models[src], self.models[to]
        p = pose_points(
            np.vstack([m1.pose(x1[None]), m2.pose(x2[None])]), m1.channels_, m1.skeleton_
        )
        D = float(np.linalg.norm(p[1] - p[0], axis=1).max())
        budget = BLEND_ACCELERATION * min(self._acc99(src), self._acc99(to))
        if budget <= 0:
            return 1
        return int(np.ceil(self.fps * np.sqrt(10.0 / np.sqrt(3.0) * D / budget)))

    def transition(
        self, to: str, blend: float = 0.4, radius: float | None = None, route: bool = True
    ) -> None:
        """TRANSITION: move to the nearest bridge, blend into model ``to`` while both idle.

        Bridges of both directions count.  Without a bridge under the threshold the
        transition still happens, by the cheapest route of :meth:`route` (``route``
        true, the default: possibly through other models, one hop each) or directly:
        a hop without a bridge crosses at its closest pair of poses.  The blend lasts
        ``blend`` seconds or longer when the two poses are far apart
        (:meth:`blend_frames`).  Each hop is reported in ``self.events`` with its route,
        pose distance and blend length.
        """
        self._need_start("TRANSITION")
        src = self.current
        m2 = self.model(to)
        check_compatible(self.models[src], m2, f"TRANSITION from {src!r} to {to!r}: ")
        if not (
            isinstance(blend, (int, float)) and not isinstance(blend, bool)
            and _isfinite(blend) and blend > 0
        ):
            raise ParameterError(
                f"TRANSITION blend must be a positive number of seconds, got {blend!r}"
            )
        if src == to:
            raise ParameterError(f"TRANSITION to {to!r}: the particle is already in it")
        hops = [src, to]
        if route:
            c = self.crossings(src, to)
            if not (c.distances < c.threshold).any():
                hops = self.route(src, to)
        for a, b in zip(hops[:-1], hops[1:]):
            self._hop(a, b, blend, radius, hops)

    def _hop(self, src: str, to: str, blend: float, radius: float | None, hops) -> None:
        """One crossing from the current model ``src`` into ``to``."""
        m1, m2 = self.models[src], self.models[to]
        c = self.crossings(src, to)
        under = c.distances < c.threshold
        pool = (
            np.flatnonzero(under)
            if under.any()
            else np.flatnonzero(c.distances <= CLOSE_ENOUGH * c.distances.min())
        )
        b = int(pool[np.argmin(((c.source_points[pool] - self.x) ** 2).sum(1))])
        x1, x2 = c.source_points[b], c.target_points[b]
        small = 0.5 * (self.params.radius if radius is None else radius)
        self.move(_Point(x1), radius=small, speed=APPROACH_SPEED)
        asked = max(1, int(round(blend * self.fps)))
        n = min(max(asked, self.blend_frames(src, to, x1, x2)), int(MAX_BLEND * self.fps))
        self.reserve(n + 1, "TRANSITION")
        still = np.repeat(x1[None, :], n + 1, axis=0)
        p1 = self.params.replace(radius=small)
        X1, _ = simulate(m1, still, self.x, self.v, self.fps, p1, self.force, self.t)
        X2, V2 = simulate(
            m2,
            np.repeat(x2[None, :], n + 1, axis=0),
            x2,
            np.zeros_like(x2),
            self.fps,
            p1,
            self.force,
            self.t,
        )
        w = smootherstep(n)[:, None]
        r1, r2 = self._root(m1, X1), self._root(m2, X2)
        root = {
            k: (1 - w.reshape((-1,) + (1,) * (r1[k].ndim - 1))) * r1[k]
            + w.reshape((-1,) + (1,) * (r1[k].ndim - 1)) * r2[k]
            for k in r1
        }
        # each model's pose is clipped to its own range before the blend, so the frames
        # after the blend continue without a jump
        blended = (1 - w) * self._clip(src, m1.pose(X1)) + w * self._clip(to, m2.pose(X2))
        self._emit(to, X2, blended, root, clip=False)
        self.events.append(
            {
                "command": self.command,
                "transition": [src, to],
                "route": list(hops),
                "bridge_frame": int(c.source_frames[b]),
                "target_frame": int(c.target_frames[b]),
                "bridge_distance": float(c.distances[b]),
                "threshold": c.threshold,
                "under_threshold": bool(under[b]),
                "bridges": int(under.sum()),
                "blend_frames": n,
                "blend_asked_frames": asked,
                "start_frame": self.n_frames - n,
            }
        )
        self.current, self.x, self.v = to, X2[-1], V2[-1]

    def play(self, segment: str, start: float = 0.0, stop: float | None = None) -> None:
        """PLAY a training segment of the current model as it was (seconds ``start..stop``)."""
        m = self._need_start("PLAY")
        try:
            s = m.segment_index(str(segment))
        except KeyError:
            raise ParameterError(
                f"model {self.current!r} has no segment {segment!r}; it has {m.segment_names_}"
            ) from None
        idx = np.flatnonzero(m.segments_ == s)
        length = m.times_[idx][-1]
        for what, value in (("start", start), ("stop", stop)):
            if value is not None and (
                not isinstance(value, (int, float)) or isinstance(value, bool)
                or not _isfinite(value)
            ):
                raise ParameterError(f"PLAY {what} must be a number of seconds, got {value!r}")
        stop = length if stop is None else float(stop)
        if not 0 <= float(start) < stop <= length + 1e-9:
            raise ParameterError(
                f"PLAY times {start}..{stop} s are not inside segment {segment!r} (0..{length:.3g} "
                "s)"
            )
        first = idx[np.argmin(np.abs(m.times_[idx] - start))]
        self.move(_Point(m.X_[first]), radius=0.25 * self.params.radius)
        self.reserve((stop - float(start)) * self.fps, "PLAY")
        t = np.arange(float(start), stop, 1.0 / self.fps)
        tt = m.times_[idx]

        def interp(a: np.ndarray) -> np.ndarray:
            return np.stack([np.interp(t, tt, col) for col in a.reshape(len(idx), -1).T], 1)

        X = interp(m.X_[idx])
        r = m.root_
        root = {
            "height": interp(r.height[idx])[:, 0],
            "velocity": interp(r.velocity[idx]),
            "turn": interp(r.turn[idx])[:, 0],
            "tilt": interp(r.tilt[idx]).reshape(-1, 3, 3),
        }
        self._emit(self.current, X, interp(m.angles(m.frames_[idx])), root)
        self.x = X[-1]
        self.v = (X[-1] - X[-2]) * self.fps if len(X) > 1 else np.zeros_like(self.x)

    # ----------------------------------------------------------------- output
    @property
    def n_frames(self) -> int:
        return self._made

    def motion(self) -> Motion:
        """The frames so far as a motion on the first model's skeleton (root integrated)."""
        from ...conventions import continuous_euler

        if not self.chunks:
            raise ParameterError("the script made no frames")
        first = self.models[self.chunks[0].model]
        angles = np.concatenate([c.angles for c in self.chunks])
        keys = ("height", "velocity", "turn", "tilt")
        root = {k: np.concatenate([c.root[k] for c in self.chunks]) for k in keys}
        T = angles.shape[0]
        theta = np.concatenate([[0.0], np.cumsum(root["turn"][:-1]) / self.fps])
        head = heading_matrix(theta)
        step = np.zeros((T, 3))
        step[:, 0], step[:, 2] = root["velocity"][:, 0], root["velocity"][:, 1]
        world = np.einsum("tab,tb->ta", head, step) / self.fps
        pos = np.concatenate([np.zeros((1, 3)), np.cumsum(world[:-1], axis=0)])
        pos[:, 1] = root["height"]
        U, _, Vt = np.linalg.svd(root["tilt"])
        # the nearest rotation to the weighted mean of rotations (never a reflection)
        U[:, :, 2] *= np.sign(np.linalg.det(U @ Vt))[:, None]
        tilt = U @ Vt
        mats = head @ tilt
        rj = first.skeleton_.joints[0]
        if not np.allclose(rj.axis, np.eye(3)):
            mats = rj.axis.T @ mats @ rj.axis
        euler = continuous_euler(mats[:, None], rj.rotation_order)[:, 0]
        channels = first.all_channels_
        frames = np.zeros((T, len(channels)))
        col = {c: i for i, c in enumerate(channels)}
        for k, d in enumerate(("tx", "ty", "tz")):
            frames[:, col[(rj.name, d)]] = pos[:, k]
        for k, ax in enumerate(rj.rotation_order.lower()):
            frames[:, col[(rj.name, "r" + ax)]] = euler[:, k]
        for k, c in enumerate(first.channels_):
            frames[:, col[c]] = angles[:, k]
        motion = Motion(
            frames=frames,
            channels=channels,
            fps=self.fps,
            skeleton=first.skeleton_,
            source="synthetic:latent",
        )
        return self._plant_feet(motion)

    def plant_spans(self, n_frames: int) -> np.ndarray:
        """How much of each step's root travel ``(T - 1,)``, in ``[0, 1]``, :meth:`motion`
        takes from the planted feet: 1 in each blend window, easing to 0 (smoothstep)
        over :data:`PLANT_MARGIN` on either side, so the root's velocity changes gently
        where the planted track takes over; all 1 with ``plant="all"``."""
        n = max(n_frames - 1, 0)
        if self.plant == "all":
            return np.ones(n)
        weight = np.zeros(n)
        if self.plant == "transitions":
            k = np.arange(n)
            margin = max(1, int(round(PLANT_MARGIN * self.fps)))
            for ev in self.events:
                a, b = ev["start_frame"], ev["start_frame"] + ev["blend_frames"]
                u = np.clip(1.0 - np.maximum(a - k, k - b + 1) / (margin + 1.0), 0.0, 1.0)
                weight = np.maximum(weight, u * u * (3.0 - 2.0 * u))
        return weight

    def _plant_feet(self, motion: Motion) -> Motion:
        """The root's ground track in :meth:`plant_spans` made to follow the planted feet.

        In a blend the root's travel is a blend of two models' root velocities and the
        feet a blend of their poses; the two disagree and planted feet slide.  There the
        root moves instead by minus the planted foot points' displacement relative to it
        (:func:`~cyclecoord.periodic.root.planted_ground`); contacts are found on the
        motion (:func:`~cyclecoord.quality.contacts.foot_contacts`) and again, twice,
        on the corrected motion, as the periodic cycle's anchoring does.  The planted
        track's steps are smoothed (:data:`PLANT_SMOOTH`): unsmoothed, the root copied
        the feet's frame-to-frame jitter and its horizontal acceleration exceeded 1.5x
        the larger of the two models' training 99th percentile in 30 of the shared-data
        models' 56 blend windows (none when smoothed, none without planting); on the
        same windows planted feet slid on 38 % of frames unsmoothed, 48 % smoothed,
        56 % without planting.
        Steps outside the spans are kept.  (A first search with a lax speed limit, 1 or
        2 leg lengths per second, for the sliding feet did no better.)
        """
        from scipy.ndimage import gaussian_filter1d, uniform_filter1d

        from ...errors import CycleCoordError
        from ...periodic.root import planted_ground, root_layout
        from ...quality.contacts import find_feet, foot_contacts

        if self.plant == "all":
            return self._carry(motion)
        share = self.plant_spans(motion.n_frames)[:, None]
        mask = share[:, 0] > 0
        layout = root_layout(motion)
        if not mask.any() or layout is None or motion.n_frames < 3:
            return motion
        if self.feet is not None:  # named feet: a wrong name is an error, not skipped
            feet = self.feet
            found = foot_contacts(motion, feet).planted
        else:
            try:
                feet = find_feet(motion.skeleton, motion)
                found = foot_contacts(motion, feet).planted
            except CycleCoordError:
                return motion
        cols = [layout.column("tx"), layout.column("tz")]
        own = np.diff(motion.frames[:, cols], axis=0)
        frames = motion.frames.copy()
        for k in range(PLANT_ROUNDS + 1):
            weights = uniform_filter1d(found.astype(float), 3, axis=0, mode="nearest")
            steps = np.diff(planted_ground(motion, layout, feet, weights), axis=0)
            # the feet's pose jitters from frame to frame (the particle's random force)
            # and the contacts switch; the root need not follow that
            steps = gaussian_filter1d(steps, PLANT_SMOOTH * self.fps, axis=0, mode="nearest")
            steps = share * steps + (1.0 - share) * own
            frames[:, cols] = motion.frames[0, cols] + np.vstack([[0.0, 0.0], np.cumsum(steps, 0)])
            if k < PLANT_ROUNDS:
                found = foot_contacts(motion.with_frames(frames), feet).planted
        out = motion.with_frames(frames)
        if not self.lock:
            return out
        from dataclasses import replace

        from ..footlock import lock_feet

        # what the root cannot keep still (two planted feet whose stance the blend
        # changes), a small leg IK pins: contacts inside the spans only
        span = np.r_[mask, False] | np.r_[False, mask]
        contacts = foot_contacts(out, feet, min_duration=LOCK_MIN_CONTACT)
        contacts = replace(contacts, planted=contacts.planted & span[:, None])
        if not contacts.planted.any():
            return out
        return lock_feet(out, contacts, blend=LOCK_BLEND, passes=1).motion

    def hold_mask(self, n_frames: int) -> np.ndarray:
        """(T,) frames an IDLE command made."""
        hold = np.zeros(n_frames, dtype=bool)
        for a, b in self.held:
            hold[a:b] = True
        return hold

    def _carry(self, motion: Motion) -> Motion:
        """``plant="all"``: the root carried by the feet everywhere, IDLE standing, no
        foot under the floor, the feet pinned where that makes no pop."""
        from ...errors import CycleCoordError
        from ...quality.contacts import foot_contacts
        from ..carry import carry_by_feet, channel_bounds, lock_where_clean

        used = sorted({c.model for c in self.chunks})
        try:
            floor = float(
                np.median(
                    [foot_contacts(self.models[k].training_motion(), self.feet).floor for k in used]
                )
            )
        except CycleCoordError:
            floor = None
        out = carry_by_feet(
            motion,
            self.feet,
            floor=floor,
            hold=self.hold_mask(motion.n_frames),
            smooth=PLANT_SMOOTH,
        )
        self.notes.append(
            "root: carried by the feet on the ground"
            + ("" if floor is None else " (no foot under the training frames' floor)")
            + ("; IDLE stands after 0.5 s" if self.held else "")
        )
        if self.lock:
            limit = 1.5 * max(self._acc99(k) for k in used)
            bounds = channel_bounds([self.models[k].training_motion() for k in used])
            locked = lock_where_clean(out, limit, self.feet, bounds=bounds)
            self.notes.append(locked.line)
            out = locked.motion
        return out

    def segments(self) -> list[dict[str, Any]]:
        """Which frames each command made and in which model."""
        out, start = [], 0
        for c in self.chunks:
            n = c.X.shape[0]
            if out and out[-1]["command"] == c.command and out[-1]["model"] == c.model:
                out[-1]["stop"] += n
            else:
                out.append(
                    {"command": c.command, "model": c.model, "start": start, "stop": start + n}
                )
            start += n
        return out

    def latent_path(self) -> list[tuple[str, np.ndarray]]:
        """The particle's path per chunk: ``(model, X)``."""
        return [(c.model, c.X) for c in self.chunks]


class _Point(list):
    """A latent point already resolved (skips the target checks)."""

    def __init__(self, x: np.ndarray) -> None:
        super().__init__(np.asarray(x, dtype=float).tolist())
