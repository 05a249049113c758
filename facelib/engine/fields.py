"""The ``field`` deformer: a displacement field learned from a face target (issue 14).

A face target (an ARKit blendshape, a scan of an action unit) says how every skin vertex
moves in one facial action. For the FAP that expresses that action the field is scaled so
that the FAP's feature point moves exactly ``value * FAPU`` along the FAP's direction
(eq. 4.6 holds in that component), while its other components and the rest of the skin move
as the target says: cheeks bunch in a smile, the lip corners go back in depth. The result is
linear in the FAP value, so it is one more block of the face's sparse operator.
"""

from __future__ import annotations

import numpy as np

from facelib.errors import FaceModelError

__all__ = ["MIN_ALONG", "field_weights"]

MIN_ALONG = 0.2
"""The least share of the feature point's motion in the target that must lie along the
FAP's direction; below it the scaled field would move the point mostly sideways."""


def field_weights(
    displacements: np.ndarray, point: int, direction: np.ndarray, fapu: float, *, name: str = ""
) -> np.ndarray:
    """Displacement of each member vertex per FAP unit.

    Parameters
    ----------
    displacements: (Vr, 3) float, the target's displacement of each member vertex (any
        length unit, any target weight: only the shape matters).
    point: row of the FAP's feature point in ``displacements``.
    direction: (3,) float, the FAP's direction (unit vector for translational FAPs).
    fapu: the FAP's unit in mesh units.
    name: the region's name, for error messages.

    Returns
    -------
    (Vr, 3) float64: ``displacements * fapu / (displacements[point] . direction)``, so row
    ``point`` projects on ``direction`` as exactly ``fapu``.

    Raises
    ------
    FaceModelError: the target does not move the feature point along the direction.
    """
    d = np.asarray(displacements, dtype=np.float64)
    u = np.asarray(direction, dtype=np.float64)
    along = float(d[point] @ u)
    size = float(np.linalg.norm(d[point]))
    if size == 0.0 or abs(along) < MIN_ALONG * size:
        raise FaceModelError(
            f"field region {name!r}: its feature point moves {size:.3g} in the target, "
            f"{along:.3g} of it along the FAP's direction (needs at least {MIN_ALONG:.0%})")
    return d * (fapu / along)
