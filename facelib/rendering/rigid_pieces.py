"""Rendered pieces that move rigidly: moved by their scene node's pose, not re-uploaded.

Hair rides the head's rotation rigidly, and so do the eyeballs and the teeth for most
frames. Rewriting their vertex buffers and recomputing their smooth normals every frame
(the hair alone is 60 % of the default head's vertices) costs the render thread time for
nothing. :class:`RigidGroup` holds what is needed to tell, per frame and from the vertices
alone, whether a group of pieces moved rigidly from its rest shape, and with which pose:
a least-squares rotation and translation of a few spread anchor vertices (Kabsch), checked
against every vertex of the group. The check is exact up to ``tolerance`` (a millionth-scale
fraction of the group's size, far below a pixel, well above float32 rounding), so a piece
that deforms (a tongue, lashes following the lids) is uploaded as before.

A group is a set of pieces whose vertices no other piece uses, so the smooth normals of
its vertices come from its own triangles only: at rest they are computed once, and moved
by the node pose in the shader (the normal matrix of the model matrix).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from facelib.rendering.normals import normal_operator

__all__ = ["RigidGroup", "anchor_ids", "rigid_groups", "rigid_pose"]

N_ANCHORS = 6
"""Anchor vertices a group's pose is fitted to (spread by farthest-point sampling)."""

TOLERANCE = 1e-5
"""Largest distance of any vertex from its rigidly moved rest position, as a fraction of the
group's bounding-box diagonal, for a frame to count as rigid."""


@dataclass(frozen=True)
class RigidGroup:
    """Pieces that may move as one rigid body.

    pieces: indices of the renderer's pieces in the group; vertex_ids: ``(Vg,) int64``
    sorted global ids of their vertices; rows: per piece, ``(Vp,) int64`` rows of its
    vertices in ``vertex_ids``; triangles: ``(Fg, 3) int64`` the face's triangles on these
    vertices, as rows of ``vertex_ids`` (the face's winding and order); operator:
    ``(Vg, Fg)`` normal operator of those triangles; anchors: ``(K,)`` rows of the anchor
    vertices; rest: ``(Vg, 3) float64`` rest positions; tolerance: in the face's unit.
    """

    pieces: tuple[int, ...]
    vertex_ids: np.ndarray
    rows: tuple[np.ndarray, ...]
    triangles: np.ndarray
    operator: sp.csr_matrix
    anchors: np.ndarray
    rest: np.ndarray
    tolerance: float


def anchor_ids(points: np.ndarray, count: int = N_ANCHORS) -> np.ndarray:
    """``(min(count, N),) int64`` rows of ``points`` ``(N, 3)`` spread over them: the point
    farthest from the centroid, then repeatedly the one farthest from those chosen."""
    points = np.asarray(points, np.float64)
    chosen = [int(np.argmax(np.linalg.norm(points - points.mean(axis=0), axis=1)))]
    distance = np.linalg.norm(points - points[chosen[0]], axis=1)
    while len(chosen) < min(count, len(points)):
        chosen.append(int(np.argmax(distance)))
        distance = np.minimum(distance, np.linalg.norm(points - points[chosen[-1]], axis=1))
    return np.array(chosen, np.int64)


def rigid_pose(group: RigidGroup, vertices: np.ndarray) -> np.ndarray | None:
    """``(4, 4) float64`` pose that moves the group's rest shape onto its vertices in
    ``vertices`` ``(V, 3)`` (all of the face's), or None where no rigid motion does."""
    now = np.asarray(vertices[group.vertex_ids], np.float64)
    rest_a, now_a = group.rest[group.anchors], now[group.anchors]
    rest_c, now_c = rest_a.mean(axis=0), now_a.mean(axis=0)
    u, _, vt = np.linalg.svd((rest_a - rest_c).T @ (now_a - now_c))
    flip = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    rotation = (u @ flip @ vt).T
    shift = now_c - rest_c @ rotation.T
    # the anchors first (cheap), then every vertex
    if np.abs(rest_a @ rotation.T + shift - now_a).max() > group.tolerance:
        return None
    if np.abs(group.rest @ rotation.T + shift - now).max() > group.tolerance:
        return None
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = rotation, shift
    return pose


def _connected(vertex_sets: Sequence[np.ndarray], n_vertices: int) -> list[list[int]]:
    """Indices of ``vertex_sets`` grouped where sets share a vertex."""
    from scipy.sparse.csgraph import connected_components

    rows = np.concatenate([np.full(len(ids), k) for k, ids in enumerate(vertex_sets)])
    member = sp.csr_matrix((np.ones(len(rows)), (rows, np.concatenate(vertex_sets))),
                           shape=(len(vertex_sets), n_vertices))
    _, labels = connected_components(member @ member.T, directed=False)
    return [list(np.flatnonzero(labels == label)) for label in np.unique(labels)]


def rigid_groups(vertex_sets: Sequence[np.ndarray], vertices: np.ndarray,
                 triangles: np.ndarray) -> list[RigidGroup]:
    """The pieces (their global ``vertex_sets``) gathered into :class:`RigidGroup` s, one per
    set of pieces that share vertices; rest shape ``vertices`` ``(V, 3)``, the face's
    ``triangles`` ``(F, 3)``."""
    vertices = np.asarray(vertices, np.float64)
    triangles = np.asarray(triangles, np.int64)
    out = []
    for members in _connected(vertex_sets, len(vertices)):
        ids = np.unique(np.concatenate([vertex_sets[k] for k in members]))
        inside = np.zeros(len(vertices), bool)
        inside[ids] = True
        tris = np.searchsorted(ids, triangles[inside[triangles].all(axis=1)])
        rest = vertices[ids]
        out.append(RigidGroup(
            pieces=tuple(int(k) for k in members), vertex_ids=ids,
            rows=tuple(np.searchsorted(ids, vertex_sets[k]) for k in members),
            triangles=tris, operator=normal_operator(len(ids), tris),
            anchors=anchor_ids(rest), rest=rest,
            tolerance=TOLERANCE * float(np.linalg.norm(np.ptp(rest, axis=0))),
        ))
    return out
