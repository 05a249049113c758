"""The control mesh of a region: a triangulation over its sources (feature points + anchors).

Peña Araya's deformers are driven by the triangles of a coarse control mesh (CANDIDE-3 in the
seed, section 1.2). facelib's regions name their feature points and static anchors, so the
control mesh is the Delaunay triangulation of those sources seen from the front (facelib's
face frame looks along +z). A best-fit plane would be wrong here: the lips and their anchors
wrap around the face, so their least-spread direction is vertical and a fit would look at
them from above, stacking the lips. Anchors move by zero,
which keeps the region's border still.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import Delaunay, cKDTree

from facelib.errors import FaceModelError

__all__ = ["ControlMesh", "control_mesh", "triangle_frames"]


@dataclass(frozen=True, eq=False)
class ControlMesh:
    """Sources and their triangles.

    sources: (S, 3) float64 rest positions, the region's controls first, then its anchors.
    triangles: (K, 3) int64 indices into ``sources``, counter-clockwise in the plane.
    axes: (3, 3) float64 rows: two in-plane unit axes and the plane normal.
    scale: float, the median length of the triangles' edges (mesh units).
    """

    sources: np.ndarray
    triangles: np.ndarray
    axes: np.ndarray
    scale: float

    def planar(self, points: np.ndarray) -> np.ndarray:
        """``(P, 3) -> (P, 2)`` coordinates in the control plane."""
        return np.asarray(points, np.float64) @ self.axes[:2].T

    def corner_distances(self, points: np.ndarray) -> np.ndarray:
        """``(P, K)`` distance from each point to the nearest corner of each triangle, the
        seed's distance to a control triangle (section 3.3)."""
        d = np.linalg.norm(points[:, None, :] - self.sources[None, :, :], axis=2)
        return d[:, self.triangles].min(axis=2)

    def barycentric(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Triangle of each point's projection and its barycentric coordinates there.

        Returns ``(P,) int64`` triangle index (the containing one, else the one whose least
        coordinate is largest), ``(P, 3)`` float64 coordinates in it (unclipped, summing to
        1) and ``(P,) bool`` whether the projection is inside that triangle.
        """
        flat = self.planar(points)
        corners = self.planar(self.sources)[self.triangles]  # (K, 3, 2)
        a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
        det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
        rel = flat[:, None, :] - a[None]
        l1 = (rel[..., 0] * (c[:, 1] - a[:, 1]) - rel[..., 1] * (c[:, 0] - a[:, 0])) / det
        l2 = ((b[:, 0] - a[:, 0]) * rel[..., 1] - (b[:, 1] - a[:, 1]) * rel[..., 0]) / det
        lam = np.stack([1 - l1 - l2, l1, l2], axis=2)  # (P, K, 3)
        worst = lam.min(axis=2)
        best = worst.argmax(axis=1)
        inside = worst[np.arange(len(flat)), best] >= -1e-12
        return best.astype(np.int64), lam[np.arange(len(flat)), best], inside


def control_mesh(controls: np.ndarray, anchors: np.ndarray, *,
                 view: tuple[float, float, float] = (0.0, 0.0, 1.0)) -> ControlMesh:
    """Delaunay triangulation of ``controls (N, 3)`` + ``anchors (A, 3)`` projected along
    ``view`` (the face's +z by default). Raises ``FaceModelError`` for fewer than three
    sources or a set that is collinear in that projection."""
    sources = np.concatenate([np.asarray(controls, np.float64),
                              np.asarray(anchors, np.float64).reshape(-1, 3)])
    if len(sources) < 3:
        raise FaceModelError("a control mesh needs at least three feature points or anchors")
    if len(cKDTree(sources).query_pairs(0.0)):
        raise FaceModelError("a control mesh's feature points and anchors must be distinct")
    normal = np.asarray(view, np.float64) / np.linalg.norm(view)
    helper = np.array([0.0, 1.0, 0.0]) if abs(normal[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, normal)
    u /= np.linalg.norm(u)
    axes = np.stack([u, np.cross(normal, u), normal])
    flat = sources @ axes[:2].T
    _, sv, _ = np.linalg.svd(flat - flat.mean(axis=0), full_matrices=False)
    if sv[1] <= 1e-9 * max(sv[0], 1e-300):
        raise FaceModelError("the feature points and anchors of a control mesh are collinear")
    tri = Delaunay(sources @ axes[:2].T)
    triangles = tri.simplices.astype(np.int64)
    edges = np.linalg.norm(sources[triangles] - sources[np.roll(triangles, 1, axis=1)], axis=2)
    # drop slivers on the hull (a Delaunay artefact, not a control triangle)
    area = np.linalg.norm(np.cross(sources[triangles[:, 1]] - sources[triangles[:, 0]],
                                   sources[triangles[:, 2]] - sources[triangles[:, 0]]), axis=1)
    keep = area > 1e-6 * edges.max(axis=1) ** 2
    triangles, edges = triangles[keep], edges[keep]
    return ControlMesh(sources, triangles, axes, float(np.median(edges)))


def triangle_frames(corners: np.ndarray) -> np.ndarray:
    """Frames ``rows(B - A, C - A, n)`` of triangles: ``(..., 3, 3) -> (..., 3, 3)``.

    ``corners[..., j, :]`` is corner j; ``n`` is the unit normal (eq. 2.5-2.8). Degenerate
    triangles get a zero normal (the frame is then singular).
    """
    e1 = corners[..., 1, :] - corners[..., 0, :]
    e2 = corners[..., 2, :] - corners[..., 0, :]
    n = np.cross(e1, e2)
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    n = np.divide(n, length, out=np.zeros_like(n), where=length > 0)
    return np.stack([e1, e2, n], axis=-2)
