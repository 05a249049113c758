"""The bundled characters as rendered: no scalp skin shows above each one's hairline at face,
head and bust framing (front and a 30 degree head turn), the method of test_render_hair.py:
the skin vertices well above the hairline that face the camera are projected, and where the
bald character shows skin there, the haired one must show something else."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine import load_face
from facelib.engine.characters import character_names, face_definition
from facelib.engine.meshfile import read_npz
from facelib.mpeg4.tables import fap
from facelib.rendering.scene import FaceRenderer, vertex_normals

pytestmark = pytest.mark.render

W, H = 240, 180
ABOVE_MM = 15.0  # scalp points at least this far above the hairline are checked


def _yawed(face, degrees: float) -> np.ndarray:
    frame = np.zeros(84, np.float32)
    frame[fap("head_yaw").index] = np.radians(degrees) / face.fapu["AU"]
    return face.deform_frame(frame)


def _hairline(name: str) -> np.ndarray:
    """``(K, 2)`` (azimuth degrees, height m): the hairline the character's hair was groomed
    to, stored in its hair mesh by tools/build_characters.py."""
    definition = face_definition(name)
    assert definition is not None
    return read_npz(definition.parent / f"{name}_hair.npz")["hairline"].astype(np.float64)


def _scalp_points(face, line: np.ndarray, vertices: np.ndarray,
                  renderer: FaceRenderer) -> np.ndarray:
    """Pixels ``(N, 2) int`` of skin points well above the hairline facing the camera: the
    skin's vertices and its triangles' centres (more points than the vertices alone, for a
    head smaller in the frame than the default's)."""
    part = face.parts["skin"]
    skin = part.vertex_ids
    tris = part.triangles
    rest = np.concatenate([face.vertices[skin], face.vertices[tris].mean(1)]).astype(np.float64)
    normals = vertex_normals(vertices, face.triangles)
    normals = np.concatenate([normals[skin], normals[tris].mean(1)])
    at = np.concatenate([vertices[skin], vertices[tris].mean(1)])
    centre_z = (rest[:, 2].min() + rest[:, 2].max()) / 2
    azimuth = np.degrees(np.abs(np.arctan2(rest[:, 0], rest[:, 2] - centre_z)))
    above = rest[:, 1] - np.interp(azimuth, line[:, 0], line[:, 1])
    to_camera = renderer.camera_pose[:3, 3] - at
    to_camera /= np.linalg.norm(to_camera, axis=1, keepdims=True)
    facing = np.einsum("ij,ij->i", normals, to_camera) > 0.4 * np.linalg.norm(normals, axis=1)
    pick = (above > ABOVE_MM / 1000) & facing & (rest[:, 1] > 0.06)
    pixels = np.round(renderer.project(at[pick])).astype(int)
    inside = (pixels[:, 0] >= 0) & (pixels[:, 0] < W) & (pixels[:, 1] >= 0) & (pixels[:, 1] < H)
    return pixels[inside]


@pytest.mark.parametrize("name", character_names())
def test_no_scalp_skin_shows_above_a_characters_hairline(name) -> None:
    face, bald = load_face(name), load_face(name, hair="none")
    line = _hairline(name)
    checked = 0
    for framing in ("face", "head", "bust"):
        for yaw in (0.0, 30.0):
            moved, bare = _yawed(face, yaw), _yawed(bald, yaw)
            with FaceRenderer(face, width=W, height=H, framing=framing) as renderer:
                haired = renderer.frame(moved).astype(int)
                points = _scalp_points(bald, line, bare, renderer)
            with FaceRenderer(bald, width=W, height=H, framing=framing) as renderer:
                skin = renderer.frame(bare).astype(int)
            # the face framing at the front shows no scalp at all (brows to chin); a receding
            # hairline leaves few scalp points facing a camera in front
            assert len(points) >= (0 if framing == "face" and yaw == 0 else 3), (
                name, framing, yaw, len(points))
            checked += len(points)
            if not len(points):
                continue
            at_hair = haired[points[:, 1], points[:, 0]]
            at_skin = skin[points[:, 1], points[:, 0]]
            skin_like = np.abs(at_hair - at_skin).sum(1) < 40
            assert skin_like.mean() < 0.03, (name, framing, yaw, skin_like.mean())
    assert checked > 100, (name, checked)
