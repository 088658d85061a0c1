"""Acclaim ASF (skeleton) and AMC (motion) reading and writing.

Conventions (see :mod:`cyclecoord.skeleton` for the shared skeleton model):

* The ASF root becomes a joint named ``"root"`` whose offset is the ASF root
  ``position``; its dofs follow the root ``order`` line in file order and its rest axis is
  built from the root ``axis`` letters and ``orientation`` angles.
* Every ASF bone becomes one joint placed at the bone's *start* (the end of its parent
  bone).  Its offset is the parent bone's vector ``direction * length`` (ASF directions
  are global and the rest pose is world aligned, so no change of frame is needed); bones
  hanging from the root start at the root (offset zero).  A leaf bone keeps its own
  vector as ``end_site``.  A bone's own vector is therefore always recoverable: it is the
  offset of any of its children, or its end site.
* Rotation dofs listed ``rx ry rz`` are applied first listed first, i.e. the motion
  matrix is ``Rz @ Ry @ Rx`` and the intrinsic ``rotation_order`` is ``"ZYX"`` (CMU's
  mocapPlayer convention).  ``axis a b c XYZ`` pairs each angle with the letter at the
  same position and also applies the first letter first: ``C = Rz(c) @ Ry(b) @ Rx(a)``.
  A bone's ``axis a b c`` without letters means ``XYZ``.
  The root ``orientation`` is read the same way with the root ``axis`` letters.
* Angles are degrees unless the ASF says ``:units angle rad`` or the AMC says
  ``:RADIANS``; skeletons and motions always hold degrees.  An AMC with neither
  ``:DEGREES`` nor ``:RADIANS`` uses the ASF's angle unit when the ASF is read from a
  file, degrees otherwise.
* Translation dofs on a bone (``tx ty tz``) replace the matching component of the joint's
  offset, as everywhere in cyclecoord.

Writing any :class:`~cyclecoord.skeleton.Skeleton` (for instance one read from BVH) as
ASF uses this mapping:

* the first joint is written as the ASF ``root`` (whatever its name); other names are
  made ASF-safe (whitespace, ``#`` and parentheses become ``_``; names that could be read
  as numbers, ``begin``, ``end`` or ``root`` get a ``j_`` prefix; clashes get a numeric
  suffix).  The AMC written for the same skeleton uses the same names;
* a joint whose children all sit at the same offset becomes a bone with that vector; a
  leaf becomes a bone whose vector is its end site (zero length without one);
* a joint whose children sit at *different* offsets (common in BVH) becomes a
  zero-length bone, and every child with a non-zero offset ``o`` is hung from a
  zero-dof helper bone named ``<parent>_to_<child>`` whose vector is ``o``.  The root is
  always treated this way because an ASF root has no bone.  Helper bones carry no
  rotation, so every original joint keeps exactly its forward-kinematics position and
  rotation (also when it has translation channels), and helper bones never appear in
  AMC files;
* rotation dofs are listed in reverse intrinsic order (so ``rotation_order`` survives);
  translation dofs come first when the listing had to change; ``axis`` and the root
  orientation are written as ``XYZ`` angles; end sites of joints that have children and
  limits of the root are not representable and are dropped.

The work is split by job: :mod:`~cyclecoord.io.asf_read` (ASF parsing),
:mod:`~cyclecoord.io.amc_read` (AMC parsing, finding the skeleton),
:mod:`~cyclecoord.io.asfamc_write` (ASF and AMC writing) and the private
``_acclaim`` (shared text/number helpers and the skeleton-to-ASF bone mapping).
This module gathers the public functions under their historical path.
"""

from __future__ import annotations

from .amc_read import find_skeleton, read_amc
from .asf_read import read_asf
from .asfamc_write import write_amc, write_asf

__all__ = ["read_asf", "write_asf", "read_amc", "write_amc", "find_skeleton"]
