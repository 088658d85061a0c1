"""Preparation of a capture for topology: root channels differenced, optional scaling and PCA.

A walk's root translation grows without bound and its heading may turn, which turns the
closed loop of a periodic motion into a spiral.  Following the paper (§4.1) the root's
translation and orientation channels are replaced by their first differences (per-frame
velocities), which are periodic again.  Optional per-channel scaling by standard deviation
(§6.4) and a PCA projection (§5.1) follow.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ParameterError
from .motion import Motion

__all__ = ["Preprocessor", "PreparedData", "difference_root"]


@dataclass(frozen=True)
class PreparedData:
    """A capture ready for the filtration.

    Attributes
    ----------
    points : ndarray, shape (T, K)
        The analysed point cloud: one point per frame (after differencing, scaling, PCA).
    poses : ndarray, shape (T, D)
        The frames with root channels differenced but neither scaled nor projected; the
        typical cycle is averaged in this space so that it can be turned back into a
        motion.
    root_columns : ndarray of int
        Columns of ``poses`` holding differenced root channels.
    """

    points: np.ndarray
    poses: np.ndarray
    root_columns: np.ndarray


def _wrap_degrees(x: np.ndarray) -> np.ndarray:
    return (x + 180.0) % 360.0 - 180.0


def difference_root(frames: np.ndarray, root_columns: np.ndarray, rotation_mask: np.ndarray) -> np.ndarray:
    """Replace root channels by forward differences, keeping one row per frame.

    ``out[t] = x[t+1] - x[t]`` for ``t < T-1`` and the last row repeats the previous
    difference, so every frame keeps a point.  Rotation differences are wrapped into
    [-180, 180) degrees so that a heading crossing ±180 does not jump.

    Parameters
    ----------
    frames : ndarray, shape (T, D)
    root_columns : ndarray of int
        Columns to difference.
    rotation_mask : ndarray of bool, same length as ``root_columns``
        Which of those columns are angles in degrees.
    """
    out = np.array(frames, dtype=float)
    if root_columns.size == 0:
        return out
    if frames.shape[0] < 2:
        raise ParameterError("differencing the root needs at least 2 frames")
    d = np.diff(frames[:, root_columns], axis=0)
    d[:, rotation_mask] = _wrap_degrees(d[:, rotation_mask])
    out[:-1, root_columns] = d
    out[-1, root_columns] = d[-1]
    return out


class Preprocessor:
    """Turn a :class:`~cyclecoord.motion.Motion` into the point cloud that is analysed.

    Parameters
    ----------
    difference_root : bool, default True
        Replace the root's translation and rotation channels by first differences.
    normalize : bool, default False
        Divide every channel (after differencing) by its standard deviation, so each
        channel weighs the same in the distance (constant channels are left unscaled).
    pca : int or None, default None
        Project onto the first ``pca`` principal components.

    Attributes
    ----------
    root_columns_ : ndarray of int
        Root channels that were differenced.
    mean_ : ndarray, shape (D,)
        Channel means of the prepared poses (used by PCA).
    scale_ : ndarray, shape (D,)
        Per-channel divisors (ones unless ``normalize``).
    components_ : ndarray, shape (K, D) or None
        Principal axes when ``pca`` is set.
    explained_variance_ratio_ : ndarray, shape (K,) or None
    """

    def __init__(self, difference_root: bool = True, normalize: bool = False, pca: int | None = None) -> None:
        self.difference_root = difference_root
        self.normalize = normalize
        self.pca = pca

    # ------------------------------------------------------------------
    def _poses(self, motion: Motion) -> np.ndarray:
        frames = motion.frames
        if not np.all(np.isfinite(frames)):
            bad = np.argwhere(~np.isfinite(frames))[0]
            raise ParameterError(
                f"frame {motion.start_frame + bad[0]} channel {motion.channels[bad[1]]} is not a finite number"
            )
        if not self.difference_root:
            return np.array(frames, dtype=float)
        return difference_root(frames, self.root_columns_, self._rot_mask_)

    def fit(self, motion: Motion) -> "Preprocessor":
        """Learn root columns, scaling and principal axes from ``motion``."""
        if not isinstance(motion, Motion):
            raise ParameterError(f"expected a Motion, got {type(motion).__name__}")
        if motion.n_frames < 3:
            raise ParameterError(f"need at least 3 frames, got {motion.n_frames}")
        cols = np.asarray(motion.root_channels() if self.difference_root else [], dtype=int)
        self.root_columns_ = cols
        self._rot_mask_ = np.array([motion.channels[c][1].startswith("r") for c in cols], dtype=bool)
        poses = self._poses(motion)
        self.mean_ = poses.mean(axis=0)
        if self.normalize:
            sd = poses.std(axis=0)
            self.scale_ = np.where(sd > 1e-12, sd, 1.0)
        else:
            self.scale_ = np.ones(poses.shape[1])
        self.components_ = None
        self.explained_variance_ratio_ = None
        if self.pca is not None:
            k = int(self.pca)
            if k < 1 or k > min(poses.shape):
                raise ParameterError(
                    f"pca must be between 1 and {min(poses.shape)} for {poses.shape[0]} frames "
                    f"x {poses.shape[1]} channels, got {self.pca}"
                )
            z = (poses - self.mean_) / self.scale_
            _, s, vt = np.linalg.svd(z, full_matrices=False)
            self.components_ = vt[:k]
            var = s**2
            self.explained_variance_ratio_ = var[:k] / var.sum() if var.sum() > 0 else np.zeros(k)
        self.n_channels_ = motion.n_channels
        return self

    def transform(self, motion: Motion) -> PreparedData:
        """Prepare ``motion`` with the learned settings."""
        if not hasattr(self, "root_columns_"):
            raise ParameterError("this Preprocessor is not fitted yet; call fit() first")
        if motion.n_channels != self.n_channels_:
            raise ParameterError(
                f"motion has {motion.n_channels} channels, the preprocessor was fitted on {self.n_channels_}"
            )
        poses = self._poses(motion)
        if self.components_ is not None:
            points = ((poses - self.mean_) / self.scale_) @ self.components_.T
        elif self.normalize:
            points = poses / self.scale_
        else:
            points = poses
        return PreparedData(points=np.ascontiguousarray(points), poses=poses, root_columns=self.root_columns_)

    def fit_transform(self, motion: Motion) -> PreparedData:
        return self.fit(motion).transform(motion)
