"""Render the Virtual Mirror figure of docs/performance-driven.md.

    PYTHONPATH=. .venv/bin/python tools/render_mirror_figure.py docs/images/tracking/mirror.png

Renders ``examples/hello/hello.fdl`` with added head turns (yaw up to 20 degrees) and 8
neutral frames in front on the default head (640x480, whole head framed, with its speech),
tracks it as ``facelib track VIDEO -o OUT.fap --neutral 0:5 --render MIRROR.mp4
--show-landmarks`` does, picks three frames from the true stream (strongest blink, widest
open mouth, most turned head while smiling), stacks those mirror frames (source with its
landmarks, cropped on the face and enlarged 2x | avatar as the mirror renders it) into one
PNG and prints the frame indices and, per FAP, the correlation
and gain of the recovered curve against the true one (lead cut).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

import facelib
from facelib.mpeg4 import ANGLE_UNIT, FapStream, fap
from facelib.rendering.frames import render
from facelib.rendering.video import save_png
from facelib.tracking.closedloop import (
    curve_correlation,
    curve_gain,
    with_head_turns,
    with_neutral_lead,
)
from facelib.tracking.mirror import render_mirror
from facelib.tracking.video import read_video, track_video_faps

FDL = "examples/hello/hello.fdl"
LEAD = 8
"""Neutral frames in front of the clip."""
NEUTRAL = (0, 5)
"""The ``--neutral 0:5`` span given to tracking."""
REPORTED = ("open_jaw", "raise_l_cornerlip", "close_t_l_eyelid", "head_yaw")
MAX_WIDTH = 1400


def source_video(out: Path) -> FapStream:
    """Render the source clip to ``out`` (``.mp4``, 640x480, sound) and return its stream
    (lead included)."""
    animation = facelib.run_fdl(FDL)
    truth = with_neutral_lead(with_head_turns(animation.faps), LEAD)
    offset = animation.audio_offset + LEAD / truth.fps
    render(truth, out=out, width=640, height=480, audio=animation.audio,
           audio_offset=offset, framing="head", progress=False)
    return truth


def pick_frames(truth: FapStream) -> dict[str, int]:
    """Frame indices (of the video, lead included) of the strongest blink (FAP 19), the
    widest open mouth (FAP 3) and the largest ``|head yaw|`` (FAP 49) among the frames
    where the lip corner is raised (FAP 12 above half its maximum)."""
    values = truth.values.astype(np.float64)
    raise_corner = values[:, fap("raise_l_cornerlip").index]
    smiling = np.flatnonzero(raise_corner > 0.5 * raise_corner.max())
    turned = smiling[np.argmax(np.abs(values[smiling, fap("head_yaw").index]))]
    return {"blink": int(np.argmax(values[:, fap("close_t_l_eyelid").index])),
            "open mouth": int(np.argmax(values[:, fap("open_jaw").index])),
            "turned smile": int(turned)}


def mirror_images(mirror: Path, frames: list[int]) -> list[np.ndarray]:
    """The ``(H, W, 3) uint8`` frames ``frames`` of the video ``mirror``, in that order."""
    _, images = read_video(mirror)
    wanted: dict[int, np.ndarray] = {}
    for i, image in enumerate(images):
        if i in frames:
            wanted[i] = np.array(image)
    return [wanted[i] for i in frames]


def zoom_source(image: np.ndarray, points: np.ndarray) -> np.ndarray:
    """A mirror frame ``(H, 2W, 3)`` with its source half (left) cropped to half size around
    the bounding box of the frame's landmarks ``points`` ``(478, 3)`` pixels (the image's
    centre in a frame without a face) and enlarged 2x (nearest pixel), so the face and its
    landmark dots show at the avatar's scale."""
    height, width = image.shape[0], image.shape[1] // 2
    box_h, box_w = height // 2, width // 2
    seen = points[np.isfinite(points[:, :2]).all(axis=1), :2]
    centre = ((seen.min(axis=0) + seen.max(axis=0)) / 2 if len(seen)
              else np.array([width / 2, height / 2]))
    left = int(np.clip(round(centre[0]) - box_w // 2, 0, width - box_w))
    top = int(np.clip(round(centre[1]) - box_h // 2, 0, height - box_h))
    crop = image[top: top + box_h, left: left + box_w]
    return np.concatenate([crop.repeat(2, axis=0).repeat(2, axis=1), image[:, width:]], axis=1)


def compose(images: list[np.ndarray]) -> np.ndarray:
    """Stack ``images`` vertically, halved (2x2 mean) while wider than ``MAX_WIDTH``."""
    sheet = np.concatenate(images, axis=0).astype(np.float64)
    while sheet.shape[1] > MAX_WIDTH:
        h, w = sheet.shape[0] // 2 * 2, sheet.shape[1] // 2 * 2
        sheet = sheet[:h, :w].reshape(h // 2, 2, w // 2, 2, 3).mean(axis=(1, 3))
    return np.round(sheet).astype(np.uint8)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="the PNG to write")
    out = parser.parse_args().out
    with tempfile.TemporaryDirectory(prefix="mirror-figure-") as scratch:
        video, mirror = Path(scratch) / "source.mp4", Path(scratch) / "mirror.mp4"
        truth = source_video(video)
        track, found = track_video_faps(video, neutral=NEUTRAL, smooth=True)
        render_mirror(video, found.stream, mirror, landmarks=track.landmarks)
        picked = pick_frames(truth)
        images = [zoom_source(image, track.landmarks[i]) for image, i in
                  zip(mirror_images(mirror, list(picked.values())), picked.values(), strict=True)]
    save_png(compose(images), out)
    print(f"wrote {out}: {truth.n_frames} frames ({LEAD} neutral in front)")
    for what, i in picked.items():
        yaw = np.degrees(truth.values[i, fap("head_yaw").index] * ANGLE_UNIT)
        print(f"  {what}: frame {i} (clip frame {i - LEAD}, head yaw {yaw:+.1f} deg)")
    for name in REPORTED:
        col = fap(name).index
        true, seen = truth.values[LEAD:, col], found.stream.values[LEAD:, col]
        corr, gain = curve_correlation(true, seen), curve_gain(true, seen)
        print(f"  FAP {col + 1:>2} {name:<18} correlation {corr:.3f}  gain {gain:.2f}")


if __name__ == "__main__":
    main()
