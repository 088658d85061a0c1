"""Latent-space synthesis after Bailey et al., "Repurposing hand animation for interactive
applications".

One GPLVM per kind of motion (:mod:`.model`, :mod:`.gplvm`, :mod:`.influence`), a particle
steered through a model's latent space (:mod:`.particle`), bridges between models
(:mod:`.bridges`), commands (:mod:`.commands`) and JSON scripts of them (:mod:`.script`).
"""

from .bridges import Bridges, find_bridges, invert, project
from .commands import CommandGraph, Synthesizer
from .gplvm import GPLVM
from .model import LatentModel
from .particle import ParticleParams, RandomForce, simulate

__all__ = [
    "GPLVM",
    "Bridges",
    "CommandGraph",
    "LatentModel",
    "ParticleParams",
    "RandomForce",
    "Synthesizer",
    "find_bridges",
    "invert",
    "project",
    "simulate",
]
