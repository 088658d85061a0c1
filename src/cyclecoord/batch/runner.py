"""The batch run: :func:`~cyclecoord.periodic.pipeline.extract` over every capture in a folder.

:func:`run_batch` finds the captures under a folder (recursively, in sorted order), runs
load + extract on each -- in this process, in a local process pool or on a Dask
distributed cluster -- and writes, mirroring the input tree under the output folder:

* ``<relative path without suffix>.report.json`` per capture: the extraction report
  (:meth:`~cyclecoord.periodic.pipeline.ExtractionResult.to_report`) plus a ``"batch"`` block
  (status, message, input size and modification time, options and their hash, seconds);
* ``<relative path without suffix>.cycle.bvh`` (or ``.npz``, ``.csv``, ``.glb``, ``.gltf``
  with a ``.bin``, ``.usda``, ``.usdc``): the typical cycle;
* ``summary.csv``: one row per capture with the key figures (see :data:`SUMMARY_COLUMNS`).

When two captures in one folder share a stem (``walk.bvh`` and ``walk.npz``) their
outputs keep the suffix (``walk.bvh.report.json``, ``walk.npz.report.json``).

Every capture ends with one of three statuses: ``ok``, ``no_periodic`` (the barcode shows
no clear circle; the report holds the barcode) or ``error`` (unreadable file, bad option,
out of memory, a crashed worker, ...; the report holds the message).  A failure never
stops the batch.  A re-run skips every capture whose report says ``ok`` or
``no_periodic`` for the same input size, modification time and options (and, for an
``.amc``, the same size and modification time of the ``.asf`` it is read with); errors
are retried.  ``summary.csv`` is rebuilt from the reports of all captures every time, so it
is complete after a resumed run.

Outputs are never written inside the input folder: the output folder may not be the
input folder or lie inside it (captures written there would be picked up by the next
scan), and an input folder inside the output folder is allowed only when no output
falls inside it.  Every file is written atomically (temporary file, then rename).

The folder scan lives in :mod:`cyclecoord.batch.discovery` and the summary (its type, rows
and ``summary.csv``) in :mod:`cyclecoord.batch.summary`; :mod:`cyclecoord.batch`
re-exports all three.
"""

from __future__ import annotations

import hashlib
import inspect
import json
import math
import multiprocessing
import os
import time
import traceback
from collections import Counter, deque
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, Sequence

from .discovery import DEFAULT_PATTERNS, as_patterns, find_captures
from .summary import (
    STATUSES,
    SUMMARY_COLUMNS,
    SUMMARY_NAME,
    BatchSummary,
    summary_row,
    write_summary,
)
from ..errors import CycleCoordError, NoPeriodicMotionError, ParameterError, ParseError
from ..io import refuse_clobber
from ..periodic.report import clean, partial_report, write_json

__all__ = [
    "run_batch",
    "BatchSummary",
    "find_captures",
    "DEFAULT_PATTERNS",
    "SUMMARY_COLUMNS",
    "STATUSES",
]

REPORT_SUFFIX = ".report.json"
#: Formats a cycle can be written in (the suffix, as for ``extract -o``).  The ones in
#: :data:`SKELETON_FORMATS` need a skeleton: a capture without one gets ``.npz``.
CYCLE_FORMATS = ("bvh", "npz", "csv", "glb", "gltf", "usda", "usdc")
SKELETON_FORMATS = ("bvh", "glb", "gltf", "usda", "usdc")
#: Seconds to wait for a Dask scheduler given by address.
CONNECT_TIMEOUT = 10.0
_CRASHED = (
    "the worker process died while analysing this file (killed by the operating system, "
    "e.g. out of memory, or crashed)"
)


# ------------------------------------------------------------------ records
@dataclass(frozen=True)
class _Task:
    """One capture to analyse: where it is, where its outputs go, how to analyse it."""

    file: str  # path relative to the input folder, POSIX separators
    input: str  # absolute input path
    base: str  # absolute output path without the ".report.json" / ".cycle.xxx" ending
    out_dir: str
    size: int
    mtime_ns: int
    options: dict
    fps: float | None
    cycle_format: str | None
    options_hash: str
    skeleton: list | None = None  # [path, size, mtime_ns] of the .asf an .amc is read with

    @property
    def report(self) -> Path:
        return Path(self.base + REPORT_SUFFIX)


# ------------------------------------------------------------------ options
def _check_options(options: dict) -> dict:
    """Fail early on options :func:`extract` does not take; return them normalised.

    The normalised form (every parameter with its default filled in) feeds the options
    hash, so ``{}`` and ``{"random_state": 0}`` count as the same run.
    """
    from ..periodic.pipeline import extract

    if not isinstance(options, dict):
        raise ParameterError(f"extract_options must be a dict, got {type(options).__name__}")
    sig = inspect.signature(extract)
    params = list(sig.parameters)
    if "motion" in options:
        raise ParameterError("extract_options may not hold 'motion': the batch loads each capture")
    try:
        bound = sig.bind(None, **options)
    except TypeError:
        allowed = ", ".join(
            p for p in params[1:] if sig.parameters[p].kind is not inspect.Parameter.VAR_KEYWORD
        )
        unknown = sorted(k for k in options if k not in sig.parameters)
        raise ParameterError(f"unknown extract option(s) {unknown}; allowed: {allowed}") from None
    bound.apply_defaults()
    full = dict(bound.arguments)
    full.pop(params[0], None)
    for name, p in sig.parameters.items():  # flatten **kwargs, if extract ever takes them
        if p.kind is inspect.Parameter.VAR_KEYWORD:
            full.update(full.pop(name, {}))
    return json.loads(json.dumps(full, sort_keys=True, default=repr))


def _options_hash(normalised: dict, fps: float | None, cycle_format: str | None) -> str:
    blob = json.dumps(
        {"extract": normalised, "fps": fps, "cycles": cycle_format}, sort_keys=True, default=repr
    )
    return hashlib.sha256(blob.encode("utf-8")).hexdigest()[:16]


# ------------------------------------------------------------------ reports
def _batch_block(task: _Task, status: str, message: str, **extra: Any) -> dict[str, Any]:
    from .. import __version__

    return {
        "file": task.file,
        "input": task.input,
        "input_size": task.size,
        "input_mtime_ns": task.mtime_ns,
        "options": task.options,
        "fps": task.fps,
        "options_hash": task.options_hash,
        "skeleton": task.skeleton,
        "status": status,
        "message": message,
        "cycle_file": None,
        "version": __version__,
        **extra,
    }


def _failure_report(task: _Task, exc: BaseException | str) -> dict[str, Any]:
    if isinstance(exc, str):
        message, kind, tb = exc, "WorkerDied", None
    else:
        kind = type(exc).__name__
        if isinstance(exc, CycleCoordError):
            message, tb = str(exc), None
        else:  # not one of ours: keep the traceback for a bug report
            message = f"{kind}: {exc}" if str(exc) else kind
            tb = "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))
    return {"batch": _batch_block(task, "error", message, error_type=kind, traceback=tb)}


def _cycle_path(task: _Task, fmt: str) -> Path:
    return Path(f"{task.base}.cycle.{fmt}")


def _analyse(task: _Task) -> dict[str, Any]:
    """Load + extract one capture, write its cycle; return its report (not yet written)."""
    from ..io import load, save
    from ..periodic.pipeline import extract

    motion = load(task.input, fps=task.fps)
    try:
        result = extract(motion, **task.options)
    except NoPeriodicMotionError as exc:
        report = partial_report(exc)
        report["batch"] = _batch_block(task, "no_periodic", str(exc))
        written = None
    else:
        report = result.to_report()
        notes = list(result.warnings)
        written = None
        if task.cycle_format is not None:
            fmt = task.cycle_format
            if fmt in SKELETON_FORMATS and result.cycle.skeleton is None:
                notes.append(
                    "the capture has no skeleton, so its cycle was written as .npz instead of "
                    f".{fmt}"
                )
                fmt = "npz"
                report["warnings"] = notes
            written = _cycle_path(task, fmt)
            save(result.cycle, written)
        report["batch"] = _batch_block(task, "ok", "; ".join(notes))
        if written is not None:
            report["batch"]["cycle_file"] = written.relative_to(task.out_dir).as_posix()
    for fmt in CYCLE_FORMATS:  # a cycle left from an earlier run would now be stale
        stale = _cycle_path(task, fmt)
        if stale != written and stale.exists():
            stale.unlink()
            if fmt == "gltf":  # and the buffer written beside a .gltf
                stale.with_suffix(".bin").unlink(missing_ok=True)
    return report


def _write_report(task: _Task, report: dict) -> dict[str, Any]:
    """Write ``report`` atomically; return its summary row."""
    report = clean(report)
    task.report.parent.mkdir(parents=True, exist_ok=True)
    write_json(str(task.report), report)
    return summary_row(report)


def _process_one(task: _Task) -> dict[str, Any]:
    """Worker: analyse one capture, write its report and cycle, return its summary row.

    Never raises for a problem with the capture (parse errors, bad options, running out
    of memory, bugs): those become an ``error`` report.  Only the small row travels back.
    """
    t0 = time.perf_counter()
    try:
        report = _analyse(task)
    except Exception as exc:  # noqa: BLE001 -- includes MemoryError; one file must not stop the batch
        report = _failure_report(task, exc)
    report["batch"]["seconds"] = round(time.perf_counter() - t0, 3)
    try:
        return _write_report(task, report)
    except Exception as exc:  # noqa: BLE001 -- e.g. disk full: still report it
        row = summary_row(_failure_report(task, exc))
        row["message"] = f"could not write {task.report}: {row['message']}"
        return row


def _record_failure(task: _Task, exc: BaseException | str) -> dict[str, Any]:
    """Failure seen by the dispatcher (worker died, cluster error), reported as a worker would."""
    report = _failure_report(task, exc)
    report["batch"]["seconds"] = None
    try:
        return _write_report(task, report)
    except Exception:  # noqa: BLE001
        return summary_row(report)


def _skeleton_signature(path: Path) -> list | None:
    """``[path, size, mtime_ns]`` of the .asf an .amc capture is read with, else None.

    An AMC holds only angles; the skeleton beside it (found as :func:`cyclecoord.load`
    finds it) shapes the result too, so a changed .asf must make the report stale.
    """
    if path.suffix.lower() != ".amc":
        return None
    from ..io.asfamc import find_skeleton

    try:
        asf = find_skeleton(path)
        st = asf.stat()
    except (ParseError, OSError):
        return None  # the run fails and says why; a failed report is never reused
    return [str(asf), int(st.st_size), int(st.st_mtime_ns)]


def _up_to_date(task: _Task) -> dict[str, Any] | None:
    """The summary row from ``task``'s existing report, if it still holds; else None."""
    try:
        report = json.loads(task.report.read_text(encoding="utf-8"))
        b = report["batch"]
        if b.get("status") not in ("ok", "no_periodic"):
            return None
        if (
            b.get("file"),
            b.get("input_size"),
            b.get("input_mtime_ns"),
            b.get("options_hash"),
            b.get("skeleton"),
        ) != (task.file, task.size, task.mtime_ns, task.options_hash, task.skeleton):
            return None
        if b["status"] == "ok" and task.cycle_format is not None:
            cyc = b.get("cycle_file")
            if not cyc or not (Path(task.out_dir) / cyc).is_file():
                return None
        return summary_row(report)
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


# ---------------------------------------------------------------- executors
def _run_local(tasks: Sequence[_Task], jobs: int) -> Iterator[dict]:
    """Rows as captures finish, in this process (``jobs == 1``) or in ``jobs`` processes.

    Each process runs one capture at a time in its own single-worker executor, so a worker
    that dies (e.g. killed for running out of memory) is pinned to its capture exactly:
    that capture is recorded as an error and a fresh process takes the next one.
    """
    queue = deque(sorted(tasks, key=lambda t: -t.size))  # biggest first: better balance
    if jobs == 1:
        while queue:
            yield _process_one(queue.popleft())
        return
    # workers start from a clean interpreter (forkserver, or spawn where there is none):
    # a plain fork of this process copies the state of its thread pools (BLAS, OpenMP,
    # progress bar, Dask) and the child can hang on a lock held by a thread it lacks
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    slots: list[ProcessPoolExecutor] = []
    running: dict = {}

    def feed(i: int) -> None:
        if queue:
            t = queue.popleft()
            running[slots[i].submit(_process_one, t)] = (i, t)

    clean_exit = False
    try:
        for i in range(min(jobs, len(queue))):
            slots.append(ProcessPoolExecutor(max_workers=1, mp_context=context))
            feed(i)
        while running:
            done, _ = wait(list(running), return_when=FIRST_COMPLETED)
            for fut in done:
                i, t = running.pop(fut)
                try:
                    row = fut.result()
                except BrokenProcessPool:
                    row = _record_failure(t, _CRASHED)
                    slots[i].shutdown(wait=False)
                    slots[i] = ProcessPoolExecutor(max_workers=1, mp_context=context)
                except Exception as exc:  # noqa: BLE001 -- e.g. an unpicklable result
                    row = _record_failure(t, exc)
                feed(i)
                yield row
        clean_exit = True
    finally:
        for ex in slots:
            ex.shutdown(wait=clean_exit, cancel_futures=True)


def _dask_client(scheduler: Any) -> tuple[Any, bool]:
    """A ``distributed.Client`` for ``scheduler`` and whether this module opened it.

    ``scheduler`` is an address (``tcp://host:8786``), a cluster object such as
    ``distributed.LocalCluster``, or a ``Client`` (used as it is, left open).
    """
    try:
        from distributed import Client
    except ImportError:
        raise ParameterError(
            "running on a Dask cluster needs the optional dependency dask[distributed] "
            "(pip install 'cyclecoord[dask]')"
        ) from None
    if isinstance(scheduler, Client):
        return scheduler, False
    try:
        return Client(scheduler, timeout=CONNECT_TIMEOUT), True
    except (OSError, ValueError, TypeError) as exc:
        raise ParameterError(
            f"could not connect to the Dask scheduler at {scheduler!r}: {exc}"
        ) from None


def _run_dask(tasks: Sequence[_Task], client: Any) -> Iterator[dict]:
    """Rows as captures finish on a Dask distributed cluster.

    The workers must see the input and output folders at the same paths (shared
    filesystem); they need cyclecoord installed.  Only the small rows come back.
    """
    from distributed import as_completed

    ordered = sorted(tasks, key=lambda t: -t.size)  # biggest first: better balance
    futures = client.map(_process_one, ordered, pure=False)
    which = {f.key: t for f, t in zip(futures, ordered)}
    for fut in as_completed(futures):
        t = which[fut.key]
        try:
            row = fut.result()
        except Exception as exc:  # noqa: BLE001 -- KilledWorker, cancelled, lost connection, ...
            row = _record_failure(t, exc)
        yield row


# --------------------------------------------------------------------- main
def _outputs_inside(out: Path, folder: Path) -> bool:
    return out == folder or folder in out.parents


def run_batch(
    folder: str | os.PathLike[str],
    out_dir: str | os.PathLike[str],
    jobs: int = 1,
    scheduler: Any = None,
    pattern: str | Sequence[str] = DEFAULT_PATTERNS,
    recursive: bool = True,
    force: bool = False,
    extract_options: dict | None = None,
    write_cycles: str | None = "bvh",
    fps: float | None = None,
    progress: bool = True,
) -> BatchSummary:
    """Run :func:`~cyclecoord.periodic.pipeline.extract` on every capture under ``folder``.

    Parameters
    ----------
    folder : path-like
        Input folder; scanned with :func:`find_captures`.  Nothing is ever written there.
    out_dir : path-like
        Output folder (created if needed); must not be ``folder`` or lie inside it.
        Outputs mirror the input tree (see the module docstring).
    jobs : int, default 1
        Local worker processes; 1 runs in this process (no pool), 0 means one per CPU
        core.  Ignored with ``scheduler``.
    scheduler : str, cluster or distributed.Client, optional
        Run on this Dask distributed cluster instead: a scheduler address
        (``tcp://host:8786``), a cluster object (e.g. ``distributed.LocalCluster``) or a
        client, which is left open.  Needs ``dask[distributed]``; the workers must see both
        folders at the same paths and have cyclecoord installed.
    pattern : str or sequence of str
        File-name globs (case-insensitive), default ``*.amc *.bvh *.npz *.csv``.
    recursive : bool, default True
        Scan subfolders.
    force : bool, default False
        Recompute every capture, even those whose report is up to date.
    extract_options : dict, optional
        Keyword arguments for :func:`~cyclecoord.periodic.pipeline.extract` (``frames``, ``pca``,
        ``max_scale``, ``random_state``, ...), the same for every capture.  Checked
        against extract's signature before anything runs.
    write_cycles : {"bvh", "npz", "csv", "glb", "gltf", "usda", "usdc", None}, default "bvh"
        Format of the typical cycle written per capture (``NAME.cycle.<format>``, written
        by :func:`cyclecoord.save` as ``extract -o`` writes it; ``gltf`` adds
        ``NAME.cycle.bin``), or None for reports only.  A capture without a skeleton gets
        ``.npz`` when a format that needs one is asked for.  USD needs usd-core.
    fps : float, optional
        Frame rate overriding the files' own (AMC files carry none: 120).
    progress : bool, default True
        Show a progress bar (on stderr) over the analysed captures.

    Returns
    -------
    BatchSummary
        Rows per capture, what was analysed and skipped, counts and time.

    Raises
    ------
    ParameterError
        Bad arguments, a missing input folder, an output folder inside the input folder,
        or an unreachable Dask scheduler.  Problems with single captures never raise.

    Notes
    -----
    With ``jobs > 1`` each worker process takes one capture at a time; a worker that dies
    (killed for lack of memory, a crash in native code) marks only its capture as an
    error and is replaced.  ``jobs=1`` runs in this process: exceptions, ``MemoryError``
    included, are recorded per capture, but a hard crash ends the run (re-running
    resumes).  Worker processes start from a clean interpreter (``forkserver`` where
    available, else ``spawn``), never as a fork of this process; like any such use of
    :mod:`multiprocessing`, a script calling this function with ``jobs > 1`` must do so
    under ``if __name__ == "__main__":``.
    """
    t_start = time.perf_counter()
    jobs, write_cycles, fps = _check_run_arguments(jobs, write_cycles, fps)
    options = dict(extract_options or {})
    normalised = _check_options(options)
    opt_hash = _options_hash(normalised, fps, write_cycles)
    patterns = as_patterns(pattern)
    src, out = _check_folders(folder, out_dir)
    files = find_captures(src, patterns, recursive)
    tasks = _plan_tasks(files, src, out, folder, options, fps, write_cycles, opt_hash)
    _refuse_overwrites(tasks, out, write_cycles)
    out.mkdir(parents=True, exist_ok=True)
    rows, skipped, todo = _split_up_to_date(tasks, force)
    for t in todo:
        t.report.parent.mkdir(parents=True, exist_ok=True)
    _execute(todo, jobs, scheduler, progress, rows)
    for t in todo:  # defensive: every capture gets a row even if an executor lost it
        if t.file not in rows:
            rows[t.file] = _record_failure(t, "the capture was not analysed (lost by the executor)")
    ordered = [rows[t.file] for t in tasks]
    summary_path = out / SUMMARY_NAME
    write_summary(summary_path, ordered)
    return BatchSummary(
        folder=src, out_dir=out, rows=ordered, processed=[t.file for t in todo],
        skipped=skipped, seconds=time.perf_counter() - t_start, summary_path=summary_path,
        patterns=patterns,
    )


def _check_run_arguments(
    jobs: Any, write_cycles: Any, fps: Any
) -> tuple[int, str | None, float | None]:
    """``jobs`` (0: one per core), ``write_cycles`` ("none": None) and ``fps`` checked."""
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 0:
        raise ParameterError(
            f"jobs must be a whole number >= 1 (0: one per CPU core), got {jobs!r}"
        )
    jobs = jobs or (os.cpu_count() or 1)
    if isinstance(write_cycles, str) and write_cycles.lower() == "none":
        write_cycles = None
    if isinstance(write_cycles, str):
        write_cycles = write_cycles.lower().lstrip(".")
    if write_cycles is not None and write_cycles not in CYCLE_FORMATS:
        raise ParameterError(
            f"write_cycles must be one of {', '.join(CYCLE_FORMATS)} or None, got {write_cycles!r}"
        )
    if write_cycles in ("usda", "usdc"):
        from ..io.usd import require_usd

        require_usd()  # usd-core missing: one clear error before anything runs
    if fps is not None:
        try:
            fps = float(fps)
        except (TypeError, ValueError):
            raise ParameterError(f"fps must be a positive number, got {fps!r}") from None
        if not (0 < fps < math.inf):
            raise ParameterError(f"fps must be a positive number, got {fps!r}")
    return jobs, write_cycles, fps


def _check_folders(
    folder: str | os.PathLike[str], out_dir: str | os.PathLike[str]
) -> tuple[Path, Path]:
    """The resolved input and output folders; the output may not hold the input's files."""
    src = Path(folder)
    if not src.is_dir():
        raise ParameterError(f"{folder}: no such folder")
    src = src.resolve()
    out = Path(out_dir).resolve()
    if out.exists() and not out.is_dir():
        raise ParameterError(f"{out_dir}: exists and is not a folder")
    if _outputs_inside(out, src):
        raise ParameterError(
            f"the output folder {out_dir} is the input folder or inside it; choose a folder "
            "outside the input (outputs are never written among the captures)"
        )
    return src, out


def _plan_tasks(
    files: Sequence[str],
    src: Path,
    out: Path,
    folder: str | os.PathLike[str],
    options: dict,
    fps: float | None,
    write_cycles: str | None,
    opt_hash: str,
) -> list[_Task]:
    """One task per capture, its outputs mirroring the input tree under ``out``.

    Outputs are named by the capture's stem, or by its full name when several captures
    of one folder share a stem (``walk.amc`` and ``walk.bvh``).
    """
    stems = Counter((Path(f).parent.as_posix(), Path(f).stem) for f in files)
    tasks: list[_Task] = []
    for f in files:
        p = Path(f)
        name = p.stem if stems[(p.parent.as_posix(), p.stem)] == 1 else p.name
        base = out / p.parent / name
        if _outputs_inside(base, src):
            raise ParameterError(
                f"the outputs of {f} would go to {base.parent}, inside the input folder "
                f"{folder}; choose an output folder that does not hold the input folder's tree"
            )
        st = (src / f).stat()
        tasks.append(_Task(
            file=f, input=str(src / f), base=str(base), out_dir=str(out), size=int(st.st_size),
            mtime_ns=int(st.st_mtime_ns), options=options, fps=fps, cycle_format=write_cycles,
            options_hash=opt_hash, skeleton=_skeleton_signature(src / f),
        ))
    return tasks


def _refuse_overwrites(tasks: Sequence[_Task], out: Path, write_cycles: str | None) -> None:
    """ParameterError when any output (summary, report, cycle) would overwrite an input."""
    written = [("the summary", out / SUMMARY_NAME)]
    for t in tasks:
        written.append((f"the report of {t.file}", t.report))
        if write_cycles is not None:  # a capture without a skeleton gets an .npz cycle
            written += [(f"the cycle of {t.file}", Path(f"{t.base}.cycle.{fmt}"))
                        for fmt in sorted({write_cycles, "npz"})]
    refuse_clobber([t.input for t in tasks] + [t.skeleton[0] for t in tasks if t.skeleton],
                   written)


def _split_up_to_date(
    tasks: Sequence[_Task], force: bool
) -> tuple[dict[str, dict], list[str], list[_Task]]:
    """Rows of the captures whose report is up to date, their names, and the rest to run."""
    rows: dict[str, dict] = {}
    skipped: list[str] = []
    todo: list[_Task] = []
    for t in tasks:
        row = None if force else _up_to_date(t)
        if row is None:
            todo.append(t)
        else:
            rows[t.file] = row
            skipped.append(t.file)
    return rows, skipped, todo


def _execute(
    todo: Sequence[_Task], jobs: int, scheduler: Any, progress: bool, rows: dict[str, dict]
) -> None:
    """Analyse ``todo`` locally or on Dask, adding each capture's row to ``rows``."""
    client, own_client = (None, False)
    if todo and scheduler is not None:
        client, own_client = _dask_client(scheduler)  # fail on a bad address before starting
    try:
        if not todo:
            runner: Iterator[dict] = iter(())
        elif client is not None:
            runner = _run_dask(todo, client)
        else:
            runner = _run_local(todo, jobs)
        from tqdm.auto import tqdm

        with tqdm(total=len(todo), desc="batch", unit="file",
                  disable=not progress or not todo) as bar:
            for row in runner:
                rows[row["file"]] = row
                bar.set_postfix_str(f"{row['file']}: {row['status']}", refresh=False)
                bar.update(1)
    finally:
        if own_client:
            client.close()
