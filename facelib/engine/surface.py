"""Exact closest points on a triangle mesh, with a normal check (third seed, eq. 4.7).

Candidate triangles come from a :class:`scipy.spatial.cKDTree` over sample points of the
triangles (see :func:`closest_points` for why the search is exact); the point-triangle
distance is Ericson's region test (Real-Time Collision Detection, section 5.1.5). The normal
check skips triangles whose unit normal makes ``dot < min_cos`` with the query's normal, so
that a point on the upper lip is not matched to the lower lip 0.2 mm away.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from facelib.errors import FaceModelError

__all__ = [
    "Surface",
    "SurfacePoints",
    "closest_on_triangles",
    "closest_points",
    "segments_cross",
    "surface",
    "triangle_normals",
    "vertex_normals",
]



def triangle_normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Unit normals ``(F, 3)`` float64 (counter-clockwise = outside); 0 for degenerate ones."""
    v = np.asarray(vertices, dtype=np.float64)
    n = np.cross(v[triangles[:, 1]] - v[triangles[:, 0]], v[triangles[:, 2]] - v[triangles[:, 0]])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def vertex_normals(vertices: np.ndarray, triangles: np.ndarray, *,
                   unused: tuple[float, float, float] | None = None) -> np.ndarray:
    """Area-weighted unit vertex normals ``(V, 3)`` float64 (the one facelib computes).

    vertices: (V, 3) float positions; triangles: (F, 3) int, counter-clockwise = outside.
    Each vertex sums the unnormalised normals of its triangles (their length is twice the
    area). A vertex of no triangle (or whose sum is zero) gets 0, or ``unused`` when given
    (the renderer and the glTF export give ``(0, 0, 1)``).
    """
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    # summed corner by corner in triangle order (bincount adds in input order)
    corners, per_corner = t.T.ravel(), np.tile(n, (3, 1))
    out = np.stack([np.bincount(corners, per_corner[:, k], minlength=len(v)) for k in range(3)],
                   axis=1)
    length = np.linalg.norm(out, axis=1, keepdims=True)
    fill = np.zeros(3) if unused is None else np.asarray(unused, np.float64)
    return np.where(length > 0, out / np.where(length > 0, length, 1.0), fill)


@dataclass(frozen=True, eq=False)
class Surface:
    """A triangle mesh prepared for closest-point queries.

    vertices: (V, 3) float64. triangles: (F, 3) int64. normals: (F, 3) float64 unit.
    tree: cKDTree over S sample points (the vertices, and a grid on large triangles).
    indptr: (S + 1,) int64 and triangle_of: int64, the triangles of each sample (CSR).
    radius: every point of a triangle is within this distance of one of its samples.
    centroids: (F, 3) float64; sizes: (F,) float64 largest centroid-to-corner distances.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    normals: np.ndarray
    tree: cKDTree
    indptr: np.ndarray
    triangle_of: np.ndarray
    radius: float
    centroids: np.ndarray
    sizes: np.ndarray

    @property
    def corners(self) -> np.ndarray:
        """(F, 3, 3) float64 corner positions."""
        return self.vertices[self.triangles]


@dataclass(frozen=True, eq=False)
class SurfacePoints:
    """Closest points of queries on a :class:`Surface`.

    points: (m, 3) float64. triangle: (m,) int64 triangle index. barycentric: (m, 3)
    float64 weights of its corners (sum 1). distance: (m,) float64.
    """

    points: np.ndarray
    triangle: np.ndarray
    barycentric: np.ndarray
    distance: np.ndarray

    def interpolate(self, surf: Surface, values: np.ndarray) -> np.ndarray:
        """Barycentric interpolation of per-vertex ``values (V, ...)`` at the points."""
        corners = surf.triangles[self.triangle]  # (m, 3)
        vals = np.asarray(values)[corners]  # (m, 3, ...)
        w = self.barycentric.reshape(self.barycentric.shape + (1,) * (vals.ndim - 2))
        return np.sum(vals * w, axis=1)


def surface(vertices: np.ndarray, triangles: np.ndarray) -> Surface:
    """Prepare ``vertices (V, 3)``, ``triangles (F, 3)`` for :func:`closest_points`.

    Samples are the vertices plus, on triangles longer than half the median edge, a
    barycentric grid fine enough that every point of a triangle is within ``radius`` of
    one of its own samples.
    """
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles, dtype=np.int64)
    if not len(t):
        raise FaceModelError("a surface needs at least one triangle")
    corners = v[t]
    longest = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    spacing = max(float(np.median(longest)) / 2, 1e-12)
    steps = np.clip(np.ceil(longest / spacing), 1, 64).astype(np.int64)
    # sample -> triangles (CSR): each vertex to the triangles around it, grid points to theirs
    owner_rows = [np.repeat(t.ravel(), 1)]
    owner_tris = [np.repeat(np.arange(len(t)), 3)]
    samples = [v]
    count = len(v)
    for n in np.unique(steps[steps > 1]):
        which = np.flatnonzero(steps == n)
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        keep = (i + j <= n) & ~((i == n) | (j == n) | (i + j == 0))
        bary = np.stack([i[keep], j[keep], n - i[keep] - j[keep]], axis=1) / n  # (G, 3)
        grid = np.einsum("gk,fkc->fgc", bary, corners[which]).reshape(-1, 3)
        samples.append(grid)
        owner_rows.append(count + np.arange(len(grid)))
        owner_tris.append(np.repeat(which, len(bary)))
        count += len(grid)
    rows, tris = np.concatenate(owner_rows), np.concatenate(owner_tris)
    order = np.argsort(rows, kind="stable")
    indptr = np.concatenate([[0], np.cumsum(np.bincount(rows, minlength=count))])
    radius = float((longest / steps).max())
    centroids = corners.mean(axis=1)
    sizes = np.linalg.norm(corners - centroids[:, None], axis=2).max(axis=1)
    return Surface(v, t, triangle_normals(v, t), cKDTree(np.concatenate(samples)),
                   indptr, tris[order], radius, centroids, sizes)


def closest_points(surf: Surface, points: np.ndarray, *, normals: np.ndarray | None = None,
                   min_cos: float = 0.5) -> SurfacePoints:
    """The exact closest point of each query on the surface.

    points: (m, 3). normals: optional (m, 3) unit normals of the queries; triangles facing
    another way (``dot < min_cos``) are skipped, and a query that no triangle passes falls
    back to the unchecked closest point.

    A triangle within distance ``d`` of a query has one of its samples within
    ``d + radius``. ``d`` starts at the distance of the nearest sample (a point of the
    surface, so no closer than the answer) and grows to the best admissible distance found
    when that is farther, so the search is exact.
    """
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    m = len(pts)
    best_d = np.full(m, np.inf)
    best_t = np.zeros(m, np.int64)
    best_p = np.zeros((m, 3))
    reach, _ = surf.tree.query(pts)
    limit = reach.max() + 2 * float(np.linalg.norm(np.ptp(surf.vertices, axis=0)))
    todo = np.arange(m)
    while todo.size:
        row, tri = _candidates(surf, pts[todo], reach[todo] + surf.radius)
        q = todo[row]
        found_p = closest_on_triangles(surf.corners[tri], pts[q])
        found_d = np.linalg.norm(found_p - pts[q], axis=1)
        if normals is not None:
            ok = _dot(surf.normals[tri], normals[q]) >= min_cos
            found_d = np.where(ok, found_d, np.inf)
        order = np.lexsort((found_d, q))
        first = order[np.r_[True, q[order][1:] != q[order][:-1]]]
        win = first[found_d[first] < best_d[q[first]]]
        best_d[q[win]], best_t[q[win]], best_p[q[win]] = found_d[win], tri[win], found_p[win]
        grow = todo[(best_d[todo] > reach[todo]) & (reach[todo] < limit)]
        reach[grow] = np.where(np.isfinite(best_d[grow]), best_d[grow],
                               2 * reach[grow] + surf.radius)
        todo = grow
    lost = ~np.isfinite(best_d)
    if lost.any():  # nothing faces the query's way: take the plain closest point
        fallback = closest_points(surf, pts[lost])
        best_p[lost], best_t[lost], best_d[lost] = (fallback.points, fallback.triangle,
                                                    fallback.distance)
    bary = barycentric(surf.corners[best_t], best_p)
    return SurfacePoints(best_p, best_t, bary, best_d)


def _candidates(surf: Surface, pts: np.ndarray, radius: np.ndarray) -> tuple[np.ndarray,
                                                                          np.ndarray]:
    """(query row, triangle) pairs: the triangles of every sample within ``radius``."""
    hits = surf.tree.query_ball_point(pts, radius, return_sorted=False)
    per_row = np.fromiter(map(len, hits), np.int64, len(hits))
    samples = np.fromiter(itertools.chain.from_iterable(hits), np.int64, int(per_row.sum()))
    starts = surf.indptr[samples]
    counts = surf.indptr[samples + 1] - starts
    rows = np.repeat(np.repeat(np.arange(len(hits)), per_row), counts)
    offsets = np.repeat(starts - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts)
    tris = surf.triangle_of[offsets + np.arange(int(counts.sum()))]
    # no point of a triangle is nearer than its centroid's distance minus its size
    gap = np.linalg.norm(pts[rows] - surf.centroids[tris], axis=1) - surf.sizes[tris]
    keep = gap <= radius[rows] - surf.radius
    n_tri = len(surf.triangles)
    pairs = np.unique(rows[keep] * n_tri + tris[keep])  # found through each corner
    return pairs // n_tri, pairs % n_tri


def closest_on_triangles(corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Closest point of each triangle to each point (Ericson's region test, vectorised).

    corners: (..., 3, 3) triangle corners a, b, c. points: (..., 3). Returns (..., 3).
    """
    a, b, c = corners[..., 0, :], corners[..., 1, :], corners[..., 2, :]
    ab, ac, ap = b - a, c - a, points - a
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    bp, cp = points - b, points - c
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    denom = va + vb + vc
    with np.errstate(divide="ignore", invalid="ignore"):
        v = vb / denom
        w = vc / denom
        out = a + ab * v[..., None] + ac * w[..., None]  # inside the face
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        # edges, then corners: later assignments win, matching the region tests' order
        edge_bc = (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)
        out = np.where(edge_bc[..., None], b + (c - b) * t_bc[..., None], out)
        edge_ac = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
        out = np.where(edge_ac[..., None], a + ac * t_ac[..., None], out)
        edge_ab = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
        out = np.where(edge_ab[..., None], a + ab * t_ab[..., None], out)
    out = np.where(((d6 >= 0) & (d5 <= d6))[..., None], c, out)
    out = np.where(((d3 >= 0) & (d4 <= d3))[..., None], b, out)
    out = np.where(((d1 <= 0) & (d2 <= 0))[..., None], a, out)
    bad = ~np.isfinite(out).all(axis=-1)  # degenerate triangles: nearest corner
    if bad.any():
        tri = corners[bad]
        near = np.argmin(np.linalg.norm(tri - points[bad][:, None], axis=2), axis=1)
        out[bad] = tri[np.arange(len(tri)), near]
    return out


def segments_cross(starts: np.ndarray, ends: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Which segments pass through a triangle (Moller-Trumbore, vectorised).

    starts, ends: (S, 3) segment ends. corners: (F, 3, 3) triangle corners. Returns (S,)
    bool; a segment that only touches a triangle at its start does not count (a lash whose
    root sits on the skin), one that ends on it does. Memory: S x F x 3 floats.
    """
    starts, ends = np.asarray(starts, np.float64), np.asarray(ends, np.float64)
    corners = np.asarray(corners, np.float64)
    a, e1, e2 = corners[:, 0], corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    d = ends - starts
    h = np.cross(d[:, None], e2[None])
    det = _dot(h, e1[None])
    ok = np.abs(det) > 1e-18
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = starts[:, None] - a[None]
    u = _dot(s, h) * inv
    q = np.cross(s, e1[None])
    v = _dot(d[:, None], q) * inv
    t = _dot(q, e2[None]) * inv
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6) & (t <= 1)
    return np.asarray(hit.any(axis=1))


def _dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.einsum("...c,...c->...", x, y)


def barycentric(corners: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Barycentric weights ``(m, 3)`` of points ``(m, 3)`` in triangles ``(m, 3, 3)``.

    Points off the plane get the weights of their projection; a degenerate triangle gives
    all weight to its first corner.
    """
    a = corners[:, 0]
    e1, e2, p = corners[:, 1] - a, corners[:, 2] - a, points - a
    d00, d01, d11 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
    d20, d21 = _dot(p, e1), _dot(p, e2)
    denom = d00 * d11 - d01 * d01
    ok = denom > 1e-300
    safe = np.where(ok, denom, 1.0)
    v = np.where(ok, (d11 * d20 - d01 * d21) / safe, 0.0)
    w = np.where(ok, (d00 * d21 - d01 * d20) / safe, 0.0)
    return np.stack([1.0 - v - w, v, w], axis=1)
