"""Benchmark of ``cyclecoord.extract`` per stage against ripser-only and DREiMac baselines.

Run from a checkout (after ``pip install -e ".[bench]"``)::

    python benchmarks/bench_extract.py [--quick] [--repeat R] [--json out.json]

For every case the same analysed point cloud (``result.prepared.points``) is handed to
three methods:

* **cyclecoord** -- ``cc.extract`` end to end, seconds per stage (prepare, barcode,
  coordinate, density, cycle, metrics, total);
* **ripser** -- ``ripser.ripser(points, maxdim=1, thresh=<cyclecoord's threshold>,
  coeff=47, do_cocycles=True)``: the persistent cohomology alone, no coordinate;
* **DREiMac** -- ``dreimac.CircularCoords(points, n_landmarks=<all points>, prime=47)``
  followed by ``get_coordinates()`` with its defaults (``perc=0.5``, ``cocycle_idx=0``,
  ``standard_range=True``, linear partition of unity, cocycle check on).

Times are medians of ``R`` repeats after one untimed warm-up run.  Peak memory is
measured in one further, untimed run per method under :mod:`tracemalloc` (Python and
NumPy allocations only: ripser's C++ heap is invisible to it), next to the process's
high-water resident set size from :func:`resource.getrusage` (which only ever grows, so
it is reported as "so far" after each method).

The functions are importable (``tests/test_benchmarks.py`` runs a tiny case); speed is
printed, never asserted.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import math
import os
import platform
import resource
import statistics
import sys
import time
import tracemalloc
import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

import cyclecoord as cc
from cyclecoord.periodic.coordinates import unwrap
from cyclecoord.errors import CycleCoordError, ParameterError
from cyclecoord.io import atomic_write
from cyclecoord.quality.metrics import monotonicity

#: ``../shared/data`` beside the checkout (real CMU captures; never copied into the repo).
DATA_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "data"

#: Stages reported by :func:`cyclecoord.extract` in ``result.timings``.
STAGES = ("prepare", "steady", "barcode", "coordinate", "density", "cycle", "metrics", "total")

#: Published timing for CMU 69_01 frames 200-450 (Vejdemo-Johansson et al. 2014, Fig. 7):
#: cohomology 7.07 s (Dionysus) + post-processing 18.71 s, on a MacBook Air (2 GHz Core i7).
PAPER_69_01 = {"cohomology": 7.07, "post_processing": 18.71, "total": 7.07 + 18.71}

#: The issue's target for the 69_01 window end to end, in process (seconds).
TARGET_69_01 = 0.5

#: Coefficient field used by every method (cyclecoord's default).
PRIME = 47

#: Bins of the true phase used by the synthetic agreement check.
N_PHASE_BINS = 20

#: DREiMac landmark cap: above this many points fewer landmarks are used (and reported).
DEFAULT_MAX_LANDMARKS = 2000


# ----------------------------------------------------------------------------- cases
@dataclass(frozen=True)
class Case:
    """One benchmark input.

    Attributes
    ----------
    name : str
        Short label printed in the tables.
    motion : cyclecoord.Motion
        The capture handed to :func:`cyclecoord.extract`.
    frames : (int, int) or None
        Frame window passed to ``extract`` (0-based, half-open).
    max_scale : float or None
        Filtration threshold passed to ``extract`` (None: automatic).
    true_phase : ndarray, shape (T,), optional
        Known phase in cycles (unwrapped) for synthetic captures.
    period : float or None
        True mean period in frames (synthetic captures).
    paper_seconds : float or None
        Published end-to-end time for this exact window, if any.
    extract_kwargs : dict
        Further keyword arguments for ``extract`` (e.g. ``landmarks``); empty by default
        so the pipeline's own defaults are measured.
    """

    name: str
    motion: cc.Motion
    frames: tuple[int, int] | None = None
    max_scale: float | None = None
    true_phase: np.ndarray | None = None
    period: float | None = None
    paper_seconds: float | None = None
    extract_kwargs: dict = field(default_factory=dict)


def cmu_69_01_cases(data_dir: Path = DATA_DIR) -> list[Case]:
    """The CMU 69_01 walk, frames 200:450, at max scale 50 (as in the paper) and automatic.

    Raises
    ------
    FileNotFoundError
        When ``data_dir/cmu/69/69_01.amc`` does not exist.
    """
    path = Path(data_dir) / "cmu" / "69" / "69_01.amc"
    if not path.is_file():
        raise FileNotFoundError(f"CMU capture not found at {path}")
    motion = cc.load(path)
    return [
        Case("69_01 [200:450] max_scale=50", motion, (200, 450), 50.0, paper_seconds=PAPER_69_01["total"]),
        Case("69_01 [200:450] auto", motion, (200, 450), None),
    ]


def synthetic_case(n_frames: int, seed: int = 0, period: float = 120.0, noise: float = 0.5) -> Case:
    """A synthetic walk of ``n_frames`` frames with known phase (automatic threshold)."""
    cap = cc.datasets.make_periodic_capture(n_frames=n_frames, period=period, noise=noise, random_state=seed)
    return Case(
        f"synthetic {n_frames} frames", cap.motion, None, None,
        true_phase=np.asarray(cap.phase, dtype=float), period=float(period),
        # speed is measured: a clip of under 1.5 cycles (200 frames) is still read
        extract_kwargs={"min_turns": 0.75},
    )


def select_cases(
    quick: bool = False,
    data_dir: Path | None = DATA_DIR,
    synthetic_sizes: Sequence[int] = (500, 1000, 2000),
    seed: int = 0,
) -> tuple[list[Case], list[str]]:
    """The cases to run, and a printed reason for each one skipped.

    ``quick`` keeps only 69_01 at max scale 50 (or the smallest synthetic size when the
    CMU data is absent).
    """
    cases: list[Case] = []
    skipped: list[str] = []
    cmu: list[Case] = []
    if data_dir is None:
        skipped.append("69_01: no data folder given")
    else:
        try:
            cmu = cmu_69_01_cases(Path(data_dir))
        except FileNotFoundError as exc:
            skipped.append(
                f"69_01 skipped: {exc} (the real captures live in ../shared/data beside the checkout)"
            )
    if quick:
        if cmu:
            return cmu[:1], skipped
        return [synthetic_case(min(synthetic_sizes), seed)], skipped
    cases.extend(cmu)
    cases.extend(synthetic_case(int(n), seed) for n in synthetic_sizes)
    return cases, skipped


# ------------------------------------------------------------------------- measuring
def _median(values: Sequence[float]) -> float:
    return float(statistics.median(values))


def maxrss_mb() -> float:
    """High-water resident set size of this process so far, in MiB."""
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    # Linux reports KiB, macOS bytes
    return rss / (1024.0 * 1024.0) if sys.platform == "darwin" else rss / 1024.0


def python_peak_mb(fn: Callable[[], Any]) -> float:
    """Peak of memory traced by :mod:`tracemalloc` while ``fn()`` runs, in MiB.

    Covers Python objects and NumPy arrays; memory allocated inside C/C++ extensions
    with their own allocator (ripser's complex) is not seen.
    """
    was_tracing = tracemalloc.is_tracing()
    if not was_tracing:
        tracemalloc.start()
    tracemalloc.reset_peak()
    base = tracemalloc.get_traced_memory()[0]
    try:
        fn()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        if not was_tracing:
            tracemalloc.stop()
    return max(0.0, (peak - base) / (1024.0 * 1024.0))


def _extract(case: Case) -> cc.ExtractionResult:
    return cc.extract(case.motion, frames=case.frames, max_scale=case.max_scale, **case.extract_kwargs)


def time_cyclecoord(case: Case, repeat: int, tick: Callable[[], None] = lambda: None) -> tuple[dict, cc.ExtractionResult]:
    """Median seconds per stage of ``extract`` over ``repeat`` runs after one warm-up.

    Returns
    -------
    stages : dict
        Stage name -> median seconds (keys :data:`STAGES`).
    result : ExtractionResult
        The last run's result (all runs are deterministic).
    """
    result = _extract(case)
    tick()
    runs = []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        result = _extract(case)
        runs.append({**result.timings, "wall": time.perf_counter() - w0, "cpu": time.process_time() - c0})
        tick()
    # wall and CPU seconds of the whole call: on a busy machine compare the CPU seconds
    stages = {s: _median([r.get(s, 0.0) for r in runs]) for s in (*STAGES, "wall", "cpu")}
    return stages, result


def _ripser_once(points: np.ndarray, threshold: float) -> dict:
    import ripser

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ripser.ripser(points, maxdim=1, thresh=threshold, coeff=PRIME, do_cocycles=True)


def time_ripser(points: np.ndarray, threshold: float, repeat: int, tick: Callable[[], None] = lambda: None) -> dict:
    """Median seconds of ripser's full Rips cohomology (dims 0-1, cocycles) at ``threshold``."""
    res = _ripser_once(points, threshold)
    tick()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = _ripser_once(points, threshold)
        times.append(time.perf_counter() - t0)
        tick()
    h1 = np.asarray(res["dgms"][1]).reshape(-1, 2)
    pers = np.minimum(h1[:, 1], threshold) - h1[:, 0] if h1.size else np.zeros(0)
    return {
        "seconds": _median(times),
        "threshold": float(threshold),
        "n_edges": int(res.get("num_edges", 0)),
        "n_h1": int(len(h1)),
        "longest_h1_persistence": float(pers.max()) if pers.size else 0.0,
    }


def dreimac_status() -> tuple[bool, str]:
    """Whether DREiMac can be imported, and its version or the reason it cannot."""
    try:
        import dreimac
    except Exception as exc:  # ImportError, or a broken numba install
        return False, f"{type(exc).__name__}: {exc}"
    return True, str(getattr(dreimac, "__version__", "unknown"))


DREIMAC_MISSING = (
    "DREiMac baseline skipped: dreimac is not installed ({reason}); "
    'install it with  pip install -e ".[bench]"  (or  pip install dreimac)'
)


def _dreimac_once(points: np.ndarray, n_landmarks: int, standard_range: bool) -> tuple[np.ndarray, float, float]:
    """One DREiMac run: (coordinate in cycles, construction seconds, get_coordinates seconds)."""
    from dreimac import CircularCoords

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t0 = time.perf_counter()
        model = CircularCoords(points, n_landmarks=n_landmarks, prime=PRIME)
        t1 = time.perf_counter()
        theta = model.get_coordinates(perc=0.5, cocycle_idx=0, standard_range=standard_range)
        t2 = time.perf_counter()
    return np.mod(np.asarray(theta, dtype=float) / (2.0 * np.pi), 1.0), t1 - t0, t2 - t1


def time_dreimac(
    points: np.ndarray,
    repeat: int,
    max_landmarks: int = DEFAULT_MAX_LANDMARKS,
    tick: Callable[[], None] = lambda: None,
) -> dict:
    """Median seconds of DREiMac ``CircularCoords`` construction + ``get_coordinates``.

    Uses every point as a landmark when there are at most ``max_landmarks`` of them.
    ``get_coordinates`` runs with DREiMac's defaults (``perc=0.5``, ``cocycle_idx=0``
    -- the most persistent class --, linear partition of unity, ``standard_range=True``,
    cocycle check on); if DREiMac rejects the class as too short for the standard range
    the run is repeated with ``standard_range=False`` and that is reported.

    Returns
    -------
    dict
        ``construct``, ``coordinates``, ``total`` (median seconds), ``n_landmarks``,
        ``all_points`` (bool), ``settings`` and ``coordinate`` (ndarray (T,), cycles);
        or ``{"skipped": reason}`` when DREiMac is not installed.
    """
    ok, info = dreimac_status()
    if not ok:
        return {"skipped": DREIMAC_MISSING.format(reason=info)}
    n = len(points)
    n_land = int(min(n, max_landmarks))
    notes = []
    if n_land < n:
        notes.append(f"used {n_land} landmarks of {n} points (cap --max-landmarks {max_landmarks})")
    standard_range = True
    try:
        theta, _, _ = _dreimac_once(points, n_land, standard_range)
    except Exception as exc:  # DREiMac raises a bare Exception when the class is too short
        if "too short" not in str(exc):
            return {"skipped": f"DREiMac failed: {type(exc).__name__}: {exc}"}
        standard_range = False
        notes.append("the class is too short for standard_range=True; used standard_range=False")
        theta, _, _ = _dreimac_once(points, n_land, standard_range)
    tick()
    cons, coords, tot = [], [], []
    for _ in range(repeat):
        theta, a, b = _dreimac_once(points, n_land, standard_range)
        cons.append(a)
        coords.append(b)
        tot.append(a + b)
        tick()
    return {
        "version": info,
        "construct": _median(cons),
        "coordinates": _median(coords),
        "total": _median(tot),
        "n_landmarks": n_land,
        "all_points": n_land == n,
        "settings": {
            "prime": PRIME, "perc": 0.5, "cocycle_idx": 0, "partunity_fn": "linear (default)",
            "standard_range": standard_range, "check_cocycle_condition": True,
        },
        "notes": notes,
        "coordinate": theta,
    }


# ------------------------------------------------------------------------- agreement
def _orient(theta: np.ndarray) -> np.ndarray:
    """Flip a coordinate (cycles) so that it advances, on the whole, with frame order."""
    steps = np.mod(np.diff(theta) + 0.5, 1.0) - 0.5
    return np.mod(-theta, 1.0) if steps.sum() < 0 else theta


def circular_agreement(a: np.ndarray, b: np.ndarray) -> dict:
    """Agreement of two circular coordinates (cycles) up to rotation and reflection.

    For each orientation ``s`` in (+1, -1) the differences ``d = s * a - b`` are put on
    the circle; the best rotation is their circular mean.  The orientation with the
    larger mean resultant length wins.

    Returns
    -------
    dict
        ``correlation`` -- mean resultant length ``|mean(exp(2 pi i d))|`` in [0, 1]
        (1: equal up to a rotation; about 0: unrelated); ``median_difference`` and
        ``p90_difference`` -- circular distance after the best rotation, in cycles
        (0 to 0.5); ``reflected`` -- whether ``s = -1`` won; ``rotation`` in cycles.
    """
    x = np.asarray(a, dtype=float)
    y = np.asarray(b, dtype=float)
    if x.shape != y.shape or x.ndim != 1 or x.size == 0:
        raise ParameterError(f"need two 1-D coordinates of equal length, got {x.shape} and {y.shape}")
    best = None
    for s in (1.0, -1.0):
        z = np.exp(2j * np.pi * (s * x - y)).mean()
        if best is None or abs(z) > best[1]:
            best = (s, abs(z), np.angle(z) / (2 * np.pi))
    s, r, rot = best
    resid = np.abs(np.mod(s * x - y - rot + 0.5, 1.0) - 0.5)
    return {
        "correlation": float(r),
        "median_difference": float(np.median(resid)),
        "p90_difference": float(np.percentile(resid, 90)),
        "reflected": bool(s < 0),
        "rotation": float(np.mod(rot, 1.0)),
    }


def phase_agreement(theta: np.ndarray, true_phase: np.ndarray, n_bins: int = N_PHASE_BINS) -> dict:
    """How well a coordinate (cycles) follows a known phase.

    The coordinate is first oriented to advance with frame order (the same rule for
    every method).  Frames are binned by ``true_phase mod 1`` into ``n_bins`` bins; a bin
    *advances* when the circular mean coordinate of the next bin (cyclically) lies
    ahead of its own by less than half a turn.

    Returns
    -------
    dict
        ``bins_advancing`` -- fraction of the ``n_bins`` bins that advance (1.0 ideal;
        empty bins count as not advancing); ``cycles`` -- unwrapped change of the
        coordinate from the first to the last frame; ``cycles_true`` -- the same for the
        true phase; ``mean_abs_error`` -- mean circular error after the best rotation /
        reflection (:func:`cyclecoord.quality.metrics.monotonicity`), in cycles.
    """
    th = _orient(np.asarray(theta, dtype=float))
    ph = np.asarray(true_phase, dtype=float)
    if th.shape != ph.shape:
        raise ParameterError(f"coordinate and phase differ in length: {th.shape} vs {ph.shape}")
    bins = np.minimum((np.mod(ph, 1.0) * n_bins).astype(int), n_bins - 1)
    means = np.full(n_bins, np.nan)
    for k in range(n_bins):
        sel = th[bins == k]
        if sel.size:
            means[k] = np.mod(np.angle(np.exp(2j * np.pi * sel).mean()) / (2 * np.pi), 1.0)
    step = np.mod(np.roll(means, -1) - means + 0.5, 1.0) - 0.5
    advancing = np.isfinite(step) & (step > 0)
    u = unwrap(th)
    return {
        "bins_advancing": float(advancing.sum() / n_bins),
        "cycles": float(u[-1] - u[0]),
        "cycles_true": float(ph[-1] - ph[0]),
        "mean_abs_error": float(monotonicity(th, ph).mean_abs_error_after_alignment),
    }


# ---------------------------------------------------------------------------- driver
def run_case(
    case: Case,
    repeat: int = 3,
    with_dreimac: bool = True,
    max_landmarks: int = DEFAULT_MAX_LANDMARKS,
    progress: bool = True,
) -> dict:
    """Measure one case with all methods on the same analysed points.

    Returns
    -------
    dict
        ``name``, ``n_frames``, ``dims``, ``threshold``; per method (``cyclecoord``,
        ``ripser``, ``dreimac``) seconds, peak traced Python memory (MiB) and process
        high-water RSS so far (MiB); ``ratios`` (cyclecoord total / baseline seconds,
        < 1 means cyclecoord is faster); ``agreement``.  ``error`` instead when
        ``extract`` fails on the case.
    """
    if repeat < 1:
        raise ParameterError(f"repeat must be at least 1, got {repeat}")
    n_methods = 3 if with_dreimac else 2
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=n_methods * (repeat + 2), desc=case.name, unit="run", leave=False, file=sys.stderr)

    def tick(label: str | None = None) -> Callable[[], None]:
        def _t() -> None:
            if bar is not None:
                if label:
                    bar.set_postfix_str(label)
                bar.update(1)
        return _t

    out: dict[str, Any] = {"name": case.name, "frames": list(case.frames) if case.frames else None,
                           "max_scale": case.max_scale}
    try:
        # --- cyclecoord
        stages, result = time_cyclecoord(case, repeat, tick("cyclecoord"))
        clock = {k: stages.pop(k) for k in ("wall", "cpu")}  # the whole call: clock and CPU seconds
        peak = python_peak_mb(lambda: _extract(case))
        tick("cyclecoord")()
        points = np.asarray(result.prepared.points, dtype=float)
        threshold = float(result.barcode.threshold)
        out.update(n_frames=int(points.shape[0]), dims=int(points.shape[1]), threshold=threshold)
        out["cyclecoord"] = {
            "stages": stages,
            "cycles": float(result.cycles),
            "period_frames": float(result.period_frames),
            "bar": [float(result.selection.birth), None if not math.isfinite(result.selection.death) else float(result.selection.death)],
            "scale": float(result.selection.scale),
            "n_edges": int(result.barcode.n_edges),
            # points the filtration was built on (fewer than n_frames when landmarks are used)
            "filtration_points": int(result.barcode.n_points),
            "landmarks": getattr(result.estimator, "landmark_reason_", None),
            "warnings": list(result.warnings),
            "peak_python_mb": peak,
            "maxrss_mb": maxrss_mb(),
            **clock,
        }
        # --- ripser only
        rip = time_ripser(points, threshold, repeat, tick("ripser"))
        rip["peak_python_mb"] = python_peak_mb(lambda: _ripser_once(points, threshold))
        tick("ripser")()
        rip["maxrss_mb"] = maxrss_mb()
        out["ripser"] = rip
        # --- DREiMac
        coord_d = None
        if with_dreimac:
            dm = time_dreimac(points, repeat, max_landmarks, tick("DREiMac"))
            if "skipped" not in dm:
                coord_d = dm.pop("coordinate")
                u = unwrap(_orient(coord_d))
                dm["cycles"] = float(u[-1] - u[0])
                n_land = dm["n_landmarks"]
                std = dm["settings"]["standard_range"]
                dm["peak_python_mb"] = python_peak_mb(lambda: _dreimac_once(points, n_land, std))
                dm["maxrss_mb"] = maxrss_mb()
            tick("DREiMac")()
            out["dreimac"] = dm
        else:
            out["dreimac"] = {"skipped": "DREiMac baseline not requested (--no-dreimac)"}
    except CycleCoordError as exc:
        out["error"] = f"{type(exc).__name__}: {exc}"
        return out
    finally:
        if bar is not None:
            bar.close()

    total = stages["total"]
    ratios: dict[str, float | None] = {
        "cyclecoord_over_ripser": total / rip["seconds"] if rip["seconds"] > 0 else None,
        "barcode_over_ripser": stages["barcode"] / rip["seconds"] if rip["seconds"] > 0 else None,
        "cyclecoord_over_dreimac": (total / out["dreimac"]["total"]) if coord_d is not None else None,
        "cyclecoord_over_paper": (total / case.paper_seconds) if case.paper_seconds else None,
    }
    out["ratios"] = ratios
    if case.paper_seconds:
        out["paper_seconds"] = case.paper_seconds
        out["target_seconds"] = TARGET_69_01
        out["target_met"] = bool(total < TARGET_69_01)

    agreement: dict[str, Any] = {}
    theta_c = np.asarray(result.coordinate, dtype=float)
    if coord_d is not None:
        agreement["cyclecoord_vs_dreimac"] = circular_agreement(theta_c, coord_d)
    if case.true_phase is not None:
        ph = case.true_phase
        agreement["truth"] = {"cyclecoord": phase_agreement(theta_c, ph)}
        if coord_d is not None:
            agreement["truth"]["dreimac"] = phase_agreement(coord_d, ph)
        agreement["cycles_true"] = float(ph[-1] - ph[0])
    out["agreement"] = agreement
    if hasattr(os, "getloadavg"):
        out["load_average_1min"] = round(os.getloadavg()[0], 2)  # other work on the machine skews times
    return out


def machine_info() -> dict:
    """Where and with what the figures were taken."""
    import ripser
    import scipy

    ok, dm = dreimac_status()
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cpus = os.cpu_count()
    return {
        "date": _dt.datetime.now().astimezone().isoformat(timespec="seconds"),
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpus": cpus,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "ripser": getattr(ripser, "__version__", "unknown"),
        "dreimac": dm if ok else None,
        "cyclecoord": cc.__version__,
        "load_average": [round(v, 2) for v in os.getloadavg()] if hasattr(os, "getloadavg") else None,
        "git": _git_state(),
    }


def _git_state() -> str | None:
    """Commit of the checkout the benchmark runs in (``+dirty`` with local changes)."""
    import subprocess

    root = Path(__file__).resolve().parents[1]
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True,
                              text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return head + ("+dirty" if dirty else "")


def run_benchmark(
    cases: Sequence[Case],
    repeat: int = 3,
    with_dreimac: bool = True,
    max_landmarks: int = DEFAULT_MAX_LANDMARKS,
    progress: bool = True,
    skipped: Sequence[str] = (),
) -> dict:
    """Run every case; returns ``{"machine", "repeat", "paper", "skipped", "cases"}``."""
    if repeat < 1:
        raise ParameterError(f"repeat must be at least 1, got {repeat}")
    skipped = list(skipped)
    if with_dreimac:
        ok, info = dreimac_status()
        if not ok:  # each case also records the skip reason
            skipped.append(DREIMAC_MISSING.format(reason=info))
    machine = machine_info()  # load average before the runs
    results = []
    for k, case in enumerate(cases):
        if progress:
            print(f"[{k + 1}/{len(cases)}] {case.name} ...", file=sys.stderr, flush=True)
        results.append(run_case(case, repeat, with_dreimac, max_landmarks, progress))
    return {
        "machine": machine,
        "repeat": int(repeat),
        "paper": {"case": "69_01 [200:450]", **PAPER_69_01,
                  "hardware": "MacBook Air, 2 GHz Intel Core i7, 8 GB RAM; Dionysus + SciPy"},
        "target_69_01_seconds": TARGET_69_01,
        "skipped": skipped,
        "cases": results,
    }


# -------------------------------------------------------------------------- printing
def _f(x: float | None, fmt: str = "{:.3f}") -> str:
    return "-" if x is None or (isinstance(x, float) and not math.isfinite(x)) else fmt.format(x)


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h) for i, h in enumerate(headers)]
    line = "  ".join(h.ljust(w) if i == 0 else h.rjust(w) for i, (h, w) in enumerate(zip(headers, widths)))
    out = [line, "  ".join("-" * w for w in widths)]
    for r in rows:
        out.append("  ".join(c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths))))
    return "\n".join(out)


def format_report(report: dict) -> str:
    """Human-readable tables of a :func:`run_benchmark` report."""
    m = report["machine"]
    lines = [
        f"cyclecoord {m['cyclecoord']} (git {m.get('git') or 'unknown'}) benchmark  {m['date']}",
        f"{m['platform']}  {m['processor']}  cpus={m['cpus']}  python {m['python']}  numpy {m['numpy']}  "
        f"scipy {m['scipy']}  ripser {m['ripser']}  dreimac {m['dreimac'] or 'not installed'}",
        f"seconds are medians of {report['repeat']} run(s) after one warm-up; prime {PRIME} everywhere; "
        f"load average before the runs {m.get('load_average')}",
        "",
    ]
    for s in report["skipped"]:
        lines.append(f"NOTE: {s}")
    if report["skipped"]:
        lines.append("")
    cases = [c for c in report["cases"] if "error" not in c]
    for c in report["cases"]:
        if "error" in c:
            lines.append(f"ERROR in {c['name']}: {c['error']}")

    lines.append("cyclecoord.extract, seconds per stage")
    rows = [[c["name"], str(c["n_frames"]), _f(c["threshold"], "{:.2f}")]
            + [_f(c["cyclecoord"]["stages"][s]) for s in STAGES]
            + [_f(c["cyclecoord"].get(s)) for s in ("wall", "cpu")]
            + [_f(c.get("load_average_1min"), "{:.2f}")] for c in cases]
    lines.append(_table(["case", "T", "thresh", *STAGES, "wall", "CPU", "load*"], rows))
    lines.append("  wall / CPU = seconds of the whole extract call by the clock / by this process's CPU time "
                 "(on a busy machine wall > CPU: compare CPU seconds)")
    lines.append("  * 1-minute load average after the case (> 0 means other processes competed for the cores)")
    lines.append("")

    lines.append("baselines on the same points, seconds, and ratios (cyclecoord total / baseline; < 1 = cyclecoord faster)")
    rows = []
    for c in cases:
        d, r = c["dreimac"], c["ratios"]
        rows.append([
            c["name"], str(c["cyclecoord"]["filtration_points"]),
            _f(c["cyclecoord"]["stages"]["total"]), _f(c["ripser"]["seconds"]),
            _f(d.get("construct")), _f(d.get("coordinates")), _f(d.get("total")),
            (str(d["n_landmarks"]) + ("" if d.get("all_points") else "*")) if "n_landmarks" in d else "-",
            _f(r["cyclecoord_over_ripser"], "{:.2f}"), _f(r["barcode_over_ripser"], "{:.2f}"),
            _f(r["cyclecoord_over_dreimac"], "{:.2f}"), _f(r["cyclecoord_over_paper"], "{:.4f}"),
        ])
    lines.append(_table(
        ["case", "cc pts", "cc total", "ripser", "DM build", "DM coords", "DM total", "DM lmk",
         "cc/ripser", "cc barcode/ripser", "cc/DM", "cc/paper*"], rows))
    p = report["paper"]
    lines.append(
        f"* paper: {p['total']:.1f} s for {p['case']} ({p['cohomology']} s cohomology + {p['post_processing']} s "
        f"post-processing), published in Fig. 7 of the paper, measured on other hardware ({p['hardware']}); not measured here."
    )
    lines.append("  cc pts = points cyclecoord built its filtration on (fewer than T: greedy landmarks, "
                 "coordinate extended to every frame).  DM lmk = DREiMac landmarks (all points unless marked *).")
    lines.append("  ripser = full Rips cohomology on all T points (dims 0-1, cocycles) at cyclecoord's "
                 "threshold, no coordinate.")
    for c in cases:
        if "paper_seconds" in c:
            tot = c["cyclecoord"]["stages"]["total"]
            lines.append(
                f"  {c['name']}: {tot:.3f} s end to end = {c['paper_seconds'] / tot:.0f}x faster than the paper's "
                f"published {c['paper_seconds']:.1f} s; target < {c['target_seconds']} s "
                f"{'MET' if c['target_met'] else 'NOT met'}"
            )
        for note in c["dreimac"].get("notes", []):
            lines.append(f"  {c['name']}: DREiMac {note}")
        if "skipped" in c["dreimac"]:
            lines.append(f"  {c['name']}: {c['dreimac']['skipped']}")
    lines.append("")

    lines.append("memory: peak traced Python/NumPy allocation (MiB, tracemalloc) | process peak RSS so far (MiB, getrusage)")
    rows = []
    for c in cases:
        d = c["dreimac"]
        rows.append([
            c["name"], _f(c["cyclecoord"]["peak_python_mb"], "{:.1f}"), _f(c["ripser"]["peak_python_mb"], "{:.1f}"),
            _f(d.get("peak_python_mb"), "{:.1f}"), _f(c["cyclecoord"]["maxrss_mb"], "{:.0f}"),
            _f(c["ripser"]["maxrss_mb"], "{:.0f}"), _f(d.get("maxrss_mb"), "{:.0f}"),
        ])
    lines.append(_table(["case", "cc py", "ripser py", "DM py", "RSS after cc", "after ripser", "after DM"], rows))
    lines.append("")

    lines.append("agreement (printed, not asserted)")
    rows = []
    for c in cases:
        a = c["agreement"]
        vs = a.get("cyclecoord_vs_dreimac", {})
        tr = a.get("truth", {})
        tc, td = tr.get("cyclecoord", {}), tr.get("dreimac", {})
        rows.append([
            c["name"],
            _f(vs.get("correlation")), _f(vs.get("median_difference")),
            ("yes" if vs["reflected"] else "no") if vs else "-",
            _f(tc.get("bins_advancing"), "{:.2f}"), _f(td.get("bins_advancing"), "{:.2f}"),
            _f(c["cyclecoord"]["cycles"], "{:.2f}"), _f(c["dreimac"].get("cycles"), "{:.2f}"),
            _f(a.get("cycles_true"), "{:.2f}"),
            _f(tc.get("mean_abs_error")), _f(td.get("mean_abs_error")),
        ])
    lines.append(_table(
        ["case", "cc~DM corr", "cc~DM median diff", "reflected", "cc bins adv", "DM bins adv",
         "cc cycles", "DM cycles", "true cycles", "cc err", "DM err"], rows))
    lines.append(
        f"  corr = mean resultant length of the difference after best rotation/reflection (1 = same up to rotation); "
        f"diff in cycles.  bins adv = fraction of {N_PHASE_BINS} true-phase bins whose circular-mean "
        "coordinate advances; cycles = unwrapped change first->last frame (truth (T-1)/120); "
        "err = mean circular error vs true phase after best rotation/reflection (cycles)."
    )
    return "\n".join(lines)


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return [_jsonable(v) for v in x.tolist()]
    if isinstance(x, (np.floating, float)):
        return float(x) if math.isfinite(float(x)) else None
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, np.bool_):
        return bool(x)
    return x


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help="only 69_01 (or synthetic 500 without the data), 1 repeat: a smoke test")
    ap.add_argument("--repeat", type=int, default=None, help="timed repeats per method (default 3; 1 with --quick)")
    ap.add_argument("--json", metavar="OUT", help="also write the full report as JSON")
    ap.add_argument("--no-dreimac", action="store_true", help="skip the DREiMac baseline")
    ap.add_argument("--max-landmarks", type=int, default=DEFAULT_MAX_LANDMARKS,
                    help=f"DREiMac landmark cap (default {DEFAULT_MAX_LANDMARKS}; all points up to it)")
    ap.add_argument("--sizes", type=int, nargs="+", default=[500, 1000, 2000], help="synthetic capture lengths")
    ap.add_argument("--seed", type=int, default=0, help="seed of the synthetic captures")
    ap.add_argument("--data", type=Path, default=DATA_DIR, help=f"shared data folder (default {DATA_DIR})")
    ap.add_argument("--no-progress", action="store_true", help="no progress bars")
    ap.add_argument("--landmarks", default=None,
                    help="pass landmarks=... to extract ('none' = every frame, or a number); "
                         "default: the pipeline's own default")
    args = ap.parse_args(argv)
    repeat = args.repeat if args.repeat is not None else (1 if args.quick else 3)
    if repeat < 1:
        ap.error("--repeat must be at least 1")
    if args.max_landmarks < 3:
        ap.error("--max-landmarks must be at least 3")
    if any(n < 20 for n in args.sizes):
        ap.error("--sizes must be at least 20 frames each")
    if args.json:
        out = Path(args.json)
        if not (out.parent if str(out.parent) else Path(".")).is_dir():
            ap.error(f"--json: folder {out.parent} does not exist")
    cases, skipped = select_cases(args.quick, args.data, args.sizes, args.seed)
    if args.landmarks is not None:
        value: Any = None if args.landmarks.lower() == "none" else args.landmarks
        if isinstance(value, str) and value.isdigit():
            value = int(value)
        cases = [replace(c, extract_kwargs={**c.extract_kwargs, "landmarks": value}) for c in cases]
    for s in skipped:
        print(s, flush=True)
    if not args.no_dreimac:
        ok, info = dreimac_status()
        if not ok:
            print(DREIMAC_MISSING.format(reason=info), flush=True)
    report = run_benchmark(cases, repeat, not args.no_dreimac, args.max_landmarks,
                           progress=not args.no_progress, skipped=skipped)
    print(format_report(report), flush=True)
    if args.json:
        with atomic_write(args.json, "w") as fh:
            json.dump(_jsonable(report), fh, indent=2)
            fh.write("\n")
        print(f"report written to {args.json}")
    return 1 if any("error" in c for c in report["cases"]) else 0


if __name__ == "__main__":
    sys.exit(main())
