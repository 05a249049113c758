"""Close-ups of the default head's skin, wrinkles, eyes, lids and mouth (issue 32/33 look).

    PYTHONPATH=. python tools/render_skin_sheet.py /tmp/skin/sheet.png

One row per pose (neutral, joy, surprise, anger, disgust, closed eyes, open mouth): the face
framing, a close-up of the left eye and one of the mouth, labelled.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from contact_sheet import label, sheet

from facelib.engine import default_face
from facelib.expressions import default_library

POSES = ("neutral", "joy", "surprise", "anger", "disgust", "closed", "open")


def pose(name: str) -> np.ndarray:
    """``(84,) float32`` FAP values of a pose of this sheet."""
    values = np.zeros(84, np.float32)
    if name == "closed":
        values[18] = values[19] = 1100.0  # close_t_l/r_eyelid
    elif name == "open":
        values[2] = 500.0  # open_jaw
        values[11] = values[12] = 400.0
    elif name != "neutral":
        expression = default_library().get(name)
        values = (expression.share(0.8) * expression.values).astype(np.float32)
    return values


def main() -> None:
    from facelib.rendering.scene import FaceRenderer
    from facelib.rendering.video import save_png

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--poses", default=",".join(POSES))
    args = parser.parse_args()
    face = default_face()
    v, fp = face.vertices, face.feature_points
    eye = v[[fp["4.3"], fp["4.5"], fp["3.3"], fp["4.1"]]]
    mouth = v[[fp["8.3"], fp["8.4"], fp["9.15"], fp["2.10"]]]
    cells = []
    renderers = [FaceRenderer(face, width=320, height=320, framing=frame)
                 for frame in ("face", eye, mouth)]
    try:
        for name in args.poses.split(","):
            values = pose(name)
            vertices = face.deform_frame(values)
            cells += [label(renderer.frame(vertices, faps=values), name)
                      for renderer in renderers]
    finally:
        for renderer in renderers:
            renderer.close()
    save_png(sheet(cells, 3), args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
