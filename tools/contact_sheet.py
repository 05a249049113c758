"""Contact sheets for the tools that draw them (``render_*.py``): a labelled cell and a
grid of cells."""

from __future__ import annotations

import numpy as np


def label(image: np.ndarray, text: str) -> np.ndarray:
    """``(H, W, 3) uint8`` ``image`` with ``text`` written in its top-left corner."""
    from PIL import Image, ImageDraw

    picture = Image.fromarray(image)
    ImageDraw.Draw(picture).text((8, 6), text, fill=(235, 235, 235))
    return np.asarray(picture)


def sheet(images: list[np.ndarray], columns: int) -> np.ndarray:
    """Equal-sized ``images`` laid out ``columns`` to a row, the last row padded black."""
    blank = np.zeros_like(images[0])
    rows = [images[i : i + columns] for i in range(0, len(images), columns)]
    rows[-1] = rows[-1] + [blank] * (columns - len(rows[-1]))
    return np.concatenate([np.concatenate(row, 1) for row in rows], 0)
