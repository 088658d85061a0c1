"""The motion object: a capture as frames of channel values with its skeleton and rate."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Callable, Hashable, Iterable, Sequence

import numpy as np

from .errors import ParameterError
from .skeleton import DOF_NAMES, JointPositions, Skeleton, forward_kinematics

__all__ = ["Motion", "DEFAULT_FPS"]

#: CMU captures are recorded at 120 Hz; AMC files do not store a rate.
DEFAULT_FPS = 120.0
#: Largest positions array (values: frames x points x 3) :meth:`Motion.positions` keeps
#: with its motion: 3 million values, 24 MB (a minute at 120 fps of a 100-point rig);
#: longer motions have their positions made on each call.
FK_KEPT_VALUES = 3_000_000

Channel = tuple[str, str]


def _frozen_floats(a) -> bool:
    """Whether ``a`` is a float64 array nobody can write to (it and every array it views
    read-only): a motion keeps such an array as it is, a reader's frames or a slice of
    another motion's, instead of copying it."""
    if not isinstance(a, np.ndarray) or a.dtype != np.float64:
        return False
    while isinstance(a, np.ndarray):
        if a.flags.writeable:
            return False
        a = a.base
    return True


@dataclass(frozen=True, eq=False)
class Motion:
    """A capture: ``T`` frames of ``D`` channel values.

    Attributes
    ----------
    frames : ndarray, shape (T, D)
        Channel values per frame; angles in degrees, translations in the skeleton's
        length units.
    channels : tuple of (str, str)
        ``(joint, dof)`` per column, dof one of ``tx ty tz rx ry rz`` (or any string for
        captures without a skeleton, e.g. a CSV's free-form columns).
    fps : float
        Frames per second.
    skeleton : Skeleton or None
        The joint hierarchy when known (ASF or BVH); needed for forward kinematics.
    source : str or None
        Where the frames came from (a path, ``"synthetic:..."``, ...).
    start_frame : int
        Index of ``frames[0]`` in the original capture (0-based), kept through slicing so
        reports can speak in the capture's own frame numbers.
    metadata : dict
        Free-form extras (e.g. the AMC header lines); never used in computations.
    """

    frames: np.ndarray
    channels: tuple[Channel, ...]
    fps: float = DEFAULT_FPS
    skeleton: Skeleton | None = None
    source: str | None = None
    start_frame: int = 0
    metadata: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        frames = self.frames
        if not _frozen_floats(frames):  # own copy: the caller's array is never frozen
            frames = np.array(frames, dtype=float)
        if frames.ndim == 1:
            frames = frames[:, None]
        if frames.ndim != 2:
            raise ParameterError(f"frames must be a (T, D) array, got shape {frames.shape}")
        channels = tuple((str(j), str(d)) for j, d in self.channels)
        if len(channels) != frames.shape[1]:
            raise ParameterError(
                f"{len(channels)} channel names for {frames.shape[1]} columns of frames"
            )
        if len(set(channels)) != len(channels):
            dup = sorted({c for c in channels if channels.count(c) > 1})
            raise ParameterError(f"duplicate channels: {dup}")
        if not np.isfinite(self.fps) or self.fps <= 0:
            raise ParameterError(f"fps must be a positive number, got {self.fps}")
        frames.flags.writeable = False
        object.__setattr__(self, "frames", frames)
        object.__setattr__(self, "channels", channels)
        object.__setattr__(self, "fps", float(self.fps))

    # ---------------------------------------------------------------- basics
    @property
    def n_frames(self) -> int:
        return int(self.frames.shape[0])

    @property
    def n_channels(self) -> int:
        return int(self.frames.shape[1])

    @property
    def duration(self) -> float:
        """Length in seconds (frames / fps)."""
        return self.n_frames / self.fps

    def __len__(self) -> int:
        return self.n_frames

    def __repr__(self) -> str:
        skel = f", skeleton={len(self.skeleton.joints)} joints" if self.skeleton else ""
        src = f", source={self.source!r}" if self.source else ""
        return (
            f"Motion({self.n_frames} frames x {self.n_channels} channels, "
            f"{self.fps:g} fps{skel}{src})"
        )

    def channel_index(self, joint: str, dof: str) -> int:
        """Column of channel ``(joint, dof)``."""
        try:
            return self.channels.index((joint, dof))
        except ValueError:
            raise KeyError(f"no channel ({joint!r}, {dof!r}) in this motion") from None

    def channel_names(self, sep: str = ".") -> list[str]:
        """Flat names such as ``"root.tx"``."""
        return [f"{j}{sep}{d}" for j, d in self.channels]

    # --------------------------------------------------------------- slicing
    def __getitem__(self, key: int | slice | Sequence[int] | np.ndarray) -> "Motion":
        """Select frames; everything else (channels, skeleton, rate) is kept.

        ``motion[200:450]`` gives frames 200..449 with ``start_frame`` advanced.
        """
        if isinstance(key, tuple):
            raise TypeError("index a Motion by frames only; use select() for channels")
        if isinstance(key, (int, np.integer)):
            n = self.n_frames
            k = int(key) + n if key < 0 else int(key)
            if not 0 <= k < n:
                raise IndexError(f"frame {key} out of range for {n} frames")
            key = slice(k, k + 1)
        if isinstance(key, slice):
            start, stop, step = key.indices(self.n_frames)
            if step != 1:
                fps = self.fps / abs(step)
            else:
                fps = self.fps
            sub = replace(
                self, frames=self.frames[key], fps=fps, start_frame=self.start_frame + start
            )
            return self._rows_kept(sub, key)
        idx = np.asarray(key)
        if idx.dtype == bool:
            idx = np.flatnonzero(idx)
        first = int(idx[0]) if idx.size else 0
        sub = replace(self, frames=self.frames[idx], start_frame=self.start_frame + first)
        return self._rows_kept(sub, idx)

    def _rows_kept(self, sub: "Motion", rows: slice | np.ndarray) -> "Motion":
        """``sub`` (these ``rows`` of this motion) with their rows of the positions kept by
        :meth:`positions`, if any: forward kinematics is frame by frame."""
        kept = self.__dict__.get("_positions")
        if kept is not None and sub.n_frames > 1:  # (one frame alone rounds differently)
            object.__setattr__(sub, "_positions", replace(kept, positions=kept.positions[rows]))
        return sub

    def window(self, frames: tuple[int | None, int | None] | None) -> "Motion":
        """Frames ``start:stop`` (0-based, half-open; ``None`` ends mean the capture's ends),
        checked to lie inside the capture; ``None`` returns the motion itself."""
        if frames is None:
            return self
        a, b = frames
        n = self.n_frames
        a = 0 if a is None else int(a)
        b = n if b is None else int(b)
        if a >= b:
            raise ParameterError(
                f"frame range {a}:{b} is reversed or empty: frames A:B run from A to B-1, so A "
                "must be below B"
            )
        if not 0 <= a < b <= n:
            raise ParameterError(
                f"frame range {a}:{b} is not inside the capture's {n} frames (0-based, half-open)"
            )
        return self if (a, b) == (0, n) else self[a:b]

    def select(self, channels: Iterable[Channel | str]) -> "Motion":
        """Keep only some channels (``(joint, dof)`` pairs, ``"joint.dof"`` or a joint
        name for all its channels), in the order given."""
        wanted: list[Channel] = []
        for c in channels:
            if isinstance(c, str):
                if "." in c:
                    j, d = c.rsplit(".", 1)
                    wanted.append((j, d))
                else:
                    found = [ch for ch in self.channels if ch[0] == c]
                    if not found:
                        raise KeyError(f"no channels for joint {c!r} in this motion")
                    wanted.extend(found)
            else:
                wanted.append((str(c[0]), str(c[1])))
        cols = [self.channel_index(j, d) for j, d in wanted]
        return replace(self, frames=self.frames[:, cols], channels=tuple(wanted))

    def with_frames(self, frames: np.ndarray, **changes) -> "Motion":
        """A copy with new frame values (same channels unless ``channels=`` is given).

        With the same channels and skeleton, the copy's :meth:`positions` find forward
        kinematics again only on the frames that differ from this motion's, when this
        motion's positions are kept (foot locking and limb checks change a few frames of
        a long motion, over and over)."""
        out = replace(self, frames=frames, **changes)
        kept = self.__dict__.get("_fk_of")
        if kept is not None and out.skeleton is self.skeleton and out.channels == self.channels:
            object.__setattr__(out, "_fk_base", kept)
        return out

    @staticmethod
    def concatenate(motions: Sequence["Motion"]) -> "Motion":
        """Join captures end to end; they must share channels and frame rate."""
        if not motions:
            raise ParameterError("nothing to concatenate")
        first = motions[0]
        for i, m in enumerate(motions[1:], start=1):
            if m.channels != first.channels:
                missing = set(first.channels) ^ set(m.channels)
                detail = f" (differing: {sorted(missing)[:4]})" if missing else " (order differs)"
                raise ParameterError(f"motion {i} has different channels from motion 0{detail}")
            if abs(m.fps - first.fps) > 1e-9:
                raise ParameterError(
                    f"motion {i} is at {m.fps:g} fps, motion 0 at {first.fps:g} fps; resample first"
                )
        frames = np.concatenate([m.frames for m in motions], axis=0)
        sources = [m.source for m in motions if m.source]
        return replace(
            first,
            frames=frames,
            start_frame=0,
            source=" + ".join(sources) if sources else None,
            metadata={"parts": [(m.source, m.n_frames) for m in motions]},
        )

    # ---------------------------------------------------------- conveniences
    def positions(self):
        """Forward kinematics: world positions of every joint (see
        :func:`cyclecoord.skeleton.forward_kinematics`).

        Made once per motion up to :data:`FK_KEPT_VALUES` position values and kept
        read-only (the frames and the skeleton never change, so neither do they): a
        latent script asked 79 times for the positions of 34 motions.  Copy the array to
        change it.  A slice of this motion (``motion[a:b]``) takes its rows of the kept
        positions, and a copy by :meth:`with_frames` finds them again only on the frames
        it changes: the same bits as forward kinematics on every frame (a latent script
        found 2,383 frames' positions where it had found 5,090, with the same output)."""
        kept = self.__dict__.get("_positions")
        if kept is not None:
            return kept
        frames = np.asarray(self.frames, dtype=float)
        fk = _rows_changed(self, frames, self.__dict__.get("_fk_base"))
        if fk is None:
            fk = forward_kinematics(self)
        if fk.positions.size <= FK_KEPT_VALUES:
            fk.positions.flags.writeable = False
            object.__setattr__(self, "_positions", fk)
            # the frames as they are now, for copies that change some (with_frames)
            object.__setattr__(self, "_fk_of", (frames.copy(), fk))
        self.__dict__.pop("_fk_base", None)
        return fk

    def derived(self, key: Hashable, make: Callable[[], Any]) -> Any:
        """``make()``, found once per ``key`` for this motion and kept: a value that
        depends only on its frames and skeleton (which never change), such as its legs
        or foot contacts (a latent script found its training takes' legs and contacts
        twice each).  Arrays in the value are made read-only."""
        memo = self.__dict__.setdefault("_derived", {})
        if key not in memo:
            value = make()
            for a in getattr(value, "__dict__", {}).values():
                if isinstance(a, np.ndarray):
                    a.flags.writeable = False
            memo[key] = value
        return memo[key]

    def root_channels(self) -> list[int]:
        """Columns of the root joint's translation and rotation channels.

        The root is the skeleton's first joint when known, otherwise the joint of the
        first channel if it carries translation dofs.
        """
        if self.skeleton is not None:
            root = self.skeleton.joints[0].name
        elif self.channels and any(
            d.startswith("t") for j, d in self.channels if j == self.channels[0][0]
        ):
            root = self.channels[0][0]
        else:
            return []
        return [i for i, (j, d) in enumerate(self.channels) if j == root and d in DOF_NAMES]


def _rows_changed(motion: Motion, frames: np.ndarray, base) -> JointPositions | None:
    """Positions of ``motion`` (its ``frames``) from ``base`` (the frames and positions of
    the motion it was made from): forward kinematics on the rows that changed only, or
    None when most did (or the shapes differ).  Identical to forward kinematics on every
    frame: it works frame by frame (on two frames or more; one frame alone is computed
    with a neighbour)."""
    if base is None or base[0].shape != frames.shape or frames.shape[0] < 2:
        return None
    old, fk = base
    rows = np.flatnonzero(~(frames == old).all(axis=1))
    if rows.size > 0.6 * frames.shape[0]:
        return None
    pos = fk.positions.copy()
    if rows.size:
        if rows.size == 1:
            rows = np.array([rows[0], rows[0] - 1 if rows[0] else 1])
        pos[rows] = forward_kinematics(motion.with_frames(frames[rows])).positions
    return replace(fk, positions=pos)
