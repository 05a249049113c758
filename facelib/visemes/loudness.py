"""Loudness -> jaw: louder speech opens the jaw further, within bounds (issue 14, item 8).

Each frame's speech level (dBFS of the phone under it, :func:`facelib.speech.loudness.
phone_loudness` through the viseme animation) scales the jaw opening of the viseme blend by
``1 + per_db * (level - reference_dbfs)``, clipped to ``[min_gain, max_gain]``; rules in
``coarticulation.json`` (``loudness``). Frames without a level (pauses, no audio) keep 1.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

__all__ = ["jaw_gain"]


def jaw_gain(levels_db: np.ndarray, *, rules: Mapping[str, float]) -> np.ndarray:
    """``(n_frames,) float64`` jaw gain for per-frame speech levels ``(n_frames,)`` dBFS.

    rules: ``reference_dbfs``, ``per_db``, ``min_gain``, ``max_gain``, ``floor_dbfs``
    (levels at or below it count as silence: gain 1).
    """
    level = np.asarray(levels_db, np.float64)
    gain = np.clip(1.0 + rules["per_db"] * (level - rules["reference_dbfs"]),
                   rules["min_gain"], rules["max_gain"])
    return np.where(level > rules["floor_dbfs"], gain, 1.0)
