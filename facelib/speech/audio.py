"""Speech audio input: any file soundfile reads, as 16 kHz mono for the aligner."""

from __future__ import annotations

from math import gcd
from pathlib import Path

import numpy as np

from facelib.checks import check_sample_rate
from facelib.errors import ParameterError, SpeechError

__all__ = ["ALIGN_RATE", "SILENCE_PEAK", "load_speech", "read_sound", "to_pcm16"]

ALIGN_RATE = 16000
"""Sample rate of the aligner's acoustic model (Hz)."""
SILENCE_PEAK = 10 ** (-60 / 20)
"""Audio whose peak stays below -60 dBFS is treated as silent."""


def load_speech(
    audio: str | Path | np.ndarray, *, sample_rate: int | None = None
) -> np.ndarray:
    """Read speech as ``(n,) float32`` samples at 16 kHz mono in [-1, 1].

    ``audio`` is a file in any format, rate and channel count soundfile reads, or an array
    ``(n,)`` / ``(n, channels)`` with ``sample_rate``. Channels are averaged, the rate is
    converted with a polyphase filter. Raises :class:`SpeechError` naming the file if it is
    unreadable, empty or silent, or if its sample rate is outside
    :data:`facelib.checks.SAMPLE_RATES` (checked before any sample is read or resampled).
    """
    name = "<array>"
    if isinstance(audio, np.ndarray):
        if sample_rate is None:
            raise SpeechError("an audio array needs a sample_rate, got None")
        data, rate = np.asarray(audio, dtype=np.float64), _rate(sample_rate, "sample_rate")
    else:
        data, rate = read_sound(Path(audio))
        name = str(audio)
    if data.ndim == 2:
        data = data.mean(axis=1)
    if data.ndim != 1 or data.size == 0:
        raise SpeechError(f"speech audio {name} is empty (no samples)")
    if not np.isfinite(data).all():
        raise SpeechError(f"speech audio {name} has non-finite samples")
    if rate != ALIGN_RATE:
        from scipy.signal import resample_poly

        g = gcd(ALIGN_RATE, int(rate))
        data = resample_poly(data, ALIGN_RATE // g, int(rate) // g)
    peak = float(np.max(np.abs(data))) if data.size else 0.0
    if peak < SILENCE_PEAK:
        raise SpeechError(
            f"speech audio {name} is silent (peak {20 * np.log10(max(peak, 1e-12)):.1f} dBFS)"
        )
    if data.size < ALIGN_RATE // 10:
        raise SpeechError(f"speech audio {name} is too short ({data.size / ALIGN_RATE:.3f} s)")
    return np.clip(data, -1.0, 1.0).astype(np.float32)


def _rate(rate: object, source: str) -> int:
    """``rate`` checked by :func:`~facelib.checks.check_sample_rate`, as a SpeechError."""
    try:
        return check_sample_rate(rate, source=source)
    except ParameterError as exc:
        raise SpeechError(exc.message) from None


def read_sound(path: Path) -> tuple[np.ndarray, int]:
    """The samples ``(n,)`` or ``(n, channels)`` float64 and the rate of the sound file
    ``path``; the rate is checked from the header before any sample is read."""
    import soundfile

    if not path.is_file():
        raise SpeechError("speech audio file not found", path=path)
    try:
        with soundfile.SoundFile(str(path)) as source:
            rate = _rate(source.samplerate, f"speech audio {path}")
            data = source.read(dtype="float64", always_2d=False)
    except (soundfile.LibsndfileError, RuntimeError, TypeError) as exc:
        raise SpeechError(f"cannot read speech audio: {exc}", path=path) from exc
    return data, rate


def to_pcm16(samples: np.ndarray, *, pad_ms: int, seed: int = 0) -> bytes:
    """16-bit little-endian PCM of ``samples`` (16 kHz) with ``pad_ms`` of near-silence on
    both sides (the aligner's beams need leading and trailing silence). The padding carries
    a faint seeded dither so the feature normalisation never sees exact zeros."""
    pad = np.random.default_rng(seed).normal(0.0, 2.0, ALIGN_RATE * pad_ms // 1000)
    body = samples.astype(np.float64) * 32767.0
    pcm = np.concatenate([pad, body, pad[::-1]])
    return np.clip(np.round(pcm), -32768, 32767).astype("<i2").tobytes()
