"""Speech without a transcript: what was said, found from the audio alone (Whisper through
faster-whisper, the ``asr`` extra, or pocketsphinx, the ``speech`` extra).

English takes two passes: pass 1 decodes words, each with its confidence (0-1), by the
first installed decoder of ``recognition.json``'s ``word_decoders``: Whisper (weights from
a model package, :mod:`facelib.speech.whisper`; the word's probability) or pocketsphinx
(the language model and dictionary its wheel ships; the word's posterior probability in
the word lattice); pass 2 aligns that transcript to the audio exactly as a given one
(:mod:`facelib.speech.align`), so phones and boundaries are as precise as the words are
right. Only where pass 1 hears no word, or its words cannot be aligned, do the phones come
from the phone loop (every phone recognised on its own, far less accurate). Settings:
``recognition.json``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from itertools import pairwise
from pathlib import Path
from typing import Any, Literal

import numpy as np

from facelib.errors import ParameterError, SpeechError
from facelib.optional import require
from facelib.speech.audio import ALIGN_RATE, load_speech, to_pcm16
from facelib.speech.decoding import decode, forced, phone_loop, tokenize_words
from facelib.speech.denoise import denoised
from facelib.speech.tables import alignment_settings, recognition_settings
from facelib.speech.timeline import SILENCE, PhoneTimeline, Source, Span, append_span, cover

__all__ = ["METHODS", "WORD_DECODERS", "Method", "auto_method", "decode_words",
           "recognizable_languages", "recognize", "word_decoder"]

Method = Literal["auto", "words", "phones", "acoustic"]
"""How speech without a transcript is recognised: ``"auto"`` (the best path measured for the
language: ``recognition.json``'s ``auto``), ``"words"`` (the two passes alone),
``"phones"`` (the phone loop), ``"acoustic"`` (the project's acoustic viseme model,
:mod:`facelib.speech.acoustic`: any language, numpy only)."""
METHODS = ("auto", "words", "phones", "acoustic")
WORD_DECODERS = ("whisper", "pocketsphinx")
"""Pass 1's word decoders; ``"whisper:NAME"`` names one of ``whisper.models`` too."""
_FILLERS = {"<s>", "</s>", "<sil>", "[NOISE]", "[SPEECH]", "[BREATH]", "[COUGH]", "[LAUGH]",
            "[UM]", "[UH]", "[SMACK]"}


def recognizable_languages(method: Method = "auto") -> tuple[str, ...]:
    """The languages (ISO 639-1) that ``method`` recognises without a transcript; ``("*",)``
    for every language (``"acoustic"``, and so ``"auto"``)."""
    settings = recognition_settings()
    if method in ("acoustic", "auto"):
        return ("*",)
    key = "phone_loop_languages" if method == "phones" else "word_languages"
    return tuple(settings[key])


def auto_method(language: str) -> Method:
    """The method ``"auto"`` takes for ``language``: ``recognition.json``'s ``auto`` entry
    for it (the path that measured best), else its ``"*"`` entry."""
    table = recognition_settings()["auto"]
    method: Method = table.get(_language_code(language), table["*"])
    return method


def _language_code(language: str) -> str:
    """The primary subtag of ``language`` in lower case (``"en-GB"``, ``"en_gb"``: ``"en"``)."""
    return language.lower().replace("_", "-").split("-")[0]


def recognize(
    audio: str | Path | np.ndarray, *, sample_rate: int | None = None,
    language: str = "en", method: Method = "auto", decoder: str | None = None,
) -> PhoneTimeline:
    """Phones and words of speech ``audio`` without its transcript.

    ``method="auto"`` (the default) takes the path that measured best for ``language``
    (:func:`auto_method`: ``recognition.json``'s ``auto``). ``"acoustic"``: the acoustic
    viseme model, any language (``source="acoustic"``, IPA phones standing for their
    visemes, no words). ``"words"``: words decoded, then aligned
    (``source="recognized"``, each word's ``confidence`` in [0, 1]); under ``"auto"`` a
    recording where no word is heard goes to the phone loop (``source="phone-loop"``, no
    words), ``"words"`` alone raises instead. ``"phones"`` takes the phone loop at once.
    Recordings over ``piece_ms`` are recognised in pieces cut at their quietest moments (a
    piece without words takes the phone loop alone; the timeline's ``source`` is then that
    of most of its time).

    ``decoder``: pass 1's word decoder (:data:`WORD_DECODERS`; default
    :func:`word_decoder`, the first installed of ``recognition.json``'s
    ``word_decoders``).

    ``language``: ``"words"`` and ``"phones"`` have English models only
    (``recognition.json``); another language raises :class:`SpeechError` naming it.

    Raises SpeechError (unreadable or silent audio, no speech heard, a language without a
    model), ParameterError (an unknown ``method``), MissingExtraError (no pocketsphinx).
    """
    if method not in METHODS:
        raise ParameterError(f"method must be one of {', '.join(METHODS)}, not {method!r}")
    if method == "acoustic" or (method == "auto" and auto_method(language) == "acoustic"):
        from facelib.speech.acoustic import recognize_acoustic

        heard = recognize_acoustic(audio, sample_rate=sample_rate)
        if all(s.label == SILENCE for s in heard.phones):
            raise SpeechError("no speech recognised in the audio",
                              path=None if isinstance(audio, np.ndarray) else audio)
        return heard
    if _language_code(language) not in recognizable_languages(method) and method != "auto":
        known = ", ".join(recognizable_languages(method))
        raise SpeechError(
            f"speech in {language!r} needs its transcript (text): there is no recogniser "
            f"for {language!r} audio alone (method {method!r} knows {known})",
            path=None if isinstance(audio, np.ndarray) else audio)
    timeline = _recognize_pieces(load_speech(audio, sample_rate=sample_rate), method, decoder)
    if all(s.label == SILENCE for s in timeline.phones):
        raise SpeechError("no speech recognised in the audio",
                          path=None if isinstance(audio, np.ndarray) else audio)
    return timeline


def _recognize_pieces(samples: np.ndarray, method: Method, decoder: str | None) -> PhoneTimeline:
    """Phones and words of ``samples`` (``(n,)`` at ALIGN_RATE) recognised piece by piece
    (:func:`piece_bounds`), joined on one clock; the source is that of most of the time."""
    duration_ms = round(samples.size * 1000 / ALIGN_RATE)
    phones: list[Span] = []
    words: list[Span] = []
    sources: dict[Source, int] = {}
    for start, end in piece_bounds(samples):
        piece = samples[start * ALIGN_RATE // 1000:end * ALIGN_RATE // 1000]
        p, w, source = _recognize_piece(piece, end - start, method, decoder)
        sources[source] = sources.get(source, 0) + end - start
        _append_shifted(phones, p, start)
        _append_shifted(words, w, start)
    source = max(sources, key=lambda s: sources[s])
    return PhoneTimeline(cover(phones, duration_ms), cover(words, duration_ms), source,
                         duration_ms)


def _append_shifted(out: list[Span], spans: Sequence[Span], offset_ms: int) -> None:
    """``spans`` shifted by ``offset_ms`` appended to ``out`` (as ``append_span`` appends)."""
    for s in spans:
        append_span(out, s.label, s.start_ms + offset_ms, s.end_ms + offset_ms,
                    confidence=s.confidence)


def _recognize_piece(
    samples: np.ndarray, duration_ms: int, method: Method, decoder: str | None
) -> tuple[tuple[Span, ...], tuple[Span, ...], Source]:
    """Phones, words and source of one piece (times from the piece's start): the words
    decoded from the recording as it is, the aligner and the phone loop given it
    :func:`denoised`."""
    pad = alignment_settings()["pad_ms"]
    clean = denoised(samples)
    if method != "phones":
        decoded = decode_words(samples, decoder=decoder)
        tokens = [(t, c) for word, c in decoded for t in tokenize_words(word)]
        if tokens:
            try:
                return _align_decoded(clean, tokens, duration_ms)
            except SpeechError:
                if method == "words":
                    raise
        elif method == "words":
            raise SpeechError("no word recognised in the audio")
    try:
        return phone_loop(to_pcm16(clean, pad_ms=pad), duration_ms), (), "phone-loop"
    except SpeechError:
        silence = (Span(SILENCE, 0, duration_ms),) if duration_ms > 0 else ()
        return silence, (), "phone-loop"


def _align_decoded(
    samples: np.ndarray, tokens: list[tuple[str, float]], duration_ms: int
) -> tuple[tuple[Span, ...], tuple[Span, ...], Source]:
    """Pass 2: the decoded words force-aligned, each word span with its confidence."""
    pad = alignment_settings()["pad_ms"]
    text = " ".join(t for t, _ in tokens)
    phones, words, _, _ = forced(to_pcm16(samples, pad_ms=pad), text, duration_ms, None, {})
    spoken = iter(c for _, c in tokens)
    out = []
    for w in words:
        if w.label == SILENCE:
            out.append(w)
        else:
            out.append(replace(w, confidence=next(spoken, None)))
    return phones, tuple(out), "recognized"


def word_decoder() -> str:
    """Pass 1's decoder: the first of ``recognition.json``'s ``word_decoders`` that is
    installed (``"whisper"`` needs faster-whisper and a model package, the ``asr`` extra);
    the last one (pocketsphinx) when none is."""
    from facelib.speech.whisper import whisper_model

    names: list[str] = recognition_settings()["word_decoders"]
    for name in names:
        if name != "whisper" or whisper_model() is not None:
            return name
    return names[-1]


def decode_words(samples: np.ndarray, *, decoder: str | None = None) -> list[tuple[str, float]]:
    """Pass 1: the words ``decoder`` (:data:`WORD_DECODERS`, default :func:`word_decoder`)
    hears in ``samples`` (``(n,) float64`` at 16 kHz, as :func:`load_speech` gives them), in
    order, each with its confidence in [0, 1] (Whisper's word probability, pocketsphinx's
    posterior in its lattice); fillers (silence, noise) are left out and alternative
    pronunciations named by the word alone. Empty when no word is heard. Raises
    ParameterError for an unknown decoder."""
    name = decoder or word_decoder()
    kind, _, model = name.partition(":")
    if kind not in WORD_DECODERS:
        raise ParameterError(f"decoder must be one of {', '.join(WORD_DECODERS)}, "
                             f"not {name!r}")
    if kind == "whisper":
        from facelib.speech.whisper import transcribe_words

        return transcribe_words(samples, model=model or None)
    return _pocketsphinx_words(samples)


def _pocketsphinx_words(samples: np.ndarray) -> list[tuple[str, float]]:
    """Pass 1 with pocketsphinx's word decoder and the language model its wheel ships."""
    settings = recognition_settings()
    decoder = _word_decoder(settings)
    decode(decoder, to_pcm16(samples, pad_ms=alignment_settings()["pad_ms"]))
    out = []
    for seg in decoder.seg():
        if seg.word in _FILLERS:
            continue
        out.append((seg.word.split("(")[0], float(min(max(seg.prob, 0.0), 1.0))))
    return out


def _word_decoder(settings: Any) -> Any:
    """A new pocketsphinx decoder with the wheel's language model and a word lattice (for
    the posteriors); not kept, like the aligner's."""
    Decoder = require("recognition").Decoder  # noqa: N806
    return Decoder(bestpath=True, loglevel="FATAL", frate=round(1000 / settings["frame_ms"]),
                   wlen=settings["window_ms"] / 1000, lw=settings["language_weight"])


def piece_bounds(samples: np.ndarray) -> list[tuple[int, int]]:
    """``(start_ms, end_ms)`` pieces covering ``samples`` (16 kHz): one piece up to
    ``piece_ms``; longer audio is cut near every ``piece_ms`` mark at the centre of the
    quietest ``cut_window_ms`` within ``cut_search_ms`` before it."""
    settings = recognition_settings()
    duration_ms = round(samples.size * 1000 / ALIGN_RATE)
    piece, search = settings["piece_ms"], settings["cut_search_ms"]
    if duration_ms <= piece:
        return [(0, duration_ms)]
    hop = ALIGN_RATE // 100  # 10 ms frames
    energy = np.square(samples[:samples.size // hop * hop]).reshape(-1, hop).mean(axis=1)
    width = max(settings["cut_window_ms"] // 10, 1)
    smooth = np.convolve(energy, np.ones(width) / width, mode="same")
    cuts = [0]
    while duration_ms - cuts[-1] > piece:
        hi = (cuts[-1] + piece) // 10
        lo = max(hi - search // 10, cuts[-1] // 10 + 1)
        cuts.append(10 * (lo + _quietest(smooth[lo:hi])))
    cuts.append(duration_ms)
    return list(pairwise(cuts))


def _quietest(energy: np.ndarray) -> int:
    """Index of the middle of the quietest run of ``energy`` ``(n,)`` (the run of frames
    around its minimum within 1 % of the range above it)."""
    k = int(np.argmin(energy))
    quiet = energy <= energy[k] + 0.01 * (energy.max() - energy[k])
    lo = hi = k
    while lo > 0 and quiet[lo - 1]:
        lo -= 1
    while hi + 1 < energy.size and quiet[hi + 1]:
        hi += 1
    return (lo + hi) // 2
