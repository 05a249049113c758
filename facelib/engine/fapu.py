"""Facial animation parameter units from a neutral face (thesis eq. 4.1-4.5)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from facelib.errors import FaceModelError
from facelib.mpeg4.tables import ANGLE_UNIT, FAPU_SCALE

__all__ = ["FAPU_FEATURE_POINTS", "compute_fapu"]

FAPU_FEATURE_POINTS = ("3.1", "3.3", "3.5", "3.6", "9.15", "2.2", "8.3", "8.4")
"""The feature points the five distance units are measured between."""


def compute_fapu(vertices: np.ndarray, feature_points: Mapping[str, int]) -> dict[str, float]:
    """The FAPU of a neutral face, in the mesh's length unit (AU in radians).

    ``IRISD0 = |3.1y - 3.3y|``, ``ES0 = |3.5x - 3.6x|``, ``ENS0 = |3.5y - 9.15y|``,
    ``MNS0 = |9.15y - 2.2y|``, ``MW0 = |8.3x - 8.4x|`` (eq. 4.1-4.5); each unit is its distance
    divided by 1024. ``AU`` is 1e-5 rad.

    Parameters
    ----------
    vertices: (V, 3) float, neutral positions.
    feature_points: feature point id -> vertex index.

    Returns
    -------
    ``{"IRISD", "ES", "ENS", "MNS", "MW", "AU"}`` -> float.
    """
    missing = [f for f in FAPU_FEATURE_POINTS if f not in feature_points]
    if missing:
        raise FaceModelError(f"FAPU needs feature points {', '.join(missing)}, which are missing")

    def p(fp: str) -> np.ndarray:
        return np.asarray(vertices[feature_points[fp]], dtype=np.float64)

    distances = {
        "IRISD": abs(p("3.1")[1] - p("3.3")[1]),
        "ES": abs(p("3.5")[0] - p("3.6")[0]),
        "ENS": abs(p("3.5")[1] - p("9.15")[1]),
        "MNS": abs(p("9.15")[1] - p("2.2")[1]),
        "MW": abs(p("8.3")[0] - p("8.4")[0]),
    }
    for name, value in distances.items():
        if not value > 0:
            raise FaceModelError(f"FAPU {name}0 is {value!r}: its feature points coincide")
    fapu = {name: float(value / FAPU_SCALE) for name, value in distances.items()}
    fapu["AU"] = ANGLE_UNIT
    return fapu
