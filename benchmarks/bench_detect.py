"""Evidence for ``cyclecoord.detect``: synthetic chains, real captures and the time on 13_29.

Run from a checkout::

    python benchmarks/bench_detect.py [--quick] [--json out.json]

Sections (each can be chosen with ``--parts``):

* **synthetic** -- :func:`cyclecoord.datasets.make_motion_chain` with three different
  periodic motions and known boundaries, for several kind triples and seeds, with every
  method of ``detect`` (``auto``, the default, then ``global`` and ``windows``; the
  summary of each is printed side by side).  Printed per case (default method): frame accuracy after the best one-to-one matching of detected motions to
  true ones (:func:`cyclecoord.periodic.detection.best_match_accuracy`), the largest boundary error
  (:func:`cyclecoord.periodic.detection.boundary_errors`), the motions found and the seconds; then
  the mean and minimum.  Targets: accuracy >= 90 %, boundaries within 30 frames.
* **13_29** -- CMU 13_29 (six exercises) against ``../shared/data/labels/13_29.csv``:
  accuracy after matching (target >= 80 %), the matching, per activity the fraction of
  its frames given its matched motion, the segments, and a small table over settings
  (method, delay, landmarks).
* **01_09** -- CMU 01_09 (playground) against the annotation printed in Fig. 10 of
  Vejdemo-Johansson et al. (2014): per activity, the fraction of its frames covered by
  any detected motion, and by which.
* **concat** -- the paper's concatenation experiment (walk, jog, hop) rebuilt from the
  captures at hand: 69_01 [200:450] (walk), 143_01 [0:96] (jog) and 13_29 [0:456]
  (jumping jacks, in place of the paper's hop 143_05, which we do not have); every
  method side by side.
* **timing** -- ``cc.load`` + ``detect`` on 13_29 (4,592 frames) end to end, per stage,
  against the 30 s target (PASS/FAIL printed, never asserted).

Real captures are read from ``../shared/data`` beside the checkout; when they are
absent those sections print why they were skipped.  The functions are importable
(``tests/test_benchmarks.py`` runs one small chain); nothing here asserts speed.
"""

from __future__ import annotations

import argparse
import csv
import datetime as _dt
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

_HERE = Path(__file__).resolve().parent
if str(_HERE) not in sys.path:  # the sibling benchmark module, also when imported from tests
    sys.path.insert(0, str(_HERE))

import bench_extract as bx  # noqa: E402  (table printing, JSON conversion, git state)

import cyclecoord as cc  # noqa: E402
from cyclecoord.periodic.detection import DetectionResult, best_match_accuracy, boundary_errors, detect  # noqa: E402
from cyclecoord.errors import NoPeriodicMotionError, ParameterError, ParseError  # noqa: E402
from cyclecoord.io import atomic_write  # noqa: E402

#: ``../shared/data`` beside the checkout (real CMU captures; never copied into the repo).
DATA_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data"

#: Every section, in the order it runs.
PARTS = ("synthetic", "13_29", "01_09", "concat", "timing")

#: Kind triples of the synthetic chains (every kind of the generator appears).
TRIPLES: tuple[tuple[str, str, str], ...] = (
    ("walk", "jumping_jack", "arm_circles"),
    ("walk", "jog", "squat"),
    ("squat", "arm_circles", "jog"),
    ("jog", "jumping_jack", "squat"),
    ("arm_circles", "walk", "jumping_jack"),
)
#: Seeds of the synthetic chains.
SEEDS = (0, 1, 2, 3, 4)
#: Frames per synthetic segment (the generator's default).
SEGMENT_FRAMES = 600

#: The issue's targets.
TARGET_CHAIN_ACCURACY = 0.90
TARGET_BOUNDARY_FRAMES = 30
TARGET_13_29_ACCURACY = 0.80
TARGET_13_29_SECONDS = 30.0

#: CMU 01_09 annotation printed in Fig. 10 of the paper: (activity, first, last frame),
#: 0-based and *inclusive* as printed.  Frame 2745 is listed twice (end of the second
#: ladder climb and start of the second sitting); here it goes to the later entry.
#: Frames 3881-4241 are not annotated.
FIG10_01_09: tuple[tuple[str, int, int], ...] = (
    ("walking", 0, 293),
    ("climbing a ladder", 294, 617),
    ("sitting, dangling feet", 618, 1483),
    ("jumping down", 1484, 1960),
    ("walking", 1961, 2136),
    ("climbing a ladder", 2137, 2745),
    ("sitting, dangling feet", 2745, 3880),
)

#: Parts of the concatenation experiment: (name, subject folder, trial, start, stop, note).
CONCAT_PARTS: tuple[tuple[str, str, str, int, int, str], ...] = (
    ("walk", "69", "69_01", 200, 450, "the paper's walk window"),
    ("jog", "143", "143_01", 0, 96, "the paper's jog frames; subject 143 may really be 60 fps, kept at 120"),
    ("jumping jacks", "13", "13_29", 0, 456, "real jumping jacks, in place of the paper's hop (143_05, not available)"),
)

#: Detection methods compared side by side (the default, ``"auto"``, is the main run).
METHODS: tuple[str, ...] = ("auto", "global", "windows")

#: Settings of the 13_29 sensitivity table (``detect`` keyword arguments).
SENSITIVITY: tuple[dict, ...] = (
    {"method": "global"},
    {"method": "windows"},
    {"delay": 0.0},
    {"delay": 0.25},
    {"delay": 0.5},
    {"delay": 0.0, "landmarks": 1000},
    {"delay": 0.25, "landmarks": 1000},
    {"delay": 0.5, "landmarks": 1000},
)


# ------------------------------------------------------------------------ helpers
def _bar(total: int, desc: str, progress: bool):
    if not progress or total < 1:
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit="run", leave=False, file=sys.stderr)


def settings_label(kwargs: dict) -> str:
    """Short text of ``detect`` keyword arguments ("defaults" when empty)."""
    if not kwargs:
        return "defaults"
    return ", ".join(f"{k}={v}" for k, v in kwargs.items())


def run_detect(motion: cc.Motion, **kwargs: Any) -> tuple[DetectionResult, float, str | None]:
    """``detect(motion, **kwargs)`` timed by wall clock.

    Returns
    -------
    result : DetectionResult
        Also when nothing periodic was found (the partial result of the error).
    seconds : float
        Wall-clock seconds of the call.
    note : str or None
        The :class:`NoPeriodicMotionError` message when nothing was found.
    """
    kwargs.setdefault("progress", False)
    t0 = time.perf_counter()
    try:
        result = detect(motion, **kwargs)
        note = None
    except NoPeriodicMotionError as exc:
        result = exc.result
        note = str(exc)
    return result, time.perf_counter() - t0, note


def frame_truth(spans: Sequence[tuple[int, int, str]], n_frames: int) -> tuple[np.ndarray, list[str]]:
    """Per-frame truth from half-open ``(start, stop, name)`` spans.

    Returns
    -------
    truth : ndarray of int, shape (n_frames,)
        Index of the frame's activity in ``names``; -1 where no span covers it.  Later
        spans overwrite earlier ones where they overlap.
    names : list of str
        Distinct activity names in order of first appearance.
    """
    names: list[str] = []
    truth = np.full(int(n_frames), -1, dtype=int)
    for a, b, name in spans:
        if name not in names:
            names.append(name)
        truth[max(0, int(a)) : min(int(n_frames), int(b))] = names.index(name)
    return truth, names


def segments_of(truth: np.ndarray, names: Sequence[str]) -> list[tuple[int, int, str]]:
    """Half-open ``(start, stop, name)`` runs of a per-frame truth (``-1`` runs left out)."""
    t = np.asarray(truth)
    out = []
    start = 0
    for i in range(1, len(t) + 1):
        if i == len(t) or t[i] != t[start]:
            if t[start] >= 0:
                out.append((start, i, names[int(t[start])]))
            start = i
    return out


def activity_scores(labels: np.ndarray, truth: np.ndarray, names: Sequence[str]) -> dict:
    """Accuracy after best matching, and per activity what the detector gave its frames.

    Returns
    -------
    dict
        ``accuracy`` (frames with truth -1 not scored), ``matching`` ``{motion id:
        activity name}``, and ``activities``: per name ``frames``, ``matched_motion``
        (or None), ``matched_fraction`` (share of its frames labelled with its matched
        motion), ``covered_fraction`` (share labelled with any motion) and ``by_motion``
        ``{motion id: share}``.
    """
    lab = np.asarray(labels)
    tru = np.asarray(truth)
    acc, match = best_match_accuracy(lab, tru)
    inverse = {t: p for p, t in match.items()}
    per = {}
    for k, name in enumerate(names):
        sel = tru == k
        n = int(sel.sum())
        got = lab[sel]
        mids, counts = np.unique(got[got >= 0], return_counts=True)
        pid = inverse.get(k)
        per[name] = {
            "frames": n,
            "matched_motion": pid,
            "matched_fraction": float(np.mean(got == pid)) if (n and pid is not None) else 0.0,
            "covered_fraction": float(np.mean(got >= 0)) if n else 0.0,
            "by_motion": {int(m): float(c / n) for m, c in zip(mids, counts)},
        }
    return {
        "accuracy": acc,
        "matching": {int(p): names[t] for p, t in sorted(match.items())},
        "activities": per,
    }


def class_table(result: DetectionResult) -> list[dict]:
    """Every candidate H1 class: index, bar, scale, status, motion, excited frames."""
    return [
        {
            "index": c.index, "birth": float(c.birth), "death": float(c.death), "scale": float(c.scale),
            "status": c.status, "motion": c.motion, "excited_frames": int(c.mask.sum()),
        }
        for c in result.classes
    ]


def class_coverage(result: DetectionResult, spans: Sequence[tuple[int, int, str]]) -> dict:
    """Per span name, the share of its frames inside each kept class's excitation mask.

    This is the detector's view *before* frames are labelled (short label runs are
    dropped afterwards), so it shows classes that found a motion but lost its frames.
    """
    out: dict[str, dict[int, float]] = {}
    for a, b, name in spans:
        row = out.setdefault(name, {})
        for c in result.classes:
            share = float(np.mean(c.mask[a:b])) if b > a else 0.0
            if share > 0:
                row[c.index] = max(row.get(c.index, 0.0), share)
    return out


def unlabelled_motions(result: DetectionResult, spans: Sequence[tuple[int, int, str]]) -> list[str]:
    """Notes on kept classes whose motion ended up labelling no frame at all.

    :func:`cyclecoord.periodic.detection.detect` drops label runs shorter than its smoothing window
    (``window`` seconds, odd number of frames), so a motion excited for less than that
    is found as a class but labels nothing.
    """
    fps = result.motion.fps
    w = max(3, int(round(result.parameters.get("window", 1.0) * fps)) | 1)
    notes = []
    for c in result.classes:
        if c.motion < 0 or np.any(result.labels == c.motion):
            continue
        n = int(c.mask.sum())
        where = max(spans, key=lambda sp: float(np.sum(c.mask[sp[0] : sp[1]])), default=None)
        inside = "" if where is None else (
            f", {100 * float(np.mean(c.mask[where[0] : where[1]])):.1f}% of {where[2]} ({where[0]}-{where[1]})")
        why = (f"its excited stretch ({n} frames) is shorter than the {w}-frame smoothing window, "
               "and shorter label runs are dropped") if n < w else "another motion's excitation was stronger there"
        notes.append(f"class {c.index} (motion {c.motion}) is excited on {n} frames{inside}, but motion "
                     f"{c.motion} labels no frame: {why}")
    return notes


def _summary(result: DetectionResult, seconds: float, note: str | None) -> dict:
    return {
        "seconds": seconds,
        "timings": dict(result.timings),
        "n_motions": int(result.n_motions),
        "segments": [s.to_dict() for s in result.segments],
        "classes": class_table(result),
        "warnings": list(result.warnings),
        "threshold": float(result.barcode.threshold),
        "filtration_points": int(result.barcode.n_points),
        "nothing_found": note,
        "n_labelled_motions": int(len(np.unique(result.labels[result.labels >= 0]))),
    }


def _load(data_dir: Path, subject: str, trial: str) -> cc.Motion:
    path = Path(data_dir) / "cmu" / subject / f"{trial}.amc"
    if not path.is_file():
        raise FileNotFoundError(f"CMU capture not found at {path} (the real captures live in ../shared/data "
                                "beside the checkout)")
    return cc.load(path)


def load_activity_labels(path: Path, n_frames: int | None = None) -> list[tuple[int, int, str]]:
    """Read a ``start_frame,stop_frame,activity`` CSV (0-based frames, stop exclusive).

    Raises
    ------
    FileNotFoundError
        When the file does not exist.
    ParseError
        On a missing header, a row without three fields, non-integer frames, an empty
        span or one beyond ``n_frames``.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"label file not found at {path}")
    spans = []
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    if not rows or [h.strip() for h in rows[0]] != ["start_frame", "stop_frame", "activity"]:
        raise ParseError("expected the header 'start_frame,stop_frame,activity'", path, 1)
    for line, row in enumerate(rows[1:], start=2):
        if not row or all(not f.strip() for f in row):
            continue
        if len(row) != 3:
            raise ParseError(f"expected 3 fields (start_frame,stop_frame,activity), got {len(row)}", path, line)
        try:
            a, b = int(row[0]), int(row[1])
        except ValueError:
            raise ParseError(f"expected integer frames, got {row[0]!r} and {row[1]!r}", path, line) from None
        if not 0 <= a < b or (n_frames is not None and b > n_frames):
            limit = "" if n_frames is None else f" within the capture's {n_frames} frames"
            raise ParseError(f"expected 0 <= start < stop{limit}, got {a},{b}", path, line)
        spans.append((a, b, row[2].strip()))
    if not spans:
        raise ParseError("no labelled spans", path)
    return spans


def fig10_spans() -> list[tuple[int, int, str]]:
    """:data:`FIG10_01_09` as half-open spans (the later entry wins the shared frame 2745)."""
    return [(a, b + 1, name) for name, a, b in FIG10_01_09]


# ------------------------------------------------------------------------ sections
def run_chain(
    kinds: Sequence[str], seed: int, segment_frames: int = SEGMENT_FRAMES, **detect_kwargs: Any
) -> dict:
    """``detect`` on one synthetic chain, scored against its known labels and boundaries.

    Returns
    -------
    dict
        ``kinds``, ``seed``, ``n_frames``, ``accuracy`` (after best matching),
        ``matching`` ``{motion id: kind}``, ``boundary_errors`` (frames, both ways; see
        :func:`cyclecoord.periodic.detection.boundary_errors`), ``max_boundary_error``,
        ``n_motions``, ``kinds_found`` (number of true kinds matched to a motion),
        ``periods`` (true, per kind) and ``segment_periods`` (detected, per segment with
        its matched kind), ``accuracy_ok``, ``boundaries_ok``, plus ``seconds``,
        ``timings``, ``segments``, ``classes``.
    """
    cap = cc.datasets.make_motion_chain(kinds=tuple(kinds), segment_frames=segment_frames, random_state=seed)
    T = cap.motion.n_frames
    result, seconds, note = run_detect(cap.motion, **detect_kwargs)
    names = [k for _, _, k in cap.boundaries]
    names = list(dict.fromkeys(names))
    scores = activity_scores(result.labels, cap.labels, names)
    errs = boundary_errors(result.segments, cap.boundaries, T) if result.segments else []
    max_err = max(errs) if errs else T
    true_periods = dict(zip([k for _, _, k in cap.boundaries], cap.motion.metadata["periods"]))
    seg_periods = [
        {"start": s.start, "stop": s.stop, "kind": scores["matching"].get(s.motion),
         "period_frames": float(s.period_frames)}
        for s in result.segments
    ]
    out = {
        "kinds": list(kinds), "seed": int(seed), "n_frames": int(T), "segment_frames": int(segment_frames),
        "truth": [list(b) for b in cap.boundaries],
        "accuracy": scores["accuracy"], "matching": scores["matching"], "activities": scores["activities"],
        "boundary_errors": [int(e) for e in errs], "max_boundary_error": int(max_err),
        "kinds_found": len(scores["matching"]),
        "periods": {k: float(v) for k, v in true_periods.items()}, "segment_periods": seg_periods,
        "accuracy_ok": bool(scores["accuracy"] >= TARGET_CHAIN_ACCURACY),
        "boundaries_ok": bool(max_err <= TARGET_BOUNDARY_FRAMES),
    }
    out.update(_summary(result, seconds, note))
    return out


def synthetic_section(
    triples: Sequence[Sequence[str]] = TRIPLES,
    seeds: Sequence[int] = SEEDS,
    segment_frames: int = SEGMENT_FRAMES,
    progress: bool = True,
    methods: Sequence[str] = METHODS,
) -> dict:
    """:func:`run_chain` for every triple and seed, with the mean/min summary.

    ``cases`` and ``summary`` are for ``detect``'s defaults; ``by_method`` holds the
    summary of every method in ``methods`` (the default's included) run on the same chains.
    """
    by_method: dict[str, dict] = {}
    default_cases: list[dict] = []
    for method in methods:
        cases = []
        bar = _bar(len(triples) * len(seeds), f"synthetic chains ({method})", progress)
        try:
            for kinds in triples:
                for seed in seeds:
                    if bar is not None:
                        bar.set_postfix_str(f"{'/'.join(kinds)} seed {seed}")
                    cases.append(run_chain(kinds, seed, segment_frames, method=method))
                    if bar is not None:
                        bar.update(1)
        finally:
            if bar is not None:
                bar.close()
        by_method[method] = _chain_summary(cases)
        if method == "auto":
            default_cases = cases
    if not default_cases:
        default_cases = [run_chain(k, sd, segment_frames) for k in triples for sd in seeds]
    return {
        "segment_frames": int(segment_frames),
        "cases": default_cases,
        "summary": _chain_summary(default_cases),
        "by_method": by_method,
    }


def _chain_summary(cases: Sequence[dict]) -> dict:
    """Mean/min accuracy, boundary errors, targets met and seconds over chain cases."""
    accs = [c["accuracy"] for c in cases]
    errs = [c["max_boundary_error"] for c in cases]
    return {
        "n_cases": len(cases),
        "mean_accuracy": float(np.mean(accs)) if accs else float("nan"),
        "min_accuracy": float(np.min(accs)) if accs else float("nan"),
        "mean_max_boundary_error": float(np.mean(errs)) if errs else float("nan"),
        "worst_boundary_error": int(max(errs)) if errs else None,
        "accuracy_ok": sum(c["accuracy_ok"] for c in cases),
        "boundaries_ok": sum(c["boundaries_ok"] for c in cases),
        "both_ok": sum(c["accuracy_ok"] and c["boundaries_ok"] for c in cases),
        "three_motions": sum(c["n_motions"] == 3 for c in cases),
        "mean_seconds": float(np.mean([c["seconds"] for c in cases])) if cases else float("nan"),
    }


def section_13_29(
    data_dir: Path = DATA_DIR,
    sensitivity: Sequence[dict] = SENSITIVITY,
    progress: bool = True,
) -> dict:
    """13_29 against its activity labels, with defaults and over ``sensitivity`` settings.

    Returns ``{"skipped": reason}`` when the capture or its labels are absent.
    """
    try:
        t0 = time.perf_counter()
        motion = _load(data_dir, "13", "13_29")
        load_seconds = time.perf_counter() - t0
        spans = load_activity_labels(Path(data_dir) / "labels" / "13_29.csv", motion.n_frames)
    except FileNotFoundError as exc:
        return {"skipped": f"13_29 skipped: {exc}"}
    truth, names = frame_truth(spans, motion.n_frames)
    out: dict[str, Any] = {
        "n_frames": int(motion.n_frames), "load_seconds": load_seconds,
        "truth": [list(s) for s in spans], "unlabelled_frames": int(np.sum(truth < 0)),
        "target_accuracy": TARGET_13_29_ACCURACY,
    }
    result, seconds, note = run_detect(motion)
    default = activity_scores(result.labels, truth, names)
    default.update(_summary(result, seconds, note))
    default["class_coverage"] = class_coverage(result, spans)
    default["unlabelled_motions"] = unlabelled_motions(result, spans)
    default["target_met"] = bool(default["accuracy"] >= TARGET_13_29_ACCURACY)
    out["defaults"] = default
    rows = []
    bar = _bar(len(sensitivity), "13_29 settings", progress)
    try:
        for kw in sensitivity:
            if bar is not None:
                bar.set_postfix_str(settings_label(kw))
            if _is_default(kw):
                r, s, n = result, seconds, note
            else:
                r, s, n = run_detect(motion, **kw)
            sc = activity_scores(r.labels, truth, names)
            rows.append({
                "settings": dict(kw), "label": settings_label(kw), "accuracy": sc["accuracy"],
                "n_motions": int(r.n_motions),
                "activities_found": [a for a, v in sc["activities"].items() if v["matched_fraction"] >= 0.5],
                "matched_fractions": {a: v["matched_fraction"] for a, v in sc["activities"].items()
                                      if v["matched_motion"] is not None},
                "matching": sc["matching"], "seconds": s, "nothing_found": n,
                "filtration_points": int(r.barcode.n_points),
            })
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    out["sensitivity"] = rows
    return out


def _is_default(kwargs: dict) -> bool:
    """Whether ``detect(**kwargs)`` is the same call as ``detect()`` with its defaults."""
    defaults = {"delay": 0.25, "landmarks": "auto", "method": "auto"}
    return all(k in defaults and defaults[k] == v for k, v in kwargs.items())


def section_01_09(data_dir: Path = DATA_DIR, settings: Sequence[dict] = ({}, {"method": "global"}, {"method": "windows"},
                                                                         {"delay": 0.0}, {"delay": 0.5}),
                  progress: bool = True) -> dict:
    """01_09 against the paper's Fig. 10 annotation, for each of ``settings``."""
    try:
        motion = _load(data_dir, "01", "01_09")
    except FileNotFoundError as exc:
        return {"skipped": f"01_09 skipped: {exc}"}
    spans = fig10_spans()
    truth, names = frame_truth(spans, motion.n_frames)
    truth_spans = segments_of(truth, names)
    out: dict[str, Any] = {
        "n_frames": int(motion.n_frames), "truth": [list(s) for s in truth_spans],
        "unannotated_frames": int(np.sum(truth < 0)), "runs": [],
    }
    bar = _bar(len(settings), "01_09 settings", progress)
    try:
        for kw in settings:
            result, seconds, note = run_detect(motion, **kw)
            run = {"settings": dict(kw), "label": settings_label(kw)}
            run.update(activity_scores(result.labels, truth, names))
            run.update(_summary(result, seconds, note))
            run["class_coverage"] = class_coverage(result, truth_spans)
            run["unlabelled_motions"] = unlabelled_motions(result, truth_spans)
            out["runs"].append(run)
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return out


def build_concatenation(data_dir: Path = DATA_DIR) -> tuple[cc.Motion, list[tuple[int, int, str]], list[str]]:
    """The walk + jog + jumping-jacks capture of :data:`CONCAT_PARTS` and its true spans.

    Returns
    -------
    motion : Motion
        ``Motion.concatenate`` of the parts (the first part's skeleton is kept).
    spans : list of (start, stop, name)
        Half-open frames of each part in the joined capture.
    notes : list of str
    """
    parts, spans, notes = [], [], []
    at = 0
    for name, subject, trial, a, b, note in CONCAT_PARTS:
        m = _load(data_dir, subject, trial)
        if b > m.n_frames:
            raise ParameterError(f"{trial} has {m.n_frames} frames, fewer than the {b} needed")
        parts.append(m[a:b])
        spans.append((at, at + (b - a), name))
        notes.append(f"{name}: {trial} [{a}:{b}] ({b - a} frames) -- {note}")
        at += b - a
    first = parts[0]
    # same channels in another order are reordered; anything else is left for concatenate to reject
    aligned = [first] + [p.select(first.channels) if p.channels != first.channels
                         and set(p.channels) == set(first.channels) else p for p in parts[1:]]
    return cc.Motion.concatenate(aligned), spans, notes


def section_concat(data_dir: Path = DATA_DIR) -> dict:
    """The concatenation experiment: detected segments, accuracy, parts found."""
    try:
        motion, spans, notes = build_concatenation(data_dir)
    except FileNotFoundError as exc:
        return {"skipped": f"concatenation skipped: {exc}"}
    truth, names = frame_truth(spans, motion.n_frames)
    result, seconds, note = run_detect(motion)
    out: dict[str, Any] = {"n_frames": int(motion.n_frames), "truth": [list(s) for s in spans], "notes": notes}
    out.update(activity_scores(result.labels, truth, names))
    out.update(_summary(result, seconds, note))
    errs = boundary_errors(result.segments, spans, motion.n_frames) if result.segments else []
    out["boundary_errors"] = [int(e) for e in errs]
    out["parts_found"] = [a for a, v in out["activities"].items() if v["matched_fraction"] >= 0.5]
    out["class_coverage"] = class_coverage(result, spans)
    out["unlabelled_motions"] = unlabelled_motions(result, spans)
    out["methods"] = {}
    for method in METHODS:
        r, sec, n = (result, seconds, note) if method == "auto" else run_detect(motion, method=method)
        sc = activity_scores(r.labels, truth, names)
        errs = boundary_errors(r.segments, spans, motion.n_frames) if r.segments else []
        out["methods"][method] = {
            "accuracy": sc["accuracy"], "n_motions": int(r.n_motions), "seconds": sec, "nothing_found": n,
            "parts_found": [a for a, v in sc["activities"].items() if v["matched_fraction"] >= 0.5],
            "matched_fractions": {a: v["matched_fraction"] for a, v in sc["activities"].items()},
            "boundary_errors": [int(e) for e in errs],
        }
    return out


def section_timing(data_dir: Path = DATA_DIR, repeat: int = 1, progress: bool = True) -> dict:
    """``cc.load`` + ``detect`` (defaults) on 13_29, median of ``repeat`` runs, per stage."""
    if repeat < 1:
        raise ParameterError(f"repeat must be at least 1, got {repeat}")
    path = Path(data_dir) / "cmu" / "13" / "13_29.amc"
    if not path.is_file():
        return {"skipped": f"timing skipped: CMU capture not found at {path}"}
    runs = []
    bar = _bar(repeat, "13_29 timing", progress)
    try:
        for _ in range(repeat):
            t0 = time.perf_counter()
            motion = cc.load(path)
            t1 = time.perf_counter()
            c1 = time.process_time()
            result, seconds, _ = run_detect(motion)
            runs.append({"load": t1 - t0, "detect": seconds, "end_to_end": t1 - t0 + seconds,
                         "detect_cpu": time.process_time() - c1, "stages": dict(result.timings)})
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    med = lambda key: float(statistics.median(r[key] for r in runs))  # noqa: E731
    stages = {k: float(statistics.median(r["stages"].get(k, 0.0) for r in runs)) for k in runs[0]["stages"]}
    total = med("end_to_end")
    return {
        "n_frames": int(motion.n_frames), "repeat": int(repeat), "load": med("load"), "detect": med("detect"),
        "detect_cpu": med("detect_cpu"),
        "end_to_end": total, "stages": stages, "runs": runs, "target_seconds": TARGET_13_29_SECONDS,
        "passed": bool(total < TARGET_13_29_SECONDS),
        "filtration_points": int(result.barcode.n_points),
        "load_average_1min": round(os.getloadavg()[0], 2) if hasattr(os, "getloadavg") else None,
    }


# ------------------------------------------------------------------------ driver
def machine_info() -> dict:
    """Where and with what the figures were taken."""
    import ripser
    import scipy

    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cpus = os.cpu_count()
    return {
        "date": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
        "platform": platform.platform(), "cpus": cpus, "python": platform.python_version(),
        "numpy": np.__version__, "scipy": scipy.__version__,
        "ripser": getattr(ripser, "__version__", "unknown"), "cyclecoord": cc.__version__,
        "git": bx._git_state(),
        "load_average": [round(v, 2) for v in os.getloadavg()] if hasattr(os, "getloadavg") else None,
    }


def run_benchmark(
    parts: Sequence[str] = PARTS,
    quick: bool = False,
    data_dir: Path = DATA_DIR,
    triples: Sequence[Sequence[str]] | None = None,
    seeds: Sequence[int] | None = None,
    segment_frames: int = SEGMENT_FRAMES,
    repeat: int = 1,
    progress: bool = True,
) -> dict:
    """Run the chosen sections.

    ``quick`` runs one chain (first triple, seed 0), 13_29 with defaults only (no
    settings table) and the timing, and skips 01_09 and the concatenation.  Returns
    ``{"machine", "quick", "parts", "skipped", <section name>: ...}``.
    """
    unknown = [p for p in parts if p not in PARTS]
    if unknown:
        raise ParameterError(f"unknown part(s) {unknown}; choose from {list(PARTS)}")
    data_dir = Path(data_dir)
    triples = list(triples) if triples is not None else (list(TRIPLES[:1]) if quick else list(TRIPLES))
    seeds = list(seeds) if seeds is not None else ([0] if quick else list(SEEDS))
    report: dict[str, Any] = {"machine": machine_info(), "quick": bool(quick), "parts": list(parts),
                              "data_dir": str(data_dir), "skipped": []}
    steps: list[tuple[str, Callable[[], dict]]] = [
        ("synthetic", lambda: synthetic_section(triples, seeds, segment_frames, progress,
                                                ("auto",) if quick else METHODS)),
        ("13_29", lambda: section_13_29(data_dir, () if quick else SENSITIVITY, progress)),
        ("01_09", lambda: section_01_09(data_dir, progress=progress)),
        ("concat", lambda: section_concat(data_dir)),
        ("timing", lambda: section_timing(data_dir, repeat, progress)),
    ]
    for name, fn in steps:
        if name not in parts:
            continue
        if quick and name in ("01_09", "concat"):
            report["skipped"].append(f"{name} skipped in --quick mode")
            continue
        if progress:
            print(f"[{name}] ...", file=sys.stderr, flush=True)
        section = fn()
        report[name] = section
        if "skipped" in section:
            report["skipped"].append(section["skipped"])
    return report


# ------------------------------------------------------------------------ printing
_f = bx._f
_table = bx._table


def _pct(x: float | None) -> str:
    return "-" if x is None or not np.isfinite(x) else f"{100 * x:.1f}%"


def _segment_rows(segments: Sequence[dict], matching: dict) -> list[list[str]]:
    return [[f"{s['start']}-{s['stop']}", str(s["motion"]), str(matching.get(s["motion"], "-")),
             ",".join(str(c) for c in s["classes"]), _f(s["birth"], "{:.1f}"),
             _f(s["death"], "{:.1f}"), _f(s["scale"], "{:.1f}"), _f(s["cycles"], "{:.2f}"),
             _f(s["period_frames"], "{:.1f}")] for s in segments]


_SEG_HEAD = ["frames", "motion", "matched to", "classes", "birth", "death", "scale", "cycles", "period (frames)"]


def _activity_rows(activities: dict) -> list[list[str]]:
    rows = []
    for name, v in activities.items():
        by = ", ".join(f"m{m}: {_pct(f)}" for m, f in sorted(v["by_motion"].items(), key=lambda kv: -kv[1]))
        rows.append([name, str(v["frames"]), "-" if v["matched_motion"] is None else str(v["matched_motion"]),
                     _pct(v["matched_fraction"]), _pct(v["covered_fraction"]), by or "none"])
    return rows


_ACT_HEAD = ["activity", "frames", "matched motion", "got its motion", "any motion", "by motion"]


def _class_lines(classes: Sequence[dict], coverage: dict | None = None, lost: Sequence[str] = ()) -> list[str]:
    lines = [_table(["class", "birth", "death", "scale", "excited frames", "motion", "status"],
                    [[str(c["index"]), _f(c["birth"], "{:.1f}"), _f(c["death"], "{:.1f}"), _f(c["scale"], "{:.1f}"),
                      str(c["excited_frames"]), str(c["motion"]), c["status"]] for c in classes])]
    if coverage:
        lines.append("  excitation of each class (before labelling) per activity: "
                     + "; ".join(f"{a}: " + (", ".join(f"class {k} {_pct(v)}" for k, v in sorted(cov.items()))
                                             or "none") for a, cov in coverage.items()))
    lines.extend(f"  NOTE: {n}" for n in lost)
    return lines


def format_report(report: dict) -> str:
    """Human-readable tables of a :func:`run_benchmark` report."""
    m = report["machine"]
    lines = [
        f"cyclecoord {m['cyclecoord']} (git {m.get('git') or 'unknown'}) detect benchmark  {m['date']}",
        f"{m['platform']}  cpus={m['cpus']}  python {m['python']}  numpy {m['numpy']}  scipy {m['scipy']}  "
        f"ripser {m['ripser']}  load average before the runs {m.get('load_average')}",
        "",
    ]
    for s in report["skipped"]:
        lines.append(f"NOTE: {s}")
    if report["skipped"]:
        lines.append("")

    syn = report.get("synthetic")
    if syn:
        lines.append(f"== synthetic chains (make_motion_chain, {syn['segment_frames']} frames per motion, "
                     "40-frame transitions not scored)")
        rows = []
        for c in syn["cases"]:
            found = ",".join(sorted(c["matching"].values()))
            rows.append([f"{'/'.join(c['kinds'])} seed {c['seed']}", str(c["n_frames"]), _pct(c["accuracy"]),
                         str(c["max_boundary_error"]), f"{c['n_motions']} ({found or 'none'})",
                         " ".join(_f(p["period_frames"], "{:.0f}") for p in c["segment_periods"]) or "-",
                         " ".join(f"{c['periods'][k]:.0f}" for k in c["kinds"]),
                         _f(c["seconds"], "{:.2f}"),
                         "ok" if c["accuracy_ok"] and c["boundaries_ok"] else "MISS"])
        lines.append(_table(["chain", "T", "accuracy", "max bnd err", "motions (matched kinds)",
                             "segment periods", "true periods", "seconds", "targets"], rows))
        s = syn["summary"]
        lines.append(
            f"  {s['n_cases']} chains: accuracy mean {_pct(s['mean_accuracy'])}, min {_pct(s['min_accuracy'])} "
            f"(target >= {TARGET_CHAIN_ACCURACY:.0%}: {s['accuracy_ok']}/{s['n_cases']}); max boundary error "
            f"mean {_f(s['mean_max_boundary_error'], '{:.1f}')}, worst {s['worst_boundary_error']} frames "
            f"(target <= {TARGET_BOUNDARY_FRAMES}: {s['boundaries_ok']}/{s['n_cases']}); both targets "
            f"{s['both_ok']}/{s['n_cases']}; exactly 3 motions {s['three_motions']}/{s['n_cases']}; "
            f"mean {_f(s['mean_seconds'], '{:.2f}')} s per chain"
        )
        lines.append("  accuracy = frame accuracy after the best one-to-one matching of motions to kinds; "
                     "boundary errors both ways (true->nearest detected, detected->nearest true)")
        if syn.get("by_method"):
            lines.append("  methods side by side on the same chains:")
            lines.append(_table(
                ["method", "mean accuracy", "min accuracy", "worst bnd err", "both targets", "3 motions", "s/chain"],
                [[m + (" (default)" if m == "auto" else ""), _pct(v["mean_accuracy"]), _pct(v["min_accuracy"]),
                  str(v["worst_boundary_error"]), f"{v['both_ok']}/{v['n_cases']}",
                  f"{v['three_motions']}/{v['n_cases']}", _f(v["mean_seconds"], "{:.2f}")]
                 for m, v in syn["by_method"].items()]))
        lines.append("")

    r = report.get("13_29")
    if r and "skipped" not in r:
        d = r["defaults"]
        lines.append(f"== 13_29 ({r['n_frames']} frames, six exercises) against ../shared/data/labels/13_29.csv "
                     f"({r['unlabelled_frames']} unlabelled frames not scored), detect() defaults")
        lines.append(f"  accuracy after best matching: {_pct(d['accuracy'])} (target >= {TARGET_13_29_ACCURACY:.0%}: "
                     f"{'MET' if d['target_met'] else 'NOT met'}); {d['n_motions']} motion(s), "
                     f"{len(d['matching'])} of {len(d['activities'])} activities matched; "
                     f"{_f(d['seconds'], '{:.1f}')} s; filtration on {d['filtration_points']} points")
        lines.append("  matching: " + (", ".join(f"motion {k} -> {v}" for k, v in d["matching"].items()) or "none"))
        lines.append(_table(_ACT_HEAD, _activity_rows(d["activities"])))
        lines.append(_table(_SEG_HEAD, _segment_rows(d["segments"], d["matching"])))
        lines.extend(_class_lines(d["classes"], d.get("class_coverage"), d.get("unlabelled_motions", ())))
        if d["nothing_found"]:
            lines.append(f"  nothing found: {d['nothing_found']}")
        if r["sensitivity"]:
            lines.append("  settings (all else default):")
            rows = [[row["label"], _pct(row["accuracy"]), str(row["n_motions"]),
                     ", ".join(f"{a} {100 * v:.0f}%" for a, v in row["matched_fractions"].items()) or "none",
                     str(len(row["activities_found"])), str(row["filtration_points"]),
                     _f(row["seconds"], "{:.1f}")] for row in r["sensitivity"]]
            lines.append(_table(["settings", "accuracy", "motions", "matched activities (share of their frames)",
                                 ">= 50%", "filtration pts", "seconds"], rows))
        lines.append("")

    r = report.get("01_09")
    if r and "skipped" not in r:
        lines.append(f"== 01_09 ({r['n_frames']} frames) against the paper's Fig. 10 annotation "
                     f"({r['unannotated_frames']} unannotated frames at the end not scored)")
        lines.append("  truth: " + "; ".join(f"{n} {a}-{b - 1}" for a, b, n in r["truth"]))
        for run in r["runs"]:
            lines.append(f"  -- detect({run['label']}): {run['n_motions']} motion(s), accuracy after matching "
                         f"{_pct(run['accuracy'])}, {_f(run['seconds'], '{:.1f}')} s, filtration on "
                         f"{run['filtration_points']} points")
            lines.append(_table(_ACT_HEAD, _activity_rows(run["activities"])))
            if run["segments"]:
                lines.append(_table(_SEG_HEAD, _segment_rows(run["segments"], run["matching"])))
            lines.extend(_class_lines(run["classes"], run.get("class_coverage"), run.get("unlabelled_motions", ())))
            if run["nothing_found"]:
                lines.append(f"  nothing found: {run['nothing_found']}")
        lines.append("")

    r = report.get("concat")
    if r and "skipped" not in r:
        lines.append(f"== concatenation (paper §6.4 / Fig. 9: walk, jog, hop), {r['n_frames']} frames")
        for n in r["notes"]:
            lines.append(f"  {n}")
        lines.append(f"  accuracy after best matching: {_pct(r['accuracy'])}; {r['n_motions']} motion(s) "
                     f"({r['n_labelled_motions']} labelling frames); parts found "
                     f"(>= 50% of frames with their motion): {', '.join(r['parts_found']) or 'none'}; boundary errors "
                     f"{r['boundary_errors'] or '-'}; {_f(r['seconds'], '{:.1f}')} s")
        lines.append(_table(_ACT_HEAD, _activity_rows(r["activities"])))
        if r["segments"]:
            lines.append(_table(_SEG_HEAD, _segment_rows(r["segments"], r["matching"])))
        lines.extend(_class_lines(r["classes"], r.get("class_coverage"), r.get("unlabelled_motions", ())))
        if r["nothing_found"]:
            lines.append(f"  nothing found: {r['nothing_found']}")
        if r.get("methods"):
            lines.append("  methods side by side:")
            lines.append(_table(
                ["method", "accuracy", "motions", "parts found (>= 50%)", "share of each part", "boundary errors", "seconds"],
                [[m, _pct(v["accuracy"]), str(v["n_motions"]), ", ".join(v["parts_found"]) or "none",
                  ", ".join(f"{a} {_pct(f)}" for a, f in v["matched_fractions"].items()),
                  str(v["boundary_errors"] or "-"), _f(v["seconds"], "{:.1f}")] for m, v in r["methods"].items()]))
        lines.append("")

    r = report.get("timing")
    if r and "skipped" not in r:
        lines.append(f"== timing: cc.load + detect() on 13_29 ({r['n_frames']} frames), median of {r['repeat']} run(s)")
        stages = r["stages"]
        lines.append(_table(["load", *stages.keys(), "detect (wall)", "detect (CPU)", "end to end"],
                            [[_f(r["load"], "{:.2f}"), *(_f(v, "{:.2f}") for v in stages.values()),
                              _f(r["detect"], "{:.2f}"), _f(r.get("detect_cpu"), "{:.2f}"),
                              _f(r["end_to_end"], "{:.2f}")]]))
        lines.append("  CPU = this process's CPU seconds for detect() (on a busy machine wall > CPU: compare CPU)")
        lines.append(f"  target < {r['target_seconds']:.0f} s end to end: {'PASS' if r['passed'] else 'FAIL'} "
                     f"({r['end_to_end']:.2f} s; filtration on {r['filtration_points']} points; 1-min load average "
                     f"after {r['load_average_1min']})")
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status (1 when a section fails to run)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="one chain, 13_29 with defaults only and the timing; no 01_09 or concatenation")
    ap.add_argument("--json", metavar="OUT", help="also write the full report as JSON")
    ap.add_argument("--parts", nargs="+", default=list(PARTS), choices=PARTS, help="sections to run")
    ap.add_argument("--seeds", type=int, nargs="+", default=None, help=f"chain seeds (default {list(SEEDS)})")
    ap.add_argument("--segment-frames", type=int, default=SEGMENT_FRAMES,
                    help=f"frames per chain segment (default {SEGMENT_FRAMES})")
    ap.add_argument("--repeat", type=int, default=1, help="timed runs of the 13_29 timing (median; default 1)")
    ap.add_argument("--data", type=Path, default=DATA_DIR, help=f"shared data folder (default {DATA_DIR})")
    ap.add_argument("--no-progress", action="store_true", help="no progress bars")
    args = ap.parse_args(argv)
    if args.repeat < 1:
        ap.error("--repeat must be at least 1")
    if args.segment_frames < 100:
        ap.error("--segment-frames must be at least 100")
    if args.json:
        out = Path(args.json)
        if not (out.parent if str(out.parent) else Path(".")).is_dir():
            ap.error(f"--json: folder {out.parent} does not exist")
    report = run_benchmark(args.parts, args.quick, args.data, None, args.seeds, args.segment_frames,
                           args.repeat, progress=not args.no_progress)
    print(format_report(report), end="", flush=True)
    if args.json:
        with atomic_write(args.json, "w") as fh:
            json.dump(bx._jsonable(report), fh, indent=2)
            fh.write("\n")
        print(f"report written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
