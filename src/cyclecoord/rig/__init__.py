"""Rig conventions of a capture, found, reported and undone for the analysis.

This subpackage has one job: to say how a capture's rig is laid out and to hand the analysis a
motion in one convention, then write results back in the user's own rig.
:func:`describe_rig` finds the joint that travels (the root, or a static root whose
channels never change with one child that carries the travel, as in the Bandai Namco
rig), the joints whose position channels are constant offsets, the length unit (from the
body's height by forward kinematics: metres, centimetres, millimetres, inches, CMU's
ASF unit of 1/0.45 inch, or the ASF ``:units length``), the up axis (Y or Z, the axis the
body extends along), the frame rate and a reference pose in the first frame that is
discontinuous with the rest (Xsens MVN exports); :meth:`RigInfo.summary` says it in one
line.  :func:`normalize_rig` gives the motion the analysis should see (static root folded
into its child, constant position channels made offsets, Y up, reference frame dropped)
and a :class:`RigAdapter` whose :meth:`~RigAdapter.restore` writes any motion on the
analysis skeleton (a cycle, a blend) back with the original skeleton and channels.

Finding lives in :mod:`.describe` (:func:`describe_rig`, units and up axis), undoing in
:mod:`.normalize` (:func:`normalize_rig`, :class:`RigAdapter`), putting one rig's takes by
actors of other proportions on one skeleton in :mod:`.retarget` (:func:`onto_skeleton`);
every name is importable from ``cyclecoord.rig``.
"""

from .describe import (
    CMU_UNIT,
    UNITS,
    Z_TO_Y,
    RigInfo,
    Units,
    describe_rig,
    metres_per_unit,
    parse_units,
    rig_summary,
)
from .normalize import RigAdapter, analysis_motion, normalize_rig
from .retarget import Proportions, onto_skeleton, proportions_differ, same_rig

__all__ = [
    "CMU_UNIT",
    "UNITS",
    "Z_TO_Y",
    "Proportions",
    "RigAdapter",
    "RigInfo",
    "Units",
    "describe_rig",
    "metres_per_unit",
    "analysis_motion",
    "normalize_rig",
    "onto_skeleton",
    "proportions_differ",
    "parse_units",
    "rig_summary",
    "same_rig",
]
