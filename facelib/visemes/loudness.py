"""Loudness -> jaw: louder speech opens the jaw further, within bounds (issue 14, item 8).

The speech audio's short-time level (RMS in dBFS over ``window_ms``) at each frame scales
the jaw opening of the viseme blend by ``1 + per_db * (level - reference_dbfs)``, clipped to
``[min_gain, max_gain]``; rules in ``coarticulation.json`` (``loudness``). Between sounds
and outside the audio the gain is 1.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from facelib.speech.audio import ALIGN_RATE

__all__ = ["jaw_gain"]


def jaw_gain(
    samples: np.ndarray, times_ms: np.ndarray, *, start_ms: float, rules: Mapping[str, float]
) -> np.ndarray:
    """``(len(times_ms),) float64`` jaw gain per frame.

    samples: ``(n,) float32`` speech at 16 kHz (:func:`facelib.speech.audio.load_speech`).
    times_ms: frame times in storyboard ms; the audio starts at ``start_ms``.
    rules: ``window_ms``, ``reference_dbfs``, ``per_db``, ``min_gain``, ``max_gain``,
    ``floor_dbfs`` (levels below it count as silence: gain 1).
    """
    x = np.asarray(samples, np.float64)
    width = max(int(rules["window_ms"] * ALIGN_RATE / 1000), 1)
    power = np.convolve(x * x, np.ones(width) / width, mode="same")
    level = 10.0 * np.log10(np.maximum(power, 1e-12))
    at = np.round((np.asarray(times_ms, np.float64) - start_ms) * ALIGN_RATE / 1000).astype(int)
    inside = (at >= 0) & (at < x.size)
    frame_level = np.full(at.shape, -np.inf)
    frame_level[inside] = level[at[inside]]
    gain = 1.0 + rules["per_db"] * (frame_level - rules["reference_dbfs"])
    gain = np.clip(gain, rules["min_gain"], rules["max_gain"])
    return np.where(frame_level > rules["floor_dbfs"], gain, 1.0)
