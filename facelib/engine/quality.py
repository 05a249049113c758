"""Mesh-quality metric: dihedral-angle roughness (Peña Araya 2012, section 3.2, after Wu et al.).

For two triangles A and B sharing an edge, the dihedral roughness is ``rho_d = 1 - nA . nB``
(eq. 3.2; 0 when coplanar, 2 when folded flat onto each other). For a vertex v, ``G(v)`` is the
mean of ``rho_d`` over the pairs of adjacent triangles around v and ``V(v)`` their variance.
A triangle's roughness is the variance-weighted mean of its corners (eq. 3.3)::

    rho(T) = (G(v1) V(v1) + G(v2) V(v2) + G(v3) V(v3)) / (V(v1) + V(v2) + V(v3))

Where the three variances are all zero (a flat or uniformly bent neighbourhood) the weighted
mean is taken in its limit of equal weights, ``mean(G)``. A zero-area triangle has a zero
normal, so each interior edge it shares scores ``rho_d = 1`` (a right angle); only edges with
exactly two triangles count (boundary and non-manifold edges are skipped). A smooth face
scores near 0; bumps, creases and folds raise it. The seed's test mesh scores 0 when flat,
and 0.255 / 0.512 on average with a small / large bump (tables 4.3-4.4).
"""

from __future__ import annotations

import numpy as np

from facelib.errors import ParameterError

__all__ = ["mean_roughness", "triangle_roughness", "vertex_roughness"]


def _check(vertices: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ParameterError(f"vertices must have shape (V, 3), got {v.shape}")
    if t.ndim != 2 or t.shape[1] != 3 or (t.size and (t.min() < 0 or t.max() >= len(v))):
        raise ParameterError(f"triangles must be (F, 3) indices into {len(v)} vertices")
    return v, t.astype(np.int64)


def _unit_normals(v: np.ndarray, t: np.ndarray) -> np.ndarray:
    n = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def vertex_roughness(vertices: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``G(v)`` and ``V(v)``: mean and variance of the dihedral roughness around each vertex.

    Parameters
    ----------
    vertices: (V, 3) float positions.
    triangles: (F, 3) int.

    Returns
    -------
    Two (V,) float64 arrays; vertices on no interior edge get 0 for both.
    """
    v, t = _check(vertices, triangles)
    normals = _unit_normals(v, t)
    edges = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    face = np.tile(np.arange(len(t)), 3)
    edges.sort(axis=1)
    order = np.lexsort((edges[:, 1], edges[:, 0]))
    edges, face = edges[order], face[order]
    same = np.all(edges[1:] == edges[:-1], axis=1)
    # interior edges: exactly two triangles (a run of length 2)
    start = np.flatnonzero(same)
    run_ok = np.ones(start.size, bool)
    run_ok &= ~np.isin(start - 1, start) & ~np.isin(start + 1, start)
    start = start[run_ok]
    rho = 1.0 - np.einsum("ij,ij->i", normals[face[start]], normals[face[start + 1]])
    ends = edges[start].reshape(-1)
    rho2 = np.repeat(rho, 2)
    count = np.bincount(ends, minlength=len(v)).astype(np.float64)
    total = np.bincount(ends, weights=rho2, minlength=len(v))
    total_sq = np.bincount(ends, weights=rho2**2, minlength=len(v))
    mean = np.divide(total, count, out=np.zeros(len(v)), where=count > 0)
    var = np.divide(total_sq, count, out=np.zeros(len(v)), where=count > 0) - mean**2
    return mean, np.maximum(var, 0.0)


def triangle_roughness(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Roughness ``rho(T)`` of every triangle (eq. 3.3): ``(F,) float64``, 0 for a flat mesh."""
    v, t = _check(vertices, triangles)
    g, var = vertex_roughness(v, t)
    gt, vt = g[t], var[t]
    weight = vt.sum(axis=1)
    weighted = np.divide((gt * vt).sum(axis=1), weight, out=np.zeros(len(t)), where=weight > 0)
    return np.where(weight > 1e-18, weighted, gt.mean(axis=1))


def mean_roughness(
    vertices: np.ndarray, triangles: np.ndarray, *, vertex_ids: np.ndarray | None = None
) -> float:
    """Mean triangle roughness over the mesh, or over the triangles whose three corners are all
    in ``vertex_ids`` (a region such as the lips). Neighbours outside the region still count in
    ``G`` and ``V``, so a region's border is measured as it is seen on the whole mesh.
    """
    v, t = _check(vertices, triangles)
    rho = triangle_roughness(v, t)
    if vertex_ids is not None:
        inside = np.zeros(len(v), bool)
        inside[np.asarray(vertex_ids, dtype=np.int64)] = True
        keep = inside[t].all(axis=1)
        if not keep.any():
            raise ParameterError("the region contains no whole triangle")
        rho = rho[keep]
    return float(rho.mean())
