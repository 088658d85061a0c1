"""The frames a :class:`~.commands.Synthesizer` made, as one motion: root integrated,
then carried by the planted feet (and the feet pinned where that adds no pop)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import ParameterError
from ...motion import Motion
from .easing import paced_root, smooth
from .model import heading_matrix
from .untangle import POP_SOFTEN, UntangleMixin

__all__ = [
    "DETAIL_FADE",
    "LOCK_BLEND",
    "LOCK_MIN_CONTACT",
    "PLANT_MARGIN",
    "PLANT_ROUNDS",
    "PLANT_SMOOTH",
    "STAND_LEG_SWAY",
]

#: Seconds either side of a blend in which the root follows the planted feet.
PLANT_MARGIN = 0.2
#: Seconds over which a foot eases into and out of an IK lock.
LOCK_BLEND = 0.1
#: Shortest contact (s) the IK lock pins (shorter ones toggle and make the legs jitter).
LOCK_MIN_CONTACT = 0.2
#: Gaussian width (s) of the smoothing of the planted track's steps.  At 0.07 the root
#: still copied contact switches: over 400 random scripts (seeds 11-15) roots
#: accelerated over 2x the takes' p99 in 23 / 77 / 8 (synthetic / subject 35 / Bandai),
#: 5 / 23 / 0 at 0.1 (as the motion graph's ``CARRY_SMOOTH``); no joint pop either way.
PLANT_SMOOTH = 0.1
#: Contact searches on the corrected motion.
PLANT_ROUNDS = 2
#: Seconds over which a gait's detail fades out into frames without a gait (and in from
#: them): an IDLE after a TRANSITION, a MOVE to a target between MOVEs ahead.
DETAIL_FADE = 0.25
#: Share of the pose's drift that a stand's legs keep once the stand has settled
#: (:meth:`OutputMixin._stand_legs`).
STAND_LEG_SWAY = 0.25


class OutputMixin(UntangleMixin):
    """:meth:`motion` and the frame bookkeeping of :class:`~.commands.Synthesizer`."""

    @property
    def n_frames(self) -> int:
        return sum(c.X.shape[0] for c in self.chunks)

    def motion(self) -> Motion:
        """The frames so far as a motion on the first model's skeleton (root integrated),
        limbs kept from passing closer than the training takes' (:meth:`_untangled`),
        then the root carried by the feet, and limbs still too close turned apart at the
        shoulder or hip (:func:`~cyclecoord.synthesis.clearance.push_limbs_apart`)."""
        if not self.chunks:
            raise ParameterError("the script made no frames")
        return self._pushed_apart(self._plant_feet(self._untangled()))

    def _pushed_apart(self, motion: Motion) -> Motion:
        """:func:`~cyclecoord.synthesis.clearance.push_limbs_apart` against the training
        takes, said on the console."""
        from ..clearance import push_limbs_apart

        takes = [self.models[k].training_motion() for k in sorted({c.model for c in self.chunks})]
        out, pushed = push_limbs_apart(motion, takes, cache=self._plausibility,
                                       feet=self.feet_of(motion) or ())
        if pushed.line():
            self.notes.append(pushed.line())
        return out

    def _assemble(
        self, angles: np.ndarray, root: dict[str, np.ndarray], like: Motion | None = None
    ) -> Motion:
        """A motion from every frame's joint angles and root motion (root integrated);
        ``like``: an earlier assembly, which it changes on some frames (its positions
        are then found again on those only, :meth:`~cyclecoord.motion.Motion.with_frames`)."""
        from ...conventions import continuous_euler, nearest_rotations

        first = self.models[self.skeleton_model]
        T = angles.shape[0]
        angles = self._stand_legs(angles)
        turn = root["turn"][:-1]
        if self.held:
            # an IDLE stands: its heading stops turning as its ground track stops (the
            # root's turn rate of a Bandai walk's frames turned a standing body 50
            # degrees over a 2 s IDLE, pivoting the feet out of their pins)
            from ..carry import _moving

            turn = turn * _moving(self.hold_mask(T), self.fps)
        theta = np.concatenate([[0.0], np.cumsum(turn) / self.fps])
        head = heading_matrix(theta)
        step = np.zeros((T, 3))
        step[:, 0], step[:, 2] = root["velocity"][:, 0], root["velocity"][:, 1]
        world = np.einsum("tab,tb->ta", head, step) / self.fps
        pos = np.concatenate([np.zeros((1, 3)), np.cumsum(world[:-1], axis=0)])
        pos[:, 1] = root["height"]
        mats = head @ nearest_rotations(root["tilt"])  # (the tilt: a mean of rotations)
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
        if like is not None:
            return like.with_frames(frames)
        return Motion(
            frames=frames,
            channels=channels,
            fps=self.fps,
            skeleton=first.skeleton_,
            source="synthetic:latent",
        )

    def _stand_legs(self, angles: np.ndarray) -> np.ndarray:
        """``angles`` ``(T, C)`` with the legs of each IDLE at one pose (a stand; an IDLE
        moving between several poses moves its legs on purpose) held near their pose where
        it came to rest (its first frame's, or where the stop along the gait it began
        with ended: ``rests``): each leg joint's rotation keeps :data:`STAND_LEG_SWAY` of
        its turn away from that pose, easing in over the stand's first
        :data:`~cyclecoord.synthesis.carry.STAND_AFTER` s (and out over its last as
        long when frames follow).  The particle's sway moves the whole pose; in the legs
        it lifted a heel and then the foot of a standing figure (subject 35's walk model,
        a foot 10 cm up for the last second of 5 of 12 stops), which the pins, asked no
        lower than the toe end on the floor allows, held up."""
        if not self.stands:
            return angles
        from scipy.spatial.transform import Rotation

        from ...conventions import continuous_euler
        from ..carry import STAND_AFTER

        first = self.models[self.skeleton_model]
        legs = self._leg_mask(first)
        if not legs.any():
            return angles
        T = angles.shape[0]
        n = max(1, int(round(STAND_AFTER * self.fps)))
        keep = np.ones(T)
        for a, b in self.stands:
            b = min(b, T)
            if b - a < 2:
                continue
            t = np.arange(a, b)
            u = np.clip((t - a) / n, 0.0, 1.0)
            if b < T:
                u = np.minimum(u, np.clip((b - 1 - t) / n, 0.0, 1.0))
            u = smooth(u)
            keep[a:b] = np.minimum(keep[a:b], 1.0 - (1.0 - STAND_LEG_SWAY) * u)
        if np.all(keep == 1.0):
            return angles
        out = np.array(angles, dtype=float)
        cols = np.flatnonzero(legs)
        balls = [(idx, order) for idx, order in first.rotation_columns() if legs[idx].all()]
        cache = self.__dict__.setdefault("_stand_cache", {})  # (untangling poses again)
        for a, b in self.stands:
            b = min(b, T)
            if b - a < 2:
                continue
            block = out[a:b, cols]
            key = (a, b, block.tobytes())
            if key not in cache:
                k = keep[a:b, None]
                r = min(self.rests.get(a, 0), b - a - 1)  # (where the pose came to rest)
                # a joint with one or two angles: its channels eased linearly
                held = block[r] + k * (block - block[r])
                for idx, order in balls:  # a ball joint: its rotation turned
                    j = np.searchsorted(cols, idx)
                    R = Rotation.from_euler(order, block[:, j], degrees=True)
                    R0 = Rotation.from_euler(order, block[r, j], degrees=True)
                    turn = (R0.inv() * R).as_rotvec() * k
                    mats = (R0 * Rotation.from_rotvec(turn)).as_matrix()
                    held[:, j] = continuous_euler(mats[:, None], order, block[0, j])[:, 0]
                if len(cache) > 64:
                    cache.clear()
                cache[key] = held
            out[a:b, cols] = cache[key]
        return out

    def _leg_mask(self, model) -> np.ndarray:
        """Which of ``model``'s channels turn a leg (the hip joint and below), found once."""
        cache = self.__dict__.setdefault("_leg_masks", {})
        key = id(model)
        if key not in cache:
            from ...quality.generated_kinematics import leg_channels

            train = model.training_motion()
            train.positions()  # kept: the limb checks measure the takes too
            cache[key] = leg_channels(train, model.channels_)
        return cache[key]

    def _posed(
        self, pull: np.ndarray | None = None, whole: np.ndarray | None = None,
        soften: np.ndarray | None = None,
    ) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """Every frame's joint angles ``(T, C)`` and root motion, the particle's path
        smoothed; with ``pull`` ``(T,)``, frames along a gait's path moved that fraction of
        the way to the captured pose at their phase (:meth:`_untangled`), or with ``whole``
        ``(T,)`` bool to the captured frame nearest the path there; with ``soften``
        ``(T,)``, a particle's path that fraction of the way to its path smoothed by a
        Gaussian of :data:`~.untangle.POP_SOFTEN` seconds (:meth:`_softened`).

        Each run of consecutive particle chunks of one model (MOVEs, IDLEs) is posed again
        from its latent path smoothed by a Gaussian of ``params.smooth`` seconds
        (:class:`~.particle.ParticleParams`). Where the run meets a blend or a played
        capture the smoothing fades out over three widths, so the run's first and last
        frames stay those the blend or the capture joins. Blends and played captures are
        kept. The joint-limit easing counted in the report is the unsmoothed path's.
        """
        from scipy.ndimage import gaussian_filter1d

        keys = ("height", "velocity", "turn", "tilt")
        chunks = self.chunks
        angles = [c.angles for c in chunks]
        roots = [c.root for c in chunks]
        sigma = self.params.smooth * self.fps
        i = 0
        while i < len(chunks):
            if not chunks[i].particle:
                i += 1
                continue
            j = i
            while (
                j + 1 < len(chunks)
                and chunks[j + 1].particle
                and chunks[j + 1].model == chunks[i].model
            ):
                j += 1
            X = np.concatenate([c.X for c in chunks[i : j + 1]])
            if sigma <= 0 or X.shape[0] < 3:
                i = j + 1
                continue
            k = np.arange(X.shape[0], dtype=float)
            fade = max(3.0 * sigma, 1.0)
            u = np.ones_like(k)
            if i > 0:  # joins the chunk before: its first frame kept
                u = np.minimum(u, k / fade)
            if j + 1 < len(chunks):  # and the chunk after: its last frame kept
                u = np.minimum(u, (k[-1] - k) / fade)
            u = np.clip(u, 0.0, 1.0)
            w = smooth(u)
            Xs = X + w[:, None] * (gaussian_filter1d(X, sigma, axis=0, mode="nearest") - X)
            if soften is not None:
                a0 = sum(c.X.shape[0] for c in chunks[:i])
                s = w * soften[a0 : a0 + X.shape[0]]
                if s.any():
                    wide = gaussian_filter1d(X, POP_SOFTEN * self.fps, axis=0, mode="nearest")
                    Xs = Xs + s[:, None] * (wide - Xs)
            m = self.models[chunks[i].model]
            P, R = m.pose(Xs), self._root(m, Xs)
            edges = np.cumsum([0] + [c.X.shape[0] for c in chunks[i : j + 1]])
            for c, a, b in zip(chunks[i : j + 1], edges[:-1], edges[1:]):
                if c.detail is not None:
                    P[a:b] += c.detail["angles"]
                    for key in keys:
                        R[key][a:b] += c.detail[key]
            A = self._clip(chunks[i].model, P, count=False)
            for n, (a, b) in enumerate(zip(edges[:-1], edges[1:])):
                angles[i + n] = A[a:b]
                roots[i + n] = {key: R[key][a:b] for key in keys}
                if chunks[i + n].pace is not None:  # (travel at the chunk's pace)
                    roots[i + n] = paced_root(roots[i + n], chunks[i + n].pace)
            i = j + 1
        angles, roots = self._fade_detail(angles, roots)
        if pull is not None:
            start, anchors = 0, self._idle_anchors()
            for n, c in enumerate(chunks):
                stop = start + c.X.shape[0]
                if pull[start:stop].any() and (c.targets is not None or c.path is not None
                                               or n in anchors):
                    mask = None if whole is None else whole[start:stop]
                    target = self._untangle_target(c, mask, anchors.get(n))
                    g = pull[start:stop, None]
                    angles[n] = angles[n] + g * (target - angles[n])
                start = stop
        # each chunk's angles are in its model's chart: the rig's channels, continuous
        angles = [self.models[c.model].to_channels(a) for c, a in zip(chunks, angles)]
        return self._continuous(np.concatenate(angles)), {
            key: np.concatenate([r[key] for r in roots]) for key in keys
        }

    def _fade_detail(self, angles: list, roots: list) -> tuple[list, list]:
        """Each chunk's angles and root motion with the gait detail of the nearest frames
        that have it (within :data:`DETAIL_FADE` seconds, of the same model) added to
        frames that have none, held at its value there and fading out as a smoothstep of
        the distance, so a gait's frames meet an IDLE or a MOVE to a target without a
        step."""
        F = int(round(DETAIL_FADE * self.fps))
        chunks = self.chunks
        sizes = [c.X.shape[0] for c in chunks]
        has = np.repeat([c.detail is not None for c in chunks], sizes)
        if F < 1 or has.all() or not has.any():
            return angles, roots
        which = np.repeat(np.arange(len(chunks)), sizes)
        local = np.concatenate([np.arange(n) for n in sizes])
        src = np.flatnonzero(has)
        angles = [a.copy() for a in angles]
        roots = [{k: v.copy() for k, v in r.items()} for r in roots]
        for t in np.flatnonzero(~has):
            c = which[t]
            k = np.searchsorted(src, t)
            near = []  # (weight, detail, its frame) of the nearest detailed frame each side
            for f in (src[k - 1] if k > 0 else None, src[k] if k < src.size else None):
                if f is None or abs(f - t) > F or chunks[which[f]].model != chunks[c].model:
                    continue
                u = 1.0 - abs(f - t) / (F + 1.0)
                near.append((smooth(u), chunks[which[f]].detail, local[f]))
            if not near:
                continue
            # a short stretch between two gait runs takes a mix of their details, never
            # both in full (a one-frame MOVE between a TRANSITION and a MOVE ahead had the
            # detail added twice: its joints accelerated 3.6x the run's p99)
            scale = max(w for w, _, _ in near) / sum(w for w, _, _ in near)
            for w, d, f in near:
                angles[c][local[t]] += scale * w * d["angles"][f]
                for key in roots[c]:
                    roots[c][key][local[t]] += scale * w * d[key][f]
        return angles, roots

    def _continuous(self, angles: np.ndarray) -> np.ndarray:
        """The Euler channels ``(T, C)`` of every joint a model charts about its mean
        rotation made continuous over the frames (the first nearest the first model's
        first training frame); the other channels as they are."""
        import warnings

        from scipy.spatial.transform import Rotation

        from ...conventions import continuous_euler

        first = self.models[self.skeleton_model]
        joints = {}
        for name in dict.fromkeys(c.model for c in self.chunks):
            for idx, order, _ in self.models[name].chart():
                joints[tuple(int(i) for i in idx)] = order
        if not joints:
            return angles
        out = np.array(angles, dtype=float)
        start = first._centred(first._channels0()[None])[0]
        for idx, order in joints.items():
            cols = list(idx)
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message=".*[Gg]imbal.*")
                R = Rotation.from_euler(order, out[:, cols], degrees=True).as_matrix()
            out[:, cols] = continuous_euler(R[:, None], order, start[cols])[:, 0]
        return out

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
                weight = np.maximum(weight, smooth(u))
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

        from ..footlock import pin_feet

        # what the root cannot keep still (two planted feet whose stance the blend
        # changes), a small leg IK pins: contacts inside the spans only
        span = np.r_[mask, False] | np.r_[False, mask]
        contacts = foot_contacts(out, feet, min_duration=LOCK_MIN_CONTACT)
        contacts = replace(contacts, planted=contacts.planted & span[:, None])
        if not contacts.planted.any():
            return out
        return pin_feet(out, contacts, blend=LOCK_BLEND)

    def feet_of(self, motion: Motion) -> tuple[str, ...] | None:
        """The feet named (``feet``), else those :func:`~cyclecoord.quality.legs.find_feet`
        finds on the first motion asked, kept for the script's later steps (planting,
        locking, the report: finding them took some 3 ms a time, asked five times a
        script); None when none are found (each step then says why)."""
        from ...errors import CycleCoordError
        from ...quality.legs import find_feet

        if self.feet is not None:
            return self.feet
        if not self._feet_found:
            try:
                self._feet_found.append(find_feet(motion.skeleton, motion))
            except CycleCoordError:
                self._feet_found.append(None)
        return self._feet_found[0]

    def hold_mask(self, n_frames: int, asked: bool = False) -> np.ndarray:
        """(T,) frames an IDLE command made; with ``asked``, also those of TRANSITIONs
        crossed standing (``stood``: the stillness the script asked for, which the
        freeze measure does not count)."""
        hold = np.zeros(n_frames, dtype=bool)
        for a, b in self.held + (self.stood if asked else []):
            hold[a:b] = True
        return hold

    def _carry(self, motion: Motion) -> Motion:
        """``plant="all"``: the root carried by the feet everywhere, IDLE standing, no
        foot under the floor, the feet pinned where that makes no pop."""
        from ...errors import CycleCoordError
        from ...quality.contacts import foot_contacts
        from ..carry import carry_by_feet, channel_bounds, lock_where_clean

        used = sorted({c.model for c in self.chunks})
        feet = self.feet_of(motion)
        try:
            floor = float(
                np.median(
                    [foot_contacts(self.models[k].training_motion(), feet).floor for k in used]
                )
            )
        except CycleCoordError:
            floor = None
        out = carry_by_feet(
            motion,
            feet,
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
            limit = 1.5 * self._frame_acc99(motion.n_frames)
            takes = [self.models[k].training_motion() for k in used]
            locked = lock_where_clean(
                out,
                limit,
                feet,
                bounds=channel_bounds(takes),
                hold=self.hold_mask(motion.n_frames),
                floor=floor,
                blend=self._lock_ease(used),
                references=takes,
                plausibility_cache=self._plausibility,
                analysed=True,  # a model's output and takes are in their analysis rig
            )
            self.notes.append(locked.line)
            out = locked.motion
            if self.stands and feet is not None:
                from ..stance import close_stands

                done = close_stands(
                    out, feet, self.stands, cycle=self._cycle_at(self.stands[0][0]),
                    bounds=channel_bounds(takes), references=takes,
                    plausibility_cache=self._plausibility, analysed=True, limit=limit,
                )
                if done.line:
                    self.notes.append(done.line)
                self.stand_steps = done.to_dict()
                out = done.motion
        return out

    def _cycle_at(self, frame: int) -> float:
        """The leg cycle (s) of the model that made the frame before ``frame`` (nan
        without a gait)."""
        start = 0
        name = self.chunks[0].model
        for c in self.chunks:
            if start >= frame:
                break
            name, start = c.model, start + c.X.shape[0]
        g = self.gait(name)
        if not len(g.usable):
            return float("nan")
        return float(np.median(g.period[g.usable])) / self.models[name].fps_

    def _frame_acc99(self, n_frames: int) -> np.ndarray:
        """(T,) the training 99th percentile of joint acceleration of the model that posed
        each frame (:meth:`_lock_acc99`); a TRANSITION's frames (its approach and blend)
        the largest of the models on its route, and a frame next to another's the smaller
        of the two (as the report's figures judge each command's frames with their
        neighbours).  One figure for the whole script (the largest model's) let the locks
        of a walk pop at 2.0x the walk's own 99th percentile on subject 35's walk + jog
        script: 1.5x the jog's was within the limit.  The larger of two models for 0.2 s
        either side of a change of model let a jog's pins pop at 1.59x its own 99th
        percentile five frames before a TRANSITION to the walk (whose is 1.35x the
        jog's): the report judges those frames as the jog's."""
        from scipy.ndimage import minimum_filter1d

        routes = {e["command"]: e.get("route", e["transition"])
                  for e in self.events if "transition" in e}
        per = np.concatenate([
            np.full(c.X.shape[0], max(self._lock_acc99(k)
                                      for k in {c.model, *routes.get(c.command, ())}))
            for c in self.chunks] or [[0.0]])
        if per.size != n_frames:  # not the chunks' frames: one figure, the largest
            return np.full(n_frames, float(per.max()))
        return minimum_filter1d(per, size=3, mode="nearest")

    def _lock_ease(self, names) -> float:
        """Seconds a foot pin eases in and out: :data:`LOCK_BLEND`, or a tenth of the
        quickest leg cycle among the models ``names`` when that is shorter.  A run's
        stance at 30 fps is 5-7 frames; eased over 3 frames each way, most of the Bandai
        run's pins popped and came off (slip 1.56x its capture's; 1.37x over 2 frames)."""
        ease = LOCK_BLEND
        for k in names:
            g = self.gait(k)
            if len(g.usable):
                cycle = float(np.median(g.period[g.usable])) / self.models[k].fps_
                ease = min(ease, cycle / 10.0)
        return ease

    def _lock_acc99(self, name: str) -> float:
        """99th percentile of the largest root-relative joint acceleration per training
        frame of model ``name`` (units/s^2), measured as
        :func:`~cyclecoord.synthesis.carry.lock_where_clean` measures the motion it pins:
        world-oriented, root at the origin.  The pelvis-frame figure of
        :meth:`_acc99` (which the blends' budget uses) reads the pelvis's own sway as
        the limbs' acceleration: 1.56x this one on the Bandai run, so locks passed at
        2.3x the training 99th percentile."""
        key = ("lock", name)
        if key not in self._acc:
            from ..carry import _joint_accel

            m = self.models[name]
            train = m.training_motion()
            p = train.positions().positions  # (every frame's points: one pass for all takes)
            acc = [
                _joint_accel(p[rows[0] : rows[-1] + 1], train.fps)[1:-1]
                for s in np.unique(m.segments_)
                if (rows := np.flatnonzero(m.segments_ == s)).size > 2
            ]
            # (a model sized to the output skeleton moves its joints that much more or less)
            self._acc[key] = float(np.percentile(np.concatenate(acc), 99)) * self.sizes.get(
                name, 1.0)
        return self._acc[key]

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


