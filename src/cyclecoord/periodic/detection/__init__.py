"""Several periodic motions in one capture: significant classes, excitation, segments, labels.

The paper (§4.6, §6.4) reads several long H1 bars as several periodic motions: each
class's circular coordinate sweeps round steadily while its motion is performed and
stays put elsewhere (its *excitation region*).  :func:`detect` automates the choices the
paper made by hand:

1. **Candidate classes**: H1 bars with death/birth at least 1.5 (death capped at the
   threshold) and at least ``min_persistence`` of the longest bar's persistence (at most
   ``max_classes``), or exactly the ``n_classes`` longest when forced.
2. **Scale per class**: each class is read at its own scale, high inside its own bar,
   so motions born at different scales (a walk and a hop) are all kept.
3. **Excitation**: per frame, the coordinate's signed speed averaged over a short window
   (cycles per frame) together with the consistency of its direction.  A frame is
   excited when the coordinate advances steadily, faster than one cycle per
   ``max_period`` seconds.
4. **Validation**: a class counts only where it completes at least ``min_cycles``
   cycles in an excited stretch; classes that never do are dropped (this is the rule
   that decides significance when the barcode shows no clear gap).
5. **Motions**: classes that excite the same frames (overlap over half of the smaller
   region) are one motion; each frame is labelled with the motion whose excitation is
   strongest there, ``-1`` where none is excited.

The global barcode's long classes are often large-scale loops (the drift from one
exercise to the next) while each exercise's own loop is small and lives in a short
stretch of time; on CMU 13_29 (six exercises) steps 1-5 label 28% of the frames
correctly.  A **windowed stage** looks locally:

6. **Windows**: sliding windows of 2, 4 and 6 s (``window_lengths``; a window of length
   ``L`` steps by ``max(0.5 s, L / 8)``) over the same prepared points, at most 100
   frames each.  Each gets its full Rips barcode; when its longest bar is clear
   (:func:`cyclecoord.periodic.barcode.select_bar`), its circular coordinate.  The window
   *loops* when the coordinate turns at least 0.9 times with at least half its steps
   the same way; its typical cycle is then the mean pose (root channels left out) in 16
   phase bins of the coordinate (:func:`binned_cycle`).
7. **Motions from windows**: looping windows are grouped by average linkage on
   :func:`cycle_distance` (best rotation and reflection) relative to the cycles'
   amplitudes, cut at ``similarity``; non-adjacent windows of the same motion fall into
   the same group.  A group is a motion when one of its windows completes
   ``min_cycles`` turns, or when at least three of its windows together cover
   ``min_cycles`` of their median period (a slow motion performed for under two of its
   cycles, which no single window holds one and a half times: 13_29's alternating toe
   touches take about 4.1 s a cycle and are performed for 6.5 s).
8. **Labels**: every frame within ``window`` seconds of a motion's windows may take that
   motion; the cost of a frame is its :func:`~cyclecoord.quality.metrics.distance_to_cycle` to the
   motion's nearest window cycle, over that cycle's typical distance to its own frames,
   and :data:`NONE_COST` for "nothing periodic".  The cheapest labelling that pays half
   a ``window`` of frames per change (Viterbi) gives the labels; runs shorter than half
   a window are dropped.  A windowed segment's period is the median of its windows'
   ``frames / cycles`` (those completing ``min_cycles`` when there are any), refined by
   the segment's own autocorrelation (:func:`autocorrelation_period`).

``method="auto"`` (the default) runs both: a group of windows whose frames overlap a
global motion's excited frames by more than ``merge_overlap`` of the smaller region
joins it, other groups become motions of their own, and frames the global stage
labelled keep their global label.  Measured (``benchmarks/bench_detect.py``): on 25
synthetic chains ``auto`` keeps the global method's accuracy (mean 99.4%, min 97.9%)
with boundaries within 27 frames, while windows alone merge jumping jacks with arm
circles in some chains; on 13_29 ``auto`` labels 95% of frames correctly and finds all
six exercises (global 28%).
``method="global"`` is the paper's method alone, ``method="windows"`` the windowed stage
alone.

:func:`motion_cycles` then gives each motion a typical cycle with the phase detection
found (its class's coordinate, or time over the segment's period), rather than a fresh
barcode of the segment whose most persistent class may be one pass through it.

The package's modules: :mod:`.detector` (:func:`detect`), :mod:`.classes` (the global
stage, steps 1-5), :mod:`.windows` (the windowed stage, steps 6-8), :mod:`.result` (the
result types), :mod:`.cycles` (:func:`motion_cycles`) and :mod:`.scoring` (frame accuracy
and boundary errors against ground truth).
"""

from .classes import excitation
from .cycles import MotionCycle, motion_cycles
from .detector import METHODS, detect
from ._segments import MAX_TURN, MIN_SPEED
from .result import DetectedClass, DetectionResult, Segment, WindowInfo
from .scoring import best_match_accuracy, boundary_errors
from .windows import (
    CYCLE_BINS,
    NONE_COST,
    autocorrelation_period,
    binned_cycle,
    cycle_distance,
    window_table,
)

__all__ = [
    "detect",
    "DetectionResult",
    "DetectedClass",
    "Segment",
    "WindowInfo",
    "METHODS",
    "window_table",
    "binned_cycle",
    "cycle_distance",
    "autocorrelation_period",
    "motion_cycles",
    "MotionCycle",
    "excitation",
    "best_match_accuracy",
    "boundary_errors",
    "CYCLE_BINS",
    "NONE_COST",
    "MAX_TURN",
    "MIN_SPEED",
]
