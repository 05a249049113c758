"""A small synthetic face for rendering tests (independent of the default head).

A unit-sphere head (skin) whose lower cap is a "jaw" that FAP 3 (open_jaw, positive down,
MNS units) moves down, red lips at the mouth line, and two eyeballs (white sclera, dark
iris/pupil cap looking along +z) that FAPs 23/24 (yaw, 1e-5 rad, positive toward the face's
left, +x) and 25/26 (pitch, positive down) rotate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from facelib.mpeg4.stream import FapStream

MNS = 0.3 / 1024  # mouth-nose separation / 1024, in face units
SKIN = (0.85, 0.66, 0.55)
LIPS = (0.70, 0.25, 0.25)
SCLERA = (0.95, 0.95, 0.93)
IRIS = (0.05, 0.05, 0.08)
EYE_RADIUS = 0.16


def uv_sphere(n_lat: int, n_lon: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit sphere: ``(V, 3)`` vertices and ``(F, 3)`` counter-clockwise-outward triangles."""
    lat = np.linspace(0, np.pi, n_lat + 1)[1:-1]
    lon = np.linspace(0, 2 * np.pi, n_lon, endpoint=False)
    ring = np.stack(
        [
            np.sin(lat)[:, None] * np.sin(lon)[None, :],
            np.cos(lat)[:, None] * np.ones_like(lon)[None, :],
            np.sin(lat)[:, None] * np.cos(lon)[None, :],
        ],
        axis=-1,
    ).reshape(-1, 3)
    verts = np.vstack([[0, 1, 0], ring, [0, -1, 0]]).astype(np.float32)
    top, bottom = 0, len(verts) - 1
    tris = []
    for j in range(n_lon):
        k = (j + 1) % n_lon
        tris.append((top, 1 + j, 1 + k))
        for i in range(n_lat - 2):
            a, b = 1 + i * n_lon + j, 1 + i * n_lon + k
            c, d = a + n_lon, b + n_lon
            tris += [(a, c, d), (a, d, b)]
        last = 1 + (n_lat - 2) * n_lon
        tris.append((bottom, last + k, last + j))
    tris = np.array(tris, np.int32)
    # make the winding face outward (checked, not assumed)
    a, b, c = (verts[tris[:, i]] for i in range(3))
    if np.einsum("ij,ij->", np.cross(b - a, c - a), a + b + c) < 0:
        tris = tris[:, ::-1]
    return verts, np.ascontiguousarray(tris)


@dataclass(frozen=True)
class Part:
    name: str
    vertex_ids: np.ndarray
    triangles: np.ndarray


class SyntheticFace:
    """Duck-typed stand-in for ``facelib.engine.Face`` (see module docstring)."""

    def __init__(self) -> None:
        head_v, head_t = uv_sphere(24, 32)
        eye_v, eye_t = uv_sphere(12, 16)
        self.eye_centres = {
            "eye_l": np.array([0.33, 0.25, 0.86], np.float32),
            "eye_r": np.array([-0.33, 0.25, 0.86], np.float32),
        }
        verts = [head_v]
        tris = [head_t]
        colors = [np.tile(SKIN, (len(head_v), 1))]
        lips = (np.abs(head_v[:, 1] + 0.38) < 0.07) & (head_v[:, 2] > 0.6)
        colors[0][lips] = LIPS
        self._eye_ids = {}
        self.parts = {"skin": Part("skin", np.arange(len(head_v), dtype=np.int32), head_t)}
        offset = len(head_v)
        self._eye_dirs = eye_v
        for name, centre in self.eye_centres.items():
            ids = np.arange(offset, offset + len(eye_v), dtype=np.int32)
            verts.append(centre + EYE_RADIUS * eye_v)
            tris.append(eye_t + offset)
            eye_colors = np.tile(SCLERA, (len(eye_v), 1))
            eye_colors[eye_v[:, 2] > 0.8] = IRIS
            colors.append(eye_colors)
            self.parts[name] = Part(name, ids, eye_t + offset)
            self._eye_ids[name] = ids
            offset += len(eye_v)
        self.vertices = np.vstack(verts).astype(np.float32)
        self.triangles = np.vstack(tris).astype(np.int32)
        self.vertex_colors = np.vstack(colors).astype(np.float32)
        self.jaw = np.flatnonzero(head_v[:, 1] < -0.38)
        self.forehead = np.flatnonzero(head_v[:, 1] > 0.55)

    def deform_frame(self, values: np.ndarray) -> np.ndarray:
        values = np.asarray(values, np.float64)
        out = self.vertices.astype(np.float64).copy()
        out[self.jaw, 1] -= values[2] * MNS
        for name, yaw_col, pitch_col in (("eye_l", 22, 24), ("eye_r", 23, 25)):
            yaw, pitch = values[yaw_col] * 1e-5, values[pitch_col] * 1e-5
            ry = np.array([[np.cos(yaw), 0, np.sin(yaw)], [0, 1, 0],
                           [-np.sin(yaw), 0, np.cos(yaw)]])
            # positive pitch turns the gaze down: +z toward -y
            rx = np.array([[1, 0, 0], [0, np.cos(pitch), -np.sin(pitch)],
                           [0, np.sin(pitch), np.cos(pitch)]])
            dirs = self._eye_dirs @ (ry @ rx).T
            out[self._eye_ids[name]] = self.eye_centres[name] + EYE_RADIUS * dirs
        return out.astype(np.float32)

    def deform(self, stream: FapStream) -> np.ndarray:
        return np.stack([self.deform_frame(v) for v in stream.values]).astype(np.float32)


@pytest.fixture(scope="session")
def synthetic_face() -> SyntheticFace:
    return SyntheticFace()

