"""Tracker landmarks in the neutral head's frame: the first steps of every FAP measurement.

Image coordinates are turned into the face frame (``x`` to the face's left = the image's
right in a non-mirrored camera, ``y`` up, ``z`` toward the camera), frames without a face
are interpolated, the rigid head pose is fitted on the layout's stable points and undone,
and the user's FAPU are measured on the neutral frames (eq. 4.12-4.15).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from facelib.errors import ParameterError, TrackingError
from facelib.tracking.layouts import LandmarkLayout
from facelib.tracking.pose import HeadPose, fit_pose, refine_pose_2d, unpose, unpose_2d
from facelib.tracking.userfapu import user_fapu

__all__ = ["HeadFrame", "face_frame", "fill_gaps", "frame_spans", "head_frame",
           "neutral_span"]


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
    pose: the per-frame head fit (None when only translation was corrected).
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


def fill_gaps(landmarks: np.ndarray) -> tuple[np.ndarray, tuple[int, ...]]:
    """Interpolate frames whose landmarks hold NaN (no face) linearly in time.

    ``(n, K, D)`` -> (filled copy, the filled frame indices). Frames before the first or
    after the last face hold the nearest face. TrackingError if no frame has a face.
    """
    data = np.array(landmarks, np.float64)
    lost = ~np.isfinite(data).reshape(len(data), -1).all(axis=1)
    if not lost.any():
        return data, ()
    good = np.flatnonzero(~lost)
    if not good.size:
        raise TrackingError(f"no face in any of the {len(data)} frames")
    flat = data.reshape(len(data), -1)
    idx = np.arange(len(data))
    for col in range(flat.shape[1]):
        flat[lost, col] = np.interp(idx[lost], good, flat[good, col])
    return data, tuple(int(i) for i in np.flatnonzero(lost))


def neutral_span(neutral: int | tuple[int, int], n: int) -> slice:
    """The neutral frame or ``(start, stop)`` span as a slice; ParameterError outside
    ``n`` frames."""
    start, stop = (neutral, neutral + 1) if isinstance(neutral, int) else neutral
    if not 0 <= start < stop <= n:
        raise ParameterError(f"neutral frames {neutral!r} are outside the {n} frames")
    return slice(start, stop)


def _remove_pose(points: np.ndarray, layout: LandmarkLayout, span: slice,
                 rest_all: np.ndarray) -> tuple[np.ndarray, HeadPose | None]:
    """All landmarks ``(n, K, D)`` in the neutral head's frame, and the fit."""
    dim = points.shape[2]
    if len(layout.stable) > dim:
        stable = points[:, layout.stable]
        rest = rest_all[layout.stable]
        pose = fit_pose(rest, stable)
        if dim == 2:
            return unpose(points, pose), pose
        pose = refine_pose_2d(rest, stable, pose)
        return unpose_2d(points, rest_all, pose), pose
    if "9.3" not in layout.feature_points:
        raise TrackingError("without stable points the nose tip 9.3 must be tracked "
                            "(the seed's reference point)")
    nose = layout.feature_point_positions(points)[:, layout.index("9.3")]
    return points - (nose - nose[span].mean(axis=0))[:, None, :], None


def head_frame(landmarks: np.ndarray, *, layout: LandmarkLayout, span: slice,
               fapu: Mapping[str, float] | None = None) -> HeadFrame:
    """``(n, K, D)`` image-coordinate landmarks without gaps (:func:`fill_gaps`) in the
    neutral head's frame, with the neutral frames ``span`` and FAPU overrides ``fapu``."""
    points = face_frame(landmarks)
    local_all, pose = _remove_pose(points, layout, span, points[span].mean(axis=0))
    local = layout.feature_point_positions(local_all)
    rest = local[span].mean(axis=0)
    units = user_fapu(dict(zip(layout.feature_points, rest, strict=True)), fapu)
    return HeadFrame(local_all, local_all[span].mean(axis=0), local, rest, units, pose)
