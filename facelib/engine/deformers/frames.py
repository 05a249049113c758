"""Frame-based deformers of Peña Araya (2012): SOFFD and Planar Bones.

Each control triangle k of the region's control mesh carries a frame; a member P is
expressed in the rest frame and re-placed in the deformed one, and the results are blended
with normalised weights ``u_k`` (eq. 2.6 / 2.15):

    P' = sum_k u_k (a_k + (P - A_k) Q_k^-1 Q'_k)

with ``Q = rows(B - A, C - A, n)`` (eq. 2.7 with the triangle origin restored, which is
eq. 2.8). Because ``n`` is a unit normal the map is not linear in the control
displacements; it reproduces any rigid motion of all sources exactly.

- ``soffd`` (Singh's surface-oriented FFD, eq. 2.5-2.7): ``w_k = 1 / (1 + (d_k / s)^local)``
  with ``d_k`` the distance to triangle k's nearest corner (section 3.3), ``s`` the control
  mesh's median edge, cut at ``radius * s`` (default 3: "in practice u is 0 for most k").
- ``planar_bones`` (Sanchez Lorenzo & Maddock, eq. 2.8-2.16): the frame depends on the zone
  of P around the triangle: inside (eq. 2.8), beside an edge (eq. 2.9-2.10, with the rest
  normal where the seed prints the deformed one) or beside a corner (eq. 2.11-2.14, the
  in-plane part rescaled to keep its length), and ``w = [(1 + cos(pi d / r)) / 2]^n`` inside
  ``r = x`` times the triangle's longest edge (eq. 2.16).

Both compile as their linearisation at rest (a central-difference Jacobian of the exact map,
``mode="linearised"``); ``mode="exact"`` adds the exact map as a per-frame step.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp

from facelib.engine.deformers.base import Deformer, FrameStep, RegionSetup
from facelib.engine.deformers.control_mesh import ControlMesh, control_mesh, triangle_frames

__all__ = ["DEFORMERS", "FrameMap", "frame_map", "linearise"]

BASE, EDGE, CORNER = 0, 1, 2


@dataclass(frozen=True, eq=False)
class FrameMap:
    """The exact map of a frame-based deformer over (member, triangle) pairs.

    mesh: the control mesh (sources: controls then anchors).
    n_controls: N, the sources that move (the rest are anchors).
    member: (K,) int64 member row of each pair; tri: (K,) int64 triangle; u: (K,) float64
        normalised weight; zone: (K,) int8 BASE / EDGE / CORNER; corner: (K,) int64 the edge's
        start or the corner vertex (0-2) for EDGE / CORNER pairs.
    local: (K, 3) float64 coordinates of the member in the pair's rest frame.
    planar: (K,) float64 in-plane distance from the corner (CORNER pairs; 0 otherwise).
    n_members: Vr.
    """

    mesh: ControlMesh
    n_controls: int
    member: np.ndarray
    tri: np.ndarray
    u: np.ndarray
    zone: np.ndarray
    corner: np.ndarray
    local: np.ndarray
    planar: np.ndarray
    n_members: int

    def displace(self, dc: np.ndarray) -> np.ndarray:
        """``dC (n, N, 3) -> (n, Vr, 3)`` exact member displacements."""
        dc = np.asarray(dc, np.float64)
        n = dc.shape[0]
        moved = np.broadcast_to(self.mesh.sources, (n, *self.mesh.sources.shape)).copy()
        moved[:, : self.n_controls] += dc
        return self._blend(moved) - self._rest

    @cached_property
    def _variant(self) -> np.ndarray:
        """(K,) int64 frame variant of each pair (see :func:`_all_frames`)."""
        return np.where(self.zone == BASE, 0,
                        np.where(self.zone == EDGE, 1 + self.corner, 4 + self.corner))

    @cached_property
    def _linear_parts(self) -> tuple[sp.csr_array, sp.csr_array]:
        """Sparse ``O (Vr, 3T)`` and ``L (Vr, 21T)``: for pairs outside corner zones the
        blended position is ``O @ corners + L @ frames`` (both flattened by rows), so a frame
        costs two sparse products instead of a loop over the pairs."""
        keep = self.zone != CORNER
        t = self.tri[keep]
        n_tri = len(self.mesh.triangles)
        origin = sp.csr_array((self.u[keep], (self.member[keep], t * 3 + self.corner[keep])),
                              shape=(self.n_members, 3 * n_tri))
        rows = np.repeat(self.member[keep], 3)
        cols = ((t * 7 + self._variant[keep])[:, None] * 3 + np.arange(3)).ravel()
        vals = (self.u[keep, None] * self.local[keep]).ravel()
        frames = sp.csr_array((vals, (rows, cols)), shape=(self.n_members, 21 * n_tri))
        return origin, frames

    @cached_property
    def _rest(self) -> np.ndarray:
        """(1, Vr, 3) the blended rest positions (the members, up to rounding)."""
        return self._blend(self.mesh.sources[None])

    def _blend(self, sources: np.ndarray) -> np.ndarray:
        """``(n, S, 3) -> (n, Vr, 3)`` the members placed in every weighted frame, blended."""
        n = len(sources)
        corners = sources[:, self.mesh.triangles]  # (n, T, 3, 3)
        frames = _all_frames(corners)  # (n, T, 7, 3, 3)
        origin, linear = self._linear_parts
        flat_c = corners.reshape(n, -1, 3).transpose(1, 0, 2).reshape(-1, n * 3)
        flat_f = frames.reshape(n, -1, 3).transpose(1, 0, 2).reshape(-1, n * 3)
        out = np.asarray(origin @ flat_c + linear @ flat_f)
        out = out.reshape(self.n_members, n, 3).transpose(1, 0, 2)
        corner = np.flatnonzero(self.zone == CORNER)
        if corner.size:
            tri, var = self.tri[corner], self._variant[corner]
            f = frames[:, tri, var]  # (n, k, 3, 3)
            local = np.broadcast_to(self.local[corner], (n, corner.size, 3)).copy()
            inplane = np.einsum("nkj,nkjc->nkc", local[..., :2], f[:, :, :2])
            length = np.linalg.norm(inplane, axis=2)
            scale = np.divide(self.planar[corner], length, out=np.ones_like(length),
                              where=length > 0)
            local[..., :2] *= scale[..., None]
            placed = corners[:, tri, self.corner[corner]] + np.einsum("nkj,nkjc->nkc", local, f)
            blend = sp.csr_array((self.u[corner], (self.member[corner], np.arange(corner.size))),
                                 shape=(self.n_members, corner.size))
            summed = np.asarray(blend @ placed.transpose(1, 0, 2).reshape(corner.size, -1))
            out += summed.reshape(self.n_members, n, 3).transpose(1, 0, 2)
        return out


def _all_frames(corners: np.ndarray) -> np.ndarray:
    """Every frame of every triangle: ``corners (n, T, 3, 3) -> (n, T, 7, 3, 3)`` rows.

    Variant 0 is the triangle frame (eq. 2.8), 1 + i the frame of edge i (from corner i to
    i + 1; eq. 2.9) and 4 + i the frame of corner i (eq. 2.11).
    """
    base = triangle_frames(corners)
    normal = base[..., 2, :]
    edges = np.roll(corners, -1, axis=2) - corners  # e_i = corner_{i+1} - corner_i
    outward = _unit(np.cross(edges, normal[..., None, :]))  # (n, T, 3, 3)
    n3 = np.broadcast_to(normal[..., None, :], edges.shape)
    edge_frames = np.stack([edges, outward, n3], axis=-2)
    corner_frames = np.stack([outward, np.roll(outward, 1, axis=2), n3], axis=-2)
    return np.concatenate([base[..., None, :, :], edge_frames, corner_frames], axis=2)


def _unit(v: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.divide(v, length, out=np.zeros_like(v), where=length > 0)


def _zones(mesh: ControlMesh, members: np.ndarray, tri: np.ndarray, member: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """Zone (BASE / EDGE / CORNER) and edge start / corner of each pair, from the closest
    point of the member's in-plane projection on the triangle."""
    corners = mesh.sources[mesh.triangles[tri]]  # (K, 3, 3)
    normal = triangle_frames(corners)[:, 2]
    p = members[member]
    proj = p - ((p - corners[:, 0]) * normal).sum(axis=1, keepdims=True) * normal
    zone = np.full(len(tri), BASE, np.int8)
    start = np.zeros(len(tri), np.int64)
    inside = np.ones(len(tri), bool)
    best = np.full(len(tri), np.inf)
    for i in range(3):
        a, b = corners[:, i], corners[:, (i + 1) % 3]
        e = b - a
        side = (np.cross(e, proj - a) * normal).sum(axis=1)
        out = side < 0
        inside &= ~out
        t = ((proj - a) * e).sum(axis=1) / (e * e).sum(axis=1)
        closest = a + np.clip(t, 0, 1)[:, None] * e
        dist = np.linalg.norm(proj - closest, axis=1)
        better = out & (dist < best)
        best[better] = dist[better]
        on_edge = (t > 0) & (t < 1)
        zone[better & on_edge] = EDGE
        start[better & on_edge] = i
        zone[better & (t <= 0)] = CORNER
        start[better & (t <= 0)] = i
        zone[better & (t >= 1)] = CORNER
        start[better & (t >= 1)] = (i + 1) % 3
    zone[inside] = BASE
    start[inside] = 0
    return zone, start


def frame_map(setup: RegionSetup, *, kind: str) -> FrameMap:
    """Build the exact map of ``soffd`` or ``planar_bones`` for a region."""
    pos = setup.vertices
    mesh = control_mesh(pos[setup.controls], pos[setup.anchors])
    members = pos[setup.members]
    d = mesh.corner_distances(members)  # (Vr, T)
    if kind == "soffd":
        w = 1.0 / (1.0 + (d / mesh.scale) ** float(setup.params["local"]))
        radius = setup.params["radius"]
        if radius is not None:
            w = np.where(d <= float(radius) * mesh.scale, w, 0.0)
    else:
        corners = mesh.sources[mesh.triangles]
        longest = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
        r = float(setup.params["reach"]) * longest
        w = np.where(d < r, (0.5 * (1 + np.cos(np.pi * np.minimum(d / r, 1.0)))), 0.0)
        w = w ** float(setup.params["power"])
    empty = w.sum(axis=1) <= 0  # beyond every reach: the nearest triangle alone
    w[empty, d[empty].argmin(axis=1)] = 1.0
    w /= w.sum(axis=1, keepdims=True)
    member, tri = np.nonzero(w > 1e-12)
    u = w[member, tri]
    if kind == "planar_bones":
        zone, start = _zones(mesh, members, tri, member)
    else:
        zone, start = np.full(tri.size, BASE, np.int8), np.zeros(tri.size, np.int64)
    variant = np.where(zone == BASE, 0, np.where(zone == EDGE, 1 + start, 4 + start))
    frames = _all_frames(mesh.sources[None][:, mesh.triangles])[0][tri, variant]
    origin = mesh.sources[mesh.triangles[tri, start]]
    rel = members[member] - origin
    local = np.linalg.solve(np.swapaxes(frames, 1, 2), rel[..., None])[..., 0]
    planar = np.linalg.norm(np.einsum("kj,kjc->kc", local[:, :2], frames[:, :2]), axis=1)
    return FrameMap(mesh, setup.controls.size, member, tri, u, zone, start, local,
                    np.where(zone == CORNER, planar, 0.0), setup.members.size)


def linearise(fmap: FrameMap, *, step: float | None = None) -> np.ndarray:
    """Central-difference Jacobian of the exact map at rest: ``(Vr, 3, N, 3)`` float64.

    ``step`` is the probe displacement (mesh units); None takes 1e-4 of the control mesh's
    median edge (the error is O(step^2)).
    """
    h = 1e-4 * fmap.mesh.scale if step is None else float(step)
    n = fmap.n_controls
    probes = np.zeros((2 * n * 3, n, 3))
    for i in range(n):
        for b in range(3):
            probes[2 * (3 * i + b), i, b] = h
            probes[2 * (3 * i + b) + 1, i, b] = -h
    moved = fmap.displace(probes)  # (6N, Vr, 3)
    jac = (moved[0::2] - moved[1::2]) / (2 * h)  # (3N, Vr, 3)
    return jac.reshape(n, 3, fmap.n_members, 3).transpose(2, 3, 0, 1)


def _check_mode(setup: RegionSetup) -> None:
    if setup.params["mode"] not in ("linearised", "exact"):
        raise setup.fail(f"mode must be 'linearised' or 'exact', got {setup.params['mode']!r}")


def _weights(kind: str) -> Callable[[RegionSetup], np.ndarray]:
    def weights(setup: RegionSetup) -> np.ndarray:
        _check_mode(setup)
        return linearise(frame_map(setup, kind=kind))

    return weights


def _step(kind: str) -> Callable[[RegionSetup], FrameStep]:
    def step(setup: RegionSetup) -> FrameStep:
        return FrameStep(frame_map(setup, kind=kind).displace)

    return step


DEFORMERS = (
    Deformer(
        "soffd", _weights("soffd"), {"local": 2.0, "radius": 3.0, "mode": "linearised"},
        "surface-oriented free-form deformation over the control mesh's triangle frames",
        "second seed eq. 2.5-2.7 (origin restored as in eq. 2.8)", step=_step("soffd")),
    Deformer(
        "planar_bones", _weights("planar_bones"),
        {"reach": 1.0, "power": 1.0, "mode": "linearised"},
        "Planar Bones: zone-dependent triangle frames, raised-cosine weights",
        "second seed eq. 2.8-2.16, with the reference's corrections", step=_step("planar_bones")),
)
