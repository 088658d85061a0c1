"""Per-take figures of a loopable cycle, measured against the take and a hand-made loop.

The figures of issue 12 (item 7), each a function with its units:

* :func:`period_error` -- relative error of a period against the autocorrelation's;
* :func:`cycle_jerk` -- mean norm of the cyclic third difference, deg/s^3;
* :func:`leg_ranges` -- max - min of every leg channel over the cycle, degrees;
* :func:`seam` -- last-to-first step over the median step (joint angles);
* :func:`coverage` -- mean distance from the take's frames to the cycle, degrees;
* :func:`foot_skating_speed` -- horizontal speed of feet in contact, length units/s;
* :func:`root_closure` -- last-to-first change of the root's pitch and roll, degrees and
  median steps; :func:`heading_change` -- root turn per cycle, degrees (both from
  :func:`root_orientation`, free of the Euler channels' gimbal lock).

:func:`cycle_quality` gathers them into a :class:`CycleQuality`; :func:`targets` checks
one cycle against a reference (the best loop cut) with the issue's thresholds.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from ..skeleton import rotation_matrices
from .metrics import distance_to_cycle, largest_steps, loop_closure
from .reference import joint_angles, joint_columns, used_mask

__all__ = [
    "LEG_JOINTS",
    "leg_joint_ranges",
    "TARGETS",
    "CycleQuality",
    "period_error",
    "cycle_jerk",
    "leg_channels",
    "leg_ranges",
    "seam",
    "step_spread",
    "largest_step",
    "coverage",
    "foot_skating_speed",
    "root_orientation",
    "root_closure",
    "heading_change",
    "cycle_quality",
    "targets",
]

#: Joint name stems of the leg (CMU: lfemur, ltibia, lfoot, ltoes and the right side).
LEG_JOINTS = ("femur", "tibia", "foot", "toes")
#: Leg channels whose reference range is below this (degrees) are left out of the range
#: ratios: a ratio of two sub-degree ranges measures noise, not a missing swing.
MIN_LEG_RANGE = 2.0

#: The issue's targets for our cycle.
TARGETS = {
    "period_error": 0.05,  # |period / autocorrelation period - 1|
    "root_closure_steps": 1.5,  # or ...
    "root_closure_degrees": 0.5,
    "jerk_ratio": 1.5,  # over the loop cut's
    "leg_range_ratio": 0.85,  # every leg channel, over the loop cut's
    "seam": 1.5,
    "coverage_ratio": 1.0,  # over the loop cut's
    "skating_ratio": 1.0,  # over the take's
}


# --------------------------------------------------------------------- figures
def period_error(period_frames: float, reference_frames: float) -> float:
    """Relative period error ``period / reference - 1`` (a fraction; x100 for %).

    NaN when either period is missing or the reference is not positive.
    """
    if not (np.isfinite(period_frames) and np.isfinite(reference_frames)) or reference_frames <= 0:
        return float("nan")
    return float(period_frames / reference_frames - 1.0)


def cycle_jerk(angles: np.ndarray, fps: float) -> float:
    """Mean norm of the cyclic third difference, times ``fps**3``.

    ``j[t] = x[t+3] - 3 x[t+2] + 3 x[t+1] - x[t]`` with indices taken modulo ``P``, so
    the loop's seam counts like any other frame.

    Parameters
    ----------
    angles : ndarray, shape (P, D)
        One cycle of joint angles, degrees.
    fps : float
        Frames per second.

    Returns
    -------
    float
        ``mean_t |j[t]| * fps**3`` in degrees / s^3.
    """
    x = np.asarray(angles, dtype=float)
    if x.ndim != 2 or x.shape[0] < 4:
        raise ParameterError(
            f"a cycle needs at least 4 frames of (P, D) values for its jerk, got {x.shape}"
        )
    j = np.roll(x, -3, axis=0) - 3 * np.roll(x, -2, axis=0) + 3 * np.roll(x, -1, axis=0) - x
    return float(np.linalg.norm(j, axis=1).mean() * fps**3)


def leg_channels(motion: Motion) -> list[int]:
    """Positions, within :func:`joint_columns`, of the channels of leg joints
    (names ending in one of :data:`LEG_JOINTS`, e.g. ``lfemur``, ``rtoes``)."""
    cols = joint_columns(motion)
    out = []
    for k, c in enumerate(cols):
        name = motion.channels[c][0].lower()
        if any(name.endswith(stem) for stem in LEG_JOINTS) and motion.channels[c][1].startswith(
            "r"
        ):
            out.append(k)
    return out


def leg_ranges(motion: Motion) -> dict[str, float]:
    """Range ``max - min`` over the frames of every leg rotation channel, degrees.

    Returns ``{"lfemur.rx": ..., ...}`` (unwrapped angles); empty when the motion has no
    channel named like a leg joint.
    """
    x = joint_angles(motion)
    cols = joint_columns(motion)
    return {
        "{}.{}".format(*motion.channels[cols[k]]): float(np.ptp(x[:, k]))
        for k in leg_channels(motion)
    }


def leg_joint_ranges(motion: Motion, spike: int = 5) -> dict[str, float]:
    """Range of motion of every leg joint, degrees: the diameter of its angle trajectory.

    For each joint named like a leg joint (:data:`LEG_JOINTS`), the largest distance
    between two frames' angle vectors over the joint's rotation dofs, after a cyclic
    running median over ``spike`` frames.  The median removes the one- and two-frame
    spikes of raw marker data (a toe flicking 25 degrees for a frame) that would
    otherwise decide a raw clip's range, and leaves any extreme held for three frames or
    more.  Per joint, so a femur's 40 degrees of flexion is not judged by its few degrees
    of twist.
    """
    from scipy.ndimage import median_filter

    x = joint_angles(motion)
    cols = joint_columns(motion)
    by_joint: dict[str, list[int]] = {}
    for k in leg_channels(motion):
        by_joint.setdefault(motion.channels[cols[k]][0], []).append(k)
    out = {}
    for joint, ks in by_joint.items():
        y = x[:, ks]
        if spike > 1 and len(y) > spike:
            y = median_filter(y, size=(spike, 1), mode="wrap")
        d = np.linalg.norm(y[:, None, :] - y[None, :, :], axis=2) if len(y) <= 2000 else None
        out[joint] = float(d.max()) if d is not None else float(np.linalg.norm(np.ptp(y, axis=0)))
    return out


def seam(angles: np.ndarray) -> float:
    """Last-to-first step of a cycle over its median frame step (dimensionless; about 1
    for a clean loop).  See :func:`cyclecoord.quality.metrics.loop_closure`."""
    return float(loop_closure(angles))


def step_spread(angles: np.ndarray) -> float:
    """Hold-and-snap: the 90th over the 10th percentile of a cycle's frame steps.

    Steps ``|x[t+1] - x[t]|`` around the loop (the seam included).  A cycle that holds
    still and then moves in a few frames has many tiny steps and some huge ones (tens);
    a capture's own cycle stays within a few.  Dimensionless; ``inf`` when a tenth of
    the steps are zero.  Not one of the issue's targets: a diagnostic, since the jerk of
    a raw loop cut is dominated by capture noise and does not see a hold-and-snap.
    """
    x = np.asarray(angles, dtype=float)
    steps = np.linalg.norm(np.roll(x, -1, axis=0) - x, axis=1)
    lo, hi = np.percentile(steps, [10, 90])
    return float(hi / lo) if lo > 0 else float("inf")


def largest_step(
    angles: np.ndarray, take_angles: np.ndarray, mask: np.ndarray | None = None
) -> float:
    """Pop: a cycle's largest frame step over the take's 99th-percentile step.

    Steps ``|x[t+1] - x[t]|`` around the loop (the seam included) against the steps
    between consecutive used frames of the take.  Above about 1.3 the cycle makes a jump
    its capture hardly ever makes: where an average switches from two repetitions to one
    (a partial repetition starts or stops), or a seam left open.  Dimensionless; a
    diagnostic, not one of the issue's targets (a mean jerk does not see one bad step).
    """
    big, ref = largest_steps(angles, take_angles, mask)
    return big / ref if ref > 0 else float("nan")


def coverage(
    take_angles: np.ndarray, cycle_angles: np.ndarray, mask: np.ndarray | None = None
) -> float:
    """Mean distance from every take frame to the cycle, degrees.

    The cycle is the closed polyline through its frames (so a cycle with more frames
    is not favoured by denser sampling; the nearest *frame* is at most half a step
    further).  ``mask`` selects the take frames measured (the used frames).
    """
    x = np.asarray(take_angles, dtype=float)
    if mask is not None:
        x = x[np.asarray(mask, dtype=bool)]
    return float(distance_to_cycle(x, cycle_angles).mean())


# ------------------------------------------------------------------ foot skating
#: Contact: a foot point within this many leg lengths of its resting level ...
_CONTACT_HEIGHT = 0.05
#: ... and slower (horizontally) than this many leg lengths per second.
_CONTACT_SPEED = 1.0
_FLOOR_QUANTILE = 0.05


def _leg_length(motion: Motion, point: str) -> float:
    """Length of the chain from the root down to a foot point (skeleton units)."""
    skel = motion.skeleton
    j = skel.names.index(point)
    total = 0.0
    while j > 0:
        total += float(np.linalg.norm(skel.joints[j].offset))
        j = skel.joints[j].parent
    return total


def _skating(motion: Motion) -> float:
    """Mean horizontal speed of foot and toe joints in contact (units/s); see
    :func:`foot_skating_speed`."""
    skel = motion.skeleton
    feet = [n for n in skel.names if n.lower().endswith(("foot", "toes", "toe"))]
    if not feet or motion.n_frames < 3:
        return float("nan")
    pos = motion.positions()
    idx = [pos.names.index(n) for n in feet]
    p = pos.positions[:, idx]  # (T, F, 3), y up
    leg = max(_leg_length(motion, n) for n in feet)
    h = p[:, :, 1]
    floor = np.quantile(h.min(axis=1), _FLOOR_QUANTILE)
    level = np.minimum(np.quantile(h, _FLOOR_QUANTILE, axis=0), floor + 0.25 * leg)
    v = np.linalg.norm(np.diff(p[:, :, [0, 2]], axis=0), axis=2) * motion.fps  # (T-1, F)
    hm = 0.5 * (h[1:] + h[:-1])
    contact = (hm <= level + _CONTACT_HEIGHT * leg) & (v <= _CONTACT_SPEED * leg)
    return float(v[contact].mean()) if contact.any() else 0.0


def foot_skating_speed(motion: Motion) -> float:
    """Foot skating: mean horizontal speed of feet while in contact, units/s.

    The one place the contact model lives, so that it can be swapped for
    :mod:`cyclecoord.quality.contacts` (its ``foot_skating(motion).mean_speed``) once that
    module is in.  Until then: foot and toe joints from forward kinematics (y up); a
    point is in contact on a step between two frames when its height is within 5 % of
    the leg length (root-to-foot chain) of its resting level (the 5 % height quantile,
    kept within a quarter leg of the floor, the 5 % quantile of the lowest point) and
    its horizontal speed is under one leg length per second.  The floor is the motion's
    own, so a cycle and its take are each judged on their own ground.

    Returns
    -------
    float
        Skeleton length units per second (CMU: 1 unit = 1/0.45 inch); 0 when no point is
        ever in contact; NaN without a skeleton or foot joints.
    """
    if motion.skeleton is None:
        return float("nan")
    return _skating(motion)


# -------------------------------------------------------------------- root
def _root_columns(motion: Motion) -> dict[str, int]:
    return {motion.channels[c][1]: c for c in motion.root_channels()}


def root_orientation(motion: Motion) -> np.ndarray | None:
    """Heading, pitch and roll of the root per frame, degrees, shape (T, 3).

    From the root's rotation matrix ``R`` (its Euler channels in the skeleton's order,
    y up): the heading turns the root's forward axis (z) in the horizontal plane,
    ``atan2(f_x, f_z)`` with ``f = R e_z``; with the heading taken out
    (``R_y(-heading) R``), pitch and roll tilt the root's up axis ``u`` about x and z,
    ``atan2(u_z, u_y)`` and ``atan2(-u_x, u_y)``.  Unlike the Euler channels these do not
    flip near gimbal lock (a CMU root facing 90 degrees has rx and rz degenerate).
    Without a skeleton the channels ry, rx, rz are returned as they are.  All three are
    unwrapped along time.  None when the root has no rotation channels.
    """
    rc = _root_columns(motion)
    if not {"rx", "ry", "rz"} <= set(rc):
        return None
    skel = motion.skeleton
    root = skel.joints[0] if skel is not None else None
    if root is None or not root.rotation_order:
        hpr = motion.frames[:, [rc["ry"], rc["rx"], rc["rz"]]]
        return np.unwrap(hpr, period=360.0, axis=0)
    vals = motion.frames[:, [rc["r" + ax] for ax in root.rotation_order.lower()]]
    R = rotation_matrices(vals, root.rotation_order)
    if not np.allclose(root.axis, np.eye(3)):
        R = root.axis @ R @ root.axis.T
    f = R[:, :, 2]
    heading = np.arctan2(f[:, 0], f[:, 2])
    c, s = np.cos(heading), np.sin(heading)
    u = R[:, :, 1]
    ux = c * u[:, 0] - s * u[:, 2]  # R_y(-heading) applied to the up axis
    uz = s * u[:, 0] + c * u[:, 2]
    pitch = np.arctan2(uz, u[:, 1])
    roll = np.arctan2(-ux, u[:, 1])
    return np.unwrap(np.degrees(np.column_stack([heading, pitch, roll])), period=360.0, axis=0)


def root_closure(cycle: Motion) -> tuple[float, float]:
    """How far the root's pitch and roll are from closing the loop.

    Pitch and roll as in :func:`root_orientation` (for a root facing along z with a
    small tilt, about the AMC channels rx and rz).

    Returns
    -------
    (degrees, steps)
        ``|(pitch, roll)[last] - (pitch, roll)[first]|`` in degrees, and that over the
        median frame step of ``(pitch, roll)`` in the cycle; ``(nan, nan)`` without root
        rotation channels.
    """
    hpr = root_orientation(cycle)
    if hpr is None or len(hpr) < 2:
        return float("nan"), float("nan")
    r = hpr[:, 1:]
    gap = float(np.linalg.norm(r[-1] - r[0]))
    med = float(np.median(np.linalg.norm(np.diff(r, axis=0), axis=1)))
    steps = gap / med if med > 0 else (0.0 if gap == 0 else float("inf"))
    return gap, steps


def heading_change(cycle: Motion) -> float:
    """Turn of the root heading over one loop, degrees (heading as in
    :func:`root_orientation`).

    ``(h[last] - h[first]) * P / (P - 1)``: the change over the ``P - 1`` steps inside
    the cycle extended by the one step of the seam.  NaN without root rotations.
    """
    hpr = root_orientation(cycle)
    if hpr is None or cycle.n_frames < 2:
        return float("nan")
    P = cycle.n_frames
    return float((hpr[-1, 0] - hpr[0, 0]) * P / (P - 1))


# ------------------------------------------------------------------- summary
@dataclass
class CycleQuality:
    """The figures of one cycle of one take (see the module functions for units).

    ``min_femur_tibia_ratio`` is the smallest leg range ratio over femur and tibia
    channels only (the toes and feet of a raw capture carry the most noise, which widens
    the loop cut's ranges).  ``*_ratio`` fields compare with the reference (the best loop
    cut) or the take and are NaN when there is none.
    """

    method: str
    n_frames: int
    period_frames: float
    reference_period: float
    period_error: float
    jerk: float
    jerk_ratio: float
    leg_ranges: dict
    leg_range_ratios: dict
    min_leg_range_ratio: float
    min_leg_channel: str | None
    min_femur_tibia_ratio: float
    joint_ranges: dict
    joint_range_ratios: dict
    min_joint_range_ratio: float
    min_joint: str | None
    seam: float
    step_spread: float
    largest_step: float
    coverage: float
    coverage_ratio: float
    skating: float
    skating_take: float
    skating_ratio: float
    root_closure_degrees: float
    root_closure_steps: float
    heading_change: float
    extra: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """JSON-ready (NaN becomes None)."""

        def clean(v):
            if isinstance(v, dict):
                return {k: clean(w) for k, w in v.items()}
            if isinstance(v, (float, np.floating)):
                return float(v) if np.isfinite(v) else None
            if isinstance(v, np.integer):
                return int(v)
            return v

        return {k: clean(v) for k, v in asdict(self).items()}


def _ratio(a: float, b: float) -> float:
    if not (np.isfinite(a) and np.isfinite(b)) or b == 0:
        return float("nan")
    return float(a / b)


def cycle_quality(
    cycle: Motion,
    take: Motion,
    *,
    method: str = "cycle",
    period_frames: float | None = None,
    reference_period: float = float("nan"),
    reference: "CycleQuality | None" = None,
    used_frames: list | None = None,
    skating_take: float | None = None,
) -> CycleQuality:
    """Every figure of ``cycle`` (a loopable clip) measured against its ``take``.

    Parameters
    ----------
    cycle : Motion
        The cycle, same channels as the take.
    take : Motion
        The capture it summarises.
    method : str
        Label (``"ours"``, ``"loop cut"``, ``"average"``).
    period_frames : float, optional
        The period claimed for the cycle (default its frame count).
    reference_period : float
        The autocorrelation period, frames.
    reference : CycleQuality, optional
        The loop cut's figures; jerk, leg ranges and coverage are given over its.
    used_frames : list of [start, stop], optional
        Take frames measured by coverage (default all).
    skating_take : float, optional
        The take's own skating (computed when not given).
    """
    if cycle.channels != take.channels:
        raise ParameterError(f"the {method} cycle's channels differ from the take's")
    mask = used_mask(take.n_frames, used_frames)
    take_x = joint_angles(take)
    cyc_x = joint_angles(cycle, like=take_x[mask].mean(axis=0))
    period = float(cycle.n_frames if period_frames is None else period_frames)
    ranges = leg_ranges(cycle)
    ratios = {}
    if reference is not None:
        ratios = {
            k: _ratio(v, reference.leg_ranges[k])
            for k, v in ranges.items()
            if reference.leg_ranges.get(k, 0.0) >= MIN_LEG_RANGE
        }
    low = min(ratios, key=ratios.get) if ratios else None
    joints = leg_joint_ranges(cycle)
    joint_ratios = {}
    if reference is not None:
        joint_ratios = {
            k: _ratio(v, reference.joint_ranges[k])
            for k, v in joints.items()
            if reference.joint_ranges.get(k, 0.0) >= MIN_LEG_RANGE
        }
    low_joint = min(joint_ratios, key=joint_ratios.get) if joint_ratios else None
    jerk = cycle_jerk(cyc_x, cycle.fps)
    cov = coverage(take_x, cyc_x, mask)
    skate = foot_skating_speed(cycle)
    skate_take = foot_skating_speed(take) if skating_take is None else float(skating_take)
    gap, steps = root_closure(cycle)
    return CycleQuality(
        method=method,
        n_frames=int(cycle.n_frames),
        period_frames=period,
        reference_period=float(reference_period),
        period_error=period_error(period, reference_period),
        jerk=jerk,
        jerk_ratio=_ratio(jerk, reference.jerk) if reference else float("nan"),
        leg_ranges=ranges,
        leg_range_ratios=ratios,
        min_leg_range_ratio=float(ratios[low]) if low else float("nan"),
        min_leg_channel=low,
        min_femur_tibia_ratio=min(
            (v for k, v in ratios.items() if k.split(".")[0].endswith(("femur", "tibia"))),
            default=float("nan"),
        ),
        joint_ranges=joints,
        joint_range_ratios=joint_ratios,
        min_joint_range_ratio=float(joint_ratios[low_joint]) if low_joint else float("nan"),
        min_joint=low_joint,
        step_spread=step_spread(cyc_x),
        largest_step=largest_step(cyc_x, take_x, mask),
        seam=seam(cyc_x),
        coverage=cov,
        coverage_ratio=_ratio(cov, reference.coverage) if reference else float("nan"),
        skating=skate,
        skating_take=skate_take,
        skating_ratio=_ratio(skate, skate_take),
        root_closure_degrees=gap,
        root_closure_steps=steps,
        heading_change=heading_change(cycle),
    )


def targets(q: CycleQuality) -> dict[str, bool | None]:
    """The issue's targets for a cycle whose figures were taken against the loop cut.

    Returns ``{target: passed}``, None where the figure is missing (no reference period,
    no reference, no root or feet).
    """

    def check(value: float, ok) -> bool | None:
        return None if not np.isfinite(value) else bool(ok(value))

    t = TARGETS
    root_ok = None
    if np.isfinite(q.root_closure_degrees):
        root_ok = bool(
            q.root_closure_steps <= t["root_closure_steps"]
            or q.root_closure_degrees <= t["root_closure_degrees"]
        )
    return {
        "period": check(q.period_error, lambda v: abs(v) <= t["period_error"]),
        "root": root_ok,
        "jerk": check(q.jerk_ratio, lambda v: v <= t["jerk_ratio"]),
        "legs": check(q.min_joint_range_ratio, lambda v: v >= t["leg_range_ratio"]),
        "seam": check(q.seam, lambda v: v <= t["seam"]),
        "coverage": check(q.coverage_ratio, lambda v: v <= t["coverage_ratio"]),
        "skating": check(q.skating_ratio, lambda v: v <= t["skating_ratio"]),
    }
