"""libespeak-ng through ctypes (the ``speech`` extra: the ``espeakng-loader`` wheel ships
the library and its data): synthesis in synchronous mode, whose callback receives the audio
samples together with a PHONEME event (IPA name, sample position) for every phone and a
WORD event (text position) for every word, so phone times are exact for the audio made.

The library keeps one synthesizer per process; calls are serialised by a lock and every
call sets the voice and parameters it needs, so no setting leaks from one call to another.
"""

from __future__ import annotations

import ctypes
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

from facelib.errors import MissingExtraError, SpeechError

__all__ = ["EspeakEvent", "EspeakVoice", "RawSynthesis", "list_voices", "synth_raw"]

_SYNCHRONOUS = 2
_INIT_PHONEME_EVENTS = 0x0001
_INIT_PHONEME_IPA = 0x0002
_INIT_DONT_EXIT = 0x8000
_CHARS_UTF8 = 1
_POS_CHARACTER = 1
_EVENT_WORD = 1
_EVENT_PHONEME = 7
_PARAM_RATE = 1
_PARAM_PITCH = 3
_DEFAULT_WPM = 175
"""espeak-ng's default speaking rate (words per minute): ``rate=1.0``."""
_LOCK = threading.Lock()


class _EventId(ctypes.Union):
    _fields_ = (("number", ctypes.c_int), ("name", ctypes.c_char_p),
                ("string", ctypes.c_char * 8))


class _Event(ctypes.Structure):
    _fields_ = (("type", ctypes.c_int), ("unique_identifier", ctypes.c_uint),
                ("text_position", ctypes.c_int), ("length", ctypes.c_int),
                ("audio_position", ctypes.c_int), ("sample", ctypes.c_int),
                ("user_data", ctypes.c_void_p), ("id", _EventId))


class _Voice(ctypes.Structure):
    _fields_ = (("name", ctypes.c_char_p), ("languages", ctypes.c_char_p),
                ("identifier", ctypes.c_char_p), ("gender", ctypes.c_ubyte),
                ("age", ctypes.c_ubyte), ("variant", ctypes.c_ubyte),
                ("xx1", ctypes.c_ubyte), ("score", ctypes.c_int), ("spare", ctypes.c_void_p))


_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_short), ctypes.c_int,
                             ctypes.POINTER(_Event))


@dataclass(frozen=True, slots=True)
class EspeakEvent:
    """A PHONEME (``kind="phone"``, ``name`` the IPA symbol, ``""`` for a pause) or WORD
    (``kind="word"``, ``name`` empty) event: ``sample`` where it starts in the audio,
    ``text_position`` (1-based character) and ``length`` (characters, words only)."""

    kind: str
    name: str
    sample: int
    text_position: int
    length: int


@dataclass(frozen=True, slots=True)
class RawSynthesis:
    """``samples`` ``(n,) int16`` at ``sample_rate`` Hz and the events in time order."""

    samples: np.ndarray
    sample_rate: int
    events: tuple[EspeakEvent, ...]


@dataclass(frozen=True, slots=True)
class EspeakVoice:
    """An installed voice: ``identifier`` (what ``voice=`` takes, e.g. ``"roa/pt"``),
    ``name``, ``languages`` (codes, most preferred first) and ``gender`` (``"male"``,
    ``"female"`` or ``""``)."""

    identifier: str
    name: str
    languages: tuple[str, ...]
    gender: str


@cache
def _library() -> tuple[Any, int]:
    """The initialised library and its output sample rate (Hz); loaded once."""
    try:
        import espeakng_loader
    except ImportError as exc:
        raise MissingExtraError("speech synthesis", "speech", "espeakng-loader") from exc
    lib = ctypes.CDLL(espeakng_loader.get_library_path())
    lib.espeak_Initialize.argtypes = (ctypes.c_int, ctypes.c_int, ctypes.c_char_p, ctypes.c_int)
    lib.espeak_SetVoiceByName.argtypes = (ctypes.c_char_p,)
    lib.espeak_SetParameter.argtypes = (ctypes.c_int, ctypes.c_int, ctypes.c_int)
    lib.espeak_Synth.argtypes = (ctypes.c_char_p, ctypes.c_size_t, ctypes.c_uint, ctypes.c_int,
                                 ctypes.c_uint, ctypes.c_uint, ctypes.c_void_p, ctypes.c_void_p)
    lib.espeak_ListVoices.argtypes = (ctypes.c_void_p,)
    lib.espeak_ListVoices.restype = ctypes.POINTER(ctypes.POINTER(_Voice))
    rate = lib.espeak_Initialize(_SYNCHRONOUS, 0, espeakng_loader.get_data_path().encode(),
                                 _INIT_PHONEME_EVENTS | _INIT_PHONEME_IPA | _INIT_DONT_EXIT)
    if rate <= 0:
        raise SpeechError(f"libespeak-ng failed to initialise (code {rate})")
    return lib, int(rate)


@contextmanager
def _collecting() -> Iterator[tuple[list[np.ndarray], list[EspeakEvent]]]:
    """Install a synthesis callback that appends to two lists; remove it afterwards."""
    lib, _ = _library()
    chunks: list[np.ndarray] = []
    events: list[EspeakEvent] = []

    def on_synth(wav: Any, n: int, ev: Any) -> int:
        if n > 0:
            chunks.append(np.ctypeslib.as_array(wav, (n,)).copy())
        i = 0
        while ev[i].type != 0:
            e = ev[i]
            if e.type == _EVENT_PHONEME:
                name = e.id.string.decode("utf-8", "replace")
                events.append(EspeakEvent("phone", name, e.sample, e.text_position, 0))
            elif e.type == _EVENT_WORD:
                events.append(EspeakEvent("word", "", e.sample, e.text_position, e.length))
            i += 1
        return 0

    callback = _CALLBACK(on_synth)
    lib.espeak_SetSynthCallback(callback)
    try:
        yield chunks, events
    finally:
        lib.espeak_SetSynthCallback(_CALLBACK())


@cache
def _libc() -> Any:
    return ctypes.CDLL(None)


def synth_raw(text: str, *, voice: str, words_per_minute: int, pitch: int,
              seed: int = 0) -> RawSynthesis:
    """Speak ``text`` (plain UTF-8, no SSML) with espeak-ng ``voice`` (a language code or a
    voice identifier, ``"+variant"`` allowed) at ``words_per_minute`` (80-450) and
    ``pitch`` (0-100, 50 the voice's own). Raises SpeechError for an unknown voice.

    espeak-ng varies its output with a pseudo-random generator (pitch jitter, noise
    sources, some phone lengths); it is seeded with ``seed`` first
    (``espeak_ng_SetRandSeed``, and the C library's ``srand``), so the same text, voice and
    seed give the same samples and times, bit for bit."""
    lib, rate = _library()
    with _LOCK:
        lib.espeak_ng_SetRandSeed(ctypes.c_long(seed))
        _libc().srand(ctypes.c_uint(seed & 0xFFFFFFFF))
        if lib.espeak_SetVoiceByName(voice.encode()) != 0:
            raise SpeechError(f"espeak-ng has no voice {voice!r} (see `facelib list voices`)")
        lib.espeak_SetParameter(_PARAM_RATE, int(words_per_minute), 0)
        lib.espeak_SetParameter(_PARAM_PITCH, int(pitch), 0)
        data = text.encode("utf-8")
        with _collecting() as (chunks, events):
            code = lib.espeak_Synth(data, len(data) + 1, 0, _POS_CHARACTER, 0, _CHARS_UTF8,
                                    None, None)
        if code != 0:
            raise SpeechError(f"espeak-ng could not speak {text[:40]!r} (code {code})")
    samples = np.concatenate(chunks) if chunks else np.zeros(0, np.int16)
    return RawSynthesis(samples.astype(np.int16, copy=False), rate, tuple(events))


def default_words_per_minute() -> int:
    """espeak-ng's default rate (words per minute), the speed of ``rate=1.0``."""
    return _DEFAULT_WPM


def list_voices() -> tuple[EspeakVoice, ...]:
    """Every voice the bundled espeak-ng data holds, sorted by identifier."""
    lib, _ = _library()
    out = []
    with _LOCK:
        table = lib.espeak_ListVoices(None)
        i = 0
        while table[i]:
            v = table[i].contents
            out.append(EspeakVoice(
                identifier=(v.identifier or b"").decode(),
                name=(v.name or b"").decode(),
                languages=_languages(ctypes.cast(v.languages, ctypes.c_void_p).value),
                gender={1: "male", 2: "female"}.get(v.gender, ""),
            ))
            i += 1
    return tuple(sorted(out, key=lambda v: v.identifier))


def _languages(address: int | None) -> tuple[str, ...]:
    """espeak's language list: (priority byte, NUL-terminated name) pairs, ended by 0."""
    if not address:
        return ()
    out = []
    offset = 0
    while ctypes.c_ubyte.from_address(address + offset).value != 0:
        name = ctypes.string_at(address + offset + 1)
        out.append(name.decode())
        offset += 2 + len(name)
    return tuple(out)
