"""Render the default head's expressions and visemes to the docs gallery.

    PYTHONPATH=. python tools/render_gallery.py docs/images

writes ``expressions.png`` (every library expression at full intensity) and ``visemes.png``
(the 15 MPEG-4 visemes) into the folder given.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from facelib.engine import load_face
from facelib.expressions import default_library
from facelib.rendering.scene import FaceRenderer
from facelib.rendering.video import save_png
from facelib.visemes import viseme_name, viseme_targets


def _label(image: np.ndarray, text: str) -> np.ndarray:
    from PIL import Image, ImageDraw

    picture = Image.fromarray(image)
    ImageDraw.Draw(picture).text((8, 6), text, fill=(235, 235, 235))
    return np.asarray(picture)


def _sheet(images: list[np.ndarray], columns: int) -> np.ndarray:
    blank = np.zeros_like(images[0])
    rows = [images[i : i + columns] for i in range(0, len(images), columns)]
    rows[-1] = rows[-1] + [blank] * (columns - len(rows[-1]))
    return np.concatenate([np.concatenate(row, 1) for row in rows], 0)


def main(folder: str) -> None:
    out = Path(folder)
    face = load_face()
    poses = {"neutral": np.zeros(84, np.float32)}
    poses |= {name: e.values for name, e in default_library().expressions.items()}
    with FaceRenderer(face, width=300, height=340) as renderer:
        pictures = [_label(renderer.frame(face.deform_frame(v)), k) for k, v in poses.items()]
        save_png(_sheet(pictures, 4), out / "expressions.png")
    fp = face.feature_points
    around_mouth = face.vertices[[fp[k] for k in ("8.3", "8.4", "9.15", "2.1")]]
    with FaceRenderer(face, width=240, height=180, framing=around_mouth) as renderer:
        mouth = [_label(renderer.frame(face.deform_frame(values)), f"{vid} {viseme_name(vid)}")
                 for vid, values in enumerate(viseme_targets())]
        save_png(_sheet(mouth, 5), out / "visemes.png")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/images")
