"""Transfer of a face definition onto another head (third seed, sections 4.7.1-4.7.3).

1. the thin-plate spline ``T`` of the landmarks (eq. 4.1-4.5) warps the source;
2. every warped source vertex moves to its closest point on the same part of the target
   (eq. 4.7, with a normal check): the *guide model*;
3. each target vertex takes the source attributes interpolated (barycentric) at its closest
   point on the guide: region membership (an indicator, kept at >= 0.5), per-vertex weights
   (jaw, eyelids), learned displacements and colours. Weights and displacements are
   interpolated as 0 at non-members (the source does not move them), so a vertex on a
   region's border gets the source's own, smaller motion there, not its members' average;
4. point attributes (feature points, RBF anchors) go to the target vertex nearest to their
   guide position; pivots and the neck plane go through ``T`` (normals by ``J^-T``, lengths
   by ``|det J|^(1/3)``);
5. parts the target lacks (eyeballs, teeth, tongue) are carried: eyeballs by a similarity
   about ``T(centre)`` so they stay spheres, teeth and tongue through ``T``; the source's
   lashes are always carried through ``T``, each lash vertex riding on the target vertices
   nearest to its anchors' guide positions. The source's attached parts (bust, garment,
   hair: :mod:`~facelib.engine.attachments`) are not transferred: they are fitted to the
   source head (the bust shares its neck loop), so the new face has the head's parts only.

FAPU come out of the new mesh when the :class:`~facelib.engine.face.Face` is built, which
rescales every FAP stream to the new proportions (the seed's animation transfer).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from facelib.engine import rigid
from facelib.engine.face import OPTIONAL_PARTS, PART_NAMES, Face, Region, Riders
from facelib.engine.fapu import compute_fapu
from facelib.engine.setup.eyelids import close_upper_lid
from facelib.engine.setup.headmesh import HeadMesh
from facelib.engine.setup.tps import ThinPlateSpline
from facelib.engine.surface import Surface, SurfacePoints, closest_points, surface, vertex_normals
from facelib.mpeg4.tables import FAPU_SCALE, fap_table

__all__ = ["transfer_face"]

# a target eyeball centred this far (x its radius) from the warped source eye centre
# rotates about its own centre (sphere fit) instead
_EYE_CENTRE_TOLERANCE = 0.05
_EYE_LIDS = {"eye_l": ("3.1", "3.3"), "eye_r": ("3.2", "3.4")}  # upper, lower lid points


@dataclass(frozen=True, eq=False)
class _Dense:
    """A part of the target matched to the same part of the source.

    offset: first global vertex id of the part in the output mesh.
    guide: (Vs, 3) float64 guide model (warped, projected source vertices of the part).
    guide_surface: the guide as a surface (source triangles, local ids).
    match: each target vertex's closest point on the guide.
    tree: cKDTree over the target part's vertices.
    """

    offset: int
    guide: np.ndarray
    guide_surface: Surface
    match: SurfacePoints
    tree: cKDTree


@dataclass(frozen=True, eq=False)
class _Carried:
    """A source part copied into the output (warped): ``offset`` of its first vertex."""

    offset: int


def _local(ids: np.ndarray, n: int) -> np.ndarray:
    out = np.full(n, -1, np.int64)
    out[ids] = np.arange(ids.size)
    return out


def transfer_face(source: Face, target: HeadMesh, tps: ThinPlateSpline,
                  landmark_vertices: Mapping[str, tuple[str, int]], *,
                  min_cos: float = 0.5, skin: Surface | None = None) -> Face:
    """A new Face on ``target`` (metres, face frame) from ``source`` through ``tps``.

    skin: the target's skin already prepared by :func:`~facelib.engine.surface.surface`
        (its vertices and triangles in the skin part's own numbering), to save building it
        again.

    landmark_vertices: feature point -> (part, index within the target's part) for
        landmarks given as vertices: they keep exactly that vertex when the part is the
        feature point's part on the source.
    """
    warped = tps(source.vertices.astype(np.float64))
    blocks: dict[str, _Dense | _Carried] = {}
    positions, triangles, colours, occlusion = [], [], [], []
    offset = 0
    source_ao = source.vertex_ao if source.vertex_ao is not None else np.ones(source.n_vertices)
    names = (*PART_NAMES, *(p for p in OPTIONAL_PARTS if p in source.parts))
    for name in names:
        src = source.parts[name]
        src_tris = _local(src.vertex_ids, source.n_vertices)[src.triangles]
        ao = source_ao[src.vertex_ids]
        if name in PART_NAMES and name in target.parts and target.parts[name].size:
            ids = target.parts[name]
            pos = target.vertices[ids]
            tris = target.part_triangles(name)
            block = _dense(warped[src.vertex_ids], src_tris, pos, tris, offset=offset,
                           min_cos=min_cos, prepared=skin if name == "skin" else None)
            col = (target.colors[ids] if target.colors is not None else
                   block.match.interpolate(block.guide_surface,
                                           source.vertex_colors[src.vertex_ids]))
            ao = block.match.interpolate(block.guide_surface, ao)  # baked on the source
            blocks[name] = block
        else:
            pos, tris = _carry(source, name, tps, warped), src_tris
            col = source.vertex_colors[src.vertex_ids]
            blocks[name] = _Carried(offset)
        positions.append(pos)
        triangles.append(tris + offset)
        colours.append(col)
        occlusion.append(ao)
        offset += len(pos)
    mapper = _mapper(source, blocks, warped, names)
    points = mapper.feature_points(source.feature_points, landmark_vertices)
    pivots = _pivots(source, tps, blocks, positions)
    verts = np.concatenate(positions)
    parts = _part_ranges(names, positions)
    regions = _closed_lids(tuple(mapper.region(r, points) for r in source.regions),
                           verts=verts, skin=triangles[0], points=points, pivots=pivots,
                           eyes={p: parts[p] for p in ("eye_l", "eye_r")})
    return Face.build(
        vertices=verts, triangles=np.concatenate(triangles),
        vertex_colors=np.clip(np.concatenate(colours), 0, 1),
        parts=parts, feature_points=points, regions=regions,
        pivots=pivots, neck=_neck(source, tps), riders=_riders(source, mapper),
        vertex_ao=None if source.vertex_ao is None else np.clip(np.concatenate(occlusion), 0, 1))


def _mapper(source: Face, blocks: Mapping[str, object], warped: np.ndarray,
            names: tuple[str, ...]) -> _Mapper:
    """The :class:`_Mapper` of the source parts ``names`` onto their output blocks."""
    part_of = np.empty(source.n_vertices, dtype=object)
    local_of = np.zeros(source.n_vertices, np.int64)
    for name in names:
        ids = source.parts[name].vertex_ids
        part_of[ids] = name
        local_of[ids] = np.arange(ids.size)
    return _Mapper(blocks, part_of, local_of, warped, names)


def _riders(source: Face, mapper: _Mapper) -> Riders:
    """The source's riders on the output: carried rider vertices, anchors on the output
    vertices nearest to the source anchors' guide positions, the same blends."""
    r = source.riders
    if not r.size:
        return r
    return Riders(mapper.nearest(r.vertices.astype(np.int64)).astype(np.int32),
                  mapper.nearest(r.anchors.ravel().astype(np.int64)).reshape(-1, 2)
                  .astype(np.int32), r.blend)


def _dense(warped: np.ndarray, src_tris: np.ndarray, pos: np.ndarray, tris: np.ndarray, *,
           offset: int, min_cos: float, prepared: Surface | None = None) -> _Dense:
    target_surface = surface(pos, tris) if prepared is None else prepared
    projected = closest_points(target_surface, warped,
                               normals=vertex_normals(warped, src_tris), min_cos=min_cos)
    guide = projected.points
    guide_surface = surface(guide, src_tris)
    match = closest_points(guide_surface, pos, normals=vertex_normals(pos, tris),
                           min_cos=min_cos)
    return _Dense(offset, guide, guide_surface, match, cKDTree(pos))


def _carry(source: Face, name: str, tps: ThinPlateSpline, warped: np.ndarray) -> np.ndarray:
    ids = source.parts[name].vertex_ids
    if name in _EYE_LIDS:
        centre = source.pivots[name]
        scale = abs(float(np.linalg.det(tps.jacobian(centre)[0]))) ** (1 / 3)
        return (_eye_centre(source, name, tps)
                + scale * (source.vertices[ids].astype(np.float64) - centre))
    return warped[ids]


def _eye_centre(source: Face, name: str, tps: ThinPlateSpline) -> np.ndarray:
    """``T(centre)`` of a carried eyeball (3,), placed against the warped upper and lower
    lid points as the source's lies against its own: its height at the same share of the
    way from the lower to the upper lid point, its depth the same distance behind their
    mean, times the warp's local scale (as the eyeball's radius). A warp with few landmarks
    about the eye (automatic ones, without pupils) may otherwise sink the eyeball in its
    opening or push it through the lids, and the closed lids would not cover it."""
    centre = source.pivots[name].astype(np.float64)
    moved = tps(centre)[0]
    if not all(k in source.feature_points for k in _EYE_LIDS[name]):
        return moved
    upper, lower = (source.vertices[source.feature_points[k]].astype(np.float64)
                    for k in _EYE_LIDS[name])
    if abs(upper[1] - lower[1]) < 1e-12:
        return moved
    share = (centre[1] - lower[1]) / (upper[1] - lower[1])
    up, low = tps(np.vstack([upper, lower]))
    scale = abs(float(np.linalg.det(tps.jacobian(centre)[0]))) ** (1 / 3)
    moved[1] = low[1] + share * (up[1] - low[1])
    moved[2] = (up[2] + low[2]) / 2 - scale * ((upper[2] + lower[2]) / 2 - centre[2])
    return moved


def _part_ranges(names: tuple[str, ...], positions: list[np.ndarray]
                 ) -> dict[str, np.ndarray]:
    out, start = {}, 0
    for name, pos in zip(names, positions, strict=True):
        out[name] = np.arange(start, start + len(pos))
        start += len(pos)
    return out


def _pivots(source: Face, tps: ThinPlateSpline, blocks: Mapping[str, object],
            positions: list[np.ndarray]) -> dict[str, np.ndarray]:
    out = {name: tps(p)[0] for name, p in source.pivots.items()}
    for k, name in enumerate(PART_NAMES[1:3], start=1):
        if not isinstance(blocks[name], _Dense):  # carried: about its placed centre
            out[name] = _eye_centre(source, name, tps)
        else:  # the target's own eyeball
            centre, radius = _sphere(positions[k])
            if np.linalg.norm(out[name] - centre) > _EYE_CENTRE_TOLERANCE * radius:
                out[name] = centre
    return out


def _sphere(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares sphere through ``points (n, 3)``: centre (3,) and radius."""
    a = np.c_[2 * points, np.ones(len(points))]
    b = np.sum(points * points, axis=1)
    sol = np.linalg.lstsq(a, b, rcond=None)[0]
    centre = sol[:3]
    return centre, float(np.sqrt(max(sol[3] + centre @ centre, 0.0)))


def _closed_lids(regions: tuple[Region, ...], *, verts: np.ndarray, skin: np.ndarray,
                 points: Mapping[str, int], pivots: Mapping[str, np.ndarray],
                 eyes: Mapping[str, np.ndarray]) -> tuple[Region, ...]:
    """The upper eyelid regions refitted to close over the target's eye opening
    (:func:`facelib.engine.setup.eyelids.close_upper_lid`). verts: (V, 3) output positions;
    skin: (F, 3) skin triangles; eyes: eye part name -> its vertex ids."""
    fapu = compute_fapu(verts, points)
    out = []
    for region in regions:
        fp_id = region.feature_points[0] if region.feature_points else ""
        info = next((f for f in fap_table() if f.fapu == "IRISD" and f.direction[1] < 0
                     and f.feature_points == (fp_id,)), None)
        if region.deformer != "eyelid" or info is None or region.pivot not in eyes:
            out.append(region)
            continue
        centre = pivots[region.pivot]
        full = rigid.hinge_angle(verts[points[fp_id]], centre,
                                 np.array([FAPU_SCALE * fapu[info.fapu] * info.direction[1]]))[0]
        radius = float(np.linalg.norm(verts[eyes[region.pivot]] - centre, axis=1).max())
        out.append(close_upper_lid(region, vertices=verts, triangles=skin, centre=centre,
                                   radius=radius, full_angle=float(full)))
    return tuple(out)


def _neck(source: Face, tps: ThinPlateSpline) -> tuple[np.ndarray, np.ndarray, float]:
    point, normal, blend = source.neck
    jac = tps.jacobian(point)[0]
    moved = np.linalg.solve(jac.T, normal)
    scale = abs(float(np.linalg.det(jac))) ** (1 / 3)
    return tps(point)[0], moved / np.linalg.norm(moved), blend * scale


class _Mapper:
    """Maps source vertex sets and fields onto the output mesh, part by part."""

    def __init__(self, blocks: Mapping[str, object], part_of: np.ndarray,
                 local_of: np.ndarray, warped: np.ndarray,
                 names: tuple[str, ...] = PART_NAMES):
        self.blocks = blocks
        self.part_of = part_of
        self.local_of = local_of
        self.names = names
        self.warped = warped  # (V, 3) the source's vertices through the warp

    def around(self, block: _Dense, sub: np.ndarray) -> np.ndarray:
        """Local ids of the target part's vertices within the warped extent of the source
        vertices ``sub`` (their centroid's and largest distance from it, through the warp),
        or the 8 nearest to that centroid when the ball holds fewer than 2."""
        pts = self.warped[sub]
        centre = pts.mean(axis=0)
        found = np.asarray(block.tree.query_ball_point(
            centre, float(np.linalg.norm(pts - centre, axis=1).max())), np.int64)
        if found.size < 2:
            found = np.atleast_1d(block.tree.query(centre, k=min(8, block.tree.n))[1])
        return np.unique(found).astype(np.int64)

    def _by_part(self, ids: np.ndarray) -> dict[str, np.ndarray]:
        parts = self.part_of[ids]
        return {name: ids[parts == name] for name in self.names if (parts == name).any()}

    def nearest(self, ids: np.ndarray) -> np.ndarray:
        """Output vertex nearest to each source vertex's guide position (or its copy)."""
        out = np.zeros(ids.size, np.int64)
        parts = self.part_of[ids]
        for name, sub in self._by_part(ids).items():
            block = self.blocks[name]
            local = self.local_of[sub]
            if isinstance(block, _Dense):
                _, hit = block.tree.query(block.guide[local])
                out[parts == name] = block.offset + np.asarray(hit)
            else:
                assert isinstance(block, _Carried)
                out[parts == name] = block.offset + local
        return out

    def feature_points(self, points: Mapping[str, int],
                       given: Mapping[str, tuple[str, int]]) -> dict[str, int]:
        """Each feature point on its own output vertex (given landmark vertices first)."""
        out: dict[str, int] = {}
        taken: set[int] = set()
        for fp_id, (part, vertex) in given.items():
            block = self.blocks[part]
            if part == self.part_of[points[fp_id]] and isinstance(block, _Dense):
                out[fp_id] = block.offset + vertex
                taken.add(out[fp_id])
        for fp_id, v in points.items():
            if fp_id in out:
                continue
            block = self.blocks[str(self.part_of[v])]
            if isinstance(block, _Carried):
                out[fp_id] = block.offset + int(self.local_of[v])
                continue
            assert isinstance(block, _Dense)
            k = min(8, block.tree.n)
            _, hits = block.tree.query(block.guide[self.local_of[v]], k=k)
            free = [int(h) + block.offset for h in np.atleast_1d(hits)
                    if int(h) + block.offset not in taken]
            out[fp_id] = free[0] if free else int(np.atleast_1d(hits)[0]) + block.offset
            taken.add(out[fp_id])
        return out

    def region(self, region: Region, points: Mapping[str, int]) -> Region:
        members, weights, moves = [], [], []
        for name, sub in self._by_part(region.vertices.astype(np.int64)).items():
            block = self.blocks[name]
            if isinstance(block, _Carried):
                members.append(block.offset + self.local_of[sub])
                if region.weights.size:
                    weights.append(region.weights[np.isin(region.vertices, sub)])
                if region.displacements.size:
                    moves.append(region.displacements[np.isin(region.vertices, sub)])
                continue
            assert isinstance(block, _Dense)
            indicator = np.zeros(block.guide.shape[0])
            indicator[self.local_of[sub]] = 1.0
            inside = block.match.interpolate(block.guide_surface, indicator)
            keep = np.flatnonzero(inside >= 0.5)
            if keep.size < min(2, sub.size):  # too small for this mesh, or carried onto
                keep = self.around(block, sub)  # next to nothing (far from the landmarks)
            members.append(block.offset + keep)
            if region.weights.size:
                field = np.zeros(block.guide.shape[0])
                field[self.local_of[sub]] = region.weights[np.isin(region.vertices, sub)]
                value = block.match.interpolate(block.guide_surface, field)[keep]
                weights.append(np.clip(value, 0.0, 1.0))
            if region.displacements.size:  # a learned field: each axis like a weight
                # (0 at non-members, like the weights: not renormalised by `inside`)
                axes = []
                for axis in range(3):
                    field = np.zeros(block.guide.shape[0])
                    field[self.local_of[sub]] = region.displacements[
                        np.isin(region.vertices, sub), axis]
                    value = block.match.interpolate(block.guide_surface, field)[keep]
                    axes.append(value)
                moves.append(np.stack(axes, axis=1))
        ids = np.concatenate(members)
        order = np.argsort(ids, kind="stable")
        ids, first = np.unique(ids[order], return_index=True)
        w = np.concatenate(weights)[order][first] if weights else np.zeros(0)
        d = (np.concatenate(moves)[order][first] if moves
             else np.zeros((0, 3))).astype(np.float32)
        if region.deformer == "field":
            ids, d = _with_point(ids, d, points[region.feature_points[0]], self)
        anchors = np.zeros(0, np.int64)
        if region.anchors.size:
            controls = [points[f] for f in region.feature_points]
            anchors = np.setdiff1d(self.nearest(region.anchors.astype(np.int64)),
                                   np.concatenate([ids, controls]))
        return Region(name=region.name, deformer=region.deformer,
                      feature_points=region.feature_points, vertices=ids.astype(np.int32),
                      anchors=anchors.astype(np.int32), weights=w.astype(np.float32),
                      pivot=region.pivot, params=region.params, group=region.group,
                      custom=region.custom, displacements=d)


def _with_point(ids: np.ndarray, moves: np.ndarray, point: int, mapper: object
                ) -> tuple[np.ndarray, np.ndarray]:
    """A transferred field keeps its feature point as a member: if the mapped members miss
    it, it joins with the displacement of the nearest member."""
    if np.isin(point, ids):
        return ids, moves
    del mapper
    at = int(np.searchsorted(ids, point))
    near = min(max(at, 0), len(ids) - 1)
    return (np.insert(ids, at, point),
            np.insert(moves, at, moves[near] if len(moves) else 0.0, axis=0))
