"""IDLE for :class:`~.commands.Synthesizer` (:class:`IdleMixin`): the particle hovers at
one pose (a stand) or between several, its pace easing to a stop; an IDLE that begins
stepping on at a gait's pace first comes to a stop along the gait, and a stand's hover
ends back where its legs are held, so the motion after goes on from them."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...errors import ParameterError
from ..carry import STAND_AFTER
from .crossing import Point
from .easing import smooth

__all__ = ["IDLE_SWAY", "IdleMixin"]

#: Share of the particle's random force while an IDLE hovers (its ``sway``): a stand
#: sways, it does not step (see :meth:`IdleMixin.idle`).
IDLE_SWAY = 0.3


class IdleMixin:
    """:meth:`idle` and its parts (the :class:`~.commands.Synthesizer` state it uses:
    ``x``, ``v``, ``t``, ``chunks``, ``held``, ``stands``, ``models``, ``params``)."""

    def idle(
        self, at: Any = None, duration: float = 1.0, radius: float | None = None,
        hover: float = 1.0, sway: float | None = None,
    ) -> None:
        """IDLE within ``radius`` of one point (default: where the particle is) or several.

        While it hovers the particle's random force is ``sway`` (default
        :data:`IDLE_SWAY`) of the model's: a stand sways, it does not step.  At the full
        force the particle wandered along a walk model's stride loop and the legs stepped
        in place (pose speed 9-34 % of the walk's median); the pins that would hold the
        feet then crossed the legs and were let go, and the feet glided (0.45 m/s on
        subject 35's script seed 4 of 15; 0.32 m/s on a Bandai seed with two-cycle seam
        fades).  At 0.3 no seed of 30 glides (at most 0.001 m/s) and the pose sways at
        2-10 % of the walk's pose speed; ``sway=1`` gives the old behaviour.  Moves
        between several IDLE points keep the full force.  An IDLE at the particle's own
        pose that begins stepping on at the gait's pace (after an in-step TRANSITION) first
        comes to a stop along the gait, as a MOVE ahead that stops does, within its
        ``duration``: it stands as any IDLE does (its root from 0.5 s in), its legs held
        where they came to rest (``rests``)."""
        from .commands import _isfinite

        self._need_start("IDLE")
        sway = IDLE_SWAY if sway is None else sway
        if not (
            isinstance(sway, (int, float)) and not isinstance(sway, bool)
            and _isfinite(sway) and 0 <= sway <= 1
        ):
            raise ParameterError(f"IDLE sway must be a number from 0 to 1, got {sway!r}")
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
        if at is None and self._moving_on():
            # stepping on at the gait's pace (an in-step TRANSITION's blend ends so, 1.0-1.3
            # times the latent speed): held there, the particle overshot, met the IDLE's
            # radius and turned back within a frame (a Bandai run's knee 2.2x its p99)
            t0 = self.t
            self.move({"ahead": min(self.ease, 0.5 * duration)})
            self.notes.append(f"commands[{self.command}] IDLE: stepping on at the gait's pace, "
                              f"it first came to a stop along the gait ({self.t - t0:.2f} s)")
            points = [self.x.copy()]
        self.rests[first] = self.n_frames - first  # (where the stand holds its legs)
        try:
            self._idle(points, end, radius, hover, sway)
        finally:
            self.held.append((first, self.n_frames))
            if len(points) == 1:  # (between several poses the legs move on purpose)
                self.stands.append((first, self.n_frames))

    def _moving_on(self) -> bool:
        """Whether the particle steps along a gait at over half its latent speed (a MOVE
        that stopped leaves it at 0.1-0.3 of it)."""
        return bool(self._stepping and self.v is not None
                    and np.linalg.norm(self.v) >= 0.5 * self.models[self.current].speed_)

    def _stopping(self, n: int) -> np.ndarray:
        """``(n,)`` pace of an IDLE's frames: the root's own travel goes on from the
        pace the frames before it had (a MOVE that stops eases its pace to 0, a blend's
        is 1) and eases to 0 over :data:`~cyclecoord.synthesis.carry.STAND_AFTER` s."""
        last = self.chunks[-1] if self.chunks else None
        before = 1.0 if last is None or last.pace is None else float(last.pace[-1])
        u = np.clip(np.arange(1, n + 1) / max(1.0, STAND_AFTER * self.fps), 0.0, 1.0)
        return before * (1.0 - smooth(u))

    def _idle(self, points, end: float, radius, hover: float, sway: float = 1.0) -> None:
        duration = end - self.t
        while self.t < end - 0.5 / self.fps:
            p = points[int(self.rng.integers(len(points)))] if len(points) > 1 else points[0]
            m = self.models[self.current]
            gap = float(np.linalg.norm(p - self.x))
            if gap > self.params.radius * m.speed_:
                self.move(Point(p), radius=radius)
                if self.t >= end:
                    break
            n = max(
                1, int(round(min(hover if len(points) > 1 else duration, end - self.t) * self.fps))
            )
            path = np.repeat(p[None, :], n + 1, axis=0)
            # one pose: the hover ends back at its first frame's, where the stand holds
            # its legs (``_stand_legs``: in an IDLE under 1 s only part of the way, and
            # the hover goes back as far), so the motion after goes on from them (the
            # particle drifted 0.1 s of travel along a synthetic run's stride, and the
            # legs eased out of the stand swapped their stride while the feet were
            # pinned: a foot swept 0.4 m in 2 frames)
            self._run(path, radius, sway=sway, pace=self._stopping(n),
                      settle=0 if len(points) == 1 else None)
