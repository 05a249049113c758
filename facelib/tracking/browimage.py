"""The inner brows' motion read off the video frames: what MediaPipe's landmarks miss.

MediaPipe's brow landmarks report about half of the brows' motion and mix a brow's raise
with its squeeze (FAPs 37/38 pull it toward the midline and down). The image itself holds
both: a patch over each inner brow (from above the brow to just under it, clear of the
lids and lashes) is laid on the neutral face, sampled in every frame through the head's
pose, and registered against the neutral frames' patch by normalised cross-correlation in
the head's frame, across (squeeze) and up (raise). The two shifts of each brow, over the
user's eye separation ES0, join the landmark motion as inputs of the observation model
(:mod:`~facelib.tracking.observation`), which learns what they mean from its training
renders.

The pose used for sampling is the tracking's rigid fit with the model's learned correction
of its angles, and its scale and translation fitted again on the nose bridge and tip alone
(the nostrils move with speech). Sizes are in ES0 (``model.json``, ``brow_image``), so a
patch covers the same part of any face at any resolution.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from functools import cache
from itertools import islice

import numpy as np

from facelib.data import json_data
from facelib.errors import DataError, TrackingError
from facelib.mpeg4 import FAPU_SCALE
from facelib.tracking.headframe import (
    Neutral,
    face_found,
    face_frame,
    fill_gaps,
    neutral_face,
    neutral_frames,
    neutral_span,
    to_head_frame,
)
from facelib.tracking.layouts import landmark_layout
from facelib.tracking.observation import ObservationModel, head_angles
from facelib.tracking.pose import HeadPose

__all__ = ["N_FEATURES", "BrowPatches", "brow_features", "brow_patches", "sampling_poses",
           "track_brows"]

N_FEATURES = 4
"""Features per frame: across and up shifts of the face's left inner brow, then the right's."""


@dataclass(frozen=True)
class _Settings:
    """``model.json``'s ``brow_image``: landmark rows and sizes in ES0."""

    brows: tuple[tuple[int, int], tuple[int, int]]
    nose: tuple[int, ...]
    half_width: float
    above: float
    below: float
    across: float
    up: float
    down: float
    step: float


@cache
def _settings() -> _Settings:
    raw = json_data("tracking/model.json").get("brow_image")
    try:
        brows = tuple((int(a), int(b)) for a, b in (raw["left"], raw["right"]))
        sizes = {k: float(raw[k]) for k in ("half_width", "above", "below", "search_across",
                                            "search_up", "search_down", "step")}
        return _Settings(brows, tuple(int(i) for i in raw["nose"]),  # type: ignore[arg-type]
                         sizes["half_width"], sizes["above"], sizes["below"],
                         sizes["search_across"], sizes["search_up"], sizes["search_down"],
                         sizes["step"])
    except (KeyError, TypeError, ValueError) as exc:
        raise DataError(f"malformed brow_image settings ({exc})",
                        path="tracking/model.json") from exc


@dataclass(frozen=True)
class BrowPatches:
    """The neutral brows a track's frames are registered against.

    Attributes
    ----------
    regions: ``(2, rh, rw, 3) float64`` points on the neutral face (face frame, the
        landmarks' unit) sampled in every frame: each brow's patch widened by the search.
    templates: ``(2, th, tw) float32`` the neutral frames' mean grey patch of each brow.
    """

    regions: np.ndarray
    templates: np.ndarray


def _grey(image: np.ndarray) -> np.ndarray:
    """``(H, W, 3) uint8`` RGB -> ``(H, W) float32`` luma."""
    import cv2

    return cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2GRAY).astype(np.float32)


def sampling_poses(landmarks: np.ndarray, neutral: Neutral, model: ObservationModel
                   ) -> HeadPose:
    """``(n, 478, 3)`` gap-free MediaPipe landmarks -> the poses the brows are sampled
    through: the fit's angles with ``model``'s correction, scale and translation fitted
    again on the nose bridge and tip."""
    from facelib.engine.rigid import rotation_matrices

    angles = head_angles(to_head_frame(landmarks, neutral, layout=landmark_layout("mediapipe")),
                         model)
    level = neutral.level  # the angles are about the neutral head's axes, levelled
    rotation = level.T @ rotation_matrices(angles[:, 0], angles[:, 1], angles[:, 2]) @ level
    nose = list(_settings().nose)
    turned = np.einsum("nij,sj->nsi", rotation, neutral.image_rest[nose])[..., :2]  # (n, s, 2)
    seen = face_frame(landmarks[:, nose])[..., :2]
    n, s = turned.shape[:2]
    design = np.zeros((n, s, 2, 3))
    design[..., 0] = turned
    design[..., 0, 1] = design[..., 1, 2] = 1.0
    design = design.reshape(n, 2 * s, 3)
    solved = np.linalg.solve(np.einsum("nki,nkj->nij", design, design),
                             np.einsum("nki,nk->ni", design, seen.reshape(n, 2 * s))[..., None]
                             )[..., 0]
    translation = np.zeros((n, 3))
    translation[:, :2] = solved[:, 1:]
    return HeadPose(solved[:, 0], rotation, translation)


def _grids(neutral: Neutral) -> tuple[np.ndarray, np.ndarray]:
    """Each brow's patch grid ``(2, th, tw, 3)`` and search region ``(2, rh, rw, 3)`` on the
    neutral face (rows from the top down, the landmarks' unit)."""
    from scipy.interpolate import LinearNDInterpolator

    cfg = _settings()
    es = neutral.fapu["ES"] * FAPU_SCALE
    rest = neutral.image_rest @ neutral.level.T  # laid out upright, then turned back
    depth = LinearNDInterpolator(rest[:468, :2], rest[:468, 2])
    step = cfg.step * es
    tops = [rest[upper, 1] + cfg.above * es for upper, _ in cfg.brows]
    height = max(top - (rest[lower, 1] - cfg.below * es)
                 for top, (_, lower) in zip(tops, cfg.brows, strict=True))
    patches: list[np.ndarray] = []
    regions: list[np.ndarray] = []
    for top, (upper, lower) in zip(tops, cfg.brows, strict=True):
        centre = (rest[upper, 0] + rest[lower, 0]) / 2
        for (left, up, width, tall), out in (
                ((cfg.half_width, 0.0, 2 * cfg.half_width, height), patches),
                ((cfg.half_width + cfg.across, cfg.up, 2 * (cfg.half_width + cfg.across),
                  height + (cfg.up + cfg.down) * es), regions)):
            xs = centre - left * es + step * np.arange(round(width * es / step) + 1)
            ys = top + up * es - step * np.arange(round(tall / step) + 1)
            gx, gy = np.meshgrid(xs, ys)
            out.append(np.stack([gx, gy, depth(gx, gy)], axis=-1))
    if not np.isfinite(np.concatenate([r.ravel() for r in regions])).all():
        raise TrackingError("the brow patches reach beyond the neutral face's landmarks")
    return np.stack(patches) @ neutral.level, np.stack(regions) @ neutral.level


def _sample(grey: np.ndarray, points: np.ndarray, pose: HeadPose, i: int) -> np.ndarray:
    """``(..., 3)`` neutral face-frame points seen in frame ``i`` through ``pose``, sampled
    from the ``(H, W)`` grey image (bilinear; edges repeated): ``(...)`` float32."""
    import cv2

    cols, rows = _seen(points, pose, i)
    return cv2.remap(grey, cols, rows, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)


def _seen(points: np.ndarray, pose: HeadPose, i: int) -> tuple[np.ndarray, np.ndarray]:
    """``(..., 3)`` neutral face-frame points seen in frame ``i`` through ``pose``: their
    image columns and rows, ``(...)`` float32 each."""
    # the image's two axes alone, as one product over the points: the same sums of three
    # products as over all three axes point by point, at half the time
    seen = (pose.scale[i] * points).reshape(-1, 3) @ pose.rotation[i, :2].T
    shape = points.shape[:-1]
    return ((seen[:, 0] + pose.translation[i, 0]).astype(np.float32).reshape(shape),
            (-(seen[:, 1] + pose.translation[i, 1])).astype(np.float32).reshape(shape))


def brow_patches(images: Iterable[np.ndarray], landmarks: np.ndarray, neutral: Neutral,
                 model: ObservationModel) -> BrowPatches:
    """The :class:`BrowPatches` of the neutral frames: their ``(H, W, 3) uint8`` RGB
    ``images`` and ``(k, 478, 3)`` gap-free MediaPipe ``landmarks``, measured against the
    track's ``neutral`` face with ``model``'s pose correction."""
    patch, regions = _grids(neutral)
    pose = sampling_poses(landmarks, neutral, model)
    sums = np.zeros(patch.shape[:3], np.float64)
    count = 0
    for i, image in enumerate(images):
        if i >= len(landmarks):
            raise TrackingError(f"more neutral images than the {len(landmarks)} landmark "
                                "frames")
        grey = _grey(image)
        sums += np.stack([_sample(grey, p, pose, i) for p in patch])
        count += 1
    if count != len(landmarks):
        raise TrackingError(f"{count} neutral images for {len(landmarks)} landmark frames")
    return BrowPatches(regions, (sums / count).astype(np.float32))


def _peak(scores: np.ndarray, at: int) -> float:
    """Sub-step offset of the peak ``at`` of a ``(m,)`` score line by a parabola."""
    if 0 < at < len(scores) - 1:
        a, b, c = scores[at - 1], scores[at], scores[at + 1]
        curve = a - 2 * b + c
        if curve < 0:
            return float(0.5 * (a - c) / curve)
    return 0.0


_CHUNK_FRAMES = 1024
"""Frames whose sampling poses are fitted at a time (a long track is never copied whole)."""


def brow_features(images: Iterable[np.ndarray], landmarks: np.ndarray, patches: BrowPatches,
                  neutral: Neutral, model: ObservationModel) -> np.ndarray:
    """``(n, 4) float64`` each inner brow's shift across (toward the face's left) and up
    from the neutral, in the head's frame over ES0 (left brow, then right), from ``n``
    ``(H, W, 3) uint8`` RGB ``images`` and their ``(n, 478, 3)`` MediaPipe ``landmarks``
    (NaN rows: no face; NaN features there). TrackingError unless there is one image per
    landmark frame."""
    data = np.asarray(landmarks, np.float64)
    found = face_found(data)
    out = np.full((len(data), N_FEATURES), np.nan)
    count = 0
    for i, image in enumerate(images):
        if i >= len(data):
            raise TrackingError(f"more images than the {len(data)} landmark frames")
        count += 1
        if i % _CHUNK_FRAMES == 0:  # the poses of the next chunk of frames
            chunk = data[i:i + _CHUNK_FRAMES]
            faces = found[i:i + _CHUNK_FRAMES, None, None]
            pose = sampling_poses(np.where(faces, chunk, face_frame(neutral.image_rest)),
                                  neutral, model)  # face_frame is its own inverse
        if found[i]:
            out[i] = _register(image, patches, pose, i % _CHUNK_FRAMES)
    if count != len(data):
        raise TrackingError(f"{count} images for {len(data)} landmark frames")
    return out


def _register(image: np.ndarray, patches: BrowPatches, pose: HeadPose, i: int
              ) -> np.ndarray:
    """``(4,)`` the brows' shifts (across, up; over ES0) in the ``(H, W, 3) uint8`` RGB
    frame seen through ``pose``'s frame ``i``. Only the part of the frame around the two
    search regions is made grey (a pixel beyond each side: the same samples, edges of the
    frame repeated as before; whole numbers move the sampling points exactly)."""
    import cv2

    cfg = _settings()
    seen = [_seen(region, pose, i) for region in patches.regions]
    height, width = image.shape[:2]
    box = []
    for axis, size in ((0, width), (1, height)):
        low = min(float(s[axis].min()) for s in seen)
        high = max(float(s[axis].max()) for s in seen)
        if not np.isfinite([low, high]).all():
            box.append((0, size))
            continue
        start = min(max(math.floor(low) - 1, 0), size - 1)
        box.append((start, min(max(math.ceil(high) + 2, start + 1), size)))
    (left, right), (top, bottom) = box
    grey = _grey(image[top:bottom, left:right])
    out = np.empty(N_FEATURES)
    for side, (cols, rows) in enumerate(seen):
        region = cv2.remap(grey, cols - np.float32(left), rows - np.float32(top),
                           cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)
        scores = cv2.matchTemplate(region, patches.templates[side], cv2.TM_CCOEFF_NORMED)
        row, col = (int(k) for k in np.unravel_index(int(np.argmax(scores)), scores.shape))
        out[2 * side] = (col + _peak(scores[row, :], col)) * cfg.step - cfg.across
        out[2 * side + 1] = cfg.up - (row + _peak(scores[:, col], row)) * cfg.step
    return out


def track_brows(open_frames: Callable[[], Iterable[np.ndarray]], landmarks: np.ndarray, *,
                neutral: int | tuple[int, int] | None, model: ObservationModel) -> np.ndarray:
    """``(n, 4)`` :func:`brow_features` of a track: ``open_frames()`` gives its ``(H, W, 3)
    uint8`` RGB frames from the first, each time it is called (it is called twice: once up
    to the end of the ``neutral`` frames, once for all); ``(n, 478, 3)`` MediaPipe
    ``landmarks`` (NaN rows: no face), ``neutral`` and ``model`` as for
    :func:`~facelib.tracking.faps.measure_faps` (the templates come from the neutral frames
    with a face)."""
    filled, lost = fill_gaps(landmarks)
    span = neutral_span(neutral, len(filled), lost=lost)
    rest = neutral_face(filled, layout=landmark_layout("mediapipe"), span=span, lost=lost)
    frames = neutral_frames(span, lost)
    keep = set(frames.tolist())
    images = (image for i, image in enumerate(islice(open_frames(), span.stop)) if i in keep)
    patches = brow_patches(images, filled[frames], rest, model)
    return brow_features(open_frames(), landmarks, patches, rest, model)
