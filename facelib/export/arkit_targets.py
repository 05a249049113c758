"""The 52 ARKit shapes as morph targets of any face: each shape's FAP recipe, and the face
deformed by it.

A recipe is the FAP frame (84 values, FAP units) that plays one ARKit shape at weight 1:

* a ``shape`` blendshape: the FAPs that :func:`facelib.export.from_arkit` gives for that
  weight alone (the default head's least-squares map from its MakeHuman ARKit sculpts plus
  the learned correction);
* an eye look (``angle``): the eye yaw or pitch FAP at the angle of weight 1
  (``export/arkit.json`` ``eye_look_full_deg``);
* ``TongueOut``: the tongue-tip thrust (FAP 45) that puts the tip the full reach past the
  upper incisors.

FAPs are in face-relative units, so the same recipes play on every face (the default head or
an own head from face set-up); weights from :func:`facelib.export.to_arkit` played on these
targets give, frame by frame, what ``from_arkit(to_arkit(stream))`` plays on the face (the
targets are linear; the lid and eye rotations inside them are taken at weight 1).
"""

from __future__ import annotations

import numpy as np

from facelib import data
from facelib.engine import Face
from facelib.export.arkit import _THRUST, _basis, _correction, arkit_names

__all__ = ["arkit_recipes", "arkit_shape_targets", "arkit_target_names"]

# eye-look name -> (FAP number, sign of the FAP value that looks that way); yaw > 0 turns an
# eye toward +x (the face's left: out for the left eye), pitch > 0 looks down
_EYE_LOOK = {"EyeLookOutLeft": (23, 1), "EyeLookInLeft": (23, -1),
             "EyeLookDownLeft": (25, 1), "EyeLookUpLeft": (25, -1),
             "EyeLookInRight": (24, 1), "EyeLookOutRight": (24, -1),
             "EyeLookDownRight": (26, 1), "EyeLookUpRight": (26, -1)}


def arkit_target_names() -> tuple[str, ...]:
    """The 52 names as ARKit spells them (``eyeBlinkLeft`` ... ``tongueOut``, Apple's
    ``ARFaceAnchor.BlendShapeLocation`` values), in :func:`arkit_names` order."""
    return tuple(row["anny_target"] for _, row in data.csv_rows("export/arkit.csv"))


def arkit_recipes() -> np.ndarray:
    """``(52, 84) float32``: the FAP frame of each ARKit shape at weight 1 (module doc),
    rows in :func:`arkit_names` order."""
    face, basis = _basis(None)
    out = basis.to_faps.T.astype(np.float64) + _correction()
    au = face.fapu["AU"]
    full = data.json_data("export/arkit.json")["eye_look_full_deg"]
    names = arkit_names()
    for name, (number, sign) in _EYE_LOOK.items():
        angle = np.radians(full["horizontal"] if number in (23, 24) else full["vertical"])
        out[names.index(name), number - 1] = sign * angle / au
    rest, per_unit = basis.tongue
    reach = float(data.json_data("export/arkit.json")["tongue_out_reach_m"])
    if per_unit > 0:
        out[names.index("TongueOut"), _THRUST - 1] = max((reach - rest) / per_unit, 0.0)
    return out.astype(np.float32)


def arkit_shape_targets(face: Face) -> np.ndarray:
    """``(52, V, 3) float32`` displacements (the face's unit): ``face`` deformed by each
    recipe, minus its rest positions."""
    recipes = arkit_recipes()
    rest = face.vertices.astype(np.float32)
    return np.stack([face.deform_frame(r) - rest for r in recipes]).astype(np.float32)
