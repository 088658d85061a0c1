"""Built-in synthetic captures (walk, jog, jumping jacks, ...) with known phase and labels.

Every generator returns a :class:`SyntheticCapture`: the noisy :class:`~cyclecoord.motion.Motion`
a user would load, the noise-free signal it was made from, and the ground truth the
pipeline's tests compare against (true phase, mean period, per-frame motion labels,
segment boundaries).  Nothing here reads a file, so the README's example and the tests
of the periodic pipeline need no data.

Conventions of :func:`cmu_skeleton` (all joint axes are the identity, so the rotation
channels act about world-aligned axes of the parent's frame; y is up, the character faces
+z and its left is +x):

* ``rx`` on a leg or arm bone: positive swings it backward (hip/shoulder extension),
  negative forward (flexion).  Knee flexion is positive ``tibia rx``; elbow flexion is
  *negative* ``radius rx``; ankle plantar flexion (toes down) is positive ``foot rx``.
* ``rz`` on the left limbs is abduction (away from the body), on the right limbs
  adduction; ``ry`` is rotation about the bone's long axis (vertical at rest).
* ``rx`` on the spine and neck leans forward; root ``ry`` is the heading (yaw).

Angles are in degrees; lengths in CMU-like units (``length_unit`` 0.45, i.e. one unit
is 1/0.45 inch): thigh 7.4, shin 7.5, standing pelvis height about 17.3, total height
about 29.

The package's modules: :mod:`.captures` (one motion, chains, still and random captures),
:mod:`.whole_take` (whole takes with starts, turns, pauses and stops) and the private
``_body`` (the skeleton, poses and timing they share).
"""

from ._body import AMC_JOINT_ORDER, KINDS, cmu_skeleton
from .captures import (
    SyntheticCapture,
    example_capture,
    make_motion_chain,
    make_periodic_capture,
    make_random_walk_capture,
    make_static_capture,
)
from .whole_take import PART_NAMES, make_whole_take

__all__ = [
    "KINDS",
    "AMC_JOINT_ORDER",
    "SyntheticCapture",
    "cmu_skeleton",
    "make_periodic_capture",
    "make_motion_chain",
    "make_whole_take",
    "PART_NAMES",
    "make_static_capture",
    "make_random_walk_capture",
    "example_capture",
]
