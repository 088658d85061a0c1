"""The extraction report's shared pieces: its header, strict JSON writing and the partial
report of a run with nothing periodic.

:meth:`~cyclecoord.periodic.results.ExtractionResult.to_report` starts with
:func:`capture_header`; the command line (``cyclecoord.cli``) and :mod:`cyclecoord.batch`
write reports with :func:`write_json` and :func:`partial_report`.  It imports neither, so
neither imports the other for it.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from ..errors import NoPeriodicMotionError

__all__ = ["capture_header", "clean", "partial_report", "write_json"]


def capture_header(motion: Any) -> dict[str, Any]:
    """The first keys of every report: the capture's source, frame range, length and rate."""
    return {
        "source": motion.source,
        "frames": [int(motion.start_frame), int(motion.start_frame + motion.n_frames)],
        "n_frames": int(motion.n_frames),
        "fps": motion.fps,
    }


def write_json(path: str, payload: dict) -> None:
    """Write ``payload`` as indented strict JSON, atomically (numpy scalars and arrays allowed)."""
    from ..io import atomic_write

    with atomic_write(path, "w") as fh:
        json.dump(payload, fh, indent=1, allow_nan=False, default=_json_default)
        fh.write("\n")


def _json_default(o):
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, (np.floating,)):
        v = float(o)
        return v if np.isfinite(v) else None
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def clean(obj):
    """Replace non-finite floats by None so the JSON is strict."""
    if isinstance(obj, dict):
        return {k: clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean(v) for v in obj]
    if isinstance(obj, (float, np.floating)):
        return float(obj) if np.isfinite(obj) else None
    return obj


def partial_report(exc: NoPeriodicMotionError) -> dict[str, Any]:
    """Report of a capture with nothing periodic: its barcode and why it was rejected.

    The same for ``cyclecoord extract --report`` and the per-capture reports of
    :func:`cyclecoord.batch.run_batch`. Without a partial result (nothing got as far as a
    barcode) only ``selected`` (None) and ``error`` are filled.
    """
    partial = exc.result
    if partial is None:
        return {"selected": None, "error": str(exc)}
    return {
        **capture_header(partial.motion),
        "dims": int(partial.prepared.points.shape[1]),
        "parameters": partial.parameters,
        "threshold": partial.barcode.threshold,
        "prime": int(partial.barcode.prime),
        "barcode": partial.barcode.to_dict(),
        "selected": None,
        "error": str(exc),
        "timings": {k: round(float(v), 6) for k, v in partial.timings.items()},
        "warnings": list(partial.warnings),
    }
