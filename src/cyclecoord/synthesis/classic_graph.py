"""Baselines for generated motion: a classic motion graph and nearest-take replay.

:class:`ClassicMotionGraph` follows Kovar, Gleicher and Pighin, *Motion Graphs*
(SIGGRAPH 2002), written here from the paper's description:

* **distance**: for frames ``a`` and ``b``, the joint positions of the windows
  ``a .. a+W-1`` and ``b .. b+W-1`` (``W`` frames, :data:`WINDOW` seconds) as two point
  clouds; the second is turned about the vertical and moved on the floor by the rigid
  motion that fits it best to the first (the paper's closed form), and the distance is
  the RMS of what is left over the window's points;
* **transition points**: local minima of that distance over ``(a, b)`` (3 x 3
  neighbourhood) under :data:`THRESHOLD` leg lengths, not between two frames of one take
  within a window of each other;
* **transitions**: ``W`` frames blending the window of ``a`` into the window of ``b``
  (the second aligned by the fitted rigid motion) with the paper's ease
  ``2 u**3 - 3 u**2 + 1``: joint angles interpolated linearly (unwrapped; the two poses
  are close at a transition point), the root's position linearly and its rotation by
  slerp; playback then goes on at ``b + W``;
* **pruning**: only the largest strongly connected component of the graph is walked, so
  no walk reaches a dead end (a take's last frame);
* **walk**: random (a transition is taken with probability :data:`JUMP` per frame where
  one leaves, always where the take ends).

:func:`replay_nearest` is the plainest baseline: play the training take whose frame is
nearest the start pose, and at its end cut (no blend) to the frame nearest its last
pose, turned and moved to continue the path.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial.transform import Rotation

from ..errors import ParameterError
from ..motion import Motion

__all__ = ["ClassicMotionGraph", "ClassicWalk", "replay_nearest", "WINDOW", "THRESHOLD"]

#: Transition window, seconds (the paper's 1/3 s).
WINDOW = 1.0 / 3.0
#: Largest RMS point distance (leg lengths) at a transition point.
THRESHOLD = 0.06
#: Chance per frame of taking a transition where one leaves (a random walk).
JUMP = 0.05
#: A replay cuts to a frame with at least this long (s) left of its take.
REPLAY_LEFT_S = 1.0


def _up_check(motion: Motion) -> None:
    if motion.skeleton is None:
        raise ParameterError("the classic motion graph needs a skeleton (joint positions)")


def _yaw(theta: np.ndarray) -> Rotation:
    return Rotation.from_rotvec(np.asarray(theta, float)[..., None] * np.array([0.0, 1.0, 0.0]))


@dataclass
class _Clouds:
    """Per training frame the window's points, centred on the floor: x, y, z ``(N, W J)``."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    cx: np.ndarray  # window means on the floor (N,)
    cz: np.ndarray


def _clouds(pos: np.ndarray, take: np.ndarray, w: int, stride: int) -> _Clouds:
    """Window point clouds of every frame; a window past its take's end repeats the end."""
    n = pos.shape[0]
    last = np.zeros(n, dtype=int)
    for t in np.unique(take):
        idx = np.flatnonzero(take == t)
        last[idx] = idx[-1]
    rows = np.minimum(np.arange(n)[:, None] + np.arange(0, w, stride)[None, :], last[:, None])
    win = pos[rows]  # (N, w', J, 3)
    x, y, z = (win[..., i].reshape(n, -1) for i in range(3))
    cx, cz = x.mean(axis=1), z.mean(axis=1)
    return _Clouds(x - cx[:, None], y, z - cz[:, None], cx, cz)


def window_distance(c: _Clouds) -> np.ndarray:
    """RMS point distance ``(N, N)`` after the best turn and floor shift of the second
    window onto the first (Kovar et al.'s closed form)."""
    m = c.x.shape[1]
    a = c.x @ c.x.T + c.z @ c.z.T
    b = c.x @ c.z.T - c.z @ c.x.T
    sq = (c.x**2).sum(1) + (c.z**2).sum(1)
    ny = (c.y**2).sum(1)
    d = sq[:, None] + sq[None, :] - 2.0 * np.hypot(a, b)
    d += ny[:, None] + ny[None, :] - 2.0 * (c.y @ c.y.T)
    return np.sqrt(np.maximum(d, 0.0) / m)


def _fit(c: _Clouds, a: int, b: int) -> tuple[float, np.ndarray]:
    """The turn (about +y) and floor shift taking window ``b`` onto window ``a``."""
    sa = float(c.x[a] @ c.x[b] + c.z[a] @ c.z[b])
    sb = float(c.x[a] @ c.z[b] - c.z[a] @ c.x[b])
    theta = float(np.arctan2(sb, sa))
    # a rotation by theta about +y maps (x, z) to (x cos + z sin, -x sin + z cos)
    ct, st = np.cos(theta), np.sin(theta)
    bx, bz = c.cx[b] * ct + c.cz[b] * st, -c.cx[b] * st + c.cz[b] * ct
    return theta, np.array([c.cx[a] - bx, 0.0, c.cz[a] - bz])


@dataclass
class ClassicWalk:
    """A walk on the classic graph: the played segments and where it transitioned."""

    motion: Motion
    transitions: list = field(default_factory=list)  # (output frame, from node, to node)
    segments: list = field(default_factory=list)


class ClassicMotionGraph:
    """Kovar, Gleicher and Pighin's motion graph over training takes (see the module notes).

    Parameters
    ----------
    window : float
        Transition length and distance window, seconds.
    threshold : float
        Largest RMS point distance at a transition point, in leg lengths.
    stride : int
        Every ``stride``-th frame of a window enters the distance (1: all).
    """

    def __init__(self, window: float = WINDOW, threshold: float = THRESHOLD, stride: int = 2):
        self.window = window
        self.threshold = threshold
        self.stride = stride

    def fit(self, takes: Sequence[Motion]) -> "ClassicMotionGraph":
        from ..quality.contacts import leg_length
        from ..quality.legs import find_feet
        from .graph.latent import check_takes

        self.notes_: list[str] = []
        self.takes_ = check_takes(takes, minimum=1, notes=self.notes_)
        _up_check(self.takes_[0])
        fps = self.takes_[0].fps
        self.w_ = max(2, int(round(self.window * fps)))
        pos = [m.positions().positions for m in self.takes_]
        self.take_ = np.concatenate([np.full(len(p), i) for i, p in enumerate(pos)])
        self.frame_ = np.concatenate([np.arange(len(p)) for p in pos])
        self.start_ = np.r_[0, np.cumsum([len(p) for p in pos])[:-1]]
        self.pos_ = np.concatenate(pos)
        self.clouds_ = _clouds(self.pos_, self.take_, self.w_, self.stride)
        skel = self.takes_[0].skeleton
        legs = leg_length(skel, find_feet(skel, self.takes_[0]))
        self.distance_ = window_distance(self.clouds_)
        self.transitions_ = self._transition_points(self.distance_, self.threshold * legs)
        self._prune()
        return self

    def _transition_points(self, d: np.ndarray, limit: float) -> np.ndarray:
        """Pairs ``(a, b)``: local minima of ``d`` under ``limit``, windows inside takes."""
        from scipy.ndimage import minimum_filter

        # a window and the frame after it inside the take
        ok = self.frame_ + self.w_ < np.bincount(self.take_)[self.take_]
        low = (d == minimum_filter(d, size=3, mode="nearest")) & (d <= limit)
        low &= ok[:, None] & ok[None, :]
        gap = self.w_  # a jump within its own window is no transition
        same = self.take_[:, None] == self.take_[None, :]
        near = np.abs(self.frame_[:, None] - self.frame_[None, :]) <= gap
        low &= ~(same & near)
        a, b = np.nonzero(low)
        return np.stack([a, b], axis=1)

    def _prune(self) -> None:
        """Keep the transitions inside the largest strongly connected component."""
        n = self.take_.size
        nxt = np.flatnonzero(self.take_[1:] == self.take_[:-1])
        # a transition a -> b goes on at b + w (after the blended window)
        t = self.transitions_
        src = np.r_[nxt, t[:, 0]]
        dst = np.r_[nxt + 1, t[:, 1] + self.w_]
        g = csr_matrix((np.ones(src.size), (src, dst)), shape=(n, n))
        _, label = connected_components(g, directed=True, connection="strong")
        big = np.argmax(np.bincount(label))
        self.alive_ = label == big
        keep = self.alive_[t[:, 0]] & self.alive_[t[:, 1] + self.w_]
        self.transitions_ = t[keep]
        self.out_ = {int(a): [] for a in np.unique(self.transitions_[:, 0])}
        for a, b in self.transitions_:
            self.out_[int(a)].append(int(b))

    @property
    def n_transitions(self) -> int:
        return int(len(self.transitions_))

    def nearest_frame(self, motion: Motion, frame: int) -> int:
        """The live training frame whose window is nearest the given frame's."""
        from .graph.latent import check_takes

        check_takes([self.takes_[0], motion], minimum=1)
        p = motion.positions().positions
        tk = np.zeros(p.shape[0], dtype=int)
        c = _clouds(p, tk, self.w_, self.stride)
        q = _Clouds(*(np.vstack([getattr(c, k)[frame : frame + 1], getattr(self.clouds_, k)])
                      for k in ("x", "y", "z")),
                    np.r_[c.cx[frame], self.clouds_.cx], np.r_[c.cz[frame], self.clouds_.cz])
        d = window_distance(q)[0, 1:]
        d[~self.alive_] = np.inf
        return int(np.argmin(d))

    def walk(
        self, n_frames: int, start: int = 0, seed: int = 0, jump: float = JUMP
    ) -> ClassicWalk:
        """A random walk of ``n_frames`` from training node ``start`` (moved to the
        nearest live frame of the component when outside it)."""
        if not self.n_transitions:
            raise ParameterError(
                f"no transition points under {self.threshold} leg lengths: the takes are "
                "too far apart for a motion graph at this threshold"
            )
        rng = np.random.default_rng(seed)
        node = int(start)
        if not self.alive_[node]:
            live = np.flatnonzero(self.alive_)
            node = int(live[np.argmin(np.abs(live - node))])
        plan: list[tuple[str, int, int]] = []  # ("play", node, node) or ("blend", a, b)
        count, n = 0, self.take_.size
        while count < n_frames:  # node: the next training frame to play
            has_next = (
                node + 1 < n and self.take_[node + 1] == self.take_[node] and self.alive_[node + 1]
            )
            outs = self.out_.get(node, [])
            if outs and (not has_next or rng.random() < jump):
                b = int(outs[rng.integers(len(outs))])
                plan.append(("blend", node, b))
                count += self.w_
                node = b + self.w_
                continue
            if not has_next:  # cannot happen inside the strongly connected component
                raise ParameterError(f"dead end at training frame {node}")
            plan.append(("play", node, node))
            count += 1
            node += 1
        return self._render(plan, n_frames)

    def _render(self, plan, n_frames: int) -> ClassicWalk:
        """Frames of a plan, each segment turned and moved to continue the previous."""
        rows, alphas, others, xf_a, xf_b, marks = [], [], [], [], [], []
        theta, shift = 0.0, np.zeros(3)  # the current segment's placement
        for kind, a, b in plan:
            if kind == "play":
                rows.append(a)
                others.append(a)
                alphas.append(1.0)
                xf_a.append((theta, shift.copy()))
                xf_b.append((theta, shift.copy()))
                continue
            th, sh = _fit(self.clouds_, a, b)  # window b onto window a, in a's placement
            new_theta = theta + th
            new_shift = shift + _yaw(np.array(theta)).apply(sh)
            marks.append((len(rows), a, b))
            u = (np.arange(self.w_) + 1.0) / self.w_
            for i in range(self.w_):
                rows.append(a + i)
                others.append(b + i)
                alphas.append(2 * u[i] ** 3 - 3 * u[i] ** 2 + 1)
                xf_a.append((theta, shift.copy()))
                xf_b.append((new_theta, new_shift.copy()))
            theta, shift = new_theta, new_shift
        n = min(n_frames, len(rows))
        motion = self._frames(
            np.array(rows[:n]), np.array(others[:n]), np.array(alphas[:n]), xf_a[:n], xf_b[:n]
        )
        return ClassicWalk(motion=motion, transitions=marks)

    def _frames(self, ra, rb, alpha, xa, xb) -> Motion:
        return _blend_frames(self.takes_, ra, rb, alpha, xa, xb)


def _blend_frames(takes, ra, rb, alpha, xa, xb) -> Motion:
    """Frames ``alpha * A + (1 - alpha) * B`` of training frames ``ra`` and ``rb`` (root
    placed by ``xa`` / ``xb``: a turn about +y and a floor shift, each about the origin)."""
    from ..conventions import continuous_euler
    from .align import root_rotation
    from .graph.latent import angle_columns

    template = takes[0]
    all_frames = np.concatenate([m.frames for m in takes])
    mats = np.concatenate([root_rotation(m)[0] for m in takes])
    _, order, rcols = root_rotation(template)
    root = template.skeleton.joints[0]
    tcols = [template.channel_index(root.name, "t" + a) for a in "xyz"]
    ang = angle_columns(template)
    ia, ib = ra, rb
    fa, fb = all_frames[ia].copy(), all_frames[ib].copy()
    # joint angles: B unwrapped onto A, then linear
    d = fb[:, ang] - fa[:, ang]
    fb[:, ang] = fa[:, ang] + (d + 180.0) % 360.0 - 180.0
    al = np.asarray(alpha)[:, None]
    out = fa * al + fb * (1 - al)
    th_a = np.array([t for t, _ in xa])
    th_b = np.array([t for t, _ in xb])
    sh_a = np.array([s for _, s in xa])
    sh_b = np.array([s for _, s in xb])
    from .carry import _translation_scale

    unit = _translation_scale(template, tcols[0])  # positions per channel unit
    pa = _yaw(th_a).apply(fa[:, tcols]) + sh_a / unit
    pb = _yaw(th_b).apply(fb[:, tcols]) + sh_b / unit
    out[:, tcols] = pa * al + pb * (1 - al)
    qa = _yaw(th_a) * Rotation.from_matrix(mats[ia])
    qb = _yaw(th_b) * Rotation.from_matrix(mats[ib])
    rel = (qa.inv() * qb).as_rotvec()
    rot = (qa * Rotation.from_rotvec(rel * (1 - al))).as_matrix()
    if not np.allclose(root.axis, np.eye(3)):
        rot = root.axis.T @ rot @ root.axis
    out[:, rcols] = continuous_euler(rot[:, None], order, all_frames[ia[0], rcols])[:, 0]
    return template.with_frames(out, start_frame=0, source="synthetic:classic-motion-graph",
                                metadata={})


def replay_nearest(
    takes: Sequence[Motion], n_frames: int, start: Motion, frame: int = 0
) -> ClassicWalk:
    """Replay the training take nearest the start pose; at its end cut (no blend) to the
    frame nearest its last pose, turned and moved onto it, and so on."""
    g = ClassicMotionGraph(window=2.0 / start.fps, threshold=np.inf, stride=1).fit(takes)
    node = g.nearest_frame(start, frame)
    plan = []
    count = 0
    ends = np.r_[g.take_[1:] != g.take_[:-1], True]
    left = np.bincount(g.take_)[g.take_] - g.frame_  # frames left in the take
    d = g.distance_.copy()
    d[:, left < min(REPLAY_LEFT_S * start.fps, 0.5 * left.max())] = np.inf
    while count < n_frames:
        plan.append(("play", node, node))
        count += 1
        if ends[node]:
            b = int(np.argmin(d[node]))
            plan.append(("cut", node, b))
            node = b
        else:
            node += 1
    return _replay_render(g, plan, n_frames)


def _replay_render(g: ClassicMotionGraph, plan, n_frames: int) -> ClassicWalk:
    rows, xf, marks = [], [], []
    theta, shift = 0.0, np.zeros(3)
    for kind, a, b in plan:
        if kind == "play":
            rows.append(a)
            xf.append((theta, shift.copy()))
        else:
            th, sh = _fit(g.clouds_, a, b)
            shift = shift + _yaw(np.array(theta)).apply(sh)
            theta = theta + th
            marks.append((len(rows), a, b))
    rows = np.array(rows[:n_frames])
    motion = _blend_frames(g.takes_, rows, rows, np.ones(rows.size),
                           xf[:n_frames], xf[:n_frames])
    return ClassicWalk(motion=motion, transitions=marks)
