"""Limbs kept apart and pops smoothed in a :class:`~.commands.Synthesizer`'s posed frames:
frames whose limbs come closer than the training takes' (or that accelerate too fast)
are pulled toward captured poses: along a gait the captured pose at their phase, in a
blend both models' captured poses blended, in an IDLE one captured frame of its own."""

from __future__ import annotations

import numpy as np

from ..._words import plural
from ...motion import Motion
from .easing import smooth

__all__ = [
    "POP_PULL", "POP_ROUNDS", "POP_SOFTEN", "UNTANGLE_OFF_WIDTH", "UNTANGLE_POP", "UNTANGLE_ROUNDS",
    "UNTANGLE_WIDTH",
]

#: Seconds each side of a frame whose limbs came too close over which the pull toward the
#: captured pose eases off, and the passes that look again.
UNTANGLE_WIDTH = 0.15
UNTANGLE_ROUNDS = 3
#: The same width (s) about a frame of an IDLE (off any gait's path), whose pose can lie
#: farther from its captured frame's: within the IDLE, easing in from its ends.
UNTANGLE_OFF_WIDTH = 0.5
#: Frames along a gait accelerating over this many times the training 99th percentile
#: are pulled toward the captured pose at their phase (:meth:`UntangleMixin._unpopped`),
#: up to this many times.
POP_PULL = 1.4
POP_ROUNDS = 3
#: Seconds: a particle's frames off any gait's path that accelerate over :data:`POP_PULL`
#: times the training 99th percentile have their latent path smoothed this much more
#: (:meth:`UntangleMixin._softened`).
POP_SOFTEN = 3.0 / 30.0
#: A pull that untangles limbs but makes its frames accelerate over this many times the
#: training 99th percentile (and faster than before it) is taken back: the pops' own
#: limit.  The limbs are then turned apart at the shoulder or hip by a few degrees
#: (:mod:`cyclecoord.synthesis.clearance`).  At 2.0, pulls within 0.15 s made 4 of the 9
#: pops over 1.5x of 670 random scripts (subject 35: a blend's toes 0.2x -> 1.84x the
#: walk's p99); at 1.4 none, and no script's limbs were left closer than the takes'.
UNTANGLE_POP = POP_PULL


def _spread(weights: np.ndarray, frames: np.ndarray, bump: np.ndarray) -> None:
    """``weights`` ``(T,)`` raised in place to ``bump`` (odd length, its peak at the
    middle) centred on each of ``frames``."""
    w, T = (bump.size - 1) // 2, weights.size
    for f in frames:
        a, b = max(f - w, 0), min(f + w + 1, T)
        weights[a:b] = np.maximum(weights[a:b], bump[a - f + w : b - f + w])


def _rounds(motion: Motion, weights: np.ndarray, eligible: np.ndarray, limit: np.ndarray,
            bump: np.ndarray, pose, strict: bool = False) -> tuple[Motion, set[int]]:
    """Up to :data:`POP_ROUNDS` rounds: the ``eligible`` frames accelerating over ``limit``
    (whose ``weights`` are under 1) get ``bump`` in ``weights`` (in place) and ``pose(weights,
    motion)`` is tried; a round that makes the raised frames pop worse than before
    (``strict``: or no better) is taken back and ends them.  Returns the motion and the
    frames the kept rounds raised."""
    from ..carry import _accel

    acc = _accel(motion)
    done: set[int] = set()
    for _ in range(POP_ROUNDS):
        bad = np.flatnonzero((acc > limit) & eligible & (weights < 1.0))
        if not bad.size:
            break
        was = weights.copy()
        _spread(weights, bad, bump)
        trial = pose(weights, motion)
        near = weights > was
        after = _accel(trial)
        worse, before = (after[near] / limit[near]).max(), (acc[near] / limit[near]).max()
        if worse > before or (strict and worse == before):
            weights[:] = was
            break
        done.update(int(f) for f in bad)
        motion, acc = trial, after
    return motion, done


class UntangleMixin:
    """:meth:`_untangled` and :meth:`_unpopped` of :class:`~.output.OutputMixin`."""

    def _untangled(self) -> Motion:
        """The posed motion; where two limbs come closer than the training takes ever do
        (:func:`~cyclecoord.quality.plausibility.check_plausibility`'s new contacts) on
        frames stepping along a gait, those frames are pulled toward the captured frame
        at their phase (the pose of the gait's path plus its detail: the training takes'
        own pose, which makes no new contact), fully at the frame and easing off over
        :data:`UNTANGLE_WIDTH` seconds each side, up to :data:`UNTANGLE_ROUNDS` times.  A
        frame still too close there takes the nearest whole captured frame, the frames
        about it the capture played on from there at its pace: the pose at a
        phase between two frames cut the corner where a swinging foot passed the other
        shin (on a Bandai run, a shin and a foot 5.1 units apart against the takes'
        closest 6.3, and animate refused three script seeds in ten).
        With the gait detail on the Bandai walk-run script, legs passed 1-2 cm closer
        than the captures on one or two frames in eight script seeds of fifteen.  Blends
        are pulled toward their chunk's targets (``_Chunk.targets``), an IDLE's frames
        toward one captured frame of its own over :data:`UNTANGLE_OFF_WIDTH` (within the
        IDLE), and a pull that makes its frames pop is taken back
        (:meth:`_unpulled_pops`)."""
        motion = plain = self._assemble(*self._posed())
        pullable = self._on_path(particles=True)
        if not pullable.any():
            return motion
        takes = [self.models[k].training_motion() for k in sorted({c.model for c in self.chunks})]
        from ...quality.contacts import contact_runs
        from ...quality.plausibility import check_plausibility

        pull = np.zeros(motion.n_frames)
        # pulled to a whole captured frame (1), the capture played on about it (2)
        whole = np.zeros(motion.n_frames, dtype=np.int8)
        w = max(1, int(round(UNTANGLE_WIDTH * self.fps)))
        k = np.arange(-w, w + 1)
        u = 1.0 - np.abs(k) / (w + 1.0)
        bump = smooth(u)
        # an IDLE's pose can lie far from its captured frame: pulled over a wider window,
        # within the IDLE, easing in from the frames before and after it
        off = pullable & ~self._on_path()
        w2 = max(w, int(round(UNTANGLE_OFF_WIDTH * self.fps)))
        u2 = 1.0 - np.abs(np.arange(-w2, w2 + 1)) / (w2 + 1.0)
        wide = smooth(u2)
        cap = np.zeros(motion.n_frames)
        for a, b in contact_runs(off):
            t = np.arange(a, b, dtype=float)
            edge = np.minimum(t - a + 1 if a > 0 else np.inf,
                              b - t if b < motion.n_frames else np.inf)
            e = np.clip(edge / (w2 + 1.0), 0.0, 1.0)
            cap[a:b] = smooth(e)
        pulled: set[int] = set()
        before = None  # the last round's motion: only its pulled frames are checked again
        for _ in range(UNTANGLE_ROUNDS):
            frames = np.asarray(
                check_plausibility(
                    motion, takes, cache=self._plausibility, base=before, analysed=True
                ).new_contact_frames,
                dtype=int,
            )
            frames = frames - int(motion.start_frame)
            frames = frames[pullable[frames]] if frames.size else frames
            # a frame already at the captured pose of its phase and still too close: that
            # pose lies between two captured frames (a swinging foot passing the other
            # shin cuts the corner between them), so it takes the nearer captured frame
            stuck = np.array([f for f in frames if pull[f] >= 1.0 and not whole[f]
                              and not off[f]], dtype=int)
            frames = np.array([f for f in frames if pull[f] < 1.0], dtype=int)
            if not frames.size and not stuck.size:
                break
            for f in frames:
                r, bp = (w2, wide) if off[f] else (w, bump)
                a, b = max(f - r, 0), min(f + r + 1, motion.n_frames)
                add = bp[a - f + r : b - f + r] * (cap[a:b] if off[f] else 1.0)
                pull[a:b] = np.maximum(pull[a:b], add)
            pulled.update(int(f) for f in frames)
            before, motion = motion, self._whole_frames(motion, pull, whole, stuck, w)
        if pulled:
            motion = self._unpulled_pops(plain, motion, pull, whole, pulled)
        motion = self._unpopped(motion, pull, whole, bump)
        if pulled:
            idle = sum(bool(off[f]) for f in pulled)
            self._note_pulled(pulled, f"limbs: {plural(len(pulled), 'frame')} came closer than "
                              "the training takes' and", "" if not idle else
                              f"; {idle} in an IDLE toward one captured frame of its own")
        return motion

    def _unpulled_pops(self, plain: Motion, motion: Motion, pull: np.ndarray,
                       whole: np.ndarray, pulled: set[int]) -> Motion:
        """``motion`` with each run of pulled frames whose pull made it accelerate over
        :data:`UNTANGLE_POP` times the training 99th percentile, and faster than the posed
        ``plain`` there, posed as before (``pull``, ``whole`` and ``pulled`` changed in
        place; a note says where).  Its limbs then stay too close and animate refuses the
        script, where the pull wrote a pop: a subject 35 MOVE ahead easing in after an
        IDLE had its first frames pulled toward the captured pose at their phase within
        0.15 s, 1.46x -> 2.86x, and its limbs were still too close."""
        from ...quality.contacts import contact_runs
        from ..carry import _accel

        limit = UNTANGLE_POP * self._frame_acc99(motion.n_frames)
        was, now = _accel(plain) / limit, _accel(motion) / limit
        undone = []
        for a, b in contact_runs(pull > 0):
            lo, hi = max(a - 1, 0), min(b + 1, now.size)
            if now[lo:hi].max() > 1.0 and now[lo:hi].max() > was[lo:hi].max():
                pull[a:b], whole[a:b] = 0.0, 0
                undone.append((a, b))
        if not undone:
            return motion
        gone = {f for f in pulled if any(a <= f < b for a, b in undone)}
        pulled -= gone
        if gone:
            spans = ", ".join(f"{a}-{b - 1}" for a, b in undone)
            self.notes.append(f"limbs: {plural(len(gone), 'frame')} too close left as posed "
                              f"(frames {spans}): pulled toward the captured pose they "
                              f"accelerated over {UNTANGLE_POP:g}x the training 99th "
                              "percentile")
        return self._assemble(*self._posed(pull, whole), like=motion)

    def _whole_frames(self, motion: Motion, pull: np.ndarray, whole: np.ndarray,
                      stuck: np.ndarray, w: int) -> Motion:
        """``motion`` posed again with ``pull`` and the ``stuck`` frames at their nearest
        whole captured frame (``whole`` set in place): alone (1), or with the capture
        played on at its pace about them (2, the frames the pull eases over), whichever
        accelerates less there.  Alone among poses at their phase, such a frame threw a
        Bandai run's toes 2.4x its p99 of acceleration; played about it, a frame after an
        IDLE pulled the frames before it off their stride (2.3x)."""
        from ..carry import _accel

        if not stuck.size:
            return self._assemble(*self._posed(pull, whole), like=motion)
        a, b = max(int(stuck.min()) - 2 * w, 0), int(stuck.max()) + 2 * w + 1
        best = None
        joined = np.flatnonzero(whole)  # (frames taken whole in an earlier round nearby)
        joined = joined[np.abs(joined[:, None] - stuck[None, :]).min(axis=1) <= w]
        for kind in (2, 1):
            trial = whole.copy()
            trial[stuck] = kind
            if kind == 2:  # one run with them
                trial[joined] = 2
            out = self._assemble(*self._posed(pull, trial), like=motion)
            peak = float(_accel(out)[a:b].max())
            if best is None or peak < best[0]:
                best = (peak, out, kind)
        whole[stuck] = best[2]
        if best[2] == 2:
            whole[joined] = 2
        return best[1]

    def _note_pulled(self, frames: set[int], lead: str, more: str = "") -> None:
        """The console note for ``frames`` pulled toward the captured pose, after ``lead``
        (``more`` before the closing parenthesis)."""
        spans = sorted(frames)
        where = f"frames {spans[0]}-{spans[-1]}" if len(spans) > 1 else f"frame {spans[0]}"
        one = len(spans) == 1
        self.notes.append(f"{lead} {'was' if one else 'were'} pulled toward the captured pose "
                          f"at {'its' if one else 'their'} gait phase ({where}{more})")

    def _unpopped(
        self, motion: Motion, pull: np.ndarray, whole: np.ndarray, bump: np.ndarray
    ) -> Motion:
        """``motion`` with its frames along a gait (or an in-step blend) whose largest
        joint acceleration exceeds :data:`POP_PULL` times the training 99th percentile
        pulled toward the captured poses at their phase as :meth:`_untangled` pulls
        (``pull``, ``whole`` and the ``bump`` are its, updated in place), up to
        :data:`POP_ROUNDS` times; a note says where.  The captured pose at a phase
        accelerates as the capture does where the particle's own pose strayed: subject
        35's and the Bandai scripts' largest accelerations were over 1.5x on one or two
        seeds in fifteen, at a MOVE's start (none after).  A round that makes its frames
        pop worse is taken back: on a latent model of the Xsens walk, whose gait loops
        through its turn, the captured pose at the phase popped at 3.9x where the
        particle's popped at 2.6x."""

        on = self._on_path()
        limit = POP_PULL * self._frame_acc99(motion.n_frames)
        if not on.any():
            return self._softened(motion, pull, whole, bump, limit)
        motion, popped = _rounds(
            motion, pull, on, limit, bump,
            lambda w, m: self._assemble(*self._posed(w, whole), like=m))
        # (a round whose captured poses pop too, a seam of the gait's loop through a
        # take's turn, is taken back: the particle's own pose is kept)
        if popped:
            self._note_pulled(popped, f"pops: {plural(len(popped), 'frame')} accelerating over "
                              f"{POP_PULL:g}x the training 99th percentile")
        return self._softened(motion, pull, whole, bump, limit)

    def _softened(self, motion: Motion, pull: np.ndarray, whole: np.ndarray,
                  bump: np.ndarray, limit: np.ndarray) -> Motion:
        """``motion`` with a particle's frames off any gait's path (a MOVE to a point or
        along the command graph, a crossing's approach), or on one after
        :meth:`_unpopped`'s pull, that accelerate over
        :data:`POP_PULL` times the training 99th percentile posed again from their latent
        path smoothed by a Gaussian of :data:`POP_SOFTEN` seconds, fully at the frame and
        easing off over the ``bump``, up to :data:`POP_ROUNDS` times while it helps.
        Such a path turns or speeds up sharply where the particle rides a line's end or
        a turn of the graph (a Bandai MOVE along the graph after a crossing, 1.74x; a
        crossing's approach from an IDLE, 1.68x), and no captured pose at a phase is
        there to pull toward.  The pose stays a pose of the model (the path is smoothed
        in its latent space, not the joint angles)."""
        # (and a particle's frames along a gait's path that the pull toward the captured
        # poses left over the limit: a Bandai run's toes at 1.54x on a held-out script)
        off = np.repeat([c.particle and c.targets is None for c in self.chunks],
                        [c.X.shape[0] for c in self.chunks])
        soften = np.zeros(motion.n_frames)
        motion, done = _rounds(
            motion, soften, off, limit, bump,
            lambda w, m: self._assemble(*self._posed(pull, whole, w), like=m), strict=True)
        if done:
            spans = sorted(done)
            where = f"frames {spans[0]}-{spans[-1]}" if len(spans) > 1 else f"frame {spans[0]}"
            self.notes.append(f"pops: {plural(len(done), 'frame')} "
                              f"accelerating over {POP_PULL:g}x the training 99th percentile "
                              f"had their latent path smoothed ({where})")
        return motion

    def _on_path(self, particles: bool = False) -> np.ndarray:
        """(T,) frames of chunks that followed a gait's path or blend with a pose to pull
        toward (``_Chunk.targets``: in-step blends and crossings); with ``particles``,
        also a particle's frames off any path (IDLEs, lines: their nearest captured
        frame, :meth:`_untangle_target`)."""
        sizes = [c.X.shape[0] for c in self.chunks]
        return np.repeat(
            [c.path is not None or c.targets is not None for c in self.chunks], sizes
        ) | (particles & self._idle_frames())

    def _idle_anchors(self) -> dict[int, int]:
        """For each particle chunk wholly in an IDLE, the training frame its untangling
        pulls toward: the one nearest the mean latent point of its run of such chunks
        (consecutive, one model), one pose for the run."""
        idle, out, start, run = self._idle_frames(), {}, 0, []
        for n, c in enumerate(self.chunks + [None]):
            if c is not None and idle[start] and (not run or self.chunks[run[0]].model == c.model):
                run.append(n)
            else:
                if run:
                    m = self.models[self.chunks[run[0]].model]
                    x = np.concatenate([self.chunks[i].X for i in run]).mean(axis=0)
                    k = int(m.nearest_frame(x[None])[0])
                    out.update({i: k for i in run})
                run = [n] if c is not None and idle[start] else []
            if c is not None:
                start += c.X.shape[0]
        return out

    def _idle_frames(self) -> np.ndarray:
        """(T,) frames of particle chunks that lie wholly in an IDLE."""
        hold = self.hold_mask(sum(c.X.shape[0] for c in self.chunks))
        out = np.zeros(hold.size, dtype=bool)
        start = 0
        for c in self.chunks:
            stop = start + c.X.shape[0]
            out[start:stop] = c.particle and c.path is None and hold[start:stop].all()
            start = stop
        return out

    def _untangle_target(self, c, whole: np.ndarray | None, anchor: int | None = None
                         ) -> np.ndarray:
        """The angles ``(T, C)`` untangling pulls chunk ``c``'s frames toward: along a
        gait's path, the captured pose at each frame's phase (the path's pose plus its
        detail), or where ``whole`` the captured frame nearest the path; in an in-step
        blend, the same of both gaits blended; in a crossing's blend, the two particles'
        nearest captured frames blended (``_Chunk.targets``)."""
        some = whole is not None and whole.any()
        k = np.flatnonzero(whole) if some else None
        played = np.flatnonzero(whole == 2) if some else np.zeros(0, dtype=int)
        if c.targets is not None:
            near, whole_frames = c.targets()
            target = near.copy()
            if some:
                target[k] = whole_frames[k]
            return target
        m = self.models[c.model]
        if anchor is not None:  # an IDLE's particle: its run's captured frame
            target = np.repeat(m.frame_angles()[anchor][None], c.X.shape[0], axis=0)
            return self._clip(c.model, target, count=False)
        target = m.pose(c.path) + c.detail["angles"]
        if some:
            target[k] = m.frame_angles()[m.nearest_frame(c.path[k])]
        if played.size:  # about those frames the capture played on at its pace
            fa, w = m.frame_angles(), max(1, int(round(UNTANGLE_WIDTH * self.fps)))
            # one anchor per run of such frames (its middle one): consecutive frames
            # anchored apart jumped between two strides
            runs = np.split(played, np.flatnonzero(np.diff(played) > w) + 1)
            k = np.array([r[len(r) // 2] for r in runs])
            near = m.nearest_frame(c.path[k])
            t = np.unique(np.concatenate([np.arange(r[0] - w, r[-1] + w + 1) for r in runs]))
            t = t[(t >= 0) & (t < len(target))]
            i = np.abs(t[:, None] - k[None, :]).argmin(axis=1)  # each frame's anchor
            at = near[i] + (t - k[i]) * m.fps_ / self.fps
            for seg in np.unique(m.segments_[near[i]]):  # (within its frame's take)
                rows = np.flatnonzero(m.segments_ == seg)
                j = m.segments_[near[i]] == seg
                target[t[j]] = np.stack([np.interp(np.clip(at[j], rows[0], rows[-1]), rows,
                                                   fa[rows, c_]) for c_ in range(fa.shape[1])],
                                        axis=1)
        return self._clip(c.model, target, count=False)

