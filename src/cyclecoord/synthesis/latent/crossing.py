"""Crossings between latent models: bridges, routes over the models, blend lengths and the
TRANSITION command's hop (Bailey et al. Sec. 5.2-5.3), a part of
:class:`~.commands.Synthesizer`.

A hop moves to the nearest crossing (a bridge under the threshold, else the closest pair
of poses), then blends into the other model while both particles idle.  Walk and run
models whose training frames have a gait phase (:mod:`.gait`) cross by
:meth:`~.commands.Synthesizer.gait_hop` instead: both keep stepping, in phase.
"""

from __future__ import annotations

from dataclasses import dataclass

import networkx as nx
import numpy as np

from ..._words import plural
from ...errors import ParameterError
from .bridges import DEFAULT_THRESHOLD, Bridges, check_compatible, find_bridges
from .easing import mix_rows, paced_root, smootherstep, smoothstep
from .influence import pose_points
from .particle import simulate

__all__ = [
    "APPROACH_SPEED", "BLEND_ACCELERATION", "CLOSE_ENOUGH", "MAX_BLEND", "START_LEAD",
    "Crossings", "Point",
]

#: A blend alone may accelerate a joint by at most this fraction of the two models'
#: training 99th percentile (the pose's own motion comes on top).
BLEND_ACCELERATION = 0.5
#: Speed of the MOVE to a crossing, as a fraction of the model's training speed: a
#: straight line to a far crossing can leave the data, where the pose changes fast (on
#: the shared-data models 1.0 made joints accelerate up to 1.74x the training 99th
#: percentile on the way, 0.6 at most 1.44x).
APPROACH_SPEED = 0.6
#: Seconds a script's first command, a TRANSITION from a start frame on a gait, steps
#: along the gait (easing in from rest) before it blends in step: crossed while both
#: models idle, the figure stood at its start frame, mid-stride, for 0.3-0.4 s (most of
#: the 20 freezes of 220 random scripts over three seeds; 6 with this step).  Blended in
#: step at once from the start frame, a subject 35 walk's feet passed closer than the
#: takes' ever do (animate refused 4 scripts in 30 more).
START_LEAD = 0.25
#: Longest blend, seconds.
MAX_BLEND = 4.0
#: What the console adds for a crossing that a standing figure makes (``_standing``).
_STOOD = ("; crossed standing (after an IDLE, or from a start frame without a gait): a "
          "standing figure changing its stance, asked to stand still, so its frames are not "
          "counted as freezes")
#: Without a bridge, pairs within this factor of the closest distance are candidates
#: (the one nearest the particle is taken).
CLOSE_ENOUGH = 1.1


def blend_asked(blend: float, fps: float) -> int:
    """Frames of a blend of ``blend`` seconds; shorter than one frame is an error."""
    if blend * fps < 1.0 - 1e-9:
        raise ParameterError(
            f"TRANSITION blend {blend:g} s is shorter than one frame at {fps:g} fps"
        )
    return int(round(blend * fps))


class Point(list):
    """A latent point already resolved (skips the target checks)."""

    def __init__(self, x: np.ndarray) -> None:
        super().__init__(np.asarray(x, dtype=float).tolist())


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



class CrossingMixin:
    """Bridges, crossings, routes and hops of :class:`~.commands.Synthesizer`."""

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
            pts = pose_points(m.to_channels(m.angles(m.frames_)), m.channels_, m.skeleton_)
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
            np.vstack([m1.to_channels(m1.pose(x1[None])), m2.to_channels(m2.pose(x2[None]))]),
            m1.channels_,
            m1.skeleton_,
        )
        D = float(np.linalg.norm(p[1] - p[0], axis=1).max())
        budget = BLEND_ACCELERATION * min(self._acc99(src), self._acc99(to))
        if budget <= 0:
            return 1
        return int(np.ceil(self.fps * np.sqrt(10.0 / np.sqrt(3.0) * D / budget)))

    def crossings_threshold(self, src: str) -> float:
        """The bridge threshold (skeleton units) of crossings from model ``src``."""
        if self.bridge_threshold is not None:
            return float(self.bridge_threshold)
        return DEFAULT_THRESHOLD * self.models[src].skeleton_.total_length()

    def transition(
        self,
        to: str,
        blend: float = 0.4,
        radius: float | None = None,
        route: bool = True,
        in_step: bool = True,
    ) -> None:
        """TRANSITION into model ``to``.

        Between two models with a gait phase (:meth:`~.stepping.GaitMixin.gait_hop`,
        ``in_step`` true, the default): at once and in step, the two gaits blending over
        ``blend`` seconds while both keep stepping.  Otherwise: move to the nearest
        bridge, blend into model ``to`` while both idle.  Bridges of both directions
        count.  Without a bridge under the threshold the
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
        from .commands import _isfinite

        if not (
            isinstance(blend, (int, float)) and not isinstance(blend, bool)
            and _isfinite(blend) and blend > 0
        ):
            raise ParameterError(
                f"TRANSITION blend must be a positive number of seconds, got {blend!r}"
            )
        if src == to:
            raise ParameterError(f"TRANSITION to {to!r}: the particle is already in it")
        across = in_step and self.can_step_across(src, to)
        if across:
            if not self._stepping and self._starts_on_gait(src):
                self.move({"ahead": START_LEAD}, stop=False, at_stance=False)
                self.notes.append(
                    f"commands[{self.command}] TRANSITION {src} -> {to}: the script's first "
                    f"frames step {START_LEAD:g} s along {src!r}'s gait from the start "
                    "frame, then blend in step")
            if self._stepping:
                self.gait_hop(src, to, blend)
                return
        standing = self._standing()
        if across:
            # from an IDLE or a MOVE to a latent point the particle has no step to keep: the
            # gaits blended in step from there popped at 1.1-6.5x the run's p99 of
            # acceleration over ten seeds of a Bandai script, 0.4-1.7x at a bridge
            self.notes.append(
                f"commands[{self.command}] TRANSITION {src} -> {to}: not in step, crossed "
                "while both models idle (the particle was not stepping: in step needs a "
                "MOVE ahead, a MOVE to a frame of the gait, a PLAY or a TRANSITION in step "
                "before it)"
                + (_STOOD if standing else "")
            )
        hops = [src, to]
        if route:
            c = self.crossings(src, to)
            if not (c.distances < c.threshold).any():
                hops = self.route(src, to)
        first = self.n_frames
        for a, b in zip(hops[:-1], hops[1:]):
            self._hop(a, b, blend, radius, hops)
        if standing:
            self.stood.append((first, self.n_frames))
            self._set_off(first)
            if not across:
                self.notes.append(f"commands[{self.command}] TRANSITION {src} -> {to}: crossed "
                                  "while both models idle" + _STOOD)

    def _set_off(self, first: int) -> None:
        """The frames from ``first`` on, a crossing made standing, set off from rest: their
        chunks' pace rises from 0 to 1 (smoothstep) over them, their root's travel and
        turn with it (read from the pose, a standing figure in a running pose went with a
        run's speed: after an IDLE, a Bandai run -> walk crossing lurched from 0.03 to 1.5
        m/s in two frames, its feet gliding with it)."""
        ramp = smoothstep(self.n_frames - first)
        start = 0
        for c in self.chunks:
            k = c.X.shape[0]
            if start >= first:
                seg = ramp[start - first : start - first + k]
                c.root = paced_root(c.root, seg)
                c.pace = seg if c.pace is None else c.pace * seg
            start += k

    def _standing(self) -> bool:
        """Whether the figure stands before a crossing while both models idle: the
        frames made last are an IDLE's (or such a crossing's), or none is made yet and
        the start frame has no gait phase.  Such a crossing changes a standing figure's
        stance, which the script asked for: its frames (``stood``) are left out of the
        freeze measure as an IDLE's are (:meth:`~.output.OutputMixin.hold_mask`), and
        posed as any crossing's (the root carried by the feet).  They moved under a tenth
        of the takes' median pose speed for 0.3-0.7 s after an IDLE: 6 of the 8 freezes
        of 220 random scripts.  Held as an IDLE's frames (root and heading stopped), the
        walk after them popped where the hold let go (subject 35, 0.89x -> 1.48x)."""
        if not self.chunks:
            return not self._starts_on_gait(self.current)
        return any(r and r[-1][1] == self.n_frames for r in (self.held, self.stood))

    def _starts_on_gait(self, name: str) -> bool:
        """Whether no frame is made yet and the particle starts on a training frame of
        model ``name`` that has a gait phase (then a TRANSITION steps first:
        :data:`START_LEAD`)."""
        if self.chunks:
            return False
        m, g = self.models[name], self.gait(name)
        k = int(m.nearest_frame(self.x[None])[0])
        return bool(np.isin(g.segments[k], g.usable) and np.isfinite(g.phase[k]))

    def _mix(
        self, src: str, to: str, a: np.ndarray, b: np.ndarray, w: np.ndarray
    ) -> np.ndarray:
        """``(1 - w) a + w b`` of model ``src``'s angles ``a`` and model ``to``'s ``b``
        (each ``(T, C)``, ``w`` ``(T,)``), in ``to``'s chart, each joint's rotation
        slerped: linear in the rig's channels elsewhere.

        Linear in ``to``'s chart, a joint ``to`` models about its mean rotation mixed a
        pose far from that mean written in it, whose Euler angles there flip from frame
        to frame: at the Bandai walk-run hop the right elbow swung 17 degrees a frame
        with the run's weight at 0.05 and the hand accelerated 2.3x the run's 99th
        percentile."""
        from scipy.spatial.transform import Rotation

        from ...conventions import continuous_euler

        ma, mb = self.models[src], self.models[to]
        ca, cb = ma.to_channels(a), mb.to_channels(b)
        w = np.asarray(w, dtype=float).reshape(-1)
        out = (1.0 - w[:, None]) * ca + w[:, None] * cb
        by_order: dict[str, list[np.ndarray]] = {}
        for idx, order in mb.rotation_columns():
            by_order.setdefault(order, []).append(idx)
        T = len(w)
        for order, cols in by_order.items():  # the joints of one Euler order at once
            idx = np.array(cols)  # (J, 3)
            Ra = Rotation.from_euler(order, ca[:, idx].reshape(-1, 3), degrees=True)
            Rb = Rotation.from_euler(order, cb[:, idx].reshape(-1, 3), degrees=True)
            step = (Ra.inv() * Rb).as_rotvec()
            R = Ra * Rotation.from_rotvec(np.repeat(w, len(cols))[:, None] * step)
            # the Euler solution nearest the first pose's, continuous over the blend
            out[:, idx] = continuous_euler(R.as_matrix().reshape(T, len(cols), 3, 3), order,
                                           ca[0, idx])
        return mb.to_model(out)

    def _into(self, src: str, to: str, angles: np.ndarray) -> np.ndarray:
        """Model ``src``'s angles ``(T, C)`` in model ``to``'s chart: the same rotations
        (:meth:`~.model.LatentModel.chart`), so a blend mixes like with like."""
        if src == to:
            return angles
        return self.models[to].to_model(self.models[src].to_channels(angles))

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
        # (from a figure that moves, the approach flows into the blend: stopping at the
        # bridge first, two crossings in a row stood still 0.27 s between them, a freeze)
        self.move(Point(x1), radius=small, speed=APPROACH_SPEED, stop=self._standing())
        asked = blend_asked(blend, self.fps)
        n = min(max(asked, self.blend_frames(src, to, x1, x2)), int(MAX_BLEND * self.fps))
        self.reserve(n + 1, "TRANSITION")
        if n != asked:
            self.notes.append(
                f"commands[{self.command}] TRANSITION {src} -> {to}: blend raised from "
                f"{blend:g} s ({plural(asked, 'frame')}) to {n / self.fps:.2f} s ({n} frames): "
                "blending "
                f"poses {c.distances[b]:.3g} units apart faster "
                f"would accelerate joints over {BLEND_ACCELERATION:g}x the models' training "
                "99th percentile"
            )
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
        root = {k: mix_rows(r1[k], r2[k], w) for k in r1}
        # each model's pose is clipped to its own range before the blend, so the frames
        # after the blend continue without a jump
        blended = self._mix(
            src, to, self._clip(src, m1.pose(X1)), self._clip(to, m2.pose(X2)), w[:, 0]
        )
        k1, k2 = int(m1.nearest_frame(x1[None])[0]), int(m2.nearest_frame(x2[None])[0])

        def targets() -> tuple[np.ndarray, np.ndarray]:
            # untangling pulls toward the two nearest captured frames blended: the jog
            # actor's hand passed into the walk's hip in the blend of the particles'
            # poses (subject 35, refused by animate; 6 frames of one script -> 0)
            a1 = np.repeat(m1.frame_angles()[k1][None], len(w), axis=0)
            a2 = np.repeat(m2.frame_angles()[k2][None], len(w), axis=0)
            near = self._mix(src, to, a1, a2, w[:, 0])
            return near, near

        self._emit(to, X2, blended, root, clip=False, targets=targets)
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
        self._stepping = False

