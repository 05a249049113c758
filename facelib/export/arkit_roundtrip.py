"""How much of a stream the ARKit round trip (FapStream -> ARKit curves -> FapStream) keeps,
region by region of the face."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facelib.export.arkit import from_arkit, to_arkit
from facelib.export.source import Source, export_clip
from facelib.mpeg4.highlevel import apply_high_level
from facelib.mpeg4.stream import FapStream

__all__ = ["RegionResidual", "arkit_residuals"]

_HEAD = (47, 48, 49)  # columns of FAPs 48-50, the head rotation


@dataclass(frozen=True)
class RegionResidual:
    """One region's round-trip error on the default head.

    region: the face definition's region name (``upper_lip``, ``brow_l`` ...); vertices:
    how many vertices it has. residual_m: RMS over frames and the region's vertices of the
    distance (metres) between the stream's deformation and the round trip's; motion_m: RMS
    distance of the stream's deformation from the neutral face (the signal); relative:
    ``residual_m / motion_m`` (NaN where the region does not move).
    """

    region: str
    vertices: int
    residual_m: float
    motion_m: float

    @property
    def relative(self) -> float:
        return self.residual_m / self.motion_m if self.motion_m > 0 else float("nan")


def arkit_residuals(source: Source) -> tuple[RegionResidual, ...]:
    """Play ``source`` (a FapStream or animation) and its ARKit round trip
    (``from_arkit(to_arkit(source))``) on the default head and compare them per region
    (regions of learned fields, which overlap the named ones, are left out), in the face
    definition's region order. The head rotation (FAPs 48-50), which the curves carry
    exactly, is left out of both, so that ``motion_m`` is the face's own motion."""
    from facelib.engine import default_face

    played = apply_high_level(export_clip(source).stream)
    values = np.array(played.values)
    values[:, list(_HEAD)] = 0.0  # carried exactly; it would swamp the regions' motion
    stream = FapStream(played.fps, values, played.mask)
    face = default_face()
    sent, back = face.deform(stream), face.deform(from_arkit(to_arkit(stream)))
    error = np.linalg.norm(back - sent, axis=2)  # (n, V)
    motion = np.linalg.norm(sent - face.vertices, axis=2)
    out = []
    for region in face.regions:
        if region.deformer == "field":
            continue
        ids = np.asarray(region.vertices)
        out.append(RegionResidual(region.name, len(ids),
                                  float(np.sqrt(np.mean(error[:, ids] ** 2))),
                                  float(np.sqrt(np.mean(motion[:, ids] ** 2)))))
    return tuple(out)
