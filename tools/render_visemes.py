"""Render the 15 visemes and a spoken sentence on a head, for the docs and for review.

    PYTHONPATH=. python tools/render_visemes.py docs/images
    PYTHONPATH=. python tools/render_visemes.py docs/images --review /work/review

writes into the folder given:

- ``visemes.png``: the 15 MPEG-4 visemes at full intensity, front view of the mouth and jaw;
- ``visemes_three_quarter.png``: the same with the head turned 30 degrees (protrusion shows);
- ``visemes_sentence.png``: every second frame of a sentence spoken at normal style (25 fps),
  labelled with the viseme under it, and the same sentence mumbled and emphatic at its
  widest opening;

and with ``--review DIR``: ``visemes_unlabelled.png`` (front and three-quarter pairs of the
15 visemes in a seeded random order, numbered only) and ``visemes_unlabelled_order.txt`` (the
answer key, not for the reviewer).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from render_gallery import _label, _sheet  # tools/ (the script's folder is on sys.path)

import facelib
from facelib.engine import load_face
from facelib.mpeg4.tables import fap
from facelib.rendering.scene import FaceRenderer
from facelib.rendering.video import save_png
from facelib.visemes import viseme_name, viseme_targets

SENTENCE = "Father was calm, but the dog barked at the park."
TURN_AU = 52_360  # head yaw (FAP 49) of 30 degrees, in 1e-5 rad
REVIEW_SEED = 31
SIZE = (240, 200)


def _mouth(face, vertices: np.ndarray) -> np.ndarray:
    """``(4, 3)`` points the camera frames: the lip corners, the nose tip and the chin
    lowered by 20 mm (room for the jaw drop)."""
    fp = face.feature_points
    points = np.array(vertices[[fp[k] for k in ("8.3", "8.4", "9.15", "2.1")]], np.float32)
    points[3, 1] -= 0.02
    return points


def _turned(values: np.ndarray) -> np.ndarray:
    out = np.array(values, np.float32)
    out[fap("head_yaw").index] = TURN_AU
    return out


def viseme_views(face) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """Front and three-quarter renders of the 15 visemes, unlabelled."""
    turned_rest = face.deform_frame(_turned(np.zeros(84, np.float32)))
    front, side = [], []
    with FaceRenderer(face, width=SIZE[0], height=SIZE[1],
                      framing=_mouth(face, face.vertices)) as renderer, \
         FaceRenderer(face, width=SIZE[0], height=SIZE[1],
                      framing=_mouth(face, turned_rest)) as turned:
        for values in viseme_targets():
            front.append(renderer.frame(face.deform_frame(values)))
            side.append(turned.frame(face.deform_frame(_turned(values))))
    return front, side


def sentence_strip(face) -> np.ndarray:
    """Every second frame of :data:`SENTENCE` at normal style, then the widest frame of the
    mumbled, normal and emphatic readings side by side."""
    fp = face.feature_points
    rows: list[np.ndarray] = []
    widest = []
    with tempfile.TemporaryDirectory() as tmp, FaceRenderer(
            face, width=160, height=140, framing=_mouth(face, face.vertices)) as renderer:
        for style in ("normal", "mumble", "emphatic"):
            path = Path(tmp) / "sentence.fdl"
            path.write_text(f'fps = 25\nsay {{ "{SENTENCE}", style = "{style}" }}\n')
            anim = facelib.run_fdl(path)
            values = np.array(anim.faps.values)
            values[:, 47:50] = 0.0  # keep the head still: the mouth is what is shown
            moved = face.deform(facelib.FapStream(anim.faps.fps, values))
            gap = moved[:, fp["2.2"], 1] - moved[:, fp["2.3"], 1]
            k = int(np.argmax(gap))
            widest.append(_label(renderer.frame(moved[k]), f"{style} widest"))
            if style != "normal":
                continue
            spans = anim.visemes or ()
            for i in range(0, len(moved), 2):
                ms = 1000 * i / anim.faps.fps
                name = next((s.name for s in spans if s.start_ms <= ms < s.end_ms), "")
                rows.append(_label(renderer.frame(moved[i]), f"{ms:.0f} ms {name}"))
    strip = _sheet(rows, 10)
    pad = np.zeros((widest[0].shape[0], strip.shape[1] - 3 * widest[0].shape[1], 3),
                   np.uint8)
    return np.concatenate([strip, np.concatenate([*widest, pad], 1)], 0)


def review_sheet(front: list[np.ndarray], side: list[np.ndarray], folder: Path) -> None:
    order = list(range(15))
    np.random.default_rng(REVIEW_SEED).shuffle(order)
    pairs = [_label(np.concatenate([front[v], side[v]], 1), str(i + 1))
             for i, v in enumerate(order)]
    folder.mkdir(parents=True, exist_ok=True)
    save_png(_sheet(pairs, 3), folder / "visemes_unlabelled.png")
    key = "".join(f"{i + 1} {viseme_name(v)}\n" for i, v in enumerate(order))
    (folder / "visemes_unlabelled_order.txt").write_text(
        f"# answer key of visemes_unlabelled.png (seed {REVIEW_SEED}); do not show the "
        f"reviewer\n{key}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folder", nargs="?", default="docs/images", type=Path)
    parser.add_argument("--review", type=Path, help="also write the unlabelled review sheet")
    args = parser.parse_args()
    face = load_face()
    front, side = viseme_views(face)
    names = [f"{v} {viseme_name(v)}" for v in range(15)]
    save_png(_sheet([_label(im, n) for im, n in zip(front, names, strict=True)], 5),
             args.folder / "visemes.png")
    save_png(_sheet([_label(im, n) for im, n in zip(side, names, strict=True)], 5),
             args.folder / "visemes_three_quarter.png")
    save_png(sentence_strip(face), args.folder / "visemes_sentence.png")
    if args.review:
        review_sheet(front, side, args.review)


if __name__ == "__main__":
    main()
