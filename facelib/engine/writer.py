"""Writing a Face as a face definition JSON beside its ``.npz`` mesh (what ``load_face`` reads).

Both files are written atomically; the mesh first, so a definition never names a mesh
that is not there.
"""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import numpy as np

from facelib.atomic import atomic_path, write_text_atomic
from facelib.engine.definition import FORMAT, VERSION
from facelib.engine.face import OPTIONAL_PARTS, PART_NAMES, Face
from facelib.errors import FaceModelError

__all__ = ["face_document", "write_face"]


def _round(values: np.ndarray) -> list[float]:
    return [float(v) for v in np.asarray(values, dtype=np.float64)]


def face_document(face: Face, *, mesh: str, name: str, source: str = "") -> dict[str, Any]:
    """The JSON document of a face definition (format ``facelib-face`` version 1)."""
    parts = {}
    for part in (*PART_NAMES, *(p for p in OPTIONAL_PARTS if p in face.parts)):
        ids = face.parts[part].vertex_ids
        if not ids.size or not np.array_equal(ids, np.arange(ids[0], ids[0] + ids.size)):
            raise FaceModelError(f"part {part!r} is not one contiguous vertex range")
        parts[part] = [int(ids[0]), int(ids[0] + ids.size)]
    regions = []
    for r in face.regions:
        item: dict[str, Any] = {"name": r.name, "deformer": r.deformer,
                                "feature_points": list(r.feature_points),
                                "vertices": [int(v) for v in r.vertices]}
        if r.anchors.size:
            item["anchors"] = [int(v) for v in r.anchors]
        if r.deformer in ("weights", "eyelid"):
            item["weights"] = [round(float(w), 6) for w in r.weights]
        if r.deformer == "field":
            item["field"] = f"field_{r.name}"
        if r.pivot:
            item["pivot"] = r.pivot
        if r.group:
            item["group"] = r.group
        if r.params:
            item["params"] = dict(r.params)
        if r.custom is not None:
            raise FaceModelError(f"region {r.name!r} has a custom deformer object, which a "
                                 "face definition file cannot hold; register it by name")
        regions.append(item)
    point, normal, blend = face.neck
    return {
        "format": FORMAT, "version": VERSION, "name": name, "mesh": mesh, "unit": "metre",
        "frame": "+x is the face's own left, +y up, +z out of the face",
        "source": source, "parts": parts,
        "feature_points": {k: int(v) for k, v in face.feature_points.items()},
        "pivots": {k: _round(v) for k, v in face.pivots.items()},
        "neck": {"point": _round(point), "normal": _round(normal), "blend": float(blend)},
        "regions": regions,
    } | _riders(face)


def _riders(face: Face) -> dict[str, Any]:
    """The ``riders`` entry: per optional part, its vertices' anchor pairs and blends."""
    out = {}
    order = {int(v): k for k, v in enumerate(face.riders.vertices)}
    for part in OPTIONAL_PARTS:
        if part not in face.parts:
            continue
        at = [order[int(v)] for v in face.parts[part].vertex_ids]
        out[part] = {"anchors": face.riders.anchors[at].tolist(),
                     "blend": [round(float(t), 6) for t in face.riders.blend[at]]}
    return {"riders": out} if out else {}


def write_face(face: Face, path: str | Path, *, name: str = "", source: str = "") -> Path:
    """Write ``face`` to ``path`` (``DIR/face.json``; the mesh goes to ``DIR/face.npz``).

    Returns the JSON path. ``load_face(path)`` gives the same face back.
    """
    path = Path(path)
    if path.suffix.lower() != ".json":
        raise FaceModelError(f"a face definition is a .json file, not {path.name!r}")
    mesh_path = path.with_suffix(".npz")
    doc = face_document(face, mesh=mesh_path.name, name=name or path.stem, source=source)
    text = json.dumps(doc, indent=1) + "\n"
    buffer = io.BytesIO()
    fields = {f"field_{r.name}": r.displacements for r in face.regions
              if r.deformer == "field"}
    arrays: dict[str, np.ndarray] = {
        "vertices": face.vertices, "triangles": face.triangles,
        "vertex_colors": np.round(face.vertex_colors * 255).astype(np.uint8), **fields}
    if face.vertex_ao is not None:
        arrays["vertex_ao"] = np.round(face.vertex_ao * 255).astype(np.uint8)
    np.savez_compressed(buffer, **arrays)  # type: ignore[arg-type]
    with atomic_path(mesh_path) as temp:
        temp.write_bytes(buffer.getvalue())
    write_text_atomic(path, text)
    return path
