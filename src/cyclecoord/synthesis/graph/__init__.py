"""Motion graph and vector-field synthesis over a Delaunay complex (Gauch & Peters).

From a few training takes: a PCA space of the joint angles (:class:`PoseSpace`), a motion
graph over the training frames from a Delaunay triangulation, k nearest neighbours or
both (:func:`build_graph`), the interpolated field of the takes' velocities
(:class:`VectorField`; the Delaunay field optionally widened to the adjacent simplices and
weighted by agreement with the path's heading, ``"delaunay+ring+agree"``, which keeps the
2-D paths from stalling at a walk's cusps), paths that follow it or run to a target
along the graph (:func:`follow_field`, :func:`path_to_target`), a playable result with a
root trajectory (:class:`MotionGraphSynth`) and the paper's leave-one-out table
(:func:`cross_validate`).  Beyond the paper, ``"delaunay+phase"`` (what ``cyclecoord
graph`` generates with) follows a phase-aware field instead (:mod:`.phase`): the periodic
pipeline's circular coordinate gives every training frame a phase, so the path keeps
moving through the cusps where the paper's field stalls.
"""

from .build import METHODS, MotionGraph, build_graph, training_vectors
from .crossval import (
    DEFAULT_METHODS,
    HORIZON,
    PAPER,
    PAPER_W1,
    CrossValidation,
    bottleneck,
    cross_validate,
    h1_diagram,
    paper_set,
    path_errors,
)
from .field import FIELD_OPTIONS, VectorField, parse_variant
from .latent import PoseSpace, check_takes
from .model import Generation, MotionGraphSynth
from .paths import GraphPath, follow_field, path_to_target, root_trajectory, shortest_path

__all__ = [
    "DEFAULT_METHODS",
    "FIELD_OPTIONS",
    "METHODS",
    "HORIZON",
    "PAPER",
    "PAPER_W1",
    "paper_set",
    "CrossValidation",
    "Generation",
    "GraphPath",
    "MotionGraph",
    "MotionGraphSynth",
    "PoseSpace",
    "VectorField",
    "bottleneck",
    "build_graph",
    "check_takes",
    "cross_validate",
    "follow_field",
    "h1_diagram",
    "path_errors",
    "parse_variant",
    "path_to_target",
    "root_trajectory",
    "shortest_path",
    "training_vectors",
]
