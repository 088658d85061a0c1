"""After a refusal: try the options that most often help and say which do, for this capture.

A refusal that lists options to try leaves the user to run them one by one, and the generic
list (``--max-scale``, ``--pca``, ``--frames``) did not help on any of the BVH walks it was
first shown on.  :func:`what_would_help` runs :func:`~cyclecoord.periodic.pipeline.extract`
again with each alternative in turn (rotations read as rotation vectors, every frame
instead of the steady ones, three principal components, every channel scaled to unit
variance), cheaply: only on captures up to :data:`MAX_FRAMES` frames, with landmarks as
``extract`` chooses them, and it stops at the first two that find a cycle whose quality
holds (no pop, no stray pose).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

from ..errors import CycleCoordError
from ..motion import Motion

__all__ = ["Suggestion", "what_would_help", "ALTERNATIVES", "MAX_FRAMES"]

#: Captures longer than this are not retried (each try is a whole extraction).
MAX_FRAMES = 20_000

#: (command-line option, extract keywords) in the order they are tried.
ALTERNATIVES: tuple[tuple[str, dict[str, Any]], ...] = (
    ("--rotations rotvec", {"rotations": "rotvec"}),
    ("--no-steady", {"steady": False}),
    ("--pca 3", {"pca": 3}),
    ("--normalize", {"normalize": True}),
)


@dataclass(frozen=True)
class Suggestion:
    """An option that finds a cycle on this capture.

    Attributes
    ----------
    option : str
        As typed on the command line.
    period_frames : float
    cycles : float
        Turns of the coordinate over the frames used.
    """

    option: str
    period_frames: float
    cycles: float

    def text(self) -> str:
        return f"{self.option} (period {self.period_frames:.1f} frames, {self.cycles:.1f} cycles)"

    def to_dict(self) -> dict:
        return {"option": self.option, "period_frames": float(self.period_frames),
                "cycles": float(self.cycles)}


def what_would_help(motion: Motion, options: dict[str, Any], most: int = 2) -> list[Suggestion]:
    """The alternatives that find a clean cycle where ``extract(motion, **options)`` did not.

    Parameters
    ----------
    motion : Motion
        The capture that was refused (already windowed, or with ``frames`` in ``options``).
    options : dict
        The keywords the refused extraction ran with; an alternative that sets one of them
        to the value already given is skipped.
    most : int
        Stop after this many successes.

    Returns
    -------
    list of Suggestion
        Empty when nothing helps, or when the capture is longer than :data:`MAX_FRAMES`.
    """
    from .pipeline import extract

    if motion.n_frames > MAX_FRAMES:
        return []
    found: list[Suggestion] = []
    for option, change in ALTERNATIVES:
        if all(options.get(k) == v for k, v in change.items()):
            continue
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = extract(motion, **{**options, **change})
        except CycleCoordError:
            continue
        q = res.pose_quality
        if q is not None and (q.pops or q.strays):
            continue
        found.append(Suggestion(option, float(res.period_frames), float(res.cycles)))
        if len(found) >= most:
            break
    return found
