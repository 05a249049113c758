"""Contact sheet of every bundled character at face, head and bust framing, neutral and smiling.

Usage (from the repository root)::

    PYOPENGL_PLATFORM=osmesa PYTHONPATH=. python tools/render_characters.py \\
        docs/images/characters.png [--plain]

One row per character (``facelib list characters``), columns: face, head and bust framing,
each neutral then with the library's ``joy`` at 0.8. Each row is labelled with the
character's name unless ``--plain`` (the sheet shown to a reviewer). Needs the render extra
and Pillow; a tool, not part of the library.
"""

from __future__ import annotations

import argparse

import numpy as np
from contact_sheet import label, sheet  # tools/
from PIL import Image

from facelib.engine import load_face
from facelib.engine.characters import character_names
from facelib.expressions import default_library
from facelib.rendering.scene import FaceRenderer

FRAMINGS = ("face", "head", "bust")
W, H = 320, 320
SMILE = ("joy", 0.8)


def smile() -> np.ndarray:
    """``(84,) float32`` FAP values of the smile the sheet shows."""
    name, intensity = SMILE
    expression = default_library().get(name)
    return (expression.share(intensity) * expression.values).astype(np.float32)


def row(name: str, *, plain: bool) -> list[np.ndarray]:
    face = load_face(name)
    values = smile()
    poses = ((face.vertices, np.zeros_like(values)), (face.deform_frame(values), values))
    images = []
    for framing in FRAMINGS:
        with FaceRenderer(face, width=W, height=H, framing=framing) as renderer:
            # the FAPs too, so the smile's wrinkles show as in a rendered video
            images += [np.asarray(renderer.frame(v, faps=f)) for v, f in poses]
    if not plain:
        images[0] = label(images[0], name)
    return images


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="docs/images/characters.png")
    parser.add_argument("--plain", action="store_true", help="no names on the sheet")
    parser.add_argument("--only", help="comma-separated characters (default: all)")
    args = parser.parse_args()
    names = args.only.split(",") if args.only else character_names()
    cells = [image for name in names for image in row(name, plain=args.plain)]
    Image.fromarray(sheet(cells, 2 * len(FRAMINGS))).save(args.out)
    print(f"wrote {args.out}: rows {', '.join(names)}; columns "
          f"{', '.join(FRAMINGS)} x (neutral, {SMILE[0]} {SMILE[1]})")


if __name__ == "__main__":
    main()
