"""An observation model learned by analysis by synthesis: FAPs read off the tracker's
landmark motion by a linear estimator learned from renders.

The default head is rendered with random FAP poses and head turns (a seeded training
stream, ``tools/build_tracking_observation.py``), MediaPipe tracks the renders, and the
landmarks are put in the neutral head's frame (rigid fit, :mod:`facelib.tracking.headframe`).
Each frame gives ``d``: the ``x, y`` motion of all 478 landmarks from their neutral
positions over the user's eye separation ``ES0``, and the FAPs that made it, each as a
displacement ``f_k L_k / ES0`` (``L_k`` the FAP's unit length, :func:`fap_lengths`). A
regression on the leading principal components of ``d`` (the components take the
correlated jitter of neighbouring landmarks out) learns ``E``, ``(478 * 2, m)``, and
tracking reads ``f_k = (d E)_k ES0 / L_k``, kept within the range seen in training.

Why an estimator and not the inverse of a forward model: MediaPipe's landmarks on a face
are not the mesh's vertices and do not move linearly with the FAPs (a linear forward model
explains the training renders' jaw only to r = 0.89), and many FAPs move the same landmarks
alike (inner and outer lip); solving the forward model by bounded least squares split the
motion between them (open_jaw r = 0.72-0.78 on the closed loop), where the learned estimator
carries the statistics of facelib's visemes and expressions (r = 0.88). Both sides are
measured on the tracker's own landmarks in the user's FAPU, so the model carries over to
other faces.

Some FAPs can be learned from some landmarks alone (:class:`LandmarkRegion`): the packaged
model reads the gaze from the eyes and the face's outline only (:func:`gaze_region`), so that
a raised brow or an open jaw is not read as a look on a face other than the training head.

The same regression learns the rigid pose fit's error (true minus fitted pitch, yaw and
roll): expressions move the fit's stable points (a smile lifts the nostrils, which the fit
alone reads as a nod of several degrees); tracking adds the estimate to the fitted angles
(:func:`pose_correction`).
"""

from __future__ import annotations

import dataclasses
import io
import os
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np

from facelib.atomic import atomic_path
from facelib.checks import check_count
from facelib.data import json_data
from facelib.data import path as data_path
from facelib.errors import DataError, ParameterError, TrackingError
from facelib.mpeg4 import ANGLE_UNIT, FAPU_SCALE, N_FAPS, fap_table
from facelib.tracking.headframe import HeadFrame, head_frame, neutral_span
from facelib.tracking.layouts import landmark_layout
from facelib.tracking.pose import HEAD_FAP_IDS, euler_angles

__all__ = ["IMAGE_FAPS", "MODEL_FAPS", "LandmarkRegion", "ObservationModel", "default_observation",
           "fap_lengths", "gaze_region", "head_angles", "image_inputs", "learn_observation",
           "load_observation", "pose_correction", "save_observation", "solve_observation"]

IMAGE_FAPS = (31, 32, 33, 34, 35, 36, 37, 38)
"""FAPs the packaged model also reads off the brows' image shifts: the brows' raise and
squeeze."""
MODEL_FAPS = (3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 16, 17, 19, 20, 21, 22, 23, 24, 25, 26,
              31, 32, 33, 34, 35, 36, 37, 38, 41, 42, 51, 52, 53, 54, 55, 56, 57, 58, 59, 60,
              61, 62)
"""FAPs the packaged model learns: what facelib's visemes, expressions, lids and gaze move
on the skin and eyes (tongue, head and ears are left out)."""
_DATA = "tracking/observation_mediapipe.npz"


@dataclass(frozen=True)
class LandmarkRegion:
    """Some FAPs learned from some landmarks only (see :func:`learn_observation`).

    faps: FAP ids (among the model's); landmarks: distinct landmark rows they are read
    from; components: principal components of those landmarks' motion the regression uses
    (at most twice the landmarks, and fewer than the frames).
    """

    faps: tuple[int, ...]
    landmarks: tuple[int, ...]
    components: int


def gaze_region() -> LandmarkRegion:
    """The packaged model's gaze FAPs 23-26 and the MediaPipe landmarks they are learned
    from (``model.json``, ``gaze_region``): the eye contours, the irises and the face's
    outline."""
    raw = json_data("tracking/model.json")["gaze_region"]
    return LandmarkRegion(tuple(raw["faps"]), tuple(raw["landmarks"]), int(raw["components"]))


@dataclass(frozen=True)
class ObservationModel:
    """A learned linear map from landmark motion to FAPs.

    Attributes
    ----------
    faps: ``(m,) int64`` FAP ids.
    estimator: ``(L, 2, m) float64``: FAP displacement (over ES0) per unit of each
        landmark's ``x, y`` motion (over ES0) in the neutral head's frame.
    bounds: ``(m, 2) float64`` lowest and highest FAP value (FAP units) seen in training,
        widened by a tenth of the range.
    pose: ``(L, 2, 3) float64`` or None: the error of the rigid pose fit (true minus fitted
        pitch, yaw, roll, radians) per unit of landmark motion, learned alike: expressions
        move the fit's stable points (a smile lifts the nostrils and the fit reads a nod).
    pose_bounds: ``(3, 2) float64`` or None: the range of that error in training, widened
        by a tenth.
    image_faps: ``(b,) int64`` or None: FAPs read with the brows' image shifts too
        (:mod:`~facelib.tracking.browimage`) when a video's frames give them.
    image_estimator: ``(L, 2, b) float64`` or None: those FAPs' part of the landmark motion.
    image_weights: ``(10, b) float64`` or None: their part of the 4 brow shifts (over ES0),
        the 3 corrected head angles and the angles' squares (radians).
    """

    faps: np.ndarray
    estimator: np.ndarray
    bounds: np.ndarray
    pose: np.ndarray | None = None
    pose_bounds: np.ndarray | None = None
    image_faps: np.ndarray | None = None
    image_estimator: np.ndarray | None = None
    image_weights: np.ndarray | None = None


def fap_lengths(faps: np.ndarray, fapu: Mapping[str, float]) -> np.ndarray:
    """``(m,)`` length of one unit of each FAP in the units' length unit: its FAPU, and for
    angles (``AU``, radians) the angle times the eye separation ``ES0``."""
    table = fap_table()
    es = fapu["ES"] * FAPU_SCALE
    return np.array([ANGLE_UNIT * es if table[f - 1].fapu == "AU" else fapu[table[f - 1].fapu]
                     for f in np.asarray(faps, np.int64)], np.float64)


def _normalised(landmarks: np.ndarray, neutral: int | tuple[int, int]
                ) -> tuple[np.ndarray, dict[str, float], np.ndarray]:
    """MediaPipe landmarks ``(n, 478, 3)`` -> displacements ``(n, 478, 2)`` over ES0 in the
    neutral head frame, the user's FAPU and the fitted ``(n, 3)`` pitch, yaw, roll
    (radians)."""
    data = np.asarray(landmarks, np.float64)
    layout = landmark_layout("mediapipe")
    frame = head_frame(data, layout=layout, span=neutral_span(neutral, len(data)))
    if frame.pose is None:
        raise TrackingError("the observation model needs a rigid head fit")
    return _over_es(frame.motion, frame.fapu), frame.fapu, head_angles(frame, None)


def head_angles(frame: HeadFrame, model: ObservationModel | None) -> np.ndarray:
    """``(n, 3)`` pitch, yaw and roll (radians) of ``frame``'s rigid fit (which must have
    one), with ``model``'s learned error of the fit taken out (:func:`pose_correction`;
    None: the fit alone)."""
    assert frame.pose is not None
    angles = np.stack(euler_angles(frame.pose.rotation), axis=1)
    if model is not None:
        angles += pose_correction(model, frame.motion, frame.fapu)
    return angles


def _over_es(displacements: np.ndarray, fapu: Mapping[str, float]) -> np.ndarray:
    """``(n, L, 2)`` landmark displacements (the unit of ``fapu``) over the user's eye
    separation ES0, same shape, float64."""
    return np.asarray(displacements, np.float64) / (fapu["ES"] * FAPU_SCALE)


def _model_input(model: ObservationModel, displacements: np.ndarray,
                 fapu: Mapping[str, float]) -> np.ndarray:
    """``(n, L * 2)`` the displacements ``(n, L, 2)`` over ES0, flattened as the model
    reads them; ParameterError unless ``L`` is the model's landmark count."""
    shape = np.shape(displacements)
    n_land = model.estimator.shape[0]
    if len(shape) != 3 or shape[1:] != (n_land, 2):
        raise ParameterError(f"the observation model reads displacements (n, {n_land}, 2), "
                             f"got {shape}")
    return _over_es(displacements, fapu).reshape(shape[0], -1)


def _check_ids(faps: tuple[int, ...], name: str) -> np.ndarray:
    """``(m,) int64`` distinct FAP ids; ParameterError naming ``name`` otherwise."""
    ids = np.asarray(faps, np.int64)
    if ids.ndim != 1 or not ids.size or len(set(ids.tolist())) != ids.size or not (
            (ids >= 1) & (ids <= N_FAPS)).all():
        raise ParameterError(f"{name} must be distinct FAP ids in 1-{N_FAPS}, got {faps!r}")
    return ids


def image_inputs(brows: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """``(n, 10)`` what the image part reads besides the landmark motion: the ``(n, 4)``
    brow shifts (over ES0), the ``(n, 3)`` corrected pitch, yaw and roll (radians) and
    their squares (the brow patches' registration drifts with the turn)."""
    return np.hstack([brows, angles, angles ** 2])


def learn_observation(landmarks: np.ndarray, values: np.ndarray, *,
                      neutral: int | tuple[int, int] = 0,
                      faps: tuple[int, ...] = MODEL_FAPS,
                      components: int = 60, brows: np.ndarray | None = None,
                      image_faps: tuple[int, ...] = IMAGE_FAPS,
                      regions: tuple[LandmarkRegion, ...] = (),
                      segments: tuple[int, ...] = ()) -> ObservationModel:
    """Learn the model from ``(n, 478, 3)`` MediaPipe landmarks (image coordinates, no
    missing frames) of a face driven by ``(n, 84)`` known FAP ``values``.

    ``neutral``: the neutral frame(s); ``components``: principal components of the landmark
    motion the regression uses (fewer than frames); ``faps``: the distinct FAP ids (1-84) to
    learn; ``brows``: ``(n, 4)`` the frames' brow image shifts
    (:func:`~facelib.tracking.browimage.brow_features`), from which the ``image_faps``
    (some of ``faps``) are learned a second time, with them; ``regions``: FAPs learned from
    some landmarks alone (:class:`LandmarkRegion`; their estimator is 0 elsewhere), so that
    the motion of the rest of the face, which comes with them on the training head, is not
    read as them on another face; ``segments``: the frame counts of the training streams
    laid end to end in ``landmarks`` (each with its own neutral frames ``neutral``, counted
    from its own start, and its own FAPU: streams of several faces); empty, one stream.
    ParameterError when ``values`` is not one row of 84 FAPs
    per landmark frame, ``brows`` not 4 finite numbers per frame, or a region's FAPs not
    among ``faps``.
    """
    known = np.asarray(values, np.float64)
    if known.shape != (len(landmarks), N_FAPS):
        raise ParameterError(f"values must be ({len(landmarks)}, {N_FAPS}): the FAPs of each "
                             f"landmark frame, got {known.shape}")
    ids = _check_ids(faps, "faps")
    if brows is not None and (np.shape(brows) != (len(known), 4)
                              or not np.isfinite(brows).all()):
        raise ParameterError(f"brows must be ({len(known)}, 4) finite shifts, got "
                             f"{np.shape(brows)}")
    moved, fitted, scale = _stacked(landmarks, len(known), ids, neutral=neutral,
                                    segments=segments)
    n, n_land = moved.shape[:2]
    components = check_count("components", components, low=1)
    if components > n - 2:
        raise ParameterError(f"{components} components need more than {components + 1} "
                             f"frames, got {n}")
    truth = known[:, ids - 1]
    target = truth * scale
    pose_error = known[:, [f - 1 for f in HEAD_FAP_IDS]] * ANGLE_UNIT - fitted
    basis, scores = _principal(moved.reshape(n, -1), components)
    coef = _least_squares(scores, np.hstack([target, pose_error]))
    estimator = (basis.T @ coef).reshape(n_land, 2, len(ids) + 3)
    for region in regions:
        _learn_region(estimator, moved, target, ids, region)
    model = ObservationModel(ids, estimator[..., :-3], _range(truth), estimator[..., -3:],
                             _range(pose_error))
    if brows is None:
        return model
    chosen = _check_ids(image_faps, "image_faps")
    if not set(chosen.tolist()) <= set(ids.tolist()):
        raise ParameterError(f"image_faps {image_faps!r} must be among faps")
    return _with_image(model, np.asarray(brows, np.float64), chosen, moved=moved,
                       fitted=fitted, basis=basis, scores=scores, target=target)


def _with_image(model: ObservationModel, shifts: np.ndarray, chosen: np.ndarray, *,
                moved: np.ndarray, fitted: np.ndarray, basis: np.ndarray,
                scores: np.ndarray, target: np.ndarray) -> ObservationModel:
    """``model`` with the FAPs ``chosen`` learned a second time from the landmark motion's
    principal ``scores`` (on ``basis``) together with the ``(n, 4)`` brow image ``shifts``."""
    unit = {"ES": 1.0 / FAPU_SCALE}  # the motion is over ES0 already
    angles = fitted + pose_correction(model, moved, unit)
    columns = [int(np.flatnonzero(model.faps == f)[0]) for f in chosen]
    inputs = image_inputs(shifts, angles)
    coef = _least_squares(np.hstack([scores, inputs]), target[:, columns])
    components, n_land = scores.shape[1], moved.shape[1]
    return dataclasses.replace(
        model, image_faps=chosen,
        image_estimator=(basis.T @ coef[:components]).reshape(n_land, 2, len(chosen)),
        image_weights=coef[components:])


def _stacked(landmarks: np.ndarray, n: int, ids: np.ndarray, *,
             neutral: int | tuple[int, int], segments: tuple[int, ...]
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The training streams of ``segments`` (frame counts; empty: one stream of ``n``)
    laid end to end, each normalised against its own neutral: the ``(n, L, 2)`` motion,
    the ``(n, 3)`` fitted head angles and the ``(n, m)`` scale of each frame's FAPs ``ids``
    from FAP units to its face's ES0 (each stream its own FAPU)."""
    lengths = tuple(segments) or (n,)
    if sum(lengths) != n or min(lengths) < 1:
        raise ParameterError(f"segments {segments!r} must be frame counts adding up to {n}")
    edges = np.concatenate([[0], np.cumsum(lengths)])
    parts = [_normalised(np.asarray(landmarks)[a:b], neutral) for a, b in pairwise(edges)]
    scale = np.concatenate([np.broadcast_to(fap_lengths(ids, u) / (u["ES"] * FAPU_SCALE),
                                            (b - a, len(ids)))
                            for (_, u, _), (a, b) in zip(parts, pairwise(edges),
                                                         strict=True)])
    return (np.concatenate([m for m, _, _ in parts]),
            np.concatenate([f for _, _, f in parts]), scale)


def _learn_region(estimator: np.ndarray, moved: np.ndarray, target: np.ndarray,
                  ids: np.ndarray, region: LandmarkRegion) -> None:
    """Overwrite ``estimator``'s ``(L, 2, m + 3)`` columns of ``region``'s FAPs with a
    regression on the leading principal components of the ``(n, L, 2)`` motion of its
    landmarks alone, for the ``(n, m)`` ``target``."""
    wanted = _check_ids(region.faps, "region faps")
    if not set(wanted.tolist()) <= set(ids.tolist()):
        raise ParameterError(f"region FAPs {region.faps!r} must be among faps")
    columns = [int(np.flatnonzero(ids == f)[0]) for f in wanted]
    rows = np.asarray(region.landmarks, np.int64)
    if (rows.ndim != 1 or not rows.size or len(np.unique(rows)) != rows.size
            or rows.min() < 0 or rows.max() >= moved.shape[1]):
        raise ParameterError(f"region landmarks must be distinct rows in 0-{moved.shape[1] - 1}"
                             f", got {region.landmarks!r}")
    most = min(2 * rows.size, len(moved) - 2)
    if check_count("region components", region.components, low=1) > most:
        raise ParameterError(f"region components must be 1-{most} for {rows.size} landmarks "
                             f"and {len(moved)} frames, got {region.components}")
    basis, scores = _principal(moved[:, rows].reshape(len(moved), -1), region.components)
    coef = _least_squares(scores, target[:, columns])
    estimator[..., columns] = 0.0
    estimator[np.ix_(rows, np.arange(2), np.asarray(columns))] = (
        basis.T @ coef).reshape(len(rows), 2, -1)


def _principal(rows: np.ndarray, count: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``count`` leading principal axes ``(k, d)`` of the ``(n, d)`` ``rows`` and the
    rows' scores on them ``(n, k)``."""
    centred = rows - rows.mean(axis=0)
    basis = np.linalg.svd(centred, full_matrices=False)[2][:count]
    return basis, centred @ basis.T


def _least_squares(design: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Coefficients ``(d, m)`` of the ``(n, d)`` design (with an intercept, then dropped: a
    neutral frame reads 0) for the ``(n, m)`` target."""
    ones = np.ones((len(design), 1))
    return np.linalg.lstsq(np.hstack([design, ones]), target, rcond=None)[0][:-1]


def _range(values: np.ndarray) -> np.ndarray:
    """``(m, 2)`` lowest and highest of each column of ``(n, m)`` values, widened by a tenth
    of the range."""
    span = np.ptp(values, axis=0)
    return np.stack([values.min(axis=0) - 0.1 * span, values.max(axis=0) + 0.1 * span], axis=1)


def solve_observation(model: ObservationModel, displacements: np.ndarray,
                      fapu: Mapping[str, float], *, brows: np.ndarray | None = None,
                      angles: np.ndarray | None = None) -> np.ndarray:
    """``(n, m) float64`` FAP values of ``model.faps`` from ``(n, L, 2)`` landmark
    displacements (neutral head frame, the unit of ``fapu``), each kept within
    ``model.bounds``; 0 for a frame with no motion. With ``(n, 4)`` ``brows`` (the brows'
    image shifts over ES0) and ``(n, 3)`` corrected head ``angles`` (radians), the model's
    image part reads its FAPs with them. ParameterError for another ``L`` than the
    model's."""
    moved = _model_input(model, displacements, fapu)
    found = moved @ model.estimator.reshape(moved.shape[1], -1)
    if brows is not None and model.image_faps is not None:
        if angles is None or np.shape(brows) != (len(moved), 4) or np.shape(angles) != (
                len(moved), 3):
            raise ParameterError(f"the image part reads brows ({len(moved)}, 4) with angles "
                                 f"({len(moved)}, 3), got {np.shape(brows)} and "
                                 f"{None if angles is None else np.shape(angles)}")
        assert model.image_estimator is not None
        assert model.image_weights is not None
        columns = [int(np.flatnonzero(model.faps == f)[0]) for f in model.image_faps]
        found[:, columns] = (moved @ model.image_estimator.reshape(moved.shape[1], -1)
                             + image_inputs(brows, angles) @ model.image_weights)
    found *= fapu["ES"] * FAPU_SCALE / fap_lengths(model.faps, fapu)
    return np.clip(found, model.bounds[:, 0], model.bounds[:, 1])


def pose_correction(model: ObservationModel, displacements: np.ndarray,
                    fapu: Mapping[str, float]) -> np.ndarray:
    """``(n, 3) float64`` correction (radians) to add to the fitted pitch, yaw and roll, from
    ``(n, L, 2)`` landmark displacements (neutral head frame, the unit of ``fapu``), within
    ``model.pose_bounds``; zeros for a model without one."""
    moved = _model_input(model, displacements, fapu)
    if model.pose is None or model.pose_bounds is None:
        return np.zeros((len(moved), 3))
    found = moved @ model.pose.reshape(moved.shape[1], 3)
    return np.clip(found, model.pose_bounds[:, 0], model.pose_bounds[:, 1])


_OPTIONAL = (("pose", "pose_bounds"), ("image_faps", "image_estimator", "image_weights"))
"""Arrays of a saved model that come all or none."""


def save_observation(model: ObservationModel, path: str | os.PathLike[str]) -> Path:
    """Write ``model`` as a compressed ``.npz`` (float32), atomically."""
    buffer = io.BytesIO()
    arrays = {"faps": model.faps.astype(np.int16), "estimator": model.estimator,
              "bounds": model.bounds}
    for group in _OPTIONAL:
        for key in group:
            value = getattr(model, key)
            arrays[key] = np.zeros(0) if value is None else value
    payload: dict[str, Any] = {k: v.astype(np.int16 if "faps" in k else np.float32)
                               for k, v in arrays.items()}
    np.savez_compressed(buffer, **payload)
    with atomic_path(path) as temp:
        temp.write_bytes(buffer.getvalue())
    return Path(path)


def load_observation(source: str | os.PathLike[str] | io.BufferedIOBase, *,
                     name: str | None = None) -> ObservationModel:
    """Read a model written by :func:`save_observation` (the pose and image arrays may be
    absent or empty); DataError if it is malformed, naming ``name`` (default: the path,
    or ``<stream>`` for an open stream)."""
    if name is None:
        name = str(source) if isinstance(source, (str, os.PathLike)) else "<stream>"
    try:
        with np.load(source, allow_pickle=False) as raw:
            arrays = {k: np.array(raw[k], np.float64) for k in ("faps", "estimator", "bounds")}
            for group in _OPTIONAL:
                for key in group:
                    if key in raw.files and raw[key].size:
                        arrays[key] = np.array(raw[key], np.float64)
    except (OSError, KeyError, ValueError) as exc:
        raise DataError(f"not an observation model ({exc})", path=name) from exc
    if not _shapes_agree(arrays):
        shapes = ", ".join(f"{k} {v.shape}" for k, v in arrays.items())
        raise DataError(f"observation model arrays disagree in shape: {shapes} (want faps "
                        "(m,), estimator (L, 2, m), bounds (m, 2) and, all or none, pose "
                        "(L, 2, 3) and pose_bounds (3, 2); image_faps (b,) among faps, "
                        "image_estimator (L, 2, b) and image_weights (10, b))", path=name)
    for value in arrays.values():
        value.flags.writeable = False
    for key in ("faps", "image_faps"):
        if key in arrays:
            arrays[key] = arrays[key].astype(np.int64)
    return ObservationModel(**arrays)


def _shapes_agree(arrays: Mapping[str, np.ndarray]) -> bool:
    """Whether the arrays read by :func:`load_observation` fit :class:`ObservationModel`."""
    faps, estimator = arrays["faps"], arrays["estimator"]
    if faps.ndim != 1 or estimator.ndim != 3:
        return False
    m, n_land = len(faps), estimator.shape[0]
    if estimator.shape[1:] != (2, m) or arrays["bounds"].shape != (m, 2):
        return False
    if any(0 < sum(k in arrays for k in group) < len(group) for group in _OPTIONAL):
        return False
    if "pose" in arrays and (arrays["pose"].shape != (n_land, 2, 3)
                             or arrays["pose_bounds"].shape != (3, 2)):
        return False
    if "image_faps" not in arrays:
        return True
    b = arrays["image_faps"]
    return (b.ndim == 1 and set(b.tolist()) <= set(faps.tolist())
            and arrays["image_estimator"].shape == (n_land, 2, len(b))
            and arrays["image_weights"].shape == (10, len(b)))


@cache
def default_observation() -> ObservationModel:
    """The packaged model: MediaPipe's 478 landmarks on the default head at 640x480
    (``facelib/data/tracking/observation_mediapipe.npz``)."""
    with data_path(_DATA).open("rb") as f:
        return load_observation(io.BytesIO(f.read()), name=_DATA)
