"""The user's FAPU from a neutral frame of tracked points (first seed, eq. 4.12-4.15).

Points are in the face frame (``x`` to the face's left, ``y`` up, ``z`` toward the camera;
see :func:`facelib.tracking.faps.face_frame`), any length unit (pixels for video).

Eq. 4.12-4.15 fill in the FAPU points a tracker may lack. As printed, their ``y`` component
is half a *difference*; the intent is the midpoint (the eye centre between the lids, the
inner upper lip between the outer lip midpoints, the nose base between the nose tip and the
upper lip), which is what is implemented::

    FP3.5  = (FP3.1x, (FP3.1y + FP3.3y) / 2)      (4.12)
    FP3.6  = (FP3.2x, (FP3.2y + FP3.4y) / 2)      (4.13)
    FP2.2  = (FP8.1x, (FP8.1y + FP8.2y) / 2)      (4.14)
    FP9.15 = (FP9.3x, (FP9.3y + FP2.2y) / 2)      (4.15)

(``z``, when given, is the midpoint too.) Tracked points are never replaced.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from facelib.engine.fapu import FAPU_FEATURE_POINTS, compute_fapu
from facelib.errors import TrackingError

__all__ = ["FILL_INS", "complete_points", "user_fapu"]

FILL_INS = (("3.5", "3.1", "3.3"), ("3.6", "3.2", "3.4"), ("2.2", "8.1", "8.2"),
            ("9.15", "9.3", "2.2"))
"""(missing point, point giving x, second point of the midpoint) for eq. 4.12-4.15, in the
order they are applied (4.15 may use the 2.2 of 4.14)."""


def complete_points(points: Mapping[str, np.ndarray]) -> dict[str, np.ndarray]:
    """``points`` (feature point id -> ``(..., D)`` positions) plus the eq. 4.12-4.15 fill-ins
    for those of 3.5, 3.6, 2.2, 9.15 that are missing and computable."""
    out = {k: np.asarray(v, np.float64) for k, v in points.items()}
    for target, first, second in FILL_INS:
        if target in out or first not in out or second not in out:
            continue
        filled = (out[first] + out[second]) / 2
        filled[..., 0] = out[first][..., 0]
        out[target] = filled
    return out


def user_fapu(points: Mapping[str, np.ndarray],
              overrides: Mapping[str, float] | None = None) -> dict[str, float]:
    """The user's FAPU (eq. 4.1-4.5 on the completed neutral points), in the points' length
    unit per FAP unit (``AU`` in radians).

    Parameters
    ----------
    points: feature point id -> ``(2,)`` or ``(3,)`` neutral position.
    overrides: FAPU name -> value to use instead (e.g. ``{"MNS": 0.018}`` measured by hand),
        in the same unit.

    Raises
    ------
    TrackingError naming the feature points still missing after eq. 4.12-4.15.
    """
    full = complete_points(points)
    overrides = dict(overrides or {})
    missing = [fp for fp in FAPU_FEATURE_POINTS if fp not in full]
    if missing:
        raise TrackingError(
            f"the user's FAPU need feature points {', '.join(missing)} (or eq. 4.12-4.15 "
            "inputs 3.1/3.3, 3.2/3.4, 8.1/8.2, 9.3); they are not tracked"
        )
    ids = list(FAPU_FEATURE_POINTS)
    xyz = np.zeros((len(ids), 3))
    for row, fp in enumerate(ids):
        value = full[fp]
        xyz[row, : value.shape[-1]] = value
    try:
        fapu = compute_fapu(xyz, {fp: i for i, fp in enumerate(ids)})
    except Exception as exc:  # FaceModelError: coincident points on the neutral frame
        raise TrackingError(f"cannot measure the user's FAPU on the neutral frame: {exc}") from exc
    for name, given in overrides.items():
        if name not in fapu or not given > 0:
            raise TrackingError(f"bad FAPU override {name}={given!r}")
        fapu[name] = float(given)
    return fapu
