"""The ``field`` deformer: a displacement field learned from a face target (issue 14).

A face target (an ARKit blendshape, a scan of an action unit) says how every skin vertex
moves in one facial action. For the FAP that expresses that action the field is scaled so
that the FAP's feature point moves exactly ``value * FAPU`` along the FAP's direction
(eq. 4.6 holds in that component), while its other components and the rest of the skin move
as the target says: cheeks bunch in a smile, the lip corners go back in depth. The result is
linear in the FAP value, so it is one more block of the face's sparse operator.

A ``field`` region names its FAP (``params: {"fap": ...}``) and drives that FAP alone: the
face's other regions do not respond to it (see :func:`facelib.engine.face`'s compile step),
and the field does not respond to the other FAPs that move the same feature point.
"""

from __future__ import annotations

import numpy as np

from facelib.engine.deformers.base import Deformer, RegionSetup
from facelib.errors import FacelibError, FaceModelError
from facelib.mpeg4.tables import fap

__all__ = ["DEFORMERS", "MIN_ALONG", "field_weights"]

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


def _field(setup: RegionSetup) -> np.ndarray:
    """Registry weights ``(Vr, 3, 1, 3)``: member ``v`` moves by ``D_v / (D_p . u)`` times
    the control's displacement along the FAP's direction ``u``."""
    try:
        info = fap(str(setup.params["fap"]))
    except FacelibError as exc:
        raise setup.fail(f"a field names the FAP it drives: {exc.message}") from exc
    if setup.controls.size != 1 or setup.displacements.shape != (setup.members.size, 3):
        raise setup.fail("a field has one feature point and one displacement per member")
    at = np.flatnonzero(setup.members == setup.controls[0])
    if at.size != 1:
        raise setup.fail(f"a field region must contain its feature point "
                         f"(vertex {int(setup.controls[0])})")
    u = np.asarray(info.direction, dtype=np.float64)
    per_unit = field_weights(setup.displacements, int(at[0]), u, 1.0, name=setup.name)
    return per_unit[:, :, None, None] * u[None, None, None, :]


DEFORMERS = (
    Deformer("field", _field, {"fap": ""},
             "a displacement field learned from a face target; drives one FAP alone",
             "issue 14: ARKit targets of the head, scaled so eq. 4.6 holds along the FAP",
             interpolating=False),
)
