"""Visemes of speech audio as it streams in, chunk by chunk: the acoustic viseme model
(``method="acoustic"``, any language: :class:`facelib.speech.acoustic.
AcousticStream`, each frame decided a fixed look-ahead after it, the undecided end held at
the last viseme decided) or pocketsphinx's phone loop (``method="phones"``, English: its
partial phone segmentation read after each chunk).

A stretch of audio is one recognizer utterance; it ends (and the recognizer's memory with it)
once it is longer than ``MAX_STRETCH_MS`` and its last ``QUIET_MS`` are quiet, or at
``HARD_STRETCH_MS`` whatever the audio: memory stays bounded over hours of input.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np

from facelib.errors import ParameterError
from facelib.speech.acoustic import AcousticStream, classes_to_spans, load_model
from facelib.speech.audio import ALIGN_RATE, to_pcm16
from facelib.speech.decoding import NOISE, PHONE_LOOP, new_decoder
from facelib.speech.loudness import window_loudness
from facelib.speech.tables import alignment_settings
from facelib.speech.timeline import SILENCE, PhoneTimeline, Span, append_span, cover
from facelib.visemes.animate import SpeechAudio
from facelib.visemes.mapping import with_visemes
from facelib.visemes.timeline import SpeechTimeline

__all__ = ["HARD_STRETCH_MS", "LISTEN_METHODS", "MAX_CHUNK_SAMPLES", "MAX_STRETCH_MS",
           "QUIET_MS", "ListenMethod", "Listener", "pcm16_samples"]

ListenMethod = Literal["acoustic", "phones"]
LISTEN_METHODS = ("acoustic", "phones")

MAX_STRETCH_MS = 8_000
HARD_STRETCH_MS = 30_000
QUIET_MS = 300
_QUIET_DB = -45.0
MAX_CHUNK_SAMPLES = ALIGN_RATE * 5
"""Most samples one audio chunk may carry (5 s at 16 kHz)."""


def pcm16_samples(pcm: bytes) -> np.ndarray:
    """``(n,) float32`` in [-1, 1] of 16-bit little-endian mono PCM ``pcm``."""
    if len(pcm) % 2 or len(pcm) // 2 > MAX_CHUNK_SAMPLES:
        raise ParameterError(f"audio chunks are 16-bit PCM of at most {MAX_CHUNK_SAMPLES} "
                             f"samples, got {len(pcm)} bytes")
    return np.frombuffer(pcm, "<i2").astype(np.float32) / 32768.0


class Listener:
    """One stretch of streamed 16 kHz speech and its partial phone timeline, recognised by
    ``method`` (``"acoustic"`` or ``"phones"``)."""

    def __init__(self, *, method: ListenMethod = "acoustic") -> None:
        if method not in LISTEN_METHODS:
            raise ParameterError(f"listen must be one of {', '.join(LISTEN_METHODS)}, "
                                 f"not {method!r}")
        self.method = method
        self._stream: AcousticStream | None = None
        self._decoder: Any = None
        self._chunks: list[np.ndarray] = []
        self._open = False  # an utterance is started
        self.n_samples = 0

    @property
    def duration_ms(self) -> int:
        return self.n_samples * 1000 // ALIGN_RATE

    def prepare(self) -> None:
        """Load the recognizer (about 0.6 s and 90 MB) and open the next stretch's utterance
        (its leading pad decoded) now, rather than at the first samples; for the acoustic
        model, load it (a few ms) and start the stretch's stream."""
        if self.method == "acoustic":
            if self._stream is None:
                self._stream = AcousticStream(load_model())
            return
        if self._decoder is None:
            decoder = new_decoder()
            decoder.activate_search(PHONE_LOOP)
            self._decoder = decoder
        if not self._open:
            self._decoder.start_utt()
            pad = alignment_settings()["pad_ms"]
            self._decoder.process_raw(to_pcm16(np.zeros(0, np.float32), pad_ms=pad // 2),
                                      no_search=False, full_utt=False)
            self._open = True

    def feed(self, samples: np.ndarray) -> tuple[SpeechTimeline, SpeechAudio]:
        """Add ``samples`` (``(n,) float32`` at 16 kHz) to the stretch: its timeline so far
        (phones of the phone loop, their visemes; the last may still change) and its
        samples from the first."""
        self.prepare()
        self._chunks.append(np.asarray(samples, np.float32))
        self.n_samples += samples.size
        if self._stream is not None:
            self._stream.feed(samples)
            audio = np.concatenate(self._chunks)
            self._chunks = [audio]
            return self._acoustic_timeline(), SpeechAudio(audio, ALIGN_RATE)
        pcm = np.clip(np.round(samples.astype(np.float64) * 32767), -32768, 32767)
        self._decoder.process_raw(pcm.astype("<i2").tobytes(), no_search=False,
                                  full_utt=False)
        audio = np.concatenate(self._chunks)
        self._chunks = [audio]
        return self._timeline(), SpeechAudio(audio, ALIGN_RATE)

    def _acoustic_timeline(self) -> SpeechTimeline:
        assert self._stream is not None
        duration = self.duration_ms
        classes = self._stream.classes
        # frames not yet decided hold the last decided viseme (they may still change)
        held = classes + [classes[-1] if classes else 0] * max(
            -(-duration // 10) - len(classes), 0)
        phones = classes_to_spans(held, self._stream.model.labels, duration) or (
            Span(SILENCE, 0, duration),)
        return with_visemes(PhoneTimeline(phones, (), "acoustic", duration, alphabet="ipa"))

    def _timeline(self) -> SpeechTimeline:
        settings = alignment_settings()
        frame, pad = settings["frame_ms"], settings["pad_ms"] // 2 * 2
        duration = self.duration_ms
        spans: list[Span] = []
        for seg in self._decoder.seg():
            label = SILENCE if seg.word in NOISE else seg.word
            start = min(max(seg.start_frame * frame - pad, 0), duration)
            end = min(max((seg.end_frame + 1) * frame - pad, 0), duration)
            append_span(spans, label, int(start), int(end))
        phones = cover(spans, duration) or (Span(SILENCE, 0, duration),)
        return with_visemes(PhoneTimeline(phones, (), "phone-loop", duration))

    def should_end(self) -> bool:
        """Whether the stretch is long enough to end here (quiet lately, or very long)."""
        if self.duration_ms >= HARD_STRETCH_MS:
            return True
        if self.duration_ms < MAX_STRETCH_MS:
            return False
        audio = self._chunks[0]
        level = window_loudness(audio, sample_rate=ALIGN_RATE,
                                starts_ms=np.array([self.duration_ms - QUIET_MS]),
                                ends_ms=np.array([self.duration_ms]))
        return bool(level[0] < _QUIET_DB)

    def end(self) -> None:
        """End the stretch: the next samples start a new one."""
        if self._open:
            self._decoder.end_utt()
            self._open = False
        self._stream = None
        self._chunks = []
        self.n_samples = 0
