"""The engine's deformation as morph targets plus a joint skeleton (what glTF players run).

``Face.deform`` is a linear operator followed by rotations (thesis section 4; see
:mod:`facelib.engine.face`). Players evaluate ``morph targets -> linear blend skinning``, so:

* every row of the face's compiled linear operator (one basis vector per FAP, whatever
  deformer or learned field made it) becomes a morph target whose weight is the FAP value;
* eyes (joints ``eyeball_l``, ``eyeball_r``: the mesh nodes ``eye_l``, ``eye_r`` are the
  parts') and lower teeth and tongue (``jaw``) are rigid: one joint each, exact;
* eyelid vertices turn about the eye centre by ``w * angle`` and neck vertices by ``w`` of
  the head rotation, with per-vertex ``w`` in [0, 1]. Linear blend skinning between two joints
  would cut the arc, so each hinge gets ``FRACTIONS`` joints turned by ``k / FRACTIONS`` of
  its angle and a vertex blends the two joints around its own ``w``: the chord error falls
  with ``FRACTIONS ** 2`` (under 0.01 mm for a 0.6 rad blink on the default head).

Joint transforms are local to their parent (glTF nodes); all lengths in the face's unit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facelib.engine import Face, rigid
from facelib.errors import ParameterError
from facelib.mpeg4.highlevel import apply_high_level
from facelib.mpeg4.stream import FapStream

__all__ = ["FRACTIONS", "Pose", "Rig", "build_rig", "morph_weights", "pose_rig"]

FRACTIONS = 8
# each eyelid hinge's joint chain is named for the FAP that drives it (FAP 19-22: close the
# top left, top right, bottom left, bottom right eyelid; the face's left is +x)
_LID_NAMES = {19: "lid_upper_l", 20: "lid_upper_r", 21: "lid_lower_l", 22: "lid_lower_r"}
# each eye part's joint: not the part's own name, which its mesh node has (three.js renames
# a second node of one name, and a script that looks a name up must find one thing)
_EYE_JOINTS = {"eye_l": "eyeball_l", "eye_r": "eyeball_r"}


@dataclass(frozen=True, eq=False)
class Rig:
    """A skeleton for a face.

    names: (J,) joint names; joint 0 is the static root at the head pivot.
    parents: (J,) int, parent joint index (-1 for the root).
    rest: (J, 3) float64 rest position of each joint in mesh space (its inverse bind matrix
        is the translation by ``-rest``).
    joints: (V, 2) uint16 the two joints of each vertex; weights: (V, 2) float32, summing to 1.
    """

    names: tuple[str, ...]
    parents: np.ndarray
    rest: np.ndarray
    joints: np.ndarray
    weights: np.ndarray


@dataclass(frozen=True, eq=False)
class Pose:
    """Per-frame local joint transforms: rotation (n, J, 4) quaternions ``x, y, z, w`` and
    translation (n, J, 3), both float32 relative to the parent joint."""

    rotation: np.ndarray
    translation: np.ndarray


def _fraction_pair(w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For weights (K,) in [0, 1]: the lower fraction joint index (K,) in 0..FRACTIONS-1 and
    the blend (K,) toward the next one."""
    scaled = np.clip(w, 0.0, 1.0) * FRACTIONS
    low = np.minimum(np.floor(scaled), FRACTIONS - 1)
    return low.astype(np.int64), (scaled - low).astype(np.float32)


def build_rig(face: Face) -> Rig:
    """The joints of ``face`` and each vertex's two joints and weights."""
    r = face._rigid  # the engine's precomputed rigid steps (hinges, neck weights)
    names = ["root", *(f"neck_{k}" for k in range(1, FRACTIONS)), "head",
             *_EYE_JOINTS.values(), "jaw"]
    head = len(names) - 4
    parents = [-1] + [0] * (FRACTIONS - 1) + [0, head, head, head]
    rest = [face.pivots["head"]] * (FRACTIONS + 1) + [face.pivots["eye_l"], face.pivots["eye_r"],
                                                      face.pivots["jaw"]]
    lid_first = []
    for k, (fap_index, _, pivot, _) in enumerate(r.lids.hinges):
        lid_first.append(len(names))
        chain_name = _LID_NAMES.get(int(fap_index) + 1, f"lid_{k}")
        for j in range(1, FRACTIONS + 1):
            names.append(f"{chain_name}_{j}")
            parents.append(head)
            rest.append(pivot)
    nv = face.n_vertices
    joints = np.zeros((nv, 2), np.int64)
    weights = np.zeros((nv, 2), np.float32)
    joints[:, 0], weights[:, 0] = head, 1.0
    # neck: fraction k of the head rotation is joint "neck_k" (k = 0 the root, FRACTIONS head)
    neck_ids = r.neck[::3] // 3
    low, blend = _fraction_pair(r.head_weights.astype(np.float64))
    fraction_joint = np.array([0, *range(1, FRACTIONS), head])
    joints[neck_ids] = np.stack([fraction_joint[low], fraction_joint[low + 1]], 1)
    weights[neck_ids] = np.stack([1 - blend, blend], 1)
    # what the head leaves where it is (the bust, the garment): the static root
    joints[r.still[::3] // 3, 0] = 0
    for name, joint in zip(_EYE_JOINTS, (head + 1, head + 2), strict=True):
        joints[face.parts[name].vertex_ids, 0] = joint
    jaw_ids = r.jaw_y // 3
    joints[jaw_ids, 0] = head + 3
    lid_ids = r.lids.y // 3
    for k, first in enumerate(lid_first):
        member = r.lids.weights[k] > 0
        low, blend = _fraction_pair(r.lids.weights[k, member])
        chain = np.array([head, *range(first, first + FRACTIONS)])
        joints[lid_ids[member]] = np.stack([chain[low], chain[low + 1]], 1)
        weights[lid_ids[member]] = np.stack([1 - blend, blend], 1)
    joints[weights == 0] = 0  # glTF: a joint with zero weight must be 0
    return Rig(tuple(names), np.array(parents), np.array(rest, np.float64),
               joints.astype(np.uint16), weights)


def _quaternions(matrices: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(matrices).as_quat().astype(np.float32)  # x, y, z, w


def _about_x(angles: np.ndarray) -> np.ndarray:
    """(n,) radians -> (n, 4) quaternions of rotations about +x."""
    half = np.asarray(angles, np.float64) / 2
    zero = np.zeros_like(half)
    return np.stack([np.sin(half), zero, zero, np.cos(half)], 1).astype(np.float32)


def pose_rig(face: Face, rig: Rig, stream: FapStream) -> Pose:
    """The joints' local transforms at every frame of ``stream`` (FAP 1/2 decoded first)."""
    from scipy.spatial.transform import Rotation

    if not isinstance(stream, FapStream):
        raise ParameterError(f"pose_rig() takes a FapStream, not {type(stream).__name__}")
    f = np.asarray(apply_high_level(stream).values, np.float64)
    n, nj = len(f), len(rig.names)
    r, au = face._rigid, face.fapu["AU"]
    rot = np.zeros((n, nj, 4), np.float32)
    rot[..., 3] = 1.0
    local = rig.rest - np.where(rig.parents[:, None] >= 0, rig.rest[rig.parents], 0.0)
    trans = np.broadcast_to(local.astype(np.float32), (n, nj, 3)).copy()
    head = rig.names.index("head")
    head_rot = rigid.rotation_matrices(f[:, 47] * au, f[:, 48] * au, f[:, 49] * au)
    rot[:, head] = _quaternions(head_rot)
    rotvec = Rotation.from_matrix(head_rot).as_rotvec()
    for k in range(1, FRACTIONS):
        rot[:, k] = Rotation.from_rotvec(rotvec * (k / FRACTIONS)).as_quat()
    for name, yaw, pitch, thrust in (("eye_l", 23, 25, 27), ("eye_r", 24, 26, 28)):
        j = rig.names.index(_EYE_JOINTS[name])
        rot[:, j] = _quaternions(rigid.rotation_matrices(
            f[:, pitch - 1] * au, f[:, yaw - 1] * au, np.zeros(n)))
        trans[:, j, 2] += (f[:, thrust - 1] * face.fapu["ES"]).astype(np.float32)
    jaw = rig.names.index("jaw")
    rot[:, jaw] = _about_x(rigid.hinge_angle(r.chin, r.jaw_pivot, -f[:, 2] * r.chin_drop))
    trans[:, jaw, 2] += (f[:, 13] * face.fapu["MNS"]).astype(np.float32)
    trans[:, jaw, 0] -= (f[:, 14] * face.fapu["MW"]).astype(np.float32)
    first = jaw + 1
    for k, (fap_index, dy_per_unit, pivot, rest) in enumerate(r.lids.hinges):
        angle = rigid.hinge_angle(rest, pivot, f[:, fap_index] * dy_per_unit)
        for j in range(1, FRACTIONS + 1):
            rot[:, first + k * FRACTIONS + j - 1] = _about_x(angle * (j / FRACTIONS))
    return Pose(rot, trans)


def morph_weights(face: Face, stream: FapStream) -> tuple[np.ndarray, np.ndarray]:
    """The basis vectors ``stream`` uses and their weights.

    Returns ``(rows (T,) int64, weights (n, T) float32)``: row ``rows[t]`` of
    ``face.operator`` is target ``t``; its weight at each frame is the (decoded) value of
    that column of the stream.
    """
    values = np.asarray(apply_high_level(stream).values, np.float32)
    op = face.operator.tocsr()
    has_basis = np.diff(op.indptr) > 0
    used = np.flatnonzero(has_basis[: values.shape[1]] & np.any(values != 0, axis=0))
    return used.astype(np.int64), values[:, used]
