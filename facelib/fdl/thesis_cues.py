"""The thesis format's lists and ``FDL`` table (see :mod:`facelib.fdl.thesis`) as cues.

Each list runs from time 0, one entry after the other; every entry's origin is its line
in the file that defines the list (the storyboard or a ``.sb`` sub-script).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass

from facelib.cues import ExpressionCue, GazeCue, SpeechSpec, VisemeCue
from facelib.fdl.context import Context
from facelib.fdl.paths import read_text, resolve_inside
from facelib.fdl.thesis import SequenceEntry, sequence
from facelib.fdl.values import LuaTable
from facelib.fdl.visemes import check_viseme

__all__ = ["ThesisList", "expression_cues", "gaze_cues", "speech_spec"]


@dataclass(frozen=True, slots=True)
class ThesisList:
    """A thesis list's value (a converted Lua table) and the script it came from."""

    value: object
    ctx: Context


def _entries(
    given: ThesisList, list_name: str, *, max_len: int | None
) -> Iterator[SequenceEntry]:
    line = given.value.line if isinstance(given.value, LuaTable) else None
    return sequence(given.value, given.ctx, list_name=list_name, min_len=2, max_len=max_len,
                    line=line)


def expression_cues(given: ThesisList | None) -> tuple[ExpressionCue, ...]:
    """``expressions = { {"joy", frames}, ... }`` as full-intensity expression cues."""
    if given is None:
        return ()
    return tuple(
        ExpressionCue(name=e.name, start_ms=e.start_ms, duration_ms=e.duration_ms,
                      origin=given.ctx.origin(e.line))
        for e in _entries(given, "expressions", max_len=2)
    )


def gaze_cues(given: ThesisList | None) -> tuple[GazeCue, ...]:
    """``eyes = { {"lookTo", "left", 17.0, "yes", frames}, ... }`` as gaze cues."""
    if given is None:
        return ()
    return tuple(
        GazeCue(behaviour=e.name, args=e.args, start_ms=e.start_ms, duration_ms=e.duration_ms,
                origin=given.ctx.origin(e.line))
        for e in _entries(given, "eyes", max_len=None)
    )


def _viseme_cues(sentence: ThesisList) -> tuple[VisemeCue, ...]:
    cues = []
    for e in _entries(sentence, "Sentence", max_len=2):
        check_viseme(e.name, path=sentence.ctx.path, line=e.line)
        cues.append(VisemeCue(viseme=e.name, start_ms=e.start_ms, duration_ms=e.duration_ms,
                              origin=sentence.ctx.origin(e.line)))
    return tuple(cues)


def speech_spec(
    fdl: Mapping[str, str | None] | None, fdl_line: int | None, sentence: ThesisList | None,
    ctx: Context,
) -> SpeechSpec | None:
    """Speech from ``FDL.speakSound`` / ``FDL.speakText`` and the ``Sentence`` list (stored
    visemes), starting at 0; None when none of them is given."""
    sound = None if fdl is None else fdl.get("speakSound")
    text_file = None if fdl is None else fdl.get("speakText")
    if sound is None and text_file is None and sentence is None:
        return None
    visemes = None if sentence is None else _viseme_cues(sentence)
    audio = text = None
    if sound is not None:
        audio = resolve_inside(ctx.base_dir, sound, what="FDL.speakSound", path=ctx.path,
                               line=ctx.line_of("speakSound", after=fdl_line))
    if text_file is not None:
        where = ctx.line_of("speakText", after=fdl_line)
        file = resolve_inside(ctx.base_dir, text_file, what="FDL.speakText", path=ctx.path,
                              line=where)
        text = read_text(file, what="FDL.speakText", path=ctx.path, line=where).strip()
    origin = ctx.origin(fdl_line) if fdl is not None else (visemes[0].origin if visemes else None)
    return SpeechSpec(audio=audio, text=text, visemes=visemes, start_ms=0, origin=origin)
