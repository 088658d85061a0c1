"""One measure of generated motion, judged against the captures it came from.

:func:`measure_generated` answers what an animator asks of a generated motion (a motion
graph's path, a latent script, a blend or a transition), each figure beside the same
figure of the source captures (resampled to the motion's rate):

* **feet**: contact from the height of each foot point above its own ground level, *not*
  gated by speed (:func:`~cyclecoord.quality.contacts.foot_contacts` with ``speed=None``;
  a foot gliding along the floor is on it), the median speed of feet in contact and the
  frames on which one moves faster than the old speed-gated test allowed, and the
  **support-foot slip**: the horizontal speed of the lowest foot point on each frame
  (central differences), median over frames, in m/s and leg lengths/s.  A planted walk
  scores about 0.09 m/s, a capture's run about 0.6; a motion whose feet glide scores the
  body's speed;
* **ground penetration**: how far the lowest foot point goes under the sources' floor;
* **freezes**: runs longer than :data:`FREEZE_SECONDS` whose pose speed (RMS joint speed
  relative to the root, heading removed) is under :data:`FREEZE_FRACTION` of the sources'
  median, outside the frames where a hold was asked (``hold``);
* **stride amplitude**: knee and hip flexion p1-p99 ranges per leg against the sources'
  median (over takes and legs), over the frames outside the asked holds when at least
  :data:`STRIDE_SECONDS` of them are left (a stand is no stride: a script that stood 3
  of its 6 s read its knees at 0.39 of the sources');
* **cadence**: the leg cycle (peak of the knee angle's autocorrelation between 0.4 and
  2.5 s; over the longest run of frames outside the holds when it spans two of the
  sources' cycles, else over all) against the sources' cycle at the same root speed
  (interpolated between the takes' median root speeds);
* **pops**: the largest pose step and the largest joint acceleration relative to the
  root (heading removed) against the sources' 99th percentiles, and the root's own
  horizontal acceleration (velocity averaged over 0.1 s) against theirs, which
  the joints' cannot see (a latent run set off from an IDLE at 3.5 m/s in two frames
  read 1.05x there, 4.4x here);
* **root speed**: median horizontal root speed over 0.5 s windows (outside the holds
  asked) against the sources'.

The sources' speeds, slip and accelerations are taken over the frames where each take
moves (:func:`~cyclecoord.quality.generated_kinematics._moving`), so a take that stands
still before and after its walk (the Xsens walk stands for 14 of its 25 s) is judged by
its walk, not by its standing.  The kinematics it reads (legs, root-relative poses, leg
cycle, support foot) live in :mod:`cyclecoord.quality.generated_kinematics`.

A motion on a body of another size than its sources' (a script whose run model was
captured on a smaller actor, written on the walk's skeleton) is compared per leg length:
the ratios of slip, root speed, pose step and acceleration divide the motion's figure by
its leg length over the sources' (:attr:`GeneratedQuality.body_scale`, said on the
console).  Played unchanged on subject 35's skeleton, whose legs are 1.18x subject 143's,
143_01's own jog read an acceleration 1.19x its p99 in units/s²; the same angular
motion on longer bones is not a more violent one.

The figures follow the definitions of an independent checker's (its own forward
kinematics); ``tests/quality/test_generated.py`` compares them on a graph output and on a
captured take.  Distances are in metres from the sources' skeleton unit
(:func:`~cyclecoord.rig.metres_per_unit`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from ..errors import ParameterError
from ..motion import Motion
from .contacts import contact_runs, foot_contacts
from .generated_kinematics import (  # noqa: F401  (names callers and tests use from here)
    CYCLE_PEAK,
    CYCLE_RANGE,
    MOVING_FRACTION,
    ROOT_WINDOW,
    _angle,
    _cycle,
    _Kin,
    _kin,
    _lowest,
    _moving,
    _over,
    _ranges,
    _resampled,
    _Rig,
    _rig,
    _support,
    _windows,
)

__all__ = [
    "GeneratedQuality",
    "SourceFigures",
    "source_figures",
    "mixed_reference",
    "measure_generated",
    "FREEZE_FRACTION",
    "FREEZE_SECONDS",
    "STRIDE_SECONDS",
]

#: A frame is frozen when its pose speed is under this fraction of the sources' median.
FREEZE_FRACTION = 0.1
#: A freeze lasts longer than this, in seconds.
FREEZE_SECONDS = 0.2
#: Seconds outside the asked holds from which strides and cadence are measured (fewer:
#: over every frame, and the console says the motion mostly stands).
STRIDE_SECONDS = 1.0
#: Support-foot slip up to this multiple of the sources' is "planted" (the issue's target).
PLANTED_RATIO = 1.5
#: Above this multiple the feet "glide" (between the two they "slip").
GLIDING_RATIO = 4.0
#: Leg lengths within this fraction of the sources' are the same body (nothing said).
BODY_SAME = 0.02
#: A foot point deeper than this (metres) under the floor counts as under it.
PENETRATION_M = 0.02
#: Height band (leg lengths) above a foot point's ground level that counts as contact: 0.03
#: (about 2.5 cm) keeps heel strike and toe-off, whose feet still move, mostly out of it
#: (in-contact median speed on 35_07: 0.12 m/s at 0.03, 0.15 at 0.05).
CONTACT_HEIGHT = 0.03
#: In-contact speed (leg lengths/s) the old, speed-gated contact test stopped at.
FAST_CONTACT = 0.5


# ------------------------------------------------------------------ sources
@dataclass(frozen=True)
class SourceFigures:
    """The sources' figures a generated motion is compared with (at one frame rate)."""

    fps: float
    metres: float  # metres per unit
    leg_length: float  # units
    floor: float  # units
    pose_speed_median: float  # units/s
    step_p99: float  # units/s (pose speed)
    accel_p99: float  # units/s^2
    support_slip: float  # units/s, median
    knee_range: float  # degrees, median over takes and legs
    hip_range: float
    take_speed: np.ndarray  # (S,) median root speed per take, units/s
    take_cycle: np.ndarray  # (S,) leg cycle per take, s
    penetration: float  # fraction of frames deeper than PENETRATION_M under the floor
    contact_slide: float  # units/s, median speed of foot points in contact
    knee_range_legs: tuple[float, ...] = ()  # degrees per leg, median over takes
    hip_range_legs: tuple[float, ...] = ()
    #: fraction of frames on which a foot in contact moves faster than FAST_CONTACT
    sliding_fraction: float = float("nan")
    root_accel_p99: float = float("nan")  # units/s^2, horizontal (the root's own)

    @property
    def root_speed(self) -> float:
        return float(np.median(self.take_speed))

    def cycle_at(self, speed: float) -> float:
        ok = np.isfinite(self.take_cycle)
        if not ok.any():
            return float("nan")
        s, c = self.take_speed[ok], self.take_cycle[ok]
        order = np.argsort(s)
        return float(np.interp(speed, s[order], c[order]))


def source_figures(
    sources: Sequence[Motion], fps: float, feet: Sequence[str] | None = None,
    *, analysed: bool = False, cache: dict | None = None,
) -> SourceFigures:
    """The figures of the source captures, resampled to ``fps`` (a whole-number step).

    A source is taken every ``k = round(source fps / fps)`` frames when ``k > 1`` and its
    rate then lands within 5 % of ``fps``; otherwise it is used at its own rate.
    ``analysed``: the sources are already in the analysis rig
    (:func:`~cyclecoord.rig.analysis_motion`; a latent model's training takes are).
    ``cache``: a dict kept between calls on overlapping sets of sources (a latent script
    measures each model's takes and all of them): each take's own figures are found
    once per take object, rate and legs (sources are not changed in place meanwhile).
    """
    from ..rig import analysis_motion, metres_per_unit

    if not sources:
        raise ParameterError("the measure of generated motion needs the source captures")
    srcs = [_resampled(s if analysed else analysis_motion(s), fps) for s in sources]
    rig = _rig(srcs[0], feet)
    # what a take's figures use of the rig: its joints (not the first source's leg length:
    # a walk and a jog of two actors had the jog's takes measured once for each)
    rkey = (float(fps), tuple(rig.feet), tuple(rig.foot_cols), tuple(rig.hips),
            tuple(rig.knees), tuple(rig.ankles), rig.trunk)

    def kept(kind, orig, make):
        if cache is None:
            return make()
        key = (kind, id(orig), rkey)
        entry = cache.get(key)
        if entry is None or entry[0] is not orig:  # (the take is kept: its id stays its own)
            entry = cache[key] = (orig, make())
        return entry[1]

    takes = [kept("take", o, lambda s=s: _take_figures(s, rig)) for o, s in zip(sources, srcs)]
    floor = float(np.median([t["floor"] for t in takes]))
    ps = np.concatenate([t["pose_speed"] for t in takes])
    lowest = np.concatenate([t["lowest"] for t in takes])
    metres = metres_per_unit(sources[0])
    slides = [kept(("slide", floor), o, lambda s=s: _contact_speeds(s, rig, floor)[0::2])
              for o, s in zip(sources, srcs)]
    n_frames = np.array([s.n_frames for s in srcs], dtype=float)
    return SourceFigures(
        fps=float(fps),
        metres=metres,
        leg_length=rig.leg_length,
        floor=floor,
        pose_speed_median=float(np.median(ps)),
        step_p99=float(np.percentile(ps, 99)),
        accel_p99=float(np.percentile(np.concatenate([t["accel"] for t in takes]), 99)),
        root_accel_p99=float(np.percentile(np.concatenate([t["root_accel"] for t in takes]),
                                           99)),
        support_slip=float(np.median(np.concatenate([t["support"] for t in takes]))),
        knee_range=float(np.median(np.concatenate([t["knee"] for t in takes]))),
        hip_range=float(np.median(np.concatenate([t["hip"] for t in takes]))),
        take_speed=np.array([t["speed"] for t in takes]),
        take_cycle=np.array([t["cycle"] for t in takes]),
        penetration=float(np.mean(floor - lowest > PENETRATION_M / metres)),
        contact_slide=float(np.median(np.concatenate([sl[0] for sl in slides]))),
        sliding_fraction=float(np.average([sl[1] for sl in slides], weights=n_frames)),
        knee_range_legs=tuple(float(x) for x in np.median([t["knee"] for t in takes], 0)),
        hip_range_legs=tuple(float(x) for x in np.median([t["hip"] for t in takes], 0)),
    )


def mixed_reference(parts: Sequence[tuple[SourceFigures, float]]) -> SourceFigures:
    """The sources' figures for a motion several models made, ``parts`` each model's own
    figures (:func:`source_figures` of its takes, at one rate) with the frames it made:
    each figure is the frame-weighted mean of the models' (the takes' speeds and cycles
    joined).  Pooling the takes instead judges the motion by whichever model has the
    most training frames: a subject 35 walk and 143_01 jog script that mostly jogged read
    "feet gliding" (0.40 m/s against the walk-heavy 0.06) while the walk's and the jog's
    frames, each against their own takes, read planted."""
    from dataclasses import replace

    refs = [r for r, _ in parts]
    w = np.array([float(n) for _, n in parts])
    w = w / w.sum() if w.sum() > 0 else np.full(len(refs), 1.0 / len(refs))

    def mean(name: str) -> float:
        return float(sum(wi * getattr(r, name) for r, wi in zip(refs, w)))

    def legs(name: str) -> tuple[float, ...]:
        sets = [getattr(r, name) for r in refs]
        if not sets[0] or any(len(x) != len(sets[0]) for x in sets):
            return ()
        return tuple(float(v) for v in np.tensordot(w, np.asarray(sets, dtype=float), 1))

    return replace(
        refs[0],
        floor=mean("floor"),
        pose_speed_median=mean("pose_speed_median"),
        step_p99=mean("step_p99"),
        accel_p99=mean("accel_p99"),
        root_accel_p99=mean("root_accel_p99"),
        support_slip=mean("support_slip"),
        knee_range=mean("knee_range"),
        hip_range=mean("hip_range"),
        take_speed=np.concatenate([r.take_speed for r in refs]),
        take_cycle=np.concatenate([r.take_cycle for r in refs]),
        penetration=mean("penetration"),
        contact_slide=mean("contact_slide"),
        sliding_fraction=mean("sliding_fraction"),
        knee_range_legs=legs("knee_range_legs"),
        hip_range_legs=legs("hip_range_legs"),
    )


def _take_figures(s: Motion, rig: _Rig) -> dict[str, Any]:
    """One source take's own figures (:func:`source_figures` pools them)."""
    k = _kin(s, rig)
    moving = _moving(k)
    rs = k.root_speed()
    return {
        "floor": foot_contacts(s, rig.feet).floor,
        "speed": float(np.median(rs[_windows(moving, rs.size)])),
        "cycle": k.cycle(),
        "pose_speed": k.pose_speed()[moving[:-1]],
        "lowest": _lowest(k, rig),
        "accel": k.accel()[moving[1:-1]],
        "root_accel": k.root_accel()[moving[1:-1]],
        "support": _support(k, rig)[moving[1:-1]],
        "knee": _ranges(k.knee),
        "hip": _ranges(k.hip),
    }


def _contact_speeds(motion: Motion, rig: _Rig, floor: float):
    """Speeds (units/s) of foot points in contact (height only), the contacts and the
    fraction of frames on which one in contact is faster than :data:`FAST_CONTACT`."""
    c = foot_contacts(motion, rig.feet, speed=None, height=CONTACT_HEIGHT, floor=floor)
    spd = c.speed[c.planted]
    fast = (c.planted & (c.speed > FAST_CONTACT * c.leg_length)).any(axis=1).mean()
    return (spd if spd.size else np.zeros(1)), c, float(fast)


def _leg_ratios(
    ranges: tuple[float, ...], legs: tuple[float, ...], pooled: float
) -> tuple[float, ...]:
    """Range over the sources', leg by leg: a capture measured against itself reads 1 on
    each leg (against the range pooled over legs, the Bandai run's right hip read 0.91 of
    its own sources: that leg swings less than the left)."""
    refs = legs if len(legs) == len(ranges) else (pooled,) * len(ranges)
    return tuple(k / max(r, 1e-9) for k, r in zip(ranges, refs))


# ------------------------------------------------------------------ result
@dataclass(frozen=True)
class GeneratedQuality:
    """The measure of a generated motion against its sources (:func:`measure_generated`).

    Lengths in metres, speeds in m/s (and leg lengths/s), ratios against the sources'
    figure at the motion's frame rate.
    """

    frames: int
    fps: float
    feet: tuple[str, ...]
    leg_length_m: float
    support_slip: float
    support_slip_legs: float
    source_support_slip: float
    contact_fraction: dict[str, float]
    contact_slide: float
    source_contact_slide: float
    sliding_fraction: float
    penetration_m: float
    penetration_fraction: float
    source_penetration_fraction: float
    freezes: list[tuple[int, int]]
    longest_freeze_s: float
    knee_range: tuple[float, ...]
    hip_range: tuple[float, ...]
    source_knee_range: float
    source_hip_range: float
    cycle_s: float
    source_cycle_s: float
    largest_step: float
    largest_step_frame: int
    largest_accel: float
    largest_accel_frame: int
    root_speed: float
    source_root_speed: float
    held_frames: int = 0
    notes: list[str] = field(default_factory=list)
    knee_p99: tuple[float, ...] = ()  # degrees of flexion per leg (the table)
    #: the sources' ranges leg by leg (median over takes), which the ratios use
    source_knee_legs: tuple[float, ...] = ()
    source_hip_legs: tuple[float, ...] = ()
    #: the motion's leg length over the sources': every ratio of a length (slip, root
    #: speed, pose step, acceleration) is taken per leg length, so a motion played on a
    #: bigger body than its sources' is not a faster or more violent one
    body_scale: float = 1.0
    source_sliding_fraction: float = float("nan")
    #: frames the stride ranges and the cadence are measured on (those outside the asked
    #: holds when :data:`STRIDE_SECONDS` of them are left, else all; 0: all, as before)
    stride_frames: int = 0
    #: the root's own horizontal acceleration over the sources' p99, and its frame: the
    #: joint measure is taken against the root and cannot see the root lurch (a run set
    #: off from an IDLE at 3.5 m/s in two frames read 1.05x there)
    largest_root_accel: float = float("nan")
    largest_root_accel_frame: int = 0

    # ---- derived
    @property
    def slip_ratio(self) -> float:
        """Support-foot slip over the sources', per leg length."""
        return self.support_slip / self.body_scale / max(self.source_support_slip, 1e-9)

    @property
    def feet_word(self) -> str:
        """``"planted"`` (slip within 1.5x the sources'), ``"slipping"`` or ``"gliding"``
        (over 4x: the feet slide with the body)."""
        r = self.slip_ratio
        return (
            "planted" if r <= PLANTED_RATIO else ("slipping" if r <= GLIDING_RATIO else "gliding")
        )

    @property
    def knee_ratio(self) -> tuple[float, ...]:
        """Each leg's knee range over the sources' range of the same leg (over their range
        pooled over legs when the leg counts differ)."""
        return _leg_ratios(self.knee_range, self.source_knee_legs, self.source_knee_range)

    @property
    def hip_ratio(self) -> tuple[float, ...]:
        return _leg_ratios(self.hip_range, self.source_hip_legs, self.source_hip_range)

    @property
    def cadence_ratio(self) -> float:
        return self.cycle_s / max(self.source_cycle_s, 1e-9)

    @property
    def root_ratio(self) -> float:
        """Root speed over the sources', per leg length."""
        return self.root_speed / self.body_scale / max(self.source_root_speed, 1e-9)

    def headline(self) -> str:
        """The first line of a report: feet, freezes, strides, pops, speed."""
        knees = "/".join(f"{r:.2f}" for r in self.knee_ratio)
        return (
            f"generated motion: feet {self.feet_word} (support foot {self.support_slip:.2f} m/s, "
            f"sources {self.source_support_slip:.2f}); longest freeze "
            f"{self.longest_freeze_s:.2f} s; knee range {knees} of the sources'; largest accel "
            f"{self.largest_accel:.2f}x the sources' p99; root {self.root_speed:.2f} m/s "
            f"(sources {self.source_root_speed:.2f})"
        )

    def summary(self) -> list[str]:
        """Console lines, the headline first."""
        lines = [self.headline()]
        lines.append(
            f"  feet: support-foot slip {self.support_slip:.2f} m/s "
            f"({self.support_slip_legs:.2f} leg lengths/s, {self.slip_ratio:.1f}x the sources'); "
            f"in contact (height only) "
            + ", ".join(f"{k} {100 * v:.0f}%" for k, v in self.contact_fraction.items())
            + f"; a foot in contact moves {self.contact_slide:.2f} m/s (median; sources "
            f"{self.source_contact_slide:.2f}), faster than {FAST_CONTACT} leg lengths/s on "
            f"{100 * self.sliding_fraction:.0f}% of frames"
            + ("" if not np.isfinite(self.source_sliding_fraction)
               else f" (sources {100 * self.source_sliding_fraction:.0f}%: heel strike and "
               "toe-off)")
        )
        lines.append(
            f"  floor: lowest foot {100 * self.penetration_m:.1f} cm under the sources' floor, "
            f"{100 * self.penetration_fraction:.0f}% of frames over "
            f"{100 * PENETRATION_M:.0f} cm under "
            f"(sources {100 * self.source_penetration_fraction:.0f}%)"
        )
        if self.freezes:
            spans = ", ".join(f"{a}-{b}" for a, b in self.freezes[:4])
            more = f" and {len(self.freezes) - 4} more" if len(self.freezes) > 4 else ""
            lines.append(
                f"  freezes: {len(self.freezes)} (pose speed under {FREEZE_FRACTION:.0%} of the "
                f"sources' median over {FREEZE_SECONDS} s): frames {spans}{more}"
                + (f"; {self.held_frames} held frames asked for" if self.held_frames else "")
            )
        else:
            lines.append(
                "  freezes: none"
                + (f" ({self.held_frames} held frames asked for)" if self.held_frames else "")
            )
        hips = "/".join(f"{r:.2f}" for r in self.hip_ratio)
        knees = "/".join(f"{r:.2f}" for r in self.knee_ratio)
        where = ""
        if self.held_frames and self.stride_frames and self.stride_frames < self.frames:
            where = f" (over the {self.stride_frames} frames outside the holds)"
        elif self.held_frames and self.frames - self.held_frames < STRIDE_SECONDS * self.fps:
            where = (f" (the motion stands on {self.held_frames} of its {self.frames} frames, "
                     "as asked: no stride to judge)")
        lines.append(
            f"  strides{where}: knee range {knees}, hip range {hips} of the sources' "
            f"({self.source_knee_range:.0f} / {self.source_hip_range:.0f} deg); leg cycle "
            + (
                f"{self.cycle_s:.2f} s against the sources' {self.source_cycle_s:.2f} s at "
                f"this root speed ({self.cadence_ratio:.2f}x)"
                if np.isfinite(self.source_cycle_s)
                else f"{self.cycle_s:.2f} s (the sources give none: under two knee swings each)"
            )
        )
        lines.append(
            f"  pops: largest pose step {self.largest_step:.2f}x (frame "
            f"{self.largest_step_frame}), largest accel {self.largest_accel:.2f}x (frame "
            f"{self.largest_accel_frame}) the sources' p99; root speed {self.root_speed:.2f} "
            f"m/s, {self.root_ratio:.2f}x the sources'; root acceleration "
            f"{self.largest_root_accel:.2f}x theirs (frame {self.largest_root_accel_frame})"
        )
        if abs(self.body_scale - 1.0) > BODY_SAME:
            lines.append(
                f"  body: legs {self.body_scale:.2f}x the sources' ({self.leg_length_m:.2f} m): "
                "slip, root speed, steps and accelerations are compared per leg length"
            )
        lines.extend(f"  {n}" for n in self.notes)
        return lines

    def to_dict(self) -> dict:
        """JSON-ready figures."""

        def f(x: float) -> float | None:
            return float(x) if np.isfinite(x) else None

        return {
            "frames": self.frames,
            "fps": self.fps,
            "feet": list(self.feet),
            "feet_verdict": self.feet_word,
            "leg_length_m": f(self.leg_length_m),
            "body_scale": f(self.body_scale),
            "support_slip_m_per_s": f(self.support_slip),
            "support_slip_leg_lengths_per_s": f(self.support_slip_legs),
            "sources_support_slip_m_per_s": f(self.source_support_slip),
            "support_slip_ratio": f(self.slip_ratio),
            "contact_fraction": {k: float(v) for k, v in self.contact_fraction.items()},
            "contact_slide_m_per_s": f(self.contact_slide),
            "sources_contact_slide_m_per_s": f(self.source_contact_slide),
            "fast_contact_fraction": f(self.sliding_fraction),
            "sources_fast_contact_fraction": f(self.source_sliding_fraction),
            "penetration_m": f(self.penetration_m),
            "penetration_fraction": f(self.penetration_fraction),
            "sources_penetration_fraction": f(self.source_penetration_fraction),
            "freezes": [list(r) for r in self.freezes],
            "longest_freeze_s": f(self.longest_freeze_s),
            "held_frames": self.held_frames,
            "stride_frames": self.stride_frames,
            "knee_range_deg": [f(x) for x in self.knee_range],
            "knee_p99_deg": [f(x) for x in self.knee_p99],
            "hip_range_deg": [f(x) for x in self.hip_range],
            "knee_range_ratio": [f(x) for x in self.knee_ratio],
            "hip_range_ratio": [f(x) for x in self.hip_ratio],
            "sources_knee_range_deg": f(self.source_knee_range),
            "sources_hip_range_deg": f(self.source_hip_range),
            "sources_knee_range_by_leg_deg": [f(x) for x in self.source_knee_legs],
            "sources_hip_range_by_leg_deg": [f(x) for x in self.source_hip_legs],
            "cycle_s": f(self.cycle_s),
            "sources_cycle_s": f(self.source_cycle_s),
            "cadence_ratio": f(self.cadence_ratio),
            "largest_step_ratio": f(self.largest_step),
            "largest_step_frame": self.largest_step_frame,
            "largest_accel_ratio": f(self.largest_accel),
            "largest_accel_frame": self.largest_accel_frame,
            "largest_root_accel_ratio": f(self.largest_root_accel),
            "largest_root_accel_frame": self.largest_root_accel_frame,
            "root_speed_m_per_s": f(self.root_speed),
            "sources_root_speed_m_per_s": f(self.source_root_speed),
            "root_speed_ratio": f(self.root_ratio),
            "notes": list(self.notes),
        }


def measure_generated(
    motion: Motion,
    sources: Sequence[Motion] | None = None,
    *,
    feet: Sequence[str] | None = None,
    hold: np.ndarray | None = None,
    reference: SourceFigures | None = None,
    analysed: bool = False,
) -> GeneratedQuality:
    """Measure a generated motion against the captures it came from.

    Parameters
    ----------
    motion : Motion
        The generated motion (any rig with two legs; a quadruped's first two legs).
    sources : sequence of Motion
        The source captures (training takes, the cycles' captures); resampled to the
        motion's rate by a whole-number step when that lands within 5 % of it.
    feet : sequence of str, optional
        Foot points; default found (:func:`~cyclecoord.quality.legs.find_legs`).
    hold : ndarray of bool, shape (T,), optional
        Frames where a hold was asked (IDLE): slow frames there are not freezes.
    reference : SourceFigures, optional
        The sources' figures already computed (then ``sources`` may be None).
    analysed : bool, default False
        ``motion`` and ``sources`` are already in the analysis rig
        (:func:`~cyclecoord.rig.analysis_motion`): a latent model's output and training
        takes, or a slice of a motion found to need no change (a latent script measures
        some ten slices; finding each one's rig afresh was a tenth of the report's time).

    Returns
    -------
    GeneratedQuality
    """
    if motion.n_frames < 3:
        raise ParameterError(f"the measure needs at least 3 frames, got {motion.n_frames}")
    from ..rig import analysis_motion

    ref = reference if reference is not None else source_figures(
        sources or [], motion.fps, feet, analysed=analysed)
    motion = motion if analysed else analysis_motion(motion)
    rig = _rig(motion, feet)
    kin = _kin(motion, rig)
    m = ref.metres
    legs = rig.leg_length
    body = legs / ref.leg_length if ref.leg_length > 0 and legs > 0 else 1.0
    # feet: contact from height alone, at the sources' floor
    spd, contacts, fast = _contact_speeds(motion, rig, ref.floor)
    support = _support(kin, rig)
    slip = float(np.median(support))
    lowest = _lowest(kin, rig)
    depth = ref.floor - lowest
    # freezes
    slow = kin.pose_speed() / body < FREEZE_FRACTION * ref.pose_speed_median
    slow = np.r_[slow, slow[-1:]]  # a step's flag on its first frame; the last frame copies
    held = np.zeros(kin.n, dtype=bool) if hold is None else np.asarray(hold, dtype=bool)
    if held.shape != (kin.n,):
        raise ParameterError(f"hold must have one flag per frame ({kin.n}), got {held.shape}")
    min_len = FREEZE_SECONDS * kin.fps
    freezes = [(a, b) for a, b in contact_runs(slow & ~held) if b - a > min_len]
    runs = contact_runs(slow & ~held)
    longest = max((b - a for a, b in runs), default=0) / kin.fps
    # pops
    ps = kin.pose_speed()
    acc = kin.accel()
    racc = kin.root_accel()
    rs_all = kin.root_speed()
    free = _windows(~held, rs_all.size)  # an asked hold's stand is not the gait's speed
    rs = float(np.median(rs_all[free] if free.any() else rs_all))
    unheld = ~held
    knee, hip, cycle, stride_frames = kin.knee, kin.hip, None, kin.n
    if unheld.sum() >= STRIDE_SECONDS * kin.fps:  # strides where the script did not stand
        knee, hip, stride_frames = kin.knee[unheld], kin.hip[unheld], int(unheld.sum())
        a, b = max(contact_runs(unheld), key=lambda r: r[1] - r[0])
        expected = ref.cycle_at(rs / body)
        if np.isfinite(expected) and b - a >= 2.0 * expected * kin.fps:
            cycle = _cycle(kin.knee[a:b, 0], kin.fps)  # (two cycles at least, else all)
    cycle = kin.cycle() if cycle is None else cycle
    notes = []
    if motion.fps != ref.fps:
        notes.append(f"sources measured at {ref.fps:g} fps, the motion at {motion.fps:g}")
    return GeneratedQuality(
        frames=kin.n,
        fps=kin.fps,
        feet=rig.feet,
        leg_length_m=legs * m,
        support_slip=slip * m,
        support_slip_legs=slip / legs,
        source_support_slip=ref.support_slip * m,
        contact_fraction={f: float(contacts.planted[:, i].mean()) for i, f in enumerate(rig.feet)},
        contact_slide=float(np.median(spd)) * m,
        source_contact_slide=ref.contact_slide * m,
        sliding_fraction=fast,
        source_sliding_fraction=ref.sliding_fraction,
        penetration_m=max(float(depth.max()), 0.0) * m,
        penetration_fraction=float(np.mean(depth > PENETRATION_M / m)),
        source_penetration_fraction=ref.penetration,
        freezes=freezes,
        longest_freeze_s=float(longest),
        knee_range=tuple(float(x) for x in _ranges(knee)),
        hip_range=tuple(float(x) for x in _ranges(hip)),
        source_knee_range=ref.knee_range,
        source_hip_range=ref.hip_range,
        cycle_s=cycle,
        source_cycle_s=ref.cycle_at(rs / body),
        largest_step=_over(float(ps.max()) / body, ref.step_p99),
        largest_step_frame=int(ps.argmax()),
        largest_accel=_over(float(acc.max()) / body, ref.accel_p99),
        largest_accel_frame=int(acc.argmax()) + 1,
        largest_root_accel=(_over(float(racc.max()) / body, ref.root_accel_p99)
                            if np.isfinite(ref.root_accel_p99) else float("nan")),
        largest_root_accel_frame=int(racc.argmax()) + 1,
        root_speed=rs * m,
        source_root_speed=ref.root_speed * m,
        held_frames=int(held.sum()),
        stride_frames=stride_frames,
        notes=notes,
        knee_p99=tuple(float(x) for x in np.percentile(kin.knee, 99, axis=0)),
        source_knee_legs=ref.knee_range_legs,
        source_hip_legs=ref.hip_range_legs,
        body_scale=float(body),
    )


def lead_lines(
    motion: Motion,
    sources: Sequence[Motion],
    *,
    feet: Sequence[str] | str | None = None,
    hold: np.ndarray | None = None,
    reference: SourceFigures | None = None,
    analysed: bool = False,
    shares: Sequence[float] | None = None,
) -> tuple[dict | None, list[str]]:
    """The measure as a report dict and the console lines that lead a command's output;
    ``(None, [why])`` when it cannot be measured (no skeleton, no legs found).
    Parameters as :func:`measure_generated`'s; ``shares``, one per source: how much of
    the motion each source makes (a blend's weights, a transition's frames of each
    cycle), so the motion is judged against each source's own figures mixed so
    (:func:`mixed_reference`; pooled, a walk-to-jog transition read the jog's slip
    against the walk's)."""
    from ..errors import CycleCoordError
    from .legs import resolve_feet

    try:
        if isinstance(feet, str):
            feet = resolve_feet(motion.skeleton, feet)
        if reference is None and shares is not None and len(sources) > 1:
            cache: dict = {}
            parts = [(source_figures([src], motion.fps, feet, analysed=analysed, cache=cache),
                      float(w)) for src, w in zip(sources, shares) if w > 0]
            reference = parts[0][0] if len(parts) == 1 else mixed_reference(parts)
        q = measure_generated(motion, sources, feet=feet, hold=hold, reference=reference,
                              analysed=analysed)
    except CycleCoordError as exc:
        return None, [f"generated motion: not measured ({exc})"]
    return q.to_dict(), q.summary()
