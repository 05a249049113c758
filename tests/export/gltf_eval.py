"""An independent glTF evaluator for the tests: accessors (sparse included), morph targets
and linear blend skinning at a keyframe, as the glTF 2.0 specification defines them, for
every node with a mesh (facelib writes one per part) and its own weights channel."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pygltflib
from scipy.spatial.transform import Rotation

from facelib import FapStream
from facelib.mpeg4 import fap

_DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32,
           5126: np.float32}
_WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}


class Gltf:
    def __init__(self, path: Path):
        binary = Path(path).read_bytes()[:4] == b"glTF"  # .glb, .vrm, .vrma
        self.g = (pygltflib.GLTF2.load_binary if binary else pygltflib.GLTF2.load)(str(path))
        self.blob = self.g.binary_blob()

    def _view(self, index: int, dtype: type, count: int, width: int, offset: int = 0):
        view = self.g.bufferViews[index]
        start = (view.byteOffset or 0) + offset
        return np.frombuffer(self.blob, dtype, count * width, start).reshape(count, width)

    def accessor(self, index: int) -> np.ndarray:
        a = self.g.accessors[index]
        dtype, width = _DTYPES[a.componentType], _WIDTH[a.type]
        if a.bufferView is None:
            out = np.zeros((a.count, width), dtype)
        else:
            out = self._view(a.bufferView, dtype, a.count, width, a.byteOffset or 0).copy()
        if a.sparse is not None:
            s = a.sparse
            ids = self._view(s.indices.bufferView, _DTYPES[s.indices.componentType], s.count, 1)
            out[ids[:, 0]] = self._view(s.values.bufferView, dtype, s.count, width)
        return out

    @property
    def mesh_nodes(self) -> list[int]:
        """The nodes that hold a mesh, in node order."""
        return [i for i, n in enumerate(self.g.nodes) if n.mesh is not None]

    def _mesh_of(self, node: int):
        return self.g.meshes[self.g.nodes[node].mesh]

    def local_matrices(self, frame: int) -> list[np.ndarray]:
        """Every node's local matrix at keyframe ``frame`` of the first animation (and each
        mesh node's morph weights: its channel's, else its mesh's default)."""
        trs = {i: [np.array(n.translation or [0, 0, 0], float),
                   np.array(n.rotation or [0, 0, 0, 1], float)]
               for i, n in enumerate(self.g.nodes)}
        weights = {i: np.array(self._mesh_of(i).weights or [], float) for i in self.mesh_nodes}
        targets = set()
        for ch in self.g.animations[0].channels:
            assert (ch.target.node, ch.target.path) not in targets  # the spec: once each
            targets.add((ch.target.node, ch.target.path))
            sampler = self.g.animations[0].samplers[ch.sampler]
            out = self.accessor(sampler.output)
            if ch.target.path == "weights":
                n_targets = len(self._mesh_of(ch.target.node).weights)
                weights[ch.target.node] = out.reshape(-1, n_targets)[frame].astype(float)
            elif ch.target.path == "rotation":
                trs[ch.target.node][1] = out[frame].astype(float)
            elif ch.target.path == "translation":
                trs[ch.target.node][0] = out[frame].astype(float)
        mats = []
        for i in range(len(self.g.nodes)):
            m = np.eye(4)
            m[:3, :3] = Rotation.from_quat(trs[i][1]).as_matrix()
            m[:3, 3] = trs[i][0]
            mats.append(m)
        self._weights = weights
        return mats

    def evaluate(self, frame: int) -> list[np.ndarray]:
        """World positions (Vp, 3) of each primitive of each mesh node (node order) at
        keyframe ``frame``."""
        return self.pose(self.local_matrices(frame))

    def rest_matrices(self) -> list[np.ndarray]:
        """Every node's local matrix as the nodes give it (no animation); weights all 0."""
        mats = []
        for n in self.g.nodes:
            m = np.eye(4)
            m[:3, :3] = Rotation.from_quat(n.rotation or [0, 0, 0, 1]).as_matrix()
            m[:3, 3] = n.translation or [0, 0, 0]
            mats.append(m)
        self._weights = {i: np.zeros(len(self._mesh_of(i).weights or []))
                         for i in self.mesh_nodes}
        return mats

    @property
    def weights(self) -> np.ndarray:
        """(T,) the morph weights of the last ``local_matrices`` / ``rest_matrices``: every
        mesh node's, which must all be equal (facelib's parts play the same weights)."""
        (first, *others) = self._weights.values()
        for w in others:
            np.testing.assert_array_equal(w, first)
        return first

    def pose(self, local: list[np.ndarray]) -> list[np.ndarray]:
        """World positions (Vp, 3) of each primitive of each mesh node (node order) with the
        nodes' local matrices ``local`` and the morph weights of the last
        ``local_matrices``/``rest_matrices``; every mesh node uses skin 0."""
        parent = {c: i for i, n in enumerate(self.g.nodes) for c in (n.children or [])}

        def world(i: int) -> np.ndarray:
            return world(parent[i]) @ local[i] if i in parent else local[i]

        skin = self.g.skins[0]
        inverse = self.accessor(skin.inverseBindMatrices).reshape(-1, 4, 4).transpose(0, 2, 1)
        joint_mats = np.stack([world(j) @ inverse[k] for k, j in enumerate(skin.joints)])
        out = []
        for node in self.mesh_nodes:
            assert self.g.nodes[node].skin == 0
            out.extend(self._skinned(node, joint_mats))
        return out

    def _skinned(self, node: int, joint_mats: np.ndarray) -> list[np.ndarray]:
        out = []
        for prim in self._mesh_of(node).primitives:
            pos = self.accessor(prim.attributes.POSITION).astype(float)
            for t, target in enumerate(prim.targets or []):
                pos += self._weights[node][t] * self.accessor(target["POSITION"])
            joints = self.accessor(prim.attributes.JOINTS_0).astype(int)
            weights = self.accessor(prim.attributes.WEIGHTS_0).astype(float)
            homo = np.c_[pos, np.ones(len(pos))]
            skinned = np.zeros_like(pos)
            for k in range(4):
                m = joint_mats[joints[:, k]]
                skinned += weights[:, k:k + 1] * np.einsum("vij,vj->vi", m, homo)[:, :3]
            out.append(skinned)
        return out


def busy_stream(n: int = 12) -> FapStream:
    """Every rigid step at once: jaw, lids, eyes, head, plus lips, brows and FAP 1/2."""
    t = np.linspace(0, 1, n)
    values = np.zeros((n, 84), np.float32)
    for name, amp in (("open_jaw", 500), ("thrust_jaw", 80), ("shift_jaw", -60),
                      ("close_t_l_eyelid", 1000), ("close_t_r_eyelid", 700),
                      ("close_b_l_eyelid", 300), ("yaw_l_eyeball", 20000),
                      ("pitch_r_eyeball", -15000), ("thrust_l_eyeball", 100),
                      ("head_pitch", 20000), ("head_yaw", -30000), ("head_roll", 12000),
                      ("raise_l_i_eyebrow", 200), ("stretch_l_cornerlip", 150)):
        values[:, fap(name).index] = amp * np.sin(np.pi * t)
    mask = np.ones((n, 84), bool)
    viseme = np.tile([10, 1, 40, 0], (n, 1))
    expression = np.tile([1, 50, 0, 0, 0, 0], (n, 1))
    return FapStream(25, values, mask, viseme, expression)
