"""The latent pose space of the motion graph: PCA of the joint angles (Gauch & Peters §III-A).

The root's six channels are left out, as in the paper, so that a walk stays in place
and each take comes back near where it started; the other joint-angle channels (56 on
a CMU skeleton) are unwrapped along time (no jump of 360 degrees inside a take) and
every take is moved by whole turns per channel to lie nearest the first training take,
so that 179 and -181 degrees are one pose.  PCA is fitted on the training takes only.

Latent coordinates keep the units of the angles: a distance of 1 is one degree of
Euclidean distance over all the channels.  :attr:`PoseSpace.scale_` (the longest side
of the training points' bounding box) is the unit the paper's errors appear to be
normalised by (values of 0.02-0.1).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ...errors import ParameterError
from ...motion import Motion
from ...rig.retarget import onto_skeleton, proportions_differ, same_rig

__all__ = ["PoseSpace", "angle_columns", "check_takes"]


def angle_columns(motion: Motion) -> np.ndarray:
    """Columns of the joint-angle channels: every ``r*`` channel but the root's."""
    root = set(motion.root_channels())
    cols = [
        i for i, (_, d) in enumerate(motion.channels) if d in ("rx", "ry", "rz") and i not in root
    ]
    return np.asarray(cols, dtype=int)


def _name(m: Motion, i: int) -> str:
    return m.source or f"take {i}"


def _ordinal(k: int) -> str:
    return f"{k}{'nd' if k == 2 else 'rd' if k == 3 else 'th'}"


def _short(m: Motion, i: int) -> str:
    return m.source.replace("\\", "/").rsplit("/", 1)[-1] if m.source else f"take {i}"


def check_takes(
    motions: Sequence[Motion], minimum: int = 2, notes: list[str] | None = None
) -> list[Motion]:
    """The training takes, checked to share rig, channels and frame rate.

    With ``notes`` (a list the lines saying what was done go to): a take of the first
    take's rig worn by another actor (other bone lengths) is put on the first take's
    skeleton (:func:`cyclecoord.rig.retarget.onto_skeleton`: rotations kept, travel
    scaled by the legs' ratio), and a take whose rate is a whole multiple of the slowest
    take's (CMU's 120 fps beside a 60 fps take) has every k-th frame taken.  Without
    ``notes`` such takes are refused.

    Raises
    ------
    ParameterError
        One line naming the take that differs, or saying how many takes are needed.
    """
    takes = list(motions)
    if any(not isinstance(m, Motion) for m in takes):
        raise ParameterError("the motion graph is trained on Motion objects (cyclecoord.load)")
    if len(takes) < minimum:
        got = "one take" if len(takes) == 1 else f"{len(takes)} takes"
        raise ParameterError(
            f"the motion graph needs at least {minimum} training takes, got {got}"
            + (" (cross-validation leaves one out)" if minimum > 2 else "")
        )
    first = takes[0]
    for i, m in enumerate(takes):
        if m.n_frames < 3:
            raise ParameterError(f"{_name(m, i)}: {m.n_frames} frames; a take needs at least 3")
        if not np.all(np.isfinite(m.frames)):
            raise ParameterError(f"{_name(m, i)}: holds NaN or infinite values")
        if i == 0:
            continue
        if m.channels != first.channels:
            diff = sorted(set(m.channels) ^ set(first.channels))
            what = (
                f"differing: {', '.join('.'.join(c) for c in diff[:4])}"
                if diff
                else "same channels, other order"
            )
            raise ParameterError(
                f"{_name(m, i)}: its {m.n_channels} channels differ from {_name(first, 0)}'s "
                f"{first.n_channels} ({what}); every take needs the same skeleton and channels"
            )
        why = same_rig(first.skeleton, m.skeleton)
        if why:
            raise ParameterError(
                f"{_name(m, i)}: its skeleton differs from {_name(first, 0)}'s ({why}); "
                "train on takes of one rig"
            )
        if proportions_differ(first.skeleton, m.skeleton):
            if notes is None:
                raise ParameterError(
                    f"{_name(m, i)}: its bone lengths differ from {_name(first, 0)}'s; "
                    "put it on one skeleton first (cyclecoord.rig.onto_skeleton)"
                )
            takes[i], p = onto_skeleton(m, first)
            notes.append(p.describe(_short(m, i), _short(first, 0)))
    slowest = min(m.fps for m in takes)
    for i, m in enumerate(takes):
        if abs(m.fps - slowest) <= 1e-9:
            continue
        k = int(round(m.fps / slowest))
        if notes is None or k < 2 or abs(m.fps / k - slowest) > 0.01 * slowest:
            j = next(j for j, t in enumerate(takes) if abs(t.fps - slowest) <= 1e-9)
            raise ParameterError(
                f"{_name(m, i)}: {m.fps:g} fps, {_name(takes[j], j)} "
                f"{slowest:g} fps; resample first"
                + ("" if notes is None or k < 2 else " (not a whole multiple of the rate)")
            )
        takes[i] = m[::k]
        notes.append(
            f"{_short(m, i)}: {m.fps:g} fps, every {_ordinal(k)} frame taken "
            f"({slowest:g} fps, the slowest take's rate)"
        )
    if angle_columns(first).size < 2:
        raise ParameterError(
            f"{_name(first, 0)}: fewer than 2 joint-angle channels besides the root"
        )
    return takes


class PoseSpace:
    """PCA of unwrapped joint angles, fitted on training takes.

    Parameters
    ----------
    n_components : int, default 2
        Latent dimensions ``d`` (the paper's 2; 3-5 for the Delaunay graph, more for k-NN).

    Attributes
    ----------
    columns_ : ndarray of int, shape (A,)
        Joint-angle columns of the takes' frames (A = 56 on CMU).
    channels_ : tuple of (str, str)
    reference_ : ndarray, shape (A,)
        Mean of the first take's unwrapped angles: every take is brought to within 180
        degrees of it per channel.
    mean_ : ndarray, shape (A,)
    components_ : ndarray, shape (d, A)
        Orthonormal rows.
    explained_variance_ratio_ : ndarray, shape (d,)
    scale_ : float
        Longest side of the training points' latent bounding box (degrees).
    """

    def __init__(self, n_components: int = 2) -> None:
        self.n_components = n_components

    def fit(self, motions: Sequence[Motion]) -> "PoseSpace":
        takes = list(motions)
        d = self.n_components
        if isinstance(d, bool) or not isinstance(d, (int, np.integer)) or d < 1:
            raise ParameterError(
                f"the latent space needs a whole number of dimensions >= 1, got {d!r}"
            )
        self.columns_ = angle_columns(takes[0])
        self.channels_ = tuple(takes[0].channels[c] for c in self.columns_)
        first = np.unwrap(takes[0].frames[:, self.columns_], period=360.0, axis=0)
        self.reference_ = first.mean(axis=0)
        x = np.vstack([self.angles(m) for m in takes])
        if d > min(x.shape):
            raise ParameterError(
                f"{d} latent dimensions from {x.shape[0]} frames of {x.shape[1]} angles"
            )
        self.mean_ = x.mean(axis=0)
        xc = x - self.mean_
        var, vecs = np.linalg.eigh(xc.T @ xc)  # A x A: cheaper than an SVD of all frames
        var, vt = np.maximum(var[::-1], 0.0), vecs[:, ::-1].T
        # a deterministic sign: the largest loading of each component is positive
        signs = np.sign(vt[np.arange(vt.shape[0]), np.argmax(np.abs(vt), axis=1)])
        vt *= signs[:, None]
        self.components_ = vt[:d]
        self.explained_variance_ratio_ = var[:d] / var.sum()
        z = (x - self.mean_) @ self.components_.T
        self.scale_ = float(np.ptp(z, axis=0).max()) or 1.0
        return self

    def angles(self, motion: Motion) -> np.ndarray:
        """Unwrapped joint angles ``(T, A)`` of a take, on the training takes' turns."""
        if any(
            c >= motion.n_channels or motion.channels[c] != ch
            for c, ch in zip(self.columns_, self.channels_)
        ):
            raise ParameterError(
                f"{motion.source or 'this motion'}: its channels differ from the training takes'"
            )
        a = np.unwrap(motion.frames[:, self.columns_], period=360.0, axis=0)
        return a - 360.0 * np.round((a.mean(axis=0) - self.reference_) / 360.0)

    def transform(self, motion_or_angles: Motion | np.ndarray) -> np.ndarray:
        """Latent points ``(T, d)`` of a take (or of unwrapped angles ``(T, A)``)."""
        a = (
            self.angles(motion_or_angles)
            if isinstance(motion_or_angles, Motion)
            else np.asarray(motion_or_angles)
        )
        return (a - self.mean_) @ self.components_.T

    def residuals(self, motions: Sequence[Motion]) -> np.ndarray:
        """What the latent space leaves out of each training frame: angles ``(N, A)``
        minus their reconstruction, the takes' frames one after another."""
        a = np.vstack([self.angles(m) for m in motions])
        return a - self.inverse_transform(self.transform(a))

    def inverse_transform(self, z: np.ndarray) -> np.ndarray:
        """Joint angles ``(T, A)`` in degrees from latent points ``(T, d)``."""
        return np.asarray(z, dtype=float) @ self.components_ + self.mean_

    def motion(
        self,
        z: np.ndarray,
        template: Motion,
        root: np.ndarray | None = None,
        detail: np.ndarray | None = None,
    ) -> Motion:
        """A playable :class:`Motion`: ``template``'s channels and skeleton, joint angles
        from ``z`` plus ``detail`` ``(T, A)`` when given (wrapped into [-180, 180)), root
        channels from ``root`` ``(T, R)`` (zeros when None), other channels at the
        template's first frame."""
        z = np.asarray(z, dtype=float)
        frames = np.repeat(np.asarray(template.frames[:1], dtype=float), z.shape[0], axis=0)
        angles = self.inverse_transform(z) + (0.0 if detail is None else detail)
        frames[:, self.columns_] = (angles + 180.0) % 360.0 - 180.0
        rc = template.root_channels()
        frames[:, rc] = 0.0 if root is None else root
        return template.with_frames(
            frames, start_frame=0, source="synthetic:motion-graph", metadata={}
        )
