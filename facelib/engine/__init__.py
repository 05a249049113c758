"""The deformation engine: a head mesh with its face definition, deformed by FAP streams.

``load_face()`` gives the default head; ``Face.deform(stream)`` gives vertex positions for
every frame. Rendering lives in :mod:`facelib.rendering` (behind the ``render`` extra).
"""

from facelib.engine.definition import (
    default_face,
    hair_style_names,
    load_face,
    required_feature_points,
)
from facelib.engine.face import ATTACHED_PARTS, OPTIONAL_PARTS, PART_NAMES, Face, Part, Region
from facelib.engine.fapu import compute_fapu

__all__ = ["ATTACHED_PARTS", "OPTIONAL_PARTS", "PART_NAMES", "Face", "Part", "Region",
           "compute_fapu", "default_face", "hair_style_names", "load_face",
           "required_feature_points"]
