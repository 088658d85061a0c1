"""Whole synthetic takes as people record them: stand, start, walk, turn, pause, stop.

:func:`make_whole_take` (re-exported by :mod:`cyclecoord.datasets`) strings a script of
parts together on one timeline.  A per-frame *activity* ``a`` in [0, 1] blends the
standing pose (``a = 0``) into the steady gait (``a = 1``): every joint angle is
``standing + a * (gait(phase) - standing)``, so the oscillation's amplitude and the
posture ramp up together at a start and down at a stop, and standing frames are exactly
still.  The phase advances at the period's own (slightly wobbling) speed times a
cadence factor (0 standing, 0.55 -> 1 over a start, a little slower in turns); the root
travels ``stride * a`` per cycle along the current heading, and the heading turns
smoothly (C2) over each turn while the walker leans into it, looks ahead and takes
slightly shorter steps.  The root rotation is the exact composition of the heading with
the gait's pelvis tilt, written back as AMC ``rx ry rz`` Euler angles (the solution with
the smaller tilt, ``ry`` unwrapped), as a capture system would record a person facing any
direction.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..motion import DEFAULT_FPS
from ._body import (
    capture_pair,
    CHANNELS,
    COL,
    DEFAULT_PERIODS,
    POSES,
    STRIDE,
    add_noise,
    check_float,
    check_int,
    check_random_state,
    cmu_skeleton,
    draw_phase_law,
    draw_style,
    ground,
    pose_to_frames,
    seed_text,
    smoothstep,
    standing_pose,
)
from .captures import SyntheticCapture

__all__ = ["PART_NAMES", "make_whole_take"]

#: Names of the parts of a whole take; ``SyntheticCapture.part_labels`` indexes this tuple.
PART_NAMES = ("stand", "start", "steady", "turn", "stop")

#: Kinds that travel, hence can start, turn and stop.
_GAIT_KINDS = ("walk", "jog")

#: Gravity in CMU length units (1/0.45 inch) per second squared.
_GRAVITY = 9.81 / (0.0254 / 0.45)

_CADENCE_FLOOR = 0.55  # cadence at the first step, relative to the steady one
_TURN_STRIDE = 0.10  # steps this much shorter at the middle of a turn
_TURN_CADENCE = 0.05  # and this much slower
_TURN_LEAN = 0.3  # fraction of the centripetal lean angle actually taken
_LOOK_AHEAD = 0.3  # seconds: the head turns by half the heading change in this much time
_PAUSE_STOP = 0.75  # cycles of slowing down before a pause's standing
_PAUSE_START = 1.0  # cycles of starting again after it


@dataclass(frozen=True)
class _Part:
    name: str
    frames: int
    degrees: float = 0.0  # turns only: signed heading change, positive to the left


# ----------------------------------------------------------------------- the script
def _frames_of(index: int, name: str, amount: object, unit: float, what: str) -> int:
    try:
        value = float(amount)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError(
            f"script entry {index} ({name!r}): {what} must be a number, got {amount!r}"
        ) from None
    if not np.isfinite(value) or value <= 0:
        raise ParameterError(f"script entry {index} ({name!r}): {what} must be > 0, got {amount!r}")
    frames = round(value * unit)
    if frames < 2:
        raise ParameterError(f"script entry {index} ({name!r}): {value:g} {what} is under 2 frames")
    return frames


def _parse_script(script: object, period: float, fps: float) -> list[_Part]:
    """Check a user script and expand it into parts with frame counts."""
    if isinstance(script, (str, bytes)):
        raise ParameterError(f"script must be a sequence of (part, amount) entries, got {script!r}")
    try:
        entries = list(script)  # type: ignore[arg-type]
    except TypeError:
        raise ParameterError(
            f"script must be a sequence of (part, amount) entries, got {script!r}"
        ) from None
    if not entries:
        raise ParameterError("script must have at least one entry")
    parts: list[_Part] = []
    for i, entry in enumerate(entries):
        try:
            name, amount, *rest = entry
        except (TypeError, ValueError):
            raise ParameterError(
                f"script entry {i}: expected (part, amount[, degrees]), got {entry!r}"
            ) from None
        if name not in PART_NAMES and name != "pause":
            raise ParameterError(
                f"script entry {i}: unknown part {name!r}; "
                f"choose from {', '.join(PART_NAMES)}, pause"
            )
        if rest and (name != "turn" or len(rest) > 1):
            raise ParameterError(f"script entry {i} ({name!r}): too many values in {entry!r}")
        if name in ("stand", "pause"):
            frames = _frames_of(i, name, amount, fps, "seconds")
        else:
            frames = _frames_of(i, name, amount, period, "cycles")
        if name == "pause":
            parts += [
                _Part("stop", max(2, round(_PAUSE_STOP * period))),
                _Part("stand", frames),
                _Part("start", max(2, round(_PAUSE_START * period))),
            ]
        elif name == "turn":
            degrees = rest[0] if rest else 90.0
            try:
                degrees = float(degrees)
            except (TypeError, ValueError):
                raise ParameterError(
                    f"script entry {i} ('turn'): degrees must be a number, got {degrees!r}"
                ) from None
            if not np.isfinite(degrees):
                raise ParameterError(
                    f"script entry {i} ('turn'): degrees must be finite, got {degrees!r}"
                )
            parts.append(_Part("turn", frames, degrees))
        else:
            parts.append(_Part(name, frames))
    _check_order(parts, entries)
    return parts


def _check_order(parts: list[_Part], entries: list) -> None:
    """Standing parts and moving parts must meet through a start or a stop."""
    moving = parts[0].name not in ("stand", "start")
    for j, part in enumerate(parts):
        needs_moving = part.name in ("steady", "turn", "stop")
        if needs_moving != moving:
            entry = _entry_of(j, parts, entries)
            hint = f"insert a ('{'start' if needs_moving else 'stop'}', cycles) before it"
            what = "walking" if needs_moving else "standing"
            raise ParameterError(
                f"script entry {entry} ({entries[entry][0]!r}) needs the person {what} "
                f"but follows {'standing' if not moving else 'walking'}: {hint}"
            )
        if part.name == "start":
            moving = True
        elif part.name == "stop":
            moving = False


def _entry_of(part_index: int, parts: list[_Part], entries: list) -> int:
    """Script entry a part came from (a pause expands into three parts)."""
    j = 0
    for i, entry in enumerate(entries):
        j += 3 if entry[0] == "pause" else 1
        if j > part_index:
            return i
    return len(entries) - 1  # pragma: no cover - part_index is always in range


def _turn(rng: np.random.Generator, period: float) -> _Part:
    degrees = float(rng.uniform(90.0, 180.0)) * (1.0 if rng.random() < 0.5 else -1.0)
    return _Part("turn", round(float(rng.uniform(1.0, 2.0)) * period), degrees)


def _pause(rng: np.random.Generator, period: float, fps: float) -> list[_Part]:
    return [
        _Part("stop", round(_PAUSE_STOP * period)),
        _Part("stand", round(float(rng.uniform(1.0, 2.0)) * fps)),
        _Part("start", round(_PAUSE_START * period)),
    ]


def _default_script(rng: np.random.Generator, period: float, fps: float) -> list[_Part]:
    steady = _Part("steady", round(4 * period))
    return [
        _Part("stand", round(1.5 * fps)), _Part("start", round(period)), steady,
        _turn(rng, period), steady, *_pause(rng, period, fps), steady,
        _Part("stop", round(period)), _Part("stand", round(1.0 * fps)),
    ]


def _script_for_length(rng: np.random.Generator, n: int, period: float, fps: float) -> list[_Part]:
    """Stand, start, then steady walking broken by turns and pauses in turn, stop, stand.

    As many turns and pauses as fit with at least three steady cycles between them; the
    frames left over are shared among the steady parts (randomly weighted).
    """
    head = [_Part("stand", round(1.5 * fps)), _Part("start", round(period))]
    tail = [_Part("stop", round(period)), _Part("stand", round(1.0 * fps))]
    fixed = sum(p.frames for p in head + tail)
    shortest = round(3 * period)
    if n < fixed + round(period):
        raise ParameterError(
            f"n_frames must be at least {fixed + round(period)} for a take at period "
            f"{period:g} (standing, a start, one steady cycle, a stop), got {n}"
        )
    events: list[list[_Part]] = []
    while True:
        nxt = [_turn(rng, period)] if len(events) % 2 == 0 else _pause(rng, period, fps)
        used = fixed + sum(p.frames for e in events + [nxt] for p in e)
        if used + (len(events) + 2) * shortest > n:
            break
        events.append(nxt)
    spare = n - fixed - sum(p.frames for e in events for p in e)
    lengths = np.full(len(events) + 1, min(shortest, spare))
    spare -= int(lengths.sum())
    weights = rng.uniform(0.7, 1.3, size=len(events) + 1)
    lengths += np.floor(spare * weights / weights.sum()).astype(int)
    lengths[-1] += n - fixed - sum(p.frames for e in events for p in e) - int(lengths.sum())
    parts = list(head)
    for k, length in enumerate(lengths):
        parts.append(_Part("steady", int(length)))
        if k < len(events):
            parts += events[k]
    return parts + tail


# --------------------------------------------------------------------- the timeline
def _timeline(parts: list[_Part], heading0: float) -> dict[str, np.ndarray]:
    """Per-frame part code, activity, turn bump, cadence factor and heading (degrees)."""
    n = sum(p.frames for p in parts)
    out = {
        "code": np.empty(n, dtype=int),
        "activity": np.ones(n),
        "bump": np.zeros(n),
        "cadence": np.ones(n),
        "heading": np.empty(n),
    }
    s, heading = 0, heading0
    for part in parts:
        e = s + part.frames
        u = (np.arange(part.frames) + 1.0) / (part.frames + 1.0)
        out["code"][s:e] = PART_NAMES.index(part.name)
        out["heading"][s:e] = heading
        if part.name == "stand":
            out["activity"][s:e] = 0.0
            out["cadence"][s:e] = 0.0
        elif part.name in ("start", "stop"):
            a = smoothstep(u) if part.name == "start" else 1.0 - smoothstep(u)
            out["activity"][s:e] = a
            out["cadence"][s:e] = _CADENCE_FLOOR + (1.0 - _CADENCE_FLOOR) * a
        elif part.name == "turn":
            bump = (4.0 * u * (1.0 - u)) ** 2
            out["bump"][s:e] = bump
            out["cadence"][s:e] = 1.0 - _TURN_CADENCE * bump
            out["heading"][s:e] = heading + part.degrees * smoothstep(u)
            heading += part.degrees
        s = e
    return out


def _amc_euler(world) -> np.ndarray:
    """AMC root angles ``(T, 3)`` as ``(rz, ry, rx)`` of rotations, as a capture would write them.

    ``ZYX`` Euler angles have two solutions, ``(z, y, x)`` and ``(z + 180, 180 - y,
    x + 180)``; each frame takes the one with the smaller tilt (``rx`` and ``rz`` nearer
    0, wrapped to [-180, 180)), and ``ry`` is unwrapped, so it follows the heading through
    any number of turns.  Where the heading passes +-90 degrees (within the pelvis tilt,
    a few degrees) both solutions tilt a lot and ``rx``/``rz`` swing fast, as they do in
    real CMU takes (143_01: jumps of up to 86 degrees between frames).
    """
    e = world.as_euler("ZYX", degrees=True)
    alt = np.column_stack([e[:, 0] + 180.0, 180.0 - e[:, 1], e[:, 2] + 180.0])
    e, alt = ((a + 180.0) % 360.0 - 180.0 for a in (e, alt))
    tilt = np.abs(e[:, [0, 2]]).sum(axis=1)
    out = np.where((np.abs(alt[:, [0, 2]]).sum(axis=1) < tilt)[:, None], alt, e)
    out[:, 1] = np.degrees(np.unwrap(np.radians(out[:, 1])))
    return out


# ------------------------------------------------------------------------ rendering
def _render_take(
    kind: str,
    phase: np.ndarray,
    rate: np.ndarray,
    line: dict[str, np.ndarray],
    style,
    fps: float,
) -> np.ndarray:
    """Noise-free frames ``(T, 62)`` of the take from its phase and timeline."""
    from scipy.spatial.transform import Rotation

    col = COL
    skeleton = cmu_skeleton()
    n = phase.shape[0]
    a = line["activity"][:, None]
    bump = line["bump"]
    heading = line["heading"]
    amp = style.amp * (1.0 - _TURN_STRIDE * bump)
    gait = pose_to_frames(POSES[kind](np.mod(phase, 1.0), amp), n)
    stand = pose_to_frames(standing_pose(n), n)
    frames = stand + a * (gait - stand) + style.posture
    lift = frames[:, col[("root", "ty")]].copy()
    sway = frames[:, col[("root", "tx")]].copy()
    wobble = frames[:, col[("root", "tz")]].copy()

    # forward progression: one stride per cycle at full amplitude, along the heading
    step = STRIDE[kind] * line["activity"] * (1.0 - _TURN_STRIDE * bump) * rate  # units/frame
    h = np.radians(heading)
    omega = np.gradient(h)  # rad/frame
    lean = -_TURN_LEAN * np.degrees(np.arctan(step * omega / (_GRAVITY / fps**2)))
    ahead = np.gradient(heading) * _LOOK_AHEAD * fps  # degrees the heading turns in 0.3 s
    frames[:, col[("head", "ry")]] += 0.5 * ahead
    frames[:, col[("thorax", "ry")]] += 0.2 * ahead

    # root orientation: the heading composed with the pelvis tilt and yaw of the gait
    rx, ry = frames[:, col[("root", "rx")]], frames[:, col[("root", "ry")]]
    rz = frames[:, col[("root", "rz")]] + lean
    body = Rotation.from_euler("ZYX", np.column_stack([rz, ry, rx]), degrees=True)
    world = Rotation.from_euler("Y", heading[:, None], degrees=True) * body
    zyx = _amc_euler(world)
    frames[:, col[("root", "rz")]] = zyx[:, 0]
    frames[:, col[("root", "ry")]] = zyx[:, 1]
    frames[:, col[("root", "rx")]] = zyx[:, 2]

    # root translation: progression (frame t moved by the steps before it) plus the
    # body-frame sway and wobble turned to the heading; height keeps a foot on the floor
    cos, sin = np.cos(h), np.sin(h)
    x = np.concatenate([[0.0], np.cumsum(step * sin)[:-1]])
    z = np.concatenate([[0.0], np.cumsum(step * cos)[:-1]])
    frames[:, col[("root", "tx")]] = x + sway * cos + wobble * sin
    frames[:, col[("root", "tz")]] = z - sway * sin + wobble * cos
    frames[:, col[("root", "ty")]] = ground(frames, skeleton) + lift
    return frames


# --------------------------------------------------------------------------- public
def make_whole_take(
    kind: str = "walk",
    *,
    period: float | None = None,
    n_frames: int | None = None,
    script: Sequence[tuple] | None = None,
    noise: float = 0.5,
    speed_variation: float = 0.05,
    curve: float = 0.0,
    fps: float = DEFAULT_FPS,
    random_state: int | np.random.Generator | None = 0,
) -> SyntheticCapture:
    """A whole take as people record it: standing, starting, walking, turning, pausing.

    The take follows a script of parts.  ``stand``: quiet standing, exactly still before
    the noise.  ``start``: the gait's amplitude, posture and stride grow from the
    standing pose (C2 ramp) while the cadence rises from 0.55 of the steady one.
    ``steady``: the steady gait (the joint angles of :func:`make_periodic_capture` at
    the same phase) at the period's own speed wobble of a few percent.  ``turn``: still
    walking while the heading turns smoothly by the scripted angle; the steps get up to
    10 % shorter and 5 % slower, the body leans into the turn and the head looks ahead.
    ``stop``: the start backwards.  ``pause``: a stop (0.75 cycle), standing, a start
    (1 cycle).  The root travels one stride per cycle times the amplitude along the
    current heading, so the person walks a path with corners; the root rotation is the
    heading composed with the pelvis motion, as AMC Euler angles (which swing fast when
    the heading passes +-90 degrees, as in real CMU takes).

    Parameters
    ----------
    kind : str
        ``"walk"`` or ``"jog"`` (the kinds that travel).
    period : float, optional
        Mean steady period in frames (> 1); default the kind's natural period (walk 120,
        jog 80).
    n_frames : int, optional
        Length of a generated script: stand 1.5 s, start, then steady walking (three
        cycles or more) broken alternately by a turn (1-2 cycles, 90-180 degrees either
        way) and a pause (standing 1-2 s), as many as fit, then a stop and 1 s of
        standing; the take has exactly ``n_frames`` frames.  Not with ``script``.
    script : sequence of tuples, optional
        The parts in order, each ``(name, amount)``: ``("stand", seconds)``,
        ``("start", cycles)``, ``("steady", cycles)``, ``("stop", cycles)``,
        ``("pause", seconds standing)`` or ``("turn", cycles, degrees)`` (degrees
        positive to the left, default 90).  Standing and walking parts must meet through
        a start or a stop.  Default (neither ``script`` nor ``n_frames``): stand 1.5 s,
        start 1, steady 4, turn (1-2 cycles, 90-180 degrees), steady 4, pause (1-2 s),
        steady 4, stop 1, stand 1 s: about 2,500 frames at period 120.
    noise : float
        Angle noise in degrees (>= 0), as in :func:`make_periodic_capture`.
    speed_variation : float
        Relative wobble of the phase speed, ``0 <= speed_variation < 1`` (0.05: single
        cycles a few percent longer or shorter than ``period``).
    curve : float
        Heading drift while walking, degrees per ``period`` frames at full amplitude
        (scaled by the amplitude in starts and stops; positive to the left).  Real
        straight walks drift a few degrees a cycle (CMU 69_01: about 5); 0 walks straight.
        The drift is part of ``heading``.
    fps : float
        Frame rate (seconds in the script are converted with it).
    random_state : int, numpy Generator or None
        Seed: the performer's style, the initial heading, the drawn turns and pauses,
        the speed wobble and the noise.

    Returns
    -------
    SyntheticCapture
        ``phase``: the gait phase in cycles, continuous over the take and strictly
        increasing while moving (start, steady, turn, stop), NaN on standing frames.
        ``period``: the true mean period of the steady frames (their frame count over
        the cycles the true phase makes on them).  ``labels``: 0 on steady frames, -1
        elsewhere; ``boundaries`` and ``steady``: the steady ranges.  ``parts`` and
        ``part_labels``: every part (codes index :data:`PART_NAMES`).  ``heading``:
        the scripted heading per frame (degrees).  ``motion.metadata`` holds the
        expanded script (``"script"``: ``(name, frames, degrees)``) and the nominal
        period.

    Raises
    ------
    ParameterError
        On a kind that does not travel, a bad script (naming the entry), both ``script``
        and ``n_frames``, or an argument out of range.
    """
    if not isinstance(kind, str) or kind not in _GAIT_KINDS:
        raise ParameterError(
            f"a whole take needs a gait; kind must be one of {', '.join(_GAIT_KINDS)}, got {kind!r}"
        )
    if period is None:
        period = DEFAULT_PERIODS[kind]
    period = check_float("period", period, 1.0, low_open=True)
    noise = check_float("noise", noise, 0.0)
    variation = check_float("speed_variation", speed_variation, 0.0, high=1.0)
    curve = check_float("curve", curve, -np.inf)
    fps = check_float("fps", fps, 0.0, low_open=True)
    if script is not None and n_frames is not None:
        raise ParameterError("give either script or n_frames, not both")
    rng = check_random_state(random_state)

    style = draw_style(rng)
    heading0 = float(rng.uniform(-180.0, 180.0))
    if script is not None:
        parts = _parse_script(script, period, fps)
    elif n_frames is not None:
        parts = _script_for_length(rng, check_int("n_frames", n_frames, 2), period, fps)
    else:
        parts = _default_script(rng, period, fps)
    line = _timeline(parts, heading0)
    if curve:
        drift = curve / period * line["activity"]
        line["heading"] = line["heading"] + np.concatenate([[0.0], np.cumsum(drift)[:-1]])
    n = line["code"].shape[0]
    law = draw_phase_law(rng, period, variation, n)
    grid = law(np.arange(n + 1, dtype=float))
    rate = np.diff(grid) * line["cadence"]  # cycles from frame t to t + 1
    phase = np.concatenate([[0.0], np.cumsum(rate)[:-1]])
    clean = _render_take(kind, phase, rate, line, style, fps)
    noisy = add_noise(clean, noise, rng)

    meta = {
        "kind": kind,
        "period": period,
        "noise": noise,
        "speed_variation": variation,
        "script": [(p.name, p.frames, p.degrees) for p in parts],
        "initial_heading": heading0,
        "curve": curve,
    }
    source = f"synthetic:take({kind}; seed={seed_text(random_state)})"
    return _assemble(kind, parts, line, phase, rate, clean, noisy, fps, source, meta)


def _assemble(
    kind: str,
    parts: list[_Part],
    line: dict[str, np.ndarray],
    phase: np.ndarray,
    rate: np.ndarray,
    clean: np.ndarray,
    noisy: np.ndarray,
    fps: float,
    source: str,
    meta: dict,
) -> SyntheticCapture:
    """The capture and its ground truth from the rendered take."""
    bounds = np.cumsum([0] + [p.frames for p in parts])
    ranges = [(p.name, int(bounds[k]), int(bounds[k + 1])) for k, p in enumerate(parts)]
    steady = [(s, e) for name, s, e in ranges if name == "steady"]
    steady_mask = line["code"] == PART_NAMES.index("steady")
    moving = line["code"] != PART_NAMES.index("stand")
    true_period = float(steady_mask.sum() / rate[steady_mask].sum()) if steady else float("nan")
    skeleton, channels = cmu_skeleton(), CHANNELS
    return SyntheticCapture(
        **capture_pair(noisy, clean, channels, skeleton, source, meta, fps),
        phase=np.where(moving, phase, np.nan),
        period=true_period,
        labels=np.where(steady_mask, 0, -1),
        boundaries=[(s, e, kind) for s, e in steady],
        name=f"synthetic-take({kind})",
        parts=ranges,
        part_labels=line["code"],
        steady=steady,
        heading=line["heading"],
    )
