"""Render the hello demo on the default head and the two test heads, side by side.

    PYTHONPATH=. python tools/render_own_heads.py docs/images

sets up ``examples/heads/soma_head.ply`` and ``examples/heads/cartoon_head.obj`` from their
landmark files (as ``facelib face setup`` does), runs ``examples/hello/hello.fdl`` once (its
seed), and writes ``own_heads.png``: one row per head, one column per moment of the demo,
plus ``own_heads_landmarks.png``: each test head with its landmarks (green) and the
transferred feature points (red).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from contact_sheet import label

from facelib.animation import run_fdl
from facelib.engine import default_face
from facelib.engine.setup import setup_face
from facelib.rendering.scene import FaceRenderer
from facelib.rendering.video import save_png

ROOT = Path(__file__).resolve().parent.parent
HEADS = ROOT / "examples" / "heads"
MOMENTS = (0.6, 1.6, 3.2, 4.4, 5.6)  # seconds into the demo



def _dots(image: np.ndarray, pixels: np.ndarray, colour: tuple[int, int, int]) -> np.ndarray:
    from PIL import Image, ImageDraw

    picture = Image.fromarray(image)
    draw = ImageDraw.Draw(picture)
    for x, y in pixels:
        draw.ellipse((x - 2.5, y - 2.5, x + 2.5, y + 2.5), fill=colour)
    return np.asarray(picture)


def main(folder: str) -> None:
    out = Path(folder)
    source = default_face()
    heads = {"default head": (source, None)}
    for name, mesh in (("SOMA-X head", "soma_head.ply"), ("cartoon head", "cartoon_head.obj")):
        stem = mesh.split("_")[0]
        result = setup_face(HEADS / mesh, landmarks=HEADS / f"{stem}_landmarks.json",
                            source=source, report=True)
        heads[name] = (result.face, result)
    animation = run_fdl(ROOT / "examples" / "hello" / "hello.fdl")
    stream = animation.faps
    frames = [min(round(t * stream.fps), stream.n_frames - 1) for t in MOMENTS]
    rows, marks = [], []
    for name, (face, result) in heads.items():
        with FaceRenderer(face, width=260, height=300) as renderer:
            row = [label(renderer.frame(face.deform_frame(stream.values[k])),
                          f"{name}  {k / stream.fps:.1f} s") for k in frames]
            rows.append(np.concatenate(row, axis=1))
            if result is not None:
                image = renderer.frame(face.vertices)
                given = np.array([face.vertices[face.feature_points[k]]
                                  for k in result.landmarks])
                every = face.vertices[list(face.feature_points.values())]
                image = _dots(image, renderer.project(every), (230, 60, 60))
                image = _dots(image, renderer.project(given), (60, 220, 90))
                marks.append(label(image, f"{name}: {len(result.landmarks)} landmarks"))
    save_png(np.concatenate(rows, axis=0), out / "own_heads.png")
    save_png(np.concatenate(marks, axis=1), out / "own_heads_landmarks.png")
    print(f"wrote {out / 'own_heads.png'} and {out / 'own_heads_landmarks.png'}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/images")
