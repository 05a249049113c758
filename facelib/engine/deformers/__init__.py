"""Deformers: how feature-point motion reaches a region's vertices.

:mod:`~facelib.engine.deformers.base` holds the types (:class:`RegionSetup`,
:class:`Deformer`, :class:`FrameStep`), :mod:`~facelib.engine.deformers.registry` the table
of built-in deformers and its look-ups; each algorithm family has its own module
(``linear``: raised cosine, explicit weights and the thesis's multiquadric; ``rbf``;
``interpolation``; ``frames`` on a ``control_mesh``; ``fields``).
"""

from facelib.engine.deformers.base import Deformer, FrameStep, RegionSetup
from facelib.engine.deformers.registry import (
    ALIASES,
    BUILTIN,
    deformer,
    deformer_names,
    registry,
)

__all__ = ["ALIASES", "BUILTIN", "Deformer", "FrameStep", "RegionSetup", "deformer",
           "deformer_names", "registry"]
