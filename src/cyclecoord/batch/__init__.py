"""Batch processing: :func:`~cyclecoord.periodic.pipeline.extract` over every capture in a folder.

The modules follow a run: :mod:`.discovery` finds the captures under a folder,
:mod:`.runner` extracts each (in this process, a local process pool or on a Dask
cluster) and writes its report and cycle, and :mod:`.summary` gathers the reports into
``summary.csv``.  The names a script uses are re-exported here
(``from cyclecoord.batch import run_batch``).
"""

from __future__ import annotations

from .discovery import DEFAULT_PATTERNS, as_patterns, find_captures
from .runner import CYCLE_FORMATS, REPORT_SUFFIX, SKELETON_FORMATS, run_batch
from .summary import (
    STATUSES,
    SUMMARY_COLUMNS,
    SUMMARY_NAME,
    BatchSummary,
    summary_row,
    write_summary,
)

__all__ = [
    "run_batch",
    "BatchSummary",
    "find_captures",
    "as_patterns",
    "summary_row",
    "write_summary",
    "DEFAULT_PATTERNS",
    "SUMMARY_COLUMNS",
    "SUMMARY_NAME",
    "STATUSES",
    "CYCLE_FORMATS",
    "REPORT_SUFFIX",
    "SKELETON_FORMATS",
]
