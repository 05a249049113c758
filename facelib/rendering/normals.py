"""Smooth vertex normals of a rendered mesh, with the sparse operator reused per frame.

The renderer's own (float32, per frame) counterpart of ``facelib.engine.surface``'s: the
normal of a vertex is the area-weighted sum of its triangles' normals, one sparse product.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["normal_operator", "vertex_normals"]


def normal_operator(n_vertices: int, triangles: np.ndarray) -> sp.csr_matrix:
    """``(V, F)`` sparse incidence matrix: vertex normal = sum of its triangles' normals."""
    triangles = np.asarray(triangles, np.int64)
    rows = triangles.ravel()
    cols = np.repeat(np.arange(len(triangles)), 3)
    weights = np.ones(len(rows), np.float32)
    return sp.csr_matrix((weights, (rows, cols)), shape=(n_vertices, len(triangles)))


def vertex_normals(
    vertices: np.ndarray, triangles: np.ndarray, operator: sp.csr_matrix | None = None
) -> np.ndarray:
    """Smooth unit normals ``(V, 3) float32``: area-weighted mean of adjacent face normals.

    ``vertices`` ``(V, 3)``, ``triangles`` ``(F, 3)`` indices; pass ``operator`` from
    :func:`normal_operator` to reuse it across frames. Vertices of no triangle get ``+z``.
    """
    vertices = np.asarray(vertices, np.float32)
    triangles = np.asarray(triangles, np.int64)
    if operator is None:
        operator = normal_operator(len(vertices), triangles)
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    summed = operator @ np.cross(b - a, c - a)
    length = np.linalg.norm(summed, axis=1, keepdims=True)
    normals = np.where(length > 0, summed / np.maximum(length, 1e-30), (0.0, 0.0, 1.0))
    return normals.astype(np.float32)
