"""Forced alignment of speech audio to its transcript, and phone-loop recognition, with
pocketsphinx (the ``speech`` extra): audio -> phone and word timelines.

Two passes on 5 ms frames: the words are aligned first (``set_align_text``), then the phones
inside them (``set_alignment``); inside each word, boundaries at transitions where the aligner
is systematically early or late are shifted by a fixed amount (``alignment.json``). Words
missing from the dictionary get a letter-to-sound pronunciation. A transcript that does not
match the audio either fails to align (:class:`SpeechError`) or aligns implausibly; the
plausibility checks then warn or raise naming the word.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping, Sequence
from itertools import pairwise
from pathlib import Path
from typing import Any, Literal

import numpy as np

from facelib.errors import ParameterError, PronunciationWarning, SpeechError, SpeechWarning
from facelib.optional import require
from facelib.speech.audio import ALIGN_RATE, load_speech, to_pcm16
from facelib.speech.pronounce import model_dir, pronounce, tokenize
from facelib.speech.tables import alignment_settings, phone_durations
from facelib.speech.timeline import SILENCE, PhoneTimeline, Span, append_span, cover

__all__ = ["align"]

OnImplausible = Literal["warn", "raise", "ignore"]
LONG_MS = 60_000
"""Recordings longer than this (ms) are aligned sentence by sentence (bounded memory)."""
_NOISE = {"SIL", "NSN", "SPN", "<sil>", "<s>", "</s>", "[NOISE]", "+NSN+", "+SPN+"}
_PHONE_LOOP = "_facelib_phone_loop"


def _decoder(*, wide: bool = False) -> Any:
    """A new pocketsphinx decoder (``wide``: with the wide beams of alignment.json). Not
    kept: a decoder holds on to the memory of its last search (gigabytes after a long
    recording), so each alignment loads the model afresh (about a second) and frees it."""
    Decoder = require("pocketsphinx").Decoder  # noqa: N806
    settings = alignment_settings()
    beams = settings["wide_beams"] if wide else {}
    decoder = Decoder(bestpath=False, loglevel="FATAL", frate=1000 // settings["frame_ms"],
                      wlen=settings["window_ms"] / 1000, **beams)
    decoder.add_allphone_file(_PHONE_LOOP, str(model_dir() / "en-us-phone.lm.bin"))
    return decoder


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
        from facelib.speech.recognize import recognize

        return recognize(audio, sample_rate=sample_rate)
    samples = load_speech(audio, sample_rate=sample_rate)
    duration_ms = round(samples.size * 1000 / ALIGN_RATE)
    settings = alignment_settings()
    where = audio if not isinstance(audio, np.ndarray) else None
    if duration_ms > LONG_MS:
        phones, words, problems, guessed = _forced_in_pieces(samples, text, where)
    else:
        pcm = to_pcm16(samples, pad_ms=settings["pad_ms"])
        phones, words, problems, guessed = _forced(pcm, text, duration_ms, where, {})
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
        p, w, trouble, oov = _forced(to_pcm16(piece, pad_ms=pad), span.label, end - start,
                                     where, decoders)
        for s in p:
            append_span(phones, s.label, s.start_ms + start, s.end_ms + start)
        for s in w:
            append_span(words, s.label, s.start_ms + start, s.end_ms + start)
        problems += trouble
        guessed += [g for g in oov if g not in guessed]
    decoders.clear()
    return cover(phones, duration_ms), cover(words, duration_ms), problems, guessed


def tokenize_words(text: str) -> list[str]:
    """The words of ``text`` as the aligner sees them (no punctuation); empty if none."""
    try:
        return [t for t in tokenize(text) if t[0].isalpha()]
    except SpeechError:
        return []


def _decode(decoder: Any, pcm: bytes) -> None:
    decoder.start_utt()
    decoder.process_raw(pcm, full_utt=True)
    decoder.end_utt()


def _forced(
    pcm: bytes, text: str, duration_ms: int, where: str | Path | None,
    decoders: dict[bool, Any],
) -> tuple[tuple[Span, ...], tuple[Span, ...], list[str], list[str]]:
    """Forced alignment of one utterance; ``decoders`` (wide beams? -> decoder) holds the
    decoders made so far in this call, so pieces of one recording share them."""
    words = [t for t in tokenize(text) if t[0].isalpha()]

    def decoder(*, wide: bool) -> Any:
        if wide not in decoders:
            decoders[wide] = _decoder(wide=wide)
        return decoders[wide]

    try:
        return _forced_with(decoder(wide=False), pcm, words, text=text, duration_ms=duration_ms,
                            where=where)
    except SpeechError:
        # The default beams sometimes prune every path of a correct transcript (seen on
        # espeak-ng speech); the wide beams find it, at some cost in boundary precision.
        return _forced_with(decoder(wide=True), pcm, words, text=text,
                            duration_ms=duration_ms, where=where)


def _forced_with(
    decoder: Any, pcm: bytes, words: list[str], *, text: str, duration_ms: int,
    where: str | Path | None,
) -> tuple[tuple[Span, ...], tuple[Span, ...], list[str], list[str]]:
    guessed = []
    for word in words:
        if decoder.lookup_word(word) is None:
            phones, _ = pronounce(word)
            decoder.add_word(word, " ".join(phones), update=True)
            guessed.append(word)
    decoder.set_align_text(" ".join(words))
    _decode(decoder, pcm)
    try:
        decoder.set_alignment()
    except RuntimeError as exc:
        raise SpeechError(
            f"the transcript {text!r} cannot be aligned to the audio (does it match what is said?)",
            path=where,
        ) from exc
    _decode(decoder, pcm)
    alignment = decoder.get_alignment()
    if alignment is None:
        raise SpeechError(f"the transcript {text!r} cannot be aligned to the audio", path=where)
    settings = alignment_settings()
    to_ms = _frame_to_ms(duration_ms)
    phone_spans: list[Span] = []
    word_spans: list[Span] = []
    problems: list[str] = []
    # copy out of pocketsphinx at once: its entries are views into the decoder's memory
    entries = [(w.name.split("(")[0], w.start, [(p.name, p.start, p.duration, p.score)
                                                  for p in w]) for w in alignment]
    n_entries = len(entries)
    for k, (name, word_start, word_phones) in enumerate(entries):
        is_sil = name in _NOISE
        start = to_ms(word_start)
        end = to_ms(word_phones[-1][1] + word_phones[-1][2]) if word_phones else start
        append_span(word_spans, SILENCE if is_sil else name, start, end)
        spans = [(SILENCE if (is_sil or label in _NOISE) else label, to_ms(p_start),
                  to_ms(p_start + p_dur)) for label, p_start, p_dur, _ in word_phones]
        for label, p_start, p_end in _shift_boundaries(spans, settings):
            append_span(phone_spans, label, p_start, p_end)
        if not is_sil:
            final = k + 1 == n_entries or entries[k + 1][0] in _NOISE
            problems += _check_word(name, word_phones, settings, name in guessed, final=final)
        else:
            problems += _check_pause(word_spans, word_phones, settings)
    return (cover(phone_spans, duration_ms), cover(word_spans, duration_ms), problems,
            guessed)


def _shift_boundaries(
    phones: Sequence[tuple[str, int, int]], settings: Mapping[str, Any]
) -> list[tuple[str, int, int]]:
    """The phones ``(label, start_ms, end_ms)`` of one word with the boundary between two
    phones moved by ``boundary_shift_ms["CLASS CLASS"]`` of their ``phone_classes`` (ms,
    positive: later; the aligner's systematic bias at vowel -> nasal, nasal -> stop and
    liquid -> vowel transitions). Each phone keeps at least ``min_phone_ms``."""
    classes = {p: c for c, members in settings["phone_classes"].items() for p in members}
    shifts, min_ms = settings["boundary_shift_ms"], settings["min_phone_ms"]
    out = list(phones)
    for i in range(1, len(out)):
        (a, a_start, _), (b, b_start, b_end) = out[i - 1], out[i]
        shift = shifts.get(f"{classes.get(a)} {classes.get(b)}", 0)
        t = min(max(b_start + shift, a_start + min_ms), b_end - min_ms)
        if shift and a_start + min_ms <= t:
            out[i - 1], out[i] = (a, a_start, t), (b, t, b_end)
    return out


def _check_word(
    word: str,
    phones: Sequence[tuple[str, int, int, int]],
    settings: Mapping[str, Any],
    oov: bool,
    *,
    final: bool,
) -> list[str]:
    frame_ms = settings["frame_ms"]
    note = " (pronunciation guessed)" if oov else ""
    means = phone_durations()
    out = []
    for i, (label, _, dur, _) in enumerate(phones):
        factor = settings["final_phone_factor" if final and i == len(phones) - 1
                          else "max_phone_factor"]
        limit = factor * means.get(label, (200, 0))[0]
        if dur * frame_ms > limit:
            out.append(f"word {word!r}{note}: phone {label} lasts {dur * frame_ms} ms "
                       f"(more than {limit:.0f} ms)")
    min_frames = settings["min_phone_ms"] // frame_ms
    if len(phones) >= 3 and all(dur <= min_frames for _, _, dur, _ in phones):
        out.append(f"word {word!r}{note}: every phone squeezed to {settings['min_phone_ms']} ms")
    frames = sum(dur for _, _, dur, _ in phones)
    score = sum(s for *_, s in phones) / max(frames, 1)
    if score < settings["min_word_score_per_frame"]:
        out.append(f"word {word!r}{note}: poor acoustic match ({score:.0f} per frame)")
    return out


def _check_pause(
    words: Sequence[Span], phones: Sequence[tuple[str, int, int, int]], settings: Mapping[str, Any]
) -> list[str]:
    """A long pause that scores like speech holds words missing from the transcript."""
    frames = sum(dur for _, _, dur, _ in phones)
    score = sum(s for *_, s in phones) / max(frames, 1)
    if frames * settings["frame_ms"] < settings["check_pause_ms"]:
        return []
    if score >= settings["min_pause_score_per_frame"]:
        return []
    spoken = [w.label for w in words if w.label != SILENCE]
    after = f"after word {spoken[-1]!r}" if spoken else "before the first word"
    message = (f"the pause {after} sounds like speech ({score:.0f} per frame); "
               "is a word missing from the transcript?")
    return [message]


def _phone_loop(pcm: bytes, duration_ms: int) -> tuple[Span, ...]:
    decoder = _decoder()
    decoder.activate_search(_PHONE_LOOP)
    _decode(decoder, pcm)
    to_ms = _frame_to_ms(duration_ms)
    spans: list[Span] = []
    for seg in decoder.seg():
        label = SILENCE if seg.word in _NOISE else seg.word
        append_span(spans, label, to_ms(seg.start_frame), to_ms(seg.end_frame + 1))
    if not spans or all(s.label == SILENCE for s in spans):
        raise SpeechError("no speech recognised in the audio")
    return cover(spans, duration_ms)


def _frame_to_ms(duration_ms: int) -> Callable[[int], int]:
    """Frame index (of the padded audio) -> ms in the audio, clipped to [0, duration_ms]."""
    settings = alignment_settings()
    pad, frame = settings["pad_ms"], settings["frame_ms"]

    def to_ms(frame_index: int) -> int:
        return int(min(max(frame_index * frame - pad, 0), duration_ms))

    return to_ms

