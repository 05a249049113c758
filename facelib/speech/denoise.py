"""Noise reduction before alignment: stationary spectral gating (noisereduce) for noisy
recordings; clean ones pass unchanged.

The aligner's acoustic models (pocketsphinx en-us) were trained on clean speech: under
white noise at 10 dB SNR forced alignment put the visemes right 52 % of the time on the
tuning sentences, 72 % after gating (``benchmarks/visemes_audio_only.py``, docs/visemes.md).
On clean speech the gate costs (88 % -> 76 %), so it runs only where the recording's
noise floor is high (``alignment.json``'s ``denoise``).
"""

from __future__ import annotations

import numpy as np

from facelib.optional import require
from facelib.speech.audio import ALIGN_RATE
from facelib.speech.tables import alignment_settings

__all__ = ["denoised", "speech_to_floor_db"]


def speech_to_floor_db(samples: np.ndarray) -> float:
    """How far the loud 10 ms frames of ``samples`` (``(n,)`` at 16 kHz) stand above its
    quiet ones, in dB: the 95th over the 10th percentile of the frames' RMS. Clean speech
    with pauses measures 50 dB or more; speech in white noise at an SNR of S dB about
    S + 3 dB. ``inf`` for fewer than ten frames or digital silence between words."""
    hop = ALIGN_RATE // 100
    n = samples.size // hop
    if n < 10:
        return float("inf")
    rms = np.sqrt(np.square(samples[:n * hop].astype(np.float64)).reshape(n, hop).mean(axis=1))
    quiet, loud = np.percentile(rms, [10, 95])
    return float("inf") if quiet <= 0 else float(20 * np.log10(max(loud, quiet) / quiet))


def denoised(samples: np.ndarray) -> np.ndarray:
    """``samples`` (``(n,)`` float at 16 kHz) with stationary noise gated out when
    :func:`speech_to_floor_db` is below ``denoise.below_db``; else ``samples`` itself.
    The gate: noisereduce's stationary spectral gating, a frequency bin kept where it
    stands ``denoise.n_std`` standard deviations above the recording's own noise profile.
    Raises MissingExtraError when noisereduce (extra ``speech``) is missing and the
    recording needs it."""
    settings = alignment_settings()["denoise"]
    if speech_to_floor_db(samples) >= settings["below_db"]:
        return samples
    gate = require("noisereduce")
    out = gate.reduce_noise(y=np.asarray(samples, np.float64), sr=ALIGN_RATE, stationary=True,
                            n_std_thresh_stationary=settings["n_std"])
    return np.asarray(out, samples.dtype)
