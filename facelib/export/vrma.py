"""VRM Animation export: a storyboard's motion as a ``.vrma`` (a ``.glb`` with the
``VRMC_vrm_animation`` extension, specVersion 1.0) that plays on any VRM 1.0 avatar, facelib's
own (:func:`facelib.export.export_vrm`) or another tool's.

What the file holds, one keyframe per frame:

* **expressions**: one node per preset that an animation may drive (``aa`` ... ``surprised``;
  the four looks are the look-at's), whose translation's x is the preset's weight in [0, 1].
  The visemes and emotions are the bounded least-squares mix of their FAP recipes
  (:mod:`facelib.export.vrm_presets`) nearest to each frame's mouth, brows, cheeks and lower
  lids, each FAP scaled by its largest value in any recipe; the blinks are the upper lids'
  closure (FAPs 19/20) beyond what that mix closes (``blink`` what both lids share,
  ``blinkLeft``/``blinkRight`` the rest);
* **humanoid**: a T-pose skeleton with the bones VRM 1.0 requires (``export/vrm.json``
  ``body``, every rest rotation the identity, hips above the floor) and the head, whose
  rotation track is the head rotation of FAPs 48-50;
* **lookAt**: a node whose rotation is the mean eye turn (FAPs 23-26), the yaw about +y and
  the pitch about +x that the avatar's look-at maps to its eyes.

Positions and times: metres, seconds; quaternions ``x, y, z, w``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.optimize import lsq_linear
from scipy.spatial.transform import Rotation

from facelib import data
from facelib.atomic import atomic_path
from facelib.engine import default_face, rigid
from facelib.errors import ParameterError
from facelib.export.gltf import _Builder, _import_pygltflib
from facelib.export.source import Source, export_clip, face_of
from facelib.export.vrm_presets import preset_names, preset_recipes
from facelib.mpeg4.highlevel import apply_high_level
from facelib.mpeg4.tables import fap

__all__ = ["VrmaExport", "export_vrma", "preset_weights"]

_FILE = "export/vrm.json"
_LOOKS = ("lookUp", "lookDown", "lookLeft", "lookRight")
_BLINKS = ("blink", "blinkLeft", "blinkRight")
# FAPs the expression fit leaves out: the high-level pair, the upper lids (the blinks'),
# the eyeballs (the look-at's) and the head (the head bone's)
_NOT_FIT = ("viseme", "expression", "close_t_l_eyelid", "close_t_r_eyelid", "yaw_l_eyeball",
            "yaw_r_eyeball", "pitch_l_eyeball", "pitch_r_eyeball", "head_pitch", "head_yaw",
            "head_roll")
_LID_CLOSED = 1024.0  # FAP 19/20 value of a closed lid (the blink recipes')


@dataclass(frozen=True)
class VrmaExport:
    """What :func:`export_vrma` wrote.

    path: the ``.vrma``; presets: the expression presets animated; weights: (n, P) float32,
    their weights per frame; n_frames, fps: the animation's frames and rate.
    """

    path: Path
    presets: tuple[str, ...]
    weights: np.ndarray
    n_frames: int
    fps: float


def animated_presets() -> tuple[str, ...]:
    """The presets a VRM animation drives: every preset but the four looks, file order."""
    return tuple(name for name in preset_names() if name not in _LOOKS)


def preset_weights(values: np.ndarray) -> np.ndarray:
    """Expression preset weights of FAP frames.

    Parameters
    ----------
    values: (n, 84) FAP values (FAP units), high-level FAPs already decoded.

    Returns
    -------
    (n, P) float32 in [0, 1], columns in :func:`animated_presets` order.
    """
    names = preset_names()
    recipes = preset_recipes().astype(np.float64)  # eye turns are not fit: any AU will do
    values = np.asarray(values, np.float64)
    order = animated_presets()
    out = np.zeros((len(values), len(order)), np.float32)
    fitted = [name for name in order if name not in _BLINKS]
    rows = recipes[[names.index(name) for name in fitted]]  # (K, 84)
    keep = np.ones(rows.shape[1], bool)
    keep[[fap(name).index for name in _NOT_FIT]] = False
    reach = np.abs(rows).max(axis=0)
    keep &= reach > 0
    basis = (rows[:, keep] / reach[keep]).T  # (F, K)
    targets = values[:, keep] / reach[keep]
    mix = np.zeros((len(values), len(fitted)))
    for i in np.flatnonzero(np.any(targets != 0, axis=1)):
        mix[i] = lsq_linear(basis, targets[i], bounds=(0.0, 1.0), method="bvls").x
    out[:, [order.index(name) for name in fitted]] = mix
    # the blinks close what the fitted presets' own lids (sadness droops them) leave open
    lids = [fap("close_t_l_eyelid").index, fap("close_t_r_eyelid").index]
    closed = np.clip((values[:, lids] - mix @ rows[:, lids]) / _LID_CLOSED, 0.0, 1.0)
    both = closed.min(axis=1)
    for name, column in zip(_BLINKS, (both, closed[:, 0] - both, closed[:, 1] - both),
                            strict=True):
        out[:, order.index(name)] = column
    return out


def export_vrma(
    source: Source,
    out: str | os.PathLike[str],
) -> VrmaExport:
    """Write a VRM 1.0 animation (``.vrma``) of a stream, a clip or an animation.

    Parameters
    ----------
    source: a FapStream, a :class:`~facelib.clip.Clip` or an animation, as for
        :func:`~facelib.export.export_gltf`. Its face sets the angle unit of the eye and head
        rotations (the bundled head's when it names none).
    out: the ``.vrma`` path (written atomically).
    """
    lib = _import_pygltflib()
    out = Path(out)
    if out.suffix.lower() != ".vrma":
        raise ParameterError(f"export_vrma writes VRM animations: give a .vrma path, not {out}")
    clip = export_clip(source)
    face = face_of(clip) or default_face()
    values = np.asarray(apply_high_level(clip.stream).values, np.float64)
    weights = preset_weights(values)
    with atomic_path(out) as temp:
        temp.write_bytes(_container(lib, values, weights, fps=clip.fps,
                                    au=float(face.fapu["AU"])))
    return VrmaExport(out, animated_presets(), weights, len(values), clip.fps)


def _quaternions(pitch: np.ndarray, yaw: np.ndarray, roll: np.ndarray) -> np.ndarray:
    """(n, 4) float32 quaternions ``x, y, z, w`` of ``R_y(yaw) R_x(pitch) R_z(roll)``;
    angles (n,) radians."""
    return Rotation.from_matrix(rigid.rotation_matrices(pitch, yaw, roll)).as_quat().astype(
        np.float32)


def _turns(values: np.ndarray, au: float) -> tuple[np.ndarray, np.ndarray]:
    """(n, 4) quaternions of the head (FAPs 48-50) and of the eyes' mean turn (23-26)."""
    def column(name: str) -> np.ndarray:
        return values[:, fap(name).index] * au

    head = _quaternions(column("head_pitch"), column("head_yaw"), column("head_roll"))
    eyes = _quaternions((column("pitch_l_eyeball") + column("pitch_r_eyeball")) / 2,
                        (column("yaw_l_eyeball") + column("yaw_r_eyeball")) / 2,
                        np.zeros(len(values)))
    return head, eyes


def _skeleton(b: _Builder) -> dict[str, int]:
    """The T-pose nodes (``export/vrm.json`` body, then the head above the neck), shifted so
    that the lowest bone stands on the floor: node index per bone."""
    spec = data.json_data(_FILE)["body"]
    at = {row["bone"]: np.asarray(row["at"], np.float64) for row in spec}
    at["head"] = np.zeros(3)
    parents = {row["bone"]: row["parent"] for row in spec} | {"head": "neck"}
    floor = np.array([0.0, -min(p[1] for p in at.values()), 0.0])
    nodes: dict[str, int] = {}
    for bone, parent in parents.items():
        local = at[bone] - at[parent] if parent else at[bone] + floor
        b.g.nodes.append(b.lib.Node(name=bone, translation=local.tolist(), children=[]))
        nodes[bone] = len(b.g.nodes) - 1
        if parent:
            b.g.nodes[nodes[parent]].children.append(nodes[bone])
    for index in nodes.values():
        b.g.nodes[index].children = b.g.nodes[index].children or None
    return nodes


def _container(lib: Any, values: np.ndarray, weights: np.ndarray, *, fps: float,
               au: float) -> bytes:
    """The ``.vrma`` bytes."""
    g = lib.GLTF2(asset=lib.Asset(generator="facelib", version="2.0"))
    b = _Builder(g, lib)
    bones = _skeleton(b)
    presets = animated_presets()
    expression_nodes = {}
    for name in presets:
        g.nodes.append(lib.Node(name=f"expression_{name}"))
        expression_nodes[name] = len(g.nodes) - 1
    g.nodes.append(lib.Node(name="look_at"))
    look = len(g.nodes) - 1
    g.scenes.append(lib.Scene(name="facelib", nodes=[bones["hips"], *expression_nodes.values(),
                                                     look]))
    g.scene = 0
    times = b.accessor((np.arange(len(values)) / fps).astype(np.float32)[:, None], "SCALAR",
                       bounds=True)
    head, eyes = _turns(values, au)
    moves = [(bones["head"], "rotation", head, "VEC4"), (look, "rotation", eyes, "VEC4")]
    for k, name in enumerate(presets):
        shift = np.zeros((len(values), 3), np.float32)
        shift[:, 0] = weights[:, k]
        moves.append((expression_nodes[name], "translation", shift, "VEC3"))
    samplers, channels = [], []
    for node, path, track, kind in moves:
        samplers.append(lib.AnimationSampler(input=times, output=b.accessor(track, kind),
                                             interpolation="LINEAR"))
        channels.append(lib.AnimationChannel(
            sampler=len(samplers) - 1, target=lib.AnimationChannelTarget(node=node, path=path)))
    g.animations.append(lib.Animation(name="facelib", samplers=samplers, channels=channels))
    g.extensionsUsed = ["VRMC_vrm_animation"]
    g.extensions = {"VRMC_vrm_animation": {
        "specVersion": "1.0",
        "humanoid": {"humanBones": {bone: {"node": n} for bone, n in bones.items()}},
        "expressions": {"preset": {name: {"node": n} for name, n in expression_nodes.items()}},
        "lookAt": {"node": look}}}
    blob = b.blob()
    g.buffers.append(lib.Buffer(byteLength=len(blob)))
    g.set_binary_blob(blob)
    return b"".join(g.save_to_bytes())
