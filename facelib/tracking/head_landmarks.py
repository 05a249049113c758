"""Automatic landmarks for face set-up: find the feature points of a head mesh by looking.

The mesh is rendered from the front with facelib's renderer, MediaPipe's face mesh finds
its 478 landmarks in the picture, the packaged table maps them to MPEG-4 feature points
(:mod:`facelib.tracking.layouts`), and a ray from the camera through each feature point's
pixel is cast back onto the mesh; the first hit is the landmark. The mesh's own shape
then corrects what a face model trained on people misplaces on other faces: eyelid points
snap onto their lid's rim and mouth corners into their fold (:func:`_settle`), and the
nose tip, lower lip and chin points are placed on the midline profile
(:mod:`facelib.tracking.profile`). The mesh is searched upright, looking along +z with +y
up (any unit): give the axes of one that is not.

Feature points whose MediaPipe position follows another convention than the default head's
(mid and outer brows 4.3-4.6 on the brow's upper edge, nostrils 9.1/9.2, 9.15) and the
inner lip points but 2.2 are left out (on closed lips they all fall on the one mouth line;
2.2 there pins the line where the lips part), as are the pupils when the mesh has no
eyeballs.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

import numpy as np

from facelib.engine.setup.headmesh import HeadMesh, axes_rotation
from facelib.errors import FaceModelError, TrackingError

__all__ = ["AUTO_EXCLUDED", "HeadLandmarks", "detect_head_landmarks", "draw_landmarks"]

AUTO_EXCLUDED = ("4.3", "4.4", "4.5", "4.6", "9.1", "9.2", "9.15",
                 "2.3", "2.4", "2.5", "2.6", "2.7", "2.8", "2.9")
"""Feature points the automatic landmarks leave out (see the module docstring)."""
_DOT = (40, 220, 80)
_HOLE_DEPTH = 0.08  # a hit this far (x the head's size) behind the median hit went through
_SKIN = (0.87, 0.68, 0.57)  # the default head's skin colour (sRGB), for uncoloured meshes
# eyelid points lie on the lid's rim: the way (image rows) from the opening to the lid
_LIDS = {"3.1": -1.0, "3.2": -1.0, "3.3": 1.0, "3.4": 1.0}
_WALK = 0.1  # how far (x the upper lid points' pixel distance) to walk toward the lid
_JUMP = 0.03  # a step whose hit comes this far forward (x their distance) crosses the rim
_CORNERS = ("8.3", "8.4")  # the mouth corners lie at the bottom of their fold
_STENCIL = 0.04  # radius (x the lid points' pixel distance) of the rays about a corner
_FOLD = 0.15  # a corner lies at most this far (x the lid points' distance) behind its hit


@dataclass(frozen=True, eq=False)
class HeadLandmarks:
    """What the automatic landmark search found.

    points: feature point id -> (3,) float64 position on the mesh (its unit).
    pixels: feature point id -> (2,) float64 (column, row) where MediaPipe put it.
    image: (H, W, 3) uint8 the front view that was searched.
    """

    points: dict[str, np.ndarray]
    pixels: dict[str, np.ndarray]
    image: np.ndarray

    def as_json(self) -> dict[str, list[float]]:
        """``{fp: [x, y, z]}`` for a landmark file."""
        return {k: [float(c) for c in v] for k, v in self.points.items()}


@dataclass(frozen=True, eq=False)
class _View:
    """The mesh as the renderer wants it (no parts: one piece)."""

    vertices: np.ndarray
    triangles: np.ndarray
    vertex_colors: np.ndarray
    parts: None = None


def _render(mesh: HeadMesh, size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Front view ``(size, size, 3) uint8``, the camera pose (4, 4) and projection (4, 4)."""
    from facelib.rendering.protocols import Deformable
    from facelib.rendering.scene import FaceRenderer

    colours = (np.tile(_SKIN, (len(mesh.vertices), 1)) if mesh.colors is None
               else mesh.colors)
    view = _View(mesh.vertices.astype(np.float32), mesh.triangles,
                 np.asarray(colours, np.float32))
    skin = mesh.vertices[mesh.parts["skin"]]
    # the renderer reads only vertices, triangles, vertex_colors and parts of a still face
    still = cast("Deformable", view)
    with FaceRenderer(still, width=size, height=size, framing=skin) as renderer:
        image = renderer.frame(view.vertices)
        camera = renderer.scene.main_camera_node.camera
        projection = camera.get_projection_matrix(size, size)
        return image, np.asarray(renderer.camera_pose, np.float64), projection


def _rays(pixels: np.ndarray, pose: np.ndarray, projection: np.ndarray, size: int
          ) -> tuple[np.ndarray, np.ndarray]:
    """Origins and unit directions ``(n, 3)`` of camera rays through ``pixels (n, 2)``."""
    ndc = np.c_[2 * pixels[:, 0] / size - 1, 1 - 2 * pixels[:, 1] / size]
    inverse = np.linalg.inv(projection @ np.linalg.inv(pose))
    ends = []
    for depth in (-1.0, 1.0):
        homo = np.c_[ndc, np.full(len(ndc), depth), np.ones(len(ndc))] @ inverse.T
        ends.append(homo[:, :3] / homo[:, 3:4])
    direction = ends[1] - ends[0]
    return ends[0], direction / np.linalg.norm(direction, axis=1, keepdims=True)


def _hits(mesh: HeadMesh, origins: np.ndarray, directions: np.ndarray, *,
          front: float | None = None) -> np.ndarray:
    """First hit of each ray on the mesh ``(n, 3)``; NaN where a ray misses.

    Moller-Trumbore against every triangle (a few dozen rays: ``n x F`` tests). front:
    the depth of the face's front (default: the median hit's), see :func:`_through_holes`.
    """
    corners = mesh.vertices[mesh.triangles]  # (F, 3, 3)
    a = corners[:, 0]
    e1, e2 = corners[:, 1] - a, corners[:, 2] - a
    out = np.full((len(origins), 3), np.nan)
    for k, (origin, direction) in enumerate(zip(origins, directions, strict=True)):
        p = np.cross(direction, e2)
        det = np.einsum("fc,fc->f", e1, p)
        ok = np.abs(det) > 1e-18
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        t_vec = origin - a
        u = np.einsum("fc,fc->f", t_vec, p) * inv
        q = np.cross(t_vec, e1)
        v = (q @ direction) * inv
        dist = np.einsum("fc,fc->f", e2, q) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (dist > 0)
        if hit.any():
            out[k] = origin + direction * dist[hit].min()
    return _through_holes(mesh, origins, directions, out, front=front)


def _through_holes(mesh: HeadMesh, origins: np.ndarray, directions: np.ndarray,
                   hits: np.ndarray, *, front: float | None = None) -> np.ndarray:
    """Rays that slip through an opening (eye sockets without eyeballs, under the chin)
    hit far behind the face's ``front`` (default: the median hit's depth): take the
    vertex nearest to such a ray instead, among those no deeper than that."""
    depth = np.einsum("nc,nc->n", hits - origins, directions)
    front = float(np.nanmedian(depth)) if front is None else front
    extent = float(np.ptp(mesh.vertices[mesh.parts["skin"]], axis=0).max())
    out = hits.copy()
    for k in np.flatnonzero(~(depth <= front + _HOLE_DEPTH * extent)):
        rel = mesh.vertices - origins[k]
        along = rel @ directions[k]
        off = np.linalg.norm(rel - along[:, None] * directions[k], axis=1)
        off[along > front + _HOLE_DEPTH * extent] = np.inf
        out[k] = mesh.vertices[int(np.argmin(off))]
    return out


def detect_head_landmarks(mesh: HeadMesh, *, up: str | None = None,
                          forward: str | None = None, size: int = 640,
                          feature_points: tuple[str, ...] | None = None) -> HeadLandmarks:
    """Find feature points on a head mesh (see the module docstring).

    up, forward: the mesh's axes ("+x" ... "-z", as for
        :func:`~facelib.engine.setup.headmesh.axes_rotation`) when it is not upright (+y up)
        looking along +z; the mesh is turned upright for the search and the points are given
        in the mesh's own frame, so they go with the same axes to ``setup_face(mesh,
        landmarks=found.as_json(), up=up, forward=forward)``. Default: upright.
    feature_points: the ids wanted (default: the default head's feature points); those in
        ``AUTO_EXCLUDED`` and the ones the MediaPipe table does not map are left out.

    Raises ParameterError for an unknown axis, FaceModelError when MediaPipe finds no face
    in the front view (the mesh is not upright and facing +z, or not a face) or too few
    rays hit the mesh.
    """
    from facelib.tracking.layouts import landmark_layout
    from facelib.tracking.mediapipe import detect_landmarks

    turn = None if up is None and forward is None else axes_rotation(up or "+y",
                                                                      forward or "+z")
    if turn is not None:
        mesh = mesh.rotated(turn)
    image, pose, projection = _render(mesh, size)
    try:
        found = detect_landmarks(image)
    except TrackingError as exc:
        raise FaceModelError(
            f"{mesh.name}: no face was found in the front view of the mesh ({exc.message}); "
            "turn the mesh upright (+y up) facing +z, or give landmarks by hand") from exc
    layout = landmark_layout("mediapipe")
    pixels = layout.feature_point_positions(found.points[None, :, :2])[0]
    wanted = [fp for fp in layout.feature_points if fp not in AUTO_EXCLUDED
              and (fp not in ("3.5", "3.6") or "eye_l" in mesh.parts)]
    if feature_points is None:
        from facelib.engine import default_face

        feature_points = tuple(default_face().feature_points)
    wanted = [fp for fp in wanted if fp in feature_points]
    rows = np.array([layout.index(fp) for fp in wanted])
    origins, directions = _rays(pixels[rows], pose, projection, size)
    hit = _hits(mesh, origins, directions)
    ok = np.isfinite(hit).all(axis=1)
    if ok.sum() < 4:
        raise FaceModelError(f"{mesh.name}: only {int(ok.sum())} feature points found on the "
                             "mesh; give landmarks by hand")
    front = float(np.nanmedian(np.einsum("nc,nc->n", hit - origins, directions)))
    points, where = _refined(
        mesh, {fp: hit[k] for k, fp in enumerate(wanted) if ok[k]},
        {fp: pixels[rows[k]] for k, fp in enumerate(wanted) if ok[k]},
        camera=(pose, projection, size), front=front)
    if turn is not None:  # back into the mesh's frame (a signed permutation: exact)
        points = {fp: turn.T @ point for fp, point in points.items()}
    return HeadLandmarks(points=points, pixels=where, image=image)


def _refined(mesh: HeadMesh, points: dict[str, np.ndarray], pixels: dict[str, np.ndarray],
             *, camera: tuple[np.ndarray, np.ndarray, int], front: float
             ) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """The points after :func:`_settle` and :func:`_on_profile`, and their pixels (those
    of the moved points projected again, so that the picture shows where they ended up)."""
    moved = _settle(mesh, pixels, points, camera=camera, front=front)
    moved.update(_on_profile(mesh, {**points, **moved}))
    where = dict(pixels)
    if moved:
        pose, projection, size = camera
        at = _project(np.array(list(moved.values())), pose, projection, size)
        where.update(zip(moved, at, strict=True))
    return {**points, **moved}, where


def _settle(mesh: HeadMesh, pixels: dict[str, np.ndarray], points: dict[str, np.ndarray],
            *, camera: tuple[np.ndarray, np.ndarray, int], front: float
            ) -> dict[str, np.ndarray]:
    """Eyelid points moved onto their lid's rim (:func:`_on_rims`) and mouth corners into
    their fold (:func:`_in_folds`); ``{}`` without both upper lid points, which set the
    scale. Rays through an opening (far behind the face's ``front``) do not count."""
    if not all(k in pixels for k in ("3.1", "3.2")):
        return {}
    spread = float(np.linalg.norm(pixels["3.1"] - pixels["3.2"]))
    size3d = float(np.linalg.norm(points["3.1"] - points["3.2"]))
    behind = front + _HOLE_DEPTH * float(np.ptp(mesh.vertices[mesh.parts["skin"]], axis=0).max())
    hit_at = functools.partial(_raw_hits, mesh, camera=camera, behind=behind)
    return {**_on_rims(hit_at, pixels, spread=spread, size3d=size3d),
            **_in_folds(hit_at, pixels, spread=spread, size3d=size3d)}


def _on_rims(hit_at: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
             pixels: dict[str, np.ndarray], *, spread: float, size3d: float
             ) -> dict[str, np.ndarray]:
    """Eyelid points on their lid's rim. A lid point's pixel may fall just inside the eye
    opening, where the ray meets the socket behind the lid: walking from it toward the lid
    (up for the upper lids, down for the lower ones, up to :data:`_WALK` of the lid points'
    pixel distance ``spread``), the first step whose hit comes forward by more than
    :data:`_JUMP` (x their distance ``size3d`` on the mesh) is the rim, and its hit the
    point. ``hit_at``: pixels ``(n, 2)`` -> hits ``(n, 3)`` and depths ``(n,)`` (NaN through
    an opening)."""
    out = {}
    for fp, way in _LIDS.items():
        if fp in pixels:
            steps = np.arange(0, int(np.ceil(_WALK * spread)) + 1)[:, None] * [0.0, way]
            hits, depth = hit_at(pixels[fp] + steps)
            depth = np.where(np.isnan(depth), np.inf, depth)  # through the opening
            with np.errstate(invalid="ignore"):
                jump = np.flatnonzero((depth[:-1] - depth[1:] > _JUMP * size3d)
                                      & np.isfinite(depth[1:]))
            if jump.size:
                out[fp] = hits[jump[-1] + 1]
    return out


def _in_folds(hit_at: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
              pixels: dict[str, np.ndarray], *, spread: float, size3d: float
              ) -> dict[str, np.ndarray]:
    """Mouth corners at the bottom of their fold. A corner's pixel may fall on the cheek in
    front of the fold: the deepest hit within :data:`_STENCIL` (x ``spread``, pixels) of
    its pixel, at most :data:`_FOLD` (x ``size3d``) behind the nearest, is the corner.
    ``hit_at`` as in :func:`_on_rims`."""
    radius = _STENCIL * spread
    grid = np.arange(-np.ceil(radius), np.ceil(radius) + 1)
    disc = np.array([(a, b) for a in grid for b in grid if a * a + b * b <= radius * radius])
    out = {}
    for fp in _CORNERS:
        if fp in pixels:
            hits, depth = hit_at(pixels[fp] + disc)
            if not np.isnan(depth).all():
                limit = float(np.nanmin(depth)) + _FOLD * size3d
                out[fp] = hits[int(np.nanargmax(np.where(depth <= limit, depth, np.nan)))]
    return out


def _raw_hits(mesh: HeadMesh, pixels: np.ndarray, *,
              camera: tuple[np.ndarray, np.ndarray, int], behind: float
              ) -> tuple[np.ndarray, np.ndarray]:
    """First hits ``(n, 3)`` of the rays through ``pixels (n, 2)`` and their depths ``(n,)``
    along the ray (NaN for a miss or a hit deeper than ``behind``)."""
    pose, projection, size = camera
    origins, directions = _rays(pixels, pose, projection, size)
    hits = _hits(mesh, origins, directions, front=np.inf)
    depth = np.einsum("nc,nc->n", hits - origins, directions)
    depth[~(depth <= behind)] = np.nan
    return hits, depth


def _on_profile(mesh: HeadMesh, points: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """The found points of :data:`~facelib.tracking.profile.PROFILE_POINTS` placed again
    from the mesh's midline profile (:mod:`facelib.tracking.profile`)."""
    from facelib.engine import default_face
    from facelib.tracking.profile import PROFILE_NEEDS, PROFILE_POINTS, profile_points

    wanted = [k for k in PROFILE_POINTS if k in points]
    if not wanted or not all(k in points for k in PROFILE_NEEDS):
        return {}
    src = default_face()
    source = (src.vertices.astype(np.float64), src.parts["skin"].triangles,
              {k: src.vertices[v].astype(np.float64) for k, v in src.feature_points.items()})
    placed = profile_points(mesh.vertices, mesh.triangles, points, source=source)
    return {k: placed[k] for k in wanted}


def _project(points: np.ndarray, pose: np.ndarray, projection: np.ndarray, size: int
             ) -> np.ndarray:
    """Pixels ``(n, 2)`` (column, row) of ``points (n, 3)`` (the inverse of :func:`_rays`)."""
    clip = np.c_[points, np.ones(len(points))] @ (projection @ np.linalg.inv(pose)).T
    ndc = clip[:, :2] / clip[:, 3:4]
    return np.c_[(ndc[:, 0] + 1) * size / 2, (1 - ndc[:, 1]) * size / 2]


def draw_landmarks(found: HeadLandmarks) -> np.ndarray:
    """The searched front view with the found feature points drawn: ``(H, W, 3) uint8``."""
    image = found.image.copy()
    height, width = image.shape[:2]
    for x, y in found.pixels.values():
        cx, cy = round(float(x)), round(float(y))
        image[max(cy - 2, 0):min(cy + 3, height), max(cx - 2, 0):min(cx + 3, width)] = _DOT
    return image
