"""The synthetic walk (1.1 s leg cycle) and run (0.7 s) latent models the gait tests share:
two 4 s segments each, every 4th frame of a 120 fps synthetic capture."""

from __future__ import annotations

import cyclecoord as cc
from cyclecoord.synthesis.latent import LatentModel


def gait_model(kind: str, period: int, seed: int) -> LatentModel:
    """A latent model of ``kind`` (``"walk"``, ``"jog"``) with the given period (frames)."""
    m = cc.datasets.make_periodic_capture(
        kind=kind, n_frames=960, period=period, noise=0.3, speed_variation=0.1,
        random_state=seed,
    ).motion
    return LatentModel(gplvm={"max_iter": 80}).fit([m[0:480:4], m[480:960:4]], ["a", "b"])


def gait_pair() -> dict[str, LatentModel]:
    """``{"walk": ..., "run": ...}``."""
    return {"walk": gait_model("walk", 132, 0), "run": gait_model("jog", 84, 1)}


def stop(models: dict, part: str, seed: int, then: int = 0):
    """A MOVE ahead of ``1.0 + 0.07 seed`` s that comes to a stop, IDLE 2 s, then ``then``
    MOVEs ahead of 0.5 s: the synthesizer and its motion."""
    from cyclecoord.synthesis.latent import Synthesizer

    syn = Synthesizer(models, fps=30, seed=seed)
    syn.start(part, {"frame": 0})
    syn.command += 1
    syn.move({"ahead": 1.0 + 0.07 * seed})
    syn.command += 1
    syn.idle(duration=2.0)
    for _ in range(then):
        syn.command += 1
        syn.move({"ahead": 0.5}, stop=False)
    return syn, syn.motion()
