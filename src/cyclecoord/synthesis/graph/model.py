"""The motion-graph synthesiser: latent space, graph and field fitted together, and playable output.

>>> synth = MotionGraphSynth(method="delaunay", dims=2).fit(takes)      # doctest: +SKIP
>>> result = synth.generate(450, start=takes[0], frame=0)              # doctest: +SKIP
>>> cc.save(result.motion, "walk.bvh")                                 # doctest: +SKIP
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from ..._blas import one_blas_thread
from ...errors import ParameterError
from ...motion import Motion
from .build import MotionGraph, build_graph
from .field import VectorField, parse_variant
from .latent import PoseSpace, check_takes
from .paths import INTEGRATORS, GraphPath, follow_field, path_to_target, root_trajectory

__all__ = ["MotionGraphSynth", "Generation", "take_name", "AUTO_VARIANCE", "auto_dims"]

#: ``dims="auto"``: the fewest PCA dimensions explaining this much of the joint-angle
#: variance.  The paper's 2 explain 61 % on subject 35's walks, and its paths shuffle: both
#: feet stay within a centimetre of the floor and slide against each other (support foot
#: 0.96 m/s with the root carried by the feet); 4 explain 85 % and keep the stride.
AUTO_VARIANCE = 0.85
#: Gaussian width (s) of the smoothing of a phase-aware path's detail (the neighbours'
#: joint angles the latent space leaves out): neighbours entering and leaving the
#: neighbourhood change it faster than the pose itself changes.
DETAIL_SMOOTH = 0.025
#: Gaussian width (s) of the smoothing of the root's carried steps: unsmoothed, the root
#: copied every contact switch and a 1,200-frame walk on subject 35 surged 1.1 -> 2.2 ->
#: 0.6 m/s within 0.1 s (its root acceleration 3.44x the takes' p99, 0.33x smoothed; the
#: 143_01 jog 1.96 -> 0.23x, its joints' 1.16 -> 0.71x; over 80 random ``to_target``
#: pairs of the synthesis benchmark, roots over 2x the p99 55 -> 1, at 0.07 s 6 and a
#: joint pop of 1.52x).  The feet stay pinned by the lock after it.
CARRY_SMOOTH = 0.1
#: Largest ``"auto"`` dimension.
AUTO_MAX_DIMS = 6


def auto_dims(takes: Sequence[Motion], variance: float = AUTO_VARIANCE) -> int:
    """The fewest latent dimensions (2 to :data:`AUTO_MAX_DIMS`) explaining ``variance``."""
    ratio = np.cumsum(PoseSpace(AUTO_MAX_DIMS).fit(takes).explained_variance_ratio_)
    return int(min(max(2, np.searchsorted(ratio, variance) + 1), AUTO_MAX_DIMS))


def take_name(m: Motion, i: int = 0) -> str:
    """A take's short name: its file name without folder and suffix."""
    return (
        m.source.replace("\\", "/").rsplit("/", 1)[-1].rsplit(".", 1)[0]
        if m.source
        else f"take {i}"
    )


@dataclass
class Generation:
    """A generated motion.

    Attributes
    ----------
    motion : Motion
        Joint angles from the path (inverse PCA), root from :func:`root_trajectory`; the
        training takes' channels and skeleton.
    path : GraphPath
    start : dict
        ``take`` (name), ``frame`` and ``latent`` (the projected start pose).
    hold : ndarray of bool, shape (T,), or None
        Frames of a stand the start or target asked for (one in a take's stand), which
        the measure of generated motion counts as asked, not as a freeze.
    """

    motion: Motion
    path: GraphPath
    start: dict
    notes: list = field(default_factory=list)
    hold: np.ndarray | None = None


class MotionGraphSynth:
    """Gauch & Peters' generator: PCA space, motion graph and vector field over training takes.

    Parameters
    ----------
    method : str, default "delaunay"
        ``"delaunay"``, ``"knn"`` or ``"union"``, optionally with the field options
        ``+ring`` and ``+agree`` (:func:`~.field.parse_variant`), e.g.
        ``"delaunay+ring+agree"``; or with ``+phase`` (``"delaunay+phase"``, what
        ``cyclecoord graph`` generates with): the phase-aware field of
        :mod:`~.phase`, which follows the gait's circular coordinate through the cusps
        where the paper's field stalls (the graph still serves :meth:`to_target`).
    dims : int or "auto", default 2
        Latent dimensions (the paper's 2); ``"auto"``: :func:`auto_dims` (what ``cyclecoord
        graph`` generates with).
    k : int, default 16
    integrator : {"euler", "rk4"}, default "euler"
    step_scale : float, default 1
        1 is the paper's step (about half the captured speed); 2 about the captured speed.
    carry : bool, default True
        The root's ground track carried by the feet on the ground
        (:func:`~cyclecoord.synthesis.carry.carry_by_feet`; no foot under the training
        takes' floor) instead of the training frames' mean root step, which the feet do
        not follow (they glide).
    lock : bool, default True
        Then pin the planted feet by a leg IK where that makes no pop
        (:func:`~cyclecoord.synthesis.carry.lock_where_clean`, limit 1.5x the training
        takes' 99th percentile of joint acceleration); ``Generation.notes`` says where not.

    Attributes
    ----------
    space_ : PoseSpace
    graph_ : MotionGraph
    field_ : VectorField
    takes_ : list of Motion
    names_ : list of str
    reference_frames_ : list of bool
        Per take, whether its frame 0 is a reference pose (a start there starts at 1).
    proportion_notes_ : list of str
        One line per take of the first take's rig by an actor of other proportions, put
        on the first take's skeleton (:func:`cyclecoord.rig.onto_skeleton`).
    phase_field_ : PhaseField or None
        With ``+phase``; then also ``phase_notes_`` (how each take got its phase),
        ``residual_`` (what the latent space leaves out of each training frame) and
        ``gaits_`` (the takes' indices per gait, :meth:`gaits`), ``take_gait_``
        ``(n_takes,)``, ``gain_`` ``(G, A)``, each gait's leg-angle stride widening
        (:func:`~.phase.amplitude_gain`; ones for a gait whose averaging mixes gaits),
        and ``angle_mean_`` ``(G, A)``, each gait's mean pose.
    """

    def __init__(
        self,
        method: str = "delaunay",
        dims: int = 2,
        k: int = 16,
        integrator: str = "euler",
        step_scale: float = 1.0,
        carry: bool = True,
        lock: bool = True,
    ) -> None:
        self.carry = carry
        self.lock = lock
        self.method = method
        self.dims = dims
        self.k = k
        self.integrator = integrator
        self.step_scale = step_scale

    @one_blas_thread
    def fit(self, takes: Sequence[Motion]) -> "MotionGraphSynth":
        method, ring, agree, phase = _parse(self.method)
        if self.integrator not in INTEGRATORS:
            raise ParameterError(
                f"unknown integrator {self.integrator!r}; choose from {', '.join(INTEGRATORS)}"
            )
        self.proportion_notes_: list[str] = []
        raw = check_takes(takes, minimum=2, notes=self.proportion_notes_)
        self.names_ = [take_name(m, i) for i, m in enumerate(raw)]
        self.takes_, self.rig_ = _analysis_takes(raw)
        self.reference_frames_ = [_has_reference_frame(m) for m in raw]
        self.dims_ = auto_dims(self.takes_) if self.dims == "auto" else int(self.dims)
        self.space_ = PoseSpace(self.dims_).fit(self.takes_)
        self.floor_, self.accel_limit_ = _ground(self.takes_) if self.carry else (None, None)
        latent = [self.space_.transform(m) for m in self.takes_]
        self.graph_: MotionGraph = build_graph(latent, method, self.k, self.names_)
        self.field_ = VectorField(self.graph_, ring=ring, agree=agree)
        self.phase_field_ = None
        self.phase_notes_: list[str] = []
        if phase:
            from .phase import PhaseField, take_phases

            tp = take_phases(self.takes_, latent)
            self.phase_notes_ = tp.notes
            self.phase_field_ = PhaseField(self.graph_, tp.phases)
            self.residual_ = self.space_.residuals(self.takes_)
            angles = np.vstack([self.space_.angles(m) for m in self.takes_])
            self._widen(angles)
        return self

    def _start(self, start: Motion | int, frame: int) -> tuple[Motion, int, str]:
        if isinstance(start, (int, np.integer)) and not isinstance(start, bool):
            if not 0 <= int(start) < len(self.takes_):
                raise ParameterError(
                    f"start take {start} is not one of the {len(self.takes_)} training takes"
                )
            motion, name = self.takes_[int(start)], self.names_[int(start)]
        elif isinstance(start, Motion):
            name = take_name(start)
            _frame_in(frame, start.n_frames, name)
            motion = _analysis_takes([start])[0][0] if self.rig_ is not None else start
            motion = check_takes([self.takes_[0], motion], minimum=2, notes=[])[1]
            rate = self.takes_[0].fps
            if abs(motion.fps - rate) > 1e-9:
                raise ParameterError(
                    f"{name}: {start.fps:g} fps, slower than the training takes' {rate:g} fps; "
                    "start from a take at their rate"
                )
            step = max(1, int(round(start.fps / rate)))
            frame = (int(frame) % start.n_frames) // step
            if step > 1:  # (its frame numbers are now the graph's rate's)
                name = f"{name} at {rate:g} fps"
        else:
            raise ParameterError(
                f"start must be a Motion or a training take's index, got {type(start).__name__}"
            )
        n = motion.n_frames
        _frame_in(frame, n, name)
        return motion, int(frame) % n, name

    def _past_reference(self, start: Motion | int, f: int, name: str) -> tuple[int, list]:
        """Frame 1 instead of a start at a take's reference first frame (a T-pose before
        the motion, as Xsens exports have; starting there, the path snapped into the walk
        at 20x the takes' 99th percentile of pose step), with a note."""
        if f != 0:
            return f, []
        if isinstance(start, Motion):
            ref = _has_reference_frame(start)
        else:
            ref = self.reference_frames_[int(start)]
        if not ref:
            return f, []
        return 1, [f"start: {name}'s frame 0 is a reference pose, not a pose of its motion; "
                   "started at frame 1"]

    def start_point(self, start: Motion | int = 0, frame: int = 0) -> np.ndarray:
        """The latent point ``(d,)`` of a take's frame."""
        motion, f, _ = self._start(start, frame)
        return self.space_.transform(motion[f])[0]

    @one_blas_thread
    def generate(self, n_frames: int, start: Motion | int = 0, frame: int = 0) -> Generation:
        """Follow the field for ``n_frames`` from a take's frame and make a playable motion.

        Parameters
        ----------
        n_frames : int
        start : Motion or int
            A take (any take of the skeleton, trained on or not) or a training take's index.
        frame : int
            0-based frame of ``start`` (negative counts from the end).
        """
        from ...io._limits import MAX_FRAMES, check_memory

        if isinstance(n_frames, (int, np.integer)) and not isinstance(n_frames, bool):
            if n_frames > MAX_FRAMES:
                raise ParameterError(f"{n_frames:,} frames; at most {MAX_FRAMES:,} are supported")
            # the path, the motion made of it and the plausibility checks' kinematics
            D = self.takes_[0].n_channels
            check_memory(n_frames * 8.0 * (8 * D + 64), f"{n_frames:,} generated frames")
        motion, f, name = self._start(start, frame)
        f, said = self._past_reference(start, f, name)
        x0 = self.space_.transform(motion[f])[0]
        if self.phase_field_ is not None:
            from .phase import follow_phase

            path = follow_phase(self.phase_field_, x0, n_frames, self.step_scale)
        else:
            path = follow_field(self.field_, x0, n_frames, self.integrator, self.step_scale)
        out = self._result(path, motion, f, name, x0)
        out.notes[:0] = said
        return out

    @one_blas_thread
    def to_target(
        self,
        start: Motion | int,
        frame: int,
        target: Motion | int,
        target_frame: int,
        speed: float = 1.0,
    ) -> Generation:
        """A playable path from one take's frame to another's pose.

        With the phase-aware field (``+phase``, the default) the path walks the gait at
        its captured cadence and eases onto the target at its phase
        (:func:`~.phase.phase_to_target`, ``speed`` times the captured speed); a target
        the gait does not come near (another gait) is reached by a cross-fade in step
        into its take (:func:`~.phase.phase_across`); a target in the stand a take begins
        with, which no capture walks into, by the gait fading into the stand over a cycle
        (:func:`~.phase.phase_to_stand`, the stand's frames in :attr:`Generation.hold`);
        failing those by the paper's shortest graph path (§V-A,
        :func:`~.paths.path_to_target`), a note saying which; the other fields always take
        the graph path.
        """
        motion, f, name = self._start(start, frame)
        f, said = self._past_reference(start, f, name)
        tmotion, tf, tname = self._start(target, target_frame)
        x0 = self.space_.transform(motion[f])[0]
        x1 = self.space_.transform(tmotion[tf])[0]
        path = stand = None
        if self.phase_field_ is not None:
            from .phase import phase_to_target

            path, miss = phase_to_target(self.phase_field_, x0, x1,
                                         self.phase_field_.phase_of(x1), 2.0 * float(speed))
            if path is None:
                from .phase import phase_across

                path = phase_across(self.phase_field_, x0, x1, 2.0 * float(speed))
                if path is not None:
                    said.append(
                        f"target {tname}:{tf} is on another gait (the start's comes no nearer "
                        f"than {miss:.2f} of the latent radius): a half-cycle cross-fade in "
                        "step into its take, then walked to it")
            held = None if path is not None else self._opening_stand(x0, x1)
            if held is not None:
                from .phase import phase_to_stand

                path, stops = phase_to_stand(self.phase_field_, x0, x1, 2.0 * float(speed))
                stand = (stops, path.points.shape[0])
                said.append(
                    f"target {tname}:{tf} is in the stand its take begins with (frames "
                    f"{held[0]}-{held[1]}, where the pose holds still), which no capture "
                    "walks into: the path walks the start's gait and over its last cycle "
                    "fades its strides into the stand's pose")
            elif path is None:
                said.append(
                    f"target {tname}:{tf} is not on the start's gait (the gait comes no "
                    f"nearer than {miss:.2f} of the latent radius): the shortest graph path "
                    "instead, which hops between takes and may pop")
        out = None
        if path is not None:
            out = self._result(path, motion, f, name, x0, stand=stand)
            if path.kind.endswith("across-to-target") and self._crosses(out.motion):
                # the fade brought two limbs too close: a fade a half or a whole cycle
                # later, else the graph path
                from .phase import phase_across

                tries = [phase_across(self.phase_field_, x0, x1, 2.0 * float(speed), later)
                         for later in (0.5, 1.0)]
                tries = [self._result(p, motion, f, name, x0) for p in tries if p is not None]
                tries.append(self._result(path_to_target(self.graph_, x0, x1, speed), motion,
                                          f, name, x0))
                clean = [t for t in tries if not self._crosses(t.motion)]
                if clean:
                    out = clean[0]
                    if out.path.kind.startswith("graph:"):
                        said[-1] = said[-1].split(": a half-cycle")[0] + (
                            ": the shortest graph path (cross-fades in step into its take "
                            "brought two limbs closer than the takes ever do; the graph path "
                            "hops between takes and may pop)")
        if out is None:
            out = self._result(path_to_target(self.graph_, x0, x1, speed), motion, f, name, x0)
        out.notes[:0] = said
        return out

    def _opening_stand(self, x0: np.ndarray, x1: np.ndarray) -> tuple[int, int] | None:
        """The frames (first, last) of the stand its take begins with that holds the
        target ``x1``, when the start ``x0`` is not in it (no capture walks into such a
        stand: CMU 69_01's first 1.3 s; from subject 35's walk the graph path jumped into
        it at 2.1x the sources' p99 of acceleration); else None."""
        from .phase import stand_at

        stand = stand_at(self.phase_field_, x1)
        g = self.graph_
        if stand is None or stand[1] != int(g.frame[g.take == stand[0]].min()) or (
                stand_at(self.phase_field_, x0) == stand):
            return None
        return stand[1:]

    def _in_stands(self, path: GraphPath) -> np.ndarray:
        """(T,) the path's first and last frames whose neighbours lie mostly (half the
        weight or more) in a take's stand (:func:`~.phase.moving_frames`): a start or
        target in a stand stands as its capture does (CMU 69_01 from its frame 11 stood
        0.7 s before its walk), which is asked for, not a freeze (none without the
        phase-aware field)."""
        hold = np.zeros(path.points.shape[0], dtype=bool)
        field = self.phase_field_
        if field is None or path.neighbours is None or not path.neighbours.size:
            return hold
        from .phase import standing

        held = (path.weights * standing(field)[path.neighbours]).sum(axis=1) >= 0.5
        # at the start and the end only: a path that stands on its way (through a stand
        # to a target just after it) freezes
        first = int(np.argmin(held)) if not held.all() else held.size
        last = held.size - int(np.argmin(held[::-1])) if not held.all() else 0
        hold[:first] = True
        hold[last:] = True
        return hold

    def _closed(self, motion: Motion, stand: tuple[int, int], notes: list[str]) -> Motion:
        """``motion`` with the closing step of :mod:`~cyclecoord.synthesis.stance` over the
        frames ``stand`` (the stop's fade, a gait cycle long) where its feet end apart, not
        made where it would accelerate a joint past the pins' limit (``accel_limit_``)."""
        from ...errors import CycleCoordError
        from ...quality.legs import find_feet
        from ..carry import channel_bounds
        from ..stance import close_stands

        try:
            feet = find_feet(motion.skeleton, motion)
        except CycleCoordError:
            return motion
        done = close_stands(motion, feet, [stand], cycle=(stand[1] - stand[0]) / motion.fps,
                            bounds=channel_bounds(self.takes_), references=self.takes_,
                            limit=self.accel_limit_)
        if done.line:
            notes.append(done.line)
        return done.motion

    def _crosses(self, motion: Motion) -> bool:
        """Whether two limbs of ``motion`` come closer than the training takes ever do."""
        from ...quality.plausibility import check_plausibility

        return bool(check_plausibility(motion, self.takes_).new_contact_frames)

    def _widen(self, angles: np.ndarray) -> None:
        """Per gait (:meth:`gaits`), the leg angles' stride widening
        (:func:`~.phase.amplitude_gain` over that gait's frames) and its mean pose.

        The widening undoes the narrowing of averaging repetitions of one gait; a gait
        whose frames draw more than :data:`MIXED_NEIGHBOURS` of their neighbours' weight
        from another gait is not widened (there the averaging mixes gaits, not strides:
        the Bandai walk forwards beside its walk backwards went to 1.3x its leg range and
        crossed the legs, with one gain over both).  One gain for all the takes left a
        walk-and-jog graph's jog unwidened: subject 35's walks and the 143_01 jog at 60
        fps, knees 0.87 / 0.86 of the jog's range (0.93 / 0.92 widened by its own)."""
        from ...quality.generated_kinematics import leg_channels
        from .phase import amplitude_gain

        self.gaits_ = self.gaits()
        g_of = np.empty(len(self.takes_), dtype=int)
        for g, members in enumerate(self.gaits_):
            g_of[members] = g
        self.take_gait_ = g_of
        frame_gait = g_of[self.graph_.take]
        idx, w = self.phase_field_.neighbours(self.graph_.points, self.phase_field_.phase)
        own = (w * (frame_gait[idx] == frame_gait[:, None])).sum(axis=1)
        legs = leg_channels(self.takes_[0], self.space_.channels_)
        self.gain_ = np.ones((len(self.gaits_), angles.shape[1]))
        self.angle_mean_ = np.empty_like(self.gain_)
        for g, members in enumerate(self.gaits_):
            mine = frame_gait == g
            self.angle_mean_[g] = angles[mine].mean(axis=0)
            names = "+".join(self.names_[i] for i in members)
            mixed = 1.0 - float(np.mean(own[mine]))
            if mixed > MIXED_NEIGHBOURS:  # its averaging mixes gaits, not strides
                self.phase_notes_.append(
                    f"strides not widened: {names}'s frames draw {100 * mixed:.0f} % of "
                    "their neighbours from another gait"
                )
                continue
            gain = amplitude_gain(self.phase_field_, angles, self.takes_[0].fps, mine)
            self.gain_[g, legs] = gain[legs]
        if len(self.gaits_) > 1:
            self.phase_notes_.append(
                "gaits (widened each on its own): "
                + " | ".join("+".join(self.names_[i] for i in m) for m in self.gaits_)
            )

    def _step_takes(self, path: GraphPath) -> np.ndarray:
        """Per path step, its neighbours' weight on each training take ``(T, n_takes)``."""
        nb = np.asarray(path.neighbours)
        w = np.where(nb >= 0, np.asarray(path.weights, dtype=float), 0.0)
        take = self.graph_.take[np.where(nb >= 0, nb, 0)]
        out = np.zeros((nb.shape[0], len(self.takes_)))
        np.add.at(out, (np.arange(nb.shape[0])[:, None], take), w)
        return out

    def _gait_weights(self, path: GraphPath) -> np.ndarray:
        """Per path step, its neighbours' weight per gait ``(T, G)``, rows summing to 1."""
        per_take = self._step_takes(path)
        out = np.stack([per_take[:, g].sum(axis=1) for g in self.gaits_], axis=1)
        total = out.sum(axis=1, keepdims=True)
        return np.where(total > 0, out / np.where(total > 0, total, 1.0), 1.0 / out.shape[1])

    def take_shares(self, path: GraphPath) -> np.ndarray:
        """How much a path draws on each training take ``(n_takes,)``, summing to 1: its
        neighbours' weights per take, over its steps.  A graph of a walk and a jog that
        jogged is judged against the jog (:meth:`reference`)."""
        shares = self._step_takes(path).sum(axis=0)
        total = shares.sum()
        return shares / total if total > 0 else np.full(len(self.takes_), 1 / len(self.takes_))

    def gaits(self) -> list[list[int]]:
        """The training takes grouped by gait: two takes are one gait when each one's
        poses lie within :data:`OTHER_GAIT_MISFIT` of the other's cycle at its phase
        (:func:`~.phase.match_misfit`); one group without the phase-aware field."""
        n = len(self.takes_)
        if self.phase_field_ is None or n < 2:
            return [list(range(n))]
        from .phase import match_misfit

        field = self.phase_field_
        take, z, ph = field.graph.take, field.graph.points, field.unwrapped
        group = list(range(n))

        def root(i: int) -> int:
            while group[i] != i:
                i = group[i]
            return i

        for a in range(n):
            for b in range(a + 1, n):
                ia, ib = take == a, take == b
                if not (ia.any() and ib.any()):
                    continue
                worst = max(match_misfit(z[ia], ph[ia], ph[ib], z[ib]),
                            match_misfit(z[ib], ph[ib], ph[ia], z[ia]))
                if worst <= OTHER_GAIT_MISFIT:
                    group[root(b)] = root(a)
        out: dict[int, list[int]] = {}
        for i in range(n):
            out.setdefault(root(i), []).append(i)
        return list(out.values())

    def reference(self, gen: Generation, feet=None):
        """The training takes' figures to judge ``gen`` by
        (:class:`~cyclecoord.quality.generated.SourceFigures`): each gait's takes
        (:meth:`gaits`) pooled, the gaits weighted by how much the path drew on them
        (:meth:`take_shares`).  Pooling every training frame judged a walk-and-jog
        graph's jog against the walks: "feet gliding (support foot 2.11 m/s, sources
        0.10)", where against the jog it is 1.5x the take's."""
        from ...quality.generated import mixed_reference, source_figures

        shares = self.take_shares(gen.path)
        n, fps = gen.motion.n_frames, gen.motion.fps
        cache: dict = {}
        parts = [
            (source_figures([self.takes_[i] for i in g], fps, feet, analysed=True,
                            cache=cache), shares[g].sum() * n)
            for g in getattr(self, "gaits_", None) or self.gaits()
            if shares[g].sum() > 0
        ]
        return parts[0][0] if len(parts) == 1 else mixed_reference(parts)

    def _result(
        self, path: GraphPath, motion: Motion, f: int, name: str, x0: np.ndarray,
        stand: tuple[int, int] | None = None,
    ) -> Generation:
        root = root_trajectory(self.takes_, path, motion, f)
        detail = None
        if path.phases is not None and self.phase_field_ is not None:
            # the neighbours share the path's phase: their detail is the pose's
            from scipy.ndimage import gaussian_filter1d

            detail = np.einsum("nk,nka->na", path.weights, self.residual_[path.neighbours])
            detail = gaussian_filter1d(detail, DETAIL_SMOOTH * motion.fps, axis=0, mode="nearest")
            # the neighbours' average is narrower than the strides it averages: widen it
            angles = self.space_.inverse_transform(path.points) + detail
            gw = self._gait_weights(path)
            detail = detail + (gw @ self.gain_ - 1.0) * (angles - gw @ self.angle_mean_)
        out = self.space_.motion(path.points, self.takes_[0], root, detail)
        notes = []
        if self.carry and self.floor_ is not None:
            from ..carry import carry_by_feet, channel_bounds, lock_where_clean

            out = carry_by_feet(out, floor=self.floor_, smooth=CARRY_SMOOTH)
            notes.append("root: carried by the feet on the ground (no foot under the floor)")
            if self.lock:
                locked = lock_where_clean(
                    out, self.accel_limit_, bounds=channel_bounds(self.takes_)
                )
                out = locked.motion
                notes.append(locked.line)
                if stand is not None:  # (phase_to_stand's stop: feet left apart close)
                    out = self._closed(out, stand, notes)
        if self.rig_ is not None:  # back in the takes' own rig
            out = self.rig_.restore(out)
        out = out.with_frames(
            out.frames,
            metadata={
                "generator": f"motion graph ({path.kind}, {self.dims_} dims)",
                "start": f"{name}:{f}",
            },
        )
        hold = self._in_stands(path)
        if hold.any() and stand is None:  # (a stop into a stand says so itself)
            notes.append(f"the path stands {hold.sum()} frames where its takes stand (a start "
                         "or target in a take's stand): counted as asked, not as freezes")
        if stand is not None:
            hold[stand[0] : stand[1]] = True
        hold = hold if hold.any() else None
        return Generation(
            motion=out,
            path=path,
            start={"take": name, "frame": f, "latent": x0.tolist()},
            notes=notes,
            hold=hold,
        )


def _frame_in(frame, n: int, name: str) -> None:
    """Refuse a start frame that is not a whole number within a take's ``n`` frames."""
    if isinstance(frame, bool) or not isinstance(frame, (int, np.integer)) or not -n <= frame < n:
        raise ParameterError(
            f"{name}: start frame {frame} is outside its {n} frames (0 to {n - 1})"
        )


def _has_reference_frame(m: Motion) -> bool:
    """Whether a take's first frame is a reference pose (:func:`cyclecoord.rig.describe_rig`)."""
    from ...errors import CycleCoordError
    from ...rig import describe_rig

    if m.skeleton is None or m.n_frames < 3:
        return False
    try:
        return bool(describe_rig(m).reference_frame)
    except CycleCoordError:
        return False


def _analysis_takes(takes: Sequence[Motion]) -> tuple[list[Motion], Any]:
    """The takes in their analysis rig (:func:`cyclecoord.rig.normalize_rig`, every frame
    kept, so frame numbers stay the takes'), and the first take's adapter that writes a
    generated motion back in their rig (None when nothing changed).

    A static root with travelling hips (the Bandai rig) otherwise left the hips' heading
    among the joint angles of the pose space and their travel out of the root's.
    """
    from ...rig import normalize_rig

    out = [normalize_rig(m, drop_reference=False) for m in takes]
    adapter = out[0][1]
    for i, (m, a) in enumerate(out[1:], 1):
        if a.changes() != adapter.changes() or m.channels != out[0][0].channels:
            raise ParameterError(
                f"{take_name(takes[i], i)}: its rig reads differently from "
                f"{take_name(takes[0], 0)}'s ({'; '.join(a.changes()) or 'nothing to change'} "
                f"against {'; '.join(adapter.changes()) or 'nothing to change'}); train on "
                "takes of one rig"
            )
    return [m for m, _ in out], (None if adapter.identity else adapter)


#: A take whose poses lie further than this from the other takes' mean pose at its
#: phase (:func:`~.phase.match_misfit`, against the cycle's spread) is another gait:
#: measured 0.01-0.02 on subject 35's walks, 0.08-0.10 on the 143_01 jog's halves,
#: 0.3-0.6 on the Bandai walks turning left and right, 1.4 and 19 on its walk forwards
#: with its walk backwards.
OTHER_GAIT_MISFIT = 1.0

#: A gait whose training frames draw more than this share of their neighbours' weight
#: from another gait is not widened (:meth:`MotionGraphSynth._widen`).
MIXED_NEIGHBOURS = 0.1


def _parse(method: str) -> tuple[str, bool, bool, bool]:
    """``"METHOD[+ring][+agree][+phase]"`` -> ``(method, ring, agree, phase)``."""
    parts = [p.strip() for p in str(method).split("+")]
    phase = "phase" in parts[1:]
    rest = "+".join(p for p in parts if p != "phase" or p is parts[0])
    if phase and parts.count("phase") > 1:
        raise ParameterError(f"{method!r}: +phase once")
    m, ring, agree = parse_variant(rest)
    if phase and (ring or agree):
        raise ParameterError(
            f"{method!r}: +phase replaces the Delaunay field, so +ring and +agree do not apply"
        )
    return m, ring, agree, phase


def _ground(takes: Sequence[Motion]) -> tuple[float | None, float | None]:
    """The training takes' floor (their foot contacts' median) and 1.5x the 99th
    percentile of their joint accelerations relative to the root; None without feet."""
    from ...errors import CycleCoordError
    from ...quality.contacts import foot_contacts
    from ..carry import _accel

    try:
        floor = float(np.median([foot_contacts(m).floor for m in takes]))
    except CycleCoordError:
        return None, None
    acc = np.concatenate([_accel(m) for m in takes])
    return floor, 1.5 * float(np.percentile(acc, 99))
