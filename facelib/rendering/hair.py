"""Which hair triangles are drawn from one side only.

Hair cards are thin ribbons, so the look draws them from both sides (``double_sided``). On
llvmpipe (Mesa's software rasteriser, what facelib renders with on CPU machines) every
triangle costs for every pixel it covers, hidden or not: with 4x multisampling the per-sample
depth test and colour store run for the whole covered block whatever the depth test says,
so neither draw order nor early depth rejection saves anything (measured in
``benchmarks/render_speed.py``). The back faces of the cards that lie on the head, the ones
facing the scalp, are never seen from outside, yet they were rasterised like the rest.

:func:`split_hair` cuts the hair piece in two: the triangles near the body (within
``within`` of a vertex of another part), turned to face away from that surface, which the
renderer draws single-sided with back-face culling; and the rest (cards that hang free of
the head, long hair over the shoulders, a ponytail), still double-sided. A culled triangle
only ever hides its own back face, which looks at the scalp a few millimetres away, so the
image changes at most along silhouettes where a card is seen edge-on (sub-pixel to a pixel).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["split_hair"]


def split_hair(
    hair: np.ndarray, triangles: np.ndarray, body: np.ndarray, body_normals: np.ndarray, *,
    within: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The hair's triangles split into ``(single_sided (Fs, 3), double_sided (Fd, 3))``.

    ``hair`` ``(Vh, 3)`` rest positions of the hair piece's vertices, ``triangles``
    ``(F, 3)`` indices into them; ``body`` ``(B, 3)`` vertices of the other parts with their
    unit ``body_normals`` ``(B, 3)`` (pointing out of the body); ``within``: how far from the
    body (same length unit) all three corners of a triangle must lie for it to be drawn
    single-sided. Single-sided triangles are wound so that their normal points away from the
    nearest body vertex's normal side (counter-clockwise seen from outside); the other
    triangles keep their winding. Same dtype as ``triangles``; together they hold every
    triangle once.
    """
    triangles = np.asarray(triangles)
    if len(body) == 0 or within <= 0 or len(triangles) == 0:
        return triangles[:0], triangles
    hair = np.asarray(hair, np.float64)
    distance, nearest = cKDTree(np.asarray(body, np.float64)).query(hair)
    near = (distance[triangles] <= within).all(axis=1)
    a, b, c = (hair[triangles[:, k]] for k in range(3))
    facing = np.cross(b - a, c - a)
    # the body's normal at each corner's nearest vertex, summed over the corners
    outward = np.asarray(body_normals, np.float64)[nearest[triangles]].sum(axis=1)
    away = np.einsum("ij,ij->i", facing, outward) >= 0
    single = triangles[near]
    single = np.where(away[near, None], single, single[:, ::-1])
    return np.ascontiguousarray(single), triangles[~near]
