"""A user's head mesh for face set-up: reading (through trimesh), parts, validation.

A head mesh is the skin plus, when the file has them as separate objects, eyeballs, teeth
and tongue. Objects are recognised by name (``eye``, ``teeth``/``tooth``, ``tongue``; left
and right eyes by the side of the face they sit on, upper and lower teeth by height) or
named by the user; everything else is skin.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from facelib.engine.mesh_files import ConfinedFiles, check_mesh_file
from facelib.errors import FaceModelError
from facelib.optional import require

__all__ = ["AXES", "MESH_SUFFIXES", "HeadMesh", "axes_rotation", "head_mesh", "load_head_mesh"]

AXES = {"+x": (1.0, 0.0, 0.0), "-x": (-1.0, 0.0, 0.0), "+y": (0.0, 1.0, 0.0),
        "-y": (0.0, -1.0, 0.0), "+z": (0.0, 0.0, 1.0), "-z": (0.0, 0.0, -1.0)}
"""Axis names for a mesh's up and forward directions."""

MAX_COORDINATE = 1e6
"""Largest vertex coordinate accepted, in the file's unit (a head is about 300 in mm, 3e5
in micrometres); beyond it distances overflow in the set-up's squares and kernels."""

MESH_SUFFIXES = (".obj", ".ply", ".glb", ".gltf", ".off", ".stl")
_PART_WORDS = (("tongue", r"tongue"), ("teeth", r"teeth|tooth"),
               ("eye", r"eye(?!brow|lash|lid)"))


@dataclass(frozen=True, eq=False)
class HeadMesh:
    """A head mesh in its own unit and frame.

    vertices: (V, 3) float64. triangles: (F, 3) int64.
    parts: part name (``skin``, ``eye_l``, ``eye_r``, ``teeth_upper``, ``teeth_lower``,
        ``tongue``) -> (Vp,) int64 vertex ids; ``skin`` always, the others when present.
    colors: (V, 3) float64 RGB in [0, 1], or None when the file has no vertex colours.
    name: where it came from (file name), for messages.
    repairs: what :func:`head_mesh` repaired, one line each ("dropped 30 zero-area
        triangles"); empty when the mesh was clean.
    """

    vertices: np.ndarray
    triangles: np.ndarray
    parts: Mapping[str, np.ndarray] = field(default_factory=dict)
    colors: np.ndarray | None = None
    name: str = "mesh"
    repairs: tuple[str, ...] = ()

    def rotated(self, rotation: np.ndarray) -> HeadMesh:
        """The same mesh with every vertex turned by ``rotation (3, 3)`` (``v -> R v``)."""
        return HeadMesh(self.vertices @ np.asarray(rotation, np.float64).T, self.triangles,
                        self.parts, self.colors, self.name, self.repairs)

    def part_triangles(self, name: str) -> np.ndarray:
        """(Fp, 3) int64 triangles of a part, re-indexed into ``parts[name]``."""
        ids = self.parts[name]
        local = np.full(len(self.vertices), -1, np.int64)
        local[ids] = np.arange(ids.size)
        tris = local[self.triangles]
        return tris[(tris >= 0).all(axis=1)]


def axes_rotation(up: str = "+y", forward: str = "+z") -> np.ndarray:
    """The rotation ``(3, 3)`` that turns a mesh whose face points ``forward`` with ``up``
    upwards into facelib's frame (+y up, looking along +z, +x the face's left).

    Raises ParameterError for an unknown axis name or an ``up`` not at right angles to
    ``forward``.
    """
    from facelib.errors import ParameterError

    for name, value in (("up", up), ("forward", forward)):
        if value not in AXES:
            raise ParameterError(f"{name} axis {value!r} is not one of {', '.join(AXES)}")
    u, f = np.array(AXES[up]), np.array(AXES[forward])
    if abs(float(u @ f)) > 0:
        raise ParameterError(f"up {up} and forward {forward} must be at right angles")
    return np.stack([np.cross(u, f), u, f])


def head_mesh(vertices: Any, triangles: Any, *, parts: Mapping[str, Any] | None = None,
              colors: Any = None, name: str = "mesh") -> HeadMesh:
    """Validate arrays into a :class:`HeadMesh`; vertices not in a named part are skin.

    Repairs what mesh tools repair, noting each in ``repairs``: vertices at the same place
    in the same part are merged, and zero-area triangles (a repeated vertex, or three in a
    line) and second copies of a triangle are dropped. Raises FaceModelError for malformed
    arrays and for what cannot be repaired: a skin with non-manifold edges (used by more
    than two triangles), inconsistent winding, or no shared edges at all.
    """
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles)
    if v.ndim != 2 or v.shape[1] != 3 or len(v) < 4 or not np.all(np.isfinite(v)):
        raise FaceModelError(f"{name}: vertices must be finite (V >= 4, 3), got {v.shape}")
    if np.abs(v).max() > MAX_COORDINATE:
        bad = int(np.argmax(np.abs(v).max(axis=1)))
        raise FaceModelError(f"{name}: vertex {bad} is at {v[bad].tolist()}, beyond "
                             f"{MAX_COORDINATE:g} units from the origin in a coordinate; "
                             "is the file's unit or an outlier wrong?")
    if t.ndim != 2 or t.shape[1] != 3 or not len(t) or t.dtype.kind not in "iu":
        raise FaceModelError(f"{name}: triangles must be integer (F, 3), got {t.dtype} {t.shape}")
    t = t.astype(np.int64)
    if t.min() < 0 or t.max() >= len(v):
        raise FaceModelError(f"{name}: triangle index {int(t.max())} is outside 0-{len(v) - 1}")
    named = {k: np.unique(np.asarray(ids, dtype=np.int64)) for k, ids in (parts or {}).items()}
    used = np.zeros(len(v), bool)
    for ids in named.values():
        used[ids] = True
    if "skin" not in named:
        named["skin"] = np.flatnonzero(~used)
    c = None if colors is None else np.clip(np.asarray(colors, dtype=np.float64)[:, :3], 0, 1)
    v, t, named, c, merged = _merge_duplicates(v, t, named, c)
    t, degenerate, repeated = _drop_bad_triangles(v, t)
    repairs = tuple(note for count, note in (
        (merged, f"merged {merged} duplicate vertices"),
        (degenerate, f"dropped {degenerate} zero-area triangles"),
        (repeated, f"dropped {repeated} duplicate triangles")) if count)
    if not len(t):
        raise FaceModelError(f"{name}: every triangle has zero area")
    mesh = HeadMesh(v, t, MappingProxyType(named), c, name, repairs)
    _check_surface(mesh)
    return mesh


def _merge_duplicates(
    v: np.ndarray, t: np.ndarray, parts: dict[str, np.ndarray], colors: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray], np.ndarray | None, int]:
    """Vertices at exactly the same place in the same part merged into the first of them
    (order kept); returns the new arrays and how many vertices were merged away."""
    label = np.zeros(len(v))
    for i, ids in enumerate(parts.values()):
        label[ids] = i
    _, first, inverse = np.unique(np.column_stack([label, v]), axis=0, return_index=True,
                                  return_inverse=True)
    if len(first) == len(v):
        return v, t, parts, colors, 0
    order = np.argsort(first)
    new_id = np.empty(len(first), np.int64)
    new_id[order] = np.arange(len(first))
    remap = new_id[inverse.reshape(-1)]
    keep = first[order]
    return (v[keep], remap[t], {k: np.unique(remap[ids]) for k, ids in parts.items()},
            None if colors is None else colors[keep], len(v) - len(keep))


def _drop_bad_triangles(v: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, int, int]:
    """``t`` without zero-area triangles (a repeated vertex, or area below 1e-12 of the
    squared size of the mesh) and without second copies of a triangle (the same three
    vertices in any order); returns it and how many of each were dropped."""
    size = float(np.ptp(v, axis=0).max()) or 1.0
    area = np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1)
    flat = (t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 2] == t[:, 0]) | (
        area <= 1e-12 * size * size)
    t = t[~flat]
    _, first = np.unique(np.sort(t, axis=1), axis=0, return_index=True)
    repeated = len(t) - len(first)
    return t[np.sort(first)], int(flat.sum()), repeated


def _check_surface(mesh: HeadMesh) -> None:
    tris = mesh.part_triangles("skin")
    if len(tris) < 4:
        raise FaceModelError(f"{mesh.name}: the skin has {len(tris)} triangles; is it a head?")
    directed = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    undirected, counts = np.unique(np.sort(directed, axis=1), axis=0, return_counts=True)
    skin = mesh.parts["skin"]
    if (counts > 2).any():
        a, b = (int(skin[i]) for i in undirected[np.argmax(counts > 2)])
        raise FaceModelError(
            f"{mesh.name}: the skin is non-manifold: {int((counts > 2).sum())} edges are "
            f"shared by more than two triangles (first: vertices {a}-{b}); separate the "
            "objects or repair the mesh (e.g. Blender's Select > All by Trait > Non Manifold)")
    if (counts == 1).all():
        raise FaceModelError(
            f"{mesh.name}: no two triangles of the skin share an edge (an unwelded 'triangle "
            "soup'); merge duplicate vertices before set-up")
    same, twice = np.unique(directed, axis=0, return_counts=True)
    if (twice > 1).any():
        a, b = (int(skin[i]) for i in same[np.argmax(twice > 1)])
        raise FaceModelError(
            f"{mesh.name}: the skin's triangles are not wound consistently "
            f"({int((twice > 1).sum())} edges run the same way in both triangles; first: "
            f"vertices {a}-{b}); recalculate the normals outside")


def _classify(name: str) -> str:
    """The kind of part an object's name says: ``tongue``, ``teeth``, ``eye`` or ``skin``."""
    lower = name.lower()
    for kind, pattern in _PART_WORDS:
        if re.search(pattern, lower):
            return kind
    return "skin"


def _eye_sides(meshes: list[tuple[str, Any]], wanted: Mapping[str, str]) -> dict[str, str]:
    """``eye_l`` or ``eye_r`` for each object named like an eye (and not named by the
    user), told by the side of the face's own midline it sits on (+x is the face's left):
    the midline between the two eyes when there are two, else the middle of the skin's
    width. A head modelled off the origin keeps one eye on each side."""
    eyes = [(name, float(np.asarray(m.vertices)[:, 0].mean())) for name, m in meshes
            if name not in wanted and _classify(name) == "eye"]
    if len(eyes) == 2:
        midline = (eyes[0][1] + eyes[1][1]) / 2
    else:
        skin = [np.asarray(m.vertices)[:, 0] for name, m in meshes
                if name not in wanted and _classify(name) == "skin"]
        xs = np.concatenate(skin) if skin else np.zeros(1)
        midline = (float(xs.min()) + float(xs.max())) / 2
    return {name: "eye_l" if x > midline else "eye_r" for name, x in eyes}


def _trimesh() -> Any:
    return require("trimesh")


_PARSER_SLIPS = (IndexError, KeyError, AttributeError, TypeError, NameError, AssertionError,
                 ZeroDivisionError)
"""Exceptions a mesh parser raises when a file breaks its assumptions rather than to say
what is wrong (``'attributes'``, ``list index out of range``, or no message at all)."""


def _reason(exc: Exception, path: Path) -> str:
    """One line saying why a mesh reader failed: its own message when it gave one, and
    that the file is malformed, naming the format and the parser's exception, when it
    slipped over the file or said nothing."""
    text = " ".join(str(exc).split())[:200]
    if text and text not in ("None", "''") and not isinstance(exc, _PARSER_SLIPS):
        return text
    detail = f"{type(exc).__name__}: {text}" if text else type(exc).__name__
    return (f"the {path.suffix.lower().lstrip('.').upper()} file is malformed or uses a "
            f"feature the reader does not support ({detail})")


def load_head_mesh(path: str | Path, *, parts: Mapping[str, str] | None = None) -> HeadMesh:
    """Read a head mesh file (OBJ, PLY, GLB/glTF, OFF, STL) with trimesh.

    parts: optional facelib part name -> object name in the file (overrides recognition
        by name). Objects named like eyes, teeth or tongue become those parts; two teeth
        objects split into upper and lower by height; everything else is skin.

    Raises FaceModelError for unreadable files, unknown formats, empty meshes, an
    object name given in ``parts`` that the file does not have, or a file the mesh refers
    to (texture, material library, buffer) outside its folder (see
    :mod:`facelib.engine.mesh_files`).
    """
    path = Path(path)
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise FaceModelError(f"unknown mesh format {path.suffix!r}; use one of "
                             f"{', '.join(MESH_SUFFIXES)}", path=path)
    check_mesh_file(path)
    trimesh = _trimesh()
    files = ConfinedFiles(path)
    try:
        # OBJ: every object (o) and group (g) its own mesh, so separate eyeballs stay parts
        split = ({"split_objects": True, "split_groups": True}
                 if path.suffix.lower() == ".obj" else {})
        scene = trimesh.load(path, force="scene", process=True, resolver=files, **split)
    except FaceModelError:
        raise
    except Exception as exc:
        files.check()
        raise FaceModelError(f"cannot read the mesh: {_reason(exc, path)}", path=path) from exc
    files.check()
    dumped = _scene_meshes(scene)
    if path.suffix.lower() == ".obj":
        dumped = _obj_piece_names(dumped, path)
    if not dumped:
        raise FaceModelError("the file holds no triangles", path=path)
    wanted = {obj: part for part, obj in (parts or {}).items()}
    missing = set(wanted) - {n for n, _ in dumped}
    if missing:
        raise FaceModelError(f"the file has no object {sorted(missing)[0]!r}; it has "
                             f"{sorted(n for n, _ in dumped)}", path=path)
    return _assemble(dumped, wanted, path)


def _obj_piece_names(pieces: list[tuple[str, Any]], path: Path) -> list[tuple[str, Any]]:
    """``pieces`` named as the OBJ file names them: trimesh calls a group ``g`` inside an
    object ``o`` "o_g"; such a piece takes the group's name (unless two would share it)."""
    groups = set()
    with path.open(encoding="utf-8", errors="replace") as file:
        for line in file:
            if line.startswith("g "):
                groups.add(" ".join(line.split()[1:]))
    renamed = []
    for name, mesh in pieces:
        matches = [g for g in groups if g and (name == g or name.endswith("_" + g))]
        renamed.append((max(matches, key=len) if matches else name, mesh))
    if len({n for n, _ in renamed}) < len(renamed):
        return pieces
    return renamed


def _scene_meshes(scene: Any) -> list[tuple[str, Any]]:
    """(object name, Trimesh in world coordinates) for every triangle mesh of a scene."""
    out = []
    for node in scene.graph.nodes_geometry:
        transform, geom_name = scene.graph[node]
        geom = scene.geometry[geom_name]
        if not hasattr(geom, "faces") or not len(geom.faces):
            continue
        mesh = geom.copy()
        mesh.apply_transform(transform)
        out.append((str(node), mesh))
    return out


def _assemble(meshes: list[tuple[str, Any]], wanted: Mapping[str, str], path: Path) -> HeadMesh:
    verts, tris, cols, kinds = [], [], [], []
    offset = 0
    has_colour = False
    sides = _eye_sides(meshes, wanted)
    for name, mesh in meshes:
        v = np.asarray(mesh.vertices, dtype=np.float64)
        kind = wanted.get(name) or sides.get(name) or _classify(name)
        kinds.append((kind, offset, offset + len(v), float(v[:, 1].mean())))
        verts.append(v)
        tris.append(np.asarray(mesh.faces, dtype=np.int64) + offset)
        colour = _vertex_colours(mesh)
        has_colour |= colour is not None
        cols.append(np.full((len(v), 3), 0.8) if colour is None else colour)
        offset += len(v)
    parts: dict[str, list[np.ndarray]] = {}
    teeth = sorted((k for k in kinds if k[0] == "teeth"), key=lambda k: -k[3])
    for kind, start, stop, _ in kinds:
        part = kind
        if kind == "teeth":
            part = "teeth_upper" if (start, stop) == teeth[0][1:3] else "teeth_lower"
        parts.setdefault(part, []).append(np.arange(start, stop))
    return head_mesh(np.concatenate(verts), np.concatenate(tris),
                     parts={k: np.concatenate(v) for k, v in parts.items()},
                     colors=np.concatenate(cols) if has_colour else None, name=path.name)


def _vertex_colours(mesh: Any) -> np.ndarray | None:
    visual = getattr(mesh, "visual", None)
    if visual is None or getattr(visual, "kind", None) != "vertex":
        return None
    colours = np.asarray(visual.vertex_colors, dtype=np.float64)[:, :3] / 255.0
    return colours if len(colours) == len(mesh.vertices) else None
