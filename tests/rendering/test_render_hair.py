"""Hair and bust of the default head, as rendered: no scalp skin shows above the hairline in
any style at head and bust framing (front and a 30 degree head turn), and the neck shows no
seam where the bust meets the head, on the default head and every character."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine import load_face
from facelib.engine.characters import character_names
from facelib.mpeg4.tables import fap
from facelib.rendering.scene import FaceRenderer, vertex_normals

pytestmark = pytest.mark.render

W, H = 240, 180
STYLES = ("short", "long", "tied")
ABOVE_MM = 15.0  # scalp points at least this far above the hairline are checked


def _yawed(face, degrees: float) -> np.ndarray:
    frame = np.zeros(84, np.float32)
    frame[fap("head_yaw").index] = np.radians(degrees) / face.fapu["AU"]
    return face.deform_frame(frame)


def _scalp_points(face, vertices: np.ndarray, renderer: FaceRenderer) -> np.ndarray:
    """Pixels ``(N, 2) int`` of skin vertices well above the hairline that face the camera."""
    import json

    from facelib import data

    line = np.array(json.loads(data.path("head/hair_styles.json").read_text())
                    ["hairline"]["points"], float)
    skin = face.parts["skin"].vertex_ids
    rest = face.vertices[skin].astype(np.float64)
    centre_z = (rest[:, 2].min() + rest[:, 2].max()) / 2
    azimuth = np.degrees(np.abs(np.arctan2(rest[:, 0], rest[:, 2] - centre_z)))
    above = rest[:, 1] - np.interp(azimuth, line[:, 0], line[:, 1])
    normals = vertex_normals(vertices, face.triangles)[skin]
    to_camera = renderer.camera_pose[:3, 3] - vertices[skin]
    to_camera /= np.linalg.norm(to_camera, axis=1, keepdims=True)
    facing = np.einsum("ij,ij->i", normals, to_camera) > 0.4
    # above y = 6 cm only: the mouth's cavity lies behind the head's centre too, where the
    # hairline is low (the nape)
    pick = skin[(above > ABOVE_MM / 1000) & facing & (rest[:, 1] > 0.06)]
    pixels = np.round(renderer.project(vertices[pick])).astype(int)
    inside = (pixels[:, 0] >= 0) & (pixels[:, 0] < W) & (pixels[:, 1] >= 0) & (pixels[:, 1] < H)
    return pixels[inside]


@pytest.fixture(scope="module")
def bald():
    return load_face(None, hair="none")


@pytest.mark.parametrize("style", STYLES)
@pytest.mark.parametrize("framing", ["head", "bust"])
def test_no_scalp_skin_shows_above_the_hairline(bald, style, framing) -> None:
    face = load_face(None, hair=style)
    for yaw in (0.0, 30.0):
        moved, bare = _yawed(face, yaw), _yawed(bald, yaw)
        with FaceRenderer(face, width=W, height=H, framing=framing) as renderer:
            haired = renderer.frame(moved).astype(int)
            points = _scalp_points(bald, bare, renderer)
        with FaceRenderer(bald, width=W, height=H, framing=framing) as renderer:
            skin = renderer.frame(bare).astype(int)
        assert len(points) > 10
        at_hair = haired[points[:, 1], points[:, 0]]
        at_skin = skin[points[:, 1], points[:, 0]]
        # where the bald head shows scalp skin, the haired one shows something else, darker
        skin_like = np.abs(at_hair - at_skin).sum(1) < 40
        assert skin_like.mean() < 0.03, (style, framing, yaw, skin_like.mean())
        assert np.median(at_hair.mean(1)) < 0.75 * np.median(at_skin.mean(1))


def test_hair_turns_with_the_head_exactly() -> None:
    for style in STYLES:
        face = load_face(None, hair=style)
        ids = face.parts["hair"].vertex_ids
        moved = _yawed(face, 30.0)
        a = np.radians(30.0)
        rot = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
        pivot = face.pivots["head"]
        expected = (face.vertices[ids] - pivot) @ rot.T + pivot
        np.testing.assert_allclose(moved[ids], expected, atol=2e-6)


@pytest.mark.parametrize("name", [None, *character_names()])
def test_neck_shows_no_seam_at_a_30_degree_turn(name) -> None:
    """The default head and every character (whose neck loops dip lower at the front, in a
    V: the bust leaves the loop along the head's neck and its first rings descend part of
    the way to ring 2 in every column, or a light line shows along the seam)."""
    face = load_face(name, hair=None if name else "short")  # a character in its own hair
    moved = _yawed(face, 30.0)
    with FaceRenderer(face, width=480, height=360, framing="bust") as renderer:
        image = renderer.frame(moved).astype(float)
        seam = np.load(str(_bust_file(name)))["seam"]
        front = seam[np.argsort(-face.vertices[seam, 2])[:5]]
        column, seam_row = np.round(renderer.project(moved[front]).mean(0)).astype(int)
        chin_row = int(renderer.project(moved[face.feature_points["2.1"]])[0, 1])
    lum = image[:, column - 2: column + 3].mean(axis=(1, 2))
    steps = np.abs(np.diff(lum))
    near = steps[seam_row - 4: seam_row + 4]
    neck = steps[chin_row + 8: seam_row + 20]
    assert near.max() < max(8.0, 2.5 * np.median(neck)), (near, np.median(neck))


def _bust_file(name: str | None):
    from facelib import data

    return data.path(f"head/{name or 'default'}_bust.npz")
