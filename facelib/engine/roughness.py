"""Per-frame roughness reports (Peña Araya 2012, section 3.2.2) and flipped-triangle counts.

The seed's tool writes, for every frame, one row per lip control point (minimum, maximum and
mean roughness of the triangles around it, eq. 3.2-3.3) and a summary row with index -1.
:func:`roughness_report` computes the same over a stream of deformed meshes; the
neighbourhood of a point (which the seed leaves open) is the triangles within ``rings``
edges of its vertex.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from facelib.engine.quality import triangle_roughness
from facelib.errors import ParameterError

__all__ = ["RoughnessReport", "flipped_triangles", "neighbourhoods", "region_roughness",
           "roughness_report"]


def flipped_triangles(rest: np.ndarray, deformed: np.ndarray, triangles: np.ndarray) -> int:
    """How many triangles turned over: normal at ``deformed`` opposite to the one at ``rest``.

    rest, deformed: (V, 3) float positions; triangles: (F, 3) int. Degenerate triangles
    (zero normal at rest) are not counted.
    """
    t = np.asarray(triangles, np.int64)

    def normals(v: np.ndarray) -> np.ndarray:
        v = np.asarray(v, np.float64)
        return np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])

    return int(np.count_nonzero(np.einsum("ij,ij->i", normals(rest), normals(deformed)) < 0))


def neighbourhoods(triangles: np.ndarray, points: np.ndarray, n_vertices: int, *,
                   rings: int = 2) -> list[np.ndarray]:
    """Triangles within ``rings`` edges of each point: one ``(k,) int64`` array per point.

    A triangle belongs to a point's neighbourhood when one of its corners is within
    ``rings - 1`` edges of the point (``rings = 1``: the fan around it).
    """
    if rings < 1:
        raise ParameterError(f"rings must be >= 1, got {rings!r}")
    t = np.asarray(triangles, np.int64)
    faces = np.repeat(np.arange(len(t)), 3)
    incidence = sp.csr_array((np.ones(t.size), (t.ravel(), faces)), shape=(n_vertices, len(t)))
    adjacency = (incidence @ incidence.T).astype(bool)
    out = []
    for p in np.asarray(points, np.int64):
        reached = np.zeros(n_vertices, bool)
        reached[p] = True
        for _ in range(rings - 1):
            reached = reached | (adjacency @ reached.astype(np.float64) > 0)
        out.append(np.flatnonzero(incidence.T @ reached.astype(np.float64) > 0))
    return out


def region_roughness(frames: np.ndarray, triangles: np.ndarray, vertex_ids: np.ndarray
                     ) -> np.ndarray:
    """Per frame min, max and mean roughness of the triangles whose corners all lie in
    ``vertex_ids``: ``frames (n, V, 3) -> (n, 3) float64``."""
    t = np.asarray(triangles, np.int64)
    inside = np.zeros(np.shape(frames)[1], bool)
    inside[np.asarray(vertex_ids, np.int64)] = True
    keep = inside[t].all(axis=1)
    if not keep.any():
        raise ParameterError("the region contains no whole triangle")
    out = np.empty((len(frames), 3))
    for i, v in enumerate(frames):
        rho = triangle_roughness(v, t)[keep]
        out[i] = rho.min(), rho.max(), rho.mean()
    return out


@dataclass(frozen=True, eq=False)
class RoughnessReport:
    """The seed's ``dataMetrics.txt``, as arrays.

    labels: the points' labels (feature point ids), then ``"-1"`` for the summary.
    vertices: (P,) int64 the points' vertex ids.
    fps: frames per second (the time column is ``frame / fps``).
    values: (n_frames, P + 1, 3) float64 min, max, mean roughness; row P is the summary
        (min of the minima, max of the maxima, mean over the union of the neighbourhoods).
    """

    labels: tuple[str, ...]
    vertices: np.ndarray
    fps: float
    values: np.ndarray

    def rows(self) -> list[tuple[int, float, str, float, float, float]]:
        """``(frame, time s, label, min, max, mean)`` rows, frame by frame, as the seed
        writes them."""
        out = []
        for f, frame in enumerate(self.values):
            for label, (lo, hi, mean) in zip(self.labels, frame, strict=True):
                out.append((f, f / self.fps, label, float(lo), float(hi), float(mean)))
        return out


def roughness_report(frames: np.ndarray, triangles: np.ndarray, points: Mapping[str, int],
                     *, fps: float = 25.0, rings: int = 2) -> RoughnessReport:
    """Per-frame roughness around each point and the summary row (section 3.2.2).

    frames: (n, V, 3) float deformed positions; triangles: (F, 3) int; points: label ->
    vertex id (the seed uses the 18 lip vertices).
    """
    frames = np.asarray(frames)
    if frames.ndim != 3 or frames.shape[2] != 3:
        raise ParameterError(f"frames must have shape (n, V, 3), got {frames.shape}")
    if not points:
        raise ParameterError("roughness_report needs at least one point")
    ids = np.array(list(points.values()), np.int64)
    hoods = neighbourhoods(triangles, ids, frames.shape[1], rings=rings)
    union = np.unique(np.concatenate(hoods))
    values = np.empty((len(frames), len(ids) + 1, 3))
    for i, v in enumerate(frames):
        rho = triangle_roughness(v, triangles)
        for k, hood in enumerate(hoods):
            r = rho[hood]
            values[i, k] = r.min(), r.max(), r.mean()
        values[i, -1] = values[i, :-1, 0].min(), values[i, :-1, 1].max(), rho[union].mean()
    values.flags.writeable = False
    return RoughnessReport((*points, "-1"), ids, float(fps), values)
