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
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import networkx as nx
import numpy as np

from ...errors import ParameterError
from ..carry import STAND_AFTER
from . import easing
from .bridges import Bridges
from .crossing import (  # noqa: F401  (re-exported: the module's names before the split)
    APPROACH_SPEED,
    BLEND_ACCELERATION,
    CLOSE_ENOUGH,
    MAX_BLEND,
    CrossingMixin,
    Crossings,
    Point,
)
from .easing import eased, paced_root, resample, smootherstep, smoothstep  # noqa: F401
from .gplvm import sqdist
from .idling import IDLE_SWAY, IdleMixin  # noqa: F401  (IDLE_SWAY: re-exported)
from .model import LatentModel
from .output import (  # noqa: F401
    LOCK_BLEND,
    LOCK_MIN_CONTACT,
    PLANT_MARGIN,
    PLANT_ROUNDS,
    PLANT_SMOOTH,
    OutputMixin,
)
from .particle import ParticleParams, RandomForce, simulate
from .stepping import GaitMixin, interp_rows

__all__ = ["CommandGraph", "Crossings", "Synthesizer", "resample", "smootherstep", "smoothstep"]

#: A latent target whose density proxy is below this lies outside the model.
OUTSIDE_DENSITY = 0.05
#: Joint angles may pass the training range by at most this fraction of it (eased).
LIMIT_MARGIN = 0.1
#: Path radius of a MOVE ahead along the gait, as a fraction of the particle's: on the
#: synthetic run the full radius let the random force throw the pose 3.2x the training
#: 99th percentile of pose speed in one step.  The path is the captured gait's own
#: latent trajectory; what the particle strays from it the pose shows as jitter.  The
#: gait sections' largest acceleration over the training 99th percentile (medians over
#: 15 script seeds of ``benchmarks/bench_latent_gait.py``; [largest]):
#:
#: ======  ==============  ==============  ==============  ==============
#: ahead   Bandai run      143_01 jog      Bandai walk     subject 35 walk
#: ======  ==============  ==============  ==============  ==============
#: 0.25    1.92 [2.49]     1.59 [1.87]     1.33 [1.68]     1.14 [1.53]
#: 0.2     1.78 [2.14]     1.54 [1.92]     1.25 [1.35]     1.07 [1.41]
#: 0.15    1.80 [1.98]     1.41 [1.69]     1.22 [1.44]     0.96 [1.20]
#: ======  ==============  ==============  ==============  ==============
#:
#: Tighter is stiff: at 0.083 one seed in five of the jog threw the pose 21x, at 0.05
#: most pairs did.  The jog's knee range reads 0.81 at 0.15 (0.86 at 0.25).
AHEAD_RADIUS = 0.15
#: Bytes of one edge of a networkx graph (its weight dict in both directions).
_EDGE_BYTES = 400
#: Bytes a synthesised frame takes until the motion is written, besides a training frame
#: (latent point, pose, root motion, the motion's frames, forward kinematics of the
#: checks) and per training frame (the kernel and root weights of the frame).
_FRAME_BYTES = 8 * 16
_FRAME_BYTES_PER_TRAINING_FRAME = 8 * 4
#: Training frames this close in a segment are joined at their captured pace by a MOVE.
PACE_GAP = 2


#: A MOVE from rest at a gait's pose to another take's frame steps along the gait
#: (rather than following its path) where the training frames on its path (a line's
#: nearest) go back along the gait by this many cycles in all
BACKWARDS_CYCLES = 0.1
#: Points along a line MOVE whose nearest training frames' phases say which way it goes
LINE_PROBES = 16


def _backwards(gait, nodes: list[int]) -> float:
    """Cycles a MOVE's path plays its gait backwards, from the training frames it passes
    (``nodes``, in order; -1 for none): minus the sum of their gait-phase changes (each
    the nearest way round, over frames with a phase on a usable segment), 0 where that
    goes forward."""
    ok = [k for k in nodes if k >= 0 and np.isfinite(gait.phase[k])
          and np.isin(gait.segments[k], gait.usable)]
    if len(ok) < 2:
        return 0.0
    step = (np.diff(gait.phase[ok]) + 0.5) % 1.0 - 0.5
    return max(0.0, -float(step.sum()))


def _path_times(m: LatentModel, poly: np.ndarray, nodes: list[int]) -> np.ndarray:
    """Seconds at each vertex of a MOVE's polyline (``nodes``: its training frames, -1
    for the ends): consecutive frames of a segment at their captured pace, the rest at
    the model's median latent speed."""
    seg = np.linalg.norm(np.diff(poly, axis=0), axis=1)
    dt = seg / m.speed_
    for i, (a, b) in enumerate(zip(nodes[:-1], nodes[1:])):
        if a >= 0 and b >= 0 and m.segments_[a] == m.segments_[b] and abs(a - b) <= PACE_GAP:
            dt[i] = abs(float(m.times_[b] - m.times_[a]))
    return np.concatenate([[0.0], np.cumsum(dt)])


def _isfinite(value: Any) -> bool:
    """``math.isfinite`` of a JSON or Python number; False, not an error as from
    ``np.isfinite``, for an integer too large for a float."""
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


class CommandGraph:
    """Shortest paths over a model's training latent points (complete graph, cost ``d^p``)."""

    def __init__(self, model: LatentModel, power: float = 4.0) -> None:
        self.model = model
        self.power = power
        from ...io._limits import check_memory

        X = model.X_
        n = X.shape[0]
        # networkx keeps every edge of the complete graph as Python objects
        check_memory(_EDGE_BYTES * n * (n - 1) / 2, f"the command graph of {n:,} latent points")
        i, j = np.triu_indices(n, 1)
        cost = np.sqrt(sqdist(X, X))[i, j] ** power
        self.graph = nx.Graph()
        self.graph.add_weighted_edges_from(zip(i.tolist(), j.tolist(), cost.tolist()))

    def path(self, a: np.ndarray, b: np.ndarray, nodes: bool = False):
        """Polyline from ``a`` to ``b`` through training points, ``(M, q)`` (and with
        ``nodes`` the training frame of each vertex, -1 for the ends)."""
        X = self.model.X_
        g = self.graph
        da = np.sqrt(((X - a) ** 2).sum(1)) ** self.power
        db = np.sqrt(((X - b) ** 2).sum(1)) ** self.power
        g.add_weighted_edges_from(("a", k, float(c)) for k, c in enumerate(da))
        g.add_weighted_edges_from(("b", k, float(c)) for k, c in enumerate(db))
        g.add_edge("a", "b", weight=float(np.linalg.norm(a - b) ** self.power))
        try:
            path = nx.dijkstra_path(g, "a", "b")
        finally:
            g.remove_nodes_from(["a", "b"])
        poly = np.vstack([a] + [X[k] for k in path[1:-1]] + [b])
        return (poly, [-1] + list(path[1:-1]) + [-1]) if nodes else poly


@dataclass
class _Chunk:
    model: str
    X: np.ndarray
    angles: np.ndarray
    root: dict[str, np.ndarray]
    command: int
    #: the angles and root are the model's pose of X (a particle's path), not a blend or a
    #: played capture: :meth:`OutputMixin.motion` may pose a smoothed X instead
    particle: bool = False
    #: the gait detail the frames carry (:meth:`~.model.LatentModel.detail`'s parts, each
    #: ``(T, ...)``; included in ``angles`` and ``root``, added again when a particle's X
    #: is posed again), None without a gait
    detail: dict[str, np.ndarray] | None = None
    #: the latent path ``(T, q)`` the particle followed along a gait (None elsewhere):
    #: its pose plus the detail is the captured frame at each frame's phase
    path: np.ndarray | None = None
    #: for an in-step blend, a function giving the angles ``(T, C)`` (this chunk's
    #: model's chart) the untangling pulls toward (the two gaits' captured poses at the
    #: blend's phases, blended without the particle's stray) and, second, each gait's
    #: nearest whole captured frame blended (:meth:`OutputMixin._untangled`); for a
    #: crossing's blend, both the two particles' nearest captured frames blended; asked only
    #: when a frame there is pulled (computing them on every hop cost 8 % of a script's
    #: time); None elsewhere
    targets: Callable[[], tuple[np.ndarray, np.ndarray]] | None = None
    #: ``(T,)`` how fast the particle's path plays the training takes' time (0 at rest,
    #: 1 at the captured pace): the root's own travel and turn scale with it; None: 1
    pace: np.ndarray | None = None


@dataclass
class Synthesizer(IdleMixin, CrossingMixin, OutputMixin, GaitMixin):
    """Runs commands over named latent models and collects the frames.

    Parameters
    ----------
    models : dict of str to LatentModel
        Same joint-angle channels for any two models a TRANSITION joins.  The frames
        are written on the skeleton of the model :meth:`start` names; a model of another
        actor on the same rig has its root track sized to it
        (:func:`~.sizing.sized_roots`; the dict and models given are not changed, the
        scales are in ``sizes``).
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
        height, not speed, the lowest foot carrying the body unless it goes over the
        ground faster than half the root's speed; IDLE stands after 0.5 s; no foot
        under the training frames' floor), then, with ``lock``, the weight-bearing feet
        pinned where that makes no pop
        (:func:`~cyclecoord.synthesis.carry.lock_where_clean`, limit 1.5x the 99th
        percentile of root-relative joint acceleration of the training takes of the
        model posing each frame, a TRANSITION's the faster one's; the ``notes``
        attribute says where not).
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
    detail : bool, default True
        Frames stepping along a gait (MOVE ahead, in-step TRANSITION) carry the joint
        angles the model's PCA leaves out of the training frame at their phase
        (:meth:`~.model.LatentModel.detail`); it fades in and out over
        :data:`DETAIL_FADE` seconds where frames without a gait meet them.
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
    detail: bool = True

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
        self._acc: dict = {}
        self._feet_found: list = []  # the feet feet_of found (or None), once a script
        self._given_models = self.models  # (start() sizes them to its model's skeleton)
        #: the models start() sized to the output skeleton: the scale of each
        self.sizes: dict[str, float] = {}
        #: the model whose skeleton the frames are written on (the first start's)
        self.skeleton_model: str | None = None
        self._size_notes: dict[str, str] = {}  # (said once a model's frames are made)
        self.sim_seconds = 0.0
        self.sim_cpu_seconds = 0.0
        self.clamped = {"values": 0, "max_deg": 0.0}
        self.held: list[tuple[int, int]] = []  # frame ranges of IDLE commands
        # those of TRANSITIONs crossed standing (after an IDLE): asked still, not held
        self.stood: list[tuple[int, int]] = []
        self.stands: list[tuple[int, int]] = []  # those of IDLEs at one pose (legs held)
        self.rests: dict[int, int] = {}  # a stand's first frame -> frames to its rest
        #: each stand after a stride: its closing step, or why none (:meth:`motion`)
        self.stand_steps: list[dict] = []
        self.notes: list[str] = []
        # check_plausibility's cache: the motion is checked up to seven times against
        # the same training takes (limbs kept apart, each round of foot pinning, report)
        self._plausibility: dict = {}
        self._ranges: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._gaits: dict = {}
        self._fades: dict = {}  # each (model, segment)'s seam cross-fade (seam_fade)
        self._stances: dict = {}  # each model's training frames' stance (GaitMixin.stance)
        self._frame_steps: dict = {}  # each model's median GP-mean step along its gait
        # (model, segment, unwrapped phase) where the last stepping command left the
        # particle, and the one the MOVE being made will leave
        self._cursor = self._next_cursor = None
        # whether the particle is stepping along its model's gait (a MOVE ahead, a PLAY,
        # a TRANSITION in step) rather than idling or going to a target: an in-step
        # TRANSITION needs a gait to step from
        self._stepping = False
        self._path_detail: dict | None = None  # the gait detail along the MOVE's path
        widest = max(m.X_.shape[0] for m in self.models.values())
        channels = max(len(m.all_channels_) for m in self.models.values())
        self.frame_bytes = _FRAME_BYTES * channels + _FRAME_BYTES_PER_TRAINING_FRAME * widest

    def reserve(self, n: float, what: str = "") -> int:
        """``n`` more frames as a whole number, or ParameterError when the script's frames
        would pass :data:`~cyclecoord.io._limits.MAX_FRAMES` or the memory limit."""
        from ...io._limits import MAX_FRAMES, check_memory

        total = self.n_frames + float(n)
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
        if isinstance(spec, Point):
            return np.asarray(spec, dtype=float)
        q = m.X_.shape[1]
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

    def _run(
        self,
        path: np.ndarray,
        radius: float | None = None,
        ride: bool = False,
        detail: dict[str, np.ndarray] | None = None,
        sway: float = 1.0,
        pace: np.ndarray | None = None,
        settle: int | np.ndarray | None = None,
    ) -> None:
        m = self._need_start("moving")
        self._cursor, self._next_cursor = self._next_cursor, None
        params = self.params if radius is None else self.params.replace(radius=radius)
        if sway != 1.0:  # (an IDLE's hover: a share of the random force)
            params = params.replace(random=params.random * sway)
        t0, c0 = time.perf_counter(), time.process_time()
        self.reserve(path.shape[0] - 1)
        X, V = simulate(m, path, self.x, self.v, self.fps, params, self.force, self.t, ride)
        if settle is not None:  # (an IDLE's last frames: back to a point, or its frame's)
            n = max(1, round(STAND_AFTER * self.fps))
            u = min(1.0, 0.5 * (len(X) - 1) / n)  # (as far as its stand holds the legs)
            to = X[min(settle, len(X) - 1)] if isinstance(settle, int) else settle
            X, V = easing.settle(X, V, to, n, easing.smooth(u))
        pose, root = m.pose(X), self._root(m, X)
        if detail is not None:
            pose = pose + detail["angles"]
            root = {k: root[k] + detail[k] for k in root}
        if pace is not None:
            root = paced_root(root, pace)
        self._emit(
            self.current, X, pose, root, particle=True, detail=detail,
            path=None if detail is None else np.array(path[1:], dtype=float), pace=pace,
        )
        self.sim_seconds += time.perf_counter() - t0
        self.sim_cpu_seconds += time.process_time() - c0
        self.x, self.v = X[-1], V[-1]
        self._stepping = False  # (a MOVE ahead says otherwise after its run)

    def _clip(self, name: str, angles: np.ndarray, count: bool = True) -> np.ndarray:
        """Joint limits: angles beyond the training range of model ``name`` are eased
        back towards it, never past :data:`LIMIT_MARGIN` of the range beyond it
        (``hi + m tanh((a - hi) / m)``: slope 1 at the limit and rising, so a joint
        never flattens against it as a hard clip made it; counted)."""
        if not self.clamp:
            return angles
        lo, hi = self._range(name)
        mg = np.maximum(LIMIT_MARGIN * (hi - lo), 1e-6)
        clipped = np.where(angles > hi, hi + mg * np.tanh((angles - hi) / mg), angles)
        clipped = np.where(clipped < lo, lo - mg * np.tanh((lo - clipped) / mg), clipped)
        if count:
            over = np.abs(clipped - angles)
            self.clamped["values"] += int((over > 1e-9).sum())
            self.clamped["max_deg"] = max(self.clamped["max_deg"], float(over.max(initial=0.0)))
        return clipped

    def _emit(
        self,
        name,
        X,
        angles,
        root,
        clip: bool = True,
        particle: bool = False,
        detail=None,
        path=None,
        targets=None,
        pace=None,
    ) -> None:
        if name in self._size_notes:  # said once a model's frames are made
            self.notes.append(self._size_notes.pop(name))
        if clip:
            angles = self._clip(name, angles)
        self.chunks.append(
            _Chunk(name, X, angles, root, self.command, particle, detail, path, targets, pace)
        )
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

    # --------------------------------------------------------------- commands
    def start(self, model: str, at: Any = None) -> None:
        """Place the particle in ``model`` (at a target, default its first training frame).

        The first start also sizes the other models' root tracks to this model's skeleton,
        on which the frames are written (:func:`~.sizing.sized_roots`)."""
        m = self.model(model)
        if not self.chunks:  # (a start before any frame may name another first model)
            from .sizing import size_note, sized_roots

            self.models, self.sizes = sized_roots(self._given_models, model, self.feet)
            self.skeleton_model = model
            self._size_notes = {k: size_note(k, s, model) for k, s in self.sizes.items()}
        self.current = model
        k = None
        if at is None:
            k = 0
        elif isinstance(at, dict) and set(at) == {"frame"}:
            k = at["frame"]
        if (
            isinstance(k, int) and not isinstance(k, bool)
            and 0 <= k < m.X_.shape[0] - 1 and m.is_reference_frame(k)
        ):
            # a T-pose before the capture's motion: the script snapped out of it at 10x
            # the training 99th percentile of acceleration
            self.notes.append(f"start: training frame {k} of {model!r} is a reference pose, "
                              f"not a pose of its motion; started at frame {k + 1}")
            at = {"frame": k + 1}
        self.x = self.target(at, model) if at is not None else m.X_[0].copy()
        self.v = np.zeros_like(self.x)

    def move(
        self,
        to: Any,
        path: str = "line",
        duration: float | None = None,
        speed: float = 1.0,
        radius: float | None = None,
        stop: bool = True,
        at_stance: bool = True,
    ) -> None:
        """MOVE to a target along a line or the command graph's shortest path, or
        ``{"ahead": seconds}`` along the gait.

        The path is timed from the training takes: a stretch between two consecutive
        training frames of a segment takes the time it took in the capture, the rest
        (a line, a jump between takes) its length at the model's median latent speed, a
        line no faster than a blend between its two poses
        (``blend_frames``: a short line in the latent space
        between far poses threw a Bandai run's joints 2.1x its p99, a random script's
        MOVE to a frame after a TRANSITION crossed while idle); ``speed`` scales and
        ``duration`` sets the whole.  The particle speeds up over ``ease`` seconds only
        when it starts from rest and slows down only with ``stop``
        (a script passes ``stop=False`` when a MOVE or TRANSITION follows), so a chain of
        MOVEs flows through its waypoints; the root's own travel and turn go at the
        same pace (``_Chunk.pace``).  A MOVE ahead that stops ends where both feet
        are down, the nearest such phase of the gait within a quarter of a cycle of the
        asked seconds (:meth:`~.stepping.GaitMixin.stop_ahead`; ``at_stance=False``:
        exactly the seconds asked).  From a stepping particle, a MOVE to a training frame
        with a gait phase steps on to that phase along either path
        (:meth:`~.stepping.GaitMixin.step_to`; along the graph's training frames, the
        phase jumped where the path left the gait: a Bandai walk's toes 1.5x its p99),
        and so does a MOVE to a training frame (``{"frame": k}``, ``{"segment": s,
        "time": t}``) from rest at a pose of the gait (to another take's frame only where
        its path would play the gait backwards: :data:`BACKWARDS_CYCLES`); a latent point
        ``[x, y, z]`` is reached along the path asked.
        """
        m = self._need_start("MOVE")
        if not (
            isinstance(speed, (int, float)) and not isinstance(speed, bool)
            and _isfinite(speed) and speed > 0
        ):
            raise ParameterError(f"MOVE speed must be a positive number, got {speed!r}")
        stepped = None
        if isinstance(to, dict) and "ahead" in to:
            if set(to) != {"ahead"}:
                raise ParameterError(f"an ahead target takes no other keys, got {sorted(to)}")
            seconds = to["ahead"]
            if stop and at_stance and duration is None:
                seconds = self.stop_ahead(seconds)
            timed = self.ahead_path(seconds) or self.segment_ahead(seconds)
            poly, times = timed
            along = self._path_detail
            if radius is None:
                radius = AHEAD_RADIUS * self.params.radius
        else:
            along = None
            goal = self.target(to)
            if path not in ("line", "graph"):
                raise ParameterError(f"MOVE path must be 'line' or 'graph', got {path!r}")
            stepped = self.step_to(goal)
            if stepped is None:
                if path == "line":
                    poly, nodes = np.vstack([self.x, goal]), [-1, -1]
                    passed = m.nearest_frame(self.x + np.linspace(0.0, 1.0, LINE_PROBES)[:, None]
                                             * (goal - self.x)).tolist()
                else:
                    if self.current not in self._graphs:
                        self._graphs[self.current] = CommandGraph(m)
                    poly, nodes = self._graphs[self.current].path(self.x, goal, nodes=True)
                    passed = nodes
                if isinstance(to, dict):  # (a training frame's: not a latent point)
                    # from rest at a gait's pose, to a frame of the gait, the steps go on
                    # along it: the path (the latent space's nearest poses) morphed the
                    # legs or played the gait backwards while the root went forward (on
                    # 40 random pairs of gait frames of each shared model 11-18 went back
                    # over a tenth of a cycle: a subject 35 run from frame 33 to 21 slid
                    # the feet 5.4 m/s, 8.8x the takes'; a walk's line from frame 250 to
                    # 239, 2.8x), or stood nearly still where the two poses were alike (a
                    # Bandai run's line from frame 28 to 79, two cycles on: 0.27 s under
                    # a tenth of the takes' pose speed, a freeze).  To another take only
                    # where the path goes back (:data:`BACKWARDS_CYCLES`).
                    back = _backwards(self.gait(self.current), passed) > BACKWARDS_CYCLES
                    stepped = self.step_to(goal, from_rest=True, across=back)
            if stepped is not None:  # from a gait: stepping on to the goal's phase
                poly, times = stepped
                along = self._path_detail
                if radius is None:
                    radius = AHEAD_RADIUS * self.params.radius
            if stepped is None:
                times = _path_times(m, poly, nodes)
                if path == "line":  # no faster than a blend between its two poses
                    need = self.blend_frames(self.current, self.current, self.x, goal) / self.fps
                    if times[-1] < need:
                        times = times * (need / max(times[-1], 1e-12))
        captured = times[-1]  # (the path's seconds at the training takes' pace)
        times = times / speed
        if duration is not None:
            if not (
                isinstance(duration, (int, float)) and not isinstance(duration, bool)
                and _isfinite(duration) and duration > 0
            ):
                raise ParameterError(
                    f"MOVE duration must be a positive number of seconds, got {duration!r}"
                )
            times = times * (duration / max(times[-1], 1e-12))
        ramp = int(round(self.ease * self.fps))
        still = self.v is None or np.linalg.norm(self.v) < 0.25 * m.speed_
        if along is not None and stepped is None and not self._stepping:
            still = True  # (a gait begun from a line or an idle: its steps ease in)
        r_in, r_out = (ramp if still else 0), (ramp if stop else 0)
        with np.errstate(all="ignore"):
            frames = np.round(times[-1] * self.fps)
        n = max(1, self.reserve(frames if np.isfinite(frames) else np.inf, "MOVE"))
        if stepped is None and not (isinstance(to, dict) and "ahead" in to):
            # a MOVE to a point (not along a gait) shorter than its ramps eases over its
            # own length: stretched to two full ramps, a MOVE to the neighbouring frame
            # crawled for 0.3 s (a freeze), and so did a crossing's approach from a pose
            # already near its bridge
            r_in, r_out = min(r_in, n), min(r_out, n)
        n += (r_in + r_out) // 2
        u = eased(n, r_in, r_out) * times[-1]
        samples = np.stack([np.interp(u, times, poly[:, k]) for k in range(poly.shape[1])], 1)
        detail = None
        if along is not None:
            detail = {k: interp_rows(u, times, v)[1:] for k, v in along.items()}
        # the root travels and turns at the pace the poses play the takes: easing in
        # from rest, it had the captured speed at once (a run from an IDLE lurched from
        # 0 to 3.5 m/s in two frames, its planted foot dragged and snapped free)
        pace = np.diff(u) * self.fps * (captured / max(times[-1], 1e-12))
        self._run(samples, radius, ride=True, detail=detail, pace=pace)
        self._stepping = stepped is not None or (isinstance(to, dict) and "ahead" in to)

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
        self.move(Point(m.X_[first]), radius=0.25 * self.params.radius)
        # the approach stops at the segment's frame: the playback speeds up from rest over
        # ``ease`` seconds (the captured frames re-timed, the root's velocity and turn with
        # them) instead of jumping to the captured pace (the README's script then threw a
        # hand at 2.6x the Twist takes' 99th percentile of acceleration)
        ramp = int(round(self.ease * self.fps))
        n = len(np.arange(float(start), stop, 1.0 / self.fps)) + ramp // 2
        self.reserve(n, "PLAY")
        t = float(start) + eased(n, ramp, 0)[:-1] * (stop - float(start))
        pace = np.gradient(t) * self.fps if n > 1 else np.ones(n)
        tt = m.times_[idx]

        def interp(a: np.ndarray) -> np.ndarray:
            return np.stack([np.interp(t, tt, col) for col in a.reshape(len(idx), -1).T], 1)

        X = interp(m.X_[idx])
        r = m.root_
        root = {
            "height": interp(r.height[idx])[:, 0],
            "velocity": interp(r.velocity[idx]) * pace[:, None],
            "turn": interp(r.turn[idx])[:, 0] * pace,
            "tilt": interp(r.tilt[idx]).reshape(-1, 3, 3),
        }
        # the captured frames carry what the model leaves out of them: marked as detail,
        # it fades out into a MOVE after them (and in from one before) instead of
        # stepping (the README's script popped its toes at 3.6x the Twist takes' 99th
        # percentile where its PLAY met the next MOVE)
        detail = None
        if self.detail:
            detail = {
                k: interp(v[idx]).reshape((len(t),) + v.shape[1:]) for k, v in m.detail().items()
            }
        self._emit(self.current, X, interp(m.angles(m.frames_[idx])), root, detail=detail)
        self._stepping = True
        self.x = X[-1]
        self.v = (X[-1] - X[-2]) * self.fps if len(X) > 1 else np.zeros_like(self.x)
