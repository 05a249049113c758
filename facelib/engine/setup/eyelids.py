"""Upper eyelids that close over the whole eye of a transferred face.

An eyelid region turns its vertices about the x axis through the eye centre, each by its
weight times the angle that brings the lid feature point down by one IRISD (FAP 19/20 at
1024). Weights carried over from another head keep that head's shares, which leave the
corners of a taller or rounder eye opening (a cartoon's big eyes) uncovered. Here the
opening is measured in a front view (looking along -z, the eyeball a sphere of the given
centre and radius, the skin triangles in front of it), and in every column ``x`` where the
closed lid still shows the eyeball, the lid's weight at its rim (the skin just above the
opening's top edge) is raised to the share of the full angle that turns the rim down to the
opening's bottom edge, and the members around the rim by the same amount fading out
(raised cosine) over half the eyeball's radius; the lid is closed again and this repeats
(at most three rounds) while the eyeball shows. Where the lid already closes, nothing
changes (a transfer onto the source itself stays exact).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from facelib.engine import rigid
from facelib.engine.face import Region

__all__ = ["Opening", "close_upper_lid", "eye_opening"]

_SAMPLES = 48  # front-view samples across the eyeball's diameter
_ROUNDS = 3  # refits while the closed lid still shows the eyeball


@dataclasses.dataclass(frozen=True, eq=False)
class Opening:
    """Where the eyeball shows in a front view, column by column.

    x: (C,) float64 column positions. low, high: (C,) float64 lowest and highest ``y``
    where the eyeball shows (NaN where it does not). z_low, z_high: (C,) float64 the
    eyeball's front ``z`` at those two points. rim: (C,) int64 the skin triangle in front
    one sample above ``high`` (-1 where none); rim_weights: (C, 3) float64 its barycentric
    weights there.
    """

    x: np.ndarray
    low: np.ndarray
    high: np.ndarray
    z_low: np.ndarray
    z_high: np.ndarray
    rim: np.ndarray
    rim_weights: np.ndarray

    @property
    def shows(self) -> bool:
        """True when the eyeball shows anywhere."""
        return bool(np.isfinite(self.high).any())


def _front(grid: np.ndarray, depth: np.ndarray, corners: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The front-most triangle of ``corners (F, 3, 3)`` over each sample ``(i, j)`` of the
    square ``grid (n,)`` x ``grid`` of offsets, if it is nearer the viewer (larger z) than
    ``depth (n, n)``: its index ``(n, n) int64`` (-1 where none) and barycentric ``u, v``
    ``(n, n) float64``. Corners are relative to the grid's origin; each triangle is tested
    against the samples in its bounding box only."""
    step = float(grid[1] - grid[0])
    lo = np.clip(np.ceil((corners[..., :2].min(axis=1) - grid[0]) / step), 0, grid.size)
    hi = np.clip(np.floor((corners[..., :2].max(axis=1) - grid[0]) / step), -1, grid.size - 1)
    span = np.maximum(hi - lo + 1, 0).astype(np.int64)  # (F, 2) samples along x and y
    count = span[:, 0] * span[:, 1]
    tri = np.repeat(np.arange(len(corners)), count)
    k = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
    i = lo[tri, 0].astype(np.int64) + k // np.maximum(span[tri, 1], 1)
    j = lo[tri, 1].astype(np.int64) + k % np.maximum(span[tri, 1], 1)
    a = corners[tri, 0]
    e1, e2 = corners[tri, 1] - a, corners[tri, 2] - a
    px, py = grid[i] - a[:, 0], grid[j] - a[:, 1]
    den = e1[:, 0] * e2[:, 1] - e2[:, 0] * e1[:, 1]
    ok = np.abs(den) > 1e-18
    safe = np.where(ok, den, 1.0)
    u = (px * e2[:, 1] - e2[:, 0] * py) / safe
    v = (e1[:, 0] * py - px * e1[:, 1]) / safe
    z = a[:, 2] + u * e1[:, 2] + v * e2[:, 2]
    over = np.flatnonzero(ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (z > depth[i, j]))
    over = over[np.argsort(z[over], kind="stable")]  # the nearest written last wins
    best = np.full(depth.shape, -1, np.int64)
    bu, bv = np.zeros(depth.shape), np.zeros(depth.shape)
    best[i[over], j[over]], bu[i[over], j[over]], bv[i[over], j[over]] = (
        tri[over], u[over], v[over])
    return best, bu, bv


def eye_opening(vertices: np.ndarray, triangles: np.ndarray, centre: np.ndarray,
                radius: float) -> Opening:
    """The eye opening of skin ``vertices (V, 3)``, ``triangles (F, 3)`` in front of the
    eyeball sphere ``centre (3,)``, ``radius`` (metres, face frame: looking along -z)."""
    c = np.asarray(centre, dtype=np.float64)
    offsets = np.linspace(-radius, radius, _SAMPLES)
    dx, dy = np.meshgrid(offsets, offsets, indexing="ij")
    dz2 = radius**2 - dx**2 - dy**2
    front = dz2 > 0
    depth = np.where(front, np.sqrt(np.where(front, dz2, 0.0)), np.inf)
    corners = np.asarray(vertices, dtype=np.float64)[triangles] - c
    near = np.flatnonzero(corners[..., 2].max(axis=1) > 0)
    tri, u, v = _front(offsets, depth, corners[near])
    shows = front & (tri < 0)
    low, high, z_low, z_high = np.full((4, _SAMPLES), np.nan)
    rim, rim_weights = np.full(_SAMPLES, -1, np.int64), np.zeros((_SAMPLES, 3))
    for i in np.flatnonzero(shows.any(axis=1)):
        rows = np.flatnonzero(shows[i])
        low[i], high[i] = c[1] + offsets[rows[0]], c[1] + offsets[rows[-1]]
        z_low[i], z_high[i] = c[2] + depth[i, rows[0]], c[2] + depth[i, rows[-1]]
        above = rows[-1] + 1
        if above < _SAMPLES and tri[i, above] >= 0:
            rim[i] = near[tri[i, above]]
            rim_weights[i] = (1 - u[i, above] - v[i, above], u[i, above], v[i, above])
    return Opening(c[0] + offsets, low, high, z_low, z_high, rim, rim_weights)


def close_upper_lid(region: Region, *, vertices: np.ndarray, triangles: np.ndarray,
                    centre: np.ndarray, radius: float, full_angle: float) -> Region:
    """``region`` (an upper eyelid of the face with skin ``vertices (V, 3)``, ``triangles
    (F, 3)``) with weights raised where its closed pose leaves the eye open.

    full_angle: radians the lid feature point turns at full closure (FAP 19/20 = 1024).
    """
    members = region.vertices.astype(np.int64)
    if not members.size or full_angle <= 0:
        return region
    pos = np.asarray(vertices, dtype=np.float64)
    weights = region.weights.astype(np.float64)
    opening = eye_opening(pos, triangles, centre, radius)
    for _ in range(_ROUNDS):
        closed = pos.copy()
        y, z = rigid.rotate_about_x(pos[members, 1][None], pos[members, 2][None], centre[1],
                                    centre[2], (weights * full_angle)[None])
        closed[members, 1], closed[members, 2] = y[0], z[0]
        still = eye_opening(closed, triangles, centre, radius)
        field = np.zeros(len(pos))
        field[members] = weights
        # columns without a rim (-1) index the last triangle here; _lift skips them
        lift = _lift(opening, np.isfinite(still.high), pos[triangles[opening.rim]],
                     field[triangles[opening.rim]], members=pos[members], centre=centre,
                     full_angle=full_angle, reach=radius / 2)
        if not lift.any():
            break
        weights = np.clip(weights + lift, 0.0, 1.0)
    if np.array_equal(weights, region.weights.astype(np.float64)):
        return region
    return dataclasses.replace(region, weights=weights.astype(np.float32))


def _lift(opening: Opening, open_columns: np.ndarray, rim_corners: np.ndarray,
          rim_field: np.ndarray, *, members: np.ndarray, centre: np.ndarray,
          full_angle: float, reach: float) -> np.ndarray:
    """``(Vr,)`` float64 weight to add to each member at ``members (Vr, 3)``.

    In each column that still shows the eyeball (``open_columns (C,) bool``) the lid's
    weight at the rim (``rim_field (C, 3)``, the weights at the corners ``rim_corners (C, 3,
    3)`` of the column's rim triangle, interpolated) must reach the share of ``full_angle``
    that turns the opening's top edge to its bottom edge (each known to one sample, so one
    sample beyond); members within ``reach`` of the rim get the shortfall times a raised
    cosine of their distance, the largest over the columns."""
    lift = np.zeros(len(members))
    step = float(opening.x[1] - opening.x[0])
    for i in np.flatnonzero(open_columns & (opening.rim >= 0)):
        top, bottom = opening.high[i] + step - centre[1], opening.low[i] - step - centre[1]
        needed = (np.arctan2(top, opening.z_high[i] - centre[2])
                  - np.arctan2(bottom, opening.z_low[i] - centre[2]))
        short = min(needed / full_angle, 1.0) - float(opening.rim_weights[i] @ rim_field[i])
        if short <= 0:
            continue
        d = np.linalg.norm(members - opening.rim_weights[i] @ rim_corners[i], axis=1)
        fade = np.where(d < reach, 0.5 * (1 + np.cos(np.pi * d / reach)), 0.0)
        lift = np.maximum(lift, short * fade)
    return lift
