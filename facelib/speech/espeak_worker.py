"""libespeak-ng through ctypes, standalone (standard library and ``espeakng_loader`` only).

:mod:`facelib.speech.espeak` imports it to list voices, and runs it as a script
(``python .../espeak_worker.py``) to synthesize with a freshly loaded library: it loads the
library, then reads a
pickled list of ``(text, voice, words_per_minute, pitch)`` from stdin and writes a pickled
list of ``(sample_rate, int16 PCM bytes, events)`` (events: ``(kind, name, sample,
text_position, length)``), or ``("error", message)``, to stdout. Only facelib starts it,
with its own data. It imports nothing from facelib, so it starts in about 0.1 s.
"""

from __future__ import annotations

import contextlib
import ctypes
import pickle
import sys
from functools import cache
from typing import Any

SYNCHRONOUS = 2
INIT_FLAGS = 0x0001 | 0x0002 | 0x8000  # phoneme events, IPA names, don't exit on errors
CHARS_UTF8 = 1
POS_CHARACTER = 1
EVENT_WORD = 1
EVENT_PHONEME = 7
PARAM_RATE = 1
PARAM_PITCH = 3

Event = tuple[str, str, int, int, int]
Result = tuple[int, bytes, list[Event]]


class EventId(ctypes.Union):
    _fields_ = (("number", ctypes.c_int), ("name", ctypes.c_char_p),
                ("string", ctypes.c_char * 8))


class EventStruct(ctypes.Structure):
    _fields_ = (("type", ctypes.c_int), ("unique_identifier", ctypes.c_uint),
                ("text_position", ctypes.c_int), ("length", ctypes.c_int),
                ("audio_position", ctypes.c_int), ("sample", ctypes.c_int),
                ("user_data", ctypes.c_void_p), ("id", EventId))


class VoiceStruct(ctypes.Structure):
    _fields_ = (("name", ctypes.c_char_p), ("languages", ctypes.c_void_p),
                ("identifier", ctypes.c_char_p), ("gender", ctypes.c_ubyte),
                ("age", ctypes.c_ubyte), ("variant", ctypes.c_ubyte),
                ("xx1", ctypes.c_ubyte), ("score", ctypes.c_int), ("spare", ctypes.c_void_p))


CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_short), ctypes.c_int,
                            ctypes.POINTER(EventStruct))


@cache
def library() -> tuple[Any, int]:
    """The initialised library and its sample rate (Hz). ImportError without the wheel;
    RuntimeError if it does not initialise."""
    import espeakng_loader

    lib = ctypes.CDLL(espeakng_loader.get_library_path())
    lib.espeak_Initialize.argtypes = (ctypes.c_int, ctypes.c_int, ctypes.c_char_p, ctypes.c_int)
    lib.espeak_SetVoiceByName.argtypes = (ctypes.c_char_p,)
    lib.espeak_SetParameter.argtypes = (ctypes.c_int, ctypes.c_int, ctypes.c_int)
    lib.espeak_Synth.argtypes = (ctypes.c_char_p, ctypes.c_size_t, ctypes.c_uint, ctypes.c_int,
                                 ctypes.c_uint, ctypes.c_uint, ctypes.c_void_p, ctypes.c_void_p)
    lib.espeak_ListVoices.argtypes = (ctypes.c_void_p,)
    lib.espeak_ListVoices.restype = ctypes.POINTER(ctypes.POINTER(VoiceStruct))
    lib.espeak_ng_SetRandSeed.argtypes = (ctypes.c_long,)
    rate = lib.espeak_Initialize(SYNCHRONOUS, 0, espeakng_loader.get_data_path().encode(),
                                 INIT_FLAGS)
    if rate <= 0:
        raise RuntimeError(f"libespeak-ng failed to initialise (code {rate})")
    return lib, int(rate)


def speak(text: str, voice: str, words_per_minute: int, pitch: int) -> Result:
    """``(sample_rate, int16 PCM bytes, events)`` of ``text``; ValueError for an unknown
    voice or a failed synthesis. The library's random generators are seeded (0) first."""
    lib, rate = library()
    if lib.espeak_SetVoiceByName(voice.encode()) != 0:
        raise ValueError(f"espeak-ng has no voice {voice!r} (see `facelib list voices`)")
    lib.espeak_SetParameter(PARAM_RATE, int(words_per_minute), 0)
    lib.espeak_SetParameter(PARAM_PITCH, int(pitch), 0)
    lib.espeak_ng_SetRandSeed(0)
    chunks: list[bytes] = []
    events: list[Event] = []

    def on_synth(wav: Any, n: int, ev: Any) -> int:
        if n > 0:
            chunks.append(ctypes.string_at(wav, 2 * n))
        i = 0
        while ev[i].type != 0:
            e = ev[i]
            if e.type == EVENT_PHONEME:
                name = e.id.string.decode("utf-8", "replace")
                events.append(("phone", name, e.sample, e.text_position, 0))
            elif e.type == EVENT_WORD:
                events.append(("word", "", e.sample, e.text_position, e.length))
            i += 1
        return 0

    callback = CALLBACK(on_synth)
    lib.espeak_SetSynthCallback(callback)
    try:
        data = text.encode("utf-8")
        code = lib.espeak_Synth(data, len(data) + 1, 0, POS_CHARACTER, 0, CHARS_UTF8, None, None)
    finally:
        lib.espeak_SetSynthCallback(CALLBACK())
    if code != 0:
        raise ValueError(f"espeak-ng could not speak {text[:40]!r} (code {code})")
    return rate, b"".join(chunks), events


def voices() -> list[tuple[str, str, tuple[str, ...], int]]:
    """``(identifier, name, languages, gender)`` of every installed voice (gender 1 male,
    2 female, 0 unknown)."""
    lib, _ = library()
    out = []
    table = lib.espeak_ListVoices(None)
    i = 0
    while table[i]:
        v = table[i].contents
        address = v.languages
        out.append(((v.identifier or b"").decode(), (v.name or b"").decode(),
                    _languages(address), int(v.gender)))
        i += 1
    return out


def _languages(address: int | None) -> tuple[str, ...]:
    """espeak's language list: (priority byte, NUL-terminated name) pairs, ended by 0."""
    out: list[str] = []
    offset = 0
    while address and ctypes.c_ubyte.from_address(address + offset).value != 0:
        name = ctypes.string_at(address + offset + 1)
        out.append(name.decode())
        offset += 2 + len(name)
    return tuple(out)


def main() -> int:
    # the library is loaded before the requests are read, so a process started ahead of its
    # request (facelib.speech.espeak.Worker) has it ready; the result is the same either way
    with contextlib.suppress(RuntimeError, ImportError):  # reported below, with the requests
        library()
    requests = pickle.loads(sys.stdin.buffer.read())
    try:
        result: object = [speak(*request) for request in requests]
    except (ValueError, RuntimeError, ImportError) as exc:
        result = ("error", str(exc))
    sys.stdout.buffer.write(pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL))
    return 0


if __name__ == "__main__":
    sys.exit(main())
