"""A cycle's quality measured on joint positions, where the rotation channels do not matter.

Loop closure, jerk and step figures computed on channels depend on how a file writes its
rotations: a cycle read back from BVH (three Euler channels a joint) measures otherwise
than from AMC, and an Euler wrap reads as a 360-degree jump.  Here every figure is taken
from **joint positions by forward kinematics, in the root's frame**: each joint's (and end
site's) position minus the travelling root's, turned by the inverse of the root's heading
(the twist of its rotation about the vertical, so the body's lean is kept), plus the
root's height.  Two files holding the same motion give the same numbers, and a pose step
is what a viewer sees: how far the body's points move.

* the **pose step** between two frames is the root-mean-square displacement of those
  points (skeleton length units);
* **seam**: the last-to-first step over the cycle's median step;
* **pop**: the cycle's largest step (seam included) over the capture's 99th-percentile
  step on the frames the cycle was made from;
* **nearest-pose distance**: each cycle pose's distance to the nearest captured pose,
  over the capture's own **spread**, the 90th percentile over captured poses of the
  distance to the nearest pose of another repetition (at least half a period away), and
  at least the capture's median frame step (a capture that repeats exactly has no
  spread of its own).
  Under 1, a cycle pose is as close to something the actor did as nine in ten captured
  poses are to another repetition;
* **jerk**: the mean norm of the points' third derivative (length units / s³), cycle over
  capture (a ratio: no unit to picture).

:func:`cycle_figures` gives a cycle's own three figures the same way, with no capture
beside it: **loop closure** (the seam above), **jerk** in metres per second cubed and the
**largest step** in metres (the skeleton's length unit from
:func:`cyclecoord.rig.describe_rig`).  ``extract``, ``blend``, ``transition``, ``view``,
``batch`` and every report print these, so a cycle read from AMC, BVH, NPZ or glTF reads
the same.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from ..motion import Motion

__all__ = [
    "CycleFigures", "PoseQuality", "cycle_figures", "point_jerk", "root_frame_points",
    "pose_quality",
    "MAX_POP", "MAX_SEAM",
]

#: A cycle step over this many times the capture's 99th-percentile step is a pop.
MAX_POP = 2.0
#: A seam over this many median steps shows.
MAX_SEAM = 1.5
#: Captured frames compared against (a long take is sampled evenly down to this).
MAX_REFERENCE_FRAMES = 20_000
#: The spread is at least this part of the capture's median frame step: a capture that
#: repeats exactly (a synthetic walk) has a spread near 0, and a cycle pose between two of
#: its frames is then as close to a captured pose as the sampling lets it be.
SPREAD_FLOOR = 1.0

#: Captured poses (evenly spaced) whose nearest other repetition gives the spread.
MAX_SPREAD_PROBES = 2_000


def _distinct_points(skeleton, names: list[str]) -> list[int]:
    """Indices of the forward-kinematics points that are not a parent's place again: a
    joint or end site at zero offset from its parent always sits on it (a BVH ``Head``
    end site of length 0; the zero-length bones an ASF adds where a BVH joint's children
    start at different places), and counting it twice would weigh that place double in
    every RMS figure, differently in each format."""
    joints = {j.name: j for j in skeleton.joints}
    scale = max([float(np.linalg.norm(j.offset)) for j in skeleton.joints] + [1e-300])
    keep = []
    for i, n in enumerate(names):
        j = joints.get(n[:-4] if n.endswith("/end") else n)
        off = None if j is None else (j.end_site if n.endswith("/end") else j.offset)
        if i == 0 or off is None or np.linalg.norm(off) > 1e-9 * scale:
            keep.append(i)
    return keep


def root_frame_points(motion: Motion, rig=None, names=None) -> np.ndarray:
    """Joint and end-site positions in the root's frame, plus the root's height.

    Parameters
    ----------
    motion : Motion
        With a skeleton.
    rig : RigInfo, optional
        How to read the rig (:func:`cyclecoord.rig.describe_rig`), so that a cycle is read
        as the capture it came from; default: described afresh.
    names : sequence of str, optional
        Only these points, in this order (forward-kinematics names, end sites
        ``"<joint>/end"``): a cycle read back from a format that lays out its skeleton
        otherwise (ASF bones against BVH joints) is compared point for point.

    Returns
    -------
    ndarray, shape (T, 3 * P + 1)
        Per frame: every point's position minus the travelling root's, turned by the
        inverse of the root's heading (skeleton length units), then the root's up (y)
        coordinate.  Without ``names``, a point at zero offset from its parent (always on
        it) is left out, so each place of the body counts once in every format.
    """
    from ..periodic.root import root_layout, root_rotations
    from ..rig import normalize_rig

    if motion.skeleton is not None:
        motion, _ = normalize_rig(motion, rig, drop_reference=False)  # travelling joint first
    fk = motion.positions()
    pos = np.asarray(fk.positions, dtype=float)  # (T, N, 3)
    if names is not None:
        index = {n: i for i, n in enumerate(fk.names)}
        pos = pos[:, [0] + [index[n] for n in names if n != fk.names[0]], :]
    elif motion.skeleton is not None:
        pos = pos[:, _distinct_points(motion.skeleton, fk.names), :]
    layout = root_layout(motion)
    root = pos[:, :1, :]
    rel = pos - root
    if layout is not None:
        # heading only (the twist of the root's rotation about the vertical): the body's
        # lean stays in the points, so a cycle whose hips tilt back at the seam shows it
        q = Rotation.from_matrix(root_rotations(motion.frames, layout)).as_quat()
        yaw = 2.0 * np.arctan2(q[:, 1], q[:, 3])
        Y = Rotation.from_rotvec(np.outer(yaw, [0.0, 1.0, 0.0])).as_matrix()
        rel = np.einsum("tji,tnj->tni", Y, rel)
    T = pos.shape[0]
    return np.concatenate([rel.reshape(T, -1), root[:, 0, 1:2]], axis=1)


def _steps(x: np.ndarray, cyclic: bool = False) -> np.ndarray:
    n = x.shape[1] // 3 or 1
    d = np.diff(x, axis=0, append=x[:1]) if cyclic else np.diff(x, axis=0)
    return np.linalg.norm(d, axis=1) / np.sqrt(n)


def point_jerk(x: np.ndarray, fps: float, cyclic: bool) -> np.ndarray:
    """Per-frame jerk of :func:`root_frame_points` rows: the norm of the third difference
    times ``fps**3``, RMS over the points (length units / s³).  ``cyclic``: the loop's
    last 3 frames lead into its first, one value per frame (each ending at that frame),
    so the seam counts like any other frame."""
    if cyclic:
        x = np.concatenate([x[-3:], x])
    j = np.diff(x, n=3, axis=0) * fps**3
    n = x.shape[1] // 3 or 1
    return np.linalg.norm(j, axis=1) / np.sqrt(n)


def _jerk(x: np.ndarray, fps: float, cyclic: bool) -> float:
    if len(x) < 5:
        return float("nan")
    return float(np.mean(point_jerk(x, fps, cyclic)))


def _seam(steps: np.ndarray) -> float:
    """Last (seam) step of a loop's cyclic steps over their median."""
    med = float(np.median(steps))
    if med > 0:
        return float(steps[-1] / med)
    return 1.0 if steps[-1] == 0 else float("inf")


@dataclass(frozen=True)
class CycleFigures:
    """A cycle's own figures on joint positions in the root's frame (module notes).

    Attributes
    ----------
    loop_closure : float
        Last-to-first step over the median step around the loop (no unit; up to
        :data:`MAX_SEAM` loops cleanly).
    jerk : float
        Mean norm of the third time derivative of the points around the loop, RMS over the
        body's points, metres / s³.
    largest_step : float
        Largest step around the loop (the seam included), RMS over the points, metres.
    median_step : float
        Median step around the loop, metres.
    metres_per_unit : float
        The skeleton's length unit the figures were converted with.
    """

    loop_closure: float
    jerk: float
    largest_step: float
    median_step: float
    metres_per_unit: float

    def to_dict(self) -> dict:
        return {k: (None if not np.isfinite(v) else float(v)) for k, v in asdict(self).items()}


def _figures(points: np.ndarray, fps: float, metres: float) -> CycleFigures:
    steps = _steps(points, cyclic=True)
    return CycleFigures(
        loop_closure=_seam(steps),
        jerk=_jerk(points, fps, cyclic=True) * metres,
        largest_step=float(steps.max()) * metres,
        median_step=float(np.median(steps)) * metres,
        metres_per_unit=float(metres),
    )


def cycle_figures(cycle: Motion, rig=None, names=None) -> CycleFigures | None:
    """Loop closure, jerk and largest step of a loop, on joint positions.

    The one computation behind every console line and report that gives these figures:
    joint and end-site positions by forward kinematics in the root's heading frame
    (:func:`root_frame_points`), so the rotation channels (Euler orders, wraps, ASF axes,
    quaternions) do not matter.

    Parameters
    ----------
    cycle : Motion
        One loop of frames (frame ``T - 1`` is followed by frame 0), with a skeleton.
    rig : RigInfo, optional
        How to read the rig and its length unit; default :func:`cyclecoord.rig.describe_rig`
        of ``cycle``.
    names : sequence of str, optional
        Only these points (see :func:`root_frame_points`).

    Returns
    -------
    CycleFigures or None
        None without a skeleton or with fewer than 5 frames.
    """
    if cycle.skeleton is None or cycle.n_frames < 5:
        return None
    if rig is None:
        from ..rig import describe_rig

        rig = describe_rig(cycle)
    return _figures(root_frame_points(cycle, rig, names), cycle.fps, rig.metres_per_unit)


@dataclass(frozen=True)
class PoseQuality:
    """A cycle's figures on joint positions (see the module notes).

    Attributes
    ----------
    seam : float
        Last-to-first step over the cycle's median step (no unit).
    pop : float
        Largest cycle step, seam included, over the capture's 99th-percentile step.
    largest_step, p99_capture_step, median_cycle_step : float
        The steps behind them (skeleton length units, RMS over the body's points).
    nearest_max, nearest_median : float
        Largest and median distance from a cycle pose to its nearest captured pose,
        over the capture's spread (no unit).
    spread : float
        The capture's spread (length units).
    jerk_ratio : float
        The cycle's jerk over the capture's.
    capture_jerk : float
        The capture's jerk on the frames the cycle was made from, metres / s³ (the cycle's
        is ``figures.jerk``).
    figures : CycleFigures or None
        The cycle's own loop closure (``seam``), jerk and largest step in metres
        (:func:`cycle_figures`, read with the capture's rig).
    """

    seam: float
    pop: float
    largest_step: float
    p99_capture_step: float
    median_cycle_step: float
    nearest_max: float
    nearest_median: float
    spread: float
    jerk_ratio: float
    capture_jerk: float = float("nan")
    figures: CycleFigures | None = None

    @property
    def pops(self) -> bool:
        return bool(np.isfinite(self.pop) and self.pop > MAX_POP)

    @property
    def seamless(self) -> bool:
        return bool(self.seam <= MAX_SEAM and not self.pops)

    @property
    def strays(self) -> bool:
        """Some cycle pose is farther from every captured pose than the capture's spread."""
        return bool(np.isfinite(self.nearest_max) and self.nearest_max > 1.0)

    def to_dict(self) -> dict:
        out = {k: (None if not np.isfinite(v) else float(v))
               for k, v in asdict(self).items() if k != "figures"}
        out["figures"] = None if self.figures is None else self.figures.to_dict()
        return out


def _point_names(motion: Motion, rig) -> list[str]:
    from ..rig import normalize_rig

    one = motion.with_frames(motion.frames[:1])
    return list(normalize_rig(one, rig, drop_reference=False)[0].positions().names)


def _runs_points(capture: Motion, runs: list[tuple[int, int]], rig, names=None
                 ) -> list[np.ndarray]:
    total = sum(b - a for a, b in runs)
    every = max(1, int(np.ceil(total / MAX_REFERENCE_FRAMES)))
    out = []
    for a, b in runs:
        if b - a >= 2:
            # whole runs, sampled evenly on long takes before forward kinematics
            part = capture.with_frames(capture.frames[a:b:every])
            out.append(root_frame_points(part, rig, names))
    return out


def _capture_steps(capture: Motion, runs: list[tuple[int, int]], rig, names=None
                   ) -> np.ndarray:
    """Frame steps of the capture: every run whole, or on a long take the middle
    :data:`MAX_REFERENCE_FRAMES` frames of its longest run."""
    if sum(b - a for a, b in runs) <= MAX_REFERENCE_FRAMES:
        parts = [root_frame_points(capture.window((a, b)), rig, names)
                 for a, b in runs if b - a >= 2]
        return np.concatenate([_steps(p) for p in parts]) if parts else np.zeros(0)
    a, b = max(runs, key=lambda r: r[1] - r[0])
    mid = (a + b) // 2
    lo, hi = max(a, mid - MAX_REFERENCE_FRAMES // 2), min(b, mid + MAX_REFERENCE_FRAMES // 2)
    return _steps(root_frame_points(capture.window((lo, hi)), rig, names))


def pose_quality(
    cycle: Motion, capture: Motion, runs: list[tuple[int, int]], period: float
) -> PoseQuality | None:
    """Measure ``cycle`` against the frames of ``capture`` it was made from.

    Parameters
    ----------
    cycle : Motion
        The loop, one period of frames.
    capture : Motion
        The capture (same skeleton).
    runs : list of (start, stop)
        The capture's frames the cycle was made from (half-open, 0-based).
    period : float
        Frames per cycle in the capture (the spread compares poses at least half a period
        apart).

    Returns
    -------
    PoseQuality or None
        None without a skeleton or with too few frames.
    """
    if cycle.skeleton is None or capture.skeleton is None or cycle.n_frames < 3:
        return None
    from ..rig import describe_rig

    rig = describe_rig(capture)
    names = None
    cap_names = _point_names(capture, rig)
    cyc_names = _point_names(cycle, rig)
    if cap_names != cyc_names:  # another layout of the same body: the points both have
        names = [n for n in cap_names if n in set(cyc_names)]
        if cap_names[0] != cyc_names[0] or len(names) < 3:
            return None
    parts = _runs_points(capture, runs, rig, names)
    if not parts:
        return None
    every = max(1, int(np.ceil(sum(b - a for a, b in runs) / MAX_REFERENCE_FRAMES)))
    cyc = root_frame_points(cycle, rig, names)
    csteps = _steps(cyc, cyclic=True)
    figures = _figures(cyc, cycle.fps, rig.metres_per_unit) if len(cyc) >= 5 else None
    seam = _seam(csteps)
    cap_steps = _capture_steps(capture, runs, rig, names)
    p99 = float(np.percentile(cap_steps, 99)) if cap_steps.size else float("nan")
    pop = float(csteps.max() / p99) if p99 > 0 else float("nan")
    pts = np.concatenate(parts)
    frame_of = np.concatenate([
        np.arange(a, b)[::every][: len(p)] for (a, b), p in zip(
            [r for r in runs if r[1] - r[0] >= 2], parts)
    ])
    rms = 1.0 / np.sqrt(max(1, pts.shape[1] // 3))  # distances as RMS point distances
    tree = cKDTree(pts * rms)
    near, _ = tree.query(cyc * rms)
    # spread: each captured pose's nearest pose in another repetition
    half = max(1.0, 0.5 * float(period))
    k = int(min(len(pts), max(8, 4 * np.ceil(period / every))))
    probe = np.unique(np.linspace(0, len(pts) - 1, min(len(pts), MAX_SPREAD_PROBES)).astype(int))
    d, idx = tree.query(pts[probe] * rms, k=k)
    far = np.abs(frame_of[idx] - frame_of[probe][:, None]) >= half
    d = np.where(far, d, np.inf)
    best = d.min(axis=1)
    best = best[np.isfinite(best)]
    spread = float(np.percentile(best, 90)) if best.size else float("nan")
    if cap_steps.size:  # the sampling's own resolution (a capture that repeats exactly)
        spread = max(spread, SPREAD_FLOOR * float(np.median(cap_steps)))
    jc = figures.jerk / rig.metres_per_unit if figures is not None else float("nan")
    jo = np.average([_jerk(p, capture.fps / every, False) for p in parts if len(p) >= 5],
                    weights=[len(p) for p in parts if len(p) >= 5]) \
        if any(len(p) >= 5 for p in parts) else float("nan")
    return PoseQuality(
        seam=seam,
        pop=pop,
        largest_step=float(csteps.max()),
        p99_capture_step=p99,
        median_cycle_step=float(np.median(csteps)),
        nearest_max=float(near.max() / spread) if spread > 0 else float("nan"),
        nearest_median=float(np.median(near) / spread) if spread > 0 else float("nan"),
        spread=spread,
        jerk_ratio=float(jc / jo) if jo and np.isfinite(jo) and jo > 0 else float("nan"),
        capture_jerk=float(jo) * rig.metres_per_unit,
        figures=figures,
    )
