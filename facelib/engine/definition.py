"""Reading and validating a face definition (FDP): a versioned JSON file beside its mesh.

The format is documented in ``docs/face-definition.md``. The mesh is an ``.npz`` file with
``vertices (V, 3) float``, ``triangles (F, 3) int`` and ``vertex_colors (V, 3)`` (uint8 0-255
or float 0-1).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np

from facelib import data
from facelib.engine.attachments import attach, definition_hair_styles, read_attachments
from facelib.engine.characters import face_definition
from facelib.engine.deformers import ALIASES, Deformer, deformer, deformer_names
from facelib.engine.face import (
    ATTACHED_PARTS,
    OPTIONAL_PARTS,
    PART_NAMES,
    RIGID_DEFORMERS,
    Face,
    Region,
)
from facelib.engine.meshfile import mesh_path, read_npz
from facelib.engine.riders import Riders, no_riders
from facelib.errors import FacelibError, FaceModelError, ParameterError
from facelib.mpeg4.tables import fap, fap_table, feature_point_table

__all__ = ["FORMAT", "VERSION", "hair_style_names", "load_face", "required_feature_points"]

FORMAT = "facelib-face"
VERSION = 1
PIVOTS = ("eye_l", "eye_r", "head", "jaw")
MAX_DEFINITION_BYTES = 64 * 1024 * 1024
"""Size limit of a face definition's JSON (the default head's is 250 KB; a 20-million-vertex
face's region lists fit)."""


def required_feature_points() -> tuple[str, ...]:
    """Feature points every face must place: those moved by FAP 3-84.

    7.1 (top of the spine) is exempt: head rotations use the ``head`` pivot instead.
    """
    needed = {p for f in fap_table()[2:] for p in f.feature_points} - {"7.1"}
    order = list(feature_point_table())
    return tuple(sorted(needed, key=order.index))


def _default_path() -> Path:
    return Path(str(data.path("head/default_head.json")))


def default_face() -> Face:
    """facelib's default head (metres), loaded and compiled: ``load_face(None)``."""
    return load_face(None)


Override = str | Deformer | Mapping[str, Any]
"""A deformer override: a registered name, a Deformer, or ``{"deformer": name, **params}``."""


def load_face(
    path: str | os.PathLike[str] | None = None, *, deformers: Mapping[str, Override] | None = None,
    hair: str | None = None,
) -> Face:
    """Load a face definition and its mesh, validate them and compile the deformers.

    Parameters
    ----------
    path: the JSON face definition, the name of a bundled character (``"ben"``,
        :func:`~facelib.engine.characters.character_names`) or the folder ``facelib face
        setup`` wrote; None loads facelib's default head (metres). Resolved by
        :func:`~facelib.engine.characters.face_definition` (FaceModelError with a
        did-you-mean for an unknown character name).
    deformers: overrides of the definition's deformers, keyed by region name or group
        (``{"lips": "inverse_distance", "brow_l": {"deformer": "rbf", "kernel": "gaussian"}}``);
        a region name wins over its group. A bare name keeps no parameters of the
        definition; give them in the mapping form. Every key must match a region.
    hair: a hair style of the definition's hair mesh (``"short"``, ``"long"``, ``"tied"``
        for the default head) instead of the one the definition names; ``"none"``: bald.

    Raises
    ------
    FaceModelError: unreadable or malformed file, missing feature points, out-of-range
        indices, empty regions, unknown deformers or pivots; the message names the item.
    ParameterError: an override key that names no region or group.
    """
    path = face_definition(path) or _default_path()
    return _Reader(path, _definition(path), dict(deformers or {}), hair).face()


def hair_style_names(path: str | os.PathLike[str] | None = None) -> tuple[str, ...]:
    """The hair styles the face definition at ``path`` (None: the default head) may wear,
    as ``load_face(path, hair=...)`` takes them: its hair mesh's styles, then ``"none"``.
    FaceModelError for an unreadable definition or hair mesh."""
    path = face_definition(path) or _default_path()
    doc = _definition(path)
    if not isinstance(doc, dict):
        raise FaceModelError("a face definition is a JSON object", path=path)
    return definition_hair_styles(path, doc)


def _definition(path: Path) -> Any:
    """The face definition at ``path`` with what it ``extends`` filled in: a definition
    may name another beside it (``"extends": "default_head.json"``, which must not extend
    a third) whose entries it takes for every key it does not give itself."""
    doc = _read_definition(path)
    if not isinstance(doc, dict) or "extends" not in doc:
        return doc
    name = doc["extends"]
    if not isinstance(name, str):
        raise FaceModelError(f"'extends' must be a file name, not {name!r}", path=path)
    base_path = mesh_path(path, name)
    base = _read_definition(base_path)
    if not isinstance(base, dict) or "extends" in base:
        raise FaceModelError(f"'extends' names {name!r}, which must be a face definition "
                             "that extends no other", path=path)
    return {**base, **{k: v for k, v in doc.items() if k != "extends"}}


def _read_definition(path: Path) -> Any:
    """The JSON document of the face definition at ``path`` (size, UTF-8 and syntax checked)."""
    try:
        with path.open("rb") as file:
            raw = file.read(MAX_DEFINITION_BYTES + 1)
    except OSError as exc:
        raise FaceModelError(f"cannot read face definition: {exc.strerror}", path=path) from exc
    if len(raw) > MAX_DEFINITION_BYTES:
        raise FaceModelError(f"a face definition is at most {MAX_DEFINITION_BYTES} bytes",
                             path=path)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise FaceModelError(f"not UTF-8 text (byte {exc.start})", path=path) from None
    try:
        doc = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FaceModelError(f"invalid JSON: {exc.msg}", path=path, line=exc.lineno) from exc
    except RecursionError:
        raise FaceModelError("the face definition's JSON is nested too deeply (a face "
                             "definition is a few levels deep)", path=path) from None
    return doc


def _override(value: Override, key: str) -> tuple[str, Deformer | None, dict[str, Any]]:
    """(name, custom deformer or None, params) of one override value."""
    if isinstance(value, Deformer):
        return value.name, value, {}
    if isinstance(value, str):
        return value, None, {}
    if isinstance(value, Mapping) and isinstance(value.get("deformer"), (str, Deformer)):
        params = {k: v for k, v in value.items() if k != "deformer"}
        name, custom, _ = _override(value["deformer"], key)
        return name, custom, params
    raise ParameterError(f"deformers[{key!r}] must be a deformer name, a Deformer or a "
                         f"mapping with a 'deformer' key, not {value!r}")


class _Reader:
    def __init__(self, path: Path, doc: Any, overrides: dict[str, Override],
                 hair: str | None = None):
        self.path = path
        self.hair = hair
        self.hair_uv: np.ndarray | None = None  # the mesh file's hair_uv, if any
        self.doc = doc
        self.overrides = overrides
        self.fields: dict[str, np.ndarray] = {}  # the mesh file's field_* arrays
        self.occlusion: np.ndarray | None = None  # the mesh file's vertex_ao, if any

    def fail(self, message: str) -> FaceModelError:
        return FaceModelError(message, path=self.path)

    def get(self, key: str, kind: type | tuple[type, ...]) -> Any:
        if not isinstance(self.doc, dict) or key not in self.doc:
            raise self.fail(f"the face definition has no {key!r} entry")
        value = self.doc[key]
        if not isinstance(value, kind):
            raise self.fail(f"{key!r} must be a {getattr(kind, '__name__', kind)}, not {value!r}")
        return value

    def face(self) -> Face:
        if self.get("format", str) != FORMAT:
            raise self.fail(f"format is {self.doc['format']!r}, expected {FORMAT!r}")
        version = self.get("version", int)
        if version != VERSION:
            raise self.fail(f"face definition version {version} is not supported (only {VERSION})")
        vertices, triangles, colours = self.mesh()
        nv = len(vertices)
        parts = self.parts(nv)
        points = self.feature_points(nv)
        pivots = self.pivots()
        regions = self.regions(nv, points, pivots)
        neck = self.neck()
        riders = self.riders(parts, nv)
        pieces = read_attachments(self.path, self.doc, vertices, hair=self.hair)
        vertices, triangles, colours, ao, extra, uv = attach(
            vertices, triangles, colours, self.occlusion, pieces)
        parts.update(extra)
        try:
            return Face.build(vertices=vertices, triangles=triangles, vertex_colors=colours,
                              parts=parts, feature_points=points, regions=regions, pivots=pivots,
                              neck=neck, vertex_ao=ao, riders=riders,
                              hair_uv=self.hair_uv if uv is None else uv)
        except FaceModelError as exc:
            raise self.fail(exc.message) from exc

    def mesh(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        names = self.get("mesh", (str, list))
        names = [names] if isinstance(names, str) else names
        if not names or not all(isinstance(n, str) for n in names):
            raise self.fail(f"'mesh' must be a file name or a non-empty list of them, not "
                            f"{names!r}")
        data: dict[str, np.ndarray] = {}
        for name in names:  # a later file's arrays replace an earlier one's
            data.update(read_npz(mesh_path(self.path, name)))
        mesh_file = mesh_path(self.path, names[-1])
        missing = [k for k in ("vertices", "triangles", "vertex_colors") if k not in data]
        if missing:
            raise self.fail(f"mesh {mesh_file.name!r} lacks the array {missing[0]!r}")
        self.fields = {k: a for k, a in data.items() if k.startswith("field_")}
        occlusion = data.get("vertex_ao")
        v, t, c = data["vertices"], data["triangles"], data["vertex_colors"]
        if v.ndim != 2 or v.shape[1] != 3 or not len(v) or not np.all(np.isfinite(v)):
            raise self.fail(f"mesh vertices must be finite (V, 3), got shape {v.shape}")
        if t.ndim != 2 or t.shape[1] != 3 or not np.issubdtype(t.dtype, np.integer):
            raise self.fail(f"mesh triangles must be integer (F, 3), got {t.dtype} {t.shape}")
        if t.size and (t.min() < 0 or t.max() >= len(v)):
            raise self.fail(f"mesh triangle index {int(t.max())} is outside 0-{len(v) - 1}")
        if c.shape != v.shape:
            raise self.fail(f"vertex_colors must have shape {v.shape}, got {c.shape}")
        c = c / 255.0 if np.issubdtype(c.dtype, np.integer) else c.astype(np.float64)
        self.occlusion = None if occlusion is None else self.occlusion_values(occlusion, len(v))
        uv = data.get("hair_uv")
        if uv is not None and (uv.shape != (len(v), 2) or not np.all(np.isfinite(uv))):
            raise self.fail(f"hair_uv must be finite ({len(v)}, 2), got {uv.shape}")
        self.hair_uv = None if uv is None else uv.astype(np.float32)
        return v, t, np.clip(c, 0.0, 1.0)

    def occlusion_values(self, values: np.ndarray, nv: int) -> np.ndarray:
        """The mesh's ``vertex_ao`` as ``(V,) float64`` in [0, 1]: integers as 0-255
        (uint8), floats as they are, both clipped to the range."""
        if values.shape != (nv,):
            raise self.fail(f"vertex_ao must have shape ({nv},), got {values.shape}")
        if np.issubdtype(values.dtype, np.integer):
            return np.clip(values / 255.0, 0.0, 1.0)
        if not np.all(np.isfinite(values)):
            raise self.fail("vertex_ao must be finite")
        return np.clip(values.astype(np.float64), 0.0, 1.0)

    def index(self, value: Any, nv: int, what: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < nv:
            raise self.fail(f"{what} is {value!r}, not a vertex index in 0-{nv - 1}")
        return value

    def indices(self, values: Any, nv: int, what: str, *, allow_empty: bool = False) -> np.ndarray:
        if not isinstance(values, list) or (not values and not allow_empty):
            raise self.fail(f"{what} must be a non-empty list of vertex indices")
        arr = np.asarray(values)
        if arr.size and (arr.dtype.kind not in "iu" or arr.min() < 0 or arr.max() >= nv):
            bad = next(v for v in values if not (isinstance(v, int) and 0 <= v < nv))
            raise self.fail(f"{what} contains {bad!r}, not a vertex index in 0-{nv - 1}")
        return arr.astype(np.int32)

    def parts(self, nv: int) -> dict[str, np.ndarray]:
        raw = self.get("parts", dict)
        out = {}
        for name in (*PART_NAMES, *OPTIONAL_PARTS, *ATTACHED_PARTS):
            if name not in raw:
                if name not in PART_NAMES:
                    continue
                raise self.fail(f"parts has no {name!r}")
            span = raw[name]
            if (not isinstance(span, list) or len(span) != 2
                    or not all(isinstance(s, int) for s in span)
                    or not 0 <= span[0] < span[1] <= nv):
                raise self.fail(f"parts[{name!r}] = {span!r} is not a vertex range [start, stop)"
                                f" within 0-{nv}")
            out[name] = np.arange(span[0], span[1], dtype=np.int32)
        unknown = set(raw) - set(PART_NAMES) - set(OPTIONAL_PARTS) - set(ATTACHED_PARTS)
        if unknown:
            raise self.fail(f"unknown part {sorted(unknown)[0]!r}; parts are "
                            f"{(*PART_NAMES, *OPTIONAL_PARTS, *ATTACHED_PARTS)}")
        return out

    def riders(self, parts: dict[str, np.ndarray], nv: int) -> Riders:
        """The riders of the optional parts: ``riders[part]`` gives, for every vertex of the
        part in order, two ``anchors`` and a ``blend`` in [0, 1] (see Riders)."""
        raw = self.doc.get("riders", {})
        if not isinstance(raw, dict) or set(raw) - set(OPTIONAL_PARTS):
            raise self.fail(f"riders must map parts of {OPTIONAL_PARTS} to their anchors")
        found = [no_riders()]
        for name in OPTIONAL_PARTS:
            if name not in parts:
                continue
            item = raw.get(name)
            if not isinstance(item, dict):
                raise self.fail(f"part {name!r} needs riders[{name!r}] with anchors and blend")
            ids = parts[name]
            try:
                anchors = np.asarray(item["anchors"], dtype=np.int64).reshape(ids.size, 2)
                blend = np.asarray(item["blend"], dtype=np.float64).reshape(ids.size)
            except (KeyError, TypeError, ValueError) as exc:
                raise self.fail(f"riders[{name!r}] needs {ids.size} anchor pairs and "
                                f"{ids.size} blends: {exc}") from exc
            if anchors.min() < 0 or anchors.max() >= nv:
                raise self.fail(f"riders[{name!r}] anchors must be vertex indices in "
                                f"0-{nv - 1}")
            found.append(Riders(ids, anchors.astype(np.int32), blend.astype(np.float32)))
        return Riders(np.concatenate([r.vertices for r in found]),
                      np.concatenate([r.anchors for r in found]),
                      np.concatenate([r.blend for r in found]))

    def feature_points(self, nv: int) -> dict[str, int]:
        raw = self.get("feature_points", dict)
        table = feature_point_table()
        for key in raw:
            if key not in table:
                raise self.fail(f"feature_points has unknown feature point {key!r}")
        missing = [p for p in required_feature_points() if p not in raw]
        if missing:
            raise self.fail(f"feature point {missing[0]} is missing"
                            + (f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""))
        return {k: self.index(v, nv, f"feature point {k}") for k, v in raw.items()}

    def pivots(self) -> dict[str, np.ndarray]:
        raw = self.get("pivots", dict)
        out = {}
        for name in PIVOTS:
            value = raw.get(name)
            if (not isinstance(value, list) or len(value) != 3
                    or not all(isinstance(c, (int, float)) for c in value)):
                raise self.fail(f"pivot {name!r} must be three numbers, got {value!r}")
            out[name] = np.asarray(value, dtype=np.float64)
        return out

    def neck(self) -> tuple[np.ndarray, np.ndarray, float]:
        raw = self.get("neck", dict)
        try:
            point = np.asarray(raw["point"], dtype=np.float64).reshape(3)
            normal = np.asarray(raw["normal"], dtype=np.float64).reshape(3)
            blend = float(raw["blend"])
        except (KeyError, TypeError, ValueError) as exc:
            raise self.fail(f"neck needs point, normal and blend: {exc}") from exc
        length = float(np.linalg.norm(normal))
        if not length > 0 or not blend > 0:
            raise self.fail(f"neck normal {raw['normal']!r} and blend {blend!r} must be nonzero")
        return point, normal / length, blend

    def regions(
        self, nv: int, points: dict[str, int], pivots: dict[str, np.ndarray]
    ) -> tuple[Region, ...]:
        raw = self.get("regions", list)
        out: list[Region] = []
        names: set[str] = set()
        for i, item in enumerate(raw):
            if not isinstance(item, dict) or not isinstance(item.get("name"), str):
                raise self.fail(f"regions[{i}] must be an object with a name")
            if item["name"] in names:
                raise self.fail(f"region {item['name']!r} is defined twice")
            names.add(item["name"])
            out.append(self.region(item, nv, points, pivots))
        unused = sorted(set(self.overrides) - names - {r.group for r in out})
        if unused:
            known = sorted(names | {r.group for r in out if r.group})
            raise ParameterError(f"deformers override {unused[0]!r} names no region or group "
                                 f"of {self.path.name} (known: {', '.join(known)})")
        return tuple(out)

    def field(self, item: dict[str, Any], where: str, *, deformer: str,
              params: dict[str, Any], controls: list[str], n_members: int) -> np.ndarray:
        """A ``field`` region's ``(Vr, 3)`` displacements from the mesh file (empty for other
        deformers); its ``params["fap"]`` must move the region's one feature point."""
        if deformer != "field":
            return np.zeros((0, 3), np.float32)
        try:
            info = fap(str(params.get("fap")))
        except FacelibError as exc:
            raise self.fail(f"{where}: a field region names the FAP it drives in params.fap, "
                            f"got {params.get('fap')!r}") from exc
        if info.kind != "translation" or list(info.feature_points[:1]) != controls:
            raise self.fail(f"{where}: field FAP {info.name} moves {info.feature_points}, "
                            f"not the region's feature points {controls}")
        key = item.get("field")
        if not isinstance(key, str) or key not in self.fields:
            raise self.fail(f"{where}: the mesh file has no field array {key!r}")
        array = np.asarray(self.fields[key], dtype=np.float32)
        if array.shape != (n_members, 3) or not np.all(np.isfinite(array)):
            raise self.fail(f"{where}: field {key!r} must be finite ({n_members}, 3), got "
                            f"{array.shape}")
        return array

    def region(self, item: dict, nv: int, points: dict[str, int],
               pivots: dict[str, np.ndarray]) -> Region:
        """One region of the definition, validated, with its deformer resolved."""
        name = item["name"]
        where = f"region {name!r}"
        group = item.get("group", "")
        if not isinstance(group, str):
            raise self.fail(f"{where} group must be a string, not {group!r}")
        deformer_name, custom, params = self.deformer_of(item, name, group, where)
        controls = item.get("feature_points")
        if not isinstance(controls, list) or not controls:
            raise self.fail(f"{where} needs a non-empty list of feature_points")
        for c in controls:
            if c not in points:
                raise self.fail(f"{where} uses feature point {c!r}, which the face lacks")
        vertices = self.indices(item.get("vertices"), nv, f"{where} vertices")
        anchors = self.indices(item.get("anchors", []), nv, f"{where} anchors",
                               allow_empty=True)
        deformer = ALIASES.get(deformer_name, deformer_name)
        if deformer == "rbf" and len(controls) + anchors.size < 2:
            raise self.fail(f"{where}: an RBF needs at least two sources")
        weights = np.zeros(0, np.float32)
        if deformer in ("weights", "eyelid"):
            if len(controls) != 1:
                raise self.fail(f"{where}: a {deformer} region has exactly one feature point")
            weights = np.asarray(item.get("weights", []), dtype=np.float64)
            if weights.shape != vertices.shape or not np.all((weights >= 0) & (weights <= 1)):
                raise self.fail(f"{where}: weights must be {vertices.size} numbers in [0, 1]")
        pivot = ""
        if deformer == "eyelid":
            pivot = str(item.get("pivot"))
            if pivot not in pivots:
                raise self.fail(f"{where} has pivot {pivot!r}; known: {tuple(pivots)}")
        displacements = self.field(item, where, deformer=deformer, params=params,
                                   controls=controls, n_members=vertices.size)
        return Region(name=name, deformer=deformer, feature_points=tuple(controls),
                      vertices=vertices, anchors=anchors, weights=weights.astype(np.float32),
                      pivot=pivot, params=MappingProxyType(params), group=group, custom=custom,
                      displacements=displacements)

    def deformer_of(self, item: dict, name: str, group: str, where: str
                    ) -> tuple[str, Deformer | None, dict[str, Any]]:
        """The region's deformer name, custom deformer and parameters, overrides applied."""
        key = name if name in self.overrides else group if group in self.overrides else None
        if key is not None and item.get("deformer") not in RIGID_DEFORMERS:
            return _override(self.overrides[key], key)
        if key is not None:
            raise ParameterError(f"deformers[{key!r}]: {where} is an eyelid (a rigid step); "
                                 "it cannot take another deformer")
        name_ = item.get("deformer")
        if name_ not in RIGID_DEFORMERS:
            try:
                deformer(name_ if isinstance(name_, str) else repr(name_))
            except FaceModelError:
                raise self.fail(f"{where} has deformer {name_!r}; known: "
                                f"{(*deformer_names(), *RIGID_DEFORMERS)}") from None
        params = item.get("params", {})
        if not isinstance(params, dict):
            raise self.fail(f"{where} params must be an object, not {params!r}")
        return str(name_), None, dict(params)
