"""What the exporters take: a FapStream, or an animation with ``faps`` and its speech audio."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from facelib.errors import ParameterError
from facelib.mpeg4.stream import FapStream

__all__ = ["Source", "resolve_source"]

Source = Any
"""A :class:`~facelib.mpeg4.stream.FapStream` or an object with ``faps`` (``audio`` and
``audio_offset`` optional), such as ``facelib.run_fdl``'s ``Animation``."""


def resolve_source(
    source: Source, audio: str | os.PathLike[str] | None = None
) -> tuple[FapStream, Path | None, float]:
    """``(stream, audio path or None, audio offset in seconds)`` of an export's source.

    ``audio`` given explicitly wins over the source's own; it must exist.
    """
    stream = source if isinstance(source, FapStream) else getattr(source, "faps", None)
    if not isinstance(stream, FapStream):
        raise ParameterError(f"export needs a FapStream or an animation with .faps, not "
                             f"{type(source).__name__}")
    if stream.n_frames == 0:
        raise ParameterError("nothing to export: the stream has no frames")
    own = getattr(source, "audio", None)
    offset = float(getattr(source, "audio_offset", 0.0) or 0.0)
    chosen = Path(audio) if audio is not None else (Path(own) if own is not None else None)
    if audio is not None:
        offset = 0.0
    if chosen is not None and not chosen.is_file():
        raise ParameterError(f"audio file {chosen} does not exist")
    return stream, chosen, offset
