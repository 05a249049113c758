"""Tracker landmarks in the neutral head's frame: the first steps of every FAP measurement.

Image coordinates are turned into the face frame (``x`` to the face's left = the image's
right in a non-mirrored camera, ``y`` up, ``z`` toward the camera), frames without a face
are interpolated, the rigid head pose is fitted on the layout's stable points and undone,
and the user's FAPU are measured on the neutral frames (eq. 4.12-4.15).

The neutral head's frame is upright: a neutral face tilted in the image (a tilted head, a
camera on its side) is turned about the camera's axis until its eyes are level, so
the FAPs' axes are the face's own whatever the tilt; the head pose keeps the neutral as its
rest, its pitch and yaw about the face's axes.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass

import numpy as np

from facelib.errors import ParameterError, TrackingError
from facelib.tracking.layouts import LandmarkLayout
from facelib.tracking.pose import HeadPose, fit_pose, refine_pose_2d, unpose, unpose_2d
from facelib.tracking.userfapu import complete_points, user_fapu

__all__ = ["HeadFrame", "Neutral", "face_found", "face_frame", "fill_gaps", "frame_spans",
           "head_frame", "neutral_face", "neutral_frames", "neutral_span", "to_head_frame"]


@dataclass(frozen=True)
class HeadFrame:
    """Landmarks with the head pose undone.

    Attributes
    ----------
    landmarks: ``(n, K, D) float64`` every landmark in the neutral head's frame (the
        landmarks' unit, pixels for video).
    rest: ``(K, D)`` their mean over the neutral frames.
    points: ``(n, P, D)`` the layout's feature points, same frame.
    rest_points: ``(P, D)`` their neutral mean.
    fapu: the user's FAPU in the landmarks' unit per FAP unit (``AU`` in radians).
    pose: the per-frame head fit, its axes the neutral head's (None when only translation
        was corrected).
    """

    landmarks: np.ndarray
    rest: np.ndarray
    points: np.ndarray
    rest_points: np.ndarray
    fapu: dict[str, float]
    pose: HeadPose | None

    @property
    def motion(self) -> np.ndarray:
        """``(n, K, 2) float64`` every landmark's ``x, y`` displacement from ``rest`` (the
        landmarks' unit): what the observation model reads."""
        return (self.landmarks - self.rest)[..., :2]


def face_frame(landmarks: np.ndarray) -> np.ndarray:
    """Image coordinates (column, row[, depth toward the scene]) -> the face frame (``x``
    right in the image = the face's left, ``y`` up, ``z`` toward the camera). Same shape."""
    out = np.array(landmarks, np.float64)
    out[..., 1:] *= -1.0
    return out


def frame_spans(frames: np.ndarray) -> str:
    """Frame indices (sorted) as text: ``"3-7, 12"``."""
    parts, start = [], None
    for i, f in enumerate(frames):
        if start is None:
            start = f
        if i + 1 == len(frames) or frames[i + 1] != f + 1:
            parts.append(f"{start}" if start == f else f"{start}-{f}")
            start = None
    return ", ".join(parts)


def face_found(landmarks: np.ndarray) -> np.ndarray:
    """``(n,) bool`` the frames of ``(n, K, D)`` landmarks that hold a face (no NaN)."""
    data = np.asarray(landmarks)
    return np.asarray(np.isfinite(data).reshape(len(data), -1).all(axis=1))


def fill_gaps(landmarks: np.ndarray) -> tuple[np.ndarray, tuple[int, ...]]:
    """Interpolate frames whose landmarks hold NaN (no face) linearly in time.

    ``(n, K, D)`` -> (the landmarks as float64, a filled copy if any frame was lost; the
    filled frame indices). Frames before the first or after the last face hold the nearest
    face. TrackingError if no frame has a face.
    """
    data = np.asarray(landmarks, np.float64)
    lost = ~face_found(data)
    if not lost.any():
        return data, ()
    data = data.copy()
    good = np.flatnonzero(~lost)
    if not good.size:
        raise TrackingError(f"no face in any of the {len(data)} frames")
    flat = data.reshape(len(data), -1)
    idx = np.arange(len(data))
    for col in range(flat.shape[1]):
        flat[lost, col] = np.interp(idx[lost], good, flat[good, col])
    return data, tuple(int(i) for i in np.flatnonzero(lost))


def neutral_span(neutral: int | tuple[int, int] | None, n: int, *,
                 lost: Collection[int] = ()) -> slice:
    """The neutral frame or ``(start, stop)`` span as a slice, None: the first of ``n``
    frames with a face (not in ``lost``; TrackingError if there is none). ParameterError for
    an empty span or one outside the ``n`` frames."""
    if neutral is None:
        missing = set(lost)
        first = next((i for i in range(n) if i not in missing), None)
        if first is None:
            raise TrackingError(f"no face in any of the {n} frames")
        return slice(first, first + 1)
    start, stop = (neutral, neutral + 1) if isinstance(neutral, int) else neutral
    if start >= stop:
        raise ParameterError(f"neutral frames {neutral!r} are an empty span")
    if not 0 <= start < stop <= n:
        raise ParameterError(f"neutral frames {neutral!r} are outside the {n} frames")
    return slice(start, stop)


def neutral_frames(span: slice, lost: Collection[int]) -> np.ndarray:
    """``(k,) int64`` the frames of the neutral ``span`` with a face (not in ``lost``);
    TrackingError naming the span when there are none."""
    frames = np.setdiff1d(np.arange(span.start, span.stop), np.asarray(list(lost), np.int64))
    if not frames.size:
        raise TrackingError("no face in the neutral frames "
                            f"{frame_spans(np.arange(span.start, span.stop))}: choose frames "
                            "where the face is seen, still and relaxed")
    return frames


@dataclass(frozen=True)
class Neutral:
    """The neutral face a track is measured against (from its neutral frames alone, so a
    long track can be put in the head frame a chunk at a time).

    Attributes
    ----------
    image_rest: ``(K, D) float64`` the landmarks' mean over the neutral frames in the face
        frame, pose not removed: what the pose fit fits to.
    rest: ``(K, D) float64`` their mean in the neutral head's frame.
    rest_points: ``(P, D) float64`` the layout's feature points there.
    fapu: the user's FAPU in the landmarks' unit per FAP unit (``AU`` in radians).
    level: ``(D, D) float64`` the rotation about the camera's axis that turns the face frame
        into the neutral head's (eyes level; identity when the layout has no eyes).
    """

    image_rest: np.ndarray
    rest: np.ndarray
    rest_points: np.ndarray
    fapu: dict[str, float]
    level: np.ndarray


def _levelling(image_rest: np.ndarray, layout: LandmarkLayout) -> np.ndarray:
    """``(D, D)`` the rotation about the camera's axis that levels the eyes of the ``(K, D)``
    neutral ``image_rest``: the midpoints of their corners (3.7/3.11, 3.8/3.12), which do not
    move with the gaze as the pupils do, else the eye centres 3.5/3.6 or their eq.
    4.12/4.13 fill-ins; the identity for a layout with neither."""
    level = np.eye(image_rest.shape[1])
    points = complete_points(dict(zip(layout.feature_points,
                                      layout.feature_point_positions(image_rest[None])[0],
                                      strict=True)))
    for left, right in ((("3.7", "3.11"), ("3.8", "3.12")), (("3.5",), ("3.6",))):
        if all(fp in points for fp in left + right):
            across = (np.mean([points[fp][:2] for fp in left], axis=0)
                      - np.mean([points[fp][:2] for fp in right], axis=0))
            tilt = np.arctan2(across[1], across[0])  # the face's right eye to its left
            level[:2, :2] = [[np.cos(tilt), np.sin(tilt)], [-np.sin(tilt), np.cos(tilt)]]
            break
    return level


def _levelled(pose: HeadPose, level: np.ndarray) -> HeadPose:
    """``pose`` (the fit in the face frame) with its axes the neutral head's: rotations
    ``L R L^T``, translations ``L t``."""
    return HeadPose(pose.scale, level @ pose.rotation @ level.T, pose.translation @ level.T)


def _remove_pose(points: np.ndarray, layout: LandmarkLayout, image_rest: np.ndarray
                 ) -> tuple[np.ndarray, HeadPose | None]:
    """All landmarks ``(n, K, D)`` (face frame) in the neutral head's frame, and the fit to
    the neutral ``image_rest`` ``(K, D)``."""
    dim = points.shape[2]
    if len(layout.stable) > dim:
        stable = points[:, layout.stable]
        rest = image_rest[layout.stable]
        pose = fit_pose(rest, stable)
        if dim == 2:
            return unpose(points, pose), pose
        pose = refine_pose_2d(rest, stable, pose)
        return unpose_2d(points, image_rest, pose), pose
    if "9.3" not in layout.feature_points:
        raise TrackingError("without stable points the nose tip 9.3 must be tracked "
                            "(the seed's reference point)")
    nose = layout.feature_point_positions(points)[:, layout.index("9.3")]
    nose_rest = layout.feature_point_positions(image_rest[None])[0, layout.index("9.3")]
    return points - (nose - nose_rest)[:, None, :], None


def neutral_face(landmarks: np.ndarray, *, layout: LandmarkLayout, span: slice,
                 fapu: Mapping[str, float] | None = None, lost: Collection[int] = ()
                 ) -> Neutral:
    """The :class:`Neutral` of ``(n, K, D)`` image-coordinate landmarks without gaps
    (:func:`fill_gaps`), from the frames of ``span`` that had a face (not in ``lost``, the
    filled ones), with FAPU overrides ``fapu``. TrackingError when none of them had one."""
    frames = neutral_frames(span, lost)
    points = face_frame(landmarks[frames])
    image_rest = points.mean(axis=0)
    level = _levelling(image_rest, layout)
    rest = _remove_pose(points, layout, image_rest)[0].mean(axis=0) @ level.T
    rest_points = layout.feature_point_positions(rest[None])[0]
    units = user_fapu(dict(zip(layout.feature_points, rest_points, strict=True)), fapu)
    return Neutral(image_rest, rest, rest_points, units, level)


def to_head_frame(landmarks: np.ndarray, neutral: Neutral, *, layout: LandmarkLayout
                  ) -> HeadFrame:
    """``(n, K, D)`` image-coordinate landmarks without gaps in the head frame of
    ``neutral`` (any frames of the track it was taken from, e.g. a chunk of a long one)."""
    local, pose = _remove_pose(face_frame(landmarks), layout, neutral.image_rest)
    local = local @ neutral.level.T
    return HeadFrame(local, neutral.rest, layout.feature_point_positions(local),
                     neutral.rest_points, neutral.fapu,
                     None if pose is None else _levelled(pose, neutral.level))


def head_frame(landmarks: np.ndarray, *, layout: LandmarkLayout, span: slice,
               fapu: Mapping[str, float] | None = None) -> HeadFrame:
    """``(n, K, D)`` image-coordinate landmarks without gaps (:func:`fill_gaps`) in the
    neutral head's frame, with the neutral frames ``span`` and FAPU overrides ``fapu``."""
    neutral = neutral_face(landmarks, layout=layout, span=span, fapu=fapu)
    return to_head_frame(landmarks, neutral, layout=layout)
