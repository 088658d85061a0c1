"""Stepping at the training takes' cadence: MOVEs ahead along a gait and TRANSITIONs
between two gaits in step, a part of :class:`~.commands.Synthesizer`.

* ``{"ahead": seconds}`` targets: the training frames ``seconds`` further along the
  particle's gait, reached along them at the pace they were captured at (wrapping by
  whole cycles at a segment's end, :class:`~.gait.Gait`), so chained MOVEs step at the
  captured cadence and with the captured stride.
* :meth:`GaitMixin.gait_hop`: a TRANSITION between two models with a gait starts at once
  (no approach MOVE, no bridge search): the other model's frame at the same gait phase
  (nearest in pose among those) is taken, both models keep stepping with one shared
  phase whose rate eases from the first model's cadence to the second's, and their
  poses and root motions blend.  The walk-run crossings of the issue's shared-data
  models were all 2.35-2.58x the bridge threshold apart: the idle blend there stood
  still for the length of the blend; in step, the legs never stop.
"""

from __future__ import annotations

import functools
from typing import Any, Callable

import numpy as np

from ..._words import plural
from ...errors import ParameterError
from .crossing import BLEND_ACCELERATION, blend_asked
from .easing import carried, mix_rows, smooth, smootherstep
from .gait import FADE_TIE, SEAM_FADES, Gait, choose_seam_fade
from .influence import pose_points

__all__ = ["FADE_TIE", "GaitMixin", "HOP_ACCELERATION", "IN_STEP_LONGEST", "SEAM_FADES"]

#: An in-step blend is raised (and said) up to this many seconds at most, so the
#: TRANSITION completes within a second of the command.
IN_STEP_LONGEST = 1.0
#: An in-step blend whose frames accelerate a joint over this many times the faster
#: model's training 99th percentile is lengthened (:meth:`GaitMixin.gait_hop`).
HOP_ACCELERATION = 1.5
#: Seconds over which the particle's own velocity off the gait's path dies away at the
#: start of an in-step blend
CARRY_SECONDS = 0.15
#: A MOVE ahead that stops looks for a stance (both feet down) on a phase grid of this
#: many bins (:meth:`GaitMixin.stop_ahead`).
STANCE_BINS = 50
#: Between two training frames of a gait, the GP mean at the mix of their latent points
#: this far (median frame steps) from the mix of their GP means starts being replaced by
#: the latter, wholly from :data:`GAP_FULL` (:meth:`GaitMixin._detail_at`).
GAP_FROM = 0.25
GAP_FULL = 0.5


class GaitMixin:
    """Gaits, the gait cursor and the in-step TRANSITION of a Synthesizer."""

    def gait(self, name: str) -> Gait:
        """The :class:`~.gait.Gait` of model ``name`` (from the model file, else computed)."""
        if name not in self._gaits:
            self._gaits[name] = self.models[name].gait()
        return self._gaits[name]

    def gait_at(self, name: str, values: np.ndarray, segment: int, u: np.ndarray) -> np.ndarray:
        """Model ``name``'s per-frame ``values`` at unwrapped phases ``u`` of ``segment``,
        looped at the seam of its captured angles with the segment's own cross-fade
        (:meth:`seam_fade`)."""
        return self.gait_sampler(name, segment, u)(values)

    def gait_sampler(
        self, name: str, segment: int, u: np.ndarray
    ) -> Callable[[np.ndarray], np.ndarray]:
        """:meth:`gait_at` at phases ``u`` as a function of the values (the frames found
        once for the several arrays a step samples)."""
        return self.gait(name).sampler(segment, u, fade=self.seam_fade(name, segment),
                                       seam=self.models[name].frame_angles())

    def seam_fade(self, name: str, segment: int) -> float:
        """The cross-fade over the seam of ``segment``'s loop (cycles): the one the model
        chose when it was fitted (:func:`~.gait.choose_seam_fade`), else chosen now."""
        key = (name, segment)
        if key not in self._fades:
            g = self.gait(name)
            self._fades[key] = (
                float(g.fade[segment]) if g.fade is not None
                else choose_seam_fade(self.models[name], g, segment)
            )
        return self._fades[key]

    def _gait_place(self, name: str) -> tuple[int, float] | None:
        """``(segment, unwrapped phase)`` of the particle in model ``name``'s gait: the
        cursor the last stepping command left, else the nearest training frame on a
        segment with a gait; None when the model has none."""
        g = self.gait(name)
        if not len(g.usable):
            return None
        if self._cursor is not None and self._cursor[0] == name:
            return self._cursor[1], self._cursor[2]
        m = self.models[name]
        ok = np.isin(g.segments, g.usable) & np.isfinite(g.phase)
        d = ((m.X_ - self.x) ** 2).sum(1)
        d[~ok] = np.inf
        k = int(np.argmin(d))
        return int(g.segments[k]), float(g.phase[k])

    def _rate(self, name: str, segment: int) -> float:
        """Gait cycles per output frame at the training cadence."""
        m = self.models[name]
        return m.fps_ / (self.gait(name).period[segment] * self.fps)

    def ahead_path(self, seconds: Any) -> tuple[np.ndarray, np.ndarray] | None:
        """``{"ahead": seconds}``: the latent path ``(M, q)`` and its times ``(M,)`` along
        the particle's gait (None when the model has no gait: the caller steps through the
        segment's frames instead)."""
        if not (isinstance(seconds, (int, float)) and not isinstance(seconds, bool)):
            raise ParameterError(f"ahead must be a number of seconds, got {seconds!r}")
        if seconds <= 0:
            raise ParameterError(f"ahead must be positive seconds, got {seconds!r}")
        place = self._gait_place(self.current)
        if place is None:
            return None
        seg, u0 = place
        m = self.models[self.current]
        n = max(1, int(round(seconds * self.fps)))
        u = u0 + self._rate(self.current, seg) * np.arange(n + 1)
        at = self.gait_sampler(self.current, seg, u)
        X = at(m.X_)
        self._next_cursor = (self.current, seg, float(u[-1]))
        self._path_detail = self._detail_at(self.current, seg, u, at)
        cursor = self._cursor
        if cursor is not None and cursor[0] == self.current and len(cursor) > 3:
            # after a MOVE to a frame (:meth:`step_to`), which ended on the frame where
            # the loop passes its phase elsewhere: the path's offset from the loop fades
            # out over half a cycle rather than in a frame
            f = min(n, max(1, int(round(0.5 / self._rate(self.current, seg)))))
            w = np.ones(n + 1)
            w[: f + 1] = np.concatenate([[0.0], smootherstep(f - 1), [1.0]])
            X = X + (1.0 - w)[:, None] * cursor[3]
        X[0] = self.x
        return X, np.arange(n + 1) / self.fps

    def _detail_at(self, name: str, segment: int, u: np.ndarray, at=None) -> dict | None:
        """Model ``name``'s gait detail (:meth:`~.model.LatentModel.detail`, each part
        ``(len(u), ...)``) at unwrapped phases ``u`` of ``segment`` (None when the
        synthesizer adds none); ``at``: :meth:`gait_sampler` of those phases, if made."""
        if not self.detail:
            return None
        m = self.models[name]
        at = self.gait_sampler(name, segment, u) if at is None else at
        out = {k: at(v) for k, v in m.detail().items()}
        # Between two training frames the path's latent point is their latents' mix.
        # Where the GPLVM put consecutive frames far apart (the Xsens walk at 16.41 s:
        # 3x its neighbours' latent step), the GP mean there is no pose between theirs
        # (1.9 median frame steps off the mix of their GP means; 0.04 at the median
        # frame, 0.13 at the 90th percentile) and the toe end accelerated 2.5x the
        # take's p99 in one frame.  There the detail is taken against the GP mean at
        # the path's own points, so pose plus detail is the mix of the captured frames.
        # Not everywhere: elsewhere the GP mean's curve between frames keeps a stride's
        # peaks, which the frames' chord cuts (knee ranges 0.02-0.04 lower over the
        # benchmark's script seeds; a Catmull-Rom mix kept them but accelerated more).
        X = at(m.X_)
        detail = m.detail()
        means = m.frame_angles() - detail["angles"]  # the GP mean at each training frame
        off = at(means) - m.pose(X)
        a = np.clip((np.sqrt((off**2).mean(axis=1)) / self._frame_step(name, means) - GAP_FROM)
                    / (GAP_FULL - GAP_FROM), 0.0, 1.0)
        w = smooth(a)
        if not w.any():
            return out
        out["angles"] = out["angles"] + w[:, None] * off
        for key, value in self._root(m, X).items():
            # the root weights at each training frame's latent point: raw minus detail
            at_frames = getattr(m.root_, key) - detail[key]
            mixed = at(at_frames)
            out[key] = out[key] + w.reshape((-1,) + (1,) * (value.ndim - 1)) * (mixed - value)
        return out

    def _frame_step(self, name: str, means: np.ndarray) -> float:
        """Model ``name``'s median RMS step of ``means`` (the GP mean at its training
        frames) between consecutive frames of a gait."""
        if name not in self._frame_steps:
            g = self.gait(name)
            steps = [np.sqrt((np.diff(means[g.rows(s)], axis=0) ** 2).mean(axis=1))
                     for s in g.usable]
            steps = np.concatenate([x for x in steps if x.size] or [np.ones(1)])
            self._frame_steps[name] = max(float(np.median(steps)), 1e-9)
        return self._frame_steps[name]

    def segment_ahead(self, seconds: float) -> tuple[np.ndarray, np.ndarray]:
        """``{"ahead": seconds}`` on a model without a gait: along the nearest training
        frame's segment at its captured pace, up to the segment's end."""
        m = self.models[self.current]
        k = int(m.nearest_frame(self.x[None])[0])
        rows = np.flatnonzero(m.segments_ == m.segments_[k])
        t0 = float(m.times_[k])
        end = float(m.times_[rows[-1]])
        if t0 + seconds > end + 1e-9:
            raise ParameterError(
                f"ahead {seconds:g} s runs past the end of segment "
                f"{m.segment_names_[int(m.segments_[k])]!r} ({end - t0:.2f} s left) and the "
                "model has no gait phase to go on stepping"
            )
        n = max(1, int(round(seconds * self.fps)))
        t = t0 + np.arange(n + 1) / self.fps
        X = np.stack([np.interp(t, m.times_[rows], m.X_[rows, j]) for j in range(m.X_.shape[1])], 1)
        X[0] = self.x
        self._path_detail = (
            {k: interp_rows(t, m.times_[rows], v[rows]) for k, v in m.detail().items()}
            if self.detail
            else None
        )
        return X, t - t0

    def step_to(self, goal: np.ndarray, from_rest: bool = False, across: bool = True
                ) -> tuple[np.ndarray, np.ndarray] | None:
        """A MOVE (along a line or the graph) to latent point ``goal`` from a gait the particle is
        stepping along (the last command stepped): the latent path ``(M, q)`` and its
        times ``(M,)``, stepping on at the training cadence to the gait phase of the
        training frame nearest ``goal``, at least as long as the line takes at the
        model's latent speed, the latent offset from the gait easing from the particle's
        to the goal's, and from the particle's segment to the goal's; None where the
        particle is not stepping or the goal's frame has no gait phase (the path asked
        then).  ``from_rest``: also from a particle at rest whose nearest training frame
        has a gait phase, its steps easing in from there (with ``across`` false, only
        to a frame of the same take: from rest, the latent paths of two takes' loops
        blended over a third of a second threw a subject 35 walk's toes 2.4x its p99).

        Played as a line, such a MOVE put the goal's phase of the stride after the phase
        the legs were at: on a random subject 35 script a one-frame MOVE to frame 34
        between a TRANSITION and a MOVE ahead swapped the legs in a frame and the toes
        accelerated 2.0x the run's 99th percentile."""
        name = self.current
        m, g = self.models[name], self.gait(name)
        stepping = self._cursor is not None and self._cursor[0] == name
        if stepping:
            s0, u0 = self._cursor[1], self._cursor[2]
            # from the path the particle was riding (the loop, or a MOVE to a frame's
            # offset from it), not from the particle, which lags it: offset by the
            # particle's lag, the path stepped back at its first frame and the captured
            # pose there jerked (a Bandai run's MOVE ahead into a MOVE to a frame read
            # 1.59x its p99 there, 1.42x from the loop)
            off = self._cursor[3] if len(self._cursor) > 3 else np.zeros_like(goal)
        elif from_rest and self._at_rest_on_gait(name):
            # from rest at a pose of the gait (the start frame, an IDLE's): the steps ease
            # in from its phase.  Along the graph's training frames, a MOVE from a run's
            # frame 33 to its frame 21 played the run backwards while the root went
            # forward: the feet slid 5.4 m/s
            s0, u0 = self._gait_place(name)
            off = self.x - self.gait_at(name, m.X_, s0, np.array([u0]))[0]
        else:
            return None
        k = int(m.nearest_frame(goal[None])[0])
        s1 = int(g.segments[k])
        if s1 not in g.usable or not np.isfinite(g.phase[k]):
            return None
        if s0 != s1 and not (across or stepping):
            return None
        rate = self._rate(name, s1)
        line = float(np.linalg.norm(goal - self.x)) / m.speed_ * self.fps * rate  # cycles
        du = (float(g.phase[k]) - u0) % 1.0
        du += max(0.0, float(np.ceil(line - du)))
        n = max(1, int(round(du / rate)))
        u = u0 + du * np.arange(n + 1) / n
        w = np.concatenate([[0.0], smootherstep(n - 1), [1.0]])[:, None]
        at = self.gait_sampler(name, s1, u)
        X, detail = at(m.X_), self._detail_at(name, s1, u, at)
        if s0 != s1:  # from the particle's segment to the goal's, in step
            at0 = self.gait_sampler(name, s0, u)
            X = (1.0 - w) * at0(m.X_) + w * X
            if detail is not None:
                d0 = self._detail_at(name, s0, u, at0)
                detail = {key: mix_rows(d0[key], v, w) for key, v in detail.items()}
        self._next_cursor = (name, s1, float(u[-1]), goal - X[-1])
        X = X + (1.0 - w) * off + w * (goal - X[-1])
        X[0] = self.x
        self._path_detail = detail
        return X, np.arange(n + 1) / self.fps

    def _at_rest_on_gait(self, name: str) -> bool:
        """Whether the particle is at rest (under a quarter of model ``name``'s median
        latent speed) and its nearest training frame has a gait phase."""
        m, g = self.models[name], self.gait(name)
        if self.v is not None and np.linalg.norm(self.v) >= 0.25 * m.speed_:
            return False
        k = int(m.nearest_frame(self.x[None])[0])
        return bool(np.isin(g.segments[k], g.usable) and np.isfinite(g.phase[k]))

    def stance(self, name: str) -> np.ndarray | None:
        """(N,) per training frame of model ``name``: the higher of its legs' lowest foot
        points above their contact level (0 where every leg has a foot down); None when
        the feet are not found."""
        if name not in self._stances:
            from ...errors import CycleCoordError
            from ...quality.contacts import foot_contacts

            train = self.models[name].training_motion()
            try:
                c = foot_contacts(train, self.feet_of(train))
            except (CycleCoordError, TypeError):
                self._stances[name] = None
            else:
                labels = np.array(c.leg_labels)
                legs = [c.height[:, labels == g].min(axis=1) for g in dict.fromkeys(labels)]
                self._stances[name] = np.max(legs, axis=0)
        return self._stances[name]

    def _stance_profile(self, name: str, segment: int) -> tuple[np.ndarray, float] | None:
        """Model ``name``'s :meth:`stance` over ``segment``'s gait, median per phase bin
        (:data:`STANCE_BINS`), and the level a stance must reach: the fifth of the
        segment's frames where the feet are lowest (a walk's double support)."""
        stance = self.stance(name)
        if stance is None:
            return None
        g = self.gait(name)
        rows = g.rows(segment)
        if not rows.size:
            return None
        ph, st = g.phase[rows] % 1.0, stance[rows]
        which = np.minimum((ph * STANCE_BINS).astype(int), STANCE_BINS - 1)
        prof = np.full(STANCE_BINS, np.inf)
        for b in np.unique(which):
            prof[b] = np.median(st[which == b])
        return prof, float(np.percentile(st, 20))

    def _stance_ahead(self, place: tuple[int, float], lo: float, hi: float,
                      nominal: float) -> float | None:
        """Cycles ahead of ``place`` (the particle's ``(segment, phase)`` on its gait),
        within ``lo .. hi``, where both feet are down (:meth:`_stance_profile`): the
        stance nearest ``nominal``, at its lowest bin; None where no such stance is in
        reach."""
        seg, u0 = place
        got = self._stance_profile(self.current, seg)
        if got is None:
            return None
        prof, level = got
        ahead = np.arange(lo, hi + 1e-9, 1.0 / STANCE_BINS)
        if not ahead.size:
            return None
        at = prof[np.minimum(((u0 + ahead) % 1.0 * STANCE_BINS).astype(int), STANCE_BINS - 1)]
        low = at <= level
        if not low.any():
            return None
        k = int(np.argmin(np.where(low, np.abs(ahead - nominal), np.inf)))
        for step in (1, -1):  # to the lowest bin of that stance
            while 0 <= k + step < ahead.size and low[k + step] and at[k + step] < at[k]:
                k += step
        return float(ahead[k])

    def stop_ahead(self, seconds: float) -> float:
        """``{"ahead": seconds}`` that comes to a stop: the seconds to the stance (both
        feet down, :meth:`_stance_ahead`) nearest the asked end, within a quarter of a
        cycle, so the particle stops on two feet, not mid-swing (on a run, which has no
        double support, where the higher leg is lowest); ``seconds`` where the model has
        no gait.  Stopped where the seconds ran out, a walk stood on one leg, the other
        bent back and lifted up to 14 cm for the whole IDLE after it: of 12 stops (MOVE
        ahead 1.0-1.77 s, IDLE 2 s) along the Bandai, subject 35 and synthetic walks,
        3, 8 and 11 had a leg over 5 cm up over the IDLE's last 1.2 s; 1, 0 and 4 with
        this and the stand's feet kept down (:func:`~..carry.lock_where_clean`)."""
        place = self._gait_place(self.current)
        if (place is None or isinstance(seconds, bool) or not isinstance(seconds, (int, float))
                or not seconds > 0):
            return seconds
        rate = self._rate(self.current, place[0])  # cycles per output frame
        nominal = float(seconds) * self.fps * rate
        # the stop's ease covers half its ramp at the cadence: no stop nearer than that
        least = max(0.5 * self.ease * self.fps * rate, rate)
        got = self._stance_ahead(place, max(least, nominal - 0.25), nominal + 0.25, nominal)
        return seconds if got is None else got / rate / self.fps

    def can_step_across(self, src: str, to: str) -> bool:
        """Whether a TRANSITION from ``src`` to ``to`` can go in step (both have a gait)."""
        return bool(len(self.gait(src).usable) and len(self.gait(to).usable))

    def _matched(self, src: str, to: str, u0: float, x: np.ndarray) -> tuple[int, float, float]:
        """The training frame of ``to`` at gait phase ``u0`` whose pose is nearest ``x``'s
        pose in ``src``: (segment, its unwrapped phase, RMS pose distance; the first of
        equals).  Every candidate is posed in one pass (one at a time they were a tenth
        of a script's time)."""
        m1, m2, g2 = self.models[src], self.models[to], self.gait(to)
        cands = []  # (segment, phase, latent point)
        for s in g2.usable:
            ph = g2.phase[g2.rows(s)]
            # the frames of this segment at phase u0 + whole cycles
            cycles = np.arange(np.ceil(ph[0] - u0), np.floor(ph[-1] - u0) + 1)
            if cycles.size:
                X2 = self.gait_at(to, m2.X_, s, u0 + cycles)
                cands += [(int(s), float(u0 + c), X2[k]) for k, c in enumerate(cycles)]
        if not cands:
            raise ParameterError(f"no frame of {to!r} at gait phase {u0 % 1:.2f}")
        angles = np.vstack([m1.to_channels(m1.pose(x[None])),
                            m2.to_channels(m2.pose(np.array([c[2] for c in cands])))])
        p = pose_points(angles, m1.channels_, m1.skeleton_)
        d = np.sqrt(((p[1:] - p[0]) ** 2).sum(-1).mean(-1))
        k = int(np.argmin(d))
        return cands[k][0], cands[k][1], float(d[k])

    def gait_hop(self, src: str, to: str, blend: float) -> None:
        """TRANSITION from ``src`` into ``to`` in step (see the module's text)."""
        m1, m2 = self.models[src], self.models[to]
        sa, ua = self._gait_place(src)
        sb, ub, dist = self._matched(src, to, ua, self.x)
        asked = blend_asked(blend, self.fps)
        x2 = self.gait_at(to, m2.X_, sb, np.array([ub]))[0]
        need = min(self.blend_frames(src, to, self.x, x2), int(IN_STEP_LONGEST * self.fps))
        n = max(asked, need)
        if n != asked:
            self.notes.append(
                f"commands[{self.command}] TRANSITION {src} -> {to}: blend raised from "
                f"{blend:g} s ({plural(asked, 'frame')}) to {n / self.fps:.2f} s ({n} frames): "
                "blending "
                f"poses {dist:.3g} units apart faster would accelerate joints over "
                f"{BLEND_ACCELERATION:g}x the models' training 99th percentile"
            )
        # the blended frames measured: changing cadence, stride and lean at once, a blend
        # the poses' distance allowed still popped (a Bandai walk -> run over 0.31 s: the
        # hands at 1.67x the run's 99th percentile)
        n0, longest = n, max(n, int(IN_STEP_LONGEST * self.fps))
        hop = self._in_step(src, to, (sa, ua), (sb, ub), n, count=False)
        tried = [(self._hop_peak(src, to, hop["blended"], hop["root"]), n, hop)]
        while tried[-1][0] > HOP_ACCELERATION and n < longest:
            n = min(longest, n + max(1, n // 4))
            hop = self._in_step(src, to, (sa, ua), (sb, ub), n, count=False)
            tried.append((self._hop_peak(src, to, hop["blended"], hop["root"]), n, hop))
        # the shortest under the limit, else the one that accelerates least
        peak, n, hop = min(tried, key=lambda t: (t[0] > HOP_ACCELERATION,
                                                  t[1] if t[0] <= HOP_ACCELERATION else t[0]))
        if n != n0:
            was = f"{blend:g}" if n0 == asked else f"{n0 / self.fps:.2f}"
            self.notes.append(
                f"commands[{self.command}] TRANSITION {src} -> {to}: blend raised from "
                f"{was} s ({plural(n0, 'frame')}) to {n / self.fps:.2f} s "
                f"({n} frames): over {n0} frames its joints accelerated {tried[0][0]:.2f}x "
                f"the faster model's training 99th percentile (limit {HOP_ACCELERATION:g}x; "
                f"{peak:.2f}x now)"
            )
        self._clip(src, hop["Pa"])  # (counted once, on the frames kept)
        self._clip(to, hop["Pb"])
        w, du, Xb, blended = hop["w"], hop["du"], hop["Xb"], hop["blended"]
        root, detail, on_path, Pb, Da = (hop[k] for k in ("root", "detail", "on_path", "Pb", "Da"))
        self._emit(to, Xb, blended, root, clip=False, detail=detail,
                   targets=functools.cache(
                       functools.partial(self._hop_targets, src, to, on_path, Xb, Pb, Da, w)))
        c = self.crossings_threshold(src)
        self.events.append(
            {
                "command": self.command,
                "transition": [src, to],
                "route": [src, to],
                "in_step": True,
                "phase": float(ua % 1.0),
                "bridge_frame": int(m1.nearest_frame(self.x[None])[0]),
                "target_frame": int(m2.nearest_frame(Xb[:1])[0]),
                "bridge_distance": dist,
                "threshold": c,
                "under_threshold": bool(dist < c),
                "bridges": 0,
                "blend_frames": n,
                "blend_asked_frames": asked,
                "start_frame": self.n_frames - n,
            }
        )
        self.current, self.x = to, Xb[-1]
        self.v = (Xb[-1] - Xb[-2]) * self.fps if n > 1 else np.zeros_like(self.x)
        self._cursor = (to, sb, float(ub + du[-1]))
        self._stepping = True

    def _in_step(self, src: str, to: str, place_a: tuple[int, float],
                 place_b: tuple[int, float], n: int, count: bool = True) -> dict:
        """The frames of an in-step blend of ``n`` frames from ``src`` at ``place_a`` (its
        segment and unwrapped phase) into ``to`` at ``place_b``: paths, root motion,
        detail, the two gaits' poses and their blend (``to``'s chart)."""
        m1, m2 = self.models[src], self.models[to]
        (sa, ua), (sb, ub) = place_a, place_b
        w = smootherstep(n)
        ra, rb = self._rate(src, sa), self._rate(to, sb)
        steps = (1.0 - w) * ra + w * rb
        du = np.concatenate([[0.0], np.cumsum(steps)])[1:]
        at_a, at_b = self.gait_sampler(src, sa, ua + du), self.gait_sampler(to, sb, ub + du)
        Xa = at_a(m1.X_)
        # the particle's stray from the path fades over the blend: jumping back onto the
        # path at the blend's first frame threw the Bandai run's hands up to 1.86x its
        # p99 of acceleration (6 script seeds in 15 over 1.5x; at most 1.40x after)
        here = self.gait_at(src, m1.X_, sa, np.array([ua]))[0]
        stray = self.x - here
        on_path = Xa
        Xa = Xa + (1.0 - w)[:, None] * stray[None, :]
        if self.v is not None:
            # ... at the rate the particle was straying: its velocity carries on into the
            # blend (faded from rest, a subject 35 jog's particle catching up 0.07 latent
            # units a frame on its path stopped doing so at once, and both feet
            # accelerated 1.5x the jog's p99 there)
            rate = self.v / self.fps - (on_path[0] - here)
            span = min(n, max(1, int(round(CARRY_SECONDS * self.fps))))
            Xa[:span] += carried(span)[:, None] * rate[None, :]
        Xb = at_b(m2.X_)
        r1, r2 = self._root(m1, Xa), self._root(m2, Xb)
        root = {k: mix_rows(r1[k], r2[k], w) for k in r1}
        Da, Db = self._detail_at(src, sa, ua + du, at_a), self._detail_at(to, sb, ub + du, at_b)
        Pa, Pb = m1.pose(Xa), m2.pose(Xb)
        detail = None
        if Da is not None:
            Pa, Pb = Pa + Da["angles"], Pb + Db["angles"]
            detail = {k: mix_rows(Da[k], Db[k], w) for k in Da}
            root = {k: root[k] + detail[k] for k in root}
        blended = self._mix(src, to, self._clip(src, Pa, count), self._clip(to, Pb, count), w)
        return {"w": w, "du": du, "Xa": Xa, "Xb": Xb, "on_path": on_path, "root": root,
                "detail": detail,
                "Pa": Pa, "Pb": Pb, "Da": Da, "blended": blended}

    def _hop_peak(self, src: str, to: str, blended: np.ndarray, root: dict) -> float:
        """The largest joint acceleration relative to the root of an in-step blend's
        frames (``to``'s chart; the root's tilt and turn included, as the report
        measures: a walk-to-run blend tilts the whole body forward), over the faster of
        the two models' training 99th percentile measured so
        (:meth:`~.output.OutputMixin._lock_acc99`, in the models' own units)."""
        from ...conventions import nearest_rotations
        from .model import heading_matrix

        m2 = self.models[to]
        if blended.shape[0] < 3:
            return 0.0
        theta = np.concatenate([[0.0], np.cumsum(root["turn"][:-1]) / self.fps])
        rot = heading_matrix(theta) @ nearest_rotations(root["tilt"])
        p = np.einsum("tab,tpb->tpa", rot,
                      pose_points(m2.to_channels(blended), m2.channels_, m2.skeleton_))
        acc = float(np.linalg.norm(np.diff(p, 2, axis=0), axis=2).max()) * self.fps**2
        ref = max(self._lock_acc99(k) / self.sizes.get(k, 1.0) for k in (src, to))
        return acc / max(ref, 1e-12)

    def _hop_targets(self, src, to, Xa, Xb, Pb, Da, w) -> tuple[np.ndarray, np.ndarray]:
        """What untangling pulls an in-step blend's frames toward (``_Chunk.targets``):
        the two gaits' poses on their paths ``Xa``, ``Xb`` (plus detail ``Da``; ``Pb``
        is ``to``'s already) blended by ``w`` without the particle's stray, and each
        gait's nearest whole captured frame blended.  At the first frames of a subject
        35 run -> walk blend the stray still swung a thumb 1.68 units from the thigh
        (the takes' closest 1.93), where the frames of a MOVE would have been pulled."""
        m1, m2 = self.models[src], self.models[to]
        Pa = m1.pose(Xa) + (0.0 if Da is None else Da["angles"])
        near = self._mix(src, to, self._clip(src, Pa, count=False),
                         self._clip(to, Pb, count=False), w)
        whole = self._mix(src, to, m1.frame_angles()[m1.nearest_frame(Xa)],
                          m2.frame_angles()[m2.nearest_frame(Xb)], w)
        return near, whole


def interp_rows(t: np.ndarray, times: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` ``(M, ...)`` given at ``times`` ``(M,)``, linear at ``t`` ``(T,)``."""
    flat = values.reshape(values.shape[0], -1)
    out = np.stack([np.interp(t, times, col) for col in flat.T], axis=1)
    return out.reshape((len(t),) + values.shape[1:])
