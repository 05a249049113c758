"""Contact sheet of the default head's hair styles at face, head and bust framing.

Usage (from the repository root)::

    PYOPENGL_PLATFORM=osmesa PYTHONPATH=. python tools/render_hair_sheet.py \
        docs/images/hair_styles.png

One row per style (short, long, tied), columns: each framing, front and with the head turned
30 degrees (FAP 49). Needs the render extra and Pillow; a tool, not part of the library.
"""

from __future__ import annotations

import sys

import numpy as np
from PIL import Image

from facelib.engine import load_face
from facelib.mpeg4.tables import fap
from facelib.rendering.scene import FaceRenderer

STYLES = ("short", "long", "tied")
FRAMINGS = ("face", "head", "bust")
W, H = 320, 240


def main(out: str) -> None:
    rows = []
    for style in STYLES:
        face = load_face(None, hair=style)
        turned = np.zeros(84, np.float32)
        turned[fap("head_yaw").index] = np.radians(30.0) / face.fapu["AU"]
        poses = (face.vertices, face.deform_frame(turned))
        images = []
        for framing in FRAMINGS:
            with FaceRenderer(face, width=W, height=H, framing=framing) as renderer:
                images += [renderer.frame(v) for v in poses]
        rows.append(np.hstack(images))
    Image.fromarray(np.vstack(rows)).save(out)
    print(f"wrote {out}: rows {', '.join(STYLES)}; columns {', '.join(FRAMINGS)} x (front, 30 deg)")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "docs/images/hair_styles.png")
