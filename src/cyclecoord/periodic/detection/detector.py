"""The entry point of detection: :func:`detect` runs the stages in order.

Preparation and the global barcode here; the global stage in :mod:`.classes`, the
windowed stage in :mod:`.windows`, pauses and turns taken out of segments in
``_segments``; the method and its measured choices are described in
:mod:`cyclecoord.periodic.detection`.
"""

from __future__ import annotations

import numbers
import time
from typing import Any

import numpy as np

from ..._blas import one_blas_thread
from ..._validation import Interval, Options, check_params
from ...errors import NoPeriodicMotionError, ParameterError
from ...motion import Motion
from ..barcode import DEFAULT_PRIME
from ..coordinates import CircularCoordinates
from ..preprocess import Preprocessor
from ._segments import drop_unsteady
from .classes import candidate_classes, motions_from_classes, read_classes
from .result import DetectionResult, WindowInfo
from .windows import window_table, windowed_motions

__all__ = ["detect", "METHODS"]

#: Detection methods of :func:`detect`.
METHODS = ("auto", "global", "windows")


def _speed_window(window: float, fps: float) -> int:
    """Frames the coordinate's speed is averaged over for a ``window`` of seconds: the
    nearest whole number of frames to ``window * fps``, made odd (an even count gets one
    more frame) so that the window is centred on its frame, and at least 3."""
    return max(3, int(round(window * fps)) | 1)


@one_blas_thread
def detect(
    motion: Motion,
    frames: tuple[int | None, int | None] | None = None,
    *,
    pca: int | None = None,
    normalize: bool = False,
    temporal: bool = False,
    difference_root: bool = True,
    rotations: str = "auto",
    rig: bool = True,
    prime: int = DEFAULT_PRIME,
    max_scale: float | None = None,
    delay: float | tuple | None = 0.25,
    landmarks: int | str | None = "auto",
    memory_limit: float | None = None,
    n_classes: int | None = None,
    max_classes: int = 30,
    min_persistence: float = 0.1,
    scale_fraction: float = 0.9,
    window: float = 1.0,
    max_period: float = 4.0,
    min_consistency: float = 0.4,
    min_cycles: float = 1.5,
    merge_overlap: float = 0.5,
    method: str = "auto",
    window_lengths: tuple = (2.0, 4.0, 6.0),
    window_stride: float = 0.5,
    window_points: int = 100,
    window_cycles: float = 0.9,
    window_steadiness: float = 0.5,
    similarity: float = 1.5,
    progress: bool = True,
    preprocessor: Preprocessor | None = None,
    estimator: CircularCoordinates | None = None,
) -> DetectionResult:
    """Find the periodic motions in a capture and the frames where each happens.

    Parameters
    ----------
    motion : Motion
    frames : (start, stop), optional
        0-based half-open frame range to analyse.
    pca, normalize, temporal, difference_root, rotations, prime, max_scale, landmarks
        As for :func:`cyclecoord.extract`; so are ``memory_limit`` and ``rig`` (the
        capture's rig read first: ``result.motion`` is the analysed motion, and the cycles
        of :func:`motion_cycles` are written back in the capture's own rig).
    delay : float, sequence of float, or None, default 0.25
        Delay embedding in seconds (each pose joined by the poses this long before), so
        that out-and-back movements (squats, jumping jacks, knee raises) form loops.
        ``None`` or 0 analyses the poses alone, as the paper did.  A delay of half a
        motion's period folds that motion's loop flat; several delays can be given.
        Measured: 0.25 s keeps synthetic boundaries within 30 frames; 0.5 s finds more of
        CMU 13_29's slow exercises (42% against 28% of frames) but blurs boundaries.
    n_classes : int, optional
        Use exactly the ``n_classes`` most persistent H1 classes (still validated by
        excitation for the segments).
    max_classes : int, default 30
        At most this many candidate classes.
    min_persistence : float, default 0.1
        Candidates need at least this fraction of the longest bar's persistence.
    scale_fraction : float, default 0.9
        Each class is read this far up its own bar.
    window : float, default 1.0
        Seconds over which the coordinate's speed is averaged.
    max_period : float, default 4.0
        Slowest periodic motion looked for, in seconds: excitation needs at least one
        cycle per ``max_period``.
    min_consistency : float, default 0.4
        Excited frames need the coordinate to move one way this consistently.
    min_cycles : float, default 1.5
        An excited stretch must complete this many cycles.
    merge_overlap : float, default 0.5
        Classes whose excited frames overlap by more than this fraction of the smaller
        region are one motion (and, with ``method="auto"``, a group of windows joins the
        global motion whose excited frames hold more than this fraction of its frames).
    method : {"auto", "global", "windows"}, default "auto"
        ``"global"``: the classes of the one barcode on the whole capture (steps 1-5
        above, the paper's method).  ``"windows"``: the windowed stage alone (steps
        6-8).  ``"auto"``: both; windowed motions that excite a global motion's frames
        join it, the others are added, and the global labels are kept where the global
        stage labelled a frame.  See the module notes for the measured reasons.
    window_lengths : sequence of float, default (2, 4, 6)
        Window lengths in seconds.  A window must hold about a cycle of a motion to see
        its loop, so the longest should exceed the slowest period looked for.
    window_stride : float, default 0.5
        Smallest step between window starts, seconds (a window of length ``L`` steps by
        ``max(window_stride, L / 8)``).
    window_points : int, default 100
        At most this many frames per window go into its filtration (evenly spaced).
    window_cycles : float, default 0.9
        A window *loops* when its clear bar's coordinate completes this many turns ...
    window_steadiness : float, default 0.5
        ... with at least this fraction of its steps going the same way.  A group of
        looping windows becomes a motion when one of its windows completes
        ``min_cycles`` turns, or when three or more of them cover ``min_cycles`` of
        their median period.
    similarity : float, default 1.5
        Looping windows whose typical cycles differ by less than this (RMS pose distance
        after the best rotation and reflection, over the geometric mean of the two
        cycles' amplitudes; average linkage) are one motion.
    progress : bool, default True
        tqdm bar on stderr over the windows, shown only when they take over 2 s.
    preprocessor, estimator : Preprocessor, CircularCoordinates, optional
        Configured objects whose parameters replace the keywords of the same meaning
        (difference_root, normalize, pca, delay; max_scale, prime, scale_fraction,
        temporal, landmarks, memory_limit), as for :func:`cyclecoord.extract`.

    Returns
    -------
    DetectionResult

    Raises
    ------
    NoPeriodicMotionError
        When no class is excited anywhere (``result`` holds the partial detection).
    """
    if preprocessor is not None or estimator is not None:
        options = {k: v for k, v in locals().items() if k not in ("motion", "frames")}
        return detect(motion, frames=frames, **_from_configured(motion, options))
    window_lengths = _check_arguments(
        motion,
        window_lengths,
        dict(
            n_classes=n_classes, min_persistence=min_persistence, window=window,
            max_period=max_period, min_consistency=min_consistency, min_cycles=min_cycles,
            merge_overlap=merge_overlap, method=method, window_stride=window_stride,
            window_points=window_points, window_cycles=window_cycles,
            window_steadiness=window_steadiness, similarity=similarity, normalize=normalize,
            temporal=temporal, difference_root=difference_root, progress=progress,
            rotations=rotations,
        ),
    )
    params = dict(
        frames=None if frames is None else list(frames), pca=pca, normalize=normalize,
        temporal=temporal, difference_root=difference_root, prime=prime, max_scale=max_scale,
        rotations=rotations, rig=rig, landmarks=landmarks, delay=delay, n_classes=n_classes,
        max_classes=max_classes,
        min_persistence=min_persistence, scale_fraction=scale_fraction, window=window,
        max_period=max_period, min_consistency=min_consistency, min_cycles=min_cycles,
        merge_overlap=merge_overlap, method=method, window_lengths=list(window_lengths),
        window_stride=window_stride, window_points=int(window_points),
        window_cycles=window_cycles, window_steadiness=window_steadiness, similarity=similarity,
    )
    motion = motion.window(frames)
    adapter = None
    if rig and motion.skeleton is not None:
        from ...rig import normalize_rig

        motion, adapter = normalize_rig(motion)
        if adapter.identity:
            adapter = None
    T = motion.n_frames
    if T < 20:
        raise ParameterError(f"{T} frames are too few to look for periodic motion")
    timings: dict[str, float] = {}
    notes: list[str] = []

    prepared, est, barcode = _barcode_of(
        motion, timings, notes,
        preprocess=dict(difference_root=difference_root, normalize=normalize, pca=pca,
                        delay=delay, rotations=rotations),
        estimate=dict(max_scale=max_scale, prime=prime, scale_fraction=scale_fraction,
                      temporal=temporal, landmarks=landmarks, memory_limit=memory_limit),
    )

    # 1-4. candidate classes, their coordinates, excitation and validation
    cand = candidate_classes(barcode, n_classes, max_classes, min_persistence)
    fps = motion.fps
    w = _speed_window(window, fps)
    v_min = 1.0 / (max_period * fps)
    t0 = time.perf_counter()
    classes = read_classes(
        est, cand if method != "windows" else [], w, v_min, min_consistency, min_cycles, notes
    )
    timings["coordinates"] = time.perf_counter() - t0

    # 5. motions: union of classes exciting the same frames; labels and segments
    t0 = time.perf_counter()
    kept, labels, segments, n_motions = motions_from_classes(classes, T, w, merge_overlap)
    timings["segments"] = time.perf_counter() - t0

    # 6-8. windowed stage
    windows: list[WindowInfo] = []
    if method != "global":
        windows, labels, segments, n_motions = _windowed_stage(
            prepared, fps, method, kept, labels, n_motions, timings,
            table=(window_lengths, window_stride, int(window_points), prime, scale_fraction,
                   window_cycles, window_steadiness, progress),
            grouping=(w, min_cycles, similarity, merge_overlap),
        )
    t0 = time.perf_counter()
    joint_cols = np.setdiff1d(np.arange(prepared.poses.shape[1]), prepared.root_columns)
    labels, segments = drop_unsteady(
        labels, segments, prepared.poses[:, joint_cols] if joint_cols.size else prepared.poses,
        motion, min_run=max(w // 2, 1),
    )
    timings["segments"] = timings.get("segments", 0.0) + time.perf_counter() - t0
    timings["total"] = sum(timings.values())
    result = DetectionResult(
        motion=motion, barcode=barcode, classes=classes, segments=segments, labels=labels,
        n_motions=n_motions, timings=timings, parameters=params, warnings=notes, estimator=est,
        windows=windows, method=method, rig_adapter=adapter,
    )
    if not segments:
        raise _nothing_found(result, len(cand), min_cycles)
    return result


def _barcode_of(
    motion: Motion, timings: dict, notes: list, preprocess: dict, estimate: dict
) -> tuple[Any, CircularCoordinates, Any]:
    """Steps 0-1 of :func:`detect`: the prepared capture (``delay`` in seconds), the
    estimator and the barcode of the whole capture, timed into ``timings``."""
    t0 = time.perf_counter()
    delay = preprocess.pop("delay")
    lag = (
        [int(round(d * motion.fps)) for d in np.atleast_1d(delay) if d]
        if delay is not None
        else None
    )
    prepared = Preprocessor(delay=lag or None, **preprocess).fit_transform(motion)
    timings["prepare"] = time.perf_counter() - t0

    memory_limit = estimate.pop("memory_limit")
    est = CircularCoordinates(
        refine_birth=False, **estimate,
        **({} if memory_limit is None else {"memory_limit": memory_limit}),
    )
    t0 = time.perf_counter()
    barcode = est.fit_barcode(prepared.points)
    timings["barcode"] = time.perf_counter() - t0
    if est.landmarks_ is not None:
        notes.append(f"barcode on {len(est.landmarks_)} landmarks: {est.landmark_reason_}")
    return prepared, est, barcode


def _windowed_stage(
    prepared, fps: float, method: str, kept: list, labels: np.ndarray, n_motions: int,
    timings: dict, table: tuple, grouping: tuple,
) -> tuple[list[WindowInfo], np.ndarray, list, int]:
    """Steps 6-8 of :func:`detect`: the sliding windows' barcodes (``table``: lengths,
    stride, points, prime, scale fraction, cycles, steadiness, progress) and the motions
    grouped from them (``grouping``: smoothing window, min cycles, similarity, merge
    overlap), joined to the global motions when ``method`` is ``"auto"``."""
    w, min_cycles, similarity, merge_overlap = grouping
    keep_cols = np.setdiff1d(np.arange(prepared.poses.shape[1]), prepared.root_columns)
    poses = prepared.poses[:, keep_cols] if keep_cols.size else prepared.poses
    t0 = time.perf_counter()
    lengths, stride, points, prime, scale_fraction, cycles, steadiness, progress = table
    windows = window_table(
        prepared.points, poses, fps, lengths, stride, points, prime, scale_fraction, cycles,
        steadiness, progress,
    )
    timings["windows"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    n_global = n_motions if method == "auto" else 0
    if method == "windows":
        for c in kept:
            c.motion = -1
    labels, segments, n_motions = windowed_motions(
        windows, kept if n_global else [], labels, n_global, poses, w, min_cycles, similarity,
        merge_overlap,
    )
    timings["segments"] += time.perf_counter() - t0
    return windows, labels, segments, n_motions


def _nothing_found(result: DetectionResult, n_candidates: int, min_cycles: float):
    """The error :func:`detect` raises when no segment stands (``result`` attached)."""
    windows = result.windows
    local = ""
    if result.method != "global":
        looping = sum(wi.looping for wi in windows)
        local = (f"; {len(windows)} window(s), {looping} looping, no group of them holds "
                 f"{min_cycles:g} cycles")
    return NoPeriodicMotionError(
        f"no periodic motion found: {n_candidates} candidate H1 class(es), none completes "
        f"{min_cycles:g} steady cycles anywhere in the capture" + local,
        result=result,
    )


#: detect's defaults for the settings a Preprocessor or CircularCoordinates can carry.
_DETECT_CONFIGURED = dict(
    difference_root=True, normalize=False, pca=None, delay=0.25, rotations="auto",
    max_scale=None,
    prime=DEFAULT_PRIME, scale_fraction=0.9, temporal=False, landmarks="auto", memory_limit=None,
)

def _from_configured(motion: Motion, options: dict[str, Any]) -> dict[str, Any]:
    """detect's keyword options with the settings of its configured ``preprocessor`` and
    ``estimator`` (both removed) in place of their keywords."""
    from ..results import configured_keywords

    pre, est = options.pop("preprocessor"), options.pop("estimator")
    given = {k: options[k] for k in _DETECT_CONFIGURED}
    chosen = configured_keywords(motion, pre, est, given, _DETECT_CONFIGURED, "detect()",
                                 several_delays=True)
    return {**options, **chosen}


_POSITIVE = [Interval(numbers.Real, 0, None, closed="neither")]
_FRACTION = [Interval(numbers.Real, 0, 1, closed="right")]

#: What :func:`detect`'s own options may be (:mod:`cyclecoord._validation`); those shared
#: with :func:`cyclecoord.extract` are checked as there, ``window_lengths`` below.
DETECT_CONSTRAINTS = {
    "window": _POSITIVE,
    "max_period": _POSITIVE,
    "min_cycles": _POSITIVE,
    "min_consistency": _FRACTION,
    "merge_overlap": _FRACTION,
    "min_persistence": [Interval(numbers.Real, 0, 1)],
    "n_classes": [Interval(numbers.Integral, 1, None), None],
    "method": [Options(*METHODS)],
    "window_stride": _POSITIVE,
    "window_cycles": _POSITIVE,
    "similarity": _POSITIVE,
    "window_steadiness": [Interval(numbers.Real, 0, 1)],
    "window_points": [Interval(numbers.Integral, 10, None)],
    "normalize": ["boolean"],
    "temporal": ["boolean"],
    "difference_root": ["boolean"],
    "rotations": [Options("auto", "rotvec", "euler")],
    "progress": ["boolean"],
}


def _check_arguments(motion: Motion, window_lengths: Any, values: dict) -> tuple[float, ...]:
    """Check :func:`detect`'s arguments (ParameterError naming the first bad one):
    ``values`` against :data:`DETECT_CONSTRAINTS`, then ``window_lengths``.

    Returns
    -------
    tuple of float
        ``window_lengths`` as seconds.
    """
    if not isinstance(motion, Motion):
        raise ParameterError(f"detect() takes a Motion, got {type(motion).__name__}")
    check_params(values, DETECT_CONSTRAINTS, "detect()")
    try:
        lengths = tuple(float(v) for v in np.atleast_1d(window_lengths))
    except (TypeError, ValueError):
        raise ParameterError(
            f"window_lengths must be numbers of seconds, got {window_lengths!r}"
        ) from None
    if not lengths or not all(np.isfinite(v) and v > 0 for v in lengths):
        raise ParameterError(f"window_lengths must be positive numbers of seconds, got {lengths}")
    return lengths
