"""Where a tracker's landmarks lie on a face mesh: one vertex per MediaPipe landmark.

Found by looking: the neutral face is rendered, MediaPipe tracks the render, and each
landmark takes the front-most mesh vertex that projects within a few pixels of it. The
result for facelib's default head is package data
(``facelib/data/tracking/default_head_mediapipe.json``), so tracking a video needs no
rendering; :func:`embed_landmarks` recomputes it for any face (needs the ``render`` and
``track`` extras).
"""

from __future__ import annotations

from functools import cache
from types import SimpleNamespace
from typing import cast

import numpy as np

from facelib.checks import check_number
from facelib.data import json_data
from facelib.data import path as data_path
from facelib.engine.face import ATTACHED_PARTS, OPTIONAL_PARTS
from facelib.errors import DataError, TrackingError
from facelib.mpeg4 import N_FAPS, FapStream
from facelib.rendering.protocols import Deformable
from facelib.tracking.mediapipe import N_LANDMARKS

__all__ = ["default_head_embedding", "embed_landmarks"]


def embed_landmarks(face: Deformable, *, open_jaw: float = 400.0, width: int = 640,
                    height: int = 480, radius: float = 3.0) -> np.ndarray:
    """``(478,) int64`` vertex id of each MediaPipe landmark on ``face``'s mesh.

    Parameters
    ----------
    face: a Face (``vertices``, ``triangles``, ``vertex_colors``, ``parts``, ``deform``).
    open_jaw: FAP 3 of the pose that is rendered and tracked: with the mouth open the inner
        lip landmarks of the upper and lower lip fall on different vertices (on a neutral
        mesh with closed lips they coincide).
    width, height: the render's size in pixels.
    radius: pixels; among the vertices projecting this close to a landmark, the one
        nearest the camera is taken (else the nearest projection).
    """
    from facelib.rendering import FaceRenderer
    from facelib.rendering.scene import framing_points
    from facelib.tracking.mediapipe import FaceMeshTracker

    radius = check_number("radius", radius, low=0, low_open=True)
    values = np.zeros(N_FAPS, np.float32)
    values[2] = check_number("open_jaw", open_jaw, low=0)
    vertices = np.asarray(face.deform(FapStream(25.0, values[None]))[0], np.float64)
    with FaceRenderer(_without_hair(face), width=width, height=height,  # framed with them
                      framing=framing_points(face, "head")) as renderer:
        image = renderer.frame(vertices)
        projected = renderer.project(vertices)
        camera = np.linalg.inv(renderer.camera_pose)
    with FaceMeshTracker(video=False) as tracker:
        found = tracker.detect(image)
    if found is None:
        raise TrackingError("MediaPipe finds no face on the rendered neutral mesh")
    depth = -(np.hstack([vertices, np.ones((len(vertices), 1))]) @ camera.T)[:, 2]
    parts = getattr(face, "parts", {}) or {}
    hair = [parts[p].vertex_ids for p in (*OPTIONAL_PARTS, *ATTACHED_PARTS) if p in parts]
    projected[np.concatenate([np.zeros(0, np.int64), *hair])] = np.inf  # no landmark there
    out = np.empty(N_LANDMARKS, np.int64)
    for i, point in enumerate(found.points[:, :2]):
        dist = np.linalg.norm(projected - point, axis=1)
        near = np.flatnonzero(dist < radius)
        out[i] = near[np.argmin(depth[near])] if near.size else int(np.argmin(dist))
    return out


def _without_hair(face: Deformable) -> Deformable:
    """``face`` as the renderer sees it, less its optional and attached parts (lashes, hair,
    bust): landmarks lie on the skin, and MediaPipe should see it unhidden."""
    parts = dict(getattr(face, "parts", {}) or {})
    hair = [parts.pop(p) for p in (*OPTIONAL_PARTS, *ATTACHED_PARTS) if p in parts]
    if not hair:
        return face
    drop = np.concatenate([h.vertex_ids for h in hair])
    triangles = np.asarray(face.triangles)
    keep = ~np.isin(triangles, drop).any(axis=1)
    return cast(Deformable, SimpleNamespace(
        vertices=face.vertices, triangles=triangles[keep],
        vertex_colors=getattr(face, "vertex_colors", None),
        vertex_ao=getattr(face, "vertex_ao", None),
        parts=parts, feature_points=getattr(face, "feature_points", {}), deform=face.deform))


@cache
def default_head_embedding() -> np.ndarray:
    """The packaged ``(478,) int64`` embedding of the MediaPipe landmarks on the default
    head (read-only)."""
    doc = json_data("tracking/default_head_mediapipe.json")
    ids = np.asarray(doc.get("vertices", []), np.int64)
    if ids.shape != (N_LANDMARKS,) or ids.min() < 0:
        raise DataError(f"needs {N_LANDMARKS} vertex ids >= 0",
                        path=str(data_path("tracking/default_head_mediapipe.json")))
    ids.flags.writeable = False
    return ids
