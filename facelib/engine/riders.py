"""Riders: vertices that carry no deformer of their own but move with the skin under them.

Eyelashes are the case in point: each lash vertex rides on a point of the lid margin, a
blend of two skin vertices ``(1 - t) a + t b``. A rider takes that blend of its anchors'
rows of the linear operator (whatever deformer or learned field moves them) and of their
eyelid weights, so it turns over the eye with the lid by exactly the margin's angle. Its own
offset from the margin (the lash's length and curl) is carried along: the translation it
copies leaves that offset as it is and the lid's rotation about the eye centre turns it with
the lid. Exact per-frame corrections of non-linear regions (``mode="exact"``) move members
only; riders follow those regions' linear part.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from facelib.errors import FaceModelError

__all__ = ["Riders", "no_riders"]


@dataclass(frozen=True, eq=False)
class Riders:
    """Which vertices ride on which.

    vertices: (R,) int32 rider vertex ids.
    anchors: (R, 2) int32 the two anchor vertices of each rider.
    blend: (R,) float32 ``t`` in [0, 1]: a rider follows ``(1 - t) * anchor_0 + t * anchor_1``.
    """

    vertices: np.ndarray
    anchors: np.ndarray
    blend: np.ndarray

    @property
    def size(self) -> int:
        """The number of riders ``R``."""
        return int(self.vertices.size)

    def check(self, n_vertices: int, region_vertices: np.ndarray) -> None:
        """Raise :class:`FaceModelError` unless the riders are well formed: ids in range,
        shapes matching, blends in [0, 1], no rider anchored on a rider or in a region."""
        v, a, t = self.vertices, self.anchors, self.blend
        if v.ndim != 1 or a.shape != (v.size, 2) or t.shape != v.shape:
            raise FaceModelError(f"riders: {v.size} vertices need ({v.size}, 2) anchors and "
                                 f"{v.size} blends, got {a.shape} and {t.shape}")
        if v.size == 0:
            return
        if min(v.min(), a.min()) < 0 or max(v.max(), a.max()) >= n_vertices:
            raise FaceModelError(f"riders: a vertex or anchor is outside 0-{n_vertices - 1}")
        if not np.all((t >= 0) & (t <= 1)):
            raise FaceModelError("riders: blends must lie in [0, 1]")
        if np.unique(v).size != v.size or np.isin(a, v).any():
            raise FaceModelError("riders: a rider is listed twice or anchored on a rider")
        inside = np.isin(v, region_vertices)
        if inside.any():
            raise FaceModelError(f"riders: vertex {int(v[inside][0])} is also a member of a "
                                 "region; a rider only follows its anchors")

    def operator(self, operator: sp.csr_array) -> sp.csr_array:
        """``operator`` ``(84, 3V)`` float32 with the blend of each rider's anchors' columns
        added to the rider's own (x, y, z) columns, which are zero: a rider belongs to no
        region (:meth:`check`), so the result is the blend."""
        if self.size == 0:
            return operator
        n = operator.shape[1]
        axes = np.arange(3)
        rider_cols = (self.vertices.astype(np.int64)[:, None] * 3 + axes).ravel()
        rows = [np.arange(n)]
        cols = [np.arange(n)]
        vals = [np.ones(n)]
        for k, share in ((0, 1.0 - self.blend.astype(np.float64)), (1, self.blend)):
            rows.append((self.anchors[:, k].astype(np.int64)[:, None] * 3 + axes).ravel())
            cols.append(rider_cols)
            vals.append(np.repeat(np.asarray(share, np.float64), 3))
        carry = sp.csr_array((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(n, n))
        out = sp.csr_array(operator @ carry).astype(np.float32)
        out.eliminate_zeros()
        out.sum_duplicates()
        return out

    def weighted_region(self, vertices: np.ndarray, weights: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
        """A weighted region's ``(Vr,)`` members and weights extended by the riders whose
        anchors it holds, each weighted by the blend of its anchors' weights."""
        if self.size == 0:
            return vertices, weights
        lookup = dict(zip(vertices.tolist(), weights.tolist(), strict=True))
        w = np.array([[lookup.get(int(a), 0.0) for a in pair] for pair in self.anchors])
        t = self.blend.astype(np.float64)
        share = (1.0 - t) * w[:, 0] + t * w[:, 1]
        held = np.isin(self.anchors, vertices).any(axis=1) & (share > 0)
        return (np.concatenate([vertices, self.vertices[held]]).astype(np.int32),
                np.concatenate([weights, share[held]]).astype(np.float32))


def no_riders() -> Riders:
    """A face without riders."""
    return Riders(np.zeros(0, np.int32), np.zeros((0, 2), np.int32), np.zeros(0, np.float32))

