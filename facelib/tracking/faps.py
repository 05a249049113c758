"""Landmark tracks to a FapStream (first seed, section 4.3, eq. 4.12-4.17).

The chain, each step a function over arrays:

1. tracker landmarks ``(n, K, D)`` in image coordinates -> the face frame (``x`` to the
   face's left = the image's right in a non-mirrored camera, ``y`` up, ``z`` toward the
   camera); frames without a face are interpolated and reported;
2. rigid head pose per frame from the layout's stable points (similarity fit), undone so
   every point is in the neutral head's frame; with no stable points, the seed's nose-tip
   translation correction (steps 2-5 run on chunks of frames against the neutral face read
   first, so a long track is never copied whole);
3. the user's FAPU from the neutral frames (eq. 4.1-4.5 with the midpoint reading of
   eq. 4.12-4.15), optionally overridden;
4. per-axis displacements of each tracked feature point from its neutral position divided by
   the FAP's unit, signed by the FAP table's direction (eq. 4.16 read per axis, not as the
   printed scalar distance); eyelids 19-22 are the lid points' vertical motion in IRISD;
   optionally refined by fitting a face's rig (:mod:`~facelib.tracking.rigfit`);
   for MediaPipe's 478 landmarks in 3-D, by default, the learned observation model
   (:mod:`~facelib.tracking.observation`) replaces this step and the next one's gaze;
5. gaze 23-26 from the pupils' motion relative to the eye corners (eyeball radius from the
   eye width), head pitch/yaw/roll 48-50 from the fit (with the learned model, plus its
   estimate of the fit's error);
6. One Euro smoothing (blinks and closures keep their depth) and the jaw drawn across brief
   closures, the closed mouth of p/b/m (:mod:`~facelib.tracking.lipclosure`), then the FAP
   relationships of eq. 4.17 (and high-level states such as pucker) fill untracked FAPs.
"""

from __future__ import annotations

import warnings
from collections.abc import Collection, Mapping
from dataclasses import dataclass
from functools import cache
from typing import Any, Literal

import numpy as np

from facelib.checks import check_fps
from facelib.data import json_data
from facelib.errors import DataError, ParameterError, TrackingError, TrackingWarning
from facelib.mpeg4 import ANGLE_UNIT, FAPU_SCALE, N_FAPS, FapStream, fap, fap_table
from facelib.tracking import lipclosure
from facelib.tracking.headframe import (
    HeadFrame,
    Neutral,
    face_frame,
    fill_gaps,
    frame_spans,
    neutral_face,
    neutral_span,
    to_head_frame,
)
from facelib.tracking.layouts import LandmarkLayout, landmark_layout
from facelib.tracking.neutral import NeutralChoice, neutral_news, neutral_window
from facelib.tracking.observation import (
    ObservationModel,
    default_observation,
    head_angles,
    solve_observation,
)
from facelib.tracking.pose import HEAD_FAP_IDS, HeadPose, join_poses
from facelib.tracking.relations import apply_relations
from facelib.tracking.rigfit import RigModel, fit_faps, rig_model
from facelib.tracking.smoothing import one_euro
from facelib.tracking.userfapu import user_fapu

__all__ = ["FilterBand", "MeasuredFrames", "TrackedFaps", "checked_inputs", "face_frame",
           "fill_gaps", "filter_bands", "frame_spans", "landmarks_to_faps", "measure_faps",
           "measure_frames", "mouth_closed", "settle_faps"]

_AXES = {"x": 0, "y": 1, "z": 2}
_EYES = (("3.5", "3.7", "3.11", 23, 25), ("3.6", "3.12", "3.8", 24, 26))
"""(pupil, corner, corner, yaw FAP, pitch FAP) per eye."""


@dataclass(frozen=True)
class TrackedFaps:
    """What :func:`measure_faps` found.

    Attributes
    ----------
    stream: the FAPs, ``(n, 84)``.
    fapu: the user's FAPU in the landmarks' unit per FAP unit (``AU`` in radians).
    pose: the per-frame head fit, its axes the neutral head's, levelled (rotations
        ``L R L^T``, translations ``L t`` with ``L`` the neutral's ``level``; None when
        only translation was corrected).
    filled_frames: frames with no landmarks, interpolated from their neighbours.
    """

    stream: FapStream
    fapu: dict[str, float]
    pose: HeadPose | None
    filled_frames: tuple[int, ...]


@cache
def _model() -> dict[str, dict[str, Any]]:
    return json_data("tracking/model.json")


def _plan(layout: LandmarkLayout, pose: HeadPose | None
          ) -> list[tuple[int, int, int, float, str]]:
    """(FAP column, point row, axis, sign, FAPU name) for every directly measured FAP.

    Points that cannot move relative to the head are left out: the stable points of the
    pose fit, or, without one, the nose tip 9.3, the seed's reference.
    """
    stable = set(layout.stable.tolist())
    fixed = {fp for p, fp in enumerate(layout.feature_points)
             if set(np.flatnonzero(layout.weights[p]).tolist()) <= stable}
    if pose is None:
        fixed = {"9.3"}
    plan = []
    for entry in fap_table():
        if entry.kind != "translation" or entry.axis not in ("x", "y"):
            continue
        fp = entry.feature_points[0]
        if fp not in layout.feature_points or fp in fixed:
            continue
        axis = _AXES[entry.axis]
        plan.append((entry.index, layout.index(fp), axis, float(np.sign(entry.direction[axis])),
                     entry.fapu))
    return plan


def _pupil_offset(points: np.ndarray, rows: tuple[int, int, int]) -> np.ndarray:
    """``(..., P, D)`` feature points -> ``(..., D)`` the pupil (row ``rows[0]``) relative to
    the midpoint of the eye corners (rows ``rows[1:]``)."""
    pupil, c1, c2 = rows
    return points[..., pupil, :] - (points[..., c1, :] + points[..., c2, :]) / 2


def _gaze(frame: HeadFrame, layout: LandmarkLayout, values: np.ndarray,
          mask: np.ndarray) -> None:
    """Eyeball yaw/pitch (FAPs 23-26, AU) from pupil motion relative to the eye corners."""
    ratio = float(_model()["eyeball_radius_per_eye_width"]["value"])
    for pupil, c1, c2, yaw_id, pitch_id in _EYES:
        if not all(fp in layout.feature_points for fp in (pupil, c1, c2)):
            continue
        rows = (layout.index(pupil), layout.index(c1), layout.index(c2))
        rest = frame.rest_points
        radius = ratio * float(np.linalg.norm((rest[rows[1]] - rest[rows[2]])[:2]))
        move = (_pupil_offset(frame.points, rows) - _pupil_offset(rest, rows)) / radius
        values[:, yaw_id - 1] = np.arcsin(np.clip(move[:, 0], -1, 1)) / ANGLE_UNIT
        values[:, pitch_id - 1] = np.arcsin(np.clip(-move[:, 1], -1, 1)) / ANGLE_UNIT
        mask[:, [yaw_id - 1, pitch_id - 1]] = True


def _fit(frame: HeadFrame, model: RigModel, *, values: np.ndarray, mask: np.ndarray
         ) -> None:
    """FAPs of ``model`` by fitting the face's rig, plus a small residual head motion, to
    the landmark motion relative to nearby anchors (:mod:`~facelib.tracking.rigfit`)."""
    points = frame.landmarks[:, model.landmarks]
    rest = frame.rest[model.landmarks]
    found = fit_faps(model, points[..., :2] - rest[:, :2], frame.fapu,
                     rest=rest if points.shape[2] == 3 else None)
    values[:, model.faps - 1] = found
    mask[:, model.faps - 1] = True


@cache
def default_rig() -> RigModel:
    """The default head's rig for MediaPipe's mesh landmarks (0-467, the iris excluded)."""
    from facelib.engine import default_face
    from facelib.tracking.embedding import default_head_embedding

    layout = landmark_layout("mediapipe")
    face = default_face()
    on_face = layout.feature_point_positions(face.vertices[default_head_embedding()][None])[0]
    measured = user_fapu(dict(zip(layout.feature_points, on_face, strict=True)))
    return rig_model(face, default_head_embedding(), np.arange(468), anchors=layout.anchors,
                     landmark_fapu=measured)


@dataclass(frozen=True)
class FilterBand:
    """FAP columns the One Euro filter treats alike: ``cols`` ``(c,)``, ``scale`` ``(c,)``
    from FAP units to FAPU0 distances and radians, and the filter's parameters."""

    cols: np.ndarray
    scale: np.ndarray
    min_cutoff: float
    beta: float
    d_cutoff: float


def filter_bands(measured: np.ndarray) -> list[FilterBand]:
    """The bands of the ``(84,) bool`` measured columns: the jaw and lips with a higher
    still cutoff than the rest (``model.json``); a band with no column is left out."""
    params = _model()["one_euro"]
    try:
        mouth = np.isin(np.arange(N_FAPS) + 1, params["mouth_faps"])
        cutoffs = (float(params["mouth_min_cutoff_hz"]), float(params["min_cutoff_hz"]))
        beta, d_cutoff = float(params["beta"]), float(params["d_cutoff_hz"])
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"malformed one_euro parameters ({exc})",
                        path="tracking/model.json") from exc
    bands = []
    for group, cutoff in zip((mouth, ~mouth), cutoffs, strict=True):
        cols = np.flatnonzero(measured & group)
        scale = np.array([ANGLE_UNIT if fap_table()[c].fapu == "AU" else 1 / FAPU_SCALE
                          for c in cols])
        if cols.size:
            bands.append(FilterBand(cols, scale, cutoff, beta, d_cutoff))
    return bands


def _smooth(values: np.ndarray, mask: np.ndarray, fps: float) -> np.ndarray:
    """``(n, 84)`` ``values`` with the One Euro filter run both ways (no lag: the track is
    recorded) over the columns ``mask`` ``(n, 84)`` measures (:func:`filter_bands`)."""
    out = values.copy()
    for band in filter_bands(np.any(mask, axis=0)):
        out[:, band.cols] = one_euro(values[:, band.cols] * band.scale, fps=fps,
                                     min_cutoff=band.min_cutoff, beta=band.beta,
                                     d_cutoff=band.d_cutoff, causal=False) / band.scale
    return out


Model = RigModel | ObservationModel
"""What :func:`measure_faps` fits to the landmark motion."""


def checked_inputs(landmarks: np.ndarray, layout: str | LandmarkLayout,
                   rig: Model | Literal["auto", "default", "observed"] | None
                   ) -> tuple[np.ndarray, LandmarkLayout, Model | None]:
    """Checked ``(n, K, D)`` landmarks (float64), the layout, and the model to fit (or None),
    by :func:`measure_faps`'s rules for ``layout`` and ``rig``."""
    data = np.asarray(landmarks, np.float64)
    if data.ndim != 3 or data.shape[2] not in (2, 3) or len(data) == 0:
        raise TrackingError(f"landmarks must have shape (n_frames, K, 2 or 3), got {data.shape}")
    if isinstance(layout, str):
        layout = landmark_layout(layout, data.shape[1])
    mediapipe_3d = layout.name == "mediapipe" and data.shape[2] == 3
    if rig == "auto":
        rig = "observed" if mediapipe_3d and layout.n_points == 478 else None
    if rig == "default" and layout.name != "mediapipe":
        raise ParameterError(f"rig='default' needs MediaPipe landmarks, not {layout.name!r}")
    if (rig == "observed" or isinstance(rig, ObservationModel)) and not (
            mediapipe_3d and layout.n_points == 478):
        raise ParameterError("the observation model needs MediaPipe's 478 landmarks in 3-D")
    if rig == "default":
        return data, layout, default_rig()
    if rig == "observed":
        return data, layout, default_observation()
    return data, layout, rig


def _observe(frame: HeadFrame, model: ObservationModel, *, values: np.ndarray,
             mask: np.ndarray, brows: np.ndarray | None, angles: np.ndarray | None) -> None:
    """FAPs of ``model`` from the landmark motion (:mod:`~facelib.tracking.observation`),
    and the brows' image shifts when there are some."""
    found = solve_observation(model, frame.motion, frame.fapu, brows=brows, angles=angles)
    values[:, model.faps - 1] = found
    mask[:, model.faps - 1] = True


def _face_faps(frame: HeadFrame, layout: LandmarkLayout, model: Model | None, *,
               brows: np.ndarray | None = None, angles: np.ndarray | None = None
               ) -> tuple[np.ndarray, np.ndarray]:
    """``(n, 84)`` values and mask of the face FAPs: the learned model (with the ``(n, 4)``
    ``brows`` and ``(n, 3)`` ``angles`` its image part reads), or eq. 4.16 (refined by a rig
    fit) and the gaze of the pupils."""
    n = len(frame.landmarks)
    values = np.zeros((n, N_FAPS))
    mask = np.zeros((n, N_FAPS), bool)
    if isinstance(model, ObservationModel):
        _observe(frame, model, values=values, mask=mask, brows=brows, angles=angles)
        return values, mask
    moved = frame.points - frame.rest_points
    for col, row, axis, sign, unit in _plan(layout, frame.pose):  # eq. 4.16, per axis
        values[:, col] = sign * moved[:, row, axis] / frame.fapu[unit]
        mask[:, col] = True
    if model is not None:
        _fit(frame, model, values=values, mask=mask)
    _gaze(frame, layout, values, mask)
    return values, mask


@dataclass(frozen=True)
class MeasuredFrames:
    """What :func:`measure_frames` reads off ``n`` frames, before smoothing: ``values`` and
    ``mask`` ``(n, 84)``, the head ``pose`` (None without stable points) and the inner-lip
    ``aperture`` ``(n,)`` (None when the mouth state is not read)."""

    values: np.ndarray
    mask: np.ndarray
    pose: HeadPose | None
    aperture: np.ndarray | None


_CHUNK_FRAMES = 1024
_NEUTRAL_SEARCH_FRAMES = 3000  # a first pass over at most about this many frames
"""Frames put in the head frame at a time, so a long track needs a few copies of a chunk's
landmarks, not of the whole track's."""


def measure_frames(landmarks: np.ndarray, neutral: Neutral, *, layout: LandmarkLayout,
                   model: Model | None, lips: bool, brows: np.ndarray | None = None
                   ) -> MeasuredFrames:
    """The face FAPs, head pose and (``lips``) inner-lip aperture of ``(n, K, D)`` gap-free
    landmarks (any frames of a track), measured against the track's ``neutral`` face
    (:func:`~facelib.tracking.headframe.neutral_face`) with ``model`` (see
    :func:`measure_faps`'s ``rig``) and the frames' ``(n, 4)`` brow image shifts, if any."""
    frame = to_head_frame(landmarks, neutral, layout=layout)
    angles = None
    if frame.pose is not None:  # with the learned model, the fit's learned error taken out
        angles = head_angles(frame, model if isinstance(model, ObservationModel) else None)
    values, mask = _face_faps(frame, layout, model, brows=brows, angles=angles)
    if angles is not None:
        values[:, [f - 1 for f in HEAD_FAP_IDS]] = angles / ANGLE_UNIT
        mask[:, [f - 1 for f in HEAD_FAP_IDS]] = True
    aperture = (lipclosure.inner_lip_aperture(frame, lipclosure.lip_closure())
                if lips else None)
    return MeasuredFrames(values, mask, frame.pose, aperture)


def _chunks(n: int) -> list[slice]:
    """``n`` frames cut into chunks of :data:`_CHUNK_FRAMES`."""
    return [slice(i, i + _CHUNK_FRAMES) for i in range(0, n, _CHUNK_FRAMES)]


def _join(chunks: list[MeasuredFrames]) -> MeasuredFrames:
    """Consecutive chunks of a track as one."""
    poses = [c.pose for c in chunks if c.pose is not None]
    apertures = [c.aperture for c in chunks if c.aperture is not None]
    return MeasuredFrames(np.concatenate([c.values for c in chunks]),
                          np.concatenate([c.mask for c in chunks]),
                          join_poses(poses) if poses else None,
                          np.concatenate(apertures) if apertures else None)


def mouth_closed(aperture: np.ndarray, *, closed: bool = False) -> np.ndarray:
    """``(n,) bool`` frames in the closed mouth state by the packaged rule's hysteresis on
    the ``(n,)`` inner-lip ``aperture`` (:mod:`~facelib.tracking.lipclosure`); ``closed``:
    the state before the first frame."""
    rule = lipclosure.lip_closure()
    return lipclosure.closed_frames(aperture, close_below=rule.close_below,
                                    open_above=rule.open_above, closed=closed)


def settle_faps(values: np.ndarray, mask: np.ndarray, *,
                lips: tuple[np.ndarray, np.ndarray] | None,
                states: Mapping[str, np.ndarray] | None = None, relations: bool = True
                ) -> tuple[np.ndarray, np.ndarray]:
    """After smoothing: the floor of unidirectional FAPs, the mouth state, then eq. 4.17.

    ``values`` and ``mask`` ``(n, 84)``; ``lips``: the inner-lip aperture ``(n,)`` and the
    closed state ``(n,) bool`` (:func:`mouth_closed`): closed lips for p/b/m, at least the
    aperture's opening elsewhere (None: left as measured); ``states`` and ``relations`` as
    in :func:`measure_faps`.
    """
    values = values.copy()
    for entry in fap_table():  # unidirectional FAPs with a floor of 0 (open_jaw, thrust_jaw)
        if entry.bidirectional is False and entry.min == 0:
            values[:, entry.index] = np.maximum(values[:, entry.index], 0.0)
    if lips is not None:  # after the floor: the lip separation counts open_jaw as shown
        aperture, closed = lips
        rule = lipclosure.lip_closure()
        mask = mask.copy()
        mask[:, lipclosure.closed_lip_columns(rule)] = True
        values = lipclosure.close_lips(values, closed, rule)
        values = lipclosure.open_lips(values, aperture, closed, rule)
    if relations or states:
        values, mask = apply_relations(values, mask, frame_states=states)
    return values, mask


def _brow_shifts(brows: np.ndarray | None, model: Model | None, n: int) -> np.ndarray | None:
    """``(n, 4)`` brow image shifts with lost frames interpolated, or None without any or
    when ``model`` cannot read them; ParameterError for another shape."""
    if brows is None:
        return None
    shifts = np.asarray(brows, np.float64)
    if shifts.shape != (n, 4):
        raise ParameterError(f"brows must be ({n}, 4): 4 shifts per landmark frame, got "
                             f"{shifts.shape}")
    if (not isinstance(model, ObservationModel) or model.image_faps is None
            or not np.isfinite(shifts).all(axis=1).any()):
        return None
    return fill_gaps(shifts[:, None, :])[0][:, 0, :]


def measure_faps(
    landmarks: np.ndarray,
    *,
    fps: float,
    layout: str | LandmarkLayout = "mediapipe",
    neutral: int | tuple[int, int] | None = None,
    fapu: Mapping[str, float] | None = None,
    smooth: bool = True,
    states: Mapping[str, np.ndarray] | None = None,
    relations: bool = True,
    rig: Model | Literal["auto", "default", "observed"] | None = "auto",
    close_lips: bool = True,
    brows: np.ndarray | None = None,
) -> TrackedFaps:
    """FAPs from landmark tracks; see the module docstring for the steps.

    Parameters
    ----------
    landmarks: ``(n_frames, K, 2 or 3)`` image coordinates (column, row[, depth, larger =
        farther, in pixel units]); a frame of NaN means no face there.
    fps: the frames' rate.
    layout: a packaged layout name (``"mediapipe"``, ``"ibug68"``) or a
        :class:`~facelib.tracking.layouts.LandmarkLayout`.
    neutral: the neutral frame, or a ``(start, stop)`` span averaged over its frames with a
        face; None: the first frame with a face, or :func:`find_neutral`'s span (warned)
        when that is clearly not neutral. TrackingError when it has none.
    fapu: FAPU overrides in the landmarks' unit (e.g. ``{"MNS": 18.3 / 1024}``).
    smooth: the steps that need the whole track: the One Euro filter (both ways) and, with
        the mouth state, open_jaw drawn across brief closures (``lipclosure.bridge_jaw``).
    states: high-level state -> ``(n_frames,) bool`` (``{"pucker": frames}``), eq. 4.17.
    relations: fill untracked FAPs by eq. 4.17.
    rig: the model read off the landmark motion instead of eq. 4.16's one point per FAP:
        ``"observed"`` (or an :class:`~facelib.tracking.observation.ObservationModel`) the
        observation model learned from renders (needs MediaPipe's 478 landmarks in 3-D;
        it also gives gaze); ``"default"`` (or a
        :class:`~facelib.tracking.rigfit.RigModel`) the default head's rig fitted to the
        landmarks (needs the ``mediapipe`` layout); ``"auto"`` (the default): ``"observed"``
        for 478 3-D MediaPipe landmarks, else eq. 4.16; None: always eq. 4.16.
    close_lips: with a model (``rig`` not None) on MediaPipe landmarks, apply the mouth
        state read off the inner-lip aperture (:mod:`~facelib.tracking.lipclosure`): close
        the lips in the frames of a p, b or m and open them at least as far as the
        aperture shows in the others. False turns both off.
    brows: ``(n_frames, 4)`` the brows' shifts read off the video's frames
        (:mod:`~facelib.tracking.browimage`; NaN rows: no face): an observation model with
        an image part (the packaged one) reads its brow FAPs with them, others ignore them.
    """
    rate = check_fps(fps)
    data, layout, model = checked_inputs(landmarks, layout, rig)
    data, filled = fill_gaps(data)
    rest = _neutral(data, filled, neutral, fps=rate, layout=layout, model=model, fapu=fapu)
    shifts = _brow_shifts(brows, model, len(data))
    lips = close_lips and model is not None and layout.name == "mediapipe"
    found = _join([measure_frames(data[cut], rest, layout=layout, model=model, lips=lips,
                                  brows=None if shifts is None else shifts[cut])
                   for cut in _chunks(len(data))])
    mouth = None if found.aperture is None else (found.aperture, mouth_closed(found.aperture))
    values, mask = settle_faps(  # the smoothed values are passed on, not kept: one copy less
        _over_time(found, rate, None if mouth is None else mouth[1]) if smooth else found.values,
        found.mask, states=states, relations=relations, lips=mouth)
    return TrackedFaps(FapStream(rate, values, mask), rest.fapu, found.pose, filled)


_GAZE = slice(22, 26)
_UPPER_LIDS = slice(18, 20)


def bridge_gaze(values: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """``(n, 84)`` ``values`` with the gaze (23-26) drawn straight across the frames whose
    upper lids (19, 20) read closed (``model.json``, ``gaze_under_closed_lids``) from the
    open frames either side (held at a track's ends); ``values`` itself where the mask has
    no gaze and lids or no lid closes (a copy otherwise)."""
    if not (mask[:, _GAZE].all() and mask[:, _UPPER_LIDS].all()):
        return values
    shut = values[:, _UPPER_LIDS].mean(axis=1) > _model()["gaze_under_closed_lids"]["lid_above"]
    if not shut.any() or shut.all():
        return values
    out = np.array(values)
    frames = np.arange(len(values))
    for col in range(_GAZE.start, _GAZE.stop):
        out[shut, col] = np.interp(frames[shut], frames[~shut], values[~shut, col])
    return out


def _over_time(found: MeasuredFrames, rate: float, closed: np.ndarray | None) -> np.ndarray:
    """The steps that need the whole recorded track, on ``found``'s ``(n, 84)`` values: the
    gaze drawn across closed lids (:func:`bridge_gaze`), the One Euro filter both ways,
    then open_jaw drawn across the brief runs of ``closed``
    ``(n,) bool`` frames (:func:`~facelib.tracking.lipclosure.bridge_jaw`; None: no mouth
    state)."""
    values = _smooth(bridge_gaze(found.values, found.mask), found.mask, rate)
    if closed is not None:
        jaw = fap("open_jaw").index
        values[:, jaw] = lipclosure.bridge_jaw(
            values[:, jaw], closed, longest=round(lipclosure.lip_closure().jaw_bridge_s * rate))
    return values


def _neutral(data: np.ndarray, filled: tuple[int, ...], neutral: int | tuple[int, int] | None,
             *, fps: float, layout: LandmarkLayout, model: Model | None,
             fapu: Mapping[str, float] | None) -> Neutral:
    """:func:`measure_faps`'s neutral face of the gap-filled ``data`` at ``fps`` (its
    ``filled`` frames had no face), after a TrackingWarning naming those frames, and one
    when ``neutral`` is None and the first frame with a face is not neutral
    (:func:`find_neutral`)."""
    span = neutral_span(neutral, len(data), lost=filled)
    if filled:
        news = f"no face in frames {frame_spans(np.array(filled))} of {len(data)}; interpolated"
        if neutral is None and span.start:
            news += f"; the neutral is frame {span.start}, the first with a face"
        warnings.warn(TrackingWarning(news), stacklevel=3)
    if neutral is None:
        choice = find_neutral(data, fps=fps, layout=layout, rig=model, first=span.start,
                              excluded=filled)
        if choice.searched:
            warnings.warn(TrackingWarning(neutral_news(choice, span.start)), stacklevel=3)
        span = choice.span
    return neutral_face(data, layout=layout, span=span, fapu=fapu, lost=filled)


def find_neutral(landmarks: np.ndarray, *, fps: float,
                 layout: str | LandmarkLayout = "mediapipe",
                 rig: Model | Literal["auto", "default", "observed"] | None = "auto",
                 first: int = 0, excluded: Collection[int] = ()) -> NeutralChoice:
    """The neutral frames of ``(n, K, D)`` landmarks (NaN rows: no face) at ``fps`` when
    the user names none: frame ``first`` (the first with a face, or a well-lit one) unless
    a first pass of :func:`measure_frames` against it, with ``layout`` and ``rig`` as for
    :func:`measure_faps`, finds it clearly not neutral
    (:func:`~facelib.tracking.neutral.neutral_window`; ``excluded`` frames are never the
    neutral). Long tracks are searched at about :data:`_NEUTRAL_SEARCH_FRAMES` frames."""
    data, layout, model = checked_inputs(landmarks, layout, rig)
    data, lost = fill_gaps(data)
    rest = neutral_face(data, layout=layout, span=slice(first, first + 1), lost=lost)
    step = max(1, len(data) // _NEUTRAL_SEARCH_FRAMES)
    values = np.concatenate([measure_frames(data[::step][cut], rest, layout=layout,
                                            model=model, lips=False).values
                             for cut in _chunks(len(data[::step]))])
    skip = {i // step for i in {*lost, *excluded} if i % step == 0}
    found = neutral_window(values, fps=fps / step, first=-(-first // step), excluded=skip)
    if not found.searched:
        return NeutralChoice(slice(first, first + 1))
    span = slice(found.span.start * step, (found.span.stop - 1) * step + 1)
    return NeutralChoice(span, found.jaw_below)


def landmarks_to_faps(landmarks: np.ndarray, *, fps: float, **options: object) -> FapStream:
    """:func:`measure_faps` (same options), returning only the FapStream."""
    return measure_faps(landmarks, fps=fps, **options).stream  # type: ignore[arg-type]
