"""Contact sheets of every library expression at intensity 0.6 and 1.0, one per head.

    PYTHONPATH=. python tools/render_expressions.py docs/images
    PYTHONPATH=. python tools/render_expressions.py docs/images --review /tmp/review
    PYTHONPATH=. python tools/render_expressions.py /tmp/out --heads default --only anger,fear

writes into the folder given ``expressions_<head>.png`` for the default head and the two heads
of ``examples/heads`` (set up from their landmark files as ``facelib face setup`` does): the
neutral face and each expression, every one at 0.6 (the upper row of a pair) and 1.0 (the
lower), each as a cue of that intensity shows it (its intensity curve applied).

With ``--review DIR``: ``expressions_review.png``, neutral and every library expression at
0.6 on the default head in a seeded shuffled order, cells numbered, no names, and
``expressions_review_key.txt``, the answer key (not for the reviewer's eyes).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from contact_sheet import label, sheet

from facelib.engine import Face, default_face
from facelib.expressions import default_library

ROOT = Path(__file__).resolve().parent.parent
HEADS = ROOT / "examples" / "heads"
REVIEW_SEED = 32
COLUMNS = 6
CELL = (220, 264)  # width, height in pixels




def heads(names: tuple[str, ...]) -> dict[str, Face]:
    """The heads to draw: ``default``, ``soma``, ``cartoon`` (set up from the default)."""
    from facelib.engine.setup import set_up_face

    source = default_face()
    out = {"default": source} if "default" in names else {}
    for name, mesh in (("soma", "soma_head.ply"), ("cartoon", "cartoon_head.obj")):
        if name in names:
            out[name] = set_up_face(HEADS / mesh, landmarks=HEADS / f"{name}_landmarks.json",
                                    source=source).face
    return out


def pose(name: str, intensity: float) -> np.ndarray:
    """``(84,) float32``: FAP values of library expression ``name`` as a cue of
    ``intensity`` holds it ("neutral": zeros)."""
    if name == "neutral":
        return np.zeros(84, np.float32)
    expression = default_library().get(name)
    return (expression.share(intensity) * expression.values).astype(np.float32)


def contactsheet(face: Face, names: list[str], title: str) -> np.ndarray:
    """Pairs of rows: each expression at 0.6 above the same at 1.0."""
    from facelib.rendering.scene import FaceRenderer

    cells: list[np.ndarray] = []
    with FaceRenderer(face, width=CELL[0], height=CELL[1]) as renderer:
        for start in range(0, len(names), COLUMNS):
            chunk = names[start : start + COLUMNS]
            for intensity in (0.6, 1.0):
                row = [label(renderer.frame(face.deform_frame(pose(n, intensity)),
                                             faps=pose(n, intensity)),
                              f"{title}: {n} {intensity:g}") for n in chunk]
                cells += row + [np.zeros_like(row[0])] * (COLUMNS - len(row))
    return sheet(cells, COLUMNS)


def reviewsheet(face: Face, names: list[str], folder: Path) -> None:
    """The unlabelled shuffled sheet at 0.6 and its key."""
    from facelib.rendering.scene import FaceRenderer
    from facelib.rendering.video import save_png

    order = list(names)
    np.random.default_rng(REVIEW_SEED).shuffle(order)
    with FaceRenderer(face, width=300, height=360) as renderer:
        pictures = [label(renderer.frame(face.deform_frame(pose(n, 0.6)), faps=pose(n, 0.6)),
                              str(i + 1))
                    for i, n in enumerate(order)]
    folder.mkdir(parents=True, exist_ok=True)
    save_png(sheet(pictures, 4), folder / "expressions_review.png")
    key = "".join(f"{i + 1} {n}\n" for i, n in enumerate(order))
    (folder / "expressions_review_key.txt").write_text(
        f"# answer key of expressions_review.png (intensity 0.6, default head, seed "
        f"{REVIEW_SEED}); do not show the reviewer\n{key}", encoding="utf-8")


def main() -> None:
    from facelib.rendering.video import save_png

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folder", nargs="?", default="docs/images")
    parser.add_argument("--review", type=Path, help="also write the unlabelled sheet here")
    parser.add_argument("--heads", default="default,soma,cartoon")
    parser.add_argument("--only", help="comma-separated expressions (default: all)")
    args = parser.parse_args()
    names = ["neutral", *default_library().names]
    if args.only:
        names = ["neutral", *args.only.split(",")]
    out = Path(args.folder)
    for title, face in heads(tuple(args.heads.split(","))).items():
        save_png(contactsheet(face, names, title), out / f"expressions_{title}.png")
        print(f"wrote {out / f'expressions_{title}.png'}")
    if args.review:
        reviewsheet(default_face(), ["neutral", *default_library().names], args.review)
        print(f"wrote {args.review / 'expressions_review.png'} and its key")


if __name__ == "__main__":
    main()
