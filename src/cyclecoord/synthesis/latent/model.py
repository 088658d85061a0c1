"""A latent motion model: influence scaling, PCA and a GPLVM over one kind of motion.

:class:`LatentModel` chains the paper's Sec. 4: joint angles scaled by influence
(:mod:`.influence`), PCA to the components explaining 85 % of the variance, and the
GPLVM (:mod:`.gplvm`).  It maps latent points to poses (Eq. 8, linear in the number of
training frames), gives the predictive variance and its gradient (the particle's
likelihood force) and keeps the training frames, their segments and the root motion
per frame, so a synthesised walk can walk.  Models are saved to and loaded from ``.npz``.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import ParameterError, ParseError
from ...io._limits import check_memory
from ...motion import Motion
from ...skeleton import Skeleton
from .gplvm import GPLVM, rbf, sqdist
from .influence import influence_weights

__all__ = ["LatentModel", "RootTrack", "heading_matrix", "root_track"]

_FORMAT = "cyclecoord-latent-model"
_VERSION = 1


def heading_matrix(theta: np.ndarray) -> np.ndarray:
    """Rotations ``(T, 3, 3)`` by ``theta`` (radians) about the vertical y axis (z -> x)."""
    c, s = np.cos(theta), np.sin(theta)
    m = np.zeros(np.shape(theta) + (3, 3))
    m[..., 0, 0], m[..., 0, 2], m[..., 1, 1], m[..., 2, 0], m[..., 2, 2] = c, s, 1.0, -s, c
    return m


@dataclass(frozen=True)
class RootTrack:
    """Root motion per training frame, free of where and which way the capture went.

    Attributes
    ----------
    height : ndarray, shape (N,)
        Root height (y), length units.
    velocity : ndarray, shape (N, 2)
        Horizontal velocity (x, z) in the root's heading frame, units per second.
    turn : ndarray, shape (N,)
        Heading rate about the vertical, radians per second.
    tilt : ndarray, shape (N, 3, 3)
        Root rotation with the heading removed.
    """

    height: np.ndarray
    velocity: np.ndarray
    turn: np.ndarray
    tilt: np.ndarray


def root_position_problem(motion: Motion) -> str | None:
    """Why ``motion`` cannot train a latent model's root (its root has no position
    channel on some axis), or None."""
    root = motion.skeleton.joints[0].name
    have = set(motion.channels)
    missing = [d for d in ("tx", "ty", "tz") if (root, d) not in have]
    if not missing:
        return None
    return (f"a latent model needs the root's position; root {root!r} has no "
            f"{', '.join(missing)} channel")


def root_track(motion: Motion) -> RootTrack:
    """The :class:`RootTrack` of one contiguous capture (y up, CMU facing +z at rest)."""
    from ..align import root_rotation

    mats, _, _ = root_rotation(motion)
    pos = motion.frames[
        :, [motion.channel_index(motion.skeleton.joints[0].name, d) for d in ("tx", "ty", "tz")]
    ]
    fwd = mats[:, :, 2]
    theta = np.arctan2(fwd[:, 0], fwd[:, 2])
    head = heading_matrix(theta)
    tilt = np.transpose(head, (0, 2, 1)) @ mats
    n = motion.n_frames
    step = np.diff(pos, axis=0, append=pos[-1:] + (pos[-1:] - pos[-2:-1] if n > 1 else 0))
    local = np.einsum("tba,tb->ta", head, step)  # head^T @ step
    dth = np.diff(
        np.unwrap(theta),
        append=np.unwrap(theta)[-1] if n < 2 else 2 * np.unwrap(theta)[-1] - np.unwrap(theta)[-2],
    )
    return RootTrack(
        height=pos[:, 1].copy(),
        velocity=local[:, [0, 2]] * motion.fps,
        turn=dth * motion.fps,
        tilt=tilt,
    )


class LatentModel:
    """One kind of motion as a low-dimensional latent space (Bailey et al. Sec. 4).

    Parameters
    ----------
    n_components : int, default 3
        Latent dimension.
    variance : float, default 0.85
        Fraction of the scaled data's variance the PCA keeps (at least ``n_components + 1``
        components are kept, as the GPLVM reduces the PCA space further).
    gplvm : dict, optional
        Further :class:`~.gplvm.GPLVM` parameters.
    random_state : int, default 0

    Attributes
    ----------
    channels_ : tuple of (joint, dof)
        The modelled joint-angle channels (every channel but the root's).
    root_channels_ : tuple of (joint, dof)
    all_channels_ : tuple of (joint, dof)
        Every channel of the training frames, in their order.
    skeleton_ : Skeleton
    fps_ : float
        Rate of the training frames.
    frames_ : ndarray, shape (N, D)
        Training frames, every channel (root first as in the capture).
    segments_ : ndarray of int, shape (N,)
    segment_names_ : list of str
    times_ : ndarray, shape (N,)
        Seconds from each segment's start.
    mean_, weights_ : ndarray, shape (C,)
        Mean pose and influence weights (Eq. 3).
    components_ : ndarray, shape (C, d_pca)
        ``T_pca``.
    Y_ : ndarray, shape (N, d_pca)
    gp_ : GPLVM
    X_ : ndarray, shape (N, q)
    root_ : RootTrack
    gait_stale_ : bool
        Loaded from a file whose gait phases came from an older cyclecoord (or had
        none): they are computed again on use, and written by :meth:`save`.
    """

    def __init__(
        self,
        n_components: int = 3,
        variance: float = 0.85,
        gplvm: dict | None = None,
        random_state: int = 0,
    ) -> None:
        self.n_components = n_components
        self.variance = variance
        self.gplvm = gplvm
        self.random_state = random_state

    # ------------------------------------------------------------------ fitting
    def fit(
        self, motions: Sequence[Motion], names: Sequence[str] | None = None, *,
        progress: bool = False,
        gait: bool = True,
    ) -> LatentModel:
        """Fit to training segments (each a contiguous capture; same channels and rate).

        Parameters
        ----------
        motions : sequence of Motion
            With skeletons; their root channels drive :attr:`root_`, every other
            channel is modelled.
        names : sequence of str, optional
            One name per segment (default ``"segment0"``, ...).
        progress : bool, default False
            A tqdm bar on stderr over the GPLVM's optimisation (shown after 1 s).
        gait : bool, default True
            Also find the gait phase of every training frame (:meth:`gait`; a segment
            without a cycle gets none), which MOVEs ``ahead`` and in-step TRANSITIONs use.
        """
        from ...rig import analysis_motion

        if not motions:
            raise ParameterError("a latent model needs at least one training segment")
        if any(m.skeleton is None for m in motions):
            raise ParameterError(
                "a latent model needs motions with a skeleton (forward kinematics)"
            )
        # the analysis rig (every frame kept): the travelling joint is the root and Y is
        # up, so a static root with moving hips (the Bandai rig) does not put the hips'
        # travel among the modelled angles; the model and what it makes use that rig
        motions = [analysis_motion(m) for m in motions]
        first = motions[0]
        problem = root_position_problem(first)
        if problem:  # the root's travel is modelled apart (root_track): it must be there
            raise ParameterError(f"training segment 0: {problem}")
        for i, m in enumerate(motions):
            if m.channels != first.channels:
                raise ParameterError(f"training segment {i} has different channels from segment 0")
            if abs(m.fps - first.fps) > 1e-9:
                raise ParameterError(
                    f"training segment {i} is at {m.fps:g} fps, segment 0 at {first.fps:g}"
                )
            if m.n_frames < 3:
                raise ParameterError(
                    f"training segment {i} has {m.n_frames} frames; at least 3 are needed"
                )
        if not 0 < self.variance <= 1:
            raise ParameterError(f"variance must be in (0, 1], got {self.variance}")
        root = set(first.root_channels())
        self.root_channels_ = tuple(first.channels[i] for i in sorted(root))
        self.channels_ = tuple(c for i, c in enumerate(first.channels) if i not in root)
        self.all_channels_ = first.channels
        self.skeleton_ = first.skeleton
        self.fps_ = float(first.fps)
        self.segment_names_ = (
            list(names) if names is not None else [f"segment{i}" for i in range(len(motions))]
        )
        if len(self.segment_names_) != len(motions):
            raise ParameterError(f"{len(self.segment_names_)} names for {len(motions)} segments")
        self.frames_ = np.concatenate([m.frames for m in motions])
        self._centres = self._chart = None  # angle_centres() and chart() of these frames
        self.segments_ = np.concatenate([np.full(m.n_frames, i) for i, m in enumerate(motions)])
        self.times_ = np.concatenate([np.arange(m.n_frames) / m.fps for m in motions])
        tracks = [root_track(m) for m in motions]
        self.root_ = RootTrack(
            *(
                np.concatenate([getattr(t, f) for t in tracks])
                for f in ("height", "velocity", "turn", "tilt")
            )
        )
        angles = self.angles(self.frames_)
        self.mean_ = angles.mean(axis=0)
        self.weights_ = influence_weights(
            angles, self.channels_, self.skeleton_, to_channels=self.to_channels
        )
        Z = (angles - self.mean_) * self.weights_
        _, S, Vt = np.linalg.svd(Z, full_matrices=False)
        if not S.size or not S[0] > 1e-12:  # nothing to learn (and a log of zero variance)
            raise ParameterError(
                f"segments {self.segment_names_}: no joint angle changes over the training "
                "frames; a model needs motion"
            )
        ratio = np.cumsum(S**2) / max((S**2).sum(), 1e-300)
        d_pca = int(np.searchsorted(ratio, self.variance - 1e-12) + 1)
        d_pca = max(d_pca, int(self.n_components) + 1)
        d_pca = min(d_pca, Vt.shape[0])
        self.explained_variance_ = float(ratio[d_pca - 1])
        self.components_ = Vt[:d_pca].T
        self.Y_ = Z @ self.components_
        self.gp_ = GPLVM(
            n_components=self.n_components, random_state=self.random_state, **(self.gplvm or {})
        ).fit(self.Y_, self.segments_, self.times_, progress=progress)
        self._precompute()
        self.gait_, self.gait_stale_ = None, False
        if gait:
            self.gait()
        return self

    def gait(self):
        """The gait phase of every training frame (:func:`~.gait.training_gait`, from the
        periodic pipeline's circular coordinate; computed once, saved with the model)."""
        if getattr(self, "gait_", None) is None:
            from .gait import training_gait

            self.gait_ = training_gait(self)
        return self.gait_

    def _precompute(self) -> None:
        self.X_ = self.gp_.X_
        self._detail = None
        self._frame_angles = None
        self._reference_rows: dict | None = None
        inv_w = np.where(
            self.weights_ > 0, 1.0 / np.where(self.weights_ > 0, self.weights_, 1.0), 0.0
        )
        # pose(x) = mean + k(x) @ B: Eq. 8's mean taken back through PCA and the scaling
        self._B = (self.gp_.alpha_ @ self.components_.T) * inv_w
        self._l2 = self.gp_.lengthscale_**2
        steps = np.linalg.norm(np.diff(self.X_, axis=0), axis=1)
        same = self.segments_[1:] == self.segments_[:-1]
        self.speed_ = float(np.median(steps[same]) * self.fps_) if same.any() else 1.0
        self._root_h2 = float((2.0 * np.median(steps[same]) if same.any() else 0.1) ** 2)

    # -------------------------------------------------------------- mappings
    def angles(self, frames: np.ndarray) -> np.ndarray:
        """The model's angles ``(T, C)`` of full frames ``(T, D)``: the modelled channels,
        each on the branch within 180 degrees of its centre (:meth:`angle_centres`), the
        joints of :meth:`chart` re-expressed about their mean rotation."""
        cols = self._columns()
        return self.to_model(np.asarray(frames, dtype=float)[:, cols])

    def _columns(self) -> list[int]:
        """Columns of the modelled channels in full frames."""
        modelled = set(self.channels_)
        return [i for i, c in enumerate(self.all_channels_) if c in modelled]

    def _centred(self, x: np.ndarray) -> np.ndarray:
        c = self.angle_centres()
        # whole turns only, and only where needed: a value on the branch keeps its bits
        return np.where(np.abs(x - c) > 180.0, x - 360.0 * np.round((x - c) / 360.0), x)

    def chart(self) -> tuple:
        """The joints modelled about their mean rotation: ``(columns, order, mean)`` per
        joint, ``columns`` its three channels (of :attr:`channels_`) in Euler order.

        A joint whose Euler channels wrap, flip or come near gimbal lock in the training
        frames (:func:`~cyclecoord.periodic.rotations.euler_is_safe`; the Bandai rig's
        thighs at +-180 and its spine at 88 degrees of the middle angle) is modelled as
        the Euler angles of ``mean^T R``, a rotation within a few tens of degrees of the
        identity, whose angles are continuous and far from gimbal lock; as written, a GP
        mean between two frames of one pose written two ways twisted the spine (the
        Bandai walk-run script's head accelerated 18.7x the training 99th percentile).
        The model's angles (:meth:`angles`, :meth:`pose`) are in this chart;
        :meth:`to_channels` gives the rig's channels back.  Empty on every CMU take we
        hold: their channels are modelled as written.
        """
        ch = getattr(self, "_chart", None)
        if ch is None:
            ch = self._chart = self._fit_chart()
        return ch

    def _fit_chart(self) -> tuple:
        import warnings

        from scipy.spatial.transform import Rotation

        from ...periodic.rotations import euler_is_safe

        cols = self._columns()
        x = self._centred(np.asarray(self.frames_, dtype=float)[:, cols])
        out = []
        for idx, order in self.rotation_columns():
            if euler_is_safe(x[:, idx]):
                continue
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message=".*[Gg]imbal.*")
                mean = Rotation.from_euler(order, x[:, idx], degrees=True).mean()
            out.append((idx, order, mean.as_matrix()))
        return tuple(out)

    def rotation_columns(self) -> list[tuple[np.ndarray, str]]:
        """``(columns, order)`` of each joint with three rotation channels: its columns of
        :attr:`channels_` in its Euler order (upper case)."""
        by_joint: dict[str, dict[str, int]] = {}
        for k, (j, d) in enumerate(self.channels_):
            if d in ("rx", "ry", "rz"):
                by_joint.setdefault(j, {})[d[1]] = k
        out = []
        for j, c in by_joint.items():
            order = self.skeleton_[j].rotation_order.upper()
            if len(c) == 3 and sorted(order) == ["X", "Y", "Z"]:
                out.append((np.array([c[a.lower()] for a in order], dtype=int), order))
        return out

    def to_model(self, values: np.ndarray) -> np.ndarray:
        """Channel values ``(T, C)`` of :attr:`channels_` (degrees) in the model's chart."""
        import warnings

        from scipy.spatial.transform import Rotation

        x = self._centred(np.atleast_2d(np.asarray(values, dtype=float)))
        for idx, order, mean in self.chart():
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message=".*[Gg]imbal.*")
                R = Rotation.from_euler(order, x[:, idx], degrees=True)
                x[:, idx] = (Rotation.from_matrix(mean).inv() * R).as_euler(order, degrees=True)
        return x

    def to_channels(self, angles: np.ndarray, continuous: bool = False) -> np.ndarray:
        """The model's angles ``(T, C)`` as the rig's channel values (degrees).

        Parameters
        ----------
        angles : ndarray, shape (T, C)
        continuous : bool, default False
            Each charted joint's Euler angles continuous over the rows, starting nearest
            the first training frame (for a motion); otherwise each row on its own
            (any valid angles: enough for forward kinematics).
        """
        from scipy.spatial.transform import Rotation

        from ...conventions import continuous_euler

        a = np.array(np.atleast_2d(angles), dtype=float)
        if not self.chart():
            return a
        for idx, order, mean in self.chart():
            R = Rotation.from_matrix(mean) * Rotation.from_euler(order, a[:, idx], degrees=True)
            if continuous:
                near = self._centred(self._channels0()[None])[0, idx]
                a[:, idx] = continuous_euler(R.as_matrix()[:, None], order, near)[:, 0]
            else:
                a[:, idx] = R.as_euler(order, degrees=True)
        return a

    def _channels0(self) -> np.ndarray:
        cols = self._columns()
        return np.asarray(self.frames_[0], dtype=float)[cols]

    def angle_centres(self) -> np.ndarray:
        """``(C,)`` degrees: each modelled channel's branch centre, its circular mean over
        the training frames rounded to a multiple of 180.

        An angle near +-180 (the Bandai rig's thighs) wraps from one end to the other in
        the capture; modelled as written, the PCA and the GP saw 360-degree jumps and
        the model made poses of averages of -179 and 179.  Centred, the channel is
        continuous; rounded, the centre is the same for every model of a rig (a walk's
        and a run's thighs), so their poses blend.  Channels whose mean is within 90
        degrees of 0 (every CMU channel) keep their values.
        """
        c = getattr(self, "_centres", None)
        if c is None or c.shape != (len(self.channels_),):
            from ...periodic.rotations import circular_mean_degrees

            cols = self._columns()
            mean = circular_mean_degrees(np.asarray(self.frames_, dtype=float)[:, cols])
            c = 180.0 * np.round(mean / 180.0)
            c[c <= -180.0] += 360.0  # one name for the half turn: 180, never -180
            self._centres = c
        return c

    def kernel(self, X: np.ndarray) -> np.ndarray:
        """``k(x)`` for latent points ``(T, q)``: ``(T, N)``."""
        return rbf(np.atleast_2d(X), self.X_, self.gp_.variance_, self._l2)

    def pose(self, X: np.ndarray) -> np.ndarray:
        """Joint angles (degrees) ``(T, C)`` of latent points ``(T, q)`` (Eq. 8's mean)."""
        return self.mean_ + self.kernel(X) @ self._B

    def frame_angles(self) -> np.ndarray:
        """The model's angles ``(N, C)`` of its training frames (degrees; computed once).
        A gait loops every part of a pose at the seam these choose
        (:meth:`~.gait.Gait.at` ``seam``)."""
        if self._frame_angles is None:
            self._frame_angles = self.angles(self.frames_)
        return self._frame_angles

    def detail(self) -> dict[str, np.ndarray]:
        """What the model leaves out of each training frame: ``"angles"`` ``(N, C)``
        (degrees, the model's angles of :meth:`angles`) the GP mean at the frame's latent
        point misses, and ``"height"``, ``"velocity"``, ``"turn"``, ``"tilt"`` (shaped as
        :class:`RootTrack`'s) the root weights of the frame's latent point miss.

        The angles' part is what the PCA's components do not span (the GP reproduces the
        frames' PCA coordinates within 0.1 % of their spread): with four components on
        the Bandai run the hips' range is 0.89 of the capture's and the toes hover 1-4 cm,
        so the support foot slips 1.7x the capture's.  The root's is what the weights'
        average over neighbouring frames smooths away, the pelvis's sway with each step,
        which the legs' detailed angles go with.  A gait plays both back at the phase it
        steps through (:class:`~.commands.Synthesizer` ``detail``)."""
        if self._detail is None:
            w = self.root_weights(self.X_)
            r = self.root_
            self._detail = {
                "angles": self.frame_angles() - self.pose(self.X_),
                "height": r.height - w @ r.height,
                "velocity": r.velocity - w @ r.velocity,
                "turn": r.turn - w @ r.turn,
                "tilt": r.tilt - np.einsum("tn,nab->tab", w, r.tilt),
            }
        return self._detail

    def pca_coordinates(self, angles: np.ndarray) -> np.ndarray:
        """Eq. 13: joint angles ``(T, C)`` into this model's PCA space ``(T, d_pca)``."""
        return ((np.atleast_2d(angles) - self.mean_) * self.weights_) @ self.components_

    def mean_y(self, X: np.ndarray) -> np.ndarray:
        """GP mean in PCA space ``(T, d_pca)``."""
        return self.kernel(X) @ self.gp_.alpha_

    def predictive_variance(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """Predictive variance ``k(x, x) - k(x)^T K^-1 k(x)`` of the noise-free GP (Eq. 8)
        at latent point ``x`` (q,) and its gradient (time quadratic in the training size)."""
        diff = x[None, :] - self.X_
        k = self.gp_.variance_ * np.exp(-0.5 * np.einsum("ij,ij->i", diff, diff) / self._l2)
        u = self.gp_.kinv_times(k)
        var = max(self.gp_.variance_ - float(k @ u), 0.0)
        grad = (2.0 / self._l2) * ((u * k) @ diff)
        return var, grad

    def density(self, x: np.ndarray) -> tuple[float, np.ndarray]:
        """Likelihood proxy ``p(x|M) = s_w / (s_w + sigma^2(x))`` in (0, 1] and its gradient.

        ``sigma^2(x)`` is :meth:`predictive_variance` and ``s_w`` the white noise variance: ``p`` is
        near 1 where the GP knows the pose up to the data's own noise and falls towards
        0 away from the training points.  (Normalising by the RBF variance instead gives
        a proxy that stays near 1 wherever the fitted length scale exceeds the data's
        extent, which it often does.)
        """
        var, grad = self.predictive_variance(x)
        w = self.gp_.noise_
        p = w / (w + var)
        return p, (-w / (w + var) ** 2) * grad

    def densities(self, X: np.ndarray) -> np.ndarray:
        """:meth:`density` (without gradient) of many latent points ``(T, q)`` at once."""
        K = self.kernel(X)
        var = np.maximum(self.gp_.variance_ - ((K @ self.gp_.kinv_) * K).sum(1), 0.0)
        return self.gp_.noise_ / (self.gp_.noise_ + var)

    def nearest_frame(self, X: np.ndarray) -> np.ndarray:
        """Index of the training frame nearest each latent point ``(T, q)``."""
        return np.argmin(sqdist(np.atleast_2d(X), self.X_), axis=1)

    def root_weights(self, X: np.ndarray) -> np.ndarray:
        """Normalised weights ``(T, N)`` of the training frames near each latent point."""
        d2 = sqdist(np.atleast_2d(X), self.X_)
        w = np.exp(-0.5 * (d2 - d2.min(axis=1, keepdims=True)) / self._root_h2)
        return w / w.sum(axis=1, keepdims=True)

    def segment_index(self, name: str) -> int:
        try:
            return self.segment_names_.index(name)
        except ValueError:
            raise KeyError(name) from None

    def describe(self) -> dict:
        """Sizes and hyperparameters for reports."""
        return {
            "frames": int(self.X_.shape[0]),
            "segments": list(self.segment_names_),
            "fps": self.fps_,
            "channels": len(self.channels_),
            "pca_components": int(self.components_.shape[1]),
            "explained_variance": self.explained_variance_,
            "latent_dims": int(self.X_.shape[1]),
            "rbf_variance": self.gp_.variance_,
            "lengthscale": self.gp_.lengthscale_,
            "white_variance": self.gp_.noise_,
            "latent_speed_per_s": self.speed_,
            "joints_about_their_mean_rotation": [
                self.channels_[idx[0]][0] for idx, _, _ in self.chart()
            ],
            "gait": self._gait_summary(),
        }

    def _gait_summary(self) -> list[dict] | None:
        """Per segment: its gait's cycle (s) and the seconds of the segment whose frames
        have a gait phase (frames a period beyond the steady ones have none: standing
        before a walk); None where the gait is not computed yet."""
        g = getattr(self, "gait_", None)
        if g is None:
            return None
        out = []
        for s, name in enumerate(self.segment_names_):
            times = self.times_[self.segments_ == s]
            rows = g.rows(s) if g.has(s) else np.zeros(0, int)
            out.append({
                "segment": str(name),
                "seconds": float(times[-1] - times[0]) if times.size else 0.0,
                "cycle_s": float(g.period[s] / self.fps_) if g.has(s) else None,
                "phase_from_s": float(self.times_[rows[0]] - times[0]) if rows.size else None,
                "phase_to_s": float(self.times_[rows[-1]] - times[0]) if rows.size else None,
            })
        return out

    def is_reference_frame(self, k: int) -> bool:
        """Whether training frame ``k`` is a reference pose: the first frame of a segment
        whose capture begins with one (an Xsens T-pose; :func:`cyclecoord.rig.describe_rig`).
        """
        from ...errors import CycleCoordError
        from ...rig import describe_rig

        k = int(k)
        idx = np.flatnonzero(self.segments_ == self.segments_[k])
        if k != idx[0] or idx.size < 10:
            return False
        if self._reference_rows is None:
            self._reference_rows = {}
        if k not in self._reference_rows:  # each segment's capture described once
            seg = Motion(frames=self.frames_[idx], channels=self.all_channels_,
                         fps=self.fps_, skeleton=self.skeleton_)
            try:
                self._reference_rows[k] = bool(describe_rig(seg).reference_frame)
            except CycleCoordError:
                self._reference_rows[k] = False
        return self._reference_rows[k]

    def training_motion(self) -> Motion:
        """The training frames as one motion (segments end to end), made once per ``frames_``
        array (a script asked some ten times, each object's positions found again)."""
        if self.__dict__.get("_train", (None,))[0] is not self.frames_:
            self._train = (self.frames_, Motion(self.frames_, self.all_channels_, self.fps_,
                                                self.skeleton_))
        return self._train[1]

    # --------------------------------------------------------------- storage
    def save(self, path: str | os.PathLike[str]) -> None:
        """Write the model and its training frames to ``path`` (``.npz``, atomic), with
        its gait phases (computed now for a model loaded from a file whose phases came
        from an older cyclecoord, so that they are not computed again on every load)."""
        from ...io import atomic_write
        from ...io.tabular import read_npz, write_npz  # noqa: F401

        train = Motion(
            frames=self.frames_, channels=self.all_channels_, fps=self.fps_, skeleton=self.skeleton_
        )
        with tempfile.TemporaryDirectory() as tmp:
            write_npz(train, Path(tmp) / "train.npz")
            with np.load(Path(tmp) / "train.npz", allow_pickle=False) as data:
                arrays = {f"motion_{k}": data[k] for k in data.files}
        arrays.update(
            {
                "format": np.array(_FORMAT),
                "version": np.array(_VERSION),
                "segments": self.segments_,
                "times": self.times_,
                "segment_names": np.array(json.dumps(self.segment_names_)),
                "n_modelled": np.array(len(self.channels_)),
                "n_root": np.array(len(self.root_channels_)),
                "mean": self.mean_,
                "weights": self.weights_,
                "components": self.components_,
                "Y": self.Y_,
                "X": self.X_,
                "explained_variance": np.array(self.explained_variance_),
                "hyper": np.array([self.gp_.variance_, self.gp_.lengthscale_, self.gp_.noise_]),
                "params": np.array(
                    json.dumps(
                        {
                            "n_components": self.n_components,
                            "variance": self.variance,
                            "gplvm": self.gplvm,
                            "random_state": self.random_state,
                        }
                    )
                ),
            }
        )
        # a file whose phases were stale gets them now, so they are not computed again
        g = self.gait() if self.gait_stale_ else getattr(self, "gait_", None)
        if g is not None:
            from .gait import GAIT_VERSION

            arrays.update({"gait_phase": g.phase, "gait_period": g.period,
                           "gait_version": np.array(GAIT_VERSION)})
            if g.fade is not None:
                arrays["gait_fade"] = g.fade
        with atomic_write(path, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> LatentModel:
        """Read a model written by :meth:`save`.

        Raises
        ------
        ParseError
            One line naming the file and the array: not a readable archive (a truncated
            or corrupted zip), not a latent model, a missing array, an array of the wrong
            dtype or shape, values that are not finite, sizes that do not agree, or a
            model too large for the memory limit.
        """
        from ...io.tabular import _Arrays, _open_npz, npz_motion

        p = Path(path)
        spath = str(p)
        if not p.is_file():
            raise ParseError("no such file" if not p.exists() else "not a file", spath)
        arrays = _open_npz(p, spath)  # zip integrity, no pickle, within the size cap
        a = _Arrays(arrays, spath)
        if "format" not in arrays or a.text("format") != _FORMAT:
            raise ParseError(f"not a latent model (no format '{_FORMAT}')", spath)
        version = a.integer("version", -(2**62), 2**62)
        if version != _VERSION:
            raise a.error("version", f"model version {version}; this cyclecoord reads {_VERSION}")
        train = npz_motion(
            _Arrays({k[7:]: v for k, v in arrays.items() if k.startswith("motion_")}, spath,
                    "motion_")
        )
        if train.skeleton is None:
            raise a.error("motion_has_skeleton", "a model's training frames need their skeleton")
        N = train.n_frames
        # the kernel matrix, its inverse and the temporaries of _finish and densities()
        check_memory(48.0 * N * N, f"a model of {N:,} training frames", spath)
        params = _json(a, "params", dict)
        unknown = sorted(set(params) - {"n_components", "variance", "gplvm", "random_state"})
        if unknown:
            raise a.error("params", f"unknown key(s) {unknown}")
        try:
            m = cls(**params)
            m.gplvm = None if m.gplvm is None else dict(m.gplvm)
        except (TypeError, ValueError):
            raise a.error("params", "expects n_components, variance, gplvm, random_state") from None
        m.all_channels_ = train.channels
        root = set(train.root_channels())
        m.root_channels_ = tuple(c for i, c in enumerate(train.channels) if i in root)
        m.channels_ = tuple(c for i, c in enumerate(train.channels) if i not in root)
        n_root = a.integer("n_root", 0, len(train.channels))
        n_modelled = a.integer("n_modelled", 0, len(train.channels))
        if len(m.root_channels_) != n_root or len(m.channels_) != n_modelled:
            raise ParseError("the stored training frames do not match the model's channels", p)
        C = n_modelled
        if C < 1:
            raise a.error("n_modelled", "a model needs at least one modelled channel")
        names = [str(x) for x in _json(a, "segment_names", list)]
        if not names:
            raise a.error("segment_names", "a model needs at least one segment")
        if len(set(names)) != len(names):
            twice = sorted({x for x in names if names.count(x) > 1})
            raise a.error("segment_names", f"names repeat: {twice[:5]}")
        m.segment_names_ = names
        m.skeleton_, m.fps_, m.frames_ = train.skeleton, train.fps, np.array(train.frames)
        m.segments_ = np.asarray(a.integers("segments", N, 0, len(names) - 1))
        empty = sorted(set(range(len(names))) - set(m.segments_.tolist()))
        if empty:
            raise a.error("segments", f"segment {empty[0]} ({names[empty[0]]!r}) has no frames")
        m.times_ = a.reals("times", (N,))
        comp = a.get("components")
        d = comp.shape[1] if comp.ndim == 2 else 0
        if not 1 <= d <= C:
            raise a.error("components", f"expected shape ({C}, d) with 1 <= d <= {C}, got "
                          f"{comp.shape}")
        X = a.get("X")
        q = X.shape[1] if X.ndim == 2 else 0
        if not 1 <= q <= d:
            raise a.error("X", f"expected shape ({N}, q) with 1 <= q <= {d}, got {X.shape}")
        m.mean_ = a.reals("mean", (C,))
        m.weights_ = a.reals("weights", (C,))
        if (m.weights_ < 0).any():
            raise a.error("weights", "influence weights are never negative")
        m.components_ = a.reals("components", (C, d))
        m.Y_ = a.reals("Y", (N, d))
        X = a.reals("X", (N, q))
        m.explained_variance_ = a.real("explained_variance")
        hyper = a.reals("hyper", (3,))
        if not (hyper > 0).all():
            raise a.error("hyper", f"variance, length scale and noise are positive, got {hyper}")
        try:
            m.gp_ = GPLVM.from_arrays(X, *hyper, m.Y_)
        except ParameterError as exc:
            raise ParseError(f"arrays 'X', 'hyper', 'Y': {exc}", spath) from None
        m.gait_ = None
        # phases saved by an older training_gait, or none: computed again on every load
        # (run_script says so; saving the model again keeps them)
        m.gait_stale_ = "gait_phase" not in arrays
        if "gait_phase" in arrays:  # files written before the gait phase compute it on use
            from .gait import GAIT_VERSION, Gait

            phase = a.reals("gait_phase", (N,), allow_nan=True)  # NaN: a segment without gait
            period = a.get("gait_period")
            S = period.shape[0] if period.ndim == 1 else -1
            if S < len(names):
                raise a.error("gait_period", f"expected one period per segment ({len(names)}), "
                              f"got shape {period.shape}")
            period = a.reals("gait_period", (S,), allow_nan=True)
            if (period <= 0).any():
                raise a.error("gait_period", "frames per cycle are positive")
            fade = None  # (files written before the seam fades were kept choose on use)
            if "gait_fade" in arrays:
                fade = a.reals("gait_fade", (S,))
                if (fade <= 0).any():
                    raise a.error("gait_fade", "seam cross-fades are positive cycles")
            # phases from an older training_gait (or none said) are computed again on use
            if "gait_version" in arrays and a.integer("gait_version", 0, GAIT_VERSION) == (
                    GAIT_VERSION):
                m.gait_ = Gait(phase, period, m.segments_, fade)
            else:
                m.gait_stale_ = True
        starts = np.flatnonzero(np.r_[True, m.segments_[1:] != m.segments_[:-1]])
        stops = np.r_[starts[1:], len(m.segments_)]
        try:
            tracks = [root_track(train[a:b]) for a, b in zip(starts, stops)]
        except (KeyError, ValueError, ParameterError) as exc:
            raise ParseError(f"training frames: no root motion to take ({exc})", spath) from None
        m.root_ = RootTrack(
            *(
                np.concatenate([getattr(t, f) for t in tracks])
                for f in ("height", "velocity", "turn", "tilt")
            )
        )
        with np.errstate(all="ignore"):
            m._precompute()
        if not (np.isfinite(m.speed_) and m.speed_ > 0 and np.isfinite(m._B).all()):
            raise a.error("X", "the latent points do not move (no latent speed), or the pose "
                          "map is not finite")
        return m


def _json(a, key: str, kind: type):
    """The JSON value a string array holds, of type ``kind`` (size and depth checked first)."""
    from ...io._limits import metadata_problem

    text = a.text(key)
    problem = metadata_problem(text)
    if problem is not None:
        raise a.error(key, problem)
    try:
        value = json.loads(text)
    except (ValueError, RecursionError):
        raise a.error(key, "not valid JSON") from None
    if not isinstance(value, kind):
        raise a.error(key, f"expected a JSON {kind.__name__}, got {type(value).__name__}")
    return value


def _check_skeleton(a: Skeleton, b: Skeleton) -> bool:
    """Whether two skeletons have the same joints and dofs (bone lengths may differ)."""
    return [(j.name, j.dofs) for j in a.joints] == [(j.name, j.dofs) for j in b.joints]
