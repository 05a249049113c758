"""MediaPipe face mesh on facelib's own rendered head: 478 landmarks where the face is."""

from __future__ import annotations

import numpy as np
import pytest

from facelib.errors import ParameterError, TrackingError

pytest.importorskip("mediapipe")
pytestmark = pytest.mark.render

from facelib.tracking.layouts import landmark_layout  # noqa: E402
from facelib.tracking.mediapipe import FaceMeshTracker, detect_landmarks  # noqa: E402

CLOSE = ("2.1", "2.2", "2.3", "2.6", "2.8", "3.1", "3.2", "3.3", "3.4", "3.5", "3.6", "4.1",
         "4.2", "8.1", "8.2", "8.3", "8.4", "9.13", "9.14")


def test_landmarks_fall_on_the_projected_feature_points(default_head_render):
    image, projected = default_head_render
    found = detect_landmarks(image)
    assert found.points.shape == (478, 3)
    assert found.n_faces == 1
    layout = landmark_layout("mediapipe")
    fps = layout.feature_point_positions(found.points[None])[0]
    for fp in CLOSE:
        error = np.linalg.norm(fps[layout.index(fp), :2] - projected[fp])
        assert error < 8.0, (fp, error)
    # the face's left (+x) is the image's right: left pupil right of the right pupil
    assert fps[layout.index("3.5"), 0] > fps[layout.index("3.6"), 0]


def test_two_faces_keeps_the_largest(default_head_render):
    image, _ = default_head_render
    from PIL import Image

    small = np.asarray(Image.fromarray(image).resize((480, 360)))
    canvas = np.concatenate([image, np.zeros_like(image)], axis=1)
    canvas[60:420, 720:1200] = small
    with FaceMeshTracker(video=False, max_faces=3) as tracker:
        found = tracker.detect(canvas)
    assert found is not None
    assert found.n_faces == 2
    assert found.box[2] < 640  # the big face, on the left half


def _small_then_both(image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(480, 1280, 3)`` frames: ``image`` small on the right half, and the same with
    ``image`` at full size on the left half beside it."""
    from PIL import Image

    alone = np.zeros((480, 1280, 3), np.uint8)
    alone[60:420, 720:1200] = np.asarray(Image.fromarray(image).resize((480, 360)))
    joined = alone.copy()
    joined[:, :640] = image
    return alone, joined


def test_a_video_follows_its_face_when_a_larger_one_comes(default_head_render):
    """In a video the face tracked so far is kept when a second, larger one appears: a
    colleague leaning in closer does not take over the track."""
    alone, joined = _small_then_both(default_head_render[0])
    with FaceMeshTracker(video=True, max_faces=3) as tracker:
        found = [tracker.detect(frame) for frame in [alone] * 3 + [joined] * 3]
    assert all(f is not None for f in found)
    assert [f.n_faces for f in found] == [1, 1, 1, 2, 2, 2]
    assert all(f.box[0] > 640 for f in found)  # the small face, on the right half


def test_faces_counted_on_some_frames_name_them_all(default_head_render):
    """A video's track looks for one face and counts faces on some frames: a second face
    coming after the first is counted on every frame it is in (back from the count that
    finds it), and the first is kept; two faces where the face is first found: the track
    looks for two from there, keeping the largest, as before."""
    from facelib.tracking.overlap import InOrder
    from facelib.tracking.video import _COUNT_EVERY, _Faces

    alone, joined = _small_then_both(default_head_render[0])
    for frames, counts, right in (([alone] * (_COUNT_EVERY + 2) + [joined] * 3,
                                   [1] * (_COUNT_EVERY + 2) + [2] * 3, True),
                                  ([joined] * 3, [2] * 3, False)):
        faces = _Faces(2)
        try:
            with InOrder() as beside:  # the counts run on its thread, as in track_video
                found = [faces.detect(frame, beside) for frame in frames]
                beside.submit(faces.finish)
        finally:
            faces.close()
        assert faces.counts == counts
        assert all(f is not None and (f.box[0] > 640) == right for f in found)


def test_the_face_kept_is_the_one_overlapping_most():
    """Overlap as intersection over union: the same face moved a little wins over a larger
    box around it; with nothing kept before, or no overlap, the largest."""
    from facelib.tracking.mediapipe import _pick

    before = np.array([100.0, 100, 200, 220])
    moved, around = before + 4, np.array([60.0, 60, 260, 300])
    assert _pick([around, moved], before) == 1
    assert _pick([around, moved], None) == 0
    assert _pick([moved, around], np.array([400.0, 400, 450, 460])) == 1


def test_no_face_and_bad_images():
    blank = np.full((240, 320, 3), 40, np.uint8)
    with pytest.raises(TrackingError, match="no face"):
        detect_landmarks(blank)
    with pytest.raises(ParameterError, match="uint8"):
        detect_landmarks(blank.astype(np.float32))
    with pytest.raises(ParameterError, match="shape"):
        detect_landmarks(blank[..., 0])



def test_the_graph_starting_keeps_stderr_clean(default_head_render, capfd, caplog):
    """What MediaPipe's C++ side prints as its graph starts (TensorFlow Lite's delegate
    notice, absl warnings) goes to facelib's log, not to the process's stderr."""
    image, _ = default_head_render
    capfd.readouterr()
    with caplog.at_level("INFO", logger="facelib.tracking"), \
            FaceMeshTracker(video=True, max_faces=1) as tracker:
        assert tracker.detect(image) is not None
        assert tracker.detect(image) is not None
    assert capfd.readouterr().err == ""
    assert all(r.getMessage().startswith("mediapipe: ") for r in caplog.records)
