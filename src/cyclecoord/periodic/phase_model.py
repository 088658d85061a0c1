"""A fitted phase model: the preparation and the coordinate, saved and applied to new frames.

:class:`PhaseModel` gives the phase of frames a fit never saw — a new take of the same
motion, or frames arriving from a live stream — with the preparation (root
differencing, scaling, PCA) and the coordinate learned on the original capture.  It is
saved as a plain ``.npz`` (no pickle) and loads back without refitting.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .coordinates import CircularCoordinates, unwrap
from ..errors import ParameterError, ParseError
from ..io import atomic_write
from ..motion import Motion
from .preprocess import Preprocessor
from .rotations import RotationMap

__all__ = ["PhaseModel"]

_FORMAT = "cyclecoord-phase-model"
_VERSION = 2  # 2: the joint-rotation map (rotations='rotvec'); 1 still reads


@dataclass
class PhaseModel:
    """Preparation + circular coordinate of one periodic motion.

    Attributes
    ----------
    preprocessor : Preprocessor
        Fitted on the training capture.
    estimator : CircularCoordinates
        Fitted on the prepared training points.
    channels : tuple of (str, str)
        Channels the model expects, in order.
    period_frames : float
        Period measured on the training capture (frames at ``fps``).
    fps : float
    """

    preprocessor: Preprocessor
    estimator: CircularCoordinates
    channels: tuple
    period_frames: float
    fps: float

    @classmethod
    def from_result(cls, result) -> "PhaseModel":
        """The model behind an :class:`~cyclecoord.periodic.pipeline.ExtractionResult`."""
        if result.estimator is None or result.preprocessor is None:
            raise ParameterError("this result carries no fitted model")
        return cls(
            preprocessor=result.preprocessor,
            estimator=result.estimator,
            channels=result.motion.channels,
            period_frames=float(result.period_frames),
            fps=float(result.motion.fps),
        )

    # ---------------------------------------------------------------- apply
    def _check(self, motion: Motion) -> Motion:
        if not isinstance(motion, Motion):
            raise ParameterError(f"expected a Motion, got {type(motion).__name__}")
        if motion.channels != tuple(self.channels):
            if set(self.channels) <= set(motion.channels):
                return motion.select(self.channels)
            missing = [f"{j}.{d}" for j, d in self.channels if (j, d) not in set(motion.channels)]
            raise ParameterError(
                f"the capture lacks {len(missing)} channel(s) "
                f"the model was fitted on, e.g. {missing[:3]}"
            )
        return motion

    def phase(self, motion: Motion) -> np.ndarray:
        """Phase in [0, 1) of every frame of ``motion``, shape (T,)."""
        motion = self._check(motion)
        prepared = self.preprocessor.transform(motion)
        return self.estimator.transform(prepared.points)

    def summary(self, motion: Motion) -> dict:
        """Phase per frame plus cycles and period measured on ``motion`` with this model."""
        theta = self.phase(motion)
        u = unwrap(theta)
        cycles = float(u[-1] - u[0])
        period = (len(theta) - 1) / cycles if cycles > 0 else float("nan")
        return {"coordinate": theta, "cycles": cycles, "period_frames": period}

    # ------------------------------------------------------------- file I/O
    def save(self, path: str | Path) -> None:
        """Write the model to ``path`` (``.npz``, atomically)."""
        p = self.preprocessor
        arrays = {f"cc_{k}": v for k, v in self.estimator.to_arrays().items()}
        arrays.update(
            pre_root_columns=np.asarray(p.root_columns_),
            pre_rot_mask=np.asarray(p.root_rotation_mask_),
            pre_mean=np.asarray(p.mean_),
            pre_scale=np.asarray(p.scale_),
            pre_components=np.asarray(
                p.components_ if p.components_ is not None else np.zeros((0, len(p.mean_)))
            ),
        )
        rmap = getattr(p, "rotation_map_", None)
        if rmap is not None:
            arrays.update({f"rot_{k}": v for k, v in rmap.to_arrays().items()})
        header = {
            "format": _FORMAT,
            "version": _VERSION,
            "channels": [list(c) for c in self.channels],
            "period_frames": self.period_frames,
            "fps": self.fps,
            "difference_root": bool(p.difference_root),
            "normalize": bool(p.normalize),
            "pca": p.pca,
            "root": getattr(p, "root_mode_", "euler"),
            "rotations": "rotvec" if rmap is not None else "euler",
            "delay": None if p.delay is None else np.atleast_1d(p.delay).astype(int).tolist(),
            "n_channels": int(p.n_channels_),
        }
        arrays["header"] = np.array(json.dumps(header))
        with atomic_write(path, "wb") as fh:
            np.savez_compressed(fh, **arrays)

    @classmethod
    def load(cls, path: str | Path) -> "PhaseModel":
        """Read a model written by :meth:`save`."""
        try:
            with np.load(path, allow_pickle=False) as data:
                arrays = {k: data[k] for k in data.files}
        except FileNotFoundError:
            raise ParseError("no such file", path) from None
        except Exception as exc:  # zip or npy format errors
            raise ParseError(f"not a cyclecoord model file ({exc})", path) from None
        try:
            header = json.loads(str(arrays["header"]))
        except (KeyError, ValueError):
            raise ParseError("not a cyclecoord model file (no header)", path) from None
        if header.get("format") != _FORMAT:
            raise ParseError(f"not a cyclecoord model file (format {header.get('format')!r})", path)
        if header.get("version") not in (1, _VERSION):
            raise ParseError(f"model file version {header.get('version')} is not supported", path)
        pre = Preprocessor(
            difference_root=header["difference_root"],
            normalize=header["normalize"],
            pca=header["pca"],
            delay=header.get("delay"),
            root=header.get("root", "euler"),
            rotations="rotvec" if header.get("rotations") == "rotvec" else "euler",
        )
        try:
            pre.root_columns_ = arrays["pre_root_columns"].astype(int)
            pre.root_rotation_mask_ = arrays["pre_rot_mask"].astype(bool)
            pre.root_mode_ = header.get("root", "euler")
            pre.mean_ = arrays["pre_mean"]
            pre.scale_ = arrays["pre_scale"]
            comp = arrays["pre_components"]
            pre.components_ = comp if comp.size else None
            pre.explained_variance_ratio_ = None
            pre.n_channels_ = int(header["n_channels"])
            pre.rotation_map_ = None
            if pre.rotations == "rotvec":
                pre.rotation_map_ = RotationMap.from_arrays(
                    {k[4:]: v for k, v in arrays.items() if k.startswith("rot_")},
                    pre.n_channels_,
                )
            est = CircularCoordinates.from_arrays(
                {k[3:]: v for k, v in arrays.items() if k.startswith("cc_")}
            )
        except (KeyError, ValueError, ParameterError) as exc:
            raise ParseError(f"incomplete model file ({exc})", path) from None
        return cls(
            preprocessor=pre,
            estimator=est,
            channels=tuple(tuple(c) for c in header["channels"]),
            period_frames=float(header["period_frames"]),
            fps=float(header["fps"]),
        )
