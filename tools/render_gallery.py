"""Render the default head's expressions to the docs gallery (visemes: render_visemes.py).

    PYTHONPATH=. python tools/render_gallery.py docs/images
    PYTHONPATH=. python tools/render_gallery.py docs/images --review /work/review

writes into the folder given:

- ``expressions.png``: every library expression at full intensity, default ("face") framing;
- ``expression_heatmaps.png``: skin displacement (mm, 0 blue to 15 red) of joy, fear and
  surprise, facelib's deformation above the head's own ARKit target mix below;

and with ``--review DIR``: ``expressions_unlabelled.png`` (the six universal expressions in a
seeded random order, no labels) and ``expressions_unlabelled_order.txt`` (the answer key).
"""

from __future__ import annotations

import argparse
import dataclasses
from importlib import resources
from pathlib import Path

import numpy as np
from contact_sheet import label, sheet

from facelib.engine import load_face
from facelib.expressions import default_library
from facelib.rendering.scene import FaceRenderer
from facelib.rendering.video import save_png

UNIVERSAL = ("joy", "sadness", "anger", "fear", "disgust", "surprise")
HEAT_MAX_MM = 15.0
REVIEW_SEED = 14




def _heat(mm: np.ndarray) -> np.ndarray:
    """``(V,)`` millimetres -> ``(V, 3)`` colours: blue (0) through green to red (max)."""
    t = np.clip(mm / HEAT_MAX_MM, 0.0, 1.0)[:, None]
    blue, green, red = np.array([0.15, 0.25, 0.85]), np.array([0.2, 0.8, 0.3]), np.array(
        [0.9, 0.15, 0.1])
    return np.where(t < 0.5, blue + (green - blue) * 2 * t, green + (red - green) * (2 * t - 1))


def heatmaps(face, out: Path) -> None:
    path = resources.files("facelib.data").joinpath("head", "default_head.npz")
    with np.load(str(path)) as data:
        mixes = {name: data[f"mix_{name}"] for name in ("joy", "fear", "surprise")}
    n_skin = next(iter(mixes.values())).shape[0]
    rows: list[list[np.ndarray]] = [[], []]
    for name, mix in mixes.items():
        moved = face.deform_frame(default_library().get(name).values) - face.vertices
        for row, disp, what in ((0, moved[:n_skin], "facelib"), (1, mix, "ARKit mix")):
            colours = np.array(face.vertex_colors)
            colours[:n_skin] = _heat(1000 * np.linalg.norm(disp, axis=1))
            painted = dataclasses.replace(face, vertex_colors=colours)
            with FaceRenderer(painted, width=260, height=300) as renderer:
                rows[row].append(label(renderer.frame(face.vertices), f"{name}: {what}"))
    save_png(sheet(rows[0] + rows[1], 3), out / "expression_heatmaps.png")


def reviewsheet(face, folder: Path) -> None:
    order = list(UNIVERSAL)
    np.random.default_rng(REVIEW_SEED).shuffle(order)
    lib = default_library()
    with FaceRenderer(face, width=300, height=360) as renderer:
        pictures = [label(renderer.frame(face.deform_frame(lib.get(n).values)), str(i + 1))
                    for i, n in enumerate(order)]
    folder.mkdir(parents=True, exist_ok=True)
    save_png(sheet(pictures, 3), folder / "expressions_unlabelled.png")
    key = "".join(f"{i + 1} {n}\n" for i, n in enumerate(order))
    (folder / "expressions_unlabelled_order.txt").write_text(
        f"# answer key of expressions_unlabelled.png (seed {REVIEW_SEED}); do not show the "
        f"reviewer\n{key}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folder", nargs="?", default="docs/images")
    parser.add_argument("--review", type=Path, help="also write the unlabelled review sheet here")
    args = parser.parse_args()
    out = Path(args.folder)
    face = load_face()
    poses = {"neutral": np.zeros(84, np.float32)}
    poses |= {name: e.values for name, e in default_library().expressions.items()}
    with FaceRenderer(face, width=300, height=360) as renderer:
        pictures = [label(renderer.frame(face.deform_frame(v)), k) for k, v in poses.items()]
        save_png(sheet(pictures, 4), out / "expressions.png")
    heatmaps(face, out)
    if args.review:
        reviewsheet(face, args.review)


if __name__ == "__main__":
    main()
