"""Shared fixtures for the tracking tests: the default head rendered neutral at 640x480."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest


@pytest.fixture(scope="session")
def default_head_render() -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """``(480, 640, 3) uint8`` RGB of the default head and its projected feature points
    (id -> ``(2,)`` pixels)."""
    if importlib.util.find_spec("pyrender") is None:
        pytest.skip("needs the render extra")
    from facelib.engine import default_face
    from facelib.rendering import FaceRenderer

    face = default_face()
    with FaceRenderer(face, width=640, height=480) as renderer:
        image = renderer.frame(face.vertices)
        ids = sorted(face.feature_points)
        proj = renderer.project(face.vertices[[face.feature_points[k] for k in ids]])
    return image, dict(zip(ids, proj, strict=True))
