"""Eyelashes of the default head (issue 14, item 3): cards that ride on the lid margins."""

from __future__ import annotations

import json

import numpy as np
import pytest

from facelib.engine import Face, load_face
from facelib.engine.surface import segments_cross
from facelib.errors import FaceModelError
from facelib.expressions.library import default_library

RIBS = 9  # vertices per lash card (tools/build_lashes.py: two per rib, one at the tip)
ROOTED = 0.0004  # metres next to the root that may lie in the skin (as real roots do)


@pytest.fixture(scope="module")
def face(default_face: Face) -> Face:
    return default_face


def _lashes(face: Face) -> np.ndarray:
    return face.parts["lashes"].vertex_ids


def _margin(face: Face, positions: np.ndarray) -> np.ndarray:
    """(R, 3) the lid-margin point each lash vertex rides on, in ``positions``."""
    r = face.riders
    t = r.blend.astype(np.float64)[:, None]
    return (1 - t) * positions[r.anchors[:, 0]] + t * positions[r.anchors[:, 1]]


def _blink(fap_frame, amount: float) -> np.ndarray:  # type: ignore[no-untyped-def]
    return fap_frame(close_t_l_eyelid=amount, close_t_r_eyelid=amount)


def test_lashes_are_a_dark_part_on_the_lid_margins(face: Face) -> None:
    ids = _lashes(face)
    assert 150 <= ids.size // RIBS <= 400 and ids.size % RIBS == 0
    assert np.array_equal(face.riders.vertices, ids)
    assert face.vertex_colors[ids].max() < 0.2  # dark
    rest = face.vertices.astype(np.float64)
    to_eye = np.minimum(*(np.linalg.norm(rest[ids] - face.pivots[e], axis=1)
                          for e in ("eye_l", "eye_r")))
    assert to_eye.max() < 0.03
    roots = ids.reshape(-1, RIBS)[:, :2].ravel()
    gap = np.linalg.norm(rest[roots] - _margin(face, rest)[np.searchsorted(ids, roots)], axis=1)
    assert gap.max() < 0.0003  # the roots sit on the margin


@pytest.mark.parametrize("amount", [256.0, 512.0, 768.0, 1024.0])
def test_lashes_follow_the_lid_margin_through_a_blink(face: Face, fap_frame,  # type: ignore[no-untyped-def]
                                                     amount: float) -> None:
    rest = face.vertices.astype(np.float64)
    moved = face.deform_frame(_blink(fap_frame, amount)).astype(np.float64)
    ids = _lashes(face)
    margin_moves = _margin(face, moved) - _margin(face, rest)
    lash_moves = moved[ids] - rest[ids]
    # the middle of a lash's root moves as its point of the margin does (to 0.04 mm: it
    # sits 0.05 mm off the skin and turns with the lid)
    root_moves = lash_moves.reshape(-1, RIBS, 3)[:, :2].mean(axis=1)
    assert np.abs(root_moves - margin_moves[::RIBS]).max() < 4e-5
    # the upper lashes went down with the lid, most near the lid's middle (3.1)
    point = face.feature_points["3.1"]
    drop = rest[point, 1] - moved[point, 1]
    assert drop > 0.002 * amount / 1024
    near = np.argmin(np.linalg.norm(rest[ids] - rest[point], axis=1))
    assert lash_moves[near, 1] == pytest.approx(-drop, rel=0.15)
    # every card turns rigidly with its lid: its shape is kept
    cards_rest, cards_moved = rest[ids].reshape(-1, RIBS, 3), moved[ids].reshape(-1, RIBS, 3)
    length = np.linalg.norm(cards_rest[:, -1] - cards_rest[:, 0], axis=1)
    np.testing.assert_allclose(np.linalg.norm(cards_moved[:, -1] - cards_moved[:, 0], axis=1),
                               length, rtol=1e-4)


def test_lower_lashes_follow_a_cheek_raise_through_the_operator(face: Face,  # type: ignore[no-untyped-def]
                                                                fap_frame) -> None:
    rest = face.vertices.astype(np.float64)
    moved = face.deform_frame(fap_frame(lift_l_cheek=400, close_b_l_eyelid=200)
                              ).astype(np.float64)
    ids = _lashes(face)
    margin_moves = _margin(face, moved) - _margin(face, rest)
    roots = ids.reshape(-1, RIBS)[:, :2].ravel() - ids[0]
    assert np.abs(margin_moves).max() > 0.001
    assert np.abs((moved[ids] - rest[ids])[roots] - margin_moves[roots]).max() < 5e-5


def _poses(fap_frame) -> list[np.ndarray]:  # type: ignore[no-untyped-def]
    library = default_library()
    return [_blink(fap_frame, 512.0), _blink(fap_frame, 1024.0),
            *(library.get(name).values for name in library.names)]


@pytest.mark.slow  # every lid pose
def test_lashes_never_pass_through_the_skin_or_the_eyeballs(face: Face,  # type: ignore[no-untyped-def]
                                                            fap_frame) -> None:
    ids = _lashes(face)
    skin = face.parts["skin"].triangles
    for values in [fap_frame(), *_poses(fap_frame)]:
        p = face.deform_frame(values).astype(np.float64)
        cards = p[ids].reshape(-1, RIBS, 3)
        line = np.concatenate([(cards[:, 0:-1:2] + cards[:, 1:-1:2]) / 2, cards[:, -1:]], 1)
        first = line[:, 1] - line[:, 0]
        line[:, 0] += first * np.minimum(ROOTED / np.linalg.norm(first, axis=1), 0.5)[:, None]
        near = np.zeros(len(skin), bool)
        for eye in ("eye_l", "eye_r"):
            near |= np.linalg.norm(p[skin].mean(1) - face.pivots[eye], axis=1) < 0.035
            ball = face.parts[eye].vertex_ids  # (thrust moves the eyeball, and its centre)
            centre = face.pivots[eye] + (p[ball] - face.vertices[ball]).mean(axis=0)
            radius = np.linalg.norm(p[ball] - centre, axis=1).max()
            assert np.linalg.norm(p[ids] - centre, axis=1).min() > radius
        crossed = segments_cross(line[:, :-1].reshape(-1, 3), line[:, 1:].reshape(-1, 3),
                                 p[skin][near])
        assert not crossed.any()


def test_segments_cross_finds_a_segment_through_a_triangle() -> None:
    tri = np.array([[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
    starts = np.array([[0.2, 0.2, -1.0], [0.2, 0.2, 0.0], [0.8, 0.8, -1.0], [0.2, 0.2, 0.5]])
    ends = np.array([[0.2, 0.2, 1.0], [0.2, 0.2, 1.0], [0.8, 0.8, 1.0], [0.2, 0.2, 1.0]])
    assert segments_cross(starts, ends, tri).tolist() == [True, False, False, False]


def test_written_face_keeps_its_lashes(face: Face, tmp_path, fap_frame) -> None:  # type: ignore[no-untyped-def]
    from facelib.engine.writer import write_face

    path = write_face(face, tmp_path / "copy.json")
    again = load_face(path)
    assert np.array_equal(again.parts["lashes"].vertex_ids, _lashes(face))
    values = _blink(fap_frame, 800.0)
    np.testing.assert_allclose(again.deform_frame(values), face.deform_frame(values),
                               atol=2e-6)


def test_bad_riders_are_reported(face: Face, tmp_path) -> None:  # type: ignore[no-untyped-def]
    from facelib.engine.writer import write_face

    path = write_face(face, tmp_path / "bad.json")
    doc = json.loads(path.read_text())
    doc["riders"]["lashes"]["blend"][0] = 1.5
    path.write_text(json.dumps(doc))
    with pytest.raises(FaceModelError, match="blends must lie in"):
        load_face(path)
    doc["riders"]["lashes"]["blend"] = [0.5]
    path.write_text(json.dumps(doc))
    with pytest.raises(FaceModelError, match="anchor pairs"):
        load_face(path)
    del doc["riders"]
    path.write_text(json.dumps(doc))
    with pytest.raises(FaceModelError, match="needs riders"):
        load_face(path)
