"""Root tracks of a script's models sized to the skeleton the output is written on.

A script's frames are written on the skeleton of the model it starts in; another model
trained on an actor with other bone lengths carries its own actor's root height and
speed.  On subject 35's walk and the 143_01 jog (legs 15.5 and 13.1 units) a script
that started in the jog and crossed to the walk held the shorter skeleton's pelvis at the
walk actor's height: its feet hung 0.2 leg lengths above the floor, no contact was found
to carry the root or pin a foot, and the walk glided at 0.35 m/s (the takes: 0.06).
"""

from __future__ import annotations

import copy

import numpy as np

from ...errors import CycleCoordError
from .model import LatentModel, RootTrack

__all__ = ["SIZE_TOLERANCE", "size_note", "sized_roots"]

#: Leg length ratios within this of 1 leave a model's root track as it is.
SIZE_TOLERANCE = 0.01


def sized_roots(
    models: dict[str, LatentModel], output: str, feet: tuple[str, ...] | None = None
) -> tuple[dict[str, LatentModel], dict[str, float]]:
    """``models`` with each other model's root track in ``output``'s size, and the scale
    of each model sized.

    A model of another actor on the rig (:func:`~cyclecoord.rig.retarget.proportions_differ`)
    whose legs are ``1 / s`` times the output model's
    (:func:`~cyclecoord.rig.retarget.leg_scale`) has its root height above its training
    frames' floor and its root velocity scaled by ``s`` (the heading turn and the tilt
    are angles and stay), as retargeting a root by leg length does; its poses (joint
    angles) are the same.  The models given are not changed: a changed one is a shallow
    copy.  (Where a skeleton's feet cannot be found, its summed bone length stands for
    its legs.)

    Parameters
    ----------
    models : dict of str to LatentModel
    output : str
        The model whose skeleton the frames are written on (the script's first).
    feet : tuple of str, optional
        Foot points on every model's skeleton (default found on each).

    Returns
    -------
    models : dict of str to LatentModel
    scales : dict of str to float
        ``s`` of each model sized, by name (its joint positions, speeds and
        accelerations on the output skeleton are ``s`` times those of its takes).
    """
    from ...quality.contacts import foot_contacts
    from ...rig.retarget import leg_scale, proportions_differ

    out = models[output]
    sized, scales, floor = dict(models), {}, None
    for name, m in models.items():
        if name == output or not proportions_differ(out.skeleton_, m.skeleton_):
            continue
        try:
            s = leg_scale(m.training_motion(), out.training_motion())
            if abs(s - 1.0) <= SIZE_TOLERANCE:
                continue
            if floor is None:
                floor = foot_contacts(out.training_motion(), feet).floor
            own = foot_contacts(m.training_motion(), feet).floor
        except CycleCoordError:
            continue
        r = m.root_
        c = copy.copy(m)
        c.root_ = RootTrack(height=floor + s * (np.asarray(r.height) - own),
                            velocity=s * np.asarray(r.velocity), turn=r.turn, tilt=r.tilt)
        c._detail = None  # (made from the root track)
        sized[name] = c
        scales[name] = s
    return sized, scales


def size_note(name: str, scale: float, output: str) -> str:
    """The console line for model ``name`` sized by ``scale`` to ``output``'s skeleton."""
    return (f"model {name!r}: another actor (legs {1.0 / scale:.2f}x {output!r}'s, on whose "
            f"skeleton the frames are written): its root height and speed scaled "
            f"{scale:.2f}x")
