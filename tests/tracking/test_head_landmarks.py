"""Automatic landmarks for face set-up: MediaPipe on a front view of a head mesh, rays cast
back onto the mesh, checked against the test heads' true feature points."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from facelib.engine.setup import read_landmarks, setup_face
from facelib.engine.setup.headmesh import axes_rotation, head_mesh, load_head_mesh
from facelib.errors import FaceModelError

pytest.importorskip("mediapipe")
if importlib.util.find_spec("pyrender") is None:
    pytest.skip("needs the render extra", allow_module_level=True)
pytestmark = pytest.mark.render

from facelib.tracking.head_landmarks import (  # noqa: E402
    AUTO_EXCLUDED,
    detect_head_landmarks,
    draw_landmarks,
)

HEADS = Path(__file__).resolve().parents[2] / "examples" / "heads"


def _errors(name: str, suffix: str) -> tuple[np.ndarray, object]:
    mesh = load_head_mesh(HEADS / f"{name}_head.{suffix}")
    truth = read_landmarks(HEADS / f"{name}_landmarks.json")
    found = detect_head_landmarks(mesh)
    assert not set(found.points) & set(AUTO_EXCLUDED[1:])
    err = np.array([np.linalg.norm(found.points[k] - truth[k]) for k in found.points
                    if k in truth])
    return err, found


def test_soma_head_landmarks_within_3_mm() -> None:
    err, found = _errors("soma", "ply")
    assert len(err) >= 15
    assert np.median(err) <= 3e-3  # measured 1.93 mm
    picture = draw_landmarks(found)  # type: ignore[arg-type]
    assert picture.shape == found.image.shape  # type: ignore[attr-defined]
    assert (picture != found.image).any()  # type: ignore[attr-defined]


def test_cartoon_head_landmarks_within_3_mm() -> None:
    # MediaPipe puts the long chin's 2.1 and 2.10 31-38 mm too high; the midline profile
    # places them (and 9.3, 8.2) from the mesh's shape, the lid points snap onto their
    # rim and the mouth corners into their fold (measured median 2.84 mm, before 4.2 mm)
    err, found = _errors("cartoon", "obj")
    assert len(err) >= 18
    assert np.median(err) <= 3e-3
    truth = read_landmarks(HEADS / "cartoon_landmarks.json")
    assert np.linalg.norm(found.points["2.1"] - truth["2.1"]) <= 3e-3  # type: ignore[attr-defined]
    assert np.sort(err)[-3] <= 6e-3



def test_a_mesh_lying_on_its_back_is_searched_upright_and_answered_in_its_own_frame() -> None:
    upright = load_head_mesh(HEADS / "soma_head.ply")
    turn = axes_rotation("+z", "-y")  # the mesh looks down -y with +z up
    lying = upright.rotated(turn.T)
    with pytest.raises(FaceModelError, match="no face was found"):
        detect_head_landmarks(lying)
    found = detect_head_landmarks(lying, up="+z", forward="-y")
    reference = detect_head_landmarks(upright)
    assert found.points.keys() == reference.points.keys()
    for fp, point in found.points.items():  # the same search, the points in lying's frame
        np.testing.assert_array_equal(point, turn.T @ reference.points[fp])
    face = setup_face(lying, landmarks=found.as_json(), up="+z", forward="-y")
    np.testing.assert_allclose(
        face.vertices, setup_face(upright, landmarks=reference.as_json()).vertices,
        atol=1e-6)

def test_auto_landmarks_set_up_a_face() -> None:
    mesh = load_head_mesh(HEADS / "soma_head.ply")
    found = detect_head_landmarks(mesh)
    face = setup_face(mesh, landmarks=found.as_json())
    fp = face.feature_points
    # the lips part where they should: the inner upper lip above the inner lower lip
    assert face.vertices[fp["2.2"], 1] > face.vertices[fp["2.3"], 1]
    assert 8e-3 < face.fapu["MNS"] * 1024 < 16e-3
    # the carried eyeballs sit in their openings (placed against the lid points, not
    # sunk by a warp without pupils): closed lids hide the sclera (white pixels)
    from facelib.rendering.scene import FaceRenderer

    lids = face.vertices[[fp[k] for k in ("3.1", "3.2", "3.3", "3.4")]]
    side = np.array([0.014, 0.0, 0.0])
    closed = np.zeros(84, np.float32)
    closed[[18, 19]] = 1024
    white = []
    with FaceRenderer(face, width=400, height=150,
                      framing=np.vstack([lids + side, lids - side])) as renderer:
        for values in (np.zeros(84, np.float32), closed):
            image = renderer.frame(face.deform_frame(values)).astype(int)
            white.append(((image.min(2) > 120) & (np.ptp(image, axis=2) < 40)).sum())
    assert white[0] > 300
    assert white[1] < 0.01 * white[0]


def test_auto_landmarks_set_up_the_cartoon() -> None:
    """Without ear landmarks the warp carries the cartoon's small ear regions onto next to
    nothing (ear_back_r onto its feature point alone, which failed the set-up): such a
    region takes the target vertices around where the warp puts it."""
    mesh = load_head_mesh(HEADS / "cartoon_head.obj")
    face = setup_face(mesh, landmarks=detect_head_landmarks(mesh).as_json())
    for region in face.regions:
        assert region.vertices.size >= 2, region.name
    ears = {r.name: r for r in face.regions}["ear_back_r"]
    fp = face.vertices[face.feature_points["10.4"]]
    assert np.linalg.norm(face.vertices[ears.vertices] - fp, axis=1).max() > 1e-3


def test_no_face_in_the_front_view() -> None:
    sphere = __import__("trimesh").creation.icosphere(subdivisions=3, radius=0.1)
    mesh = head_mesh(np.asarray(sphere.vertices), np.asarray(sphere.faces), name="ball")
    with pytest.raises(FaceModelError, match="ball: no face was found"):
        detect_head_landmarks(mesh)
