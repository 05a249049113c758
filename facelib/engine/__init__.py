"""The deformation engine: a head mesh with its face definition, deformed by FAP streams.

``load_face()`` gives the default head; ``Face.deform(stream)`` gives vertex positions for
every frame. Rendering lives in ``facelib.engine.render`` (behind the ``render`` extra) and is
not imported here.
"""

from facelib.engine.definition import load_face, required_feature_points
from facelib.engine.face import PART_NAMES, Face, Part, Region
from facelib.engine.fapu import compute_fapu

__all__ = ["PART_NAMES", "Face", "Part", "Region", "compute_fapu", "load_face",
           "required_feature_points"]
