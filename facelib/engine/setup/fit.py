"""Face set-up: make any reasonable head mesh animatable from a few landmarks.

``setup_face(mesh, landmarks=...)`` finds the mesh's unit and orientation from the
landmarks, fits the thin-plate spline from the source face's feature points to them, and
transfers the source's whole face definition (see :mod:`facelib.engine.setup.transfer`).
``write_face`` stores the result as a normal face definition JSON plus mesh.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, overload

import numpy as np

from facelib.engine.definition import default_face
from facelib.engine.face import Face
from facelib.engine.setup.headmesh import HeadMesh, axes_rotation, load_head_mesh
from facelib.engine.setup.tps import ThinPlateSpline, check_landmarks, fit_tps
from facelib.engine.setup.transfer import transfer_face
from facelib.engine.surface import Surface, closest_points, surface
from facelib.errors import FaceModelError, ParameterError

__all__ = ["UNITS", "FaceSetup", "read_landmarks", "setup_face"]

_Mesh = HeadMesh | str | Path
_Marks = Mapping[str, Any] | str | Path

# length units a head mesh may come in: metres per unit
UNITS = {"m": 1.0, "dm": 0.1, "cm": 0.01, "mm": 0.001, "in": 0.0254}
_REORIENT_DEG = 5.0  # rotations of the landmarks beyond this are undone (face frame)
_OFF_SURFACE = 0.03  # a landmark this far off the mesh (x the landmarks' extent) is an error


@dataclass(frozen=True, eq=False)
class FaceSetup:
    """What ``setup_face(..., report=True)`` returns: the Face and how it was made.

    face: the new Face (metres, facelib's face frame).
    unit: the mesh unit used (a key of ``UNITS``).
    rotation: (3, 3) float64 rotation applied to the mesh, the given axes' included
        (identity if it was upright).
    carried: parts of the face the mesh lacked (lashes always), warped into place from
        the source (its attached bust, garment and hair are not: they fit the source head).
    landmarks: feature point ids used as landmarks, in fit order.
    residual: (n,) float64 metres: each landmark's distance to the mesh surface as given.
    tps: the fitted warp (source feature points -> the landmarks).
    """

    face: Face
    unit: str
    rotation: np.ndarray
    carried: tuple[str, ...]
    landmarks: tuple[str, ...]
    residual: np.ndarray
    tps: ThinPlateSpline


def read_landmarks(path: str | Path) -> dict[str, Any]:
    """A landmark JSON file: ``{"9.3": 1234, "2.1": [x, y, z], ...}`` (or under a
    ``"landmarks"`` key); values are vertex indices or points in the mesh's unit."""
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise FaceModelError(f"cannot read landmarks: {exc.strerror}", path=path) from exc
    except json.JSONDecodeError as exc:
        raise FaceModelError(f"invalid JSON: {exc.msg}", path=path, line=exc.lineno) from exc
    if isinstance(doc, dict) and isinstance(doc.get("landmarks"), dict):
        doc = doc["landmarks"]
    if not isinstance(doc, dict):
        raise FaceModelError("landmarks must be an object of feature point -> vertex or "
                             "[x, y, z]", path=path)
    return doc


def _landmark_points(mesh: HeadMesh, landmarks: Mapping[str, Any], source: Face
                     ) -> tuple[list[str], np.ndarray, dict[str, tuple[str, int]]]:
    ids, points, vertices = [], [], {}
    for key, value in landmarks.items():
        fp_id = str(key)
        if fp_id not in source.feature_points:
            raise FaceModelError(f"landmark {fp_id!r} is not a feature point of the source "
                                 f"face (it has {', '.join(source.feature_points)})")
        if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
            if not 0 <= int(value) < len(mesh.vertices):
                raise FaceModelError(f"landmark {fp_id}: vertex {value} is outside "
                                     f"0-{len(mesh.vertices) - 1}")
            point = mesh.vertices[int(value)]
            for part, part_ids in mesh.parts.items():
                at = int(np.searchsorted(part_ids, int(value)))
                if at < part_ids.size and part_ids[at] == int(value):
                    vertices[fp_id] = (part, at)
        else:
            try:
                point = np.asarray(value, dtype=np.float64).reshape(3)
            except (TypeError, ValueError) as exc:
                raise FaceModelError(f"landmark {fp_id} is {value!r}, not a vertex index or "
                                     "[x, y, z]") from exc
        ids.append(fp_id)
        points.append(point)
    pts = check_landmarks(np.array(points).reshape(-1, 3), what="landmarks")
    return ids, pts, vertices


def _similarity(src: np.ndarray, dst: np.ndarray) -> tuple[float, np.ndarray]:
    """Scale and rotation of the best similarity ``dst ~ s R src + t`` (Umeyama)."""
    a, b = src - src.mean(0), dst - dst.mean(0)
    u, sv, vt = np.linalg.svd(b.T @ a)
    d = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt))])
    rot = u @ d @ vt
    return float(np.trace(np.diag(sv) @ d) / np.sum(a * a)), rot


def _unit(scale: float, unit: str | None, extent: float) -> str:
    """The mesh unit: given and checked, or the one that makes the head life-sized."""
    def misfit(name: str) -> float:
        return abs(math.log(scale * UNITS[name]))

    best = min(UNITS, key=misfit)
    if unit is None:
        unit = best
    elif unit not in UNITS:
        raise ParameterError(f"unit {unit!r} is not one of {', '.join(UNITS)}")
    if misfit(unit) > math.log(2.0):
        raise FaceModelError(
            f"the landmarks span {extent:g} mesh units, which in {unit} makes a head "
            f"{1 / (scale * UNITS[unit]):.3g} times the size of the source face; the mesh "
            f"looks like it is in {best} (pass unit={best!r}) or the landmarks are wrong")
    return unit


def set_up_face(mesh: HeadMesh | str | Path, *, landmarks: Mapping[str, Any] | str | Path,
                source: Face | None = None, unit: str | None = None,
                up: str | None = None, forward: str | None = None,
                min_normal_cos: float = 0.5) -> FaceSetup:
    """``setup_face(..., report=True)`` by its older name (docs/own-head.md showed it)."""
    src = default_face() if source is None else source
    head = mesh if isinstance(mesh, HeadMesh) else load_head_mesh(mesh)
    marks = read_landmarks(landmarks) if isinstance(landmarks, (str, Path)) else landmarks
    given = np.eye(3)
    if up is not None or forward is not None:
        given = axes_rotation(up or "+y", forward or "+z")
        head = head.rotated(given)
        marks = {k: v if isinstance(v, (int, np.integer)) else
                 (given @ np.asarray(v, np.float64).reshape(3)).tolist()
                 for k, v in marks.items()}
    ids, points, vertices = _landmark_points(head, marks, src)
    source_points = src.vertices[[src.feature_points[i] for i in ids]].astype(np.float64)
    scale, rot = _similarity(source_points, points)
    unit = _unit(scale, unit, float(np.ptp(points, axis=0).max()))
    factor = UNITS[unit]
    angle = math.degrees(math.acos(np.clip((np.trace(rot) - 1) / 2, -1, 1)))
    rotation = rot.T if angle > _REORIENT_DEG else np.eye(3)
    if factor != 1.0 or angle > _REORIENT_DEG:
        points = (points * factor) @ rotation.T
        head = HeadMesh((head.vertices * factor) @ rotation.T, head.triangles, head.parts,
                        head.colors, head.name)
    skin = surface(head.vertices[head.parts["skin"]], head.part_triangles("skin"))
    residual = _residuals(skin, ids, points, src)
    tps = fit_tps(source_points, points)
    face = transfer_face(src, head, tps, vertices, min_cos=min_normal_cos, skin=skin)
    # every part of the face the mesh did not hold, lashes included (always the source's)
    carried = tuple(p for p in face.parts if p not in head.parts)
    return FaceSetup(face=face, unit=unit, rotation=rotation @ given, carried=carried,
                     landmarks=tuple(ids), residual=residual, tps=tps)


def _residuals(skin: Surface, ids: Sequence[str], points: np.ndarray, src: Face) -> np.ndarray:
    """Distance of each landmark to the ``skin`` surface; an error for one clearly off it."""
    on_skin = np.isin([src.feature_points[i] for i in ids], src.parts["skin"].vertex_ids)
    dist = np.zeros(len(ids))
    if on_skin.any():
        dist[on_skin] = closest_points(skin, points[on_skin]).distance
    limit = _OFF_SURFACE * float(np.ptp(points, axis=0).max())
    worst = int(np.argmax(dist))
    if dist[worst] > limit:
        raise FaceModelError(
            f"landmark {ids[worst]} is {dist[worst] * 1000:.1f} mm off the mesh surface "
            f"(at most {limit * 1000:.1f} mm); place it on the skin or give a vertex index")
    return dist


@overload
def setup_face(mesh: _Mesh, *, landmarks: _Marks, source: Face | None = ...,
               unit: str | None = ..., up: str | None = ..., forward: str | None = ...,
               min_normal_cos: float = ..., report: Literal[False] = ...) -> Face: ...


@overload
def setup_face(mesh: _Mesh, *, landmarks: _Marks, source: Face | None = ...,
               unit: str | None = ..., up: str | None = ..., forward: str | None = ...,
               min_normal_cos: float = ..., report: Literal[True]) -> FaceSetup: ...


def setup_face(mesh: _Mesh, *, landmarks: _Marks, source: Face | None = None,
               unit: str | None = None, up: str | None = None, forward: str | None = None,
               min_normal_cos: float = 0.5, report: bool = False) -> Face | FaceSetup:
    """Make a head mesh animatable: the source's face definition transferred onto it.

    Parameters
    ----------
    mesh: a mesh file (OBJ, PLY, GLB/glTF, OFF, STL) or a :class:`HeadMesh`.
    landmarks: feature point id -> vertex index or ``[x, y, z]`` in the mesh's unit (a
        dict, or the path of such a JSON file); at least 4 not in one plane, 20-35 well
        spread ones recommended (see ``docs/own-head.md``).
    source: the face whose definition is transferred (default: facelib's default head).
    unit: the mesh's length unit (``m``, ``dm``, ``cm``, ``mm``, ``in``); guessed from the
        landmarks' size when None.
    up, forward: the mesh's up axis and the way its face looks (``"+z"``, ``"-y"``, ...);
        when both are None the orientation is guessed from the landmarks.
    min_normal_cos: the normal check of the closest-point steps.
    report: return a :class:`FaceSetup` (the Face with the unit, rotation, carried parts,
        landmark residuals and fitted warp) instead of the Face alone.

    Returns a Face in metres in facelib's face frame (a mesh whose landmarks are rotated
    more than 5 degrees from it is turned upright).

    Raises FaceModelError for a non-manifold or unwelded mesh, too few, duplicate or
    coplanar landmarks, a landmark off the surface, or a mesh in the wrong unit.
    """
    result = set_up_face(mesh, landmarks=landmarks, source=source, unit=unit, up=up,
                         forward=forward, min_normal_cos=min_normal_cos)
    return result if report else result.face

