"""A command's input (a file or a built-in example) and its printed and JSON reports.

The JSON writing and the partial report of a capture with nothing periodic live in the neutral
:mod:`cyclecoord.periodic.report`, which ``cyclecoord.batch`` shares without importing the CLI."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..periodic.report import clean, partial_report, write_json

__all__ = ["clean", "load_input", "partial_report", "summary_barcode", "write_json"]

EXAMPLES = ("walk", "jog", "jumping_jack", "arm_circles", "squat", "chain", "take")


def load_input(path: str, skeleton: str | None = None, fps: float | None = None):
    """Load a capture, or a built-in example when ``path`` is ``example[:kind]``."""
    from .. import datasets
    from ..io import load

    if (path == "example" or path.startswith("example:")) and not Path(path).exists():
        kind = path.split(":", 1)[1] if ":" in path else "walk"
        if kind not in EXAMPLES:
            raise ParameterError(
                f"unknown built-in example {kind!r}; choose from {', '.join(EXAMPLES)}"
            )
        if kind == "walk":
            cap = datasets.example_capture()
        elif kind == "chain":
            cap = datasets.make_motion_chain(random_state=0)
        elif kind == "take":
            cap = datasets.make_whole_take(random_state=0)
        else:
            cap = datasets.make_periodic_capture(kind=kind, n_frames=480, random_state=0)
        m = cap.motion
        if fps is not None:
            from dataclasses import replace

            m = replace(m, fps=fps)
        return m
    return load(path, skeleton=skeleton, fps=fps)


def summary_barcode(bc, sel=None) -> str:
    """The barcode in a few lines: its size and the five longest H1 bars (``sel`` marked)."""
    pers = bc.persistence(1)
    head = f"barcode up to {bc.threshold:.4g} (Z/{bc.prime}): "
    lines = [head + f"{len(bc.h0)} H0 bars, {len(bc.h1)} H1 bars"]
    for k, (b, d) in enumerate(bc.h1[:5]):
        mark = "  <- selected" if sel is not None and k == sel.index else ""
        ds = "inf" if not np.isfinite(d) else f"{d:.4g}"
        lines.append(f"  H1 #{k}: [{b:.4g}, {ds})  persistence {pers[k]:.4g}{mark}")
    if len(bc.h1) > 5:
        lines.append(f"  ... {len(bc.h1) - 5} shorter H1 bars (longest {pers[5]:.4g})")
    return "\n".join(lines)
