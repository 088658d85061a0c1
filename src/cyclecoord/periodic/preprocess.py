"""Preparation of a capture for topology: root channels differenced, optional scaling and PCA.

A walk's root translation grows without bound and its heading may turn, which turns the
closed loop of a periodic motion into a spiral.  Following the paper (§4.1) the root's
translation and orientation are replaced by per-frame changes, which are periodic again.

Two forms of the change are offered.  ``root="body"`` (default when the skeleton is
known): the rotation from one frame's root orientation to the next as a rotation vector
(degrees), and the translation step expressed in the root's own frame.  Both are free of
gimbal lock and do not depend on which way the actor faces.  ``root="euler"``: plain
differences of the Euler channels (wrapped to ±180°), as in the paper; used when there
is no skeleton.  Euler differences break down where the root's middle angle nears ±90°
(CMU 143_01 faces that way: two channels jump by up to 86° between frames).

Optional per-channel scaling by standard deviation (§6.4), a PCA projection (§5.1) and a
delay embedding follow.  :meth:`Preprocessor.integrate_root` inverts the differencing.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from ..errors import ParameterError
from ..motion import Motion

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


def difference_root(
    frames: np.ndarray, root_columns: np.ndarray, rotation_mask: np.ndarray
) -> np.ndarray:
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


_AX = {"x": 0, "y": 1, "z": 2}


def _root_layout(motion: Motion, cols: np.ndarray):
    """For body-frame differencing: the root joint and, per root column, its role.

    Returns ``None`` unless the root has exactly the three translation and three
    rotation dofs and a skeleton describes its rotation convention.
    """
    sk = motion.skeleton
    if sk is None or cols.size != 6:
        return None
    root = sk.joints[0]
    dofs = [motion.channels[c][1] for c in cols]
    if (
        sorted(dofs) != sorted(["tx", "ty", "tz", "rx", "ry", "rz"])
        or len(root.rotation_order) != 3
    ):
        return None
    return root, dofs


def _root_rotations(frames: np.ndarray, cols: np.ndarray, root, dofs) -> np.ndarray:
    vals = np.column_stack(
        [frames[:, cols[dofs.index("r" + a.lower())]] for a in root.rotation_order]
    )
    local = Rotation.from_euler(root.rotation_order, vals, degrees=True).as_matrix()
    return root.axis @ local @ root.axis.T


def body_frame_differences(frames: np.ndarray, cols: np.ndarray, root, dofs) -> np.ndarray:
    """Root changes per frame in the root's own frame, one row per frame.

    Columns follow ``cols``: the translation dofs get ``R_tᵀ (p_{t+1} - p_t)`` and the
    rotation dofs the rotation vector (degrees) of ``R_tᵀ R_{t+1}``; the last row repeats
    the previous one.
    """
    R = _root_rotations(frames, cols, root, dofs)
    p = np.column_stack([frames[:, cols[dofs.index(t)]] for t in ("tx", "ty", "tz")])
    dp = np.einsum("tji,tj->ti", R[:-1], np.diff(p, axis=0))
    rel = np.einsum("tji,tjk->tik", R[:-1], R[1:])
    w = Rotation.from_matrix(rel).as_rotvec(degrees=True)
    out = np.empty((len(frames), 6))
    for k, d in enumerate(dofs):
        src = dp if d.startswith("t") else w
        out[:-1, k] = src[:, _AX[d[1]]]
    out[-1] = out[-2]
    return out


def _delays(delay) -> list[int]:
    """Delays in frames from an int or a sequence of ints (validated)."""
    values = list(delay) if np.ndim(delay) else [delay]
    out = []
    for v in values:
        if int(v) != v or v < 0:
            raise ParameterError(f"delays must be whole numbers of frames >= 0, got {delay}")
        if int(v) > 0:
            out.append(int(v))
    return out


def _start_frame(start: np.ndarray, cols: np.ndarray, motion: Motion) -> np.ndarray:
    """A one-frame array holding ``start`` in the root columns (for the rotation helper)."""
    f = np.zeros((1, motion.n_channels))
    f[0, cols] = start
    return f


class Preprocessor:
    """Turn a :class:`~cyclecoord.motion.Motion` into the point cloud that is analysed.

    Parameters
    ----------
    difference_root : bool, default True
        Replace the root's translation and rotation channels by per-frame changes.
    root : {"body", "euler"}, default "body"
        How the root changes are expressed (see the module notes): rotation vectors and
        translation steps in the root's frame (needs a skeleton; otherwise falls back to
        Euler), or plain Euler-channel differences as in the paper.
    normalize : bool, default False
        Divide every channel (after differencing) by its standard deviation, so each
        channel weighs the same in the distance (constant channels are left unscaled).
    pca : int or None, default None
        Project onto the first ``pca`` principal components.
    rotations : {"auto", "rotvec", "euler"}, default "auto"
        How joint rotations enter the point cloud (:mod:`cyclecoord.periodic.rotations`).
        ``"rotvec"``: each joint's rotation as a rotation vector (degrees) about its mean
        rotation over the fitted capture, hinge angles kept on one branch, so Euler wraps
        and flips change nothing.  ``"auto"``: the same for every joint whose Euler
        channels wrap, flip or near gimbal lock anywhere in the capture, the channels as
        written for the others (where they measure the rotation as faithfully), hinges on
        one branch: a CMU capture reads exactly as in the paper, a BVH whose hips cross
        +-180 degrees as rotations.  ``"euler"``: the Euler channels as written, the
        paper's space (§3).
    delay : int, sequence of int, or None, default None
        Delay embedding: each point becomes ``[p(t), p(t - d1), p(t - d2), ...]`` for the
        given delays in frames (frames before the first repeat it).  A motion that goes
        out and back along the same path (a squat, a jumping jack) is a segment in pose
        space, not a loop; paired with its past it becomes a loop (Takens; paper §4.2).
        The typical cycle is still averaged from the poses themselves.

    Attributes
    ----------
    root_columns_ : ndarray of int
        Root channels that were differenced.
    root_rotation_mask_ : ndarray of bool, shape (``len(root_columns_)``,)
        Which of them are rotations (differenced as angles, wrapped into [-180, 180)).
    mean_ : ndarray, shape (D,)
        Channel means of the prepared poses (used by PCA).
    rotation_map_ : RotationMap or None
        The fitted joint-rotation map (None when no joint needs one or ``rotations="euler"``).
    scale_ : ndarray, shape (D,)
        Per-channel divisors (ones unless ``normalize``).
    components_ : ndarray, shape (K, D) or None
        Principal axes when ``pca`` is set.
    explained_variance_ratio_ : ndarray, shape (K,) or None
    """

    def __init__(
        self,
        difference_root: bool = True,
        normalize: bool = False,
        pca: int | None = None,
        delay: int | None = None,
        root: str = "body",
        rotations: str = "auto",
    ) -> None:
        self.root = root
        self.rotations = rotations
        self.difference_root = difference_root
        self.normalize = normalize
        self.pca = pca
        self.delay = delay

    # ------------------------------------------------------------------
    def _poses(self, motion: Motion) -> np.ndarray:
        frames = motion.frames
        if not np.all(np.isfinite(frames)):
            bad = np.argwhere(~np.isfinite(frames))[0]
            raise ParameterError(
                f"frame {motion.start_frame + bad[0]} channel "
                f"{motion.channels[bad[1]]} is not a finite number"
            )
        if self.rotation_map_ is not None:
            joints = self.rotation_map_.to_vectors(frames)
        else:
            joints = np.array(frames, dtype=float)
        if not self.difference_root:
            return joints
        if self.root_mode_ == "body":
            layout = _root_layout(motion, self.root_columns_)
            if layout is None:
                raise ParameterError(
                    "body-frame root differencing needs the capture's skeleton with a 6-dof root; "
                    "use root='euler'"
                )
            out = joints
            out[:, self.root_columns_] = body_frame_differences(frames, self.root_columns_, *layout)
            return out
        out = difference_root(frames, self.root_columns_, self.root_rotation_mask_)
        rest = np.setdiff1d(np.arange(frames.shape[1]), self.root_columns_)
        out[:, rest] = joints[:, rest]
        return out

    def channel_values(self, poses: np.ndarray, near: np.ndarray | None = None) -> np.ndarray:
        """Joint columns of prepared poses back to the capture's channel values.

        The inverse of the joint-rotation map (Euler angles continuous over rows, the first
        row nearest ``near``); root columns are copied unchanged (see
        :meth:`integrate_root` for them).

        Parameters
        ----------
        poses : ndarray, shape (P, D)
            Rows in the prepared space (before scaling and PCA).
        near : ndarray, shape (D,), optional
            Channel values (e.g. a captured frame) the first row's angles lie closest to.
        """
        if not hasattr(self, "root_columns_"):
            raise ParameterError("this Preprocessor is not fitted yet; call fit() first")
        p = np.array(poses, dtype=float)
        if self.rotation_map_ is None:
            return p
        return self.rotation_map_.to_channels(p, near=near)

    def fit(self, motion: Motion) -> "Preprocessor":
        """Learn root columns, scaling and principal axes from ``motion``."""
        self._setup(motion)
        self._fit_poses(self._poses(motion), motion)
        return self

    def _setup(self, motion: Motion) -> None:
        if not isinstance(motion, Motion):
            raise ParameterError(f"expected a Motion, got {type(motion).__name__}")
        if motion.n_frames < 3:
            raise ParameterError(f"need at least 3 frames, got {motion.n_frames}")
        cols = np.asarray(motion.root_channels() if self.difference_root else [], dtype=int)
        self.root_columns_ = cols
        self.root_rotation_mask_ = np.array(
            [motion.channels[c][1].startswith("r") for c in cols], dtype=bool
        )
        if self.root not in ("body", "euler"):
            raise ParameterError(f"root must be 'body' or 'euler', got {self.root!r}")
        self.root_mode_ = (
            "body" if (self.root == "body" and _root_layout(motion, cols) is not None) else "euler"
        )
        if self.rotations not in ("auto", "rotvec", "euler"):
            raise ParameterError(
                f"rotations must be 'auto', 'rotvec' or 'euler', got {self.rotations!r}"
            )
        self.rotation_map_ = None
        if self.rotations != "euler":
            from .rotations import fit_rotation_map

            bad = ~np.isfinite(motion.frames)
            if not bad.any():
                rmap = fit_rotation_map(motion, exclude=cols, mode=self.rotations)
                self.rotation_map_ = rmap if rmap.columns.size else None

    def _fit_poses(self, poses: np.ndarray, motion: Motion) -> None:
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
        if self.delay is not None:
            _delays(self.delay)  # validates
        self.n_channels_ = motion.n_channels

    def transform(self, motion: Motion) -> PreparedData:
        """Prepare ``motion`` with the learned settings."""
        if not hasattr(self, "root_columns_"):
            raise ParameterError("this Preprocessor is not fitted yet; call fit() first")
        if motion.n_channels != self.n_channels_:
            raise ParameterError(
                f"motion has {motion.n_channels} channels, the "
                f"preprocessor was fitted on {self.n_channels_}"
            )
        return self._transform_poses(self._poses(motion))

    def _transform_poses(self, poses: np.ndarray) -> PreparedData:
        if self.components_ is not None:
            points = ((poses - self.mean_) / self.scale_) @ self.components_.T
        elif self.normalize:
            points = poses / self.scale_
        else:
            points = poses
        if self.delay:
            parts = [points]
            for k in _delays(self.delay):
                k = min(k, len(points))
                parts.append(
                    np.concatenate([np.repeat(points[:1], k, axis=0), points[: len(points) - k]])
                )
            points = np.hstack(parts)
        return PreparedData(
            points=np.ascontiguousarray(points), poses=poses, root_columns=self.root_columns_
        )

    def fit_transform(self, motion: Motion) -> PreparedData:
        """``fit(motion).transform(motion)``, preparing the poses once (the root's
        rotations of a long take are the costliest part of preparing it)."""
        self._setup(motion)
        poses = self._poses(motion)
        self._fit_poses(poses, motion)
        return self._transform_poses(poses)

    def integrate_root(
        self, deltas: np.ndarray, start: np.ndarray, mean_delta: np.ndarray | None, motion: Motion
    ) -> np.ndarray:
        """Turn per-frame root changes of a loop back into root channel values.

        Parameters
        ----------
        deltas : ndarray, shape (P, R)
            Root changes in this preprocessor's form (columns as ``root_columns_``).
        start : ndarray, shape (R,)
            Root channel values of the first frame.
        mean_delta : ndarray, shape (R,), optional
            The mean change per frame the loop should have (the source capture's), so
            that looping the result travels and turns like the original; the deltas are
            shifted by a constant to reach it.
        motion : Motion
            Gives the root's rotation convention (skeleton).

        Returns
        -------
        ndarray, shape (P, R)
            Absolute root values; rotation channels continuous in time (no ±180 jumps).
        """
        d = np.array(deltas, dtype=float)
        if mean_delta is not None:
            d += np.asarray(mean_delta, dtype=float) - d.mean(axis=0)
        cols = self.root_columns_
        if self.root_mode_ != "body":
            out = np.empty_like(d)
            out[0] = start
            out[1:] = start + np.cumsum(d[:-1], axis=0)
            return out
        root, dofs = _root_layout(motion, cols)
        R0 = _root_rotations(_start_frame(start, cols, motion), cols, root, dofs)[0]
        t_idx = [dofs.index(t) for t in ("tx", "ty", "tz")]
        r_idx = [dofs.index("r" + a) for a in "xyz"]
        steps = Rotation.from_rotvec(d[:, r_idx], degrees=True).as_matrix()
        P = len(d)
        R = np.empty((P, 3, 3))
        pos = np.empty((P, 3))
        R[0] = R0
        pos[0] = np.asarray(start, dtype=float)[t_idx]
        for k in range(1, P):
            R[k] = R[k - 1] @ steps[k - 1]
            pos[k] = pos[k - 1] + R[k - 1] @ d[k - 1, t_idx]
        local = np.einsum("ji,tjk,kl->til", root.axis, R, root.axis)
        ang = Rotation.from_matrix(local).as_euler(root.rotation_order, degrees=True)
        ang = np.degrees(np.unwrap(np.radians(ang), axis=0))
        out = np.empty((P, len(cols)))
        for k, a in enumerate(root.rotation_order.lower()):
            out[:, dofs.index("r" + a)] = ang[:, k]
        for k, t in enumerate(("tx", "ty", "tz")):
            out[:, dofs.index(t)] = pos[:, k]
        # keep the first frame's Euler angles exactly as given (same rotation, same numbers)
        first = np.asarray(start, dtype=float)
        shift = np.round((first[r_idx] - out[0, r_idx]) / 360.0) * 360.0
        out[:, r_idx] += shift
        return out
