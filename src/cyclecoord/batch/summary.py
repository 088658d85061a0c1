"""What a batch run leaves: :class:`BatchSummary`, the ``summary.csv`` row of one capture's
report (:func:`summary_row`) and the writing of ``summary.csv``."""

from __future__ import annotations

import csv
import math
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

from .discovery import DEFAULT_PATTERNS
from ..io import atomic_write

__all__ = [
    "BatchSummary",
    "summary_row",
    "write_summary",
    "SUMMARY_COLUMNS",
    "STATUSES",
    "SUMMARY_NAME",
]

#: Columns of ``summary.csv``.  ``birth``/``death``/``scale`` describe the selected H1 bar
#: (for ``no_periodic``: the most persistent bar, no scale); ``death`` ``inf`` means the
#: bar lives past the filtration threshold; ``jerk_ratio`` is the cycle's mean jerk over
#: the capture's; ``seconds`` is the wall time of load + extract + writing.
SUMMARY_COLUMNS = (
    "file", "status", "frames", "dims", "cycles", "period_frames", "period_seconds",
    "birth", "death", "scale", "loop_closure", "jerk_ratio", "seconds", "cycle_file", "message",
)
#: Possible statuses of a capture.
STATUSES = ("ok", "no_periodic", "error")
SUMMARY_NAME = "summary.csv"


@dataclass
class BatchSummary:
    """What :func:`run_batch` did.

    Attributes
    ----------
    folder, out_dir : Path
        The resolved input and output folders.
    rows : list of dict
        One row per capture, sorted by file, keyed by :data:`SUMMARY_COLUMNS` (numbers as
        floats/ints, ``None`` where not applicable) -- the content of ``summary.csv``.
    processed : list of str
        Captures analysed in this run (relative paths).
    skipped : list of str
        Captures whose report was up to date.
    seconds : float
        Wall time of the whole run.
    summary_path : Path
        The ``summary.csv`` written.
    patterns : tuple of str
        The file-name patterns scanned.
    """

    folder: Path
    out_dir: Path
    rows: list[dict]
    processed: list[str]
    skipped: list[str]
    seconds: float
    summary_path: Path
    patterns: tuple[str, ...] = DEFAULT_PATTERNS
    counts: dict = field(init=False)

    def __post_init__(self) -> None:
        c = Counter(r["status"] for r in self.rows)
        self.counts = {s: int(c.get(s, 0)) for s in STATUSES}

    @property
    def n_ok(self) -> int:
        """Captures with a cycle."""
        return self.counts["ok"]

    @property
    def n_no_periodic(self) -> int:
        """Captures with nothing periodic."""
        return self.counts["no_periodic"]

    @property
    def n_error(self) -> int:
        """Captures that failed."""
        return self.counts["error"]

    @property
    def errors(self) -> list[dict]:
        """Rows of the failed captures."""
        return [r for r in self.rows if r["status"] == "error"]

    def row(self, file: str) -> dict:
        """The summary row of one capture (relative path as in ``rows``)."""
        for r in self.rows:
            if r["file"] == file:
                return r
        raise KeyError(file)

    def describe(self) -> str:
        """Human-readable summary: counts, failures, time and where summary.csv is."""
        if not self.rows:
            return (
                f"no captures matching {' '.join(self.patterns)} under {self.folder}\n"
                f"summary: {self.summary_path}"
            )
        n = len(self.rows)
        parts = [f"{self.n_ok} ok", f"{self.n_no_periodic} no periodic motion",
                 f"{self.n_error} error" + ("s" if self.n_error != 1 else "")]
        lines = [
            f"{n} capture{'s' if n != 1 else ''} under {self.folder}: "
            + ", ".join(parts)
            + f" ({len(self.processed)} analysed, {len(self.skipped)} up to date)"
            + f" in {self.seconds:.1f} s"
        ]
        for r in self.errors:
            lines.append(f"error: {r['file']}: {r['message']}")
        lines.append(f"summary: {self.summary_path}")
        return "\n".join(lines)


def _num(v: Any) -> float | None:
    if v is None or isinstance(v, bool):
        return None
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return None if math.isnan(f) else f


def summary_row(report: dict) -> dict[str, Any]:
    """Summary row (:data:`SUMMARY_COLUMNS`) of one capture's report."""
    b = report["batch"]
    row: dict[str, Any] = dict.fromkeys(SUMMARY_COLUMNS)
    status = b["status"]
    if status not in STATUSES:
        raise ValueError(f"unknown status {status!r}")
    row.update(file=b["file"], status=status, seconds=_num(b.get("seconds")),
               cycle_file=b.get("cycle_file"), message=b.get("message") or "")
    if status == "error":
        return row
    row["frames"] = report.get("n_frames")
    row["dims"] = report.get("dims")
    if status == "ok":
        sel = report["selected"]
        jerk = report.get("jerk") or {}
        orig, cyc = _num(jerk.get("original")), _num(jerk.get("cycle"))
        row.update(
            cycles=_num(report.get("cycles")),
            period_frames=_num(report.get("period_frames")),
            period_seconds=_num(report.get("period_seconds")),
            birth=_num(sel.get("birth")),
            death=math.inf if sel.get("death") is None else _num(sel["death"]),
            scale=_num(sel.get("scale")),
            loop_closure=_num(report.get("loop_closure")),
            jerk_ratio=cyc / orig if orig and cyc is not None else None,
        )
    else:  # the most persistent H1 bar, to show how far from clear it was
        bars = (report.get("barcode") or {}).get("h1") or []
        cap = _num(report.get("threshold"))
        best = None
        for birth, death in bars:
            end = death if death is not None else (cap if cap is not None else math.inf)
            if best is None or end - birth > best[2]:
                best = (birth, death, end - birth)
        if best is not None:
            row["birth"] = _num(best[0])
            row["death"] = math.inf if best[1] is None else _num(best[1])
    return row


def write_summary(path: Path, rows: Sequence[dict]) -> None:
    def cell(v: Any) -> str:
        if v is None:
            return ""
        if isinstance(v, float):
            if math.isinf(v):
                return "inf" if v > 0 else "-inf"
            return f"{v:.6g}"
        return str(v)

    with atomic_write(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(SUMMARY_COLUMNS)
        for r in rows:
            w.writerow([cell(r.get(c)) for c in SUMMARY_COLUMNS])
