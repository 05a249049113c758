"""Meshes a face definition attaches to its head: the bust (neck, shoulders, garment) and the
hair (one style of several), each from its own ``.npz`` beside the definition.

A definition names them as ``"bust": {"mesh": "default_bust.npz"}`` and ``"hair": {"mesh":
"default_hair.npz", "style": "short"}``; their vertices are appended after the head's, in
that order, so every vertex id of the head (feature points, regions, fields, embeddings)
stays what it was. The bust's triangles may use head vertices (its first row is the head's
neck loop, so the two surfaces share vertices and normals there); the hair's are its own.
Parts: ``bust`` (the skin of neck and chest) and ``garment`` from the bust, ``hair`` from the
hair. The files are made by ``tools/build_bust.py`` and ``tools/build_hair.py``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from facelib.checks import did_you_mean
from facelib.engine.meshfile import mesh_path, read_npz
from facelib.errors import FaceModelError

__all__ = ["Attachment", "attach", "definition_hair_styles", "hair_styles", "read_attachments"]


@dataclass(frozen=True)
class Attachment:
    """Vertices to append to a head of ``base`` vertices.

    vertices: (A, 3) float64; triangles: (F, 3) int64 into the head's vertices (``< base``)
    and the attachment's (``base + i``); colours: (A, 3) float64 sRGB in [0, 1]; ao: (A,)
    float64 in [0, 1]; parts: name -> (start, stop) range of the attachment's own vertices;
    uv: (A, 2) float32 hair card coordinates (across, root to tip) or None.
    """

    base: int
    vertices: np.ndarray
    triangles: np.ndarray
    colours: np.ndarray
    ao: np.ndarray
    parts: dict[str, tuple[int, int]]
    uv: np.ndarray | None = None


def _colours(values: np.ndarray) -> np.ndarray:
    out = values / 255.0 if np.issubdtype(values.dtype, np.integer) else values
    return np.clip(np.asarray(out, np.float64), 0.0, 1.0)


def _checked(name: str, where: Path, vertices: np.ndarray, triangles: np.ndarray, *,
             colours: np.ndarray, ao: np.ndarray, base: int) -> None:
    total = base + len(vertices)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or not np.all(np.isfinite(vertices)):
        raise FaceModelError(f"{name} vertices must be finite (A, 3), got {vertices.shape}",
                             path=where)
    if triangles.ndim != 2 or triangles.shape[1] != 3 or not len(triangles):
        raise FaceModelError(f"{name} triangles must be (F, 3), got {triangles.shape}",
                             path=where)
    if triangles.min() < 0 or triangles.max() >= total:
        raise FaceModelError(f"{name} triangle index {int(triangles.max())} is outside "
                             f"0-{total - 1}", path=where)
    if colours.shape != vertices.shape or ao.shape != (len(vertices),):
        raise FaceModelError(f"{name} colours {colours.shape} / ao {ao.shape} do not match "
                             f"{len(vertices)} vertices", path=where)


def _bust(where: Path, head: np.ndarray) -> Attachment:
    data = read_npz(where)
    try:
        base, seam = int(data["base"]), data["seam"].astype(np.int64)
        v, t = data["vertices"].astype(np.float64), data["triangles"].astype(np.int64)
        c, ao = _colours(data["vertex_colors"]), _colours(data["vertex_ao"])
        split = int(data["garment_start"])
        seam_at = data["seam_vertices"]
    except KeyError as exc:
        raise FaceModelError(f"the bust mesh lacks the array {exc.args[0]!r}", path=where) from None
    if base != len(head) or seam.min() < 0 or seam.max() >= len(head) or not np.allclose(
            head[seam], seam_at, atol=1e-6):
        raise FaceModelError(f"this bust was built for another head ({base} vertices, its "
                             f"seam elsewhere); this head has {len(head)}", path=where)
    _checked("bust", where, v, t, colours=c, ao=ao, base=base)
    return Attachment(base, v, t, c, ao, {"bust": (0, split), "garment": (split, len(v))})


def hair_styles(where: Path) -> tuple[str, ...]:
    """The style names a hair mesh file holds."""
    return tuple(str(s) for s in read_npz(where).get("styles", np.zeros(0, str)))


def _hair(where: Path, style: str, base: int) -> Attachment:
    data = read_npz(where)
    styles = tuple(str(s) for s in data.get("styles", ()))
    if style not in styles:
        raise FaceModelError(f"hair style {style!r} is not in {where.name} (styles: "
                             f"{', '.join((*styles, 'none'))}){did_you_mean(style, styles)}",
                             path=where)
    try:
        v = data[f"{style}_vertices"].astype(np.float64)
        t = data[f"{style}_triangles"].astype(np.int64) + base
        c, ao = _colours(data[f"{style}_colors"]), _colours(data[f"{style}_ao"])
        uv = data[f"{style}_uv"].astype(np.float32)
    except KeyError as exc:
        raise FaceModelError(f"the hair mesh lacks the array {exc.args[0]!r}", path=where) from None
    _checked("hair", where, v, t, colours=c, ao=ao, base=base)
    if uv.shape != (len(v), 2) or not np.all(np.isfinite(uv)):
        raise FaceModelError(f"hair uv must be finite ({len(v)}, 2), got {uv.shape}", path=where)
    return Attachment(base, v, t, c, ao, {"hair": (0, len(v))}, uv)


def _entry(doc: dict[str, Any], key: str, where: Path) -> dict[str, Any] | None:
    item = doc.get(key)
    if item is None:
        return None
    if not isinstance(item, dict) or not isinstance(item.get("mesh"), str):
        raise FaceModelError(f"{key!r} must be an object with a 'mesh' file name", path=where)
    return item


def definition_hair_styles(definition: Path, doc: dict[str, Any]) -> tuple[str, ...]:
    """The hair styles a definition ``doc`` (read from ``definition``) may wear: its hair
    mesh's styles, then ``"none"`` (bald; the only one of a definition without hair)."""
    item = _entry(doc, "hair", definition)
    if item is None:
        return ("none",)
    return (*hair_styles(mesh_path(definition, item["mesh"])), "none")


def read_attachments(definition: Path, doc: dict[str, Any], head: np.ndarray, *,
                     hair: str | None = None) -> list[Attachment]:
    """The bust and hair a definition ``doc`` (read from ``definition``) names for a head
    of vertices ``head`` ``(V, 3)``; ``hair`` overrides the definition's style (``"none"``:
    no hair). A definition without them gets none."""
    out: list[Attachment] = []
    base = len(head)
    bust = _entry(doc, "bust", definition)
    if bust is not None:
        out.append(_bust(mesh_path(definition, bust["mesh"]), head))
        base += len(out[-1].vertices)
    item = _entry(doc, "hair", definition)
    style = hair if hair is not None else (item or {}).get("style", "none")
    if style == "none":
        return out
    if item is None:
        raise FaceModelError(f"hair style {style!r} asked for, but the face definition has no "
                             "hair mesh", path=definition)
    if not isinstance(style, str):
        raise FaceModelError(f"hair style must be a name, not {style!r}", path=definition)
    out.append(_hair(mesh_path(definition, item["mesh"]), style, base))
    return out


def attach(vertices: np.ndarray, triangles: np.ndarray, colours: np.ndarray,
           ao: np.ndarray | None, pieces: list[Attachment]
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None,
                      dict[str, np.ndarray], np.ndarray | None]:
    """The head's arrays with ``pieces`` appended: vertices, triangles, colours, ao (None
    stays None only without pieces), the pieces' parts as global ``(Vp,) int32`` ids, and
    ``(V, 2) float32`` hair uv (None without hair)."""
    if not pieces:
        return vertices, triangles, colours, ao, {}, None
    n = len(vertices)
    ao = np.ones(n) if ao is None else ao
    parts: dict[str, np.ndarray] = {}
    uv_rows = [np.zeros((n, 2), np.float32)]
    for piece in pieces:
        start = len(vertices)
        for name, (lo, hi) in piece.parts.items():
            parts[name] = np.arange(start + lo, start + hi, dtype=np.int32)
        vertices = np.concatenate([vertices, piece.vertices])
        triangles = np.concatenate([triangles, piece.triangles])
        colours = np.concatenate([colours, piece.colours])
        ao = np.concatenate([ao, piece.ao])
        uv_rows.append(piece.uv if piece.uv is not None
                       else np.zeros((len(piece.vertices), 2), np.float32))
    has_uv = any(p.uv is not None for p in pieces)
    return (vertices, triangles, colours, ao, parts,
            np.concatenate(uv_rows) if has_uv else None)
