"""Rendered pixels: motion shows where it should, conventions of the image, buffer updates."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream
from facelib.rendering.frames import render, render_still
from facelib.rendering.scene import FaceRenderer

pytestmark = pytest.mark.render

W, H = 160, 120


@pytest.fixture(scope="module")
def renderer(synthetic_face):
    with FaceRenderer(synthetic_face, width=W, height=H, framing="head") as r:
        yield r


def _box(renderer, points, pad=2):
    px = renderer.project(points)
    c0, r0 = np.floor(px.min(axis=0)).astype(int) - pad
    c1, r1 = np.ceil(px.max(axis=0)).astype(int) + pad
    return slice(max(r0, 0), min(r1, H)), slice(max(c0, 0), min(c1, W))


def test_jaw_open_changes_mouth_not_forehead(renderer, synthetic_face, fap_frame):
    face = synthetic_face
    neutral = renderer.frame(face.deform_frame(fap_frame()))
    open_jaw = renderer.frame(face.deform_frame(fap_frame(f3=700)))
    diff = np.abs(neutral.astype(int) - open_jaw.astype(int)).sum(axis=2)
    front = face.vertices[:, 2] > 0.3
    mouth = face.vertices[np.intersect1d(face.jaw, np.flatnonzero(front))]
    forehead = face.vertices[np.intersect1d(face.forehead, np.flatnonzero(front))]
    assert diff[_box(renderer, mouth)].max() > 60
    assert (diff[_box(renderer, mouth)] > 30).sum() > 100
    assert diff[_box(renderer, forehead, pad=0)].max() == 0
    # the change is below the eyes only
    eye_row = renderer.project(face.eye_centres["eye_l"][None])[0, 1]
    rows = np.flatnonzero(diff.max(axis=1) > 30)
    assert rows.min() > eye_row


def _iris_centroid(image, renderer, face):
    rows, cols = _box(renderer, np.vstack(list(face.eye_centres.values())), pad=8)
    patch = image[rows, cols].astype(int)
    dark = patch.sum(axis=2) < 120
    assert dark.sum() > 5
    r, c = np.nonzero(dark)
    return c.mean() + cols.start, r.mean() + rows.start


def test_eyes_turned_to_the_faces_left_move_iris_to_image_right(
    renderer, synthetic_face, fap_frame
):
    face = synthetic_face
    x0, y0 = _iris_centroid(renderer.frame(face.deform_frame(fap_frame())), renderer, face)
    turn = fap_frame(f23=50000, f24=50000)  # +0.5 rad toward the face's own left (+x)
    x1, y1 = _iris_centroid(renderer.frame(face.deform_frame(turn)), renderer, face)
    back = fap_frame(f23=-50000, f24=-50000)
    x2, _ = _iris_centroid(renderer.frame(face.deform_frame(back)), renderer, face)
    # the camera faces the face, so the face's left is the image's right
    assert x1 - x0 > 2
    assert x0 - x2 > 2
    assert abs(y1 - y0) < 1.0
    down = fap_frame(f25=40000, f26=40000)  # pitch down
    _, y3 = _iris_centroid(renderer.frame(face.deform_frame(down)), renderer, face)
    assert y3 - y0 > 1.5


def test_buffer_update_matches_fresh_meshes(synthetic_face, fap_frame):
    face = synthetic_face
    poses = [fap_frame(f3=500), fap_frame(f23=20000, f24=20000), fap_frame()]
    with FaceRenderer(face, width=W, height=H, mesh_update="swap") as swap, \
            FaceRenderer(face, width=W, height=H, mesh_update="buffers") as buffers:
        for pose in poses:
            vertices = face.deform_frame(pose)
            assert np.array_equal(swap.frame(vertices), buffers.frame(vertices))
        # the in-place update really moved the mesh (pyrender issue #43 would show no change)
        assert not np.array_equal(buffers.frame(face.deform_frame(poses[0])),
                                  buffers.frame(face.deform_frame(poses[2])))


def test_camera_frames_the_whole_face(renderer, synthetic_face):
    px = renderer.project(synthetic_face.vertices)
    assert px[:, 0].min() > 0 and px[:, 0].max() < W
    assert px[:, 1].min() > 0 and px[:, 1].max() < H
    # and fills it: the taller extent uses most of the height
    assert px[:, 1].max() - px[:, 1].min() > 0.75 * H
    image = renderer.frame(synthetic_face.vertices)
    assert tuple(image[0, 0]) == tuple(image[-1, -1])  # corners show background
    assert image.shape == (H, W, 3) and image.dtype == np.uint8


def test_render_returns_frames_in_order_and_deterministic(synthetic_face):
    values = np.zeros((3, 84), np.float32)
    values[1, 2] = 700
    stream = FapStream(25, values)
    frames = render(stream, face=synthetic_face, width=W, height=H, progress=False)
    assert frames.shape == (3, H, W, 3) and frames.dtype == np.uint8
    assert np.array_equal(frames[0], frames[2])
    assert not np.array_equal(frames[0], frames[1])
    again = render(stream, face=synthetic_face, width=W, height=H, progress=False)
    assert np.array_equal(frames, again)
    still = render_still(synthetic_face, values[1], width=W, height=H)
    assert np.array_equal(still, frames[1])
    by_vertices = render_still(synthetic_face, synthetic_face.deform_frame(values[1]),
                               width=W, height=H)
    assert np.array_equal(by_vertices, frames[1])


def test_background_colour_and_bad_arguments(synthetic_face):
    image = render_still(synthetic_face, width=W, height=H, background=(1.0, 0.0, 0.0))
    assert tuple(image[0, 0]) == (255, 0, 0)
    with pytest.raises(ParameterError, match="width"):
        render_still(synthetic_face, width=0, height=H)
    with pytest.raises(ParameterError, match="pose"):
        render_still(synthetic_face, np.zeros(5), width=W, height=H)
    with pytest.raises(ParameterError, match="background"):
        render_still(synthetic_face, width=W, height=H, background=(2, 0, 0))
    with pytest.raises(ParameterError, match="FapStream"):
        render("not a stream", face=synthetic_face)
