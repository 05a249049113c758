"""Speech audio copied next to an export, under a name facelib chooses.

The copy is named after the export (``a.glb`` -> ``a.wav``; a web player's ``face.glb`` ->
``face.wav``) with the suffix of the format the file's first bytes show
(``data/export/audio_signatures.csv``), never the suffix the caller's file had: a WAV named
``voice.html`` with a script appended is copied as ``face.wav``, not as a page beside
``index.html``. A file that shows no known audio format is refused.
"""

from __future__ import annotations

import shutil
import stat
from functools import cache
from pathlib import Path

from facelib import data
from facelib.atomic import atomic_path
from facelib.errors import FileError, ParameterError

__all__ = ["audio_suffix", "copy_audio"]

_HEAD_BYTES = 64


@cache
def _signatures() -> tuple[tuple[str, tuple[tuple[int, bytes], ...]], ...]:
    """(suffix, ((offset, signature bytes), ...)) per format, in the data file's order."""
    formats: dict[str, tuple[str, list[tuple[int, bytes]]]] = {}
    for _, row in data.csv_rows("export/audio_signatures.csv"):
        _, parts = formats.setdefault(row["format"], (row["suffix"], []))
        parts.append((int(row["offset"]), bytes.fromhex(row["signature"])))
    return tuple((suffix, tuple(parts)) for suffix, parts in formats.values())


def audio_suffix(audio: Path) -> str:
    """The suffix (``.wav``, ``.flac``, ...) of the audio format ``audio``'s first bytes show.

    Raises ParameterError naming the file if it is not a regular file or its content is no
    audio format facelib copies; FileError if it cannot be read.
    """
    try:
        if not stat.S_ISREG(audio.stat().st_mode):
            raise ParameterError(f"audio {str(audio)!r} is not a regular file")
        with audio.open("rb") as handle:
            head = handle.read(_HEAD_BYTES)
    except OSError as exc:
        raise FileError.wrap(exc, "read", audio) from exc
    for suffix, parts in _signatures():
        if all(head[offset:offset + len(sig)] == sig for offset, sig in parts):
            return suffix
    shown = head[:8].hex(" ") if head else "an empty file"
    kinds = sorted({suffix for suffix, _ in _signatures()})
    raise ParameterError(f"audio {str(audio)!r} is not an audio file facelib can copy (it "
                         f"starts with {shown}; expected one of {', '.join(kinds)})")


def copy_audio(audio: Path | None, out: Path) -> Path | None:
    """Copy ``audio`` beside ``out`` as ``out``'s stem with the suffix its content shows
    (:func:`audio_suffix`), atomically; the copy's path, or None for no audio."""
    if audio is None:
        return None
    copied = out.with_suffix(audio_suffix(audio))
    with atomic_path(copied) as temp:
        shutil.copyfile(audio, temp)
    return copied
