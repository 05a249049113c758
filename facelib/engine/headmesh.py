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
from facelib.errors import FaceModelError, MissingExtraError

__all__ = ["AXES", "MESH_SUFFIXES", "HeadMesh", "axes_rotation", "head_mesh", "load_head_mesh"]

AXES = {"+x": (1.0, 0.0, 0.0), "-x": (-1.0, 0.0, 0.0), "+y": (0.0, 1.0, 0.0),
        "-y": (0.0, -1.0, 0.0), "+z": (0.0, 0.0, 1.0), "-z": (0.0, 0.0, -1.0)}
"""Axis names for a mesh's up and forward directions."""

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
    """

    vertices: np.ndarray
    triangles: np.ndarray
    parts: Mapping[str, np.ndarray] = field(default_factory=dict)
    colors: np.ndarray | None = None
    name: str = "mesh"

    def rotated(self, rotation: np.ndarray) -> HeadMesh:
        """The same mesh with every vertex turned by ``rotation (3, 3)`` (``v -> R v``)."""
        return HeadMesh(self.vertices @ np.asarray(rotation, np.float64).T, self.triangles,
                        self.parts, self.colors, self.name)

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

    Raises FaceModelError for malformed arrays, a skin with non-manifold edges (used by
    more than two triangles), inconsistent winding, or no shared edges at all.
    """
    v = np.asarray(vertices, dtype=np.float64)
    t = np.asarray(triangles)
    if v.ndim != 2 or v.shape[1] != 3 or len(v) < 4 or not np.all(np.isfinite(v)):
        raise FaceModelError(f"{name}: vertices must be finite (V >= 4, 3), got {v.shape}")
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
    mesh = HeadMesh(v, t, MappingProxyType(named), c, name)
    _check_surface(mesh)
    return mesh


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


def _classify(name: str, centre: np.ndarray) -> str:
    lower = name.lower()
    for kind, pattern in _PART_WORDS:
        if re.search(pattern, lower):
            if kind == "tongue":
                return "tongue"
            if kind == "teeth":
                return "teeth"
            return "eye_l" if centre[0] > 0 else "eye_r"
    return "skin"


def _trimesh() -> Any:
    try:
        import trimesh
    except ImportError as exc:
        raise MissingExtraError("reading head meshes", "mesh", "trimesh") from exc
    return trimesh


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
        scene = trimesh.load(path, force="scene", process=True, resolver=files)
    except FaceModelError:
        raise
    except Exception as exc:
        files.check()
        raise FaceModelError(f"cannot read the mesh: {exc}", path=path) from exc
    files.check()
    dumped = _scene_meshes(scene)
    if not dumped:
        raise FaceModelError("the file holds no triangles", path=path)
    wanted = {obj: part for part, obj in (parts or {}).items()}
    missing = set(wanted) - {n for n, _ in dumped}
    if missing:
        raise FaceModelError(f"the file has no object {sorted(missing)[0]!r}; it has "
                             f"{sorted(n for n, _ in dumped)}", path=path)
    return _assemble(dumped, wanted, path)


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
    for name, mesh in meshes:
        v = np.asarray(mesh.vertices, dtype=np.float64)
        kind = wanted.get(name) or _classify(name, v.mean(axis=0))
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
