"""Loudness of speech per phone: the RMS level of the audio over each phone span, in dBFS,
for generators that scale articulation with vocal effort."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from facelib.errors import ParameterError
from facelib.speech.timeline import Span

__all__ = ["FLOOR_DB", "phone_loudness", "window_loudness"]

FLOOR_DB = -100.0
"""Level given to digital silence and to spans outside the audio (dBFS)."""


def phone_loudness(
    samples: np.ndarray, *, sample_rate: int, spans: Sequence[Span]
) -> np.ndarray:
    """``(len(spans),) float32``: the RMS level of ``samples`` (``(n,)`` float in [-1, 1] at
    ``sample_rate`` Hz, time 0 at sample 0) over each span, in dBFS (a full-scale sine is
    -3 dB), at least :data:`FLOOR_DB`. Linear time: one cumulative sum of squares."""
    return window_loudness(samples, sample_rate=sample_rate,
                           starts_ms=np.array([s.start_ms for s in spans], np.int64),
                           ends_ms=np.array([s.end_ms for s in spans], np.int64))


def window_loudness(samples: np.ndarray, *, sample_rate: int, starts_ms: np.ndarray,
                    ends_ms: np.ndarray) -> np.ndarray:
    """``(k,) float32`` dBFS: the RMS level of ``samples`` over each window
    ``[starts_ms, ends_ms)`` (``(k,)`` integer ms; parts outside the audio count as silence),
    at least :data:`FLOOR_DB`, as :func:`phone_loudness`."""
    if sample_rate <= 0:
        raise ParameterError(f"sample_rate must be positive, got {sample_rate!r}")
    x = np.asarray(samples, dtype=np.float64).reshape(-1)
    energy = np.concatenate(([0.0], np.cumsum(x * x)))
    starts = np.asarray(starts_ms, np.int64) * sample_rate // 1000
    ends = np.asarray(ends_ms, np.int64) * sample_rate // 1000
    starts = np.clip(starts, 0, x.size)
    ends = np.clip(ends, 0, x.size)
    count = np.maximum(ends - starts, 1)
    mean_square = np.where(ends > starts, (energy[ends] - energy[starts]) / count, 0.0)
    floor = 10 ** (FLOOR_DB / 10)
    return (10 * np.log10(np.maximum(mean_square, floor))).astype(np.float32)
