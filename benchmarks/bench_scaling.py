"""Long-capture benchmark: ``cyclecoord.extract`` from 1k to 64k frames, beside DREiMac and full ripser.

Run from a checkout (after ``pip install -e ".[bench]"``)::

    python benchmarks/bench_scaling.py [--quick] [--sizes 1000,4000,16000,64000] [--json out.json]

Cases: synthetic walks ``cc.datasets.make_periodic_capture(n_frames=N, period=120,
noise=0.5, random_state=0)`` for each size, and the real CMU captures 01_09 (4,242 frames)
and 13_29 (4,592 frames) from ``../shared/data/cmu`` (skipped, with the reason printed,
when absent).

Every measurement runs in its own fresh Python process (this file with ``--one TASK``),
one at a time, so cases and methods do not share memory or warm caches:

* **cyclecoord** -- ``cc.extract(motion)`` with its defaults, seconds per stage from
  ``result.timings``.  Captures that hold several activities may end with
  :class:`~cyclecoord.errors.NoPeriodicMotionError` (no single clear class); that is a
  legitimate outcome and its stages are timed too (``exc.result.timings``), and then
  ``extract(..., require_clear=False)`` is timed as well so the whole pipeline is
  measured.  The child first runs a 200-frame warm-up so imports are not timed.
* **tracemalloc** -- one more, untimed run of the same calls in another fresh process
  under :mod:`tracemalloc` (peak of Python/NumPy allocations; ripser's C++ heap is not
  seen by it).
* **DREiMac** -- ``CircularCoords(points, n_landmarks=<cyclecoord's landmark count>,
  prime=47)`` then ``get_coordinates()`` with DREiMac's defaults, on the same prepared
  points ``cc.Preprocessor().fit_transform(motion).points``; after a small warm-up (numba
  compilation); killed and reported as "timed out" after ``--timeout`` seconds.
* **full ripser** -- ``ripser.ripser(points, maxdim=1, thresh=<cyclecoord's threshold>,
  coeff=47, do_cocycles=True)`` on every point, only where it fits: ``N <= 4,000`` and the
  estimated memory ``13 N^2`` bytes (distance matrices) ``+ 64 E`` bytes (E = estimated
  edges at the threshold, :func:`cyclecoord.periodic.landmarks.estimate_complex`) within 2 GiB;
  same timeout.

Peak memory of a process is its exact high-water resident set size, read with
:func:`os.wait4` when the child ends (interpreter and imports included; the resident
size just before the timed work is reported next to it).  While a child runs, the
parent samples its resident size every 20 ms from ``/proc/<pid>/status``; the samples
falling inside each stage's time window give an (approximate) peak per stage.

Speed is printed, never asserted; the issue's targets are printed as PASS/FAIL lines.
The functions are importable (``tests/test_benchmarks.py`` runs one tiny case).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
import warnings
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

_HERE = Path(__file__).resolve().parent
if str(_HERE) not in sys.path:  # the sibling benchmark module, also from tests and child processes
    sys.path.insert(0, str(_HERE))

import bench_extract as bx  # noqa: E402  (helpers shared with the short-capture benchmark)

import cyclecoord as cc  # noqa: E402
from cyclecoord.errors import NoPeriodicMotionError, ParameterError  # noqa: E402
from cyclecoord.io import atomic_write  # noqa: E402
from cyclecoord.periodic.landmarks import DEFAULT_MEMORY_LIMIT, estimate_complex  # noqa: E402

#: Stages of ``result.timings`` (and "total").
STAGES = bx.STAGES
#: Default synthetic sizes, and those of ``--quick``.
SIZES = (1000, 4000, 16000, 64000)
QUICK_SIZES = (1000, 4000)
#: Real CMU captures: (name, subject folder, frames).
REAL_CAPTURES = (("01_09", "01", 4242), ("13_29", "13", 4592))
#: Mean period of the synthetic walks, in frames.
PERIOD = 120.0
#: The issue's targets.
TARGET_01_09_SECONDS = 5.0
TARGET_64K_SECONDS = 8.0
TARGET_64K_BYTES = 4e9
TARGET_64K_FRAMES = 64000
#: ``--million``: a 1,000,000-frame walk (issue 17: under 60 s and 2.5 GB, O(N) memory,
#: the same landmark count as at 64k).
MILLION = 1_000_000
TARGET_1M_SECONDS = 60.0
TARGET_1M_BYTES = 2.5e9
#: Synthetic captures this long are generated once, in a process of their own (the
#: generator peaks at about 6 GB at a million frames), and read back from an NPZ cache,
#: so a measuring child's peak memory is extract's and not the generator's.
CACHE_FROM_FRAMES = 200_000
CACHE_DIR = Path(tempfile.gettempdir()) / "cyclecoord_bench_captures"
#: DREiMac is not run above this many frames (its partition of unity on every frame).
DREIMAC_MAX_FRAMES = 100_000
#: Full ripser runs only up to this many points, and when its estimate fits this budget.
RIPSER_MAX_POINTS = 4000
RIPSER_MEMORY_BUDGET = DEFAULT_MEMORY_LIMIT
#: ``--quick`` runs DREiMac only up to this many points.
QUICK_DREIMAC_MAX = 4000
#: Seconds after which a baseline child is killed, and a cyclecoord child.
BASELINE_TIMEOUT = 300.0
CC_TIMEOUT = 1800.0
#: Resident-size sampling interval of a running child, seconds.
SAMPLE_INTERVAL = 0.02
#: Frames of the warm-up extract run in each cyclecoord child.
WARMUP_FRAMES = 200

_MB = 1024.0 * 1024.0


# ----------------------------------------------------------------------------- cases
@dataclass(frozen=True)
class Case:
    """One capture to measure (plain data, so it can be handed to a child process).

    Attributes
    ----------
    name : str
        Label printed in the tables.
    kind : {"synthetic", "cmu"}
    n_frames : int
        Frames of the capture.
    path : str or None
        The AMC file of a real capture.
    seed : int
        Seed of a synthetic capture.
    """

    name: str
    kind: str
    n_frames: int
    path: str | None = None
    seed: int = 0


def synthetic(n_frames: int, seed: int = 0) -> Case:
    """The synthetic walk of ``n_frames`` frames (period 120, noise 0.5)."""
    if int(n_frames) < 100:
        raise ParameterError(f"synthetic captures need at least 100 frames, got {n_frames}")
    return Case(f"synthetic {int(n_frames)}", "synthetic", int(n_frames), None, int(seed))


def select_cases(
    sizes: Sequence[int] = SIZES, data_dir: Path | None = bx.DATA_DIR, seed: int = 0
) -> tuple[list[Case], list[str]]:
    """Synthetic cases for ``sizes`` (ascending) and the real captures found, with the
    printed reason for each real capture skipped."""
    cases = [synthetic(n, seed) for n in sorted(set(int(n) for n in sizes))]
    skipped = []
    for name, folder, frames in REAL_CAPTURES:
        if data_dir is None:
            skipped.append(f"{name} skipped: no data folder given")
            continue
        path = Path(data_dir) / "cmu" / folder / f"{name}.amc"
        if path.is_file():
            cases.append(Case(name, "cmu", frames, str(path)))
        else:
            skipped.append(
                f"{name} skipped: CMU capture not found at {path} "
                "(the real captures live in ../shared/data beside the checkout)"
            )
    return cases, skipped


def _cached_capture(case: Case, load: bool = True) -> tuple[cc.Motion, np.ndarray] | None:
    """A long synthetic capture from the NPZ cache, generated by a child process if absent
    (``load=False``: only make sure it is there; the parent must not load it, since a
    child's peak RSS starts from its parent's)."""
    stem = CACHE_DIR / f"synthetic_{case.n_frames}_seed{case.seed}"
    npz, phase = stem.with_suffix(".npz"), stem.with_suffix(".phase.npy")
    if not (npz.is_file() and phase.is_file()):
        CACHE_DIR.mkdir(parents=True, exist_ok=True)
        print(f"generating {case.name} once into {npz} (a separate process) ...", file=sys.stderr, flush=True)
        subprocess.run([sys.executable, str(Path(__file__).resolve()), "--make-capture",
                        str(case.n_frames), str(case.seed), str(stem)], check=True)
    return (cc.load(npz), np.load(phase)) if load else None


def _make_capture(n_frames: int, seed: int, stem: str) -> int:
    cap = cc.datasets.make_periodic_capture(n_frames=n_frames, period=PERIOD, noise=0.5, random_state=seed)
    cc.save(cap.motion, stem + ".npz")
    with atomic_write(stem + ".phase.npy", "wb") as fh:
        np.save(fh, np.asarray(cap.phase, dtype=float))
    return 0


def load_case(case: Case) -> tuple[cc.Motion, np.ndarray | None]:
    """The capture's motion and, for synthetic ones, its true phase (cycles, unwrapped)."""
    if case.kind == "synthetic" and case.n_frames >= CACHE_FROM_FRAMES:
        return _cached_capture(case)
    if case.kind == "synthetic":
        cap = cc.datasets.make_periodic_capture(
            n_frames=case.n_frames, period=PERIOD, noise=0.5, random_state=case.seed
        )
        return cap.motion, np.asarray(cap.phase, dtype=float)
    if case.kind == "cmu":
        return cc.load(case.path), None
    raise ParameterError(f"unknown case kind {case.kind!r}")


def ripser_fits(n_points: int, estimated_bytes: float) -> tuple[bool, str]:
    """The rule for running full ripser: ``N <= 4,000`` and the estimate within 2 GiB.

    ``estimated_bytes`` is ``13 N^2 + 64 E`` (dense distance matrices plus a reduction
    column per edge, E = estimated edges at the threshold).
    """
    if n_points > RIPSER_MAX_POINTS:
        return False, f"{n_points} points > {RIPSER_MAX_POINTS} (rule: N <= {RIPSER_MAX_POINTS})"
    if estimated_bytes > RIPSER_MEMORY_BUDGET:
        return False, (f"estimated {estimated_bytes / 1e9:.2f} GB > "
                       f"{RIPSER_MEMORY_BUDGET / 1e9:.2f} GB budget")
    return True, f"{n_points} points, estimated {estimated_bytes / 1e9:.2f} GB"


# ------------------------------------------------------------- work done in a child
def _rss_now_mb() -> float | None:
    """Current resident set size of this process (MiB), Linux only."""
    return _proc_rss_mb(os.getpid())


def _proc_rss_mb(pid: int) -> float | None:
    try:
        with open(f"/proc/{pid}/status") as fh:
            for line in fh:
                if line.startswith("VmRSS:"):
                    return float(line.split()[1]) / 1024.0
    except OSError:
        return None
    return None


def _extract_once(motion: cc.Motion, require_clear: bool) -> tuple[str, Any]:
    """``("ok", result)`` or ``("no periodic motion", partial result)``."""
    try:
        return "ok", cc.extract(motion, require_clear=require_clear)
    except NoPeriodicMotionError as exc:
        return "no periodic motion", exc


def _landmark_count(est: Any, n_frames: int) -> int:
    lm = getattr(est, "landmarks_", None)
    return int(n_frames if lm is None else len(lm))


def _task_cyclecoord(task: dict, out_dir: Path) -> dict:
    """Timed extract runs (default, then ``require_clear=False`` if that raised)."""
    case = Case(**task["case"])
    repeat = int(task.get("repeat", 1))
    trace = bool(task.get("trace", False))
    warm, _ = load_case(synthetic(WARMUP_FRAMES))
    _extract_once(warm, True)  # imports and first-call costs are not timed
    t0 = time.perf_counter()
    motion, phase = load_case(case)
    load_s = time.perf_counter() - t0
    out: dict[str, Any] = {"load_seconds": load_s, "n_frames": int(motion.n_frames),
                           "rss_before_mb": _rss_now_mb(), "modes": {}}
    modes = [("default", True)]
    k = 0
    while k < len(modes):
        label, clear = modes[k]
        k += 1
        if trace:
            box: dict = {}
            peak = bx.python_peak_mb(lambda: box.update(r=_extract_once(motion, clear)))
            outcome, res = box["r"]
            out["modes"][label] = {"require_clear": clear, "outcome": outcome, "peak_python_mb": peak}
        else:
            runs = []
            for _ in range(repeat):
                start, cpu0 = time.perf_counter(), time.process_time()
                outcome, res = _extract_once(motion, clear)
                timings = dict(res.timings if outcome == "ok" else res.result.timings)
                timings.setdefault("total", sum(v for s, v in timings.items() if s != "total"))
                # the whole call by the clock and in CPU seconds (compare those on a busy machine)
                timings["wall"] = time.perf_counter() - start
                timings["cpu"] = time.process_time() - cpu0
                runs.append({"start": start, "timings": timings, "outcome": outcome})
            out["modes"][label] = _summarise_cc(runs, clear, outcome, res, motion, phase, out_dir, label)
        if outcome != "ok" and clear:
            modes.append(("require_clear=False", False))
    return out


def _summarise_cc(runs: list, clear: bool, outcome: str, res: Any, motion: cc.Motion,
                  phase: np.ndarray | None, out_dir: Path, label: str) -> dict:
    """Median stage seconds of the runs and what the last run found."""
    done = [s for s in STAGES if all(s in r["timings"] for r in runs)]
    mode: dict[str, Any] = {
        "require_clear": clear,
        "outcome": outcome,
        "repeat": len(runs),
        "stages": {s: float(statistics.median(r["timings"][s] for r in runs)) for s in done},
        # the whole call by the clock and in CPU seconds
        **{k: float(statistics.median(r["timings"][k] for r in runs)) for k in ("wall", "cpu")},
        "runs": runs,
    }
    result = res if outcome == "ok" else res.result
    est = result.estimator
    mode["landmarks"] = _landmark_count(est, motion.n_frames)
    mode["landmark_reason"] = getattr(est, "landmark_reason_", None)
    mode["covering_radius"] = float(getattr(est, "covering_radius_", 0.0))
    mode["threshold"] = float(result.barcode.threshold)
    mode["n_h1"] = int(len(result.barcode.h1))
    mode["stopped_after"] = [s for s in STAGES[:-1] if s in mode["stages"]][-1]
    mode["warnings"] = list(result.warnings)
    if outcome == "ok":
        coordinate = result.coordinate
        sel = result.selection
        mode["period_frames"] = float(result.period_frames)
    else:  # the exception may come after the coordinate stage (too few cycles, say)
        mode["message"] = str(res)
        coordinate = getattr(est, "coordinates_", None)
        sel = getattr(est, "selection_", None)
    if sel is not None:
        mode["bar"] = [float(sel.birth), float(sel.death) if math.isfinite(sel.death) else None]
        mode["full_birth"] = getattr(sel, "full_birth", None)
    if coordinate is not None:
        coordinate = np.asarray(coordinate, dtype=float)
        u = bx.unwrap(coordinate)
        mode["cycles"] = float(u[-1] - u[0])
        path = out_dir / f"cc_{label.replace('=', '_')}.npy"
        with atomic_write(path, "wb") as fh:
            np.save(fh, coordinate)
        mode["coordinate_file"] = str(path)
        if phase is not None:
            mode["truth"] = bx.phase_agreement(coordinate, phase)
    return mode


def _task_dreimac(task: dict, out_dir: Path) -> dict:
    """DREiMac circular coordinates on the prepared points, after a small warm-up."""
    ok, info = bx.dreimac_status()
    if not ok:
        return {"status": "skipped", "reason": bx.DREIMAC_MISSING.format(reason=info)}
    rng = np.random.default_rng(0)
    ang = rng.uniform(0.0, 2 * np.pi, 120)
    ring = np.column_stack([np.cos(ang), np.sin(ang)]) + 0.05 * rng.standard_normal((120, 2))
    try:  # numba compilation and imports are not timed
        bx._dreimac_once(ring, 60, True)
    except Exception:  # the warm-up's own result does not matter
        pass
    case = Case(**task["case"])
    motion, phase = load_case(case)
    points = np.asarray(cc.Preprocessor().fit_transform(motion).points, dtype=float)
    n_land = int(min(task["n_landmarks"], len(points)))
    out: dict[str, Any] = {"rss_before_mb": _rss_now_mb(), "n_landmarks": n_land, "notes": []}
    standard_range = True
    try:
        theta, build, coords = bx._dreimac_once(points, n_land, standard_range)
    except Exception as exc:  # DREiMac raises a bare Exception when the class is too short
        if "too short" not in str(exc):
            return {**out, "status": "failed", "reason": f"DREiMac failed: {type(exc).__name__}: {exc}"}
        standard_range = False
        out["notes"].append("class too short for standard_range=True; timed again with standard_range=False")
        theta, build, coords = bx._dreimac_once(points, n_land, standard_range)
    out.update(construct=build, coordinates=coords, total=build + coords, standard_range=standard_range,
               settings={"prime": bx.PRIME, "perc": 0.5, "cocycle_idx": 0, "partunity_fn": "linear"})
    u = bx.unwrap(bx._orient(theta))
    out["cycles"] = float(u[-1] - u[0])
    path = out_dir / "dreimac.npy"
    with atomic_write(path, "wb") as fh:
        np.save(fh, theta)
    out["coordinate_file"] = str(path)
    if phase is not None:
        out["truth"] = bx.phase_agreement(theta, phase)
    return out


def _task_ripser(task: dict, out_dir: Path) -> dict:
    """Full Rips cohomology (dims 0-1, cocycles) on every prepared point."""
    import ripser  # noqa: F401  (imported before the clock starts)

    case = Case(**task["case"])
    motion, _ = load_case(case)
    points = np.asarray(cc.Preprocessor().fit_transform(motion).points, dtype=float)
    threshold = float(task["threshold"])
    out: dict[str, Any] = {"rss_before_mb": _rss_now_mb()}
    t0 = time.perf_counter()
    res = bx._ripser_once(points, threshold)
    out["seconds"] = time.perf_counter() - t0
    h1 = np.asarray(res["dgms"][1]).reshape(-1, 2)
    out.update(threshold=threshold, n_edges=int(res.get("num_edges", 0)), n_h1=int(len(h1)))
    return out


_TASKS: dict[str, Callable[[dict, Path], dict]] = {
    "cyclecoord": _task_cyclecoord,
    "dreimac": _task_dreimac,
    "ripser": _task_ripser,
}


def run_task(task: dict, out_dir: Path) -> dict:
    """Do one measurement in this process; ``status`` is "ok" unless the task says otherwise."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = _TASKS[task["method"]](task, Path(out_dir))
    out.setdefault("status", "ok")
    out["self_maxrss_mb"] = bx.maxrss_mb()
    return out


# ----------------------------------------------------------------- child processes
def _wait_sampling(proc: subprocess.Popen, timeout: float) -> tuple[int | None, float | None, list, bool]:
    """Wait for ``proc``, sampling its resident size; kill its group after ``timeout`` s.

    Returns (exit code or None, peak RSS of the child in MiB from ``wait4`` or None,
    samples ``[(perf_counter, MiB), ...]``, timed_out).
    """
    samples: list[tuple[float, float]] = []
    start = time.perf_counter()
    timed_out = False
    use_wait4 = hasattr(os, "wait4")
    while True:
        if use_wait4:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                proc.returncode = os.waitstatus_to_exitcode(status)
                rss = usage.ru_maxrss / (_MB if sys.platform == "darwin" else 1024.0)
                return proc.returncode, rss, samples, timed_out
        elif proc.poll() is not None:
            return proc.returncode, None, samples, timed_out
        now = time.perf_counter()
        rss_now = _proc_rss_mb(proc.pid)
        if rss_now is not None:
            samples.append((now, rss_now))
        if not timed_out and now - start > timeout:
            timed_out = True
            try:
                os.killpg(proc.pid, signal.SIGKILL)  # the child was started in its own session
            except OSError:
                proc.kill()
        time.sleep(SAMPLE_INTERVAL)


def run_child(task: dict, timeout: float, isolate: bool = True, work_dir: Path | None = None) -> dict:
    """Run one task in a fresh process (``isolate``) or in this one.

    Returns
    -------
    dict
        The task's own output plus ``status`` ("ok", "timed out", "failed" or
        "skipped"), ``wall_seconds``, ``peak_rss_mb`` (the child's high-water RSS; with
        ``isolate=False`` this process's, so far) and ``samples`` (time, MiB).
    """
    own_tmp = None
    if work_dir is None:
        own_tmp = tempfile.TemporaryDirectory(prefix="bench_scaling_")
        work_dir = Path(own_tmp.name)
    work_dir = Path(work_dir)
    t0 = time.perf_counter()
    if not isolate:
        try:
            out = run_task(task, work_dir)
        except Exception as exc:  # reported like a failed child process
            out = {"status": "failed", "reason": f"{type(exc).__name__}: {exc}", "self_maxrss_mb": bx.maxrss_mb()}
        out.update(wall_seconds=time.perf_counter() - t0, peak_rss_mb=out["self_maxrss_mb"], samples=[])
        return out
    tag = f"{task['method']}_{os.getpid()}_{time.perf_counter_ns()}"
    task_file, result_file, log_file = (work_dir / f"{tag}.{ext}" for ext in ("task.json", "out.json", "log"))
    with atomic_write(task_file, "w") as fh:
        json.dump({**task, "out_dir": str(work_dir), "result_file": str(result_file)}, fh)
    with open(log_file, "w") as log:
        proc = subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "--one", str(task_file)],
                                stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
        code, rss, samples, timed_out = _wait_sampling(proc, timeout)
    wall = time.perf_counter() - t0
    if timed_out:
        out = {"status": "timed out", "reason": f"killed after {timeout:.0f} s"}
    elif code != 0 or not result_file.is_file():
        tail = log_file.read_text(errors="replace").strip().splitlines()[-5:]
        out = {"status": "failed", "reason": f"exit code {code}: " + " | ".join(tail)}
    else:
        out = json.loads(result_file.read_text())
    out.update(wall_seconds=wall, peak_rss_mb=rss if rss is not None else out.get("self_maxrss_mb"),
               samples=samples)
    return out


def stage_peaks(runs: Sequence[dict], samples: Sequence[tuple[float, float]]) -> dict:
    """Peak sampled RSS (MiB) inside each stage's time window, over all runs.

    A run started at ``start`` spends ``timings[s]`` seconds in each stage in order, so
    stage ``s`` covers ``[start + sum(previous), start + sum(previous) + timings[s]]``
    (the short glue code between stages is ignored).  Stages without a sample inside
    (shorter than the sampling interval) get ``None``.
    """
    if not samples:
        return {}
    t = np.array([s[0] for s in samples])
    m = np.array([s[1] for s in samples])
    peaks: dict[str, float | None] = {}
    for r in runs:
        clock = float(r["start"])
        for s in STAGES[:-1]:
            if s not in r["timings"]:
                continue
            end = clock + float(r["timings"][s])
            inside = (t >= clock) & (t <= end)
            if inside.any():
                peaks[s] = max(float(m[inside].max()), peaks.get(s) or 0.0)
            else:
                peaks.setdefault(s, None)
            clock = end
    return peaks


# ------------------------------------------------------------------------- driver
def run_case(
    case: Case,
    repeat: int = 1,
    with_dreimac: bool = True,
    with_ripser: bool = True,
    trace: bool = True,
    dreimac_max: int | None = None,
    timeout: float = BASELINE_TIMEOUT,
    cc_timeout: float = CC_TIMEOUT,
    isolate: bool = True,
    tick: Callable[[str], None] = lambda label: None,
) -> dict:
    """Measure one case: cyclecoord, its tracemalloc peak, DREiMac and full ripser.

    Parameters
    ----------
    repeat : int
        Timed extract runs per mode (median reported).
    dreimac_max : int, optional
        Run DREiMac only up to this many frames (``--quick``: 4,000).
    isolate : bool
        Each measurement in a fresh process (default); ``False`` runs everything in
        this process (a quick smoke test: peak memory is then this process's so far).
    tick : callable
        Called with a label as each measurement starts (progress display).

    Returns
    -------
    dict
        ``case``, ``cyclecoord`` (``modes`` -> per mode: ``outcome``, ``stages``
        seconds, ``stage_rss_mb``, ``landmarks``, ``threshold``, ...; ``peak_rss_mb``),
        ``dreimac``, ``ripser`` (each with ``status``) and ``agreement``.
    """
    if repeat < 1:
        raise ParameterError(f"repeat must be at least 1, got {repeat}")
    with tempfile.TemporaryDirectory(prefix="bench_scaling_") as tmp:
        work = Path(tmp)
        out: dict[str, Any] = {"case": asdict(case)}
        tick(f"{case.name}: cyclecoord")
        ccr = run_child({"method": "cyclecoord", "case": asdict(case), "repeat": repeat}, cc_timeout, isolate, work)
        samples = ccr.pop("samples", [])
        for mode in ccr.get("modes", {}).values():
            mode["stage_rss_mb"] = stage_peaks(mode.get("runs", []), samples)
        out["cyclecoord"] = ccr
        if trace:
            tick(f"{case.name}: tracemalloc")
            tr = run_child({"method": "cyclecoord", "case": asdict(case), "trace": True}, cc_timeout, isolate, work)
            for label, mode in tr.get("modes", {}).items():
                if label in ccr.get("modes", {}):
                    ccr["modes"][label]["peak_python_mb"] = mode.get("peak_python_mb")
            if tr["status"] != "ok":
                ccr["trace_status"] = f"{tr['status']}: {tr.get('reason', '')}"
        ref = furthest_mode(out)
        coord_cc = np.load(ref["coordinate_file"]) if ref and "coordinate_file" in ref else None

        # DREiMac at cyclecoord's landmark count
        if not with_dreimac:
            out["dreimac"] = {"status": "skipped", "reason": "not requested (--no-dreimac)"}
        elif ref is None:
            out["dreimac"] = {"status": "skipped", "reason": "cyclecoord did not run, so no landmark count"}
        elif dreimac_max is not None and case.n_frames > dreimac_max:
            out["dreimac"] = {"status": "skipped", "reason": f"--quick: no DREiMac above {dreimac_max} frames"}
        elif case.n_frames > DREIMAC_MAX_FRAMES:
            out["dreimac"] = {"status": "skipped", "reason": f"no DREiMac above {DREIMAC_MAX_FRAMES} frames"}
        else:
            tick(f"{case.name}: DREiMac")
            dm = run_child({"method": "dreimac", "case": asdict(case), "n_landmarks": ref["landmarks"]},
                           timeout, isolate, work)
            dm.pop("samples", None)
            out["dreimac"] = dm

        # full ripser where it fits
        if not with_ripser:
            out["ripser"] = {"status": "skipped", "reason": "not requested (--no-ripser)"}
        elif ref is None:
            out["ripser"] = {"status": "skipped", "reason": "cyclecoord did not run, so no threshold"}
        elif case.n_frames > RIPSER_MAX_POINTS:  # decided without loading it into this process
            out["ripser"] = {"status": "skipped", "reason": f"{case.n_frames} points > {RIPSER_MAX_POINTS} "
                             f"(rule: N <= {RIPSER_MAX_POINTS})"}
        else:
            motion, _ = load_case(case)
            points = cc.Preprocessor().fit_transform(motion).points
            est = estimate_complex(points, ref["threshold"])
            fits, why = ripser_fits(len(points), est.bytes)
            if fits:
                tick(f"{case.name}: full ripser")
                rp = run_child({"method": "ripser", "case": asdict(case), "threshold": ref["threshold"]},
                               timeout, isolate, work)
                rp.pop("samples", None)
            else:
                rp = {"status": "skipped", "reason": why}
            rp["estimated_bytes"] = float(est.bytes)
            rp["rule"] = why
            out["ripser"] = rp

        # agreement
        agreement: dict[str, Any] = {}
        dm = out["dreimac"]
        if coord_cc is not None and dm.get("status") == "ok":
            agreement["cyclecoord_vs_dreimac"] = bx.circular_agreement(coord_cc, np.load(dm["coordinate_file"]))
        if case.kind == "synthetic":
            agreement["cycles_true"] = (case.n_frames - 1) / PERIOD
            if ref and "truth" in ref:
                agreement["cyclecoord_truth"] = ref["truth"]
            if "truth" in dm:
                agreement["dreimac_truth"] = dm["truth"]
        out["agreement"] = agreement
    if hasattr(os, "getloadavg"):
        out["load_average_1min"] = round(os.getloadavg()[0], 2)
    return out


def full_mode(case_report: dict) -> dict | None:
    """The cyclecoord mode that ran the whole pipeline (default, else ``require_clear=False``)."""
    modes = case_report.get("cyclecoord", {}).get("modes", {})
    for label in ("default", "require_clear=False"):
        if modes.get(label, {}).get("outcome") == "ok":
            return modes[label]
    return None


def furthest_mode(case_report: dict) -> dict | None:
    """The mode that ran the whole pipeline, else the one that got furthest (the last run)."""
    full = full_mode(case_report)
    if full is not None:
        return full
    modes = list(case_report.get("cyclecoord", {}).get("modes", {}).values())
    return modes[-1] if modes else None


def planned_steps(cases: Sequence[Case], with_dreimac: bool, with_ripser: bool, trace: bool,
                  dreimac_max: int | None) -> int:
    """Child processes the run will start at most (for the progress bar)."""
    n = 0
    for c in cases:
        n += 1 + int(trace) + int(with_ripser and c.n_frames <= RIPSER_MAX_POINTS)
        n += int(with_dreimac and (dreimac_max is None or c.n_frames <= dreimac_max))
    return n


def run_benchmark(
    cases: Sequence[Case],
    repeat: int = 1,
    with_dreimac: bool = True,
    with_ripser: bool = True,
    trace: bool = True,
    dreimac_max: int | None = None,
    timeout: float = BASELINE_TIMEOUT,
    cc_timeout: float = CC_TIMEOUT,
    isolate: bool = True,
    progress: bool = True,
    skipped: Sequence[str] = (),
) -> dict:
    """Run every case in turn; returns ``{"machine", "settings", "skipped", "cases",
    "growth", "targets"}``."""
    skipped = list(skipped)
    if with_dreimac:
        ok, info = bx.dreimac_status()
        if not ok:
            skipped.append(bx.DREIMAC_MISSING.format(reason=info))
            with_dreimac = False
    machine = bx.machine_info()
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=planned_steps(cases, with_dreimac, with_ripser, trace, dreimac_max),
                   desc="bench_scaling", unit="run", file=sys.stderr)
    pending = [False]

    def tick(label: str) -> None:
        """A measurement starts: count the previous one as done, show this one's name."""
        if bar is not None:
            if pending[0]:
                bar.update(1)
            bar.set_postfix_str(label)
            pending[0] = True

    results = []
    try:
        for case in cases:
            results.append(run_case(case, repeat, with_dreimac, with_ripser, trace, dreimac_max,
                                    timeout, cc_timeout, isolate, tick))
    finally:
        if bar is not None:
            if pending[0]:
                bar.update(1)
            bar.total = bar.n  # baselines skipped by their rules were counted in advance
            bar.refresh()
            bar.close()
    report = {
        "machine": machine,
        "settings": {"repeat": repeat, "isolated": isolate, "baseline_timeout": timeout,
                     "sample_interval": SAMPLE_INTERVAL, "ripser_rule":
                     f"N <= {RIPSER_MAX_POINTS} and 13 N^2 + 64 E <= {RIPSER_MEMORY_BUDGET / 1e9:.2f} GB",
                     "dreimac_max_frames": dreimac_max},
        "skipped": skipped,
        "cases": results,
    }
    report["growth"] = growth_table(results)
    report["targets"] = evaluate_targets(results)
    return report


# ------------------------------------------------------------------ derived figures
def growth_exponent(n1: float, t1: float, n2: float, t2: float) -> float | None:
    """``log(t2/t1) / log(n2/n1)``: 1 for linear growth, 2 for quadratic."""
    if min(n1, n2, t1, t2) <= 0 or n1 == n2:
        return None
    return math.log(t2 / t1) / math.log(n2 / n1)


def growth_table(cases: Sequence[dict]) -> list[dict]:
    """Growth exponents of the total and of each stage between successive synthetic sizes."""
    syn = []
    for c in cases:
        m = full_mode(c)
        if c["case"]["kind"] == "synthetic" and m is not None:
            syn.append((c["case"]["n_frames"], m["stages"]))
    syn.sort(key=lambda x: x[0])
    rows = []
    for (n1, s1), (n2, s2) in zip(syn, syn[1:]):
        rows.append({"from": n1, "to": n2,
                     "exponents": {s: growth_exponent(n1, s1.get(s, 0.0), n2, s2.get(s, 0.0)) for s in STAGES}})
    return rows


def evaluate_targets(cases: Sequence[dict]) -> list[dict]:
    """The issue's three targets: ``passed`` is True/False, or None when not measured."""
    by_name = {c["case"]["name"]: c for c in cases}
    out = []
    c = by_name.get("01_09")
    m = furthest_mode(c) if c else None
    if m:
        label = "default" if m["require_clear"] else "require_clear=False"
        how = ("whole pipeline" if m["outcome"] == "ok" else
               f"ended with NoPeriodicMotionError after the {m['stopped_after']} stage")
        note = (f"extract(..., {label}), the longest call timed: {how}; "
                f"loading the AMC takes {c['cyclecoord'].get('load_seconds', float('nan')):.2f} s more")
    else:
        note = "01_09 not measured"
    out.append({
        "target": f"01_09 extract end to end < {TARGET_01_09_SECONDS:g} s",
        "value": m["stages"]["total"] if m else None, "limit": TARGET_01_09_SECONDS, "unit": "s",
        "passed": (m["stages"]["total"] < TARGET_01_09_SECONDS) if m else None,
        "note": note,
    })
    c = by_name.get(f"synthetic {TARGET_64K_FRAMES}")
    m = full_mode(c) if c else None
    out.append({
        "target": f"{TARGET_64K_FRAMES // 1000}k frames < {TARGET_64K_SECONDS:g} s",
        "value": m["stages"]["total"] if m else None, "limit": TARGET_64K_SECONDS, "unit": "s",
        "passed": (m["stages"]["total"] < TARGET_64K_SECONDS) if m else None,
        "note": "" if m else f"synthetic {TARGET_64K_FRAMES} not measured",
    })
    rss = c["cyclecoord"].get("peak_rss_mb") if c else None
    ok = c is not None and c["cyclecoord"].get("status") == "ok" and rss is not None
    out.extend(_million_targets(by_name.get(f"synthetic {MILLION}"), m))
    out.append({
        "target": f"{TARGET_64K_FRAMES // 1000}k frames peak memory < {TARGET_64K_BYTES / 1e9:g} GB",
        "value": rss * _MB / 1e9 if ok else None, "limit": TARGET_64K_BYTES / 1e9, "unit": "GB",
        "passed": (rss * _MB < TARGET_64K_BYTES) if ok else None,
        "note": "peak RSS of the whole child process (interpreter and imports included)" if ok else
                f"synthetic {TARGET_64K_FRAMES} not measured",
    })
    return out


def _million_targets(c: dict | None, m64: dict | None) -> list[dict]:
    """``--million``: time, peak memory and landmark count at 1,000,000 frames."""
    m = full_mode(c) if c else None
    rss = c["cyclecoord"].get("peak_rss_mb") if c else None
    if m is None:
        return []
    same = m64 is not None and m["landmarks"] == m64["landmarks"]
    return [
        {"target": f"1M frames < {TARGET_1M_SECONDS:g} s", "value": m["stages"]["total"],
         "limit": TARGET_1M_SECONDS, "unit": "s", "passed": m["stages"]["total"] < TARGET_1M_SECONDS,
         "note": f"CPU {m.get('cpu', float('nan')):.1f} s, wall {m.get('wall', float('nan')):.1f} s"},
        {"target": f"1M frames peak memory < {TARGET_1M_BYTES / 1e9:g} GB",
         "value": None if rss is None else rss * _MB / 1e9, "limit": TARGET_1M_BYTES / 1e9, "unit": "GB",
         "passed": None if rss is None else rss * _MB < TARGET_1M_BYTES,
         "note": "peak RSS of the child (interpreter, imports, the capture and extract)"},
        {"target": "1M frames: the landmark count of 64k", "value": float(m["landmarks"]), "limit": None,
         "unit": "landmarks", "passed": same if m64 is not None else None,
         "note": f"64k: {m64['landmarks'] if m64 else 'not measured'}; {m.get('landmark_reason')}"},
    ]


# -------------------------------------------------------------------------- printing
_f = bx._f


def _status_or(d: dict, fmt: Callable[[dict], str]) -> str:
    return fmt(d) if d.get("status") == "ok" else d.get("status", "-")


def format_report(report: dict) -> str:
    """Human-readable tables of a :func:`run_benchmark` report."""
    m = report["machine"]
    st = report["settings"]
    lines = [
        f"cyclecoord {m['cyclecoord']} (git {m.get('git') or 'unknown'}) scaling benchmark  {m['date']}",
        f"{m['platform']}  {m['processor']}  cpus={m['cpus']}  python {m['python']}  numpy {m['numpy']}  "
        f"scipy {m['scipy']}  ripser {m['ripser']}  dreimac {m['dreimac'] or 'not installed'}",
        f"each measurement in a fresh process: {st['isolated']}; timed extract runs per mode: {st['repeat']} "
        f"(median); baseline timeout {st['baseline_timeout']:.0f} s; load average before {m.get('load_average')}",
        "",
    ]
    for s in report["skipped"]:
        lines.append(f"NOTE: {s}")
    if report["skipped"]:
        lines.append("")
    cases = report["cases"]

    lines.append("cyclecoord.extract: seconds per stage, peak memory (MiB)")
    rows = []
    for c in cases:
        ccr = c["cyclecoord"]
        if ccr.get("status") != "ok":
            rows.append([c["case"]["name"], str(c["case"]["n_frames"]), "-", ccr.get("status", "?")]
                        + ["-"] * (len(STAGES) + 5))
            continue
        for label, mode in ccr["modes"].items():
            outcome = "ok" if mode["outcome"] == "ok" else "no clear class"
            rows.append([
                c["case"]["name"], str(ccr["n_frames"]), str(mode["landmarks"]), f"{label}: {outcome}",
                *[_f(mode["stages"].get(s)) for s in STAGES], _f(mode.get("wall")), _f(mode.get("cpu")),
                _f(ccr.get("peak_rss_mb"), "{:.0f}"), _f(ccr.get("rss_before_mb"), "{:.0f}"),
                _f(mode.get("peak_python_mb"), "{:.0f}"),
            ])
    lines.append(bx._table(["case", "N", "lmk", "mode", *STAGES, "wall", "CPU", "peak RSS", "RSS before", "py peak"],
                           rows))
    lines.append("  wall / CPU = the whole extract call by the clock / in this process's CPU seconds (on a busy "
                 "machine compare CPU; the load average is in the header and per case below)")
    lines.append("  lmk = points the filtration was built on (greedy landmarks; the coordinate is extended to every "
                 "frame).  peak RSS = the child's high-water mark (interpreter, imports, 200-frame warm-up and all "
                 "timed runs); RSS before = resident size just before the timed runs; py peak = tracemalloc peak "
                 "in a separate run (Python/NumPy only).  A stage left '-' was not reached.")
    lines.append("")

    lines.append(f"peak resident size per stage (MiB, sampled every {st['sample_interval'] * 1000:.0f} ms; "
                 "'-' = stage shorter than one sample)")
    rows = []
    for c in cases:
        for label, mode in c["cyclecoord"].get("modes", {}).items():
            sr = mode.get("stage_rss_mb", {})
            rows.append([c["case"]["name"], label, *[_f(sr.get(s), "{:.0f}") for s in STAGES[:-1]]])
    lines.append(bx._table(["case", "mode", *STAGES[:-1]], rows))
    lines.append("")

    lines.append("baselines on the same prepared points (seconds, peak RSS MiB) and ratios (cyclecoord / baseline; "
                 "< 1 = cyclecoord faster)")
    rows = []
    for c in cases:
        fm = furthest_mode(c)
        tot = fm["stages"]["total"] if fm else None
        # the part DREiMac does too: barcode + circular coordinate
        coord = (fm["stages"].get("barcode") or 0) + (fm["stages"].get("coordinate") or 0) if fm else None
        d, r = c["dreimac"], c["ripser"]
        dm_s = d.get("total") if d.get("status") == "ok" else None
        rp_s = r.get("seconds") if r.get("status") == "ok" else None
        rows.append([
            c["case"]["name"], str(c["case"]["n_frames"]), str(fm["landmarks"]) if fm else "-",
            _f(tot) + ("" if fm is None or fm["outcome"] == "ok" else "*"), _f(coord),
            _status_or(d, lambda x: f"{x['total']:.3f}"), _status_or(d, lambda x: f"{x['peak_rss_mb']:.0f}"),
            _status_or(r, lambda x: f"{x['seconds']:.3f}"), _status_or(r, lambda x: f"{x['peak_rss_mb']:.0f}"),
            _f(tot / dm_s if tot and dm_s else None, "{:.2f}"),
            _f(coord / dm_s if coord and dm_s else None, "{:.2f}"), _f(tot / rp_s if tot and rp_s else None, "{:.2f}"),
        ])
    lines.append(bx._table(["case", "N", "lmk", "cc total", "cc coord", "DREiMac s", "DM RSS", "full ripser s",
                            "ripser RSS", "cc/DM", "coord/DM", "cc/ripser"], rows))
    lines.append("  cc coord = cyclecoord's barcode + coordinate stages, the part DREiMac does (cc total adds density, "
                 "typical cycle and metrics; the coordinate stage includes the full-resolution birth refinement, which DREiMac does not do).")
    lines.append(f"  DREiMac: CircularCoords(points, n_landmarks=lmk, prime={bx.PRIME}) + get_coordinates() "
                 "(defaults: perc=0.5, most persistent class, linear partition of unity).")
    lines.append("  * the longest extract call ended early (NoPeriodicMotionError); its time up to that point.")
    lines.append(f"  full ripser: ripser(points, maxdim=1, thresh=<cyclecoord's threshold>, coeff={bx.PRIME}, "
                 f"do_cocycles=True) on all N points; rule: {st['ripser_rule']}.")
    for c in cases:
        for key, name in (("dreimac", "DREiMac"), ("ripser", "full ripser")):
            d = c[key]
            if d.get("status") != "ok" and d.get("reason"):
                lines.append(f"  {c['case']['name']}: {name} {d['status']}: {d['reason']}")
            for note in d.get("notes", []):
                lines.append(f"  {c['case']['name']}: DREiMac {note}")
    lines.append("")

    if report["growth"]:
        lines.append("growth exponent log(t2/t1)/log(N2/N1) between successive synthetic sizes (1 = linear)")
        rows = [[f"{g['from']} -> {g['to']}", *[_f(g["exponents"][s], "{:.2f}") for s in STAGES]]
                for g in report["growth"]]
        lines.append(bx._table(["sizes", *STAGES], rows))
        lines.append("")

    lines.append("agreement (printed, not asserted)")
    rows = []
    for c in cases:
        a = c["agreement"]
        vs = a.get("cyclecoord_vs_dreimac", {})
        fm = furthest_mode(c)
        rows.append([
            c["case"]["name"], _f(vs.get("median_difference")), _f(vs.get("correlation")),
            ("yes" if vs["reflected"] else "no") if vs else "-",
            _f(fm.get("cycles") if fm else None, "{:.2f}"),
            _f(c["dreimac"].get("cycles"), "{:.2f}"), _f(a.get("cycles_true"), "{:.2f}"),
            _f(a.get("cyclecoord_truth", {}).get("mean_abs_error")),
        ])
    lines.append(bx._table(["case", "cc~DM median diff", "cc~DM corr", "reflected", "cc cycles", "DM cycles",
                            "true cycles", "cc err"], rows))
    lines.append("  median diff: circular distance (cycles) after the best rotation/reflection; corr: mean resultant "
                 "length of the difference (1 = same up to rotation); true cycles = (N - 1)/120; cc err = mean "
                 "circular error against the true phase after best rotation/reflection (cycles).")
    lines.append("")

    lines.append("targets")
    for t in report["targets"]:
        verdict = {True: "PASS", False: "FAIL", None: "NOT RUN"}[t["passed"]]
        val = "-" if t["value"] is None else f"{t['value']:.3f} {t['unit']}"
        lines.append(f"  {verdict}: {t['target']}: {val}" + (f"  ({t['note']})" if t["note"] else ""))
    return "\n".join(lines)


def _strip(report: dict) -> dict:
    """The report as plain JSON types."""
    return bx._jsonable(report)


def _parse_sizes(text: str) -> list[int]:
    try:
        sizes = [int(v) for v in text.replace(" ", "").split(",") if v]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--sizes takes comma-separated frame counts, got {text!r}") from None
    if not sizes or min(sizes) < 100:
        raise argparse.ArgumentTypeError(f"--sizes needs frame counts of at least 100, got {text!r}")
    return sizes


def _child_main(task_file: str) -> int:
    task = json.loads(Path(task_file).read_text())
    out = run_task(task, Path(task["out_dir"]))
    with atomic_write(task["result_file"], "w") as fh:
        json.dump(bx._jsonable(out), fh)
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns the exit status (1 when a cyclecoord run failed)."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true",
                    help=f"sizes {','.join(map(str, QUICK_SIZES))} only and no DREiMac above {QUICK_DREIMAC_MAX} frames")
    ap.add_argument("--sizes", type=_parse_sizes, default=None,
                    help=f"synthetic capture lengths, comma-separated (default {','.join(map(str, SIZES))})")
    ap.add_argument("--json", metavar="OUT", help="also write the full report as JSON")
    ap.add_argument("--repeat", type=int, default=1, help="timed extract runs per case and mode (median; default 1)")
    ap.add_argument("--timeout", type=float, default=BASELINE_TIMEOUT,
                    help=f"seconds before a DREiMac or full-ripser run is killed (default {BASELINE_TIMEOUT:.0f})")
    ap.add_argument("--no-dreimac", action="store_true", help="skip the DREiMac baseline")
    ap.add_argument("--no-ripser", action="store_true", help="skip the full-ripser baseline")
    ap.add_argument("--no-trace", action="store_true", help="skip the tracemalloc run")
    ap.add_argument("--in-process", action="store_true",
                    help="run everything in this process (no per-case peak memory; for debugging)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the synthetic captures")
    ap.add_argument("--data", type=Path, default=bx.DATA_DIR, help=f"shared data folder (default {bx.DATA_DIR})")
    ap.add_argument("--no-progress", action="store_true", help="no progress bar")
    ap.add_argument("--million", action="store_true",
                    help=f"also run {MILLION:,} frames (opt-in: generating it takes minutes, once, cached in "
                         f"{CACHE_DIR}; extract itself about a minute)")
    ap.add_argument("--one", metavar="TASK", help=argparse.SUPPRESS)  # child process entry
    ap.add_argument("--make-capture", nargs=3, help=argparse.SUPPRESS)  # cache a long capture
    args = ap.parse_args(argv)
    if args.one:
        return _child_main(args.one)
    if args.make_capture:
        n, seed, stem = args.make_capture
        return _make_capture(int(n), int(seed), stem)
    if args.repeat < 1:
        ap.error("--repeat must be at least 1")
    if args.timeout <= 0:
        ap.error("--timeout must be positive")
    if args.json:
        out = Path(args.json)
        if not (out.parent if str(out.parent) else Path(".")).is_dir():
            ap.error(f"--json: folder {out.parent} does not exist")
    sizes = args.sizes or list(QUICK_SIZES if args.quick else SIZES)
    if args.million and MILLION not in sizes:
        sizes = [*sizes, MILLION]
    cases, skipped = select_cases(sizes, args.data, args.seed)
    for c in cases:  # generate long captures before any measuring child starts (their memory)
        if c.kind == "synthetic" and c.n_frames >= CACHE_FROM_FRAMES:
            _cached_capture(c, load=False)
    for s in skipped:
        print(s, flush=True)
    if not args.no_dreimac:
        ok, info = bx.dreimac_status()
        if not ok:
            print(bx.DREIMAC_MISSING.format(reason=info), flush=True)
    report = run_benchmark(
        cases, repeat=args.repeat, with_dreimac=not args.no_dreimac, with_ripser=not args.no_ripser,
        trace=not args.no_trace, dreimac_max=QUICK_DREIMAC_MAX if args.quick else None,
        timeout=args.timeout, isolate=not args.in_process, progress=not args.no_progress, skipped=skipped,
    )
    print(format_report(report), flush=True)
    if args.json:
        with atomic_write(args.json, "w") as fh:
            json.dump(_strip(report), fh, indent=2)
            fh.write("\n")
        print(f"report written to {args.json}")
    return 1 if any(c["cyclecoord"].get("status") != "ok" for c in report["cases"]) else 0


if __name__ == "__main__":
    sys.exit(main())
