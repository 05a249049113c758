"""Noise reduction before alignment: clean speech untouched, noisy speech gated."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from facelib.speech.audio import load_speech
from facelib.speech.denoise import denoised, speech_to_floor_db
from facelib.speech.tables import alignment_settings

pytest.importorskip("noisereduce")

FOX = Path(__file__).parents[1] / "data" / "speech" / "alignment" / "quick_fox.flac"


def _in_noise(x: np.ndarray, snr_db: float) -> np.ndarray:
    """``x`` plus seeded white noise ``snr_db`` below the power of its speech samples."""
    speech = x[np.abs(x) > 0.01 * np.abs(x).max()]
    noise = np.random.default_rng(0).normal(0.0, 1.0, x.size)
    return (x + noise * np.sqrt(np.mean(speech ** 2) / 10 ** (snr_db / 10))).astype(x.dtype)


def test_clean_speech_passes_untouched():
    x = load_speech(FOX)
    assert speech_to_floor_db(x) > 45
    assert denoised(x) is x


@pytest.mark.parametrize("snr_db", [10, 20])
def test_noise_floor_tracks_the_snr(snr_db):
    """White noise at S dB SNR measures about S + 3 dB (the loud frames are louder than the
    speech's mean power)."""
    assert speech_to_floor_db(_in_noise(load_speech(FOX), snr_db)) == pytest.approx(
        snr_db + 3, abs=2)


def test_noisy_speech_is_gated_in_its_pauses_and_kept_in_its_words():
    """At 10 dB the pauses fall by more than half against the words (the gate scales the
    whole recording down too, which the aligner's cepstral mean normalisation ignores),
    and the result follows the clean speech at least as closely as the noisy one does."""
    x = load_speech(FOX)
    noisy = _in_noise(x, 10)
    assert speech_to_floor_db(noisy) < alignment_settings()["denoise"]["below_db"]
    gated = denoised(noisy)
    assert gated.shape == noisy.shape and gated.dtype == noisy.dtype

    def pause_to_words(y: np.ndarray) -> float:
        return float(np.sqrt(np.mean(y[np.abs(x) < 1e-4] ** 2)
                             / np.mean(y[np.abs(x) > 0.05] ** 2)))

    assert pause_to_words(gated) < 0.5 * pause_to_words(noisy)
    assert np.corrcoef(x, gated)[0, 1] >= np.corrcoef(x, noisy)[0, 1]
    assert speech_to_floor_db(gated) > speech_to_floor_db(noisy) + 8


def test_too_short_or_silent_audio_measures_no_floor():
    assert speech_to_floor_db(np.zeros(16_000)) == float("inf")
    assert speech_to_floor_db(np.ones(100)) == float("inf")
