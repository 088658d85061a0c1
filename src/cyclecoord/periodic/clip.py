"""A typical cycle made a loopable clip, timed by the capture or by the coordinate.

:func:`capture_cycle` (the default of :func:`~cyclecoord.periodic.pipeline.extract`)
averages the repetitions in a phase re-timed to the capture's pace
(:func:`~cyclecoord.periodic.windings.retime`), aligned by time warping
(:func:`~cyclecoord.periodic.registration.register`) and given back their typical
amplitude (:func:`typical_amplitude`); its root closes in height, pitch and roll, turns
by its mean heading steps and travels as its planted feet carry it
(:func:`planted_weights`, :func:`~cyclecoord.periodic.root.planted_ground`), so that a
foot on the ground does not slide (:mod:`~cyclecoord.periodic.root`).
:func:`loop_cycle` turns the paper's density-sampled cycle into a clip.  Both start the
loop at its slowest pose (:func:`slowest_frame`), where a seam is least visible.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..errors import NoPeriodicMotionError, ParameterError
from ..motion import Motion
from .cycle import TypicalCycle, select_bandwidth
from .preprocess import PreparedData, Preprocessor
from .registration import hold_weights, register
from .root import compose_root, decompose_root, heading, planted_ground, root_layout
from .windings import edge_taper, phase_average, stretches

__all__ = [
    "capture_cycle",
    "loop_cycle",
    "planted_weights",
    "anchor_to_feet",
    "typical_amplitude",
    "window_ranges",
    "spike_frames",
    "slowest_frame",
    "joint_columns",
    "CAPTURE_WIDTH",
    "MAX_CYCLE_FRAMES",
    "MAX_AMPLITUDE_GAIN",
]

#: Default width (frames of time) of the kernel that averages the re-timed cycle.
CAPTURE_WIDTH = 1.0
#: Each phased run fades in and out over this fraction of a period (:func:`edge_taper`).
EDGE_TAPER = 0.05
#: Rounds of contacts found on the cycle itself after the capture's (:func:`anchor_to_feet`).
ANCHOR_ROUNDS = 2
#: At most this many phased frames are aligned and averaged into the capture-timed cycle.
MAX_CYCLE_FRAMES = 20_000


def slowest_frame(frames: np.ndarray, window: int = 5) -> int:
    """Index of the frame where a closed cycle moves least.

    Step sizes around the loop are smoothed over ``window`` frames (cyclically); the frame
    between the two smallest smoothed steps is returned.  Starting a loop there hides the
    seam best, as animators cut loops at a rest pose.
    """
    f = np.asarray(frames, dtype=float)
    steps = np.linalg.norm(np.roll(f, -1, axis=0) - f, axis=1)  # step i: frame i -> i+1
    around = steps + np.roll(steps, 1)  # motion entering and leaving frame i
    w = max(1, min(window, len(f)))
    kernel = np.ones(w) / w
    smooth = np.convolve(np.concatenate([around[-w:], around, around[:w]]), kernel, mode="same")[
        w:-w
    ]
    return int(np.argmin(smooth))


def joint_columns(motion: Motion, prepared: PreparedData) -> np.ndarray:
    """Columns of the poses that are joint angles (not the root)."""
    cols = np.setdiff1d(np.arange(prepared.poses.shape[1]), prepared.root_columns)
    return cols if cols.size else np.arange(prepared.poses.shape[1])


def loop_cycle(
    typical: TypicalCycle,
    motion: Motion,
    prepared: PreparedData,
    preprocessor: Preprocessor,
    cycle_start: str = "slowest",
    rows: np.ndarray | None = None,
    metadata: dict | None = None,
) -> tuple[TypicalCycle, Motion]:
    """Turn a typical cycle in the prepared space into a loopable clip of the capture.

    The cycle is rotated to begin at its slowest pose (``cycle_start="slowest"``, where
    a loop's seam is least visible), and its root channels, per-frame differences in the
    prepared space, are integrated so that the clip travels and turns per frame as the
    capture did on average.

    Parameters
    ----------
    typical : TypicalCycle
        From :func:`~cyclecoord.periodic.cycle.typical_cycle` on ``prepared.poses`` (or rows of it).
    motion : Motion
        The capture ``prepared`` was made from.
    prepared : PreparedData
    preprocessor : Preprocessor
        The fitted preprocessor that made ``prepared``.
    cycle_start : {"slowest", "first"}
    rows : ndarray of int, optional
        The frames the cycle was averaged from (default all); their root differences
        give the travel per frame.
    metadata : dict, optional
        Stored on the returned clip.

    Returns
    -------
    (TypicalCycle, Motion)
        The cycle (rotated when ``cycle_start="slowest"``) and the clip, with the
        capture's channels, skeleton and frame rate.
    """
    if cycle_start not in ("slowest", "first"):
        raise ParameterError(f"cycle_start must be 'slowest' or 'first', got {cycle_start!r}")
    root = prepared.root_columns
    if cycle_start == "slowest":
        joints = (
            np.delete(typical.frames, root, axis=1)
            if root.size < typical.frames.shape[1]
            else typical.frames
        )
        shift = slowest_frame(joints)
        if shift:
            typical = replace(
                typical,
                frames=np.roll(typical.frames, -shift, axis=0),
                phases=np.roll(typical.phases, -shift),
            )
    near = motion.frames[int(rows[0]) if rows is not None and len(rows) else 0]
    cyc = preprocessor.channel_values(typical.frames, near=near)
    if root.size:
        last = len(prepared.poses) - 1  # the last row repeats the one before (see difference_root)
        used = np.arange(last) if rows is None else np.asarray(rows, dtype=int)
        used = used[used < last] if np.any(used < last) else used
        mean_delta = prepared.poses[used][:, root].mean(axis=0)
        cyc[:, root] = preprocessor.integrate_root(
            typical.frames[:, root], motion.frames[int(used.min()), root], mean_delta, motion
        )
    clip = motion.with_frames(
        cyc,
        start_frame=0,
        source=f"cycle of {motion.source or 'capture'}",
        metadata=dict(metadata or {}),
    )
    return typical, clip


#: A channel of the averaged cycle is widened at most this much (typical amplitude).
MAX_AMPLITUDE_GAIN = 1.5

#: Longest feature, in seconds, that :func:`typical_amplitude` takes for a glitch rather
#: than amplitude: five frames at 120 fps.
SPIKE_SECONDS = 5.0 / 120.0


def spike_frames(fps: float) -> int:
    """Frames of the running median of :func:`typical_amplitude` at ``fps``: the odd
    number of frames nearest below :data:`SPIKE_SECONDS` plus one (5 at 120 and 100
    fps, 3 at 60, 1 -- no filter -- at 30 and 24 fps).

    Counted in frames, the 5-frame median flattened real features at 30 fps: over a
    sixth of a second it clipped a Bandai walk's ankle roll, and the cycle's ankle range
    came out at 0.93 of the median stride's (1.02 with no filter, as on CMU's 120 fps
    takes).
    """
    return 2 * int(np.floor(SPIKE_SECONDS * float(fps) / 2.0)) + 1


def window_ranges(
    poses: np.ndarray, runs: list[tuple[int, int]], period: int, spike: int = 5
) -> np.ndarray | None:
    """Median range ``(C,)`` of each channel over every window of one period.

    Windows lie inside the runs ``[(start, stop), ...]`` of ``poses`` ``(T, C)``, one
    starting every eighth of a period, each channel after a running median of ``spike``
    frames; None when no run holds a whole window.
    """
    from scipy.ndimage import median_filter

    P = int(period)
    ranges = []
    for a, b in runs:
        if b - a < max(P, spike + 1):
            continue
        smooth = median_filter(poses[a:b], size=(spike, 1), mode="nearest")
        for s in range(0, b - a - P + 1, max(1, P // 8)):
            ranges.append(np.ptp(smooth[s : s + P], axis=0))
    return np.median(np.asarray(ranges), axis=0) if ranges else None


def typical_amplitude(
    cycle: np.ndarray, phase: np.ndarray, poses: np.ndarray, spike: int = 5
) -> np.ndarray:
    """Give each channel of an averaged cycle the median range of the capture's repetitions.

    Averaging repetitions whose sharp features (a toe's flick, a foot's roll) differ a
    little in timing and size flattens them: the average's range is smaller than any
    single repetition's.  Each channel is scaled about the cycle's mean by the median
    range of the capture over one period, over the cycle's range, both after a running
    median of ``spike`` frames (a one- or two-frame marker glitch is not amplitude).  The
    capture's ranges are taken over every window of one period (the cycle's length)
    inside the phased runs, a window starting every eighth of a period: a take of two
    and a half repetitions gives about a dozen windows rather than the two complete
    repetitions between wraps, so one odd repetition does not set the amplitude.  The
    gain is kept in ``[1, MAX_AMPLITUDE_GAIN]``: a channel is never narrowed, nor a noisy
    one blown up.

    Parameters
    ----------
    cycle : ndarray, shape (P, C)
    phase : ndarray, shape (T,)
        Phase per frame, NaN where there is none (only which frames are phased is read).
    poses : ndarray, shape (T, C)
    spike : int
        Frames of the running median (odd; 1: none).  5 suits 120 fps;
        :func:`spike_frames` gives it for any frame rate.

    Returns
    -------
    ndarray, shape (P, C)
    """
    from scipy.ndimage import median_filter

    ok = np.isfinite(np.asarray(phase, dtype=float))
    P = len(cycle)
    typical = window_ranges(poses, stretches(ok), P, spike)
    if typical is None:
        return cycle
    have = np.ptp(median_filter(cycle, size=(spike, 1), mode="wrap"), axis=0)
    gain = np.clip(
        np.where(have > 1e-9, typical / np.maximum(have, 1e-9), 1.0), 1.0, MAX_AMPLITUDE_GAIN
    )
    mean = cycle.mean(axis=0)
    return mean + (cycle - mean) * gain


def planted_weights(
    motion: Motion,
    rows: np.ndarray,
    phase: np.ndarray,
    n_out: int,
    width: float,
    feet: tuple[str, ...] | None = None,
) -> tuple[tuple[str, ...], np.ndarray] | None:
    """How often each foot point is planted at each phase of the cycle, over the capture.

    Contacts (:func:`~cyclecoord.quality.contacts.foot_contacts`) are found on the
    capture's frames ``rows[0] .. rows[-1]`` and averaged at ``n_out`` phases with the
    cycle's kernel, so a point planted in every repetition at some phase weighs 1 there.
    The foot points are ``feet`` when given, else found on the capture
    (:func:`~cyclecoord.quality.legs.find_legs`: by name on the common rigs, else by
    geometry).

    Returns
    -------
    (feet, weights) or None
        The foot point names and an array of shape ``(n_out, len(feet))`` in ``[0, 1]``;
        None without a skeleton, or without ``feet`` and no feet found.
    """
    from ..quality.contacts import find_feet, foot_contacts

    if motion.skeleton is None or rows.size < 2:
        return None
    lo, hi = int(rows[0]), int(rows[-1]) + 1
    if feet is None:
        try:
            feet = find_feet(motion.skeleton, motion[lo:hi])
        except ParameterError:
            return None
    contacts = foot_contacts(motion[lo:hi], feet)
    planted = contacts.planted[rows - lo].astype(float)
    return feet, phase_average(phase, planted, n_out, width)


def anchor_to_feet(
    clip: Motion, layout, feet: tuple[str, ...], weights: np.ndarray, rounds: int = ANCHOR_ROUNDS
) -> np.ndarray:
    """Root ground track of a cycle that its planted feet carry, contacts refined on the cycle.

    The first track follows the capture's phase-averaged contacts (``weights``); those are
    blurred where repetitions differ (a foot lifting off a little earlier in one than in
    another), so the contacts are then found on the cycle itself as it walks on that track
    (:func:`~cyclecoord.quality.contacts.foot_contacts`, averaged over three frames) and
    the track is made again from them, ``rounds`` times.  On 69_01 whole (contacts'
    measure): 0.152 leg lengths/s while planted with the capture's weights alone, 0.084
    after two rounds; the take itself 0.128.

    Returns
    -------
    ndarray, shape (P, 2)
        Values for the root's ``tx`` and ``tz`` channels.
    """
    from scipy.ndimage import uniform_filter1d

    from ..quality.contacts import foot_contacts

    ground = planted_ground(clip, layout, feet, weights)
    cols = [layout.column("tx"), layout.column("tz")]
    for _ in range(rounds):
        frames = clip.frames.copy()
        frames[:, cols] = ground
        found = foot_contacts(clip.with_frames(frames), feet).planted.astype(float)
        ground = planted_ground(clip, layout, feet, uniform_filter1d(found, 3, axis=0, mode="wrap"))
    return ground


def capture_cycle(
    phase: np.ndarray,
    motion: Motion,
    prepared: PreparedData,
    preprocessor: Preprocessor,
    period: float,
    *,
    bandwidth: str | float | None = None,
    cycle_start: str = "slowest",
    travel: str = "keep",
    k: int = 10,
    register_iter: int = 2,
    amplitude: str = "typical",
    metadata: dict | None = None,
    feet: tuple[str, ...] | None = None,
) -> tuple[TypicalCycle, Motion, float]:
    """The typical cycle averaged in a phase that advances at the capture's pace.

    Parameters
    ----------
    phase : ndarray, shape (T,)
        Re-timed phase per frame in ``[0, 1)`` (:func:`~cyclecoord.periodic.windings.retime`),
        NaN for frames left out.
    motion, prepared, preprocessor
        The capture, its prepared data and the fitted preprocessor.
    period : float
        Period in frames; the cycle has ``round(period)`` frames.
    bandwidth : None, "auto" or float
        Kernel width in frames of time (None: :data:`CAPTURE_WIDTH`).
    cycle_start : {"slowest", "first"}
    travel : {"keep", "straight", "in_place"}
        See :func:`~cyclecoord.periodic.root.compose_root`.
    k : int
        Neighbours for the ``"auto"`` bandwidth's cross-validation.
    register_iter : int
        Rounds of :func:`~cyclecoord.periodic.registration.register` (0: none), which
        align every repetition to the cycle so that sharp features are not averaged
        away.  Frames that registration holds on one sample share one frame's weight
        (:func:`~cyclecoord.periodic.registration.hold_weights`), and every run of phased
        frames fades in and out over ``EDGE_TAPER`` of a period
        (:func:`~cyclecoord.periodic.windings.edge_taper`), so that the average does not
        jump where a repetition dwells or a partial one starts or stops.
    amplitude : {"typical", "average"}
        ``"typical"``: each joint channel of the average is widened about its mean to the
        median range of the capture's own repetitions (:func:`typical_amplitude`);
        ``"average"``: the plain average, whose sharp features shrink where repetitions
        differ.
    metadata : dict, optional
        Stored on the returned clip.
    feet : tuple of str, optional
        Foot points whose contacts carry the root (:func:`planted_weights`; default found).

    Returns
    -------
    (TypicalCycle, Motion, float)
        The cycle in the prepared space, the loopable clip (root pitch, roll and height
        averaged as absolute values, so they close; heading integrated from its mean
        changes; ground travel from the planted feet, the mean ground step where no foot
        is planted) and the heading change per cycle in degrees (NaN
        without a six-dof root and a skeleton).
    """
    P = max(2, int(round(period)))
    width = CAPTURE_WIDTH if bandwidth is None or bandwidth == "auto" else float(bandwidth)
    phase = np.array(phase, dtype=float)
    finite = np.flatnonzero(np.isfinite(phase))
    if finite.size < 2:
        raise NoPeriodicMotionError(
            f"only {finite.size} of the {phase.size} frames could be given a phase in the "
            "cycle (the circular coordinate never completes a steady turn): nothing to "
            "average into a cycle"
        )
    if finite.size > MAX_CYCLE_FRAMES:
        # a long take's cycle is averaged from its middle MAX_CYCLE_FRAMES phased frames
        # (over a hundred repetitions): registration's cost stays bounded
        mid = finite.size // 2
        keep = finite[mid - MAX_CYCLE_FRAMES // 2 : mid + MAX_CYCLE_FRAMES // 2]
        drop = np.ones(phase.size, dtype=bool)
        drop[keep] = False
        phase[drop] = np.nan
        finite = keep
    # work on the span of phased frames only (a view: a long take is never copied whole)
    lo, hi = (int(finite[0]), int(finite[-1]) + 1) if finite.size else (0, phase.size)
    phase = phase[lo:hi]
    span = prepared.poses[lo:hi]
    joints = joint_columns(motion, prepared)
    if register_iter:
        phase = register(phase, span[:, joints], stretches(np.isfinite(phase)), P,
                         width / float(period), n_iter=register_iter)
    local = np.flatnonzero(np.isfinite(phase))
    rows = local + lo
    ph = phase[local]
    poses = span[local]
    # each repetition gets one vote per cycle sample, and runs fade in and out: no pops
    weights = edge_taper(np.isfinite(phase), EDGE_TAPER * float(period)) * hold_weights(phase)
    votes = weights[local]
    selection = None
    if bandwidth == "auto":
        selection = select_bandwidth(ph, poses, float(period), k=min(k, rows.size))
        width = float(selection.bandwidth)
    frames = phase_average(ph, poses, P, width / float(period), weights=votes)
    if amplitude == "typical":
        frames[:, joints] = typical_amplitude(frames[:, joints], phase, span[:, joints],
                                              spike=spike_frames(motion.fps))
    layout = root_layout(motion) if prepared.root_columns.size else None
    feats = None
    if layout:
        feats = phase_average(
            ph, decompose_root(motion.frames[lo:hi], layout)[local], P, width / float(period),
            weights=votes,
        )
    shift = 0
    if cycle_start == "slowest":
        joints = (
            np.delete(frames, prepared.root_columns, axis=1)
            if prepared.root_columns.size < frames.shape[1]
            else frames
        )
        shift = slowest_frame(joints)
    frames = np.roll(frames, -shift, axis=0)
    phases = np.mod((np.arange(P) + shift) / P, 1.0)
    cyc = preprocessor.channel_values(frames, near=motion.frames[rows[0]])
    heading_change = float("nan")
    if feats is not None:
        feats = np.roll(feats, -shift, axis=0)
        heading_change = float(feats[:, 4].sum())
        first = motion.frames[rows[0]]
        start_heading = float(heading(first[None, :], layout)[0])
        ground = (float(first[layout.column("tx")]), float(first[layout.column("tz")]))
        cyc[:, layout.columns] = compose_root(feats, layout, start_heading, ground, travel=travel)
    elif prepared.root_columns.size:
        root = prepared.root_columns
        mean_delta = frames[:, root].mean(axis=0) if travel == "keep" else np.zeros(root.size)
        cyc[:, root] = preprocessor.integrate_root(
            frames[:, root], motion.frames[rows[0], root], mean_delta, motion
        )
    clip = motion.with_frames(cyc, start_frame=0, source=f"cycle of {motion.source or 'capture'}",
                              metadata=dict(metadata or {}))
    if feats is not None and travel != "in_place":
        planted = planted_weights(motion, rows, ph, P, width / float(period), feet)
        if planted is not None:
            feet, weights = planted
            cyc[:, [layout.column("tx"), layout.column("tz")]] = anchor_to_feet(
                clip, layout, feet, np.roll(weights, -shift, axis=0))
            clip = clip.with_frames(cyc)
    if feats is not None:
        # the cycle in the prepared space is the written clip's own (one definition of its
        # root changes, so its jerk and loop closure read the same from the file)
        frames = preprocessor.transform(clip).poses
    typ = TypicalCycle(
        frames=frames,
        phases=phases,
        curve=frames,
        sample_phases=phases,
        bandwidth=width,
        bandwidth_selection=selection,
    )
    for arr in (typ.frames, typ.phases):
        arr.flags.writeable = False
    return typ, clip, heading_change
