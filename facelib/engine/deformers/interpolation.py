"""Linear interpolation deformers of Peña Araya (2012), the second seed.

Every deformer here weighs the region's *sources* (its feature points, then its static
anchors) and returns the feature-point columns, since anchors move by zero:

- ``inverse_distance`` (Point Distance, eq. 3.4 with the weights of eq. 2.5-2.6);
- ``feature_point`` (Kshirsagar's geometric interpolation, eq. 2.1-2.4, surface distances);
- ``barycentric`` (Cerda's barycentric interpolation, eq. 1.1-1.2 and 2.22-2.23, over the
  region's control mesh).

All are linear in the control displacements, so they compile into the face's operator.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra

from facelib.engine.deformers.base import Deformer, RegionSetup
from facelib.engine.deformers.control_mesh import control_mesh

__all__ = ["DEFORMERS", "barycentric_weights", "feature_point_weights",
           "inverse_distance_weights", "kshirsagar_weight"]


def _spacing(sources: np.ndarray) -> float:
    """Median distance from a source to its nearest other source (the unit of distances)."""
    d = np.linalg.norm(sources[:, None] - sources[None], axis=2)
    np.fill_diagonal(d, np.inf)
    return float(np.median(d.min(axis=1)))


def inverse_distance_weights(
    members: np.ndarray, sources: np.ndarray, *, exponent: float = 2.0,
    scale: float | None = None, nearest: int | None = None, radius: float | None = None,
) -> np.ndarray:
    """Point Distance weights (eq. 3.4 on displacements; eq. 2.5-2.6).

    ``w_k = 1 / (1 + (d_k / scale)^exponent)`` for the source distances ``d_k``, kept for the
    ``nearest`` closest sources (variant G: 3) or all (variant H), and for ``d_k <= radius *
    scale`` when a radius is given, then normalised per row. A source's own weight is
    ``1 / (1 + 0) = 1`` before normalisation but others stay positive, so the scheme does
    *not* interpolate: a control vertex moves by less than its control.

    Parameters
    ----------
    members: (Vr, 3) float rest positions; sources: (S, 3) float rest positions.
    exponent: the seed's ``local`` (> 0; the seed gives no value).
    scale: the distance unit; None takes the median source spacing (unit-free).
    nearest: keep only this many closest sources; None keeps all.
    radius: cut-off in units of ``scale``; None for none. The nearest source is always kept.

    Returns
    -------
    (Vr, S) float64, rows summing to 1.
    """
    sources = np.asarray(sources, np.float64)
    d = np.linalg.norm(np.asarray(members, np.float64)[:, None] - sources[None], axis=2)
    unit = _spacing(sources) if scale is None else float(scale)
    w = 1.0 / (1.0 + (d / unit) ** float(exponent))
    order = np.argsort(d, axis=1)
    rank = np.empty_like(order)
    np.put_along_axis(rank, order, np.arange(d.shape[1])[None].repeat(len(d), 0), axis=1)
    keep = np.ones(d.shape, bool)
    if nearest is not None:
        keep &= rank < int(nearest)
    if radius is not None:
        keep &= d <= float(radius) * unit
    keep |= rank == 0
    w = np.where(keep, w, 0.0)
    return w / w.sum(axis=1, keepdims=True)


def kshirsagar_weight(distance: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """``W = sin(pi/2 (1 - d / d_bar))`` of eq. 2.1-2.2, clamped to [0, 1]: 1 at the control,
    0 at ``d_bar`` and beyond (the printed formula turns negative there)."""
    ratio = np.divide(distance, reach, out=np.full(np.shape(distance), np.inf),
                      where=np.asarray(reach) > 0)
    return np.clip(np.sin(0.5 * np.pi * (1.0 - np.clip(ratio, 0.0, 1.0))), 0.0, 1.0)


def _surface_distances(setup: RegionSetup, nodes: np.ndarray, sources: np.ndarray
                       ) -> np.ndarray:
    """``(S, n)`` shortest-path lengths over the mesh edges among ``nodes`` (the region's
    members and sources), from each source; inf where no path stays inside."""
    pos = setup.vertices
    local = np.full(len(pos), -1, np.int64)
    local[nodes] = np.arange(nodes.size)
    tri = local[setup.triangles]
    tri = tri[(tri >= 0).all(axis=1)]
    a = np.concatenate([tri[:, 0], tri[:, 1], tri[:, 2]])
    b = np.concatenate([tri[:, 1], tri[:, 2], tri[:, 0]])
    length = np.linalg.norm(pos[nodes[a]] - pos[nodes[b]], axis=1)
    graph = sp.coo_array((length, (a, b)), shape=(nodes.size, nodes.size)).tocsr()
    return dijkstra(graph, directed=False, indices=local[sources])


def feature_point_weights(setup: RegionSetup) -> np.ndarray:
    """Kshirsagar's geometric interpolation (eq. 2.1-2.4) over surface distances.

    Zones grow over the surface from every source; sources whose zones touch are neighbours.
    Seen from a vertex P, source i has the reach ``d_bar_i`` of eq. 2.3: the cosine-weighted
    mean of its surface distances to the two neighbours at the smallest angles (at i,
    between i->P and i->j) below pi/2. Its weight is ``W_i`` of eq. 2.1 and ``M[P, i] = (W_i /
    d_i^2) / sum_j (W_j / d_j^2)`` (eq. 2.4); at ``d_i = 0`` the row is ``e_i``.

    ``influences`` (a parameter) picks the sources that act on P: ``"zones"`` (default,
    Kshirsagar's original) every source whose reach covers P; ``"nearest"`` (the seed's
    implementation, section 3.3) P's nearest source and that source's two chosen neighbours.
    Returns (Vr, S) over all sources; a vertex beyond every reach follows its nearest source.
    """
    mode = setup.params.get("influences", "zones")
    if mode not in ("zones", "nearest"):
        raise setup.fail(f"feature_point influences must be 'zones' or 'nearest', got {mode!r}")
    sources = np.concatenate([setup.controls, setup.anchors])
    nodes = np.unique(np.concatenate([setup.members, sources]))
    dist = _surface_distances(setup, nodes, sources)  # (S, n)
    zone = dist.argmin(axis=0)  # nearest source of every node
    neighbours = _zone_neighbours(setup, nodes, zone, sources.size)
    d_src = dist[:, np.searchsorted(nodes, sources)]  # (S, S) surface distances
    local = np.searchsorted(nodes, setup.members)
    d = dist[:, local].T  # (Vr, S)
    members = setup.vertices[setup.members]
    src = setup.vertices[sources]
    reach = np.zeros_like(d)
    acting = np.zeros(d.shape, bool)
    first = zone[local]
    for i in range(sources.size):
        reach[:, i], chosen = _reach_all(members, i, neighbours[i], src, d_src)
        if mode == "nearest":
            mine = first == i
            acting[mine, i] = True
            for column in chosen.T:
                ok = mine & (column >= 0)
                acting[ok, column[ok]] = True
    if mode == "zones":
        acting = np.isfinite(d)
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.where(acting, kshirsagar_weight(d, reach) / d**2, 0.0)
    total = w.sum(axis=1)
    rows = np.arange(len(d))
    out = np.zeros_like(d)
    good = np.isfinite(total) & (total > 0) & (d[rows, first] > 0)
    out[good] = w[good] / total[good, None]
    out[~good, first[~good]] = 1.0  # on a source (d = 0: e_i), or beyond every reach
    return out


def _reach_all(members: np.ndarray, i: int, candidates: np.ndarray, src: np.ndarray,
               d_src: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``d_bar`` of eq. 2.3 for source i seen from every member, and the two neighbours
    chosen for each (``(Vr,)`` float64, ``(Vr, 2)`` int64, -1 where none). With no neighbour
    below pi/2 the reach is the nearest neighbour's distance (eq. 2.3 is undefined there)."""
    n = len(members)
    finite = d_src[i, candidates][np.isfinite(d_src[i, candidates])] if candidates.size else []
    fallback = float(np.min(finite)) if len(finite) else 0.0
    if not candidates.size:
        return np.full(n, fallback), np.full((n, 2), -1, np.int64)
    to_p = members - src[i]
    to_j = src[candidates] - src[i]
    norm = np.linalg.norm(to_p, axis=1)[:, None] * np.linalg.norm(to_j, axis=1)[None, :]
    cos = np.divide(to_p @ to_j.T, norm, out=np.zeros((n, candidates.size)), where=norm > 0)
    theta = np.arccos(np.clip(cos, -1.0, 1.0))
    order = np.argsort(theta, axis=1, kind="stable")[:, :2]
    picked = np.take_along_axis(theta, order, axis=1)
    valid = picked < 0.5 * np.pi
    weight = np.where(valid, np.cos(picked), 0.0)
    dist = d_src[i, candidates[order]]
    with np.errstate(invalid="ignore"):
        total = np.where(valid, dist * weight, 0.0).sum(axis=1)
    norm_w = weight.sum(axis=1)
    reach = np.divide(total, norm_w, out=np.full(n, fallback), where=norm_w > 0)
    chosen = np.where(valid, candidates[order], -1)
    return reach, chosen


def _zone_neighbours(setup: RegionSetup, nodes: np.ndarray, zone: np.ndarray, n: int
                     ) -> list[np.ndarray]:
    local = np.full(len(setup.vertices), -1, np.int64)
    local[nodes] = np.arange(nodes.size)
    tri = local[setup.triangles]
    tri = tri[(tri >= 0).all(axis=1)]
    pairs = np.concatenate([zone[tri[:, [0, 1]]], zone[tri[:, [1, 2]]], zone[tri[:, [2, 0]]]])
    pairs = pairs[pairs[:, 0] != pairs[:, 1]]
    adjacency = np.zeros((n, n), bool)
    adjacency[pairs[:, 0], pairs[:, 1]] = adjacency[pairs[:, 1], pairs[:, 0]] = True
    return [np.flatnonzero(adjacency[i]) for i in range(n)]


def barycentric_weights(setup: RegionSetup) -> np.ndarray:
    """Barycentric interpolation over the region's control mesh (eq. 1.1, 2.22-2.23).

    A member whose projection falls inside a control triangle takes its barycentric
    coordinates there. Outside, ``outside`` picks the seed's variant: ``"exponential"``
    (eq. 1.2 on displacements, normalised: ``w_j ~ exp(-|P - C_j| / alpha^2)`` over the
    nearest triangle's corners; Barycentrics 1 / Renato 2), ``"absolute"`` (``|mu|``
    normalised; Renato 1) or ``"extrapolate"`` (eq. 2.22-2.23 everywhere; Barycentrics 2).
    ``alpha2`` is ``alpha^2`` in units of the control mesh's median edge. Returns (Vr, S).
    """
    mode = setup.params["outside"]
    if mode not in ("exponential", "absolute", "extrapolate"):
        raise setup.fail(f"barycentric outside must be 'exponential', 'absolute' or "
                         f"'extrapolate', got {mode!r}")
    pos = setup.vertices
    mesh = control_mesh(pos[setup.controls], pos[setup.anchors])
    members = pos[setup.members]
    index, lam, inside = mesh.barycentric(members)
    out = np.zeros((setup.members.size, len(mesh.sources)))
    rows = np.flatnonzero(inside)
    np.add.at(out, (rows[:, None], mesh.triangles[index[rows]]), lam[rows])
    outside = np.flatnonzero(~inside)
    if not outside.size:
        return out
    nearest = mesh.corner_distances(members[outside]).argmin(axis=1)
    corners = mesh.triangles[nearest]
    if mode == "exponential":
        d = np.linalg.norm(members[outside][:, None] - mesh.sources[corners], axis=2)
        alpha2 = float(setup.params["alpha2"]) * mesh.scale
        w = np.exp(-(d - d.min(axis=1, keepdims=True)) / alpha2)
    else:
        w = np.abs(lam[outside]) if mode == "absolute" else lam[outside]
        corners = mesh.triangles[index[outside]]
    np.add.at(out, (outside[:, None], corners), w / w.sum(axis=1, keepdims=True))
    return out


def _controls_only(weights: np.ndarray, setup: RegionSetup) -> np.ndarray:
    return weights[:, : setup.controls.size]


def _inverse_distance(setup: RegionSetup) -> np.ndarray:
    p = setup.params
    pos = setup.vertices
    sources = pos[np.concatenate([setup.controls, setup.anchors])]
    w = inverse_distance_weights(pos[setup.members], sources, exponent=p["exponent"],
                                 scale=p["scale"], nearest=p["nearest"], radius=p["radius"])
    return _controls_only(w, setup)


DEFORMERS = (
    Deformer(
        "inverse_distance", _inverse_distance,
        {"exponent": 2.0, "scale": None, "nearest": None, "radius": None},
        "Point Distance: normalised 1/(1 + d^p) weights of the sources (not interpolating)",
        "second seed eq. 3.4 with eq. 2.5-2.6", interpolating=False),
    Deformer(
        "feature_point", lambda s: _controls_only(feature_point_weights(s), s),
        {"influences": "zones"},
        "Kshirsagar's geometric interpolation over surface distances",
        "second seed eq. 2.1-2.4"),
    Deformer(
        "barycentric", lambda s: _controls_only(barycentric_weights(s), s),
        {"outside": "exponential", "alpha2": 1.0},
        "barycentric coordinates in the control mesh; eq. 1.2 outside it",
        "second seed eq. 1.1-1.2, 2.22-2.23"),
)
