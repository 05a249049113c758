"""Landmark tracks to a FapStream (first seed, section 4.3, eq. 4.12-4.17).

The chain, each step a function over arrays:

1. tracker landmarks ``(n, K, D)`` in image coordinates -> the face frame (``x`` to the
   face's left = the image's right in a non-mirrored camera, ``y`` up, ``z`` toward the
   camera); frames without a face are interpolated and reported;
2. rigid head pose per frame from the layout's stable points (similarity fit), undone so
   every point is in the neutral head's frame; with no stable points, the seed's nose-tip
   translation correction;
3. the user's FAPU from the neutral frames (eq. 4.1-4.5 with the midpoint reading of
   eq. 4.12-4.15), optionally overridden;
4. per-axis displacements of each tracked feature point from its neutral position divided by
   the FAP's unit, signed by the FAP table's direction (eq. 4.16 read per axis, not as the
   printed scalar distance); eyelids 19-22 are the lid points' vertical motion in IRISD;
5. gaze 23-26 from the pupils' motion relative to the eye corners (eyeball radius from the
   eye width), head pitch/yaw/roll 48-50 from the fit;
6. One Euro smoothing (blinks and closures keep their depth), then the FAP relationships of
   eq. 4.17 (and high-level states such as pucker) fill untracked FAPs.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache

import numpy as np

from facelib.checks import check_fps
from facelib.data import json_data
from facelib.errors import ParameterError, TrackingError, TrackingWarning
from facelib.mpeg4 import ANGLE_UNIT, FAPU_SCALE, N_FAPS, FapStream, fap_table
from facelib.tracking.layouts import LandmarkLayout, landmark_layout
from facelib.tracking.pose import HeadPose, euler_angles, fit_pose, unpose
from facelib.tracking.relations import apply_relations
from facelib.tracking.smoothing import one_euro
from facelib.tracking.userfapu import user_fapu

__all__ = ["TrackedFaps", "face_frame", "fill_gaps", "frame_spans", "landmarks_to_faps",
           "measure_faps"]

_AXES = {"x": 0, "y": 1, "z": 2}
_EYES = (("3.5", "3.7", "3.11", 23, 25), ("3.6", "3.12", "3.8", 24, 26))
"""(pupil, corner, corner, yaw FAP, pitch FAP) per eye."""
_HEAD = (48, 49, 50)


@dataclass(frozen=True)
class TrackedFaps:
    """What :func:`measure_faps` found.

    Attributes
    ----------
    stream: the FAPs, ``(n, 84)``.
    fapu: the user's FAPU in the landmarks' unit per FAP unit (``AU`` in radians).
    pose: the per-frame head fit (None when only translation was corrected).
    filled_frames: frames with no landmarks, interpolated from their neighbours.
    """

    stream: FapStream
    fapu: dict[str, float]
    pose: HeadPose | None
    filled_frames: tuple[int, ...]


@cache
def _model() -> dict[str, dict[str, float]]:
    return json_data("tracking/model.json")


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


def _neutral_span(neutral: int | tuple[int, int], n: int) -> slice:
    start, stop = (neutral, neutral + 1) if isinstance(neutral, int) else neutral
    if not 0 <= start < stop <= n:
        raise ParameterError(f"neutral frames {neutral!r} are outside the {n} frames")
    return slice(start, stop)


def _remove_pose(points: np.ndarray, fps: np.ndarray, layout: LandmarkLayout,
                 span: slice) -> tuple[np.ndarray, HeadPose | None]:
    """Feature points ``(n, P, D)`` in the neutral head's frame, and the fit."""
    dim = points.shape[2]
    if len(layout.stable) > dim:
        stable = points[:, layout.stable]
        pose = fit_pose(stable[span].mean(axis=0), stable)
        return unpose(fps, pose), pose
    if "9.3" not in layout.feature_points:
        raise TrackingError("without stable points the nose tip 9.3 must be tracked "
                            "(the seed's reference point)")
    nose = fps[:, layout.index("9.3")]
    return fps - (nose - nose[span].mean(axis=0))[:, None, :], None


def _plan(layout: LandmarkLayout, pose: HeadPose | None
          ) -> list[tuple[int, int, int, float, str]]:
    """(FAP column, point row, axis, sign, FAPU name) for every directly measured FAP."""
    stable = set(layout.stable.tolist())
    fixed = {fp for p, fp in enumerate(layout.feature_points)
             if set(np.flatnonzero(layout.weights[p]).tolist()) <= stable}
    if pose is None:
        fixed = {"9.3"}
    plan = []
    for fap in fap_table():
        if fap.kind != "translation" or fap.axis not in ("x", "y"):
            continue
        fp = fap.feature_points[0]
        if fp not in layout.feature_points or fp in fixed:
            continue
        axis = _AXES[fap.axis]
        plan.append((fap.index, layout.index(fp), axis, float(np.sign(fap.direction[axis])),
                     fap.fapu))
    return plan


def _gaze(local: np.ndarray, layout: LandmarkLayout, span: slice,
          values: np.ndarray, mask: np.ndarray) -> None:
    """Eyeball yaw/pitch (FAPs 23-26, AU) from pupil motion relative to the eye corners."""
    ratio = float(_model()["eyeball_radius_per_eye_width"]["value"])
    for pupil, c1, c2, yaw_id, pitch_id in _EYES:
        if not all(fp in layout.feature_points for fp in (pupil, c1, c2)):
            continue
        a, b = local[:, layout.index(c1)], local[:, layout.index(c2)]
        rel = local[:, layout.index(pupil)] - (a + b) / 2
        radius = ratio * float(np.linalg.norm((a - b)[span].mean(axis=0)[:2]))
        move = (rel - rel[span].mean(axis=0)) / radius
        values[:, yaw_id - 1] = np.arcsin(np.clip(move[:, 0], -1, 1)) / ANGLE_UNIT
        values[:, pitch_id - 1] = np.arcsin(np.clip(-move[:, 1], -1, 1)) / ANGLE_UNIT
        mask[:, [yaw_id - 1, pitch_id - 1]] = True


def _smooth(values: np.ndarray, mask: np.ndarray, fps: float) -> np.ndarray:
    """One Euro filter on the measured columns, in FAPU0 distances and radians."""
    cols = np.flatnonzero(mask.any(axis=0))
    if not cols.size:
        return values
    scale = np.array([ANGLE_UNIT if fap_table()[c].fapu == "AU" else 1 / FAPU_SCALE
                      for c in cols])
    params = _model()["one_euro"]
    smooth = one_euro(values[:, cols] * scale, fps=fps, min_cutoff=params["min_cutoff_hz"],
                      beta=params["beta"], d_cutoff=params["d_cutoff_hz"])
    out = values.copy()
    out[:, cols] = smooth / scale
    return out


def measure_faps(
    landmarks: np.ndarray,
    *,
    fps: float,
    layout: str | LandmarkLayout = "mediapipe",
    neutral: int | tuple[int, int] = 0,
    fapu: Mapping[str, float] | None = None,
    smooth: bool = True,
    states: Mapping[str, np.ndarray] | None = None,
    relations: bool = True,
) -> TrackedFaps:
    """FAPs from landmark tracks; see the module docstring for the steps.

    Parameters
    ----------
    landmarks: ``(n_frames, K, 2 or 3)`` image coordinates (column, row[, depth, larger =
        farther, in pixel units]); a frame of NaN means no face there.
    fps: the frames' rate.
    layout: a packaged layout name (``"mediapipe"``, ``"ibug68"``) or a
        :class:`~facelib.tracking.layouts.LandmarkLayout`.
    neutral: the neutral frame, or a ``(start, stop)`` span averaged.
    fapu: FAPU overrides in the landmarks' unit (e.g. ``{"MNS": 18.3 / 1024}``).
    smooth: apply the One Euro filter.
    states: high-level state -> ``(n_frames,) bool`` (``{"pucker": frames}``), eq. 4.17.
    relations: fill untracked FAPs by eq. 4.17.
    """
    rate = check_fps(fps)
    data = np.asarray(landmarks, np.float64)
    if data.ndim != 3 or data.shape[2] not in (2, 3) or len(data) == 0:
        raise TrackingError(f"landmarks must have shape (n_frames, K, 2 or 3), got {data.shape}")
    if isinstance(layout, str):
        layout = landmark_layout(layout, data.shape[1])
    data, filled = fill_gaps(data)
    if filled:
        warnings.warn(TrackingWarning(f"no face in frames {frame_spans(np.array(filled))} of "
                                      f"{len(data)}; interpolated"), stacklevel=2)
    points = face_frame(data)
    span = _neutral_span(neutral, len(data))
    local, pose = _remove_pose(points, layout.feature_point_positions(points), layout, span)
    rest = local[span].mean(axis=0)
    units = user_fapu(dict(zip(layout.feature_points, rest, strict=True)), fapu)
    values = np.zeros((len(data), N_FAPS))
    mask = np.zeros((len(data), N_FAPS), bool)
    disp = local - rest
    for col, row, axis, sign, unit in _plan(layout, pose):
        values[:, col] = sign * disp[:, row, axis] / units[unit]
        mask[:, col] = True
    _gaze(local, layout, span, values, mask)
    if pose is not None:
        for fap_id, angle in zip(_HEAD, euler_angles(pose.rotation), strict=True):
            values[:, fap_id - 1] = angle / ANGLE_UNIT
            mask[:, fap_id - 1] = True
    if smooth:
        values = _smooth(values, mask, rate)
    for fap in fap_table():  # unidirectional FAPs with a floor of 0 (open_jaw, thrust_jaw)
        if fap.bidirectional is False and fap.min == 0:
            values[:, fap.index] = np.maximum(values[:, fap.index], 0.0)
    if relations or states:
        values, mask = apply_relations(values, mask, frame_states=states)
    return TrackedFaps(FapStream(rate, values, mask), units, pose, filled)


def landmarks_to_faps(landmarks: np.ndarray, *, fps: float, **options: object) -> FapStream:
    """:func:`measure_faps` (same options), returning only the FapStream."""
    return measure_faps(landmarks, fps=fps, **options).stream  # type: ignore[arg-type]
