"""libespeak-ng (the ``speech`` extra: the ``espeakng-loader`` wheel ships the library and
its data): synthesis whose callback receives the audio samples together with a PHONEME
event (IPA name, sample position) for every phone and a WORD event (text position) for every
word, so phone times are exact for the audio made. The ctypes binding itself is
:mod:`facelib.speech.espeak_worker`.

Synthesis runs in a fresh process: libespeak-ng keeps waveform state (voicing phase) in
static variables that neither its seeds nor re-initialisation reset, so within one process
the same text comes out a few ms different from call to call, depending on everything
spoken before. A freshly loaded library given the same requests in the same order gives the
same samples and times, bit for bit, so an animation never depends on what the process did
earlier. It costs one small interpreter start (about 0.1 s) per batch of requests; a
:class:`Worker` started ahead of its request (a live session keeps one spare) has paid it,
and the library is loaded, by the time the text comes.
"""

from __future__ import annotations

import pickle
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facelib.errors import SpeechError
from facelib.optional import require
from facelib.speech import espeak_worker

__all__ = ["EspeakEvent", "EspeakVoice", "RawSynthesis", "Worker", "default_words_per_minute",
           "list_voices", "synth_fresh"]

_DEFAULT_WPM = 175
"""espeak-ng's default speaking rate (words per minute): ``rate=1.0``."""


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


def _check_installed() -> None:
    require("espeak")


class Worker:
    """A synthesis process, started now and given its one batch of requests later (by
    :func:`synth_fresh`): a fresh library either way, so the same result bit for bit, without
    the wait for the interpreter and the library once the text comes. :meth:`close` ends
    one that is not used."""

    def __init__(self) -> None:
        _check_installed()
        self._process: subprocess.Popen[bytes] | None = subprocess.Popen(
            [sys.executable, str(Path(espeak_worker.__file__))], stdin=subprocess.PIPE,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE)

    def run(self, payload: bytes) -> tuple[int, bytes, bytes]:
        """Exit status, stdout and stderr of the worker given ``payload`` (once only)."""
        process, self._process = self._process, None
        if process is None:
            raise SpeechError("an espeak-ng worker speaks one batch of requests only")
        out, err = process.communicate(payload)
        return process.returncode, out, err

    def close(self) -> None:
        """End the process if it has not been used."""
        process, self._process = self._process, None
        if process is not None:
            process.kill()
            process.communicate()


def synth_fresh(requests: Sequence[tuple[str, str, int, int]], *,
                worker: Worker | None = None) -> list[RawSynthesis]:
    """Each ``(text, voice, words_per_minute, pitch)`` spoken in turn by a freshly loaded
    libespeak-ng in a new process (``worker``, started ahead, or one started now).
    ``voice``: a language code or voice identifier (``"+variant"`` allowed);
    ``words_per_minute`` 80-450; ``pitch`` 0-100 (50: the voice's own). Raises SpeechError
    for an unknown voice or a failed synthesis."""
    _check_installed()
    payload = pickle.dumps([(str(t), str(v), int(w), int(p)) for t, v, w, p in requests])
    code, stdout, stderr = (worker or Worker()).run(payload)
    if code != 0:
        raise SpeechError("espeak-ng synthesis failed: "
                          + stderr.decode("utf-8", "replace").strip()[-400:])
    result = pickle.loads(stdout)
    if isinstance(result, tuple) and result and result[0] == "error":
        raise SpeechError(str(result[1]))
    out = []
    for rate, pcm, events in result:
        samples = np.frombuffer(pcm, dtype="<i2").astype(np.int16)
        out.append(RawSynthesis(samples, int(rate), tuple(EspeakEvent(*e) for e in events)))
    return out


def default_words_per_minute() -> int:
    """espeak-ng's default rate (words per minute), the speed of ``rate=1.0``."""
    return _DEFAULT_WPM


def list_voices() -> tuple[EspeakVoice, ...]:
    """Every voice the bundled espeak-ng data holds, sorted by identifier."""
    _check_installed()
    try:
        found = espeak_worker.voices()
    except RuntimeError as exc:
        raise SpeechError(str(exc)) from exc
    return tuple(sorted(
        (EspeakVoice(identifier, name, languages, {1: "male", 2: "female"}.get(gender, ""))
         for identifier, name, languages, gender in found),
        key=lambda v: v.identifier,
    ))
