"""The Virtual Mirror, offline (first seed, section 5.2): the source video and the avatar
driven by its tracked FAPs, side by side, with the source's sound.

Needs the ``render`` extra (the avatar is drawn with :mod:`facelib.rendering`).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from facelib.engine import default_face
from facelib.errors import ParameterError
from facelib.mpeg4 import FapStream
from facelib.rendering import FaceRenderer, iter_frames
from facelib.rendering.protocols import Deformable
from facelib.rendering.video import open_writer
from facelib.tracking.video import read_video

__all__ = ["mirror_frames", "render_mirror"]


def _even(value: int) -> int:
    return value - value % 2


def mirror_frames(source: Iterator[np.ndarray], avatar: Iterator[np.ndarray],
                  *, landmarks: np.ndarray | None = None) -> Iterator[np.ndarray]:
    """Join source and avatar frames side by side (``(H, W1 + W2, 3) uint8``), source on the
    left, cropped to the avatar's height. ``landmarks`` ``(n, K, 2+)`` pixels are drawn on the
    source as small green dots (None draws nothing)."""
    for i, (image, right) in enumerate(zip(source, avatar, strict=False)):
        height = right.shape[0]
        left = np.array(image[:height, : _even(image.shape[1])])
        if landmarks is not None and i < len(landmarks) and np.isfinite(landmarks[i]).all():
            cols = np.clip(np.round(landmarks[i][:, 0]).astype(int), 0, left.shape[1] - 1)
            rows = np.clip(np.round(landmarks[i][:, 1]).astype(int), 0, left.shape[0] - 1)
            left[rows, cols] = (40, 220, 60)
        yield np.concatenate([left, right], axis=1)


def render_mirror(video: str | os.PathLike[str], stream: FapStream,
                  out: str | os.PathLike[str], *, face: Deformable | None = None,
                  landmarks: np.ndarray | None = None, avatar_width: int | None = None) -> Path:
    """Write ``out`` (``.mp4``): ``video`` on the left, ``face`` (default head) animated by
    ``stream`` on the right at the video's height, with the video's sound if it has any.

    ``stream`` must have the video's frame count (at most; extra video frames are dropped)
    and rate. ``avatar_width`` defaults to 4/3 of the height. Written atomically.
    """
    info, frames = read_video(video)
    if abs(stream.fps - info.fps) > 1e-6 * info.fps:
        raise ParameterError(f"the stream runs at {stream.fps:g} fps, the video at {info.fps:g}")
    height = _even(info.height)
    width = _even(avatar_width or round(height * 4 / 3))
    face = default_face() if face is None else face
    sound = Path(video) if info.audio and Path(out).suffix.lower() == ".mp4" else None
    with FaceRenderer(face, width=width, height=height) as renderer:
        writer = open_writer(out, fps=info.fps, width=_even(info.width) + width, height=height,
                             audio=sound,
                             duration=stream.duration)
        try:
            for image in mirror_frames(frames, iter_frames(renderer, face, stream),
                                       landmarks=landmarks):
                writer.write(image)
        except BaseException:
            writer.abort()
            raise
        return writer.commit()
