"""The pocketsphinx layer under alignment and recognition: decoders, forced alignment of
a transcript, the phone loop, and the checks of an alignment's plausibility.

:mod:`facelib.speech.align` (with a transcript) and :mod:`facelib.speech.recognize`
(without) both build on it; the live listener uses its decoder.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from facelib.errors import SpeechError
from facelib.optional import require
from facelib.speech.pronounce import model_dir, pronounce, tokenize
from facelib.speech.tables import alignment_settings, phone_durations
from facelib.speech.timeline import SILENCE, Span, append_span, cover

__all__ = ["NOISE", "PHONE_LOOP", "decode", "forced", "new_decoder", "phone_loop",
           "tokenize_words"]

NOISE = {"SIL", "NSN", "SPN", "<sil>", "<s>", "</s>", "[NOISE]", "+NSN+", "+SPN+"}
"""pocketsphinx's labels of silence and noise."""
PHONE_LOOP = "_facelib_phone_loop"
"""The name of the phone-loop search a decoder is given."""


def new_decoder(*, wide: bool = False) -> Any:
    """A new pocketsphinx decoder (``wide``: with the wide beams of alignment.json). Not
    kept: a decoder holds on to the memory of its last search (gigabytes after a long
    recording), so each alignment loads the model afresh (about a second) and frees it."""
    Decoder = require("pocketsphinx").Decoder  # noqa: N806
    settings = alignment_settings()
    beams = settings["wide_beams"] if wide else {}
    decoder = Decoder(bestpath=False, loglevel="FATAL", frate=1000 // settings["frame_ms"],
                      wlen=settings["window_ms"] / 1000, **beams)
    decoder.add_allphone_file(PHONE_LOOP, str(model_dir() / "en-us-phone.lm.bin"))
    return decoder


def tokenize_words(text: str) -> list[str]:
    """The words of ``text`` as the aligner sees them (no punctuation); empty if none."""
    try:
        return [t for t in tokenize(text) if t[0].isalpha()]
    except SpeechError:
        return []


def decode(decoder: Any, pcm: bytes) -> None:
    decoder.start_utt()
    decoder.process_raw(pcm, full_utt=True)
    decoder.end_utt()


def forced(
    pcm: bytes, text: str, duration_ms: int, where: str | Path | None,
    decoders: dict[bool, Any],
) -> tuple[tuple[Span, ...], tuple[Span, ...], list[str], list[str]]:
    """Forced alignment of one utterance; ``decoders`` (wide beams? -> decoder) holds the
    decoders made so far in this call, so pieces of one recording share them."""
    words = [t for t in tokenize(text) if t[0].isalpha()]

    def decoder(*, wide: bool) -> Any:
        if wide not in decoders:
            decoders[wide] = new_decoder(wide=wide)
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
    decode(decoder, pcm)
    try:
        decoder.set_alignment()
    except RuntimeError as exc:
        raise SpeechError(
            f"the transcript {text!r} cannot be aligned to the audio (does it match what is said?)",
            path=where,
        ) from exc
    decode(decoder, pcm)
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
        is_sil = name in NOISE
        start = to_ms(word_start)
        end = to_ms(word_phones[-1][1] + word_phones[-1][2]) if word_phones else start
        append_span(word_spans, SILENCE if is_sil else name, start, end)
        spans = [(SILENCE if (is_sil or label in NOISE) else label, to_ms(p_start),
                  to_ms(p_start + p_dur)) for label, p_start, p_dur, _ in word_phones]
        for label, p_start, p_end in _shift_boundaries(spans, settings):
            append_span(phone_spans, label, p_start, p_end)
        if not is_sil:
            final = k + 1 == n_entries or entries[k + 1][0] in NOISE
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


def phone_loop(pcm: bytes, duration_ms: int) -> tuple[Span, ...]:
    decoder = new_decoder()
    decoder.activate_search(PHONE_LOOP)
    decode(decoder, pcm)
    to_ms = _frame_to_ms(duration_ms)
    spans: list[Span] = []
    for seg in decoder.seg():
        label = SILENCE if seg.word in NOISE else seg.word
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

