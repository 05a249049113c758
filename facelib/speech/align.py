"""Alignment of speech audio to its transcript with pocketsphinx (the ``speech`` extra),
or recognition without one (:mod:`facelib.speech.recognize`): audio -> phone and word
timelines (the decoders: :mod:`facelib.speech.decoding`).

Two passes on 5 ms frames: the words are aligned first (``set_align_text``), then the phones
inside them (``set_alignment``); inside each word, boundaries at transitions where the aligner
is systematically early or late are shifted by a fixed amount (``alignment.json``). Words
missing from the dictionary get a letter-to-sound pronunciation. A transcript that does not
match the audio either fails to align (:class:`SpeechError`) or aligns implausibly; the
plausibility checks then warn or raise naming the word.
"""

from __future__ import annotations

import warnings
from itertools import pairwise
from pathlib import Path
from typing import Any, Literal

import numpy as np

from facelib.errors import ParameterError, PronunciationWarning, SpeechError, SpeechWarning
from facelib.speech.audio import ALIGN_RATE, load_speech, to_pcm16
from facelib.speech.decoding import forced, tokenize_words
from facelib.speech.denoise import denoised
from facelib.speech.recognize import recognize
from facelib.speech.tables import alignment_settings
from facelib.speech.timeline import PhoneTimeline, Span, append_span, cover

__all__ = ["align"]

OnImplausible = Literal["warn", "raise", "ignore"]
LONG_MS = 60_000
"""Recordings longer than this (ms) are aligned sentence by sentence (bounded memory)."""


def align(
    audio: str | Path | np.ndarray,
    text: str | None = None,
    *,
    sample_rate: int | None = None,
    on_implausible: OnImplausible = "warn",
) -> PhoneTimeline:
    """Phones and words of speech ``audio``.

    Parameters
    ----------
    audio:
        A sound file in any format soundfile reads, or an array (then give ``sample_rate``).
    text:
        The transcript. With it: forced alignment (``source="forced"``). Without: English
        speech recognised by :func:`facelib.speech.recognize.recognize` (words decoded,
        then aligned; the phone loop where no word is heard).
    on_implausible:
        What to do when the alignment looks wrong (a phone three times its usual length, a
        word squeezed to the minimum duration, a very poor acoustic score, a pause that
        sounds like speech; thresholds in ``alignment.json``): ``"warn"`` (a
        :class:`SpeechWarning` naming the word), ``"raise"`` (:class:`SpeechError`) or
        ``"ignore"``.

    Returns
    -------
    PhoneTimeline with times in ms from the start of the audio.

    Raises
    ------
    SpeechError: unreadable, empty or silent audio; a transcript without words or that
        cannot be aligned to the audio. MissingExtraError: pocketsphinx is not installed.
    """
    if on_implausible not in ("warn", "raise", "ignore"):
        raise ParameterError(
            f"on_implausible must be warn, raise or ignore, not {on_implausible!r}"
        )
    if text is None:
        return recognize(audio, sample_rate=sample_rate)
    samples = denoised(load_speech(audio, sample_rate=sample_rate))
    duration_ms = round(samples.size * 1000 / ALIGN_RATE)
    settings = alignment_settings()
    where = audio if not isinstance(audio, np.ndarray) else None
    if duration_ms > LONG_MS:
        phones, words, problems, guessed = _forced_in_pieces(samples, text, where)
    else:
        pcm = to_pcm16(samples, pad_ms=settings["pad_ms"])
        phones, words, problems, guessed = forced(pcm, text, duration_ms, where, {})
    if guessed:
        warnings.warn(f"not in the pronunciation dictionary, pronounced as spelt: "
                      f"{', '.join(repr(w) for w in guessed)}", PronunciationWarning,
                      stacklevel=2)
    if problems and on_implausible != "ignore":
        message = "implausible alignment: " + "; ".join(problems)
        if on_implausible == "raise":
            raise SpeechError(message, path=where)
        warnings.warn(message, SpeechWarning, stacklevel=2)
    return PhoneTimeline(phones, words, "forced", duration_ms)


def _forced_in_pieces(
    samples: np.ndarray, text: str, where: str | Path | None
) -> tuple[tuple[Span, ...], tuple[Span, ...], list[str], list[str]]:
    """Forced alignment of a long recording one sentence at a time: the sentences are found
    in the audio by DTW against the synthesized transcript (:func:`sentence_spans`), the
    audio is cut halfway through the pauses between them, and each piece is aligned by
    pocketsphinx with its sentence; the results are stitched. Memory stays that of one
    sentence; time grows linearly."""
    from facelib.speech.dtw import sentence_spans

    duration_ms = round(samples.size * 1000 / ALIGN_RATE)
    spans = sentence_spans(samples, text, lang="en-us")
    cuts = [0] + [(a.end_ms + b.start_ms) // 2 for a, b in pairwise(spans)]
    cuts.append(duration_ms)
    pad = alignment_settings()["pad_ms"]
    decoders: dict[bool, Any] = {}
    phones: list[Span] = []
    words: list[Span] = []
    problems: list[str] = []
    guessed: list[str] = []
    for span, start, end in zip(spans, cuts[:-1], cuts[1:], strict=True):
        piece = samples[start * ALIGN_RATE // 1000:end * ALIGN_RATE // 1000]
        if end - start < 100 or not tokenize_words(span.label):
            continue
        p, w, trouble, oov = forced(to_pcm16(piece, pad_ms=pad), span.label, end - start,
                                     where, decoders)
        for s in p:
            append_span(phones, s.label, s.start_ms + start, s.end_ms + start)
        for s in w:
            append_span(words, s.label, s.start_ms + start, s.end_ms + start)
        problems += trouble
        guessed += [g for g in oov if g not in guessed]
    decoders.clear()
    return cover(phones, duration_ms), cover(words, duration_ms), problems, guessed
