"""VRM 1.0 export: the head as a VRM avatar (a ``.glb`` named ``.vrm`` with the ``VRMC_vrm``
extension, specVersion 1.0).

What the file holds besides the glTF head of :mod:`facelib.export.gltf` (parts, vertex
colours, the joint skin of eyes, lids, jaw and head):

* one mesh and node per part (``skin``, ``eye_l`` ... ``hair``), each with one morph target
  per expression preset (``aa`` ... ``lookRight``, :mod:`facelib.export.vrm_presets`; the
  same list on every part), bound on every part by ``expressions.preset``;
* a humanoid: the head rig's ``head``, ``eyeball_l``, ``eyeball_r`` and ``jaw`` joints as
  ``head``, ``leftEye``, ``rightEye`` and ``jaw``, below stand-in body nodes for the bones
  VRM 1.0 requires (hips, spine, chest, neck, legs, arms: ``export/vrm.json``) that no
  vertex follows;
* ``lookAt`` of type ``bone`` (the eye joints), ``firstPerson`` (every part mesh ``auto``:
  a viewer hides what follows the head bone, so the bust and neck stay), and ``meta``.

VRM lists animations among the glTF items it does not use, so the file holds none: the
avatar is driven by its expressions (lip sync, blinks, emotions) and look-at.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from facelib import data
from facelib.atomic import atomic_path
from facelib.engine import Face, default_face
from facelib.errors import ParameterError
from facelib.export.gltf import _Builder, _import_pygltflib, _part_nodes, _skeleton
from facelib.export.rig import Rig, build_rig, pose_rig
from facelib.export.source import Source, export_clip, face_of
from facelib.export.vrm_presets import preset_names, preset_targets
from facelib.mpeg4.stream import FapStream

__all__ = ["VrmExport", "export_vrm"]

_FILE = "export/vrm.json"


@dataclass(frozen=True)
class VrmExport:
    """What :func:`export_vrm` wrote.

    path: the ``.vrm``; presets: the expression preset names, in morph-target order (target
    ``k`` of each part's mesh is preset ``k`` at weight 1); bones: the humanoid bone names
    written; parts: the part names, which are the mesh nodes' names, in node order.
    """

    path: Path
    presets: tuple[str, ...]
    bones: tuple[str, ...]
    parts: tuple[str, ...] = ()


def _body(b: _Builder, rig: Rig, face: Face, rig_root: int) -> dict[str, int]:
    """The stand-in body nodes (``export/vrm.json`` ``body``) above the head rig: node index
    of each bone. Positions are relative to the head pivot; the neck's child is the rig's root
    joint, placed so that it stays where the skin's bind pose has it."""
    lib, pivot = b.lib, np.asarray(face.pivots["head"], np.float64)
    spec = data.json_data(_FILE)["body"]
    at = {row["bone"]: pivot + np.asarray(row["at"], np.float64) for row in spec}
    nodes: dict[str, int] = {}
    for row in spec:
        parent = row["parent"]
        local = at[row["bone"]] - (at[parent] if parent else 0.0)
        b.g.nodes.append(lib.Node(name=row["bone"], translation=local.tolist(), children=[]))
        nodes[row["bone"]] = len(b.g.nodes) - 1
        if parent:
            b.g.nodes[nodes[parent]].children.append(nodes[row["bone"]])
    b.g.nodes[nodes["neck"]].children.append(rig_root)
    b.g.nodes[rig_root].translation = (rig.rest[0] - at["neck"]).tolist()
    for index in nodes.values():
        b.g.nodes[index].children = b.g.nodes[index].children or None
    return nodes


def _expressions(names: tuple[str, ...], mesh_nodes: list[int]) -> dict[str, Any]:
    """``expressions.preset``: each preset binds its own target at weight 1 on every part's
    mesh node."""
    return {"preset": {name: {
        "morphTargetBinds": [{"node": node, "index": k, "weight": 1.0} for node in mesh_nodes],
        "isBinary": False, "overrideBlink": "none", "overrideLookAt": "none",
        "overrideMouth": "none"} for k, name in enumerate(names)}}


def _look_at(face: Face) -> dict[str, Any]:
    """``lookAt``: the eye bones turned 1:1 up to the ranges of ``export/vrm.json``; the
    reference point between the eyes, relative to the head bone."""
    ranges = data.json_data(_FILE)["look_at"]
    between = (np.asarray(face.pivots["eye_l"]) + np.asarray(face.pivots["eye_r"])) / 2

    def span(deg: float) -> dict[str, float]:
        return {"inputMaxValue": float(deg), "outputScale": float(deg)}

    return {"type": "bone",
            "offsetFromHeadBone": (between - np.asarray(face.pivots["head"])).tolist(),
            "rangeMapHorizontalInner": span(ranges["horizontal_deg"]),
            "rangeMapHorizontalOuter": span(ranges["horizontal_deg"]),
            "rangeMapVerticalDown": span(ranges["down_deg"]),
            "rangeMapVerticalUp": span(ranges["up_deg"])}


def _vrm_extension(face: Face, rig: Rig, nodes: dict[str, int], joint_nodes: list[int], *,
                   mesh_nodes: list[int], names: tuple[str, ...],
                   meta: dict[str, Any]) -> dict[str, Any]:
    """The ``VRMC_vrm`` object."""
    bones = dict(nodes)
    for bone, joint in (("head", "head"), ("leftEye", "eyeball_l"), ("rightEye", "eyeball_r"),
                        ("jaw", "jaw")):
        bones[bone] = joint_nodes[rig.names.index(joint)]
    return {"specVersion": "1.0", "meta": meta,
            "humanoid": {"humanBones": {bone: {"node": n} for bone, n in bones.items()}},
            "firstPerson": {"meshAnnotations": [{"node": node, "type": "auto"}
                                                for node in mesh_nodes]},
            "lookAt": _look_at(face), "expressions": _expressions(names, mesh_nodes)}


def _meta(overrides: dict[str, Any] | None) -> dict[str, Any]:
    meta = {**data.json_data(_FILE)["meta"], **(overrides or {})}
    authors = meta.get("authors")
    if not meta.get("name") or not isinstance(authors, list | tuple) or not any(authors):
        raise ParameterError("VRM meta needs a name and at least one non-empty author")
    meta["authors"] = [str(a) for a in authors]
    return meta


def export_vrm(
    source: Source,
    out: str | os.PathLike[str],
    *,
    face: Face | None = None,
    meta: dict[str, Any] | None = None,
) -> VrmExport:
    """Write a VRM 1.0 avatar (``.vrm``) of the head that ``source`` plays on.

    Parameters
    ----------
    source: a FapStream, a :class:`~facelib.clip.Clip` or an animation, as for
        :func:`~facelib.export.export_gltf`; its face is the avatar's (``face`` overrides).
        The stream itself is not written: VRM files carry no animation.
    out: the ``.vrm`` path (written atomically).
    face: the head (default: the clip's, else the bundled head).
    meta: ``VRMC_vrm.meta`` fields to set over the defaults of ``export/vrm.json`` (``name``,
        ``authors``, the permission fields ...).
    """
    lib = _import_pygltflib()
    out = Path(out)
    if out.suffix.lower() != ".vrm":
        raise ParameterError(f"export_vrm writes VRM: give a .vrm path, not {out}")
    clip = export_clip(source, face=face)
    face = face_of(clip) or default_face()
    names = preset_names()
    fields = _meta(meta)
    with atomic_path(out) as temp:
        temp.write_bytes(_container(lib, face, names, fields))
    bones = tuple(row["bone"] for row in data.json_data(_FILE)["body"])
    return VrmExport(out, names, (*bones, "head", "leftEye", "rightEye", "jaw"),
                     tuple(face.parts))


def _container(lib: Any, face: Face, names: tuple[str, ...], meta: dict[str, Any]) -> bytes:
    """The ``.vrm`` bytes: a mesh per part with one target per preset, the skin at rest, the
    body nodes and the extension."""
    rig = build_rig(face)
    g = lib.GLTF2(asset=lib.Asset(generator="facelib", version="2.0"))
    b = _Builder(g, lib)
    g.nodes.append(lib.Node(name="vrm_root"))  # node 0, above the body (gltf._FIRST_ROOT)
    parts = _part_nodes(b, face, rig, preset_targets(face), names)
    joint_nodes = _skeleton(b, rig, pose_rig(face, rig, FapStream.zeros(1, fps=25)))
    nodes = _body(b, rig, face, joint_nodes[0])
    g.nodes[0].children = [nodes["hips"]]
    g.scenes.append(lib.Scene(name="facelib", nodes=[0, *parts]))
    g.scene = 0
    g.extensionsUsed = ["VRMC_vrm"]
    g.extensions = {"VRMC_vrm": _vrm_extension(face, rig, nodes, joint_nodes, mesh_nodes=parts,
                                                  names=names, meta=meta)}
    blob = b.blob()
    g.buffers.append(lib.Buffer(byteLength=len(blob)))
    g.set_binary_blob(blob)
    return b"".join(g.save_to_bytes())
