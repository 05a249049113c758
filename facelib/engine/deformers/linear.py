"""Linear deformers of the thesis (section 4.1.4): raised cosine and multiquadric RBF.

Each deformer answers one question: when its control feature points move by
``(N, 3)`` displacements, how far does each member vertex move? Both are linear in the
displacements, so each returns a matrix ``M (Vr, N)``: member displacement = ``M @ dFP``
(the same matrix for x, y and z).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.distance import cdist

from facelib.engine.deformers.base import Deformer, RegionSetup
from facelib.errors import FaceModelError

__all__ = ["RAISED_COSINE", "WEIGHTS", "explicit_weights", "raised_cosine_weights", "rbf_weights"]

RAISED_COSINE_W = 0.5
"""The constant w of eq. 4.7: with 0.5 the feature point itself moves by exactly its dFP."""

EDGE_RADIUS_MIN = 0.25
"""An edge closer to the feature point than this fraction of the region's extent means the
point lies on (or next to) the edge: the falloff then spans the whole region instead."""


def raised_cosine_weights(
    members: np.ndarray, controls: np.ndarray, *, edge: np.ndarray | None = None
) -> np.ndarray:
    """Raised-cosine falloff of eq. 4.7, averaged over the controls of the region.

    ``F(v) = [1 + cos(pi * d_v / d_max)] * w * dFP`` with ``w = 0.5``, ``d_v`` the distance of
    member ``v`` to the control and ``d_max`` the distance of the farthest member. With several
    controls each column is divided by their number (the thesis averages the cosines).

    A region is seldom a disc around its point: with ``edge`` given, ``d_max`` is instead the
    distance to the nearest of those edge vertices (members next to the rest of the mesh),
    and members farther out stay still, so the surface is continuous (with zero slope) where
    the region meets the rest of the mesh instead of creasing there. A feature point on the
    region's own edge (nearest edge vertex closer than ``EDGE_RADIUS_MIN`` of the farthest
    member) would leave no room to fall off, so there ``d_max`` is the farthest member's
    distance, as in the thesis.

    Parameters
    ----------
    members: (Vr, 3) float, rest positions of the region's vertices.
    controls: (N, 3) float, rest positions of its feature points.
    edge: (E, 3) float, rest positions of the region's edge vertices, or None.

    Returns
    -------
    (Vr, N) float64 weights in [0, 1].
    """
    d = cdist(members, controls)
    far = d.max(axis=0)
    if np.any(far == 0):
        raise FaceModelError("a raised-cosine region has no extent: every member sits on its "
                             "feature point")
    d_max = far
    if edge is not None and len(edge):
        near = cdist(edge, controls).min(axis=0)
        d_max = np.where(near >= EDGE_RADIUS_MIN * far, near, far)
    w = (1.0 + np.cos(np.pi * np.clip(d / d_max, 0.0, 1.0))) * RAISED_COSINE_W
    return w / controls.shape[0]


def explicit_weights(weights: np.ndarray) -> np.ndarray:
    """Per-vertex weights given in the face definition (one control): ``(Vr,) -> (Vr, 1)``."""
    return np.asarray(weights, dtype=np.float64)[:, None]


def _stiffness(sources: np.ndarray) -> np.ndarray:
    """Eck's stiffness ``sc_j``: the distance from source j to its nearest other source."""
    d = cdist(sources, sources)
    np.fill_diagonal(d, np.inf)
    return d.min(axis=1)


def rbf_weights(members: np.ndarray, controls: np.ndarray, anchors: np.ndarray) -> np.ndarray:
    """Multiquadric RBF of eq. 4.8-4.10, trained on controls + static anchors.

    The sources are ``S = controls + anchors``; ``H_ij = sqrt(|s_i - s_j|^2 + sc_j^2)`` with
    ``sc_j`` the distance from ``s_j`` to its nearest other source (eq. 4.8; the seed prints
    ``sc_j^2 = min |s_j - s_i|``, which is not unit-free, so this follows Eck's definition).
    The RBF interpolates displacements (anchors move by zero), so a member's displacement is
    ``h(x) @ H^-1 @ T`` (eq. 4.9-4.10): linear in the control displacements ``T``.

    Parameters
    ----------
    members: (Vr, 3) float, rest positions of the vertices to move.
    controls: (N, 3) float, rest positions of the feature points (they move).
    anchors: (A, 3) float, rest positions of the static border points.

    Returns
    -------
    (Vr, N) float64: member displacement = result @ control displacements.
    """
    sources = np.concatenate([controls, anchors])
    sc = _stiffness(sources)
    if not np.all(np.isfinite(sc)) or np.any(sc == 0):
        raise FaceModelError("RBF sources must be at least two distinct points")
    h = np.sqrt(cdist(sources, sources) ** 2 + sc[None, :] ** 2)
    hx = np.sqrt(cdist(members, sources) ** 2 + sc[None, :] ** 2)
    try:
        # members @ H^-1, restricted to the control columns of T (anchors are zero)
        m = np.linalg.solve(h.T, hx.T).T
    except np.linalg.LinAlgError as exc:  # pragma: no cover - multiquadric H is invertible
        raise FaceModelError(f"RBF matrix is singular: {exc}") from exc
    return m[:, : controls.shape[0]]


def _raised_cosine(setup: RegionSetup) -> np.ndarray:
    pos = setup.vertices
    members = pos[setup.members]
    controls = pos[setup.controls]
    radius = setup.params["radius"]
    if radius == "edge":
        edge = pos[_edge(setup.members, setup.triangles, len(pos))]
        return raised_cosine_weights(members, controls, edge=edge)
    if radius == "farthest":
        return raised_cosine_weights(members, controls)
    raise setup.fail(f"raised_cosine radius must be 'edge' or 'farthest', got {radius!r}")


def _edge(members: np.ndarray, triangles: np.ndarray, n_vertices: int) -> np.ndarray:
    """Ids of the members that share a triangle with a vertex outside ``members``."""
    inside = np.zeros(n_vertices, bool)
    inside[members] = True
    mixed = triangles[inside[triangles].any(1) & ~inside[triangles].all(1)]
    return np.unique(mixed[inside[mixed]])


def _explicit(setup: RegionSetup) -> np.ndarray:
    return explicit_weights(setup.weights)


RAISED_COSINE = Deformer(
    "raised_cosine", _raised_cosine, {"radius": "edge"},
    "raised-cosine falloff around each feature point, averaged over them",
    "first seed eq. 4.7; radius 'farthest' is the thesis's d_max, 'edge' the nearest "
    "region-edge vertex")
WEIGHTS = Deformer("weights", _explicit, {}, "explicit per-vertex weights of one feature point",
                   "face definition")
