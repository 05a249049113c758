"""Several voices on one soundtrack: speech recordings and synthesized speech mixed.

A storyboard with characters has one video and one soundtrack: every character's speech,
each starting where its ``say`` puts it, summed at one sample rate (the highest of the
voices, so no voice loses bandwidth) and kept within [-1, 1].
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from math import gcd
from pathlib import Path

import numpy as np

from facelib.speech.audio import read_sound

__all__ = ["Voice", "mix_voices"]


@dataclass(frozen=True, eq=False)
class Voice:
    """One voice of a mix: a sound ``file`` or ``samples (n,)`` in [-1, 1] at
    ``sample_rate`` Hz, starting ``offset`` seconds into the soundtrack (negative: its
    beginning is cut)."""

    offset: float
    file: Path | None = None
    samples: np.ndarray | None = None
    sample_rate: int = 0


def _samples(voice: Voice) -> tuple[np.ndarray, int]:
    """``(n,) float64`` mono samples of ``voice`` and their rate."""
    if voice.file is not None:
        data, rate = read_sound(Path(voice.file))
    else:
        data, rate = np.asarray(voice.samples, np.float64), int(voice.sample_rate)
    return (data.mean(axis=1) if data.ndim == 2 else data), rate


def mix_voices(voices: Sequence[Voice]) -> tuple[np.ndarray, int]:
    """``(samples (n,) float32 in [-1, 1], sample_rate)`` of ``voices`` summed, sample 0 at
    time 0; ``(empty, 16000)`` without voices. Where voices overlap and the sum would clip,
    it is limited to [-1, 1]."""
    loaded = [(_samples(v), v.offset) for v in voices]
    if not loaded:
        return np.zeros(0, np.float32), 16_000
    from scipy.signal import resample_poly  # loaded on first use (import facelib stays light)

    rate = max(r for (_, r), _ in loaded)
    pieces = []
    for (raw, own), offset in loaded:
        g = gcd(rate, own)
        samples = raw if own == rate else resample_poly(raw, rate // g, own // g)
        start = round(offset * rate)
        pieces.append((start, samples[max(0, -start):]))
    out = np.zeros(max(max(s, 0) + d.size for s, d in pieces), np.float64)
    for start, data in pieces:
        out[max(start, 0): max(start, 0) + data.size] += data
    return np.clip(out, -1.0, 1.0).astype(np.float32), rate
