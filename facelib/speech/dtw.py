"""Alignment of recorded speech in any language by dynamic time warping (the technique of
the aeneas aligner): the transcript is synthesized with espeak-ng (phone times known to the
sample), both signals become MFCC sequences, librosa's DTW finds the cheapest monotonic
match between them, and each synthesized phone boundary is carried through that warp into
the recording.

Memory stays bounded for long recordings: a recording over 30 s is aligned sentence by
sentence; each sentence is matched inside a window of the recording that starts where the
previous one ended (fixed start, open end), so the cost matrix is never larger than a
sentence by its window.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from math import gcd
from pathlib import Path

import numpy as np

from facelib.errors import SpeechError
from facelib.optional import require
from facelib.speech.audio import ALIGN_RATE, load_speech
from facelib.speech.synth import DEFAULT_LANGUAGE, Synthesis, synthesize_many, voice_for
from facelib.speech.timeline import SILENCE, PhoneTimeline, Span, append_span, cover

__all__ = ["HOP_MS", "align_dtw", "mfcc_features", "sentence_spans"]

HOP_MS = 10
"""Feature frame step (ms): the resolution of the warp."""
_N_MFCC = 13
_BLOCK_FRAMES = 6000  # one minute of feature frames per block
_WINDOW_FACTOR = 1.6
"""A sentence is searched in a window of the recording this many times its synthesized
length, plus ``_WINDOW_EXTRA_S``, from where the previous sentence ended."""
_WINDOW_EXTRA_S = 3.0
_VOICE_VARIANTS = ("", "+f2")
"""Voices tried when none is given: the language's own (male) and a female variant."""
_WHOLE_MAX_S = 30.0
"""Recordings up to this long are warped in one piece (cost matrix ~3000 x 3000 frames);
longer ones sentence by sentence."""
_SENTENCE = re.compile(r"[^.!?;:]+[.!?;:]*")


def mfcc_features(samples: np.ndarray) -> np.ndarray:
    """``(n_frames, 12) float32`` MFCCs 1-12 (no energy term) of 16 kHz ``samples``, one frame
    every :data:`HOP_MS` (25 ms windows centred on the frame times), each coefficient
    normalised to zero mean and unit variance over the signal (so voices and recording
    levels compare). Computed in blocks of a minute, so a long recording never needs its
    whole spectrogram at once."""
    librosa = require("librosa")
    hop = ALIGN_RATE * HOP_MS // 1000
    n_fft = 512
    x = np.asarray(samples, np.float32).reshape(-1)
    n_frames = 1 + x.size // hop
    padded = np.concatenate([np.zeros(n_fft // 2, np.float32), x,
                             np.zeros(n_fft // 2 + hop, np.float32)])
    blocks = []
    for first in range(0, n_frames, _BLOCK_FRAMES):
        count = min(_BLOCK_FRAMES, n_frames - first)
        chunk = padded[first * hop:first * hop + (count - 1) * hop + n_fft]
        blocks.append(librosa.feature.mfcc(y=chunk, sr=ALIGN_RATE, n_mfcc=_N_MFCC, n_fft=n_fft,
                                           win_length=400, hop_length=hop, n_mels=40,
                                           center=False)[1:, :count])
    mfcc = np.concatenate(blocks, axis=1)
    mfcc -= mfcc.mean(axis=1, keepdims=True)
    mfcc /= mfcc.std(axis=1, keepdims=True) + 1e-6
    return np.ascontiguousarray(mfcc.T, dtype=np.float32)


def _to_align_rate(samples: np.ndarray, rate: int) -> np.ndarray:
    from scipy.signal import resample_poly

    g = gcd(ALIGN_RATE, rate)
    return resample_poly(samples, ALIGN_RATE // g, rate // g).astype(np.float32)


def _warp(syn: np.ndarray, rec: np.ndarray, *, open_end: bool) -> tuple[np.ndarray, float]:
    """For each synthesized frame, the recording frame it matches, ``(len(syn),) float64``
    (mean over the path, non-decreasing), and the path's cost per step. Both start at frame
    0; with ``open_end`` the match may end before the end of ``rec`` (where the path cost
    per step is least)."""
    import librosa

    acc, steps = librosa.sequence.dtw(X=syn.T, Y=rec.T, metric="euclidean", backtrack=False,
                                      return_steps=True)
    per_step = acc[-1] / (len(syn) + np.arange(1, len(rec) + 1))
    if open_end:
        end = int(np.argmin(per_step))
        path = librosa.sequence.dtw_backtracking(steps, subseq=True, start=end)
    else:
        end = len(rec) - 1
        path = librosa.sequence.dtw_backtracking(steps, subseq=False)
    cost = float(per_step[end])
    path = np.asarray(path, dtype=np.int64)
    del acc, steps
    sums = np.bincount(path[:, 0], weights=path[:, 1], minlength=len(syn))
    counts = np.bincount(path[:, 0], minlength=len(syn))
    mapped: np.ndarray = np.maximum.accumulate(sums / np.maximum(counts, 1))
    return mapped, cost


def _closest_voice(rec: np.ndarray, sentence: str, *, lang: str, last: bool) -> str:
    """The candidate voice (``_VOICE_VARIANTS`` of the language's voice) whose rendering of
    the first sentence matches the start of the recording at the least cost per step: a
    synthetic voice close to the speaker's (above all in register) warps more accurately
    (Harvard lists 3-4, a female Festival voice: 43 % of onsets within 20 ms with a female
    espeak-ng variant, 31 % with the default male voice)."""
    base = voice_for(lang)
    candidates = [base + variant for variant in _VOICE_VARIANTS]
    made = synthesize_many([sentence] * len(candidates), lang=lang, voice=None,
                           voices=candidates)
    costs = []
    for syn in made:
        feats = mfcc_features(_to_align_rate(np.asarray(syn.samples), syn.sample_rate))
        size = len(rec) if last else int(len(feats) * _WINDOW_FACTOR
                                          + _WINDOW_EXTRA_S * 1000 / HOP_MS)
        costs.append(_warp(feats, rec[:size], open_end=not last)[1])
    return candidates[int(np.argmin(costs))]


def _sentences(text: str) -> list[str]:
    found = [s.strip() for s in _SENTENCE.findall(text) if s.strip()]
    return found or [text]


def align_dtw(
    audio: str | Path | np.ndarray,
    text: str,
    *,
    lang: str = DEFAULT_LANGUAGE,
    voice: str | None = None,
    sample_rate: int | None = None,
) -> PhoneTimeline:
    """Phones (IPA) and words of recorded speech ``audio`` saying ``text`` in ``lang``.

    ``audio`` is a sound file or an array (with ``sample_rate``), as for
    :func:`facelib.speech.align`; ``voice`` is the espeak-ng voice to synthesize the
    transcript with (default: the language's own or its female variant ``+f2``, whichever
    matches the start of the recording better). Returns a timeline in ms from the start of
    the audio, ``source="dtw"``, ``alphabet="ipa"``. Raises SpeechError for unreadable or
    silent audio or a transcript without words; MissingExtraError without the speech extra.
    """
    samples = load_speech(audio, sample_rate=sample_rate)
    duration_ms = round(samples.size * 1000 / ALIGN_RATE)
    where = None if isinstance(audio, np.ndarray) else audio
    phones: list[Span] = []
    words: list[Span] = []
    by_sentence = duration_ms > _WHOLE_MAX_S * 1000
    for _, syn, to_rec_ms in _warped(samples, text, lang=lang, voice=voice,
                                       by_sentence=by_sentence, where=where):
        for span in syn.timeline.phones:
            append_span(phones, span.label, to_rec_ms(span.start_ms), to_rec_ms(span.end_ms))
        for span in syn.timeline.words:
            append_span(words, span.label, to_rec_ms(span.start_ms), to_rec_ms(span.end_ms))
    return PhoneTimeline(cover(_clipped(phones, duration_ms), duration_ms),
                         cover(_clipped(words, duration_ms), duration_ms), "dtw",
                         duration_ms, alphabet="ipa")


def sentence_spans(
    samples: np.ndarray, text: str, *, lang: str = DEFAULT_LANGUAGE, voice: str | None = None,
) -> list[Span]:
    """Where each sentence of ``text`` is spoken in ``samples`` (``(n,) float32`` at 16 kHz):
    spans labelled with the sentence, from its first sound to its last (ms), found by DTW
    sentence by sentence (bounded memory). Used to cut long recordings into utterances."""
    out: list[Span] = []
    for sentence, syn, to_rec_ms in _warped(samples, text, lang=lang, voice=voice,
                                              by_sentence=True, where=None):
        sounds = [p for p in syn.timeline.phones if p.label != SILENCE]
        if not sounds:
            continue
        start, end = to_rec_ms(sounds[0].start_ms), to_rec_ms(sounds[-1].end_ms)
        if out:
            start = max(start, out[-1].end_ms)
        out.append(Span(sentence, start, max(start, end)))
    return out


def _warped(
    samples: np.ndarray, text: str, *, lang: str, voice: str | None, by_sentence: bool,
    where: str | Path | None,
) -> Iterator[tuple[str, Synthesis, Callable[[int], int]]]:
    """For each sentence (or the whole ``text``): the sentence, its synthesis, and the map
    from its synthesized time (ms) to recording time (ms)."""
    if not isinstance(text, str) or not text.strip():
        raise SpeechError(f"transcript {text!r} has no words")
    rec = mfcc_features(samples)
    cursor = 0
    parts = _sentences(text) if by_sentence else [text]
    if voice is None:
        voice = _closest_voice(rec, parts[0], lang=lang, last=len(parts) == 1)
    spoken = synthesize_many(parts, lang=lang, voice=voice)
    for k, (sentence, syn) in enumerate(zip(parts, spoken, strict=True)):
        feats = mfcc_features(_to_align_rate(np.asarray(syn.samples), syn.sample_rate))
        last = k + 1 == len(parts)
        if last:
            window = rec[cursor:]
        else:
            size = int(len(feats) * _WINDOW_FACTOR + _WINDOW_EXTRA_S * 1000 / HOP_MS)
            window = rec[cursor:cursor + size]
        if len(window) < 2:
            raise SpeechError(f"the recording ends before the sentence {sentence[:40]!r}",
                              path=where)
        mapped, _ = _warp(feats, window, open_end=not last)
        offset = cursor

        def to_rec_ms(ms: int, mapped: np.ndarray = mapped, offset: int = offset) -> int:
            i = min(round(ms / HOP_MS), len(mapped) - 1)
            return round(float(mapped[i] + offset) * HOP_MS)

        yield sentence, syn, to_rec_ms
        cursor = offset + int(np.ceil(mapped[-1]))


def _clipped(spans: list[Span], duration_ms: int) -> list[Span]:
    """The spans cut at ``duration_ms`` (the warp may reach a little past the recording)."""
    return [Span(s.label, min(s.start_ms, duration_ms), min(s.end_ms, duration_ms))
            for s in spans if s.start_ms < duration_ms]
