"""The issue's pixel checks on the real default head (skipped while the engine is absent)."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.engine.render_scene import FaceRenderer

engine = pytest.importorskip("facelib.engine")
W, H = 200, 200


@pytest.fixture(scope="module")
def head():
    face = engine.load_face(None)
    with FaceRenderer(face, width=W, height=H) as renderer:
        yield face, renderer


def _faps(**values: float) -> np.ndarray:
    out = np.zeros(84, np.float32)
    for key, value in values.items():
        out[int(key[1:]) - 1] = value
    return out


def test_jaw_open_moves_mouth_pixels_not_forehead(head):
    face, renderer = head
    neutral = renderer.frame(face.deform_frame(_faps()))
    opened = renderer.frame(face.deform_frame(_faps(f3=600)))
    diff = np.abs(neutral.astype(int) - opened.astype(int)).sum(axis=2)
    chin_row = renderer.project(face.vertices[face.feature_points["2.1"]])[0, 1]
    eye_row = renderer.project(face.pivots["eye_l"])[0, 1]
    changed = np.flatnonzero(diff.max(axis=1) > 30)
    assert changed.size > 3
    assert changed.min() > eye_row  # forehead and eyes untouched
    assert np.abs(changed - chin_row).min() < 10  # the change is around the mouth and chin


def test_eyes_turned_left_move_the_iris_right_in_the_image(head):
    face, renderer = head
    centres = renderer.project(np.vstack([face.pivots["eye_l"], face.pivots["eye_r"]]))

    def iris_x(image: np.ndarray) -> float:
        xs = []
        for cx, cy in centres:
            r0, c0 = int(cy) - 6, int(cx) - 10
            patch = image[r0 : r0 + 12, c0 : c0 + 20].astype(int).sum(axis=2)
            dark = patch < np.percentile(patch, 15)
            xs.append(np.nonzero(dark)[1].mean() + c0)
        return float(np.mean(xs))

    x0 = iris_x(renderer.frame(face.deform_frame(_faps())))
    x_left = iris_x(renderer.frame(face.deform_frame(_faps(f23=40000, f24=40000))))
    x_right = iris_x(renderer.frame(face.deform_frame(_faps(f23=-40000, f24=-40000))))
    # FAP 23/24 positive turns the eyes to the face's own left, the image's right
    assert x_left > x0 + 1.5
    assert x_right < x0 - 1.5
